"""The compiled passes of the 2D step (numba): :func:`mpm_fem.plane.step.step` with the lumped mass.

One step is three passes (the numpy step's equations, :mod:`mpm_fem.plane.step`):

    _project   over particles:  m_i, P_i = sum_p m_p v_p S_ip,
                                f_i = sum_p m_p b_p S_ip - sum_p V_p sigma_p G_ip      (sigma_p of F_p^n)
    _solve     over nodes:      v_i = P_i / m_i,  a_i = f_i / m_i  (0 where m_i = 0),  v_i^+ = v_i + dt a_i
    _move      over particles:  v_p <- flip (v_p + dt sum_i S_ip a_i) + (1 - flip) sum_i S_ip v_i^+,
                                x_p <- x_p + dt sum_i S_ip v_i^+,
                                F_p <- (I + dt sum_i v_i^+ (x) G_ip) F_p,   V_p = det(F_p) V_p^0

with the tensor rows ``S_ip = S^x_a S^y_b``, ``G_ip = (S^x_a' S^y_b, S^x_a S^y_b')``, node ``i =
w_x(r^x_a) n_y + w_y(r^y_b)`` (:mod:`mpm_fem.plane.bases`). Each axis's row is the 1D basis's
compiled ``row`` (:class:`mpm_fem.bases.contract.Kernels`) on that axis's line (:class:`Line`: the
padded line of a periodic axis, whose node ``r`` is axis node ``wrap[r]``), at the position folded
into the domain; on a grid uniform to round-off that row finds the cell as ``floor((x - x_0)/h)``.
``ROW`` (that kernel) and ``K`` (the basis's width, columns per axis) are compile-time globals of
each variant (:mod:`mpm_fem.plane.fused`). The particles are cut into ``chunks`` contiguous ranges
(:func:`mpm_fem.fused.sums._chunk`), one per thread: pass 1 scatters chunk k into its own node
buffer ``buf[k]`` and pass 2 writes only chunk k's particles, so the ``prange`` over chunks shares
no write; the result depends on the number of chunks only (one chunk: the particles' order).

Arrays: ``buf`` (chunks, n_nodes, NSUM) the node sums (columns ``IM, IPX, IPY, IFX, IFY``; zeroed
by :func:`_solve` for the next step); ``nodal`` (n_nodes, 4) ``a_i`` and ``v_i^+`` (columns ``IAX,
IAY, IVX, IVY``); ``flags`` (chunks, 3): per chunk the first particle outside the grid, the widest
row a particle needs (columns per axis) and the first particle with ``J <= 0`` or NaN (-1: none).
As in the 1D passes (:mod:`mpm_fem.fused.passes`), every array is taken out of its named tuple by
attribute, one a statement, before the ``prange`` (numba/numba#5872).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit, prange

from mpm_fem.fused.sums import _chunk

ROW = K = None  # placeholders: each variant has its own (mpm_fem.plane.fused)

IM, IPX, IPY, IFX, IFY = range(5)  # columns of buf
NSUM = 5
IAX, IAY, IVX, IVY = range(4)  # columns of nodal
IMU, ILAM, IDT, IFLIP = range(4)  # consts
IOUT, INEED, IBAD = range(3)  # columns of flags


class Line(NamedTuple):
    """One axis as the passes read it: the 1D line's ``nodes`` (n,), ``h`` (2, n - 1) its cell sizes
    and their inverses, ``inv_spacing`` (``1/h`` on a line uniform to round-off, else 0), ``wrap``
    (n,) the axis node of each line node, and the fold ``lo``, ``length``, ``periodic``."""

    nodes: np.ndarray
    h: np.ndarray
    inv_spacing: float
    wrap: np.ndarray
    lo: float
    length: float
    periodic: bool


class Cloud(NamedTuple):
    """The particle arrays of :class:`~mpm_fem.plane.state.PlaneParticles` the passes read or write."""

    x: np.ndarray
    v: np.ndarray
    F: np.ndarray
    volume: np.ndarray
    volume0: np.ndarray
    mass: np.ndarray
    lengths: np.ndarray


@njit(cache=True, inline="always")
def _fold(x, lo, length, inv_length, periodic):
    """:meth:`mpm_fem.plane.grid.Axis.fold` of one coordinate to round-off, ``x - L floor((x - lo)/L)``
    (no ``fmod``): it may land a round-off outside ``[lo, hi)``, inside the padded line."""
    if periodic:
        return x - length * np.floor((x - lo) * inv_length)
    return x


@njit(cache=True, inline="always")
def _stress(F00, F01, F10, F11, mu, lam, V):
    """``V sigma`` of one particle (:func:`mpm_fem.plane.model.neo_hookean_stress` times the volume ``V``,
    one division): ``V sigma_00, V sigma_01, V sigma_11``."""
    J = F00 * F11 - F01 * F10
    log_J = lam * np.log(J)
    w = V / J
    B00 = F00 * F00 + F01 * F01 - 1.0
    B01 = F00 * F10 + F01 * F11
    B11 = F10 * F10 + F11 * F11 - 1.0
    return w * (mu * B00 + log_J), w * (mu * B01), w * (mu * B11 + log_J)


def _project(ax, ay, n_y, old, b, consts, chunks, buf, flags):
    """Pass 1 (module docstring) into ``buf[k]`` for chunk k; ``b`` (n_p, 2) the body force per unit mass."""
    x_nodes = ax.nodes
    x_h = ax.h
    x_inv = ax.inv_spacing
    x_wrap = ax.wrap
    x_lo = ax.lo
    x_len = ax.length
    x_per = ax.periodic
    x_inv_len = 1.0 / x_len
    y_nodes = ay.nodes
    y_h = ay.h
    y_inv = ay.inv_spacing
    y_wrap = ay.wrap
    y_lo = ay.lo
    y_len = ay.length
    y_per = ay.periodic
    y_inv_len = 1.0 / y_len
    x = old.x
    v = old.v
    F = old.F
    vol = old.volume
    m = old.mass
    lengths = old.lengths
    mu = consts[IMU]
    lam = consts[ILAM]
    n = x.shape[0]
    xa, xb = x_nodes[0], x_nodes[x_nodes.size - 1]
    ya, yb = y_nodes[0], y_nodes[y_nodes.size - 1]
    for k in prange(chunks):
        rx, Sx, Gx = np.empty(K, np.intp), np.empty(K), np.empty(K)
        ry, Sy, Gy = np.empty(K, np.intp), np.empty(K), np.empty(K)
        outside, need = -1, 0
        lo, hi = _chunk(n, chunks, k)
        for q in range(lo, hi):
            px = _fold(x[q, 0], x_lo, x_len, x_inv_len, x_per)
            py = _fold(x[q, 1], y_lo, y_len, y_inv_len, y_per)
            if not (px >= xa and px <= xb and py >= ya and py <= yb):  # NaN too
                if outside < 0:
                    outside = q
                continue
            _, need_x = ROW(x_nodes, x_h, x_inv, px, lengths[q, 0], rx, Sx, Gx)
            _, need_y = ROW(y_nodes, y_h, y_inv, py, lengths[q, 1], ry, Sy, Gy)
            need = max(need, need_x, need_y)
            s00, s01, s11 = _stress(F[q, 0, 0], F[q, 0, 1], F[q, 1, 0], F[q, 1, 1], mu, lam, vol[q])
            mq = m[q]
            mvx, mvy = mq * v[q, 0], mq * v[q, 1]
            mbx, mby = mq * b[q, 0], mq * b[q, 1]
            for a in range(K):
                row = x_wrap[rx[a]] * n_y
                for c in range(K):
                    i = row + y_wrap[ry[c]]
                    S = Sx[a] * Sy[c]
                    G0 = Gx[a] * Sy[c]
                    G1 = Sx[a] * Gy[c]
                    buf[k, i, IM] += S * mq
                    buf[k, i, IPX] += S * mvx
                    buf[k, i, IPY] += S * mvy
                    buf[k, i, IFX] += S * mbx - (s00 * G0 + s01 * G1)
                    buf[k, i, IFY] += S * mby - (s01 * G0 + s11 * G1)
        flags[k, IOUT] = outside
        flags[k, INEED] = need


def _solve(buf, dt, mass, velocity, nodal):
    """The grid pass (module docstring): the chunks' sums added in chunk order, ``mass`` (n_nodes,),
    ``velocity`` ``v_i`` (n_nodes, 2) and ``nodal`` written; ``buf`` zeroed."""
    chunks = buf.shape[0]
    for i in prange(mass.size):
        m, px, py, fx, fy = buf[0, i, IM], buf[0, i, IPX], buf[0, i, IPY], buf[0, i, IFX], buf[0, i, IFY]
        for k in range(1, chunks):
            m += buf[k, i, IM]
            px += buf[k, i, IPX]
            py += buf[k, i, IPY]
            fx += buf[k, i, IFX]
            fy += buf[k, i, IFY]
        for k in range(chunks):
            for j in range(NSUM):
                buf[k, i, j] = 0.0
        vx = vy = ax = ay = 0.0
        if m > 0:
            vx, vy, ax, ay = px / m, py / m, fx / m, fy / m
        mass[i] = m
        velocity[i, 0], velocity[i, 1] = vx, vy
        nodal[i, IAX], nodal[i, IAY] = ax, ay
        nodal[i, IVX], nodal[i, IVY] = vx + dt * ax, vy + dt * ay


def _move(ax, ay, n_y, old, new, nodal, consts, chunks, flags):
    """Pass 2 (module docstring): ``old`` into ``new``'s ``x``, ``v``, ``F``, ``volume``."""
    x_nodes = ax.nodes
    x_h = ax.h
    x_inv = ax.inv_spacing
    x_wrap = ax.wrap
    x_lo = ax.lo
    x_len = ax.length
    x_per = ax.periodic
    x_inv_len = 1.0 / x_len
    y_nodes = ay.nodes
    y_h = ay.h
    y_inv = ay.inv_spacing
    y_wrap = ay.wrap
    y_lo = ay.lo
    y_len = ay.length
    y_per = ay.periodic
    y_inv_len = 1.0 / y_len
    x = old.x
    v = old.v
    F = old.F
    V0 = old.volume0
    lengths = old.lengths
    x_new = new.x
    v_new = new.v
    F_new = new.F
    vol_new = new.volume
    dt = consts[IDT]
    flip = consts[IFLIP]
    n = x.shape[0]
    for k in prange(chunks):
        rx, Sx, Gx = np.empty(K, np.intp), np.empty(K), np.empty(K)
        ry, Sy, Gy = np.empty(K, np.intp), np.empty(K), np.empty(K)
        bad = -1
        lo, hi = _chunk(n, chunks, k)
        for q in range(lo, hi):
            px = _fold(x[q, 0], x_lo, x_len, x_inv_len, x_per)
            py = _fold(x[q, 1], y_lo, y_len, y_inv_len, y_per)
            ROW(x_nodes, x_h, x_inv, px, lengths[q, 0], rx, Sx, Gx)
            ROW(y_nodes, y_h, y_inv, py, lengths[q, 1], ry, Sy, Gy)
            acc_x = acc_y = vel_x = vel_y = L00 = L01 = L10 = L11 = 0.0
            for a in range(K):
                row = x_wrap[rx[a]] * n_y
                for c in range(K):
                    i = row + y_wrap[ry[c]]
                    S = Sx[a] * Sy[c]
                    G0 = Gx[a] * Sy[c]
                    G1 = Sx[a] * Gy[c]
                    vx, vy = nodal[i, IVX], nodal[i, IVY]
                    acc_x += S * nodal[i, IAX]
                    acc_y += S * nodal[i, IAY]
                    vel_x += S * vx
                    vel_y += S * vy
                    L00 += vx * G0
                    L01 += vx * G1
                    L10 += vy * G0
                    L11 += vy * G1
            v_new[q, 0] = flip * (v[q, 0] + dt * acc_x) + (1.0 - flip) * vel_x
            v_new[q, 1] = flip * (v[q, 1] + dt * acc_y) + (1.0 - flip) * vel_y
            x_new[q, 0] = x[q, 0] + dt * vel_x
            x_new[q, 1] = x[q, 1] + dt * vel_y
            F00, F01, F10, F11 = F[q, 0, 0], F[q, 0, 1], F[q, 1, 0], F[q, 1, 1]
            G00 = F00 + dt * (L00 * F00 + L01 * F10)
            G01 = F01 + dt * (L00 * F01 + L01 * F11)
            G10 = F10 + dt * (L10 * F00 + L11 * F10)
            G11 = F11 + dt * (L10 * F01 + L11 * F11)
            F_new[q, 0, 0], F_new[q, 0, 1], F_new[q, 1, 0], F_new[q, 1, 1] = G00, G01, G10, G11
            J = G00 * G11 - G01 * G10
            vol_new[q] = J * V0[q]
            if not (J > 0.0) and bad < 0:
                bad = q
        flags[k, IBAD] = bad
