"""The exact forms of the stages of the MPM step (ARCHITECTURE.md, "The stage switches").

The slides ("Explicit MPM Algorithm Errors") name four sources of error: projection,
interpolation, time, and finite element + mass lumping. Each stage of :func:`mpm_fem.core.step.
explicit_step` can be replaced by an exact form that removes the error *that stage adds*, while
the errors carried in from the stages before it pass through unchanged. That is what makes the
error budget (E1) additive. With ``f*`` the exact field a stage should deliver:

    projection (particles -> grid)      m_i = int rho S_i dx,  P_i = int rho v S_i dx,
                                        F_i = - int sigma S_i' dx
                                        (composite Gauss-Legendre, split at the cell nodes, the
                                        half cells and the problem's breakpoints: exact to
                                        round-off for piecewise-polynomial fields)
    mass (FE + lumping, grid solve)     u_i = u*(x_i) + [solve(MPM data) - solve(exact data)]:
                                        the solve makes no error of its own on exact data
                                        (exact data: the FE mass matrices of the exact density
                                        on scikit-fem's basis, :mod:`mpm_fem.exact_stages.mass`)
    interpolation (grid -> particles)   f_p = f*(x_p) + sum_i S_ip (f_i - f*_i): the interpolant is
                                        exact for the exact field; the nodal error still reaches
                                        the particle
    time                                dt -> dt / k (``Stages.refine``)

``solve`` is the lumped division ``rhs_i / m_i`` (the MPM default) and ``f*_i`` are the exact
nodal values with the boundary conditions applied (the grid's boundary rule is part of the
scheme). Every stage exact leaves semi-implicit Euler on the exact fields:

    v_p^{n+1} = v_p^n + dt a*(x_p^n, t^n),    x_p^{n+1} = x_p^n + dt (v* + dt a*)(x_p^n, t^n),
    (dv/dx)_p = v*_x(x_p^n, t^{n+1})  (USL; USF: t^n),

so the remainder is the time error of the (refined) step alone.

A problem supplies its exact fields (:class:`~mpm_fem.exact_stages.fields.ExactFields`): point values
for the projection integrals and the reference fields ``v*``, ``v*_x``, ``a* = Dv*/Dt`` that grid and
particle values approximate (averages over a particle domain across Sod's shock).

:class:`ExactGridStage` is the grid stage of a step with any of these exact forms; :class:`FieldStages`
hands it, with the fields at the particles, to the numpy step (which reaches it through the
protocol :class:`mpm_fem.core.step.ExactStages`, never by importing this package). The exact forms
themselves: ``quadrature``, ``projection``, ``mass``, ``grid_data`` of this package.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

import mpm_fem.exact_stages.grid_kernels as grid_kernels
from mpm_fem.core.grid import Grid
from mpm_fem.core.shape import Shape
from mpm_fem.exact_stages.fields import ExactFields
from mpm_fem.exact_stages.grid_data import GridData, nodal_values
from mpm_fem.exact_stages.projection import exact_projection


class ExactGridStage:
    """The grid stage of a step with exact stages (:func:`mpm_fem.core.step.explicit_step`), written once
    for the numpy step and the fused one (:mod:`mpm_fem.fused.step`), which differ in how the particle
    sums ``mpm`` (``m_i``, ``P_i``) and ``F_i`` are made, not in what the grid does with them.

    Built at the start of a step it holds the exact nodal data and ``v_i``:

        projection exact   the quadrature's data ``quad`` in place of the particles'
                           (:func:`~mpm_fem.exact_stages.projection.exact_projection`)
        mass exact         v_i = v*_i + [solve(MPM data) - solve(exact data)] (``solve``: the lumped
                           division; exact data with the FE mass when the projection is MPM)
        both exact         v_i = v*_i (and a_i = a*_i: no quadrature data are made)

    and the exact nodal values with the grid's boundary rule, ``star_v = BC(v*_i)``,
    ``star_a = BC(a*_i)``, which the exact interpolation corrects against. :meth:`acceleration`
    gives ``a_i`` from the particles' force ``F_i`` the same way."""

    def __init__(self, grid: Grid, boundary, stages, exact: ExactFields, mpm: GridData, t: float, dt: float):
        self.grid, self.boundary, self.stages, self.mpm, self.t, self.dt = grid, boundary, stages, mpm, t, dt
        fe_mass_stage = stages.mass == "exact" and stages.projection == "mpm"  # solves exact data with the FE mass
        # the quadrature data where a solve reads them (both exact: v_i = v*_i reads none)
        self.quad = (exact_projection(grid, stages.basis, exact, t, with_fe_mass=fe_mass_stage)
                     if (stages.projection == "exact") != (stages.mass == "exact") else None)
        self.source = self.quad if stages.projection == "exact" else mpm
        self.kind = "lumped" if stages.mass == "exact" else stages.mass
        ref_v, _, self.ref_a = exact.reference(grid.nodes, t)
        P_exact = self.quad.P_i if self.quad is not None else None
        self.v_i = boundary.velocity(grid, self.solve(self.source.P_i if self.source is not None else None,
                                                      P_exact, ref_v), t)
        self.star_v = boundary.velocity(grid, ref_v, t)
        self.star_a = boundary.acceleration(grid, self.ref_a, self.star_v, t, dt)

    def solve(self, rhs: np.ndarray, exact_rhs: np.ndarray | None, reference: np.ndarray) -> np.ndarray:
        """Nodal values of a projected right-hand side, the mass stage's form (class docstring)."""
        if self.stages.mass != "exact":
            return nodal_values(self.source, rhs, self.kind)
        if self.stages.projection == "exact":
            return reference.copy()
        # the lumped solves (the mass stage's form) in one compiled pass
        return grid_kernels.corrected(reference, rhs, self.mpm.m_i, exact_rhs, self.quad.m_i)

    def solve_numpy(self, rhs: np.ndarray, exact_rhs: np.ndarray | None, reference: np.ndarray) -> np.ndarray:
        """The readable reference of :meth:`solve` (equal bit for bit): the mass exact and the
        projection MPM give ``v*_i + rhs_i / m_i - rhs*_i / m*_i`` with :func:`nodal_values`."""
        if self.stages.mass == "exact" and self.stages.projection == "mpm":
            return reference + nodal_values(self.mpm, rhs, self.kind) - nodal_values(self.quad, exact_rhs, self.kind)
        return self.solve(rhs, exact_rhs, reference)

    def acceleration(self, F_mpm: np.ndarray | None) -> np.ndarray:
        """``a_i`` from the particles' force ``F_mpm`` (the quadrature's when the projection is exact,
        where ``F_mpm`` may be None), the boundary rule applied."""
        F_i = F_mpm if self.stages.projection == "mpm" else (self.quad.F_i if self.quad is not None else None)
        a_i = self.solve(F_i, self.quad.F_i if self.quad is not None else None, self.ref_a)
        return self.boundary.acceleration(self.grid, a_i, self.v_i, self.t, self.dt)

    @property
    def star_new(self) -> np.ndarray:
        """``star_v + dt star_a``: the exact nodal ``v^{n+1}`` the exact interpolation corrects against."""
        return self.star_v + self.dt * self.star_a


