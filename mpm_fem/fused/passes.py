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
in the numpy step's order (:mod:`mpm_fem.fused.sums`). ``MODEL``, ``WIDTH``, ``WEIGHT`` and the
basis's pieces are compile-time globals of each variant (:mod:`mpm_fem.fused.compiler`): ``ROW``
(a particle's row after pass 1, :class:`mpm_fem.bases.contract.Kernels`' ``pass_row``), ``STORED``
(1: the basis's rows are pass 1's stored ones, read in place), ``REGISTERS`` (1: the basis gives
pass 2's sums with its row in registers, ``MOVE_RUN``) and ``ANY_GRID`` (that function serves any
grid, else a grid uniform to round-off).

The arguments travel as named tuples: ``g`` the grid (:class:`~mpm_fem.bases.contract.Geometry`),
``store`` pass 1's rows and cells (:class:`~mpm_fem.bases.contract.RowStore`), ``old`` and ``new``
the particles' state read and written (:class:`~mpm_fem.fused.models.ParticleState`), ``checks``
the per-chunk flags, values and speeds (:class:`~mpm_fem.fused.models.Checks`). Each pass takes
their arrays out by attribute before its ``prange``, whose body never reaches an array through a
tuple: numba 0.68's parallel variants lose writes to an array reached through a tuple inside the
``prange`` body, and to some arrays taken out of a tuple by unpacking (``flags, values, speed =
checks`` lost the writes to ``speed``) where the attribute works (numba/numba#5872, #7135, #10338;
``docs/performance.md``; the two-thread tests compare every pass with one thread).
"""

import numpy as np
from numba import prange

from mpm_fem.fused.codes import GAS, IEPS, IFLIP, IGGM1, IXPIC, MUSL, PRESSURE, USL, VISCOUS_STRESS
from mpm_fem.fused.models import _NO_TALLY, _checked, _flags, _new_state, _store
from mpm_fem.fused.sums import _chunk, _gather, _gather_stored, _one_row, _scatter, _scatter_stored, _sum_chunks

# placeholders: each variant has its own (mpm_fem.fused.compiler)
MODEL = WIDTH = WEIGHT = ROW = STORED = REGISTERS = ANY_GRID = MOVE_RUN = None


def _scatter_pass(g, x, store, f_i, a, b, coef, chunks, out):
    """One scatter over the particles at ``x``, ``out_i = sum_p w_p W_ip`` (each particle's row
    recomputed or read as in pass 2), with the weight the compile-time ``WEIGHT`` picks:

        PRESSURE         W = G_ip, w_p = a_p b_p:                  the gas force ``F_i = sum_p V_p p_p G_ip``
                                                                   (after the volume reset)
        VISCOUS_STRESS   W = G_ip, w_p = a_p (coef sum_j G_jp f_j), ``out = -sum``: Burgers' force
                         ``F_i = - sum_p V_p eps (dv/dx)_p G_ip`` (its stress before the force)
        MOMENTUM         W = S_ip, w_p = a_p sum_j S_jp f_j:        XPIC's ``P_i = sum_p S_ip m_p (sum_j S_jp u_j)``
                         (:func:`mpm_fem.core.transfer.nodal_momentum` of ``shape.gather(u)``)

    (``b``, ``coef``, ``f_i``: unused where the weight does not name them)."""
    nodes = g.nodes
    h = g.h
    inv_spacing = g.inv_spacing
    rows = store.rows
    S = store.S
    G = store.G
    cell = store.cell
    n = x.size
    K = WIDTH  # nodes per particle
    buf = np.zeros((chunks, 1, out.size))
    for k in prange(chunks):
        r, Sl, Gl = _one_row(K)
        for q in range(*_chunk(n, chunks, k)):
            # stored rows: pass 1's row read in place (the same sums as a copy into the row scratch)
            if STORED == 1:
                if WEIGHT == PRESSURE:
                    _scatter_stored(buf, k, rows, q, G, a[q] * b[q], K)
                elif WEIGHT == VISCOUS_STRESS:
                    _scatter_stored(buf, k, rows, q, G, a[q] * (coef * _gather_stored(G, q, f_i, rows, K)), K)
                else:
                    _scatter_stored(buf, k, rows, q, S, a[q] * _gather_stored(S, q, f_i, rows, K), K)
                continue
            ROW(nodes, h, inv_spacing, x, q, rows, S, G, cell, r, Sl, Gl)
            if WEIGHT == PRESSURE:
                _scatter(buf, k, r, Gl, a[q] * b[q], K)
            elif WEIGHT == VISCOUS_STRESS:
                _scatter(buf, k, r, Gl, a[q] * (coef * _gather(Gl, f_i, r, K)), K)
            else:
                _scatter(buf, k, r, Sl, a[q] * _gather(Sl, f_i, r, K), K)
    _sum_chunks(buf, 0, out, -1.0 if WEIGHT == VISCOUS_STRESS else 1.0)


def _update(g, store, v_i, old, dt, consts, force, chunks, new, F_i, checks):
    """USF: the model's state update from ``L_p = sum_i G_ip v_i`` before the force (rows at
    ``old.x``; ``new``'s V, m, rho, eps, p written), and the force of the updated state into ``F_i``
    (if ``force``). ``checks.flags[k] = (first particle with factor <= 0, first with energy <= 0)``,
    ``checks.values[k]`` their values."""
    nodes = g.nodes
    h = g.h
    inv_spacing = g.inv_spacing
    rows = store.rows
    S = store.S
    G = store.G
    cell = store.cell
    # one array a statement: a tuple's arrays unpacked together lose their writes in the prange (docstring)
    x = old.x
    V = old.V
    m = old.m
    rho = old.rho
    e = old.e
    p = old.p
    V_new = new.V
    m_new = new.m
    rho_new = new.rho
    e_new = new.e
    p_new = new.p
    flags = checks.flags
    values = checks.values
    speed = checks.speed
    n = x.size
    K = WIDTH  # nodes per particle
    gas, eps = MODEL == GAS, consts[IEPS]
    buf = np.zeros((chunks, 1, F_i.size))
    for k in prange(chunks):
        tally = _NO_TALLY
        r, Sl, Gl = _one_row(K)
        for q in range(*_chunk(n, chunks, k)):
            c = ROW(nodes, h, inv_spacing, x, q, rows, S, G, cell, r, Sl, Gl)
            L = _gather(Gl, v_i, r, K)
            tally = _new_state(gas, q, L, dt, h[0, c], rho[q], e[q], p[q], m[q], V[q], consts, tally)
            _store(gas, q, tally, V_new, m_new, rho_new, e_new, p_new)
            if force:
                _scatter(buf, k, r, Gl, V_new[q] * p_new[q] if gas else -(V_new[q] * (eps * L)), K)
        _flags(k, tally, flags, values, speed)
    if force:
        _sum_chunks(buf, 0, F_i, 1.0)


def _move(g, store, a_i, v_n, old, new, dt, consts, scheme, chunks, P_i, checks):
    """Pass 2 from the rows at ``old.x``: ``new.v = old.v + dt sum S a``, ``new.x = old.x + dt sum S
    v^{n+1}``; USL (``scheme``, :mod:`mpm_fem.fused.codes`): the state update from
    ``L_p = sum G v^{n+1}``, ``old`` into ``new``; MUSL: ``P_i = sum_p m_p v_p^{n+1} S_ip``. The blend
    ``consts[IFLIP]`` (FLIP 1) mixes in ``sum S v^{n+1}``; with ``consts[IXPIC] > 0`` (XPIC) ``a_i``
    holds ``v* + dt a`` and ``v_p = sum S a_i``. ``checks.speed[k]``: max of ``c_p + |v_p|`` (gas) or
    ``|v_p|`` (Burgers) over chunk k; ``checks.flags[k] = (first bad factor, first bad energy, first
    non-finite particle)``."""
    nodes = g.nodes
    h = g.h
    inv_spacing = g.inv_spacing
    rows = store.rows
    S = store.S
    G = store.G
    cell = store.cell
    # one array a statement: a tuple's arrays unpacked together lose their writes in the prange (docstring)
    x = old.x
    v = old.v
    V = old.V
    m = old.m
    rho = old.rho
    e = old.e
    p = old.p
    x_new = new.x
    v_new = new.v
    V_new = new.V
    m_new = new.m
    rho_new = new.rho
    e_new = new.e
    p_new = new.p
    flags = checks.flags
    values = checks.values
    speed = checks.speed
    n = x.size
    K = WIDTH  # nodes per particle
    usl, musl = scheme == USL, scheme == MUSL
    gas, g_gm1 = MODEL == GAS, consts[IGGM1]
    flip = consts[IFLIP] if consts.size > IFLIP else 1.0  # the PIC/FLIP blend (a shorter consts: FLIP)
    pic = consts.size > IXPIC and consts[IXPIC] > 0  # XPIC: a_i holds v* + dt a
    buf = np.zeros((chunks if musl else 1, 1, P_i.size))
    for k in prange(chunks):
        tally = _NO_TALLY
        r, Sl, Gl = _one_row(K)
        lo, hi = _chunk(n, chunks, k)
        if REGISTERS == 1:  # USL, FLIP: the basis's sums with the row in registers (the loop below then skipped)
            if (ANY_GRID == 1 or inv_spacing > 0.0) and usl and flip == 1.0 and not pic:
                for q in range(lo, hi):
                    c, acc, vel, L = MOVE_RUN(nodes, h, inv_spacing, x[q], a_i, v_n)
                    v_new[q] = v[q] + dt * acc
                    x_new[q] = x[q] + dt * vel
                    tally = _new_state(gas, q, L, dt, h[0, c], rho[q], e[q], p[q], m[q], V[q], consts, tally)
                    _store(gas, q, tally, V_new, m_new, rho_new, e_new, p_new)
                    tally = _checked(gas, q, tally.sound_speed, x_new, v_new, rho_new, e_new, p_new, V_new, tally)
                lo = hi
        for q in range(lo, hi):
            # stored rows: pass 1's row read in place, and USL's L_p (_gather's sum) in the same loop
            if STORED == 1:
                cq = cell[q]
                i = rows[q, 0]
                acc, vel, L = S[q, 0] * a_i[i], S[q, 0] * v_n[i], G[q, 0] * v_n[i]
                for j in range(1, K):
                    i = rows[q, j]
                    acc += S[q, j] * a_i[i]
                    vel += S[q, j] * v_n[i]
                    L += G[q, j] * v_n[i]
            else:
                cq = ROW(nodes, h, inv_spacing, x, q, rows, S, G, cell, r, Sl, Gl)
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
                if STORED == 1:
                    _scatter_stored(buf, k, rows, q, S, m[q] * v_new[q], K)
                else:
                    _scatter(buf, k, r, Sl, m[q] * v_new[q], K)
                continue
            if usl:
                if STORED == 0:
                    L = _gather(Gl, v_n, r, K)
                tally = _new_state(gas, q, L, dt, h[0, cq], rho[q], e[q], p[q], m[q], V[q], consts, tally)
                _store(gas, q, tally, V_new, m_new, rho_new, e_new, p_new)
                c = tally.sound_speed
            else:
                c = np.sqrt(g_gm1 * max(e_new[q], 0.0)) if gas else 0.0
            tally = _checked(gas, q, c, x_new, v_new, rho_new, e_new, p_new, V_new, tally)
        _flags(k, tally, flags, values, speed)
    if musl:
        _sum_chunks(buf, 0, P_i, 1.0)


def _finish(g, store, v_n, old, new, dt, consts, chunks, checks):
    """MUSL's last pass: the state update from ``L_p = sum_i G_ip v_i^{n+1}`` (re-projected; the
    shape at ``old.x``, ``x_p^n``), ``old`` into ``new`` (whose x and v pass 2 wrote), the speed and
    the checks, as in :func:`_move`."""
    nodes = g.nodes
    h = g.h
    inv_spacing = g.inv_spacing
    rows = store.rows
    S = store.S
    G = store.G
    cell = store.cell
    # one array a statement: a tuple's arrays unpacked together lose their writes in the prange (docstring)
    x = old.x
    V = old.V
    m = old.m
    rho = old.rho
    e = old.e
    p = old.p
    x_new = new.x
    v_new = new.v
    V_new = new.V
    m_new = new.m
    rho_new = new.rho
    e_new = new.e
    p_new = new.p
    flags = checks.flags
    values = checks.values
    speed = checks.speed
    n = x.size
    K = WIDTH  # nodes per particle
    gas = MODEL == GAS
    for k in prange(chunks):
        r, Sl, Gl = _one_row(K)
        tally = _NO_TALLY
        for q in range(*_chunk(n, chunks, k)):
            cq = ROW(nodes, h, inv_spacing, x, q, rows, S, G, cell, r, Sl, Gl)
            L = _gather(Gl, v_n, r, K)
            tally = _new_state(gas, q, L, dt, h[0, cq], rho[q], e[q], p[q], m[q], V[q], consts, tally)
            _store(gas, q, tally, V_new, m_new, rho_new, e_new, p_new)
            tally = _checked(gas, q, tally.sound_speed, x_new, v_new, rho_new, e_new, p_new, V_new, tally)
        _flags(k, tally, flags, values, speed)


def _move_exact(g, store, a_c, v_c, p_v, p_a, old, new, dt, chunks, L_c):
    """Pass 2 of a step with the exact interpolation (:func:`mpm_fem.core.step.explicit_step`), before its
    state update: with ``a_c = a_i - a*_i`` and ``v_c = v_i^{n+1} - v*_i^{n+1}`` (the nodal values
    less the exact ones, the boundary rule applied to both) and ``p_v = v*(x_p^n)``, ``p_a = a*(x_p^n)``,

        v_p <- v_p + dt (p_a + sum_i S_ip a_c,i),
        x_p <- x_p + dt ((p_v + dt p_a) + sum_i S_ip v_c,i),       L_c,p = sum_i G_ip v_c,i,

    ``old``'s x and v into ``new``'s, the numpy step's operations in its order
    (``L_p = v*_x(x_p^{n+1}, t + dt) + L_c,p`` follows)."""
    nodes = g.nodes
    h = g.h
    inv_spacing = g.inv_spacing
    rows = store.rows
    S = store.S
    G = store.G
    cell = store.cell
    # one array a statement: a tuple's arrays unpacked together lose their writes in the prange (docstring)
    x = old.x
    v = old.v
    x_new = new.x
    v_new = new.v
    n = x.size
    K = WIDTH  # nodes per particle
    for k in prange(chunks):
        r, Sl, Gl = _one_row(K)
        for q in range(*_chunk(n, chunks, k)):
            ROW(nodes, h, inv_spacing, x, q, rows, S, G, cell, r, Sl, Gl)
            acc = p_a[q] + _gather(Sl, a_c, r, K)
            moving = p_v[q] + dt * p_a[q] + _gather(Sl, v_c, r, K)
            v_new[q] = v[q] + dt * acc
            x_new[q] = x[q] + dt * moving
            L_c[q] = _gather(Gl, v_c, r, K)


def _update_exact(h, cell, L, old, new, dt, consts, chunks, checks):
    """The state update of :func:`_move_exact`'s particles from their ``L_p`` (USL, the cell of
    ``x_p^n``), ``old`` into ``new``, with pass 2's checks (``checks`` as :func:`_move`'s)."""
    # one array a statement: a tuple's arrays unpacked together lose their writes in the prange (docstring)
    V = old.V
    m = old.m
    rho = old.rho
    e = old.e
    p = old.p
    x_new = new.x
    v_new = new.v
    V_new = new.V
    m_new = new.m
    rho_new = new.rho
    e_new = new.e
    p_new = new.p
    flags = checks.flags
    values = checks.values
    speed = checks.speed
    n = L.size
    gas = MODEL == GAS
    for k in prange(chunks):
        tally = _NO_TALLY
        for q in range(*_chunk(n, chunks, k)):
            tally = _new_state(gas, q, L[q], dt, h[0, cell[q]], rho[q], e[q], p[q], m[q], V[q], consts, tally)
            _store(gas, q, tally, V_new, m_new, rho_new, e_new, p_new)
            tally = _checked(gas, q, tally.sound_speed, x_new, v_new, rho_new, e_new, p_new, V_new, tally)
        _flags(k, tally, flags, values, speed)
