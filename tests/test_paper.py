"""The report as a paper a journal takes: a main text of at most MAIN_WORDS words (prose and table cells),
an abstract of at most five sentences that states five findings each with its number, no verdict word pasted
into prose, the long evidence in ``APPENDIX.md`` beside it and linked from every section, no ``nan``; and
the quick tier's first screen, which says which stage the error comes from and how MPM compares with the FEM.

Everything is asserted on a fresh rendering of the committed tables (``written``) or on small tables built
here from them."""

from __future__ import annotations

import re
import shutil
import tempfile
from pathlib import Path

import pytest

from mpm_fem.app.paper import abstract_sentences, counted, stage_orders, verdict_text
from mpm_fem.app.report import render_both, write_report
from mpm_fem.measure.claims import Finding
from mpm_fem.measure.tables import load_tables

FIGURES = Path(__file__).resolve().parent.parent / "figures"
#: The longest main text, in words of prose and table cells.
MAIN_WORDS = 8000
VERDICT_WORDS = ("confirmed", "partly", "differs", "refuted", "not measured")
#: A verdict word pasted into prose: emphasised, or "partly" at all (its count says it instead).
PASTED = re.compile(r"\*{1,2}(" + "|".join(VERDICT_WORDS) + r")\*{1,2}|\bpartly\b", re.IGNORECASE)
_RULE = re.compile(r"^\|?(\s*:?-+:?\s*\|)+\s*$")


def main_words(markdown: str) -> int:
    """The words of ``markdown`` counting prose, headings and table cells; not table rules, image links,
    anchors or comments."""
    n = 0
    for line in (line.strip() for line in markdown.splitlines()):
        if not line or line.startswith(("<a id=", "<!--", "![")) or _RULE.match(line):
            continue
        n += len(line.replace("|", " ").split())
    return n


def prose_lines(markdown: str) -> list[str]:
    """The lines of ``markdown`` that are prose: not table rows, headings, images, anchors or comments."""
    return [line for line in markdown.splitlines()
            if line.strip() and not line.startswith(("|", "#", "![", "<a id=", "<!--"))]


@pytest.fixture(scope="module")
def written():
    with tempfile.TemporaryDirectory() as folder:
        shutil.copytree(FIGURES, folder, dirs_exist_ok=True, ignore=shutil.ignore_patterns(".cache"))
        path = write_report(Path(folder))
        return path.read_text(), (path.parent / "APPENDIX.md").read_text(), (path.parent / "APPENDIX.md").exists()


@pytest.fixture(scope="module")
def tables():
    return load_tables(FIGURES)


def test_the_main_text_is_at_most_eight_thousand_words(written):
    report, appendix, _ = written
    words = main_words(report)
    assert words <= MAIN_WORDS, f"main text {words} words"
    assert main_words(appendix) > words, "the long evidence is in the appendix"


def test_the_word_count_leaves_out_rules_images_and_anchors():
    text = "# T\n\nTwo words.\n\n| a | b c |\n|---|---|\n| 1 | 2 |\n\n![x y z](a.png)\n\n<a id=\"q\"></a>\n"
    assert main_words(text) == 2 + 2 + 3 + 2


def test_the_abstract_is_at_most_five_sentences_each_a_finding_with_its_number(written):
    report = written[0]
    found = abstract_sentences(report)
    assert 1 <= len(found) <= 5, found
    for label in ("C11", "E6a", "E5", "E1", "E3"):
        said = [s for s in found if f"({label})" in s or f"; {label})" in s]
        assert len(said) == 1 and re.search(r"\d\.\d", said[0].replace(label, "")), (label, found)
    body = " ".join(found)
    assert "projection" in body and "Burgers" in body and "FEM" in body, body


def test_no_verdict_word_is_pasted_into_prose(written):
    """The main text's prose never emphasises a verdict word nor says "partly": the verdict cells do, with the
    count where the finding states one."""
    report, appendix, _ = written
    pasted = [line[:120] for line in prose_lines(report) if PASTED.search(line)]
    assert not pasted, pasted
    emphasised = [line[:120] for line in prose_lines(appendix) if re.search(r"\*\*(" + "|".join(VERDICT_WORDS)
                                                                            + r")\*\*", line)]
    assert not emphasised, emphasised


def test_the_check_finds_a_pasted_verdict_word():
    text = "| C5 | **partly** |\n\nThe claim is **refuted** here.\n\nIt holds partly.\n\nA count: 3 of 4.\n"
    assert [line for line in prose_lines(text) if PASTED.search(line)] == ["The claim is **refuted** here.",
                                                                          "It holds partly."]


