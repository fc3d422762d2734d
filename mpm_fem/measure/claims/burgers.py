"""The Burgers study's claims: C13 (first order in h) and C3 and C15 on Burgers, from ``burgers/*``."""

from __future__ import annotations

from mpm_fem.measure.claims.base import Tables, claim
from mpm_fem.measure.claims.rows import num, select, span
from mpm_fem.measure.claims.shared import LUMPING_RULE, PPC_RULE, lumping_claim, ppc_claim
from mpm_fem.measure.schema import BURGERS_LUMPING, BURGERS_ORDERS, BURGERS_PPC
from mpm_fem.measure.source import OPTIMAL_PPC

#: The solution and norm the Burgers tables are compared with the source in (why: ``burgers/norms``).
BURGERS_SHOWN = dict(solution="rarefaction", where="particles", norm="max")
#: C13: a least-squares order in FIRST_ORDER counts as first order.
FIRST_ORDER = (0.8, 1.2)
C13_METHODS = {"exact a, dt ~ h": "mpm_exact_dt_h", "calculated a": "mpm_calculated"}


_C13_RULE = (f"least-squares order in [{FIRST_ORDER[0]}, {FIRST_ORDER[1]}] on every eps, for the exact (dt ~ h) and "
             "the calculated acceleration -> confirmed; for one of them -> partly; for none -> differs")


@claim("C13", source="first order with exact and with calculated acceleration", tables=(BURGERS_ORDERS.name,),
       study="burgers", thresholds=_C13_RULE)
def _c13(t: Tables) -> tuple[str, str]:
    """With the exact acceleration the O(dt) time error dominates when dt ~ h; with the viscous time step
    it is second order. The calculated acceleration stalls at four particles per cell: the weight of each
    cell in the force quadrature jumps whenever a particle crosses a node."""
    rows = t[BURGERS_ORDERS.name]

    def fitted(method):
        return [num(r, "fitted") for r in select(rows, method=method, **BURGERS_SHOWN)]

    first = {label: all(FIRST_ORDER[0] <= o <= FIRST_ORDER[1] for o in fitted(m)) and bool(fitted(m))
             for label, m in C13_METHODS.items()}
    verdict = {2: "confirmed", 1: "partly", 0: "differs"}[sum(first.values())]
    return verdict, (", ".join(f"{label} {span(fitted(m))}" for label, m in C13_METHODS.items())
                     + f"; exact a with the viscous dt {span(fitted('mpm_exact'))}, calculated a at 16 per cell "
                       f"{span(fitted('mpm_calculated_16'))}")


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
