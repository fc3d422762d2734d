"""The time loop: ``run(problem, grid, particles, stages) -> Result``.

Steps :func:`mpm_fem.core.step.explicit_step` from ``t = 0`` to ``T`` with ``dt = model.stable_dt``,
or the problem's fixed ``dt``, divided by ``stages.refine`` (the last step shortened to land on
``T``). Every step is checked: lost positivity raises
:class:`~mpm_fem.core.particles.PositivityError` naming the step, and a non-finite particle state raises
:class:`FloatingPointError` naming the step and the particle: a run never returns NaN. Between
walls or Dirichlet ends with the lumped mass (and Burgers' reservoir, applied between loops) the
fused step takes the steps in compiled loops (:meth:`~mpm_fem.fused.step.FusedStep.advance`), the same
steps bit for bit.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from tqdm.auto import tqdm

from mpm_fem.bases import compiled
from mpm_fem.core.grid import Grid
from mpm_fem.core.particles import Particles, PositivityError
from mpm_fem.core.shape import basis_integrals, make_shape
from mpm_fem.core.step import Boundary, GridState, Model, Stages, explicit_step, numpy_only
from mpm_fem.core.transfer import MASS_KINDS, grid_values, nodal_mass, nodal_momentum
from mpm_fem.exact_stages import ExactFields, FieldStages
from mpm_fem.fused import FusedStep, all_finite, check_kernel, supported

LOOP_WORK = 4_000_000  # particle-steps per compiled loop of the fused step (about 0.1 s)
Observer = Callable[[int, float, Particles, Particles, GridState], None]


@dataclass(frozen=True)
class Problem:
    """What the time loop needs besides the particles.

    ``particle_boundary(particles, grid, t) -> particles`` removes particles that left the grid
    and adds inflow particles (Burgers); ``exact_acceleration(x_i, t)`` serves the exact stage;
    ``exact`` (:class:`~mpm_fem.exact_stages.fields.ExactFields`) serves the exact projection, mass and
    interpolation stages; ``dt``, if given, is a fixed time step instead of the CFL step.
    """

    model: Model
    boundary: Boundary
    T: float
    cfl: float
    exact_acceleration: Callable[[np.ndarray, float], np.ndarray] | None = None
    particle_boundary: Callable[[Particles, Grid, float], Particles] | None = None
    exact: ExactFields | None = None
    dt: float | None = None

    def __post_init__(self):
        if not (np.isfinite(self.T) and self.T >= 0):
            raise ValueError(f"the final time T must be >= 0, got {self.T}")
        if not (0 < self.cfl <= 1):
            raise ValueError(f"the CFL number must lie in (0, 1], got {self.cfl}")
        if self.dt is not None and not (np.isfinite(self.dt) and self.dt > 0):
            raise ValueError(f"a fixed time step must be positive, got {self.dt}")


@dataclass(frozen=True, eq=False)
class Result:
    """Final particles, the grid fields projected from them, and run statistics; ``kernel`` the step that
    ran: ``"fused"`` (compiled) or ``"numpy"``."""

    particles: Particles
    grid: Grid
    t: float
    steps: int
    wall_s: float
    nodal_mass: np.ndarray = field(repr=False)
    nodal_velocity: np.ndarray = field(repr=False)
    dt_min: float = 0.0
    dt_max: float = 0.0
    basis: str = "mpm"
    kernel: str = "numpy"

    @property
    def nodal_density(self) -> np.ndarray:
        """``m_i / int S_i dx``: the grid density seen by the projection (``S_i`` of the run's basis)."""
        return self.nodal_mass / basis_integrals(self.grid, self.basis)


def project(grid: Grid, particles: Particles, stages: Stages) -> tuple[np.ndarray, np.ndarray]:
    """Nodal mass ``m_i`` and velocity ``v_i`` of the particles (no boundary condition imposed)."""
    shape = make_shape(grid, particles.x, particles.volume, stages.basis)
    m_i = nodal_mass(shape, particles.mass)
    P_i = nodal_momentum(shape, particles.mass, particles.velocity)
    kind = stages.mass if stages.mass in MASS_KINDS else "lumped"  # "exact" is a stage switch
    return m_i, grid_values(shape, particles.mass, m_i, P_i, kind)


def _check_finite(particles: Particles, step: int, t: float) -> None:
    P = particles
    if all_finite(P.x, P.velocity, P.density, P.energy, P.pressure, P.volume):
        return
    for name in ("x", "velocity", "density", "energy", "pressure", "volume"):
        a = getattr(particles, name)
        bad = ~np.isfinite(a)
        if bad.any():
            p = int(np.flatnonzero(bad)[0])
            raise FloatingPointError(f"non-finite {name} at step {step} (t={t:.6g}) in particle {p}")


def _particle_boundary(problem: Problem, grid: Grid, particles: Particles, t: float, fused: FusedStep | None,
                       step: int | None = None) -> Particles:
    """The particle boundary applied at ``t``. If it changed the particles, the fused step's speed
    (the next time step's) is theirs; with ``step`` (after a compiled loop) they are checked finite."""
    new = problem.particle_boundary(particles, grid, t)
    if new is not particles:
        if step is not None:
            _check_finite(new, step, t)
        if fused is not None:
            fused.speed = problem.model.max_speed(new)
    return new


def _keeps_particles(observer: Observer | None) -> bool:
    """Whether ``observer`` may keep the particles it is handed beyond its call: yes unless it says
    otherwise (``keeps_particles = False``, as :class:`~mpm_fem.measure.regions.ExtremaCounter`). The fused
    step then writes into two alternating sets of arrays (:class:`~mpm_fem.fused.step.FusedStep`'s
    ``reuse``) instead of fresh ones, which cost a page fault per page on every step."""
    return observer is not None and getattr(observer, "keeps_particles", True) is not False


def _needs_numpy_step(observer: Observer | None) -> bool:
    """Whether ``observer`` asks for the numpy step (``needs_numpy_step = True``): the fused step's grid
    state is not the numpy step's arrays, and an instrumented run must take the steps it measures."""
    return observer is not None and getattr(observer, "needs_numpy_step", False) is True


def _counts_in_loop(observer: Observer, problem: Problem) -> bool:
    """Whether the compiled loop serves ``observer``: it counts what the loop can count (a ``tally`` and an
    ``absorb`` method, as :class:`~mpm_fem.measure.regions.ExtremaCounter`) and no particle boundary acts
    between steps (the loop would count before it, the per-step observer after it)."""
    return (callable(getattr(observer, "tally", None)) and callable(getattr(observer, "absorb", None))
            and problem.particle_boundary is None)


def run(
    problem: Problem,
    grid: Grid,
    particles: Particles,
    stages: Stages = Stages(),
    progress: bool | None = None,
    observer: Observer | None = None,
    max_steps: int = 10_000_000,
    kernel: str = "fused",
    threads: int = 1,
) -> Result:
    """Integrate to ``problem.T``. ``progress=None`` shows a bar on a terminal for runs over 2 s.

    ``kernel="fused"`` steps with the compiled :class:`~mpm_fem.fused.step.FusedStep` (on ``threads``
    threads) wherever it supports the model and stages (and they use no option of
    :func:`~mpm_fem.core.step.numpy_only`), the numpy :func:`explicit_step` otherwise;
    ``kernel="numpy"`` always steps with :func:`explicit_step`. Both take the same steps: bit for
    bit on one thread where the fused step does the numpy arithmetic, to round-off (measured at most
    6e-14 relative) where it takes a uniform grid's node arithmetic (``tests/test_fused.py``).
    ``observer(step, t, old, new, state)`` is called after every step, which then runs one at a time
    rather than in compiled loops, unless the loop counts for it (:func:`_counts_in_loop`: the loop
    takes ``observer.tally(particles)`` and hands it back to ``observer.absorb(tally, particles)``); the
    particles it is handed stay valid only for the call if it says it keeps none (:func:`_keeps_particles`).
    An observer that reads the numpy step's grid state (``needs_numpy_step = True``, as
    :class:`~mpm_fem.measure.defect.DefectObserver`) routes the run to the numpy step whatever ``kernel`` says."""
    check_kernel(kernel, threads)
    fused = None
    if (kernel == "fused" and supported(problem.model, stages) is None and numpy_only(problem.model, stages) is None
            and compiled(stages.basis) and not _needs_numpy_step(observer)):
        fused = FusedStep(grid, problem.model, problem.boundary, stages, problem.exact_acceleration, threads,
                          reuse=not _keeps_particles(observer), exact=problem.exact)
    # walls or Dirichlet ends, lumped mass, no observer, and no particle boundary or one that says
    # when it acts: steps in compiled loops of about LOOP_WORK particle-steps each (the bar and
    # Ctrl-C are served between them); a loop stops after a step the particle boundary acts on
    loop = fused is not None and (observer is None or _counts_in_loop(observer, problem)) and fused.loops(problem)
    exact = FieldStages(problem.exact) if problem.exact is not None else None  # the numpy step's exact stages
    start = time.perf_counter()
    t, steps = 0.0, 0
    dt_min, dt_max = np.inf, -np.inf
    disable = {True: False, False: True, None: None}[progress]  # None: only on a terminal
    bar = tqdm(total=problem.T, disable=disable, delay=2.0, leave=False,
               bar_format="{l_bar}{bar}| t={n:.4g}/{total:.4g} [{elapsed}<{remaining}]")
    try:
        while t < problem.T * (1 - 1e-12):
            if loop and steps > 0:
                t_old = t
                tally = observer.tally(particles) if observer is not None else None
                particles, t, done, low, high = fused.advance(particles, t, problem, steps, max_steps,
                                                              max(1, LOOP_WORK // max(particles.n, 1)), tally)
                if done:
                    if observer is not None:
                        observer.absorb(tally, particles)
                    steps += done
                    dt_min, dt_max = min(dt_min, low), max(dt_max, high)
                    bar.update(t - t_old)
                    if problem.particle_boundary is not None:
                        particles = _particle_boundary(problem, grid, particles, t, fused, steps - 1)
                    continue
            if problem.dt is not None:
                base = problem.dt
            elif fused is not None and steps > 0 and problem.particle_boundary is None:
                base = problem.model.dt_for_speed(fused.speed, grid, problem.cfl)  # max speed of the fused pass
            else:
                base = problem.model.stable_dt(particles, grid, problem.cfl)
            dt = min(base / stages.refine, problem.T - t)
            if not (dt > 0 and np.isfinite(dt)):
                raise FloatingPointError(f"time step {dt!r} at step {steps} (t={t:.6g}) is not positive and finite")
            if steps >= max_steps:
                raise RuntimeError(f"{max_steps} steps did not reach T={problem.T} (t={t:.6g})")
            try:
                if fused is not None:
                    new, state = fused.step(particles, t, dt)
                else:
                    new, state = explicit_step(grid, particles, problem.model, problem.boundary, t, dt, stages,
                                               problem.exact_acceleration, exact)
            except PositivityError as err:
                raise err.at(steps, t) from None
            if problem.particle_boundary is not None:
                new = _particle_boundary(problem, grid, new, t + dt, fused)
            if fused is None or problem.particle_boundary is not None or not fused.finite:
                _check_finite(new, steps, t)
            if observer is not None:
                observer(steps, t, particles, new, state)
            particles = new
            t += dt
            steps += 1
            dt_min, dt_max = min(dt_min, dt), max(dt_max, dt)
            bar.update(dt)
    finally:
        bar.close()
    m_i, v_i = project(grid, particles, stages)
    return Result(
        particles=particles,
        grid=grid,
        t=t,
        steps=steps,
        wall_s=time.perf_counter() - start,
        nodal_mass=m_i,
        nodal_velocity=v_i,
        dt_min=dt_min if steps else 0.0,
        dt_max=dt_max if steps else 0.0,
        basis=stages.basis,
        kernel="numpy" if fused is None else "fused",
    )
