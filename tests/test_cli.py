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
    # the processor and the compiler's target for it: the last digits of some tables depend on them
    assert "llvm target" in summary["versions"]["cpu"] and summary["versions"]["numba"][0].isdigit()
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
    (["sod", "--basis", "bspline9"], "unknown basis 'bspline9'; choose one of mpm, gimp"),
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


# --- a mistyped option or command: the closest valid one, and the subcommand's own help ----------

MISTYPED = [
    (["sod", "--ppcc", "8"], "unrecognized arguments: --ppcc 8; did you mean --ppc? (see mpm-fem sod --help)"),
    (["sood", "--h", "0.01"], "invalid choice: 'sood' (choose from 'sod', 'burgers', 'study', 'reproduce', 'method', "
                              "'plane'); did you mean 'sod'? (see mpm-fem sod --help)"),
    (["study", "sood"], "did you mean 'sod'? (see mpm-fem study --help)"),
    (["sod", "--mass", "lumpd"], "did you mean 'lumped'? (see mpm-fem sod --help)"),
    (["burgers", "--solutoin=front"], "did you mean --solution? (see mpm-fem burgers --help)"),
]


@pytest.mark.parametrize("argv,message", MISTYPED, ids=[" ".join(a) for a, _ in MISTYPED])
def test_a_mistyped_name_gets_the_closest_one_and_the_subcommands_help(argv, message, capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(argv)
    assert exit_info.value.code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.endswith(message), err


def test_an_unknown_argument_with_nothing_close_gets_the_help_alone(capsys):
    with pytest.raises(SystemExit):
        main(["sod", "--zzz"])
    err = capsys.readouterr().err.strip()
    assert err == "mpm-fem sod: error: unrecognized arguments: --zzz (see mpm-fem sod --help)", err


# --- the grid's fields carry the density, the exact solution and the error --------------------------


def test_the_grid_vtu_carries_the_nodal_density_the_exact_solution_and_the_error(tmp_path):
    import meshio
    import numpy as np

    from mpm_fem.problems import sod

    out = tmp_path / "f"
    assert main(["sod", "--h", "0.05", "--T", "0.05", "--save-fields", "5", "--out", str(out), "--quiet"]) == 0
    grids = sorted((out / "fields").glob("grid_*.vtu"))
    times = [float(line.split('"')[1]) for line in (out / "fields" / "grid.pvd").read_text().splitlines()
             if "<DataSet" in line]
    for path, t in ((grids[1], times[1]), (grids[-1], times[-1])):
        grid = meshio.read(path)
        x, data = grid.points[:, 0], grid.point_data
        np.testing.assert_allclose(data["density"], data["mass"] / sod.uniform_grid(0, 1, 0.05).lumped_mass)
        rho, u, _ = sod.exact(sod.SodSettings(), x, t)
        np.testing.assert_allclose(data["density_exact"], rho, rtol=1e-12)
        np.testing.assert_allclose(data["velocity_exact"], u, rtol=1e-12, atol=1e-15)
        np.testing.assert_allclose(data["density_error"], data["density"] - rho, rtol=1e-12, atol=1e-15)
        assert 0 < np.abs(data["density_error"]).max() < 0.5
    summary = json.loads((out / "summary.json").read_text())
    final = meshio.read(grids[-1]).point_data
    l1 = float(np.sum(np.abs(final["density_error"]) * sod.uniform_grid(0, 1, 0.05).lumped_mass))
    assert l1 == pytest.approx(summary["errors"]["density"]["nodes"]["L1"], rel=1e-6)
    particles = meshio.read(sorted((out / "fields").glob("particles_*.vtu"))[-1]).point_data
    assert {"density_exact", "density_error", "velocity_error", "pressure_error"} <= set(particles)


def test_burgers_grid_vtu_has_the_velocity_error_and_no_exact_density(tmp_path):
    import meshio

    out = tmp_path / "b"
    assert main(["burgers", "--h", "0.05", "--T", "0.05", "--save-fields", "5", "--out", str(out), "--quiet"]) == 0
    data = meshio.read(sorted((out / "fields").glob("grid_*.vtu"))[-1]).point_data
    assert {"density", "velocity_exact", "velocity_error"} <= set(data) and "density_exact" not in data


# --- progress: a line while numba compiles, and the time left ---------------------------------------


def test_a_line_says_when_numba_compiles_and_none_when_the_kernel_comes_from_its_cache(tmp_path, monkeypatch):
    import importlib
    import io

    from mpm_fem.app.compiling import LINE, compile_notice

    (tmp_path / "toy_kernel.py").write_text("from numba import njit\n\n\n@njit(cache=True)\n"
                                            "def twice(x):\n    return 2 * x\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    toy = importlib.import_module("toy_kernel")
    first, again, off = io.StringIO(), io.StringIO(), io.StringIO()
    with compile_notice(stream=first):
        assert toy.twice(2) == 4 and toy.twice(3) == 6
    assert first.getvalue() == LINE + "\n"  # once, at the compilation
    toy = importlib.reload(toy)  # a new dispatcher: loads the compiled kernel from the disk cache
    with compile_notice(stream=again):
        assert toy.twice(2) == 4
    assert again.getvalue() == ""
    with compile_notice(enabled=False, stream=off):
        assert toy.twice(2.5) == 5.0  # a new signature compiles, unannounced when disabled
    assert off.getvalue() == ""


def compiles(case: dict) -> dict:
    """A sweep's case that compiles a fresh kernel (no cache) in the process that runs it."""
    import time

    from numba import njit

    time.sleep(0.2)  # both workers take a case
    n = case["n"]
    return {"value": njit(lambda x: x + n)(1)}


def test_of_the_workers_compiling_one_says_so(capfd):
    from mpm_fem.app.compiling import LINE
    from mpm_fem.app.sweep import run_cases

    got = run_cases(compiles, [{"n": n} for n in range(4)], jobs=2, progress=True)
    assert [r["value"] for r in got] == [1, 2, 3, 4]
    assert capfd.readouterr().err.count(LINE) == 1
    run_cases(compiles, [{"n": n} for n in range(2)], jobs=2, progress=False)
    assert LINE not in capfd.readouterr().err


def test_the_time_left_is_the_mean_time_of_the_cases_run_so_far():
    from mpm_fem.app.sweep import time_left

    assert time_left(10.0, 2, 3) == "about 15 s left"
    assert time_left(600.0, 1, 1) == "about 10 min left"
    assert time_left(5.0, 0, 4) == "time left unknown" and time_left(5.0, 4, 0) == "done"
    # before a tenth of the cost has run, the time so far is mostly compiling: no guess
    assert time_left(32.0, 9, 91) == "time left unknown" and time_left(3.0, 10, 90) == "about 27 s left"


def test_the_time_left_weighs_the_cases_by_their_cost(capsys, monkeypatch):
    """The costly case first (as a sweep starts them): by case count the time left would be the first
    case's time again; weighed by the cost models' estimate it is a tenth of it."""
    from mpm_fem.app import sweep

    monkeypatch.setattr(sweep.sys.stderr, "isatty", lambda: False, raising=False)
    clock = iter([0.0, 100.0, 200.0])
    monkeypatch.setattr(sweep.time, "perf_counter", lambda: next(clock))
    weighed = sweep._Progress(2, 0, "cases", True, to_run=11.0)
    weighed.update({}, 10.0)
    assert capsys.readouterr().err.splitlines()[-1] == "[cases] 1/2 done, 100 s, about 10 s left"
    clock = iter([0.0, 100.0])
    counted = sweep._Progress(2, 0, "cases", True)
    counted.update({})
    assert capsys.readouterr().err.splitlines()[-1] == "[cases] 1/2 done, 100 s, about 100 s left"


def test_plain_progress_lines_show_the_time_left(capsys, monkeypatch):
    from mpm_fem.app import sweep
    from mpm_fem.app.convergence import measured

    monkeypatch.setattr(sweep.sys.stderr, "isatty", lambda: False, raising=False)
    case = {"problem": "sod", "solver": "fv", "field": "density", "settings": {"h": 0.1, "T": 0.01}}
    sweep.run_cases(measured, [case, {**case, "settings": {"h": 0.05, "T": 0.01}}], jobs=1, progress=True)
    lines = capsys.readouterr().err.splitlines()
    assert lines[1].startswith("[cases] 1/2 done, ") and lines[1].endswith(" s left"), lines
    assert lines[2].endswith(", done"), lines
