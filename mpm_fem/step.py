"""One explicit MPM step (slides, "Forward Euler time integration").

    v_i^{n+1} = v_i^n + dt a_i
    v_p^{n+1} = v_p^n + dt sum_i S_ip a_i
    x_p^{n+1} = x_p^n + dt sum_i S_ip v_i^{n+1}            (semi-implicit: the new grid velocity)

with ``v_i^n = P_i / m_i`` and ``a_i = F_i / m_i`` from the projections of :mod:`mpm_fem.transfer`.
The particle state (density, energy, pressure) is updated from the velocity gradient

    USL (update stress last, the slides' order):  (dv/dx)_p = sum_i G_ip v_i^{n+1}, after the move
    USF (update stress first):                    (dv/dx)_p = sum_i G_ip v_i^n, before the force
    MUSL (modified USL): as USL, with v_i^{n+1} re-projected from the updated particle velocities.

Each stage of the step has a switch (:class:`Stages`); the exact forms used by the error budget
are supplied by the problem (``exact_acceleration``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Protocol

import numpy as np

from .grid import Grid
from .particles import Particles
from .shape import BASES, make_shape
from .transfer import MASS_KINDS, grid_values, nodal_internal_force, nodal_mass, nodal_momentum

SCHEMES = ("usl", "usf", "musl")
ACCELERATIONS = ("calculated", "exact")


@dataclass(frozen=True)
class Stages:
    """Which form each stage of the step takes.

    ``basis``: ``"mpm"`` (point mass) or ``"gimp"``; ``mass``: ``"lumped"`` or ``"consistent"``
    (particle mass matrix); ``acceleration``: ``"calculated"`` (``F_i/m_i``) or ``"exact"`` (the
    problem's exact nodal acceleration); ``scheme``: ``"usl"``, ``"usf"`` or ``"musl"``.
    """

    basis: str = "mpm"
    mass: str = "lumped"
    acceleration: str = "calculated"
    scheme: str = "usl"

    def __post_init__(self):
        for name, allowed in (("basis", BASES), ("mass", MASS_KINDS), ("acceleration", ACCELERATIONS), ("scheme", SCHEMES)):
            value = getattr(self, name)
            if value not in allowed:
                raise ValueError(f"unknown {name} {value!r}; choose one of {', '.join(allowed)}")


class Model(Protocol):
    """A material: its stress, its state update and its stable time step."""

    def stress(self, particles: Particles, grad_v: np.ndarray) -> np.ndarray: ...

    def update(self, particles: Particles, grad_v: np.ndarray, dt: float, cell_size: np.ndarray) -> Particles: ...

    def stable_dt(self, particles: Particles, grid: Grid, cfl: float) -> float: ...


class Boundary(Protocol):
    """Grid boundary conditions: impose them on the nodal velocity and acceleration."""

    def velocity(self, grid: Grid, v: np.ndarray, t: float) -> np.ndarray: ...

    def acceleration(self, grid: Grid, a: np.ndarray, v: np.ndarray, t: float, dt: float) -> np.ndarray: ...


@dataclass(frozen=True)
class Walls:
    """Rigid walls at both ends: ``v_i = a_i = 0`` on the boundary nodes."""

    def velocity(self, grid, v, t):
        v = v.copy()
        v[grid.boundary_nodes] = 0.0
        return v

    def acceleration(self, grid, a, v, t, dt):
        a = a.copy()
        a[grid.boundary_nodes] = 0.0
        return a


@dataclass(frozen=True)
class Dirichlet:
    """Prescribed velocity ``g(x, t)`` at both ends; ``a_i`` makes ``v_i^{n+1} = g(x_i, t + dt)``."""

    g: Callable[[np.ndarray, float], np.ndarray]

    def velocity(self, grid, v, t):
        v = v.copy()
        b = grid.boundary_nodes
        v[b] = self.g(grid.nodes[b], t)
        return v

    def acceleration(self, grid, a, v, t, dt):
        a = a.copy()
        b = grid.boundary_nodes
        a[b] = (self.g(grid.nodes[b], t + dt) - v[b]) / dt
        return a


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
) -> tuple[Particles, GridState]:
    """Advance the particles from ``t`` to ``t + dt``; returns the new particles and the grid state."""
    shape = make_shape(grid, particles.x, particles.volume, stages.basis)
    h_p = grid.h[shape.cell]
    m, V = particles.mass, particles.volume
    m_i = nodal_mass(shape, m)
    v_i = boundary.velocity(grid, grid_values(shape, m, m_i, nodal_momentum(shape, m, particles.velocity), stages.mass), t)

    if stages.scheme == "usf":
        particles = model.update(particles, shape.gather_gradient(v_i), dt, h_p)
        V = particles.volume

    if stages.acceleration == "exact":
        if exact_acceleration is None:
            raise ValueError("this problem has no exact acceleration to use")
        a_i = exact_acceleration(grid.nodes, t)
    else:
        stress = model.stress(particles, shape.gather_gradient(v_i))
        a_i = grid_values(shape, m, m_i, nodal_internal_force(shape, V, stress), stages.mass)
    a_i = boundary.acceleration(grid, a_i, v_i, t, dt)
    v_new = v_i + dt * a_i

    velocity = particles.velocity + dt * shape.gather(a_i)
    x = particles.x + dt * shape.gather(v_new)
    particles = particles.replace(x=x, velocity=velocity)

    if stages.scheme == "musl":
        v_new = boundary.velocity(
            grid, grid_values(shape, m, m_i, nodal_momentum(shape, m, velocity), stages.mass), t + dt
        )
    if stages.scheme in ("usl", "musl"):
        particles = model.update(particles, shape.gather_gradient(v_new), dt, h_p)
    return particles, GridState(m_i, v_i, a_i, v_new)
