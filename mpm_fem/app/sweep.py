"""Sweeps: a study is a list of independent cases, run in parallel, each result cached.

``run_cases(fn, cases)`` calls the module-level function ``fn(case) -> dict`` on every case (a
JSON-able dict of settings). Results are cached under ``cache_dir`` by a key made of ``fn``'s
qualified name, the case, and the version of the code that case runs through
(:func:`mpm_fem.measure.version.case_version`: the model and ``fn``'s closure in its module): a
finished case is never recomputed while that code is unchanged, an edit of it recomputes every
case, and an edit of a study's plan alone recomputes none. Each entry also records the version of
all the code (:func:`mpm_fem.measure.version.code_version`, re-exported here). Each result is
written atomically (temporary file + rename), so a sweep that is interrupted resumes where it
stopped and never reads a half-written result.

Parallelism: ``jobs`` worker processes (``concurrent.futures``), or an existing Dask cluster when
``scheduler="tcp://HOST:PORT"`` is given (``dask.distributed``, the optional extra ``[dask]``).
Progress: a ``tqdm`` bar on a terminal, plain lines otherwise (CI logs), both with the time left;
one line when numba starts compiling the kernels (a first run: :mod:`mpm_fem.app.compiling`).

Workers die with their parent: each worker ignores Ctrl-C (the parent handles it and ends them),
asks Linux to kill it when its parent dies (``prctl(PR_SET_PDEATHSIG)``), and runs a watchdog
thread that ends it within half a second once the parent process is gone (any platform).
"""

from __future__ import annotations

import ctypes
import hashlib
import json
import multiprocessing
import os
import signal
import sys
import threading
import time
from collections import deque
from collections.abc import Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Callable

from tqdm.auto import tqdm

from mpm_fem.app.compiling import compile_notice, families, notice_once
from mpm_fem.app.output import write_json
from mpm_fem.measure.version import case_version, code_version

CaseFn = Callable[[dict], dict]


def case_key(fn: CaseFn, case: dict) -> str:
    """Cache key of ``fn(case)`` under the current code (:func:`fn_version`)."""
    text = json.dumps({"fn": f"{fn.__module__}.{fn.__qualname__}", "case": case, "code": fn_version(fn)},
                      sort_keys=True, default=repr)
    return hashlib.sha256(text.encode()).hexdigest()[:20]


def timed(fn: CaseFn, case: dict) -> tuple[dict, float, float]:
    """``(fn(case), CPU seconds, wall seconds)`` of the process that runs it: every cache entry records
    what its case cost (``cpu_s``, ``wall_s``), the measurements the studies' cost models are fitted to."""
    cpu, wall = time.process_time(), time.perf_counter()
    result = fn(case)
    return result, time.process_time() - cpu, time.perf_counter() - wall


def fn_version(fn: CaseFn) -> str:
    """:func:`~mpm_fem.measure.version.case_version` of ``fn``, found by its module's file."""
    return case_version(sys.modules[fn.__module__].__file__, fn.__qualname__)


def _load(path: Path) -> dict | None:
    try:
        return json.loads(path.read_text())["result"]
    except (OSError, ValueError, KeyError):
        return None


def _watch_parent(parent: int, interval: float = 0.5) -> None:
    while os.getppid() == parent:
        time.sleep(interval)
    os._exit(1)  # the parent is gone: nobody waits for this worker's result


def _worker_init(parent: int, compiling=None) -> None:
    """Runs in each worker process before its first case: see the module docstring. ``compiling``: the
    workers' shared flag of the compile line (:func:`mpm_fem.app.compiling.notice_once`), ``None``: no line."""
    if compiling is not None:
        notice_once(compiling)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if sys.platform.startswith("linux"):
        try:
            ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG = 1
        except (OSError, AttributeError):
            pass
    if os.getppid() != parent:  # the parent died before prctl took effect
        os._exit(1)
    threading.Thread(target=_watch_parent, args=(parent,), daemon=True, name="watch-parent").start()


#: The case keys that, with its function, choose the compiled kernels a case runs through: a task's
#: group (:func:`kernel_group`). A guess from the studies' cases: a wrong one costs compiling time,
#: never a number.
KERNEL_KEYS = ("solver", "problem", "kind", "basis", "scheme", "mass", "transfer")
#: For this long after a compile family's latest task starts (or until it ends), the pool starts the family's
#: other tasks only when a task of another family can start: numba compiles a kernel at the first task
#: that calls it and caches it on disk, and a second worker starting the family meanwhile would compile it
#: again (a cold quick tier's two workers did so, each compiling every kernel). A family is a kernel group
#: with the groups it shares uncached compiles with (:func:`mpm_fem.app.compiling.families`: the Sod and
#: Burgers loops share their projection and scatter passes). The latest task, not only the first: a
#: group's first task need not call every kernel of the group (the mechanism study's first subset makes
#: time exact; its next two, the projection and the mass, both compile the exact projection's kernels).
COMPILE_S = 45.0


