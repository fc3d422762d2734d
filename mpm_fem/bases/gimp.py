"""GIMP (``"gimp"``): the P1 hats averaged over the particle domain ``[x_p - V_p/2, x_p + V_p/2]``.

    S_ip = (Phi_i(x_+) - Phi_i(x_-)) / (x_+ - x_-),    G_ip = (S_i(x_+) - S_i(x_-)) / (x_+ - x_-),

with ``Phi_i`` the antiderivative of the hat ``S_i`` and ``x_+- = x_p +- V_p/2`` cut at the ends of
the grid (the average taken over what is left, which keeps the partition of unity at walls). A
row spans the nodes ``c_- .. c_+ + 1`` of the cells the domain reaches: 3 columns to start, wider
as a domain spans more cells. ``int S_i dx`` is the hats' (:func:`~mpm_fem.bases.point.hat_integrals`).
The compiled row on a grid uniform to round-off is built from scalars (:func:`_scalars`,
:func:`_column`) in uniform-grid arithmetic: equal to the numpy rows to round-off; elsewhere
their arithmetic, bit for bit.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from numba import njit

from mpm_fem.bases.cells import DOMAIN_FIELDS, domain_ends, put, stored_row
from mpm_fem.bases.cells import locate as _locate
from mpm_fem.bases.contract import Basis, Kernels
from mpm_fem.bases.point import hat_integrals
from mpm_fem.bases.shape import Shape, particle_domains

if TYPE_CHECKING:
    from mpm_fem.core.grid import Grid


def hat_and_integral(grid: Grid, i: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``S_i(y)`` and ``int_{-inf}^y S_i`` for node indices ``i`` (any shape, broadcast with y).

    End nodes carry a half hat: their missing neighbour is taken as the node itself (zero width).
    """
    xpad = np.concatenate(([grid.nodes[0]], grid.nodes, [grid.nodes[-1]]))
    xl, xc, xr = xpad[i], xpad[i + 1], xpad[i + 2]
    hl, hr = xc - xl, xr - xc
    with np.errstate(divide="ignore", invalid="ignore"):
        yl = np.clip(y, xl, xc)
        yr = np.clip(y, xc, xr)
        left = np.where(hl > 0, (yl - xl) ** 2 / (2 * hl), 0.0)
        right = np.where(hr > 0, (hr**2 - (xr - yr) ** 2) / (2 * hr), 0.0)
        in_left = (y >= xl) & (y < xc) & (hl > 0)
        in_right = (y >= xc) & (y <= xr) & (hr > 0)
        value = np.where(in_left, (y - xl) / hl, 0.0) + np.where(in_right, (xr - y) / hr, 0.0)
    # y exactly on node xc from the left of a node with hl == 0 (the first node): value 1
    value = np.where((y == xc) & (hr == 0) & (hl > 0), 1.0, value)
    return value, left + right


def gimp_shape(grid: Grid, x: np.ndarray, volume: np.ndarray) -> Shape:
    """GIMP's ``S_ip``, ``G_ip`` (module docstring); columns clipped onto the last node are zeroed."""
    cell, lo, hi, c_lo, c_hi = particle_domains(grid, x, volume, "GIMP needs")
    k = int((c_hi - c_lo).max()) + 2
    nodes = np.minimum(c_lo[:, None] + np.arange(k), grid.n_nodes - 1)
    s_hi, phi_hi = hat_and_integral(grid, nodes, hi[:, None])
    s_lo, phi_lo = hat_and_integral(grid, nodes, lo[:, None])
    # columns clipped onto the last node would count it twice: zero them
    dup = np.zeros_like(nodes, dtype=bool)
    dup[:, 1:] = nodes[:, 1:] == nodes[:, :-1]
    length = (hi - lo)[:, None]
    S = np.where(dup, 0.0, (phi_hi - phi_lo) / length)
    G = np.where(dup, 0.0, (s_hi - s_lo) / length)
    return Shape(nodes, S, G, grid.n_nodes, cell)


@njit(cache=True, inline="always")
def _hat_antiderivative(r):
    """``Psi(r) = int_{-inf}^r max(0, 1 - |r'|) dr'`` of the unit hat, without a branch:
    ``(u^2 + 1 - w^2) / 2`` with ``u = clip(r + 1, 0, 1)``, ``w = clip(1 - r, 0, 1)``."""
    u = min(max(r + 1.0, 0.0), 1.0)
    w = min(max(1.0 - r, 0.0), 1.0)
    return 0.5 * (u * u + (1.0 - w * w))


@njit(cache=True, inline="always")
def _hat_and_integral_at(nodes, i, y):
    """:func:`hat_and_integral` for node ``i`` at ``y``: ``S_i(y)``, ``int^y S_i``."""
    n = nodes.size
    xl = nodes[max(i - 1, 0)]
    xc = nodes[i]
    xr = nodes[min(i + 1, n - 1)]
    hl, hr = xc - xl, xr - xc
    yl = min(max(y, xl), xc)
    yr = min(max(y, xc), xr)
    left = (yl - xl) * (yl - xl) / (2 * hl) if hl > 0 else 0.0
    right = (hr * hr - (xr - yr) * (xr - yr)) / (2 * hr) if hr > 0 else 0.0
    value = ((y - xl) / hl if (y >= xl and y < xc and hl > 0) else 0.0) + (
        (xr - y) / hr if (y >= xc and y <= xr and hr > 0) else 0.0)
    if y == xc and hr == 0 and hl > 0:
        value = 1.0
    return value, left + right


