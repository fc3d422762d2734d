"""The FE + mass lumping stage's mass matrices, assembled by scikit-fem (mpm_fem.exact_stages.mass.fe_mass),
against the particle mass matrix on Gauss points, an exact matrix, and where the step uses them."""

import numpy as np
import pytest
import scipy.sparse as sp
from skfem import Basis, BilinearForm, ElementLineP1, ElementLineP2, ElementLinePp, MeshLine, asm

from mpm_fem.bases import get, names
from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.models.euler import IdealGas
from mpm_fem.core.shape import make_shape
from mpm_fem.core.step import Stages, Walls, explicit_step
from mpm_fem.core.transfer import particle_mass_matrix
from mpm_fem.exact_stages import FieldStages, projection
from mpm_fem.exact_stages.grid_data import nodal_values
from mpm_fem.exact_stages.mass import fe_mass, fe_mass_operator
from mpm_fem.exact_stages.projection import exact_projection
from mpm_fem.exact_stages.quadrature import _pieces, quadrature
from mpm_fem.problems import sod
from mpm_fem.problems.burgers import SmoothBurgersFields
from mpm_fem.problems.sod import RiemannFields

SOD = ((1.0, 0.0, 1.0), (0.125, 0.0, 0.1))


class Cubic:
    """A smooth density ``1 + x + x^3`` with two breakpoints that cut cells (tests the splits)."""

    def integrand(self, x, t):
        return 1 + x + x**3, x, x

    def breakpoints(self, t):
        return np.array([0.3141, 0.777])


FIELDS = {"sod at t = 0.13": (RiemannFields(*SOD, 0.5, 1.4, 0.01), 0.13), "cubic": (Cubic(), 0.0)}


@BilinearForm
def _density_mass(u, v, w):
    return w["rho"] * u * v


def rebuilt_fe_mass(grid, basis, fields, t):
    """The FE mass as scikit-fem assembles it from scratch: a ``Basis`` on the pieces split at the
    nodes, half cells and breakpoints, the form ``rho u v``, and ``M = E^T M_pieces E`` with
    ``E_ki = S_i(y_k)`` at the degrees of freedom (the grid functions are polynomials on a piece)."""
    kernel, degree = get(basis).grid_functions, get(get(basis).grid_functions).degree
    edges = _pieces(grid, fields.breakpoints(t))
    element = {1: ElementLineP1, 2: ElementLineP2}.get(degree, lambda: ElementLinePp(degree))()
    pieces = Basis(MeshLine(edges), element, intorder=9)
    x = np.asarray(pieces.global_coordinates()[0]).ravel()
    rho = fields.integrand(x, t)[0].reshape(pieces.nelems, -1)
    y = pieces.doflocs[0]
    if np.all(np.isfinite(y)):  # nodal: E_ki = S_i(y_k)
        E = make_shape(grid, y, np.zeros_like(y), kernel).matrix()
    else:  # ElementLinePp's hierarchical dofs: E from S_i(x_q) = sum_k E_ki phi_k(x_q), exact on the pieces
        phi = pieces.probes(x[None, :]).toarray()
        E = sp.csr_matrix(np.linalg.lstsq(phi, make_shape(grid, x, np.zeros_like(x), kernel).matrix().toarray(),
                                          rcond=None)[0])
    return (E.T @ asm(_density_mass, pieces, rho=rho) @ E).tocsr()


# the smooth bases' compiled FE-mass entries (20 s of numba each on a cold cache) with the slow tests
@pytest.mark.parametrize("basis", [pytest.param(b, marks=pytest.mark.slow) if b in ("bspline", "cubic") else b
                                   for b in names()])
@pytest.mark.parametrize("case", FIELDS)
def test_the_operator_built_once_equals_scikit_fem_assembling_from_scratch(basis, case):
    """:class:`FEMass` (scikit-fem's basis evaluated once per grid, the density summed per step)
    gives scikit-fem's assembly on the split mesh to round-off, at several times of one run."""
    fields, t = FIELDS[case]
    grid = uniform_grid(0.0, 1.0, 0.05)
    for time in (t, 0.5 * t, 0.0, 0.07):
        M, m = fe_mass(grid, basis, fields, time)
        want = rebuilt_fe_mass(grid, basis, fields, time)
        gap = np.abs((M - want).toarray()).max()
        assert gap < 1e-14 * np.abs(want.toarray()).max(), f"t = {time}: largest difference {gap:.2e}"
    kernel = get(basis).grid_functions
    assert fe_mass_operator(grid, kernel) is fe_mass_operator(grid, kernel)  # built once


# the cubic's compiled FE-mass entries (20-30 s of numba on a cold cache) with the slow tests; the point mass's and
# the quadratic's compile for tests/test_budget.py's exact projection anyway
@pytest.mark.parametrize("basis", [pytest.param(b, marks=pytest.mark.slow) if b == "cubic" else b for b in names()])
@pytest.mark.parametrize("case", FIELDS)
def test_scikit_fem_mass_equals_the_particle_matrix_on_gauss_points(basis, case):
    """Particles at the Gauss points of :func:`quadrature`, of mass ``w_q rho(x_q)``, give the
    same ``M_ij = sum_q w_q rho_q S_iq S_jq`` as scikit-fem's ``rho u v`` form, to round-off."""
    fields, t = FIELDS[case]
    grid = uniform_grid(0.0, 1.0, 0.05)
    M, m = fe_mass(grid, basis, fields, t)
    x, w = quadrature(grid, fields.breakpoints(t))
    kernel = get(basis).grid_functions
    particles = particle_mass_matrix(make_shape(grid, x, w, kernel), w * fields.integrand(x, t)[0])
    gap = np.abs((M - particles).toarray()).max()
    assert gap < 1e-14 * np.abs(M).max(), f"largest difference {gap:.2e}"
    np.testing.assert_allclose(m, np.asarray(M.sum(axis=1)).ravel(), rtol=1e-15)  # lumped = row sums


