"""The bar of the 1D control: the x part of the axis-aligned solution (``baselines.exact.solids.AxisAligned1D``,
``u = A sin(pi X) sin(c pi t)`` on the periodic ``[0, 2)``) run by the 1D MPM step of the neo-Hookean bar
(:func:`mpm_fem.core.bar.bar_step`), to one period by default.

Seeding: ``ppc`` particles in every cell, the 1D layouts of :func:`mpm_fem.core.particles.seed_positions`
(the 2D seeding per axis), each with ``V_p^0 = h / ppc`` and ``m_p = rho_0 V_p^0``. The start of the
symplectic Euler step: ``x_p = X_p + u(X_p, 0)``, ``F_p = F(X_p, 0)``, ``V_p = F_p V_p^0`` and the
velocity at the half step before, ``v_p = v(X_p, -dt/2)``. The fixed step is ``dt = T / N``,
``N = ceil(T c / (cfl h))`` with ``c = sqrt(E / rho0)`` (or ``dt`` given, ``N = round(T / dt)``).
The loop is over time steps only. Errors: the particle displacement at ``T``,

    L2 = sqrt( sum_p V_p (u_p - u(X_p, T))^2 / sum_p V_p ),     Linf = max_p |u_p - u(X_p, T)|,

and the largest L2 over the steps. Bad settings raise ``ValueError`` before any work.
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field

import numpy as np

from baselines.exact.solids import AxisAligned1D
from mpm_fem.core.bar import BarParticles, bar_step, check_stages
from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.models.solid import InvertedBarError, NeoHookeanBar
from mpm_fem.core.particles import LAYOUTS, seed_positions
from mpm_fem.core.periodic import periodic_line
from mpm_fem.core.step import Stages


@dataclass(frozen=True)
class BarSettings:
    """One run of the bar: ``h`` the cell size, ``ppc`` particles per cell, the solution's
    ``amplitude``, the ``basis``, the ``mass`` (``lumped``, ``consistent``), ``cfl``, the layout and
    its ``seed``, ``T`` (None: one period), ``dt`` (None: from ``cfl``), the PIC/FLIP ``flip`` and the
    ``scheme`` (``usl``, ``musl``)."""

    h: float = 1 / 16
    ppc: int = 2
    amplitude: float = 1e-4
    basis: str = "mpm"
    mass: str = "lumped"
    cfl: float = 0.25
    seed: int = 0
    layout: str = "regular"
    T: float | None = None
    dt: float | None = None
    flip: float = 1.0
    scheme: str = "usl"

    def __post_init__(self):
        if isinstance(self.h, bool) or not isinstance(self.h, (int, float)) or not (math.isfinite(self.h)
                                                                                   and self.h > 0):
            raise ValueError(f"the cell size h must be positive and finite, got {self.h!r}")
        if not (isinstance(self.cfl, (int, float)) and 0 < self.cfl <= 1):
            raise ValueError(f"the CFL number must lie in (0, 1], got {self.cfl!r}")
        if self.layout not in LAYOUTS:
            raise ValueError(f"unknown particle layout {self.layout!r}; choose one of {', '.join(LAYOUTS)}")
        for name in ("T", "dt"):
            value = getattr(self, name)
            if value is not None and not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be positive and finite, got {value!r}")
        check_stages(self.stages)

    @property
    def stages(self) -> Stages:
        return Stages(basis=self.basis, mass=self.mass, flip=self.flip, scheme=self.scheme)


@dataclass(frozen=True, eq=False)
class BarRun:
    """One run: ``settings``; the particles at ``t``; ``steps`` of ``dt`` (s) at the CFL number
    ``cfl`` (``dt c / h``); ``errors`` ``{"displacement": {"L2", "Linf", "L2_max"}}``; ``wall_s``
    the loop's wall time (s)."""

    settings: BarSettings
    particles: BarParticles = field(repr=False)
    t: float
    steps: int
    dt: float
    cfl: float
    errors: dict = field(repr=False)
    wall_s: float


def start(solution: AxisAligned1D, X: np.ndarray, volume0: np.ndarray, dt: float) -> BarParticles:
    """The particles at ``t = 0`` with the velocity at ``-dt/2`` (module docstring)."""
    F = np.asarray(solution.deformation_gradient(X, 0.0), dtype=float)
    return BarParticles(X=X.copy(), x=X + solution.displacement(X, 0.0), v=solution.velocity(X, -0.5 * dt),
                        F=F, volume=F * volume0, volume0=volume0.copy(), mass=solution.material.rho0 * volume0)


def displacement_l2(volume: np.ndarray, error: np.ndarray) -> float:
    """``sqrt(sum V_p e_p^2 / sum V_p)``; ``volume``, ``error`` (n_p,)."""
    return float(np.sqrt(np.sum(volume * error**2) / np.sum(volume)))


def run(s: BarSettings, observer=None) -> BarRun:
    """Run ``s`` (module docstring); ``observer(n, t, particles, grid_state)`` is called after each step."""
    solution = AxisAligned1D(amplitude=s.amplitude)
    lo, hi = solution.domain
    grid = periodic_line(lo, hi, s.h)
    X, V0 = seed_positions(uniform_grid(lo, hi, s.h), s.ppc, s.layout, s.seed)
    T = solution.period if s.T is None else s.T
    c = solution.material.c
    n_steps = max(1, math.ceil(T * c / (s.cfl * s.h) - 1e-9) if s.dt is None else round(T / s.dt))
    dt = T / n_steps if s.dt is None else s.dt
    model = NeoHookeanBar.of(solution.material)
    stages = s.stages
    state = start(solution, X, V0, dt)
    worst, t = 0.0, 0.0
    t0 = time.perf_counter()
    for n in range(n_steps):
        try:
            state, grid_state = bar_step(state, grid, model, dt, t, solution.body_force, stages)
        except InvertedBarError as error:
            raise error.at(n + 1, t + dt) from None
        t = (n + 1) * dt
        error = state.displacement - solution.displacement(state.X, t)
        worst = max(worst, displacement_l2(state.volume, error))
        if observer is not None:
            observer(n + 1, t, state, grid_state)
    wall = time.perf_counter() - t0
    errors = {"displacement": {"L2": displacement_l2(state.volume, error), "Linf": float(np.max(np.abs(error))),
                               "L2_max": worst}}
    return BarRun(s, state, t, n_steps, dt, dt * c / s.h, errors, wall)


def bar(**settings) -> BarRun:
    """One run of the bar: the keywords are :class:`BarSettings`'.

    >>> bar(h=1/16, ppc=2, basis="mpm").errors["displacement"]["L2"]
    """
    known = set(asdict(BarSettings()))
    unknown = sorted(set(settings) - known)
    if unknown:
        raise TypeError(f"bar() got unknown settings {', '.join(unknown)}; choose from {', '.join(sorted(known))}")
    return run(BarSettings(**settings))
