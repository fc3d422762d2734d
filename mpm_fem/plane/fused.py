"""The compiled 2D step: :func:`mpm_fem.plane.step.step_with_grid` with the lumped mass, in numba.

:class:`PlaneFused` holds one grid's compiled passes (:mod:`mpm_fem.plane.kernels`) for one basis
and its buffers; :meth:`PlaneFused.step_with_grid` takes the numpy step's arguments and returns
what it returns, equal to round-off (the node sums are added in another order). It serves USL
with the MPM stages and the lumped mass, the PIC/FLIP blend, the body force and the neo-Hookean
stress (:func:`served` says whether a run's stages and basis are served); the consistent and
exact mass, the exact projection, interpolation and acceleration, and MUSL stay on the numpy step.
Every basis of the registry with compiled kernels is served (point mass, GIMP, the B-splines):
its 2D row is the tensor product of its 1D ``Kernels.row`` per axis, no second copy of its shape
functions.

The body force ``b(X_p, t)`` is the problem's numpy callable, evaluated once per step at the
reference positions (vectorised), or a compiled one (:mod:`mpm_fem.plane.forces`, which writes the
array itself); the passes read the array. ``threads`` > 1 runs the parallel
variants with one chunk of particles per thread (:mod:`mpm_fem.plane.kernels`: per-chunk node
buffers); the result depends on the number of threads only. A particle with ``J <= 0`` raises
:class:`~mpm_fem.plane.model.InversionError` naming the first such particle, as the numpy step;
a position outside a non-periodic axis raises :class:`~mpm_fem.bases.shape.OutsideGridError`.

Variants: a pass is its code with the globals ``ROW`` (the basis's ``Kernels.row``) and ``K`` (its
width) replaced by constants, compiled serial or parallel, named by the basis and a digest of the
sources they compile (the passes and the bases), as :mod:`mpm_fem.fused.compiler` does, so that
numba's on-disk caches stay apart.
"""

from __future__ import annotations

import hashlib
import inspect
import types
from pathlib import Path

import numba
import numpy as np
from numba import njit

import mpm_fem.bases as bases
from mpm_fem.bases import get
from mpm_fem.bases.contract import Basis
from mpm_fem.bases.shape import OutsideGridError
from mpm_fem.core.step import Stages
from mpm_fem.fused.step import _uniform_to_round_off
from mpm_fem.plane.grid import PlaneGrid
from mpm_fem.plane.kernels import IBAD, IDT, IFLIP, ILAM, IMU, INEED, IOUT, NSUM, Cloud, Line, _move, _project, _solve
from mpm_fem.plane.model import InversionError
from mpm_fem.plane.state import PlaneParticles
from mpm_fem.plane.step import BodyForce, PlaneGridState, check_stages

#: the stage switches the compiled step serves, with the value they must have
SERVED = {"scheme": "usl", "mass": "lumped", "projection": "mpm", "interpolation": "mpm",
          "acceleration": "calculated"}
SOURCES = [Path(inspect.getsourcefile(_project))] + sorted(Path(inspect.getsourcefile(bases)).parent.glob("*.py"))
DIGEST = hashlib.sha1(b"".join(path.read_bytes() for path in SOURCES)).hexdigest()[:8]
_VARIANTS: dict = {}  # (pass, basis name, parallel) -> compiled variant, made on first use


def served(basis: str | Basis, stages: Stages = Stages()) -> bool:
    """Whether the compiled step takes ``basis`` (a registered tensor basis with compiled kernels) with
    ``stages`` (the switches of :data:`SERVED` at their values)."""
    b = get(basis)
    stages_served = all(getattr(stages, k) == v for k, v in SERVED.items())
    return b.kernels is not None and getattr(b, "tensor", False) and stages_served


def variant(fn, basis: Basis | None, parallel: bool):
    """``fn`` of :mod:`mpm_fem.plane.kernels` compiled with ``ROW``, ``K`` of ``basis`` (None: a pass
    that reads neither), serial or parallel; made once and kept."""
    key = (fn.__name__, None if basis is None else basis.name, parallel)
    if key not in _VARIANTS:
        replaced = {} if basis is None else dict(ROW=basis.kernels.row, K=int(basis.width))
        name = f"{fn.__name__}_{'any' if basis is None else basis.name}{'_parallel' if parallel else ''}_{DIGEST}"
        code = types.FunctionType(fn.__code__, dict(fn.__globals__, **replaced), name, fn.__defaults__)
        code.__qualname__ = name
        _VARIANTS[key] = njit(cache=True, parallel=parallel)(code)
    return _VARIANTS[key]


def _line(axis) -> Line:
    line = axis.line
    inv = 1.0 / line.uniform_spacing if _uniform_to_round_off(line) else 0.0
    return Line(np.ascontiguousarray(line.nodes, dtype=float), np.ascontiguousarray([line.h, 1.0 / line.h]),
                float(inv), np.ascontiguousarray(axis.wrap, dtype=np.intp), axis.lo, axis.length, axis.periodic)


def _cloud(p: PlaneParticles) -> Cloud:
    c = np.ascontiguousarray
    return Cloud(c(p.x, dtype=float), c(p.v, dtype=float), c(p.F, dtype=float), c(p.volume, dtype=float),
                 c(p.volume0, dtype=float), c(p.mass, dtype=float), c(p.lengths, dtype=float))


