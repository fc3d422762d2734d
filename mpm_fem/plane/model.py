"""The compressible neo-Hookean solid of the 2D step (plane strain), per particle.

    F_p^{n+1} = (I + dt L_p) F_p^n,      L_p = sum_i v_i^{n+1/2} (x) G_ip     (the velocity gradient)
    J_p = det F_p,                        V_p = J_p V_p^0
    sigma_p = (mu (F_p F_p^T - I) + lambda ln J_p I) / J_p                   (Cauchy stress)

with the Lame constants ``mu``, ``lambda`` of the material (``Material(E, nu, rho0)`` of
``baselines.exact.solids``: any object with ``mu`` and ``lam``). ``J_p <= 0`` (an inverted
particle) stops the run: :class:`InversionError` names the step and the particle. Shapes: ``F``,
``L``, ``sigma`` (n_p, 2, 2), ``J`` (n_p,).
"""

from __future__ import annotations

import numpy as np


class InversionError(ArithmeticError):
    """A particle whose deformation gradient lost a positive determinant."""

    def __init__(self, particle: int, J: float, position, step: int | None = None, t: float | None = None):
        self.particle, self.J, self.position, self.step, self.t = particle, J, position, step, t
        where = "" if step is None else f"at step {step} (t={t:.6g}) "
        super().__init__(f"J = det F = {J:.6g} <= 0 {where}in particle {particle} at "
                         f"({position[0]:.6g}, {position[1]:.6g}); reduce the CFL number")

    def at(self, step: int, t: float) -> InversionError:
        return InversionError(self.particle, self.J, self.position, step, t)


def determinant(F: np.ndarray) -> np.ndarray:
    """``J = det F`` (n_p,) of (n_p, 2, 2) matrices."""
    return F[:, 0, 0] * F[:, 1, 1] - F[:, 0, 1] * F[:, 1, 0]


def check_orientation(J: np.ndarray, x: np.ndarray) -> None:
    """Raise :class:`InversionError` for the first particle with ``J <= 0`` (or NaN); ``x`` (n_p, 2)."""
    bad = ~(J > 0)
    if bad.any():
        p = int(np.flatnonzero(bad)[0])
        raise InversionError(p, float(J[p]), x[p])


def _product(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """``A B`` of (n_p, 2, 2) stacks, by components (faster than ``einsum`` for 2 x 2)."""
    out = np.empty_like(A)
    for a in range(2):
        for c in range(2):
            out[:, a, c] = A[:, a, 0] * B[:, 0, c] + A[:, a, 1] * B[:, 1, c]
    return out


def update_deformation(F: np.ndarray, L: np.ndarray, dt: float) -> np.ndarray:
    """``F <- (I + dt L) F`` (n_p, 2, 2)."""
    return F + dt * _product(L, F)


def neo_hookean_stress(F: np.ndarray, mu: float, lam: float) -> np.ndarray:
    """``sigma = (mu (F F^T - I) + lambda ln J I) / J`` (n_p, 2, 2); ``J > 0`` is the caller's check."""
    J = determinant(F)
    B = _product(F, np.swapaxes(F, 1, 2))
    B[:, 0, 0] -= 1.0
    B[:, 1, 1] -= 1.0
    sigma = mu * B
    log_J = lam * np.log(J)
    sigma[:, 0, 0] += log_J
    sigma[:, 1, 1] += log_J
    return sigma / J[:, None, None]
