"""The quadratic B-spline basis (``"bspline"``): a C1 basis on a uniform grid (Steffen, Kirby & Berzins 2008).

    S_ip = N((x_p - x_i)/h),    G_ip = N'((x_p - x_i)/h) / h,
    N(r) = 3/4 - r^2 for |r| <= 1/2,   (3/2 - |r|)^2 / 2 for 1/2 <= |r| <= 3/2,   0 beyond,

at the nodes ``c - 1 .. c + 2`` of the particle's cell ``c`` (a ghost column outside the grid
holds 0). At the walls the first and last three functions are the end functions of the open knot
vector ``0, 0, 0, 3/2, 5/2, ..., n - 3/2, n, n, n`` (:mod:`mpm_fem.bases.ends`): the functions sum
to 1 on the whole grid and only the end node's is nonzero at a wall, so a velocity that is 0 at the
wall nodes interpolates to 0 at the walls. ``S_ip`` and ``G_ip`` are continuous in ``x_p``: a
particle crossing a node sees no jump in ``dS/dx`` (slides: the jump in the third derivative of
``x_p``). ``int S_i dx`` by two-point Gauss rules on each half cell, exact for the piecewise
quadratics (the end node integrates to ``h/2``, the next two to ``5h/6`` and ``7h/6``, the others
to ``h``: :data:`~mpm_fem.bases.ends.QUADRATIC_TOTAL`). The compiled row on a grid uniform to round-off takes
the three splines around the nearest node ``n = floor(s + 1/2)``, ``s = (x - x_0)/h``, and within
four cells of a wall the row's four functions from :func:`_spline` (equal to the numpy rows to
round-off); elsewhere the numpy arithmetic, bit for bit. A grid needs at least five cells.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from mpm_fem.bases.cells import locate as _locate
from mpm_fem.bases.cells import scaled
from mpm_fem.bases.contract import Basis, Kernels
from mpm_fem.bases.ends import clamp_rows, quadratic_end, require_cells
from mpm_fem.bases.shape import Shape, locate

if TYPE_CHECKING:
    from mpm_fem.core.grid import Grid


def quadratic_bspline(r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``N(r)`` and ``N'(r)`` of the uniform quadratic B-spline centred at 0, support |r| < 3/2."""
    a = np.abs(r)
    inner = a <= 0.5
    outer = (a > 0.5) & (a < 1.5)
    value = np.where(inner, 0.75 - r * r, np.where(outer, 0.5 * (1.5 - a) ** 2, 0.0))
    slope = np.where(inner, -2.0 * r, np.where(outer, -(1.5 - a) * np.sign(r), 0.0))
    return value, slope


def require_uniform(grid: Grid) -> None:
    """Raise ``ValueError`` unless the grid's cells are equal to 1e-9 relative."""
    h = grid.h
    if np.ptp(h) > 1e-9 * h.max():
        raise ValueError("the quadratic B-spline basis needs a uniform grid")


def bspline_shape(grid: Grid, x: np.ndarray) -> Shape:
    """The quadratic B-spline's ``S_ip``, ``G_ip`` (module docstring)."""
    require_uniform(grid)
    require_cells(grid, 2, "quadratic B-spline")
    h = grid.h
    cell, xi = locate(grid, x)
    offsets = np.arange(-1, 3)
    r = xi[:, None] - offsets  # (x_p - x_{c+k}) / h for k = -1, 0, 1, 2
    S, dS = quadratic_bspline(r)
    j = cell[:, None] + offsets
    S, dS = clamp_rows(2, j, (cell + xi)[:, None], grid.n_cells, S, dS)
    nodes = np.clip(j, 0, grid.n_nodes - 1)
    return Shape(nodes, S, dS / h[0], grid.n_nodes, cell)


def spline_integrals(grid: Grid) -> np.ndarray:
    """``int S_i dx`` of the quadratic B-splines (n_nodes,): two-point Gauss rules on each half cell."""
    left, h = grid.nodes[:-1], grid.h
    g = 0.5 + np.array([-1.0, 1.0]) / (2.0 * np.sqrt(3.0))  # Gauss points on [0, 1]
    local = np.concatenate((0.5 * g, 0.5 + 0.5 * g))
    x = (left[:, None] + h[:, None] * local).ravel()
    weights = np.repeat(h / 4.0, local.size)
    return bspline_shape(grid, x).scatter(weights)


@njit(cache=True, inline="always")
def _nearest(s, top):
    """The row on a uniform grid from ``s = (x - x_0)/h``: the nearest node ``n = floor(s + 1/2)``
    and ``t = s - n`` in [-1/2, 1/2]; the splines of nodes ``n - 1, n, n + 1`` are ``N(t + 1) =
    (1/2 - t)^2 / 2``, ``N(t) = 3/4 - t^2``, ``N(t - 1) = (1/2 + t)^2 / 2``, their slopes ``t - 1/2``,
    ``-2 t``, ``t + 1/2`` (per unit ``s``); every other spline is 0 at ``x``."""
    n = min(int(s + 0.5), top)
    t = s - n
    u, w = 0.5 - t, 0.5 + t
    return n, t, 0.5 * (u * u), 0.75 - t * t, 0.5 * (w * w)


