"""One explicit MPM step (slides, "Forward Euler time integration").

    v_i^{n+1} = v_i^n + dt a_i
    v_p^{n+1} = v_p^n + dt sum_i S_ip a_i
    x_p^{n+1} = x_p^n + dt sum_i S_ip v_i^{n+1}            (semi-implicit: the new grid velocity)

with ``v_i^n = P_i / m_i`` and ``a_i = F_i / m_i`` from the projections of :mod:`mpm_fem.core.transfer`.
The particle state (density, energy, pressure) is updated from the velocity gradient

    USL (update stress last, the slides' order):  (dv/dx)_p = sum_i G_ip v_i^{n+1}, after the move
    USF (update stress first):                    (dv/dx)_p = sum_i G_ip v_i^n, before the force
    MUSL (modified USL): as USL, with v_i^{n+1} re-projected from the updated particle velocities.

Each stage of the step has a switch (:class:`Stages`); the exact forms used by the error budget
are supplied by the caller (``exact_acceleration``, and for the projection, mass and interpolation
switches an :class:`ExactStages`, which :class:`mpm_fem.exact_stages.FieldStages` implements on a
problem's exact fields; their equations are in :mod:`mpm_fem.exact_stages.stage`). This module
imports no package above the core: the exact stages reach the step through that protocol. The
default stages run the plain MPM step below, untouched.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Protocol

import numpy as np

from mpm_fem.bases import get, names
from mpm_fem.core.grid import Grid
from mpm_fem.core.particles import Particles
from mpm_fem.core.reconstruction import RECONSTRUCTIONS, reconstructed_force
from mpm_fem.core.shape import Shape, make_shape
from mpm_fem.core.transfer import (
    COUPLED_KINDS,
    FMPM_KINDS,
    MASS_KINDS,
    grid_values,
    nodal_internal_force,
    nodal_mass,
    nodal_momentum,
)
from mpm_fem.core.transfers import GridVelocities
from mpm_fem.core.transfers import get as get_transfer
from mpm_fem.core.volume import VOLUME_RATES, VOLUMES, domain_rate, grid_volume_factor
from mpm_fem.core.xpic import boundary_change_rule, check_order

SCHEMES = ("usl", "usf", "musl")
ACCELERATIONS = ("calculated", "exact")
PROJECTIONS = ("mpm", "exact")
INTERPOLATIONS = ("mpm", "exact")
STAGE_MASS = MASS_KINDS + ("exact",)


@dataclass(frozen=True)
class StageSwitches:
    """The stage switches of :class:`Stages` that every run's settings carry (all but the
    acceleration, which only a problem with an exact one offers)."""

    basis: str = "mpm"
    mass: str = "lumped"
    scheme: str = "usl"
    projection: str = "mpm"
    interpolation: str = "mpm"
    refine: int = 1
    flip: float = 1.0
    reconstruct: str = "none"
    volume: str = "carried"
    xpic: int = 0
    transfer: str = "flip"


@dataclass(frozen=True)
class Stages(StageSwitches):
    """Which form each stage of the step takes.

    ``basis``: ``"mpm"`` (point mass), ``"gimp"`` or ``"bspline"``; ``mass``: ``"lumped"``,
    ``"consistent"`` (particle mass matrix), ``"fmpm1"`` .. ``"fmpm4"`` (FMPM(k), the k-term series
    of its inverse: :mod:`mpm_fem.masses.fmpm`) or ``"exact"`` (FE + lumping error removed);
    ``acceleration``: ``"calculated"`` (``F_i/m_i``) or ``"exact"`` (the problem's exact nodal
    acceleration); ``scheme``: ``"usl"``, ``"usf"`` or ``"musl"``; ``projection`` and
    ``interpolation``: ``"mpm"`` or ``"exact"``; ``refine``: the time step is ``dt / refine``.
    The exact forms are those of :mod:`mpm_fem.exact_stages.stage`. The remedies (module docstring):
    ``flip`` in [0, 1] (1: FLIP, 0: PIC), ``xpic`` the order ``m >= 1`` of the XPIC update
    (:mod:`mpm_fem.core.xpic`; 0: off, else in place of the blend), ``reconstruct`` ``"none"`` or
    ``"taylor"``, ``volume`` ``"carried"`` or ``"grid"``, and the basis ``"bspline_gimp"``.
    ``volume_rate``: the rate the model's volume (and density) update takes, ``"point"`` (``L_p``,
    the slides') or ``"domain"`` (``dv_h/dx`` integrated over the particle domain,
    :func:`mpm_fem.core.volume.domain_rate`; a model with ``takes_volume_rate``, the MPM stages, and
    the numpy step only: :func:`numpy_only`). Not a run setting (:class:`StageSwitches`): the drift
    study sets it.
    """

    acceleration: str = "calculated"
    volume_rate: str = "point"

    def __post_init__(self):
        get_transfer(self.transfer)
        if self.transfer == "xpic" and not self.xpic:
            raise ValueError("the xpic transfer needs its order: Stages(xpic=m) with m >= 1")
        if self.transfer == "apic" and (self.flip != 1 or self.xpic != 0):
            raise ValueError(f"APIC replaces the PIC/FLIP blend and XPIC: use it with flip 1 and xpic 0, "
                             f"got flip {self.flip!r}, xpic {self.xpic!r}")
        if self.transfer != "flip" and self.uses_exact_fields:
            raise ValueError(f"the transfer {self.transfer!r} runs with the MPM stages only")
        for name, allowed in (("basis", names()), ("mass", STAGE_MASS), ("acceleration", ACCELERATIONS),
                              ("scheme", SCHEMES), ("projection", PROJECTIONS), ("interpolation", INTERPOLATIONS),
                              ("reconstruct", RECONSTRUCTIONS), ("volume", VOLUMES), ("volume_rate", VOLUME_RATES)):
            value = getattr(self, name)
            if value not in allowed:
                raise ValueError(f"unknown {name} {value!r}; choose one of {', '.join(allowed)}")
        if isinstance(self.refine, bool) or not isinstance(self.refine, (int, np.integer)) or self.refine < 1:
            raise ValueError(f"the time refinement must be an integer >= 1, got {self.refine!r}")
        if self.mass in FMPM_KINDS and self.projection == "exact":
            raise ValueError(f"the mass {self.mass} is the series of the particles' mass matrix: it runs with the MPM "
                             "projection (projection 'mpm')")
        if self.uses_exact_fields and self.scheme == "musl":
            raise ValueError("the exact projection, mass and interpolation stages are defined for USL and USF only")
        if isinstance(self.flip, bool) or not isinstance(self.flip, (int, float, np.number)) or not 0 <= self.flip <= 1:
            raise ValueError(f"the PIC/FLIP blend must lie in [0, 1] (1: FLIP, 0: PIC), got {self.flip!r}")
        check_order(self.xpic)
        if self.xpic and self.flip != 1:
            raise ValueError(f"XPIC replaces the PIC/FLIP blend: use xpic {self.xpic} with flip 1, "
                             f"got flip {self.flip!r}")
        if self.uses_exact_fields and (self.flip != 1 or self.xpic != 0 or self.reconstruct != "none"
                                       or self.volume != "carried"):
            raise ValueError("the remedies flip, xpic, reconstruct and volume run with the MPM stages only "
                             "(the basis bspline_gimp also with the exact stages)")
        if self.volume == "grid" and not get(get(self.basis).domain_twin).domain:
            raise ValueError(f"the grid volume reset averages the grid functions over the particle domains: the "
                             f"basis {self.basis} has no particle-domain twin")
        if self.uses_exact_fields and self.volume_rate != "point":
            raise ValueError("the volume rate over the particle domain runs with the MPM stages only")

    @property
    def uses_remedy(self) -> bool:
        """Whether a plateau remedy is on (the fused step runs every one: the blend, XPIC,
        ``bspline_gimp``, the grid volume and ``reconstruct``)."""
        return (self.basis == "bspline_gimp" or self.flip != 1 or self.xpic != 0 or self.reconstruct != "none"
                or self.volume != "carried")

    @property
    def transfer_name(self) -> str:
        """The registered transfer this step takes (:mod:`mpm_fem.core.transfers`): ``transfer``,
        with the old API mapped: ``xpic >= 1`` is ``"xpic"``."""
        return "xpic" if self.xpic else self.transfer

    @property
    def transfer_setting(self):
        """The parameter of :attr:`transfer_name`: the order for XPIC, the blend for the others."""
        return self.xpic if self.xpic else self.flip

    @property
    def uses_exact_fields(self) -> bool:
        """Whether a stage needs the problem's exact fields (an :class:`ExactStages`)."""
        return self.projection == "exact" or self.interpolation == "exact" or self.mass == "exact"


