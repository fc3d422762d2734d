"""Sod's shock tube (slides, "a case study from Gas Dynamics").

x in [0, 1], diaphragm at 0.5, gamma = 1.4, (rho, u, p) = (1, 0, 1) left and (0.125, 0, 0.1) right,
T = 0.2, walls at both ends. Errors are measured against the exact Riemann solution (Toro ch. 4):

    over particles   e_p = rho_p - rho(x_p, T),           weights V_p
    over grid nodes  e_i = m_i / int S_i - rho(x_i, T),   weights int S_i dx
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from baselines.exact import riemann
from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.models.euler import IdealGas
from mpm_fem.core.norms import norms
from mpm_fem.core.particles import make_particles, seed_positions
from mpm_fem.core.step import Walls
from mpm_fem.core.transfer import COUPLED_KINDS, FMPM_KINDS
from mpm_fem.exact_stages import kernels
from mpm_fem.fused.step import check_kernel
from mpm_fem.problems import (
    Cost,
    RunSettings,
    check_non_negative,
    check_run_settings,
    check_stable_cfl,
    relative_change,
    run_cost,
    totals,
)
from mpm_fem.run.solve import Problem, Result, run

DOMAIN = (0.0, 1.0)

# The explicit step's stable CFL range, by measurement on Sod (h = 0.01 and 0.0025, 4 and 16
# particles per cell, every basis and scheme): 0.5 runs and 0.6 loses positivity with lumped mass;
# 0.25 runs and 0.3 does not with consistent mass. A run inside the range can still lose
# positivity (1 particle per cell at 0.4 does): it then stops, naming the step.
# FMPM(k) takes the consistent mass's bound (its stable step lies between the two), FMPM(1) the lumped one's.
CFL_LIMIT = {"lumped": 0.5, "exact": 0.5, "consistent": 0.25,
             **{kind: 0.25 if kind in COUPLED_KINDS else 0.5 for kind in FMPM_KINDS}}


@dataclass(frozen=True)
class SodSettings(RunSettings):
    """Every setting of a Sod run, with the CLI's defaults (:class:`RunSettings` and the gas)."""

    gamma: float = 1.4
    av_linear: float = 0.5
    av_quadratic: float = 2.0
    left: tuple = (1.0, 0.0, 1.0)
    right: tuple = (0.125, 0.0, 0.1)
    x0: float = 0.5

    def __post_init__(self):
        if not (np.isfinite(self.gamma) and self.gamma > 1):
            raise ValueError(f"the ratio of specific heats gamma must be > 1, got {self.gamma}")
        check_non_negative(av_linear=self.av_linear, av_quadratic=self.av_quadratic)
        if not (np.isfinite(self.x0) and DOMAIN[0] < self.x0 < DOMAIN[1]):
            raise ValueError(f"the diaphragm x0 must lie inside the domain {DOMAIN}, got {self.x0}")
        for side in ("left", "right"):
            riemann._checked_state(getattr(self, side), side)  # finite, rho > 0, p > 0
        check_run_settings(self, DOMAIN)
        check_kernel(self.kernel, self.threads)


def initial_particles(settings: SodSettings, grid):
    """Particles of the two states, ``eps = p / ((gamma - 1) rho)``, at rest."""
    x, volume = seed_positions(grid, settings.ppc, settings.layout, settings.seed)
    left = x < settings.x0
    rho = np.where(left, settings.left[0], settings.right[0])
    u = np.where(left, settings.left[1], settings.right[1])
    p = np.where(left, settings.left[2], settings.right[2])
    return make_particles(x, volume, rho, u, p / ((settings.gamma - 1.0) * rho), p)


def exact(settings: SodSettings, x: np.ndarray, t: float):
    """Exact ``(rho, u, p)`` at ``x`` and time ``t``."""
    return riemann.sample(x, t, settings.left, settings.right, x0=settings.x0, gamma=settings.gamma)


