"""The per-particle basis rows: ``S_ip`` and ``G_ip`` of one particle at its nodes.

A row is the particle's cell ``c``, its K nodes ``i``, ``S_ip`` and ``G_ip = dS_i/dx (x_p)``, for the
point mass (``S = (1 - xi, xi)``), the quadratic B-spline (ghost splines folded into the end nodes),
GIMP and the particle-domain B-spline (the hats or splines averaged over ``[x_p - V_p/2, x_p + V_p/2]``
cut at the grid's ends). Each repeats the numpy arithmetic of :mod:`mpm_fem.core.shape` operation
for operation (bit for bit), except on a grid uniform to round-off (``inv_spacing = 1/h > 0``), where
the row comes in closed form from ``s = (x - x_0)/h``, ``c = floor(s)``, ``xi = s - c``: equal to the
node arithmetic to round-off, not bit for bit. The particle-domain rows on a uniform grid are built
from scalars (:func:`_domain`, :func:`_domain_column`) because an inlined helper handed arrays costs
reference counting per particle. All are inlined into the passes.
"""

from numba import njit

from mpm_fem.exact_stages.grid_kernels import locate as _locate
from mpm_fem.fused.codes import BSPLINE, BSPLINE_GIMP, GIMP, POINT


@njit(cache=True, inline="always")
def _point(nodes, h, inv_spacing, x):
    """The point-mass row of one point: cell ``c``, ``xi`` and ``1/h_c``. On a uniform grid
    (``inv_spacing = 1/h > 0``) from uniform-grid arithmetic, ``s = (x - x_0)/h``, ``c = floor(s)``,
    ``xi = s - c``, ``1/h_c = 1/h`` (no node coordinates read, no division): equal to the numpy
    step's node arithmetic to round-off (``xi`` to about ``eps |x| / h``), not bit for bit.
    Otherwise as :func:`mpm_fem.core.shape.locate` and :func:`mpm_fem.core.shape.point_shape` (bit for bit)."""
    last = nodes.size - 2
    if inv_spacing > 0.0:
        s = (x - nodes[0]) * inv_spacing
        c = min(int(s), last)  # s >= 0 inside the grid; the last node belongs to the last cell
        return c, s - c, inv_spacing
    c, xi = _locate(nodes, inv_spacing, x)
    return c, xi, h[1, c]


@njit(cache=True, inline="always")
def _scaled(nodes, inv_spacing, y):
    """Uniform-grid arithmetic for one point ``y`` in the grid: ``s = (y - x_0)/h`` and its cell
    ``c = floor(s)`` (the last node in the last cell)."""
    s = (y - nodes[0]) * inv_spacing
    return s, min(int(s), nodes.size - 2)


@njit(cache=True, inline="always")
def _bspline_nearest(s, top):
    """The quadratic B-spline row on a uniform grid from ``s = (x - x_0)/h``: the nearest node
    ``n = floor(s + 1/2)`` and ``t = s - n`` in [-1/2, 1/2]; the splines of nodes ``n - 1, n, n + 1``
    are ``N(t + 1) = (1/2 - t)^2 / 2``, ``N(t) = 3/4 - t^2``, ``N(t - 1) = (1/2 + t)^2 / 2``, their
    slopes ``t - 1/2``, ``-2 t``, ``t + 1/2`` (per unit ``s``); every other spline is 0 at ``x``."""
    n = min(int(s + 0.5), top)
    t = s - n
    u, w = 0.5 - t, 0.5 + t
    return n, t, 0.5 * (u * u), 0.75 - t * t, 0.5 * (w * w)


@njit(cache=True, inline="always")
def _hat_antiderivative(r):
    """``Psi(r) = int_{-inf}^r max(0, 1 - |r'|) dr'`` of the unit hat, without a branch:
    ``(u^2 + 1 - w^2) / 2`` with ``u = clip(r + 1, 0, 1)``, ``w = clip(1 - r, 0, 1)``."""
    u = min(max(r + 1.0, 0.0), 1.0)
    w = min(max(1.0 - r, 0.0), 1.0)
    return 0.5 * (u * u + (1.0 - w * w))


