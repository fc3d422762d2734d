"""The drift study (C11's mechanism): the numpy step's density-update and volume-rate options, their
fall-back from the fused step, the study's plan and table, and the sentence
:func:`mpm_fem.measure.claims.drift.mechanism` formatted from the table, with perturbed tables
that change it."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.models.euler import IdealGas
from mpm_fem.core.particles import PositivityError, make_particles
from mpm_fem.core.shape import make_shape
from mpm_fem.core.step import Stages, Walls, explicit_step, numpy_only
from mpm_fem.core.volume import domain_rate
from mpm_fem.measure.claims.drift import GROWTH_ORDER, REDUCED, STUDY, mechanism
from mpm_fem.measure.schema import DRIFT
from mpm_fem.problems import sod
from mpm_fem.run import solve
from studies import drift

# ----------------------------------------------------------------------------- the options of the numpy step


def _gas_particles(n=50, seed=0):
    rng = np.random.default_rng(seed)
    x = np.sort(rng.uniform(0.05, 0.95, n))
    rho = rng.uniform(0.2, 1.0, n)
    eps = rng.uniform(1.0, 3.0, n)
    return make_particles(x, np.full(n, 1.0 / n), rho, 0.0, eps, 0.4 * rho * eps), rng.uniform(-2.0, 2.0, n)


def test_the_default_density_update_is_the_slides_bit_for_bit():
    P, L = _gas_particles()
    dt, l = 0.01, np.full(P.n, 0.02)
    new = IdealGas().update(P, L, dt, l)
    assert np.array_equal(new.density, P.density * (1.0 - L * dt))
    assert np.array_equal(IdealGas(density_update="linear").update(P, L, dt, l).pressure, new.pressure)


@pytest.mark.parametrize("form, ratio", [("inverse", lambda r: 1.0 / (1.0 + r)), ("exp", lambda r: np.exp(-r))])
def test_the_density_update_forms(form, ratio):
    P, L = _gas_particles()
    dt, l = 0.01, np.full(P.n, 0.02)
    new = IdealGas(density_update=form).update(P, L, dt, l)
    np.testing.assert_allclose(new.density / P.density, ratio(L * dt), rtol=1e-14)
    plain = IdealGas().update(P, L, dt, l)
    assert np.array_equal(new.energy, plain.energy)  # the energy keeps L_p
    np.testing.assert_allclose(new.density, plain.density, rtol=2 * np.max(np.abs(L * dt)) ** 2)


def test_a_volume_rate_moves_only_the_density_and_volume():
    P, L = _gas_particles()
    D = L + 0.3
    dt, l = 0.01, np.full(P.n, 0.02)
    new = IdealGas(density_update="inverse").update(P, L, dt, l, volume_rate=D)
    np.testing.assert_allclose(new.volume, P.volume * (1.0 + D * dt), rtol=1e-14)
    assert np.array_equal(new.energy, IdealGas().update(P, L, dt, l).energy)


def test_unknown_form_and_positivity():
    with pytest.raises(ValueError, match="density update"):
        IdealGas(density_update="cubic")
    P, _ = _gas_particles()
    with pytest.raises(PositivityError, match=r"1 \+ \(dv/dx\) dt"):
        IdealGas(density_update="inverse").update(P, np.full(P.n, -200.0), 0.01, np.full(P.n, 0.02))
    assert np.all(IdealGas(density_update="exp").update(P, np.full(P.n, 200.0), 0.01, np.full(P.n, 0.02)).density > 0)


@pytest.mark.parametrize("basis, domain", [("mpm", "gimp"), ("gimp", "gimp"), ("bspline", "bspline_gimp")])
def test_the_domain_rate_is_the_exact_integral_over_the_domain(basis, domain):
    """Inside the grid: ``(v_h(x + V/2) - v_h(x - V/2)) / V``, the particle-domain basis' gradient."""
    grid = uniform_grid(0.0, 1.0, 0.05)
    rng = np.random.default_rng(1)
    x = np.sort(rng.uniform(0.1, 0.9, 200))
    V = rng.uniform(0.002, 0.04, 200)
    v = rng.normal(size=grid.n_nodes)
    D = domain_rate(grid, x, V, v, basis)
    np.testing.assert_allclose(D, make_shape(grid, x, V, domain).gather_gradient(v), rtol=1e-10, atol=1e-10)
    point = make_shape(grid, np.concatenate((x + V / 2, x - V / 2)), basis="bspline" if domain != "gimp" else "mpm")
    ends = point.gather(v)
    np.testing.assert_allclose(D * V, ends[:200] - ends[200:], rtol=1e-12, atol=1e-12)


