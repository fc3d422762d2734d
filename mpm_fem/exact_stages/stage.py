"""The exact forms of the stages of the MPM step (ARCHITECTURE.md, "The stage switches").

The slides ("Explicit MPM Algorithm Errors") name four sources of error: projection,
interpolation, time, and finite element + mass lumping. Each stage of :func:`mpm_fem.core.step.
explicit_step` can be replaced by an exact form that removes the error *that stage adds*, while
the errors carried in from the stages before it pass through unchanged. That is what makes the
error budget (E1) additive. With ``f*`` the exact field a stage should deliver:

    projection (particles -> grid)      m_i = int rho S_i dx,  P_i = int rho v S_i dx,
                                        F_i = - int sigma S_i' dx
                                        (composite Gauss-Legendre, split at the cell nodes, the
                                        half cells and the problem's breakpoints: exact to
                                        round-off for piecewise-polynomial fields)
    mass (FE + lumping, grid solve)     u_i = u*(x_i) + [solve(MPM data) - solve(exact data)]:
                                        the solve makes no error of its own on exact data
                                        (exact data: the FE mass matrices of the exact density
                                        on scikit-fem's basis, :func:`fe_mass`)
    interpolation (grid -> particles)   f_p = f*(x_p) + sum_i S_ip (f_i - f*_i): the interpolant is
                                        exact for the exact field; the nodal error still reaches
                                        the particle
    time                                dt -> dt / k (``Stages.refine``)

``solve`` is the lumped division ``rhs_i / m_i`` (the MPM default) and ``f*_i`` are the exact
nodal values with the boundary conditions applied (the grid's boundary rule is part of the
scheme). Every stage exact leaves semi-implicit Euler on the exact fields:

    v_p^{n+1} = v_p^n + dt a*(x_p^n, t^n),    x_p^{n+1} = x_p^n + dt (v* + dt a*)(x_p^n, t^n),
    (dv/dx)_p = v*_x(x_p^n, t^{n+1})  (USL; USF: t^n),

so the remainder is the time error of the (refined) step alone.

A problem supplies its exact fields through :class:`ExactFields`: point values for the
projection integrals, and the *reference* fields ``v*``, ``v*_x``, ``a* = Dv*/Dt`` that grid and
particle values approximate. A smooth problem (Burgers, :class:`~mpm_fem.problems.burgers.SmoothBurgersFields`) uses the
point values. Across a shock ``v*_x`` and ``a*`` are Dirac masses, so Sod
(:class:`~mpm_fem.problems.sod.RiemannFields`) uses the exact fields averaged over a particle domain of width ``2 l``
(the GIMP ``chi_p``):

    v*(x) = 1/(2l) int_{x-l}^{x+l} u dy,   v*_x = (u(x+l) - u(x-l)) / (2l),   a* = dv*/dt + v* v*_x,

which is ``u + O(l^2)`` where ``u`` is smooth, finite at a shock, and consistent: a point moving
with ``v*`` crosses a shock with the Rankine-Hugoniot density ratio, since
``int v*_x dt = int_{u_1}^{u_2} du/(s - u) = log((s - u_1)/(s - u_2))``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from typing import Callable, Protocol

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve
from skfem import Basis, ElementLineP1, ElementLineP2, MeshLine

from mpm_fem.exact_stages import grid_kernels
from mpm_fem.core.grid import Grid
from mpm_fem.core.shape import Shape, grid_functions, make_shape
from mpm_fem.core.transfer import divide_by_lumped, grid_values, nodal_internal_force, nodal_mass, nodal_momentum

GAUSS_POINTS = 5  # exact for polynomials of degree 9 (Sod's fan: rho u S_i has degree 7)
_XI, _W = np.polynomial.legendre.leggauss(GAUSS_POINTS)


class ExactFields(Protocol):
    """The exact solution as the exact stages need it (all arrays have the shape of ``x``)."""

    def integrand(self, x: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Point values ``(rho, v, sigma)`` integrated by the exact projection."""
        ...

    def breakpoints(self, t: float) -> np.ndarray:
        """Where the integrand may jump or kink at time ``t`` (quadrature splits there)."""
        ...

    def reference(self, x: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Reference fields ``(v*, v*_x, a*)`` at ``x``: what nodal and particle values approximate."""
        ...

    def velocity_gradient(self, x: np.ndarray, t: float) -> np.ndarray:
        """``v*_x`` alone (the second entry of :meth:`reference`)."""
        ...


@dataclass(frozen=True, eq=False)
class GridData:
    """What the projection hands the grid: the kernel and weights of the particles (or quadrature
    points), and ``m_i``, ``P_i``, ``F_i``. The mass matrix is ``matrix`` where given (the FE mass
    of exact data, :func:`fe_mass`, or a function of no arguments that assembles it: the lumped
    solve needs only ``m_i``), else the particle matrix ``M_ij = sum_q w_q S_iq S_jq``."""

    shape: Shape
    mass: np.ndarray
    m_i: np.ndarray
    P_i: np.ndarray
    F_i: np.ndarray | None = field(default=None)
    matrix: sp.csr_matrix | Callable[[], sp.csr_matrix] | None = field(default=None)


def nodal_values(data: GridData, rhs: np.ndarray, kind: str) -> np.ndarray:
    """Grid values from a projected right-hand side: ``rhs_i / m_i`` (``kind="lumped"``) or
    ``M^{-1} rhs`` (``"consistent"``), with ``data``'s FE mass if it has one, else its particles'."""
    if data.matrix is None:
        return grid_values(data.shape, data.mass, data.m_i, rhs, kind)
    if kind == "lumped":
        return divide_by_lumped(rhs, data.m_i)
    if kind == "consistent":
        matrix = data.matrix() if callable(data.matrix) else data.matrix
        return spsolve(matrix.tocsc(), rhs)
    raise ValueError(f"unknown mass kind {kind!r}; choose one of lumped, consistent")


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
    :class:`QuadratureRule` and :class:`FEMass` (the same fixed pieces) both splice in, made once a
    step (:meth:`QuadratureRule.cuts`)."""

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

    def __call__(self, breakpoints) -> tuple[np.ndarray, np.ndarray, Shape]:
        """``(x, w, shape)`` of the rule split at ``breakpoints`` (those inside the domain)."""
        return self.splice(self.cuts(breakpoints))

    def cuts(self, breakpoints) -> Cuts:
        """The pieces cut by ``breakpoints`` (those inside the domain) and their sub-pieces: the
        compiled :func:`~mpm_fem.exact_stages.grid_kernels.cut_pieces`, equal bit for bit to :meth:`cuts_numpy`."""
        bp = np.ascontiguousarray(breakpoints, dtype=float).ravel()
        grid = self.grid
        inv_spacing = 1.0 / grid.uniform_spacing if grid.uniform_spacing is not None else 0.0
        cut, first, x, w, nodes, S, G, cell = grid_kernels.cut_pieces(
            self.edges, bp, _XI, _W, grid.nodes, grid.h, inv_spacing, self.functions == "bspline")
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
        return self._flat(grid_kernels.splice(*fixed, *sub, cuts.cut, cuts.first))

    def splice_numpy(self, cuts: Cuts) -> tuple[np.ndarray, np.ndarray, Shape]:
        """The readable reference of :meth:`splice`: runs of fixed pieces and of sub-pieces, concatenated."""
        fixed = (self.x, self.w, self.rows.nodes, self.rows.S, self.rows.G, self.rows.cell)
        sub = (cuts.x, cuts.w, cuts.rows.nodes, cuts.rows.S, cuts.rows.G, cuts.rows.cell)
        runs = _runs(cuts.cut.tolist(), cuts.first.tolist(), self.x.shape[0])
        return self._flat([np.concatenate([(f, s)[j][lo:hi] for j, lo, hi in runs]) for f, s in zip(fixed, sub)])

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


@dataclass(frozen=True, eq=False)
class FEMass:
    """The FE mass matrices of a density on one grid: :func:`fe_mass`'s operator, built once per
    grid and basis (:func:`fe_mass_operator`).

    What depends on the mesh only is evaluated once, by scikit-fem: a ``Basis`` on the fixed pieces
    of :func:`_pieces` (nodes and half cells; P1, or P2 for the B-splines) gives the Gauss points
    ``x_q`` (``GAUSS_POINTS`` per piece), the weights ``dx_q`` (Gauss weight times Jacobian) and its
    element functions there. The grid functions are polynomials of the piece's element, ``S_i =
    sum_k S_i(y_k) phi_k`` over its degrees of freedom ``y_k``, which gives ``S_qi = S_i(x_q)``. Per
    step only the density is evaluated and summed, a sparse matrix-vector product onto the entries
    of ``M`` (``assemble``, row ``(i, j)`` holding ``S_qi S_qj``):

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
        breakpoints cut (:meth:`QuadratureRule.cuts`), when the caller has made them already;
        ``assembled=False``: ``M`` is a function of no arguments that assembles it (the lumped
        solves need ``m`` only)."""
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
            self.assemble.indptr, self.assemble.indices, self.assemble.data, self.mirror, self.dx,
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


@lru_cache(maxsize=8)
def fe_mass_operator(grid: Grid, functions: str) -> FEMass:
    """:class:`FEMass` of ``grid`` for the grid functions ``"mpm"`` (P1 hats) or ``"bspline"``; one
    per grid (a run builds it at its first step)."""
    edges = _pieces(grid)
    pieces = Basis(MeshLine(edges), ElementLineP2() if functions == "bspline" else ElementLineP1(),
                   intorder=2 * GAUSS_POINTS - 1)
    points = np.asarray(pieces.global_coordinates()[0])
    if points.shape != (edges.size - 1, GAUSS_POINTS):
        raise RuntimeError(f"scikit-fem's rule has {points.shape[1]} points per piece, not {GAUSS_POINTS}")
    n = points.size
    phi = sp.csr_matrix((np.concatenate([np.asarray(f[0]).ravel() for f in pieces.basis]),
                         (np.tile(np.arange(n), len(pieces.basis)),
                          np.concatenate([np.repeat(d, GAUSS_POINTS) for d in pieces.element_dofs]))),
                        shape=(n, pieces.N))
    y = pieces.doflocs[0]
    S = (phi @ make_shape(grid, y, np.zeros_like(y), functions).matrix()).tocsr()  # S_qi = S_i(x_q)
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


def exact_projection(grid: Grid, basis: str, fields: ExactFields, t: float, with_fe_mass: bool = False) -> GridData:
    """``m_i = int rho S_i``, ``P_i = int rho v S_i``, ``F_i = -int sigma S_i'`` of the exact fields.

    The grid functions are the P1 hats for the point-mass and GIMP bases (GIMP averages the same
    hats over the particle domain) and the quadratic B-splines for ``"bspline"`` and ``"bspline_gimp"``.
    The quadrature points act as particles of mass ``w_q rho_q`` and volume ``w_q``, so ``m_i`` and the consistent
    mass ``int rho S_i S_j`` come from the same code as the particle mass matrix. ``with_fe_mass``
    (the exact form of the mass stage): the mass matrices are instead the FE mass of
    :func:`fe_mass` (on scikit-fem's basis), ``m_i`` its row sums (the same integrals).
    """
    rule = quadrature_rule(grid, grid_functions(basis))
    cuts = rule.cuts(fields.breakpoints(t))
    x, w, shape = rule.splice(cuts)
    rho, v, sigma = fields.integrand(x, t)
    M, m_fe = fe_mass(grid, basis, fields, t, cuts=cuts, assembled=False) if with_fe_mass else (None, None)
    m_i, P_i, F_i = nodal_sums(shape, w, rho, v, sigma, with_mass=not with_fe_mass)
    return GridData(shape, w * rho, m_i if m_fe is None else m_fe, P_i, F_i, M)


def nodal_sums(shape: Shape, w: np.ndarray, rho: np.ndarray, v: np.ndarray, sigma: np.ndarray,
               with_mass: bool = True) -> tuple[np.ndarray | None, np.ndarray, np.ndarray]:
    """``m_i`` (``None`` unless ``with_mass``), ``P_i``, ``F_i`` of quadrature points of weight ``w``:
    the compiled :func:`~mpm_fem.exact_stages.grid_kernels.project`, equal bit for bit to :func:`nodal_sums_numpy`."""
    m_i, P_i, F_i = grid_kernels.project(shape.nodes, shape.S, shape.G, w, rho, v, sigma, shape.n_nodes, with_mass)
    return (m_i if with_mass else None), P_i, F_i


def nodal_sums_numpy(shape: Shape, w: np.ndarray, rho: np.ndarray, v: np.ndarray, sigma: np.ndarray,
                     with_mass: bool = True) -> tuple[np.ndarray | None, np.ndarray, np.ndarray]:
    """The readable reference of :func:`nodal_sums` (:mod:`mpm_fem.core.transfer`): the points as
    particles of mass ``w rho`` and volume ``w``."""
    mass = w * rho
    return (nodal_mass(shape, mass) if with_mass else None), nodal_momentum(shape, mass, v), \
        nodal_internal_force(shape, w, sigma)


class ExactGridStage:
    """The grid stage of a step with exact stages (:func:`mpm_fem.core.step.explicit_step`), written once
    for the numpy step and the fused one (:mod:`mpm_fem.fused.step`), which differ in how the particle
    sums ``mpm`` (``m_i``, ``P_i``) and ``F_i`` are made, not in what the grid does with them.

    Built at the start of a step it holds the exact nodal data and ``v_i``:

        projection exact   the quadrature data ``quad`` (:func:`exact_projection`) replace the particles'
        mass exact         v_i = v*_i + [solve(MPM data) - solve(exact data)] (``solve``: the lumped
                           division; exact data with the FE mass when the projection is MPM)
        both exact         v_i = v*_i (and a_i = a*_i: no quadrature data are made)

    and the exact nodal values with the grid's boundary rule, ``star_v = BC(v*_i)``,
    ``star_a = BC(a*_i)``, which the exact interpolation corrects against. :meth:`acceleration`
    gives ``a_i`` from the particles' force ``F_i`` the same way."""

    def __init__(self, grid: Grid, boundary, stages, exact: ExactFields, mpm: GridData, t: float, dt: float):
        self.grid, self.boundary, self.stages, self.mpm, self.t, self.dt = grid, boundary, stages, mpm, t, dt
        fe_mass_stage = stages.mass == "exact" and stages.projection == "mpm"  # solves exact data with the FE mass
        # the quadrature data where a solve reads them (both exact: v_i = v*_i reads none)
        self.quad = (exact_projection(grid, stages.basis, exact, t, with_fe_mass=fe_mass_stage)
                     if (stages.projection == "exact") != (stages.mass == "exact") else None)
        self.source = self.quad if stages.projection == "exact" else mpm
        self.kind = "lumped" if stages.mass == "exact" else stages.mass
        ref_v, _, self.ref_a = exact.reference(grid.nodes, t)
        P_exact = self.quad.P_i if self.quad is not None else None
        self.v_i = boundary.velocity(grid, self.solve(self.source.P_i if self.source is not None else None,
                                                      P_exact, ref_v), t)
        self.star_v = boundary.velocity(grid, ref_v, t)
        self.star_a = boundary.acceleration(grid, self.ref_a, self.star_v, t, dt)

    def solve(self, rhs: np.ndarray, exact_rhs: np.ndarray | None, reference: np.ndarray) -> np.ndarray:
        """Nodal values of a projected right-hand side, the mass stage's form (class docstring)."""
        if self.stages.mass != "exact":
            return nodal_values(self.source, rhs, self.kind)
        if self.stages.projection == "exact":
            return reference.copy()
        # the lumped solves (the mass stage's form) in one compiled pass
        return grid_kernels.corrected(reference, rhs, self.mpm.m_i, exact_rhs, self.quad.m_i)

    def solve_numpy(self, rhs: np.ndarray, exact_rhs: np.ndarray | None, reference: np.ndarray) -> np.ndarray:
        """The readable reference of :meth:`solve` (equal bit for bit): the mass exact and the
        projection MPM give ``v*_i + rhs_i / m_i - rhs*_i / m*_i`` with :func:`nodal_values`."""
        if self.stages.mass == "exact" and self.stages.projection == "mpm":
            return reference + nodal_values(self.mpm, rhs, self.kind) - nodal_values(self.quad, exact_rhs, self.kind)
        return self.solve(rhs, exact_rhs, reference)

    def acceleration(self, F_mpm: np.ndarray | None) -> np.ndarray:
        """``a_i`` from the particles' force ``F_mpm`` (the quadrature's when the projection is exact,
        where ``F_mpm`` may be None), the boundary rule applied."""
        F_i = F_mpm if self.stages.projection == "mpm" else (self.quad.F_i if self.quad is not None else None)
        a_i = self.solve(F_i, self.quad.F_i if self.quad is not None else None, self.ref_a)
        return self.boundary.acceleration(self.grid, a_i, self.v_i, self.t, self.dt)

    @property
    def star_new(self) -> np.ndarray:
        """``star_v + dt star_a``: the exact nodal ``v^{n+1}`` the exact interpolation corrects against."""
        return self.star_v + self.dt * self.star_a
