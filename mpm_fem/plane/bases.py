"""The 2D bases: the tensor product of a registered 1D basis's rows, one factor per axis.

    S_ip   = S^x_a(x_p) S^y_b(y_p),
    G_ip   = (S^x_a'(x_p) S^y_b(y_p),  S^x_a(x_p) S^y_b'(y_p)),          i = a n_y + b,

with ``S^x``, ``S^y`` the rows the 1D basis module gives on each axis (its numpy
:meth:`~mpm_fem.bases.contract.Basis.shape`, called per axis: no shape function is copied here, so
any 1D basis meeting the contract has this 2D form). A particle-domain basis (GIMP, the B-spline
averaged over the particle) takes the particle's lengths per axis ``(l_x, l_y)`` as the 1D
"volume": it averages over the rectangle ``l_x x l_y`` (uGIMP when the lengths are the initial
ones). A basis whose ``tensor`` flag is False is refused before any work.

Rows are stored compactly (:class:`PlaneShape`): ``nodes`` (n_p, K) with ``K = K_x K_y``, ``S``
(n_p, K), ``G`` (n_p, K, 2). The transfers are ``np.bincount`` scatters and row-sum gathers.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from mpm_fem.bases import get
from mpm_fem.bases.contract import Basis
from mpm_fem.plane.grid import PlaneGrid


@dataclass(frozen=True, eq=False)
class PlaneShape:
    """``S_ip`` (n_p, K) and ``G_ip`` (n_p, K, 2) at the nodes ``nodes`` (n_p, K) of a grid of
    ``n_nodes`` nodes. A node may repeat in a row (its weights add)."""

    nodes: np.ndarray
    S: np.ndarray
    G: np.ndarray
    n_nodes: int

    def scatter(self, q: np.ndarray) -> np.ndarray:
        """Particles -> grid: ``sum_p q_p S_ip``, ``q`` (n_p,) -> (n_nodes,) or (n_p, d) -> (n_nodes, d)."""
        if q.ndim == 1:
            return np.bincount(self.nodes.ravel(), (self.S * q[:, None]).ravel(), self.n_nodes)
        return np.column_stack([self.scatter(q[:, k]) for k in range(q.shape[1])])

    def scatter_gradient(self, q: np.ndarray) -> np.ndarray:
        """Particles -> grid: ``sum_p q_p^{ab} G_ip^b`` for ``q`` (n_p, d, 2) -> (n_nodes, d)."""
        Gx, Gy, nodes = self.G[:, :, 0], self.G[:, :, 1], self.nodes.ravel()
        return np.column_stack([np.bincount(nodes, (q[:, a, 0, None] * Gx + q[:, a, 1, None] * Gy).ravel(),
                                            self.n_nodes) for a in range(q.shape[1])])

    def gather(self, f: np.ndarray) -> np.ndarray:
        """Grid -> particles: ``sum_i S_ip f_i``, ``f`` (n_nodes, d) -> (n_p, d)."""
        return np.column_stack([np.sum(self.S * f[self.nodes, a], axis=1) for a in range(f.shape[1])])

    def gather_gradient(self, f: np.ndarray) -> np.ndarray:
        """Grid -> particles: ``sum_i f_i^a G_ip^b`` (n_p, d, 2), for ``f`` (n_nodes, d): the gradient."""
        out = np.empty((self.nodes.shape[0], f.shape[1], 2))
        for a in range(f.shape[1]):  # the components: d x 2 row sums
            fa = f[self.nodes, a]
            out[:, a, 0] = np.sum(fa * self.G[:, :, 0], axis=1)
            out[:, a, 1] = np.sum(fa * self.G[:, :, 1], axis=1)
        return out

    def matrix(self) -> sp.csr_matrix:
        """The (n_p x n_nodes) sparse matrix of ``S_ip``; repeated nodes summed."""
        n_p, k = self.nodes.shape
        rows = np.repeat(np.arange(n_p), k)
        return sp.csr_matrix((self.S.ravel(), (rows, self.nodes.ravel())), shape=(n_p, self.n_nodes))


def tensor_basis(name: str | Basis) -> Basis:
    """The 1D basis ``name`` (registered, or a :class:`~mpm_fem.bases.contract.Basis` instance),
    refused with ``ValueError`` unless it has a tensor form (its ``tensor`` flag)."""
    basis = name if isinstance(name, Basis) else get(name)
    if not getattr(basis, "tensor", False):
        raise ValueError(f"the basis {basis.name!r} has no 2D (tensor-product) form")
    return basis


def plane_shape(grid: PlaneGrid, basis: str | Basis, x: np.ndarray, lengths: np.ndarray | None = None) -> PlaneShape:
    """The rows of the tensor basis of ``basis`` at the particles ``x`` (n_p, 2) with lengths per
    axis ``lengths`` (n_p, 2; a point basis ignores them). Positions on a periodic axis may lie
    outside the domain (they are folded); elsewhere a position outside the grid raises
    :class:`~mpm_fem.bases.shape.OutsideGridError`."""
    basis = tensor_basis(basis)
    rows = []
    for k, axis in enumerate(grid.axes):
        xk = axis.fold(x[:, k])
        shape = basis.shape(axis.line, xk, None if lengths is None else lengths[:, k])
        rows.append((axis.wrap[shape.nodes], shape.S, shape.G))
    (ix, Sx, Gx), (iy, Sy, Gy) = rows
    n_p, kx, ky = x.shape[0], Sx.shape[1], Sy.shape[1]
    nodes = (ix[:, :, None] * grid.shape[1] + iy[:, None, :]).reshape(n_p, kx * ky)
    S = (Sx[:, :, None] * Sy[:, None, :]).reshape(n_p, kx * ky)
    G = np.stack(((Gx[:, :, None] * Sy[:, None, :]).reshape(n_p, kx * ky),
                  (Sx[:, :, None] * Gy[:, None, :]).reshape(n_p, kx * ky)), axis=-1)
    return PlaneShape(nodes, S, G, grid.n_nodes)
