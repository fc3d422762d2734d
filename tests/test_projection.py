"""Nodal projection errors of the slides (claims C5-C10) on small sweeps."""

import numpy as np
import pytest
from skfem import Basis, ElementLineP1, LinearForm, asm

from mpm_fem.core.grid import grid_from_nodes, uniform_grid
from mpm_fem.core.particles import seed_positions
from mpm_fem.measure.errors import fitted_order
from mpm_fem.measure.projection import (
    Advection,
    Fields,
    cell_weights,
    exact_nodal,
    layout,
    particle_nodal,
    projection_errors,
    smooth_fields,
)

FIELDS = smooth_fields()
HS = [1 / 10, 1 / 20, 1 / 40, 1 / 80, 1 / 160]


def sweep(layout_name, n, quantities, norm="L1", seeds=(0,), weights="cell", hs=HS):
    """Mean (over seeds) of ``norm`` of each quantity, for every h."""
    out = {q: [] for q in quantities}
    for h in hs:
        grid = uniform_grid(0, 1, h)
        values = {q: [] for q in quantities}
        for seed in seeds:
            x, V = layout(grid, layout_name, n, seed, rho=FIELDS.rho)
            w = cell_weights(grid, x) if weights == "cell" else V
            norms = projection_errors(grid, x, w, FIELDS).norms()
            for q in quantities:
                values[q].append(norms[q][norm])
        for q in quantities:
            out[q].append(np.mean(values[q]))
    return out


def test_exact_nodal_integrals_match_scikit_fem_assembly():
    grid = grid_from_nodes([0.0, 0.04, 0.1, 0.25, 0.3, 0.5, 0.71, 0.9, 1.0])
    basis = Basis(grid.mesh, ElementLineP1(), intorder=30)
    f = FIELDS
    m = asm(LinearForm(lambda v, w: f.rho(w.x[0]) * v), basis)
    P = asm(LinearForm(lambda v, w: f.rho(w.x[0]) * f.v(w.x[0]) * v), basis)
    F = asm(LinearForm(lambda v, w: f.p(w.x[0]) * v.grad[0]), basis)
    ours = exact_nodal(grid, f)
    for name, ref in (("m", m), ("P", P), ("F", F)):
        err = np.abs(getattr(ours, name) - ref).max()
        assert err < 1e-14, f"{name}_i differs from scikit-fem's assembly by {err:.2e}"


def test_cell_weights_are_h_over_particles_in_the_cell():
    grid = uniform_grid(0, 1, 0.25)
    x = np.array([0.9, 0.1, 0.95, 0.3, 0.2, 0.99])
    w = cell_weights(grid, x)
    np.testing.assert_allclose(w, [0.25 / 3, 0.25 / 2, 0.25 / 3, 0.25, 0.25 / 2, 0.25 / 3])


def _poly_fields(rho, v, p):
    zero = lambda x: 0.0 * x  # noqa: E731
    return Fields(rho=rho, drho=zero, v=v, dv=zero, p=p, dp=zero)


@pytest.mark.parametrize("n", [1, 2, 5, 16])
def test_errors_vanish_where_fields_are_exactly_represented_by_regular_layouts(n):
    """Regular midpoints: constant density (E_m), linear momentum (E_P, interior nodes: the midpoint
    errors of the two halves of the hat cancel), linear pressure (E_F: cell means are exact)."""
    grid = uniform_grid(0, 1, 0.05)
    x, V = seed_positions(grid, n, "regular")
    fields = _poly_fields(lambda x: 1.3 + 0 * x, lambda x: 0.4 - 2.0 * x, lambda x: 1.0 + 3.0 * x)
    e = projection_errors(grid, x, V, fields)
    worst = {q: np.abs(getattr(e, q)).max() for q in ("E_m", "E_P", "E_F")}
    assert max(worst.values()) < 1e-14, f"errors that should vanish: {worst}"


def test_constant_velocity_is_projected_exactly_by_any_layout():
    grid = uniform_grid(0, 1, 0.05)
    x, V = seed_positions(grid, 3, "random", seed=11)
    fields = Fields(FIELDS.rho, FIELDS.drho, lambda x: 0.7 + 0 * x, lambda x: 0 * x, FIELDS.p, FIELDS.dp)
    e = projection_errors(grid, x, V, fields)
    assert np.abs(e.E_v).max() < 1e-14 and np.abs(e.E_VG).max() < 1e-12, "constant velocity not exact"
    assert np.abs(e.E_m).max() > 1e-4  # while the mass projection itself is not exact


