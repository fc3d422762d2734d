"""The exact stages of the 2D step (mpm_fem/plane/exact.py): with the projection, mass and
interpolation exact the error left is the time step's, second order under dt -> dt/2, on both
problems; the reference position of a grid node solves x = X + u(X, t)."""

from __future__ import annotations

import numpy as np
import pytest

from mpm_fem.plane import axis, vortex
from mpm_fem.plane.exact import reference_of

solids = pytest.importorskip("baselines.exact.solids")
EXACT = dict(projection="exact", mass="exact", interpolation="exact")


@pytest.mark.parametrize("problem, settings", [(axis, dict(h=1 / 8)), (vortex, dict(h=1 / 8, amplitude=0.5))])
def test_with_every_stage_exact_the_error_is_the_time_steps_and_second_order(problem, settings):
    coarse, fine = (problem(ppc=2, refine=k, **EXACT, **settings) for k in (1, 2))
    e1, e2 = (r.errors["displacement"]["particles"]["L2_max"] for r in (coarse, fine))
    order = np.log2(e1 / e2)
    assert 1.8 <= order <= 2.2, f"{problem.__name__}: L2 max over time {e1:.3g} -> {e2:.3g}, order {order:.3f}"
    a = coarse.errors["acceleration"]["nodes"]["L2"]
    assert a < 1e-10, f"the nodal acceleration with the stages exact misses by {a:.3g}"


def test_exact_projection_shrinks_the_displacement_error_of_the_axis_problem():
    """The projection (mass, momentum, force integrals) is the P1 run's largest error at h = 1/8: exact, the
    largest L2 over the period drops from 9.2e-6 to 3.7e-6 (measured 2026-12-01)."""
    mpm, exact = (axis(h=1 / 8, ppc=2, projection=p) for p in ("mpm", "exact"))
    e_mpm, e_exact = (r.errors["displacement"]["particles"]["L2_max"] for r in (mpm, exact))
    assert e_exact < 0.5 * e_mpm, f"L2 max {e_mpm:.3g} (MPM projection) vs {e_exact:.3g} (exact)"


@pytest.mark.parametrize("solution, t", [(solids.AxisAligned(amplitude=0.1), 0.004),
                                         (solids.GeneralizedVortex(), 0.5)])
def test_reference_position_of_a_node_maps_back_onto_it(solution, t):
    rng = np.random.default_rng(0)
    x = rng.random((200, 2)) * 2 - (0.0 if isinstance(solution, solids.AxisAligned) else 1.0)
    X = reference_of(solution, x, t)
    back = X + solution.displacement(X[:, 0], X[:, 1], t).T
    assert np.abs(back - x).max() < 1e-12, f"X + u(X, t) misses x by {np.abs(back - x).max():.3g}"
