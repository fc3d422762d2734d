"""Nodal projection errors of the slides, against the exact integrals of smooth fields.

Slides, "Mass Projection Error" to "Velocity gradient projection error". Particles at ``x_p`` with
quadrature weights ``w_p`` carry the exact values of smooth fields ``rho``, ``v``, ``p``; the
projections of :mod:`mpm_fem.core.transfer` (``m_p = rho_p w_p``) are compared with the integrals they
stand in for (Gauss-Legendre on each cell, :func:`mpm_fem.measure.quadrature.integrate_cells`):

    m_i = int S_i rho dx        P_i = int S_i rho v dx        F_i = int p S_i' dx
    E_m^i = m_i - sum_p m_p S_ip,   E_P^i = P_i - sum_p m_p v_p S_ip,   E_F^i = F_i - sum_p w_p p_p G_ip

(the signed errors, exact minus projected; the slides write their absolute values). Nodal
acceleration and velocity are the ratios ``a_i = F_i/m_i`` and ``v_i = P_i/m_i`` of the exact
integrals, and their projection errors

    E_a^i = a_i - F_i^MPM/m_i^MPM,     predicted to first order by  E_F^i/m_i - a_i E_m^i/m_i
    E_v^i = v_i - P_i^MPM/m_i^MPM,     E_v1^i = v(x_i) - v_i

(with the projected mass ``m_i^MPM`` in place of ``m_i`` both predictions are identities). The
velocity gradient at a particle in cell ``[x_i, x_{i+1}]`` is ``(v_{i+1}^MPM - v_i^MPM)/h``:

    E_VG^p = v'(x_p) - sum_i G_ip v_i^MPM                 (projection + interpolation)
    E_VG^i = (E_v^{i+1} - E_v^i)/h                         (its projection part, per cell)

Nodal errors are taken at the interior nodes, whose hat ``S_i`` is whole (the slides' two-cell
form), and the velocity gradient errors on the cells between interior nodes (at the particles whose
``S_ip``, ``G_ip`` touch interior nodes only): a cut hat at a wall is a boundary error the slides do
not analyse (``E_v1`` is O(h) there, O(h^2) inside). Norms (:func:`mpm_fem.measure.errors.norms`) weigh
nodes by ``int S_i dx = h``, particles by ``w_p`` and cells by ``h``.

Weights: ``"cell"`` is the slides' ``w_p = h/N_p^i`` (``m_ip = h rho_p / N_p^i``, the equal-weight
rule of Hickernell's bound); ``"volume"`` is the particle volume ``V_p`` that a run carries. The two
coincide for seeded layouts (``V_p = h/N_p``) and differ once particles have moved.

Basis: ``"mpm"`` (point mass, ``S_ip = S_i(x_p)``, the slides' analysis) or ``"gimp"`` (``S_ip``,
``G_ip`` averaged over the particle domain ``[x_p - w_p/2, x_p + w_p/2]``); both stand in for the
same integrals of the P1 hats.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from mpm_fem.core.grid import Grid
from mpm_fem.core.particles import seed_positions
from mpm_fem.core.shape import make_shape, point_shape
from mpm_fem.core.transfer import divide_by_lumped, nodal_internal_force, nodal_mass, nodal_momentum
from mpm_fem.measure.errors import norms
from mpm_fem.measure.quadrature import (
    cell_mean_error,
    cell_points,
    derivative_l2,
    discrepancy_d2,
    hickernell_bound,
    integrate_cells,
)

Field = Callable[[np.ndarray], np.ndarray]
QUANTITIES = ("E_m", "E_P", "E_F", "E_a", "E_a_pred", "E_v", "E_v1", "E_VG", "E_VG_proj")
LAYOUTS = ("regular", "jittered", "random", "advected")
WEIGHTS = ("cell", "volume")
BASES = ("mpm", "gimp")


@dataclass(frozen=True)
class Fields:
    """Density, velocity and pressure with the derivatives the errors and bounds need."""

    rho: Field
    drho: Field
    v: Field
    dv: Field
    p: Field
    dp: Field


def smooth_fields(gamma: float = 1.4, rho_amplitude: float = 0.5, v_amplitude: float = 1.0) -> Fields:
    """docs/claims.md's fields on [0, 1]: ``rho = 1 + a sin(2 pi x)``, ``v = b sin(2 pi x)``, ``p = rho^gamma``."""
    k = 2 * np.pi
    rho = lambda x: 1.0 + rho_amplitude * np.sin(k * x)  # noqa: E731
    drho = lambda x: rho_amplitude * k * np.cos(k * x)  # noqa: E731
    return Fields(
        rho=rho,
        drho=drho,
        v=lambda x: v_amplitude * np.sin(k * x),
        dv=lambda x: v_amplitude * k * np.cos(k * x),
        p=lambda x: rho(x) ** gamma,
        dp=lambda x: gamma * rho(x) ** (gamma - 1) * drho(x),
    )


