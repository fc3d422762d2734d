"""The 2D projection claims, D8 and D9: do the 1D projection bands (C5-C9) and Hickernell's bound (C4)
carry over to the plane? From ``plane_projection/orders`` and ``plane_projection/bounds``, written by
``studies/plane_projection.py``.

An order is judged in the 1D units (``order``: an extensive nodal error, ``E_m``, ``E_P``, ``E_F``, whose
size scales with the nodal measure ``h^2``, divided by ``h``, so that a 2D order is comparable with the 1D
band), per quantity, layout and particles per cell, with the slides' weights, point masses and the L1 norm.
"""

from __future__ import annotations

from mpm_fem.measure.claims.base import CONFIRMED, REFUTED, Finding, Tables, claim, short
from mpm_fem.measure.claims.rows import ORDER_TOLERANCE, count_verdict, in_band, num, select, span
from mpm_fem.measure.schema import PLANE_PROJECTION_BOUNDS, PLANE_PROJECTION_ORDERS
from mpm_fem.measure.source import PROJECTION_BANDS, band_text

ORDERS, BOUNDS = PLANE_PROJECTION_ORDERS.name, PLANE_PROJECTION_BOUNDS.name
#: The quantities D8 judges (the 1D C5-C9) and the layouts, each in a row of its own.
JUDGED = ("E_m", "E_P", "E_F", "E_a", "E_v")
LAYOUTS = ("jittered", "random", "advected", "regular")
NAMES = {"E_m": "mass", "E_P": "momentum", "E_F": "force", "E_a": "acceleration", "E_v": "velocity"}
_SHOWN = dict(norm="L1", weights="cell", basis="mpm")


def band_rows(t: Tables) -> tuple[dict, ...]:
    """One row per judged quantity and layout: the orders over the particle counts and how many lie inside
    the source's band (widened by ORDER_TOLERANCE). D8 counts orders, so a row carries no yes/no of its own."""
    out = []
    for q in JUDGED:
        lo, hi = PROJECTION_BANDS[q]
        for lay in LAYOUTS:
            orders = [num(r, "order") for r in select(t[ORDERS], quantity=q, layout=lay, **_SHOWN)]
            if not orders:
                continue
            hits = sum(in_band(p, lo, hi) for p in orders)
            out.append({"quantity": q, "layout": lay, "orders": span(orders), "band": band_text(q),
                        "inside": f"{hits} of {len(orders)}", "_hits": hits, "_total": len(orders)})
    return tuple(out)


@claim("D8", source="mass, momentum, force O(h^p), 1 <= p <= 2; acceleration, velocity 0 <= p <= 1",
       tables=(ORDERS,), study="plane_projection",
       thresholds=f"least-squares L1 order over every mesh in the 1D units, point mass with the slides' weights, for "
                  f"each of {', '.join(JUDGED)} on each of the {', '.join(LAYOUTS)} layouts and every particle count: "
                  f"inside the band (+-{ORDER_TOLERANCE:g}, the rule book's one tolerance of an order) on every one -> "
                  "confirmed, on some -> partly (the evidence names the quantities and layouts on which it holds), on "
                  "none -> refuted")
def _d8(t: Tables) -> Finding:
    """In 2D the derivative of a bilinear hat varies across a cell, so the equal-weight rule of an irregular
    layout does not integrate a constant stress against it exactly: the force error loses the order the
    1D hat keeps, and the acceleration, a force over a mass of size h^2, loses it too. Regular midpoints
    integrate the bilinear parts exactly and converge faster than the band, as in 1D."""
    rows = band_rows(t)
    hits, total = sum(r["_hits"] for r in rows), sum(r["_total"] for r in rows)
    table = tuple({k: v for k, v in r.items() if not k.startswith("_")} for r in rows)
    every = [f"{NAMES[r['quantity']]} on {r['layout']}" for r in rows if r["_hits"] == r["_total"]]
    others = [f"{NAMES[r['quantity']]} on {r['layout']} {r['orders']}" for r in rows if r["_hits"] < r["_total"]]
    by_q = "; ".join(NAMES[q] + " " + ", ".join(f"{r['layout']} {r['orders']}" for r in rows if r["quantity"] == q)
                     for q in JUDGED)
    cases = f"orders ({len(rows)} quantities and layouts, each particle count apart)"
    sentence = (f"the 2D projection orders lie in the source's bands on {hits} of {total} {cases}; on every "
                f"particle count: {', '.join(every) or 'none'}" + (f"; not {', '.join(others)}" if others else ""))
    evidence = f"holds on {hits} of {total} {cases}: {by_q}"
    key = short(sentence, f"the 2D projection orders lie in the source's bands on {hits} of {total} {cases}",
                f"the 2D projection orders lie in the source's bands on {hits} of {total} orders")
    return Finding(count_verdict(hits, total), evidence, sentence, table, key=key)


@claim("D9", source="|int f - h^2/N sum f(z_k)| <= h^2 D2 V(f) on every cell and node", tables=(BOUNDS,),
       study="plane_projection",
       thresholds="bound/error >= 1 on every entry (cell, or interior node and component) of every check, layout, "
                  "particle count, mesh and seed -> confirmed; below somewhere -> refuted (the rows named)")
def _d9(t: Tables) -> Finding:
    """The bound is Zaremba's identity closed with Cauchy-Schwarz, with the modified L2 discrepancy (the 1D D2
    extended by the tensor product) and the variation of the integrand on the cell and two of its edges: it
    holds for every point set, so a failure is a defect of the measurement."""
    rows = t[BOUNDS]
    holding = [r for r in rows if num(r, "min_ratio") >= 1]
    ratio = min(num(r, "min_ratio") for r in rows)
    entries = sum(int(num(r, "entries")) for r in rows)
    checks = dict.fromkeys(r["check"] for r in rows)
    table = tuple({"check": c, "smallest bound/error": span([num(r, "min_ratio") for r in rows if r["check"] == c],
                                                            ".3g"),
                   "rows holding": f"{sum(r['check'] == c for r in holding)} of {sum(r['check'] == c for r in rows)}"}
                  for c in checks)
    failing = [f"{r['check']} {r['layout']} {r['ppc']}x{r['ppc']} h = {r['h']}" for r in rows if r not in holding]
    verdict = CONFIRMED if len(holding) == len(rows) else REFUTED
    sentence = (f"Hickernell's bound with the 2D discrepancy holds on {len(holding)} of {len(rows)} rows "
                f"({entries} entries), the smallest bound over error {ratio:.3g}")
    return Finding(verdict, f"bound >= error on {len(holding)} of {len(rows)} rows, smallest bound/error {ratio:.3g}"
                   + (f"; fails on {', '.join(failing)}" if failing else ""), sentence, table,
                   key=short(f"the 2D bound holds on {len(holding)} of {len(rows)} rows, smallest bound "
                                       f"over error {ratio:.3g}"))
