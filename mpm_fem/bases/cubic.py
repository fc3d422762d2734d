"""The cubic B-spline basis (``"cubic"``): a C2 basis on a uniform grid (Steffen, Kirby & Berzins 2008).

    S_ip = N((x_p - x_i)/h),    G_ip = N'((x_p - x_i)/h) / h,
    N(r) = 2/3 - r^2 + |r|^3/2 for |r| <= 1,   (2 - |r|)^3 / 6 for 1 <= |r| <= 2,   0 beyond,

at the nodes ``c - 1 .. c + 2`` of the particle's cell ``c`` (all four nonzero inside the cell).
``S_ip``, ``G_ip`` and ``dG_ip/dx_p`` are continuous in ``x_p``: the splines are C2, their knots
the nodes (a cubic on each cell).

Away from the walls the splines reproduce cubics: with ``s = x/h`` on a grid with ``x_i = i h``,

    sum_i N(s - i) = 1,   sum_i N(s - i) i = s,   sum_i N(s - i) (i^2 - 1/3) = s^2,
    sum_i N(s - i) (i^3 - i) = s^3,

so ``sum_i S_ip x_i = x_p`` and ``sum_i S_ip (x_i^2 - h^2/3) = x_p^2``: the nodal coefficients of
``x^2`` are ``x_i^2 - h^2/3``, not ``x_i^2`` (``sum_i S_ip x_i^2 = x_p^2 + h^2/3``).

The wall: the spline of the ghost node outside each end (node -1, node n) is folded into the end
node, as the quadratic B-spline basis (:mod:`~mpm_fem.bases.bspline`) does, which keeps the
partition of unity on the whole grid (and ``sum_i G_ip = 0``). The ghost spline is nonzero only in
the end cell, so the reproduction above holds for every particle at least one cell ``h`` from a
wall; in the end cell the folded end function is a boundary-modified one: the ghost's
coefficient is replaced by the end node's, so ``sum_i S_ip f_i`` is off by ``N_g (f_w - f_g)``,
with ``N_g = (1 - t)^3 / 6`` the ghost spline, ``t`` the distance to the wall in cells, ``f_w`` and
``f_g`` the coefficients at the wall node ``x_w`` and at the ghost ``x_g = x_w -+ h``: ``+- h N_g``
for ``x`` (at most ``h/6``, at the wall), ``(x_w^2 - x_g^2) N_g`` for ``x^2`` (``-h^2/6`` at a wall
at 0). Constants are reproduced everywhere.

``int S_i dx`` by two-point Gauss rules on each cell, exact for the piecewise cubics (an end node
with its folded ghost integrates to ``13h/24``, its neighbour to ``23h/24``, the others to ``h``).
The compiled row on a grid uniform to round-off takes ``s = (x - x_0)/h``, ``c = floor(s)``, ``t = s
- c`` and the four splines ``(1 - t)^3/6``, ``(3t^3 - 6t^2 + 4)/6``, ``(3u^3 - 6u^2 + 4)/6``,
``t^3/6`` (``u = 1 - t``): equal to the numpy rows to round-off; elsewhere the numpy arithmetic, bit
for bit.

There is no particle-domain cubic basis yet: the basis is its own ``domain_twin``, and the grid
volume reset (which averages the grid functions over the particle domains) is refused for it
(:class:`mpm_fem.core.step.Stages`). The exact stages take its ``degree`` 3: scikit-fem's
``ElementLinePp(3)`` on the nodes and half cells (:mod:`mpm_fem.exact_stages.mass`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from mpm_fem.bases.cells import locate as _locate
from mpm_fem.bases.cells import scaled
from mpm_fem.bases.contract import Basis, Kernels
from mpm_fem.bases.shape import Shape, locate

if TYPE_CHECKING:
    from mpm_fem.core.grid import Grid

TWO_THIRDS = 2.0 / 3.0
SIXTH = 1.0 / 6.0


def cubic_bspline(r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``N(r)`` and ``N'(r)`` of the uniform cubic B-spline centred at 0, support |r| < 2."""
    a = np.abs(r)
    inner = a <= 1.0
    outer = (a > 1.0) & (a < 2.0)
    w = 2.0 - a
    value = np.where(inner, TWO_THIRDS - r * r + 0.5 * (a * a * a), np.where(outer, SIXTH * (w * w * w), 0.0))
    slope = np.where(inner, r * (1.5 * a - 2.0), np.where(outer, -0.5 * (w * w) * np.sign(r), 0.0))
    return value, slope


def cubic_shape(grid: Grid, x: np.ndarray) -> Shape:
    """The cubic B-spline's ``S_ip``, ``G_ip`` (module docstring): nodes ``c - 1 .. c + 2``, the
    ghosts folded into the end nodes."""
    h = grid.h
    if np.ptp(h) > 1e-9 * h.max():
        raise ValueError("the cubic B-spline basis needs a uniform grid")
    cell, xi = locate(grid, x)
    offsets = np.arange(-1, 3)
    r = xi[:, None] - offsets  # (x_p - x_{c+k}) / h for k = -1, 0, 1, 2
    S, dS = cubic_bspline(r)
    nodes = np.clip(cell[:, None] + offsets, 0, grid.n_nodes - 1)
    return Shape(nodes, S, dS / h[0], grid.n_nodes, cell)


