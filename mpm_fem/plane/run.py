"""The 2D time loop and the two problems' runs: ``axis(...)`` and ``vortex(...)``.

A run steps :func:`mpm_fem.plane.step.step_with_grid` (or the compiled step where it serves:
``PlaneSettings.compiled``) from ``t = 0`` to ``T`` with the fixed step
``dt = T / N``, ``N = ceil(T c / (cfl h) * refine)`` (so that ``dt <= cfl h / (c refine)``, with
``c = sqrt(E / rho0)`` the material's speed and ``h`` the smaller cell size; the CFL number run is
``dt c refine / h``, stated in the :class:`Run`). The loop is over time steps only. Errors
(:mod:`mpm_fem.plane.norms`): the particle displacement at ``T`` (L2, Linf) and the largest L2 over
the steps, and the nodal acceleration of the last step (L2). Bad settings raise ``ValueError``
before any work.

The problems (``baselines.exact.solids``): ``axis`` the axis-aligned solution on the periodic
square ``[0, 2)^2``, to one period by default; ``vortex`` the generalized vortex, its particles
in the annulus on the non-periodic square ``[-1.5, 1.5]^2`` (traction-free: nothing imposed), to
``T = 1``. At the vortex's own amplitude 1 the shear ``R alpha_R`` reaches 7.07 (at ``t = 1/2``) and
every basis loses a particle (``det F <= 0``, or thrown out of the grid) before ``T``, earlier on finer
meshes: the default CFL 0.25 is above the stretched solid's limit for P1 and uGIMP
(:func:`mpm_fem.plane.stability.stretched_cfl_limit`: 0.219), and within every basis's limit the
particles' volume error in the free surface's cells does not converge in the maximum norm (docs/method.md,
"The vortex at A = 1"); small amplitudes (0.01) run to ``T``.
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field

import numpy as np

import mpm_fem.masses as masses
from mpm_fem.core.step import Stages
from mpm_fem.plane.bases import tensor_basis
from mpm_fem.plane.exact import ExactStages2, cell_quadrature, reference_of
from mpm_fem.plane.forces import compiled_force
from mpm_fem.plane.fused import PlaneFused, served
from mpm_fem.plane.grid import plane_grid
from mpm_fem.plane.model import InversionError
from mpm_fem.plane.norms import nodal_l2, particle_l2, particle_linf
from mpm_fem.plane.problems import LAYOUTS, inside, seed_reference, start
from mpm_fem.plane.step import check_stages, step_with_grid

PROBLEMS = ("axis", "vortex")
VORTEX_BOX = 1.5  # the vortex's grid: [-VORTEX_BOX, VORTEX_BOX]^2 about the centre


@dataclass(frozen=True)
class PlaneSettings:
    """One 2D run: the problem, ``h`` the cell size, ``ppc`` particles per cell per axis, the
    solution's ``amplitude``, the 1D ``basis`` of the tensor basis, the grid ``mass`` (a name of the
    registry :func:`mpm_fem.masses.names`: ``lumped``, ``consistent``, ``exact``, ``grid``, ``fmpm1`` ..
    ``fmpm4``), ``cfl``, the layout (``regular``, ``jittered``) and its ``seed``,
    ``T`` (None: one period for ``axis``, 1 for ``vortex``), the PIC/FLIP ``flip``, the stage
    switches ``projection``, ``interpolation``, ``acceleration`` and the time ``refine``, the
    order of the exact projection's reference quadrature ``quadrature``, the ``scheme``
    (``usl``, or ``musl``: :mod:`mpm_fem.plane.step`), ``amplitude_y`` the axis-aligned
    solution's y amplitude (None: ``amplitude``; 0: the y part off; ``axis`` only), and ``compiled``:
    True runs the compiled step (:mod:`mpm_fem.plane.fused`) where it serves the basis and the stages
    (:func:`mpm_fem.plane.fused.served`: a basis with compiled rows, USL, the lumped mass, the MPM
    stages), the numpy step elsewhere; False the numpy step always (equal to round-off)."""

    problem: str = "axis"
    h: float = 1 / 16
    ppc: int = 2
    amplitude: float | None = None
    basis: str = "mpm"
    mass: str = "lumped"
    cfl: float = 0.25
    seed: int = 0
    layout: str = "regular"
    T: float | None = None
    flip: float = 1.0
    projection: str = "mpm"
    interpolation: str = "mpm"
    acceleration: str = "calculated"
    refine: int = 1
    quadrature: int = 4
    scheme: str = "usl"
    amplitude_y: float | None = None
    compiled: bool = False

    def __post_init__(self):
        if self.problem not in PROBLEMS:
            raise ValueError(f"unknown 2D problem {self.problem!r}; choose one of {', '.join(PROBLEMS)}")
        if isinstance(self.h, bool) or not isinstance(self.h, (int, float)) or not (math.isfinite(self.h)
                                                                                   and self.h > 0):
            raise ValueError(f"the cell size h must be positive and finite, got {self.h!r}")
        if not (isinstance(self.cfl, (int, float)) and 0 < self.cfl <= 1):
            raise ValueError(f"the CFL number must lie in (0, 1], got {self.cfl!r}")
        if self.layout not in LAYOUTS:
            raise ValueError(f"unknown particle layout {self.layout!r}; choose one of {', '.join(LAYOUTS)}")
        if self.T is not None and not (math.isfinite(self.T) and self.T > 0):
            raise ValueError(f"the final time T must be positive, got {self.T!r}")
        if isinstance(self.quadrature, bool) or not isinstance(self.quadrature, int) or self.quadrature < 1:
            raise ValueError(f"the quadrature order must be an integer >= 1, got {self.quadrature!r}")
        if isinstance(self.ppc, bool) or not isinstance(self.ppc, (int, np.integer)) or self.ppc < 1:
            raise ValueError(f"particles per cell per axis must be an integer >= 1, got {self.ppc!r}")
        if self.amplitude_y is not None and self.problem != "axis":
            raise ValueError(f"amplitude_y is the axis-aligned solution's y amplitude; {self.problem} has none")
        if not isinstance(self.compiled, bool):
            raise ValueError(f"compiled must be True or False, got {self.compiled!r}")
        tensor_basis(self.basis)
        if masses.get(self.mass).fills and self.problem != "axis":  # ValueError naming the registered masses
            raise ValueError(f"the {self.mass} mass needs a body that fills the grid; the {self.problem}'s does not "
                             "(use the consistent mass)")
        check_stages(self.stages)

    @property
    def stages(self) -> Stages:
        return Stages(basis=self.basis, mass=masses.get(self.mass).stage, flip=self.flip, projection=self.projection,
                      interpolation=self.interpolation, acceleration=self.acceleration, refine=self.refine,
                      scheme=self.scheme)


@dataclass(frozen=True, eq=False)
class Run:
    """One 2D run: ``settings``; the particles at ``t`` (``particles``) on ``grid``; ``steps`` of ``dt`` (s) at
    the CFL number ``cfl`` (``dt c / h``); ``errors`` ``{"displacement": {"particles": {"L2", "Linf",
    "L2_max"}}, "acceleration": {"nodes": {"L2"}}}``; ``wall_s`` the loop's wall time (s); ``compiled``
    whether the compiled step ran it."""

    settings: PlaneSettings
    particles: object = field(repr=False)
    grid: object = field(repr=False)
    t: float
    steps: int
    dt: float
    cfl: float
    errors: dict = field(repr=False)
    wall_s: float
    compiled: bool = False

    def __repr__(self) -> str:
        e = self.errors["displacement"]["particles"]
        return (f"Run({self.settings.problem}: h={self.settings.h:g}, ppc={self.settings.ppc}, basis="
                f"{self.settings.basis}, {self.particles.n} particles, {self.steps} steps of dt={self.dt:.3g} "
                f"(cfl {self.cfl:.3g}) to t={self.t:.6g}; displacement L2 {e['L2']:.3g}, Linf {e['Linf']:.3g})")


def solution_of(s: PlaneSettings):
    """The manufactured solution of ``s`` (``baselines.exact.solids``)."""
    from baselines.exact.solids import AxisAligned, GeneralizedVortex

    if s.problem == "axis":
        given = {"amplitude": s.amplitude, "amplitude_y": s.amplitude_y}
        return AxisAligned(**{k: v for k, v in given.items() if v is not None})
    return GeneralizedVortex() if s.amplitude is None else GeneralizedVortex(amplitude=s.amplitude)


def setup(s: PlaneSettings):
    """The solution, grid, reference particles (``X``, ``V^0``, lengths) and final time of ``s``."""
    solution = solution_of(s)
    if s.problem == "axis":
        (x0, x1), (y0, y1) = solution.domain
        grid = plane_grid((x0, y0), (x1, y1), s.h, (True, True))
        T = solution.period if s.T is None else s.T
    else:
        cx, cy = solution.centre
        grid = plane_grid((cx - VORTEX_BOX, cy - VORTEX_BOX), (cx + VORTEX_BOX, cy + VORTEX_BOX), s.h)
        T = 1.0 if s.T is None else s.T
    X, V0, lengths = seed_reference(grid, s.ppc, s.layout, s.seed)
    keep = inside(solution, X)
    return solution, grid, (X[keep], V0[keep], lengths[keep]), T


def run(s: PlaneSettings, observer=None) -> Run:
    """Run ``s`` (module docstring); ``observer(n, t, particles, grid_state)`` is called after each step."""
    solution, grid, (X, V0, lengths), T = setup(s)
    c = solution.material.c
    h = min(grid.h)
    n_steps = max(1, math.ceil(T * c * s.refine / (s.cfl * h) - 1e-9))
    dt = T / n_steps
    stages = s.stages
    exact = None
    if stages.uses_exact_fields or stages.acceleration == "exact":
        Xq, wq = cell_quadrature(grid, s.quadrature)
        keep = inside(solution, Xq)
        exact = ExactStages2(solution, Xq[keep], wq[keep])
    state = start(solution, X, V0, lengths, dt)
    # the compiled step where it serves (its arrays reused step to step unless an observer may keep a state)
    fused = PlaneFused(grid, s.basis, reuse=observer is None) if s.compiled and served(s.basis, stages) else None
    force = (compiled_force(solution) or solution.body_force) if fused is not None else solution.body_force
    worst = 0.0
    t0 = time.perf_counter()
    t = 0.0
    for n in range(n_steps):
        try:
            if fused is None:
                state, grid_state = step_with_grid(state, grid, s.basis, solution.material, dt, t, force, stages,
                                                   exact, s.mass)
            else:
                state, grid_state = fused.step_with_grid(state, solution.material, dt, t, force, stages)
        except InversionError as error:
            raise error.at(n + 1, t + dt) from None
        a_time = t
        t = (n + 1) * dt
        u_exact = np.asarray(solution.displacement(state.X[:, 0], state.X[:, 1], t)).T
        worst = max(worst, particle_l2(state.volume, state.displacement - u_exact))
        if observer is not None:
            observer(n + 1, t, state, grid_state)
    wall = time.perf_counter() - t0
    error = state.displacement - u_exact
    with_mass = grid_state.mass > 0
    X_nodes = reference_of(solution, grid.nodes[with_mass], a_time)
    a_star = np.zeros_like(grid_state.acceleration)
    a_star[with_mass] = np.asarray(solution.acceleration(X_nodes[:, 0], X_nodes[:, 1], a_time)).T
    errors = {"displacement": {"particles": {"L2": particle_l2(state.volume, error), "Linf": particle_linf(error),
                                             "L2_max": worst}},
              "acceleration": {"nodes": {"L2": nodal_l2(grid_state.mass, grid_state.acceleration - a_star)}}}
    return Run(s, state, grid, t, n_steps, dt, dt * c * s.refine / h, errors, wall, fused is not None)


def axis(**settings) -> Run:
    """One run of the axis-aligned problem: the keywords are :class:`PlaneSettings`' (not ``problem``).

    >>> mpm_fem.plane.axis(h=1/16, ppc=2, basis="mpm").errors["displacement"]["particles"]["L2"]
    """
    return _entry("axis", settings)


def vortex(**settings) -> Run:
    """One run of the generalized vortex: the keywords are :class:`PlaneSettings`' (not ``problem``)."""
    return _entry("vortex", settings)


def _entry(problem: str, settings: dict) -> Run:
    known = set(asdict(PlaneSettings()))
    unknown = sorted(set(settings) - known) + (["problem"] if "problem" in settings else [])
    if unknown:
        raise TypeError(f"{problem}() got unknown settings {', '.join(unknown)}; choose from "
                        f"{', '.join(sorted(known - {'problem'}))}")
    return run(PlaneSettings(problem=problem, **settings))
