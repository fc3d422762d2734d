"""Compiled sums of the exact grid stage (numba): the quadrature's nodal sums and the FE mass.

The exact grid stage (:class:`~mpm_fem.exact_stages.ExactGridStage`) runs every step on a few
thousand Gauss points and a few hundred nodes; in numpy its cost is mostly the overhead of many
small array calls. The kernels below make the same sums with the same floating-point operations in
the same order, so they equal the numpy ones bit for bit (tested: ``tests/test_grid_kernels.py``);
the numpy forms (:mod:`mpm_fem.transfer`, :meth:`~mpm_fem.exact_stages.FEMass.entries_numpy`) stay
the readable reference.

    project     m_i = sum_q (w_q rho_q) S_qi,   P_i = sum_q ((w_q rho_q) v_q) S_qi,
                F_i = - sum_q (w_q sigma_q) G_qi,
                each sum in the order of the points and of a row's columns, as ``np.bincount``
                adds its weights (one after the other, from 0).
    splice      the rows of the fixed pieces with each cut piece replaced by its sub-pieces
                (:meth:`~mpm_fem.exact_stages.QuadratureRule.__call__`): copies only.
    fe_entries  the entries of the FE mass, ``M_e = sum_q A_eq (dx_q rho_q)`` (scipy's CSR
                matrix-vector product: each row summed from 0 in its stored order), the cut pieces'
                points weighted 0, then the sub-pieces' products ``(dx_q rho_q) S_qi S_qj`` summed
                from 0 into their entries in the order of ``np.bincount`` and added.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from . import frame_chunks

frame_chunks.install()  # numba's compiler crosses CPython 3.11's frame-chunk starts: reuse the chunks


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


@njit(cache=True)
def _splice_into(out, fixed, sub, cut, first):
    """``out``: the pieces of ``fixed`` (n_pieces, ...) in order, each cut piece ``cut[j]`` replaced
    by the sub-pieces ``first[j] ... first[j + 1] - 1`` of ``sub``."""
    o, start = 0, 0
    for j in range(cut.size):
        for p in range(start, cut[j]):
            out[o] = fixed[p]
            o += 1
        for p in range(first[j], first[j + 1]):
            out[o] = sub[p]
            o += 1
        start = cut[j] + 1
    for p in range(start, fixed.shape[0]):
        out[o] = fixed[p]
        o += 1


def splice(fixed: np.ndarray, sub: np.ndarray, cut: np.ndarray, first: np.ndarray) -> np.ndarray:
    """:func:`_splice_into` a new array of ``fixed.shape[0] - cut.size + sub.shape[0]`` pieces."""
    out = np.empty((fixed.shape[0] - cut.size + sub.shape[0], *fixed.shape[1:]), fixed.dtype)
    _splice_into(out, fixed, sub, cut, first)
    return out


@njit(cache=True)
def fe_entries(indptr, indices, data, dx, rho, cut, keys, n_nodes, sub_nodes, sub_S, sub_w, sub_rho):
    """The entries of the FE mass (module docstring) and whether a sub-piece product that is not 0
    falls outside the pattern ``keys`` (``i n_nodes + j`` of each stored entry, increasing).

    ``indptr``, ``indices``, ``data``: the CSR operator ``A`` (entries x points); ``dx``, ``rho``:
    the fixed pieces' (n_pieces, n_gauss) weights and densities; ``cut``: the cut pieces; the sub-
    pieces' rows ``sub_nodes``, ``sub_S`` (n_sub, k), weights ``sub_w`` and densities ``sub_rho``."""
    q = dx * rho
    for c in cut:
        q[c, :] = 0.0
    q = q.ravel()
    n = indptr.size - 1
    out = np.zeros(n)
    for e in range(n):
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
