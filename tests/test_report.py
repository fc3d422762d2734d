"""The report is only ever generated: rendering the committed tables gives the committed REPORT.md
byte for byte (and APPENDIX.md beside it); every claim is listed; anchors and links resolve inside the folder; every
table row has as many cells as its header. It reads as a paper: the sections in order, no paragraph
over the limit, no heading without content, an abstract of at most five plain sentences that follow
the tables, five to eight conclusions with their numbers (the structure is asserted on a fresh
rendering of the committed tables, ``rendered``)."""

from __future__ import annotations

import re
import shutil
import tempfile
from pathlib import Path

import pytest

from mpm_fem.app.report import Page, View, cell, markdown_table, render, render_both, write_report
from mpm_fem.measure.claims import STATEMENTS
from mpm_fem.measure.tables import load_tables
from mpm_fem.measure.version import code_version as current_code_version

FIGURES = Path(__file__).resolve().parent.parent / "figures"


@pytest.fixture(scope="module")
def committed():
    return (FIGURES / "REPORT.md").read_text()


@pytest.fixture(scope="module")
def written():
    """``REPORT.md`` and ``APPENDIX.md`` rendered now from the committed tables (in a copy of the folder)."""
    with tempfile.TemporaryDirectory() as folder:
        shutil.copytree(FIGURES, folder, dirs_exist_ok=True, ignore=shutil.ignore_patterns(".cache"))
        path = write_report(Path(folder))
        return path.read_text(), (path.parent / "APPENDIX.md").read_text()


@pytest.fixture(scope="module")
def rendered(written):
    return written[0]


@pytest.fixture(scope="module")
def appendix(written):
    return written[1]


@pytest.fixture(scope="module")
def tables():
    return load_tables(FIGURES)


def test_the_committed_report_is_the_rendering_of_the_committed_tables(committed):
    with tempfile.TemporaryDirectory() as folder:
        shutil.copytree(FIGURES, folder, dirs_exist_ok=True, ignore=shutil.ignore_patterns(".cache"))
        rendered = write_report(Path(folder)).read_text()
    assert rendered == committed, "figures/REPORT.md differs from `python -m mpm_fem.app.report --out figures`"


def test_the_header_names_the_code_version_of_the_tables(rendered):
    codes = {r["code"] for r in load_tables(FIGURES)["versions"]}
    assert any(f"code version {c}" in rendered.splitlines()[2] for c in codes)


def test_the_first_screen_says_when_the_figures_lag_the_code():
    """Tables of another code version than the current one: the caveats say the figures lag it (E4)."""
    tables = load_tables(FIGURES)
    now = current_code_version()
    lagging = {**tables, "versions": [{**r, "code": "0123456789ab"} for r in tables["versions"]]}
    current = {**tables, "versions": [{**r, "code": now} for r in tables["versions"]]}
    first = "\n".join(render(lagging, [], current=now).splitlines()[:60])
    lag = f"**The figures lag the code**: the tables were written by code version 0123456789ab, the code is now {now}"
    assert lag in first
    assert "lag" not in render(current, [], current=now).split(" The record\n")[1].split("## 3 Results")[0]


def test_every_claim_is_in_the_summary(rendered):
    """The 1D claims in the results' summary; the 2D ones (D) each a paragraph of their own section."""
    summary = rendered.split("## 3 Results")[1].split("<a id=")[0]
    plane = rendered.split("## 4 Two dimensions")[1].split("\n## ")[0]
    for cid in STATEMENTS:
        if cid.startswith("D"):
            assert re.search(rf"^\*\*{cid}[* (]", plane, re.M), cid
        else:
            assert re.search(rf"^\| \[?{cid}[\] (|]", summary, re.M), cid


def test_the_first_screen_holds_the_abstract_and_the_two_key_figures(rendered):
    first = "\n".join(rendered.splitlines()[:40])
    assert "## Abstract" in first
    assert first.count("![") >= 2, "the two key figures"


def test_every_embedded_figure_is_at_most_two_and_a_half_wide(rendered):
    import matplotlib.image as image

    from mpm_fem.app.plots import MAX_ASPECT

    # a study whose tables an older code wrote keeps that code's figures: E4 reports the lag
    from mpm_fem.measure.version import code_version

    current = {r["table"].split("/")[0] for r in load_tables(FIGURES)["versions"] if r["code"] == code_version()}
    for target in re.findall(r"!\[[^]]*\]\(([^)]+)\)", rendered):
        if target.split("/")[0] not in current:
            continue
        height, width = image.imread(FIGURES / target).shape[:2]
        assert width <= MAX_ASPECT * height * 1.01, (target, width, height)


