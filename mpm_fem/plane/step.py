"""One explicit 2D MPM step, update stress last (USL), symplectic Euler: the numpy reference.

The particles carry ``v_p^{n-1/2}`` (the run starts from the exact ``v(X_p, -dt/2)``), ``x_p^n``,
``F_p^n``; one step from ``t_n`` to ``t_n + dt``:

    m_i = sum_p m_p S_ip,      P_i = sum_p m_p v_p S_ip,
    f_i = - sum_p V_p sigma_p G_ip + sum_p m_p b(X_p, t_n) S_ip         (internal + body force)
    v_i = M^-1 P_i,  a_i = M^-1 f_i               (the grid mass ``mass``, :mod:`mpm_fem.masses`: lumped
                                                  P_i / m_i; consistent the particle mass matrix
                                                  M_ij = sum_p m_p S_ip S_jp; grid rho0 int S_i S_j;
                                                  fmpm<k> the truncated series of M^-1)
    v_i^+ = v_i + dt a_i
    v_p <- flip (v_p + dt sum_i S_ip a_i) + (1 - flip) sum_i S_ip v_i^+      (FLIP/PIC blend)
    x_p <- x_p + dt sum_i S_ip v_i^+
    F_p <- (I + dt sum_i v_i^+ (x) G_ip) F_p,   V_p = det(F_p) V_p^0,   sigma_p: :mod:`~mpm_fem.plane.model`

MUSL (``scheme="musl"``, as in 1D): the velocity gradient takes ``v_i^+`` re-projected from the new
particle velocities, ``v_i^+ = sum_p m_p v_p S_ip / m_i`` (or the consistent solve), which keeps a
node that a particle barely touches (a free surface) from handing its large ``a_i`` to ``L_p``.
(``S_ip``, ``G_ip``: :mod:`~mpm_fem.plane.bases`). A node without mass gets ``v_i = a_i = 0``.
The stage switches are the 1D :class:`~mpm_fem.core.step.Stages` (``mass``, ``projection``,
``interpolation``, ``acceleration``, ``flip``; ``refine`` is the time loop's), their exact forms
those of :mod:`mpm_fem.exact_stages.stage` as :mod:`mpm_fem.plane.exact` gives them; the 1D-only
switches (``scheme`` USF, ``xpic``, ``reconstruct``, ``volume``, ``transfer``, ``volume_rate``) must keep
their defaults. The basis is the ``basis`` argument (``stages.basis`` is not read); the grid mass is the
``mass`` argument (a name of :func:`mpm_fem.masses.names` or a :class:`~mpm_fem.masses.GridMass`;
default ``stages.mass``), whose ``stage`` must be ``stages.mass``. No Python loop runs over
particles or nodes.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass
from typing import Callable, NamedTuple, Protocol

import numpy as np
import scipy.sparse as sp

import mpm_fem.masses as masses
from mpm_fem.bases.contract import Basis
from mpm_fem.core.step import Stages
from mpm_fem.masses.consistent import factorised
from mpm_fem.masses.contract import GridMass, MassSystem
from mpm_fem.plane.bases import PlaneShape, plane_shape, tensor_basis
from mpm_fem.plane.grid import PlaneGrid
from mpm_fem.plane.mass import grid_mass, q1_mass
from mpm_fem.plane.model import check_orientation, determinant, neo_hookean_stress, update_deformation
from mpm_fem.plane.state import PlaneParticles

#: the 1D switches the 2D step does not offer, with the value they must keep
ONE_D_ONLY = {"xpic": 0, "reconstruct": "none", "volume": "carried", "transfer": "flip",
              "volume_rate": "point"}
SCHEMES = ("usl", "musl")
BodyForce = Callable[[np.ndarray, np.ndarray, float], np.ndarray]  # (X, Y, t) -> (2, n) per unit mass


def check_stages(stages: Stages) -> None:
    """Raise ``ValueError`` for a switch the 2D step does not take (module docstring)."""
    if stages.scheme not in SCHEMES:
        raise ValueError(f"the 2D step runs the schemes {', '.join(SCHEMES)}, got {stages.scheme!r}")
    for name, value in ONE_D_ONLY.items():
        if getattr(stages, name) != value:
            raise ValueError(f"the 2D step runs with {name}={value!r}, got {getattr(stages, name)!r}")


@dataclass(frozen=True, eq=False)
class PlaneGridState:
    """What the grid held in one step: ``mass`` (n_nodes,), ``velocity`` ``v_i``, ``acceleration``
    ``a_i`` and ``new_velocity`` ``v_i^+`` (n_nodes, 2)."""

    mass: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    new_velocity: np.ndarray


class Projected(NamedTuple):
    """The exact projection's nodal sums ``m*_i`` (n_nodes,), ``P*_i``, ``f*_i`` (n_nodes, 2), and
    ``solver(kind, grid_solve)``: the solve of its data by the grid mass ``kind`` (:mod:`mpm_fem.masses`)."""

    m_i: np.ndarray
    P_i: np.ndarray
    f_i: np.ndarray
    solver: Callable[..., Callable[[np.ndarray], np.ndarray]]


class Nodal(NamedTuple):
    """The exact nodal velocity ``v*_i`` (at ``t - dt/2``) and acceleration ``a*_i`` (n_nodes, 2)."""

    v: np.ndarray
    a: np.ndarray


class ExactPlane(Protocol):
    """The exact stages as the step reaches them (:class:`mpm_fem.plane.exact.ExactStages2`):
    :class:`Projected`, :class:`Nodal` and, at the particles, ``(v*_p, a*_p, L*_p)``."""

    def projection(self, grid: PlaneGrid, basis: Basis, t: float, dt: float) -> Projected: ...

    def nodal(self, grid: PlaneGrid, t: float, dt: float) -> Nodal: ...

    def at_particles(self, X: np.ndarray, t: float, dt: float) -> tuple: ...


def lumped(rhs: np.ndarray, m_i: np.ndarray) -> np.ndarray:
    """``rhs_i / m_i`` (n_nodes, 2) where ``m_i > 0``, else 0."""
    out = np.zeros_like(rhs)
    np.divide(rhs, m_i[:, None], out=out, where=(m_i > 0)[:, None])
    return out


def consistent_solver(shape: PlaneShape, mass: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
    """``rhs -> M^{-1} rhs`` (n_nodes, 2) with the particle mass matrix ``M = S^T diag(m) S``
    factorised once (sparse LU) on the nodes with mass; the others get 0
    (:mod:`mpm_fem.masses.consistent`)."""
    return masses.get("consistent").solver(MassSystem(shape.matrix(), mass, shape.scatter(mass)))


def step_with_grid(state: PlaneParticles, grid: PlaneGrid, basis: str | Basis, material, dt: float, t: float,
                   body_force: BodyForce | None, stages: Stages = Stages(),
                   exact: ExactPlane | None = None, mass: str | GridMass | None = None
                   ) -> tuple[PlaneParticles, PlaneGridState]:
    """:func:`step`, also returning the grid's :class:`PlaneGridState`."""
    check_stages(stages)
    grid_mass_ = grid_mass_of(stages, mass)
    if stages.uses_exact_fields or stages.acceleration == "exact":
        if exact is None:
            raise ValueError("the exact projection, mass, interpolation and acceleration stages need the "
                             "problem's exact solution (exact=...)")
    shape = plane_shape(grid, basis, state.x, state.lengths)
    m = state.mass
    m_i = shape.scatter(m)
    P_i = shape.scatter(m[:, None] * state.v)
    f_i = -shape.scatter_gradient(state.volume[:, None, None] * neo_hookean_stress(state.F, material.mu, material.lam))
    if body_force is not None:
        f_i += shape.scatter(m[:, None] * np.asarray(body_force(state.X[:, 0], state.X[:, 1], t)).T)

    grid_solve = _grid_solver(grid, basis, material.rho0)
    solve = grid_mass_.solver(MassSystem(shape.matrix(), m, m_i, grid_solve))
    star = exact.nodal(grid, t, dt) if exact is not None and _needs_nodal(stages) else None
    quad = exact.projection(grid, basis, t, dt) if stages.projection == "exact" or stages.mass == "exact" else None
    v_i, a_i = _grid_values(stages, solve, m_i, P_i, f_i, quad, star, grid_mass_, grid_solve)
    active = (m_i > 0)[:, None]
    v_i, a_i = np.where(active, v_i, 0.0), np.where(active, a_i, 0.0)
    v_new = v_i + dt * a_i

    if stages.interpolation == "exact":  # f_p = f*(X_p) + sum_i S_ip (f_i - f*_i)
        v_star, a_star, L_star = exact.at_particles(state.X, t, dt)
        star_new = star.v + dt * star.a
        acceleration = a_star + shape.gather(a_i - star.a)
        moving = v_star + dt * a_star + shape.gather(v_new - star_new)
        L = L_star + shape.gather_gradient(v_new - star_new)
    else:
        acceleration, moving = shape.gather(a_i), shape.gather(v_new)
        L = shape.gather_gradient(v_new)
    v = stages.flip * (state.v + dt * acceleration) + (1.0 - stages.flip) * moving
    x = state.x + dt * moving
    if stages.scheme == "musl":  # the velocity gradient from the grid velocity re-projected from the new v_p
        v_new = np.where(active, solve(shape.scatter(m[:, None] * v)), 0.0)
        L = shape.gather_gradient(v_new)
    F = update_deformation(state.F, L, dt)
    J = determinant(F)
    check_orientation(J, x)
    new = state.replace(x=x, v=v, F=F, volume=J * state.volume0)
    return new, PlaneGridState(m_i, v_i, a_i, v_new)


