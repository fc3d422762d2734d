"""The plateau remedies (E5): what each must conserve, and its order on smooth problems.

Remedies: the B-spline averaged over the particle domain (``basis="bspline_gimp"``), the Taylor
least-squares stress reconstruction (``reconstruct="taylor"``), the volume reset against the grid
(``volume="grid"``) and the PIC/FLIP blend (``flip``); XPIC(m) (``xpic``) has its own tests in
tests/test_xpic.py, and its conservation in the step here.
"""

import dataclasses

import numpy as np
import pytest

from mpm_fem.bases import names
from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.models.euler import IdealGas
from mpm_fem.core.particles import make_particles, seed_positions
from mpm_fem.core.reconstruction import reconstructed_force, taylor_fit
from mpm_fem.core.shape import basis_integrals, bspline_shape, make_shape
from mpm_fem.core.step import Stages, explicit_step
from mpm_fem.core.transfer import nodal_internal_force
from mpm_fem.core.volume import grid_volume_factor
from mpm_fem.measure.errors import fitted_order
from mpm_fem.measure.timing import PulseSettings, field_difference, pulse_setup
from mpm_fem.problems import burgers
from mpm_fem.run.solve import run


@pytest.fixture
def rng():
    """A fresh generator per test: each test's data do not depend on which tests ran before."""
    return np.random.default_rng(14)


# ---------------------------------------------------------------- (a) B-spline over the particle domain

def test_bspline_gimp_is_a_partition_of_unity_with_zero_gradient_sum(rng):
    grid = uniform_grid(0.0, 1.0, 0.1)
    x = rng.uniform(0, 1, 3000)
    volume = rng.uniform(0.01, 1.0, x.size) * 0.1
    shape = make_shape(grid, x, volume, "bspline_gimp")
    assert np.abs(shape.S.sum(axis=1) - 1).max() < 1e-13
    assert np.abs(shape.G.sum(axis=1)).max() < 1e-11
    assert shape.S.min() > -1e-15


def test_bspline_gimp_is_the_domain_average_of_the_point_bspline():
    """S_ip = 1/V_p int N_i chi_p and G_ip = 1/V_p int N_i' chi_p, by a 4000-point midpoint rule."""
    grid = uniform_grid(0.0, 1.0, 0.1)
    x = np.array([0.0, 0.013, 0.2, 0.449, 0.5, 0.77, 0.95, 1.0])
    volume = np.array([0.02, 0.03, 0.1, 0.05, 0.2, 0.004, 0.12, 0.06])
    shape = make_shape(grid, x, volume, "bspline_gimp")
    for p in range(x.size):
        lo, hi = max(x[p] - volume[p] / 2, 0.0), min(x[p] + volume[p] / 2, 1.0)
        s = lo + (np.arange(4000) + 0.5) / 4000 * (hi - lo)
        point = bspline_shape(grid, s)
        avg_S = point.matrix().toarray().mean(axis=0)
        avg_G = point.matrix(derivative=True).toarray().mean(axis=0)
        one = make_shape(grid, x[p:p + 1], volume[p:p + 1], "bspline_gimp")
        assert np.abs(one.matrix().toarray()[0] - avg_S).max() < 1e-6, p
        assert np.abs(one.matrix(derivative=True).toarray()[0] - avg_G).max() < 1e-4, p
    assert shape.S.shape[0] == x.size


def test_bspline_gimp_gradient_is_the_derivative_of_its_value(rng):
    """``G_ip = d S_ip / d x_p`` (central differences, interior particles)."""
    grid = uniform_grid(0.0, 1.0, 0.05)
    x = rng.uniform(0.1, 0.9, 200)
    V = rng.uniform(0.2, 1.5, x.size) * 0.05
    d = 1e-6
    S_plus = make_shape(grid, x + d, V, "bspline_gimp").matrix().toarray()
    S_minus = make_shape(grid, x - d, V, "bspline_gimp").matrix().toarray()
    G = make_shape(grid, x, V, "bspline_gimp").matrix(derivative=True).toarray()
    assert np.abs((S_plus - S_minus) / (2 * d) - G).max() < 1e-5 * np.abs(G).max()


