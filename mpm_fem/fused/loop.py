"""The compiled loop (:func:`_advance`): many steps of the fused step in one call.

Between walls or Dirichlet ends with the lumped mass, a run takes its steps here: per step the time
step of :func:`mpm_fem.run.solve.run`, pass 1, the grid stage (``v_i = P_i / m_i``, ``a_i = F_i /
m_i``, the end conditions), the remedies' passes and pass 2, in the order and with the operations
of the per-step path :meth:`mpm_fem.fused.step.FusedStep.step`, so the same numbers bit for bit.
The Dirichlet data come from a table the caller evaluates ahead, at the times the loop will reach
(:meth:`mpm_fem.core.step.Dirichlet.end_values_at`: the same floats as one call per time), and from the
boundary object in object mode at a time the table misses; an exact acceleration likewise, from a
table of the problem's own function evaluated ahead, or in object mode (the same floats). The loop's arguments
travel in a few named structures (:class:`~mpm_fem.bases.contract.Geometry`, :class:`Conditions`, :class:`Clock`,
:class:`Scratch`, :class:`Remedies`). The scheme, the remedies that run and the passes it calls are
compile-time globals of each variant (:mod:`mpm_fem.fused.compiler`): the branches not taken are
pruned and their passes never compile. With USL and no remedy, pass 2 and the next
step's pass 1 are one blocked pass over the particles (:mod:`mpm_fem.fused.sweep`, ``SWEEP_ON``):
the next step then starts at its grid stage.
"""

from typing import NamedTuple

import numpy as np
from numba import njit, objmode

from mpm_fem.bases.contract import Cloud, RowStore
from mpm_fem.bases.contract import Geometry as Geometry  # the grid as every pass reads it
from mpm_fem.fused.codes import (
    GA,
    GAS,
    GF,
    GM,
    GP,
    GPMUSL,
    GPX,
    GTARGET,
    GTERM,
    GV,
    GVN,
    GVSTAR,
    IE,
    IEPS,
    IM,
    IP,
    IRHO,
    IV,
    IVOL,
    IX,
    USF,
    USL,
)
from mpm_fem.fused.extrema import tally_step
from mpm_fem.fused.models import Checks, ParticleState
from mpm_fem.fused.remedies import Quadrature, Reset, State
from mpm_fem.fused.sums import _divide_by_lumped
from mpm_fem.fused.sweep import BLOCK, Sweeping

# placeholders: each variant has its own (mpm_fem.fused.compiler)
STORED = ANY_GRID = MODEL = WIDTH = SCHEME = XPIC_ON = VOLUME_ON = TAYLOR_ON = SWEEP_ON = None
PROJECT = MOVE = UPDATE = FINISH = VISCOUS = GAS_FORCE = XPIC = VOLUME = TAYLOR = SWEEP = None

class Conditions(NamedTuple):
    """The problem's conditions at the ends and on the particles."""

    ends: np.ndarray  # the end nodes: walls (zero velocity and acceleration) or Dirichlet ends
    dirichlet: bool  # the ends take the boundary's data g(t)
    window: np.ndarray  # the reservoir's (a, b, spacing); empty: no particle boundary
    exact: bool  # the problem's exact nodal acceleration in place of F_i / m_i, and no viscous force
    times: np.ndarray  # (K,) increasing: the times of the tables (empty: no table)
    table: np.ndarray  # (K, ends): the Dirichlet data g at the end nodes at those times
    accelerations: np.ndarray  # (K, nodes): the exact nodal acceleration at those times ((0, 0): none)


class Clock(NamedTuple):
    """The run's time control (:func:`mpm_fem.run.solve.run`'s time step)."""

    t: float
    T: float  # the final time
    speed: float  # the previous step's max_p (c_p + |v_p|) (gas) or max_p |v_p| (Burgers)
    fixed_dt: float  # > 0: the problem's own time step
    cfl: float
    h_min: float  # the smallest cell
    refine: float  # the time step is dt / refine
    viscous_limit: bool  # Burgers' bound dt <= cfl h^2 / (2 eps)
    steps: int  # the steps the run has taken
    max_steps: int
    budget: int  # the steps this call may take


