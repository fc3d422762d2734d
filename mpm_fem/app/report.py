"""``REPORT.md``, rendered from the claims (:mod:`mpm_fem.measure.claims`) and the tables, never typed.

Each study's section is a :class:`~mpm_fem.app.pages.Page` (:data:`mpm_fem.app.pages.PAGES`): a title, a
caption in words, and views of its tables (a table, the rows and columns shown, the figure beside
it); the figures' one-line captions are those the study recorded when it drew them. The report opens
with a one-screen summary (claim, verdict, key number, link), then shows every study's claims
(verdict, evidence, the source's number, the thresholds) beside the tables and figures they rest on.
Every number in it comes from the tables it was rendered from, so rendering the committed tables
again gives the same bytes: ``python -m mpm_fem.app.report [--out figures]``.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from mpm_fem.app.output import write_atomic
from mpm_fem.app.pages import PAGES, Page, View  # noqa: F401  (View: part of this module's interface)
from mpm_fem.app.plots import CAPTIONS
from mpm_fem.measure.claims import CLAIMS, STATEMENTS, Claim, claims_of, select
from mpm_fem.measure.tables import Tables, load_tables
from mpm_fem.measure.version import code_version as current_code_version

TITLE = "# mpm-fem: where does the error of MPM come from?"
#: Views longer than this are cut, with a pointer to the whole CSV.
MAX_ROWS = 40


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


def figure(page: str, file: str, captions: dict) -> list[str]:
    caption = captions.get(file, file)
    return [f"![{caption}]({page}/{file})", "", f"*{caption}*", ""]


def captions_of(folder: Path) -> dict[str, str]:
    """``{file: one-line caption}`` of the figures in ``folder``: recorded by the study when it drew
    them (``figures.json``), else the file name of every PNG."""
    index = Path(folder) / CAPTIONS
    if index.exists():
        return json.loads(index.read_text())
    return {p.name: p.name for p in sorted(Path(folder).glob("*.png"))}


def view_section(page: Page, v: View, tables: Tables, captions: dict) -> list[str]:
    rows = select(tables.get(v.table, []), **v.where)
    lines = [f"#### {v.caption}", ""]
    if v.figure:
        lines += figure(page.name, v.figure, captions)
    if not rows:
        return lines + [f"No rows in `{v.table}.csv`.", ""]
    lines += markdown_table(rows[:MAX_ROWS], v.columns)
    more = len(rows) - MAX_ROWS
    return lines + ([""] + ([f"{more} more rows in [{v.table}.csv]({v.table}.csv)."] if more > 0 else []) + [""])


def page_section(page: Page, tables: Tables, captions: dict) -> list[str]:
    lines = [f'<a id="{page.name}"></a>', "", f"## {page.title}", "", page.caption, ""]
    for c in claims_of(page.name):
        lines += claim_section(c, tables)
    for v in page.views:
        lines += view_section(page, v, tables, captions)
    shown = {v.figure for v in page.views}
    for file in captions:
        if file not in shown:
            lines += figure(page.name, file, captions)
    own = sorted(t for t in tables if t.startswith(page.name + "/"))
    return lines + ["All tables, with their settings in the JSON beside each: "
                    + ", ".join(f"[{t.split('/')[1]}.csv]({t}.csv)" for t in own) + ".", ""]


def reproduction_section(tables: Tables) -> list[str]:
    lines = ['<a id="reproduce"></a>', "", "## Reproduction", ""]
    for c in claims_of("reproduce"):
        lines += claim_section(c, tables)
    return lines + markdown_table(tables.get("versions", []), ("table", "code", "quick")) + [""]


def render(tables: Tables, pages, captions: dict[str, dict] | None = None) -> str:
    """The whole report, from ``tables`` (:func:`mpm_fem.measure.tables.load_tables`), the study ``pages`` and
    the figure ``captions`` of each study folder (``{study: {file: caption}}``)."""
    captions = captions or {}
    quick = is_quick(tables)
    head = [TITLE, "",
            f"Rendered by `python -m mpm_fem.app.report` from the tables of code version {code_version(tables)}, "
            + ("written by `mpm-fem reproduce --quick`: a subset of the meshes of each study." if quick
               else "written by `mpm-fem reproduce --full`.")
            + ("" if code_version(tables) == current_code_version()
               else f" The current code is version {current_code_version()}: the figures lag it ([E4](#e4))."),
            "Source: L.-T. Tran and M. Berzins, Error Analysis for Material Point Method and a case study from Gas "
            "Dynamics (slides). The claims, the source's tables and the corrections made to them are listed in "
            "`docs/claims.md` of the repository.", "",
            "## Summary", ""]
    lines = head + summary(tables) + [""]
    for page in pages:
        if any(t.startswith(page.name + "/") for t in tables):
            lines += page_section(page, tables, captions.get(page.name, {}))
    return "\n".join(lines + reproduction_section(tables))


# ----------------------------------------------------------------------------- the command

def study_pages(folder: Path) -> list[Page]:
    """The pages of :data:`mpm_fem.app.pages.PAGES`, then a plain page for every other study folder."""
    named = {p.name for p in PAGES}
    others = [Page(d.name, d.name, "Tables and figures of this study.") for d in sorted(Path(folder).iterdir())
              if d.is_dir() and d.name not in named and any(d.glob("*.csv"))]
    return list(PAGES) + others


def write_report(out: Path, pages: list[Page] | None = None) -> Path:
    """Render ``<out>/REPORT.md`` from the tables and figure captions in ``out``; returns its path."""
    out = Path(out)
    pages = study_pages(out) if pages is None else pages
    text = render(load_tables(out), pages, {p.name: captions_of(out / p.name) for p in pages})
    path = out / "REPORT.md"
    write_atomic(path, text + "\n")
    return path


def reproduce(options) -> Path:
    """Run every study with ``options`` (:class:`mpm_fem.app.study.StudyOptions`), then write the report."""
    from mpm_fem.app.study import STUDIES, run_study

    for name in STUDIES:
        run_study(name, options)
    return write_report(options.out)


README_BEGIN = "<!-- results in brief: generated by `python -m mpm_fem.app.report --readme README.md` -->"
README_END = "<!-- end of the results in brief -->"


def results_in_brief(tables: Tables, report: str = "figures/REPORT.md") -> str:
    """README's "Results in brief": the summary of the report, its links pointing into ``report``."""
    return "\n".join([README_BEGIN, f"Verdicts computed from the committed tables (code version "
                      f"{code_version(tables)}); each claim links to its section of `{report}`.", "",
                      *summary(tables, report), README_END])


def update_readme(readme: Path, tables: Tables) -> None:
    """Replace the block between :data:`README_BEGIN` and :data:`README_END` of ``readme``."""
    text = Path(readme).read_text()
    if README_BEGIN not in text or README_END not in text:
        raise ValueError(f"{readme} has no results block ({README_BEGIN} ... {README_END})")
    head, rest = text.split(README_BEGIN, 1)
    write_atomic(Path(readme), head + results_in_brief(tables) + rest.split(README_END, 1)[1])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m mpm_fem.app.report",
                                     description="Render REPORT.md from the tables already written; runs nothing.")
    parser.add_argument("--out", type=Path, default=Path("figures"), help="the figures folder (default: figures)")
    parser.add_argument("--readme", type=Path, help="also rewrite the results in brief of this README")
    args = parser.parse_args(argv)
    if not args.out.is_dir():
        print(f"error: no folder {args.out}", file=sys.stderr)
        return 2
    print(f"report written to {write_report(args.out)}")
    if args.readme:
        update_readme(args.readme, load_tables(args.out))
        print(f"results in brief written to {args.readme}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
