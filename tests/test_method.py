"""A method's measurements: the projection of any registered basis against the exact integrals
of its own grid functions, and the pytest plugin that hands them to a researcher's tests."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from mpm_fem.app.method import Method
from mpm_fem.bases import get, plugins, registry
from mpm_fem.core.grid import uniform_grid
from mpm_fem.measure.method import nodal_errors, projection_orders, quadrature_points
from mpm_fem.measure.projection import exact_nodal, layout, particle_nodal, smooth_fields

TESTS = Path(__file__).parent


@pytest.fixture(autouse=True)
def own_registry(monkeypatch):
    monkeypatch.setattr(registry, "_BASES", dict(registry._BASES))
    monkeypatch.setattr(plugins.LOADER, "loaded", {})


def test_the_quadrature_gives_the_hats_exact_integrals_of_the_projection_study():
    grid, fields = uniform_grid(0.0, 1.0, 1 / 40), smooth_fields()
    points, weights = quadrature_points(grid)
    assert weights.sum() == pytest.approx(1.0, abs=1e-15)
    hats, exact = get("mpm").shape(grid, points), exact_nodal(grid, fields)
    assert np.abs(hats.scatter(weights * fields.rho(points)) - exact.m).max() < 1e-15
    assert np.abs(hats.scatter_gradient(weights * fields.p(points)) - exact.F).max() < 1e-14


def test_the_hats_errors_are_the_projection_studys_sums():
    grid, fields = uniform_grid(0.0, 1.0, 1 / 20), smooth_fields()
    x, V = layout(grid, "jittered", 4, 2, rho=fields.rho)
    ex, mpm = exact_nodal(grid, fields), particle_nodal(grid, x, V, fields, "mpm")
    inner = slice(3, grid.n_nodes - 3)
    expected = float(np.sum(grid.lumped_mass[inner] * np.abs((ex.m - mpm.m)[inner])))
    assert nodal_errors(grid, x, V, fields, "mpm")["E_m"] == pytest.approx(expected, rel=1e-12)


def test_projection_orders_measure_each_basis_and_the_jitters_non_converging_acceleration():
    regular = {b: projection_orders(b, layout_name="regular") for b in ("mpm", "bspline")}
    assert regular["mpm"]["E_m"].runs == 1 and 2.8 < regular["mpm"]["E_m"].mean < 3.0
    assert 1.7 < regular["mpm"]["E_a"].mean < 1.9
    assert regular["bspline"]["E_m"].mean > 4.5  # the quadratic B-spline's midpoint sums, two orders more
    jittered = projection_orders("mpm", seeds=(1, 2, 3))
    assert jittered["E_m"].runs == 3 and 0.8 < jittered["E_m"].lo <= jittered["E_m"].hi < 1.2
    assert jittered["E_a"].hi < 0.1  # C8: the nodal acceleration error does not converge on jittered particles
    with pytest.raises(ValueError, match="at least two meshes"):
        projection_orders("mpm", cells=(20, 20))


def test_a_method_from_outside_measures_as_the_basis_it_copies():
    assert Method("plugin_bases:Hats").projection(cells=(20, 40)) == Method("mpm").projection(cells=(20, 40))
    with pytest.raises(plugins.ContractError, match="no partition of unity"):
        Method("plugin_bases:Heavy")


def _pytest(tmp_path: Path, *options: str) -> subprocess.CompletedProcess:
    """A researcher's test session in ``tmp_path`` with the plugin (installed with the package)."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(TESTS), os.environ.get("PYTHONPATH", "")])}
    return subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-p", "no:xdist",
                           *options], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)


def test_the_pytest_plugin_hands_a_researchers_test_the_measured_orders(tmp_path):
    (tmp_path / "test_theirs.py").write_text(textwrap.dedent("""
        def test_hats_project_at_third_order_on_regular_particles(mpm_method):
            assert mpm_method.basis == "hats"
            assert mpm_method.projection(cells=(20, 40, 80), layout="regular")["E_m"].lo > 2.8
    """))
    got = _pytest(tmp_path, "--mpm-basis", "plugin_bases:Hats")
    assert got.returncode == 0 and "1 passed" in got.stdout, got.stdout + got.stderr
    broken = _pytest(tmp_path, "--mpm-basis", "plugin_bases:Heavy")
    assert broken.returncode == 1 and "no partition of unity" in broken.stdout, broken.stdout
    missing = _pytest(tmp_path)
    assert missing.returncode == 1 and "measures the basis given with --mpm-basis" in missing.stdout


def test_a_session_that_does_not_use_the_plugin_imports_nothing_of_the_package(tmp_path):
    (tmp_path / "conftest.py").write_text(textwrap.dedent("""
        import sys

        def pytest_collection_finish(session):
            heavy = sorted(m for m in ("numba", "mpm_fem.bases", "mpm_fem.app.method") if m in sys.modules)
            assert not heavy, heavy
    """))
    (tmp_path / "test_other.py").write_text("def test_nothing():\n    assert 1 + 1 == 2\n")
    got = _pytest(tmp_path)
    assert got.returncode == 0 and "1 passed" in got.stdout, got.stdout + got.stderr
