"""E6a: where the growth of point-mass MPM's particle error under refinement comes from, stage by stage,
judged from ``mechanism/summary``, which :func:`summary_rows` builds from
``mechanism/growth`` (both written by ``studies/mechanism.py``).

A *run* is one particle setting (particles per cell, layout, seed: the regular layout is seed 0) and a
*subset* the stages in MPM form, the others exact, as in the error budget (E1); ``made_exact`` names
what is exact (``none``: all MPM; a stage: that stage alone; ``all``: every stage). Between two
successive meshes ``h_c > h_f`` of one run the order of the particle L1 error ``v(S)`` is

    p = log(v_c / v_f) / log(h_c / h_f).

All MPM *grows* on a run where its ``p < GROWTH_ORDER``. On one (particles per cell, mesh pair), a
subset *turns the growth into convergence* when all MPM grows on some run and, on every run where it
grows, the subset's own ``p >= CONVERGING_ORDER`` (it *stops* the growth where its ``p >=
GROWTH_ORDER`` on each of them). ``mechanism/summary`` holds, per problem, particles per cell, subset
and mesh pair, the orders' range over the runs and these counts.

E6a reads it per problem. The *growth cases* are the (particles per cell, mesh pair) where all MPM
grows on at least one run, among the settings measured on MIN_RUNS runs and MECHANISM_MESHES meshes.
A stage is *named* on a growth case when making it alone exact turns the growth into convergence
there, on every growing run, whatever its share of the error on one mesh (E1): a stage that converges
on all but one of the growing runs is not named. Verdict: a stage named on every growth case ->
confirmed; a stage named on some growth cases -> partly; none on any -> refuted; no growth case (all
MPM converges or levels on every run and mesh pair) -> differs.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import NamedTuple

from mpm_fem.measure.claims.base import CONFIRMED, DIFFERS, NOT_MEASURED, PARTLY, REFUTED, Finding, Tables, claim, short
from mpm_fem.measure.claims.rows import CONVERGING_ORDER, GROWTH_ORDER, num, select, span
from mpm_fem.measure.claims.rules import rule
from mpm_fem.measure.schema import MECHANISM_SUMMARY
from mpm_fem.measure.spread import spread

#: The stages that can be made exact alone, in the step's order (the error budget's stages).
STAGES = ("projection", "mass", "interpolation", "time")
#: The subsets, by what is exact: all MPM, each stage alone exact, every stage exact.
MADE_EXACT = ("none", *STAGES, "all")
#: The runs a setting must have on every mesh pair (the regular layout and the jittered seeds).
MIN_RUNS = int(rule("MIN_RUNS"))
#: The meshes a run must have: growth over several refinements, not one.
MECHANISM_MESHES = int(rule("MECHANISM_MESHES"))
_RUN = ("ppc", "layout", "seed")

SUMMARY = MECHANISM_SUMMARY.name


class GrowthCase(NamedTuple):
    """A particles-per-cell value and a pair of successive meshes, on which a growth is judged."""

    ppc: int
    h_coarse: float
    h_fine: float


def _run_key(row: dict) -> tuple:
    return tuple(str(row[c]) for c in _RUN)


def summary_rows(growth: Iterable[dict]) -> list[dict]:
    """``mechanism/summary`` from ``mechanism/growth`` rows (numbers or strings): per problem, basis,
    particles per cell, subset and mesh pair, the orders over the runs and the counts of the module
    docstring, against all MPM's orders on the same runs."""
    groups: dict[tuple, dict[tuple, float]] = {}
    stages = {}
    for r in growth:
        key = (r["problem"], r["basis"], str(r["ppc"]), r["made_exact"], num(r, "h_coarse"), num(r, "h_fine"))
        groups.setdefault(key, {})[_run_key(r)] = num(r, "order")
        stages[key] = r["mpm_stages"]
    out = []
    for key, orders in groups.items():
        problem, basis, ppc, made_exact, hc, hf = key
        mpm = groups.get((problem, basis, ppc, "none", hc, hf), {})
        growing = [run for run, p in mpm.items() if p < GROWTH_ORDER]
        mine = [orders.get(run, math.nan) for run in growing]
        s = spread(orders.values())
        regular = [p for run, p in orders.items() if run[1] == "regular"]
        converging = sum(p >= CONVERGING_ORDER for p in mine)
        out.append({"problem": problem, "basis": basis, "ppc": int(ppc), "made_exact": made_exact,
                    "mpm_stages": stages[key], "h_coarse": hc, "h_fine": hf, "runs": s.n, "order_min": s.lo,
                    "order_mean": s.mean, "order_max": s.hi, "order_regular": regular[0] if regular else math.nan,
                    "mpm_growing": len(growing), "stops_growth": sum(p >= GROWTH_ORDER for p in mine),
                    "converging_where_mpm_grows": converging,
                    "turns_growth": bool(growing) and converging == len(growing)})
    return out


