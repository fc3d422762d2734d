"""What a problem's exact solution hands the exact stages: the protocol :class:`ExactFields`.

At one time ``t`` and points ``x`` (any shape; every returned array has the shape of ``x``):

    integrand(x, t)          (rho, v, sigma)    point values, integrated against the grid functions
                                                by the exact projection and the FE mass
    breakpoints(t)           (n_b,)             where the integrand may jump or kink; the quadrature
                                                splits its pieces there (any order; those outside
                                                the domain are ignored)
    reference(x, t)          (v*, v*_x, a*)     the reference fields that nodal and particle values
                                                approximate, ``a* = Dv*/Dt = dv*/dt + v* v*_x``
    velocity_gradient(x, t)  v*_x               the second entry of ``reference`` alone

The projection and the FE mass are exact to round-off where ``integrand`` is a polynomial between
the breakpoints of no higher degree than the quadrature integrates exactly
(:mod:`mpm_fem.exact_stages.quadrature`); a smooth non-polynomial solution (Burgers) leaves the
rule's own error. A smooth solution gives point values as the reference (``v* = v``). Across a shock
``v_x`` and ``Dv/Dt`` are Dirac masses, so a problem with shocks gives finite averages that equal
``v`` to ``O(l^2)`` where it is smooth (Sod: :class:`mpm_fem.problems.sod.RiemannFields`).

The problems implement the protocol beside their set-ups (:mod:`mpm_fem.problems`); this package
never imports them (the problems import it).
"""

from __future__ import annotations

from typing import Protocol

import numpy as np


class ExactFields(Protocol):
    """The exact solution as the exact stages need it (all arrays have the shape of ``x``)."""

    def integrand(self, x: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Point values ``(rho, v, sigma)`` integrated by the exact projection."""
        ...

    def breakpoints(self, t: float) -> np.ndarray:
        """Where the integrand may jump or kink at time ``t`` (quadrature splits there)."""
        ...

    def reference(self, x: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Reference fields ``(v*, v*_x, a*)`` at ``x``: what nodal and particle values approximate."""
        ...

    def velocity_gradient(self, x: np.ndarray, t: float) -> np.ndarray:
        """``v*_x`` alone (the second entry of :meth:`reference`)."""
        ...
