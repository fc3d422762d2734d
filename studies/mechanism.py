"""Where the growth of MPM's particle error comes from, stage by stage (E6a).

Point-mass MPM's particle error grows under refinement at a fixed number of particles per cell. The
error budget's stages (:mod:`studies.budget`: projection, mass (FE + mass lumping), interpolation,
time) are made exact one at a time, and the *growth* is decomposed, not the error on one mesh: for
each run (problem, particles per cell, layout, seed) and subset ``S`` of the stages in MPM form, the
particle L1 error ``v(S)`` on every mesh (the budget's: the trapezoid rule over the piecewise-linear
particle field minus the exact solution; Sod density, Burgers velocity) and the order between
successive meshes, ``p = log(v_c / v_f) / log(h_c / h_f)``. The subsets, by what is exact
(``made_exact``): none (all MPM), each stage alone, and (deep tier) all. *Time exact* is the budget's
Richardson extrapolation from the runs at ``dt`` and ``dt / K``, point by point.

A case is one run and one of ``CASES``: ``time`` runs all MPM at ``dt`` and ``dt / K`` (v(all MPM)
and v(time exact)), ``projection``, ``mass`` and ``interpolation`` one run at ``dt`` with that stage
exact (the budget's ``EXACT_FORM``), ``all`` every stage but time exact at ``dt`` and ``dt / K`` (v(all
exact)); each run is the budget's (:func:`studies.budget._run`, same settings and points), so v(S) is
the budget's own value of the same subset.

Settings: the budget's (:data:`studies.budget.SOD`, :data:`studies.budget.BURGERS`) at 4 and 8 particles
per cell, on the regular layout and the jittered layouts of seeds 1-5. Tables: ``growth.csv`` (one row
per run, subset and mesh pair: v(S) on both meshes and the order), ``summary.csv`` (per problem,
particles per cell, subset and mesh pair: the orders over the runs and whether the subset turns all
MPM's growth into convergence on every run where it grows, :func:`mpm_fem.measure.claims.mechanism.summary_rows`),
``runs.csv`` (each run's steps and wall time) and ``growth.png``.

Tiers: the quick tier runs Sod on h = 0.01 and 0.005 and Burgers on its two coarsest meshes at 4 per cell,
on the regular layout and seeds 1 and 2, every subset of :data:`CASES` (:data:`QUICK`), on the numpy step
(:func:`run_numpy_case`: no fused exact-stage variant to compile, only the exact grid stage's kernels,
:mod:`mpm_fem.exact_stages.grid_kernels`). The full tier runs Sod on h = 0.01 ...
0.00125 and Burgers on h = 0.08 ... 0.01, four meshes each, every layout, without the all-exact subset
(:data:`FULL`). Burgers at h = 0.005 (its viscous step, dt ~ h^2, makes one run there cost as much as
the full tier's Burgers runs together), Sod at h = 0.000625, 16 per cell (whose growth starts near
h = 0.0025) and the all-exact subset are in the deep tier only (:data:`DEEP`).
"""

from __future__ import annotations

import sys

import numpy as np

from mpm_fem.app.plots import grid_shape, plt, save, slope_guides
from mpm_fem.app.study import StudyOptions, publish, script_main
from mpm_fem.measure.claims.mechanism import summary_rows
from mpm_fem.measure.decomposition import label
from mpm_fem.measure.schema import MECHANISM_GROWTH, MECHANISM_SUMMARY
from studies.budget import (
    BURGERS,
    EXACT_FORM,
    SEEDS,
    SOD,
    STAGES,
    K,
    _layout_changes,
    _run,
    _settings,
    _steps,
    norm_points,
    setting_of,
)

NAME = "mechanism"
BASIS = "mpm"
#: The kinds of case (module docstring): ``time`` yields all MPM and time exact, ``all`` every stage exact,
#: a stage that stage alone exact.
CASES = ("time", "projection", "mass", "interpolation", "all")
LAYOUTS = (("regular", 0),) + tuple(("jittered", s) for s in SEEDS)
#: The quick tier, where the error comes from at a glance: Sod on h = 0.01 and 0.005 and Burgers on its two
#: coarsest meshes, 4 per cell, the regular layout and seeds 1 and 2, each stage alone exact and every stage
#: exact, on the numpy step (``kernel``: :func:`run_numpy_case`, which compiles no fused exact-stage variant; the
#: exact grid stage's kernels it compiles, :mod:`mpm_fem.exact_stages.grid_kernels`).
QUICK = {"ppc": (4,), "h": {"sod": (0.01, 0.005), "burgers": (0.08, 0.04)}, "layouts": LAYOUTS[:3],
         "cases": CASES, "kernel": "numpy"}
