"""Identification: the settings the source leaves unsaid, fitted to its own tables until the fit converges.

Every continuous setting is fitted by a bracketed search to a stated tolerance (:mod:`mpm_fem.measure.search`,
the procedures of :mod:`mpm_fem.measure.identify`), never read off a grid; the grids below only bracket.

- **Sod** (C11's table): a candidate is particles per cell (:data:`SOD_PPC`) and read-out (nodal or
  particle density); its CFL is fitted in ``ln CFL`` (bracket :data:`SOD_GRID`, tolerance
  :data:`SOD_XTOL`) to the L1 column on :data:`SOD_MESHES`, the plateau's meshes inside the fit; the L2
  column is held out. The runs are the Sod study's cases (``studies.sod.run_case``, its cache).
- **Burgers** (C13's table): a candidate is the whole table, one solution (:data:`SOLUTIONS`) with its
  parameters (:data:`PARAMETERS`: the rarefaction's states and time shift, the Cole-Hopf amplitude),
  particles per cell, read-out (particles or nodes) and norm for both rows; the exact row with the exact
  acceleration and ``dt = CFL h/max|v|``, the calculated row with the stable ``dt = CFL min(h/max|v|,
  h^2/(2 eps))`` (its explicit viscous force needs the viscous limit), each CFL fitted (brackets
  :data:`ADVECTIVE_GRID`, :data:`STABLE_GRID`; dt ~ h reaching CFL 0.03 in every tier, the stable rule in the deep tier:
  its dt ~ h^2 makes CFL 0.03 cost minutes a run; tolerance :data:`CFL_XTOL`).
  The misfit counts the spread over eps (``row_misfit``); it is fitted on :data:`FIT_EPS` and checked on
  :data:`HELD_EPS`. Beside it the per-eps diagnostic. The runs: :func:`run_burgers_case` (the Burgers
  run with the solution's parameters, :class:`FamilySettings`), cached here.
- **Refinement test**: the best candidate of each problem searched again with every tolerance halved,
  restarted at its converged point; the change of its best misfit (``identification/refinement``).
- **Identified**: the best candidate of each problem rerun on the regular layout and the jittered
  layouts of :data:`SEEDS` (Burgers at the largest eps; every eps on the regular layout), one mesh finer
  for Burgers than the fit (``identification/identified``): C11 and C13 read it.

Meshes by tier: Sod full h >= 0.000625 (five of the source's six, the plateau's first mesh inside the
fit; h = 0.0003125, about 20 s a run at 16 per cell at every point of the search, is in the deep tier,
with 4, 8 and 32 per cell); Burgers full: the search on h = 0.01 and 0.005 at the five eps (the calculated
row's stable step makes a run cost ~ h^-3), the identified setting rerun one mesh further (h = 0.0025:
its ratio to the source is in ``identified``), deep one mesh more each. Quick: the coarsest meshes, one
solution, loose tolerances.

Cost: the brackets are the plan (:data:`PLANS`, priced by :mod:`mpm_fem.app.estimate`); the search's
steps inside the brackets depend on what it measures and are not in the plan: their CPU time is written
in the tables' settings (``search_cpu_s``).
"""

from __future__ import annotations

import math
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from types import SimpleNamespace

from baselines.exact import burgers as exact_burgers
from mpm_fem.app.study import StudyOptions, publish, script_main
from mpm_fem.app.sweep import run_cases
from mpm_fem.measure import identify, source
from mpm_fem.measure.claims.identification import rank
from mpm_fem.measure.claims.rules import rule
from mpm_fem.measure.schema import (
    IDENTIFICATION_BURGERS,
    IDENTIFICATION_IDENTIFIED,
    IDENTIFICATION_REFINEMENT,
    IDENTIFICATION_SOD,
)
from mpm_fem.measure.search import Coordinate
from mpm_fem.problems import burgers
from studies import burgers as burgers_study
from studies import sod as sod_study

NAME = "identification"
SEEDS = (1, 2, 3, 4, 5)

SOD_PPC = {"quick": (16,), "full": (16,), "deep": (4, 8, 16, 32)}
SOD_GRID = (0.025, 0.05, 0.1, 0.2)
SOD_XTOL = 0.1
SOD_MESHES = {"quick": sod_study.H[:2], "full": sod_study.H[:5], "deep": sod_study.H[:6]}

