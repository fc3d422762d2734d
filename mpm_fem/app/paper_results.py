"""The report's Results, the appendix's further results and the appendix of each claim's evidence.

The verdicts counted, then every claim in the order of its study's page: statement, verdict, its
finding in words, one figure (shown once, at the first claim that reads it), the failed runs and the
links to its evidence (with the source's words), its rule and its study's tables in the appendix. The
claims of the studies of :data:`~mpm_fem.app.paper_findings.IN_APPENDIX` are said so in the appendix
(:func:`further_results`), the main text pointing to them. A finding without a
sentence is said by its evidence's first clause, whole; one without a table shows its evidence as a
list cut at its semicolons.
"""

from __future__ import annotations

from mpm_fem.app.markdown import anchor_of, bullets, figure, markdown_table, prose, readable, sentences, split_outside
from mpm_fem.app.pages import Page
from mpm_fem.app.paper_abstract import KEY_FIGURES
from mpm_fem.app.paper_findings import (
    APPENDIX_FILE,
    COUNT_MEANING,
    IN_APPENDIX,
    Found,
    claim_href,
    first_clause,
    verdict_text,
)
from mpm_fem.measure.claims import STATEMENTS, Claim, Finding, claims_of
from mpm_fem.measure.claims.base import PARTLY
from mpm_fem.measure.claims.rules import VERDICT_MEANING
from mpm_fem.measure.tables import Tables

#: The results' section of the claims on the record itself (E4): they read the tables' stamps.
REPRODUCTION = Page("reproduce", "Reproduction", "Every table carries the version of the code that wrote it; one "
                    "command regenerates them all. Each table's stamp is in the appendix.")


def _has_tables(tables: Tables, study: str) -> bool:
    """Whether ``tables`` hold a table of ``study`` (its appendix is written only then)."""
    return any(rows for name, rows in tables.items() if name.startswith(study + "/"))


def evidence(f: Finding) -> list[str]:
    """The evidence as its small table, or (a criterion without one) as a list cut at its semicolons."""
    if f.table:
        columns = list(dict.fromkeys(k for row in f.table for k in row))
        return markdown_table(list(f.table), columns) + [""]
    return bullets(split_outside(f.evidence))


def claim_section(c: Claim, f: Finding, figure_lines: list[str] = (), appendix: str = "",
                  linked: bool = True) -> list[str]:
    """A claim in the results: statement, verdict (a one-cell table), its finding in words, one figure, the
    failed runs, and the links to its evidence (which gives the source's words), its rule and (``linked``: a
    study in the folder) its study's tables in the appendix."""
    text = f.sentence.strip() or first_clause(f)
    links = (f"Evidence: [table](APPENDIX.md#evidence-{anchor_of(c.label)}), "
             f"[rule](APPENDIX.md#rule-{anchor_of(c.label)})"
             + (f", [study](APPENDIX.md#{appendix})." if appendix and linked else "."))
    return [f'<a id="{anchor_of(c.label)}"></a>', "", f"#### {c.label}: {c.statement}", "",
            *markdown_table([{"verdict": verdict_text(f)}]), "",
            *([readable(text[:1].upper() + text[1:]).rstrip(".") + ".", ""] if text else []), *figure_lines,
            *failed_runs(f), links, ""]


def evidence_section(c: Claim, f: Finding) -> list[str]:
    """A claim's evidence in the appendix: its finding, its small table (or its evidence as a list), the
    failed runs, and the link back to its results."""
    return [f'<a id="evidence-{anchor_of(c.label)}"></a>', "", f"#### {c.label}: {c.statement}", "",
            *markdown_table([{"verdict": verdict_text(f), "source": c.source}]), "", *evidence(f), *failed_runs(f),
            f"In the report: [{c.label}]({claim_href(c, APPENDIX_FILE)}).", ""]


def failed_runs(f: Finding) -> list[str]:
    """The runs of the finding's tables that failed, by cause (count, where, cause), as a paragraph; how the
    verdict reads them (left out, or failing every condition they enter) is in the evidence."""
    if not f.failed:
        return []
    return [f"Runs that failed (count, where they ran, cause): {'; '.join(f.failed)}.", ""]


def claim_figure(c: Claim, page: Page | None, captions: dict) -> list[str]:
    """The first figure of the page's views of a table the claim reads (none if no view has one)."""
    for v in page.views if page else ():
        if v.figure and v.table in c.tables and v.figure in captions:
            return figure(page.name, v.figure, captions)
    return []


def verdict_counts(found: Found) -> list[str]:
    """How many of the source's claims and of the extensions got each verdict, as a table (a count of
    ``partly`` verdicts, whatever each one's count)."""
    rows = []
    for v in VERDICT_MEANING:
        source = sum(f.verdict == v for c, f in found.values() if c.id.startswith("C"))
        extensions = sum(f.verdict == v for c, f in found.values() if c.id.startswith("E"))
        plane = sum(f.verdict == v for c, f in found.values() if c.id.startswith("D"))
        if source or extensions or plane:
            rows.append({"verdict": COUNT_MEANING[0] if v == PARTLY else v, "the source's claims": source,
                         "the extensions": extensions, "in two dimensions": plane})
    return markdown_table(rows) + [""]


