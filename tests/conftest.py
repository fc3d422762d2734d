"""Fixtures shared by the test modules, and numba's on-disk cache of the test run.

numba's cache: one folder in the system's temporary directory (``mpm-fem-numba-<user>``), set here as
``NUMBA_CACHE_DIR`` before the package is imported, so that every xdist worker and every process a
test starts (they inherit the environment) load the kernels another one compiled, later runs start
warm, and a run writes no cache file into the repository. A ``NUMBA_CACHE_DIR`` set beforehand wins
(a fresh one measures a cold run).
"""

import getpass
import os
import sys
import tempfile
from pathlib import Path


def _user() -> str:
    try:
        return getpass.getuser()
    except (KeyError, OSError):  # no login name (a container without one)
        return "user"


if not os.environ.get("NUMBA_CACHE_DIR"):
    os.environ["NUMBA_CACHE_DIR"] = str(Path(tempfile.gettempdir()) / f"mpm-fem-numba-{_user()}")
if "numba" in sys.modules:  # imported by a plugin before this file: numba reads its settings again
    from numba.core import config

    config.reload_config()

import pytest  # noqa: E402

import mpm_fem.fused.step as fused_module  # noqa: E402


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
