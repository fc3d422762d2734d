"""The models' update of one particle, and the checks a pass tallies.

From the velocity gradient ``L_p = sum_i G_ip v_i``: the ideal gas (:meth:`IdealGas.update`:
``rho <- rho (1 - L dt)``, ``eps <- eps - p/rho L dt``, ``p = (gamma - 1) rho eps + q``, ``V = m/rho``,
the sound speed) or viscous Burgers (``V <- V (1 + L dt)``, ``m = V``), the numpy model's
operations in its order. A pass's checks (the first particle whose factor or energy is not
positive, the first non-finite one, the largest signal speed) travel as a :class:`Tally` of seven
floats through the particle loop, so that they stay in registers and numba's parallel analysis
accepts them.
Inlined into the passes, except :func:`all_finite`, the run's own check. The passes hand the particle
state over as :class:`ParticleState` named tuples, which these helpers unpack before they index: inside
a ``prange`` body numba 0.68 loses a write through a named tuple's attribute (``new.e[q] = ...``),
while writes through the unpacked arrays land (``tests/test_fused_remedies.py``'s two-thread runs
caught it; numba/numba#7135, ``docs/performance.md``).
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
    """A pass's checks so far, seven floats (particle indices < 2^53 are exact; -1: none yet). Floats,
    not arrays: the tally stays in registers, and numba's parallel analysis takes it (it mistakes
    integer tuples for shapes)."""

    bad_factor: float  # the first particle whose factor (1 - L dt, Burgers 1 + L dt) is not > 0
    bad_energy: float  # the first particle whose energy is not > 0 (gas)
    bad_finite: float  # the first particle with a non-finite state
    factor: float  # the factor of ``bad_factor``
    energy: float  # the energy of ``bad_energy``
    speed: float  # the largest signal speed, ``max c_p + |v_p|`` (gas) or ``max |v_p|``
    sound_speed: float  # the sound speed of the particle last updated (what :func:`_checked` reads)


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
def _new_state(gas, q, L, dt, l, old, new, consts, tally):
    """The model's update of particle q from ``L_p`` (gas: :meth:`IdealGas.update`; Burgers:
    ``V_p <- V_p (1 + L_p dt)``, ``m_p = V_p``), from the :class:`ParticleState` ``old`` into ``new``
    (``l`` the cell size of the artificial viscosity). Returns the :class:`Tally` updated, with this
    particle's sound speed."""
    bad_f, bad_e, bad_n, val_f, val_e, top, _ = tally
    _, _, V, m, rho, e, p = old
    _, _, V_new, m_new, rho_new, e_new, p_new = new  # unpacked: see the module docstring
    if gas:
        factor, rho_new[q], e_new[q], p_new[q], V_new[q], c = _gas_update(
            rho[q], e[q], p[q], m[q], L, dt, l, consts[IGM1], consts[IGGM1], consts[ILIN], consts[IQUAD])
        bad_e, val_e = _first(bad_e, val_e, q, e_new[q])
    else:
        factor, c = 1.0 + L * dt, 0.0
        V_new[q] = V[q] * factor
        m_new[q] = V_new[q]
    bad_f, val_f = _first(bad_f, val_f, q, factor)
    return Tally(bad_f, bad_e, bad_n, val_f, val_e, top, c)


@njit(cache=True, inline="always")
def _checked(gas, q, c, new, tally):
    """The tally with ``max(top, c_p + |v_p|)`` (gas) or ``max(top, |v_p|)`` of particle q of the
    :class:`ParticleState` ``new``, and the first non-finite particle."""
    bad_f, bad_e, bad_n, val_f, val_e, top, _ = tally
    x, v, V, _, rho, e, p = new
    if gas:
        top = max(top, c + abs(v[q]))
        ok = _finite(x[q], v[q], rho[q], e[q], p[q], V[q])
    else:
        top = max(top, abs(v[q]))
        ok = _finite(x[q], v[q], V[q], 0.0, 0.0, 0.0)
    if bad_n < 0 and not ok:
        bad_n = float(q)
    return Tally(bad_f, bad_e, bad_n, val_f, val_e, top, c)


@njit(cache=True, inline="always")
def _flags(k, tally, checks):
    """Chunk k's tally into the pass's :class:`Checks`: ``flags[k]`` (the first bad particles: factor,
    energy and, if it has three columns, non-finite), ``values[k]`` (the two values), ``speed[k]``
    (where the pass has one per chunk)."""
    flags, values, speed = checks  # unpacked: see the module docstring
    flags[k, 0], flags[k, 1] = int(tally.bad_factor), int(tally.bad_energy)
    if flags.shape[1] > 2:
        flags[k, 2] = int(tally.bad_finite)
    values[k, 0], values[k, 1] = tally.factor, tally.energy
    if speed.size > k:
        speed[k] = tally.speed


_NO_TALLY = Tally(-1.0, -1.0, -1.0, 0.0, 0.0, 0.0, 0.0)  # no bad particle yet, speed 0