@njit(cache=True, inline="always")
def _domain_ends(x0, b, top_cell, inv_spacing, x, V):
    """The particle domain ``[x - V/2, x + V/2]`` cut at the grid's ends ``[x0, b]``, in uniform-grid
    arithmetic (:func:`_scaled`'s operations, from scalars: no array handed over per particle, which
    would cost reference counting in the hot loops): the particle's cell ``c``, and ``s_-, c_-,
    s_+, c_+``, the scaled ends and their cells."""
    c = min(int((x - x0) * inv_spacing), top_cell)
    s_lo = (max(x - 0.5 * V, x0) - x0) * inv_spacing
    s_hi = (min(x + 0.5 * V, b) - x0) * inv_spacing
    return c, s_lo, min(int(s_lo), top_cell), s_hi, min(int(s_hi), top_cell)


@njit(cache=True, inline="always")
def _gimp_entry(k, s_lo, c_lo, s_hi, c_hi, inv_w, inv_spacing, last):
    """Node, ``S`` and ``G`` of column ``k`` of GIMP's row on a uniform grid (:func:`_domain_column`):
    a domain inside one cell has the hats' values at its midpoint, ``S = (1 - xi_m, xi_m)``, ``G =
    (-1, 1)/h`` (no division; ``inv_w`` unused); otherwise node ``i = min(c_- + k, last)``, ``S =
    (Psi(s_+ - i) - Psi(s_- - i)) inv_w``, ``G = (N(s_+ - i) - N(s_- - i)) inv_w / h``, with
    ``inv_w = 1 / (s_+ - s_-)`` and a node repeated at the last node zeroed."""
    if c_hi == c_lo:
        xi = 0.5 * (s_lo + s_hi) - c_lo
        if k == 0:
            return c_lo, 1.0 - xi, -inv_spacing
        if k == 1:
            return c_lo + 1, xi, inv_spacing
        return min(c_lo + k, last), 0.0, 0.0
    i = min(c_lo + k, last)
    if k > 0 and i == min(c_lo + k - 1, last):
        return i, 0.0, 0.0
    r_lo, r_hi = s_lo - i, s_hi - i
    return (i, (_hat_antiderivative(r_hi) - _hat_antiderivative(r_lo)) * inv_w,
            (max(1.0 - abs(r_hi), 0.0) - max(1.0 - abs(r_lo), 0.0)) * (inv_w * inv_spacing))


@njit(cache=True, inline="always")
def _hat_and_integral(nodes, i, y):
    """:func:`mpm_fem.core.shape._hat_and_integral` for node ``i`` at ``y``: ``S_i(y)``, ``int^y S_i``."""
    n = nodes.size
    xl = nodes[max(i - 1, 0)]
    xc = nodes[i]
    xr = nodes[min(i + 1, n - 1)]
    hl, hr = xc - xl, xr - xc
    yl = min(max(y, xl), xc)
    yr = min(max(y, xc), xr)
    left = (yl - xl) * (yl - xl) / (2 * hl) if hl > 0 else 0.0
    right = (hr * hr - (xr - yr) * (xr - yr)) / (2 * hr) if hr > 0 else 0.0
    value = ((y - xl) / hl if (y >= xl and y < xc and hl > 0) else 0.0) + (
        (xr - y) / hr if (y >= xc and y <= xr and hr > 0) else 0.0)
    if y == xc and hr == 0 and hl > 0:
        value = 1.0
    return value, left + right


@njit(cache=True, inline="always")
def _bspline_value(r):
    """``N(r)`` of :func:`mpm_fem.core.shape._quadratic_bspline`."""
    a = abs(r)
    if a <= 0.5:
        return 0.75 - r * r
    if a < 1.5:
        return 0.5 * ((1.5 - a) * (1.5 - a))
    return 0.0


@njit(cache=True, inline="always")
def _bspline_antiderivative(r):
    """``M(r) = int_{-inf}^r N`` of :func:`mpm_fem.core.shape._bspline_integral`, operation for operation."""
    r = min(max(r, -1.5), 1.5)
    u = min(max(r + 1.5, 0.0), 1.0)
    m = min(max(r, -0.5), 0.5)
    w = min(max(1.5 - r, 0.0), 1.0)
    return u * u * u / 6.0 + (0.75 * (m + 0.5) - (m * m * m + 0.125) / 3.0) + (1.0 - w * w * w) / 6.0


