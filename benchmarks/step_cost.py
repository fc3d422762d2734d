"""Cost of one MPM step of Sod's tube, numpy against fused, as the particle count grows.

One run reports, for each basis (point mass, GIMP, B-spline, the particle-domain B-spline; USL,
lumped mass, 4 particles per cell) at n_p = 1e3 ... 1e7:
  * particle-steps per second of the numpy step (``mpm_fem.core.step.explicit_step``), of the fused
    step called once per step (``mpm_fem.fused.step.FusedStep.step``, one thread) and of the fused
    step's compiled loop (``FusedStep.advance``, which ``solve.run`` takes between walls with the
    lumped mass), and their ratios to the numpy step;
  * the log-log slope of step time against n_p (n_p >= 1e4; 1.0 = linear);
  * bytes per particle held by a run: the caller's particles plus the loop's two sets of particle
    arrays and its scratch (the per-step buffers are freed when the loop starts);
  * the machine's triad bandwidth (numpy ``a = b + s c`` on 2e7 doubles, counted as 24 B per
    element as STREAM does) and the fused step as a fraction of the bound ``bandwidth / (bytes
    moved per particle-step)``;
  * the speed-up of ``threads=2`` over one thread (wall time of the compiled loop, batches alternated);
  * the anchor (``benchmarks/anchor.py``, the bare P1 Sod loop written for speed) at the
    same particle counts, and each basis's fused loop as a fraction of it; and the sweep's gain,
    the loop over the same loop with pass 2 and the next pass 1 apart (``FusedStep(sweep=False)``,
    the loop before the sweep of 2026-11-28): the three loops' batches alternate (loop, loop apart, anchor, loop,
    ...) in the same run, the best batch of each is kept, and the ratios, not wall times, are the
    result.
Times are the best of ``--repeat`` steps, as CPU time of this process (``time.process_time``):
the machines are shared, and CPU time is what a loaded machine gives the step. Ratios in one run
are the result. Usage: ``python benchmarks/step_cost.py [--max 1e7] [--repeat 3] [--bases mpm,gimp]
[--no-threads]``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from anchor import Anchor  # benchmarks/anchor.py, beside this script
from measured import add_markdown_option, measured_block  # benchmarks/measured.py

from mpm_fem.bases import names
from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.models.euler import IdealGas
from mpm_fem.core.step import Stages, Walls, explicit_step
from mpm_fem.fused.step import FusedStep
from mpm_fem.problems.sod import SodSettings, initial_particles
from mpm_fem.run.solve import Problem

BASES = names()  # every registered basis
# particle-steps/s of the fused loop at 1e6 particles, one thread (uniform-grid arithmetic in every basis)
RATE_TARGETS = {"mpm": 3e7, "gimp": 2e7, "bspline": 2.5e7, "bspline_gimp": 1e7, "cubic": 2e7}
PPC = 4
BATCH_MIN = 20  # the fewest steps of a timed loop call
SWEEP_GAIN_TARGET = 2.0  # the sweep's target: every basis's loop at least twice as fast as with pass 2 and 1 apart
ANCHOR_TARGET = 0.6  # P1's loop at least this fraction of the anchor's rate
THREADS_TARGET = 1.8  # two threads over one
ANCHOR_BYTES = 6 * 8 + 5 * 8  # the anchor reads x, v, rho, eps, s, m and writes all but m
STATE_FIELDS = ("x", "volume", "mass", "velocity", "density", "energy", "pressure")


def bytes_moved(basis: str) -> int:
    """Bytes the fused USL gas step reads and writes per particle (write-allocate not counted).

    Pass 1 reads x, V, m, v, p (40 B) and writes the cell (a 4-byte index); pass 2 reads x, v, rho,
    eps, p, m (48 B) and writes x, v, rho, eps, p, V (48 B). The particle-domain bases also store
    their rows (node index, S, G: 4 + 8 + 8 B per node; GIMP 3 nodes, the particle-domain B-spline
    5) in pass 1 and read them back in pass 2.
    """
    return 40 + 4 + 48 + 48 + 2 * 20 * {"gimp": 3, "bspline_gimp": 5}.get(basis, 0)


def triad_bandwidth(n: int = 20_000_000, repeat: int = 5) -> float:
    """STREAM triad ``a = b + s c`` with numpy (in place, no temporaries): bytes/s, 24 B per element."""
    b, c, a = np.random.default_rng(0).random(n), np.random.default_rng(1).random(n), np.empty(n)
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        np.multiply(c, 3.0, out=a)
        np.add(a, b, out=a)
        best = min(best, time.perf_counter() - t0)
    return 24.0 * n / best


def best_time(fn, repeat: int, clock=time.process_time) -> float:
    times = []
    for _ in range(repeat):
        t0 = clock()
        fn()
        times.append(clock() - t0)
    return min(times)


def interleaved(fns, repeat: int, clock=time.process_time) -> list[float]:
    """The best time of each of ``fns``, called in turn ``repeat`` times (a, b, a, b, ...): a load
    that comes and goes on a shared machine falls on both."""
    best = [np.inf] * len(fns)
    for _ in range(repeat):
        for k, fn in enumerate(fns):
            t0 = clock()
            fn()
            best[k] = min(best[k], clock() - t0)
    return best


def anchor_loop(n_particles: int, batch: int):
    """A batch of ``batch`` steps of the anchor on Sod's data at ``n_particles`` (4 per cell, CFL
    0.1, no final time), compiled and one step taken; each call continues from the last."""
    anchor = Anchor(max(2, n_particles // PPC), PPC, T=1e9)
    anchor.advance(1)

    def loop():
        done = anchor.advance(batch)
        assert done == batch, f"the anchor stopped after {done} of {batch} steps"

    return loop, anchor.n


def setup(n_particles: int):
    n_cells = max(2, n_particles // PPC)
    h = 1.0 / n_cells
    grid = uniform_grid(0.0, 1.0, h)
    particles = initial_particles(SodSettings(h=h, ppc=PPC), grid)
    gas = IdealGas()
    return grid, particles, gas, 0.1 * gas.stable_dt(particles, grid, 1.0)


def loop_batches(fused: FusedStep, particles, problem, batch: int):
    """A batch of ``batch`` steps of ``fused``'s compiled loop, compiled and one step taken; each call
    continues from the particles the loop returned last (no copy)."""
    current = [fused.advance(particles, 0.0, problem, 1, 10**9, 1)[0]]  # compile, copy the particles in

    def loop():
        current[0], _, done, _, _ = fused.advance(current[0], 0.0, problem, 1, 10**9, batch)
        assert done == batch, f"the loop stopped after {done} of {batch} steps"

    return loop


def measure(basis: str, n_particles: int, repeat: int, numpy_too: bool = True) -> dict:
    grid, particles, gas, dt = setup(n_particles)
    stages = Stages(basis=basis)
    fused = FusedStep(grid, gas, Walls(), stages, reuse=True)
    fused.step(particles, 0.0, dt)  # compile (or load the cache) and fill the buffers
    fused_s = best_time(lambda: fused.step(particles, 0.0, dt), repeat)
    problem = Problem(model=gas, boundary=Walls(), T=1e9, cfl=1.0, dt=dt)  # T never reached
    # steps per timed loop: a loop call's first pass 1 and its Python are a few per cent of a batch
    batch = max(BATCH_MIN, min(200, 20_000_000 // particles.n))
    loop = loop_batches(fused, particles, problem, batch)
    apart = loop_batches(FusedStep(grid, gas, Walls(), stages, reuse=True, sweep=False), particles, problem, batch)
    anchor, n_anchor = anchor_loop(n_particles, batch)
    loop_s, apart_s, anchor_s = (b / batch for b in interleaved([loop, apart, anchor], repeat))
    numpy_s = best_time(lambda: explicit_step(grid, particles, gas, Walls(), 0.0, dt, stages),
                        repeat if n_particles <= 10**6 else 1) if numpy_too else np.nan
    n = particles.n
    held = sum(getattr(particles, f).nbytes for f in STATE_FIELDS)  # the caller's particles, and the
    held += fused._state.nbytes + sum(a.nbytes for a in fused._scratch)  # loop's two sets and scratch
    return {"basis": basis, "n_p": n, "numpy_s": numpy_s, "fused_s": fused_s, "loop_s": loop_s,
            "numpy_rate": n / numpy_s, "fused_rate": n / fused_s, "loop_rate": n / loop_s,
            "apart_rate": n / apart_s, "sweep_gain": apart_s / loop_s,
            "bytes_per_particle": held / n, "anchor_rate": n_anchor / anchor_s,
            "of_anchor": (n / loop_s) / (n_anchor / anchor_s)}


def threads_ratio(basis: str, n_particles: int, repeat: int) -> float:
    """Wall time of the one-thread loop over the two-thread loop (their batches alternated; the swept
    loop on both)."""
    grid, particles, gas, dt = setup(n_particles)
    problem = Problem(model=gas, boundary=Walls(), T=1e9, cfl=1.0, dt=dt)  # T never reached
    batch = max(BATCH_MIN, min(200, 20_000_000 // particles.n))
    loops = [loop_batches(FusedStep(grid, gas, Walls(), Stages(basis=basis), threads=k, reuse=True), particles,
                          problem, batch) for k in (1, 2)]
    one, two = interleaved(loops, repeat, time.perf_counter)
    return one / two


def slope(rows, key):
    n = np.array([r["n_p"] for r in rows], float)
    t = np.array([r[key] for r in rows])
    keep = (n >= 1e4) & np.isfinite(t)
    return np.polyfit(np.log(n[keep]), np.log(t[keep]), 1)[0] if keep.sum() >= 2 else float("nan")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max", type=float, default=1e7, help="largest particle count (default 1e7)")
    parser.add_argument("--repeat", type=int, default=3, help="timed steps per size; the best is kept")
    parser.add_argument("--bases", default=",".join(BASES), help="comma-separated bases (default: all registered)")
    parser.add_argument("--no-threads", action="store_true", help="skip the two-thread measurement")
    add_markdown_option(parser)
    args = parser.parse_args(argv)
    args.bases = [b.strip() for b in args.bases.split(",") if b.strip()]
    unknown = sorted(set(args.bases) - set(BASES))
    if unknown or not args.bases:
        parser.error(f"unknown bases {unknown}; choose from {', '.join(BASES)}")
    with measured_block(args.markdown, "step_cost"):
        _run(args)


def _run(args) -> None:
    sizes = [int(10**k) for k in range(3, int(round(np.log10(args.max))) + 1)]
    bandwidth = triad_bandwidth()
    print(f"triad bandwidth (numpy a = b + s c, 24 B/element): {bandwidth / 1e9:.1f} GB/s\n")
    print("| basis | particles | numpy particle-steps/s | fused step, particle-steps/s | fused loop, particle-steps/s "
          "| loop without the sweep | sweep gain | step / numpy | loop / numpy | anchor, particle-steps/s "
          "| loop / anchor | bytes per particle (state + buffers) |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    summary = []
    for basis in args.bases:
        rows = [measure(basis, n, args.repeat) for n in sizes]
        for r in rows:
            print(f"| {basis} | {r['n_p']:.0e} | {r['numpy_rate']:.3g} | {r['fused_rate']:.3g} | "
                  f"{r['loop_rate']:.3g} | {r['apart_rate']:.3g} | {r['sweep_gain']:.2f} | "
                  f"{r['fused_rate'] / r['numpy_rate']:.1f} | {r['loop_rate'] / r['numpy_rate']:.1f} | "
                  f"{r['anchor_rate']:.3g} | {r['of_anchor']:.2f} | {r['bytes_per_particle']:.0f} |")
        at = next((r for r in rows if r["n_p"] == 10**6), rows[-1])
        summary.append((basis, at, slope(rows, "loop_s"), slope(rows, "numpy_s")))
    print("\n| basis | fused loop at 1e6, particle-steps/s | sweep gain | loop / anchor | loop / numpy | slope loop | "
          "slope numpy | bytes moved per particle-step | bandwidth bound, particle-steps/s | fraction of the bound | "
          "2 threads / 1 thread (loop) |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    verdicts = []
    anchors = []
    for basis, at, s_fused, s_numpy in summary:
        moved = bytes_moved(basis)
        bound = bandwidth / moved
        ratio = np.nan if args.no_threads else threads_ratio(basis, at["n_p"], args.repeat)
        speedup = at["loop_rate"] / at["numpy_rate"]
        anchors.append(at["anchor_rate"])
        print(f"| {basis} | {at['loop_rate']:.3g} | {at['sweep_gain']:.2f} | {at['of_anchor']:.2f} | {speedup:.1f} | "
              f"{s_fused:.2f} | {s_numpy:.2f} | {moved} | {bound:.3g} | {at['loop_rate'] / bound:.2f} | {ratio:.2f} |")
        rate_target = RATE_TARGETS[basis]
        verdicts.append(f"{basis}: {at['loop_rate']:.3g} particle-steps/s at {at['n_p']:.0e} "
                        f"(target >= {rate_target:.0e}: {'met' if at['loop_rate'] >= rate_target else 'NOT met'})")
        if basis == "mpm":
            met = "met" if speedup >= 5 else "NOT met"
            verdicts.append(f"mpm: fused loop / numpy {speedup:.1f} (target >= 5: {met})")
        met = "met" if abs(s_fused - 1) <= 0.1 else "NOT met"
        verdicts.append(f"{basis}: slope {s_fused:.2f} (target 1.0 +- 0.1: {met})")
        held = at["bytes_per_particle"]
        verdicts.append(f"{basis}: {held:.0f} B per particle (target <= 250: {'met' if held <= 250 else 'NOT met'})")
        gain = at["sweep_gain"]
        verdicts.append(f"{basis}: loop / loop without the sweep {gain:.2f} (target: >= {SWEEP_GAIN_TARGET:g}: "
                        f"{'met' if gain >= SWEEP_GAIN_TARGET else 'NOT met'})")
        if basis == "mpm":
            verdicts.append(f"mpm: loop / anchor {at['of_anchor']:.2f} (target: >= {ANCHOR_TARGET:g}: "
                            f"{'met' if at['of_anchor'] >= ANCHOR_TARGET else 'NOT met'})")
        if not args.no_threads:
            verdicts.append(f"{basis}: 2 threads / 1 thread {ratio:.2f} (target: >= {THREADS_TARGET:g}: "
                            f"{'met' if ratio >= THREADS_TARGET else 'NOT met'})")
    moved = ANCHOR_BYTES
    print(f"| anchor (benchmarks/anchor.py, P1) | {np.median(anchors):.3g} | | 1.00 | | | | {moved} | "
          f"{bandwidth / moved:.3g} | {np.median(anchors) / (bandwidth / moved):.2f} | |")
    print(f"\nThe anchor row: the median of its {len(anchors)} measurements at {summary[0][1]['n_p']:.0e} "
          f"particles (one beside each basis; {min(anchors):.3g} ... {max(anchors):.3g} particle-steps/s); "
          "each basis's fraction is taken against the anchor measured beside it.")
    print("\nTargets:\n" + "\n".join(f"- {v}" for v in verdicts))


if __name__ == "__main__":
    main()
