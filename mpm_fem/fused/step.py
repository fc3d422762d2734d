"""The fused step: :func:`mpm_fem.core.step.explicit_step` compiled, in a few passes over the particles.

The numpy step builds ``S_ip``, ``G_ip`` and makes about thirty array passes per step (scatters,
gathers, the gas update). The same step compiled with numba does each particle's work in one
loop body, so a step reads the particle state about twice (USL):

    pass 1   S_ip, G_ip at x_p^n;  m_i, P_i (and, for the gas, F_i = sum_p V_p p_p G_ip)
    grid     v_i = P_i / m_i (or M^{-1} P_i), a_i, v_i^{n+1}, boundary conditions (numpy)
    pass 2   v_p += dt sum_i S_ip a_i;  x_p += dt sum_i S_ip v_i^{n+1};  L_p = sum_i G_ip v_i^{n+1};
             the model's state update; max_p (c_p + |v_p|) for the next time step; the
             positivity and finiteness checks

(viscous Burgers, USF and MUSL add one pass each: the stress needs ``(dv/dx)_p`` before the force,
and MUSL re-projects the momentum). Every sum is taken in the numpy step's order (particles in
index order, a particle's nodes left to right) with the same operations, so the fused step equals
:func:`~mpm_fem.core.step.explicit_step` bit for bit on one thread. The grid stage calls the same numpy
functions as the numpy step (``divide_by_lumped``, ``solve_consistent``, the boundary objects), so
any :class:`~mpm_fem.core.step.Boundary` and both mass kinds are supported.

Except on a grid uniform to round-off (nodes within ``1e-9 h`` of ``x_0 + i h``): there every basis
takes uniform-grid arithmetic, ``s = (x - x_0)/h``, ``c = floor(s)``, ``xi = s - c``, its row in
closed form from ``s`` with no node coordinate read and no division per node (:func:`_point`;
the B-spline :func:`_bspline_nearest`, the three splines around the nearest node; the particle-domain
bases from the domain's ends, :func:`_domain` and :func:`_domain_column`: GIMP one division per
particle whose domain crosses a node, the particle-domain B-spline one division per particle, ``M``
and ``N`` evaluated only in the pieces that do not vanish, :func:`_bspline_pieces`, the formula's
floats). That equals the numpy step's node arithmetic to round-off (tested to 1e-12 relative over
1,000 steps), not bit for bit.
The point mass and the B-spline keep the row and the node sums of consecutive particles in
registers (:func:`_project_point`, :func:`_move_point`, :func:`_project_bspline`,
:func:`_move_bspline`); the particle-domain bases build their rows in a loop of their own, from
scalars, before they scatter (:func:`_project_domain`): an inlined helper that takes arrays costs
reference counting on every call, which made their pass 1 two to three times slower. The grid
volume reset of the point bases builds their domain rows the same way (:func:`_volume_reset`).
A grid not uniform to round-off keeps the node arithmetic, bit for bit, in every basis.

Threads (``threads > 1``): the particles are cut into ``threads`` contiguous chunks; each chunk
scatters into its own grid buffer and the buffers are summed in chunk order. The result depends
only on ``threads``, not on scheduling (deterministic), but the sums are grouped differently, so
it equals the one-thread step to round-off, not bit for bit.

The loop (``FusedStep.advance``, :func:`_advance`): between walls or Dirichlet ends with the lumped
mass, a run takes many steps in one compiled call, the grid stage, the end conditions and the time
step of :func:`mpm_fem.core.solve.run` included, in the same order as the per-step path (the same
numbers). The Dirichlet data come from the boundary's own function, called in object mode once per
step (the same floats); a reservoir that says when it acts (Burgers') ends a loop after the step it
acts on, and the run applies it and re-enters.

The plateau remedies of :class:`~mpm_fem.core.step.Stages`, with the numpy step's operations:

    flip      pass 2 blends, ``v_p <- flip (v_p + dt sum S a) + (1 - flip) sum S v^{n+1}``
              (``consts[5]``; per step and in the loop)
    xpic      m - 1 compiled passes ``P_i = sum_p S_ip m_p sum_j S_jp u_j`` (:func:`_scatter_pass`),
              each solved with the step's mass and the boundary rule of a velocity change
              (:mod:`mpm_fem.core.xpic`; per step in numpy, in the loop compiled: the lumped mass, zero
              change at the end nodes); pass 2 then sets ``v_p = sum_i S_ip (v*_i + dt a_i)``
              (``consts[6] > 0``: its nodal field comes in place of ``a_i``). Per step and in the loop.
    basis     ``"bspline_gimp"`` (code 3): the B-splines averaged over the particle domain
              (:func:`_bspline_domain_row`, :func:`_domain`); rows stored and widened as GIMP's
              (``c_hi - c_lo + 4``).
    volume    ``"grid"``: after pass 1 (without the gas force) the volume reset of the numpy step
              (:func:`mpm_fem.core.volume.grid_volume_factor`, the model's ``with_volume``), compiled in
              two passes (:func:`_volume_reset`), then the gas force of the reset state
              (:func:`_scatter_pass`). Per step and in the loop.
    reconstruct  ``"taylor"``: the force of the Taylor least-squares stress
              (:func:`mpm_fem.core.reconstruction.reconstructed_force`) in place of the particles' force,
              compiled (:func:`_taylor_force`: one pass for the cell sums, one over the cells'
              quadrature points, in the numpy order). Per step and in the loop.

Supported: the four bases (``"mpm"``, ``"gimp"``, ``"bspline"``, ``"bspline_gimp"``), USL, USF,
MUSL, lumped and consistent mass, calculated or exact acceleration, the ideal gas and viscous
Burgers (both its forces), and every remedy: the PIC/FLIP blend, XPIC(m), the grid volume and the
Taylor reconstruction. The exact stages of the error budget (an exact projection, mass or
interpolation) run compiled for the gas with USL, the lumped mass and the calculated acceleration
(:meth:`FusedStep._exact_step`): pass 1 gives the particles' sums; the grid stage is the numpy
step's own (:class:`~mpm_fem.exact_stages.stage.ExactGridStage`: the quadrature, the FE mass, the exact
nodal values; its sums compiled in :mod:`mpm_fem.exact_stages.grid_kernels`); pass 2 is the plain one with the MPM interpolation, else

    pass 2   v_p += dt (a*_p + sum_i S_ip (a_i - a*_i)),  x_p += dt ((v*_p + dt a*_p) + sum_i S_ip (v_i^{n+1} - v*_i^{n+1}))
             (:func:`_move_exact`, the exact fields at x_p^n), then
             L_p = v*_x(x_p^{n+1}, t + dt) + sum_i G_ip (v_i^{n+1} - v*_i^{n+1}) and the state update
             (:func:`_update_exact`),

with the numpy step's operations in its order (bit for bit off a uniform grid). The other exact
stages (USF, the consistent mass, Burgers) run the numpy step (:func:`supported` says which), as
does any ``kernel="numpy"`` run.
"""

from __future__ import annotations

import types

import numpy as np
from numba import njit, objmode, prange

from mpm_fem.core import frame_chunks
from mpm_fem.core.grid import Grid
from mpm_fem.core.models.burgers import ViscousBurgers
from mpm_fem.core.models.euler import IdealGas
from mpm_fem.core.particles import Particles, PositivityError
from mpm_fem.core.reconstruction import OFFSETS, force_quadrature
from mpm_fem.core.shape import Shape, basis_integrals, make_shape
from mpm_fem.exact_stages import ExactFields, ExactGridStage, GridData
from mpm_fem.exact_stages.grid_kernels import locate as _locate
from mpm_fem.core.step import SCHEMES, Dirichlet, GridState, Stages, Walls
from mpm_fem.core.transfer import solve_consistent
from mpm_fem.core.xpic import boundary_change_rule

frame_chunks.install()  # numba's compiler crosses CPython 3.11's frame-chunk starts: reuse the chunks

KERNELS = ("fused", "numpy")
GAS, BURGERS = 0, 1
_BASIS_CODE = {"mpm": 0, "gimp": 1, "bspline": 2, "bspline_gimp": 3}
_DOMAIN_BASES = (1, 3)  # the bases averaged over the particle domain: rows of varying width, stored


def supported(model, stages: Stages) -> str | None:
    """``None`` if the fused step implements this model and these stages, else the reason."""
    if not isinstance(model, (IdealGas, ViscousBurgers)):
        return f"the fused step has no kernel for the model {type(model).__name__}"
    if stages.uses_exact_fields and not (isinstance(model, IdealGas) and stages.scheme == "usl"
                                         and stages.mass in ("lumped", "exact") and stages.acceleration == "calculated"):
        return ("the exact projection, mass and interpolation stages run compiled for the gas, USL, the lumped "
                "mass and the calculated acceleration; the others run the numpy step")
    return None


def check_kernel(kernel: str, threads: int) -> None:
    """Raise ``ValueError`` for an unknown kernel or a thread count that is not an integer >= 1."""
    if kernel not in KERNELS:
        raise ValueError(f"unknown kernel {kernel!r}; choose one of {', '.join(KERNELS)}")
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or threads < 1:
        raise ValueError(f"the number of threads must be an integer >= 1, got {threads!r}")


# --------------------------------------------------------------------------- per-particle helpers
# Each repeats the numpy arithmetic of mpm_fem.core.shape / mpm_fem.core.models operation for operation.

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
    """The row of a particle-domain basis (GIMP, ``basis`` 1; the particle-domain B-spline, 3) on a
    uniform grid, in scalars, for :func:`_domain_column`: the particle's cell ``c``, the K its row
    needs (GIMP ``c_+ - c_- + 2``, the B-spline ``c_+ - c_- + 4``), the domain's ends ``c_-, c_+,
    s_-, s_+`` (:func:`_domain_ends`), ``inv_w = 1 / (s_+ - s_-)`` (GIMP: 0 for a domain inside one
    cell, which needs no division) and the B-spline's pieces at both ends (:func:`_bspline_pieces`;
    GIMP does not read them, and the compiler drops them). A flat tuple, so that no array is handed
    to a helper per particle (reference counting); a tuple of tuples failed to compile in numba's
    parallel variants."""
    c, s_lo, c_lo, s_hi, c_hi = _domain_ends(a, b, top_cell, inv_spacing, x, V)
    inv_w = 1.0 / (s_hi - s_lo) if basis == 3 or c_hi != c_lo else 0.0
    need = c_hi - c_lo + (4 if basis == 3 else 2)
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
    if basis == 1:
        return _gimp_entry(k, s_lo, c_lo, s_hi, c_hi, inv_w, inv_spacing, last)
    d_hi += c_hi - c_lo
    S = (_piece(k - d_hi, _M_TOP, Ml_hi, M0_hi, Mr_hi) - _piece(k - d_lo, _M_TOP, Ml_lo, M0_lo, Mr_lo)) * inv_w
    G = (_piece(k - d_hi, 0.0, Nl_hi, N0_hi, Nr_hi) - _piece(k - d_lo, 0.0, Nl_lo, N0_lo, Nr_lo)) * (inv_w * inv_spacing)
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
        return _uniform_domain_row(3, nodes, inv_spacing, x, V, row, S, G)
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
    """``S_ip``, ``G_ip`` of one particle of a point basis (point mass, ``basis`` 0; the B-spline, 2)
    into ``row``, ``S``, ``G``; returns its cell and the K it needs (2, 4). ``h`` holds the cell
    sizes ``h_c`` and ``1 / h_c`` (the numpy step's ``1 / h_c``, computed once). The passes pick
    this or :func:`_domain_shape_row` by the compile-time ``BASIS``, so that a variant never holds
    the other's code: a branch on a helper's argument is pruned only after the helpers are inlined,
    and the dead rows of the other bases made the cold compile of a pass up to 14 times longer."""
    n_nodes = nodes.size
    if basis == 0:  # point mass: S = (1 - xi, xi), G = (-1, 1)/h_c
        c, xi, inv_h = _point(nodes, h, inv_spacing, x)
        row[0], row[1] = c, c + 1
        S[0], S[1] = 1.0 - xi, xi
        G[0], G[1] = -inv_h, inv_h
        return c, 2
    if basis == 2 and inv_spacing > 0.0:  # uniform grid: the three splines around the nearest node n,
        # stored as the row c-1 .. c+2 (n = c: its last entry 0; n = c + 1: its first)
        s, c = _scaled(nodes, inv_spacing, x)
        n, t, w_l, w_0, w_r = _bspline_nearest(s, n_nodes - 1)
        first = n - c  # 0 or 1
        for k in range(4):
            row[k] = min(max(c + k - 1, 0), n_nodes - 1)
            S[k], G[k] = 0.0, 0.0
        S[first], S[first + 1], S[first + 2] = w_l, w_0, w_r
        G[first], G[first + 1], G[first + 2] = (t - 0.5) * inv_spacing, (-2.0 * t) * inv_spacing, (t + 0.5) * inv_spacing
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
    """``S_ip``, ``G_ip`` of one particle of a particle-domain basis (GIMP, ``basis`` 1; the
    particle-domain B-spline, 3) into ``row``, ``S``, ``G`` (length K); returns its cell and the K
    it needs (GIMP: ``c_hi - c_lo + 2``; the caller reruns with that K if it differs)."""
    n_nodes = nodes.size
    K = row.size
    if basis == 3:
        return _bspline_domain_row(nodes, h, inv_spacing, x, V, row, S, G)
    # GIMP: hats averaged over [x - V/2, x + V/2], cut at the ends of the grid
    if inv_spacing > 0.0:
        return _uniform_domain_row(1, nodes, inv_spacing, x, V, row, S, G)
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


