"""The grid masses (mpm_fem/masses): the registry and its refusals; FMPM(k) against the consistent
mass it approximates (the series' error is exactly R^k M^-1 rhs, bounded by rho(R)^k in the lumped
norm, and below 1e-10 of the consistent solve at k = 400 on a small problem); momentum conserved to
round-off by every mass in a step; the grid basis's mass against scikit-fem's Q1 matrix."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sl
import scipy.sparse.linalg as spl
from skfem import Basis as SkBasis
from skfem import BilinearForm, ElementQuad1, asm

from mpm_fem import masses
from mpm_fem.core.step import Stages
from mpm_fem.masses import FMPM, GridMass, MassSystem
from mpm_fem.masses.contract import particle_matrix
from mpm_fem.masses.registry import IncompleteMassError
from mpm_fem.plane.bases import plane_shape
from mpm_fem.plane.grid import plane_grid
from mpm_fem.plane.problems import seed_reference
from mpm_fem.plane.state import PlaneParticles
from mpm_fem.plane.step import grid_basis_matrix, step_with_grid

solids = pytest.importorskip("baselines.exact.solids")
MATERIAL = solids.Material(1e4, 0.3, 1.0)
SMALL = dict(lower=(0.0, 0.0), upper=(2.0, 2.0), h=0.25, periodic=(True, True))  # 8 x 8 cells, 64 nodes


def _system(basis="mpm", layout="jittered", seed=3, move=0.02):
    """The mass system of 2 x 2 particles per cell on the small periodic grid, moved randomly off their
    seeds by ``move`` (a tenth of a cell) and with masses varying by 10 %."""
    grid = plane_grid(**SMALL)
    X, V, L = seed_reference(grid, 2, layout, seed)
    rng = np.random.default_rng(seed)
    shape = plane_shape(grid, basis, X + move * rng.standard_normal(X.shape), L)
    m = V * (1 + 0.1 * rng.random(V.size))
    return grid, MassSystem(shape.matrix(), m, shape.scatter(m)), rng


def test_the_registry_lists_every_mass_and_refuses_an_unknown_name_listing_them():
    assert masses.names() == ("lumped", "consistent", "exact", "grid", "fmpm1", "fmpm2", "fmpm3", "fmpm4")
    assert masses.get("fmpm3").order == 3 and masses.get("grid").stage == "consistent"
    with pytest.raises(ValueError, match="unknown mass 'fmpm9'; choose one of lumped, consistent, exact, grid"):
        masses.get("fmpm9")
    own = FMPM(12)
    assert masses.get(own) is own  # a caller's own instance serves as it is


def test_an_incomplete_mass_or_a_bad_order_is_refused_naming_what_is_missing():
    class NoStage(GridMass):
        name, title = "nostage", "a mass without its stage"

        def solver(self, system):
            return lambda rhs: rhs

    with pytest.raises(IncompleteMassError, match=r"'nostage' is incomplete; it lacks: stage"):
        masses.register(NoStage())
    with pytest.raises(ValueError, match="a grid mass named 'lumped' is registered already"):
        masses.register(masses.get("lumped"))
    for bad in (0, 2.0, True):
        with pytest.raises(ValueError, match="the FMPM order must be an integer >= 1"):
            FMPM(bad)


@pytest.mark.parametrize("basis", ["mpm", "gimp", "bspline"])
@pytest.mark.parametrize("layout", ["regular", "jittered"])
def test_fmpm_error_is_the_series_remainder_bounded_by_rho_to_the_k(basis, layout):
    """A_k = (I - R^k) M^-1 with R = I - M_L^-1 M, so the error M^-1 rhs - A_k rhs = R^k M^-1 rhs, whose
    lumped norm is at most rho(R)^k times that of M^-1 rhs (R is self-adjoint in the lumped inner product)."""
    grid, system, rng = _system(basis, layout)
    M, m_i = particle_matrix(system).toarray(), system.m_i
    rho = 1.0 - sl.eigvalsh(M, np.diag(m_i))[0]
    assert 0.9 < rho < 0.99, f"{basis}: rho(R) = {rho:.4f} outside the range measured on 2 x 2 per cell (0.93-0.99)"
    rhs = rng.standard_normal((grid.n_nodes, 2))
    exact = np.linalg.solve(M, rhs)
    R = np.eye(grid.n_nodes) - M / m_i[:, None]
    norm = lambda e: np.sqrt(np.sum(m_i[:, None] * e**2))  # noqa: E731
    for k in (1, 2, 3, 4, 16):
        error = exact - FMPM(k).solver(system)(rhs)
        remainder = np.linalg.matrix_power(R, k) @ exact
        gap = np.abs(error - remainder).max() / np.abs(exact).max()
        assert gap < 1e-11, f"{basis}, k={k}: the error differs from R^k M^-1 rhs by {gap:.2g}"
        assert norm(error) <= rho**k * norm(exact) * (1 + 1e-9), f"{basis}, k={k}: error above rho^k"


@pytest.mark.parametrize("basis", ["mpm", "gimp"])
def test_fmpm_of_a_large_order_is_the_consistent_mass_in_a_step(basis):
    """The paper's limit: FMPM(k) -> the full (particle) mass matrix as k grows. At k = 400 on the small
    problem (rho(R) <= 0.96 here: rho^400 < 1.5e-8) the step's velocities and positions equal the
    consistent mass's to 1e-8 relative (measured 4e-10 for uGIMP, less for P1), at both ends of the
    PIC/FLIP blend; at k = 4 they differ by more than 1e-4 (the test can fail)."""
    grid = plane_grid(**SMALL)
    state = _particles(grid)
    for flip in (0.0, 1.0):
        stages = Stages(mass="consistent", flip=flip)
        want = step_with_grid(state, grid, basis, MATERIAL, 1e-4, 0.0, None, stages)[0]
        for order, band in ((400, (0.0, 1e-8)), (4, (1e-4, 1.0))):
            got = step_with_grid(state, grid, basis, MATERIAL, 1e-4, 0.0, None, stages, mass=FMPM(order))[0]
            gap = np.abs(got.v - want.v).max() / np.abs(want.v).max()
            assert band[0] <= gap < band[1], f"{basis}, flip {flip}, FMPM({order}): velocity gap {gap:.3g}"
            if order == 400:
                moved = np.abs(got.x - want.x).max() / np.abs(want.x - state.x).max()
                assert moved < 1e-8, f"{basis}, flip {flip}: FMPM(400) moves the particles {moved:.3g} apart"


def _particles(grid, seed=0, strain=1e-3):
    """Jittered particles with random velocities, masses and deformation gradients near I."""
    X, V0, lengths = seed_reference(grid, 2, "jittered", seed)
    rng = np.random.default_rng(seed + 1)
    F = np.eye(2) + strain * rng.standard_normal((X.shape[0], 2, 2))
    J = F[:, 0, 0] * F[:, 1, 1] - F[:, 0, 1] * F[:, 1, 0]
    return PlaneParticles(X=X, x=X + 0.02 * rng.standard_normal(X.shape), v=rng.standard_normal(X.shape), F=F,
                          volume=J * V0, volume0=V0, mass=MATERIAL.rho0 * V0 * (1 + 0.1 * rng.random(J.size)),
                          lengths=lengths)


def _drift(state, new):
    return np.abs(state.mass @ state.v - new.mass @ new.v).max() / np.sum(state.mass[:, None] * np.abs(state.v))


@pytest.mark.parametrize("mass", ["lumped", "consistent", "fmpm1", "fmpm2", "fmpm3", "fmpm4"])
@pytest.mark.parametrize("basis", ["mpm", "gimp", "bspline"])
@pytest.mark.parametrize("flip", [1.0, 0.0])
def test_every_mass_conserves_momentum_to_round_off(mass, basis, flip):
    """sum_p m_p v_p is unchanged by a step without body force (the stress sums to zero on the periodic
    square): the columns of each matrix sum to the lumped masses."""
    grid = plane_grid(**SMALL)
    state = _particles(grid)
    stages = Stages(mass=masses.get(mass).stage, flip=flip)
    new = step_with_grid(state, grid, basis, MATERIAL, 1e-4, 0.0, None, stages, mass=mass)[0]
    drift = _drift(state, new)
    assert drift < 1e-13, f"{mass}, {basis}, flip {flip}: momentum drifts by {drift:.3g} of sum m|v|"


@pytest.mark.parametrize("basis", ["mpm", "bspline"])
def test_the_grid_mass_conserves_momentum_only_where_the_particles_lumped_masses_are_its_row_sums(basis):
    """On the undeformed regular layout (the 2 x 2 midpoint rule integrates S_i exactly) the drift is
    round-off; with the particles moved randomly by 0.08 h it is not (measured 5e-5 to 8e-5 of sum m|v|
    in one step of dt = 1e-4: the band 1e-6 to 1e-2)."""
    grid = plane_grid(**SMALL)
    X, V0, lengths = seed_reference(grid, 2, "regular", 0)
    rng = np.random.default_rng(2)
    n = X.shape[0]
    F = np.tile(np.eye(2), (n, 1, 1)) + 1e-3 * rng.standard_normal((n, 2, 2))
    J = F[:, 0, 0] * F[:, 1, 1] - F[:, 0, 1] * F[:, 1, 0]
    state = PlaneParticles(X=X, x=X.copy(), v=rng.standard_normal((n, 2)), F=F, volume=J * V0, volume0=V0,
                           mass=MATERIAL.rho0 * V0, lengths=lengths)
    stages = Stages(mass="consistent")
    still = _drift(state, step_with_grid(state, grid, basis, MATERIAL, 1e-4, 0.0, None, stages, mass="grid")[0])
    assert still < 1e-13, f"{basis}: the grid mass drifts by {still:.3g} on the undeformed regular layout"
    moved = state.replace(x=X + 0.02 * rng.standard_normal(X.shape))
    drift = _drift(moved, step_with_grid(moved, grid, basis, MATERIAL, 1e-4, 0.0, None, stages, mass="grid")[0])
    assert 1e-6 < drift < 1e-2, f"{basis}: the grid mass drifts by {drift:.3g} with the particles moved"


@pytest.mark.parametrize("basis", ["mpm", "gimp"])
def test_the_grid_mass_of_the_hat_bases_is_skfem_s_q1_mass_and_its_solve(basis):
    """For P1 and uGIMP the grid mass is rho0 int S_i S_j of the Q1 hats: scikit-fem's BilinearForm
    assembled here on the MeshQuad (periodic ends folded), to round-off, and so is its solve."""
    grid = plane_grid(**SMALL)
    mass = asm(BilinearForm(lambda u, v, w: u * v), SkBasis(grid.mesh, ElementQuad1()))
    n = grid.mesh.p.shape[1]
    P = np.zeros((n, grid.n_nodes))
    P[np.arange(n), grid.mesh_nodes] = 1.0
    want = 3.0 * (P.T @ mass.toarray() @ P)
    got = grid_basis_matrix(grid, basis, 3.0).toarray()
    assert np.abs(got - want).max() < 1e-14 * np.abs(want).max()
    rhs = np.random.default_rng(0).standard_normal((grid.n_nodes, 2))
    X, V, L = seed_reference(grid, 2, "regular", 0)
    shape = plane_shape(grid, basis, X, L)
    system = MassSystem(shape.matrix(), V, shape.scatter(V), lambda: (lambda r: spl.spsolve(
        grid_basis_matrix(grid, basis, 3.0).tocsc(), r)))
    solved = masses.get("grid").solver(system)(rhs)
    assert np.abs(want @ solved - rhs).max() < 1e-12 * np.abs(rhs).max()


def test_the_grid_mass_is_refused_for_a_body_that_does_not_fill_its_grid():
    from mpm_fem.plane import PlaneSettings

    with pytest.raises(ValueError, match="the grid mass needs a body that fills the grid; the vortex's does not"):
        PlaneSettings(problem="vortex", mass="grid")
    grid, system, _ = _system()
    empty = MassSystem(system.S, system.m, np.where(np.arange(grid.n_nodes) == 5, 0.0, system.m_i), lambda: None)
    with pytest.raises(ValueError, match="1 nodes have none"):
        masses.get("grid").solver(empty)


def test_the_command_line_and_the_python_entry_take_a_registered_mass(capsys):
    import mpm_fem
    from mpm_fem.app.cli import main

    assert main(["plane", "axis", "--h", "0.25", "--mass", "fmpm2", "--quiet"]) == 0
    run = mpm_fem.plane.axis(h=0.25, mass="fmpm2")
    assert run.settings.mass == "fmpm2" and run.settings.stages.mass == "consistent"
    assert not mpm_fem.plane.axis(h=0.25, mass="fmpm2", compiled=True).compiled  # the numpy step serves it
    with pytest.raises(mpm_fem.UsageError, match=r"^axis\(\): unknown mass 'fmpm5'; choose one of lumped, "
                       r"consistent, exact, grid, fmpm1, fmpm2, fmpm3, fmpm4$"):
        mpm_fem.plane.axis(h=0.25, mass="fmpm5")


def test_the_cfl_limit_of_each_mass_falls_from_the_lumped_one_toward_the_consistent_one_with_the_order():
    """The linearised step's limit 2 c / (h omega_max), P1, 2 x 2 regular, h = 1/8, in units of c / c_p
    (measured 2026-12-02): lumped 1 = FMPM(1), FMPM(2) 0.756, (3) 0.658, (4) 0.605, consistent 0.441;
    the grid (Q1) mass 1/sqrt(3). FMPM(k)'s step is less stable as k grows (Nairn 2026)."""
    from mpm_fem.plane.run import PlaneSettings, setup
    from mpm_fem.plane.stability import linearised_cfl, p_wave_ratio

    solution, grid, (X, V, L), _ = setup(PlaneSettings(h=1 / 8, ppc=2))
    unit = p_wave_ratio(solution.material)
    limit = {m: linearised_cfl(grid, "mpm", m, solution.material, X, V, L) / unit
             for m in ("lumped", "fmpm1", "fmpm2", "fmpm3", "fmpm4", "consistent", "grid")}
    assert abs(limit["lumped"] - 1) < 1e-9 and abs(limit["fmpm1"] - 1) < 1e-9, limit
    orders = [limit[f"fmpm{k}"] for k in (1, 2, 3, 4)]
    assert all(a > b for a, b in zip(orders, orders[1:], strict=False)) and orders[-1] > limit["consistent"], limit
    assert abs(limit["fmpm2"] - 0.756) < 0.005 and abs(limit["consistent"] - 0.441) < 0.005, limit
    assert abs(limit["grid"] - 1 / np.sqrt(3)) < 1e-3, limit
    with pytest.raises(ValueError, match="the exact mass stage has no linearised step"):
        linearised_cfl(grid, "mpm", "exact", solution.material, X, V, L)
