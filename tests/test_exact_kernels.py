"""The compiled point evaluations of the exact stages equal the numpy ones bit for bit."""

import numpy as np
import pytest

from baselines.exact import riemann
from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.shape import make_shape
from mpm_fem.exact_stages.quadrature import quadrature, quadrature_rule
from mpm_fem.problems.sod import RiemannFields

# Sod; a left shock and right rarefaction (mirror image); two shocks; two rarefactions
CASES = {
    "sod": ((1.0, 0.0, 1.0), (0.125, 0.0, 0.1)),
    "mirrored sod": ((0.125, 0.0, 0.1), (1.0, 0.0, 1.0)),
    "two shocks": ((1.0, 1.0, 1.0), (1.0, -1.0, 1.0)),
    "two rarefactions": ((1.0, -0.5, 0.4), (1.0, 0.5, 0.4)),
}


@pytest.mark.parametrize("name", CASES)
def test_compiled_riemann_sample_equals_numpy_bit_for_bit(name):
    left, right = CASES[name]
    fields = RiemannFields(left, right, 0.5, 1.4, 0.01)
    x = np.concatenate((np.random.default_rng(1).uniform(-0.5, 1.5, 20_000), fields.breakpoints(0.2), [0.5]))
    for t in (0.2, 1e-3, 3.0):
        got = fields._sample(x, t)
        want = riemann.sample(x, t, left, right, x0=0.5, gamma=1.4)
        for g, w in zip(got, want, strict=False):
            assert np.array_equal(g, w), f"{name} t={t}: {np.count_nonzero(g != w)} points differ"
    regions = np.unique(np.searchsorted(fields.breakpoints(0.2), x))
    assert regions.size == fields.breakpoints(0.2).size + 1  # every wave region sampled


@pytest.mark.parametrize("name", CASES)
def test_compiled_profile_equals_numpy_bit_for_bit(name):
    fields = RiemannFields(*CASES[name], 0.5, 1.4, 0.01)
    xi = np.concatenate((np.random.default_rng(2).uniform(-4, 4, 20_000), fields._speeds))
    for got, want in zip(fields._profile(xi), fields._profile_numpy(xi), strict=False):
        assert np.array_equal(got, want)
    assert np.array_equal(fields._profile(xi[:20_000].reshape(100, -1))[1],
                          fields._profile_numpy(xi[:20_000])[1].reshape(100, -1))


@pytest.mark.parametrize("functions", ["mpm", "bspline"])
def test_quadrature_rule_equals_quadrature_and_make_shape_bit_for_bit(functions):
    """The cached rule spliced at the breakpoints: the points, weights and rows of ``quadrature``
    and ``make_shape`` (breakpoints: two in one piece, one on a node, one on a half cell, outside)."""
    grid = uniform_grid(0.0, 1.0, 0.01)
    rule = quadrature_rule(grid, functions)
    for bp in ([0.2631, 0.2632, 0.37, 0.455, 0.5, 1.2, -0.1], [], [0.999], [0.0001, 0.6853]):
        x, w, shape = rule(bp)
        want_x, want_w = quadrature(grid, bp)
        want = make_shape(grid, want_x, want_w, functions)
        assert np.array_equal(x, want_x) and np.array_equal(w, want_w)
        for name in ("nodes", "S", "G", "cell"):
            assert np.array_equal(getattr(shape, name), getattr(want, name)), name
        inside = [b for b in bp if 0 < b < 1 and not np.isclose(b * 200, round(b * 200))]
        assert x.size == 5 * (200 + len(inside))  # 200 half cells, one more piece per breakpoint inside


@pytest.mark.parametrize("name", CASES)
def test_compiled_reference_fields_equal_numpy_bit_for_bit(name):
    """v*, v*_x, a* (and the gradient alone) of the compiled pass against the numpy formulas."""
    fields = RiemannFields(*CASES[name], 0.5, 1.4, 0.01)
    x = np.random.default_rng(3).uniform(0, 1, 20_000)
    for t in (0.2, 0.013):
        got, want = fields.reference(x, t), fields._averaged_numpy(x, t)
        for g, w in zip(got, want, strict=False):
            assert np.array_equal(g, w)
        assert np.array_equal(fields.velocity_gradient(x, t), want[1])
    assert np.abs(want[1]).max() > 1.0  # a shock or a fan inside the sample


def test_numpy_pow_of_an_array_does_not_depend_on_its_place_in_memory():
    """:func:`mpm_fem.exact_stages.kernels.sample` hands numpy the fan's ``c`` in an array the compiled pass
    allocated (the numpy reference: ``c[fan]``, the same values in the same order): the powers must
    not depend on the array's alignment (numpy's vectorised ``pow``, unlike the C library's, is used
    by both)."""
    c = np.random.default_rng(3).uniform(0.3, 1.0, 4099)
    want = c ** (2.0 / 0.4)
    for offset in range(9):
        buffer = np.empty(c.size + 9)
        buffer[offset:offset + c.size] = c
        assert np.array_equal(buffer[offset:offset + c.size] ** (2.0 / 0.4), want)
