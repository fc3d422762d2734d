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
one case runs through, found by reading the imports (:func:`case_files`). Of the case function's own
module, and of each module outside the model it reads a name from (another study, the verdicts, the
application layer: :data:`OUTSIDE_THE_MODEL`), only the top-level statements the function depends
on enter (:func:`closure`); of the model (:func:`model_files`), every file those statements import,
then every file those files import, to a fixed point: ``import m`` and ``from m import a`` at the top
or inside a function, relative imports, the ``__init__.py`` of every package on the way (so the
registries, which their packages' ``__init__.py`` fill, bring every basis and transfer: a case names
them by a string), and ``importlib.import_module`` / ``__import__`` calls, a constant name as the
module and an f-string's head (``f"mpm_fem.problems.{problem}"``) as every module it can start.
A module's lazy ``__getattr__`` (PEP 562: the notebook entry points and the 2D package of
``mpm_fem/__init__.py``) is not followed, nor a ``package.module:Name`` given at run time (the
extensions' loader): it names a module outside the packages, whose source's hash the method study
puts in its cases' settings.
So a study's plan (which meshes, seeds and tiers) chooses cases but computes none, and a package no
case imports (a 2D package, a new baseline) is in no case's version: changing either leaves every
finished case valid, while an edit of a model file a case imports, of the case function or of a
constant it reads recomputes the cases.
The version is 12 hexadecimal digits of a SHA-256; it depends on the Python version only through
:func:`ast.dump`. Parsing the files takes a few CPU-s, once per process: each version computed is
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
             "mpm_fem/app/plots.py", "mpm_fem/app/discussion.py", "mpm_fem/app/paper_plane.py",
             "mpm_fem/app/paper_findings.py", "mpm_fem/app/paper_abstract.py", "mpm_fem/app/paper_method.py",
             "mpm_fem/app/paper_results.py", "mpm_fem/app/paper_discussion.py")


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
#: (tests/test_layers.py); the case function's own module enters by its :func:`closure`. The root
#: package's ``mpm_fem/__init__.py`` is the application's front door (the notebook entry points and the
#: 2D entry points, loaded on first use) and computes nothing, so it is outside too.
OUTSIDE_THE_MODEL = ("studies/", "mpm_fem/app/", "mpm_fem/measure/claims/", "mpm_fem/measure/schema.py",
                     "mpm_fem/measure/tables.py", "mpm_fem/measure/version.py", "mpm_fem/__init__.py")


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


def _module_parts(root: Path, path: Path) -> tuple[str, ...]:
    """The dotted name of the module in ``path``, as parts (a package's ``__init__.py`` names the
    package); ``()`` for a file outside ``root``."""
    if not path.is_relative_to(root):
        return ()
    parts = path.relative_to(root).with_suffix("").parts
    return parts[:-1] if parts[-1] == "__init__" else parts


def _file_of(root: Path, parts: tuple[str, ...]) -> Path | None:
    """The file of the project module ``parts`` (``a/b.py`` or ``a/b/__init__.py``), ``None`` for one
    outside :data:`PACKAGES`."""
    if not parts or parts[0] not in PACKAGES:
        return None
    folder = root.joinpath(*parts)
    for candidate in (folder.with_suffix(".py"), folder / "__init__.py"):
        if candidate.is_file():
            return candidate
    return None


def _packages_of(root: Path, parts: tuple[str, ...]) -> list[Path]:
    """The ``__init__.py`` files that importing the module ``parts`` runs first, outermost first."""
    return [f for k in range(1, len(parts)) if (f := _file_of(root, parts[:k])) is not None]


#: The calls that import a module named by a string at run time: ``importlib.import_module(name)``,
#: ``import_module(name)`` and ``__import__(name)``.
_DYNAMIC = ("import_module", "__import__")


def _dynamic_name(node: ast.AST) -> ast.AST | None:
    """The argument naming the module of a call in :data:`_DYNAMIC`; ``None`` for any other node."""
    if not (isinstance(node, ast.Call) and node.args):
        return None
    func = node.func
    called = func.attr if isinstance(func, ast.Attribute) else func.id if isinstance(func, ast.Name) else ""
    return node.args[0] if called in _DYNAMIC else None


