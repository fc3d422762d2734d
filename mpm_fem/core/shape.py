"""The grid basis at the particles: ``S_ip`` and its derivative ``G_ip``.

Slides, "MPM Basis Overview":

    point mass (standard MPM)   S_ip = S_i(x_p),                       G_ip = S_i'(x_p)
    particle domain (GIMP)      S_ip = 1/V_p int S_i(x) chi_p(x) dx,    G_ip = 1/V_p int S_i'(x) chi_p(x) dx

with ``chi_p`` the indicator of the particle's domain ``[x_p - V_p/2, x_p + V_p/2]`` (1D volume =
length). A particle touches only a few nodes, so both are stored compactly: row ``p`` of the
(n_p, k) arrays ``nodes``, ``S``, ``G`` holds the nodes it touches and its weights there. The
transfers are then a ``np.bincount`` (scatter, particles -> grid) and a row sum of a gather
(grid -> particles): O(n_p k) per call, no Python loop over particles or nodes.

The cell of a point and its local coordinate come from the mesh's own node coordinates, exactly as
scikit-fem's ``MeshLine1`` mapping computes them, so the point-mass kernel agrees with
``Basis.probes`` (values) and ``gbasis`` (derivatives) to round-off.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from mpm_fem.core.grid import Grid

BASES = ("mpm", "gimp", "bspline", "bspline_gimp")
# the grid functions S_i(x) behind each basis (the particle-domain bases average them over chi_p)
GRID_FUNCTIONS = {"mpm": "mpm", "gimp": "mpm", "bspline": "bspline", "bspline_gimp": "bspline"}


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


def point_shape(grid: Grid, x: np.ndarray) -> Shape:
    """Standard MPM: P1 hats at the particle points, ``S = (1 - xi, xi)``, ``G = (-1, 1)/h_c``."""
    cell, xi = locate(grid, x)
    inv_h = 1.0 / grid.h[cell]
    n = cell.size
    nodes, S, G = np.empty((n, 2), np.intp), np.empty((n, 2)), np.empty((n, 2))
    nodes[:, 0], nodes[:, 1] = cell, cell + 1
    S[:, 0], S[:, 1] = 1.0 - xi, xi
    G[:, 0], G[:, 1] = -inv_h, inv_h
    return Shape(nodes, S, G, grid.n_nodes, cell)


def _hat_and_integral(grid: Grid, i: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``S_i(y)`` and ``int_{-inf}^y S_i`` for node indices ``i`` (any shape, broadcast with y).

    End nodes carry a half hat: their missing neighbour is taken as the node itself (zero width).
    """
    xpad = np.concatenate(([grid.nodes[0]], grid.nodes, [grid.nodes[-1]]))
    xl, xc, xr = xpad[i], xpad[i + 1], xpad[i + 2]
    hl, hr = xc - xl, xr - xc
    with np.errstate(divide="ignore", invalid="ignore"):
        yl = np.clip(y, xl, xc)
        yr = np.clip(y, xc, xr)
        left = np.where(hl > 0, (yl - xl) ** 2 / (2 * hl), 0.0)
        right = np.where(hr > 0, (hr**2 - (xr - yr) ** 2) / (2 * hr), 0.0)
        in_left = (y >= xl) & (y < xc) & (hl > 0)
        in_right = (y >= xc) & (y <= xr) & (hr > 0)
        value = np.where(in_left, (y - xl) / hl, 0.0) + np.where(in_right, (xr - y) / hr, 0.0)
    # y exactly on node xc from the left of a node with hl == 0 (the first node): value 1
    value = np.where((y == xc) & (hr == 0) & (hl > 0), 1.0, value)
    return value, left + right


def _particle_domains(grid: Grid, x, volume, who: str):
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


