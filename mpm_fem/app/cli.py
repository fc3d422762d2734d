"""The ``mpm-fem`` command line.

    mpm-fem sod      [--h 0.01] [--ppc 4] [--T 0.2] [--cfl C] [--mass lumped|consistent] [--basis p1|gimp] ...
    mpm-fem burgers  [--h 0.01] [--eps 0.045] [--acceleration exact|calculated] [--solution NAME] ...
    mpm-fem plane    axis|vortex [--h 0.0625] [--ppc 2] [--basis p1] [--vtu] ...   (:mod:`mpm_fem.app.plane_cli`)

Each option's default is the field default of the problem's settings dataclass (one place).
Before a run allocates anything its cost is estimated from the settings and checked
(:mod:`mpm_fem.app.guard`); the run then writes into a temporary folder renamed into place when done
(:func:`mpm_fem.app.output.staged_dir`). Bad input ends with a one-line message and exit status 2; a
run that fails (lost positivity) with a one-line message and exit status 1; Ctrl-C with one line
and exit status 130. The study options are parsed by :mod:`mpm_fem.app.study`, which the study
scripts use without this module.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

import numpy as np

from mpm_fem.app import guard, inputs, output, plane_cli
from mpm_fem.app.compiling import compile_notice
from mpm_fem.app.guard import UsageError
from mpm_fem.app.study import add_study_options, add_tier_options, start_study, study_options
from mpm_fem.bases import compiled, get, names, plugins
from mpm_fem.core.grid import GridError
from mpm_fem.core.particles import LAYOUTS
from mpm_fem.core.reconstruction import RECONSTRUCTIONS
from mpm_fem.core.step import ACCELERATIONS, INTERPOLATIONS, PROJECTIONS, SCHEMES, STAGE_MASS
from mpm_fem.core.transfers import get as get_transfer
from mpm_fem.core.transfers import names as transfer_names
from mpm_fem.core.transfers import plugins as transfer_plugins
from mpm_fem.core.volume import VOLUMES

CHOICES = {"mass": STAGE_MASS, "scheme": SCHEMES, "layout": LAYOUTS, "acceleration": ACCELERATIONS,
           "projection": PROJECTIONS, "interpolation": INTERPOLATIONS}
# --- remedies (E5): --flip ALPHA, --xpic M, --reconstruct none|taylor, --volume carried|grid, --basis bspline_gimp
CHOICES.update({"reconstruct": RECONSTRUCTIONS, "volume": VOLUMES, "kernel": ("fused", "numpy")})
REMEDY_HELP = {
    "flip": "PIC/FLIP blend alpha in [0, 1]: 1 FLIP (standard), 0 PIC",
    "xpic": "XPIC(M) particle velocity update of order M >= 1 in place of the blend (1: PIC); 0: off",
    "reconstruct": "stress before the force integral: none (particle sum) or taylor (per-cell least-squares line)",
    "volume": "particle volumes: carried by the flow, or grid (reset to tile the grid every step)",
    "transfer": "grid-to-particle transfer (the registry of mpm_fem.core.transfers, or package.module:Name of one "
                "outside it, run on the numpy step with the blend of --flip as its setting): flip (the blend of "
                "--flip), xpic (the order of --xpic) or apic (affine particle-in-cell)",
}
HELP = {
    "h": "cell size (must divide the domain)",
    "ppc": "particles per cell N_p",
    "T": "final time",
    "cfl": "CFL number: dt = CFL h / max(c + |v|); stable range (0, 0.5] with lumped mass, (0, 0.25] with "
           "consistent mass (a run inside it can still lose positivity: exit status 1)",
    "gamma": "ratio of specific heats, > 1",
    "av_linear": "artificial viscosity, linear coefficient C_lin >= 0",
    "av_quadratic": "artificial viscosity, quadratic coefficient C_quad >= 0",
    "x0": "position of the diaphragm, inside (0, 1)",
    "mass": "grid mass matrix; exact: the FE + mass lumping stage made exact (error budget)",
    "projection": "particle-to-grid projection: MPM sums or exact integrals of the exact fields",
    "interpolation": "grid-to-particle interpolation: MPM sums or exact for the exact fields",
    "refine": "time stage: the time step divided by this integer",
    "kernel": "step implementation: compiled fused passes, or the numpy reference step",
    "threads": "threads of the fused step (deterministic; equal to one thread to round-off)",
    "scheme": "stress update order",
    "layout": "initial particle layout in each cell",
    "seed": "random seed (integer >= 0) of jittered/random layouts",
    "eps": "viscosity eps > 0",
    "solution": "exact solution giving initial, boundary data and errors",
    "acceleration": "nodal acceleration: calculated F_i/m_i or the exact eps v_xx",
    "weights": "particle weights: volume (V_p carried by the flow, standard MPM) or cell (the slides' h/N_p^i); "
               "cell needs point mass with USL",
    "force": "internal force: weak (F_i = -sum_p V_p eps (dv/dx)_p G_ip) or slides (their count-normalised second "
             "difference); slides needs point mass with USL",
    "dt_rule": "time step: stable (CFL min(h/max|v|, h^2/(2 eps))) or advective (CFL h/max|v|, exact "
               "acceleration only)",
}
BURGERS_HELP = {
    "cfl": "CFL number: dt = CFL min(h/max|v|, h^2/(2 eps)); stable range (0, 1], (0, 1/3] with consistent mass "
           "and the calculated acceleration",
}
HELP.update(REMEDY_HELP)


def basis_option(spec: str) -> str:
    """The ``--basis`` value: a registered name, an alias (``p1``: ``mpm``), an installed entry point's
    or a ``package.module:Name`` checked against the contract (:func:`mpm_fem.app.inputs.extension`, as
    the Python API); a refusal is argparse's one-line error."""
    return _extension("basis", spec)


