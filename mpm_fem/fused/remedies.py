"""The remedies' passes: the grid volume reset and the Taylor reconstruction's force.

The grid volume reset (:func:`_volume_reset`, :func:`mpm_fem.core.volume.grid_volume_factor` then the
model's ``with_volume``): ``V_i = sum_p V_p Sbar_ip``, ``V_p <- V_p sum_i Sbar_ip (int S_i / V_i)``
with the particle-domain rows ``Sbar_ip``. The Taylor reconstruction (:func:`_taylor_force`,
:func:`mpm_fem.core.reconstruction.reconstructed_force`): the stress fitted linearly cell by cell,
and the force of the fit by quadrature. Both in the numpy step's operations and order. The other
remedies live in the passes they change: the PIC/FLIP blend and XPIC's interpolation in pass 2
(:func:`mpm_fem.fused.passes._move`), XPIC's projections in the scatter pass
(:func:`mpm_fem.fused.passes._scatter_pass` with ``MOMENTUM``) and the loop's XPIC iteration
(:mod:`mpm_fem.fused.loop`). ``MODEL``, ``WIDTH``, ``ROW``, ``STORED`` and the twin's kernels
``TWIN_ROW``, ``TWIN_SCALARS``, ``TWIN_COLUMN`` (the particle-domain basis the volume reset
averages over, the basis's ``domain_twin``) are compile-time globals of each variant
(:mod:`mpm_fem.fused.compiler`).
"""

from typing import NamedTuple

import numpy as np
from numba import prange

from mpm_fem.bases.cells import locate as _locate
from mpm_fem.fused.codes import GAS, IGM1
from mpm_fem.fused.models import _first
from mpm_fem.fused.sums import (
    _chunk,
    _divide_by_lumped,
    _gather,
    _gather_stored,
    _one_row,
    _scatter,
    _scatter_stored,
    _sum_chunks,
)

# placeholders: each variant has its own (mpm_fem.fused.compiler)
MODEL = WIDTH = ROW = STORED = TWIN_ROW = TWIN_SCALARS = TWIN_COLUMN = None


class State(NamedTuple):
    """The particles' state the grid volume reset reads (n_p,)."""

    x: np.ndarray
    V: np.ndarray
    m: np.ndarray
    rho: np.ndarray
    e: np.ndarray  # the specific internal energy eps
    p: np.ndarray


class Reset(NamedTuple):
    """The grid volume reset's nodal scratch (n_nodes,) and the reset state it writes (n_p,)."""

    V_i: np.ndarray  # sum_p V_p Sbar_ip
    ratio: np.ndarray  # int S_i / V_i
    V: np.ndarray
    rho: np.ndarray
    p: np.ndarray


class Quadrature(NamedTuple):
    """The Taylor force's quadrature (:func:`~mpm_fem.core.reconstruction.force_quadrature`)."""

    points: np.ndarray  # the points' nodes (n_points, k)
    G_q: np.ndarray  # S_i' there (n_points, k)
    weights: np.ndarray  # their weights w_g (n_points,)
    offsets: np.ndarray  # xi_g - 1/2 of a cell's points


