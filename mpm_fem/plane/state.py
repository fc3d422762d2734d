"""The particle state of the 2D step: one frozen dataclass of arrays with named fields.

Notation: reference position ``X_p`` (the material point's label), position ``x_p`` (unwrapped: a
periodic axis folds it only to evaluate the basis, so that ``u_p = x_p - X_p``), velocity ``v_p``
(at the half step ``t - dt/2`` of the symplectic Euler step), deformation gradient ``F_p``,
volume ``V_p = J_p V_p^0``, reference volume ``V_p^0``, mass ``m_p = rho_0 V_p^0`` and the lengths
of the particle domain per axis ``l_p`` (fixed: uGIMP). Shapes: ``X``, ``x``, ``v``, ``lengths``
(n_p, 2); ``F`` (n_p, 2, 2); ``volume``, ``volume0``, ``mass`` (n_p,).
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np


@dataclass(frozen=True, eq=False)
class PlaneParticles:
    """The particles (module docstring)."""

    X: np.ndarray
    x: np.ndarray
    v: np.ndarray
    F: np.ndarray
    volume: np.ndarray
    volume0: np.ndarray
    mass: np.ndarray
    lengths: np.ndarray

    def __post_init__(self):
        n = self.X.shape[0]
        want = {"X": (n, 2), "x": (n, 2), "v": (n, 2), "F": (n, 2, 2), "volume": (n,), "volume0": (n,),
                "mass": (n,), "lengths": (n, 2)}
        for f in fields(self):
            a = getattr(self, f.name)
            if not isinstance(a, np.ndarray) or a.shape != want[f.name]:
                raise ValueError(f"particle field {f.name!r} must be an array of shape {want[f.name]}")

    @property
    def n(self) -> int:
        return self.X.shape[0]

    @property
    def displacement(self) -> np.ndarray:
        """``u_p = x_p - X_p`` (n_p, 2)."""
        return self.x - self.X

    def replace(self, **changes) -> PlaneParticles:
        return replace(self, **changes)
