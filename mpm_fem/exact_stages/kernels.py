"""Compiled point evaluations of Sod's exact fields for the exact stages (numba).

:class:`~mpm_fem.problems.sod.RiemannFields` evaluates the Riemann solution for the exact stages
(:mod:`mpm_fem.exact_stages.stage`) on the projection's Gauss points and on the particles through
these kernels. Each makes one pass over the points with the same floating-point operations in the
same order as the numpy evaluation it replaces, so the two are equal bit for bit (tested:
``tests/test_exact_kernels.py``); the numpy versions stay the readable reference. Why compiled:
``docs/performance.md``.

    sample       Toro's sampling (section 4.5) at ``S = (x - x0)/t``: left of the contact the
                 left wave, right of it the mirror image of a left wave (``S -> -S``, ``u -> -u``).
                 Inside a fan

                     c = 2/(gamma+1) + (gamma-1)/((gamma+1) a_K) (u_K - S),
                     rho = rho_K c^(2/(gamma-1)),   p = p_K c^(2 gamma/(gamma-1))    (Toro 4.56)

                 the two powers are left to numpy (:func:`sample`): numpy's vectorised ``pow``
                 differs from the C library's in the last bit, and the numpy reference uses it.
    profile      ``U(xi)``, ``F(xi) = int U`` and ``G = F - xi U`` of the piecewise-linear
                 self-similar velocity (:class:`~mpm_fem.problems.sod.RiemannFields`):

                     U = U_k + m_k d,   F = F_k + U_k d + m_k d^2 / 2,
                     G = F_k - U_k xi_k + m_k d^2 / 2 - xi m_k d,      d = xi - xi_k,

                 ``k`` the piece holding ``xi`` (the number of wave speeds ``<= xi``).
    averaged     the fields averaged over ``[x - l, x + l]``, from ``alpha = (x - l - x0)/t`` and
                 ``beta = (x + l - x0)/t``:

                     v* = t (F(beta) - F(alpha)) / (2l),   v*_x = (U(beta) - U(alpha)) / (2l),
                     a* = (G(beta) - G(alpha)) / (2l) + v* v*_x.
"""

from __future__ import annotations

import numpy as np
from numba import njit

# the layout of a wave's constants (:func:`wave_constants`)
RHO, U, P, A, SHOCK, SPEED, HEAD, TAIL, RHO_STAR = range(9)
FAN = 2  # region code of a point inside a fan


def wave_constants(state, wave: dict, gamma: float) -> np.ndarray:
    """A left wave (``baselines.exact.riemann._left_wave``'s dict) and its state ``(rho, u, p)`` as
    the float array the kernel reads (``RHO ... RHO_STAR``); ``a = sqrt(gamma p / rho)``."""
    rho, u, p = state
    shock = bool(wave["shock"])
    return np.array([rho, u, p, np.sqrt(gamma * p / rho), float(shock), wave["speed"] if shock else 0.0,
                     0.0 if shock else wave["head"], 0.0 if shock else wave["tail"], wave["rho_star"]])


@njit(cache=True)
def _left_wave_point(s, w, p_star, u_star, gamma):
    """``(rho, u, p, c, region)`` of the left wave ``w`` at ``S = s`` (Toro section 4.5.1); in a
    fan (region 2) ``rho`` and ``p`` are ``rho_K`` and ``p_K``, to be multiplied by the powers of ``c``."""
    if w[SHOCK] != 0.0:
        if s < w[SPEED]:
            return w[RHO], w[U], w[P], 0.0, 0
        return w[RHO_STAR], u_star, p_star, 0.0, 1
    if s <= w[HEAD]:
        return w[RHO], w[U], w[P], 0.0, 0
    if s >= w[TAIL]:
        return w[RHO_STAR], u_star, p_star, 0.0, 1
    a = w[A]
    c = 2.0 / (gamma + 1.0) + (gamma - 1.0) / ((gamma + 1.0) * a) * (w[U] - s)
    if c < 0.0:
        c = 0.0
    u = 2.0 / (gamma + 1.0) * (a + 0.5 * (gamma - 1.0) * w[U] + s)
    return w[RHO], u, w[P], c, FAN


