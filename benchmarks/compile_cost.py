"""What each variant of the fused compiled step costs to compile, against running it.

The fused step (:mod:`mpm_fem.fused`) compiles one variant of its loop and passes per basis, model,
scheme and remedy; a first run on a machine (an empty numba cache) pays each variant's compile once,
and the quick tier's cold time is mostly these compiles. This script runs, in one fresh process with
an empty numba cache of its own, one short run per variant in the order listed (the order a
reproduction meets them, so that passes shared with an earlier variant are already compiled), then
the same run again with the variant compiled. Per variant it reports the CPU seconds of the first
run minus the second (its compile, ``time.process_time``) and the ratio of that compile to a
compiled run of the quick tier's finest Sod case (h = 0.0025, 16 per cell, CFL 0.05, to T = 0.2),
measured in the same process: the machines are shared, ratios in one run are the result.

Usage: ``python benchmarks/compile_cost.py [--markdown FILE]``.
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import subprocess
import sys
import tempfile
import time

#: (label, problem, settings) in the order a reproduction compiles them: the study settings first.
VARIANTS = (
    ("Sod, point basis (P1)", "sod", {}),
    ("Burgers, point basis (P1)", "burgers", {}),
    ("Sod, GIMP", "sod", {"basis": "gimp"}),
    ("Sod, B-spline", "sod", {"basis": "bspline"}),
    ("Burgers, B-spline", "burgers", {"basis": "bspline"}),
    ("Sod, USF", "sod", {"scheme": "usf"}),
    ("Sod, exact projection (E1)", "sod", {"projection": "exact"}),
    ("Sod, XPIC(5)", "sod", {"xpic": 5}),
    ("Sod, grid volume", "sod", {"volume": "grid"}),
    ("Sod, Taylor LS", "sod", {"reconstruct": "taylor"}),
    ("Sod, B-spline domain", "sod", {"basis": "bspline_gimp"}),
)
SHORT = {"sod": dict(h=0.05, ppc=4, T=0.01), "burgers": dict(h=0.1, ppc=4, T=0.01)}
REFERENCE = dict(h=0.0025, ppc=16, cfl=0.05)


def _run(problem: str, settings: dict) -> float:
    """CPU seconds of one run of ``problem`` with ``settings``."""
    from mpm_fem.problems import burgers, sod

    module, kind = (sod, sod.SodSettings) if problem == "sod" else (burgers, burgers.BurgersSettings)
    start = time.process_time()
    module.simulate(kind(**settings), progress=False)
    return time.process_time() - start


def measure() -> tuple[list[dict], float]:
    """The rows of the table and the CPU seconds of the compiled reference run; runs in a process whose
    numba cache is empty (:func:`main` sees to it)."""
    rows = []
    for label, problem, changes in VARIANTS:
        settings = {**SHORT[problem], **changes}
        first, second = _run(problem, settings), _run(problem, settings)
        rows.append({"variant": label, "compile_s": first - second, "run_s": second})
        print(f"  {label}: compile {first - second:.1f} CPU-s", file=sys.stderr, flush=True)
    reference = _run("sod", REFERENCE)
    for row in rows:
        row["ratio"] = row["compile_s"] / reference
    return rows, reference


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--markdown", help="also write the table into this markdown file's generated block")
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if not args.child:  # a fresh process with an empty numba cache of its own
        with tempfile.TemporaryDirectory() as cache:
            env = {**os.environ, "NUMBA_CACHE_DIR": cache}
            command = [sys.executable, __file__, "--child"] + (["--markdown", args.markdown] if args.markdown else [])
            return subprocess.call(command, env=env)
    from mpm_fem.app.output import tee_markdown

    header = (f"Compile cost of the fused step's variants ({datetime.date.today()}, {platform.machine()}, Python "
              f"{platform.python_version()}, an empty numba cache; `python benchmarks/compile_cost.py`)")
    with tee_markdown(args.markdown, "compile_cost", header):
        rows, reference = measure()
        total = sum(r["compile_s"] for r in rows)
        print("| variant | compile, CPU s | / one compiled quick Sod run | share of all compiles |")
        print("|---|---:|---:|---:|")
        for r in rows:
            print(f"| {r['variant']} | {r['compile_s']:.1f} | {r['ratio']:.1f}x | {r['compile_s'] / total:.0%} |")
        print(f"\nAll {len(rows)} variants: {total:.0f} CPU s, {total / reference:.0f}x one compiled run of the "
              f"quick tier's finest Sod case ({reference:.2f} CPU s).")
    return 0


if __name__ == "__main__":
    sys.exit(main())
