"""What a transfer provides: the grid-to-particle update and its particle-to-grid momentum.

A transfer is the pair of maps between the particles' velocity state and the grid's (the bases'
contract, :mod:`mpm_fem.bases.contract`, is the model): ``momentum`` gives the grid momentum
``P_i`` the particles project (P2G), ``update`` the particles' new velocity state from the step's
grid velocities (G2P). A transfer is a small class in a module of its own, one instance registered
(:mod:`mpm_fem.core.transfers.registry`); the numpy step reads the registry, and the compiled step
takes only the transfers whose ``compiled`` is set (the others run the numpy step,
:func:`mpm_fem.fused.step.supported`).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Callable, NamedTuple

import numpy as np

from mpm_fem.bases.shape import Shape
from mpm_fem.core.transfer import nodal_momentum


@dataclass(frozen=True, eq=False)
class GridVelocities:
    """What the grid hands a transfer in one step: ``shape`` the rows at ``x_p^n``; ``mass`` the
    particle masses; ``m_i``, ``v_i`` (``v_i^n``), ``a_i``, ``v_new`` (``v_i^{n+1}``) all (n_nodes,);
    ``moving`` ``sum_i S_ip v_i^{n+1}``; ``dt``; ``kind`` the grid mass (``"lumped"`` or
    ``"consistent"``); ``rule`` the boundary rule for a velocity change (XPIC's ``P``)."""

    shape: Shape
    mass: np.ndarray
    m_i: np.ndarray
    v_i: np.ndarray
    a_i: np.ndarray
    v_new: np.ndarray
    moving: np.ndarray
    dt: float
    kind: str
    rule: Callable[[np.ndarray], np.ndarray]


class AffineKernels(NamedTuple):
    """An affine transfer's compiled pieces (numba functions over a step's stored rows: ``rows``
    (n_p, K) node indices, ``S``, ``G`` (n_p, K) at ``x_p^n``), each the numpy form's operations in
    its order, so that the fused step equals the numpy step bit for bit on one thread. The fused
    step's particle velocity of an affine transfer is PIC's, ``v_p = sum_i S_ip v_i^{n+1}``.

    momentum     ``(nodes, rows, S, x, m, C, P)``: the affine part of P2G added to ``P`` (n_nodes,)
                 in place, ``P_i += sum_p S_ip (x_i - x_p) m_p C_p``, the sum accumulated on its
                 own from zero in particle order, a row left to right (``np.bincount``'s), then added.
    coefficient  ``(rows, G, v, C)``: G2P's new coefficient into ``C`` (n_p,), ``C_p = sum_i G_ip v_i``
                 (``Shape.gather_gradient``'s order)."""

    momentum: Callable
    coefficient: Callable


class Transfer(ABC):
    """A transfer: ``name`` (a run's ``Stages(transfer=...)``), ``title`` (a few words),
    ``affine`` (whether the particles carry an affine velocity coefficient ``C_p``,
    :attr:`mpm_fem.core.particles.Particles.affine`), ``compiled`` (whether the fused step has
    its kernels: the blend and XPIC are the passes' own, an affine transfer brings ``kernels``)."""

    name: str
    title: str
    affine: bool = False
    compiled: bool = True
    #: an affine transfer's compiled pieces (:class:`AffineKernels`); the fused step refuses an affine
    #: transfer without them
    kernels: AffineKernels | None = None

    def momentum(self, shape: Shape, nodes: np.ndarray, x: np.ndarray, mass: np.ndarray, velocity: np.ndarray,
                 affine: np.ndarray | None) -> np.ndarray:
        """P2G: ``P_i = sum_p m_p v_p S_ip`` (``nodes`` the grid's node positions)."""
        return nodal_momentum(shape, mass, velocity)

    @abstractmethod
    def update(self, grid: GridVelocities, velocity: np.ndarray, setting) -> tuple[np.ndarray, np.ndarray | None]:
        """G2P: the particles' new velocity (n_p,) and affine coefficient (``None`` for a transfer
        without), from the step's ``grid`` and the old particle ``velocity``; ``setting`` the
        transfer's parameter (the blend, the order)."""

    def __repr__(self) -> str:
        return f"<transfer {self.name}>"