@dataclass(frozen=True, eq=False)
class Nodal:
    """Nodal mass ``m``, momentum ``P`` and force ``F`` (n_nodes,)."""

    m: np.ndarray
    P: np.ndarray
    F: np.ndarray


def _hat_parts(grid: Grid, left: np.ndarray, right: np.ndarray) -> np.ndarray:
    """Nodal sums of per-cell parts: ``left[c]`` goes to node ``c``, ``right[c]`` to node ``c + 1``."""
    out = np.zeros(grid.n_nodes)
    out[:-1] += left
    out[1:] += right
    return out


def exact_nodal(grid: Grid, fields: Fields) -> Nodal:
    """``m_i = int S_i rho``, ``P_i = int S_i rho v``, ``F_i = int p S_i'`` by Gauss-Legendre per cell."""
    def hat_integrals(f):
        right = integrate_cells(grid, lambda x, xi, h: xi * f(x))
        whole = integrate_cells(grid, lambda x, xi, h: f(x))
        return _hat_parts(grid, whole - right, right)

    mean_p = integrate_cells(grid, lambda x, xi, h: fields.p(x)) / grid.h
    return Nodal(
        m=hat_integrals(fields.rho),
        P=hat_integrals(lambda x: fields.rho(x) * fields.v(x)),
        F=_hat_parts(grid, -mean_p, mean_p),
    )


def _shape(grid: Grid, x: np.ndarray, w: np.ndarray, basis: str):
    if basis not in BASES:
        raise ValueError(f"the projection errors compare with integrals of the P1 hats: basis must be one of "
                         f"{', '.join(BASES)}, got {basis!r}")
    return make_shape(grid, x, w, basis)


def particle_nodal(grid: Grid, x: np.ndarray, w: np.ndarray, fields: Fields, basis: str = "mpm") -> Nodal:
    """The MPM sums with ``m_p = rho(x_p) w_p``: ``m_i``, ``P_i``, ``F_i = sum_p w_p p_p G_ip``."""
    shape = _shape(grid, x, w, basis)
    m_p = fields.rho(x) * w
    return Nodal(
        m=nodal_mass(shape, m_p),
        P=nodal_momentum(shape, m_p, fields.v(x)),
        F=nodal_internal_force(shape, w, -fields.p(x)),
    )


def cell_weights(grid: Grid, x: np.ndarray) -> np.ndarray:
    """The slides' weights ``w_p = h_i / N_p^i`` of the particles (n_p,), in input order."""
    pts = cell_points(grid, x)
    w = np.empty(pts.cell.size)
    w[pts.order] = grid.h[pts.cell] / pts.count[pts.cell]
    return w