def transfer_option(spec: str) -> str:
    """The ``--transfer`` value, as :func:`basis_option` (:mod:`mpm_fem.core.transfers.plugins`)."""
    return _extension("transfer", spec)


def _extension(setting: str, spec: str) -> str:
    try:
        return inputs.extension(setting, spec)
    except UsageError as err:
        raise argparse.ArgumentTypeError(str(err)) from None


#: the options whose value is a registered extension or one from outside: its parser and its registry's names
EXTENSIONS = {"basis": (basis_option, names), "transfer": (transfer_option, transfer_names)}


def basis_help() -> str:
    """The ``--basis`` help: every registered basis (installed entry points included)."""
    aliases = {name: alias for alias, name in inputs.ALIASES["basis"].items()}
    return ("particle basis (the registry of mpm_fem.bases, or package.module:Name of one outside it): "
            + ", ".join(f"{get(b).title} ({b}{' or ' + aliases[b] if b in aliases else ''})" for b in names()))


def _add_settings_options(parser: argparse.ArgumentParser, settings_cls, extra_choices=None, extra_help=None) -> None:
    choices = {**CHOICES, **(extra_choices or {})}
    helps = {**HELP, "basis": basis_help(), **(extra_help or {})}
    for f in dataclasses.fields(settings_cls):
        if isinstance(f.default, tuple):
            continue  # initial states stay in the settings JSON, not on the command line
        kind, registered = EXTENSIONS.get(f.name, (type(f.default), None))
        parser.add_argument(
            f"--{f.name.replace('_', '-')}",
            dest=f.name,
            type=kind,
            default=f.default,
            choices=choices.get(f.name),
            metavar="|".join(registered()) if registered else None if f.name in choices else f.name.upper(),
            help=f"{helps[f.name]} (default: %(default)s)",
        )
    parser.add_argument("--out", default=None,
                        help="output directory (default: runs/<problem>-<settings hash>/, replaced whole on a rerun); "
                             "the run writes into a temporary folder beside it and renames it into place when done")
    parser.add_argument("--overwrite", action="store_true", help="replace a non-empty --out whole (refused without it)")
    parser.add_argument("--yes-long", action="store_true",
                        help=f"run even if estimated over {guard.LONG_RUN_S / 3600:g} h (the estimate is printed "
                             "at the start of every run and recorded in summary.json)")
    parser.add_argument("--save-fields", type=int, nargs="?", const=20, default=None, metavar="EVERY",
                        help="write particle and grid fields every EVERY steps (default 20) and at T as VTU files "
                             "with a .pvd time series for ParaView, into DIR/fields/")
    parser.add_argument("--quiet", action="store_true", help="no estimate, progress bar or summary line")


