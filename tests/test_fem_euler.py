"""Fixed-mesh Galerkin FEM for Sod's shock tube (baselines/fem_euler.py): conservation, accuracy
against the exact Riemann solution, the kernel against scikit-fem, the compiled loop
(baselines/fem_euler_kernel.py) against the numpy loop, and error handling."""

from functools import lru_cache

import numpy as np
import pytest
from skfem import Basis, ElementLineP1, LinearForm, asm

from baselines.exact.riemann import sample
from baselines.fem_euler import (
    MASS_KINDS,
    SOD_LEFT,
    SOD_RIGHT,
    PositivityError,
    Viscosity,
    _operators,
    label,
    residual,
    sod_initial_state,
    solve,
)
from mpm_fem.core.grid import grid_from_nodes, uniform_grid

GAMMA = 1.4
RHO_POST_SHOCK = 0.26557  # Toro, Table 4.2: rho*_R of Sod's problem


COMPRESSION_ONLY = Viscosity(compression_only=True)


@lru_cache(maxsize=None)
def _run(h, mass, viscosity=Viscosity(), kernel="fused"):
    return solve(h, mass=mass, viscosity=viscosity, kernel=kernel)


def _density_l1(result):
    """``sum_i w_i |rho_i - rho_exact(x_i)|`` with the lumped-mass weights ``w_i = int S_i dx``."""
    x = result.nodes
    w = np.zeros_like(x)
    w[:-1] += 0.5 * np.diff(x)
    w[1:] += 0.5 * np.diff(x)
    rho_exact, _, _ = sample(x, result.t, SOD_LEFT, SOD_RIGHT, x0=0.5, gamma=GAMMA)
    return float(np.sum(w * np.abs(result.rho - rho_exact)))


@pytest.mark.parametrize("kernel", ["fused", "numpy"])
@pytest.mark.parametrize("mass", ["lumped", "consistent"])
def test_mass_and_energy_are_conserved_to_round_off(mass, kernel):
    h = 0.01
    result = _run(h, mass, kernel=kernel)
    grid = uniform_grid(0.0, 1.0, h)
    m = grid.lumped_mass
    U0 = sod_initial_state(grid.nodes, GAMMA)
    mass0, mass_t = np.sum(m * U0[0]), np.sum(m * result.rho)
    E_t = result.rho * result.e + 0.5 * result.rho * result.u**2
    energy0, energy_t = np.sum(m * U0[2]), np.sum(m * E_t)
    drift = mass_t - mass0
    assert abs(drift) <= 1e-13 * mass0, f"mass drift {drift:.3e} after {result.steps} steps"
    assert abs(energy_t - energy0) <= 1e-13 * energy0, f"energy drift {energy_t - energy0:.3e}"


@pytest.mark.parametrize("mass", ["lumped", "consistent"])
def test_post_shock_density_is_within_one_percent_at_h_0_0025(mass):
    result = _run(0.0025, mass)
    plateau = (result.nodes >= 0.72) & (result.nodes <= 0.82)
    rho = float(result.rho[plateau].mean())
    assert abs(rho / RHO_POST_SHOCK - 1) < 0.01, f"post-shock density {rho:.5f} vs {RHO_POST_SHOCK}"


@pytest.mark.parametrize("mass", ["lumped", "consistent"])
def test_density_l1_error_decreases_with_h(mass):
    errors = [_density_l1(_run(h, mass)) for h in (0.01, 0.005, 0.0025)]
    assert errors[1] < 0.8 * errors[0] and errors[2] < 0.8 * errors[1], f"L1 errors {errors}"
    # A first-order-viscosity Galerkin scheme on Sod: L1 ~ h^(0.5..1) (measured ~0.7).
    order = np.log2(errors[0] / errors[2]) / 2
    assert 0.5 < order < 1.1, f"observed L1 order {order:.3f} from {errors}"


@pytest.mark.parametrize("mass", ["lumped", "consistent"])
def test_solution_is_finite_positive_and_reaches_T(mass):
    result = _run(0.005, mass)
    assert result.t == pytest.approx(0.2, abs=1e-14)
    for name in ("rho", "u", "p", "e"):
        assert np.all(np.isfinite(getattr(result, name))), name
    assert result.rho.min() > 0 and result.p.min() > 0
    assert result.u[0] == 0.0 and result.u[-1] == 0.0, "walls: u = 0 at the end nodes"
    assert np.allclose(result.e, result.p / (0.4 * result.rho))
    assert result.settings["mass"] == mass
    assert result.settings["viscosity"] == {"linear": 0.1, "quadratic": 1.0, "compression_only": False}
    assert result.settings["viscosity_variant"] == "viscosity everywhere"