@njit(cache=True)
def _divide_by_lumped(rhs, m_i, out):
    """:func:`~mpm_fem.core.transfer.divide_by_lumped` into ``out``: ``rhs_i / m_i`` where ``m_i > 0``, else 0."""
    for i in range(out.size):
        out[i] = rhs[i] / m_i[i] if m_i[i] > 0 else 0.0
    return out


def _chunk(n, chunks, k):
    return k * n // chunks, (k + 1) * n // chunks


_chunk = njit(cache=True, inline="always")(_chunk)


@njit(cache=True, inline="always")
def _recomputed_row(basis, nodes, h, inv_spacing, x, q, rows, S, G, cell, r, Sl, Gl):
    """Particle q's nodes and weights into ``r``, ``Sl``, ``Gl``, and its cell, recomputed from
    ``x_q^n`` (point mass, B-spline: the same numbers as pass 1, and cheaper than reading them back).
    ``ROW`` of the point bases' passes (:func:`_compile`)."""
    c, _ = _point_row(basis, nodes, h, inv_spacing, x[q], r, Sl, Gl)
    return c


@njit(cache=True, inline="always")
def _stored_row(basis, nodes, h, inv_spacing, x, q, rows, S, G, cell, r, Sl, Gl):
    """Particle q's nodes and weights into ``r``, ``Sl``, ``Gl``, and its cell, read from pass 1's
    rows (GIMP, the particle-domain B-spline). ``ROW`` of the domain bases' passes (:func:`_compile`)."""
    for j in range(r.size):
        r[j], Sl[j], Gl[j] = rows[q, j], S[q, j], G[q, j]
    return cell[q]


# --------------------------------------------------------------------------- the passes
# Written once; compiled per basis and model, serial (threads = 1) or parallel (threads > 1,
# prange over the chunks). BASIS and MODEL are compile-time globals of each variant (_compile).
# The helpers below are inlined; each keeps the numpy step's order of operations.

@njit(cache=True, inline="always")
def _one_row(K):
    """Scratch for one particle's row: node indices, ``S_ip``, ``G_ip``."""
    return np.empty(K, np.intp), np.empty(K), np.empty(K)


@njit(cache=True, inline="always")
def _gather(W, f, r, K):
    """``sum_j W_j f_{r_j}``, left to right: ``(dv/dx)_p`` or ``v_p`` of one particle."""
    s = W[0] * f[r[0]]
    for j in range(1, K):
        s += W[j] * f[r[j]]
    return s


@njit(cache=True, inline="always")
def _scatter(buf, k, r, W, w, K):
    """``buf[k, 0, r_j] += W_j w``: one particle's share of a nodal sum, into chunk k's buffer."""
    for j in range(K):
        buf[k, 0, r[j]] += W[j] * w


@njit(cache=True, inline="always")
def _gather_stored(W, q, f, rows, K):
    """:func:`_gather` of particle q's stored row (``rows[q]``, ``W[q]``), read in place."""
    s = W[q, 0] * f[rows[q, 0]]
    for j in range(1, K):
        s += W[q, j] * f[rows[q, j]]
    return s


@njit(cache=True, inline="always")
def _scatter_stored(buf, k, rows, q, W, w, K):
    """:func:`_scatter` of particle q's stored row, read in place."""
    for j in range(K):
        buf[k, 0, rows[q, j]] += W[q, j] * w


@njit(cache=True, inline="always")
def _sum_chunks(buf, j, out, sign):
    """``out = sign sum_k buf[k, j]``, the chunks summed in their order."""
    for i in range(out.size):
        out[i] = sign * buf[0, j, i]
    for k in range(1, buf.shape[0]):
        for i in range(out.size):
            out[i] += sign * buf[k, j, i]


@njit(cache=True, inline="always")
def _first(bad, value_at_bad, q, value):
    """The first particle whose ``value`` is not > 0, and that value: ``(q, value)`` if none yet."""
    if bad < 0 and not (value > 0):
        return float(q), value
    return bad, value_at_bad


@njit(cache=True, inline="always")
def _new_state(gas, q, L, dt, l, V, m, rho, e, p, V_new, m_new, rho_new, e_new, p_new, consts, tally):
    """The model's update of particle q from ``L_p`` (gas: :meth:`IdealGas.update`; Burgers:
    ``V_p <- V_p (1 + L_p dt)``, ``m_p = V_p``). ``tally = (first particle with a factor <= 0, first
    with an energy <= 0 (gas), first non-finite, their two values, max speed, this particle's sound
    speed)`` is returned updated. Seven floats (indices < 2^53 are exact), not arrays: the tally
    stays in registers, and numba's parallel analysis takes it (it mistakes integer tuples for shapes)."""
    bad_f, bad_e, bad_n, val_f, val_e, top, _ = tally
    if gas:
        factor, rho_new[q], e_new[q], p_new[q], V_new[q], c = _gas_update(
            rho[q], e[q], p[q], m[q], L, dt, l, consts[0], consts[1], consts[2], consts[3])
        bad_e, val_e = _first(bad_e, val_e, q, e_new[q])
    else:
        factor, c = 1.0 + L * dt, 0.0
        V_new[q] = V[q] * factor
        m_new[q] = V_new[q]
    bad_f, val_f = _first(bad_f, val_f, q, factor)
    return bad_f, bad_e, bad_n, val_f, val_e, top, c


@njit(cache=True, inline="always")
def _checked(gas, q, c, x_new, v_new, rho_new, e_new, p_new, V_new, tally):
    """The tally with ``max(top, c_p + |v_p|)`` (gas) or ``max(top, |v_p|)``, and the first
    non-finite particle."""
    bad_f, bad_e, bad_n, val_f, val_e, top, _ = tally
    if gas:
        top = max(top, c + abs(v_new[q]))
        ok = _finite(x_new[q], v_new[q], rho_new[q], e_new[q], p_new[q], V_new[q])
    else:
        top = max(top, abs(v_new[q]))
        ok = _finite(x_new[q], v_new[q], V_new[q], 0.0, 0.0, 0.0)
    if bad_n < 0 and not ok:
        bad_n = float(q)
    return bad_f, bad_e, bad_n, val_f, val_e, top, c


@njit(cache=True, inline="always")
def _flags(k, tally, flags, values):
    """Chunk k's tally into the pass's outputs: ``flags[k]`` (the first bad particles: factor,
    energy and, if it has three columns, non-finite), ``values[k]`` (the two values); returns the speed."""
    flags[k, 0], flags[k, 1] = int(tally[0]), int(tally[1])
    if flags.shape[1] > 2:
        flags[k, 2] = int(tally[2])
    values[k, 0], values[k, 1] = tally[3], tally[4]
    return tally[5]


_NO_TALLY = (-1.0, -1.0, -1.0, 0.0, 0.0, 0.0, 0.0)  # no bad particle yet, speed 0


@njit(cache=True, inline="always")
def _project_point(nodes, h, inv_spacing, x, V, m, v, p, gas_force, store, lo, hi, rows, S, G, cell, buf):
    """Pass 1 of the point mass over particles ``lo .. hi-1``: ``buf[0..2]`` += ``m_p S_ip``,
    ``m_p v_p S_ip``, ``V_p p_p G_ip`` (the last if ``gas_force``). Each node's terms are added in
    particle order, as in :func:`_project` (the same numbers), but a cell's two node sums stay in
    registers while consecutive particles share the cell (sorted particles: ``ppc`` in a row), and
    go back to ``buf`` when the cell changes: one load and store per cell instead of one per term.
    Returns the first particle outside the grid (-1 if none)."""
    n_nodes = nodes.size
    a, b = nodes[0], nodes[n_nodes - 1]
    outside, held = -1, -1  # held: the cell whose node sums are in registers
    m0 = m1 = P0 = P1 = F0 = F1 = 0.0
    for q in range(lo, hi):
        if not (x[q] >= a and x[q] <= b):
            if outside < 0:
                outside = q
            continue
        c, xi, inv_h = _point(nodes, h, inv_spacing, x[q])  # the row (c, c + 1), (1 - xi, xi), (-1, 1)/h_c
        S0 = 1.0 - xi
        cell[q] = c
        if store:
            rows[q, 0], S[q, 0], G[q, 0] = c, S0, -inv_h
            rows[q, 1], S[q, 1], G[q, 1] = c + 1, xi, inv_h
        if c != held:
            if held >= 0:
                buf[0, held], buf[1, held], buf[2, held] = m0, P0, F0
                buf[0, held + 1], buf[1, held + 1], buf[2, held + 1] = m1, P1, F1
            m0, P0, F0 = buf[0, c], buf[1, c], buf[2, c]
            m1, P1, F1 = buf[0, c + 1], buf[1, c + 1], buf[2, c + 1]
            held = c
        mv = m[q] * v[q]
        m0 += S0 * m[q]
        P0 += S0 * mv
        m1 += xi * m[q]
        P1 += xi * mv
        if gas_force:
            Vp = V[q] * p[q]
            F0 += -inv_h * Vp
            F1 += inv_h * Vp
    if held >= 0:
        buf[0, held], buf[1, held], buf[2, held] = m0, P0, F0
        buf[0, held + 1], buf[1, held + 1], buf[2, held + 1] = m1, P1, F1
    return outside


