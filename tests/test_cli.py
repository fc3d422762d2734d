"""The ``mpm-fem`` command line: outputs of a run, and every bad input refused with exit status 2."""

import json
import os
import subprocess
import sys

import pytest

from mpm_fem.app.cli import main


def test_sod_run_writes_summary_particles_and_figure(tmp_path, capsys):
    out = tmp_path / "sod"
    assert main(["sod", "--h", "0.02", "--T", "0.05", "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    for key in ("errors", "steps", "particles", "cells", "wall_s", "settings", "versions"):
        assert key in summary, key
    e = summary["errors"]["density"]
    assert set(e) == {"particles", "nodes"} and set(e["particles"]) == {"L1", "L2", "max"}
    assert summary["cells"] == 50 and summary["particles"] == 200
    assert summary["settings"]["ppc"] == 4 and summary["settings"]["cfl"] == 0.1  # defaults recorded
    header = (out / "particles.csv").read_text().splitlines()[0]
    assert header.startswith("x,volume,mass,velocity,density") and "density_exact" in header
    assert (out / "profiles.png").stat().st_size > 10_000
    assert "density L1" in capsys.readouterr().out


def test_burgers_run_writes_velocity_errors(tmp_path):
    out = tmp_path / "b"
    assert main(["burgers", "--h", "0.04", "--T", "0.1", "--acceleration", "exact", "--out", str(out), "--quiet"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    v = summary["errors"]["velocity"]["particles"]
    assert 0 < v["max"] < 1e-2 and v["L1"] <= v["L2"] * 2 ** 0.5 + 1e-15
    assert summary["settings"]["solution"] == "rarefaction"


def test_default_output_directory_is_named_by_settings_hash(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["sod", "--h", "0.05", "--T", "0.01", "--quiet"]) == 0
    (run_dir,) = (tmp_path / "runs").iterdir()
    assert run_dir.name.startswith("sod-") and len(run_dir.name) == 14


BAD = [
    (["sod", "--h", "0"], "cell size h must be positive"),
    (["sod", "--h", "-0.01"], "cell size h must be positive"),
    (["sod", "--h", "0.003"], "does not divide"),
    (["sod", "--ppc", "0"], "particles per cell"),
    (["sod", "--T", "-1"], "final time"),
    (["sod", "--cfl", "0"], "CFL"),
    (["sod", "--cfl", "1.5"], "CFL"),
    (["sod", "--mass", "diagonal"], "invalid choice"),
    (["sod", "--basis", "bspline9"], "invalid choice"),
    (["sod", "--h", "abc"], "invalid float"),
    (["burgers", "--eps", "0"], "eps must be positive"),
    (["burgers", "--eps", "-0.1"], "eps must be positive"),
    (["burgers", "--solution", "nonesuch"], "invalid choice"),
    (["burgers", "--acceleration", "magic"], "invalid choice"),
    (["burgers", "--h", "0.3"], "does not divide"),
    (["nonesuch"], "invalid choice"),
]


@pytest.mark.parametrize("argv,message", BAD, ids=[" ".join(a) for a, _ in BAD])
def test_bad_input_exits_2_with_one_line(argv, message, capsys, tmp_path):
    with pytest.raises(SystemExit) as exit_info:
        code = main(argv + ["--out", str(tmp_path / "x")] if argv[0] in ("sod", "burgers") else argv)
        raise SystemExit(code)
    assert exit_info.value.code == 2
    err = capsys.readouterr().err.strip()
    assert message in err and "Traceback" not in err
    assert len(err.splitlines()[-1]) > 10


def test_unwritable_output_directory_exits_2(tmp_path, capsys):
    blocked = tmp_path / "file"
    blocked.write_text("not a directory")
    assert main(["sod", "--h", "0.05", "--T", "0.01", "--out", str(blocked / "sub")]) == 2
    assert "cannot write to the output directory" in capsys.readouterr().err


def test_help_of_every_command_exits_0():
    for argv in (["--help"], ["sod", "--help"], ["burgers", "--help"]):
        proc = subprocess.run([sys.executable, "-m", "mpm_fem.app.cli", *argv], capture_output=True, text=True,
                              env={**os.environ, "PYTHONPATH": os.getcwd()})
        assert proc.returncode == 0 and "usage: mpm-fem" in proc.stdout


def test_saved_fields_read_back_with_meshio_match_the_run(tmp_path):
    import meshio
    import numpy as np

    out = tmp_path / "f"
    assert main(["sod", "--h", "0.05", "--T", "0.05", "--save-fields", "5", "--out", str(out), "--quiet"]) == 0
    fields = out / "fields"
    pvd = (fields / "particles.pvd").read_text()
    assert pvd.count("<DataSet") == len(list(fields.glob("particles_*.vtu"))) >= 3
    names = sorted(fields.glob("particles_*.vtu"))
    first, last = meshio.read(names[0]), meshio.read(names[-1])
    np.testing.assert_allclose(first.point_data["density"], np.where(first.points[:, 0] < 0.5, 1.0, 0.125))
    table = np.loadtxt(out / "particles.csv", delimiter=",", skiprows=1)
    order = np.argsort(last.points[:, 0], kind="stable")
    np.testing.assert_allclose(last.points[order, 0], table[:, 0], rtol=1e-15)
    np.testing.assert_allclose(last.point_data["density"][order], table[:, 4], rtol=1e-15)
    grid = meshio.read(sorted(fields.glob("grid_*.vtu"))[0])
    assert grid.points.shape[0] == 21 and grid.cells_dict["line"].shape == (20, 2)
    assert abs(grid.point_data["mass"].sum() - 0.5625) < 1e-12
    assert main(["sod", "--h", "0.05", "--save-fields", "0", "--out", str(out)]) == 2
