"""The B-splines' end functions at the walls: the splines of an open (clamped) knot vector.

On a uniform grid of ``n`` cells (``s = (x - x_0)/h``, nodes at ``s = 0 .. n``) the grid functions
of the quadratic and cubic B-spline bases are the B-splines ``B_j`` (``j = 0 .. n``) of degree ``p``
on the open knot vector with the ends repeated ``p + 1`` times,

    p = 2:   0, 0, 0, 3/2, 5/2, ..., n - 3/2, n, n, n      (the half cells, less the first and last)
    p = 3:   0, 0, 0, 0, 2, 3, ..., n - 2, n, n, n, n     (the nodes, less 1 and n - 1)

(de Boor's not-a-knot choice: ``n + 1`` functions for the ``n + 1`` nodes, the knot vector of
``scipy.interpolate.make_interp_spline`` on the nodes; B-spline MPM on open knot vectors: Tielen,
Wobbes, Möller & Beuth 2017, "A high order material point method", Procedia Eng. 175, 265-272,
doi:10.1016/j.proeng.2017.01.022). Away from the ends these are the uniform splines ``N(s - j)``;
the first ``J + 1 = p + 1`` at each end are the end functions ``E_j`` tabulated here (``J = p``),
the right end's the mirror images, ``B_{n-j}(s) = E_j(n - s)``. The B-splines of an open knot
vector sum to 1 on ``[0, n]`` and only ``B_0`` (``B_n``) is nonzero at ``s = 0`` (``s = n``),
where it is 1: a nodal field that is 0 at the wall nodes interpolates to exactly 0 at the walls.
The knot vector holds the tables below for ``n >= MIN_CELLS[p]`` (the end functions of the two
ends then share no knot span that changes them).

``E_j(y)``, ``y`` the distance to the wall in cells, is a polynomial on each span ``[b_k, b_{k+1}]``
of ``BREAKS[p]``, stored in ascending powers of ``y - b_k`` (zero beyond its support); the
antiderivative ``int_0^y E_j`` likewise, its constant the integral over the spans before. Numpy
(:func:`end_values`, :func:`end_integrals`) and the compiled rows (:func:`quadratic_end`,
:func:`cubic_end`, :func:`quadratic_end_integral`) evaluate the same coefficients by Horner's rule
in the same order: the same floats.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: the span ends of the end functions, in cells from the wall, per degree
BREAKS = {2: np.array([0.0, 1.5, 2.5, 3.5]), 3: np.array([0.0, 2.0, 3.0, 4.0, 5.0])}
#: the fewest cells for which the knot vector gives these end functions, per degree
MIN_CELLS = {2: 5, 3: 7}

#: ``E_j`` of the quadratic (j = 0, 1, 2; span k; ascending powers of y - b_k)
QUADRATIC = np.array([
    [[1.0, -4.0 / 3.0, 4.0 / 9.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]],
    [[0.0, 4.0 / 3.0, -32.0 / 45.0], [2.0 / 5.0, -4.0 / 5.0, 2.0 / 5.0], [0.0, 0.0, 0.0]],
    [[0.0, 0.0, 4.0 / 15.0], [3.0 / 5.0, 4.0 / 5.0, -9.0 / 10.0], [1.0 / 2.0, -1.0, 1.0 / 2.0]],
])
#: ``E_j`` of the cubic (j = 0 .. 3; span k; ascending powers of y - b_k)
CUBIC = np.array([
    [[1.0, -3.0 / 2.0, 3.0 / 4.0, -1.0 / 8.0], [0.0] * 4, [0.0] * 4, [0.0] * 4],
    [[0.0, 3.0 / 2.0, -5.0 / 4.0, 19.0 / 72.0], [1.0 / 9.0, -1.0 / 3.0, 1.0 / 3.0, -1.0 / 9.0], [0.0] * 4, [0.0] * 4],
    [[0.0, 0.0, 1.0 / 2.0, -13.0 / 72.0], [5.0 / 9.0, -1.0 / 6.0, -7.0 / 12.0, 23.0 / 72.0],
     [1.0 / 8.0, -3.0 / 8.0, 3.0 / 8.0, -1.0 / 8.0], [0.0] * 4],
    [[0.0, 0.0, 0.0, 1.0 / 24.0], [1.0 / 3.0, 1.0 / 2.0, 1.0 / 4.0, -3.0 / 8.0],
     [17.0 / 24.0, -1.0 / 8.0, -7.0 / 8.0, 11.0 / 24.0], [1.0 / 6.0, -1.0 / 2.0, 1.0 / 2.0, -1.0 / 6.0]],
])
TABLES = {2: QUADRATIC, 3: CUBIC}


def _antiderivative(table: np.ndarray, breaks: np.ndarray) -> np.ndarray:
    """``int_0^y E_j`` per span in ascending powers of ``y - b_k`` (J + 1, spans, p + 2)."""
    powers = np.arange(1, table.shape[2] + 1)
    out = np.zeros(table.shape[:2] + (table.shape[2] + 1,))
    out[:, :, 1:] = table / powers
    width = np.diff(breaks)
    span = (out[:, :, 1:] * width[None, :, None] ** powers).sum(axis=2)  # each span's integral
    out[:, 1:, 0] = np.cumsum(span, axis=1)[:, :-1]
    return out


#: ``int_0^y E_j`` of the quadratic's end functions (j, span, powers 0 .. 3)
QUADRATIC_INTEGRAL = _antiderivative(QUADRATIC, BREAKS[2])
#: ``int_0^inf E_j``, the quadratic's end functions' integrals (in cells)
QUADRATIC_TOTAL = QUADRATIC_INTEGRAL[:, -1, 0] + (QUADRATIC_INTEGRAL[:, -1, 1:] * np.diff(BREAKS[2])[-1]
                                                  ** np.arange(1, 4)).sum(axis=1)
_QB, _CB = BREAKS[2], BREAKS[3]


def require_cells(grid, degree: int, name: str) -> None:
    """Raise ``ValueError`` unless the grid has the cells the open knot vector's end functions need."""
    if grid.n_cells < MIN_CELLS[degree]:
        raise ValueError(f"the {name} basis needs at least {MIN_CELLS[degree]} cells (its end functions at the walls), "
                         f"got {grid.n_cells}")


