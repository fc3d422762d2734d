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
    for basis in ("bspline", "bspline_gimp"):  # a B-spline budget at 0.00125 costs three P1 ones
        assert ("sod", 0.00125, basis) in budget.plan("deep")["budget"]
        assert ("sod", 0.00125, basis) not in budget.plan("full")["budget"]
        assert ("sod", 0.0025, basis) in budget.plan("full")["budget"]
    assert ("sod", 0.00125, "mpm") in budget.plan("full")["budget"]
    assert ("sod", 0.00125, "gimp") in budget.plan("deep")["budget"]
    assert ("sod", 0.00125, "gimp") not in budget.plan("full")["budget"]


def test_the_roundoff_rerun_is_deep_on_every_mesh_full_on_the_coarser_quick_never():
    budget = importlib.import_module("studies.budget")
    meshes = {tier: sorted(h for _, h, _ in budget.plan(tier)["roundoff"]) for tier in ("quick", "full", "deep")}
    assert meshes["quick"] == [] and meshes["full"] == sorted(budget.ROUNDOFF_H)
    assert meshes["deep"] == sorted(set(budget.H["sod"]) | {0.000625})
    assert all(c["kernel"] == "numpy" for c in budget.plan("deep")["roundoff"].values())


def test_the_quick_tier_compiles_no_remedy_and_no_second_basis():
    """What each fused variant costs to compile is in docs/performance.md: the quick tier runs the drift
    and remedies studies on the numpy step and the time study on P1 alone."""
    drift, remedies, time = (importlib.import_module(f"studies.{n}") for n in ("drift", "remedies", "time"))
    assert {c["kernel"] for c in drift._plan("quick")["drift"].values()} == {"numpy"}
    assert {c["kernel"] for c in drift._plan("full")["drift"].values()} == {"fused", "numpy"}
    mpm = [c for g in ("sod", "burgers") for c in remedies._plan("quick")[g].values()]
    assert len(mpm) == 24 and {c["kernel"] for c in mpm} == {"numpy"}
    assert {c["basis"] for c in time.plan("quick")["time"].values()} == {"mpm"}


def test_a_study_runs_one_tier():
    assert StudyOptions().tier == "full" and StudyOptions(quick=True).tier == "quick"
    assert StudyOptions(deep=True).tier == "deep"
    with pytest.raises(ValueError, match="one tier"):
        StudyOptions(quick=True, deep=True)


@pytest.mark.parametrize("argv, tier", [(["reproduce"], "quick"), (["reproduce", "--full"], "full"),
                                        (["reproduce", "--deep"], "deep"), (["study", "sod"], "quick"),
                                        (["study", "sod", "--full"], "full"), (["study", "sod", "--deep"], "deep")])
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


def test_the_quick_reproduction_leaves_out_the_plateau_studies_and_says_so(tmp_path, monkeypatch):
    """Remedies and drift ask about Sod's plateau, below the quick meshes: the quick ``reproduce`` runs
    neither (``mpm-fem study NAME --quick`` still does), the full and deep ones run every study."""
    from mpm_fem.app import report, study

    assert study.reproduced("quick") == ("projection", "sod", "burgers", "budget", "time")
    assert study.reproduced("full") == study.reproduced("deep") == study.STUDIES
    started = []
    monkeypatch.setattr(study, "run_study", lambda name, options: started.append(name))
    monkeypatch.setattr(report, "write_report", lambda out: out)
    monkeypatch.setattr("mpm_fem.app.estimate.tasks", lambda name, options: [])
    report.reproduce(StudyOptions(quick=True, out=tmp_path, jobs=1, progress=False))
    assert started == list(study.reproduced("quick"))
    text = "\n".join(report.caveats({"versions": [{"table": "sod/convergence", "code": "x", "tier": "quick"}]}, "x"))
    assert "leaves out the studies remedies and drift" in text
    # every verdict the quick tier does not judge, with the tier that does
    assert "The quick tier does not judge E2 (the full tier does: " in text and "; E5 (the full tier does: " in text
