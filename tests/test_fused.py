"""The fused compiled step (mpm_fem.fused.step) against the numpy step it compiles (mpm_fem.core.step).

Every combination of basis, scheme, mass, model and boundary (the fast set a pairwise cover of
basis, scheme and model, the slow set the rest) runs 1,000 steps through ``solve.run`` twice,
``kernel="numpy"`` and ``kernel="fused"``: the particle states must agree bit for bit where the
kernel keeps the numpy step's arithmetic order (every basis on a grid that is not uniform to
round-off), and to ``TOLERANCE`` where it does not (every basis on a uniform grid: uniform-grid
arithmetic), on smooth data and on Sod's shocked tube. Threads group the sums differently: equal to
round-off, and the same on every run. The checks of a run (positivity, finiteness, particles outside
the grid) raise the same errors from both paths.
"""

from dataclasses import dataclass

import numpy as np
import pytest

from mpm_fem.bases import get, names
from mpm_fem.core.grid import grid_from_nodes, uniform_grid
from mpm_fem.core.models.burgers import ViscousBurgers
from mpm_fem.core.models.euler import IdealGas
from mpm_fem.core.particles import PositivityError, make_particles, seed_positions
from mpm_fem.core.shape import OutsideGridError
from mpm_fem.core.step import SCHEMES, Dirichlet, Stages, Walls
from mpm_fem.fused.step import FusedStep, supported
from mpm_fem.problems.burgers import Reservoir
from mpm_fem.problems.sod import SodSettings, simulate
from mpm_fem.run.solve import Problem, run

FIELDS = ("x", "velocity", "volume", "mass", "density", "energy", "pressure")
STEPS = 1000
GRID = uniform_grid(0.0, 1.0, 0.1)


def _seed(seed, regular):
    """Four jittered particles per cell, or regular ones (a B-spline particle close to a wall can
    cross it: the wall holds the node, not the particle; the regular layout keeps h/8 away)."""
    return seed_positions(GRID, 4, "regular" if regular else "jittered", seed=seed)


def _gas_particles(regular):
    """A smooth acoustic wave: density, velocity and pressure perturbed by a sine."""
    x, V = _seed(3, regular)
    rho = 1.0 + 0.1 * np.sin(2 * np.pi * x)
    p = rho**1.4
    return make_particles(x, V, rho, 0.05 * np.sin(np.pi * x), p / (0.4 * rho), p)


def _burgers_particles(regular, walls):
    """Between walls a flow that vanishes there, ``u = 0.2 sin(2 pi x)`` (its shock forms at
    ``t = 1/(0.4 pi)``, after the 1,000 steps); with Dirichlet ends an inflow, ``0.3 + 0.2 sin(2 pi x)``.
    (An inflow between walls piles the particles against the right wall, and particle-domain
    B-spline particles cross it: the numpy step then stops with ``OutsideGridError``, rightly.)"""
    x, V = _seed(4, regular)
    return make_particles(x, V, 1.0, (0.0 if walls else 0.3) + 0.2 * np.sin(2 * np.pi * x))


def _burgers_inflow(x, t):
    return 0.3 + 0.1 * np.sin(3.0 * t) + 0.0 * x


def _case(model, boundary, steps=STEPS, basis="mpm"):
    """(problem, particles) of ``steps`` fixed steps for the model and boundary named."""
    regular = boundary == "walls" and get(basis).uniform
    if model == "gas":
        problem = dict(model=IdealGas(), T=steps * 1e-3, cfl=1.0, dt=1e-3)
        particles = _gas_particles(regular)
        g = lambda x, t: 0.02 * np.sin(5.0 * t) + 0.0 * x  # noqa: E731 (a small piston at both ends)
    else:
        problem = dict(model=ViscousBurgers(0.01), T=steps * 5e-4, cfl=1.0, dt=5e-4)
        particles = _burgers_particles(regular, boundary == "walls")
        g = _burgers_inflow
    if boundary == "walls":
        return Problem(boundary=Walls(), **problem), particles
    inflow = Reservoir(0.025, g) if model == "burgers" else None
    return Problem(boundary=Dirichlet(g), particle_boundary=inflow, **problem), particles


