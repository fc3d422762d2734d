"""Exact Riemann solver for the 1D Euler equations of an ideal gas.

Source: E. F. Toro, *Riemann Solvers and Numerical Methods for Fluid Dynamics*, 3rd ed.,
Springer 2009, chapter 4. Equation numbers below are Toro's.

Notation (Toro's): a state is ``(rho, u, p)``; ``a_K = sqrt(gamma p_K / rho_K)`` is the sound
speed of the left (K = L) or right (K = R) state. The star region between the two nonlinear waves
has pressure ``p_star`` and velocity ``u_star``, the root of (4.5)

    f(p) = f_L(p) + f_R(p) + (u_R - u_L) = 0,

with the pressure function (4.6)-(4.7)

    f_K(p) = (p - p_K) sqrt(A_K / (p + B_K))                    if p > p_K   (shock)
    f_K(p) = 2 a_K / (gamma - 1) ((p / p_K)^((gamma-1)/(2gamma)) - 1)   if p <= p_K  (rarefaction)

    A_K = 2 / ((gamma + 1) rho_K),   B_K = (gamma - 1) / (gamma + 1) p_K,

and ``u_star = (u_L + u_R)/2 + (f_R(p_star) - f_L(p_star))/2`` (4.9). The root is found by Newton's
method (4.44) from Toro's adaptive initial guess (section 9.5.1: PVRS, two-rarefaction or
two-shock), unfloored: near vacuum both waves are rarefactions and the two-rarefaction guess (4.46)
is the root itself. Newton stops on a relative change of ``p`` below ``1e-12``, or when ``f(p)``
is at the round-off of its three terms (near vacuum ``p_star`` is tiny and ``f`` cancels).

Vacuum is generated when ``u_R - u_L >= 2 (a_L + a_R)/(gamma - 1)`` (4.40, the pressure positivity
condition). There is no star region then: :func:`sample` gives Toro's solution of section 4.6.3,
a left rarefaction whose tail ``S*_L = u_L + 2 a_L/(gamma - 1)`` (4.76) meets vacuum, vacuum
(``rho = p = 0``; the velocity is set to ``S``, continuous with both fans), and a right rarefaction
from ``S*_R = u_R - 2 a_R/(gamma - 1)`` (4.79). :func:`star_state` and :func:`wave_positions`,
which need a star region, raise ``ValueError`` for such data.

The solution is self-similar in ``S = (x - x0)/t`` and is sampled as in Toro section 4.5. The
right wave is the mirror image of a left wave (``x -> -x``, ``u -> -u``), so only the left wave is
coded and the right one is sampled through the mirror.
"""

from __future__ import annotations

import numpy as np

_NEWTON_RTOL = 1e-12
_NEWTON_MAXITER = 100
_ROUND_OFF = 8.0 * np.finfo(float).eps


def _checked_state(state, side: str) -> tuple[float, float, float]:
    try:
        rho, u, p = (float(q) for q in state)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{side} state must be a tuple (rho, u, p) of numbers, got {state!r}") from exc
    if not all(np.isfinite((rho, u, p))):
        raise ValueError(f"{side} state must be finite, got (rho, u, p) = {state!r}")
    if rho <= 0.0:
        raise ValueError(f"{side} density must be positive, got rho = {rho}")
    if p <= 0.0:
        raise ValueError(f"{side} pressure must be positive, got p = {p}")
    return rho, u, p


def _checked_gamma(gamma: float) -> float:
    gamma = float(gamma)
    if not np.isfinite(gamma) or gamma <= 1.0:
        raise ValueError(f"the ratio of specific heats must satisfy gamma > 1, got gamma = {gamma}")
    return gamma


def _sound_speed(rho: float, p: float, gamma: float) -> float:
    return float(np.sqrt(gamma * p / rho))


def _pressure_function(p: float, rho_k: float, p_k: float, gamma: float) -> tuple[float, float]:
    """``f_K(p)`` and ``f_K'(p)``, Toro (4.6)-(4.7) and (4.37)."""
    if p > p_k:
        a_k = 2.0 / ((gamma + 1.0) * rho_k)
        b_k = (gamma - 1.0) / (gamma + 1.0) * p_k
        root = np.sqrt(a_k / (p + b_k))
        return (p - p_k) * root, root * (1.0 - 0.5 * (p - p_k) / (p + b_k))
    c_k = _sound_speed(rho_k, p_k, gamma)
    ratio = p / p_k
    f = 2.0 * c_k / (gamma - 1.0) * (ratio ** ((gamma - 1.0) / (2.0 * gamma)) - 1.0)
    df = ratio ** (-(gamma + 1.0) / (2.0 * gamma)) / (rho_k * c_k)
    return f, df


