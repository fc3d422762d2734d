"""Problem set-ups: settings with their defaults in one place, initial particles, exact solutions."""

import numpy as np

from ..grid import uniform_grid
from ..particles import LAYOUTS


def check_run_settings(settings, domain: tuple[float, float]) -> None:
    """The checks every run's settings share: ``h`` divides ``domain``, a known layout, integer
    ``ppc >= 1``, ``T >= 0``, CFL in (0, 1], and valid stage switches. Raises ``ValueError``."""
    uniform_grid(*domain, settings.h)  # raises GridError (a ValueError) unless h divides the domain
    if settings.layout not in LAYOUTS:
        raise ValueError(f"unknown particle layout {settings.layout!r}; choose one of {', '.join(LAYOUTS)}")
    if isinstance(settings.ppc, bool) or not isinstance(settings.ppc, int) or settings.ppc < 1:
        raise ValueError(f"particles per cell must be an integer >= 1, got {settings.ppc!r}")
    if not (np.isfinite(settings.T) and settings.T >= 0):
        raise ValueError(f"the final time T must be >= 0, got {settings.T}")
    if not (0 < settings.cfl <= 1):
        raise ValueError(f"the CFL number must lie in (0, 1], got {settings.cfl}")
    settings.stages  # validates the stage switches
