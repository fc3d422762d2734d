"""The 2D anchor: a minimal compiled P1 loop of the axis-aligned solid, written for speed.

It is the 2D USL step of :mod:`mpm_fem.plane.step` for one case only (the point-mass P1 basis on
the periodic square, lumped mass, FLIP, the neo-Hookean solid, the body force), with none of the
project's switches or basis kernels, so that ``benchmarks/plane_step.py`` can report the compiled
2D step (:mod:`mpm_fem.plane.fused`) as a fraction of what one thread does. An upper anchor, not a
like-for-like target. On the grid ``x_a = lo + a h`` (``n`` cells per axis, node ``i = a n + b``,
periodic), a particle at ``s = (x - lo)/h`` has the cell ``c = floor(s) mod n`` and ``xi = s -
floor(s)``, the P1 weights ``S = (1 - xi, xi)``, ``G = (-1, 1)/h`` per axis, and one step reads

    m_i = sum S m,  P_i = sum S m v,  f_i = sum S m b - sum V^0 tau G     (V sigma = V^0 tau, tau(F))
    v_i = P_i / m_i,  a_i = f_i / m_i,  v_i^+ = v_i + dt a_i
    v_p <- v_p + dt sum S a,  x_p <- x_p + dt sum S v^+,  F_p <- (I + dt sum v^+ (x) G) F_p

How it is fast: the particles are seeded cell by cell (the node order), so consecutive particles
share a cell; pass 1 keeps the cell's four nodes' five sums in registers while they do and adds
them to the nodal array when the cell changes; the state is ten flat arrays (``x, y, v_x, v_y,
F_00, F_01, F_10, F_11, V^0, m``); ``V_p sigma_p`` is ``V^0_p`` times the Kirchhoff stress
``tau = mu (F F^T - I) + lambda ln J I`` (no division); pass 1,
the grid pass and pass 2 run in one compiled call. The body force ``b(X_p, t)`` per unit mass is an
array the caller gives each step (the problem's numpy callable, or one array for all steps).

Usage: ``python benchmarks/plane_anchor.py [--cells 32] [--steps 20]`` runs the axis-aligned
solution and prints its displacement errors (L2, Linf over the particles).
"""

from __future__ import annotations

import argparse
import math

import numpy as np
from numba import njit

ROWS = ("x", "y", "vx", "vy", "F00", "F01", "F10", "F11", "V0", "m")  # the state's rows
IX, IY, IVX, IVY, I00, I01, I10, I11, IV0, IM = range(10)


@njit(cache=True, inline="always")
def _add(sums, i, m, px, py, fx, fy):
    """A held node's five sums added to ``sums[i]``."""
    sums[i, 0] += m
    sums[i, 1] += px
    sums[i, 2] += py
    sums[i, 3] += fx
    sums[i, 4] += fy


