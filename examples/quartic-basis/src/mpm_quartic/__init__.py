"""The uniform quartic B-spline as an mpm-fem basis: a C3 point basis with numpy rows only.

    S_ip = N((x_p - x_i)/h),  G_ip = N'((x_p - x_i)/h) / h,
    N(r) = 115/192 - 5/8 r^2 + 1/4 r^4                        |r| <= 1/2
           55/96 + 5/24 |r| - 5/4 r^2 + 5/6 |r|^3 - 1/6 r^4   1/2 <= |r| <= 3/2
           (5/2 - |r|)^4 / 24                                 3/2 <= |r| <= 5/2

at the six nodes ``c - 2 .. c + 3`` of the particle's cell ``c``; the splines of the ghost nodes
beyond a wall are folded into the end node (the partition of unity holds on the whole grid; linears
are reproduced only two cells or more from a wall). It ships no compiled kernels (``kernels =
None``): mpm-fem runs it on its numpy step and says so.
"""

from __future__ import annotations

import numpy as np

from mpm_fem.bases import Basis, Shape, locate
from mpm_fem.measure.method import quadrature_points

__all__ = ["Quartic", "quartic_bspline"]


def quartic_bspline(r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``N(r)`` and ``N'(r)`` (module docstring)."""
    a = np.abs(r)
    sign = np.sign(r)
    inner, middle, outer = a <= 0.5, (a > 0.5) & (a <= 1.5), (a > 1.5) & (a < 2.5)
    value = np.where(inner, 115 / 192 - 5 / 8 * a**2 + a**4 / 4,
                     np.where(middle, 55 / 96 + 5 / 24 * a - 5 / 4 * a**2 + 5 / 6 * a**3 - a**4 / 6,
                              np.where(outer, (2.5 - a) ** 4 / 24, 0.0)))
    slope = np.where(inner, -5 / 4 * a + a**3,
                     np.where(middle, 5 / 24 - 5 / 2 * a + 5 / 2 * a**2 - 2 / 3 * a**3,
                              np.where(outer, -((2.5 - a) ** 3) / 6, 0.0)))
    return value, slope * sign


class Quartic(Basis):
    """The quartic B-spline basis (module docstring)."""

    name = "quartic"
    title = "C3 quartic B-splines (mpm-quartic)"
    width = 6
    grid_functions = "quartic"
    domain = False
    domain_twin = "bspline_gimp"  # the grid volume reset's particle-domain rows (not used by the point runs here)
    degree = 4
    uniform = True
    kernels = None

    def shape(self, grid, x, volume=None) -> Shape:
        self.check_grid(grid)
        cell, xi = locate(grid, x)
        offsets = np.arange(-2, 4)
        S, dS = quartic_bspline(xi[:, None] - offsets)
        nodes = np.clip(cell[:, None] + offsets, 0, grid.n_nodes - 1)
        return Shape(nodes, S, dS / grid.h[0], grid.n_nodes, cell)

    def integrals(self, grid) -> np.ndarray:
        points, weights = quadrature_points(grid)
        return self.shape(grid, points).scatter(weights)
