"""The ``mpm-fem`` command line.

    mpm-fem sod      [--h 0.01] [--ppc 4] [--T 0.2] [--cfl C] [--mass lumped|consistent] [--basis mpm|gimp] ...
    mpm-fem burgers  [--h 0.01] [--eps 0.045] [--acceleration exact|calculated] [--solution NAME] ...

Each option's default is the field default of the problem's settings dataclass (one place).
Bad input ends with a one-line message and exit status 2; a run that fails (lost positivity)
with a one-line message and exit status 1.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

import numpy as np

from . import output, plots
from .grid import GridError
from .particles import LAYOUTS, PositivityError
from .shape import BASES
from .step import ACCELERATIONS, INTERPOLATIONS, PROJECTIONS, SCHEMES, STAGE_MASS
from .reconstruction import RECONSTRUCTIONS
from .volume import VOLUMES

CHOICES = {"mass": STAGE_MASS, "basis": BASES, "scheme": SCHEMES, "layout": LAYOUTS, "acceleration": ACCELERATIONS,
           "projection": PROJECTIONS, "interpolation": INTERPOLATIONS}
# --- remedies (E5): --flip ALPHA, --reconstruct none|taylor, --volume carried|grid, --basis bspline_gimp
CHOICES.update({"reconstruct": RECONSTRUCTIONS, "volume": VOLUMES})
REMEDY_HELP = {
    "flip": "PIC/FLIP blend alpha in [0, 1]: 1 FLIP (standard), 0 PIC",
    "reconstruct": "stress before the force integral: none (particle sum) or taylor (per-cell least-squares line)",
    "volume": "particle volumes: carried by the flow, or grid (reset to tile the grid every step)",
}
HELP = {
    "h": "cell size (must divide the domain)",
    "ppc": "particles per cell N_p",
    "T": "final time",
    "cfl": "CFL number in (0, 1]",
    "gamma": "ratio of specific heats",
    "av_linear": "artificial viscosity, linear coefficient",
    "av_quadratic": "artificial viscosity, quadratic coefficient",
    "mass": "grid mass matrix; exact: the FE + mass lumping stage made exact (error budget)",
    "projection": "particle-to-grid projection: MPM sums or exact integrals of the exact fields",
    "interpolation": "grid-to-particle interpolation: MPM sums or exact for the exact fields",
    "refine": "time stage: the time step divided by this integer",
    "basis": "particle basis: point mass (mpm), particle domain (gimp), quadratic B-spline (bspline) or the "
             "B-spline averaged over the particle domain (bspline_gimp)",
    "scheme": "stress update order",
    "layout": "initial particle layout in each cell",
    "seed": "random seed of jittered/random layouts",
    "eps": "viscosity eps > 0",
    "solution": "exact solution giving initial, boundary data and errors",
    "acceleration": "nodal acceleration: calculated F_i/m_i or the exact eps v_xx",
}
HELP.update(REMEDY_HELP)


class UsageError(Exception):
    """Bad input: reported on one line, exit status 2."""


def _add_settings_options(parser: argparse.ArgumentParser, settings_cls, extra_choices=None) -> None:
    choices = {**CHOICES, **(extra_choices or {})}
    for f in dataclasses.fields(settings_cls):
        if isinstance(f.default, tuple):
            continue  # initial states stay in the settings JSON, not on the command line
        kind = type(f.default)
        parser.add_argument(
            f"--{f.name.replace('_', '-')}",
            dest=f.name,
            type=kind,
            default=f.default,
            choices=choices.get(f.name),
            metavar=None if f.name in choices else f.name.upper(),
            help=f"{HELP.get(f.name, f.name)} (default: %(default)s)",
        )
    parser.add_argument("--out", default=None, help="output directory (default: runs/<problem>-<settings hash>/)")
    parser.add_argument("--save-fields", type=int, nargs="?", const=20, default=None, metavar="EVERY",
                        help="write particle and grid fields every EVERY steps (default 20) as VTU files with a "
                             ".pvd time series for ParaView, into DIR/fields/")
    parser.add_argument("--quiet", action="store_true", help="no progress bar and no summary line")


def build_parser() -> argparse.ArgumentParser:
    from baselines.exact.burgers import SOLUTIONS

    from .problems.burgers import BurgersSettings
    from .problems.sod import SodSettings

    parser = argparse.ArgumentParser(
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
    _add_settings_options(burgers, BurgersSettings, {"solution": tuple(SOLUTIONS)})

    from studies import STUDIES

    study = sub.add_parser("study", help="run one study: tables and figures into figures/<name>/",
                           description="Run one study of the error analysis; results are cached per case.")
    study.add_argument("name", choices=STUDIES, help="which study")
    _add_study_options(study)
    reproduce = sub.add_parser("reproduce", help="run every study and write figures/REPORT.md",
                               description="Regenerate every table and figure and figures/REPORT.md.")
    size = reproduce.add_mutually_exclusive_group()
    size.add_argument("--quick", dest="quick", action="store_true", default=True,
                      help="a subset of meshes, a few minutes on 2 cores (default)")
    size.add_argument("--full", dest="quick", action="store_false", help="every mesh of every study")
    _add_study_options(reproduce, quick_flag=False,
                       out_help="figures folder (default: figures/quick with --quick, figures with --full)")
    return parser


def _add_study_options(parser: argparse.ArgumentParser, quick_flag: bool = True, out_help: str | None = None) -> None:
    if quick_flag:
        parser.add_argument("--quick", action="store_true", help="the subset of meshes of the quick reproduction")
    parser.add_argument("--jobs", type=int, default=None, help="worker processes (default: the number of cores)")
    parser.add_argument("--scheduler", default=None, help="address of a running Dask scheduler, tcp://HOST:PORT")
    parser.add_argument("--out", default=None, help=out_help or "figures folder (default: figures, or figures/quick with --quick)")
    parser.add_argument("--quiet", action="store_true", help="no progress output")


def _settings(cls, args):
    values = {f.name: getattr(args, f.name) for f in dataclasses.fields(cls) if hasattr(args, f.name)}
    try:
        return cls(**values)
    except (ValueError, GridError) as err:
        raise UsageError(str(err)) from None


def _out_dir(args, problem: str, settings) -> Path:
    out = args.out or f"runs/{problem}-{output.settings_hash(settings.as_dict())}"
    try:
        return output.ensure_writable_dir(out)
    except PermissionError as err:
        raise UsageError(str(err)) from None


def _field_writer(args, out: Path, grid):
    if args.save_fields is None:
        return None
    if args.save_fields < 1:
        raise UsageError(f"--save-fields takes a step interval >= 1, got {args.save_fields}")
    from .fields import FieldWriter

    return FieldWriter(out / "fields", grid, args.save_fields)


def _record(out: Path, problem: str, settings, result, errors: dict, extra_csv=None) -> dict:
    summary = {
        "problem": problem,
        "errors": errors,
        "steps": result.steps,
        "particles": int(result.particles.n),
        "cells": int(result.grid.n_cells),
        "t": result.t,
        "dt_min": result.dt_min,
        "dt_max": result.dt_max,
        "wall_s": round(result.wall_s, 4),
        "settings": settings.as_dict(),
        "versions": output.versions(),
    }
    output.write_atomic(out / "particles.csv", output.particles_csv(result.particles, extra_csv))
    output.write_json(out / "summary.json", summary)
    return summary


def cmd_sod(args) -> dict:
    from .problems import sod

    settings = _settings(sod.SodSettings, args)
    out = _out_dir(args, "sod", settings)
    writer = _field_writer(args, out, sod.uniform_grid(*sod.DOMAIN, settings.h))
    result = sod.simulate(settings, progress=False if args.quiet else None, observer=writer)
    if writer is not None:
        writer.close(result.t, result.particles)
    errors = sod.errors(settings, result)
    rho, u, p = sod.exact(settings, result.particles.x, result.t)
    summary = _record(out, "sod", settings, result, errors, {"density_exact": rho})
    xe = np.linspace(0, 1, 2001)
    ex = dict(zip(("density", "velocity", "pressure"), sod.exact(settings, xe, result.t)))
    ex["internal energy"] = ex["pressure"] / ((settings.gamma - 1) * ex["density"])
    P = result.particles
    part = {"density": P.density, "velocity": P.velocity, "pressure": (settings.gamma - 1) * P.density * P.energy,
            "internal energy": P.energy}
    plots.profiles(out / "profiles.png", xe, ex, P.x, part, result.grid.nodes,
                   {"density": result.nodal_density, "velocity": result.nodal_velocity},
                   title=f"Sod, MPM h={settings.h}, N_p={settings.ppc}, t={result.t:.3g}")
    e = errors["density"]
    line = (f"sod h={settings.h} ppc={settings.ppc}: density L1 {e['particles']['L1']:.4g} (particles), "
            f"{e['nodes']['L1']:.4g} (nodes); {result.steps} steps in {result.wall_s:.2f} s -> {out}")
    return {"summary": summary, "line": line}


def cmd_burgers(args) -> dict:
    from .problems import burgers

    settings = _settings(burgers.BurgersSettings, args)
    out = _out_dir(args, "burgers", settings)
    writer = _field_writer(args, out, burgers.uniform_grid(*settings.exact.domain, settings.h))
    result = burgers.simulate(settings, progress=False if args.quiet else None, observer=writer)
    if writer is not None:
        writer.close(result.t, result.particles)
    errors = burgers.errors(settings, result)
    solution = settings.exact
    summary = _record(out, "burgers", settings, result, errors, {"velocity_exact": solution.v(result.particles.x, result.t)})
    xe = np.linspace(*solution.domain, 2001)
    plots.profiles(out / "profiles.png", xe, {"velocity": solution.v(xe, result.t)}, result.particles.x,
                   {"velocity": result.particles.velocity}, result.grid.nodes, {"velocity": result.nodal_velocity},
                   title=f"Burgers ({settings.solution}), eps={settings.eps}, h={settings.h}, {settings.acceleration} acceleration")
    e = errors["velocity"]["particles"]
    line = (f"burgers {settings.solution} eps={settings.eps} h={settings.h} ({settings.acceleration}): velocity "
            f"L1 {e['L1']:.4g}, L2 {e['L2']:.4g}, max {e['max']:.4g}; {result.steps} steps in {result.wall_s:.2f} s -> {out}")
    return {"summary": summary, "line": line}


def _study_options(args):
    from .study import StudyOptions

    if args.jobs is not None and args.jobs < 1:
        raise UsageError(f"--jobs must be >= 1, got {args.jobs}")
    out = args.out or ("figures/quick" if args.quick else "figures")
    try:
        out = output.ensure_writable_dir(out)
    except PermissionError as err:
        raise UsageError(str(err)) from None
    return StudyOptions(quick=args.quick, jobs=args.jobs, scheduler=args.scheduler, out=out,
                        progress=False if args.quiet else None)


def cmd_study(args) -> dict:
    import importlib

    options = _study_options(args)
    module = importlib.import_module(f"studies.{args.name}")
    module.run(options)
    return {"line": f"study {args.name} written to {options.folder(args.name)}"}


def cmd_reproduce(args) -> dict:
    from .report import reproduce

    options = _study_options(args)
    path = reproduce(options)
    return {"line": f"report written to {path}"}


COMMANDS = {"sod": cmd_sod, "burgers": cmd_burgers, "study": cmd_study, "reproduce": cmd_reproduce}


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        outcome = COMMANDS[args.command](args)
    except UsageError as err:
        print(f"mpm-fem {args.command}: error: {err}", file=sys.stderr)
        return 2
    except (PositivityError, FloatingPointError, RuntimeError) as err:
        print(f"mpm-fem {args.command}: run failed: {err}", file=sys.stderr)
        return 1
    if not getattr(args, "quiet", False) and outcome.get("line"):
        print(outcome["line"])
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
