"""The estimates count numba's compiles of the variants its cache lacks; the time left blends model and rate."""

import importlib
import re
import sys

import numpy as np
import pytest

from mpm_fem.app import compile_times, compiling
from mpm_fem.app.estimate import compile_seconds, estimate, tasks
from mpm_fem.app.study import StudyOptions
from mpm_fem.app.sweep import Task, kernel_group, time_left


def toy_case(case: dict) -> dict:
    """A sweep's case whose only kernel is the toy one (its group is priced by the test's table)."""
    return {"value": sys.modules["toy_compiled"].twice(case["x"])}


def test_a_variant_counts_until_numba_caches_it_and_again_when_its_source_changes(tmp_path, monkeypatch):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "numba"))
    source = tmp_path / "toy_compiled.py"
    source.write_text("from numba import njit\n\n\n@njit(cache=True)\ndef twice(x):\n    return 2 * x\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    variant = f"{source}::toy_compiled.twice"
    task = Task(toy_case, {"x": 2})
    monkeypatch.setattr(compile_times, "SECONDS", {variant: 7.5})
    monkeypatch.setattr(compile_times, "GROUPS", {"|".join(kernel_group(task)): [variant]})
    try:
        assert not compiling.cached(variant) and compile_seconds([task]) == 7.5
        importlib.import_module("toy_compiled")  # after numba has read NUMBA_CACHE_DIR again (cached does)
        assert toy_case({"x": 2}) == {"value": 4}  # numba compiles twice and writes its cache
        got = compile_seconds([task])
        assert compiling.cached(variant) and got == 0.0, got
        source.write_text(source.read_text() + "\n# edited\n")  # numba's stamp no longer matches
        assert not compiling.cached(variant) and compile_seconds([task]) == 7.5
        seen = set()
        assert compile_seconds([task], seen) == 7.5 and compile_seconds([task], seen) == 0.0  # priced once
    finally:
        sys.modules.pop("toy_compiled", None)


def _fill(variants) -> None:
    """Index files as numba writes them for ``variants`` (no compile): a cache that holds them."""
    import numba
    from numba.core.caching import IndexDataCacheFile, UserProvidedCacheLocator

    for variant in variants:
        name, _, stem = variant.partition("::")
        source = compiling.ROOT / name
        locator = object.__new__(UserProvidedCacheLocator)
        locator._py_file = str(source)
        folder = compiling.cache_folder(source)
        folder.mkdir(parents=True, exist_ok=True)
        base = f"{stem.replace('{digest}', compiling._digest())}-1.py{sys.version_info[0]}{sys.version_info[1]}" \
               f"{getattr(sys, 'abiflags', '')}"
        IndexDataCacheFile(str(folder), base, locator.get_source_stamp())._save_index({})
    assert numba.__version__


def test_an_empty_cache_adds_the_measured_compile_of_the_studys_variants(tmp_path, monkeypatch):
    """The Sod study's quick tier, a table giving each of its kernel groups two variants (one shared with
    the next group) and their seconds: from an empty numba cache its estimate is larger than from a cache
    that holds every variant by the seconds of the variants, each counted once."""
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "numba"))
    options = StudyOptions(quick=True, out=tmp_path / "figures")
    groups = sorted({"|".join(kernel_group(t)) for _, t in tasks("sod", options)})
    name = "mpm_fem/fused/loop.py::loop._advance_test{k}_{{digest}}"
    table = {g: [name.format(k=k), name.format(k=k + 1)] for k, g in enumerate(groups)}
    seconds = {name.format(k=k): 2.0 + k for k in range(len(groups) + 1)}
    monkeypatch.setattr(compile_times, "GROUPS", table)
    monkeypatch.setattr(compile_times, "SECONDS", seconds)
    measured = sum(seconds.values())
    cold = estimate("sod", options)
    _fill(seconds)
    warm = estimate("sod", options)
    assert len(groups) >= 3 and warm.compile == 0.0, (groups, warm)
    assert cold.compile == pytest.approx(measured) and cold.seconds - warm.seconds == pytest.approx(measured), (
        cold, warm, measured)
    one = compile_seconds([t for _, t in tasks("sod", options)][:1])
    assert one == 0.0  # the filled cache holds them


