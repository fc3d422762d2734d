"""The plateau remedies in the fused step (mpm_fem.fused.step) against the numpy step (mpm_fem.core.step):
the PIC/FLIP blend, XPIC(m), the particle-domain B-spline ``"bspline_gimp"`` and the grid volume
reset, to 1e-12 relative (every basis on a uniform grid takes uniform-grid arithmetic), through
the per-step path (the consistent mass; an observer) and the compiled loop (walls or Dirichlet ends
with a reservoir, lumped mass: every remedy), and the loop against the per-step path bit for bit in
every basis."""

import numpy as np
import pytest

from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.models.burgers import ViscousBurgers
from mpm_fem.core.models.euler import IdealGas
from mpm_fem.core.particles import make_particles, seed_positions
from mpm_fem.core.step import Dirichlet, Stages, Walls, explicit_step
from mpm_fem.fused.step import FusedStep, supported
from mpm_fem.problems.burgers import Reservoir
from mpm_fem.problems.sod import SodSettings, simulate
from mpm_fem.run.solve import Problem, run

FIELDS = ("x", "velocity", "volume", "mass", "density", "energy", "pressure")
GRID = uniform_grid(0.0, 1.0, 0.1)


TOLERANCE = 1e-12  # every basis on a uniform grid: the fused step's uniform-grid arithmetic (test_fused.py)
DRIFT = 1e-10  # a whole run with the Taylor reconstruction (its round-off grows: see its test)


def _assert_same(a, b):
    """Each particle and nodal field to ``TOLERANCE`` relative (uniform-grid arithmetic)."""
    assert a.steps == b.steps and a.particles.n == b.particles.n
    pairs = [(name, getattr(a.particles, name), getattr(b.particles, name)) for name in FIELDS]
    pairs += [("m_i", a.nodal_mass, b.nodal_mass), ("v_i", a.nodal_velocity, b.nodal_velocity)]
    for name, u, v in pairs:
        gap = float(np.max(np.abs(u - v), initial=0.0))
        assert gap <= TOLERANCE * float(np.max(np.abs(u), initial=0.0)), f"{name} differs by {gap:.3g}"


def _worst(a, b):
    """The largest relative deviation of any particle or nodal field of two runs (0: bit for bit)."""
    pairs = [(getattr(a.particles, name), getattr(b.particles, name)) for name in FIELDS]
    pairs += [(a.nodal_mass, b.nodal_mass), (a.nodal_velocity, b.nodal_velocity)]
    return max(float(np.max(np.abs(u - v), initial=0.0)) / max(float(np.max(np.abs(u), initial=0.0)), 1e-300)
               for u, v in pairs)


def _allowed(stages):
    """Every basis on a uniform grid (its uniform-grid arithmetic): ``TOLERANCE``."""
    return TOLERANCE


def _gas(boundary, steps):
    """A smooth acoustic wave between walls, or driven by a small piston at both ends."""
    x, V = seed_positions(GRID, 4, "regular")
    rho = 1.0 + 0.1 * np.sin(2 * np.pi * x)
    p = rho**1.4
    particles = make_particles(x, V, rho, 0.05 * np.sin(np.pi * x), p / (0.4 * rho), p)
    g = lambda x, t: 0.02 * np.sin(5.0 * t) + 0.0 * x  # noqa: E731
    wall = Walls() if boundary == "walls" else Dirichlet(g)
    return Problem(model=IdealGas(), boundary=wall, T=steps * 1e-3, cfl=1.0, dt=1e-3), particles


def _burgers(steps):
    """Viscous Burgers with Dirichlet inflow at both ends and a reservoir feeding particles in."""
    x, V = seed_positions(GRID, 4, "jittered", seed=4)
    particles = make_particles(x, V, 1.0, 0.3 + 0.2 * np.sin(2 * np.pi * x))
    g = lambda x, t: 0.3 + 0.1 * np.sin(3.0 * t) + 0.0 * x  # noqa: E731
    return Problem(model=ViscousBurgers(0.01), boundary=Dirichlet(g), particle_boundary=Reservoir(0.025, g),
                   T=steps * 5e-4, cfl=1.0, dt=5e-4), particles


