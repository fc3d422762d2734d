"""The Sod claims C11, C12, C14 and E3 follow their numbers: made-up runs (``sod_fixture``) turned into
the study's tables, perturbed to pass and to fail (mutation tests), judged per setting, with the
headline on the settings the source prescribes and an order counted only when its range over the
seeds lies on one side of a threshold."""

from __future__ import annotations

import math

import pytest
from claim_mutations import claim_named, judge, mutate
from sod_fixture import MESHES, diverging, extrema, made_up_tables

from mpm_fem.measure.claims import shape
from mpm_fem.measure.spread import Spread
from studies import sod as study

FINEST = MESHES[-1]


def _model(particles, nodes=None, fem=lambda h: 1.1 * h, noise=0.02, only=None):
    """Errors ``particles(h)`` (the energy three times it), ``nodes(h)`` and ``fem(h)``, a relative deviation
    per seed and mesh within ``noise``; ``only`` a setting (ppc, cfl) that takes this model, the others
    :func:`diverging`."""
    nodes = nodes or particles

    def model(quantity, ppc, cfl, h, seed):
        if only is not None and quantity != "fem" and (ppc, cfl) != only:
            return diverging(quantity, ppc, cfl, h, seed)
        value = {"particles": particles, "energy": lambda x: 3 * particles(x), "nodes": nodes, "fem": fem}[quantity](h)
        return value * (1.0 + (0.0 if seed in (None, 0) else noise * math.sin(7.0 * seed + 3.0 * math.log(h))))
    return model


def _levelling(h):
    return 0.001 + 0.5 * h


@pytest.fixture(scope="module")
def tables():
    return made_up_tables()


# ----------------------------------------------------------------------------- C11

def _orders(*ranges):
    return [Spread((lo + hi) / 2, lo, hi, 6) for lo, hi in ranges]


def test_shape_reads_the_range_of_the_orders():
    assert shape.shape(_orders((0.9, 1.0), (0.8, 0.9), (-0.6, -0.4), (-0.7, -0.2))) == "grows"
    assert shape.shape(_orders((0.9, 1.0), (0.8, 0.9), (-0.3, 0.2), (-0.7, -0.2))) == "levels off"
    assert shape.shape(_orders((0.3, 0.4), (0.8, 0.9), (-0.3, 0.2), (0.1, 0.2))) == "stalls"  # no converging start
    assert shape.shape(_orders((0.9, 1.0), (0.8, 0.9), (0.75, 1.1))) == "converges"
    assert shape.shape(_orders((0.9, 1.0), (0.3, 0.6), (-0.7, -0.2))) == "undecided"  # 0.6 straddles 0.5
    assert shape.shape(_orders((0.9, 1.0), (0.6, 0.8), (0.8, 0.9))) == "undecided"  # 0.6 below 0.7


def test_c11_an_error_that_grows_differs_and_never_confirms(tables):
    """The default made-up runs converge, then the particle error grows (order -0.5 over every seed)
    while the nodal error levels off: a divergence, not the source's plateau."""
    verdict, evidence = judge("C11", tables)
    assert verdict == "differs"
    assert evidence.startswith("particle density at 4-8 per cell: differs (8 ppc at CFL 0.05)")
    assert "particle density grows from h = 0.00125" in evidence and "nodal density levels off" in evidence
    assert evidence.count("ppc, CFL") >= len(study.SETTINGS)  # one clause per setting


def test_c11_an_error_that_grows_from_the_second_refinement_is_not_confirmed():
    def grows(h):
        return 1.2 * h if h >= 0.005 else 1.2 * 0.005 * (0.005 / h) ** 0.5
    verdict, evidence = judge("C11", made_up_tables(_model(grows)))
    assert verdict == "differs" and "particle density grows from h = 0.005" in evidence


def test_c11_confirms_a_level_error_and_is_refuted_by_convergence(tables):
    level = made_up_tables(_model(_levelling))
    verdict, evidence = judge("C11", level)
    assert verdict == "confirmed" and "particle density levels off" in evidence
    assert "grows" not in evidence.split("Mechanism")[0]
    converging = made_up_tables(_model(lambda h: 1.2 * h))
    assert judge("C11", converging)[0] == "refuted"
    # the perturbed table changes the Finding's sentence too
    grows, levels = (claim_named("C11").finding(t).sentence for t in (tables, level))
    assert "the particle density error grows under refinement (mean orders" in grows
    assert "the particle density error converges, then levels off (mean orders" in levels