def test_bspline_gimp_tends_to_the_point_bspline_for_small_domains(rng):
    grid = uniform_grid(0.0, 1.0, 0.1)
    x = rng.uniform(0.01, 0.99, 500)
    small = make_shape(grid, x, np.full(x.size, 1e-5), "bspline_gimp").matrix().toarray()
    assert np.abs(small - bspline_shape(grid, x).matrix().toarray()).max() < 1e-8  # O(V^2 / h^2) + round-off


def test_tiling_domains_project_the_exact_volume_of_each_spline(rng):
    """``sum_p V_p S_ip = int N_i dx`` (h/2 at an end node: the open knot vector's end function) when the
    domains tile the grid."""
    grid = uniform_grid(0.0, 1.0, 0.1)
    edges = np.sort(np.concatenate(([0.0, 1.0], rng.uniform(0, 1, 97))))
    x, V = 0.5 * (edges[1:] + edges[:-1]), np.diff(edges)
    claimed = make_shape(grid, x, V, "bspline_gimp").scatter(V)
    integrals = basis_integrals(grid, "bspline_gimp")
    assert np.abs(claimed - integrals).max() < 1e-14
    assert integrals[0] == pytest.approx(0.1 / 2, rel=1e-12)


# ---------------------------------------------------------------- (b) Taylor least-squares reconstruction

def test_taylor_fit_reproduces_a_line_and_falls_back_to_the_mean():
    cell = np.array([0, 0, 0, 1, 2, 2])
    xi = np.array([0.1, 0.5, 0.8, 0.3, 0.4, 0.4])
    q = np.array([1.0 + 2 * (0.1 - 0.5), 1.0, 1.0 + 2 * 0.3, 7.0, 2.0, 4.0])
    s0, s1 = taylor_fit(cell, xi, q, 4)
    np.testing.assert_allclose([s0[0], s1[0]], [1.0, 2.0], atol=1e-13)
    assert (s0[1], s1[1]) == (7.0, 0.0)  # one particle: constant
    assert (s0[2], s1[2]) == (3.0, 0.0)  # two particles at one point: their mean
    assert (s0[3], s1[3]) == (0.0, 0.0)  # empty cell: no stress


@pytest.mark.parametrize("basis", ["mpm", "bspline"])
def test_reconstructed_force_is_exact_for_a_linear_stress_at_random_particles(basis, rng):
    """``F_i = - int sigma S_i'`` exactly for ``sigma = 2 - 3x``, wherever the particles sit; the
    particle sum at the same random particles is not."""
    grid = uniform_grid(0.0, 1.0, 0.1)
    x = np.sort(rng.uniform(0, 1, 80))
    V = np.full(x.size, 1.0 / x.size)
    sigma = lambda y: 2.0 - 3.0 * y  # noqa: E731
    fine, w = seed_positions(grid, 1000)  # midpoint rule with 1000 points per cell: exact to ~1e-7
    exact = nodal_internal_force(make_shape(grid, fine, w, basis), w, sigma(fine))
    F = reconstructed_force(grid, x, sigma(x), basis)
    assert np.abs(F - exact).max() < 1e-6
    assert np.abs(nodal_internal_force(make_shape(grid, x, V, basis), V, sigma(x)) - exact).max() > 1e-2


def test_reconstructed_force_sums_to_zero(rng):
    grid = uniform_grid(0.0, 1.0, 0.05)
    x = rng.uniform(0, 1, 400)
    for basis in names():
        F = reconstructed_force(grid, x, rng.normal(size=x.size), basis)
        assert abs(F.sum()) < 1e-12 * np.abs(F).sum(), basis


# ---------------------------------------------------------------- (c) volume reset against the grid

@pytest.mark.parametrize("basis", ["mpm", "bspline"])
def test_volume_reset_leaves_tiling_domains_alone_and_restores_the_total_volume(basis, rng):
    grid = uniform_grid(0.0, 1.0, 0.05)
    edges = (np.arange(301) + np.r_[0.0, rng.uniform(-0.35, 0.35, 299), 0.0]) / 300  # domains of 0.3 to 1.7 / 300
    x, V = 0.5 * (edges[1:] + edges[:-1]), np.diff(edges)
    assert np.abs(grid_volume_factor(grid, x, V, basis) - 1).max() < 1e-12
    drifted = V * rng.uniform(0.9, 1.15, V.size)
    f = grid_volume_factor(grid, x, drifted, basis)
    assert f.min() > 0
    assert np.sum(drifted * f) == pytest.approx(1.0, abs=1e-13)


