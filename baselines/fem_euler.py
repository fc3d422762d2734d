"""Fixed-mesh Galerkin FEM for the 1D Euler equations (Sod's shock tube), on scikit-fem.

The baseline that MPM is compared with on the same mesh (docs/claims.md, C15 and E3). Conservative
variables at the nodes, ``U = (rho, rho u, E)``, ideal gas ``p = (gamma - 1)(E - rho u^2 / 2)``,
flux ``F(U) = (rho u, rho u^2 + p, (E + p) u)``. The equations solved are

    U_t + F(U)_x = (nu U_x)_x            on [0, 1],  u = 0 at both ends (reflecting walls),

discretised with P1 elements (hat functions ``S_i``) in the group (product-interpolation) form:
the flux is interpolated like the unknowns, ``F_h = sum_j F(U_j) S_j``, and the artificial
viscosity ``nu_e`` is constant on each cell ``e``. The semi-discrete equations are

    sum_j M_ij dU_j/dt = R_i(U),
    R_i(U) = - int S_i (F_h)_x dx - sum_e nu_e int_e (U_h)_x S_i' dx,

which, cell by cell (``e = [x_a, x_b]``, ``h_e = x_b - x_a``), is

    R_a += -(F_b - F_a)/2 + nu_e (U_b - U_a)/h_e,    R_b += -(F_b - F_a)/2 - nu_e (U_b - U_a)/h_e.

``M`` is the consistent mass ``int S_i S_j dx`` (scikit-fem, factorised once) or its row sums
(lumped). Wall conditions: the momentum equation at the two end nodes is replaced by
``(rho u)_i = 0``; the mass and energy fluxes ``rho u`` and ``(E + p) u`` then vanish there, so
``sum_i m_i rho_i`` (``m_i = int S_i dx``, equal to ``int rho_h dx``) and ``sum_i m_i E_i`` are
conserved to round-off with either mass matrix (``sum_i M_ij = m_j``, ``sum_i S_i' = 0``).

Artificial viscosity (a von Neumann-Richtmyer / Lapidus form, constants fixed for every mesh):

    nu_e = h_e ( c_lin s_e + c_quad max(0, -(u_b - u_a)) ),     s_e = max_{a,b} (|u| + c),

linear in the signal speed and quadratic (``h |du|`` ~ ``h^2 |u_x|``) in the compressive
velocity jump across the cell. Defaults ``c_lin = 0.1``, ``c_quad = 1``, the same for every mesh
and both mass matrices; the artificial viscosity acts on all three conserved variables, so it
enters the energy equation too. Two variants (:attr:`Viscosity.name`):

    everywhere (the default)   nu_e as above on every cell;
    compression only           nu_e as above where ``u_b < u_a`` (``du/dx < 0``), 0 elsewhere,

the second as MPM's von Neumann-Richtmyer viscosity, which acts only in compression: it leaves
rarefactions and contacts to the Galerkin scheme alone.

Time: SSP-RK3 (Shu-Osher) with ``dt = cfl h / max_i (|u_i| + c_i)`` recomputed every step, the
last step shortened to land on ``T``. Default ``cfl = 0.3``: with the consistent mass the first
step across the diaphragm loses positivity for ``cfl >= 0.5`` (0.45 runs), the lumped mass runs
up to ``cfl = 1``. Positivity of density and pressure is checked after every stage.

The time loop runs compiled (:mod:`baselines.fem_euler_kernel`, ``kernel="fused"``, the default):
bit for bit with the numpy loop below (``kernel="numpy"``, the readable reference) for the lumped
mass, to round-off for the consistent one (a Thomas solve where numpy uses SuperLU).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

from baselines import fem_euler_kernel
from baselines.fem_burgers_kernel import tridiagonal_factors
from baselines.galerkin import (
    MASS_KINDS,  # noqa: F401 (the choices of ``mass``, for callers)
    P1Cells,
    check_mass,
    check_settings,
    mesh,
    p1_cells,
)
from mpm_fem.core.grid import Grid

SOD_LEFT = (1.0, 0.0, 1.0)
SOD_RIGHT = (0.125, 0.0, 0.1)
SOD_DIAPHRAGM = 0.5
KERNELS = ("fused", "numpy")  # the compiled loop, the numpy reference (:func:`solve`)
PROGRESS_EVERY = 100  # steps per compiled call, and between progress lines


class PositivityError(ArithmeticError):
    """Density or pressure lost positivity (or became non-finite) during a run."""


@dataclass(frozen=True)
class Viscosity:
    """Constants of ``nu_e = h_e (linear s_e + quadratic max(0, -du_e))`` (module docstring), on
    every cell or, with ``compression_only``, only where ``du_e < 0``."""

    linear: float = 0.1
    quadratic: float = 1.0
    compression_only: bool = False

    def __post_init__(self):
        for name in ("linear", "quadratic"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                raise ValueError(f"viscosity constant {name} must be finite and >= 0, got {value}")
        if not isinstance(self.compression_only, (bool, np.bool_)):
            raise ValueError(f"compression_only must be True or False, got {self.compression_only!r}")

    @property
    def name(self) -> str:
        """Which variant: ``"viscosity everywhere"`` or ``"compression-only viscosity"``."""
        return "compression-only viscosity" if self.compression_only else "viscosity everywhere"

    def coefficient(self, h: np.ndarray, speed: np.ndarray, du: np.ndarray) -> np.ndarray:
        """``nu_e`` from the cell sizes, the signal speed ``s_e`` and the velocity jump ``du_e``."""
        nu = h * (self.linear * speed + self.quadratic * np.maximum(0.0, -du))
        return np.where(du < 0, nu, 0.0) if self.compression_only else nu


@dataclass(frozen=True)
class EulerFEMResult:
    """Nodal fields at time ``t``: ``nodes``, ``rho``, ``u``, ``p``, ``e`` (specific internal
    energy ``p / ((gamma - 1) rho)``), all (n_nodes,); ``steps`` taken; ``settings`` of the run."""

    nodes: np.ndarray
    rho: np.ndarray
    u: np.ndarray
    p: np.ndarray
    e: np.ndarray
    t: float
    steps: int
    settings: dict


@dataclass(frozen=True, eq=False)
class _Operators(P1Cells):
    """The P1 cells and the consistent mass: its matrices and their (SuperLU) solves."""

    M_free: object = None  # consistent M, for rho and E
    M_wall: object = None  # consistent M with wall rows replaced by identity, for rho u
    solve_free: object = None
    solve_wall: object = None


def _operators(grid: Grid, mass: str) -> _Operators:
    ops = p1_cells(grid, mass)
    if mass == "consistent":
        M = grid.consistent_mass.tocsc()
        keep = np.ones(grid.n_nodes)
        keep[grid.boundary_nodes] = 0.0
        wall = (sp.diags(keep) @ M + sp.diags(1.0 - keep)).tocsc()
        ops.update(M_free=M, M_wall=wall, solve_free=splu(M).solve, solve_wall=splu(wall).solve)
    return _Operators(**ops)


def primitives(U: np.ndarray, gamma: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(rho, u, p)`` from ``U = (rho, rho u, E)`` (3, n)."""
    rho, mom, E = U
    u = mom / rho
    return rho, u, (gamma - 1.0) * (E - 0.5 * mom * u)


