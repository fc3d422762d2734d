"""A researcher's method beside the package's bases: the study's measurements and verdicts for it.

``mpm-fem method SPEC`` (SPEC a registered basis, an installed entry point's or
``package.module:Name``, :mod:`mpm_fem.bases.plugins`) measures that basis beside :data:`OURS`:

- the projection (C5-C10's quantities): the orders of the nodal mass, momentum, force and
  acceleration errors against the exact integrals of each basis's own grid functions
  (:func:`mpm_fem.measure.method.projection_orders`) on the regular layout and on jittered ones
  (:data:`PLAN`'s seeds), 4 per cell;
- Sod's density and Burgers' velocity errors at the study's settings (``preset="study"``: Sod 16
  per cell, CFL 0.05; Burgers the rarefaction with the calculated acceleration, 4 per cell) on
  :data:`PLAN`'s meshes, the regular layout and jittered seeds, and the orders between successive
  meshes with their range over the runs.
- the error budget (E1's measurement, ``studies/budget.py``'s :func:`~studies.budget.budget_case`):
  the sixteen subsets of the four stages {projection, mass, interpolation, time} in MPM or exact
  form at the budget study's settings, the regular layout, on one mesh a problem (:data:`PLAN`'s
  ``budget``), and each stage's Shapley share of ``v(all MPM) - v(all exact)`` (particle L1). A
  basis without compiled kernels runs it on the numpy step, its exact stages on its numpy rows.

Tables, in ``<out>/method/<basis>/``: ``projection.csv`` (basis, layout, quantity, mean, lo, hi,
runs), ``runs.csv`` (basis, problem, h, seed, ok, particles_L1, nodes_L1), ``orders.csv`` (basis,
problem, h_coarse, h_fine, mean, lo, hi, runs), ``budget.csv`` (the budget study's ``shapley.csv``
columns, particle norm, and ``ok``/``error``: basis, problem, h, stage, shapley, share, alone,
removed, mpm_error, exact_error); ``METHOD.md`` their verdicts, judged by
:mod:`mpm_fem.measure.claims.method` with the rule book's thresholds, every number formatted from
the tables of the same run, and the budget as a table without a verdict. A basis from outside the
package runs in each worker after being resolved there; its cases' cache keys hold a hash of its
module's source, so a change to it reruns them. The quick plan runs in a few minutes on 2 cores
(the numpy step of a basis without kernels costs about ten times the compiled one); ``--full``
takes finer meshes and more seeds.
"""

from __future__ import annotations

import hashlib
import importlib
import inspect
from pathlib import Path

import numpy as np

from mpm_fem.app.study import StudyOptions, publish
from mpm_fem.measure.claims.method import METHOD_CLAIMS, judge_method
from mpm_fem.measure.claims.rows import num

NAME = "method"
OURS = ("mpm", "gimp", "bspline", "bspline_gimp")
PROBLEMS = {"sod": "density", "burgers": "velocity"}
PLAN = {
    "quick": {"cells": (20, 40, 80), "seeds": (1, 2, 3), "h": {"sod": (0.02, 0.01), "burgers": (0.04, 0.02)},
              "runs": (0, 1, 2), "budget": {"sod": 0.02, "burgers": 0.04}},
    "full": {"cells": (20, 40, 80, 160, 320), "seeds": (1, 2, 3, 4, 5),
             "h": {"sod": (0.01, 0.005, 0.0025, 0.00125), "burgers": (0.04, 0.02, 0.01)}, "runs": (0, 1, 2, 3, 4, 5),
             "budget": {"sod": 0.01, "burgers": 0.04}},
}
LAYOUTS = ("regular", "jittered")
PPC = 4  # the projection's particles per cell
NUMPY_SLOWDOWN = 10.0  # the numpy step's cost over the compiled step's (benchmarks/step_cost.py: 5-10 at 1e3-1e6)


def source_hash(spec: str | None) -> str:
    """A short hash of the module source of a basis from outside the package (empty for ours)."""
    if not spec or ":" not in spec:
        return ""
    module = importlib.import_module(spec.partition(":")[0])
    return hashlib.sha256(inspect.getsource(module).encode()).hexdigest()[:12]


