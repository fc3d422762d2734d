"""The registry of transfers: :func:`register` one instance per transfer, :func:`get` it by name,
:func:`names`. :func:`get` refuses a name that is not registered, listing those that are, so an
unknown transfer never runs as another."""

from __future__ import annotations

from mpm_fem.core.transfers.contract import Transfer

_TRANSFERS: dict[str, Transfer] = {}


def register(transfer: Transfer) -> Transfer:
    """Add ``transfer`` (an instance) under its name; ``TypeError`` for one that is not a
    :class:`Transfer` or lacks a name, ``ValueError`` for a name taken."""
    if not isinstance(transfer, Transfer) or not isinstance(getattr(transfer, "name", None), str):
        raise TypeError(f"a transfer is a Transfer instance with a name, got {transfer!r}")
    if transfer.name in _TRANSFERS:
        raise ValueError(f"a transfer named {transfer.name!r} is registered already")
    _TRANSFERS[transfer.name] = transfer
    return transfer


def get(name: str | Transfer) -> Transfer:
    """The registered transfer named ``name``; ``ValueError`` naming the known ones otherwise."""
    if isinstance(name, Transfer) and _TRANSFERS.get(name.name) is name:
        return name
    if not isinstance(name, str) or name not in _TRANSFERS:
        raise ValueError(f"unknown transfer {name!r}; choose one of {', '.join(_TRANSFERS)}")
    return _TRANSFERS[name]


def names() -> tuple[str, ...]:
    """The registered transfers' names, in the order they were registered."""
    return tuple(_TRANSFERS)
