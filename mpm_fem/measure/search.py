"""Bracketed, converging searches for continuous settings, to a stated tolerance.

A setting the source leaves unsaid (a time-step constant, an exact solution's parameter) is fitted,
never read off a coarse grid: :func:`bracketed` evaluates ``f`` on a coarse grid only to bracket the
least value (the best grid point and its two neighbours), then minimises ``f`` inside that bracket by
bounded Brent (``scipy.optimize.minimize_scalar(method="bounded")``) until the step is below ``xtol``;
:func:`fit_scalar` is that Brent step on given bounds; :func:`coordinate_fit` cycles such fits over
several coordinates until a whole pass lowers the least value by less than ``ftol``.

A coordinate may be searched in ``ln x`` (``log``): then ``xtol`` is relative (``0.02``: 2 %).
Every evaluation is memoised on the point (a point tried twice is evaluated once), so a search's cost
is the number of distinct points it tried (``Fit.evaluations``). Pure: ``f`` is any callable
``dict -> float`` (``float -> float`` for :func:`fit_scalar`); ``inf`` marks a failed point.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

from scipy.optimize import minimize_scalar


@dataclass(frozen=True)
class Fit:
    """A search's result: the least point ``x`` (a float, or ``{coordinate: value}``), ``value = f(x)``
    and ``evaluations``, the number of distinct points ``f`` was evaluated at."""

    x: object
    value: float
    evaluations: int


class _Memo:
    """``f`` memoised on its argument (rounded to 12 significant digits), counting distinct points."""

    def __init__(self, f: Callable):
        self.f, self.seen = f, {}

    def __call__(self, x):
        key = tuple(sorted((k, float(f"{v:.12g}")) for k, v in x.items())) if isinstance(x, Mapping) \
            else float(f"{x:.12g}")
        if key not in self.seen:
            value = float(self.f(x))
            self.seen[key] = value if math.isfinite(value) else math.inf
        return self.seen[key]


def _check_bounds(lo: float, hi: float, xtol: float, log: bool) -> None:
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise ValueError(f"a search needs finite bounds lo < hi, got [{lo}, {hi}]")
    if not xtol > 0:
        raise ValueError(f"a search needs a positive tolerance, got {xtol}")
    if log and lo <= 0:
        raise ValueError(f"a search in ln x needs positive bounds, got [{lo}, {hi}]")


def fit_scalar(f: Callable[[float], float], lo: float, hi: float, xtol: float, log: bool = False) -> Fit:
    """The least value of ``f`` on ``[lo, hi]`` by bounded Brent to the step ``xtol`` (in ``ln x`` when
    ``log``); the bounds themselves are evaluated too, so that a least value at an end is found."""
    _check_bounds(lo, hi, xtol, log)
    g = f if isinstance(f, _Memo) else _Memo(f)
    to_x = math.exp if log else float
    a, b = (math.log(lo), math.log(hi)) if log else (lo, hi)
    before = len(g.seen)
    res = minimize_scalar(lambda u: g(to_x(u)), bounds=(a, b), method="bounded", options={"xatol": xtol})
    candidates = [(g(to_x(float(res.x))), to_x(float(res.x))), (g(lo), lo), (g(hi), hi)]
    value, x = min(candidates, key=lambda c: c[0])
    return Fit(x, value, len(g.seen) - before)


def bracketed(f: Callable[[float], float], grid: Sequence[float], xtol: float, log: bool = False) -> Fit:
    """The least value of ``f``: ``grid`` (increasing, at least three points) brackets it (its best
    point and the two neighbours, the end point at an end), then :func:`fit_scalar` refines it inside
    the bracket to ``xtol``."""
    grid = [float(x) for x in grid]
    if len(grid) < 3 or any(b <= a for a, b in zip(grid, grid[1:], strict=False)):
        raise ValueError(f"a bracketing grid needs three increasing points at least, got {grid}")
    g = f if isinstance(f, _Memo) else _Memo(f)
    before = len(g.seen)
    values = [g(x) for x in grid]
    k = min(range(len(grid)), key=values.__getitem__)
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)]
    fit = fit_scalar(g, lo, hi, xtol, log)
    if values[k] < fit.value:
        fit = Fit(grid[k], values[k], 0)
    return Fit(fit.x, fit.value, len(g.seen) - before)


@dataclass(frozen=True)
class Coordinate:
    """One coordinate of :func:`coordinate_fit`: its bounds, tolerance ``xtol`` and whether it is
    searched in ``ln x``."""

    lo: float
    hi: float
    xtol: float
    log: bool = False


def coordinate_fit(f: Callable[[dict], float], start: Mapping[str, float], coordinates: Mapping[str, Coordinate],
                   ftol: float, passes: int = 3, order: Sequence[str] | None = None) -> Fit:
    """The least value of ``f`` over the ``coordinates`` (the other keys of ``start`` held), by cycles
    of :func:`fit_scalar` over one coordinate at a time, in ``order`` (default: that of ``coordinates``),
    from ``start``; it stops when a whole pass lowers the least value by less than ``ftol``, or after
    ``passes`` passes."""
    if not ftol > 0 or passes < 1:
        raise ValueError(f"a coordinate search needs ftol > 0 and a pass at least, got {ftol}, {passes}")
    g = _Memo(f)
    x = dict(start)
    value = g(x)
    for _ in range(passes):
        before = value
        for name in order or list(coordinates):
            c = coordinates[name]
            fit = fit_scalar(lambda v, name=name, x=x: g({**x, name: v}), c.lo, c.hi, c.xtol, c.log)
            if fit.value <= value:
                x, value = {**x, name: fit.x}, fit.value
        if before - value < ftol:
            break
    return Fit(x, value, len(g.seen))