#: The full tier: four meshes a problem, every layout, the subsets of all MPM and each stage alone exact.
FULL = {"ppc": (4, 8), "h": {"sod": (0.01, 0.005, 0.0025, 0.00125), "burgers": (0.08, 0.04, 0.02, 0.01)},
        "layouts": LAYOUTS, "cases": CASES[:4]}
#: The deep tier: one mesh finer a problem, 16 per cell, and the all-exact subset.
DEEP = {"ppc": (4, 8, 16), "h": {"sod": FULL["h"]["sod"] + (0.000625,), "burgers": FULL["h"]["burgers"] + (0.005,)},
        "layouts": LAYOUTS, "cases": CASES}
TIERS = {"quick": QUICK, "full": FULL, "deep": DEEP}


def _case(problem: str, h: float, ppc: int, layout: str, seed: int, made_exact: str) -> dict:
    return {"kind": "mechanism", "problem": problem, "h": h, "basis": BASIS, "K": K, "made_exact": made_exact,
            **_layout_changes(problem, ppc, layout, seed)}


def plan(tier: str) -> dict:
    """``{"growth": {(problem, ppc, layout, seed, h, made_exact): case}}`` of the tier (:data:`TIERS`); a tier
    naming a ``kernel`` adds it to every case (:func:`task_function`)."""
    t = TIERS[tier]
    kernel = {"kernel": t["kernel"]} if "kernel" in t else {}
    return {"growth": {(p, n, lay, s, h, c): {**_case(p, h, n, lay, s, c), **kernel}
                       for p, meshes in t["h"].items() for n in t["ppc"] for lay, s in t["layouts"]
                       for h in meshes for c in t["cases"]}}


#: CPU milliseconds per step of one run, ``a + b n`` with ``n`` = particles per cell / h, per (problem, what
#: the run is): ``mpm`` the all-MPM runs (the compiled step of each problem), ``exact`` a run with exact stages
#: (their numpy grid stage). A least-squares fit, weighted by steps, to the full tier's 384 cases (2026-11-28,
#: 8.6 CPU-min on the 2-core machine shared with other jobs); the budget's own model (``BUDGET_STEP_MS``)
#: predates Burgers' compiled loop and overestimates its all-MPM runs sevenfold.
#: ``numpy``: every run of a case on the numpy step (the quick tier), fitted by eye to its 40 cases of the regular
#: layout and seed 1 (2026-12-02, 20 CPU-s, the 2-core machine at a load of 5).
STEP_MS = {("sod", "mpm"): (0.0031, 3.9e-5), ("sod", "exact"): (0.39, 9.1e-5),
           ("burgers", "mpm"): (0.22, 3.4e-5), ("burgers", "exact"): (0.83, 1.7e-3),
           ("sod", "numpy"): (0.15, 5e-5), ("burgers", "numpy"): (0.4, 0.0)}


def cost(case: dict) -> float:
    """Estimated CPU milliseconds of a case (:data:`STEP_MS`): one step's worth per step at dt, ``1 + K`` for
    the cases run at dt and dt / K."""
    problem, h = case["problem"], case["h"]
    n = setting_of(problem, case)["ppc"] / h
    a, b = STEP_MS[(problem, "numpy" if case.get("kernel") == "numpy" else
                    "mpm" if case["made_exact"] == "time" else "exact")]
    runs = 1 + K if case["made_exact"] in ("time", "all") else 1
    return runs * _steps(problem, h) * (a + b * n)


# ---------------------------------------------------------------- one case

