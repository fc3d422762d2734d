"""Compiled sums of the exact grid stage (numba): the quadrature's nodal sums and the FE mass.

The kernels of the exact grid stage (:class:`~mpm_fem.exact_stages.stage.ExactGridStage`) make the
same sums as its numpy forms with the same floating-point operations in the same order, so they
equal them bit for bit (tested: ``tests/test_grid_kernels.py``); the numpy forms
(:mod:`mpm_fem.core.transfer`, :meth:`~mpm_fem.exact_stages.mass.FEMass.entries_numpy`) stay the
readable reference. Why compiled: ``docs/performance.md``.

    project     m_i = sum_q (w_q rho_q) S_qi,   P_i = sum_q ((w_q rho_q) v_q) S_qi,
                F_i = - sum_q (w_q sigma_q) G_qi,
                each sum in the order of the points and of a row's columns, as ``np.bincount``
                adds its weights (one after the other, from 0).
    cut_pieces  the pieces (nodes and half cells) that breakpoints cut, their sub-pieces' Gauss
                points ``x = (a + w/2) + (w/2) xi_g`` and weights ``(w/2) w_g`` and the rows of the
                grid functions there (:meth:`~mpm_fem.exact_stages.quadrature.QuadratureRule.cuts`):
                the compiled row of the grid functions' basis (:mod:`mpm_fem.bases`) in the node
                arithmetic of its numpy rows, its point location included; one variant per basis.
    splice      the rows of the fixed pieces with each cut piece replaced by its sub-pieces
                (:meth:`~mpm_fem.exact_stages.quadrature.QuadratureRule.splice`): copies only.
    fe_entries  the entries of the FE mass, ``M_e = sum_q A_eq (dx_q rho_q)`` (scipy's CSR
                matrix-vector product: each row summed from 0 in its stored order; ``M_ji`` copied
                from ``M_ij`` where their rows of ``A`` are equal), the cut pieces' points weighted
                0, then the sub-pieces' products ``(dx_q rho_q) S_qi S_qj`` summed from 0 into
                their entries in the order of ``np.bincount`` and added.
    corrected   the exact mass stage's nodal value ``u*_i + rhs_i / m_i - rhs*_i / m*_i``, each
                lumped division 0 where its mass is not positive
                (:func:`~mpm_fem.core.transfer.divide_by_lumped`), added in that order.
"""

from __future__ import annotations

import hashlib
import types
from functools import lru_cache
from pathlib import Path

import numpy as np
from numba import njit

from mpm_fem.bases import get
from mpm_fem.bases.cells import locate

__all__ = ["corrected", "cut_pieces", "fe_entries", "locate", "project", "splice"]


@njit(cache=True)
def project(nodes, S, G, w, rho, v, sigma, n_nodes, with_mass):
    """``(m_i, P_i, F_i)`` of the quadrature points (module docstring); ``with_mass=False`` leaves
    ``m_i`` empty. ``nodes``, ``S``, ``G`` are (n_q, k) rows, the rest (n_q,)."""
    m_i, P_i, F_i = np.zeros(n_nodes if with_mass else 0), np.zeros(n_nodes), np.zeros(n_nodes)
    for q in range(nodes.shape[0]):
        mass = w[q] * rho[q]
        momentum = mass * v[q]
        force = w[q] * sigma[q]
        for k in range(nodes.shape[1]):
            i = nodes[q, k]
            if with_mass:
                m_i[i] += S[q, k] * mass
            P_i[i] += S[q, k] * momentum
            F_i[i] += G[q, k] * force
    return m_i, P_i, -F_i


ROW = WIDTH = None  # placeholders: each grid function's variant of _cut_pieces has its own (cut_pieces)
#: the files whose code a variant of _cut_pieces compiles (the bases' rows are inlined into it)
SOURCES = sorted((Path(__file__).parent.parent / "bases").glob("*.py")) + [Path(__file__)]
DIGEST = hashlib.sha1(b"".join(path.read_bytes() for path in SOURCES)).hexdigest()[:8]


