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


def test_the_blend_is_found_through_its_entry_point_and_is_flip_at_0_99():
    from mpm_fem.core.transfers import plugins
    from mpm_fem.problems import burgers

    assert plugins.resolve("flip99") == "flip99"
    settings = dict(h=0.04, T=0.2)
    ours = burgers.simulate(burgers.BurgersSettings(transfer="flip99", **settings), progress=False)
    package = burgers.simulate(burgers.BurgersSettings(flip=0.99, kernel="numpy", **settings), progress=False)
    flip = burgers.simulate(burgers.BurgersSettings(kernel="numpy", **settings), progress=False)
    assert ours.kernel == "numpy" and ours.steps == package.steps > 20
    assert np.abs(ours.particles.velocity - package.particles.velocity).max() <= 1e-12  # the package's blend at 0.99
    assert np.abs(ours.particles.velocity - flip.particles.velocity).max() > 1e-4  # and not FLIP (7.9e-4 apart)
