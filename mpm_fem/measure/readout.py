"""The nodal read-out's own error on Sod: the nodal density ``m_i / int S_i dx`` of particles at their
exact positions, against the exact density at the nodes (E1's evidence; the budget's nodal norm).

In 1D a material point keeps its mass coordinate: the particle seeded at ``x_p^0`` (the study's
layout, ``m_p = rho_0(x_p^0) V_p``) is at ``T`` where the exact mass to its left is the initial one,

    M_T(x_p) = M_0(x_p^0),      M_t(x) = int_0^x rho(s, t) ds        (walls: no mass crosses x = 0),

with ``M_0`` exact (two constant states) and ``M_T`` the trapezoid rule of the exact Riemann density on
:data:`FINE` points (its error, about the wave jumps times the spacing, is far below the read-out's).
The read-out is then a particle quadrature of the exact density, ``m_i = sum_p m_p S_i(x_p)``, and its
error is the L1 over the nodes with the weights ``int S_i dx`` (the budget's nodal norm): what the
nodal error is when every stage of the step is exact and the particles sit where they should.
"""

from __future__ import annotations

import numpy as np

from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.shape import basis_integrals, make_shape
from mpm_fem.problems import sod

#: points of the trapezoid rule of the exact mass coordinate
FINE = 400_001


def exact_positions(settings: sod.SodSettings, x0: np.ndarray) -> np.ndarray:
    """The positions at ``settings.T`` (n_p,) of the material points at ``x0`` (n_p,) at ``t = 0``."""
    a, b = sod.DOMAIN
    fine = np.linspace(a, b, FINE)
    rho = sod.exact(settings, fine, settings.T)[0]
    M_T = np.concatenate([[0.0], np.cumsum(0.5 * (rho[1:] + rho[:-1]) * np.diff(fine))])
    left, right = settings.left[0], settings.right[0]
    M_0 = left * np.minimum(x0 - a, settings.x0 - a) + right * np.maximum(x0 - settings.x0, 0.0)
    return np.interp(M_0, M_T, fine)


def sod_readout(h: float, ppc: int, layout: str = "regular", seed: int = 0, basis: str = "mpm") -> float:
    """L1 over the nodes of the read-out's density error at ``T`` (module docstring) for the Sod study's
    particles (``ppc``, ``layout``, ``seed``) on the mesh ``h``."""
    settings = sod.SodSettings(h=h, ppc=ppc, layout=layout, seed=seed, basis=basis)
    grid = uniform_grid(*sod.DOMAIN, h)
    particles = sod.initial_particles(settings, grid)
    x = exact_positions(settings, particles.x)
    weights = basis_integrals(grid, basis)
    m_i = make_shape(grid, x, particles.volume, basis).scatter(particles.mass)
    error = m_i / weights - sod.exact(settings, grid.nodes, settings.T)[0]
    return float(np.sum(weights * np.abs(error)))
