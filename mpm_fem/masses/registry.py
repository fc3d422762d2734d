"""The registry of grid masses: :func:`register` one instance per mass, :func:`get` it by name, :func:`names`.

The one list of grid masses the 2D step, the command line (``mpm-fem plane --mass``), the Python
entry points (``mpm_fem.plane.axis(mass=...)``) and the studies read. A mass is checked against its
contract when registered (:func:`mpm_fem.masses.contract.missing`); :func:`get` refuses a name that
is not registered, listing those that are.
"""

from __future__ import annotations

from mpm_fem.masses.contract import GridMass, missing

_MASSES: dict[str, GridMass] = {}


class IncompleteMassError(TypeError):
    """A grid mass that does not meet the contract of :class:`~mpm_fem.masses.contract.GridMass`."""


def register(mass: GridMass) -> GridMass:
    """Add ``mass`` (an instance) under ``mass.name``; returns it. Raises :class:`IncompleteMassError`
    naming every missing piece, and ``ValueError`` for a name taken."""
    lacking = missing(mass)
    if lacking:
        name = getattr(mass, "name", type(mass).__name__)
        raise IncompleteMassError(f"the grid mass {name!r} is incomplete; it lacks: {'; '.join(lacking)}")
    if mass.name in _MASSES:
        raise ValueError(f"a grid mass named {mass.name!r} is registered already")
    _MASSES[mass.name] = mass
    return mass


def get(name: str | GridMass) -> GridMass:
    """The registered mass named ``name`` (a :class:`GridMass` instance is returned as it is, registered
    or not: a caller's own, e.g. FMPM of a higher order). Raises ``ValueError`` for a name that is not
    registered, listing those that are."""
    if isinstance(name, GridMass):
        return name
    if not isinstance(name, str) or name not in _MASSES:
        raise ValueError(f"unknown mass {name!r}; choose one of {', '.join(_MASSES)}")
    return _MASSES[name]


def names() -> tuple[str, ...]:
    """The registered masses' names, in the order they were registered."""
    return tuple(_MASSES)
