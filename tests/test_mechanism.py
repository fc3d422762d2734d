"""E6a: the growth of MPM's particle error decomposed by stage (studies/mechanism.py): the runs are the error
budget's, the plan fits its share of the full tier, and the criterion names a stage only where making it
exact turns the growth into convergence on every layout where all MPM grows (mutation tests)."""

from __future__ import annotations

import math

import mechanism_fixture as made_up
import numpy as np
import pytest
from claim_mutations import judge, mutate

from mpm_fem.measure.claims.mechanism import growth_cases, summary_rows
from mpm_fem.measure.decomposition import label
from mpm_fem.measure.schema import MECHANISM_GROWTH, MECHANISM_SUMMARY
from studies import budget
from studies import mechanism as study

SUMMARY = MECHANISM_SUMMARY.name


# ---------------------------------------------------------------- the runs are the budget's

@pytest.mark.parametrize("problem, h", [("sod", 0.05), ("burgers", 0.08)])
def test_each_subset_is_the_budgets_value_of_the_same_subset_bit_for_bit(problem, h):
    """v(S) of all MPM, each stage alone exact and time exact equal the budget's sixteen-subset runner's
    (studies.budget.subset_fields) on the same case, 4 per cell, jittered seed 2."""
    fields, weights, _, _ = budget.subset_fields(problem, h, "mpm", {"ppc": 4, "layout": "jittered", "seed": 2})
    want = {label(S): float(np.sum(weights["particles"] * np.abs(f["particles"]))) for S, f in fields.items()}
    for kind in study.CASES:
        got = study.run_case(study._case(problem, h, 4, "jittered", 2, kind))
        assert got["ok"]
        for made_exact, v in got["errors"].items():
            assert v == want[study.mpm_stages(made_exact)], (problem, made_exact, v, want[study.mpm_stages(made_exact)])


@pytest.fixture(scope="module")
def quick():
    """The quick tier's cases (Sod h = 0.01 and 0.005, Burgers' two coarsest meshes, 4 per cell, the regular
    layout and seeds 1 and 2, every subset), run once on the numpy step: the growth and summary rows."""
    got = {key: study.task_function(case)(case) for key, case in study.plan("quick")["growth"].items()}
    rows = study.growth_rows(got)
    return got, rows, summary_rows(rows)


def _order(rows, problem, seed, made_exact):
    found = [r for r in rows if (r["problem"], r["seed"], r["made_exact"]) == (problem, seed, made_exact)]
    assert len(found) == 1, found
    return found[0]["order"]


@pytest.mark.slow
def test_the_quick_tables_hold_every_run_subset_and_mesh_pair_with_their_measured_orders(quick):
    """Every quick case runs (about 15 CPU-s); one growth row per problem, layout and subset (two meshes, one
    pair), with the declared columns. From h = 0.01 to 0.005 Sod's all-MPM density L1 stalls on the regular
    layout (order 0.08) and grows on the jittered ones (-0.15 on seed 1), where the exact projection stops the
    growth (0.52) and every stage exact converges (0.79-0.95); Burgers' velocity L1 from h = 0.08 to 0.04: 2.04
    regular, 0.48 on seed 1, 2.4-2.5 with the exact projection. On the jittered layouts the exact projection
    lowers the error of both problems on both meshes."""
    got, rows, summary = quick
    assert all(r["ok"] for r in got.values())
    MECHANISM_GROWTH.check(rows)
    MECHANISM_SUMMARY.check(summary)
    assert len(rows) == 2 * 3 * 6 and len(summary) == 2 * 6
    bands = {("sod", 0, "none"): (-0.05, 0.2), ("sod", 1, "none"): (-0.3, -0.05), ("sod", 1, "projection"): (0.4, 0.65),
             ("sod", 1, "all"): (0.7, 1.1), ("burgers", 0, "none"): (1.9, 2.2), ("burgers", 1, "none"): (0.35, 0.6),
             ("burgers", 0, "projection"): (2.3, 2.7), ("burgers", 1, "projection"): (2.3, 2.7)}
    for (problem, seed, made_exact), (lo, hi) in bands.items():
        p = _order(rows, problem, seed, made_exact)
        assert lo < p < hi, (problem, seed, made_exact, p)
    for r in (r for r in rows if r["made_exact"] == "projection" and r["seed"] in (1, 2)):
        mpm = next(x for x in rows if (x["problem"], x["seed"], x["made_exact"]) == (r["problem"], r["seed"], "none"))
        assert r["error_fine"] < mpm["error_fine"] and r["error_coarse"] < mpm["error_coarse"], (r, mpm)
    mpm = next(r for r in summary if r["problem"] == "sod" and r["made_exact"] == "none")
    assert mpm["runs"] == 3 and mpm["mpm_growing"] == 2 and not mpm["turns_growth"]


