"""Extensions from outside the package, of any kind: found by an entry point or a ``package.module:Name``,
checked on numbers, registered; one :class:`Loader` per kind (the bases, :mod:`mpm_fem.bases.plugins`;
the transfers, :mod:`mpm_fem.core.transfers.plugins`).

    entry point   ``[project.entry-points."<group>"] name = "mypkg.module:Name"`` in a package's
                  ``pyproject.toml``: :meth:`Loader.discover` loads every installed one;
    a spec        ``"mypkg.module:Name"`` where a registered name goes: :meth:`Loader.resolve` imports it.

Either names a subclass of the kind's base class (instantiated without arguments) or an instance.
Before it is registered it must pass the kind's ``verify`` (the first failed check in a few words,
``None`` if it passes); one that fails is refused with the kind's error class naming the check and
never reaches a run. The module sits with the bases because they are the lowest package that both
kinds import (``tests/test_layers.py``); it imports nothing of the project.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass, field
from importlib.metadata import entry_points
from typing import Callable


@dataclass
class Loader:
    """The extensions of one kind. ``kind`` the word in messages (``"basis"``), ``group`` the entry
    point group, ``base`` the base class of the contract, ``names`` and ``register`` the kind's
    registry, ``verify`` its checks on numbers, ``error`` the exception of a refusal (a
    ``TypeError``), ``prepare`` what is done to an admitted instance before it is registered. Its
    state: ``loaded`` (a spec or entry point's value -> the registered name) and ``failed`` (an entry
    point's name -> why it was refused)."""

    kind: str
    group: str
    base: type
    names: Callable[[], tuple[str, ...]]
    register: Callable[[object], object]
    verify: Callable[[object], str | None]
    error: type[Exception]
    prepare: Callable[[object], None] = lambda extension: None
    loaded: dict[str, str] = field(default_factory=dict)
    failed: dict[str, str] = field(default_factory=dict)

    def resolve(self, spec: str) -> str:
        """The registered name of ``spec``: a registered name as it is, an installed entry point's
        name, or a ``module:Name`` imported, checked and registered on first use. Raises
        :attr:`error` naming what failed (the import, the attribute, the failed check) and
        ``ValueError`` for a name that is neither registered, nor an installed entry point, nor a
        spec."""
        if spec in self.names():
            return spec
        if spec in self.loaded:
            return self.loaded[spec]
        if ":" not in spec:
            self.discover()
            if spec in self.names():
                return spec
            if spec in self.failed:
                raise self.error(self.failed[spec])
            raise ValueError(f"unknown {self.kind} {spec!r}; choose one of {', '.join(self.names())} or give "
                             "package.module:Name")
        module, _, attribute = spec.partition(":")
        try:
            target = getattr(importlib.import_module(module), attribute)
        except (ImportError, AttributeError) as err:
            raise self.error(f"the {self.kind} {spec} cannot be loaded: {err}") from None
        self.loaded[spec] = self.admit(target, spec)
        return self.loaded[spec]

    def discover(self) -> tuple[str, ...]:
        """Load, check and register every installed entry point of :attr:`group` not loaded yet;
        the names registered now. One that fails is kept out and its reason kept for
        :meth:`resolve`, so a broken plugin refuses only a run that asks for it."""
        added = []
        for point in entry_points(group=self.group):
            if point.value in self.loaded or point.name in self.failed:
                continue
            try:
                self.loaded[point.value] = self.admit(point.load(), point.value)
                added.append(self.loaded[point.value])
            except Exception as err:  # noqa: BLE001 - any failure of a third-party import refuses that plugin only
                self.failed[point.name] = str(err) if isinstance(err, self.error) else (
                    f"the {self.kind} {point.value} (entry point {point.name}) cannot be loaded: {err}")
        return tuple(added)

    def admit(self, target, spec: str) -> str:
        """Instantiate ``target`` if it is a subclass of :attr:`base`, check, prepare and register
        it; its name."""
        try:
            extension = target() if isinstance(target, type) and issubclass(target, self.base) else target
        except TypeError as err:  # e.g. an abstract method left out: the base class names it
            raise self.error(f"the {self.kind} {spec} cannot be instantiated: {err}") from None
        failed = self.verify(extension)
        if failed:
            raise self.error(f"the {self.kind} {spec} breaks its contract: {failed}")
        if extension.name in self.names():
            raise self.error(f"the {self.kind} {spec} is named {extension.name!r}, a name registered already")
        self.prepare(extension)
        self.register(extension)
        return extension.name
