"""Particle quadrature: Hickernell's discrepancy ``D2(P, N)`` and its error bound.

Slides, "Arbitrary point Quadrature Error [Hickernell]". The ``N = N_p^i`` particles of cell
``I_i = [x_{i-1}, x_i]`` (size ``h``) stand in for an integral over the cell with equal weights:

    | 1/h int_{I_i} f dx - 1/N sum_k f(z_k) |  <=  D2(P, N) h^{1/2} ||f'||_{2,h}          (1)
    | int_{I_i} f dx - h/N sum_k f(z_k) |      <=  D2(P, N) h^2 |f'(zeta)|                (2)

with ``||f'||_{2,h} = (int_{I_i} f'^2 dx)^{1/2}`` and, for the local coordinates ``xi_k = (z_k -
x_{i-1})/h`` sorted increasingly,

    D2(P, N)^2 = 1/(12 N^2) + 1/N sum_{k=1..N} (xi_k - (2k-1)/(2N))^2.                   (3)

(3) is the L2 star discrepancy of the points in the unit cell (Warnock's formula), and (1) is
Zaremba's identity ``1/N sum f(z_k) - 1/h int f = int_0^1 g'(t) (A(t)/N - t) dt`` (``g(t) = f(x_{i-1}
+ t h)``, ``A(t)`` the number of points at or left of ``t``) closed with Cauchy-Schwarz: it holds
for every point set. (2) follows from (1) with ``|f'(zeta)|`` the root mean square of ``f'`` on the
cell (attained at some ``zeta`` by continuity); :func:`hickernell_bound_max` uses the maximum of
``|f'|`` instead, which bounds it from above.

The slides write (3) with the physical positions, ``z_k - (x_{i-1} + (2k-1)h/(2N))``, and then

    D2 ~ [1/(12 N^2) + C h^2]^{1/2},   1/4 <= C <= 1/3.                                  (4)

In physical units the second term of (3) is ``h^2 delta`` with ``delta = 1/N sum (xi_k - (2k-1)/(2N))^2``
the (dimensionless) mean squared offset of the points from the cell's regular midpoints, so the
constant of (4) is ``C = delta``: :func:`estimate_c` measures it. In the scale-free form (3), which
is the one for which (1) holds, ``D2`` does not depend on ``h`` for a given pattern of points.

Arrays: ``x`` (n_p,) particle positions; per-cell results (n_cells,), NaN in cells with no particle.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from mpm_fem.core.grid import Grid
from mpm_fem.core.shape import locate

#: Gauss-Legendre points per cell used for the exact integrals (exact for polynomials of degree 39).
GAUSS_POINTS = 20


@dataclass(frozen=True, eq=False)
class CellPoints:
    """The particles of each cell: ``cell`` (n_p,) and local coordinate ``xi`` (n_p,) sorted by
    (cell, xi); ``order`` (n_p,) maps sorted back to input order (``xi = xi_input[order]``);
    ``rank`` (n_p,) the 0-based rank ``k - 1`` within the cell; ``count`` (n_cells,) ``N_p^i``."""

    cell: np.ndarray
    xi: np.ndarray
    order: np.ndarray
    rank: np.ndarray
    count: np.ndarray


def cell_points(grid: Grid, x: np.ndarray) -> CellPoints:
    """Group the particles by cell (a point on an interior node belongs to the cell on its right)."""
    cell, xi = locate(grid, x)
    order = np.lexsort((xi, cell))
    cell, xi = cell[order], xi[order]
    count = np.bincount(cell, minlength=grid.n_cells)
    start = np.concatenate(([0], np.cumsum(count)[:-1]))
    rank = np.arange(cell.size) - start[cell]
    return CellPoints(cell, xi, order, rank, count)


def _per_cell_mean(points: CellPoints, values: np.ndarray) -> np.ndarray:
    total = np.bincount(points.cell, values, minlength=points.count.size)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(points.count > 0, total / points.count, np.nan)


def offset_term(grid: Grid, x: np.ndarray) -> np.ndarray:
    """``delta_i = 1/N sum_k (xi_k - (2k-1)/(2N))^2`` per cell: the second term of (3) (n_cells,)."""
    pts = cell_points(grid, x)
    n = pts.count[pts.cell]
    target = (2 * pts.rank + 1) / (2 * n)
    return _per_cell_mean(pts, (pts.xi - target) ** 2)


def expected_offset(layout: str, n: int) -> float:
    """Expected ``delta`` (the second term of (3)) of the seeded layouts of ``N = n`` points:

    regular midpoints 0; jittered (one uniform point in each sub-cell) ``1/(12 N^2)``; random
    (``N`` sorted uniform points, order statistics ``E xi_k = k/(N+1)``, ``Var xi_k = k(N+1-k) /
    ((N+1)^2 (N+2))``) ``1/(6(N+1)) + (N-1)/(12 N^2 (N+1))``.
    """
    if layout == "regular":
        return 0.0
    if layout == "jittered":
        return 1.0 / (12.0 * n**2)
    if layout == "random":
        return 1.0 / (6.0 * (n + 1)) + (n - 1) / (12.0 * n**2 * (n + 1))
    raise ValueError(f"no closed form for layout {layout!r}")


def discrepancy_d2(grid: Grid, x: np.ndarray) -> np.ndarray:
    """Hickernell's ``D2(P, N_p^i)`` of each cell, formula (3), in local coordinates (n_cells,).

    Regular midpoints ``xi_k = (2k-1)/(2N)`` give exactly ``1/(sqrt(12) N)``, the smallest value.
    """
    pts = cell_points(grid, x)
    with np.errstate(divide="ignore"):
        first = np.where(pts.count > 0, 1.0 / (12.0 * pts.count.astype(float) ** 2), np.nan)
    return np.sqrt(first + offset_term(grid, x))


def discrepancy_d2_slides(grid: Grid, x: np.ndarray) -> np.ndarray:
    """The slides' literal (3), offsets in physical units: ``[1/(12N^2) + h^2 delta]^{1/2}`` (n_cells,)."""
    pts = cell_points(grid, x)
    with np.errstate(divide="ignore"):
        first = np.where(pts.count > 0, 1.0 / (12.0 * pts.count.astype(float) ** 2), np.nan)
    return np.sqrt(first + grid.h**2 * offset_term(grid, x))


