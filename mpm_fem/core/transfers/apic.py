"""APIC, the affine particle-in-cell transfer (Jiang, Schroeder, Selle, Teran & Stomakhin, SIGGRAPH 2015), in 1D.

Each particle carries an affine velocity coefficient ``C_p`` (a scalar in 1D,
:attr:`mpm_fem.core.particles.Particles.affine`; ``None`` is read as 0, the initial value: the
particles start without an affine part, whatever the initial velocity's gradient).

    P2G:  m_i v_i = sum_p m_p S_ip (v_p + C_p (x_i - x_p))
    G2P:  v_p = sum_i S_ip v_i^{n+1},   C_p = sum_i G_ip v_i^{n+1}
    move: x_p += dt v_p                  (the PIC move with the new grid velocity)

The G2P ``C_p`` is the gradient form (Jiang et al. 2015, sec. 5.3: ``B_p D_p^{-1}`` replaced by
``sum_i v_i (grad S_ip)^T``), exact for any basis that reproduces linears: an affine nodal field
``v_i = a + b x_i`` gives ``v_p = a + b x_p`` and ``C_p = b``; and P2G of ``v_p = a + b x_p``,
``C_p = b`` gives ``v_i = a + b x_i`` for any basis, since ``v_p + C_p (x_i - x_p) = a + b x_i``
(lumped mass). Momentum: ``sum_i S_ip (x_i - x_p) = 0`` for a linear-reproducing basis, so
``sum_i P_i = sum_p m_p v_p`` (``tests/test_apic.py`` checks both on P1 and the quadratic B-spline
away from the walls).

The compiled step takes APIC's two kernels (:class:`~mpm_fem.core.transfers.contract.AffineKernels`:
:func:`affine_momentum`, :func:`affine_coefficient`, the numpy forms' operations in their order) and
moves the particles with PIC's velocity; ``tests/test_apic.py`` checks a run equal to the numpy step's
bit for bit on one thread, each scheme.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from mpm_fem.core.transfers.contract import AffineKernels, Transfer


@njit(cache=True)
def affine_momentum(nodes, rows, S, x, m, C, P):
    """``P_i += sum_p S_ip (x_i - x_p) m_p C_p`` in place (:meth:`Apic.momentum`'s ``np.bincount`` of
    ``(S_ip (x_i - x_p)) (m_p C_p)``, accumulated in particle order from zero, then added)."""
    extra = np.zeros(P.size)
    for q in range(x.size):
        w = m[q] * C[q]
        for j in range(rows.shape[1]):
            i = rows[q, j]
            extra[i] += S[q, j] * (nodes[i] - x[q]) * w
    for i in range(P.size):
        P[i] += extra[i]


@njit(cache=True)
def affine_coefficient(rows, G, v, C):
    """``C_p = sum_i G_ip v_i`` into ``C`` (``Shape.gather_gradient``'s order, a row left to right)."""
    for q in range(C.size):
        s = G[q, 0] * v[rows[q, 0]]
        for j in range(1, rows.shape[1]):
            s += G[q, j] * v[rows[q, j]]
        C[q] = s


class Apic(Transfer):
    name = "apic"
    title = "affine particle-in-cell (Jiang et al. 2015)"
    affine = True
    kernels = AffineKernels(affine_momentum, affine_coefficient)

    def momentum(self, shape, nodes, x, mass, velocity, affine):
        P = shape.scatter(mass * velocity)
        if affine is None:
            return P
        offset = nodes[shape.nodes] - x[:, None]
        return P + np.bincount(shape.nodes.ravel(), (shape.S * offset * (mass * affine)[:, None]).ravel(),
                               shape.n_nodes)

    def update(self, grid, velocity, setting):
        return grid.moving, grid.shape.gather_gradient(grid.v_new)
