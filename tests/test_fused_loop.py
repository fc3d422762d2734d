"""The fused step's compiled loop (FusedStep.advance, taken by solve.run between walls or Dirichlet
ends with the lumped mass, with or without a reservoir) against the fused step taken one step at a
time and against the numpy step: the same time steps (CFL from each step's max(c + |v|) or max |v|
with the viscous limit, the last step landing on T) and the same particles, bit for bit. On a uniform
grid every basis takes uniform-grid arithmetic: it equals the numpy step to ``TOLERANCE`` relative
(tests/test_fused.py), and its loop the per-step path bit for bit."""

import numpy as np
import pytest
from same_runs import FIELDS, assert_same_run

import mpm_fem.fused.codes as fused_codes
import mpm_fem.fused.compiler as fused_compiler
import mpm_fem.fused.loop as fused_loop
import mpm_fem.fused.step as fused_module
from baselines.exact.burgers import SOLUTIONS, make_solution
from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.models.burgers import ViscousBurgers
from mpm_fem.core.models.euler import IdealGas
from mpm_fem.core.particles import make_particles, seed_positions
from mpm_fem.core.step import Dirichlet, Stages, Walls, at_times
from mpm_fem.problems import burgers
from mpm_fem.problems.sod import DOMAIN, SodSettings, initial_particles, simulate
from mpm_fem.run.solve import Problem, run

TOLERANCE = 1e-12  # as tests/test_fused.py: max_p |u_fused - u_numpy| <= TOLERANCE max_p |u_numpy|, each field


def _deviation(u, v):
    scale = float(np.max(np.abs(u), initial=0.0))
    gap = float(np.max(np.abs(u - v), initial=0.0))
    return gap / scale if scale > 0 else gap


def _assert_close(a, b):
    """The numpy step against the uniform-grid arithmetic: ``TOLERANCE`` relative, each particle and
    nodal field; returns the worst relative deviation."""
    assert a.steps == b.steps and a.t == pytest.approx(b.t, rel=TOLERANCE)
    pairs = [(name, getattr(a.particles, name), getattr(b.particles, name)) for name in FIELDS]
    pairs += [("m_i", a.nodal_mass, b.nodal_mass), ("v_i", a.nodal_velocity, b.nodal_velocity)]
    for name, u, v in pairs:
        assert _deviation(u, v) <= TOLERANCE, f"{name} differs by {_deviation(u, v):.3g} relative"
    return max(_deviation(u, v) for _, u, v in pairs)


# the quadratic B-spline's loop variant (about 3 min of numba on a cold 2-core machine) runs with the slow tests;
# its compiled rows stay in the fast set (tests/test_walls.py, tests/test_bases.py)
@pytest.mark.parametrize(("basis", "scheme"), [("mpm", "usl"), ("mpm", "usf"), ("mpm", "musl"), ("gimp", "usl"),
                                               pytest.param("bspline", "usl", marks=pytest.mark.slow),
                                               ("gimp", "musl")])
def test_sod_with_the_cfl_step_equals_the_numpy_step_bit_for_bit(basis, scheme, loop_steps, one_at_a_time):
    """Sod's tube to T = 0.1 (about 300 steps of dt = CFL h / max(c + |v|), the last one shortened).
    The loop equals its per-step path bit for bit, and the numpy step to ``TOLERANCE`` (uniform grid)."""
    settings = dict(h=0.01, ppc=4, T=0.1, cfl=0.3, basis=basis, scheme=scheme)
    reference = simulate(SodSettings(**settings, kernel="numpy"), progress=False)
    fused = simulate(SodSettings(**settings), progress=False)
    assert _assert_close(reference, fused) <= TOLERANCE
    one_at_a_time()
    assert_same_run(simulate(SodSettings(**settings), progress=False), fused)
    assert sum(loop_steps) == fused.steps - 1  # every step but the first ran in the loop
    assert fused.t == pytest.approx(0.1, rel=1e-12) and fused.dt_min < fused.dt_max


