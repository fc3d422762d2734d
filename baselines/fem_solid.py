"""Fixed-mesh total-Lagrangian FEM for a neo-Hookean solid in plane strain, on scikit-fem.

The baseline that 2D MPM is compared with on the same mesh size ``h``, for the manufactured solutions
of :mod:`baselines.exact.solids` (the model, the body force and the sources are there). With bilinear
elements (``ElementQuad1``, the hat functions ``N_i``) on the reference configuration, the nodal
displacements ``u_j`` (2 per node; ``u_h = sum_j u_j N_j``) satisfy

    sum_j M_ij d^2 u_j / dt^2 = f_i^ext(t) - f_i^int(u),
    f_i^int = int P(F_h) Grad N_i dX,        F_h = I + sum_j u_j (x) Grad N_j,
    f_i^ext = int rho0 b(X, t) N_i dX,       M_ij = int rho0 N_i N_j dX,

``P`` the first Piola stress (:func:`baselines.exact.solids.first_piola`). Every integral is taken with
the 2 x 2 Gauss rule of each cell; ``M`` is the consistent mass (scikit-fem, factorised once with
SuperLU) or its row sums (lumped). ``f^int`` is computed over the quadrature points with numpy, from
the basis gradients of scikit-fem's ``CellBasis`` (tested equal to scikit-fem's own ``LinearForm``
assembly).

Meshes (``MeshQuad.init_tensor``), both made periodic with scikit-fem's ``MeshQuad1DG.periodic``
(the nodes of one side replaced by those of the other, so the periodic DOFs are single unknowns):

* :class:`~baselines.exact.solids.AxisAligned`: the square ``[0, 2]^2`` in cells of side ``h``, periodic
  in X and Y;
* :class:`~baselines.exact.solids.GeneralizedVortex`: the annulus from a tensor mesh in ``(R, Theta)``,
  ``round((outer - inner) / h)`` cells in R and ``round(2 pi R_m / h)`` in Theta (side ``h`` on the
  mid circle ``R_m``), periodic in Theta, its nodes mapped to ``centre + R (cos Theta, sin Theta)``
  (straight-sided cells, a polygon of the annulus). Both circles are traction-free: the natural
  boundary condition, nothing imposed.

Time: central differences with the velocity at half steps,

    v^{n+1/2} = v^{n-1/2} + dt M^-1 (f^ext(t_n) - f^int(u^n)),     u^{n+1} = u^n + dt v^{n+1/2},

started from the nodal values ``u^0 = u(X_i, 0)`` and ``v^{-1/2} = v(X_i, -dt/2)`` of the exact
solution, with ``dt = cfl h / c`` (``c = sqrt(E / rho0)``) shortened so that ``T = steps dt``.

Error: the displacement error at the quadrature points, ``e = u_h(X_q) - u(X_q, t)``, in the L2 norm
normalised by the area of the mesh, ``sqrt(sum_q w_q |e_q|^2 / sum_q w_q)`` (a root-mean-square error),
at ``T`` and its maximum over the steps.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse
from scipy.sparse.linalg import splu
from skfem import BilinearForm, CellBasis, ElementQuad1, MeshQuad, MeshQuad1DG, asm

from baselines.exact.solids import AxisAligned, GeneralizedVortex, first_piola

MASSES = ("lumped", "consistent")
INTORDER = 3  # scikit-fem's order for quadrilaterals: the 2 x 2 Gauss rule


@dataclass(frozen=True)
class SolidFEMResult:
    """Nodal displacement ``u`` and velocity ``v`` (2, n_nodes) at the nodes ``X`` (2, n_nodes) after
    ``steps`` steps of ``dt`` (``u`` at ``t``, ``v`` at ``t - dt/2``); the normalised L2 displacement
    error at ``t`` (``error_L2``) and its maximum over the steps (``error_L2_max``)."""

    X: np.ndarray
    u: np.ndarray
    v: np.ndarray
    t: float
    steps: int
    dt: float
    error_L2: float
    error_L2_max: float
    settings: dict


@dataclass(frozen=True, eq=False)
class Discretisation:
    """The Q1 mesh data the step needs, over the ``n_q`` quadrature points ``q`` of all cells.

    ``X`` (2, n_nodes) the nodes; ``Xq`` (2, n_q) the quadrature points and ``w`` (n_q,) their weights
    (times the cell Jacobian); the sparse (n_q, n_nodes) matrices ``N`` (``N_i(X_q)``), ``D_X`` and
    ``D_Y`` (``dN_i/dX``, ``dN_i/dY`` at ``X_q``), so that a nodal field ``u`` has the values ``N @ u``
    and gradients ``D_X @ u``, ``D_Y @ u`` at the points and ``D_X.T @ (w s)`` is ``int s dN_i/dX``;
    ``lumped`` (n_nodes,) the row sums of ``int N_i N_j``; ``solve_mass`` applies ``(int N_i N_j)^-1`` to
    a (2, n_nodes) array (None for the lumped mass); ``basis`` scikit-fem's ``CellBasis``."""

    X: np.ndarray
    Xq: np.ndarray
    w: np.ndarray
    N: sparse.csr_matrix
    D_X: sparse.csr_matrix
    D_Y: sparse.csr_matrix
    lumped: np.ndarray
    basis: CellBasis
    mass: str
    solve_mass: object = None

    @property
    def n_nodes(self) -> int:
        return self.X.shape[1]

    @property
    def area(self) -> float:
        return float(self.w.sum())


