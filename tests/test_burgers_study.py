"""Viscous Burgers study (C13, C3, C15): the fused run, the orders of convergence, the source's table.

The numbers asserted here are measured by ``studies/burgers.py`` on the full set of meshes; these
fast tests run the coarse meshes of the same settings.
"""

import csv
import json
from dataclasses import replace
from functools import lru_cache

import matplotlib.image
import numpy as np
import pytest

from baselines import fem_burgers
from baselines.exact.burgers import make_solution
from mpm_fem.app.study import StudyOptions
from mpm_fem.measure import burgers_tables
from mpm_fem.problems import burgers
from studies import burgers as study


def _by_position(result):
    order = np.argsort(result.particles.x)
    P = result.particles
    return P.x[order], P.velocity[order], P.volume[order]


@pytest.mark.parametrize("changes", [
    {},
    {"acceleration": "exact"},
    {"mass": "consistent", "cfl": 0.3},
    {"solution": "cole_hopf", "eps": 0.02},
    {"acceleration": "exact", "dt_rule": "advective", "refine": 2},
    {"weights": "cell", "force": "slides"},
])
def test_fused_run_is_the_numpy_step(changes):
    """The fused kernel and ``run(explicit_step)`` take the same steps: the same particles to 1e-12
    relative (max norm, each field: the point mass's uniform-grid arithmetic, tests/test_fused.py)."""
    settings = burgers.BurgersSettings(h=0.02, **changes)
    numpy_run = burgers.simulate(replace(settings, kernel="numpy"), progress=False)
    fused = burgers.simulate(settings, progress=False)
    assert fused.steps == numpy_run.steps and fused.particles.n == numpy_run.particles.n
    pairs = zip(_by_position(numpy_run) + (numpy_run.nodal_velocity,), _by_position(fused) + (fused.nodal_velocity,),
                strict=False)
    for (a, b), name in zip(pairs, ("x", "v", "V", "v_i"), strict=False):
        gap = float(np.max(np.abs(a - b)) / np.max(np.abs(a)))
        assert gap <= 1e-12, f"{name}: fused and numpy runs differ by {gap:.3g} relative"


def test_slides_weights_are_h_over_the_cell_count():
    """weights 'cell': every particle of a cell weighs h / N_p^i after each step, whatever the flow did."""
    settings = burgers.BurgersSettings(h=0.05, weights="cell", T=0.1)
    result = burgers.simulate(settings, progress=False)
    P, grid = result.particles, result.grid
    cell = np.minimum(((P.x - grid.nodes[0]) / settings.h).astype(int), grid.n_cells - 1)
    count = np.bincount(cell, minlength=grid.n_cells)
    assert np.allclose(P.volume, settings.h / count[cell], rtol=1e-12)
    assert np.allclose(np.bincount(cell, P.volume, grid.n_cells)[count > 0], settings.h, rtol=1e-12)


def test_settings_refuse_what_they_do_not_implement():
    with pytest.raises(ValueError, match="only the exact acceleration"):
        burgers.BurgersSettings(h=0.02, dt_rule="advective")
    with pytest.raises(ValueError, match="unknown weights"):
        burgers.BurgersSettings(h=0.02, weights="mass")
    with pytest.raises(ValueError, match="point-mass second difference"):
        burgers.BurgersSettings(h=0.02, basis="gimp", force="slides")
    with pytest.raises(ValueError, match="unknown kernel"):
        burgers.BurgersSettings(h=0.02, kernel="cuda")


# ---------------------------------------------------------------- C13: orders of the study's settings

@lru_cache(maxsize=None)
def _errors(h, **changes):
    """Velocity errors at T (over particles and nodes) of the study's default problem (the viscous
    rarefaction, eps = 0.045, 4 particles per cell, CFL 0.5, lumped mass, USL) with ``changes``."""
    settings = burgers.BurgersSettings(h=h, solution=study.DEFAULT, eps=0.045, **changes)
    return burgers.errors(settings, burgers.simulate(settings, progress=False))["velocity"]


def _order(h1, h2, where, norm, **changes):
    e1, e2 = _errors(h1, **changes)[where][norm], _errors(h2, **changes)[where][norm]
    return float(np.log(e1 / e2) / np.log(h1 / h2)), (e1, e2)


@pytest.mark.parametrize("norm", ["L1", "max"])
def test_exact_acceleration_with_dt_proportional_to_h_is_first_order(norm):
    """The source's first-order row: with dt = 0.5 h / max|v| (no viscous limit, which the exact
    acceleration does not need) the O(dt) error of the semi-implicit Euler step is O(h)."""
    for h1, h2 in ((0.01, 0.005), (0.005, 0.0025)):
        order, errs = _order(h1, h2, "particles", norm, acceleration="exact", dt_rule="advective")
        assert 0.8 <= order <= 1.3, f"h {h1} -> {h2}: {norm} errors {errs}, observed order {order:.2f}"