def run_case(case: dict) -> dict:
    """v(S) of the case's subsets (:data:`CASES`), by what is exact: the runs in MPM form but the exact
    stages, at dt and, where time is made exact too, at dt / K, extrapolated point by point (the budget's
    time exact)."""
    problem, h = case["problem"], case["h"]
    changes = {k: case[k] for k in ("ppc", "layout", "seed") if k in case}
    exact = () if case["made_exact"] == "time" else STAGES[:3] if case["made_exact"] == "all" else (case["made_exact"],)
    forms = {k: v for s in exact for k, v in EXACT_FORM[s].items()}
    points, weights = norm_points(problem, _settings(problem, h, BASIS, changes))
    refines = (1, K) if case["made_exact"] in ("time", "all") else (1,)
    fields, runs = {}, []
    for refine in refines:
        row, got = _run(problem, _settings(problem, h, BASIS, {**changes, **forms, "refine": refine}), points)
        runs.append({"refine": refine, **{k: row[k] for k in ("ok", "error", "steps", "wall_s") if k in row}})
        if not row["ok"]:
            return {"ok": False, "runs": runs, "error": row["error"]}
        fields[refine] = got["particles"]
    l1 = lambda e: float(np.sum(weights * np.abs(e)))  # noqa: E731
    at_dt = l1(fields[1])
    extrapolated = l1((K * fields[K] - fields[1]) / (K - 1)) if K in fields else None
    errors = {"time": {"none": at_dt, "time": extrapolated}, "all": {"all": extrapolated}}.get(
        case["made_exact"], {case["made_exact"]: at_dt})
    return {"ok": True, "errors": errors, "runs": runs}


def run_numpy_case(case: dict) -> dict:
    """:func:`run_case` on the numpy step (:mod:`mpm_fem.core.step`: ``kernel="numpy"`` in every run's settings,
    stepped by :func:`mpm_fem.run.solve.run`): the same runs, subsets and errors, the fused step's arithmetic to
    round-off, but no compiled particle pass, so that a cold cache compiles no fused exact-stage variant (the quick
    tier's cases, :data:`QUICK`); the exact grid stage (:class:`~mpm_fem.exact_stages.stage.ExactGridStage`)
    still runs its compiled sums, :mod:`mpm_fem.exact_stages.grid_kernels`."""
    problem, h = case["problem"], case["h"]
    changes = {k: case[k] for k in ("ppc", "layout", "seed") if k in case}
    exact = () if case["made_exact"] == "time" else STAGES[:3] if case["made_exact"] == "all" else (case["made_exact"],)
    forms = {k: v for s in exact for k, v in EXACT_FORM[s].items()}
    points, weights = norm_points(problem, _settings(problem, h, BASIS, changes))
    refines = (1, K) if case["made_exact"] in ("time", "all") else (1,)
    fields, runs = {}, []
    for refine in refines:
        settings = _settings(problem, h, BASIS, {**changes, **forms, "refine": refine, "kernel": "numpy"})
        row, got = _run(problem, settings, points)
        runs.append({"refine": refine, **{k: row[k] for k in ("ok", "error", "steps", "wall_s") if k in row}})
        if not row["ok"]:
            return {"ok": False, "runs": runs, "error": row["error"]}
        fields[refine] = got["particles"]
    l1 = lambda e: float(np.sum(weights * np.abs(e)))  # noqa: E731
    at_dt = l1(fields[1])
    extrapolated = l1((K * fields[K] - fields[1]) / (K - 1)) if K in fields else None
    errors = {"time": {"none": at_dt, "time": extrapolated}, "all": {"all": extrapolated}}.get(
        case["made_exact"], {case["made_exact"]: at_dt})
    return {"ok": True, "errors": errors, "runs": runs}


def task_function(case: dict):
    """The case function of ``case`` (:mod:`mpm_fem.app.estimate` builds ``reproduce``'s tasks with it):
    :func:`run_numpy_case` for a case on the numpy step, else :func:`run_case`."""
    return run_numpy_case if case.get("kernel") == "numpy" else run_case


def mpm_stages(made_exact: str) -> str:
    """The budget's label of the stages in MPM form of a subset named by what is exact."""
    exact = set(STAGES) if made_exact == "all" else set() if made_exact == "none" else {made_exact}
    return label(set(STAGES) - exact)


# ---------------------------------------------------------------- tables

def growth_rows(got: dict) -> list[dict]:
    """``growth.csv`` from ``{(problem, ppc, layout, seed, h, case): result}``: per run and subset, v(S) on
    each pair of successive meshes both ran and the order between them (failed runs leave their pairs out)."""
    series: dict[tuple, dict[float, float]] = {}
    for (p, n, lay, s, h, _), r in got.items():
        for made_exact, v in (r.get("errors") or {}).items():
            series.setdefault((p, n, lay, s, made_exact), {})[h] = v
    rows = []
    for (p, n, lay, s, made_exact), errors in series.items():
        hs = sorted(errors, reverse=True)
        for hc, hf in zip(hs[:-1], hs[1:], strict=True):
            ec, ef = errors[hc], errors[hf]
            rows.append({"problem": p, "basis": BASIS, "ppc": n, "layout": lay, "seed": s, "made_exact": made_exact,
                         "mpm_stages": mpm_stages(made_exact), "h_coarse": hc, "h_fine": hf, "error_coarse": ec,
                         "error_fine": ef, "order": float(np.log(ec / ef) / np.log(hc / hf))})
    return rows