@pytest.mark.slow
def test_the_quick_tier_judges_nothing(quick):
    """Three runs on two meshes are fewer than the rule book's MIN_RUNS and MECHANISM_MESHES: not measured."""
    _, _, summary = quick
    tables = {SUMMARY: [{k: str(v) for k, v in r.items()} for r in summary]}
    assert judge("E6a (sod)", tables)[0] == "not measured"


def test_the_quick_tier_runs_on_the_numpy_step_and_the_other_tiers_do_not(tmp_path):
    """Every quick case names the numpy step and runs through run_numpy_case, in the study's sweep and in
    reproduce's tasks (mpm_fem.app.case_tasks); the full and deep cases are run_case's, as before."""
    from mpm_fem.app.case_tasks import tasks
    from mpm_fem.app.study import StudyOptions

    quick = list(study.plan("quick")["growth"].values())
    assert quick and all(c["kernel"] == "numpy" and study.task_function(c) is study.run_numpy_case for c in quick)
    for tier in ("full", "deep"):
        assert all("kernel" not in c and study.task_function(c) is study.run_case
                   for c in study.plan(tier)["growth"].values())
    found = tasks("mechanism", StudyOptions(quick=True, out=tmp_path))
    assert len(found) == len(quick) and {t.fn for _, t in found} == {study.run_numpy_case}
    assert {t.fn for _, t in tasks("mechanism", StudyOptions(out=tmp_path))} == {study.run_case}


def test_the_numpy_case_is_the_compiled_case_to_round_off_and_burgers_orders_in_band():
    """Burgers, 4 per cell, h = 0.08 and 0.04: all MPM and time exact on the numpy step equal the compiled
    step's to 1e-9 (relative); from h = 0.08 to 0.04 all MPM's velocity L1 converges at 1.9-2.2 on the regular
    layout and 0.35-0.6 on seed 1, the exact projection at 2.3-2.7 on both (a fraction of a CPU-s)."""
    case = study._case("burgers", 0.08, 4, "regular", 0, "time")
    numpy, fused = study.run_numpy_case({**case, "kernel": "numpy"}), study.run_case(case)
    for k in ("none", "time"):
        assert numpy["errors"][k] == pytest.approx(fused["errors"][k], rel=1e-9), (k, numpy, fused)
    got = {(s, h, c): study.run_numpy_case({**study._case("burgers", h, 4, lay, s, c), "kernel": "numpy"})
           for lay, s in study.LAYOUTS[:2] for h in (0.08, 0.04) for c in ("time", "projection")}
    order = lambda s, k: math.log(got[(s, 0.08, "time" if k == "none" else k)]["errors"][k]  # noqa: E731
                                  / got[(s, 0.04, "time" if k == "none" else k)]["errors"][k]) / math.log(2)
    assert 1.9 < order(0, "none") < 2.2 and 0.35 < order(1, "none") < 0.6, (order(0, "none"), order(1, "none"))
    assert all(2.3 < order(s, "projection") < 2.7 for s in (0, 1)), [order(s, "projection") for s in (0, 1)]


# ---------------------------------------------------------------- the plan and its cost