def _check_positive(U: np.ndarray, gamma: float, step: int, stage: int) -> None:
    """Raise :class:`PositivityError` naming the step, stage and first bad node."""
    rho = U[0]
    with np.errstate(all="ignore"):
        p = (gamma - 1.0) * (U[2] - 0.5 * U[1] ** 2 / rho)
    for name, q in (("density", rho), ("pressure", p)):
        bad = np.flatnonzero(~(q > 0))  # also catches NaN
        if bad.size:
            i = int(bad[0])
            raise PositivityError(
                f"{name} lost positivity at step {step} (RK stage {stage}), node {i}: "
                f"{name} = {float(q[i]):.6g} ({bad.size} node(s) affected)"
            )


def residual(U: np.ndarray, ops: _Operators, gamma: float, visc: Viscosity) -> np.ndarray:
    """``R_i(U)`` of the module docstring (3, n_nodes), assembled cell-wise with bincount."""
    rho, u, p = primitives(U, gamma)
    F = np.stack((U[1], U[1] * u + p, (U[2] + p) * u))
    c = np.sqrt(gamma * p / rho)
    speed = np.abs(u) + c
    a, b = ops.a, ops.b
    nu = visc.coefficient(ops.h, np.maximum(speed[a], speed[b]), u[b] - u[a])
    half_dF = 0.5 * (F[:, b] - F[:, a])
    diffusive = nu / ops.h * (U[:, b] - U[:, a])
    n = ops.n_nodes
    offset = n * np.arange(3)[:, None]  # one bincount for the three components
    R = np.bincount((a + offset).ravel(), (-half_dF + diffusive).ravel(), 3 * n)
    R += np.bincount((b + offset).ravel(), (-half_dF - diffusive).ravel(), 3 * n)
    return R.reshape(3, n)