@dataclass(frozen=True)
class RiemannFields:
    """Sod's tube (any Riemann problem without vacuum) as the exact stages need it
    (:class:`~mpm_fem.exact_stages.fields.ExactFields`): the exact ``(rho, u, -p)`` for the
    projection, and reference fields averaged over a particle domain ``[x - l, x + l]`` (the GIMP
    ``chi_p``, ``l = half_width``), since across a shock ``v*_x`` and ``a*`` are Dirac masses:

        v*(x) = 1/(2l) int_{x-l}^{x+l} u dy,   v*_x = (u(x+l) - u(x-l)) / (2l),   a* = dv*/dt + v* v*_x,

    which is ``u + O(l^2)`` where ``u`` is smooth, finite at a shock, and consistent: a point moving
    with ``v*`` crosses a shock with the Rankine-Hugoniot density ratio, since
    ``int v*_x dt = int_{u_1}^{u_2} du/(s - u) = log((s - u_1)/(s - u_2))``.

    In closed form: the solution is self-similar, ``u(x, t) = U(xi)`` with ``xi = (x - x0)/t``, and
    ``U`` is piecewise linear between the wave speeds (constant states, linear fans). With
    ``F(xi) = int U``, ``alpha = (x - l - x0)/t`` and ``beta = (x + l - x0)/t``:

        v*   = t (F(beta) - F(alpha)) / (2l),      v*_x = (U(beta) - U(alpha)) / (2l),
        dv*/dt = (G(beta) - G(alpha)) / (2l),      G = F - xi U,

    the last from differentiating ``t (F(beta) - F(alpha))`` in ``t``. At ``t = 0`` the limits.
    """

    left: tuple
    right: tuple
    x0: float
    gamma: float
    half_width: float

    def __post_init__(self):
        if not self.half_width > 0:
            raise ValueError(f"the averaging half-width must be positive, got {self.half_width}")

    @cached_property
    def _speeds(self) -> np.ndarray:
        """Sorted speeds of the wave fronts (fan heads and tails, contact, shocks)."""
        waves = riemann.wave_positions(1.0, self.left, self.right, self.x0, self.gamma)
        fronts = [v for k, v in waves.items() if k.startswith(("left_", "right_")) or k == "contact"]
        return np.sort(np.array(fronts) - self.x0)

    @cached_property
    def _pieces(self) -> tuple[np.ndarray, ...]:
        """Per piece ``k`` of ``U`` (0: left of the first speed, ...): anchor ``xi_k``, ``F(xi_k)``,
        ``U(xi_k^+)`` and slope ``m_k``, so that ``U = U_k + m_k (xi - xi_k)`` on the piece."""
        knots = self._speeds
        anchor = np.concatenate(([knots[0]], knots))
        end = np.concatenate((knots, [knots[-1] + 1.0]))
        width = end - anchor
        probe = np.where(width > 0, width, 1.0)
        a, b = anchor + 0.25 * probe, anchor + 0.75 * probe
        a[0], b[0] = knots[0] - 1.0, knots[0] - 0.5  # the outer states: constant
        _, ua, _ = self._sample(self.x0 + a, 1.0)
        _, ub, _ = self._sample(self.x0 + b, 1.0)
        slope = np.where(width > 0, (ub - ua) / (b - a), 0.0)
        slope[0] = slope[-1] = 0.0
        value = ua - slope * (a - anchor)
        value[0] = ua[0]
        F = np.zeros_like(anchor)
        inner = np.diff(knots)
        for k in range(2, anchor.size):  # a handful of wave fronts, not particles
            w = inner[k - 2]
            F[k] = F[k - 1] + value[k - 1] * w + 0.5 * slope[k - 1] * w * w
        return anchor, F, value, slope

    def _profile(self, xi):
        """``U(xi)``, ``F(xi)`` and ``G(xi) = F - xi U`` for finite ``xi``: the compiled
        :func:`~mpm_fem.exact_stages.kernels.profile`, equal bit for bit to :meth:`_profile_numpy`."""
        xi = np.asarray(xi, dtype=float)
        U, F, G = kernels.profile(np.ascontiguousarray(xi).ravel(), self._speeds, *self._pieces)
        return U.reshape(xi.shape), F.reshape(xi.shape), G.reshape(xi.shape)

    def _profile_numpy(self, xi):
        """The readable reference of :meth:`_profile`: ``U = U_k + m_k d``, ``F = F_k + U_k d + m_k
        d^2 / 2``, ``G = F - xi U`` with ``d = xi - xi_k``, ``k`` the piece holding ``xi``."""
        anchor, F0, U0, m = self._pieces
        k = np.searchsorted(self._speeds, xi, side="right")
        d = xi - anchor[k]
        U = U0[k] + m[k] * d
        F = F0[k] + U0[k] * d + 0.5 * m[k] * d * d
        G = F0[k] - U0[k] * anchor[k] + 0.5 * m[k] * d * d - xi * m[k] * d
        return U, F, G

    @cached_property
    def _waves(self) -> tuple:
        """``(p_star, u_star)`` and the left and mirrored right waves as the compiled sampler reads them."""
        p_star, u_star, left, right = riemann.waves(self.left, self.right, self.gamma)
        mirrored = (float(self.right[0]), -float(self.right[1]), float(self.right[2]))
        return (p_star, u_star, kernels.wave_constants(self.left, left, self.gamma),
                kernels.wave_constants(mirrored, right, self.gamma))

    def _sample(self, x, t):
        """The Riemann solution ``(rho, u, p)`` at ``x`` and ``t``: for ``t > 0`` the compiled
        :func:`~mpm_fem.exact_stages.kernels.sample`, equal bit for bit to :func:`baselines.exact.riemann.sample`."""
        if t > 0:
            return kernels.sample(x, t, self.x0, self.gamma, *self._waves)
        return riemann.sample(x, t, self.left, self.right, x0=self.x0, gamma=self.gamma)

    def breakpoints(self, t):
        return self.x0 + self._speeds * t

    def integrand(self, x, t):
        rho, u, p = self._sample(x, t)
        return rho, u, -p

    def _initial(self, x):
        """``(v*, v*_x, dv*/dt)`` at ``t = 0``: averages of the step data and their limits."""
        l = self.half_width
        u_l, u_r = self.left[1], self.right[1]
        lo, hi = x - l, x + l
        left_part = np.clip(self.x0 - lo, 0.0, 2 * l)
        v = (u_l * left_part + u_r * (2 * l - left_part)) / (2 * l)
        inside = (lo < self.x0) & (self.x0 <= hi)
        anchor, F0, U0, _ = self._pieces
        g_left, g_right = F0[0] - U0[0] * anchor[0], F0[-1] - U0[-1] * anchor[-1]
        return v, np.where(inside, (u_r - u_l) / (2 * l), 0.0), np.where(inside, (g_right - g_left) / (2 * l), 0.0)

    def velocity_gradient(self, x, t):
        x = np.asarray(x, dtype=float)
        if t == 0:
            return self._initial(x)[1]
        return self._averaged(x, t, False)[1]

    def reference(self, x, t):
        x = np.asarray(x, dtype=float)
        if t == 0:
            return self._initial(x)
        return self._averaged(x, t, True)

    def _averaged(self, x, t, full):
        """``(v*, v*_x, a*)`` at ``t > 0`` in one compiled pass (:func:`~mpm_fem.exact_stages.kernels.averaged`;
        ``full=False``: ``v*_x`` only), equal bit for bit to :meth:`_averaged_numpy`."""
        out = kernels.averaged(np.ascontiguousarray(x).ravel(), float(t), float(self.half_width), float(self.x0),
                                     full, self._speeds, *self._pieces)
        return tuple(a.reshape(x.shape) if a.size == x.size else a for a in out)

    def _averaged_numpy(self, x, t):
        """The readable reference of :meth:`_averaged` (class docstring), from :meth:`_profile_numpy`."""
        l = self.half_width
        U_hi, F_hi, G_hi = self._profile_numpy((x + l - self.x0) / t)
        U_lo, F_lo, G_lo = self._profile_numpy((x - l - self.x0) / t)
        v = t * (F_hi - F_lo) / (2 * l)
        v_x = (U_hi - U_lo) / (2 * l)
        v_t = (G_hi - G_lo) / (2 * l)
        return v, v_x, v_t + v * v_x


