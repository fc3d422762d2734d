"""The particle-domain B-spline (``"bspline_gimp"``): the quadratic B-splines averaged over the particle domain.

    S_ip = 1/V_p int N((x - x_i)/h) chi_p(x) dx = h (M(r_+) - M(r_-)) / (x_+ - x_-),
    G_ip = 1/V_p int N'((x - x_i)/h)/h chi_p(x) dx = (N(r_+) - N(r_-)) / (x_+ - x_-),

with ``x_+- = x_p +- V_p/2`` cut at the ends of the grid (as for GIMP), ``r_+- = (x_+- - x_i)/h``,
``N`` the quadratic B-spline (:mod:`mpm_fem.bases.bspline`) and ``M`` its antiderivative; at the
walls the end functions of the open knot vector and their antiderivatives (:mod:`mpm_fem.bases.ends`,
a ghost column outside the grid 0): the partition of unity holds on the whole grid, and at a wall
only the end node's function is nonzero. A row spans the splines ``j = c_- - 1 .. c_+ + 2``: 5
columns to start, wider as a domain spans more cells. ``int S_i dx`` is the B-splines'
(:func:`~mpm_fem.bases.bspline.spline_integrals`). The compiled row on a grid uniform to round-off
evaluates ``M`` and ``N`` at each end of the domain only in the three pieces that do not vanish
(:func:`_pieces`), the formula's floats; elsewhere the numpy arithmetic, bit for bit; a column of
an end function (or a ghost) from :func:`~mpm_fem.bases.ends.quadratic_end_pair`. A grid needs at
least five cells.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from numba import njit

from mpm_fem.bases.bspline import quadratic_bspline, require_uniform, spline_integrals
from mpm_fem.bases.cells import DOMAIN_FIELDS, domain_ends, put, stored_row
from mpm_fem.bases.cells import locate as _locate
from mpm_fem.bases.contract import Basis, Kernels
from mpm_fem.bases.ends import clamp_antiderivatives, quadratic_end_pair, require_cells
from mpm_fem.bases.shape import Shape, particle_domains

if TYPE_CHECKING:
    from mpm_fem.core.grid import Grid


def bspline_integral(r: np.ndarray) -> np.ndarray:
    """``M(r) = int_{-inf}^r N``, the antiderivative of the quadratic B-spline (0 below -3/2, 1 above 3/2)."""
    r = np.clip(r, -1.5, 1.5)
    u = np.clip(r + 1.5, 0.0, 1.0)  # the part of [r_0, r] in each of the three pieces
    m = np.clip(r, -0.5, 0.5)
    w = np.clip(1.5 - r, 0.0, 1.0)
    return u * u * u / 6.0 + (0.75 * (m + 0.5) - (m * m * m + 0.125) / 3.0) + (1.0 - w * w * w) / 6.0


def bspline_gimp_shape(grid: Grid, x: np.ndarray, volume: np.ndarray) -> Shape:
    """The particle-domain B-spline's ``S_ip``, ``G_ip`` (module docstring)."""
    require_uniform(grid)
    require_cells(grid, 2, "particle-domain B-spline")
    h = grid.h
    cell, lo, hi, c_lo, c_hi = particle_domains(grid, x, volume, "the particle-domain B-spline needs")
    a = grid.nodes[0]
    k = int((c_hi - c_lo).max()) + 4
    j = c_lo[:, None] - 1 + np.arange(k)  # spline centres x_j = a + j h, ghosts at j = -1 and n_nodes
    y_lo, y_hi = (lo[:, None] - a) / h[0], (hi[:, None] - a) / h[0]
    r_lo, r_hi = y_lo - j, y_hi - j
    length = (hi - lo)[:, None]
    M_lo, N_lo = clamp_antiderivatives(j, y_lo, grid.n_cells, bspline_integral(r_lo), quadratic_bspline(r_lo)[0])
    M_hi, N_hi = clamp_antiderivatives(j, y_hi, grid.n_cells, bspline_integral(r_hi), quadratic_bspline(r_hi)[0])
    S = h[0] * (M_hi - M_lo) / length
    G = (N_hi - N_lo) / length
    nodes = np.clip(j, 0, grid.n_nodes - 1)
    return Shape(nodes, S, G, grid.n_nodes, cell)