def cubic_integrals(grid: Grid) -> np.ndarray:
    """``int S_i dx`` of the cubic B-splines (n_nodes,): two-point Gauss rules on each cell (exact
    for the cubics there)."""
    left, h = grid.nodes[:-1], grid.h
    g = 0.5 + np.array([-1.0, 1.0]) / (2.0 * np.sqrt(3.0))  # Gauss points on [0, 1]
    x = (left[:, None] + h[:, None] * g).ravel()
    weights = np.repeat(h / 2.0, g.size)
    return cubic_shape(grid, x).scatter(weights)


@njit(cache=True, inline="always")
def _splines(t):
    """The four splines of nodes ``c - 1 .. c + 2`` at ``t = s - c`` in [0, 1] and their slopes per
    unit ``s``."""
    u = 1.0 - t
    t2, u2 = t * t, u * u
    return (SIXTH * (u2 * u), SIXTH * (3.0 * (t2 * t) - 6.0 * t2 + 4.0), SIXTH * (3.0 * (u2 * u) - 6.0 * u2 + 4.0),
            SIXTH * (t2 * t), -0.5 * u2, t * (1.5 * t - 2.0), u * (2.0 - 1.5 * u), 0.5 * t2)


@njit(cache=True, inline="always")
def _row(nodes, h, inv_spacing, x, V, row, S, G):
    """``S_ip``, ``G_ip`` of one particle into ``row``, ``S``, ``G`` (``V`` unused): the nodes
    ``c - 1 .. c + 2``, the ghosts folded into the end nodes; its cell and 4."""
    top = nodes.size - 1
    if inv_spacing > 0.0:  # uniform grid: the four splines from t = s - c
        s, c = scaled(nodes, inv_spacing, x)
        S0, S1, S2, S3, g0, g1, g2, g3 = _splines(s - c)
        row[0], row[1], row[2], row[3] = max(c - 1, 0), c, c + 1, min(c + 2, top)
        S[0], S[1], S[2], S[3] = S0, S1, S2, S3
        G[0], G[1], G[2], G[3] = g0 * inv_spacing, g1 * inv_spacing, g2 * inv_spacing, g3 * inv_spacing
        return c, 4
    # a grid not uniform to round-off: the formula of cubic_bspline at the nodes c-1 .. c+2
    c, xi = _locate(nodes, inv_spacing, x)
    for k in range(4):
        r = xi - (k - 1)
        a = abs(r)
        if a <= 1.0:
            value, slope = TWO_THIRDS - r * r + 0.5 * (a * a * a), r * (1.5 * a - 2.0)
        elif a < 2.0:
            w = 2.0 - a
            value = SIXTH * (w * w * w)
            slope = -0.5 * (w * w) * (1.0 if r > 0 else (-1.0 if r < 0 else 0.0))
        else:
            value, slope = 0.0, 0.0
        row[k] = min(max(c + k - 1, 0), top)
        S[k] = value
        G[k] = slope / h[0, 0]
    return c, 4


@njit(cache=True, inline="always")
def _pass_row(nodes, h, inv_spacing, x, q, rows, S, G, cell, r, Sl, Gl):
    """Particle q's row recomputed from ``x[q]`` (pass 1's numbers); its cell."""
    c, _ = _row(nodes, h, inv_spacing, x[q], 0.0, r, Sl, Gl)
    return c


