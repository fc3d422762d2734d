"""The compiled cell of a point, shared by the bases' row kernels (numba, inlined).

``nodes`` (n_nodes,) are the grid's nodes and ``inv_spacing`` is ``1/h`` on a grid uniform to
round-off, else 0. :func:`locate` is :func:`mpm_fem.bases.shape.locate` of one point, bit for bit;
on a uniform grid a row may instead take uniform-grid arithmetic, ``s = (y - x_0)/h``, ``c =
floor(s)`` (:func:`scaled`, :func:`domain_ends`): equal to the node arithmetic to round-off. A pass
after pass 1 reads a particle-domain basis's rows back from pass 1's store (:func:`stored_row`).
"""

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def locate(nodes, inv_spacing, x):
    """:func:`mpm_fem.bases.shape.locate` of one point inside the grid (``inv_spacing``: ``1 / h`` on a
    uniform grid, else 0): its cell ``c`` and ``xi = (x - x_c)/(x_{c+1} - x_c)``, bit for bit. The
    one compiled point location: the bases' rows and the exact stages' kernels use it."""
    last = nodes.size - 2
    if inv_spacing > 0.0:
        c = min(max(int((x - nodes[0]) * inv_spacing), 0), last)
        if x < nodes[c] or (x >= nodes[c + 1] and c < last):
            c = min(np.searchsorted(nodes, x, side="right") - 1, last)
    else:
        c = min(np.searchsorted(nodes, x, side="right") - 1, last)
    x0 = nodes[c]
    return c, (x - x0) / (nodes[c + 1] - x0)


@njit(cache=True, inline="always")
def scaled(nodes, inv_spacing, y):
    """Uniform-grid arithmetic for one point ``y`` in the grid: ``s = (y - x_0)/h`` and its cell
    ``c = floor(s)`` (the last node in the last cell)."""
    s = (y - nodes[0]) * inv_spacing
    return s, min(int(s), nodes.size - 2)


#: The fields a particle-domain basis's per-particle scalars begin with (its ``Domain`` named tuple, made
#: with ``typing.NamedTuple("Domain", DOMAIN_FIELDS + its own)``): the particle's cell, the K its row
#: needs, the domain's ends ``c_-, c_+, s_-, s_+`` (:func:`domain_ends`) and ``inv_w = 1 / (s_+ - s_-)``.
DOMAIN_FIELDS = [("cell", int), ("need", int), ("c_lo", int), ("c_hi", int), ("s_lo", float), ("s_hi", float),
                 ("inv_w", float)]


@njit(cache=True, inline="always")
def domain_ends(x0, b, top_cell, inv_spacing, x, V):
    """The particle domain ``[x - V/2, x + V/2]`` cut at the grid's ends ``[x0, b]``, in uniform-grid
    arithmetic (:func:`scaled`'s operations, from scalars: no array handed over per particle, which
    would cost reference counting in the hot loops): the particle's cell ``c``, and ``s_-, c_-,
    s_+, c_+``, the scaled ends and their cells."""
    c = min(int((x - x0) * inv_spacing), top_cell)
    s_lo = (max(x - 0.5 * V, x0) - x0) * inv_spacing
    s_hi = (min(x + 0.5 * V, b) - x0) * inv_spacing
    return c, s_lo, min(int(s_lo), top_cell), s_hi, min(int(s_hi), top_cell)


@njit(cache=True, inline="always")
def stored_row(nodes, h, inv_spacing, x, q, rows, S, G, cell, r, Sl, Gl):
    """Particle q's nodes and weights into ``r``, ``Sl``, ``Gl``, and its cell, read from pass 1's
    rows ``rows[q]``, ``S[q]``, ``G[q]`` and cells: the ``pass_row`` of a particle-domain basis, whose
    rows pass 1 stores (:class:`mpm_fem.bases.contract.Kernels`)."""
    for j in range(r.size):
        r[j], Sl[j], Gl[j] = rows[q, j], S[q, j], G[q, j]
    return cell[q]


@njit(cache=True, inline="always")
def put(q, j, i, Sj, Gj, weights, gas_force, rows, S, G, buf):
    """Column ``j`` (node ``i``) of particle ``q``'s row stored, and its pass-1 terms added to the
    chunk's ``buf``: ``m_p S_ij``, ``m_p v_p S_ij`` and, if ``gas_force``, ``V_p p_p G_ij``, with the
    particle's ``weights = (m_p, m_p v_p, V_p p_p)``."""
    mq, mv, Vp = weights
    rows[q, j], S[q, j], G[q, j] = i, Sj, Gj
    buf[0, i] += Sj * mq
    buf[1, i] += Sj * mv
    if gas_force:
        buf[2, i] += Gj * Vp
