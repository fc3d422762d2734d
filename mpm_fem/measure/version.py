"""The version of the code that computes the numbers of the tables: a hash of its syntax trees.

The code that computes numbers is every ``.py`` file of the packages in :data:`PACKAGES` (the
model, the measurements, the claims, the application's sweep and table writing, the baselines
and the studies) but the modules of :data:`RENDERING`, which only draw or lay out tables already
written: the report (``REPORT.md``), its pages and the figures. The tests, the docs and the README
are outside the packages. Each file enters by its path and its syntax tree without docstrings
(:func:`ast.dump`), so comments, formatting and docstrings do not change the version, and any
other edit does; a file that does not parse enters by its bytes.

The studies stamp every table with :func:`code_version` (``"code"`` in the JSON beside it), and E4
compares the stamps of the tables with the version of the code that judges them
(:mod:`mpm_fem.measure.claims.reproduce`).

A case's cache key (:mod:`mpm_fem.app.sweep`) uses a narrower version, :func:`case_version`: the code
one case runs through. That is the model (:func:`model_files`: every versioned file but the studies,
the application layer, the verdicts and this module, none of which the model imports) and, of the
case function's own module, the top-level statements the function depends on (:func:`closure`). A
study's plan (which meshes, seeds and tiers) chooses cases but computes none, so changing a plan
leaves every finished case valid, while an edit of the model, of the case function or of a constant
it reads recomputes the cases.
The version is 12 hexadecimal digits of a SHA-256; it depends on the Python version only through
:func:`ast.dump`. Parsing every file takes about 3 CPU-s, once per process: each version computed is
remembered on disk (:func:`_remembered`, in the user's cache folder) under a SHA-256 of the bytes of
every versioned file, so a process whose files are unchanged reads it in milliseconds (the same
value: any changed byte computes it anew). No project imports.
"""

from __future__ import annotations

import ast
import hashlib
import json
import os
import sys
import tempfile
from functools import lru_cache
from pathlib import Path

#: The repository's root: the folder holding the packages.
ROOT = Path(__file__).resolve().parents[2]
#: The packages whose ``.py`` files compute the numbers of the tables.
PACKAGES = ("mpm_fem", "baselines", "studies")
#: Modules of those packages that only render tables already written (paths from the root).
RENDERING = ("mpm_fem/app/report.py", "mpm_fem/app/paper.py", "mpm_fem/app/markdown.py", "mpm_fem/app/pages.py",
             "mpm_fem/app/plots.py", "mpm_fem/app/discussion.py")


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
    return _source_text(Path(path).read_bytes())


@lru_cache(maxsize=None)
def _source_text(source: bytes) -> bytes:
    """:func:`file_text` of a file holding ``source``, parsed once per content (the code's version and
    the cases' versions read the same files)."""
    try:
        return ast.dump(_without_docstrings(ast.parse(source))).encode()
    except (SyntaxError, ValueError):
        return source


#: Where computed versions are remembered (:func:`_remembered`); ``MPM_FEM_VERSION_CACHE`` overrides it.
VERSION_CACHE = Path(os.environ.get("MPM_FEM_VERSION_CACHE")
                     or Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "mpm-fem" / "versions.json")
_REMEMBERED = 256  # entries kept in VERSION_CACHE, the newest


def _bytes_digest(root: Path) -> str:
    """SHA-256 of the path and bytes of every versioned file under ``root`` (and of the Python version,
    which :func:`ast.dump` depends on): equal digests, equal versions."""
    digest = hashlib.sha256(sys.version.encode() + b"\0")
    for path in versioned_files(root):
        digest.update(path.relative_to(root).as_posix().encode() + b"\0" + path.read_bytes() + b"\0")
    return digest.hexdigest()


def _remembered(key: str, root: Path, compute) -> str:
    """``compute()``, remembered in :data:`VERSION_CACHE` under ``key`` and the bytes of the versioned
    files (:func:`_bytes_digest`). A cache that cannot be read or written is computed around."""
    full = f"{key}\0{_bytes_digest(root)}"
    try:
        memo = json.loads(VERSION_CACHE.read_text())
    except (OSError, ValueError):
        memo = {}
    if not isinstance(memo, dict):
        memo = {}
    if isinstance(memo.get(full), str):
        return memo[full]
    value = compute()
    memo = {k: v for k, v in list(memo.items())[-(_REMEMBERED - 1):] if k != full} | {full: value}
    try:
        VERSION_CACHE.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile("w", dir=VERSION_CACHE.parent, delete=False, suffix=".tmp") as out:
            json.dump(memo, out)
        os.replace(out.name, VERSION_CACHE)
    except OSError:
        pass
    return value