@njit(cache=True, boundscheck=False)
def _step(state, bx, by, sums, nodal, consts):
    """One step (module docstring) of the particles ``state`` (10, n_p) in place; ``sums`` (n_nodes, 5)
    zero on entry and on exit; ``nodal`` (n_nodes, 4) written (``a_i``, ``v_i^+``); ``consts`` ``(lo,
    h, n_cells, mu, lam, dt)``. Returns the first particle with ``det F <= 0`` (or NaN), else -1."""
    lo, h, n, mu, lam, dt = consts[0], consts[1], int(consts[2]), consts[3], consts[4], consts[5]
    inv_h = 1.0 / h
    n_p = state.shape[1]
    x, y, vx, vy = state[IX], state[IY], state[IVX], state[IVY]
    F00, F01, F10, F11, V0, m = state[I00], state[I01], state[I10], state[I11], state[IV0], state[IM]
    held = -1
    # the held cell's four nodes (00, 01, 10, 11) x five sums (m, P_x, P_y, f_x, f_y), in registers
    m00 = m01 = m10 = m11 = px00 = px01 = px10 = px11 = py00 = py01 = py10 = py11 = 0.0
    fx00 = fx01 = fx10 = fx11 = fy00 = fy01 = fy10 = fy11 = 0.0
    n00 = n01 = n10 = n11 = 0
    for p in range(n_p + 1):
        cell = -2  # past the last particle: flush
        if p < n_p:
            sx = (x[p] - lo) * inv_h
            sy = (y[p] - lo) * inv_h
            fx, fy = math.floor(sx), math.floor(sy)
            xi, eta = sx - fx, sy - fy
            cx, cy = int(fx) % n, int(fy) % n
            cell = cx * n + cy
        if cell != held:
            if held >= 0:
                _add(sums, n00, m00, px00, py00, fx00, fy00)
                _add(sums, n01, m01, px01, py01, fx01, fy01)
                _add(sums, n10, m10, px10, py10, fx10, fy10)
                _add(sums, n11, m11, px11, py11, fx11, fy11)
            if cell < 0:
                break
            m00 = m01 = m10 = m11 = px00 = px01 = px10 = px11 = py00 = py01 = py10 = py11 = 0.0
            fx00 = fx01 = fx10 = fx11 = fy00 = fy01 = fy10 = fy11 = 0.0
            held = cell
            ax1, ay1 = (cx + 1) % n, (cy + 1) % n
            n00, n01, n10, n11 = cx * n + cy, cx * n + ay1, ax1 * n + cy, ax1 * n + ay1
        a, b, c, d = F00[p], F01[p], F10[p], F11[p]
        log_J = lam * math.log(a * d - b * c)
        w = V0[p]  # V sigma = V^0 tau: the Kirchhoff stress, no division
        s00 = w * (mu * (a * a + b * b - 1.0) + log_J)
        s01 = w * (mu * (a * c + b * d))
        s11 = w * (mu * (c * c + d * d - 1.0) + log_J)
        mp = m[p]
        mvx, mvy, mbx, mby = mp * vx[p], mp * vy[p], mp * bx[p], mp * by[p]
        S00, S01, S10, S11 = (1.0 - xi) * (1.0 - eta), (1.0 - xi) * eta, xi * (1.0 - eta), xi * eta
        # sum_b s_ab G_b at each node: G = (dS/dx, dS/dy), dS/dx = +-(1 - eta or eta)/h, dS/dy = +-(1 - xi or xi)/h
        gx0, gx1, gy0, gy1 = (1.0 - eta) * inv_h, eta * inv_h, (1.0 - xi) * inv_h, xi * inv_h
        m00 += S00 * mp
        m01 += S01 * mp
        m10 += S10 * mp
        m11 += S11 * mp
        px00 += S00 * mvx
        px01 += S01 * mvx
        px10 += S10 * mvx
        px11 += S11 * mvx
        py00 += S00 * mvy
        py01 += S01 * mvy
        py10 += S10 * mvy
        py11 += S11 * mvy
        fx00 += S00 * mbx + (s00 * gx0 + s01 * gy0)
        fx01 += S01 * mbx + (s00 * gx1 - s01 * gy0)
        fx10 += S10 * mbx - (s00 * gx0 - s01 * gy1)
        fx11 += S11 * mbx - (s00 * gx1 + s01 * gy1)
        fy00 += S00 * mby + (s01 * gx0 + s11 * gy0)
        fy01 += S01 * mby + (s01 * gx1 - s11 * gy0)
        fy10 += S10 * mby - (s01 * gx0 - s11 * gy1)
        fy11 += S11 * mby - (s01 * gx1 + s11 * gy1)
    for i in range(sums.shape[0]):
        mi = sums[i, 0]
        ax = ay = ux = uy = 0.0
        if mi > 0.0:
            inv_m = 1.0 / mi
            ux, uy, ax, ay = sums[i, 1] * inv_m, sums[i, 2] * inv_m, sums[i, 3] * inv_m, sums[i, 4] * inv_m
        nodal[i, 0], nodal[i, 1], nodal[i, 2], nodal[i, 3] = ax, ay, ux + dt * ax, uy + dt * ay
        for j in range(5):
            sums[i, j] = 0.0
    bad = -1
    for p in range(n_p):
        sx = (x[p] - lo) * inv_h
        sy = (y[p] - lo) * inv_h
        fx, fy = math.floor(sx), math.floor(sy)
        xi, eta = sx - fx, sy - fy
        cx, cy = int(fx) % n, int(fy) % n
        ax1, ay1 = (cx + 1) % n, (cy + 1) % n
        i00, i01, i10, i11 = cx * n + cy, cx * n + ay1, ax1 * n + cy, ax1 * n + ay1
        w00, w01, w10, w11 = (1.0 - xi) * (1.0 - eta), (1.0 - xi) * eta, xi * (1.0 - eta), xi * eta
        acc_x = w00 * nodal[i00, 0] + w01 * nodal[i01, 0] + w10 * nodal[i10, 0] + w11 * nodal[i11, 0]
        acc_y = w00 * nodal[i00, 1] + w01 * nodal[i01, 1] + w10 * nodal[i10, 1] + w11 * nodal[i11, 1]
        ux00, ux01, ux10, ux11 = nodal[i00, 2], nodal[i01, 2], nodal[i10, 2], nodal[i11, 2]
        uy00, uy01, uy10, uy11 = nodal[i00, 3], nodal[i01, 3], nodal[i10, 3], nodal[i11, 3]
        vel_x = w00 * ux00 + w01 * ux01 + w10 * ux10 + w11 * ux11
        vel_y = w00 * uy00 + w01 * uy01 + w10 * uy10 + w11 * uy11
        # L = sum v (x) G: G_x = (S^y at the x+ nodes - at the x- nodes) / h, G_y likewise
        L00 = ((1.0 - eta) * (ux10 - ux00) + eta * (ux11 - ux01)) * inv_h
        L01 = ((1.0 - xi) * (ux01 - ux00) + xi * (ux11 - ux10)) * inv_h
        L10 = ((1.0 - eta) * (uy10 - uy00) + eta * (uy11 - uy01)) * inv_h
        L11 = ((1.0 - xi) * (uy01 - uy00) + xi * (uy11 - uy10)) * inv_h
        vx[p] += dt * acc_x
        vy[p] += dt * acc_y
        x[p] += dt * vel_x
        y[p] += dt * vel_y
        a, b, c, d = F00[p], F01[p], F10[p], F11[p]
        a2 = a + dt * (L00 * a + L01 * c)
        b2 = b + dt * (L00 * b + L01 * d)
        c2 = c + dt * (L10 * a + L11 * c)
        d2 = d + dt * (L10 * b + L11 * d)
        F00[p], F01[p], F10[p], F11[p] = a2, b2, c2, d2
        if not (a2 * d2 - b2 * c2 > 0.0) and bad < 0:
            bad = p
    return bad


