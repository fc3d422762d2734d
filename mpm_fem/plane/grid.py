"""The 2D background grid: a scikit-fem tensor mesh ``MeshQuad.init_tensor(x, y)`` over a rectangle.

Nodes ``x_i = (x_a, y_b)`` on the tensor product of the axis nodes, numbered as scikit-fem numbers
them, ``i = a n_y + b`` (``y`` fastest). A periodic axis identifies its last node with its first:
it keeps ``n_cells`` nodes, and a grid function of the 1D basis on that axis is the sum of its
periodic images. The 1D basis is evaluated on a padded axis (:attr:`Axis.line`: ``PAD`` extra
cells at each end, so that no particle of the domain reaches the padded ends, where the 1D bases
fold their end functions) and the padded node ``j`` is node ``(j - PAD) mod n_cells`` of the
periodic axis. A non-periodic axis is the 1D grid of its own nodes (its end functions folded as in
1D). Cell sizes must divide the domain: a mesh that does not tile it is refused.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
from skfem import MeshQuad

from mpm_fem.core.grid import Grid, GridError, n_cells_for, uniform_grid

#: cells added at each end of a periodic axis: more than the support of every registered basis (2.5
#: cells) plus the reach of the end functions the 1D bases take at the ends of a line (the open knot
#: vector's: 5 cells for the cubic B-spline), so that every particle of the domain sees the uniform functions
PAD = 8


@dataclass(frozen=True, eq=False)
class Axis:
    """One axis of the tensor grid: ``nodes`` (n_nodes,) its own nodes (the last one dropped when
    ``periodic``), ``h`` its cell size, ``line`` the 1D grid the 1D basis is evaluated on, ``wrap``
    (line.n_nodes,) the axis node of each node of ``line``."""

    lo: float
    hi: float
    h: float
    periodic: bool
    nodes: np.ndarray
    line: Grid = field(repr=False)
    wrap: np.ndarray = field(repr=False)

    @property
    def n_nodes(self) -> int:
        return self.nodes.size

    @property
    def length(self) -> float:
        return self.hi - self.lo

    def fold(self, x: np.ndarray) -> np.ndarray:
        """``x`` brought into ``[lo, hi)`` on a periodic axis (unchanged on the other)."""
        if not self.periodic:
            return x
        return self.lo + np.mod(x - self.lo, self.length)


def make_axis(lo: float, hi: float, h: float, periodic: bool) -> Axis:
    """The axis ``[lo, hi]`` in cells of size ``h`` (which must divide ``hi - lo``)."""
    n = n_cells_for(lo, hi, h)
    if periodic:
        if n < 2:
            raise GridError(f"a periodic axis needs at least two cells, got {n} on [{lo}, {hi}]")
        line = uniform_grid(lo - PAD * h, hi + PAD * h, h)
        wrap = np.mod(np.arange(line.n_nodes) - PAD, n)
        nodes = np.linspace(lo, hi, n + 1)[:-1]
    else:
        line = uniform_grid(lo, hi, h)
        wrap = np.arange(line.n_nodes)
        nodes = line.nodes
    return Axis(float(lo), float(hi), float(h), bool(periodic), nodes, line, wrap)


@dataclass(frozen=True, eq=False)
class PlaneGrid:
    """The tensor grid (module docstring): ``axes`` (x, y) and the scikit-fem ``mesh`` on the same
    nodes (every node, the periodic ends included)."""

    axes: tuple[Axis, Axis]
    mesh: MeshQuad = field(repr=False)

    @property
    def h(self) -> tuple[float, float]:
        return self.axes[0].h, self.axes[1].h

    @property
    def periodic(self) -> tuple[bool, bool]:
        return self.axes[0].periodic, self.axes[1].periodic

    @property
    def shape(self) -> tuple[int, int]:
        """Nodes per axis ``(n_x, n_y)``."""
        return self.axes[0].n_nodes, self.axes[1].n_nodes

    @property
    def n_nodes(self) -> int:
        return self.shape[0] * self.shape[1]

    @cached_property
    def nodes(self) -> np.ndarray:
        """``x_i`` (n_nodes, 2), ``i = a n_y + b``."""
        X, Y = np.meshgrid(self.axes[0].nodes, self.axes[1].nodes, indexing="ij")
        return np.column_stack((X.ravel(), Y.ravel()))

    @cached_property
    def mesh_nodes(self) -> np.ndarray:
        """The grid node of each scikit-fem mesh point (mesh.nvertices,): periodic ends folded."""
        p = self.mesh.p
        index = []
        for k, axis in enumerate(self.axes):
            a = np.rint((p[k] - axis.lo) / axis.h).astype(np.intp)
            index.append(np.mod(a, axis.n_nodes) if axis.periodic else a)
        return index[0] * self.shape[1] + index[1]

    def fold(self, x: np.ndarray) -> np.ndarray:
        """Positions (n, 2) brought into the domain along the periodic axes."""
        return np.column_stack((self.axes[0].fold(x[:, 0]), self.axes[1].fold(x[:, 1])))


def plane_grid(lower, upper, h, periodic=(False, False)) -> PlaneGrid:
    """The grid over ``[lower[0], upper[0]] x [lower[1], upper[1]]`` with square cells of size
    ``h`` (or ``(h_x, h_y)``), periodic along the axes flagged; raises :class:`GridError` unless
    ``h`` divides each side."""
    hs = np.broadcast_to(np.asarray(h, dtype=float), (2,))
    axes = tuple(make_axis(float(lower[k]), float(upper[k]), float(hs[k]), bool(periodic[k])) for k in range(2))
    edges = [np.linspace(a.lo, a.hi, round(a.length / a.h) + 1) for a in axes]
    return PlaneGrid(axes, MeshQuad.init_tensor(*edges))
