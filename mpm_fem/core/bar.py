"""One explicit MPM step of the neo-Hookean bar, update stress last (USL), symplectic Euler: the 1D
control of the 2D step (:mod:`mpm_fem.plane.step`), written with the 1D core's pieces.

The particles carry ``v_p^{n-1/2}`` (a run starts from the exact ``v(X_p, -dt/2)``), ``x_p^n``,
``F_p^n``; one step from ``t_n`` to ``t_n + dt`` on the periodic grid (:mod:`mpm_fem.core.periodic`):

    m_i = sum_p m_p S_ip,      P_i = sum_p m_p v_p S_ip,
    f_i = - sum_p V_p sigma_p G_ip + sum_p m_p b(X_p, t_n) S_ip          (internal + body force)
    v_i = P_i / m_i,  a_i = f_i / m_i          (lumped; consistent: M v = P, M a = f with the
                                                particle mass matrix M_ij = sum_p m_p S_ip S_jp)
    v_i^+ = v_i + dt a_i
    v_p <- flip (v_p + dt sum_i S_ip a_i) + (1 - flip) sum_i S_ip v_i^+      (FLIP/PIC blend)
    x_p <- x_p + dt sum_i S_ip v_i^+
    F_p <- (1 + dt sum_i G_ip v_i^+) F_p,   V_p = F_p V_p^0,   sigma_p: :mod:`~mpm_fem.core.models.solid`

MUSL (``scheme="musl"``): the velocity gradient takes ``v_i^+`` re-projected from the new particle
velocities. The rows ``S_ip``, ``G_ip`` are a registered basis's (:func:`mpm_fem.core.shape.make_shape`,
the 1D step's), a particle-domain basis averaging over the fixed length ``V_p^0`` (uGIMP, as the 2D
step's lengths); the sums are :mod:`mpm_fem.core.transfer`'s, the blend the registered transfer
``"flip"``. The stage switches are :class:`~mpm_fem.core.step.Stages`' ``basis``, ``mass``
(``lumped``, ``consistent``), ``flip`` and ``scheme`` (``usl``, ``musl``); the others must keep their
defaults (:func:`check_stages`). No Python loop runs over particles or nodes.

Particle state (:class:`BarParticles`): reference position ``X_p``, position ``x_p`` (unwrapped: the
grid folds it only to evaluate the basis, so that ``u_p = x_p - X_p``), velocity ``v_p``, stretch
``F_p``, volume ``V_p``, reference volume ``V_p^0``, mass ``m_p = rho_0 V_p^0``; all (n_p,).
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace
from typing import Callable

import numpy as np

from mpm_fem.core.models.solid import NeoHookeanBar
from mpm_fem.core.periodic import PeriodicLine
from mpm_fem.core.step import Stages
from mpm_fem.core.transfer import (
    MASS_KINDS,
    gradient,
    grid_values,
    interpolate,
    nodal_internal_force,
    nodal_mass,
    nodal_momentum,
)
from mpm_fem.core.transfers import GridVelocities
from mpm_fem.core.transfers import get as get_transfer

SCHEMES = ("usl", "musl")
BodyForce = Callable[[np.ndarray, float], np.ndarray]  # (X, t) -> (n_p,) per unit mass


@dataclass(frozen=True, eq=False)
class BarParticles:
    """The particles of the bar (module docstring); every field an (n_p,) float array."""

    X: np.ndarray
    x: np.ndarray
    v: np.ndarray
    F: np.ndarray
    volume: np.ndarray
    volume0: np.ndarray
    mass: np.ndarray

    def __post_init__(self):
        n = self.X.shape
        for f in fields(self):
            a = getattr(self, f.name)
            if not isinstance(a, np.ndarray) or a.shape != n or a.ndim != 1:
                raise ValueError(f"particle field {f.name!r} must be a 1D array of shape {n}")

    @property
    def n(self) -> int:
        return self.X.size

    @property
    def displacement(self) -> np.ndarray:
        """``u_p = x_p - X_p`` (n_p,)."""
        return self.x - self.X

    def replace(self, **changes) -> BarParticles:
        return replace(self, **changes)


@dataclass(frozen=True, eq=False)
class BarGridState:
    """What the grid held in one step, all (n_nodes,): ``m_i``, ``v_i``, ``a_i``, ``v_i^+``."""

    mass: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    new_velocity: np.ndarray


#: the switches of :class:`~mpm_fem.core.step.Stages` the bar step does not offer, with their value
FIXED = {"projection": "mpm", "interpolation": "mpm", "acceleration": "calculated", "refine": 1, "xpic": 0,
         "reconstruct": "none", "volume": "carried", "transfer": "flip", "volume_rate": "point"}


def check_stages(stages: Stages) -> None:
    """Raise ``ValueError`` for a switch the bar step does not take (module docstring)."""
    if stages.scheme not in SCHEMES:
        raise ValueError(f"the bar step runs the schemes {', '.join(SCHEMES)}, got {stages.scheme!r}")
    if stages.mass not in MASS_KINDS:
        raise ValueError(f"the bar step runs the masses {', '.join(MASS_KINDS)}, got {stages.mass!r}")
    for name, value in FIXED.items():
        if getattr(stages, name) != value:
            raise ValueError(f"the bar step runs with {name}={value!r}, got {getattr(stages, name)!r}")


def _unchanged(u: np.ndarray) -> np.ndarray:
    """The boundary rule of a periodic grid: no node's velocity is prescribed."""
    return u


