"""The compiled 2D step (mpm_fem/plane/fused.py) equals the numpy step (mpm_fem/plane/step.py) to
round-off: ten steps of the axis-aligned solution at A = 0.05 on a periodic 16 x 16 mesh (particles
cross cells), regular and jittered layouts, for each compiled basis; the vortex on its non-periodic
grid; the PIC/FLIP blend; two threads; an inverted particle named as the numpy step names it; the
stages it does not serve refused. The B-splines' variants take minutes to compile: slow; uGIMP's (15-20 CPU-s of
numba on a cold cache) too."""

from __future__ import annotations

import numpy as np
import pytest

from mpm_fem.bases.shape import OutsideGridError
from mpm_fem.core.step import Stages
from mpm_fem.plane.fused import PlaneFused, served
from mpm_fem.plane.grid import plane_grid
from mpm_fem.plane.model import InversionError
from mpm_fem.plane.problems import seed_reference, start
from mpm_fem.plane.run import PlaneSettings, setup
from mpm_fem.plane.state import PlaneParticles
from mpm_fem.plane.step import step_with_grid

solids = pytest.importorskip("baselines.exact.solids")
MATERIAL = solids.Material(1e4, 0.3, 1.0)
ROUND_OFF = 1e-12  # of each field's scale: ten steps of sums taken in another order
FAST = ("mpm", pytest.param("gimp", marks=pytest.mark.slow))
SLOW = ("bspline", "cubic", "bspline_gimp")


def _both(settings: PlaneSettings, steps: int = 10, threads: int = 1):
    """``steps`` steps of the numpy and of the compiled step from the same start: their particles,
    their last grid states, the start and the grid."""
    solution, grid, (X, V0, lengths), _ = setup(settings)
    dt = settings.cfl * min(grid.h) / solution.material.c
    state = start(solution, X, V0, lengths, dt)
    fused = PlaneFused(grid, settings.basis, threads)
    a = b = state
    for n in range(steps):
        a, grid_a = step_with_grid(a, grid, settings.basis, solution.material, dt, n * dt, solution.body_force,
                                   settings.stages)
        b, grid_b = fused.step_with_grid(b, solution.material, dt, n * dt, solution.body_force, settings.stages)
    return (a, grid_a), (b, grid_b), state, grid


def _gaps(a, b) -> dict:
    """Max abs differences of x, v, F over each field's scale (max |x - X| for x)."""
    scale = {"x": np.abs(a.x - a.X).max(), "v": np.abs(a.v).max(), "F": np.abs(a.F).max()}
    return {k: float(np.abs(getattr(a, k) - getattr(b, k)).max() / scale[k]) for k in scale}


def _crossed(state, new, grid) -> int:
    """Particles whose cell changed."""
    cells = lambda p: np.floor((grid.fold(p.x) - [a.lo for a in grid.axes]) / grid.h).astype(int)  # noqa: E731
    return int(np.any(cells(state) != cells(new), axis=1).sum())


def _check_equal(basis, layout):
    s = PlaneSettings(h=0.125, ppc=2, amplitude=0.05, basis=basis, layout=layout, cfl=0.25)
    (a, grid_a), (b, grid_b), state, grid = _both(s)
    crossed = _crossed(state, a, grid)
    assert crossed > 0.1 * state.n, f"{basis}, {layout}: only {crossed} of {state.n} particles crossed a cell"
    gaps = _gaps(a, b)
    assert max(gaps.values()) < ROUND_OFF, f"{basis}, {layout}: compiled - numpy over scale {gaps}"
    a_gap = np.abs(grid_a.acceleration - grid_b.acceleration).max() / np.abs(grid_a.acceleration).max()
    assert a_gap < ROUND_OFF, f"{basis}, {layout}: nodal acceleration differs by {a_gap:.3g} of its scale"
    assert np.allclose(a.volume, b.volume, rtol=ROUND_OFF, atol=0)
    return gaps


@pytest.mark.parametrize("layout", ["regular", "jittered"])
@pytest.mark.parametrize("basis", FAST)
def test_the_compiled_step_equals_the_numpy_step_to_round_off(basis, layout):
    gaps = _check_equal(basis, layout)
    assert max(gaps.values()) < ROUND_OFF, gaps


