"""Fixed-mesh Galerkin FEM for viscous Burgers (baselines/fem_burgers.py): convergence against
the exact viscous rarefaction, boundary data, the kernel against scikit-fem, and bad input."""

from functools import lru_cache

import numpy as np
import pytest
from skfem import Basis, ElementLineP1, LinearForm, asm

from baselines.exact.burgers import make_solution
from baselines.fem_burgers import _operators, errors, residual, solve
from mpm_fem.grid import grid_from_nodes

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
