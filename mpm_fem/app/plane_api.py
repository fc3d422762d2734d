"""The 2D entry points with the command line's checks: ``mpm_fem.plane.axis(...)``, ``mpm_fem.plane.vortex(...)``.

    >>> import mpm_fem
    >>> run = mpm_fem.plane.axis(h=1/8, ppc=2, basis="p1")
    >>> run.errors["displacement"]["particles"]["L2"], run.cfl

``axis`` and ``vortex`` take the fields of :class:`~mpm_fem.plane.run.PlaneSettings` as keywords
(``problem`` aside) and ``yes_long``, and return the :class:`~mpm_fem.plane.run.Run` of
:func:`mpm_fem.plane.run.run`. Before anything is allocated every bad input raises
:class:`~mpm_fem.app.guard.UsageError` (``mpm_fem.UsageError``) in one line naming the setting and
the value, the same line the command line ``mpm-fem plane`` prints (:mod:`mpm_fem.app.plane_cli`):

    names       an unknown keyword (:class:`~mpm_fem.app.guard.UnknownSetting`, also a ``TypeError``,
                with the closest name); a type other than the field's (:func:`mpm_fem.app.inputs.check_types`)
    mass        a name of the grid masses' registry (:func:`mpm_fem.masses.names`: ``lumped``,
                ``consistent``, ``grid``, ``exact``, ``fmpm1`` .. ``fmpm4``); another is refused listing them
    basis       a registered name, ``p1`` (the point-mass basis ``mpm``), an entry point's or
                ``package.module:Name`` (:func:`mpm_fem.app.inputs.extension`); one without a 2D
                (tensor-product) form is refused
    values      the settings' own checks; the amplitude of the solution (``A pi < 1``, ``A_y pi < 1``:
                the axis-aligned solution's ``J`` stays positive over the whole period at every point;
                the vortex is isochoric, ``J = 1``)
    mesh        ``h`` must divide the problem's domain (the axis-aligned square ``[0, 2]``, the vortex's
                ``[-1.5, 1.5]``)
    time step   ``cfl / refine`` above the linearised step's limit (:mod:`mpm_fem.plane.stability`)
    size        a run over half the available memory, or estimated over an hour without
                ``yes_long=True`` (:func:`mpm_fem.app.guard.check_cost` on :func:`cost`)

A particle that inverts during a run (``J <= 0``) stops it with
:class:`~mpm_fem.plane.model.InversionError` (an ``ArithmeticError``) naming the step, the time and
the particle. Other names (``PlaneSettings``, ``Run``, ``run``, ``step``, the submodules) are those of
:mod:`mpm_fem.plane`.
"""

from __future__ import annotations

import importlib
import math
import numbers
from dataclasses import dataclass, fields

import numpy as np

from mpm_fem.app import inputs, presets
from mpm_fem.app.guard import UsageError, check_cost
from mpm_fem.core.grid import n_cells_for
from mpm_fem.plane.run import VORTEX_BOX, PlaneSettings, Run, run, solution_of
from mpm_fem.plane.stability import cfl_limit, p_wave_ratio

_PACKAGE = importlib.import_module("mpm_fem.plane")  # the package itself, not this module (mpm_fem.plane)
__all__ = ["PlaneSettings", "Run", "axis", "vortex", "checked", "cost", "grid_of", "PlaneCost"]
YES_LONG = "yes_long=True"

# Bytes and seconds of one 2D run, measured on the numpy step (axis-aligned, h = 1/8 and 1/16, 2 x 2
# particles per cell, on the project's shared 2-core machine) with a margin: the peak of a run
# (tracemalloc) is 530 B per particle with the point-mass basis and 1220 B with the 3 x 3 and 4 x 4
# rows of GIMP and the B-splines (grid included); a step costs 1.2e-6 to 2e-6 s per particle (point
# mass, lumped) and 4.4e-6 to 5.4e-6 s (the wider rows, or the consistent mass's solve). The compiled
# step (mpm_fem.plane.fused, one thread, the problem's numpy body force, h = 1/32: 16384 particles)
# costs 1.6e-7 s per particle (point mass) and 3.2e-7 s (the quadratic B-spline).
BYTES_PER_PARTICLE = {"narrow": 600, "wide": 1300}
BYTES_PER_NODE = 400
SECONDS_PER_PARTICLE_STEP = {"numpy": {"narrow": 2e-6, "wide": 6e-6}, "fused": {"narrow": 2e-7, "wide": 4e-7}}
SECONDS_PER_STEP = 2e-3


