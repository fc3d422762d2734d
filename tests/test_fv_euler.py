"""The finite-volume reference (MUSCL-Hancock + HLLC) on Sod's tube."""

import numpy as np
import pytest

from baselines.exact import riemann
from baselines.fv_euler import hllc_flux, solve

SOD = ((1.0, 0.0, 1.0), (0.125, 0.0, 0.1))


def l1(result):
    rho, _, _ = riemann.sample(result.centres, result.t, *SOD)
    return float(np.mean(np.abs(result.rho - rho)))


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
