"""The B-spline bases at the walls (mpm_fem.bases.ends): the end functions of the open knot vector.

The quadratic (``bspline``), the cubic (``cubic``) and the particle-domain B-spline (``bspline_gimp``)
take at each end the B-splines of the knot vector with the ends repeated ``p + 1`` times: checked
against scipy's ``BSpline`` on that knot vector (values, slopes, and for the particle-domain basis
the averages of its antiderivative), the partition of unity, the wall condition (a velocity that is 0
at the wall nodes interpolates to exactly 0 at the walls, where the folded ghosts gave ``v_1/8`` and
``v_1/6``), the compiled rows against the numpy rows, and Sod runs that stay in the grid and conserve
mass.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import BSpline, make_interp_spline

from mpm_fem.bases import get
from mpm_fem.bases.bspline import _move as quadratic_move
from mpm_fem.bases.bspline import _project as quadratic_project
from mpm_fem.bases.contract import Cloud, Geometry, RowStore
from mpm_fem.bases.ends import BREAKS, MIN_CELLS, QUADRATIC_TOTAL
from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.shape import basis_integrals, make_shape
from mpm_fem.problems.sod import SodSettings, conservation, simulate

H = 0.1
GRID = uniform_grid(0.0, 1.0, H)
DEGREE = {"bspline": 2, "cubic": 3}


def _points(seed=0):
    """Random points on the grid, dense in the four cells at each wall, and the nodes and walls."""
    rng = np.random.default_rng(seed)
    return np.concatenate([rng.uniform(0, 1, 1000), rng.uniform(0, 4 * H, 500), rng.uniform(1 - 4 * H, 1, 500),
                           GRID.nodes, [1e-13, 1 - 1e-13]])


def _reference(degree, grid=GRID):
    """scipy's B-splines of the open knot vector on the nodes: ``make_interp_spline``'s knots, one
    function per node (the columns of the identity)."""
    t = make_interp_spline(grid.nodes, grid.nodes, k=degree).t
    assert np.all(t[: degree + 1] == grid.nodes[0]) and np.all(t[-degree - 1:] == grid.nodes[-1])  # open
    return BSpline(t, np.eye(grid.n_nodes), degree)


@pytest.mark.parametrize("basis", ["bspline", "cubic"])
def test_the_rows_are_scipys_open_knot_vector_bsplines_values_and_slopes(basis):
    x = _points()
    shape = make_shape(GRID, x, basis=basis)
    B = _reference(DEGREE[basis])
    values = np.abs(shape.matrix().toarray() - B(x)).max()
    slopes = np.abs(shape.matrix(derivative=True).toarray() - B.derivative()(x)).max() * H
    assert values < 1e-14 and slopes < 1e-14, (values, slopes)


def test_the_particle_domain_rows_are_averages_of_scipys_open_knot_vector_bsplines():
    """``S_ip = (M_i(x_+) - M_i(x_-))/(x_+ - x_-)``, ``G_ip = (B_i(x_+) - B_i(x_-))/(x_+ - x_-)`` with
    scipy's B-splines ``B_i`` and their antiderivatives ``M_i``, the domains cut at the walls."""
    x = _points(1)
    V = np.random.default_rng(2).uniform(0.2, 1.8, x.size) * H
    shape = make_shape(GRID, x, V, "bspline_gimp")
    B = _reference(2)
    lo, hi = np.maximum(x - V / 2, 0.0), np.minimum(x + V / 2, 1.0)
    M = B.antiderivative()
    S = (M(hi) - M(lo)) / (hi - lo)[:, None]
    G = (B(hi) - B(lo)) / (hi - lo)[:, None]
    values = np.abs(shape.matrix().toarray() - S).max()
    slopes = np.abs(shape.matrix(derivative=True).toarray() - G).max() * H
    assert values < 1e-14 and slopes < 1e-13, (values, slopes)


@pytest.mark.parametrize("basis", ["bspline", "cubic", "bspline_gimp"])
def test_partition_of_unity_and_gradients_summing_to_zero_up_to_the_walls(basis):
    x = _points(3)
    V = np.full(x.size, 0.7 * H)
    shape = make_shape(GRID, x, V, basis)
    unity, slopes = np.abs(shape.S.sum(axis=1) - 1).max(), np.abs(shape.G.sum(axis=1)).max() * H
    assert unity < 1e-14 and slopes < 1e-14, (unity, slopes)
    assert shape.S.min() > -1e-15


