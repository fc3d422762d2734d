"""Pass 2 and the passes around it.

Pass 2 (:func:`_move`), with ``S_ip``, ``G_ip`` at ``x_p^n`` (recomputed, or read back where pass 1
stored them):

    v_p <- v_p + dt sum_i S_ip a_i,    x_p <- x_p + dt sum_i S_ip v_i^{n+1},    L_p = sum_i G_ip v_i^{n+1},

then (USL) the model's update from ``L_p`` (:mod:`mpm_fem.fused.models`), the signal speed and the
checks; the PIC/FLIP blend and XPIC replace the velocity's update, MUSL re-projects the momentum
(``P_i = sum_p m_p v_p^{n+1} S_ip``) and updates the state in :func:`_finish`. USF updates the state
before the force (:func:`_update`); :func:`_scatter_pass` makes the forces that need a pass of their
own (Burgers' viscous stress, the gas force of a reset volume) and XPIC's momentum. With the exact
interpolation, :func:`_move_exact` and :func:`_update_exact` take pass 2's place. Every sum is taken
in the numpy step's order (:mod:`mpm_fem.fused.sums`). ``BASIS``, ``MODEL``, ``WIDTH``, ``WEIGHT`` and
``ROW`` are compile-time globals of each variant (:mod:`mpm_fem.fused.compiler`).
"""

import numpy as np
from numba import njit, prange

from mpm_fem.fused.basis import _bspline_nearest, _point, _scaled
from mpm_fem.fused.codes import (
    BSPLINE,
    BSPLINE_GIMP,
    GAS,
    GIMP,
    IEPS,
    IFLIP,
    IGGM1,
    IXPIC,
    POINT,
    PRESSURE,
    VISCOUS_STRESS,
)
from mpm_fem.fused.models import _NO_TALLY, _checked, _flags, _new_state
from mpm_fem.fused.sums import _chunk, _gather, _gather_stored, _one_row, _scatter, _scatter_stored, _sum_chunks

BASIS = MODEL = WIDTH = WEIGHT = ROW = None  # placeholders: each variant has its own (mpm_fem.fused.compiler)


def _scatter_pass(nodes, h, inv_spacing, x, rows, S, G, cell, f_i, a, b, coef, chunks, out):
    """One scatter over the particles, ``out_i = sum_p w_p W_ip`` (each particle's row recomputed or
    read as in pass 2), with the weight the compile-time ``WEIGHT`` picks:

        PRESSURE         W = G_ip, w_p = a_p b_p:                  the gas force ``F_i = sum_p V_p p_p G_ip``
                                                                   (after the volume reset)
        VISCOUS_STRESS   W = G_ip, w_p = a_p (coef sum_j G_jp f_j), ``out = -sum``: Burgers' force
                         ``F_i = - sum_p V_p eps (dv/dx)_p G_ip`` (its stress before the force)
        MOMENTUM         W = S_ip, w_p = a_p sum_j S_jp f_j:        XPIC's ``P_i = sum_p S_ip m_p (sum_j S_jp u_j)``
                         (:func:`mpm_fem.core.transfer.nodal_momentum` of ``shape.gather(u)``)

    (``b``, ``coef``, ``f_i``: unused where the weight does not name them)."""
    n = x.size
    K = WIDTH  # nodes per particle
    buf = np.zeros((chunks, 1, out.size))
    for k in prange(chunks):
        r, Sl, Gl = _one_row(K)
        for q in range(*_chunk(n, chunks, k)):
            # the domain bases: pass 1's stored row read in place (the same sums as a copy into the row scratch)
            if BASIS == GIMP or BASIS == BSPLINE_GIMP:
                if WEIGHT == PRESSURE:
                    _scatter_stored(buf, k, rows, q, G, a[q] * b[q], K)
                elif WEIGHT == VISCOUS_STRESS:
                    _scatter_stored(buf, k, rows, q, G, a[q] * (coef * _gather_stored(G, q, f_i, rows, K)), K)
                else:
                    _scatter_stored(buf, k, rows, q, S, a[q] * _gather_stored(S, q, f_i, rows, K), K)
                continue
            ROW(BASIS, nodes, h, inv_spacing, x, q, rows, S, G, cell, r, Sl, Gl)
            if WEIGHT == PRESSURE:
                _scatter(buf, k, r, Gl, a[q] * b[q], K)
            elif WEIGHT == VISCOUS_STRESS:
                _scatter(buf, k, r, Gl, a[q] * (coef * _gather(Gl, f_i, r, K)), K)
            else:
                _scatter(buf, k, r, Sl, a[q] * _gather(Sl, f_i, r, K), K)
    _sum_chunks(buf, 0, out, -1.0 if WEIGHT == VISCOUS_STRESS else 1.0)


