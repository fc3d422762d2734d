"""The compiled time loop of the Burgers FEM baseline (:mod:`baselines.fem_burgers`), numba.

:func:`steps` takes a block of the SSP-RK3 steps of :func:`baselines.fem_burgers.solve` in one
compiled call, with the numpy step's operations in the same order (why compiled:
``docs/performance.md``):

    R_i      = sum over the cells with a = i of  -(v_b - v_a)(2 v_a + v_b)/6 + eps (v_b - v_a)/h_e
             + sum over the cells with b = i of  -(v_b - v_a)(v_a + 2 v_b)/6 - eps (v_b - v_a)/h_e
               (the two sums kept apart and added last, as ``np.bincount(a, .) + np.bincount(b, .)``)
    lumped   dv_I/dt = R_I / m_I                                    bit for bit with numpy
    consistent  M_II dv_I/dt = R_I - M_IB g'(t), by the Thomas algorithm on the tridiagonal ``M_II``
             (:func:`tridiagonal_factors`, once per run), where numpy uses SuperLU: equal to round-off
    SSP-RK3  v1 = BC(v + dt L(v)),  v2 = BC(3/4 v + 1/4 (v1 + dt L(v1))),
             v  = BC(v/3 + 2/3 (v2 + dt L(v2))),   BC: the Dirichlet values at the stage's time.

It stops at the first step whose ``v`` is not finite and says which (``ArithmeticError`` is raised
by the caller, with the numpy step's message).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.sparse as sp
from numba import njit


class Cells(NamedTuple):
    """The mesh as the loop reads it: cell e joins nodes ``a[e]`` and ``b[e]`` and has length
    ``h[e]`` (n_cells,); ``interior`` and ``boundary`` the node indices (the Dirichlet nodes last)."""

    a: np.ndarray
    b: np.ndarray
    h: np.ndarray
    interior: np.ndarray
    boundary: np.ndarray


class Mass(NamedTuple):
    """The mass the stage solves with: ``lumped`` (n_nodes,) where not ``consistent``; else the
    factors ``l, w, u`` of :func:`tridiagonal_factors` and ``M_IB`` (n_interior, n_boundary)."""

    lumped: np.ndarray
    consistent: bool
    l: np.ndarray
    w: np.ndarray
    u: np.ndarray
    M_IB: np.ndarray


def tridiagonal_factors(M_II: sp.spmatrix) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(l, w, u)``: the LU factors of a tridiagonal ``M_II`` without pivoting (it is symmetric
    positive definite and diagonally dominant), ``w_0 = d_0``, ``l_i = M_{i,i-1} / w_{i-1}``,
    ``w_i = d_i - l_i M_{i-1,i}``, ``u_i = M_{i,i+1}``; ``w`` is returned as ``1 / w`` (the back
    substitution multiplies). ValueError if ``M_II`` has an entry off the three diagonals (a mesh
    that is not a line of cells in node order)."""
    M = sp.csr_matrix(M_II)
    n = M.shape[0]
    d, lower, upper = M.diagonal(0), M.diagonal(-1), M.diagonal(1)
    band = sp.diags([lower, d, upper], [-1, 0, 1], shape=M.shape) if n > 1 else sp.diags([d], [0], shape=M.shape)
    if abs(M - band).sum() != 0.0:
        raise ValueError("the compiled FEM step needs a tridiagonal interior mass matrix (nodes in mesh order)")
    l, w = _factor(np.asarray(d, dtype=float), np.asarray(lower, dtype=float), np.asarray(upper, dtype=float))
    return l, 1.0 / w, np.append(np.asarray(upper, dtype=float), 0.0)


@njit(cache=True)
def _factor(d, lower, upper):
    """The recursion of :func:`tridiagonal_factors`: ``l_i = lower_{i-1} / w_{i-1}``,
    ``w_i = d_i - l_i upper_{i-1}``."""
    w, l = d.copy(), np.zeros(d.size)
    for i in range(1, d.size):
        l[i] = lower[i - 1] / w[i - 1]
        w[i] = d[i] - l[i] * upper[i - 1]
    return l, w


@njit(cache=True)
def _derivative(v, k, g_t, cells, eps, mass, R1, R2, out):
    """``dv/dt`` into ``out`` at the stage time ``k dt / 2`` (the module docstring's ``L``; ``R1``,
    ``R2`` (n_nodes,) scratch)."""
    a, b, h, interior, boundary = cells
    lumped, consistent, l, w, u, M_IB = mass
    R1[:] = 0.0
    R2[:] = 0.0
    for e in range(a.size):
        va, vb = v[a[e]], v[b[e]]
        jump = vb - va
        diffusive = eps * jump / h[e]
        R1[a[e]] += -jump * (2.0 * va + vb) / 6.0 + diffusive
        R2[b[e]] += -jump * (va + 2.0 * vb) / 6.0 - diffusive
    for j in range(boundary.size):
        out[boundary[j]] = g_t[k, j]
    n = interior.size
    if not consistent:
        for r in range(n):
            i = interior[r]
            out[i] = (R1[i] + R2[i]) / lumped[i]
        return
    y = np.empty(n)
    for r in range(n):  # the right-hand side R_I - M_IB g', then the forward sweep
        i = interior[r]
        s = 0.0
        for j in range(boundary.size):
            s += M_IB[r, j] * g_t[k, j]
        y[r] = (R1[i] + R2[i]) - s
        if r > 0:
            y[r] -= l[r] * y[r - 1]
    for r in range(n - 1, -1, -1):  # the back substitution
        if r < n - 1:
            y[r] = (y[r] - u[r] * y[r + 1]) * w[r]
        else:
            y[r] = y[r] * w[r]
        out[interior[r]] = y[r]


@njit(cache=True)
def steps(v, first, count, dt, g, g_t, cells, eps, mass):
    """Steps ``first ... first + count - 1`` of SSP-RK3 on ``v`` (in place; ``g``, ``g_t``: the
    Dirichlet data and its time derivative at the half steps, (2 n_steps + 1, n_boundary); ``cells``
    a :class:`Cells`, ``mass`` a :class:`Mass`). Returns ``(-1, -1)``, or the step (counted from 1)
    and the first node at which ``v`` stopped being finite."""
    n_nodes = v.size
    boundary = cells.boundary
    R1, R2 = np.empty(n_nodes), np.empty(n_nodes)
    L, v1, v2 = np.empty(n_nodes), np.empty(n_nodes), np.empty(n_nodes)
    args = (cells, eps, mass, R1, R2)
    for n in range(first, first + count):
        k = 2 * n
        _derivative(v, k, g_t, *args, L)
        for i in range(n_nodes):
            v1[i] = v[i] + dt * L[i]
        for j in range(boundary.size):
            v1[boundary[j]] = g[k + 2, j]
        _derivative(v1, k + 2, g_t, *args, L)
        for i in range(n_nodes):
            v2[i] = 0.75 * v[i] + 0.25 * (v1[i] + dt * L[i])
        for j in range(boundary.size):
            v2[boundary[j]] = g[k + 1, j]
        _derivative(v2, k + 1, g_t, *args, L)
        for i in range(n_nodes):
            v[i] = v[i] / 3.0 + 2.0 / 3.0 * (v2[i] + dt * L[i])
        for j in range(boundary.size):
            v[boundary[j]] = g[k + 2, j]
        for i in range(n_nodes):
            if not np.isfinite(v[i]):
                return n + 1, i
    return -1, -1
