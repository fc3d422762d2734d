"""Particle quadrature on the plane: the L2 discrepancy of each cell's particles and Hickernell's bound.

The ``N`` particles of a cell ``C`` (size ``h x h``, local coordinates ``z_k`` in ``[0, 1]^2``) stand in
for its integral with equal weights. Zaremba's identity, for ``g(z) = f(x_C + h z)``,

    1/N sum_k g(z_k) - int g = sum_{u != {}} (-1)^{|u|} int disc_u(z_u) d^u g(z_u, 1) dz_u,

(``disc_u`` the local discrepancy of the points projected on the coordinates ``u``, the others at 1),
closed with Cauchy-Schwarz, gives Hickernell's bound (Hickernell, Math. Comp. 67 (1998) 299):

    | int_C f - h^2/N sum_k f(z_k) |  <=  h^2 D2 V(f),                                        (1)
    D2^2   = sum_{u != {}} D*_u^2 = (4/3)^2 - 2/N sum_k prod_j (3 - z_kj^2)/2
                                    + 1/N^2 sum_{k,l} prod_j (2 - max(z_kj, z_lj)),          (2)
    V(f)^2 = h int_top f_x^2 dx + h int_right f_y^2 dy + h^2 int_C f_xy^2 dA,                   (3)

``D*_u`` the L2-star discrepancy of the projection (Warnock's formula, :func:`l2_discrepancy` with
``c = 1``; the full ``u = {x, y}`` is the 2D L2-star discrepancy), top and right the cell's edges at
``y = y_C + h`` and ``x = x_C + h``. In 1D (2) is the 1D study's formula (3) of
:mod:`mpm_fem.measure.quadrature` (``D2^2 = 1/(12 N^2) + 1/N sum (z_(k) - (2k-1)/(2N))^2``): D2 here is its
extension by the tensor product (the modified L2 discrepancy), the one for which (1) holds. For a regular
``n x n`` pattern (2) is ``2/(12 n^2) + 1/9 - 2 A^2 + B^2`` with ``A = (8n^2+1)/(24n^2)``, ``B =
(2n^2+1)/(6n^2)`` (:func:`regular_d2`). D2 is scale-free: it depends on the pattern, not on ``h``.

The checks (:func:`quadrature_checks`), with the slides' weights ``h^2/N_p^c``: the cell mean of
``rho``; the nodal mass ``E_m^i`` against the sum of (1) for ``rho S_i`` over the four cells of node ``i``;
each component of the nodal force ``E_F^i`` against that for ``sum_b sigma_ab d_b S_i`` (``S_i`` is
bilinear in a cell, so both integrands are smooth there). A cell without particles has no bound (NaN).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mpm_fem.plane.grid import PlaneGrid
from mpm_fem.plane.projection import (
    Nodal,
    PlaneFields,
    cell_of,
    cell_weights,
    exact_sums,
    interior_nodes,
    nodal_sums,
    product,
)

#: Gauss-Legendre points per direction for the integrals of (3) on a cell and its edges.
GAUSS_POINTS = 8


def l2_discrepancy(points: np.ndarray, c: float = 2.0) -> np.ndarray:
    """``D^2`` of point sets ``points`` (n_sets, N, d) in ``[0, 1]^d`` for the kernel ``prod_j (c - max)``:
    ``c = 1`` Warnock's L2-star discrepancy, ``c = 2`` the modified one of (2); returns ``D`` (n_sets,)."""
    n = points.shape[1]
    const = (c - 2.0 / 3.0) ** points.shape[2]
    single = np.prod(c - (1.0 + points**2) / 2.0, axis=2).sum(axis=1)
    pairs = np.prod(c - np.maximum(points[:, :, None, :], points[:, None, :, :]), axis=3).sum(axis=(1, 2))
    return np.sqrt(np.maximum(const - 2.0 / n * single + pairs / n**2, 0.0))


def regular_d2(n: int) -> float:
    """(2) of the regular ``n x n`` midpoints, in closed form (module docstring)."""
    A, B = (8 * n**2 + 1) / (24 * n**2), (2 * n**2 + 1) / (6 * n**2)
    return math.sqrt(2.0 / (12 * n**2) + 1.0 / 9.0 - 2 * A**2 + B**2)


