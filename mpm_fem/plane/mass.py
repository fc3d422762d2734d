"""The grid basis's own mass matrix on the tensor grid (the fixed-mesh FE mass, density ``rho``):

    M_ij = rho int S_i S_j dx,     S_i = S^x_a S^y_b   =>   M = rho (M^x kron M^y),

with ``M^x``, ``M^y`` the 1D Gram matrices of the grid functions on each axis (periodic images
folded onto the axis nodes). For the P1 grid functions the same matrix is scikit-fem's Q1 mass,
``BilinearForm(u v)`` assembled on the ``MeshQuad`` (:func:`q1_mass`); the 1D Gram matrices of any
basis come from Gauss points per half cell (exact for the piecewise polynomials up to degree 3).
The step's ``consistent`` mass is the particle mass matrix ``sum_p m_p S_ip S_jp`` (as in 1D,
:mod:`mpm_fem.core.transfer`), which carries no mass where the body is not; this matrix, the
fixed-mesh reference beside it, is the step's ``grid`` mass (:mod:`mpm_fem.masses.grid`,
:func:`mpm_fem.plane.step.grid_basis_matrix`).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from skfem import Basis as SkBasis
from skfem import BilinearForm, ElementQuad1, asm

from mpm_fem.bases import get
from mpm_fem.bases.contract import Basis
from mpm_fem.plane.bases import tensor_basis
from mpm_fem.plane.grid import Axis, PlaneGrid

GAUSS = 4  # points per half cell of the 1D Gram matrices


@BilinearForm
def _mass(u, v, w):
    return u * v


def fold(grid: PlaneGrid) -> sp.csr_matrix:
    """The (mesh points x grid nodes) 0/1 matrix taking scikit-fem's points to the grid's nodes."""
    n = grid.mesh.p.shape[1]
    return sp.csr_matrix((np.ones(n), (np.arange(n), grid.mesh_nodes)), shape=(n, grid.n_nodes))


def q1_mass(grid: PlaneGrid, rho: float = 1.0) -> sp.csr_matrix:
    """``rho int S_i S_j`` of the Q1 functions (n_nodes x n_nodes), assembled by scikit-fem on the
    mesh and folded onto the grid's nodes (periodic ends identified)."""
    P = fold(grid)
    return (rho * (P.T @ asm(_mass, SkBasis(grid.mesh, ElementQuad1())) @ P)).tocsr()


def axis_gram(axis: Axis, basis: str | Basis) -> sp.csr_matrix:
    """``int_axis S_a S_b`` (axis nodes squared) of the grid functions of ``basis`` on ``axis``:
    Gauss points on each half cell of the domain, the rows of the 1D basis at them."""
    functions = get(tensor_basis(basis).grid_functions)
    g, w = np.polynomial.legendre.leggauss(GAUSS)
    edges = np.linspace(axis.lo, axis.hi, 2 * round(axis.length / axis.h) + 1)
    half = np.diff(edges)[:, None] / 2
    x = ((edges[:-1, None] + edges[1:, None]) / 2 + half * g).ravel()
    weights = (half * w).ravel()
    rows = functions.shape(axis.line, x, None)
    n_q, k = rows.nodes.shape
    S = sp.csr_matrix((rows.S.ravel(), (np.repeat(np.arange(n_q), k), axis.wrap[rows.nodes].ravel())),
                      shape=(n_q, axis.n_nodes))
    return (S.T @ sp.diags(weights) @ S).tocsr()


def grid_mass(grid: PlaneGrid, basis: str | Basis, rho: float = 1.0) -> sp.csr_matrix:
    """``rho (M^x kron M^y)`` (n_nodes x n_nodes; the node numbering ``i = a n_y + b``)."""
    return (rho * sp.kron(axis_gram(grid.axes[0], basis), axis_gram(grid.axes[1], basis))).tocsr()