@njit(cache=True, inline="always")
def _bspline_value(r):
    """``N(r)`` of :func:`~mpm_fem.bases.bspline.quadratic_bspline`."""
    a = abs(r)
    if a <= 0.5:
        return 0.75 - r * r
    if a < 1.5:
        return 0.5 * ((1.5 - a) * (1.5 - a))
    return 0.0


@njit(cache=True, inline="always")
def _bspline_antiderivative(r):
    """``M(r) = int_{-inf}^r N`` of :func:`bspline_integral`, operation for operation."""
    r = min(max(r, -1.5), 1.5)
    u = min(max(r + 1.5, 0.0), 1.0)
    m = min(max(r, -0.5), 0.5)
    w = min(max(1.5 - r, 0.0), 1.0)
    return u * u * u / 6.0 + (0.75 * (m + 0.5) - (m * m * m + 0.125) / 3.0) + (1.0 - w * w * w) / 6.0


_SIXTH = 1.0 / 6.0  # M's first term where r >= -1/2: u = 1
_M_ABOVE = _SIXTH + (0.75 * (0.5 + 0.5) - (0.5 * 0.5 * 0.5 + 0.125) / 3.0)  # M's first two terms where r >= 1/2
_M_TOP = _M_ABOVE + (1.0 - 0.0 * 0.0 * 0.0) / 6.0  # M(r) for r >= 3/2: 1 to round-off, as the formula gives it


@njit(cache=True, inline="always")
def _pieces(y, c):
    """``M`` and ``N`` (:func:`_bspline_antiderivative`, :func:`_bspline_value`) of the three splines
    that do not vanish at the scaled point ``y`` in cell ``c``: those of the nearest node ``n = c +
    first`` (``first = 0`` if ``y - c < 1/2``, else 1) and its neighbours. At ``r = y - j`` they are
    the formula's pieces, operation for operation, so the same floats:

        j = n - 1, r in [1/2, 3/2]:    M = 1/6 + (3/4 - 1/12) + (1 - w^3)/6,  N = w^2/2,  w = 3/2 - r
        j = n,     r in [-1/2, 1/2]:   M = 1/6 + (3/4 (r + 1/2) - (r^3 + 1/8)/3),  N = 3/4 - r^2
        j = n + 1, r in [-3/2, -1/2]:  M = u^3/6,  N = u^2/2,  u = r + 3/2

    (left of them ``M = M(3/2)``, right of them 0; ``N = 0``; the pieces agree where they meet).
    Three divisions instead of the formula's fifteen at the five nodes of a row. Returns ``first``,
    the three ``M``, then the three ``N``."""
    first = 0 if y - c < 0.5 else 1
    nearest = c + first
    w = 1.5 - (y - (nearest - 1))
    r = y - nearest
    u = (y - (nearest + 1)) + 1.5
    return (first, _M_ABOVE + (1.0 - w * w * w) / 6.0, _SIXTH + (0.75 * (r + 0.5) - (r * r * r + 0.125) / 3.0),
            u * u * u / 6.0, 0.5 * (w * w), 0.75 - r * r, 0.5 * (u * u))


@njit(cache=True, inline="always")
def _piece(d, left, a, b, c):
    """The value at the node ``d`` places right of the first of three nodes valued ``a, b, c``:
    ``left`` before them, 0 after them (a sum of one value and zeros, no branch)."""
    return (left if d < 0 else 0.0) + (a if d == 0 else 0.0) + (b if d == 1 else 0.0) + (c if d == 2 else 0.0)