@dataclass(frozen=True)
class PlaneCost:
    """The estimated size of a 2D run (the fields :func:`mpm_fem.app.guard.describe` and
    :func:`~mpm_fem.app.guard.check_cost` read): ``particles``, grid ``nodes``, time ``steps``, the
    ``kernel`` that takes them (``numpy`` or ``fused``) and the ``rows`` (``narrow``: the point-mass
    basis with the lumped mass; ``wide`` otherwise). ``bytes = b_p particles + 400 nodes`` (``b_p``
    600 or 1300 B), ``seconds = steps (a particles + 2e-3)`` (``a``: numpy 2e-6 or 6e-6 s, compiled
    2e-7 or 4e-7 s)."""

    particles: int
    nodes: int
    steps: int
    kernel: str = "numpy"
    rows: str = "narrow"

    @property
    def bytes(self) -> int:
        return BYTES_PER_PARTICLE[self.rows] * self.particles + BYTES_PER_NODE * self.nodes

    @property
    def seconds(self) -> float:
        return self.steps * (SECONDS_PER_PARTICLE_STEP[self.kernel][self.rows] * self.particles + SECONDS_PER_STEP)

    def as_dict(self) -> dict:
        return {"particles": self.particles, "nodes": self.nodes, "steps": self.steps, "kernel": self.kernel,
                "bytes": self.bytes, "seconds": round(self.seconds, 3)}


def _domain(s: PlaneSettings, solution) -> tuple[tuple[float, float], tuple[float, float], tuple[bool, bool]]:
    """The grid's sides and periodicity of ``s`` (as :func:`mpm_fem.plane.run.setup` builds it)."""
    if s.problem == "axis":
        (x0, x1), (y0, y1) = solution.domain
        return (x0, x1), (y0, y1), (True, True)
    cx, cy = solution.centre
    return (cx - VORTEX_BOX, cx + VORTEX_BOX), (cy - VORTEX_BOX, cy + VORTEX_BOX), (False, False)


def grid_of(s: PlaneSettings):
    """The grid :func:`mpm_fem.plane.run.run` builds for ``s`` (the same nodes and cells)."""
    from mpm_fem.plane.grid import plane_grid

    (x0, x1), (y0, y1), periodic = _domain(s, solution_of(s))
    return plane_grid((x0, y0), (x1, y1), s.h, periodic)


def _compiled(s: PlaneSettings) -> bool:
    """Whether the compiled step takes the run: asked for (a ``compiled`` setting) and served."""
    if not getattr(s, "compiled", False):
        return False
    from mpm_fem.plane.fused import served

    return served(s.basis, s.stages)


def cost(s: PlaneSettings, solution=None) -> PlaneCost:
    """:class:`PlaneCost` of ``s`` from the settings alone: ``ppc^2`` particles in every cell (the
    vortex: the annulus's share of the square), the grid's nodes, ``ceil(T c refine / (cfl h))`` steps."""
    solution = solution_of(s) if solution is None else solution
    (x0, x1), (y0, y1), periodic = _domain(s, solution)
    nx, ny = n_cells_for(x0, x1, s.h), n_cells_for(y0, y1, s.h)
    share = 1.0
    if s.problem == "vortex":
        share = min(1.0, math.pi * (solution.outer**2 - solution.inner**2) / ((x1 - x0) * (y1 - y0)))
    T = (solution.period if s.problem == "axis" else 1.0) if s.T is None else s.T
    steps = max(1, math.ceil(T * solution.material.c * s.refine / (s.cfl * s.h) - 1e-9))
    nodes = (nx + (not periodic[0])) * (ny + (not periodic[1]))
    rows = "narrow" if s.basis == "mpm" and s.mass == "lumped" else "wide"
    return PlaneCost(math.ceil(share * nx * ny * s.ppc**2), nodes, steps, "fused" if _compiled(s) else "numpy", rows)