class Scratch(NamedTuple):
    """The arrays the loop writes (the per-chunk ones have a row per chunk)."""

    cell: np.ndarray  # the particles' cells
    rows: np.ndarray  # the stored rows (the particle-domain bases'): node indices, S_ip, G_ip
    S: np.ndarray
    G: np.ndarray
    grid: np.ndarray  # nodal rows codes.GM .. GPMUSL, then XPIC's GPX .. GTARGET, the volume reset's V_i, ratio
    flags: np.ndarray  # pass 1's and pass 2's first bad particles, per chunk
    upd: np.ndarray  # USF's update's and the volume reset's
    values: np.ndarray  # the values at those particles
    speeds: np.ndarray  # pass 2's max speed per chunk
    reset: np.ndarray  # reset[0] = (V, rho, p): the volume reset's state
    sums: np.ndarray  # the Taylor fit's five sums per cell


class Remedies(NamedTuple):
    """The remedies' data (an off remedy: 0 or empty arrays)."""

    xpic: int  # XPIC's order m (0: off)
    volume_width: int  # the width of the volume reset's domain rows (0: off)
    integrals: np.ndarray  # int S_i, the volume reset's
    points: np.ndarray  # the Taylor force's quadrature: the points' nodes,
    G_q: np.ndarray  # S_i' there,
    weights: np.ndarray  # their weights
    offsets: np.ndarray  # and xi_g - 1/2


@njit(cache=True, inline="always")
def _pymin(a, b):
    """Python's ``min(a, b)``: ``b`` only if ``b < a`` (NaN and ties as in :func:`mpm_fem.run.solve.run`)."""
    return b if b < a else a


@njit(cache=True, inline="always")
def _lumped_walls(rhs, m_i, ends, out):
    """``out = rhs / m_i`` where ``m_i > 0``, else 0 (:func:`~mpm_fem.core.transfer.divide_by_lumped`),
    then 0 at the wall nodes ``ends`` (:class:`~mpm_fem.core.step.Walls`)."""
    _divide_by_lumped(rhs, m_i, out)
    for i in ends:
        out[i] = 0.0


_LOOP_CALLS = []  # (boundary, grid, exact acceleration) of the running loop, for its object-mode calls


def _end_values(t):
    """The Dirichlet data ``g(x_b, t)`` at the end nodes, from the running loop's boundary object
    (:meth:`~mpm_fem.core.step.Dirichlet.end_values`: the same call, the same floats, the same cache as
    the per-step path). Called from the compiled loop in object mode, once per step."""
    boundary, grid, _ = _LOOP_CALLS[-1]
    return np.ascontiguousarray(boundary.end_values(grid, t), dtype=float)


def _exact_acceleration(t):
    """The problem's exact nodal acceleration ``a*(x_i, t)``, the call the per-step path makes
    (the same floats); from the compiled loop in object mode, once per step."""
    _, grid, exact_acceleration = _LOOP_CALLS[-1]
    return np.ascontiguousarray(exact_acceleration(grid.nodes, t), dtype=float)


@njit(cache=True)
def _tabled(times, t):
    """The row of the Dirichlet table at time ``t`` exactly (``times`` increasing), or -1."""
    i = np.searchsorted(times, t)
    return i if i < times.size and times[i] == t else -1


@njit(cache=True)
def _end_data(times, table, t):
    """The Dirichlet data at ``t``: the table's row where it holds ``t`` exactly, else
    :func:`_end_values` in object mode."""
    row = _tabled(times, t)
    if row >= 0:
        return table[row]
    with objmode(values="float64[::1]"):
        values = _end_values(t)
    return values


@njit(cache=True, inline="always")
def _set_ends(ends, values, out):
    """``out[ends] = values`` (:meth:`~mpm_fem.core.step.Dirichlet.velocity`)."""
    for k in range(ends.size):
        out[ends[k]] = values[k]


@njit(cache=True)
def _reservoir_quiet(x, window):
    """Whether the reservoir with ``window = (a, b, spacing)`` leaves the particles at ``x`` as they
    are (:meth:`mpm_fem.problems.burgers.Reservoir.quiet`): every ``x_p`` in [a, b], and
    ``floor((min x - a) / spacing) <= 0``, ``floor((b - max x) / spacing) <= 0`` (no gap to fill)."""
    a, b, s = window[0], window[1], window[2]
    if x.size == 0:
        return False
    lo, hi = x[0], x[0]
    for q in range(x.size):
        if not (x[q] >= a and x[q] <= b):
            return False
        lo = min(lo, x[q])
        hi = max(hi, x[q])
    return not (np.floor((lo - a) / s) > 0) and not (np.floor((b - hi) / s) > 0)


