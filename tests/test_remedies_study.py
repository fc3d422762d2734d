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
    meshes = set(remedies.SOD_H) if tier == "deep" else set(remedies.SOD_H[:5])
    assert {h for _, h in plan["sod"]} == meshes
    assert set(plan["fv"]) == meshes  # the FV reference on every mesh any remedy runs
    assert {n for n, _ in plan["burgers"]} == set(remedies.REMEDIES)
    sod_meshes = {n: {h for m, h in plan["sod"] if m == n} for n in remedies.REMEDIES}
    finest = {"MPM", "B-spline domain", "B-spline domain + Taylor + volume", "B-spline domain + XPIC(5)"}
    # full: every remedy to h = 0.000625; deep: the four to 0.00015625, the others to 0.0003125; every
    # remedy on the compiled step (APIC too: its kernels)
    for name in remedies.REMEDIES:
        n = (7 if name in finest else 6) if tier == "deep" else 5
        expected = set(remedies.SOD_H[:n])
        assert sod_meshes[name] == expected, name
        assert supported(IdealGas(), Stages(**remedies.REMEDIES[name])) is None, name
    assert plan["sod"][("B-spline domain + XPIC(5)", 0.000625)]["xpic"] == 5
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
    sod = {r["remedy"]: r for r in errors if r["problem"] == "sod" and r["h"] == "0.01" and r["seed"] == "0"}
    jittered = [r for r in errors if r["problem"] == "sod" and r["h"] == "0.01" and r["layout"] == "jittered"]
    assert {r["seed"] for r in jittered} == {"1", "2", "3", "4", "5"}  # the quick tier's layout runs
    assert all(1.0 < float(r["nodes_L1"]) / float(sod["MPM"]["nodes_L1"]) < 1.5 for r in jittered)
    assert float(sod["MPM"]["nodes_L1"]) == pytest.approx(0.0083452, rel=1e-4)  # the Sod study's value
    ratio = float(sod["MPM"]["nodes_L1"]) / float(sod["MPM"]["fv_L1"])
    assert float(sod["MPM"]["ratio_fv_nodes_L1"]) == pytest.approx(ratio, rel=1e-4) and 1.0 < ratio < 2.0
    cost = read_table(folder / "cost.csv")
    assert list(cost[0])[-1] == "wall_s"
    verdict, evidence = judge("E5", load_tables(tmp_path))
    assert verdict in ("confirmed", "partly", "refuted") and "FV error" in evidence


def test_the_layout_runs_cover_4_8_16_per_cell_on_the_regular_and_jittered_layouts():
    """E5 over the particle layouts: the full tier runs plain MPM, the deep tier every remedy of a
    point-mass basis, at 4, 8 and 16 per cell on the regular layout and the Sod study's five jittered seeds, on the
    two coarsest meshes of each problem (the deep tier one more); the study's own setting is the study's own case
    (run once); the quick tier plain MPM at the study's particles per cell, with the seeds, on its two meshes; no
    tier runs the particle-domain B-spline on the layouts (a particle left the grid at the wall)."""
    assert remedies.SEEDS == sod.SEEDS and remedies.LAYOUT_PPC == (4, 8, 16)
    assert remedies.LAYOUT_REMEDIES["full"] == ("MPM",)
    assert not any(remedies.REMEDIES[n].get("basis") == "bspline_gimp" for n in remedies.LAYOUT_REMEDIES["deep"])
    full, deep, quick = (remedies._plan(t) for t in ("full", "deep", "quick"))
    for problem, meshes in (("sod", remedies.SOD_H[:2]), ("burgers", remedies.BURGERS_H[:2])):
        got = full[f"{problem}_layouts"]
        assert set(got) == {(n, h, ppc, lay, s) for n in remedies.LAYOUT_REMEDIES["full"] for h in meshes
                            for ppc in (4, 8, 16) for lay, s in remedies.LAYOUTS}
        own = 16 if problem == "sod" else 4
        assert all(got[(n, h, own, "regular", 0)] == full[problem][(n, h)]
                   for n in remedies.LAYOUT_REMEDIES["full"] for h in meshes)
        assert set(got) < set(deep[f"{problem}_layouts"])
        case = deep[f"{problem}_layouts"][("Taylor + volume", meshes[0], 8, "jittered", 2)]
        assert (case["ppc"], case["layout"], case["seed"], case["reconstruct"]) == (8, "jittered", 2, "taylor")
        assert {(n, ppc) for n, _, ppc, *_ in quick[f"{problem}_layouts"]} == {("MPM", own)}
        assert all(c["kernel"] == "numpy" for c in quick[f"{problem}_layouts"].values())


def test_the_error_rows_carry_the_particle_setting_and_orders_within_each_setting():
    """errors.csv: one series per remedy and particle setting, its orders against the next coarser mesh of the same
    setting; orders.csv (the study's verdict table) reads the study's own setting only."""
    from mpm_fem.measure.schema import REMEDIES_ERRORS

    def result(e):
        return {"ok": True, "nodes": {"L1": e, "L2": e}, "particles": {"L1": 2 * e, "L2": 2 * e}, "steps": 10,
                "n_p": 100, "volume_drift": 0.0}

    got = {"sod": {("MPM", 0.02): result(0.02), ("MPM", 0.01): result(0.01)}, "burgers": {},
           "fv": {0.02: {"ok": True, "nodes": {"L1": 0.015}}, 0.01: {"ok": True, "nodes": {"L1": 0.008}}},
           "sod_layouts": {("MPM", 0.02, 16, "regular", 0): result(0.5), ("MPM", 0.02, 4, "jittered", 3): result(0.04),
                           ("MPM", 0.01, 4, "jittered", 3): result(0.02)}}
    rows = remedies._errors(got)
    REMEDIES_ERRORS.check(rows)
    assert [(r["ppc"], r["layout"], r["seed"], r["h"]) for r in rows] == [
        (16, "regular", 0, 0.02), (16, "regular", 0, 0.01), (4, "jittered", 3, 0.02), (4, "jittered", 3, 0.01)]
    assert rows[0]["nodes_L1"] == 0.02  # the study's own run, not a duplicate of it
    assert rows[1]["order_nodes_L1"] == pytest.approx(1.0) and rows[3]["order_nodes_L1"] == pytest.approx(1.0)
    summary = remedies._summary(rows)
    assert len(summary) == 1 and summary[0]["finest_nodes_L1"] == 0.01


def test_a_particle_leaving_the_grid_is_a_failed_run_not_a_crash(monkeypatch):
    from mpm_fem.bases import OutsideGridError

    def leaves(settings, progress=None):
        raise OutsideGridError("particle 0 at x=-1e-07 lies outside the grid [0.0, 1.0] (1 such particles)")

    monkeypatch.setattr(remedies.sod, "simulate", leaves)
    got = remedies.run_case({"solver": "sod", "h": 0.01, **remedies.SOD_MPM, **remedies.REMEDIES["cubic B-spline"]})
    assert got == {"ok": False, "error": "particle 0 at x=-1e-07 lies outside the grid [0.0, 1.0] (1 such particles)"}