SOLUTIONS = burgers_study.SOLUTIONS
EPS = burgers_study.EPS
FIT_EPS, HELD_EPS = (0.045, 0.03, 0.01), (0.04, 0.02)
ADVECTIVE_GRID = (0.03, 0.1, 0.3, 1.0)
#: The stable rule's bracket by tier: dt ~ h^2 makes CFL 0.03 cost ~60000 steps a run at h = 0.005 (minutes
#: each), so the full tier brackets it from 0.1 and the deep tier from 0.03.
STABLE_GRID = {"quick": (0.1, 0.3, 1.0), "full": (0.1, 0.3, 1.0), "deep": (0.03, 0.1, 0.3, 1.0)}
CFL_XTOL, PARAM_XTOL, FTOL, PASSES = 0.05, 0.02, 0.005, 2
#: The parameters fitted per solution: default (that of baselines.exact.burgers) and search range.
PARAMETERS = {"rarefaction": {"t0": (0.05, Coordinate(0.01, 1.0, 2 * PARAM_XTOL, log=True)),
                              "u_left": (0.5, Coordinate(0.0, 0.9, PARAM_XTOL)),
                              "u_right": (1.0, Coordinate(1.0, 2.0, PARAM_XTOL))},
              "cole_hopf": {"A": (2.0, Coordinate(1.05, 20.0, 2 * PARAM_XTOL, log=True))}}
BURGERS_PPC = {"quick": (4,), "full": (4,), "deep": (4, 8)}
BURGERS_MESHES = {"quick": source.BURGERS_H[:1], "full": source.BURGERS_H[:2], "deep": source.BURGERS_H[:3]}
IDENTIFIED_MESHES = {"quick": source.BURGERS_H[:2], "full": source.BURGERS_H[:3], "deep": source.BURGERS_H[:4]}
#: The weight of the spread over eps in a Burgers row's misfit (the rule book's).
SPREAD_WEIGHT = rule("IDENTIFICATION_SPREAD_WEIGHT")
#: The quick tier: one solution, its constants only, loose tolerances, two fitted eps and one held out.
QUICK = dict(solutions=("rarefaction",), parameters={}, fit_eps=(0.045,), held_eps=(0.01,), cfl_xtol=0.3,
             ftol=0.05, passes=1, seeds=(1,))


def burgers_search(tier: str) -> identify.BurgersSearch:
    """The Burgers search of ``tier``."""
    q = QUICK if tier == "quick" else {}
    return identify.BurgersSearch(
        solutions=q.get("solutions", SOLUTIONS), parameters=q.get("parameters", PARAMETERS),
        ppc=BURGERS_PPC[tier], fit_eps=q.get("fit_eps", FIT_EPS), held_eps=q.get("held_eps", HELD_EPS),
        advective_grid=ADVECTIVE_GRID, stable_grid=STABLE_GRID[tier], cfl_xtol=q.get("cfl_xtol", CFL_XTOL),
        ftol=q.get("ftol", FTOL), passes=q.get("passes", PASSES))


def sod_search(tier: str) -> identify.SodSearch:
    return identify.SodSearch(SOD_PPC[tier], SOD_MESHES[tier], SOD_GRID, 3 * SOD_XTOL if tier == "quick" else SOD_XTOL)


def _round(x: float) -> float:
    return float(f"{x:.10g}")


def family_case(row: str, solution: str, params: dict, ppc: int, cfl: float, eps: float, h: float,
                **changes) -> dict:
    """The Burgers case of one source row (``exact``: exact acceleration, dt ~ h; ``calculated``: the
    calculated acceleration, the stable dt) with the solution's ``params``."""
    method = "mpm_exact_dt_h" if row == "exact" else "mpm_calculated"
    case = burgers_study.method_case(method, solution, eps, h, ppc=ppc, cfl=_round(cfl), **changes)
    return {**case, "params": {k: _round(v) for k, v in sorted(params.items())}}


@dataclass(frozen=True)
class FamilySettings(burgers.BurgersSettings):
    """:class:`~mpm_fem.problems.burgers.BurgersSettings` with the solution's parameters ``params``
    (``((name, value), ...)``, passed to :func:`baselines.exact.burgers.make_solution`): the initial and
    Dirichlet data, the exact acceleration and the error's reference all come from that one solution.
    ``params=()`` is the Burgers run itself (the same floats)."""

    params: tuple = ()

    @property
    def exact(self):
        return exact_burgers.make_solution(self.solution, self.eps, **dict(self.params))