def test_mass_projection_error_is_first_order_for_random_layout():
    """C5: 1 <= p <= 2. The error of a random layout scales like h exactly (one cell's error is
    h times a random variable whose law does not depend on h); 0.1 is left for sampling noise."""
    e = sweep("random", 4, ["E_m", "E_P", "E_F"], seeds=range(4))
    orders = {q: fitted_order(HS, e[q]) for q in e}
    for q, p in orders.items():
        assert 0.9 <= p <= 2.0, f"{q} order {p:.3f} outside the source's band [1, 2] (orders {orders})"


@pytest.mark.parametrize("layout_name, seeds", [("random", range(4)), ("jittered", range(4)), ("regular", (0,))])
def test_acceleration_error_order_is_one_below_force_error_order(layout_name, seeds):
    """C8: E_a = E_F/m_i - a_i E_m/m_i with m_i = O(h): one order below E_F."""
    e = sweep(layout_name, 4, ["E_F", "E_a"], seeds=seeds)
    p_F, p_a = fitted_order(HS, e["E_F"]), fitted_order(HS, e["E_a"])
    assert 0.8 <= p_F - p_a <= 1.2, f"{layout_name}: force order {p_F:.3f}, acceleration order {p_a:.3f}"


def test_predicted_acceleration_error_matches_measured():
    """The slides' first-order prediction; with the projected mass in place of m_i it is an identity."""
    grid = uniform_grid(0, 1, 1 / 80)
    x, V = seed_positions(grid, 4, "jittered", seed=3)
    e = projection_errors(grid, x, V, FIELDS)
    rel = np.abs(e.E_a_pred - e.E_a).max() / np.abs(e.E_a).max()
    assert rel < 0.1, f"first-order prediction off by {rel:.3f} of the largest error"
    ex, mpm = exact_nodal(grid, FIELDS), particle_nodal(grid, x, V, FIELDS)
    a = ex.F / ex.m
    identity = ((ex.F - mpm.F) / mpm.m - a * (ex.m - mpm.m) / mpm.m)[1:-1]
    assert np.abs(identity - e.E_a).max() < 1e-12 * np.abs(a).max()


def test_regular_midpoints_beat_the_claimed_band():
    """Regular midpoints: interior nodal mass error O(h^3) (midpoint rule exact for linears, the two
    halves of the hat cancel at leading order) and velocity O(h^2): better than the source claims."""
    e = sweep("regular", 4, ["E_m", "E_v"])
    p_m, p_v = fitted_order(HS, e["E_m"]), fitted_order(HS, e["E_v"])
    assert 2.8 <= p_m <= 3.2 and 1.8 <= p_v <= 2.2, f"regular: E_m order {p_m:.3f}, E_v order {p_v:.3f}"


def test_velocity_gradient_projection_error_is_one_order_below_velocity_for_random_layouts():
    """C10 fails for random layouts: E_v^i is O(h) but uncorrelated between nodes, so
    (E_v^{i+1} - E_v^i)/h is O(1); the slides' argument needs E_v^i smooth in i."""
    e = sweep("random", 4, ["E_v", "E_VG_proj"], seeds=range(4))
    p_v, p_vg = fitted_order(HS, e["E_v"]), fitted_order(HS, e["E_VG_proj"])
    assert 0.8 <= p_v <= 1.2 and -0.2 <= p_vg <= 0.2, f"E_v order {p_v:.3f}, E_VG order {p_vg:.3f}"


def test_volume_weighted_force_of_an_advected_layout_does_not_converge():
    """With the volumes a run carries, a particle whose volume straddles a node puts its whole
    p_p V_p into one cell: E_F = O(V_p p / h) = O(1/N_p), and E_a = O(1/h)."""
    e = sweep("advected", 4, ["E_F", "E_a"], weights="volume")
    p_F, p_a = fitted_order(HS, e["E_F"]), fitted_order(HS, e["E_a"])
    assert -0.3 <= p_F <= 0.3 and -1.3 <= p_a <= -0.7, f"E_F order {p_F:.3f}, E_a order {p_a:.3f}"


