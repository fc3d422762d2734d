"""Fixed-mesh Galerkin FEM for the viscous Burgers equation, on scikit-fem.

The baseline that MPM is compared with on the same mesh (docs/claims.md, C13, C15 and E3). The equation

    v_t + (v^2 / 2)_x = eps v_xx       on [a, b] = solution.domain,  0 < t <= T,
    v(x, 0) = v_exact(x, 0),  v(a, t) = v_exact(a, t),  v(b, t) = v_exact(b, t),

is discretised with P1 elements (hat functions ``S_i``), ``v_h = sum_j v_j S_j``, and the
Galerkin equations for the interior nodes ``i``

    sum_j M_ij dv_j/dt = R_i(v),
    R_i(v) = - int S_i v_h (v_h)_x dx - eps int (v_h)_x S_i' dx,

with the nonlinear term integrated exactly (it is a cubic on each cell). Cell by cell
(``e = [x_a, x_b]``, ``h_e = x_b - x_a``) this is

    R_a += -(v_b - v_a)(2 v_a + v_b)/6 + eps (v_b - v_a)/h_e,
    R_b += -(v_b - v_a)(v_a + 2 v_b)/6 - eps (v_b - v_a)/h_e,

the two convective parts adding up to ``-(v_b^2 - v_a^2)/2`` (conservative). ``M`` is the
consistent mass ``int S_i S_j dx`` (scikit-fem) or its row sums (lumped). The Dirichlet values
``g(t)`` are imposed strongly at both end nodes; with the consistent mass the interior rows
read ``M_II dv_I/dt = R_I - M_IB g'(t)``, with ``g' = v_t`` of the exact solution (the lumped
mass has ``M_IB = 0``). ``M_II`` is factorised once.

Time: SSP-RK3 (Shu-Osher) with the fixed step

    dt = min(cfl h / max_x |v(x, 0)|,  cfl_visc h^2 / (2 eps)),   shortened so that T = steps dt,

and the boundary values of each stage taken at the stage time (t, t + dt, t + dt/2). For the
consistent mass the explicit diffusion limit is ``dt <= 2.51 h^2 / (12 eps)``, i.e.
``cfl_visc <= 0.42`` (lumped: 1.25); the default 0.3 is stable for both.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse.linalg import splu

from baselines import fem_burgers_kernel
from baselines.galerkin import P1Cells, check_settings, mesh, p1_cells
from mpm_fem.core.grid import Grid

KERNELS = ("fused", "numpy")  # the compiled loop, the numpy reference (:func:`solve`)
PROGRESS_EVERY = 1000  # steps per compiled call, and between progress lines


@dataclass(frozen=True)
class BurgersFEMResult:
    """Nodal values ``v`` (n_nodes,) at ``nodes`` and time ``t`` after ``steps`` steps of ``dt``."""

    nodes: np.ndarray
    v: np.ndarray
    t: float
    steps: int
    dt: float
    settings: dict


@dataclass(frozen=True, eq=False)
class _Operators(P1Cells):
    """The P1 cells, the interior and boundary nodes, and the solve with ``M_II``."""

    interior: np.ndarray
    boundary: np.ndarray
    M_IB: object = None
    M_II: object = None
    solve_II: object = None


def _operators(grid: Grid, mass: str) -> _Operators:
    boundary = grid.boundary_nodes
    ops = dict(p1_cells(grid, mass), interior=np.setdiff1d(np.arange(grid.n_nodes), boundary), boundary=boundary)
    if mass == "consistent":
        M = grid.consistent_mass.tocsr()
        interior = ops["interior"]
        M_II = M[interior][:, interior].tocsc()
        ops.update(M_IB=M[interior][:, boundary], M_II=M_II, solve_II=splu(M_II).solve)
    return _Operators(**ops)


def residual(v: np.ndarray, ops: _Operators, eps: float) -> np.ndarray:
    """``R_i(v)`` of the module docstring at every node (n_nodes,), assembled with bincount."""
    va, vb = v[ops.a], v[ops.b]
    jump = vb - va
    diffusive = eps * jump / ops.h
    n = ops.n_nodes
    return np.bincount(ops.a, -jump * (2.0 * va + vb) / 6.0 + diffusive, n) + np.bincount(
        ops.b, -jump * (va + 2.0 * vb) / 6.0 - diffusive, n
    )


def time_derivative(v: np.ndarray, g_t: np.ndarray, ops: _Operators, eps: float) -> np.ndarray:
    """``dv/dt`` at every node: interior rows of ``M dv/dt = R``, ``g_t`` at the boundary nodes."""
    R = residual(v, ops, eps)
    out = np.empty_like(v)
    out[ops.boundary] = g_t
    if ops.mass == "lumped":
        out[ops.interior] = R[ops.interior] / ops.lumped[ops.interior]
    else:
        out[ops.interior] = ops.solve_II(R[ops.interior] - ops.M_IB @ g_t)
    return out


def solve(
    solution,
    h: float,
    T: float = 0.5,
    mass: str = "consistent",
    cfl: float = 0.5,
    cfl_visc: float = 0.3,
    progress: bool = False,
    kernel: str = "fused",
) -> BurgersFEMResult:
    """Galerkin P1 solution of Burgers' equation with the data of ``solution`` (an exact solution
    from :mod:`baselines.exact.burgers`: ``.eps``, ``.domain``, ``.v(x, t)``, ``.v_t(x, t)``) on a
    uniform mesh of size ``h``, up to time ``T`` (module docstring for the equations).

    ``kernel="fused"`` takes the steps in blocks of ``PROGRESS_EVERY`` with the compiled loop of
    :mod:`baselines.fem_burgers_kernel` (bit for bit with the numpy step for the lumped mass, to
    round-off for the consistent one: a Thomas solve in place of SuperLU); ``"numpy"`` is the
    readable reference below.

    Raises ValueError for bad input (``h`` not dividing the domain, ``cfl`` or ``cfl_visc``
    outside (0, 1], unknown ``mass`` or ``kernel``) and ArithmeticError if the solution becomes
    non-finite.
    """
    check_settings(mass, T, cfl=cfl, cfl_visc=cfl_visc)
    if kernel not in KERNELS:
        raise ValueError(f"unknown kernel {kernel!r}; choose one of {', '.join(KERNELS)}")
    eps = float(solution.eps)
    lo, hi = solution.domain
    grid = mesh(lo, hi, h)
    ops = _operators(grid, mass)
    x = grid.nodes
    x_b = x[ops.boundary]

    v = np.asarray(solution.v(x, 0.0), dtype=float)
    speed = float(np.max(np.abs(v)))
    h_min = float(grid.h.min())
    dt_limit = cfl_visc * h_min**2 / (2.0 * eps)
    if speed > 0:
        dt_limit = min(dt_limit, cfl * h_min / speed)
    steps = int(np.ceil(T / dt_limit * (1 - 1e-12)))
    dt = T / steps

    # Boundary data at every half step k dt / 2 (the stage times), one vectorised call each.
    half_times = 0.5 * dt * np.arange(2 * steps + 1)[:, None]
    g = np.asarray(solution.v(x_b[None, :], half_times), dtype=float)
    g_t = np.asarray(solution.v_t(x_b[None, :], half_times), dtype=float)

    take = _compiled_steps(ops, eps, dt, g, g_t) if kernel == "fused" else _numpy_steps(ops, eps, dt, g, g_t)
    for first in range(0, steps, PROGRESS_EVERY):  # blocks of steps, not nodes
        done = min(steps, first + PROGRESS_EVERY)
        v, bad = take(v, first, done - first)
        if bad is not None:
            step, node = bad
            raise ArithmeticError(f"v became non-finite at step {step}, node {node} (x = {x[node]:.6g})")
        if progress and done % PROGRESS_EVERY == 0:
            print(f"fem_burgers h={h} {mass}: step {done}/{steps}", flush=True)

    settings = dict(
        problem="burgers",
        solution=type(solution).__name__,
        solution_name=getattr(solution, "name", None),
        eps=eps,
        domain=(float(lo), float(hi)),
        h=h,
        T=T,
        mass=mass,
        cfl=cfl,
        cfl_visc=cfl_visc,
        dt_rule="min(cfl h / max|v(x,0)|, cfl_visc h^2 / (2 eps)), then T / ceil(T / dt)",
        time_integrator="SSPRK3",
        elements="P1",
        nonlinear_term="int S_i v_h (v_h)_x dx, exact",
        boundary="Dirichlet from the exact solution at both ends",
    )
    return BurgersFEMResult(
        nodes=x.copy(), v=v, t=steps * dt, steps=steps, dt=dt, settings=settings
    )


def _numpy_steps(ops: _Operators, eps: float, dt: float, g: np.ndarray, g_t: np.ndarray):
    """``take(v, first, count)``: steps ``first ... first + count - 1`` of SSP-RK3 in numpy (the
    reference); returns the new ``v`` and None, or ``(step, node)`` where ``v`` stopped being finite."""

    def L(w, k):
        return time_derivative(w, g_t[k], ops, eps)

    def with_boundary(w, k):
        w[ops.boundary] = g[k]
        return w

    def take(v, first, count):
        for n in range(first, first + count):
            k = 2 * n  # t = k dt / 2
            v1 = with_boundary(v + dt * L(v, k), k + 2)
            v2 = with_boundary(0.75 * v + 0.25 * (v1 + dt * L(v1, k + 2)), k + 1)
            v = with_boundary(v / 3.0 + 2.0 / 3.0 * (v2 + dt * L(v2, k + 1)), k + 2)
            if not np.all(np.isfinite(v)):
                return v, (n + 1, int(np.flatnonzero(~np.isfinite(v))[0]))
        return v, None

    return take


def _compiled_steps(ops: _Operators, eps: float, dt: float, g: np.ndarray, g_t: np.ndarray):
    """``take(v, first, count)`` of :func:`_numpy_steps` with the compiled loop
    (:mod:`baselines.fem_burgers_kernel`)."""
    consistent = ops.mass == "consistent"
    if consistent:
        l, w, u = fem_burgers_kernel.tridiagonal_factors(ops.M_II)
        M_IB = np.ascontiguousarray(ops.M_IB.toarray())
    else:
        l = w = u = np.zeros(0)
        M_IB = np.zeros((0, ops.boundary.size))
    cells = fem_burgers_kernel.Cells(ops.a, ops.b, ops.h, ops.interior, ops.boundary)
    mass = fem_burgers_kernel.Mass(ops.lumped, consistent, l, w, u, M_IB)
    fixed = (dt, np.ascontiguousarray(g), np.ascontiguousarray(g_t), cells, eps, mass)

    def take(v, first, count):
        v = v.copy()
        step, node = fem_burgers_kernel.steps(v, first, count, *fixed)
        return v, (None if step < 0 else (int(step), int(node)))

    return take


def errors(result: BurgersFEMResult, solution) -> dict[str, float]:
    """Nodal errors ``e_i = v_i - v_exact(x_i, t)``: ``L1 = sum_i w_i |e_i|``, ``L2 = sqrt(sum_i
    w_i e_i^2)``, ``max = max_i |e_i|``, with ``w_i = int S_i dx`` (the lumped-mass weights)."""
    x = result.nodes
    w = np.zeros_like(x)
    half = 0.5 * np.diff(x)
    w[:-1] += half
    w[1:] += half
    e = result.v - solution.v(x, result.t)
    return {
        "L1": float(np.sum(w * np.abs(e))),
        "L2": float(np.sqrt(np.sum(w * e * e))),
        "max": float(np.max(np.abs(e))),
    }
