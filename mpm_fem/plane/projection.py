"""The 2D projection errors: the nodal sums of particles against the integrals they stand in for.

The 1D study's question (:mod:`mpm_fem.measure.projection`, claims C4-C10) on the unit square
``[0, 1]^2`` with the tensor grid of :mod:`mpm_fem.plane.grid` (no periodic axis). Particles at ``x_p``
(n_p, 2) with weights ``w_p`` (n_p,) carry the exact values of smooth fields (:func:`smooth_fields`, the
1D fields made 2D): ``m_p = rho(x_p) w_p`` and

    m_i = sum_p m_p S_ip,    P_i = sum_p m_p v_p S_ip,    f_i = - sum_p w_p sigma_p . G_ip,

against the integrals ``int rho S_i``, ``int rho v S_i``, ``- int sigma . grad S_i``, evaluated by the
same sums over the reference quadrature of the 2D exact projection stage (scikit-fem's Gauss rule on
the half cells, :func:`mpm_fem.plane.exact.cell_quadrature`, order :data:`EXACT_ORDER`) whose points
act as particles. The errors are exact minus projected (signed), at the interior nodes (whole tensor
hats): ``E_m``, ``E_P``, ``E_F`` (extensive: ``m_i ~ h^2``), ``E_a = f_i/m_i - f_i^MPM/m_i^MPM``,
``E_v = P_i/m_i - P_i^MPM/m_i^MPM``, ``E_v1 = v(x_i) - P_i/m_i`` (intensive); ``E_VG = grad v(x_p) -
sum_i v_i^MPM (x) G_ip`` at the particles whose rows touch interior nodes only, and ``E_VG_proj`` the
Q1 gradient of ``E_v`` at the centres of the cells whose four corners are interior. Vector errors enter
the norms (:func:`mpm_fem.core.norms.norms`) by their Euclidean length, nodes and cells weighted by
``h^2``, particles by ``w_p``.

Weights: ``"cell"`` the slides' ``w_p = h^2 / N_p^c`` (the equal-weight rule of each cell ``c``: the
rule Hickernell's bound is about, :mod:`mpm_fem.plane.discrepancy`); ``"volume"`` the particle volumes
``V_p`` of the layout. Bases: ``"mpm"`` (point mass) and ``"gimp"`` (uGIMP: the hats averaged over the
rectangle of the seeded lengths ``(h/n, h/n)``); both stand in for the same integrals of the Q1 hats.

Layouts (:func:`layout`), ``n x n`` particles per cell, every random choice seeded
(``numpy.random.default_rng(seed)``): ``regular`` and ``jittered`` (:func:`mpm_fem.plane.problems.seed_reference`),
``random`` (``n^2`` uniform points in every cell, the 1D ``random`` layout per cell) and ``advected``
(the regular layout moved by the smooth displacement of :class:`Displacement`, volumes ``J V_p^0``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from mpm_fem.core.norms import norms
from mpm_fem.plane.bases import plane_shape
from mpm_fem.plane.exact import cell_quadrature
from mpm_fem.plane.grid import PlaneGrid, plane_grid
from mpm_fem.plane.problems import seed_reference

#: The errors, extensive ones first (their size scales with the nodal measure ``h^2``).
QUANTITIES = ("E_m", "E_P", "E_F", "E_a", "E_v", "E_v1", "E_VG", "E_VG_proj")
EXTENSIVE = ("E_m", "E_P", "E_F")
LAYOUTS = ("regular", "jittered", "random", "advected")
WEIGHTS = ("cell", "volume")
BASES = ("mpm", "gimp")
#: scikit-fem's Gauss order on the half cells for the exact integrals (4 x 4 points a half cell): against
#: order 14 it moves the regular 4x4 layout's largest nodal error by less than 4e-8 of itself (h = 1/8, 1/64).
EXACT_ORDER = 6

#: A scalar field's jet ``(f, f_x, f_y, f_xy)`` (4, n) at the points ``x, y`` (n,).
Jet = Callable[[np.ndarray, np.ndarray], np.ndarray]


def product(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The jet (4, n) of the product of two jets (4, n) (the product rule)."""
    return np.stack((a[0] * b[0], a[1] * b[0] + a[0] * b[1], a[2] * b[0] + a[0] * b[2],
                     a[3] * b[0] + a[1] * b[2] + a[2] * b[1] + a[0] * b[3]))


