"""A periodic 1D grid: ``[lo, hi)`` in ``n`` cells of size ``h``, its end node identified with its first.

The periodic grid keeps ``n`` nodes ``x_i = lo + i h``, and a grid function of a 1D basis is the sum
of its periodic images. The basis (:func:`mpm_fem.core.shape.make_shape`, any registered basis) is
evaluated on a padded grid (:attr:`PeriodicLine.line`: ``PAD`` extra cells at each end) at the position
folded into ``[lo, hi)``; the padded node ``j`` is node ``(j - PAD) mod n`` (:attr:`PeriodicLine.wrap`).
The padding keeps every row of a particle in ``[lo, hi)`` off the functions the 1D bases change at
an end of a grid: the cubic's end functions (open knot vector, :mod:`mpm_fem.bases.cubic`) are the
first four, so its rows need ``PAD >= 5``; then a row is the same in every cell (tested). The rows
are a :class:`~mpm_fem.core.shape.Shape` on the ``n`` nodes (a node may repeat in a row: its weights
add in every scatter and gather), so the transfers of :mod:`mpm_fem.core.transfer` serve a periodic
grid unchanged. The construction of one periodic axis of the 2D grid (:mod:`mpm_fem.plane.grid`), in
the 1D core.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mpm_fem.core.grid import Grid, GridError, n_cells_for, uniform_grid
from mpm_fem.core.shape import Shape, make_shape

#: cells added at each end of the padded grid: a row of a particle in [lo, hi) keeps off the end functions of
#: every registered basis (the cubic end functions differ from the uniform splines within four cells of an end)
PAD = 5


@dataclass(frozen=True, eq=False)
class PeriodicLine:
    """The periodic grid (module docstring): ``nodes`` (n,) its own nodes, ``h`` the cell size,
    ``line`` the padded :class:`~mpm_fem.core.grid.Grid` the basis is evaluated on, ``wrap``
    (line.n_nodes,) the node of each padded node."""

    lo: float
    hi: float
    h: float
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
        """``x`` brought into ``[lo, hi)``."""
        return self.lo + np.mod(x - self.lo, self.length)

    def shape(self, x: np.ndarray, volume: np.ndarray | None, basis: str = "mpm") -> Shape:
        """``S_ip``, ``G_ip`` (a :class:`~mpm_fem.core.shape.Shape` on the ``n`` nodes) of the
        particles at ``x`` (n_p,; any real value: folded) with the domain lengths ``volume`` (n_p,;
        a point basis ignores them), for the registered ``basis``."""
        padded = make_shape(self.line, self.fold(np.asarray(x, dtype=float)), volume, basis)
        return Shape(nodes=self.wrap[padded.nodes], S=padded.S, G=padded.G, n_nodes=self.n_nodes,
                     cell=np.mod(padded.cell - PAD, self.n_nodes))


def periodic_line(lo: float, hi: float, h: float) -> PeriodicLine:
    """The periodic grid on ``[lo, hi)`` in cells of size ``h`` (which must divide ``hi - lo``;
    at least two cells), else :class:`~mpm_fem.core.grid.GridError`."""
    n = n_cells_for(lo, hi, h)
    if n < 2:
        raise GridError(f"a periodic grid needs at least two cells, got {n} on [{lo}, {hi})")
    line = uniform_grid(lo - PAD * h, hi + PAD * h, h)
    wrap = np.mod(np.arange(line.n_nodes) - PAD, n)
    return PeriodicLine(float(lo), float(hi), float(h), np.linspace(lo, hi, n + 1)[:-1], line, wrap)