def time_derivative(U: np.ndarray, ops: _Operators, gamma: float, visc: Viscosity) -> np.ndarray:
    """``dU/dt = M^{-1} R(U)`` with ``d(rho u)/dt = 0`` at the wall nodes (3, n)."""
    R = residual(U, ops, gamma, visc)
    R[1, [0, -1]] = 0.0
    if ops.mass == "lumped":
        return R / ops.lumped
    out = np.empty_like(R)
    out[[0, 2]] = ops.solve_free(np.ascontiguousarray(R[[0, 2]].T)).T
    out[1] = ops.solve_wall(R[1])
    return out


def sod_initial_state(nodes: np.ndarray, gamma: float) -> np.ndarray:
    """Sod's data at the nodes, ``U`` (3, n); a node on the diaphragm takes the mean of the two
    conserved states, which centres the discrete jump on the diaphragm and makes the lumped
    integrals of mass and energy exact (0.5625 and 1.375 on [0, 1])."""
    def conserved(state):
        rho, u, p = state
        return np.array([rho, rho * u, p / (gamma - 1.0) + 0.5 * rho * u * u])

    UL, UR = conserved(SOD_LEFT), conserved(SOD_RIGHT)
    weight = np.where(np.isclose(nodes, SOD_DIAPHRAGM, rtol=0, atol=1e-12), 0.5, (nodes < SOD_DIAPHRAGM).astype(float))
    return UL[:, None] * weight + UR[:, None] * (1.0 - weight)


def label(mass: str = "lumped", viscosity: Viscosity = Viscosity()) -> str:
    """The baseline's name with its variant, e.g. ``"FEM P1 lumped (compression-only viscosity)"``."""
    check_mass(mass)
    return f"FEM P1 {mass} ({viscosity.name})"


def solve(
    h: float,
    T: float = 0.2,
    mass: str = "lumped",
    cfl: float = 0.3,
    gamma: float = 1.4,
    viscosity: Viscosity = Viscosity(),
    progress: bool = False,
    kernel: str = "fused",
) -> EulerFEMResult:
    """Sod's shock tube on a uniform mesh of size ``h`` up to time ``T`` (module docstring).

    ``kernel="fused"`` takes the steps in blocks of ``PROGRESS_EVERY`` with the compiled loop of
    :mod:`baselines.fem_euler_kernel` (bit for bit with the numpy step for the lumped mass, to
    round-off for the consistent one: a Thomas solve in place of SuperLU); ``"numpy"`` is the
    readable reference, :func:`_rk3_step`.

    Raises ValueError for bad input (``h`` not dividing [0, 1], ``cfl`` outside (0, 1], unknown
    ``mass`` or ``kernel``) and :class:`PositivityError` naming the step and node if density or
    pressure stops being positive (the same message from either kernel).
    """
    check_settings(mass, T, cfl=cfl)
    if not (np.isfinite(gamma) and gamma > 1):
        raise ValueError(f"gamma must be > 1, got gamma={gamma}")
    if kernel not in KERNELS:
        raise ValueError(f"unknown kernel {kernel!r}; choose one of {', '.join(KERNELS)}")
    grid = mesh(0.0, 1.0, h)
    ops = _operators(grid, mass)
    U = sod_initial_state(grid.nodes, gamma)
    run = _Run(ops, T, cfl, float(grid.h.min()), gamma, viscosity)
    take = _compiled_steps(run) if kernel == "fused" else _numpy_steps(run)

    t, steps = 0.0, 0
    while t < T * (1 - 1e-14):
        U, t, steps = take(U, t, steps, PROGRESS_EVERY)
        if progress and steps % PROGRESS_EVERY == 0:
            print(f"fem_euler h={h} {mass}: step {steps}, t={t:.4f}/{T}", flush=True)

    rho, u, p = primitives(U, gamma)
    settings = dict(
        problem="sod",
        h=h,
        T=T,
        mass=mass,
        cfl=cfl,
        gamma=gamma,
        viscosity=asdict(viscosity),
        viscosity_form="nu_e = h_e (linear max(|u|+c) + quadratic max(0, u_a - u_b)) on all of U"
        + (", where u_b < u_a only" if viscosity.compression_only else ""),
        viscosity_variant=viscosity.name,
        time_integrator="SSPRK3",
        dt_rule="cfl * h / max(|u| + c)",
        elements="P1",
        boundary="walls: rho u = 0 at both end nodes",
    )
    return EulerFEMResult(
        nodes=grid.nodes.copy(),
        rho=rho,
        u=u,
        p=p,
        e=p / ((gamma - 1.0) * rho),
        t=t,
        steps=steps,
        settings=settings,
    )


