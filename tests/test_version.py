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
    version._model_version.cache_clear()
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