@pytest.mark.parametrize("scheme", ["usl", "usf", "musl"])
@pytest.mark.parametrize("refine", [1, 3])
def test_burgers_between_walls_with_the_viscous_limit_equals_the_numpy_step(scheme, refine, loop_steps,
                                                                           one_at_a_time):
    """dt = CFL min(h / max|v|, h^2 / (2 eps)) / refine: the advective limit rules at eps = 0.001
    early on, the viscous one at eps = 0.02. The point mass on a uniform grid: the loop against its
    per-step path bit for bit, against the numpy step to ``TOLERANCE``."""
    grid = uniform_grid(0.0, 1.0, 0.02)
    x, V = seed_positions(grid, 4)
    particles = make_particles(x, V, 1.0, np.sin(2 * np.pi * x))
    stages = Stages(scheme=scheme, refine=refine)
    cases = [(Problem(model=ViscousBurgers(eps), boundary=Walls(), T=0.05, cfl=0.5), stages) for eps in (0.001, 0.02)]
    numpy_runs = [run(problem, grid, particles, stages, progress=False, kernel="numpy") for problem, stages in cases]
    loops = [run(problem, grid, particles, stages, progress=False, kernel="fused") for problem, stages in cases]
    assert sum(loop_steps) > 0
    one_at_a_time()
    for (problem, stages), reference, fused in zip(cases, numpy_runs, loops, strict=False):
        _assert_close(reference, fused)
        assert_same_run(run(problem, grid, particles, stages, progress=False, kernel="fused"), fused)


def test_the_loop_stops_where_the_run_must_fail(loop_steps):
    """max_steps reached inside the loop: the same error as the numpy path, at the same step."""
    settings = SodSettings(h=0.01, ppc=4, T=0.1, cfl=0.3)
    grid = uniform_grid(*DOMAIN, settings.h)
    problem = Problem(model=IdealGas(), boundary=Walls(), T=settings.T, cfl=settings.cfl)
    errors = []
    for kernel in ("numpy", "fused"):
        with pytest.raises(RuntimeError) as err:
            run(problem, grid, initial_particles(settings, grid), progress=False, max_steps=50, kernel=kernel)
        errors.append(str(err.value))
    assert errors[0] == errors[1] and "50 steps did not reach T=0.1" in errors[1]
    assert sum(loop_steps) == 49


def _counting_reservoir(monkeypatch):
    """Counts the reservoir's calls that changed the particles."""
    acted = []
    call = burgers.Reservoir.__call__

    def counting(self, particles, grid, t):
        new = call(self, particles, grid, t)
        acted.append(new is not particles)
        return new

    monkeypatch.setattr(burgers.Reservoir, "__call__", counting)
    return acted


@pytest.mark.parametrize(("basis", "scheme", "solution", "changes"), [
    ("mpm", "usl", "rarefaction", {}), ("mpm", "usf", "rarefaction", {}), ("mpm", "musl", "rarefaction", {}),
    ("gimp", "usl", "front", {}), pytest.param("bspline", "usl", "three_exp", {}, marks=pytest.mark.slow),
    ("mpm", "usl", "rarefaction", {"acceleration": "exact"}), ("mpm", "usf", "rarefaction", {"acceleration": "exact"}),
    ("gimp", "musl", "rarefaction", {"acceleration": "exact", "dt_rule": "advective", "refine": 4})])
def test_burgers_with_dirichlet_ends_and_the_reservoir_equals_the_numpy_step(basis, scheme, solution, changes,
                                                                            loop_steps, monkeypatch,
                                                                            one_at_a_time):
    """Viscous Burgers with the exact data at both ends and the reservoir (particles leave at one end
    and are fed in at the other), the calculated or the exact acceleration: the loop stops after
    each step the reservoir acts on and the run re-enters it after the reservoir; the same steps
    as the numpy step and its particles to ``TOLERANCE``, the per-step path's bit for bit."""
    acted = _counting_reservoir(monkeypatch)
    settings = dict(h=0.02, T=0.1, basis=basis, scheme=scheme, solution=solution, **changes)
    reference = burgers.simulate(burgers.BurgersSettings(**settings, kernel="numpy"), progress=False)
    n_numpy = sum(acted)
    fused = burgers.simulate(burgers.BurgersSettings(**settings), progress=False)
    n_fused = sum(acted) - n_numpy
    assert _assert_close(reference, fused) <= TOLERANCE  # uniform grid: to TOLERANCE of the numpy step,
    one_at_a_time()  # bit for bit of the per-step path
    assert_same_run(burgers.simulate(burgers.BurgersSettings(**settings), progress=False), fused)
    assert n_numpy >= 2 and n_fused == n_numpy  # the reservoir acted, as often on both paths
    assert sum(loop_steps) == fused.steps - 1 and len(loop_steps) >= n_numpy  # every step but the first in loops


def test_burgers_whose_reservoir_acts_every_step_stays_on_the_per_step_path(loop_steps):
    """The slides' weights ``h / N_p^i`` are reset by the reservoir after every step: no loop."""
    settings = dict(h=0.02, T=0.02, weights="cell")
    reference = burgers.simulate(burgers.BurgersSettings(**settings, kernel="numpy"), progress=False)
    fused = burgers.simulate(burgers.BurgersSettings(**settings), progress=False)
    _assert_close(reference, fused)  # the point mass on a uniform grid
    assert loop_steps == [] and fused.steps > 5


