"""C11's mechanism: the sentence that states, from ``drift/drift`` (:data:`mpm_fem.measure.schema.DRIFT`,
written by ``studies/drift.py``), which change removes or reduces the growth of Sod's particle
density error under refinement.

An order is that of the particle density L1 error between two meshes, ``p = log(e_coarse / e_fine)
/ log(h_coarse / h_fine)``; the error *grows* where ``p < GROWTH_ORDER``.

On the regular layout (the study settings'), per variant: ``p`` over its two finest meshes and the
volume drift ``sum_p V_p - 1`` on the finest. One layout resolves an order only to the spread of
orders over layouts: ``band`` is the widest range of the orders over the jittered seeds of one
variant on the same two meshes (0 when the table has none), and a regular order counts as growth
only below ``GROWTH_ORDER - band``. A variant

- *removes* the growth when the study settings' error grows and its own does not (the project's
  thresholds of :mod:`mpm_fem.measure.claims.rows` then name it converging, ``p >= CONVERGING_ORDER``,
  or a floor, ``p < FLOOR_ORDER``);
- *reduces* it when its error still grows, at most ``REDUCED`` times as fast (``p >= REDUCED p_study``);
- else leaves it.

The volume drift is said to separate the variants only when every variant that removes the growth
drifts less (``|sum_p V_p - 1|`` on the finest mesh) than every one that does not. The variants whose
nodal error equals the study settings' within ``SAME_NODES`` (relative) on every mesh they share are
named as leaving the motion unchanged.

On the jittered layouts, per seeded variant: the range of ``p`` over its seeds on the finest two
meshes every seed of the study settings ran; an order counts only when the whole range lies on one
side: the error grows on every seed (``max p < GROWTH_ORDER``) or on none (``min p >= GROWTH_ORDER``).
A variant removes the growth there when the study settings' grows on every seed and its own on
none; it reduces it when it grows on every seed, at most ``REDUCED`` times as fast as the study
settings' slowest seed (``min p >= REDUCED max p_study``). A variant that grows on every seed with
less drift on every seed than the study settings' least is named: there the drift does not explain
the growth. Nothing else is stated.
"""

from __future__ import annotations

import math

from mpm_fem.measure.claims.rows import (
    CONVERGING_ORDER,
    FLOOR_ORDER,
    GROWTH_ORDER,
    num,
    select,
    span,
    successive_orders,
)
from mpm_fem.measure.claims.rules import rule
from mpm_fem.measure.schema import DRIFT

#: The variant every other one changes one thing against: the Sod study's MPM settings.
STUDY = "study settings"
#: A variant whose error still grows reduces the growth when its order is at least REDUCED times the
#: study settings' (both negative: at most half as fast).
REDUCED = rule("REDUCED")
#: Nodal L1 errors within SAME_NODES of each other (relative) count as the same motion.
SAME_NODES = rule("SAME_NODES")


def _ok(rows: list[dict]) -> list[dict]:
    """The rows that ran, by decreasing h."""
    return sorted((r for r in rows if num(r, "particles_L1") > 0), key=lambda r: -num(r, "h"))


def _order(rows: list[dict], hs: tuple[float, float]) -> float:
    """The order between the meshes ``hs`` (NaN unless both ran)."""
    pair = [r for r in _ok(rows) if num(r, "h") in hs]
    return successive_orders(pair, "particles_L1")[0] if len(pair) == 2 else math.nan


def _kind(order: float) -> str:
    return ("converging" if order >= CONVERGING_ORDER else "a floor" if order < FLOOR_ORDER
            else "between a floor and converging")


def _same_motion(rows: list[dict], study: list[dict]) -> bool:
    base = {num(r, "h"): num(r, "nodes_L1") for r in study}
    shared = [(num(r, "nodes_L1"), base[num(r, "h")]) for r in rows if num(r, "h") in base]
    return bool(shared) and all(math.isfinite(a) and math.isfinite(b) and abs(a - b) <= SAME_NODES * abs(b)
                                for a, b in shared)


def _listed(label: str, items: list[str]) -> str:
    return f"{label}: {', '.join(items)}" if items else ""


def _seeded(rows: list[dict]) -> dict[str, dict[str, list[dict]]]:
    """``{variant: {seed: rows}}`` of the jittered layouts."""
    out: dict = {}
    for r in rows:
        if r.get("layout", "regular") != "regular":
            out.setdefault(r["variant"], {}).setdefault(r.get("seed", ""), []).append(r)
    return out


def _seed_pair(seeds: dict[str, list[dict]]) -> tuple[float, float] | None:
    """The finest two meshes every seed ran."""
    common = set.intersection(*({num(r, "h") for r in _ok(rows)} for rows in seeds.values())) if seeds else set()
    return tuple(sorted(common, reverse=True)[-2:]) if len(common) >= 2 else None