def _compare(case, stages, steps):
    problem, particles = _gas(case, steps) if case in ("walls", "piston") else _burgers(steps)
    reference = run(problem, GRID, particles, stages, progress=False, kernel="numpy")
    fused = run(problem, GRID, particles, stages, progress=False, kernel="fused")
    assert reference.steps >= steps
    _assert_same(reference, fused)
    assert not np.array_equal(fused.particles.velocity, particles.velocity[:fused.particles.n])
    return reference, fused


# each case compiles its basis' passes for its model and schemes: the default run keeps to the gas
# with the point mass (USL, MUSL); the rest run with -m slow, the particle-domain B-spline's too (its
# pass 1 with the stored rows alone takes 1-1.5 CPU-min of numba on a cold cache)
SLOW = pytest.mark.slow


@pytest.mark.parametrize(("remedy", "scheme", "mass", "case"), [
    (dict(flip=0.99), "usl", "lumped", "walls"),
    (dict(flip=0.0), "musl", "lumped", "piston"),
    pytest.param(dict(flip=0.5), "usf", "consistent", "burgers", marks=SLOW),
    (dict(xpic=3), "usl", "lumped", "walls"),
    (dict(xpic=2), "musl", "consistent", "piston"),
    pytest.param(dict(xpic=5), "usl", "lumped", "burgers", marks=SLOW),
    pytest.param(dict(basis="bspline_gimp"), "usl", "lumped", "walls", marks=SLOW),
    pytest.param(dict(basis="bspline_gimp"), "usf", "consistent", "burgers", marks=SLOW),
    pytest.param(dict(basis="bspline_gimp", xpic=5), "musl", "lumped", "piston", marks=SLOW),
    pytest.param(dict(basis="bspline_gimp", flip=0.9), "usl", "lumped", "burgers", marks=SLOW),
    (dict(volume="grid"), "usl", "lumped", "walls"),
    pytest.param(dict(volume="grid"), "usf", "consistent", "piston", marks=SLOW),
    pytest.param(dict(volume="grid", basis="gimp"), "musl", "lumped", "burgers", marks=SLOW),
    # volume + particle-domain B-spline + XPIC: with a piston it compiles its own variants, ~100 s cold
    pytest.param(dict(volume="grid", basis="bspline_gimp", xpic=2), "usl", "lumped", "piston", marks=SLOW),
    (dict(reconstruct="taylor"), "usl", "lumped", "walls"),
    pytest.param(dict(reconstruct="taylor", basis="bspline_gimp"), "musl", "consistent", "piston", marks=SLOW),
    pytest.param(dict(reconstruct="taylor", volume="grid"), "usf", "lumped", "piston", marks=SLOW),
    pytest.param(dict(reconstruct="taylor"), "usf", "consistent", "burgers", marks=SLOW),
    pytest.param(dict(reconstruct="taylor", basis="bspline", volume="grid"), "usl", "lumped", "burgers", marks=SLOW),
])
def test_remedy_in_the_fused_step_equals_the_numpy_step_bit_for_bit(remedy, scheme, mass, case):
    """200 steps (the reservoir adds and removes particles on the Burgers case)."""
    stages = Stages(scheme=scheme, mass=mass, **remedy)
    reference, fused = _compare(case, stages, 200)
    assert _worst(reference, fused) <= _allowed(stages)


def test_the_blend_changes_the_step():
    """The blend is not ignored: FLIP 0.5 and PIC differ from FLIP, and PIC equals XPIC(1)."""
    runs = {k: _compare("walls", Stages(**kw), 50)[1].particles.velocity
            for k, kw in (("flip", {}), ("half", dict(flip=0.5)), ("pic", dict(flip=0.0)), ("xpic1", dict(xpic=1)))}
    assert not np.array_equal(runs["flip"], runs["half"]) and not np.array_equal(runs["half"], runs["pic"])
    assert np.allclose(runs["pic"], runs["xpic1"], rtol=0, atol=1e-14)


# slow: the particle-domain B-spline's loops (its pass 1 with the stored rows alone 1-1.5 CPU-min of numba on a
# cold cache; the volume reset with it and XPIC a USL loop variant of its own)
@pytest.mark.parametrize("remedy", [dict(flip=0.99), pytest.param(dict(basis="bspline_gimp"), marks=SLOW),
                                    dict(xpic=5), dict(volume="grid"),
                                    pytest.param(dict(volume="grid", basis="bspline_gimp", xpic=2), marks=SLOW),
                                    dict(reconstruct="taylor"),
                                    pytest.param(dict(reconstruct="taylor", volume="grid", basis="bspline_gimp"),
                                                 marks=SLOW)])