def test_every_anchor_and_link_resolves_inside_the_folder(rendered, appendix):
    """Every link of the report and of its appendix is an anchor of its own file, of the other one, or a file
    of the folder (with, for another report, one of its anchors: the deep tier's verdicts link into
    ``deep/REPORT.md``)."""
    texts = {"REPORT.md": rendered, "APPENDIX.md": appendix}
    anchors = {name: set(re.findall(r'<a id="([^"]+)"></a>', text)) for name, text in texts.items()}
    for name, text in texts.items():
        for target in re.findall(r"\]\(([^)]+)\)", text):
            assert not target.startswith(("/", "..", "http", "figures/")), target
            path, _, anchor = target.partition("#")
            if path in texts or not path:
                assert not anchor or anchor in anchors[path or name], (name, target)
                continue
            assert (FIGURES / path).exists(), target
            if anchor:
                assert f'<a id="{anchor}"></a>' in (FIGURES / path).read_text(), target


def test_no_garbled_cells(rendered):
    lines = rendered.splitlines()
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
    path = write_report(tmp_path, [page])
    text = path.read_text() + (path.parent / "APPENDIX.md").read_text()
    assert "reproduce --quick" in text and "code version abc" in text
    assert "![A toy figure](toy/t.png)" in text and "[t.csv](toy/t.csv)" in text
    assert "| 0.25 | \\|x\\| |" in text
    assert "not measured" in text


def test_cells_keep_four_significant_digits_and_escape_pipes():
    assert [cell("0.0083452"), cell("16"), cell("nan"), cell("a|b")] == ["0.008345", "16", "", "a\\|b"]
    assert cell("nan / 0.5") == "- / 0.5" and cell("nanometre") == "nanometre"
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


def test_the_key_number_is_the_sentence_or_the_whole_first_clause(tables):
    """The summary (and the README's results in brief) never cuts a key number: the finding's sentence, or
    the evidence's first clause whole, cut at no semicolon inside parentheses."""
    from mpm_fem.app.paper import key_text
    from mpm_fem.app.report import results_in_brief
    from mpm_fem.measure.claims import Finding

    assert key_text(Finding("partly", "order 0.95 (8 ppc; CFL 0.05); the rest")) == "order 0.95 (8 ppc; CFL 0.05)"
    assert key_text(Finding("partly", "order 0.95; the rest", "The order is 0.95.")) == "The order is 0.95."
    brief = results_in_brief(tables)
    assert "..." not in brief
    assert "the particle density error grows under refinement (mean orders" in brief  # C11's sentence, whole


def test_a_folder_with_some_studies_has_a_section_for_every_claim():
    """A tier run in part (the deep tier's folder): every claim the summary links to has its section, the
    studies without tables saying so, their claims not measured."""
    from mpm_fem.app.pages import PAGES
    from mpm_fem.measure.tables import load_tables

    tables = {name: rows for name, rows in load_tables(FIGURES).items()
              if not name.startswith(("burgers/", "identification/burgers"))}
    text = render(tables, PAGES)
    anchors = set(re.findall(r'<a id="([^"]+)"></a>', text))
    assert {t[1:] for t in re.findall(r"\]\((#[^)]+)\)", text)} <= anchors
    burgers = text.split('<a id="burgers"></a>')[1].split("<a id=")[0]
    assert "No table of the study `burgers` in this folder" in burgers
    assert '<a id="c13"></a>' in text and "| not measured |" in text.split('<a id="c13"></a>')[1].split("<a id=")[0]


# ----------------------------------------------------------------------------- the report as a paper

SECTIONS = ("## Abstract", "## 1 Introduction", "## 2 Method", "### 2.1 Problems and settings", "### 2.2 Terms",
            "### 2.4 Verdicts and the rule book", "### 2.5 Seeds", "## 3 Results", "## 4 Two dimensions",
            "## 5 Discussion", "### 5.2 What makes Sod's particle error grow: the drift study",
            "### 5.3 Why the particle error grows: the local defect, accumulated", "### 5.4 What the deep tier changes",
            "## 6 Conclusions")


