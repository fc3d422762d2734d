"""The 2D tensor bases (mpm_fem/plane/bases.py): partition of unity, gradients summing to zero, and
the tensor product of the 1D P1 rows equal to scikit-fem's ElementQuad1 at random points."""

from __future__ import annotations

import numpy as np
import pytest
from skfem import Basis as SkBasis
from skfem import ElementQuad1

from mpm_fem.bases import Point, names
from mpm_fem.core.grid import GridError
from mpm_fem.plane.bases import plane_shape, tensor_basis
from mpm_fem.plane.grid import plane_grid

GRIDS = {"periodic": ((0.0, 0.0), (2.0, 2.0), 0.25, (True, True)),
         "walls": ((-1.5, -1.5), (1.5, 1.5), 0.25, (False, False)),
         "mixed": ((0.0, -1.0), (2.0, 1.0), 0.25, (True, False))}


def _points(n, lower, upper, seed=0):
    rng = np.random.default_rng(seed)
    return np.asarray(lower) + rng.random((n, 2)) * (np.asarray(upper) - np.asarray(lower))


@pytest.mark.parametrize("grid_name", sorted(GRIDS))
@pytest.mark.parametrize("basis", names())
def test_tensor_rows_are_a_partition_of_unity_with_gradients_summing_to_zero(basis, grid_name):
    lower, upper, h, periodic = GRIDS[grid_name]
    grid = plane_grid(lower, upper, h, periodic)
    x = _points(400, lower, upper)
    lengths = np.tile([h / 2, h / 3], (x.shape[0], 1))  # 2 x 3 particles per cell
    shape = plane_shape(grid, basis, x, lengths)
    unity = np.abs(shape.S.sum(axis=1) - 1).max()
    gradient = np.abs(shape.G.sum(axis=1)).max() * h
    assert unity < 1e-13, f"{basis}: sum_i S_ip - 1 up to {unity:.3g}"
    assert gradient < 1e-13, f"{basis}: h |sum_i G_ip| up to {gradient:.3g}"


