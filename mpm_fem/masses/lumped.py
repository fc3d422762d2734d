"""The lumped mass: ``M_L = diag(m_i)``, ``m_i = sum_p m_p S_ip`` (the row sums of the particle mass matrix).

    v_i = P_i / m_i,    a_i = f_i / m_i                (nodes without mass: 0)

It conserves momentum exactly (``sum_i m_i v_i = sum_i P_i``) and is the mass of the compiled step.
"""

from __future__ import annotations

from mpm_fem.masses.contract import GridMass, MassSystem, Solve, lumped_solve


class Lumped(GridMass):
    name = "lumped"
    title = "row sums of the particle mass matrix (diagonal)"
    stage = "lumped"

    def solver(self, system: MassSystem) -> Solve:
        return lumped_solve(system.m_i)


LUMPED = Lumped()