def run_burgers_case(case: dict) -> dict:
    """One Burgers run of ``case`` (the fields of :class:`FamilySettings`, ``params`` as ``{name: value}``):
    ``{"ok", "particles", "nodes", "steps"}``, the velocity errors at T by norm (``ok`` False and the
    ``error`` when the run or the settings fail: a parameter out of the solution's range)."""
    fields = {k: v for k, v in case.items() if k not in ("solver", "params")}
    try:
        settings = FamilySettings(**fields, params=tuple(sorted(case.get("params", {}).items())))
        r = burgers.simulate(settings, progress=False)
    except (ArithmeticError, ValueError, RuntimeError) as err:
        return {"ok": False, "error": str(err)}
    e = burgers.errors(settings, r)["velocity"]
    return {"ok": True, "particles": e["particles"], "nodes": e["nodes"], "steps": r.steps}


def _burgers_cost(case: dict) -> float:
    return burgers_study._cost(case)


#: The identification's own Burgers runs, priced by the Burgers study's cost model.
FAMILY = SimpleNamespace(run_case=run_burgers_case, COST=_burgers_cost, SECONDS_PER_COST=burgers_study.SECONDS_PER_COST,
                         PLAN=lambda tier: {})
#: The studies whose case functions, caches and cost models run the identification's cases.
SWEEPS = {"sod": sod_study, NAME: FAMILY}


def plans(tier: str) -> dict[str, dict]:
    """``{study: {group: {label: case}}}``: the brackets of ``tier`` (the search's steps inside them
    are not known before it measures: module docstring)."""
    s, b = sod_search(tier), burgers_search(tier)
    sod = {(n, c, h): sod_study._setting_case(h, n, c) for n in s.ppc for c in s.grid for h in s.meshes}
    burgers = {}
    for solution in b.solutions:
        params = {k: d for k, (d, _) in b.parameters.get(solution, {}).items()}
        for n in b.ppc:
            # the calculated row is bracketed at the fitted parameters: known before only without any
            for row, grid in (("exact", b.advective_grid), ("calculated", () if params else b.stable_grid)):
                burgers.update({(row, solution, n, c, e, h): family_case(row, solution, params, n, c, e, h)
                                for c in grid for e in b.fit_eps for h in BURGERS_MESHES[tier]})
    return {"sod": {"bracket": sod}, NAME: {"bracket": burgers}}


PLANS = plans


class _Runs:
    """The search's runs: each case through its study's case function and cache, in this process,
    memoised (a point the search revisits is read once)."""

    def __init__(self, options: StudyOptions, study: str, fn):
        self.options, self.study, self.fn, self.memo = options, study, fn, {}

    def __call__(self, cases: list[dict]) -> list[dict]:
        keys = [repr(sorted((k, repr(v)) for k, v in c.items())) for c in cases]
        todo = [c for k, c in zip(keys, cases, strict=True) if k not in self.memo]
        if todo:
            got = run_cases(self.fn, todo, jobs=1, cache_dir=self.options.cache_dir(self.study), progress=False)
            for c, r in zip(todo, got, strict=True):
                self.memo[repr(sorted((k, repr(v)) for k, v in c.items()))] = r
        return [self.memo[k] for k in keys]


# ----------------------------------------------------------------------------- Sod