class Model(Protocol):
    """A material: its stress, its state update and its stable time step. A model whose stress
    ignores ``(dv/dx)_p`` sets ``stress_uses_gradient = False`` (the step then gathers none); a
    model with ``force == "slides"`` gives the nodal acceleration itself (``grid_acceleration``)."""

    def stress(self, particles: Particles, grad_v: np.ndarray | None) -> np.ndarray: ...

    def update(self, particles: Particles, grad_v: np.ndarray, dt: float, cell_size: np.ndarray) -> Particles: ...

    def stable_dt(self, particles: Particles, grid: Grid, cfl: float) -> float: ...

    # the volume remedy also calls ``with_volume(particles, volume) -> Particles``: the state at
    # the same mass (and specific energy) with the volumes ``volume``



def numpy_only(model: Model, stages: Stages) -> str | None:
    """Why only the numpy step (:func:`explicit_step`) can take ``model`` and ``stages``, or ``None``:
    the drift study's options, the volume rate over the particle domain (``stages.volume_rate``) and
    a density update other than the slides' (``model.density_update``,
    :mod:`mpm_fem.core.models.euler`), have no compiled form; :func:`mpm_fem.run.solve.run` then
    steps with the numpy step."""
    if stages.volume_rate != "point":
        return f"the volume rate {stages.volume_rate!r} runs in the numpy step only"
    form = getattr(model, "density_update", "linear")
    if form != "linear":
        return f"the density update {form!r} runs in the numpy step only"
    return None


