"""Pass 1: the particles projected onto the grid.

For each particle, its row ``S_ip``, ``G_ip`` at ``x_p^n`` (:mod:`mpm_fem.fused.basis`), then

    m_i = sum_p m_p S_ip,    P_i = sum_p m_p v_p S_ip,    F_i = sum_p V_p p_p G_ip  (the gas force, if asked),

each node's terms added in particle index order, a particle's nodes left to right, as the numpy
step's scatters (:mod:`mpm_fem.core.transfer`), so the sums are its floats. The cells are stored
for the grid stage, the rows too where pass 2 reads them back (the particle-domain bases, the
consistent mass). Each basis on a uniform grid has its own particle loop (:func:`_project_point`,
:func:`_project_bspline`, :func:`_project_domain`) that keeps the node sums of consecutive particles
in registers or builds the row from scalars; the generic loop of :func:`_project` serves the rest.
``BASIS`` and ``WIDTH`` are compile-time globals of each variant (:mod:`mpm_fem.fused.compiler`).
"""

import numpy as np
from numba import njit, prange

from mpm_fem.fused.basis import (
    _bspline_domain_five,
    _bspline_nearest,
    _domain,
    _domain_column,
    _domain_shape_row,
    _point,
    _point_row,
    _scaled,
)
from mpm_fem.fused.codes import BSPLINE, BSPLINE_GIMP, GIMP, POINT
from mpm_fem.fused.sums import _chunk, _one_row, _sum_chunks

BASIS = WIDTH = None  # placeholders: each variant has its own (mpm_fem.fused.compiler)


@njit(cache=True, inline="always")
def _project_point(nodes, h, inv_spacing, x, V, m, v, p, gas_force, store, lo, hi, rows, S, G, cell, buf):
    """Pass 1 of the point mass over particles ``lo .. hi-1``: ``buf[0..2]`` += ``m_p S_ip``,
    ``m_p v_p S_ip``, ``V_p p_p G_ip`` (the last if ``gas_force``). Each node's terms are added in
    particle order, as in :func:`_project` (the same numbers), but a cell's two node sums stay in
    registers while consecutive particles share the cell (sorted particles: ``ppc`` in a row), and
    go back to ``buf`` when the cell changes: one load and store per cell instead of one per term.
    Returns the first particle outside the grid (-1 if none)."""
    n_nodes = nodes.size
    a, b = nodes[0], nodes[n_nodes - 1]
    outside, held = -1, -1  # held: the cell whose node sums are in registers
    m0 = m1 = P0 = P1 = F0 = F1 = 0.0
    for q in range(lo, hi):
        if not (x[q] >= a and x[q] <= b):
            if outside < 0:
                outside = q
            continue
        c, xi, inv_h = _point(nodes, h, inv_spacing, x[q])  # the row (c, c + 1), (1 - xi, xi), (-1, 1)/h_c
        S0 = 1.0 - xi
        cell[q] = c
        if store:
            rows[q, 0], S[q, 0], G[q, 0] = c, S0, -inv_h
            rows[q, 1], S[q, 1], G[q, 1] = c + 1, xi, inv_h
        if c != held:
            if held >= 0:
                buf[0, held], buf[1, held], buf[2, held] = m0, P0, F0
                buf[0, held + 1], buf[1, held + 1], buf[2, held + 1] = m1, P1, F1
            m0, P0, F0 = buf[0, c], buf[1, c], buf[2, c]
            m1, P1, F1 = buf[0, c + 1], buf[1, c + 1], buf[2, c + 1]
            held = c
        mv = m[q] * v[q]
        m0 += S0 * m[q]
        P0 += S0 * mv
        m1 += xi * m[q]
        P1 += xi * mv
        if gas_force:
            Vp = V[q] * p[q]
            F0 += -inv_h * Vp
            F1 += inv_h * Vp
    if held >= 0:
        buf[0, held], buf[1, held], buf[2, held] = m0, P0, F0
        buf[0, held + 1], buf[1, held + 1], buf[2, held + 1] = m1, P1, F1
    return outside


