"""The 2D projection errors (mpm_fem.plane.projection), the 2D discrepancy and Hickernell's bound
(mpm_fem.plane.discrepancy) on small sweeps, and the claims D8, D9 on made-up tables."""

from __future__ import annotations

import numpy as np
import pytest
from claim_mutations import claim_named

from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.particles import seed_positions
from mpm_fem.measure import projection as one
from mpm_fem.measure.errors import fitted_order
from mpm_fem.measure.quadrature import discrepancy_d2 as discrepancy_1d
from mpm_fem.measure.schema import PLANE_PROJECTION_BOUNDS, PLANE_PROJECTION_ORDERS
from mpm_fem.plane.discrepancy import discrepancy_d2, l2_discrepancy, quadrature_checks, regular_d2
from mpm_fem.plane.projection import (
    PlaneFields,
    cell_weights,
    exact_sums,
    interior_nodes,
    layout,
    nodal_sums,
    projection_errors,
    separable,
    smooth_fields,
    unit_square,
)

FIELDS = smooth_fields()


def test_the_regular_layout_projects_a_constant_density_exactly():
    """Sub-cell midpoints integrate the bilinear hats exactly: m_i = h^2 at every interior node."""
    one_ = (lambda s: np.ones_like(s)), (lambda s: np.zeros_like(s))
    constant = PlaneFields(*(separable(*one_, *one_) for _ in range(6)))
    grid = unit_square(1 / 8)
    for n in (1, 2, 4):
        x, V, _ = layout(grid, "regular", n)
        m = nodal_sums(grid, x, cell_weights(grid, x), constant).m[interior_nodes(grid)]
        assert np.max(np.abs(m - grid.h[0] ** 2)) < 1e-15
        assert np.max(np.abs(exact_sums(grid, constant).m[interior_nodes(grid)] - grid.h[0] ** 2)) < 1e-15


def test_the_tensor_mass_and_momentum_of_a_separable_field_are_products_of_the_1d_ones():
    """rho = r(x) r(y), rho v_x = [r sin](x) [r cos](y): on the regular layout the 2D sums are the products of
    the 1D projection module's sums, to round-off, and so are the exact integrals (to the quadrature's)."""
    h, n = 1 / 8, 2
    grid, line = unit_square(h), uniform_grid(0, 1, h)
    k, r = 2 * np.pi, (lambda s: 1 + 0.5 * np.sin(2 * np.pi * s))
    zero = lambda s: 0 * s  # noqa: E731
    fx = one.Fields(rho=r, drho=zero, v=lambda s: np.sin(k * s), dv=zero, p=r, dp=zero)
    fy = one.Fields(rho=r, drho=zero, v=lambda s: np.cos(k * s), dv=zero, p=r, dp=zero)
    s, w = seed_positions(line, n, "regular")
    mx, my = one.particle_nodal(line, s, w, fx), one.particle_nodal(line, s, w, fy)
    x, V, _ = layout(grid, "regular", n)
    got = nodal_sums(grid, x, V, FIELDS)
    assert np.max(np.abs(got.m - np.outer(mx.m, my.m).ravel())) < 1e-16
    assert np.max(np.abs(got.P[:, 0] - np.outer(mx.P, my.P).ravel())) < 1e-16
    ex, ex_x, ex_y = exact_sums(grid, FIELDS), one.exact_nodal(line, fx), one.exact_nodal(line, fy)
    assert np.max(np.abs(ex.m - np.outer(ex_x.m, ex_y.m).ravel())) < 1e-12  # Gauss order 6 on the half cells
    assert np.max(np.abs(ex.P[:, 0] - np.outer(ex_x.P, ex_y.P).ravel())) < 1e-11


def _orders(name: str, ppc: int, hs, seeds=(1,)) -> dict:
    values = {}
    for h in hs:
        grid = unit_square(h)
        ex = exact_sums(grid, FIELDS)
        norms = [projection_errors(grid, x, cell_weights(grid, x), FIELDS, exact=ex).norms()
                 for x, _, _ in (layout(grid, name, ppc, s) for s in seeds)]
        for q in norms[0]:
            values.setdefault(q, []).append(np.mean([nm[q]["L1"] for nm in norms]))
    return {q: fitted_order(hs, v) for q, v in values.items()}


def test_the_measured_orders_on_a_small_run():
    """Per node the 2D errors carry the nodal measure h^2 (one order above 1D's h). Regular midpoints: the mass
    converges at order 4 per node, 3 in the 1D units (the 1D regular layout's 3, above the band); jittered
    points: the mass at 2 per node (1 in the 1D units, inside the band), but the force at 1 per node (0 in
    the 1D units: d_x S_i varies across the cell in y, and an irregular equal-weight rule does not integrate a
    constant stress against it exactly) and the acceleration, force over a mass of size h^2, at -1."""
    hs = [1 / 8, 1 / 16, 1 / 32]
    regular = _orders("regular", 2, hs)
    assert 3.6 <= regular["E_m"] <= 4.2 and 1.3 <= regular["E_a"] <= 2.0
    jittered = _orders("jittered", 2, hs, seeds=(1, 2))
    assert 1.6 <= jittered["E_m"] <= 2.2
    assert 0.7 <= jittered["E_F"] <= 1.2
    assert -1.3 <= jittered["E_a"] <= -0.8
    assert 0.6 <= jittered["E_v"] <= 1.1


