"""The sweep (mpm_fem.fused.sweep): pass 2 of a USL step (the gas, Burgers) and the next step's pass 1 in one blocked
pass. Runs of several blocks (more than ``BLOCK`` particles) in the compiled loop against the per-step
path bit for bit, on every basis; a step refused in a later block, and a particle that leaves the grid
mid-run, end as the numpy step ends; the sweep is compiled into the loop variants it serves only."""

import numpy as np
import pytest
from numba import njit
from same_runs import FIELDS, assert_same_run

import mpm_fem.fused.compiler as fused_compiler
import mpm_fem.fused.step as fused_module
from mpm_fem.bases import get, names
from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.models.euler import IdealGas
from mpm_fem.core.particles import PositivityError, make_particles
from mpm_fem.core.shape import OutsideGridError
from mpm_fem.core.step import Walls
from mpm_fem.fused.codes import BURGERS, GAS, MUSL, USF, USL
from mpm_fem.fused.sweep import BLOCK, fmax
from mpm_fem.problems.sod import DOMAIN, SodSettings, initial_particles, simulate
from mpm_fem.run.solve import Problem, run

H = 0.0004  # 2,500 cells: 10,000 particles at 4 per cell, five blocks


# the smooth bases' swept variants (1.5-3 min of numba each on a cold 2-core machine) run with the slow tests, and
# uGIMP's on the jittered layout (its rows one node wider: a variant of its own, 20-30 CPU-s)
@pytest.mark.parametrize(("basis", "changes"), [
    pytest.param(b, {}, marks=() if b in ("mpm", "gimp") else pytest.mark.slow) for b in names()] + [
    ("mpm", {"flip": 0.99}), ("mpm", {"layout": "jittered", "seed": 3}),
    pytest.param("gimp", {"layout": "jittered", "seed": 1}, marks=pytest.mark.slow)])
def test_the_swept_loop_equals_the_per_step_path_over_several_blocks(basis, changes, loop_steps, one_at_a_time):
    """Sod's tube on 2,500 cells to T = 0.01 (about 80 steps): each node's sums run across the
    blocks' edges, the rows of the particle-domain bases are stored block by block, and the loop's
    particles and nodal fields equal the per-step path's bit for bit."""
    settings = SodSettings(h=H, ppc=4, T=0.01, cfl=0.3, basis=basis, **changes)
    swept = simulate(settings, progress=False)
    assert swept.particles.n > 4 * BLOCK and sum(loop_steps) > 50  # a widening GIMP row: a step per step
    one_at_a_time()
    assert_same_run(simulate(settings, progress=False), swept)


def test_a_step_refused_in_a_later_block_fails_as_the_numpy_step_does(loop_steps):
    """A time step too long for the shock (0.6 h / 1.2, fixed): the energy of particle 5004 (the
    third block) turns negative in the third step. The loop takes the second step, stops before
    the third, and the per-step path raises the numpy step's error, word for word."""
    settings = SodSettings(h=H, ppc=4)
    grid = uniform_grid(*DOMAIN, settings.h)
    problem = Problem(model=IdealGas(), boundary=Walls(), T=0.05, cfl=1.0, dt=0.6 * settings.h / 1.2)
    errors = []
    for kernel in ("numpy", "fused"):
        with pytest.raises(PositivityError) as err:
            run(problem, grid, initial_particles(settings, grid), progress=False, kernel=kernel)
        errors.append(str(err.value))
    assert errors[0] == errors[1] and "step 2 " in errors[1] and "particle 5004 " in errors[1]
    assert sum(loop_steps) == 1 and 5004 > 2 * BLOCK


