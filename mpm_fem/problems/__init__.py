"""Problem set-ups: settings with their defaults in one place, initial particles, exact solutions.

Also what every problem shares before a run starts: the checks of its settings, and the estimate
of its cost (:class:`Cost`), both made from the settings alone, without allocating the grid or
the particles.
"""

import math
from dataclasses import asdict, dataclass, fields

import numpy as np

from mpm_fem.bases import compiled
from mpm_fem.core.grid import n_cells_for
from mpm_fem.core.particles import LAYOUTS
from mpm_fem.core.step import Stages, StageSwitches
from mpm_fem.core.transfers import get as get_transfer
from mpm_fem.fused.support import COMPILED_MASSES

# Bytes and seconds of one run, measured and then given a margin (stated, not tuned per run):
# the particle state plus the peak of one step is 212-250 B per particle (benchmarks/step_cost.py,
# README "Performance"); the grid with its scikit-fem basis and mass matrices peaks at 320 B per
# node; 32 B per step are kept as a margin (the run once kept every time step). A step costs, in
# CPU time on a shared 2-core machine: the numpy step 1.5e-7 to 3.2e-7 s per particle plus about
# 0.7 ms (Sod, 4 and 16 particles per cell); the fused step 3e-8 s per particle (P1; GIMP, the
# B-spline and the consistent mass 7e-8 to 1.6e-7) plus 4 us (walls: the compiled loop) to
# 0.13 ms (Burgers: one call per step, its inflow and Dirichlet data in Python).
# The fused constants apply where the fused step runs (not the exact stages, not the Taylor
# reconstruction: the blend, XPIC(m), the particle-domain B-spline and the grid volume run fused).
BYTES_PER_PARTICLE = 400
BYTES_PER_NODE = 400
BYTES_PER_STEP = 32
SECONDS_PER_PARTICLE_STEP = {"numpy": 3e-7, "fused": 1e-7}
SECONDS_PER_STEP = {"numpy": 1e-3, "fused": 3e-4}


@dataclass(frozen=True)
class Cost:
    """The estimated size of a run: particles ``n_p``, grid nodes, time steps; from these the
    bytes ``400 n_p + 400 nodes + 32 steps`` and the seconds ``steps (a n_p + b)`` with the
    constants of the ``kernel`` that takes the steps (numpy: a = 3e-7 s, b = 1e-3 s; fused: 1e-7 s,
    3e-4 s)."""

    particles: int
    nodes: int
    steps: int
    kernel: str = "numpy"

    @property
    def bytes(self) -> int:
        return BYTES_PER_PARTICLE * self.particles + BYTES_PER_NODE * self.nodes + BYTES_PER_STEP * self.steps

    @property
    def seconds(self) -> float:
        per_particle, per_step = SECONDS_PER_PARTICLE_STEP[self.kernel], SECONDS_PER_STEP[self.kernel]
        return self.steps * (per_particle * self.particles + per_step)

    def as_dict(self) -> dict:
        return {"particles": self.particles, "nodes": self.nodes, "steps": self.steps, "bytes": self.bytes,
                "seconds": round(self.seconds, 3)}


@dataclass(frozen=True)
class RunSettings(StageSwitches):
    """The settings every MPM run shares, with the command line's defaults: the mesh size ``h``,
    particles per cell ``ppc`` and their ``layout`` (``seed`` for the random ones), the final time
    ``T`` and CFL number ``cfl``, the stage switches (:class:`~mpm_fem.core.step.StageSwitches`; a
    problem adds ``acceleration`` where it has an exact one), and the step's implementation (``kernel``,
    ``threads``; :func:`mpm_fem.run.solve.run`). A problem's settings subclass this one, adding its own
    parameters and changing the defaults it needs."""

    # the mesh and the particles
    h: float = 0.01
    ppc: int = 4
    layout: str = "regular"
    seed: int = 0
    # the time interval and the time step
    T: float = 0.2
    cfl: float = 0.1
    # the implementation of the step
    kernel: str = "fused"
    threads: int = 1

    @property
    def stages(self) -> Stages:
        """The stage switches of these settings (``Stages``' defaults for those they lack)."""
        return Stages(**{f.name: getattr(self, f.name) for f in fields(Stages) if hasattr(self, f.name)})

    def as_dict(self) -> dict:
        return asdict(self)