def test_gas_state_at_a_reset_volume_keeps_mass_and_internal_energy(rng):
    gas = IdealGas(1.4, 0.5, 2.0)
    p = make_particles(np.linspace(0.1, 0.9, 9), 0.1, rng.uniform(0.5, 2, 9), 0.0, rng.uniform(1, 3, 9), 0.0)
    p = p.replace(pressure=gas.thermal_pressure(p.density, p.energy) + 0.1 * p.density)  # with a viscosity q
    new = gas.with_volume(p, p.volume * rng.uniform(0.8, 1.2, 9))
    np.testing.assert_array_equal(new.mass, p.mass)
    np.testing.assert_array_equal(new.energy, p.energy)
    np.testing.assert_allclose(new.density * new.volume, p.mass, rtol=1e-15)
    np.testing.assert_allclose(new.pressure, gas.thermal_pressure(new.density, new.energy) + 0.1 * new.density,
                               rtol=1e-14)


# ---------------------------------------------------------------- conservation by the step, every remedy

@dataclasses.dataclass(frozen=True)
class Free:
    """No boundary condition: the particles stay away from the ends, so no reaction enters."""

    def velocity(self, grid, v, t):
        return v

    def acceleration(self, grid, a, v, t, dt):
        return a


REMEDIES = {
    "bspline_gimp": dict(basis="bspline_gimp"),
    "taylor": dict(reconstruct="taylor"),
    "grid volume": dict(volume="grid"),
    "flip 0.7": dict(flip=0.7),
    "PIC": dict(flip=0.0),
    "all four": dict(basis="bspline_gimp", reconstruct="taylor", volume="grid", flip=0.9),
    "XPIC(2)": dict(xpic=2),
    "XPIC(5) + bspline_gimp": dict(xpic=5, basis="bspline_gimp"),
    "XPIC(3), consistent mass": dict(xpic=3, mass="consistent"),
    "XPIC(2), MUSL": dict(xpic=2, scheme="musl"),
}


@pytest.mark.parametrize("remedy", REMEDIES)
def test_remedy_conserves_mass_and_momentum_in_the_step(remedy):
    """A gas slab [0.3, 0.7] with a pressure pulse (nearly zero at its free ends) and a velocity,
    on [0, 1], no boundary force:
    ``sum m_p`` stays exact and ``sum m_p v_p`` to round-off over 40 steps; after each step it is the
    grid's ``sum_i m_i v_i^{n+1}`` (what PIC gives the particles)."""
    grid = uniform_grid(0.0, 1.0, 0.02)
    x, V = seed_positions(grid, 4)
    keep = (x > 0.3) & (x < 0.7)
    x, V = x[keep], V[keep]
    gas = IdealGas(1.4, 0.5, 2.0)
    p = 1e-3 + 0.3 * np.exp(-((x - 0.5) / 0.05) ** 2)
    particles = make_particles(x, V, 1.0, 0.05 * np.sin(9 * x), p / 0.4, p)
    stages = Stages(**REMEDIES[remedy])
    mass, momentum = particles.mass.sum(), np.sum(particles.mass * particles.velocity)
    for n in range(40):
        particles, state = explicit_step(grid, particles, gas, Free(), n * 1e-3, 1e-3, stages)
        assert abs(np.sum(particles.mass * particles.velocity) - np.sum(state.mass * state.new_velocity)) < 1e-15 * 40
    assert particles.mass.sum() == mass
    assert abs(np.sum(particles.mass * particles.velocity) - momentum) < 1e-15 * 40
    assert np.all(np.isfinite(particles.density))


def test_flip_one_is_the_plain_step_and_pic_takes_the_grid_velocity():
    problem, grid, particles, stages = pulse_setup(PulseSettings(h=0.05, T=0.02))
    plain, _ = explicit_step(grid, particles, problem.model, problem.boundary, 0.0, problem.dt, Stages())
    flip, _ = explicit_step(grid, particles, problem.model, problem.boundary, 0.0, problem.dt, Stages(flip=1.0))
    np.testing.assert_array_equal(plain.velocity, flip.velocity)
    pic, state = explicit_step(grid, particles, problem.model, problem.boundary, 0.0, problem.dt, Stages(flip=0.0))
    shape = make_shape(grid, particles.x)
    np.testing.assert_allclose(pic.velocity, shape.gather(state.new_velocity), rtol=0, atol=1e-15)