class Boundary(Protocol):
    """Grid boundary conditions: impose them on the nodal velocity and acceleration."""

    def velocity(self, grid: Grid, v: np.ndarray, t: float) -> np.ndarray: ...

    def acceleration(self, grid: Grid, a: np.ndarray, v: np.ndarray, t: float, dt: float) -> np.ndarray: ...


@dataclass(frozen=True)
class Walls:
    """Rigid walls at both ends: ``v_i = a_i = 0`` on the boundary nodes."""

    def fixed_nodes(self, grid):
        """The nodes whose values :meth:`velocity` and :meth:`acceleration` prescribe, whatever their input."""
        return grid.boundary_nodes

    def velocity(self, grid, v, t):
        v = v.copy()
        v[grid.boundary_nodes] = 0.0
        return v

    def acceleration(self, grid, a, v, t, dt):
        a = a.copy()
        a[grid.boundary_nodes] = 0.0
        return a


def at_times(f: Callable[[np.ndarray, float], np.ndarray], x: np.ndarray, times: np.ndarray) -> np.ndarray:
    """``f(x, t)`` at each of ``times`` (K,), as (K, x.size), C-contiguous: one call of ``f`` on the
    broadcast arrays ``(x[None, :], times[:, None])``, elementwise the floats of one call per time
    when ``f`` is elementwise (the exact solutions are: a test checks); an ``f`` that does not
    broadcast is called once per time."""
    x, times = np.asarray(x, dtype=float), np.asarray(times, dtype=float)
    try:
        values = np.asarray(f(x[None, :], times[:, None]), dtype=float)
    except (ValueError, TypeError, IndexError):
        values = None
    if values is None or values.shape != (times.size, x.size):
        values = np.array([np.asarray(f(x, t), dtype=float) for t in times]).reshape(times.size, x.size)
    return np.ascontiguousarray(values)