def run_cost(settings, domain: tuple[float, float], max_speed: float, dt_cap: float = math.inf) -> Cost:
    """:class:`Cost` of a run on ``domain`` whose time step is ``min(CFL h / max_speed, CFL dt_cap)
    / refine`` (the CFL step, ``dt_cap`` a further limit such as explicit diffusion)."""
    n_cells = n_cells_for(*domain, settings.h)
    dt = settings.cfl * min(settings.h / max_speed if max_speed > 0 else math.inf, dt_cap) / settings.refine
    ratio = settings.T / dt if settings.T > 0 and dt > 0 else (math.inf if settings.T > 0 else 0.0)
    if not math.isfinite(ratio):
        raise ValueError(f"the run is too large to estimate: T / dt = {settings.T:g} / {dt:g} steps is not finite")
    steps = math.ceil(ratio)
    stages = settings.stages
    fused = (settings.kernel == "fused" and not (stages.uses_exact_fields or stages.reconstruct != "none")
             and stages.mass in COMPILED_MASSES
             and compiled(stages.basis) and get_transfer(stages.transfer_name).compiled)  # else the numpy step
    return Cost(particles=n_cells * settings.ppc, nodes=n_cells + 1, steps=steps, kernel="fused" if fused else "numpy")


def check_run_settings(settings, domain: tuple[float, float]) -> None:
    """The checks every run's settings share: ``h`` divides ``domain`` (without building the
    grid), a known layout, integer ``ppc >= 1``, an integer seed >= 0, ``T >= 0``, CFL in
    ``(0, 1]``, and valid stage switches. Raises ``ValueError``."""
    n_cells_for(*domain, settings.h)  # raises GridError (a ValueError) unless h divides the domain
    if settings.layout not in LAYOUTS:
        raise ValueError(f"unknown particle layout {settings.layout!r}; choose one of {', '.join(LAYOUTS)}")
    if isinstance(settings.ppc, bool) or not isinstance(settings.ppc, int) or settings.ppc < 1:
        raise ValueError(f"particles per cell must be an integer >= 1, got {settings.ppc!r}")
    if isinstance(settings.seed, bool) or not isinstance(settings.seed, int) or settings.seed < 0:
        raise ValueError(f"the random seed must be an integer >= 0, got {settings.seed!r}")
    if not (np.isfinite(settings.T) and settings.T >= 0):
        raise ValueError(f"the final time T must be finite and >= 0, got {settings.T}")
    if not (0 < settings.cfl <= 1):
        raise ValueError(f"the CFL number must lie in (0, 1], got {settings.cfl}")
    _ = settings.stages  # building the stage switches validates them (ValueError)


def check_stable_cfl(settings, limit: float, why: str) -> None:
    """CFL in ``(0, limit]``, the stable range of the explicit step (``why`` names the case).
    The command line refuses a run outside it; a study may run one on purpose, to show it fail."""
    if not settings.cfl <= limit:
        raise ValueError(f"the CFL number must lie in (0, {limit:g}] {why} (the stable range of the explicit "
                         f"step), got {settings.cfl}")


def check_non_negative(**values) -> None:
    """Each named value is finite and >= 0 (coefficients such as the artificial viscosity's)."""
    for name, value in values.items():
        if not (np.isfinite(value) and value >= 0):
            raise ValueError(f"{name} must be finite and >= 0, got {value}")


def totals(particles) -> dict:
    """What the particles carry: mass ``sum m_p``, momentum ``sum m_p v_p`` and energy
    ``sum m_p (eps_p + v_p^2 / 2)`` (internal plus kinetic; ``eps_p = 0`` for Burgers)."""
    m, v = particles.mass, particles.velocity
    return {"mass": float(m.sum()), "momentum": float((m * v).sum()),
            "energy": float((m * (particles.energy + 0.5 * v * v)).sum())}


def relative_change(start: float, end: float, expected_change: float = 0.0) -> float | None:
    """``(end - start - expected_change) / |start|``, or relative to ``|expected_change|`` when
    ``start`` is zero; ``None`` if both are zero."""
    scale = abs(start) or abs(expected_change)
    return (end - start - expected_change) / scale if scale else None
