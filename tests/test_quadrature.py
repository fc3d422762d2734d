"""Hickernell's discrepancy D2 and quadrature bound (claim C4)."""

import numpy as np
import pytest

from mpm_fem.core.grid import grid_from_nodes, uniform_grid
from mpm_fem.core.particles import seed_positions
from mpm_fem.measure.projection import quadrature_checks, smooth_fields
from mpm_fem.measure.quadrature import (
    cell_mean_error,
    cell_points,
    derivative_l2,
    discrepancy_d2,
    discrepancy_d2_slides,
    estimate_c,
    expected_offset,
    hickernell_bound,
    hickernell_bound_max,
    integrate_cells,
    offset_term,
)

GRADED = grid_from_nodes([0.0, 0.03, 0.1, 0.18, 0.3, 0.45, 0.62, 0.8, 1.0])


@pytest.mark.parametrize("grid", [uniform_grid(0, 1, 0.1), uniform_grid(0, 1, 1 / 640), GRADED],
                         ids=["h=0.1", "h=1/640", "graded"])
@pytest.mark.parametrize("n", [1, 2, 3, 4, 8, 16, 32])
def test_d2_of_regular_midpoints_is_one_over_sqrt12_n(grid, n):
    x, _ = seed_positions(grid, n, "regular")
    d2 = discrepancy_d2(grid, x)
    err = np.abs(d2 * np.sqrt(12) * n - 1).max()
    assert err < 1e-13, f"D2 sqrt(12) N - 1 = {err:.2e} for N={n}"


def test_d2_is_the_l2_star_discrepancy_by_direct_integration():
    """(3) against ``(int_0^1 (A(t)/N - t)^2 dt)^{1/2}`` integrated exactly between the sorted points."""
    grid = grid_from_nodes([0.0, 1.0])
    for seed, n in [(0, 1), (1, 5), (2, 17)]:
        z = np.sort(np.random.default_rng(seed).random(n))
        knots = np.concatenate(([0.0], z, [1.0]))
        total = 0.0
        for k in range(n + 1):  # A(t) = k on [knots[k], knots[k+1]): int (k/N - t)^2 exactly
            a, b = knots[k], knots[k + 1]
            total += ((b - k / n) ** 3 - (a - k / n) ** 3) / 3
        d2 = discrepancy_d2(grid, z)[0]
        assert abs(d2 - np.sqrt(total)) < 1e-14, f"D2 = {d2!r}, direct integration {np.sqrt(total)!r}"


@pytest.mark.parametrize("layout", ["jittered", "random"])
@pytest.mark.parametrize("n", [1, 4, 16])
def test_mean_offset_term_of_seeded_layouts_matches_its_closed_form(layout, n):
    grid = uniform_grid(0, 1, 1 / 400)
    x, _ = seed_positions(grid, n, layout, seed=7)
    measured = offset_term(grid, x).mean()
    expected = expected_offset(layout, n)
    # 400 independent cells: the sample mean is within ~5 standard errors
    assert abs(measured / expected - 1) < 0.12, f"mean delta {measured:.5g}, closed form {expected:.5g}"


def test_d2_is_nan_in_empty_cells_and_counts_particles():
    grid = uniform_grid(0, 1, 0.25)
    x = np.array([0.1, 0.2, 0.3, 0.9, 0.95, 0.99])
    pts = cell_points(grid, x)
    assert pts.count.tolist() == [2, 1, 0, 3]
    d2 = discrepancy_d2(grid, x)
    assert np.isnan(d2[2]) and np.all(np.isfinite(d2[[0, 1, 3]]))


def test_slides_literal_d2_and_estimated_c():
    """In physical units the offset term is ``h^2 delta``: the fitted C equals delta for a fixed pattern."""
    pattern = np.array([0.05, 0.3, 0.4, 0.9])
    h_list, d_list = [], []
    for h in (0.5, 0.25, 0.1, 0.05):
        grid = uniform_grid(0, 1, h)
        x = (grid.nodes[:-1, None] + pattern * h).ravel()
        d = discrepancy_d2_slides(grid, x)
        h_list += [h] * d.size
        d_list += list(d)
    delta = offset_term(uniform_grid(0, 1, 0.5), (np.array([0.0, 0.5])[:, None] + pattern * 0.5).ravel())[0]
    c = estimate_c(h_list, np.full(len(h_list), 4), d_list)
    assert abs(c - delta) < 1e-12, f"C = {c!r}, delta = {delta!r}"


def test_gauss_cell_integrals_are_exact_for_smooth_fields():
    grid = GRADED
    got = integrate_cells(grid, lambda x, xi, h: np.sin(2 * np.pi * x))
    exact = (np.cos(2 * np.pi * grid.nodes[:-1]) - np.cos(2 * np.pi * grid.nodes[1:])) / (2 * np.pi)
    assert np.abs(got - exact).max() < 1e-15


@pytest.mark.parametrize("layout", ["random", "jittered"])
def test_hickernell_bound_holds_on_random_layouts(layout):
    """Bound (1) for the cell means of rho, and its two-cell forms for E_m and E_F, on every cell/node."""
    fields = smooth_fields()
    worst = {}
    for n in (1, 2, 4, 8):
        for seed in range(4):
            for h in (0.1, 1 / 80):
                grid = uniform_grid(0, 1, h)
                x, _ = seed_positions(grid, n, layout, seed=seed)
                for name, check in quadrature_checks(grid, x, fields).items():
                    worst[name] = min(worst.get(name, np.inf), check.min_ratio)
    assert min(worst.values()) >= 1.0, f"smallest bound/error ratios {worst}"
    # the bound is not vacuous: within two orders of magnitude of the worst cell
    assert worst["cell_rho"] < 100, f"smallest bound/error ratio for rho is {worst['cell_rho']:.3g}"


def test_hickernell_bound_holds_for_a_rough_function_and_its_max_form_is_weaker():
    """A field that oscillates within a cell, where the bound is nearly sharp."""
    grid = uniform_grid(0, 1, 0.1)
    f, df = (lambda x: np.sin(40 * np.pi * x)), (lambda x: 40 * np.pi * np.cos(40 * np.pi * x))
    ratios = []
    for seed in range(20):
        x, _ = seed_positions(grid, 3, "random", seed=seed)
        d2 = discrepancy_d2(grid, x)
        err = np.abs(cell_mean_error(grid, x, f))
        bound = hickernell_bound(d2, grid.h, derivative_l2(grid, df))
        bound_max = hickernell_bound_max(d2, grid.h, np.full(grid.n_cells, 40 * np.pi)) / grid.h
        assert np.all(bound_max >= bound)
        ratios.append((bound / err).min())
    assert min(ratios) >= 1.0, f"smallest bound/error ratio {min(ratios):.4g}"
