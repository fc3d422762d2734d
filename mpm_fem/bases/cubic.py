"""The cubic B-spline basis (``"cubic"``): a C2 basis on a uniform grid (Steffen, Kirby & Berzins 2008).

    S_ip = N((x_p - x_i)/h),    G_ip = N'((x_p - x_i)/h) / h,
    N(r) = 2/3 - r^2 + |r|^3/2 for |r| <= 1,   (2 - |r|)^3 / 6 for 1 <= |r| <= 2,   0 beyond,

at the nodes ``c - 1 .. c + 2`` of the particle's cell ``c`` (all four nonzero inside the cell);
in the end cells the row is ``0 .. 3`` and ``n - 3 .. n`` (the four functions nonzero there).
``S_ip``, ``G_ip`` and ``dG_ip/dx_p`` are continuous in ``x_p``: the splines are C2, their knots
the nodes (a cubic on each cell).

Away from the walls the splines reproduce cubics: with ``s = x/h`` on a grid with ``x_i = i h``,

    sum_i N(s - i) = 1,   sum_i N(s - i) i = s,   sum_i N(s - i) (i^2 - 1/3) = s^2,
    sum_i N(s - i) (i^3 - i) = s^3,

so ``sum_i S_ip x_i = x_p`` and ``sum_i S_ip (x_i^2 - h^2/3) = x_p^2``: the nodal coefficients of
``x^2`` are ``x_i^2 - h^2/3``, not ``x_i^2`` (``sum_i S_ip x_i^2 = x_p^2 + h^2/3``).

The walls: the first and last four functions are the end functions of the open knot vector ``0, 0,
0, 0, 2, 3, ..., n - 2, n, n, n, n`` (:mod:`mpm_fem.bases.ends`), so the functions sum to 1 on the
whole grid (``sum_i G_ip = 0``) and only the end node's is nonzero at a wall (1 there): a velocity
that is 0 at the wall nodes interpolates to 0 at the walls. The space is the cubic splines with
the knots ``0, 2, 3, ..., n - 2, n``: it holds every cubic, but the nodal coefficients of ``x`` and
``x^2`` differ from ``x_i`` and ``x_i^2 - h^2/3`` within four cells of a wall (the coefficients
of the open knot vector are its Greville abscissae, ``0, 2h/3, 5h/3, 3h, 4h, ...``). Constants
are reproduced everywhere with coefficient 1.

``int S_i dx`` by two-point Gauss rules on each cell, exact for the piecewise cubics (the end
node integrates to ``h/2``, the next three to ``3h/4``, ``h``, ``5h/4``, the others to ``h``).
The compiled row on a grid uniform to round-off takes ``s = (x - x_0)/h``, ``c = floor(s)``, ``t = s
- c`` and the four splines ``(1 - t)^3/6``, ``(3t^3 - 6t^2 + 4)/6``, ``(3u^3 - 6u^2 + 4)/6``,
``t^3/6`` (``u = 1 - t``), and within five cells of a wall the row's functions from
:func:`_spline`: equal to the numpy rows to round-off; elsewhere the numpy arithmetic, bit for
bit. A grid needs at least seven cells.

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
from mpm_fem.bases.ends import clamp_rows, cubic_end, require_cells
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
    """The cubic B-spline's ``S_ip``, ``G_ip`` (module docstring): nodes ``c - 1 .. c + 2`` (``0 ..
    3``, ``n - 3 .. n`` in the end cells), the end functions at the walls."""
    h = grid.h
    if np.ptp(h) > 1e-9 * h.max():
        raise ValueError("the cubic B-spline basis needs a uniform grid")
    require_cells(grid, 3, "cubic B-spline")
    cell, xi = locate(grid, x)
    top = grid.n_nodes - 1
    nodes = np.minimum(np.maximum(cell - 1, 0), top - 3)[:, None] + np.arange(4)
    r = xi[:, None] - (nodes - cell[:, None])  # (x_p - x_j) / h at the row's nodes j
    S, dS = cubic_bspline(r)
    S, dS = clamp_rows(3, nodes, (cell + xi)[:, None], grid.n_cells, S, dS)
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
def _uniform(r):
    """``N(r)`` and ``N'(r)`` of :func:`cubic_bspline` at one ``r``."""
    a = abs(r)
    if a <= 1.0:
        return TWO_THIRDS - r * r + 0.5 * (a * a * a), r * (1.5 * a - 2.0)
    if a < 2.0:
        w = 2.0 - a
        return SIXTH * (w * w * w), -0.5 * (w * w) * (1.0 if r > 0 else (-1.0 if r < 0 else 0.0))
    return 0.0, 0.0


@njit(cache=True, inline="always")
def _end_column(j, s, n, r):
    """Column ``j`` (a node) of a row at ``s`` on ``n`` cells, value and slope per unit ``s``: the
    uniform spline at ``r = s - j`` (:func:`_uniform`), but the end function for ``j <= 3`` or
    ``j >= n - 3`` (:func:`~mpm_fem.bases.ends.clamp_rows`, the same floats)."""
    if j <= 3:
        return cubic_end(j, s)
    if j >= n - 3:
        v, g = cubic_end(n - j, n - s)
        return v, -g
    return _uniform(r)


@njit(cache=True, inline="always")
def _near_wall(c, top):
    """Whether the row of cell ``c`` holds an end function (``top``: the last node)."""
    return c <= 4 or c >= top - 5