def _sod(options: StudyOptions) -> dict:
    """The Sod search, its refinement test and the identified setting's seeds: the rows of the tables."""
    start, tier = time.process_time(), options.tier
    search, runs = sod_search(tier), _Runs(options, "sod", sod_study.run_case)

    def measure(n, c, hs=search.meshes, **changes):
        return dict(zip(hs, runs([sod_study._setting_case(h, n, _round(c), **changes) for h in hs]), strict=True))

    found = identify.fit_sod(measure, source.SOD, search)
    meshes = " ".join(f"{h:g}" for h in search.meshes)
    rows = rank([{"problem": "sod", "candidate": f"{r['ppc']} ppc, {r['readout']} L1, CFL {r['cfl']:.4g}",
                  "ppc": r["ppc"], "cfl": round(r["cfl"], 5), "readout": r["readout"], "norm": "L1",
                  "held_out": "L2 column", "source_row": "L1", "misfit": r["misfit"],
                  "misfit_held_out": r["misfit_held_out"], "misfit_raw": r["misfit"], "meshes": meshes, "rank": 0,
                  "matching": "False"} for r in found])
    best = next(r for r in found if r["ppc"] == rows[0]["ppc"] and r["readout"] == rows[0]["readout"])
    halved = identify.fit_sod(measure, source.SOD, identify.SodSearch((best["ppc"],), search.meshes, search.grid,
                                                                      search.xtol / 2))
    again = next(r for r in halved if r["readout"] == best["readout"])
    refinement = [_refined("sod", rows[0]["candidate"], "stated", search.xtol, "", best["misfit"], best["misfit"],
                           best["evaluations"]),
                  _refined("sod", rows[0]["candidate"], "halved", search.xtol / 2, "", again["misfit"], best["misfit"],
                           again["evaluations"])]
    identified = []
    for layout, seed in (("regular", 0), *(("jittered", k) for k in (QUICK["seeds"] if tier == "quick" else SEEDS))):
        got = measure(best["ppc"], best["cfl"], **({"layout": layout, "seed": seed} if seed else {}))
        for readout in identify.READOUTS:
            for k, norm in enumerate(("L1", "L2")):
                identified += [{"problem": "sod", "source_row": norm, "setting": rows[0]["candidate"],
                                "readout": readout, "norm": norm, "layout": layout, "seed": seed, "eps": "", "h": h,
                                "error": identify._density(r, readout, norm), "source": source.SOD[h][k],
                                "ratio": _ratio(identify._density(r, readout, norm), source.SOD[h][k])}
                               for h, r in got.items()]
    return {"rows": rows, "refinement": refinement, "identified": identified, "cpu_s": time.process_time() - start}


def _ratio(a, b) -> float:
    return a / b if a is not None and math.isfinite(a) else math.nan


def _refined(problem, candidate, tolerance, cfl_xtol, param_xtol, misfit, stated, evaluations) -> dict:
    return {"problem": problem, "candidate": candidate, "tolerance": tolerance, "cfl_xtol": cfl_xtol,
            "param_xtol": param_xtol, "misfit": misfit, "change": abs(misfit - stated), "evaluations": evaluations}


# ----------------------------------------------------------------------------- Burgers

def burgers_source(hs) -> tuple[dict, dict]:
    """``(corrected, raw)``: the source's Burgers rows on the meshes ``hs``, ``{row: {(eps, h): error}}``;
    the raw table has the slide's printed exponents (each corrected entry x 10)."""
    corrected = {row: {(e, h): source.burgers_value(row, e, h) for e in EPS for h in hs} for row in source.BURGERS}
    printed = lambda row, e, h: 10.0 if (row, e, h) in source.BURGERS_CORRECTED else 1.0  # noqa: E731
    raw = {row: {(e, h): v * printed(row, e, h) for (e, h), v in entries.items()} for row, entries in corrected.items()}
    return corrected, raw


def _params_text(params: dict) -> str:
    return " ".join(f"{k}={v:.4g}" for k, v in params.items()) or "defaults"


