"""``REPORT.md``, rendered from the claims (:mod:`mpm_fem.claims`) and the tables, never typed.

Each study describes its section as a :class:`Page`: a title, a caption in words, the views of its
tables (a table, the rows and columns shown, the figure beside it) and its other figures with one-line
captions. The report opens with a one-screen summary (claim, verdict, key number, link), then shows
every study's claims (verdict, evidence, the source's number, the thresholds) beside the tables and
figures they rest on. Every number in it comes from the tables it was rendered from, so rendering the
committed tables again gives the same bytes: ``python -m mpm_fem.report [--out figures]``.
"""

from __future__ import annotations

import argparse
import importlib
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path

from .claims import CLAIMS, STATEMENTS, Claim, claims_of, select
from .output import write_atomic
from .tables import Tables, load_tables

TITLE = "# mpm-fem: where does the error of MPM come from?"
#: Views longer than this are cut, with a pointer to the whole CSV.
MAX_ROWS = 40


@dataclass(frozen=True)
class View:
    """Rows of ``table`` (``"sod/convergence"``) matching ``where``, in ``columns`` (all when empty),
    under ``caption``, with the ``figure`` (a file in the study's folder) shown above them."""

    table: str
    caption: str
    columns: tuple[str, ...] = ()
    where: dict = field(default_factory=dict)
    figure: str = ""


@dataclass(frozen=True)
class Page:
    """A study's section: ``name`` (its folder), ``title``, ``caption`` (words, no numbers), its
    ``views`` and its other ``figures`` as ``(file, one-line caption)``."""

    name: str
    title: str
    caption: str
    views: tuple[View, ...] = ()
    figures: tuple[tuple[str, str], ...] = ()


# ----------------------------------------------------------------------------- Markdown

def cell(value) -> str:
    """One table cell: numbers to four significant digits, text with its pipes escaped."""
    text = str(value).strip()
    try:
        number = float(text)
    except ValueError:
        return text.replace("|", "\\|").replace("\n", " ")
    if not math.isfinite(number):
        return ""
    if text.lstrip("-").isdigit():
        return text
    return format(number, ".4g")


def markdown_table(rows: list[dict], columns: tuple[str, ...] | list[str] = ()) -> list[str]:
    """A Markdown table of ``rows`` in ``columns`` (every column of the first row when empty)."""
    columns = list(columns) or list(rows[0])
    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    return lines + ["| " + " | ".join(cell(r.get(c, "")) for c in columns) + " |" for r in rows]


def anchor(claim: Claim) -> str:
    return claim.label.lower().replace(" (", "-").replace(")", "")


def key_number(evidence: str) -> str:
    """The summary's key number: the first clause of the evidence."""
    return evidence.split(";")[0]


def code_version(tables: Tables) -> str:
    """The code version most tables were written by (E4 names any other)."""
    codes = [r["code"] for r in tables.get("versions", [])]
    return max(set(codes), key=codes.count) if codes else "none"


def is_quick(tables: Tables) -> bool:
    return any(r["quick"] == "True" for r in tables.get("versions", []))


# ----------------------------------------------------------------------------- sections

def summary(tables: Tables, link: str = "") -> list[str]:
    """The one-screen summary: every claim, its verdict, key number and section (``link`` prefixes
    the anchors, e.g. ``figures/REPORT.md`` from the README)."""
    lines = ["| claim | statement | verdict | key number |", "|---|---|---|---|"]
    for cid, statement in STATEMENTS.items():
        found = sorted((c for c in CLAIMS if c.id == cid), key=lambda c: c.problem)
        if not found:
            lines.append(f"| {cid} | {statement} | not measured | no criterion registered |")
        for c in found:
            verdict, evidence = c.verdict(tables)
            lines.append(f"| [{c.label}]({link}#{anchor(c)}) | {cell(statement)} | **{verdict}** | "
                         f"{cell(key_number(evidence))} |")
    return lines


def claim_section(c: Claim, tables: Tables) -> list[str]:
    verdict, evidence = c.verdict(tables)
    lines = [f'<a id="{anchor(c)}"></a>', "", f"### {c.label}: {c.statement}", "",
             f"**{verdict}**: {evidence}.", "",
             f"- Source: {c.source}.", f"- Verdict rule: {c.thresholds}.",
             "- Tables: " + ", ".join(f"[{t}.csv]({t}.csv)" for t in c.tables if "/" in t) + "."]
    return lines + ([f"- Why: {c.explanation}", ""] if c.explanation else [""])


