"""Viscous Burgers study (C13, C3, C15): the fast loop, the orders of convergence, the source's table.

The numbers asserted here are measured by ``studies/burgers.py`` on the full set of meshes; these
fast tests run the coarse meshes of the same settings.
"""

import numpy as np
import pytest

from mpm_fem.problems import burgers
from mpm_fem.problems import burgers_fast


def _by_position(result):
    order = np.argsort(result.particles.x)
    P = result.particles
    return P.x[order], P.velocity[order], P.volume[order]


@pytest.mark.parametrize("changes", [
    {},
    {"acceleration": "exact"},
    {"mass": "consistent", "cfl": 0.3},
    {"solution": "cole_hopf", "eps": 0.02},
    {"acceleration": "exact", "dt_rule": "advective", "refine": 2},
])
def test_fast_loop_is_the_general_step_to_round_off(changes):
    """The fused loop and ``run(explicit_step)`` take the same steps: same particles to 1e-12."""
    settings = burgers.BurgersSettings(h=0.02, **changes)
    general = burgers.simulate_general(settings, progress=False)
    fast = burgers_fast.simulate(settings, progress=False)
    assert fast.steps == general.steps and fast.particles.n == general.particles.n
    for a, b, name in zip(_by_position(general), _by_position(fast), ("x", "v", "V")):
        gap = float(np.max(np.abs(a - b)))
        assert gap < 1e-12, f"{name}: fast and general loops differ by {gap:.3g}"
    gap = float(np.max(np.abs(general.nodal_velocity - fast.nodal_velocity)))
    assert gap < 1e-12, f"nodal velocity differs by {gap:.3g}"


def test_settings_and_loops_refuse_what_they_do_not_implement():
    with pytest.raises(ValueError, match="only the exact acceleration"):
        burgers.BurgersSettings(h=0.02, dt_rule="advective")
    with pytest.raises(ValueError, match="unknown weights"):
        burgers.BurgersSettings(h=0.02, weights="mass")
    with pytest.raises(ValueError, match="point mass"):
        burgers_fast.simulate(burgers.BurgersSettings(h=0.02, basis="gimp"))
    with pytest.raises(ValueError, match="USL only"):
        burgers.simulate(burgers.BurgersSettings(h=0.02, basis="gimp", force="slides"))
