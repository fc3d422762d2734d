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
        for stage, share in zip(STAGES, values, strict=False):
            rows.append({"problem": problem, "h": str(h), "basis": basis, "norm": norm, "stage": stage,
                         "shapley": repr(share * 1e-3), "share": repr(share),
                         "mpm_error": "0.0012", "exact_error": "0.0002"})
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
    fits = [{"problem": p, "basis": b, "quantity": "velocity", "refine": "1", "order": "",
             "fitted_order": repr(global_order)}
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
    meshes = sorted({r["h"] for r in TABLES["budget/bases"]}, key=float)  # the last refinement: meshes[1] -> [0]
    finest = {"h": meshes[0]}
    coarse = {r["basis"]: float(r["particles_L1"]) for r in TABLES["budget/bases"] if r["h"] == meshes[1]}
    p1_fine = next(float(r["particles_L1"]) for r in TABLES["budget/bases"]
                   if r["h"] == meshes[0] and r["basis"] == "mpm")
    stalled = TABLES
    for basis in ("gimp", "bspline"):  # the smooth bases level off as P1 does, a little worse (order P1's - 0.14)
        stalled = mutate(stalled, "budget/bases", {**finest, "basis": basis},
                         particles_L1=1.1 * coarse[basis] * p1_fine / coarse["mpm"])
    converging = mutate(TABLES, "budget/bases", {**finest, "basis": "bspline"}, particles_L1=0.45 * coarse["bspline"])
    assert_flips("E2", stalled, converging)
    assert judge("E2", stalled)[0] == "refuted"
    p1_converges = mutate(converging, "budget/bases", {**finest, "basis": "mpm"}, particles_L1=0.5 * coarse["mpm"])
    assert judge("E2", p1_converges)[0] == "differs"


# ---------------------------------------------------------------- C15: the budget's mass stage

def _c15_tables(mass_share: float, problem: str = "sod") -> dict:
    """The committed lumping table with every ratio passing, and a budget whose mass stage carries
    ``mass_share`` at the finest mesh of one basis (0.3 elsewhere)."""
    shares = {(0.01, "mpm"): (0.6, 0.3, 0.05, 0.05), (0.005, "mpm"): (0.6, 0.3, 0.05, 0.05),
              (0.01, "gimp"): (0.6, 0.3, 0.05, 0.05), (0.005, "gimp"): (1 - mass_share - 0.1, mass_share, 0.05, 0.05)}
    if problem == "sod":
        tables = mutate(TABLES, "sod/mass", mpm_consistent_over_lumped_nodes=0.5, fem_consistent_over_lumped=0.5)
    else:
        tables = mutate(TABLES, "burgers/lumping", {"mass": "consistent"}, L2=1e-9)
    return {**tables, "budget/shapley": _shapley(shares, problem)}


def test_c15_reads_the_mass_stage_share_of_the_budget():
    """A mass stage below 10% at the finest mesh of one basis is one case that fails (partly); 30%
    passes, and so does -30% (the lumped solve compensating the other stages is a source too)."""
    assert_flips("C15 (sod)", _c15_tables(0.05), _c15_tables(0.3))
    assert judge("C15 (sod)", _c15_tables(-0.3))[0] == "confirmed"
    verdict, evidence = judge("C15 (sod)", _c15_tables(0.05))
    assert verdict == "partly"
    assert "Shapley share of the mass stage at the finest budget mesh: mpm particles h = 0.005 30%, " \
           "gimp particles h = 0.005 5%" in evidence
    assert_flips("C15 (burgers)", _c15_tables(0.05, "burgers"), _c15_tables(0.3, "burgers"))
    assert judge("C15 (sod)", {k: v for k, v in TABLES.items() if k != "budget/shapley"})[0] == "not measured"


# ---------------------------------------------------------------- E5: the budget of the closest remedy

def _e5_tables(shares: tuple) -> dict:
    """E5's made-up remedy table (tests/test_remedies_claim.py: "fix" closest) with the remedies'
    settings ("fix" is the particle-domain B-spline) and a budget of that basis."""
    from test_remedies_claim import table

    settings = [{"table": "remedies/errors", "key": "remedies.fix.basis", "value": "bspline_gimp"}]
    budget = _shapley({(0.01, "bspline_gimp"): (0.5, 0.2, 0.2, 0.1), (0.005, "bspline_gimp"): shares,
                       (0.005, "mpm"): (0.1, 0.1, 0.7, 0.1)}, "sod")
    return {"remedies/errors": table()["errors"], "settings": settings, "budget/shapley": budget}


def test_e5_names_the_stage_that_dominates_the_closest_remedys_remaining_error():
    verdict, evidence = judge("E5", _e5_tables((0.7, -0.1, 0.3, 0.1)))
    assert verdict == "confirmed"
    assert ("the budget of its basis bspline_gimp at h = 0.005 (particle density L1): projection carries 70% of "
            "the remaining error v(all MPM) - v(all exact) = 0.001, then interpolation 30%, time 10%, "
            "mass -10%") in evidence
    moved = judge("E5", _e5_tables((0.1, 0.1, 0.2, 0.6)))[1]
    assert "time carries 60%" in moved and "projection carries" not in moved
    assert "no error budget of its basis bspline_gimp" in judge(
        "E5", {**_e5_tables((0.7, 0, 0.2, 0.1)), "budget/shapley": []})[1]
