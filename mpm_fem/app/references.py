"""The baselines and the exact solutions from Python: thin wrappers around :mod:`baselines`.

    sod_fem(h, mass)        P1 Galerkin FEM on Sod's tube (:func:`baselines.fem_euler.solve`)
    sod_fv(h)               MUSCL-Hancock finite volumes with HLLC (:func:`baselines.fv_euler.solve`)
    burgers_fem(h, mass)    P1 Galerkin FEM on viscous Burgers (:func:`baselines.fem_burgers.solve`)
    exact(problem, x, t)    the exact solution (:mod:`baselines.exact`)

Each takes the settings under the names its study uses (:mod:`mpm_fem.app.presets`), and the errors
are those the studies tabulate: ``e = q_h - q(x, t)`` with the weights ``int S_i dx`` at FEM nodes
and ``h`` at FV cell centres, so that ``sod_fem(h, "lumped").errors["density"]["nodes"]["L1"]`` is
the ``fem_lumped_L1`` column of ``figures/sod/convergence.csv``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np

from mpm_fem.app import inputs
from mpm_fem.app.guard import UsageError
from mpm_fem.app.presets import baseline_settings, check_keywords, check_name, settings_type
from mpm_fem.core.grid import uniform_grid
from mpm_fem.measure.errors import norms

SOD_FIELDS = ("density", "velocity", "pressure")


@dataclass(frozen=True, repr=False)
class Reference:
    """One run of a baseline.

    Attributes
    ----------
    method : str
        The baseline's name, e.g. ``"FEM P1 lumped (viscosity everywhere)"``.
    settings : Mapping
        Its settings (read-only), ``h`` and ``mass`` (FEM) among them.
    x : ndarray, shape (n,)
        Where its values live: the nodes (FEM) or the cell centres (FV).
    fields, exact : dict of ndarray, shape (n,)
        The computed and the exact fields at ``x`` (Sod: density, velocity, pressure; Burgers: velocity).
    errors : dict
        ``{field: {"nodes" | "cells": {"L1", "L2", "max"}}}``.
    t : float
        The final time.
    steps : int
        Time steps taken.
    """

    method: str
    settings: Mapping
    x: np.ndarray = field(repr=False)
    fields: dict = field(repr=False)
    exact: dict = field(repr=False)
    errors: dict = field(repr=False)
    t: float = 0.0
    steps: int = 0

    def __repr__(self) -> str:
        name = next(iter(self.errors))
        where, e = next(iter(self.errors[name].items()))
        return (f"Reference({self.method}, h={self.settings['h']:g}: {self.x.size} {where}, {self.steps} steps to "
                f"t={self.t:.6g}; {name} L1 {e['L1']:.3g}, L2 {e['L2']:.3g}, max {e['max']:.3g})")


def _errors(fields: dict, exact: dict, weights: np.ndarray, where: str) -> dict:
    return {k: {where: norms(fields[k] - exact[k], weights)} for k in fields}


#: The keywords of each baseline besides its preset's settings (``mass``: the FEM's argument).
EXTRA = {("sod", "fem"): ("mass", "T", "gamma"), ("sod", "fv"): ("T", "gamma"),
         ("burgers", "fem"): ("mass", "solution", "eps", "T")}


def keywords(problem: str, solver: str, preset: str = "defaults") -> tuple[str, ...]:
    """The keywords a baseline takes besides ``h`` and ``preset``."""
    return (*baseline_settings(problem, solver, preset), *EXTRA[(problem, solver)])


#: The mass matrices of the FEM baselines.
MASSES = ("lumped", "consistent")


def check_types(problem: str, solver: str, preset: str, given: dict, call: str) -> None:
    """Each of ``given`` (a baseline's keywords but ``h``) has the type of its default (the preset's,
    or the MPM settings' for ``T``, ``gamma``, ``solution``, ``eps``); ``mass`` is one of
    :data:`MASSES`. Raises :class:`~mpm_fem.app.guard.UsageError`."""
    mpm = {f: v.default for f, v in settings_type(problem).__dataclass_fields__.items()}
    defaults = {**mpm, **baseline_settings(problem, solver, preset)}
    inputs.check_types(defaults, {k: v for k, v in given.items() if k != "mass"}, call)
    if "mass" in given:
        check_name("mass", given["mass"], MASSES)


def _settings(problem: str, solver: str, preset: str, given: dict, extra: dict, call: str) -> dict:
    """The preset's settings of the baseline with ``given`` applied (unknown names and wrong types
    refused); ``extra``: the defaults of the names of :data:`EXTRA` but ``mass``."""
    values = {**baseline_settings(problem, solver, preset), **extra}
    check_keywords(given, values, call)
    check_types(problem, solver, preset, given, call)
    return {**values, **given}


def _mesh(h, domain: tuple[float, float], call: str) -> float:
    """``h`` a finite number dividing ``domain``, else :class:`~mpm_fem.app.guard.UsageError`."""
    h = inputs.number("h", h, call)
    with inputs.refused(call):
        uniform_grid(*domain, h)
    return h


def sod_fem(h: float, mass: str = "lumped", preset: str = "defaults", **settings) -> Reference:
    """Sod's tube with P1 Galerkin FEM (``mass`` ``"lumped"`` or ``"consistent"``) on the mesh ``h``.

    Parameters
    ----------
    h : float
        Cell size (must divide [0, 1]).
    mass : str
        The mass matrix.
    preset : str
        Named settings (:mod:`mpm_fem.app.presets`).
    **settings
        ``cfl``, ``viscosity_linear``, ``viscosity_quadratic``, ``compression_only``, ``T``, ``gamma``.

    Returns
    -------
    Reference
        The nodal density, velocity and pressure at ``T``, the exact ones, their errors at the nodes.
    """
    from baselines import fem_euler
    from mpm_fem.problems.sod import SodSettings

    s = _settings("sod", "fem", preset, settings, {"T": SodSettings.T, "gamma": SodSettings.gamma}, "sod.fem")
    check_name("mass", mass, MASSES)
    h = _mesh(h, (0.0, 1.0), "sod.fem")
    with inputs.refused("sod.fem"):  # the baseline's checks of its settings (a failed run: ArithmeticError)
        viscosity = fem_euler.Viscosity(s["viscosity_linear"], s["viscosity_quadratic"], s["compression_only"])
        r = fem_euler.solve(h, T=s["T"], mass=mass, cfl=s["cfl"], gamma=s["gamma"], viscosity=viscosity)
    fields = {"density": r.rho, "velocity": r.u, "pressure": r.p}
    exact = _sod_exact(r.nodes, r.t, s["gamma"])
    weights = uniform_grid(0.0, 1.0, h).lumped_mass
    return Reference(fem_euler.label(mass, viscosity), MappingProxyType({"h": h, "mass": mass, **s}), r.nodes, fields,
                     exact, _errors(fields, exact, weights, "nodes"), r.t, r.steps)


def sod_fv(h: float, preset: str = "defaults", **settings) -> Reference:
    """Sod's tube with MUSCL-Hancock finite volumes and the HLLC flux on the cells of the mesh ``h``.

    Parameters
    ----------
    h : float
        Cell size (must divide [0, 1]).
    preset : str
        Named settings (:mod:`mpm_fem.app.presets`; ``defaults``: minmod, ``study``: MC).
    **settings
        ``cfl``, ``limiter``, ``T``, ``gamma``.

    Returns
    -------
    Reference
        Cell averages at ``T`` beside the exact solution at the cell centres, their errors (weights ``h``).
    """
    from baselines import fv_euler
    from mpm_fem.problems.sod import SodSettings

    s = _settings("sod", "fv", preset, settings, {"T": SodSettings.T, "gamma": SodSettings.gamma}, "sod.fv")
    h = _mesh(h, (0.0, 1.0), "sod.fv")
    with inputs.refused("sod.fv"):  # the baseline's checks of its settings (a failed run: ArithmeticError)
        r = fv_euler.solve(h, T=s["T"], cfl=s["cfl"], gamma=s["gamma"], limiter=s["limiter"])
    fields = {"density": r.rho, "velocity": r.u, "pressure": r.p}
    exact = _sod_exact(r.centres, r.t, s["gamma"])
    return Reference(r.name, MappingProxyType({"h": h, **s}), r.centres, fields, exact,
                     _errors(fields, exact, np.full(r.centres.size, h), "cells"), r.t, r.steps)


def burgers_fem(h: float, mass: str = "lumped", preset: str = "defaults", **settings) -> Reference:
    """Viscous Burgers with P1 Galerkin FEM (``mass`` ``"lumped"`` or ``"consistent"``) on the mesh ``h``.

    Parameters
    ----------
    h : float
        Cell size (must divide the solution's domain).
    mass : str
        The mass matrix.
    preset : str
        Named settings (:mod:`mpm_fem.app.presets`): the time step's ``cfl`` and ``cfl_visc``, and the
        MPM preset's ``solution`` and ``eps``.
    **settings
        ``cfl``, ``cfl_visc``, ``solution``, ``eps``, ``T``.

    Returns
    -------
    Reference
        The nodal velocity at ``T``, the exact one, and its error at the nodes.
    """
    from baselines import fem_burgers
    from mpm_fem.app.presets import settings as mpm_settings

    problem = mpm_settings("burgers", preset)
    s = _settings("burgers", "fem", preset, settings, {k: problem[k] for k in ("solution", "eps", "T")},
                  "burgers.fem")
    check_name("mass", mass, MASSES)
    solution = inputs.settings(settings_type("burgers"), {"solution": s["solution"], "eps": s["eps"]},
                               "burgers.fem").exact
    h = _mesh(h, solution.domain, "burgers.fem")
    with inputs.refused("burgers.fem"):  # the baseline's checks of its settings (a failed run: ArithmeticError)
        r = fem_burgers.solve(solution, h, T=s["T"], mass=mass, cfl=s["cfl"], cfl_visc=s["cfl_visc"])
    fields, exact = {"velocity": r.v}, {"velocity": solution.v(r.nodes, r.t)}
    e = fem_burgers.errors(r, solution)
    return Reference(f"FEM P1 {mass}", MappingProxyType({"h": h, "mass": mass, **s}), r.nodes, fields, exact,
                     {"velocity": {"nodes": e}}, r.t, r.steps)


def _sod_exact(x: np.ndarray, t: float, gamma: float) -> dict:
    from mpm_fem.problems import sod

    return dict(zip(SOD_FIELDS, sod.exact(sod.SodSettings(gamma=gamma), x, t), strict=True))


def exact(problem: str, x, t: float | None = None, **settings) -> dict:
    """The exact solution of ``problem`` at the points ``x`` and time ``t`` (default: the settings' ``T``).

    Parameters
    ----------
    problem : str
        ``"sod"`` (the exact Riemann solution, :func:`baselines.exact.riemann.sample`) or ``"burgers"``
        (the exact solution named by ``solution``, :mod:`baselines.exact.burgers`).
    x : array_like, shape (n,)
        Points of the domain.
    t : float, optional
        Time.
    **settings
        MPM settings (:func:`mpm_fem.app.presets.settings`): Sod's ``gamma``, ``left``, ``right``,
        ``x0``; Burgers' ``solution`` and ``eps``.

    Returns
    -------
    dict of ndarray, shape (n,)
        Sod: ``density``, ``velocity``, ``pressure``; Burgers: ``velocity``.
    """
    kind, call = settings_type(problem), f"{problem}.exact"
    check_keywords(settings, {f for f in kind.__dataclass_fields__}, call)
    s = inputs.settings(kind, settings, call)
    x = inputs.points(x, call)
    t = s.T if t is None else inputs.number("t", t, call)
    if t < 0:
        raise UsageError(f"{call}(): the time t must be >= 0, got {t!r}")
    if problem == "sod":
        from mpm_fem.problems import sod

        return dict(zip(SOD_FIELDS, sod.exact(s, x, t), strict=True))
    return {"velocity": s.exact.v(x, t)}
