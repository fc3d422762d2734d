"""The time study's claims: C1 (the time error's orders in dt) and C2 (the jump of d^3 x_p/dt^3 at a
node crossing), from ``time/*``."""

from __future__ import annotations

import math

from mpm_fem.measure.claims.base import CONFIRMED, PARTLY, REFUTED, Finding, Tables, claim, short
from mpm_fem.measure.claims.rows import ORDER_TOLERANCE, count_verdict, num, select, span
from mpm_fem.measure.claims.rules import rule
from mpm_fem.measure.schema import TIME_CROSSING_SUMMARY, TIME_LOCAL_ERROR, TIME_ORDER

#: C1: least-squares orders in dt inside these bands count as first (global) and second (local) order: the
#: stated order +- the rule book's one tolerance of an order (ORDER_TOLERANCE, shared with C5-C10 and C13).
GLOBAL_ORDER = (1 - ORDER_TOLERANCE, 1 + ORDER_TOLERANCE)
LOCAL_ORDER = (GLOBAL_ORDER[0] + 1, GLOBAL_ORDER[1] + 1)
#: C2: P1 with the exact nodal acceleration matches the formula when every crossing's measured/predicted
#: ratio is within CROSSING_TOLERANCE of one; a C1 basis has no jump when |measured| stays below
#: NO_JUMP x the P1 formula at every crossing.
CROSSING_TOLERANCE, NO_JUMP = rule("CROSSING_TOLERANCE"), rule("NO_JUMP")


@claim("C1", source="local error O(dt^2), global O(dt)", tables=(TIME_ORDER.name, TIME_LOCAL_ERROR.name),
       study="time",
       thresholds=f"least-squares order in dt of every global error in [{GLOBAL_ORDER[0]}, {GLOBAL_ORDER[1]}] and of "
                  f"every local position error in [{LOCAL_ORDER[0]}, {LOCAL_ORDER[1]}] -> confirmed; some -> partly; "
                  "none -> refuted")
def _c1(t: Tables) -> Finding:
    """With the point-mass basis node crossings make the solution a rough function of dt (C2), so its
    orders between successive refinements scatter about the fitted one."""
    fits = {(r["problem"], r["basis"], r["quantity"]): num(r, "fitted_order")
            for r in select(t[TIME_ORDER.name], order="")}
    local = {(r["problem"], r["basis"]): num(r, "fitted_order")
             for r in select(t[TIME_LOCAL_ERROR.name], order="", quantity="x")}
    off = [" ".join(k) for k, o in fits.items() if not GLOBAL_ORDER[0] <= o <= GLOBAL_ORDER[1]]
    off += [f"{p} {b} local" for (p, b), o in local.items() if not LOCAL_ORDER[0] <= o <= LOCAL_ORDER[1]]
    total = len(fits) + len(local)
    table = tuple({"problem": p, "basis": b,
                   "global orders": span([o for (p2, b2, _), o in fits.items() if (p2, b2) == (p, b)]),
                   "local order of x_p": span([o for k, o in local.items() if k == (p, b)])}
                  for p, b in dict.fromkeys((p, b) for p, b, _ in fits))
    sentence = (f"the global error's order in dt is {span(fits.values())} and the local position error's "
                f"{span(local.values())} over {len(fits)} and {len(local)} fits, in the band on {total - len(off)} of "
                f"{total} fits")
    return Finding(count_verdict(total - len(off), total), (
        f"global order in dt {span(fits.values())}, local order of x_p {span(local.values())} over "
        f"{len(fits)} global and {len(local)} local fits" + (f"; outside the band: {', '.join(off)}" if off else "")),
        sentence, table, key=short(sentence, f"order in dt {span(fits.values())} (global error), "
                                             f"{span(local.values())} (local position error)"))


def _second_half(t: Tables) -> tuple[bool | None, str, tuple[dict, ...]]:
    """C2's second half from the global orders in dt (``time/time_order``): per problem and quantity,
    P1's fitted order against GIMP's and the B-spline's, which have no jump. It holds where P1's order
    is at most first order (within ORDER_TOLERANCE), a smooth basis reaches at least first order, and
    that basis's order exceeds P1's by more than ORDER_TOLERANCE: the jump, not the integrator, limits
    P1. Where every basis is first order alike (forward Euler's own order) the runs cannot tell the jump's
    limit from the integrator's, and the half does not hold. None without the smooth bases' rows (said so)."""
    fits = {(r["problem"], r["quantity"], r["basis"]): num(r, "fitted_order")
            for r in select(t.get(TIME_ORDER.name) or [], order="")}
    cases = sorted({(p, q) for p, q, b in fits if b == "mpm" and any((p, q, o) in fits for o in _SMOOTH)})
    if not cases:
        return None, "second half not measured: no global orders in dt of P1 beside GIMP's or the B-spline's", ()
    table = tuple({"problem": p, "quantity": q, **{_NAMES[b]: f"{fits[(p, q, b)]:.2f}" for b in ("mpm", *_SMOOTH)
                                                   if (p, q, b) in fits}} for p, q in cases)
    best = {(p, q): max(fits.get((p, q, b), -math.inf) for b in _SMOOTH) for p, q in cases}
    limited = [fits[(p, q, "mpm")] <= GLOBAL_ORDER[1] for p, q in cases]
    smooth = [best[c] >= GLOBAL_ORDER[0] for c in cases]
    apart = [best[(p, q)] - fits[(p, q, "mpm")] > ORDER_TOLERANCE for p, q in cases]
    holds = all(limited) and all(smooth) and all(apart)
    text = (f"second half: P1's global order in dt {span([fits[(p, q, 'mpm')] for p, q in cases])} (at most "
            f"{GLOBAL_ORDER[1]:g} on {sum(limited)} of {len(cases)}), the smooth bases' "
            f"{span([fits[(p, q, b)] for p, q in cases for b in _SMOOTH if (p, q, b) in fits])} (at least "
            f"{GLOBAL_ORDER[0]:g} on {sum(smooth)} of {len(cases)}; above P1's by more than {ORDER_TOLERANCE:g} on "
            f"{sum(apart)} of {len(cases)}, where the jump and not the integrator limits P1): "
            + "; ".join(f"{r['problem']} {r['quantity']}: " + ", ".join(f"{k} {v}" for k, v in r.items()
                                                                        if k not in ("problem", "quantity"))
                        for r in table))
    return holds, text, table


