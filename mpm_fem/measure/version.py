"""The version of the code that computes the numbers of the tables: a hash of its syntax trees.

The code that computes numbers is every ``.py`` file of the packages in :data:`PACKAGES` (the
model, the measurements, the claims, the application's sweep and table writing, the baselines
and the studies) but the modules of :data:`RENDERING`, which only draw or lay out tables already
written: the report (``REPORT.md``), its pages and the figures. The tests, the docs and the README
are outside the packages. Each file enters by its path and its syntax tree without docstrings
(:func:`ast.dump`), so comments, formatting and docstrings do not change the version, and any
other edit does; a file that does not parse enters by its bytes.

The studies stamp every table with :func:`code_version` (``"code"`` in the JSON beside it), the
sweeps key their case cache by it (:mod:`mpm_fem.app.sweep`), and E4 compares the stamps of the
tables with the version of the code that judges them (:mod:`mpm_fem.measure.claims.reproduce`).
The version is 12 hexadecimal digits of a SHA-256; it depends on the Python version only through
:func:`ast.dump`. No project imports.
"""

from __future__ import annotations

import ast
import hashlib
from functools import lru_cache
from pathlib import Path

#: The repository's root: the folder holding the packages.
ROOT = Path(__file__).resolve().parents[2]
#: The packages whose ``.py`` files compute the numbers of the tables.
PACKAGES = ("mpm_fem", "baselines", "studies")
#: Modules of those packages that only render tables already written (paths from the root).
RENDERING = ("mpm_fem/app/report.py", "mpm_fem/app/pages.py", "mpm_fem/app/plots.py")


def versioned_files(root: Path = ROOT) -> list[Path]:
    """The files the version is computed over, sorted by path: the ``.py`` files of
    :data:`PACKAGES` under ``root``, without :data:`RENDERING`."""
    root = Path(root)
    return [path for package in PACKAGES for path in sorted((root / package).rglob("*.py"))
            if path.relative_to(root).as_posix() not in RENDERING]


def _without_docstrings(tree: ast.AST) -> ast.AST:
    """``tree`` with the docstring (a leading string constant) of its module, classes and functions removed."""
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and node.body:
            first = node.body[0]
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant) \
                    and isinstance(first.value.value, str):
                node.body = node.body[1:]
    return tree


def file_text(path: Path) -> bytes:
    """What a file contributes to the version: its syntax tree without docstrings, or its bytes
    when it does not parse."""
    source = Path(path).read_bytes()
    try:
        return ast.dump(_without_docstrings(ast.parse(source))).encode()
    except (SyntaxError, ValueError):
        return source


def source_version(root: Path = ROOT) -> str:
    """12 hexadecimal digits of the SHA-256 of every versioned file's path and :func:`file_text`."""
    root = Path(root)
    digest = hashlib.sha256()
    for path in versioned_files(root):
        digest.update(path.relative_to(root).as_posix().encode() + b"\0")
        digest.update(file_text(path) + b"\0")
    return digest.hexdigest()[:12]


@lru_cache(maxsize=1)
def code_version() -> str:
    """The version of the code of this checkout (:func:`source_version` of :data:`ROOT`), computed once."""
    return source_version(ROOT)