@njit(cache=True, inline="always")
def _project_bspline(nodes, inv_spacing, x, V, m, v, p, gas_force, store, lo, hi, rows, S, G, cell, buf):
    """Pass 1 of the B-spline on a uniform grid over particles ``lo .. hi-1``, as
    :func:`_project_point`: the row from :func:`_bspline_nearest` (three nodes around the nearest
    node ``n``), and the three nodes' sums held in registers while consecutive particles share ``n``
    (each node's terms still added in particle order). A particle whose nearest node is an end node
    (its ghost spline folded into it) adds into ``buf`` directly. Returns the first particle outside
    the grid (-1 if none)."""
    n_nodes = nodes.size
    top = n_nodes - 1
    a, b = nodes[0], nodes[top]
    outside, held = -1, -1  # held: the nearest node whose three node sums are in registers
    m0 = m1 = m2 = P0 = P1 = P2 = F0 = F1 = F2 = 0.0
    for q in range(lo, hi):
        if not (x[q] >= a and x[q] <= b):
            if outside < 0:
                outside = q
            continue
        s, c = _scaled(nodes, inv_spacing, x[q])
        n, t, w_l, w_0, w_r = _bspline_nearest(s, top)
        g_l, g_0, g_r = (t - 0.5) * inv_spacing, (-2.0 * t) * inv_spacing, (t + 0.5) * inv_spacing
        cell[q] = c
        if store:  # the row c-1 .. c+2, as _point_row stores it
            first = n - c
            for k in range(4):
                rows[q, k], S[q, k], G[q, k] = min(max(c + k - 1, 0), top), 0.0, 0.0
            S[q, first], S[q, first + 1], S[q, first + 2] = w_l, w_0, w_r
            G[q, first], G[q, first + 1], G[q, first + 2] = g_l, g_0, g_r
        mq = m[q]
        mv = mq * v[q]
        Vp = V[q] * p[q] if gas_force else 0.0
        if n == 0 or n == top:  # a ghost folded into the end node: straight into buf
            if held >= 0:
                buf[0, held - 1], buf[1, held - 1], buf[2, held - 1] = m0, P0, F0
                buf[0, held], buf[1, held], buf[2, held] = m1, P1, F1
                buf[0, held + 1], buf[1, held + 1], buf[2, held + 1] = m2, P2, F2
                held = -1
            i_l, i_r = max(n - 1, 0), min(n + 1, top)
            buf[0, i_l] += w_l * mq
            buf[1, i_l] += w_l * mv
            buf[0, n] += w_0 * mq
            buf[1, n] += w_0 * mv
            buf[0, i_r] += w_r * mq
            buf[1, i_r] += w_r * mv
            if gas_force:
                buf[2, i_l] += g_l * Vp
                buf[2, n] += g_0 * Vp
                buf[2, i_r] += g_r * Vp
            continue
        if n != held:
            if held >= 0:
                buf[0, held - 1], buf[1, held - 1], buf[2, held - 1] = m0, P0, F0
                buf[0, held], buf[1, held], buf[2, held] = m1, P1, F1
                buf[0, held + 1], buf[1, held + 1], buf[2, held + 1] = m2, P2, F2
            m0, P0, F0 = buf[0, n - 1], buf[1, n - 1], buf[2, n - 1]
            m1, P1, F1 = buf[0, n], buf[1, n], buf[2, n]
            m2, P2, F2 = buf[0, n + 1], buf[1, n + 1], buf[2, n + 1]
            held = n
        m0 += w_l * mq
        P0 += w_l * mv
        m1 += w_0 * mq
        P1 += w_0 * mv
        m2 += w_r * mq
        P2 += w_r * mv
        if gas_force:
            F0 += g_l * Vp
            F1 += g_0 * Vp
            F2 += g_r * Vp
    if held >= 0:
        buf[0, held - 1], buf[1, held - 1], buf[2, held - 1] = m0, P0, F0
        buf[0, held], buf[1, held], buf[2, held] = m1, P1, F1
        buf[0, held + 1], buf[1, held + 1], buf[2, held + 1] = m2, P2, F2
    return outside


@njit(cache=True, inline="always")
def _project_domain(basis, nodes, inv_spacing, x, V, m, v, p, gas_force, lo, hi, rows, S, G, cell, buf):
    """Pass 1 of a particle-domain basis (GIMP, ``basis`` 1; the particle-domain B-spline, 3) on a
    uniform grid over particles ``lo .. hi-1``, as the generic loop of :func:`_project` (the same
    sums in the same order) in one loop over the particles: the row from scalars (:func:`_domain`,
    then :func:`_domain_column`, or for the B-spline's five columns :func:`_bspline_domain_five`; no
    array handed to a helper per particle), stored in ``rows``, ``S``, ``G`` for pass 2 and added at
    once to ``buf[0..2]``: ``m_p S_ip``, ``m_p v_p S_ip``, ``V_p p_p G_ip`` (a second loop reading the
    stored rows back cost the B-spline's pass 1 a third more). Returns the first particle outside the
    grid, the first with ``V <= 0`` (-1 if none) and the K the rows need."""
    n_nodes = nodes.size
    K = rows.shape[1]
    last = n_nodes - 1
    a, b = nodes[0], nodes[last]
    outside, empty, need = -1, -1, 0
    for q in range(lo, hi):
        if not (x[q] >= a and x[q] <= b):
            if outside < 0:
                outside = q
            continue
        if not (V[q] > 0):
            if empty < 0:
                empty = q
            continue
        D = _domain(basis, a, b, n_nodes - 2, inv_spacing, x[q], V[q])
        need = max(need, D[1])
        cell[q] = D[0]
        mq = m[q]
        mv = mq * v[q]
        Vp = V[q] * p[q]
        if basis == 3 and K == 5:
            S0, S1, S2, S3, S4, G0, G1, G2, G3, G4 = _bspline_domain_five(inv_spacing, D)
            first = D[2] - 1  # the columns' nodes c_- - 1 + j, ghosts folded into the end nodes
            _put(q, 0, min(max(first, 0), last), S0, G0, mq, mv, Vp, gas_force, rows, S, G, buf)
            _put(q, 1, min(max(first + 1, 0), last), S1, G1, mq, mv, Vp, gas_force, rows, S, G, buf)
            _put(q, 2, min(first + 2, last), S2, G2, mq, mv, Vp, gas_force, rows, S, G, buf)
            _put(q, 3, min(first + 3, last), S3, G3, mq, mv, Vp, gas_force, rows, S, G, buf)
            _put(q, 4, min(first + 4, last), S4, G4, mq, mv, Vp, gas_force, rows, S, G, buf)
            continue
        for j in range(K):
            i, Sj, Gj = _domain_column(basis, j, inv_spacing, last, D)
            _put(q, j, i, Sj, Gj, mq, mv, Vp, gas_force, rows, S, G, buf)
    return outside, empty, need


@njit(cache=True, inline="always")
def _put(q, j, i, Sj, Gj, mq, mv, Vp, gas_force, rows, S, G, buf):
    """Column ``j`` (node ``i``) of particle ``q``'s row: stored, and its terms added to ``buf``."""
    rows[q, j], S[q, j], G[q, j] = i, Sj, Gj
    buf[0, i] += Sj * mq
    buf[1, i] += Sj * mv
    if gas_force:
        buf[2, i] += Gj * Vp


def _project(nodes, h, inv_spacing, x, V, m, v, p, gas_force, store, chunks,
             rows, S, G, cell, m_i, P_i, F_i, flags):
    """Pass 1: the shape of every particle, ``m_i``, ``P_i`` and, if ``gas_force``, ``F_i = sum_p
    V_p p_p G_ip``. The cells are stored; the rows ``rows``, ``S``, ``G`` only if ``store`` (the
    consistent mass and GIMP need them). ``flags[k] = (first particle outside the grid, first
    with V <= 0, the K it needs)`` of chunk k."""
    n = x.size
    K = WIDTH  # nodes per particle
    n_nodes = nodes.size
    a, b = nodes[0], nodes[n_nodes - 1]
    buf = np.zeros((chunks, 3, n_nodes))
    for k in prange(chunks):
        lo, hi = _chunk(n, chunks, k)
        outside, empty, need = -1, -1, 0
        r, Sl, Gl = _one_row(K)
        if BASIS == 0:  # point mass: its own loop, the sums held in registers (the loop below then skipped)
            outside, need = _project_point(nodes, h, inv_spacing, x, V, m, v, p, gas_force, store, lo, hi,
                                           rows, S, G, cell, buf[k]), 2
            lo = hi
        if BASIS == 2 and inv_spacing > 0.0:  # the B-spline on a uniform grid: likewise
            outside, need = _project_bspline(nodes, inv_spacing, x, V, m, v, p, gas_force, store, lo, hi,
                                             rows, S, G, cell, buf[k]), 4
            lo = hi
        if (BASIS == 1 or BASIS == 3) and inv_spacing > 0.0:  # the domain bases on a uniform grid: likewise
            outside, empty, need = _project_domain(BASIS, nodes, inv_spacing, x, V, m, v, p, gas_force, lo, hi,
                                                   rows, S, G, cell, buf[k])
            lo = hi
        for q in range(lo, hi):
            if not (x[q] >= a and x[q] <= b):
                if outside < 0:
                    outside = q
                continue
            if (BASIS == 1 or BASIS == 3) and not (V[q] > 0):
                if empty < 0:
                    empty = q
                continue
            if BASIS == 0 or BASIS == 2:
                c, kq = _point_row(BASIS, nodes, h, inv_spacing, x[q], r, Sl, Gl)
            else:
                c, kq = _domain_shape_row(BASIS, nodes, h, inv_spacing, x[q], V[q], r, Sl, Gl)
            cell[q] = c
            need = max(need, kq)
            if store:
                for j in range(K):
                    rows[q, j], S[q, j], G[q, j] = r[j], Sl[j], Gl[j]
            mv = m[q] * v[q]
            Vp = V[q] * p[q]
            for j in range(K):
                i = r[j]
                buf[k, 0, i] += Sl[j] * m[q]
                buf[k, 1, i] += Sl[j] * mv
                if gas_force:
                    buf[k, 2, i] += Gl[j] * Vp
        flags[k, 0], flags[k, 1], flags[k, 2] = outside, empty, need
    for j, out in enumerate((m_i, P_i, F_i)):
        _sum_chunks(buf, j, out, 1.0)


PRESSURE, VISCOUS_STRESS, MOMENTUM = 0, 1, 2  # the weights of _scatter_pass


def _scatter_pass(nodes, h, inv_spacing, x, rows, S, G, cell, f_i, a, b, coef, chunks, out):
    """One scatter over the particles, ``out_i = sum_p w_p W_ip`` (each particle's row recomputed or
    read as in pass 2), with the weight the compile-time ``WEIGHT`` picks:

        PRESSURE         W = G_ip, w_p = a_p b_p:                  the gas force ``F_i = sum_p V_p p_p G_ip``
                                                                   (after the volume reset)
        VISCOUS_STRESS   W = G_ip, w_p = a_p (coef sum_j G_jp f_j), ``out = -sum``: Burgers' force
                         ``F_i = - sum_p V_p eps (dv/dx)_p G_ip`` (its stress before the force)
        MOMENTUM         W = S_ip, w_p = a_p sum_j S_jp f_j:        XPIC's ``P_i = sum_p S_ip m_p (sum_j S_jp u_j)``
                         (:func:`mpm_fem.core.transfer.nodal_momentum` of ``shape.gather(u)``)

    (``b``, ``coef``, ``f_i``: unused where the weight does not name them)."""
    n = x.size
    K = WIDTH  # nodes per particle
    buf = np.zeros((chunks, 1, out.size))
    for k in prange(chunks):
        r, Sl, Gl = _one_row(K)
        for q in range(*_chunk(n, chunks, k)):
            if BASIS == 1 or BASIS == 3:  # the domain bases: pass 1's stored row read where it lies (the
                # same sums; copied into the row scratch first, it cost XPIC's passes a tenth more)
                if WEIGHT == PRESSURE:
                    _scatter_stored(buf, k, rows, q, G, a[q] * b[q], K)
                elif WEIGHT == VISCOUS_STRESS:
                    _scatter_stored(buf, k, rows, q, G, a[q] * (coef * _gather_stored(G, q, f_i, rows, K)), K)
                else:
                    _scatter_stored(buf, k, rows, q, S, a[q] * _gather_stored(S, q, f_i, rows, K), K)
                continue
            ROW(BASIS, nodes, h, inv_spacing, x, q, rows, S, G, cell, r, Sl, Gl)
            if WEIGHT == PRESSURE:
                _scatter(buf, k, r, Gl, a[q] * b[q], K)
            elif WEIGHT == VISCOUS_STRESS:
                _scatter(buf, k, r, Gl, a[q] * (coef * _gather(Gl, f_i, r, K)), K)
            else:
                _scatter(buf, k, r, Sl, a[q] * _gather(Sl, f_i, r, K), K)
    _sum_chunks(buf, 0, out, -1.0 if WEIGHT == VISCOUS_STRESS else 1.0)