def plan(basis: str, spec: str | None, tier: str) -> list[dict]:
    """The cases: per basis of ``(basis,) + OURS``, the projection on each layout and the runs of each
    problem, mesh and run (0: the regular layout, k: jittered seed k)."""
    p = PLAN[tier]
    outside = {"spec": spec, "source": source_hash(spec)} if spec and ":" in spec else {}
    cases = []
    for b in (basis,) + tuple(o for o in OURS if o != basis):
        extra = outside if b == basis else {}
        cases += [{"kind": "projection", "basis": b, "layout": lay, "cells": list(p["cells"]),
                   "seeds": [0] if lay == "regular" else list(p["seeds"]), **extra} for lay in LAYOUTS]
        cases += [{"kind": "run", "problem": prob, "basis": b, "h": h, "seed": s, **extra}
                  for prob in PROBLEMS for h in p["h"][prob] for s in p["runs"]]
        cases += [{"kind": "budget", "problem": prob, "basis": b, "h": h, **extra} for prob, h in p["budget"].items()]
    return cases


def describe_estimate(basis: str, spec: str, options: StudyOptions) -> str:
    """One line: the cases and their estimated CPU time (the runs' cost models; the numpy step for a
    basis without compiled kernels; numba's compiles of the variants its cache lacks,
    :func:`mpm_fem.app.estimate.compile_seconds`)."""
    from mpm_fem.app.api import checked_settings
    from mpm_fem.app.estimate import compile_seconds
    from mpm_fem.app.sweep import Task
    from mpm_fem.bases import compiled

    cases = plan(basis, spec if ":" in spec else None, "quick" if options.quick else "full")
    seconds = sum(budget_seconds(c) for c in cases if c["kind"] == "budget")
    for c in cases:
        if c["kind"] == "run":
            s = checked_settings(c["problem"], "study", {"h": c["h"], "basis": c["basis"]}, "mpm-fem method",
                                 yes_long=True)
            seconds += importlib.import_module(f"mpm_fem.problems.{c['problem']}").cost(s).seconds
    building = compile_seconds([Task(run_case, c) for c in cases])
    step = "the compiled step" if compiled(basis) else "the numpy step (no compiled kernels: slower)"
    build = f" ({building / 60:.1f} of them compiling the kernels numba's cache lacks)" if building else ""
    return f"{len(cases)} cases, estimated {(seconds + building) / 60:.1f} CPU-min{build}, {basis} on {step}"


def budget_seconds(case: dict) -> float:
    """Estimated CPU seconds of a budget case: the budget study's cost model, P1's for a basis it has
    none for, times :data:`NUMPY_SLOWDOWN` for a basis without compiled kernels."""
    from mpm_fem.bases import compiled

    budget = importlib.import_module("studies.budget")
    known = (case["problem"], case["basis"]) in budget.BUDGET_STEP_MS
    seconds = budget.cost({**case, "basis": case["basis"] if known else "mpm"}) * budget.SECONDS_PER_COST
    return seconds if compiled(case["basis"]) else NUMPY_SLOWDOWN * seconds


def budget_case(case: dict) -> dict:
    """The error budget of one (problem, h, basis) (``studies/budget.py``'s case at its settings): ``ok``
    and the subsets' ``v(S)`` per norm, or why it has none."""
    budget = importlib.import_module("studies.budget")
    got = budget.budget_case({"kind": "budget", "problem": case["problem"], "h": case["h"], "basis": case["basis"],
                              "K": budget.K})
    failed = [r.get("error", "") for r in got["runs"] if not r["ok"]]
    return {"ok": got["ok"], "subsets": got.get("subsets", {}), "error": failed[0] if failed else ""}


def run_case(case: dict) -> dict:
    """One case in a worker: the basis resolved there first (a basis from outside the package)."""
    from mpm_fem.bases import plugins

    if case.get("spec"):
        plugins.resolve(case["spec"])
    if case["kind"] == "budget":
        return budget_case(case)
    if case["kind"] == "projection":
        from mpm_fem.measure.method import projection_orders

        got = projection_orders(case["basis"], case["cells"], PPC, case["layout"], case["seeds"])
        return {"ok": True, "orders": {q: o._asdict() for q, o in got.items()}}
    from mpm_fem.app.api import checked_settings
    from mpm_fem.app.convergence import measured

    layout = {"layout": "jittered", "seed": case["seed"]} if case["seed"] else {}
    s = checked_settings(case["problem"], "study", {"h": case["h"], "basis": case["basis"], **layout},
                         "mpm-fem method", yes_long=True)
    try:
        return measured({"problem": case["problem"], "solver": "mpm", "field": PROBLEMS[case["problem"]],
                         "settings": s.as_dict()})
    except ValueError as err:  # a particle outside the grid: the basis's wall treatment
        return {"ok": False, "error": str(err)}