def exact_fields(settings: SodSettings) -> RiemannFields:
    """The exact fields of the exact stages (:class:`RiemannFields`): the Riemann solution,
    averaged over one cell (half-width ``h / 2``) where a stage needs ``v_x`` or ``Dv/Dt``, which
    are Dirac masses at the shock. One cell, not one particle: the artificial viscosity's length
    is the cell size, and a gradient spread over ``h / N_p`` makes it overheat the shock."""
    return RiemannFields(settings.left, settings.right, settings.x0, settings.gamma, settings.h / 2)


def simulate(settings: SodSettings = SodSettings(), progress: bool | None = None, observer=None) -> Result:
    """Run MPM on Sod's tube with ``settings``."""
    grid = uniform_grid(*DOMAIN, settings.h)
    model = IdealGas(settings.gamma, settings.av_linear, settings.av_quadratic)
    problem = Problem(model=model, boundary=Walls(), T=settings.T, cfl=settings.cfl, exact=exact_fields(settings))
    return run(problem, grid, initial_particles(settings, grid), settings.stages, progress, observer,
               kernel=settings.kernel, threads=settings.threads)


def check_stable(settings: SodSettings) -> None:
    """Refuse a CFL number outside the stable range of :data:`CFL_LIMIT` (``ValueError``)."""
    check_stable_cfl(settings, CFL_LIMIT[settings.mass], f"with {settings.mass} mass")


