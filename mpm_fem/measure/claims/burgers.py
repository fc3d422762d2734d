"""The Burgers study's claims: C13 (first order in h, with the diagnosis of the calculated acceleration)
and C3 and C15 on Burgers, from ``burgers/*``."""

from __future__ import annotations

import math

from mpm_fem.measure.claims.base import CONFIRMED, DIFFERS, NOT_MEASURED, PARTLY, Finding, Tables, claim, short
from mpm_fem.measure.claims.identification import source_matching
from mpm_fem.measure.claims.identified import IDENTIFIED, burgers_orders
from mpm_fem.measure.claims.mass import MASS_RULE, mass_finding
from mpm_fem.measure.claims.rows import FIRST_ORDER, FLOOR_ORDER, GROWTH_ORDER, num, saturation, select, span
from mpm_fem.measure.claims.shared import LUMPING_RULE, PPC_RULE, SATURATION, ppc_claim
from mpm_fem.measure.claims.stages import SUBSETS
from mpm_fem.measure.schema import BURGERS_DIAGNOSIS, BURGERS_LUMPING, BURGERS_ORDERS, BURGERS_PPC
from mpm_fem.measure.seeds import side
from mpm_fem.measure.source import OPTIMAL_PPC

#: The solution and norm the Burgers tables are compared with the source in (why: ``burgers/norms``).
BURGERS_SHOWN = dict(solution="rarefaction", where="particles", norm="max")
#: C13 judges the exact acceleration with dt ~ h beside the calculated one (the methods whose name starts
#: with C13_CALCULATED_PREFIX, their particles per cell read from the table's ``ppc``).
C13_EXACT, C13_CALCULATED_PREFIX = "mpm_exact_dt_h", "mpm_calculated"
#: C13 counts a fitted order as first order when its interval over the runs lies at or above the rule
#: book's one definition of first order (rows.FIRST_ORDER, shared with C1 and C5-C10).

_C13_RULE = (f"the least-squares order of the velocity error over {BURGERS_SHOWN['where']}, fitted per run (the "
             "regular and the jittered layouts of the seeded eps; a solution run once per eps: its range over the "
             f"eps), counts as first order when every run's is at least {FIRST_ORDER:.2g} (the rule book's one "
             "definition), as below first order when every run's is below it (a stall when below "
             f"{FLOOR_ORDER}, a growing error when below {GROWTH_ORDER:g}), otherwise as undecided. Judged at the "
             "source-matching settings of the identification (the solution, particles per cell and norm of the "
             "calculated-acceleration row and of the exact row): both first order -> confirmed, both below -> "
             "differs, otherwise partly; without the identification table at the study's settings "
             f"({BURGERS_SHOWN['solution']}, {BURGERS_SHOWN['norm']} norm, {OPTIMAL_PPC[0]} and {OPTIMAL_PPC[1]} "
             "per cell), said so; every solution shown beside. Where the identification reran its identified "
             "setting (identification/identified: the one solution with its fitted parameters for both rows), the "
             "orders of those runs (the regular layout at every eps, the jittered ones at the largest) are judged "
             "instead, by the same rule")


def _finite(values) -> list[float]:
    return [v for v in values if math.isfinite(v)]


def calculated_methods(rows: list[dict]) -> dict[int, str]:
    """``{particles per cell: method}`` of the calculated-acceleration methods in ``rows``."""
    return dict(sorted({int(num(r, "ppc")): r["method"] for r in rows
                        if r["method"].startswith(C13_CALCULATED_PREFIX) and math.isfinite(num(r, "ppc"))}.items()))