#: A particle domain on a uniform grid in scalars (:func:`_scalars`): the fields of
#: :data:`~mpm_fem.bases.cells.DOMAIN_FIELDS`, then at each end (``_lo``, ``_hi``) :func:`_pieces`: the
#: first of the three splines there ``d``, their antiderivatives ``M`` (left, centre, right) and values
#: ``N``. Scalars only, so that no array is handed to a helper per particle (reference counting).
Domain = NamedTuple("Domain", DOMAIN_FIELDS + [
    (f"{name}_{end}", int if name == "d" else float)
    for end in ("lo", "hi") for name in ("d", "Ml", "M0", "Mr", "Nl", "N0", "Nr")])


@njit(cache=True, inline="always")
def _scalars(a, b, top_cell, inv_spacing, x, V):
    """The row on a uniform grid in scalars, for :func:`_column`: a :class:`Domain` with
    ``K_needed = c_+ - c_- + 4`` (flat: a tuple of tuples failed to compile in numba's parallel variants)."""
    c, s_lo, c_lo, s_hi, c_hi = domain_ends(a, b, top_cell, inv_spacing, x, V)
    inv_w = 1.0 / (s_hi - s_lo)
    d_lo, Ml_lo, M0_lo, Mr_lo, Nl_lo, N0_lo, Nr_lo = _pieces(s_lo, c_lo)
    d_hi, Ml_hi, M0_hi, Mr_hi, Nl_hi, N0_hi, Nr_hi = _pieces(s_hi, c_hi)
    return Domain(c, c_hi - c_lo + 4, c_lo, c_hi, s_lo, s_hi, inv_w, d_lo, Ml_lo, M0_lo, Mr_lo, Nl_lo, N0_lo, Nr_lo,
                  d_hi, Ml_hi, M0_hi, Mr_hi, Nl_hi, N0_hi, Nr_hi)


@njit(cache=True, inline="always")
def _end_node(j, last):
    """Whether the spline of node ``j`` is a ghost or an end function (``last``: the last node)."""
    return j <= 2 or j >= last - 2


@njit(cache=True, inline="always")
def _column(k, inv_spacing, last, D):
    """Node, ``S`` and ``G`` of column ``k`` from :func:`_scalars`' ``D`` (``last``: the last node):
    the spline of node ``j = c_- - 1 + k`` (ghosts folded into the end nodes), ``S = (M(s_+ - j) -
    M(s_- - j)) / (s_+ - s_-)``, ``G = (N(s_+ - j) - N(s_- - j)) / (x_+ - x_-)``, ``M`` and ``N`` at
    each end from its pieces (:func:`_piece`: the columns where each end's three splines start are
    ``d_-`` and ``d_+ + c_+ - c_-``); a ghost's or an end function's column from
    :func:`~mpm_fem.bases.ends.quadratic_end_pair`."""
    (_, _, c_lo, c_hi, s_lo, s_hi, inv_w, d_lo, Ml_lo, M0_lo, Mr_lo, Nl_lo, N0_lo, Nr_lo,
     d_hi, Ml_hi, M0_hi, Mr_hi, Nl_hi, N0_hi, Nr_hi) = D
    j = c_lo - 1 + k
    if _end_node(j, last):
        M_hi, N_hi = quadratic_end_pair(j, s_hi, last)
        M_lo, N_lo = quadratic_end_pair(j, s_lo, last)
        return min(max(j, 0), last), (M_hi - M_lo) * inv_w, (N_hi - N_lo) * (inv_w * inv_spacing)
    d_hi += c_hi - c_lo
    S = (_piece(k - d_hi, _M_TOP, Ml_hi, M0_hi, Mr_hi) - _piece(k - d_lo, _M_TOP, Ml_lo, M0_lo, Mr_lo)) * inv_w
    G = ((_piece(k - d_hi, 0.0, Nl_hi, N0_hi, Nr_hi) - _piece(k - d_lo, 0.0, Nl_lo, N0_lo, Nr_lo))
         * (inv_w * inv_spacing))
    return j, S, G


