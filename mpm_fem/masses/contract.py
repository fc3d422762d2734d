"""What a grid mass provides: the contract every grid-mass module meets (scikit-fem's ``Element`` is the model).

The grid stage of an explicit MPM step turns the particles' nodal sums into nodal values,

    v_i = (M^-1 P)_i,    a_i = (M^-1 f)_i,

with ``P_i = sum_p m_p v_p S_ip`` the nodal momentum and ``f_i`` the nodal force. A grid mass is the
operator ``rhs -> M^-1 rhs`` (or an approximation of it): one small class in a module of its own
(:mod:`mpm_fem.masses.lumped` is the model), one instance registered
(:mod:`mpm_fem.masses.registry`). The step builds a :class:`MassSystem` from its rows and asks the
registered mass for its :meth:`GridMass.solver`. The matrices a mass may read (``S_ip`` the
particles' rows, ``m_p`` their masses):

    lumped        M_L = diag(m_i),  m_i = sum_p m_p S_ip                       (the row sums of M_P)
    particle      M_P = S^T diag(m_p) S,  (M_P)_ij = sum_p m_p S_ip S_jp       (the "full" mass of MPM)
    grid          M_G = rho_0 int S_i S_j dx over the grid (the grid basis's own mass matrix, fixed)

The invariant every mass is tested on: it conserves the particles' momentum, ``m^T M^-1 rhs =
sum_i rhs_i`` (with ``m`` the lumped masses), which holds when the columns of ``M`` sum to ``m_i``
(``M_L``, ``M_P`` and every truncation of the series of :mod:`mpm_fem.masses.fmpm`); ``M_G`` meets
it only where the particles' lumped masses equal its row sums (:mod:`mpm_fem.masses.grid`).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import Callable, NamedTuple

import numpy as np
import scipy.sparse as sp

Solve = Callable[[np.ndarray], np.ndarray]  # rhs (n_nodes, d) -> M^-1 rhs (n_nodes, d)


class MassSystem(NamedTuple):
    """What a grid mass may read: ``S`` the (n_p x n_nodes) sparse matrix of ``S_ip``, ``m`` (n_p,)
    the particle masses, ``m_i`` (n_nodes,) the lumped nodal masses ``sum_p m_p S_ip``, and
    ``grid_solve``: a callable giving the solve of the grid basis's own mass matrix ``M_G``
    (factorised once per grid by the caller), or ``None`` where the caller has none."""

    S: sp.csr_matrix
    m: np.ndarray
    m_i: np.ndarray
    grid_solve: Callable[[], Solve] | None = None


class GridMass(ABC):
    """A grid mass: its class attributes and :meth:`solver`.

    name    the name a run's ``mass=`` and the command line's ``--mass`` use
    title   what it is, in a few words (the command line's help)
    stage   the mass stage of the 1D stage switches it belongs to (``Stages.mass``): ``lumped`` (a
            diagonal solve: the compiled step serves it), ``consistent`` (a solve with a full matrix,
            exact or approximate) or ``exact`` (the exact mass stage: the step's exact stages)
    fills   whether it needs a body that fills the grid (every node with mass); default False
    """

    name: str
    title: str
    stage: str
    fills: bool = False

    @abstractmethod
    def solver(self, system: MassSystem) -> Solve:
        """``rhs -> M^-1 rhs`` for right-hand sides (n_nodes, d); nodes without mass (``m_i = 0``) get 0."""

    def constrained_solver(self, system: MassSystem, fixed: np.ndarray) -> Callable[[np.ndarray, np.ndarray],
                                                                                       np.ndarray]:
        """``(rhs, values) -> u`` with ``u[fixed] = values`` prescribed (a wall, a Dirichlet end) and the free
        rows ``F`` solving ``M_FF u_F = rhs_F - M_F,fixed values`` (or the mass's approximation of it); a mass
        that has none refuses (``NotImplementedError``)."""
        raise NotImplementedError(f"the grid mass {self.name!r} has no solve with prescribed nodal values")

    def __repr__(self) -> str:
        return f"<grid mass {self.name}>"


ATTRIBUTES = {"name": "its name", "title": "what it is, in a few words",
              "stage": "its mass stage: lumped, consistent or exact"}
STAGES = ("lumped", "consistent", "exact")


def missing(mass) -> list[str]:
    """The pieces of the contract ``mass`` lacks (empty: complete)."""
    if not isinstance(mass, GridMass):
        return [f"the base class GridMass (got {type(mass).__name__})"]
    out = [f"{a} ({what})" for a, what in ATTRIBUTES.items() if not isinstance(getattr(mass, a, None), str)]
    if isinstance(getattr(mass, "stage", None), str) and mass.stage not in STAGES:
        out.append(f"stage (one of {', '.join(STAGES)}, got {mass.stage!r})")
    return out


def lumped_solve(m_i: np.ndarray) -> Solve:
    """``rhs -> rhs_i / m_i`` where ``m_i > 0``, else 0."""
    with_mass = (m_i > 0)[:, None]

    def solve(rhs):
        out = np.zeros_like(rhs)
        np.divide(rhs, m_i[:, None], out=out, where=with_mass)
        return out

    return solve


def particle_matrix(system: MassSystem) -> sp.csr_matrix:
    """``M_P = S^T diag(m_p) S`` (n_nodes x n_nodes)."""
    S = system.S
    return (S.T @ sp.diags(system.m) @ S).tocsr()


def particle_product(system: MassSystem) -> Callable[[np.ndarray], np.ndarray]:
    """``x -> M_P x`` for x (n_nodes, d), matrix free: ``S^T (m_p (S x))`` (a gather and a scatter)."""
    S, St, m = system.S, system.S.T.tocsr(), system.m[:, None]
    return lambda x: St @ (m * (S @ x))
