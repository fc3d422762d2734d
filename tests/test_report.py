"""The report is only ever generated: rendering the committed tables gives the committed REPORT.md
byte for byte; every claim is listed; anchors and links resolve inside the figures folder; every
table row has as many cells as its header."""

from __future__ import annotations

import re
import shutil
import tempfile
from pathlib import Path

import pytest

from mpm_fem.app.report import Page, View, cell, markdown_table, render, write_report
from mpm_fem.measure.claims import STATEMENTS
from mpm_fem.measure.tables import load_tables
from mpm_fem.measure.version import code_version as current_code_version

FIGURES = Path(__file__).resolve().parent.parent / "figures"


@pytest.fixture(scope="module")
def committed():
    return (FIGURES / "REPORT.md").read_text()


def test_the_committed_report_is_the_rendering_of_the_committed_tables(committed):
    with tempfile.TemporaryDirectory() as folder:
        shutil.copytree(FIGURES, folder, dirs_exist_ok=True, ignore=shutil.ignore_patterns(".cache"))
        rendered = write_report(Path(folder)).read_text()
    assert rendered == committed, "figures/REPORT.md differs from `python -m mpm_fem.app.report --out figures`"


def test_the_header_names_the_code_version_of_the_tables(committed):
    codes = {r["code"] for r in load_tables(FIGURES)["versions"]}
    assert any(f"code version {c}" in committed.splitlines()[2] for c in codes)


def test_the_first_screen_says_when_the_figures_lag_the_code():
    """Tables of another code version than the current one: the caveats say the figures lag it (E4)."""
    tables = load_tables(FIGURES)
    now = current_code_version()
    lagging = {**tables, "versions": [{**r, "code": "0123456789ab"} for r in tables["versions"]]}
    current = {**tables, "versions": [{**r, "code": now} for r in tables["versions"]]}
    first = "\n".join(render(lagging, [], current=now).splitlines()[:60])
    lag = f"**The figures lag the code**: the tables were written by code version 0123456789ab, the code is now {now}"
    assert lag in first
    assert "lag" not in render(current, [], current=now).split("## Caveats")[1].split("<a id=")[0]


def test_every_claim_is_in_the_summary(committed):
    summary = committed.split("## The source's claims")[1].split("<a id=")[0]
    for cid in STATEMENTS:
        assert re.search(rf"^\| \[?{cid}[\] (|]", summary, re.M), cid


def test_the_first_screen_holds_the_abstract_the_two_verdict_tables_and_two_figures(committed):
    first = "\n".join(committed.splitlines()[:60])
    for heading in ("## Abstract", "## The source's claims", "## Extensions"):
        assert heading in first, heading
    assert first.count("![") >= 2, "the two key figures"


def test_every_embedded_figure_is_at_most_two_and_a_half_wide(committed):
    import matplotlib.image as image

    from mpm_fem.app.plots import MAX_ASPECT

    # a study whose tables an older code wrote keeps that code's figures: E4 reports the lag
    from mpm_fem.measure.version import code_version

    current = {r["table"].split("/")[0] for r in load_tables(FIGURES)["versions"] if r["code"] == code_version()}
    for target in re.findall(r"!\[[^]]*\]\(([^)]+)\)", committed):
        if target.split("/")[0] not in current:
            continue
        height, width = image.imread(FIGURES / target).shape[:2]
        assert width <= MAX_ASPECT * height * 1.01, (target, width, height)


def test_every_anchor_and_link_resolves_inside_the_folder(committed):
    """Every link is an anchor of the report, or a file of the folder (with, for another report, one
    of its anchors: the deep tier's verdicts link into ``deep/REPORT.md``)."""
    anchors = set(re.findall(r'<a id="([^"]+)"></a>', committed))
    for target in re.findall(r"\]\(([^)]+)\)", committed):
        assert not target.startswith(("/", "..", "http", "figures/")), target
        path, _, anchor = target.partition("#")
        if not path:
            assert anchor in anchors, target
            continue
        assert (FIGURES / path).exists(), target
        if anchor:
            assert f'<a id="{anchor}"></a>' in (FIGURES / path).read_text(), target


