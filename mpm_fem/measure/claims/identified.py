"""The claims judged at the identified settings, from ``identification/identified``.

The identification (``studies/identification.py``) reruns the best candidate of each problem on the
regular layout and the jittered layouts of its seeds. Two readings of those runs:

- **C11 (nodes)**: the source's plateau, at the nodes, at the identified Sod setting. The source's own
  L1 column says where it converges and where it levels: a step between successive meshes whose source
  order is at least ``CONVERGING_ORDER`` converges, one below ``FLOOR_ORDER`` levels. Per seed the
  measured orders on those steps: every seed converging where the source converges and levelling (below
  ``FLOOR_ORDER``, not below ``GROWTH_ORDER``) where it levels -> confirmed; every seed still converging
  (at least ``CONVERGING_ORDER``) or growing (below ``GROWTH_ORDER``) on every levelling step -> differs;
  else partly. Fewer than ``MIN_RUNS`` runs on a mesh, or no levelling step among the meshes -> not
  measured. (The particle error at the source's 4-8 per cell is C11 of the Sod study.)
- :func:`burgers_orders`: the least-squares order of each identified Burgers run (one series per
  source row, layout, seed and eps) that C13 judges (:mod:`.burgers`).
"""

from __future__ import annotations

import math

from mpm_fem.measure.claims.base import CONFIRMED, DIFFERS, NOT_MEASURED, PARTLY, Finding, Tables, claim, short
from mpm_fem.measure.claims.rows import CONVERGING_ORDER, FLOOR_ORDER, GROWTH_ORDER, num, span
from mpm_fem.measure.claims.rules import rule
from mpm_fem.measure.errors import fitted_order
from mpm_fem.measure.source import SOD

IDENTIFIED = "identification/identified"
MIN_RUNS = int(rule("MIN_RUNS"))


def _series(rows: list[dict], **where) -> dict[tuple, dict[float, float]]:
    """``{(layout, seed, eps): {h: error}}`` of the rows matching ``where``."""
    out: dict[tuple, dict[float, float]] = {}
    for r in rows:
        if all(str(r.get(k)) == str(v) for k, v in where.items()):
            out.setdefault((r["layout"], str(r["seed"]), str(r.get("eps", ""))), {})[num(r, "h")] = num(r, "error")
    return out


def _step_order(errors: dict[float, float], coarse: float, fine: float) -> float:
    a, b = errors.get(coarse, math.nan), errors.get(fine, math.nan)
    return math.log(a / b) / math.log(coarse / fine) if a > 0 and b > 0 else math.nan


def source_steps(meshes: list[float]) -> dict[str, list[tuple[float, float]]]:
    """The steps between successive ``meshes`` (coarsest first) by what the source's L1 column does on
    them: ``converges`` (order >= CONVERGING_ORDER), ``levels`` (order < FLOOR_ORDER)."""
    steps = {"converges": [], "levels": []}
    for a, b in zip(meshes, meshes[1:], strict=False):
        o = math.log(SOD[a][0] / SOD[b][0]) / math.log(a / b)
        if o >= CONVERGING_ORDER:
            steps["converges"].append((a, b))
        elif o < FLOOR_ORDER:
            steps["levels"].append((a, b))
    return steps