class PlaneFused:
    """The compiled step on ``grid`` with the 1D basis ``basis`` (module docstring), on ``threads``
    threads; the node buffers are allocated once and reused by every step. With ``reuse`` the
    particles and the grid state a step returns live in two sets of arrays the object holds,
    written in turn: a step's result is overwritten two steps later (a time loop that keeps only
    the last state; no page of new arrays is touched per step); without, every step returns new arrays."""

    def __init__(self, grid: PlaneGrid, basis: str | Basis, threads: int = 1, reuse: bool = False):
        self.basis = get(basis)
        if self.basis.kernels is None:
            raise ValueError(f"the basis {self.basis.name!r} has no compiled kernels; run it on the numpy step")
        if not getattr(self.basis, "tensor", False):
            raise ValueError(f"the basis {self.basis.name!r} has no 2D (tensor-product) form")
        if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or threads < 1:
            raise ValueError(f"threads must be an integer >= 1, got {threads!r}")
        for axis in grid.axes:
            self.basis.check_grid(axis.line)
        self.grid, self.threads = grid, int(threads)
        self.axes = tuple(_line(a) for a in grid.axes)
        parallel = self.threads > 1
        self._project = variant(_project, self.basis, parallel)
        self._move = variant(_move, self.basis, parallel)
        self._solve = variant(_solve, None, parallel)
        n = grid.n_nodes
        self.buf = np.zeros((self.threads, n, NSUM))
        self.flags = np.full((self.threads, 3), -1, dtype=np.int64)
        self.reuse = bool(reuse)
        self._sets, self._turn = [None, None], 0

    def _outputs(self, old: Cloud):
        """The arrays a step writes: the particles' ``x, v, F, volume`` and the body force, nodal
        ``mass, velocity, nodal`` (new ones, or the next of the two sets that are not ``old``'s)."""
        n, n_nodes = old.x.shape[0], self.grid.n_nodes
        fresh = lambda: (np.empty((n, 2)), np.empty((n, 2)), np.empty((n, 2, 2)), np.empty(n),  # noqa: E731
                         np.empty((n, 2)), np.empty(n_nodes), np.empty((n_nodes, 2)), np.empty((n_nodes, 4)))
        if not self.reuse:
            return fresh()
        k = self._turn
        if self._sets[k] is not None and self._sets[k][0] is old.x:  # stepping an older state: take the other
            k = 1 - k
        if self._sets[k] is None or self._sets[k][0].shape[0] != n:
            self._sets[k] = fresh()
        self._turn = 1 - k
        return self._sets[k]

    def step_with_grid(self, state: PlaneParticles, material, dt: float, t: float, body_force: BodyForce | None,
                       stages: Stages = Stages()) -> tuple[PlaneParticles, PlaneGridState]:
        """:func:`mpm_fem.plane.step.step_with_grid` (its arguments but ``grid``, ``basis`` and ``exact``:
        the compiled step takes no exact stage); raises ``ValueError`` for stages it does not serve."""
        check_stages(stages)
        for name, value in SERVED.items():
            if getattr(stages, name) != value:
                raise ValueError(f"the compiled 2D step runs with {name}={value!r}, got {getattr(stages, name)!r}; "
                                 "use the numpy step (compiled=False)")
        old = _cloud(state)
        x, v, F, volume, b, mass, velocity, nodal = self._outputs(old)
        if body_force is None:
            b[:] = 0.0
        elif hasattr(body_force, "into"):  # a compiled body force (mpm_fem.plane.forces) writes b itself
            body_force.into(state.X, t, b)
        else:
            b[:] = np.asarray(body_force(state.X[:, 0], state.X[:, 1], t), dtype=float).T
        consts = np.zeros(4)
        consts[IMU], consts[ILAM], consts[IDT], consts[IFLIP] = material.mu, material.lam, dt, stages.flip
        ax, ay = self.axes
        n_y = self.grid.shape[1]
        chunks = self.threads
        if chunks > 1:
            numba.set_num_threads(chunks)
        flags = self.flags
        flags[:] = -1
        self._project(ax, ay, n_y, old, b, consts, chunks, self.buf, flags)
        outside = flags[:, IOUT][flags[:, IOUT] >= 0]
        if outside.size:
            p = int(outside.min())
            raise OutsideGridError(f"particle {p} at ({state.x[p, 0]!r}, {state.x[p, 1]!r}) lies outside the grid")
        need = int(flags[:, INEED].max())
        if need > self.basis.width:
            self.buf[:] = 0.0
            raise ValueError(f"a {self.basis.name} row needs {need} nodes per axis, more than the compiled "
                             f"{self.basis.width}: a particle domain longer than a cell; use the numpy step")
        self._solve(self.buf, dt, mass, velocity, nodal)
        new = Cloud(x, v, F, volume, old.volume0, old.mass, old.lengths)
        self._move(ax, ay, n_y, old, new, nodal, consts, chunks, flags)
        bad = flags[:, IBAD][flags[:, IBAD] >= 0]
        if bad.size:
            p = int(bad.min())
            F = new.F[p]
            raise InversionError(p, float(F[0, 0] * F[1, 1] - F[0, 1] * F[1, 0]), new.x[p])
        moved = state.replace(x=new.x, v=new.v, F=new.F, volume=new.volume)
        return moved, PlaneGridState(mass, velocity, nodal[:, :2], nodal[:, 2:])

    def step(self, state, material, dt, t, body_force, stages=Stages()) -> PlaneParticles:
        """:meth:`step_with_grid`'s particles."""
        return self.step_with_grid(state, material, dt, t, body_force, stages)[0]