# Every basis on a uniform grid (uniform-grid arithmetic) against the numpy step: each field of the
# particles and the grid, max_p |u_fused - u_numpy| <= TOLERANCE max_p |u_numpy| (measured: at most 6e-14).
TOLERANCE = 1e-12


def _deviation(u, v):
    """``max |u - v| / max |u|`` (0 where both are 0): the relative deviation in the max norm."""
    scale = float(np.max(np.abs(u), initial=0.0))
    gap = float(np.max(np.abs(u - v), initial=0.0))
    return gap / scale if scale > 0 else gap


def _assert_same(a, b, tolerance=0.0):
    """The same run: bit for bit, or (``tolerance > 0``) each field to ``tolerance`` relative."""
    assert a.steps == b.steps and a.particles.n == b.particles.n
    pairs = [(name, getattr(a.particles, name), getattr(b.particles, name)) for name in FIELDS]
    pairs += [("m_i", a.nodal_mass, b.nodal_mass), ("v_i", a.nodal_velocity, b.nodal_velocity)]
    for name, u, v in pairs:
        if tolerance:
            assert _deviation(u, v) <= tolerance, f"{name} differs by {_deviation(u, v):.3g} relative"
        else:
            assert np.array_equal(u, v), f"{name} differs by {float(np.max(np.abs(u - v))):.3g}"


def _worst(a, b):
    """The largest relative deviation of any particle or nodal field of two runs (0: bit for bit)."""
    pairs = [(getattr(a.particles, name), getattr(b.particles, name)) for name in FIELDS]
    pairs += [(a.nodal_mass, b.nodal_mass), (a.nodal_velocity, b.nodal_velocity)]
    return max(_deviation(u, v) for u, v in pairs)


def _compare(basis, scheme, mass, model, boundary, steps):
    problem, particles = _case(model, boundary, steps, basis)
    stages = Stages(basis=basis, scheme=scheme, mass=mass)
    reference = run(problem, GRID, particles, stages, progress=False, kernel="numpy")
    fused = run(problem, GRID, particles, stages, progress=False, kernel="fused")
    assert reference.steps >= steps
    _assert_same(reference, fused, TOLERANCE)
    assert not np.array_equal(fused.particles.x[:10], particles.x[:10])  # the particles did move
    return reference, fused


BASES, MODELS = ("mpm", "gimp", "bspline"), ("gas", "burgers")  # the schemes: mpm_fem.core.step.SCHEMES


def _pairwise(basis, scheme, model):
    """Whether the triple is in the fast set: ``model = MODELS[(b + s) % 2]`` for basis ``b`` and
    scheme ``s``, 9 of the 18 triples, which still pair every basis with every scheme, every basis
    with both models and every scheme with both models. Each triple is a compiled loop variant of
    its own (about 25 s of numba on a cold cache); the other 9 run with the slow tests. The smooth bases'
    triples (the quadratic and cubic B-splines: 1.5-4 min of numba each on a cold 2-core machine) all run with
    the slow tests; their compiled rows stay in the fast set (tests/test_walls.py, tests/test_cubic.py)."""
    if basis in ("bspline", "cubic"):
        return False
    return model == MODELS[(names().index(basis) + SCHEMES.index(scheme)) % 2]


COMBINATIONS = pytest.mark.parametrize(("basis", "scheme", "model", "boundary"), [
    pytest.param(basis, scheme, model, boundary, marks=() if _pairwise(basis, scheme, model) else pytest.mark.slow)
    for basis in BASES for scheme in SCHEMES for model in MODELS for boundary in ("walls", "dirichlet")])


@COMBINATIONS
@pytest.mark.parametrize("mass", ["lumped", "consistent"])
def test_fused_equals_the_numpy_step(basis, scheme, mass, model, boundary):
    """1,000 steps with the lumped mass; 100 with the consistent mass (its sparse solve is slow in
    both paths: the 1,000-step runs are the slow test below). Bit for bit, or to ``TOLERANCE``.
    Every combination: the fast set the pairwise ones (:func:`_pairwise`), the slow set the rest."""
    reference, fused = _compare(basis, scheme, mass, model, boundary, STEPS if mass == "lumped" else 100)
    assert _worst(reference, fused) <= TOLERANCE


