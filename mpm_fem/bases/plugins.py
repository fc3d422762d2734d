"""Bases from outside the package: an entry point or a ``package.module:Name``, checked before any run.

A researcher's package adds a basis without editing this one, in either of two ways:

    entry point   ``[project.entry-points."mpm_fem.bases"] cubic5 = "mypkg.bases:Quintic"`` in its
                  ``pyproject.toml``: :func:`discover` loads every installed one (the command line
                  does, before it lists its choices);
    a spec        ``"mypkg.bases:Quintic"`` given where a basis name goes (``mpm-fem sod --basis
                  mypkg.bases:Quintic``): :func:`resolve` imports it.

Either names a :class:`~mpm_fem.bases.contract.Basis` subclass (instantiated without arguments) or
an instance. Before it is registered it must pass :func:`verify`, the contract checked on numbers:
its pieces (:func:`~mpm_fem.bases.contract.missing`), then on a uniform grid of
:data:`CHECK_CELLS` cells with particles at :data:`CHECK_PPC` per cell, the ends included, rows of
the right shapes with finite weights, the partition of unity ``sum_i S_ip = 1`` and ``sum_i G_ip =
0`` to :data:`TOLERANCE`, ``int S_i dx`` summing to the domain's length, and, if it ships compiled
kernels, its compiled row equal to its numpy rows to :data:`TOLERANCE`. A basis that fails is
refused with a :class:`ContractError` naming the first failed check; it never reaches a run. A
basis without compiled kernels (``kernels = None``) runs on the numpy step only
(:func:`mpm_fem.run.solve.run` says so in its result).
"""

from __future__ import annotations

import numpy as np

from mpm_fem.bases.contract import Basis, missing
from mpm_fem.bases.loader import Loader
from mpm_fem.bases.registry import IncompleteBasisError, names, register

ENTRY_POINT_GROUP = "mpm_fem.bases"
CHECK_CELLS = 8  # the check's grid on [0, 1]
CHECK_PPC = 5  # particles per cell of the check, plus both ends of the grid
TOLERANCE = 1e-10  # the partition of unity and the compiled row against the numpy rows, relative to 1 and 1/h


class ContractError(IncompleteBasisError):
    """A basis that breaks its contract on numbers (or cannot be imported): the message names the check."""


def resolve(spec: str) -> str:
    """The registered name of ``spec``: a registered name as it is, an installed entry point's name,
    a ``module:Name`` imported, checked (:func:`verify`) and registered on first use. Raises
    :class:`ContractError` naming what failed (the import, the attribute, the failed check) and
    ``ValueError`` for a name that is neither registered, nor an installed entry point, nor a spec
    (:meth:`mpm_fem.bases.loader.Loader.resolve`)."""
    return LOADER.resolve(spec)


def discover() -> tuple[str, ...]:
    """Load, check and register every installed entry point of :data:`ENTRY_POINT_GROUP` not loaded
    yet; returns the names registered now. One that fails is kept out and its reason kept for
    :func:`resolve`, so a broken plugin refuses only a run that asks for it."""
    return LOADER.discover()


def verify(basis) -> str | None:
    """The first check of the module docstring that ``basis`` fails, in a few words; ``None`` if it
    passes them all."""
    lacking = missing(basis)
    if lacking:
        return f"it lacks {'; '.join(lacking)}"
    from mpm_fem.core.grid import uniform_grid  # the grid layer: imported when a check runs

    grid = uniform_grid(0.0, 1.0, 1.0 / CHECK_CELLS)
    x = np.r_[0.0, (np.arange(CHECK_CELLS * CHECK_PPC) + 0.5) / (CHECK_CELLS * CHECK_PPC), 1.0]
    volume = np.full(x.size, 1.0 / (CHECK_CELLS * CHECK_PPC))
    try:
        shape = basis.shape(grid, x, volume)
        integrals = np.asarray(basis.integrals(grid), dtype=float)
    except Exception as err:  # noqa: BLE001 - a third-party basis may raise anything: that is the finding
        return f"its numpy rows raise {type(err).__name__}: {err}"
    S, G, nodes = (np.asarray(a) for a in (shape.S, shape.G, shape.nodes))
    if not (S.ndim == 2 and S.shape[0] == x.size and S.shape == G.shape == nodes.shape):
        return (f"its rows have shapes S {S.shape}, G {G.shape}, nodes {nodes.shape}, not (n_p, K) each "
                f"with n_p = {x.size}")
    if not (np.all(np.isfinite(S)) and np.all(np.isfinite(G))):
        return "its weights S_ip or G_ip are not finite"
    if nodes.min() < 0 or nodes.max() >= grid.n_nodes:
        return f"its rows name nodes outside 0 .. {grid.n_nodes - 1}"
    unity = np.abs(S.sum(axis=1) - 1.0).max()
    if unity > TOLERANCE:
        return f"no partition of unity: |sum_i S_ip - 1| up to {unity:.3g}"
    slope = np.abs(G.sum(axis=1)).max() / CHECK_CELLS
    if slope > TOLERANCE:
        return f"sum_i G_ip is not 0: up to {slope:.3g} h^-1"
    if integrals.shape != (grid.n_nodes,) or abs(integrals.sum() - 1.0) > TOLERANCE:
        return f"int S_i dx ({integrals.shape}) does not sum to the domain's length 1"
    if basis.kernels is not None:
        return _compare_row(basis, grid, x, volume, shape)
    return None


def _compare_row(basis: Basis, grid, x: np.ndarray, volume: np.ndarray, shape) -> str | None:
    """Whether the compiled row of every check particle gives its numpy row (as dense rows)."""
    h = np.vstack((grid.h, 1.0 / grid.h))
    width = max(basis.width, shape.S.shape[1]) + 4  # room for a particle-domain row that widens
    dense = shape.matrix().toarray(), shape.matrix(derivative=True).toarray()
    for p in range(x.size):  # a check on a few dozen particles, not a hot path
        row, S, G = np.zeros(width, np.intp), np.zeros(width), np.zeros(width)
        try:
            _, used = basis.kernels.row(grid.nodes, h, 1.0 / grid.h[0], x[p], volume[p], row, S, G)
        except Exception as err:  # noqa: BLE001 - a third-party kernel may raise anything
            return f"its compiled row raises {type(err).__name__}: {err}"
        for numpy_row, weights, scale in ((dense[0][p], S, 1.0), (dense[1][p], G, 1.0 / grid.h[0])):
            compiled = np.bincount(row[:used], weights[:used], grid.n_nodes)
            gap = np.abs(compiled - numpy_row).max() / scale
            if gap > TOLERANCE:
                return f"its compiled row differs from its numpy rows by {gap:.3g} at x = {x[p]:.6g}"
    return None


#: the bases from outside the package: their entry points, specs and refusals (:class:`~mpm_fem.bases.loader.Loader`)
LOADER = Loader("basis", ENTRY_POINT_GROUP, Basis, names, register, verify, ContractError)
