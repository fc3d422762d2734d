"""Particle-to-grid projection and grid-to-particle interpolation.

Slides, "MPM Basis Overview" and "Mass/Momentum/Force Projection Error":

    nodal mass        m_i = sum_p m_p S_ip
    nodal momentum    P_i = sum_p m_p v_p S_ip          v_i = P_i / m_i   (lumped)
    internal force    F_i = - sum_p V_p sigma_p G_ip    a_i = F_i / m_i   (lumped)

with the Cauchy stress ``sigma_p`` (gas: ``sigma = -p``, so ``F_i = sum_p V_p p_p G_ip``). With a
consistent mass the nodal values solve ``M v = P`` and ``M a = F`` instead, where ``M`` is the
particle mass matrix ``M_ij = sum_p m_p S_ip S_jp``; with FMPM(k) they are ``v = A_k P`` and
``a = A_k F``, ``A_k`` the k-term series of ``M^-1`` (:mod:`mpm_fem.masses.fmpm`, read from the
grid-mass registry). Interpolation back to the particles:

    v_p = sum_i S_ip v_i,     (dv/dx)_p = sum_i G_ip v_i.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.linalg import solve_banded
from scipy.sparse.linalg import spsolve

from mpm_fem.core.shape import Shape
from mpm_fem.masses import ORDERS, MassSystem
from mpm_fem.masses import get as get_mass

#: the registered FMPM(k) masses the 1D step takes (:mod:`mpm_fem.masses.fmpm`)
FMPM_KINDS = tuple(f"fmpm{k}" for k in ORDERS)
MASS_KINDS = ("lumped", "consistent") + FMPM_KINDS
#: the masses that are not diagonal (FMPM(1) is the lumped mass): their stable step is the
#: consistent mass's or larger (the series' eigenvalues lie between the two; masses.fmpm)
COUPLED_KINDS = ("consistent",) + FMPM_KINDS[1:]


def nodal_mass(shape: Shape, mass: np.ndarray) -> np.ndarray:
    """``m_i = sum_p m_p S_ip``."""
    return shape.scatter(mass)


def nodal_momentum(shape: Shape, mass: np.ndarray, velocity: np.ndarray) -> np.ndarray:
    """``P_i = sum_p m_p v_p S_ip``."""
    return shape.scatter(mass * velocity)


def nodal_internal_force(shape: Shape, volume: np.ndarray, stress: np.ndarray) -> np.ndarray:
    """``F_i = - sum_p V_p sigma_p G_ip``."""
    return -shape.scatter_gradient(volume * stress)


def particle_mass_matrix(shape: Shape, mass: np.ndarray) -> sp.csr_matrix:
    """Consistent particle mass matrix ``M_ij = sum_p m_p S_ip S_jp`` (n_nodes x n_nodes)."""
    S = shape.matrix()
    return (S.T @ sp.diags(mass) @ S).tocsr()


def divide_by_lumped(rhs: np.ndarray, m: np.ndarray) -> np.ndarray:
    """``rhs_i / m_i`` where the node carries mass, 0 where it carries none."""
    out = np.zeros_like(rhs)
    np.divide(rhs, m, out=out, where=m > 0)
    return out


def _tridiagonal_mass(shape: Shape, mass: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Diagonal ``M_ii`` (n_nodes,) and super-diagonal ``M_{i,i+1}`` (n_nodes - 1,) of the particle
    mass matrix when every particle touches two neighbouring nodes ``(c, c + 1)`` (P1 point mass):
    the same sums as :func:`particle_mass_matrix`, by bincount instead of sparse products."""
    c, n = shape.nodes[:, 0], shape.n_nodes
    S0, S1 = shape.S[:, 0], shape.S[:, 1]
    diag = np.bincount(c, mass * S0 * S0, n) + np.bincount(c + 1, mass * S1 * S1, n)
    return diag, np.bincount(c, mass * S0 * S1, n)[: n - 1]


Fixed = tuple  # (nodes (k,) int, values (k,)): nodal values a boundary prescribes


def _coupling(shape: Shape, mass: np.ndarray, fixed: Fixed | None, tridiagonal: bool, n: int):
    """``(M u_E, is_fixed)``: the particle mass matrix times the vector holding the prescribed values at their
    nodes (0 elsewhere), and the mask of those nodes; ``(0, none)`` without ``fixed``."""
    is_fixed = np.zeros(n, dtype=bool)
    if fixed is None:
        return 0.0, is_fixed
    nodes, values = fixed
    is_fixed[nodes] = True
    u = np.zeros(n)
    u[nodes] = values
    if not tridiagonal:
        return particle_mass_matrix(shape, mass) @ u, is_fixed
    diag, upper = _tridiagonal_mass(shape, mass)
    Mu = diag * u
    Mu[:-1] += upper * u[1:]
    Mu[1:] += upper * u[:-1]
    return Mu, is_fixed


