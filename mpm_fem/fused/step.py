"""The fused step of one run (:class:`FusedStep`): :func:`mpm_fem.core.step.explicit_step` compiled.

Per step (:meth:`FusedStep.step`): pass 1 (:mod:`mpm_fem.fused.project`), the grid stage in numpy
with the numpy step's own functions (``divide_by_lumped``, ``solve_consistent``, the boundary
objects: any :class:`~mpm_fem.core.step.Boundary` and both mass kinds), the remedies' passes, pass 2
(:mod:`mpm_fem.fused.passes`). Many steps in one compiled call (:meth:`FusedStep.advance`, the loop
of :mod:`mpm_fem.fused.loop`): between walls or Dirichlet ends with the lumped mass, the same numbers.
The exact stages of the error budget (the gas, USL, the lumped mass, the calculated acceleration;
:meth:`FusedStep._exact_step`): pass 1 for the particles' sums, the grid stage of
:class:`~mpm_fem.exact_stages.ExactGridStage`, then the plain pass 2, or with the exact interpolation

    v_p += dt (a*_p + sum_i S_ip (a_i - a*_i)),  x_p += dt ((v*_p + dt a*_p) + sum_i S_ip (v_i^{n+1} - v*_i^{n+1})),
    L_p = v*_x(x_p^{n+1}, t + dt) + sum_i G_ip (v_i^{n+1} - v*_i^{n+1}),  then the state update,
with the numpy step's operations in its order; the other exact stages, and ``kernel="numpy"``, run the
numpy step (:func:`supported`).
"""

from __future__ import annotations

import numpy as np

from mpm_fem.bases import get
from mpm_fem.bases.contract import Cloud, RowStore
from mpm_fem.core.grid import Grid
from mpm_fem.core.models.euler import IdealGas
from mpm_fem.core.particles import Particles, PositivityError
from mpm_fem.core.reconstruction import OFFSETS, force_quadrature
from mpm_fem.core.shape import Shape, basis_integrals, make_shape
from mpm_fem.core.step import SCHEMES, Dirichlet, GridState, Stages, Walls, at_times, prescribed
from mpm_fem.core.transfer import solve_consistent
from mpm_fem.core.transfers import get as get_transfer
from mpm_fem.core.xpic import boundary_change_rule
from mpm_fem.exact_stages import ExactFields, ExactGridStage, GridData
from mpm_fem.fused.codes import (
    BURGERS,
    FIELDS,
    GAS,
    IEPS,
    IFLIP,
    IGGM1,
    IGM1,
    ILIN,
    IQUAD,
    IXPIC,
    MOMENTUM,
    PRESSURE,
    SCHEME_CODE,
    VISCOUS_STRESS,
)
from mpm_fem.fused.compiler import PASSES
from mpm_fem.fused.extrema import Tally, no_tally
from mpm_fem.fused.loop import _LOOP_CALLS, Clock, Conditions, Geometry, Remedies, Scratch, _advance, _nodal_rows
from mpm_fem.fused.models import Checks, ParticleState
from mpm_fem.fused.passes import _finish, _move, _move_exact, _scatter_pass, _update, _update_exact
from mpm_fem.fused.project import _project
from mpm_fem.fused.remedies import Quadrature, Reset, State, _taylor_force, _volume_reset
from mpm_fem.fused.sums import _divide_by_lumped
from mpm_fem.fused.support import KERNELS, check_kernel, supported  # noqa: F401 (the package's names)

_STATE = ("x", "v", "V", "m", "rho", "e", "p", "C")  # the arrays of the particles a step returns
_PAD = 40  # doubles between advance's particle arrays: 5 cache lines, so that they do not share cache sets
_TABLE_ROWS = 4096  # at most this many times of the tables ahead (FusedStep._tables)
_TABLE_VALUES = 1 << 18  # at most this many exact nodal accelerations in a table (2 MiB)


