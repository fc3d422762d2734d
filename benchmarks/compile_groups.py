"""The compile seconds of each cached numba variant, and the variants each kernel group runs through.

A sweep's task belongs to a kernel group (:func:`mpm_fem.app.sweep.kernel_group`: its function and the
case keys that choose its kernels). For each group of the studies' plans this script runs the group's
cheapest case of each kind (:func:`signature`: the mechanism study's stages made exact run different
kernels within one group) in a fresh process; all of them share one numba cache, empty at the start, so a variant
is compiled once, in the first group that meets it, and loaded from the cache by the later ones. In
each process it times numba's compiles (the ``"numba:compile"`` event, each function's own time, its
callees' compiles subtracted: CPU seconds, ``time.process_time``) and, after the case, lists the
functions it ran that numba caches (a dispatcher with ``cache=True`` and an overload). It writes
:mod:`mpm_fem.app.compile_times`: ``SECONDS`` (variant -> compile CPU seconds) and ``GROUPS`` (group ->
its variants), the table :mod:`mpm_fem.app.estimate` prices a cold run with. A variant is named
``"SOURCE::STEM"`` (:mod:`mpm_fem.app.compiling`). Groups measured earlier and not run again keep their rows.

Usage: ``python benchmarks/compile_groups.py [--tier quick|full] [--studies sod burgers ...] [--no-method]``
(default: the studies ``reproduce`` runs at the tier, and ``mpm-fem method mpm`` at the tier).
Machines are shared: a busy machine measures longer compiles; the table states where it was measured.
"""

from __future__ import annotations

import argparse
import datetime
import gc
import importlib
import json
import os
import platform
import pprint
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from numba.core import event

ROOT = Path(__file__).resolve().parents[1]
TABLE = ROOT / "mpm_fem" / "app" / "compile_times.py"


def group_key(task) -> str:
    """The key of ``task``'s kernel group in the table: :func:`~mpm_fem.app.sweep.kernel_group` joined by ``|``."""
    from mpm_fem.app.sweep import kernel_group

    return "|".join(kernel_group(task))


def signature(case: dict) -> tuple:
    """What of ``case`` can choose its kernels beyond its kernel group: its string-valued settings (a stage made
    exact, a layout, a quantity), not its numbers (meshes, seeds, particle counts)."""
    return tuple(sorted((k, v) for k, v in case.items() if isinstance(v, str)))


def groups(tier: str, studies, method: bool) -> dict[str, dict]:
    """``{group key: {"module", "fn", "cases"}}``: per group, its cheapest case of each :func:`signature` (by the
    studies' cost models; the first case of a group of the method study, which states none per case), so that
    every variant the group's cases run through is met; each case with the function ``reproduce`` runs it with
    (:mod:`mpm_fem.app.case_tasks`)."""
    from mpm_fem.app.case_tasks import tasks
    from mpm_fem.app.study import StudyOptions, reproduced
    from mpm_fem.app.sweep import Task

    options = StudyOptions(quick=tier == "quick", out=Path(tempfile.gettempdir()) / "compile-groups-plan")
    priced = []
    for name in studies or reproduced(tier):
        priced += [(s, t) for s, t in tasks(name, options) or () if s > 0]
    if method:
        study = importlib.import_module("studies.method")
        priced += [(float("inf"), Task(study.run_case, c)) for c in study.plan("mpm", None, tier)]
    cheapest: dict[str, dict] = {}
    for seconds, task in priced:
        mine = cheapest.setdefault(group_key(task), {})
        kind = signature(task.case)
        if kind not in mine or seconds < mine[kind][0]:
            mine[kind] = (seconds, task)
    return {k: {"module": next(iter(v.values()))[1].fn.__module__, "fn": next(iter(v.values()))[1].fn.__qualname__,
                "cases": [t.case for _, t in sorted(v.values(), key=lambda st: st[0])]} for k, v in cheapest.items()}


class _Timer(event.Listener):
    """Each compiled variant's own CPU seconds, by variant name: a callee variant's compile subtracted from its
    caller's, but a function numba does not cache on disk (its own overloads of numpy and the builtins, compiled
    into the variant that calls them and loaded with it from the cache) counted in its caller's."""

    def __init__(self):
        self.stack, self.seconds = [], {}

    def on_start(self, ev):
        self.stack.append([ev.data["dispatcher"], time.process_time(), 0.0])

    def on_end(self, ev):
        dispatcher, start, inner = self.stack.pop()
        spent = time.process_time() - start
        name = variant_name(dispatcher)
        if self.stack:
            self.stack[-1][2] += spent if name is not None else inner
        if name is not None:
            self.seconds[name] = self.seconds.get(name, 0.0) + spent - inner


