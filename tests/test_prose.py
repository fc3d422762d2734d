"""No typed numbers in prose, and no internal references: the project speaks of itself only.

Every number a reader sees in the report is formatted from a table: the test parses the study
modules and the report layer, takes every string literal of six words or more (the literal parts of
f-strings included, docstrings excluded: they document code, they are not the report) and fails on a
word that is a bare number (``0.5``, ``16``, ``40%``, ``3x``), naming the file and line. Numbers
belong in code (constants, settings) or in tables, never in sentences.

The texts of the project (the README, CHANGES.md, docs/, the application and measurement layers, the
studies, the benchmarks and the tests) date things by day and code version and name the work by what it
did: a line that cites a numbered issue or a sitting of work fails, naming the file and line (pytest's
test session, its fixture scope and hooks are not one).
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
#: Study modules left out of the check of typed numbers (none).
PENDING: set = set()
MODULES = ([p for p in sorted((ROOT / "studies").glob("*.py")) if p.name not in PENDING]
           + [ROOT / "mpm_fem" / "app" / name for name in ("report.py", "paper.py", "markdown.py", "pages.py",
                                                           "paper_findings.py", "paper_abstract.py", "paper_method.py",
                                                           "paper_results.py", "paper_discussion.py")])
NUMBER = re.compile(r"^[-+~]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?(%|x)?$")
PROSE_WORDS = 6


def _docstrings(tree: ast.AST) -> set[int]:
    ids = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and node.body:
            first = node.body[0]
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant):
                ids.add(id(first.value))
    return ids


def typed_numbers(path: Path) -> list[str]:
    """``"file:line: number in 'text'"`` for every bare number inside a prose string of ``path``."""
    tree = ast.parse(path.read_text())
    skip = _docstrings(tree)
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.JoinedStr):
            parts = [v.value for v in node.values if isinstance(v, ast.Constant) and isinstance(v.value, str)]
            for v in node.values:
                skip.add(id(v))
        elif isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in skip:
            parts = [node.value]
        else:
            continue
        text = " {} ".join(parts)
        words = [w.strip(",.;:()[]*`'\"") for w in text.split()]
        if sum(bool(re.search("[A-Za-z]", w)) for w in words) < PROSE_WORDS:
            continue
        found += [f"{path.relative_to(ROOT)}:{node.lineno}: {w!r} in {text[:60]!r}" for w in words if NUMBER.match(w)]
    return found


def test_no_typed_numbers_in_study_or_report_prose():
    found = [hit for path in MODULES for hit in typed_numbers(path)]
    assert not found, f"{len(found)} typed numbers in prose:\n" + "\n".join(found)


def test_the_check_finds_a_typed_number(tmp_path):
    path = ROOT / "tests" / "_probe_prose.py"
    try:
        path.write_text('"""Doc 1 2 3 4 5 6 7."""\nTEXT = "the order is 0.88 on every mesh of the study"\n'
                        'OK = f"the order is {x:.2f} on every mesh of the study"\n')
        assert [h.split(": ", 1)[1] for h in typed_numbers(path)] == [
            "'0.88' in 'the order is 0.88 on every mesh of the study'"]
    finally:
        path.unlink()


# ---------------------------------------------------------------- internal references

#: The texts checked for internal references (folders: every text file under them).
TEXTS = ("README.md", "CHANGES.md", "docs", "mpm_fem/app", "mpm_fem/measure", "studies", "benchmarks", "tests")
#: Texts left out of the check (paths from the root): none.
REWRITING: set = set()
SUFFIXES = {".md", ".py", ".txt", ".toml", ".cfg", ".rst"}
#: A numbered issue or a sitting of work (the word built in pieces so that this file does not match).
REFERENCE = re.compile(r"\b" + "ses" + r"sions?\b|issues? [0-9]+|issue-[0-9]+", re.IGNORECASE)
#: pytest's sense of the word: the test session, the fixture scope, the hooks and their argument.
PYTEST_SESSION = re.compile(r"test " + "ses" + r"sion|scope=.ses" + r"sion.|pytest_\w+|\(ses" + r"sion\)",
                            re.IGNORECASE)


def references(path: Path) -> list[str]:
    """``"file:line: text"`` for every line of ``path`` that cites an issue or a sitting of work."""
    found = []
    for number, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
        if REFERENCE.search(PYTEST_SESSION.sub("", line)):
            found.append(f"{path.relative_to(ROOT)}:{number}: {line.strip()[:100]}")
    return found


def _texts() -> list[Path]:
    paths = []
    for name in TEXTS:
        path = ROOT / name
        files = [path] if path.is_file() else sorted(p for p in path.rglob("*") if p.suffix in SUFFIXES)
        paths += [p for p in files if "__pycache__" not in p.parts
                  and p.relative_to(ROOT).as_posix() not in REWRITING]
    return paths


def test_the_project_texts_cite_no_issue_number_and_no_sitting_of_work():
    paths = _texts()
    assert len(paths) > 100 and ROOT / "CHANGES.md" in paths
    found = [hit for path in paths for hit in references(path)]
    assert not found, f"{len(found)} internal references (date them, or name the work):\n" + "\n".join(found)


def test_the_reference_check_finds_one_and_spares_pytest(tmp_path):
    path = ROOT / "tests" / "_probe_references.md"
    word, issue = "ses" + "sion", "iss" + "ue"
    try:
        path.write_text(f"measured in the third {word}\nas {issue} 47 asks\nsee {issue}-12\na test {word} of pytest\n"
                        f"@pytest.fixture(scope=\"{word}\")\ndef pytest_{word}start({word}):\nmeasured on 2026-11-29\n")
        assert [h.split(":")[1] for h in references(path)] == ["1", "2", "3"]
    finally:
        path.unlink()