def estimate_c(h, n, d2_slides) -> float:
    """Least-squares ``C`` of (4), relative to ``h^2``: minimises ``sum ((D2^2 - 1/(12 N^2))/h^2 - C)^2``
    over the samples (every mesh weighs the same), i.e. the mean of ``(D2^2 - 1/(12 N^2))/h^2``.

    ``h``, ``n`` (particles per cell) and ``d2_slides`` (the literal (3)) are arrays of samples.
    """
    h, n, d = (np.asarray(a, dtype=float) for a in (h, n, d2_slides))
    return float(np.mean((d**2 - 1.0 / (12.0 * n**2)) / h**2))


def integrate_cells(grid: Grid, integrand: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray],
                    points: int = GAUSS_POINTS) -> np.ndarray:
    """``int_{I_i} integrand(x, xi, h) dx`` on every cell by Gauss-Legendre (n_cells,).

    ``integrand`` receives (n_cells, points) arrays: position ``x``, local coordinate ``xi`` in
    [0, 1] and the cell size ``h`` (broadcast).
    """
    t, w = np.polynomial.legendre.leggauss(points)
    xi = 0.5 * (t + 1.0)
    h = grid.h[:, None]
    x = grid.nodes[:-1, None] + xi[None, :] * h
    values = integrand(x, np.broadcast_to(xi, x.shape), np.broadcast_to(h, x.shape))
    return (values * (0.5 * w)).sum(axis=1) * grid.h


def cell_mean_error(grid: Grid, x: np.ndarray, f: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
    """Left side of (1): ``1/h int_{I_i} f dx - 1/N sum_k f(z_k)`` per cell (n_cells,), NaN if N = 0."""
    pts = cell_points(grid, x)
    exact = integrate_cells(grid, lambda y, xi, h: f(y)) / grid.h
    return exact - _per_cell_mean(pts, f(np.asarray(x, float)[pts.order]))


def derivative_l2(grid: Grid, df: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
    """``||f'||_{2,h} = (int_{I_i} f'^2 dx)^{1/2}`` per cell (n_cells,)."""
    return np.sqrt(integrate_cells(grid, lambda y, xi, h: df(y) ** 2))


def hickernell_bound(d2: np.ndarray, h: np.ndarray, df_l2: np.ndarray) -> np.ndarray:
    """Right side of (1): ``D2 h^{1/2} ||f'||_{2,h}`` (bounds the error of the cell mean)."""
    return d2 * np.sqrt(h) * df_l2


def hickernell_bound_max(d2: np.ndarray, h: np.ndarray, df_max: np.ndarray) -> np.ndarray:
    """Right side of (2) with ``|f'(zeta)| <= max_{I_i} |f'|``: ``D2 h^2 max|f'|`` (bounds the
    error of the cell integral, ``h`` times the error of the mean)."""
    return d2 * h**2 * df_max
