"""What the sweep kernel (2026-11-28/29) saves of a tier, measured in one run: the time ledger, before and after.

The record's CPU time compared across machines mixes the kernel with the machine (the same code ran a
third slower on the machine of the record at 79c9907f69f3 than on that of 10aaef63d6f2). This script
measures the saving on one machine in one run. It takes a sample of every study's cases of a tier and
runs each sampled case two ways at once, in two processes (each kept on a processor of its own), and
compares their CPU times:

- ``now``: as the studies run it (the compiled loop with the sweep; Sod's new extrema counted inside
  the loop);
- ``before``: the kernel before the sweep, the loop with pass 2 and the next pass 1 apart
  (``FusedStep(sweep=False)``) and the extrema counter called after every step, so that those runs
  step one at a time (``benchmarks/deep_case.py``'s two baselines together).

On a shared machine the two processors need not run alike (measured: the same code ran up to a quarter
faster on one of them), so each case runs ``--rounds`` times each way, the two ways swapping processors
every round; a case's ratio is the geometric mean of its rounds' ratios.

The sample: a study's cases sorted by their estimated cost (the cost models,
:func:`mpm_fem.app.estimate.tasks`) are cut into ``k`` consecutive groups of equal estimated cost, and
the case at the middle of each group's cost stands for it (sampling proportional to size). A study's
ratio ``r`` is its sampled cases' CPU before over their CPU now (sums over the cases and rounds: a case
too short to time adds nothing), and its CPU before the sweep is estimated as ``r`` times its estimated CPU now. Neither
change moves a float or a count, so every pair's results must be equal (every field but the times),
and the script fails if one differs.
The numba cache must be warm for a fair timing (the ``before`` variants compile at their first call):
run it once to compile, then again to measure.
Usage: ``python benchmarks/ledger.py [--tier full] [--per-study 3] [--rounds 2] [--studies sod,burgers]
[--markdown docs/performance.md]``.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np
from deep_case import run_as, without_walls  # benchmarks/deep_case.py, beside this script
from measured import add_markdown_option, measured_block  # benchmarks/measured.py

from mpm_fem.app.study import STUDIES

WAYS = ("now", "before")


def pin(cpu: int) -> None:
    """Keep this worker on one processor (where the system allows), so that a round's two runs stay on
    their own processors and the next round swaps them."""
    if hasattr(os, "sched_setaffinity") and cpu in os.sched_getaffinity(0):
        os.sched_setaffinity(0, {cpu})


def timed(way: str, fn, case: dict) -> tuple[dict, float]:
    """``(fn(case), CPU seconds of this process)``, the case run ``way``."""
    run_as(*(("apart", "per step") if way == "before" else ()))
    cpu = time.process_time()
    result = fn(case)
    return result, time.process_time() - cpu


def sample(costs: np.ndarray, k: int) -> list[int]:
    """Indices into ``costs`` (sorted ascending) of the cases at the middle of ``k`` consecutive groups
    of equal total cost (distinct; fewer than ``k`` if the study has fewer cases)."""
    total = np.cumsum(costs)
    picks = np.searchsorted(total, (np.arange(k) + 0.5) * total[-1] / k)
    return sorted({int(i) for i in np.minimum(picks, costs.size - 1)})


def plan(tier: str, k: int, names) -> list[tuple[str, float, list[tuple[float, object]]]]:
    """Per study of ``names`` with a cost model: ``(name, estimated CPU s of the tier, [(estimated s, task),
    ...])``, the sampled tasks (cases another study's plan holds are counted there and left out)."""
    from mpm_fem.app.estimate import tasks
    from mpm_fem.app.study import StudyOptions

    options = StudyOptions(quick=tier == "quick", deep=tier == "deep")
    out = []
    for name in names:
        found = sorted(((s, task) for s, task in tasks(name, options) or () if s > 0), key=lambda st: st[0])
        if found:
            costs = np.array([s for s, _ in found])
            out.append((name, float(costs.sum()), [found[i] for i in sample(costs, k)]))
    return out


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tier", choices=("quick", "full", "deep"), default="full", help="whose cases (default: full)")
    parser.add_argument("--per-study", type=int, default=3, help="cases sampled per study (default 3)")
    parser.add_argument("--rounds", type=int, default=2,
                        help="runs of each case each way, the processors swapped every round (default 2)")
    parser.add_argument("--studies", default=",".join(STUDIES), help="comma-separated studies (default: all)")
    add_markdown_option(parser)
    args = parser.parse_args(argv)
    if args.per_study < 1 or args.rounds < 1:
        parser.error(f"--per-study and --rounds must be at least 1, got {args.per_study} and {args.rounds}")
    names = [n for n in args.studies.split(",") if n]
    unknown = sorted(set(names) - set(STUDIES))
    if unknown or not names:
        parser.error(f"unknown studies {unknown}; known: {', '.join(STUDIES)}")
    studies = plan(args.tier, args.per_study, names)
    cpus = sorted(os.sched_getaffinity(0))[:2] if hasattr(os, "sched_getaffinity") else [0, 1]
    pools = [ProcessPoolExecutor(max_workers=1, initializer=pin, initargs=(cpu,)) for cpu in (cpus * 2)[:2]]
    rows, differ = [], []
    for name, estimated, picked in studies:
        ratios, cpu = [], {way: 0.0 for way in WAYS}
        for seconds, task in picked:
            logs = []
            for turn in range(args.rounds):  # a round: both ways at once; the next swaps their processors
                ways = WAYS if turn % 2 == 0 else WAYS[::-1]
                futures = {way: pool.submit(timed, way, task.fn, task.case)
                           for way, pool in zip(ways, pools, strict=True)}
                (r_now, cpu_now), (r_before, cpu_before) = (futures[way].result() for way in WAYS)
                logs.append(np.log(cpu_before / cpu_now) if cpu_now > 0 and cpu_before > 0 else np.nan)
                cpu["now"] += cpu_now
                cpu["before"] += cpu_before
                if without_walls(r_now) != without_walls(r_before):
                    differ.append((name, task.case))
                print(f"{name}: a case estimated at {seconds:.1f} s, {cpu_now:.1f} CPU-s now, {cpu_before:.1f} before",
                      file=sys.stderr, flush=True)
            ratios.append(np.exp(np.mean(logs)))  # the rounds' geometric mean: a slower processor cancels
        rows.append((name, estimated, len(picked), cpu, np.array(ratios)))
    for pool in pools:
        pool.shutdown()
    with measured_block(args.markdown, "ledger"):
        print(f"The {args.tier} tier, {args.per_study} cases per study sampled in proportion to their estimated cost, "
              f"each run now and before the sweep at once in two processes, {args.rounds} rounds, the processors "
              "swapped each round:\n")
        print("| study | estimated now, CPU-min | cases sampled | sample now, CPU-s | sample before, CPU-s "
              "| before / now, sums (cases: min ... max) | estimated before, CPU-min |\n"
              "|---|---:|---:|---:|---:|---:|---:|")
        now_total = before_total = 0.0
        for name, estimated, count, cpu, each in rows:
            r = cpu["before"] / cpu["now"] if cpu["now"] > 0 else 1.0  # nothing measurable: no change counted
            now_total += estimated / 60
            before_total += estimated / 60 * r
            spread = f"({np.nanmin(each):.2f} ... {np.nanmax(each):.2f})" if np.isfinite(each).any() else "(too short)"
            print(f"| {name} | {estimated / 60:.1f} | {count} | {cpu['now']:.1f} | {cpu['before']:.1f} | "
                  f"{r:.2f} {spread} | {estimated / 60 * r:.1f} |")
        print(f"| all | {now_total:.1f} | | | | {before_total / now_total:.2f} | {before_total:.1f} |")
        print(f"\nThe sweep kernel saves about {before_total - now_total:.1f} of {before_total:.1f} estimated "
              f"CPU-min of the {args.tier} tier ({1 - now_total / before_total:.0%}); "
              f"{'every pair of results equal' if not differ else f'{len(differ)} pairs DIFFER'} "
              "(every field but the times).")
    if differ:
        raise SystemExit(f"the two ways differ on {differ}")


if __name__ == "__main__":
    main()
