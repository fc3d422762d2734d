"""E5's criterion (mpm_fem.measure.claims, block "remedies: E5") on made-up tables: each part of the goal
can fail it (mutation tests: one number moved across a threshold flips the verdict)."""

import pytest
from claim_mutations import judge

from mpm_fem.measure.claims import remedy_assessment as assess


def verdict(tables):
    return judge("E5", {"remedies/errors": tables["errors"]})

H = (0.01, 0.005, 0.0025, 0.00125)


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
    assert v == "partly" and evidence.endswith("the Sod plateau is removed by fix (1.31x / 1.60x FV)")


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
