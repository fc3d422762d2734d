"""The benchmark scripts run and print what their docstrings promise (benchmarks/)."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _script(name: str, *args: str, timeout: float = 120) -> subprocess.CompletedProcess:
    """``python benchmarks/NAME ARGS`` (or ``python -c CODE`` for ``"-c"``) run from the repository's root."""
    target = name if name == "-c" else str(ROOT / "benchmarks" / name)
    return subprocess.run([sys.executable, target, *args], capture_output=True, text=True, timeout=timeout, cwd=ROOT)


def test_fem_cost_reports_numpy_compiled_and_mpm_per_mesh():
    proc = _script("fem_cost.py", "--T", "0.01", "--finest", "0.0025", timeout=600)
    assert proc.returncode == 0, proc.stderr
    rows = [line.split() for line in proc.stdout.splitlines() if line.split() and line.split()[0].startswith("0.00")]
    assert [(r[0], r[1]) for r in rows] == [(h, m) for h in ("0.005000", "0.002500") for m in ("lumped", "consistent")]
    for r in rows:  # numpy, compiled, speed-up, MPM, two ratios: positive and finite
        numpy_us, fused_us, speedup = float(r[2]), float(r[3]), float(r[4].rstrip("x"))
        assert numpy_us > 0 and fused_us > 0 and abs(speedup - numpy_us / fused_us) <= 0.05 * speedup + 0.05


def test_fem_cost_rejects_bad_arguments():
    proc = _script("fem_cost.py", "--T", "0")
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
    proc = _script("step_cost.py", "--max", "1e3", "--repeat", "1", "--bases", "mpm", "--no-threads", timeout=600)
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
    proc = _script("step_cost.py", "--bases", "fem")
    assert proc.returncode == 2 and "unknown bases" in proc.stderr


@pytest.mark.parametrize(("against", "ratio_of"), [("sweep", "apart / swept"), ("count", "per step / swept")])
def test_deep_case_runs_the_case_two_ways_and_finds_the_same_result(against, ratio_of):
    proc = _script("deep_case.py", "--h", "0.005", "--against", against, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert "the two results equal" in proc.stdout
    ratio = float(proc.stdout.split(f"CPU time {ratio_of}: ")[1].split(";")[0])
    assert 0 < ratio < 100


def test_deep_case_rejects_a_bad_cell_size():
    proc = _script("deep_case.py", "--h", "0")
    assert proc.returncode == 2 and "--h must lie in (0, 0.01]" in proc.stderr


def _ledger_sample(costs, k):
    code = ("import sys, json; sys.path.insert(0, 'benchmarks'); import numpy as np; from ledger import sample; "
            f"print(json.dumps(sample(np.array({costs!r}, float), {k})))")
    proc = _script("-c", code)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout)


def test_the_ledger_samples_cases_in_proportion_to_their_cost():
    # total 14: the middles of two equal halves lie at 3.5 (the fourth case) and 10.5 (the largest)
    assert _ledger_sample([1, 1, 1, 1, 10], 2) == [3, 4]
    # without the large case the halves' middles are 1 and 3: the first and the third case
    assert _ledger_sample([1, 1, 1, 1], 2) == [0, 2]
    # more groups than cases: each case once
    assert _ledger_sample([5, 5], 4) == [0, 1]


def test_the_ledger_times_the_tier_now_and_before_with_equal_results():
    proc = _script("ledger.py", "--tier", "quick", "--per-study", "2", "--studies", "sod", timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert "every pair of results equal" in proc.stdout
    row = next(line for line in proc.stdout.splitlines() if line.startswith("| sod |"))
    cells = [c.strip() for c in row.split("|")[1:-1]]
    assert cells[2] == "2"  # two cases sampled
    now, before = float(cells[3]), float(cells[4])
    assert now > 0 and before > 0
    ratio = float(cells[5].split()[0])  # the ratio of the sums, each printed to 0.05 CPU-s, itself to 0.005
    assert (before - 0.05) / (now + 0.05) - 0.005 <= ratio <= (before + 0.05) / (now - 0.05) + 0.005


def test_the_ledger_refuses_an_unknown_study():
    proc = _script("ledger.py", "--studies", "sod,nonesuch")
    assert proc.returncode == 2 and "unknown studies ['nonesuch']" in proc.stderr


def test_a_measured_block_names_the_script_and_its_arguments_but_not_the_page(tmp_path):
    page = tmp_path / "page.md"
    code = ("import sys\nsys.path.insert(0, 'benchmarks')\n"
            f"sys.argv = ['deep_case.py', '--h', '0.005', '--markdown', {str(page)!r}, '--against', 'count']\n"
            "from measured import measured_block\n"
            f"with measured_block({str(page)!r}, 'deep_case', 'deep_case_count'):\n    print('| x |')\n")
    proc = _script("-c", code)
    assert proc.returncode == 0, proc.stderr
    text = page.read_text()
    assert "<!-- begin deep_case_count" in text and "| x |" in text
    assert "by `python benchmarks/deep_case.py --h 0.005 --against count`" in text


def test_the_kernel_before_issue_47_is_switched_on_and_off_per_change():
    code = ("import sys\nsys.path.insert(0, 'benchmarks')\nfrom deep_case import run_as\n"
            "import mpm_fem.run.solve as solve, studies.sod as sod\nfrom mpm_fem.fused.step import FusedStep\n"
            "run_as('apart', 'per step')\n"
            "assert solve.FusedStep.keywords == {'sweep': False} and sod.ExtremaCounter.tally is None\n"
            "run_as('per step')\nassert solve.FusedStep is FusedStep and sod.ExtremaCounter.tally is None\n"
            "run_as()\nassert solve.FusedStep is FusedStep and sod.ExtremaCounter.tally is not None\n")
    proc = _script("-c", code)
    assert proc.returncode == 0, proc.stderr