def tables(cases: list[dict], results: list[dict]) -> dict[str, list[dict]]:
    """``projection``, ``runs`` and ``orders`` rows (module docstring)."""
    from mpm_fem.measure.spread import spread

    projection, runs, budgets = [], [], []
    for c, r in zip(cases, results, strict=True):
        if c["kind"] == "budget":
            budgets.append((c, r))
        elif c["kind"] == "projection":
            projection += [{"basis": c["basis"], "layout": c["layout"], "quantity": q, **o}
                           for q, o in r["orders"].items()]
        else:
            e = r.get("errors", {})
            runs.append({"basis": c["basis"], "problem": c["problem"], "h": c["h"], "seed": c["seed"], "ok": r["ok"],
                         "particles_L1": e.get("particles", {}).get("L1", ""),
                         "nodes_L1": e.get("nodes", {}).get("L1", "")})
    orders = []
    keys = sorted({(r["basis"], r["problem"]) for r in runs})
    for basis, problem in keys:
        rows = [r for r in runs if r["basis"] == basis and r["problem"] == problem]
        hs = sorted({r["h"] for r in rows}, reverse=True)
        for coarse, fine in zip(hs, hs[1:], strict=False):
            got = []
            for seed in sorted({r["seed"] for r in rows}):
                pair = {r["h"]: r for r in rows if r["seed"] == seed and r["h"] in (coarse, fine) and r["ok"]}
                if len(pair) == 2:
                    e_c, e_f = num(pair[coarse], "particles_L1"), num(pair[fine], "particles_L1")
                    got.append(float(np.log(e_c / e_f) / np.log(coarse / fine)))
            s = spread(got) if got else None
            orders.append({"basis": basis, "problem": problem, "h_coarse": coarse, "h_fine": fine,
                           "mean": s.mean if s else "", "lo": s.lo if s else "", "hi": s.hi if s else "",
                           "runs": len(got),
                           "failed": sum(1 for r in rows if not r["ok"] and r["h"] in (coarse, fine))})
    return {"projection": projection, "runs": runs, "orders": orders, "budget": budget_rows(budgets)}


def budget_rows(budgets: list[tuple[dict, dict]]) -> list[dict]:
    """``budget.csv``: the budget study's Shapley rows (particle norm) of each budget that ran
    (:func:`studies.budget.decomposition_rows`), ``ok`` True; one row ``ok`` False with its
    ``error`` for each that did not."""
    budget = importlib.import_module("studies.budget")
    ran = {(c["problem"], c["h"], c["basis"]): r for c, r in budgets if r["ok"]}
    shapley = budget.decomposition_rows([row for row in budget.subset_rows(ran) if row["norm"] == "particles"])[0]
    rows = [{"basis": r["basis"], "problem": r["problem"], "h": r["h"], "ok": True, "error": "",
             **{k: r[k] for k in BUDGET_COLUMNS}} for r in shapley]
    rows += [{"basis": c["basis"], "problem": c["problem"], "h": c["h"], "ok": False, "error": r.get("error", ""),
              **dict.fromkeys(BUDGET_COLUMNS, "")} for c, r in budgets if not r["ok"]]
    return rows


#: the columns ``budget.csv`` keeps of the budget study's ``shapley.csv``
BUDGET_COLUMNS = ("stage", "shapley", "share", "alone", "removed", "mpm_error", "exact_error")


def run(spec: str, options: StudyOptions) -> Path:
    """Run the plan for ``spec`` with ``options`` (tier, jobs, out); returns ``METHOD.md``'s path."""
    from mpm_fem.app.sweep import run_cases
    from mpm_fem.bases import plugins

    basis = plugins.resolve(spec)
    tier = "quick" if options.quick else "full"
    cases = plan(basis, spec if ":" in spec else None, tier)
    folder = Path(options.out) / NAME / basis
    folder.mkdir(parents=True, exist_ok=True)
    results = run_cases(run_case, cases, jobs=options.jobs, cache_dir=Path(options.out) / NAME / ".cache",
                        desc=f"method {basis}", progress=options.progress)
    got = tables(cases, results)
    publish(folder, got, {"basis": basis, "spec": spec, "tier": tier, "plan": PLAN[tier], "ppc": PPC,
                          "preset": "study"})
    page = folder / "METHOD.md"
    page.write_text(judge_method(basis, got, OURS))
    return page


__all__ = ["METHOD_CLAIMS", "NAME", "OURS", "PLAN", "plan", "run", "run_case", "tables"]