@dataclass(frozen=True)
class Dirichlet:
    """Prescribed velocity ``g(x, t)`` at both ends; ``a_i`` makes ``v_i^{n+1} = g(x_i, t + dt)``.

    The data at ``t + dt`` of one step are the data at ``t`` of the next: the last evaluation is
    kept, so ``g`` is called once per step."""

    g: Callable[[np.ndarray, float], np.ndarray]
    _last: dict = field(default_factory=dict, compare=False, repr=False)

    def _values(self, grid, t):
        b = grid.boundary_nodes
        key = (float(grid.nodes[b[0]]), float(grid.nodes[b[-1]]), t)
        if self._last.get("key") != key:
            self._last.update(key=key, value=self.g(grid.nodes[b], t))
        return b, self._last["value"]

    def fixed_nodes(self, grid):
        """The nodes whose values :meth:`velocity` and :meth:`acceleration` prescribe, whatever their input."""
        return grid.boundary_nodes

    def end_values(self, grid, t):
        """``g`` at the boundary nodes at ``t``, the evaluation the step uses (kept per ``t``)."""
        return self._values(grid, t)[1]

    def end_values_at(self, grid, times: np.ndarray) -> np.ndarray:
        """``g`` at the boundary nodes at each of ``times`` (K,), as (K, boundary nodes)
        (:func:`at_times`: the floats of :meth:`end_values` at each time)."""
        return at_times(self.g, grid.nodes[grid.boundary_nodes], times)

    def velocity(self, grid, v, t):
        v = v.copy()
        b, g = self._values(grid, t)
        v[b] = g
        return v

    def acceleration(self, grid, a, v, t, dt):
        a = a.copy()
        b, g = self._values(grid, t + dt)
        a[b] = (g - v[b]) / dt
        return a


def prescribed(boundary: Boundary, grid: Grid, kind: str, impose: Callable[[np.ndarray], np.ndarray]):
    """The ``fixed`` argument of :func:`~mpm_fem.core.transfer.grid_values`: ``(nodes, values)`` a boundary
    prescribes, for a coupled mass (``COUPLED_KINDS``: its solve must see them) and a boundary that names its
    nodes (``fixed_nodes(grid)``, as :class:`Walls` and :class:`Dirichlet`); ``impose`` applies the boundary
    (its values at those nodes do not depend on its input: they are read off ``impose(0)``). ``None``
    otherwise: the lumped mass has no coupling, and the boundary is imposed on the solution as before."""
    nodes_of = getattr(boundary, "fixed_nodes", None)
    if kind not in COUPLED_KINDS or nodes_of is None:
        return None
    nodes = np.asarray(nodes_of(grid))
    return nodes, impose(np.zeros(grid.n_nodes))[nodes]


class ExactGrid(Protocol):
    """The grid stage of one step with exact stages (built by :meth:`ExactStages.grid_stage`; the
    equations are :class:`mpm_fem.exact_stages.ExactGridStage`'s), all (n_nodes,): ``v_i`` the nodal
    velocity, ``star_v`` and ``star_a`` the exact nodal ``v*`` and ``a*`` with the boundary rule,
    ``star_new = star_v + dt star_a``; :meth:`acceleration` gives ``a_i`` from the particles'
    force ``F_i`` (None where the projection is exact)."""

    v_i: np.ndarray
    star_v: np.ndarray
    star_a: np.ndarray

    @property
    def star_new(self) -> np.ndarray: ...

    def acceleration(self, F_mpm: np.ndarray | None) -> np.ndarray: ...


class ExactStages(Protocol):
    """The exact projection, mass and interpolation stages as the numpy step reaches them, passed in
    by the caller (:class:`mpm_fem.exact_stages.FieldStages` on a problem's exact fields), so that
    the step imports no package above the core.

    ``reference(x, t) -> (v*, v*_x, a*)`` and ``velocity_gradient(x, t) -> v*_x`` at the particles
    (arrays of the shape of ``x``); ``grid_stage`` the step's :class:`ExactGrid` from the particles'
    sums: ``shape`` their rows, ``mass`` (n_p,) their masses, ``m_i`` and ``P_i`` (n_nodes,)."""

    def reference(self, x: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]: ...

    def velocity_gradient(self, x: np.ndarray, t: float) -> np.ndarray: ...

    def grid_stage(self, grid: Grid, boundary: Boundary, stages: Stages, shape: Shape, mass: np.ndarray,
                   m_i: np.ndarray, P_i: np.ndarray, t: float, dt: float) -> ExactGrid: ...