@njit(cache=True, inline="always")
def _uniform(r):
    """``N(r)`` and ``N'(r)`` of :func:`quadratic_bspline` at one ``r``."""
    a = abs(r)
    if a <= 0.5:
        return 0.75 - r * r, -2.0 * r
    if a < 1.5:
        return 0.5 * ((1.5 - a) * (1.5 - a)), -(1.5 - a) * (1.0 if r > 0 else (-1.0 if r < 0 else 0.0))
    return 0.0, 0.0


@njit(cache=True, inline="always")
def _end_column(j, s, n, r):
    """Column ``j`` of a row at ``s`` on ``n`` cells, value and slope per unit ``s``: the uniform
    spline at ``r = s - j`` (:func:`_uniform`), but 0 for a ghost, the end function for ``j <= 2``
    or ``j >= n - 2`` (:func:`~mpm_fem.bases.ends.clamp_rows`, the same floats)."""
    if j < 0 or j > n:
        return 0.0, 0.0
    if j <= 2:
        return quadratic_end(j, s)
    if j >= n - 2:
        v, g = quadratic_end(n - j, n - s)
        return v, -g
    return _uniform(r)


@njit(cache=True, inline="always")
def _near_wall(c, top):
    """Whether the row ``c - 1 .. c + 2`` of cell ``c`` holds an end function or a ghost (``top``: the last node)."""
    return c <= 3 or c >= top - 4


@njit(cache=True, inline="always")
def _spline(c, s, top):
    """The row ``c - 1 .. c + 2`` at ``s`` near a wall, value and slope per unit ``s`` of each column."""
    v0, g0 = _end_column(c - 1, s, top, s - (c - 1))
    v1, g1 = _end_column(c, s, top, s - c)
    v2, g2 = _end_column(c + 1, s, top, s - (c + 1))
    v3, g3 = _end_column(c + 2, s, top, s - (c + 2))
    return v0, v1, v2, v3, g0, g1, g2, g3