@pytest.mark.parametrize("basis", ["bspline", "cubic", "bspline_gimp"])
def test_the_interpolated_velocity_is_exactly_zero_at_the_walls(basis):
    """With ``v_0 = v_n = 0`` the grid functions' velocity at a wall is exactly 0 (only the end
    function is nonzero there; the folded ghosts gave ``v_1/8``, the cubic ``v_1/6``); at a
    distance ``d`` from the wall it is ``O(d)``, and so is the particle-domain basis's average over a
    domain ``[0, 2d]`` at the wall: a particle moving with it approaches the wall, it does not cross."""
    v = np.random.default_rng(4).uniform(0.5, 1.5, GRID.n_nodes)
    v[GRID.boundary_nodes] = 0.0
    d = 1e-6 * H
    near = make_shape(GRID, np.array([d, 1 - d]), np.full(2, 2 * d), basis).gather(v)
    assert np.all(np.abs(near) < 3 * v.max() * d / H), near
    if basis == "bspline_gimp":  # a domain average: the walls' values are those of its grid functions
        return
    at_walls = make_shape(GRID, np.array([0.0, 1.0]), basis=basis).gather(v)
    assert np.array_equal(at_walls, [0.0, 0.0]), at_walls


def test_the_integrals_are_the_end_functions_h_2_5h_6_7h_6_then_h():
    w = basis_integrals(GRID, "bspline") / H
    np.testing.assert_allclose(w[:4], [1 / 2, 5 / 6, 7 / 6, 1.0], rtol=1e-14)
    np.testing.assert_allclose(w[-4:], [1.0, 7 / 6, 5 / 6, 1 / 2], rtol=1e-14)
    np.testing.assert_allclose(QUADRATIC_TOTAL, [1 / 2, 5 / 6, 7 / 6], rtol=1e-15)
    np.testing.assert_allclose(w, _reference(2).integrate(0.0, 1.0) / H, rtol=1e-14)
    np.testing.assert_allclose(basis_integrals(GRID, "cubic"), _reference(3).integrate(0.0, 1.0), rtol=1e-14)
    assert np.array_equal(basis_integrals(GRID, "bspline_gimp"), basis_integrals(GRID, "bspline"))


@pytest.mark.parametrize("basis", ["bspline", "cubic", "bspline_gimp"])
def test_a_grid_too_small_for_the_end_functions_is_refused(basis):
    degree = DEGREE.get(basis, 2)
    small = uniform_grid(0.0, 1.0, 1.0 / (MIN_CELLS[degree] - 1))
    with pytest.raises(ValueError, match=f"at least {MIN_CELLS[degree]} cells"):
        make_shape(small, np.array([0.5]), np.array([0.1]), basis)
    with pytest.raises(ValueError, match="cells"):
        get(basis).check_grid(small)
    assert BREAKS[degree][-1] <= MIN_CELLS[degree]


def _rows(kernel, grid, x, V, K, inv_spacing):
    h = np.ascontiguousarray([grid.h, 1.0 / grid.h])
    rows, S, G = np.zeros((x.size, K), np.intp), np.zeros((x.size, K)), np.zeros((x.size, K))
    cells = np.empty(x.size, np.intp)
    for q in range(x.size):
        cells[q], need = kernel(grid.nodes, h, inv_spacing, x[q], V[q], rows[q], S[q], G[q])
        assert need <= K
    return cells, rows, S, G


@pytest.mark.parametrize("basis", ["bspline", "cubic", "bspline_gimp"])
def test_the_compiled_rows_are_the_numpy_rows_in_the_end_cells(basis):
    """The compiled ``row`` near the walls: the numpy rows bit for bit in the node arithmetic, to
    round-off in the uniform-grid arithmetic (the end functions at ``y = n - s``, ``s`` to a few
    ulps of ``n``)."""
    x = _points(5)
    V = np.random.default_rng(6).uniform(0.2, 1.5, x.size) * H
    want = make_shape(GRID, x, V, basis)
    K = want.S.shape[1]
    kernel = get(basis).kernels.row
    cells, rows, S, G = _rows(kernel, GRID, x, V, K, 0.0)
    assert np.array_equal(cells, want.cell) and np.array_equal(rows, want.nodes)
    assert np.array_equal(S, want.S) and np.array_equal(G, want.G)
    cells, rows, S, G = _rows(kernel, GRID, x, V, K, 1.0 / H)
    dense = np.zeros((x.size, GRID.n_nodes))
    np.add.at(dense, (np.repeat(np.arange(x.size), K), rows.ravel()), S.ravel())
    gap = np.abs(dense - want.matrix().toarray()).max()
    assert gap < 1e-14, gap


