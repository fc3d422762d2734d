"""C13 follows its numbers: the orders' intervals over the runs (regular and jittered layouts) decide
each verdict, at the source-matching settings of the identification (the study's without it), and the
diagnosis clause says what the diagnosis table shows (mutation tests, as tests/test_claims.py)."""

from __future__ import annotations

import pytest
from claim_mutations import TABLES, assert_flips, claim_named, judge, mutate

from mpm_fem.measure.claims import BURGERS_SHOWN
from mpm_fem.measure.claims.burgers import C13_EXACT
from mpm_fem.measure.claims.rows import FIRST_ORDER, FLOOR_ORDER
from mpm_fem.measure.schema import BURGERS_DIAGNOSIS, BURGERS_ORDERS

ORDERS, DIAGNOSIS, IDENTIFICATION = BURGERS_ORDERS.name, BURGERS_DIAGNOSIS.name, "identification/burgers"
#: The calculated-acceleration methods by particles per cell (as the Burgers study names them).
C13_CALCULATED = {4: "mpm_calculated", 8: "mpm_calculated_8", 16: "mpm_calculated_16"}
_PPC = {m: str(n) for n, m in C13_CALCULATED.items()} | {C13_EXACT: "4", "mpm_exact": "4"}
#: A measured-looking table: every interval above the threshold (runs of 6 layouts at the seeded eps).
FIRST = {C13_EXACT: (0.97, 0.93, 1.02), **{m: (1.0, 0.9, 1.1) for m in C13_CALCULATED.values()}}


def _orders(intervals: dict, single: float = 1.0, solution: str = BURGERS_SHOWN["solution"]) -> list[dict]:
    """Orders rows of the compared solution and error: ``intervals`` ``{method: (mean, lo, hi)}`` at the
    seeded eps over 6 runs, and one more eps of one run (order ``single``) per method."""
    rows = []
    for method, (mean, lo, hi) in intervals.items():
        base = {**BURGERS_SHOWN, "solution": solution, "method": method, "ppc": _PPC[method],
                "h_range": "0.01-0.00125"}
        rows.append({**base, "eps": "0.045", "fitted": str(mean), "runs": "6", "fitted_mean": str(mean),
                     "fitted_lo": str(lo), "fitted_hi": str(hi)})
        rows.append({**base, "eps": "0.01", "fitted": str(single), "runs": "1", "fitted_mean": str(single),
                     "fitted_lo": "", "fitted_hi": ""})
    rows.append({**BURGERS_SHOWN, "method": "mpm_exact", "eps": "0.045", "fitted": "2.0", "runs": "1"})
    return rows


def _tables(intervals=FIRST, **changes) -> dict:
    """The committed tables with made-up orders and no identification table."""
    return {**{k: v for k, v in TABLES.items() if not k.startswith("identification/")},
            ORDERS: _orders({**intervals, **changes})}


def test_c13_is_confirmed_when_every_interval_lies_above_the_threshold_and_partly_when_one_straddles_it():
    passing = _tables()
    failing = mutate(passing, ORDERS, {"method": C13_CALCULATED[4], "eps": 0.045}, fitted_lo=FIRST_ORDER - 0.2)
    assert_flips("C13", failing, passing)
    assert judge("C13", failing)[0] == "partly"
    assert "calculated a, 4 per cell, max) 1.00 [0.60, 1.10] over 6 runs, undecided" in judge("C13", failing)[1]


def test_c13_without_the_identification_is_judged_at_the_studys_particles_per_cell_and_says_so():
    """16 per cell below first order leaves the verdict (the source's 4-8) confirmed; it is shown in the
    Finding's table beside."""
    sixteen_stalls = _tables(**{C13_CALCULATED[16]: (0.0, -0.3, 0.2)})
    verdict, evidence = judge("C13", sixteen_stalls)
    assert verdict == "confirmed" and "the study's settings" in evidence and "no identification table" in evidence
    table = claim_named("C13").finding(sixteen_stalls).table
    assert table[0]["calculated a, 16 per cell"] == "0.00 [-0.30, 0.20]"
    four_stalls = _tables(**{C13_CALCULATED[4]: (0.0, -0.3, 0.2)})
    assert_flips("C13", four_stalls, sixteen_stalls)


def _identified(solution: str, ppc: int = 4) -> list[dict]:
    """An identification table whose source-matching candidate of both rows is ``solution``."""
    base = {"problem": "burgers", "dt_rule": "stable", "cfl": "0.5", "norm": "max", "misfit": "0.1",
            "misfit_raw": "0.1", "meshes": "5"}
    rows = [{**base, "candidate": f"{solution} {ppc}", "solution": solution, "ppc": str(ppc), "source_row": row,
             "rank": "1", "matching": "True"} for row in ("calculated", "exact")]
    return rows + [{**base, "candidate": "other", "solution": "front", "ppc": "8", "source_row": "calculated",
                    "rank": "2", "matching": "False"}]