def build_parser() -> argparse.ArgumentParser:
    from baselines.exact.burgers import SOLUTIONS
    from mpm_fem.problems.burgers import DT_RULES, FORCES, WEIGHTS, BurgersSettings
    from mpm_fem.problems.sod import SodSettings

    plugins.discover()  # installed bases and transfers join the choices
    transfer_plugins.discover()
    parser = guard.OneLineParser(
        prog="mpm-fem",
        description="Where does the error of the Material Point Method come from? "
        "MPM runs, studies and the reproduction of Tran & Berzins' error analysis.",
    )
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    sod = sub.add_parser("sod", help="MPM on Sod's shock tube against the exact Riemann solution",
                         description="MPM on Sod's shock tube, x in [0,1], T=0.2, walls at both ends.")
    _add_settings_options(sod, SodSettings)
    burgers = sub.add_parser("burgers", help="MPM on viscous Burgers against an exact solution",
                             description="MPM on viscous Burgers v_t + v v_x = eps v_xx on [0,2], T=0.5.")
    _add_settings_options(burgers, BurgersSettings, {"solution": tuple(SOLUTIONS), "weights": WEIGHTS, "force": FORCES,
                                                     "dt_rule": DT_RULES}, BURGERS_HELP)

    from mpm_fem.app.study import STUDIES

    study = sub.add_parser("study", help="run one study: tables and figures into figures/quick/<name>/ (the quick "
                           "tier, the default), figures/<name>/ (--full) or figures/deep/<name>/ (--deep)",
                           description="Run one study of the error analysis, in the quick tier unless --full or "
                           "--deep, into figures/quick/<name>/ (figures/<name>/ with --full, figures/deep/<name>/ "
                           "with --deep, or --out DIR); prints the estimate first; results are cached per case. A "
                           "folder holds one tier: a folder with tables of another tier is refused unless "
                           "--overwrite.")
    study.add_argument("name", choices=STUDIES, help="which study")
    add_study_options(study)
    reproduce = sub.add_parser("reproduce", help="run every study and write REPORT.md: into figures/quick/ (--quick, "
                               "the default), figures/ (--full) or figures/deep/ (--deep)",
                               description="Regenerate every table and figure and REPORT.md, into figures/quick/ with "
                               "--quick (the default), figures/ with --full, figures/deep/ with --deep (or --out DIR); "
                               "prints the estimate first. A folder holds one tier: a folder with tables of another "
                               "tier is refused unless --overwrite.")
    add_tier_options(reproduce, "quick")
    method = sub.add_parser("method", help="a basis (yours: package.module:Name or an entry point) beside the "
                            "package's: projection orders, Sod and Burgers convergence, the study's verdicts",
                            description="Measure one basis beside mpm, gimp, bspline and bspline_gimp: the "
                            "projection orders on regular and jittered particles, Sod's and Burgers' convergence at "
                            "the study's settings over seeds, and the verdicts M1-M3 (METHOD.md), into "
                            "OUT/method/<basis>/ (default runs/); prints the estimate first; cases are cached.")
    method.add_argument("basis", help="a registered basis, an installed entry point's, or package.module:Name")
    method.add_argument("--full", action="store_true", help="finer meshes and five seeds (the quick plan otherwise)")
    method.add_argument("--jobs", type=int, default=None, help="worker processes (default: the cores, at most 8)")
    method.add_argument("--out", default="runs", help="folder holding method/<basis>/ (default: runs)")
    method.add_argument("--quiet", action="store_true", help="no estimate or progress output")
    add_study_options(reproduce, quick_flag=False,
                       out_help="figures folder (default: figures/quick, figures or figures/deep by tier)")
    plane_cli.add_parser(sub)
    return parser


def _settings(cls, args):
    values = {f.name: getattr(args, f.name) for f in dataclasses.fields(cls) if hasattr(args, f.name)}
    try:
        return cls(**values)
    except (ValueError, GridError) as err:
        raise UsageError(str(err)) from None