def test_the_sections_of_a_paper_come_in_order(rendered):
    at = [rendered.find("\n" + s + "\n") for s in SECTIONS]
    assert all(k > 0 for k in at), [s for s, k in zip(SECTIONS, at, strict=True) if k <= 0]
    assert at == sorted(at), "sections out of order"


def test_the_introduction_is_one_paragraph(rendered):
    block = rendered.split("## 1 Introduction\n")[1].split("\n## ")[0]
    assert len([p for p in block.split("\n\n") if p.strip()]) == 1, block


def test_no_paragraph_is_over_the_limit_and_no_heading_is_empty(rendered, appendix):
    from mpm_fem.app.markdown import MAX_WORDS, headings_without_content, words_of_paragraphs

    for text in (rendered, appendix):
        long = [(n, start) for n, start in words_of_paragraphs(text) if n > MAX_WORDS]
        assert not long, long
        assert not headings_without_content(text), headings_without_content(text)


def test_the_checks_find_a_long_paragraph_and_an_empty_heading():
    from mpm_fem.app.markdown import MAX_WORDS, headings_without_content, words_of_paragraphs

    text = "## A\n\n### B\n\nshort.\n\n" + "word " * (MAX_WORDS + 1) + "\n\n- item one\n- item two\n\n## C\n"
    assert [n for n, _ in words_of_paragraphs(text)] == [1, MAX_WORDS + 1, 6]  # a tight list is one block
    assert headings_without_content(text) == ["## A", "## C"]


def test_long_prose_is_cut_into_paragraphs_of_whole_sentences():
    from mpm_fem.app.markdown import MAX_WORDS, paragraphs, split_outside

    text = " ".join(f"Sentence {k} has the order 0.{k} (on mesh {k}; seed {k})." for k in range(60))
    cut = paragraphs(text)
    assert len(cut) > 1 and all(len(p.split()) <= MAX_WORDS for p in cut)
    assert " ".join(cut) == text
    one = "; ".join(f"clause {k} with the order 0.{k}" for k in range(60))
    assert all(len(p.split()) <= MAX_WORDS for p in paragraphs(one)) and len(paragraphs(one)) > 1
    assert split_outside("a (b; c); d") == ["a (b; c)", "d"]


def test_the_abstract_is_at_most_five_plain_sentences(rendered):
    from mpm_fem.app.paper import abstract_sentences

    found = abstract_sentences(rendered)
    assert 1 <= len(found) <= 5, found
    body = " ".join(found)
    assert "..." not in body and "**" not in body
    assert not re.search(r"\bis (confirmed|partly|refuted|differs)\b", body), body


def test_a_perturbed_table_changes_the_abstract(tables):
    """C11 judged on a particle error that converges at first order: the abstract's sentence about it changes."""
    from mpm_fem.app.paper import _clause, abstract, judge
    from mpm_fem.measure.claims import select

    converging = {**tables, "sod/seeds": [dict(r) for r in tables["sod/seeds"]]}
    for r in select(converging["sod/seeds"], ok="True"):
        r["particles_L1"] = r["energy_L1"] = repr(1.2 * float(r["h"]))
    before, after = judge(tables), judge(converging)
    assert before["C11"][1].verdict != after["C11"][1].verdict
    text, changed = "\n".join(abstract(tables, before)), "\n".join(abstract(converging, after))
    assert text != changed
    clause = lambda f: _clause(f)[1:].rstrip(")")  # noqa: E731  (lowered; a label may join its parenthesis)
    assert clause(before["C11"][1]) in text and clause(after["C11"][1]) in changed
    assert clause(before["C11"][1]) != clause(after["C11"][1])


def test_the_conclusions_are_five_to_eight_findings_with_their_numbers(rendered):
    block = rendered.split("## 6 Conclusions")[1].split("\n## ")[0]
    items = [line for line in block.splitlines() if line.startswith("- ")]
    assert 5 <= len(items) <= 8, items
    assert all(re.search(r"\d", item) for item in items), items