def cost(settings: SodSettings) -> Cost:
    """The run's size from the settings alone. The time step is ``CFL h / max(c + |v|)``; the
    largest ``c + |v|`` of the exact solution (the data and the two star states), times 1.25 for the
    viscosity's overshoot behind the shock (Sod: 2.19 exact, 2.47 measured at h = 0.001)."""
    gamma = settings.gamma
    speeds = [np.sqrt(gamma * p / rho) + abs(u) for rho, u, p in (settings.left, settings.right)]
    try:
        waves = riemann.wave_positions(1.0, settings.left, settings.right, 0.0, gamma)
        for side in ("left", "right"):
            speeds.append(np.sqrt(gamma * waves["p_star"] / waves[f"rho_star_{side}"]) + abs(waves["u_star"]))
    except ValueError:  # vacuum: no star region; gas speeds up to |u| + 2 c / (gamma - 1)
        speeds += [abs(u) + 2 * np.sqrt(gamma * p / rho) / (gamma - 1) for rho, u, p in (settings.left, settings.right)]
    return run_cost(settings, DOMAIN, 1.25 * max(speeds))


def conservation(settings: SodSettings, result: Result) -> dict:
    """Mass, momentum and energy the particles carry at ``t = 0`` and at ``T`` (:func:`totals`).

    Between walls mass and energy are conserved (the walls do no work; the artificial viscosity
    enters both the momentum and the energy equation through ``p_p``, so it turns kinetic into
    internal energy and conserves their sum). Momentum changes by the walls' impulse, ``(p_L -
    p_R) T`` while no wave has reached a wall (``None`` after). ``relative_change`` is the change
    beyond that, relative to the value at ``t = 0`` (to the impulse for momentum, which starts at 0).
    """
    start = totals(initial_particles(settings, uniform_grid(*DOMAIN, settings.h)))
    end = totals(result.particles)
    try:
        waves = riemann.wave_positions(result.t, settings.left, settings.right, settings.x0, settings.gamma)
        fronts = [v for k, v in waves.items() if not k.startswith(("rho_", "p_", "u_"))]
        inside = DOMAIN[0] < min(fronts) and max(fronts) < DOMAIN[1]
    except ValueError:
        inside = False
    impulse = (settings.left[2] - settings.right[2]) * result.t if inside else None
    expected = {"mass": 0.0, "momentum": impulse, "energy": 0.0}
    out = {"t0": start, "T": end, "expected_change": expected}
    out["relative_change"] = {k: relative_change(start[k], end[k], expected[k]) if expected[k] is not None else None
                              for k in start}
    return out


def errors(settings: SodSettings, result: Result) -> dict:
    """Density (and velocity, pressure) errors over particles and over grid nodes."""
    P, g = result.particles, result.grid
    rho_p, u_p, p_p = exact(settings, P.x, result.t)
    rho_i, u_i, _ = exact(settings, g.nodes, result.t)
    thermal = (settings.gamma - 1.0) * P.density * P.energy
    return {
        "density": {
            "particles": norms(P.density - rho_p, P.volume),
            "nodes": norms(result.nodal_density - rho_i, g.lumped_mass),
        },
        "velocity": {
            "particles": norms(P.velocity - u_p, P.volume),
            "nodes": norms(result.nodal_velocity - u_i, g.lumped_mass),
        },
        "pressure": {"particles": norms(thermal - p_p, P.volume)},
    }