def test_sod_through_the_compiled_loop_equals_the_numpy_step(remedy, loop_steps):
    """Sod's tube with the CFL step: every remedy runs in the compiled loop (every step but the first)."""
    settings = dict(h=0.02, ppc=4, T=0.05, cfl=0.3, **remedy)
    reference = simulate(SodSettings(**settings, kernel="numpy"), progress=False)
    fused = simulate(SodSettings(**settings), progress=False)
    _assert_same(reference, fused)
    assert _worst(reference, fused) <= TOLERANCE
    assert reference.t == pytest.approx(fused.t, rel=TOLERANCE)
    assert (reference.dt_min, reference.dt_max) == pytest.approx((fused.dt_min, fused.dt_max), rel=TOLERANCE)
    assert sum(loop_steps) == fused.steps - 1


@pytest.mark.parametrize(("remedy", "scheme", "case"), [
    (dict(xpic=3), "usl", "walls"),
    (dict(volume="grid"), "usf", "piston"),
    pytest.param(dict(volume="grid", basis="bspline_gimp", xpic=2), "musl", "walls", marks=SLOW),
    pytest.param(dict(xpic=5, basis="bspline_gimp"), "musl", "piston", marks=SLOW),
    pytest.param(dict(volume="grid", basis="bspline"), "usl", "walls", marks=SLOW),
    pytest.param(dict(xpic=5), "usl", "burgers", marks=SLOW),
    pytest.param(dict(volume="grid", basis="gimp"), "musl", "burgers", marks=SLOW),
    pytest.param(dict(volume="grid", xpic=2), "usf", "burgers", marks=SLOW),
    (dict(reconstruct="taylor", volume="grid"), "usf", "piston"),
    pytest.param(dict(reconstruct="taylor", basis="bspline_gimp"), "musl", "burgers", marks=SLOW),
])
def test_remedies_in_the_compiled_loop_equal_the_per_step_path_bit_for_bit(remedy, scheme, case, loop_steps):
    """Lumped mass, walls or Dirichlet ends (Burgers: and the reservoir): the compiled loop takes
    every step but the first; an observer keeps the run on the per-step path (no loop step). The
    two are the same code and grid arithmetic, so every field is equal bit for bit, in every basis
    (the per-step path equals the numpy step: the test above)."""
    problem, particles = _gas(case, 200) if case in ("walls", "piston") else _burgers(200)
    stages = Stages(scheme=scheme, **remedy)
    per_step = run(problem, GRID, particles, stages, progress=False, observer=lambda *args: None)
    assert sum(loop_steps) == 0
    loop = run(problem, GRID, particles, stages, progress=False)
    assert loop.steps == per_step.steps >= 200 and sum(loop_steps) == loop.steps - 1
    worst = _worst(per_step, loop)
    assert worst == 0.0, f"the loop differs from the per-step path by {worst:.3g}"
    numpy = run(problem, GRID, particles, stages, progress=False, kernel="numpy")
    assert _worst(numpy, loop) <= _allowed(stages)


def test_what_the_fused_step_runs_and_refuses():
    for remedy in (dict(flip=0.5), dict(xpic=5), dict(basis="bspline_gimp"), dict(basis="bspline_gimp", xpic=5),
                   dict(volume="grid"), dict(reconstruct="taylor"),
                   dict(reconstruct="taylor", volume="grid", basis="bspline_gimp")):
        assert supported(IdealGas(), Stages(**remedy)) is None
    assert supported(IdealGas(), Stages(projection="exact", basis="bspline_gimp")) is None  # tests/test_fused_exact.py
    assert "exact" in supported(IdealGas(), Stages(projection="exact", scheme="usf"))