def test_the_domain_rate_cuts_a_domain_at_the_grid_ends():
    grid = uniform_grid(0.0, 1.0, 0.1)
    v = np.linspace(0.0, 1.0, grid.n_nodes) ** 2
    D = domain_rate(grid, np.array([0.01, 0.99]), np.array([0.04, 0.04]), v)
    expected = [np.interp(0.03, grid.nodes, v) - v[0], v[-1] - np.interp(0.97, grid.nodes, v)]
    np.testing.assert_allclose(D * 0.04, expected)


def test_the_stage_switch_and_numpy_only():
    assert numpy_only(IdealGas(), Stages()) is None
    assert "numpy step only" in numpy_only(IdealGas(density_update="exp"), Stages())
    assert "numpy step only" in numpy_only(IdealGas(), Stages(volume_rate="domain"))
    with pytest.raises(ValueError, match="volume_rate"):
        Stages(volume_rate="corners")
    with pytest.raises(ValueError, match="MPM stages only"):
        Stages(volume_rate="domain", projection="exact")


def _sod_run(kernel: str, form: str = "linear", rate: str = "point", h=0.01, T=0.02, volume="carried"):
    settings = sod.SodSettings(h=h, ppc=4, cfl=0.1, T=T, kernel=kernel, volume=volume)
    grid = uniform_grid(0.0, 1.0, h)
    problem = solve.Problem(IdealGas(density_update=form), Walls(), settings.T, settings.cfl)
    stages = dataclasses.replace(settings.stages, volume_rate=rate)
    return solve.run(problem, grid, sod.initial_particles(settings, grid), stages, progress=False, kernel=kernel)


@pytest.mark.parametrize("form, rate", [("exp", "point"), ("inverse", "domain")])
def test_the_options_fall_back_to_the_numpy_step(form, rate):
    """``kernel="fused"`` with an option of :func:`numpy_only` takes the numpy step's steps, bit for bit."""
    a, b = _sod_run("fused", form, rate), _sod_run("numpy", form, rate)
    assert a.steps == b.steps
    for name in ("x", "velocity", "density", "energy", "volume"):
        assert np.array_equal(getattr(a.particles, name), getattr(b.particles, name)), name


@pytest.mark.parametrize("form, rate", [("inverse", "point"), ("exp", "point"), ("linear", "domain"),
                                        ("inverse", "domain")])
def test_the_options_do_not_change_the_motion(form, rate):
    """The particle density does not feed back into the motion (:mod:`mpm_fem.core.models.euler`)."""
    plain, other = _sod_run("numpy"), _sod_run("numpy", form, rate)
    for name in ("x", "velocity", "energy"):
        np.testing.assert_allclose(getattr(other.particles, name), getattr(plain.particles, name), rtol=1e-10,
                                   atol=1e-12)
    assert not np.array_equal(other.particles.density, plain.particles.density)


def test_the_domain_volume_update_tracks_the_grid():
    """``V + dt int dv/dx``: the particle volumes keep filling the tube (interior domains telescope)."""
    plain, tracked = _sod_run("numpy", T=0.1), _sod_run("numpy", "inverse", "domain", T=0.1)
    assert abs(tracked.particles.volume.sum() - 1.0) < 0.1 * abs(plain.particles.volume.sum() - 1.0)


def test_the_model_must_take_a_volume_rate():
    from mpm_fem.core.models.burgers import ViscousBurgers

    grid = uniform_grid(0.0, 1.0, 0.1)
    P = make_particles(np.linspace(0.05, 0.95, 10), 0.1, 1.0, 0.1)
    with pytest.raises(ValueError, match="takes a volume rate"):
        explicit_step(grid, P, ViscousBurgers(0.1), Walls(), 0.0, 0.001, Stages(volume_rate="domain"))


# ----------------------------------------------------------------------------- the study's plan and table

def _keys(plan: dict) -> set:
    return {repr(sorted(c.items())) for c in plan.values()}


