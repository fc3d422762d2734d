"""What a study costs before it runs: its cases, those already cached, and the CPU time of the rest.

A study opts in by naming three things (module attributes of ``studies/<name>.py``):

    PLAN(tier) -> {group: {label: case}}     the cases of a tier (the plan it sweeps)
    COST(case) -> float                      its relative cost (particle-steps, or 1 per case)
    SECONDS_PER_COST                         CPU seconds per unit of COST, measured on the project's
                                             2-core machine (each study states its measurement)

``CPU seconds = SECONDS_PER_COST * sum(COST(case))`` over the cases not in the cache.

A study whose cases are other studies' cases (the identification runs the Sod and Burgers studies'
case functions, so that a case both run is one cached case) names instead

    SWEEPS                                   {study: its module}, whose run_case, cache, COST and
                                             SECONDS_PER_COST run and price the cases
    PLANS(tier) -> {study: {group: {label: case}}}

and a case that study's own PLAN holds at the same tier costs nothing here (it is counted there;
:func:`mpm_fem.app.sweep.run_tasks` runs a case listed twice once). On ``J``
workers the wall time is at least the total over ``J`` and at least the largest single case (the
critical path): :meth:`Estimate.wall`. The estimate is a model fitted to one machine; the progress
line of each sweep reports the real progress.

:func:`tasks` gives the same cases as sweep tasks with their estimated seconds, so that
``reproduce`` runs every study's cases in one pool, the longest first (:func:`mpm_fem.app.sweep.run_tasks`).
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass

from mpm_fem.app.sweep import Task


@dataclass(frozen=True)
class Estimate:
    """``cases`` in the plan, ``cached`` of them done, ``seconds`` of CPU for the rest, ``longest`` case;
    ``measured``: the CPU seconds the cached cases took when they ran (each case's ``cpu_s`` in the cache,
    a case shared with another study counted by the study that owns it)."""

    cases: int
    cached: int
    seconds: float
    longest: float
    measured: float = 0.0

    def wall(self, workers: int) -> float:
        """Seconds on ``workers`` workers: the larger of the shared total and the longest case."""
        return max(self.seconds / max(workers, 1), self.longest)


@dataclass(frozen=True)
class _Priced:
    """One case of a study's plan: its estimated CPU ``seconds``, the ``study`` whose case function and cache
    run it, that study's ``module``, and whether another study's own plan holds it (``owned``: priced there)."""

    seconds: float
    case: dict
    study: str
    module: object
    owned: bool


def _key(case: dict) -> str:
    return repr(sorted(case.items()))


def _unique(plan: dict) -> dict[str, dict]:
    """The cases of ``{group: {label: case}}``, once each, by key."""
    return {k: c for k, c in ((_key(c), c) for group in plan.values() for c in group.values())}


def _priced(name: str, tier: str) -> list[_Priced] | None:
    """Every case of study ``name`` at ``tier``, once each (see the module docstring); ``None`` if the study
    states no cost model."""
    module = importlib.import_module(f"studies.{name}")
    if hasattr(module, "SWEEPS"):
        out = []
        for study, plan in module.PLANS(tier).items():
            owner = module.SWEEPS[study]
            owned = set(_unique(owner.PLAN(tier)))
            out += [_Priced(owner.SECONDS_PER_COST * owner.COST(c), c, study, owner, k in owned)
                    for k, c in _unique(plan).items()]
        return out
    plan, cost, rate = (getattr(module, a, None) for a in ("PLAN", "COST", "SECONDS_PER_COST"))
    if plan is None or cost is None or rate is None:
        return None
    return [_Priced(rate * cost(c), c, name, module, False) for c in _unique(plan(tier)).values()]


def tasks(name: str, options) -> list[tuple[float, Task]] | None:
    """The cases of study ``name`` at ``options.tier``, once each, as ``(estimated CPU seconds, task)``
    with ``options``' cache (a case another study's plan holds costs nothing here: it is counted there);
    ``None`` if the study does not state its cost model."""
    found = _priced(name, options.tier)
    if found is None:
        return None
    return [(0.0 if p.owned else p.seconds, Task(p.module.run_case, p.case, options.cache_dir(p.study)))
            for p in found]


def estimate(name: str, options) -> Estimate | None:
    """The :class:`Estimate` of study ``name`` at ``options.tier`` with ``options``' cache; ``None`` if
    the study does not state its cost model."""
    found = tasks(name, options)
    if found is None:
        return None
    seconds = [s for s, task in found if not task.path.exists()]
    owned = {_key(p.case) for p in _priced(name, options.tier) if p.owned}
    measured = sum(_cpu_s(task.path) for _, task in found if task.path.exists() and _key(task.case) not in owned)
    return Estimate(len(found), len(found) - len(seconds), sum(seconds), max(seconds, default=0.0), measured)


def _cpu_s(path) -> float:
    """The CPU seconds a cached case took when it ran (0 for a cache file without them)."""
    import json

    try:
        return float(json.loads(path.read_text()).get("cpu_s", 0.0))
    except (OSError, ValueError):
        return 0.0


def describe(estimates: dict[str, Estimate | None], workers: int) -> str:
    """One line per study and a total: cases to run, CPU minutes, and the wall time on ``workers``."""
    lines, total, longest, measured = [], 0.0, 0.0, 0.0
    for name, e in estimates.items():
        if e is None:
            lines.append(f"  {name}: no cost model")
            continue
        ran = f" (the {e.cached} cached took {e.measured / 60:.1f} CPU-min when they ran)" if e.measured else ""
        lines.append(f"  {name}: {e.cases - e.cached} of {e.cases} cases to run, ~{e.seconds / 60:.1f} CPU-min{ran}")
        total, longest, measured = total + e.seconds, max(longest, e.longest), measured + e.measured
    wall = max(total / max(workers, 1), longest)
    ran = f"; the cached cases took {measured / 60:.1f} CPU-min when they ran" if measured else ""
    return "\n".join([f"estimated ~{total / 60:.1f} CPU-min, ~{wall / 60:.1f} min on {workers} worker(s) "
                      f"(the model of each study: mpm_fem.app.estimate){ran}", *lines])


@dataclass(frozen=True)
class Added:
    """What a tier adds to a lower one in a study: ``cases``, their estimated CPU ``seconds`` and the
    ``meshes`` (distinct ``h``, largest first) they run on."""

    cases: int
    seconds: float
    meshes: tuple[float, ...]


def added(names, lower: str = "full", higher: str = "deep") -> dict[str, Added]:
    """Per study of ``names``, the cases of tier ``higher`` that tier ``lower`` does not run (what the
    full tier leaves to the deep one to fit its time budget); studies that add none are left out."""
    out = {}
    for name in names:
        below = {_key(p.case) for p in _priced(name, lower) or () if not p.owned}
        extra = [(p.seconds, p.case) for p in _priced(name, higher) or () if not p.owned and _key(p.case) not in below]
        if extra:
            meshes = tuple(sorted({c["h"] for _, c in extra if "h" in c}, reverse=True))
            out[name] = Added(len(extra), sum(s for s, _ in extra), meshes)
    return out
