"""The local defect of the particle update, accumulated over a run.

Step ``n`` takes the particles from ``t^n`` to ``t^{n+1} = t^n + dt`` (:mod:`mpm_fem.core.step`). With the
grid functions ``S_ip``, ``G_ip`` at the positions ``x_p^n``, the particle update (FLIP) takes three
quantities from the grid:

    acceleration   A_p = sum_i S_ip a_i           v_p <- v_p + dt A_p
    motion         W_p = sum_i S_ip v_i^{n+1}     x_p <- x_p + dt W_p
    rate           L_p = sum_i G_ip v_i^{n+1}     rho_p <- rho_p (1 - dt L_p)   (USL, MUSL; USF: v_i^n)

(with the exact interpolation stage ``f_p = f*(x_p) + sum_i S_ip (f_i - f*_i)``,
:mod:`mpm_fem.exact_stages.stage`). Their exact values at that step are the values the update takes when
every stage but time is exact, from the reference fields ``(v*, v*_x, a*)``
(:class:`~mpm_fem.exact_stages.fields.ExactFields`):

    A*_p = a*(x_p^n, t^n),   W*_p = v*(x_p^n, t^n) + dt a*(x_p^n, t^n),   L*_p = v*_x(x_p^n, t^{n+1})  (USF: t^n),

and the defects are ``d_A = A - A*``, ``d_W = W - W*``, ``d_L = L - L*``. On the grid the defects of the
nodal acceleration ``a_i - a*_i`` and velocity ``v_i^{n+1} - (v*_i + dt a*_i)`` (the exact nodal values
with the grid's boundary rule, as :class:`~mpm_fem.exact_stages.ExactGridStage` makes them).

Accumulated along each particle's path with the update's own propagation: the particle error
``e_p = q_p - q*(x_p, t)`` of the velocity or the density obeys, to first order in ``dt``,

    velocity   e^{n+1} = e^n + dt (d_A - v*_x d_W)
    density    e^{n+1} = (1 - dt L_p) e^n - dt (rho_p d_L + rho*_x d_W)

(the particle moves with ``W``, not ``W*``, through a field of slope ``q*_x``; the density update
multiplies the error it carries by ``1 - dt L_p``). The components, each accumulated with the
propagation of the quantity it enters, add up to the accumulated defect: acceleration ``dt d_A``
(velocity), velocity ``-dt q*_x d_W`` (the measured quantity), rate ``-dt rho_p d_L`` (density; for
Burgers the volume's drift in density units). The predicted error of the density is rate + velocity,
of the velocity acceleration + velocity. Left out: the initial error (zero: the problems start on the
exact solution), the time error on the exact fields, second-order terms. A particle fed in starts at zero.

:class:`DefectObserver` is an observer of :func:`mpm_fem.run.solve.run`, which routes a run it
instruments to the numpy step (``needs_numpy_step``); it changes no number of the run. The step's
``dt`` reaches an observer as the difference of successive times, so each step is accounted when the
next one (or :meth:`DefectObserver.finish`) arrives.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, NamedTuple

import numpy as np

from mpm_fem.core.grid import Grid
from mpm_fem.core.particles import Particles
from mpm_fem.core.shape import make_shape
from mpm_fem.core.step import Boundary, GridState, Stages
from mpm_fem.exact_stages.fields import ExactFields

QUANTITIES = ("velocity", "density")
COMPONENTS = ("acceleration", "velocity", "rate")
#: the components the predicted error of each measured quantity sums
PREDICTED = {"velocity": ("acceleration", "velocity"), "density": ("rate", "velocity")}


class StepDefect(NamedTuple):
    """The defects of one step (module docstring): per particle (n_p,) ``d_A``, ``d_W``, ``d_L``, the
    motion ``W`` and rate ``L`` the update took; per node (n_nodes,) ``d_a`` and ``d_v`` (the nodal
    acceleration and new velocity)."""

    d_A: np.ndarray
    d_W: np.ndarray
    d_L: np.ndarray
    W: np.ndarray
    L: np.ndarray
    d_a: np.ndarray
    d_v: np.ndarray


def step_defect(grid: Grid, boundary: Boundary, fields: ExactFields, stages: Stages, old: Particles,
                state: GridState, t: float, dt: float) -> StepDefect:
    """The defects of the step from ``t`` to ``t + dt`` that started from ``old``, whose grid held ``state``.

    Parameters
    ----------
    grid, boundary, stages
        The run's grid, grid boundary rule and stage switches.
    fields
        The problem's exact fields (``reference(x, t) -> (v*, v*_x, a*)``).
    old : Particles
        The particles at ``t`` (n_p,).
    state : GridState
        ``a_i``, ``v_i^n``, ``v_i^{n+1}`` of the step (n_nodes,).

    Returns
    -------
    StepDefect
        Per particle (n_p,) and per node (n_nodes,), in the units of the quantity (1/s for ``d_L``).
    """
    shape = make_shape(grid, old.x, old.volume, stages.basis)
    p_v, p_vx, p_a = fields.reference(old.x, t)
    ref_v, _, ref_a = fields.reference(grid.nodes, t)
    star_v = boundary.velocity(grid, ref_v, t)
    star_a = boundary.acceleration(grid, ref_a, star_v, t, dt)
    star_new = star_v + dt * star_a
    usf = stages.scheme == "usf"
    nodal, star = (state.velocity, star_v) if usf else (state.new_velocity, star_new)
    exact_vx = p_vx if usf else fields.velocity_gradient(old.x, t + dt)
    if stages.interpolation == "exact":
        A = p_a + shape.gather(state.acceleration - star_a)
        W = p_v + dt * p_a + shape.gather(state.new_velocity - star_new)
        L = exact_vx + shape.gather_gradient(nodal - star)
    else:
        A, W, L = shape.gather(state.acceleration), shape.gather(state.new_velocity), shape.gather_gradient(nodal)
    return StepDefect(A - p_a, W - (p_v + dt * p_a), L - exact_vx, W, L, state.acceleration - star_a,
                      state.new_velocity - star_new)


def propagate(carried: dict[str, np.ndarray], d: StepDefect, slope: np.ndarray, density: np.ndarray,
              quantity: str, dt: float) -> dict[str, np.ndarray]:
    """The accumulated components after one more step (module docstring), all (n_p,): ``carried``
    ``{component: (n_p,)}`` before it, ``slope`` ``q*_x`` of the measured ``quantity`` at the
    particles, ``density`` the particles' ``rho_p`` at the start of the step."""
    keep = 1.0 - dt * d.L  # the density update's factor on the error it carries
    motion_keep = keep if quantity == "density" else 1.0
    return {"acceleration": carried["acceleration"] + dt * d.d_A,
            "velocity": motion_keep * carried["velocity"] - dt * slope * d.d_W,
            "rate": keep * carried["rate"] - dt * density * d.d_L}


