"""The models' update of one particle, and the checks a pass tallies.

From the velocity gradient ``L_p = sum_i G_ip v_i``: the ideal gas (:meth:`IdealGas.update`:
``rho <- rho (1 - L dt)``, ``eps <- eps - p/rho L dt``, ``p = (gamma - 1) rho eps + q``, ``V = m/rho``,
the sound speed) or viscous Burgers (``V <- V (1 + L dt)``, ``m = V``), the numpy model's
operations in its order. A pass's checks (the first particle whose factor or energy is not
positive, the first non-finite one, the largest signal speed) travel as a :class:`Tally` of seven
floats through the particle loop, so that they stay in registers and numba's parallel analysis
accepts them.
Inlined into the passes, except :func:`all_finite`, the run's own check. These helpers run inside
the passes' ``prange`` bodies, so they take arrays and scalars, never a named tuple of arrays: numba
0.68 loses writes to an array reached through a tuple inside a ``prange`` body (numba/numba#5872,
#7135, #10338; ``docs/performance.md``). The passes take :class:`ParticleState` and :class:`Checks`
and unpack them before their ``prange``.
"""

from typing import NamedTuple

import numpy as np
from numba import njit

from mpm_fem.fused.codes import IGGM1, IGM1, ILIN, IQUAD


class ParticleState(NamedTuple):
    """The particles' arrays a pass reads or writes (n_p,), in the columns' order ``IX .. IP``
    (:mod:`mpm_fem.fused.codes`): position, velocity, volume, mass, density, specific internal energy
    ``eps``, pressure. A pass takes the old state and the new one it writes (the same arrays where
    the scheme updates a field in place or not at all)."""

    x: np.ndarray
    v: np.ndarray
    V: np.ndarray
    m: np.ndarray
    rho: np.ndarray
    e: np.ndarray
    p: np.ndarray


class Checks(NamedTuple):
    """A pass's per-chunk outputs (a row per chunk k): ``flags[k]`` the first bad particles (factor,
    energy and, with three columns, non-finite; -1: none), ``values[k]`` the factor and energy there,
    ``speed[k]`` the largest signal speed."""

    flags: np.ndarray
    values: np.ndarray
    speed: np.ndarray


class Tally(NamedTuple):
    """A pass's checks so far and the state of the particle last updated, twelve floats (particle
    indices < 2^53 are exact; -1: none yet). Floats, not arrays: the tally stays in registers, and
    numba's parallel analysis takes it (it mistakes integer tuples, and a tuple of a tally and a
    tuple, for shapes)."""

    bad_factor: float  # the first particle whose factor (1 - L dt, Burgers 1 + L dt) is not > 0
    bad_energy: float  # the first particle whose energy is not > 0 (gas)
    bad_finite: float  # the first particle with a non-finite state
    factor: float  # the factor of ``bad_factor``
    energy: float  # the energy of ``bad_energy``
    speed: float  # the largest signal speed, ``max c_p + |v_p|`` (gas) or ``max |v_p|``
    sound_speed: float  # the sound speed of the particle last updated (what :func:`_checked` reads)
    V: float  # the particle last updated: its new volume,
    m: float  # mass,
    rho: float  # density,
    e: float  # specific internal energy
    p: float  # and pressure (what :func:`_store` writes)


@njit(cache=True, inline="always")
def _gas_update(rho, e, p, m, L, dt, l, gm1, g_gm1, c_lin, c_quad):
    """:meth:`IdealGas.update` of one particle: factor, rho, eps, p, V and the sound speed."""
    factor = 1.0 - L * dt
    density = rho * factor
    energy = e - p / rho * L * dt
    c = np.sqrt(g_gm1 * max(energy, 0.0))
    jump = l * min(L, 0.0)
    q = density * (c_quad * (jump * jump) + c_lin * c * abs(jump))
    return factor, density, energy, gm1 * density * energy + q, m / density, c


@njit(cache=True, inline="always")
def _finite(a, b, c, d, e, f):
    """Whether all six are finite: ``0 a + ... + 0 f`` is 0 exactly then, NaN otherwise (no branch)."""
    return a * 0.0 + b * 0.0 + c * 0.0 + d * 0.0 + e * 0.0 + f * 0.0 == 0.0


