"""C11's mechanism: the sentence that states, from ``drift/drift`` (:data:`mpm_fem.measure.schema.DRIFT`,
written by ``studies/drift.py``), which change removes or reduces the growth of Sod's particle
density error under refinement.

Per variant, the observed order of the particle density L1 error over its two finest meshes that
ran (``p = log(e_coarse / e_fine) / log(2)`` for a halving of h) and its volume drift
``sum_p V_p - 1`` on the finest one. The error *grows* where ``p < GROWTH_ORDER``. A variant:

- *removes* the growth when the study settings' error grows and its own does not (``p >= GROWTH_ORDER``;
  the project's thresholds then name it converging, ``p >= CONVERGING_ORDER``, or a floor,
  ``p < FLOOR_ORDER``, of :mod:`mpm_fem.measure.claims.rows`);
- *reduces* it when its error still grows, at most ``REDUCED`` times as fast as the study settings'
  (``p >= REDUCED * p_study``);
- else leaves it.

The drift is said to separate the variants only when every variant that removes the growth drifts
less (``|sum_p V_p - 1|`` on the finest mesh) than every variant that does not. The variants whose
nodal error equals the study settings' within ``SAME_NODES`` (relative) on every mesh they share are
named as leaving the motion unchanged. Nothing else is stated: no cause the table does not measure.
"""

from __future__ import annotations

import math

from mpm_fem.measure.claims.rows import CONVERGING_ORDER, FLOOR_ORDER, num, select, successive_orders
from mpm_fem.measure.schema import DRIFT

#: The variant every other one changes one thing against: the Sod study's MPM settings.
STUDY = "study settings"
#: An order of the particle density L1 error below GROWTH_ORDER: the error grows as h shrinks.
GROWTH_ORDER = 0.0
#: A variant whose error still grows reduces the growth when its order is at least REDUCED times the
#: study settings' (both negative: at most half as fast).
REDUCED = 0.5
#: Nodal L1 errors within SAME_NODES of each other (relative) count as the same motion.
SAME_NODES = 1e-3


def _finest(rows: list[dict]) -> tuple[list[dict], float]:
    """The two finest meshes of a variant that ran, and the order of the particle L1 between them."""
    ok = sorted((r for r in rows if math.isfinite(num(r, "particles_L1")) and num(r, "particles_L1") > 0),
                key=lambda r: -num(r, "h"))[-2:]
    return ok, (successive_orders(ok, "particles_L1")[0] if len(ok) == 2 else math.nan)


def _kind(order: float) -> str:
    return ("converging" if order >= CONVERGING_ORDER else "a floor" if order < FLOOR_ORDER
            else "between a floor and converging")


def _same_motion(rows: list[dict], study: list[dict]) -> bool:
    base = {num(r, "h"): num(r, "nodes_L1") for r in study}
    shared = [(num(r, "nodes_L1"), base[num(r, "h")]) for r in rows if num(r, "h") in base]
    return bool(shared) and all(math.isfinite(a) and math.isfinite(b) and abs(a - b) <= SAME_NODES * abs(b)
                                for a, b in shared)


def mechanism(tables) -> str:
    """The sentence of C11's explanation, formatted from ``tables["drift/drift"]`` (module docstring)."""
    rows = tables.get(DRIFT.name) or []
    names = list(dict.fromkeys(r["variant"] for r in rows))
    if STUDY not in names:
        return f"not measured: no {STUDY} rows in {DRIFT.name}"
    series = {n: select(rows, variant=n) for n in names}
    measured = {n: _finest(series[n]) for n in names}
    (coarse, fine), p_study = measured[STUDY]
    if not math.isfinite(p_study):
        return f"not measured: {STUDY} ran on fewer than two meshes of {DRIFT.name}"
    drift = {n: num(pair[-1], "volume_drift") for n, (pair, p) in measured.items() if math.isfinite(p)}
    where = f"h = {coarse['h']} to {fine['h']}"
    head = (f"With the {STUDY} the particle density L1 error {'grows' if p_study < GROWTH_ORDER else 'does not grow'} "
            f"over the finest meshes (order {p_study:.2f} from {where}; volume drift {drift[STUDY]:.2g} at "
            f"h = {fine['h']})")
    others = [n for n in names if n != STUDY and n in drift]

    def item(n: str, kind: bool = False) -> str:
        pair, p = measured[n]
        at = "" if [r["h"] for r in pair] == [coarse["h"], fine["h"]] else f" from h = {pair[0]['h']} to {pair[1]['h']}"
        return f"{n} ({p:.2f}{', ' + _kind(p) if kind else ''}{at}; drift {drift[n]:.2g})"

    def listed(label: str, group: list[str], kind: bool = False) -> str:
        return f"{label}: {', '.join(item(n, kind) for n in group)}" if group else ""

    same = [n for n in others if _same_motion(series[n], series[STUDY])]
    motion = (f"The nodal density error is the {STUDY}' within {SAME_NODES:.1%} on every mesh with "
              f"{', '.join(same)}: these change the particle density, not the motion." if same else "")
    if p_study >= GROWTH_ORDER:
        tail = listed("orders of the other variants", others)
        return " ".join(s for s in (f"{head}: no growth to remove{'; ' + tail if tail else ''}.", motion) if s)
    removes = [n for n in others if measured[n][1] >= GROWTH_ORDER]
    reduces = [n for n in others if n not in removes and measured[n][1] >= REDUCED * p_study]
    leaves = [n for n in others if n not in removes and n not in reduces]
    parts = [listed(f"removed (order at least {GROWTH_ORDER:g}) by", removes, kind=True),
             listed(f"reduced (still growing, at most {REDUCED:.0%} of the {STUDY}' rate) by", reduces),
             listed("not reduced by", leaves)]
    text = f"{head}; " + "; ".join(p for p in parts if p) + "."
    if removes:
        lo = max(abs(drift[n]) for n in removes)
        rest = [abs(drift[n]) for n in [STUDY] + reduces + leaves]
        text += (f" The volume drift separates them: |drift| at most {lo:.2g} where the growth is removed, at "
                 f"least {min(rest):.2g} where it is not." if lo < min(rest) else
                 f" The volume drift does not separate them: |drift| up to {lo:.2g} where the growth is removed, "
                 f"down to {min(rest):.2g} where it is not.")
    else:
        text += " No variant removes the growth."
    return " ".join(s for s in (text, motion) if s)
