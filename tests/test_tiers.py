"""The three tiers of a reproduction: quick, full and deep (``mpm_fem.app.study.TIERS``)."""

from __future__ import annotations

import importlib
from pathlib import Path

import pytest

from mpm_fem.app.cli import build_parser
from mpm_fem.app.study import STUDIES, TIER_FOLDERS, StudyOptions, study_options

PLANS = {"sod": "_plan", "burgers": "_plan", "budget": "plan", "remedies": "_plan", "time": "plan", "drift": "_plan",
         "defect": "plan",
         "mechanism": "plan", "lumping": "plan", "plane": "plan", "plane_projection": "plan"}


def _cases(plan: dict) -> set:
    return {repr(sorted(case.items())) for group in plan.values() for case in group.values()}


@pytest.mark.parametrize("name", sorted(PLANS))
def test_the_deep_plan_holds_every_case_of_the_full_plan(name):
    make = getattr(importlib.import_module(f"studies.{name}"), PLANS[name])
    full, deep = _cases(make("full")), _cases(make("deep"))
    assert full <= deep, f"{len(full - deep)} full cases missing from the deep plan of {name}"
    if name in ("sod", "burgers", "budget", "drift", "mechanism"):  # the finest meshes moved to the deep tier
        assert len(deep) > len(full), name


def test_the_finest_meshes_are_deep_only():
    sod, budget = importlib.import_module("studies.sod"), importlib.import_module("studies.budget")
    assert 0.000078125 in {c["h"] for c in sod._plan("deep")["mpm"].values()}
    assert {0.000078125, 0.00015625}.isdisjoint(c["h"] for c in sod._plan("full")["mpm"].values())
    assert ("sod", 0.000625, "mpm") in budget.plan("deep")["budget"]
    assert ("sod", 0.000625, "mpm") not in budget.plan("full")["budget"]
    for basis in ("bspline", "bspline_gimp"):  # a B-spline budget at 0.00125 costs three P1 ones
        assert ("sod", 0.00125, basis) in budget.plan("deep")["budget"]
        assert ("sod", 0.00125, basis) not in budget.plan("full")["budget"]
        assert ("sod", 0.0025, basis) in budget.plan("full")["budget"]
    for basis in ("mpm", "gimp"):
        assert ("sod", 0.00125, basis) in budget.plan("deep")["budget"]
        assert ("sod", 0.00125, basis) not in budget.plan("full")["budget"]


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
    assert set(PLANS) | {"projection", "identification"} == set(STUDIES)  # identification: PLANS, by study


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
    assert again.measured == 0.0 and "took" not in line  # a cache file without its CPU time counts nothing
    (cache / f"{case_key(module.run_case, case)}.json").write_text('{"cpu_s": 90.0}')
    line = describe({"budget": estimate("budget", full)}, 2)
    assert "the cached cases took 1.5 CPU-min when they ran" in line and "(the 1 cached took 1.5 CPU-min" in line


def test_the_quick_reproduction_leaves_out_the_plateau_studies_and_says_so(tmp_path, monkeypatch):
    """Remedies and drift ask about Sod's plateau, below the quick meshes, and the budget's exact-stage kernels
    cost a minute to compile: the quick ``reproduce`` runs none of them (``mpm-fem study NAME --quick`` still
    does) but the mechanism study's small stage-exact set on the numpy step; the full and deep ones run every
    study."""
    from mpm_fem.app import report, study

    assert study.reproduced("quick") == ("projection", "sod", "burgers", "identification", "time", "mechanism",
                                         "lumping", "plane", "plane_projection")
    assert study.reproduced("full") == study.reproduced("deep") == study.STUDIES
    started = []
    monkeypatch.setattr(study, "run_study", lambda name, options: started.append(name))
    monkeypatch.setattr(report, "write_report", lambda out: out)
    monkeypatch.setattr("mpm_fem.app.case_tasks.tasks", lambda name, options, seen=None: [])
    monkeypatch.setattr("mpm_fem.app.case_tasks.compiles", lambda name, options, priced: [])
    report.reproduce(StudyOptions(quick=True, out=tmp_path, jobs=1, progress=False))
    assert started == list(study.reproduced("quick"))
    text = "\n".join(report.caveats({"versions": [{"table": "sod/convergence", "code": "x", "tier": "quick"}]}, "x"))
    assert "leaves out the studies remedies, drift, budget" in text
    # every verdict the quick tier does not judge, with the tier that does
    assert "The quick tier does not judge " in text and "E2 (the full tier does: " in text
    assert all(f"{c} (the full tier does: " in text for c in ("E5", "E1 (sod)", "C15 (burgers)"))


