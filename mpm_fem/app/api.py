"""The notebook entry points: one call runs a case, a convergence study, a baseline or the exact solution.

    >>> import mpm_fem
    >>> run = mpm_fem.sod(h=0.01, ppc=4)                     # one MPM run (the command line's defaults)
    >>> run = mpm_fem.sod(preset="study", h=0.01)            # at the Sod study's settings
    >>> mpm_fem.sod.settings("study")                        # the settings of a preset, read-only
    >>> mpm_fem.sod.convergence(hs=(0.01, 0.005), seeds=(0, 1, 2), preset="study")
    >>> mpm_fem.sod.fem(h=0.01, mass="consistent")           # the fixed-mesh baselines
    >>> mpm_fem.sod.exact(x, t=0.2)                          # the exact solution

:data:`sod` and :data:`burgers` are :class:`Entry` objects: called, they take any field of
:class:`~mpm_fem.problems.sod.SodSettings` / :class:`~mpm_fem.problems.burgers.BurgersSettings` as a
keyword (the same names and defaults as ``mpm-fem sod`` / ``mpm-fem burgers``, or a ``preset``'s:
:mod:`mpm_fem.app.presets`) and return a :class:`Run`: the particles at ``T``, the nodal fields
projected from them, the exact solution at both, and the error norms (L1, L2, max over particles and
over nodes) of :func:`mpm_fem.problems.sod.errors` / :func:`~mpm_fem.problems.burgers.errors`. Their
methods run a convergence study (:mod:`mpm_fem.app.convergence`), the baselines and the exact solution
(:mod:`mpm_fem.app.references`). Every bad input raises one exception,
:class:`~mpm_fem.app.guard.UsageError` (``mpm_fem.UsageError``, a ``ValueError``), in one line naming
the setting and the value (:mod:`mpm_fem.app.inputs`); an unknown keyword is its subclass
:class:`~mpm_fem.app.guard.UnknownSetting` (also a ``TypeError``), naming the closest one; a run too
large for the machine, or estimated over the command line's time limit, is refused before anything is
allocated (naming ``yes_long=True``). ``basis`` and ``transfer`` take what the command line's
``--basis`` and ``--transfer`` take: a registered name (``p1`` is the point-mass basis ``mpm``), an
installed entry point's (found on first use) or ``package.module:Name``. While numba compiles the
kernels (a first run) one line on stderr says so (:mod:`mpm_fem.app.compiling`).
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass, field, fields

import numpy as np

from mpm_fem.app import inputs, presets, references
from mpm_fem.app.compiling import compile_notice
from mpm_fem.app.convergence import FIELDS, SOLVERS, Convergence, measured, summarise
from mpm_fem.app.guard import LONG_RUN_S, UsageError, check_cost
from mpm_fem.core.particles import Particles
from mpm_fem.run.solve import Result

#: The fields whose error a convergence study can measure, by problem.
MEASURED = {"sod": ("density", "velocity", "pressure"), "burgers": ("velocity",)}
#: How a Python caller asks for a long run (the guard's message names it).
YES_LONG = "yes_long=True"


@dataclass(frozen=True, eq=False, repr=False)
class RunResult(Result):
    """The solver's :class:`~mpm_fem.run.solve.Result`, shown in one line (no arrays)."""

    def __repr__(self) -> str:
        return (f"Result(t={self.t:.6g}, {self.steps} steps, dt {self.dt_min:.3g} to {self.dt_max:.3g}, "
                f"{self.particles.n} particles, {self.grid.n_nodes} nodes, {self.wall_s:.2f} s)")


@dataclass(frozen=True, repr=False)
class Run:
    """One run: ``settings``; ``particles`` at ``t`` (sorted as the run keeps them);
    ``nodes`` (n_nodes,) and ``nodal`` fields on them (``density``, ``velocity`` for Sod; ``velocity``
    for Burgers); ``exact`` the exact solution at ``"particles"`` and ``"nodes"`` (the same fields);
    ``errors`` ``{field: {"particles" | "nodes": {"L1", "L2", "max"}}}``; ``result`` the solver's
    :class:`~mpm_fem.run.solve.Result` (steps, time steps, wall time). Shown in one line."""

    settings: object
    particles: Particles
    t: float
    nodes: np.ndarray
    nodal: dict = field(repr=False)
    exact: dict = field(repr=False)
    errors: dict = field(repr=False)
    result: Result = field(repr=False)

    def __repr__(self) -> str:
        s = self.settings
        problem = type(s).__name__.removesuffix("Settings").lower()
        changed = "".join(f", {f.name}={getattr(s, f.name)!r}" for f in fields(s)
                          if f.name not in ("h", "ppc", "cfl") and getattr(s, f.name) != f.default)
        name = next(iter(self.errors))
        e = self.errors[name]
        return (f"Run({problem}: h={s.h:g}, ppc={s.ppc}, cfl={s.cfl:g}{changed}; {self.particles.n} particles, "
                f"{self.result.steps} steps to t={self.t:.6g}; {name} L1 {e['particles']['L1']:.3g} (particles), "
                f"{e['nodes']['L1']:.3g} (nodes))")