class PlaneAnchor:
    """The axis-aligned solution (``baselines.exact.solids.AxisAligned(amplitude)``) on ``cells x
    cells`` cells of the periodic ``[0, 2)^2``, ``ppc x ppc`` regular particles per cell (seeded
    cell by cell, as :func:`mpm_fem.plane.problems.seed_reference`), stepped by :func:`_step`."""

    def __init__(self, cells: int, ppc: int = 2, amplitude: float = 0.05, dt: float | None = None,
                 cfl: float = 0.25):
        from baselines.exact.solids import AxisAligned

        self.solution = AxisAligned(amplitude=amplitude)
        lo, hi = self.solution.domain[0]
        self.h = (hi - lo) / cells
        local = (np.arange(ppc) + 0.5) / ppc
        corner = lo + self.h * np.arange(cells)
        X = np.broadcast_to((corner[:, None, None, None] + self.h * local[None, None, :, None]),
                            (cells, cells, ppc, ppc)).ravel()
        Y = np.broadcast_to((corner[None, :, None, None] + self.h * local[None, None, None, :]),
                            (cells, cells, ppc, ppc)).ravel()
        self.X, self.Y = X.copy(), Y.copy()
        self.n = X.size
        material = self.solution.material
        self.dt = cfl * self.h / material.c if dt is None else dt
        V0 = np.full(self.n, self.h**2 / ppc**2)
        u = self.solution.displacement(X, Y, 0.0)
        F = np.asarray(self.solution.deformation_gradient(X, Y, 0.0), dtype=float).reshape(-1, 2, 2)
        v = self.solution.velocity(X, Y, -0.5 * self.dt)
        self.state = np.empty((len(ROWS), self.n))
        s = self.state
        s[IX], s[IY], s[IVX], s[IVY] = X + u[0], Y + u[1], v[0], v[1]
        s[I00], s[I01], s[I10], s[I11] = F[:, 0, 0], F[:, 0, 1], F[:, 1, 0], F[:, 1, 1]
        s[IV0], s[IM] = V0, material.rho0 * V0
        self.sums = np.zeros((cells * cells, 5))
        self.nodal = np.zeros((cells * cells, 4))
        self.consts = np.array([lo, self.h, cells, material.mu, material.lam, self.dt])
        self.t, self.steps = 0.0, 0

    def advance(self, steps: int, body_force=None) -> None:
        """``steps`` steps; ``body_force(X, Y, t) -> (2, n_p)`` (default: the solution's) is called each step."""
        force = self.solution.body_force if body_force is None else body_force
        for _ in range(steps):
            b = np.asarray(force(self.X, self.Y, self.t))
            bad = _step(self.state, b[0], b[1], self.sums, self.nodal, self.consts)
            self.steps += 1
            self.t = self.steps * self.dt
            if bad >= 0:
                raise FloatingPointError(f"anchor: det F <= 0 in particle {bad} at step {self.steps}")

    def errors(self) -> dict:
        """The displacement's particle errors at ``t`` (:mod:`mpm_fem.plane.norms`): ``L2``, ``Linf``."""
        from mpm_fem.plane.norms import particle_l2, particle_linf

        s = self.state
        u = np.column_stack((s[IX] - self.X, s[IY] - self.Y))
        error = u - np.asarray(self.solution.displacement(self.X, self.Y, self.t)).T
        volume = (s[I00] * s[I11] - s[I01] * s[I10]) * s[IV0]
        return {"L2": particle_l2(volume, error), "Linf": particle_linf(error)}


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cells", type=int, default=32, help="cells per axis (default 32)")
    parser.add_argument("--steps", type=int, default=20)
    args = parser.parse_args(argv)
    anchor = PlaneAnchor(args.cells)
    anchor.advance(args.steps)
    e = anchor.errors()
    print(f"plane anchor: {args.cells}^2 cells x 4 particles, {anchor.steps} steps of dt = {anchor.dt:.3g}: "
          f"displacement L2 {e['L2']:.4e}, Linf {e['Linf']:.4e}")


if __name__ == "__main__":
    main()