def test_c11_needs_the_source_size_at_the_coarsest_mesh():
    """A plateau ten times the source's size at the coarsest mesh is not the source's shape."""
    big = made_up_tables(_model(lambda h: 10 * _levelling(h) / 0.6 * 0.0083))
    verdict, evidence = judge("C11", big)
    assert verdict == "partly" and "levels off" in evidence


def test_c11_counts_an_order_only_when_its_range_over_the_seeds_is_decided(tables):
    """One jittered run perturbed on the finest mesh widens the last order's range across 0 and the floor."""
    smaller = {k: (lambda r, k=k: float(r[k]) / 8) for k in ("particles_L1", "energy_L1")}
    perturbed = mutate(tables, "sod/seeds", {"h": FINEST, "seed": 3}, **smaller)
    assert judge("C11", perturbed)[0] == "partly"
    noisy = made_up_tables(_model(_levelling, noise=0.4))  # the seeds scatter by 40%: no order is decided
    assert judge("C11", noisy)[0] == "partly"


def test_c11_headline_is_the_verdict_on_the_prescribed_settings():
    one_converges = made_up_tables(_model(lambda h: 1.2 * h, only=(4, 0.1)))
    verdict, evidence = judge("C11", one_converges)
    assert verdict == "partly" and "4 ppc, CFL 0.1: refuted" in evidence and "8 ppc, CFL 0.05: differs" in evidence
    study_setting = made_up_tables(_model(lambda h: 1.2 * h, only=(16, 0.05)))  # not a setting the source prescribes
    verdict, evidence = judge("C11", study_setting)
    assert verdict == "differs" and "16 ppc, CFL 0.05: refuted" in evidence


def _identified(ppc: int, cfl: float, quantity: str = "nodes") -> list[dict]:
    base = {"problem": "sod", "misfit": "0.05", "misfit_raw": "0.05", "meshes": "5", "source_row": "L1"}
    return [{**base, "candidate": f"{ppc} {cfl}", "ppc": str(ppc), "cfl": str(cfl), "quantity": quantity,
             "norm": "L1", "rank": "1", "matching": "True"},
            {**base, "candidate": "4 0.2", "ppc": "4", "cfl": "0.2", "quantity": "particles", "norm": "L1",
             "rank": "7", "matching": "False"}]


def test_c11_shows_the_source_matching_setting_in_its_own_column(tables):
    """With the identification table the matching setting is named in the Finding's table and the
    sentence says how closely it reproduces the source; without it the evidence says so and the closest
    setting of the convergence table stands in."""
    found = claim_named("C11").finding({**tables, "identification/sod": _identified(16, 0.05)})
    column = {r["setting"]: r["source-matching"] for r in found.table}
    assert column["16 ppc, CFL 0.05"] == "nodes L1, rank 1" and column["8 ppc, CFL 0.05"] == ""
    assert "at 16 per cell and CFL 0.05 the nodal density L1 is" in found.sentence
    assert "source-matching settings from the identification table" in found.evidence
    elsewhere = claim_named("C11").finding({**tables, "identification/sod": _identified(32, 0.2)})
    assert {"setting": "32 ppc, CFL 0.2", "verdict": "not run in sod/seeds", "source-matching": "nodes L1, rank 1"} \
        in elsewhere.table
    without = claim_named("C11").finding(tables)
    assert "no identification table" in without.evidence
    assert found.verdict == without.verdict  # the column informs, the verdict is the source's settings'


def test_c11_needs_five_meshes_and_six_runs_on_each():
    assert judge("C11", made_up_tables(meshes=MESHES[:4]))[0] == "not measured"
    assert judge("C11", made_up_tables(seeds=study.SEEDS[:4]))[0] == "not measured"


# ----------------------------------------------------------------------------- E3

def test_e3_is_confirmed_when_mpm_stays_within_a_constant_factor_of_fem():
    constant = made_up_tables(_model(lambda h: 2.2 * h, nodes=lambda h: 1.5 * h))
    verdict, evidence = judge("E3", constant)
    assert verdict == "confirmed" and "particles x0.99 [0.97, 1.03] (constant)" in evidence
    assert "FV: FV MUSCL-HLLC (MC); FEM: viscosity everywhere" in evidence


