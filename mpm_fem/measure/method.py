"""The projection of any registered basis, measured like the projection study's (claims C5-C7).

The projection study compares the MPM sums with the exact integrals of the P1 hats. A basis from
the registry (a researcher's own, :mod:`mpm_fem.bases.plugins`) projects onto its own grid functions
``S_i`` (``Basis.grid_functions``), so its sums are compared with the integrals of those:

    m_i = int rho S_i dx,    P_i = int rho v S_i dx,    F_i = int p S_i' dx,    a_i = F_i / m_i,

against ``sum_p m_p S_ip``, ``sum_p m_p v_p S_ip``, ``sum_p V_p p_p G_ip`` and their ratio, with
``m_p = rho(x_p) V_p`` and the smooth fields of :func:`~mpm_fem.measure.projection.smooth_fields`.
The integrals take :data:`GAUSS_POINTS` Gauss-Legendre points on each half cell (the grid functions
are polynomials between nodes and half cells), evaluated through the basis's own numpy rows, so they
are exact for the basis to the fields' quadrature error (below 1e-13 on the meshes used here). The
errors are the L1 norms over the nodes at least :data:`WALL_CELLS` cells from a wall (a wall's
folded or modified functions are not the interior's), weighted by ``h``. :func:`projection_orders`
fits the order over the meshes for each seed and reports its mean and range over the seeds.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from mpm_fem.bases import get
from mpm_fem.core.grid import Grid, uniform_grid
from mpm_fem.measure.errors import fitted_order
from mpm_fem.measure.projection import Fields, layout, smooth_fields

GAUSS_POINTS = 8  # per half cell
WALL_CELLS = 3  # the nodes this close to a wall are left out of the norms
QUANTITIES = ("E_m", "E_P", "E_F", "E_a")


class Order(NamedTuple):
    """A fitted order over the meshes: its mean and range over the seeds, and the seeds' count."""

    mean: float
    lo: float
    hi: float
    runs: int


def quadrature_points(grid: Grid) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre points and weights (n,), :data:`GAUSS_POINTS` on each half cell."""
    xi, w = np.polynomial.legendre.leggauss(GAUSS_POINTS)
    left = np.repeat(grid.nodes[:-1], 2) + np.tile([0.0, 0.5], grid.n_cells) * np.repeat(grid.h, 2)
    half = np.repeat(grid.h, 2) / 2
    points = left[:, None] + half[:, None] * (xi + 1) / 2
    return points.ravel(), (half[:, None] * w / 2).ravel()


def nodal_errors(grid: Grid, x: np.ndarray, V: np.ndarray, fields: Fields, basis: str) -> dict[str, float]:
    """``{quantity: L1 error}`` of :data:`QUANTITIES` for particles ``x`` (n_p,) with volumes ``V``
    (n_p,) projected with ``basis`` (module docstring)."""
    method = get(basis)
    points, weights = quadrature_points(grid)
    exact_shape = get(method.grid_functions).shape(grid, points)
    m = exact_shape.scatter(weights * fields.rho(points))
    P = exact_shape.scatter(weights * fields.rho(points) * fields.v(points))
    F = exact_shape.scatter_gradient(weights * fields.p(points))
    shape = method.shape(grid, x, V)
    m_p = fields.rho(x) * V
    m_mpm = shape.scatter(m_p)
    P_mpm = shape.scatter(m_p * fields.v(x))
    F_mpm = shape.scatter_gradient(V * fields.p(x))
    inner = slice(WALL_CELLS, grid.n_nodes - WALL_CELLS)
    h = grid.lumped_mass[inner]
    with np.errstate(divide="ignore", invalid="ignore"):
        a_mpm = np.where(m_mpm > 0, F_mpm / m_mpm, np.nan)
    errors = {"E_m": m - m_mpm, "E_P": P - P_mpm, "E_F": F - F_mpm, "E_a": F / m - a_mpm}
    return {q: float(np.sum(h * np.abs(e[inner]))) for q, e in errors.items()}


def projection_orders(basis: str, cells=(20, 40, 80, 160), ppc: int = 4, layout_name: str = "jittered",
                      seeds=(1, 2, 3)) -> dict[str, Order]:
    """``{quantity: Order}``: the order of each of :data:`QUANTITIES` fitted over the meshes of
    ``cells`` cells on [0, 1] for each seed (the ``layout_name`` layout at ``ppc`` per cell; the
    regular layout takes seed 0 only), its mean and range over the seeds. Raises ``ValueError`` for
    fewer than two meshes, an unknown basis or layout, or a mesh where a cell is left empty (a
    non-finite acceleration error)."""
    cells = tuple(int(k) for k in cells)
    if len(set(cells)) < 2:
        raise ValueError(f"projection orders need at least two meshes, got cells={cells}")
    seeds = (0,) if layout_name == "regular" else tuple(seeds)
    fields = smooth_fields()
    fitted = {q: [] for q in QUANTITIES}
    for seed in seeds:
        errors = {q: [] for q in QUANTITIES}
        for k in cells:
            grid = uniform_grid(0.0, 1.0, 1.0 / k)
            x, V = layout(grid, layout_name, ppc, seed, rho=fields.rho)
            for q, e in nodal_errors(grid, x, V, fields, basis).items():
                errors[q].append(e)
        for q, e in errors.items():
            if not np.all(np.isfinite(e)) or min(e) <= 0:
                raise ValueError(f"the {q} errors of {basis} are not positive and finite on every mesh: {e}")
            fitted[q].append(fitted_order(1.0 / np.array(cells), e))
    return {q: Order(float(np.mean(o)), float(min(o)), float(max(o)), len(o)) for q, o in fitted.items()}