@dataclass(frozen=True, eq=False)
class GridState:
    """What the grid held during one step, all (n_nodes,): ``m_i``, ``v_i^n``, ``a_i``, ``v_i^{n+1}``."""

    mass: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    new_velocity: np.ndarray


def explicit_step(
    grid: Grid,
    particles: Particles,
    model: Model,
    boundary: Boundary,
    t: float,
    dt: float,
    stages: Stages = Stages(),
    exact_acceleration: Callable[[np.ndarray, float], np.ndarray] | None = None,
    exact: ExactStages | None = None,
) -> tuple[Particles, GridState]:
    """Advance the particles from ``t`` to ``t + dt``; returns the new particles and the grid state.
    ``exact`` serves the exact projection, mass and interpolation stages (:class:`ExactStages`)."""
    if stages.uses_exact_fields:
        return _step_with_exact_stages(grid, particles, model, boundary, t, dt, stages, exact_acceleration, exact)
    shape = make_shape(grid, particles.x, particles.volume, stages.basis)
    h_p = grid.h[shape.cell]
    m, V = particles.mass, particles.volume
    m_i = nodal_mass(shape, m)
    transfer = get_transfer(stages.transfer_name)
    P_i = transfer.momentum(shape, grid.nodes, particles.x, m, particles.velocity, particles.affine)
    velocity_at_t = lambda u: boundary.velocity(grid, u, t)  # noqa: E731
    v_i = velocity_at_t(grid_values(shape, m, m_i, P_i, stages.mass,
                                    prescribed(boundary, grid, stages.mass, velocity_at_t)))
    if stages.volume == "grid":
        particles = _reset_volume(model, particles, grid_volume_factor(grid, particles.x, V, stages.basis, shape))
        V = particles.volume

    x_n = particles.x
    if stages.scheme == "usf":
        particles = _update(model, grid, particles, shape, x_n, v_i, dt, h_p, stages)
        V = particles.volume

    if stages.acceleration == "exact":
        if exact_acceleration is None:
            raise ValueError("this problem has no exact acceleration to use")
        a_i = exact_acceleration(grid.nodes, t)
    elif getattr(model, "force", "weak") == "slides":
        a_i = model.grid_acceleration(grid, shape.cell, v_i)
    else:
        if getattr(model, "stress_uses_gradient", True):
            stress = model.stress(particles, shape.gather_gradient(v_i))
        else:
            stress = model.stress(particles, None)
        if stages.reconstruct == "taylor":
            F_i = reconstructed_force(grid, particles.x, stress, stages.basis)
        else:
            F_i = nodal_internal_force(shape, V, stress)
        a_i = grid_values(shape, m, m_i, F_i, stages.mass, prescribed(
            boundary, grid, stages.mass, lambda u: boundary.acceleration(grid, u, v_i, t, dt)))
    a_i = boundary.acceleration(grid, a_i, v_i, t, dt)
    v_new = v_i + dt * a_i

    moving = shape.gather(v_new)
    x_old = particles.x
    velocity, affine = transfer.update(
        GridVelocities(shape, m, m_i, v_i, a_i, v_new, moving, dt, stages.mass,
                       boundary_change_rule(boundary, grid, t)),
        particles.velocity, stages.transfer_setting)
    x = particles.x + dt * moving
    particles = particles.replace(x=x, velocity=velocity, affine=affine)

    if stages.scheme == "musl":
        P_new = transfer.momentum(shape, grid.nodes, x_old, m, velocity, affine)
        velocity_at_end = lambda u: boundary.velocity(grid, u, t + dt)  # noqa: E731
        v_new = velocity_at_end(grid_values(shape, m, m_i, P_new, stages.mass,
                                            prescribed(boundary, grid, stages.mass, velocity_at_end)))
    if stages.scheme in ("usl", "musl"):
        particles = _update(model, grid, particles, shape, x_n, v_new, dt, h_p, stages)
    return particles, GridState(m_i, v_i, a_i, v_new)