@pytest.mark.slow
@COMBINATIONS
def test_fused_equals_the_numpy_step_over_1000_steps_with_the_consistent_mass(basis, scheme, model, boundary):
    reference, fused = _compare(basis, scheme, "consistent", model, boundary, STEPS)
    assert _worst(reference, fused) <= TOLERANCE


@pytest.mark.slow
@pytest.mark.parametrize(("scheme", "model", "boundary"), [
    (scheme, model, boundary) for scheme in ("usl", "usf", "musl") for model in ("gas", "burgers")
    for boundary in ("walls", "dirichlet")])
@pytest.mark.parametrize("mass", ["lumped", "consistent"])
def test_particle_domain_bspline_equals_the_numpy_step_over_1000_steps(scheme, mass, model, boundary):
    """The particle-domain B-spline (uniform-grid arithmetic) through every combination, 1,000 steps."""
    reference, fused = _compare("bspline_gimp", scheme, mass, model, boundary, STEPS)
    assert _worst(reference, fused) <= TOLERANCE


@pytest.mark.parametrize("scheme", ["usl", "usf", "musl"])
@pytest.mark.parametrize("mass", ["lumped", "consistent"])
def test_point_mass_on_sods_shocked_tube_within_the_tolerance(scheme, mass):
    """Sod's tube, 1,000 CFL steps (to T = 0.2: the shock, contact and rarefaction formed): the
    uniform-grid arithmetic stays within ``TOLERANCE`` of the numpy step through the shock."""
    settings = dict(h=0.01, ppc=4, T=0.2, cfl=0.045, scheme=scheme, mass=mass)
    reference = simulate(SodSettings(**settings, kernel="numpy"), progress=False)
    fused = simulate(SodSettings(**settings), progress=False)
    assert reference.steps >= 1000
    _assert_same(reference, fused, TOLERANCE)
    assert np.ptp(fused.particles.pressure) > 0.5  # the shocked tube, not a quiet one


def _drifting_grid():
    """Cells equal to 8e-10 relative (the B-splines accept it), nodes off ``x_0 + i h`` by 2e-9 h:
    not uniform to round-off."""
    h = 0.1 * np.where(np.arange(10) < 5, 1 + 4e-10, 1 - 4e-10)
    return grid_from_nodes(np.concatenate(([0.0], np.cumsum(h))))


def _gas_variant_in_the_fast_set(basis, scheme):
    """The gas loop variants in the fast set: the pairwise triples of :func:`_pairwise`; the
    particle-domain B-spline's (its USL loop is tests/test_fused_remedies.py's) with the slow tests."""
    return False if basis == "bspline_gimp" else _pairwise(basis, scheme, "gas")


@pytest.mark.parametrize(("basis", "scheme"), [
    pytest.param(basis, scheme, marks=() if _gas_variant_in_the_fast_set(basis, scheme) else pytest.mark.slow)
    for basis in names() for scheme in SCHEMES])
@pytest.mark.parametrize("mass", ["lumped", "consistent"])
def test_a_grid_not_uniform_to_round_off_keeps_the_node_arithmetic_bit_for_bit(basis, scheme, mass):
    """Off a uniform grid every basis keeps the node arithmetic: bit for bit, 200 steps. P1 and GIMP
    on a stretched grid and on one uniform only to 1e-8 (``uniform_spacing`` accepts it); the
    B-splines (which need equal cells) on one whose nodes drift 2e-9 h from ``x_0 + i h``. The node
    arithmetic lives in the shape rows every scheme shares: the fast set takes each basis with the
    schemes whose gas variant it compiles anyway (:func:`_gas_variant_in_the_fast_set`), the slow
    set the others."""
    stretched = grid_from_nodes(np.linspace(0.0, 1.0, 11) ** 1.2)
    nearly = grid_from_nodes(np.linspace(0.0, 1.0, 11) * (1 + 1e-8 * np.sin(np.arange(11.0))))
    assert stretched.uniform_spacing is None and nearly.uniform_spacing is not None
    grids = (_drifting_grid(),) if get(basis).uniform else (stretched, nearly)
    for grid in grids:
        assert FusedStep(grid, IdealGas(), Walls()).inv_spacing == 0.0  # the node arithmetic
        x, V = seed_positions(grid, 4, "regular" if get(basis).uniform else "jittered", seed=3)
        rho = 1.0 + 0.1 * np.sin(2 * np.pi * x)
        particles = make_particles(x, V, rho, 0.05 * np.sin(np.pi * x), rho**0.4 / 0.4, rho**1.4)
        problem = Problem(model=IdealGas(), boundary=Walls(), T=0.2, cfl=1.0, dt=1e-3)
        stages = Stages(basis=basis, scheme=scheme, mass=mass)
        reference = run(problem, grid, particles, stages, progress=False, kernel="numpy")
        fused = run(problem, grid, particles, stages, progress=False, kernel="fused")
        _assert_same(reference, fused)
        assert _worst(reference, fused) == 0.0
    assert FusedStep(GRID, IdealGas(), Walls()).inv_spacing > 0.0  # the uniform-grid arithmetic