def test_advected_layout_follows_the_exact_flow():
    adv = Advection()
    errs = []
    for h in (1 / 20, 1 / 80):
        grid = uniform_grid(0, 1, h)
        x, V = adv.run(grid, 2, FIELDS.rho)
        x0, _ = seed_positions(grid, 2, "regular")
        errs.append(np.abs(x - adv.flow(x0)).max())
        assert abs(V.sum() - 1) < 0.05, f"total volume {V.sum():.4f}"
    assert errs[1] < errs[0] / 2 and errs[1] < 5e-3, f"distance to the exact flow {errs}"


def test_e_v1_is_second_order_inside_and_first_order_at_the_end_nodes():
    """``v(x_i) - int S_i rho v / int S_i rho``: the whole hat is symmetric about x_i, the cut one is not."""
    inner, end = [], []
    for h in (1 / 20, 1 / 40, 1 / 80):
        grid = uniform_grid(0, 1, h)
        ex = exact_nodal(grid, FIELDS)
        e = np.abs(FIELDS.v(grid.nodes) - ex.P / ex.m)
        inner.append(e[1:-1].max())
        end.append(e[0])
    p_inner, p_end = fitted_order([1 / 20, 1 / 40, 1 / 80], inner), fitted_order([1 / 20, 1 / 40, 1 / 80], end)
    assert 1.8 <= p_inner <= 2.2 and 0.9 <= p_end <= 1.1, f"E_v1 order inside {p_inner:.3f}, at x=0 {p_end:.3f}"


def test_study_case_and_tables_on_a_tiny_sweep():
    from studies.projection import case, tables

    cs = [{"layout": lay, "ppc": 2, "cells": k, "seed": 0} for lay in ("random", "advected") for k in (10, 20, 40)]
    t = tables([(c, case(c)) for c in cs])
    orders = {(r["quantity"], r["layout"], r["weights"], r["basis"], r["norm"]): r for r in t["orders"]}
    assert orders[("E_m", "random", "cell", "mpm", "L1")]["band"] == "[1, 2]"
    assert (("E_F", "advected", "volume", "mpm", "L1") in orders
            and ("E_F", "random", "volume", "mpm", "L1") not in orders)
    assert all(r["holds"] == "yes" for r in t["bounds"]), [r for r in t["bounds"] if r["holds"] != "yes"]


@pytest.mark.parametrize("quick", [True, False])
def test_the_regular_layout_has_rows_of_its_own_in_every_tier(quick):
    """C5-C10: the regular layout the simulations use (``seed_positions``, sub-cell midpoints) is a
    layout of the projection study in every tier, beside the jittered, random and advected ones."""
    from mpm_fem.app.study import StudyOptions
    from studies.projection import cases

    layouts = {c["layout"] for c in cases(StudyOptions(quick=quick))}
    assert layouts == {"regular", "jittered", "random", "advected"}
    assert {c["seed"] for c in cases(StudyOptions(quick=quick)) if c["layout"] == "regular"} == {0}


def test_the_regular_layout_orders_row_is_measured():
    """The regular layout's own rows of ``orders``: on smooth periodic fields its sub-cell midpoints are a midpoint
    rule, the mass projection error third order (2.99 in the record), the velocity gradient's first order
    (0.99), far from the jittered layouts' orders."""
    from studies.projection import case, tables

    cs = [{"layout": lay, "ppc": 4, "cells": k, "seed": 0} for lay in ("regular", "jittered") for k in (10, 20, 40, 80)]
    t = tables([(c, case(c)) for c in cs])
    orders = {(r["quantity"], r["layout"]): r["order"] for r in t["orders"]
              if (r["weights"], r["basis"], r["norm"]) == ("cell", "mpm", "L1")}
    assert 2.6 <= orders[("E_m", "regular")] <= 3.2, orders[("E_m", "regular")]
    assert 0.9 <= orders[("E_VG", "regular")] <= 1.1, orders[("E_VG", "regular")]
    assert orders[("E_m", "jittered")] < orders[("E_m", "regular")] - 0.5