def _cut_pieces(edges, bp, xi, wq, nodes, h):
    """The pieces ``edges`` (n_pieces + 1,) that the breakpoints ``bp`` inside them cut, and their
    sub-pieces (module docstring; :meth:`~mpm_fem.exact_stages.quadrature.QuadratureRule.cuts_numpy`):
    ``(cut, first, x, w, rows, S, G, cell)`` with ``first`` each cut piece's first sub-piece and
    then their number, ``x``, ``w``, ``cell`` (n_sub, n_gauss) and ``rows``, ``S``, ``G`` (n_sub,
    n_gauss, k). The rows are the grid functions' compiled row ``ROW`` in the node arithmetic
    (``inv_spacing = 0``: the numpy rows bit for bit), ``WIDTH`` = k columns; ``h`` (2, n_cells): the
    cell sizes and their inverses (:class:`~mpm_fem.bases.contract.Kernels`)."""
    n = edges.size - 1
    piece = np.searchsorted(edges, bp, side="right") - 1
    inside = np.zeros(bp.size, np.bool_)
    for j in range(bp.size):
        inside[j] = piece[j] >= 0 and piece[j] < n and bp[j] > edges[min(max(piece[j], 0), n)]
    cut = np.unique(piece[inside])
    ends = np.unique(np.concatenate((edges[cut], edges[cut + 1], bp[inside])))
    owner = np.searchsorted(edges, 0.5 * (ends[:-1] + ends[1:])) - 1
    keep = np.zeros(owner.size, np.bool_)
    for j in range(owner.size):
        c = np.searchsorted(cut, owner[j])
        keep[j] = c < cut.size and cut[c] == owner[j]
    left, width = ends[:-1][keep], (ends[1:] - ends[:-1])[keep]
    first = np.append(np.searchsorted(owner[keep], cut), left.size)
    g, k = xi.size, WIDTH
    x, w, cell = np.empty((left.size, g)), np.empty((left.size, g)), np.empty((left.size, g), np.intp)
    rows, S, G = np.empty((left.size, g, k), np.intp), np.empty((left.size, g, k)), np.empty((left.size, g, k))
    for p in range(left.size):
        for q in range(g):
            x[p, q] = (left[p] + 0.5 * width[p]) + 0.5 * width[p] * xi[q]
            w[p, q] = 0.5 * width[p] * wq[q]
            c, _ = ROW(nodes, h, 0.0, x[p, q], 0.0, rows[p, q], S[p, q], G[p, q])
            cell[p, q] = c
    return cut, first, x, w, rows, S, G, cell


@lru_cache(maxsize=None)
def cut_pieces(functions: str):
    """:func:`_cut_pieces` compiled for the registered point basis ``functions`` (its row kernel and
    width as the variant's globals), named by a digest of :data:`SOURCES` so that numba's on-disk
    cache never serves a variant compiled from other sources."""
    basis = get(functions)
    if basis.domain:
        raise ValueError(f"the exact stages integrate grid functions of a point basis, not {functions!r}")
    name = f"_cut_pieces_{basis.name}_{DIGEST}"
    variant = types.FunctionType(_cut_pieces.__code__, dict(_cut_pieces.__globals__, ROW=basis.kernels.row,
                                                            WIDTH=basis.width), name)
    variant.__qualname__ = name
    return njit(cache=True)(variant)


@njit(cache=True)
def _order(n, cut, first):
    """Where each piece of the spliced rule comes from: ``p >= 0`` the fixed piece ``p``, ``-1 - s``
    the sub-piece ``s`` (each cut piece ``cut[j]`` replaced by the sub-pieces ``first[j] ...
    first[j + 1] - 1``)."""
    order = np.empty(n - cut.size + first[-1], np.int64)
    o, start = 0, 0
    for j in range(cut.size + 1):
        stop = cut[j] if j < cut.size else n
        for p in range(start, stop):
            order[o] = p
            o += 1
        if j < cut.size:
            for p in range(first[j], first[j + 1]):
                order[o] = -1 - p
                o += 1
            start = cut[j] + 1
    return order


