"""APIC (:mod:`mpm_fem.core.transfers.apic`): the transfer contract, affine exactness, momentum, a Sod run."""

import numpy as np
import pytest

from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.shape import make_shape
from mpm_fem.core.step import Stages
from mpm_fem.core.transfer import nodal_mass
from mpm_fem.core.transfers import GridVelocities, get, names
from mpm_fem.fused import supported


def _interior(basis):
    grid = uniform_grid(0.0, 1.0, 0.05)
    rng = np.random.default_rng(3)
    x = np.sort(rng.uniform(0.2, 0.8, 60))
    mass = rng.uniform(0.5, 1.5, x.size)
    return grid, x, mass, make_shape(grid, x, np.full(x.size, 0.01), basis)


def test_registry_names_and_refuses_unknown():
    assert names() == ("flip", "xpic", "apic")
    with pytest.raises(ValueError, match="unknown transfer 'nope'; choose one of flip, xpic, apic"):
        Stages(transfer="nope")
    with pytest.raises(ValueError, match="APIC replaces"):
        Stages(transfer="apic", flip=0.5)
    assert Stages(xpic=2).transfer_name == "xpic" and Stages(flip=0.3).transfer_name == "flip"


@pytest.mark.parametrize("basis", ["mpm", "bspline"])
def test_affine_field_round_trip_is_exact(basis):
    """v(x) = a + b x with C_p = b: P2G gives v_i = a + b x_i, G2P gives back v_p and C_p = b."""
    grid, x, mass, shape = _interior(basis)
    a, b = 0.7, -1.3
    apic = get("apic")
    m_i = nodal_mass(shape, mass)
    P_i = apic.momentum(shape, grid.nodes, x, mass, a + b * x, np.full(x.size, b))
    touched = m_i > 0
    v_i = np.where(touched, P_i / np.where(touched, m_i, 1.0), 0.0)
    assert np.abs(v_i[touched] - (a + b * grid.nodes[touched])).max() < 1e-13
    moving = shape.gather(v_i)
    v_p, C_p = apic.update(GridVelocities(shape, mass, m_i, v_i, 0 * v_i, v_i, moving, 0.1, "lumped", lambda u: u),
                           a + b * x, 1.0)
    assert np.abs(v_p - (a + b * x)).max() < 1e-13
    assert np.abs(C_p - b).max() < 1e-12


@pytest.mark.parametrize("basis", ["mpm", "bspline"])
def test_p2g_conserves_momentum(basis):
    grid, x, mass, shape = _interior(basis)
    rng = np.random.default_rng(5)
    v, C = rng.normal(size=x.size), rng.normal(size=x.size) * 10
    P_i = get("apic").momentum(shape, grid.nodes, x, mass, v, C)
    assert abs(P_i.sum() - (mass * v).sum()) < 1e-12 * np.abs(mass * v).sum()


def _stretched_or_drifting(basis):
    """A grid that is not uniform to round-off (the fused step keeps the node arithmetic there, so
    fused and numpy agree bit for bit): stretched for the point bases, nodes drifting 2e-9 h off
    ``x_0 + i h`` for the bases that need equal cells."""
    from mpm_fem.bases import get as get_basis
    from mpm_fem.core.grid import grid_from_nodes

    if not get_basis(basis).uniform:
        return grid_from_nodes(np.linspace(0.0, 1.0, 11) ** 1.2)
    h = 0.1 * np.where(np.arange(10) < 5, 1 + 4e-10, 1 - 4e-10)
    return grid_from_nodes(np.concatenate(([0.0], np.cumsum(h))))


def _wave_run(basis, scheme, kernel, grid, steps=200):
    """An acoustic wave between walls, ``steps`` fixed steps of APIC: the run's result."""
    from mpm_fem.core.models.euler import IdealGas
    from mpm_fem.core.particles import make_particles, seed_positions
    from mpm_fem.core.step import Walls
    from mpm_fem.run.solve import Problem, run

    x, V = seed_positions(grid, 4, "regular", seed=3)
    rho = 1.0 + 0.1 * np.sin(2 * np.pi * x)
    particles = make_particles(x, V, rho, 0.05 * np.sin(np.pi * x), rho**0.4 / 0.4, rho**1.4)
    problem = Problem(model=IdealGas(), boundary=Walls(), T=steps * 1e-3, cfl=1.0, dt=1e-3)
    return run(problem, grid, particles, Stages(transfer="apic", basis=basis, scheme=scheme), progress=False,
               kernel=kernel)


_FIELDS = ("x", "velocity", "volume", "density", "energy", "pressure", "affine")

#: besides the point mass's three schemes, USL with uGIMP; the smooth bases' APIC loops (0.5-1 CPU-min of numba
#: each on a cold cache), the particle-domain B-spline's (its pass 1 alone 1-1.5 CPU-min) and the other schemes run
#: with the slow tests
FAST_USL = {("usl", "gimp")}