@njit(cache=True, inline="always")
def _five(d, left, a, b, c):
    """:func:`_piece` at columns 0 .. 4 for a start ``d`` in 0 .. 2, by selecting (``left`` before
    the three values, 0 after them): the same floats, without :func:`_piece`'s four compares per
    column. A larger ``d`` (a row wider than five, which the caller rejects) gives a finite row."""
    return (a if d == 0 else left, b if d == 0 else (a if d == 1 else left), c if d == 0 else (b if d == 1 else a),
            0.0 if d == 0 else (c if d == 1 else b), c if d == 2 else 0.0)


@njit(cache=True, inline="always")
def _five_columns(inv_spacing, D):
    """``S`` and ``G`` of the particle-domain B-spline's five columns (K = 5: a domain within two
    cells) from its :func:`_scalars` ``D``, as a flat tuple ``S_0 .. S_4, G_0 .. G_4`` (a tuple
    of tuples fails to compile in the parallel variants): :func:`_column`'s values, column for column
    the same floats, with :func:`_five` placing each end's three pieces (the low end's start ``d_-``
    is 0 or 1, the high end's ``d_+ + c_+ - c_-`` is 0 .. 2)."""
    (_, _, c_lo, c_hi, _, _, inv_w, d_lo, Ml_lo, M0_lo, Mr_lo, Nl_lo, N0_lo, Nr_lo,
     d_hi, Ml_hi, M0_hi, Mr_hi, Nl_hi, N0_hi, Nr_hi) = D
    d_hi += c_hi - c_lo
    A0, A1, A2, A3, A4 = _five(d_lo, _M_TOP, Ml_lo, M0_lo, Mr_lo)
    B0, B1, B2, B3, B4 = _five(d_hi, _M_TOP, Ml_hi, M0_hi, Mr_hi)
    a0, a1, a2, a3, a4 = _five(d_lo, 0.0, Nl_lo, N0_lo, Nr_lo)
    b0, b1, b2, b3, b4 = _five(d_hi, 0.0, Nl_hi, N0_hi, Nr_hi)
    g = inv_w * inv_spacing
    return ((B0 - A0) * inv_w, (B1 - A1) * inv_w, (B2 - A2) * inv_w, (B3 - A3) * inv_w, (B4 - A4) * inv_w,
            (b0 - a0) * g, (b1 - a1) * g, (b2 - a2) * g, (b3 - a3) * g, (b4 - a4) * g)


@njit(cache=True, inline="always")
def _row(nodes, h, inv_spacing, x, V, row, S, G):
    """:func:`bspline_gimp_shape` of one particle into ``row``, ``S``, ``G`` (K = ``row.size``
    columns): the splines centred at ``j = c_lo - 1 .. c_lo - 2 + K`` averaged over the domain; its
    cell and the K it needs (``c_hi - c_lo + 4``). On a uniform grid (``inv_spacing > 0``) from
    :func:`_scalars` and :func:`_column`, else the numpy arithmetic, bit for bit."""
    n_nodes = nodes.size
    K = row.size
    a, b = nodes[0], nodes[n_nodes - 1]
    h0 = h[0, 0]
    if inv_spacing > 0.0:  # uniform-grid arithmetic, the particle's one division
        D = _scalars(a, b, n_nodes - 2, inv_spacing, x, V)
        for k in range(K):
            row[k], S[k], G[k] = _column(k, inv_spacing, n_nodes - 1, D)
        return D.cell, D.need
    c, _ = _locate(nodes, inv_spacing, x)
    lo = max(x - 0.5 * V, a)
    hi = min(x + 0.5 * V, b)
    c_lo, _ = _locate(nodes, inv_spacing, lo)
    c_hi, _ = _locate(nodes, inv_spacing, hi)
    y_lo, y_hi = (lo - a) / h0, (hi - a) / h0
    length = hi - lo
    for k in range(K):
        j = c_lo - 1 + k
        r_lo, r_hi = y_lo - j, y_hi - j
        row[k] = min(max(j, 0), n_nodes - 1)
        if _end_node(j, n_nodes - 1):
            M_hi, N_hi = quadratic_end_pair(j, y_hi, n_nodes - 1)
            M_lo, N_lo = quadratic_end_pair(j, y_lo, n_nodes - 1)
        else:
            M_hi, N_hi = _bspline_antiderivative(r_hi), _bspline_value(r_hi)
            M_lo, N_lo = _bspline_antiderivative(r_lo), _bspline_value(r_lo)
        S[k] = h0 * (M_hi - M_lo) / length
        G[k] = (N_hi - N_lo) / length
    return c, c_hi - c_lo + 4


