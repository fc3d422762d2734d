"""The cubic B-spline basis (mpm_fem.bases.cubic): partition of unity, reproduction of linear and
quadratic functions away from the walls, C2 continuity across nodes, the integrals, the compiled
kernels against the numpy rows, the fused step against the numpy step, and the projection order."""

from __future__ import annotations

import numpy as np
import pytest

from mpm_fem.bases import get, names
from mpm_fem.bases.contract import Cloud, Geometry, RowStore
from mpm_fem.bases.cubic import _move, _project
from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.shape import basis_integrals, make_shape
from mpm_fem.problems.sod import SodSettings, simulate

H = 0.1
GRID = uniform_grid(0.0, 1.0, H)


def _dense(x, derivative=False, grid=GRID):
    return make_shape(grid, x, basis="cubic").matrix(derivative).toarray()


def test_registered_with_its_attributes():
    b = get("cubic")
    assert "cubic" in names() and b.title == "C2 cubic B-splines at the particle points"
    assert (b.width, b.degree, b.uniform, b.domain, b.grid_functions, b.domain_twin) == (4, 3, True, False, "cubic",
                                                                                       "cubic")
    with pytest.raises(ValueError, match="needs a uniform grid"):
        make_shape(_stretched(), np.array([0.5]), basis="cubic")


def _stretched():
    from mpm_fem.core.grid import grid_from_nodes
    return grid_from_nodes(np.linspace(0.0, 1.0, 11) ** 1.2)


def test_the_interior_values_are_the_spline_2_3_1_6_at_a_node_and_23_48_1_48_at_a_midpoint():
    S = _dense(np.array([0.5, 0.55]))
    np.testing.assert_allclose(S[0, 4:7], [1 / 6, 2 / 3, 1 / 6], rtol=1e-14)
    np.testing.assert_allclose(S[1, 4:8], [1 / 48, 23 / 48, 23 / 48, 1 / 48], rtol=1e-14)
    assert S[0].sum() == pytest.approx(1.0, abs=1e-15)


def test_partition_of_unity_everywhere_and_gradients_sum_to_zero():
    x = np.concatenate([np.linspace(0.0, 1.0, 2001), GRID.nodes, np.random.default_rng(1).uniform(0, 1, 3000)])
    shape = make_shape(GRID, x, basis="cubic")
    assert np.abs(shape.S.sum(axis=1) - 1).max() < 1e-15  # a few ulps: four terms
    assert np.abs(shape.G.sum(axis=1)).max() < 1e-13 / H
    assert shape.S.min() >= 0.0
    # at the walls only the end node's function is nonzero (the open knot vector): 1 there
    walls = _dense(np.array([0.0, 1.0]))
    assert np.array_equal(walls[0], np.eye(GRID.n_nodes)[0]) and np.array_equal(walls[1], np.eye(GRID.n_nodes)[-1])


def _blossoms(t):
    """The B-spline coefficients of 1, x, x^2, x^3 for the cubic splines of the knots ``t`` (Marsden's
    identity: the symmetric functions of the knots ``t_{i+1}, t_{i+2}, t_{i+3}`` over 1, 3, 3, 1)."""
    a, b, c = t[1:-3], t[2:-2], t[3:-1]
    return np.ones_like(a), (a + b + c) / 3, (a * b + a * c + b * c) / 3, a * b * c


def test_reproduces_cubics_with_the_knot_vectors_coefficients_and_the_uniform_ones_away_from_the_walls():
    """``sum_i S_ip x_i^k``: 1 everywhere; away from the walls (``x >= 4h``, where every nonzero
    function is a uniform spline) ``x_p`` exactly, ``x_p^2`` with the coefficients ``x_i^2 - h^2/3``
    (the plain ``x_i^2`` give ``x_p^2 + h^2/3``) and ``x_p^3`` with ``x_i^3 - h^2 x_i``; everywhere,
    the end cells included, 1, x, x^2, x^3 with the open knot vector's coefficients (Marsden's identity)."""
    xi = GRID.nodes
    x = np.linspace(0.0, 1.0, 4001)
    shape = make_shape(GRID, x, basis="cubic")
    inside = (x >= 4 * H) & (x <= 1 - 4 * H)
    for coefficients, want in ((np.ones_like(xi), np.ones_like(x)), (xi, x), (xi**2 - H**2 / 3, x**2),
                               (xi**3 - H**2 * xi, x**3)):
        assert np.abs(shape.gather(coefficients) - want)[inside].max() < 1e-15
    assert np.abs(shape.gather(xi**2) - x**2 - H**2 / 3)[inside].max() < 1e-15
    assert np.abs(shape.gather(np.ones_like(xi)) - 1).max() < 1e-15
    t = np.r_[[0.0] * 4, xi[2:-2], [1.0] * 4]
    for k, coefficients in enumerate(_blossoms(t)):
        gap = np.abs(shape.gather(coefficients) - x**k).max()
        assert gap < 1e-15, f"x^{k}: {gap:.2e}"
    # the end nodes' coefficients of x are the Greville abscissae 0, 2h/3, 5h/3, 3h
    np.testing.assert_allclose(_blossoms(t)[1][:5] / H, [0, 2 / 3, 5 / 3, 3, 4], atol=1e-14)