def _check_optional_numbers(given: dict, call: str) -> None:
    """The settings whose default is ``None`` (``amplitude``, ``amplitude_y``, ``T``): a finite number or None."""
    for name in ("amplitude", "amplitude_y", "T"):
        value = given.get(name)
        if value is None:
            continue
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real) or not math.isfinite(value):
            raise UsageError(f"{call}(): {name} must be a finite number (or None), got {value!r}")


def checked(problem: str, given: dict, call: str | None = None, yes_long: bool = False,
            flag: str = YES_LONG) -> tuple[PlaneSettings, PlaneCost]:
    """The settings of one 2D run of ``problem`` with ``given`` and their cost, every check of the
    module docstring made before anything is allocated; else :class:`UsageError` naming ``call``
    (``flag``: how the caller asks for a long run)."""
    call = call or problem
    allowed = {f.name for f in fields(PlaneSettings)} - {"problem"}
    presets.check_keywords(given, allowed, call)
    _check_optional_numbers(given, call)
    s = inputs.settings(PlaneSettings, {"problem": problem, **given}, call, given)
    with inputs.refused(call):
        if s.seed < 0:
            raise ValueError(f"the random seed must be an integer >= 0, got {s.seed!r}")
        solution = solution_of(s)
        (x0, x1), (y0, y1), _ = _domain(s, solution)
        n_cells_for(x0, x1, s.h), n_cells_for(y0, y1, s.h)  # GridError (a ValueError) unless h tiles both sides
        limit = cfl_limit(s.basis, s.mass, solution.material)
        if limit is not None and s.cfl / s.refine > limit:
            raise ValueError(f"the CFL number dt c / h must lie in (0, {limit:.3g}] with the {s.mass} mass and the "
                             f"{s.basis} basis (dt <= {limit / p_wave_ratio(solution.material):.3g} h / c_p, c_p the "
                             f"P-wave speed: the stable range of the explicit step), got cfl={s.cfl:g}"
                             + (f" with refine={s.refine}" if s.refine != 1 else ""))
        with np.errstate(all="ignore"):
            estimate = cost(s, solution)
    try:
        check_cost(estimate, yes_long, flag=flag)
    except UsageError as err:
        raise UsageError(f"{call}(): {err} (h={s.h:g}, ppc={s.ppc}: a coarser h or fewer particles per cell)") from None
    return s, estimate


def axis(yes_long: bool = False, **settings) -> Run:
    """One checked run of the axis-aligned problem (module docstring).

    Parameters
    ----------
    yes_long : bool
        Run even if estimated over the command line's time limit (one hour).
    **settings
        Fields of :class:`~mpm_fem.plane.run.PlaneSettings` (``h``, ``ppc``, ``basis``, ``mass``,
        ``amplitude``, ``amplitude_y``, ``cfl``, ...).

    Returns
    -------
    Run
        ``errors["displacement"]["particles"]["L2" | "Linf" | "L2_max"]``,
        ``errors["acceleration"]["nodes"]["L2"]``, ``cfl``, ``steps``, ``dt`` (s), the particles and grid.
    """
    s, _ = checked("axis", settings, "axis", yes_long)
    return run(s)


def vortex(yes_long: bool = False, **settings) -> Run:
    """One checked run of the generalized vortex (module docstring; the keywords as :func:`axis`'s
    but ``amplitude_y``)."""
    s, _ = checked("vortex", settings, "vortex", yes_long)
    return run(s)


def __getattr__(name: str):
    return getattr(_PACKAGE, name)


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(dir(_PACKAGE)))
