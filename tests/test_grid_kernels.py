"""The compiled sums of the exact grid stage (mpm_fem.exact_stages.grid_kernels) equal the numpy ones bit for bit."""

import numpy as np
import pytest

from mpm_fem.core.grid import uniform_grid
from mpm_fem.exact_stages.mass import fe_mass, fe_mass_operator
from mpm_fem.exact_stages.projection import exact_projection, nodal_sums, nodal_sums_numpy
from mpm_fem.exact_stages.quadrature import quadrature_rule
from mpm_fem.problems.sod import RiemannFields

SOD = RiemannFields((1.0, 0.0, 1.0), (0.125, 0.0, 0.1), 0.5, 1.4, 0.01)
TIMES = (0.0, 0.013, 0.1, 0.2)  # no cut (t = 0: every breakpoint on the node x0), then four cuts


class Cubic:
    """A smooth density with breakpoints two in one piece, one on a node, one on a half cell, outside."""

    def integrand(self, x, t):
        return 1 + x + x**3, x, -x * x

    def breakpoints(self, t):
        return np.array([0.2631, 0.2632, 0.37, 0.455, 0.5, 1.2, -0.1])


@pytest.mark.parametrize("functions", ["mpm", "bspline"])
@pytest.mark.parametrize("h", [0.05, 0.01])
def test_splice_and_nodal_sums_equal_numpy_bit_for_bit(functions, h):
    grid = uniform_grid(0.0, 1.0, h)
    rule = quadrature_rule(grid, functions)
    for fields, t in [(SOD, t) for t in TIMES] + [(Cubic(), 0.0)]:
        cuts = rule.cuts(fields.breakpoints(t))
        (x, w, shape), (x0, w0, shape0) = rule.splice(cuts), rule.splice_numpy(cuts)
        assert np.array_equal(x, x0) and np.array_equal(w, w0)
        for name in ("nodes", "S", "G", "cell"):
            assert np.array_equal(getattr(shape, name), getattr(shape0, name)), name
        rho, v, sigma = fields.integrand(x, t)
        for with_mass in (True, False):
            got, want = (nodal_sums(shape, w, rho, v, sigma, with_mass),
                         nodal_sums_numpy(shape, w, rho, v, sigma, with_mass))
            assert (got[0] is None) == (want[0] is None) == (not with_mass)
            for a, b in zip(got, want, strict=False):
                assert a is None or np.array_equal(a, b)


@pytest.mark.parametrize("functions", ["mpm", "bspline"])
@pytest.mark.parametrize("h", [0.05, 0.01])
def test_fe_mass_entries_equal_numpy_bit_for_bit(functions, h):
    grid = uniform_grid(0.0, 1.0, h)
    op = fe_mass_operator(grid, functions)
    for fields, t in [(SOD, t) for t in TIMES] + [(Cubic(), 0.0)]:
        assert np.array_equal(op.entries(fields, t), op.entries_numpy(fields, t))
        cuts = quadrature_rule(grid, functions).cuts(fields.breakpoints(t))
        assert np.array_equal(op.entries(fields, t, cuts), op.entries_numpy(fields, t))


def test_the_lumped_fe_mass_assembles_its_matrix_only_on_demand():
    grid = uniform_grid(0.0, 1.0, 0.02)
    M, m = fe_mass(grid, "bspline", SOD, 0.1)
    build, m_lazy = fe_mass(grid, "bspline", SOD, 0.1, assembled=False)
    assert np.array_equal(m, m_lazy) and callable(build)
    assert (build() != M).nnz == 0
    data = exact_projection(grid, "bspline", SOD, 0.1, with_fe_mass=True)
    assert np.array_equal(data.m_i, m) and callable(data.matrix)