def kernel_group(task: Task) -> tuple:
    """The group of ``task``: its function and the values of :data:`KERNEL_KEYS` in its case."""
    return (task.fn.__module__, task.fn.__qualname__, *(repr(task.case.get(key)) for key in KERNEL_KEYS))


def _next_task(waiting: deque, groups: dict, latest: dict, now: float, ended: dict | None = None):
    """Take from ``waiting`` (``(k, path)`` in their order) the first task whose group ``groups[k]`` (the
    pool's: a compile family) may not be compiling: its latest task (``latest[group] = (start time,
    future)``) has ended or started :data:`COMPILE_S` ago or more, or it has none. When every group may
    be, the first task of the group with the most ended tasks (``ended[group]``, the likeliest to have its
    kernels compiled): a worker never idles."""
    for i, (k, path) in enumerate(waiting):
        started = latest.get(groups[k])
        if started is None or started[1].done() or now - started[0] >= COMPILE_S:
            del waiting[i]
            return k, path
    ended = ended or {}
    most = max(ended.get(groups[k], 0) for k, _ in waiting)
    i = next(i for i, (k, _) in enumerate(waiting) if ended.get(groups[k], 0) == most)
    k, path = waiting[i]
    del waiting[i]
    return k, path


def _run_pool(tasks, todo, jobs: int, finish, followups=(), notice: bool = False) -> None:
    """The tasks of ``todo`` in ``jobs`` worker processes, started in their order (but a compile family's
    tasks held back while its latest task may compile kernels: :func:`_next_task`) and at most ``jobs + 1``
    at a time, so that a follow-up (a function of no arguments: ``followups``, and what ``finish``
    returns) starts ahead of the tasks still waiting. If the parent is interrupted (Ctrl-C) or fails,
    the workers are ended at once instead of finishing their cases. ``notice``: the first worker to
    compile a kernel says so in one line."""
    compiling = multiprocessing.Value("b", 0) if notice else None
    pool = ProcessPoolExecutor(max_workers=jobs, initializer=_worker_init, initargs=(os.getpid(), compiling))
    waiting, ahead, running = deque(todo), deque(followups), {}
    family = families(kernel_group(tasks[k]) for k, _ in todo)
    groups, latest, ended = {k: family[kernel_group(tasks[k])] for k, _ in todo}, {}, {}

    def start() -> None:
        while len(running) <= jobs and (ahead or waiting):
            if ahead:
                running[pool.submit(ahead.popleft())] = None
            else:
                k, path = _next_task(waiting, groups, latest, time.perf_counter(), ended)
                future = pool.submit(timed, tasks[k].fn, tasks[k].case)
                running[future] = (k, path)
                latest[groups[k]] = (time.perf_counter(), future)

    try:
        start()
        while running:
            finished, _ = wait(running, return_when=FIRST_COMPLETED)
            for future in finished:
                item = running.pop(future)
                result = future.result()
                if item is not None:
                    ended[groups[item[0]]] = ended.get(groups[item[0]], 0) + 1
                then = finish(*item, result) if item is not None else None
                if then is not None:
                    ahead.append(then)
            start()
    except BaseException:
        workers = list(getattr(pool, "_processes", {}).values())  # no public handle on the workers
        pool.shutdown(wait=False, cancel_futures=True)
        for process in workers:
            process.kill()
        raise
    pool.shutdown()


def default_jobs() -> int:
    return max(1, min(os.cpu_count() or 1, 8))


def run_cases(
    fn: CaseFn,
    cases: list[dict],
    jobs: int | None = None,
    cache_dir: str | os.PathLike | None = None,
    desc: str = "cases",
    scheduler: str | None = None,
    progress: bool | None = None,
) -> list[dict]:
    """``[fn(case) for case in cases]``, in parallel, cached; results in the order of ``cases``."""
    return run_tasks([Task(fn, case, cache_dir) for case in cases], jobs, desc, scheduler, progress)


@dataclass(frozen=True)
class Task:
    """One case of a sweep: ``fn(case)``, its result cached in ``cache_dir`` (``None``: not cached)."""

    fn: CaseFn
    case: dict
    cache_dir: str | os.PathLike | None = None

    @property
    def path(self) -> Path | None:
        return None if self.cache_dir is None else Path(self.cache_dir) / f"{case_key(self.fn, self.case)}.json"