def bar_step(state: BarParticles, grid: PeriodicLine, model: NeoHookeanBar, dt: float, t: float,
             body_force: BodyForce | None, stages: Stages = Stages()) -> tuple[BarParticles, BarGridState]:
    """Advance the bar's particles from ``t`` to ``t + dt`` (module docstring).

    Parameters
    ----------
    state : BarParticles
        The particles at ``t`` (velocity at ``t - dt/2``).
    grid : PeriodicLine
    model : NeoHookeanBar
    dt, t : float
        Time step and time (s).
    body_force : callable or None
        ``b(X, t) -> (n_p,)`` per unit mass (m/s^2) at the reference positions.
    stages : Stages
        ``basis``, ``mass``, ``flip``, ``scheme`` (:func:`check_stages`).

    Returns
    -------
    BarParticles, BarGridState
        The particles at ``t + dt`` (velocity at ``t + dt/2``) and the grid of the step. Raises
        :class:`~mpm_fem.core.models.solid.InvertedBarError` for a particle with ``F <= 0``.
    """
    check_stages(stages)
    shape = grid.shape(state.x, state.volume0, stages.basis)
    m = state.mass
    m_i = nodal_mass(shape, m)
    P_i = nodal_momentum(shape, m, state.v)
    f_i = nodal_internal_force(shape, state.volume, model.stress(state.F))
    if body_force is not None:
        f_i += shape.scatter(m * np.asarray(body_force(state.X, t), dtype=float))
    v_i = grid_values(shape, m, m_i, P_i, stages.mass)
    a_i = grid_values(shape, m, m_i, f_i, stages.mass)
    v_new = v_i + dt * a_i

    moving = interpolate(shape, v_new)
    v, _ = get_transfer("flip").update(
        GridVelocities(shape, m, m_i, v_i, a_i, v_new, moving, dt, stages.mass, _unchanged), state.v, stages.flip)
    x = state.x + dt * moving
    if stages.scheme == "musl":
        v_new = grid_values(shape, m, m_i, nodal_momentum(shape, m, v), stages.mass)
    F = model.update(state.F, gradient(shape, v_new), x, dt)
    new = state.replace(x=x, v=v, F=F, volume=F * state.volume0)
    return new, BarGridState(m_i, v_i, a_i, v_new)