def test_e3_gives_a_sentence_and_a_table_from_its_numbers(tables):
    constant = claim_named("E3").finding(made_up_tables(_model(lambda h: 2.2 * h, nodes=lambda h: 1.5 * h)))
    grows = claim_named("E3").finding(tables)
    assert "changes by a factor 1.0 at 4-8 particles per cell" in constant.sentence
    assert constant.sentence != grows.sentence and "changes by a factor" in grows.sentence
    assert [r["verdict"] for r in constant.table] == ["confirmed"] * len(study.SETTINGS)


def test_e3_names_the_error_that_grows(tables):
    verdict, evidence = judge("E3", tables)  # MPM's particle error grows below h = 0.00125, FEM's falls
    assert verdict == "refuted" and "(MPM's grows)" in evidence
    fem_worse = made_up_tables(_model(lambda h: 50 * h ** 2, fem=lambda h: 0.1 * h ** 0.5))
    assert judge("E3", fem_worse)[0] == "refuted" and "(FEM's grows)" in judge("E3", fem_worse)[1]


def test_e3_counts_a_change_only_when_its_range_over_the_seeds_is_decided():
    # MPM over FEM grows by (0.01 / 0.0003125)^0.117 = 1.5 at the finest mesh: the seeds straddle the factor
    straddling = made_up_tables(_model(lambda h: 2.0 * h ** 0.883 * 0.01 ** 0.117, noise=0.1))
    assert judge("E3", straddling)[0] == "partly"


# ----------------------------------------------------------------------------- C12, C14

def test_c12_ranks_the_waves_by_error_per_unit_length_per_setting(tables):
    """The made-up waves carry 60% of the error on 0.16 of the tube, the smooth region 25% on 0.34: 5x per
    unit length. A smooth region carrying 90% brings the waves to 1.4x, below the study's factor 2."""
    verdict, evidence = judge("C12", tables)
    assert verdict == "confirmed" and "the waves' error per unit length 5.1x the smooth region's" in evidence
    smooth = mutate(tables, "sod/regions", {"method": "MPM nodes", "h": FINEST}, share_2=0.9)
    assert judge("C12", smooth)[0] == "partly"
    none = mutate(tables, "sod/regions", {"method": "MPM nodes"}, share_2=0.9)
    assert judge("C12", none)[0] == "differs"
    only_16 = mutate(tables, "sod/regions", {"method": "MPM nodes", "ppc": 16}, share_2=0.9)
    verdict, evidence = judge("C12", only_16)
    assert verdict == "confirmed" and "16 ppc, CFL 0.05: differs" in evidence
    sentences = {claim_named("C12").finding(t).sentence for t in (tables, none)}
    assert len(sentences) == 2 and all("times the smooth region's" in x for x in sentences)
    unrecorded = {**tables, "settings": [r for r in tables["settings"] if r["key"] != "region_half_width"]}
    assert judge("C12", unrecorded)[0] == "not measured"


def test_c14_compares_crossing_particles_with_moving_ones():
    """Particles at rest make no extrema: against every non-crossing particle the crossing rate looks
    five times larger, against the moving ones it is 1.5x, below the threshold."""
    weak = made_up_tables(counter=lambda: extrema(crossing=0.0015, moving=0.001))
    verdict, evidence = judge("C14", weak)
    assert verdict == "refuted", evidence
    assert float(weak["sod/extrema"][0]["density_rate_ratio"]) == pytest.approx(5.0)
    assert judge("C14", made_up_tables())[0] == "confirmed"
    some = mutate(made_up_tables(), "sod/extrema", {"ppc": 4}, density_moving_ratio=1.5)
    assert judge("C14", some)[0] == "partly"


def test_c11_quotes_the_drift_studys_mechanism_from_its_table(tables):
    """C11's evidence ends with the drift study's sentence, formatted from ``drift/drift``: absent, it says
    so; present, the sentence follows the table (a growth removed by a variant is named there)."""
    from test_drift import MEASURED, _tables

    from mpm_fem.measure.claims.drift import mechanism
    from mpm_fem.measure.schema import DRIFT

    verdict, without = judge("C11", {k: v for k, v in tables.items() if k != DRIFT.name})
    assert "Mechanism (drift/drift): not measured" in without
    drift = _tables(MEASURED)
    verdict_with, evidence = judge("C11", {**tables, **drift})
    assert verdict_with == verdict  # the mechanism is quoted, not judged
    assert evidence.endswith(f"Mechanism (drift/drift): {mechanism(drift)}")
    assert "V + dt int dv/dx" in evidence