def square_mesh(solution: AxisAligned, h: float) -> MeshQuad1DG:
    """The periodic square ``solution.domain`` in cells of side ``h``."""
    (x0, x1), (y0, y1) = solution.domain
    nx, ny = _cells(x1 - x0, h, "the square's side"), _cells(y1 - y0, h, "the square's side")
    mesh = MeshQuad.init_tensor(np.linspace(x0, x1, nx + 1), np.linspace(y0, y1, ny + 1))
    # Node (i, j) of the tensor mesh has index i * (ny + 1) + j (scikit-fem's init_tensor order).
    i, j = np.divmod(np.arange(mesh.nvertices), ny + 1)
    eliminated = np.flatnonzero((i == nx) | (j == ny))
    kept = (i[eliminated] % nx) * (ny + 1) + j[eliminated] % ny
    return MeshQuad1DG.periodic(mesh, eliminated, kept)


def annulus_mesh(solution: GeneralizedVortex, h: float) -> MeshQuad1DG:
    """The annulus of ``solution`` in cells of side about ``h`` (module docstring), periodic in Theta."""
    n_R = _cells(solution.outer - solution.inner, h, "the annulus' width")
    n_T = max(8, int(round(np.pi * (solution.inner + solution.outer) / h)))
    R_nodes = np.linspace(solution.inner, solution.outer, n_R + 1)
    mesh = MeshQuad.init_tensor(R_nodes, np.linspace(0, 2 * np.pi, n_T + 1))
    i, j = np.divmod(np.arange(mesh.nvertices), n_T + 1)
    eliminated = np.flatnonzero(j == n_T)
    kept = i[eliminated] * (n_T + 1)
    R, Theta = mesh.p
    x0, y0 = solution.centre
    mapped = MeshQuad(np.stack([x0 + R * np.cos(Theta), y0 + R * np.sin(Theta)]), mesh.t)
    return MeshQuad1DG.periodic(mapped, eliminated, kept)


def _cells(length: float, h: float, what: str) -> int:
    if not (np.isfinite(h) and 0 < h <= length):
        raise ValueError(f"fem_solid: the mesh size must satisfy 0 < h <= {length:g} ({what}), got h = {h}")
    n = int(round(length / h))
    if abs(n * h - length) > 1e-9 * length:
        raise ValueError(f"fem_solid: h = {h} does not divide {what} {length:g}")
    return n