# ----------------------------------------------------------------------------- quick answers the question

def test_the_quick_plan_runs_c11s_setting_on_the_meshes_and_runs_c11_needs():
    """The cheapest setting the source states (4 per cell, CFL 0.1) on at least FLOOR_MESHES meshes with
    MIN_RUNS runs each (the rule book's numbers, the same for every tier), and no other setting of the
    source's 4-8 per cell whose fewer meshes would leave its verdict not measured."""
    from mpm_fem.measure.claims.sod import FLOOR_MESHES, MIN_RUNS, _prescribed

    sod = importlib.import_module("studies.sod")
    plan = sod._plan("quick")
    c11 = (4, 0.1)
    assert {k[:2] for k in plan["settings"] if _prescribed(k[0])} == {c11}
    meshes = {h: 1 for n, cfl, h in plan["settings"] if (n, cfl) == c11}
    for n, cfl, h, _ in plan["seeds"]:
        if (n, cfl) == c11:
            meshes[h] += 1
    assert sum(runs >= MIN_RUNS for runs in meshes.values()) >= FLOOR_MESHES
    assert max(meshes) == 0.01 and min(meshes) == 0.000625
    assert set(meshes) <= set(plan["fem_lumped"]) and set(meshes) <= set(plan["fv"])  # E3 and the figure


def test_the_quick_identification_reruns_c13s_setting_on_two_meshes_every_eps_and_a_seed():
    """C13 is judged at the identified Burgers setting's reruns (``identification/identified``): in the quick
    tier as in the full one, both rows on two meshes, every eps on the regular layout and the largest eps on
    the jittered seeds, so that the criterion has two meshes per run (fake measurements: the plan, not the
    numerics)."""
    from types import SimpleNamespace

    identification = importlib.import_module("studies.identification")
    calls = []

    def measure(row, solution, params, ppc, cfl, eps, hs, **changes):
        calls.append((row, tuple(eps), tuple(hs), changes.get("seed", 0)))
        return {(e, h): {"ok": True, "nodes": {"L1": h}, "particles": {"L1": h}} for e in eps for h in hs}

    fit = SimpleNamespace(solution="rarefaction", params={}, ppc=4, cfl={"exact": 0.1, "calculated": 0.3},
                          readout="nodes", norm="L1")
    rows = identification._burgers_identified(measure, fit, "identified", "quick")
    meshes = identification.IDENTIFIED_MESHES["quick"]
    assert len(meshes) >= 2
    assert {r for r, *_ in calls} == {"exact", "calculated"}
    for row in ("exact", "calculated"):
        regular = [c for c in calls if c[0] == row and c[3] == 0]
        assert regular == [(row, identification.EPS, meshes, 0)]
        jittered = sorted(c[3] for c in calls if c[0] == row and c[3])
        assert jittered == sorted(identification.QUICK["seeds"]) and jittered
    assert len(rows) == 2 * len(meshes) * (len(identification.EPS) + len(identification.QUICK["seeds"]))


