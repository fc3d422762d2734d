"""Pass 1: the particles projected onto the grid.

For each particle, its row ``S_ip``, ``G_ip`` at ``x_p^n`` (the basis's compiled kernels,
:class:`mpm_fem.bases.contract.Kernels`), then

    m_i = sum_p m_p S_ip,    P_i = sum_p m_p v_p S_ip,    F_i = sum_p V_p p_p G_ip  (the gas force, if asked),

each node's terms added in particle index order, a particle's nodes left to right, as the numpy
step's scatters (:mod:`mpm_fem.core.transfer`), so the sums are its floats. The cells are stored
for the grid stage, the rows too where pass 2 reads them back (the particle-domain bases, the
consistent mass). The basis's own particle loop (``PROJECT_RUN``: node sums of consecutive
particles kept in registers, or rows built from scalars) serves the grids it is written for
(``ANY_GRID``, else a grid uniform to round-off); the generic loop of :func:`_project` over the
basis's row (``SHAPE_ROW``) serves the rest. ``WIDTH``, ``STORED`` (whether the basis's rows are
stored), ``ANY_GRID``, ``PROJECT_RUN`` and ``SHAPE_ROW`` are compile-time globals of each variant
(:mod:`mpm_fem.fused.compiler`).
"""

import numpy as np
from numba import prange

from mpm_fem.fused.sums import _chunk, _one_row, _sum_chunks

# placeholders: each variant has its own (mpm_fem.fused.compiler)
WIDTH = STORED = ANY_GRID = PROJECT_RUN = SHAPE_ROW = None


def _project(geometry, cloud, gas_force, store, chunks, stored, m_i, P_i, F_i, flags):
    """Pass 1: the shape of every particle (``geometry``, ``cloud``, ``stored``: the grid, the
    particles and the row store of :mod:`mpm_fem.bases.contract`), ``m_i``, ``P_i`` and, if
    ``gas_force``, ``F_i = sum_p V_p p_p G_ip``. The cells are stored; the rows ``rows``, ``S``,
    ``G`` only if ``store`` (the consistent mass and the particle-domain bases need them).
    ``flags[k] = (first particle outside the grid, first with V <= 0, the K it needs)`` of chunk k."""
    nodes, h, inv_spacing = geometry
    x, V, m, v, p = cloud
    rows, S, G, cell = stored
    n = x.size
    K = WIDTH  # nodes per particle
    n_nodes = nodes.size
    a, b = nodes[0], nodes[n_nodes - 1]
    buf = np.zeros((chunks, 3, n_nodes))
    for k in prange(chunks):
        lo, hi = _chunk(n, chunks, k)
        outside, empty, need = -1, -1, 0
        r, Sl, Gl = _one_row(K)
        if ANY_GRID == 1 or inv_spacing > 0.0:  # the basis's own loop (the loop below then skipped)
            outside, empty, need = PROJECT_RUN(geometry, cloud, gas_force, store, lo, hi, stored, buf[k])
            lo = hi
        for q in range(lo, hi):
            if not (x[q] >= a and x[q] <= b):
                if outside < 0:
                    outside = q
                continue
            if STORED == 1 and not (V[q] > 0):
                if empty < 0:
                    empty = q
                continue
            c, kq = SHAPE_ROW(nodes, h, inv_spacing, x[q], V[q], r, Sl, Gl)
            cell[q] = c
            need = max(need, kq)
            if store:
                for j in range(K):
                    rows[q, j], S[q, j], G[q, j] = r[j], Sl[j], Gl[j]
            mv = m[q] * v[q]
            Vp = V[q] * p[q]
            for j in range(K):
                i = r[j]
                buf[k, 0, i] += Sl[j] * m[q]
                buf[k, 1, i] += Sl[j] * mv
                if gas_force:
                    buf[k, 2, i] += Gl[j] * Vp
        flags[k, 0], flags[k, 1], flags[k, 2] = outside, empty, need
    for j, out in enumerate((m_i, P_i, F_i)):
        _sum_chunks(buf, j, out, 1.0)

