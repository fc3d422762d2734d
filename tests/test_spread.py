"""The spread over seeds (mpm_fem/measure/spread.py): mean and range of values, the order paired by
seed and its range, and a threshold counted only when the whole range lies on one side of it."""

from __future__ import annotations

import math

import pytest

from mpm_fem.measure.spread import NONE, Spread, by_mesh, order_spread, order_spreads, spread


def test_spread_is_the_mean_and_range_of_the_finite_values():
    assert spread([1.0, 3.0, math.nan, 2.0]) == Spread(2.0, 1.0, 3.0, 3)
    assert spread([]) is NONE and spread([math.nan]).n == 0
    assert spread([0.25, 0.5]).text() == "0.38 [0.25, 0.50]" and NONE.text() == "-"


def test_a_threshold_counts_only_when_the_whole_range_is_on_one_side():
    s = Spread(0.6, 0.4, 0.8, 5)
    assert s.above(0.4) and not s.above(0.5) and s.below(0.9) and not s.below(0.8)
    assert not NONE.above(-math.inf) and not NONE.below(math.inf)


def test_the_order_is_paired_by_seed_over_the_seeds_run_on_both_meshes():
    coarse = {0: 0.04, 1: 0.08, 2: 0.02, 3: 1.0}
    fine = {0: 0.01, 1: 0.04, 2: 0.02, 4: 1.0}  # seed 0 converges at order 2, seed 1 at 1, seed 2 not at all
    s = order_spread(0.2, coarse, 0.1, fine)
    assert (s.n, s.lo, s.hi) == (3, pytest.approx(0.0), pytest.approx(2.0)) and s.mean == pytest.approx(1.0)
    assert order_spread(0.2, {0: 0.0}, 0.1, {0: 1.0}) is NONE  # no positive pair: no order


def test_orders_from_rows_as_read_from_a_csv():
    rows = [{"h": str(h), "seed": str(k), "e": str(h ** (1 + 0.1 * k))} for h in (0.1, 0.05, 0.025) for k in range(3)]
    rows.append({"h": "0.025", "seed": "3", "e": ""})  # a failed run: NaN, left out
    assert list(by_mesh(rows, "e")) == [0.1, 0.05, 0.025]
    found = order_spreads(rows, "e")
    assert [(a, b) for a, b, _ in found] == [(0.1, 0.05), (0.05, 0.025)]
    assert all((s.n, s.lo, s.hi) == (3, pytest.approx(1.0), pytest.approx(1.2)) for _, _, s in found)
