"""Cost of one 2D MPM step (the compiled P1 step of ``mpm_fem.plane.fused``) as ratios, in one run.

The case: the axis-aligned solid (``baselines.exact.solids.AxisAligned``, A = 0.05) on the periodic
square ``[0, 2)^2``, 2 x 2 regular particles per cell (seeded cell by cell: sorted by cell), USL,
lumped mass, FLIP, the body force. At each particle count n_p (1e4 ... ``--max``) the batches of
these loops alternate (a load that comes and goes on a shared machine falls on all of them) and
the best batch of each is kept:

  * step     ``PlaneFused(grid, "mpm", reuse=True).step_with_grid``, one thread, the body force the
             compiled one of :mod:`mpm_fem.plane.forces` evaluated each step (what a run pays); also
             with the problem's numpy callable instead (``step, numpy force``);
  * passes   the same with the body force one array given for every step (the compiled passes alone);
  * anchor   ``benchmarks/plane_anchor.py``: the minimal compiled 2D P1 loop of the same physics, one
             thread, given the passes' body force (one array), and the step's (the compiled one);
  * 1D loop  the project's compiled 1D P1 loop of Sod's tube (``FusedStep.advance``, as
             ``benchmarks/step_cost.py`` runs it) at the same n_p (at the largest n_p only).

Printed: each loop's rate in particle-steps/s and the ratios: passes / anchor (target >= 0.6 at
1e6), step / anchor with the compiled force, 2D step / 1D loop (target >= 0.2), the log-log slope of the
step's time per step against n_p over n_p >= 1e4 (target 0.95 ... 1.05), and the wall-time
speed-up of two threads over one (``PlaneFused(threads=2)``, batches alternated; target >= 1.6).
Times are CPU time of this process (``time.process_time``) but the threads' (wall time). Usage:
``python benchmarks/plane_step.py [--max 1e6] [--repeat 3] [--no-threads] [--no-1d]``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from plane_anchor import PlaneAnchor  # benchmarks/plane_anchor.py, beside this script
from step_cost import interleaved  # benchmarks/step_cost.py

from mpm_fem.plane.forces import compiled_force
from mpm_fem.plane.fused import PlaneFused
from mpm_fem.plane.problems import start
from mpm_fem.plane.run import PlaneSettings, setup

PPC, AMPLITUDE, CFL = 2, 0.05, 0.25
ANCHOR_TARGET, ONE_D_TARGET, THREADS_TARGET, SLOPE_BAND = 0.6, 0.2, 1.6, (0.95, 1.05)
WORK = 2_000_000  # particle-steps per timed batch (at least 2 steps)
BATCH_MAX = 50  # steps per batch at most (the frozen body force drives the solid off its solution)


def cells_for(n_particles: int) -> int:
    """Cells per axis for about ``n_particles`` at ``PPC x PPC`` per cell."""
    return max(4, int(round(np.sqrt(n_particles / PPC**2))))


def case(cells: int):
    """The solution, grid, particles at t = 0 and dt of ``cells x cells`` cells."""
    s = PlaneSettings(h=2.0 / cells, ppc=PPC, amplitude=AMPLITUDE, cfl=CFL)
    solution, grid, (X, V0, lengths), _ = setup(s)
    dt = CFL * min(grid.h) / solution.material.c
    return solution, grid, start(solution, X, V0, lengths, dt), dt


def step_batches(cells: int, batch: int, force: str, threads: int = 1):
    """A batch of ``batch`` compiled steps (``reuse``: the state in two sets of arrays), each call
    continuing from the last, with the body force ``force``: ``compiled`` (:mod:`mpm_fem.plane.forces`),
    ``numpy`` (the solution's callable) or ``frozen`` (one array, of t = 0, for every step)."""
    solution, grid, state, dt = case(cells)
    fused = PlaneFused(grid, "mpm", threads, reuse=True)
    force = _force(solution, state.X[:, 0], state.X[:, 1], force)
    current = [state, 0]

    def loop():
        p, k = current
        for _ in range(batch):
            p = fused.step(p, solution.material, dt, k * dt, force)
            k += 1
        current[:] = [p, k]

    loop()  # compile (or load the cache) and touch the buffers
    return loop, state.n


def _force(solution, X, Y, kind: str):
    if kind == "numpy":
        return solution.body_force
    if kind == "compiled":
        return compiled_force(solution)
    b0 = np.asarray(solution.body_force(X, Y, 0.0))
    return lambda X, Y, t: b0


def anchor_batches(cells: int, batch: int, force: str):
    """A batch of ``batch`` steps of the anchor with the body force ``force`` (as :func:`step_batches`')."""
    anchor = PlaneAnchor(cells, PPC, AMPLITUDE, cfl=CFL)
    force = _force(anchor.solution, anchor.X, anchor.Y, force)
    anchor.advance(1, force)
    return (lambda: anchor.advance(batch, force)), anchor.n


def one_d_loop(n_particles: int, batch: int):
    """The 1D P1 loop of ``benchmarks/step_cost.py`` at about ``n_particles``: a batch callable and n_p."""
    from step_cost import loop_batches
    from step_cost import setup as sod_setup

    from mpm_fem.core.step import Stages, Walls
    from mpm_fem.fused.step import FusedStep
    from mpm_fem.run.solve import Problem

    grid, particles, gas, dt = sod_setup(n_particles)
    problem = Problem(model=gas, boundary=Walls(), T=1e9, cfl=1.0, dt=dt)
    fused = FusedStep(grid, gas, Walls(), Stages(basis="mpm"), reuse=True)
    return loop_batches(fused, particles, problem, batch), particles.n


def measure(n_particles: int, repeat: int, one_d: bool) -> dict:
    cells = cells_for(n_particles)
    batch = max(2, min(BATCH_MAX, WORK // (cells * cells * PPC**2)))
    loops = [step_batches(cells, batch, "compiled"), step_batches(cells, batch, "frozen"),
             anchor_batches(cells, batch, "frozen"), anchor_batches(cells, batch, "compiled"),
             step_batches(cells, batch, "numpy")]
    if one_d:
        loops.append(one_d_loop(n_particles, batch))
    best = interleaved([fn for fn, _ in loops], repeat)
    rates = [n * batch / s for (_, n), s in zip(loops, best, strict=True)]
    return {"n_p": loops[0][1], "cells": cells, "step_s": best[0] / batch, "step": rates[0], "passes": rates[1],
            "anchor": rates[2], "anchor_force": rates[3], "numpy_force": rates[4],
            "one_d": rates[5] if one_d else np.nan}


def threads_ratio(n_particles: int, repeat: int) -> float:
    """Wall time of the one-thread step over the two-thread step (passes; batches alternated)."""
    cells = cells_for(n_particles)
    batch = max(2, min(BATCH_MAX, WORK // (cells * cells * PPC**2)))
    one, two = interleaved([step_batches(cells, batch, "frozen", k)[0] for k in (1, 2)], repeat, time.perf_counter)
    return one / two


def slope(rows) -> float:
    n = np.array([r["n_p"] for r in rows], float)
    t = np.array([r["step_s"] for r in rows])
    keep = n >= 1e4
    return float(np.polyfit(np.log(n[keep]), np.log(t[keep]), 1)[0]) if keep.sum() >= 2 else float("nan")


def sizes(smallest: float, largest: float) -> list[int]:
    """Particle counts from ``smallest`` to ``largest``, three per decade."""
    k = np.arange(np.log10(smallest), np.log10(largest) + 1e-9, 1 / 2)
    return [int(round(10**e)) for e in k]


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max", type=float, default=1e6, help="largest particle count (default 1e6)")
    parser.add_argument("--min", type=float, default=1e4, help="smallest particle count (default 1e4)")
    parser.add_argument("--repeat", type=int, default=3, help="timed batches per loop; the best is kept")
    parser.add_argument("--no-threads", action="store_true", help="skip the two-thread measurement")
    parser.add_argument("--no-1d", action="store_true", help="skip the 1D loop")
    args = parser.parse_args(argv)
    if not (1e2 <= args.min <= args.max):
        parser.error(f"need 1e2 <= --min <= --max, got {args.min:g}, {args.max:g}")
    counts = sizes(args.min, args.max)
    rows = [measure(n, args.repeat, one_d=(not args.no_1d and n == counts[-1])) for n in counts]
    print("| particles | cells | step, particle-steps/s | passes | anchor (passes' force) | anchor (step's force) "
          "| step, numpy force | passes / anchor | step / anchor | step / passes | numpy force / step |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for r in rows:
        print(f"| {r['n_p']:.2e} | {r['cells']}^2 | {r['step']:.3g} | {r['passes']:.3g} | {r['anchor']:.3g} | "
              f"{r['anchor_force']:.3g} | {r['numpy_force']:.3g} | {r['passes'] / r['anchor']:.2f} | "
              f"{r['step'] / r['anchor_force']:.2f} | {r['step'] / r['passes']:.2f} | "
              f"{r['numpy_force'] / r['step']:.2f} |")
    top = rows[-1]
    s = slope(rows)
    ratio = np.nan if args.no_threads else threads_ratio(top["n_p"], args.repeat)
    verdict = lambda ok: "met" if ok else "NOT met"  # noqa: E731
    lines = [f"passes / anchor at {top['n_p']:.1e}: {top['passes'] / top['anchor']:.2f} "
             f"(target >= {ANCHOR_TARGET}: {verdict(top['passes'] / top['anchor'] >= ANCHOR_TARGET)})",
             f"step / anchor, both with the compiled body force: {top['step'] / top['anchor_force']:.2f}"]
    if not args.no_1d:
        lines += [f"1D P1 loop at {top['n_p']:.1e}: {top['one_d']:.3g} particle-steps/s",
                  f"2D step / 1D loop: {top['step'] / top['one_d']:.2f} (target >= {ONE_D_TARGET}: "
                  f"{verdict(top['step'] / top['one_d'] >= ONE_D_TARGET)}); 2D passes / 1D loop: "
                  f"{top['passes'] / top['one_d']:.2f}"]
    lines.append(f"slope of the step's time against n_p (n_p >= 1e4): {s:.2f} (target {SLOPE_BAND[0]} ... "
                 f"{SLOPE_BAND[1]}: {verdict(SLOPE_BAND[0] <= s <= SLOPE_BAND[1])})")
    if not args.no_threads:
        lines.append(f"2 threads / 1 thread (passes, wall time) at {top['n_p']:.1e}: {ratio:.2f} "
                     f"(target >= {THREADS_TARGET}: {verdict(ratio >= THREADS_TARGET)})")
    print("\nTargets:\n" + "\n".join(f"- {line}" for line in lines))


if __name__ == "__main__":
    main()