def _update(nodes, h, inv_spacing, x, rows, S, G, cell, v_i, V, m, rho, e, p, dt, consts, force, chunks,
            V_new, m_new, rho_new, e_new, p_new, F_i, flags, values):
    """USF: the model's state update from ``L_p = sum_i G_ip v_i`` before the force, and the force
    of the updated state into ``F_i`` (if ``force``). ``flags[k] = (first particle with factor <= 0,
    first with energy <= 0)``, ``values[k]`` their values."""
    n = x.size
    K = WIDTH  # nodes per particle
    gas, eps = MODEL == GAS, consts[IEPS]
    buf = np.zeros((chunks, 1, F_i.size))
    for k in prange(chunks):
        tally = _NO_TALLY
        r, Sl, Gl = _one_row(K)
        for q in range(*_chunk(n, chunks, k)):
            c = ROW(BASIS, nodes, h, inv_spacing, x, q, rows, S, G, cell, r, Sl, Gl)
            L = _gather(Gl, v_i, r, K)
            tally = _new_state(gas, q, L, dt, h[0, c], V, m, rho, e, p, V_new, m_new, rho_new, e_new, p_new, consts,
                               tally)
            if force:
                _scatter(buf, k, r, Gl, V_new[q] * p_new[q] if gas else -(V_new[q] * (eps * L)), K)
        _flags(k, tally, flags, values)
    if force:
        _sum_chunks(buf, 0, F_i, 1.0)


@njit(cache=True, inline="always")
def _move_point(nodes, h, inv_spacing, a_i, v_n, x, V, m, v, rho, e, p, dt, consts, gas, lo, hi,
                x_new, v_new, V_new, m_new, rho_new, e_new, p_new, tally):
    """Pass 2 of the point mass, USL, over particles ``lo .. hi-1``: :func:`_move`'s arithmetic with
    the row ``(c, c + 1)``, ``(1 - xi, xi)``, ``(-1, 1)/h_c`` held in registers. Returns the tally."""
    for q in range(lo, hi):
        c, xi, inv_h = _point(nodes, h, inv_spacing, x[q])
        S0 = 1.0 - xi
        v_new[q] = v[q] + dt * (S0 * a_i[c] + xi * a_i[c + 1])
        x_new[q] = x[q] + dt * (S0 * v_n[c] + xi * v_n[c + 1])
        L = -inv_h * v_n[c] + inv_h * v_n[c + 1]
        tally = _new_state(gas, q, L, dt, h[0, c], V, m, rho, e, p, V_new, m_new, rho_new, e_new, p_new, consts, tally)
        tally = _checked(gas, q, tally[6], x_new, v_new, rho_new, e_new, p_new, V_new, tally)
    return tally


@njit(cache=True, inline="always")
def _move_bspline(nodes, h, inv_spacing, a_i, v_n, x, V, m, v, rho, e, p, dt, consts, gas, lo, hi,
                  x_new, v_new, V_new, m_new, rho_new, e_new, p_new, tally):
    """Pass 2 of the B-spline on a uniform grid, USL, over particles ``lo .. hi-1``: :func:`_move`'s
    arithmetic with the row of :func:`~mpm_fem.fused.basis._bspline_nearest` in registers. Returns the tally."""
    top = nodes.size - 1
    for q in range(lo, hi):
        s, c = _scaled(nodes, inv_spacing, x[q])
        n, t, w_l, w_0, w_r = _bspline_nearest(s, top)
        i_l, i_r = max(n - 1, 0), min(n + 1, top)
        v_new[q] = v[q] + dt * (w_l * a_i[i_l] + w_0 * a_i[n] + w_r * a_i[i_r])
        x_new[q] = x[q] + dt * (w_l * v_n[i_l] + w_0 * v_n[n] + w_r * v_n[i_r])
        L = ((t - 0.5) * inv_spacing) * v_n[i_l] + ((-2.0 * t) * inv_spacing) * v_n[n] \
            + ((t + 0.5) * inv_spacing) * v_n[i_r]
        tally = _new_state(gas, q, L, dt, h[0, c], V, m, rho, e, p, V_new, m_new, rho_new, e_new, p_new, consts, tally)
        tally = _checked(gas, q, tally[6], x_new, v_new, rho_new, e_new, p_new, V_new, tally)
    return tally