def grid_mass_of(stages: Stages, mass: str | GridMass | None) -> GridMass:
    """The grid mass ``mass`` (default ``stages.mass``) from the registry; ``ValueError`` for an unknown
    name or one whose stage is not ``stages.mass``."""
    grid_mass_ = masses.get(stages.mass if mass is None else mass)
    if grid_mass_.stage != stages.mass:
        raise ValueError(f"the {grid_mass_.name} mass is a {grid_mass_.stage} mass stage; the stages say "
                         f"mass={stages.mass!r}")
    return grid_mass_


#: the grid basis's own mass matrix of each grid, factorised once: {grid: {(basis, rho0): solve}}
_GRID_SOLVES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def grid_basis_matrix(grid: PlaneGrid, basis: str | Basis, rho0: float) -> sp.csr_matrix:
    """``rho0 int S_i S_j`` of the grid functions of ``basis``: scikit-fem's Q1 mass for the bases on the
    hats (the point mass, uGIMP), the kron of the 1D Gram matrices for the B-splines
    (:mod:`mpm_fem.plane.mass`)."""
    functions = tensor_basis(basis).grid_functions
    return q1_mass(grid, rho0) if functions == "mpm" else grid_mass(grid, basis, rho0)


def _grid_solver(grid: PlaneGrid, basis: str | Basis, rho0: float):
    """A callable giving the solve of :func:`grid_basis_matrix`, factorised on its first call and kept."""
    key = (tensor_basis(basis).name, float(rho0))

    def get():
        kept = _GRID_SOLVES.setdefault(grid, {})
        if key not in kept:
            M = grid_basis_matrix(grid, basis, rho0)
            kept[key] = factorised(M, M.diagonal(), "grid basis's mass matrix")
        return kept[key]

    return get