def run_tasks(
    tasks: list[Task],
    jobs: int | None = None,
    desc: str = "cases",
    scheduler: str | None = None,
    progress: bool | None = None,
    done: Callable[[int], Callable[[], object] | None] | None = None,
    costs: Sequence[float] | None = None,
) -> list[dict]:
    """``[t.fn(t.case) for t in tasks]``, in parallel, each cached in its task's folder; results in the
    order of ``tasks``, which is also the order they start in; a task listed twice (the same function and
    case into the same cache folder: two studies sharing a case) runs once and fills both. Tasks of
    several functions (several studies) share one pool, so no worker idles at the end of one study
    while another has cases left.
    ``done(k)`` is called in this process once task ``k``'s result is in (cached ones first), while the
    workers go on with the others. It may return a follow-up, a picklable function of no arguments
    (a study's tables and figures once its last case is in): a worker of the pool runs it ahead of the
    cases not yet started; without a pool (one job) or on a Dask cluster (whose workers need not share
    this file system) this process runs it at once.
    ``costs`` (one per task: the cost models' CPU seconds, numba's compiles included) weigh the progress's
    time left and are its model: the model's time left (the cost still to run over the workers) blended
    with the measured rate's (the time so far times the cost still to run over the cost run so far) by
    the share of the cost run (:func:`time_left`); without them each case weighs the same and the time
    left is the measured rate's."""
    if jobs is not None and jobs < 1:
        raise ValueError(f"jobs must be >= 1, got {jobs}")
    jobs = jobs or default_jobs()
    for folder in {Path(t.cache_dir) for t in tasks if t.cache_dir is not None}:
        folder.mkdir(parents=True, exist_ok=True)
    results: list[dict | None] = [None] * len(tasks)
    todo, first, twins = [], {}, {}  # a case listed twice (same cache file) runs once, for both
    for k, task in enumerate(tasks):
        path = task.path
        cached = _load(path) if path is not None and path.exists() else None
        if cached is not None:
            results[k] = cached
        elif path is not None and path in first:
            twins.setdefault(first[path], []).append(k)
        else:
            if path is not None:
                first[path] = k
            todo.append((k, path))
    pooled = scheduler is None and jobs > 1
    weights = list(costs) if costs is not None else [1.0] * len(tasks)
    if len(weights) != len(tasks):
        raise ValueError(f"costs: {len(weights)} for {len(tasks)} tasks")
    waiting = len(todo) + sum(len(js) for js in twins.values())  # a twin is done when its first is
    reporter = _Progress(len(tasks), len(tasks) - waiting, desc, progress, to_run=sum(weights[k] for k, _ in todo),
                         workers=None if costs is None else max(1, min(jobs, len(todo))))

    def follow(k: int):
        """``done(k)``'s follow-up, for the pool to run; run here when there is no pool."""
        then = done(k) if done is not None else None
        if then is not None and not pooled:
            then()
            return None
        return then

    running = {k for k, _ in todo} | {j for js in twins.values() for j in js}
    followups = [f for f in (follow(k) for k in range(len(tasks)) if k not in running) if f is not None]

    def finish(k: int, path: Path | None, run: tuple[dict, float, float]):
        result, cpu_s, wall_s = run
        if path is not None:
            write_json(path, {"case": tasks[k].case, "case_code": fn_version(tasks[k].fn), "code": code_version(),
                              "cpu_s": round(cpu_s, 3), "wall_s": round(wall_s, 3), "result": result})
        thens = []
        for j in (k, *twins.get(k, ())):
            results[j] = result
            reporter.update(tasks[j].case, weights[j] if j == k else 0.0)
            thens.append(follow(j))
        thens = tuple(t for t in thens if t is not None)
        return None if not thens else thens[0] if len(thens) == 1 else partial(_run_all, thens)

    try:
        if scheduler is not None:
            if todo:
                _run_dask(tasks, todo, scheduler, finish)
        elif pooled and len(todo) + len(followups) > 1:
            _run_pool(tasks, todo, min(jobs, len(todo) + len(followups)), finish, followups, notice=reporter.enabled)
        else:
            with compile_notice(reporter.enabled):
                for then in followups:
                    then()
                for k, path in todo:
                    then = finish(k, path, timed(tasks[k].fn, tasks[k].case))
                    if then is not None:
                        then()
    finally:
        reporter.close()
    return results  # type: ignore[return-value]