def nodal_plateau(rows: list[dict]) -> Finding:
    """C11 (nodes) from the Sod rows of ``identification/identified`` (module docstring)."""
    series = _series(rows, problem="sod", readout="nodes", norm="L1")
    meshes = sorted({h for s in series.values() for h in s}, reverse=True)
    runs = {h: sum(math.isfinite(s.get(h, math.nan)) for s in series.values()) for h in meshes}
    steps = source_steps(meshes)
    setting = next((r["setting"] for r in rows if r.get("problem") == "sod"), "")
    if not steps["levels"] or any(n < MIN_RUNS for n in runs.values()):
        return Finding(NOT_MEASURED, f"at {setting or 'no identified setting'}: {len(series)} runs on "
                       f"{len(meshes)} meshes, levelling steps of the source among them: {len(steps['levels'])}")
    orders = {kind: {step: [_step_order(s, *step) for s in series.values()] for step in found}
              for kind, found in steps.items()}
    converging = all(o >= CONVERGING_ORDER for v in orders["converges"].values() for o in v)
    levelling = all(GROWTH_ORDER <= o < FLOOR_ORDER for v in orders["levels"].values() for o in v)
    no_plateau = all(o >= CONVERGING_ORDER or o < GROWTH_ORDER for v in orders["levels"].values() for o in v)
    verdict = CONFIRMED if converging and levelling else DIFFERS if no_plateau else PARTLY
    ratios = [num(r, "ratio") for r in rows if r.get("problem") == "sod" and r["readout"] == "nodes"
              and r["norm"] == "L1"]
    text = lambda found: "; ".join(f"h = {a:g} -> {b:g}: {span(v)}" for (a, b), v in found.items())  # noqa: E731
    table = tuple({"step": f"{a:g} -> {b:g}", "source": kind, "source order":
                   f"{math.log(SOD[a][0] / SOD[b][0]) / math.log(a / b):.2f}", "measured orders over the runs": span(v)}
                  for kind, found in orders.items() for (a, b), v in found.items())
    evidence = (f"at {setting} over {len(series)} runs (the regular layout and the jittered seeds): where the source "
                f"converges {text(orders['converges'])}; where it levels {text(orders['levels'])}; nodal density L1 / "
                f"source {span(ratios)} on {len(meshes)} meshes")
    where = "levels off where the source's does" if verdict == CONFIRMED else (
        "keeps converging (or grows) where the source's levels" if verdict == DIFFERS
        else "levels off on some runs only")
    level_orders = [o for v in orders["levels"].values() for o in v]
    hits = sum(GROWTH_ORDER <= o < FLOOR_ORDER for o in level_orders)
    sentence = (f"at the identified Sod setting ({setting}) the nodal density error {where}, {span(ratios)} times "
                f"the source's: it levels on {hits} of {len(level_orders)} runs and levelling steps")
    key = short(f"at the identified Sod setting the nodal density error levels on {hits} of {len(level_orders)} runs "
                f"and steps, {span(ratios)}x the source's")
    return Finding(verdict, evidence, sentence, table, key=key)


@claim("C11", source="the density error levels off near 0.0011 from h = 0.000625 (the source's L1 column)",
       tables=(IDENTIFIED,), study="identification", problem="nodes",
       thresholds=f"at the identified Sod setting, over the regular and the jittered layouts (at least {MIN_RUNS} "
                  f"runs a mesh), the nodal density's L1 orders between successive meshes: on the steps where the "
                  f"source's order is at least {CONVERGING_ORDER} every run's too, and on those where it is below "
                  f"{FLOOR_ORDER} every run's in [{GROWTH_ORDER:g}, {FLOOR_ORDER}) -> {CONFIRMED}; every run's order "
                  f"on every levelling step at least {CONVERGING_ORDER} or below {GROWTH_ORDER:g} -> {DIFFERS}; else "
                  f"{PARTLY}")
def _c11_nodes(t: Tables) -> Finding:
    """The plateau the source's table shows is the nodal density's (the identification matches it there);
    it is reproduced only if every seed levels where the source levels."""
    return nodal_plateau(t[IDENTIFIED])


def burgers_orders(rows: list[dict], source_row: str) -> list[float]:
    """The least-squares order of every identified Burgers run of ``source_row`` (one per layout, seed and
    eps over its meshes; a series of fewer than two meshes is left out)."""
    out = []
    for errors in _series(rows, problem="burgers", source_row=source_row).values():
        hs = [h for h, e in errors.items() if e > 0 and math.isfinite(e)]
        if len(hs) >= 2:
            out.append(fitted_order(hs, [errors[h] for h in hs]))
    return out