@njit(cache=True)
def all_finite(x, v, rho, e, p, V):
    """Whether every entry of the six particle arrays is finite (one pass; the run's check)."""
    ok = True
    for q in range(x.size):  # no branch per particle: the loop vectorizes
        ok &= (np.isfinite(x[q]) & np.isfinite(v[q]) & np.isfinite(rho[q]) & np.isfinite(e[q]) & np.isfinite(p[q])
               & np.isfinite(V[q]))
    return ok


@njit(cache=True, inline="always")
def _first(bad, value_at_bad, q, value):
    """The first particle whose ``value`` is not > 0, and that value: ``(q, value)`` if none yet."""
    if bad < 0 and not (value > 0):
        return float(q), value
    return bad, value_at_bad


@njit(cache=True, inline="always")
def _new_state(gas, q, L, dt, l, rho, e, p, m, V, consts, tally):
    """The model's update of particle q from ``L_p`` and its state ``rho, e, p, m, V`` (scalars; gas:
    :meth:`IdealGas.update`; Burgers: ``V_p <- V_p (1 + L_p dt)``, ``m_p = V_p``; ``l`` the cell size of
    the artificial viscosity). Returns the :class:`Tally` updated with this particle's sound speed and
    new ``V, m, rho, eps, p`` (:func:`_store` writes those the model changes)."""
    bad_f, bad_e, bad_n, val_f, val_e, top = (tally.bad_factor, tally.bad_energy, tally.bad_finite, tally.factor,
                                               tally.energy, tally.speed)
    if gas:
        factor, rho_n, e_n, p_n, V_n, c = _gas_update(
            rho, e, p, m, L, dt, l, consts[IGM1], consts[IGGM1], consts[ILIN], consts[IQUAD])
        m_n = m
        bad_e, val_e = _first(bad_e, val_e, q, e_n)
    else:
        factor, c = 1.0 + L * dt, 0.0
        V_n = V * factor
        m_n, rho_n, e_n, p_n = V_n, rho, e, p
    bad_f, val_f = _first(bad_f, val_f, q, factor)
    return Tally(bad_f, bad_e, bad_n, val_f, val_e, top, c, V_n, m_n, rho_n, e_n, p_n)


@njit(cache=True, inline="always")
def _store(gas, q, tally, V_new, m_new, rho_new, e_new, p_new):
    """Particle q's new state from the :class:`Tally` :func:`_new_state` returned into the arrays the
    model changes: the gas's V, rho, eps, p; Burgers' V and m."""
    if gas:
        V_new[q], rho_new[q], e_new[q], p_new[q] = tally.V, tally.rho, tally.e, tally.p
    else:
        V_new[q], m_new[q] = tally.V, tally.m


@njit(cache=True, inline="always")
def _checked(gas, q, c, x_new, v_new, rho_new, e_new, p_new, V_new, tally):
    """The tally with ``max(top, c_p + |v_p|)`` (gas) or ``max(top, |v_p|)``, and the first
    non-finite particle."""
    bad_f, bad_e, bad_n, val_f, val_e, top = (tally.bad_factor, tally.bad_energy, tally.bad_finite, tally.factor,
                                               tally.energy, tally.speed)
    if gas:
        top = max(top, c + abs(v_new[q]))
        ok = _finite(x_new[q], v_new[q], rho_new[q], e_new[q], p_new[q], V_new[q])
    else:
        top = max(top, abs(v_new[q]))
        ok = _finite(x_new[q], v_new[q], V_new[q], 0.0, 0.0, 0.0)
    if bad_n < 0 and not ok:
        bad_n = float(q)
    return Tally(bad_f, bad_e, bad_n, val_f, val_e, top, c, tally.V, tally.m, tally.rho, tally.e, tally.p)


@njit(cache=True, inline="always")
def _flags(k, tally, flags, values, speed):
    """Chunk k's tally into a pass's outputs (:class:`Checks`' arrays): ``flags[k]`` (the first bad
    particles: factor, energy and, if it has three columns, non-finite), ``values[k]`` (the two
    values), ``speed[k]`` (where the pass has one per chunk)."""
    flags[k, 0], flags[k, 1] = int(tally.bad_factor), int(tally.bad_energy)
    if flags.shape[1] > 2:
        flags[k, 2] = int(tally.bad_finite)
    values[k, 0], values[k, 1] = tally.factor, tally.energy
    if speed.size > k:
        speed[k] = tally.speed


_NO_TALLY = Tally(-1.0, -1.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)  # no bad particle yet, speed 0
