"""Sod's shock tube study (studies/sod.py): FEM baseline conservation and accuracy, MPM
against the source's table (C11), the region split (C12), new-extrema counting (C14), and lost
positivity reported cleanly."""

from functools import lru_cache

import numpy as np
import pytest

from baselines import fem_euler
from baselines.exact import riemann
from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.particles import make_particles
from mpm_fem.measure import shock_tube
from mpm_fem.measure.regions import (
    REGION_NAMES,
    ExtremaCounter,
    l1_by_region,
    mean_by_region,
    sod_regions,
    strict_extrema,
)
from mpm_fem.problems.sod import SodSettings
from studies import sod as study

RHO_POST_SHOCK = 0.26557  # Toro, Table 4.2
WAVES = riemann.wave_positions(0.2, (1.0, 0.0, 1.0), (0.125, 0.0, 0.1))


@lru_cache(maxsize=None)
def _case(kind: str, h: float, mass: str = "lumped", **changes):
    case = study.fem_case(h, mass) if kind == "fem" else study.mpm_case(h, **changes)
    return study.run_case(case)


@pytest.mark.parametrize("mass", ["consistent", "lumped"])
def test_fem_conserves_mass_to_round_off_and_post_shock_density_is_within_1_percent(mass):
    r = _case("fem", 0.0025, mass)
    assert r["ok"], r.get("error")
    grid = uniform_grid(0, 1, 0.0025)
    initial = float(np.sum(grid.lumped_mass * fem_euler.sod_initial_state(grid.nodes, 1.4)[0]))
    assert abs(r["mass"] - initial) < 1e-13 * initial, f"FEM {mass}: mass {r['mass']!r} at T, {initial!r} at t = 0"
    profile = r["profile"]  # h = 0.0025 is a profile mesh
    x, rho = np.array(profile["x"]), np.array(profile["density"])
    plateau = (x > WAVES["contact"] + 0.03) & (x < WAVES["shock"] - 0.03)
    mean = rho[plateau].mean()
    assert abs(mean / RHO_POST_SHOCK - 1) < 0.01, f"FEM {mass}: post-shock density {mean:.5f} vs {RHO_POST_SHOCK}"


def test_mpm_density_error_falls_from_h_001_to_0005_and_both_are_within_factor_two_of_the_source():
    """C11 at the start of the table: the nodal density L1 (the norm that matches the source)."""
    e = {h: _case("mpm", h)["density"]["nodes"]["L1"] for h in (0.01, 0.005)}
    assert e[0.005] < e[0.01], f"L1 {e}: no convergence from h = 0.01 to 0.005"
    for h, value in e.items():
        source = study.SOURCE[h][0]
        assert source / 2 < value < 2 * source, f"h={h}: nodal L1 {value:.4g} vs the source's {source:.4g}"


@pytest.mark.parametrize("where", ["nodes", "particles"])
def test_region_split_sums_to_the_total_l1_error(where):
    r = _case("mpm", 0.01)
    parts = np.array(r["regions"][where])
    total = r["density"][where]["L1"]
    assert parts.shape == (len(REGION_NAMES),) and np.all(parts >= 0)
    assert abs(parts.sum() - total) < 1e-12 * total, f"{where}: regions sum {parts.sum()!r}, L1 {total!r}"


def test_regions_follow_the_exact_waves_and_cover_the_domain():
    w = 0.02
    regions = sod_regions(WAVES, w)
    probes = {0.1: 0, WAVES["rarefaction_head"]: 1, 0.37: 2, WAVES["rarefaction_tail"]: 3, 0.6: 2,
              WAVES["contact"]: 4, 0.77: 5, WAVES["shock"]: 6, 0.95: 0, 0.0: 0, 1.0: 0}
    got = regions.index(np.array(list(probes)))
    assert got.tolist() == list(probes.values())
    x = np.linspace(0, 1, 1001)
    e = np.sin(7 * x)
    weights = np.full_like(x, 1e-3)
    assert l1_by_region(x, e, weights, regions).sum() == pytest.approx(np.sum(weights * np.abs(e)), rel=1e-13)
    assert mean_by_region(x, np.ones_like(x), weights, regions) == pytest.approx(np.ones(len(REGION_NAMES)))
    with pytest.raises(ValueError, match="overlap"):
        sod_regions(WAVES, 0.2)


