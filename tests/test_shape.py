"""The particle-grid kernel against scikit-fem's own basis evaluation, and its identities."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mpm_fem.bases import get, names
from mpm_fem.core.grid import GridError, grid_from_nodes, uniform_grid
from mpm_fem.core.shape import OutsideGridError, gimp_shape, locate, make_shape, point_shape

MESHES = {
    "uniform": np.linspace(0.0, 1.0, 11),
    "graded": np.array([0.0, 0.02, 0.05, 0.11, 0.2, 0.34, 0.5, 0.7, 0.85, 1.0]),
}


def scikit_fem_derivatives(grid, x):
    """``dS_i/dx`` at ``x`` from the element's ``gbasis`` and the mapping's ``invF`` (as probes does)."""
    basis = grid.basis
    cells = grid.mesh.element_finder(mapping=basis.mapping)(x)
    local = basis.mapping.invF(x[None, :, None], tind=cells)
    out = np.zeros((x.size, grid.n_nodes))
    for k in range(basis.Nbfun):
        dphi = basis.elem.gbasis(basis.mapping, local, k, tind=cells)[0].grad[0][:, 0]
        np.add.at(out, (np.arange(x.size), basis.element_dofs[k, cells]), dphi)
    return out


@pytest.mark.parametrize("mesh", MESHES)
def test_point_shape_values_and_derivatives_match_scikit_fem(mesh):
    grid = grid_from_nodes(MESHES[mesh])
    x = np.random.default_rng(1).uniform(0, 1, 500)
    x[:3] = [0.0, 1.0, grid.nodes[3]]  # ends and an interior node
    shape = point_shape(grid, x)
    probes = grid.basis.probes(x[None, :]).toarray()
    err_S = np.abs(shape.matrix().toarray() - probes).max()
    err_G = np.abs(shape.matrix(derivative=True).toarray() - scikit_fem_derivatives(grid, x)).max()
    assert err_S < 1e-14, f"S_ip differs from Basis.probes by {err_S:.2e}"
    assert err_G < 1e-12 * (1 / grid.h.min()), f"G_ip differs from gbasis by {err_G:.2e}"


@pytest.mark.parametrize("basis", names())
@pytest.mark.parametrize("mesh", MESHES)
def test_partition_of_unity_and_zero_gradient_sum(mesh, basis):
    if get(basis).uniform and mesh != "uniform":
        pytest.skip(f"the {basis} basis is defined on uniform grids")
    grid = grid_from_nodes(MESHES[mesh])
    rng = np.random.default_rng(2)
    x = rng.uniform(0, 1, 2000)
    volume = rng.uniform(0.1, 1.0, x.size) * grid.h.min()
    shape = make_shape(grid, x, volume, basis)
    assert np.abs(shape.S.sum(axis=1) - 1).max() < 1e-13
    assert np.abs(shape.G.sum(axis=1)).max() < 1e-10 / grid.h.min()
    assert shape.S.min() > -1e-15


@settings(max_examples=60, deadline=None, derandomize=True)
@given(xp=st.floats(0.0, 1.0), v=st.floats(1e-6, 0.05))
def test_gimp_equals_average_of_point_shape_over_particle_domain(xp, v):
    """S_ip = 1/V_p int S_i chi_p, checked by a fine midpoint rule of the point-mass kernel."""
    grid = uniform_grid(0.0, 1.0, 0.1)
    lo, hi = max(xp - v / 2, 0.0), min(xp + v / 2, 1.0)
    gimp = gimp_shape(grid, np.array([xp]), np.array([v])).matrix().toarray()[0]
    z = lo + (np.arange(4000) + 0.5) / 4000 * (hi - lo)
    average = point_shape(grid, z).matrix().toarray().mean(axis=0)
    assert np.abs(gimp - average).max() < 1e-6


def test_gimp_tends_to_point_mass_as_the_particle_shrinks():
    grid = grid_from_nodes(MESHES["graded"])
    x = np.random.default_rng(3).uniform(0.01, 0.99, 300)
    diff = gimp_shape(grid, x, np.full(x.size, 1e-9)).matrix().toarray() - point_shape(grid, x).matrix().toarray()
    assert np.abs(diff).max() < 1e-6


def test_gimp_gradient_is_difference_of_hat_values_at_domain_ends():
    grid = uniform_grid(0.0, 1.0, 0.25)
    # domain [0.2, 0.3] straddles node 0.25: S_1 goes 0.8 -> 1 -> 0.8 (mean slope 0), S_0 and S_2
    # each fall or rise by 0.2 over 0.1 on one side only
    shape = gimp_shape(grid, np.array([0.25]), np.array([0.1]))
    G = shape.matrix(derivative=True).toarray()[0]
    S = shape.matrix().toarray()[0]
    np.testing.assert_allclose(S, [0.05, 0.9, 0.05, 0.0, 0.0], atol=1e-14)
    np.testing.assert_allclose(G, [-2.0, 0.0, 2.0, 0.0, 0.0], atol=1e-12)


def test_points_outside_the_grid_are_named():
    grid = uniform_grid(0.0, 1.0, 0.1)
    with pytest.raises(OutsideGridError, match=r"particle 1 at x=1\.5"):
        locate(grid, np.array([0.5, 1.5]))
    with pytest.raises(OutsideGridError, match="nan"):
        locate(grid, np.array([np.nan]))


def test_bad_grids_are_refused():
    with pytest.raises(GridError, match="does not divide"):
        uniform_grid(0.0, 1.0, 0.3)
    with pytest.raises(GridError, match="positive"):
        uniform_grid(0.0, 1.0, -0.1)
    with pytest.raises(GridError, match="increasing"):
        grid_from_nodes([0.0, 0.5, 0.4])


def test_lumped_mass_is_row_sum_of_scikit_fem_consistent_mass():
    grid = grid_from_nodes(MESHES["graded"])
    h = grid.h
    expected = np.concatenate(([h[0] / 2], (h[:-1] + h[1:]) / 2, [h[-1] / 2]))
    np.testing.assert_allclose(grid.lumped_mass, expected, rtol=1e-13)
    assert abs(grid.consistent_mass.sum() - 1.0) < 1e-14


def test_bspline_basis_is_c1_across_nodes_and_p1_is_not():
    """Values and derivatives of S_ip are continuous as a particle crosses a node for the C1 basis."""
    grid = uniform_grid(0.0, 1.0, 0.1)
    node = 0.5
    x = np.array([node - 1e-9, node + 1e-9])
    b = make_shape(grid, x, basis="bspline")
    jump_S = np.abs(np.diff(b.matrix().toarray(), axis=0)).max()
    jump_G = np.abs(np.diff(b.matrix(derivative=True).toarray(), axis=0)).max()
    assert jump_S < 1e-7 and jump_G < 1e-6, (jump_S, jump_G)
    p1 = make_shape(grid, x, basis="mpm")
    assert np.abs(np.diff(p1.matrix(derivative=True).toarray(), axis=0)).max() > 9.0  # 1/h jumps


def test_bspline_reproduces_linear_fields_in_the_interior():
    """With the nodes as coefficients, where every nonzero function is a uniform spline (2.5 cells
    from a wall: the end functions' coefficients of ``x`` are the Greville abscissae, not the nodes)."""
    grid = uniform_grid(0.0, 1.0, 0.1)
    x = np.random.default_rng(8).uniform(0.25, 0.75, 300)
    b = make_shape(grid, x, basis="bspline")
    f = 3.0 * grid.nodes - 1.0
    np.testing.assert_allclose(b.gather(f), 3.0 * x - 1.0, atol=1e-13)
    np.testing.assert_allclose(b.gather_gradient(f), 3.0, atol=1e-12)


def test_bspline_refuses_non_uniform_grids():
    with pytest.raises(ValueError, match="uniform"):
        make_shape(grid_from_nodes(MESHES["graded"]), np.array([0.5]), basis="bspline")


@pytest.mark.parametrize("n_cells", [3, 10, 3200, 125000])
def test_fast_uniform_cell_search_agrees_with_bisection_on_nodes_and_neighbours(n_cells):
    grid = uniform_grid(0.0, 1.0, 1.0 / n_cells)
    nodes = grid.nodes
    x = np.concatenate((np.random.default_rng(9).random(20000), nodes,
                        np.nextafter(nodes[1:], -1.0), np.nextafter(nodes[:-1], 2.0)))
    cell, xi = locate(grid, x)
    expected = np.minimum(np.searchsorted(nodes, x, side="right") - 1, n_cells - 1)
    assert np.array_equal(cell, expected)
    assert xi.min() >= 0.0 and xi.max() <= 1.0


@pytest.mark.parametrize("basis", ["mpm", "bspline"])
def test_basis_integrals_sum_to_the_domain_length_and_match_the_ends(basis):
    from mpm_fem.core.shape import basis_integrals

    grid = uniform_grid(0.0, 1.0, 0.1)
    w = basis_integrals(grid, basis)
    assert abs(w.sum() - 1.0) < 1e-14
    expected = [0.05, 0.1] if basis == "mpm" else [0.1 / 2, 5 * 0.1 / 6]  # the open knot vector's end functions
    np.testing.assert_allclose([w[0], w[1]], expected, rtol=1e-13)
    np.testing.assert_allclose(w[3:-3], 0.1, rtol=1e-13)
