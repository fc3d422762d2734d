"""The Burgers MPM time loop at array level, for the standard stages (point mass, USL).

The same step as :func:`mpm_fem.step.explicit_step` with the problem of :mod:`.burgers` (slides,
"Forward Euler time integration" and "Burgers' Problem"), written on the particle arrays directly:
one cell search, the two-node P1 weights ``S = (1 - xi, xi)``, ``G = (-1, 1)/h`` and bincounts,
with no per-step objects and the boundary data evaluated once per step. With quadrature weights
``w_p`` (below) and unit density (``m_p = V_p = w_p``):

    m_i = sum_p w_p S_ip,   v_i = sum_p w_p v_p S_ip / m_i            (lumped; consistent: M v = P)
    a_i = eps v_xx(x_i, t)                                            (acceleration "exact")
    a_i = F_i / m_i,   F_i = - sum_p w_p eps (dv/dx)_p G_ip           (calculated, force "weak")
    a_i = eps [ (v_{i+1} - v_i) [N_{i+1} > 0] - (v_i - v_{i-1}) [N_i > 0] ] / h^2
                                                                      (calculated, force "slides")
    v_i, a_i at the two end nodes: the Dirichlet data, a_i = (g(t + dt) - v_i) / dt
    v_p += dt sum_i S_ip a_i,   x_p += dt sum_i S_ip (v_i + dt a_i),   V_p *= 1 + dt (dv/dx)_p^{n+1}

The force "slides" is the slides' formula ``a_i = -eps (v_i - v_{i-1}) / (h^2 N_p^i) sum_{p in
I_i} 1 + eps (v_{i+1} - v_i) / (h^2 N_p^{i+1}) sum_{p in I_{i+1}} 1``: the count-normalised sums
make each cell weigh exactly ``h``, whatever particles it holds. The weights are

    "volume"  w_p = V_p, the particle volume carried by the flow (standard MPM)
    "cell"    w_p = h / N_p^i for the N_p^i particles of cell I_i (the slides' m_ip = h rho_p / N_p^i
              and their count-weighted velocity lambda_ip = S_ip N_p^j / sum_p S_ip N_p^j)

The time step is ``dt = CFL min(h / max|v_p|, h^2 / (2 eps)) / refine`` (dt rule "stable"), or
without the viscous limit, ``CFL h / max|v_p| / refine`` ("advective"), which only the exact
acceleration may use: it computes no viscous force, so the explicit-diffusion limit does not
apply to it. Tested against :func:`mpm_fem.solve.run` to round-off (``tests/test_burgers_study.py``).
"""

from __future__ import annotations

import time

import numpy as np
from tqdm.auto import tqdm

from ..grid import uniform_grid
from ..particles import Particles, PositivityError, make_particles
from ..shape import point_shape
from ..solve import Result
from ..step import GridState
from ..transfer import solve_consistent

def supports(settings) -> bool:
    """Whether this loop implements ``settings``: point mass, USL, MPM projection and interpolation,
    lumped or consistent mass, no remedy (the general :func:`mpm_fem.solve.run` does the rest)."""
    return (settings.basis == "mpm" and settings.scheme == "usl" and settings.projection == "mpm"
            and settings.interpolation == "mpm" and settings.mass in ("lumped", "consistent")
            and not settings.stages.uses_remedy)


def cells(x: np.ndarray, a: float, h: float, n_cells: int) -> tuple[np.ndarray, np.ndarray]:
    """Cell ``c = floor((x - a)/h)`` and local coordinate ``xi = (x - a)/h - c`` on the uniform grid.

    The particles are inside ``[a, b]`` (the reservoir removes the others), so no bounds check; a
    point within round-off of a node may be given to either cell, which changes nothing beyond
    round-off since the P1 interpolant is continuous (:func:`mpm_fem.shape.locate` is the careful
    version, used by the general loop).
    """
    s = (x - a) * (1.0 / h)
    cell = s.astype(np.intp)
    np.minimum(cell, n_cells - 1, out=cell)  # x = b belongs to the last cell; x >= a gives cell >= 0
    return cell, s - cell


def to_nodes(total: np.ndarray, moment: np.ndarray) -> np.ndarray:
    """``sum_p q_p S_ip`` from the per-cell sums ``total_c = sum_{p in c} q_p`` and ``moment_c =
    sum_{p in c} q_p xi_p``: the left node of cell c gets ``total - moment``, the right ``moment``."""
    out = np.zeros(total.size + 1)
    out[:-1] = total - moment
    out[1:] += moment
    return out


