"""A study's sweep tasks and estimate with each case's own case function.

:mod:`mpm_fem.app.estimate` builds a study's tasks with its ``run_case``. A study whose tier runs its
cases through another function names it per case:

    task_function(case) -> function          the case function of ``case`` (module attribute of
                                             ``studies/<name>.py``; default: its ``run_case``)

(the mechanism study's quick tier runs :func:`studies.mechanism.run_numpy_case`, the numpy step, which
compiles no fused exact-stage variant). :func:`tasks` and :func:`estimate` are those of
:mod:`mpm_fem.app.estimate` (the same cost models, cached cases and compile pricing by kernel group,
:func:`mpm_fem.app.estimate.compile_seconds`) with that function in each task, so that ``reproduce``
runs, and prices, the tasks the study's ``run`` reads from its cache. They live beside the estimate
rather than in it because the method study's cases read the estimate's compile pricing, so that an
edit of :mod:`mpm_fem.app.estimate` is a new version of those cases (:mod:`mpm_fem.measure.version`).
"""

from __future__ import annotations

from mpm_fem.app.estimate import Estimate, _Priced, _priced, _with_compile
from mpm_fem.app.estimate import estimate as _estimate
from mpm_fem.app.sweep import Task


def case_function(module, case: dict):
    """The case function of ``case`` in the study ``module``: its ``task_function(case)`` where it names one,
    else its ``run_case``."""
    chosen = getattr(module, "task_function", None)
    return chosen(case) if chosen is not None else module.run_case


def _plain(found: list[_Priced], options) -> list[tuple[float, Task]]:
    """The priced cases as ``(estimated CPU seconds without compiling, task)``, an owned case at 0, each
    task with its case's function (:func:`case_function`)."""
    return [(0.0 if p.owned else p.seconds, Task(case_function(p.module, p.case), p.case,
                                                 options.cache_dir(p.study))) for p in found]


def tasks(name: str, options, seen: set | None = None) -> list[tuple[float, Task]] | None:
    """:func:`mpm_fem.app.estimate.tasks` with each case's function: the cases of study ``name`` at
    ``options.tier``, once each, as ``(estimated CPU seconds, task)``, the compile of the variants numba's
    cache lacks added to the costliest case of each group to run (``seen``: the variants priced already,
    updated); ``None`` if the study does not state its cost model."""
    found = _priced(name, options.tier)
    return None if found is None else _with_compile(_plain(found, options), set() if seen is None else seen)


def compiles(name: str, options, priced: list[tuple[float, Task]]) -> list[bool] | None:
    """Per task of ``priced`` (what :func:`tasks` returned for study ``name``, in its order), whether its
    estimate carries the compile of variants numba's cache lacks: the costliest case to run of each kernel
    group that compiles, its price above the case's own; ``None`` as :func:`tasks`."""
    found = _priced(name, options.tier)
    if found is None:
        return None
    return [s > p for (s, _), (p, _) in zip(priced, _plain(found, options), strict=True)]


def estimate(name: str, options, seen: set | None = None) -> Estimate | None:
    """:func:`mpm_fem.app.estimate.estimate` with each case's function: the :class:`Estimate` of study
    ``name`` at ``options.tier`` with ``options``' cache; ``None`` without a cost model."""
    return _estimate(name, options, seen, tasks=_plain)