def _horner(coefficients: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Value and slope of ``sum_m c_m u^m`` (coefficients along the last axis), highest power first."""
    d = coefficients.shape[-1] - 1
    value, slope = coefficients[..., d], np.zeros_like(u)
    for m in range(d - 1, -1, -1):
        slope = slope * u + value
        value = value * u + coefficients[..., m]
    return value, slope


def _span(breaks: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The span of each ``y >= 0``, ``y - b_k`` there, and whether ``y`` lies before the last break."""
    k = np.clip(np.searchsorted(breaks, y, side="right") - 1, 0, breaks.size - 2)
    return k, y - breaks[k], y < breaks[-1]


def end_values(degree: int, j: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``E_j(y)`` and ``dE_j/dy`` for ``j`` in 0 .. J (int arrays) at distances ``y >= 0`` (cells)."""
    table = TABLES[degree]
    k, u, inside = _span(BREAKS[degree], y)
    value, slope = _horner(table[j, k], u)
    return np.where(inside, value, 0.0), np.where(inside, slope, 0.0)


def end_integrals(j: np.ndarray, y: np.ndarray) -> np.ndarray:
    """``int_0^y E_j`` of the quadratic's end functions for ``j`` in 0 .. 2 at ``y >= 0`` (cells)."""
    k, u, inside = _span(_QB, y)
    value, _ = _horner(QUADRATIC_INTEGRAL[j, k], u)
    return np.where(inside, value, QUADRATIC_TOTAL[j])


def clamp_rows(degree: int, j: np.ndarray, s: np.ndarray, n: int, S: np.ndarray, dS: np.ndarray):
    """The rows ``S``, ``dS`` (per unit ``s``) of the uniform splines ``N(s - j)`` at the columns'
    nodes ``j`` (n_p, K; ghosts outside 0 .. n) with the end columns replaced: a ghost's by 0,
    ``j <= J`` by ``E_j(s)``, ``j >= n - J`` by ``E_{n-j}(n - s)`` (slope negated); ``s`` (n_p, 1)."""
    J = degree
    left, right = (j >= 0) & (j <= J), (j <= n) & (j >= n - J)
    yl, yr = np.broadcast_to(s, j.shape), np.broadcast_to(n - s, j.shape)
    vl, gl = end_values(degree, np.clip(j, 0, J), yl)
    vr, gr = end_values(degree, np.clip(n - j, 0, J), yr)
    ghost = (j < 0) | (j > n)
    S = np.where(left, vl, np.where(right, vr, np.where(ghost, 0.0, S)))
    dS = np.where(left, gl, np.where(right, -gr, np.where(ghost, 0.0, dS)))
    return S, dS


@njit(cache=True, inline="always")
def _find(breaks, y):
    """The span ``k`` of ``y`` (-1 at or beyond the last break)."""
    if not y < breaks[breaks.size - 1]:
        return -1
    k = 0
    while k < breaks.size - 2 and y >= breaks[k + 1]:
        k += 1
    return k


@njit(cache=True, inline="always")
def quadratic_end(j, y):
    """:func:`end_values` of the quadratic at one ``j``, ``y``: ``E_j(y)``, ``dE_j/dy``."""
    k = _find(_QB, y)
    if k < 0:
        return 0.0, 0.0
    u = y - _QB[k]
    value, slope = QUADRATIC[j, k, 2], 0.0
    for m in range(1, -1, -1):
        slope = slope * u + value
        value = value * u + QUADRATIC[j, k, m]
    return value, slope


@njit(cache=True, inline="always")
def cubic_end(j, y):
    """:func:`end_values` of the cubic at one ``j``, ``y``: ``E_j(y)``, ``dE_j/dy``."""
    k = _find(_CB, y)
    if k < 0:
        return 0.0, 0.0
    u = y - _CB[k]
    value, slope = CUBIC[j, k, 3], 0.0
    for m in range(2, -1, -1):
        slope = slope * u + value
        value = value * u + CUBIC[j, k, m]
    return value, slope


@njit(cache=True, inline="always")
def quadratic_end_integral(j, y):
    """:func:`end_integrals` at one ``j``, ``y``: ``int_0^y E_j``."""
    k = _find(_QB, y)
    if k < 0:
        return QUADRATIC_TOTAL[j]
    u = y - _QB[k]
    value = QUADRATIC_INTEGRAL[j, k, 3]
    for m in range(2, -1, -1):
        value = value * u + QUADRATIC_INTEGRAL[j, k, m]
    return value


def clamp_antiderivatives(j: np.ndarray, y: np.ndarray, n: int, M: np.ndarray, N: np.ndarray):
    """The quadratic's ``M_j(y) = int_{-inf}^y B_j`` and ``N_j(y) = B_j(y)`` (per cell) at the columns'
    nodes ``j`` (n_p, K; ghosts outside 0 .. n) from the uniform ``M``, ``N``, the end columns
    replaced: a ghost's by 0, ``j <= 2`` by ``int_0^y E_j``, ``E_j(y)``, ``j >= n - 2`` by
    ``I_{n-j} - int_0^{n-y} E_{n-j}``, ``E_{n-j}(n - y)`` (``I``: :data:`QUADRATIC_TOTAL`); ``y`` (n_p, 1)."""
    left, right = (j >= 0) & (j <= 2), (j <= n) & (j >= n - 2)
    yl, yr = np.broadcast_to(y, j.shape), np.broadcast_to(n - y, j.shape)
    jl, jr = np.clip(j, 0, 2), np.clip(n - j, 0, 2)
    ml, nl = end_integrals(jl, yl), end_values(2, jl, yl)[0]
    mr, nr = QUADRATIC_TOTAL[jr] - end_integrals(jr, yr), end_values(2, jr, yr)[0]
    ghost = (j < 0) | (j > n)
    M = np.where(left, ml, np.where(right, mr, np.where(ghost, 0.0, M)))
    N = np.where(left, nl, np.where(right, nr, np.where(ghost, 0.0, N)))
    return M, N


@njit(cache=True, inline="always")
def quadratic_end_pair(j, y, n):
    """At one node ``j`` that is a ghost or an end function's (``j <= 2`` or ``j >= n - 2``) and one
    ``y``: ``M_j(y)`` and ``B_j(y)`` of :func:`clamp_antiderivatives`, the same floats."""
    if j < 0 or j > n:
        return 0.0, 0.0
    if j <= 2:
        return quadratic_end_integral(j, y), quadratic_end(j, y)[0]
    return QUADRATIC_TOTAL[n - j] - quadratic_end_integral(n - j, n - y), quadratic_end(n - j, n - y)[0]