def test_no_garbled_cells(committed):
    lines = committed.splitlines()
    for k, line in enumerate(lines):
        if line.startswith("|---"):
            width = lines[k - 1].count("|")
            for row in lines[k + 1:]:
                if not row.startswith("|"):
                    break
                assert len(re.findall(r"(?<!\\)\|", row)) == width, row


def test_a_quick_report_links_only_to_its_own_folder(tmp_path):
    (tmp_path / "toy").mkdir()
    (tmp_path / "toy" / "t.csv").write_text("h,quick_value\n0.5,1.25\n0.25,|x|\n")
    (tmp_path / "toy" / "t.json").write_text('{"settings": {"quick": true}, "code": "abc"}')
    (tmp_path / "toy" / "figures.json").write_text('{"t.png": "A toy figure"}')
    page = Page("toy", "Toy", "A toy study.", views=(View("toy/t", "The toy table", (), {}, "t.png"),))
    text = write_report(tmp_path, [page]).read_text()
    assert "reproduce --quick" in text and "code version abc" in text
    assert "![A toy figure](toy/t.png)" in text and "[t.csv](toy/t.csv)" in text
    assert "| 0.25 | \\|x\\| |" in text
    assert "not measured" in text


def test_cells_keep_four_significant_digits_and_escape_pipes():
    assert [cell("0.0083452"), cell("16"), cell("nan"), cell("a|b")] == ["0.008345", "16", "", "a\\|b"]
    assert markdown_table([{"a": "1", "b": "x"}]) == ["| a | b |", "|---|---|", "| 1 | x |"]


def test_readme_results_in_brief_are_generated_from_the_committed_tables():
    from mpm_fem.app.report import README_BEGIN, README_END, results_in_brief

    readme = (FIGURES.parent / "README.md").read_text()
    block = README_BEGIN + readme.split(README_BEGIN, 1)[1].split(README_END, 1)[0] + README_END
    assert block == results_in_brief(load_tables(FIGURES)), "run `python -m mpm_fem.app.report --readme README.md`"


def test_the_command_refuses_a_missing_folder(tmp_path, capsys):
    from mpm_fem.app.report import main

    assert main(["--out", str(tmp_path / "absent")]) == 2
    assert "no folder" in capsys.readouterr().err


def test_the_grid_of_panels_keeps_every_figure_at_most_two_and_a_half_wide():
    from mpm_fem.app.plots import MAX_ASPECT, grid_shape

    for n in range(1, 13):
        for size in ((4.2, 3.8), (3.6, 4.4), (4.6, 3.8), (6.0, 2.0)):
            rows, cols = grid_shape(n, size)
            assert rows * cols >= n and (rows - 1) * cols < n, (n, size, rows, cols)
            assert size[0] * cols <= MAX_ASPECT * size[1] * rows or cols == 1, (n, size, rows, cols)
    assert grid_shape(4, (4.2, 3.6)) == (2, 2) and grid_shape(2, (4.2, 3.8)) == (1, 2)


def test_a_key_number_is_cut_at_a_comma_to_fit_the_summary():
    from mpm_fem.app.report import KEY_LENGTH, key_number

    assert key_number("order 0.95; the rest") == "order 0.95"
    long = ", ".join(f"mesh {k}: order 0.{k}" for k in range(20))
    cut = key_number(long)
    assert len(cut) <= KEY_LENGTH and cut.endswith(" ...") and long.startswith(cut[:-4])
    assert cut[:-4].split(", ")[-1].startswith("mesh")  # whole items only


def test_a_folder_with_some_studies_has_a_section_for_every_claim():
    """A tier run in part (the deep tier's folder): every claim the summary links to has its section, the
    studies without tables saying so, their claims not measured."""
    from mpm_fem.app.pages import PAGES
    from mpm_fem.measure.tables import load_tables

    tables = {name: rows for name, rows in load_tables(FIGURES).items() if not name.startswith("burgers/")}
    text = render(tables, PAGES)
    anchors = set(re.findall(r'<a id="([^"]+)"></a>', text))
    assert {t[1:] for t in re.findall(r"\]\((#[^)]+)\)", text)} <= anchors
    burgers = text.split('<a id="burgers"></a>')[1].split("<a id=")[0]
    assert "No table of the study `burgers` in this folder" in burgers
    assert '<a id="c13"></a>' in text and "**not measured**" in text.split('<a id="c13"></a>')[1].split("<a id=")[0]