def test_strict_extrema_ignore_round_off_and_plateaus():
    q = np.array([1.0, 1.0, 1.0 + 1e-14, 1.0, 0.5, 0.7, 0.3, 0.3])
    assert strict_extrema(q).tolist() == [False, False, False, False, True, True, False, False]


def test_extrema_counter_attributes_a_new_extremum_to_the_particle_that_crossed_a_node():
    grid = uniform_grid(0, 1, 0.25)
    x = np.array([0.05, 0.15, 0.24, 0.3, 0.4])
    old = make_particles(x, 0.05, np.array([1.0, 0.9, 0.8, 0.7, 0.6]), energy=np.array([1.0, 1.0, 1.0, 1.0, 1.0]))
    x_new = x.copy()
    x_new[2] = 0.26  # crosses the node 0.25
    rho = old.density.copy()
    rho[2] = 0.95  # leaves the range (0.7, 0.9) of its neighbours
    rho[3] = 0.65  # stays between its neighbours 0.95 and 0.6
    new = old.replace(x=x_new, density=rho)
    counter = ExtremaCounter(grid)
    counter(0, 0.0, old, new)
    s = counter.summary()
    assert s["crossings"] == 1
    # in a monotone sequence a new maximum makes its left neighbour (0.9 < 1, 0.95) a new minimum
    assert s["density"]["new_at_crossing"] == 1 and s["density"]["new_elsewhere"] == 1, s
    assert s["density"]["rate_crossing"] == 1.0 and s["density"]["rate_elsewhere"] == 0.25, s
    assert s["energy"]["new_at_crossing"] == 0 and s["energy"]["new_elsewhere"] == 0, s


def test_extrema_counter_compares_crossings_with_moving_particles_that_do_not_cross():
    """Of the four particles that do not cross, two move faster than the threshold; the new extremum
    of a particle at rest counts against every non-crossing particle, not against the moving ones."""
    grid = uniform_grid(0, 1, 0.25)
    x = np.array([0.05, 0.1, 0.15, 0.24, 0.3, 0.4])
    old = make_particles(x, 0.05, np.array([1.0, 0.9, 0.8, 0.7, 0.6, 0.5]), velocity=np.zeros(6))
    x_new = x.copy()
    x_new[3] = 0.26  # crosses the node 0.25
    rho = old.density.copy()
    rho[1] = 1.1  # a new maximum at a particle at rest
    rho[4] = 0.8  # a new maximum at a moving particle, which makes the crossing particle 3 a new minimum
    new = old.replace(x=x_new, density=rho, velocity=np.array([0.0, 0.0, 0.5, 0.5, 0.5, 1e-3]))
    counter = ExtremaCounter(grid, fields=("density",), moving_speed=0.01)
    counter(0, 0.0, old, new)
    s = counter.summary()
    assert (s["crossings"], s["moving_steps"]) == (1, 2)  # particles 2 and 4 move and stay in their cell
    d = s["density"]
    assert (d["new_at_crossing"], d["new_elsewhere"], d["new_moving"]) == (1, 2, 1), d
    assert (d["rate_crossing"], d["rate_moving"], d["rate_elsewhere"]) == (1.0, 1 / 2, 2 / 5), d


def test_the_particle_energy_error_is_measured_against_the_exact_internal_energy():
    r = _case("mpm", 0.01)
    energy = r["energy"]["particles"]
    assert 0 < energy["L1"] < 0.1 * shock_tube.exact_energy(np.array([0.1]))[0], energy
    rho, _, p = riemann.sample(np.array([0.7]), 0.2, (1.0, 0.0, 1.0), (0.125, 0.0, 0.1))
    assert shock_tube.exact_energy(np.array([0.7]))[0] == pytest.approx(p[0] / (0.4 * rho[0]))


