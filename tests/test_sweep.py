"""Sweeps: parallel equals serial, finished cases are cached and never recomputed."""

import json

import pytest

from mpm_fem.app.sweep import case_key, run_cases


def square(case):
    """A case function that leaves a trace of every call in ``case['trace']``."""
    with open(case["trace"], "a") as f:
        f.write(f"{case['n']}\n")
    return {"n": case["n"], "square": case["n"] ** 2}


def test_parallel_results_equal_serial_and_keep_case_order(tmp_path):
    cases = [{"n": n, "trace": str(tmp_path / "trace")} for n in range(7)]
    serial = run_cases(square, cases, jobs=1, progress=False)
    parallel = run_cases(square, cases, jobs=2, progress=False)
    assert serial == parallel == [{"n": n, "square": n * n} for n in range(7)]


def test_cached_cases_are_not_recomputed(tmp_path):
    trace = tmp_path / "trace"
    cases = [{"n": n, "trace": str(trace)} for n in range(5)]
    run_cases(square, cases[:3], jobs=1, cache_dir=tmp_path / "cache", progress=False)
    assert trace.read_text().split() == ["0", "1", "2"]
    out = run_cases(square, cases, jobs=2, cache_dir=tmp_path / "cache", progress=False)
    assert sorted(trace.read_text().split()) == ["0", "1", "2", "3", "4"]  # only 3 and 4 ran again
    assert [r["square"] for r in out] == [0, 1, 4, 9, 16]
    stored = json.loads((tmp_path / "cache" / f"{case_key(square, cases[4])}.json").read_text())
    assert stored["result"] == {"n": 4, "square": 16} and stored["case"] == cases[4]


def test_a_corrupt_cache_entry_is_recomputed(tmp_path):
    trace = tmp_path / "trace"
    case = {"n": 3, "trace": str(trace)}
    (tmp_path / "cache").mkdir()
    (tmp_path / "cache" / f"{case_key(square, case)}.json").write_text('{"result": ')
    assert run_cases(square, [case], cache_dir=tmp_path / "cache", progress=False) == [{"n": 3, "square": 9}]
    assert trace.read_text().split() == ["3"]


def test_bad_job_count_is_refused():
    with pytest.raises(ValueError, match="jobs"):
        run_cases(square, [], jobs=0)


def slow_square(case):
    """``square`` taking a while, so that a sweep can be killed midway."""
    import time

    time.sleep(case["sleep"])
    return square(case)


def test_a_killed_sweep_resumes_without_recomputing_finished_cases(tmp_path):
    import os
    import signal
    import subprocess
    import sys
    import time
    from pathlib import Path

    trace, cache = tmp_path / "trace", tmp_path / "cache"
    cases = [{"n": n, "trace": str(trace), "sleep": 0.3} for n in range(12)]
    script = (
        "import sys, json; sys.path.insert(0, sys.argv[1]); import test_sweep; "
        "from mpm_fem.app.sweep import run_cases; "
        "run_cases(test_sweep.slow_square, json.loads(sys.argv[2]), jobs=1, cache_dir=sys.argv[3], progress=False)"
    )
    import json

    proc = subprocess.Popen([sys.executable, "-c", script, str(Path(__file__).parent), json.dumps(cases), str(cache)])
    deadline = time.time() + 300  # generous: the subprocess imports numpy, scipy and scikit-fem on a loaded machine
    while time.time() < deadline and len(list(cache.glob("*.json"))) < 2:
        time.sleep(0.05)
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    finished = len(list(cache.glob("*.json")))
    assert 2 <= finished < len(cases), f"{finished} cases finished before the kill"
    ran_before = trace.read_text().split()

    results = run_cases(slow_square, cases, jobs=2, cache_dir=cache, progress=False)
    assert [r["square"] for r in results] == [n * n for n in range(12)]
    ran_after = trace.read_text().split()[len(ran_before):]
    # every case cached before the kill is reused; only the others (and at most the one killed mid-run) run
    assert len(ran_after) == len(cases) - finished, (finished, ran_after)
    assert not set(ran_after) & set(ran_before[:finished])


def cube(case):
    with open(case["trace"], "a") as f:
        f.write(f"c{case['n']}\n")
    return {"n": case["n"], "cube": case["n"] ** 3}