def _seconds(line: str) -> float:
    number, unit = re.fullmatch(r"about (\d+) (s|min) left", line).groups()
    return float(number) * (60 if unit == "min" else 1)


def test_the_blended_time_left_does_not_swing_past_two_after_a_tenth():
    """200 cases whose cost model is off by a factor 0.6-1.6 and each case by a lognormal factor (sigma 0.5),
    the first four compiling kernels 0.5-2 times the model's compile: once a tenth of the cost has run, the
    total the line implies (time so far + time left) stays within a factor 2 of the true total, and of
    itself; the line before (the measured rate alone, the costs without the compiles) swings past 2."""
    rng = np.random.default_rng(7)
    blended, rate = [], []
    for _ in range(40):
        cost = np.sort(rng.lognormal(0.0, 1.0, 200))[::-1]
        took = cost * rng.lognormal(0.0, 0.5, cost.size) * rng.uniform(0.6, 1.6)
        compile_s, plain = 0.5 * cost.sum(), np.cumsum(cost)
        cost[:4] += compile_s / 4
        took[:4] += compile_s * rng.uniform(0.5, 2.0) / 4
        elapsed, ran, total = np.cumsum(took), np.cumsum(cost), cost.sum()
        after = [i for i in range(cost.size - 1) if ran[i] >= 0.1 * total]
        implied = np.array([elapsed[i] + _seconds(time_left(elapsed[i], ran[i], total - ran[i], total - ran[i]))
                            for i in after])
        by_rate = np.array([elapsed[i] + _seconds(time_left(elapsed[i], plain[i], plain[-1] - plain[i]))
                            for i in range(cost.size - 1) if plain[i] >= 0.1 * plain[-1]])
        blended.append(max(implied.max() / implied.min(), implied.max() / elapsed[-1], elapsed[-1] / implied.min()))
        rate.append(by_rate.max() / by_rate.min())
    assert max(blended) < 2.0, max(blended)
    assert max(rate) > 2.0, max(rate)


def test_the_costliest_case_of_each_compiling_group_carries_the_compile(tmp_path, monkeypatch):
    """The Sod study's quick tier, a table giving each kernel group one variant of its own: from an empty
    numba cache one case per group carries a compile (:func:`mpm_fem.app.case_tasks.compiles`), its costliest;
    from a cache that holds them none does."""
    from mpm_fem.app.case_tasks import compiles
    from mpm_fem.app.case_tasks import tasks as case_tasks

    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "numba"))
    options = StudyOptions(quick=True, out=tmp_path / "figures")
    found = case_tasks("sod", options)
    groups = sorted({"|".join(kernel_group(t)) for _, t in found})
    name = "mpm_fem/fused/loop.py::loop._advance_carry{k}_{{digest}}"
    monkeypatch.setattr(compile_times, "GROUPS", {g: [name.format(k=k)] for k, g in enumerate(groups)})
    monkeypatch.setattr(compile_times, "SECONDS", {name.format(k=k): 3.0 for k in range(len(groups))})
    found = case_tasks("sod", options)
    carried = compiles("sod", options, found)
    assert len(carried) == len(found) and sum(carried) == len(groups) >= 3
    for group in groups:
        mine = [(s, c) for (s, t), c in zip(found, carried, strict=True) if "|".join(kernel_group(t)) == group]
        assert [c for _, c in mine].count(True) == 1 and max(mine)[1], (group, mine)
    _fill([name.format(k=k) for k in range(len(groups))])
    assert not any(compiles("sod", options, case_tasks("sod", options)))