def _move(nodes, h, inv_spacing, rows, S, G, cell, a_i, v_n, x, V, m, v, rho, e, p, dt, consts, usl, musl, chunks,
          x_new, v_new, V_new, m_new, rho_new, e_new, p_new, P_i, flags, values, speed):
    """Pass 2: ``v_p += dt sum S a``, ``x_p += dt sum S v^{n+1}``; USL: the state update from
    ``L_p = sum G v^{n+1}``; MUSL: ``P_i = sum_p m_p v_p^{n+1} S_ip``. The blend ``consts[IFLIP]``
    (FLIP 1) mixes in ``sum S v^{n+1}``; with ``consts[IXPIC] > 0`` (XPIC) ``a_i`` holds ``v* + dt a``
    and ``v_p = sum S a_i``. ``speed[k]``: max of
    ``c_p + |v_p|`` (gas) or ``|v_p|`` (Burgers) over chunk k; ``flags[k] = (first bad factor,
    first bad energy, first non-finite particle)``."""
    n = x.size
    K = WIDTH  # nodes per particle
    gas, g_gm1 = MODEL == GAS, consts[IGGM1]
    flip = consts[IFLIP] if consts.size > IFLIP else 1.0  # the PIC/FLIP blend (a shorter consts: FLIP)
    pic = consts.size > IXPIC and consts[IXPIC] > 0  # XPIC: a_i holds v* + dt a
    buf = np.zeros((chunks if musl else 1, 1, P_i.size))
    for k in prange(chunks):
        tally = _NO_TALLY
        r, Sl, Gl = _one_row(K)
        lo, hi = _chunk(n, chunks, k)
        if BASIS == POINT and usl and flip == 1.0 and not pic:  # point mass, USL, FLIP: its own loop, the row in
            # registers (the loop below then skipped)
            tally = _move_point(nodes, h, inv_spacing, a_i, v_n, x, V, m, v, rho, e, p, dt, consts, gas, lo, hi,
                                x_new, v_new, V_new, m_new, rho_new, e_new, p_new, tally)
            lo = hi
        if BASIS == BSPLINE and inv_spacing > 0.0 and usl and flip == 1.0 and not pic:  # the B-spline on a uniform
            # grid, likewise
            tally = _move_bspline(nodes, h, inv_spacing, a_i, v_n, x, V, m, v, rho, e, p, dt, consts, gas, lo, hi,
                                  x_new, v_new, V_new, m_new, rho_new, e_new, p_new, tally)
            lo = hi
        for q in range(lo, hi):
            # the domain bases: pass 1's stored row read in place, and USL's L_p (_gather's sum) in the same loop
            if BASIS == GIMP or BASIS == BSPLINE_GIMP:
                cq = cell[q]
                i = rows[q, 0]
                acc, vel, L = S[q, 0] * a_i[i], S[q, 0] * v_n[i], G[q, 0] * v_n[i]
                for j in range(1, K):
                    i = rows[q, j]
                    acc += S[q, j] * a_i[i]
                    vel += S[q, j] * v_n[i]
                    L += G[q, j] * v_n[i]
            else:
                cq = ROW(BASIS, nodes, h, inv_spacing, x, q, rows, S, G, cell, r, Sl, Gl)
                acc = Sl[0] * a_i[r[0]]
                vel = Sl[0] * v_n[r[0]]
                for j in range(1, K):
                    acc += Sl[j] * a_i[r[j]]
                    vel += Sl[j] * v_n[r[j]]
            if pic:
                v_new[q] = acc
            else:
                v_new[q] = v[q] + dt * acc
                if flip != 1.0:
                    v_new[q] = flip * v_new[q] + (1.0 - flip) * vel
            x_new[q] = x[q] + dt * vel
            if musl:
                if BASIS == GIMP or BASIS == BSPLINE_GIMP:
                    _scatter_stored(buf, k, rows, q, S, m[q] * v_new[q], K)
                else:
                    _scatter(buf, k, r, Sl, m[q] * v_new[q], K)
                continue
            if usl:
                if BASIS != GIMP and BASIS != BSPLINE_GIMP:
                    L = _gather(Gl, v_n, r, K)
                tally = _new_state(gas, q, L, dt, h[0, cq], V, m, rho, e, p,
                                   V_new, m_new, rho_new, e_new, p_new, consts, tally)
                c = tally[6]
            else:
                c = np.sqrt(g_gm1 * max(e_new[q], 0.0)) if gas else 0.0
            tally = _checked(gas, q, c, x_new, v_new, rho_new, e_new, p_new, V_new, tally)
        speed[k] = _flags(k, tally, flags, values)
    if musl:
        _sum_chunks(buf, 0, P_i, 1.0)


