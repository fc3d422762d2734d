"""The deep tier's longest swept case, with and without the sweep, side by side (issue 47).

The deep tier's critical path on a cluster is its longest case. Of the cases the swept loop serves
(USL, the lumped mass, no remedy), the longest by the cost models is Sod's tube at h = 7.8125e-5 with
16 particles per cell (204,800 particles, about 17 CPU-min by the model). This script runs
``studies.sod.run_case`` on it twice at the same time, in two processes: once as the studies run it
(the compiled loop with the sweep) and once with ``FusedStep(sweep=False)`` (pass 2 and the next pass 1
apart, the loop before issue 47), then reports each one's CPU and wall time, their ratio, and whether
the two results are equal (every field but the wall times: the sweep changes no float). The two runs
share the machine the whole time, so their ratio, not their times, is the result.
Usage: ``python benchmarks/deep_case.py [--h 7.8125e-5] [--T 0.2] [--markdown docs/performance.md]``.
"""

from __future__ import annotations

import argparse
import time
from concurrent.futures import ProcessPoolExecutor
from functools import partial

from measured import add_markdown_option, measured_block  # benchmarks/measured.py

CASE = {"solver": "mpm", "h": 7.8125e-05, "ppc": 16, "cfl": 0.05, "av_linear": 0.5, "av_quadratic": 2.0,
        "mass": "lumped", "scheme": "usl", "basis": "mpm", "layout": "regular", "seed": 0,
        "region_half_width": 0.02, "profiles": False, "extrema": True}


def timed_case(case: dict, sweep: bool) -> tuple[dict, float, float]:
    """``(run_case(case), CPU s, wall s)`` in this process, the loop with or without the sweep."""
    import mpm_fem.run.solve as solve
    from mpm_fem.fused.step import FusedStep
    from studies.sod import run_case

    solve.FusedStep = partial(FusedStep, sweep=sweep)  # what solve.run builds: this process only
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
    add_markdown_option(parser)
    args = parser.parse_args(argv)
    if not 0 < args.h <= 0.01:
        parser.error(f"--h must lie in (0, 0.01], got {args.h}")
    case = dict(CASE, h=args.h)
    with ProcessPoolExecutor(max_workers=2) as pool:  # both at once: the same machine state for both
        swept, apart = (pool.submit(timed_case, case, sweep) for sweep in (True, False))
        (r_swept, cpu_swept, wall_swept), (r_apart, cpu_apart, wall_apart) = swept.result(), apart.result()
    equal = without_walls(r_swept) == without_walls(r_apart)
    with measured_block(args.markdown, "deep_case"):
        print(f"Sod, h = {args.h:g}, 16 particles per cell, the two runs at once in two processes:\n")
        print("| loop | CPU s | wall s |\n|---|---:|---:|")
        print(f"| with the sweep | {cpu_swept:.1f} | {wall_swept:.1f} |")
        print(f"| pass 2 and pass 1 apart | {cpu_apart:.1f} | {wall_apart:.1f} |")
        print(f"\nCPU time apart / with the sweep: {cpu_apart / cpu_swept:.2f}; the two results "
              f"{'equal' if equal else 'DIFFER'} (every field but the wall times).")
    if not equal:
        raise SystemExit("the runs with and without the sweep differ")


if __name__ == "__main__":
    main()