def test_tasks_of_two_functions_share_one_pool_each_cached_in_its_folder(tmp_path):
    from mpm_fem.app.sweep import Task, fn_version, run_tasks
    trace = tmp_path / "trace"
    tasks = [Task(square if n % 2 else cube, {"n": n, "trace": str(trace)}, tmp_path / ("sq" if n % 2 else "cu"))
             for n in range(6)]
    out = run_tasks(tasks, jobs=2, progress=False)
    assert out == [{"n": n, "square": n * n} if n % 2 else {"n": n, "cube": n ** 3} for n in range(6)]
    assert len(list((tmp_path / "sq").glob("*.json"))) == len(list((tmp_path / "cu").glob("*.json"))) == 3
    stored = json.loads(tasks[1].path.read_text())
    assert tasks[1].path.parent == tmp_path / "sq" and stored["case_code"] == fn_version(square)
    assert run_tasks(tasks, jobs=2, progress=False) == out and len(trace.read_text().split()) == 6  # all cached


def note(trace, text):
    """A follow-up's body: ``text`` and the process that ran it, into ``trace``."""
    import os

    with open(trace, "a") as f:
        f.write(f"{text}:{os.getpid()}\n")


@pytest.mark.parametrize("jobs", [1, 2])
def test_a_follow_up_runs_in_a_worker_ahead_of_the_waiting_cases_or_here_without_a_pool(tmp_path, jobs):
    """``done(k)`` may return a function for the pool: with two workers it runs in a worker before the
    cases still waiting start (at most jobs + 1 cases are handed to the pool at a time); with one job,
    here, at once. A cached case's follow-up runs too (before the pool's cases)."""
    import functools
    import os

    from mpm_fem.app.sweep import Task, run_tasks

    trace = tmp_path / "trace"
    tasks = [Task(slow_square, {"n": n, "trace": str(trace), "sleep": 0.2}, tmp_path / "cache") for n in range(8)]
    run_tasks(tasks[7:], jobs=1, progress=False)  # the last case is cached
    trace.write_text("")
    follow = {0: "after0", 7: "after7"}
    out = run_tasks(tasks, jobs=jobs, progress=False,
                    done=lambda k: functools.partial(note, trace, follow[k]) if k in follow else None)
    assert out == [{"n": n, "square": n * n} for n in range(8)]
    lines = trace.read_text().split()
    notes = {line.split(":")[0]: int(line.split(":")[1]) for line in lines if ":" in line}
    assert set(notes) == {"after0", "after7"}
    cases = [line for line in lines if ":" not in line]
    assert sorted(cases, key=int) == [str(n) for n in range(7)]  # the cached one did not run again
    assert lines.index(f"after7:{notes['after7']}") < lines.index("1")  # ahead of the cases (beside case 0)
    if jobs == 1:
        assert set(notes.values()) == {os.getpid()} and lines.index(f"after0:{os.getpid()}") == lines.index("0") + 1
    else:
        assert os.getpid() not in notes.values()
        # when case 0 ends, cases 1 and 2 are already handed to the pool; 3 .. 6 wait behind the follow-up
        assert lines.index(f"after0:{notes['after0']}") < lines.index("4")


def test_off_a_terminal_a_progress_line_comes_every_tenth_of_the_cases_or_every_plain_every_seconds(
        tmp_path, capsys, monkeypatch):
    """40 cases: a line at 4, 8, ... (every 10 %); with PLAIN_EVERY = 0, a line for every case."""
    from mpm_fem.app import sweep

    cases = [{"n": n, "trace": str(tmp_path / "trace")} for n in range(40)]
    monkeypatch.setattr(sweep.sys.stderr, "isatty", lambda: False, raising=False)
    run_cases(square, cases, jobs=1, progress=True)
    lines = capsys.readouterr().err.splitlines()
    assert lines[0] == "[cases] 40 of 40 cases to run (0 cached)"
    assert [line.split()[1] for line in lines[1:]] == [f"{k}/40" for k in range(4, 41, 4)]
    monkeypatch.setattr(sweep, "PLAIN_EVERY", 0.0)
    run_cases(square, cases, jobs=1, progress=True)
    assert [line.split()[1] for line in capsys.readouterr().err.splitlines()[1:]] == [f"{k}/40" for k in range(1, 41)]


class _Future:
    def __init__(self, done: bool):
        self._done = done

    def done(self) -> bool:
        return self._done


def test_a_group_compiling_its_kernels_is_held_back_until_its_latest_task_ends_or_compile_s_passes():
    """Tasks 0, 1 of group a, 2 of group b: while a's latest task runs (started 1 s ago) the pool takes
    b's task; once it ended, or COMPILE_S after it started, the order again; with every group held
    back, the first task (a worker never idles)."""
    from collections import deque

    from mpm_fem.app.sweep import COMPILE_S, _next_task

    groups = {0: "a", 1: "a", 2: "b"}
    todo = [(0, None), (1, None), (2, None)]
    running = {"a": (100.0, _Future(False))}
    assert _next_task(deque(todo), groups, running, 101.0) == (2, None)
    assert _next_task(deque(todo), groups, {"a": (100.0, _Future(True))}, 101.0) == (0, None)
    assert _next_task(deque(todo), groups, running, 100.0 + COMPILE_S) == (0, None)
    waiting = deque(todo[:2])
    assert _next_task(waiting, groups, running, 101.0) == (0, None) and list(waiting) == [(1, None)]