def _burgers(options: StudyOptions) -> dict:
    """The Burgers search, its diagnostic, refinement test and the identified setting's reruns."""
    start, tier = time.process_time(), options.tier
    search, runs = burgers_search(tier), _Runs(options, NAME, run_burgers_case)
    hs = BURGERS_MESHES[tier]
    corrected, raw = burgers_source(hs)

    def measure(row, solution, params, ppc, cfl, eps, meshes=hs, **changes):
        keys = [(e, h) for e in eps for h in meshes]
        return dict(zip(keys, runs([family_case(row, solution, params, ppc, cfl, e, h, **changes)
                                    for e, h in keys]), strict=True))

    fits, rows, diagnostic = {}, [], []
    meshes = " ".join(f"{h:g}" for h in hs)
    held = "eps " + " ".join(f"{e:g}" for e in search.held_eps)
    for solution in search.solutions:
        names = list(search.parameters.get(solution, {}))
        for n in search.ppc:
            scores = identify.BurgersTable(measure, solution, n, names, corrected, SPREAD_WEIGHT)
            fit = identify.fit_family(scores, search)
            fits[(solution, n)] = (scores, fit)
            x = {**fit.params, **{f"cfl_{r}": c for r, c in fit.cfl.items()}}
            for r in identify.candidate_results(scores, fit, search):
                label = f"{solution} ({_params_text(fit.params)}), {n} ppc, {r['readout']} {r['norm']}"
                raw_rows = identify.BurgersTable(measure, solution, n, names, raw, SPREAD_WEIGHT)
                rows.append({"problem": "burgers", "fit": "table", "candidate": label, "solution": solution,
                             "params": _params_text(fit.params), "dt_rule": identify.DT_RULES[r["source_row"]],
                             "cfl": round(fit.cfl[r["source_row"]], 5), "ppc": n, "readout": r["readout"],
                             "norm": r["norm"], "eps": "", "table_misfit": r["table_misfit"], "held_out": held,
                             "source_row": r["source_row"], "misfit": r["misfit"],
                             "misfit_held_out": r["misfit_held_out"],
                             "misfit_raw": raw_rows.row(r["source_row"], x, search.fit_eps, r["readout"], r["norm"]),
                             "meshes": meshes, "rank": 0, "matching": "False"})
            for e in EPS if tier != "quick" else search.fit_eps:
                for d in identify.per_eps(scores, fit, search, e):
                    diagnostic.append({"problem": "burgers", "fit": "eps",
                                       "candidate": f"{solution} ({_params_text(d['params'])}), {n} ppc, "
                                                    f"{d['readout']} {d['norm']}, eps {e:g}",
                                       "solution": solution, "params": _params_text(d["params"]),
                                       "dt_rule": identify.DT_RULES[d["source_row"]], "cfl": round(d["cfl"], 5),
                                       "ppc": n, "readout": d["readout"], "norm": d["norm"], "eps": e,
                                       "table_misfit": "", "held_out": "", "source_row": d["source_row"],
                                       "misfit": d["misfit"], "misfit_held_out": "", "misfit_raw": "",
                                       "meshes": meshes, "rank": 0, "matching": "False"})
    table = _rank_table(rows)
    best_row = table[0]
    scores, fit = fits[(best_row["solution"], best_row["ppc"])]
    again = identify.fit_family(scores, search.halved(),
                                {**fit.params, **{f"cfl_{r}": c for r, c in fit.cfl.items()}})
    refinement = [_refined("burgers", best_row["candidate"], "stated", search.cfl_xtol, PARAM_XTOL, fit.value,
                           fit.value, fit.evaluations),
                  _refined("burgers", best_row["candidate"], "halved", search.cfl_xtol / 2, PARAM_XTOL / 2,
                           again.value, fit.value, again.evaluations)]
    identified = _burgers_identified(measure, fit, best_row["candidate"], tier)
    return {"rows": table + _rank_eps(diagnostic), "refinement": refinement, "identified": identified,
            "cpu_s": time.process_time() - start}


def _rank_table(rows: list[dict]) -> list[dict]:
    """The whole-table candidates by ``table_misfit`` (both rows of a candidate share a rank), ``matching``
    within ``IDENTIFICATION_BAND`` of the least."""
    band = rule("IDENTIFICATION_BAND")
    order = sorted(dict.fromkeys(r["candidate"] for r in rows),
                   key=lambda c: next(float(r["table_misfit"]) for r in rows if r["candidate"] == c))
    best = min(float(r["table_misfit"]) for r in rows)
    out = []
    for k, c in enumerate(order, 1):
        for r in rows:
            if r["candidate"] == c:
                m = float(r["table_misfit"])
                out.append({**r, "rank": k, "matching": str(math.isfinite(m) and m - best <= band)})
    return out


def _rank_eps(rows: list[dict]) -> list[dict]:
    """The per-eps diagnostic ranked within each eps and source row."""
    out = []
    for key in dict.fromkeys((r["eps"], r["source_row"]) for r in rows):
        out += [{**r, "source_row": r["source_row"]} for r in
                rank([{**r, "source_row": f"{r['source_row']}@{r['eps']}"} for r in rows
                      if (r["eps"], r["source_row"]) == key])]
    for r in out:
        r["source_row"] = r["source_row"].split("@")[0]
    return out


