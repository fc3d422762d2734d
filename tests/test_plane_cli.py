"""``mpm-fem plane axis|vortex`` (mpm_fem/app/plane_cli.py): a tiny run's errors and CFL number printed after
the estimate, VTU files that meshio reads back, and every bad input refused with exit status 2 and
one line before any work."""

import json
import re
import sys

import meshio
import pytest

import mpm_fem
from mpm_fem.app.cli import main
from mpm_fem.bases import plugins, registry


@pytest.fixture(autouse=True)
def own_registry(monkeypatch):
    monkeypatch.setattr(registry, "_BASES", dict(registry._BASES))
    monkeypatch.setattr(plugins.LOADER, "loaded", {})
    monkeypatch.setattr(plugins.LOADER, "failed", {})


def _no_run(monkeypatch):
    """Make any 2D run fail the test: a refusal must come before it."""
    monkeypatch.setattr(sys.modules["mpm_fem.plane.run"], "run", lambda *a, **k: pytest.fail("the run started"))


def test_axis_prints_the_estimate_first_then_its_errors_and_cfl(capsys):
    assert main(["plane", "axis", "--h", "0.25"]) == 0
    captured = capsys.readouterr()
    assert captured.err.startswith("plane axis: estimated 32 steps, 256 particles, 64 nodes"), captured.err
    line = captured.out.strip()
    expected = mpm_fem.plane.axis(h=1 / 4).errors
    L2 = float(re.search(r"displacement L2 (\S+),", line).group(1))
    assert L2 == pytest.approx(expected["displacement"]["particles"]["L2"], rel=1e-3), line
    assert "Linf" in line and "acceleration L2" in line and "cfl 0.25 (32 steps" in line, line


def test_p1_and_the_stage_switches_are_taken(capsys):
    assert main(["plane", "axis", "--h", "0.25", "--basis", "p1", "--projection", "exact", "--mass", "consistent",
                 "--cfl", "0.2", "--refine", "2", "--amplitude-y", "0", "--quiet"]) == 0
    assert capsys.readouterr().out == ""  # --quiet: no estimate and no line


def test_vtu_files_read_back_with_the_particles_and_grid_nodes(tmp_path, capsys):
    out = tmp_path / "vortex"
    assert main(["plane", "vortex", "--h", "0.125", "--amplitude", "0.01", "--vtu", "8", "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["steps"] == 32 and summary["cfl"] == pytest.approx(0.25)
    frames = sorted(out.glob("particles_*.vtu"))
    assert len(frames) == 4 and (out / "particles.pvd").read_text().count("<DataSet") == 4, frames
    particles = meshio.read(frames[-1])
    assert len(particles.points) == summary["particles"] == 816, len(particles.points)
    for name, width in (("displacement", 3), ("velocity", 3), ("F", 9), ("stress", 9)):
        assert particles.point_data[name].shape == (816, width), name
    J = particles.point_data["J"]
    assert abs(J.min() - 1) < 0.1 and abs(J.max() - 1) < 0.1, (J.min(), J.max())  # the vortex is isochoric
    grid = meshio.read(out / "grid_00003.vtu")
    assert len(grid.points) == 25 * 25 and grid.cells_dict["quad"].shape == (24 * 24, 4)
    assert grid.point_data["mass"].sum() == pytest.approx(particles.point_data["mass"].sum(), rel=1e-12)
    assert str(out) in capsys.readouterr().out


def test_the_periodic_grid_is_written_with_its_end_points(tmp_path):
    assert main(["plane", "axis", "--h", "0.25", "--vtu", "--out", str(tmp_path / "a"), "--quiet"]) == 0
    grid = meshio.read(tmp_path / "a" / "grid_00000.vtu")
    particles = meshio.read(tmp_path / "a" / "particles_00000.vtu")
    assert len(grid.points) == 9 * 9 and len(particles.points) == 256
    assert not list((tmp_path / "a").glob("particles_00001.vtu"))  # --vtu alone: the frame at T only


@pytest.mark.parametrize("options, words", [
    (["axis", "--h", "0.3"], "h=0.3 does not divide the domain"),
    (["axis", "--amplitude", "0.4"], "A pi < 1"),
    (["axis", "--amplitude-y", "0.4"], "A_y pi < 1"),
    (["vortex", "--amplitude-y", "0.1"], "vortex has none"),
    (["axis", "--cfl", "0.9"], r"must lie in \(0, 0.862\]"),
    (["axis", "--cfl", "0"], r"must lie in \(0, 1\]"),
    (["axis", "--basis", "nope"], "unknown basis 'nope'"),
    (["axis", "--basis", "plugin_plane_bases:Flat"], "has no 2D"),
    (["axis", "--ppc", "0"], "integer >= 1"),
    (["axis", "--h=-0.25"], "must be positive"),
    (["axis", "--seed", "-1"], "seed must be an integer >= 0"),
    (["axis", "--mass", "diagonal"], "unknown mass 'diagonal'; choose one of lumped, consistent, exact, grid, fmpm1"),
    (["axis", "--ppc", "two"], "invalid int value"),
    (["axis", "--amplitdue", "1e-4"], "did you mean --amplitude"),
    (["square"], "invalid choice: 'square'"),
    (["axis", "--vtu=-1"], "--vtu takes a step interval"),
    (["axis", "--h", "1e-5"], r"the run needs about .* \(h=1e-05, ppc=2"),
    (["axis", "--h", "0.002"], r"over 1 h; pass --yes-long to run it"),
])
def test_bad_input_exits_2_with_one_line_before_any_work(monkeypatch, capsys, options, words):
    _no_run(monkeypatch)
    try:
        code = main(["plane", *options])
    except SystemExit as exited:  # argparse's refusals (a choice, a type, an unknown option)
        code = exited.code
    assert code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("mpm-fem plane: error:"), err
    assert re.search(words, err), err


def test_an_explicit_non_empty_out_is_refused_without_overwrite(tmp_path, monkeypatch, capsys):
    (tmp_path / "kept.txt").write_text("x")
    _no_run(monkeypatch)
    assert main(["plane", "axis", "--h", "0.25", "--out", str(tmp_path)]) == 2
    assert "error" in capsys.readouterr().err and (tmp_path / "kept.txt").exists()


def test_a_particle_that_inverts_ends_the_run_with_exit_1_naming_the_step_after_the_estimate(capsys):
    assert main(["plane", "vortex", "--h", "0.125"]) == 1
    err = capsys.readouterr().err.splitlines()
    assert err[0].startswith("plane vortex: estimated 32 steps"), err
    stopped = r"mpm-fem plane: run failed: J = det F = \S+ <= 0 at step \d+ \(t=\S+\) in particle \d+"
    assert re.match(stopped, err[-1]), err
    assert len(err) == 2, err