def test_the_full_tier_fits_its_share_and_the_deep_tier_holds_it():
    """The full tier's estimate is at most 12 CPU-min, with four meshes a problem at 4 and 8 per cell on six
    layouts; the deep tier holds every full case and adds the finer meshes, 16 per cell and all exact."""
    full, deep = plan_cases("full"), plan_cases("deep")
    minutes = sum(study.cost(dict(c)) for c in full.values()) * study.SECONDS_PER_COST / 60
    assert 6 < minutes <= 12, minutes
    assert set(full.items()) <= set(deep.items()) and len(deep) > 2 * len(full)
    full_cases, deep_cases = [dict(c) for c in full.values()], [dict(c) for c in deep.values()]
    for problem in ("sod", "burgers"):
        assert len({c["h"] for c in full_cases if c["problem"] == problem}) == 4
    assert {(c.get("layout", "regular"), c.get("seed", 0)) for c in full_cases} == set(study.LAYOUTS)
    assert {c["made_exact"] for c in deep_cases} - {c["made_exact"] for c in full_cases} == {"all"}
    quick = sum(study.cost(c) for c in study.plan("quick")["growth"].values()) * study.SECONDS_PER_COST
    assert 5 < quick < 25, quick  # about 15 CPU-s measured on the numpy step (2026-12-02)


def plan_cases(tier):
    return {k: tuple(sorted(c.items())) for k, c in study.plan(tier)["growth"].items()}


def test_the_cost_model_reproduces_measured_cases():
    """The per-step model against cases measured on the 2-core machine (2026-11-28, the CPU seconds of one
    process): Sod, 8 per cell, jittered seed 1, h = 0.0025 (projection exact 1.67 s, mass exact 2.12 s),
    h = 0.00125 (all MPM and time exact 6.31 s), within a factor 1.6; the full tier's 384 cases took 8.56
    CPU-min together (shared machine), within 15 %."""
    for (h, kind), seconds in (((0.0025, "projection"), 1.67), ((0.0025, "mass"), 2.12), ((0.00125, "time"), 6.31)):
        got = study.cost(study._case("sod", h, 8, "jittered", 1, kind)) * study.SECONDS_PER_COST
        assert 1 / 1.6 < got / seconds < 1.6, (h, kind, got, seconds)
    full = sum(study.cost(c) for c in study.plan("full")["growth"].values()) * study.SECONDS_PER_COST / 60
    assert 0.85 < full / 8.56 < 1.15, full


# ---------------------------------------------------------------- the criterion follows its numbers

def test_summary_counts_the_runs_where_all_mpm_grows_and_where_each_subset_converges_there():
    summary = summary_rows(study.growth_rows(made_up.got()))
    fine = {r["made_exact"]: r for r in summary if r["h_fine"] == made_up.MESHES[-1]}
    assert fine["none"]["mpm_growing"] == 6 and fine["none"]["order_mean"] == pytest.approx(-0.4)
    assert fine["projection"]["converging_where_mpm_grows"] == 6 and fine["projection"]["turns_growth"]
    assert fine["interpolation"]["stops_growth"] == 0 and not fine["interpolation"]["turns_growth"]
    coarse = {r["made_exact"]: r for r in summary if r["h_coarse"] == made_up.MESHES[0]}
    assert coarse["none"]["mpm_growing"] == 0 and not coarse["projection"]["turns_growth"]


def test_e6a_names_the_stage_that_turns_the_growth_into_convergence_on_every_run():
    tables = made_up.tables()
    verdict, evidence = judge("E6a (sod)", tables)
    assert verdict == "confirmed", evidence
    assert "(projection on every one)" in evidence and "named: projection" in evidence
    found = growth_cases([r for r in tables[SUMMARY]])
    assert set(found["growth"]) == {(4, 0.005, 0.0025), (4, 0.0025, 0.00125)}
    assert all(found["named"][c] == ["projection"] for c in found["growth"])


def test_a_stage_that_converges_on_five_of_six_growing_runs_is_not_named():
    """Projection exact at order 0.5 on seed 3 on the finest pair: not named there (partly); on both pairs: refuted."""
    one = {**made_up.GROWS, "projection": lambda s: (0.9, 0.9, 0.5 if s == 3 else 0.8)}
    both = {**made_up.GROWS, "projection": lambda s: (0.9, 0.5, 0.5) if s == 3 else (0.9, 0.9, 0.8)}
    assert judge("E6a (sod)", made_up.tables(one))[0] == "partly"
    verdict, evidence = judge("E6a (sod)", made_up.tables(both))
    assert verdict == "refuted" and "in 0 of 2 growth cases" in evidence, evidence