_SIXTH = 1.0 / 6.0  # M's first term where r >= -1/2: u = 1
_M_ABOVE = _SIXTH + (0.75 * (0.5 + 0.5) - (0.5 * 0.5 * 0.5 + 0.125) / 3.0)  # M's first two terms where r >= 1/2
_M_TOP = _M_ABOVE + (1.0 - 0.0 * 0.0 * 0.0) / 6.0  # M(r) for r >= 3/2: 1 to round-off, as the formula gives it


@njit(cache=True, inline="always")
def _bspline_pieces(y, c):
    """``M`` and ``N`` (:func:`_bspline_antiderivative`, :func:`_bspline_value`) of the three splines
    that do not vanish at the scaled point ``y`` in cell ``c``: those of the nearest node ``n = c +
    first`` (``first = 0`` if ``y - c < 1/2``, else 1) and its neighbours. At ``r = y - j`` they are
    the formula's pieces, operation for operation, so the same floats:

        j = n - 1, r in [1/2, 3/2]:    M = 1/6 + (3/4 - 1/12) + (1 - w^3)/6,  N = w^2/2,  w = 3/2 - r
        j = n,     r in [-1/2, 1/2]:   M = 1/6 + (3/4 (r + 1/2) - (r^3 + 1/8)/3),  N = 3/4 - r^2
        j = n + 1, r in [-3/2, -1/2]:  M = u^3/6,  N = u^2/2,  u = r + 3/2

    (left of them ``M = M(3/2)``, right of them 0; ``N = 0``; the pieces agree where they meet).
    Three divisions instead of the formula's fifteen at the five nodes of a row. Returns ``first``,
    the three ``M``, then the three ``N``."""
    first = 0 if y - c < 0.5 else 1
    nearest = c + first
    w = 1.5 - (y - (nearest - 1))
    r = y - nearest
    u = (y - (nearest + 1)) + 1.5
    return (first, _M_ABOVE + (1.0 - w * w * w) / 6.0, _SIXTH + (0.75 * (r + 0.5) - (r * r * r + 0.125) / 3.0),
            u * u * u / 6.0, 0.5 * (w * w), 0.75 - r * r, 0.5 * (u * u))


@njit(cache=True, inline="always")
def _piece(d, left, a, b, c):
    """The value at the node ``d`` places right of the first of three nodes valued ``a, b, c``:
    ``left`` before them, 0 after them (a sum of one value and zeros, no branch)."""
    return (left if d < 0 else 0.0) + (a if d == 0 else 0.0) + (b if d == 1 else 0.0) + (c if d == 2 else 0.0)


@njit(cache=True, inline="always")
def _domain(basis, a, b, top_cell, inv_spacing, x, V):
    """The row of a particle-domain basis (``GIMP`` or ``BSPLINE_GIMP``) on a
    uniform grid, in scalars, for :func:`_domain_column`: the particle's cell ``c``, the K its row
    needs (GIMP ``c_+ - c_- + 2``, the B-spline ``c_+ - c_- + 4``), the domain's ends ``c_-, c_+,
    s_-, s_+`` (:func:`_domain_ends`), ``inv_w = 1 / (s_+ - s_-)`` (GIMP: 0 for a domain inside one
    cell, which needs no division) and the B-spline's pieces at both ends (:func:`_bspline_pieces`;
    GIMP does not read them, and the compiler drops them). A flat tuple, so that no array is handed
    to a helper per particle (reference counting); a tuple of tuples failed to compile in numba's
    parallel variants."""
    c, s_lo, c_lo, s_hi, c_hi = _domain_ends(a, b, top_cell, inv_spacing, x, V)
    inv_w = 1.0 / (s_hi - s_lo) if basis == BSPLINE_GIMP or c_hi != c_lo else 0.0
    need = c_hi - c_lo + (4 if basis == BSPLINE_GIMP else 2)
    return ((c, need, c_lo, c_hi, s_lo, s_hi, inv_w)
            + _bspline_pieces(s_lo, c_lo) + _bspline_pieces(s_hi, c_hi))


