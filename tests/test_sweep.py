"""Sweeps: parallel equals serial, finished cases are cached and never recomputed."""

import json

import pytest

from mpm_fem.sweep import case_key, run_cases


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
