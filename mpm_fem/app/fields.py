"""Field output over time for ParaView: VTU snapshots written with meshio and a ``.pvd`` series.

``FieldWriter`` is an observer of :func:`mpm_fem.run.solve.run`: at every ``every``-th step it writes the
particles (points with their state as point data) and the grid (P1 line cells with nodal mass,
velocity, acceleration and density ``m_i / int S_i dx``) to ``folder/particles_NNNNN.vtu`` and
``folder/grid_NNNNN.vtu``, and ``close()`` adds the final frame at ``T`` and writes ``particles.pvd``
and ``grid.pvd``, the time series ParaView opens. The grid's final frame is the projection of the
final particles: its mass and velocity; its acceleration is NaN, since no step is taken at ``T``.

Given the problem's exact solution (``exact(x, t) -> {field: values}``), both meshes also carry, for
each field it has, ``<field>_exact`` and ``<field>_error`` (computed minus exact) at the frame's time
``t``: at the particles their state, at the nodes the density and the projected velocity ``v_i^n``
(the frame's ``velocity`` is the updated ``v_i^{n+1}``; at ``T`` the two are the same projection).
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable
from xml.sax.saxutils import quoteattr

import meshio
import numpy as np

from mpm_fem.core.grid import Grid
from mpm_fem.core.particles import Particles
from mpm_fem.core.shape import basis_integrals
from mpm_fem.core.step import GridState

PARTICLE_FIELDS = ("velocity", "density", "energy", "pressure", "volume", "mass")
#: The exact solution of a problem: ``exact(x, t) -> {field: values at x}``.
Exact = Callable[[np.ndarray, float], dict]


def _points(x: np.ndarray) -> np.ndarray:
    return np.column_stack((x, np.zeros_like(x), np.zeros_like(x)))


def compared(values: dict, x: np.ndarray, t: float, exact: Exact | None) -> dict:
    """``values`` with ``<field>_exact`` and ``<field>_error`` for each field of ``values`` that
    ``exact`` gives (none without ``exact``)."""
    if exact is None:
        return values
    reference = exact(x, t)
    out = dict(values)
    for name, value in values.items():
        if name in reference:
            out[f"{name}_exact"] = np.asarray(reference[name], dtype=float)
            out[f"{name}_error"] = value - out[f"{name}_exact"]
    return out


def particle_mesh(particles: Particles, t: float = 0.0, exact: Exact | None = None) -> meshio.Mesh:
    """The particles as meshio vertices carrying their state (and its error at ``t``, with ``exact``)."""
    n = particles.n
    data = compared({name: getattr(particles, name) for name in PARTICLE_FIELDS}, particles.x, t, exact)
    return meshio.Mesh(_points(particles.x), [("vertex", np.arange(n).reshape(-1, 1))], point_data=data)


def grid_mesh(grid: Grid, state: GridState, t: float = 0.0, exact: Exact | None = None,
              basis: str = "mpm") -> meshio.Mesh:
    """The grid as meshio line cells carrying ``m_i``, ``v_i^{n+1}``, ``a_i`` and the density
    ``m_i / int S_i dx`` (``S_i`` of ``basis``); with ``exact``, the density's and ``v_i^n``'s exact
    values and errors at ``t``."""
    cells = np.column_stack((np.arange(grid.n_cells), np.arange(1, grid.n_nodes)))
    density = state.mass / basis_integrals(grid, basis)
    data = {"mass": state.mass, "velocity": state.new_velocity, "acceleration": state.acceleration,
            "density": density}
    checked = compared({"density": density, "velocity": state.velocity}, grid.nodes, t, exact)
    data.update({k: v for k, v in checked.items() if k.endswith(("_exact", "_error"))})
    return meshio.Mesh(_points(grid.nodes), [("line", cells)], point_data=data)


class FieldWriter:
    """Observer writing snapshots every ``every`` steps (and at the first step) into ``folder``; with
    the problem's ``exact`` solution, its values and the errors beside the fields; ``basis``: the
    run's (the nodal density's ``int S_i dx``)."""

    keeps_particles = False  # it writes what it is handed at once (mpm_fem.run.solve.run may reuse the arrays)

    def __init__(self, folder, grid: Grid, every: int = 20, exact: Exact | None = None, basis: str = "mpm"):
        if every < 1:
            raise ValueError(f"fields are written every EVERY >= 1 steps, got {every}")
        self.folder = Path(folder)
        self.folder.mkdir(parents=True, exist_ok=True)
        self.grid, self.every, self.exact, self.basis = grid, every, exact, basis
        self.series: dict[str, list[tuple[float, str]]] = {"particles": [], "grid": []}

    def _write(self, kind: str, mesh: meshio.Mesh, t: float) -> None:
        name = f"{kind}_{len(self.series[kind]):05d}.vtu"
        meshio.write(self.folder / name, mesh)
        self.series[kind].append((t, name))

    def __call__(self, step: int, t: float, old: Particles, new: Particles, state: GridState) -> None:
        """At steps 0, EVERY, 2 EVERY, ...: the particles at the start of the step (time ``t``) and
        the grid they projected to."""
        if step % self.every == 0:
            self._write("particles", particle_mesh(old, t, self.exact), t)
            self._write("grid", grid_mesh(self.grid, state, t, self.exact, self.basis), t)

    def close(self, t_final: float, particles: Particles, nodal_mass: np.ndarray, nodal_velocity: np.ndarray) -> None:
        """Write the final particles and grid (if not yet written) and the two ``.pvd`` series."""
        if not self.series["particles"] or self.series["particles"][-1][0] < t_final:
            self._write("particles", particle_mesh(particles, t_final, self.exact), t_final)
            state = GridState(nodal_mass, nodal_velocity, np.full_like(nodal_mass, np.nan), nodal_velocity)
            self._write("grid", grid_mesh(self.grid, state, t_final, self.exact, self.basis), t_final)
        for kind, entries in self.series.items():
            lines = ['<?xml version="1.0"?>', '<VTKFile type="Collection" version="0.1">', "  <Collection>"]
            lines += [f'    <DataSet timestep="{t:.10g}" part="0" file={quoteattr(name)}/>' for t, name in entries]
            lines += ["  </Collection>", "</VTKFile>", ""]
            (self.folder / f"{kind}.pvd").write_text("\n".join(lines))