def _pairs(rows: list[dict]) -> list[tuple[float, float]]:
    return sorted({(num(r, "h_coarse"), num(r, "h_fine")) for r in rows}, reverse=True)


def growth_cases(rows: list[dict]) -> dict:
    """From one problem's summary rows: ``{"judged": [GrowthCase, ...], "growth": {case: mpm row},
    "named": {case: [stages]}, "stops": {case: [stages]}}``; a particles-per-cell value is judged when
    all MPM has MIN_RUNS runs on every one of at least MECHANISM_MESHES - 1 mesh pairs."""
    judged, growth, named, stops = [], {}, {}, {}
    for ppc in sorted({int(num(r, "ppc")) for r in rows}):
        mpm = select(rows, ppc=ppc, made_exact="none")
        if len(_pairs(mpm)) < MECHANISM_MESHES - 1 or any(num(r, "runs") < MIN_RUNS for r in mpm):
            continue
        for r in sorted(mpm, key=lambda r: -num(r, "h_coarse")):
            case = GrowthCase(ppc, num(r, "h_coarse"), num(r, "h_fine"))
            judged.append(case)
            if num(r, "mpm_growing") > 0:
                growth[case] = r
                alone = {s: select(rows, ppc=ppc, made_exact=s, h_coarse=case.h_coarse, h_fine=case.h_fine)
                         for s in STAGES}
                g = num(r, "mpm_growing")
                named[case] = [s for s, x in alone.items() if x and num(x[0], "converging_where_mpm_grows") >= g]
                stops[case] = [s for s, x in alone.items() if x and num(x[0], "stops_growth") >= g]
    return {"judged": judged, "growth": growth, "named": named, "stops": stops}


def _case_text(case: GrowthCase) -> str:
    ppc, hc, hf = case
    return f"{ppc} ppc, h = {hc:g} -> {hf:g}"


def _orders(rows: list[dict], case: GrowthCase, made_exact: str) -> str:
    ppc, hc, hf = case
    found = select(rows, ppc=ppc, made_exact=made_exact, h_coarse=hc, h_fine=hf)
    return span([num(found[0], "order_min"), num(found[0], "order_max")]) if found else "-"