def test_the_rule_book_and_the_verdict_words_are_printed_in_the_method(tables, monkeypatch):
    from mpm_fem.app import paper
    from mpm_fem.measure.claims.rules import RULES, VERDICT_MEANING, Rule

    monkeypatch.setitem(RULES, "TEST_FLOOR", Rule("TEST_FLOOR", 0.5, "an order below it is a floor",
                                                  "the study's", ("C11",)))
    method, book = "\n".join(paper.method(tables, [])), "\n".join(paper.rule_book())
    assert "| TEST_FLOOR | 0.5 | an order below it is a floor | the study's | C11 |" in book
    assert "APPENDIX.md#rule-book" in method and "TEST_FLOOR" not in method
    for word, meaning in (*VERDICT_MEANING.items(), paper.COUNT_MEANING):
        assert f"| {word} | {meaning} |" in method


def test_a_finding_shows_its_table_or_its_evidence_as_a_list():
    from mpm_fem.app.paper import evidence
    from mpm_fem.measure.claims import Finding

    assert evidence(Finding("partly", "a (b; c); d")) == ["- a (b; c)", "", "- d", ""]  # items apart
    table = evidence(Finding("partly", "e", "s", ({"ppc": "8", "order": "0.5"}, {"ppc": "16", "order": "0.9"})))
    assert table[:3] == ["| ppc | order |", "|---|---|", "| 8 | 0.5 |"]


def test_the_drift_study_is_a_section_of_the_discussion(rendered):
    section = rendered.split("### 5.2 What makes Sod's particle error grow")[1].split("### 5.3")[0]
    assert "| study settings | regular |" in section and "volume drift" in section
    assert "drift/drift.png" in section


def test_the_deep_tier_says_which_verdicts_move(tables):
    from dataclasses import replace

    from mpm_fem.app.paper import deep_changes, judge, verdict_text

    found = judge(tables)
    assert "No verdict moves" in "\n".join(deep_changes(found, found))
    c, f = found["C12"]
    moved = {**found, "C12": (c, replace(f, verdict="confirmed" if f.verdict != "confirmed" else "partly"))}
    text = "\n".join(deep_changes(found, moved))
    assert f"| C12 | {verdict_text(f)} | {verdict_text(moved['C12'][1])} |" in text and "No verdict moves" not in text
    assert "holds no tables" in "\n".join(deep_changes(found, None))


def test_the_stamps_and_the_deep_verdicts_are_in_the_appendices(rendered, appendix):
    assert "## Appendix" not in rendered and "| budget/bases |" not in rendered and "| budget/bases |" in appendix
    assert "## Appendix" in appendix.split('<a id="deep"></a>')[1]


def test_the_source_matching_settings_are_stated_when_identified(tables):
    from mpm_fem.app.paper import identification_appendix, identification_section

    rows = [{"source_row": "L1", "ppc": "16", "cfl": "0.05", "quantity": "nodes", "norm": "L1", "misfit": "0.07",
             "rank": "1", "matching": "True"},
            {"source_row": "L1", "ppc": "8", "cfl": "0.05", "quantity": "nodes", "norm": "L1", "misfit": "0.9",
             "rank": "2", "matching": "False"}]
    identified = {**tables, "identification/sod": rows, "identification/burgers": []}
    said = "\n".join(identification_section(identified))
    assert "Sod L1 column is reproduced within 7 %" in said and "16 per cell" in said, said
    assert "| sod | L1 | 16 | 0.05 |" in "\n".join(identification_appendix(identified))
    bare = {k: v for k, v in tables.items() if not k.startswith("identification/")}
    assert "are not in this folder" in "\n".join(identification_section(bare))


def test_a_finding_with_a_sentence_and_a_table_is_said_in_words(tables):
    """Where a criterion writes a plain sentence and a small table, the abstract says its first clause, the
    results and the conclusions say the sentence, the appendix shows the table, and its verdict rule keeps the
    whole evidence line."""
    from dataclasses import replace

    from mpm_fem.app.pages import PAGES
    from mpm_fem.measure.claims import CLAIMS, Finding

    sentence = "At 8 particles per cell the particle density error grows from the second refinement on."
    found = Finding("differs", "orders 0.18, -0.24; the rest", sentence, ({"ppc": "8", "last order": "-0.52"},))
    k = next(k for k, c in enumerate(CLAIMS) if c.label == "C11")
    original = CLAIMS[k]
    CLAIMS[k] = replace(original, criterion=lambda t: found)
    try:
        text, extra = render_both(tables, PAGES)
    finally:
        CLAIMS[k] = original
    head = text.split("## 1 Introduction")[0]
    assert "on Sod at 8 particles per cell the particle density error grows from the second refinement on (C11)." \
        in head, head
    assert sentence in text.split('<a id="c11"></a>')[1].split("<a id=")[0]
    evidence = extra.split('<a id="evidence-c11"></a>')[1].split("<a id=")[0]
    assert "| ppc | last order |" in evidence and "| 8 | -0.52 |" in evidence
    assert sentence.rstrip(".") + " (C11)." in text.split(" Conclusions\n")[1]
    assert "The evidence in full: orders 0.18, -0.24; the rest." in extra.split('<a id="rule-c11"></a>')[1]


