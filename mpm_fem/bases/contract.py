"""What a basis provides: the contract every basis module meets (scikit-fem's ``Element`` is the model).

Slides, "MPM Basis Overview": a basis gives each particle its weights at the grid nodes,

    point basis             S_ip = S_i(x_p),                       G_ip = S_i'(x_p)
    particle-domain basis   S_ip = 1/V_p int S_i(x) chi_p(x) dx,    G_ip = 1/V_p int S_i'(x) chi_p(x) dx

with ``S_i(x)`` the grid functions (the P1 hats, the quadratic B-splines, ...) and ``chi_p`` the
indicator of the particle's domain ``[x_p - V_p/2, x_p + V_p/2]``. A basis is a small class in a
module of its own (:mod:`mpm_fem.bases.point` is the model) holding its numpy rows (the readable
reference of the numpy step) and its compiled kernels (:class:`Kernels`, the fused step's), and one
instance of it is registered (:mod:`mpm_fem.bases.registry`); the numpy step, the compiled step, the
exact stages, the studies and the command line read the registry. Registration checks the contract
(:func:`missing`): a basis without one of its pieces is refused at once, naming the piece.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import TYPE_CHECKING, Callable, NamedTuple

import numpy as np

from mpm_fem.bases.shape import Shape

if TYPE_CHECKING:
    from mpm_fem.core.grid import Grid


class Geometry(NamedTuple):
    """The grid as the compiled kernels and passes read it."""

    nodes: np.ndarray  # x_i (n_nodes,)
    h: np.ndarray  # (2, n_cells): the cell sizes h_c and 1 / h_c
    inv_spacing: float  # 1/h on a grid uniform to round-off, else 0 (the node arithmetic)


class Cloud(NamedTuple):
    """The particle arrays pass 1 reads (n_p,): position, volume, mass, velocity, pressure."""

    x: np.ndarray
    V: np.ndarray
    m: np.ndarray
    v: np.ndarray
    p: np.ndarray


class RowStore(NamedTuple):
    """Pass 1's store: the particles' rows (node indices, ``S_ip``, ``G_ip``; (n_p, K), or no rows
    where they are not stored) and their cells (n_p,)."""

    rows: np.ndarray
    S: np.ndarray
    G: np.ndarray
    cell: np.ndarray


class Kernels(NamedTuple):
    """A basis's compiled pieces: numba functions (``njit(inline="always")``) that the fused step's
    variants take as compile-time globals (:mod:`mpm_fem.fused.compiler`), so that a variant holds
    one basis's arithmetic and no other. The arguments: ``nodes`` (n_nodes,); ``h`` (2, n_cells):
    the cell sizes ``h_c`` and ``1 / h_c``; ``inv_spacing``: ``1/h`` on a grid uniform to round-off,
    else 0 (then the node arithmetic of the numpy rows, bit for bit); one particle's ``x``, ``V``; a
    row's scratch ``row`` (K,) int, ``S``, ``G`` (K,).

    row       ``(nodes, h, inv_spacing, x, V, row, S, G) -> (c, K_needed)``: ``S_ip``, ``G_ip`` of one
              particle (a point basis ignores ``V``) into the K columns given; its cell and the
              columns it needs (a particle-domain row widens when its domain spans more cells).
    pass_row  ``(nodes, h, inv_spacing, x, q, rows, S, G, cell, r, Sl, Gl) -> c``: particle q's row
              in the passes after pass 1: recomputed from ``x[q]`` (a point basis: the same
              numbers, and cheaper than reading them back) or read from pass 1's store ``rows``,
              ``S``, ``G``, ``cell`` (a particle-domain basis: :func:`mpm_fem.bases.cells.stored_row`).
    project   ``(geometry, cloud, gas_force, store, lo, hi, stored, buf) -> (outside, empty,
              K_needed)``: pass 1 over particles ``lo .. hi-1`` (``geometry``: :class:`Geometry`,
              the grid's ``nodes``, ``h``, ``inv_spacing``; ``cloud``: :class:`Cloud`, the
              particles' ``x``, ``V``, ``m``, ``v``, ``p``) into the chunk's buffer ``buf`` (3,
              n_nodes): ``m_p S_ip``, ``m_p v_p S_ip`` and, if ``gas_force``, ``V_p p_p G_ip``, each
              node's terms added in particle order, a row's nodes left to right (the numpy step's
              ``np.bincount`` order); into ``stored`` (:class:`RowStore`) the cells, and the rows
              ``rows``, ``S``, ``G`` if ``store``; returns the first particle outside the grid, the
              first without volume (-1 if none) and the columns the rows need.
    any_grid  whether ``project`` and ``move`` serve a grid that is not uniform too (else the fused
              step calls them only where ``inv_spacing > 0`` and takes ``row`` elsewhere).
    move      ``(nodes, h, inv_spacing, x, a_i, v_n) -> (c, sum_i S_ip a_i, sum_i S_ip v_n,i,
              sum_i G_ip v_n,i)``: pass 2's three sums of one particle with its row in registers,
              each in ``_gather``'s order; ``None``: pass 2 takes ``pass_row`` and the gathers.
    scalars   a particle-domain basis on a uniform grid: ``(a, b, top_cell, inv_spacing, x, V) ->
              D``, a flat tuple of scalars starting ``(c, K_needed, c_-, c_+, ...)`` (no array
              handed to a helper per particle); ``None`` for a point basis.
    column    ``(k, inv_spacing, last, D) -> (i, S_ik, G_ik)``: column k of that row from ``D``.
    """

    row: Callable
    pass_row: Callable
    project: Callable
    any_grid: bool
    move: Callable | None
    scalars: Callable | None
    column: Callable | None


class Basis(ABC):
    """A basis: its class attributes, its numpy rows (:meth:`shape`), the integrals of its grid
    functions (:meth:`integrals`) and its compiled :class:`Kernels`.

    name            the name a run's ``Stages(basis=...)`` and the command line use
    title           what it is, in a few words (the command line's help)
    width           K, the nodes per particle a row starts with
    grid_functions  the registered point basis whose ``S_i(x)`` this basis uses (its own name for a
                    point basis; a particle-domain basis averages those functions)
    domain          whether ``S_ip`` averages over the particle domain (rows need volumes, may widen
                    as a domain spans more cells, and are stored by pass 1)
    domain_twin     the registered particle-domain basis over the same ``S_i`` (its own name for a
                    particle-domain basis): the grid volume reset's ``Sbar_ip``
    degree          the polynomial degree of ``S_i`` on each piece between nodes and half cells: the
                    exact stages integrate with elements of that degree
    uniform         whether the basis needs a uniform grid (:meth:`check_grid` raises otherwise)
    kernels         the compiled pieces (:class:`Kernels`), or ``None`` for a basis that runs on the numpy
                    step only (a researcher's first version, :mod:`mpm_fem.bases.plugins`)
    tensor          whether the tensor product of its rows per axis is its 2D form (:mod:`mpm_fem.plane.bases`;
                    a particle-domain basis then averages over a rectangle); default True
    """

    name: str
    title: str
    width: int
    grid_functions: str
    domain: bool
    domain_twin: str
    degree: int
    uniform: bool
    kernels: Kernels | None
    tensor: bool = True

    @abstractmethod
    def shape(self, grid: Grid, x: np.ndarray, volume: np.ndarray | None = None) -> Shape:
        """``S_ip``, ``G_ip`` of the particles at ``x`` (n_p,) with volumes ``volume`` (n_p,; a point
        basis ignores them): a :class:`~mpm_fem.bases.shape.Shape` of n_p rows. Raises
        :class:`~mpm_fem.bases.shape.OutsideGridError` for a point outside the grid."""

    @abstractmethod
    def integrals(self, grid: Grid) -> np.ndarray:
        """``int S_i dx`` (n_nodes,) of the grid functions, the weight that turns a nodal mass into a
        density (the grid volume reset's ``int S_i``)."""

    def check_grid(self, grid: Grid) -> None:
        """Raise ``ValueError`` if this basis cannot take ``grid``: a basis with ``uniform`` needs
        equal cells (to 1e-9 relative)."""
        h = grid.h
        if self.uniform and np.ptp(h) > 1e-9 * h.max():
            raise ValueError(f"the {self.name} basis needs a uniform grid")

    def __repr__(self) -> str:
        return f"<basis {self.name}>"


#: the attributes a basis must set: their type and what each is (for the message refusing an incomplete one)
ATTRIBUTES = {
    "name": (str, "its name"),
    "title": (str, "what it is, in a few words"),
    "width": (int, "the nodes per particle a row starts with"),
    "grid_functions": (str, "the point basis of its S_i(x)"),
    "domain": (bool, "whether it averages over the particle domain"),
    "domain_twin": (str, "the particle-domain basis of the grid volume reset"),
    "degree": (int, "the polynomial degree of its S_i for the exact stages"),
    "uniform": (bool, "whether it needs a uniform grid"),
    "kernels": ((Kernels, type(None)), "its compiled Kernels, or None: the numpy step only"),
}
#: the kernels every basis needs; a particle-domain basis needs ``DOMAIN_KERNELS`` too
KERNELS = ("row", "pass_row", "project")
DOMAIN_KERNELS = ("scalars", "column")


def missing(basis) -> list[str]:
    """The pieces of the contract ``basis`` lacks or gets wrong (empty: complete), each named with
    what it is: an attribute unset or of the wrong type, a kernel that is not a compiled function
    (a subclass without ``shape`` or ``integrals`` cannot be instantiated: the base class names
    the method)."""
    if not isinstance(basis, Basis):
        return [f"the base class Basis (got {type(basis).__name__})"]
    out = [f"{a} ({what})" for a, (kind, what) in ATTRIBUTES.items() if not _is(getattr(basis, a, None), kind)]
    kernels = getattr(basis, "kernels", None)
    if isinstance(kernels, Kernels):
        wanted = KERNELS + (DOMAIN_KERNELS if basis.domain is True else ())
        out += [f"kernels.{k} (a compiled function)" for k in wanted if not hasattr(getattr(kernels, k), "py_func")]
        if kernels.move is not None and not hasattr(kernels.move, "py_func"):
            out.append("kernels.move (a compiled function or None)")
    return out


def _is(value, kind) -> bool:
    """Whether ``value`` is a ``kind`` (an int that is not a bool, for ``kind`` int)."""
    return isinstance(value, kind) and not (kind is int and isinstance(value, bool))