def _volume_reset(geometry, stored, state, integrals, consts, chunks, width, out, flags, values):
    """The grid volume reset (:func:`mpm_fem.core.volume.grid_volume_factor`, then the model's
    ``with_volume``) of the particles ``state`` (:class:`State`), with the grid ``geometry`` and pass
    1's row store ``stored`` (:mod:`mpm_fem.bases.contract`): ``V_i = sum_p V_p Sbar_ip``, ``f_p =
    sum_i Sbar_ip (int S_i / V_i)`` (0 where ``V_i = 0``; ``integrals`` holds ``int S_i``), ``V_p <-
    V_p f_p``; the gas at the same mass and specific energy, ``rho_p = m_p / V_p``, ``p_p = (gamma -
    1) rho_p eps_p + q_p rho_p / rho_p^old`` (``q_p`` its viscosity) (Burgers: ``m_p = V_p``, which
    its update sets anyway): ``V_i``, the ratio and the reset ``V``, ``rho``, ``p`` into ``out``
    (:class:`Reset`). The domain rows take ``width`` columns. ``flags[k] = (first particle of chunk
    k whose new density (gas) or volume (Burgers) is not > 0, the width its rows need)``,
    ``values[k, 0]`` that density or volume."""
    nodes, h, inv_spacing = geometry
    rows, S = stored.rows, stored.S
    x, V, m, rho, e, p = state
    V_i, ratio, V_r, rho_r, p_r = out
    n = x.size
    gas = MODEL == GAS
    # Sbar_ip: the step's stored rows (a particle-domain basis), or the rows of its twin (a point
    # basis: the particle-domain basis over its grid functions), on a uniform grid from scalars as
    # pass 1 of the twin builds them. The basis is tested in the loop, on the compile-time
    # constants: flags set in branches before a prange loop (`fresh = ... and ...`) gave NaN
    # particles in a parallel variant called by the loop (numba 0.68.1). The scalar rows are
    # written out here because an inlined helper handed `buf` or `ratio` costs reference counting
    a, b, last = nodes[0], nodes[nodes.size - 1], nodes.size - 1
    buf = np.zeros((chunks, 1, V_i.size))
    for k in prange(chunks):
        r, Sl, Gl = _one_row(width)
        need = 0
        for q in range(*_chunk(n, chunks, k)):
            if STORED == 1:  # the step's own rows, read where they lie
                need = width
                _scatter_stored(buf, k, rows, q, S, V[q], width)
            elif inv_spacing > 0.0:
                D = TWIN_SCALARS(a, b, last - 1, inv_spacing, x[q], V[q])
                need = max(need, D.need)
                for j in range(width):
                    i, s, _ = TWIN_COLUMN(j, inv_spacing, last, D)
                    buf[k, 0, i] += s * V[q]
            else:
                need = max(need, TWIN_ROW(nodes, h, inv_spacing, x[q], V[q], r, Sl, Gl)[1])
                _scatter(buf, k, r, Sl, V[q], width)
        flags[k, 1] = need
    _sum_chunks(buf, 0, V_i, 1.0)
    _divide_by_lumped(integrals, V_i, ratio)
    gm1 = consts[IGM1]
    for k in prange(chunks):
        r, Sl, Gl = _one_row(width)
        bad, value = -1.0, 0.0
        for q in range(*_chunk(n, chunks, k)):
            if STORED == 1:
                V_r[q] = V[q] * _gather_stored(S, q, ratio, rows, width)
            elif inv_spacing > 0.0:  # sum_j Sbar_qj ratio_j, left to right (_gather's order)
                D = TWIN_SCALARS(a, b, last - 1, inv_spacing, x[q], V[q])
                f = 0.0
                for j in range(width):
                    i, s, _ = TWIN_COLUMN(j, inv_spacing, last, D)
                    f = s * ratio[i] if j == 0 else f + s * ratio[i]
                V_r[q] = V[q] * f
            else:
                TWIN_ROW(nodes, h, inv_spacing, x[q], V[q], r, Sl, Gl)
                V_r[q] = V[q] * _gather(Sl, ratio, r, width)
            if gas:
                rho_r[q] = m[q] / V_r[q]
                viscosity = p[q] - gm1 * rho[q] * e[q]
                p_r[q] = gm1 * rho_r[q] * e[q] + viscosity * rho_r[q] / rho[q]
                bad, value = _first(bad, value, q, rho_r[q])
            else:
                bad, value = _first(bad, value, q, V_r[q])
        flags[k, 0], values[k, 0] = int(bad), value


def _taylor_force(geometry, x, stored, p, v_i, eps, quadrature, chunks, sums, F_i):
    """The reconstructed force (:func:`mpm_fem.core.reconstruction.reconstructed_force`, the same
    operations): the stress ``sigma_p`` (gas ``-p_p``; Burgers ``eps sum_i G_ip v_i``) fitted cell by
    cell by ``s0_c + s1_c (xi - 1/2)`` (:func:`~mpm_fem.core.reconstruction.taylor_fit`: the sums of 1,
    ``d``, ``d^2``, ``sigma``, ``sigma d`` over a cell's particles in index order, ``d = xi_p - 1/2``,
    into ``sums``), then ``F_i = - sum_g w_g sigma_h(x_g) S_i'(x_g)`` over the four points ``x_g`` of
    every cell (:func:`~mpm_fem.core.reconstruction.force_quadrature`, ``quadrature``: their nodes
    ``points``, ``S_i'`` in ``G_q``, ``w_g = h_c / 4``; ``offsets``: ``xi_g - 1/2``), point by point;
    the grid ``geometry`` and pass 1's row store ``stored`` as :mod:`mpm_fem.bases.contract`'s."""
    nodes, h, inv_spacing = geometry
    rows, S, G, cell = stored
    points, G_q, weights, offsets = quadrature
    n = x.size
    K = WIDTH  # nodes per particle
    gas = MODEL == GAS
    n_cells = sums.shape[1]
    buf = np.zeros((chunks, 5, n_cells))
    for k in prange(chunks):
        r, Sl, Gl = _one_row(K)
        for q in range(*_chunk(n, chunks, k)):
            if gas:
                sigma = -p[q]
            else:
                ROW(nodes, h, inv_spacing, x, q, rows, S, G, cell, r, Sl, Gl)
                sigma = eps * _gather(Gl, v_i, r, K)
            c, xi = _locate(nodes, inv_spacing, x[q])
            d = xi - 0.5
            buf[k, 0, c] += 1.0
            buf[k, 1, c] += d
            buf[k, 2, c] += d * d
            buf[k, 3, c] += sigma
            buf[k, 4, c] += sigma * d
    for j in range(5):
        _sum_chunks(buf, j, sums[j], 1.0)
    F_i[:] = 0.0
    per_cell = offsets.size
    for c in range(n_cells):
        count, sd, sdd, sq, sqd = sums[0, c], sums[1, c], sums[2, c], sums[3, c], sums[4, c]
        det = count * sdd - sd * sd
        least = max(count, 1.0)
        s1 = (count * sqd - sd * sq) / det if det > 1e-12 * (least * least) else 0.0
        s0 = (sq - s1 * sd) / count if count > 0 else 0.0
        for g in range(c * per_cell, (c + 1) * per_cell):
            w_sigma = weights[g] * (s0 + s1 * offsets[g - c * per_cell])
            for j in range(points.shape[1]):
                F_i[points[g, j]] += G_q[g, j] * w_sigma
    for i in range(F_i.size):
        F_i[i] = -F_i[i]