def _uniform_to_round_off(grid: Grid) -> bool:
    """Whether the grid is uniform (``grid.uniform_spacing``) and its nodes lie within ``1e-9 h`` of
    ``x_0 + i h`` (a ``linspace``): then the uniform-grid arithmetic of every basis
    (the bases' compiled rows, :class:`mpm_fem.bases.contract.Kernels`) agrees with the node
    arithmetic to round-off. A grid uniform only to ``grid.uniform_spacing``'s 1e-6 takes the node
    arithmetic (and bisection to locate the particles, in every basis)."""
    h = grid.uniform_spacing
    if h is None:
        return False
    nodes = grid.nodes
    return bool(np.abs(nodes - (nodes[0] + h * np.arange(nodes.size))).max() <= 1e-9 * h)


class FusedStep:
    """The fused step of one run: ``step(particles, t, dt) -> (particles, GridState)``, as
    :func:`~mpm_fem.core.step.explicit_step` (the same numbers on one thread). After each step
    ``speed`` holds ``max_p (c_p + |v_p|)`` (gas) or ``max_p |v_p|`` (Burgers) of the new particles
    and ``finite`` whether their state is finite, for the time step and the run's checks. With
    ``reuse`` the step writes into two alternating sets of arrays instead of fresh ones (no page
    faults on a new 8 MB array per field and step): the particles a step returns are overwritten
    two steps later, so a run that hands them to an observer reuses only if the observer keeps none
    of them (:func:`mpm_fem.run.solve._keeps_particles`)."""

    def __init__(self, grid: Grid, model, boundary, stages: Stages = Stages(), exact_acceleration=None,
                 threads: int = 1, reuse: bool = False, exact: ExactFields | None = None, sweep: bool = True):
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
        self.sweep = bool(sweep)  # False: the loop keeps pass 2 and the next pass 1 apart (the benchmarks' baseline)
        passes = PASSES[self.threads > 1]
        self.kind = GAS if isinstance(model, IdealGas) else BURGERS
        self.basis = get(stages.basis)  # the registered basis: its kernels are the variants' globals
        self._passes = passes
        self.basis.check_grid(grid)
        self.nodes = np.ascontiguousarray(grid.nodes, dtype=float)
        self.h = np.ascontiguousarray([grid.h, 1.0 / grid.h], dtype=float)  # h_c and 1/h_c: read, not divided
        self.inv_spacing = 1.0 / grid.uniform_spacing if _uniform_to_round_off(grid) else 0.0
        self.consts = np.zeros(IXPIC + 1)  # the model's constants and the remedies' (codes.IGM1 .. IXPIC)
        if self.kind == GAS:
            g = model.gamma
            self.consts[IGM1], self.consts[IGGM1] = g - 1.0, g * (g - 1.0)
            self.consts[ILIN], self.consts[IQUAD] = model.av_linear, model.av_quadratic
        else:
            self.consts[IEPS] = model.eps
        self.consts[IFLIP], self.consts[IXPIC] = float(stages.flip), float(stages.xpic)
        self.transfer = get_transfer(stages.transfer_name)
        self.move_consts = self.consts.copy()  # an affine transfer moves with PIC's velocity: XPIC(1)'s
        if self.transfer.affine:
            self.move_consts[IXPIC] = 1.0
        self.slides = self.kind == BURGERS and getattr(model, "force", "weak") == "slides"
        self._width(self.basis.width)
        self.speed, self.finite = np.nan, True
        # advance's tables: the last call's steady dt, the tables, the dt and the rows ahead they were built with
        self._steady_dt, self._table = None, (np.empty(0), np.empty((0, 0)), np.empty((0, 0)))
        self._table_dt, self._ahead, self._built_at = None, 0, 0
        self.reuse, self._pools, self._turn = reuse, ({}, {}), 0
        self._state = self._out = self._scratch = None  # advance's two sets of particle arrays, its last
        self._cur = 0  # particles, and its scratch arrays
        self._ends = np.ascontiguousarray(grid.boundary_nodes, dtype=np.intp)
        # the stored cells and node indices (pass 1 -> the grid stage and pass 2): 4 bytes, not 8
        self._index = np.int32 if grid.n_nodes <= np.iinfo(np.int32).max else np.intp
        self._h_min = float(grid.h.min())
        self.integrals = (np.ascontiguousarray(basis_integrals(grid, stages.basis), dtype=float)
                          if stages.volume == "grid" else np.empty(0))  # the volume reset: int S_i
        self.volume_width = get(self.basis.domain_twin).width  # the volume reset's domain rows
        self.quadrature = (np.empty((0, 2), np.intp), np.empty((0, 2)), np.empty(0), np.empty(0))
        if stages.reconstruct == "taylor":  # the reconstructed force's points: their nodes, S_i', weights
            points, weights = force_quadrature(grid, stages.basis)
            self.quadrature = (np.ascontiguousarray(points.nodes, dtype=np.intp), np.ascontiguousarray(points.G),
                               np.ascontiguousarray(weights), np.ascontiguousarray(OFFSETS))

    def _width(self, K):
        """Use the passes compiled for K nodes per particle (a particle-domain basis widens its rows
        as a domain spans more cells)."""
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

    def _solve(self, shape, mass, m_i, rhs, name="v_solved", impose=None):
        """The numpy step's nodal solve (``impose``: the boundary it then applies, whose prescribed values a
        coupled mass's system takes: :func:`~mpm_fem.core.step.prescribed`)."""
        if self.stages.mass == "lumped":
            return _divide_by_lumped(rhs, m_i, self._empty(name, m_i.shape))
        fixed = prescribed(self.boundary, self.grid, self.stages.mass, impose) if impose is not None else None
        return solve_consistent(shape, mass, rhs, fixed)

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
        return (ends and self.stages.mass == "lumped" and not self.stages.uses_exact_fields and not self.transfer.affine
                and (self.stages.acceleration == "calculated" or exact)
                and not self.slides and (problem.particle_boundary is None or self._window(problem) is not None))

    def _window(self, problem):
        """``(a, b, spacing)`` of a particle boundary that leaves the particles as they are while
        they lie in [a, b] with no end gap of ``spacing`` (``particle_boundary.quiet(grid)``, as
        :class:`~mpm_fem.problems.burgers.Reservoir` gives), else ``None`` (it may act every step)."""
        quiet = getattr(problem.particle_boundary, "quiet", None)
        return None if quiet is None else quiet(self.grid)

    def advance(self, particles: Particles, t: float, problem, steps: int, max_steps: int, budget: int,
                tally: Tally | None = None):
        """Up to ``budget`` steps from ``t`` in one compiled loop (:func:`~mpm_fem.fused.loop._advance`), each the step
        :meth:`step` takes with the time step :func:`mpm_fem.run.solve.run` takes after its first step
        (from :attr:`speed`): the same numbers bit for bit. Returns ``(particles, t, steps taken,
        dt_min, dt_max)``; zero steps when the next step must go through :meth:`step` (it fails, or
        a stored row changes width). A ``tally`` counts new extrema on the way (:mod:`~mpm_fem.fused.extrema`)."""
        n, chunks = particles.n, max(1, min(self.threads, particles.n))
        spare = (lambda k: k // 16) if problem.particle_boundary is not None else (lambda k: 0)  # a reservoir's inflow
        if self._out is not particles or self._state.shape[2] < n + _PAD:
            # particles from elsewhere: copied into both sets (the mass of the gas, rho, eps, p of Burgers
            # stay there), with room for a reservoir's inflow
            if self._state is None or self._state.shape[2] < n + _PAD:
                self._state = np.empty((2, len(FIELDS), n + spare(n) + _PAD))
            for j, name in enumerate(FIELDS):
                self._state[:, j, :n] = getattr(particles, name)
            self._pools = ({}, {})  # the per-step arrays: refilled if a step falls back to step()
            self._cur = 0
        rows_n = n if self.basis.domain else 0
        volume, taylor = self.stages.volume == "grid", self.stages.reconstruct == "taylor"
        kept = self._scratch
        if (kept is None or kept.cell.size < n or kept.rows.shape[0] < rows_n or kept.rows.shape[1] != self.K
                or kept.flags.shape[0] != chunks or (volume and kept.reset.shape[2] < n)):
            room, rows_room = n + spare(n), rows_n + spare(rows_n)
            self._scratch = kept = Scratch(
                cell=np.empty(room, self._index), rows=np.empty((rows_room, self.K), self._index),
                S=np.empty((rows_room, self.K)), G=np.empty((rows_room, self.K)),
                grid=np.empty((_nodal_rows(self.stages.xpic > 0, volume), self.grid.n_nodes)),
                flags=np.empty((chunks, 3), np.int64), upd=np.empty((chunks, 2), np.int64),
                values=np.zeros((chunks, 2)), speeds=np.empty(chunks), reset=np.empty((1, 3, room if volume else 0)),
                sums=np.empty((5, self.grid.n_cells if taylor else 0)))
        scratch = kept._replace(cell=kept.cell[:n], rows=kept.rows[:rows_n], S=kept.S[:rows_n], G=kept.G[:rows_n])
        loop = self._passes.get(_advance, BASIS=self.basis, MODEL=self.kind, WIDTH=self.K,
                                SCHEME=SCHEME_CODE[self.stages.scheme], XPIC_ON=int(self.stages.xpic > 0),
                                VOLUME_ON=int(volume), TAYLOR_ON=int(taylor), SWEPT=int(self.sweep))
        fixed = problem.dt if problem.dt is not None else 0.0
        viscous = bool(getattr(self.model, "viscous_limit", False))
        window = np.empty(0) if problem.particle_boundary is None else np.array(self._window(problem), dtype=float)
        dirichlet = type(self.boundary) is Dirichlet
        exact = self.stages.acceleration == "exact"
        times, table, accelerations = (self._tables(float(t), float(problem.T), exact, steps) if dirichlet or exact
                                       else (np.empty(0), np.empty((0, 0)), np.empty((0, 0))))
        conditions = Conditions(ends=self._ends, dirichlet=dirichlet, window=window, exact=exact, times=times,
                                table=table, accelerations=accelerations)
        clock = Clock(t=float(t), T=float(problem.T), speed=float(self.speed), fixed_dt=float(fixed),
                      cfl=float(problem.cfl), h_min=self._h_min, refine=float(self.stages.refine),
                      viscous_limit=viscous, steps=steps, max_steps=max_steps, budget=budget)
        remedies = Remedies(int(self.stages.xpic), self.volume_width if volume else 0, self.integrals, *self.quadrature)
        _LOOP_CALLS.append((self.boundary, self.grid, self.exact_acceleration))
        try:
            cur, t, done, speed, dt_min, dt_max = loop(
                Geometry(self.nodes, self.h, self.inv_spacing), conditions, clock, self.consts, chunks, self._state,
                self._cur, scratch, remedies, no_tally() if tally is None else tally)
        finally:
            _LOOP_CALLS.pop()
        if done:
            self._steady_dt = float(dt_max) if dt_min == dt_max and done > 1 else None
            self._cur, self.speed, self.finite = cur, float(speed), True
            self._out = Particles(**{name: self._state[cur, j, :n] for j, name in enumerate(FIELDS)})
            particles = self._out
        return particles, t, done, dt_min, dt_max

    def _tables(self, t: float, T: float, exact: bool, steps: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The tables :meth:`advance` hands the loop: the times ``t, t + dt, t + 2 dt, ...`` it will
        reach if its time step stays the last call's ``dt`` (accumulated one addition at a time, as the
        loop's ``t += dt``: ``np.add.accumulate`` is sequential), up to ``T``; there the Dirichlet data
        (:meth:`~mpm_fem.core.step.Dirichlet.end_values_at`; none between walls) and, with ``exact``,
        the exact nodal acceleration, each one vectorised call of the problem's function (elementwise:
        the floats of one call per time; a test checks). Kept while the next call starts on one of
        its times. How far ahead: ``t`` alone unless the last call took more than one step, all with one
        ``dt``; twice the rows of the last table (from one, at most :data:`_TABLE_ROWS` rows and
        :data:`_TABLE_VALUES` exact accelerations) when that ``dt`` is the one the last table was built
        with, else one row ahead; and never more than twice the steps the run took (``steps``, counted
        from the run's start) since the last table was built, plus one (why: ``docs/performance.md``)."""
        times, table, accelerations = self._table
        row = int(np.searchsorted(times, t))
        if row < times.size and times[row] == t and times.size - row > 1:
            return times[row:], table[row:], accelerations[row:]
        dt, rows = self._steady_dt, _TABLE_ROWS if not exact else max(1, _TABLE_VALUES // self.grid.n_nodes)
        if dt is None or not dt > 0:
            ahead = 0
        else:
            ahead = min(max(1, 2 * self._ahead), rows) if dt == self._table_dt else 1
            ahead = min(ahead, 2 * max(steps - self._built_at, 0) + 1)
        self._table_dt, self._ahead, self._built_at = dt, ahead, steps
        count = int(min(max((T - t) / dt, 0.0), ahead)) if ahead else 0
        times = np.add.accumulate(np.concatenate(([t], np.full(count, dt if count else 0.0))))
        table = (self.boundary.end_values_at(self.grid, times) if type(self.boundary) is Dirichlet
                 else np.empty((0, 0)))
        accelerations = at_times(self.exact_acceleration, self.grid.nodes, times) if exact else np.empty((0, 0))
        self._table = (times, table, accelerations)
        return self._table

    def _grid_volume(self, geometry, stored, x, V, m, rho, e, p, chunks):
        """The grid volume reset (:func:`~mpm_fem.fused.remedies._volume_reset`): ``(V, rho, p)`` of the
        reset state (Burgers: ``rho``, ``p`` as they are); raises :class:`PositivityError` as the model's
        ``with_volume``."""
        reset = self._passes.get(_volume_reset, BASIS=self.basis, MODEL=self.kind)
        n, n_nodes = x.size, self.grid.n_nodes
        V_r, rho_r, p_r = (self._empty(name, n) for name in ("V_reset", "rho_reset", "p_reset"))
        V_i, ratio = self._empty("V_i", n_nodes), self._empty("ratio", n_nodes)
        flags, values = np.empty((chunks, 2), np.int64), np.zeros((chunks, 2))
        while True:
            width = self.K if self.basis.domain else self.volume_width
            reset(geometry, stored, State(x, V, m, rho, e, p),
                  self.integrals, self.consts, chunks, width, Reset(V_i, ratio, V_r, rho_r, p_r), flags, values)
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
        """Pass 1 (:func:`~mpm_fem.fused.project._project`): ``(shape, m_i, P_i, F_i, flags)``, the rows in ``shape`` if
        ``store`` (the particle-domain bases store theirs always), the cells always; raises the numpy step's
        error for a particle outside the grid or without volume."""
        grid, n = self.grid, particles.n
        x, V, m, v, p = particles.x, particles.volume, particles.mass, particles.velocity, particles.pressure
        store = store or self.basis.domain
        n_nodes = grid.n_nodes
        empty = self._empty
        m_i, P_i, F_i = empty("m_i", n_nodes), empty("P_i", n_nodes), empty("F_i", n_nodes)
        flags = np.empty((chunks, 3), np.int64)
        cell = empty("cell", n, self._index)
        while True:
            rows_n = n if store else 0
            rows, S, G = (empty("rows", (rows_n, self.K), self._index), empty("S", (rows_n, self.K)),
                          empty("G", (rows_n, self.K)))
            self.project(Geometry(self.nodes, self.h, self.inv_spacing), Cloud(x, V, m, v, p), gas_force, store,
                         chunks, RowStore(rows, S, G, cell), m_i, P_i, F_i, flags)
            if (flags[:, :2] >= 0).any():
                make_shape(grid, x, V, self.stages.basis)  # raises the numpy step's error
                raise ValueError("a particle lies outside the grid or has no volume")  # not reached
            need = int(flags[:, 2].max(initial=2))
            if not self.basis.domain or need == self.K or n == 0:
                break
            self._width(need)  # a particle domain spans another cell; redo with the wider rows
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
        geometry = Geometry(self.nodes, self.h, self.inv_spacing)
        n_nodes = grid.n_nodes
        self._turn = 1 - self._turn
        empty = self._empty
        affine = self.transfer.kernels if self.transfer.affine else None  # its rows stored: they serve its sums
        shape, m_i, P_i, F_i, flags = self._pass1(particles, gas_force,
                                                  self.stages.mass == "consistent" or affine is not None, chunks)
        rows, S, G, cell = shape.nodes, shape.S, shape.G, shape.cell
        if affine is not None and particles.affine is not None:
            affine.momentum(self.nodes, rows, S, x, m, particles.affine, P_i)
        velocity_at_t = lambda u: self.boundary.velocity(grid, u, t)  # noqa: E731
        v_i = velocity_at_t(self._solve(shape, m, m_i, P_i, impose=velocity_at_t))
        shape_args = (geometry, x, RowStore(rows, S, G, cell))
        if grid_volume:  # the volume reset (mpm_fem.core.volume), then the force of the reset state
            V, rho, p = self._grid_volume(geometry, RowStore(rows, S, G, cell), x, V, m, rho, e, p, chunks)
            if gas and scheme != "usf" and not exact and not taylor:
                self._passes.get(_scatter_pass, BASIS=self.basis, WIDTH=self.K, WEIGHT=PRESSURE)(
                    *shape_args, v_i, V, p, 0.0, chunks, F_i)

        V_new, m_new = empty("V", n), (empty("m", n) if not gas else m)
        rho_new, e_new, p_new = (empty("rho", n), empty("e", n), empty("p", n)) if gas else (rho, e, p)
        values = np.zeros((chunks, 2))
        old = ParticleState(x, v, V, m, rho, e, p)
        if scheme == "usf":
            upd = np.empty((chunks, 2), np.int64)
            force = not exact and not self.slides and not taylor
            self.update(geometry, shape_args[2], v_i, old, dt, self.consts, force, chunks,
                        ParticleState(x, v, V_new, m_new, rho_new, e_new, p_new), F_i, Checks(upd, values, np.empty(0)))
            if (upd >= 0).any():
                self._positivity(upd, values, x)
        elif not gas and not exact and not self.slides and not taylor:
            self.viscous_force(*shape_args, v_i, V, V, self.consts[IEPS], chunks, F_i)
        if taylor and not exact and not self.slides:  # the reconstructed force of the (updated) stress
            self._passes.get(_taylor_force, BASIS=self.basis, MODEL=self.kind, WIDTH=self.K)(
                geometry, x, RowStore(rows, S, G, cell), p_new if scheme == "usf" else p, v_i,
                self.consts[IEPS], Quadrature(*self.quadrature), chunks, empty("sums", (5, grid.n_cells)), F_i)
        if exact:
            if self.exact_acceleration is None:
                raise ValueError("this problem has no exact acceleration to use")
            a_i = self.exact_acceleration(grid.nodes, t)
        elif self.slides:
            a_i = self.model.grid_acceleration(grid, cell, v_i)
        else:
            a_i = self._solve(shape, m, m_i, F_i, "a_solved",
                              impose=lambda u: self.boundary.acceleration(grid, u, v_i, t, dt))
        a_i = self.boundary.acceleration(grid, a_i, v_i, t, dt)
        v_n = v_i + dt * a_i

        x_new, vel_new = empty("x", n), empty("v", n)
        speed = np.empty(chunks)
        usl, musl = scheme == "usl", scheme == "musl"
        new = ParticleState(x_new, vel_new, V_new, m_new, rho_new, e_new, p_new)
        if usl:  # the move writes the new state
            moving, moved = old, new
        elif scheme == "usf":  # updated already: the move reads and keeps the updated state
            moving = ParticleState(x, v, V_new, m, rho_new, e_new, p_new)
            moved = new
        else:  # MUSL: the state updated after the re-projection
            moving, moved = old, ParticleState(x_new, vel_new, V, m, rho, e, p)
        P_musl = empty("P_musl", n_nodes)
        target = self._xpic_target(shape, shape_args, m, m_i, v_i, a_i, t, dt, chunks) if self.stages.xpic else a_i
        checks = Checks(flags, values, speed)
        self.move(geometry, shape_args[2], v_n if affine is not None else target, v_n, moving, moved, dt,
                  self.move_consts, SCHEME_CODE[scheme], chunks, P_musl, checks)
        C_new = None
        if affine is not None:  # G2P's coefficient from v_i^{n+1}; MUSL re-projects with it
            C_new = empty("C", n)
            affine.coefficient(rows, G, v_n, C_new)
        if musl:
            if affine is not None:
                affine.momentum(self.nodes, rows, S, x, m, C_new, P_musl)
            velocity_at_end = lambda u: self.boundary.velocity(grid, u, t + dt)  # noqa: E731
            v_n = velocity_at_end(self._solve(shape, m, m_i, P_musl, "v_musl", impose=velocity_at_end))
            self.finish(geometry, shape_args[2], v_n, old, new, dt, self.consts, chunks, checks)
        if usl or musl:
            if (flags[:, :2] >= 0).any():
                self._positivity(flags[:, :2], values, x_new)
        new_particles = self._new_particles(x_new, vel_new, V_new, m_new, rho_new, e_new, p_new, flags, speed)
        if C_new is not None:
            new_particles = new_particles.replace(affine=C_new)
        return new_particles, GridState(m_i, v_i, a_i, v_n)

    def _new_particles(self, x, v, V, m, rho, e, p, flags, speed) -> Particles:
        """The step's particles; :attr:`speed` and :attr:`finite` from pass 2's tallies."""
        self.speed = float(speed.max())
        self.finite = bool((flags[:, 2] < 0).all())
        return Particles(x=x, volume=V, mass=m, velocity=v, density=rho, energy=e, pressure=p)

    def _exact_step(self, particles: Particles, t: float, dt: float) -> tuple[Particles, GridState]:
        """The step with exact stages (:func:`mpm_fem.core.step.explicit_step`; the gas, USL): pass 1 for
        the particles' ``m_i``, ``P_i`` and (MPM projection) ``F_i``; the grid stage of the numpy step
        (:class:`~mpm_fem.exact_stages.stage.ExactGridStage`); pass 2 as the plain step's with the MPM
        interpolation, else :func:`~mpm_fem.fused.passes._move_exact` with the exact fields at ``x_p^n``,
        then ``L_p = v*_x(x_p^{n+1}, t + dt) + sum_i G_ip (v_i^{n+1} - v*_i^{n+1})`` and the state update
        (:func:`~mpm_fem.fused.passes._update_exact`)."""
        n, chunks = particles.n, max(1, min(self.threads, particles.n))
        x, V, m, v = particles.x, particles.volume, particles.mass, particles.velocity
        rho, e, p = particles.density, particles.energy, particles.pressure
        self._turn = 1 - self._turn
        empty = self._empty
        interpolate = self.stages.interpolation == "exact"
        shape, m_i, P_i, F_i, flags = self._pass1(particles, self.stages.projection != "exact", False, chunks)
        stage = ExactGridStage(self.grid, self.boundary, self.stages, self.exact, GridData(shape, m, m_i, P_i), t, dt)
        a_i = stage.acceleration(F_i)
        v_n = stage.v_i + dt * a_i
        x_new, vel_new = empty("x", n), empty("v", n)
        V_new, rho_new, e_new, p_new = (empty(name, n) for name in ("V", "rho", "e", "p"))
        values, speed = np.zeros((chunks, 2)), np.empty(chunks)
        geometry = Geometry(self.nodes, self.h, self.inv_spacing)
        store = RowStore(shape.nodes, shape.S, shape.G, shape.cell)
        old = ParticleState(x, v, V, m, rho, e, p)
        new = ParticleState(x_new, vel_new, V_new, m, rho_new, e_new, p_new)
        checks = Checks(flags, values, speed)
        if interpolate:
            p_v, _, p_a = self.exact.reference(x, t)
            star_new = stage.star_new
            L = empty("L", n)
            self._passes.get(_move_exact, BASIS=self.basis, WIDTH=self.K)(
                geometry, store, a_i - stage.star_a, v_n - star_new, p_v, p_a, old, new, dt, chunks, L)
            L = self.exact.velocity_gradient(x_new, t + dt) + L
            self._passes.get(_update_exact, MODEL=self.kind)(self.h, shape.cell, L, old, new, dt, self.consts, chunks,
                                                             checks)
        else:
            self.move(geometry, store, a_i, v_n, old, new, dt, self.consts, SCHEME_CODE["usl"], chunks,
                      empty("P_musl", self.grid.n_nodes), checks)
        if (flags[:, :2] >= 0).any():
            self._positivity(flags[:, :2], values, x_new)
        return self._new_particles(x_new, vel_new, V_new, m, rho_new, e_new, p_new, flags, speed), \
            GridState(m_i, stage.v_i, a_i, v_n)
