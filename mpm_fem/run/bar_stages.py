"""The bar of the 1D control (:mod:`mpm_fem.run.bar`) with the stage switches of the error budget: the
control problem of E1, on which the stages should separate (the particles move ``A = 1e-4`` of the
domain: no particle crosses a node).

The four stages and their exact forms, as :mod:`mpm_fem.exact_stages.stage` defines them for Sod and
Burgers, on the bar's symplectic Euler step (:func:`mpm_fem.core.bar.bar_step`, P1 point mass, FLIP,
USL). With ``X*(x, t)`` the material point at ``x`` at ``t`` (the inverse of ``x = X + u(X, t)``, by
Newton's method) the exact fields of a step from ``t`` to ``t + dt`` are

    v*(x) = v(X*(x, t), t - dt/2),   a*(x) = a(X*(x, t), t),   L*(x) = F_t / F at (X*(x, t), t + dt/2)

(the velocity the particles carry is the half step's), and

    projection exact     m_i = int rho S_i dx,  P_i = int rho v* S_i dx,
                         f_i = - int sigma S_i' dx + int rho b S_i dx      (at t, on the current
                         configuration: Gauss-Legendre, QUADRATURE_POINTS a cell; S_i is linear in each
                         cell, so only the smooth fields limit it, far below the errors measured)
    mass exact           v_i = v*_i + [P_i / m_i - P*_i / m*_i]   (the lumped solve of the MPM data
                         minus that of the exact data: the lumped mass makes no error of its own);
                         with the projection exact too, v_i = v*_i; the same for a_i with f_i, a*_i
    interpolation exact  a_p = a*(x_p) + sum_i S_ip (a_i - a*_i),
                         w_p = v*(x_p) + dt a*(x_p) + sum_i S_ip (v_i^+ - v*_i - dt a*_i)   (the motion),
                         L_p = L*(x_p) + sum_i G_ip (v_i^+ - v*_i - dt a*_i)
    time                 dt -> dt / refine

then ``v_p <- v_p + dt a_p``, ``x_p <- x_p + dt w_p``, ``F_p <- (1 + dt L_p) F_p``. Every stage
exact leaves the leapfrog on the exact fields, a second-order time error (:data:`TIME_ORDER`). Every
stage in MPM form is :func:`~mpm_fem.core.bar.bar_step` (equal bit for bit, tested).

The particle error field is ``e_p = u_p - u(X_p, T)`` (n_p,) and its norm the L1 over the reference
volumes, ``sum_p V_p^0 |e_p| / sum_p V_p^0`` (one functional for every combination of the stages).
:func:`readout_errors` is the error of the nodal read-out alone: the nodal velocity
``sum_p m_p S_ip v_p / m_i`` of particles at their exact positions with the exact velocity, against
the exact nodal velocity (L1 over the nodes): on a jittered layout a particle quadrature.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from baselines.exact.solids import AxisAligned1D
from mpm_fem.core.bar import BarParticles, bar_step
from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.models.solid import InvertedBarError, NeoHookeanBar
from mpm_fem.core.particles import LAYOUTS, seed_positions
from mpm_fem.core.periodic import PeriodicLine, periodic_line
from mpm_fem.core.step import Stages
from mpm_fem.core.transfer import (
    divide_by_lumped,
    gradient,
    interpolate,
    nodal_internal_force,
    nodal_mass,
    nodal_momentum,
)
from mpm_fem.run.bar import start

#: the Gauss-Legendre points per cell of the exact projection
QUADRATURE_POINTS = 8
#: the order of the time error of the bar's step (leapfrog): the time-exact extrapolation's
TIME_ORDER = 2
STAGE_FORMS = {"projection": ("mpm", "exact"), "mass": ("lumped", "exact"), "interpolation": ("mpm", "exact")}


@dataclass(frozen=True)
class BarStages:
    """The stage switches of the bar (module docstring): ``projection`` ``mpm``/``exact``, ``mass``
    ``lumped``/``exact``, ``interpolation`` ``mpm``/``exact``, ``refine`` (an integer >= 1)."""

    projection: str = "mpm"
    mass: str = "lumped"
    interpolation: str = "mpm"
    refine: int = 1

    def __post_init__(self):
        for name, forms in STAGE_FORMS.items():
            if getattr(self, name) not in forms:
                raise ValueError(f"the bar's {name} stage is one of {', '.join(forms)}, got {getattr(self, name)!r}")
        if isinstance(self.refine, bool) or not isinstance(self.refine, int) or self.refine < 1:
            raise ValueError(f"the time refinement must be an integer >= 1, got {self.refine!r}")

    @property
    def all_mpm(self) -> bool:
        return self.projection == "mpm" and self.mass == "lumped" and self.interpolation == "mpm"


@dataclass(frozen=True)
class ControlSettings:
    """One control run: cell size ``h`` (dividing 2), ``ppc``, ``layout`` and ``seed``, ``amplitude``,
    ``cfl`` (``dt = T / ceil(T c / (cfl h))`` before the refinement), ``T`` (None: one period)."""

    h: float = 1 / 16
    ppc: int = 4
    layout: str = "regular"
    seed: int = 0
    amplitude: float = 1e-4
    cfl: float = 0.25
    T: float | None = None

    def __post_init__(self):
        if not (isinstance(self.h, (int, float)) and math.isfinite(self.h) and self.h > 0):
            raise ValueError(f"the cell size h must be positive and finite, got {self.h!r}")
        if not (isinstance(self.cfl, (int, float)) and 0 < self.cfl <= 1):
            raise ValueError(f"the CFL number must lie in (0, 1], got {self.cfl!r}")
        if self.layout not in LAYOUTS:
            raise ValueError(f"unknown particle layout {self.layout!r}; choose one of {', '.join(LAYOUTS)}")
        if isinstance(self.ppc, bool) or not isinstance(self.ppc, int) or self.ppc < 1:
            raise ValueError(f"particles per cell must be an integer >= 1, got {self.ppc!r}")


def material_point(solution: AxisAligned1D, x: np.ndarray, t: float) -> np.ndarray:
    """``X*(x, t)``: the solution of ``X + u(X, t) = x`` (Newton from ``X = x``; ``|u_X| <= pi A < 1``)."""
    x = np.asarray(x, dtype=float)
    X = x.copy()
    for _ in range(50):
        step = (X + solution.displacement(X, t) - x) / solution.deformation_gradient(X, t)
        X -= step
        if np.max(np.abs(step), initial=0.0) <= 4 * np.finfo(float).eps * max(1.0, float(np.max(np.abs(x)))):
            return X
    raise ArithmeticError("the inverse of the bar's motion did not converge")


def stretch_rate(solution: AxisAligned1D, X: np.ndarray, t: float) -> np.ndarray:
    """``dF/dt = A pi^2 c cos(pi X) cos(pi c t)`` (the time derivative of ``F = 1 + u_X``)."""
    c = solution.material.c
    return solution.amplitude * np.pi**2 * c * np.cos(np.pi * np.asarray(X, dtype=float)) * np.cos(np.pi * c * t)


@dataclass(frozen=True, eq=False)
class ExactFields:
    """The exact fields of one step from ``t`` to ``t + dt`` (module docstring) at the points ``x``:
    ``v``, ``a``, ``L`` (each the shape of ``x``)."""

    solution: AxisAligned1D
    t: float
    dt: float

    def at(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        s, t, dt = self.solution, self.t, self.dt
        X = material_point(s, x, t)
        v = s.velocity(X, t - 0.5 * dt)
        a = s.acceleration(X, t)
        half = t + 0.5 * dt
        L = stretch_rate(s, X, half) / s.deformation_gradient(X, half)
        return v, a, L


def exact_projection(grid: PeriodicLine, fields: ExactFields) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(m*_i, P*_i, f*_i)`` (n_nodes,): the integrals of the module docstring at ``fields.t``."""
    s, t = fields.solution, fields.t
    g, w = np.polynomial.legendre.leggauss(QUADRATURE_POINTS)
    left = grid.lo + grid.h * np.arange(grid.n_nodes)
    x = (left[:, None] + 0.5 * grid.h * (g[None, :] + 1.0)).ravel()
    weight = np.tile(0.5 * grid.h * w, grid.n_nodes)
    X = material_point(s, x, t)
    rho = s.material.rho0 / s.deformation_gradient(X, t)
    v = s.velocity(X, t - 0.5 * fields.dt)
    shape = grid.shape(x, None, "mpm")
    m_i = shape.scatter(weight * rho)
    P_i = shape.scatter(weight * rho * v)
    f_i = -shape.scatter_gradient(weight * s.stress(X, t)) + shape.scatter(weight * rho * s.body_force(X, t))
    return m_i, P_i, f_i


