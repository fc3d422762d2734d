"""2D field output for ParaView: the particles and the grid of a 2D run as VTU files (meshio), with ``.pvd`` series.

    particles   a point cloud (``vertex`` cells) at the positions ``x_p`` (z = 0) carrying the
                displacement ``u_p`` with its exact value and error at the frame's time, the velocity
                ``v_p``, ``F_p`` and the Cauchy stress ``sigma_p`` as 3 x 3 tensors (plane strain:
                ``F_zz = 1``, ``sigma_zz = lambda ln J / J``), ``J``, the volume and the mass
    grid        the scikit-fem quadrilaterals of the grid (a periodic axis's last row of points is
                its first node's copy) carrying the nodal mass ``m_i``, velocity ``v_i``, acceleration
                ``a_i`` and updated velocity ``v_i^+`` of the frame's step

:class:`PlaneFieldWriter` is an observer of :func:`mpm_fem.plane.run.run` (``observer(n, t, particles,
grid_state)``): it writes ``particles_NNNNN.vtu`` and ``grid_NNNNN.vtu`` after every ``every``-th
step (``every = 0``: none), and :meth:`~PlaneFieldWriter.close` writes the final step's frame (if not
written) and ``particles.pvd``, ``grid.pvd``. Vectors have three components (z = 0), as ParaView
reads them.
"""

from __future__ import annotations

from pathlib import Path
from xml.sax.saxutils import quoteattr

import meshio
import numpy as np

from mpm_fem.plane.model import determinant, neo_hookean_stress


def _vectors(a: np.ndarray) -> np.ndarray:
    """(n, 2) -> (n, 3), z = 0."""
    return np.column_stack((a, np.zeros(a.shape[0])))


def _tensors(a: np.ndarray, zz: np.ndarray) -> np.ndarray:
    """(n, 2, 2) in-plane tensors with the out-of-plane ``zz`` (n,) -> (n, 9) row-major 3 x 3."""
    out = np.zeros((a.shape[0], 3, 3))
    out[:, :2, :2] = a
    out[:, 2, 2] = zz
    return out.reshape(-1, 9)


def particle_mesh(particles, t: float, solution) -> meshio.Mesh:
    """The particles at ``t`` as meshio vertices carrying their state (module docstring)."""
    m = solution.material
    J = determinant(particles.F)
    sigma = neo_hookean_stress(particles.F, m.mu, m.lam)
    u = particles.displacement
    u_exact = np.asarray(solution.displacement(particles.X[:, 0], particles.X[:, 1], t)).T
    data = {"displacement": _vectors(u), "displacement_exact": _vectors(u_exact),
            "displacement_error": _vectors(u - u_exact), "velocity": _vectors(particles.v),
            "F": _tensors(particles.F, np.ones_like(J)), "stress": _tensors(sigma, m.lam * np.log(J) / J),
            "J": J, "volume": particles.volume, "mass": particles.mass}
    return meshio.Mesh(_vectors(particles.x), [("vertex", np.arange(particles.n).reshape(-1, 1))], point_data=data)


def grid_mesh(grid, state) -> meshio.Mesh:
    """The grid's quadrilaterals carrying the nodal fields of one step (module docstring)."""
    node = grid.mesh_nodes
    data = {"mass": state.mass[node], "velocity": _vectors(state.velocity[node]),
            "acceleration": _vectors(state.acceleration[node]), "new_velocity": _vectors(state.new_velocity[node])}
    return meshio.Mesh(_vectors(grid.mesh.p.T), [("quad", grid.mesh.t.T)], point_data=data)


class PlaneFieldWriter:
    """Observer writing the frames of a 2D run into ``folder`` (module docstring)."""

    def __init__(self, folder, grid, solution, every: int = 0):
        if every < 0:
            raise ValueError(f"fields are written every EVERY >= 1 steps (0: at the end only), got {every}")
        self.folder = Path(folder)
        self.folder.mkdir(parents=True, exist_ok=True)
        self.grid, self.solution, self.every = grid, solution, every
        self.series: dict[str, list[tuple[float, str]]] = {"particles": [], "grid": []}
        self.last = None

    def _write(self, kind: str, mesh: meshio.Mesh, t: float) -> None:
        name = f"{kind}_{len(self.series[kind]):05d}.vtu"
        meshio.write(self.folder / name, mesh)
        self.series[kind].append((t, name))

    def _frame(self, t: float, particles, state) -> None:
        self._write("particles", particle_mesh(particles, t, self.solution), t)
        self._write("grid", grid_mesh(self.grid, state), t)

    def __call__(self, step: int, t: float, particles, state) -> None:
        if self.every and step % self.every == 0:
            self._frame(t, particles, state)
        self.last = (t, particles, state)

    def close(self) -> None:
        """The final frame (if not yet written) and the ``.pvd`` series."""
        if self.last is not None and (not self.series["particles"] or self.series["particles"][-1][0] < self.last[0]):
            self._frame(*self.last)
        for kind, entries in self.series.items():
            lines = ['<?xml version="1.0"?>', '<VTKFile type="Collection" version="0.1">', "  <Collection>"]
            lines += [f'    <DataSet timestep="{t:.10g}" part="0" file={quoteattr(name)}/>' for t, name in entries]
            lines += ["  </Collection>", "</VTKFile>", ""]
            (self.folder / f"{kind}.pvd").write_text("\n".join(lines))