def discretise(solution, h: float, mass: str = "lumped") -> Discretisation:
    """The mesh of ``solution`` (module docstring) with its Q1 basis data and mass."""
    if mass not in MASSES:
        raise ValueError(f"unknown mass {mass!r}; choose one of {', '.join(MASSES)}")
    if isinstance(solution, AxisAligned):
        mesh = square_mesh(solution, h)
    elif isinstance(solution, GeneralizedVortex):
        mesh = annulus_mesh(solution, h)
    else:
        raise ValueError(f"fem_solid: no mesh for {type(solution).__name__}; AxisAligned or GeneralizedVortex")
    basis = CellBasis(mesh, ElementQuad1(), intorder=INTORDER)
    n_cells, n_q = basis.dx.shape
    # Point (cell, q) is row cell * n_q + q; local function a of the cell is node element_dofs[a, cell].
    rows = np.broadcast_to(np.arange(n_cells * n_q).reshape(n_cells, n_q), (4, n_cells, n_q)).ravel()
    cols = np.broadcast_to(basis.element_dofs[:, :, None], (4, n_cells, n_q)).ravel()

    def at_points(values):  # values (4, n_cells, n_q) -> sparse (n_points, n_nodes)
        return sparse.csr_matrix((values.ravel(), (rows, cols)), shape=(n_cells * n_q, basis.N))

    grad = np.stack([basis.basis[a][0].grad for a in range(4)])  # (4, 2, n_cells, n_q)
    M = asm(BilinearForm(lambda u, v, w: u * v), basis).tocsc()
    X = basis.doflocs.copy()
    if isinstance(solution, AxisAligned):  # the periodic node's representative in [0, L)
        for k, (lo, hi) in enumerate(solution.domain):
            X[k] = lo + np.mod(X[k] - lo, hi - lo)
    solve_mass = None
    if mass == "consistent":
        lu = splu(M)

        def solve_mass(f):
            return lu.solve(np.ascontiguousarray(f.T)).T

    return Discretisation(
        X=X,
        Xq=np.asarray(basis.global_coordinates()).reshape(2, -1),
        w=basis.dx.ravel(),
        N=at_points(np.stack([np.asarray(basis.basis[a][0]) for a in range(4)])),
        D_X=at_points(grad[:, 0]),
        D_Y=at_points(grad[:, 1]),
        lumped=np.asarray(M.sum(axis=1)).ravel(),
        basis=basis,
        mass=mass,
        solve_mass=solve_mass,
    )


def deformation_gradient(u: np.ndarray, disc: Discretisation) -> np.ndarray:
    """``F_h = I + sum_j u_j (x) Grad N_j`` at the quadrature points, (n_q, 2, 2), from the nodal
    displacement ``u`` (2, n_nodes)."""
    F = np.stack([(disc.D_X @ u.T), (disc.D_Y @ u.T)], -1)  # [q, i, J] = du_i/dX_J
    F[:, 0, 0] += 1.0
    F[:, 1, 1] += 1.0
    return F


def internal_force(u: np.ndarray, disc: Discretisation, material) -> np.ndarray:
    """``f_i^int = int P(F_h) Grad N_i dX`` (2, n_nodes) at the nodal displacement ``u`` (2, n_nodes)."""
    wP = first_piola(deformation_gradient(u, disc), material) * disc.w[:, None, None]  # (n_q, 2, 2)
    return (disc.D_X.T @ wP[:, :, 0] + disc.D_Y.T @ wP[:, :, 1]).T


def external_force(b_q: np.ndarray, disc: Discretisation, rho0: float) -> np.ndarray:
    """``f_i^ext = int rho0 b N_i dX`` (2, n_nodes) from the body force ``b_q`` (2, n_q) at the
    quadrature points."""
    return (disc.N.T @ (rho0 * disc.w * b_q).T).T


def l2_error(u: np.ndarray, disc: Discretisation, solution, t: float) -> float:
    """``sqrt(sum_q w_q |u_h(X_q) - u(X_q, t)|^2 / sum_q w_q)``."""
    e = (disc.N @ u.T).T - solution.displacement(disc.Xq[0], disc.Xq[1], t)
    return float(np.sqrt(np.sum(disc.w * (e[0] ** 2 + e[1] ** 2)) / disc.area))


def acceleration(f: np.ndarray, disc: Discretisation, rho0: float) -> np.ndarray:
    """``M^-1 f`` for the nodal force ``f`` (2, n_nodes), ``M = rho0 int N_i N_j`` or its row sums."""
    if disc.mass == "lumped":
        return f / (rho0 * disc.lumped)
    return disc.solve_mass(f) / rho0