@pytest.mark.slow
@pytest.mark.parametrize("layout", ["regular", "jittered"])
@pytest.mark.parametrize("basis", SLOW)
def test_the_compiled_b_spline_steps_equal_the_numpy_step_to_round_off(basis, layout):
    gaps = _check_equal(basis, layout)
    assert max(gaps.values()) < ROUND_OFF, gaps


def test_the_compiled_step_equals_the_numpy_step_with_the_pic_flip_blend():
    blend = PlaneSettings(h=0.125, ppc=2, amplitude=0.05, layout="jittered", flip=0.5)
    (a, _), (b, _), _, _ = _both(blend)
    gaps = _gaps(a, b)
    assert max(gaps.values()) < ROUND_OFF, f"flip 0.5: compiled - numpy over scale {gaps}"


def _check_vortex(basis):
    vortex = PlaneSettings(problem="vortex", h=0.125, ppc=2, basis=basis)  # jittered: its free surface inverts
    (a, _), (b, _), state, grid = _both(vortex, steps=5)
    assert not any(grid.periodic)
    gaps = _gaps(a, b)
    assert max(gaps.values()) < ROUND_OFF, f"{basis}, vortex: compiled - numpy over scale {gaps}"
    return gaps


@pytest.mark.parametrize("basis", FAST)
def test_the_compiled_step_equals_the_numpy_step_on_the_vortex_s_walled_grid(basis):
    gaps = _check_vortex(basis)
    assert max(gaps.values()) < ROUND_OFF, gaps


@pytest.mark.slow
@pytest.mark.parametrize("basis", SLOW)
def test_the_compiled_b_spline_steps_equal_the_numpy_step_on_the_vortex_s_walled_grid(basis):
    gaps = _check_vortex(basis)
    assert max(gaps.values()) < ROUND_OFF, gaps


def test_two_threads_equal_one_thread_to_round_off():
    s = PlaneSettings(h=0.125, ppc=2, amplitude=0.05, layout="jittered")
    (_, _), (one, _), _, _ = _both(s, steps=5, threads=1)
    (_, _), (two, _), _, _ = _both(s, steps=5, threads=2)
    gaps = _gaps(one, two)
    assert max(gaps.values()) < ROUND_OFF, f"two threads - one thread over scale {gaps}"


def _converging(grid):
    """Particles at rest, unstrained, whose velocity field converges at x = 1 (inverts them in one step
    of 0.05 s)."""
    X, V0, lengths = seed_reference(grid, 2, "jittered", 0)
    n = X.shape[0]
    v = np.column_stack((-np.sin(np.pi * X[:, 0]) * 40.0, np.zeros(n)))
    F = np.broadcast_to(np.eye(2), (n, 2, 2)).copy()
    return PlaneParticles(X=X, x=X.copy(), v=v, F=F, volume=V0.copy(), volume0=V0, mass=MATERIAL.rho0 * V0,
                          lengths=lengths)


def test_an_inverted_particle_is_named_as_the_numpy_step_names_it():
    grid = plane_grid((0.0, 0.0), (2.0, 2.0), 0.25, (True, True))
    state = _converging(grid)
    with pytest.raises(InversionError) as numpy_error:
        step_with_grid(state, grid, "mpm", MATERIAL, 0.05, 0.0, None)
    with pytest.raises(InversionError) as compiled_error:
        PlaneFused(grid, "mpm").step_with_grid(state, MATERIAL, 0.05, 0.0, None)
    assert compiled_error.value.particle == numpy_error.value.particle, (compiled_error.value, numpy_error.value)
    assert compiled_error.value.J == pytest.approx(numpy_error.value.J, rel=1e-12)
    assert str(compiled_error.value.at(3, 0.15)) == str(numpy_error.value.at(3, 0.15))


def test_a_particle_outside_a_wall_is_refused():
    grid = plane_grid((0.0, 0.0), (2.0, 2.0), 0.25)
    state = _converging(grid)
    x = state.x.copy()
    x[5, 1] = 2.5
    with pytest.raises(OutsideGridError, match="particle 5 at"):
        PlaneFused(grid, "mpm").step_with_grid(state.replace(x=x), MATERIAL, 1e-4, 0.0, None)


@pytest.mark.parametrize("change", [dict(mass="consistent"), dict(mass="exact"), dict(projection="exact"),
                                    dict(interpolation="exact"), dict(acceleration="exact"), dict(scheme="musl")])
