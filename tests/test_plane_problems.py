"""The 2D set-ups (mpm_fem/plane/problems.py, run.py): n x n particles per cell filling the domain's
area, the jittered layout inside its sub-cells and repeatable by seed, the vortex's particles in the
annulus only, and the start of the symplectic Euler step at v(X, -dt/2)."""

from __future__ import annotations

import numpy as np
import pytest

from mpm_fem.plane.grid import plane_grid
from mpm_fem.plane.problems import seed_reference, start
from mpm_fem.plane.run import PlaneSettings, setup

solids = pytest.importorskip("baselines.exact.solids")


@pytest.mark.parametrize("ppc", [1, 2, 3])
def test_regular_particles_fill_every_cell_with_their_sub_cell_volumes(ppc):
    grid = plane_grid((0.0, 0.0), (2.0, 2.0), 0.25, (True, True))
    X, V0, lengths = seed_reference(grid, ppc)
    assert X.shape == (64 * ppc**2, 2) and abs(V0.sum() - 4.0) < 1e-12
    counts = np.bincount((X[:, 0] // 0.25).astype(int) * 8 + (X[:, 1] // 0.25).astype(int), minlength=64)
    assert np.all(counts == ppc**2), counts
    assert np.allclose(lengths, 0.25 / ppc)


def test_jittered_particles_stay_in_their_sub_cells_and_repeat_by_seed():
    grid = plane_grid((0.0, 0.0), (2.0, 2.0), 0.25, (True, True))
    regular, _, _ = seed_reference(grid, 2)
    a, b, c = (seed_reference(grid, 2, "jittered", seed)[0] for seed in (7, 7, 8))
    assert np.array_equal(a, b) and not np.array_equal(a, c)
    offset = np.abs(a - regular).max()
    assert 0.05 < offset <= 0.0625, f"jitter moved a particle by {offset:.4g} (sub-cell half-width 0.0625)"


def test_vortex_particles_lie_in_the_annulus_and_fill_its_area():
    solution, grid, (X, V0, _), T = setup(PlaneSettings(problem="vortex", h=1 / 32))
    R = np.hypot(X[:, 0], X[:, 1])
    assert R.min() >= 0.75 and R.max() <= 1.25 and T == 1.0
    area = np.pi * (1.25**2 - 0.75**2)
    assert abs(V0.sum() - area) < 0.01 * area, f"particle volume {V0.sum():.4f}, annulus area {area:.4f}"
    assert grid.periodic == (False, False) and grid.axes[0].lo == -1.5


def test_the_start_takes_the_velocity_half_a_step_before():
    solution = solids.AxisAligned()
    grid = plane_grid((0.0, 0.0), (2.0, 2.0), 0.25, (True, True))
    X, V0, lengths = seed_reference(grid, 2)
    dt = 1e-4
    state = start(solution, X, V0, lengths, dt)
    assert np.array_equal(state.v, solution.velocity(X[:, 0], X[:, 1], -dt / 2).T)
    u = solution.displacement(X[:, 0], X[:, 1], 0.0).T
    assert np.abs(state.displacement - u).max() < 1e-15  # x - X: the round-off of X
    J = np.linalg.det(state.F)
    assert np.allclose(state.volume, J * V0) and np.array_equal(state.mass, V0 * solution.material.rho0)