def figure(page: str, file: str, caption: str) -> list[str]:
    return [f"![{caption}]({page}/{file})", "", f"*{caption}*", ""]


def view_section(page: Page, v: View, tables: Tables) -> list[str]:
    rows = select(tables.get(v.table, []), **v.where)
    lines = [f"#### {v.caption}", ""]
    if v.figure:
        lines += figure(page.name, v.figure, v.caption)
    if not rows:
        return lines + [f"No rows in `{v.table}.csv`.", ""]
    lines += markdown_table(rows[:MAX_ROWS], v.columns)
    more = len(rows) - MAX_ROWS
    return lines + ([""] + ([f"{more} more rows in [{v.table}.csv]({v.table}.csv)."] if more > 0 else []) + [""])


def page_section(page: Page, tables: Tables) -> list[str]:
    lines = [f'<a id="{page.name}"></a>', "", f"## {page.title}", "", page.caption, ""]
    for c in claims_of(page.name):
        lines += claim_section(c, tables)
    for v in page.views:
        lines += view_section(page, v, tables)
    for file, caption in page.figures:
        lines += figure(page.name, file, caption)
    own = sorted(t for t in tables if t.startswith(page.name + "/"))
    return lines + ["All tables, with their settings in the JSON beside each: "
                    + ", ".join(f"[{t.split('/')[1]}.csv]({t}.csv)" for t in own) + ".", ""]


def reproduction_section(tables: Tables) -> list[str]:
    lines = ['<a id="reproduce"></a>', "", "## Reproduction", ""]
    for c in claims_of("reproduce"):
        lines += claim_section(c, tables)
    return lines + markdown_table(tables.get("versions", []), ("table", "code", "quick")) + [""]


def render(tables: Tables, pages: list[Page]) -> str:
    """The whole report, from ``tables`` (:func:`mpm_fem.tables.load_tables`) and the study ``pages``."""
    quick = is_quick(tables)
    head = [TITLE, "",
            f"Rendered by `python -m mpm_fem.report` from the tables of code version {code_version(tables)}, "
            + ("written by `mpm-fem reproduce --quick`: a subset of the meshes of each study." if quick
               else "written by `mpm-fem reproduce --full`."),
            "Source: L.-T. Tran and M. Berzins, Error Analysis for Material Point Method and a case study from Gas "
            "Dynamics (slides). The claims, the source's tables and the corrections made to them are listed in "
            "`docs/claims.md` of the repository.", "",
            "## Summary", ""]
    lines = head + summary(tables) + [""]
    for page in pages:
        if any(t.startswith(page.name + "/") for t in tables):
            lines += page_section(page, tables)
    return "\n".join(lines + reproduction_section(tables))


# ----------------------------------------------------------------------------- the command

def study_pages(folder: Path) -> list[Page]:
    """Every study's :class:`Page`, found by name (``studies.<name>.PAGE``): the studies are the top
    layer and are loaded as plug-ins, never imported by this module. A study without a page gets its
    figures listed under its folder name."""
    studies = importlib.import_module("studies")
    pages = []
    for name in studies.STUDIES:
        page = getattr(importlib.import_module(f"studies.{name}"), "PAGE", None)
        if page is None:
            pngs = sorted(p.name for p in (Path(folder) / name).glob("*.png"))
            page = Page(name, name, "Tables and figures of this study.", figures=tuple((f, f) for f in pngs))
        pages.append(page)
    return pages


def write_report(out: Path, pages: list[Page] | None = None) -> Path:
    """Render ``<out>/REPORT.md`` from the tables in ``out``; returns its path."""
    out = Path(out)
    path = out / "REPORT.md"
    write_atomic(path, render(load_tables(out), study_pages(out) if pages is None else pages) + "\n")
    return path


def reproduce(options) -> Path:
    """Run every study with ``options`` (:class:`mpm_fem.study.StudyOptions`), then write the report."""
    studies = importlib.import_module("studies")
    for name in studies.STUDIES:
        importlib.import_module(f"studies.{name}").run(options)
    return write_report(options.out)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m mpm_fem.report",
                                     description="Render REPORT.md from the tables already written; runs nothing.")
    parser.add_argument("--out", type=Path, default=Path("figures"), help="the figures folder (default: figures)")
    args = parser.parse_args(argv)
    if not (args.out / "REPORT.md").parent.is_dir():
        print(f"error: no folder {args.out}", file=sys.stderr)
        return 2
    print(f"report written to {write_report(args.out)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
