"""The compiled sums of the exact grid stage (mpm_fem.grid_kernels) equal the numpy ones bit for bit."""

import numpy as np
import pytest

from mpm_fem.exact_stages import (RiemannFields, exact_projection, fe_mass, fe_mass_operator, nodal_sums,
                                  nodal_sums_numpy, quadrature_rule)
from mpm_fem.grid import uniform_grid

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
            got, want = nodal_sums(shape, w, rho, v, sigma, with_mass), nodal_sums_numpy(shape, w, rho, v, sigma, with_mass)
            assert (got[0] is None) == (want[0] is None) == (not with_mass)
            for a, b in zip(got, want):
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