def _update(nodes, h, inv_spacing, x, rows, S, G, cell, v_i, V, m, rho, e, p, dt, consts, force, chunks,
            V_new, m_new, rho_new, e_new, p_new, F_i, flags, values):
    """USF: the model's state update from ``L_p = sum_i G_ip v_i`` before the force, and the force
    of the updated state into ``F_i`` (if ``force``). ``flags[k] = (first particle with factor <= 0,
    first with energy <= 0)``, ``values[k]`` their values."""
    n = x.size
    K = WIDTH  # nodes per particle
    gas, eps = MODEL == GAS, consts[4]
    buf = np.zeros((chunks, 1, F_i.size))
    for k in prange(chunks):
        tally = _NO_TALLY
        r, Sl, Gl = _one_row(K)
        for q in range(*_chunk(n, chunks, k)):
            c = ROW(BASIS, nodes, h, inv_spacing, x, q, rows, S, G, cell, r, Sl, Gl)
            L = _gather(Gl, v_i, r, K)
            tally = _new_state(gas, q, L, dt, h[0, c], V, m, rho, e, p, V_new, m_new, rho_new, e_new, p_new, consts,
                               tally)
            if force:
                _scatter(buf, k, r, Gl, V_new[q] * p_new[q] if gas else -(V_new[q] * (eps * L)), K)
        _flags(k, tally, flags, values)
    if force:
        _sum_chunks(buf, 0, F_i, 1.0)


@njit(cache=True, inline="always")
def _move_point(nodes, h, inv_spacing, a_i, v_n, x, V, m, v, rho, e, p, dt, consts, gas, lo, hi,
                x_new, v_new, V_new, m_new, rho_new, e_new, p_new, tally):
    """Pass 2 of the point mass, USL, over particles ``lo .. hi-1``: :func:`_move`'s arithmetic with
    the row ``(c, c + 1)``, ``(1 - xi, xi)``, ``(-1, 1)/h_c`` held in registers. Returns the tally."""
    for q in range(lo, hi):
        c, xi, inv_h = _point(nodes, h, inv_spacing, x[q])
        S0 = 1.0 - xi
        v_new[q] = v[q] + dt * (S0 * a_i[c] + xi * a_i[c + 1])
        x_new[q] = x[q] + dt * (S0 * v_n[c] + xi * v_n[c + 1])
        L = -inv_h * v_n[c] + inv_h * v_n[c + 1]
        tally = _new_state(gas, q, L, dt, h[0, c], V, m, rho, e, p, V_new, m_new, rho_new, e_new, p_new, consts, tally)
        tally = _checked(gas, q, tally[6], x_new, v_new, rho_new, e_new, p_new, V_new, tally)
    return tally


@njit(cache=True, inline="always")
def _move_bspline(nodes, h, inv_spacing, a_i, v_n, x, V, m, v, rho, e, p, dt, consts, gas, lo, hi,
                  x_new, v_new, V_new, m_new, rho_new, e_new, p_new, tally):
    """Pass 2 of the B-spline on a uniform grid, USL, over particles ``lo .. hi-1``: :func:`_move`'s
    arithmetic with the row of :func:`_bspline_nearest` in registers. Returns the tally."""
    top = nodes.size - 1
    for q in range(lo, hi):
        s, c = _scaled(nodes, inv_spacing, x[q])
        n, t, w_l, w_0, w_r = _bspline_nearest(s, top)
        i_l, i_r = max(n - 1, 0), min(n + 1, top)
        v_new[q] = v[q] + dt * (w_l * a_i[i_l] + w_0 * a_i[n] + w_r * a_i[i_r])
        x_new[q] = x[q] + dt * (w_l * v_n[i_l] + w_0 * v_n[n] + w_r * v_n[i_r])
        L = ((t - 0.5) * inv_spacing) * v_n[i_l] + ((-2.0 * t) * inv_spacing) * v_n[n] \
            + ((t + 0.5) * inv_spacing) * v_n[i_r]
        tally = _new_state(gas, q, L, dt, h[0, c], V, m, rho, e, p, V_new, m_new, rho_new, e_new, p_new, consts, tally)
        tally = _checked(gas, q, tally[6], x_new, v_new, rho_new, e_new, p_new, V_new, tally)
    return tally


def _move(nodes, h, inv_spacing, rows, S, G, cell, a_i, v_n, x, V, m, v, rho, e, p, dt, consts, usl, musl, chunks,
          x_new, v_new, V_new, m_new, rho_new, e_new, p_new, P_i, flags, values, speed):
    """Pass 2: ``v_p += dt sum S a``, ``x_p += dt sum S v^{n+1}``; USL: the state update from
    ``L_p = sum G v^{n+1}``; MUSL: ``P_i = sum_p m_p v_p^{n+1} S_ip``. The blend ``consts[5]``
    (FLIP 1) mixes in ``sum S v^{n+1}``; with ``consts[6] > 0`` (XPIC) ``a_i`` holds ``v* + dt a``
    and ``v_p = sum S a_i``. ``speed[k]``: max of
    ``c_p + |v_p|`` (gas) or ``|v_p|`` (Burgers) over chunk k; ``flags[k] = (first bad factor,
    first bad energy, first non-finite particle)``."""
    n = x.size
    K = WIDTH  # nodes per particle
    gas, g_gm1 = MODEL == GAS, consts[1]
    flip = consts[5] if consts.size > 5 else 1.0  # the PIC/FLIP blend (a shorter consts: FLIP)
    pic = consts.size > 6 and consts[6] > 0  # XPIC: a_i holds v* + dt a (module docstring)
    buf = np.zeros((chunks if musl else 1, 1, P_i.size))
    for k in prange(chunks):
        tally = _NO_TALLY
        r, Sl, Gl = _one_row(K)
        lo, hi = _chunk(n, chunks, k)
        if BASIS == 0 and usl and flip == 1.0 and not pic:  # point mass, USL, FLIP: its own loop, the row in
            # registers (the loop below then skipped)
            tally = _move_point(nodes, h, inv_spacing, a_i, v_n, x, V, m, v, rho, e, p, dt, consts, gas, lo, hi,
                                x_new, v_new, V_new, m_new, rho_new, e_new, p_new, tally)
            lo = hi
        if BASIS == 2 and inv_spacing > 0.0 and usl and flip == 1.0 and not pic:  # the B-spline on a uniform
            # grid, likewise
            tally = _move_bspline(nodes, h, inv_spacing, a_i, v_n, x, V, m, v, rho, e, p, dt, consts, gas, lo, hi,
                                  x_new, v_new, V_new, m_new, rho_new, e_new, p_new, tally)
            lo = hi
        for q in range(lo, hi):
            if BASIS == 1 or BASIS == 3:  # the domain bases: pass 1's stored row read where it lies, and USL's
                cq = cell[q]  # L_p (_gather's sum) in the same loop (copied into the row scratch first, it cost
                i = rows[q, 0]  # their loop 5-8%)
                acc, vel, L = S[q, 0] * a_i[i], S[q, 0] * v_n[i], G[q, 0] * v_n[i]
                for j in range(1, K):
                    i = rows[q, j]
                    acc += S[q, j] * a_i[i]
                    vel += S[q, j] * v_n[i]
                    L += G[q, j] * v_n[i]
            else:
                cq = ROW(BASIS, nodes, h, inv_spacing, x, q, rows, S, G, cell, r, Sl, Gl)
                acc = Sl[0] * a_i[r[0]]
                vel = Sl[0] * v_n[r[0]]
                for j in range(1, K):
                    acc += Sl[j] * a_i[r[j]]
                    vel += Sl[j] * v_n[r[j]]
            if pic:
                v_new[q] = acc
            else:
                v_new[q] = v[q] + dt * acc
                if flip != 1.0:
                    v_new[q] = flip * v_new[q] + (1.0 - flip) * vel
            x_new[q] = x[q] + dt * vel
            if musl:
                if BASIS == 1 or BASIS == 3:
                    _scatter_stored(buf, k, rows, q, S, m[q] * v_new[q], K)
                else:
                    _scatter(buf, k, r, Sl, m[q] * v_new[q], K)
                continue
            if usl:
                if BASIS != 1 and BASIS != 3:
                    L = _gather(Gl, v_n, r, K)
                tally = _new_state(gas, q, L, dt, h[0, cq], V, m, rho, e, p,
                                   V_new, m_new, rho_new, e_new, p_new, consts, tally)
                c = tally[6]
            else:
                c = np.sqrt(g_gm1 * max(e_new[q], 0.0)) if gas else 0.0
            tally = _checked(gas, q, c, x_new, v_new, rho_new, e_new, p_new, V_new, tally)
        speed[k] = _flags(k, tally, flags, values)
    if musl:
        _sum_chunks(buf, 0, P_i, 1.0)


def _volume_reset(nodes, h, inv_spacing, x, rows, S, V, m, rho, e, p, integrals, consts, chunks, width,
                  V_i, ratio, V_r, rho_r, p_r, flags, values):
    """The grid volume reset (:func:`mpm_fem.core.volume.grid_volume_factor`, then the model's
    ``with_volume``): ``V_i = sum_p V_p Sbar_ip``, ``f_p = sum_i Sbar_ip (int S_i / V_i)`` (0 where
    ``V_i = 0``; ``integrals`` holds ``int S_i``), ``V_p <- V_p f_p`` into ``V_r``; the gas at the same
    mass and specific energy, ``rho_p = m_p / V_p``, ``p_p = (gamma - 1) rho_p eps_p + q_p rho_p /
    rho_p^old`` (``q_p`` its viscosity) into ``rho_r``, ``p_r`` (Burgers: ``m_p = V_p``, which its
    update sets anyway). The domain rows take ``width`` columns. ``flags[k] = (first particle of
    chunk k whose new density (gas) or volume (Burgers) is not > 0, the width its rows need)``,
    ``values[k, 0]`` that density or volume."""
    n = x.size
    gas = MODEL == GAS
    # Sbar_ip: the step's stored rows (the domain bases), or the rows of DOMAIN (the point bases: GIMP
    # for the point mass, the particle-domain B-spline for the B-spline; _compile), on a uniform grid
    # from scalars as pass 1 of those bases builds them. The basis is tested in the loop, on the
    # compile-time constants: flags set in branches before a prange loop (`fresh = ... and ...`)
    # gave NaN particles in a parallel variant called by the loop (numba 0.68.1). The scalar rows
    # are written out here: an inlined helper handed `buf` or `ratio` cost 16 ns per particle-step
    a, b, last = nodes[0], nodes[nodes.size - 1], nodes.size - 1
    buf = np.zeros((chunks, 1, V_i.size))
    for k in prange(chunks):
        r, Sl, Gl = _one_row(width)
        need = 0
        for q in range(*_chunk(n, chunks, k)):
            if BASIS == 1 or BASIS == 3:  # the step's own rows, read where they lie
                need = width
                _scatter_stored(buf, k, rows, q, S, V[q], width)
            elif inv_spacing > 0.0:
                D = _domain(DOMAIN, a, b, last - 1, inv_spacing, x[q], V[q])
                need = max(need, D[1])
                for j in range(width):
                    i, s, _ = _domain_column(DOMAIN, j, inv_spacing, last, D)
                    buf[k, 0, i] += s * V[q]
            else:
                need = max(need, _domain_shape_row(DOMAIN, nodes, h, inv_spacing, x[q], V[q], r, Sl, Gl)[1])
                _scatter(buf, k, r, Sl, V[q], width)
        flags[k, 1] = need
    _sum_chunks(buf, 0, V_i, 1.0)
    _divide_by_lumped(integrals, V_i, ratio)
    gm1 = consts[0]
    for k in prange(chunks):
        r, Sl, Gl = _one_row(width)
        bad, value = -1.0, 0.0
        for q in range(*_chunk(n, chunks, k)):
            if BASIS == 1 or BASIS == 3:
                V_r[q] = V[q] * _gather_stored(S, q, ratio, rows, width)
            elif inv_spacing > 0.0:  # sum_j Sbar_qj ratio_j, left to right (_gather's order)
                D = _domain(DOMAIN, a, b, last - 1, inv_spacing, x[q], V[q])
                f = 0.0
                for j in range(width):
                    i, s, _ = _domain_column(DOMAIN, j, inv_spacing, last, D)
                    f = s * ratio[i] if j == 0 else f + s * ratio[i]
                V_r[q] = V[q] * f
            else:
                _domain_shape_row(DOMAIN, nodes, h, inv_spacing, x[q], V[q], r, Sl, Gl)
                V_r[q] = V[q] * _gather(Sl, ratio, r, width)
            if gas:
                rho_r[q] = m[q] / V_r[q]
                viscosity = p[q] - gm1 * rho[q] * e[q]
                p_r[q] = gm1 * rho_r[q] * e[q] + viscosity * rho_r[q] / rho[q]
                bad, value = _first(bad, value, q, rho_r[q])
            else:
                bad, value = _first(bad, value, q, V_r[q])
        flags[k, 0], values[k, 0] = int(bad), value