def mechanism(tables) -> str:
    """The sentence of C11's explanation, formatted from ``tables["drift/drift"]`` (module docstring)."""
    rows = tables.get(DRIFT.name) or []
    regular = [r for r in rows if r.get("layout", "regular") == "regular"]
    names = list(dict.fromkeys(r["variant"] for r in regular))
    if STUDY not in names:
        return f"not measured: no {STUDY} rows on the regular layout in {DRIFT.name}"
    series = {n: select(regular, variant=n) for n in names}
    study_ok = _ok(series[STUDY])
    if len(study_ok) < 2:
        return f"not measured: {STUDY} ran on fewer than two meshes of {DRIFT.name}"
    coarse, fine = study_ok[-2:]
    hs = (num(coarse, "h"), num(fine, "h"))
    seeded = _seeded(rows)
    spreads = []
    for seeds in seeded.values():
        p = [q for q in (_order(s, hs) for s in seeds.values()) if math.isfinite(q)]
        if len(p) >= 2:
            spreads.append(max(p) - min(p))
    band = max(spreads, default=0)
    measured = {n: (_ok(series[n])[-2:], _order(series[n], hs)) for n in names}
    measured = {n: (pair, order) for n, (pair, order) in measured.items() if math.isfinite(order)}
    _, p_study = measured[STUDY]
    drift = {n: num(pair[-1], "volume_drift") for n, (pair, _) in measured.items()}
    resolution = (f"a growth counts below {GROWTH_ORDER - band:.2f}, the spread of an order over the jittered seeds"
                  if spreads else "one layout, no spread over seeds in the table")
    grows = p_study < GROWTH_ORDER - band
    head = (f"On the regular layout, with the {STUDY} the particle density L1 error "
            f"{'grows' if grows else 'does not grow'} over the finest meshes (order {p_study:.2f} from "
            f"h = {coarse['h']} to {fine['h']}, {resolution}; volume drift {drift[STUDY]:.2g} at h = {fine['h']})")
    others = [n for n in names if n != STUDY and n in measured]
    not_run = [n for n in names if n != STUDY and n not in measured]

    def item(n: str, kind: bool = False) -> str:
        p = measured[n][1]
        return f"{n} ({p:.2f}{', ' + _kind(p) if kind else ''}; drift {drift[n]:.2g})"

    if not grows:
        text = f"{head}: no growth to remove; {_listed('orders of the other variants', [item(n) for n in others])}."
    else:
        removes = [n for n in others if measured[n][1] >= GROWTH_ORDER - band]
        reduces = [n for n in others if n not in removes and measured[n][1] >= REDUCED * p_study]
        leaves = [n for n in others if n not in removes and n not in reduces]
        parts = [_listed("removed by", [item(n, True) for n in removes]),
                 _listed(f"reduced (still growing, at most {REDUCED:.0%} of the {STUDY}' rate) by",
                         [item(n) for n in reduces]),
                 _listed("not reduced by", [item(n) for n in leaves])]
        text = f"{head}; " + "; ".join(p for p in parts if p) + "."
        if removes:
            lo, rest = max(abs(drift[n]) for n in removes), min(abs(drift[n]) for n in [STUDY] + reduces + leaves)
            text += (f" The volume drift separates them: |drift| at most {lo:.2g} where the growth is removed, at "
                     f"least {rest:.2g} where it is not." if lo < rest else
                     f" The volume drift does not separate them: |drift| up to {lo:.2g} where the growth is "
                     f"removed, down to {rest:.2g} where it is not.")
        else:
            text += " No variant removes the growth."
    if not_run:
        text += f" Not on these two meshes: {', '.join(not_run)}."
    return " ".join(s for s in (text, _jittered(seeded), _motion(names, series)) if s)


def _jittered(seeded: dict[str, dict[str, list[dict]]]) -> str:
    """The clause of the jittered layouts (module docstring); empty without the study settings' seeds."""
    pair = _seed_pair(seeded.get(STUDY, {}))
    if pair is None:
        return ""
    ranges, drifts = {}, {}
    for n, seeds in seeded.items():
        p = [_order(rows, pair) for rows in seeds.values()]
        if len(p) >= 2 and all(math.isfinite(q) for q in p):
            ranges[n] = (min(p), max(p))
            drifts[n] = [num(r, "volume_drift") for rows in seeds.values() for r in rows if num(r, "h") == pair[1]]
    if STUDY not in ranges:
        return ""

    def status(n: str) -> str:
        lo, hi = ranges[n]
        return ("grows on every seed" if hi < GROWTH_ORDER else "grows on no seed" if lo >= GROWTH_ORDER
                else "grows on some seeds")

    n_seeds = len(seeded[STUDY])
    items = [f"{n} {span(ranges[n])} ({status(n)}; drift {span(drifts[n], '.2g')})" for n in ranges]
    text = (f"On {n_seeds} jittered layouts, orders from h = {pair[0]:g} to {pair[1]:g}: {', '.join(items)}")
    if status(STUDY) == "grows on no seed":
        return text + ": no growth to remove."
    if status(STUDY) != "grows on every seed":
        return text + f": the {STUDY}' growth is not resolved over seeds (some grow, some do not)."
    s_hi = ranges[STUDY][1]
    removes = [n for n in ranges if n != STUDY and status(n) == "grows on no seed"]
    reduces = [n for n in ranges if n != STUDY and status(n) == "grows on every seed"
               and ranges[n][0] >= REDUCED * s_hi]
    found = "; ".join(p for p in (_listed("removed on every seed by", removes),
                                  _listed(f"reduced on every seed (at most {REDUCED:.0%} of the {STUDY}' slowest "
                                          "seed) by", reduces)) if p)
    text += f"; {found}." if found else "; no seeded variant removes or reduces it."
    s_low = min(abs(d) for d in drifts[STUDY])
    flat = [n for n in ranges if n != STUDY and status(n) == "grows on every seed"
            and max(abs(d) for d in drifts[n]) < s_low]
    if flat:
        text += (f" There the growth outlasts the drift: {', '.join(flat)} grows on every seed at |drift| at most "
                 f"{max(abs(d) for n in flat for d in drifts[n]):.2g}, below the {STUDY}' least {s_low:.2g}.")
    return text


def _motion(names: list[str], series: dict[str, list[dict]]) -> str:
    same = [n for n in names if n != STUDY and _same_motion(series[n], series[STUDY])]
    return (f"The nodal density error is the {STUDY}' within {SAME_NODES:.1%} on every mesh with "
            f"{', '.join(same)}: these change the particle density, not the motion." if same else "")