def test_exact_acceleration_with_the_viscous_time_step_is_second_order():
    """With the calculated variant's dt = 0.5 h^2 / (2 eps), the exact variant's error (time error
    O(dt) plus space error O(h^2): see timestep.csv) is second order, not first as in the source."""
    order, errs = _order(0.01, 0.005, "particles", "max", acceleration="exact")
    assert 1.7 <= order <= 2.3, f"max errors {errs}, observed order {order:.2f}"


@pytest.mark.parametrize("norm", ["L1", "max"])
def test_calculated_acceleration_stalls_with_four_particles_per_cell(norm):
    """Not the source's first order: with 4 particles per cell the calculated acceleration stops
    converging by h = 0.01 (study: 0.01 -> 0.0025 gives orders -0.4 (L1) and 0.05 (max)). What
    changes it, one change at a time, is diagnosis.csv's (C13's evidence states it)."""
    order, errs = _order(0.01, 0.005, "particles", norm)
    assert -0.5 <= order <= 0.4, f"{norm} errors {errs}, observed order {order:.2f}"


def test_exact_acceleration_beats_calculated_at_every_h_with_the_same_time_step():
    """As in the source, the exact acceleration is the more accurate, here by more than 10x."""
    for h in (0.01, 0.005):
        for norm in ("L1", "L2", "max"):
            exact, calc = _errors(h, acceleration="exact")["particles"][norm], _errors(h)["particles"][norm]
            assert 10 * exact < calc, f"h={h} {norm}: exact {exact:.3g}, calculated {calc:.3g}"


def test_time_error_of_the_calculated_acceleration_is_below_its_space_error():
    """dt / 4 at h = 0.01 changes the calculated variant's max error by less than 15 %."""
    coarse, fine = _errors(0.01)["particles"]["max"], _errors(0.01, refine=4)["particles"]["max"]
    assert abs(coarse - fine) < 0.15 * fine, f"max error {coarse:.4g} at dt, {fine:.4g} at dt/4"


@pytest.mark.slow
def test_sixteen_particles_per_cell_restore_first_order_for_the_calculated_acceleration():
    """C3 for Burgers: at 16 particles per cell the node-crossing jumps are 4x smaller and the
    calculated acceleration converges at first order over h = 0.01 ... 0.0025."""
    for h1, h2 in ((0.01, 0.005), (0.005, 0.0025)):
        order, errs = _order(h1, h2, "particles", "max", ppc=16)
        assert 0.7 <= order <= 1.3, f"h {h1} -> {h2}: max errors {errs}, observed order {order:.2f}"


@pytest.mark.slow
def test_gimp_removes_the_stall_of_the_calculated_acceleration():
    """GIMP's G_ip is continuous as a particle crosses a node: no jump in the force quadrature."""
    order, errs = _order(0.01, 0.005, "particles", "L1", basis="gimp")
    assert order >= 1.5, f"L1 errors {errs}, observed order {order:.2f}"


def test_smoke_sixteen_particles_per_cell_cut_the_stalled_error():
    """The fast version of the slow check above, on the two coarsest meshes: at h = 0.01, 16 particles
    per cell make the calculated acceleration's max error at least 2x smaller than 4 per cell
    (3.4x measured), and it still falls from h = 0.02 (order 1.28 measured)."""
    sixteen, four = _errors(0.01, ppc=16)["particles"]["max"], _errors(0.01)["particles"]["max"]
    assert 2 * sixteen < four, f"max error 16 ppc {sixteen:.3g}, 4 ppc {four:.3g}"
    order, errs = _order(0.02, 0.01, "particles", "max", ppc=16)
    assert 0.7 <= order <= 1.6, f"max errors {errs}, observed order {order:.2f}"


def test_smoke_gimp_removes_the_stall_on_the_coarse_meshes():
    """The fast version of the slow GIMP check: order of the L1 error from h = 0.02 to 0.01 (2.00 measured).
    On the numpy step, which measures the same method (the fused step's equality to it, GIMP and
    Burgers, is tests/test_fused.py) without compiling GIMP's Burgers variants here."""
    order, errs = _order(0.02, 0.01, "particles", "L1", basis="gimp", kernel="numpy")
    assert order >= 1.5, f"L1 errors {errs}, observed order {order:.2f}"


def test_fem_p1_consistent_is_second_order_in_l2_and_lumped_is_larger():
    solution = make_solution(study.DEFAULT, 0.045)
    e = {(m, h): fem_burgers.errors(fem_burgers.solve(solution, h, mass=m), solution)["L2"]
         for m in ("consistent", "lumped") for h in (0.02, 0.01)}
    order = np.log2(e[("consistent", 0.02)] / e[("consistent", 0.01)])
    assert 1.8 <= order <= 2.2, f"consistent L2 {e}, observed order {order:.2f}"
    assert e[("lumped", 0.01)] > 2 * e[("consistent", 0.01)], e