def run(options: StudyOptions) -> None:
    fn = run_numpy_case if TIERS[options.tier].get("kernel") == "numpy" else run_case
    got = options.sweep_plan(NAME, fn, plan(options.tier), cost=cost)["growth"]
    rows = growth_rows(got)
    runs = [{"problem": p, "ppc": n, "layout": lay, "seed": s, "h": h, "case": c, **x}
            for (p, n, lay, s, h, c), r in got.items() for x in r["runs"]]
    t = TIERS[options.tier]
    settings = {"sod": SOD, "burgers": BURGERS, "basis": BASIS, "K": K, "stages": STAGES, "exact_form": EXACT_FORM,
                "ppc": list(t["ppc"]), "h": {p: list(hs) for p, hs in t["h"].items()},
                "layouts": [f"{lay} {s}" for lay, s in t["layouts"]], "cases": list(t["cases"])}
    folder = options.folder(NAME)
    publish(folder, {MECHANISM_GROWTH: rows, MECHANISM_SUMMARY: summary_rows(rows), "runs": runs}, settings)
    figure(folder, got)


# ---------------------------------------------------------------- figure

COLORS = {"none": "k", "projection": "tab:blue", "mass": "tab:orange", "interpolation": "tab:green",
          "time": "tab:red", "all": "tab:gray"}


def _panel_order(panel: tuple[str, int]) -> tuple[bool, int]:
    """Sod's panels first, then by particles per cell."""
    problem, ppc = panel
    return problem != "sod", ppc


def figure(folder, got: dict) -> None:
    """``growth.png``: per problem and particles per cell, v(S) against h (log-log) for each subset: the
    jittered layouts' mean as a solid line and their range as a band, the regular layout dotted; slope 1."""
    from matplotlib.ticker import NullFormatter

    values: dict[tuple, dict] = {}
    for (p, n, lay, _, h, _), r in got.items():
        for made_exact, v in (r.get("errors") or {}).items():
            values.setdefault((p, n), {}).setdefault(made_exact, {}).setdefault(lay, {}).setdefault(h, []).append(v)
    panels = sorted(values, key=_panel_order)
    nrows, ncols = grid_shape(len(panels), (4.2, 3.6))
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.2 * ncols, 3.6 * nrows), squeeze=False)
    for ax in axes.ravel()[len(panels):]:
        ax.set_visible(False)
    for ax, (p, n) in zip(axes.ravel(), panels, strict=False):
        for made_exact, by_layout in values[(p, n)].items():
            name, color = "all MPM" if made_exact == "none" else f"{made_exact} exact", COLORS[made_exact]
            if "jittered" in by_layout:
                by_h = by_layout["jittered"]
                hs = sorted(by_h)
                lo, mean, hi = ([f(by_h[h]) for h in hs] for f in (min, np.mean, max))
                ax.loglog(hs, mean, "o-", ms=3, lw=1.1, color=color, label=name)
                ax.fill_between(hs, lo, hi, color=color, alpha=0.1, lw=0)
            if "regular" in by_layout:
                hs = sorted(by_layout["regular"])
                ax.loglog(hs, [by_layout["regular"][h][0] for h in hs], ":", lw=1.1, color=color,
                          label=None if "jittered" in by_layout else name)
        every = [v for by_layout in values[(p, n)].values() for by_h in by_layout.values() for vs in by_h.values()
                 for v in vs]
        hs = sorted({h for by_layout in values[(p, n)].values() for by_h in by_layout.values() for h in by_h})
        slope_guides(ax, hs, min(every), (1,))
        ax.set_xticks(hs, [f"{h:g}" for h in hs])
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set(xlabel="h", ylabel=f"particle {'density' if p == 'sod' else 'velocity'} error (L1)",
               title=f"{p}, {n} per cell")
    axes[0][0].legend(fontsize=7)
    save(fig, folder / "growth.png", caption="E6a: the particle L1 error against h with all stages MPM and with each "
                                             "stage alone exact: the jittered layouts' mean (solid) and range "
                                             "(band), the regular layout (dotted)")


#: The cost model of :mod:`mpm_fem.app.estimate`: :func:`cost` is in CPU milliseconds (:data:`STEP_MS`).
PLAN, COST, SECONDS_PER_COST = plan, cost, 1e-3

if __name__ == "__main__":
    sys.exit(script_main(NAME))