def test_the_plan_per_tier_and_the_kernels():
    quick, full, deep = (drift._plan(t)["drift"] for t in ("quick", "full", "deep"))
    assert len({tuple(sorted(c)) for c in (*full.values(), *deep.values())}) == 1  # every case has the same keys
    assert _keys(full) < _keys(deep)
    regular = {t: {(h, n) for h, n, layout, _ in plan if layout == "regular"} for t, plan in
               (("quick", quick), ("full", full), ("deep", deep))}
    assert regular["full"] == {(h, n) for h in drift.H for n in drift.VARIANTS if n not in drift.DEEP_VARIANTS}
    assert regular["deep"] == {(h, n) for h in drift.H + drift.DEEP_H for n in drift.VARIANTS}
    assert len(drift.H) >= 4 and len(drift.VARIANTS) - len(drift.DEEP_VARIANTS) >= 4
    assert len({h for h, _ in regular["quick"]}) >= 2
    jittered = {(h, n, s) for h, n, layout, s in full if layout == "jittered"}
    assert jittered == {(h, n, s) for h in drift.SEED_H for n in drift.SEEDED for s in drift.SEEDS}
    assert len(drift.SEEDS) >= 5 and drift.STUDY in drift.SEEDED
    for (_, name, layout, seed), c in full.items():
        numpy = "density_update" in drift.VARIANTS[name] or "volume_rate" in drift.VARIANTS[name]
        assert c["kernel"] == ("numpy" if numpy else "fused"), name
        assert (c["layout"], c["seed"]) == (layout, seed)
        assert {k: c[k] for k in drift.MPM if k not in drift.VARIANTS[name] and k not in ("layout", "seed")} == {
            k: v for k, v in drift.MPM.items() if k not in drift.VARIANTS[name] and k not in ("layout", "seed")}


def test_the_settings_recorded_are_the_tiers():
    for tier in ("quick", "full", "deep"):
        c, plan = drift._config(tier), drift._plan(tier)["drift"]
        assert {(h, n) for h, n, layout, _ in plan if layout == "regular"} == {
            (h, n) for h in c["h"] for n in c["variants"]}
        j = c["jittered"]
        assert {k for k in plan if k[2] == "jittered"} == {
            (h, n, "jittered", s) for h in j["h"] for n in j["variants"] for s in j["seeds"]}


def _got(hs=(0.01, 0.005), seeds=(1, 2)) -> dict:
    rng = np.random.default_rng(0)
    got = {(h, n, "regular", 0): {"ok": True, "particles_L1": float(rng.uniform(1e-3, 1e-2)), "nodes_L1": 1e-3,
                                  "volume_drift": float(rng.normal()) * 1e-3, "steps": 10}
           for h in hs for n in drift.VARIANTS}
    got.update({(h, drift.STUDY, "jittered", s): {"ok": True, "particles_L1": 2e-3 * s, "nodes_L1": 1e-3,
                                                  "volume_drift": 1e-3, "steps": 10} for h in hs for s in seeds})
    return got


def test_the_table_has_the_declared_columns():
    got = _got()
    got[(0.005, "8 ppc", "regular", 0)] = {"ok": False, "error": "positivity lost"}
    rows = drift.table(got)
    DRIFT.check(rows)
    study = [r for r in rows if r["variant"] == STUDY and r["layout"] == "regular"]
    assert study[0]["h"] == 0.01 and study[1]["order_particles_L1"] == pytest.approx(
        np.log(study[0]["particles_L1"] / study[1]["particles_L1"]) / np.log(2.0))
    assert all(r["particles_vs_study"] == pytest.approx(1.0) for r in rows if r["variant"] == STUDY)
    assert [r for r in rows if not r["ok"]][0]["error"] == "positivity lost"
    assert [(r["layout"], r["seed"]) for r in rows if r["variant"] == STUDY] == [
        ("regular", 0)] * 2 + [("jittered", 1)] * 2 + [("jittered", 2)] * 2


def test_the_figure_and_its_caption(tmp_path):
    drift.figure(tmp_path, drift.table(_got()))
    assert (tmp_path / "drift.png").stat().st_size > 0
    assert drift.CAPTION in (tmp_path / "figures.json").read_text()


# ----------------------------------------------------------------------------- the mechanism's sentence

