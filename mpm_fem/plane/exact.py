"""The exact forms of the 2D stages (the equations of :mod:`mpm_fem.exact_stages.stage`), on a
manufactured solution given in reference coordinates (``baselines.exact.solids``).

The fields are Lagrangian, ``f(X, t)``; a grid node sits at a spatial position, so its exact value
is that of the material point there: ``X`` solving ``X + u(X, t) = x_i`` (:func:`reference_of`,
Newton's method with ``F``, started from the last time's solution). The symplectic Euler step's
times: the velocity at ``t - dt/2``, the acceleration and the stress at ``t``, so

    v*_i = v(X(x_i, t - dt/2), t - dt/2),     a*_i = a(X(x_i, t), t).

Projection exact: the integrals over the current body by a quadrature in the reference one,
points ``X_q`` and weights ``w_q`` (scikit-fem's Gauss rule of order ``order`` on the half cells,
or the caller's), whose points act as particles at ``x_q = X_q + u(X_q, t)``:

    m*_i = sum_q w_q rho_0 S_i(x_q),    P*_i = sum_q w_q rho_0 v(X_q, t - dt/2) S_i(x_q),
    f*_i = - sum_q w_q J_q sigma(X_q, t) grad S_i(x_q) + sum_q w_q rho_0 b(X_q, t) S_i(x_q),

with ``S_i`` the grid functions of the basis (the hats for GIMP, the B-splines for the B-spline
averaged over the particle). The integrand is smooth on each reference cell up to the kinks of
``S_i`` in the current configuration: the rule is exact to the accuracy of the Gauss rule across
those kinks (they move by ``|u|`` from the cell edges). Interpolation exact at the particles:
``v(X_p, t - dt/2)``, ``a(X_p, t)`` and the velocity gradient ``L = dF/dt F^-1`` at ``t + dt/2``
(``dF/dt`` by the central difference of step ``DT_FD`` of the period, round-off about 1e-10 of ``L``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from skfem import Basis as SkBasis
from skfem import ElementQuad1

import mpm_fem.masses as masses
from mpm_fem.bases import get
from mpm_fem.bases.contract import Basis
from mpm_fem.masses.contract import MassSystem
from mpm_fem.plane.bases import plane_shape, tensor_basis
from mpm_fem.plane.grid import PlaneGrid
from mpm_fem.plane.step import Nodal, Projected

NEWTON_STEPS = 30
CONTINUATION = 32  # time steps of the continuation that follows a node's material point when Newton fails
DT_FD = 1e-6  # the time step of the central difference of F, as a share of the period


def _vector(f, X: np.ndarray, t: float) -> np.ndarray:
    return np.ascontiguousarray(np.asarray(f(X[:, 0], X[:, 1], t), dtype=float).T)


def _newton(solution, x: np.ndarray, t: float, X: np.ndarray, tol: float) -> tuple[np.ndarray, float]:
    """Newton's method for ``X + u(X, t) = x`` from ``X``: the last iterate and its residual."""
    scale = 1.0 + np.abs(x).max()
    for _ in range(NEWTON_STEPS):
        r = X + _vector(solution.displacement, X, t) - x
        if np.abs(r).max() <= tol * scale:
            return X, 0.0
        F = np.asarray(solution.deformation_gradient(X[:, 0], X[:, 1], t), dtype=float).reshape(-1, 2, 2)
        X = X - np.linalg.solve(F, r[:, :, None])[:, :, 0]
    return X, float(np.abs(r).max())


def reference_of(solution, x: np.ndarray, t: float, guess: tuple[float, np.ndarray] | None = None,
                 tol: float = 1e-13) -> np.ndarray:
    """The reference positions ``X`` (n, 2) with ``X + u(X, t) = x`` (n, 2), by Newton's method from
    ``guess`` (a time and the positions solved there) or ``X = x``; where that fails (a large
    rotation), by continuation in time from ``guess`` (or from ``t = 0``) in ``CONTINUATION``
    steps, each starting from the last. Raises ``ArithmeticError`` if that fails too."""
    t0, X0 = guess if guess is not None else (0.0, x)
    X, residual = _newton(solution, x, t, X0.copy(), tol)
    if residual == 0.0:
        return X
    if guess is None:
        X0, residual = _newton(solution, x, 0.0, x.copy(), tol)
    for tau in np.linspace(t0, t, CONTINUATION + 1)[1:]:
        if residual > 0:
            break
        X0, residual = _newton(solution, x, tau, X0, tol)
    if residual > 0:
        raise ArithmeticError(f"the reference position of a grid node did not converge at t={t:.6g} "
                              f"(residual {residual:.3g})")
    return X0