@pytest.mark.parametrize("basis", names())
def test_periodic_rows_are_translation_invariant_near_the_domain_ends(basis):
    """The rows of points in the first and last cells equal those of the same points moved by half the
    period (their nodes moved by half the nodes): no end function of the padded 1D line reaches them."""
    grid = plane_grid((0.0, 0.0), (2.0, 2.0), 0.25, (True, True))
    rng = np.random.default_rng(4)
    x = np.concatenate((rng.random((50, 2)) * 0.25, 2.0 - rng.random((50, 2)) * 0.25))
    lengths = np.full_like(x, 0.125)
    here, there = (plane_shape(grid, basis, y, lengths) for y in (x, x + 1.0))
    n = grid.shape[1]
    shifted = ((here.nodes // n + 4) % 8) * n + (here.nodes % n + 4) % 8
    order_here, order_there = np.argsort(shifted, axis=1), np.argsort(there.nodes, axis=1)
    same_nodes = np.array_equal(np.take_along_axis(shifted, order_here, 1),
                                np.take_along_axis(there.nodes, order_there, 1))
    gap = np.abs(np.take_along_axis(here.S, order_here, 1) - np.take_along_axis(there.S, order_there, 1)).max()
    assert same_nodes and gap < 1e-13, f"{basis}: rows near the ends differ from their translates by {gap:.3g}"


def _skfem_quad1(grid, x):
    """Values and gradients (n_p, n_nodes) of scikit-fem's ElementQuad1 at ``x`` (n_p, 2): the element
    holding each point, its reference coordinates by the mesh mapping, ``lbasis`` there, the
    gradients by the inverse Jacobian; mesh points folded onto the grid's nodes."""
    mesh = grid.mesh
    element = ElementQuad1()
    cells = mesh.element_finder()(x[:, 0], x[:, 1])
    mapping = mesh._mapping()
    local = mapping.invF(x.T[:, :, None], tind=cells)[:, :, 0]
    inv_jacobian = mapping.invDF(local[:, :, None], tind=cells)[:, :, :, 0]  # (2, 2, n_p)
    values = np.zeros((x.shape[0], grid.n_nodes))
    gx, gy = np.zeros_like(values), np.zeros_like(values)
    rows = np.arange(x.shape[0])
    for k in range(4):  # the four local functions of a quad
        phi, dphi = element.lbasis(local, k)
        node = grid.mesh_nodes[mesh.t[k, cells]]
        grad = np.einsum("jip,jp->ip", inv_jacobian, dphi)
        np.add.at(values, (rows, node), phi)
        np.add.at(gx, (rows, node), grad[0])
        np.add.at(gy, (rows, node), grad[1])
    return values, gx, gy


@pytest.mark.parametrize("grid_name", sorted(GRIDS))
def test_p1_tensor_rows_equal_skfem_quad1_at_random_points(grid_name):
    lower, upper, h, periodic = GRIDS[grid_name]
    grid = plane_grid(lower, upper, h, periodic)
    x = _points(300, lower, upper, seed=3)
    shape = plane_shape(grid, "mpm", x)
    ours = shape.matrix().toarray()
    n_p, k = shape.nodes.shape
    gx, gy = (np.zeros_like(ours) for _ in range(2))
    np.add.at(gx, (np.repeat(np.arange(n_p), k), shape.nodes.ravel()), shape.G[:, :, 0].ravel())
    np.add.at(gy, (np.repeat(np.arange(n_p), k), shape.nodes.ravel()), shape.G[:, :, 1].ravel())
    values, sx, sy = _skfem_quad1(grid, x)
    worst = max(np.abs(ours - values).max(), h * np.abs(gx - sx).max(), h * np.abs(gy - sy).max())
    assert worst < 1e-13, f"P1 tensor rows differ from scikit-fem's ElementQuad1 by {worst:.3g}"
    # the values again through scikit-fem's own probes (no mapping by hand)
    probes = SkBasis(grid.mesh, ElementQuad1()).probes(x.T).toarray()
    folded = np.zeros_like(ours)
    np.add.at(folded.T, grid.mesh_nodes, probes.T)
    assert np.abs(ours - folded).max() < 1e-13


@pytest.mark.parametrize("domain_basis", ["gimp", "bspline_gimp"])
def test_particle_domain_rows_average_the_grid_functions_over_the_particle_rectangle(domain_basis):
    """uGIMP per axis: ``S_ip`` is the mean of the point basis's ``S_i`` over ``l_x x l_y``, here by a
    composite Gauss rule (4 pieces of 8 points per axis) that the hats' kinks limit to about 1e-4 (the
    B-splines': 4e-7); the lengths swapped between the axes miss by 3e-2 (GIMP) and 8e-3."""
    grid = plane_grid((0.0, 0.0), (2.0, 2.0), 0.25, (True, True))
    x = _points(40, (0.0, 0.0), (2.0, 2.0), seed=5)
    lengths = np.tile([0.25 / 2, 0.25 / 3], (x.shape[0], 1))
    ours = plane_shape(grid, domain_basis, x, lengths).matrix().toarray()
    point = tensor_basis(domain_basis).grid_functions
    g, w = np.polynomial.legendre.leggauss(8)
    pieces = 4
    offsets = ((np.arange(pieces)[:, None] + (g[None, :] + 1) / 2) / pieces - 0.5).ravel()
    weights = np.tile(w / 2, pieces) / pieces
    mean = np.zeros_like(ours)
    for a, wa in zip(offsets, weights, strict=True):
        for b, wb in zip(offsets, weights, strict=True):
            y = x + np.column_stack((a * lengths[:, 0], b * lengths[:, 1]))
            mean += wa * wb * plane_shape(grid, point, y).matrix().toarray()
    worst = np.abs(ours - mean).max()
    bound = {"gimp": 1e-3, "bspline_gimp": 1e-5}[domain_basis]
    assert worst < bound, f"{domain_basis}: rows differ from the rectangle mean by {worst:.3g}"


def test_a_basis_without_a_tensor_form_is_refused_before_any_work():
    class Flat(Point):
        name = "flat"
        tensor = False

    with pytest.raises(ValueError, match="no 2D"):
        tensor_basis(Flat())
    assert all(tensor_basis(name).tensor for name in names())


def test_a_mesh_that_does_not_tile_the_domain_is_refused():
    with pytest.raises(GridError, match="does not divide"):
        plane_grid((0.0, 0.0), (2.0, 2.0), 0.3, (True, True))
