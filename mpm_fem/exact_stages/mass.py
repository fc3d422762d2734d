"""The exact form of the mass stage: the FE mass matrices of the exact density.

    M_ij = int rho S_i S_j dx      (n_nodes, n_nodes), sparse, symmetric to round-off,
    m_i  = sum_j M_ij = int rho S_i dx      (the grid functions sum to 1),

with ``S_i`` the grid functions (P1 hats, the quadratic or the cubic B-splines) and ``rho`` the density of the
problem's :class:`~mpm_fem.exact_stages.fields.ExactFields` at time ``t``. The integrals are
scikit-fem's, on the pieces of :mod:`mpm_fem.exact_stages.quadrature` (nodes, half cells and the
breakpoints) with ``GAUSS_POINTS`` points each: exact to round-off for piecewise-polynomial
densities. :func:`fe_mass_operator` evaluates what depends on the mesh once per grid
(:class:`FEMass`); :func:`fe_mass` sums the density into it every step.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import scipy.sparse as sp
from skfem import Basis, ElementLineP1, ElementLineP2, ElementLinePp, MeshLine

import mpm_fem.exact_stages.grid_kernels as grid_kernels
from mpm_fem.bases import get
from mpm_fem.core.grid import Grid
from mpm_fem.core.shape import grid_functions, make_shape
from mpm_fem.exact_stages.fields import ExactFields
from mpm_fem.exact_stages.quadrature import GAUSS_POINTS, Cuts, _pieces, quadrature_rule


@dataclass(frozen=True, eq=False)
class FEMass:
    """The FE mass matrices of a density on one grid: :func:`fe_mass`'s operator, built once per
    grid and basis (:func:`fe_mass_operator`).

    What depends on the mesh only is evaluated once, by scikit-fem: a ``Basis`` on the fixed pieces
    of :func:`~mpm_fem.exact_stages.quadrature._pieces` (nodes and half cells; P1, or P2 for the
    B-splines) gives the Gauss points ``x_q`` (``GAUSS_POINTS`` per piece), the weights ``dx_q``
    (Gauss weight times Jacobian) and its element functions there. The grid functions are
    polynomials of the piece's element, ``S_i = sum_k S_i(y_k) phi_k`` over its degrees of freedom
    ``y_k``, which gives ``S_qi = S_i(x_q)``. Per step only the density is evaluated and summed, a
    sparse matrix-vector product onto the entries of ``M`` (``assemble``, row ``(i, j)`` holding
    ``S_qi S_qj``):

        M_ij = sum_q dx_q rho(x_q) S_qi S_qj,      m_i = sum_j M_ij.

    A piece that a breakpoint of the exact fields cuts (the density jumps or kinks there) drops out,
    and its sub-pieces come in with the same Gauss rule: the sum is exact for piecewise-polynomial
    densities, as scikit-fem's assembly on the split mesh is.
    """

    grid: Grid
    functions: str
    edges: np.ndarray  # (n_pieces + 1,) the fixed pieces
    points: np.ndarray  # (n_pieces, GAUSS_POINTS) scikit-fem's Gauss points x_q
    dx: np.ndarray  # (n_pieces, GAUSS_POINTS) its weights dx_q
    assemble: sp.csr_matrix  # (nnz of M, n_points): S_qi S_qj in the row of the entry (i, j)
    pattern: sp.csr_matrix  # M's sparsity pattern, data: the keys i n_nodes + j of its entries
    mirror: np.ndarray  # per entry (i, j): (j, i) where i > j and their rows of assemble are equal, else itself

    def __call__(self, fields: ExactFields, t: float, cuts: Cuts | None = None,
                 assembled: bool = True) -> tuple[sp.csr_matrix, np.ndarray]:
        """``(M, m)`` of the exact density of ``fields`` at time ``t``. ``cuts``: the pieces the
        breakpoints cut (:meth:`~mpm_fem.exact_stages.quadrature.QuadratureRule.cuts`), when the
        caller has made them already; ``assembled=False``: ``M`` is a function of no arguments
        that assembles it (the lumped solves need ``m`` only)."""
        data = self.entries(fields, t, cuts)
        m = np.add.reduceat(data, self.pattern.indptr[:-1])
        return (self._matrix(data) if assembled else lambda: self._matrix(data)), m

    def _matrix(self, data: np.ndarray) -> sp.csr_matrix:
        return sp.csr_matrix((data, self.pattern.indices, self.pattern.indptr), self.pattern.shape)

    def _density(self, fields: ExactFields, t: float, cuts: Cuts | None) -> tuple[Cuts, np.ndarray]:
        """The cut pieces, and the density at the fixed Gauss points then at the sub-pieces' points."""
        if cuts is None:
            cuts = quadrature_rule(self.grid, self.functions).cuts(fields.breakpoints(t))
        return cuts, fields.integrand(np.concatenate((self.points.ravel(), cuts.x.ravel())), t)[0]

    def entries(self, fields: ExactFields, t: float, cuts: Cuts | None = None) -> np.ndarray:
        """The stored entries of ``M`` (in the order of :attr:`pattern`): the compiled
        :func:`~mpm_fem.exact_stages.grid_kernels.fe_entries`, equal bit for bit to :meth:`entries_numpy`."""
        cuts, rho = self._density(fields, t, cuts)
        k = cuts.rows.nodes.shape[-1]
        n = self.points.size
        data, outside = grid_kernels.fe_entries(
            (self.assemble.indptr, self.assemble.indices, self.assemble.data), self.mirror, self.dx,
            rho[:n].reshape(self.dx.shape), cuts.cut, self.keys, self.grid.n_nodes,
            cuts.rows.nodes.reshape(-1, k), cuts.rows.S.reshape(-1, k), cuts.w.ravel(), rho[n:])
        if outside:
            raise RuntimeError("a sub-piece couples nodes outside the FE mass pattern")
        return data

    def entries_numpy(self, fields: ExactFields, t: float, cuts: Cuts | None = None) -> np.ndarray:
        """The readable reference of :meth:`entries`: ``A (dx rho)`` with the cut pieces' points
        weighted 0, plus the sub-pieces' ``w_q rho_q S_qi S_qj`` summed into their entries."""
        cuts, rho = self._density(fields, t, cuts)
        q = self.dx * np.reshape(rho[: self.points.size], self.dx.shape)
        q[cuts.cut] = 0.0
        data = self.assemble @ q.ravel()
        if cuts.x.size:
            k = cuts.rows.nodes.shape[-1]
            nodes, S, w = cuts.rows.nodes.reshape(-1, k), cuts.rows.S.reshape(-1, k), cuts.w.ravel()
            n = self.grid.n_nodes
            wanted = nodes[:, :, None] * n + nodes[:, None, :]
            entry = np.minimum(np.searchsorted(self.keys, wanted), self.keys.size - 1)
            product = (w * rho[self.points.size:])[:, None, None] * S[:, :, None] * S[:, None, :]
            if np.any((self.keys[entry] != wanted) & (product != 0)):
                raise RuntimeError("a sub-piece couples nodes outside the FE mass pattern")
            data = data + np.bincount(entry.ravel(), product.ravel(), self.keys.size)
        return data

    @property
    def keys(self) -> np.ndarray:
        """``i n_nodes + j`` of each stored entry ``(i, j)`` of ``M``, increasing."""
        return self.pattern.data