def test_sod_lumped_mass_sums_to_the_exact_total_mass():
    """``sum_i m_i = int rho dx``: the Sod tube holds 0.5625 at any time before the waves reach the walls."""
    grid = uniform_grid(0.0, 1.0, 0.01)
    for basis in ("mpm", "bspline"):
        _, m = fe_mass(grid, basis, RiemannFields(*SOD, 0.5, 1.4, 0.005), 0.17)
        assert m.sum() == pytest.approx(0.5625, rel=1e-14)


def test_unit_density_gives_the_textbook_p1_mass_matrix():
    """rho = 1: ``M = h/6 [2 1; 1 2]`` per cell, i.e. 2h/3 and h/6 inside, h/3 at the ends."""
    h = 0.1
    M, m = fe_mass(uniform_grid(0.0, 1.0, h), "mpm", SmoothBurgersFields(_Flat(), 0.1), 0.0)
    A = M.toarray()
    np.testing.assert_allclose(np.diag(A), [h / 3] + [2 * h / 3] * 9 + [h / 3], rtol=1e-14)
    np.testing.assert_allclose(np.diag(A, 1), h / 6, rtol=1e-14)
    assert np.abs(np.triu(A, 2)).max() == 0.0
    np.testing.assert_allclose(m, [h / 2] + [h] * 9 + [h / 2], rtol=1e-14)


class _Flat:
    """A Burgers 'solution' v = 0 (only the unit density matters here)."""

    def fields(self, x, t):
        zero = np.zeros_like(np.asarray(x, dtype=float))
        return zero, zero, zero, zero


def _sod_step(stages):
    settings = sod.SodSettings(h=0.05, ppc=4)
    grid = uniform_grid(0.0, 1.0, settings.h)
    particles = sod.initial_particles(settings, grid)
    return explicit_step(grid, particles, IdealGas(), Walls(), 0.1, 1e-3, stages,
                         exact=FieldStages(sod.exact_fields(settings)))


def test_only_the_exact_mass_stage_assembles_with_scikit_fem(monkeypatch):
    """The MPM stages (lumped, consistent particle mass) and the exact projection never call
    :func:`fe_mass`; the FE + mass lumping stage does, once a step, and its nodal values differ
    from those with the Gauss-point sums by round-off only."""
    calls = []
    real = projection.fe_mass

    def spy(*args, **kwargs):
        calls.append(args[1])
        return real(*args, **kwargs)

    monkeypatch.setattr(projection, "fe_mass", spy)
    for stages in (Stages(), Stages(mass="consistent"), Stages(projection="exact"),
                   Stages(projection="exact", mass="consistent"), Stages(projection="exact", mass="exact")):
        _sod_step(stages)
    assert calls == []
    _, with_fe = _sod_step(Stages(mass="exact"))
    assert calls == ["mpm"]

    def gauss_sums(grid, basis, fields, t, cuts=None, assembled=True):
        x, w = quadrature(grid, fields.breakpoints(t))
        M = particle_mass_matrix(make_shape(grid, x, w, "mpm"), w * fields.integrand(x, t)[0])
        return M, np.asarray(M.sum(axis=1)).ravel()

    monkeypatch.setattr(projection, "fe_mass", gauss_sums)
    _, with_sums = _sod_step(Stages(mass="exact"))
    for name in ("velocity", "acceleration"):
        a, b = getattr(with_fe, name), getattr(with_sums, name)
        assert np.abs(a - b).max() < 1e-13 * np.abs(b).max(), name


def test_exact_projection_mass_agrees_with_and_without_scikit_fem():
    grid = uniform_grid(0.0, 1.0, 0.02)
    fields = RiemannFields(*SOD, 0.5, 1.4, 0.01)
    sums = exact_projection(grid, "bspline", fields, 0.1)
    fe = exact_projection(grid, "bspline", fields, 0.1, with_fe_mass=True)
    assert sums.matrix is None and fe.matrix is not None
    np.testing.assert_allclose(fe.m_i, sums.m_i, rtol=1e-14)
    np.testing.assert_array_equal(fe.P_i, sums.P_i)


@pytest.mark.parametrize("kind", ["lumped", "consistent"])
def test_solves_with_the_fe_mass_equal_those_with_the_gauss_point_particles(kind):
    grid = uniform_grid(0.0, 1.0, 0.02)
    fields = RiemannFields(*SOD, 0.5, 1.4, 0.01)
    sums = exact_projection(grid, "mpm", fields, 0.1)
    fe = exact_projection(grid, "mpm", fields, 0.1, with_fe_mass=True)
    want = nodal_values(sums, sums.P_i, kind)
    assert np.abs(nodal_values(fe, fe.P_i, kind) - want).max() < 1e-13 * np.abs(want).max()
    with pytest.raises(ValueError, match="unknown mass kind"):
        nodal_values(fe, fe.P_i, "diagonal")
