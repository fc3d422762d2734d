"""The 2D problems: particles seeded in the reference configuration of a manufactured solution.

Seeding (the 1D layouts of :func:`mpm_fem.core.particles.seed_positions`, per axis): ``n x n``
particles in every grid cell, ``regular`` at the midpoints of ``n x n`` equal sub-cells,
``jittered`` each moved uniformly within ``+- jitter/2`` of its sub-cell along each axis (seeded:
``numpy.random.default_rng(seed)``). Every particle gets the reference volume ``V_p^0 = h_x h_y /
n^2``, the mass ``rho_0 V_p^0`` and the domain lengths ``(h_x/n, h_y/n)``. A body that does not fill
the grid (the vortex's annulus) keeps the particles whose reference position it contains.

The start of the symplectic Euler step (:mod:`mpm_fem.plane.step`): ``x_p = X_p + u(X_p, 0)``,
``F_p = F(X_p, 0)``, ``V_p = det(F_p) V_p^0`` and the velocity at the half step before,
``v_p = v(X_p, -dt/2)``.
"""

from __future__ import annotations

import numpy as np

from mpm_fem.plane.grid import PlaneGrid
from mpm_fem.plane.model import check_orientation, determinant
from mpm_fem.plane.state import PlaneParticles

LAYOUTS = ("regular", "jittered")


def seed_reference(grid: PlaneGrid, ppc: int, layout: str = "regular", seed: int | None = 0,
                   jitter: float = 1.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Reference positions ``X`` (n_p, 2), volumes ``V^0`` (n_p,) and lengths (n_p, 2) of ``ppc x ppc``
    particles in every cell of ``grid`` (module docstring), cell by cell."""
    if isinstance(ppc, bool) or not isinstance(ppc, (int, np.integer)) or ppc < 1:
        raise ValueError(f"particles per cell per axis must be an integer >= 1, got {ppc!r}")
    if layout not in LAYOUTS:
        raise ValueError(f"unknown particle layout {layout!r}; choose one of {', '.join(LAYOUTS)}")
    if not 0 <= jitter <= 1:
        raise ValueError(f"jitter must lie in [0, 1], got {jitter}")
    (hx, hy) = grid.h
    left = [np.linspace(a.lo, a.hi, round(a.length / a.h) + 1)[:-1] for a in grid.axes]
    nx, ny = left[0].size, left[1].size
    local = (np.arange(ppc) + 0.5) / ppc
    # (cell x, cell y, sub x, sub y) -> positions
    xi = np.broadcast_to(local[None, None, :, None], (nx, ny, ppc, ppc)).copy()
    eta = np.broadcast_to(local[None, None, None, :], (nx, ny, ppc, ppc)).copy()
    if layout == "jittered":
        rng = np.random.default_rng(seed)
        xi += jitter * (rng.random(xi.shape) - 0.5) / ppc
        eta += jitter * (rng.random(eta.shape) - 0.5) / ppc
    X = left[0][:, None, None, None] + hx * xi
    Y = left[1][None, :, None, None] + hy * eta
    positions = np.column_stack((X.ravel(), Y.ravel()))
    n = positions.shape[0]
    return positions, np.full(n, hx * hy / ppc**2), np.tile([hx / ppc, hy / ppc], (n, 1))


def start(solution, X: np.ndarray, volume0: np.ndarray, lengths: np.ndarray, dt: float) -> PlaneParticles:
    """The particles at ``t = 0`` with the velocity at ``-dt/2`` (module docstring)."""
    rho0 = solution.material.rho0
    u = np.asarray(solution.displacement(X[:, 0], X[:, 1], 0.0)).T
    F = np.asarray(solution.deformation_gradient(X[:, 0], X[:, 1], 0.0), dtype=float).reshape(-1, 2, 2)
    J = determinant(F)
    check_orientation(J, X + u)
    v = np.asarray(solution.velocity(X[:, 0], X[:, 1], -0.5 * dt)).T
    return PlaneParticles(X=X.copy(), x=X + u, v=np.ascontiguousarray(v), F=F.copy(), volume=J * volume0,
                          volume0=volume0.copy(), mass=rho0 * volume0, lengths=lengths.copy())


def inside(solution, X: np.ndarray) -> np.ndarray:
    """The mask of the reference positions ``X`` (n_p, 2) in the body (all of them where the
    solution has no ``contains``)."""
    contains = getattr(solution, "contains", None)
    return np.ones(X.shape[0], bool) if contains is None else np.asarray(contains(X[:, 0], X[:, 1]), bool)
