"""``mpm-fem method``: a researcher's basis measured beside the package's, its verdicts
M1-M3 read from its tables (each flipped by a perturbed table), and the command's refusals."""

from __future__ import annotations

import json

import pytest

from mpm_fem.app.cli import main
from mpm_fem.bases import plugins, registry
from mpm_fem.measure.claims.base import CONFIRMED, NOT_MEASURED, PARTLY, REFUTED
from mpm_fem.measure.claims.method import acceleration, budget_section, convergence
from studies import method


@pytest.fixture(autouse=True)
def own_registry(monkeypatch):
    monkeypatch.setattr(registry, "_BASES", dict(registry._BASES))
    monkeypatch.setattr(plugins.LOADER, "loaded", {})


def _projection(mean, lo, hi):
    return [{"basis": "b", "layout": "jittered", "quantity": "E_a", "mean": mean, "lo": lo, "hi": hi, "runs": 3}]


def _orders(*pairs, failed=0):
    return [{"basis": "b", "problem": "sod", "h_coarse": 0.02 / 2**k, "h_fine": 0.01 / 2**k, "mean": m, "lo": lo,
             "hi": hi, "runs": 3, "failed": failed} for k, (m, lo, hi) in enumerate(pairs)]


def test_m1_reads_the_jittered_acceleration_order():
    assert acceleration(_projection(-0.07, -0.15, -0.03), "b")[0] == REFUTED  # the hats' C8 finding
    assert acceleration(_projection(0.9, 0.75, 1.0), "b")[0] == CONFIRMED
    assert acceleration(_projection(0.75, 0.5, 1.0), "b")[0] == PARTLY
    assert acceleration(_projection(0.9, 0.75, 1.0), "other")[0] == NOT_MEASURED


def test_m2_reads_every_pair_of_meshes_and_every_run():
    assert convergence(_orders((0.9, 0.8, 1.0), (0.85, 0.75, 0.9)), "b", "sod")[0] == CONFIRMED
    partly = convergence(_orders((0.9, 0.8, 1.0), (0.3, -0.2, 0.6)), "b", "sod")
    assert partly[0] == PARTLY and "grows on 1 pairs" in partly[1]
    assert convergence(_orders((0.6, 0.5, 0.7), (0.3, 0.1, 0.5)), "b", "sod")[0] == REFUTED
    assert convergence(_orders((0.9, 0.8, 1.0), failed=2), "b", "sod")[0] == NOT_MEASURED
    assert convergence(_orders((0.9, 0.8, 1.0)), "b", "burgers")[0] == NOT_MEASURED


def test_the_tables_take_the_order_of_each_run_between_successive_meshes():
    cases = [{"kind": "run", "problem": "sod", "basis": "b", "h": h, "seed": s} for h in (0.02, 0.01) for s in (0, 1)]
    results = [{"ok": True, "errors": {"particles": {"L1": e}, "nodes": {"L1": e}}} for e in (0.04, 0.08, 0.01, 0.04)]
    (row,) = method.tables(cases, results)["orders"]
    assert (row["h_coarse"], row["h_fine"], row["runs"]) == (0.02, 0.01, 2)
    assert (row["lo"], row["hi"]) == pytest.approx((1.0, 2.0)) and row["mean"] == pytest.approx(1.5)


def test_a_small_plan_measures_a_copy_of_the_hats_as_the_hats(monkeypatch, tmp_path):
    monkeypatch.setattr(method, "OURS", ("mpm",))
    monkeypatch.setitem(method.PLAN, "quick", {"cells": (20, 40), "seeds": (1, 2), "runs": (0, 1),
                                               "h": {"sod": (0.05, 0.025), "burgers": (0.08, 0.04)},
                                               "budget": {"burgers": 0.08}})
    assert main(["method", "plugin_bases:Hats", "--out", str(tmp_path), "--jobs", "1", "--quiet"]) == 0
    page = (tmp_path / "method" / "hats" / "METHOD.md").read_text()
    for claim in ("M1", "M2", "M3"):  # the same verdict and numbers for the copy and the hats, claim by claim
        section = page.split(f"## {claim}")[1].split("##")[0]
        table = [line.split("|") for line in section.splitlines() if line.startswith("| ") and "basis" not in line]
        (hats, mpm) = (cells[2:4] for cells in table)
        assert table[0][1].strip() == "**hats**" and hats == mpm, (claim, hats, mpm)
    orders = (tmp_path / "method" / "hats" / "orders.csv").read_text().splitlines()
    assert len(orders) == 1 + 2 * 2  # (hats, mpm) x (sod, burgers), one pair of meshes each
    assert json.loads((tmp_path / "method" / "hats" / "orders.json").read_text())["settings"]["spec"] == \
        "plugin_bases:Hats"
    budget = page.split("## The error budget")[1]
    (mpm,) = [line for line in budget.splitlines() if line.startswith("| mpm | 0.08 |")]
    shares = [float(cell.strip(" %")) for cell in mpm.split("|")[5:9]]
    assert abs(sum(shares) - 100) <= 2 and len(shares) == 4, mpm  # four stages' shares of the gap, rounded
    # the numpy-only copy's budget (numpy step, exact stages on its numpy rows) is P1's, cell for cell
    (hats,) = [line for line in budget.splitlines() if line.startswith("| **hats** | 0.08 |")]
    assert hats.split("|")[3:] == mpm.split("|")[3:], (hats, mpm)


def _budget_case(basis, problem, subsets):
    return ({"kind": "budget", "problem": problem, "h": 0.04, "basis": basis},
            {"ok": True, "subsets": {"particles": subsets}})


def test_the_budget_table_is_the_budget_studys_shapley_decomposition():
    from studies.budget import STAGES, label, subsets

    # v(S) = 1 + 3 [projection in S] + 1 [time in S]: projection holds 3/4 of the gap, time 1/4, no interaction
    values = {label(S): 1.0 + 3.0 * ("projection" in S) + 1.0 * ("time" in S) for S in subsets(STAGES)}
    rows = method.budget_rows([_budget_case("b", "burgers", values),
                               ({"kind": "budget", "problem": "burgers", "h": 0.04, "basis": "c"},
                                {"ok": False, "error": "a particle left the grid"})])
    share = {r["stage"]: r["share"] for r in rows if r["ok"]}
    assert share == pytest.approx({"projection": 0.75, "mass": 0.0, "interpolation": 0.0, "time": 0.25})
    assert {r["mpm_error"] for r in rows if r["ok"]} == {5.0} and {r["exact_error"] for r in rows if r["ok"]} == {1.0}
    page = "\n".join(budget_section(rows, ("b", "c")))
    assert "| **b** | 0.04 | 5 | 1 | 75 % | 0 % | 0 % | 25 % |" in page, page
    assert "| c | 0.04 | not measured: a particle left the grid |" in page


def test_a_basis_that_breaks_its_contract_is_refused_before_any_case(tmp_path, capsys):
    assert main(["method", "plugin_bases:Heavy", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip()
    assert "no partition of unity" in err and "\n" not in err
    assert not (tmp_path / "method").exists()