def gimp_shape(grid: Grid, x: np.ndarray, volume: np.ndarray) -> Shape:
    """GIMP: hats averaged over the particle domain ``[x_p - V_p/2, x_p + V_p/2]``.

    ``S_ip = (Phi_i(x_p + l) - Phi_i(x_p - l)) / (2 l)`` and ``G_ip = (S_i(x_p + l) - S_i(x_p - l))
    / (2 l)`` with ``Phi_i`` the antiderivative of ``S_i``. A domain that reaches past the end of
    the grid is cut at the boundary (and the average taken over what is left), which keeps the
    partition of unity at walls.
    """
    cell, lo, hi, c_lo, c_hi = _particle_domains(grid, x, volume, "GIMP needs")
    k = int((c_hi - c_lo).max()) + 2
    nodes = np.minimum(c_lo[:, None] + np.arange(k), grid.n_nodes - 1)
    s_hi, phi_hi = _hat_and_integral(grid, nodes, hi[:, None])
    s_lo, phi_lo = _hat_and_integral(grid, nodes, lo[:, None])
    # columns clipped onto the last node would count it twice: zero them
    dup = np.zeros_like(nodes, dtype=bool)
    dup[:, 1:] = nodes[:, 1:] == nodes[:, :-1]
    length = (hi - lo)[:, None]
    S = np.where(dup, 0.0, (phi_hi - phi_lo) / length)
    G = np.where(dup, 0.0, (s_hi - s_lo) / length)
    return Shape(nodes, S, G, grid.n_nodes, cell)