def _run_all(functions) -> None:
    """Call each of ``functions`` (follow-ups due at once: a case listed twice ended two studies)."""
    for f in functions:
        f()


def _run_dask(tasks, todo, scheduler, finish) -> None:
    try:
        from dask.distributed import Client
        from dask.distributed import as_completed as dask_completed
    except ImportError:
        raise RuntimeError("--scheduler needs dask.distributed: pip install 'mpm-fem[dask]'") from None
    try:
        client = Client(scheduler, timeout="10s")
    except Exception as err:  # noqa: BLE001 -- one line, whatever the failure of the connection
        raise RuntimeError(f"cannot connect to the Dask scheduler at {scheduler}: {err.__class__.__name__}: "
                           f"{str(err).splitlines()[0] if str(err) else ''}") from None
    with client:
        futures = {}
        for k, path in todo:
            future = client.submit(timed, tasks[k].fn, tasks[k].case, pure=False, key=f"case-{k}-{time.time_ns()}")
            futures[future] = (k, path)
        for future in dask_completed(list(futures)):
            k, path = futures[future]
            finish(k, path, future.result())


#: Off a terminal, a progress line every ~10 % of the cases, or at the first case to end after this
#: many seconds without a line (the longest cases run first, so the first 10 % can take most of a run).
PLAIN_EVERY = 60.0


class _Progress:
    """A tqdm bar on a terminal (elapsed and left); on other streams a plain line every ~10 % of the
    cases or every :data:`PLAIN_EVERY` seconds, whichever comes first, with the time left at the
    rate of the cases run so far, each weighed by its cost (:func:`time_left`; ``to_run``: the cost
    of every case to run), blended with the model's when the costs are CPU seconds run on ``workers``."""

    def __init__(self, total: int, done: int, desc: str, progress: bool | None, to_run: float | None = None,
                 workers: int | None = None):
        self.total, self.done, self.desc, self.cached = total, done, desc, done
        self.workers = workers
        self.to_run = float(total - done) if to_run is None else float(to_run)
        self.ran = 0.0
        self.start = self.last = time.perf_counter()
        tty = sys.stderr.isatty()
        self.enabled = progress if progress is not None else True
        self.bar = tqdm(total=total, initial=done, desc=desc, leave=False) if (self.enabled and tty) else None
        self.plain = self.enabled and not tty and total > done
        self.step = max(1, (total - done) // 10)
        if self.plain:
            print(f"[{desc}] {total - done} of {total} cases to run ({done} cached)", file=sys.stderr, flush=True)

    def update(self, case: dict, cost: float = 1.0) -> None:
        self.done += 1
        self.ran += cost
        if self.bar is not None:
            self.bar.update(1)
        elif self.plain:
            now = time.perf_counter()
            if self.done % self.step == 0 or self.done == self.total or now - self.last >= PLAIN_EVERY:
                self.last = now
                rest = self.to_run - self.ran
                model = None if self.workers is None else rest / self.workers
                left = time_left(now - self.start, self.ran, rest, model) if self.done < self.total else "done"
                print(f"[{self.desc}] {self.done}/{self.total} done, {now - self.start:.0f} s, {left}", file=sys.stderr,
                      flush=True)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


#: The share of the cost a run must have done before its progress says the time left by the measured rate
#: alone (no cost model): before it, the time so far is mostly numba compiling the kernels and starting
#: the workers (a cold quick tier said "about 46 min left" after its first tenth of the cases, and took 80 s).
RATE_AFTER = 0.1


def time_left(elapsed: float, run: float, left: float, model: float | None = None) -> str:
    """``"about N s left"`` for the cost ``left`` still to run (costs in any unit: cases, or the cost models'
    seconds), ``"done"`` when none is left. Without ``model``: ``elapsed * left / run``, at the rate of the
    cost ``run`` so far, and ``"time left unknown"`` before :data:`RATE_AFTER` of the cost has run. With
    ``model`` (the cost model's seconds left):

        f = run / (run + left),   seconds = f * elapsed * left / run + (1 - f) * model

    the model's guess at the start, the measured rate's at the end: an early rate that is mostly
    compiling, or a case far off the model, moves the line by its share of the work only."""
    if left <= 0:
        return "done"
    if model is None:
        if run <= 0 or run < RATE_AFTER * (run + left):
            return "time left unknown"
        seconds = elapsed / run * left
    else:
        share = max(run, 0.0) / (max(run, 0.0) + left)
        seconds = (share * elapsed / run * left if run > 0 else 0.0) + (1 - share) * model
    return f"about {seconds:.0f} s left" if seconds < 120 else f"about {seconds / 60:.0f} min left"
