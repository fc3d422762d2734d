"""The grid basis at the particles: ``S_ip`` and its derivative ``G_ip``, for the basis a run names.

Slides, "MPM Basis Overview":

    point mass (standard MPM)   S_ip = S_i(x_p),                       G_ip = S_i'(x_p)
    particle domain (GIMP)      S_ip = 1/V_p int S_i(x) chi_p(x) dx,    G_ip = 1/V_p int S_i'(x) chi_p(x) dx

Each basis is a module of :mod:`mpm_fem.bases` behind its contract, read from the registry
(:func:`mpm_fem.bases.get`); the functions here are the numpy step's names for it: :func:`make_shape`
(the rows ``S_ip``, ``G_ip``, a :class:`Shape`), :func:`basis_integrals` (``int S_i dx``) and
:func:`grid_functions` (the point basis of the ``S_i`` behind a basis).
"""

from __future__ import annotations

import numpy as np

from mpm_fem.bases import get
from mpm_fem.bases.bspline import bspline_shape
from mpm_fem.bases.bspline_gimp import bspline_gimp_shape
from mpm_fem.bases.gimp import gimp_shape
from mpm_fem.bases.point import point_shape
from mpm_fem.bases.shape import OutsideGridError, Shape, locate
from mpm_fem.core.grid import Grid

__all__ = ["OutsideGridError", "Shape", "basis_integrals", "bspline_gimp_shape", "bspline_shape",
           "gimp_shape", "grid_functions", "locate", "make_shape", "point_shape"]


def grid_functions(basis: str) -> str:
    """The point basis of the grid functions ``S_i(x)`` of ``basis`` (``"mpm"`` or ``"bspline"``)."""
    return get(basis).grid_functions


def basis_integrals(grid: Grid, basis: str = "mpm") -> np.ndarray:
    """``int S_i dx`` over the grid (n_nodes,), the weight that turns a nodal mass into a density
    (:meth:`mpm_fem.bases.contract.Basis.integrals` of the basis's grid functions)."""
    return get(basis).integrals(grid)


def make_shape(grid: Grid, x: np.ndarray, volume: np.ndarray | None = None, basis: str = "mpm") -> Shape:
    """``S_ip``, ``G_ip`` of the particles at ``x`` (n_p,) for the registered ``basis``
    (:meth:`mpm_fem.bases.contract.Basis.shape`; a particle-domain basis needs ``volume``)."""
    return get(basis).shape(grid, x, volume)
