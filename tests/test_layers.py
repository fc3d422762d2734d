"""Layers import downwards only, and no import cycle exists (parsed with ``ast``, no code run).

The layers are the folders:

1. exact solutions: ``baselines/exact/`` (no project imports);
2. the MPM core and the fixed-mesh baselines, packages in this order (each imports only its own
   and those before it, so no cycle runs between them):

   a. ``mpm_fem/core/grid.py`` (the mesh every basis is defined on);
   b. ``mpm_fem/bases/`` (the bases behind their contract, and their registry) and
      ``mpm_fem/masses/`` (the grid masses behind their contract, and their registry: numpy and
      scipy only; the 1D and the 2D step read them);
   c. ``mpm_fem/core/`` (shape, particles, transfer, the numpy step, models);
   d. ``mpm_fem/exact_stages/`` (the exact stages and their kernels; the numpy step reaches them
      through the protocol ``core.step.ExactStages``) and ``baselines/`` (all but ``baselines/exact/``),
      which import the core only;
   e. ``mpm_fem/fused/`` (the compiled step);
   f. ``mpm_fem/run/`` (the time loop, choosing between the numpy and the compiled step);
   g. ``mpm_fem/problems/`` (the problem set-ups, which run through the time loop);
   h. ``mpm_fem/plane/`` (the 2D package: its grid, tensor bases, step, problems and runs);
3. measurements: ``mpm_fem/measure/``;
4. the application: ``mpm_fem/app/``;
5. the studies: ``studies/``.

A module's place is its folder's: a new module needs no entry here, a new folder does. A module may
import its own package, or one of a lower layer, or of its layer ranked before it. Imports inside
functions count too: a lazy import is still a dependency. Studies are found by name at run time
(``importlib``), which is how the application runs them without depending on them. Cycles are
looked for twice: between modules, and between packages (a package cycle runs through modules that
form no module cycle: ``core.solve -> fused.step -> core.step`` was one).
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
#: folder (as a dotted package) -> (layer, rank inside the layer); the longest matching folder decides.
FOLDERS = {
    "baselines.exact": (1, 0),
    "mpm_fem.core.grid": (2, 0),
    "mpm_fem.bases": (2, 1),
    "mpm_fem.core": (2, 2),
    "mpm_fem.exact_stages": (2, 3),
    "baselines": (2, 3),
    "mpm_fem.masses": (2, 1),
    "mpm_fem.fused": (2, 4),
    "mpm_fem.run": (2, 5),
    "mpm_fem.problems": (2, 6),
    "mpm_fem.plane": (2, 7),
    "mpm_fem.measure": (3, 0),
    "mpm_fem.app": (4, 0),
    "studies": (5, 0),
}
#: modules that are not in a layer folder: the package's own ``__init__``, whose notebook entry
#: points (``mpm_fem.sod``) are the application's (``mpm_fem.app.api``), above it.
TOP = {"mpm_fem": (4, 1)}
LAYERS = sorted({place[0] for place in FOLDERS.values()})


def modules() -> dict[str, Path]:
    found = {}
    for package in ("mpm_fem", "baselines", "studies"):
        for path in sorted((ROOT / package).rglob("*.py")):
            parts = path.relative_to(ROOT).with_suffix("").parts
            found[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return found


def package(module: str) -> str:
    """The layer folder ``module`` lies in: the deepest one (or the module itself if in ``TOP``)."""
    if module in TOP:
        return module
    found = [folder for folder in FOLDERS if module == folder or module.startswith(folder + ".")]
    if not found:
        raise KeyError(f"{module} has no layer: put it in a layer folder (or add its folder to FOLDERS)")
    return max(found, key=len)


def place(module: str) -> tuple[int, int]:
    """``(layer, rank)`` of ``module``'s folder: a module imports its own folder or a lower place."""
    folder = package(module)
    return TOP[folder] if folder in TOP else FOLDERS[folder]


def layer(module: str) -> int:
    """The layer of ``module``: that of the deepest folder it lies in (or its own ``TOP`` entry)."""
    return place(module)[0]


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


def upward(g: dict[str, set[str]]) -> list[str]:
    """The imports of ``g`` from one folder into another at the same or a higher place."""
    return [f"{a} {place(a)} imports {b} {place(b)}" for a, bs in sorted(g.items()) for b in sorted(bs)
            if package(a) != package(b) and place(b) >= place(a)]


def packages(g: dict[str, set[str]], folder=package) -> dict[str, set[str]]:
    """The import graph of the folders: ``p -> q`` where a module of ``p`` imports one of ``q``."""
    out: dict[str, set[str]] = {}
    for a, bs in g.items():
        out.setdefault(folder(a), set()).update(folder(b) for b in bs if folder(b) != folder(a))
    return out


def test_every_module_has_a_layer():
    for m in modules():
        assert layer(m) in LAYERS, m
    with pytest.raises(KeyError, match="no layer"):
        layer("mpm_fem.new_module")
    assert layer("mpm_fem.app.new_module") == 4 and layer("baselines.exact.new") == 1
    assert package("mpm_fem.core.models.euler") == "mpm_fem.core" and package("baselines.fem_euler") == "baselines"


def test_no_module_imports_a_higher_layer():
    higher = [f"{a} (layer {layer(a)}) imports {b} (layer {layer(b)})" for a, bs in graph().items() for b in bs
              if layer(b) > layer(a)]
    assert not higher, "\n".join(higher)


def test_layer_two_packages_import_in_their_order():
    """grid < bases, masses < core < exact_stages, baselines < fused < run < problems: no package of layer 2
    imports one ranked at or above it (nor does any folder of another layer)."""
    found = upward(graph())
    assert not found, "\n".join(found)
    order = sorted((p for p in FOLDERS if FOLDERS[p][0] == 2), key=FOLDERS.get)
    assert order[:4] == ["mpm_fem.core.grid", "mpm_fem.bases", "mpm_fem.masses", "mpm_fem.core"], order
    assert order[-4:] == ["mpm_fem.fused", "mpm_fem.run", "mpm_fem.problems", "mpm_fem.plane"], order


def test_the_order_check_finds_the_time_loop_in_the_core():
    """The cycle this test was extended for: the time loop in the core importing the compiled step,
    and the numpy step importing the exact stages."""
    found = upward({"mpm_fem.core.solve": {"mpm_fem.fused", "mpm_fem.core.step"},
                    "mpm_fem.core.step": {"mpm_fem.exact_stages"}, "mpm_fem.fused.step": {"mpm_fem.core.step"}})
    assert found == ["mpm_fem.core.solve (2, 2) imports mpm_fem.fused (2, 4)",
                     "mpm_fem.core.step (2, 2) imports mpm_fem.exact_stages (2, 3)"], found
    assert upward({"baselines.fem_euler": {"mpm_fem.exact_stages.stage"}}), "the same rank is no licence"


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


def test_no_import_cycle_between_packages():
    cycles = [f"{a} -> {b} -> ... -> {a}" for a, b in _cycles(packages(graph()))]
    assert not cycles, "\n".join(cycles)


def test_the_check_finds_a_cycle_and_names_the_pair():
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [("a", "b"), ("b", "c"), ("c", "a")]


def test_the_package_check_finds_a_cycle_no_module_is_on():
    """``p.a -> q.b -> p.c``: no module cycle, but the packages p and q import each other."""
    g = {"p.a": {"q.b"}, "q.b": {"p.c"}, "p.c": set()}
    assert _cycles(g) == []
    assert _cycles(packages(g, folder=lambda m: m.split(".")[0])) == [("p", "q"), ("q", "p")]