def _quadratic_bspline(r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``N(r)`` and ``N'(r)`` of the uniform quadratic B-spline centred at 0, support |r| < 3/2."""
    a = np.abs(r)
    inner = a <= 0.5
    outer = (a > 0.5) & (a < 1.5)
    value = np.where(inner, 0.75 - r * r, np.where(outer, 0.5 * (1.5 - a) ** 2, 0.0))
    slope = np.where(inner, -2.0 * r, np.where(outer, -(1.5 - a) * np.sign(r), 0.0))
    return value, slope


def bspline_shape(grid: Grid, x: np.ndarray) -> Shape:
    """A C1 basis: nodal quadratic B-splines on a uniform grid (Steffen, Kirby & Berzins 2008).

    ``S_ip = N((x_p - x_i)/h)``, ``G_ip = N'((x_p - x_i)/h)/h`` with ``N`` the quadratic B-spline,
    ``N(r) = 3/4 - r^2`` for ``|r| <= 1/2``, ``(3/2 - |r|)^2 / 2`` for ``1/2 <= |r| <= 3/2``. The
    spline of the ghost node outside each end is folded into the end node, which keeps the
    partition of unity on the whole grid. ``S_ip`` and ``G_ip`` are continuous in ``x_p``: a particle
    crossing a node sees no jump in ``dS/dx`` (slides: the jump in the third derivative of ``x_p``).
    """
    h = grid.h
    if np.ptp(h) > 1e-9 * h.max():
        raise ValueError("the quadratic B-spline basis needs a uniform grid")
    cell, xi = locate(grid, x)
    offsets = np.arange(-1, 3)
    r = xi[:, None] - offsets  # (x_p - x_{c+k}) / h for k = -1, 0, 1, 2
    S, dS = _quadratic_bspline(r)
    nodes = np.clip(cell[:, None] + offsets, 0, grid.n_nodes - 1)
    return Shape(nodes, S, dS / h[0], grid.n_nodes, cell)


def grid_functions(basis: str) -> str:
    """The point basis of the grid functions ``S_i(x)`` of ``basis`` (``"mpm"`` or ``"bspline"``)."""
    if basis not in GRID_FUNCTIONS:
        raise ValueError(f"unknown basis {basis!r}; choose one of {', '.join(BASES)}")
    return GRID_FUNCTIONS[basis]


def basis_integrals(grid: Grid, basis: str = "mpm") -> np.ndarray:
    """``int S_i dx`` over the grid (n_nodes,), the weight that turns a nodal mass into a density.

    P1 (and GIMP, whose averaged hats integrate like P1): the lumped mass of scikit-fem. The
    B-spline (point or particle-domain averaged): two-point Gauss rules on each half cell, exact
    for its piecewise quadratics (an end node with its folded ghost integrates to ``25h/48``, its
    neighbour to ``47h/48``).
    """
    basis = grid_functions(basis)
    if basis == "mpm":
        return grid.lumped_mass
    left, h = grid.nodes[:-1], grid.h
    g = 0.5 + np.array([-1.0, 1.0]) / (2.0 * np.sqrt(3.0))  # Gauss points on [0, 1]
    local = np.concatenate((0.5 * g, 0.5 + 0.5 * g))
    x = (left[:, None] + h[:, None] * local).ravel()
    weights = np.repeat(h / 4.0, local.size)
    return make_shape(grid, x, basis=basis).scatter(weights)


def _bspline_integral(r: np.ndarray) -> np.ndarray:
    """``M(r) = int_{-inf}^r N``, the antiderivative of the quadratic B-spline (0 below -3/2, 1 above 3/2)."""
    r = np.clip(r, -1.5, 1.5)
    u = np.clip(r + 1.5, 0.0, 1.0)  # the part of [r_0, r] in each of the three pieces
    m = np.clip(r, -0.5, 0.5)
    w = np.clip(1.5 - r, 0.0, 1.0)
    return u * u * u / 6.0 + (0.75 * (m + 0.5) - (m * m * m + 0.125) / 3.0) + (1.0 - w * w * w) / 6.0


def bspline_gimp_shape(grid: Grid, x: np.ndarray, volume: np.ndarray) -> Shape:
    """The quadratic B-splines averaged over the particle domain (particle-domain quadrature):

        S_ip = 1/V_p int N((x - x_i)/h) chi_p(x) dx = h (M(r_+) - M(r_-)) / (x_+ - x_-),
        G_ip = 1/V_p int N'((x - x_i)/h)/h chi_p(x) dx = (N(r_+) - N(r_-)) / (x_+ - x_-),

    with ``x_+- = x_p +- V_p/2`` (cut at the ends of the grid, as for GIMP), ``r_+- = (x_+- - x_i)/h``
    and ``M`` the antiderivative of ``N``. The ghost splines outside each end fold into the end
    nodes, as in :func:`bspline_shape`: the partition of unity holds on the whole grid.
    """
    h = grid.h
    if np.ptp(h) > 1e-9 * h.max():
        raise ValueError("the quadratic B-spline basis needs a uniform grid")
    cell, lo, hi, c_lo, c_hi = _particle_domains(grid, x, volume, "the particle-domain B-spline needs")
    a = grid.nodes[0]
    k = int((c_hi - c_lo).max()) + 4
    j = c_lo[:, None] - 1 + np.arange(k)  # spline centres x_j = a + j h, ghosts at j = -1 and n_nodes
    r_lo = (lo[:, None] - a) / h[0] - j
    r_hi = (hi[:, None] - a) / h[0] - j
    length = (hi - lo)[:, None]
    S = h[0] * (_bspline_integral(r_hi) - _bspline_integral(r_lo)) / length
    G = (_quadratic_bspline(r_hi)[0] - _quadratic_bspline(r_lo)[0]) / length
    nodes = np.clip(j, 0, grid.n_nodes - 1)
    return Shape(nodes, S, G, grid.n_nodes, cell)


def make_shape(grid: Grid, x: np.ndarray, volume: np.ndarray | None = None, basis: str = "mpm") -> Shape:
    """``S_ip``, ``G_ip`` for the named basis: ``"mpm"`` (point mass), ``"gimp"``, ``"bspline"`` or
    ``"bspline_gimp"`` (the B-spline averaged over the particle domain)."""
    if basis == "mpm":
        return point_shape(grid, x)
    if basis == "bspline":
        return bspline_shape(grid, x)
    if basis in ("gimp", "bspline_gimp"):
        if volume is None:
            raise ValueError(f"the {basis} basis needs the particle volumes")
        return (gimp_shape if basis == "gimp" else bspline_gimp_shape)(grid, x, volume)
    raise ValueError(f"unknown basis {basis!r}; choose one of {', '.join(BASES)}")