def variant_name(dispatcher) -> str | None:
    """``"SOURCE::STEM"`` of a dispatcher numba caches on disk, ``None`` for one it does not or from outside
    the project."""
    from mpm_fem.fused.compiler import DIGEST

    cache = getattr(dispatcher, "_cache", None)
    impl = getattr(cache, "_impl", None)
    if impl is None:
        return None
    source = Path(dispatcher.py_func.__code__.co_filename).resolve()
    try:
        relative = source.relative_to(ROOT)
    except ValueError:
        return None
    stem = impl.filename_base.rsplit("-", 1)[0].replace(DIGEST, "{digest}")
    return f"{relative.as_posix()}::{stem}"


def child(spec: dict) -> dict:
    """Run a group's cases (in a fresh process): ``{"seconds": {variant: compile CPU s}, "used": [variants]}``."""
    from numba.core.registry import CPUDispatcher

    timer = _Timer()
    fn = getattr(importlib.import_module(spec["module"]), spec["fn"])
    with event.install_listener("numba:compile", timer):
        for case in spec["cases"]:
            fn(case)
    used = sorted({name for obj in gc.get_objects() if isinstance(obj, CPUDispatcher) and obj.overloads
                   for name in [variant_name(obj)] if name is not None})
    return {"seconds": {k: round(v, 2) for k, v in timer.seconds.items()}, "used": used}


def write_table(seconds: dict, groups_: dict, where: str) -> None:
    header = f'''"""numba's compile CPU seconds of each cached variant, and the variants each kernel group runs through.

Generated by ``python benchmarks/compile_groups.py``; do not edit.
Measured: {where}.
``SECONDS``: variant (``"SOURCE::STEM"``, :mod:`mpm_fem.app.compiling`) -> CPU seconds of its own
compile, measured from an empty cache. ``GROUPS``: kernel group (:func:`mpm_fem.app.sweep.kernel_group`
joined by ``|``) -> the variants its cases run through. :mod:`mpm_fem.app.estimate` adds the seconds
of the variants numba's cache lacks to a study's estimate.
"""
# ruff: noqa: E501  (generated: variant names are longer than a line)

'''
    body = (f"SECONDS = {pprint.pformat(dict(sorted(seconds.items())), width=115)}\n\n"
            f"GROUPS = {pprint.pformat(dict(sorted(groups_.items())), width=115)}\n")
    TABLE.write_text(header + body)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tier", default="quick", choices=("quick", "full"))
    parser.add_argument("--studies", nargs="*", help="the studies (default: those reproduce runs at the tier)")
    parser.add_argument("--no-method", action="store_true", help="leave out the method study's groups")
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        print(json.dumps(child(json.loads(sys.stdin.read()))))
        return 0
    sys.path.insert(0, str(ROOT))
    plan = groups(args.tier, args.studies, not args.no_method)
    try:
        from mpm_fem.app.compile_times import GROUPS, SECONDS
    except ImportError:
        GROUPS, SECONDS = {}, {}
    seconds, table = dict(SECONDS), dict(GROUPS)
    fresh = set()
    import numba

    where = (f"{datetime.date.today()}, {platform.machine()}, Python {platform.python_version()}, numba "
             f"{numba.__version__}, tier {args.tier}")
    with tempfile.TemporaryDirectory(prefix="compile-groups-") as cache:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache, "PYTHONPATH": str(ROOT)}
        for k, (key, spec) in enumerate(plan.items()):
            start = time.perf_counter()
            got = subprocess.run([sys.executable, __file__, "--child"], input=json.dumps(spec), env=env,
                                 capture_output=True, text=True, cwd=ROOT)
            if got.returncode != 0:
                print(f"  {key}: failed\n{got.stderr[-2000:]}", file=sys.stderr, flush=True)
                continue
            out = json.loads(got.stdout.strip().splitlines()[-1])
            for name, s in out["seconds"].items():
                if name not in fresh:  # the first group to meet a variant compiles it
                    seconds[name] = s
                    fresh.add(name)
            table[key] = out["used"]
            write_table(seconds, table, where)  # after each group: an interrupted run keeps what it measured
            spent = sum(out["seconds"].values())
            print(f"  {k + 1}/{len(plan)} {key}: {len(out['used'])} variants, compiled {len(out['seconds'])} in "
                  f"{spent:.1f} CPU-s ({time.perf_counter() - start:.0f} s wall)", file=sys.stderr, flush=True)
    total = sum(seconds[v] for v in {v for vs in table.values() for v in vs} if v in seconds)
    print(f"{len(table)} groups, {len(seconds)} variants, {total:.0f} CPU-s of compiles; wrote {TABLE}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