def test_residual_kernel_matches_scikit_fem_linear_form():
    """The bincount kernel equals the weak form assembled by scikit-fem on a non-uniform mesh."""
    rng = np.random.default_rng(7)
    grid = grid_from_nodes(np.sort(np.r_[0.0, rng.uniform(0, 1, 30), 1.0]))
    n = grid.n_nodes
    rho = 1 + 0.5 * rng.uniform(size=n)
    u = rng.normal(size=n)
    p = 1 + rng.uniform(size=n)
    U = np.stack((rho, rho * u, p / (GAMMA - 1) + 0.5 * rho * u**2))
    visc = Viscosity(linear=0.3, quadratic=1.5)
    R = residual(U, _operators(grid, "lumped"), GAMMA, visc)

    F = np.stack((U[1], U[1] * u + p, (U[2] + p) * u))
    a, b = grid.mesh.t
    c = np.sqrt(GAMMA * p / rho)
    s_e = np.maximum(np.abs(u[a]) + c[a], np.abs(u[b]) + c[b])
    nu = grid.h * (visc.linear * s_e + visc.quadratic * np.maximum(0.0, u[a] - u[b]))
    basis = Basis(grid.mesh, ElementLineP1(), intorder=2)
    nu_qp = np.repeat(nu[:, None], basis.X.shape[1], axis=1)

    @LinearForm
    def weak(v, w):
        return -w["F"].grad[0] * v - w["nu"] * w["U"].grad[0] * v.grad[0]

    for k in range(3):
        ref = asm(weak, basis, F=basis.interpolate(F[k]), U=basis.interpolate(U[k]), nu=nu_qp)
        gap = np.abs(R[k] - ref).max()
        assert np.allclose(R[k], ref, rtol=1e-12, atol=1e-12), f"component {k}: {gap:.2e}"


def test_lost_positivity_raises_with_step_and_node():
    # The consistent mass with cfl = 1 overshoots at the diaphragm in the first step.
    with pytest.raises(PositivityError, match=r"step 1 .*node \d+"):
        solve(0.01, mass="consistent", cfl=1.0)


@pytest.mark.parametrize("viscosity", [Viscosity(), COMPRESSION_ONLY], ids=lambda v: v.name)
def test_compiled_loop_equals_the_numpy_loop(viscosity):
    """The lumped mass bit for bit (the same operations in the same order), the consistent mass to
    round-off (a Thomas solve where numpy uses SuperLU; measured max |difference| / max |field| over
    rho, u, p, e: 2.1e-15 / 3.3e-15 at h = 0.01, 5.6e-15 / 1.1e-14 at h = 0.0025, viscosity
    everywhere / compression only); the same steps and final time either way."""
    for h in (0.01, 0.0025):
        for mass in ("lumped", "consistent"):
            a = _run(h, mass, viscosity, "numpy")
            b = _run(h, mass, viscosity, "fused")
            assert a.steps == b.steps and a.t == b.t, (h, mass, a.steps, b.steps, a.t, b.t)
            assert a.settings == b.settings and np.array_equal(a.nodes, b.nodes)
            for name in ("rho", "u", "p", "e"):
                x, y = getattr(a, name), getattr(b, name)
                if mass == "lumped":
                    assert np.array_equal(x, y), (h, name, np.abs(x - y).max())
                else:
                    gap = np.abs(x - y).max() / np.abs(x).max()
                    assert gap <= 1e-12, (h, name, gap)


@pytest.mark.parametrize("cfl, where", [(0.9, "step 1 (RK stage 3)"), (0.7, "step 3 (RK stage 2)")])
def test_both_loops_raise_the_same_positivity_error(cfl, where):
    """The consistent mass at cfl 0.9 (0.7) loses positivity in step 1 (3): the compiled loop stops
    there and the step retaken in numpy raises the numpy loop's message."""
    messages = []
    for kernel in ("numpy", "fused"):
        with pytest.raises(PositivityError, match=r"lost positivity at step \d+ .*node \d+") as err:
            solve(0.01, mass="consistent", cfl=cfl, kernel=kernel)
        messages.append(str(err.value))
    assert messages[0] == messages[1]
    assert where in messages[0], messages[0]


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(h=0.03), "does not divide"),
        (dict(h=-0.01), "positive"),
        (dict(h=0.01, cfl=0.0), "cfl"),
        (dict(h=0.01, cfl=1.5), "cfl"),
        (dict(h=0.01, cfl=np.nan), "cfl"),
        (dict(h=0.01, mass="diagonal"), "unknown mass"),
        (dict(h=0.01, T=-1.0), "T"),
        (dict(h=0.01, gamma=1.0), "gamma"),
        (dict(h=0.01, kernel="cuda"), "unknown kernel"),
    ],
)
def test_bad_input_raises_value_error(kwargs, message):
    with pytest.raises(ValueError, match=message):
        solve(**kwargs)