def _grid_values(stages: Stages, solve, m_i, P_i, f_i, quad: Projected | None, star: Nodal | None,
                 grid_mass_: GridMass | None = None, grid_solve=None):
    """``v_i``, ``a_i`` (n_nodes, 2) from the particles' sums, the mass stage's form
    (:mod:`mpm_fem.exact_stages.stage`): MPM ``solve(P_i)``, ``solve(f_i)``; projection exact the
    quadrature's data solved; mass exact ``v*_i + P_i/m_i - P*_i/m*_i`` (lumped solves); both exact
    ``v*_i``, ``a*_i``; the acceleration exact ``a*_i`` whatever the others."""
    if stages.projection == "exact" and stages.mass == "exact":
        v_i, a_i = star.v.copy(), star.a.copy()
    elif stages.projection == "exact":
        solve_q = quad.solver(grid_mass_ or stages.mass, grid_solve)
        v_i, a_i = _both(solve_q, quad.P_i, quad.f_i)
    elif stages.mass == "exact":
        v_i = star.v + lumped(P_i, m_i) - lumped(quad.P_i, quad.m_i)
        a_i = star.a + lumped(f_i, m_i) - lumped(quad.f_i, quad.m_i)
    else:
        v_i, a_i = _both(solve, P_i, f_i)
    if stages.acceleration == "exact":
        a_i = star.a.copy()
    return v_i, a_i


def _both(solve, P_i: np.ndarray, f_i: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``solve(P_i)``, ``solve(f_i)`` in one call (an iterated mass pays its extrapolations once)."""
    both = solve(np.hstack((P_i, f_i)))
    return both[:, :P_i.shape[1]], both[:, P_i.shape[1]:]


def _needs_nodal(stages: Stages) -> bool:
    """Whether a stage reads the exact nodal ``v*_i``, ``a*_i``."""
    return (stages.mass == "exact" or stages.interpolation == "exact" or stages.acceleration == "exact")


def step(state: PlaneParticles, grid: PlaneGrid, basis: str | Basis, material, dt: float, t: float,
         body_force: BodyForce | None, stages: Stages = Stages(), exact: ExactPlane | None = None,
         mass: str | GridMass | None = None) -> PlaneParticles:
    """Advance the particles from ``t`` to ``t + dt`` (module docstring).

    Parameters
    ----------
    state : PlaneParticles
        The particles at ``t`` (velocity at ``t - dt/2``).
    grid : PlaneGrid
    basis : str or Basis
        The 1D basis whose tensor product is the 2D basis.
    material
        ``mu``, ``lam`` (Pa): the neo-Hookean constants.
    dt, t : float
        Time step and time (s).
    body_force : callable or None
        ``b(X, Y, t) -> (2, n)`` per unit mass at the reference positions.
    stages : Stages
        The stage switches; ``exact`` serves their exact forms.
    mass : str or GridMass, optional
        The grid mass (:mod:`mpm_fem.masses`); default ``stages.mass``.

    Returns
    -------
    PlaneParticles
        The particles at ``t + dt`` (velocity at ``t + dt/2``). Raises
        :class:`~mpm_fem.plane.model.InversionError` for a particle with ``det F <= 0``.
    """
    return step_with_grid(state, grid, basis, material, dt, t, body_force, stages, exact, mass)[0]