def dynamic_modules(root: Path, argument: ast.AST) -> list[tuple[str, ...]] | None:
    """The modules a dynamic import whose name is ``argument`` can load, as dotted parts: the one a
    constant names; every project module whose dotted name starts with an f-string's constant head
    (``f"mpm_fem.problems.{problem}"``: every module of that package); ``None`` when the source does
    not write the name (a ``package.module:Name`` given at run time, :mod:`mpm_fem.bases.loader`)."""
    if isinstance(argument, ast.Constant) and isinstance(argument.value, str):
        return [tuple(argument.value.split("."))]
    head = ""
    if isinstance(argument, ast.JoinedStr):
        for value in argument.values:
            if not (isinstance(value, ast.Constant) and isinstance(value.value, str)):
                break
            head += value.value
    if not head or head.split(".")[0] not in PACKAGES:
        return None
    found = {_module_parts(root, f) for package in PACKAGES for f in (root / package).rglob("*.py")}
    return sorted(parts for parts in found if ".".join(parts).startswith(head))


#: One import a statement makes: the module's dotted name as parts and, for ``from m import a as b``,
#: the pairs (imported name, bound name); ``None`` for ``import m`` and a dynamic import.
_Request = tuple[tuple[str, ...], tuple[tuple[str, str], ...] | None]


def _node_requests(root: Path, here: Path, node: ast.AST) -> list[_Request]:
    """The imports ``node`` itself makes (not those of the nodes inside it), relative ones resolved
    against the file ``here``."""
    if isinstance(node, ast.Import):
        return [(tuple(a.name.split(".")), None) for a in node.names]
    if isinstance(node, ast.ImportFrom):
        package = _module_parts(root, here)
        if here.name != "__init__.py":
            package = package[:-1]
        if node.level and node.level - 1 > len(package):
            return []
        base = package[:len(package) - node.level + 1] if node.level else ()
        parts = base + (tuple(node.module.split(".")) if node.module else ())
        return [(parts, tuple((a.name, a.asname or a.name) for a in node.names))]
    argument = _dynamic_name(node)
    return [(parts, None) for parts in dynamic_modules(root, argument) or ()] if argument is not None else []


def _lazy(stmt: ast.stmt) -> bool:
    """Whether ``stmt`` is a module's ``__getattr__`` (PEP 562): what it imports loads on the first
    access of an attribute the module lacks (the package's notebook entry points and its 2D package,
    ``mpm_fem/__init__.py``), not when the module is imported."""
    return isinstance(stmt, (ast.FunctionDef, ast.AsyncFunctionDef)) and stmt.name == "__getattr__"


@lru_cache(maxsize=None)
def _file_requests(root: Path, path: Path, source: bytes) -> tuple[_Request, ...]:
    """Every import anywhere in the file ``path`` holding ``source`` (in its functions too, and the
    dynamic imports :func:`dynamic_modules` can name) but in its lazy ``__getattr__`` (:func:`_lazy`);
    none when it does not parse."""
    try:
        tree = ast.parse(source)
    except (SyntaxError, ValueError):
        return ()
    return tuple(r for stmt in tree.body if not _lazy(stmt) for node in ast.walk(stmt)
                 for r in _node_requests(root, path, node))


def _request_files(root: Path, request: _Request) -> list[Path]:
    """The project files an import runs: the packages' ``__init__.py`` files, the module, and, for
    ``from package import name``, the submodule ``name`` when there is one."""
    parts, names = request
    files = _packages_of(root, parts) + [f for f in [_file_of(root, parts)] if f is not None]
    for name, _ in names or ():
        files += [f for f in [_file_of(root, parts + (name,))] if f is not None]
    return files


def _import_closure(root: Path, seeds: set[Path], model: frozenset[Path]) -> list[Path]:
    """The files of ``model`` that importing the files ``seeds`` runs, ``seeds`` of the model included,
    sorted: the transitive closure of every import in them (:func:`_file_requests`) within ``model``.
    The model imports nothing outside it but in the lazy ``__getattr__`` of ``mpm_fem/__init__.py``
    (the notebook entry points load the application on first use), which is not followed
    (tests/test_version.py)."""
    done, todo = set(), [s for s in seeds if s in model]
    while todo:
        path = todo.pop()
        if path in done:
            continue
        done.add(path)
        for request in _file_requests(root, path, path.read_bytes()):
            todo += [f for f in _request_files(root, request) if f in model and f not in done]
    return sorted(done)


