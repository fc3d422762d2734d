"""E5 study (studies/remedies.py): the quick run writes its tables, figures and verdict."""

import pytest
from claim_mutations import judge

from mpm_fem.app.study import StudyOptions, read_table
from mpm_fem.core.models.euler import IdealGas
from mpm_fem.core.step import Stages
from mpm_fem.fused.step import supported
from mpm_fem.measure.tables import load_tables
from studies import remedies, sod


@pytest.mark.parametrize("tier", ["full", "deep"])
def test_plan_runs_every_remedy_on_the_stated_meshes(tier):
    plan = remedies._plan(tier)
    assert remedies.SOD_H == sod.H[:7]  # the convergence study's meshes to h = 0.00015625
    meshes = set(remedies.SOD_H) if tier == "deep" else set(remedies.SOD_H[:6])
    assert {h for _, h in plan["sod"]} == meshes
    assert set(plan["fv"]) == meshes  # the FV reference on every mesh any remedy runs
    assert {n for n, _ in plan["burgers"]} == set(remedies.REMEDIES)
    sod_meshes = {n: {h for m, h in plan["sod"] if m == n} for n in remedies.REMEDIES}
    finest = {"MPM", "B-spline domain", "B-spline domain + Taylor + volume", "B-spline domain + XPIC(5)"}
    for name in remedies.REMEDIES:  # the four to h = 0.0003125 (deep: 0.00015625), the others one mesh coarser
        n = (6 if name in finest else 5) + (tier == "deep")
        expected = set(remedies.SOD_H[:n])
        assert sod_meshes[name] == expected, name
        assert supported(IdealGas(), Stages(**remedies.REMEDIES[name])) is None, name
    assert plan["sod"][("B-spline domain + XPIC(5)", 0.0003125)]["xpic"] == 5
    assert all(case["ppc"] == 16 and case["cfl"] == 0.05 for case in plan["sod"].values())
    assert all(case["ppc"] == 4 and case["acceleration"] == "calculated" for case in plan["burgers"].values())
    assert all("kernel" not in case for part in ("sod", "burgers") for case in plan[part].values())  # fused


def test_quick_plan_runs_the_numpy_step():
    plan = remedies._plan("quick")
    assert all(case["kernel"] == "numpy" for part in ("sod", "burgers") for case in plan[part].values())


@pytest.mark.slow
def test_quick_run_writes_tables_figures_and_the_e5_verdict(tmp_path):
    remedies.run(StudyOptions(quick=True, out=tmp_path, jobs=1, progress=False))
    folder = tmp_path / "remedies"
    for name in ("errors.csv", "orders.csv", "cost.csv", "cost.png", "errors.png"):
        assert (folder / name).exists(), name
    errors = read_table(folder / "errors.csv")
    sod = {r["remedy"]: r for r in errors if r["problem"] == "sod" and r["h"] == "0.01"}
    assert float(sod["MPM"]["nodes_L1"]) == pytest.approx(0.0083452, rel=1e-4)  # the Sod study's value
    ratio = float(sod["MPM"]["nodes_L1"]) / float(sod["MPM"]["fv_L1"])
    assert float(sod["MPM"]["ratio_fv_nodes_L1"]) == pytest.approx(ratio, rel=1e-4) and 1.0 < ratio < 2.0
    cost = read_table(folder / "cost.csv")
    assert list(cost[0])[-1] == "wall_s"
    verdict, evidence = judge("E5", load_tables(tmp_path))
    assert verdict in ("confirmed", "partly", "refuted") and "FV error" in evidence