@njit(cache=True, inline="always")
def _project_bspline(nodes, inv_spacing, x, V, m, v, p, gas_force, store, lo, hi, rows, S, G, cell, buf):
    """Pass 1 of the B-spline on a uniform grid over particles ``lo .. hi-1``, as
    :func:`_project_point`: the row from :func:`~mpm_fem.fused.basis._bspline_nearest` (three nodes around the nearest
    node ``n``), and the three nodes' sums held in registers while consecutive particles share ``n``
    (each node's terms still added in particle order). A particle whose nearest node is an end node
    (its ghost spline folded into it) adds into ``buf`` directly. Returns the first particle outside
    the grid (-1 if none)."""
    n_nodes = nodes.size
    top = n_nodes - 1
    a, b = nodes[0], nodes[top]
    outside, held = -1, -1  # held: the nearest node whose three node sums are in registers
    m0 = m1 = m2 = P0 = P1 = P2 = F0 = F1 = F2 = 0.0
    for q in range(lo, hi):
        if not (x[q] >= a and x[q] <= b):
            if outside < 0:
                outside = q
            continue
        s, c = _scaled(nodes, inv_spacing, x[q])
        n, t, w_l, w_0, w_r = _bspline_nearest(s, top)
        g_l, g_0, g_r = (t - 0.5) * inv_spacing, (-2.0 * t) * inv_spacing, (t + 0.5) * inv_spacing
        cell[q] = c
        if store:  # the row c-1 .. c+2, as _point_row stores it
            first = n - c
            for k in range(4):
                rows[q, k], S[q, k], G[q, k] = min(max(c + k - 1, 0), top), 0.0, 0.0
            S[q, first], S[q, first + 1], S[q, first + 2] = w_l, w_0, w_r
            G[q, first], G[q, first + 1], G[q, first + 2] = g_l, g_0, g_r
        mq = m[q]
        mv = mq * v[q]
        Vp = V[q] * p[q] if gas_force else 0.0
        if n == 0 or n == top:  # a ghost folded into the end node: straight into buf
            if held >= 0:
                buf[0, held - 1], buf[1, held - 1], buf[2, held - 1] = m0, P0, F0
                buf[0, held], buf[1, held], buf[2, held] = m1, P1, F1
                buf[0, held + 1], buf[1, held + 1], buf[2, held + 1] = m2, P2, F2
                held = -1
            i_l, i_r = max(n - 1, 0), min(n + 1, top)
            buf[0, i_l] += w_l * mq
            buf[1, i_l] += w_l * mv
            buf[0, n] += w_0 * mq
            buf[1, n] += w_0 * mv
            buf[0, i_r] += w_r * mq
            buf[1, i_r] += w_r * mv
            if gas_force:
                buf[2, i_l] += g_l * Vp
                buf[2, n] += g_0 * Vp
                buf[2, i_r] += g_r * Vp
            continue
        if n != held:
            if held >= 0:
                buf[0, held - 1], buf[1, held - 1], buf[2, held - 1] = m0, P0, F0
                buf[0, held], buf[1, held], buf[2, held] = m1, P1, F1
                buf[0, held + 1], buf[1, held + 1], buf[2, held + 1] = m2, P2, F2
            m0, P0, F0 = buf[0, n - 1], buf[1, n - 1], buf[2, n - 1]
            m1, P1, F1 = buf[0, n], buf[1, n], buf[2, n]
            m2, P2, F2 = buf[0, n + 1], buf[1, n + 1], buf[2, n + 1]
            held = n
        m0 += w_l * mq
        P0 += w_l * mv
        m1 += w_0 * mq
        P1 += w_0 * mv
        m2 += w_r * mq
        P2 += w_r * mv
        if gas_force:
            F0 += g_l * Vp
            F1 += g_0 * Vp
            F2 += g_r * Vp
    if held >= 0:
        buf[0, held - 1], buf[1, held - 1], buf[2, held - 1] = m0, P0, F0
        buf[0, held], buf[1, held], buf[2, held] = m1, P1, F1
        buf[0, held + 1], buf[1, held + 1], buf[2, held + 1] = m2, P2, F2
    return outside