def c13_order(rows: list[dict], method: str) -> dict:
    """The fitted order of ``method`` in the orders rows of one solution and error: over its series of
    several runs, the mean of their means (``mean``), the least ``fitted_lo`` and the largest
    ``fitted_hi`` (``lo``, ``hi``); a method run once per eps: the mean and range of its fitted orders
    over the eps (two at least); their :func:`~mpm_fem.measure.seeds.side` of FIRST_ORDER (``side``), the runs
    (``runs``) and ``single``: the regular layout's order of each series of one run."""
    sub = select(rows, method=method)
    seeded = [r for r in sub if num(r, "runs") > 1]
    single = [num(r, "fitted") for r in sub if not num(r, "runs") > 1]
    means, los, his = (_finite(num(r, k) for r in seeded) for k in ("fitted_mean", "fitted_lo", "fitted_hi"))
    runs = "/".join(r["runs"] for r in seeded)
    if not seeded:  # a range needs two eps at least
        means = los = his = _finite(single) if len(_finite(single)) > 1 else []
        runs = f"{len(means)} eps x 1"
    lo, hi = (min(los) if los else math.nan), (max(his) if his else math.nan)
    return {"mean": sum(means) / len(means) if means else math.nan, "lo": lo, "hi": hi,
            "side": side(lo, hi, FIRST_ORDER), "runs": runs, "single": single}


def _reading(o: dict) -> str:
    """An order's reading: first order, below it (stalls, grows), undecided, or no interval."""
    if o["side"] == "below":
        return ("the error grows" if o["hi"] < GROWTH_ORDER else "stalls" if o["hi"] < FLOOR_ORDER
                else "below first order")
    return {"above": "first order", "across": "undecided"}.get(o["side"], "no interval")


def _interval(o: dict, runs: bool = False) -> str:
    """``mean [lo, hi]`` (with ``runs``: the runs and the reading), or that there is no interval."""
    if o["side"] == "unknown":
        return "no interval over runs"
    text = f"{o['mean']:.2f} [{o['lo']:.2f}, {o['hi']:.2f}]"
    return text + (f" over {o['runs']} runs, {_reading(o)}" if runs else "")


def _pair_verdict(*sides: str) -> str:
    return CONFIRMED if all(s == "above" for s in sides) else DIFFERS if all(s == "below" for s in sides) else (
        PARTLY)


def _judged_settings(t: Tables) -> tuple[list[dict], str]:
    """The settings C13 is judged at: ``[{row, solution, ppc, norm, dt_rule}]`` for the calculated and
    the exact row, from the identification (``source_matching``; its best candidate of each row), or the
    study's settings when the table is absent, and the words saying which."""
    found = []
    for row in ("calculated", "exact"):
        best = source_matching(t, "burgers", row)[:1]
        found += [{"row": row, "solution": r["solution"], "ppc": int(num(r, "ppc")), "norm": r["norm"],
                   "dt_rule": r.get("dt_rule", ""), "cfl": r.get("cfl", "")} for r in best]
    if len(found) == 2:
        return found, "the source-matching settings (identification/burgers)"
    study = [{"row": "calculated", "solution": BURGERS_SHOWN["solution"], "ppc": n, "norm": BURGERS_SHOWN["norm"],
              "dt_rule": "", "cfl": ""} for n in OPTIMAL_PPC]
    study.append({"row": "exact", "solution": BURGERS_SHOWN["solution"], "ppc": OPTIMAL_PPC[0],
                  "norm": BURGERS_SHOWN["norm"], "dt_rule": "", "cfl": ""})
    return study, (f"the study's settings ({BURGERS_SHOWN['solution']}, {BURGERS_SHOWN['norm']} norm; no "
                   "identification table)")


def _setting_order(t: Tables, s: dict) -> tuple[dict, str]:
    """The order of the setting ``s`` and the method it is read from (the calculated method at its
    particles per cell, or the nearest one the orders table holds for its solution, said so)."""
    rows = select(t[BURGERS_ORDERS.name], solution=s["solution"], where=BURGERS_SHOWN["where"], norm=s["norm"])
    if s["row"] == "exact":
        return c13_order(rows, C13_EXACT), "exact a, dt ~ h"
    methods = calculated_methods(rows)
    if not methods:
        return c13_order([], ""), "no calculated run"
    n = min(methods, key=lambda k: abs(math.log(k / s["ppc"])))
    label = f"calculated a, {n} per cell" + ("" if n == s["ppc"] else f" (no run at {s['ppc']})")
    return c13_order(rows, methods[n]), label


