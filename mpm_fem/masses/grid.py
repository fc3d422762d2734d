"""The grid basis's own mass matrix, exact over the grid and fixed: ``M_G = rho_0 int S_i S_j dx``.

For the point-mass basis and uGIMP the grid functions ``S_i`` are the Q1 hats and ``M_G`` is
scikit-fem's Q1 mass (``BilinearForm(u v)`` assembled on the ``MeshQuad``); for the B-splines it is
their own Gram matrix (:mod:`mpm_fem.plane.mass` builds both; the caller hands the factorised matrix
in as ``MassSystem.grid_solve``, built once per grid). It is the mass of the fixed-mesh FEM on the
same grid, at the reference density: it does not follow the body. So it needs a body that fills the
grid (every node with mass: the axis-aligned problem's periodic square; a body that leaves nodes
empty, the vortex's annulus, is refused), and it conserves the particles' momentum only where their
lumped masses ``m_i`` equal its row sums ``rho_0 int S_i``: on the undeformed regular layout (the
``n x n`` midpoint rule integrates the grid functions exactly), and to ``O(|u_x|)`` (the
displacement gradient) once the body deforms, as the uniform motion ``v_i = v`` is then reproduced
only to that order too.
"""

from __future__ import annotations

from mpm_fem.masses.contract import GridMass, MassSystem, Solve


class GridBasisMass(GridMass):
    name = "grid"
    title = "the grid basis's own mass matrix rho0 int S_i S_j (Q1 by scikit-fem; the B-splines' Gram), fixed"
    stage = "consistent"
    fills = True

    def solver(self, system: MassSystem) -> Solve:
        if system.grid_solve is None:
            raise ValueError("the grid mass needs the grid basis's mass matrix from the caller (grid_solve)")
        if not (system.m_i > 0).all():
            raise ValueError("the grid mass needs a body that fills the grid (every node with mass); "
                             f"{int((system.m_i <= 0).sum())} nodes have none: use the consistent mass")
        return system.grid_solve()


GRID = GridBasisMass()
