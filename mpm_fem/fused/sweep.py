"""The sweep: pass 2 of one USL step and pass 1 of the next in one pass over the particles, by blocks.

With USL and no remedy, step n's pass 2 and step n+1's pass 1 read the same particles one
after the other, and pass 1 needs nothing of the grid stage between them. The compiled loop
(:func:`mpm_fem.fused.loop._advance`) therefore takes them together, :func:`_sweep`, over blocks of
``BLOCK`` particles, each in three loops:

    A  the gather: each particle's row at ``x_p^n`` (the basis's ``move`` kernel, pass 1's stored
       row read in place, or ``pass_row`` and the gathers) and its sums
       ``acc_p = sum_i S_ip a_i``, ``vel_p = sum_i S_ip v_i^{n+1}``, ``L_p = sum_i G_ip v_i^{n+1}``,
       with ``h_c`` of its cell (the gas's artificial viscosity length), into the block's scratch;
    B  the update over the block's contiguous slices, branch-free so that LLVM vectorises it:
       ``v_p^{n+1} = v_p + dt acc_p`` (blended with ``vel_p`` where ``flip != 1``),
       ``x_p^{n+1} = x_p + dt vel_p``, the model's update from ``L_p`` (the gas:
       :func:`mpm_fem.fused.models._gas_update`; viscous Burgers: ``V_p <- V_p (1 + L_p dt)``,
       ``m_p = V_p``), the signal speed's maximum (``c_p + |v_p|``, Burgers ``|v_p|``), and a count
       of the particles a check refuses (factor or the gas's energy not > 0, a non-finite state);
    C  step n+1's pass 1 over the block's new state, the basis's ``project`` kernel (``m_i``,
       ``P_i`` and the gas's ``F_i = sum_p V_p p_p G_ip``, each node's terms in particle order, the
       rows stored where the basis stores them).

The floats are those of pass 2 and pass 1 taken one after the other (:func:`mpm_fem.fused.passes._move`,
:func:`mpm_fem.fused.project._project`): the same operations per particle in the same order, and
each node's sum added in particle order from zero across the blocks (a block's ``project`` call
starts from the sums the blocks before it left). With threads, each sweeps a contiguous chunk of the
particles into sums of its own, added in chunk order as pass 1's chunks are. Vectorising the update
changes no float: it has no sum across particles but the maximum, which does not depend on the order.
A refused particle stops the sweep (the loop then stops before the step, and :meth:`mpm_fem.fused.step.FusedStep.step`
retakes it and raises as the numpy step does); a particle of step n+1 outside the grid, without
volume, or whose row needs other columns makes the loop take step n+1's pass 1 again, which stops it.
Compiled with ``error_model="numpy"``: a division by zero gives an infinity the checks then refuse,
where numba's Python model would test every divisor and the update would not vectorise.
"""

from typing import NamedTuple

import numpy as np
from llvmlite import ir
from numba import prange, types
from numba.extending import intrinsic

from mpm_fem.bases.contract import Cloud
from mpm_fem.fused.codes import GAS, IFLIP, IGGM1, IGM1, ILIN, IQUAD
from mpm_fem.fused.models import _finite, _gas_update
from mpm_fem.fused.sums import _chunk, _one_row


class Sweeping(NamedTuple):
    """The sweep's scratch and what it reports, per chunk k of the particles."""

    block: np.ndarray  # (chunks, 4, BLOCK): the blocks' scratch
    sums: np.ndarray  # (chunks - 1, 3, n_nodes): the sums of chunks 1, 2, ... (chunk 0's go into ``out``)
    flags: np.ndarray  # (chunks, 3): first particle outside the grid, first without volume, the width it needs
    speeds: np.ndarray  # (chunks,): the largest signal speed
    refusals: np.ndarray  # (chunks,): the first particle of the first block with a refused particle, or -1


BLOCK = 2048  # particles per block: its slices and scratch stay in the L1/L2 cache
ACC, VEL, GRAD, LENGTH = range(4)  # rows of the block's scratch: sum S a, sum S v^{n+1}, L_p, h_c

