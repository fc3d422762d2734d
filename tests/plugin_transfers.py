"""Transfers as a researcher's package would write them, for ``test_plugins.py`` (``plugin_transfers:Name``).

``Flip2`` is the package's PIC/FLIP blend written again from the contract alone (numpy step); the
others each break one check of :func:`mpm_fem.core.transfers.plugins.verify`.
"""

from __future__ import annotations

import numpy as np

from mpm_fem.core.transfers import Transfer


class Flip2(Transfer):
    """``v_p^{n+1} = b (v_p^n + dt S a) + (1 - b) S v^{n+1}``, the blend ``b`` the run's ``--flip``."""

    name = "flip2"
    title = "the PIC/FLIP blend, from outside"
    compiled = True  # claimed: a transfer from outside runs on the numpy step all the same

    def update(self, grid, velocity, setting):
        flip = velocity + grid.dt * grid.shape.gather(grid.a_i)
        return (flip if setting == 1 else setting * flip + (1.0 - setting) * grid.moving), None


class Damped(Flip2):
    """PIC damped by 1 %: a uniform velocity comes back 1 % slower."""

    name = "damped"

    def update(self, grid, velocity, setting):
        return 0.99 * grid.moving, None


class Leaky(Flip2):
    """P2G that loses 1 % of the momentum."""

    name = "leaky"

    def momentum(self, shape, nodes, x, mass, velocity, affine):
        return 0.99 * super().momentum(shape, nodes, x, mass, velocity, affine)


class Stretched(Flip2):
    """One velocity too many."""

    name = "stretched"

    def update(self, grid, velocity, setting):
        return np.r_[grid.moving, 0.0], None


class Exploding(Flip2):
    """A division by the velocity's change: NaN where it does not change."""

    name = "exploding"

    def update(self, grid, velocity, setting):
        with np.errstate(all="ignore"):
            return grid.moving * np.inf, None


class Nameless(Transfer):
    """A transfer without a name."""

    title = "nameless"

    def update(self, grid, velocity, setting):
        return grid.moving, None


class Abstract(Transfer):
    """A transfer without its update: the base class cannot instantiate it."""

    name = "abstract"


class NotATransfer:
    """Not a transfer at all."""

    name = "not_a_transfer"
