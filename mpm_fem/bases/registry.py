"""The registry of bases: :func:`register` one instance per basis, :func:`get` it by name, :func:`names`.

The registry is the one list of bases the package reads (the numpy step, the compiled step, the
exact stages, the studies and the command line): a basis added here is a choice everywhere. A
basis is checked against its contract when registered (:func:`mpm_fem.bases.contract.missing`) and
refused at once if a piece is missing, so an incomplete basis never reaches a run, and :func:`get`
refuses a name that is not registered, listing the names that are.
"""

from __future__ import annotations

from mpm_fem.bases.contract import Basis, missing

_BASES: dict[str, Basis] = {}


class IncompleteBasisError(TypeError):
    """A basis that does not meet the contract of :class:`~mpm_fem.bases.contract.Basis`."""


def register(basis: Basis) -> Basis:
    """Add ``basis`` (an instance) under ``basis.name``; returns it. Raises
    :class:`IncompleteBasisError` naming every missing piece, and ``ValueError`` for a name taken."""
    lacking = missing(basis)
    if lacking:
        name = getattr(basis, "name", type(basis).__name__)
        raise IncompleteBasisError(f"the basis {name!r} is incomplete; it lacks: {'; '.join(lacking)}")
    if basis.name in _BASES:
        raise ValueError(f"a basis named {basis.name!r} is registered already")
    _BASES[basis.name] = basis
    return basis


def get(name: str | Basis) -> Basis:
    """The registered basis named ``name`` (a registered basis is returned as it is). Raises
    ``ValueError`` for a name that is not registered, listing those that are."""
    if isinstance(name, Basis) and _BASES.get(name.name) is name:
        return name
    if not isinstance(name, str) or name not in _BASES:
        raise ValueError(f"unknown basis {name!r}; choose one of {', '.join(_BASES)}")
    return _BASES[name]


def names() -> tuple[str, ...]:
    """The registered bases' names, in the order they were registered."""
    return tuple(_BASES)


def compiled(name: str | Basis) -> bool:
    """Whether the fused step can take the basis ``name``: it and its particle-domain twin (the grid
    volume reset's) ship compiled kernels; a basis without them runs on the numpy step."""
    basis = get(name)
    return basis.kernels is not None and get(basis.domain_twin).kernels is not None
