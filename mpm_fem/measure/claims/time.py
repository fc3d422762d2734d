"""The time study's claims: C1 (the time error's orders in dt) and C2 (the jump of d^3 x_p/dt^3 at a
node crossing), from ``time/*``."""

from __future__ import annotations

from mpm_fem.measure.claims.base import CONFIRMED, PARTLY, REFUTED, Tables, claim
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
def _c1(t: Tables) -> tuple[str, str]:
    """With the point-mass basis node crossings make the solution a rough function of dt (C2), so its
    orders between successive refinements scatter about the fitted one."""
    fits = {(r["problem"], r["basis"], r["quantity"]): num(r, "fitted_order")
            for r in select(t[TIME_ORDER.name], order="")}
    local = {(r["problem"], r["basis"]): num(r, "fitted_order")
             for r in select(t[TIME_LOCAL_ERROR.name], order="", quantity="x")}
    off = [" ".join(k) for k, o in fits.items() if not GLOBAL_ORDER[0] <= o <= GLOBAL_ORDER[1]]
    off += [f"{p} {b} local" for (p, b), o in local.items() if not LOCAL_ORDER[0] <= o <= LOCAL_ORDER[1]]
    total = len(fits) + len(local)
    return count_verdict(total - len(off), total), (
        f"global order in dt {span(fits.values())}, local order of x_p {span(local.values())} over "
        f"{len(fits)} global and {len(local)} local fits" + (f"; outside the band: {', '.join(off)}" if off else ""))


@claim("C2", source="the slides' formula for the jump of d^3 x_p/dt^3 at a node crossing (point-mass P1)",
       tables=(TIME_CROSSING_SUMMARY.name,), study="time",
       thresholds=f"P1 with the exact nodal acceleration matches the formula within {CROSSING_TOLERANCE:.0%} at every "
                  f"crossing and every C1 basis stays below {NO_JUMP:.0%} of it -> confirmed; only the P1 part holds "
                  "-> partly; P1 does not match -> refuted")
def _c2(t: Tables) -> tuple[str, str]:
    """With the calculated acceleration the nodal accelerations themselves jump whenever any particle
    crosses a node (force quadrature), so the crossing jump is buried in that noise."""
    rows = select(t[TIME_CROSSING_SUMMARY.name], acceleration="exact")
    p1 = select(rows, basis="mpm")
    smooth = {r["basis"]: num(r, "max_abs_ratio") for r in rows if r["basis"] != "mpm"}
    if not p1:
        return "not measured", "no point-mass row with the exact acceleration"
    matches = num(p1[0], "max_ratio_error") <= CROSSING_TOLERANCE
    no_jump = bool(smooth) and all(v <= NO_JUMP for v in smooth.values())
    return (CONFIRMED if matches and no_jump else PARTLY if matches else REFUTED), (
        f"P1, exact acceleration: measured/predicted median {num(p1[0], 'median_ratio'):.3f}, worst deviation "
        f"{num(p1[0], 'max_ratio_error'):.3f} over {p1[0]['crossings']} crossings; C1 bases |measured|/P1 formula "
        + ", ".join(f"{b} {v:.3f}" for b, v in smooth.items()))
