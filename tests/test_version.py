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
