"""Two runs compared bit for bit: the compiled loop against the per-step path (tests/test_fused_loop.py,
tests/test_fused_sweep.py)."""

import numpy as np

FIELDS = ("x", "velocity", "volume", "mass", "density", "energy", "pressure")  # the particles' fields


def assert_same_run(a, b):
    """The same steps, time and time steps, and every particle and nodal field equal bit for bit."""
    assert (a.steps, a.t, a.dt_min, a.dt_max) == (b.steps, b.t, b.dt_min, b.dt_max)
    for name in FIELDS:
        u, v = getattr(a.particles, name), getattr(b.particles, name)
        assert np.array_equal(u, v), f"{name} differs by {float(np.max(np.abs(u - v))):.3g}"
    assert np.array_equal(a.nodal_mass, b.nodal_mass) and np.array_equal(a.nodal_velocity, b.nodal_velocity)