def _taylor_force(nodes, h, inv_spacing, x, rows, S, G, cell, p, v_i, eps, points, G_q, weights, offsets, chunks,
                  sums, F_i):
    """The reconstructed force (:func:`mpm_fem.core.reconstruction.reconstructed_force`, the same
    operations): the stress ``sigma_p`` (gas ``-p_p``; Burgers ``eps sum_i G_ip v_i``) fitted cell by
    cell by ``s0_c + s1_c (xi - 1/2)`` (:func:`~mpm_fem.core.reconstruction.taylor_fit`: the sums of 1,
    ``d``, ``d^2``, ``sigma``, ``sigma d`` over a cell's particles in index order, ``d = xi_p - 1/2``,
    into ``sums``), then ``F_i = - sum_g w_g sigma_h(x_g) S_i'(x_g)`` over the four points ``x_g`` of
    every cell (:func:`~mpm_fem.core.reconstruction.force_quadrature`: their nodes ``points``, ``S_i'`` in
    ``G_q``, ``w_g = h_c / 4``; ``offsets``: ``xi_g - 1/2``), point by point."""
    n = x.size
    K = WIDTH  # nodes per particle
    gas = MODEL == GAS
    n_cells = sums.shape[1]
    buf = np.zeros((chunks, 5, n_cells))
    for k in prange(chunks):
        r, Sl, Gl = _one_row(K)
        for q in range(*_chunk(n, chunks, k)):
            if gas:
                sigma = -p[q]
            else:
                ROW(BASIS, nodes, h, inv_spacing, x, q, rows, S, G, cell, r, Sl, Gl)
                sigma = eps * _gather(Gl, v_i, r, K)
            c, xi = _locate(nodes, inv_spacing, x[q])
            d = xi - 0.5
            buf[k, 0, c] += 1.0
            buf[k, 1, c] += d
            buf[k, 2, c] += d * d
            buf[k, 3, c] += sigma
            buf[k, 4, c] += sigma * d
    for j in range(5):
        _sum_chunks(buf, j, sums[j], 1.0)
    F_i[:] = 0.0
    per_cell = offsets.size
    for c in range(n_cells):
        count, sd, sdd, sq, sqd = sums[0, c], sums[1, c], sums[2, c], sums[3, c], sums[4, c]
        det = count * sdd - sd * sd
        least = max(count, 1.0)
        s1 = (count * sqd - sd * sq) / det if det > 1e-12 * (least * least) else 0.0
        s0 = (sq - s1 * sd) / count if count > 0 else 0.0
        for g in range(c * per_cell, (c + 1) * per_cell):
            w_sigma = weights[g] * (s0 + s1 * offsets[g - c * per_cell])
            for j in range(points.shape[1]):
                F_i[points[g, j]] += G_q[g, j] * w_sigma
    for i in range(F_i.size):
        F_i[i] = -F_i[i]


def _finish(nodes, h, inv_spacing, x, rows, S, G, cell, v_n, V, m, v, rho, e, p, dt, consts, chunks,
            V_new, m_new, rho_new, e_new, p_new, x_new, flags, values, speed):
    """MUSL's last pass: the state update from ``L_p = sum_i G_ip v_i^{n+1}`` (re-projected; the
    shape at ``x_p^n``), the speed and the checks, as in :func:`_move`."""
    n = x.size
    K = WIDTH  # nodes per particle
    gas = MODEL == GAS
    for k in prange(chunks):
        r, Sl, Gl = _one_row(K)
        tally = _NO_TALLY
        for q in range(*_chunk(n, chunks, k)):
            cq = ROW(BASIS, nodes, h, inv_spacing, x, q, rows, S, G, cell, r, Sl, Gl)
            tally = _new_state(gas, q, _gather(Gl, v_n, r, K), dt, h[0, cq], V, m, rho, e, p,
                               V_new, m_new, rho_new, e_new, p_new, consts, tally)
            tally = _checked(gas, q, tally[6], x_new, v, rho_new, e_new, p_new, V_new, tally)
        speed[k] = _flags(k, tally, flags, values)


def _move_exact(nodes, h, inv_spacing, rows, S, G, cell, a_c, v_c, p_v, p_a, x, v, dt, chunks, x_new, v_new, L_c):
    """Pass 2 of a step with the exact interpolation (:func:`mpm_fem.core.step.explicit_step`), before its
    state update: with ``a_c = a_i - a*_i`` and ``v_c = v_i^{n+1} - v*_i^{n+1}`` (the nodal values
    less the exact ones, the boundary rule applied to both) and ``p_v = v*(x_p^n)``, ``p_a = a*(x_p^n)``,

        v_p <- v_p + dt (p_a + sum_i S_ip a_c,i),
        x_p <- x_p + dt ((p_v + dt p_a) + sum_i S_ip v_c,i),       L_c,p = sum_i G_ip v_c,i,

    the numpy step's operations in its order (``L_p = v*_x(x_p^{n+1}, t + dt) + L_c,p`` follows)."""
    n = x.size
    K = WIDTH  # nodes per particle
    for k in prange(chunks):
        r, Sl, Gl = _one_row(K)
        for q in range(*_chunk(n, chunks, k)):
            ROW(BASIS, nodes, h, inv_spacing, x, q, rows, S, G, cell, r, Sl, Gl)
            acc = p_a[q] + _gather(Sl, a_c, r, K)
            moving = p_v[q] + dt * p_a[q] + _gather(Sl, v_c, r, K)
            v_new[q] = v[q] + dt * acc
            x_new[q] = x[q] + dt * moving
            L_c[q] = _gather(Gl, v_c, r, K)


def _update_exact(h, cell, L, x_new, v_new, V, m, rho, e, p, dt, consts, chunks, V_new, m_new, rho_new, e_new,
                  p_new, flags, values, speed):
    """The state update of :func:`_move_exact`'s particles from their ``L_p`` (USL, the cell of
    ``x_p^n``), with pass 2's checks: ``speed[k]``, ``flags[k]``, ``values[k]`` as :func:`_move`'s."""
    n = x_new.size
    gas = MODEL == GAS
    for k in prange(chunks):
        tally = _NO_TALLY
        for q in range(*_chunk(n, chunks, k)):
            tally = _new_state(gas, q, L[q], dt, h[0, cell[q]], V, m, rho, e, p, V_new, m_new, rho_new, e_new, p_new,
                               consts, tally)
            tally = _checked(gas, q, tally[6], x_new, v_new, rho_new, e_new, p_new, V_new, tally)
        speed[k] = _flags(k, tally, flags, values)


@njit(cache=True, inline="always")
def _pymin(a, b):
    """Python's ``min(a, b)``: ``b`` only if ``b < a`` (NaN and ties as in :func:`mpm_fem.core.solve.run`)."""
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