def test_the_discrepancy_of_a_regular_pattern_is_its_closed_form_and_sums_its_projections():
    grid = unit_square(1 / 4)
    for n in (1, 2, 3, 4):
        x, _, _ = layout(grid, "regular", n)
        assert np.allclose(discrepancy_d2(grid, x), regular_d2(n), rtol=1e-12, atol=0)
        # each axis' projection is the 1D regular pattern: D*_x = 1/(sqrt(12) n)
        assert np.allclose(discrepancy_d2(grid, x, 1.0, (0,)), 1 / (np.sqrt(12) * n), rtol=1e-12)
    assert regular_d2(1) == pytest.approx(np.sqrt(2 / 12 + 1 / 9 - 2 * (3 / 8) ** 2 + 1 / 4), rel=1e-14)
    x, _, _ = layout(grid, "random", 3, seed=4)
    d = {u: discrepancy_d2(grid, x, 1.0, u) for u in ((0,), (1,), (0, 1))}
    assert np.allclose(discrepancy_d2(grid, x) ** 2, sum(v**2 for v in d.values()), rtol=1e-10)


def test_in_1d_the_discrepancy_is_the_1d_studys():
    line = uniform_grid(0, 1, 1 / 5)
    s, _ = seed_positions(line, 6, "random", seed=2)
    local = (s - np.floor(s * 5) / 5) * 5
    order = np.argsort(np.floor(s * 5), kind="stable")
    mine = l2_discrepancy(local[order].reshape(5, 6, 1), c=2.0)
    assert np.allclose(mine, discrepancy_1d(line, s), rtol=1e-12)


@pytest.mark.parametrize("name", ["jittered", "random", "advected"])
def test_hickernells_bound_holds_on_every_cell_and_node(name):
    grid = unit_square(1 / 16)
    x, _, _ = layout(grid, name, 2, seed=3)
    for check in quadrature_checks(grid, x, FIELDS).values():
        assert check.entries > 0 and 1.0 <= check.min_ratio < 20


# ----------------------------------------------------------------------------- the claims on made-up tables

def _orders_table(order=lambda q, lay, n: 1.0 if q in ("E_m", "E_P", "E_F") else 0.5) -> list[dict]:
    return [{"quantity": q, "layout": lay, "weights": "cell", "basis": "mpm", "ppc": n, "norm": "L1",
             "order": str(order(q, lay, n)), "order_per_node": "", "order_coarse": "", "order_fine": "",
             "successive": "", "band": "", "inside": ""}
            for q in ("E_m", "E_P", "E_F", "E_a", "E_v") for lay in ("regular", "jittered", "random", "advected")
            for n in (2, 4)]


def test_d8_counts_the_orders_inside_the_bands():
    good = {PLANE_PROJECTION_ORDERS.name: _orders_table()}
    found = claim_named("D8").finding(good)
    assert found.verdict == "confirmed" and found.evidence.startswith("holds on 40 of 40")
    bad = {PLANE_PROJECTION_ORDERS.name: _orders_table(
        lambda q, lay, n: 0.0 if (q, lay) == ("E_F", "random") else 1.0 if q in ("E_m", "E_P", "E_F") else 0.5)}
    found = claim_named("D8").finding(bad)
    assert found.verdict == "partly" and found.evidence.startswith("holds on 38 of 40")
    assert "force on random 0.00" in found.sentence
    none = {PLANE_PROJECTION_ORDERS.name: _orders_table(lambda q, lay, n: 3.0)}
    assert claim_named("D8").finding(none).verdict == "refuted"


def test_d8s_verdict_counts_the_orders_its_verdict_is_judged_on():
    """The verdict cell counts the orders (38 of 40), not the quantity-layout rows that hold on every count."""
    from mpm_fem.app.paper_findings import verdict_text

    bad = {PLANE_PROJECTION_ORDERS.name: _orders_table(
        lambda q, lay, n: 0.0 if (q, lay, n) == ("E_F", "random", 2) else 1.0 if q in ("E_m", "E_P", "E_F") else 0.5)}
    assert verdict_text(claim_named("D8").finding(bad)).startswith("holds on 39 of 40 orders")


def test_d9_needs_the_bound_on_every_entry():
    rows = [{"check": c, "layout": lay, "ppc": "2", "h": "0.0625", "min_ratio": "1.2", "entries": "100",
             "holds": "yes"} for c in ("cell_rho", "node_m", "node_F") for lay in ("jittered", "random")]
    found = claim_named("D9").finding({PLANE_PROJECTION_BOUNDS.name: rows})
    assert found.verdict == "confirmed" and "6 of 6 rows" in found.evidence
    rows[3] = {**rows[3], "min_ratio": "0.9", "holds": "no"}
    found = claim_named("D9").finding({PLANE_PROJECTION_BOUNDS.name: rows})
    assert found.verdict == "refuted" and "fails on node_m random 2x2" in found.evidence
