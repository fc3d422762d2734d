"""The nodal data a projection hands the grid (:class:`GridData`), and the nodal values solved from them.

With ``n_q`` particles, or quadrature points acting as particles, and ``n`` nodes:

    shape    the grid functions' rows at the points (:class:`~mpm_fem.core.shape.Shape`)
    mass     (n_q,)          the points' masses (``w_q rho_q`` for quadrature points)
    m_i      (n,)            the lumped mass
    P_i      (n,)            the momentum
    F_i      (n,) or None    the internal force, where the projection made it
    matrix   the consistent mass, where it is not the points' ``M_ij = sum_q mass_q S_qi S_qj``:
             a sparse (n, n) matrix or a function of no arguments that assembles it

:func:`nodal_values` solves the nodal values ``u`` of a right-hand side ``rhs`` (n,):

    lumped       u_i = rhs_i / m_i      (0 where ``m_i`` is not positive)
    consistent   M u = rhs              (``M``: ``matrix`` if given, else the points')
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve

from mpm_fem.core.shape import Shape
from mpm_fem.core.transfer import divide_by_lumped, grid_values


@dataclass(frozen=True, eq=False)
class GridData:
    """What the projection hands the grid: the kernel and weights of the particles (or quadrature
    points), and ``m_i``, ``P_i``, ``F_i``. The mass matrix is ``matrix`` where given (the FE mass
    of exact data, :func:`~mpm_fem.exact_stages.mass.fe_mass`, or a function of no arguments that
    assembles it: the lumped solve needs only ``m_i``), else the particle matrix
    ``M_ij = sum_q w_q S_iq S_jq``."""

    shape: Shape
    mass: np.ndarray
    m_i: np.ndarray
    P_i: np.ndarray
    F_i: np.ndarray | None = field(default=None)
    matrix: sp.csr_matrix | Callable[[], sp.csr_matrix] | None = field(default=None)


def nodal_values(data: GridData, rhs: np.ndarray, kind: str) -> np.ndarray:
    """Grid values from a projected right-hand side: ``rhs_i / m_i`` (``kind="lumped"``) or
    ``M^{-1} rhs`` (``"consistent"``), with ``data``'s FE mass if it has one, else its particles'."""
    if data.matrix is None:
        return grid_values(data.shape, data.mass, data.m_i, rhs, kind)
    if kind == "lumped":
        return divide_by_lumped(rhs, data.m_i)
    if kind == "consistent":
        matrix = data.matrix() if callable(data.matrix) else data.matrix
        return spsolve(matrix.tocsc(), rhs)
    raise ValueError(f"unknown mass kind {kind!r}; choose one of lumped, consistent")
