"""The deep tier's longest swept case, run two ways side by side (the compiled sweep).

The deep tier's critical path on a cluster is its longest case. Of the cases the swept loop serves
(USL, the lumped mass, no remedy), the longest by the cost models is Sod's tube at h = 7.8125e-5 with
16 particles per cell (204,800 particles, about 17 CPU-min by the model). This script runs
``studies.sod.run_case`` on it twice at the same time, in two processes, and compares (``--against``):

- ``sweep``: the compiled loop as the studies run it (with the sweep) against ``FusedStep(sweep=False)``
  (pass 2 and the next pass 1 apart, the loop before the sweep of 2026-11-28);
- ``count``: the new extrema (C14) counted inside the compiled loop, as the studies count them, against
  the same counter as an observer called after every step (the path before: the steps one at a time).

It reports each run's CPU and wall time, their ratio, and whether the two results are equal (every field
but the wall times: neither change moves a float or a count). The two runs share the machine the whole
time, so their ratio, not their times, is the result.
Usage: ``python benchmarks/deep_case.py [--h 7.8125e-5] [--against sweep|count] [--markdown docs/performance.md]``.
"""

from __future__ import annotations

import argparse
import time
from concurrent.futures import ProcessPoolExecutor
from functools import partial

from measured import add_markdown_option, measured_block  # benchmarks/measured.py

WAYS = {"sweep": ("swept", "apart"), "count": ("swept", "per step")}  # --against: the two runs
LABELS = {"swept": "the loop with the sweep, counting in it", "apart": "pass 2 and pass 1 apart",
          "per step": "steps one at a time, counted by the observer"}
CASE = {"solver": "mpm", "h": 7.8125e-05, "ppc": 16, "cfl": 0.05, "av_linear": 0.5, "av_quadratic": 2.0,
        "mass": "lumped", "scheme": "usl", "basis": "mpm", "layout": "regular", "seed": 0,
        "region_half_width": 0.02, "profiles": False, "extrema": True}


_ORIGINAL = {}  # this process's FusedStep and ExtremaCounter as solve.run and studies.sod take them


def run_as(*before: str) -> None:
    """Make this process's runs take the sweep kernel except for the changes named in ``before``, which run
    as they did before it: ``"apart"``, pass 2 and the next pass 1 apart (``FusedStep(sweep=False)``, what
    ``solve.run`` builds); ``"per step"``, Sod's extrema counter called after every step (it has no ``tally``,
    so ``solve.run`` steps one at a time instead of counting in the loop). No names: the kernel as it is."""
    import mpm_fem.run.solve as solve
    import studies.sod as sod_study

    if not _ORIGINAL:
        _ORIGINAL.update(step=solve.FusedStep, counter=sod_study.ExtremaCounter)
    solve.FusedStep, sod_study.ExtremaCounter = _ORIGINAL["step"], _ORIGINAL["counter"]
    if "apart" in before:
        solve.FusedStep = partial(_ORIGINAL["step"], sweep=False)
    if "per step" in before:
        sod_study.ExtremaCounter = type("PerStepCounter", (_ORIGINAL["counter"],), {"tally": None})


def timed_case(case: dict, way: str) -> tuple[dict, float, float]:
    """``(run_case(case), CPU s, wall s)`` in this process, taken ``way`` (one of ``WAYS``)."""
    from studies.sod import run_case

    run_as(*(() if way == "swept" else (way,)))
    cpu, wall = time.process_time(), time.perf_counter()
    result = run_case(case)
    return result, time.process_time() - cpu, time.perf_counter() - wall


def without_walls(value):
    """``value`` with every entry whose key names a wall time removed (nested dicts and lists)."""
    if isinstance(value, dict):
        return {k: without_walls(v) for k, v in value.items() if "wall" not in k}
    if isinstance(value, list):
        return [without_walls(v) for v in value]
    return value


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--h", type=float, default=CASE["h"], help="cell size (default: the deep tier's 7.8125e-5)")
    parser.add_argument("--against", choices=sorted(WAYS), default="sweep",
                        help="sweep: with and without the sweep; count: extrema counted in the loop or per step")
    add_markdown_option(parser)
    args = parser.parse_args(argv)
    if not 0 < args.h <= 0.01:
        parser.error(f"--h must lie in (0, 0.01], got {args.h}")
    case = dict(CASE, h=args.h)
    ways = WAYS[args.against]
    with ProcessPoolExecutor(max_workers=2) as pool:  # both at once: the same machine state for both
        futures = [pool.submit(timed_case, case, way) for way in ways]
        (r_new, cpu_new, wall_new), (r_old, cpu_old, wall_old) = (f.result() for f in futures)
    equal = without_walls(r_new) == without_walls(r_old)
    block = "deep_case" if args.against == "sweep" else f"deep_case_{args.against}"
    with measured_block(args.markdown, "deep_case", block):
        print(f"Sod, h = {args.h:g}, 16 particles per cell, the two runs at once in two processes:\n")
        print("| run | CPU s | wall s |\n|---|---:|---:|")
        print(f"| {LABELS[ways[0]]} | {cpu_new:.1f} | {wall_new:.1f} |")
        print(f"| {LABELS[ways[1]]} | {cpu_old:.1f} | {wall_old:.1f} |")
        print(f"\nCPU time {ways[1]} / {ways[0]}: {cpu_old / cpu_new:.2f}; the two results "
              f"{'equal' if equal else 'DIFFER'} (every field but the wall times).")
    if not equal:
        raise SystemExit(f"the runs {ways[0]} and {ways[1]} differ")


if __name__ == "__main__":
    main()
