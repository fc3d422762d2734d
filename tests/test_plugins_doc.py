"""The example bases of ``docs/plugins.md``, built from the page's own code blocks: the numpy-only P1
hats give the numpy step's P1 numbers bit for bit and the compiled step's to round-off; the subclass
of ``Point`` inherits the compiled kernels and gives P1's compiled numbers bit for bit."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import mpm_fem
from mpm_fem.bases import plugins, registry

DOC = Path(__file__).resolve().parent.parent / "docs" / "plugins.md"
FIELDS = ("x", "density", "velocity", "energy", "volume")
RUN = dict(h=0.05, ppc=2, T=0.05)  # 17 steps: short, past the first wave interactions


@pytest.fixture
def doc_module(tmp_path, monkeypatch):
    """The page's Python blocks that define the example bases, as the module ``plugins_doc_example``;
    the bases register into a copy of the registry."""
    monkeypatch.setattr(registry, "_BASES", dict(registry._BASES))
    monkeypatch.setattr(plugins.LOADER, "loaded", {})
    monkeypatch.setattr(plugins.LOADER, "failed", {})
    blocks = [b for b in re.findall(r"```python\n(.*?)```", DOC.read_text(), re.S) if "class MyHat" in b]
    assert len(blocks) == 2, f"docs/plugins.md should hold the two example bases, found {len(blocks)} blocks"
    (tmp_path / "plugins_doc_example.py").write_text("\n\n".join(blocks))
    monkeypatch.syspath_prepend(str(tmp_path))
    return "plugins_doc_example"


def _gap(ours, reference) -> float:
    """The largest difference of the particle fields, relative to each field's largest value."""
    return max(float(np.abs(getattr(ours.particles, f) - getattr(reference.particles, f)).max()
                     / np.abs(getattr(reference.particles, f)).max()) for f in FIELDS)


def test_the_pages_numpy_only_hats_are_p1_on_the_numpy_step_bit_for_bit(doc_module):
    ours = mpm_fem.sod(basis=f"{doc_module}:MyHat", **RUN)
    assert ours.settings.basis == "myhat" and ours.result.kernel == "numpy"
    numpy_p1 = mpm_fem.sod(kernel="numpy", **RUN)
    assert ours.result.steps == numpy_p1.result.steps > 10
    for f in FIELDS:
        assert np.array_equal(getattr(ours.particles, f), getattr(numpy_p1.particles, f)), f
    compiled_p1 = mpm_fem.sod(**RUN)
    gap = _gap(ours, compiled_p1)
    assert compiled_p1.result.kernel == "fused" and 0 < gap < 1e-12, f"numpy-only hats vs compiled P1: {gap:.3g}"


def test_the_pages_subclass_of_point_inherits_the_compiled_kernels_bit_for_bit(doc_module):
    ours = mpm_fem.sod(basis=f"{doc_module}:MyHatCompiled", **RUN)
    p1 = mpm_fem.sod(basis="p1", **RUN)
    assert ours.result.kernel == p1.result.kernel == "fused" and ours.result.steps == p1.result.steps
    for f in FIELDS:
        assert np.array_equal(getattr(ours.particles, f), getattr(p1.particles, f)), f
