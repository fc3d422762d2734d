"""Exact solutions of the viscous Burgers equation ``v_t + v v_x = eps v_xx``.

Source: the candidates (a)-(d) of docs/claims.md, "Problem settings" (the slides of Tran & Berzins do
not say which exact solution their Burgers table used). All four are Cole-Hopf solutions

    v = -2 eps phi_x / phi,        phi_t = eps phi_xx                                   (CH)

(Cole 1951, Hopf 1950; Whitham, *Linear and Nonlinear Waves*, section 4.4). Each solution is a
frozen dataclass with the viscosity ``eps`` and its parameters, the class attributes ``name`` and
``domain``, and the methods ``v``, ``v_x``, ``v_xx``, ``v_t`` in closed form (``fields`` gives all
four from one evaluation). The methods take arrays ``x`` and ``t`` that broadcast against each
other and return an array of the broadcast shape. ``v_t + v v_x`` (the material acceleration
that MPM needs) equals ``eps v_xx``.

Each is written so that nothing overflows for small eps. The fronts (a) and (b) are exponential
mixtures: ``phi = sum_k exp(-a_k)`` with ``a_k = kappa_k x + tau_k t + c_k`` linear, so
``v = sum_k v_k p_k`` is a weighted mean of the constants ``v_k = 2 eps kappa_k`` with weights
``p_k = exp(-a_k)/phi`` (a softmax, evaluated after shifting the exponents by their pointwise
minimum). Differentiating the weights gives, with ``Var`` and ``mu_3`` the variance and third
central moment of ``v_k`` under ``p_k``,

    v_x = -Var / (2 eps),    v_xx = mu_3 / (4 eps^2),    v_t = -sum_k p_k (v_k - v)(tau_k - tau_bar).

The wave (c) and the rarefaction (d) state their formulas in their classes.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import ClassVar

import numpy as np
from scipy.special import erfc, erfcx, expit

__all__ = ["Front", "ThreeExponential", "ColeHopfWave", "Rarefaction", "SOLUTIONS", "make_solution"]


def _broadcast(x, t):
    return np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(t, dtype=float))


def _above(default: float, bound: float, why: str):
    """A parameter that must exceed ``bound`` (checked by ``_BurgersSolution.__post_init__``)."""
    return field(default=default, metadata={"above": bound, "why": why})


@dataclass(frozen=True)
class _BurgersSolution:
    """Common interface: ``v``, ``v_x``, ``v_xx``, ``v_t``, or all four at once with ``fields``."""

    eps: float

    name: ClassVar[str]
    domain: ClassVar[tuple[float, float]] = (0.0, 2.0)

    def __post_init__(self):
        if not np.isfinite(self.eps) or self.eps <= 0.0:
            raise ValueError(f"{self.name}: the viscosity must satisfy eps > 0, got eps = {self.eps}")
        for parameter in fields(self):
            if "above" in parameter.metadata:
                value, bound = getattr(self, parameter.name), parameter.metadata["above"]
                if not value > bound:
                    raise ValueError(f"{self.name}: {parameter.name} must be > {bound:g} "
                                     f"{parameter.metadata['why']}, got {parameter.name} = {value}")

    def _fields(self, x, t):
        """``(v, v_x, v_xx, v_t)`` at the arrays ``x``, ``t`` of one shape."""
        raise NotImplementedError

    def _velocity(self, x, t):
        """``v`` alone at the arrays ``x``, ``t`` of one shape: ``_fields(x, t)[0]``, or the same
        operations without the derivatives (the same floats, at a fraction of the cost)."""
        return self._fields(x, t)[0]

    def fields(self, x, t):
        """``(v, v_x, v_xx, v_t)`` at ``(x, t)`` from one evaluation."""
        return self._fields(*_broadcast(x, t))

    def v(self, x, t):
        return self._velocity(*_broadcast(x, t))

    def v_x(self, x, t):
        return self.fields(x, t)[1]

    def v_xx(self, x, t):
        return self.fields(x, t)[2]

    def v_t(self, x, t):
        return self.fields(x, t)[3]


def _exponential_mixture(x, t, eps, kappa, tau, c, velocity_only=False):
    """``(v, v_x, v_xx, v_t)`` for ``phi = sum_k exp(-(kappa_k x + tau_k t + c_k))``, the moment
    formulas of the module docstring; ``kappa``, ``tau``, ``c`` are sequences of equal length.
    ``velocity_only``: ``v`` alone."""
    x, t = _broadcast(x, t)
    kappa, tau, c = (np.asarray(q, dtype=float)[:, None] for q in (kappa, tau, c))
    a = kappa * x.ravel() + tau * t.ravel() + c
    weights = np.exp(-(a - a.min(axis=0)))
    weights /= weights.sum(axis=0)
    values = 2.0 * eps * kappa
    v = (weights * values).sum(axis=0)
    if velocity_only:
        return v.reshape(x.shape)
    dev = values - v
    variance = (weights * dev**2).sum(axis=0)
    mu3 = (weights * dev**3).sum(axis=0)
    tau_bar = (weights * tau).sum(axis=0)
    cov_tau = (weights * dev * (tau - tau_bar)).sum(axis=0)
    shape = x.shape
    return (
        v.reshape(shape),
        (-variance / (2.0 * eps)).reshape(shape),
        (mu3 / (4.0 * eps**2)).reshape(shape),
        (-cov_tau).reshape(shape),
    )


@dataclass(frozen=True)
class Front(_BurgersSolution):
    """(a) Travelling front ``v = 0.5 - 0.5 tanh((x - x0 - t/2) / (4 eps))``, docs/claims.md (a).

    The viscous shock from 1 (left) to 0 (right) moving at the Rankine-Hugoniot speed 1/2, width
    ~ 4 eps. It is the two-term mixture ``phi = exp(-(x - x0 - t/2)/(2 eps)) + 1`` (values 1, 0),
    evaluated with the moment formulas of the module docstring.
    """

    x0: float = 0.75

    name: ClassVar[str] = "front"

    def _fields(self, x, t, velocity_only=False):
        eps = self.eps
        return _exponential_mixture(
            x, t, eps,
            kappa=(1.0 / (2.0 * eps), 0.0),
            tau=(-1.0 / (4.0 * eps), 0.0),
            c=(-self.x0 / (2.0 * eps), 0.0),
            velocity_only=velocity_only,
        )

    def _velocity(self, x, t):
        return self._fields(x, t, velocity_only=True)


@dataclass(frozen=True)
class ThreeExponential(_BurgersSolution):
    """(b) Berzins' three-exponential solution, docs/claims.md (b):

        v = (0.1 e^-a + 0.5 e^-b + e^-c) / (e^-a + e^-b + e^-c),
        a = 0.05/eps (x - 0.5 + 4.95 t),  b = 0.25/eps (x - 0.5 + 0.75 t),  c = 0.5/eps (x - 0.375).

    Usually posed on [0, 1] in Berzins' test sets; here on [0, 2], the study's Burgers domain.
    It is the mixture of the module docstring with values ``v_k = 2 eps kappa_k = 0.1, 0.5, 1``;
    the exponents are shifted by their pointwise minimum, so it is finite for any eps > 0.
    """

    name: ClassVar[str] = "three_exp"

    def _fields(self, x, t, velocity_only=False):
        eps = self.eps
        return _exponential_mixture(
            x, t, eps,
            kappa=(0.05 / eps, 0.25 / eps, 0.5 / eps),
            tau=(0.05 * 4.95 / eps, 0.25 * 0.75 / eps, 0.0),
            c=(-0.05 * 0.5 / eps, -0.25 * 0.5 / eps, -0.5 * 0.375 / eps),
            velocity_only=velocity_only,
        )

    def _velocity(self, x, t):
        return self._fields(x, t, velocity_only=True)


@dataclass(frozen=True)
class ColeHopfWave(_BurgersSolution):
    """(c) Decaying Cole-Hopf wave, docs/claims.md (c), from ``phi = A + E cos(pi x)``,
    ``E = exp(-pi^2 eps t)``:

        v    = 2 eps pi E sin(pi x) / D,                     D = A + E cos(pi x),
        v_x  = 2 eps pi^2 E (A cos(pi x) + E) / D^2,
        v_xx = 2 eps pi^3 E sin(pi x) (2 E^2 + A E cos(pi x) - A^2) / D^3,
        v_t  = -2 eps^2 pi^3 A E sin(pi x) / D^2.

    ``A > 1`` keeps ``D >= A - 1 > 0``. On [0, 2], ``v = 0`` at both ends; ``|v| <= 2 eps pi /
    sqrt(A^2 - 1)``, so the amplitude is proportional to eps.
    """

    A: float = _above(2.0, 1.0, "so that phi > 0")

    name: ClassVar[str] = "cole_hopf"

    def _parts(self, x, t):
        decay = np.exp(-(np.pi**2) * self.eps * t)
        sin, cos = np.sin(np.pi * x), np.cos(np.pi * x)
        return decay, sin, cos, self.A + decay * cos

    def _velocity(self, x, t):
        decay, sin, _, d = self._parts(x, t)
        return 2.0 * self.eps * np.pi * decay * sin / d

    def _fields(self, x, t):
        eps, big_a, pi = self.eps, self.A, np.pi
        decay, sin, cos, d = self._parts(x, t)
        return (
            2.0 * eps * pi * decay * sin / d,
            2.0 * eps * pi**2 * decay * (big_a * cos + decay) / d**2,
            2.0 * eps * pi**3 * decay * sin * (2.0 * decay**2 + big_a * decay * cos - big_a**2) / d**3,
            -2.0 * eps**2 * pi**3 * big_a * decay * sin / d**2,
        )


def _log_erfcx(z):
    """``log(erfcx(z))`` without overflow: ``erfcx(z) = exp(z^2) erfc(z)`` overflows for
    ``z < -26``, where ``log(erfc(z)) + z^2`` is exact (``erfc(z)`` is in [1, 2] for z <= 0)."""
    negative = z < 0.0
    return np.where(negative, np.log(erfc(np.where(negative, z, 0.0))) + z**2, np.log(erfcx(np.abs(z))))


@dataclass(frozen=True)
class Rarefaction(_BurgersSolution):
    """(d) Viscous rarefaction, docs/claims.md (d): the Cole-Hopf solution of the step ``v = u_left``
    for ``x < x_step``, ``u_right`` for ``x > x_step``, at time ``s = t0 + t`` (``t0 > 0`` makes the
    data at ``t = 0`` smooth).

    Derivation. With ``xi = x - x_step`` and ``kappa_K = u_K / (2 eps)``, the step gives
    ``phi(x, 0) = exp(-kappa_L xi)`` for ``xi < 0`` and ``exp(-kappa_R xi)`` for ``xi > 0``; its heat
    evolution is ``phi = phi_L + phi_R`` with (completing the square in the Gaussian convolution)

        phi_L = 1/2 exp(-kappa_L xi + eps kappa_L^2 s) erfc( z_L),   z_L = (xi - u_L s)/sqrt(4 eps s),
        phi_R = 1/2 exp(-kappa_R xi + eps kappa_R^2 s) erfc(-z_R),   z_R = (xi - u_R s)/sqrt(4 eps s),

    each a heat solution. Since ``-kappa_K xi + eps kappa_K^2 s - z_K^2 = -xi^2/(4 eps s)``, both
    are ``1/2 exp(-xi^2/(4 eps s)) erfcx(+-z_K)``: the common factor cancels from every ratio below,
    and with ``lambda_L = log erfcx(z_L)``, ``lambda_R = log erfcx(-z_R)`` nothing overflows. The
    Gaussian terms of ``phi_L,x`` and ``phi_R,x`` cancel (the data are continuous), so with weights
    ``w_R = phi_R / phi = expit(lambda_R - lambda_L)``, ``w_L = 1 - w_R`` and ``du = u_R - u_L``:

        v    = u_L + du w_R,
        v_x  = du (gamma - du w_L w_R / (2 eps)),
        v_xx = du gamma (v s - xi) / (2 eps s) - du (w_L - w_R) v_x / (2 eps),
        v_t  = du (w_L w_R (u_R^2 - u_L^2) / (4 eps) - gamma/2 (u_L + u_R - v + xi/s)),

    where ``gamma = g / phi = 2 / (sqrt(4 pi eps s) (exp(lambda_L) + exp(lambda_R)))`` and
    ``g = exp(-xi^2/(4 eps s)) / sqrt(4 pi eps s)`` is the heat kernel at the step. ``v_t`` follows
    from ``v_t = Cov_w(u, phi_t/phi)`` and ``phi_K,t = eps phi_K,xx``; it is not obtained from the
    Burgers equation, which the tests check instead. As eps -> 0 it tends to the inviscid fan
    ``v = xi / s`` for ``u_L < xi/s < u_R``. With ``u_left > u_right`` the same formulas give a
    viscous shock.
    """

    u_left: float = 0.5
    u_right: float = 1.0
    x_step: float = 0.5
    t0: float = _above(0.05, 0.0, "so that the data are smooth")

    name: ClassVar[str] = "rarefaction"

    def _exponents(self, x, t):
        """``s``, ``xi``, ``sqrt(4 eps s)``, ``lambda_L``, ``lambda_R`` (the docstring's)."""
        eps, u_l, u_r = self.eps, self.u_left, self.u_right
        s = self.t0 + t
        xi = x - self.x_step
        root = np.sqrt(4.0 * eps * s)
        return s, xi, root, _log_erfcx((xi - u_l * s) / root), _log_erfcx(-(xi - u_r * s) / root)

    def _velocity(self, x, t):
        _, _, _, lam_l, lam_r = self._exponents(x, t)
        return self.u_left + (self.u_right - self.u_left) * expit(lam_r - lam_l)

    def _fields(self, x, t):
        eps, u_l, u_r = self.eps, self.u_left, self.u_right
        du = u_r - u_l
        s, xi, root, lam_l, lam_r = self._exponents(x, t)
        w_r = expit(lam_r - lam_l)
        w_l = expit(lam_l - lam_r)
        gamma = 2.0 / (np.sqrt(np.pi) * root) * np.exp(-np.logaddexp(lam_l, lam_r))
        v = u_l + du * w_r
        v_x = du * (gamma - du * w_l * w_r / (2.0 * eps))
        v_xx = du * gamma * (v * s - xi) / (2.0 * eps * s) - du * (w_l - w_r) * v_x / (2.0 * eps)
        v_t = du * (w_l * w_r * (u_r**2 - u_l**2) / (4.0 * eps) - 0.5 * gamma * (u_l + u_r - v + xi / s))
        return v, v_x, v_xx, v_t


SOLUTIONS: dict[str, type[_BurgersSolution]] = {
    cls.name: cls for cls in (Front, ThreeExponential, ColeHopfWave, Rarefaction)
}


def make_solution(name: str, eps: float, **params) -> _BurgersSolution:
    """The exact solution ``SOLUTIONS[name](eps, **params)``; ``ValueError`` for an unknown name
    or parameter, or for ``eps <= 0``."""
    if name not in SOLUTIONS:
        raise ValueError(f"unknown Burgers solution {name!r}; valid names: {', '.join(sorted(SOLUTIONS))}")
    cls = SOLUTIONS[name]
    valid = {f.name for f in fields(cls)} - {"eps"}
    unknown = set(params) - valid
    if unknown:
        raise ValueError(
            f"{name}: unknown parameter(s) {', '.join(sorted(unknown))}; valid: {', '.join(sorted(valid)) or 'none'}"
        )
    return cls(eps, **params)