def separable(fx: Callable, dfx: Callable, fy: Callable, dfy: Callable, c: float = 1.0) -> Jet:
    """The jet of ``c f(x) g(y)`` from the 1D functions and their derivatives."""
    return lambda x, y: c * np.stack((fx(x) * fy(y), dfx(x) * fy(y), fx(x) * dfy(y), dfx(x) * dfy(y)))


@dataclass(frozen=True)
class PlaneFields:
    """Density ``rho``, velocity ``v = (v_x, v_y)`` and Cauchy stress ``sigma = [[s_xx, s_xy], [s_xy, s_yy]]``
    as jets (:data:`Jet`); the point values (n,), (n, 2), (n, 2, 2) at positions (n, 2) by the methods."""

    rho: Jet
    v_x: Jet
    v_y: Jet
    s_xx: Jet
    s_yy: Jet
    s_xy: Jet

    def density(self, x: np.ndarray) -> np.ndarray:
        return self.rho(x[:, 0], x[:, 1])[0]

    def velocity(self, x: np.ndarray) -> np.ndarray:
        """(n, 2)."""
        return np.column_stack((self.v_x(x[:, 0], x[:, 1])[0], self.v_y(x[:, 0], x[:, 1])[0]))

    def velocity_gradient(self, x: np.ndarray) -> np.ndarray:
        """``[p, a, b] = d v_a / d x_b`` (n, 2, 2)."""
        jx, jy = self.v_x(x[:, 0], x[:, 1]), self.v_y(x[:, 0], x[:, 1])
        return np.stack((np.stack((jx[1], jx[2]), axis=-1), np.stack((jy[1], jy[2]), axis=-1)), axis=1)

    def stress(self, x: np.ndarray) -> np.ndarray:
        """(n, 2, 2)."""
        xx, yy, xy = (f(x[:, 0], x[:, 1])[0] for f in (self.s_xx, self.s_yy, self.s_xy))
        return np.stack((np.stack((xx, xy), axis=-1), np.stack((xy, yy), axis=-1)), axis=1)


def smooth_fields(gamma: float = 1.4, rho_amplitude: float = 0.5, v_amplitude: float = 1.0,
                  shear: float = 0.25) -> PlaneFields:
    """The 1D study's fields on the square: ``rho = r(x) r(y)`` with ``r = 1 + a sin(2 pi s)``;
    ``v = b (sin(2 pi x) cos(2 pi y), cos(2 pi x) sin(2 pi y))``; ``sigma = -p I + tau (e_x e_y + e_y e_x)``
    with the pressure ``p = rho^gamma`` and the shear ``tau = c sin(2 pi x) sin(2 pi y)``."""
    k = 2 * np.pi
    r = lambda s: 1.0 + rho_amplitude * np.sin(k * s)  # noqa: E731
    dr = lambda s: rho_amplitude * k * np.cos(k * s)  # noqa: E731
    sin, cos = (lambda s: np.sin(k * s)), (lambda s: np.cos(k * s))
    dsin, dcos = (lambda s: k * np.cos(k * s)), (lambda s: -k * np.sin(k * s))
    rho = separable(r, dr, r, dr)

    def pressure(x, y):
        j = rho(x, y)
        f, g, gg = j[0] ** gamma, gamma * j[0] ** (gamma - 1), gamma * (gamma - 1) * j[0] ** (gamma - 2)
        return -np.stack((f, g * j[1], g * j[2], gg * j[1] * j[2] + g * j[3]))

    return PlaneFields(rho=rho, v_x=separable(sin, dsin, cos, dcos, v_amplitude),
                       v_y=separable(cos, dcos, sin, dsin, v_amplitude), s_xx=pressure, s_yy=pressure,
                       s_xy=separable(sin, dsin, sin, dsin, shear))


# ----------------------------------------------------------------------------- layouts