#: A particle domain on a uniform grid in scalars (:func:`_scalars`): the fields of
#: :data:`~mpm_fem.bases.cells.DOMAIN_FIELDS`.
Domain = NamedTuple("Domain", DOMAIN_FIELDS)


@njit(cache=True, inline="always")
def _scalars(a, b, top_cell, inv_spacing, x, V):
    """The row on a uniform grid in scalars, for :func:`_column`: a :class:`Domain` with
    ``K_needed = c_+ - c_- + 2`` and ``inv_w`` 0 for a domain inside one cell (which needs no division)."""
    c, s_lo, c_lo, s_hi, c_hi = domain_ends(a, b, top_cell, inv_spacing, x, V)
    inv_w = 1.0 / (s_hi - s_lo) if c_hi != c_lo else 0.0
    return Domain(c, c_hi - c_lo + 2, c_lo, c_hi, s_lo, s_hi, inv_w)


@njit(cache=True, inline="always")
def _column(k, inv_spacing, last, D):
    """Node, ``S`` and ``G`` of column ``k`` from :func:`_scalars`' ``D``: a domain inside one cell
    has the hats' values at its midpoint, ``S = (1 - xi_m, xi_m)``, ``G = (-1, 1)/h`` (no division);
    otherwise node ``i = min(c_- + k, last)``, ``S = (Psi(s_+ - i) - Psi(s_- - i)) inv_w``, ``G =
    (N(s_+ - i) - N(s_- - i)) inv_w / h`` (``N`` the unit hat), a node repeated at the last node zeroed."""
    c_lo, c_hi, s_lo, s_hi, inv_w = D.c_lo, D.c_hi, D.s_lo, D.s_hi, D.inv_w
    if c_hi == c_lo:
        xi = 0.5 * (s_lo + s_hi) - c_lo
        if k == 0:
            return c_lo, 1.0 - xi, -inv_spacing
        if k == 1:
            return c_lo + 1, xi, inv_spacing
        return min(c_lo + k, last), 0.0, 0.0
    i = min(c_lo + k, last)
    if k > 0 and i == min(c_lo + k - 1, last):
        return i, 0.0, 0.0
    r_lo, r_hi = s_lo - i, s_hi - i
    return (i, (_hat_antiderivative(r_hi) - _hat_antiderivative(r_lo)) * inv_w,
            (max(1.0 - abs(r_hi), 0.0) - max(1.0 - abs(r_lo), 0.0)) * (inv_w * inv_spacing))


@njit(cache=True, inline="always")
def _row(nodes, h, inv_spacing, x, V, row, S, G):
    """``S_ip``, ``G_ip`` of one particle into ``row``, ``S``, ``G`` (K = ``row.size`` columns); its
    cell and the K it needs (``c_+ - c_- + 2``; the caller reruns with that K if it differs)."""
    n_nodes = nodes.size
    K = row.size
    a, b = nodes[0], nodes[n_nodes - 1]
    if inv_spacing > 0.0:
        D = _scalars(a, b, n_nodes - 2, inv_spacing, x, V)
        for k in range(K):
            row[k], S[k], G[k] = _column(k, inv_spacing, n_nodes - 1, D)
        return D.cell, D.need
    c, _ = _locate(nodes, inv_spacing, x)
    lo = max(x - 0.5 * V, a)
    hi = min(x + 0.5 * V, b)
    c_lo, _ = _locate(nodes, inv_spacing, lo)
    c_hi, _ = _locate(nodes, inv_spacing, hi)
    need = c_hi - c_lo + 2
    length = hi - lo
    previous = -1
    for k in range(K):
        i = min(c_lo + k, n_nodes - 1)
        row[k] = i
        if i == previous:
            S[k], G[k] = 0.0, 0.0
        else:
            s_hi, phi_hi = _hat_and_integral_at(nodes, i, hi)
            s_lo, phi_lo = _hat_and_integral_at(nodes, i, lo)
            S[k] = (phi_hi - phi_lo) / length
            G[k] = (s_hi - s_lo) / length
        previous = i
    return c, need


@njit(cache=True, inline="always")
def _project(geometry, cloud, gas_force, store, lo, hi, stored, buf):
    """Pass 1 over particles ``lo .. hi-1`` on a uniform grid (:class:`~mpm_fem.bases.contract.Kernels`;
    the rows are stored whatever ``store``): each row from scalars (:func:`_scalars`, :func:`_column`)
    stored and added at once to ``buf`` (:func:`~mpm_fem.bases.cells.put`), in the loop that builds it."""
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
        for j in range(K):
            i, Sj, Gj = _column(j, inv_spacing, last, D)
            put(q, j, i, Sj, Gj, (mq, mv, Vp), gas_force, rows, S, G, buf)
    return outside, empty, need


class Gimp(Basis):
    """GIMP (module docstring)."""

    title = "particle domain"
    name, width, grid_functions, domain, domain_twin, degree, uniform = "gimp", 3, "mpm", True, "gimp", 1, False
    kernels = Kernels(row=_row, pass_row=stored_row, project=_project, any_grid=False, move=None, scalars=_scalars,
                      column=_column)

    def shape(self, grid, x, volume=None):
        if volume is None:
            raise ValueError(f"the {self.name} basis needs the particle volumes")
        return gimp_shape(grid, x, volume)

    def integrals(self, grid):
        return hat_integrals(grid)
