"""Volume reset against the grid: the particle volumes made to tile the grid again.

The volumes carried by the flow, ``V_p^{n+1} = m_p / rho_p^{n+1}``, drift from the space the
particles fill (Sod: ``sum_p V_p - 1`` grows as ``h`` shrinks). The grid knows the space: node
``i`` owns ``int S_i dx``, and the particle domains ``chi_p = [x_p - V_p/2, x_p + V_p/2]`` claim
``V_i = sum_p int S_i chi_p = sum_p V_p Sbar_ip`` of it, with ``Sbar_ip`` the grid function averaged
over the particle domain (the basis's ``domain_twin``: GIMP for the hats, ``"bspline_gimp"`` for
the B-splines, whatever the step's basis). The reset gives each node's space back to its particles
in proportion to their claims,

    V_p <- sum_i (V_p Sbar_ip / V_i) int S_i dx = V_p f_p,     f_p = sum_i Sbar_ip (int S_i dx / V_i),

so that ``sum_p V_p = sum_i int S_i dx = |domain|`` exactly (every node touched by a particle), and
domains that tile the grid, wherever the particles sit, are left unchanged (``V_i = int S_i``,
``f_p = 1``): only overlaps and gaps are corrected. ``f_p`` is a smooth, positive factor: it moves
no discontinuity. (With point weights ``S_i(x_p)`` instead of the domain averages, ``V_i`` would
carry the projection's own quadrature noise and the reset would feed it into the density.) The masses
are untouched (mass is conserved exactly) and so are the velocities (momentum too); the model sets the
state at the new volume (gas: ``rho_p = m_p / V_p`` at the same specific energy, so the total energy is conserved too).

The volume rate over the particle domain (:func:`domain_rate`, the step's ``volume_rate="domain"``):
instead of the point quadrature ``V_p^{n+1} = V_p^n (1 + dt L_p)``, ``L_p = sum_i G_ip v_i``, the
volume takes the exact integral of the grid velocity's derivative over the particle domain,

    V_p^{n+1} = V_p^n + dt int_{chi_p} dv_h/dx dx = V_p^n + dt (v_h(x_p + V_p/2) - v_h(x_p - V_p/2)),

``v_h = sum_i v_i S_i`` with the grid functions of the step's basis: the domain's ends move with the
grid velocity there, so domains that tile the grid keep tiling it to first order in ``dt`` (the sum
over the domains telescopes to the velocities at the grid's ends). A domain end past the end of the
grid is cut there (``v_h`` taken constant beyond, the end node's velocity).
"""

from __future__ import annotations

import numpy as np

from mpm_fem.bases import get
from mpm_fem.core.grid import Grid
from mpm_fem.core.shape import Shape, basis_integrals, grid_functions, make_shape
from mpm_fem.core.transfer import divide_by_lumped

VOLUMES = ("carried", "grid")
#: The quadrature of the volume rate: at the particle point (``L_p``, the slides') or over its domain.
VOLUME_RATES = ("point", "domain")


def grid_volume_factor(grid: Grid, x: np.ndarray, volume: np.ndarray, basis: str = "mpm",
                       shape: Shape | None = None) -> np.ndarray:
    """``f_p = sum_i Sbar_ip int S_i / V_i`` with ``V_i = sum_p V_p Sbar_ip`` (n_p,), for the grid
    functions ``S_i`` of ``basis`` (module docstring). ``shape``: the step's own ``Sbar_ip`` when
    ``basis`` already averages over the particle domains at these volumes (saves computing it again)."""
    twin = get(basis).domain_twin
    if shape is None or basis != twin:
        shape = make_shape(grid, x, volume, twin)
    return shape.gather(divide_by_lumped(basis_integrals(grid, grid_functions(basis)), shape.scatter(volume)))


def domain_rate(grid: Grid, x: np.ndarray, volume: np.ndarray, v: np.ndarray, basis: str = "mpm") -> np.ndarray:
    """``D_p = (v_h(x_p + V_p/2) - v_h(x_p - V_p/2)) / V_p`` (n_p,): the grid velocity's derivative
    integrated exactly over the particle domain, per unit volume (module docstring), for the nodal
    velocities ``v`` (n_nodes,) and the grid functions of ``basis``. ``V_p (1 + dt D_p)`` is then
    ``V_p + dt int_{chi_p} dv_h/dx dx``."""
    half = 0.5 * volume
    if get(grid_functions(basis)).degree == 1:  # the hats: v_h is the piecewise linear interpolant, constant beyond
        # the ends
        return (np.interp(x + half, grid.nodes, v) - np.interp(x - half, grid.nodes, v)) / volume
    a, b = grid.nodes[0], grid.nodes[-1]
    ends = np.concatenate((np.clip(x + half, a, b), np.clip(x - half, a, b)))
    at = make_shape(grid, ends, basis=grid_functions(basis)).gather(v)
    return (at[: x.size] - at[x.size:]) / volume