def _module(problem: str):
    return importlib.import_module(f"mpm_fem.problems.{problem}")


def checked_settings(problem: str, preset: str, given: dict, call: str, yes_long: bool = False):
    """The settings of one run: ``preset``'s with ``given`` applied, checked for unknown names,
    stability and cost (``yes_long``) before anything is allocated."""
    kind = presets.settings_type(problem)
    presets.check_keywords(given, {f.name for f in fields(kind)}, call)
    s = inputs.settings(kind, {**presets.changes(problem, preset), **given}, call, given)
    module = _module(problem)
    with inputs.refused(call), np.errstate(all="ignore"):  # extreme settings: a non-finite estimate is refused
        module.check_stable(s)
        cost = module.cost(s)
    check_cost(cost, yes_long, flag=YES_LONG)
    return s


def run(problem: str, preset: str = "defaults", progress: bool | None = False, yes_long: bool = False,
        **settings) -> Run:
    """One MPM run of ``problem`` (``"sod"`` or ``"burgers"``); see :class:`Entry`."""
    s = checked_settings(problem, preset, settings, problem, yes_long)
    module = _module(problem)
    with compile_notice():
        r = module.simulate(s, progress=progress)
    r = RunResult(**{f.name: getattr(r, f.name) for f in fields(r)})
    P, g = r.particles, r.grid
    if problem == "sod":
        exact = {where: dict(zip(references.SOD_FIELDS, module.exact(s, x, r.t), strict=True))
                 for where, x in (("particles", P.x), ("nodes", g.nodes))}
        nodal = {"density": r.nodal_density, "velocity": r.nodal_velocity}
    else:
        v = s.exact.v
        exact = {"particles": {"velocity": v(P.x, r.t)}, "nodes": {"velocity": v(g.nodes, r.t)}}
        nodal = {"velocity": r.nodal_velocity}
    return Run(s, P, r.t, g.nodes, nodal, exact, module.errors(s, r), r)


def convergence(problem: str, hs, seeds=(0,), preset: str = "defaults", solver: str = "mpm",
                field: str | None = None, seeded: str = "jittered", jobs: int | None = None, cache=None,
                progress: bool | None = None, yes_long: bool = False, **settings) -> Convergence:
    """Run ``problem`` on every mesh of ``hs`` and every seed of ``seeds``: the errors and observed
    orders with their range over the seeds (:mod:`mpm_fem.app.convergence`).

    Parameters
    ----------
    problem : str
        ``"sod"`` or ``"burgers"``.
    hs : sequence of float
        The meshes (cell sizes); at least two.
    seeds : sequence of int
        Seed 0: the settings' layout (regular unless set); seed ``k >= 1``: the ``seeded`` layout drawn
        with seed ``k``. The baselines take seed 0 only.
    preset : str
        Named settings (:mod:`mpm_fem.app.presets`).
    solver : str
        ``"mpm"``, ``"fem"`` (``mass`` among the settings) or, for Sod, ``"fv"``.
    field : str, optional
        The field whose error is measured (Sod: ``density``; Burgers: ``velocity``).
    seeded : str
        The layout of the seeds ``k >= 1`` (``"jittered"`` or ``"random"``).
    jobs : int, optional
        Worker processes (default: the cores, at most 8).
    cache : path, optional
        A folder keeping finished runs: a rerun with the same settings and code reads them.
    progress : bool, optional
        Progress on stderr (``None``: a bar on a terminal, lines otherwise).
    yes_long : bool
        Run even if the runs together are estimated over the command line's time limit.
    **settings
        The settings every run shares (MPM: fields of the settings dataclass; baselines:
        :mod:`mpm_fem.app.references`).

    Returns
    -------
    Convergence
        ``runs`` (one row per run), ``rows`` (one per mesh), ``orders`` (fitted over the meshes).
    """
    from mpm_fem.app.sweep import run_cases

    presets.check_name("problem", problem, presets.PROBLEMS)
    presets.check_name(f"solver of {problem}", solver, SOLVERS[problem])
    field = field or FIELDS[problem]
    presets.check_name(f"field of {problem}", field, MEASURED[problem])
    call = f"{problem}.convergence"
    seeds = _sequence("seeds", seeds, call)
    if not seeds or any(isinstance(k, bool) or not isinstance(k, int) or k < 0 for k in seeds):
        raise UsageError(f"{call}(): seeds are integers >= 0 (0: the settings' own layout), got seeds={seeds}")
    hs = tuple(inputs.number("h of hs", h, call) for h in _sequence("hs", hs, call))
    hs, seeds = tuple(sorted(hs, reverse=True)), tuple(sorted(set(seeds)))
    if len(hs) < 2 or len(set(hs)) < len(hs):
        raise UsageError(f"{call}(): a convergence study takes at least two different meshes, got hs={hs}")
    if solver != "mpm" and seeds != (0,):
        raise UsageError(f"{call}(): the {solver} baseline has no particle layout: run it with seeds=(0,), "
                         f"got seeds={seeds}")
    cases, seconds = [], 0.0
    for h in hs:
        for k in seeds:
            if solver == "mpm":
                layout = {"layout": seeded, "seed": k} if k else {}
                s = checked_settings(problem, preset, {**settings, "h": h, **layout}, call, yes_long=True)
                seconds += _module(problem).cost(s).seconds
                given = s.as_dict()
            else:
                given = _baseline_settings(problem, solver, preset, {**settings, "h": h})
                problem_of = {k: given[k] for k in ("solution", "eps") if k in given}
                inputs.settings(presets.settings_type(problem), {"h": h, **problem_of}, call)  # h divides the domain
            cases.append({"problem": problem, "solver": solver, "field": field, "settings": given})
    if seconds > LONG_RUN_S and not yes_long:
        raise UsageError(f"{len(cases)} runs estimated at {seconds / 3600:.3g} h together: over "
                         f"{LONG_RUN_S / 3600:g} h; pass {YES_LONG} to run them")
    order = sorted(range(len(cases)), key=lambda k: cases[k]["settings"]["h"])  # the costliest first
    got = run_cases(measured, [cases[k] for k in order], jobs=jobs, cache_dir=cache,
                    desc=f"{problem} {solver} convergence", progress=progress)
    results = [None] * len(cases)
    for k, r in zip(order, got, strict=True):
        results[k] = r
    shared = {k: v for k, v in cases[0]["settings"].items() if k not in ("h", "layout", "seed")}
    return summarise(problem, solver, field, shared, cases, results)