def test_the_quadratics_compiled_project_and_move_are_the_numpy_scatters_and_gathers():
    """Pass 1's sums (``m S``, ``m v S``, ``V p G``) and pass 2's gathers of the quadratic B-spline
    on a uniform grid equal the numpy rows' to round-off, near the walls included."""
    rng = np.random.default_rng(7)
    x = np.sort(_points(7))
    want = make_shape(GRID, x, basis="bspline")
    n_p = x.size
    m, v, V, p = (rng.uniform(0.5, 2, n_p), rng.normal(size=n_p), rng.uniform(0.5, 2, n_p), rng.uniform(0.1, 1, n_p))
    rows, S, G = np.zeros((n_p, 4), np.intp), np.zeros((n_p, 4)), np.zeros((n_p, 4))
    cell, buf = np.zeros(n_p, np.intp), np.zeros((3, GRID.n_nodes))
    h = np.ascontiguousarray([GRID.h, 1.0 / GRID.h])
    out = quadratic_project(Geometry(GRID.nodes, h, 1.0 / H), Cloud(x, V, m, v, p), True, True, 0, n_p,
                            RowStore(rows, S, G, cell), buf)
    assert out == (-1, -1, 4) and np.array_equal(rows, want.nodes) and np.array_equal(cell, want.cell)
    np.testing.assert_allclose(buf[0], want.scatter(m), rtol=1e-13)
    np.testing.assert_allclose(buf[1], want.scatter(m * v), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(buf[2], want.scatter_gradient(V * p), rtol=1e-12, atol=1e-10)
    a_i, v_n = rng.normal(size=GRID.n_nodes), rng.normal(size=GRID.n_nodes)
    sums = np.array([quadratic_move(GRID.nodes, h, 1.0 / H, xq, a_i, v_n) for xq in x])
    assert np.array_equal(sums[:, 0], want.cell)
    np.testing.assert_allclose(sums[:, 1], want.gather(a_i), atol=1e-14)
    np.testing.assert_allclose(sums[:, 2], want.gather(v_n), atol=1e-14)
    np.testing.assert_allclose(sums[:, 3], want.gather_gradient(v_n), atol=1e-12)


# the numpy step in the fast set; the compiled loop (a variant of its own per basis, 1-2.5 CPU-min of numba
# on a cold cache) with the slow tests: its equality to the numpy step is tests/test_cubic.py's and test_fused.py's
@pytest.mark.parametrize("kernel", ["numpy", pytest.param("fused", marks=pytest.mark.slow)])
@pytest.mark.parametrize("basis", ["bspline", "cubic"])
def test_sod_between_walls_stays_in_the_grid_and_conserves_mass_and_momentum_balance(basis, kernel):
    """Sod, h = 0.02, 4 particles per cell, to T = 0.05 (no wave at a wall): every field finite,
    every particle inside the grid, the mass to round-off, and the momentum grows by the walls'
    impulse ``(p_L - p_R) T``: to round-off for the quadratic (the particles' midpoint rule
    integrates its piecewise-linear wall slope ``G_0`` exactly; measured 1.5e-14), within the
    midpoint rule's error for the cubic's piecewise-quadratic ``G_0 = -(3/2h)(1 - x/2h)^2``,
    ``(w^2/24) |G_0'(0)| = 1/(16 ppc^2)`` relative for particles of width ``w = h/ppc`` (measured 1.1e-3)."""
    settings = SodSettings(h=0.02, T=0.05, basis=basis, kernel=kernel)
    result = simulate(settings, progress=False)
    particles = result.particles
    for field in ("x", "velocity", "density", "pressure", "energy"):
        assert np.isfinite(getattr(particles, field)).all(), field
    assert 0.0 < particles.x.min() and particles.x.max() < 1.0
    change = conservation(settings, result)["relative_change"]
    assert abs(change["mass"]) < 1e-15, change
    bound = 1e-12 if basis == "bspline" else 1.0 / (16 * settings.ppc**2)
    assert abs(change["momentum"]) < bound, change


@pytest.mark.slow
@pytest.mark.parametrize("settings", [
    dict(basis="cubic", h=0.01, ppc=16),
    dict(basis="bspline", h=0.005, ppc=16, layout="jittered", seed=1, cfl=0.05),
], ids=["cubic-regular", "bspline-jittered"])
def test_the_sod_runs_that_left_the_grid_in_the_record_now_run(settings):
    """Settings whose runs stopped with "particle 0 at x = -1.7e-06 lies outside the grid" in the
    record: the cubic at 16 particles per cell on the regular layout, h = 0.01
    (figures/remedies/errors.csv, figures/budget/bases.csv), and the quadratic at 16 per cell,
    jittered layout seed 1, h = 0.005, CFL 0.05 (figures/budget/bases.csv). Each run reaches T = 0.2,
    finite, inside the grid, its mass conserved to round-off."""
    settings = SodSettings(**settings)
    result = simulate(settings, progress=False)
    assert result.t == pytest.approx(0.2, rel=1e-12)
    particles = result.particles
    assert np.isfinite(particles.density).all() and np.isfinite(particles.velocity).all()
    assert 0.0 < particles.x.min() and particles.x.max() < 1.0
    assert abs(conservation(settings, result)["relative_change"]["mass"]) < 1e-14
