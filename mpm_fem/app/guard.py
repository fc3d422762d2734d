"""Guard rails of the command line, checked before any work starts.

- Bad input is a :class:`UsageError` (a ``ValueError``; ``mpm_fem.UsageError`` for Python callers):
  one line on stderr, exit status 2. An unknown keyword is :class:`UnknownSetting`, also a ``TypeError``.
- A run whose estimated memory (:class:`mpm_fem.problems.Cost`, from the settings alone) exceeds
  half the available memory is refused; one estimated over an hour needs ``--yes-long``.
- ``--jobs`` is capped at the number of cores; a scheduler address must parse and answer a TCP
  connect within a few seconds before Dask is given it.
- Ctrl-C ends with one line and exit status 130; a run that fails (lost positivity, non-finite
  state) with one line and exit status 1.
"""

from __future__ import annotations

import argparse
import difflib
import os
import re
import socket
import sys
from urllib.parse import urlsplit

MEMORY_SHARE = 0.5  # a run may take at most this share of the available memory
LONG_RUN_S = 3600.0  # runs estimated longer need --yes-long
SCHEDULER_TIMEOUT_S = 3.0


class UsageError(ValueError):
    """Bad input, the one exception of every refused setting or option: reported on one line naming
    the setting and the value (exit status 2 on the command line)."""


class UnknownSetting(UsageError, TypeError):
    """An unknown keyword: bad input, and a ``TypeError`` as Python's own for an unexpected keyword."""


class OneLineParser(argparse.ArgumentParser):
    """An ``argparse`` parser whose usage errors are one line (exit status 2), not the usage text,
    ending with the closest valid name to a mistyped option or choice ("did you mean") and the
    ``--help`` of the (sub)command that refused it."""

    def error(self, message: str):
        if "expected one argument" in message:
            message += "; write a negative value as --option=VALUE"
        help_of = self.prog
        choice = re.search(r"invalid choice: '([^']*)' \(choose from (.*)\)$", message)
        if choice:
            close = closest(choice.group(1), re.findall(r"'([^']*)'", choice.group(2)))
            if close:
                message += f"; did you mean {close!r}?"
                sub = self._subcommands().get(close)
                help_of = sub.prog if sub is not None else help_of
        self.exit(2, f"{self.prog}: error: {message} (see {help_of} --help)\n")

    def _subcommands(self) -> dict:
        """The parsers of this parser's subcommands, by name."""
        actions = [a for a in self._actions if isinstance(a, argparse._SubParsersAction)]
        return dict(actions[0].choices) if actions else {}

    def parse_args(self, args=None, namespace=None):
        """As ``argparse``'s, but an unknown option is refused by the subcommand it was given to, with
        the closest option of that subcommand."""
        parsed, extras = self.parse_known_args(args, namespace)
        if extras:
            parser = self
            while True:  # the innermost subcommand chosen
                subs = parser._subcommands() if isinstance(parser, OneLineParser) else {}
                chosen = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
                name = getattr(parsed, chosen[0].dest, None) if chosen else None
                if name not in subs:
                    break
                parser = subs[name]
            message = f"unrecognized arguments: {' '.join(extras)}"
            unknown = next((e.split("=", 1)[0] for e in extras if e.startswith("-")), None)
            close = closest(unknown, list(parser._option_string_actions)) if unknown else None
            parser.error(message + (f"; did you mean {close}?" if close else ""))
        return parsed


def closest(name: str, choices: list[str]) -> str | None:
    """The choice closest to a mistyped ``name`` (``difflib``'s ratio at least 0.6), or ``None``."""
    close = difflib.get_close_matches(name, [c for c in choices if c not in ("-h", "--help")], n=1)
    return close[0] if close else None


