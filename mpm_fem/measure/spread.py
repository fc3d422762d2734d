"""The spread of a measurement over seeds: its mean and range, and the interval of an observed order.

A study repeats a run ``n`` times, changing only a random choice (the seed of a particle layout:
``seed = 0`` the regular layout, ``1, 2, ...`` jittered ones). Over the runs

    a value (an error)   mean = (1/n) sum_k E_k,              interval [min_k E_k, max_k E_k]
    an observed order    p_k = log(E_k(h_1) / E_k(h_2)) / log(h_1 / h_2)   for each seed k run on
                         both meshes h_1 > h_2;   mean = (1/n) sum_k p_k,   interval [min_k p_k, max_k p_k]

(:func:`spread`, :func:`order_spread`; over the rows of a table with one row per run,
:func:`by_mesh` and :func:`order_spreads`). An order is paired by seed, so runs of different layouts can
be pooled: each seed contributes the order of its own layout, and the interval holds the order of
every layout run. A verdict counts a value as above (below) a threshold only when its whole interval
is (:meth:`Spread.above`, :meth:`Spread.below`); otherwise the interval straddles the threshold and
the runs do not decide. NaN values (a failed run) are left out; a spread of no value is NaN
throughout with ``n = 0``, and neither above nor below anything. No project imports.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass


@dataclass(frozen=True)
class Spread:
    """``mean`` of ``n`` finite values and their range ``[lo, hi]`` (``lo <= mean <= hi``)."""

    mean: float
    lo: float
    hi: float
    n: int

    def above(self, threshold: float) -> bool:
        """Every value is at least ``threshold`` (``lo >= threshold``); false when ``n = 0``."""
        return self.n > 0 and self.lo >= threshold

    def below(self, threshold: float) -> bool:
        """Every value is below ``threshold`` (``hi < threshold``); false when ``n = 0``."""
        return self.n > 0 and self.hi < threshold

    def text(self, fmt: str = ".2f") -> str:
        """``"mean [lo, hi]"`` (``"-"`` when ``n = 0``)."""
        if self.n == 0:
            return "-"
        return f"{self.mean:{fmt}} [{self.lo:{fmt}}, {self.hi:{fmt}}]"


NONE = Spread(math.nan, math.nan, math.nan, 0)


def spread(values: Iterable[float]) -> Spread:
    """Mean and range of the finite ``values``."""
    v = [float(x) for x in values if math.isfinite(float(x))]
    if not v:
        return NONE
    return Spread(sum(v) / len(v), min(v), max(v), len(v))


def order_spread(h1: float, errors1: Mapping, h2: float, errors2: Mapping) -> Spread:
    """The spread of the observed order between meshes ``h1 > h2`` over the seeds run on both:
    ``errors1`` and ``errors2`` map a seed to its error on each mesh (module docstring); a seed
    with a non-positive or non-finite error on either mesh is left out."""
    scale = math.log(h1 / h2)
    orders = []
    for seed in sorted(errors1.keys() & errors2.keys(), key=repr):
        a, b = float(errors1[seed]), float(errors2[seed])
        if a > 0 and b > 0 and math.isfinite(a) and math.isfinite(b):
            orders.append(math.log(a / b) / scale)
    return spread(orders)


def _float(value) -> float:
    try:
        return float(value)
    except (TypeError, ValueError):
        return math.nan


def by_mesh(rows: Iterable[Mapping], key: str, mesh: str = "h", seed: str = "seed") -> dict[float, dict]:
    """``{h: {seed: value}}`` of column ``key`` over ``rows``, one row per run (numbers, or strings as
    read from a CSV; an empty or non-numeric value is NaN), the meshes in decreasing order."""
    out: dict[float, dict] = {}
    for row in rows:
        out.setdefault(_float(row[mesh]), {})[row[seed]] = _float(row.get(key, ""))
    return dict(sorted(out.items(), reverse=True))


def order_spreads(rows: Iterable[Mapping], key: str, mesh: str = "h", seed: str = "seed") -> list[tuple]:
    """``[(h_1, h_2, Spread)]``: the order of column ``key`` between each pair of successive meshes
    of ``rows`` (decreasing ``h``), over the seeds run on both (:func:`order_spread`)."""
    meshes = by_mesh(rows, key, mesh, seed)
    hs = list(meshes)
    return [(a, b, order_spread(a, meshes[a], b, meshes[b])) for a, b in zip(hs[:-1], hs[1:], strict=True)]
