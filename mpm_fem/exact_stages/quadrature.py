"""The exact projection's quadrature: composite Gauss-Legendre on pieces of the grid's domain.

The domain is cut at every node, every cell midpoint (the knots of the quadratic B-splines) and
every breakpoint of the exact fields inside it (:func:`_pieces`). Each piece ``[a, a + d]`` carries
``GAUSS_POINTS`` points and weights

    x_g = (a + d/2) + (d/2) xi_g,      w_g = (d/2) W_g,      (xi_g, W_g): Gauss-Legendre on [-1, 1],

exact for polynomials of degree ``2 GAUSS_POINTS - 1`` on a piece: to round-off for the integrands
of piecewise-polynomial fields. :func:`quadrature` gives the points and weights flat,
``(n_pieces GAUSS_POINTS,)``, in order along the domain.

:class:`QuadratureRule` (one per grid and grid functions, :func:`quadrature_rule`) holds the fixed
pieces (nodes and half cells) with the grid functions' rows at their points; per step it evaluates
only the pieces that breakpoints cut (:class:`Cuts`) and splices their sub-pieces in. Invariant: its
points, weights and rows equal ``quadrature(grid, breakpoints)`` and ``make_shape(grid, x, w,
functions)`` bit for bit. The FE mass (:mod:`mpm_fem.exact_stages.mass`) is built on the same fixed
pieces and splices the same :class:`Cuts`.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property, lru_cache

import numpy as np

import mpm_fem.exact_stages.grid_kernels as grid_kernels
from mpm_fem.bases import get
from mpm_fem.core.grid import Grid
from mpm_fem.core.shape import Shape, make_shape

GAUSS_POINTS = 5  # exact for polynomials of degree 9 (Sod's fan: rho u S_i has degree 7)
_XI, _W = np.polynomial.legendre.leggauss(GAUSS_POINTS)


def _pieces(grid: Grid, breakpoints=()) -> np.ndarray:
    """Edges of the pieces of the domain: every node, every cell midpoint (the knots of the
    quadratic B-splines) and every breakpoint inside it."""
    a, b = grid.domain
    cuts = [grid.nodes, 0.5 * (grid.nodes[:-1] + grid.nodes[1:])]
    inner = np.asarray(breakpoints, dtype=float)
    cuts.append(inner[(inner > a) & (inner < b)])
    return np.unique(np.concatenate(cuts))


def quadrature(grid: Grid, breakpoints=()) -> tuple[np.ndarray, np.ndarray]:
    """Points and weights of the composite Gauss-Legendre rule on the grid's domain: ``GAUSS_POINTS``
    points on each piece of :func:`_pieces` (split at nodes, half cells and breakpoints)."""
    edges = _pieces(grid, breakpoints)
    return _gauss(edges[:-1], np.diff(edges))


def _gauss(left: np.ndarray, width: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``GAUSS_POINTS`` Gauss-Legendre points and weights on each piece ``[left, left + width]``."""
    x = (left + 0.5 * width)[:, None] + 0.5 * width[:, None] * _XI
    w = 0.5 * width[:, None] * _W
    return x.ravel(), w.ravel()


@dataclass(frozen=True, eq=False)
class Cuts:
    """The fixed pieces (nodes and half cells) that the breakpoints of one time cut, and the
    sub-pieces that replace them, with their Gauss points, weights and rows: what
    :class:`QuadratureRule` and :class:`~mpm_fem.exact_stages.mass.FEMass` (the same fixed pieces)
    both splice in, made once a step (:meth:`QuadratureRule.cuts`)."""

    cut: np.ndarray  # (n_cut,) the cut pieces, increasing
    first: np.ndarray  # (n_cut + 1,) each cut piece's first sub-piece, then the number of sub-pieces
    x: np.ndarray  # (n_sub, GAUSS_POINTS) the sub-pieces' Gauss points
    w: np.ndarray  # (n_sub, GAUSS_POINTS) and weights
    rows: Shape  # rows of the points x, as (n_sub, GAUSS_POINTS, k) arrays