def _burgers_identified(measure, fit, label: str, tier: str) -> list[dict]:
    """The identified Burgers setting rerun: every eps on the regular layout, the largest eps on the
    jittered layouts too, on :data:`IDENTIFIED_MESHES`; both rows, its read-out and norm."""
    hs, seeds = IDENTIFIED_MESHES[tier], QUICK["seeds"] if tier == "quick" else SEEDS
    out = []
    for row in identify.DT_RULES:
        for layout, seed, eps in (("regular", 0, EPS), *(("jittered", k, EPS[:1]) for k in seeds)):
            changes = {"layout": layout, "seed": seed} if seed else {}
            got = measure(row, fit.solution, fit.params, fit.ppc, fit.cfl[row], eps, hs, **changes)
            for (e, h), r in got.items():
                v, s = identify.value(r, fit.readout, fit.norm), source.burgers_value(row, e, h)
                out.append({"problem": "burgers", "source_row": row, "setting": label, "readout": fit.readout,
                            "norm": fit.norm, "layout": layout, "seed": seed, "eps": e, "h": h, "error": v,
                            "source": s, "ratio": _ratio(v, s)})
    return out


# ----------------------------------------------------------------------------- the study

def run(options: StudyOptions) -> None:
    """The brackets through the Sod study's and this study's caches (one sweep), then the two searches
    (in two processes unless one job), then the tables."""
    tier = options.tier
    for study, plan in plans(tier).items():
        options.sweep_plan(study, SWEEPS[study].run_case, plan, cost=SWEEPS[study].COST)
    if options.jobs == 1:
        sod, burgers = _sod(options), _burgers(options)
    else:
        with ProcessPoolExecutor(2) as pool:
            sod_job, burgers_job = pool.submit(_sod, options), pool.submit(_burgers, options)
            sod, burgers = sod_job.result(), burgers_job.result()
    settings = {"tier": tier, "quick": options.quick, "band": rule("IDENTIFICATION_BAND"),
                "misfit": "mean |log(measured / source)| over the fitted entries; Burgers adds "
                          "IDENTIFICATION_SPREAD_WEIGHT x the mean over meshes of the difference of the log spreads "
                          "over eps; misfit_held_out the same on the held-out part",
                "search": "bracketed grid, then bounded Brent (scipy minimize_scalar) to the tolerance; Burgers: "
                          "then a coordinate search over the solution's parameters and both CFLs",
                "search_cpu_s": {"sod": round(sod["cpu_s"], 1), "burgers": round(burgers["cpu_s"], 1)}}
    extra = {IDENTIFICATION_SOD.stem: {"meshes": list(SOD_MESHES[tier]), "ppc": list(SOD_PPC[tier]),
                                       "cfl_bracket": list(SOD_GRID), "cfl_xtol_ln": sod_search(tier).xtol,
                                       "other settings": "as in the Sod study's mpm", "layout": "regular"},
             IDENTIFICATION_BURGERS.stem: {"meshes": list(BURGERS_MESHES[tier]), "fit_eps": list(FIT_EPS),
                                           "held_eps": list(HELD_EPS), "advective_bracket": list(ADVECTIVE_GRID),
                                           "stable_bracket": list(STABLE_GRID[tier]), "cfl_xtol_ln": CFL_XTOL,
                                           "param_xtol": PARAM_XTOL, "ftol": FTOL,
                                           "parameters": {s: {k: [d, c.lo, c.hi] for k, (d, c) in p.items()}
                                                          for s, p in PARAMETERS.items()},
                                           "layout": "regular", "other settings": "as in the Burgers study's mpm",
                                           "raw": "the entries of source.BURGERS_CORRECTED with the exponent the "
                                                  "slide prints (one power of ten up)"},
             IDENTIFICATION_IDENTIFIED.stem: {"seeds": list(SEEDS), "burgers_meshes": list(IDENTIFIED_MESHES[tier])}}
    tables = {IDENTIFICATION_SOD: sod["rows"], IDENTIFICATION_BURGERS: burgers["rows"],
              IDENTIFICATION_REFINEMENT: sod["refinement"] + burgers["refinement"],
              IDENTIFICATION_IDENTIFIED: sod["identified"] + burgers["identified"]}
    publish(options.folder(NAME), tables, settings, extra)


if __name__ == "__main__":
    sys.exit(script_main(NAME))
