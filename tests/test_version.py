"""The version of the code that computes numbers (mpm_fem/measure/version.py): what changes it and
what does not, on a copy of the packages in a temporary folder."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from mpm_fem.app import sweep
from mpm_fem.measure import version
from mpm_fem.measure.version import PACKAGES, RENDERING, ROOT, source_version, versioned_files


@pytest.fixture
def tree(tmp_path) -> Path:
    for package in PACKAGES:
        shutil.copytree(ROOT / package, tmp_path / package, ignore=shutil.ignore_patterns("__pycache__", ".*"))
    return tmp_path


def _edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text, (path, old)
    path.write_text(text.replace(old, new, 1))


def test_the_sweeps_and_the_claims_share_one_version():
    assert sweep.code_version is version.code_version
    assert version.code_version() == source_version(ROOT)


def test_the_rendering_modules_and_the_tests_are_outside():
    names = {p.relative_to(ROOT).as_posix() for p in versioned_files()}
    assert not names & set(RENDERING) and all((ROOT / r).exists() for r in RENDERING)
    assert {"mpm_fem/measure/version.py", "mpm_fem/app/sweep.py", "studies/sod.py", "baselines/fv_euler.py"} <= names
    assert not any(n.startswith("tests/") for n in names)


def test_an_edit_of_a_rendering_module_leaves_the_version(tree):
    before = source_version(tree)
    report = tree / "mpm_fem/app/report.py"
    _edit(report, '"""``REPORT.md``, rendered', '"""The report, ``REPORT.md``, rendered')  # its docstring only
    assert source_version(tree) == before
    _edit(report, "MAX_ROWS = 40", "MAX_ROWS = 41")  # and its code too: it renders, it computes no number
    assert source_version(tree) == before


def test_docstrings_and_comments_leave_the_version_and_code_changes_it(tree):
    before = source_version(tree)
    sweep_py = tree / "mpm_fem/app/sweep.py"
    _edit(sweep_py, '"""Sweeps: a study is a list', '"""Sweeps. A study is a list')  # the module's docstring
    _edit(sweep_py, '"""Cache key of ``fn(case)``', '"""The cache key of ``fn(case)``')  # a function's
    _edit(sweep_py, "CaseFn = Callable[[dict], dict]", "CaseFn = Callable[[dict], dict]  # a comment")
    assert source_version(tree) == before
    _edit(sweep_py, "hexdigest()[:20]", "hexdigest()[:21]")
    changed = source_version(tree)
    assert changed != before
    (tree / "studies" / "new_study.py").write_text("X = 1\n")
    assert source_version(tree) != changed


def test_a_file_that_does_not_parse_enters_by_its_bytes(tree):
    broken = tree / "studies" / "broken.py"
    broken.write_text("def f(:\n")
    before = source_version(tree)
    broken.write_text("def f(:\n    # a comment\n")
    assert source_version(tree) != before


# ------------------------------------------------------------------ the version a case runs through

def _case_version(tree: Path, study: str, fn: str = "run_case") -> str:
    return version.case_source_version(tree / "studies" / f"{study}.py", fn, tree)


def test_a_plan_edit_leaves_the_case_versions_and_changes_the_code_version(tree):
    cases, code = {s: _case_version(tree, s) for s in ("sod", "remedies", "drift")}, source_version(tree)
    _edit(tree / "studies/sod.py", "DEEP_H = (0.000078125,)", "DEEP_H = (0.000078125, 0.0000390625)")
    _edit(tree / "studies/sod.py", "SEEDS = (1, 2, 3, 4, 5)", "SEEDS = (1, 2, 3)")
    _edit(tree / "studies/sod.py", 'script_main(', 'script_main(  # a comment\n    ')  # the __main__ block
    assert {s: _case_version(tree, s) for s in cases} == cases
    assert source_version(tree) != code


def test_a_constant_the_case_reads_changes_its_version_and_of_the_studies_importing_it(tree):
    before = {s: _case_version(tree, s) for s in ("sod", "remedies", "drift", "burgers")}
    # sod's FEM settings: sod's cases carry them (its plan copies them in), remedies' case reads them
    _edit(tree / "studies/sod.py", "FEM = dict(cfl=0.3,", "FEM = dict(cfl=0.25,")
    after = {s: _case_version(tree, s) for s in before}
    assert after["remedies"] != before["remedies"]
    assert after["sod"] == before["sod"] and after["drift"] == before["drift"] and after["burgers"] == before["burgers"]
    _edit(tree / "studies/sod.py", "MOVING_FRACTION = 0.01", "MOVING_FRACTION = 0.02")  # through MOVING_SPEED
    assert _case_version(tree, "sod") != after["sod"]
    drift = _case_version(tree, "drift")
    claims = tree / "mpm_fem/measure/claims/drift.py"
    claims.write_text(claims.read_text() + "\nSTUDY = STUDY + ' '\n")  # a verdicts' constant drift's case reads
    assert _case_version(tree, "drift") != drift


def test_a_top_level_statement_that_changes_a_read_name_enters(tree):
    before = _case_version(tree, "sod")
    sod = tree / "studies/sod.py"
    sod.write_text(sod.read_text() + "\nMPM.update(ppc=8)\n")
    assert _case_version(tree, "sod") != before


def test_an_edit_of_the_model_changes_every_case_version(tree):
    before = {s: _case_version(tree, s) for s in ("sod", "burgers", "time")}
    _edit(tree / "mpm_fem/core/norms.py", '"""', '"""', )  # a no-op first: the docstring is untouched
    assert {s: _case_version(tree, s) for s in before} == before
    norms = tree / "mpm_fem/core/norms.py"
    norms.write_text(norms.read_text() + "\n_UNUSED = 1\n")
    after = {s: _case_version(tree, s) for s in before}
    assert all(after[s] != before[s] for s in before)


def test_a_case_version_names_a_missing_function():
    with pytest.raises(ValueError, match="no top-level 'nowhere'"):
        version.case_source_version(ROOT / "studies/sod.py", "nowhere")


def test_the_model_imports_nothing_outside_it():
    """The case version leaves out studies/, the application, the verdicts and this module because the
    model never imports them (the package's own lazy notebook entry points, mpm_fem/__init__.py, aside)."""
    import ast
    outside = tuple(p.rstrip("/").removesuffix(".py").replace("/", ".") for p in version.OUTSIDE_THE_MODEL)
    for path in version.model_files():
        if path == ROOT / "mpm_fem/__init__.py":
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            names = [node.module or ""] if isinstance(node, ast.ImportFrom) and not node.level else \
                [a.name for a in node.names] if isinstance(node, ast.Import) else []
            assert not [n for n in names if n.startswith(outside)], (path, names)


def test_the_sweeps_key_by_the_case_version(tmp_path):
    from studies import sod
    case = {"h": 0.01}
    key = sweep.case_key(sod.run_case, case)
    version.case_version.cache_clear()
    assert sweep.fn_version(sod.run_case) == version.case_source_version(ROOT / "studies/sod.py", "run_case")
    assert sweep.case_key(sod.run_case, case) == key


def test_a_remembered_version_is_the_computed_one_and_an_edit_computes_it_anew(tree, tmp_path, monkeypatch):
    """The versions are remembered on disk under the files' bytes: a second process's lookup gives the
    computed value, an edit (one byte of code) gives the new file's version, not the remembered one,
    and an unreadable memo is computed around."""
    memo = tmp_path / "memo" / "versions.json"
    monkeypatch.setattr(version, "VERSION_CACHE", memo)
    computed = version._source_version(tree.resolve())
    assert source_version(tree) == computed and memo.exists()
    monkeypatch.setattr(version, "_source_version", lambda root: pytest.fail("not read from the memo"))
    assert source_version(tree) == computed
    monkeypatch.undo()
    monkeypatch.setattr(version, "VERSION_CACHE", memo)
    model = tree / "mpm_fem" / "core" / "norms.py"
    model.write_text(model.read_text() + "\nEXTRA = 1\n")
    assert source_version(tree) == version._source_version(tree.resolve()) != computed
    memo.write_text("not json")
    assert source_version(tree) == version._source_version(tree.resolve())


# ------------------------------------------------------------------ the import closure of a case

_ONE_D = (("sod", "run_case"), ("burgers", "run_case"), ("time", "run_case"), ("remedies", "run_case"))


def _versions(tree: Path, cases=_ONE_D) -> dict:
    return {(s, f): _case_version(tree, s, f) for s, f in cases}


#: Files that nothing of the 1D code imports: the 2D package, its FEM baseline and exact solutions
#: (taken out of the copy, then put back when the tree holds them), and a few written here.
_NEW = ("mpm_fem/plane", "baselines/fem_solid.py", "baselines/exact/solids.py")
_WRITTEN = {"mpm_fem/plane2/__init__.py": '"""A second 2D package."""\n',
            "mpm_fem/plane2/step.py": "from mpm_fem.bases import get\nfrom mpm_fem.core.step import Stages\n"
                                      "from . import grid2\n\nSTAGES = Stages()\nP1 = get(\"mpm\")\n",
            "mpm_fem/plane2/grid2.py": "import numpy as np\n\nN = np.arange(3)\n",
            "baselines/fem_solid2.py": "from baselines.galerkin import *  # noqa\n\nE = 1.0\n",
            "mpm_fem/bases/tensor.py": "from mpm_fem.bases.contract import Basis\n\nT = Basis\n",
            "mpm_fem/problems/plane_sod.py": "from mpm_fem.plane2.step import STAGES\n"}


def test_new_packages_leave_the_1d_case_versions(tree):
    """A 2D package, a new FEM baseline, an exact solution and a new method module that nothing of
    the 1D code imports (the package's lazy ``mpm_fem.plane`` aside) are outside every 1D case's
    closure: no 1D case recomputes when they are added."""
    for name in _NEW:
        shutil.rmtree(tree / name, ignore_errors=True) if (tree / name).is_dir() else (tree / name).unlink(True)
    before, code = _versions(tree), source_version(tree)
    for name in _NEW:
        if (ROOT / name).is_dir():
            shutil.copytree(ROOT / name, tree / name, ignore=shutil.ignore_patterns("__pycache__", ".*"))
        elif (ROOT / name).is_file():
            shutil.copy(ROOT / name, tree / name)
    for name, text in _WRITTEN.items():
        (tree / name).parent.mkdir(exist_ok=True)
        (tree / name).write_text(text)
    assert _versions(tree) == before
    assert source_version(tree) != code
    files = {p.relative_to(tree.resolve()).as_posix() for p in version.case_files(tree / "studies/sod.py", "run_case",
                                                                                   tree)}
    assert not {f for f in files if f.startswith(_NEW + tuple(_WRITTEN))}, sorted(files)
    assert {"mpm_fem/core/step.py", "mpm_fem/bases/point.py", "baselines/fem_euler.py"} <= files, sorted(files)


@pytest.mark.parametrize("edited", ["mpm_fem/bases/point.py", "mpm_fem/core/step.py"])
def test_an_edit_in_the_import_closure_changes_the_case_versions(tree, edited):
    before = _versions(tree)
    path = tree / edited
    path.write_text(path.read_text() + "\n_UNUSED = 1\n")
    after = _versions(tree)
    assert all(after[c] != before[c] for c in before), (before, after)


@pytest.mark.parametrize("edited", ["mpm_fem/bases/cubic.py", "mpm_fem/core/transfers/apic.py"])
def test_a_module_only_a_registry_reaches_changes_the_case_versions(tree, edited):
    """No 1D case imports the cubic B-spline or APIC by name: they reach a run through the registries
    their packages' ``__init__.py`` fill (a case names them by a string), and they are in the closure."""
    before = _versions(tree)
    path = tree / edited
    _edit(path, "from __future__ import annotations", "from __future__ import annotations\n\n_UNUSED = 1")
    after = _versions(tree)
    assert all(after[c] != before[c] for c in before), (before, after)


@pytest.mark.parametrize("edited", ["mpm_fem/bases/point.py", "mpm_fem/core/step.py", "mpm_fem/bases/cubic.py"])
def test_a_docstring_edit_in_the_closure_leaves_the_case_versions(tree, edited):
    before = _versions(tree)
    path = tree / edited
    _edit(path, '"""', '"""In words: ')  # the module's docstring
    path.write_text(path.read_text() + "\n# a comment\n")
    assert _versions(tree) == before


def test_function_local_and_relative_imports_enter_the_closure(tree):
    (tree / "mpm_fem/core/relative.py").write_text("from .grid import uniform_grid\n\nG = uniform_grid\n")
    (tree / "studies/local.py").write_text("def run_case(case):\n    from mpm_fem.core import relative\n"
                                           "    from mpm_fem.bases.registry import get\n\n"
                                           "    return {'n': relative.G(0.0, 1.0, case['h']).n_nodes,\n"
                                           "            'b': get('mpm').name}\n")
    files = {p.relative_to(tree.resolve()).as_posix() for p in version.case_files(tree / "studies/local.py",
                                                                                   "run_case", tree)}
    # the registry's package runs first and registers every basis: the bases enter through it
    assert {"mpm_fem/core/__init__.py", "mpm_fem/core/relative.py", "mpm_fem/core/grid.py",
            "mpm_fem/bases/__init__.py", "mpm_fem/bases/registry.py", "mpm_fem/bases/cubic.py"} <= files, sorted(files)
    assert "mpm_fem/core/transfers/apic.py" not in files and "mpm_fem/fused/step.py" not in files, sorted(files)
    assert "mpm_fem/__init__.py" not in files, "the root package's front door is outside the model"
    before = _case_version(tree, "local")
    grid = tree / "mpm_fem/core/grid.py"
    grid.write_text(grid.read_text() + "\n_UNUSED = 1\n")
    assert _case_version(tree, "local") != before


def test_every_dynamic_import_names_its_modules_but_the_specs_given_at_run_time():
    """Every ``import_module``/``__import__`` of the versioned code names its module by a constant or
    an f-string's head (whose package's modules all enter the closure), but the two that import a
    ``package.module:Name`` given at run time, from outside the packages: the extensions' loader and
    the method study's hash of that module's source (which the case carries in its settings)."""
    import ast
    unresolved = set()
    for path in versioned_files():
        for node in ast.walk(ast.parse(path.read_bytes())):
            argument = version._dynamic_name(node)
            if argument is not None and version.dynamic_modules(ROOT, argument) is None:
                unresolved.add(path.relative_to(ROOT).as_posix())
    assert unresolved == {"mpm_fem/bases/loader.py", "studies/method.py"}, unresolved
    problems = {p for p in (ROOT / "mpm_fem/problems").glob("*.py")}
    files = set(version.case_files(ROOT / "studies/method.py", "run_case"))
    assert problems <= files, sorted(p.name for p in problems - files)  # f"mpm_fem.problems.{problem}"


def test_a_sod_case_runs_through_fewer_files_than_the_model():
    files = version.case_files(ROOT / "studies/sod.py", "run_case")
    model = version.model_files()
    assert set(files) < set(model), sorted(set(files) - set(model))
    names = {p.relative_to(ROOT).as_posix() for p in files}
    assert "mpm_fem/problems/burgers.py" not in names and "baselines/fem_burgers.py" not in names, sorted(names)
    assert {"mpm_fem/bases/cubic.py", "mpm_fem/core/transfers/apic.py", "mpm_fem/fused/step.py"} <= names


def test_an_edit_of_the_root_package_front_door_leaves_the_case_versions(tree):
    """``mpm_fem/__init__.py`` holds the lazily loaded entry points and computes nothing: a new entry
    point there recomputes no case, while the same edit in the model (core/step.py) recomputes them."""
    before = _versions(tree)
    path = tree / "mpm_fem/__init__.py"
    path.write_text(path.read_text() + "\n\ndef _entry():\n    return 1\n")
    assert _versions(tree) == before
    step = tree / "mpm_fem/core/step.py"
    step.write_text(step.read_text() + "\n\ndef _entry():\n    return 1\n")
    assert all(v != before[c] for c, v in _versions(tree).items())
