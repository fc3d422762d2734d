"""The stable time step of the 2D explicit step: the CFL limit a run is refused above.

The linearised step (the neo-Hookean tangent at ``F = I``: the Lame constants ``lambda``, ``mu``) is
the central-difference scheme ``M a = -K u`` on the grid, stable for ``dt omega_max <= 2`` with
``omega_max^2`` the largest eigenvalue of ``K u = omega^2 M u``,

    K = sum_p V_p B_p^T C B_p,       M = lumped (diag of sum_p m_p S_ip S_jp rows) or consistent,

``B_p`` the strain-displacement rows of ``G_ip`` (:func:`linearised_cfl`). In the run's CFL number
``cfl = dt c / h`` (``c = sqrt(E / rho0)``) the limit is ``2 c / (h omega_max)``. For the lumped
mass and the point-mass or GIMP basis this is the textbook ``dt <= h / c_p``, the P-wave speed
``c_p = sqrt((lambda + 2 mu) / rho0)``, on every regular layout (1 to 4 particles per cell per axis,
to round-off; 0.99 of it on a jittered one): ``cfl <= c / c_p`` (0.862 for ``nu = 0.3``). The
B-splines' limit is higher (1.7 and 1.9 times, the quadratic and the cubic), above the CFL numbers a
run takes (``<= 1``). The consistent mass's limit depends on the particles per cell (0.44 c / c_p
for the point-mass basis at 2 x 2 particles per cell; singular at 1 x 1) and is not a refusal: such
a run stops at the step where a particle inverts. The factors of ``c / c_p``: :data:`LUMPED`.

A large deformation stiffens the neo-Hookean solid: the acoustic tensor of ``sigma`` at ``F`` (with
its geometric part ``n . sigma n``) gives the fastest wave, along the largest stretch ``lambda``
(``lambda^2`` the largest eigenvalue of ``B = F F^T``),

    rho0 c_F^2 = lam + mu + mu lambda^2 - lam ln J            (c_F = c_p at F = I),

so the limit at the motion's peak stretch is the small-strain one times ``c_p / max c_F``
(:func:`stretched_cfl_limit`). The generalized vortex at ``A = 1`` reaches ``g = R alpha_R = 7.07``
(``lambda^2 = 51.9``, ``max c_F = 4.57 c = 3.94 c_p``): the lumped P1 and uGIMP limit falls from 0.862
to 0.219, below the default CFL 0.25; the B-splines' (0.370, 0.378, 0.418: the quadratic, the
particle-domain and the cubic) stay above it.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.linalg as sl
import scipy.sparse as sp

import mpm_fem.masses as masses
from mpm_fem.masses.contract import MassSystem
from mpm_fem.plane.bases import plane_shape

#: the lumped-mass CFL limit in units of ``c / c_p`` by basis (:func:`linearised_cfl`, 2 x 2 regular, h = 1/8)
LUMPED = {"mpm": 1.0, "gimp": 1.0, "bspline": 1.69, "bspline_gimp": 1.73, "cubic": 1.91}


def p_wave_ratio(material) -> float:
    """``c / c_p = sqrt(E / (lambda + 2 mu))`` of ``material`` (``E``, ``lam``, ``mu``)."""
    return math.sqrt(material.E / (material.lam + 2.0 * material.mu))


def cfl_limit(basis: str, mass: str, material) -> float | None:
    """The CFL number (``dt c / h``) above which the linearised step is unstable, where it is
    known: the lumped mass with a basis of :data:`LUMPED`; else ``None`` (module docstring)."""
    if mass != "lumped" or basis not in LUMPED:
        return None
    return LUMPED[basis] * p_wave_ratio(material)


def linearised_cfl(grid, basis: str, mass: str, material, X: np.ndarray, volume: np.ndarray,
                   lengths: np.ndarray) -> float:
    """``2 c / (h omega_max)`` of the linearised step at the reference particles ``X`` (n_p, 2) with
    volumes (n_p,) and lengths (n_p, 2) on ``grid`` (module docstring); a dense eigenproblem of
    ``2 n_nodes`` unknowns: small grids only. ``mass`` is a grid mass of :mod:`mpm_fem.masses`: the
    lumped and consistent masses as the generalised problem ``K u = omega^2 M u``, every other
    (``grid``, ``fmpm<k>``) through its solver, ``omega^2`` the largest eigenvalue of ``A K`` with ``A``
    its (symmetric, positive) inverse applied to the identity; the exact mass stage is no linear
    operator and is refused."""
    shape = plane_shape(grid, basis, X, lengths)
    n_p, k = shape.nodes.shape
    rows = np.repeat(np.arange(n_p), k)
    Gx, Gy = (sp.csr_matrix((shape.G[:, :, a].ravel(), (rows, shape.nodes.ravel())), shape=(n_p, grid.n_nodes))
              for a in range(2))
    lam, mu = material.lam, material.mu
    V = sp.diags(volume)
    xx, yy, xy, yx = (Gx.T @ V @ Gx), (Gy.T @ V @ Gy), (Gx.T @ V @ Gy), (Gy.T @ V @ Gx)
    K = sp.bmat([[(lam + 2 * mu) * xx + mu * yy, lam * xy + mu * yx],
                 [lam * yx + mu * xy, (lam + 2 * mu) * yy + mu * xx]]).toarray()
    S = shape.matrix()
    if mass not in ("lumped", "consistent"):
        return _solver_cfl(grid, basis, mass, material, shape, volume, K)
    M = (S.T @ sp.diags(material.rho0 * volume) @ S).toarray()
    if mass == "lumped":
        M = np.diag(M.sum(axis=1))
    M = sl.block_diag(M, M)
    keep = np.diag(M) > 0
    omega2 = sl.eigh(K[np.ix_(keep, keep)], M[np.ix_(keep, keep)], eigvals_only=True)[-1]
    return 2.0 * material.c / (math.sqrt(omega2) * min(grid.h))


def _solver_cfl(grid, basis: str, mass: str, material, shape, volume: np.ndarray, K: np.ndarray) -> float:
    """:func:`linearised_cfl` of a grid mass given by its solver (its docstring)."""
    from mpm_fem.plane.step import _grid_solver

    grid_mass = masses.get(mass)
    if grid_mass.stage == "exact":
        raise ValueError("the exact mass stage has no linearised step (it reads the exact solution)")
    m = material.rho0 * volume
    m_i = shape.scatter(m)
    solve = grid_mass.solver(MassSystem(shape.matrix(), m, m_i, _grid_solver(grid, basis, material.rho0)))
    inverse = solve(np.eye(grid.n_nodes))
    keep = np.tile(m_i > 0, 2)
    A = sl.block_diag(inverse, inverse)[np.ix_(keep, keep)]
    omega2 = float(np.max(np.linalg.eigvals(A @ K[np.ix_(keep, keep)]).real))
    return 2.0 * material.c / (math.sqrt(omega2) * min(grid.h))


def wave_speed(F: np.ndarray, material) -> np.ndarray:
    """``c_F = sqrt((lam + mu + mu lambda^2 - lam ln J) / rho0)`` (n,) of deformation gradients ``F``
    (n, 2, 2): the fastest wave of the stretched solid (module docstring)."""
    B = np.einsum("nij,nkj->nik", F, F)
    tr, det = B[:, 0, 0] + B[:, 1, 1], B[:, 0, 0] * B[:, 1, 1] - B[:, 0, 1] * B[:, 1, 0]
    stretch2 = 0.5 * tr + np.sqrt(np.maximum(0.25 * tr * tr - det, 0.0))
    J = F[:, 0, 0] * F[:, 1, 1] - F[:, 0, 1] * F[:, 1, 0]
    lam, mu = material.lam, material.mu
    return np.sqrt((lam + mu + mu * stretch2 - lam * np.log(J)) / material.rho0)


def peak_wave_speed(solution, X: np.ndarray, T: float, samples: int = 201) -> float:
    """The largest :func:`wave_speed` of ``solution`` at the reference points ``X`` (n, 2) over
    ``samples`` times in ``[0, T]``."""
    out = 0.0
    for t in np.linspace(0.0, T, samples):
        F = np.asarray(solution.deformation_gradient(X[:, 0], X[:, 1], t), dtype=float).reshape(-1, 2, 2)
        out = max(out, float(wave_speed(F, solution.material).max()))
    return out


def stretched_cfl_limit(basis: str, mass: str, solution, X: np.ndarray, T: float) -> float | None:
    """:func:`cfl_limit` scaled by ``c_p / max c_F`` over the motion of ``solution`` at the reference
    points ``X`` to ``T`` (module docstring); ``None`` where :func:`cfl_limit` is."""
    limit = cfl_limit(basis, mass, solution.material)
    if limit is None:
        return None
    m = solution.material
    return limit * math.sqrt((m.lam + 2.0 * m.mu) / m.rho0) / peak_wave_speed(solution, X, T)