@dataclass(frozen=True, eq=False)
class FieldStages:
    """The exact stages on a problem's exact fields, as the numpy step takes them
    (:class:`mpm_fem.core.step.ExactStages`): the reference fields at the particles are the
    fields' own, and :meth:`grid_stage` is the :class:`ExactGridStage` of the particles' sums."""

    fields: ExactFields

    def reference(self, x: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(v*, v*_x, a*)`` at ``x`` (:meth:`ExactFields.reference`)."""
        return self.fields.reference(x, t)

    def velocity_gradient(self, x: np.ndarray, t: float) -> np.ndarray:
        """``v*_x`` at ``x`` (:meth:`ExactFields.velocity_gradient`)."""
        return self.fields.velocity_gradient(x, t)

    def grid_stage(self, grid: Grid, boundary, stages, shape: Shape, mass: np.ndarray, m_i: np.ndarray,
                   P_i: np.ndarray, t: float, dt: float) -> ExactGridStage:
        """The grid stage of the step from ``t`` to ``t + dt`` on the particles' rows ``shape``, masses
        ``mass`` (n_p,), ``m_i`` and ``P_i`` (n_nodes,)."""
        return ExactGridStage(grid, boundary, stages, self.fields, GridData(shape, mass, m_i, P_i), t, dt)
