"""The benchmark scripts run and print what their docstrings promise (benchmarks/)."""

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_fem_cost_reports_numpy_compiled_and_mpm_per_mesh():
    proc = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "fem_cost.py"),
                           "--T", "0.01", "--finest", "0.0025"],
                          capture_output=True, text=True, timeout=600, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    rows = [line.split() for line in proc.stdout.splitlines() if line.split() and line.split()[0].startswith("0.00")]
    assert [(r[0], r[1]) for r in rows] == [(h, m) for h in ("0.005000", "0.002500") for m in ("lumped", "consistent")]
    for r in rows:  # numpy, compiled, speed-up, MPM, two ratios: positive and finite
        numpy_us, fused_us, speedup = float(r[2]), float(r[3]), float(r[4].rstrip("x"))
        assert numpy_us > 0 and fused_us > 0 and abs(speedup - numpy_us / fused_us) <= 0.05 * speedup + 0.05


def test_fem_cost_rejects_bad_arguments():
    proc = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "fem_cost.py"), "--T", "0"],
                          capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert proc.returncode == 2 and "--T must lie in (0, 0.5]" in proc.stderr


def test_a_generated_block_replaces_only_itself(tmp_path):
    from mpm_fem.app.output import replace_block, tee_markdown

    page = tmp_path / "page.md"
    page.write_text("# Title\n\ntyped text\n")
    replace_block(page, "bench", "| a |\n|---|\n| 1 |")
    replace_block(page, "bench", "| a |\n|---|\n| 2 |")
    text = page.read_text()
    assert text.count("begin bench") == 1 and "| 2 |" in text and "| 1 |" not in text and "typed text" in text
    with tee_markdown(page, "other", "Measured today."):
        print("| b |")
    assert "Measured today.\n\n| b |" in page.read_text() and "| 2 |" in page.read_text()


def test_step_cost_reports_each_basis_as_a_fraction_of_the_anchor():
    proc = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "step_cost.py"), "--max", "1e3", "--repeat", "1",
                           "--bases", "mpm", "--no-threads"], capture_output=True, text=True, timeout=600, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    cells = lambda line: [c.strip() for c in line.strip("|").split("|")]  # noqa: E731
    rows = [cells(line) for line in proc.stdout.splitlines() if line.startswith("| mpm | 1e+03")]
    assert len(rows) == 1  # loop rate, the loop without the sweep, its gain, anchor rate, their ratio
    loop, apart, gain = float(rows[0][4]), float(rows[0][5]), float(rows[0][6])
    anchor, ratio = float(rows[0][9]), float(rows[0][10])
    assert loop > 0 and anchor > 0 and ratio == pytest.approx(loop / anchor, rel=0.02, abs=0.01)
    assert apart > 0 and gain == pytest.approx(loop / apart, rel=0.02, abs=0.01)
    assert any(line.startswith("| anchor (benchmarks/anchor.py, P1) |") for line in proc.stdout.splitlines())


def test_step_cost_rejects_an_unknown_basis():
    proc = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "step_cost.py"), "--bases", "fem"],
                          capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert proc.returncode == 2 and "unknown bases" in proc.stderr


@pytest.mark.parametrize(("against", "ratio_of"), [("sweep", "apart / swept"), ("count", "per step / swept")])
def test_deep_case_runs_the_case_two_ways_and_finds_the_same_result(against, ratio_of):
    proc = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "deep_case.py"), "--h", "0.005",
                           "--against", against], capture_output=True, text=True, timeout=600, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    assert "the two results equal" in proc.stdout
    ratio = float(proc.stdout.split(f"CPU time {ratio_of}: ")[1].split(";")[0])
    assert 0 < ratio < 100


def test_deep_case_rejects_a_bad_cell_size():
    proc = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "deep_case.py"), "--h", "0"],
                          capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert proc.returncode == 2 and "--h must lie in (0, 0.01]" in proc.stderr