@pytest.mark.slow
@pytest.mark.parametrize("basis", ["mpm", "bspline_gimp"])
@pytest.mark.parametrize("case", ["walls", "burgers"])
def test_taylor_reconstruction_with_the_grid_volume_over_1000_steps(basis, case):
    """The compiled reconstruction keeps the numpy step's operations: every 100th step of a
    1,000-step numpy run, one fused step from the same particles equals one numpy step to
    ``TOLERANCE``. The whole fused run (the compiled loop) stays within ``DRIFT`` of the numpy run:
    the least-squares fit divides by the spread of a cell's particles, so the uniform-grid
    arithmetic's round-off, made afresh every step, grows over the run (measured at most 1.4e-12
    relative, the particle-domain B-spline between walls; 4e-14 after 100 steps), while a defect
    moves a field by the discretisation error, 1e-3 or more."""
    stages = Stages(basis=basis, reconstruct="taylor", volume="grid")
    problem, particles = _gas(case, 1000) if case == "walls" else _burgers(1000)
    states = []
    keep = lambda step, t, old, new, state: states.append((t, old)) if step % 100 == 0 else None  # noqa: E731
    reference = run(problem, GRID, particles, stages, progress=False, kernel="numpy", observer=keep)
    fused = run(problem, GRID, particles, stages, progress=False, kernel="fused")
    assert reference.steps == fused.steps >= 1000 and len(states) >= 10
    assert _worst(reference, fused) <= DRIFT
    step = FusedStep(GRID, problem.model, problem.boundary, stages)
    for t, old in states:
        new, grid_state = explicit_step(GRID, old, problem.model, problem.boundary, t, problem.dt, stages)
        new_fused, grid_fused = step.step(old, t, problem.dt)
        for name in FIELDS:
            u, v = getattr(new, name), getattr(new_fused, name)
            assert float(np.max(np.abs(u - v))) <= TOLERANCE * float(np.max(np.abs(u))), (name, t)
        assert float(np.max(np.abs(grid_state.velocity - grid_fused.velocity))) <= TOLERANCE * float(
            np.max(np.abs(grid_state.velocity)))


@pytest.mark.slow
@pytest.mark.parametrize("scheme", ["usl", "usf", "musl"])
@pytest.mark.parametrize("mass", ["lumped", "consistent"])
@pytest.mark.parametrize("case", ["walls", "piston", "burgers"])
def test_particle_domain_bspline_with_xpic_over_1000_steps(scheme, mass, case):
    reference, fused = _compare(case, Stages(basis="bspline_gimp", xpic=5, scheme=scheme, mass=mass), 1000)
    assert _worst(reference, fused) <= TOLERANCE  # uniform-grid arithmetic, over 1,000 steps


@pytest.mark.slow  # compiles the parallel passes of the particle-domain B-spline and XPIC
def test_threads_with_the_remedies_agree_to_round_off_and_repeat_exactly():
    settings = dict(h=0.02, ppc=4, T=0.02, basis="bspline_gimp", xpic=5)
    one = simulate(SodSettings(**settings), progress=False)
    two, again = (simulate(SodSettings(**settings, threads=2), progress=False) for _ in range(2))
    assert one.steps == two.steps
    for name in FIELDS:
        u, v = getattr(one.particles, name), getattr(two.particles, name)
        assert float(np.max(np.abs(u - v))) <= 1e-12 * float(np.max(np.abs(u))), name
        assert np.array_equal(v, getattr(again.particles, name)), f"{name} changes from run to run"


# slow: the parallel passes of the point mass and its volume reset, and their threaded loop, compile in
# 1-1.5 CPU-min on a cold cache; the fast set's two-thread run in 1D is tests/test_fused_sweep.py's refused step
@pytest.mark.slow
def test_the_grid_volume_on_two_threads_in_the_loop_agrees_with_one_thread_and_leaves_the_input_alone():
    """The point mass with the grid volume reset, between walls (the compiled loop), on two threads:
    a parallel variant of the reset once gave NaN particles when the loop called it (after 45 steps,
    then at the first step of every later run), though the per-step path and one thread were right."""
    problem, particles = _gas("walls", 50)
    kept = {name: getattr(particles, name).copy() for name in FIELDS}
    stages = Stages(volume="grid")
    one = run(problem, GRID, particles, stages, progress=False)
    two, again = (run(problem, GRID, particles, stages, progress=False, threads=2) for _ in range(2))
    assert one.steps == two.steps == again.steps == 50
    for name in FIELDS:
        u, v = getattr(one.particles, name), getattr(two.particles, name)
        assert float(np.max(np.abs(u - v))) <= TOLERANCE * float(np.max(np.abs(u))), name
        assert np.array_equal(v, getattr(again.particles, name)), f"{name} changes from run to run"
        assert np.array_equal(getattr(particles, name), kept[name]), f"the caller's {name} changed"