@njit(cache=True)
def _sample_pass(x, t, x0, gamma, p_star, u_star, left, right):
    """One pass over the points: ``rho, u, p`` outside the fans, ``rho_K, u, p_K`` inside, and the
    fan points' indices with their ``c``, in order."""
    n = x.size
    rho, u, p, c = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    fan = np.empty(n, np.int64)
    k = 0
    for q in range(n):
        s = (x[q] - x0) / t
        if s <= u_star:
            r, v, pr, cq, region = _left_wave_point(s, left, p_star, u_star, gamma)
        else:
            r, v, pr, cq, region = _left_wave_point(-s, right, p_star, -u_star, gamma)
            v = -v
        rho[q], u[q], p[q] = r, v, pr
        if region == FAN:
            fan[k], c[k] = q, cq
            k += 1
    return rho, u, p, c[:k].copy(), fan[:k]


@njit(cache=True)
def _scale_fan(rho, p, fan, rho_power, p_power):
    """``rho_q <- rho_q c^(2/(gamma-1))``, ``p_q <- p_q c^(2 gamma/(gamma-1))`` at the fan points ``fan``."""
    for j in range(fan.size):
        rho[fan[j]] = rho[fan[j]] * rho_power[j]
        p[fan[j]] = p[fan[j]] * p_power[j]


def sample(x: np.ndarray, t: float, x0: float, gamma: float, p_star: float, u_star: float,
           left: np.ndarray, right: np.ndarray):
    """``(rho, u, p)`` of the Riemann problem at ``x`` and ``t > 0`` (no vacuum), equal bit for bit
    to :func:`baselines.exact.riemann.sample`. ``left`` and ``right`` are :func:`wave_constants` of
    the left wave and of the mirrored right wave. numpy raises the fan points' ``c`` (one array, in
    the order of the points, as the numpy reference's ``c[fan]``) to the two powers."""
    x = np.ascontiguousarray(x, dtype=float)
    rho, u, p, c, fan = _sample_pass(x.ravel(), float(t), float(x0), float(gamma), float(p_star), float(u_star),
                                     left, right)
    if fan.size:
        _scale_fan(rho, p, fan, c ** (2.0 / (gamma - 1.0)), c ** (2.0 * gamma / (gamma - 1.0)))
    return rho.reshape(x.shape), u.reshape(x.shape), p.reshape(x.shape)


@njit(cache=True, inline="always")
def _profile_point(x, speeds, anchor, F0, U0, m):
    """``U(xi), F(xi), G(xi)`` at one ``xi = x``."""
    k = 0
    while k < speeds.size and speeds[k] <= x:  # a handful of wave speeds
        k += 1
    d = x - anchor[k]
    U = U0[k] + m[k] * d
    F = F0[k] + U0[k] * d + 0.5 * m[k] * d * d
    G = F0[k] - U0[k] * anchor[k] + 0.5 * m[k] * d * d - x * m[k] * d
    return U, F, G


@njit(cache=True)
def profile(xi, speeds, anchor, F0, U0, m):
    """``U(xi)``, ``F(xi)``, ``G(xi)`` (module docstring) for a 1D array of finite ``xi``."""
    n = xi.size
    U, F, G = np.empty(n), np.empty(n), np.empty(n)
    for q in range(n):
        U[q], F[q], G[q] = _profile_point(xi[q], speeds, anchor, F0, U0, m)
    return U, F, G


@njit(cache=True)
def averaged(x, t, l, x0, full, speeds, anchor, F0, U0, m):
    """``(v*, v*_x, a*)`` at the points ``x`` and ``t > 0`` (module docstring); ``full=False``
    fills ``v*_x`` only (``v*`` and ``a*`` are then left empty)."""
    n = x.size
    v, v_x, a = np.empty(n if full else 0), np.empty(n), np.empty(n if full else 0)
    for q in range(n):
        U_hi, F_hi, G_hi = _profile_point((x[q] + l - x0) / t, speeds, anchor, F0, U0, m)
        U_lo, F_lo, G_lo = _profile_point((x[q] - l - x0) / t, speeds, anchor, F0, U0, m)
        v_x[q] = (U_hi - U_lo) / (2 * l)
        if full:
            v[q] = t * (F_hi - F_lo) / (2 * l)
            a[q] = (G_hi - G_lo) / (2 * l) + v[q] * v_x[q]
    return v, v_x, a
