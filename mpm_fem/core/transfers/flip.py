"""The PIC/FLIP blend: ``v_p^{n+1} = b (v_p^n + dt S a) + (1 - b) S v^{n+1}`` (``b = 1``: FLIP, the
slides' update; ``b = 0``: PIC). Its parameter is ``Stages.flip``, the blend ``b`` in [0, 1]."""

from __future__ import annotations

from mpm_fem.core.transfers.contract import Transfer


class Flip(Transfer):
    name = "flip"
    title = "the PIC/FLIP blend (flip = 1: FLIP, 0: PIC)"

    def update(self, grid, velocity, setting):
        out = velocity + grid.dt * grid.shape.gather(grid.a_i)
        if setting != 1:
            out = setting * out + (1.0 - setting) * grid.moving
        return out, None
