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

Compiling: a case to run also pays numba's compile of the kernel variants its kernel group
(:func:`mpm_fem.app.sweep.kernel_group`) runs through that numba's cache lacks, measured per variant
(:mod:`mpm_fem.app.compile_times`, ``benchmarks/compile_groups.py``) and looked up in the cache without
compiling (:func:`mpm_fem.app.compiling.cached`). Each variant is priced once, on the costliest case of
the first group that needs it (``seen`` carries the variants already priced from one study to the next);
a group the table does not hold is priced at the median group's compile (:func:`compile_seconds`).
"""

from __future__ import annotations

import importlib
import statistics
from dataclasses import dataclass

from mpm_fem.app.sweep import Task, kernel_group


@dataclass(frozen=True)
class Estimate:
    """``cases`` in the plan, ``cached`` of them done, ``seconds`` of CPU for the rest (``compile`` of them
    numba's compiles), ``longest`` case; ``measured``: the CPU seconds the cached cases took when they ran
    (each case's ``cpu_s`` in the cache, a case shared with another study counted by the study that owns it)."""

    cases: int
    cached: int
    seconds: float
    longest: float
    measured: float = 0.0
    compile: float = 0.0

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


def tasks(name: str, options, seen: set | None = None) -> list[tuple[float, Task]] | None:
    """The cases of study ``name`` at ``options.tier``, once each, as ``(estimated CPU seconds, task)``
    with ``options``' cache (a case another study's plan holds costs nothing here: it is counted there),
    the compile of the variants numba's cache lacks added to the costliest case of each group to run
    (module docstring; ``seen``: the variants priced already, updated); ``None`` if the study does not
    state its cost model."""
    found = _priced(name, options.tier)
    return None if found is None else _with_compile(_plain(found, options), set() if seen is None else seen)


def _plain(found: list[_Priced], options) -> list[tuple[float, Task]]:
    """The priced cases as ``(estimated CPU seconds without compiling, task)``, an owned case at 0."""
    return [(0.0 if p.owned else p.seconds, Task(p.module.run_case, p.case, options.cache_dir(p.study)))
            for p in found]


def _with_compile(priced: list[tuple[float, Task]], seen: set) -> list[tuple[float, Task]]:
    """``priced`` with each group's compile (:func:`compile_seconds`) added to its costliest case to run."""
    costliest = {}
    for k, (s, task) in enumerate(priced):
        if s > 0 and not task.path.exists():
            group = kernel_group(task)
            if group not in costliest or s > priced[costliest[group]][0]:
                costliest[group] = k
    out = list(priced)
    for k in costliest.values():
        s, task = out[k]
        out[k] = (s + compile_seconds([task], seen), task)
    return out


def compile_seconds(tasks, seen: set | None = None) -> float:
    """CPU seconds numba spends compiling the variants the kernel groups of ``tasks`` run through that
    its cache lacks and ``seen`` (the variants priced already; updated) does not hold: their measured
    compiles (:data:`mpm_fem.app.compile_times.SECONDS`); a group the table does not hold costs the
    median group's compile once (``seen`` then holds the group)."""
    from mpm_fem.app.compile_times import GROUPS
    from mpm_fem.app.compiling import uncached_seconds

    seen = set() if seen is None else seen
    seconds = 0.0
    for group in {"|".join(kernel_group(t)) for t in tasks}:
        if group in GROUPS:
            new = set(GROUPS[group]) - seen
            seconds += uncached_seconds(new)
            seen |= new
        elif group not in seen:
            seen.add(group)
            seconds += _median_group()
    return seconds


def _median_group() -> float:
    """The median over the table's groups of their variants' compile seconds."""
    from mpm_fem.app.compile_times import GROUPS, SECONDS

    return statistics.median(sum(SECONDS.get(v, 0.0) for v in vs) for vs in GROUPS.values()) if GROUPS else 0.0


def estimate(name: str, options, seen: set | None = None, tasks=None) -> Estimate | None:
    """The :class:`Estimate` of study ``name`` at ``options.tier`` with ``options``' cache; ``None`` if
    the study does not state its cost model. ``seen``: the variants priced already by another study (updated);
    ``tasks(found, options)``: the priced cases' tasks (default :func:`_plain`, each with its study's ``run_case``)."""
    found = _priced(name, options.tier)
    if found is None:
        return None
    plain = (tasks or _plain)(found, options)
    priced = _with_compile(plain, set() if seen is None else seen)
    seconds = [s for s, task in priced if not task.path.exists()]
    compiling = sum(seconds) - sum(s for s, task in plain if not task.path.exists())
    owned = {_key(p.case) for p in found if p.owned}
    measured = sum(_cpu_s(task.path) for _, task in priced if task.path.exists() and _key(task.case) not in owned)
    return Estimate(len(priced), len(priced) - len(seconds), sum(seconds), max(seconds, default=0.0), measured,
                    compiling)


def _cpu_s(path) -> float:
    """The CPU seconds a cached case took when it ran (0 for a cache file without them)."""
    import json

    try:
        return float(json.loads(path.read_text()).get("cpu_s", 0.0))
    except (OSError, ValueError):
        return 0.0


def describe(estimates: dict[str, Estimate | None], workers: int) -> str:
    """One line per study and a total: cases to run, CPU minutes (numba's compiles among them), and the wall
    time on ``workers``."""
    lines, total, longest, measured, compiling = [], 0.0, 0.0, 0.0, 0.0
    for name, e in estimates.items():
        if e is None:
            lines.append(f"  {name}: no cost model")
            continue
        ran = f" (the {e.cached} cached took {e.measured / 60:.1f} CPU-min when they ran)" if e.measured else ""
        build = f", {e.compile / 60:.1f} of them compiling kernels" if e.compile else ""
        lines.append(f"  {name}: {e.cases - e.cached} of {e.cases} cases to run, ~{e.seconds / 60:.1f} "
                     f"CPU-min{build}{ran}")
        total, longest, measured = total + e.seconds, max(longest, e.longest), measured + e.measured
        compiling += e.compile
    wall = max(total / max(workers, 1), longest)
    ran = f"; the cached cases took {measured / 60:.1f} CPU-min when they ran" if measured else ""
    build = f" ({compiling / 60:.1f} of them compiling the kernels numba's cache lacks)" if compiling else ""
    return "\n".join([f"estimated ~{total / 60:.1f} CPU-min{build}, ~{wall / 60:.1f} min on {workers} worker(s) "
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
