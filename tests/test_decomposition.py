"""The exact decomposition of the error budget (E1): Moebius terms and Shapley values."""

from itertools import permutations

import numpy as np
import pytest

from mpm_fem.measure.decomposition import decompose, label, shapley_by_orders, subsets

STAGES = ("projection", "mass", "interpolation", "time")


def _from_terms(terms: dict, stages=STAGES) -> dict:
    """v(S) = sum of the terms m(T) over T subset of S."""
    return {S: sum(m for T, m in terms.items() if T <= S) for S in subsets(stages)}


def _known_terms(seed=0) -> dict:
    """Integer main effects and interactions of every order (sums of integers are exact)."""
    rng = np.random.default_rng(seed)
    return {S: float(rng.integers(-50, 50)) for S in subsets(STAGES)}


def test_known_main_effects_and_interactions_are_recovered_exactly():
    terms = _known_terms()
    d = decompose(_from_terms(terms), STAGES)
    assert d.moebius == terms
    want = {s: sum(m / len(S) for S, m in terms.items() if s in S) for s in STAGES}
    for s in STAGES:
        assert d.shapley[s] == pytest.approx(want[s], abs=1e-12)
    assert set(d.interactions()) == {S for S in terms if len(S) >= 2}
    assert len(d.interactions()) == 11


def test_additive_error_gives_main_effects_and_a_pure_interaction_is_split_equally():
    main = {"projection": 3.0, "mass": -1.0, "interpolation": 0.5, "time": 2.0}
    v = {S: 7.0 + sum(main[s] for s in S) for S in subsets(STAGES)}
    d = decompose(v, STAGES)
    assert d.shapley == main
    assert all(m == 0 for m in d.interactions().values())
    pair = {S: (6.0 if {"mass", "time"} <= S else 0.0) for S in subsets(STAGES)}
    d = decompose(pair, STAGES)
    assert d.shapley == {"projection": 0.0, "mass": 3.0, "interpolation": 0.0, "time": 3.0}


def test_the_order_of_the_stages_changes_nothing():
    rng = np.random.default_rng(1)
    v = {S: float(rng.uniform(0.001, 0.02)) for S in subsets(STAGES)}
    first = decompose(v, STAGES)
    by_orders = shapley_by_orders(v, STAGES)
    for order in permutations(STAGES):
        d = decompose(v, order)
        for s in STAGES:
            assert abs(d.shapley[s] - first.shapley[s]) < 1e-17
            assert abs(by_orders[s] - first.shapley[s]) < 1e-17
        assert all(abs(d.moebius[S] - first.moebius[S]) < 1e-17 for S in subsets(STAGES))
        total = sum(d.shapley.values())
        assert abs(total - (v[frozenset(STAGES)] - v[frozenset()])) < 1e-15
        assert sum(d.moebius.values()) == pytest.approx(v[frozenset(STAGES)], rel=1e-14)


def test_field_decomposition_adds_exactly_at_every_point():
    """Signed error fields: the decomposition is taken point by point (the same numbers as the
    scalar decomposition at each point) and the Shapley fields add up to e_MPM - e_exact."""
    rng = np.random.default_rng(2)
    x = np.linspace(0, 1, 301)
    v = {S: rng.normal(size=x.size) * 0.01 + 0.002 * len(S) * np.sin(7 * x) for S in subsets(STAGES)}
    d = decompose(v, STAGES)
    gap = v[frozenset(STAGES)] - v[frozenset()]
    assert np.abs(sum(d.shapley.values()) - gap).max() < 1e-16
    assert np.abs(sum(d.moebius.values()) - v[frozenset(STAGES)]).max() < 1e-16
    for k in (0, 150, 300):
        point = decompose({S: f[k] for S, f in v.items()}, STAGES)
        assert all(point.shapley[s] == pytest.approx(d.shapley[s][k], abs=0) for s in STAGES)


def test_subsets_labels_and_missing_subsets():
    assert len(subsets(STAGES)) == 16
    assert label(frozenset()) == "none"
    assert label({"time", "mass"}) == "mass+time"
    v = {S: 1.0 for S in subsets(STAGES)}
    del v[frozenset({"mass", "time"})]
    with pytest.raises(ValueError, match="missing 1 of the 16 subsets: mass\\+time"):
        decompose(v, STAGES)
    with pytest.raises(ValueError, match="repeat"):
        subsets(("mass", "mass"))