@njit(cache=True, inline="always")
def _nodal_rows(xpic_on, volume_on):
    """The loop's nodal scratch arrays: ``m_i``, ``P_i``, ``F_i``, ``v_i``, ``a_i``, ``v_i^{n+1}``,
    MUSL's ``P_i``; XPIC's ``P``, term, ``v*`` and target if it runs; the volume reset's ``V_i`` and
    ratio if it runs (a plain run allocates 7; the reset's first is ``_nodal_rows(XPIC_ON, 0)``)."""
    return 7 + 4 * xpic_on + 2 * volume_on


def _advance(geometry, conditions, clock, consts, chunks, state, cur, scratch, remedies, tally):
    """Up to ``clock.budget`` steps of :meth:`~mpm_fem.fused.step.FusedStep.step` with the lumped mass, each
    with the time step :func:`mpm_fem.run.solve.run` takes (``dt = min(dt_CFL / refine, T - t)``, ``dt_CFL`` from the
    previous step's ``speed``, or ``fixed_dt`` if > 0). The particles alternate between ``state[cur]``
    and ``state[1 - cur]`` (columns ``IX .. IP``: x, v, V, m, rho, eps, p; ``consts[IGM1 .. IXPIC]``
    the model's constants, ``chunks`` the particle ranges of the threads). Stops before a step that
    would fail or leave this path (the time step not positive and finite, ``max_steps``, a particle
    outside the grid, a stored row of another width, lost positivity, a non-finite state): the caller
    takes that step with :meth:`~mpm_fem.fused.step.FusedStep.step`, which raises as the numpy step does.
    With ``dirichlet`` the ends take :class:`~mpm_fem.core.step.Dirichlet`'s data instead of the walls'
    zeros (as its ``velocity`` and ``acceleration``: ``v_b = g(t)``, ``a_b = (g(t + dt) - v_b) / dt``,
    MUSL's re-projection ``g(t + dt)``), ``g`` read from the table ``(times, table)`` where it holds the
    time exactly, else evaluated in object mode (:func:`_end_values`). A non-empty ``window`` stops the
    loop after the first step whose particles the reservoir would change (:func:`_reservoir_quiet`):
    the caller applies it. With ``exact`` the nodal acceleration is the problem's exact one, from the
    table ``accelerations`` at the times it holds, else in object mode (:func:`_exact_acceleration`).
    The remedies: ``xpic = m > 0``, XPIC(m) as :meth:`~mpm_fem.fused.step.FusedStep._xpic_target` with the lumped mass
    (``m - 1`` scatter passes, each divided by ``m_i``, the change zero at the end nodes);
    ``volume_width > 0``, the grid volume reset (domain rows that wide, the reset state in
    ``reset[0]``) and then the force of the reset state; the Taylor reconstruction, its force in place
    of the particles' force. ``SCHEME``, ``XPIC_ON``, ``VOLUME_ON`` and ``TAYLOR_ON`` are compile-time
    constants of the variant; the passes it calls (``PROJECT``, ``MOVE``, ...) are its globals too.
    A ``tally`` with counts (:class:`~mpm_fem.fused.extrema.Tally`) counts each step's new extrema
    (:func:`~mpm_fem.fused.extrema.tally_step`). Returns ``(cur, t, steps taken, speed, dt_min, dt_max)``."""
    nodes, h, inv_spacing = geometry
    ends, dirichlet, window, exact, times, table, accelerations = conditions
    t, T, speed, fixed_dt, cfl, h_min, refine, viscous_limit, steps, max_steps, budget = clock
    cell, rows, S, G, grid, flags, upd, values, speeds, reset, sums = scratch
    stored = RowStore(rows, S, G, cell)
    xpic, volume_width, integrals, points, G_q, weights, offsets = remedies
    quadrature = Quadrature(points, G_q, weights, offsets)
    n = cell.size
    gas = MODEL == GAS
    eps = consts[IEPS]
    store = STORED == 1
    m_i, P_i, F_i, v_i, a_i, v_n, P_musl = grid[GM], grid[GP], grid[GF], grid[GV], grid[GA], grid[GVN], grid[GPMUSL]
    done, dt_min, dt_max = 0, np.inf, -np.inf
    g_t, g_next, known = np.empty(0), np.empty(0), False  # Dirichlet data at t and t + dt
    # the sweep (USL, a grid the basis's own kernels serve): pass 2 and the next pass 1 together, the first
    # chunk's sums into m_i, P_i, F_i, each later chunk's into sums of its own
    sweeping = SWEEP_ON == 1 and (ANY_GRID == 1 or inv_spacing > 0.0)
    sweep_scratch = Sweeping(np.empty((chunks, 4, BLOCK if sweeping else 0)),
                             np.empty((chunks - 1 if sweeping else 0, 3, grid.shape[1])), flags, speeds,
                             np.empty(chunks, np.int64))
    projected = False  # m_i, P_i, F_i (and the cells, rows) hold pass 1 of state[cur]: the last sweep's
    while done < budget and t < T * (1 - 1e-12):
        if fixed_dt > 0:
            base = fixed_dt
        elif gas:
            if not speed > 0:
                break
            base = cfl * h_min / speed
        else:
            advective = h_min / speed if speed > 0 else np.inf
            base = cfl * _pymin(advective, h_min * h_min / (2.0 * eps)) if viscous_limit else cfl * advective
        dt = _pymin(base / refine, T - t)
        if not (dt > 0 and np.isfinite(dt)) or steps + done >= max_steps:
            break
        x, v, V, m, rho, e, p = state[cur, IX, :n], state[cur, IV, :n], state[cur, IVOL, :n], state[cur, IM, :n], \
            state[cur, IRHO, :n], state[cur, IE, :n], state[cur, IP, :n]
        o = 1 - cur  # the other set: the new state
        x_n, v_new, V_n, m_n, rho_n, e_n, p_n = state[o, IX, :n], state[o, IV, :n], state[o, IVOL, :n], \
            state[o, IM, :n], state[o, IRHO, :n], state[o, IE, :n], state[o, IP, :n]
        if not projected:
            PROJECT(geometry, Cloud(x, V, m, v, p), gas and SCHEME != USF and not VOLUME_ON and not TAYLOR_ON,
                    store, chunks, stored, m_i, P_i, F_i, flags)
            need = 2
            for k in range(chunks):
                need = max(need, flags[k, 2])
            if (flags[:, :2] >= 0).any() or (store and need != WIDTH and n > 0):
                break
        projected = False
        _lumped_walls(P_i, m_i, ends, v_i)
        if dirichlet:
            if not known:
                g_t = _end_data(times, table, t)
                known = True
            t_next = t + dt
            g_next = _end_data(times, table, t_next)
            _set_ends(ends, g_t, v_i)
        if VOLUME_ON:  # the volume reset, then the force of the reset state
            V_i = _nodal_rows(XPIC_ON, 0)  # its V_i and ratio follow XPIC's arrays
            VOLUME(geometry, stored, State(x, V, m, rho, e, p), integrals, consts, chunks,
                   WIDTH if store else volume_width,
                   Reset(grid[V_i], grid[V_i + 1], reset[0, 0, :n], reset[0, 1, :n], reset[0, 2, :n]), upd, values)
            wide = 0
            for k in range(chunks):
                wide = max(wide, upd[k, 1])
            if (upd[:, 0] >= 0).any() or (not store and wide > volume_width):
                break
            V = reset[0, 0, :n]
            if gas:
                rho, p = reset[0, 1, :n], reset[0, 2, :n]
                if SCHEME != USF and not exact and not TAYLOR_ON:
                    GAS_FORCE(geometry, x, stored, v_i, V, p, 0.0, chunks, F_i)
        if SCHEME == USF:  # the state first, then its force
            UPDATE(geometry, stored, v_i, ParticleState(x, v, V, m, rho, e, p), dt, consts, not exact and not TAYLOR_ON,
                   chunks, ParticleState(x_n, v_new, V_n, m_n, rho_n, e_n, p_n), F_i, Checks(upd, values, speeds[:0]))
            if (upd >= 0).any():
                break
        elif not gas and not exact and not TAYLOR_ON:
            VISCOUS(geometry, x, stored, v_i, V, V, eps, chunks, F_i)
        if TAYLOR_ON and not exact:
            TAYLOR(geometry, x, stored, p_n if SCHEME == USF else p, v_i, eps, quadrature, chunks, sums, F_i)
        if exact:
            row = _tabled(times, t) if accelerations.shape[0] else -1
            if row >= 0:
                a_i[:] = accelerations[row]
            else:
                with objmode(a_exact="float64[::1]"):
                    a_exact = _exact_acceleration(t)
                a_i[:] = a_exact
            for i in ends:
                a_i[i] = 0.0
        else:
            _lumped_walls(F_i, m_i, ends, a_i)
        if dirichlet:
            for k in range(ends.size):
                a_i[ends[k]] = (g_next[k] - v_i[ends[k]]) / dt
        for i in range(v_n.size):
            v_n[i] = v_i[i] + dt * a_i[i]
        target = a_i
        if XPIC_ON:  # XPIC(m): v* = sum_k [P (I - B)]^k v_i, and pass 2 interpolates v* + dt a_i
            P_x, term, v_star, target = grid[GPX], grid[GTERM], grid[GVSTAR], grid[GTARGET]
            term[:] = v_i
            v_star[:] = v_i
            for _ in range(xpic - 1):
                XPIC(geometry, x, stored, term, m, m, 0.0, chunks, P_x)
                _divide_by_lumped(P_x, m_i, P_x)
                for i in range(term.size):
                    term[i] = term[i] - P_x[i]
                for i in ends:
                    term[i] = 0.0
                for i in range(term.size):
                    v_star[i] += term[i]
            for i in range(target.size):
                target[i] = v_star[i] + dt * a_i[i]
        checks = Checks(flags, values, speeds)
        old, new = ParticleState(x, v, V, m, rho, e, p), ParticleState(x_n, v_new, V_n, m_n, rho_n, e_n, p_n)
        if SCHEME == USL:
            if SWEEP_ON == 1 and sweeping:  # pass 2, and the next step's pass 1 into m_i, P_i, F_i (GM, GP, GF)
                if SWEEP(geometry, stored, target, v_n, old, new, dt, consts, chunks, grid[GM:GM + 3],
                         sweep_scratch) >= 0:
                    break  # the per-step path retakes this step and raises
                need = 0
                for k in range(chunks):
                    need = max(need, flags[k, 2])
                projected = not (flags[:, :2] >= 0).any() and (not store or need == WIDTH or n == 0)
                flags[:, :] = -1
            else:
                MOVE(geometry, stored, target, v_n, old, new, dt, consts, SCHEME, chunks, P_musl, checks)
        elif SCHEME == USF:  # the state updated already: pass 2 moves the particles only
            MOVE(geometry, stored, target, v_n, ParticleState(x, v, V_n, m, rho_n, e_n, p_n), new, dt, consts, SCHEME,
                 chunks, P_musl, checks)
        else:  # MUSL: move, re-project the momentum, then the state
            MOVE(geometry, stored, target, v_n, old, ParticleState(x_n, v_new, V, m, rho, e, p), dt, consts, SCHEME,
                 chunks, P_musl, checks)
            _lumped_walls(P_musl, m_i, ends, v_n)
            if dirichlet:
                _set_ends(ends, g_next, v_n)
            FINISH(geometry, stored, v_n, old, new, dt, consts, chunks, checks)
        if (flags >= 0).any():
            break
        if tally.counts.shape[0]:
            tally_step(tally.nodes, state[o, :, :n], tally.fields, tally.rtol, tally.moving_speed, tally.counts,
                       tally.cells, tally.marks)
        speed = speeds.max()
        cur = 1 - cur
        t += dt
        done += 1
        dt_min, dt_max = min(dt_min, dt), max(dt_max, dt)
        g_t = g_next
        if window.size and not _reservoir_quiet(state[cur, IX, :n], window):
            break  # the particle boundary acts on these particles: the caller's
    return cur, t, done, speed, dt_min, dt_max