def source_version(root: Path = ROOT) -> str:
    """12 hexadecimal digits of the SHA-256 of every versioned file's path and :func:`file_text`
    (remembered: :func:`_remembered`)."""
    root = Path(root).resolve()
    return _remembered(f"source\0{root}", root, lambda: _source_version(root))


def _source_version(root: Path) -> str:
    digest = hashlib.sha256()
    for path in versioned_files(root):
        digest.update(path.relative_to(root).as_posix().encode() + b"\0")
        digest.update(file_text(path) + b"\0")
    return digest.hexdigest()[:12]


#: What a case cannot run through (paths from the root; a folder ends with "/"): the studies' plans
#: and tables, the application layer, the verdicts, the tables' declarations and their reader (which
#: name and read columns, computing none) and this module. The model imports none of them
#: (tests/test_layers.py); the case function's own module enters by its :func:`closure`.
OUTSIDE_THE_MODEL = ("studies/", "mpm_fem/app/", "mpm_fem/measure/claims/", "mpm_fem/measure/schema.py",
                     "mpm_fem/measure/tables.py", "mpm_fem/measure/version.py")


def model_files(root: Path = ROOT) -> list[Path]:
    """The versioned files a case can run through: :func:`versioned_files` but :data:`OUTSIDE_THE_MODEL`."""
    root = Path(root)
    return [p for p in versioned_files(root) if not p.relative_to(root).as_posix().startswith(OUTSIDE_THE_MODEL)]


#: The test of a module's ``if __name__ == "__main__":`` block, as :func:`ast.dump` writes it.
_MAIN_TEST = ast.dump(ast.parse('__name__ == "__main__"').body[0].value)
_DEFINITIONS = (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)
_BINDINGS = (ast.Assign, ast.AnnAssign, ast.AugAssign, ast.Import, ast.ImportFrom)


def _names(node: ast.AST) -> set[str]:
    return {n.id for n in ast.walk(node) if isinstance(n, ast.Name)}


def _target_names(target: ast.AST) -> set[str]:
    """The names an assignment target binds or changes: ``x``, ``a, b``, and the ``x`` of ``x[k]`` or ``x.y``."""
    while isinstance(target, (ast.Subscript, ast.Attribute, ast.Starred)):
        target = target.value
    if isinstance(target, (ast.Tuple, ast.List)):
        return set().union(*map(_target_names, target.elts))
    return {target.id} if isinstance(target, ast.Name) else set()


def _binds(stmt: ast.stmt) -> set[str]:
    """The module-level names ``stmt`` binds or may change. A statement other than a definition, an
    assignment or an import (a call, a loop, a ``try``) may change any name it mentions; the
    ``if __name__ == "__main__":`` block changes none (it does not run when a worker imports the module)."""
    if isinstance(stmt, _DEFINITIONS):
        return {stmt.name}
    if isinstance(stmt, (ast.Import, ast.ImportFrom)):
        return {(a.asname or a.name).split(".")[0] for a in stmt.names}
    if isinstance(stmt, ast.Assign):
        return set().union(*map(_target_names, stmt.targets))
    if isinstance(stmt, (ast.AnnAssign, ast.AugAssign)):
        return _target_names(stmt.target)
    if isinstance(stmt, ast.If) and ast.dump(stmt.test) == _MAIN_TEST:
        return set()
    return _names(stmt)


def closure(tree: ast.Module, name: str) -> list[ast.stmt]:
    """The top-level statements of ``tree`` that the top-level definition ``name`` depends on, in the
    module's order: ``name``'s own, then every statement binding or changing a name that an included
    statement mentions, to a fixed point. Over-inclusive (a name counts wherever it appears), so a
    change the function can see is never left out; a name reached only through ``globals()`` or
    ``getattr(module, ...)``, or changed by a function called at import time, would be; the studies'
    case functions use none of these."""
    needed, included = {name}, [False] * len(tree.body)
    changed = True
    while changed:
        changed = False
        for k, stmt in enumerate(tree.body):
            if not included[k] and _binds(stmt) & needed:
                included[k], changed = True, True
                needed |= _names(stmt)
    return [stmt for k, stmt in enumerate(tree.body) if included[k]]


