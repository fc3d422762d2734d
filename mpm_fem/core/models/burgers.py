"""Viscous Burgers on particles (slides, "Burgers' Problem").

``v_t + v v_x = eps v_xx`` in Lagrangian form is ``Dv/Dt = eps v_xx``: the convective term is
carried by the particle motion, and the grid carries the viscous acceleration. As a stress,
``sigma_p = eps (dv/dx)_p`` with unit density (``m_p = V_p``), so that the MPM internal force is

    F_i = - sum_p V_p eps (dv/dx)_p G_ip,      a_i = F_i / m_i.

With ``N_p`` particles per cell at regular positions and ``m_i = h`` this is the slides'

    a_i = -eps (v_i - v_{i-1}) / h^2 + eps (v_{i+1} - v_i) / h^2

(the slides write the counts ``sum_{p in I_i} 1 / N_p^i``, equal to one in every non-empty cell).
``force="slides"`` takes that second difference as the nodal acceleration itself, with the counts:

    a_i = eps [ (v_{i+1} - v_i) [N_p^{i+1} > 0] - (v_i - v_{i-1}) [N_p^i > 0] ] / h^2.

The particle volume, the quadrature weight, follows the motion: ``V_p^{n+1} = V_p^n (1 + L_p dt)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mpm_fem.core.particles import Particles, check_positive

FORCES = ("weak", "slides")


@dataclass(frozen=True)
class ViscousBurgers:
    """Burgers' viscous stress with coefficient ``eps`` > 0; ``viscous_limit=False`` drops the
    explicit-diffusion limit from the time step (for the exact acceleration, which computes no
    viscous force)."""

    eps: float
    viscous_limit: bool = True
    force: str = "weak"

    stress_uses_gradient = True

    def __post_init__(self):
        if not (np.isfinite(self.eps) and self.eps > 0):
            raise ValueError(f"the viscosity eps must be positive, got {self.eps}")
        if self.force not in FORCES:
            raise ValueError(f"unknown force {self.force!r}; choose one of {', '.join(FORCES)}")

    def grid_acceleration(self, grid, cell: np.ndarray, v_i: np.ndarray) -> np.ndarray:
        """The slides' nodal acceleration (``force="slides"``, module docstring) on a uniform grid;
        ``cell`` (n_p,) holds each particle's cell, which gives the occupied cells."""
        h = float(grid.h.mean())
        occupied = np.bincount(cell, minlength=grid.n_cells) > 0
        flux = np.where(occupied, v_i[1:] - v_i[:-1], 0.0)  # (v_{i+1} - v_i) [N_{i+1} > 0]
        a_i = np.zeros(grid.n_nodes)
        a_i[:-1] += flux
        a_i[1:] -= flux
        a_i *= self.eps / (h * h)
        return a_i

    def stress(self, particles: Particles, grad_v: np.ndarray) -> np.ndarray:
        """``sigma_p = eps (dv/dx)_p``."""
        return self.eps * grad_v

    def update(self, particles: Particles, grad_v: np.ndarray, dt: float, cell_size: np.ndarray) -> Particles:
        """``V_p <- V_p (1 + L_p dt)``, ``m_p = V_p`` (unit density)."""
        factor = 1.0 + grad_v * dt
        check_positive("1 + (dv/dx) dt", factor, particles.x)
        volume = particles.volume * factor
        return particles.replace(volume=volume, mass=volume.copy())

    def max_speed(self, particles: Particles) -> float:
        """``max_p |v_p|``, the advective speed of the time step."""
        return float(np.max(np.abs(particles.velocity), initial=0.0))

    def with_volume(self, particles: Particles, volume: np.ndarray) -> Particles:
        """The quadrature weights ``V_p = volume`` (unit density: ``m_p = V_p`` with them)."""
        check_positive("volume", volume, particles.x)
        return particles.replace(volume=volume, mass=volume.copy())

    def stable_dt(self, particles: Particles, grid, cfl: float) -> float:
        """``dt = CFL min(h / max|v|, h^2 / (2 eps))``: advective and explicit-diffusion limits
        (the advective one alone without ``viscous_limit``)."""
        return self.dt_for_speed(self.max_speed(particles), grid, cfl)

    def dt_for_speed(self, vmax: float, grid, cfl: float) -> float:
        """:meth:`stable_dt` for the maximum speed ``vmax``."""
        h = float(grid.h.min())
        advective = h / vmax if vmax > 0 else np.inf
        if not self.viscous_limit:
            return cfl * advective
        return cfl * min(advective, h * h / (2.0 * self.eps))