def test_remedy_options_are_checked():
    with pytest.raises(ValueError, match="PIC/FLIP blend"):
        Stages(flip=1.5)
    with pytest.raises(ValueError, match="unknown reconstruct"):
        Stages(reconstruct="wls")
    with pytest.raises(ValueError, match="unknown volume"):
        Stages(volume="fixed")
    with pytest.raises(ValueError, match="MPM stages only"):
        Stages(projection="exact", reconstruct="taylor")
    assert not Stages().uses_remedy and Stages(flip=0.5).uses_remedy


# ---------------------------------------------------------------- orders on smooth problems

def _pulse_order(quantity: str, changes: dict) -> float:
    """Fitted order of ``|q_h - q_ref|`` (L1 of the piecewise-linear particle fields) over
    h = 0.04, 0.02, 0.01 against the same scheme at h = 0.0025 (the smooth pulse, T = 0.1).
    The numpy step: these runs measure the method; the fused step's equality to it, remedy by
    remedy, is tests/test_fused_remedies.py (and this way no loop variant compiles here)."""
    out = []
    hs = (0.04, 0.02, 0.01, 0.0025)
    for h in hs:
        problem, grid, particles, stages = pulse_setup(PulseSettings(h=h, basis=changes.get("basis", "mpm")))
        stages = dataclasses.replace(stages, **{k: v for k, v in changes.items() if k != "basis"})
        out.append(run(problem, grid, particles, stages, progress=False, kernel="numpy").particles)
    errors = [field_difference(r, out[-1], (0.0, 1.0), quantity) for r in out[:-1]]
    return fitted_order(hs[:-1], errors)


PULSE_BANDS = {  # (changes, lowest order accepted): first order at least, the time error's order
    "bspline_gimp": (dict(basis="bspline_gimp"), 0.8),
    "taylor": (dict(reconstruct="taylor"), 1.0),
    "taylor + grid volume": (dict(reconstruct="taylor", volume="grid"), 1.0),
    "bspline_gimp + grid volume": (dict(basis="bspline_gimp", volume="grid"), 0.8),
    "taylor + flip 0.9": (dict(reconstruct="taylor", flip=0.9), 1.0),
    "taylor + PIC": (dict(reconstruct="taylor", flip=0.0), 1.0),
}


@pytest.mark.parametrize("remedy", PULSE_BANDS)
def test_remedy_converges_on_the_smooth_pulse(remedy):
    changes, band = PULSE_BANDS[remedy]
    for quantity in ("velocity", "density"):
        order = _pulse_order(quantity, changes)
        assert band <= order < 2.6, f"{remedy}: {quantity} order {order:.2f}"


def test_plain_mpm_does_not_converge_on_the_pulse():
    """The contrast: point-mass MPM with 4 particles per cell stalls on the same pulse (cell-crossing
    noise), which is what the remedies above remove."""
    assert _pulse_order("velocity", {}) < 0.3


BURGERS_BANDS = {  # smooth exact solution (rarefaction, eps = 0.045), 4 ppc, calculated acceleration
    "bspline_gimp": (dict(basis="bspline_gimp"), 1.8),
    "taylor": (dict(reconstruct="taylor"), 1.2),
    "bspline_gimp + grid volume": (dict(basis="bspline_gimp", volume="grid"), 1.8),
}


@pytest.mark.parametrize("remedy", BURGERS_BANDS)
def test_remedy_order_on_smooth_burgers_against_the_exact_solution(remedy):
    changes, band = BURGERS_BANDS[remedy]
    hs = (0.04, 0.02, 0.01)
    errors = {"particles": [], "nodes": []}
    for h in hs:
        settings = burgers.BurgersSettings(h=h, ppc=4, kernel="numpy", **changes)  # as _pulse_order
        e = burgers.errors(settings, burgers.simulate(settings, progress=False))["velocity"]
        for where in errors:
            errors[where].append(e[where]["L1"])
    for where, e in errors.items():
        order = fitted_order(hs, e)
        assert band <= order < 2.6, f"{remedy}: {where} order {order:.2f} ({e})"
