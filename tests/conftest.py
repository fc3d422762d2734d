"""Fixtures shared by the test modules."""

import pytest

import mpm_fem.fused.step as fused_module


@pytest.fixture
def loop_steps(monkeypatch):
    """Counts the steps the compiled loop takes (the rest go through FusedStep.step)."""
    taken = []
    advance = fused_module.FusedStep.advance

    def counting(self, *args, **kwargs):
        out = advance(self, *args, **kwargs)
        taken.append(out[2])
        return out

    monkeypatch.setattr(fused_module.FusedStep, "advance", counting)
    return taken


@pytest.fixture
def one_at_a_time(monkeypatch):
    """Runs the fused step without its loop (every step through FusedStep.step), when called."""
    return lambda: monkeypatch.setattr(fused_module.FusedStep, "loops", lambda self, problem: False)
