"""The three tiers of a reproduction: quick, full and deep (``mpm_fem.app.study.TIERS``)."""

from __future__ import annotations

import importlib
from pathlib import Path

import pytest

from mpm_fem.app.cli import build_parser
from mpm_fem.app.study import STUDIES, TIER_FOLDERS, StudyOptions, study_options

PLANS = {"sod": "_plan", "burgers": "_plan", "budget": "plan", "remedies": "_plan", "time": "plan", "drift": "_plan"}


def _cases(plan: dict) -> set:
    return {repr(sorted(case.items())) for group in plan.values() for case in group.values()}


@pytest.mark.parametrize("name", sorted(PLANS))
def test_the_deep_plan_holds_every_case_of_the_full_plan(name):
    make = getattr(importlib.import_module(f"studies.{name}"), PLANS[name])
    full, deep = _cases(make("full")), _cases(make("deep"))
    assert full <= deep, f"{len(full - deep)} full cases missing from the deep plan of {name}"
    if name in ("sod", "burgers", "budget", "drift"):  # the finest meshes moved to the deep tier
        assert len(deep) > len(full), name


def test_the_finest_meshes_are_deep_only():
    sod, budget = importlib.import_module("studies.sod"), importlib.import_module("studies.budget")
    assert 0.000078125 in {c["h"] for c in sod._plan("deep")["mpm"].values()}
    assert 0.000078125 not in {c["h"] for c in sod._plan("full")["mpm"].values()}
    assert ("sod", 0.000625, "mpm") in budget.plan("deep")["budget"]
    assert ("sod", 0.000625, "mpm") not in budget.plan("full")["budget"]


def test_a_study_runs_one_tier():
    assert StudyOptions().tier == "full" and StudyOptions(quick=True).tier == "quick"
    assert StudyOptions(deep=True).tier == "deep"
    with pytest.raises(ValueError, match="one tier"):
        StudyOptions(quick=True, deep=True)


@pytest.mark.parametrize("argv, tier", [(["reproduce"], "quick"), (["reproduce", "--full"], "full"),
                                        (["reproduce", "--deep"], "deep"), (["study", "sod"], "full"),
                                        (["study", "sod", "--quick"], "quick"), (["study", "sod", "--deep"], "deep")])
def test_the_command_line_picks_the_tier_and_its_folder(argv, tier, monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    options = study_options(build_parser().parse_args(argv))
    assert options.tier == tier and Path(options.out) == TIER_FOLDERS[tier]
    # the deep tier reads the full tier's finished cases; the others their own
    expected_cache = TIER_FOLDERS["full"] if tier == "deep" else TIER_FOLDERS[tier]
    assert options.cache_dir("sod") == expected_cache / "sod" / ".cache"


def test_tiers_are_exclusive_on_the_command_line(capsys):
    with pytest.raises(SystemExit):
        build_parser().parse_args(["reproduce", "--quick", "--deep"])
    assert "not allowed with" in capsys.readouterr().err


def test_every_study_has_a_plan_per_tier():
    assert set(PLANS) | {"projection"} == set(STUDIES)


def test_the_estimate_counts_the_cached_cases_and_grows_with_the_tier(tmp_path):
    from mpm_fem.app.estimate import describe, estimate
    from mpm_fem.app.sweep import case_key

    full, deep = StudyOptions(out=tmp_path), StudyOptions(deep=True, out=tmp_path)
    e_full, e_deep = estimate("budget", full), estimate("budget", deep)
    assert e_full.cached == 0 and e_deep.cases > e_full.cases and e_deep.seconds > e_full.seconds > 0
    assert e_full.wall(1) == e_full.seconds and e_full.wall(10**6) == e_full.longest
    module = importlib.import_module("studies.budget")
    case = next(iter(module.plan("full")["budget"].values()))
    cache = full.cache_dir("budget")
    cache.mkdir(parents=True)
    (cache / f"{case_key(module.run_case, case)}.json").write_text("{}")
    again = estimate("budget", full)
    assert again.cached == 1 and again.seconds < e_full.seconds
    line = describe({"budget": again, "other": None}, 2)
    assert "budget: 49 of 50 cases to run" in line.replace(f"{again.cases - 1} of {again.cases}", "49 of 50")
    assert "other: no cost model" in line