def _element(degree: int):
    """scikit-fem's line element of polynomials of ``degree`` on each piece: the grid functions of
    that degree are exactly its combinations (the pieces split at their knots)."""
    return {1: ElementLineP1, 2: ElementLineP2}.get(degree, lambda: ElementLinePp(degree))()


@lru_cache(maxsize=8)
def fe_mass_operator(grid: Grid, functions: str) -> FEMass:
    """:class:`FEMass` of ``grid`` for the grid functions ``"mpm"`` (P1 hats) or ``"bspline"``; one
    per grid (a run builds it at its first step)."""
    edges = _pieces(grid)
    pieces = Basis(MeshLine(edges), _element(get(functions).degree), intorder=2 * GAUSS_POINTS - 1)
    points = np.asarray(pieces.global_coordinates()[0])
    if points.shape != (edges.size - 1, GAUSS_POINTS):
        raise RuntimeError(f"scikit-fem's rule has {points.shape[1]} points per piece, not {GAUSS_POINTS}")
    n = points.size
    phi = sp.csr_matrix((np.concatenate([np.asarray(f[0]).ravel() for f in pieces.basis]),
                         (np.tile(np.arange(n), len(pieces.basis)),
                          np.concatenate([np.repeat(d, GAUSS_POINTS) for d in pieces.element_dofs]))),
                        shape=(n, pieces.N))
    y = pieces.doflocs[0]
    if np.all(np.isfinite(y)):  # a nodal element (P1, P2): S_qi = S_i(x_q) through its functions
        S = (phi @ make_shape(grid, y, np.zeros_like(y), functions).matrix()).tocsr()
    else:  # ElementLinePp (degree > 2): its interior dofs are not point values; S_qi = S_i(x_q) directly
        S = make_shape(grid, points.ravel(), np.zeros(n), functions).matrix().tocsr()
    S.sort_indices()
    # the nonzeros of each row q padded to k columns (a repeated column with value 0)
    counts = np.diff(S.indptr)
    k = int(counts.max())
    slot = np.minimum(np.arange(k), counts[:, None] - 1) + S.indptr[:-1, None]
    cols = S.indices[slot]
    vals = np.where(np.arange(k) < counts[:, None], S.data[slot], 0.0)
    pattern = (S.T @ S).tocsr()
    pattern.sort_indices()
    key = np.repeat(np.arange(grid.n_nodes), np.diff(pattern.indptr)) * grid.n_nodes + pattern.indices
    entry = np.searchsorted(key, cols[:, :, None] * grid.n_nodes + cols[:, None, :])
    assemble = sp.csr_matrix(((vals[:, :, None] * vals[:, None, :]).ravel(),
                              (entry.ravel(), np.repeat(np.arange(n), k * k))), shape=(key.size, n))
    pattern.data = key
    return FEMass(grid, functions, edges, points, np.ascontiguousarray(pieces.dx), assemble, pattern,
                  _mirror(assemble, key, grid.n_nodes))


