"""Statistics over seeds: the spread of an error and of an observed order over runs that differ only
in their particle layout (the regular one and jittered ones, each from its seed).

A *run* is one layout of one setting; a *series* is the errors of one run on a sequence of meshes,
``{h: E}``. Over the runs of a setting at one mesh, :func:`spread` gives the mean and the range
(min, max) of the error. For an order, each run's series is fitted on its own (the least-squares
slope of ``log E`` against ``log h``, :func:`mpm_fem.measure.errors.fitted_order`), over the meshes
every run has, and :func:`order_spread` gives the mean, the range and the Student-t interval of the
mean of these fitted orders. The range is the interval the claims read: with ``n`` runs it holds
every observed order, so an order counts as above or below a threshold (:func:`side`) only when
every run's order is. No project imports but :mod:`mpm_fem.measure.errors`.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping

import numpy as np
from scipy import stats

from mpm_fem.measure.errors import fitted_order, observed_orders

#: The confidence level of :func:`t_interval`.
LEVEL = 0.95


def _finite(values: Iterable) -> np.ndarray:
    v = np.asarray([float(x) for x in values], float)
    return v[np.isfinite(v)]


def spread(values: Iterable) -> dict:
    """``{"n", "mean", "lo", "hi"}`` of the finite ``values``: their count, mean, min and max (NaN
    when there is none)."""
    v = _finite(values)
    if v.size == 0:
        return {"n": 0, "mean": math.nan, "lo": math.nan, "hi": math.nan}
    return {"n": int(v.size), "mean": float(v.mean()), "lo": float(v.min()), "hi": float(v.max())}


def t_interval(values: Iterable, level: float = LEVEL) -> tuple[float, float]:
    """The Student-t interval of the mean of the finite ``values``: ``mean -+ t_{(1+level)/2, n-1}
    s / sqrt(n)`` with ``s`` the sample standard deviation; ``(nan, nan)`` for fewer than two values."""
    v = _finite(values)
    if v.size < 2:
        return math.nan, math.nan
    half = float(stats.t.ppf(0.5 + level / 2, v.size - 1) * v.std(ddof=1) / math.sqrt(v.size))
    return float(v.mean()) - half, float(v.mean()) + half


def common_meshes(series: Mapping[object, Mapping[float, float]]) -> list[float]:
    """The meshes on which every run of ``series`` (``{run: {h: E}}``) has a positive finite error,
    coarsest first."""
    def valid(by_h):
        return {h for h, e in by_h.items() if math.isfinite(float(e)) and float(e) > 0}

    sets = [valid(by_h) for by_h in series.values()]
    return sorted(set.intersection(*sets), reverse=True) if sets else []


def order_spread(series: Mapping[object, Mapping[float, float]]) -> dict:
    """The orders of ``series`` (``{run: {h: E}}``) over their :func:`common_meshes`: ``runs`` (the
    number of runs), ``h`` (the meshes), ``fitted`` (each run's least-squares order, by run), the
    :func:`spread` of these (``mean``, ``lo``, ``hi``), their :func:`t_interval` (``t_lo``, ``t_hi``),
    and ``pairs``: for each pair of successive meshes ``(h_k, h_{k+1})`` the :func:`spread` of the
    runs' observed orders between them. Fewer than two common meshes: no orders (``fitted`` empty,
    the statistics NaN)."""
    hs = common_meshes(series)
    if len(hs) < 2:
        return {"runs": len(series), "h": hs, "fitted": {}, **spread(()), "t_lo": math.nan, "t_hi": math.nan,
                "pairs": {}}
    errors = {run: [float(by_h[h]) for h in hs] for run, by_h in series.items()}
    fitted = {run: fitted_order(hs, e) for run, e in errors.items()}
    successive = np.array([observed_orders(hs, e) for e in errors.values()])
    t_lo, t_hi = t_interval(fitted.values())
    return {"runs": len(series), "h": hs, "fitted": fitted, **spread(fitted.values()), "t_lo": t_lo, "t_hi": t_hi,
            "pairs": {(a, b): spread(successive[:, k]) for k, (a, b) in enumerate(zip(hs[:-1], hs[1:], strict=True))}}


def side(lo: float, hi: float, threshold: float) -> str:
    """Where the interval ``[lo, hi]`` lies against ``threshold``: ``"above"`` (``lo >= threshold``),
    ``"below"`` (``hi < threshold``), ``"across"`` (it straddles the threshold) or ``"unknown"`` (an
    end is not finite: no interval)."""
    if not (math.isfinite(lo) and math.isfinite(hi)):
        return "unknown"
    return "above" if lo >= threshold else "below" if hi < threshold else "across"