@njit(cache=True)
def _spliced(fixed, sub, order):
    """The pieces of ``fixed`` and ``sub`` (C-contiguous, the trailing axes alike) in ``order``."""
    out = np.empty((order.size,) + fixed.shape[1:], fixed.dtype)
    m = fixed[0].size
    o2, f2, s2 = out.reshape((order.size, m)), fixed.reshape((fixed.shape[0], m)), sub.reshape((sub.shape[0], m))
    for o in range(order.size):
        src = order[o]
        if src >= 0:
            for c in range(m):
                o2[o, c] = f2[src, c]
        else:
            for c in range(m):
                o2[o, c] = s2[-1 - src, c]
    return out


@njit(cache=True)
def splice(fixed, sub, cut, first):
    """The fixed pieces' points ``x``, weights ``w`` (n_pieces, n_gauss), rows ``nodes``, ``S``,
    ``G`` (n_pieces, n_gauss, k) and ``cell`` (the tuple ``fixed``, in that order) with each cut
    piece replaced by its sub-pieces (the tuple ``sub`` of the same six; :func:`_order`), in order
    along the domain."""
    x, w, nodes, S, G, cell = fixed
    sub_x, sub_w, sub_nodes, sub_S, sub_G, sub_cell = sub
    order = _order(x.shape[0], cut, first)
    return (_spliced(x, sub_x, order), _spliced(w, sub_w, order), _spliced(nodes, sub_nodes, order),
            _spliced(S, sub_S, order), _spliced(G, sub_G, order), _spliced(cell, sub_cell, order))


@njit(cache=True)
def fe_entries(operator, mirror, dx, rho, cut, keys, n_nodes, sub_nodes, sub_S, sub_w, sub_rho):
    """The entries of the FE mass (module docstring) and whether a sub-piece product that is not 0
    falls outside the pattern ``keys`` (``i n_nodes + j`` of each stored entry, increasing).

    ``operator = (indptr, indices, data)``: the CSR operator ``A`` (entries x points); ``mirror``: an
    earlier entry whose row of ``A`` is the same, stored and valued (the transposed entry of a
    symmetric ``M``), whose sum is then copied, else the entry itself; ``dx``, ``rho``:
    the fixed pieces' (n_pieces, n_gauss) weights and densities; ``cut``: the cut pieces; the sub-
    pieces' rows ``sub_nodes``, ``sub_S`` (n_sub, k), weights ``sub_w`` and densities ``sub_rho``."""
    indptr, indices, data = operator
    g = dx.shape[1]
    q = np.empty(dx.size)
    for p in range(dx.shape[0]):
        for j in range(g):
            q[p * g + j] = dx[p, j] * rho[p, j]
    for c in cut:
        q[c * g: (c + 1) * g] = 0.0
    n = indptr.size - 1
    out = np.zeros(n)
    for e in range(n):
        if mirror[e] < e:  # the same products summed in the same order
            out[e] = out[mirror[e]]
            continue
        total = 0.0
        for jj in range(indptr[e], indptr[e + 1]):
            total += data[jj] * q[indices[jj]]
        out[e] = total
    outside = False
    if sub_w.size:
        extra = np.zeros(n)
        k = sub_nodes.shape[1]
        for p in range(sub_w.size):
            mass = sub_w[p] * sub_rho[p]
            for a in range(k):
                left = mass * sub_S[p, a]
                for b in range(k):
                    wanted = sub_nodes[p, a] * n_nodes + sub_nodes[p, b]
                    entry = min(np.searchsorted(keys, wanted), keys.size - 1)
                    product = left * sub_S[p, b]
                    if keys[entry] != wanted and product != 0.0:
                        outside = True
                    extra[entry] += product
        out = out + extra
    return out, outside


@njit(cache=True)
def corrected(reference, rhs, m, exact_rhs, exact_m):
    """``(reference_i + rhs_i / m_i) - exact_rhs_i / exact_m_i`` (module docstring)."""
    out = np.empty(reference.size)
    for i in range(reference.size):
        a = rhs[i] / m[i] if m[i] > 0 else 0.0
        b = exact_rhs[i] / exact_m[i] if exact_m[i] > 0 else 0.0
        out[i] = (reference[i] + a) - b
    return out
