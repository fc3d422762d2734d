"""Fixed-mesh Q1 FEM for the neo-Hookean solid (baselines/fem_solid.py): the forces against
scikit-fem's own assembly, the periodic meshes, momentum conservation, second-order convergence
on the axis-aligned and the vortex solutions, the time step, and bad input."""

from functools import lru_cache

import numpy as np
import pytest
from skfem import ElementQuad1, ElementVector, LinearForm, asm
from skfem.helpers import ddot, det, dot, eye, grad, inv, transpose

from baselines.exact.solids import AxisAligned, GeneralizedVortex
from baselines.fem_solid import (
    DEFAULT_CFL,
    acceleration,
    central_differences,
    discretise,
    external_force,
    internal_force,
    solve,
)

HS = (1 / 8, 1 / 16, 1 / 32)


def _skfem_vector_basis(disc):
    return disc.basis.with_element(ElementVector(ElementQuad1()))


def _random_displacement(disc, seed, size):
    rng = np.random.default_rng(seed)
    return size * rng.standard_normal((2, disc.n_nodes))


@pytest.mark.parametrize("solution", [AxisAligned(), GeneralizedVortex()], ids=["square", "annulus"])
def test_internal_force_equals_scikit_fem_linear_form_assembly(solution):
    disc = discretise(solution, 1 / 4)
    u = _random_displacement(disc, seed=11, size=0.02)
    mu, lam = solution.material.mu, solution.material.lam

    @LinearForm
    def piola_work(v, w):
        F = eye(np.ones_like(w["u"][0]), 2) + grad(w["u"])
        F_inv_T = transpose(inv(F))
        P = mu * (F - F_inv_T) + lam * np.log(det(F)) * F_inv_T
        return ddot(P, grad(v))

    vb = _skfem_vector_basis(disc)
    u_flat = np.zeros(vb.N)
    u_flat[vb.nodal_dofs] = u
    reference = asm(piola_work, vb, u=vb.interpolate(u_flat))[vb.nodal_dofs]
    ours = internal_force(u, disc, solution.material)
    worst = np.max(np.abs(ours - reference)) / np.max(np.abs(reference))
    assert worst < 1e-13, f"relative difference {worst:.2e}"


def test_external_force_equals_scikit_fem_linear_form_assembly():
    solution = AxisAligned(amplitude=0.05)
    disc = discretise(solution, 1 / 4)
    b_q = solution.body_force(disc.Xq[0], disc.Xq[1], 0.3 * solution.period)
    vb = _skfem_vector_basis(disc)

    @LinearForm
    def load(v, w):
        return solution.material.rho0 * dot(w["b"], v)

    reference = asm(load, vb, b=b_q.reshape(2, *disc.basis.dx.shape))[vb.nodal_dofs]
    ours = external_force(b_q, disc, solution.material.rho0)
    worst = np.max(np.abs(ours - reference)) / np.max(np.abs(reference))
    assert worst < 1e-13, f"relative difference {worst:.2e}"


def test_periodic_square_identifies_opposite_sides():
    disc = discretise(AxisAligned(), 1 / 8)
    assert disc.n_nodes == 16 * 16, disc.n_nodes
    assert disc.area == pytest.approx(4.0, rel=1e-14) and disc.lumped.sum() == pytest.approx(4.0, rel=1e-14)
    assert disc.X.min() == 0.0 and disc.X.max() < 2.0
    # Partition of unity with no boundary: the gradients of all functions sum to zero at every point.
    ones = np.ones(disc.n_nodes)
    assert np.max(np.abs(disc.D_X @ ones)) < 1e-12 and np.max(np.abs(disc.D_Y @ ones)) < 1e-12


def test_annulus_mesh_is_periodic_in_theta_and_converges_to_the_annulus_area():
    solution = GeneralizedVortex()
    exact = np.pi * (solution.outer**2 - solution.inner**2)
    gaps = []
    for h in (1 / 8, 1 / 16):
        disc = discretise(solution, h)
        n_R, n_T = round(0.5 / h), round(2 * np.pi / h)  # side h on the mid circle R = 1
        assert disc.n_nodes == (n_R + 1) * n_T, (disc.n_nodes, n_R, n_T)
        assert np.all(solution.contains(*disc.X))
        gaps.append(exact - disc.area)
    # The polygon's area falls short by (pi^3 / 3)(outer^2 - inner^2) / n_Theta^2: second order.
    assert 3.6 <= gaps[0] / gaps[1] <= 4.4, f"area gaps {gaps}"