def solve_consistent(shape: Shape, mass: np.ndarray, rhs: np.ndarray, fixed: Fixed | None = None) -> np.ndarray:
    """Solve ``M u = rhs`` with the particle mass matrix; nodes with no mass get 0. With ``fixed`` (nodes,
    values) those nodes take the prescribed values and the free rows ``F`` solve ``M_FF u_F = rhs_F - M_FE
    u_E``: the wall or Dirichlet condition imposed on the system, not on its solution.

    For P1 the matrix is tridiagonal and is solved banded; otherwise by sparse LU.
    """
    out = np.zeros_like(rhs)
    tridiagonal = shape.nodes.shape[1] == 2 and np.array_equal(shape.nodes[:, 1], shape.nodes[:, 0] + 1)
    coupling, is_fixed = _coupling(shape, mass, fixed, tridiagonal, out.size)
    rhs = rhs - coupling if fixed is not None else rhs
    try:
        if tridiagonal:
            diag, upper = _tridiagonal_mass(shape, mass)
            active = np.flatnonzero((diag > 0) & ~is_fixed)
            ab = np.zeros((3, active.size))
            ab[1] = diag[active]
            # neighbours across a node without mass (or a prescribed one) are not coupled
            ab[0, 1:] = np.where(np.diff(active) == 1, upper[active[:-1]], 0.0)
            ab[2, :-1] = ab[0, 1:]
            out[active] = solve_banded((1, 1), ab, rhs[active])
        else:
            M = particle_mass_matrix(shape, mass)
            active = (np.asarray(M.diagonal()) > 0) & ~is_fixed
            out[active] = spsolve(M[active][:, active].tocsc(), rhs[active])
        singular = not np.all(np.isfinite(out))
    except np.linalg.LinAlgError:
        singular = True
    if singular:
        raise FloatingPointError(
            "the consistent particle mass matrix is singular (too few particles in some cells); "
            "use the lumped mass or more particles per cell"
        )
    if fixed is not None:
        out[fixed[0]] = fixed[1]
    return out


def registered_values(shape: Shape, mass: np.ndarray, m_i: np.ndarray, rhs: np.ndarray, kind,
                      fixed: Fixed | None = None) -> np.ndarray:
    """``rhs -> A rhs`` (n_nodes,) with the registered grid mass ``kind``'s solver
    (:class:`mpm_fem.masses.GridMass`, or an instance) on the particles' rows: ``MassSystem(S, m_p, m_i)``;
    with ``fixed`` (nodes, values) its :meth:`~mpm_fem.masses.GridMass.constrained_solver`."""
    grid_mass, system = get_mass(kind), MassSystem(shape.matrix(), mass, m_i)
    if fixed is None:
        return grid_mass.solver(system)(rhs[:, None])[:, 0]
    nodes, values = fixed
    return grid_mass.constrained_solver(system, nodes)(rhs[:, None], np.asarray(values, dtype=float)[:, None])[:, 0]


def grid_values(shape: Shape, mass: np.ndarray, m_i: np.ndarray, rhs: np.ndarray, kind: str,
                fixed: Fixed | None = None) -> np.ndarray:
    """Nodal values from a projected right-hand side: ``rhs/m_i`` (lumped), ``M^{-1} rhs``
    (consistent) or ``A_k rhs`` (FMPM(k), :func:`registered_values`). ``fixed`` (nodes, values): the
    values a boundary prescribes, imposed on the coupled masses' systems (the lumped mass has no coupling:
    the caller imposes them after the division, as without ``fixed``)."""
    if kind == "lumped":
        return divide_by_lumped(rhs, m_i)
    if kind == "consistent":
        return solve_consistent(shape, mass, rhs, fixed)
    if kind in FMPM_KINDS:
        return registered_values(shape, mass, m_i, rhs, kind, fixed)
    raise ValueError(f"unknown mass kind {kind!r}; choose one of {', '.join(MASS_KINDS)}")


def interpolate(shape: Shape, f: np.ndarray) -> np.ndarray:
    """``f_p = sum_i S_ip f_i``."""
    return shape.gather(f)


def gradient(shape: Shape, f: np.ndarray) -> np.ndarray:
    """``(df/dx)_p = sum_i G_ip f_i``."""
    return shape.gather_gradient(f)
