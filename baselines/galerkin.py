"""What the two fixed-mesh Galerkin baselines (:mod:`baselines.fem_burgers`,
:mod:`baselines.fem_euler`) share: the P1 cells of the mesh and the checks of a run's settings.

A P1 mesh is read cell by cell: cell ``e = [x_a, x_b]`` joins the nodes ``a`` and ``b`` and has
the size ``h_e = x_b - x_a``; the lumped mass is ``m_i = int S_i dx``, the row sums of the
consistent mass ``M_ij = int S_i S_j dx`` (both assembled by scikit-fem in :mod:`mpm_fem.core.grid`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mpm_fem.core.grid import Grid, GridError, uniform_grid

MASS_KINDS = ("consistent", "lumped")


@dataclass(frozen=True, eq=False)
class P1Cells:
    """Cell connectivity (``a``, ``b``: the end nodes of each cell), cell sizes ``h``, the number
    of nodes, which mass matrix the run solves with and the lumped mass ``m_i``."""

    a: np.ndarray
    b: np.ndarray
    h: np.ndarray
    n_nodes: int
    mass: str
    lumped: np.ndarray


def p1_cells(grid: Grid, mass: str) -> dict:
    """The fields of :class:`P1Cells` on ``grid`` (a dict, to build a subclass with more fields)."""
    a, b = grid.mesh.t
    x = grid.mesh.p[0]
    return dict(a=a, b=b, h=x[b] - x[a], n_nodes=grid.n_nodes, mass=mass, lumped=grid.lumped_mass)


def check_mass(mass: str) -> None:
    """ValueError unless ``mass`` is one of :data:`MASS_KINDS`."""
    if mass not in MASS_KINDS:
        raise ValueError(f"unknown mass {mass!r}: expected one of {MASS_KINDS}")


def check_settings(mass: str, T: float, **fractions: float) -> None:
    """ValueError for an unknown ``mass``, a final time ``T`` that is not positive and finite, or
    a step fraction (``cfl=...``) outside (0, 1]."""
    check_mass(mass)
    for name, value in fractions.items():
        if not (np.isfinite(value) and 0.0 < value <= 1.0):
            raise ValueError(f"{name} must lie in (0, 1], got {name}={value}")
    if not (np.isfinite(T) and T > 0):
        raise ValueError(f"final time T must be positive and finite, got T={T}")


def mesh(lo: float, hi: float, h: float) -> Grid:
    """The uniform grid of size ``h`` on ``[lo, hi]``; ValueError if ``h`` does not tile it."""
    try:
        return uniform_grid(lo, hi, h)
    except GridError as err:
        raise ValueError(str(err)) from err