@njit(cache=True, inline="always")
def _domain_column(basis, k, inv_spacing, last, D):
    """Node, ``S`` and ``G`` of column ``k`` of a particle-domain row from its :func:`_domain` scalars
    ``D`` (``last``: the last node). GIMP: :func:`_gimp_entry`. The particle-domain B-spline: the
    spline of node ``j = c_- - 1 + k`` (ghosts folded into the end nodes), ``S = (M(s_+ - j) -
    M(s_- - j)) / (s_+ - s_-)``, ``G = (N(s_+ - j) - N(s_- - j)) / (x_+ - x_-)``, ``M`` and ``N`` at
    each end from its pieces (:func:`_piece`: the columns where each end's three splines start are
    ``d_-`` and ``d_+ + c_+ - c_-``)."""
    (_, _, c_lo, c_hi, s_lo, s_hi, inv_w, d_lo, Ml_lo, M0_lo, Mr_lo, Nl_lo, N0_lo, Nr_lo,
     d_hi, Ml_hi, M0_hi, Mr_hi, Nl_hi, N0_hi, Nr_hi) = D
    if basis == GIMP:
        return _gimp_entry(k, s_lo, c_lo, s_hi, c_hi, inv_w, inv_spacing, last)
    d_hi += c_hi - c_lo
    S = (_piece(k - d_hi, _M_TOP, Ml_hi, M0_hi, Mr_hi) - _piece(k - d_lo, _M_TOP, Ml_lo, M0_lo, Mr_lo)) * inv_w
    G = ((_piece(k - d_hi, 0.0, Nl_hi, N0_hi, Nr_hi) - _piece(k - d_lo, 0.0, Nl_lo, N0_lo, Nr_lo))
         * (inv_w * inv_spacing))
    return min(max(c_lo - 1 + k, 0), last), S, G


@njit(cache=True, inline="always")
def _five(d, left, a, b, c):
    """:func:`_piece` at columns 0 .. 4 for a start ``d`` in 0 .. 2, by selecting (``left`` before
    the three values, 0 after them): the same floats, without :func:`_piece`'s four compares per
    column. A larger ``d`` (a row wider than five, which the caller rejects) gives a finite row."""
    return (a if d == 0 else left, b if d == 0 else (a if d == 1 else left), c if d == 0 else (b if d == 1 else a),
            0.0 if d == 0 else (c if d == 1 else b), c if d == 2 else 0.0)


@njit(cache=True, inline="always")
def _bspline_domain_five(inv_spacing, D):
    """``S`` and ``G`` of the particle-domain B-spline's five columns (K = 5: a domain within two
    cells) from its :func:`_domain` scalars ``D``, as a flat tuple ``S_0 .. S_4, G_0 .. G_4`` (a tuple
    of tuples fails to compile in the parallel variants): :func:`_domain_column`'s values, column for column
    the same floats, with :func:`_five` placing each end's three pieces (the low end's start ``d_-``
    is 0 or 1, the high end's ``d_+ + c_+ - c_-`` is 0 .. 2)."""
    (_, _, c_lo, c_hi, _, _, inv_w, d_lo, Ml_lo, M0_lo, Mr_lo, Nl_lo, N0_lo, Nr_lo,
     d_hi, Ml_hi, M0_hi, Mr_hi, Nl_hi, N0_hi, Nr_hi) = D
    d_hi += c_hi - c_lo
    A0, A1, A2, A3, A4 = _five(d_lo, _M_TOP, Ml_lo, M0_lo, Mr_lo)
    B0, B1, B2, B3, B4 = _five(d_hi, _M_TOP, Ml_hi, M0_hi, Mr_hi)
    a0, a1, a2, a3, a4 = _five(d_lo, 0.0, Nl_lo, N0_lo, Nr_lo)
    b0, b1, b2, b3, b4 = _five(d_hi, 0.0, Nl_hi, N0_hi, Nr_hi)
    g = inv_w * inv_spacing
    return ((B0 - A0) * inv_w, (B1 - A1) * inv_w, (B2 - A2) * inv_w, (B3 - A3) * inv_w, (B4 - A4) * inv_w,
            (b0 - a0) * g, (b1 - a1) * g, (b2 - a2) * g, (b3 - a3) * g, (b4 - a4) * g)


