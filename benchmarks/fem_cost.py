"""Cost of a step of viscous Burgers: the FEM baseline's numpy and compiled loops, and MPM beside FEM.

One run reports, on the Burgers study's meshes (rarefaction, eps = 0.045, the viscous step limit of
each method), per mesh:
  * the CPU time of one SSP-RK3 step of :func:`baselines.fem_burgers.solve` with the lumped and the
    consistent mass, numpy loop (``kernel="numpy"``) against the compiled one (``"fused"``), and
    their ratio;
  * the CPU time of one step of MPM on the same mesh (4 particles per cell, calculated acceleration,
    the fused compiled loop), its ratio to a compiled FEM step, and the ratio of whole runs to T
    (MPM and FEM take different steps: ``dt <= h^2 / (2 eps)`` times 0.5 and 0.3).
Times are CPU time of this process (``time.process_time``) of a run to ``--T`` after a warm-up run
that compiles; the machines are shared, and ratios in one run are the result.
Usage: ``python benchmarks/fem_cost.py [--T 0.05] [--finest 0.000625]``.
"""

from __future__ import annotations

import argparse
import time

from measured import add_markdown_option, measured_block  # benchmarks/measured.py, beside this script

from baselines import fem_burgers
from baselines.exact.burgers import make_solution
from mpm_fem.problems import burgers

H = (0.005, 0.0025, 0.00125, 0.000625)
EPS = 0.045


def _cpu(fn) -> float:
    start = time.process_time()
    fn()
    return time.process_time() - start


def fem_step(h: float, mass: str, kernel: str, T: float) -> tuple[float, int]:
    """CPU seconds per step and the step count of a FEM run to ``T``."""
    solution = make_solution("rarefaction", EPS)
    out = {}
    seconds = _cpu(lambda: out.setdefault("r", fem_burgers.solve(solution, h, T=T, mass=mass, kernel=kernel)))
    return seconds / out["r"].steps, out["r"].steps


def mpm_step(h: float, T: float) -> tuple[float, int]:
    """CPU seconds per step and the step count of an MPM run (the Burgers study's settings) to ``T``."""
    settings = burgers.BurgersSettings(h=h, T=T, eps=EPS, ppc=4, cfl=0.5)
    out = {}
    seconds = _cpu(lambda: out.setdefault("r", burgers.simulate(settings, progress=False)))
    return seconds / out["r"].steps, out["r"].steps


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--T", type=float, default=0.05, help="final time of each timed run (default 0.05)")
    parser.add_argument("--finest", type=float, default=H[-1], help="the finest mesh (default 0.000625)")
    add_markdown_option(parser)
    args = parser.parse_args()
    if not 0 < args.T <= 0.5:
        parser.error(f"--T must lie in (0, 0.5], got {args.T}")
    if not [h for h in H if h >= args.finest]:
        parser.error(f"--finest must be at most {H[0]}, got {args.finest}")
    with measured_block(args.markdown, "fem_cost"):
        _run(args)


def _run(args) -> None:
    meshes = [h for h in H if h >= args.finest]
    # compile first
    fem_step(H[0], "lumped", "fused", 0.01), fem_step(H[0], "consistent", "fused", 0.01), mpm_step(H[0], 0.01)
    print(f"viscous Burgers, rarefaction, eps = {EPS}, runs to T = {args.T}; CPU microseconds per step")
    print(f"{'h':>9} {'mass':>10} {'FEM numpy':>10} {'compiled':>9} {'speed-up':>8} {'MPM':>9} "
          f"{'MPM/FEM step':>12} {'MPM/FEM run':>11}")
    for h in meshes:
        mpm, mpm_steps = mpm_step(h, args.T)
        for mass in ("lumped", "consistent"):
            numpy_s, _ = fem_step(h, mass, "numpy", args.T)
            fused_s, fem_steps = fem_step(h, mass, "fused", args.T)
            print(f"{h:9.6f} {mass:>10} {1e6 * numpy_s:10.1f} {1e6 * fused_s:9.1f} {numpy_s / fused_s:7.1f}x "
                  f"{1e6 * mpm:9.1f} {mpm / fused_s:11.2f}x {mpm * mpm_steps / (fused_s * fem_steps):10.2f}x",
                  flush=True)


if __name__ == "__main__":
    main()
