"""The notebook entry points: ``docs/api.md`` is run as a doctest (its examples are the test)."""

from __future__ import annotations

import doctest
from pathlib import Path

import numpy as np
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


# --- bad input: one exception family, one line naming the setting and the value ---------------------

@pytest.fixture
def own_registry(monkeypatch):
    """Bases and transfers registered by a test go into a copy of the registries."""
    from mpm_fem.bases import plugins, registry
    from mpm_fem.core.transfers import plugins as transfer_plugins
    from mpm_fem.core.transfers import registry as transfer_registry

    monkeypatch.setattr(registry, "_BASES", dict(registry._BASES))
    monkeypatch.setattr(transfer_registry, "_TRANSFERS", dict(transfer_registry._TRANSFERS))
    for loader in (plugins.LOADER, transfer_plugins.LOADER):
        monkeypatch.setattr(loader, "loaded", {})
        monkeypatch.setattr(loader, "failed", {})


REFUSED = [
    (lambda: mpm_fem.sod(h=0.013), r"^sod\(\): h=0.013 does not divide the domain"),
    (lambda: mpm_fem.sod(h=float("nan")), r"^sod\(\): cell size h must be positive and finite, got h=nan"),
    (lambda: mpm_fem.sod(h="0.01"), r"^sod\(\): h must be a number, got '0.01' \(str\)"),
    (lambda: mpm_fem.sod("study"), r"^sod\(\): h must be a number, got 'study' .*preset='study'"),
    (lambda: mpm_fem.sod(ppc="4"), r"^sod\(\): ppc must be an integer, got '4'"),
    (lambda: mpm_fem.sod(ppc=0), r"^sod\(\): particles per cell must be an integer >= 1, got 0"),
    (lambda: mpm_fem.sod(cfl=True), r"^sod\(\): cfl must be a number, got True"),
    (lambda: mpm_fem.sod(cfl=0.9), r"^sod\(\): the CFL number must lie in \(0, 0.5\] with lumped mass"),
    (lambda: mpm_fem.sod(gamma=1.0), r"^sod\(\): the ratio of specific heats gamma must be > 1, got 1.0"),
    (lambda: mpm_fem.sod(left="abc"), r"^sod\(\): left must be a tuple of numbers, got 'abc'"),
    (lambda: mpm_fem.sod(layout="grid"), r"^sod\(\): unknown particle layout 'grid'"),
    (lambda: mpm_fem.sod(mass="heavy"), r"^sod\(\): unknown mass 'heavy'"),
    (lambda: mpm_fem.sod(basis="nope"), r"^sod\(\): unknown basis 'nope'; choose one of mpm, .*package.module:Name"),
    (lambda: mpm_fem.sod(basis=3), r"^sod\(\): basis must be a name \(a string\), got 3"),
    (lambda: mpm_fem.sod(basis="no_such_pkg.bases:Quintic"),
     r"^sod\(\): the basis no_such_pkg.bases:Quintic cannot be loaded: No module named 'no_such_pkg'"),
    (lambda: mpm_fem.sod(basis="plugin_bases:Heavy"), r"^sod\(\): the basis plugin_bases:Heavy breaks its contract"),
    (lambda: mpm_fem.sod(transfer="zzz"), r"^sod\(\): unknown transfer 'zzz'"),
    (lambda: mpm_fem.sod(flip=2.0), r"^sod\(\): the PIC/FLIP blend must lie in \[0, 1\]"),
    (lambda: mpm_fem.sod(kernel="c"), r"^sod\(\): unknown kernel 'c'"),
    (lambda: mpm_fem.sod(preset=0.01), r"^unknown preset 0.01; choose one of"),
    (lambda: mpm_fem.burgers(solution="zz"), r"^burgers\(\): unknown Burgers solution 'zz'"),
    (lambda: mpm_fem.sod.settings("paper"), r"^unknown preset 'paper'"),
    (lambda: mpm_fem.sod.exact([0.5, float("nan")], t=0.2),
     r"^sod\.exact\(\): the positions x must be finite, got nan at index 1"),
    (lambda: mpm_fem.sod.exact([float("inf")]), r"^sod\.exact\(\): the positions x must be finite, got inf"),
    (lambda: mpm_fem.sod.exact(["a"], t=0.2), r"^sod\.exact\(\): x must be numbers"),
    (lambda: mpm_fem.sod.exact([0.5], t="0.2"), r"^sod\.exact\(\): t must be a finite number, got '0.2'"),
    (lambda: mpm_fem.sod.exact([0.5], t=-1.0), r"^sod\.exact\(\): the time t must be >= 0, got -1.0"),
    (lambda: mpm_fem.burgers.exact([float("nan")]), r"^burgers\.exact\(\): the positions x must be finite"),
    (lambda: mpm_fem.sod.fem(h=0.013), r"^sod\.fem\(\): h=0.013 does not divide the domain"),
    (lambda: mpm_fem.sod.fem(h="0.1"), r"^sod\.fem\(\): h must be a finite number, got '0.1'"),
    (lambda: mpm_fem.sod.fem(h=0.1, mass="x"), r"^unknown mass 'x'; choose one of 'lumped', 'consistent'"),
    (lambda: mpm_fem.sod.fem(h=0.1, cfl="x"), r"^sod\.fem\(\): cfl must be a number, got 'x'"),
    (lambda: mpm_fem.sod.fv(h=0.1, limiter="zz"), r"^sod\.fv\(\): unknown limiter 'zz'"),
    (lambda: mpm_fem.burgers.fem(h=0.03), r"^burgers\.fem\(\): h=0.03 does not divide the domain \[0.0, 2.0\]"),
    (lambda: mpm_fem.burgers.fv(h=0.05), r"^burgers has no finite-volume baseline"),
    (lambda: mpm_fem.sod.convergence(hs=(0.013, 0.1)), r"^sod\.convergence\(\): h=0.013 does not divide"),
    (lambda: mpm_fem.sod.convergence(hs="0.1"), r"^sod\.convergence\(\): hs takes a sequence"),
    (lambda: mpm_fem.sod.convergence(hs=(0.1, "0.05")), r"^sod\.convergence\(\): h of hs must be a finite number"),
    (lambda: mpm_fem.sod.convergence(hs=(0.1, 0.05), seeds=(-1,)), r"^sod\.convergence\(\): seeds are integers"),
    (lambda: mpm_fem.sod.convergence(hs=(0.1, 0.05), solver="fem", mass="x"), r"^unknown mass 'x'"),
    (lambda: mpm_fem.sod.convergence(hs=(0.1, 0.05), solver="pic"), r"^unknown solver of sod 'pic'"),
    (lambda: mpm_fem.sod(h=1e-7), r"over the limit|pass yes_long=True"),
]