def _update(model: Model, grid: Grid, particles: Particles, shape, x_n: np.ndarray, v: np.ndarray, dt: float,
            h_p: np.ndarray, stages: Stages) -> Particles:
    """The model's state update from ``L_p = sum_i G_ip v_i`` (the shape at ``x_n``, the positions
    at the start of the step); with ``stages.volume_rate == "domain"`` the volume takes the rate
    over the particle domains at ``x_n`` (:func:`mpm_fem.core.volume.domain_rate`): their ends move
    with the grid velocity, as the particle points do."""
    grad_v = shape.gather_gradient(v)
    if stages.volume_rate == "point":
        return model.update(particles, grad_v, dt, h_p)
    if not getattr(model, "takes_volume_rate", False):
        raise ValueError(f"the volume rate {stages.volume_rate!r} needs a model whose update takes a volume rate; "
                         f"{type(model).__name__} has none")
    rate = domain_rate(grid, x_n, particles.volume, v, stages.basis)
    return model.update(particles, grad_v, dt, h_p, volume_rate=rate)


def _reset_volume(model: Model, particles: Particles, factor: np.ndarray) -> Particles:
    """``V_p <- f_p V_p`` through the model (:mod:`mpm_fem.core.volume`)."""
    if not hasattr(model, "with_volume"):
        raise ValueError(f"the volume reset needs a model with with_volume(); {type(model).__name__} has none")
    return model.with_volume(particles, particles.volume * factor)


def _step_with_exact_stages(grid, particles, model, boundary, t, dt, stages, exact_acceleration, exact):
    """:func:`explicit_step` with some stages in their exact form (:mod:`mpm_fem.exact_stages.stage`).

    The same pipeline as the plain step; at each stage the MPM value is replaced as follows.
    projection: ``m_i, P_i, F_i`` are the exact integrals. mass ``"exact"``: a nodal value is the
    exact nodal value plus the projection error carried through the lumped solve (MPM data: the
    particle mass; exact data: the FE mass assembled by scikit-fem). interpolation:
    ``f_p = f*(x_p) + sum_i S_ip (f_i - f*_i)`` for the particle acceleration, the velocity that
    moves the particle and the velocity gradient.
    """
    if exact is None:
        raise ValueError("the exact projection, mass and interpolation stages need the problem's exact fields")
    if not hasattr(exact, "grid_stage"):
        raise TypeError(f"the exact stages take an ExactStages (mpm_fem.exact_stages.FieldStages(fields)), "
                        f"got {type(exact).__name__}")
    shape = make_shape(grid, particles.x, particles.volume, stages.basis)
    h_p = grid.h[shape.cell]
    m = particles.mass
    m_i = nodal_mass(shape, m)
    stage = exact.grid_stage(grid, boundary, stages, shape, m, m_i, nodal_momentum(shape, m, particles.velocity), t, dt)
    v_i, star_v, star_a = stage.v_i, stage.star_v, stage.star_a
    exact_at_particles = stages.interpolation == "exact"
    if exact_at_particles:
        p_v, p_vx, p_a = exact.reference(particles.x, t)

    def gradient(nodal, star, time):
        if not exact_at_particles:
            return shape.gather_gradient(nodal)
        field = p_vx if time == t else exact.velocity_gradient(particles.x, time)
        return field + shape.gather_gradient(nodal - star)

    if stages.scheme == "usf":
        particles = model.update(particles, gradient(v_i, star_v, t), dt, h_p)

    if stages.acceleration == "exact":
        if exact_acceleration is None:
            raise ValueError("this problem has no exact acceleration to use")
        a_i = boundary.acceleration(grid, exact_acceleration(grid.nodes, t), v_i, t, dt)
    else:
        stress = model.stress(particles, gradient(v_i, star_v, t))
        a_i = stage.acceleration(nodal_internal_force(shape, particles.volume, stress)
                                 if stages.projection == "mpm" else None)
    v_new = v_i + dt * a_i

    if exact_at_particles:
        star_new = stage.star_new
        acceleration = p_a + shape.gather(a_i - star_a)
        moving = p_v + dt * p_a + shape.gather(v_new - star_new)
    else:
        star_new = None
        acceleration, moving = shape.gather(a_i), shape.gather(v_new)
    particles = particles.replace(x=particles.x + dt * moving, velocity=particles.velocity + dt * acceleration)
    if stages.scheme == "usl":
        particles = model.update(particles, gradient(v_new, star_new, t + dt), dt, h_p)
    return particles, GridState(m_i, v_i, a_i, v_new)