@dataclass(frozen=True, eq=False)
class ProjectionErrors:
    """Signed errors (exact minus MPM). Nodal ones at the interior nodes (n_nodes - 2,); ``E_VG``
    at the particles that touch interior nodes only; ``E_VG_proj`` on the cells between interior
    nodes (n_cells - 2,). ``nodal_weights``, ``particle_weights`` and ``cell_weights`` (same
    shapes) are the norms' weights."""

    E_m: np.ndarray
    E_P: np.ndarray
    E_F: np.ndarray
    E_a: np.ndarray
    E_a_pred: np.ndarray
    E_v: np.ndarray
    E_v1: np.ndarray
    E_VG: np.ndarray
    E_VG_proj: np.ndarray
    nodal_weights: np.ndarray
    particle_weights: np.ndarray
    cell_weights: np.ndarray

    def norms(self) -> dict[str, dict[str, float]]:
        """``{quantity: {"L1", "L2", "max"}}`` for every quantity of :data:`QUANTITIES`."""
        weights = {"E_VG": self.particle_weights, "E_VG_proj": self.cell_weights}
        return {q: norms(getattr(self, q), weights.get(q, self.nodal_weights)) for q in QUANTITIES}


def projection_errors(grid: Grid, x: np.ndarray, w: np.ndarray, fields: Fields, basis: str = "mpm") -> ProjectionErrors:
    """Every projection error of the slides for particles ``x`` with weights ``w`` (see module doc);
    ``basis="gimp"`` projects with the hats averaged over the particle domains ``x_p +- w_p/2``."""
    x, w = np.asarray(x, dtype=float), np.asarray(w, dtype=float)
    ex, mpm = exact_nodal(grid, fields), particle_nodal(grid, x, w, fields, basis)
    inner = slice(1, -1)
    a, v = ex.F / ex.m, ex.P / ex.m
    a_mpm, v_mpm = divide_by_lumped(mpm.F, mpm.m), divide_by_lumped(mpm.P, mpm.m)
    E_m, E_F = ex.m - mpm.m, ex.F - mpm.F
    E_v = v - v_mpm
    shape = _shape(grid, x, w, basis)
    end = (shape.nodes == 0) | (shape.nodes == grid.n_nodes - 1)
    inside = ~np.any(end & ((shape.S != 0) | (shape.G != 0)), axis=1)
    return ProjectionErrors(
        E_m=E_m[inner],
        E_P=(ex.P - mpm.P)[inner],
        E_F=E_F[inner],
        E_a=(a - a_mpm)[inner],
        E_a_pred=(E_F / ex.m - a * E_m / ex.m)[inner],
        E_v=E_v[inner],
        E_v1=(fields.v(grid.nodes) - v)[inner],
        E_VG=(fields.dv(x) - shape.gather_gradient(v_mpm))[inside],
        E_VG_proj=np.diff(E_v[inner]) / grid.h[inner],
        nodal_weights=grid.lumped_mass[inner],
        particle_weights=w[inside],
        cell_weights=grid.h[inner].copy(),
    )


@dataclass(frozen=True, eq=False)
class BoundCheck:
    """Measured errors beside Hickernell's bound, one entry per cell or interior node."""

    error: np.ndarray
    bound: np.ndarray

    @property
    def min_ratio(self) -> float:
        """Smallest ``bound / |error|`` over the entries with a nonzero error (must be >= 1)."""
        e = np.abs(self.error)
        ok = np.isfinite(self.bound) & (e > 0)
        return float(np.min(self.bound[ok] / e[ok])) if ok.any() else math.inf


