"""Reconstruction of the particle stress before the force integral (Taylor least squares).

The MPM internal force ``F_i = - sum_p V_p sigma_p G_ip`` is a quadrature of ``- int sigma S_i' dx``
with the particles as points and their volumes as weights; when a particle crosses a node the
weights of a cell jump, and the quadrature error with them (the cell-crossing error). Following the
Taylor least-squares reconstruction (Wobbes, Moeller, Galavi & Vuik 2019), the stress is first
fitted, cell by cell, by a linear polynomial in the local coordinate ``xi = (x - x_c)/h_c``,

    sigma_h(x) = s0_c + s1_c (xi - 1/2),     (s0_c, s1_c) = argmin sum_{p in I_c} (sigma_h(x_p) - sigma_p)^2,

(one particle, or particles at one point: the constant fit ``s0_c = mean sigma_p``; an empty cell
carries no stress), and the force is then integrated exactly over the cells,

    F_i = - sum_c int_{I_c} sigma_h S_i' dx,

by two-point Gauss rules on each half cell: exact for the P1 hats and for the quadratic B-splines,
whose derivatives are linear on each half cell. ``sum_i S_i' = 0`` keeps ``sum_i F_i = 0``: the
reconstruction conserves momentum as the particle sum does. Mass and momentum projections are
left as they are (mass stays exactly ``sum_p m_p``). The cells are assumed filled with material,
as in the shock tube and in Burgers' problem with its inflow reservoirs.
"""

from __future__ import annotations

import numpy as np

from mpm_fem.core.grid import Grid
from mpm_fem.core.shape import Shape, grid_functions, locate, make_shape

RECONSTRUCTIONS = ("none", "taylor")

_G = 0.5 + np.array([-1.0, 1.0]) / (2.0 * np.sqrt(3.0))  # Gauss points on [0, 1]
_LOCAL = np.concatenate((0.5 * _G, 0.5 + 0.5 * _G))  # two per half cell, weights 1/4 each
OFFSETS = _LOCAL - 0.5  # xi - 1/2 at the four points of a cell


def taylor_fit(cell: np.ndarray, xi: np.ndarray, q: np.ndarray, n_cells: int) -> tuple[np.ndarray, np.ndarray]:
    """Per-cell least-squares line ``q ~ s0 + s1 (xi - 1/2)`` through the particle values (n_cells,) each."""
    d = xi - 0.5
    sums = [np.bincount(cell, w, n_cells) for w in (None, d, d * d, q, q * d)]
    n, sd, sdd, sq, sqd = sums
    det = n * sdd - sd * sd
    linear = det > 1e-12 * np.maximum(n, 1.0) ** 2
    s1 = np.zeros(n_cells)
    np.divide(n * sqd - sd * sq, det, out=s1, where=linear)
    s0 = np.zeros(n_cells)
    np.divide(sq - s1 * sd, n, out=s0, where=n > 0)
    return s0, s1


def reconstructed_force(grid: Grid, x: np.ndarray, stress: np.ndarray, basis: str = "mpm") -> np.ndarray:
    """``F_i = - int sigma_h S_i' dx`` with ``sigma_h`` the Taylor least-squares fit of ``stress`` at
    the particles ``x`` (module docstring); ``S_i`` the grid functions of ``basis`` (n_nodes,)."""
    cell, xi = locate(grid, x)
    s0, s1 = taylor_fit(cell, xi, np.asarray(stress, dtype=float), grid.n_cells)
    sigma = (s0[:, None] + s1[:, None] * OFFSETS).ravel()
    shape, weights = force_quadrature(grid, basis)
    return -shape.scatter_gradient(weights * sigma)


def force_quadrature(grid: Grid, basis: str = "mpm") -> tuple[Shape, np.ndarray]:
    """The quadrature of the reconstructed force: the four points of every cell, cell by cell
    (``x_c + h_c`` times the local points), the grid functions of ``basis`` there (their ``G`` is
    ``S_i'``), and the weights ``h_c / 4``."""
    left, h = grid.nodes[:-1], grid.h
    points = (left[:, None] + h[:, None] * _LOCAL).ravel()
    return make_shape(grid, points, basis=grid_functions(basis)), np.repeat(h / 4.0, _LOCAL.size)
