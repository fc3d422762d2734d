"""E5's criterion (mpm_fem.measure.claims.remedies) on made-up tables: each part of the goal can fail
it (mutation tests: one number moved across a threshold flips the verdict). On Sod a remedy is held to
the finite-volume reference's own orders and error on the same meshes."""

import pytest
from claim_mutations import judge

from mpm_fem.measure.claims import CONVERGING_ORDER, FLOOR_ORDER, FV_DRIFT, ORDER_MARGIN
from mpm_fem.measure.claims import remedy_assessment as assess


def verdict(tables):
    return judge("E5", {"remedies/errors": tables["errors"]})

H = (0.01, 0.005, 0.0025, 0.00125, 0.000625, 0.0003125)


def rows(problem, remedy, nodes, particles, fv=None):
    out = []
    for k, h in enumerate(H[: len(nodes)]):
        r = {"problem": problem, "remedy": remedy, "h": str(h), "nodes_L1": str(nodes[k]),
             "particles_L1": str(particles[k])}
        if fv is not None:
            r["fv_L1"] = str(fv[k])
        out.append(r)
    return out


FV = [0.008, 0.004, 0.002, 0.001]
GOOD_SOD = dict(nodes=[0.009, 0.0045, 0.00225, 0.00112], particles=[0.011, 0.0056, 0.0029, 0.0015])
STALLED_SOD = dict(nodes=[0.009, 0.0046, 0.0024, 0.0020], particles=[0.011, 0.0064, 0.0041, 0.0035])
GOOD_BURGERS = dict(nodes=[4e-4, 1e-4, 2.5e-5], particles=[5e-4, 1.3e-4, 3e-5])


def table(sod=GOOD_SOD, burgers=GOOD_BURGERS, fv=FV, extra=()):
    return {"errors": rows("sod", "MPM", **STALLED_SOD, fv=fv) + rows("sod", "fix", **sod, fv=fv)
            + rows("burgers", "MPM", nodes=[4e-4, 3e-4, 3e-4], particles=[5e-4, 4e-4, 4e-4])
            + rows("burgers", "fix", **burgers) + list(extra)}


def test_a_remedy_meeting_every_part_of_the_goal_is_confirmed_by_name():
    v, evidence = verdict(table())
    assert v == "confirmed" and evidence.startswith("meets the goal: fix:")


def test_one_stalled_pair_of_meshes_is_a_plateau():
    sod = dict(GOOD_SOD, particles=[0.011, 0.0056, 0.0029, 0.0021])  # order 0.47 on the last pair
    v, evidence = verdict(table(sod=sod))
    assert v == "refuted" and evidence.startswith("closest: fix")
    assert not assess(rows("sod", "fix", **sod, fv=FV))["removes_plateau"]


def test_more_than_one_and_a_half_times_the_fv_error_is_partly():
    v, evidence = verdict(table(fv=[x / 1.6 for x in GOOD_SOD["particles"]]))
    assert v == "partly" and "the Sod plateau is removed by fix (1.31x / 1.60x FV); " in evidence


def test_burgers_below_first_order_is_partly():
    v, _ = verdict(table(burgers=dict(nodes=[4e-4, 2.2e-4, 1.2e-4], particles=[5e-4, 2.8e-4, 1.5e-4])))  # ~0.87
    assert v == "partly"


def test_a_remedy_stopped_before_the_finest_sod_mesh_removes_no_plateau():
    """Good orders on the three coarse meshes only: not a remover (the plateau shows on fine meshes)."""
    coarse = rows("sod", "fix", nodes=GOOD_SOD["nodes"][:3], particles=GOOD_SOD["particles"][:3], fv=FV)
    full = table()
    stopped = {"errors": [r for r in full["errors"] if not (r["problem"] == "sod" and r["remedy"] == "fix")] + coarse}
    assert assess(coarse)["removes_plateau"]
    v, evidence = verdict(stopped)
    assert v == "refuted" and "over h = 0.01..0.0025" in evidence
    assert verdict(full)[0] == "confirmed"


def test_a_failed_run_counts_as_not_converging():
    sod = dict(GOOD_SOD, nodes=[0.009, 0.0045, 0.00225, float("nan")])
    assert verdict(table(sod=sod))[0] == "refuted"


@pytest.mark.parametrize("errors", [[], rows("sod", "fix", nodes=[0.01], particles=[0.01], fv=[0.01])])
def test_fewer_than_two_meshes_is_not_measured(errors):
    assert verdict({"errors": errors})[0] == "not measured"