def test_a_particle_that_leaves_the_grid_mid_loop_fails_as_the_numpy_step_does(loop_steps):
    """Gas in [0.1, 0.5], nearly without pressure, moving right at speed 1 with a fixed dt = 1.5 h: it travels
    1.5 h a step until the last cell's wall node (v = 0) lets its particles out at once. The sweep
    that moves them out must not pass its sums on: the loop stops, and the per-step path raises the
    numpy step's error, word for word, at the same step."""
    h = 0.001
    grid = uniform_grid(0.0, 1.0, h)
    x = 0.1 + (np.arange(2400) + 0.5) * (0.4 / 2400)  # [0.1, 0.5], six per cell, away from the left wall
    problem = Problem(model=IdealGas(), boundary=Walls(), T=1.0, cfl=1.0, dt=1.5 * h)
    errors = []
    for kernel in ("numpy", "fused"):
        particles = make_particles(x, 0.4 / 2400, 1.0, velocity=1.0, energy=2.5e-6, pressure=1e-6)
        with pytest.raises(OutsideGridError) as err:
            run(problem, grid, particles, progress=False, kernel=kernel)
        errors.append(str(err.value))
    assert errors[0] == errors[1] and sum(loop_steps) > 100


@pytest.mark.parametrize(("model", "scheme", "remedy", "parallel", "sweeps"), [
    (GAS, USL, {}, False, 1), (GAS, USF, {}, False, 0), (GAS, MUSL, {}, False, 0), (BURGERS, USL, {}, False, 1),
    (GAS, USL, {"XPIC_ON": 1}, False, 0), (GAS, USL, {"VOLUME_ON": 1}, False, 0),
    (GAS, USL, {"TAYLOR_ON": 1}, False, 0), (GAS, USL, {}, True, 1), (BURGERS, USL, {}, True, 1),
    (GAS, USL, {"SWEPT": 0}, False, 0), (GAS, USL, {"SWEPT": 0}, True, 0)])
def test_the_sweep_serves_only_the_plain_usl_loop(model, scheme, remedy, parallel, sweeps):
    """The USL loop without a remedy, serial or threaded, compiles the sweep (the gas and Burgers);
    every other loop keeps pass 2 and pass 1 apart (its SWEEP is None and the branch calling it is
    pruned)."""
    constants = dict(BASIS=get("mpm"), MODEL=model, WIDTH=2, SCHEME=scheme, XPIC_ON=0, VOLUME_ON=0, TAYLOR_ON=0,
                     SWEPT=1)
    passes = fused_compiler._Passes(parallel)._loop_passes(**dict(constants, **remedy))
    assert passes["SWEEP_ON"] == sweeps and (passes["SWEEP"] is not None) == bool(sweeps)


def test_fmax_is_max_on_finite_numbers():
    """The sweep's speed: ``llvm.maxnum`` equals Python's ``max`` where the speeds are finite."""
    values = np.random.default_rng(7).random(1000) * 3.0
    assert _reduce(values) == max(0.0, *values)


@njit(cache=True)
def _reduce(a):
    speed = 0.0
    for j in range(a.size):
        speed = fmax(speed, a[j])
    return speed


@pytest.mark.parametrize(("basis", "changes"), [("mpm", {}), ("gimp", {}),
                                                pytest.param("bspline_gimp", {}, marks=pytest.mark.slow),
                                                ("mpm", {"acceleration": "exact"})])
def test_a_swept_burgers_loop_equals_the_per_step_path_over_several_blocks(basis, changes, loop_steps, one_at_a_time):
    """Viscous Burgers (the rarefaction, its exact data at the ends, the reservoir) on 2,500 cells,
    about 200 steps: the viscous force reads the rows the sweep stored block by block; the loop's
    particles and nodal fields equal the per-step path's bit for bit."""
    from mpm_fem.problems import burgers

    settings = burgers.BurgersSettings(h=H, T=2e-4, basis=basis, **changes)
    swept = burgers.simulate(settings, progress=False)
    assert swept.particles.n > 4 * BLOCK and sum(loop_steps) > 100
    one_at_a_time()
    assert_same_run(burgers.simulate(settings, progress=False), swept)


