"""Statistics over seeds (:mod:`mpm_fem.measure.seeds`): the spread of an error and of a fitted order
over runs that differ only in their particle layout, and which side of a threshold an interval lies on."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from mpm_fem.measure.seeds import common_meshes, order_spread, side, spread, t_interval

H = (0.01, 0.005, 0.0025, 0.00125)


def _series(order: float, constant: float = 1.0, hs=H) -> dict:
    """Errors ``constant h^order`` on ``hs``: every observed order is ``order``."""
    return {h: constant * h**order for h in hs}


def test_spread_is_the_mean_and_the_range_of_the_finite_values():
    assert spread([1.0, 3.0, float("nan"), 2.0]) == {"n": 3, "mean": 2.0, "lo": 1.0, "hi": 3.0}
    empty = spread([float("nan")])
    assert empty["n"] == 0 and all(math.isnan(empty[k]) for k in ("mean", "lo", "hi"))


def test_t_interval_is_the_student_interval_of_the_mean():
    values = [0.9, 1.1, 1.0, 0.95, 1.05]
    lo, hi = t_interval(values)
    half = stats.t.ppf(0.975, 4) * np.std(values, ddof=1) / math.sqrt(5)
    assert (lo, hi) == pytest.approx((1.0 - half, 1.0 + half))
    assert lo > min(values) and hi < max(values)  # narrower than the range here
    assert all(math.isnan(x) for x in t_interval([1.0]))


def test_each_run_is_fitted_on_its_own_over_the_meshes_every_run_has():
    series = {("regular", 0): _series(1.0), ("jittered", 1): _series(0.5, 3.0), ("jittered", 2): _series(2.0, 0.1)}
    series[("jittered", 2)].pop(H[-1])  # one run lacks the finest mesh: the common meshes stop before it
    s = order_spread(series)
    assert s["runs"] == 3 and s["h"] == list(H[:-1]) == common_meshes(series)
    assert s["fitted"] == pytest.approx({("regular", 0): 1.0, ("jittered", 1): 0.5, ("jittered", 2): 2.0})
    assert (s["mean"], s["lo"], s["hi"]) == pytest.approx((3.5 / 3, 0.5, 2.0))
    assert set(s["pairs"]) == {(H[0], H[1]), (H[1], H[2])}
    assert s["pairs"][(H[0], H[1])]["lo"] == pytest.approx(0.5) and s["pairs"][(H[1], H[2])]["hi"] == pytest.approx(2)
    assert s["t_lo"] < s["mean"] < s["t_hi"]


def test_a_failed_run_or_a_single_mesh_gives_no_order():
    series = {0: _series(1.0), 1: {**_series(1.0), H[1]: float("nan"), H[2]: float("nan"), H[3]: float("nan")}}
    s = order_spread(series)
    assert s["fitted"] == {} and math.isnan(s["lo"]) and s["h"] == [H[0]]


@pytest.mark.parametrize("lo, hi, expected", [
    (0.8, 1.2, "above"), (0.7, 0.9, "above"), (0.1, 0.6, "below"), (0.5, 0.9, "across"),
    (float("nan"), 1.0, "unknown")])
def test_an_interval_counts_on_one_side_only_when_all_of_it_does(lo, hi, expected):
    assert side(lo, hi, 0.7) == expected