def test_with_every_group_held_back_the_pool_takes_the_group_with_the_most_ended_tasks():
    """Tasks 0 of group a (one ended task), 1 of group b (five ended): both groups' latest tasks run
    (started 1 s ago), so both may be compiling; the pool takes b's task, whose kernels are the likelier
    compiled, not the first in the order (a second worker compiling a's kernels again)."""
    from collections import deque

    from mpm_fem.app.sweep import _next_task

    groups, todo = {0: "a", 1: "b"}, [(0, None), (1, None)]
    running = {"a": (100.0, _Future(False)), "b": (100.0, _Future(False))}
    waiting = deque(todo)
    assert _next_task(waiting, groups, running, 101.0, {"a": 1, "b": 5}) == (1, None) and list(waiting) == [(0, None)]
    assert _next_task(deque(todo), groups, running, 101.0, {"a": 5, "b": 5}) == (0, None)
    assert _next_task(deque(todo), groups, running, 101.0) == (0, None)


def test_the_kernel_group_is_the_function_and_the_keys_that_choose_kernels():
    from mpm_fem.app.sweep import Task, kernel_group

    sod = {"solver": "mpm", "basis": "mpm", "scheme": "usl", "mass": "lumped", "h": 0.01, "seed": 0}
    assert kernel_group(Task(square, sod)) == kernel_group(Task(square, {**sod, "h": 0.005, "seed": 3}))
    assert kernel_group(Task(square, sod)) != kernel_group(Task(square, {**sod, "basis": "gimp"}))
    assert kernel_group(Task(square, sod)) != kernel_group(Task(cube, sod))


def test_groups_sharing_an_uncached_compile_of_shared_s_or_more_are_one_family():
    """a and b share 1.5 s of uncached variants (one family); c shares 0.5 s with b (below SHARED_S: its own);
    d shares 2 s with a, but cached (its own); e is joined to a through b; f is not in the table (its own).
    With every variant cached, each group is its own family."""
    from mpm_fem.app.compiling import SHARED_S, families

    assert SHARED_S == 1.0
    seconds = {"ab": 1.5, "bc": 0.5, "ad": 2.0, "be": 1.0, "a": 9.0}
    table = {"a": ["a", "ab", "ad"], "b": ["ab", "bc", "be"], "c": ["bc"], "d": ["ad"], "e": ["be"]}
    groups = [(g,) for g in "abcdef"]
    got = families(groups, table, seconds, is_cached=lambda v: v == "ad")
    assert got == {("a",): ("a",), ("b",): ("a",), ("c",): ("c",), ("d",): ("d",), ("e",): ("a",), ("f",): ("f",)}
    assert families(groups, table, seconds, is_cached=lambda v: True) == {g: g for g in groups}
    assert families(groups, table, {**seconds, "ab": 0.9}, is_cached=lambda v: v == "ad")[("b",)] == ("b",)


def negate(case):
    return {"y": -case.get("x", 0)}


def test_the_pool_holds_back_a_family_not_only_a_group(monkeypatch):
    """Two groups (two functions) sharing an uncached compile: while the first's task may compile, the pool
    starts a task of a third group, not the second's (it would compile the shared variants again)."""
    import mpm_fem.app.sweep as sweep

    started = []

    class Pool:
        def __init__(self, **_):
            pass

        def submit(self, fn, *args):
            started.append(args[0].__name__ if args else "followup")
            return _Future(False)

        def shutdown(self, **_):
            pass

    from functools import partial

    from mpm_fem.app.compiling import families

    table = {"|".join(sweep.kernel_group(sweep.Task(f, {}))): ["shared"] for f in (square, cube)}
    monkeypatch.setattr(sweep, "families", partial(families, table=table, seconds={"shared": 5.0},
                                                   is_cached=lambda v: False))
    monkeypatch.setattr(sweep, "ProcessPoolExecutor", Pool)
    class Started(Exception):
        """Raised where the pool would wait: the first two tasks have started."""

    def wait(running, return_when):
        raise Started

    monkeypatch.setattr(sweep, "wait", wait)
    tasks = [sweep.Task(square, {}), sweep.Task(cube, {}), sweep.Task(negate, {})]
    with pytest.raises(Started):
        sweep._run_pool(tasks, [(0, None), (1, None), (2, None)], 1, lambda *a: None)
    assert started == ["square", "negate"]