def cell_quadrature(grid: PlaneGrid, order: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """scikit-fem's Gauss rule of ``order`` on the half cells (the mesh refined once, so that the
    quadratic B-splines' knots at the half cells are piece edges too, as in 1D): points (n_q, 2),
    weights (n_q,)."""
    sk = SkBasis(grid.mesh.refined(), ElementQuad1(), intorder=order)
    x = np.asarray(sk.global_coordinates())
    return np.column_stack((x[0].ravel(), x[1].ravel())), np.asarray(sk.dx).ravel()


@dataclass(frozen=True, eq=False)
class ExactStages2:
    """The exact stages of :func:`mpm_fem.plane.step.step` on ``solution`` with the reference
    quadrature ``points`` (n_q, 2), ``weights`` (n_q,) (module docstring)."""

    solution: object
    points: np.ndarray = field(repr=False)
    weights: np.ndarray = field(repr=False)
    _last: dict = field(default_factory=dict, compare=False, repr=False)  # the nodes' last (t, X)

    def reference_of_nodes(self, grid: PlaneGrid, t: float) -> np.ndarray:
        """:func:`reference_of` the nodes at ``t``, started from the last time solved."""
        X = reference_of(self.solution, grid.nodes, t, self._last.get(grid))
        self._last[grid] = (t, X)
        return X

    def projection(self, grid: PlaneGrid, basis: str | Basis, t: float, dt: float):
        """:class:`~mpm_fem.plane.step.Projected`: the quadrature's sums, and ``solver(kind, grid_solve)``
        giving the solve of its data by the grid mass ``kind`` (a name or a
        :class:`~mpm_fem.masses.GridMass`: lumped ``m*_i``, consistent the points' mass matrix, FMPM(k)
        its series; ``grid_solve`` the grid basis's mass for the ``grid`` mass)."""
        s, X, w = self.solution, self.points, self.weights
        functions = get(tensor_basis(basis).grid_functions)
        x = X + _vector(s.displacement, X, t)
        F = np.asarray(s.deformation_gradient(X[:, 0], X[:, 1], t), dtype=float).reshape(-1, 2, 2)
        J = F[:, 0, 0] * F[:, 1, 1] - F[:, 0, 1] * F[:, 1, 0]
        shape = plane_shape(grid, functions, x)
        mass = w * s.material.rho0
        m_i = shape.scatter(mass)
        P_i = shape.scatter(mass[:, None] * _vector(s.velocity, X, t - 0.5 * dt))
        sigma = np.asarray(s.stress(X[:, 0], X[:, 1], t), dtype=float).reshape(-1, 2, 2)
        f_i = -shape.scatter_gradient((w * J)[:, None, None] * sigma)
        f_i += shape.scatter(mass[:, None] * _vector(s.body_force, X, t))

        def solver(kind, grid_solve=None):
            return masses.get(kind).solver(MassSystem(shape.matrix(), mass, m_i, grid_solve))

        return Projected(m_i, P_i, f_i, solver)

    def nodal(self, grid: PlaneGrid, t: float, dt: float):
        """``(v*_i, a*_i)`` (n_nodes, 2) at the nodes (module docstring)."""
        s, half = self.solution, t - 0.5 * dt
        return Nodal(_vector(s.velocity, self.reference_of_nodes(grid, half), half),
                     _vector(s.acceleration, self.reference_of_nodes(grid, t), t))

    def at_particles(self, X: np.ndarray, t: float, dt: float):
        """``(v(X_p, t - dt/2), a(X_p, t), L(X_p, t + dt/2))``: (n_p, 2), (n_p, 2), (n_p, 2, 2)."""
        s = self.solution
        half = t + 0.5 * dt
        e = DT_FD * s.period
        F = lambda tau: np.asarray(s.deformation_gradient(X[:, 0], X[:, 1], tau), float).reshape(-1, 2, 2)  # noqa: E731
        rate = (F(half + e) - F(half - e)) / (2 * e)
        L = np.einsum("pab,pbc->pac", rate, np.linalg.inv(F(half)))
        return _vector(s.velocity, X, t - 0.5 * dt), _vector(s.acceleration, X, t), L