def cell_weights(cell: np.ndarray, h: float, n_cells: int) -> np.ndarray:
    """``w_p = h / N_p^i`` for the particles of cell ``i`` (the slides' ``m_ip``)."""
    count = np.bincount(cell, minlength=n_cells)
    return h / count[cell]


def simulate(settings, progress: bool | None = None, observer=None) -> Result:
    """Run MPM on viscous Burgers with ``settings`` (a ``BurgersSettings``, with its ``weights``,
    ``force`` and ``dt_rule``); the module docstring gives the equations. ``observer(step, t, old,
    new, grid_state)`` as for :func:`mpm_fem.solve.run`."""
    from .burgers import initial_particles

    if not supports(settings):
        raise ValueError("the fast Burgers loop runs point mass, USL, MPM projection and interpolation with a "
                         f"lumped or consistent mass only; got {settings.stages}")
    weights, force, dt_rule = settings.weights, settings.force, settings.dt_rule
    eps, T, cfl = float(settings.eps), float(settings.T), float(settings.cfl)
    refine = int(settings.refine)
    solution = settings.exact
    grid = uniform_grid(*solution.domain, settings.h)
    h = float(grid.h.mean())
    nodes, n_nodes, n_cells = grid.nodes, grid.n_nodes, grid.n_cells
    a = float(nodes[0])
    ends = grid.boundary_nodes
    spacing = settings.h / settings.ppc
    consistent = settings.mass == "consistent"
    exact_acc = settings.acceleration == "exact"

    P0 = initial_particles(settings, grid)
    x, v, V = P0.x.copy(), P0.velocity.copy(), P0.volume.copy()
    start = time.perf_counter()
    t, steps, dts = 0.0, 0, []
    dirichlet = EndValues(solution.v, nodes[ends])
    g_now = solution.v(nodes[ends], 0.0)
    disable = {True: False, False: True, None: None}[progress]
    bar = tqdm(total=T, disable=disable, delay=2.0, leave=False,
               bar_format="{l_bar}{bar}| t={n:.4g}/{total:.4g} [{elapsed}<{remaining}]")

    def grid_solve(w, m_i, rhs):
        if not consistent:
            out = np.zeros_like(rhs)
            np.divide(rhs, m_i, out=out, where=m_i > 0)
            return out
        return solve_consistent(point_shape(grid, x), w, rhs)

    try:
        while t < T * (1 - 1e-12):
            vmax = float(np.abs(v).max())
            dt = cfl * (h / vmax if vmax > 0 else np.inf)
            if dt_rule == "stable":
                dt = min(dt, cfl * h * h / (2.0 * eps))
            dt = min(dt / refine, T - t)
            if not (dt > 0 and np.isfinite(dt)):
                raise FloatingPointError(f"time step {dt!r} at step {steps} (t={t:.6g}) is not positive and finite")

            cell, xi = cells(x, a, h, n_cells)
            w = V if weights == "volume" else cell_weights(cell, h, n_cells)
            wx = w * xi
            m_i = to_nodes(np.bincount(cell, w, n_cells), np.bincount(cell, wx, n_cells))
            P_i = to_nodes(np.bincount(cell, w * v, n_cells), np.bincount(cell, wx * v, n_cells))
            v_i = grid_solve(w, m_i, P_i)
            v_i[ends] = g_now

            if exact_acc:
                a_i = eps * solution.v_xx(nodes, t)
            elif force == "weak":
                # F_i = -sum_p V_p sigma_p G_ip, sigma_p = eps (dv/dx)_p: per cell, C_c = sum V_p sigma_p
                C = np.bincount(cell, w * (v_i[1:] - v_i[:-1])[cell], n_cells) * (eps / (h * h))
                F_i = np.zeros(n_nodes)
                F_i[:-1] += C
                F_i[1:] -= C
                a_i = grid_solve(w, m_i, F_i)
            else:
                occupied = np.bincount(cell, minlength=n_cells) > 0
                flux = np.where(occupied, v_i[1:] - v_i[:-1], 0.0)  # (v_{i+1} - v_i) [N_{i+1} > 0]
                a_i = np.zeros(n_nodes)
                a_i[:-1] += flux
                a_i[1:] -= flux
                a_i *= eps / (h * h)
            t_next, g_next = dirichlet.step(t, dt)
            a_i[ends] = (g_next - v_i[ends]) / dt
            v_new = v_i + dt * a_i

            dv_new = (v_new[1:] - v_new[:-1])[cell]
            v_p = v + dt * (a_i[cell] + xi * (a_i[1:] - a_i[:-1])[cell])
            x_p = x + dt * (v_new[cell] + xi * dv_new)
            factor = 1.0 + (dt / h) * dv_new
            if not np.all(factor > 0):
                p = int(np.flatnonzero(~(factor > 0))[0])
                raise PositivityError("1 + (dv/dx) dt", p, float(x[p]), float(factor[p]), steps, t)
            V_p = V * factor
            if not np.isfinite(v_i).all():
                raise FloatingPointError(f"non-finite grid velocity at step {steps} (t={t:.6g})")

            if observer is not None:
                old = make_state(x, v, V)
            x, v, V = feed(x_p, v_p, V_p, spacing, grid.domain, solution.v, t_next)
            if observer is not None:
                observer(steps, t, old, make_state(x, v, V), GridState(m_i, v_i, a_i, v_new))
            t, g_now = t_next, g_next
            steps += 1
            dts.append(dt)
            bar.update(dt)
    finally:
        bar.close()

    cell, xi = cells(x, a, h, n_cells)
    if weights == "cell":
        V = cell_weights(cell, h, n_cells)
    wx = V * xi
    m_i = to_nodes(np.bincount(cell, V, n_cells), np.bincount(cell, wx, n_cells))
    P_i = to_nodes(np.bincount(cell, V * v, n_cells), np.bincount(cell, wx * v, n_cells))
    v_i = grid_solve(V, m_i, P_i)
    return Result(
        particles=make_state(x, v, V), grid=grid, t=t, steps=steps, wall_s=time.perf_counter() - start,
        nodal_mass=m_i, nodal_velocity=v_i, dt_min=min(dts, default=0.0), dt_max=max(dts, default=0.0),
    )


