"""The 2D step-cost benchmark (benchmarks/plane_step.py) and its anchor (benchmarks/plane_anchor.py):
the anchor computes the errors the 2D step computes on a small case, and the script runs and prints
its ratios at a tiny size."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

pytest.importorskip("baselines.exact.solids")


def test_the_anchor_computes_the_errors_of_the_2d_step():
    from plane_anchor import PlaneAnchor

    from mpm_fem.plane.run import PlaneSettings, run

    cells = 16
    reference = run(PlaneSettings(h=2.0 / cells, ppc=2, amplitude=0.05, T=0.004))
    assert reference.steps >= 10
    anchor = PlaneAnchor(cells, 2, 0.05, dt=reference.dt)
    anchor.advance(reference.steps)
    assert anchor.t == pytest.approx(reference.t, rel=1e-12)
    want = reference.errors["displacement"]["particles"]
    got = anchor.errors()
    for norm in ("L2", "Linf"):
        gap = abs(got[norm] - want[norm]) / want[norm]
        assert gap < 1e-9, f"anchor {norm} {got[norm]:.12g} against the step's {want[norm]:.12g} (gap {gap:.3g})"
    assert want["L2"] > 1e-4  # the case has an error to compare (A = 0.05 on 16^2 cells)


def test_plane_step_prints_its_ratios_at_a_tiny_size():
    proc = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "plane_step.py"), "--min", "1e2", "--max", "1e3",
                           "--repeat", "1"], capture_output=True, text=True, timeout=900, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    cells = lambda line: [c.strip() for c in line.strip("|").split("|")]  # noqa: E731
    rows = [cells(line) for line in proc.stdout.splitlines() if line.startswith("| ") and "^2 |" in line]
    assert len(rows) == 3, proc.stdout  # 1e2, 10^2.5, 1e3 particles
    for r in rows:
        step, passes, anchor, anchor_force = (float(r[k]) for k in (2, 3, 4, 5))
        assert min(step, passes, anchor, anchor_force) > 0
        assert float(r[7]) == pytest.approx(passes / anchor, rel=0.02, abs=0.01)
        assert float(r[8]) == pytest.approx(step / anchor_force, rel=0.02, abs=0.01)
    targets = proc.stdout.split("Targets:")[1]
    for what in ("passes / anchor", "2D step / 1D loop", "slope", "2 threads / 1 thread"):
        assert what in targets, targets


def test_plane_step_refuses_bad_sizes():
    proc = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "plane_step.py"), "--min", "1e5", "--max", "1e4"],
                          capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert proc.returncode == 2 and "--min <= --max" in proc.stderr