def _prepare(args, problem: str, module, settings_cls):
    """Settings, the guarded cost estimate (printed unless ``--quiet``) and the checked output folder,
    all before anything is allocated. A default folder (named by the settings hash, so it holds the
    same run) is replaced on a rerun; an explicit ``--out`` needs ``--overwrite`` if not empty."""
    settings = _settings(settings_cls, args)
    try:
        module.check_stable(settings)
    except ValueError as err:
        raise UsageError(str(err)) from None
    if args.save_fields is not None and args.save_fields < 1:
        raise UsageError(f"--save-fields takes a step interval >= 1, got {args.save_fields}")
    try:
        with np.errstate(all="ignore"):  # extreme settings: a non-finite estimate is refused below
            cost = module.cost(settings)
    except ValueError as err:  # a run too large to estimate is refused like one too large to run
        raise UsageError(str(err)) from None
    guard.check_cost(cost, args.yes_long)
    out = Path(args.out or f"runs/{problem}-{output.settings_hash(settings.as_dict())}")
    try:
        output.check_run_dir(out, overwrite=args.overwrite or args.out is None)
    except (PermissionError, FileExistsError) as err:
        raise UsageError(str(err)) from None
    if not args.quiet:
        slower = (f" on the numpy step: the basis {settings.basis} has no compiled kernels"
                  if cost.kernel == "numpy" and settings.kernel == "fused" and not compiled(settings.basis)
                  else f" on the numpy step: the transfer {settings.transfer} has no compiled kernels"
                  if cost.kernel == "numpy" and settings.kernel == "fused"
                  and not get_transfer(settings.stages.transfer_name).compiled else "")
        print(f"{problem}: {guard.describe(cost)}{slower}", file=sys.stderr)
    return settings, cost, out


def _simulate(args, module, settings, folder: Path, grid, exact=None):
    """Run ``module.simulate``, writing fields into ``folder/fields`` if ``--save-fields`` (with the
    exact solution ``exact(x, t) -> {field: values}`` and the errors beside them); a line on stderr
    while numba compiles (unless ``--quiet``)."""
    writer = None
    if args.save_fields is not None:
        from mpm_fem.app.fields import FieldWriter

        writer = FieldWriter(folder / "fields", grid, args.save_fields, exact, settings.basis)
    with compile_notice(not args.quiet):
        result = module.simulate(settings, progress=False if args.quiet else None, observer=writer)
    if writer is not None:
        writer.close(result.t, result.particles, result.nodal_mass, result.nodal_velocity)
    return result


def _record(folder: Path, problem: str, settings, cost, result, errors: dict, conservation: dict, csv_columns) -> dict:
    summary = {
        "problem": problem,
        "errors": errors,
        "conservation": conservation,
        "steps": result.steps,
        "particles": int(result.particles.n),
        "cells": int(result.grid.n_cells),
        "t": result.t,
        "dt_min": result.dt_min,
        "dt_max": result.dt_max,
        "wall_s": round(result.wall_s, 4),
        "kernel": result.kernel,
        "estimate": cost.as_dict(),
        "settings": settings.as_dict(),
        "versions": output.versions(),
    }
    output.write_atomic(folder / "particles.csv", output.particles_csv(result.particles, csv_columns))
    output.write_json(folder / "summary.json", summary)
    return summary


def _publishing(out: Path, args):
    return output.staged_dir(out, overwrite=args.overwrite or args.out is None)