def test_negative_viscosity_constant_is_rejected():
    with pytest.raises(ValueError, match="quadratic"):
        Viscosity(linear=0.1, quadratic=-1.0)


def test_initial_data_integrate_exactly_with_the_diaphragm_on_a_node():
    grid = uniform_grid(0.0, 1.0, 0.01)
    U0 = sod_initial_state(grid.nodes, GAMMA)
    assert abs(np.sum(grid.lumped_mass * U0[0]) - 0.5625) < 1e-14
    assert abs(np.sum(grid.lumped_mass * U0[2]) - 1.375) < 1e-14


def _gas(u):
    """A smooth gas state on a non-uniform mesh with the velocity ``u(x)``: ``(grid, U)``."""
    grid = grid_from_nodes(np.linspace(0.0, 1.0, 41) ** 1.2)
    x = grid.nodes
    rho, p = 1.0 + 0.3 * np.sin(3 * x), 1.0 + 0.2 * x
    v = u(x)
    return grid, np.stack((rho, rho * v, p / (GAMMA - 1) + 0.5 * rho * v**2))


def test_compression_only_viscosity_vanishes_on_an_expansion():
    grid, U = _gas(lambda x: 0.2 + x**2)  # du/dx > 0 on every cell: a rarefaction
    ops = _operators(grid, "lumped")
    galerkin = residual(U, ops, GAMMA, Viscosity(0.0, 0.0))
    assert np.array_equal(residual(U, ops, GAMMA, COMPRESSION_ONLY), galerkin)
    assert np.abs(residual(U, ops, GAMMA, Viscosity()) - galerkin).max() > 1e-3  # the default acts there


def test_compression_only_viscosity_equals_the_default_in_compression():
    grid, U = _gas(lambda x: 0.2 - x**2)  # du/dx < 0 on every cell
    ops = _operators(grid, "lumped")
    np.testing.assert_array_equal(residual(U, ops, GAMMA, COMPRESSION_ONLY), residual(U, ops, GAMMA, Viscosity()))


def test_compression_only_coefficient_is_zero_exactly_where_the_cell_expands():
    du = np.array([-0.5, -1e-12, 0.0, 1e-12, 0.5])
    nu = COMPRESSION_ONLY.coefficient(np.full(5, 0.1), np.full(5, 2.0), du)
    np.testing.assert_allclose(nu, [0.1 * (0.2 + 0.5), 0.1 * (0.2 + 1e-12), 0, 0, 0], rtol=1e-14, atol=0)


def test_compression_only_variant_converges_on_sod_and_conserves():
    # measured density L1 (lumped): 0.01455, 0.00923, 0.00606 at h = 0.01, 0.005, 0.0025
    # (viscosity everywhere: 0.01187, 0.00742, 0.00458)
    errors = [_density_l1(_run(h, "lumped", COMPRESSION_ONLY)) for h in (0.01, 0.005, 0.0025)]
    assert errors[1] < 0.8 * errors[0] and errors[2] < 0.8 * errors[1], f"L1 errors {errors}"
    order = np.log2(errors[0] / errors[2]) / 2
    assert 0.5 < order < 0.9, f"observed L1 order {order:.3f} from {errors}"
    r = _run(0.0025, "lumped", COMPRESSION_ONLY)
    grid = uniform_grid(0.0, 1.0, 0.0025)
    assert abs(np.sum(grid.lumped_mass * r.rho) - 0.5625) < 1e-13
    assert r.settings["viscosity_variant"] == "compression-only viscosity"


def test_each_variant_has_a_name():
    assert label() == "FEM P1 lumped (viscosity everywhere)"
    assert label("consistent", COMPRESSION_ONLY) == "FEM P1 consistent (compression-only viscosity)"
    assert {label(m) for m in MASS_KINDS} == {"FEM P1 lumped (viscosity everywhere)",
                                              "FEM P1 consistent (viscosity everywhere)"}
    with pytest.raises(ValueError, match="compression_only"):
        Viscosity(compression_only="yes")