@pytest.mark.parametrize("model", ["gas", "burgers"])
@pytest.mark.parametrize("acceleration", ["exact"])
def test_fused_exact_acceleration_and_slides_force(model, acceleration):
    """The exact nodal acceleration and the slides' second difference, through both paths."""
    problem, particles = _case(model, "walls")
    stages = Stages(acceleration=acceleration)
    exact = lambda x, t: np.cos(x + t)  # noqa: E731 (any nodal field will do)
    problem = Problem(model=problem.model, boundary=problem.boundary, T=problem.T, cfl=1.0, dt=problem.dt,
                      exact_acceleration=exact)
    _assert_same(run(problem, GRID, particles, stages, progress=False, kernel="numpy"),
                 run(problem, GRID, particles, stages, progress=False, kernel="fused"), TOLERANCE)
    if model == "burgers":
        slides = Problem(model=ViscousBurgers(0.01, force="slides"), boundary=Walls(), T=problem.T, cfl=1.0,
                         dt=problem.dt)
        _assert_same(run(slides, GRID, particles, progress=False, kernel="numpy"),
                     run(slides, GRID, particles, progress=False, kernel="fused"), TOLERANCE)


@pytest.mark.slow  # compiling the parallel passes takes about a minute on a fresh machine
@pytest.mark.parametrize("basis", ["mpm", "gimp", "bspline"])
def test_threads_agree_to_round_off_and_repeat_exactly(basis):
    """Two threads sum the grid in two chunks: within 1e-12 of one thread, identical run to run.
    (The parallel passes compile in about 20 s per basis on a cold cache: GIMP and the B-spline
    run with the slow tests.)"""
    settings = SodSettings(h=0.01, ppc=4, T=0.02, basis=basis)
    one = simulate(settings, progress=False)
    two = simulate(SodSettings(h=0.01, ppc=4, T=0.02, basis=basis, threads=2), progress=False)
    again = simulate(SodSettings(h=0.01, ppc=4, T=0.02, basis=basis, threads=2), progress=False)
    assert one.steps == two.steps
    for name in FIELDS:
        u, v = getattr(one.particles, name), getattr(two.particles, name)
        scale = float(np.max(np.abs(u)))
        assert float(np.max(np.abs(u - v))) <= 1e-12 * scale, name
        assert np.array_equal(v, getattr(again.particles, name)), f"{name} changes from run to run"


def _error(fn):
    try:
        fn()
    except Exception as err:  # noqa: BLE001 (the test compares what each path raises)
        return err
    raise AssertionError("no error raised")


def test_positivity_loss_raises_the_same_error_from_both_paths():
    settings = SodSettings(h=0.05, ppc=4, T=0.2, cfl=1.0, mass="consistent")
    errors = [_error(lambda k=k: simulate(SodSettings(**{**settings.as_dict(), "kernel": k}), progress=False))
              for k in ("numpy", "fused")]
    assert all(isinstance(e, PositivityError) for e in errors), errors
    assert str(errors[0]) == str(errors[1])
    e = errors[1]
    assert e.step is not None and e.particle >= 0 and np.isfinite(e.x)
    assert f"step {e.step}" in str(e) and f"particle {e.particle}" in str(e) and "reduce the CFL" in str(e)


