"""Run records: the settings hash, package versions, ``summary.json`` and ``particles.csv``.

Every file is written to a temporary name and renamed, so a record is either whole or absent.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
import platform
import subprocess
import tempfile
from importlib import metadata
from pathlib import Path

import numpy as np

from .particles import Particles

_UMASK = os.umask(0)
os.umask(_UMASK)

PACKAGES = ("mpm-fem", "numpy", "scipy", "scikit-fem", "meshio", "matplotlib")


def settings_hash(settings: dict, length: int = 10) -> str:
    """A short stable hash of a settings dictionary (keys sorted, floats as repr)."""
    text = json.dumps(settings, sort_keys=True, default=repr)
    return hashlib.sha256(text.encode()).hexdigest()[:length]


def versions() -> dict[str, str]:
    """Python, the packages a result depends on, and the git commit of the code if known."""
    out = {"python": platform.python_version()}
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


def particles_csv(particles: Particles, extra: dict[str, np.ndarray] | None = None) -> str:
    """The particle state as CSV text, one row per particle, sorted by position."""
    order = np.argsort(particles.x, kind="stable")
    cols = {name: getattr(particles, name)[order] for name in ("x", "volume", "mass", "velocity", "density", "energy", "pressure")}
    for name, value in (extra or {}).items():
        cols[name] = np.asarray(value)[order]
    buffer = io.StringIO()
    np.savetxt(buffer, np.column_stack(list(cols.values())), fmt="%.17g", delimiter=",", header=",".join(cols), comments="")
    return buffer.getvalue()