def test_the_reservoir_is_quiet_exactly_where_it_returns_the_particles_unchanged():
    """``Reservoir.quiet`` and the loop's compiled test agree with the call on the edge cases: a
    particle on an end, just outside it, and an end gap of just below and exactly one spacing."""
    grid = uniform_grid(0.0, 1.0, 0.1)
    reservoir = burgers.Reservoir(0.025, lambda x, t: np.zeros_like(x))
    window = np.array(reservoir.quiet(grid))
    s = 0.025
    inner = np.linspace(0.5 * s, 1.0 - 0.5 * s, 40)
    cases = {"inner": inner, "on both ends": np.r_[0.0, inner, 1.0], "left of a": np.r_[-1e-17, inner],
             "right of b": np.r_[inner, np.nextafter(1.0, 2.0)],
             "gap below s": inner[1:] - inner[1] + np.nextafter(s, 0.0),
             "gap of s": inner[1:] - inner[1] + s}
    verdicts = {}
    for name, x in cases.items():
        particles = make_particles(x, s, 1.0, np.zeros_like(x))
        unchanged = reservoir(particles, grid, 0.0) is particles
        assert fused_loop._reservoir_quiet(x, window) == unchanged, name
        verdicts[name] = unchanged
    assert verdicts == {"inner": True, "on both ends": True, "left of a": False, "right of b": False,
                        "gap below s": True, "gap of s": False}
    assert burgers.Reservoir(s, None, weights="cell").quiet(grid) is None


# slow: the grid volume with the Taylor force on USL, a loop variant no other fast test compiles (10-20 CPU-s of
# numba on a cold cache)
@pytest.mark.parametrize(("scheme", "remedy", "runs"), [
    ("usl", {}, {"PROJECT", "MOVE"}),
    ("usf", {}, {"PROJECT", "MOVE", "UPDATE"}),
    ("musl", {"xpic": 3}, {"PROJECT", "MOVE", "FINISH", "XPIC"}),
    pytest.param("usl", {"volume": "grid", "reconstruct": "taylor"},
                 {"PROJECT", "MOVE", "VOLUME", "GAS_FORCE", "TAYLOR"}, marks=pytest.mark.slow)])
def test_a_loop_variant_carries_only_the_passes_its_run_takes(scheme, remedy, runs, loop_steps, monkeypatch):
    """The scheme and the remedies are compile-time constants of the loop: a plain USL run's loop
    compiles pass 1 and pass 2 only, and each scheme or remedy adds its own passes, no other (the
    others are ``None`` in the variant's scope, so a branch that still called one would not compile).
    Reads the variant the run itself asked for."""
    asked = []
    get = fused_compiler._Passes.get

    def recording(self, fn, **constants):
        made = get(self, fn, **constants)
        if fn is fused_module._advance:
            asked.append((constants, made))
        return made

    steppers = []
    advance = fused_module.FusedStep.advance

    def keeping(self, *args, **kwargs):
        steppers.append(self)
        return advance(self, *args, **kwargs)

    monkeypatch.setattr(fused_compiler._Passes, "get", recording)
    monkeypatch.setattr(fused_module.FusedStep, "advance", keeping)
    result = simulate(SodSettings(h=0.05, ppc=4, T=0.02, scheme=scheme, **remedy), progress=False)
    assert result.steps > 1 and sum(loop_steps) > 0 and asked  # the loop took the steps
    stepper = steppers[-1]  # its scratch holds the remedies' arrays only where they run (memory)
    n_nodes, n_cells = stepper.grid.n_nodes, stepper.grid.n_cells
    xpic, volume, taylor = "xpic" in remedy, "volume" in remedy, "reconstruct" in remedy
    assert stepper._scratch[4].shape == (7 + 4 * xpic + 2 * volume, n_nodes)
    assert stepper._scratch[9].shape[2] == (stepper._state.shape[2] - fused_module._PAD if volume else 0)
    assert stepper._scratch[10].shape == (5, n_cells if taylor else 0)
    for constants, loop in asked:
        scope = loop.py_func.__globals__
        names = ("PROJECT", "MOVE", "UPDATE", "FINISH", "VISCOUS", "GAS_FORCE", "VOLUME", "XPIC", "TAYLOR")
        assert {name for name in names if scope[name] is not None} == runs
        assert (constants["SCHEME"], constants["XPIC_ON"], constants["VOLUME_ON"], constants["TAYLOR_ON"]) == (
            fused_codes.SCHEME_CODE[scheme], int("xpic" in remedy), int("volume" in remedy),
            int("reconstruct" in remedy))
        assert all(scope[name] == value for name, value in constants.items())