@njit(cache=True, inline="always")
def _first(c, top):
    """The first node of cell ``c``'s row: ``c - 1``, within ``0 .. top - 3``."""
    return min(max(c - 1, 0), top - 3)


@njit(cache=True, inline="always")
def _spline(c, s, top):
    """The row ``_first(c) .. + 3`` at ``s`` near a wall, value and slope per unit ``s`` of each column."""
    f = _first(c, top)
    v0, g0 = _end_column(f, s, top, s - f)
    v1, g1 = _end_column(f + 1, s, top, s - (f + 1))
    v2, g2 = _end_column(f + 2, s, top, s - (f + 2))
    v3, g3 = _end_column(f + 3, s, top, s - (f + 3))
    return v0, v1, v2, v3, g0, g1, g2, g3


@njit(cache=True, inline="always")
def _row(nodes, h, inv_spacing, x, V, row, S, G):
    """``S_ip``, ``G_ip`` of one particle into ``row``, ``S``, ``G`` (``V`` unused): the nodes
    ``c - 1 .. c + 2`` (``0 .. 3``, ``n - 3 .. n`` in the end cells), the end functions at the
    walls; its cell and 4."""
    top = nodes.size - 1
    if inv_spacing > 0.0:  # uniform grid: the four splines from t = s - c
        s, c = scaled(nodes, inv_spacing, x)
        if _near_wall(c, top):
            S0, S1, S2, S3, g0, g1, g2, g3 = _spline(c, s, top)
        else:
            S0, S1, S2, S3, g0, g1, g2, g3 = _splines(s - c)
        f = _first(c, top)
        row[0], row[1], row[2], row[3] = f, f + 1, f + 2, f + 3
        S[0], S[1], S[2], S[3] = S0, S1, S2, S3
        G[0], G[1], G[2], G[3] = g0 * inv_spacing, g1 * inv_spacing, g2 * inv_spacing, g3 * inv_spacing
        return c, 4
    # a grid not uniform to round-off: the formula of cubic_bspline at the row's nodes, the end functions
    c, xi = _locate(nodes, inv_spacing, x)
    s = c + xi
    f = _first(c, top)
    for k in range(4):
        value, slope = _end_column(f + k, s, top, xi - (f + k - c))
        row[k] = f + k
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
    share the cell (each node's terms still added in particle order). A particle within five cells
    of a wall (:func:`_near_wall`: end functions in its row) adds its row of :func:`_spline` into
    ``buf`` directly, its columns left to right."""
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
        near = _near_wall(c, top)
        if near:
            w0, w1, w2, w3, g0, g1, g2, g3 = _spline(c, s, top)
        else:
            w0, w1, w2, w3, g0, g1, g2, g3 = _splines(s - c)
        g0, g1, g2, g3 = g0 * inv_spacing, g1 * inv_spacing, g2 * inv_spacing, g3 * inv_spacing
        f = _first(c, top)
        cell[q] = c
        if store:
            rows[q, 0], rows[q, 1], rows[q, 2], rows[q, 3] = f, f + 1, f + 2, f + 3
            S[q, 0], S[q, 1], S[q, 2], S[q, 3] = w0, w1, w2, w3
            G[q, 0], G[q, 1], G[q, 2], G[q, 3] = g0, g1, g2, g3
        mq = m[q]
        mv = mq * v[q]
        Vp = V[q] * p[q] if gas_force else 0.0
        if near:  # end functions in the row: straight into buf
            if held >= 0:
                buf[0, held - 1], buf[1, held - 1], buf[2, held - 1] = m0, P0, F0
                buf[0, held], buf[1, held], buf[2, held] = m1, P1, F1
                buf[0, held + 1], buf[1, held + 1], buf[2, held + 1] = m2, P2, F2
                buf[0, held + 2], buf[1, held + 2], buf[2, held + 2] = m3, P3, F3
                held = -1
            buf[0, f] += w0 * mq
            buf[1, f] += w0 * mv
            buf[0, f + 1] += w1 * mq
            buf[1, f + 1] += w1 * mv
            buf[0, f + 2] += w2 * mq
            buf[1, f + 2] += w2 * mv
            buf[0, f + 3] += w3 * mq
            buf[1, f + 3] += w3 * mv
            if gas_force:
                buf[2, f] += g0 * Vp
                buf[2, f + 1] += g1 * Vp
                buf[2, f + 2] += g2 * Vp
                buf[2, f + 3] += g3 * Vp
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
    if _near_wall(c, top):
        w0, w1, w2, w3, g0, g1, g2, g3 = _spline(c, s, top)
    else:
        w0, w1, w2, w3, g0, g1, g2, g3 = _splines(s - c)
    f = _first(c, top)
    return (c, w0 * a_i[f] + w1 * a_i[f + 1] + w2 * a_i[f + 2] + w3 * a_i[f + 3],
            w0 * v_n[f] + w1 * v_n[f + 1] + w2 * v_n[f + 2] + w3 * v_n[f + 3],
            (g0 * inv_spacing) * v_n[f] + (g1 * inv_spacing) * v_n[f + 1] + (g2 * inv_spacing) * v_n[f + 2]
            + (g3 * inv_spacing) * v_n[f + 3])


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

    def check_grid(self, grid):
        super().check_grid(grid)
        require_cells(grid, 3, self.name)