def _mirror(assemble: sp.csr_matrix, key: np.ndarray, n: int) -> np.ndarray:
    """Per entry ``(i, j)`` of ``M``: the entry ``(j, i)`` where ``i > j`` and its row of ``assemble``
    holds the same points and values, bit for bit (``S_qi S_qj = S_qj S_qi``: ``M_ij`` is then
    ``M_ji`` bit for bit, summed once), else the entry itself."""
    entry = np.arange(key.size)
    i, j = key // n, key % n
    transposed = np.minimum(np.searchsorted(key, j * n + i), key.size - 1)
    lengths = np.diff(assemble.indptr)
    cand = np.flatnonzero((i > j) & (key[transposed] == j * n + i))
    cand = cand[lengths[cand] == lengths[transposed[cand]]]
    size = lengths[cand]
    offset = np.arange(size.sum()) - np.repeat(np.cumsum(size) - size, size)
    here = np.repeat(assemble.indptr[cand], size) + offset
    there = np.repeat(assemble.indptr[transposed[cand]], size) + offset
    bits = assemble.data.view(np.int64)
    differ = (assemble.indices[here] != assemble.indices[there]) | (bits[here] != bits[there])
    same = np.bincount(np.repeat(np.arange(cand.size), size), differ, cand.size) == 0
    mirror = entry.copy()
    mirror[cand[same]] = transposed[cand[same]]
    return mirror


def fe_mass(grid: Grid, basis: str, fields: ExactFields, t: float, cuts: Cuts | None = None,
            assembled: bool = True) -> tuple[sp.csr_matrix, np.ndarray]:
    """The FE mass matrices of the exact density (:class:`FEMass`):

        M_ij = int rho S_i S_j dx,      m_i = sum_j M_ij,

    the lumped mass being the row sums (``= int rho S_i dx``: the grid functions sum to 1). ``S_i``
    are the grid functions of ``basis`` (P1 hats, or quadratic B-splines for the B-spline bases).
    ``cuts`` and ``assembled``: as :meth:`FEMass.__call__`."""
    return fe_mass_operator(grid, grid_functions(basis))(fields, t, cuts, assembled)
