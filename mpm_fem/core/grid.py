"""The background mesh on scikit-fem.

Notation (slides, "MPM Basis Overview"): nodes ``x_i``, cells ``I_i = [x_{i-1}, x_i]`` of size
``h_i``, P1 hat functions ``S_i(x)``. The consistent mass matrix is

    M_ij = int rho S_i S_j dx          (rho = 1 here: the geometric mass)

assembled with a scikit-fem ``BilinearForm``; the lumped mass is its row sum ``diag(M 1)``. The
fixed-mesh baselines solve with these; the MPM step solves with the particle mass
(:mod:`mpm_fem.core.transfer`), and its exact FE + mass lumping stage with the same form weighted by
the exact density (:func:`mpm_fem.exact_stages.mass.fe_mass`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import scipy.sparse as sp
from skfem import Basis, BilinearForm, ElementLineP1, MeshLine, asm


@BilinearForm
def _mass(u, v, w):
    return u * v


class GridError(ValueError):
    """A mesh that cannot carry the computation (bad spacing, bad domain)."""


@dataclass(frozen=True, eq=False)
class Grid:
    """A 1D mesh of P1 elements with its scikit-fem basis.

    ``nodes`` (n_nodes,) are strictly increasing; ``h`` (n_cells,) the cell sizes.
    """

    nodes: np.ndarray
    mesh: MeshLine = field(repr=False)
    basis: Basis = field(repr=False)

    @property
    def n_nodes(self) -> int:
        return self.nodes.size

    @property
    def n_cells(self) -> int:
        return self.nodes.size - 1

    @cached_property
    def h(self) -> np.ndarray:
        return np.diff(self.nodes)

    @property
    def domain(self) -> tuple[float, float]:
        return float(self.nodes[0]), float(self.nodes[-1])

    @cached_property
    def uniform_spacing(self) -> float | None:
        """The mean cell size if all cells agree to 1e-6 relative (round-off of linspace), else None."""
        h = self.h
        return float(h.mean()) if np.ptp(h) <= 1e-6 * h.max() else None

    @cached_property
    def boundary_nodes(self) -> np.ndarray:
        """Indices of the two end nodes, as scikit-fem reports them."""
        return np.sort(self.mesh.boundary_nodes())

    @cached_property
    def consistent_mass(self) -> sp.csr_matrix:
        """``M_ij = int S_i S_j dx`` (n_nodes x n_nodes), assembled by scikit-fem."""
        return asm(_mass, self.basis).tocsr()

    @cached_property
    def lumped_mass(self) -> np.ndarray:
        """Row sums of the consistent mass, ``sum_j M_ij`` = ``int S_i dx`` (n_nodes,)."""
        return np.asarray(self.consistent_mass.sum(axis=1)).ravel()


def grid_from_nodes(nodes) -> Grid:
    """Build a :class:`Grid` on the given node coordinates (uniform or not)."""
    nodes = np.asarray(nodes, dtype=float)
    if nodes.ndim != 1 or nodes.size < 2:
        raise GridError("a grid needs at least two node coordinates in a 1D array")
    if not np.all(np.isfinite(nodes)):
        raise GridError("grid node coordinates must be finite")
    if np.any(np.diff(nodes) <= 0):
        raise GridError("grid node coordinates must be strictly increasing")
    mesh = MeshLine(nodes)
    return Grid(nodes=nodes, mesh=mesh, basis=Basis(mesh, ElementLineP1()))


def n_cells_for(a: float, b: float, h: float) -> int:
    """Number of cells of size ``h`` that tile ``[a, b]``; raises unless h divides b - a."""
    if not (np.isfinite(h) and h > 0):
        raise GridError(f"cell size h must be positive and finite, got h={h}")
    if not b > a:
        raise GridError(f"the domain [{a}, {b}] is empty")
    n = round((b - a) / h)
    if n < 1 or abs(n * h - (b - a)) > 1e-9 * (b - a):
        raise GridError(f"h={h} does not divide the domain [{a}, {b}] into whole cells")
    return int(n)


def uniform_grid(a: float, b: float, h: float) -> Grid:
    """Uniform grid on ``[a, b]`` with cells of size ``h`` (which must divide ``b - a``)."""
    return grid_from_nodes(np.linspace(a, b, n_cells_for(a, b, h) + 1))