def results(tables: Tables, found: Found, pages: list[Page], captions: dict, summary) -> list[str]:
    """Every claim in the order of its study's page: the studies without a table say so. A figure is shown
    once, at the first claim that reads it; every claim's evidence table is in the appendix. The studies of
    :data:`IN_APPENDIX` are named in one paragraph, their claims said in :func:`further_results`."""
    lines = ["## Results", "", *prose(
        "The verdicts, counted, then every claim with its key number, the source's claims first; the subsections "
        "say each finding in words, and each claim's evidence is a table of "
        "[the appendix](APPENDIX.md#appendix-evidence)."), *verdict_counts(found),
        "*The source's claims.*", "", *summary("C"), "", "*The extensions.*", "", *summary("E"), "",
        *prose("The two-dimensional claims D1-D9 are said in [their own section](#two-dimensions).")]
    # the 2D claims are said in the report's own section (mpm_fem.app.paper_plane), their tables in the appendix
    shown = [p for p in _claim_pages(pages) if p.name not in IN_APPENDIX]
    lines += _page_sections(tables, found, shown, captions, set(KEY_FIGURES))  # the first screen shows these
    further = [p for p in _claim_pages(pages) if p.name in IN_APPENDIX]
    if further:
        lines += prose(f"The summary above lists the claims of {_NUMBER.get(len(further), len(further))} further "
                       "studies, said in full in [the appendix's further results](APPENDIX.md#appendix-further): "
                       + "; ".join(p.title[:1].lower() + p.title[1:] for p in further) + ".")
    return lines


def further_results(tables: Tables, found: Found, pages: list[Page], captions: dict) -> list[str]:
    """The appendix's further results: the claims of the studies of :data:`IN_APPENDIX`, each as in the
    results (:func:`claim_section`); none when no page of them has claims."""
    further = [p for p in _claim_pages(pages) if p.name in IN_APPENDIX]
    if not further:
        return []
    return ['<a id="appendix-further"></a>', "", "## Appendix: further results", "",
            *prose("The claims the main text's summary lists but does not say in full, said as in its results."),
            *_page_sections(tables, found, further, captions, set(), "further-")]


_NUMBER = {1: "one", 2: "two", 3: "three", 4: "four"}


def _claim_pages(pages: list[Page]) -> list[Page]:
    """The pages (and the record's own, :data:`REPRODUCTION`) with 1D claims: the 2D claims have their own
    section."""
    return [p for p in [*pages, REPRODUCTION] if claims_of(p.name)
            and not all(c.id.startswith("D") for c in claims_of(p.name))]


def _page_sections(tables: Tables, found: Found, pages: list[Page], captions: dict, drawn: set,
                   prefix: str = "") -> list[str]:
    """A subsection per page (its anchor ``prefix`` + its name, its caption's first sentence, then each
    claim's section); a figure already in ``drawn`` (paths, updated) is not shown again."""
    lines = []
    for page in pages:
        present = any(tables.get(t) for c in claims_of(page.name) for t in c.tables) \
            and (page is REPRODUCTION or _has_tables(tables, page.name))
        lines += [f'<a id="{prefix}{page.name}"></a>', "", f"### {page.title}", "",
                  *prose(sentences(page.caption)[0] + " The study's settings in full: [its appendix]"
                         f"(APPENDIX.md#appendix-{page.name})." if present and page is not REPRODUCTION else
                         page.caption if present else
                         f"No table of the study `{page.name}` in this folder: its claims are not measured here.")]
        for c in claims_of(page.name):
            f = found[c.label][1]
            picture = claim_figure(c, page, captions.get(page.name, {})) if present else []
            path = picture[0].rsplit("](", 1)[1].rstrip(")") if picture else ""
            if path in drawn:
                picture = []
            drawn.add(path)
            lines += claim_section(c, f, picture, ("appendix-stamps" if page is REPRODUCTION else
                                                   f"appendix-{page.name}") if present else "", linked=present)
    return lines


def evidence_appendix(found: Found) -> list[str]:
    """Every claim's evidence, in the order of the summary."""
    order = list(STATEMENTS)
    lines = ['<a id="appendix-evidence"></a>', "", "## Appendix: the evidence of each claim", "",
             *prose("Each claim's small table (or its evidence as a list), as its criterion computed it from the "
                    "study tables; the report's results say each one in words.")]
    for c, f in sorted(found.values(), key=lambda cf: (order.index(cf[0].id), cf[0].problem)):
        lines += evidence_section(c, f)
    return lines
