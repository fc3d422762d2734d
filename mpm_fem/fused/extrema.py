"""New extrema counted inside the compiled loop (C14): the kernels of
:class:`~mpm_fem.measure.regions.ExtremaCounter`, and its count of one step in one pass.

With the particles in position order, particle ``p`` is a strict local extremum of a field ``q`` if

    q_p > max(q_{p-1}, q_{p+1}) + tol   or   q_p < min(q_{p-1}, q_{p+1}) - tol,
    tol = rtol * max(|q_{p-1}|, |q_p|, |q_{p+1}|)

(:func:`strict_extrema`; the first and last particle are never extrema). A particle *crossed* in a step
if its cell (:func:`cells`: ``clip(searchsorted(nodes, x, "right") - 1, 0, n_cells - 1)``) changed,
and *moved* if it did not cross and ``|v_p^{n+1}| > moving_speed``. :func:`tally_step` adds one step
to ``counts`` (shape ``(1 + F, 4)``, int64):

    counts[0]      steps, crossings, moving particle-steps, particle-steps
    counts[1 + f]  new extrema of field f at crossings, elsewhere, at moving particles, the most in a step

(a new extremum: an extremum after the step that was not one before it), the integers the observer adds
up per step: the same predicates on the same floats. ``memory`` carries the previous state's cells and
extremum marks from step to step; where the particles are not in position order the marks are taken in
the order of a stable sort (:func:`marks`), as the observer's ``argsort(kind="stable")``.
"""

from typing import NamedTuple

import numpy as np
from numba import njit

from mpm_fem.fused.codes import IV, IX


class Tally(NamedTuple):
    """What the compiled loop needs to count new extrema (an empty ``counts``: it counts none)."""

    nodes: np.ndarray  # (nodes,) the counting grid's nodes, increasing
    fields: np.ndarray  # (F,) int64: the counted fields' rows of the loop's state (codes.IRHO, codes.IE, ...)
    rtol: float
    moving_speed: float
    counts: np.ndarray  # (1 + F, 4) int64 (module docstring); (0, 4): no count
    cells: np.ndarray  # (n,) intp: the previous state's cells
    marks: np.ndarray  # (F, n) bool: the previous state's extrema


def no_tally() -> Tally:
    """The tally of a loop that counts nothing."""
    return Tally(np.empty(0), np.empty(0, np.int64), 0.0, 0.0, np.empty((0, 4), np.int64), np.empty(0, np.intp),
                 np.empty((0, 0), np.bool_))


@njit(cache=True, inline="always")
def _walk(nodes, j, y):
    """The last node ``k`` with ``nodes[k] <= y`` (-1 if none; the last node for NaN), from ``j``."""
    m = nodes.size
    if y != y:
        return m - 1
    while j + 1 < m and nodes[j + 1] <= y:
        j += 1
    while j >= 0 and not (nodes[j] <= y):
        j -= 1
    return j


@njit(cache=True)
def cells(nodes, x):
    """The cell of every point (module docstring), found by walking from the previous point's node:
    O(points + nodes) for points nearly in order, the integers of a binary search."""
    m = nodes.size
    out = np.empty(x.size, np.intp)
    j = -1
    for p in range(x.size):
        j = _walk(nodes, j, x[p])
        out[p] = min(max(j, 0), m - 2)
    return out


@njit(cache=True, inline="always")
def _extremum(left, mid, right, rtol):
    tol = rtol * max(max(abs(left), abs(mid)), abs(right))
    return mid > max(left, right) + tol or mid < min(left, right) - tol


@njit(cache=True)
def strict_extrema(q, rtol):
    """The strict local extrema of ordered values ``q`` (module docstring), one pass."""
    n = q.size
    out = np.zeros(n, np.bool_)
    for k in range(1, n - 1):
        out[k] = _extremum(q[k - 1], q[k], q[k + 1], rtol)
    return out


@njit(cache=True)
def in_order(x):
    """Whether ``x[p + 1] >= x[p]`` for every ``p`` (False at a NaN)."""
    for p in range(x.size - 1):
        if not (x[p + 1] >= x[p]):
            return False
    return True


@njit(cache=True)
def marks(q, x, rtol, out):
    """``out[p]``: particle ``p`` is a strict extremum of ``q`` in the position order of ``x`` (the order
    of a stable sort where ``x`` is not in order)."""
    if in_order(x):
        out[:] = strict_extrema(q, rtol)
        return
    order = np.argsort(x, kind="mergesort")
    out[order] = strict_extrema(q[order], rtol)


@njit(cache=True)
def remember(nodes, state, fields, rtol, memory_cells, memory_marks):
    """The cells and extremum marks of ``state`` (rows: the loop's fields) into the memory."""
    x = state[IX]
    memory_cells[:] = cells(nodes, x)
    for f in range(fields.size):
        marks(state[fields[f]], x, rtol, memory_marks[f])


@njit(cache=True, inline="always")
def _cell_from(nodes, c, y):
    """The cell of ``y`` (module docstring) for a point that was in cell ``c``: ``c`` if it stays there (one
    comparison per side: the common case), else found by walking from ``c`` (the same integer)."""
    m = nodes.size
    if (c == 0 or nodes[c] <= y) and (c == m - 2 or y < nodes[c + 1]):
        return c
    return min(max(_walk(nodes, c, y), 0), m - 2)


@njit(cache=True)
def tally_step(nodes, state, fields, rtol, moving_speed, counts, memory_cells, memory_marks):
    """Add the step to ``state`` (rows ``x, v, ...``: codes.IX, codes.IV, the loop's fields) to ``counts``,
    against the previous state's memory, then remember ``state`` (module docstring). One pass for the
    cells, one per field (a field's row taken once: no view per particle)."""
    x, v = state[IX], state[IV]
    n = x.size
    crossings, moving = 0, 0
    kind = np.empty(n, np.uint8)  # 1: crossed, 2: moved
    for p in range(n):
        c = memory_cells[p]
        cell = _cell_from(nodes, c, x[p])
        crossed = cell != c
        memory_cells[p] = cell
        moved = not crossed and abs(v[p]) > moving_speed
        crossings += crossed
        moving += moved
        kind[p] = crossed + 2 * moved
    counts[0, 0] += 1
    counts[0, 1] += crossings
    counts[0, 2] += moving
    counts[0, 3] += n
    ordered = in_order(x)
    after = np.empty(0 if ordered else n, np.bool_)
    for f in range(fields.size):
        q, before = state[fields[f]], memory_marks[f]
        if not ordered:
            marks(q, x, rtol, after)
        at_crossing, total, at_moving = 0, 0, 0
        for p in range(n):
            if ordered:
                now = 0 < p < n - 1 and _extremum(q[p - 1], q[p], q[p + 1], rtol)
            else:
                now = after[p]
            if now and not before[p]:
                at_crossing += kind[p] & 1
                total += 1
                at_moving += kind[p] >> 1
            before[p] = now
        counts[1 + f, 0] += at_crossing
        counts[1 + f, 1] += total - at_crossing
        counts[1 + f, 2] += at_moving
        counts[1 + f, 3] = max(counts[1 + f, 3], total)


def merge(totals: np.ndarray, counts: np.ndarray) -> None:
    """Add ``counts`` into ``totals`` (both ``(1 + F, 4)``): sums, but the most in a step is a maximum."""
    totals[0] += counts[0]
    totals[1:, :3] += counts[1:, :3]
    totals[1:, 3] = np.maximum(totals[1:, 3], counts[1:, 3])
