"""The node sums of the passes, in the numpy step's order.

``sum_j W_j f_{r_j}`` over one particle's row (gathers) and ``buf[k, 0, r_j] += W_j w_p`` (scatters),
each left to right along the row; the particles are cut into ``chunks`` contiguous ranges
(:func:`_chunk`), each scattering into its own buffer ``buf[k]``, and the buffers are summed in chunk
order (:func:`_sum_chunks`). The result depends only on the number of chunks, not on the threads'
scheduling: one chunk is the numpy step's order bit for bit, more chunks group the sums differently
(equal to round-off). Inlined into the passes.
"""

import numpy as np
from numba import njit


@njit(cache=True)
def _divide_by_lumped(rhs, m_i, out):
    """:func:`~mpm_fem.core.transfer.divide_by_lumped` into ``out``: ``rhs_i / m_i`` where ``m_i > 0``, else 0."""
    for i in range(out.size):
        out[i] = rhs[i] / m_i[i] if m_i[i] > 0 else 0.0
    return out


@njit(cache=True, inline="always")
def _chunk(n, chunks, k):
    """Particles ``lo .. hi-1`` of chunk ``k`` of ``chunks`` contiguous ranges over ``n``."""
    return k * n // chunks, (k + 1) * n // chunks


@njit(cache=True, inline="always")
def _one_row(K):
    """Scratch for one particle's row: node indices, ``S_ip``, ``G_ip``."""
    return np.empty(K, np.intp), np.empty(K), np.empty(K)


@njit(cache=True, inline="always")
def _gather(W, f, r, K):
    """``sum_j W_j f_{r_j}``, left to right: ``(dv/dx)_p`` or ``v_p`` of one particle."""
    s = W[0] * f[r[0]]
    for j in range(1, K):
        s += W[j] * f[r[j]]
    return s


@njit(cache=True, inline="always")
def _scatter(buf, k, r, W, w, K):
    """``buf[k, 0, r_j] += W_j w``: one particle's share of a nodal sum, into chunk k's buffer."""
    for j in range(K):
        buf[k, 0, r[j]] += W[j] * w


@njit(cache=True, inline="always")
def _gather_stored(W, q, f, rows, K):
    """:func:`_gather` of particle q's stored row (``rows[q]``, ``W[q]``), read in place."""
    s = W[q, 0] * f[rows[q, 0]]
    for j in range(1, K):
        s += W[q, j] * f[rows[q, j]]
    return s


@njit(cache=True, inline="always")
def _scatter_stored(buf, k, rows, q, W, w, K):
    """:func:`_scatter` of particle q's stored row, read in place."""
    for j in range(K):
        buf[k, 0, rows[q, j]] += W[q, j] * w


@njit(cache=True, inline="always")
def _sum_chunks(buf, j, out, sign):
    """``out = sign sum_k buf[k, j]``, the chunks summed in their order."""
    for i in range(out.size):
        out[i] = sign * buf[0, j, i]
    for k in range(1, buf.shape[0]):
        for i in range(out.size):
            out[i] += sign * buf[k, j, i]