class EndValues:
    """The Dirichlet data ``g(x_end, t + dt)`` at the two end nodes, and the clock ``t + dt``.

    While the step is constant (the viscous limit), the data of the next steps are evaluated in
    one call, for up to 512 step times ``t0 + k dt`` at once; the clock is then ``t0 + k dt``
    rather than a running sum (the same times to round-off).
    """

    def __init__(self, g, x_ends):
        self.g, self.x = g, np.asarray(x_ends, float)[None, :]
        self.times = self.values = np.empty(0)
        self.dt, self.k, self.n = None, 0, 1

    def step(self, t: float, dt: float) -> tuple[float, np.ndarray]:
        if not (dt == self.dt and self.k < self.times.size and (self.k == 0 or t == self.times[self.k - 1])):
            self.n = min(512, 2 * self.n) if dt == self.dt else 1
            self.dt, self.k = dt, 0
            self.times = t + dt * np.arange(1, self.n + 1)
            self.values = self.g(self.x, self.times[:, None])
        self.k += 1
        return float(self.times[self.k - 1]), self.values[self.k - 1]


def feed(x, v, V, spacing, domain, velocity, t):
    """The reservoir of :class:`.burgers.Reservoir` on arrays: drop particles outside ``domain``;
    fill a gap wider than ``spacing`` at either end with particles ``spacing`` apart, counted from
    the outermost particle, with the exact velocity ``velocity(x, t)`` and volume ``spacing``."""
    a, b = domain
    inside = (x >= a) & (x <= b)
    if not inside.all():
        x, v, V = x[inside], v[inside], V[inside]
    if x.size == 0:
        raise RuntimeError("every particle left the domain")
    lo, hi = x.min(), x.max()
    k_left = int(np.floor((lo - a) / spacing))
    k_right = int(np.floor((b - hi) / spacing))
    if k_left <= 0 and k_right <= 0:
        return x, v, V
    new = np.concatenate((lo - spacing * np.arange(max(k_left, 0), 0, -1), hi + spacing * np.arange(1, max(k_right, 0) + 1)))
    return (np.concatenate((x, new)), np.concatenate((v, velocity(new, t))),
            np.concatenate((V, np.full(new.size, spacing))))


def make_state(x: np.ndarray, v: np.ndarray, V: np.ndarray) -> Particles:
    """Unit-density particles at ``x`` with velocity ``v`` and volume ``V`` (mass ``V``)."""
    return make_particles(x, V, 1.0, v)