def discrepancy_d2(grid: PlaneGrid, x: np.ndarray, c: float = 2.0, dims: tuple[int, ...] = (0, 1)) -> np.ndarray:
    """D2 (2) of every cell's particles (n_cells,), NaN in an empty cell; ``c = 1`` with ``dims`` the L2-star
    discrepancy of the projection on those coordinates. The cells are grouped by their count (one array
    per count, no loop over particles)."""
    cell, local = cell_of(grid, x)
    n_cells = int(np.prod([round(a.length / a.h) for a in grid.axes]))
    order = np.argsort(cell, kind="stable")
    count = np.bincount(cell, minlength=n_cells)
    start = np.concatenate(([0], np.cumsum(count)[:-1]))
    out = np.full(n_cells, np.nan)
    pts = local[order][:, list(dims)]
    for n in np.unique(count[count > 0]):  # one vectorised evaluation per particle count
        cells = np.flatnonzero(count == n)
        out[cells] = l2_discrepancy(pts[start[cells][:, None] + np.arange(n)], c)
    return out


@dataclass(frozen=True, eq=False)
class BoundCheck:
    """Measured errors beside the bound, one entry per cell, or per interior node and component."""

    error: np.ndarray
    bound: np.ndarray

    @property
    def min_ratio(self) -> float:
        """Smallest ``bound / |error|`` over the entries with a bound and a nonzero error (must be >= 1)."""
        e = np.abs(self.error)
        ok = np.isfinite(self.bound) & (e > 0)
        return float(np.min(self.bound[ok] / e[ok])) if ok.any() else math.inf

    @property
    def entries(self) -> int:
        return int(np.sum(np.isfinite(self.bound) & (np.abs(self.error) > 0)))


def _cells(grid: PlaneGrid):
    """The cells' lower-left corners (n_cells, 2), ``c = a n_cy + b``, and their indices ``(a, b)``."""
    n = [round(a.length / a.h) for a in grid.axes]
    a, b = np.divmod(np.arange(n[0] * n[1]), n[1])
    return np.column_stack((grid.axes[0].lo + a * grid.h[0], grid.axes[1].lo + b * grid.h[1])), a, b


def _corner_jets(xi: np.ndarray, eta: np.ndarray, h: float):
    """For each corner ``(i, j)`` of a cell: the jets (4, ...) of its bilinear ``S``, ``d_x S`` and ``d_y S``
    at local coordinates ``xi``, ``eta``."""
    out = {}
    zero = np.zeros_like(xi)
    for i in (0, 1):
        sx, dsx = (xi, 1.0 / h) if i else (1.0 - xi, -1.0 / h)
        for j in (0, 1):
            sy, dsy = (eta, 1.0 / h) if j else (1.0 - eta, -1.0 / h)
            S = np.stack((sx * sy, dsx * sy, sx * dsy, dsx * dsy + zero))
            Sx = np.stack((dsx * sy, zero, dsx * dsy + zero, zero))
            Sy = np.stack((sx * dsy, dsx * dsy + zero, zero, zero))
            out[(i, j)] = (S, Sx, Sy)
    return out


def _integrands(fields: PlaneFields, x: np.ndarray, y: np.ndarray, xi, eta, h: float) -> dict:
    """``{(kind, corner): jet}`` of the bound's integrands at points ``x, y``: ``("rho", None)`` rho itself,
    ``("m", corner)`` rho S, ``("F0", corner)``, ``("F1", corner)`` the force components' ``sum_b sigma_ab d_b S``."""
    rho = fields.rho(x, y)
    sxx, syy, sxy = fields.s_xx(x, y), fields.s_yy(x, y), fields.s_xy(x, y)
    out = {("rho", None): rho}
    for corner, (S, Sx, Sy) in _corner_jets(xi, eta, h).items():
        out[("m", corner)] = product(rho, S)
        out[("F0", corner)] = product(sxx, Sx) + product(sxy, Sy)
        out[("F1", corner)] = product(sxy, Sx) + product(syy, Sy)
    return out