def _finish(nodes, h, inv_spacing, x, rows, S, G, cell, v_n, V, m, v, rho, e, p, dt, consts, chunks,
            V_new, m_new, rho_new, e_new, p_new, x_new, flags, values, speed):
    """MUSL's last pass: the state update from ``L_p = sum_i G_ip v_i^{n+1}`` (re-projected; the
    shape at ``x_p^n``), the speed and the checks, as in :func:`_move`."""
    n = x.size
    K = WIDTH  # nodes per particle
    gas = MODEL == GAS
    for k in prange(chunks):
        r, Sl, Gl = _one_row(K)
        tally = _NO_TALLY
        for q in range(*_chunk(n, chunks, k)):
            cq = ROW(BASIS, nodes, h, inv_spacing, x, q, rows, S, G, cell, r, Sl, Gl)
            tally = _new_state(gas, q, _gather(Gl, v_n, r, K), dt, h[0, cq], V, m, rho, e, p,
                               V_new, m_new, rho_new, e_new, p_new, consts, tally)
            tally = _checked(gas, q, tally[6], x_new, v, rho_new, e_new, p_new, V_new, tally)
        speed[k] = _flags(k, tally, flags, values)


def _move_exact(nodes, h, inv_spacing, rows, S, G, cell, a_c, v_c, p_v, p_a, x, v, dt, chunks, x_new, v_new, L_c):
    """Pass 2 of a step with the exact interpolation (:func:`mpm_fem.core.step.explicit_step`), before its
    state update: with ``a_c = a_i - a*_i`` and ``v_c = v_i^{n+1} - v*_i^{n+1}`` (the nodal values
    less the exact ones, the boundary rule applied to both) and ``p_v = v*(x_p^n)``, ``p_a = a*(x_p^n)``,

        v_p <- v_p + dt (p_a + sum_i S_ip a_c,i),
        x_p <- x_p + dt ((p_v + dt p_a) + sum_i S_ip v_c,i),       L_c,p = sum_i G_ip v_c,i,

    the numpy step's operations in its order (``L_p = v*_x(x_p^{n+1}, t + dt) + L_c,p`` follows)."""
    n = x.size
    K = WIDTH  # nodes per particle
    for k in prange(chunks):
        r, Sl, Gl = _one_row(K)
        for q in range(*_chunk(n, chunks, k)):
            ROW(BASIS, nodes, h, inv_spacing, x, q, rows, S, G, cell, r, Sl, Gl)
            acc = p_a[q] + _gather(Sl, a_c, r, K)
            moving = p_v[q] + dt * p_a[q] + _gather(Sl, v_c, r, K)
            v_new[q] = v[q] + dt * acc
            x_new[q] = x[q] + dt * moving
            L_c[q] = _gather(Gl, v_c, r, K)


def _update_exact(h, cell, L, x_new, v_new, V, m, rho, e, p, dt, consts, chunks, V_new, m_new, rho_new, e_new,
                  p_new, flags, values, speed):
    """The state update of :func:`_move_exact`'s particles from their ``L_p`` (USL, the cell of
    ``x_p^n``), with pass 2's checks: ``speed[k]``, ``flags[k]``, ``values[k]`` as :func:`_move`'s."""
    n = x_new.size
    gas = MODEL == GAS
    for k in prange(chunks):
        tally = _NO_TALLY
        for q in range(*_chunk(n, chunks, k)):
            tally = _new_state(gas, q, L[q], dt, h[0, cell[q]], V, m, rho, e, p, V_new, m_new, rho_new, e_new, p_new,
                               consts, tally)
            tally = _checked(gas, q, tally[6], x_new, v_new, rho_new, e_new, p_new, V_new, tally)
        speed[k] = _flags(k, tally, flags, values)

