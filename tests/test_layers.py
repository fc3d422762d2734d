"""Layers import downwards only, and no import cycle exists (parsed with ``ast``, no code run).

The layers are the folders:

1. exact solutions: ``baselines/exact/`` (no project imports);
2. the MPM core and the fixed-mesh baselines: ``mpm_fem/bases/`` (the bases behind their contract,
   and their registry), ``mpm_fem/core/`` (grid, shape, particles, transfer,
   step, solve, models), ``mpm_fem/exact_stages/`` (the exact stages and their kernels),
   ``mpm_fem/fused/`` (the compiled step), ``mpm_fem/problems/`` (the problem set-ups), and
   ``baselines/`` (all but ``baselines/exact/``);
3. measurements: ``mpm_fem/measure/``;
4. the application: ``mpm_fem/app/``;
5. the studies: ``studies/``.

A module's layer is its folder's: a new module needs no entry here, a new folder does. A module may
import its own layer or a lower one. Imports inside functions count too: a lazy import is still a
dependency. Studies are found by name at run time (``importlib``), which is how the application
runs them without depending on them.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
#: folder (as a dotted package) -> layer; the longest matching folder decides.
FOLDERS = {
    "baselines.exact": 1,
    "baselines": 2,
    "mpm_fem.bases": 2,
    "mpm_fem.core": 2,
    "mpm_fem.exact_stages": 2,
    "mpm_fem.fused": 2,
    "mpm_fem.problems": 2,
    "mpm_fem.measure": 3,
    "mpm_fem.app": 4,
    "studies": 5,
}
#: modules that are not in a layer folder: the package's own ``__init__``, whose notebook entry
#: points (``mpm_fem.sod``) are the application's (``mpm_fem.app.api``).
TOP = {"mpm_fem": 4}
LAYERS = sorted(set(FOLDERS.values()))


def modules() -> dict[str, Path]:
    found = {}
    for package in ("mpm_fem", "baselines", "studies"):
        for path in sorted((ROOT / package).rglob("*.py")):
            parts = path.relative_to(ROOT).with_suffix("").parts
            found[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return found


def layer(module: str) -> int:
    """The layer of ``module``: that of the deepest folder it lies in (or its own ``TOP`` entry)."""
    if module in TOP:
        return TOP[module]
    found = [folder for folder in FOLDERS if module == folder or module.startswith(folder + ".")]
    if not found:
        raise KeyError(f"{module} has no layer: put it in a layer folder (or add its folder to FOLDERS)")
    return FOLDERS[max(found, key=len)]


def imports(module: str, path: Path, known) -> set[str]:
    """The project modules ``module`` imports (absolute or relative, at any depth of the code)."""
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = package.split(".")
            base = base[: len(base) - node.level + 1] if node.level else []
            root = ".".join(base + ([node.module] if node.module else []))
            names = [f"{root}.{a.name}" for a in node.names] + [root]
        else:
            continue
        for name in names:
            while name and name not in known:
                name = name.rpartition(".")[0]
            if name and name != module:
                out.add(name)
    return out


def graph() -> dict[str, set[str]]:
    known = modules()
    return {m: imports(m, p, known) for m, p in known.items()}


def test_every_module_has_a_layer():
    for m in modules():
        assert layer(m) in LAYERS, m
    with pytest.raises(KeyError, match="no layer"):
        layer("mpm_fem.new_module")
    assert layer("mpm_fem.app.new_module") == 4 and layer("baselines.exact.new") == 1


def test_no_module_imports_a_higher_layer():
    upward = [f"{a} (layer {layer(a)}) imports {b} (layer {layer(b)})" for a, bs in graph().items() for b in bs
              if layer(b) > layer(a)]
    assert not upward, "\n".join(upward)


def _cycles(g):
    """Pairs (a, b) on an import cycle: b imports a, directly or through others, and a imports b."""
    reach = {}

    def reachable(start):
        if start not in reach:
            seen, stack = set(), [start]
            while stack:
                for nxt in g.get(stack.pop(), ()):
                    if nxt not in seen:
                        seen.add(nxt)
                        stack.append(nxt)
            reach[start] = seen
        return reach[start]

    return sorted((a, b) for a, bs in g.items() for b in bs if a in reachable(b))


def test_no_import_cycle():
    cycles = [f"{a} -> {b} -> ... -> {a}" for a, b in _cycles(graph())]
    assert not cycles, "\n".join(cycles)


def test_the_check_finds_a_cycle_and_names_the_pair():
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [("a", "b"), ("b", "c"), ("c", "a")]