H = ("0.0025", "0.00125", "0.000625")
#: (particles_L1 per mesh, nodes_L1 per mesh, volume drift per mesh) on the regular layout, as measured.
MEASURED = {
    STUDY: ((0.0040668, 0.00347826, 0.00440926), (0.00240801, 0.00135568, 0.00114814), (0.0025, 0.0039, 0.0067)),
    "rho/(1+dt L)": ((0.004029, 0.00345, 0.00437), (0.00240801, 0.00135568, 0.00114814), (0.0018, 0.0030, 0.0060)),
    "V + dt int dv/dx": ((0.0039345, 0.00291, 0.0026764), (0.00240801, 0.00135568, 0.00114814), (-8e-6, -6e-6, -3e-6)),
    "CFL 0.025": ((0.0039, 0.00289, 0.0031), (0.0024, 0.00128, 0.0011), (0.0012, 0.0019, 0.0033)),
    "8 ppc": ((0.0073, 0.0113, 0.018), (0.0036, 0.0036, 0.0035), (0.011, 0.021, 0.04)),
}
#: Jittered seeds: per variant, per seed, (particles_L1 at h = 0.00125, at 0.000625), as measured.
JITTERED = {
    STUDY: {1: (0.01737, 0.02300), 2: (0.0170, 0.0233), 3: (0.0172, 0.0228), 4: (0.0171, 0.0227), 5: (0.0173, 0.0232)},
    "grid volume": {1: (0.02276, 0.0271), 2: (0.0225, 0.0268), 3: (0.0224, 0.0260), 4: (0.0226, 0.0266),
                    5: (0.0227, 0.0266)},
}


def _row(h, n, p, q, d, layout="regular", seed=0) -> dict:
    return {"h": h, "variant": n, "layout": layout, "seed": str(seed), "particles_L1": repr(float(p)),
            "nodes_L1": repr(float(q)), "volume_drift": repr(float(d))}


def _tables(measured=MEASURED, jittered=None) -> dict:
    rows = [_row(h, n, p[k], q[k], d[k]) for n, (p, q, d) in measured.items() for k, h in enumerate(H)]
    rows += [_row(h, n, e[k], 0.004, 0.01, "jittered", s) for n, seeds in (jittered or {}).items()
             for s, e in seeds.items() for k, h in enumerate(H[1:])]
    return {DRIFT.name: rows}


def _with(name, jittered=None, **columns) -> dict:
    """MEASURED with ``name``'s columns replaced (``particles=(...)``, ``drift=(...)``)."""
    p, q, d = MEASURED[name]
    return _tables({**MEASURED, name: (columns.get("particles", p), q, columns.get("drift", d))}, jittered)


def _section(text: str, name: str) -> str:
    """Which list of the regular layout's sentence names the variant ``name``."""
    at = text.index(f"{name} (")
    found = {label: text.rfind(f"{label} by" if label != "reduced" else f"{label} (", 0, at)
             for label in ("removed", "reduced", "not reduced")}
    return max(found, key=found.get)


def _order(e_coarse, e_fine) -> float:
    return float(np.log(e_coarse / e_fine) / np.log(2.0))


def test_the_sentence_names_what_removes_reduces_and_leaves_the_growth():
    text = mechanism(_tables())
    assert text.startswith(f"On the regular layout, with the {STUDY} the particle density L1 error grows over the "
                           f"finest meshes (order {_order(0.00347826, 0.00440926):.2f} from h = {H[1]} to {H[2]}, "
                           "one layout, no spread over seeds in the table")
    assert [_section(text, n) for n in ("V + dt int dv/dx", "CFL 0.025", "rho/(1+dt L)", "8 ppc")] == [
        "removed", "reduced", "not reduced", "not reduced"]
    assert "The volume drift separates them" in text and "jittered" not in text
    assert "within 0.1% on every mesh with rho/(1+dt L), V + dt int dv/dx:" in text  # not CFL 0.025, not 8 ppc


def test_the_thresholds_are_the_stated_ones():
    assert GROWTH_ORDER == 0.0 and REDUCED == 0.5


def test_no_growth_when_the_study_settings_error_falls():
    text = mechanism(_with(STUDY, particles=(0.0040668, 0.00347826, 0.0030)))
    assert f"with the {STUDY} the particle density L1 error does not grow" in text and "no growth to remove" in text
    assert "removed by" not in text