@lru_cache(maxsize=None)
def _model_version(root: Path) -> bytes:
    digest = hashlib.sha256()
    for path in model_files(root):
        digest.update(path.relative_to(root).as_posix().encode() + b"\0" + file_text(path) + b"\0")
    return digest.digest()


def _module_file(root: Path, module: str | None, level: int, here: Path) -> Path | None:
    """The file of a project module named in an import (relative to ``here`` when ``level`` > 0), or
    ``None`` for a module outside the project."""
    base = here.parent
    for _ in range(level - 1):
        base = base.parent
    parts = (module or "").split(".") if module else []
    folder = (base if level else root).joinpath(*parts)
    for candidate in (folder.with_suffix(".py") if parts else None, folder / "__init__.py"):
        if candidate is not None and candidate.is_file():
            return candidate
    return None


def _outside_the_model(root: Path, path: Path) -> bool:
    return path.is_relative_to(root) and path.relative_to(root).as_posix().startswith(OUTSIDE_THE_MODEL)


def _closure_texts(root: Path, path: Path, name: str, seen: set) -> list[bytes]:
    """What the definition ``name`` of the file ``path`` contributes to a case version: its
    :func:`closure`, and, for every name that closure imports from a module outside the model (another
    study, the verdicts), that name's closure there (a whole module when the name is a module)."""
    if (path, name) in seen:
        return []
    seen.add((path, name))
    label = path.relative_to(root).as_posix() if path.is_relative_to(root) else path.name
    statements = closure(_without_docstrings(ast.parse(path.read_bytes())), name)
    if not statements:
        raise ValueError(f"{label} defines no top-level {name!r}")
    texts = [f"{label}\0{name}".encode()] + [ast.dump(stmt).encode() for stmt in statements]
    needed = set().union(*map(_names, statements))
    for stmt in statements:
        if isinstance(stmt, ast.ImportFrom):
            source = _module_file(root, stmt.module, stmt.level, path)
            for alias in stmt.names if source is not None and _outside_the_model(root, source) else ():
                if (alias.asname or alias.name) not in needed:
                    continue
                submodule = _module_file(root, alias.name, 1, source) if source.name == "__init__.py" else None
                texts += [file_text(submodule)] if submodule is not None and submodule != source \
                    else _closure_texts(root, source, alias.name, seen)
        elif isinstance(stmt, ast.Import):
            for alias in stmt.names:
                source = _module_file(root, alias.name, 0, path)
                if source is not None and _outside_the_model(root, source):
                    texts.append(file_text(source))
    return texts


def case_source_version(path: Path, qualname: str, root: Path = ROOT) -> str:
    """12 hexadecimal digits of the SHA-256 of the model (:func:`model_files` under ``root``) and of
    what the definition ``qualname`` (its first dotted part) of the file ``path`` depends on outside
    the model (:func:`_closure_texts`)."""
    root, path = Path(root).resolve(), Path(path).resolve()
    return _remembered(f"case\0{root}\0{path}\0{qualname}", root, lambda: _case_source_version(path, qualname, root))


def _case_source_version(path: Path, qualname: str, root: Path) -> str:
    digest = hashlib.sha256(_model_version(root))
    for text in _closure_texts(root, path, qualname.split(".")[0], set()):
        digest.update(text + b"\0")
    return digest.hexdigest()[:12]


@lru_cache(maxsize=None)
def case_version(module_file: str, qualname: str) -> str:
    """The version of the code a case of the function ``qualname`` of ``module_file`` runs through
    (:func:`case_source_version` under :data:`ROOT`), computed once per function."""
    return case_source_version(Path(module_file), qualname)


@lru_cache(maxsize=1)
def code_version() -> str:
    """The version of the code of this checkout (:func:`source_version` of :data:`ROOT`), computed once."""
    return source_version(ROOT)
