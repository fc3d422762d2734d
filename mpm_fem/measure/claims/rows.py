"""Reading rows: the helpers every criterion uses on the rows of a table (dicts of strings, as read
from the CSVs)."""

from __future__ import annotations

import math
import re
from collections.abc import Mapping

from mpm_fem.measure.claims.base import CONFIRMED, PARTLY, REFUTED
from mpm_fem.measure.claims.rules import rule

#: The study's one convergence threshold (the rule book): an observed order at or above CONVERGING_ORDER
#: counts as converging, one below FLOOR_ORDER as a floor (the error no longer falls with h), one below
#: GROWTH_ORDER as a growing error. Every claim that reads an order uses these, and counts an order only
#: when its interval over seeds lies on one side. An observed order is a stated order n within
#: ORDER_TOLERANCE (:func:`first_order`, :func:`in_band`).
CONVERGING_ORDER, FLOOR_ORDER, GROWTH_ORDER = rule("CONVERGING_ORDER"), rule("FLOOR_ORDER"), rule("GROWTH_ORDER")
ORDER_TOLERANCE = rule("ORDER_TOLERANCE")
#: 'first order' in a convergence claim: an order at least this (the one definition, rules.ORDER_TOLERANCE)
FIRST_ORDER = 1 - ORDER_TOLERANCE


def in_band(order: float, lo: float, hi: float) -> bool:
    """Whether an observed ``order`` lies in the stated band ``[lo, hi]`` widened by ORDER_TOLERANCE."""
    return lo - ORDER_TOLERANCE <= order <= hi + ORDER_TOLERANCE


def num(row: Mapping, key: str) -> float:
    """``row[key]`` as a float; NaN when absent or empty."""
    value = row.get(key, "")
    try:
        return float(value)
    except (TypeError, ValueError):
        return math.nan


def select(rows: list[dict], **where) -> list[dict]:
    """The rows whose columns equal ``where`` (numbers compared as floats, anything else as text)."""
    def same(value, wanted):
        if isinstance(wanted, (int, float)) and not isinstance(wanted, bool):
            try:
                return float(value) == float(wanted)
            except (TypeError, ValueError):
                return False
        return str(value) == str(wanted)

    return [r for r in rows if all(same(r.get(k, ""), v) for k, v in where.items())]


def span(values, fmt: str = ".2f") -> str:
    """``"lo..hi"`` of the finite values (one number when they agree, ``"-"`` when there is none)."""
    v = [x for x in values if math.isfinite(x)]
    if not v:
        return "-"
    lo, hi = format(min(v), fmt), format(max(v), fmt)
    return lo if lo == hi else f"{lo}..{hi}"


def count_verdict(hits: int, total: int, none: str = REFUTED) -> str:
    """``confirmed`` when every case holds, ``partly`` when some do, ``none`` when no case does."""
    if total == 0:
        return "not measured"
    return CONFIRMED if hits == total else (PARTLY if hits else none)


def saturation(rows: list[dict], key: str, within: float, ppc: str = "ppc") -> int:
    """The fewest particles per cell whose ``key`` error is within ``within`` of the smallest one."""
    values = [(int(num(r, ppc)), num(r, key)) for r in rows if math.isfinite(num(r, key))]
    best = min(e for _, e in values)
    return min(n for n, e in values if e <= (1 + within) * best)


def successive_orders(rows: list[dict], key: str) -> list[float]:
    """Observed orders between successive rows (sorted by decreasing ``h``); NaN where a run failed."""
    h, e = [num(r, "h") for r in rows], [num(r, key) for r in rows]
    out = []
    for k in range(len(rows) - 1):
        ok = e[k] > 0 and e[k + 1] > 0
        out.append(math.log(e[k] / e[k + 1]) / math.log(h[k] / h[k + 1]) if ok else math.nan)
    return out


def failed(rows: list[dict], flag: str | None = "ok") -> list[dict]:
    """The rows of runs that failed: ``flag`` (the table's success column) false where the table has it,
    else (or with ``flag=None``, a table without one) an ``error`` that is a message, not a number
    (``budget/subsets``' ``error`` is the measured error)."""
    def broke(r: Mapping) -> bool:
        if flag is not None and flag in r:
            return str(r[flag]) not in ("True", "true", "1")
        message = str(r.get("error", "")).strip()
        return bool(message) and not _is_number(message)
    return [r for r in rows if broke(r)]


def _is_number(value) -> bool:
    try:
        float(value)
    except (TypeError, ValueError):
        return False
    return True


#: the particulars of a run's error message (where and when), removed to leave its cause
_INVERTED = re.compile(r"^\s*J = det F = \S+ <= 0\b.*$")
_PARTICULARS = re.compile(r"\([^)]*\)|\b(at step|in particle|at [xt]\s*=)\s*[-+0-9.e]+")


def failure_cause(message: str) -> str:
    """The cause of a failed run, its particulars removed: ``"positivity lost at step 1317 (t=0.06) in
    particle 180 at x=0.46: ..."`` -> ``"positivity lost"``; ``"particle 0 at x=-1e-06 lies outside the grid
    [0.0, 1.0] (1 such particles)"`` -> ``"a particle lies outside the grid [0.0, 1.0]"``; ``"J = det F = -6.8 <= 0
    at step 7 ..."`` -> ``"a particle inverts"``."""
    text = re.split(r"[:;]", str(message), maxsplit=1)[0]
    text = _INVERTED.sub("a particle inverts", text)  # the 2D model's "J = det F = -6.8 <= 0 at ..."
    text = re.sub(r"\bparticle \d+", "a particle", _PARTICULARS.sub("", text))
    return " ".join(text.split()) or "no message"


def failures(rows: list[dict], where: tuple[str, ...] = ("h",), table: str = "",
             flag: str | None = "ok") -> tuple[str, ...]:
    """One line per cause of the failed runs among ``rows`` (:func:`failed`, :func:`failure_cause`) of
    ``table``: their count, the values of the columns ``where`` they were run at, and the cause, e.g.
    ``"sod/ppc: 2 of 18 runs failed (ppc = 1; h = 0.0025, 0.000625): positivity lost"``; empty when no run
    failed; ``flag`` as in :func:`failed`."""
    bad = failed(rows, flag)
    causes: dict[str, list[dict]] = {}
    for r in bad:
        causes.setdefault(failure_cause(r.get("error", "")), []).append(r)
    out = []
    for cause, runs in causes.items():
        at = "; ".join(f"{k} = {', '.join(_ordered(str(r.get(k, '')) for r in runs))}" for k in where
                       if any(str(r.get(k, "")) for r in runs))
        out.append((f"{table}: " if table else "") + f"{len(runs)} of {len(rows)} runs failed"
                   + (f" ({at})" if at else "") + f": {cause}")
    return tuple(out)


def _ordered(values) -> list[str]:
    """The distinct ``values``, numbers from the largest (meshes from the coarsest), text in the order met."""
    distinct = list(dict.fromkeys(values))
    return sorted(distinct, key=lambda v: -float(v)) if all(map(_is_number, distinct)) else distinct
