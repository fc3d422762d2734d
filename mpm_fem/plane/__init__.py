"""Two-dimensional MPM: a tensor grid on scikit-fem's ``MeshQuad``, the tensor products of the 1D
bases, a compressible neo-Hookean solid and the explicit USL step with its exact stages.

    grid      the tensor grid, periodic axes wrapped              :mod:`~mpm_fem.plane.grid`
    bases     S_ip = S^x S^y of a registered 1D basis             :mod:`~mpm_fem.plane.bases`
    state     the particles (frozen arrays with named fields)     :mod:`~mpm_fem.plane.state`
    model     F update, J, neo-Hookean Cauchy stress              :mod:`~mpm_fem.plane.model`
    step      the numpy reference step ``step(...)``              :mod:`~mpm_fem.plane.step`
    masses    its grid masses, read from the registry             :mod:`mpm_fem.masses`
    mass      the grid basis's own mass matrix (Q1, Gram)         :mod:`~mpm_fem.plane.mass`
    stability the CFL limits, at rest and stretched               :mod:`~mpm_fem.plane.stability`
    exact     the exact projection, mass, interpolation stages    :mod:`~mpm_fem.plane.exact`
    norms     the particle and nodal error norms                  :mod:`~mpm_fem.plane.norms`
    problems  seeding and the start of the step                   :mod:`~mpm_fem.plane.problems`
    run       the time loop, ``axis(...)``, ``vortex(...)``       :mod:`~mpm_fem.plane.run`

    >>> import mpm_fem.plane
    >>> mpm_fem.plane.axis(h=1/16, ppc=2).errors["displacement"]["particles"]["L2"]
"""

from mpm_fem.plane.run import PlaneSettings, Run, axis, run, vortex
from mpm_fem.plane.step import step

__all__ = ["PlaneSettings", "Run", "axis", "run", "step", "vortex"]
