"""XPIC(m) (Hammerquist & Nairn 2017): ``v_p^{n+1} = S (v* + dt a)``, :mod:`mpm_fem.core.xpic`.
Its parameter is ``Stages.xpic``, the order ``m >= 1``."""

from __future__ import annotations

from mpm_fem.core.transfers.contract import Transfer
from mpm_fem.core.xpic import xpic_velocity


class Xpic(Transfer):
    name = "xpic"
    title = "extended PIC of order m (Stages.xpic)"

    def update(self, grid, velocity, setting):
        return xpic_velocity(grid.shape, grid.mass, grid.m_i, grid.v_i, grid.a_i, grid.dt, setting, grid.kind,
                             grid.rule), None