_SMOOTH = ("gimp", "bspline")
_NAMES = {"mpm": "P1", "gimp": "GIMP", "bspline": "B-spline"}


@claim("C2", source="the slides' formula for the jump of d^3 x_p/dt^3 at a node crossing (point-mass P1), which "
                    "limits accuracy to first order",
       tables=(TIME_CROSSING_SUMMARY.name,), study="time",
       thresholds=f"first half: P1 with the exact nodal acceleration matches the formula within "
                  f"{CROSSING_TOLERANCE:.0%} at every crossing and every C1 basis stays below {NO_JUMP:.0%} of it; "
                  f"second half (time/time_order): P1's global order in dt at most {GLOBAL_ORDER[1]:g} where GIMP or "
                  f"the B-spline, which have no jump, reach at least {GLOBAL_ORDER[0]:g} and exceed P1's order by "
                  "more than the rule book's tolerance of an order, on every problem and quantity. Both halves -> "
                  "confirmed; the P1 formula holds but a half fails or is not measured -> partly (said so); P1 does "
                  "not match -> refuted")
def _c2(t: Tables) -> Finding:
    """With the calculated acceleration the nodal accelerations themselves jump whenever any particle
    crosses a node (force quadrature), so the crossing jump is buried in that noise. The second half
    compares P1's order in dt with that of the bases without the jump, on the same runs."""
    rows = select(t[TIME_CROSSING_SUMMARY.name], acceleration="exact")
    p1 = select(rows, basis="mpm")
    smooth = {r["basis"]: num(r, "max_abs_ratio") for r in rows if r["basis"] != "mpm"}
    if not p1:
        return Finding("not measured", "no point-mass row with the exact acceleration")
    matches = num(p1[0], "max_ratio_error") <= CROSSING_TOLERANCE
    no_jump = bool(smooth) and all(v <= NO_JUMP for v in smooth.values())
    second, text, table = _second_half(t)
    verdict = CONFIRMED if matches and no_jump and second else PARTLY if matches else REFUTED
    below = f"{max(smooth.values()):.1%}" if smooth else ""
    smooth_said = (f"the smooth bases' stays below {below} of it" if smooth else
                   "the smooth bases' jump is not measured (no GIMP or B-spline row with the exact acceleration)")
    sentence = (f"at a node crossing P1's jump of the third time derivative matches the slides' formula within "
                f"{num(p1[0], 'max_ratio_error'):.1%} over {p1[0]['crossings']} crossings, {smooth_said}"
                + (f"; P1's global order in dt is {span([float(r['P1']) for r in table])} against "
                   f"{span([float(v) for r in table for k, v in r.items() if k in ('GIMP', 'B-spline')])} for "
                   "the smooth bases" if table else "")
                + f"; the claim holds on {int(matches) + int(no_jump) + int(bool(second))} of 3 checks (the jump, "
                "the smooth bases, the order in dt)")
    return Finding(verdict, (
        f"P1, exact acceleration: measured/predicted median {num(p1[0], 'median_ratio'):.3f}, worst deviation "
        f"{num(p1[0], 'max_ratio_error'):.3f} over {p1[0]['crossings']} crossings; C1 bases |measured|/P1 formula "
        + ", ".join(f"{b} {v:.3f}" for b, v in smooth.items()) + f"; {text}"), sentence, table,
        key=short(f"P1's jump of d^3 x_p/dt^3 at a node crossing within {num(p1[0], 'max_ratio_error'):.1%} of the "
                  f"slides' formula over {p1[0]['crossings']} crossings; "
                  + (f"smooth bases below {below}" if smooth else "smooth bases not measured"),
                  f"P1's jump at a node crossing within {num(p1[0], 'max_ratio_error'):.1%} of the slides' formula; "
                  + (f"smooth bases below {below} of it" if smooth else "smooth bases not measured")))
