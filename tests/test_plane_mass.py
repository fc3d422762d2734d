"""The grid basis's mass matrix on the tensor grid (mpm_fem/plane/mass.py): scikit-fem's Q1 mass
folded onto the grid equals the kron of the 1D P1 Gram matrices, and every Gram matrix integrates
the constant: its entries sum to rho times the area."""

from __future__ import annotations

import numpy as np
import pytest

from mpm_fem.bases import names
from mpm_fem.plane.grid import plane_grid
from mpm_fem.plane.mass import grid_mass, q1_mass


@pytest.mark.parametrize("periodic", [(True, True), (False, False), (True, False)])
def test_skfem_q1_mass_is_the_kron_of_the_1d_p1_gram_matrices(periodic):
    grid = plane_grid((0.0, 0.0), (2.0, 2.0), 0.25, periodic)
    skfem, tensor = q1_mass(grid, rho=2.0), grid_mass(grid, "mpm", rho=2.0)
    gap = abs(skfem - tensor).max() / skfem.max()
    assert gap < 1e-14, f"Q1 mass (scikit-fem) and kron of 1D Gram matrices differ by {gap:.3g} relative"


@pytest.mark.parametrize("basis", names())
def test_every_gram_matrix_is_symmetric_and_integrates_the_constant(basis):
    grid = plane_grid((0.0, 0.0), (2.0, 2.0), 0.25, (True, True))
    M = grid_mass(grid, basis, rho=3.0)
    total = M.sum()
    assert abs(total - 12.0) < 1e-12, f"{basis}: sum of M_ij = {total!r}, rho x area = 12"
    assert abs(M - M.T).max() < 1e-15
    assert np.all(M.diagonal() > 0)
