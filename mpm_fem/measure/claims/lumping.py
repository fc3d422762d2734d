"""E7: does FMPM(k), the approximate full mass inverse, recover the consistent mass's accuracy in 1D? From
``lumping/errors``, written by ``studies/lumping.py``.

A *case* is one problem's acceleration (Burgers: calculated or exact; Sod: the calculated one), mesh and
read-out (nodes or particles). FMPM(k) *recovers* the consistent mass on a case when for some
``2 <= k <= 4``

    |E_FMPM(k) / E_consistent - 1| <= FMPM_RECOVERS,

the rule of the 2D claim D5 (:mod:`.plane`; :func:`recovered_by`). FMPM(1) is the lumped mass itself, so
it is shown beside and never counted: a case the lumped mass already meets says nothing of the series.
Every case -> confirmed, some -> partly (with the count),
none -> refuted. The cost of each mass per step over the consistent mass's is the median over the runs of
``step_ms`` (every run on the numpy step), shown beside. A run that failed is named with its cause.
"""

from __future__ import annotations

import math
import statistics

from mpm_fem.measure.claims.base import NOT_MEASURED, Finding, Tables, claim, short
from mpm_fem.measure.claims.rows import count_verdict, failures, num, select
from mpm_fem.measure.claims.rules import rule

ERRORS = "lumping/errors"
FMPM_RECOVERS = rule("FMPM_RECOVERS")
FMPM = ("fmpm1", "fmpm2", "fmpm3", "fmpm4")
#: The orders that can recover the consistent mass: FMPM(1) is the lumped mass (k = 1 term of the series).
COUNTED = FMPM[1:]
READOUTS = ("nodes", "particles")
RULE = (f"per acceleration, mesh and read-out (nodes, particles), FMPM(k) recovers the consistent mass's accuracy "
        f"when |E_FMPM(k) / E_consistent - 1| <= {FMPM_RECOVERS:g} for some 2 <= k <= 4 (FMPM(1) is the lumped mass, "
        "shown, not counted); every case -> confirmed, some -> partly, none -> refuted")


def recovered_by(rel: dict[str, float]) -> str:
    """The lowest order of :data:`COUNTED` whose error over the consistent mass's (``rel``: ``{mass: E /
    E_consistent}``) is within ``FMPM_RECOVERS`` of 1, or ``""``."""
    return next((m for m in COUNTED if m in rel and abs(rel[m] - 1) <= FMPM_RECOVERS), "")


def _ok(row: dict) -> bool:
    return str(row.get("ok", "")) in ("True", "true", "1")


def mass_errors(rows: list[dict]) -> dict[tuple, dict[str, float]]:
    """``{(acceleration, h, readout): {mass: E}}`` over the runs that finished."""
    out: dict = {}
    for r in rows:
        if _ok(r):
            for where in READOUTS:
                out.setdefault((r["acceleration"], num(r, "h"), where), {})[r["mass"]] = num(r, where)
    return out


def step_costs(rows: list[dict], reference: str = "consistent") -> dict[str, float]:
    """Each mass's wall time per step over the ``reference`` mass's on the same run (acceleration and mesh), the
    median over the runs."""
    per: dict = {}
    for r in rows:
        if _ok(r):
            per.setdefault((r["acceleration"], num(r, "h")), {})[r["mass"]] = num(r, "step_ms")
    ratios: dict = {}
    for by in per.values():
        for m, ms in by.items():
            if by.get(reference, 0) > 0 and math.isfinite(ms):
                ratios.setdefault(m, []).append(ms / by[reference])
    return {m: statistics.median(v) for m, v in ratios.items()}


def _range(values: list[float]) -> str:
    """``"0.5-0.9"``, or one number when they agree to two digits."""
    lo, hi = f"{min(values):.2g}", f"{max(values):.2g}"
    return lo if lo == hi else f"{lo}-{hi}"


def _finding(t: Tables, problem: str, name: str) -> Finding:
    rows = select(t[ERRORS], problem=problem)
    table, hits = [], 0
    for (acc, h, where), e in sorted(mass_errors(rows).items(), key=lambda kv: (kv[0][0], -kv[0][1], kv[0][2])):
        if not e.get("consistent") or not any(m in e for m in COUNTED):
            continue
        rel = {m: e[m] / e["consistent"] for m in FMPM if m in e}
        first = recovered_by(rel)
        hits += bool(first)
        table.append({**({"acceleration": acc} if acc else {}), "h": f"{h:g}", "read-out": where,
                      "lumped / consistent": f"{e['lumped'] / e['consistent']:.3g}" if "lumped" in e else "-",
                      "exact / consistent": f"{e['exact'] / e['consistent']:.3g}" if "exact" in e else "-",
                      **{f"{m} / consistent": f"{x:.3g}" for m, x in rel.items()}, "recovered by": first or "none"})
    failed = failures(rows, ("mass", "acceleration", "h"), ERRORS)
    if not table:
        return Finding(NOT_MEASURED, f"no FMPM runs beside the consistent mass on {name}", failed=failed)
    cost = step_costs(rows)
    cost_text = ", ".join(f"{m} {x:.2g}x" for m, x in cost.items() if m != "consistent")
    verdict = count_verdict(hits, len(table))
    where = "; ".join(f"{r.get('acceleration', '') + ' ' if r.get('acceleration') else ''}h = {r['h']} "
                      f"{r['read-out']}: {r['recovered by']}" for r in table)
    evidence = (f"recovered on {hits} of {len(table)}: {where}; wall time per step over the consistent mass's "
                f"(numpy step): {cost_text}" + "".join(f"; {line}" for line in failed))
    fmpm = [x for m, x in cost.items() if m in COUNTED]
    sentence = (f"on {name} FMPM(k) with 2 <= k <= 4 comes within {FMPM_RECOVERS:.0%} of the consistent mass's error "
                f"on {hits} of {len(table)} meshes and read-outs; a step costs {cost_text} of the consistent mass's")
    terse = (f"on {name} FMPM(2-4) within {FMPM_RECOVERS:.0%} of the consistent mass's error on {hits} of "
             f"{len(table)}" + (f", at {_range(fmpm)}x its cost per step" if fmpm else ""))
    return Finding(verdict, evidence, sentence, tuple(table), failed, key=short(sentence, terse))


@claim("E7", source="Nairn & Hammerquist (CMAME 2021): FMPM(k) approaches the consistent mass as k grows",
       tables=(ERRORS,), study="lumping", problem="sod", thresholds=RULE + " (Sod: density L1)")
def _e7_sod(t: Tables) -> Finding:
    """FMPM(k), the truncated series of the particle mass matrix's inverse (k terms, k - 1 extrapolations a
    solve), in the 1D FLIP step with the Sod study's settings, against the consistent mass it approximates;
    every mass runs the numpy step, so that their costs per step compare on one implementation."""
    return _finding(t, "sod", "Sod")


@claim("E7", source="Nairn & Hammerquist (CMAME 2021): FMPM(k) approaches the consistent mass as k grows",
       tables=(ERRORS,), study="lumping", problem="burgers",
       thresholds=RULE + " (Burgers: velocity L2, the calculated and the exact acceleration)")
def _e7_burgers(t: Tables) -> Finding:
    """FMPM(k) against the consistent mass on viscous Burgers, with the calculated acceleration (the mass enters
    the velocity and the acceleration) and with the exact one (the mass enters the velocity only)."""
    return _finding(t, "burgers", "Burgers")