def test_c2_across_the_nodes():
    """At each interior node, S, G and dG/dx (by finite differences of G) agree on both sides to
    O(d); G is the derivative of S (central differences); the third derivative jumps (the
    splines are cubics, not C3)."""
    d = 1e-6
    nodes = GRID.nodes[1:-1]
    S_l, S_r = _dense(nodes - d), _dense(nodes + d)
    G_l, G_r = _dense(nodes - d, True), _dense(nodes + d, True)
    assert np.abs(S_r - S_l).max() < 2 * d / H  # continuous value (|G| <= 1/(2h))
    assert np.abs(G_r - G_l).max() < 4 * d / H**2  # continuous slope (|S''| <= 2/h^2)
    e = 1e-4
    curvature_l = (_dense(nodes - e, True) - _dense(nodes - 2 * e, True)) / e
    curvature_r = (_dense(nodes + 2 * e, True) - _dense(nodes + e, True)) / e
    assert np.abs(curvature_r - curvature_l).max() < 4 * 3 * e / H**3  # continuous curvature: jump O(e S''')
    assert np.abs(curvature_r).max() == pytest.approx(2 / H**2, rel=1e-2)  # S'' = -2/h^2 at the own node
    x = np.random.default_rng(2).uniform(0.01, 0.99, 500)
    fd = (_dense(x + 1e-7) - _dense(x - 1e-7)) / 2e-7
    assert np.abs(fd - _dense(x, True)).max() < 1e-6 / H


def test_the_integrals_are_exact_1_2_3_4_1_5_4_then_h():
    """``int B_j = (t_{j+4} - t_j)/4``: ``h/2, 3h/4, h, 5h/4`` at the end nodes, ``h`` inside."""
    w = basis_integrals(GRID, "cubic")
    np.testing.assert_allclose(w[:5] / H, [1 / 2, 3 / 4, 1.0, 5 / 4, 1.0], rtol=1e-14)
    np.testing.assert_allclose(w[-5:] / H, [1.0, 5 / 4, 1.0, 3 / 4, 1 / 2], rtol=1e-14)
    assert w.sum() == pytest.approx(1.0, abs=1e-15)
    n = 20000  # midpoint rule: second order, to 1e-9
    x = (np.arange(n) + 0.5) / n
    np.testing.assert_allclose(make_shape(GRID, x, basis="cubic").scatter(np.full(n, 1.0 / n)), w, atol=1e-9)


def _row(kernel, x, inv_spacing, grid=GRID):
    h = np.ascontiguousarray([grid.h, 1.0 / grid.h])
    rows, S, G = np.zeros((x.size, 4), np.intp), np.zeros((x.size, 4)), np.zeros((x.size, 4))
    cells = np.empty(x.size, np.intp)
    for q in range(x.size):
        cells[q], need = kernel(grid.nodes, h, inv_spacing, x[q], 0.0, rows[q], S[q], G[q])
        assert need == 4
    return cells, rows, S, G