@njit(cache=True, inline="always")
def _project_domain(basis, nodes, inv_spacing, x, V, m, v, p, gas_force, lo, hi, rows, S, G, cell, buf):
    """Pass 1 of a particle-domain basis (``GIMP`` or ``BSPLINE_GIMP``) on a
    uniform grid over particles ``lo .. hi-1``, as the generic loop of :func:`_project` (the same
    sums in the same order) in one loop over the particles: the row from scalars
    (:func:`~mpm_fem.fused.basis._domain`, then :func:`~mpm_fem.fused.basis._domain_column`, or for the
    B-spline's five columns :func:`~mpm_fem.fused.basis._bspline_domain_five`; no array handed to a
    helper per particle), stored in ``rows``, ``S``, ``G`` for pass 2 and added at
    once to ``buf[0..2]``: ``m_p S_ip``, ``m_p v_p S_ip``, ``V_p p_p G_ip`` (in the loop that builds
    the row: a second loop reading the stored rows back is slower). Returns the first particle outside the
    grid, the first with ``V <= 0`` (-1 if none) and the K the rows need."""
    n_nodes = nodes.size
    K = rows.shape[1]
    last = n_nodes - 1
    a, b = nodes[0], nodes[last]
    outside, empty, need = -1, -1, 0
    for q in range(lo, hi):
        if not (x[q] >= a and x[q] <= b):
            if outside < 0:
                outside = q
            continue
        if not (V[q] > 0):
            if empty < 0:
                empty = q
            continue
        D = _domain(basis, a, b, n_nodes - 2, inv_spacing, x[q], V[q])
        need = max(need, D[1])
        cell[q] = D[0]
        mq = m[q]
        mv = mq * v[q]
        Vp = V[q] * p[q]
        if basis == BSPLINE_GIMP and K == 5:
            S0, S1, S2, S3, S4, G0, G1, G2, G3, G4 = _bspline_domain_five(inv_spacing, D)
            first = D[2] - 1  # the columns' nodes c_- - 1 + j, ghosts folded into the end nodes
            _put(q, 0, min(max(first, 0), last), S0, G0, mq, mv, Vp, gas_force, rows, S, G, buf)
            _put(q, 1, min(max(first + 1, 0), last), S1, G1, mq, mv, Vp, gas_force, rows, S, G, buf)
            _put(q, 2, min(first + 2, last), S2, G2, mq, mv, Vp, gas_force, rows, S, G, buf)
            _put(q, 3, min(first + 3, last), S3, G3, mq, mv, Vp, gas_force, rows, S, G, buf)
            _put(q, 4, min(first + 4, last), S4, G4, mq, mv, Vp, gas_force, rows, S, G, buf)
            continue
        for j in range(K):
            i, Sj, Gj = _domain_column(basis, j, inv_spacing, last, D)
            _put(q, j, i, Sj, Gj, mq, mv, Vp, gas_force, rows, S, G, buf)
    return outside, empty, need


@njit(cache=True, inline="always")
def _put(q, j, i, Sj, Gj, mq, mv, Vp, gas_force, rows, S, G, buf):
    """Column ``j`` (node ``i``) of particle ``q``'s row: stored, and its terms added to ``buf``."""
    rows[q, j], S[q, j], G[q, j] = i, Sj, Gj
    buf[0, i] += Sj * mq
    buf[1, i] += Sj * mv
    if gas_force:
        buf[2, i] += Gj * Vp


def _project(nodes, h, inv_spacing, x, V, m, v, p, gas_force, store, chunks,
             rows, S, G, cell, m_i, P_i, F_i, flags):
    """Pass 1: the shape of every particle, ``m_i``, ``P_i`` and, if ``gas_force``, ``F_i = sum_p
    V_p p_p G_ip``. The cells are stored; the rows ``rows``, ``S``, ``G`` only if ``store`` (the
    consistent mass and GIMP need them). ``flags[k] = (first particle outside the grid, first
    with V <= 0, the K it needs)`` of chunk k."""
    n = x.size
    K = WIDTH  # nodes per particle
    n_nodes = nodes.size
    a, b = nodes[0], nodes[n_nodes - 1]
    buf = np.zeros((chunks, 3, n_nodes))
    for k in prange(chunks):
        lo, hi = _chunk(n, chunks, k)
        outside, empty, need = -1, -1, 0
        r, Sl, Gl = _one_row(K)
        if BASIS == POINT:  # point mass: its own loop, the sums held in registers (the loop below then skipped)
            outside, need = _project_point(nodes, h, inv_spacing, x, V, m, v, p, gas_force, store, lo, hi,
                                           rows, S, G, cell, buf[k]), 2
            lo = hi
        if BASIS == BSPLINE and inv_spacing > 0.0:  # the B-spline on a uniform grid: likewise
            outside, need = _project_bspline(nodes, inv_spacing, x, V, m, v, p, gas_force, store, lo, hi,
                                             rows, S, G, cell, buf[k]), 4
            lo = hi
        if (BASIS == GIMP or BASIS == BSPLINE_GIMP) and inv_spacing > 0.0:  # the domain bases on a uniform grid:
            # likewise
            outside, empty, need = _project_domain(BASIS, nodes, inv_spacing, x, V, m, v, p, gas_force, lo, hi,
                                                   rows, S, G, cell, buf[k])
            lo = hi
        for q in range(lo, hi):
            if not (x[q] >= a and x[q] <= b):
                if outside < 0:
                    outside = q
                continue
            if (BASIS == GIMP or BASIS == BSPLINE_GIMP) and not (V[q] > 0):
                if empty < 0:
                    empty = q
                continue
            if BASIS == POINT or BASIS == BSPLINE:
                c, kq = _point_row(BASIS, nodes, h, inv_spacing, x[q], r, Sl, Gl)
            else:
                c, kq = _domain_shape_row(BASIS, nodes, h, inv_spacing, x[q], V[q], r, Sl, Gl)
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

