"""The exact form of the projection stage: the nodal sums of the exact fields.

    m_i = int rho S_i dx,      P_i = int rho v S_i dx,      F_i = - int sigma S_i' dx,      each (n_nodes,),

by the quadrature of :mod:`mpm_fem.exact_stages.quadrature` (exact to round-off for
piecewise-polynomial fields). Its points act as particles of mass ``w_q rho_q`` and volume ``w_q``:

    m_i = sum_q (w_q rho_q) S_qi,   P_i = sum_q ((w_q rho_q) v_q) S_qi,   F_i = - sum_q (w_q sigma_q) G_qi,

summed in the order of the points, so that the compiled :func:`nodal_sums` equals
:func:`nodal_sums_numpy` (the particle sums of :mod:`mpm_fem.core.transfer`) bit for bit.
:func:`exact_projection` hands the sums to the grid as
:class:`~mpm_fem.exact_stages.grid_data.GridData`, with the FE mass of
:mod:`mpm_fem.exact_stages.mass` in place of the points' mass matrix when asked.
"""

from __future__ import annotations

import numpy as np

import mpm_fem.exact_stages.grid_kernels as grid_kernels
from mpm_fem.core.grid import Grid
from mpm_fem.core.shape import Shape, grid_functions
from mpm_fem.core.transfer import nodal_internal_force, nodal_mass, nodal_momentum
from mpm_fem.exact_stages.fields import ExactFields
from mpm_fem.exact_stages.grid_data import GridData
from mpm_fem.exact_stages.mass import fe_mass
from mpm_fem.exact_stages.quadrature import quadrature_rule


def exact_projection(grid: Grid, basis: str, fields: ExactFields, t: float, with_fe_mass: bool = False) -> GridData:
    """``m_i = int rho S_i``, ``P_i = int rho v S_i``, ``F_i = -int sigma S_i'`` of the exact fields.

    The grid functions are the P1 hats for the point-mass and GIMP bases (GIMP averages the same
    hats over the particle domain) and the quadratic B-splines for ``"bspline"`` and ``"bspline_gimp"``.
    The quadrature points act as particles of mass ``w_q rho_q`` and volume ``w_q``, so ``m_i`` and the consistent
    mass ``int rho S_i S_j`` come from the same code as the particle mass matrix. ``with_fe_mass``
    (the exact form of the mass stage): the mass matrices are instead the FE mass of
    :func:`~mpm_fem.exact_stages.mass.fe_mass` (on scikit-fem's basis), ``m_i`` its row sums (the same integrals).
    """
    rule = quadrature_rule(grid, grid_functions(basis))
    cuts = rule.cuts(fields.breakpoints(t))
    x, w, shape = rule.splice(cuts)
    rho, v, sigma = fields.integrand(x, t)
    M, m_fe = fe_mass(grid, basis, fields, t, cuts=cuts, assembled=False) if with_fe_mass else (None, None)
    m_i, P_i, F_i = nodal_sums(shape, w, rho, v, sigma, with_mass=not with_fe_mass)
    return GridData(shape, w * rho, m_i if m_fe is None else m_fe, P_i, F_i, M)


def nodal_sums(shape: Shape, w: np.ndarray, rho: np.ndarray, v: np.ndarray, sigma: np.ndarray,
               with_mass: bool = True) -> tuple[np.ndarray | None, np.ndarray, np.ndarray]:
    """``m_i`` (``None`` unless ``with_mass``), ``P_i``, ``F_i`` of quadrature points of weight ``w``:
    the compiled :func:`~mpm_fem.exact_stages.grid_kernels.project`, equal bit for bit to :func:`nodal_sums_numpy`."""
    m_i, P_i, F_i = grid_kernels.project(shape.nodes, shape.S, shape.G, w, rho, v, sigma, shape.n_nodes, with_mass)
    return (m_i if with_mass else None), P_i, F_i


def nodal_sums_numpy(shape: Shape, w: np.ndarray, rho: np.ndarray, v: np.ndarray, sigma: np.ndarray,
                     with_mass: bool = True) -> tuple[np.ndarray | None, np.ndarray, np.ndarray]:
    """The readable reference of :func:`nodal_sums` (:mod:`mpm_fem.core.transfer`): the points as
    particles of mass ``w rho`` and volume ``w``."""
    mass = w * rho
    return (nodal_mass(shape, mass) if with_mass else None), nodal_momentum(shape, mass, v), \
        nodal_internal_force(shape, w, sigma)