def test_a_count_replaces_partly_where_the_finding_states_one():
    layouts = ({"layout": "regular", "holds": "False"}, {"layout": "jittered", "holds": "True"},
               {"layout": "random", "holds": "True"})
    assert verdict_text(Finding("partly", "e", "s", layouts)) == "holds on 2 of 3 layouts"
    assert counted(Finding("partly", "x on 17 of 24 settings and meshes; y")) == "holds on 17 of 24 settings and meshes"
    assert verdict_text(Finding("partly", "no count here")) == "partly"
    assert verdict_text(Finding("differs", "on 1 of 2 meshes")) == "differs"


def test_a_partial_verdict_whose_table_holds_on_none_is_counted_with_its_other_part():
    """A table that holds on none (or all) of its rows does not by itself make a verdict partial: the count
    names the claim's other part too, as E6's settings and remedies."""
    none = tuple({"setting": s, "holds": "no"} for s in ("a", "b", "c", "d"))
    evidence = "the model holds on 0 of 4 settings; not on a, b; which remedies: right on 21 of 26 remedies, not x"
    assert verdict_text(Finding("partly", evidence, "s", none)) == "holds on 0 of 4 settings and 21 of 26 remedies"
    some = ({"setting": "a", "holds": "yes"}, *none[1:])
    assert verdict_text(Finding("partly", evidence, "s", some)) == "holds on 1 of 4 settings"


def test_the_appendix_exists_and_every_section_links_to_it(written):
    report, appendix, exists = written
    assert exists and appendix.startswith("# ") and "[REPORT.md](REPORT.md)" in appendix
    sections = re.split(r"\n(?=## )", report)[1:]
    assert len(sections) >= 6, [s.splitlines()[0] for s in sections]
    for section in sections:
        if section.startswith("## Abstract"):
            continue
        assert "](APPENDIX.md" in section, section.splitlines()[0]
    assert "## Appendix" not in report and "## Appendix A: the verdict rule of each claim" in appendix


def test_no_nan_anywhere_in_the_report(written):
    report, appendix, _ = written
    for name, text in (("REPORT.md", report), ("APPENDIX.md", appendix)):
        hits = re.findall(r".{30}(?<![\w.])nan(?![\w.]).{0,30}", text, re.IGNORECASE)
        assert not hits, (name, hits)


def test_every_term_of_the_method_is_defined(written):
    terms = written[0].split("### 2.2 Terms")[1].split("\n### ")[0]
    for term in ("stable dt rule", "advective dt rule", "exact form of a stage", "misfit, misfit_raw",
                 "Burgers solutions"):
        assert f"| {term} |" in terms, term
    assert "u_left = 0.5" in terms and "A = 2" in terms, terms


# ----------------------------------------------------------------------------- the quick tier's first screen

def _quick_like(tables):
    """The committed tables cut to what the quick tier's stage-exact set measures: one mesh pair a problem,
    the coarsest (h = 0.01 -> 0.005 on Sod), and no error budget, remedies or defect study."""
    out = {k: v for k, v in tables.items() if not k.startswith(("budget/", "remedies/", "defect/", "drift/"))}
    summary = tables["mechanism/summary"]
    coarsest = {p: max(float(r["h_coarse"]) for r in summary if r["problem"] == p) for p in ("sod", "burgers")}
    out["mechanism/summary"] = [r for r in summary if float(r["h_coarse"]) == coarsest[r["problem"]]
                                and r["ppc"] == "4"]
    out["versions"] = [r for r in tables["versions"] if r["table"] in out or r["table"].startswith("mechanism/")]
    return out


def test_the_quick_first_screen_names_the_stage_with_its_number_and_the_fem(tables):
    quick = _quick_like(tables)
    sod = stage_orders(quick, "sod")
    assert sod is not None and sod.stage == "projection" and sod.lo > 0 > sod.mpm_lo, sod
    report, _ = render_both(quick, [])
    lines = report.splitlines()[:40]
    first = "\n".join(line for line in lines if not line.startswith("# "))
    first = first.split("## 1 Introduction")[0]
    assert re.search(r"Making the projection stage \(a particle quadrature\) exact alone, "
                     r"every other stage in MPM form, stops the growth: .*"
                     rf"to \[{sod.lo:.2f}, {sod.hi:.2f}\] on Sod", first), first
    assert re.search(r"fixed-mesh FEM's density error falls on \d+ of \d+ refinements \(orders \d\.\d\d to \d\.\d\d\)"
                     r".*factor \d", first), first
    assert re.search(r"[(;] E5\)|\(E5\)", first) and "not measured" in re.split(r"[(;] ?E6a\)", first)[1], first