@dataclass(frozen=True)
class _Run:
    """What every step of a run needs: the operators, the final time, the step rule's ``cfl`` and
    ``h_min``, ``gamma`` and the viscosity."""

    ops: _Operators
    T: float
    cfl: float
    h_min: float
    gamma: float
    viscosity: Viscosity


def _rk3_step(U: np.ndarray, t: float, step: int, run: _Run) -> tuple[np.ndarray, float]:
    """Step number ``step`` (from 1) of SSP-RK3 in numpy from ``(U, t)``: ``dt = min(cfl h_min /
    max(|u| + c), T - t)``, ``U1 = U + dt L(U)``, ``U2 = 3/4 U + 1/4 (U1 + dt L(U1))``,
    ``U <- U/3 + 2/3 (U2 + dt L(U2))``; returns ``(U, t + dt)``. :class:`PositivityError` after
    the first stage whose density or pressure is not positive."""
    gamma = run.gamma

    def L(V):
        return time_derivative(V, run.ops, gamma, run.viscosity)

    rho, u, p = primitives(U, gamma)
    dt = min(run.cfl * run.h_min / float(np.max(np.abs(u) + np.sqrt(gamma * p / rho))), run.T - t)
    U1 = U + dt * L(U)
    _check_positive(U1, gamma, step, 1)
    U2 = 0.75 * U + 0.25 * (U1 + dt * L(U1))
    _check_positive(U2, gamma, step, 2)
    U = U / 3.0 + 2.0 / 3.0 * (U2 + dt * L(U2))
    _check_positive(U, gamma, step, 3)
    return U, t + dt


def _numpy_steps(run: _Run):
    """``take(U, t, first, count)``: steps ``first + 1 ... first + count`` of :func:`_rk3_step`,
    fewer if ``t`` reaches ``T``; returns ``(U, t, steps taken in all)``."""

    def take(U, t, first, count):
        steps = first
        while steps < first + count and t < run.T * (1 - 1e-14):
            steps += 1
            U, t = _rk3_step(U, t, steps, run)
        return U, t, steps

    return take


def _compiled_steps(run: _Run):
    """``take(U, t, first, count)`` of :func:`_numpy_steps` with the compiled loop
    (:mod:`baselines.fem_euler_kernel`). At a loss of positivity the kernel hands back the state
    before the step, and :func:`_rk3_step` retakes that step in numpy to raise its message (with
    the consistent mass, if round-off spares the numpy step, the kernel's failed stage is named)."""
    ops = run.ops
    empty = np.zeros(0)
    free = wall = (empty, empty, empty)
    if ops.mass == "consistent":
        free, wall = tridiagonal_factors(ops.M_free), tridiagonal_factors(ops.M_wall)
    cells = fem_euler_kernel.Cells(np.ascontiguousarray(ops.a, dtype=np.int64),
                                   np.ascontiguousarray(ops.b, dtype=np.int64), np.ascontiguousarray(ops.h),
                                   np.ascontiguousarray(ops.lumped), ops.mass == "consistent", *free, *wall)
    visc = run.viscosity
    gas = fem_euler_kernel.Gas(float(run.gamma), float(visc.linear), float(visc.quadratic), bool(visc.compression_only))
    work = fem_euler_kernel.work(ops.n_nodes)
    failed = np.empty((3, ops.n_nodes))

    def take(U, t, first, count):
        U = np.array(U, dtype=float, order="C")
        t, steps, stage = fem_euler_kernel.steps(U, t, first, count, run.T, run.cfl, run.h_min, cells, gas, work,
                                                 failed)
        if stage:
            _rk3_step(U, t, steps, run)  # raises PositivityError, the numpy loop's message
            _check_positive(failed, run.gamma, steps, stage)
        return U, t, steps

    return take
