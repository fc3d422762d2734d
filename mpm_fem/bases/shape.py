"""The rows of a basis at the particles: ``S_ip``, ``G_ip`` stored compactly, and the cell of a point.

A particle touches only a few nodes, so ``S_ip`` and its derivative ``G_ip`` are stored compactly:
row ``p`` of the (n_p, k) arrays ``nodes``, ``S``, ``G`` holds the nodes it touches and its weights
there (:class:`Shape`). The transfers are then a ``np.bincount`` (scatter, particles -> grid) and a
row sum of a gather (grid -> particles): O(n_p k) per call, no Python loop over particles or nodes.

The cell of a point and its local coordinate (:func:`locate`) come from the mesh's own node
coordinates, exactly as scikit-fem's ``MeshLine1`` mapping computes them, so the point-mass rows
agree with ``Basis.probes`` (values) and ``gbasis`` (derivatives) to round-off. A particle-domain
basis reads the domain ``[x_p - V_p/2, x_p + V_p/2]`` cut at the grid's ends from
:func:`particle_domains`. Every basis (:class:`mpm_fem.bases.contract.Basis`) returns a :class:`Shape`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp

if TYPE_CHECKING:
    from mpm_fem.core.grid import Grid


class OutsideGridError(ValueError):
    """A particle position that lies outside the mesh (or is not finite)."""


@dataclass(frozen=True, eq=False)
class Shape:
    """``S_ip`` and ``G_ip`` of n_p particles on a grid of ``n_nodes`` nodes.

    ``nodes`` (n_p, k) int: the nodes particle p touches; ``S``, ``G`` (n_p, k): the weights.
    Entries with zero weight may repeat a node; they contribute nothing. ``cell`` (n_p,): the cell
    that holds each particle's position.
    """

    nodes: np.ndarray
    S: np.ndarray
    G: np.ndarray
    n_nodes: int
    cell: np.ndarray

    def scatter(self, q: np.ndarray) -> np.ndarray:
        """Particles -> grid: ``sum_p q_p S_ip`` (n_nodes,)."""
        return np.bincount(self.nodes.ravel(), (self.S * q[:, None]).ravel(), self.n_nodes)

    def scatter_gradient(self, q: np.ndarray) -> np.ndarray:
        """Particles -> grid: ``sum_p q_p G_ip`` (n_nodes,)."""
        return np.bincount(self.nodes.ravel(), (self.G * q[:, None]).ravel(), self.n_nodes)

    def gather(self, f: np.ndarray) -> np.ndarray:
        """Grid -> particles: ``sum_i S_ip f_i`` (n_p,)."""
        return _row_dot(self.S, self.nodes, f)

    def gather_gradient(self, f: np.ndarray) -> np.ndarray:
        """Grid -> particles: ``sum_i G_ip f_i`` (n_p,)."""
        return _row_dot(self.G, self.nodes, f)

    def matrix(self, derivative: bool = False) -> sp.csr_matrix:
        """The (n_p x n_nodes) sparse matrix of ``S_ip`` (or ``G_ip``); duplicates summed."""
        n_p, k = self.nodes.shape
        data = (self.G if derivative else self.S).ravel()
        rows = np.repeat(np.arange(n_p), k)
        return sp.csr_matrix((data, (rows, self.nodes.ravel())), shape=(n_p, self.n_nodes))


def _row_dot(W: np.ndarray, nodes: np.ndarray, f: np.ndarray) -> np.ndarray:
    """``sum_k W[p, k] f[nodes[p, k]]``, column by column (k is 2 to 4): faster than einsum."""
    out = W[:, 0] * f[nodes[:, 0]]
    for k in range(1, W.shape[1]):
        out += W[:, k] * f[nodes[:, k]]
    return out


def locate(grid: Grid, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cell index ``c`` and local coordinate ``xi = (x - x_c)/(x_{c+1} - x_c)`` in [0, 1].

    A point on an interior node belongs to the cell on its right; the last node to the last cell.
    Raises :class:`OutsideGridError` naming the first offending point.
    """
    x = np.asarray(x, dtype=float)
    a, b = grid.nodes[0], grid.nodes[-1]
    bad = ~((x >= a) & (x <= b))  # also catches NaN
    if bad.any():
        p = int(np.flatnonzero(bad)[0])
        raise OutsideGridError(
            f"particle {p} at x={float(x[p])!r} lies outside the grid [{float(a)}, {float(b)}] "
            f"({int(bad.sum())} such particles)"
        )
    last = grid.n_cells - 1
    if grid.uniform_spacing is not None:
        # O(n_p): floor of the scaled coordinate; the few points that round into a neighbouring
        # cell are found again by bisection among the mesh's own nodes
        cell = ((x - a) * (1.0 / grid.uniform_spacing)).astype(np.intp)
        np.clip(cell, 0, last, out=cell)
        x0 = grid.nodes[cell]
        off = (x < x0) | ((x >= grid.nodes[cell + 1]) & (cell < last))
        if off.any():
            cell[off] = np.minimum(np.searchsorted(grid.nodes, x[off], side="right") - 1, last)
            x0 = grid.nodes[cell]
    else:
        cell = np.searchsorted(grid.nodes, x, side="right") - 1
        np.minimum(cell, last, out=cell)
        x0 = grid.nodes[cell]
    xi = (x - x0) / (grid.nodes[cell + 1] - x0)
    return cell, xi


def particle_domains(grid: Grid, x, volume, who: str):
    """The particle domains ``[x_p - V_p/2, x_p + V_p/2]`` cut at the ends of the grid: the cell of
    each particle, the domain ends ``lo, hi`` and their cells. ``who`` names the basis in the error
    raised for a volume that is not positive."""
    x = np.asarray(x, dtype=float)
    volume = np.asarray(volume, dtype=float)
    if np.any(~(volume > 0)):
        p = int(np.flatnonzero(~(volume > 0))[0])
        raise ValueError(f"{who} positive particle volumes; particle {p} has V={volume[p]!r}")
    cell, _ = locate(grid, x)
    lo = np.maximum(x - 0.5 * volume, grid.nodes[0])
    hi = np.minimum(x + 0.5 * volume, grid.nodes[-1])
    c_lo, _ = locate(grid, lo)
    c_hi, _ = locate(grid, hi)
    return cell, lo, hi, c_lo, c_hi
