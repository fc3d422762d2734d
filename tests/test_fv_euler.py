"""The finite-volume reference (MUSCL-Hancock + HLLC) on Sod's tube."""

import numpy as np
import pytest

from baselines.exact import riemann
from baselines.fv_euler import cell_centres, evolve, hllc_flux, label, solve

SOD = ((1.0, 0.0, 1.0), (0.125, 0.0, 0.1))


def l1(result):
    rho, _, _ = riemann.sample(result.centres, result.t, *SOD)
    return float(np.mean(np.abs(result.rho - rho)))


def entropy_wave_l1(h, limiter):
    """Density L1 after one period of ``rho = 1 + 0.2 sin(2 pi x)``, ``u = p = 1``, periodic: the
    exact solution is the initial cell averages."""
    x = cell_centres(h)
    rho = 1.0 + 0.2 * (np.cos(2 * np.pi * (x - h / 2)) - np.cos(2 * np.pi * (x + h / 2))) / (2 * np.pi * h)
    r = evolve(rho, 1.0, 1.0, h, T=1.0, limiter=limiter, boundary="periodic")
    return float(np.sum(np.abs(r.rho - rho)) * h)


def test_mass_and_energy_are_conserved_to_round_off():
    r = solve(0.01)
    assert r.rho.mean() == pytest.approx(0.5625, rel=1e-14)
    E = r.p / 0.4 + 0.5 * r.rho * r.u**2
    assert E.mean() == pytest.approx((2.5 + 0.25) / 2, rel=1e-13)


def test_density_error_converges_and_plateau_is_exact_to_half_percent():
    coarse, fine = solve(0.005), solve(0.0025)
    e1, e2 = l1(coarse), l1(fine)
    order = np.log2(e1 / e2)
    assert 0.6 < order < 1.2, f"L1 {e1:.3g} -> {e2:.3g}, order {order:.2f}"
    plateau = fine.rho[(fine.centres > 0.72) & (fine.centres < 0.82)].mean()
    assert plateau == pytest.approx(0.26557, rel=5e-3)


def test_hllc_flux_is_the_exact_flux_for_equal_states():
    s = (np.array([0.7]), np.array([0.3]), np.array([0.9]))
    F = hllc_flux(s, s, 1.4)
    E = 0.9 / 0.4 + 0.5 * 0.7 * 0.09
    np.testing.assert_allclose(F[:, 0], [0.21, 0.7 * 0.09 + 0.9, 0.3 * (E + 0.9)], rtol=1e-14)


def test_bad_cfl_is_refused():
    with pytest.raises(ValueError, match="CFL"):
        solve(0.01, cfl=1.5)


def test_the_name_says_which_limiter():
    assert solve(0.01, limiter="mc").name == label("mc") == "FV MUSCL-HLLC (MC)"
    assert solve(0.01).name == label() == "FV MUSCL-HLLC (minmod)"


@pytest.mark.parametrize("h", [0.005, 0.00125])
def test_mc_is_more_accurate_than_minmod_on_sod(h):
    # measured: minmod / MC = 1.44 (h = 0.005), 1.57 (h = 0.00125)
    ratio = l1(solve(h)) / l1(solve(h, limiter="mc"))
    assert 1.3 < ratio < 1.8, f"minmod / MC density L1 = {ratio:.3f}"


@pytest.mark.parametrize("limiter", ["minmod", "mc"])
def test_walls_conserve_mass_and_energy_and_momentum_gains_the_wall_impulse(limiter):
    r = solve(0.005, limiter=limiter)
    h = 0.005
    assert np.sum(r.rho) * h == pytest.approx(0.5625, rel=1e-14)
    assert np.sum(r.p / 0.4 + 0.5 * r.rho * r.u**2) * h == pytest.approx(1.375, rel=1e-14)
    # the waves have not reached the walls: their pressures 1 and 0.1 push for T = 0.2
    assert np.sum(r.rho * r.u) * h == pytest.approx((1.0 - 0.1) * 0.2, abs=1e-14)


def test_mc_periodic_conserves_mass_momentum_and_energy_to_round_off():
    h = 0.01
    x = cell_centres(h)
    rho, u, p = 1.0 + 0.5 * (x < 0.5), 0.3 + 0.2 * np.sin(2 * np.pi * x), 1.0 + 0.4 * (x > 0.3)
    r = evolve(rho, u, p, h, T=0.3, limiter="mc", boundary="periodic")
    before = [np.sum(q) * h for q in (rho, rho * u, p / 0.4 + 0.5 * rho * u**2)]
    after = [np.sum(q) * h for q in (r.rho, r.rho * r.u, r.p / 0.4 + 0.5 * r.rho * r.u**2)]
    np.testing.assert_allclose(after, before, rtol=1e-14, atol=1e-15)


@pytest.mark.parametrize("limiter", ["minmod", "mc"])
def test_no_new_extrema_on_sod_density_or_an_advected_step(limiter):
    r = solve(0.0025, limiter=limiter)
    assert r.rho.min() >= 0.125 - 1e-14 and r.rho.max() <= 1.0 + 1e-14
    h = 0.01
    x = cell_centres(h)
    step = np.where((x > 0.25) & (x < 0.5), 1.0, 0.5)
    moved = evolve(step, 1.0, 1.0, h, T=0.5, limiter=limiter, boundary="periodic")
    assert moved.rho.min() >= 0.5 - 1e-14 and moved.rho.max() <= 1.0 + 1e-14
    assert moved.rho.max() > 0.9  # the step is still there, not smeared flat


@pytest.mark.parametrize("limiter, band", [("mc", (1.9, 2.3)), ("minmod", (1.7, 2.1))])
def test_second_order_on_a_smooth_entropy_wave(limiter, band):
    # measured L1 orders 100 -> 200 cells: MC 2.18, minmod 1.87 (clipped extrema cost minmod more)
    order = np.log2(entropy_wave_l1(0.01, limiter) / entropy_wave_l1(0.005, limiter))
    assert band[0] < order < band[1], f"{limiter}: order {order:.3f}"


@pytest.mark.parametrize("kwargs, message", [
    (dict(limiter="superbee"), "limiter"),
    (dict(boundary="open"), "boundary"),
])
def test_bad_limiter_or_boundary_is_refused(kwargs, message):
    x = cell_centres(0.1)
    with pytest.raises(ValueError, match=message):
        evolve(np.ones_like(x), 0.0, 1.0, 0.1, 0.1, **kwargs)
    with pytest.raises(ValueError, match="one value per cell"):
        evolve(np.ones(3), 0.0, 1.0, 0.1, 0.1)