def test_non_finite_state_raises_the_same_error_from_both_paths():
    """An energy whose pressure overflows: both paths name the step, the field and the particle."""
    x, V = seed_positions(GRID, 2)
    particles = make_particles(x, V, 10.0, 0.0, 1e308, 1.0)
    problem = Problem(model=IdealGas(), boundary=Walls(), T=1.0, cfl=0.5)
    with np.errstate(over="ignore"):
        errors = [_error(lambda k=k: run(problem, GRID, particles, progress=False, kernel=k))
                  for k in ("numpy", "fused")]
    assert all(isinstance(e, FloatingPointError) for e in errors), errors
    assert str(errors[0]) == str(errors[1]) and "non-finite pressure at step 0" in str(errors[1])


def test_a_particle_outside_the_grid_raises_the_same_error():
    x, V = seed_positions(GRID, 2)
    x[5] = 1.5
    particles = make_particles(x, V, 1.0, 0.0, 1.0, 0.4)
    problem = Problem(model=IdealGas(), boundary=Walls(), T=1.0, cfl=0.5)
    errors = [_error(lambda k=k: run(problem, GRID, particles, progress=False, kernel=k)) for k in ("numpy", "fused")]
    assert all(isinstance(e, OutsideGridError) for e in errors) and str(errors[0]) == str(errors[1])
    assert "particle 5 at x=1.5" in str(errors[1])


def test_what_the_fused_step_refuses():
    @dataclass(frozen=True)
    class Elastic:
        E: float = 1.0

    assert supported(Elastic(), Stages()) is not None
    assert supported(IdealGas(), Stages(projection="exact", scheme="usf")) is not None  # tests/test_fused_exact.py
    assert supported(IdealGas(), Stages(basis="gimp", scheme="musl", mass="consistent")) is None
    every_remedy = Stages(reconstruct="taylor", volume="grid", basis="bspline_gimp")
    assert supported(IdealGas(), every_remedy) is None
    with pytest.raises(ValueError, match="exact projection"):
        FusedStep(GRID, IdealGas(), Walls(), Stages(interpolation="exact", scheme="usf"))
    with pytest.raises(ValueError, match="threads"):
        SodSettings(threads=0)
    with pytest.raises(ValueError, match="unknown kernel"):
        SodSettings(kernel="gpu")


def _domain_rows(fused_row, x, V, nodes, K=8):
    """Each particle's row from ``fused_row`` (a compiled row of mpm_fem.fused.step) on a uniform grid,
    ``K`` columns (each row needs at most K)."""
    h = np.vstack([np.diff(nodes), 1.0 / np.diff(nodes)])
    inv_spacing = 1.0 / (nodes[1] - nodes[0])
    rows, S, G = np.empty((x.size, K), np.intp), np.empty((x.size, K)), np.empty((x.size, K))
    for q in range(x.size):
        _, need = fused_row(nodes, h, inv_spacing, x[q], V[q], rows[q], S[q], G[q])
        assert need <= K
    return rows, S, G


