"""The Burgers study's claims: C13 (first order in h, with the diagnosis of the calculated acceleration)
and C3 and C15 on Burgers, from ``burgers/*``."""

from __future__ import annotations

import math

from mpm_fem.measure.claims.base import CONFIRMED, DIFFERS, PARTLY, Tables, claim
from mpm_fem.measure.claims.rows import CONVERGING_ORDER, FLOOR_ORDER, num, select, span
from mpm_fem.measure.claims.shared import LUMPING_RULE, PPC_RULE, lumping_claim, ppc_claim
from mpm_fem.measure.schema import BURGERS_DIAGNOSIS, BURGERS_LUMPING, BURGERS_ORDERS, BURGERS_PPC
from mpm_fem.measure.seeds import side
from mpm_fem.measure.source import OPTIMAL_PPC

#: The solution and norm the Burgers tables are compared with the source in (why: ``burgers/norms``).
BURGERS_SHOWN = dict(solution="rarefaction", where="particles", norm="max")
#: C13 judges the exact acceleration with dt ~ h beside the calculated one at each number of particles
#: per cell; its verdict is the calculated acceleration's at the source's OPTIMAL_PPC.
C13_EXACT = "mpm_exact_dt_h"
C13_CALCULATED = {4: "mpm_calculated", 8: "mpm_calculated_8", 16: "mpm_calculated_16"}
C13_METHODS = {"exact a, dt ~ h": C13_EXACT, **{f"calculated a, {n} per cell": m for n, m in C13_CALCULATED.items()}}
#: C13 counts a fitted order as first order when its interval over the runs lies at or above the
#: study's one convergence threshold (not a second one).
FIRST_ORDER = CONVERGING_ORDER
_SOURCE_PPC = [n for n in C13_CALCULATED if OPTIMAL_PPC[0] <= n <= OPTIMAL_PPC[1]]

_C13_RULE = (f"the least-squares order of the {BURGERS_SHOWN['norm']} velocity error over {BURGERS_SHOWN['where']}, "
             "fitted per run (the regular and the jittered layouts of the seeded eps), counts as first order when "
             f"every run's is at least {FIRST_ORDER}, as below first order when every run's is below it (a stall "
             f"when below {FLOOR_ORDER}, a growing error when negative), otherwise as undecided; per number of "
             "particles per cell, the exact (dt ~ h) and the calculated acceleration both first order -> confirmed, "
             f"both below -> differs, otherwise partly; the verdict: that at {' and at '.join(map(str, _SOURCE_PPC))} "
             "per cell (the source's), confirmed or differs where all are, otherwise partly")


def _finite(values) -> list[float]:
    return [v for v in values if math.isfinite(v)]


def c13_order(rows: list[dict], method: str) -> dict:
    """The fitted order of ``method`` in the orders rows of the compared solution and error: over its
    series of several runs, the mean of their means (``mean``), the least ``fitted_lo`` and the largest
    ``fitted_hi`` (``lo``, ``hi``), their :func:`~mpm_fem.measure.seeds.side` of FIRST_ORDER
    (``side``) and the runs (``runs``); ``single``: the regular layout's order of each series of one run."""
    sub = select(rows, method=method)
    seeded = [r for r in sub if num(r, "runs") > 1]
    means, los, his = (_finite(num(r, k) for r in seeded) for k in ("fitted_mean", "fitted_lo", "fitted_hi"))
    lo, hi = (min(los) if los else math.nan), (max(his) if his else math.nan)
    return {"mean": sum(means) / len(means) if means else math.nan, "lo": lo, "hi": hi,
            "side": side(lo, hi, FIRST_ORDER), "runs": "/".join(r["runs"] for r in seeded),
            "single": [num(r, "fitted") for r in sub if not num(r, "runs") > 1]}


def _reading(o: dict) -> str:
    """An order's reading: first order, below it (stalls, grows), undecided, or no interval."""
    if o["side"] == "below":
        return "the error grows" if o["hi"] < 0 else "stalls" if o["hi"] < FLOOR_ORDER else "below first order"
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