def test_failed_runs_are_named_in_the_claims_section(rendered):
    """P1 losing positivity at 1 particle per cell (sod/ppc): C3's section names the failed runs, their count
    and their cause, beside the verdict judged on the runs that finished."""
    section = rendered.split('<a id="c3-sod"></a>')[1].split("<a id=")[0]
    assert ("Runs that failed (count, where they ran, cause): sod/ppc: 2 of 18 runs failed (ppc = 1; h = 0.0025, "
            "0.000625): positivity lost.") in section, section[-600:]


# ----------------------------------------------------------------------------- one code version per report

def _restamped(tables, code: str):
    return {**tables, "versions": [{**r, "code": code} for r in tables["versions"]]}


def test_a_deep_tier_of_another_code_version_is_left_out_and_changes_no_verdict(tables):
    """The committed deep tier (another code version than the record's; E2 confirmed on its tables, differs on
    the record's) is not shown: one sentence says it exists, how to run it and when it enters; no verdict moves.
    The same tables stamped with the record's code are shown, and E2's move is said."""
    from mpm_fem.app.report import code_version

    if not (FIGURES / "deep").is_dir():
        pytest.skip("no committed deep tier")
    deep = load_tables(FIGURES / "deep")
    record = code_version(tables)
    other = _restamped(deep, "0123456789ab") if code_version(deep) == record else deep
    text = render(tables, [], current=record, deep=other)
    assert f"written by code version {code_version(other)}, not this record's {record}, so they are left out of " \
           "this report and change no verdict; they enter it when `mpm-fem reproduce --deep` regenerates them at " \
           f"the current code ({record})." in text
    assert "deep/REPORT.md" not in text and "The verdicts that move on the deep tier" not in text
    summary = text.split("## 3 Results")[1].split("<a id=")[0]
    assert summary == render(tables, [], current=record).split("## 3 Results")[1].split("<a id=")[0]
    shown, extra = render_both(tables, [], current=record, deep=_restamped(deep, record))
    assert "| E2 | differs | confirmed |" in shown and "[deep/REPORT.md](deep/REPORT.md)" in extra


def test_a_table_of_another_code_version_is_left_out_of_the_report_and_the_readme(tables):
    """One table of the record stamped by another code version: its claim is not measured and says why, the
    caveats name it, its rows are not shown, and E4 still sees its stamp (other versions: refuted)."""
    from mpm_fem.app.pages import PAGES
    from mpm_fem.app.report import code_version, results_in_brief

    record = code_version(tables)
    mixed = {**tables, "versions": [{**r, "code": "0123456789ab"} if r["table"] == "sod/extrema" else r
                                    for r in tables["versions"]]}
    text, extra = render_both(mixed, PAGES, current=record)
    c14 = text.split('<a id="c14"></a>')[1].split("<a id=")[0]
    assert "| not measured |" in c14 and "Left out: `sod/extrema.csv` was written by code version 0123456789ab, " \
        "another than the record's" in c14
    assert f"**1 of {len(tables['versions'])} tables are left out of this report**: written by another code version " \
           f"than the record's {record} (sod/extrema;" in text
    e4 = text.split('<a id="e4"></a>')[1].split("<a id=")[0]
    assert "| refuted |" in e4 and "sod/extrema" in extra.split('<a id="evidence-e4"></a>')[1].split("<a id=")[0]
    assert "No rows in `sod/extrema.csv`." in extra.split('<a id="appendix-sod"></a>')[1]
    brief = results_in_brief(mixed)
    assert "| [C14](figures/REPORT.md#c14) | particle density/energy updates create new extrema at cell crossings | " \
           "**not measured** | left out: `sod/extrema.csv` was written by code version 0123456789ab" in brief