@pytest.mark.parametrize(("basis", "scheme"), [
    pytest.param(basis, scheme, marks=() if basis == "mpm" or (scheme, basis) in FAST_USL else pytest.mark.slow)
    for basis in ("mpm", "gimp", "bspline", "bspline_gimp", "cubic") for scheme in ("usl", "usf", "musl")])
def test_the_compiled_apic_step_equals_the_numpy_step_bit_for_bit(basis, scheme):
    """APIC's kernels (P2G's affine term, G2P's ``C_p``, MUSL's re-projection with it) on a grid where
    the fused step keeps the node arithmetic: every particle field and ``C_p`` bit for bit, 200 steps."""
    grid = _stretched_or_drifting(basis)
    reference, fused = (_wave_run(basis, scheme, kernel, grid) for kernel in ("numpy", "fused"))
    assert fused.kernel == "fused" and reference.steps == fused.steps == 200
    for name in _FIELDS:
        u, v = getattr(reference.particles, name), getattr(fused.particles, name)
        assert np.array_equal(u, v), f"{name} differs by {float(np.max(np.abs(u - v))):.3g}"
    assert np.abs(fused.particles.affine).max() > 0.1  # the coefficient is carried, not zero
    assert np.array_equal(reference.nodal_velocity, fused.nodal_velocity)


def test_the_compiled_apic_step_on_a_uniform_grid_agrees_to_round_off():
    """On a uniform grid (the bases' uniform-grid arithmetic) to 1e-12 relative, 1,000 steps."""
    grid = uniform_grid(0.0, 1.0, 0.1)
    reference, fused = (_wave_run("mpm", "usl", kernel, grid, steps=1000) for kernel in ("numpy", "fused"))
    for name in _FIELDS:
        u, v = getattr(reference.particles, name), getattr(fused.particles, name)
        assert np.max(np.abs(u - v)) <= 1e-12 * np.max(np.abs(u)), name


def test_an_affine_transfer_without_kernels_runs_the_numpy_step():
    from mpm_fem.core.models.euler import IdealGas
    from mpm_fem.core.transfers import register
    from mpm_fem.core.transfers.apic import Apic
    from mpm_fem.core.transfers.registry import _TRANSFERS

    class Bare(Apic):
        name = "apic_bare"
        kernels = None

    register(Bare())
    try:
        reason = supported(IdealGas(1.4, 0.5, 2.0), Stages(transfer="apic_bare"))
        assert reason is not None and "apic_bare" in reason
        assert supported(IdealGas(1.4, 0.5, 2.0), Stages(transfer="apic")) is None
    finally:
        del _TRANSFERS["apic_bare"]


def test_sod_with_apic_is_finite_and_close_to_pic():
    from mpm_fem.problems import sod
    from mpm_fem.run.solve import run

    settings = sod.SodSettings(h=0.01, T=0.1)
    grid = sod.uniform_grid(*sod.DOMAIN, settings.h)
    model = sod.IdealGas(settings.gamma, settings.av_linear, settings.av_quadratic)
    problem = sod.Problem(model=model, boundary=sod.Walls(), T=settings.T, cfl=settings.cfl,
                          exact=sod.exact_fields(settings))
    err = {}
    for name, stages in (("apic", Stages(transfer="apic")), ("pic", Stages(flip=0.0)), ("flip", Stages())):
        result = run(problem, grid, sod.initial_particles(settings, grid), stages, kernel="numpy")
        err[name] = sod.errors(settings, result)["density"]["particles"]
    print(err)
    l1 = {k: (v["L1"] if isinstance(v, dict) else v) for k, v in err.items()}
    assert np.isfinite(l1["apic"]) and 0.3 * l1["pic"] < l1["apic"] < 3 * l1["pic"]
    # the compiled kernel: the same error to round-off (a uniform grid: the uniform-grid arithmetic)
    fused = run(problem, grid, sod.initial_particles(settings, grid), Stages(transfer="apic"), kernel="fused")
    assert fused.kernel == "fused"
    got = sod.errors(settings, fused)["density"]["particles"]
    assert abs(got["L1"] - l1["apic"]) <= 1e-10 * l1["apic"]


def test_particles_without_the_affine_coefficient_join_an_apic_set_with_it_zero():
    from mpm_fem.core.particles import make_particles

    old = make_particles([0.1, 0.2], 0.1, 1.0).replace(affine=np.array([2.0, -3.0]))
    new = make_particles([0.3], 0.1, 1.0)  # a reservoir's particle
    assert np.array_equal(old.join(new).affine, [2.0, -3.0, 0.0])
    assert np.array_equal(new.join(old).affine, [0.0, 2.0, -3.0])
    assert new.join(new).affine is None
