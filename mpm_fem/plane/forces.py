"""Compiled body forces of the 2D manufactured solutions: the numpy callable's numbers, per step in numba.

A manufactured solution's body force ``b(X_p, t)`` is evaluated at the fixed reference positions
every step. Where it separates into factors of ``X_p`` alone and scalars of ``t``, the factors are
computed once (numpy) and each step is a compiled pass over them. :func:`compiled_force` gives that
object for a solution that has one (else ``None``: its numpy ``body_force`` serves). The object is
a :data:`~mpm_fem.plane.step.BodyForce` (``b(X, Y, t) -> (2, n)``, the solution's ``body_force`` to
round-off) and has ``into(X, t, out)``, which writes ``b`` into ``out`` (n, 2) as the compiled step reads it
(:mod:`mpm_fem.plane.fused`), ``X`` (n, 2). The factors are kept for the last ``X`` seen (and
recomputed when it differs), so a run's particles pay for them once.

The axis-aligned solution (:class:`baselines.exact.solids.AxisAligned`; its docstring holds the
source): with ``s_x = sin(c pi t)``, ``s_y = sin(pi (2/3 + c t))``,

    u_x = A sin(pi X) s_x,   F_x = 1 + A pi cos(pi X) s_x   (y alike, with A_y),   K = ln(F_x F_y),
    b_x = pi^2 u_x (mu/rho0 - c^2 - (lam (K - 1) - mu) / (rho0 F_x^2)),   b_y alike,

the factors ``sin(pi X), cos(pi X), sin(pi Y), cos(pi Y)`` (n, 4).
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def _axis_force(factors, A, A_y, s_x, s_y, common, lam, mu, rho0, out):
    """The axis-aligned body force (module docstring) into ``out`` (n, 2) from ``factors`` (n, 4)."""
    pi2 = np.pi * np.pi
    for p in range(factors.shape[0]):
        Fx = 1.0 + A * np.pi * factors[p, 1] * s_x
        Fy = 1.0 + A_y * np.pi * factors[p, 3] * s_y
        stiff = (lam * (np.log(Fx * Fy) - 1.0) - mu) / rho0
        out[p, 0] = pi2 * (A * factors[p, 0] * s_x) * (common - stiff / (Fx * Fx))
        out[p, 1] = pi2 * (A_y * factors[p, 2] * s_y) * (common - stiff / (Fy * Fy))


class AxisForce:
    """The compiled body force of an ``AxisAligned`` solution (module docstring)."""

    def __init__(self, solution):
        self.solution = solution
        self._labels = None  # the reference positions (n, 2) of the factors
        self._factors = None

    def _factors_of(self, X: np.ndarray) -> np.ndarray:
        """The factors of ``X`` (n, 2): kept while ``X`` is the array last seen or equals it."""
        if X is not self._labels:
            if self._labels is None or X.shape != self._labels.shape or not np.array_equal(X, self._labels):
                self._factors = np.column_stack((np.sin(np.pi * X[:, 0]), np.cos(np.pi * X[:, 0]),
                                                 np.sin(np.pi * X[:, 1]), np.cos(np.pi * X[:, 1])))
            self._labels = X
        return self._factors

    def into(self, X: np.ndarray, t: float, out: np.ndarray) -> np.ndarray:
        """``b(X_p, t)`` into ``out`` (n, 2) at the reference positions ``X`` (n, 2); returns ``out``.
        ``X`` is the particles' labels: not changed in place between calls."""
        m = self.solution.material
        c = m.c
        s_x, s_y = np.sin(np.pi * c * t), np.sin(np.pi * (2.0 / 3.0 + c * t))
        A, A_y = self.solution.amplitudes
        _axis_force(self._factors_of(X), float(A), float(A_y), s_x, s_y, m.mu / m.rho0 - c**2, m.lam, m.mu, m.rho0,
                    out)
        return out

    def __call__(self, X, Y, t: float) -> np.ndarray:
        """``b(X, Y, t)`` (2, n), the solution's ``body_force`` to round-off."""
        XY = np.column_stack((np.asarray(X, dtype=float).ravel(), np.asarray(Y, dtype=float).ravel()))
        return self.into(XY, t, np.empty(XY.shape)).T


def compiled_force(solution):
    """The compiled body force of ``solution`` (an :class:`AxisForce` for an ``AxisAligned``), or ``None``."""
    from baselines.exact.solids import AxisAligned

    return AxisForce(solution) if isinstance(solution, AxisAligned) else None
