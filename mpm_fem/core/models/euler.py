"""Ideal gas on particles (slides, "Particle Methods applied to Euler Equations").

With the particle velocity gradient ``L_p = (dv/dx)_p`` over a step ``dt``:

    energy     eps_p^{n+1} = eps_p^n - (p_p^n / rho_p^n) L_p dt      (p_p includes ArtVis)
    density    rho_p^{n+1} = rho_p^n (1 - L_p dt)                  (``density_update="linear"``)
    pressure   p_p^{n+1}   = (gamma - 1) rho_p^{n+1} eps_p^{n+1} + ArtVis
    volume     V_p^{n+1}   = m_p / rho_p^{n+1}

and the momentum equation ``a = -(1/rho) dp/dx`` enters the grid through the stress ``sigma = -p``.
``ArtVis`` is the von Neumann-Richtmyer viscosity, active in compression only:

    q_p = rho_p (C_quad (l_p L_p)^2 + C_lin c_p l_p |L_p|)   if L_p < 0,   else 0,

with ``l_p`` the size of the particle's cell and ``c_p = sqrt(gamma (gamma-1) eps_p)`` the sound
speed. Positive density requires ``1 - L_p dt > 0`` (slides); a step that breaks it, or that makes
the internal energy non-positive, raises :class:`PositivityError`.

Two options of the density update, for the drift study (``studies/drift.py``; the numpy step only,
:func:`mpm_fem.core.step.numpy_only`), each off by default (the slides' update, unchanged):

- ``density_update``, the form of ``rho_p^{n+1} / rho_p^n`` from the rate ``r_p = D_p dt``:
  ``"linear"`` ``1 - r_p`` (slides), ``"inverse"`` ``1 / (1 + r_p)`` (i.e. ``V_p^{n+1} = V_p^n
  (1 + r_p)``), ``"exp"`` ``exp(-r_p)`` (the exact solution of ``d rho / dt = -rho D`` at constant ``D``);
  they agree to ``O(r_p^2)``. ``"inverse"`` needs ``1 + r_p > 0``; ``"exp"`` is positive.
- the volume rate ``D_p`` (``update``'s ``volume_rate``): the rate the density and the volume take,
  ``L_p`` unless the step supplies another one (:func:`mpm_fem.core.volume.domain_rate`); the energy
  and the viscosity keep ``L_p``.

Neither changes the motion: the force ``sum_p V_p p_p G_ip`` has ``V_p p_p = m_p ((gamma - 1) eps_p +
q_p / rho_p)``, and ``eps_p`` and ``q_p / rho_p`` do not depend on ``rho_p``; the particle density is
carried beside the motion, not fed back into it (to round-off).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mpm_fem.core.particles import Particles, check_positive

#: The forms of the density update (module docstring).
DENSITY_UPDATES = ("linear", "inverse", "exp")


@dataclass(frozen=True)
class IdealGas:
    """Ideal gas with von Neumann-Richtmyer artificial viscosity (constants ``av_linear``, ``av_quadratic``);
    ``density_update`` the form of the density update (:data:`DENSITY_UPDATES`, module docstring)."""

    gamma: float = 1.4
    av_linear: float = 0.5
    av_quadratic: float = 2.0
    density_update: str = "linear"

    stress_uses_gradient = False  # sigma = -p: the step need not gather (dv/dx)_p for the stress
    takes_volume_rate = True  # update() accepts a volume rate of its own (module docstring)

    def __post_init__(self):
        if not self.gamma > 1:
            raise ValueError(f"gamma must exceed 1, got {self.gamma}")
        if self.av_linear < 0 or self.av_quadratic < 0:
            raise ValueError("artificial viscosity constants must be non-negative")
        if self.density_update not in DENSITY_UPDATES:
            raise ValueError(f"unknown density update {self.density_update!r}; choose one of "
                             f"{', '.join(DENSITY_UPDATES)}")

    def sound_speed(self, energy: np.ndarray) -> np.ndarray:
        """``c = sqrt(gamma (gamma - 1) eps)``."""
        return np.sqrt(self.gamma * (self.gamma - 1.0) * np.maximum(energy, 0.0))

    def thermal_pressure(self, density: np.ndarray, energy: np.ndarray) -> np.ndarray:
        """``(gamma - 1) rho eps``: the pressure without the artificial viscosity."""
        return (self.gamma - 1.0) * density * energy

    def artificial_viscosity(self, density, energy, grad_v, cell_size) -> np.ndarray:
        """``q = rho (C_quad (l L)^2 + C_lin c l |L|)`` in compression (``L < 0``), else 0."""
        jump = cell_size * np.minimum(grad_v, 0.0)
        return density * (self.av_quadratic * jump**2 + self.av_linear * self.sound_speed(energy) * np.abs(jump))

    def stress(self, particles: Particles, grad_v: np.ndarray | None) -> np.ndarray:
        """``sigma_p = -p_p`` (artificial viscosity included in ``p_p``); ``grad_v`` is not used."""
        return -particles.pressure

    def update(self, particles: Particles, grad_v: np.ndarray, dt: float, cell_size: np.ndarray,
               volume_rate: np.ndarray | None = None) -> Particles:
        """The slides' energy, density and pressure updates (module docstring); the density from
        ``volume_rate`` (n_p,) when given, else from ``grad_v``, in the form ``density_update``."""
        density = self._density(particles, grad_v if volume_rate is None else volume_rate, dt)
        energy = particles.energy - particles.pressure / particles.density * grad_v * dt
        check_positive("internal energy", energy, particles.x)
        q = self.artificial_viscosity(density, energy, grad_v, cell_size)
        return particles.replace(
            density=density,
            energy=energy,
            pressure=self.thermal_pressure(density, energy) + q,
            volume=particles.mass / density,
        )

    def _density(self, particles: Particles, rate: np.ndarray, dt: float) -> np.ndarray:
        """``rho_p^{n+1}`` from ``rho_p^n`` and the rate ``D_p``, in the form ``density_update``."""
        if self.density_update == "exp":
            return particles.density * np.exp(-rate * dt)
        if self.density_update == "inverse":
            factor = 1.0 + rate * dt
            check_positive("1 + (dv/dx) dt", factor, particles.x)
            return particles.density / factor
        factor = 1.0 - rate * dt
        check_positive("1 - (dv/dx) dt", factor, particles.x)
        return particles.density * factor

    def max_speed(self, particles: Particles) -> float:
        """``max_p (c_p + |v_p|)``, the signal speed of the time step."""
        return float(np.max(self.sound_speed(particles.energy) + np.abs(particles.velocity)))

    def dt_for_speed(self, speed: float, grid, cfl: float) -> float:
        """``dt = CFL h_min / speed``."""
        return cfl * float(grid.h.min()) / speed

    def with_volume(self, particles: Particles, volume: np.ndarray) -> Particles:
        """The state at volumes ``volume``, same mass and specific energy (volume reset):
        ``rho = m / V``, ``p = (gamma - 1) rho eps + q`` with the viscosity ``q`` scaled like ``rho``."""
        density = particles.mass / volume
        check_positive("density", density, particles.x)
        q = particles.pressure - self.thermal_pressure(particles.density, particles.energy)
        return particles.replace(volume=volume, density=density,
                                 pressure=self.thermal_pressure(density, particles.energy)
                                 + q * density / particles.density)

    def stable_dt(self, particles: Particles, grid, cfl: float) -> float:
        """``dt = CFL h_min / max_p (c_p + |v_p|)``."""
        return self.dt_for_speed(self.max_speed(particles), grid, cfl)
