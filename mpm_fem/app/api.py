"""The notebook entry points: one call runs a case with the command line's defaults.

    >>> import mpm_fem
    >>> run = mpm_fem.sod(h=0.01, ppc=4)
    >>> run.errors["density"]["particles"]["L1"]

:func:`sod` and :func:`burgers` take any field of :class:`~mpm_fem.problems.sod.SodSettings` /
:class:`~mpm_fem.problems.burgers.BurgersSettings` as a keyword (the same names and defaults as
``mpm-fem sod`` / ``mpm-fem burgers``) and return a :class:`Run`: the particles at ``T``, the nodal
fields projected from them, the exact solution at both, and the error norms (L1, L2, max over
particles and over nodes) of :func:`mpm_fem.problems.sod.errors` / :func:`~mpm_fem.problems.burgers.errors`.
Bad settings raise ``ValueError`` naming the setting; a run too large for the machine, or estimated
over the command line's time limit, is refused before anything is allocated
(:class:`~mpm_fem.app.guard.UsageError`), as on the command line.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mpm_fem.app.guard import check_cost
from mpm_fem.core.particles import Particles
from mpm_fem.core.solve import Result
from mpm_fem.problems import burgers as _burgers
from mpm_fem.problems import sod as _sod


@dataclass(frozen=True)
class Run:
    """One run: ``settings``; ``particles`` at ``t`` (sorted as the run keeps them);
    ``nodes`` (n_nodes,) and ``nodal`` fields on them (``density``, ``velocity`` for Sod; ``velocity``
    for Burgers); ``exact`` the exact solution at ``"particles"`` and ``"nodes"`` (the same fields);
    ``errors`` ``{field: {"particles" | "nodes": {"L1", "L2", "max"}}}``; ``result`` the solver's
    :class:`~mpm_fem.core.solve.Result` (steps, time steps, wall time)."""

    settings: object
    particles: Particles
    t: float
    nodes: np.ndarray
    nodal: dict = field(repr=False)
    exact: dict = field(repr=False)
    errors: dict = field(repr=False)
    result: Result = field(repr=False)


def _simulated(problem, settings_type, progress: bool | None, yes_long: bool, settings: dict):
    """The settings of ``problem`` (a module of :mod:`mpm_fem.problems`) checked for stability and cost,
    and its run: ``(settings, result)``."""
    s = settings_type(**settings)
    problem.check_stable(s)
    check_cost(problem.cost(s), yes_long)
    return s, problem.simulate(s, progress=progress)


def sod(progress: bool | None = False, yes_long: bool = False, **settings) -> Run:
    """Sod's shock tube (ideal gas, walls, ``T = 0.2``) with ``settings`` (:class:`SodSettings`)."""
    s, r = _simulated(_sod, _sod.SodSettings, progress, yes_long, settings)
    P, g = r.particles, r.grid
    names = ("density", "velocity", "pressure")
    exact = {where: dict(zip(names, _sod.exact(s, x, r.t), strict=True))
             for where, x in (("particles", P.x), ("nodes", g.nodes))}
    nodal = {"density": r.nodal_density, "velocity": r.nodal_velocity}
    return Run(s, P, r.t, g.nodes, nodal, exact, _sod.errors(s, r), r)


def burgers(progress: bool | None = False, yes_long: bool = False, **settings) -> Run:
    """Viscous Burgers on ``[0, 2]`` (``T = 0.5``) with ``settings`` (:class:`BurgersSettings`)."""
    s, r = _simulated(_burgers, _burgers.BurgersSettings, progress, yes_long, settings)
    P, g = r.particles, r.grid
    v = s.exact.v
    exact = {"particles": {"velocity": v(P.x, r.t)}, "nodes": {"velocity": v(g.nodes, r.t)}}
    return Run(s, P, r.t, g.nodes, {"velocity": r.nodal_velocity}, exact, _burgers.errors(s, r), r)