def test_source_table_with_corrections_falls_monotonically():
    """docs/claims.md's exponent corrections (*) put every row of the source's table in decreasing order."""
    for row, table in study.SOURCE.items():
        for eps, values in table.items():
            assert all(a > b for a, b in zip(values, values[1:], strict=False)), f"{row} eps={eps}: {values}"
            assert all(0.8 < a / b < 4 for a, b in zip(values, values[1:], strict=False)), f"{row} eps={eps}: {values}"


def test_the_reported_step_is_the_run_step_not_the_last_sliver():
    """57,600 steps of dt = T / 57,600 fall short of T by round-off (about 7e-13), so the run takes a
    57,601st step of that sliver to land on T; the table's ``dt`` is the run's step, not the sliver
    (its smallest step, ``dt_min``, which the table once reported: dt = 7.2e-13 at h = 0.00125)."""
    r = study.run_case({"solver": "mpm", "h": 0.04, "refine": 1024, "ppc": 4})
    assert r["steps"] == 57601 and r["dt_min"] < 1e-9, "the case no longer ends with a sliver step: pick another"
    assert r["dt"] == pytest.approx(0.5 / 57600, rel=1e-9)


# ---------------------------------------------------------------- the plan: settings shown, seeds

def test_the_calculated_acceleration_runs_at_four_eight_and_sixteen_per_cell_on_every_mesh():
    """Deep tier: every eps and mesh of the source's table at 4, 8 and 16 per cell, with the full tier's
    seeds and 8 per cell's one mesh further; full tier: every mesh but the finest at 16 per cell (at the seeds'
    eps), but the two finest at 8 per cell (its h = 0.00125 moved to the deep tier for the full tier's hour)."""
    deep, full = study._plan("deep"), study._plan("full")
    for n, m in study.CALCULATED.items():
        assert {(e, h) for s, mm, e, h in deep["table"] if (s, mm) == (study.DEFAULT, m)} == {
            (e, h) for e in study.EPS for h in study.H}, n
        meshes = {h for s, mm, e, h in full["table"] if (s, mm, e) == (study.DEFAULT, m, study.EPS[0])}
        meshes |= {h for mm, e, h, layout, _ in full["seeds"] if mm == m and layout == "regular"}
        assert set(study.H[:3 if n == 8 else 4]) <= meshes, n
    assert study.MESHES["deep"]["seeds"] == {**study.MESHES["full"]["seeds"], "mpm_calculated_8": study.H[:4]}
    for tier, plan in (("deep", deep), ("full", full)):
        for m, hs in study.MESHES[tier]["seeds"].items():
            for h in hs:
                layouts = {(layout, seed) for mm, e, hh, layout, seed in plan["seeds"] if (mm, hh) == (m, h)}
                assert layouts == {("regular", 0)} | {("jittered", k) for k in study.SEEDS}, (tier, m, h)
                assert len(study.SEEDS) >= 5


def test_the_regular_seed_is_the_table_run():
    """The regular layout's run of the seeds is the table's run (the same case: the sweep runs it once)."""
    plan = study._plan("full")
    for (m, eps, h, layout, _), case in plan["seeds"].items():
        if layout == "regular" and (study.DEFAULT, m, eps, h) in plan["table"]:
            assert case == plan["table"][(study.DEFAULT, m, eps, h)]
    jittered = [c for (_, _, _, layout, _), c in plan["seeds"].items() if layout == "jittered"]
    assert {c["seed"] for c in jittered} == set(study.SEEDS) and all(c["layout"] == "jittered" for c in jittered)


def _fake(case: dict) -> dict:
    """A run's result without running it: errors ``(1 + seed / 10) h^p``, ``p`` by method and layout."""
    if case.get("profile"):
        return {"ok": False, "error": "not run"}
    p = 1.0 if case.get("acceleration") == "exact" or case["solver"] == "fem" else (
        0.0 if case.get("layout") == "jittered" else 0.5 * np.log2(case.get("ppc", 4)) - 0.5)
    e = (1 + case.get("seed", 0) / 10) * case["h"] ** p
    errors = {"L1": e, "L2": 1.1 * e, "max": 2 * e}
    return {"ok": True, "nodes": errors, **({} if case["solver"] == "fem" else {"particles": errors, "n_p": 10}),
            "steps": 10, "dt": 0.01}