def test_cut_pieces_equal_numpy_bit_for_bit():
    """Random breakpoints (outside the domain, on nodes, on half cells, repeated) on uniform grids and,
    for the hats, a random one: the cut pieces, the sub-pieces' points, weights and rows."""
    from mpm_fem.core.grid import grid_from_nodes

    rng = np.random.default_rng(1)
    grids = [(uniform_grid(0.0, 1.0, h), ("mpm", "bspline")) for h in (0.05, 0.01)]
    grids += [(uniform_grid(-0.3, 1.7, 0.0125), ("mpm", "bspline"))]
    grids += [(grid_from_nodes(np.sort(np.concatenate(([0.0, 1.0], rng.uniform(0, 1, 60))))), ("mpm",))]
    for grid, functions in grids:
        for kind in functions:
            rule = quadrature_rule(grid, kind)
            a, b = grid.domain
            for trial in range(100):
                bp = rng.uniform(a - 0.1, b + 0.1, rng.integers(0, 8))
                if trial % 3 == 0:
                    bp = np.concatenate((bp, grid.nodes[rng.integers(0, grid.n_nodes, 2)], bp[:1]))
                if trial % 5 == 0:
                    bp = np.concatenate((bp, rule.edges[rng.integers(0, rule.edges.size, 2)]))
                got, want = rule.cuts(bp), rule.cuts_numpy(bp)
                for name in ("cut", "first", "x", "w"):
                    u, v = getattr(got, name), getattr(want, name)
                    assert u.shape == v.shape and np.array_equal(u, v), name
                for name in ("nodes", "S", "G", "cell"):
                    u, v = getattr(got.rows, name), getattr(want.rows, name)
                    assert u.shape == v.shape and np.array_equal(u, v), name


@pytest.mark.parametrize("functions", ["mpm", "bspline"])
def test_the_fe_mass_sums_a_symmetric_entry_once(functions):
    """``M_ji`` is copied from ``M_ij`` only where their rows of the operator are the same bit for bit."""
    op = fe_mass_operator(uniform_grid(0.0, 1.0, 0.01), functions)
    n, A = op.grid.n_nodes, op.assemble
    shared = np.flatnonzero(op.mirror != np.arange(op.keys.size))
    assert shared.size > 0.3 * op.keys.size
    for e in shared:
        f = op.mirror[e]
        assert f < e and op.keys[f] == (op.keys[e] % n) * n + op.keys[e] // n
        assert np.array_equal(A.indices[A.indptr[e]:A.indptr[e + 1]], A.indices[A.indptr[f]:A.indptr[f + 1]])
        assert np.array_equal(A.data[A.indptr[e]:A.indptr[e + 1]], A.data[A.indptr[f]:A.indptr[f + 1]])


@pytest.mark.parametrize("basis", ["mpm", "bspline"])
def test_the_exact_mass_stage_solve_equals_numpy_bit_for_bit(basis):
    """``v*_i + P_i / m_i - P*_i / m*_i`` compiled, against :func:`nodal_values` (a node without mass included)."""
    from mpm_fem.core.step import Stages, Walls
    from mpm_fem.exact_stages import ExactGridStage, GridData

    grid = uniform_grid(0.0, 1.0, 0.01)
    rng = np.random.default_rng(2)
    m_i, P_i = rng.uniform(0.5, 1.5, grid.n_nodes), rng.normal(size=grid.n_nodes)
    m_i[[0, 7]] = 0.0
    mpm = GridData(None, None, m_i, P_i)
    for t in (0.0, 0.1):
        stage = ExactGridStage(grid, Walls(), Stages(mass="exact", basis=basis), SOD, mpm, t, 1e-3)
        F = rng.normal(size=grid.n_nodes)
        for rhs, exact_rhs, ref in ((P_i, stage.quad.P_i, stage.star_v), (F, stage.quad.F_i, stage.ref_a)):
            assert np.array_equal(stage.solve(rhs, exact_rhs, ref), stage.solve_numpy(rhs, exact_rhs, ref))
    both = ExactGridStage(grid, Walls(), Stages(mass="exact", projection="exact", basis=basis), SOD, mpm, 0.1, 1e-3)
    assert both.quad is None and np.array_equal(both.v_i, both.star_v)  # v_i = v*_i: no quadrature made