def variations(grid: PlaneGrid, fields: PlaneFields, points: int = GAUSS_POINTS) -> dict:
    """``V(f)`` (3) per cell (n_cells,) of every integrand of :func:`_integrands`, by Gauss-Legendre
    (``points`` per direction on the cell, ``points`` on each edge)."""
    h = grid.h[0]
    if not math.isclose(grid.h[0], grid.h[1]):
        raise ValueError("the bound is written for square cells")
    t, w = np.polynomial.legendre.leggauss(points)
    s, w = 0.5 * (t + 1.0), 0.5 * w
    corner, _, _ = _cells(grid)
    one = np.ones_like(s)
    # (n_cells, q) on the top edge (eta = 1), on the right edge (xi = 1); (n_cells, q, q) on the cell
    top = _integrands(fields, corner[:, :1] + h * s, corner[:, 1:] + h * one, s + 0 * corner[:, :1],
                      one + 0 * corner[:, :1], h)
    right = _integrands(fields, corner[:, :1] + h * one, corner[:, 1:] + h * s, one + 0 * corner[:, :1],
                        s + 0 * corner[:, :1], h)
    XI, ETA = np.meshgrid(s, s, indexing="ij")
    W = np.outer(w, w)
    cx, cy = corner[:, 0, None, None], corner[:, 1, None, None]
    inner = _integrands(fields, cx + h * XI, cy + h * ETA, XI + 0 * cx, ETA + 0 * cx, h)
    return {k: np.sqrt(h * h * (top[k][1] ** 2 @ w) + h * h * (right[k][2] ** 2 @ w)
                       + h**4 * np.sum(inner[k][3] ** 2 * W, axis=(1, 2))) for k in inner}


def quadrature_checks(grid: PlaneGrid, x: np.ndarray, fields: PlaneFields, exact: Nodal | None = None,
                      V: dict | None = None) -> dict[str, BoundCheck]:
    """Hickernell's bound (1) against the equal-weight (``h^2/N_p^c``) errors (module docstring):
    ``cell_rho`` per cell, ``node_m`` per interior node, ``node_F`` per interior node and component;
    ``exact`` (:func:`~mpm_fem.plane.projection.exact_sums`) and ``V`` (:func:`variations`) are computed
    when not given (they depend on the grid and the fields only)."""
    h = grid.h[0]
    d2 = discrepancy_d2(grid, x)
    V = V if V is not None else variations(grid, fields)
    cell, _ = cell_of(grid, x)
    n_cells = d2.size
    count = np.bincount(cell, minlength=n_cells)
    _, a, b = _cells(grid)
    # the cell mean of rho: its exact value from the cell integral of (rho, 1) by the same Gauss rule
    t, w = np.polynomial.legendre.leggauss(GAUSS_POINTS)
    s, w = 0.5 * (t + 1.0), 0.5 * w
    corner, _, _ = _cells(grid)
    X = corner[:, 0, None, None] + h * s[None, :, None]
    Y = corner[:, 1, None, None] + h * s[None, None, :]
    mean = np.sum(fields.rho(X + 0 * Y, Y + 0 * X)[0] * np.outer(w, w), axis=(1, 2))
    with np.errstate(invalid="ignore", divide="ignore"):
        sampled = np.bincount(cell, fields.density(x), minlength=n_cells) / count
    checks = {"cell_rho": BoundCheck(mean - sampled, d2 * V[("rho", None)])}
    # the nodes: each cell's bound for the corner function of node (a + i, b + j)
    ny = grid.shape[1]
    inner = interior_nodes(grid)
    ex = exact if exact is not None else exact_sums(grid, fields)
    mpm = nodal_sums(grid, x, cell_weights(grid, x), fields)
    bounds = {}
    for kind in ("m", "F0", "F1"):
        total = np.zeros(grid.n_nodes)
        for i in (0, 1):
            for j in (0, 1):
                total += np.bincount((a + i) * ny + b + j, h * h * d2 * V[(kind, (i, j))], minlength=grid.n_nodes)
        bounds[kind] = total[inner]
    checks["node_m"] = BoundCheck((ex.m - mpm.m)[inner], bounds["m"])
    E_F = (ex.f - mpm.f)[inner]
    checks["node_F"] = BoundCheck(E_F.T.ravel(), np.concatenate((bounds["F0"], bounds["F1"])))
    return checks
