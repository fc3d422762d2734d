"""Grid masses: each one module behind the contract :class:`~mpm_fem.masses.contract.GridMass`, read
from the registry (:func:`get`, :func:`names`).

    lumped       diag(m_i), the row sums                                 :mod:`~mpm_fem.masses.lumped`
    consistent   the particle mass matrix sum_p m_p S_ip S_jp, solved    :mod:`~mpm_fem.masses.consistent`
    grid         the grid basis's own mass rho0 int S_i S_j, fixed       :mod:`~mpm_fem.masses.grid`
    exact        the exact mass stage                                    :mod:`~mpm_fem.masses.exact`
    fmpm1..4     FMPM(k), the truncated series of the full inverse       :mod:`~mpm_fem.masses.fmpm`
"""

from mpm_fem.masses.consistent import CONSISTENT
from mpm_fem.masses.contract import GridMass, MassSystem
from mpm_fem.masses.exact import EXACT
from mpm_fem.masses.fmpm import FMPM, ORDERS
from mpm_fem.masses.grid import GRID
from mpm_fem.masses.lumped import LUMPED
from mpm_fem.masses.registry import get, names, register

for _mass in (LUMPED, CONSISTENT, EXACT, GRID, *(FMPM(k) for k in ORDERS)):
    register(_mass)

__all__ = ["FMPM", "GridMass", "MassSystem", "get", "names", "register"]
