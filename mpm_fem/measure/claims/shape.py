"""C11's shape test: the source's Sod table has a shape (the error at the coarsest mesh of a given size,
converging orders, then a levelling), and a measured series of one setting and one quantity is read
against it over the seeds.

An order between two meshes is a :class:`~mpm_fem.measure.spread.Spread` over the runs (the regular
layout and the jittered seeds, paired by seed); it counts as above or below a threshold only when its
whole range is. With ``tail`` the last FLOOR_STEPS orders (the rule book) the shape of a series is

- ``grows``: every order from some refinement on, the tail included, is below GROWTH_ORDER over every
  seed (the error is larger on the finer mesh: a divergence, not a plateau);
- ``levels off``: the first order converging (at least CONVERGING_ORDER) and every tail order below
  FLOOR_ORDER over every seed, not all of them below GROWTH_ORDER (the source's shape);
- ``stalls``: the tail below FLOOR_ORDER but the first order not converging (never the source's start);
- ``converges``: every tail order at least CONVERGING_ORDER;
- ``undecided``: anything else (an order whose range straddles a threshold).

The size test: the error over the source's at the coarsest mesh, over the seeds, within SAME_SIZE.
"""

from __future__ import annotations

import math

from mpm_fem.measure.claims.rows import CONVERGING_ORDER, FLOOR_ORDER, GROWTH_ORDER, num, span
from mpm_fem.measure.claims.rules import rule
from mpm_fem.measure.source import SOD
from mpm_fem.measure.spread import Spread, by_mesh, spread

FLOOR_STEPS, SAME_SIZE = int(rule("FLOOR_STEPS")), rule("SAME_SIZE")
GROWS, LEVELS, STALLS, CONVERGES, UNDECIDED = "grows", "levels off", "stalls", "converges", "undecided"


def shape(orders: list[Spread]) -> str:
    """The shape of a series from its successive orders over the seeds (module docstring)."""
    tail = orders[-FLOOR_STEPS:]
    if not tail:
        return UNDECIDED
    if all(o.below(GROWTH_ORDER) for o in tail):
        return GROWS
    if all(o.above(CONVERGING_ORDER) for o in tail):
        return CONVERGES
    if all(o.below(FLOOR_ORDER) for o in tail):
        return LEVELS if len(orders) > len(tail) and orders[0].above(CONVERGING_ORDER) else STALLS
    return UNDECIDED


def growth_start(orders: list[tuple]) -> float:
    """The coarser mesh of the first refinement from which every order is below GROWTH_ORDER over every
    seed (``orders``: ``[(h_1, h_2, Spread)]``); NaN when the last one is not."""
    start = math.nan
    for h1, _, o in reversed(orders):
        if not o.below(GROWTH_ORDER):
            break
        start = h1
    return start


def size(rows: list[dict], key: str, source_column: int) -> tuple[float, Spread]:
    """``(h, spread)`` of the error ``key`` over the source's (``SOD[h][source_column]``) at the coarsest
    mesh of ``rows`` that the source's table holds, over the runs; ``(NaN, empty)`` without one."""
    runs = {h: r for h, r in by_mesh(rows, key).items() if h in SOD}
    if not runs:
        return math.nan, spread(())
    h = max(runs)
    return h, spread(v / SOD[h][source_column] for v in runs[h].values())


def same_size(ratio: Spread) -> bool:
    """The ratio to the source lies within [1/SAME_SIZE, SAME_SIZE] over every run."""
    return ratio.above(1 / SAME_SIZE) and ratio.below(SAME_SIZE)


def shape_text(found: str, orders: list[tuple]) -> str:
    """``"grows from h = 0.0025 (mean orders 0.18, -0.24, ...)"``: the shape, where a growth starts, and
    the mean orders (their ranges over the seeds are in the evidence)."""
    means = ", ".join(f"{o.mean:.2f}" for _, _, o in orders)
    start = growth_start(orders)
    where = f" from h = {start:g}" if found == GROWS and math.isfinite(start) else ""
    return f"{found}{where} (mean orders {means})"


def misfit(rows: list[dict], column: str) -> float:
    """The mean ``|log ratio|`` of ``column`` over the meshes of ``rows`` (NaN without one)."""
    logs = [abs(math.log(num(r, column))) for r in rows if num(r, column) > 0]
    return sum(logs) / len(logs) if logs else math.nan


def orders_span(orders: list[tuple]) -> str:
    """The mean orders' span, e.g. ``"-0.24..-0.61"`` from the first to the last."""
    return span([o.mean for _, _, o in orders])