def test_a_variant_that_grows_again_is_no_longer_a_remedy():
    text = mechanism(_with("V + dt int dv/dx", particles=(0.0039345, 0.00291, 0.0045)))
    assert "removed by" not in text and "No variant removes the growth." in text
    assert _section(text, "V + dt int dv/dx") == "not reduced"


def test_the_drift_statement_follows_the_drift():
    text = mechanism(_with("V + dt int dv/dx", drift=(0.01, 0.02, 0.05)))
    assert "The volume drift does not separate them" in text


def test_a_reduction_needs_at_most_the_stated_share_of_the_rate():
    order = _order(0.00347826, 0.00440926)
    for share, reduced in ((1.5 * REDUCED, False), (0.5 * REDUCED, True)):
        fine = 0.00289 * 2.0 ** (-share * order)  # the order share x the study's: still growing
        text = mechanism(_with("CFL 0.025", particles=(0.0039, 0.00289, fine)))
        assert _section(text, "CFL 0.025") == ("reduced" if reduced else "not reduced"), text


def test_the_spread_over_seeds_sets_what_one_layout_resolves():
    """A regular order of -0.03 is growth without seeds, and within the spread of the seeds' orders with them."""
    flat = (0.0039345, 0.00291, 0.00291 * 2.0 ** 0.03)
    alone = mechanism(_with("V + dt int dv/dx", particles=flat))
    seeded = mechanism(_with("V + dt int dv/dx", JITTERED, particles=flat))
    assert _section(alone, "V + dt int dv/dx") == "reduced" and _section(seeded, "V + dt int dv/dx") == "removed"
    band = max(max(o) - min(o) for o in ([_order(*e) for e in seeds.values()] for seeds in JITTERED.values()))
    assert f"a growth counts below {-band:.2f}, the spread of an order over the jittered seeds" in seeded


def test_the_jittered_clause_counts_an_order_only_when_every_seed_agrees():
    text = mechanism(_tables(jittered=JITTERED))
    lo, hi = (f(_order(*e) for e in JITTERED[STUDY].values()) for f in (min, max))
    assert f"On 5 jittered layouts, orders from h = {float(H[1]):g} to {float(H[2]):g}: {STUDY} {lo:.2f}..{hi:.2f} " \
           "(grows on every seed" in text
    assert "grid volume" in text and text.endswith("not the motion.")
    assert "no seeded variant removes or reduces it." in text  # grid volume grows faster than half the study's
    halved = {s: (e[0], e[0] * 2.0 ** (-0.4 * REDUCED * _order(*JITTERED[STUDY][s]))) for s, e in
              JITTERED["grid volume"].items()}
    assert "reduced on every seed" in mechanism(_tables(jittered={**JITTERED, "grid volume": halved}))
    flat = {s: (e[0], e[0] * 0.99) for s, e in JITTERED["grid volume"].items()}
    assert "removed on every seed by: grid volume" in mechanism(_tables(jittered={**JITTERED, "grid volume": flat}))
    assert ("There the growth outlasts the drift: grid volume grows on every seed at |drift| at most 0.01, below "
            f"the {STUDY}' least 0.01") not in text  # the same drift in the fixture: nothing to say
    low = _tables(jittered=JITTERED)
    for r in low[DRIFT.name]:
        if r["variant"] == "grid volume" and r["layout"] == "jittered":
            r["volume_drift"] = "1e-06"
    assert ("There the growth outlasts the drift: grid volume grows on every seed at |drift| at most 1e-06, below "
            f"the {STUDY}' least 0.01.") in mechanism(low)
    falling = {s: (e[0], e[0] * 0.8) for s, e in JITTERED[STUDY].items()}
    text = mechanism(_tables(jittered={**JITTERED, STUDY: falling}))
    assert f"{STUDY} {_order(1.0, 0.8):.2f} (grows on no seed" in text and "): no growth to remove." in text
    mixed = {**JITTERED[STUDY], 5: (0.0173, 0.0150)}
    assert "growth is not resolved over seeds" in mechanism(_tables(jittered={**JITTERED, STUDY: mixed}))


def test_not_measured_without_the_study_settings():
    assert mechanism({}).startswith("not measured")
    assert mechanism({DRIFT.name: [r for r in _tables()[DRIFT.name] if r["variant"] != STUDY]}).startswith(
        "not measured")