@claim("C13", source="first order with exact and with calculated acceleration", tables=(BURGERS_ORDERS.name,),
       study="burgers", thresholds=_C13_RULE)
def _c13(t: Tables) -> tuple[str, str]:
    """An order is the least-squares slope of the error against h, fitted per run; its interval is the
    range over the runs of the regular and the jittered particle layouts, and only an interval on one side
    of the threshold counts. With the exact acceleration and dt ~ h the O(dt) error of the time step sets
    the order; beside it, the evidence gives the exact acceleration's order with the viscous time step
    (dt ~ h^2; one run per eps). The last clause reads the diagnosis table (when the study wrote one):
    each change to the calculated-acceleration run, one at a time on the regular layout, by whether its
    particles' error grows, stalls or falls as h shrinks; it names no cause beyond what these changes show."""
    rows = select(t[BURGERS_ORDERS.name], **BURGERS_SHOWN)
    exact = c13_order(rows, C13_EXACT)
    calc = {n: c13_order(rows, m) for n, m in C13_CALCULATED.items()}
    verdicts = {n: _pair_verdict(exact["side"], o["side"]) for n, o in calc.items()}
    head = [verdicts[n] for n in _SOURCE_PPC]
    verdict = head[0] if len(set(head)) == 1 and head[0] != PARTLY else PARTLY
    lines = [f"the source's {'-'.join(map(str, _SOURCE_PPC))} per cell: calculated a "
             + ", ".join(f"{n} per cell {_interval(calc[n])}" for n in _SOURCE_PPC)
             + f", exact a (dt ~ h) {_interval(exact)}"]
    lines.append(f"exact a, dt ~ h: {_interval(exact, True)}, single runs (regular layout) {span(exact['single'])}; "
                 f"exact a with the viscous dt {span(c13_order(rows, 'mpm_exact')['single'])}")
    lines += [f"{n} per cell: {verdicts[n]}, calculated a {_interval(o, True)}, single runs (regular layout) "
              f"{span(o['single'])}" for n, o in calc.items()]
    diagnosis = t.get(BURGERS_DIAGNOSIS.name)
    return verdict, "; ".join(lines + ([diagnosis_text(diagnosis)] if diagnosis else []))


def _behaviour(orders: list[float]) -> str:
    if max(orders) < 0:
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
def _c3_burgers(t: Tables) -> tuple[str, str]:
    rows = t[BURGERS_PPC.name]
    keys = {(r["method"], r["h"]) for r in rows}
    groups = {f"{m} h = {h}": select(rows, method=m, h=h) for m, h in sorted(keys)}
    return ppc_claim(groups, (f"{BURGERS_SHOWN['where']}_{BURGERS_SHOWN['norm']}",))


@claim("C15", source="one of four error sources", tables=(BURGERS_LUMPING.name,), study="burgers",
       problem="burgers", thresholds=LUMPING_RULE + " (Burgers: velocity L2, MPM over particles, FEM over nodes)")
def _c15_burgers(t: Tables) -> tuple[str, str]:
    """The direct comparison: the same run with the consistent and with the lumped mass, for MPM with
    the calculated and with the exact acceleration, and for the fixed-mesh FEM beside."""
    rows = t[BURGERS_LUMPING.name]
    labels = {"fem_consistent": "FEM", "fem_lumped": "FEM", "mpm_calculated": "MPM calculated a",
              "mpm_exact": "MPM exact a"}
    ratios = {}
    for label in dict.fromkeys(labels.values()):
        at = {}
        for r in rows:
            if labels.get(r["method"]) == label:
                at.setdefault(r["h"], {})[r["mass"]] = num(r, "L2")
        ratios[label] = {h: m["consistent"] / m["lumped"] for h, m in at.items() if {"consistent", "lumped"} <= set(m)}
    return lumping_claim(ratios, judged=("MPM calculated a", "MPM exact a"))