@dataclass(frozen=True)
class Displacement:
    """The smooth map of the ``advected`` layout, ``x = X + u(X)`` with

        u = A (sin(2 pi X) sin(pi Y),  sin(pi X) sin(2 pi Y)),

    zero on the boundary of the square; ``|grad u| <= 2 pi A``, so ``J = det(I + grad u) > 0`` for ``A <
    1/(2 pi + pi)`` and the map is a bijection of the square. The default ``A = 0.06`` stretches areas by
    ``J`` between about 0.5 and 1.5."""

    amplitude: float = 0.06

    def move(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Positions (n, 2) and the Jacobians ``J`` (n,) of the map at ``X`` (n, 2)."""
        A, a, b = self.amplitude, np.pi * X[:, 0], np.pi * X[:, 1]
        u = A * np.column_stack((np.sin(2 * a) * np.sin(b), np.sin(a) * np.sin(2 * b)))
        F = np.array([[1 + 2 * np.pi * A * np.cos(2 * a) * np.sin(b), np.pi * A * np.sin(2 * a) * np.cos(b)],
                      [np.pi * A * np.cos(a) * np.sin(2 * b), 1 + 2 * np.pi * A * np.sin(a) * np.cos(2 * b)]])
        return X + u, F[0, 0] * F[1, 1] - F[0, 1] * F[1, 0]


def unit_square(h: float) -> PlaneGrid:
    """The study's grid: ``[0, 1]^2`` in cells of size ``h``."""
    return plane_grid((0.0, 0.0), (1.0, 1.0), h)


def layout(grid: PlaneGrid, name: str, ppc: int, seed: int = 0,
           displacement: Displacement = Displacement()) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Positions (n_p, 2), volumes (n_p,) and the seeded lengths (n_p, 2) of ``ppc x ppc`` particles per
    cell in layout ``name`` (:data:`LAYOUTS`, module docstring)."""
    if name in ("regular", "jittered"):
        return seed_reference(grid, ppc, name, seed=seed)
    X, V, lengths = seed_reference(grid, ppc, "regular")
    if name == "advected":
        x, J = displacement.move(X)
        return x, J * V, lengths
    if name == "random":
        h, lo = np.array(grid.h), np.array([a.lo for a in grid.axes])
        corner = lo + np.floor((X - lo) / h) * h
        return corner + np.random.default_rng(seed).random(X.shape) * h, V, lengths
    raise ValueError(f"unknown layout {name!r}; choose one of {', '.join(LAYOUTS)}")


def cell_of(grid: PlaneGrid, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The cell ``c = a n_cy + b`` (n_p,) of every particle and its local coordinates (n_p, 2) in [0, 1]^2
    (a point on an interior cell edge belongs to the cell on its right or above, as the 1D bases locate it)."""
    h = np.array(grid.h)
    n = np.array([round(a.length / a.h) for a in grid.axes])
    lo = np.array([a.lo for a in grid.axes])
    ab = np.clip(np.floor((x - lo) / h).astype(np.intp), 0, n - 1)
    return ab[:, 0] * n[1] + ab[:, 1], (x - lo) / h - ab


def cell_weights(grid: PlaneGrid, x: np.ndarray) -> np.ndarray:
    """The slides' weights ``w_p = h^2 / N_p^c`` (n_p,) of the particles of each cell ``c``."""
    cell, _ = cell_of(grid, x)
    count = np.bincount(cell)
    return grid.h[0] * grid.h[1] / count[cell]


# ----------------------------------------------------------------------------- nodal sums and errors

@dataclass(frozen=True, eq=False)
class Nodal:
    """Nodal mass ``m`` (n_nodes,), momentum ``P`` and force ``f`` (n_nodes, 2)."""

    m: np.ndarray
    P: np.ndarray
    f: np.ndarray


def _shape(grid: PlaneGrid, x: np.ndarray, basis: str, lengths: np.ndarray | None):
    if basis not in BASES:
        raise ValueError(f"the projection errors compare with integrals of the Q1 hats: basis must be one of "
                         f"{', '.join(BASES)}, got {basis!r}")
    return plane_shape(grid, basis, x, lengths)


def nodal_sums(grid: PlaneGrid, x: np.ndarray, w: np.ndarray, fields: PlaneFields, basis: str = "mpm",
               lengths: np.ndarray | None = None) -> Nodal:
    """``m_i``, ``P_i``, ``f_i`` of the points ``x`` (n, 2) with weights ``w`` (n,) (module docstring)."""
    shape = _shape(grid, x, basis, lengths)
    m = fields.density(x) * w
    return Nodal(shape.scatter(m), shape.scatter(m[:, None] * fields.velocity(x)),
                 -shape.scatter_gradient(w[:, None, None] * fields.stress(x)))


def exact_sums(grid: PlaneGrid, fields: PlaneFields, order: int = EXACT_ORDER) -> Nodal:
    """The integrals ``int rho S_i``, ``int rho v S_i``, ``- int sigma . grad S_i``: :func:`nodal_sums` over
    the 2D exact projection's reference quadrature (:func:`mpm_fem.plane.exact.cell_quadrature`)."""
    points, weights = cell_quadrature(grid, order)
    return nodal_sums(grid, points, weights, fields)


def interior_nodes(grid: PlaneGrid) -> np.ndarray:
    """The mask (n_nodes,) of the nodes off the boundary (their tensor hat is whole)."""
    nx, ny = grid.shape
    a, b = np.divmod(np.arange(grid.n_nodes), ny)
    return (a > 0) & (a < nx - 1) & (b > 0) & (b < ny - 1)


def _ratio(num: np.ndarray, den: np.ndarray) -> np.ndarray:
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(den[:, None] > 0, num / np.where(den > 0, den, 1.0)[:, None], 0.0)


def _length(e: np.ndarray) -> np.ndarray:
    """The Euclidean length of each entry of ``e`` (n,), (n, 2) or (n, 2, 2)."""
    return np.abs(e) if e.ndim == 1 else np.sqrt(np.sum(e.reshape(e.shape[0], -1) ** 2, axis=1))


@dataclass(frozen=True, eq=False)
class PlaneErrors:
    """The signed errors of the module docstring: nodal ones at the interior nodes (n_in,) or (n_in, 2),
    ``E_VG`` (n_in_p, 2, 2) at the particles touching interior nodes only, ``E_VG_proj`` (n_in_c, 2, 2) on the
    cells with four interior corners; the norms' weights beside them."""

    E_m: np.ndarray
    E_P: np.ndarray
    E_F: np.ndarray
    E_a: np.ndarray
    E_v: np.ndarray
    E_v1: np.ndarray
    E_VG: np.ndarray
    E_VG_proj: np.ndarray
    nodal_weights: np.ndarray
    particle_weights: np.ndarray
    cell_weights: np.ndarray

    def norms(self) -> dict[str, dict[str, float]]:
        """``{quantity: {"L1", "L2", "max"}}`` of the lengths of the errors, every quantity of :data:`QUANTITIES`."""
        weights = {"E_VG": self.particle_weights, "E_VG_proj": self.cell_weights}
        return {q: norms(_length(getattr(self, q)), weights.get(q, self.nodal_weights)) for q in QUANTITIES}


def projection_errors(grid: PlaneGrid, x: np.ndarray, w: np.ndarray, fields: PlaneFields, basis: str = "mpm",
                      lengths: np.ndarray | None = None, exact: Nodal | None = None) -> PlaneErrors:
    """Every projection error of the module docstring for particles ``x`` (n_p, 2) with weights ``w``
    (n_p,); ``exact`` the integrals (:func:`exact_sums`, computed when not given)."""
    ex = exact if exact is not None else exact_sums(grid, fields)
    mpm = nodal_sums(grid, x, w, fields, basis, lengths)
    inner = interior_nodes(grid)
    a, v = _ratio(ex.f, ex.m), _ratio(ex.P, ex.m)
    v_mpm = _ratio(mpm.P, mpm.m)
    E_v = v - v_mpm
    shape = _shape(grid, x, basis, lengths)
    touches = (shape.S != 0) | np.any(shape.G != 0, axis=-1)
    inside = ~np.any(touches & ~inner[shape.nodes], axis=1)
    nx, ny = grid.shape
    E = E_v.reshape(nx, ny, 2)
    hx, hy = grid.h
    gx = (E[2:-1, 1:-2] + E[2:-1, 2:-1] - E[1:-2, 1:-2] - E[1:-2, 2:-1]) / (2 * hx)
    gy = (E[1:-2, 2:-1] + E[2:-1, 2:-1] - E[1:-2, 1:-2] - E[2:-1, 1:-2]) / (2 * hy)
    proj = np.stack((gx, gy), axis=-1).reshape(-1, 2, 2)  # [cell, a, b] = d E_v^a / d x_b
    return PlaneErrors(
        E_m=(ex.m - mpm.m)[inner], E_P=(ex.P - mpm.P)[inner], E_F=(ex.f - mpm.f)[inner],
        E_a=(a - _ratio(mpm.f, mpm.m))[inner], E_v=E_v[inner],
        E_v1=(fields.velocity(grid.nodes) - v)[inner],
        E_VG=(fields.velocity_gradient(x) - shape.gather_gradient(v_mpm))[inside],
        E_VG_proj=proj,
        nodal_weights=np.full(int(inner.sum()), hx * hy), particle_weights=w[inside],
        cell_weights=np.full(proj.shape[0], hx * hy))