def test_the_stages_it_does_not_serve_are_refused(change):
    stages = Stages(**change)
    assert not served("mpm", stages) and served("mpm", Stages())
    grid = plane_grid((0.0, 0.0), (2.0, 2.0), 0.25, (True, True))
    name = next(iter(change))
    with pytest.raises(ValueError, match=f"compiled 2D step runs with {name}="):
        PlaneFused(grid, "mpm").step_with_grid(_converging(grid), MATERIAL, 1e-4, 0.0, None, stages)


def test_the_compiled_body_force_equals_the_solution_s_to_round_off():
    from mpm_fem.plane.forces import compiled_force

    rng = np.random.default_rng(3)
    for solution in (solids.AxisAligned(amplitude=0.05), solids.AxisAligned(amplitude=0.05, amplitude_y=0.02),
                     solids.AxisAligned(amplitude=0.05, amplitude_y=0.0)):
        force = compiled_force(solution)
        scale = np.pi**2 * solution.amplitude * solution.material.c**2  # the force's magnitude
        for X in (2 * rng.random((500, 2)), 2 * rng.random((300, 2))):  # a second X: its own factors
            for t in (0.0, 0.0013, 0.0071):
                want = solution.body_force(X[:, 0], X[:, 1], t)
                gap = np.abs(force(X[:, 0], X[:, 1], t) - want).max() / scale
                assert gap < 1e-14, f"{solution}, t = {t}: compiled body force - numpy over scale {gap:.3g}"
                out = force.into(X, t, np.empty_like(X))
                assert np.abs(out.T - want).max() / scale < 1e-14
    assert compiled_force(solids.GeneralizedVortex()) is None


def test_reused_arrays_and_the_compiled_force_give_the_numpy_force_s_steps():
    from mpm_fem.plane.forces import compiled_force

    s = PlaneSettings(h=0.125, ppc=2, amplitude=0.05, layout="jittered")
    solution, grid, (X, V0, lengths), _ = setup(s)
    dt = s.cfl * min(grid.h) / solution.material.c
    a = b = start(solution, X, V0, lengths, dt)
    plain, reused = PlaneFused(grid, "mpm"), PlaneFused(grid, "mpm", reuse=True)
    force = compiled_force(solution)
    kept = []
    for n in range(6):
        a = plain.step(a, solution.material, dt, n * dt, solution.body_force)
        b = reused.step(b, solution.material, dt, n * dt, force)
        kept.append(b.x)
    gaps = _gaps(a, b)
    assert max(gaps.values()) < ROUND_OFF, f"reused arrays, compiled force - plain, numpy force: {gaps}"
    assert kept[-1] is kept[-3] and kept[-1] is not kept[-2]  # two sets written in turn


def test_a_run_takes_the_compiled_step_where_it_serves_with_the_numpy_step_s_errors():
    from mpm_fem.plane import axis, run

    kw = dict(h=0.125, ppc=2, amplitude=0.05, T=0.004, layout="jittered")
    compiled, plain = axis(compiled=True, **kw), axis(**kw)  # the numpy step by default
    assert compiled.compiled and not plain.compiled and compiled.steps == plain.steps >= 10
    for norm in ("L2", "Linf", "L2_max"):
        want, got = plain.errors["displacement"]["particles"][norm], compiled.errors["displacement"]["particles"][norm]
        assert abs(got - want) < 1e-10 * want, f"{norm}: compiled {got!r}, numpy {want!r}"
    want, got = plain.errors["acceleration"]["nodes"]["L2"], compiled.errors["acceleration"]["nodes"]["L2"]
    assert abs(got - want) < 1e-10 * want, f"nodal acceleration L2: compiled {got!r}, numpy {want!r}"
    assert not axis(mass="consistent", compiled=True, **kw).compiled  # served on the numpy step
    seen = []  # an observer keeps the states: each step's arrays are its own
    run(PlaneSettings(compiled=True, **kw), observer=lambda n, t, p, g: seen.append((p, p.x.copy())))
    assert all(np.array_equal(p.x, x) for p, x in seen), "a kept state was overwritten by a later step"


def test_compiled_must_be_a_bool():
    with pytest.raises(ValueError, match="compiled must be True or False"):
        PlaneSettings(compiled="yes")