def test_particle_domain_bspline_row_is_the_formula_float_for_float():
    """The uniform-grid row of the particle-domain B-spline evaluates ``M`` and ``N`` only in the
    pieces that do not vanish (``_pieces``): the same floats as the formula of
    ``mpm_fem.bases.bspline_gimp`` (``bspline_integral``, ``quadratic_bspline``) at every node of the
    row (the end functions' columns at the walls from ``mpm_fem.bases.ends``), on domain ends placed at
    random, on nodes, half-way between nodes and at the grid's ends."""
    from mpm_fem.bases.bspline import quadratic_bspline as _quadratic_bspline
    from mpm_fem.bases.bspline_gimp import _row as _bspline_domain_row
    from mpm_fem.bases.bspline_gimp import bspline_integral as _bspline_integral
    from mpm_fem.bases.ends import clamp_antiderivatives

    nodes = np.linspace(0.0, 1.0, 41)
    n_cells = nodes.size - 1
    rng = np.random.default_rng(11)
    centres = np.concatenate([rng.uniform(0, 1, 4000), np.arange(n_cells + 1) / n_cells,
                              (np.arange(n_cells) + 0.5) / n_cells, [0.0, 1.0, 1e-17, 1 - 1e-16]])
    V = np.concatenate([rng.uniform(1e-6, 2.5, centres.size) / n_cells])
    edges = (np.arange(n_cells + 1) / n_cells)[rng.integers(0, n_cells + 1, 400)]  # a domain end on a node
    x = np.concatenate([centres, np.clip(edges + 0.5 * V[:400], 0, 1), np.clip(edges - 0.5 * V[:400], 0, 1)])
    V = np.concatenate([V, V[:400], V[:400]])
    rows, S, G = _domain_rows(_bspline_domain_row, x, V, nodes)
    inv_spacing = 1.0 / (nodes[1] - nodes[0])
    s_lo = (np.maximum(x - 0.5 * V, 0.0) - 0.0) * inv_spacing  # the row's uniform-grid arithmetic
    s_hi = (np.minimum(x + 0.5 * V, 1.0) - 0.0) * inv_spacing
    c_lo = np.minimum(s_lo.astype(int), n_cells - 1)
    j = c_lo[:, None] - 1 + np.arange(S.shape[1])
    inv_w = (1.0 / (s_hi - s_lo))[:, None]
    # the end functions of the open knot vector at the walls (mpm_fem.bases.ends), the same floats
    M_hi, N_hi = clamp_antiderivatives(j, s_hi[:, None], n_cells, _bspline_integral(s_hi[:, None] - j),
                                       _quadratic_bspline(s_hi[:, None] - j)[0])
    M_lo, N_lo = clamp_antiderivatives(j, s_lo[:, None], n_cells, _bspline_integral(s_lo[:, None] - j),
                                       _quadratic_bspline(s_lo[:, None] - j)[0])
    S_formula = (M_hi - M_lo) * inv_w
    G_formula = (N_hi - N_lo) * (inv_w * inv_spacing)
    assert np.array_equal(rows, np.clip(j, 0, n_cells))
    assert np.array_equal(S, S_formula), f"S differs by {np.abs(S - S_formula).max():.3g}"
    assert np.array_equal(G, G_formula), f"G differs by {np.abs(G - G_formula).max():.3g}"
    assert np.abs(S.sum(axis=1) - 1).max() < 1e-12  # the partition of unity


def test_the_five_column_bspline_row_is_the_column_rows_float_for_float():
    """Pass 1's five-column row of the particle-domain B-spline (``_five_columns``: each end's
    three pieces placed by selects, ``_five``) gives ``_column``'s floats at every column, for
    domains within two cells placed at random and on nodes, away from the end functions (pass 1
    takes ``_column`` for a row holding one); ``_five`` is ``_piece`` at every start it is used for."""
    from mpm_fem.bases.bspline_gimp import _column, _end_node, _five, _five_columns, _piece, _scalars

    for d in range(3):
        assert _five(d, 7.0, 1.0, 2.0, 3.0) == tuple(_piece(k - d, 7.0, 1.0, 2.0, 3.0) for k in range(5))
    nodes = np.linspace(0.0, 1.0, 41)
    inv_spacing, n_cells = 1.0 / (nodes[1] - nodes[0]), nodes.size - 1
    rng = np.random.default_rng(12)
    x = np.concatenate([rng.uniform(0, 1, 3000), nodes, [1e-17, 1 - 1e-16]])
    V = rng.uniform(1e-6, 1.0, x.size) / n_cells
    starts = set()
    for xq, Vq in zip(x, V, strict=False):
        D = _scalars(0.0, 1.0, n_cells - 1, inv_spacing, xq, Vq)
        assert D[1] <= 5
        if _end_node(D[2] - 1, n_cells) or _end_node(D[2] + 3, n_cells):
            continue
        starts.add(D[14] + D[3] - D[2])
        columns = [_column(k, inv_spacing, n_cells, D) for k in range(5)]
        S, G = np.array(_five_columns(inv_spacing, D)).reshape(2, 5)
        assert np.array_equal(S, [c[1] for c in columns]) and np.array_equal(G, [c[2] for c in columns])
    assert starts == {0, 1, 2}  # every start of the high end met