@dataclass(frozen=True, eq=False)
class QuadratureRule:
    """:func:`quadrature` with the grid functions at its points, for one grid: the points, weights
    and rows ``S_qi``, ``S_i'(x_q)`` of the fixed pieces (nodes and half cells) are evaluated once
    (:func:`quadrature_rule`); per step only the pieces that a breakpoint cuts are evaluated again,
    on their sub-pieces (:meth:`cuts`), and spliced in at their place (:meth:`splice`). The points,
    weights and rows are those of ``quadrature(grid, breakpoints)`` and ``make_shape(grid, x, w,
    functions)`` bit for bit (each row depends on its own point only)."""

    grid: Grid
    functions: str
    edges: np.ndarray  # (n_pieces + 1,) the fixed pieces
    x: np.ndarray  # (n_pieces, GAUSS_POINTS)
    w: np.ndarray  # (n_pieces, GAUSS_POINTS)
    rows: Shape  # rows of the points x, as (n_pieces, GAUSS_POINTS, k) arrays

    @cached_property
    def _cells(self) -> np.ndarray:
        """(2, n_cells): the cell sizes ``h_c`` and ``1 / h_c``, as the compiled rows read them."""
        return np.ascontiguousarray([self.grid.h, 1.0 / self.grid.h], dtype=float)

    def __call__(self, breakpoints) -> tuple[np.ndarray, np.ndarray, Shape]:
        """``(x, w, shape)`` of the rule split at ``breakpoints`` (those inside the domain)."""
        return self.splice(self.cuts(breakpoints))

    def cuts(self, breakpoints) -> Cuts:
        """The pieces cut by ``breakpoints`` (those inside the domain) and their sub-pieces: the
        compiled :func:`~mpm_fem.exact_stages.grid_kernels.cut_pieces`, equal bit for bit to :meth:`cuts_numpy`;
        :meth:`cuts_numpy` itself for grid functions without a compiled row (a basis from outside the
        package with ``kernels = None``)."""
        if get(self.functions).kernels is None:
            return self.cuts_numpy(breakpoints)
        bp = np.ascontiguousarray(breakpoints, dtype=float).ravel()
        grid = self.grid
        cut, first, x, w, nodes, S, G, cell = grid_kernels.cut_pieces(self.functions)(
            self.edges, bp, _XI, _W, grid.nodes, self._cells)
        return Cuts(cut, first, x, w, Shape(nodes, S, G, grid.n_nodes, cell))

    def cuts_numpy(self, breakpoints) -> Cuts:
        """The readable reference of :meth:`cuts`: :func:`_gauss` and :func:`~mpm_fem.core.shape.make_shape`
        on the sub-pieces."""
        bp = np.asarray(breakpoints, dtype=float).ravel()
        n = self.x.shape[0]
        piece = np.searchsorted(self.edges, bp, side="right") - 1
        inside = (piece >= 0) & (piece < n) & (bp > self.edges[np.clip(piece, 0, n)])
        cut = np.unique(piece[inside])
        edges = np.unique(np.concatenate((self.edges[cut], self.edges[cut + 1], bp[inside])))
        owner = np.searchsorted(self.edges, 0.5 * (edges[:-1] + edges[1:])) - 1
        keep = np.isin(owner, cut)
        x, w = _gauss(edges[:-1][keep], np.diff(edges)[keep])
        k = GAUSS_POINTS
        if x.size:
            sub = make_shape(self.grid, x, w, self.functions)
            rows = Shape(*(a.reshape(-1, k, *a.shape[1:]) for a in (sub.nodes, sub.S, sub.G)), self.grid.n_nodes,
                         sub.cell.reshape(-1, k))
        else:
            rows = Shape(*(a[:0] for a in (self.rows.nodes, self.rows.S, self.rows.G)), self.grid.n_nodes,
                         self.rows.cell[:0])
        first = np.append(np.searchsorted(owner[keep], cut), keep.sum())  # each cut piece's first sub-piece
        return Cuts(cut, first, x.reshape(-1, k), w.reshape(-1, k), rows)

    def splice(self, cuts: Cuts) -> tuple[np.ndarray, np.ndarray, Shape]:
        """``(x, w, shape)``: the fixed pieces with the cut ones replaced by their sub-pieces, in
        order along the domain (the compiled :func:`~mpm_fem.exact_stages.grid_kernels.splice`, equal to
        :meth:`splice_numpy`)."""
        fixed = (self.x, self.w, self.rows.nodes, self.rows.S, self.rows.G, self.rows.cell)
        if cuts.cut.size == 0:
            return self._flat(fixed)
        sub = (cuts.x, cuts.w, cuts.rows.nodes, cuts.rows.S, cuts.rows.G, cuts.rows.cell)
        return self._flat(grid_kernels.splice(fixed, sub, cuts.cut, cuts.first))

    def splice_numpy(self, cuts: Cuts) -> tuple[np.ndarray, np.ndarray, Shape]:
        """The readable reference of :meth:`splice`: runs of fixed pieces and of sub-pieces, concatenated."""
        fixed = (self.x, self.w, self.rows.nodes, self.rows.S, self.rows.G, self.rows.cell)
        sub = (cuts.x, cuts.w, cuts.rows.nodes, cuts.rows.S, cuts.rows.G, cuts.rows.cell)
        runs = _runs(cuts.cut.tolist(), cuts.first.tolist(), self.x.shape[0])
        return self._flat([np.concatenate([(f, s)[j][lo:hi] for j, lo, hi in runs])
                           for f, s in zip(fixed, sub, strict=True)])

    def _flat(self, parts) -> tuple[np.ndarray, np.ndarray, Shape]:
        x, w, nodes, S, G, cell = parts
        k = nodes.shape[-1]
        shape = Shape(nodes.reshape(-1, k), S.reshape(-1, k), G.reshape(-1, k), self.grid.n_nodes, cell.ravel())
        return x.ravel(), w.ravel(), shape


def _runs(cut: list, first: list, n: int) -> list:
    """How the pieces follow each other along the domain when each cut piece ``cut[j]`` is replaced
    by its sub-pieces ``first[j] ... first[j + 1] - 1``: runs ``(0, lo, hi)`` of the fixed pieces
    ``lo ... hi - 1`` and ``(1, lo, hi)`` of the sub-pieces."""
    runs, start = [], 0
    for j, c in enumerate(cut):  # a few breakpoints, not nodes
        runs += [(0, start, c), (1, first[j], first[j + 1])]
        start = c + 1
    return runs + [(0, start, n)]


@lru_cache(maxsize=8)
def quadrature_rule(grid: Grid, functions: str) -> QuadratureRule:
    """:class:`QuadratureRule` of ``grid`` for the grid functions ``"mpm"`` or ``"bspline"``."""
    edges = _pieces(grid)
    x, w = _gauss(edges[:-1], np.diff(edges))
    rows = make_shape(grid, x, w, functions)
    k, m = GAUSS_POINTS, edges.size - 1
    rows = Shape(rows.nodes.reshape(m, k, -1), rows.S.reshape(m, k, -1), rows.G.reshape(m, k, -1), grid.n_nodes,
                 rows.cell.reshape(m, k))
    return QuadratureRule(grid, functions, edges, x.reshape(m, k), w.reshape(m, k), rows)
