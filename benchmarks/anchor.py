"""The anchor: a minimal fused 1D MPM loop for Sod's shock tube, written for speed (the compiled sweep's yardstick).

It is the bare P1 Sod loop of the slides, with none of the project's switches, checks or second
particle set, so that ``benchmarks/step_cost.py`` can report the project's fused loop as a fraction
of what one thread can do. It is an upper anchor, not a like-for-like target.

The scheme (update stress last, point-mass hat functions ``S_ip``, FLIP, lumped mass, walls): on a
uniform grid ``x_i = i h`` with a particle in cell ``c`` at ``xi = x_p / h - c``, ``S_cp = 1 - xi``,
``S_{c+1,p} = xi``, ``G_cp = -1/h``, ``G_{c+1,p} = 1/h``, and one step ``dt`` reads

    m_i = sum_p S_ip m_p,   v_i = sum_p S_ip m_p v_p / m_i,   a_i = sum_p G_ip m_p s_p / m_i
    v_i = a_i = 0 at the end nodes (walls),   v_i^+ = v_i + dt a_i
    v_p <- v_p + dt sum_i S_ip a_i                       (FLIP)
    x_p <- x_p + dt sum_i S_ip v_i^+
    L_p dt = dt sum_i G_ip v_i^+                         (at the position before the move: USL)
    eps_p <- eps_p - s_p L_p dt,   rho_p <- rho_p (1 - L_p dt)
    s_p <- (gamma - 1) eps_p + q_p / rho_p,  q_p / rho_p = C_quad (h L_p^-)^2 + C_lin c_p h |L_p^-|

with ``s_p = p_p / rho_p`` (pressure with the von Neumann-Richtmyer viscosity, over the density:
the force ``sum_p V_p p_p G_ip`` is ``sum_p m_p s_p G_ip``, so no division per particle),
``L^- = min(L, 0)`` (the viscosity acts in compression only), ``c_p = sqrt(gamma (gamma - 1)
eps_p)``, and the next step ``dt = CFL h / max_p (c_p + |v_p|)`` over the updated particles, the
last step shortened to land on ``T``. It is the project's USL step (``mpm_fem.core.step``,
``mpm_fem.core.models.euler``) to round-off: same equations, other summation order, fast-math.

How it is fast: one sweep per step over the particles, which stay sorted (in 1D they
keep their order while ``1 - L dt > 0``). The sweep takes blocks of ``BLOCK`` particles in three
loops: a scalar gather of the nodal ``v_i, a_i`` at each particle's cell; a branch-free update over
contiguous slices, which LLVM vectorises (it also computes the new cell and the particle's
contributions to the next step's nodal sums, and the speed); and a scalar accumulation of those
contributions into two running nodal sums. A node is finished (``v_i, a_i`` written for the next
step) when the sweep passes it, so there is no grid pass, no zeroing and no scattered write; the
nodal values alternate between two buffers. The state is six fields (``x, v, rho, eps, s, m``;
88 B read and written per particle-step), stored block by block (``BLOCK`` values of each field in
turn), so that the slices of one block lie at fixed distances and LLVM vectorises the update
without alias checks; the speed and the positivity minima are reduced with ``llvm.maxnum`` and
``llvm.minnum`` (numba's ``max`` does not vectorise). No helper that takes arrays is called in the
loop. Measured rates are in ``docs/performance.md`` ("The anchor").

Usage: ``python benchmarks/anchor.py [--cells 200] [--ppc 4]`` runs Sod to ``T = 0.2`` and prints
the density L1 error against the exact Riemann solution and the rate in particle-steps/s.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

BLOCK = 2048  # particles per block: the scratch stays in L1/L2 cache
GAMMA, AV_LINEAR, AV_QUADRATIC = 1.4, 0.5, 2.0  # mpm_fem.problems.sod.SodSettings' defaults
LEFT, RIGHT, X0 = (1.0, 0.0, 1.0), (0.125, 0.0, 0.1), 0.5  # Sod's (rho, u, p) and diaphragm
ROWS = ("x", "velocity", "density", "energy", "specific_pressure", "mass")  # rows of the state
X, V, R, E, S, M = range(6)
OK, BAD_ORDER, BAD_FACTOR, BAD_ENERGY = 0, 1, 2, 3
STATUS = {BAD_ORDER: "particles left their order", BAD_FACTOR: "1 - L dt <= 0", BAD_ENERGY: "eps <= 0"}


def _float_intrinsic(name: str):
    """``llvm.<name>.f64`` (``maxnum``, ``minnum``) with fast-math flags: LLVM vectorises a max or min
    reduction written with it, not one written with ``max`` (numba's select keeps Python's order)."""
    double = ir.DoubleType()

    @intrinsic
    def call(typingctx, a, b):
        def codegen(context, builder, signature, args):
            fn = builder.module.declare_intrinsic(f"llvm.{name}", [double], ir.FunctionType(double, [double, double]))
            return builder.call(fn, args, fastmath=("fast",))

        return types.float64(types.float64, types.float64), codegen

    return call


fmax, fmin = _float_intrinsic("maxnum"), _float_intrinsic("minnum")


@njit(cache=True, fastmath=True, boundscheck=False, error_model="numpy")
def _node(m, p, f, inv_h):
    """``(v_i, a_i)`` of a finished node from its sums ``m_i``, ``sum S m v``, ``sum (G h) m s``."""
    if m > 0.0:
        r = 1.0 / m
        return p * r, f * inv_h * r
    return 0.0, 0.0


@njit(cache=True, fastmath=True, boundscheck=False, error_model="numpy")
def _sweeps(state, n_particles, nodes, scratch, consts, clock, max_steps):
    """Advance the ``n_particles`` of ``state`` by up to ``max_steps`` steps or to ``T``.

    ``state``: blocks of ``6 BLOCK`` floats, the rows ``x, v, rho, eps, s, m`` of ``BLOCK``
    particles each (the block's slices lie at fixed distances, so LLVM needs no alias check between
    them); ``nodes`` (4, n_nodes): ``v_i, a_i`` of the next step in rows ``2 cur, 2 cur + 1`` (the
    other pair is written by the sweep); ``scratch`` (10 BLOCK,): the block's buffers, likewise;
    ``consts`` ``(h, cfl, gamma, C_lin, C_quad, T)``; ``clock`` ``(t, dt, cur, steps)``, read and
    written back (``dt = 0``: the next sweep only projects). Returns a status code."""
    h, cfl, gamma, c_lin, c_quad, T = consts[0], consts[1], consts[2], consts[3], consts[4], consts[5]
    t, dt, cur, steps = clock[0], clock[1], int(clock[2]), int(clock[3])
    n = n_particles
    n_blocks = (n + BLOCK - 1) // BLOCK
    last = nodes.shape[1] - 1  # the last node; cells 0 ... last - 1
    top = float(last - 1)
    inv_h = 1.0 / h
    g1 = gamma - 1.0
    cc = gamma * g1
    done = 0
    status = OK
    while True:
        if dt > 0.0 and done >= max_steps:
            break
        dth = dt * inv_h
        k = h / dt if dt > 0.0 else 0.0  # h L dt -> h L
        v_in, a_in = nodes[2 * cur], nodes[2 * cur + 1]
        v_out, a_out = nodes[2 - 2 * cur], nodes[3 - 2 * cur]
        speed, f_min, e_min = 0.0, 1.0, np.inf
        node = 0  # the open cell: the sums of nodes `node` (a) and `node + 1` (b) are running
        ma = pa = fa = mb = pb = fb = 0.0
        for b in range(n_blocks):
            nb = min(BLOCK, n - b * BLOCK)
            blk = state[b * 6 * BLOCK:(b + 1) * 6 * BLOCK]  # one block: the six fields at fixed offsets
            x, v, rho = blk[X * BLOCK:X * BLOCK + nb], blk[V * BLOCK:V * BLOCK + nb], blk[R * BLOCK:R * BLOCK + nb]
            eps, s, m = blk[E * BLOCK:E * BLOCK + nb], blk[S * BLOCK:S * BLOCK + nb], blk[M * BLOCK:M * BLOCK + nb]
            xi, v0, v1, a0, a1 = (scratch[0:nb], scratch[BLOCK:BLOCK + nb], scratch[2 * BLOCK:2 * BLOCK + nb],
                                  scratch[3 * BLOCK:3 * BLOCK + nb], scratch[4 * BLOCK:4 * BLOCK + nb])
            w1, p1, pv = (scratch[5 * BLOCK:5 * BLOCK + nb], scratch[6 * BLOCK:6 * BLOCK + nb],
                          scratch[7 * BLOCK:7 * BLOCK + nb])
            ms, cell = scratch[8 * BLOCK:8 * BLOCK + nb], scratch[9 * BLOCK:9 * BLOCK + nb]
            # 1. scalar gather of the nodal values at each particle's cell
            for j in range(nb):
                sx = x[j] * inv_h
                c = min(int(sx), last - 1)
                xi[j] = sx - c
                v0[j], v1[j], a0[j], a1[j] = v_in[c], v_in[c + 1], a_in[c], a_in[c + 1]
            # 2. the particle update, branch-free over contiguous slices (vectorised)
            for j in range(nb):
                vn0 = v0[j] + dt * a0[j]
                vn1 = v1[j] + dt * a1[j]
                ldt = (vn1 - vn0) * dth
                xj = x[j] + dt * (vn0 + xi[j] * (vn1 - vn0))
                vj = v[j] + dt * (a0[j] + xi[j] * (a1[j] - a0[j]))
                ej = eps[j] - s[j] * ldt
                factor = 1.0 - ldt
                rho[j] *= factor
                csound = np.sqrt(cc * max(ej, 0.0))
                jump = min(ldt, 0.0) * k  # h L^- <= 0
                sj = g1 * ej + c_quad * jump * jump - c_lin * csound * jump
                x[j], v[j], eps[j], s[j] = xj, vj, ej, sj
                speed = fmax(speed, csound + abs(vj))
                f_min = fmin(f_min, factor)
                e_min = fmin(e_min, ej)
                sx = xj * inv_h
                c = max(min(np.floor(sx), top), 0.0)  # the new cell, as a float (no int conversion here)
                cell[j] = c
                w1[j] = m[j] * (sx - c)
                mv = m[j] * vj
                pv[j] = mv
                p1[j] = mv * (sx - c)
                ms[j] = m[j] * sj
            # 3. scalar sums into the running nodes; a node the sweep passes is finished
            for j in range(nb):
                c = int(cell[j])
                if c != node:
                    if c < node:
                        status = BAD_ORDER
                    v_out[node], a_out[node] = _node(ma, pa, fa, inv_h)
                    if c == node + 1:
                        ma, pa, fa = mb, pb, fb
                    else:
                        v_out[node + 1], a_out[node + 1] = _node(mb, pb, fb, inv_h)
                        for i in range(node + 2, c):
                            v_out[i] = a_out[i] = 0.0
                        ma = pa = fa = 0.0
                    mb = pb = fb = 0.0
                    node = c
                mj, w, pj, wp, f = m[j], w1[j], pv[j], p1[j], ms[j]
                ma += mj - w
                mb += w
                pa += pj - wp
                pb += wp
                fa -= f
                fb += f
        v_out[node], a_out[node] = _node(ma, pa, fa, inv_h)
        v_out[node + 1], a_out[node + 1] = _node(mb, pb, fb, inv_h)
        for i in range(node + 2, last + 1):
            v_out[i] = a_out[i] = 0.0
        v_out[0] = a_out[0] = v_out[last] = a_out[last] = 0.0  # walls
        cur = 1 - cur
        if status == OK and f_min <= 0.0:
            status = BAD_FACTOR
        if status == OK and e_min <= 0.0:
            status = BAD_ENERGY
        if dt > 0.0:
            t += dt
            steps += 1
            done += 1
        if status != OK or t >= T * (1.0 - 1e-12):
            dt = 0.0
            break
        dt = min(cfl * h / speed, T - t)
    clock[0], clock[1], clock[2], clock[3] = t, dt, cur, steps
    return status


class Anchor:
    """Sod's tube on ``n_cells`` cells of [0, 1], ``ppc`` particles per cell at ``(k + 1/2) / ppc``
    of each cell, run by the fused loop :func:`_sweeps` (module docstring)."""

    def __init__(self, n_cells: int = 200, ppc: int = 4, cfl: float = 0.1, T: float = 0.2, gamma: float = GAMMA,
                 av_linear: float = AV_LINEAR, av_quadratic: float = AV_QUADRATIC):
        h = 1.0 / n_cells
        x = ((np.arange(n_cells)[:, None] + (np.arange(ppc) + 0.5) / ppc) * h).ravel()
        left = x < X0
        rho = np.where(left, LEFT[0], RIGHT[0])
        p = np.where(left, LEFT[2], RIGHT[2])
        self.n = x.size
        n_blocks = -(-self.n // BLOCK)
        self.state = np.zeros(n_blocks * 6 * BLOCK)  # blocks of BLOCK particles: x, v, rho, eps, s, m
        self._set(X, x)
        self._set(V, np.where(left, LEFT[1], RIGHT[1]))
        self._set(R, rho)
        self._set(E, p / ((gamma - 1.0) * rho))
        self._set(S, p / rho)
        self._set(M, rho * h / ppc)
        self.nodes = np.zeros((4, n_cells + 1))
        self.scratch = np.zeros(10 * BLOCK)
        self.consts = np.array([h, cfl, gamma, av_linear, av_quadratic, T])
        self.clock = np.zeros(4)  # t, dt (0: project first), buffer, steps
        self.h, self.gamma = h, gamma

    def _rows(self) -> np.ndarray:
        return self.state.reshape(-1, 6, BLOCK)

    def _set(self, row: int, values: np.ndarray) -> None:
        flat = np.zeros(self._rows().shape[0] * BLOCK)
        flat[:self.n] = values
        self._rows()[:, row, :] = flat.reshape(-1, BLOCK)

    def _get(self, row: int) -> np.ndarray:
        return self._rows()[:, row, :].ravel()[:self.n]

    @property
    def t(self) -> float:
        return float(self.clock[0])

    @property
    def steps(self) -> int:
        return int(self.clock[3])

    def advance(self, max_steps: int = 10**9) -> int:
        """Take up to ``max_steps`` steps (or run to ``T``); returns the steps taken."""
        before = self.steps
        status = _sweeps(self.state, self.n, self.nodes, self.scratch, self.consts, self.clock, max_steps)
        if status != OK:
            raise FloatingPointError(f"anchor: {STATUS[status]} at step {self.steps} (t={self.t:.6g})")
        return self.steps - before

    def field(self, name: str) -> np.ndarray:
        """A particle field: a row of :data:`ROWS`, or ``volume`` (``m / rho``), ``pressure`` (``s rho``)."""
        if name == "volume":
            return self._get(M) / self._get(R)
        if name == "pressure":
            return self._get(S) * self._get(R)
        return self._get(ROWS.index(name))

    def totals(self) -> dict:
        """Mass, momentum and energy (``sum m (eps + v^2 / 2)``), as :func:`mpm_fem.problems.totals`."""
        m, v = self._get(M), self._get(V)
        return {"mass": float(m.sum()), "momentum": float((m * v).sum()),
                "energy": float((m * (self._get(E) + 0.5 * v * v)).sum())}

    def density_l1(self) -> float:
        """``sum_p V_p |rho_p - rho(x_p, t)|`` against the exact Riemann solution (Toro ch. 4), the
        particle density L1 of :func:`mpm_fem.problems.sod.errors`."""
        from baselines.exact import riemann

        exact, _, _ = riemann.sample(self._get(X), self.t, LEFT, RIGHT, x0=X0, gamma=self.gamma)
        return float(np.sum(self.field("volume") * np.abs(self._get(R) - exact)))


def rate(n_particles: int, steps: int = 20, repeat: int = 3, clock=time.process_time) -> float:
    """Particle-steps per second of the anchor on Sod's data (4 per cell, CFL 0.1): the best of
    ``repeat`` batches of ``steps`` steps, continuing from the previous batch."""
    anchor = Anchor(max(2, n_particles // 4), 4, T=1e9)
    anchor.advance(1)  # compile (or load the cache) and take the first step
    best = np.inf
    for _ in range(repeat):
        t0 = clock()
        anchor.advance(steps)
        best = min(best, clock() - t0)
    return anchor.n * steps / best


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cells", type=int, default=200)
    parser.add_argument("--ppc", type=int, default=4)
    parser.add_argument("--cfl", type=float, default=0.1)
    args = parser.parse_args(argv)
    anchor = Anchor(args.cells, args.ppc, args.cfl)
    anchor.advance(1)
    t0 = time.process_time()
    anchor.advance()
    seconds = time.process_time() - t0
    print(f"anchor: {args.cells} cells x {args.ppc} per cell, {anchor.steps} steps to T = {anchor.t:.3g}: "
          f"density L1 {anchor.density_l1():.4e}, {anchor.n * (anchor.steps - 1) / seconds:.3g} particle-steps/s")


if __name__ == "__main__":
    main()
