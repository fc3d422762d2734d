"""XPIC(m), the extended PIC update (mpm_fem/core/xpic.py): its equation against dense matrices, what it
filters, what it conserves, XPIC(1) = PIC, and its order on the smooth problems of the remedies.

The order bands follow from the filter: on a smooth mode ``k`` one XPIC(m) update keeps all of
FLIP but a part ``(1 - lambda)^m`` of the mode, with ``1 - lambda = O((k h)^2)`` the eigenvalue gap
of ``B = S+ S``; over ``T / dt`` steps that is an error ``O(h^{2m} / dt)``. With the viscous step of
Burgers (``dt ~ h^2``): ``O(1)`` for PIC (no convergence), ``O(h^2)`` for m = 2 and below the
scheme's own error for m = 5. With ``dt ~ h`` (the pulse): ``O(h^{2m-1})``, at least first order.
"""

import dataclasses
import math

import numpy as np
import pytest

from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.particles import seed_positions
from mpm_fem.core.shape import make_shape
from mpm_fem.core.step import Dirichlet, Stages, Walls, explicit_step
from mpm_fem.core.xpic import boundary_change_rule, xpic_grid_velocity, xpic_velocity
from mpm_fem.measure.errors import fitted_order
from mpm_fem.measure.timing import PulseSettings, field_difference, pulse_setup
from mpm_fem.problems import burgers, sod
from mpm_fem.run.solve import run


@pytest.fixture
def rng():
    return np.random.default_rng(2017)


def _cloud(rng, basis="mpm", h=0.1, ppc=4):
    grid = uniform_grid(0.0, 1.0, h)
    x, V = seed_positions(grid, ppc, "jittered", seed=int(rng.integers(1000)))
    m = rng.uniform(0.5, 2.0, x.size) * V
    shape = make_shape(grid, x, V, basis)
    return grid, shape, m, shape.scatter(m)


def _dense(shape, m, m_i):
    """``S`` (n_p x n_nodes) and ``S+ = M^{-1} S^T M_p`` (lumped) as dense matrices."""
    S = shape.matrix().toarray()
    return S, (S.T * m) / m_i[:, None]


# ---------------------------------------------------------------- the equation

@pytest.mark.parametrize("basis", ["mpm", "bspline_gimp"])
@pytest.mark.parametrize("m", [1, 2, 3, 5, 8])
def test_xpic_is_the_truncated_expansion_of_the_identity(basis, m, rng):
    """No boundary rule: ``S v* = [I - (I - S S+)^m] v_p``, by a dense matrix power."""
    grid, shape, mass, m_i = _cloud(rng, basis)
    S, S_plus = _dense(shape, mass, m_i)
    v_p = rng.normal(size=mass.size)
    I = np.eye(mass.size)
    expected = (I - np.linalg.matrix_power(I - S @ S_plus, m)) @ v_p
    got = shape.gather(xpic_grid_velocity(shape, mass, m_i, S_plus @ v_p, m))
    assert np.abs(got - expected).max() < 1e-12 * np.abs(v_p).max()


@pytest.mark.parametrize("boundary", [Walls(), Dirichlet(lambda x, t: np.where(x < 0.5, 0.3, -0.7) + t)])
@pytest.mark.parametrize("m", [1, 2, 4, 6])
def test_with_a_boundary_it_is_the_binomial_sum_with_the_rule_on_every_iterate(boundary, m, rng):
    """``v* = sum_{k=1}^m (-1)^{k+1} C(m, k) w_k``, ``w_1 = v_i``, ``w_{k+1} = rule(S+ S w_k)``."""
    grid, shape, mass, m_i = _cloud(rng)
    S, S_plus = _dense(shape, mass, m_i)
    v_i = boundary.velocity(grid, S_plus @ rng.normal(size=mass.size), 0.2)
    w, expected = v_i, np.zeros_like(v_i)
    for k in range(1, m + 1):
        expected += (-1) ** (k + 1) * math.comb(m, k) * w
        w = boundary.velocity(grid, S_plus @ (S @ w), 0.2)
    got = xpic_grid_velocity(shape, mass, m_i, v_i, m, homogeneous=boundary_change_rule(boundary, grid, 0.2))
    assert np.abs(got - expected).max() < 1e-12 * 2**m
    b = grid.boundary_nodes
    np.testing.assert_array_equal(got[b], v_i[b])  # the prescribed velocity, untouched


