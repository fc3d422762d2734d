"""The point-mass basis of standard MPM (``"mpm"``): the P1 hats at the particle points.

    S_ip = S_i(x_p) = (1 - xi, xi),    G_ip = S_i'(x_p) = (-1, 1) / h_c    at the nodes (c, c + 1),

with ``c`` the particle's cell and ``xi = (x_p - x_c)/h_c``. ``int S_i dx`` is the lumped mass of
scikit-fem. The compiled row on a grid uniform to round-off takes ``s = (x - x_0)/h``, ``c =
floor(s)``, ``xi = s - c``, ``1/h_c = 1/h`` (no node read, no division): equal to the node
arithmetic to round-off, not bit for bit; elsewhere the numpy arithmetic, bit for bit.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from mpm_fem.bases.cells import locate as _locate
from mpm_fem.bases.contract import Basis, Kernels
from mpm_fem.bases.shape import Shape, locate

if TYPE_CHECKING:
    from mpm_fem.core.grid import Grid


def point_shape(grid: Grid, x: np.ndarray) -> Shape:
    """Standard MPM: P1 hats at the particle points, ``S = (1 - xi, xi)``, ``G = (-1, 1)/h_c``."""
    cell, xi = locate(grid, x)
    inv_h = 1.0 / grid.h[cell]
    n = cell.size
    nodes, S, G = np.empty((n, 2), np.intp), np.empty((n, 2)), np.empty((n, 2))
    nodes[:, 0], nodes[:, 1] = cell, cell + 1
    S[:, 0], S[:, 1] = 1.0 - xi, xi
    G[:, 0], G[:, 1] = -inv_h, inv_h
    return Shape(nodes, S, G, grid.n_nodes, cell)


@njit(cache=True, inline="always")
def _point(nodes, h, inv_spacing, x):
    """The row of one point: cell ``c``, ``xi`` and ``1/h_c`` (module docstring: uniform-grid
    arithmetic where ``inv_spacing > 0``, else :func:`~mpm_fem.bases.shape.locate` and
    :func:`point_shape`'s, bit for bit)."""
    last = nodes.size - 2
    if inv_spacing > 0.0:
        s = (x - nodes[0]) * inv_spacing
        c = min(int(s), last)  # s >= 0 inside the grid; the last node belongs to the last cell
        return c, s - c, inv_spacing
    c, xi = _locate(nodes, inv_spacing, x)
    return c, xi, h[1, c]


@njit(cache=True, inline="always")
def _row(nodes, h, inv_spacing, x, V, row, S, G):
    """``S_ip``, ``G_ip`` of one particle into ``row``, ``S``, ``G`` (``V`` unused); its cell and 2."""
    c, xi, inv_h = _point(nodes, h, inv_spacing, x)
    row[0], row[1] = c, c + 1
    S[0], S[1] = 1.0 - xi, xi
    G[0], G[1] = -inv_h, inv_h
    return c, 2


@njit(cache=True, inline="always")
def _pass_row(nodes, h, inv_spacing, x, q, rows, S, G, cell, r, Sl, Gl):
    """Particle q's row recomputed from ``x[q]`` (pass 1's numbers); its cell."""
    c, _ = _row(nodes, h, inv_spacing, x[q], 0.0, r, Sl, Gl)
    return c


@njit(cache=True, inline="always")
def _project(geometry, cloud, gas_force, store, lo, hi, stored, buf):
    """Pass 1 over particles ``lo .. hi-1`` (:class:`~mpm_fem.bases.contract.Kernels`): each node's
    terms added in particle order, but a cell's two node sums kept in registers while consecutive
    particles share the cell (sorted particles: ``ppc`` in a row) and written back to ``buf`` when
    the cell changes: one load and store per cell instead of one per term."""
    nodes, h, inv_spacing = geometry
    x, V, m, v, p = cloud
    rows, S, G, cell = stored
    n_nodes = nodes.size
    a, b = nodes[0], nodes[n_nodes - 1]
    outside, held = -1, -1  # held: the cell whose node sums are in registers
    m0 = m1 = P0 = P1 = F0 = F1 = 0.0
    for q in range(lo, hi):
        if not (x[q] >= a and x[q] <= b):
            if outside < 0:
                outside = q
            continue
        c, xi, inv_h = _point(nodes, h, inv_spacing, x[q])  # the row (c, c + 1), (1 - xi, xi), (-1, 1)/h_c
        S0 = 1.0 - xi
        cell[q] = c
        if store:
            rows[q, 0], S[q, 0], G[q, 0] = c, S0, -inv_h
            rows[q, 1], S[q, 1], G[q, 1] = c + 1, xi, inv_h
        if c != held:
            if held >= 0:
                buf[0, held], buf[1, held], buf[2, held] = m0, P0, F0
                buf[0, held + 1], buf[1, held + 1], buf[2, held + 1] = m1, P1, F1
            m0, P0, F0 = buf[0, c], buf[1, c], buf[2, c]
            m1, P1, F1 = buf[0, c + 1], buf[1, c + 1], buf[2, c + 1]
            held = c
        mv = m[q] * v[q]
        m0 += S0 * m[q]
        P0 += S0 * mv
        m1 += xi * m[q]
        P1 += xi * mv
        if gas_force:
            Vp = V[q] * p[q]
            F0 += -inv_h * Vp
            F1 += inv_h * Vp
    if held >= 0:
        buf[0, held], buf[1, held], buf[2, held] = m0, P0, F0
        buf[0, held + 1], buf[1, held + 1], buf[2, held + 1] = m1, P1, F1
    return outside, -1, 2


@njit(cache=True, inline="always")
def _move(nodes, h, inv_spacing, x, a_i, v_n):
    """Pass 2's sums of one particle, the row ``(c, c + 1)``, ``(1 - xi, xi)``, ``(-1, 1)/h_c`` in
    registers: ``c``, ``sum S a``, ``sum S v``, ``sum G v``."""
    c, xi, inv_h = _point(nodes, h, inv_spacing, x)
    S0 = 1.0 - xi
    return (c, S0 * a_i[c] + xi * a_i[c + 1], S0 * v_n[c] + xi * v_n[c + 1],
            -inv_h * v_n[c] + inv_h * v_n[c + 1])


def hat_integrals(grid: Grid) -> np.ndarray:
    """``int S_i dx`` of the P1 hats: the lumped mass of scikit-fem (n_nodes,)."""
    return grid.lumped_mass


class Point(Basis):
    """The point-mass basis (module docstring)."""

    title = "point mass"
    name, width, grid_functions, domain, domain_twin, degree, uniform = "mpm", 2, "mpm", False, "gimp", 1, False
    kernels = Kernels(row=_row, pass_row=_pass_row, project=_project, any_grid=True, move=_move, scalars=None,
                      column=None)

    def shape(self, grid, x, volume=None):
        return point_shape(grid, x)

    def integrals(self, grid):
        return hat_integrals(grid)
