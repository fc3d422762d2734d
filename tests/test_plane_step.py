"""The 2D numpy step (mpm_fem/plane/step.py): mass and momentum conserved on the periodic square
without body force, an inverted particle refused with the step and the particle named, bad settings
refused before any work, and the displacement's second order on the axis-aligned solution (slow)."""

from __future__ import annotations

import numpy as np
import pytest

from mpm_fem.bases import names
from mpm_fem.core.step import Stages
from mpm_fem.plane import PlaneSettings, axis
from mpm_fem.plane.grid import plane_grid
from mpm_fem.plane.model import InversionError
from mpm_fem.plane.problems import seed_reference
from mpm_fem.plane.state import PlaneParticles
from mpm_fem.plane.step import check_stages, step, step_with_grid

solids = pytest.importorskip("baselines.exact.solids")
MATERIAL = solids.Material(1e4, 0.3, 1.0)


def _particles(grid, ppc=2, seed=0, strain=1e-3, speed=1.0):
    """Jittered particles with random velocities and deformation gradients near I (stress not zero)."""
    X, V0, lengths = seed_reference(grid, ppc, "jittered", seed)
    rng = np.random.default_rng(seed + 1)
    n = X.shape[0]
    F = np.eye(2) + strain * rng.standard_normal((n, 2, 2))
    J = F[:, 0, 0] * F[:, 1, 1] - F[:, 0, 1] * F[:, 1, 0]
    return PlaneParticles(X=X, x=X.copy(), v=speed * rng.standard_normal((n, 2)), F=F, volume=J * V0, volume0=V0,
                          mass=MATERIAL.rho0 * V0 * (1 + 0.1 * rng.random(n)), lengths=lengths)


@pytest.mark.parametrize("mass", ["lumped", "consistent"])
@pytest.mark.parametrize("flip", [1.0, 0.0])
@pytest.mark.parametrize("basis", names())
def test_step_conserves_mass_and_momentum_on_the_periodic_square(basis, flip, mass):
    grid = plane_grid((0.0, 0.0), (2.0, 2.0), 0.25, (True, True))
    state = _particles(grid)
    dt = 0.2 * 0.25 / MATERIAL.c
    new, grid_state = step_with_grid(state, grid, basis, MATERIAL, dt, 0.0, None, Stages(mass=mass, flip=flip))
    before = state.mass @ state.v
    after = new.mass @ new.v
    scale = np.sum(state.mass[:, None] * np.abs(state.v))
    drift = np.abs(after - before).max() / scale
    assert drift < 1e-13, f"{basis}, flip {flip}, {mass}: total momentum drifts by {drift:.3g} of sum m|v|"
    mass_gap = abs(grid_state.mass.sum() - state.mass.sum()) / state.mass.sum()
    assert mass_gap < 1e-14, f"{basis}: sum m_i differs from sum m_p by {mass_gap:.3g}"
    assert np.array_equal(new.mass, state.mass)
    moved = np.abs(new.v - state.v).max()
    assert moved > 1e-3, f"the step changed the velocities by {moved:.3g} only: the stress did no work"


def test_an_inverted_particle_stops_the_step_naming_it():
    grid = plane_grid((0.0, 0.0), (2.0, 2.0), 0.25, (True, True))
    state = _particles(grid, strain=0.0, speed=0.0)
    # a converging velocity field: with dt |dv/dx| > 1 the particles near x = 1 turn inside out
    v = np.column_stack((-np.sin(np.pi * state.X[:, 0]) * 40.0, np.zeros(state.n)))
    with pytest.raises(InversionError, match=r"J = det F = .* <= 0 in particle \d+ at \(") as caught:
        step(state.replace(v=v), grid, "mpm", MATERIAL, 0.05, 0.0, None)
    assert caught.value.J <= 0
    named = caught.value.at(7, 0.35)
    assert "at step 7 (t=0.35) in particle" in str(named), str(named)


@pytest.mark.parametrize("bad, match", [
    (dict(h=0.3), "does not divide"), (dict(basis="hermite"), "unknown basis"), (dict(mass="diagonal"), "unknown mass"),
    (dict(cfl=1.5), "CFL"), (dict(ppc=0), "particles per cell"), (dict(layout="hex"), "layout"),
    (dict(flip=2.0), "blend"), (dict(refine=0), "refinement")])
def test_bad_settings_are_refused_before_any_work(bad, match):
    with pytest.raises(ValueError, match=match):
        axis(**bad)


def test_unknown_keywords_are_refused():
    with pytest.raises(TypeError, match="unknown settings hh"):
        axis(hh=0.1)
    with pytest.raises(ValueError, match="schemes usl, musl"):
        PlaneSettings(scheme="usf")
    with pytest.raises(ValueError, match="xpic=0"):
        check_stages(Stages(xpic=1, transfer="xpic"))


def test_one_coarse_run_states_its_cfl_and_errors():
    run = axis(h=0.25, ppc=2, cfl=0.3)
    assert run.steps == int(np.ceil(2 / (0.3 * 0.25))) and abs(run.t - 2 / MATERIAL.c) < 1e-15
    assert run.cfl <= 0.3 and run.cfl > 0.29, run.cfl
    e = run.errors["displacement"]["particles"]
    assert 0 < e["L2"] <= e["L2_max"] and e["L2"] <= e["Linf"], e
    assert e["L2"] < 1e-4 * 0.5, f"the displacement error {e['L2']:.3g} is not below half the amplitude"


def _orders(basis, hs):
    errors = [axis(h=h, ppc=2, amplitude=1e-4, basis=basis).errors["displacement"]["particles"]["L2"] for h in hs]
    return errors, np.log2(np.array(errors[:-1]) / np.array(errors[1:]))


@pytest.mark.slow
@pytest.mark.parametrize("basis", names())
def test_displacement_converges_at_second_order_on_the_axis_aligned_solution(basis):
    errors, orders = _orders(basis, (1 / 8, 1 / 16, 1 / 32))
    assert np.all((orders >= 1.8) & (orders <= 2.2)), f"{basis}: L2 {errors}, orders {orders}"