def central_differences(u, v_half, disc: Discretisation, material, dt: float, steps: int, body_force=None,
                        observe=None):
    """``steps`` steps of the module's central differences from ``u^0 = u`` and ``v^{-1/2} = v_half``
    (both (2, n_nodes)). ``body_force(t)`` gives ``b`` (2, n_q) at the quadrature points (None:
    no body force); ``observe(n, u)`` is called with ``u^n`` for ``n = 1 ... steps``. Returns
    ``(u^steps, v^{steps - 1/2})``; raises ArithmeticError if ``u`` stops being finite or ``det F_h``
    positive (an unstable step)."""
    u, v = np.array(u, dtype=float), np.array(v_half, dtype=float)
    for n in range(steps):  # steps in time, not nodes
        try:
            f = -internal_force(u, disc, material)
        except ValueError as inverted:
            raise ArithmeticError(f"fem_solid: step {n + 1} (t = {n * dt:.6g}): {inverted}") from None
        if body_force is not None:
            f += external_force(body_force(n * dt), disc, material.rho0)
        v += dt * acceleration(f, disc, material.rho0)
        u += dt * v
        if not np.all(np.isfinite(u)):
            raise ArithmeticError(f"fem_solid: the displacement became non-finite at step {n + 1}")
        if observe is not None:
            observe(n + 1, u)
    return u, v


#: the default ``cfl`` of each solution: inside the stability limit of both masses (module docstring of solve).
DEFAULT_CFL = {AxisAligned: 0.25, GeneralizedVortex: 0.05}


def solve(solution, h: float, T: float | None = None, mass: str = "lumped", cfl: float | None = None
          ) -> SolidFEMResult:
    """The FEM solution of ``solution`` (:class:`~baselines.exact.solids.AxisAligned` or
    :class:`~baselines.exact.solids.GeneralizedVortex`) on the mesh of size ``h`` up to ``T`` (default:
    one period), ``dt = cfl h / c`` shortened to divide ``T`` (module docstring).

    The default ``cfl`` (:data:`DEFAULT_CFL`) is inside the stability limit of both masses: for the
    axis-aligned solution 0.25 (small strain, ``nu = 0.3``: ``dt < 2 / omega_max``, ``omega_max^2`` the
    largest eigenvalue of ``M^-1 K`` at ``u = 0``, is ``cfl < 0.86`` lumped, ``0.44`` consistent); for the
    vortex with ``A = 1`` 0.05
    (shears ``g = R alpha_R`` up to about 7 stretch the material and speed its waves up; at h = 1/16 the
    consistent mass is unstable from about 0.09).

    Raises ValueError for bad input and ArithmeticError if the solution becomes non-finite or a
    cell inverts."""
    if cfl is None:
        cfl = DEFAULT_CFL.get(type(solution), 0.25)
    if not (np.isfinite(cfl) and 0 < cfl <= 1):
        raise ValueError(f"fem_solid: cfl must be in (0, 1], got cfl = {cfl}")
    T = solution.period if T is None else float(T)
    if not (np.isfinite(T) and T > 0):
        raise ValueError(f"fem_solid: the end time must satisfy T > 0, got T = {T}")
    disc = discretise(solution, h, mass)
    material = solution.material
    steps = int(np.ceil(T / (cfl * h / material.c) * (1 - 1e-12)))
    dt = T / steps
    X, Y = disc.X

    def body_force(t):
        return solution.body_force(disc.Xq[0], disc.Xq[1], t)

    errors = []

    def observe(n, u):
        errors.append(l2_error(u, disc, solution, n * dt))

    u, v = central_differences(
        solution.displacement(X, Y, 0.0), solution.velocity(X, Y, -0.5 * dt), disc, material, dt, steps,
        body_force, observe,
    )
    settings = dict(
        problem="neo-Hookean solid, plane strain",
        solution=type(solution).__name__,
        amplitude=solution.amplitude,
        E=material.E,
        nu=material.nu,
        rho0=material.rho0,
        h=h,
        T=T,
        mass=mass,
        cfl=cfl,
        dt_rule="cfl h / sqrt(E / rho0), then T / ceil(T / dt)",
        time_integrator="central differences, velocity at half steps",
        elements="Q1 (scikit-fem ElementQuad1), 2 x 2 Gauss",
        mesh="periodic square" if isinstance(solution, AxisAligned) else "annulus, periodic in Theta",
        n_nodes=disc.n_nodes,
        error_norm="sqrt(sum_q w_q |u_h - u|^2 / area) at the quadrature points",
    )
    return SolidFEMResult(X=disc.X, u=u, v=v, t=steps * dt, steps=steps, dt=dt, error_L2=errors[-1],
                          error_L2_max=max(errors), settings=settings)
