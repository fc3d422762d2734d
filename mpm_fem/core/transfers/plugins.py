"""Transfers from outside the package: an entry point or a ``package.module:Name``, checked before any run.

As the bases (:mod:`mpm_fem.bases.plugins`, one :class:`~mpm_fem.bases.loader.Loader` serves both):

    entry point   ``[project.entry-points."mpm_fem.transfers"] blend = "mypkg.transfers:Blend"``:
                  :func:`discover` loads every installed one (the command line does);
    a spec        ``"mypkg.transfers:Blend"`` where a transfer name goes (``mpm-fem burgers --transfer
                  mypkg.transfers:Blend``): :func:`resolve` imports it.

Either names a :class:`~mpm_fem.core.transfers.contract.Transfer` subclass (instantiated without
arguments) or an instance. Before it is registered it must pass :func:`verify`, the contract checked
on numbers on the point-mass P1 rows of a uniform grid of :data:`CHECK_CELLS` cells on [0, 1] with
:data:`CHECK_PPC` particles per cell, at the run's default setting (:data:`SETTING`, ``Stages.flip``):

1. it is a :class:`Transfer` with a name (a non-empty string);
2. on a step with varied masses, velocities and nodal accelerations, ``update`` returns a velocity of
   shape (n_p,) and an affine coefficient ``None`` or (n_p,), all finite;
3. its P2G conserves momentum: ``sum_i P_i = sum_p m_p v_p`` to :data:`TOLERANCE` relative to
   ``sum_p m_p |v_p|``, for varied velocities (and affine coefficients, for an affine transfer);
4. it carries a constant velocity exactly: P2G (``momentum``) of a uniform ``v_p = U`` (``C_p = 0``)
   with no force, then G2P (``update``), gives ``v_p = U`` (and ``C_p = 0``) to :data:`TOLERANCE`
   relative to ``U`` (``U h^-1``), as every consistent transfer must.

A transfer that fails is refused with a :class:`ContractError` naming the first failed check. The
fused step has kernels for ``flip`` and ``xpic`` only, so a transfer from outside runs on the numpy
step whatever it declares: :func:`resolve` sets its ``compiled`` to False, and the estimate printed
before a run and the run's ``kernel`` say so.
"""

from __future__ import annotations

import numpy as np

from mpm_fem.bases import get as get_basis
from mpm_fem.bases.loader import Loader
from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.transfer import nodal_mass
from mpm_fem.core.transfers.contract import GridVelocities, Transfer
from mpm_fem.core.transfers.registry import names, register

ENTRY_POINT_GROUP = "mpm_fem.transfers"
CHECK_CELLS = 8
CHECK_PPC = 5
TOLERANCE = 1e-12
SETTING = 1.0  # Stages.flip's default: the setting a transfer from outside runs with unless --flip says otherwise
DT = 1e-3  # the check step's time step


class ContractError(TypeError):
    """A transfer that breaks its contract on numbers (or cannot be imported): the message names the check."""


def resolve(spec: str) -> str:
    """The registered name of ``spec`` (:meth:`mpm_fem.bases.loader.Loader.resolve`): raises
    :class:`ContractError` naming the failed check, ``ValueError`` for an unknown name."""
    return LOADER.resolve(spec)


def discover() -> tuple[str, ...]:
    """Load, check and register every installed entry point of :data:`ENTRY_POINT_GROUP` not loaded yet."""
    return LOADER.discover()