@njit(cache=True, inline="always")
def _project(geometry, cloud, gas_force, store, lo, hi, stored, buf):
    """Pass 1 over particles ``lo .. hi-1`` on a uniform grid (:class:`~mpm_fem.bases.contract.Kernels`):
    the row of :func:`_splines`, the four nodes' sums held in registers while consecutive particles
    share the cell (each node's terms still added in particle order). A particle in an end cell (a
    ghost folded into the end node: a node twice in its row) adds into ``buf`` directly, its
    columns left to right."""
    nodes, h, inv_spacing = geometry
    x, V, m, v, p = cloud
    rows, S, G, cell = stored
    n_nodes = nodes.size
    top = n_nodes - 1
    a, b = nodes[0], nodes[top]
    outside, held = -1, -1  # held: the cell whose four node sums are in registers
    m0 = m1 = m2 = m3 = P0 = P1 = P2 = P3 = F0 = F1 = F2 = F3 = 0.0
    for q in range(lo, hi):
        if not (x[q] >= a and x[q] <= b):
            if outside < 0:
                outside = q
            continue
        s, c = scaled(nodes, inv_spacing, x[q])
        w0, w1, w2, w3, g0, g1, g2, g3 = _splines(s - c)
        g0, g1, g2, g3 = g0 * inv_spacing, g1 * inv_spacing, g2 * inv_spacing, g3 * inv_spacing
        i0, i3 = max(c - 1, 0), min(c + 2, top)
        cell[q] = c
        if store:
            rows[q, 0], rows[q, 1], rows[q, 2], rows[q, 3] = i0, c, c + 1, i3
            S[q, 0], S[q, 1], S[q, 2], S[q, 3] = w0, w1, w2, w3
            G[q, 0], G[q, 1], G[q, 2], G[q, 3] = g0, g1, g2, g3
        mq = m[q]
        mv = mq * v[q]
        Vp = V[q] * p[q] if gas_force else 0.0
        if c == 0 or c + 2 > top:  # an end cell: straight into buf
            if held >= 0:
                buf[0, held - 1], buf[1, held - 1], buf[2, held - 1] = m0, P0, F0
                buf[0, held], buf[1, held], buf[2, held] = m1, P1, F1
                buf[0, held + 1], buf[1, held + 1], buf[2, held + 1] = m2, P2, F2
                buf[0, held + 2], buf[1, held + 2], buf[2, held + 2] = m3, P3, F3
                held = -1
            buf[0, i0] += w0 * mq
            buf[1, i0] += w0 * mv
            buf[0, c] += w1 * mq
            buf[1, c] += w1 * mv
            buf[0, c + 1] += w2 * mq
            buf[1, c + 1] += w2 * mv
            buf[0, i3] += w3 * mq
            buf[1, i3] += w3 * mv
            if gas_force:
                buf[2, i0] += g0 * Vp
                buf[2, c] += g1 * Vp
                buf[2, c + 1] += g2 * Vp
                buf[2, i3] += g3 * Vp
            continue
        if c != held:
            if held >= 0:
                buf[0, held - 1], buf[1, held - 1], buf[2, held - 1] = m0, P0, F0
                buf[0, held], buf[1, held], buf[2, held] = m1, P1, F1
                buf[0, held + 1], buf[1, held + 1], buf[2, held + 1] = m2, P2, F2
                buf[0, held + 2], buf[1, held + 2], buf[2, held + 2] = m3, P3, F3
            m0, P0, F0 = buf[0, c - 1], buf[1, c - 1], buf[2, c - 1]
            m1, P1, F1 = buf[0, c], buf[1, c], buf[2, c]
            m2, P2, F2 = buf[0, c + 1], buf[1, c + 1], buf[2, c + 1]
            m3, P3, F3 = buf[0, c + 2], buf[1, c + 2], buf[2, c + 2]
            held = c
        m0 += w0 * mq
        P0 += w0 * mv
        m1 += w1 * mq
        P1 += w1 * mv
        m2 += w2 * mq
        P2 += w2 * mv
        m3 += w3 * mq
        P3 += w3 * mv
        if gas_force:
            F0 += g0 * Vp
            F1 += g1 * Vp
            F2 += g2 * Vp
            F3 += g3 * Vp
    if held >= 0:
        buf[0, held - 1], buf[1, held - 1], buf[2, held - 1] = m0, P0, F0
        buf[0, held], buf[1, held], buf[2, held] = m1, P1, F1
        buf[0, held + 1], buf[1, held + 1], buf[2, held + 1] = m2, P2, F2
        buf[0, held + 2], buf[1, held + 2], buf[2, held + 2] = m3, P3, F3
    return outside, -1, 4


@njit(cache=True, inline="always")
def _move(nodes, h, inv_spacing, x, a_i, v_n):
    """Pass 2's sums of one particle on a uniform grid, the row of :func:`_splines` in registers:
    ``c``, ``sum S a``, ``sum S v``, ``sum G v`` (columns left to right)."""
    top = nodes.size - 1
    s, c = scaled(nodes, inv_spacing, x)
    w0, w1, w2, w3, g0, g1, g2, g3 = _splines(s - c)
    i0, i3 = max(c - 1, 0), min(c + 2, top)
    return (c, w0 * a_i[i0] + w1 * a_i[c] + w2 * a_i[c + 1] + w3 * a_i[i3],
            w0 * v_n[i0] + w1 * v_n[c] + w2 * v_n[c + 1] + w3 * v_n[i3],
            (g0 * inv_spacing) * v_n[i0] + (g1 * inv_spacing) * v_n[c] + (g2 * inv_spacing) * v_n[c + 1]
            + (g3 * inv_spacing) * v_n[i3])


class Cubic(Basis):
    """The cubic B-spline basis (module docstring)."""

    title = "C2 cubic B-splines at the particle points"
    name, width, grid_functions, domain, domain_twin, degree, uniform = "cubic", 4, "cubic", False, "cubic", 3, True
    kernels = Kernels(row=_row, pass_row=_pass_row, project=_project, any_grid=False, move=_move, scalars=None,
                      column=None)

    def shape(self, grid, x, volume=None):
        return cubic_shape(grid, x)

    def integrals(self, grid):
        return cubic_integrals(grid)
