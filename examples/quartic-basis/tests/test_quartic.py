"""The quartic basis measured by mpm-fem's pytest plugin (``--mpm-basis quartic`` in pyproject.toml)."""

import numpy as np


def test_it_projects_like_a_smooth_basis_on_the_regular_layout(mpm_method):
    orders = mpm_method.projection(layout="regular")
    assert orders["E_m"].lo > 3.5 and orders["E_a"].lo > 3  # beyond the P1 hats' 2.9 and 1.8


def test_on_jittered_particles_its_acceleration_error_does_not_converge(mpm_method):
    orders = mpm_method.projection(layout="jittered", seeds=(1, 2, 3))
    assert orders["E_m"].runs == 3 and 0.6 < orders["E_m"].lo  # mass: the jitter's first order
    assert orders["E_a"].hi < 0.2  # the study's C8 finding holds for this basis too


def test_burgers_converges_on_the_regular_and_a_jittered_layout(mpm_method):
    order = mpm_method.order("burgers", hs=(0.04, 0.02), seeds=(0, 1))  # particles L1 of the velocity
    assert order.runs == 2 and np.isfinite(order.mean) and order.lo > 0.8


def test_the_basis_is_found_through_its_entry_point(mpm_method_for):
    assert mpm_method_for("quartic").basis == "quartic"