def _check_step(transfer: Transfer, velocity: np.ndarray, affine: np.ndarray | None,
                acceleration: np.ndarray) -> tuple[GridVelocities, np.ndarray, np.ndarray]:
    """The grid of one check step: P2G of ``velocity`` (and ``affine``) with the transfer's own
    ``momentum``, ``a_i`` = ``acceleration``, no boundary; also the grid momentum ``P_i`` and the
    particle masses."""
    grid = uniform_grid(0.0, 1.0, 1.0 / CHECK_CELLS)
    n = CHECK_CELLS * CHECK_PPC
    x = (np.arange(n) + 0.5) / n
    mass = (1.0 + 0.5 * np.sin(3.0 * x)) / n
    shape = get_basis("mpm").shape(grid, x, np.full(n, 1.0 / n))
    m_i = nodal_mass(shape, mass)
    P_i = np.asarray(transfer.momentum(shape, grid.nodes, x, mass, velocity, affine), dtype=float)
    v_i = P_i / m_i
    v_new = v_i + DT * acceleration
    state = GridVelocities(shape=shape, mass=mass, m_i=m_i, v_i=v_i, a_i=acceleration, v_new=v_new,
                           moving=shape.gather(v_new), dt=DT, kind="lumped", rule=lambda u: u)
    return state, P_i, mass


def verify(transfer) -> str | None:
    """The first check of the module docstring that ``transfer`` fails, in a few words; ``None`` if it
    passes them all."""
    if not isinstance(transfer, Transfer):
        got = transfer.__name__ if isinstance(transfer, type) else type(transfer).__name__
        return f"it is not a Transfer (mpm_fem.core.transfers.Transfer), got {got}"
    if not (isinstance(getattr(transfer, "name", None), str) and transfer.name):
        return "it has no name (a non-empty string)"
    n = CHECK_CELLS * CHECK_PPC
    x = (np.arange(n) + 0.5) / n
    varied = 0.3 + np.cos(5.0 * x)
    affine = np.sin(7.0 * x) if transfer.affine else None
    nodes = np.linspace(0.0, 1.0, CHECK_CELLS + 1)
    try:
        state, P_i, mass = _check_step(transfer, varied, affine, np.sin(4.0 * nodes))
        velocity, new_affine = transfer.update(state, varied, SETTING)
    except Exception as err:  # noqa: BLE001 - a third-party transfer may raise anything: that is the finding
        return f"its momentum or update raises {type(err).__name__}: {err}"
    velocity = np.asarray(velocity, dtype=float)
    if velocity.shape != (n,) or (new_affine is not None and np.shape(new_affine) != (n,)):
        return (f"its update returns shapes {velocity.shape} and "
                f"{None if new_affine is None else np.shape(new_affine)}, not ({n},) and None or ({n},)")
    if not (np.all(np.isfinite(velocity)) and (new_affine is None or np.all(np.isfinite(new_affine)))):
        return "its update returns velocities or affine coefficients that are not finite"
    gap = abs(P_i.sum() - np.sum(mass * varied)) / np.sum(mass * np.abs(varied))
    if gap > TOLERANCE:
        return f"its momentum does not conserve momentum: |sum_i P_i - sum_p m_p v_p| is {gap:.3g} of it"
    U = 1.5
    try:
        state, _, _ = _check_step(transfer, np.full(n, U), np.zeros(n) if transfer.affine else None,
                                  np.zeros(nodes.size))
        velocity, new_affine = transfer.update(state, np.full(n, U), SETTING)
    except Exception as err:  # noqa: BLE001 - as above
        return f"its momentum or update raises {type(err).__name__}: {err}"
    drift = np.abs(np.asarray(velocity) - U).max() / U
    if new_affine is not None:
        drift = max(drift, np.abs(np.asarray(new_affine)).max() / (U * CHECK_CELLS))
    if not drift <= TOLERANCE:
        return f"it does not carry a constant velocity: P2G then G2P of v_p = {U:g} is off by {drift:.3g} of it"
    return None


def _numpy_step_only(transfer: Transfer) -> None:
    """The fused step has kernels for the package's ``flip`` and ``xpic`` only."""
    object.__setattr__(transfer, "compiled", False)  # also on a frozen dataclass's instance


#: the transfers from outside the package (:class:`~mpm_fem.bases.loader.Loader`)
LOADER = Loader("transfer", ENTRY_POINT_GROUP, Transfer, names, register, verify, ContractError, _numpy_step_only)
