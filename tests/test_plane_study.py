"""The 2D study's plan and tables (``studies/plane.py``): the tiers' cases and cost, and the budget's
decomposition from its runs."""

from __future__ import annotations

import importlib

import pytest

from mpm_fem.measure.decomposition import label, subsets

plane = importlib.import_module("studies.plane")


def test_the_full_tier_adds_at_most_thirty_cpu_minutes_and_the_quick_one_seconds():
    for tier, limit in (("full", 30 * 60), ("quick", 10)):
        cases = {repr(sorted(c.items())): c for g in plane.plan(tier).values() for c in g.values()}
        seconds = sum(plane.cost(c) for c in cases.values())
        assert seconds <= limit, (tier, seconds)


def test_the_quick_tier_is_numpy_p1_on_two_meshes_and_two_layouts():
    growth = plane.plan("quick")["growth"]
    assert {c["basis"] for c in growth.values()} == {"mpm"}
    assert not any(c["compiled"] for c in growth.values())
    assert len({c["h"] for c in growth.values()}) == 2 and len({c["seed"] for c in growth.values()}) == 2


def test_the_full_tier_runs_the_compiled_step_where_it_serves_and_the_numpy_step_elsewhere():
    p = plane.plan("full")
    assert all(c["compiled"] for c in p["growth"].values())
    assert not any(c["compiled"] for c in p["stages"].values() if c.get("projection") == "exact")
    assert not any(c["compiled"] for c in p["mass"].values() if c["mass"] != "lumped")


def test_the_budget_runs_every_subset_and_its_shares_add_up_to_the_gap():
    stages = plane.STAGES
    values = {label(S): 1.0 + 0.5 * ("projection" in S) + 0.25 * ("mass" in S) + 0.1 * len(S) ** 2
              for S in subsets(stages)}
    got = {("axis-0.05", 0.125, name): {"ok": True, "L2": v} for name, v in values.items()}
    rows, shapley = plane.budget_rows(got)
    assert len(rows) == 16 and len(shapley) == 4
    assert sum(r["share"] for r in shapley) == pytest.approx(1.0)
    assert shapley[0]["interactions_share"] > 0  # the len(S)^2 term interacts
    assert plane.plan("full")["budget"].keys() >= {("axis-1e-4", 0.125, label(S)) for S in subsets(stages)}