def _solve(stages: BarStages, mpm_rhs, m_i, exact_rhs, exact_m, reference) -> np.ndarray:
    """The mass stage's nodal values (module docstring)."""
    if stages.mass == "exact":
        if stages.projection == "exact":
            return reference.copy()
        return reference + divide_by_lumped(mpm_rhs, m_i) - divide_by_lumped(exact_rhs, exact_m)
    if stages.projection == "exact":
        return divide_by_lumped(exact_rhs, exact_m)
    return divide_by_lumped(mpm_rhs, m_i)


def staged_step(state: BarParticles, grid: PeriodicLine, model: NeoHookeanBar, solution: AxisAligned1D, dt: float,
                t: float, stages: BarStages) -> BarParticles:
    """One step of the bar from ``t`` to ``t + dt`` with the stages of ``stages`` (module docstring);
    ``stages.refine`` is the caller's (:func:`run_control`). Raises ``InvertedBarError``."""
    if stages.all_mpm:
        return bar_step(state, grid, model, dt, t, solution.body_force, Stages())[0]
    shape = grid.shape(state.x, state.volume0, "mpm")
    m = state.mass
    m_i = nodal_mass(shape, m)
    P_i = nodal_momentum(shape, m, state.v)
    f_i = nodal_internal_force(shape, state.volume, model.stress(state.F)) + shape.scatter(
        m * np.asarray(solution.body_force(state.X, t), dtype=float))
    fields = ExactFields(solution, t, dt)
    v_star, a_star, _ = fields.at(grid.nodes)
    need_exact = stages.projection == "exact" or stages.mass == "exact"
    m_q, P_q, f_q = exact_projection(grid, fields) if need_exact else (None, None, None)
    v_i = _solve(stages, P_i, m_i, P_q, m_q, v_star)
    a_i = _solve(stages, f_i, m_i, f_q, m_q, a_star)
    v_new = v_i + dt * a_i
    if stages.interpolation == "exact":
        star_new = v_star + dt * a_star
        p_v, p_a, p_L = fields.at(state.x)
        accel = p_a + interpolate(shape, a_i - a_star)
        moving = p_v + dt * p_a + interpolate(shape, v_new - star_new)
        rate = p_L + gradient(shape, v_new - star_new)
    else:
        accel, moving, rate = interpolate(shape, a_i), interpolate(shape, v_new), gradient(shape, v_new)
    v = state.v + dt * accel
    x = state.x + dt * moving
    F = model.update(state.F, rate, x, dt)
    return state.replace(x=x, v=v, F=F, volume=F * state.volume0)


