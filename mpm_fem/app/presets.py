"""Named settings: the command line's defaults, the study's and the source's, for MPM and the baselines.

    preset      Sod                                              Burgers
    defaults    the command line's: 4 per cell, CFL 0.1          the command line's: 4 per cell, CFL 0.5,
                                                                 eps 0.045, rarefaction, calculated acceleration
    study       studies/sod.py's MPM: 16 per cell, CFL 0.05      studies/burgers.py's calculated-acceleration
                                                                 row: the command line's
    source      what the slides state (4-8 per cell: 4) at the   the study's row compared with the source's
                command line's CFL 0.1 (the slides give none)    "calculated" row: the command line's

The baselines take the same names (:func:`baseline_settings`): ``defaults`` are their functions'
defaults (:func:`baselines.fem_euler.solve`, :func:`baselines.fv_euler.solve`,
:func:`baselines.fem_burgers.solve`), ``study`` and ``source`` the study's (Sod's finite volumes: the MC
limiter where the function's default is minmod). The study's values are read from the study modules,
so a preset is the study's own setting, never a copy of it.
"""

from __future__ import annotations

import importlib
from types import MappingProxyType

from mpm_fem.app.guard import UnknownSetting, UsageError

PRESETS = ("defaults", "study", "source")
PROBLEMS = ("sod", "burgers")
#: Sod's particles per cell in the ``source`` preset: the lower end of the slides' "1D: 4-8 particles
#: per cell is optimal", the cheapest setting the source states (also a setting of the Sod study).
SOURCE_PPC = 4


def check_name(what: str, value: str, allowed: tuple) -> None:
    """:class:`~mpm_fem.app.guard.UsageError` naming ``what`` and the choices unless ``value`` is one of
    ``allowed``."""
    if not isinstance(value, str) or value not in allowed:
        raise UsageError(f"unknown {what} {value!r}; choose one of {', '.join(map(repr, allowed))}")


def _study(problem: str):
    return importlib.import_module(f"studies.{problem}")  # the top layer, loaded by name (app.study)


def changes(problem: str, preset: str) -> dict:
    """The settings ``preset`` changes from the command line's defaults, for MPM on ``problem``."""
    check_name("problem", problem, PROBLEMS)
    check_name("preset", preset, PRESETS)
    if preset == "defaults":
        return {}
    study = _study(problem)
    if problem == "sod":
        from mpm_fem.problems.sod import SodSettings

        mpm = dict(study.MPM)
        return mpm if preset == "study" else {**mpm, "ppc": SOURCE_PPC, "cfl": SodSettings.cfl}
    return {**study.MPM, **study.METHODS["mpm_calculated"].settings, "solution": study.DEFAULT, "eps": study.EPS[0]}


def settings_type(problem: str):
    """The settings dataclass of ``problem``'s MPM runs."""
    check_name("problem", problem, PROBLEMS)
    if problem == "sod":
        from mpm_fem.problems.sod import SodSettings

        return SodSettings
    from mpm_fem.problems.burgers import BurgersSettings

    return BurgersSettings


def settings(problem: str, preset: str = "defaults") -> MappingProxyType:
    """Every MPM setting of ``problem`` under ``preset``, as a read-only mapping (the fields of
    :class:`~mpm_fem.problems.sod.SodSettings` or :class:`~mpm_fem.problems.burgers.BurgersSettings`)."""
    return MappingProxyType(settings_type(problem)(**changes(problem, preset)).as_dict())


#: The baselines of each problem.
BASELINES = {"sod": ("fem", "fv"), "burgers": ("fem",)}


def _defaults(problem: str, solver: str) -> dict:
    """The baseline function's own defaults, under the names its study uses."""
    import inspect

    from baselines import fem_burgers, fem_euler, fv_euler

    fn = {("sod", "fem"): fem_euler.solve, ("sod", "fv"): fv_euler.solve, ("burgers", "fem"): fem_burgers.solve}
    given = inspect.signature(fn[(problem, solver)]).parameters
    if solver == "fv":
        return {k: given[k].default for k in ("cfl", "limiter")}
    if problem == "burgers":
        return {k: given[k].default for k in ("cfl", "cfl_visc")}
    v = given["viscosity"].default
    return dict(cfl=given["cfl"].default, viscosity_linear=v.linear, viscosity_quadratic=v.quadratic,
                compression_only=v.compression_only)


def baseline_settings(problem: str, solver: str, preset: str = "defaults") -> MappingProxyType:
    """The settings of a baseline (``solver`` ``"fem"`` or ``"fv"``) under ``preset``, read-only; the
    mass matrix (FEM) and the mesh are the caller's."""
    check_name("problem", problem, PROBLEMS)
    check_name(f"baseline of {problem}", solver, BASELINES[problem])
    check_name("preset", preset, PRESETS)
    values = _defaults(problem, solver)
    if preset != "defaults":
        values.update(getattr(_study(problem), solver.upper()))
    return MappingProxyType(values)


def check_keywords(given, allowed, call: str) -> None:
    """:class:`~mpm_fem.app.guard.UnknownSetting` (a ``TypeError``) naming the first of ``given`` not
    in ``allowed`` (the keywords of ``call``), with the closest allowed name when one is close."""
    import difflib

    for name in given:
        if name not in allowed:
            close = difflib.get_close_matches(name, list(allowed), n=1)
            hint = f"; did you mean {close[0]}?" if close else f"; the settings are {', '.join(sorted(allowed))}"
            raise UnknownSetting(f"{call}() got an unexpected keyword argument {name!r}{hint}")