def _e6a(problem: str):
    def criterion(t: Tables) -> Finding:
        """The growth of MPM's particle error under refinement at a fixed number of particles per cell is
        decomposed by stage: each stage of the step is made exact alone, and the order of the particle L1
        error between successive meshes is compared with all MPM's on the same particle layouts (the
        regular one and jittered seeds). A stage is named the source of the growth only where making it
        exact turns the growth into convergence on every layout where all MPM grows, not on average and not
        by its share of the error on one mesh."""
        rows = select(t[SUMMARY], problem=problem, basis="mpm")
        found = growth_cases(rows)
        if not found["judged"]:
            return Finding(NOT_MEASURED, f"no particles per cell with {MIN_RUNS} runs on {MECHANISM_MESHES} "
                                           f"meshes in `{SUMMARY}.csv`")
        table = tuple({"case": _case_text(c), "all MPM grows on": f"{int(num(r, 'mpm_growing'))} of "
                       f"{int(num(r, 'runs'))}", "all MPM orders": _orders(rows, c, "none"),
                       **{f"{s} exact": _orders(rows, c, s) for s in STAGES},
                       "named": ", ".join(found["named"][c]) or "none"}
                      for c, r in found["growth"].items())
        growth, named = found["growth"], found["named"]
        every = [s for s in STAGES if growth and all(s in named[c] for c in growth)]
        some = [s for s in STAGES if any(s in named[c] for c in growth)]
        verdict = (DIFFERS if not growth else CONFIRMED if every else PARTLY if some else REFUTED)
        judged = ", ".join(_case_text(c) for c in found["judged"])
        if not growth:
            return Finding(verdict, f"all MPM's particle L1 error grows on no run ({judged}): orders "
                                    + "; ".join(f"{_case_text(c)} {_orders(rows, c, 'none')}" for c in found["judged"]),
                           f"on {problem.capitalize()} the particle error of point-mass MPM does not grow on these "
                           "meshes, so there is no growth to trace to a stage", table)
        per_case = "; ".join(f"{_case_text(c)}: all MPM grows on {int(num(r, 'mpm_growing'))} of "
                             f"{int(num(r, 'runs'))} runs ({_orders(rows, c, 'none')}), "
                             + ", ".join(f"{s} exact {_orders(rows, c, s)}" for s in STAGES)
                             + f", named: {', '.join(named[c]) or 'none'}"
                             + (f", stops it: {', '.join(found['stops'][c])}" if found["stops"][c] else "")
                             for c, r in growth.items())
        head = (f"a stage made exact turns the growth into convergence on every growing run in "
                f"{sum(bool(named[c]) for c in growth)} of {len(growth)} growth cases"
                + (f" ({', '.join(every)} on every one)" if every else ""))
        sentence = (f"on {problem.capitalize()} point-mass MPM's particle error grows on {len(growth)} of "
                    f"{len(found['judged'])} refinements; "
                    + (f"making the {' or the '.join(every)} stage exact turns every one into convergence on "
                       "every layout" if every else
                       f"making one stage exact turns {sum(bool(named[c]) for c in growth)} of them into "
                       "convergence on every layout" if some else
                       "no single stage made exact turns it into convergence on every layout"))
        grows = (f"on {problem.capitalize()} P1's particle error grows on {len(growth)} of {len(found['judged'])} "
                 "refinements")
        turned = sum(bool(named[c]) for c in growth)
        key = short(sentence, grows + (f"; the {' or the '.join(every)} stage made exact makes every one converge"
                                       if every else f"; one stage made exact makes {turned} of them converge" if some
                                       else "; no single stage made exact makes it converge"),
                    grows + (f"; exact {' or '.join(every)}: every one converges" if every else
                             f"; one exact stage: {turned} converge" if some else "; no exact stage stops it"))
        return Finding(verdict, f"{head}; {per_case}", sentence, table, key=key)
    return criterion


_E6A_RULE = (f"per problem, on the (particles per cell, mesh pair) where all MPM's particle L1 order is below "
             f"{GROWTH_ORDER:g} (it grows) on at least one run, among settings with {MIN_RUNS} runs (the regular "
             f"layout and jittered seeds) on {MECHANISM_MESHES} meshes: a stage is named where making it alone exact "
             f"gives an order at least {CONVERGING_ORDER:g} on every run where all MPM grows; a stage named on every "
             "such case -> confirmed; on some -> partly; on none -> refuted; all MPM grows nowhere -> differs. "
             "Read from mechanism/summary")
for _problem in ("sod", "burgers"):
    claim("E6a", source="E6a's question: is the growth the accumulated error of one stage (the projection study's "
                        "non-converging quadrature)?", tables=(SUMMARY,), study="mechanism", problem=_problem,
          thresholds=_E6A_RULE)(_e6a(_problem))
