"""The new-extrema count's compiled kernels (mpm_fem/fused/extrema.py) equal to their numpy forms
(mpm_fem/measure/regions.py), the compiled loop's count equal to the readable count of every step, and
runs handing an observer reused arrays (``keeps_particles = False``: the extrema counter, the time
study's recorder) seeing what runs with fresh arrays see."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.particles import make_particles
from mpm_fem.fused.extrema import cells as _cells
from mpm_fem.fused.extrema import merge, remember, tally_step
from mpm_fem.fused.extrema import strict_extrema as _strict_extrema
from mpm_fem.measure.regions import ExtremaCounter, _state, cells, new_extrema, strict_extrema
from mpm_fem.measure.timing import Recorder
from mpm_fem.problems import burgers, sod
from mpm_fem.run.solve import _keeps_particles

NODES = uniform_grid(0.0, 1.0, 0.1).nodes
STRETCHED = np.array([0.0, 0.05, 0.3, 0.31, 0.7, 1.0])


@pytest.mark.parametrize("nodes", [NODES, STRETCHED], ids=["uniform", "stretched"])
def test_compiled_cells_equal_searchsorted_at_nodes_outside_and_out_of_order(nodes):
    rng = np.random.default_rng(3)
    x = np.concatenate([nodes, np.nextafter(nodes, -np.inf), np.nextafter(nodes, np.inf), [-0.5, 1.5, np.nan],
                        rng.uniform(-0.1, 1.1, 500)])
    for points in (x, np.sort(x), x[::-1]):
        assert _cells(nodes, points).tolist() == cells(nodes, points).tolist()
    assert _cells(nodes, np.array([1.0, 0.0, -1.0, np.nan])).tolist() == [nodes.size - 2, 0, 0, nodes.size - 2]


@settings(max_examples=80, deadline=None, derandomize=True)
@given(st.lists(st.floats(-1.0, 1.0, allow_nan=False), min_size=0, max_size=40),
       st.sampled_from([0.0, 1e-9, 1e-3]))
def test_compiled_strict_extrema_equal_the_numpy_form(values, rtol):
    q = np.round(np.asarray(values, dtype=float), 2)  # rounded: plateaus and ties occur
    assert _strict_extrema(q, rtol).tolist() == strict_extrema(q, rtol).tolist()


def test_only_an_observer_that_says_so_is_handed_reused_arrays():
    assert _keeps_particles(lambda *args: None)
    assert not _keeps_particles(None)
    assert not _keeps_particles(ExtremaCounter(uniform_grid(0.0, 1.0, 0.1)))
    assert not _keeps_particles(Recorder(3))


class _Keeping:
    """The same observer behind one that does not say it keeps no particles: fresh arrays."""

    def __init__(self, observer):
        self.counter = observer

    def __call__(self, *args):
        self.counter(*args)


def test_a_run_on_reused_arrays_counts_the_extrema_a_run_on_fresh_arrays_counts():
    """Sod at h = 0.01 with the study's 16 particles per cell: the counts and the final particles
    are the same whether the fused step reuses its arrays or not."""
    settings_ = sod.SodSettings(h=0.01, ppc=16, cfl=0.05)
    grid = uniform_grid(0.0, 1.0, 0.01)
    reused, fresh = ExtremaCounter(grid), _Keeping(ExtremaCounter(grid))
    a = sod.simulate(settings_, progress=False, observer=reused)
    b = sod.simulate(settings_, progress=False, observer=fresh)
    assert reused.summary() == fresh.counter.summary()
    assert reused.steps == a.steps == b.steps > 900
    assert reused.summary()["density"]["new_at_crossing"] > 0  # it counts something
    for name in ("x", "velocity", "density", "energy", "pressure", "volume"):
        assert np.array_equal(getattr(a.particles, name), getattr(b.particles, name)), name


def test_the_recorder_on_reused_arrays_records_what_it_records_on_fresh_arrays():
    """Burgers with its Dirichlet ends and reservoir (the time study's case, shortened): the same
    track, the particle's numbers and the nodal accelerations of every step."""
    settings_ = burgers.BurgersSettings(h=0.02, T=0.05)
    reused, fresh = Recorder(7), _Keeping(Recorder(7))
    burgers.simulate(settings_, progress=False, observer=reused)
    burgers.simulate(settings_, progress=False, observer=fresh)
    a, b = reused.track(), fresh.counter.track()
    assert a.t.size == b.t.size > 20
    for name in ("t", "x", "v", "a_nodes"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name


def _random_step(rng, n, shuffle):
    """Two states of ``n`` particles on [0, 1]: the second moved by up to half a cell of NODES, its
    density and energy rounded (plateaus and ties), and with ``shuffle`` some neighbours swapped."""
    x = np.sort(rng.uniform(0.0, 1.0, n))
    old = make_particles(x, 1.0 / n, np.round(rng.uniform(0.5, 1.0, n), 1), velocity=rng.normal(0.0, 1.0, n),
                         energy=np.round(rng.uniform(1.0, 2.0, n), 1))
    x_new = np.clip(x + rng.uniform(-0.05, 0.05, n), 0.0, 1.0)
    if shuffle:
        x_new = np.sort(x_new)
        k = rng.integers(0, n - 1, n // 4)
        x_new[k], x_new[k + 1] = x_new[k + 1], x_new[k].copy()
    new = old.replace(x=x_new, density=np.round(rng.uniform(0.5, 1.0, n), 1), velocity=rng.normal(0.0, 1.0, n),
                      energy=np.round(rng.uniform(1.0, 2.0, n), 1))
    return old, new


@pytest.mark.parametrize("shuffle", [False, True], ids=["in order", "out of order"])
@pytest.mark.parametrize("nodes", [NODES, STRETCHED], ids=["uniform", "stretched"])
def test_the_compiled_count_of_a_step_equals_the_readable_count(nodes, shuffle):
    rng = np.random.default_rng(11)
    fields = np.array([4, 5], np.int64)  # codes.IRHO, codes.IE
    for n in (3, 40, 400):
        old, new = _random_step(rng, n, shuffle)
        cells_, marks = np.empty(n, np.intp), np.empty((2, n), bool)
        remember(nodes, _state(old), fields, 1e-9, cells_, marks)
        counts = np.zeros((3, 4), np.int64)
        tally_step(nodes, _state(new), fields, 1e-9, 0.5, counts, cells_, marks)
        expected = new_extrema(nodes, old, new, ("density", "energy"), 1e-9, 0.5)
        assert counts.tolist() == expected.tolist(), n
        assert n < 400 or (counts[1:, :2].sum(axis=0) > 0).all()  # it counts something, at crossings and elsewhere
        assert _cells(nodes, new.x).tolist() == cells_.tolist()  # it remembers the new state


class _Readable:
    """An observer that counts every step with the readable :func:`new_extrema` (fresh arrays each step)."""

    def __init__(self, nodes, moving_speed):
        self.nodes, self.moving_speed, self.calls = nodes, moving_speed, 0
        self.totals = np.zeros((3, 4), np.int64)

    def __call__(self, step, t, old, new, state=None):
        counts = new_extrema(self.nodes, old, new, ("density", "energy"), 1e-9, self.moving_speed)
        merge(self.totals, counts)
        self.calls += 1


def test_the_compiled_loop_counts_what_the_readable_count_of_every_step_counts():
    """Sod at h = 0.02, 16 per cell, CFL 0.05: the counter served by the compiled loop (called for the
    first step only) against the readable count called after every step; the same particles."""
    settings_ = sod.SodSettings(h=0.02, ppc=16, cfl=0.05)
    grid = uniform_grid(0.0, 1.0, 0.02)

    class _Calls(ExtremaCounter):
        calls = 0

        def __call__(self, *args):
            type(self).calls += 1
            super().__call__(*args)

    looped, readable = _Calls(grid, moving_speed=0.05), _Readable(grid.nodes, 0.05)
    a = sod.simulate(settings_, progress=False, observer=looped)
    b = sod.simulate(settings_, progress=False, observer=readable)
    assert looped.totals.tolist() == readable.totals.tolist()
    assert looped.steps == readable.calls == a.steps > 400
    assert _Calls.calls < 5  # the loop counted the rest
    assert looped.totals[1, 0] > 0 and looped.totals[2, 1] > 0  # new extrema at crossings and elsewhere
    for name in ("x", "velocity", "density", "energy", "pressure", "volume"):
        assert np.array_equal(getattr(a.particles, name), getattr(b.particles, name)), name