def _start(s: ControlSettings):
    solution = AxisAligned1D(amplitude=s.amplitude)
    lo, hi = solution.domain
    grid = periodic_line(lo, hi, s.h)
    X, V0 = seed_positions(uniform_grid(lo, hi, s.h), s.ppc, s.layout, s.seed)
    T = solution.period if s.T is None else s.T
    return solution, grid, X, V0, T


def run_control(s: ControlSettings, stages: BarStages = BarStages()) -> np.ndarray:
    """The particle error field ``e_p = u_p - u(X_p, T)`` (n_p,) of one run of ``s`` with ``stages``:
    ``N = ceil(T c / (cfl h)) * refine`` steps of ``T / N``."""
    solution, grid, X, V0, T = _start(s)
    n_steps = max(1, math.ceil(T * solution.material.c / (s.cfl * s.h) - 1e-9)) * stages.refine
    dt = T / n_steps
    model = NeoHookeanBar.of(solution.material)
    state = start(solution, X, V0, dt)
    for n in range(n_steps):
        try:
            state = staged_step(state, grid, model, solution, dt, n * dt, stages)
        except InvertedBarError as error:
            raise error.at(n + 1, (n + 1) * dt) from None
    return state.displacement - solution.displacement(state.X, T)


def l1(s: ControlSettings, error: np.ndarray) -> float:
    """``sum_p V_p^0 |e_p| / sum_p V_p^0`` (module docstring)."""
    _, _, _, V0, _ = _start(s)
    return float(np.sum(V0 * np.abs(error)) / np.sum(V0))


def readout_errors(s: ControlSettings) -> tuple[float, float]:
    """The nodal read-out's own error at ``T`` (module docstring), of the velocity (the grid's
    ``v_i = P_i / m_i``; at one period the displacement is zero): ``(L1, L1 / mean |v*_i|)`` over the
    nodes (each weighs ``h``), particles at ``X_p + u(X_p, T)`` carrying ``v(X_p, T)``."""
    solution, grid, X, V0, T = _start(s)
    shape = grid.shape(X + solution.displacement(X, T), V0, "mpm")
    m = solution.material.rho0 * V0
    v_i = divide_by_lumped(nodal_momentum(shape, m, solution.velocity(X, T)), nodal_mass(shape, m))
    exact = solution.velocity(material_point(solution, grid.nodes, T), T)
    error = float(np.mean(np.abs(v_i - exact)))
    return error, error / float(np.mean(np.abs(exact)))