def cmd_sod(args) -> dict:
    from mpm_fem.problems import sod

    settings, cost, out = _prepare(args, "sod", sod, sod.SodSettings)
    from mpm_fem.app import plots  # after the checks: matplotlib takes a while to import
    with _publishing(out, args) as folder:
        def exact(x, t):
            return dict(zip(("density", "velocity", "pressure"), sod.exact(settings, x, t), strict=True))

        result = _simulate(args, sod, settings, folder, sod.uniform_grid(*sod.DOMAIN, settings.h), exact)
        errors = sod.errors(settings, result)
        P = result.particles
        rho, u, p = sod.exact(settings, P.x, result.t)
        columns = {name: getattr(P, name) for name in output.PARTICLE_COLUMNS}
        summary = _record(folder, "sod", settings, cost, result, errors, sod.conservation(settings, result),
                          {**columns, "density_exact": rho})
        xe = np.linspace(*sod.DOMAIN, 2001)
        ex = dict(zip(("density", "velocity", "pressure"), sod.exact(settings, xe, result.t), strict=False))
        ex["internal energy"] = ex["pressure"] / ((settings.gamma - 1) * ex["density"])
        part = {"density": P.density, "velocity": P.velocity, "pressure": (settings.gamma - 1) * P.density * P.energy,
                "internal energy": P.energy}
        plots.profiles(folder / "profiles.png", xe, ex, P.x, part, result.grid.nodes,
                       {"density": result.nodal_density, "velocity": result.nodal_velocity},
                       title=f"Sod, MPM h={settings.h}, N_p={settings.ppc}, t={result.t:.3g}")
    e, energy = errors["density"], summary["conservation"]["relative_change"]["energy"]
    line = (f"sod h={settings.h} ppc={settings.ppc}: density L1 {e['particles']['L1']:.4g} (particles), "
            f"{e['nodes']['L1']:.4g} (nodes); energy change {energy:.2g}; {result.steps} steps in "
            f"{result.wall_s:.2f} s -> {out}")
    return {"summary": summary, "line": line}


def cmd_burgers(args) -> dict:
    from mpm_fem.problems import burgers

    settings, cost, out = _prepare(args, "burgers", burgers, burgers.BurgersSettings)
    from mpm_fem.app import plots  # after the checks: matplotlib takes a while to import
    solution = settings.exact
    with _publishing(out, args) as folder:
        result = _simulate(args, burgers, settings, folder, burgers.uniform_grid(*solution.domain, settings.h),
                           lambda x, t: {"velocity": solution.v(x, t)})
        errors = burgers.errors(settings, result)
        P = result.particles
        # Unit density, no energy or pressure: the meaningful columns only.
        columns = {"x": P.x, "volume": P.volume, "velocity": P.velocity, "velocity_exact": solution.v(P.x, result.t)}
        conservation = burgers.conservation(settings, result)
        summary = _record(folder, "burgers", settings, cost, result, errors, conservation, columns)
        xe = np.linspace(*solution.domain, 2001)
        plots.profiles(folder / "profiles.png", xe, {"velocity": solution.v(xe, result.t)}, P.x,
                       {"velocity": P.velocity}, result.grid.nodes, {"velocity": result.nodal_velocity},
                       title=f"Burgers ({settings.solution}), eps={settings.eps}, h={settings.h},\n"
                             f"{settings.acceleration} acceleration, t={result.t:.3g}")
    e = errors["velocity"]["particles"]
    line = (f"burgers {settings.solution} eps={settings.eps} h={settings.h} ({settings.acceleration}): velocity "
            f"L1 {e['L1']:.4g}, L2 {e['L2']:.4g}, max {e['max']:.4g}; {result.steps} steps in "
            f"{result.wall_s:.2f} s -> {out}")
    return {"summary": summary, "line": line}


def cmd_study(args) -> dict:
    return {"line": start_study(args.name, study_options(args))}


def cmd_reproduce(args) -> dict:
    from mpm_fem.app.report import reproduce

    path = reproduce(study_options(args))
    return {"line": f"report written to {path}"}


def cmd_method(args) -> dict:
    import importlib

    from mpm_fem.app.study import StudyOptions

    study = importlib.import_module("studies.method")  # the top layer, loaded by name (app.study)
    basis = inputs.extension("basis", args.basis)
    spec = inputs.ALIASES["basis"].get(args.basis, args.basis)  # studies.method resolves it in each worker
    options = StudyOptions(quick=not args.full, jobs=guard.cap_jobs(args.jobs), out=Path(args.out),
                           progress=False if args.quiet else None)
    if not args.quiet:
        print(f"method {basis}: {study.describe_estimate(basis, spec, options)}", file=sys.stderr)
    return {"line": f"verdicts written to {study.run(spec, options)}"}


COMMANDS = {"sod": cmd_sod, "burgers": cmd_burgers, "study": cmd_study, "reproduce": cmd_reproduce,
            "method": cmd_method, "plane": plane_cli.command}


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)

    def command():
        outcome = COMMANDS[args.command](args)
        if not getattr(args, "quiet", False) and outcome.get("line"):
            print(outcome["line"])

    return guard.exit_status(f"mpm-fem {args.command}", command)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