def test_the_criteria_never_read_the_tier():
    """The rule book is the same for every tier: no criterion but E4 (which checks that every table is of
    one tier) names the tier, and flipping every table's tier leaves every other verdict as it was."""
    import ast

    from claim_mutations import TABLES

    from mpm_fem.measure.claims import CLAIMS

    package = Path(importlib.import_module("mpm_fem.measure.claims").__file__).parent
    for path in sorted(package.glob("*.py")):
        if path.name == "reproduce.py":
            continue
        tree = ast.parse(path.read_text())
        docstrings = {id(n.body[0].value) for n in ast.walk(tree) if isinstance(n, (ast.Module, ast.FunctionDef,
                                                                                   ast.ClassDef))
                      and n.body and isinstance(n.body[0], ast.Expr)}
        words = [n.value for n in ast.walk(tree) if isinstance(n, ast.Constant) and isinstance(n.value, str)
                 and id(n) not in docstrings and n.value in ("tier", "quick", "full", "deep")]
        names = [n.id for n in ast.walk(tree) if isinstance(n, ast.Name) and "tier" in n.id.lower()]
        names += [n.attr for n in ast.walk(tree) if isinstance(n, ast.Attribute) and "tier" in n.attr.lower()]
        assert not words and not names, (path.name, words, names)
    flipped = {**TABLES, "versions": [{**r, "tier": "quick", "quick": "True"} for r in TABLES["versions"]],
               "settings": [{**r, "value": {"tier": "quick", "quick": "True"}.get(r["key"], r["value"])}
                            for r in TABLES["settings"]]}
    assert flipped["versions"] != TABLES["versions"]
    for c in CLAIMS:
        if c.id != "E4":
            assert c.verdict(flipped) == c.verdict(TABLES), c.label


# ----------------------------------------------------------------------------- tiers are safe

def _folder(tmp_path, tier: str, *tables: str) -> Path:
    from mpm_fem.app.study import write_table

    for table in tables:
        study, name = table.split("/")
        (tmp_path / study).mkdir(parents=True, exist_ok=True)
        write_table(tmp_path / study, name, [{"h": 0.01, "error": 1.0}], {"x": 1}, tier=tier)
    return tmp_path


def _hashes(folder: Path) -> dict:
    import hashlib

    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def test_every_table_records_the_tier_of_the_study_that_wrote_it(tmp_path, monkeypatch):
    import json
    import sys
    import types

    from mpm_fem.app import study
    from mpm_fem.measure.tables import load_tables

    fake = types.ModuleType("studies.fake")
    fake.run = lambda options: study.publish(options.folder("fake"), {"t": [{"a": 1}]}, {})
    monkeypatch.setitem(sys.modules, "studies.fake", fake)
    for tier in ("quick", "full", "deep"):
        out = tmp_path / tier
        study.run_study("fake", StudyOptions(quick=tier == "quick", deep=tier == "deep", out=out))
        assert json.loads((out / "fake" / "t.json").read_text())["tier"] == tier
        assert load_tables(out)["versions"][0]["tier"] == tier
    study.write_table(tmp_path, "outside", [{"a": 1}], {})  # outside a study run: no tier recorded
    assert "tier" not in json.loads((tmp_path / "outside.json").read_text())


def test_a_table_written_before_the_stamp_reads_its_tier_from_its_settings_or_counts_as_another():
    from mpm_fem.measure.tables import UNSTAMPED, table_tier

    assert table_tier({"settings": {"quick": False}}) == "full"  # the committed record's tables
    assert table_tier({"settings": {"quick": True}}) == "quick"
    assert table_tier({"settings": {"quick": False, "tier": "deep"}}) == "deep"
    assert table_tier({"tier": "quick", "settings": {"quick": False}}) == "quick"
    assert table_tier({"settings": {}}) == table_tier({}) == UNSTAMPED


def test_the_committed_record_reads_as_one_tier():
    from mpm_fem.measure.tables import tiers

    figures = Path(__file__).resolve().parent.parent / "figures"
    assert set(tiers(figures).values()) == {"full"}
    assert set(tiers(figures / "deep").values()) <= {"deep", "full"}