@pytest.mark.parametrize("mass", ["lumped", "consistent"])
def test_total_momentum_is_conserved_without_body_force_on_the_periodic_square(mass):
    solution = AxisAligned()
    disc = discretise(solution, 1 / 8, mass)
    material = solution.material
    u = _random_displacement(disc, seed=12, size=1e-3)
    v = 0.3 + _random_displacement(disc, seed=13, size=1.0)
    momentum = []

    def record(velocity):
        momentum.append(material.rho0 * velocity @ disc.lumped)  # 1^T M v = lumped^T v for both masses

    record(v)
    dt = 0.25 * (1 / 8) / material.c
    for _ in range(4):
        u, v = central_differences(u, v, disc, material, dt, 10)
        record(v)
    momentum = np.array(momentum)
    scale = material.rho0 * np.abs(v) @ disc.lumped
    drift = np.max(np.abs(momentum - momentum[0])) / np.max(scale)
    assert np.all(np.abs(momentum[0]) > 0.1) and drift < 1e-13, f"momentum {momentum[:, 0]}, drift {drift:.2e}"


@lru_cache(maxsize=None)
def _run(solution, h, mass, T=None, cfl=None):
    return solve(solution, h, T=T, mass=mass, cfl=cfl)


def _orders(solution, mass, T=None, cfl=None, key="error_L2"):
    e = [getattr(_run(solution, h, mass, T, cfl), key) for h in HS]
    return e, [float(np.log2(e[k] / e[k + 1])) for k in range(len(e) - 1)]


@pytest.mark.parametrize("key", ["error_L2", "error_L2_max"])
@pytest.mark.parametrize("mass", ["lumped", "consistent"])
def test_axis_aligned_displacement_converges_at_second_order(mass, key):
    # Q1 in space and central differences at dt ~ h: O(h^2) in L2 (measured 2.00, 2.00 lumped; 1.99, 2.00 consistent).
    e, orders = _orders(AxisAligned(), mass, key=key)
    assert all(1.8 <= q <= 2.2 for q in orders), f"{key} {e}, orders {orders}"


@pytest.mark.slow
@pytest.mark.parametrize("mass", ["lumped", "consistent"])
def test_small_vortex_displacement_converges_at_second_order(mass):
    # A = 0.01 to T = 1 (Uintah's end time): small strain, so the asymptotic order shows at these h
    # (measured 1.93, 1.96 for both masses); A = 1 is not yet asymptotic here (docs/method.md).
    e, orders = _orders(GeneralizedVortex(amplitude=0.01), mass, T=1.0, cfl=0.25)
    assert all(1.8 <= q <= 2.2 for q in orders), f"L2 {e}, orders {orders}"


def test_time_step_follows_the_stated_rule():
    solution = AxisAligned()
    result = _run(solution, 1 / 8, "lumped")
    limit = DEFAULT_CFL[AxisAligned] * (1 / 8) / solution.material.c
    assert result.dt <= limit * (1 + 1e-12) and result.steps == int(np.ceil(solution.period / limit - 1e-9))
    assert result.t == pytest.approx(solution.period, rel=1e-14)
    assert result.error_L2 <= result.error_L2_max


def test_default_step_is_inside_the_small_strain_stability_limit_of_both_masses():
    # Central differences are stable for dt < 2 / omega_max, omega_max^2 the largest eigenvalue of
    # M^-1 K; K by differences of the internal force at u = 0 (linear to O(1e-7)). Measured limits
    # dt c / h: 0.86 lumped, 0.44 consistent.
    solution = AxisAligned()
    m = solution.material
    h = 1 / 4
    limits = {}
    for mass in ("lumped", "consistent"):
        disc = discretise(solution, h, mass)
        n = disc.n_nodes
        step = 1e-7
        K = np.stack([internal_force(step * np.eye(2 * n)[j].reshape(2, n), disc, m).ravel() / step
                      for j in range(2 * n)], -1)
        Minv_K = np.concatenate([acceleration(K[:, j].reshape(2, n), disc, m.rho0).ravel()[:, None]
                                 for j in range(2 * n)], -1)
        omega_max = np.sqrt(np.max(np.linalg.eigvals(Minv_K).real))
        limits[mass] = 2 / omega_max * m.c / h
    assert all(DEFAULT_CFL[AxisAligned] < limit for limit in limits.values()), limits


def test_vortex_runs_to_half_a_period_with_the_default_step():
    result = solve(GeneralizedVortex(), 1 / 8, T=1.0)
    # Measured 0.0759 at h = 1/8 (0.0269 at 1/16, 0.0083 at 1/32): a fraction of the ring's width 0.5.
    assert result.error_L2 < 0.1 and result.settings["cfl"] == DEFAULT_CFL[GeneralizedVortex], result.error_L2


def test_an_unstable_step_stops_the_run_with_the_step():
    with pytest.raises(ArithmeticError, match="step"):
        solve(GeneralizedVortex(), 1 / 8, T=1.0, mass="consistent", cfl=0.5)


@pytest.mark.parametrize(
    "kwargs, words",
    [
        (dict(h=0.3), "does not divide"),
        (dict(h=-1.0), "0 < h"),
        (dict(h=0.25, mass="diagonal"), "unknown mass"),
        (dict(h=0.25, cfl=1.5), "cfl"),
        (dict(h=0.25, T=-1.0), "T > 0"),
    ],
)
def test_bad_input_is_refused_with_a_message(kwargs, words):
    with pytest.raises(ValueError, match=words):
        solve(AxisAligned(), **kwargs)
