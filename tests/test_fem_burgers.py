"""Fixed-mesh Galerkin FEM for viscous Burgers (baselines/fem_burgers.py): convergence against
the exact viscous rarefaction, boundary data, the kernel against scikit-fem, the compiled loop
(baselines/fem_burgers_kernel.py) against the numpy step, and bad input."""

from functools import lru_cache

import numpy as np
import pytest
import scipy.sparse as sp
from skfem import Basis, ElementLineP1, LinearForm, asm

from baselines.exact.burgers import make_solution
from baselines.fem_burgers import _operators, errors, residual, solve
from baselines.fem_burgers_kernel import tridiagonal_factors
from mpm_fem.core.grid import grid_from_nodes

EPS = 0.045
HS = (0.02, 0.01, 0.005)


@lru_cache(maxsize=None)
def _run(h, mass):
    solution = make_solution("rarefaction", EPS)
    return solution, solve(solution, h, T=0.5, mass=mass)


def _l2_orders(mass):
    e = []
    for h in HS:
        solution, result = _run(h, mass)
        e.append(errors(result, solution)["L2"])
    return e, [np.log2(e[k] / e[k + 1]) for k in range(len(e) - 1)]


def test_consistent_mass_p1_converges_at_second_order_in_l2():
    e, orders = _l2_orders("consistent")
    assert all(1.8 <= q <= 2.2 for q in orders), f"L2 errors {e}, observed orders {orders}"


def test_lumped_mass_p1_converges_at_least_at_first_order_in_l2():
    # On a uniform mesh lumped P1 is the central difference scheme, second order too (measured 2.0).
    e, orders = _l2_orders("lumped")
    assert all(q >= 1.0 for q in orders), f"L2 errors {e}, observed orders {orders}"


@pytest.mark.parametrize("mass", ["consistent", "lumped"])
def test_dirichlet_values_are_exact_at_both_ends(mass):
    solution, result = _run(0.02, mass)
    lo, hi = solution.domain
    assert result.nodes[0] == lo and result.nodes[-1] == hi
    assert result.t == pytest.approx(0.5, rel=1e-14)
    exact = solution.v(np.array([lo, hi]), result.t)
    assert np.allclose(result.v[[0, -1]], exact, rtol=1e-15, atol=0), (result.v[[0, -1]], exact)


def test_time_step_follows_the_stated_rule():
    solution, result = _run(0.01, "consistent")
    v0 = np.abs(solution.v(result.nodes, 0.0)).max()
    limit = min(0.5 * 0.01 / v0, 0.3 * 0.01**2 / (2 * EPS))
    assert result.dt <= limit * (1 + 1e-12) and result.steps == int(np.ceil(0.5 / limit - 1e-9))
    assert result.steps * result.dt == pytest.approx(0.5, rel=1e-14)


def test_errors_use_lumped_mass_weights():
    solution, result = _run(0.02, "consistent")
    e = result.v - solution.v(result.nodes, result.t)
    w = np.full(result.nodes.size, 0.02)
    w[[0, -1]] = 0.01
    measured = errors(result, solution)
    assert measured["L1"] == pytest.approx(np.sum(w * np.abs(e)), rel=1e-12)
    assert measured["L2"] == pytest.approx(np.sqrt(np.sum(w * e**2)), rel=1e-12)
    assert measured["max"] == pytest.approx(np.abs(e).max(), rel=1e-12)


