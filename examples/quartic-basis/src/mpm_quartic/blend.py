"""A PIC/FLIP blend with its weight fixed at 0.99 as an mpm-fem transfer (entry point ``flip99``):

    v_p^{n+1} = 0.99 (v_p^n + dt sum_i S_ip a_i) + 0.01 sum_i S_ip v_i^{n+1}

the FLIP update with 1 % of PIC's damping (Brackbill's blends of the 1980s), the particle-to-grid
momentum the contract's own ``P_i = sum_p m_p v_p S_ip``. It ignores the run's ``--flip``: the
weight is the method. mpm-fem runs a transfer from outside on its numpy step.
"""

from __future__ import annotations

from mpm_fem.core.transfers import Transfer

__all__ = ["Flip99"]

WEIGHT = 0.99  # of FLIP; the rest PIC


class Flip99(Transfer):
    name = "flip99"
    title = "PIC/FLIP blend, 0.99 FLIP"
    compiled = False

    def update(self, grid, velocity, setting):
        flip = velocity + grid.dt * grid.shape.gather(grid.a_i)
        return WEIGHT * flip + (1.0 - WEIGHT) * grid.moving, None
