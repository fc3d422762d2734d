"""The consistent mass: the particle mass matrix, solved.

    M_P = S^T diag(m_p) S,   (M_P)_ij = sum_p m_p S_ip S_jp,     M_P v = P,   M_P a = f

This is the grid basis's mass matrix ``int rho S_i S_j dx`` over the current body integrated by the
particle quadrature (the particles' masses as weights, their positions as points): the "full mass
matrix" of MPM (Sulsky et al.; the matrix FMPM(k) approximates in Nairn & Hammerquist, CMAME 377
(2021) 113667, and Nairn, arXiv 2604.07307 (2026)), as the 1D ``consistent`` mass
(:mod:`mpm_fem.core.transfer`). It carries no mass where the body is not, and its columns sum to the
lumped masses (``sum_i S_ip = 1``), so it conserves momentum exactly. It changes every step with the
particles: the step factorises it once per step on the nodes with mass (scipy's sparse LU, SuperLU:
scipy has no sparse Cholesky) and solves the momentum and the force with that factor. A cell with
too few particles makes it singular (1 x 1 particles per cell with the point-mass basis): refused
with a ``FloatingPointError`` naming the remedy. The grid basis's own matrix, integrated exactly
over the grid, is :mod:`mpm_fem.masses.grid`.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse.linalg import splu

from mpm_fem.masses.contract import GridMass, MassSystem, Solve, particle_matrix


def factorised(matrix, m_i: np.ndarray, what: str) -> Solve:
    """``rhs -> matrix^-1 rhs`` on the nodes with ``m_i > 0`` (sparse LU, once); 0 elsewhere."""
    active = np.flatnonzero(m_i > 0)
    M = matrix.tocsc()[active][:, active].tocsc()
    try:
        lu = splu(M)
    except RuntimeError as error:
        raise FloatingPointError(f"the {what} is singular (too few particles in some cells); use the lumped "
                                 "mass or more particles per cell") from error

    def solve(rhs):
        out = np.zeros_like(rhs)
        out[active] = lu.solve(np.ascontiguousarray(rhs[active]))
        if not np.all(np.isfinite(out)):
            raise FloatingPointError(f"the {what} is singular; use the lumped mass")
        return out

    return solve


class Consistent(GridMass):
    name = "consistent"
    title = "the particle mass matrix sum_p m_p S_ip S_jp, solved (sparse LU each step)"
    stage = "consistent"

    def solver(self, system: MassSystem) -> Solve:
        return factorised(particle_matrix(system), system.m_i, "consistent particle mass matrix")


CONSISTENT = Consistent()
