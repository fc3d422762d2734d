"""Every grid mass in the 2D run (slow: about 3 min on two quiet cores, the exact mass 90 s of it; 18 min
under a load average of 13): the axis-aligned solution at A = 1e-4 (every particle
in its cell), 2 x 2 particles per cell, CFL 0.25, the point-mass basis, h = 1/8, 1/16, 1/32: the particle
displacement L2 at T converges at order 2 (each mesh pair's order in [1.8, 2.2]); FMPM(k) approaches the
consistent mass's error as k grows (measured on 2026-12-02: FMPM(2) 8.6 %, FMPM(3) 0.24 %, FMPM(4)
0.007 % from it at h = 1/8), and FMPM(1) is the lumped mass to round-off."""

from __future__ import annotations

import math

import pytest

from mpm_fem.plane import axis

HS = (1 / 8, 1 / 16, 1 / 32)
MASSES = ("lumped", "consistent", "grid", "exact", "fmpm1", "fmpm2", "fmpm3", "fmpm4")


@pytest.fixture(scope="module")
def errors():
    return {m: [axis(h=h, ppc=2, mass=m).errors["displacement"]["particles"]["L2"] for h in HS] for m in MASSES}


@pytest.mark.slow
@pytest.mark.parametrize("mass", MASSES)
def test_every_mass_converges_at_second_order_on_the_small_amplitude(errors, mass):
    e = errors[mass]
    orders = [math.log2(e[i] / e[i + 1]) for i in range(len(e) - 1)]
    assert all(1.8 <= o <= 2.2 for o in orders), f"{mass}: orders {orders} (errors {e})"


@pytest.mark.slow
def test_fmpm_approaches_the_consistent_mass_as_its_order_grows(errors):
    gaps = [abs(errors[f"fmpm{k}"][0] / errors["consistent"][0] - 1) for k in (2, 3, 4)]
    assert gaps[0] > gaps[1] > gaps[2] and gaps[2] < 1e-3, f"FMPM(2..4) from the consistent mass: {gaps}"
    assert errors["fmpm1"] == errors["lumped"]
