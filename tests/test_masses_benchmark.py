"""The grid masses' cost benchmark (benchmarks/mass_cost.py) runs at a tiny size and prints one row per
mesh with every mass but the exact stage, each with its ratio to the lumped step."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
pytest.importorskip("baselines.exact.solids")


def test_mass_cost_prints_each_mass_with_its_ratio_to_the_lumped_step():
    from mpm_fem import masses

    proc = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "mass_cost.py"), "--cells", "4", "8", "--steps",
                           "1", "--repeat", "1"], capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    header = next(line for line in proc.stdout.splitlines() if line.startswith("| cells"))
    assert [c.strip() for c in header.strip("|").split("|")][2:] == [m for m in masses.names() if m != "exact"]
    rows = [line for line in proc.stdout.splitlines() if re.match(r"\| \d+\^2 \|", line)]
    assert len(rows) == 2, proc.stdout
    for row in rows:
        cells = [c.strip() for c in row.strip("|").split("|")][2:]
        seconds = [float(c.split(" s ")[0]) for c in cells]
        ratios = [float(re.search(r"\(([\d.]+)x\)", c).group(1)) for c in cells]
        assert ratios[0] == 1.0 and all(s > 0 for s in seconds)
        for s, r in zip(seconds, ratios, strict=True):
            assert r == pytest.approx(s / seconds[0], rel=0.02, abs=0.01)


def test_mass_cost_refuses_bad_sizes():
    proc = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "mass_cost.py"), "--cells", "2"],
                          capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert proc.returncode == 2 and "--cells >= 4" in proc.stderr
