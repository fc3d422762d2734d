"""Manufactured solutions for a compressible neo-Hookean solid in plane strain, with closed-form body forces.

The model. With the deformation gradient ``F = I + Grad u`` (``u`` the displacement, ``Grad``
with respect to the reference coordinates ``X = (X, Y)``) and ``J = det F``,

    sigma = (mu (F F^T - I) + lam ln J I) / J                  (Cauchy stress)
    P     = J sigma F^-T = mu (F - F^-T) + lam ln J F^-T       (first Piola-Kirchhoff stress)

and the momentum balance in the reference configuration

    rho0 a = Div P + rho0 b,       so   b = a - Div P / rho0   (body force per unit mass),

with ``a = d^2 u / dt^2`` at fixed ``X``. The Lame constants are ``lam = E nu / ((1 + nu)(1 - 2 nu))``
and ``mu = E / (2 (1 + nu))``; the wave speed the solutions are scaled by is ``c = sqrt(E / rho0)``.
A manufactured solution prescribes ``u``; ``b`` is whatever body force makes it exact.

The solutions (each a frozen dataclass; their docstrings give the formulas and the sources):

* :class:`AxisAligned`: each displacement component a standing wave along its own axis, on the
  periodic square ``[0, 2)^2`` (Wallstedt & Guilkey 2008).
* :class:`GeneralizedVortex`: an annulus whose rings rotate by an angle that depends on the radius,
  traction-free on both circles (Kamojjala, Brannon, Sadeghirad & Guilkey 2015).
* :class:`AxisAligned1D`: the x part of the axis-aligned solution as a bar in uniaxial strain, the
  1D control (``P = mu (F - 1/F) + lam ln F / F``).

Shapes. The methods take reference coordinates ``X, Y`` (arrays of one shape, ``(n,)`` in the
usual case) and a time ``t`` (a float); a vector field is returned as ``(2, n)`` (component first),
a tensor field (``F``, the stresses) as ``(n, 2, 2)`` with ``[..., i, J]`` the row ``i`` (current
frame), column ``J`` (reference frame).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

__all__ = [
    "Material",
    "AxisAligned",
    "GeneralizedVortex",
    "AxisAligned1D",
    "first_piola",
    "cauchy_stress",
]


@dataclass(frozen=True)
class Material:
    """A compressible neo-Hookean material: Young's modulus ``E``, Poisson's ratio ``nu``, reference
    density ``rho0``. ``mu``, ``lam`` are the Lame constants (the plane-strain formulas of the module
    docstring), ``c = sqrt(E / rho0)`` the speed the manufactured solutions use."""

    E: float
    nu: float
    rho0: float

    def __post_init__(self):
        if not (np.isfinite(self.E) and self.E > 0):
            raise ValueError(f"Material: Young's modulus must satisfy E > 0, got E = {self.E}")
        if not (-1.0 < self.nu < 0.5):
            raise ValueError(f"Material: Poisson's ratio must satisfy -1 < nu < 0.5, got nu = {self.nu}")
        if not (np.isfinite(self.rho0) and self.rho0 > 0):
            raise ValueError(f"Material: the density must satisfy rho0 > 0, got rho0 = {self.rho0}")

    @property
    def mu(self) -> float:
        return self.E / (2.0 * (1.0 + self.nu))

    @property
    def lam(self) -> float:
        return self.E * self.nu / ((1.0 + self.nu) * (1.0 - 2.0 * self.nu))

    @property
    def c(self) -> float:
        return float(np.sqrt(self.E / self.rho0))


def _check_jacobian(J):
    if not np.all(J > 0):
        raise ValueError(f"neo-Hookean stress: det F must be > 0, got min det F = {np.min(J):.6g}")


def first_piola(F: np.ndarray, material: Material) -> np.ndarray:
    """``P = mu (F - F^-T) + lam ln J F^-T`` for ``F`` of shape ``(..., 2, 2)``; same shape.

    Raises ValueError where ``det F <= 0``."""
    F = np.asarray(F, dtype=float)
    J = F[..., 0, 0] * F[..., 1, 1] - F[..., 0, 1] * F[..., 1, 0]
    _check_jacobian(J)
    # F^-T of a 2x2 matrix: the cofactor matrix over J.
    F_inv_T = np.stack(
        [np.stack([F[..., 1, 1], -F[..., 1, 0]], -1), np.stack([-F[..., 0, 1], F[..., 0, 0]], -1)], -2
    ) / J[..., None, None]
    return material.mu * (F - F_inv_T) + (material.lam * np.log(J))[..., None, None] * F_inv_T


def cauchy_stress(F: np.ndarray, material: Material) -> np.ndarray:
    """``sigma = (mu (F F^T - I) + lam ln J I) / J`` for ``F`` of shape ``(..., 2, 2)``; same shape.

    Raises ValueError where ``det F <= 0``."""
    F = np.asarray(F, dtype=float)
    J = F[..., 0, 0] * F[..., 1, 1] - F[..., 0, 1] * F[..., 1, 0]
    _check_jacobian(J)
    eye = np.eye(2)
    FFt = np.einsum("...ik,...jk->...ij", F, F)
    return (material.mu * (FFt - eye) + (material.lam * np.log(J))[..., None, None] * eye) / J[..., None, None]


def _coordinates(X, Y):
    X, Y = np.broadcast_arrays(np.asarray(X, dtype=float), np.asarray(Y, dtype=float))
    return X, Y


def _diagonal(Fx, Fy):
    """``(..., 2, 2)`` diagonal tensors with diagonal ``(Fx, Fy)``."""
    F = np.zeros(Fx.shape + (2, 2))
    F[..., 0, 0] = Fx
    F[..., 1, 1] = Fy
    return F


@dataclass(frozen=True)
class AxisAligned:
    """The axis-aligned manufactured solution on the periodic square ``[0, 2)^2``:

        u = A sin(pi X) sin(c pi t),     v = A sin(pi Y) sin(pi (2/3 + c t)),     c = sqrt(E / rho0),

    period ``T = 2 / c``. ``F = diag(F_x, F_y)`` with ``F_x = 1 + A pi cos(pi X) sin(c pi t)``,
    ``F_y = 1 + A pi cos(pi Y) sin(pi (2/3 + c t))``, so ``P`` is diagonal too, its ``xx`` entry
    depending on ``Y`` only through ``ln J``; with ``K = ln(F_x F_y)``,

        b_x = pi^2 u (mu / rho0 - c^2 - (lam (K - 1) - mu) / (rho0 F_x^2)),
        b_y = pi^2 v (mu / rho0 - c^2 - (lam (K - 1) - mu) / (rho0 F_y^2)).

    Source: Wallstedt & Guilkey, J. Comput. Phys. 227 (2008) 9628, section on the axis-aligned
    displacement; the same body force (in 3D, with a third component) is Uintah's manufactured-solution
    code ``MMS::computeExternalForceForMMS``, case ``AxisAligned`` (E = 1e4, nu = 0.3, rho0 = 1,
    the defaults here). ``A pi < 1`` keeps ``J > 0``.

    ``amplitude_y`` is the amplitude ``A_y`` of the y part (``v = A_y sin(pi Y) ...``; ``None``: equal
    to ``amplitude``); ``A_y = 0`` turns the y part off (the x part is then the 1D bar of
    :class:`AxisAligned1D`). Every formula above holds with ``A_y`` in the y components, ``A_y pi < 1``.
    The velocity gradient is ``L = dF/dt F^-1 = diag(dF_x/dt / F_x, dF_y/dt / F_y)``.
    """

    amplitude: float = 1e-4
    material: Material = Material(1e4, 0.3, 1.0)
    amplitude_y: float | None = None

    domain: ClassVar[tuple[tuple[float, float], tuple[float, float]]] = ((0.0, 2.0), (0.0, 2.0))
    periodic: ClassVar[bool] = True

    def __post_init__(self):
        if not (np.isfinite(self.amplitude) and 0.0 <= self.amplitude * np.pi < 1.0):
            raise ValueError(f"AxisAligned: the amplitude must satisfy 0 <= A pi < 1 (det F > 0), "
                             f"got A = {self.amplitude}")
        if self.amplitude_y is not None and not (np.isfinite(self.amplitude_y)
                                                 and 0.0 <= self.amplitude_y * np.pi < 1.0):
            raise ValueError(f"AxisAligned: the y amplitude must satisfy 0 <= A_y pi < 1 (det F > 0), "
                             f"got A_y = {self.amplitude_y}")

    @property
    def amplitudes(self) -> tuple[float, float]:
        """``(A, A_y)``: the amplitudes of the x and the y part."""
        return self.amplitude, self.amplitude if self.amplitude_y is None else self.amplitude_y

    @property
    def period(self) -> float:
        return 2.0 / self.material.c

    def _phases(self, t):
        c = self.material.c
        return np.pi * c * t, np.pi * (2.0 / 3.0 + c * t)

    def displacement(self, X, Y, t):
        X, Y = _coordinates(X, Y)
        px, py = self._phases(t)
        A, A_y = self.amplitudes
        return np.stack([A * np.sin(np.pi * X) * np.sin(px), A_y * np.sin(np.pi * Y) * np.sin(py)])

    def velocity(self, X, Y, t):
        X, Y = _coordinates(X, Y)
        px, py = self._phases(t)
        w = np.pi * self.material.c
        A, A_y = self.amplitudes
        return np.stack([w * A * np.sin(np.pi * X) * np.cos(px), w * A_y * np.sin(np.pi * Y) * np.cos(py)])

    def acceleration(self, X, Y, t):
        return -((np.pi * self.material.c) ** 2) * self.displacement(X, Y, t)

    def _stretches(self, X, Y, t):
        px, py = self._phases(t)
        A, A_y = self.amplitudes
        return 1.0 + A * np.pi * np.cos(np.pi * X) * np.sin(px), 1.0 + A_y * np.pi * np.cos(np.pi * Y) * np.sin(py)

    def deformation_gradient(self, X, Y, t):
        X, Y = _coordinates(X, Y)
        return _diagonal(*self._stretches(X, Y, t))

    def velocity_gradient(self, X, Y, t):
        """``L = dF/dt F^-1`` ``(n, 2, 2)``, diagonal (class docstring)."""
        X, Y = _coordinates(X, Y)
        px, py = self._phases(t)
        A, A_y = self.amplitudes
        w = np.pi * np.pi * self.material.c
        Fx, Fy = self._stretches(X, Y, t)
        return _diagonal(w * A * np.cos(np.pi * X) * np.cos(px) / Fx, w * A_y * np.cos(np.pi * Y) * np.cos(py) / Fy)

    def first_piola(self, X, Y, t):
        return first_piola(self.deformation_gradient(X, Y, t), self.material)

    def stress(self, X, Y, t):
        """Cauchy stress ``(n, 2, 2)``."""
        return cauchy_stress(self.deformation_gradient(X, Y, t), self.material)

    def body_force(self, X, Y, t):
        X, Y = _coordinates(X, Y)
        m = self.material
        Fx, Fy = self._stretches(X, Y, t)
        K = np.log(Fx * Fy)
        u = self.displacement(X, Y, t)
        common = m.mu / m.rho0 - m.c**2
        stiff = (m.lam * (K - 1.0) - m.mu) / m.rho0
        return np.pi**2 * u * np.stack([common - stiff / Fx**2, common - stiff / Fy**2])


@dataclass(frozen=True)
class GeneralizedVortex:
    """The generalized vortex: the annulus ``inner <= R <= outer`` about ``centre`` turns ring by ring,

        x = centre + R (cos(Theta + alpha), sin(Theta + alpha)),     alpha(R, t) = A sin(c pi t) h(R),
        h(R) = (1 - s^2)^2,  s = (R - R_m) / w,  R_m = (inner + outer) / 2,  w = (outer - inner) / 2,

    with ``(R, Theta)`` the reference polar coordinates about ``centre`` and ``c = sqrt(E / rho0)``.
    With Uintah's parameters (inner 0.75, outer 1.25: ``h = 1 - 32 (R-1)^2 + 256 (R-1)^4``; E = 1000,
    nu = 0.3, rho0 = 1000, so ``c = 1``; A = 1; centre (0, 0)) this is the solution of the sources.
    ``alpha`` has period ``2 / c`` (2 here); Uintah's input runs to t = 1, half a period, when the
    displacement is back to zero and the velocity reversed.

    In the frames ``(e_r, e_theta)`` at the current angle ``beta = Theta + alpha`` and
    ``(E_R, E_Theta)`` at ``Theta``, with ``g = R alpha_R``, ``F = [[1, 0], [g, 1]]``: ``J = 1``
    (the motion is isochoric, the ``lam`` term vanishes), the velocity gradient is
    ``L = dF/dt F^-1 = alpha_t W + R alpha_Rt e_theta (x) e_r`` (``W = [[0, -1], [1, 0]]``, the spin of
    the ring; ``alpha_Rt = A c pi cos(c pi t) h_R``; ``(E_Theta (x) E_R)^2 = 0`` makes the inverse
    of the shear ``I - g E_Theta (x) E_R``) and

        P = mu g (e_r (x) E_Theta + e_theta (x) E_R),     sigma = mu [[0, g], [g, g^2]],
        Div P = mu (-R alpha_R^2 e_r + (3 alpha_R + R alpha_RR) e_theta),
        a = -R alpha_t^2 e_r + R alpha_tt e_theta,
        b = (-R alpha_t^2 + (mu/rho0) R alpha_R^2) e_r + (R alpha_tt - (mu/rho0)(3 alpha_R + R alpha_RR)) e_theta.

    ``h = h' = 0`` at ``R = inner`` and ``R = outer``, so both circles are traction-free
    (``P E_R = mu g e_theta = 0``) and at rest. Outside the annulus (no material) every field is 0;
    the body force jumps there (``alpha_RR != 0``).

    Source: Kamojjala, Brannon, Sadeghirad & Guilkey, Eng. Comput. 31 (2015) 193 ("Verification
    tests in solid mechanics"), the generalized vortex; the same formulas (body force per unit mass,
    centre (0, 0), ``sin(c pi t)``) in Uintah's manufactured-solution code
    ``MMS::computeExternalForceForMMS``, case ``GeneralizedVortex``.
    """

    amplitude: float = 1.0
    material: Material = Material(1000.0, 0.3, 1000.0)
    inner: float = 0.75
    outer: float = 1.25
    centre: tuple[float, float] = (0.0, 0.0)

    periodic: ClassVar[bool] = False

    def __post_init__(self):
        if not (np.isfinite(self.amplitude) and np.isfinite(self.inner) and 0.0 < self.inner < self.outer):
            raise ValueError(f"GeneralizedVortex: need 0 < inner < outer and a finite amplitude, got inner = "
                             f"{self.inner}, outer = {self.outer}, A = {self.amplitude}")

    @property
    def period(self) -> float:
        return 2.0 / self.material.c

    @property
    def domain(self):
        """The square that holds the annulus."""
        (x0, y0), r = self.centre, self.outer
        return ((x0 - r, x0 + r), (y0 - r, y0 + r))

    def contains(self, X, Y):
        """``inner <= R <= outer`` to round-off (bool, the shape of ``X``)."""
        R, _ = self._polar(*_coordinates(X, Y))
        return self._inside(R)

    def _polar(self, X, Y):
        dX, dY = X - self.centre[0], Y - self.centre[1]
        return np.hypot(dX, dY), np.arctan2(dY, dX)

    def _profile(self, R):
        """``h, h_R, h_RR`` at ``R``."""
        w = 0.5 * (self.outer - self.inner)
        s = (R - 0.5 * (self.inner + self.outer)) / w
        return (1.0 - s * s) ** 2, -4.0 * s * (1.0 - s * s) / w, (12.0 * s * s - 4.0) / w**2

    def _fields(self, X, Y, t):
        """``dX, dY`` (the reference position about the centre), ``R``, ``alpha`` and its derivatives
        ``(alpha_R, alpha_RR, alpha_t, alpha_tt)`` at the reference points, each 0 outside the annulus."""
        X, Y = _coordinates(X, Y)
        dX, dY = X - self.centre[0], Y - self.centre[1]
        R = np.hypot(dX, dY)
        h, h_R, h_RR = (np.where(self._inside(R), q, 0.0) for q in self._profile(R))
        omega = np.pi * self.material.c
        A = self.amplitude
        s, co = np.sin(omega * t), np.cos(omega * t)
        alpha = A * s * h
        return dX, dY, R, alpha, (A * s * h_R, A * s * h_RR, A * omega * co * h, -(omega**2) * alpha)

    def _inside(self, R):
        # Closed annulus, widened by round-off so that points (R cos theta, R sin theta) on a circle count.
        return (R >= self.inner * (1.0 - 1e-12)) & (R <= self.outer * (1.0 + 1e-12))

    @staticmethod
    def _polar_to_cartesian(radial, tangential, dX, dY, R, alpha):
        """``radial e_r(beta) + tangential e_theta(beta)`` with ``e_r(beta) = Rot(alpha) (dX, dY) / R``."""
        ca, sa = np.cos(alpha), np.sin(alpha)
        with np.errstate(invalid="ignore", divide="ignore"):
            er = np.where(R > 0, (ca * dX - sa * dY) / R, 1.0), np.where(R > 0, (sa * dX + ca * dY) / R, 0.0)
        return np.stack([radial * er[0] - tangential * er[1], radial * er[1] + tangential * er[0]])

    def displacement(self, X, Y, t):
        """``u = (Rot(alpha) - I) (X - centre)``."""
        dX, dY, _, alpha, _ = self._fields(X, Y, t)
        cm1, sa = -2.0 * np.sin(0.5 * alpha) ** 2, np.sin(alpha)  # cos(alpha) - 1 without cancellation
        return np.stack([cm1 * dX - sa * dY, sa * dX + cm1 * dY])

    def velocity(self, X, Y, t):
        dX, dY, R, alpha, (_, _, a_t, _) = self._fields(X, Y, t)
        return self._polar_to_cartesian(np.zeros_like(R), R * a_t, dX, dY, R, alpha)

    def acceleration(self, X, Y, t):
        dX, dY, R, alpha, (_, _, a_t, a_tt) = self._fields(X, Y, t)
        return self._polar_to_cartesian(-R * a_t**2, R * a_tt, dX, dY, R, alpha)

    def deformation_gradient(self, X, Y, t):
        """``F = Rot(alpha) (I + g E_Theta (x) E_R)``, ``g = R alpha_R``; ``I`` outside the annulus."""
        dX, dY, R, alpha, (a_R, _, _, _) = self._fields(X, Y, t)
        ca, sa = np.cos(alpha), np.sin(alpha)
        # g E_Theta (x) E_R = a_R (-dY, dX) (x) (dX, dY) / R: no division by R.
        with np.errstate(invalid="ignore", divide="ignore"):
            k = np.where(R > 0, a_R / R, 0.0)
        shear = np.stack([np.stack([-k * dY * dX, -k * dY * dY], -1), np.stack([k * dX * dX, k * dX * dY], -1)], -2)
        G = np.eye(2) + shear
        rot = np.stack([np.stack([ca, -sa], -1), np.stack([sa, ca], -1)], -2)
        return np.einsum("...ik,...kj->...ij", rot, G)

    def velocity_gradient(self, X, Y, t):
        """``L = dF/dt F^-1 = alpha_t W + R alpha_Rt e_theta (x) e_r`` ``(n, 2, 2)`` (class docstring); 0
        outside the annulus."""
        dX, dY, R, alpha, (_, _, a_t, _) = self._fields(X, Y, t)
        omega = np.pi * self.material.c
        h_R = np.where(self._inside(R), self._profile(R)[1], 0.0)
        # R alpha_Rt e_theta (x) e_r = k (W r) (x) r with r = Rot(alpha) (dX, dY), k = alpha_Rt / R
        with np.errstate(invalid="ignore", divide="ignore"):
            k = np.where(R > 0, self.amplitude * omega * np.cos(omega * t) * h_R / R, 0.0)
        ca, sa = np.cos(alpha), np.sin(alpha)
        rx, ry = ca * dX - sa * dY, sa * dX + ca * dY
        return np.stack([np.stack([-k * ry * rx, -k * ry * ry - a_t], -1),
                         np.stack([k * rx * rx + a_t, k * rx * ry], -1)], -2)

    def first_piola(self, X, Y, t):
        return first_piola(self.deformation_gradient(X, Y, t), self.material)

    def stress(self, X, Y, t):
        """Cauchy stress ``(n, 2, 2)``."""
        return cauchy_stress(self.deformation_gradient(X, Y, t), self.material)

    def body_force(self, X, Y, t):
        dX, dY, R, alpha, (a_R, a_RR, a_t, a_tt) = self._fields(X, Y, t)
        k = self.material.mu / self.material.rho0
        radial, tangential = -R * a_t**2 + k * R * a_R**2, R * a_tt - k * (3.0 * a_R + R * a_RR)
        return self._polar_to_cartesian(radial, tangential, dX, dY, R, alpha)


@dataclass(frozen=True)
class AxisAligned1D:
    """The x part of :class:`AxisAligned` as a bar in uniaxial strain on the periodic ``[0, 2)``:

        u = A sin(pi X) sin(c pi t),    F = 1 + A pi cos(pi X) sin(c pi t),
        P = mu (F - 1/F) + lam ln F / F,
        b = a - P_X / rho0 = pi^2 u (mu / rho0 - c^2 - (lam (ln F - 1) - mu) / (rho0 F^2)),

    ``c = sqrt(E / rho0)``, period ``2 / c``: :class:`AxisAligned`'s ``b_x`` with ``F_y = 1``. The
    methods take ``X`` (any shape) and ``t`` and return arrays of the shape of ``X``.
    """

    amplitude: float = 1e-4
    material: Material = Material(1e4, 0.3, 1.0)

    domain: ClassVar[tuple[float, float]] = (0.0, 2.0)
    periodic: ClassVar[bool] = True

    def __post_init__(self):
        if not (np.isfinite(self.amplitude) and 0.0 <= self.amplitude * np.pi < 1.0):
            raise ValueError(f"AxisAligned1D: the amplitude must satisfy 0 <= A pi < 1 (F > 0), "
                             f"got A = {self.amplitude}")

    @property
    def period(self) -> float:
        return 2.0 / self.material.c

    def displacement(self, X, t):
        return self.amplitude * np.sin(np.pi * np.asarray(X, dtype=float)) * np.sin(np.pi * self.material.c * t)

    def velocity(self, X, t):
        c = self.material.c
        return self.amplitude * np.pi * c * np.sin(np.pi * np.asarray(X, dtype=float)) * np.cos(np.pi * c * t)

    def acceleration(self, X, t):
        return -((np.pi * self.material.c) ** 2) * self.displacement(X, t)

    def deformation_gradient(self, X, t):
        return 1.0 + self.amplitude * np.pi * np.cos(np.pi * np.asarray(X, dtype=float)) * np.sin(
            np.pi * self.material.c * t
        )

    def first_piola(self, X, t):
        F = self.deformation_gradient(X, t)
        m = self.material
        return m.mu * (F - 1.0 / F) + m.lam * np.log(F) / F

    def stress(self, X, t):
        """Cauchy stress ``sigma = P / J * F = P`` in uniaxial strain (``J = F``, one component)."""
        return self.first_piola(X, t)

    def body_force(self, X, t):
        m = self.material
        F = self.deformation_gradient(X, t)
        u = self.displacement(X, t)
        return np.pi**2 * u * (m.mu / m.rho0 - m.c**2 - (m.lam * (np.log(F) - 1.0) - m.mu) / (m.rho0 * F**2))