def _solutions_table(t: Tables, judged: list[dict]) -> tuple[dict, ...]:
    """One row per solution: its exact and calculated orders (the judged norm), which one is judged."""
    norm = judged[0]["norm"]
    out = []
    for solution in dict.fromkeys(r["solution"] for r in t[BURGERS_ORDERS.name]):
        rows = select(t[BURGERS_ORDERS.name], solution=solution, where=BURGERS_SHOWN["where"], norm=norm)
        row = {"solution": solution, "norm": norm, "exact a, dt ~ h": _interval(c13_order(rows, C13_EXACT))}
        for n, m in calculated_methods(rows).items():
            row[f"calculated a, {n} per cell"] = _interval(c13_order(rows, m))
        row["judged"] = ", ".join(dict.fromkeys(f"{s['row']} row" for s in judged if s["solution"] == solution))
        out.append(row)
    return tuple(out)


@claim("C13", source="first order with exact and with calculated acceleration", tables=(BURGERS_ORDERS.name,),
       study="burgers", thresholds=_C13_RULE)
def _c13(t: Tables) -> Finding:
    """An order is the least-squares slope of the error against h, fitted per run; its interval is the
    range over the runs of the regular and the jittered particle layouts (a solution run on the regular
    layout alone: the range of its orders over the five eps), and only an interval on one side of the
    threshold counts. The slides name no exact solution: the identification picks, from the
    source's own rows, the solution and settings whose errors match them, and the claim is judged there.
    With the exact acceleration and dt ~ h the O(dt) error of the time step sets the order. The last
    clause reads the diagnosis table (when the study wrote one): each change to the calculated-acceleration
    run, one at a time on the regular layout, by whether its particles' error grows, stalls or falls as h
    shrinks; it names no cause beyond what these changes show."""
    identified = [r for r in t.get(IDENTIFIED, []) if r.get("problem") == "burgers"]
    if identified:
        return _c13_identified(identified, t.get(BURGERS_DIAGNOSIS.name))
    judged, whence = _judged_settings(t)
    found = [(s, *_setting_order(t, s)) for s in judged]
    unmeasured = [f"{s['row']} row ({s['solution']}, {label}, {s['norm']})" for s, o, label in found
                  if o["side"] == "unknown"]
    if unmeasured:  # an order without an interval over runs judges nothing
        return Finding(NOT_MEASURED, f"judged at {whence}: no interval over runs for the "
                       + "; ".join(unmeasured))
    exact = [o for s, o, _ in found if s["row"] == "exact"]
    calc = [o for s, o, _ in found if s["row"] == "calculated"]
    verdicts = {_pair_verdict(exact[0]["side"], o["side"]) for o in calc}
    verdict = verdicts.pop() if len(verdicts) == 1 else PARTLY

    def named(s, label):
        return f"{s['solution']}, {label}, {s['norm']}" + (f", dt rule {s['dt_rule']}" if s["dt_rule"] else "")

    lines = [f"judged at {whence}: " + "; ".join(f"{s['row']} row ({named(s, label)}) {_interval(o, True)}"
                                                  for s, o, label in found)]
    lines.append(f"exact a with the viscous dt ({BURGERS_SHOWN['solution']}) "
                 f"{span(c13_order(select(t[BURGERS_ORDERS.name], **BURGERS_SHOWN), 'mpm_exact')['single'])}")
    diagnosis = t.get(BURGERS_DIAGNOSIS.name)
    calc_shown, calc_order = next((s, o) for s, o, _ in found if s["row"] == "calculated")
    exact_shown, exact_order = next((s, o) for s, o, _ in found if s["row"] == "exact")
    sentence = (f"on Burgers the particle velocity error's order in h ({calc_shown['solution']}, "
                f"{calc_shown['norm']} norm) is {calc_order['mean']:.2f} ({calc_order['lo']:.2f} to "
                f"{calc_order['hi']:.2f}) with the calculated acceleration at {calc_shown['ppc']} per cell and "
                f"{exact_order['mean']:.2f} with the exact acceleration ({exact_shown['solution']})")
    key = short(f"Burgers' velocity order in h ({calc_shown['solution']}, {calc_shown['norm']}): "
                f"{calc_order['mean']:.2f} ({calc_order['lo']:.2f} to {calc_order['hi']:.2f}) calculated acceleration, "
                f"{exact_order['mean']:.2f} exact ({exact_shown['solution']})",
                f"Burgers' velocity order in h: {calc_order['mean']:.2f} with the calculated acceleration, "
                f"{exact_order['mean']:.2f} with the exact")
    return Finding(verdict, "; ".join(lines + ([diagnosis_text(diagnosis)] if diagnosis else [])), sentence,
                   _solutions_table(t, judged), key=key)


