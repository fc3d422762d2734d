"""The transfers: the grid-to-particle update (and its particle-to-grid momentum), each one module
behind a contract (:mod:`~mpm_fem.core.transfers.contract`), read from a registry, as the bases are.

    flip   the PIC/FLIP blend, parameter ``Stages.flip`` (1: FLIP, 0: PIC)   :mod:`~mpm_fem.core.transfers.flip`
    xpic   XPIC(m), parameter ``Stages.xpic`` (the order m)                   :mod:`~mpm_fem.core.transfers.xpic`
    apic   affine PIC, particle state ``C_p``                                :mod:`~mpm_fem.core.transfers.apic`

A run names its transfer by ``Stages(transfer=...)``; the old API stays: ``Stages(xpic=m)`` with
``m >= 1`` is the ``xpic`` transfer, ``Stages(flip=b)`` the ``flip`` transfer
(:attr:`mpm_fem.core.step.Stages.transfer_name`).

The package sits inside the core (layer 2c, ``tests/test_layers.py``) because the numpy step reads
it and it reads the core's projections; a package above the core would make the step import upward.

``scheme`` (USL, USF, MUSL: when the stress is updated) is not a transfer: it orders the whole step
(the state update before the force or after the move, MUSL's re-projection), not the map between
particles and grid, so it stays a field of :class:`~mpm_fem.core.step.Stages`. MUSL re-projects
with the transfer's own P2G (:meth:`Transfer.momentum`).
"""

from mpm_fem.core.transfers.apic import Apic
from mpm_fem.core.transfers.contract import GridVelocities, Transfer
from mpm_fem.core.transfers.flip import Flip
from mpm_fem.core.transfers.registry import get, names, register
from mpm_fem.core.transfers.xpic import Xpic

register(Flip())
register(Xpic())
register(Apic())

__all__ = ["GridVelocities", "Transfer", "get", "names", "register"]
