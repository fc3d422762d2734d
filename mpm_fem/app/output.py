"""Run records: the settings hash, package versions, ``summary.json`` and ``particles.csv``.

Every file is written to a temporary name and renamed, so a record is either whole or absent. A
run's folder is written the same way (:func:`staged_dir`): into a fresh temporary folder beside
it, renamed into place when the run is done, so two runs never mix their files in one folder.
"""

from __future__ import annotations

import errno
import hashlib
import io
import json
import os
import platform
import shutil
import subprocess
import sys
import tempfile
from contextlib import contextmanager
from importlib import metadata
from pathlib import Path

import numpy as np

from mpm_fem.core.particles import Particles

#: the particle fields a run writes, in this column order
PARTICLE_COLUMNS = ("x", "volume", "mass", "velocity", "density", "energy", "pressure")

_UMASK = os.umask(0)
os.umask(_UMASK)

PACKAGES = ("mpm-fem", "numpy", "scipy", "scikit-fem", "meshio", "matplotlib", "numba")


def settings_hash(settings: dict, length: int = 10) -> str:
    """A short stable hash of a settings dictionary (keys sorted, floats as repr)."""
    text = json.dumps(settings, sort_keys=True, default=repr)
    return hashlib.sha256(text.encode()).hexdigest()[:length]


def cpu() -> str:
    """The processor: its model name (Linux) and the target numba's compiler takes for it, e.g.
    ``"Intel(R) Xeon(R) Processor; llvm target emeraldrapids"``. The record states it because the last
    digits of some tables depend on the processor the same code runs on."""
    name = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as info:
            name = next((line.split(":", 1)[1].strip() for line in info if line.startswith("model name")), name)
    except OSError:
        pass
    try:
        from llvmlite import binding

        return f"{name}; llvm target {binding.get_host_cpu_name()}"
    except (ImportError, RuntimeError):
        return name


def versions() -> dict[str, str]:
    """Python, the packages a result depends on, the processor (:func:`cpu`) and the git commit of the
    code if known."""
    out = {"python": platform.python_version(), "cpu": cpu()}
    for name in PACKAGES:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = "not installed"
    try:
        here = Path(__file__).resolve().parent
        commit = subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"], cwd=here, capture_output=True, text=True, timeout=5
        ).stdout.strip()
        if commit:
            out["git_commit"] = commit
    except (OSError, subprocess.SubprocessError):
        pass
    return out


def ensure_writable_dir(path: str | os.PathLike) -> Path:
    """Create ``path`` (and parents) and check that a file can be written in it."""
    path = Path(path)
    try:
        path.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=path):
            pass
    except OSError as err:
        raise PermissionError(f"cannot write to the output directory {str(path)!r}: {err.strerror or err}") from None
    return path


def check_run_dir(path: str | os.PathLike, overwrite: bool) -> Path:
    """``path`` may receive a run: it is not a file, it is empty or absent unless ``overwrite``,
    and its parent folder can be created and written. Raises ``PermissionError`` (cannot write)
    or ``FileExistsError`` (not empty)."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise PermissionError(f"cannot write to the output directory {str(path)!r}: it is a file")
    if path.is_dir() and any(path.iterdir()) and not overwrite:
        raise FileExistsError(f"the output directory {str(path)!r} is not empty; pass --overwrite to replace it whole")
    ensure_writable_dir(path.parent)
    return path


@contextmanager
def staged_dir(path: str | os.PathLike, overwrite: bool):
    """Yield a fresh temporary folder beside ``path``; when the block ends without error rename it
    to ``path``. With ``overwrite`` an existing ``path`` is replaced whole (moved aside, then
    deleted); without it a ``path`` that another run filled meanwhile raises ``FileExistsError``.
    If the block fails the temporary folder is removed. Of concurrent runs into one folder the
    last to finish wins, whole."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(dir=path.parent, prefix=f".{path.name}.tmp-"))
    try:
        yield tmp
        os.chmod(tmp, 0o777 & ~_UMASK)  # mkdtemp makes 0700; a run folder is a normal folder
        _publish(tmp, path, overwrite)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


def _publish(tmp: Path, path: Path, overwrite: bool, attempts: int = 10) -> None:
    """Rename ``tmp`` to ``path`` (an absent or empty ``path`` is replaced by rename(2) itself)."""
    for _ in range(attempts):
        try:
            os.rename(tmp, path)
            return
        except OSError as err:
            if not path.is_dir() or err.errno not in (errno.ENOTEMPTY, errno.EEXIST):
                raise
            if not overwrite:
                raise FileExistsError(f"the output directory {str(path)!r} was filled by another run meanwhile; "
                                      "pass --overwrite to replace it") from None
        old = Path(tempfile.mkdtemp(dir=path.parent, prefix=f".{path.name}.old-"))
        try:
            os.rename(path, old / "run")
        except FileNotFoundError:
            pass  # another run moved it away first
        finally:
            shutil.rmtree(old, ignore_errors=True)
    raise FileExistsError(f"the output directory {str(path)!r} kept being replaced by other runs")


def write_atomic(path: str | os.PathLike, text: str) -> None:
    """Write ``text`` to ``path`` via a temporary file and a rename."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.")
    try:
        with os.fdopen(fd, "w") as f:
            f.write(text)
        os.chmod(tmp, 0o666 & ~_UMASK)  # mkstemp makes 0600; a record is a normal file
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_json(path, data: dict) -> None:
    write_atomic(path, json.dumps(data, indent=2, sort_keys=False, default=_jsonable) + "\n")


def _jsonable(obj):
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    return repr(obj)


def particles_csv(particles: Particles, columns: dict[str, np.ndarray] | None = None) -> str:
    """Particle columns as CSV text, one row per particle, sorted by position. ``columns`` maps a
    header to an (n_p,) array and must hold ``"x"``; by default the whole particle state."""
    if columns is None:
        columns = {name: getattr(particles, name) for name in PARTICLE_COLUMNS}
    order = np.argsort(columns["x"], kind="stable")
    buffer = io.StringIO()
    np.savetxt(buffer, np.column_stack([np.asarray(v)[order] for v in columns.values()]), fmt="%.17g", delimiter=",",
               header=",".join(columns), comments="")
    return buffer.getvalue()


def replace_block(path: str | os.PathLike, name: str, text: str) -> None:
    """Put ``text`` between ``<!-- begin NAME ... -->`` and ``<!-- end NAME -->`` in the Markdown file
    ``path`` (the block is appended when the file has none): generated content in a typed page."""
    path = Path(path)
    begin, end = f"<!-- begin {name}", f"<!-- end {name} -->"
    page = path.read_text() if path.exists() else ""
    block = f"{begin}: generated, do not edit -->\n{text.rstrip()}\n{end}"
    if begin in page and end in page:
        head, rest = page.split(begin, 1)
        page = head + block + rest.split(end, 1)[1]
    else:
        page = page.rstrip() + "\n\n" + block + "\n"
    write_atomic(path, page)


@contextmanager
def tee_markdown(path: str | os.PathLike | None, name: str, header: str):
    """Print as usual; with a ``path``, also write what was printed, after ``header``, into its block
    ``name`` (:func:`replace_block`) when the body ends without an error."""
    if path is None:
        yield
        return
    buffer, stdout = io.StringIO(), sys.stdout

    class _Tee(io.TextIOBase):
        def write(self, s: str) -> int:
            buffer.write(s)
            return stdout.write(s)

        def flush(self) -> None:
            stdout.flush()

    sys.stdout = _Tee()
    try:
        yield
    finally:
        sys.stdout = stdout
    replace_block(path, name, header + "\n\n" + buffer.getvalue())