def test_a_folder_with_a_flipped_tier_makes_e4_refuted(tmp_path):
    import json

    from claim_mutations import claim_named

    from mpm_fem.measure.tables import load_tables

    folder = _folder(tmp_path, "full", "sod/convergence", "sod/seeds", "burgers/orders")
    verdict, evidence = claim_named("E4").verdict(load_tables(folder))
    assert verdict == "partly" and "3 of the full tier" in evidence  # one tier; other tables missing
    path = folder / "sod" / "seeds.json"
    meta = json.loads(path.read_text())
    path.write_text(json.dumps({**meta, "tier": "quick"}))
    verdict, evidence = claim_named("E4").verdict(load_tables(folder))
    assert verdict == "refuted" and "other tiers: sod/seeds (quick)" in evidence


@pytest.mark.parametrize("argv", [["study", "sod", "--quick"], ["study", "sod"], ["reproduce"],
                                  ["reproduce", "--deep"]])
def test_writing_into_a_folder_of_another_tier_is_refused_in_one_line_and_changes_nothing(argv, tmp_path, capsys):
    """A copy of the committed record (full tier): the quick and deep tiers are refused before any case
    runs (no cache folder appears), exit status 2, every file as it was."""
    import shutil

    from mpm_fem.app.cli import main

    figures = Path(__file__).resolve().parent.parent / "figures"
    copy = tmp_path / "figures"
    shutil.copytree(figures, copy, ignore=shutil.ignore_patterns(".cache", "*.png", "deep"))
    before = _hashes(copy)
    assert main([*argv, "--out", str(copy)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "tier" in err and "--overwrite" in err, err
    assert _hashes(copy) == before and not (copy / "sod" / ".cache").exists()


def test_overwrite_replaces_the_tables_of_the_other_tier_and_keeps_the_cases(tmp_path):
    from mpm_fem.app.guard import UsageError
    from mpm_fem.app.study import check_folder
    from mpm_fem.measure.tables import tiers

    folder = _folder(tmp_path, "full", "sod/convergence", "sod/plateau", "burgers/orders")
    (folder / "sod" / ".cache").mkdir()
    (folder / "sod" / ".cache" / "case.json").write_text("{}")
    check_folder(StudyOptions(out=folder))  # the same tier: nothing to say
    with pytest.raises(UsageError, match="holds 3 tables of the full tier"):
        check_folder(StudyOptions(quick=True, out=folder))
    check_folder(StudyOptions(quick=True, out=folder, overwrite=True), ("sod",))
    assert tiers(folder) == {"burgers/orders": "full"}  # the study's own folder only
    assert (folder / "sod" / ".cache" / "case.json").exists()
    check_folder(StudyOptions(quick=True, out=folder, overwrite=True))  # reproduce: every study's
    assert tiers(folder) == {}


def test_study_prints_its_estimate_before_it_starts(tmp_path, monkeypatch, capsys):
    from mpm_fem.app import study

    started = []
    monkeypatch.setattr(study, "run_study", lambda name, options: started.append(name) or "done")
    assert study.start_study("budget", StudyOptions(quick=True, out=tmp_path)) == "done"
    err = capsys.readouterr().err
    assert started == ["budget"] and err.startswith("estimated ~") and "budget: " in err and "cases to run" in err


def test_the_report_names_what_the_full_tier_leaves_to_the_deep_one():
    """The runs moved out of the full tier to keep it within its hour are in the deep tier's additions, and the
    report's Method says so from the plans (mpm_fem.app.estimate.added)."""
    from mpm_fem.app.estimate import added
    from mpm_fem.app.paper import deep_text

    found = added(STUDIES)
    assert 0.00015625 in found["sod"].meshes and 0.0003125 in found["remedies"].meshes
    assert 0.00125 in found["budget"].meshes and found["budget"].cases > 0
    assert all(a.seconds > 0 for a in found.values())
    text = deep_text()
    assert text.startswith("To keep the full tier within its time budget") and "sod, 12 cases" in text.replace(
        f"sod, {found['sod'].cases} cases", "sod, 12 cases")
    assert added(STUDIES, "full", "full") == {}