def check_instrumentable(stages: Stages, model=None) -> None:
    """Refuse (``ValueError``) a run whose particle update is not the one the accumulation follows: FLIP's
    velocity update, the carried volume and the slides' density update with the point rate."""
    if stages.transfer_name != "flip" or stages.flip != 1:
        raise ValueError(f"the defect accumulates FLIP's velocity update v_p += dt sum_i S_ip a_i; the transfer "
                         f"{stages.transfer_name!r} with setting {stages.transfer_setting!r} updates otherwise")
    if stages.volume != "carried" or stages.volume_rate != "point" or stages.reconstruct != "none":
        raise ValueError("the defect follows the carried volume with the point rate L_p and no reconstruction")
    if model is not None and getattr(model, "density_update", "linear") != "linear":
        raise ValueError(f"the defect follows the density update rho (1 - dt L); the model's is "
                         f"{model.density_update!r}")


@dataclass(eq=False)
class DefectObserver:
    """Accumulates the defects of every step of a run (module docstring), called by
    :func:`mpm_fem.run.solve.run` after each step; after the run, :meth:`finish` with the run's final
    time, then :attr:`carried` holds the components ``{component: (n_p,)}`` on the final particles.

    ``quantity`` is the measured one (``"velocity"`` or ``"density"``) and ``slope(x, t)`` its exact
    ``q*_x`` at ``x``. The run must step with the numpy step (``needs_numpy_step``: the time loop routes
    it there) and update the particles as :func:`check_instrumentable` asks. It keeps the particles it is
    handed until the next call."""

    needs_numpy_step = True  # a class attribute, not a field: what solve.run asks of an observer
    keeps_particles = True

    grid: Grid
    boundary: Boundary
    fields: ExactFields
    stages: Stages
    quantity: str
    slope: Callable[[np.ndarray, float], np.ndarray]
    carried: dict = field(default_factory=dict)
    steps: int = 0
    #: sums over the steps of the per-step L1 norms of the defects: nodal ``a_i``, ``v_i^{n+1}`` (weights
    #: ``int N_i dx``) and ``d_L`` (weights ``V_p``)
    defect_sums: dict = field(default_factory=lambda: {"a": 0.0, "v": 0.0, "L": 0.0})
    _pending: tuple | None = field(default=None, repr=False)

    def __post_init__(self):
        if self.quantity not in QUANTITIES:
            raise ValueError(f"unknown measured quantity {self.quantity!r}; choose one of {', '.join(QUANTITIES)}")
        check_instrumentable(self.stages)

    def __call__(self, step: int, t: float, old: Particles, new: Particles, state: GridState) -> None:
        if self._pending is not None:
            self._account(t)
        if not self.carried:
            self.carried = {c: np.zeros(old.n) for c in COMPONENTS}
        self._pending = (t, old, new, state)

    def finish(self, t_end: float) -> dict[str, np.ndarray]:
        """Account the last step (it ended at ``t_end``, the run's ``Result.t``); returns :attr:`carried`."""
        if self._pending is not None:
            self._account(t_end)
        return self.carried

    def _account(self, t_next: float) -> None:
        t, old, new, state = self._pending
        self._pending = None
        dt = t_next - t  # the step's dt to within half an ulp of t
        d = step_defect(self.grid, self.boundary, self.fields, self.stages, old, state, t, dt)
        carried = propagate(self.carried, d, self.slope(old.x, t), old.density, self.quantity, dt)
        self.carried = _follow(carried, old, new, d, dt, self.grid)
        self.steps += 1
        w = self.grid.lumped_mass
        self.defect_sums["a"] += float(np.sum(w * np.abs(d.d_a)))
        self.defect_sums["v"] += float(np.sum(w * np.abs(d.d_v)))
        self.defect_sums["L"] += float(np.sum(old.volume * np.abs(d.d_L)))

    def mean_defects(self) -> dict[str, float]:
        """The per-step L1 norms of the defects, averaged over the steps (:attr:`defect_sums`)."""
        return {k: v / max(self.steps, 1) for k, v in self.defect_sums.items()}

    def predicted(self) -> np.ndarray:
        """The accumulated defect of the measured quantity on the final particles (n_p,)."""
        return sum(self.carried[c] for c in PREDICTED[self.quantity])


def _follow(carried: dict, old: Particles, new: Particles, d: StepDefect, dt: float, grid: Grid) -> dict:
    """``carried`` (on ``old``'s particles) on ``new``'s: a particle boundary (Burgers' reservoir) keeps the
    particles inside the domain in their order and appends the ones it feeds in, which start at zero."""
    a, b = grid.domain
    moved = old.x + dt * d.W
    inside = (moved >= a) & (moved <= b)
    k = int(np.count_nonzero(inside))
    if k == old.n == new.n:
        return carried
    if k > new.n or not np.allclose(new.x[:k], moved[inside], rtol=0, atol=1e-9 * (b - a)):
        raise RuntimeError("the particle boundary did not keep the particles inside in their order: the defect "
                           "cannot follow them")
    return {c: np.concatenate((v[inside], np.zeros(new.n - k))) for c, v in carried.items()}