def _c13_identified(rows: list[dict], diagnosis: list[dict] | None) -> Finding:
    """C13 at the identified Burgers setting: each row's orders over its runs, both rows first order ->
    confirmed, both below -> differs, else partly (the rule of the claim)."""
    orders = {row: burgers_orders(rows, row) for row in ("exact", "calculated")}
    if any(len(v) < 2 for v in orders.values()):
        return Finding(NOT_MEASURED, "identification/identified: fewer than two runs of a row with two meshes")
    found = {row: {"mean": sum(v) / len(v), "lo": min(v), "hi": max(v), "side": side(min(v), max(v), FIRST_ORDER),
                   "runs": str(len(v))} for row, v in orders.items()}
    verdict = _pair_verdict(found["exact"]["side"], found["calculated"]["side"])
    first = rows[0]
    setting = f"{first['setting']} ({first['norm']} norm over {first['readout']})"
    evidence = (f"judged at the identified setting {setting}: " + "; ".join(
        f"{row} row {_interval(o, True)}" for row, o in found.items()))
    e, c = found["exact"], found["calculated"]
    sentence = (f"on Burgers at the identified solution the velocity error's order in h is {c['mean']:.2f} "
                f"({c['lo']:.2f} to {c['hi']:.2f}) with the calculated acceleration and {e['mean']:.2f} "
                f"({e['lo']:.2f} to {e['hi']:.2f}) with the exact one: first order on "
                f"{sum(o['side'] == 'above' for o in found.values())} of {len(found)} rows")
    key = short(f"Burgers' velocity order at the identified solution: {c['mean']:.2f} ({c['lo']:.2f} to "
                f"{c['hi']:.2f}) calculated acceleration, {e['mean']:.2f} exact",
                f"Burgers' velocity order: {c['mean']:.2f} calculated, {e['mean']:.2f} exact")
    table = tuple({"row": row, "orders": _interval(o), "runs": o["runs"], "reading": _reading(o)}
                  for row, o in found.items())
    return Finding(verdict, evidence + (f"; {diagnosis_text(diagnosis)}" if diagnosis else ""), sentence, table,
                   key=key)


def _behaviour(orders: list[float]) -> str:
    if max(orders) < GROWTH_ORDER:
        return "grows"
    return "falls at first order" if min(orders) >= FIRST_ORDER else "stalls" if max(orders) < FLOOR_ORDER else (
        "changes order")