def _advance(nodes, h, inv_spacing, ends, consts, chunks, state, cur, t, T, speed, fixed_dt, cfl, h_min,
             refine, viscous_limit, steps, max_steps, budget, cell, rows, S, G, grid, flags, upd, values, speeds,
             dirichlet, window, exact, xpic, volume_width, integrals, reset, points, G_q, weights, offsets, sums):
    """Up to ``budget`` steps of :meth:`FusedStep.step` between walls with the lumped mass, each with
    the time step :func:`mpm_fem.core.solve.run` takes (``dt = min(dt_CFL / refine, T - t)``, ``dt_CFL``
    from the previous step's ``speed``, or ``fixed_dt`` if > 0). The particles alternate between
    ``state[cur]`` and ``state[1 - cur]`` (fields in the order x, v, V, m, rho, eps, p). Stops before
    a step that would fail or leave this path (the time step not positive and finite, ``max_steps``,
    a particle outside the grid, a GIMP row of another width, lost positivity, a non-finite state):
    the caller takes that step with :meth:`FusedStep.step`, which raises as the numpy step does.
    With ``dirichlet`` the ends take :class:`~mpm_fem.core.step.Dirichlet`'s data instead of the walls'
    zeros (as its ``velocity`` and ``acceleration``: ``v_b = g(t)``, ``a_b = (g(t + dt) - v_b) / dt``,
    MUSL's re-projection ``g(t + dt)``), ``g`` evaluated in object mode once per step
    (:func:`_end_values`). A non-empty ``window = (a, b, spacing)`` stops the loop after the first
    step whose particles the reservoir would change (:func:`_reservoir_quiet`): the caller applies it.
    With ``exact`` the nodal acceleration is the problem's exact one (:func:`_exact_acceleration`, in
    object mode), and no viscous force is computed.
    The remedies: ``xpic = m > 0``, XPIC(m) as :meth:`FusedStep._xpic_target` with the lumped mass
    (``m - 1`` passes :func:`_scatter_pass`, each divided by ``m_i``, the change zero at the end
    nodes); ``volume_width > 0``, the grid volume reset (:func:`_volume_reset`, domain rows that wide,
    ``integrals = int S_i``, the reset state in ``reset[0]``) and then the force of the reset state;
    the Taylor reconstruction, the reconstructed force (:func:`_taylor_force`, its quadrature
    ``points``, ``G_q``, ``weights``, ``offsets``, scratch ``sums``) in place of the particles' force.
    ``grid`` holds :func:`_nodal_rows` nodal arrays: 7, then XPIC's 4 and the volume reset's 2 where
    they run. The scheme and which remedies run are compile-time constants of the variant
    (``SCHEME``, ``XPIC_ON``, ``VOLUME_ON``, ``TAYLOR_ON``; the run-time ``xpic`` and
    ``volume_width`` give XPIC's m and the rows' width): the other branches are pruned, and their
    passes (``None`` in the variant's scope) never compile.
    Returns ``(cur, t, steps taken, speed, dt_min, dt_max)``."""
    n = cell.size
    gas = MODEL == GAS
    eps = consts[4]
    store = BASIS == 1 or BASIS == 3
    m_i, P_i, F_i, v_i, a_i, v_n, P_musl = grid[0], grid[1], grid[2], grid[3], grid[4], grid[5], grid[6]
    done, dt_min, dt_max = 0, np.inf, -np.inf
    g_t, g_next, known = np.empty(0), np.empty(0), False  # Dirichlet data at t and t + dt
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
        x, v, V, m, rho, e, p = state[cur, 0, :n], state[cur, 1, :n], state[cur, 2, :n], state[cur, 3, :n], \
            state[cur, 4, :n], state[cur, 5, :n], state[cur, 6, :n]
        o = 1 - cur
        x_n, v_new, V_n, m_n, rho_n, e_n, p_n = state[o, 0, :n], state[o, 1, :n], state[o, 2, :n], state[o, 3, :n], \
            state[o, 4, :n], state[o, 5, :n], state[o, 6, :n]
        PROJECT(nodes, h, inv_spacing, x, V, m, v, p, gas and SCHEME != 1 and not VOLUME_ON and not TAYLOR_ON,
                store, chunks, rows, S, G, cell, m_i, P_i, F_i, flags)
        need = 2
        for k in range(chunks):
            need = max(need, flags[k, 2])
        if (flags[:, :2] >= 0).any() or (store and need != WIDTH and n > 0):
            break
        _lumped_walls(P_i, m_i, ends, v_i)
        if dirichlet:
            if not known:
                with objmode(g_t="float64[::1]"):
                    g_t = _end_values(t)
                known = True
            t_next = t + dt
            with objmode(g_next="float64[::1]"):
                g_next = _end_values(t_next)
            _set_ends(ends, g_t, v_i)
        if VOLUME_ON:  # the volume reset, then the force of the reset state
            V_i = _nodal_rows(XPIC_ON, 0)  # its V_i and ratio follow XPIC's arrays
            VOLUME(nodes, h, inv_spacing, x, rows, S, V, m, rho, e, p, integrals, consts, chunks,
                   WIDTH if store else volume_width, grid[V_i], grid[V_i + 1], reset[0, 0, :n], reset[0, 1, :n],
                   reset[0, 2, :n], upd, values)
            wide = 0
            for k in range(chunks):
                wide = max(wide, upd[k, 1])
            if (upd[:, 0] >= 0).any() or (not store and wide > volume_width):
                break
            V = reset[0, 0, :n]
            if gas:
                rho, p = reset[0, 1, :n], reset[0, 2, :n]
                if SCHEME != 1 and not exact and not TAYLOR_ON:
                    GAS_FORCE(nodes, h, inv_spacing, x, rows, S, G, cell, v_i, V, p, 0.0, chunks, F_i)
        if SCHEME == 1:  # USF: the state first, then its force
            UPDATE(nodes, h, inv_spacing, x, rows, S, G, cell, v_i, V, m, rho, e, p, dt, consts, not exact and not TAYLOR_ON,
                   chunks, V_n, m_n, rho_n, e_n, p_n, F_i, upd, values)
            if (upd >= 0).any():
                break
        elif not gas and not exact and not TAYLOR_ON:
            VISCOUS(nodes, h, inv_spacing, x, rows, S, G, cell, v_i, V, V, eps, chunks, F_i)
        if TAYLOR_ON and not exact:
            TAYLOR(nodes, h, inv_spacing, x, rows, S, G, cell, p_n if SCHEME == 1 else p, v_i, eps, points, G_q,
                   weights, offsets, chunks, sums, F_i)
        if exact:
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
            P_x, term, v_star, target = grid[7], grid[8], grid[9], grid[10]
            term[:] = v_i
            v_star[:] = v_i
            for _ in range(xpic - 1):
                XPIC(nodes, h, inv_spacing, x, rows, S, G, cell, term, m, m, 0.0, chunks, P_x)
                _divide_by_lumped(P_x, m_i, P_x)
                for i in range(term.size):
                    term[i] = term[i] - P_x[i]
                for i in ends:
                    term[i] = 0.0
                for i in range(term.size):
                    v_star[i] += term[i]
            for i in range(target.size):
                target[i] = v_star[i] + dt * a_i[i]
        usl, musl = SCHEME == 0, SCHEME == 2  # run-time flags: the per-step path's compiled MOVE
        if SCHEME == 0:
            MOVE(nodes, h, inv_spacing, rows, S, G, cell, target, v_n, x, V, m, v, rho, e, p, dt, consts, usl, musl,
                 chunks, x_n, v_new, V_n, m_n, rho_n, e_n, p_n, P_musl, flags, values, speeds)
        elif SCHEME == 1:
            MOVE(nodes, h, inv_spacing, rows, S, G, cell, target, v_n, x, V_n, m, v, rho_n, e_n, p_n, dt, consts, usl,
                 musl, chunks, x_n, v_new, V_n, m_n, rho_n, e_n, p_n, P_musl, flags, values, speeds)
        else:  # MUSL: move, re-project the momentum, then the state
            MOVE(nodes, h, inv_spacing, rows, S, G, cell, target, v_n, x, V, m, v, rho, e, p, dt, consts, usl, musl,
                 chunks, x_n, v_new, V, m, rho, e, p, P_musl, flags, values, speeds)
            _lumped_walls(P_musl, m_i, ends, v_n)
            if dirichlet:
                _set_ends(ends, g_next, v_n)
            FINISH(nodes, h, inv_spacing, x, rows, S, G, cell, v_n, V, m, v_new, rho, e, p, dt, consts, chunks,
                   V_n, m_n, rho_n, e_n, p_n, x_n, flags, values, speeds)
        if (flags >= 0).any():
            break
        speed = speeds.max()
        cur = 1 - cur
        t += dt
        done += 1
        dt_min, dt_max = min(dt_min, dt), max(dt_max, dt)
        g_t = g_next
        if window.size and not _reservoir_quiet(state[cur, 0, :n], window):
            break  # the particle boundary acts on these particles: the caller's
    return cur, t, done, speed, dt_min, dt_max


def _compile(fn, parallel, passes=None, **constants):
    """``fn`` compiled serial or parallel, with ``constants`` (``BASIS``, ``MODEL``) as compile-time
    globals, so that the branches of the other bases and models drop out; each variant has its own
    name, which keeps the on-disk caches apart. ``passes``: further globals (the compiled passes
    the loop calls)."""
    suffix = "".join(f"_{k.lower()}{v}" for k, v in constants.items()) + ("_parallel" if parallel else "")
    scope = dict(fn.__globals__, **constants, **(passes or {}))
    if "BASIS" in constants:  # ROW: pass 2's row, read back or recomputed; DOMAIN: the domain basis whose
        basis = constants["BASIS"]  # rows the grid volume reset averages over (the point bases': GIMP, the
        scope.update(ROW=_stored_row if basis % 2 else _recomputed_row, DOMAIN=basis | 1)  # particle-domain B-spline)
    variant = types.FunctionType(fn.__code__, scope, fn.__name__ + suffix, fn.__defaults__)
    variant.__qualname__ = variant.__name__
    return njit(cache=True, parallel=parallel)(variant)


BASIS, MODEL, WIDTH, WEIGHT = 0, 0, 3, 0  # replaced per compiled variant
SCHEME, XPIC_ON, VOLUME_ON, TAYLOR_ON = 0, 0, 0, 0  # the loop's, per variant: its branches of the other
# schemes and of the remedies not taken are pruned when it compiles
@njit(cache=True, inline="always")
def _nodal_rows(xpic_on, volume_on):
    """The loop's nodal scratch arrays: ``m_i``, ``P_i``, ``F_i``, ``v_i``, ``a_i``, ``v_i^{n+1}``,
    MUSL's ``P_i``; XPIC's ``P``, term, ``v*`` and target if it runs; the volume reset's ``V_i`` and
    ratio if it runs (a plain run allocates 7; the reset's first is ``_nodal_rows(XPIC_ON, 0)``)."""
    return 7 + 4 * xpic_on + 2 * volume_on
ROW = DOMAIN = None  # per compiled variant of a basis (_compile)
PROJECT = VISCOUS = UPDATE = MOVE = FINISH = GAS_FORCE = XPIC = VOLUME = TAYLOR = None  # the passes a compiled _advance calls
_STATE = ("x", "v", "V", "m", "rho", "e", "p")  # the arrays of the particles a step returns
_FIELDS = ("x", "velocity", "volume", "mass", "density", "energy", "pressure")  # Particles' names, same order
_SCHEME_CODE = {"usl": 0, "usf": 1, "musl": 2}
_PAD = 40  # doubles between advance's particle arrays: 5 cache lines, so that they do not share cache sets


def _uniform_to_round_off(grid: Grid) -> bool:
    """Whether the grid is uniform (``grid.uniform_spacing``) and its nodes lie within ``1e-9 h`` of
    ``x_0 + i h`` (a ``linspace``): then the uniform-grid arithmetic of every basis (:func:`_point`,
    :func:`_scaled`) agrees with the node arithmetic to round-off. A grid uniform only to ``grid.uniform_spacing``'s
    1e-6 takes the node arithmetic (and bisection to locate the particles, in every basis)."""
    h = grid.uniform_spacing
    if h is None:
        return False
    nodes = grid.nodes
    return bool(np.abs(nodes - (nodes[0] + h * np.arange(nodes.size))).max() <= 1e-9 * h)


class _Passes:
    """The compiled passes, made on first use: ``project[basis]``, and the others per model."""

    def __init__(self, parallel: bool):
        self.parallel = parallel
        self._made = {}

    def get(self, fn, **constants):
        key = (fn.__name__, tuple(sorted(constants.items())))
        if key not in self._made:
            passes = None
            if fn is _advance:  # the loop calls this variant's passes, compiled into it; the others
                passes = self._loop_passes(**constants)  # are None, their branches pruned at compile time
                constants = dict(constants, THREADED=int(self.parallel))  # a name per variant
            self._made[key] = _compile(fn, False if fn is _advance else self.parallel, passes, **constants)
        return self._made[key]

    def _loop_passes(self, BASIS, MODEL, WIDTH, SCHEME, XPIC_ON, VOLUME_ON, TAYLOR_ON):
        """The passes the loop variant with these constants calls: pass 1 and 2 always, USF's update,
        MUSL's last pass, Burgers' viscous force and each remedy's passes only where they run, so a
        plain run compiles none of the remedies."""
        shape = dict(BASIS=BASIS, WIDTH=WIDTH)
        model = dict(shape, MODEL=MODEL)
        scatter = lambda weight: self.get(_scatter_pass, **shape, WEIGHT=weight)  # noqa: E731
        return dict(PROJECT=self.get(_project, **shape), MOVE=self.get(_move, **model),
                    UPDATE=self.get(_update, **model) if SCHEME == 1 else None,
                    FINISH=self.get(_finish, **model) if SCHEME == 2 else None,
                    VISCOUS=scatter(VISCOUS_STRESS) if MODEL == BURGERS else None,
                    GAS_FORCE=scatter(PRESSURE) if VOLUME_ON and MODEL == GAS else None,
                    VOLUME=self.get(_volume_reset, BASIS=BASIS, MODEL=MODEL) if VOLUME_ON else None,
                    XPIC=scatter(MOMENTUM) if XPIC_ON else None,
                    TAYLOR=self.get(_taylor_force, **model) if TAYLOR_ON else None)


_PASSES = {parallel: _Passes(parallel) for parallel in (False, True)}


# --------------------------------------------------------------------------- the step