def test_the_compiled_kernels_are_the_numpy_rows():
    """``row`` with the node arithmetic (``inv_spacing = 0``) gives the numpy rows bit for bit, with
    the uniform-grid arithmetic to round-off (the end functions at ``y = n - s``, ``s`` to round-off
    of ``n``: a few 1e-15); ``project`` gives the numpy scatters and ``move`` the numpy gathers to
    round-off, the end cells included."""
    b = get("cubic")
    rng = np.random.default_rng(3)
    x = np.sort(np.concatenate([rng.uniform(0, 1, 400), GRID.nodes, [1e-12, 1 - 1e-12]]))
    want = make_shape(GRID, x, basis="cubic")
    cells, rows, S, G = _row(b.kernels.row, x, 0.0)
    assert np.array_equal(cells, want.cell) and np.array_equal(rows, want.nodes)
    assert np.array_equal(S, want.S) and np.array_equal(G, want.G)
    cells, rows, S, G = _row(b.kernels.row, x, 1.0 / H)
    assert np.array_equal(cells, want.cell) and np.array_equal(rows, want.nodes)
    assert np.abs(S - want.S).max() < 1e-14 and np.abs(G - want.G).max() < 1e-13 / H
    m, v, V, p = rng.uniform(0.5, 2, x.size), rng.normal(size=x.size), rng.uniform(0.5, 2, x.size), rng.uniform(
        0.1, 1, x.size)
    n_p = x.size
    rows, S, G = np.zeros((n_p, 4), np.intp), np.zeros((n_p, 4)), np.zeros((n_p, 4))
    cell, buf = np.zeros(n_p, np.intp), np.zeros((3, GRID.n_nodes))
    h = np.ascontiguousarray([GRID.h, 1.0 / GRID.h])
    outside, empty, K = _project(Geometry(GRID.nodes, h, 1.0 / H), Cloud(x, V, m, v, p), True, True, 0, n_p,
                                 RowStore(rows, S, G, cell), buf)
    assert (outside, empty, K) == (-1, -1, 4)
    assert np.array_equal(rows, want.nodes) and np.array_equal(cell, want.cell)
    np.testing.assert_allclose(buf[0], want.scatter(m), rtol=1e-14, atol=1e-14)
    np.testing.assert_allclose(buf[1], want.scatter(m * v), rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(buf[2], want.scatter_gradient(V * p), rtol=1e-12, atol=1e-11)
    a_i, v_n = rng.normal(size=GRID.n_nodes), rng.normal(size=GRID.n_nodes)
    sums = np.array([_move(GRID.nodes, h, 1.0 / H, xq, a_i, v_n) for xq in x])
    assert np.array_equal(sums[:, 0], want.cell)
    np.testing.assert_allclose(sums[:, 1], want.gather(a_i), atol=1e-14)
    np.testing.assert_allclose(sums[:, 2], want.gather(v_n), atol=1e-14)
    np.testing.assert_allclose(sums[:, 3], want.gather_gradient(v_n), atol=1e-12)


# slow: each scheme is a loop variant of its own (1.5-3.5 CPU-min of numba on a cold cache); the cubic's compiled
# rows stay in the fast set (test_the_compiled_kernels_are_the_numpy_rows, tests/test_walls.py's end cells)
@pytest.mark.slow
@pytest.mark.parametrize("scheme", ["usl", "musl"])
def test_the_fused_step_equals_the_numpy_step_on_sod(scheme):
    """Sod's tube with the cubic basis, 0.1 in time (over 100 steps, the shock formed): the fused
    step (uniform-grid arithmetic) within 1e-12 of the numpy step."""
    settings = dict(h=0.02, ppc=4, T=0.1, basis="cubic", scheme=scheme)
    reference = simulate(SodSettings(**settings, kernel="numpy"), progress=False)
    fused = simulate(SodSettings(**settings), progress=False)
    assert reference.steps == fused.steps > 100
    for field in ("x", "velocity", "density", "pressure", "energy", "volume"):
        gap = np.abs(getattr(reference.particles, field) - getattr(fused.particles, field)).max()
        assert gap < 1e-12, f"{field}: {gap:.2e}"
    assert np.ptp(fused.particles.pressure) > 0.5  # the shocked tube


def _projection_error(n_cells, f):
    """The L2 error of the L2 projection of ``f`` onto the cubic splines of ``n_cells`` cells, with
    a 5-point Gauss rule per cell (exact for the mass matrix)."""
    grid = uniform_grid(0.0, 1.0, 1.0 / n_cells)
    g, w = np.polynomial.legendre.leggauss(5)
    x = (grid.nodes[:-1, None] + 0.5 * grid.h[:, None] * (1 + g)).ravel()
    weights = (0.5 * grid.h[:, None] * w).ravel()
    S = make_shape(grid, x, basis="cubic").matrix()
    M = (S.T @ S.multiply(weights[:, None])).toarray()
    c = np.linalg.solve(M, S.T @ (weights * f(x)))
    return np.sqrt(np.sum(weights * (S @ c - f(x)) ** 2))


def test_the_l2_projection_converges_at_fourth_order_up_to_the_walls():
    """The open knot vector's splines hold every cubic up to the walls: the L2 projection of ``f =
    sin(pi x)^4`` and of ``f = sin x`` (not zero at the walls) converge at order 4 (measured from
    1/20 to 1/80: 4.16, 4.36 and 4.44, 4.43; the folded ghosts gave ``sin x`` order 1.5)."""
    flat = [_projection_error(n, lambda x: np.sin(np.pi * x) ** 4) for n in (20, 40, 80)]
    orders = np.log2(np.array(flat[:-1]) / np.array(flat[1:]))
    assert np.all((orders > 3.9) & (orders < 4.5)), orders
    general = [_projection_error(n, np.sin) for n in (20, 40, 80)]
    orders = np.log2(np.array(general[:-1]) / np.array(general[1:]))
    assert np.all((orders > 3.9) & (orders < 4.6)), orders