# ---------------------------------------------------------------- what it filters

def test_null_space_noise_is_removed_at_every_order(rng):
    """A particle velocity the grid does not see (``S^T M_p n = 0``; FLIP carries it unchanged) is
    gone after one XPIC update, any m."""
    grid, shape, mass, m_i = _cloud(rng)
    S = shape.matrix().toarray()
    r = rng.normal(size=mass.size)
    n = r - S @ np.linalg.solve(S.T @ (S * mass[:, None]), S.T @ (mass * r))  # M_p-orthogonal to range(S)
    v_i = shape.scatter(mass * n) / m_i
    assert np.abs(v_i).max() < 1e-12 and np.abs(n).max() > 0.1
    zero = np.zeros_like(m_i)
    for m in (1, 2, 5, 50):
        assert np.abs(xpic_velocity(shape, mass, m_i, v_i, zero, 1e-3, m)).max() < 1e-12, m


def test_a_velocity_the_grid_represents_is_recovered_as_m_grows(rng):
    """``v_p = S g`` has no null-space part: XPIC(m) with no acceleration tends to ``v_p`` (FLIP),
    the difference ``(I - A)^m v_p`` decreasing with m; PIC (m = 1) smooths it."""
    grid, shape, mass, m_i = _cloud(rng, h=0.05)
    v_p = shape.gather(rng.normal(size=m_i.size))
    zero = np.zeros_like(m_i)
    v_i = shape.scatter(mass * v_p) / m_i
    gaps = [np.abs(xpic_velocity(shape, mass, m_i, v_i, zero, 1e-3, m) - v_p).max() for m in (1, 2, 5, 20, 200)]
    assert gaps[0] > 0.1 and all(a > b for a, b in zip(gaps, gaps[1:], strict=False)) and gaps[-1] < 1e-8, gaps


def test_with_the_consistent_mass_xpic_is_pic_at_every_order(rng):
    """``S+ = M_c^{-1} S^T M_p`` makes ``B = S+ S = I``: every term after the first vanishes."""
    grid, shape, mass, m_i = _cloud(rng)
    v_i = rng.normal(size=m_i.size)
    for m in (2, 5):
        got = xpic_grid_velocity(shape, mass, m_i, v_i, m, kind="consistent")
        assert np.abs(got - v_i).max() < 1e-12, m


# ---------------------------------------------------------------- in the step