def _sequence(name: str, values, call: str) -> tuple:
    """``values`` as a tuple (a sequence or array of them; not a string), else ``UsageError``."""
    if isinstance(values, (str, bytes)) or not hasattr(values, "__iter__"):
        raise UsageError(f"{call}(): {name} takes a sequence, e.g. {name}=(0.02, 0.01), got {values!r}")
    return tuple(values)


def _baseline_settings(problem: str, solver: str, preset: str, given: dict) -> dict:
    """A baseline run's keywords (:mod:`mpm_fem.app.references`), their names and types checked."""
    call = f"{problem}.convergence"
    allowed = {"h", *references.keywords(problem, solver, preset)}
    presets.check_keywords(given, allowed, call)
    references.check_types(problem, solver, preset, {k: v for k, v in given.items() if k != "h"}, call)
    return {**given, "preset": preset}


@dataclass(frozen=True)
class Entry:
    """A problem's entry point: ``entry(**settings)`` runs MPM once (:func:`run`), and its methods run
    a convergence study, the baselines and the exact solution with the same settings names."""

    problem: str

    def __call__(self, h: float | None = None, preset: str = "defaults", progress: bool | None = False,
                 yes_long: bool = False, **settings) -> Run:
        """One MPM run with ``preset``'s settings (the command line's by default) and ``settings``.

        Parameters
        ----------
        h : float, optional
            The cell size (the preset's if not given), the one setting that may be given by position.
        preset : str
            ``"defaults"``, ``"study"`` or ``"source"`` (:mod:`mpm_fem.app.presets`).
        progress : bool, optional
            A progress bar (``None``: on a terminal, for runs over 2 s).
        yes_long : bool
            Run even if estimated over the command line's time limit (one hour).
        **settings
            Any field of the problem's settings dataclass.

        Returns
        -------
        Run
        """
        if h is not None:
            settings["h"] = h
        return run(self.problem, preset, progress, yes_long, **settings)

    def settings(self, preset: str = "defaults"):
        """Every setting under ``preset``, read-only (:func:`mpm_fem.app.presets.settings`)."""
        return presets.settings(self.problem, preset)

    def convergence(self, hs, seeds=(0,), preset: str = "defaults", **options) -> Convergence:
        """A convergence study over the meshes ``hs`` and ``seeds`` (:func:`convergence`)."""
        return convergence(self.problem, hs, seeds, preset, **options)

    def fem(self, h: float, mass: str = "lumped", preset: str = "defaults", **settings) -> references.Reference:
        """The fixed-mesh P1 FEM baseline on the mesh ``h`` (:mod:`mpm_fem.app.references`)."""
        fem = references.sod_fem if self.problem == "sod" else references.burgers_fem
        return fem(h, mass, preset, **settings)

    def fv(self, h: float, preset: str = "defaults", **settings) -> references.Reference:
        """Sod's finite-volume baseline on the cells of the mesh ``h`` (:func:`~mpm_fem.app.references.sod_fv`)."""
        if self.problem != "sod":
            raise UsageError(f"{self.problem} has no finite-volume baseline; its baseline is fem()")
        return references.sod_fv(h, preset, **settings)

    def exact(self, x, t: float | None = None, **settings) -> dict:
        """The exact solution at the points ``x`` and time ``t`` (:func:`~mpm_fem.app.references.exact`)."""
        return references.exact(self.problem, x, t, **settings)


#: Sod's shock tube (ideal gas, walls, ``T = 0.2``): ``sod(**settings)`` runs MPM with :class:`SodSettings`.
sod = Entry("sod")
#: Viscous Burgers on ``[0, 2]`` (``T = 0.5``): ``burgers(**settings)`` runs MPM with :class:`BurgersSettings`.
burgers = Entry("burgers")
