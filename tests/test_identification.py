"""The identification of the source's unstated settings: the misfit, the rank and the
band on synthetic tables, the sentence that says where the source's table is reproduced, the plan's
sharing of the Sod and Burgers studies' cases and its cost, and one small real run."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from mpm_fem.app import estimate
from mpm_fem.app.study import StudyOptions
from mpm_fem.app.sweep import Task, run_tasks
from mpm_fem.measure import source
from mpm_fem.measure.claims.identification import (
    candidate_rows,
    identification_sentence,
    misfit,
    rank,
    source_matching,
)
from mpm_fem.measure.claims.rules import rule
from mpm_fem.measure.schema import IDENTIFICATION_BURGERS, IDENTIFICATION_SOD
from studies import burgers as burgers_study
from studies import identification
from studies import sod as sod_study

HS = (0.01, 0.005, 0.0025, 0.00125)


# ----------------------------------------------------------------------------- misfit, rank, band

def test_misfit_is_the_mean_absolute_log_ratio():
    assert misfit([1.0, 2.0], [1.0, 2.0]) == 0.0
    assert misfit([2.0, 4.0], [1.0, 2.0]) == pytest.approx(math.log(2))
    assert misfit([0.5, 4.0], [1.0, 2.0]) == pytest.approx(math.log(2))  # too small counts as too large
    assert misfit([1.0, None], [1.0, 2.0]) == math.inf  # a failed run
    assert misfit([1.0, float("nan")], [1.0, 2.0]) == math.inf
    with pytest.raises(ValueError, match="paired"):
        misfit([1.0], [1.0, 2.0])


def _sod_results(values: dict) -> dict:
    """``{(ppc, cfl, h): run}`` with the nodal L1 of ``values[(ppc, cfl)][k]`` on mesh ``HS[k]`` and
    every other quantity 10x the source."""
    out = {}
    for (n, c), errors in values.items():
        for h, e in zip(HS, errors, strict=True):
            far = {k: 10 * v for k, v in zip(("L1", "L2"), source.SOD[h], strict=True)}
            out[(n, c, h)] = {"ok": True, "density": {"nodes": {"L1": e, "L2": far["L2"]}, "particles": far}}
    return out


def _sod_table(values: dict) -> list[dict]:
    return identification.sod_rows(_sod_results(values), HS)


SOURCE_L1 = [source.SOD[h][0] for h in HS]


def test_a_candidate_made_to_match_exactly_ranks_first_and_alone_in_the_band():
    rows = _sod_table({(16, 0.05): SOURCE_L1, (8, 0.05): [2 * v for v in SOURCE_L1],
                       (4, 0.1): [v * math.exp(rule("IDENTIFICATION_BAND") / 2) for v in SOURCE_L1]})
    IDENTIFICATION_SOD.check(rows)
    l1 = [r for r in rows if r["source_row"] == "L1"]
    assert [r["rank"] for r in l1] == list(range(1, len(l1) + 1))
    best = l1[0]
    assert (best["ppc"], best["cfl"], best["quantity"], best["norm"], best["misfit"]) == (16, 0.05, "nodes", "L1", 0)
    assert [r["candidate"] for r in l1 if r["matching"] == "True"] == ["16 ppc, CFL 0.05, nodes L1",
                                                                        "4 ppc, CFL 0.1, nodes L1"]
    doubled = next(r for r in l1 if r["candidate"] == "8 ppc, CFL 0.05, nodes L1")
    assert doubled["misfit"] == pytest.approx(math.log(2)) and doubled["matching"] == "False"


def test_the_band_is_the_rule_books_and_moves_the_matching_set(monkeypatch):
    rows = [{"source_row": "L1", "misfit": m} for m in (0.0, 0.04, 0.2, math.inf)]
    assert [r["matching"] for r in rank(rows)] == ["True", "True", "False", "False"]
    from mpm_fem.measure.claims import rules
    monkeypatch.setitem(rules.RULES, "IDENTIFICATION_BAND", rules.RULES["IDENTIFICATION_BAND"].__class__(
        "IDENTIFICATION_BAND", 0.01, "", "", ()))
    assert [r["matching"] for r in rank(rows)] == ["True", "False", "False", "False"]


def test_a_per_mesh_best_fit_is_never_a_candidate():
    """Each candidate matches the source exactly on one mesh only: the envelope of the best fit per mesh
    would match everywhere (misfit 0), but a candidate is one setting over the whole table."""
    settings = [(4, 0.025), (8, 0.05), (16, 0.1), (32, 0.2)]
    values = {s: [v if j == k else 3 * v for j, v in enumerate(SOURCE_L1)] for k, s in enumerate(settings)}
    rows = _sod_table(values)
    assert len(rows) == len(settings) * 2 * 2 * 2  # (ppc, cfl) x quantity x norm x source row
    assert len({(r["candidate"], r["source_row"]) for r in rows}) == len(rows)
    fitted = [r["misfit"] for r in rows if (r["quantity"], r["norm"], r["source_row"]) == ("nodes", "L1", "L1")]
    assert min(fitted) == max(fitted) == pytest.approx(0.75 * math.log(3))
    assert all(r["meshes"] == "0.01 0.005 0.0025 0.00125" for r in rows)


def test_a_missing_mesh_makes_a_candidate_infinite_never_matching():
    results = _sod_results({(16, 0.05): SOURCE_L1, (8, 0.05): SOURCE_L1})
    results[(8, 0.05, HS[-1])] = {"ok": False, "error": "positivity"}
    rows = [r for r in identification.sod_rows(results, HS) if r["source_row"] == "L1" and r["ppc"] == 8]
    assert all(r["misfit"] == math.inf and r["matching"] == "False" for r in rows)


def test_burgers_raw_table_has_the_printed_exponents():
    corrected, raw = identification.burgers_source(source.BURGERS_H)
    assert corrected["exact"][(0.04, 0.0025)] == 6.09e-5 and raw["exact"][(0.04, 0.0025)] == pytest.approx(6.09e-4)
    assert raw["exact"][(0.045, 0.0025)] == corrected["exact"][(0.045, 0.0025)]
    rows = candidate_rows("burgers", dict(solution="front", dt_rule="stable", cfl=0.5, ppc=4, norm="max"),
                          corrected["exact"], {"exact": corrected["exact"]}, {"exact": raw["exact"]}, "all", "x")
    assert rows[0]["misfit"] == 0 and rows[0]["misfit_raw"] == pytest.approx(4 * math.log(10) / 25)


# ----------------------------------------------------------------------------- the reading

def test_source_matching_reads_the_band_best_rank_first():
    rows = _sod_table({(16, 0.05): SOURCE_L1, (4, 0.1): [1.01 * v for v in SOURCE_L1], (8, 0.05): SOURCE_L1[::-1]})
    tables = {"identification/sod": rows}
    found = source_matching(tables, "sod", "L1")
    assert [(r["ppc"], r["cfl"]) for r in found] == [(16, 0.05), (4, 0.1)]
    assert source_matching({}, "burgers") == []
    with pytest.raises(ValueError, match="problem"):
        source_matching(tables, "euler")


def test_the_sentence_says_where_the_source_is_reproduced_and_a_perturbed_table_changes_it():
    table = _sod_table({(16, 0.05): [1.03 * v for v in SOURCE_L1], (8, 0.05): [1.5 * v for v in SOURCE_L1]})
    text = identification_sentence({"identification/sod": table}, "sod")
    assert text.startswith("The source's Sod L1 column is reproduced within 3 % by nodal density L1 at 16 per cell "
                           "and CFL 0.05, at the source's 4-8 per cell within 50 % at best")
    assert len(text.split()) <= 80
    worse = _sod_table({(16, 0.05): [1.3 * v for v in SOURCE_L1], (8, 0.05): [1.5 * v for v in SOURCE_L1]})
    changed = identification_sentence({"identification/sod": worse}, "sod")
    assert changed != text and "L1 column is not reproduced: at best within 30 % by nodal density L1 at 16" in changed
    swapped = _sod_table({(16, 0.05): [1.5 * v for v in SOURCE_L1], (8, 0.05): [1.03 * v for v in SOURCE_L1]})
    assert "within 3 % by nodal density L1 at 8 per cell" in identification_sentence(
        {"identification/sod": swapped}, "sod")
    assert identification_sentence({}, "sod") == ""


def test_the_burgers_sentence_names_solution_norm_and_time_step():
    corrected, raw = identification.burgers_source(source.BURGERS_H[:3])
    rows = []
    for solution, factor in (("cole_hopf", 1.05), ("rarefaction", 2.0)):
        measured = {k: factor * v for k, v in corrected["calculated"].items()}
        rows += candidate_rows("burgers", dict(solution=solution, dt_rule="stable", cfl=0.5, ppc=4, norm="max"),
                               measured, {"calculated": corrected["calculated"]}, {"calculated": raw["calculated"]},
                               "0.01 0.005 0.0025", solution)
    rows = rank(rows)
    IDENTIFICATION_BURGERS.check(rows)
    text = identification_sentence({"identification/burgers": rows}, "burgers")
    assert text == ("The source's Burgers calculated-acceleration row is reproduced within 5 % by the cole_hopf "
                    "solution, max norm, 4 per cell, the stable dt at CFL 0.5 (on 3 of the source's 5 meshes, h = "
                    "0.01 to 0.0025).")
    layout = {"table": "identification/burgers", "key": "layout", "value": "regular"}
    assert identification_sentence({"identification/burgers": rows, "settings": [layout]}, "burgers").endswith(
        "(the regular layout, on 3 of the source's 5 meshes, h = 0.01 to 0.0025).")


# ----------------------------------------------------------------------------- the plan

def test_the_sod_candidates_are_the_sod_studys_cases_where_it_runs_them():
    ours = identification.plans("full")["sod"]["candidates"]
    theirs = {repr(sorted(c.items())) for g in sod_study.PLAN("full").values() for c in g.values()}
    for n, c in sod_study.SETTINGS:
        assert all(repr(sorted(ours[(n, c, h)].items())) in theirs for h in identification.SOD_MESHES["full"])
    assert {(n, c) for n, c, _ in ours} == {(n, c) for n in identification.SOD_PPC for c in identification.SOD_CFL}


def test_the_burgers_candidates_share_the_burgers_studys_cases():
    ours = {repr(sorted(c.items())) for c in identification.plans("full")["burgers"]["candidates"].values()}
    theirs = {repr(sorted(c.items())) for g in burgers_study.PLAN("full").values() for c in g.values()}
    default = burgers_study.method_case("mpm_calculated", "front", 0.01, 0.0025)
    assert repr(sorted(default.items())) in ours & theirs
    rules = {(r, d) for r, _, d, _, _ in identification.burgers_candidates("full")}
    assert rules == {("exact", "advective"), ("exact", "stable"), ("calculated", "stable")}
    assert {s for _, s, *_ in identification.burgers_candidates("full")} == set(burgers_study.SOLUTIONS)


def test_the_deep_plan_holds_every_case_of_the_full_plan_and_more():
    for study in identification.SWEEPS:
        full, deep = ({repr(sorted(c.items())) for c in identification.plans(t)[study]["candidates"].values()}
                      for t in ("full", "deep"))
        assert full < deep, study


@pytest.mark.parametrize("tier, limit_s", [("quick", 5.0), ("full", 12 * 60.0)])
def test_the_tiers_fit_their_budgets(tier, limit_s, tmp_path):
    """By the Sod and Burgers studies' cost models, every case counted (none cached, none shared)."""
    total = sum(identification.SWEEPS[s].SECONDS_PER_COST * identification.SWEEPS[s].COST(c)
                for s, plan in identification.plans(tier).items() for g in plan.values() for c in g.values())
    assert total <= limit_s
    options = StudyOptions(quick=tier == "quick", out=tmp_path)
    shared = estimate.estimate("identification", options)
    assert shared.cases == sum(len(g) for p in identification.plans(tier).values() for g in p.values())
    assert shared.seconds < total or tier == "quick"  # cases the Sod and Burgers studies run count there


