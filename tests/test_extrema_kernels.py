"""The new-extrema observer's compiled kernels (mpm_fem/measure/regions.py) equal to their numpy forms, and
runs handing an observer reused arrays (``keeps_particles = False``: the extrema counter, the time
study's recorder) seeing what runs with fresh arrays see."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mpm_fem.core.grid import uniform_grid
from mpm_fem.measure.regions import ExtremaCounter, _cells, _strict_extrema, cells, strict_extrema
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