@lru_cache(maxsize=None)
def _tree(source: bytes) -> ast.Module:
    """The syntax tree of ``source`` without docstrings, parsed once per content (read, never changed)."""
    return _without_docstrings(ast.parse(source))


def _closure_texts(root: Path, path: Path, name: str | None, model: frozenset[Path], seen: set,
                   seeds: set[Path]) -> list[bytes]:
    """What the definition ``name`` of the file ``path`` (the whole file for ``None``) contributes to a
    case version outside the model: its :func:`closure`, and, for every name that closure imports
    from a module outside the model (another study, the verdicts), that name's closure there; a whole
    module for ``import m``, a submodule or a dynamic import. The model files the statements import
    (at the top or in a function) and their packages' ``__init__.py`` are added to ``seeds``; the
    ``__init__.py`` of a package outside the model enters by the names read from it only."""
    if (path, name) in seen:
        return []
    seen.add((path, name))
    if path in model:
        seeds.add(path)
    label = path.relative_to(root).as_posix() if path.is_relative_to(root) else path.name
    tree = _tree(path.read_bytes())
    if name is None:
        statements, texts = tree.body, [f"{label}\0".encode() + file_text(path)]
    else:
        statements = closure(tree, name)
        if not statements:
            raise ValueError(f"{label} defines no top-level {name!r}")
        texts = [f"{label}\0{name}".encode()] + [ast.dump(stmt).encode() for stmt in statements]
    needed = set().union(*map(_names, statements))
    for stmt in statements:
        for node in ast.walk(stmt):
            for parts, names in _node_requests(root, path, node):
                seeds.update(_packages_of(root, parts))
                source = _file_of(root, parts)
                if source is None:
                    continue
                seeds.add(source)
                if names is None and source not in model:
                    texts += _closure_texts(root, source, None, model, seen, seeds)
                for imported, bound in names or ():
                    submodule = _file_of(root, parts + (imported,)) if source.name == "__init__.py" else None
                    if submodule is not None:
                        seeds.add(submodule)
                        if submodule not in model:
                            texts += _closure_texts(root, submodule, None, model, seen, seeds)
                    elif source not in model and (node is not stmt or bound in needed):  # nested: all used
                        texts += _closure_texts(root, source, None if imported == "*" else imported, model,
                                                seen, seeds)
    return texts


def _case_parts(path: Path, name: str, root: Path) -> tuple[list[Path], list[bytes]]:
    """The model files a case of ``name`` in ``path`` runs (:func:`_import_closure`) and the texts of
    what it reads outside the model (:func:`_closure_texts`)."""
    model, seeds = frozenset(model_files(root)), set()
    texts = _closure_texts(root, path, name, model, set(), seeds)
    return _import_closure(root, seeds, model), texts


def case_files(path: Path, qualname: str, root: Path = ROOT) -> list[Path]:
    """The files of the model that a case of the definition ``qualname`` (its first dotted part) of
    the file ``path`` runs through, sorted by path (:func:`_import_closure`)."""
    root, path = Path(root).resolve(), Path(path).resolve()
    return _case_parts(path, qualname.split(".")[0], root)[0]


def case_source_version(path: Path, qualname: str, root: Path = ROOT) -> str:
    """12 hexadecimal digits of the SHA-256 of the model files a case of the definition ``qualname``
    (its first dotted part) of the file ``path`` runs through (:func:`case_files` under ``root``: the
    path and :func:`file_text` of each) and of what it reads outside the model (:func:`_closure_texts`)."""
    root, path = Path(root).resolve(), Path(path).resolve()
    return _remembered(f"case\0{root}\0{path}\0{qualname}", root, lambda: _case_source_version(path, qualname, root))


def _case_source_version(path: Path, qualname: str, root: Path) -> str:
    files, texts = _case_parts(path, qualname.split(".")[0], root)
    digest = hashlib.sha256()
    for file in files:
        digest.update(file.relative_to(root).as_posix().encode() + b"\0" + file_text(file) + b"\0")
    digest.update(b"\0")
    for text in texts:
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