def diagnosis_text(rows: list[dict]) -> str:
    """What the diagnosis table shows: its variants grouped by how the particles' L1 error moves as h
    shrinks (every successive order below 0: grows; below FLOOR_ORDER: stalls; at least FIRST_ORDER:
    falls at first order; else changes order), with their orders, and whether the slides' second-difference
    force (``changes`` ``{'force': 'slides'}``), which sums no particle stresses, moves as the weak force
    (``changes`` ``{}``) does."""
    h = sorted({num(r, "h") for r in rows}, reverse=True)
    groups, of = {}, {}
    for variant in dict.fromkeys(r["variant"] for r in rows):
        sub = sorted(select(rows, variant=variant), key=lambda r: -num(r, "h"))
        orders = _finite(num(r, "order_L1") for r in sub)
        if orders:
            of[sub[0]["changes"]] = behaviour = _behaviour(orders)
            groups.setdefault(behaviour, []).append(f"{variant} ({', '.join(f'{o:.2f}' for o in orders)})")
    text = (f"diagnosis, one change at a time (particles' L1 error, regular layout, h = {h[0]:g} to {h[-1]:g}): "
            + "; ".join(f"the error {b} with {', '.join(v)}" for b, v in groups.items()))
    base, slides = of.get(repr({})), of.get(repr({"force": "slides"}))
    if base and slides and not base.startswith("falls") and not slides.startswith("falls"):
        text += (f"; with the slides' second-difference force, which sums no particle stresses, the error {slides}"
                 + ("" if slides == base else f" (with the weak force: {base})")
                 + ": the particle quadrature of the force is not the only cause")
    return text


@claim("C3", source=f"{OPTIMAL_PPC[0]}-{OPTIMAL_PPC[1]} particles per cell", tables=(BURGERS_PPC.name,),
       study="burgers", problem="burgers", thresholds=PPC_RULE)
def _c3_burgers(t: Tables) -> Finding:
    rows = t[BURGERS_PPC.name]
    keys = {(r["method"], r["h"]) for r in rows}
    groups = {f"{m} h = {h}": select(rows, method=m, h=h) for m, h in sorted(keys)}
    key = f"{BURGERS_SHOWN['where']}_{BURGERS_SHOWN['norm']}"
    verdict, evidence = ppc_claim(groups, (key,))
    table = tuple({"case": g, "fewest near the smallest": saturation(v, key, SATURATION)} for g, v in groups.items())
    inside = sum(OPTIMAL_PPC[0] <= r["fewest near the smallest"] <= OPTIMAL_PPC[1] for r in table)
    sentence = (f"on Burgers the fewest particles per cell within {SATURATION:.0%} of the smallest error lie in the "
                f"source's {OPTIMAL_PPC[0]}-{OPTIMAL_PPC[1]} on {inside} of {len(table)} methods and meshes")
    key = short(sentence, f"on Burgers the fewest particles per cell within {SATURATION:.0%} of the smallest error lie "
                          f"in {OPTIMAL_PPC[0]}-{OPTIMAL_PPC[1]} on {inside} of {len(table)} methods and meshes")
    return Finding(verdict, evidence, sentence, table, key=key)


@claim("C15", source="one of four error sources", tables=(SUBSETS,), study="burgers", problem="burgers",
       thresholds=MASS_RULE + ". Second reading: " + LUMPING_RULE
       + " (Burgers: velocity L2, MPM over particles, FEM over nodes)")
def _c15_burgers(t: Tables) -> Finding:
    """The direct measurement: the error budget's mass stage, alone and in its interactions with the
    other stages. The second reading compares the same run with the consistent and with the lumped
    mass, for MPM with the calculated and with the exact acceleration, and for the fixed-mesh FEM beside.
    Where the interactions swamp the direct measurement on every norm and mesh, the second reading decides."""
    rows = t.get(BURGERS_LUMPING.name) or []
    labels = {"fem_consistent": "FEM", "fem_lumped": "FEM", "mpm_calculated": "MPM calculated a",
              "mpm_exact": "MPM exact a"}
    ratios = {}
    for label in dict.fromkeys(labels.values()):
        at = {}
        for r in rows:
            if labels.get(r["method"]) == label:
                at.setdefault(r["h"], {})[r["mass"]] = num(r, "L2")
        ratios[label] = {h: m["consistent"] / m["lumped"] for h, m in at.items() if {"consistent", "lumped"} <= set(m)}
    return mass_finding(t, "burgers", ratios if rows else None, ("MPM calculated a", "MPM exact a"), "Burgers",
                        f"no table `{BURGERS_LUMPING.name}.csv`")
