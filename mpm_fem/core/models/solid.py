"""The compressible neo-Hookean solid in uniaxial strain: the bar of the 1D control.

The 2D model (:mod:`mpm_fem.plane.model`, ``baselines.exact.solids``) with ``F = diag(F, 1)``:
one stretch ``F`` per particle, ``J = F``, and

    F_p^{n+1} = (1 + dt L_p) F_p^n,      L_p = (dv/dx)_p = sum_i G_ip v_i^{n+1/2}
    V_p = F_p V_p^0
    sigma_p = (mu (F_p^2 - 1) + lambda ln F_p) / F_p        (Cauchy stress; = P in uniaxial strain)

with the Lame constants ``mu``, ``lambda`` of the material (``Material(E, nu, rho0)`` of
``baselines.exact.solids``). ``F_p <= 0`` (an inverted particle) stops the run:
:class:`InvertedBarError` names the particle. Shapes: ``F``, ``L``, ``sigma`` (n_p,).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


class InvertedBarError(ArithmeticError):
    """A particle whose stretch ``F`` lost its positive sign."""

    def __init__(self, particle: int, F: float, x: float, step: int | None = None, t: float | None = None):
        self.particle, self.F, self.x, self.step, self.t = particle, F, x, step, t
        where = "" if step is None else f"at step {step} (t={t:.6g}) "
        super().__init__(f"F = {F:.6g} <= 0 {where}in particle {particle} at x={x:.6g}; reduce the CFL number")

    def at(self, step: int, t: float) -> InvertedBarError:
        return InvertedBarError(self.particle, self.F, self.x, step, t)


@dataclass(frozen=True)
class NeoHookeanBar:
    """The neo-Hookean solid in uniaxial strain with the Lame constants ``mu``, ``lam`` (Pa)."""

    mu: float
    lam: float

    @classmethod
    def of(cls, material) -> NeoHookeanBar:
        """The bar of a material with ``mu`` and ``lam`` (``baselines.exact.solids.Material``)."""
        return cls(float(material.mu), float(material.lam))

    def stress(self, F: np.ndarray) -> np.ndarray:
        """``sigma = (mu (F^2 - 1) + lambda ln F) / F`` (n_p,); ``F > 0`` is :meth:`update`'s check."""
        return (self.mu * (F * F - 1.0) + self.lam * np.log(F)) / F

    def update(self, F: np.ndarray, L: np.ndarray, x: np.ndarray, dt: float) -> np.ndarray:
        """``F <- F + dt L F`` (n_p,); raises :class:`InvertedBarError` for the first particle
        (position ``x``) whose new ``F`` is not positive."""
        F = F + dt * (L * F)
        bad = ~(F > 0)
        if bad.any():
            p = int(np.flatnonzero(bad)[0])
            raise InvertedBarError(p, float(F[p]), float(x[p]))
        return F
