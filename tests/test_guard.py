"""The guard's run-time estimate: the constants of the kernel that will take the steps."""

import pytest

from mpm_fem.problems import SECONDS_PER_PARTICLE_STEP, SECONDS_PER_STEP, Cost, burgers, sod


def test_the_estimate_uses_the_constants_of_the_kernel_that_runs():
    fused = sod.cost(sod.SodSettings(h=0.001, ppc=4))
    numpy = sod.cost(sod.SodSettings(h=0.001, ppc=4, kernel="numpy"))
    assert (fused.kernel, numpy.kernel) == ("fused", "numpy")
    assert fused.steps == numpy.steps == 5479 and fused.particles == 4000
    assert fused.seconds == pytest.approx(5479 * (1e-7 * 4000 + 3e-4))
    assert numpy.seconds == pytest.approx(5479 * (3e-7 * 4000 + 1e-3))
    assert fused.seconds < numpy.seconds / 2.5


@pytest.mark.parametrize("changes", [dict(projection="exact"), dict(mass="exact"), dict(reconstruct="taylor")])
def test_stages_the_fused_step_does_not_run_are_estimated_as_numpy(changes):
    assert sod.cost(sod.SodSettings(h=0.01, **changes)).kernel == "numpy"
    assert burgers.cost(burgers.BurgersSettings(h=0.01, **changes)).kernel == "numpy"


@pytest.mark.parametrize("changes", [dict(flip=0.5), dict(xpic=5), dict(basis="bspline_gimp"), dict(volume="grid")])
def test_remedies_the_fused_step_runs_are_estimated_as_fused(changes):
    assert sod.cost(sod.SodSettings(h=0.01, **changes)).kernel == "fused"


def test_a_cost_without_a_kernel_is_the_numpy_estimate():
    cost = Cost(particles=10_000, nodes=2_501, steps=2_000_000)
    assert cost.seconds == pytest.approx(2e6 * (SECONDS_PER_PARTICLE_STEP["numpy"] * 1e4 + SECONDS_PER_STEP["numpy"]))