def test_e6a_is_refuted_when_no_stage_converges_and_differs_when_nothing_grows():
    none = {**made_up.GROWS, "projection": (0.9, 0.3, 0.2)}
    verdict, evidence = judge("E6a (sod)", made_up.tables(none))
    assert verdict == "refuted" and "stops it: projection" in evidence, evidence
    flat = {k: (0.8, 0.8, 0.8) for k in made_up.GROWS}
    assert judge("E6a (sod)", made_up.tables(flat))[0] == "differs"


def test_growth_on_one_run_is_a_growth_case_judged_on_that_run_alone():
    """All MPM grows on seed 4 only (finest pair): the stage converging there is named, whatever it does
    elsewhere."""
    orders = {**made_up.GROWS, "none": lambda s: (0.8, 0.6, -0.2 if s == 4 else 0.6),
              "projection": lambda s: (0.9, 0.9, 0.8 if s == 4 else 0.1)}
    tables = made_up.tables(orders)
    verdict, evidence = judge("E6a (sod)", tables)
    assert verdict == "confirmed" and "grows on 1 of 6 runs" in evidence, evidence


def test_the_summary_table_alone_flips_the_verdict():
    """One count of the summary (converging on 5 of the 6 growing runs) takes the named stage away."""
    tables = made_up.tables()
    fewer = mutate(tables, SUMMARY, {"made_exact": "projection", "h_fine": 0.00125}, converging_where_mpm_grows=5)
    assert judge("E6a (sod)", tables)[0] == "confirmed" and judge("E6a (sod)", fewer)[0] == "partly"


@pytest.mark.parametrize("runs, meshes", [(made_up.RUNS[:5], made_up.MESHES), (made_up.RUNS, made_up.MESHES[:3])])
def test_fewer_runs_or_meshes_than_the_rule_book_are_not_measured(runs, meshes):
    assert judge("E6a (sod)", made_up.tables(runs=runs, meshes=meshes))[0] == "not measured"


def test_each_problem_is_judged_on_its_own_rows():
    tables = made_up.tables(problems=("burgers",))
    assert judge("E6a (burgers)", tables)[0] == "confirmed"
    assert judge("E6a (sod)", tables)[0] == "not measured"


def test_a_failed_run_counts_as_not_converging():
    """A subset whose run failed on a growing run (no growth row) does not turn the growth into convergence."""
    got = made_up.got()
    del got[("sod", 4, "jittered", 2, 0.00125, "projection")]
    summary = summary_rows(study.growth_rows(got))
    fine = next(r for r in summary if r["made_exact"] == "projection" and r["h_fine"] == 0.00125)
    assert fine["runs"] == 5 and fine["converging_where_mpm_grows"] == 5 and not fine["turns_growth"]
    assert math.isfinite(fine["order_min"])


# ---------------------------------------------------------------- the measured finding (slow)

@pytest.mark.slow
def test_the_exact_projection_turns_burgers_growth_into_convergence_on_every_layout():
    """Burgers at 4 per cell, the full tier's runs (six layouts, h = 0.08 ... 0.01; about 35 CPU-s): all MPM grows
    from h = 0.02 to 0.01 on 5 of 6 layouts (the full tier measured orders -0.28..0.46), and with the projection
    alone exact every layout converges at about second order (2.03-2.05); E6a (burgers) names the projection."""
    cases = {k: c for k, c in study.plan("full")["growth"].items() if k[0] == "burgers" and k[1] == 4}
    rows = study.growth_rows({k: study.run_case(c) for k, c in cases.items()})
    summary = {(r["made_exact"], r["h_fine"]): r for r in summary_rows(rows)}
    mpm, projection = summary[("none", 0.01)], summary[("projection", 0.01)]
    assert mpm["mpm_growing"] == 5 and -0.35 < mpm["order_min"] < -0.2, mpm
    assert projection["turns_growth"] and 1.9 < projection["order_min"] <= projection["order_max"] < 2.2, projection
    tables = {SUMMARY: [{k: str(v) for k, v in r.items()} for r in summary.values()]}
    verdict, evidence = judge("E6a (burgers)", tables)
    assert verdict == "confirmed" and "(projection on every one)" in evidence, evidence
