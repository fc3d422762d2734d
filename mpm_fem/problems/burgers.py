"""Viscous Burgers ``v_t + v v_x = eps v_xx`` on [0, 2] up to T = 0.5 (slides, "Burgers' Problem").

Initial data, Dirichlet data at both ends and the exact acceleration ``Dv/Dt = eps v_xx`` come
from an exact solution (``baselines.exact.burgers``), so the error at T is exact:

    e_p = v_p - v(x_p, T)  over particles (weights V_p);   e_i = v_i - v(x_i, T)  over nodes,

with the grid velocity ``v_i = P_i / m_i`` taking the Dirichlet data at the two end nodes, as it
does in every step. Particles leave through the ends; a reservoir outside each end feeds new
particles in, spaced ``h / N_p`` like the initial layout, so that the domain never empties (the
pitfall of docs/claims.md).

Besides the stage switches, three settings reach the slides' own forms: ``weights`` ``"volume"``
(the volumes ``V_p`` carried by the flow, standard MPM) or ``"cell"`` (the slides' ``m_ip =
h/N_p^i``: every particle of cell ``I_i`` weighs ``h / N_p^i``, reset after every step); ``force``
``"weak"`` (``a_i = F_i/m_i`` with ``F_i = -sum_p V_p eps (dv/dx)_p G_ip``) or ``"slides"`` (their
count-normalised second difference ``eps (v_{i+1} - 2 v_i + v_{i-1})/h^2``, point mass only);
``dt_rule`` ``"stable"`` (``dt = CFL min(h/max|v|, h^2/(2 eps))``) or ``"advective"`` (``CFL
h/max|v|``: no viscous limit, for the exact acceleration, which computes no viscous force).
``kernel`` and ``threads`` choose the step's implementation (:func:`mpm_fem.run.solve.run`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from baselines.exact import burgers as exact_burgers
from mpm_fem.core.grid import Grid, uniform_grid
from mpm_fem.core.models.burgers import FORCES, ViscousBurgers
from mpm_fem.core.norms import norms
from mpm_fem.core.particles import Particles, make_particles, seed_positions
from mpm_fem.core.shape import locate
from mpm_fem.core.step import ACCELERATIONS, Dirichlet
from mpm_fem.core.transfer import COUPLED_KINDS
from mpm_fem.fused.step import check_kernel
from mpm_fem.problems import Cost, RunSettings, check_run_settings, check_stable_cfl, relative_change, run_cost, totals
from mpm_fem.run.solve import Problem, Result, run

WEIGHTS = ("volume", "cell")
DT_RULES = ("stable", "advective")
# The explicit step's stable CFL range: CFL 1 of min(h / max|v|, h^2 / (2 eps)) is the limit of
# forward-Euler diffusion with lumped mass (h^2 / (2 eps)); with consistent mass and the calculated
# acceleration the diffusion limit is a third of it (0.33 runs, 0.5 loses positivity, measured on
# the default problem; the study's budget shows the failure at 0.5).
CFL_LIMIT_CONSISTENT = 1.0 / 3.0


@dataclass(frozen=True)
class BurgersSettings(RunSettings):
    """Every setting of a Burgers run, with the CLI's defaults (:class:`RunSettings` and the
    solution, the acceleration and the three forms of the module docstring)."""

    T: float = 0.5
    cfl: float = 0.5
    # the problem, and the acceleration it supplies
    eps: float = 0.045
    solution: str = "rarefaction"
    acceleration: str = "calculated"
    # the slides' own forms
    weights: str = "volume"
    force: str = "weak"
    dt_rule: str = "stable"

    def __post_init__(self):
        if not (np.isfinite(self.eps) and self.eps > 0):
            raise ValueError(f"the viscosity eps must be positive, got {self.eps}")
        if self.acceleration not in ACCELERATIONS:
            raise ValueError(f"unknown acceleration {self.acceleration!r}; choose one of {', '.join(ACCELERATIONS)}")
        check_run_settings(self, self.exact.domain)
        for name, allowed in (("weights", WEIGHTS), ("force", FORCES), ("dt_rule", DT_RULES)):
            if getattr(self, name) not in allowed:
                raise ValueError(f"unknown {name} {getattr(self, name)!r}; choose one of {', '.join(allowed)}")
        if self.dt_rule == "advective" and self.acceleration != "exact":
            raise ValueError("dt_rule 'advective' drops the viscous limit: only the exact acceleration may use it")
        if self.force == "slides" and self.basis != "mpm":
            raise ValueError(f"force 'slides' is the point-mass second difference; basis {self.basis!r} has none")
        check_kernel(self.kernel, self.threads)

    @property
    def exact(self):
        """The exact solution object (``v``, ``v_x``, ``v_xx``, ``v_t``, ``domain``)."""
        return exact_burgers.make_solution(self.solution, self.eps)


@dataclass(frozen=True)
class Reservoir:
    """Removes particles that left ``[a, b]``; feeds in particles spaced ``spacing`` at each end.

    A gap between an end and the nearest particle wider than ``spacing`` is filled with particles
    ``spacing`` apart, counted from that particle, carrying the exact velocity and volume ``spacing``.
    With ``weights="cell"`` every particle then weighs ``h / N_p^i`` (volume and mass), the slides'
    ``m_ip`` of its cell ``I_i``.
    """

    spacing: float
    velocity: object  # callable (x, t) -> v
    weights: str = "volume"

    def quiet(self, grid: Grid) -> tuple[float, float, float] | None:
        """``(a, b, spacing)``: the call returns the particles as they are while every ``x_p`` lies
        in [a, b] and ``floor((min x_p - a) / spacing)``, ``floor((b - max x_p) / spacing)`` are
        <= 0 (no gap to fill), so a compiled loop may run until then; ``None`` with
        ``weights="cell"``, which re-weights every step."""
        if self.weights == "cell":
            return None
        a, b = grid.domain
        return float(a), float(b), float(self.spacing)

    def __call__(self, particles: Particles, grid: Grid, t: float) -> Particles:
        a, b = grid.domain
        inside = (particles.x >= a) & (particles.x <= b)
        if not inside.all():
            particles = particles.take(inside)
        if particles.n == 0:
            raise RuntimeError("every particle left the domain")
        s = self.spacing
        k_left = int(np.floor((particles.x.min() - a) / s))
        k_right = int(np.floor((b - particles.x.max()) / s))
        new = []
        if k_left > 0:
            new.append(particles.x.min() - s * np.arange(k_left, 0, -1))
        if k_right > 0:
            new.append(particles.x.max() + s * np.arange(1, k_right + 1))
        if new:
            x = np.concatenate(new)
            particles = particles.join(make_particles(x, s, 1.0, self.velocity(x, t)))
        if self.weights == "cell":
            particles = with_cell_weights(particles, grid)
        return particles


def with_cell_weights(particles: Particles, grid: Grid) -> Particles:
    """Unit-density particles whose volume and mass are ``h / N_p^i`` in their cell ``I_i``."""
    cell, _ = locate(grid, particles.x)
    w = float(grid.h.mean()) / np.bincount(cell, minlength=grid.n_cells)[cell]
    return particles.replace(volume=w, mass=w.copy())


def initial_particles(settings: BurgersSettings, grid: Grid) -> Particles:
    """Unit-density particles carrying ``v(x_p, 0)``."""
    x, volume = seed_positions(grid, settings.ppc, settings.layout, settings.seed)
    return make_particles(x, volume, 1.0, settings.exact.v(x, 0.0))


@dataclass(frozen=True)
class SmoothBurgersFields:
    """Viscous Burgers ``Dv/Dt = eps v_xx`` from a smooth exact solution, as the exact stages need
    it (:class:`~mpm_fem.exact_stages.fields.ExactFields`): point values, no breakpoints.

    Unit density; stress ``sigma = eps v_x``; reference ``(v*, v*_x, a*) = (v, v_x, eps v_xx)``.
    """

    solution: object  # baselines.exact.burgers solution: .fields(x, t) -> (v, v_x, v_xx, v_t)
    eps: float

    def integrand(self, x, t):
        v, v_x, _, _ = self.solution.fields(x, t)
        return np.ones_like(v), v, self.eps * v_x

    def breakpoints(self, t):
        return np.empty(0)

    def reference(self, x, t):
        v, v_x, v_xx, _ = self.solution.fields(x, t)
        return v, v_x, self.eps * v_xx

    def velocity_gradient(self, x, t):
        return self.solution.fields(x, t)[1]


def exact_fields(settings: BurgersSettings) -> SmoothBurgersFields:
    """The exact fields of the exact stages (:class:`SmoothBurgersFields`): point values."""
    return SmoothBurgersFields(settings.exact, settings.eps)


def simulate(settings: BurgersSettings = BurgersSettings(), progress: bool | None = None, observer=None) -> Result:
    """Run MPM on viscous Burgers with ``settings`` through :func:`mpm_fem.run.solve.run`."""
    solution = settings.exact
    grid = uniform_grid(*solution.domain, settings.h)
    problem = Problem(
        model=ViscousBurgers(settings.eps, viscous_limit=settings.dt_rule == "stable", force=settings.force),
        boundary=Dirichlet(solution.v),
        T=settings.T,
        cfl=settings.cfl,
        exact_acceleration=lambda x, t: settings.eps * solution.v_xx(x, t),
        particle_boundary=Reservoir(settings.h / settings.ppc, solution.v, settings.weights),
        exact=exact_fields(settings),
    )
    particles = initial_particles(settings, grid)
    if settings.weights == "cell":
        particles = with_cell_weights(particles, grid)
    return run(problem, grid, particles, settings.stages, progress, observer,
               kernel=settings.kernel, threads=settings.threads)


def check_stable(settings: BurgersSettings) -> None:
    """Refuse a CFL number outside the stable range (``ValueError``): (0, 1], and (0, 1/3] with
    a coupled mass (the consistent one, FMPM(k >= 2)) and the calculated acceleration."""
    if settings.mass in COUPLED_KINDS and settings.acceleration == "calculated":
        check_stable_cfl(settings, CFL_LIMIT_CONSISTENT, f"with the {settings.mass} mass and the calculated "
                         "acceleration")


def cost(settings: BurgersSettings) -> Cost:
    """The run's size from the settings alone: ``dt = CFL min(h / max|v|, h^2 / (2 eps))`` (no
    viscous limit with dt rule "advective"), ``max|v|`` of the exact solution over the domain at
    ``t = 0, T/2, T`` (1001 points each; Burgers obeys a maximum principle), times 1.25; the
    particles fed in through the ends are not counted."""
    solution = settings.exact
    x = np.linspace(*solution.domain, 1001)
    vmax = max(float(np.max(np.abs(solution.v(x, t)))) for t in (0.0, 0.5 * settings.T, settings.T))
    cap = settings.h**2 / (2 * settings.eps) if settings.dt_rule == "stable" else np.inf
    return run_cost(settings, solution.domain, 1.25 * vmax, cap)


def conservation(settings: BurgersSettings, result: Result) -> dict:
    """Mass ``sum V_p`` (unit density), momentum ``sum V_p v_p`` and energy ``sum V_p v_p^2 / 2``
    the particles carry at ``t = 0`` and at ``T``, beside the exact solution's integrals over the
    domain (trapezoidal rule on 4001 points). The ends are open (particles leave, the reservoir
    feeds), so nothing is conserved: ``relative_change`` compares the particles' change with the
    exact change."""
    solution = settings.exact
    start = totals(initial_particles(settings, uniform_grid(*solution.domain, settings.h)))
    end = totals(result.particles)
    x = np.linspace(*solution.domain, 4001)

    def exact_totals(t):
        v = solution.v(x, t)
        return {"mass": float(x[-1] - x[0]), "momentum": float(np.trapezoid(v, x)),
                "energy": float(np.trapezoid(0.5 * v * v, x))}

    exact0, exactT = exact_totals(0.0), exact_totals(result.t)
    expected = {k: exactT[k] - exact0[k] for k in start}
    return {"t0": start, "T": end, "exact_t0": exact0, "exact_T": exactT, "expected_change": expected,
            "relative_change": {k: relative_change(start[k], end[k], expected[k]) for k in start}}


def errors(settings: BurgersSettings, result: Result) -> dict:
    """Velocity errors at T over particles (weights ``V_p``) and over grid nodes (weights ``int
    S_i dx``; the end nodes carry the Dirichlet data, as in every step, so their error is zero)."""
    P, g = result.particles, result.grid
    v = settings.exact.v
    nodal = result.nodal_velocity.copy()
    nodal[g.boundary_nodes] = v(g.nodes[g.boundary_nodes], result.t)
    return {
        "velocity": {
            "particles": norms(P.velocity - v(P.x, result.t), P.volume),
            "nodes": norms(nodal - v(g.nodes, result.t), g.lumped_mass),
        }
    }
