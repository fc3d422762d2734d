"""The criteria of C1, C2, E1 and E2 follow their numbers: a table perturbed to fail and one
perturbed to pass give different verdicts. The time and budget tables are built here in the shape
the studies write them (``studies/time.py``, ``studies/budget.py``), so the tests do not depend on
which figures are committed; E2 mutates the committed ``budget/bases`` table."""

from __future__ import annotations

from claim_mutations import TABLES, assert_flips, judge, mutate

from studies import budget as study

STAGES = study.STAGES


def _shapley(shares: dict, problem: str = "burgers", norm: str = "particles") -> list[dict]:
    """``budget/shapley`` rows from ``{(h, basis): (share per stage in STAGES order)}`` (strings, as read)."""
    rows = []
    for (h, basis), values in shares.items():
        for stage, share in zip(STAGES, values):
            rows.append({"problem": problem, "h": str(h), "basis": basis, "norm": norm, "stage": stage,
                         "shapley": repr(share * 1e-3), "share": repr(share), "mpm_error": "0.0012", "exact_error": "0.0002"})
    return rows


DOMINATED = {(0.04, "mpm"): (0.55, 0.2, 0.15, 0.1), (0.02, "mpm"): (0.7, 0.1, 0.1, 0.1),
             (0.04, "gimp"): (0.6, 0.3, 0.2, -0.1), (0.02, "gimp"): (0.8, 0.1, 0.2, -0.1)}


def test_e1_names_the_dominant_stage_and_whether_its_share_grows():
    verdict, evidence = judge("E1 (burgers)", {"budget/shapley": _shapley(DOMINATED)})
    assert verdict == "confirmed"
    assert "mpm at h = 0.02: projection 70% (55% -> 70%, grows as h shrinks)" in evidence
    assert "gimp at h = 0.02: projection 80% (60% -> 80%, grows as h shrinks); compensated by time -10%" in evidence


def test_e1_is_partly_when_no_stage_reaches_half_and_names_the_two_largest():
    shared = {**DOMINATED, (0.02, "gimp"): (0.4, 0.35, 0.2, 0.05)}
    assert_flips("E1 (burgers)", {"budget/shapley": _shapley(shared)}, {"budget/shapley": _shapley(DOMINATED)})
    verdict, evidence = judge("E1 (burgers)", {"budget/shapley": _shapley(shared)})
    assert verdict == "partly" and "gimp at h = 0.02: shared: projection 40% and mass 35%" in evidence


def test_e1_is_refuted_when_the_shares_do_not_add_up():
    broken = {**DOMINATED, (0.04, "mpm"): (0.9, 0.2, 0.15, 0.1)}
    verdict, evidence = judge("E1 (burgers)", {"budget/shapley": _shapley(broken)})
    assert verdict == "refuted" and "do not add up" in evidence


def test_e1_sod_reads_both_norms_and_is_not_measured_without_its_table():
    tables = {"budget/shapley": _shapley(DOMINATED, "sod") + _shapley(DOMINATED, "sod", "nodes")}
    verdict, evidence = judge("E1 (sod)", tables)
    assert verdict == "confirmed" and "nodes L1: mpm projection 70%, gimp projection 80%" in evidence
    assert judge("E1 (sod)", {})[0] == "not measured"


def _time_tables(global_order: float, local_order: float) -> dict:
    fits = [{"problem": p, "basis": b, "quantity": "velocity", "refine": "1", "order": "", "fitted_order": repr(global_order)}
            for p in ("pulse", "burgers") for b in ("mpm", "bspline")]
    local = [{"problem": p, "basis": b, "quantity": "x", "order": "", "fitted_order": repr(local_order)}
             for p in ("pulse", "burgers") for b in ("mpm", "bspline")]
    return {"time/time_order": fits, "time/local_error": local}


def test_c1_follows_the_orders_in_dt():
    assert_flips("C1", _time_tables(0.6, 2.0), _time_tables(1.0, 2.0))
    assert_flips("C1", _time_tables(1.0, 1.2), _time_tables(1.0, 2.0))
    verdict, evidence = judge("C1", _time_tables(0.6, 2.0))
    assert verdict == "partly" and "pulse mpm velocity" in evidence
    assert judge("C1", _time_tables(0.3, 1.0))[0] == "refuted"


def _crossing(p1_error: float, smooth: float) -> dict:
    rows = [{"basis": "mpm", "acceleration": "exact", "crossings": "11", "median_ratio": "0.99",
             "max_ratio_error": repr(p1_error), "max_abs_ratio": repr(1 + p1_error)},
            {"basis": "bspline", "acceleration": "exact", "crossings": "11", "median_ratio": "0.0",
             "max_ratio_error": "1.0", "max_abs_ratio": repr(smooth)}]
    return {"time/crossing_summary": rows}


def test_c2_needs_the_p1_formula_and_no_jump_for_the_smooth_basis():
    assert_flips("C2", _crossing(0.3, 0.001), _crossing(0.02, 0.001))
    assert judge("C2", _crossing(0.3, 0.001))[0] == "refuted"
    assert judge("C2", _crossing(0.02, 0.5))[0] == "partly"


def test_e2_follows_the_last_refinement_orders():
    finest = {"h": "0.00125"}
    coarse = {r["basis"]: float(r["particles_L1"]) for r in TABLES["budget/bases"] if r["h"] == "0.0025"}
    stalled = TABLES
    for basis in ("gimp", "bspline"):  # the smooth bases level off like P1: order log2(1/0.95) ~ 0.07
        stalled = mutate(stalled, "budget/bases", {**finest, "basis": basis}, particles_L1=0.95 * coarse[basis])
    converging = mutate(TABLES, "budget/bases", {**finest, "basis": "bspline"}, particles_L1=0.45 * coarse["bspline"])
    assert_flips("E2", stalled, converging)
    assert judge("E2", stalled)[0] == "refuted"
    p1_converges = mutate(converging, "budget/bases", {**finest, "basis": "mpm"}, particles_L1=0.5 * coarse["mpm"])
    assert judge("E2", p1_converges)[0] == "differs"