@pytest.mark.parametrize("call, message", REFUSED, ids=[m for _, m in REFUSED])
def test_every_bad_input_is_one_usage_error_in_one_line_naming_the_setting(call, message, own_registry):
    with pytest.raises(mpm_fem.UsageError, match=message) as refused:
        call()
    assert isinstance(refused.value, ValueError) and "\n" not in str(refused.value), str(refused.value)


def test_an_unknown_keyword_is_a_usage_error_and_a_type_error():
    from mpm_fem.app.guard import UnknownSetting

    for call in (lambda: mpm_fem.sod(ppcc=8), lambda: mpm_fem.sod.fem(h=0.1, ppc=8),
                 lambda: mpm_fem.burgers.exact([0.5], gama=1.4)):
        with pytest.raises(UnknownSetting, match="unexpected keyword argument") as refused:
            call()
        assert isinstance(refused.value, mpm_fem.UsageError) and isinstance(refused.value, TypeError)


def test_h_by_position_is_h_by_name():
    by_position, by_name = mpm_fem.sod(0.05, T=0.02), mpm_fem.sod(h=0.05, T=0.02)
    assert by_position.settings == by_name.settings and by_position.settings.h == 0.05
    assert np.array_equal(by_position.particles.density, by_name.particles.density)


def test_p1_is_the_point_mass_basis_stored_under_its_name_mpm():
    p1, mpm = mpm_fem.sod(0.05, T=0.02, basis="p1"), mpm_fem.sod(0.05, T=0.02, basis="mpm")
    assert p1.settings == mpm.settings and p1.settings.basis == "mpm"
    for name in ("x", "density", "velocity", "energy"):
        assert np.array_equal(getattr(p1.particles, name), getattr(mpm.particles, name)), name
    assert p1.errors == mpm.errors


def test_a_basis_and_a_transfer_by_package_module_name_as_on_the_command_line(own_registry):
    run = mpm_fem.sod(0.05, T=0.02, ppc=2, basis="plugin_bases:Hats", transfer="plugin_transfers:Flip2")
    assert run.settings.basis == "hats" and run.result.kernel == "numpy"
    assert mpm_fem.sod(0.05, T=0.02, ppc=2, basis="hats").settings.basis == "hats"  # registered now


def test_an_installed_entry_point_is_found_on_first_use_without_discover(own_registry, monkeypatch):
    from importlib.metadata import EntryPoint

    from mpm_fem.bases import loader, plugins

    found = [EntryPoint("hats", "plugin_bases:Hats", plugins.ENTRY_POINT_GROUP)]
    monkeypatch.setattr(loader, "entry_points", lambda group: [e for e in found if e.group == group])
    run = mpm_fem.sod(0.05, T=0.02, ppc=2, basis="hats")
    reference = mpm_fem.sod(0.05, T=0.02, ppc=2, kernel="numpy")
    assert run.settings.basis == "hats" and np.array_equal(run.particles.density, reference.particles.density)


def test_p1_on_the_command_line_is_mpm(tmp_path):
    import json

    from mpm_fem.app.cli import main

    out = tmp_path / "run"
    assert main(["sod", "--basis", "p1", "--h", "0.1", "--ppc", "2", "--T", "0.01", "--out", str(out),
                 "--quiet"]) == 0
    assert json.loads((out / "summary.json").read_text())["settings"]["basis"] == "mpm"
