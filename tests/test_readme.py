"""The README is a user guide: short, its two set-up commands first, every link and image resolving,
its results block the generated one."""

from __future__ import annotations

import re
from pathlib import Path

from mpm_fem.app.report import README_BEGIN, README_END, results_in_brief
from mpm_fem.measure.tables import load_tables

ROOT = Path(__file__).resolve().parent.parent
README = (ROOT / "README.md").read_text()


def test_the_readme_is_at_most_150_lines_and_opens_with_the_two_commands():
    lines = README.splitlines()
    assert len(lines) <= 150, len(lines)
    commands = [line for line in lines[:6] if line.startswith("pip install")]
    assert len(commands) == 2 and "mpm-fem reproduce" in commands[0] and "pytest" in commands[1], commands


def test_every_link_and_image_of_the_readme_and_the_docs_resolves():
    for page in [ROOT / "README.md", ROOT / "CHANGES.md", *sorted((ROOT / "docs").glob("*.md"))]:
        for target in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", page.read_text()):
            if target.startswith(("http://", "https://")):
                continue
            assert (page.parent / target).exists(), f"{page.name}: {target}"


def test_the_results_in_brief_are_the_generated_ones():
    block = README.split(README_BEGIN, 1)[1].split(README_END, 1)[0]
    expected = results_in_brief(load_tables(ROOT / "figures")).split(README_BEGIN, 1)[1].split(README_END, 1)[0]
    assert block == expected, "README's results differ from `python -m mpm_fem.app.report --readme README.md`"


def test_no_key_number_of_the_readme_is_cut():
    """The key number is the finding's sentence (or the evidence's first clause), whole: never cut with "..."."""
    block = README.split(README_BEGIN, 1)[1].split(README_END, 1)[0]
    rows = [r for r in block.splitlines() if r.startswith("| [")]
    assert rows and not [r for r in rows if "..." in r.rstrip(" |").split(" | ")[-1]]


def test_every_key_number_of_the_readme_fits_its_cell():
    """The README's key numbers are the findings' sentences or their short forms (``Finding.key``), at most
    ``KEY_CHARS`` characters: no cell runs over, and none is cut."""
    from mpm_fem.app.paper import KEY_CHARS

    block = README.split(README_BEGIN, 1)[1].split(README_END, 1)[0]
    cells = [r.rstrip(" |").split(" | ")[-1] for r in block.splitlines() if r.startswith("| [")]
    long = [f"{len(c)}: {c}" for c in cells if len(c) > KEY_CHARS]
    assert len(cells) > 20 and not long, "key numbers over the cell's length:\n" + "\n".join(long)
    assert not [c for c in cells if c.endswith(("...", ",", ";", " the", " of", " and"))], cells
