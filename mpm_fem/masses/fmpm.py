"""FMPM(k): the approximate full mass matrix inverse of Nairn & Hammerquist (CMAME 377 (2021)
113667), in the revised form of Nairn (arXiv 2604.07307, 2026, and OSParticulas' FMPM loop).

The particle mass matrix ``M = M_P`` (:mod:`mpm_fem.masses.consistent`) is ``M_L (I - R)`` with
``R = I - M_L^-1 M``; its inverse is the series ``sum_j R^j M_L^-1``, truncated at order ``k``:

    A_k rhs = sum_{j=0}^{k-1} (I - M_L^-1 M)^j M_L^-1 rhs                                   (1)

computed as ``y_0 = M_L^-1 rhs``, ``y_j = y_{j-1} - M_L^-1 (M y_{j-1})``, ``A_k rhs = y_0 + ... +
y_{k-1}``; each term is one "extrapolation" (``M y = S^T (m_p (S y))``: a gather to the particles
and a scatter back, matrix free), so FMPM(k) costs ``k - 1`` of them per right-hand side.
``A_1 = M_L^-1`` is the lumped mass, and ``A_k -> M^-1`` as ``k -> infinity`` wherever the series
converges (the eigenvalues of ``M_L^-1 M`` lie in (0, 1] for a non-singular ``M``, so those of ``R``
in [0, 1): the error falls as ``rho(R)^k``, ``rho(R) = 1 - lambda_min(M_L^-1 M)``). Each ``A_k``
conserves momentum exactly: ``m^T R = m^T - 1^T M = 0`` (the columns of ``M`` sum to the lumped
masses ``m``), so ``m^T A_k rhs = sum_i rhs_i``.

How it enters the step (:mod:`mpm_fem.plane.step`): ``A_k`` replaces ``M^-1`` in both nodal solves,
``v_i = A_k P``, ``a_i = A_k f``, so the updated grid velocity is ``v_i^+ = v_i + dt a_i = A_k (P +
dt f) = A_k p^+``, Nairn's grid velocity ``v^+(k)`` from the updated grid momentum ``p^+``. Nairn's
FMPM(k) then sets the particle velocity to ``v_p = sum_i S_ip v_i^+(k)`` (no FLIP increment): that
is this mass with the PIC end of the blend, ``flip = 0``; the positions move with ``sum_i S_ip
v_i^+`` and the velocity gradient takes ``v_i^+`` (USL). With ``flip = 1`` the same inverse serves a
FLIP update (``v_p + dt sum_i S_ip a_i``). Both ends conserve momentum. The stable step shrinks
as ``k`` grows, from the lumped one toward the consistent one (P1, 2 x 2 regular: 1, 0.756, 0.658,
0.605 ``c / c_p`` for k = 1..4 against 0.441; :func:`mpm_fem.plane.stability.linearised_cfl`).
"""

from __future__ import annotations

import numpy as np

from mpm_fem.masses.contract import GridMass, MassSystem, Solve, lumped_solve, particle_product

ORDERS = (1, 2, 3, 4)  # the orders registered (fmpm1 .. fmpm4)


def series(system: MassSystem, order: int) -> Solve:
    """``rhs -> A_k rhs`` of (1), ``k = order``, on right-hand sides (n_nodes, d)."""
    lumped = lumped_solve(system.m_i)
    product = particle_product(system) if order > 1 else None

    def solve(rhs):
        y = lumped(rhs)
        out = y.copy()
        for _ in range(order - 1):
            y = y - lumped(product(y))
            out += y
        return out

    return solve


def constrained_series(system: MassSystem, order: int, fixed: np.ndarray):
    """``(rhs, values) -> u``: (1) with the nodal values ``u[fixed] = values`` prescribed, as the Richardson
    iteration that sums the series, ``u_0 = M_L^-1 rhs``, ``u_j = u_{j-1} + M_L^-1 (rhs - M u_{j-1})``, with the
    prescribed values imposed on every iterate (so ``u_{k-1} = A_k rhs`` where nothing is prescribed). Order 1 is
    the lumped solve with the values imposed after it; as ``k`` grows ``u`` tends to the constrained solve
    ``M_FF u_F = rhs_F - M_F,fixed values`` on the free nodes ``F``, wherever the series converges (the lumped
    masses of the free nodes bound the row sums of ``M_FF``)."""
    lumped = lumped_solve(system.m_i)
    product = particle_product(system) if order > 1 else None

    def solve(rhs, values):
        u = lumped(rhs)
        u[fixed] = values
        for _ in range(order - 1):
            u = u + lumped(rhs - product(u))
            u[fixed] = values
        return u

    return solve


class FMPM(GridMass):
    """FMPM(k) of order ``k >= 1`` (module docstring)."""

    stage = "consistent"

    def __init__(self, order: int):
        if isinstance(order, bool) or not isinstance(order, int) or order < 1:
            raise ValueError(f"the FMPM order must be an integer >= 1, got {order!r}")
        self.order = order
        self.name = f"fmpm{order}"
        self.title = (f"FMPM({order}): the particle mass matrix's inverse by {order} terms of its series "
                      "(Nairn & Hammerquist 2021)")

    def solver(self, system: MassSystem) -> Solve:
        return series(system, self.order)

    def constrained_solver(self, system: MassSystem, fixed: np.ndarray):
        return constrained_series(system, self.order, fixed)
