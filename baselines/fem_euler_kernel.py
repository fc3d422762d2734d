"""The compiled time loop of the Euler FEM baseline (:mod:`baselines.fem_euler`), numba.

:func:`steps` takes a block of the SSP-RK3 steps of :func:`baselines.fem_euler.solve` in one
compiled call, with the numpy step's floating-point operations in the same order (why compiled:
``docs/performance.md``). Per node ``u = (rho u)/rho``, ``p = (gamma - 1)(E - (0.5 rho u) u)``,
``F = (rho u, (rho u) u + p, (E + p) u)``, ``s = |u| + sqrt(gamma p / rho)``; per cell ``e = [a, b]``

    nu_e     = h_e (c_lin max(s_a, s_b) + c_quad max(0, -(u_b - u_a))),  0 where u_b >= u_a if
               compression only (:meth:`baselines.fem_euler.Viscosity.coefficient`)
    R_i      = sum over the cells with a = i of  -(F_b - F_a)/2 + (nu_e / h_e)(U_b - U_a)
             + sum over the cells with b = i of  -(F_b - F_a)/2 - (nu_e / h_e)(U_b - U_a)
               (the two sums kept apart and added last, as ``np.bincount(a, .) + np.bincount(b, .)``)
    walls    R_(rho u) = 0 at the two end nodes
    lumped   dU_i/dt = R_i / m_i                                         bit for bit with numpy
    consistent  M dU/dt = R for rho and E, M_wall d(rho u)/dt = R_(rho u) (the wall rows of M
             replaced by the identity), each by the Thomas algorithm on the tridiagonal matrix
             (:func:`baselines.fem_burgers_kernel.tridiagonal_factors`, once per run), where numpy
             uses SuperLU: equal to round-off only
    SSP-RK3  dt = min(cfl h_min / max_i s_i, T - t) while t < T (1 - 1e-14);
             U1 = U + dt L(U),  U2 = 3/4 U + 1/4 (U1 + dt L(U1)),  U <- U/3 + 2/3 (U2 + dt L(U2)).

After every stage density and pressure ``(gamma - 1)(E - 0.5 (rho u)^2 / rho)`` must be > 0 at
every node (NaN fails), as ``baselines.fem_euler._check_positive`` demands. At the first stage that
fails the loop stops, leaves ``U`` and ``t`` as they were before that step and the failed stage's
state in ``failed``, and says which step and stage: the caller raises ``PositivityError`` with the
numpy step's message.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit


class Cells(NamedTuple):
    """The P1 cells (end nodes ``a``, ``b``, sizes ``h``), the lumped mass ``m_i`` and, with
    ``consistent``, the Thomas factors ``(l, 1/w, u)`` of ``M`` (``free_*``) and of the wall-modified
    ``M`` (``wall_*``); empty arrays for the lumped mass."""

    a: np.ndarray
    b: np.ndarray
    h: np.ndarray
    lumped: np.ndarray
    consistent: bool
    free_l: np.ndarray
    free_w: np.ndarray
    free_u: np.ndarray
    wall_l: np.ndarray
    wall_w: np.ndarray
    wall_u: np.ndarray


class Gas(NamedTuple):
    """``gamma`` and the viscosity constants of :class:`baselines.fem_euler.Viscosity`."""

    gamma: float
    linear: float
    quadratic: float
    compression_only: bool


class Work(NamedTuple):
    """Scratch arrays: nodal ``u``, ``p``, ``speed`` (n,), flux ``F``, the two cell sums ``Ra``,
    ``Rb`` and the stage states ``U1``, ``U2``, ``D`` (= ``dU/dt``), all (3, n)."""

    u: np.ndarray
    p: np.ndarray
    speed: np.ndarray
    F: np.ndarray
    Ra: np.ndarray
    Rb: np.ndarray
    U1: np.ndarray
    U2: np.ndarray
    D: np.ndarray


def work(n: int) -> Work:
    """Scratch arrays for ``n`` nodes."""
    return Work(np.empty(n), np.empty(n), np.empty(n), *(np.empty((3, n)) for _ in range(6)))


@njit(cache=True)
def _residual(U, cells, gas, work):
    """``R = Ra + Rb`` of the module docstring, left in ``work.Ra``."""
    u, p, speed, F, Ra, Rb = work.u, work.p, work.speed, work.F, work.Ra, work.Rb
    g1 = gas.gamma - 1.0
    for i in range(U.shape[1]):
        rho, mom, E = U[0, i], U[1, i], U[2, i]
        u[i] = mom / rho
        p[i] = g1 * (E - 0.5 * mom * u[i])
        F[0, i] = mom
        F[1, i] = mom * u[i] + p[i]
        F[2, i] = (E + p[i]) * u[i]
        speed[i] = np.abs(u[i]) + np.sqrt(gas.gamma * p[i] / rho)
    Ra[:] = 0.0
    Rb[:] = 0.0
    a, b, h = cells.a, cells.b, cells.h
    for e in range(a.size):
        ia, ib = a[e], b[e]
        s = speed[ia] if speed[ia] >= speed[ib] else speed[ib]
        du = u[ib] - u[ia]
        q = -du
        nu = h[e] * (gas.linear * s + gas.quadratic * (q if q > 0.0 else 0.0))
        if gas.compression_only and not du < 0:
            nu = 0.0
        nu_h = nu / h[e]
        for k in range(3):
            half_dF = 0.5 * (F[k, ib] - F[k, ia])
            diffusive = nu_h * (U[k, ib] - U[k, ia])
            Ra[k, ia] += -half_dF + diffusive
            Rb[k, ib] += -half_dF - diffusive
    for k in range(3):
        for i in range(U.shape[1]):
            Ra[k, i] = Ra[k, i] + Rb[k, i]


@njit(cache=True)
def _thomas(l, w, up, rhs, out):
    """``out = A^{-1} rhs`` for the tridiagonal ``A`` with the factors ``(l, 1/w, u)``."""
    n = rhs.size
    out[0] = rhs[0]
    for r in range(1, n):
        out[r] = rhs[r] - l[r] * out[r - 1]
    out[n - 1] = out[n - 1] * w[n - 1]
    for r in range(n - 2, -1, -1):
        out[r] = (out[r] - up[r] * out[r + 1]) * w[r]


@njit(cache=True)
def _derivative(U, cells, gas, work, out):
    """``dU/dt`` into ``out``: ``M^{-1} R(U)`` with ``d(rho u)/dt = 0`` at the end nodes."""
    _residual(U, cells, gas, work)
    R = work.Ra
    n = U.shape[1]
    R[1, 0] = 0.0
    R[1, n - 1] = 0.0
    if not cells.consistent:
        for k in range(3):
            for i in range(n):
                out[k, i] = R[k, i] / cells.lumped[i]
        return
    _thomas(cells.free_l, cells.free_w, cells.free_u, R[0], out[0])
    _thomas(cells.wall_l, cells.wall_w, cells.wall_u, R[1], out[1])
    _thomas(cells.free_l, cells.free_w, cells.free_u, R[2], out[2])


@njit(cache=True)
def _positive(U, gamma):
    """True if density and ``(gamma - 1)(E - 0.5 (rho u)^2 / rho)`` are > 0 at every node."""
    for i in range(U.shape[1]):
        rho = U[0, i]
        p = (gamma - 1.0) * (U[2, i] - 0.5 * (U[1, i] * U[1, i]) / rho)
        if not (rho > 0 and p > 0):
            return False
    return True


@njit(cache=True)
def _max_speed(U, gamma):
    """``max_i (|u_i| + c_i)`` with ``u``, ``p`` as in ``baselines.fem_euler.primitives``."""
    top = -np.inf
    for i in range(U.shape[1]):
        rho, mom, E = U[0, i], U[1, i], U[2, i]
        u = mom / rho
        p = (gamma - 1.0) * (E - 0.5 * mom * u)
        s = np.abs(u) + np.sqrt(gamma * p / rho)
        if s > top:
            top = s
    return top


@njit(cache=True)
def _stage(stage, U, V, D, dt, out):
    """SSP-RK3 (Shu-Osher) stage ``stage`` into ``out``, with the numpy loop's operations: ``U + dt D``,
    ``3/4 U + 1/4 (V + dt D)``, ``U / 3 + 2/3 (V + dt D)`` (``V`` the previous stage, ``D = L(V)``)."""
    for k in range(3):
        for i in range(U.shape[1]):
            if stage == 1:
                out[k, i] = U[k, i] + dt * D[k, i]
            elif stage == 2:
                out[k, i] = 0.75 * U[k, i] + 0.25 * (V[k, i] + dt * D[k, i])
            else:
                out[k, i] = U[k, i] / 3.0 + 2.0 / 3.0 * (V[k, i] + dt * D[k, i])


@njit(cache=True)
def steps(U, t, first, count, T, cfl, h_min, cells, gas, work, failed):
    """Steps ``first + 1 ... first + count`` of SSP-RK3 on ``U`` (3, n, in place) from time ``t``,
    fewer if ``t`` reaches ``T``. Returns ``(t, steps taken in all, 0)``, or at the first loss of
    positivity ``(t before that step, that step, its RK stage 1-3)`` with ``U`` left as it was
    before the step and the stage's state in ``failed``."""
    U1, U2, D = work.U1, work.U2, work.D
    end = T * (1 - 1e-14)
    for step in range(first + 1, first + count + 1):
        if not t < end:
            return t, step - 1, 0
        dt = cfl * h_min / _max_speed(U, gas.gamma)
        if T - t < dt:
            dt = T - t
        for stage, source, out in ((1, U, U1), (2, U1, U2), (3, U2, U1)):
            _derivative(source, cells, gas, work, D)
            _stage(stage, U, source, D, dt, out)
            if not _positive(out, gas.gamma):
                failed[:] = out
                return t, step, stage
        U[:] = U1
        t += dt
    return t, first + count, 0