# fast: the point mass on one thread (each loop without the sweep is a variant no other test compiles: 1-3 min
# of numba each on a cold cache); slow: the rest, the stored-row basis and threads included (the fast set's
# two-thread run in 1D is the refused step in the second chunk, the last test here)
@pytest.mark.parametrize(("basis", "threads"), [("mpm", 1), pytest.param("bspline_gimp", 1, marks=pytest.mark.slow),
                                                 pytest.param("mpm", 2, marks=pytest.mark.slow),
                                                 pytest.param("gimp", 2, marks=pytest.mark.slow),
                                                 pytest.param("bspline_gimp", 2, marks=pytest.mark.slow),
                                                 pytest.param("cubic", 3, marks=pytest.mark.slow)])
def test_the_loop_with_and_without_the_sweep_takes_the_same_steps_bit_for_bit(basis, threads):
    """``FusedStep(sweep=False)`` (the benchmarks' baseline) keeps pass 2 and pass 1 apart: the
    same particles after 40 steps as the swept loop, on one thread and on several (each chunk's
    sums added in chunk order, as pass 1's chunks are)."""
    settings = SodSettings(h=H, ppc=4, basis=basis)
    grid = uniform_grid(*DOMAIN, settings.h)
    particles = initial_particles(settings, grid)
    problem = Problem(model=IdealGas(), boundary=Walls(), T=1.0, cfl=0.3)
    out = []
    for sweep in (True, False):
        stepper = fused_module.FusedStep(grid, IdealGas(), Walls(), settings.stages, threads=threads, sweep=sweep)
        first, _ = stepper.step(particles, 0.0, 1e-5)
        new, t, done, _, _ = stepper.advance(first, 1e-5, problem, 1, 10**6, 40)
        out.append((new, t, done))
    (a, t_a, done_a), (b, t_b, done_b) = out
    assert (t_a, done_a) == (t_b, done_b) and done_a == 40
    for name in FIELDS:
        assert np.array_equal(getattr(a, name), getattr(b, name)), name


# both slow: each a threaded variant of its own (Sod 6 min of numba and two threads beside the other test worker);
# the fast set keeps two threads in the refused step below and in tests/test_plane_fused.py
@pytest.mark.parametrize("kind", [pytest.param("sod", marks=pytest.mark.slow),
                                  pytest.param("burgers", marks=pytest.mark.slow)])
def test_the_threaded_swept_loop_equals_the_threaded_per_step_path(kind, loop_steps, one_at_a_time):
    """Two threads: the swept loop's run equals the per-step path's on two threads bit for bit (Sod
    with the particle-domain B-spline's stored rows, Burgers with the point masses)."""
    from mpm_fem.problems import burgers

    if kind == "sod":
        settings, simulate_ = SodSettings(h=H, ppc=4, T=0.01, cfl=0.3, basis="bspline_gimp", threads=2), simulate
    else:
        settings, simulate_ = burgers.BurgersSettings(h=H, T=2e-4, threads=2), burgers.simulate
    swept = simulate_(settings, progress=False)
    assert sum(loop_steps) > 50
    one_at_a_time()
    assert_same_run(simulate_(settings, progress=False), swept)


# fast: the fast set's one two-thread run in 1D (the point mass's parallel passes and threaded loop)
def test_a_step_refused_in_the_second_chunk_fails_as_the_numpy_step_does(loop_steps):
    """The refused step above on two threads: particle 5004 is the second chunk's (5,000 to 9,999);
    the loop stops before the third step and the per-step path raises the numpy step's error."""
    settings = SodSettings(h=H, ppc=4)
    grid = uniform_grid(*DOMAIN, settings.h)
    problem = Problem(model=IdealGas(), boundary=Walls(), T=0.05, cfl=1.0, dt=0.6 * settings.h / 1.2)
    errors = []
    for kernel, threads in (("numpy", 1), ("fused", 2)):
        with pytest.raises(PositivityError) as err:
            run(problem, grid, initial_particles(settings, grid), progress=False, kernel=kernel, threads=threads)
        errors.append(str(err.value))
    assert errors[0] == errors[1] and "particle 5004 " in errors[1] and sum(loop_steps) == 1