def available_memory() -> int | None:
    """Bytes of memory available to a new process: ``MemAvailable`` of ``/proc/meminfo`` (Linux),
    else the free physical pages (``os.sysconf``); ``None`` if neither is known."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return None


def _size(n_bytes: float) -> str:
    for unit in ("B", "kB", "MB", "GB", "TB"):
        if n_bytes < 1000 or unit == "TB":
            return f"{n_bytes:.3g} {unit}"
        n_bytes /= 1000
    raise AssertionError  # pragma: no cover


def _count(n: int) -> str:
    """An exact count up to ten digits, three significant digits beyond."""
    return str(n) if n < 10**10 else f"{n:.3g}"


def _duration(seconds: float) -> str:
    if seconds < 120:
        return f"{seconds:.2g} s"
    if seconds < 7200:
        return f"{seconds / 60:.2g} min"
    return f"{seconds / 3600:.3g} h"


def describe(cost) -> str:
    """One line: estimated steps, particles, memory and time."""
    return (f"estimated {_count(cost.steps)} steps, {_count(cost.particles)} particles, {_count(cost.nodes)} nodes, "
            f"{_size(cost.bytes)}, ~{_duration(cost.seconds)}")


def check_cost(cost, yes_long: bool = False, memory: int | None = None, flag: str = "--yes-long") -> None:
    """Refuse a run over ``MEMORY_SHARE`` of the available memory, or over ``LONG_RUN_S`` unless
    ``yes_long``. ``memory`` defaults to :func:`available_memory`; ``flag`` is how the caller asks
    for a long run (the option, or the Python keyword ``yes_long=True``)."""
    memory = available_memory() if memory is None else memory
    if memory is not None and cost.bytes > MEMORY_SHARE * memory:
        raise UsageError(f"the run needs about {_size(cost.bytes)} ({_count(cost.particles)} particles, "
                         f"{_count(cost.nodes)} nodes, {_count(cost.steps)} steps), "
                         f"over the limit of {_size(MEMORY_SHARE * memory)} "
                         f"({MEMORY_SHARE:.0%} of the available memory)")
    if cost.seconds > LONG_RUN_S and not yes_long:
        raise UsageError(f"{describe(cost)}: over {LONG_RUN_S / 3600:g} h; pass {flag} to run it")


def cap_jobs(jobs: int | None) -> int | None:
    """``jobs`` (>= 1) capped at the number of cores, with a one-line warning on stderr."""
    if jobs is None:
        return None
    if jobs < 1:
        raise UsageError(f"--jobs must be >= 1, got {jobs}")
    cores = os.cpu_count() or 1
    if jobs > cores:
        print(f"warning: --jobs {jobs} capped at the {cores} cores of this machine", file=sys.stderr)
        return cores
    return jobs


def check_scheduler(address: str | None, timeout: float = SCHEDULER_TIMEOUT_S) -> str | None:
    """A Dask scheduler address ``tcp://HOST:PORT`` that accepts a TCP connection within
    ``timeout`` seconds; returned unchanged."""
    if address is None:
        return None
    parts = urlsplit(address)
    try:
        port = parts.port
    except ValueError:
        port = None
    if parts.scheme != "tcp" or not parts.hostname or port is None:
        raise UsageError(f"--scheduler takes an address tcp://HOST:PORT, got {address!r}")
    try:
        socket.create_connection((parts.hostname, port), timeout=timeout).close()
    except OSError as err:
        raise UsageError(f"no Dask scheduler answers at {address} within {timeout:g} s: "
                         f"{err.strerror or err.__class__.__name__}") from None
    try:  # something answers: is it a Dask scheduler? (a handshake, same timeout)
        from dask.distributed import Client
    except ImportError:
        raise UsageError("--scheduler needs dask.distributed: pip install 'mpm-fem[dask]'") from None
    try:
        Client(address, timeout=f"{timeout}s").close()
    except Exception as err:  # noqa: BLE001 -- any failure of the handshake means "not a scheduler"
        raise UsageError(f"{address} answers but is not a Dask scheduler within {timeout:g} s "
                         f"({err.__class__.__name__})") from None
    return address


def exit_status(prog: str, command) -> int:
    """Call ``command()`` and turn its outcome into an exit status with at most one line on stderr:
    0 done, 1 run failed, 2 bad input (:class:`UsageError`), 130 interrupted (Ctrl-C)."""
    try:
        command()
    except UsageError as err:
        print(f"{prog}: error: {err}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"{prog}: interrupted", file=sys.stderr)
        return 130
    except (ArithmeticError, RuntimeError) as err:  # lost positivity (PositivityError), non-finite state
        print(f"{prog}: run failed: {err}", file=sys.stderr)
        return 1
    return 0