@pytest.mark.parametrize("name", sorted(SOLUTIONS))
def test_the_dirichlet_table_holds_the_floats_of_one_call_per_time(name):
    """``Dirichlet.end_values_at`` (the loop's table) gives, at every time, the floats of
    ``end_values`` at that time: the table changes no number of a run."""
    solution = make_solution(name, 0.01)
    grid = uniform_grid(*solution.domain, 0.01)
    boundary = Dirichlet(solution.v)
    times = np.add.accumulate(np.concatenate(([0.0], np.full(500, 0.5 * 0.01**2 / 0.02))))
    table = boundary.end_values_at(grid, times)
    assert table.shape == (times.size, 2)
    assert np.array_equal(table, np.array([boundary.end_values(grid, t) for t in times]))


def test_the_loop_reads_the_dirichlet_data_from_the_table_when_its_time_step_is_steady(monkeypatch):
    """With the stable rule's steady time step the loop reads ``g`` from the table: fewer than one
    call of ``g`` per ten steps (one per step without the table), the same particles as the numpy step."""
    calls = []
    original = Dirichlet.end_values

    def counting(self, grid, t):
        calls.append(t)
        return original(self, grid, t)

    monkeypatch.setattr(Dirichlet, "end_values", counting)
    settings = dict(h=0.01, T=0.1, solution="rarefaction", eps=0.045)
    fused = burgers.simulate(burgers.BurgersSettings(**settings), progress=False)
    in_loop = len(calls)
    reference = burgers.simulate(burgers.BurgersSettings(**settings, kernel="numpy"), progress=False)
    assert _assert_close(reference, fused) <= TOLERANCE
    assert fused.steps > 100 and in_loop < fused.steps / 10


@pytest.mark.parametrize("name", sorted(SOLUTIONS))
def test_a_table_of_exact_accelerations_holds_the_floats_of_one_call_per_time(name):
    """``at_times`` of the exact acceleration ``eps v_xx`` (the loop's table with the exact acceleration)
    gives the floats of one call per time; a function that does not broadcast is called per time."""
    solution = make_solution(name, 0.02)
    x = np.linspace(*solution.domain, 201)
    times = np.add.accumulate(np.concatenate(([0.0], np.full(300, 3e-4))))

    def acceleration(x, t):
        return 0.02 * solution.v_xx(x, t)

    table = at_times(acceleration, x, times)
    assert table.shape == (times.size, x.size) and table.flags.c_contiguous
    assert np.array_equal(table, np.array([acceleration(x, t) for t in times]))
    scalar_time = at_times(lambda x, t: acceleration(x, float(t)), x, times[:5])
    assert np.array_equal(scalar_time, table[:5])


@pytest.mark.parametrize("dt_rule", ["stable", "advective"])
def test_the_tables_never_evaluate_much_more_than_the_steps_need(dt_rule, monkeypatch):
    """The tables look ahead only as far as the run went since the last one was built: at most about
    three evaluations of ``g`` and of the exact acceleration per step, whatever the reservoir does
    (a table built far ahead at every call, when the reservoir acts every step, evaluated hundreds
    per step: 12,193 exact accelerations for 158 steps, the regression this guards against)."""
    counted = {"g": 0, "a": 0}
    end_values, end_values_at, at_times_fused = Dirichlet.end_values, Dirichlet.end_values_at, fused_module.at_times

    def one(self, grid, t):
        counted["g"] += 1
        return end_values(self, grid, t)

    def many(self, grid, times):
        counted["g"] += len(times)
        return end_values_at(self, grid, times)

    def accelerations(f, x, times):
        counted["a"] += len(times)
        return at_times_fused(f, x, times)

    monkeypatch.setattr(Dirichlet, "end_values", one)
    monkeypatch.setattr(Dirichlet, "end_values_at", many)
    monkeypatch.setattr(fused_module, "at_times", accelerations)
    for solution, eps in (("rarefaction", 0.045), ("three_exp", 0.02)):  # the second's reservoir acts every step
        counted.update(g=0, a=0)
        settings = dict(h=0.0025, T=0.05, ppc=16, solution=solution, eps=eps, acceleration="exact",
                        dt_rule=dt_rule, cfl=0.125)
        fused = burgers.simulate(burgers.BurgersSettings(**settings), progress=False)
        assert fused.steps > 50
        assert counted["g"] <= 3 * fused.steps + 2 and counted["a"] <= 3 * fused.steps + 2, (solution, counted)