@njit(cache=True, inline="always")
def _row(nodes, h, inv_spacing, x, V, row, S, G):
    """``S_ip``, ``G_ip`` of one particle into ``row``, ``S``, ``G`` (``V`` unused): the nodes
    ``c - 1 .. c + 2``; its cell and 4."""
    n_nodes = nodes.size
    if inv_spacing > 0.0:  # uniform grid: the three splines around the nearest node n,
        # stored as the row c-1 .. c+2 (n = c: its last entry 0; n = c + 1: its first)
        s, c = scaled(nodes, inv_spacing, x)
        n, t, w_l, w_0, w_r = _nearest(s, n_nodes - 1)
        first = n - c  # 0 or 1
        for k in range(4):
            row[k] = min(max(c + k - 1, 0), n_nodes - 1)
            S[k], G[k] = 0.0, 0.0
        if _near_wall(c, n_nodes - 1):
            S[0], S[1], S[2], S[3], G[0], G[1], G[2], G[3] = _spline(c, s, n_nodes - 1)
            for k in range(4):
                G[k] = G[k] * inv_spacing
            return c, 4
        S[first], S[first + 1], S[first + 2] = w_l, w_0, w_r
        G[first], G[first + 1], G[first + 2] = ((t - 0.5) * inv_spacing, (-2.0 * t) * inv_spacing,
                                                (t + 0.5) * inv_spacing)
        return c, 4
    # a grid not uniform to round-off: the formula at the nodes c-1 .. c+2, the end functions at the walls
    c, xi = _locate(nodes, inv_spacing, x)
    s = c + xi
    for k in range(4):
        value, slope = _end_column(c + k - 1, s, n_nodes - 1, xi - (k - 1))
        row[k] = min(max(c + k - 1, 0), n_nodes - 1)
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
    the row from :func:`_nearest` (three nodes around the nearest node ``n``), and the three nodes'
    sums held in registers while consecutive particles share ``n`` (each node's terms still added
    in particle order). A particle within four cells of a wall (:func:`_near_wall`: end functions
    or ghosts in its row) adds its row of :func:`_spline` into ``buf`` directly."""
    nodes, h, inv_spacing = geometry
    x, V, m, v, p = cloud
    rows, S, G, cell = stored
    n_nodes = nodes.size
    top = n_nodes - 1
    a, b = nodes[0], nodes[top]
    outside, held = -1, -1  # held: the nearest node whose three node sums are in registers
    m0 = m1 = m2 = P0 = P1 = P2 = F0 = F1 = F2 = 0.0
    for q in range(lo, hi):
        if not (x[q] >= a and x[q] <= b):
            if outside < 0:
                outside = q
            continue
        s, c = scaled(nodes, inv_spacing, x[q])
        cell[q] = c
        mq = m[q]
        mv = mq * v[q]
        Vp = V[q] * p[q] if gas_force else 0.0
        if _near_wall(c, top):  # end functions or ghosts in the row c-1 .. c+2: straight into buf
            if held >= 0:
                buf[0, held - 1], buf[1, held - 1], buf[2, held - 1] = m0, P0, F0
                buf[0, held], buf[1, held], buf[2, held] = m1, P1, F1
                buf[0, held + 1], buf[1, held + 1], buf[2, held + 1] = m2, P2, F2
                held = -1
            e = _spline(c, s, top)
            for k in range(4):
                i, w, g = min(max(c + k - 1, 0), top), e[k], e[4 + k] * inv_spacing
                if store:
                    rows[q, k], S[q, k], G[q, k] = i, w, g
                buf[0, i] += w * mq
                buf[1, i] += w * mv
                if gas_force:
                    buf[2, i] += g * Vp
            continue
        n, t, w_l, w_0, w_r = _nearest(s, top)
        g_l, g_0, g_r = (t - 0.5) * inv_spacing, (-2.0 * t) * inv_spacing, (t + 0.5) * inv_spacing
        if store:  # the row c-1 .. c+2, as _row stores it
            first = n - c
            for k in range(4):
                rows[q, k], S[q, k], G[q, k] = c + k - 1, 0.0, 0.0
            S[q, first], S[q, first + 1], S[q, first + 2] = w_l, w_0, w_r
            G[q, first], G[q, first + 1], G[q, first + 2] = g_l, g_0, g_r
        if n != held:
            if held >= 0:
                buf[0, held - 1], buf[1, held - 1], buf[2, held - 1] = m0, P0, F0
                buf[0, held], buf[1, held], buf[2, held] = m1, P1, F1
                buf[0, held + 1], buf[1, held + 1], buf[2, held + 1] = m2, P2, F2
            m0, P0, F0 = buf[0, n - 1], buf[1, n - 1], buf[2, n - 1]
            m1, P1, F1 = buf[0, n], buf[1, n], buf[2, n]
            m2, P2, F2 = buf[0, n + 1], buf[1, n + 1], buf[2, n + 1]
            held = n
        m0 += w_l * mq
        P0 += w_l * mv
        m1 += w_0 * mq
        P1 += w_0 * mv
        m2 += w_r * mq
        P2 += w_r * mv
        if gas_force:
            F0 += g_l * Vp
            F1 += g_0 * Vp
            F2 += g_r * Vp
    if held >= 0:
        buf[0, held - 1], buf[1, held - 1], buf[2, held - 1] = m0, P0, F0
        buf[0, held], buf[1, held], buf[2, held] = m1, P1, F1
        buf[0, held + 1], buf[1, held + 1], buf[2, held + 1] = m2, P2, F2
    return outside, -1, 4


@njit(cache=True, inline="always")
def _move(nodes, h, inv_spacing, x, a_i, v_n):
    """Pass 2's sums of one particle on a uniform grid, the row of :func:`_nearest` in registers:
    ``c``, ``sum S a``, ``sum S v``, ``sum G v``."""
    top = nodes.size - 1
    s, c = scaled(nodes, inv_spacing, x)
    if _near_wall(c, top):  # the row c-1 .. c+2 of :func:`_spline`, columns left to right
        w0, w1, w2, w3, g0, g1, g2, g3 = _spline(c, s, top)
        i0, i3 = max(c - 1, 0), min(c + 2, top)
        return (c, w0 * a_i[i0] + w1 * a_i[c] + w2 * a_i[c + 1] + w3 * a_i[i3],
                w0 * v_n[i0] + w1 * v_n[c] + w2 * v_n[c + 1] + w3 * v_n[i3],
                (g0 * inv_spacing) * v_n[i0] + (g1 * inv_spacing) * v_n[c] + (g2 * inv_spacing) * v_n[c + 1]
                + (g3 * inv_spacing) * v_n[i3])
    n, t, w_l, w_0, w_r = _nearest(s, top)
    return (c, w_l * a_i[n - 1] + w_0 * a_i[n] + w_r * a_i[n + 1], w_l * v_n[n - 1] + w_0 * v_n[n] + w_r * v_n[n + 1],
            ((t - 0.5) * inv_spacing) * v_n[n - 1] + ((-2.0 * t) * inv_spacing) * v_n[n]
            + ((t + 0.5) * inv_spacing) * v_n[n + 1])


class BSpline(Basis):
    """The quadratic B-spline basis (module docstring)."""

    title = "quadratic B-spline"
    name, width, grid_functions, domain, domain_twin, degree, uniform = ("bspline", 4, "bspline", False,
                                                                         "bspline_gimp", 2, True)
    kernels = Kernels(row=_row, pass_row=_pass_row, project=_project, any_grid=False, move=_move, scalars=None,
                      column=None)

    def shape(self, grid, x, volume=None):
        return bspline_shape(grid, x)

    def integrals(self, grid):
        return spline_integrals(grid)

    def check_grid(self, grid):
        super().check_grid(grid)
        require_cells(grid, 2, self.name)
