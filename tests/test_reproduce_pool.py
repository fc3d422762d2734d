"""``reproduce`` runs every study's cases in one pool, the longest first, and writes a study's tables
as soon as its last case is in (fake studies: the pool and the order, not the numerics)."""

from __future__ import annotations

from mpm_fem.app import case_tasks, report, study
from mpm_fem.app.study import StudyOptions
from mpm_fem.app.sweep import Task


def square(case):
    with open(case["trace"], "a") as f:
        f.write(f"{case['n']}\n")
    return {"square": case["n"] ** 2}


def test_each_study_is_written_once_after_its_last_case_the_cheapest_study_first(tmp_path, monkeypatch):
    trace = tmp_path / "trace"
    cost = {"a": (3.0, 1.0), "b": (2.0,), "c": ()}  # estimated seconds of each study's cases; c has none

    def tasks(name, options, seen=None):
        return [(s, Task(square, {"n": int(10 * s) + ord(name), "trace": str(trace)}, tmp_path / name))
                for s in cost[name]]

    written = []

    def run_study(name, options):
        cached = {p.name for p in (tmp_path / name).glob("*.json")} if (tmp_path / name).exists() else set()
        written.append((name, len(cached)))
        return name

    monkeypatch.setattr(study, "STUDIES", tuple(cost))
    monkeypatch.setattr(study, "run_study", run_study)
    monkeypatch.setattr(case_tasks, "tasks", tasks)
    monkeypatch.setattr(case_tasks, "compiles", lambda name, options, priced: None)
    monkeypatch.setattr(report, "write_report", lambda out: out)
    report.reproduce(StudyOptions(out=tmp_path, jobs=1, progress=False))
    started = [int(n) for n in trace.read_text().split()]
    # the cheaper study first (b: 2 s, a: 4 s), each study's cases the longest first
    assert started == [20 + ord("b"), 30 + ord("a"), 10 + ord("a")]
    assert written == [("b", 1), ("a", 2), ("c", 0)]  # each once, with all its cases in; c (no case) last
    written.clear()
    report.reproduce(StudyOptions(out=tmp_path, jobs=1, progress=False))  # all cached: every study at once
    assert sorted(written) == [("a", 2), ("b", 1), ("c", 0)] and len(trace.read_text().split()) == 3


def test_the_cases_that_compile_start_first_the_longest_first(tmp_path, monkeypatch):
    """Study a's 1-s case and study c's 0.5-s case compile kernels (:func:`mpm_fem.app.case_tasks.compiles`):
    they start first, the longer first, ahead of the cheaper study b; then the studies in order of their cost."""
    trace = tmp_path / "trace"
    cost = {"a": (3.0, 1.0), "b": (2.0,), "c": (0.5, 0.25)}
    carries = {"a": [False, True], "b": [False], "c": [True, False]}

    def tasks(name, options, seen=None):
        return [(s, Task(square, {"n": int(100 * s) + ord(name), "trace": str(trace)}, tmp_path / name))
                for s in cost[name]]

    monkeypatch.setattr(study, "STUDIES", tuple(cost))
    monkeypatch.setattr(study, "run_study", lambda name, options: name)
    monkeypatch.setattr(case_tasks, "tasks", tasks)
    monkeypatch.setattr(case_tasks, "compiles", lambda name, options, priced: carries[name])
    monkeypatch.setattr(report, "write_report", lambda out: out)
    report.reproduce(StudyOptions(out=tmp_path, jobs=1, progress=False))
    started = [int(n) for n in trace.read_text().split()]
    assert started == [100 + ord("a"), 50 + ord("c"), 25 + ord("c"), 200 + ord("b"), 300 + ord("a")]


def test_a_variant_two_studies_share_is_priced_once(tmp_path, monkeypatch):
    """``reproduce`` hands every study's estimate one set of the variants priced already, and every study's
    tasks another, so that a kernel two studies run through is priced in the first that meets it; the compile
    carriers are read from the tasks as priced."""
    calls = {"estimate": [], "tasks": []}
    got_priced = []

    def recorder(kind, result):
        def call(name, options, seen=None):
            calls[kind].append((name, id(seen), set(seen)))
            seen.add(name)
            return result(name)
        return call

    def compiles(name, options, priced):
        got_priced.append((name, priced))
        return [False] * len(priced)

    monkeypatch.setattr(study, "STUDIES", ("a", "b"))
    monkeypatch.setattr(study, "run_study", lambda name, options: name)
    monkeypatch.setattr(case_tasks, "estimate", recorder("estimate", lambda name: None))
    monkeypatch.setattr(case_tasks, "tasks", recorder("tasks", lambda name: [(1.0, Task(square, {"n": ord(name),
                                                      "trace": str(tmp_path / "trace")}, tmp_path / name))]))
    monkeypatch.setattr(case_tasks, "compiles", compiles)
    monkeypatch.setattr(report, "write_report", lambda out: out)
    report.reproduce(StudyOptions(out=tmp_path, jobs=1, progress=None))
    for kind, got in calls.items():
        assert [(name, before) for name, _, before in got] == [("a", set()), ("b", {"a"})], kind
        assert got[0][1] == got[1][1], kind
    assert calls["estimate"][0][1] != calls["tasks"][0][1]
    assert [(name, [t.case["n"] for _, t in priced]) for name, priced in got_priced] == [("a", [97]), ("b", [98])]


def write_study(name, options):
    """A study's tables and figures, faked: which study, how many of its cases were cached, which process."""
    import os

    folder = options.out / name
    cached = len(list(folder.glob("*.json"))) if folder.exists() else 0
    with open(options.out / "written", "a") as f:
        f.write(f"{name} {cached} {os.getpid()} {options.jobs}\n")
    return name


def test_with_two_workers_a_worker_writes_each_study_once_its_cases_are_in(tmp_path, monkeypatch):
    """The pool's follow-ups (:func:`mpm_fem.app.sweep.run_tasks`): each study is written once, by a worker
    (not this process), with every case of it in the cache, and with one job (it runs no case then)."""
    import os

    trace = tmp_path / "trace"
    cost = {"a": (3.0, 1.0, 0.5), "b": (2.0,), "c": ()}

    def tasks(name, options, seen=None):
        return [(s, Task(square, {"n": int(10 * s) + ord(name), "trace": str(trace)}, tmp_path / name))
                for s in cost[name]]

    monkeypatch.setattr(study, "STUDIES", tuple(cost))
    monkeypatch.setattr(study, "run_study", write_study)
    monkeypatch.setattr(case_tasks, "tasks", tasks)
    monkeypatch.setattr(case_tasks, "compiles", lambda name, options, priced: None)
    monkeypatch.setattr(report, "write_report", lambda out: out)
    report.reproduce(StudyOptions(out=tmp_path, jobs=2, progress=False))
    written = [line.split() for line in (tmp_path / "written").read_text().splitlines()]
    by_study = {name: (int(cached), int(pid), jobs) for name, cached, pid, jobs in written}
    assert sorted(name for name, *_ in written) == ["a", "b", "c"]  # each once
    assert by_study["a"][0] == 3 and by_study["b"][0] == 1  # after all its cases
    assert by_study["a"][1] != os.getpid() and by_study["b"][1] != os.getpid()  # in a worker
    assert by_study["a"][2] == by_study["b"][2] == "1"  # it would run a missing case itself, not start a pool