def test_a_run_that_loses_positivity_reports_it_and_returns_no_nan():
    """CFL 1 with 16 particles per cell breaks 1 - (dv/dx) dt > 0 at the diaphragm."""
    r = study.run_case(study.mpm_case(0.01, cfl=1.0))
    assert r["ok"] is False
    assert "positivity lost at step" in r["error"] and "1 - (dv/dx) dt" in r["error"], r["error"]
    assert "nan" not in r["error"].lower().replace("reduce", "")


def test_cfl_above_one_is_refused_with_a_message():
    with pytest.raises(ValueError, match="CFL number must lie in"):
        SodSettings(cfl=1.5)


def test_one_set_of_settings_for_every_mesh():
    plan = study._plan("full")
    keys = set(study.MPM)
    for h, case in plan["mpm"].items():
        assert {k: case[k] for k in keys} == study.MPM, f"h={h} uses other settings"
    assert set(plan["mpm"]) == set(study.FULL_H) == set(study.SOURCE), "every mesh of the source's table is run"
    assert set(study._plan("deep")["mpm"]) == set(study.H + study.DEEP_H)


@pytest.mark.parametrize("tier", ["full", "deep"])
def test_every_setting_runs_on_every_mesh_with_the_regular_and_five_jittered_layouts(tier):
    """4, 8 and 16 particles per cell at CFL 0.05 and 4 at the CLI's CFL, regular and jittered down to
    h = 0.0003125, the study's own on every mesh (the deep tier: 16 and 4 per cell at CFL 0.05 on every
    mesh, the others one mesh further, the seeds where the full tier has them); new extrema not counted
    on the jittered layouts."""
    plan = study._plan(tier)
    assert {(4, 0.05), (8, 0.05), (16, 0.05), (4, SodSettings.cfl)} == set(study.SETTINGS)
    assert SodSettings.cfl == 0.1 and len(study.SEEDS) >= 5
    meshes = study.H + study.DEEP_H if tier == "deep" else study.FULL_H
    other = study.H if tier == "deep" else tuple(h for h in study.H if h >= 0.0003125)
    every = {(16, 0.05), (4, 0.05)} if tier == "deep" else {(16, 0.05)}
    assert set(plan["settings"]) == ({(n, c, h) for n, c in study.SETTINGS if (n, c) not in every for h in other}
                                     | {(n, c, h) for n, c in every for h in meshes})
    seed_meshes = {h for (_, _, h, _) in plan["seeds"]}
    assert min(seed_meshes) == 0.0003125 and max(seed_meshes) == study.H[0]
    assert len(plan["seeds"]) == len(study.SETTINGS) * len(seed_meshes) * len(study.SEEDS)
    for (n, cfl, h, seed), case in plan["seeds"].items():
        assert (case["ppc"], case["cfl"], case["h"], case["seed"], case["layout"]) == (n, cfl, h, seed, "jittered")
        assert not case["extrema"] and not case["profiles"]
    for (n, cfl, _), case in plan["settings"].items():
        assert (case["ppc"], case["cfl"], case["layout"], case["extrema"]) == (n, cfl, "regular", True)
    assert plan["settings"][(16, 0.05, 0.01)] == plan["mpm"][0.01]  # the study's own runs, shared


def read_csv_rows(path):
    import csv

    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def _check_quick_outputs(folder, hs, ppc_h, c11_judged=False):
    """Every table and figure of a quick run exists, and the claims judge them from the tables; C11 only
    where the plan has its five meshes of six runs (``c11_judged``: the quick tier's own plan)."""
    from mpm_fem.measure.claims import claims_of
    from mpm_fem.measure.tables import load_tables

    for name in ("convergence", "regions", "extrema", "ppc", "mass"):
        assert (folder / "sod" / f"{name}.csv").exists() and (folder / "sod" / f"{name}.json").exists(), name
    profiles = tuple(f"profiles_h{h:g}" for h in study.PROFILE_H if h in hs)
    for png in ("convergence", "regions", "extrema", "ppc") + profiles:
        assert (folder / "sod" / f"{png}.png").exists(), png
    tables = load_tables(folder)
    verdicts = {c.label: c.verdict(tables)[0] for c in claims_of("sod")}
    assert set(verdicts) == {"C3 (sod)", "C11", "C12", "C14", "C15 (sod)", "E3"}
    assert (verdicts["C11"] != "not measured") == c11_judged, verdicts  # the floor needs five meshes of six runs
    assert verdicts["E3"] != "not measured", verdicts  # a regular and five jittered runs on every mesh
    return verdicts


