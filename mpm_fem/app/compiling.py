"""One line on stderr when numba starts compiling, so that a first run does not sit silent.

The kernels of :mod:`mpm_fem.fused` (and the FEM baselines' loops) are compiled on their first
call and cached on disk; a later run loads them in well under a second. numba announces a
compilation by its ``"numba:compile"`` event, which it sends only when the on-disk cache has no
entry for the function (a cache hit sends none), so a listener of that event knows, without a
guess, that the compiler runs. :func:`compile_notice` prints :data:`LINE` at the first such event
within its block; :func:`notice_once` does so for the rest of a worker process's life, once for all
the workers that share a flag.

What compiling costs before a run (:mod:`mpm_fem.app.estimate` adds it to a study's estimate): a
*variant* is one cached numba function, named ``"SOURCE::STEM"`` (``SOURCE`` its file relative to the
project's root, ``STEM`` numba's cache name ``module.qualname`` without the line number, ``{digest}``
in place of :data:`mpm_fem.fused.compiler.DIGEST`). numba keeps a variant in its cache folder as an
index file ``STEM-LINE.pyXY.nbi`` holding numba's version and a stamp of the source file (in numba
0.68, the sha256 of its bytes); :func:`cached` reads that index without compiling or importing the
variant, and :func:`uncached_seconds` sums the measured compile seconds
(:mod:`mpm_fem.app.compile_times`) of the variants whose index is missing or stale.
"""

from __future__ import annotations

import hashlib
import pickle
import sys
from contextlib import contextmanager
from pathlib import Path

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


#: The folder the project's sources lie in (the parent of the ``mpm_fem`` package): variants' sources are named from it.
ROOT = Path(__file__).resolve().parents[2]


def cache_folder(source: Path) -> Path:
    """numba's cache folder of the functions of ``source``: under ``NUMBA_CACHE_DIR`` numba's own sub-path
    for the file, else ``__pycache__`` beside it. numba's settings are read again from the environment
    first, as numba does before each compile."""
    from numba.core import config
    from numba.core.caching import _CacheLocator

    config.reload_config()
    if config.CACHE_DIR:
        return Path(config.CACHE_DIR) / _CacheLocator.get_suitable_cache_subpath(str(source))
    return Path(source).parent / "__pycache__"


def _digest() -> str:
    from mpm_fem.fused.compiler import DIGEST

    return DIGEST


def _stamps(source: Path) -> tuple:
    """The stamps numba may have written for ``source``: the sha256 of its bytes (numba >= 0.61) or its
    ``(mtime, size)`` (older)."""
    stat = source.stat()
    return hashlib.sha256(source.read_bytes()).digest(), (stat.st_mtime, stat.st_size)


def cached(variant: str) -> bool:
    """Whether numba's cache holds ``variant`` (``"SOURCE::STEM"``, module docstring) for the source as it
    is now and this numba: an index file of its name with this numba's version and the source's stamp."""
    import numba

    source_name, _, stem = variant.partition("::")
    source = ROOT / source_name
    if not source.is_file():
        return False
    stem = stem.replace("{digest}", _digest())
    tag = f".py{sys.version_info[0]}{sys.version_info[1]}{getattr(sys, 'abiflags', '')}.nbi"
    stamps = _stamps(source)
    for index in cache_folder(source).glob(f"{stem}-*{tag}"):
        if not index.name[len(stem) + 1:-len(tag)].isdigit():
            continue  # another variant whose name starts with this one's
        try:
            with open(index, "rb") as f:
                if pickle.load(f) != numba.__version__:
                    continue
                stamp = pickle.loads(f.read())[0]
        except (OSError, pickle.UnpicklingError, EOFError, ValueError, IndexError, TypeError):
            continue
        if stamp in stamps:
            return True
    return False


def uncached_seconds(variants) -> float:
    """The measured compile CPU seconds (:data:`mpm_fem.app.compile_times.SECONDS`) of the ``variants`` that
    numba's cache lacks (:func:`cached`), each counted once."""
    from mpm_fem.app.compile_times import SECONDS

    return sum(SECONDS.get(v, 0.0) for v in set(variants) if not cached(v))


#: Two kernel groups share a compile when the variants both run through and numba's cache lacks cost at
#: least this many CPU seconds to compile (:data:`mpm_fem.app.compile_times.SECONDS`): below it, a second
#: worker compiling them again costs less than holding its group back.
SHARED_S = 1.0


def families(groups, table=None, seconds=None, is_cached=None) -> dict:
    """Each kernel group of ``groups`` (tuples, :func:`mpm_fem.app.sweep.kernel_group`) -> its *compile
    family*, a representative group: two groups are in one family when the variants they both run through
    (``table``: group joined by ``|`` -> its variants, default :data:`mpm_fem.app.compile_times.GROUPS`)
    and ``is_cached`` says the cache lacks (default :func:`cached`) cost :data:`SHARED_S` or more of
    ``seconds`` (default :data:`~mpm_fem.app.compile_times.SECONDS`), and a family holds every group
    joined to it through others. A group the table does not hold, or one that shares no such compile, is
    its own family; with every variant cached each group is. The pool holds a family's other tasks back
    while one of them may compile (:func:`mpm_fem.app.sweep._next_task`)."""
    if table is None or seconds is None:
        from mpm_fem.app.compile_times import GROUPS, SECONDS

        table, seconds = GROUPS if table is None else table, SECONDS if seconds is None else seconds
    is_cached = cached if is_cached is None else is_cached
    groups = sorted(set(groups))
    variants = {group: set(table.get("|".join(group), ())) for group in groups}
    lacked = {v for v in set().union(*variants.values()) if not is_cached(v)}  # each variant looked up once
    missing = {group: variants[group] & lacked for group in groups}
    parent = {group: group for group in groups}

    def root(group):
        while parent[group] != group:
            parent[group] = parent[parent[group]]
            group = parent[group]
        return group

    for i, a in enumerate(groups):
        for b in groups[i + 1:]:
            if sum(seconds.get(v, 0.0) for v in missing[a] & missing[b]) >= SHARED_S:
                parent[max(root(a), root(b))] = min(root(a), root(b))
    return {group: root(group) for group in groups}
