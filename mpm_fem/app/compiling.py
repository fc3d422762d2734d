"""One line on stderr when numba starts compiling, so that a first run does not sit silent.

The kernels of :mod:`mpm_fem.fused` (and the FEM baselines' loops) are compiled on their first
call and cached on disk; a later run loads them in well under a second. numba announces a
compilation by its ``"numba:compile"`` event, which it sends only when the on-disk cache has no
entry for the function (a cache hit sends none), so a listener of that event knows, without a
guess, that the compiler runs. :func:`compile_notice` prints :data:`LINE` at the first such event
within its block; :func:`notice_once` does so for the rest of a worker process's life, once for all
the workers that share a flag.
"""

from __future__ import annotations

import sys
from contextlib import contextmanager

from numba.core import event

#: What a cold run prints before its first compiled call.
LINE = "compiling the kernels (first run with these settings, about a minute; cached for the next runs)"
#: numba's event sent when a function is compiled (not when it is loaded from the cache).
COMPILE_EVENT = "numba:compile"


class _Notice(event.Listener):
    """Print :data:`LINE` on the first compile event; ``shared`` (a ``multiprocessing.Value``)
    makes it once for every process holding it."""

    def __init__(self, stream=None, shared=None):
        self.stream, self.shared, self.printed = stream, shared, False

    def _first(self) -> bool:
        if self.printed:
            return False
        self.printed = True
        if self.shared is None:
            return True
        with self.shared.get_lock():
            first, self.shared.value = not self.shared.value, 1
        return first

    def on_start(self, ev) -> None:
        if self._first():
            stream = self.stream or sys.stderr
            stream.write(LINE + "\n")  # one write: whole beside other processes' lines
            stream.flush()

    def on_end(self, ev) -> None:
        pass


@contextmanager
def compile_notice(enabled: bool = True, stream=None):
    """Within the block, print :data:`LINE` on ``stream`` (stderr) when numba first compiles; nothing
    when every kernel comes from the cache or ``enabled`` is false."""
    if not enabled:
        yield
        return
    with event.install_listener(COMPILE_EVENT, _Notice(stream)):
        yield


def notice_once(shared) -> None:
    """For the rest of this process (a sweep's worker), print :data:`LINE` at numba's first compile
    unless another process holding the same flag ``shared`` (a ``multiprocessing.Value``) printed it."""
    event.register(COMPILE_EVENT, _Notice(None, shared))