@pytest.mark.slow
def test_quick_study_writes_every_table_and_its_claims_are_judged(tmp_path):
    from mpm_fem.app.study import StudyOptions

    study.run(StudyOptions(quick=True, jobs=1, out=tmp_path, progress=False))
    verdicts = _check_quick_outputs(tmp_path, study.QUICK["H"], study.QUICK["PPC_H"], c11_judged=True)
    assert verdicts["C14"] != "not measured" and verdicts["C11"] == "differs", verdicts


def test_smoke_a_tiny_plan_writes_every_table_and_figure(tmp_path, monkeypatch):
    """The fast version of the slow check: the same run on the two coarsest meshes, few particles."""
    from mpm_fem.app.study import StudyOptions

    tiny = dict(H=(0.04, 0.02), PPC_H=(0.04,), CONSISTENT_H=(0.04,), PLATEAU_H=(),
                SETTINGS={setting: ((0.04, 0.02), (0.04, 0.02)) for setting in study.SETTINGS})
    monkeypatch.setattr(study, "QUICK", tiny)
    monkeypatch.setattr(study, "PROFILE_H", (0.04,))
    monkeypatch.setattr(study, "PPC", (4, 8))
    monkeypatch.setattr(study, "MPM", {**study.MPM, "ppc": 4, "cfl": 0.1})
    monkeypatch.setattr(study, "SOURCE", {0.04: (0.02, 0.03), 0.02: (0.01, 0.02)})
    study.run(StudyOptions(quick=True, jobs=1, out=tmp_path, progress=False))
    _check_quick_outputs(tmp_path, tiny["H"], tiny["PPC_H"])
    rows = read_csv_rows(tmp_path / "sod" / "convergence.csv")
    assert len(rows) == len(study.SETTINGS) * len(tiny["H"])  # every setting on every mesh
    first = [r for r in rows if (int(r["ppc"]), float(r["cfl"])) == study.SETTINGS[0]]
    nodal = [float(r["mpm_nodes_L1"]) for r in first]
    assert [float(r["h"]) for r in first] == list(tiny["H"])
    assert 0 < nodal[1] < nodal[0] < 0.1, f"nodal density L1 {nodal} should fall from h = 0.04 to 0.02"
    import json

    recorded = json.loads((tmp_path / "sod" / "convergence.json").read_text())["settings"]
    assert recorded["runs"]["ppc_cfl"] == [list(x) for x in study.SETTINGS]  # the settings run, and no others
    assert recorded["runs"]["layouts"] == {"regular": [0], "jittered": list(study.SEEDS)}
    assert not {"ppc", "cfl", "layout", "seed"} & set(recorded["problem"])  # the gas and the tube only
    seeds = read_csv_rows(tmp_path / "sod" / "seeds.csv")  # one row per run: the regular layout and every seed
    assert len(seeds) == len(study.SETTINGS) * len(tiny["H"]) * (1 + len(study.SEEDS))
    assert {(r["layout"], r["seed"]) for r in seeds} == {("regular", "0")} | {("jittered", str(k)) for k in study.SEEDS}
    for r in first:  # the jittered mean lies in its range, and the order's range holds its mean
        lo, mean, hi = (float(r[f"jittered_particles_L1_{k}"]) for k in ("lo", "mean", "hi"))
        assert 0 < lo <= mean <= hi
    lo, mean, hi = (float(first[1][f"order_particles_L1_{k}"]) for k in ("lo", "mean", "hi"))
    assert lo <= mean <= hi and lo <= float(first[1]["order_particles_L1"]) <= hi  # the regular layout is seed 0