def _initial_guess(left, right, gamma: float) -> float:
    """Toro's adaptive guess (section 9.5.1): PVRS if the pressure ratio is mild and PVRS lies
    between the data pressures, else two-rarefaction (TRRS) or two-shock (TSRS)."""
    rho_l, u_l, p_l = left
    rho_r, u_r, p_r = right
    a_l, a_r = _sound_speed(rho_l, p_l, gamma), _sound_speed(rho_r, p_r, gamma)
    p_pv = max(0.0, 0.5 * (p_l + p_r) - 0.125 * (u_r - u_l) * (rho_l + rho_r) * (a_l + a_r))
    p_min, p_max = min(p_l, p_r), max(p_l, p_r)
    if p_max / p_min <= 2.0 and p_min <= p_pv <= p_max:
        return p_pv
    if p_pv < p_min:
        z = (gamma - 1.0) / (2.0 * gamma)
        num = a_l + a_r - 0.5 * (gamma - 1.0) * (u_r - u_l)
        return float((num / (a_l / p_l**z + a_r / p_r**z)) ** (1.0 / z))
    g_l = np.sqrt(2.0 / ((gamma + 1.0) * rho_l) / ((gamma - 1.0) / (gamma + 1.0) * p_l + p_pv))
    g_r = np.sqrt(2.0 / ((gamma + 1.0) * rho_r) / ((gamma - 1.0) / (gamma + 1.0) * p_r + p_pv))
    return float((g_l * p_l + g_r * p_r - (u_r - u_l)) / (g_l + g_r))


def _vacuum_speeds(left, right, gamma: float) -> tuple[float, float] | None:
    """``(S*_L, S*_R)`` of the vacuum front speeds, Toro (4.76) and (4.79), if the data generate
    vacuum, Toro (4.40) (``u_R - u_L >= 2 (a_L + a_R)/(gamma - 1)``); otherwise ``None``."""
    (rho_l, u_l, p_l), (rho_r, u_r, p_r) = left, right
    a_l, a_r = _sound_speed(rho_l, p_l, gamma), _sound_speed(rho_r, p_r, gamma)
    if u_r - u_l < 2.0 * (a_l + a_r) / (gamma - 1.0):
        return None
    return u_l + 2.0 * a_l / (gamma - 1.0), u_r - 2.0 * a_r / (gamma - 1.0)


def _solve_star(left, right, gamma: float) -> tuple[float, float]:
    rho_l, u_l, p_l = left
    rho_r, u_r, p_r = right
    if _vacuum_speeds(left, right, gamma) is not None:
        a_l, a_r = _sound_speed(rho_l, p_l, gamma), _sound_speed(rho_r, p_r, gamma)
        raise ValueError(
            "the initial data generate vacuum: u_R - u_L = "
            f"{u_r - u_l:.6g} >= 2 (a_L + a_R)/(gamma - 1) = {2.0 * (a_l + a_r) / (gamma - 1.0):.6g} "
            "(Toro (4.40)): there is no star region (sample() gives the vacuum solution)"
        )
    p = _initial_guess(left, right, gamma)
    for _ in range(_NEWTON_MAXITER):
        f_l, df_l = _pressure_function(p, rho_l, p_l, gamma)
        f_r, df_r = _pressure_function(p, rho_r, p_r, gamma)
        residual = f_l + f_r + u_r - u_l
        if abs(residual) <= _ROUND_OFF * (abs(f_l) + abs(f_r) + abs(u_r - u_l)):
            break  # f(p) = 0 to round-off: a Newton step would only move p by noise
        p_new = p - residual / (df_l + df_r)
        # f is increasing and concave: after an overshoot to p <= 0, iterates from the left of
        # the root rise monotonically to it, so stepping part-way towards zero is safe.
        if p_new <= 0.0:
            p_new = 0.1 * p
        converged = 2.0 * abs(p_new - p) / (p_new + p) < _NEWTON_RTOL
        p = p_new
        if converged:
            break
    else:
        raise RuntimeError(f"Newton iteration for p_star did not converge in {_NEWTON_MAXITER} steps")
    f_l, _ = _pressure_function(p, rho_l, p_l, gamma)
    f_r, _ = _pressure_function(p, rho_r, p_r, gamma)
    return float(p), float(0.5 * (u_l + u_r) + 0.5 * (f_r - f_l))