@njit(cache=True, inline="always")
def _uniform_domain_row(basis, nodes, inv_spacing, x, V, row, S, G):
    """The row of a particle-domain basis on a uniform grid into ``row``, ``S``, ``G`` (``row.size``
    columns; :func:`_domain`, :func:`_domain_column`); returns the particle's cell and the K it needs."""
    n_nodes = nodes.size
    D = _domain(basis, nodes[0], nodes[n_nodes - 1], n_nodes - 2, inv_spacing, x, V)
    for k in range(row.size):
        row[k], S[k], G[k] = _domain_column(basis, k, inv_spacing, n_nodes - 1, D)
    return D[0], D[1]


@njit(cache=True, inline="always")
def _bspline_domain_row(nodes, h, inv_spacing, x, V, row, S, G):
    """:func:`mpm_fem.core.shape.bspline_gimp_shape` of one particle: the splines centred at
    ``j = c_lo - 1 .. c_lo - 2 + K`` (ghosts folded into the end nodes) averaged over the domain
    ``[x - V/2, x + V/2]`` cut at the grid's ends; returns its cell and the K it needs
    (``c_hi - c_lo + 4``). On a uniform grid (``inv_spacing > 0``) from uniform-grid arithmetic
    (:func:`_uniform_domain_row`: ``M`` and ``N`` at each end of the domain from the pieces that do
    not vanish, the formula's floats), else bit for bit."""
    n_nodes = nodes.size
    K = row.size
    a, b = nodes[0], nodes[n_nodes - 1]
    h0 = h[0, 0]
    if inv_spacing > 0.0:  # uniform-grid arithmetic, the particle's one division
        return _uniform_domain_row(BSPLINE_GIMP, nodes, inv_spacing, x, V, row, S, G)
    c, _ = _locate(nodes, inv_spacing, x)
    lo = max(x - 0.5 * V, a)
    hi = min(x + 0.5 * V, b)
    c_lo, _ = _locate(nodes, inv_spacing, lo)
    c_hi, _ = _locate(nodes, inv_spacing, hi)
    y_lo, y_hi = (lo - a) / h0, (hi - a) / h0
    length = hi - lo
    for k in range(K):
        j = c_lo - 1 + k
        r_lo, r_hi = y_lo - j, y_hi - j
        row[k] = min(max(j, 0), n_nodes - 1)
        S[k] = h0 * (_bspline_antiderivative(r_hi) - _bspline_antiderivative(r_lo)) / length
        G[k] = (_bspline_value(r_hi) - _bspline_value(r_lo)) / length
    return c, c_hi - c_lo + 4


@njit(cache=True, inline="always")
def _point_row(basis, nodes, h, inv_spacing, x, row, S, G):
    """``S_ip``, ``G_ip`` of one particle of a point basis (``POINT`` or ``BSPLINE``)
    into ``row``, ``S``, ``G``; returns its cell and the K it needs (2, 4). ``h`` holds the cell
    sizes ``h_c`` and ``1 / h_c`` (the numpy step's ``1 / h_c``, computed once). The passes pick
    this or :func:`_domain_shape_row` by the compile-time ``BASIS``, so that a variant never holds
    the other's code: a branch on a helper's argument is pruned only after the helpers are inlined,
    and the dead rows of the other bases slow the cold compile (docs/performance.md)."""
    n_nodes = nodes.size
    if basis == POINT:  # point mass: S = (1 - xi, xi), G = (-1, 1)/h_c
        c, xi, inv_h = _point(nodes, h, inv_spacing, x)
        row[0], row[1] = c, c + 1
        S[0], S[1] = 1.0 - xi, xi
        G[0], G[1] = -inv_h, inv_h
        return c, 2
    if basis == BSPLINE and inv_spacing > 0.0:  # uniform grid: the three splines around the nearest node n,
        # stored as the row c-1 .. c+2 (n = c: its last entry 0; n = c + 1: its first)
        s, c = _scaled(nodes, inv_spacing, x)
        n, t, w_l, w_0, w_r = _bspline_nearest(s, n_nodes - 1)
        first = n - c  # 0 or 1
        for k in range(4):
            row[k] = min(max(c + k - 1, 0), n_nodes - 1)
            S[k], G[k] = 0.0, 0.0
        S[first], S[first + 1], S[first + 2] = w_l, w_0, w_r
        G[first], G[first + 1], G[first + 2] = ((t - 0.5) * inv_spacing, (-2.0 * t) * inv_spacing,
                                                (t + 0.5) * inv_spacing)
        return c, 4
    # a grid not uniform: the quadratic B-spline at the nodes c-1 .. c+2, ghosts folded into the ends
    c, xi = _locate(nodes, inv_spacing, x)
    for k in range(4):
        r = xi - (k - 1)
        a = abs(r)
        if a <= 0.5:
            value, slope = 0.75 - r * r, -2.0 * r
        elif a < 1.5:
            value = 0.5 * ((1.5 - a) * (1.5 - a))
            slope = -(1.5 - a) * (1.0 if r > 0 else (-1.0 if r < 0 else 0.0))
        else:
            value, slope = 0.0, 0.0
        row[k] = min(max(c + k - 1, 0), n_nodes - 1)
        S[k] = value
        G[k] = slope / h[0, 0]
    return c, 4


