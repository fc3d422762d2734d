"""A Python caller's settings checked as the command line checks its options: one exception, one line.

Every bad input is a :class:`~mpm_fem.app.guard.UsageError` (``mpm_fem.UsageError``, a
``ValueError``); an unknown keyword is its subclass :class:`~mpm_fem.app.guard.UnknownSetting`, also
a ``TypeError`` as Python's own. The checks, made before anything is allocated:

    types       each setting has its field's type: a real number where the default is a float (an
                integer accepted), an integer where it is an int, a string where it is a string, a
                tuple or list where it is a tuple (no bool for a number, no string for either)
    extensions  ``basis`` and ``transfer`` take a registered name, an alias (:data:`ALIASES`: ``p1``
                for the point-mass basis ``mpm``), an installed entry point's name (discovered on
                first use) or ``package.module:Name`` (imported and checked against its contract:
                :mod:`mpm_fem.bases.plugins`, :mod:`mpm_fem.core.transfers.plugins`), as the command
                line's ``--basis`` and ``--transfer``
    values      the settings dataclass's own checks (``h`` divides the domain, ``ppc >= 1``, ...),
                their message kept
    points      the positions and time of an exact solution are finite numbers

A message is one line naming the setting and the value given.
"""

from __future__ import annotations

import numbers
from contextlib import contextmanager
from dataclasses import fields

import numpy as np

from mpm_fem.app.guard import UsageError

#: Other names a caller may give a registered extension: ``{setting: {alias: registered name}}``.
#: The registered name is the one runs, tables and the case cache store.
ALIASES = {"basis": {"p1": "mpm"}, "transfer": {}}


def _resolver(setting: str):
    if setting == "basis":
        from mpm_fem.bases import plugins
    else:
        from mpm_fem.core.transfers import plugins
    return plugins.resolve


def extension(setting: str, spec, call: str | None = None) -> str:
    """The registered name of ``spec`` given for ``setting`` (``"basis"`` or ``"transfer"``): an alias
    replaced, an entry point's or a ``package.module:Name`` loaded and checked (module docstring).
    ``call``, if given, starts the message of a refusal."""
    start = f"{call}(): " if call else ""
    if not isinstance(spec, str):
        raise UsageError(f"{start}{setting} takes a name or package.module:Name, got {spec!r} "
                         f"({type(spec).__name__})")
    spec = ALIASES[setting].get(spec, spec)
    try:
        return _resolver(setting)(spec)
    except (ValueError, TypeError) as err:  # unknown, or refused by the contract (ContractError)
        raise UsageError(f"{start}{err}") from None


def _kind(default) -> tuple[str, object]:
    """What a field with ``default`` takes: its description and the test of a value."""
    if isinstance(default, bool):
        return "True or False", lambda v: isinstance(v, (bool, np.bool_))
    if isinstance(default, int):
        return "an integer", lambda v: isinstance(v, numbers.Integral) and not isinstance(v, (bool, np.bool_))
    if isinstance(default, float):
        return "a number", lambda v: isinstance(v, numbers.Real) and not isinstance(v, (bool, np.bool_))
    if isinstance(default, str):
        return "a name (a string)", lambda v: isinstance(v, str)
    if isinstance(default, tuple):
        return "a tuple of numbers", lambda v: isinstance(v, (tuple, list))
    return "", lambda v: True


def check_types(defaults, given: dict, call: str) -> None:
    """Each of ``given`` has the type of its default in ``defaults`` (a mapping, or a dataclass whose
    fields' defaults count); else ``UsageError`` naming ``call``, the setting and the value."""
    if not isinstance(defaults, dict):
        defaults = {f.name: f.default for f in fields(defaults)}
    for name, value in given.items():
        what, ok = _kind(defaults[name])
        if not ok(value):
            hint = f"; a preset is named by preset={value!r}" if name == "h" and isinstance(value, str) else ""
            raise UsageError(f"{call}(): {name} must be {what}, got {value!r} ({type(value).__name__}){hint}")


@contextmanager
def refused(call: str):
    """Inside: a ``ValueError`` raised by a check of the settings becomes a ``UsageError`` naming
    ``call`` (for code whose only ``ValueError`` is bad input: a failed run raises ``ArithmeticError``)."""
    try:
        yield
    except UsageError:
        raise
    except ValueError as err:
        raise UsageError(f"{call}(): {err}") from None


def settings(kind, values: dict, call: str, given: dict | None = None):
    """``kind(**values)`` with ``given`` (the caller's part of ``values``, default all) checked first:
    types (:func:`check_types`), extensions (:func:`extension`); the dataclass's own refusal
    (``ValueError``, ``GridError``) becomes a ``UsageError`` with its message."""
    given = values if given is None else given
    check_types(kind, given, call)
    values = {**values, **{k: extension(k, values[k], call) for k in ALIASES if k in given}}
    try:
        return kind(**values)
    except UsageError:
        raise
    except (ValueError, TypeError) as err:
        raise UsageError(f"{call}(): {err}") from None


def number(name: str, value, call: str) -> float:
    """``value`` as a finite float (``name`` in the message), else ``UsageError``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real) or not np.isfinite(value):
        raise UsageError(f"{call}(): {name} must be a finite number, got {value!r}")
    return float(value)


def points(x, call: str) -> np.ndarray:
    """The positions ``x`` as a float array of finite numbers, else ``UsageError``."""
    try:
        out = np.asarray(x, dtype=float)
    except (ValueError, TypeError):
        raise UsageError(f"{call}(): x must be numbers (positions), got {x!r}") from None
    bad = ~np.isfinite(out)
    if bad.any():
        raise UsageError(f"{call}(): the positions x must be finite, got {float(out[bad].ravel()[0])!r} "
                         f"at index {int(np.flatnonzero(bad.ravel())[0])}")
    return out