def star_state(left, right, gamma: float = 1.4) -> tuple[float, float]:
    """Pressure and velocity ``(p_star, u_star)`` of the star region, Toro (4.5) and (4.9).

    ``left`` and ``right`` are ``(rho, u, p)``. Raises ``ValueError`` for non-positive density or
    pressure, ``gamma <= 1``, or data that generate vacuum (no star region).
    """
    gamma = _checked_gamma(gamma)
    return _solve_star(_checked_state(left, "left"), _checked_state(right, "right"), gamma)


def _left_wave(state, p_star: float, u_star: float, gamma: float) -> dict:
    """Speeds and star density of the left wave, Toro (4.50)-(4.55)."""
    rho, u, p = state
    a = _sound_speed(rho, p, gamma)
    ratio = p_star / p
    g6 = (gamma - 1.0) / (gamma + 1.0)
    if p_star > p:
        speed = u - a * np.sqrt((gamma + 1.0) / (2.0 * gamma) * ratio + (gamma - 1.0) / (2.0 * gamma))
        return {"shock": True, "speed": speed, "rho_star": rho * (ratio + g6) / (g6 * ratio + 1.0)}
    a_star = a * ratio ** ((gamma - 1.0) / (2.0 * gamma))
    return {
        "shock": False,
        "head": u - a,
        "tail": u_star - a_star,
        "rho_star": rho * ratio ** (1.0 / gamma),
    }


def waves(left, right, gamma: float = 1.4) -> tuple[float, float, dict, dict]:
    """``(p_star, u_star, left_wave, right_wave)``: the star state and the two waves as
    :func:`sample` uses them, the right one as the left wave of the mirrored data (module
    docstring). A wave is a dict: ``shock``, and ``speed`` (shock) or ``head`` and ``tail``
    (rarefaction), and ``rho_star`` (Toro (4.50)-(4.55)). Vacuum data raise ``ValueError``."""
    gamma = _checked_gamma(gamma)
    left, right = _checked_state(left, "left"), _checked_state(right, "right")
    p_star, u_star = _solve_star(left, right, gamma)
    return (p_star, u_star, _left_wave(left, p_star, u_star, gamma),
            _left_wave(_mirror(right), p_star, -u_star, gamma))


def _sample_left_wave(s, state, p_star: float, u_star: float, gamma: float):
    """``(rho, u, p)`` at ``S = (x - x0)/t <= u_star``, Toro section 4.5.1 (left wave)."""
    rho, u, p = state
    wave = _left_wave(state, p_star, u_star, gamma)
    if wave["shock"]:
        unshocked = s < wave["speed"]
        return (
            np.where(unshocked, rho, wave["rho_star"]),
            np.where(unshocked, u, u_star),
            np.where(unshocked, p, p_star),
        )
    a = _sound_speed(rho, p, gamma)
    # Toro (4.56); clipped at zero only where it is not selected, outside the fan.
    c = np.clip(2.0 / (gamma + 1.0) + (gamma - 1.0) / ((gamma + 1.0) * a) * (u - s), 0.0, None)
    regions = [s <= wave["head"], s >= wave["tail"]]
    return (
        np.select(regions, [rho, wave["rho_star"]], rho * c ** (2.0 / (gamma - 1.0))),
        np.select(regions, [u, u_star], 2.0 / (gamma + 1.0) * (a + 0.5 * (gamma - 1.0) * u + s)),
        np.select(regions, [p, p_star], p * c ** (2.0 * gamma / (gamma - 1.0))),
    )


def _mirror(state):
    rho, u, p = state
    return rho, -u, p


def _sample_vacuum(s, left, right, gamma: float, s_left: float, s_right: float):
    """Toro section 4.6.3: the left fan up to ``S*_L``, vacuum, the right fan from ``S*_R``.

    A rarefaction to vacuum is the fan of :func:`_sample_left_wave` with ``p_star = 0``: its tail
    speed ``u_star - a_star`` is then ``S*_L`` (``a_star = 0``, ``u_star = S*_L``)."""
    rho_l, u_l, p_l = _sample_left_wave(s, left, 0.0, s_left, gamma)
    rho_r, u_r, p_r = _sample_left_wave(-s, _mirror(right), 0.0, -s_right, gamma)
    regions = [s <= s_left, s >= s_right]
    return (np.select(regions, [rho_l, rho_r], 0.0), np.select(regions, [u_l, -u_r], s),
            np.select(regions, [p_l, p_r], 0.0))