class _FakeRuns(StudyOptions):
    """The full tier's options, its sweep returning :func:`_fake` results."""

    def sweep_plan(self, name, fn, plan, cost=None):
        return {g: {k: _fake(c) for k, c in group.items()} for g, group in plan.items()}


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """The full tier's tables, JSON files and figures, written from :func:`_fake` results."""
    out = tmp_path_factory.mktemp("figures")
    study.run(_FakeRuns(out=out))
    return out / study.NAME


def _read(folder, name):
    with open(folder / f"{name}.csv", newline="") as f:
        return list(csv.DictReader(f))


def test_the_seeds_table_has_a_row_per_run(written):
    rows = _read(written, "seeds")
    assert len(rows) == len(study._plan("full")["seeds"])
    assert {"h", "ppc", "layout", "seed", "eps", "acceleration", "particles_L1", "nodes_L1", "particles_max"} <= set(
        rows[0])
    sixteen = [r for r in rows if r["method"] == "mpm_calculated_16" and r["layout"] == "jittered"]
    assert sixteen and all(r["ppc"] == "16" and r["acceleration"] == "calculated" for r in sixteen)


def test_the_orders_carry_the_spread_over_the_runs(written):
    """Fake errors: the regular layout's order at 4 / 8 / 16 per cell is 0.5 / 1 / 1.5, the jittered
    ones' 0: the mean, range and successive ranges of the table are theirs."""
    rows = [r for r in _read(written, "orders") if r["where"] == "particles" and r["norm"] == "max"]
    for n, m in study.CALCULATED.items():
        row = next(r for r in rows if r["method"] == m and float(r["eps"]) == study.EPS[0])
        regular = 0.5 * np.log2(n) - 0.5
        assert int(row["runs"]) == 1 + len(study.SEEDS) and row["ppc"] == str(n)
        assert float(row["fitted_lo"]) == pytest.approx(min(0, regular), abs=1e-6)
        assert float(row["fitted_hi"]) == pytest.approx(max(0, regular), abs=1e-6)
        assert float(row["fitted_mean"]) == pytest.approx(regular / 6, abs=1e-6)
        assert float(row["order_hi_0.01_0.005"]) == pytest.approx(max(0, regular), abs=1e-6)
        other = next(r for r in rows if r["method"] == m and float(r["eps"]) == study.EPS[-1])
        assert other["runs"] == "1" and other["fitted_lo"] == ""


def test_every_json_records_the_settings_used(written):
    """The methods' settings are the cases' own (no default block contradicting them); the seeds'
    tables record the layouts, seeds and meshes run."""
    plan = study._plan("full")
    for path in written.glob("*.json"):
        if path.name == "figures.json":
            continue
        settings = json.loads(path.read_text())["settings"]
        assert "problem" not in settings and settings["tier"] == "full", path.name
        for (_, m, _, _), case in plan["table"].items():
            recorded = settings["methods"][m]["settings"]
            assert {k: case[k] for k in recorded} == recorded, (path.name, m)
    seeds = json.loads((written / "seeds.json").read_text())["settings"]
    assert seeds["seeds"] == [0, *study.SEEDS]
    assert seeds["meshes"] == {m: list(hs) for m, hs in study.MESHES["full"]["seeds"].items()}
    assert json.loads((written / "ppc.json").read_text())["settings"]["eps"] == study.EPS[0]


def _aspects(folder) -> dict:
    return {p.name: matplotlib.image.imread(p).shape[1] / matplotlib.image.imread(p).shape[0]
            for p in sorted(folder.glob("*.png"))}


def test_no_figure_is_wider_than_two_and_a_half_times_its_height(written, tmp_path):
    """Full tier (five eps: a grid) and quick tier (one eps)."""
    study.run(_FakeRuns(out=tmp_path, quick=True))
    for aspects in (_aspects(written), _aspects(tmp_path / study.NAME)):
        assert {"convergence.png", "seeds.png", "solutions.png"} <= set(aspects)
        assert all(a <= 2.5 for a in aspects.values()), aspects


def test_the_errors_table_carries_the_range_the_figure_draws():
    seeds = {("mpm_calculated", 0.045, h, layout, k): _fake({"solver": "mpm", "h": h, "layout": layout, "seed": k})
             for h in (0.01, 0.005) for layout, k in (("regular", 0), ("jittered", 1), ("jittered", 2))}
    methods = {"mpm_calculated": {"source_row": "calculated", "ppc": 4}}
    errors, _ = burgers_tables.errors_and_orders({}, seeds, methods, study.SOLUTIONS, study.DEFAULT, "particles", "max")
    assert [r["h"] for r in errors] == [0.01, 0.005]  # the regular runs of the seeds are the table's
    row = errors[0]
    assert row["runs"] == 3 and row["particles_max_lo"] == pytest.approx(2 * 0.01**0.5)
    assert row["particles_max_hi"] == pytest.approx(2 * 1.2) and row["particles_max"] == row["particles_max_lo"]