_CALLS = []


def _count(case: dict) -> dict:
    _CALLS.append(case["x"])
    return {"x": case["x"]}


@pytest.mark.parametrize("jobs", [1, 2])
def test_a_task_listed_twice_runs_once_and_ends_both(jobs, tmp_path):
    """Two studies sharing a case in one ``reproduce`` pool: it runs once, and both are told it is in."""
    _CALLS.clear()
    done = []
    tasks = [Task(_count, {"x": 1}, tmp_path), Task(_count, {"x": 2}, tmp_path), Task(_count, {"x": 1}, tmp_path)]
    results = run_tasks(tasks, jobs=jobs, progress=False, done=done.append)
    assert results == [{"x": 1}, {"x": 2}, {"x": 1}] and sorted(done) == [0, 1, 2]
    assert sorted(_CALLS) == ([1, 2] if jobs == 1 else [])  # a pool runs them in its workers
    assert len(list(Path(tmp_path).glob("*.json"))) == 2


def test_the_progress_of_a_task_listed_twice_ends_at_the_total(tmp_path, capsys):
    """The progress line counts each task once: a twin is counted when its first is in, never before."""
    tasks = [Task(_count, {"x": 1}, tmp_path), Task(_count, {"x": 2}, tmp_path), Task(_count, {"x": 1}, tmp_path)]
    run_tasks(tasks, jobs=1, progress=True)
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if " done, " in line]
    assert "3 of 3 cases to run (0 cached)" in err and lines and lines[-1].startswith("[cases] 3/3 done")
    assert all(int(line.split("]")[1].split("/")[0]) <= 3 for line in lines)


# ----------------------------------------------------------------------------- one small real run

def test_a_small_real_identification():
    """Two Sod settings and one Burgers candidate on the coarsest mesh, through the studies' case functions."""
    sod = {(n, c, 0.01): sod_study.run_case(sod_study._setting_case(0.01, n, c)) for n, c in ((16, 0.05), (4, 0.2))}
    rows = identification.sod_rows(sod, (0.01,))
    IDENTIFICATION_SOD.check(rows)
    best = next(r for r in rows if r["source_row"] == "L1" and r["rank"] == 1)
    assert (best["ppc"], best["quantity"]) == (16, "nodes") and best["misfit"] < 0.2
    cand = ("exact", "rarefaction", "advective", 0.5, 4)
    burgers = {(*cand, e, 0.01): burgers_study.run_case(identification._burgers_case(*cand, e, 0.01))
               for e in identification.EPS}
    rows = identification.burgers_rows(burgers, (0.01,))
    IDENTIFICATION_BURGERS.check(rows)
    assert len(rows) == 3 and all(math.isfinite(r["misfit"]) for r in rows)