def test_c13_is_judged_at_the_source_matching_solution_and_names_it():
    """The rarefaction stalls, the identified solution (cole_hopf) is first order: the verdict follows
    the identification, every solution stays in the Finding's table."""
    stalls = {m: (0.0, -0.3, 0.2) for m in C13_CALCULATED.values()}
    tables = _tables(**stalls)
    tables[ORDERS] = tables[ORDERS] + _orders(FIRST, solution="cole_hopf")
    assert judge("C13", tables)[0] == "partly"  # the study's rarefaction
    identified = {**tables, IDENTIFICATION: _identified("cole_hopf")}
    verdict, evidence = judge("C13", identified)
    assert verdict == "confirmed" and "source-matching settings" in evidence and "cole_hopf" in evidence
    finding = claim_named("C13").finding(identified)
    assert "cole_hopf" in finding.sentence and "1.00" in finding.sentence
    assert [r["solution"] for r in finding.table] == ["rarefaction", "cole_hopf"]
    assert finding.table[1]["judged"] == "calculated row, exact row"
    rarefaction = {**tables, IDENTIFICATION: _identified("rarefaction")}
    assert_flips("C13", rarefaction, identified)
    assert claim_named("C13").finding(rarefaction).sentence != finding.sentence


def test_c13_differs_when_neither_acceleration_reaches_first_order():
    below = (0.2, -0.4, FLOOR_ORDER - 0.1)
    failing = _tables(**{m: below for m in (C13_EXACT, *C13_CALCULATED.values())})
    assert judge("C13", failing)[0] == "differs"
    assert_flips("C13", failing, _tables())


def test_c13_counts_no_order_without_an_interval_over_runs():
    """One run at one eps, however good, is not evidence (not measured, naming the row without one); a
    solution run once per eps (the unseeded solutions) has its range over the eps as interval, said so."""
    unseeded = mutate(_tables(), ORDERS, {"runs": 6}, runs="1", fitted_lo="", fitted_hi="")
    one_eps = {**unseeded, ORDERS: [r for r in unseeded[ORDERS] if r["eps"] == "0.045"]}
    verdict, evidence = judge("C13", one_eps)
    assert verdict == "not measured" and "no interval over runs for the calculated row" in evidence
    verdict, evidence = judge("C13", unseeded)
    assert verdict == "confirmed" and "over 2 eps x 1 runs" in evidence


def test_c13_reads_a_growing_error_as_such():
    grows = _tables(**{C13_CALCULATED[4]: (-0.4, -0.6, -0.1)})
    assert "the error grows" in judge("C13", grows)[1]


# ---------------------------------------------------------------- the diagnosis clause

def _diagnosis_order(changes: str, order: float):
    return lambda r: str(order) if r["changes"] == changes and r.get("order_L1") else r.get("order_L1", "")


def test_the_diagnosis_clause_is_formatted_from_the_diagnosis_table():
    evidence = judge("C13", _tables())[1]
    for r in TABLES[DIAGNOSIS]:
        assert r["variant"] in evidence
        if r.get("order_L1"):
            assert f"{float(r['order_L1']):.2f}" in evidence


@pytest.mark.parametrize("slides_order, says", [(-0.8, True), (1.5, False)])
def test_the_quadrature_sentence_follows_the_slides_force_row(slides_order, says):
    """'Not the only cause' only while the second-difference force, which sums no particle stresses,
    does not make the error fall either."""
    tables = mutate(_tables(), DIAGNOSIS, order_L1=_diagnosis_order("{'force': 'slides'}", slides_order))
    evidence = judge("C13", tables)[1]
    assert ("the particle quadrature of the force is not the only cause" in evidence) == says
    falls = next(c for c in evidence.split("; ") if c.startswith("the error falls at first order with"))
    slides = next(r["variant"] for r in tables[DIAGNOSIS] if r["changes"] == "{'force': 'slides'}")
    assert (f"{slides} ({slides_order:.2f}, {slides_order:.2f})" in falls) == (not says)


def test_c13_without_a_diagnosis_table_still_judges():
    tables = {k: v for k, v in _tables().items() if k != DIAGNOSIS}
    verdict, evidence = judge("C13", tables)
    assert verdict == "confirmed" and "diagnosis" not in evidence