def sample(x, t: float, left, right, x0: float = 0.5, gamma: float = 1.4):
    """Exact solution ``(rho, u, p)`` of the Riemann problem at points ``x`` and time ``t``.

    Data ``left`` for ``x < x0`` and ``right`` for ``x > x0`` at ``t = 0``; the solution is the
    self-similar sampling of Toro section 4.5 at ``S = (x - x0)/t`` (section 4.6.3 if the data
    generate vacuum: ``rho = p = 0`` between the two fans). At ``t == 0`` the initial data
    are returned (``left`` for ``x < x0``, ``right`` for ``x >= x0``). ``x`` is any array; the three
    returned arrays have its shape. The domain is unbounded: no wall reflections.
    """
    gamma = _checked_gamma(gamma)
    left, right = _checked_state(left, "left"), _checked_state(right, "right")
    t = float(t)
    if not np.isfinite(t) or t < 0.0:
        raise ValueError(f"time must be finite and non-negative, got t = {t}")
    x = np.asarray(x, dtype=float)
    if t == 0.0:
        is_left = x < x0
        return tuple(np.where(is_left, ql, qr) for ql, qr in zip(left, right, strict=False))
    s = (x - x0) / t
    vacuum = _vacuum_speeds(left, right, gamma)
    if vacuum is not None:
        return _sample_vacuum(s, left, right, gamma, *vacuum)
    p_star, u_star = _solve_star(left, right, gamma)
    rho_l, u_l, p_l = _sample_left_wave(s, left, p_star, u_star, gamma)
    rho_r, u_r, p_r = _sample_left_wave(-s, _mirror(right), p_star, -u_star, gamma)
    is_left = s <= u_star
    return np.where(is_left, rho_l, rho_r), np.where(is_left, u_l, -u_r), np.where(is_left, p_l, p_r)


def wave_positions(t: float, left, right, x0: float = 0.5, gamma: float = 1.4) -> dict:
    """Positions at time ``t`` of the wave fronts, and the star-region state.

    Position of a front moving at speed ``S`` is ``x0 + S t``; speeds from Toro (4.51)-(4.52)
    (shock), (4.54)-(4.55) (rarefaction head and tail), ``u_star`` (contact), and their mirror
    images (4.58)-(4.65) for the right wave. Keys:

    - ``'left_shock'`` or ``'left_rarefaction_head'`` and ``'left_rarefaction_tail'``;
    - ``'contact'``;
    - ``'right_shock'`` or ``'right_rarefaction_head'`` and ``'right_rarefaction_tail'``;
    - aliases without the side when the wave type is unique: ``'shock'`` if exactly one wave is a
      shock, ``'rarefaction_head'`` and ``'rarefaction_tail'`` if exactly one is a rarefaction
      (Sod's tube: left rarefaction, right shock);
    - ``'rho_star_left'``, ``'rho_star_right'`` (Toro (4.50), (4.53), (4.57), (4.60)),
      ``'p_star'``, ``'u_star'``.
    """
    gamma = _checked_gamma(gamma)
    left, right = _checked_state(left, "left"), _checked_state(right, "right")
    t = float(t)
    if not np.isfinite(t) or t < 0.0:
        raise ValueError(f"time must be finite and non-negative, got t = {t}")
    p_star, u_star = _solve_star(left, right, gamma)
    waves = {
        "left": (_left_wave(left, p_star, u_star, gamma), 1.0),
        "right": (_left_wave(_mirror(right), p_star, -u_star, gamma), -1.0),
    }
    out: dict[str, float] = {}
    for side, (wave, sign) in waves.items():
        if wave["shock"]:
            out[f"{side}_shock"] = x0 + sign * wave["speed"] * t
        else:
            out[f"{side}_rarefaction_head"] = x0 + sign * wave["head"] * t
            out[f"{side}_rarefaction_tail"] = x0 + sign * wave["tail"] * t
        out[f"rho_star_{side}"] = wave["rho_star"]
    out["contact"] = x0 + u_star * t
    shocks = [side for side, (wave, _) in waves.items() if wave["shock"]]
    if len(shocks) == 1:
        out["shock"] = out[f"{shocks[0]}_shock"]
    rarefactions = [side for side in waves if side not in shocks]
    if len(rarefactions) == 1:
        out["rarefaction_head"] = out[f"{rarefactions[0]}_rarefaction_head"]
        out["rarefaction_tail"] = out[f"{rarefactions[0]}_rarefaction_tail"]
    out["p_star"], out["u_star"] = p_star, u_star
    return {key: float(value) for key, value in out.items()}
