"""The exact mass stage: the nodal values with the mass error removed (the 1D stage of
:mod:`mpm_fem.exact_stages.stage`), given by the step from the problem's exact solution,

    v_i = v*_i + P_i / m_i - P*_i / m*_i,      a_i = a*_i + f_i / m_i - f*_i / m*_i,

with ``m*_i``, ``P*_i``, ``f*_i`` the exact integrals of the exact fields and ``v*_i``, ``a*_i`` the
exact nodal values (lumped solves on both sides). Its :meth:`solver` is the lumped one, which the
step combines with the exact data; a step without the exact stages cannot run it.
"""

from __future__ import annotations

from mpm_fem.masses.contract import GridMass, MassSystem, Solve, lumped_solve


class ExactMass(GridMass):
    name = "exact"
    title = "the mass stage made exact (the FE and lumping errors removed with the exact solution)"
    stage = "exact"

    def solver(self, system: MassSystem) -> Solve:
        return lumped_solve(system.m_i)


EXACT = ExactMass()
