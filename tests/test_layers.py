"""Layers import downwards only, and no import cycle exists (parsed with ``ast``, no code run).

1. exact solutions: ``baselines.exact`` (no project imports);
2. the MPM core and the fixed-mesh baselines: ``grid shape particles transfer step fused exact_kernels
   grid_kernels exact_stages models solve problems cases frame_chunks``, ``baselines`` (all but ``baselines.exact``);
3. measurements: ``errors quadrature projection regions timing claims source tables``;
4. the application: ``sweep study report output fields plots cli``;
5. the studies: ``studies``.

A module may import its own layer or a lower one. Imports inside functions count too: a lazy
import is still a dependency. Studies are found by name at run time (``importlib``), which is how
the application runs them without depending on them.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
LAYERS = {
    1: ("baselines.exact",),
    2: ("mpm_fem.grid", "mpm_fem.shape", "mpm_fem.particles", "mpm_fem.transfer", "mpm_fem.step",
        "mpm_fem.fused", "mpm_fem.exact_stages", "mpm_fem.exact_kernels", "mpm_fem.grid_kernels", "mpm_fem.models", "mpm_fem.solve", "mpm_fem.problems", "mpm_fem.cases",
        "mpm_fem.reconstruction", "mpm_fem.volume", "mpm_fem.xpic", "mpm_fem.norms", "mpm_fem.frame_chunks", "baselines", "mpm_fem"),
    3: ("mpm_fem.errors", "mpm_fem.quadrature", "mpm_fem.projection", "mpm_fem.regions", "mpm_fem.timing",
        "mpm_fem.claims", "mpm_fem.source", "mpm_fem.tables", "mpm_fem.shock_tube", "mpm_fem.decomposition"),
    4: ("mpm_fem.sweep", "mpm_fem.study", "mpm_fem.guard", "mpm_fem.report", "mpm_fem.pages", "mpm_fem.output", "mpm_fem.fields", "mpm_fem.plots",
        "mpm_fem.cli"),
    5: ("studies",),
}


def modules() -> dict[str, Path]:
    found = {}
    for package in ("mpm_fem", "baselines", "studies"):
        for path in sorted((ROOT / package).rglob("*.py")):
            parts = path.relative_to(ROOT).with_suffix("").parts
            found[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return found


#: Packages whose own ``__init__`` is listed, but whose modules must each be listed by name
#: (``baselines`` is a package entry: every fixed-mesh baseline is layer 2, ``baselines.exact`` layer 1).
ROOTS = ("mpm_fem",)


def layer(module: str) -> int:
    """The layer of ``module``: its own entry, or the entry of the package it lies in (not a root)."""
    found = [prefix for prefixes in LAYERS.values() for prefix in prefixes
             if module == prefix or (module.startswith(prefix + ".") and prefix not in ROOTS)]
    if not found:
        raise KeyError(f"{module} has no layer: add it to LAYERS")
    best = max(found, key=len)
    return next(n for n, prefixes in LAYERS.items() if best in prefixes)


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