def quadrature_checks(grid: Grid, x: np.ndarray, fields: Fields) -> dict[str, BoundCheck]:
    """Hickernell's bound (1) against the equal-weight (``h/N_p^i``) quadrature errors:

    ``cell_rho``: ``|1/h int rho - 1/N sum rho_p|`` per cell, bound ``D2 h^{1/2} ||rho'||_{2,h}``;
    ``node_m``: ``|E_m^i|``, bound ``sum_{c = i, i+1} D2_c h^{3/2} ||(S_i rho)'||_{2,h}`` (per node);
    ``node_F``: ``|E_F^i|``, bound ``sum_{c = i, i+1} D2_c h^{1/2} ||p'||_{2,h}`` (slides, force).
    Cells without a particle have no bound (NaN) and are left out.
    """
    d2, h = discrepancy_d2(grid, x), grid.h
    w = cell_weights(grid, x)
    errors = projection_errors(grid, x, w, fields)
    bound_p = hickernell_bound(d2, h, derivative_l2(grid, fields.dp))
    # (S_i rho)' is rho/h + xi rho' on the cell left of node i (S_i = xi rising), -rho/h + (1 - xi) rho'
    # on the cell right of it (S_i = 1 - xi falling); node i = 1..n-1 takes rising[i-1] + falling[i]
    rising = np.sqrt(integrate_cells(grid, lambda y, xi, hh: (fields.rho(y) / hh + xi * fields.drho(y)) ** 2))
    falling = np.sqrt(integrate_cells(grid, lambda y, xi, hh: (-fields.rho(y) / hh + (1 - xi) * fields.drho(y)) ** 2))
    bound_m = d2 * h**1.5 * rising, d2 * h**1.5 * falling
    return {
        "cell_rho": BoundCheck(cell_mean_error(grid, x, fields.rho),
                               hickernell_bound(d2, h, derivative_l2(grid, fields.drho))),
        "node_m": BoundCheck(errors.E_m, bound_m[0][:-1] + bound_m[1][1:]),
        "node_F": BoundCheck(errors.E_F, bound_p[:-1] + bound_p[1:]),
    }


@dataclass(frozen=True)
class Advection:
    """A kinematic MPM run that produces the ``advected`` layout: particles seeded at regular
    midpoints are moved for a time ``T`` by the velocity field ``u(x) = amplitude sin(2 pi x)``
    (zero at both ends), ``dt = cfl h / amplitude`` rounded down to land on ``T``:

        v_i = sum_p m_p u(x_p) S_ip / m_i,   x_p += dt sum_i S_ip v_i,   V_p *= 1 + dt sum_i G_ip v_i

    (the slides' step with the exact particle velocity; walls: ``v_i = 0`` at the ends). The flow
    stretches the layout by ``exp(2 pi amplitude T)`` near the ends and compresses it by the inverse
    near ``x = 1/2``; the defaults give a factor 1.65.
    """

    amplitude: float = 0.1
    T: float = 0.8
    cfl: float = 0.5

    def velocity(self, x: np.ndarray) -> np.ndarray:
        return self.amplitude * np.sin(2 * np.pi * x)

    def flow(self, x0: np.ndarray) -> np.ndarray:
        """The exact flow map of ``u`` at ``T``: ``tan(pi x) = tan(pi x0) exp(2 pi amplitude T)``."""
        s = np.exp(2 * np.pi * self.amplitude * self.T)
        return np.arctan2(s * np.sin(np.pi * x0), np.cos(np.pi * x0)) / np.pi

    def steps(self, grid: Grid) -> int:
        return max(1, math.ceil(self.T * self.amplitude / (self.cfl * grid.h.min()) - 1e-9))

    def run(self, grid: Grid, ppc: int, rho: Field) -> tuple[np.ndarray, np.ndarray]:
        """Positions and volumes (n_p,) after the run; the masses ``m_p = rho(x_p) V_p`` at seeding."""
        x, V = seed_positions(grid, ppc, "regular")
        m = rho(x) * V
        n = self.steps(grid)
        dt = self.T / n
        ends = grid.boundary_nodes
        for _ in range(n):  # the time loop; every step is vectorised over the particles
            shape = point_shape(grid, x)
            v_i = divide_by_lumped(nodal_momentum(shape, m, self.velocity(x)), nodal_mass(shape, m))
            v_i[ends] = 0.0
            V = V * (1.0 + dt * shape.gather_gradient(v_i))
            x = x + dt * shape.gather(v_i)
        return x, V


def layout(grid: Grid, name: str, ppc: int, seed: int = 0, advection: Advection = Advection(),
           rho: Field | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Particle positions and volumes of a named layout: :data:`LAYOUTS`; ``seed`` feeds the random
    ones, ``advection`` (with the density ``rho`` for the masses) the advected one."""
    if name == "advected":
        return advection.run(grid, ppc, rho if rho is not None else (lambda x: np.ones_like(x)))
    if name not in LAYOUTS:
        raise ValueError(f"unknown layout {name!r}; choose one of {', '.join(LAYOUTS)}")
    return seed_positions(grid, ppc, name, seed=seed)