@njit(cache=True, inline="always")
def _domain_shape_row(basis, nodes, h, inv_spacing, x, V, row, S, G):
    """``S_ip``, ``G_ip`` of one particle of a particle-domain basis (``GIMP`` or
    ``BSPLINE_GIMP``) into ``row``, ``S``, ``G`` (length K); returns its cell and the K
    it needs (GIMP: ``c_hi - c_lo + 2``; the caller reruns with that K if it differs)."""
    n_nodes = nodes.size
    K = row.size
    if basis == BSPLINE_GIMP:
        return _bspline_domain_row(nodes, h, inv_spacing, x, V, row, S, G)
    # GIMP: hats averaged over [x - V/2, x + V/2], cut at the ends of the grid
    if inv_spacing > 0.0:
        return _uniform_domain_row(GIMP, nodes, inv_spacing, x, V, row, S, G)
    a, b = nodes[0], nodes[n_nodes - 1]
    c, _ = _locate(nodes, inv_spacing, x)
    lo = max(x - 0.5 * V, a)
    hi = min(x + 0.5 * V, b)
    c_lo, _ = _locate(nodes, inv_spacing, lo)
    c_hi, _ = _locate(nodes, inv_spacing, hi)
    need = c_hi - c_lo + 2
    length = hi - lo
    previous = -1
    for k in range(K):
        i = min(c_lo + k, n_nodes - 1)
        row[k] = i
        if i == previous:
            S[k], G[k] = 0.0, 0.0
        else:
            s_hi, phi_hi = _hat_and_integral(nodes, i, hi)
            s_lo, phi_lo = _hat_and_integral(nodes, i, lo)
            S[k] = (phi_hi - phi_lo) / length
            G[k] = (s_hi - s_lo) / length
        previous = i
    return c, need


@njit(cache=True, inline="always")
def _recomputed_row(basis, nodes, h, inv_spacing, x, q, rows, S, G, cell, r, Sl, Gl):
    """Particle q's nodes and weights into ``r``, ``Sl``, ``Gl``, and its cell, recomputed from
    ``x_q^n`` (point mass, B-spline: the same numbers as pass 1, and cheaper than reading them back).
    ``ROW`` of the point bases' passes (:mod:`mpm_fem.fused.compiler`)."""
    c, _ = _point_row(basis, nodes, h, inv_spacing, x[q], r, Sl, Gl)
    return c


@njit(cache=True, inline="always")
def _stored_row(basis, nodes, h, inv_spacing, x, q, rows, S, G, cell, r, Sl, Gl):
    """Particle q's nodes and weights into ``r``, ``Sl``, ``Gl``, and its cell, read from pass 1's
    rows (GIMP, the particle-domain B-spline). ``ROW`` of the domain bases' passes (:mod:`mpm_fem.fused.compiler`)."""
    for j in range(r.size):
        r[j], Sl[j], Gl[j] = rows[q, j], S[q, j], G[q, j]
    return cell[q]