@njit(cache=True, inline="always")
def _project(geometry, cloud, gas_force, store, lo, hi, stored, buf):
    """Pass 1 over particles ``lo .. hi-1`` on a uniform grid (:class:`~mpm_fem.bases.contract.Kernels`;
    the rows are stored whatever ``store``): each row from scalars (:func:`_scalars`, then
    :func:`_column`, or for five columns :func:`_five_columns`) stored and added at once to ``buf``
    (:func:`~mpm_fem.bases.cells.put`), in the loop that builds it."""
    nodes, h, inv_spacing = geometry
    x, V, m, v, p = cloud
    rows, S, G, cell = stored
    n_nodes = nodes.size
    K = rows.shape[1]
    last = n_nodes - 1
    a, b = nodes[0], nodes[last]
    outside, empty, need = -1, -1, 0
    for q in range(lo, hi):
        if not (x[q] >= a and x[q] <= b):
            if outside < 0:
                outside = q
            continue
        if not (V[q] > 0):
            if empty < 0:
                empty = q
            continue
        D = _scalars(a, b, n_nodes - 2, inv_spacing, x[q], V[q])
        need = max(need, D.need)
        cell[q] = D.cell
        mq = m[q]
        mv = mq * v[q]
        Vp = V[q] * p[q]
        if K == 5 and not (_end_node(D.c_lo - 1, last) or _end_node(D.c_lo + 3, last)):
            S0, S1, S2, S3, S4, G0, G1, G2, G3, G4 = _five_columns(inv_spacing, D)
            first = D.c_lo - 1  # the columns' nodes c_- - 1 + j, ghosts folded into the end nodes
            put(q, 0, min(max(first, 0), last), S0, G0, (mq, mv, Vp), gas_force, rows, S, G, buf)
            put(q, 1, min(max(first + 1, 0), last), S1, G1, (mq, mv, Vp), gas_force, rows, S, G, buf)
            put(q, 2, min(first + 2, last), S2, G2, (mq, mv, Vp), gas_force, rows, S, G, buf)
            put(q, 3, min(first + 3, last), S3, G3, (mq, mv, Vp), gas_force, rows, S, G, buf)
            put(q, 4, min(first + 4, last), S4, G4, (mq, mv, Vp), gas_force, rows, S, G, buf)
            continue
        for j in range(K):
            i, Sj, Gj = _column(j, inv_spacing, last, D)
            put(q, j, i, Sj, Gj, (mq, mv, Vp), gas_force, rows, S, G, buf)
    return outside, empty, need


class BSplineGimp(Basis):
    """The particle-domain B-spline (module docstring)."""

    title = "B-spline averaged over the particle domain"
    name, width, grid_functions, domain, domain_twin, degree, uniform = ("bspline_gimp", 5, "bspline", True,
                                                                         "bspline_gimp", 2, True)
    kernels = Kernels(row=_row, pass_row=stored_row, project=_project, any_grid=False, move=None, scalars=_scalars,
                      column=_column)

    def shape(self, grid, x, volume=None):
        if volume is None:
            raise ValueError(f"the {self.name} basis needs the particle volumes")
        return bspline_gimp_shape(grid, x, volume)

    def integrals(self, grid):
        return spline_integrals(grid)

    def check_grid(self, grid):
        super().check_grid(grid)
        require_cells(grid, 2, self.name)
