"""``mpm-fem plane axis|vortex``: one 2D run from the command line, its errors and CFL number printed.

    mpm-fem plane axis   [--h 0.0625] [--ppc 2] [--basis p1|gimp|bspline|...] [--mass lumped|consistent|grid|fmpm2|...]
                         [--amplitude A] [--amplitude-y A_y] [--layout regular|jittered] [--seed K] [--cfl C]
                         [--flip ALPHA] [--projection mpm|exact] [--interpolation mpm|exact]
                         [--acceleration calculated|exact] [--refine K] [--T T] [--scheme usl|musl]
                         [--out DIR] [--vtu [EVERY]] [--overwrite] [--quiet] [--yes-long]
    mpm-fem plane vortex ...  (the same options but --amplitude-y)

Each option is a field of :class:`~mpm_fem.plane.run.PlaneSettings` with its default. The checks are
those of the Python entry points (:func:`mpm_fem.app.plane_api.checked`, the same one-line messages,
exit status 2), made before anything is allocated; the estimate (particles, steps, memory, time) is
printed first on stderr. A particle that inverts during the run ends it with one line naming the
step and the particle (exit status 1, as every failed run). The result line gives the particle
displacement's L2 and Linf errors at ``T``, the largest L2 over the steps, the nodal acceleration's
L2 error of the last step and the CFL number run. With ``--out DIR`` the run writes
``DIR/summary.json`` (errors, CFL, steps, estimate, settings, versions); with ``--vtu`` also the
particles and the grid as VTU files for ParaView (:mod:`mpm_fem.app.plane_fields`) at ``T`` (and every
``EVERY`` steps if given), into ``DIR`` (default ``runs/plane-<problem>-<settings hash>/``).
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

import mpm_fem.masses as masses
from mpm_fem.app import guard, output
from mpm_fem.app.compiling import compile_notice
from mpm_fem.app.guard import UsageError
from mpm_fem.core.step import ACCELERATIONS, INTERPOLATIONS, PROJECTIONS
from mpm_fem.plane.problems import LAYOUTS
from mpm_fem.plane.run import PROBLEMS, PlaneSettings
from mpm_fem.plane.step import SCHEMES

CHOICES = {"projection": PROJECTIONS, "interpolation": INTERPOLATIONS,
           "acceleration": ACCELERATIONS, "layout": LAYOUTS, "scheme": SCHEMES}
HELP = {
    "h": "cell size; must divide the domain ([0, 2] for axis, [-1.5, 1.5] for vortex)",
    "ppc": "particles per cell per axis (ppc x ppc in every cell)",
    "amplitude": "the solution's amplitude A (axis: 0 <= A pi < 1, default 1e-4; vortex: default 1, at which "
                 "every basis loses a particle before T (docs/method.md, 'The vortex at A = 1'); 0.01 runs to T)",
    "amplitude_y": "axis only: the y part's amplitude A_y (default A; 0 turns the y part off)",
    "basis": "the 1D basis of the tensor product: a registered name (p1 is mpm), an installed entry point's "
             "or package.module:Name; it must have a 2D form",
    "mass": f"grid mass, one of {', '.join(masses.names())} (lumped: row sums; consistent: the particle mass "
            "matrix, solved; grid: the grid basis's own mass rho0 int S_i S_j; fmpmK: FMPM(K), the truncated "
            "series of the full inverse; exact: the mass stage made exact)",
    "cfl": "CFL number dt c / h, c = sqrt(E / rho0), in (0, 1]; refused above the linearised step's limit "
           "(0.862 with the lumped mass and the mpm or gimp basis)",
    "seed": "random seed of the jittered layout",
    "layout": "particles in each cell: regular or jittered",
    "T": "final time (default: one period for axis, 1 for vortex)",
    "flip": "PIC/FLIP blend alpha in [0, 1]: 1 FLIP, 0 PIC",
    "projection": "particle-to-grid projection: MPM sums or exact integrals of the exact fields",
    "interpolation": "grid-to-particle interpolation: MPM sums or the exact fields",
    "acceleration": "nodal acceleration: calculated f_i / m_i or exact",
    "refine": "time stage: the time step divided by this integer",
    "quadrature": "order of the exact stages' reference quadrature",
    "scheme": "usl, or musl (the velocity gradient from re-projected velocities)",
}


def add_parser(sub) -> argparse.ArgumentParser:
    """Add ``plane`` to the subcommands ``sub`` of the ``mpm-fem`` parser."""
    plane = sub.add_parser("plane", help="one 2D run (axis-aligned solid or generalized vortex): errors, CFL, "
                           "optional VTU fields for ParaView",
                           description="One 2D MPM run of a neo-Hookean solid against its manufactured solution: "
                           "axis (the axis-aligned standing waves on the periodic square [0, 2)^2, one period) or "
                           "vortex (the generalized vortex's annulus, to T = 1). Prints the estimate first, then "
                           "the displacement and acceleration errors and the CFL number.")
    plane.add_argument("problem", choices=PROBLEMS, help="which 2D problem")
    for f in dataclasses.fields(PlaneSettings):
        if f.name == "problem":
            continue
        option, helps = f"--{f.name.replace('_', '-')}", f"{HELP.get(f.name, f.name)} (default: %(default)s)"
        if isinstance(f.default, bool):
            plane.add_argument(option, dest=f.name, action=argparse.BooleanOptionalAction, default=f.default,
                               help=helps)
            continue
        kind = {int: int, str: str}.get(type(f.default), float)  # a float, or None by default
        plane.add_argument(option, dest=f.name, type=kind, default=f.default, choices=CHOICES.get(f.name),
                           metavar=None if f.name in CHOICES else f.name.upper(), help=helps)
    plane.add_argument("--out", default=None, help="write summary.json (and the VTU files of --vtu) into this folder")
    plane.add_argument("--vtu", type=int, nargs="?", const=0, default=None, metavar="EVERY",
                       help="write the particles and the grid as VTU files for ParaView (with .pvd series) at T, "
                            "and every EVERY steps if given, into --out (default runs/plane-<problem>-<hash>/)")
    plane.add_argument("--overwrite", action="store_true", help="replace a non-empty --out whole")
    plane.add_argument("--yes-long", action="store_true",
                       help=f"run even if estimated over {guard.LONG_RUN_S / 3600:g} h")
    plane.add_argument("--quiet", action="store_true", help="no estimate or result line")
    return plane


def command(args) -> dict:
    """Run ``mpm-fem plane`` (module docstring): ``{"summary": ..., "line": ...}``."""
    from mpm_fem.app.plane_api import checked, grid_of
    from mpm_fem.plane.run import run, solution_of

    given = {f.name: getattr(args, f.name) for f in dataclasses.fields(PlaneSettings)
             if f.name != "problem" and getattr(args, f.name) != f.default}
    if args.vtu is not None and args.vtu < 0:
        raise UsageError(f"--vtu takes a step interval >= 1 (or none: at T only), got {args.vtu}")
    settings, cost = checked(args.problem, given, args.problem, args.yes_long, "--yes-long")
    out = None
    if args.out is not None or args.vtu is not None:
        out = Path(args.out or f"runs/plane-{args.problem}-{output.settings_hash(dataclasses.asdict(settings))}")
        try:
            output.check_run_dir(out, overwrite=args.overwrite or args.out is None)
        except (PermissionError, FileExistsError) as err:
            raise UsageError(str(err)) from None
    if not args.quiet:
        print(f"plane {args.problem}: {guard.describe(cost)} on the {cost.kernel} step", file=sys.stderr)
    if out is None:
        with compile_notice(not args.quiet):
            result = run(settings)
        return {"summary": _summary(settings, cost, result), "line": _line(result)}
    with output.staged_dir(out, overwrite=args.overwrite or args.out is None) as folder:
        writer = None
        if args.vtu is not None:
            from mpm_fem.app.plane_fields import PlaneFieldWriter

            writer = PlaneFieldWriter(folder, grid_of(settings), solution_of(settings), args.vtu)
        with compile_notice(not args.quiet):
            result = run(settings, observer=writer)
        if writer is not None:
            writer.close()
        summary = _summary(settings, cost, result)
        output.write_json(folder / "summary.json", summary)
    return {"summary": summary, "line": f"{_line(result)} -> {out}"}


def _summary(settings, cost, result) -> dict:
    return {"problem": settings.problem, "errors": result.errors, "cfl": result.cfl, "steps": result.steps,
            "dt": result.dt, "t": result.t, "particles": int(result.particles.n), "wall_s": round(result.wall_s, 4),
            "estimate": cost.as_dict(), "settings": dataclasses.asdict(settings), "versions": output.versions()}


def _line(result) -> str:
    s, e = result.settings, result.errors
    d = e["displacement"]["particles"]
    return (f"plane {s.problem} h={s.h:g} ppc={s.ppc} basis={s.basis} mass={s.mass}: displacement L2 {d['L2']:.4g}, "
            f"Linf {d['Linf']:.4g} (particles, t={result.t:.6g}), max L2 over the steps {d['L2_max']:.4g}; "
            f"acceleration L2 {e['acceleration']['nodes']['L2']:.4g} (nodes); cfl {result.cfl:.4g} "
            f"({result.steps} steps of dt={result.dt:.4g}) in {result.wall_s:.2f} s")