# placeholders: each variant has its own (mpm_fem.fused.compiler)
MODEL = WIDTH = ROW = STORED = REGISTERS = ANY_GRID = MOVE_RUN = PROJECT_RUN = None


@intrinsic
def fmax(typingctx, a, b):
    """``llvm.maxnum.f64(a, b)``: the larger of two floats. Equal to Python's ``max`` on finite
    numbers that are not both zeros of opposite signs; LLVM vectorises a maximum written with it,
    not one written with ``max`` (numba keeps Python's order of comparison)."""
    double = ir.DoubleType()

    def codegen(context, builder, signature, args):
        fn = builder.module.declare_intrinsic("llvm.maxnum", [double], ir.FunctionType(double, [double, double]))
        return builder.call(fn, args, fastmath=("fast",))

    return types.float64(types.float64, types.float64), codegen


def _sweep(g, stored, a_i, v_n, old, new, dt, consts, chunks, out, scratch):
    """Step n's pass 2 (USL, ``MODEL``'s update, ``old`` into ``new`` from ``a_i`` and ``v_n =
    v_i^{n+1}``) and step n+1's pass 1 of ``new`` into ``out`` (3, n_nodes): ``m_i``, ``P_i`` and the
    gas's ``F_i``, the cells and, for a basis that stores them, the rows into ``stored``. ``g``:
    :class:`~mpm_fem.bases.contract.Geometry` (a grid the basis's ``move`` and ``project`` serve:
    any grid where ``ANY_GRID``, else one uniform to round-off). The particles are cut into ``chunks``
    contiguous ranges (:func:`mpm_fem.fused.sums._chunk`, one per thread in a parallel variant), each
    swept by blocks (``scratch``: :class:`Sweeping`) into its sums (3, n_nodes, zeroed first): ``out``
    for the first, ``sums[k - 1]`` for chunk k > 0, then added to ``out`` in chunk order, node range by
    node range (the floats of :func:`mpm_fem.fused.sums._sum_chunks`, pass 1's: ``1.0 x`` is ``x``).
    Per chunk k: ``refusals[k]`` (-1: none; else ``new`` is not complete), ``speeds[k]``, ``flags[k]``
    (step n+1's, :class:`~mpm_fem.bases.contract.Kernels`' ``project``).
    Returns the first chunk's refusal (-1: none)."""
    nodes = g.nodes
    h = g.h
    inv_spacing = g.inv_spacing
    rows = stored.rows
    S = stored.S
    G = stored.G
    cell = stored.cell
    x, v, V, m, rho, e, p = old.x, old.v, old.V, old.m, old.rho, old.e, old.p
    x_new, v_new, V_new, m_new, rho_new, e_new, p_new = new.x, new.v, new.V, new.m, new.rho, new.e, new.p
    n = x.size
    K = WIDTH  # nodes per particle
    gm1, g_gm1, c_lin, c_quad = consts[IGM1], consts[IGGM1], consts[ILIN], consts[IQUAD]
    flip = consts[IFLIP] if consts.size > IFLIP else 1.0
    keep = 1.0 - flip
    cloud = Cloud(x_new, V_new, m_new, v_new, p_new)  # the gas's mass: the same floats in both sets
    block, sums, flags, speeds, refusals = scratch
    for k in prange(chunks):
        first, last = _chunk(n, chunks, k)
        dest = out if k == 0 else sums[k - 1]
        dest[:] = 0.0
        acc, vel, grad, length = block[k, ACC], block[k, VEL], block[k, GRAD], block[k, LENGTH]
        r, Sl, Gl = _one_row(K)
        speed, outside, empty, need, refused_at = 0.0, -1, -1, 0, -1
        for lo in range(first, last, BLOCK):
            hi = min(lo + BLOCK, last)
            for j in range(hi - lo):  # A: the gather (scalar: indexed loads)
                q = lo + j
                if REGISTERS == 1:
                    c, acc[j], vel[j], grad[j] = MOVE_RUN(nodes, h, inv_spacing, x[q], a_i, v_n)
                elif STORED == 1:
                    c = cell[q]
                    i = rows[q, 0]
                    sa, sv, gv = S[q, 0] * a_i[i], S[q, 0] * v_n[i], G[q, 0] * v_n[i]
                    for kk in range(1, K):
                        i = rows[q, kk]
                        sa += S[q, kk] * a_i[i]
                        sv += S[q, kk] * v_n[i]
                        gv += G[q, kk] * v_n[i]
                    acc[j], vel[j], grad[j] = sa, sv, gv
                else:
                    c = ROW(nodes, h, inv_spacing, x, q, rows, S, G, cell, r, Sl, Gl)
                    sa, sv, gv = Sl[0] * a_i[r[0]], Sl[0] * v_n[r[0]], Gl[0] * v_n[r[0]]
                    for kk in range(1, K):
                        sa += Sl[kk] * a_i[r[kk]]
                        sv += Sl[kk] * v_n[r[kk]]
                        gv += Gl[kk] * v_n[r[kk]]
                    acc[j], vel[j], grad[j] = sa, sv, gv
                if MODEL == GAS:
                    length[j] = h[0, c]
            refused = 0
            if MODEL == GAS:
                xo, vo, mo, rho_o, eo, po = x[lo:hi], v[lo:hi], m[lo:hi], rho[lo:hi], e[lo:hi], p[lo:hi]
                xn, vn, Vn, rho_n, en, pn = x_new[lo:hi], v_new[lo:hi], V_new[lo:hi], rho_new[lo:hi], \
                    e_new[lo:hi], p_new[lo:hi]
                for j in range(hi - lo):  # B: the update (branch-free over contiguous slices: vectorised)
                    u = vo[j] + dt * acc[j]
                    if flip != 1.0:
                        u = flip * u + keep * vel[j]
                    y = xo[j] + dt * vel[j]
                    factor, density, energy, pressure, volume, c = _gas_update(
                        rho_o[j], eo[j], po[j], mo[j], grad[j], dt, length[j], gm1, g_gm1, c_lin, c_quad)
                    xn[j], vn[j], Vn[j], rho_n[j], en[j], pn[j] = y, u, volume, density, energy, pressure
                    speed = fmax(speed, c + abs(u))
                    ok = (factor > 0.0) & (energy > 0.0) & _finite(y, u, density, energy, pressure, volume)
                    refused += 0 if ok else 1
            else:  # viscous Burgers: V <- V (1 + L dt), m = V
                xo, vo, Vo = x[lo:hi], v[lo:hi], V[lo:hi]
                xn, vn, Vn, mn = x_new[lo:hi], v_new[lo:hi], V_new[lo:hi], m_new[lo:hi]
                for j in range(hi - lo):  # B, as the gas's
                    u = vo[j] + dt * acc[j]
                    if flip != 1.0:
                        u = flip * u + keep * vel[j]
                    y = xo[j] + dt * vel[j]
                    factor = 1.0 + grad[j] * dt
                    volume = Vo[j] * factor
                    xn[j], vn[j], Vn[j], mn[j] = y, u, volume, volume
                    speed = fmax(speed, abs(u))
                    ok = (factor > 0.0) & _finite(y, u, volume, 0.0, 0.0, 0.0)
                    refused += 0 if ok else 1
            if refused:
                refused_at = lo
                break
            # C: step n+1's pass 1 over the block's new state
            o, em, k_need = PROJECT_RUN(g, cloud, MODEL == GAS, STORED == 1, lo, hi, stored, dest)
            if outside < 0:
                outside = o
            if empty < 0:
                empty = em
            need = max(need, k_need)
        refusals[k], speeds[k] = refused_at, speed
        flags[k, 0], flags[k, 1], flags[k, 2] = outside, empty, need
    for k in range(chunks):
        if refusals[k] >= 0:
            return refusals[k]
    n_nodes = out.shape[1]
    for part in prange(chunks if chunks > 1 else 0):  # the later chunks' sums added in their order, by node ranges
        start, stop = _chunk(n_nodes, chunks, part)
        for k in range(1, chunks):
            for j in range(3):
                for i in range(start, stop):
                    out[j, i] += sums[k - 1, j, i]
    return -1