@pytest.mark.parametrize("basis", ["mpm", "bspline_gimp"])
def test_xpic_one_is_the_pic_blend_bit_for_bit(basis):
    """30 steps of the pulse between walls: XPIC(1) and ``flip = 0`` give the same particles."""
    problem, grid, particles, stages = pulse_setup(PulseSettings(h=0.05, basis=basis))
    a = b = particles
    for n in range(30):
        t = n * problem.dt
        a, _ = explicit_step(grid, a, problem.model, problem.boundary, t, problem.dt,
                             dataclasses.replace(stages, xpic=1))
        b, _ = explicit_step(grid, b, problem.model, problem.boundary, t, problem.dt,
                             dataclasses.replace(stages, flip=0.0))
    for name in ("x", "velocity", "density", "energy", "volume"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert np.abs(a.velocity).max() > 1e-3  # the pulse moved


def test_xpic_option_is_checked_and_reaches_the_step():
    for bad in (-1, 1.5, True, "2"):
        with pytest.raises(ValueError, match="XPIC order"):
            Stages(xpic=bad)
    with pytest.raises(ValueError, match="XPIC replaces the PIC/FLIP blend"):
        Stages(xpic=2, flip=0.5)
    with pytest.raises(ValueError, match="MPM stages only"):
        Stages(xpic=2, projection="exact")
    assert Stages(xpic=2).uses_remedy and not Stages(xpic=0).uses_remedy
    assert sod.SodSettings(xpic=5).stages.xpic == 5 and burgers.BurgersSettings(xpic=2).stages.xpic == 2
    with pytest.raises(ValueError, match="XPIC order"):
        sod.SodSettings(xpic=-2)


def test_the_fused_kernel_runs_xpic_as_the_numpy_step():
    """The fused step's XPIC passes (point mass: its uniform-grid arithmetic, 1e-12 relative)."""
    settings = sod.SodSettings(h=0.05, T=0.02, xpic=3)
    fused = sod.simulate(settings, progress=False)
    numpy_step = sod.simulate(dataclasses.replace(settings, kernel="numpy"), progress=False)
    np.testing.assert_allclose(fused.particles.velocity, numpy_step.particles.velocity, rtol=0,
                               atol=1e-12 * np.abs(numpy_step.particles.velocity).max())
    plain = sod.simulate(dataclasses.replace(settings, xpic=0, kernel="numpy"), progress=False)
    assert np.abs(fused.particles.velocity - plain.particles.velocity).max() > 1e-6


# ---------------------------------------------------------------- orders on smooth problems

def _pulse_orders(changes: dict) -> dict:
    """Fitted orders of ``|q_h - q_ref|`` over h = 0.04, 0.02, 0.01 against h = 0.0025 (the
    remedies' pulse test, tests/test_remedies.py), on the numpy step: these runs measure the method;
    the fused step's XPIC equals it in tests/test_fused_remedies.py (so no loop variant compiles
    here)."""
    hs, out = (0.04, 0.02, 0.01, 0.0025), []
    for h in hs:
        problem, grid, particles, stages = pulse_setup(PulseSettings(h=h, basis=changes.get("basis", "mpm")))
        stages = dataclasses.replace(stages, **{k: v for k, v in changes.items() if k != "basis"})
        out.append(run(problem, grid, particles, stages, progress=False, kernel="numpy").particles)
    return {q: fitted_order(hs[:-1], [field_difference(r, out[-1], (0.0, 1.0), q) for r in out[:-1]])
            for q in ("velocity", "density")}


@pytest.mark.parametrize("m", [2, 5])
def test_xpic_with_the_particle_domain_bspline_converges_on_the_pulse(m):
    for quantity, order in _pulse_orders(dict(basis="bspline_gimp", xpic=m)).items():
        assert 0.8 <= order < 2.6, f"XPIC({m}): {quantity} order {order:.2f}"


def test_xpic_alone_does_not_remove_the_point_mass_plateau_on_the_pulse():
    """XPIC filters the particle velocities; the cell-crossing force error of point masses stays."""
    assert _pulse_orders(dict(xpic=5))["velocity"] < 0.3


def _burgers_orders(changes: dict) -> tuple[dict, dict]:
    hs, errors = (0.04, 0.02, 0.01), {"particles": [], "nodes": []}
    for h in hs:
        settings = burgers.BurgersSettings(h=h, ppc=4, kernel="numpy", **changes)  # the method (as _pulse_orders)
        e = burgers.errors(settings, burgers.simulate(settings, progress=False))["velocity"]
        for where in errors:
            errors[where].append(e[where]["L1"])
    return {w: fitted_order(hs, e) for w, e in errors.items()}, errors


@pytest.mark.parametrize("m, band", [(1, (-0.3, 0.3)), (2, (1.8, 2.6)), (5, (1.8, 2.6))])
def test_xpic_order_on_smooth_burgers_follows_the_filter(m, band):
    """Particle-domain B-spline, 4 per cell, calculated acceleration, viscous dt ~ h^2: the filter's
    error O(h^{2m-2}) stalls PIC and leaves m = 2 and 5 at the scheme's second order."""
    orders, errors = _burgers_orders(dict(basis="bspline_gimp", xpic=m))
    for where, order in orders.items():
        assert band[0] <= order < band[1], f"XPIC({m}) {where}: order {order:.2f} ({errors[where]})"
