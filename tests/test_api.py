"""The notebook entry points: ``docs/api.md`` is run as a doctest (its examples are the test)."""

from __future__ import annotations

import doctest
from pathlib import Path

import pytest

import mpm_fem

DOCS = Path(__file__).resolve().parent.parent / "docs" / "api.md"


def test_the_api_page_examples_give_the_numbers_they_show():
    failures, tried = doctest.testfile(str(DOCS), module_relative=False,
                                       optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert tried > 5 and failures == 0


def test_the_entry_points_agree_with_the_solver_and_the_exact_solution():
    run = mpm_fem.sod(h=0.02, ppc=2, T=0.05)
    density = run.particles.density - run.exact["particles"]["density"]
    l1 = float((abs(density) * run.particles.volume).sum())
    assert l1 == pytest.approx(run.errors["density"]["particles"]["L1"], rel=1e-12)
    assert run.nodal["density"].shape == run.nodes.shape == run.exact["nodes"]["density"].shape


def test_a_run_too_large_is_refused_before_it_starts():
    from mpm_fem.app.guard import UsageError

    with pytest.raises(UsageError, match="over the limit|over"):
        mpm_fem.sod(h=1e-7)


def test_an_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'shock'"):
        mpm_fem.shock  # noqa: B018


# --- the page's numbers against the committed tables ---------------------------------------------

FIGURES = Path(__file__).resolve().parent.parent / "figures"


def _shown(fragment: str) -> str:
    """What the page shows for its example whose code holds ``fragment``."""
    examples = doctest.DocTestParser().get_examples(DOCS.read_text())
    (want,) = [e.want for e in examples if fragment in e.source]
    return want


def _csv(name: str) -> list[dict]:
    import csv

    with open(FIGURES / "sod" / f"{name}.csv") as f:
        return list(csv.DictReader(f))


def _study_rows(name: str) -> list[dict]:
    study = mpm_fem.sod.settings("study")
    return [r for r in _csv(name) if (int(r["ppc"]), float(r["cfl"])) == (study["ppc"], study["cfl"])]


def test_the_pages_sod_runs_are_the_committed_seeds_table():
    """Each run of the page's convergence study (study settings, seeds 0-2) is its row of seeds.csv."""
    committed = {(float(r["h"]), int(r["seed"])): r for r in _study_rows("seeds")}
    lines = _shown("for r in sod.runs").strip().splitlines()
    assert len(lines) == 9
    for line in lines:
        h, seed, layout, particles, nodes = line.split()
        row = committed[(float(h), int(seed))]
        assert layout == row["layout"]
        assert (float(particles), float(nodes)) == (float(row["particles_L1"]), float(row["nodes_L1"])), line


def _orders_by_seed(rows: list[dict], key: str, seeds) -> dict:
    """``{h: [order of each seed against the previous mesh]}`` from the committed seeds table."""
    import math

    by = {(float(r["h"]), int(r["seed"])): float(r[key]) for r in rows}
    hs = sorted({h for h, _ in by}, reverse=True)
    pairs = zip(hs[:-1], hs[1:], strict=True)
    return {b: [math.log(by[(a, k)] / by[(b, k)]) / math.log(a / b) for k in seeds] for a, b in pairs}


def test_the_pages_orders_and_their_ranges_are_the_committed_tables():
    """The table of the page: seed 0's order is convergence.csv's regular-layout order; the range over
    seeds 0-2 is that of the orders seeds.csv gives; the errors are its rows."""
    seeds_rows = [r for r in _study_rows("seeds") if int(r["seed"]) in (0, 1, 2) and float(r["h"]) >= 0.0025]
    convergence = {float(r["h"]): r for r in _study_rows("convergence")}
    for key in ("particles_L1", "nodes_L1"):
        orders = _orders_by_seed(seeds_rows, key, (0, 1, 2))
        lines = _shown(f'sod.table("{key}")').strip().splitlines()[1:4]
        for line in lines:
            h, first, mean, lo, hi, *order = line.replace("[", " ").replace("]", " ").replace(",", " ").split()
            h = float(h)
            assert float(first) == pytest.approx(float(convergence[h][f"mpm_{key}"]), rel=5e-3)
            values = [float(r[key]) for r in seeds_rows if float(r["h"]) == h]
            assert (float(lo), float(hi)) == pytest.approx((min(values), max(values)), rel=5e-3)
            if h in orders:
                regular, o_mean, o_lo, o_hi = map(float, order)
                assert regular == pytest.approx(float(convergence[h][f"order_{key}"]), abs=0.005), line
                o = orders[h]
                assert (o_mean, o_lo, o_hi) == pytest.approx((sum(o) / 3, min(o), max(o)), abs=0.005), line


def test_the_pages_baselines_are_the_committed_convergence_table():
    convergence = {float(r["h"]): r for r in _study_rows("convergence")}
    for line in _shown("for r in fem.rows").strip().splitlines():
        h, error, order = line.split()
        row = convergence[float(h)]
        assert float(error) == float(row["fem_lumped_L1"]), line
        assert order == "nan" if not row["order_fem_lumped_L1"] else float(order) == pytest.approx(
            float(row["order_fem_lumped_L1"]), abs=5e-4)
    for fragment, column in (('mass="consistent", preset="study"', "fem_consistent_L1"), ("sod.fv(", "fv_L1"),
                             ('sod(preset="study", h=0.01)', "mpm_nodes_L1")):
        shown = _shown(fragment)
        value = float(shown.split("L1 ")[1].split(",")[0].split(" ")[0]) if column != "mpm_nodes_L1" else \
            float(shown.split("(particles), ")[1].split(" ")[0])
        assert value == pytest.approx(float(convergence[0.01][column]), rel=5e-3), (column, shown)


def test_the_pages_burgers_numbers_are_the_committed_errors_table():
    import csv

    with open(FIGURES / "burgers" / "errors.csv") as f:
        rows = {(r["method"], float(r["h"])): r for r in csv.DictReader(f)
                if r["solution"] == "rarefaction" and float(r["eps"]) == 0.045}
    mpm, fem = rows[("mpm_calculated", 0.01)], rows[("fem_consistent", 0.01)]
    shown = _shown("velocity max error").split()
    assert (float(shown[4].rstrip(",")), float(shown[6])) == pytest.approx(
        (float(mpm["particles_max"]), float(mpm["nodes_max"])), rel=5e-3)
    shown = _shown('burgers.fem(h=0.01, mass="consistent")')
    assert float(shown.split("L1 ")[1].split(",")[0]) == pytest.approx(float(fem["nodes_L1"]), rel=5e-3)


def test_the_pages_ratio_to_the_source_is_the_committed_one():
    rows = sorted((r for r in _study_rows("convergence") if r["source_L1"]), key=lambda r: -float(r["h"]))
    ratios = [float(r["ratio_nodes_L1"]) for r in rows]
    assert len(ratios) == 6
    assert (f"L1 is {min(ratios[:5]):.2f} to {max(ratios[:5]):.2f} times the source's on its five coarsest meshes "
            f"and {ratios[5]:.2f} times on the sixth") in " ".join(DOCS.read_text().split())


# --- the API's pieces ------------------------------------------------------------------------------


def test_the_presets_are_the_studies_settings_read_only():
    import studies.sod

    study = mpm_fem.sod.settings("study")
    assert {k: study[k] for k in studies.sod.MPM} == studies.sod.MPM
    assert (mpm_fem.sod.settings()["ppc"], mpm_fem.sod.settings()["cfl"]) == (4, 0.1)
    with pytest.raises(TypeError):
        study["cfl"] = 0.1  # type: ignore[index]
    with pytest.raises(ValueError, match="unknown preset 'paper'; choose one of 'defaults', 'study', 'source'"):
        mpm_fem.sod.settings("paper")
    from mpm_fem.app.presets import baseline_settings

    assert baseline_settings("sod", "fv")["limiter"] == "minmod" and baseline_settings("sod", "fv", "study") == \
        {**studies.sod.FV}


def test_a_run_and_its_result_are_shown_in_one_line_without_arrays():
    run = mpm_fem.sod(h=0.05, T=0.02, layout="jittered", seed=3)
    for text in (repr(run), repr(run.result), str(run.result)):
        assert "\n" not in text and "array" not in text and len(text) < 200, text
    assert "layout='jittered', seed=3" in repr(run) and "steps to t=0.02" in repr(run)


def test_errors_from_python_name_the_python_keyword():
    with pytest.raises(TypeError, match="did you mean ppc"):
        mpm_fem.sod.convergence(hs=(0.05, 0.025), ppcc=3)
    with pytest.raises(TypeError, match="did you mean gamma"):
        mpm_fem.sod.exact([0.5], gama=1.4)
    from mpm_fem.app.guard import UsageError

    with pytest.raises(UsageError, match="pass yes_long=True") as refused:
        mpm_fem.sod.convergence(hs=(2e-5, 1e-5))  # each run under an hour, not the two together
    assert "--yes-long" not in str(refused.value)
    with pytest.raises(ValueError, match="at least two different meshes"):
        mpm_fem.sod.convergence(hs=(0.05,))
    with pytest.raises(ValueError, match="seeds=\\(0,\\)"):
        mpm_fem.sod.convergence(hs=(0.05, 0.025), seeds=(0, 1), solver="fem")
    with pytest.raises(ValueError, match="no finite-volume baseline"):
        mpm_fem.burgers.fv(h=0.05)


def test_the_convergence_helper_gives_the_orders_of_the_measure_package(tmp_path):
    """Two meshes, two layouts: seed 0's order, the mean and range over seeds, and the fitted order
    are those of mpm_fem.measure from the runs' own errors; a cached rerun gives the same."""
    import math

    from mpm_fem.measure.errors import fitted_order

    c = mpm_fem.sod.convergence(hs=(0.025, 0.05), seeds=(1, 0), T=0.05, jobs=1, progress=False, cache=tmp_path)
    assert c.hs == (0.05, 0.025) and c.seeds == (0, 1) and [r["seed"] for r in c.runs] == [0, 1, 0, 1]
    e = {(r["h"], r["seed"]): r["particles_L1"] for r in c.runs}
    orders = [math.log(e[(0.05, k)] / e[(0.025, k)]) / math.log(2) for k in (0, 1)]
    fine = c.rows[1]
    assert fine["order_particles_L1"] == pytest.approx(orders[0], rel=1e-12)
    assert (fine["order_particles_L1_lo"], fine["order_particles_L1_hi"]) == pytest.approx(sorted(orders))
    assert fine["particles_L1_mean"] == pytest.approx((e[(0.025, 0)] + e[(0.025, 1)]) / 2)
    assert math.isnan(c.rows[0]["order_particles_L1_mean"])
    assert c.orders["particles_L1"]["mean"] == pytest.approx(
        sum(fitted_order([0.05, 0.025], [e[(0.05, k)], e[(0.025, k)]]) for k in (0, 1)) / 2)
    assert set(c.orders) == {"particles_L1", "particles_L2", "nodes_L1", "nodes_L2"}
    again = mpm_fem.sod.convergence(hs=(0.05, 0.025), seeds=(0, 1), T=0.05, jobs=1, progress=False, cache=tmp_path)
    assert again.runs == c.runs and len(list(tmp_path.glob("*.json"))) == 4