class FusedStep:
    """The fused step of one run: ``step(particles, t, dt) -> (particles, GridState)``, as
    :func:`~mpm_fem.core.step.explicit_step` (the same numbers on one thread). After each step
    ``speed`` holds ``max_p (c_p + |v_p|)`` (gas) or ``max_p |v_p|`` (Burgers) of the new particles
    and ``finite`` whether their state is finite, for the time step and the run's checks. With
    ``reuse`` the step writes into two alternating sets of arrays instead of fresh ones (no page
    faults on a new 8 MB array per field and step): the particles a step returns are overwritten
    two steps later, so a run that hands them to an observer reuses only if the observer keeps none
    of them (:func:`mpm_fem.core.solve._keeps_particles`)."""

    def __init__(self, grid: Grid, model, boundary, stages: Stages = Stages(), exact_acceleration=None,
                 threads: int = 1, reuse: bool = False, exact: ExactFields | None = None):
        reason = supported(model, stages)
        if reason is not None:
            raise ValueError(reason)
        if stages.uses_exact_fields and exact is None:
            raise ValueError("the exact projection, mass and interpolation stages need the problem's exact fields")
        self.exact = exact
        check_kernel("fused", threads)
        if stages.scheme not in SCHEMES:
            raise ValueError(f"unknown scheme {stages.scheme!r}")
        self.grid, self.model, self.boundary, self.stages = grid, model, boundary, stages
        self.exact_acceleration = exact_acceleration
        self.threads = int(threads)
        passes = _PASSES[self.threads > 1]
        self.kind = GAS if isinstance(model, IdealGas) else BURGERS
        self.basis = _BASIS_CODE[stages.basis]
        self._passes = passes
        if stages.basis in ("bspline", "bspline_gimp"):
            make_shape(grid, grid.nodes[:1], basis="bspline")  # raises on a non-uniform grid
        self.nodes = np.ascontiguousarray(grid.nodes, dtype=float)
        self.h = np.ascontiguousarray([grid.h, 1.0 / grid.h], dtype=float)  # h_c and 1/h_c: read, not divided
        self.inv_spacing = 1.0 / grid.uniform_spacing if _uniform_to_round_off(grid) else 0.0
        if self.kind == GAS:
            g = model.gamma
            self.consts = np.array([g - 1.0, g * (g - 1.0), model.av_linear, model.av_quadratic, 0.0])
        else:
            self.consts = np.array([0.0, 0.0, 0.0, 0.0, model.eps])
        self.consts = np.append(self.consts, [float(stages.flip), float(stages.xpic)])  # the remedies' blend, XPIC
        self.slides = self.kind == BURGERS and getattr(model, "force", "weak") == "slides"
        self._width({"mpm": 2, "bspline": 4, "gimp": 3, "bspline_gimp": 5}[stages.basis])
        self.speed, self.finite = np.nan, True
        self.reuse, self._pools, self._turn = reuse, ({}, {}), 0
        self._state = self._out = self._scratch = None  # advance's two sets of particle arrays, its last
        self._cur = 0  # particles, and its scratch arrays
        self._ends = np.ascontiguousarray(grid.boundary_nodes, dtype=np.intp)
        # the stored cells and node indices (pass 1 -> the grid stage and pass 2): 4 bytes, not 8
        self._index = np.int32 if grid.n_nodes <= np.iinfo(np.int32).max else np.intp
        self._h_min = float(grid.h.min())
        self.integrals = (np.ascontiguousarray(basis_integrals(grid, stages.basis), dtype=float)
                          if stages.volume == "grid" else np.empty(0))  # the volume reset: int S_i
        self.volume_width = 3 if self.basis in (0, 1) else 5
        self.quadrature = (np.empty((0, 2), np.intp), np.empty((0, 2)), np.empty(0), np.empty(0))
        if stages.reconstruct == "taylor":  # the reconstructed force's points: their nodes, S_i', weights
            points, weights = force_quadrature(grid, stages.basis)
            self.quadrature = (np.ascontiguousarray(points.nodes, dtype=np.intp), np.ascontiguousarray(points.G),
                               np.ascontiguousarray(weights), np.ascontiguousarray(OFFSETS))

    def _width(self, K):
        """Use the passes compiled for K nodes per particle (GIMP: 2 + the cells a domain spans)."""
        self.K = K
        constants = dict(BASIS=self.basis, MODEL=self.kind, WIDTH=K)
        self.project = self._passes.get(_project, BASIS=self.basis, WIDTH=K)
        self.update, self.move, self.finish = (self._passes.get(fn, **constants) for fn in (_update, _move, _finish))
        self.viscous_force = self._passes.get(_scatter_pass, BASIS=self.basis, WIDTH=K, WEIGHT=VISCOUS_STRESS)

    def _empty(self, name, shape, dtype=float):
        """A fresh array, or with ``reuse`` one of two alternating sets: a step never writes the
        arrays it reads, and the particles it returns stay valid until the step after next."""
        if not self.reuse:
            return np.empty(shape, dtype)
        pool = self._pools[self._turn if name in _STATE else 0]  # scratch arrays: one set
        a = pool.get(name)
        if a is None or a.shape != shape or a.dtype != dtype:
            a = pool[name] = np.empty(shape, dtype)
        return a

    def _solve(self, shape, mass, m_i, rhs, name="v_solved"):
        if self.stages.mass == "lumped":
            return _divide_by_lumped(rhs, m_i, self._empty(name, m_i.shape))
        return solve_consistent(shape, mass, rhs)

    def _positivity(self, flags, values, x):
        """Raise :class:`PositivityError` as the numpy model would (factor first, then energy)."""
        name = "1 - (dv/dx) dt" if self.kind == GAS else "1 + (dv/dx) dt"
        for col, quantity in ((0, name), (1, "internal energy")):
            for k in range(flags.shape[0]):
                q = int(flags[k, col])
                if q >= 0:
                    raise PositivityError(quantity, q, float(x[q]), float(values[k, col]))

    def loops(self, problem) -> bool:
        """Whether :meth:`advance` can take the steps of ``problem``: walls or Dirichlet ends (this
        step's boundary), the lumped mass, the calculated acceleration and the weak force or the
        exact acceleration (this step's), and no
        particle boundary or one that says when it acts (:meth:`_window`; no observer: the caller's)."""
        ends = type(problem.boundary) is Walls or (type(problem.boundary) is Dirichlet
                                                   and problem.boundary is self.boundary)
        exact = (self.stages.acceleration == "exact" and self.exact_acceleration is not None
                 and problem.exact_acceleration is self.exact_acceleration)
        return (ends and self.stages.mass == "lumped" and not self.stages.uses_exact_fields
                and (self.stages.acceleration == "calculated" or exact)
                and not self.slides and (problem.particle_boundary is None or self._window(problem) is not None))

    def _window(self, problem):
        """``(a, b, spacing)`` of a particle boundary that leaves the particles as they are while
        they lie in [a, b] with no end gap of ``spacing`` (``particle_boundary.quiet(grid)``, as
        :class:`~mpm_fem.problems.burgers.Reservoir` gives), else ``None`` (it may act every step)."""
        quiet = getattr(problem.particle_boundary, "quiet", None)
        return None if quiet is None else quiet(self.grid)

    def advance(self, particles: Particles, t: float, problem, steps: int, max_steps: int, budget: int):
        """Up to ``budget`` steps from ``t`` in one compiled loop (:func:`_advance`), each the step
        :meth:`step` takes with the time step :func:`mpm_fem.core.solve.run` takes after its first step
        (from :attr:`speed`): the same numbers bit for bit. Returns ``(particles, t, steps taken,
        dt_min, dt_max)``; zero steps when the next step must go through :meth:`step` (it fails, or
        a GIMP particle's row changes width)."""
        n, chunks = particles.n, max(1, min(self.threads, particles.n))
        spare = (lambda k: k // 16) if problem.particle_boundary is not None else (lambda k: 0)  # a reservoir's inflow
        if self._out is not particles or self._state.shape[2] < n + _PAD:  # particles from elsewhere: copied into both sets (the mass of
            if self._state is None or self._state.shape[2] < n + _PAD:  # the gas, rho, eps, p of Burgers stay there), with room
                self._state = np.empty((2, len(_FIELDS), n + spare(n) + _PAD))  # for a reservoir's inflow
            for j, name in enumerate(_FIELDS):
                self._state[:, j, :n] = getattr(particles, name)
            self._pools = ({}, {})  # the per-step arrays: refilled if a step falls back to step()
            self._cur = 0
        rows_n = n if self.basis in _DOMAIN_BASES else 0
        volume, taylor = self.stages.volume == "grid", self.stages.reconstruct == "taylor"
        if (self._scratch is None or self._scratch[0].size < n or self._scratch[1].shape[0] < rows_n
                or self._scratch[1].shape[1] != self.K or self._scratch[5].shape[0] != chunks
                or (volume and self._scratch[9].shape[2] < n)):
            room, rows_room = n + spare(n), rows_n + spare(rows_n)
            self._scratch = (np.empty(room, self._index), np.empty((rows_room, self.K), self._index),
                             np.empty((rows_room, self.K)), np.empty((rows_room, self.K)),
                             np.empty((_nodal_rows(self.stages.xpic > 0, volume), self.grid.n_nodes)),
                             np.empty((chunks, 3), np.int64), np.empty((chunks, 2), np.int64), np.zeros((chunks, 2)),
                             np.empty(chunks), np.empty((1, 3, room if volume else 0)),
                             np.empty((5, self.grid.n_cells if taylor else 0)))
        cell, rows, S, G = self._scratch[0][:n], self._scratch[1][:rows_n], self._scratch[2][:rows_n], self._scratch[3][:rows_n]
        loop = self._passes.get(_advance, BASIS=self.basis, MODEL=self.kind, WIDTH=self.K,
                                SCHEME=_SCHEME_CODE[self.stages.scheme], XPIC_ON=int(self.stages.xpic > 0),
                                VOLUME_ON=int(volume), TAYLOR_ON=int(taylor))
        fixed = problem.dt if problem.dt is not None else 0.0
        viscous = bool(getattr(self.model, "viscous_limit", False))
        dirichlet = type(self.boundary) is Dirichlet
        window = np.empty(0) if problem.particle_boundary is None else np.array(self._window(problem), dtype=float)
        exact = self.stages.acceleration == "exact"
        _LOOP_CALLS.append((self.boundary, self.grid, self.exact_acceleration))
        try:
            cur, t, done, speed, dt_min, dt_max = loop(
                self.nodes, self.h, self.inv_spacing, self._ends, self.consts, chunks, self._state, self._cur,
                float(t), float(problem.T), float(self.speed), float(fixed), float(problem.cfl), self._h_min, float(self.stages.refine), viscous, steps, max_steps, budget,
                cell, rows, S, G, *self._scratch[4:9], dirichlet, window, exact, int(self.stages.xpic),
                self.volume_width if volume else 0, self.integrals, self._scratch[9], *self.quadrature,
                self._scratch[10])
        finally:
            _LOOP_CALLS.pop()
        if done:
            self._cur, self.speed, self.finite = cur, float(speed), True
            self._out = Particles(**{name: self._state[cur, j, :n] for j, name in enumerate(_FIELDS)})
            particles = self._out
        return particles, t, done, dt_min, dt_max

    def _grid_volume(self, geometry, x, rows, S, V, m, rho, e, p, chunks):
        """The grid volume reset (:func:`_volume_reset`): ``(V, rho, p)`` of the reset state (Burgers:
        ``rho``, ``p`` as they are); raises :class:`PositivityError` as the model's ``with_volume``."""
        reset = self._passes.get(_volume_reset, BASIS=self.basis, MODEL=self.kind)
        n, n_nodes = x.size, self.grid.n_nodes
        V_r, rho_r, p_r = (self._empty(name, n) for name in ("V_reset", "rho_reset", "p_reset"))
        V_i, ratio = self._empty("V_i", n_nodes), self._empty("ratio", n_nodes)
        flags, values = np.empty((chunks, 2), np.int64), np.zeros((chunks, 2))
        while True:
            width = self.K if self.basis in _DOMAIN_BASES else self.volume_width
            reset(*geometry, x, rows, S, V, m, rho, e, p, self.integrals, self.consts, chunks, width,
                  V_i, ratio, V_r, rho_r, p_r, flags, values)
            need = int(flags[:, 1].max(initial=0))
            if need <= width:
                break
            self.volume_width = need  # a particle domain spans another cell: redo with wider rows
        for k in range(chunks):
            if flags[k, 0] >= 0:
                q = int(flags[k, 0])
                raise PositivityError("density" if self.kind == GAS else "volume", q, float(x[q]), float(values[k, 0]))
        return (V_r, rho_r, p_r) if self.kind == GAS else (V_r, rho, p)

    def _xpic_target(self, shape, shape_args, m, m_i, v_i, a_i, t, dt, chunks):
        """XPIC(m)'s grid field ``v* + dt a_i`` whose interpolation is the particle velocity
        (:func:`mpm_fem.core.xpic.xpic_grid_velocity`, the same operations): ``m - 1`` compiled passes
        ``P_i = sum_p S_ip m_p (sum_j S_jp u_j)``, each solved with the step's mass and the
        boundary rule of a velocity change applied."""
        rule = boundary_change_rule(self.boundary, self.grid, t)
        momentum = self._passes.get(_scatter_pass, BASIS=self.basis, WIDTH=self.K, WEIGHT=MOMENTUM)
        P_x = self._empty("P_xpic", m_i.shape)
        v_star, term = v_i.copy(), v_i
        for _ in range(self.stages.xpic - 1):
            momentum(*shape_args, term, m, m, 0.0, chunks, P_x)
            term = rule(term - self._solve(shape, m, m_i, P_x, "v_xpic"))
            v_star += term
        return v_star + dt * a_i

    def _pass1(self, particles: Particles, gas_force: bool, store: bool, chunks: int):
        """Pass 1 (:func:`_project`): ``(shape, m_i, P_i, F_i, flags)``, the rows in ``shape`` if
        ``store`` (the domain bases store theirs always), the cells always; raises the numpy step's
        error for a particle outside the grid or without volume."""
        grid, n = self.grid, particles.n
        x, V, m, v, p = particles.x, particles.volume, particles.mass, particles.velocity, particles.pressure
        store = store or self.basis in _DOMAIN_BASES
        n_nodes = grid.n_nodes
        empty = self._empty
        m_i, P_i, F_i = empty("m_i", n_nodes), empty("P_i", n_nodes), empty("F_i", n_nodes)
        flags = np.empty((chunks, 3), np.int64)
        cell = empty("cell", n, self._index)
        while True:
            rows_n = n if store else 0
            rows, S, G = (empty("rows", (rows_n, self.K), self._index), empty("S", (rows_n, self.K)),
                          empty("G", (rows_n, self.K)))
            self.project(self.nodes, self.h, self.inv_spacing, x, V, m, v, p, gas_force, store, chunks,
                         rows, S, G, cell, m_i, P_i, F_i, flags)
            if (flags[:, :2] >= 0).any():
                make_shape(grid, x, V, self.stages.basis)  # raises the numpy step's error
                raise ValueError("a particle lies outside the grid or has no volume")  # not reached
            need = int(flags[:, 2].max(initial=2))
            if self.basis not in _DOMAIN_BASES or need == self.K or n == 0:
                break
            self._width(need)  # GIMP: a particle domain spans another cell; redo with the wider rows
        return Shape(rows, S, G, n_nodes, cell), m_i, P_i, F_i, flags

    def step(self, particles: Particles, t: float, dt: float) -> tuple[Particles, GridState]:
        if self.stages.uses_exact_fields:
            return self._exact_step(particles, t, dt)
        grid = self.grid
        n, chunks = particles.n, max(1, min(self.threads, particles.n))
        x, V, m, v = particles.x, particles.volume, particles.mass, particles.velocity
        rho, e, p = particles.density, particles.energy, particles.pressure
        gas = self.kind == GAS
        scheme, exact = self.stages.scheme, self.stages.acceleration == "exact"
        grid_volume, taylor = self.stages.volume == "grid", self.stages.reconstruct == "taylor"
        gas_force = gas and scheme != "usf" and not exact and not grid_volume and not taylor
        geometry = (self.nodes, self.h, self.inv_spacing)
        n_nodes = grid.n_nodes
        self._turn = 1 - self._turn
        empty = self._empty
        shape, m_i, P_i, F_i, flags = self._pass1(particles, gas_force, self.stages.mass == "consistent", chunks)
        rows, S, G, cell = shape.nodes, shape.S, shape.G, shape.cell
        v_i = self.boundary.velocity(grid, self._solve(shape, m, m_i, P_i), t)
        shape_args = (*geometry, x, rows, S, G, cell)
        if grid_volume:  # the volume reset (mpm_fem.core.volume), then the force of the reset state
            V, rho, p = self._grid_volume(geometry, x, rows, S, V, m, rho, e, p, chunks)
            if gas and scheme != "usf" and not exact and not taylor:
                self._passes.get(_scatter_pass, BASIS=self.basis, WIDTH=self.K, WEIGHT=PRESSURE)(
                    *shape_args, v_i, V, p, 0.0, chunks, F_i)

        V_new, m_new = empty("V", n), (empty("m", n) if not gas else m)
        rho_new, e_new, p_new = (empty("rho", n), empty("e", n), empty("p", n)) if gas else (rho, e, p)
        values = np.zeros((chunks, 2))
        if scheme == "usf":
            upd = np.empty((chunks, 2), np.int64)
            self.update(*shape_args, v_i, V, m, rho, e, p, dt, self.consts, not exact and not self.slides and not taylor,
                        chunks, V_new, m_new, rho_new, e_new, p_new, F_i, upd, values)
            if (upd >= 0).any():
                self._positivity(upd, values, x)
        elif not gas and not exact and not self.slides and not taylor:
            self.viscous_force(*shape_args, v_i, V, V, self.consts[4], chunks, F_i)
        if taylor and not exact and not self.slides:  # the reconstructed force of the (updated) stress
            self._passes.get(_taylor_force, BASIS=self.basis, MODEL=self.kind, WIDTH=self.K)(
                *shape_args, p_new if scheme == "usf" else p, v_i, self.consts[4], *self.quadrature, chunks,
                empty("sums", (5, grid.n_cells)), F_i)
        if exact:
            if self.exact_acceleration is None:
                raise ValueError("this problem has no exact acceleration to use")
            a_i = self.exact_acceleration(grid.nodes, t)
        elif self.slides:
            a_i = self.model.grid_acceleration(grid, cell, v_i)
        else:
            a_i = self._solve(shape, m, m_i, F_i, "a_solved")
        a_i = self.boundary.acceleration(grid, a_i, v_i, t, dt)
        v_n = v_i + dt * a_i

        x_new, vel_new = empty("x", n), empty("v", n)
        speed = np.empty(chunks)
        usl, musl = scheme == "usl", scheme == "musl"
        if usl:  # the move writes the new state
            state = (V, m, rho, e, p, V_new, m_new, rho_new, e_new, p_new)
        else:  # USF: updated already; MUSL: updated after the re-projection
            V_m, m_m, rho_m, e_m, p_m = (V_new, m_new, rho_new, e_new, p_new) if scheme == "usf" else (V, m, rho, e, p)
            state = (V_m, m, rho_m, e_m, p_m, V_m, m_m, rho_m, e_m, p_m)
        P_musl = empty("P_musl", n_nodes)
        target = self._xpic_target(shape, shape_args, m, m_i, v_i, a_i, t, dt, chunks) if self.stages.xpic else a_i
        self.move(*geometry, rows, S, G, cell, target, v_n, x, state[0], state[1], v, state[2], state[3], state[4],
                  dt, self.consts, usl, musl, chunks, x_new, vel_new, *state[5:], P_musl, flags, values, speed)
        if musl:
            v_n = self.boundary.velocity(grid, self._solve(shape, m, m_i, P_musl, "v_musl"), t + dt)
            self.finish(*shape_args, v_n, V, m, vel_new, rho, e, p, dt, self.consts, chunks,
                        V_new, m_new, rho_new, e_new, p_new, x_new, flags, values, speed)
        if usl or musl:
            if (flags[:, :2] >= 0).any():
                self._positivity(flags[:, :2], values, x_new)
        return self._new_particles(x_new, vel_new, V_new, m_new, rho_new, e_new, p_new, flags, speed), \
            GridState(m_i, v_i, a_i, v_n)

    def _new_particles(self, x, v, V, m, rho, e, p, flags, speed) -> Particles:
        """The step's particles; :attr:`speed` and :attr:`finite` from pass 2's tallies."""
        self.speed = float(speed.max())
        self.finite = bool((flags[:, 2] < 0).all())
        return Particles(x=x, volume=V, mass=m, velocity=v, density=rho, energy=e, pressure=p)

    def _exact_step(self, particles: Particles, t: float, dt: float) -> tuple[Particles, GridState]:
        """The step with exact stages (:func:`mpm_fem.core.step.explicit_step`; the gas, USL): pass 1 for
        the particles' ``m_i``, ``P_i`` and (MPM projection) ``F_i``; the grid stage of the numpy step
        (:class:`~mpm_fem.exact_stages.stage.ExactGridStage`); pass 2 as the plain step's with the MPM
        interpolation, else :func:`_move_exact` with the exact fields at ``x_p^n``, then ``L_p = v*_x(x_p^{n+1},
        t + dt) + sum_i G_ip (v_i^{n+1} - v*_i^{n+1})`` and the state update (:func:`_update_exact`)."""
        n, chunks = particles.n, max(1, min(self.threads, particles.n))
        x, V, m, v = particles.x, particles.volume, particles.mass, particles.velocity
        rho, e, p = particles.density, particles.energy, particles.pressure
        self._turn = 1 - self._turn
        empty = self._empty
        interpolate = self.stages.interpolation == "exact"
        shape, m_i, P_i, F_i, flags = self._pass1(particles, self.stages.projection == "mpm", False, chunks)
        stage = ExactGridStage(self.grid, self.boundary, self.stages, self.exact, GridData(shape, m, m_i, P_i), t, dt)
        a_i = stage.acceleration(F_i)
        v_n = stage.v_i + dt * a_i
        x_new, vel_new = empty("x", n), empty("v", n)
        V_new, rho_new, e_new, p_new = (empty(name, n) for name in ("V", "rho", "e", "p"))
        values, speed = np.zeros((chunks, 2)), np.empty(chunks)
        geometry = (self.nodes, self.h, self.inv_spacing, shape.nodes, shape.S, shape.G, shape.cell)
        if interpolate:
            p_v, _, p_a = self.exact.reference(x, t)
            star_new = stage.star_new
            L = empty("L", n)
            self._passes.get(_move_exact, BASIS=self.basis, WIDTH=self.K)(
                *geometry, a_i - stage.star_a, v_n - star_new, p_v, p_a, x, v, dt, chunks, x_new, vel_new, L)
            L = self.exact.velocity_gradient(x_new, t + dt) + L
            self._passes.get(_update_exact, MODEL=self.kind)(
                self.h, shape.cell, L, x_new, vel_new, V, m, rho, e, p, dt, self.consts, chunks,
                V_new, m, rho_new, e_new, p_new, flags, values, speed)
        else:
            state = (V, m, rho, e, p, V_new, m, rho_new, e_new, p_new)
            self.move(*geometry, a_i, v_n, x, *state[:2], v, *state[2:5], dt, self.consts, True, False,
                      chunks, x_new, vel_new, *state[5:], empty("P_musl", self.grid.n_nodes), flags, values, speed)
        if (flags[:, :2] >= 0).any():
            self._positivity(flags[:, :2], values, x_new)
        return self._new_particles(x_new, vel_new, V_new, m, rho_new, e_new, p_new, flags, speed), \
            GridState(m_i, stage.v_i, a_i, v_n)
