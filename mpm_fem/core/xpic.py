"""XPIC(m): the extended PIC particle update of order ``m`` (Hammerquist & Nairn, CMAME 318, 2017).

Notation: ``S`` the (n_p x n_nodes) interpolation matrix ``S_pi = S_ip``; ``S+ = M^{-1} S^T M_p`` the
mass-weighted projection of particle values to the grid (``M`` the step's grid mass, lumped
``diag(m_i)`` or the particle mass matrix; ``M_p = diag(m_p)``); ``v_i = S+ v_p`` the grid velocity
of the step and ``a_i`` its acceleration, both with the boundary rule. The particle updates are

    FLIP:     v_p^{n+1} = v_p^n + dt S a
    PIC:      v_p^{n+1} = S (v_i + dt a)
    XPIC(m):  v_p^{n+1} = S (v* + dt a),     S v* = [I - (I - S S+)^m] v_p^n.

``A = S S+`` maps the particle velocities to their grid image; ``I - A`` keeps what the grid does
not see, including the null-space noise that FLIP carries forever. ``I - (I - A)^m`` is the
``m``-term expansion ``sum_{k<m} (I - A)^k A`` of the identity on the range of ``A``: ``m = 1`` is
PIC (``v* = v_i``); as ``m`` grows ``S v*`` tends to ``v_p^n`` without its null-space part (the
``M_p``-orthogonal projection onto the range of ``S``), so XPIC(m) tends to FLIP with that noise
filtered. Since ``(I - A)^k A = S (I - B)^k S+`` with ``B = S+ S`` (n_nodes x n_nodes), the sum is a
grid sum of ``m`` terms,

    v* = sum_{k=0}^{m-1} [P (I - B)]^k v_i,     B u = S+ (S u)   (interpolate, then project back),

where ``P`` is the boundary rule applied to a velocity change (zero where the boundary prescribes
the velocity: walls, Dirichlet data). It equals the alternating binomial form of the same
expansion, ``v* = sum_{k=1}^{m} (-1)^{k+1} C(m, k) w_k`` with ``w_1 = v_i`` and ``w_{k+1}`` the
boundary rule applied to ``B w_k`` (prescribed values kept on the boundary), but adds no large
terms of alternating sign. Mass is untouched; with ``sum_i S_ip = 1`` every term ``B u`` has the
grid momentum of ``u`` (``sum_i m_i (B u)_i = sum_p m_p (S u)_p = sum_i m_i u_i``), so without a
boundary rule the particle momentum is that of PIC and FLIP. With the consistent mass ``B = I``
and XPIC(m) is PIC for every ``m``.

Cost: ``m - 1`` extra interpolations and projections per step (one loop over ``k``, vectorised).
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from mpm_fem.core.shape import Shape
from mpm_fem.core.transfer import grid_values, nodal_momentum


def check_order(order) -> None:
    """``order`` is ``0`` (XPIC off) or an integer ``m >= 1``; a clear ``ValueError`` otherwise."""
    if isinstance(order, bool) or not isinstance(order, (int, np.integer)) or order < 0:
        raise ValueError(f"the XPIC order must be an integer >= 1 (0: off), got {order!r}")


def xpic_grid_velocity(shape: Shape, mass: np.ndarray, m_i: np.ndarray, v_i: np.ndarray, order: int,
                       kind: str = "lumped", homogeneous: Callable[[np.ndarray], np.ndarray] | None = None,
                       ) -> np.ndarray:
    """``v* = sum_{k=0}^{m-1} [P (I - B)]^k v_i`` (module docstring), ``m = order >= 1``.

    ``mass``: ``m_p``; ``m_i``: the nodal masses; ``kind``: the grid mass (``"lumped"`` or
    ``"consistent"``) of ``S+``; ``homogeneous``: ``P``, the boundary rule for a velocity change
    (``None``: no boundary rule)."""
    check_order(order)
    if order < 1:
        raise ValueError("XPIC needs an order m >= 1")
    P = homogeneous if homogeneous is not None else (lambda u: u)
    v_star, term = v_i.copy(), v_i
    for _ in range(order - 1):
        projected = grid_values(shape, mass, m_i, nodal_momentum(shape, mass, shape.gather(term)), kind)
        term = P(term - projected)
        v_star += term
    return v_star


def xpic_velocity(shape: Shape, mass: np.ndarray, m_i: np.ndarray, v_i: np.ndarray, a_i: np.ndarray, dt: float,
                  order: int, kind: str = "lumped", homogeneous: Callable[[np.ndarray], np.ndarray] | None = None,
                  ) -> np.ndarray:
    """The XPIC(m) particle velocity ``v_p^{n+1} = sum_i S_ip (v*_i + dt a_i)`` (n_p,)."""
    return shape.gather(xpic_grid_velocity(shape, mass, m_i, v_i, order, kind, homogeneous) + dt * a_i)


def boundary_change_rule(boundary, grid, t: float) -> Callable[[np.ndarray], np.ndarray]:
    """``P``: the boundary rule of the step (``boundary.velocity``, affine in ``u``) applied to a
    velocity change, ``P u = rule(u) - rule(0)``: zero where the boundary prescribes the velocity."""
    def P(u: np.ndarray) -> np.ndarray:
        return boundary.velocity(grid, u, t) - boundary.velocity(grid, np.zeros_like(u), t)
    return P