def test_of_two_plateau_removers_the_one_nearer_the_fv_error_is_named():
    """Both remove the plateau and miss 1.5x FV: the smaller largest FV ratio names the closest, and
    moving that ratio above the other's names the other."""
    fv = [x / 2.0 for x in GOOD_SOD["particles"]]  # 'fix': particles at 2x the FV error
    near = dict(nodes=GOOD_SOD["nodes"], particles=[x * 1.8 for x in fv])  # 1.8x the FV error
    v, evidence = verdict(table(fv=fv, extra=rows("sod", "near", **near, fv=fv)
                                + rows("burgers", "near", **GOOD_BURGERS)))
    assert v == "partly" and evidence.startswith("near:")
    far = dict(near, particles=[x * 2.2 for x in fv])  # now beyond 'fix'
    v, evidence = verdict(table(fv=fv, extra=rows("sod", "near", **far, fv=fv)
                                + rows("burgers", "near", **GOOD_BURGERS)))
    assert v == "partly" and evidence.startswith("fix:")


def _power(e0: float, orders: list[float]) -> list[float]:
    """Errors from ``e0`` on the coarsest mesh of H, falling with the observed ``orders`` (halvings)."""
    out = [e0]
    for q in orders:
        out.append(out[-1] / 2 ** q)
    return out


def test_the_margin_to_the_fv_order_is_the_studys_undecided_band():
    assert ORDER_MARGIN == CONVERGING_ORDER - FLOOR_ORDER


@pytest.mark.parametrize("gap, removes", [(-0.15, True), (-0.25, False)])
def test_orders_are_judged_against_the_fv_references_own_on_the_same_meshes(gap, removes):
    """FV converging at 0.75 (a contact limits every method): a remedy 0.15 below it on the last pair
    still converges as the FV does; 0.25 below (more than the margin) it does not."""
    fv = _power(0.008, [0.75] * 3)
    sod = dict(nodes=_power(0.009, [0.75, 0.75, 0.75 + gap]), particles=_power(0.01, [0.75, 0.75, 0.75 + gap]))
    s = assess(rows("sod", "fix", **sod, fv=fv))
    assert s["removes_plateau"] is removes
    assert abs(s["min_gap_fv_particles_L1"] - gap) < 1e-9
    assert verdict(table(sod=sod, fv=fv))[0] == ("confirmed" if removes else "refuted")


def test_an_order_below_the_floor_is_a_plateau_even_where_the_fv_is_slow():
    fv = _power(0.008, [0.6] * 3)
    sod = dict(nodes=_power(0.009, [0.6, 0.6, 0.45]), particles=_power(0.011, [0.6, 0.6, 0.45]))
    assert 0.6 - 0.45 < ORDER_MARGIN and 0.45 < FLOOR_ORDER
    assert not assess(rows("sod", "fix", **sod, fv=fv))["removes_plateau"]


@pytest.mark.parametrize("gap, removes", [(-0.05, True), (-0.18, False)])
def test_an_error_drifting_away_from_the_fv_error_is_a_plateau(gap, removes):
    """Five halvings, each order within the margin of the FV's: at 0.18 below it the ratio to the FV
    error grows by 2^0.9 = 1.87x from the coarsest mesh to the finest, beyond FV_DRIFT; at 0.05, 1.19x.
    The remedy starts at half the FV error, so it stays within the goal's 1.5x on every mesh."""
    fv = _power(0.008, [1.0] * 5)
    sod = dict(nodes=_power(0.004, [1.0 + gap] * 5), particles=_power(0.004, [1.0 + gap] * 5))
    s = assess(rows("sod", "fix", **sod, fv=fv))
    assert (s["fv_drift_nodes_L1"] <= FV_DRIFT) is removes and s["removes_plateau"] is removes
    assert s["max_fv_ratio_particles_L1"] < 1.5
    assert verdict(table(sod=sod, fv=fv))[0] == ("confirmed" if removes else "refuted")


@pytest.mark.parametrize("order, removes", [(0.75, True), (0.65, False)])
def test_burgers_without_an_fv_reference_is_held_to_the_converging_order(order, removes):
    burgers = rows("burgers", "fix", nodes=_power(4e-4, [order] * 2), particles=_power(5e-4, [order] * 2))
    assert assess(burgers)["removes_plateau"] is removes
    assert "max_fv_ratio_nodes_L1" in assess(burgers) and "fv_drift_nodes_L1" not in assess(burgers)


def test_e5_reads_the_main_run_and_gives_the_other_runs_beside():
    """Rows of more runs (8 per cell, jittered seeds on the two coarsest meshes) do not mix with the
    main series: the verdict is the main run's, the other runs' lowest orders are given beside."""
    base = table()["errors"]
    sod = [r for r in base if r["problem"] == "sod"]
    coarse = sorted({float(r["h"]) for r in sod}, reverse=True)[:2]
    more = [{**r, "ppc": "8", "layout": "jittered", "seed": str(seed)} for seed in (1, 2) for r in sod
            if float(r["h"]) in coarse]
    plain = verdict({"errors": base})
    with_more = verdict({"errors": [{**r, "ppc": "", "layout": "", "seed": ""} for r in base] + more})
    assert with_more[0] == plain[0] == "confirmed"
    assert "; over 2 more runs (8 ppc, jittered 1, 8 ppc, jittered 2) on h = 0.01..0.005 its lowest" in with_more[1]
    assert "more runs" not in plain[1]