def test_residual_kernel_matches_scikit_fem_linear_form():
    """The bincount kernel equals the exactly integrated weak form assembled by scikit-fem."""
    rng = np.random.default_rng(3)
    grid = grid_from_nodes(np.sort(np.r_[0.0, rng.uniform(0, 2, 40), 2.0]))
    v = rng.normal(size=grid.n_nodes)
    eps = 0.03
    R = residual(v, _operators(grid, "consistent"), eps)

    @LinearForm
    def weak(phi, w):
        return -w["v"] * w["v"].grad[0] * phi - eps * w["v"].grad[0] * phi.grad[0]

    basis = Basis(grid.mesh, ElementLineP1(), intorder=4)  # the integrand is cubic on a cell
    ref = asm(weak, basis, v=basis.interpolate(v))
    assert np.allclose(R, ref, rtol=1e-12, atol=1e-13), np.abs(R - ref).max()


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(h=0.03), "does not divide"),
        (dict(h=0.0), "positive"),
        (dict(h=0.01, cfl=0.0), "cfl"),
        (dict(h=0.01, cfl=2.0), "cfl"),
        (dict(h=0.01, cfl_visc=1.5), "cfl_visc"),
        (dict(h=0.01, mass="row-sum"), "unknown mass"),
        (dict(h=0.01, T=0.0), "T"),
    ],
)
def test_bad_input_raises_value_error(kwargs, message):
    with pytest.raises(ValueError, match=message):
        solve(make_solution("rarefaction", EPS), **kwargs)


@pytest.mark.parametrize("solution_name", ["rarefaction", "cole_hopf"])
def test_compiled_loop_equals_the_numpy_step(solution_name):
    """6,000 SSP-RK3 steps at h = 0.005: the lumped mass bit for bit (the same operations in the same
    order), the consistent mass to round-off (a Thomas solve where numpy uses SuperLU)."""
    solution = make_solution(solution_name, EPS)
    for mass, tol in (("lumped", 0.0), ("consistent", 1e-13)):
        a = solve(solution, 0.005, mass=mass, kernel="numpy")
        b = solve(solution, 0.005, mass=mass, kernel="fused")
        assert a.steps == b.steps == 6000 and a.dt == b.dt
        scale = np.abs(a.v).max()
        assert np.abs(a.v - b.v).max() <= tol * scale, (mass, np.abs(a.v - b.v).max() / scale)
        if mass == "lumped":
            assert np.array_equal(a.v, b.v)


def test_tridiagonal_factors_reproduce_the_interior_mass():
    ops = _operators(grid_from_nodes(np.linspace(0.0, 2.0, 41)), "consistent")
    l, w, u = tridiagonal_factors(ops.M_II)
    n = w.size
    lower = sp.diags([np.ones(n), l[1:]], [0, -1])
    upper = sp.diags([1.0 / w, u[:-1]], [0, 1])
    assert abs(lower @ upper - ops.M_II).max() <= 1e-15 * abs(ops.M_II).max()
    full = ops.M_II.toarray()
    full[0, 2] = 0.1
    with pytest.raises(ValueError, match="tridiagonal"):
        tridiagonal_factors(sp.csr_matrix(full))


class _BlowsUp:
    """The rarefaction, but its right boundary value is NaN from t = 0.1 on."""

    def __init__(self):
        self._s = make_solution("rarefaction", EPS)
        self.eps, self.domain = self._s.eps, self._s.domain

    def v(self, x, t):
        out = np.array(self._s.v(x, t), dtype=float)
        return np.where((np.asarray(t) >= 0.1) & (np.asarray(x) >= self.domain[1]), np.nan, out)

    def v_t(self, x, t):
        return self._s.v_t(x, t)


def test_non_finite_values_raise_arithmetic_error_naming_the_step():
    """Both loops stop at the same step and node, the first step after the data turned NaN."""
    dt = solve(make_solution("rarefaction", EPS), 0.02, mass="lumped").dt
    messages = []
    for kernel in ("numpy", "fused"):
        with pytest.raises(ArithmeticError, match=r"non-finite at step \d+, node \d+") as err:
            solve(_BlowsUp(), 0.02, mass="lumped", kernel=kernel)
        messages.append(str(err.value))
    assert messages[0] == messages[1]
    step = int(messages[0].split("step ")[1].split(",")[0])
    assert 0.1 <= step * dt <= 0.1 + 2 * dt, (step, dt)


def test_unknown_kernel_raises_value_error():
    with pytest.raises(ValueError, match="unknown kernel"):
        solve(make_solution("rarefaction", EPS), 0.02, kernel="cuda")
