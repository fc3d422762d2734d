"""``REPORT.md``, rendered from the claims (:mod:`mpm_fem.measure.claims`) and the tables, never typed.

The report reads as a paper. Its first screen: the title, an abstract formatted from the verdicts
and their key numbers, the verdict table split into the source's claims and the extensions, the
two figures that carry the study, and the caveats (the settings that differ from the source's, the
tier, whether the figures lag the code). Then one section per study with one subsection per claim
(statement, source, verdict, one figure, the evidence and the rule), then the deep tier's verdicts
when ``<out>/deep/`` holds tables, then the appendices: each study's tables and figures
(:class:`~mpm_fem.app.pages.Page`, :data:`mpm_fem.app.pages.PAGES`), linked from its claims. Every
number comes from the tables it was rendered from, so rendering the committed tables again gives
the same bytes: ``python -m mpm_fem.app.report [--out figures]``.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import replace
from functools import partial
from pathlib import Path

from mpm_fem.app.output import write_atomic
from mpm_fem.app.pages import PAGES, Page, View  # noqa: F401  (View: part of this module's interface)
from mpm_fem.app.plots import CAPTIONS
from mpm_fem.app.study import NOT_JUDGED, QUICK_LEAVES_OUT
from mpm_fem.measure.claims import CLAIMS, STATEMENTS, Claim, claims_of, select
from mpm_fem.measure.tables import Tables, load_tables
from mpm_fem.measure.version import code_version as current_code

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


#: The longest key number of the summary; the whole evidence is in the claim's section.
KEY_LENGTH = 80


def key_number(evidence: str, limit: int = KEY_LENGTH) -> str:
    """The summary's key number: the first clause of the evidence, cut after its last comma-separated
    item that fits ``limit`` characters (then ending in " ...")."""
    first = evidence.split(";")[0].strip()
    if len(first) <= limit:
        return first
    items, kept = first.split(", "), ""
    for item in items:
        longer = f"{kept}, {item}" if kept else item
        if len(longer) > limit - 4:
            break
        kept = longer
    return f"{kept or first[: limit - 4]} ..."


def code_version(tables: Tables) -> str:
    """The code version most tables were written by (E4 names any other)."""
    codes = [r["code"] for r in tables.get("versions", [])]
    return max(set(codes), key=codes.count) if codes else "none"


def is_quick(tables: Tables) -> bool:
    return any(r.get("tier") == "quick" for r in tables.get("versions", []))


def not_judged(tables: Tables) -> list[str]:
    """A caveat line per tier of the tables: the verdicts it does not judge (:data:`NOT_JUDGED`) and
    the tier that judges each."""
    found = dict.fromkeys(r.get("tier") for r in tables.get("versions", []))
    return [f"- The {tier} tier does not judge " + "; ".join(f"{c} (the {by} tier does: {why})"
                                                            for c, (by, why) in NOT_JUDGED[tier].items()) + "."
            for tier in found if NOT_JUDGED.get(tier)]


# ----------------------------------------------------------------------------- sections

def summary(tables: Tables, link: str = "", kind: str = "") -> list[str]:
    """The one-screen summary: every claim, its verdict, key number and section (``link`` prefixes
    the anchors, e.g. ``figures/REPORT.md`` from the README); ``kind`` ``"C"`` (the source's claims)
    or ``"E"`` (the extensions) keeps those only."""
    lines = ["| claim | statement | verdict | key number |", "|---|---|---|---|"]
    for cid, statement in STATEMENTS.items():
        if not cid.startswith(kind):
            continue
        found = sorted((c for c in CLAIMS if c.id == cid), key=lambda c: c.problem)
        if not found:
            lines.append(f"| {cid} | {statement} | not measured | no criterion registered |")
        for c in found:
            verdict, evidence = c.verdict(tables)
            lines.append(f"| [{c.label}]({link}#{anchor(c)}) | {cell(statement)} | **{verdict}** | "
                         f"{cell(key_number(evidence))} |")
    return lines


def claim_section(c: Claim, tables: Tables, figure_lines: list[str] = (), appendix: str = "") -> list[str]:
    """A claim: statement, verdict, its figure, the evidence, the source and the rule, the tables."""
    verdict, evidence = c.verdict(tables)
    lines = [f'<a id="{anchor(c)}"></a>', "", f"### {c.label}: {c.statement}", "", f"**{verdict}**", "",
             *figure_lines, f"{evidence}.", "",
             f"- Source: {c.source}.", f"- Verdict rule: {c.thresholds}.",
             "- Tables: " + ", ".join(f"[{t}.csv]({t}.csv)" for t in c.tables if "/" in t)
             + (f" ([appendix](#{appendix}))." if appendix else ".")]
    return lines + ([f"- Why: {c.explanation}", ""] if c.explanation else [""])


def claim_figure(c: Claim, page: Page | None, captions: dict) -> list[str]:
    """The first figure of the page's views of a table the claim reads (none if no view has one)."""
    for v in page.views if page else ():
        if v.figure and v.table in c.tables and v.figure in captions:
            return figure(page.name, v.figure, captions)
    return []


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
    """A study's claims, each with its figure, linking to the study's appendix."""
    lines = [f'<a id="{page.name}"></a>', "", f"## {page.title}", "", page.caption, ""]
    for c in claims_of(page.name):
        lines += claim_section(c, tables, claim_figure(c, page, captions), f"appendix-{page.name}")
    return lines


def missing_section(page: Page, tables: Tables) -> list[str]:
    """A study with no table in the folder (a tier run in part): its claims, each not measured, so that
    every claim of the summary has its section."""
    lines = [f'<a id="{page.name}"></a>', "", f"## {page.title}", "",
             f"No table of the study `{page.name}` in this folder: its claims are not measured here.", ""]
    for c in claims_of(page.name):
        lines += claim_section(c, tables)
    return lines


def appendix_section(page: Page, tables: Tables, captions: dict) -> list[str]:
    """A study's tables and every figure it drew."""
    lines = [f'<a id="appendix-{page.name}"></a>', "", f"## Appendix: {page.title}", ""]
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
    return lines + markdown_table(tables.get("versions", []), ("table", "code", "tier")) + [""]


#: The two figures that carry the study, shown on the first screen when the report's folder has them.
KEY_FIGURES = ("sod/convergence.png", "burgers/convergence.png")
#: The claims the abstract reports, in this order, with what each says in words.
ABSTRACT = (("C11", "Sod's shock tube"), ("C13", "viscous Burgers"), ("E1", "the error budget"),
            ("E3", "MPM against fixed-mesh FEM on the same mesh"))


def abstract(tables: Tables) -> list[str]:
    """Three to five sentences formatted from the verdicts and their key numbers."""
    found = {}
    for c in CLAIMS:
        found.setdefault(c.id, []).append((c, *c.verdict(tables)))
    source = [v for cid, vs in found.items() if cid.startswith("C") for _, v, _ in vs]
    counts = {v: source.count(v) for v in dict.fromkeys(source)}
    lines = [f"We judge {len(source)} verdicts on the source's claims and "
             f"{sum(len(vs) for cid, vs in found.items() if cid.startswith('E'))} on the extensions, each "
             "computed from the tables below: " + ", ".join(f"{n} {v}" for v, n in counts.items()) + "."]
    for cid, words in ABSTRACT:
        for c, verdict, evidence in found.get(cid, []):
            lines.append(f"On {words}{f' ({c.problem})' if c.problem else ''}, {c.id} is **{verdict}**: "
                         f"{key_number(evidence, 2 * KEY_LENGTH)}.")
    return [" ".join(lines), ""]


def caveats(tables: Tables, current: str | None) -> list[str]:
    """What a reader must know before the numbers: the tier, the study's settings that differ from the
    source's, and whether the figures lag the code (``current``: the code version now, if known)."""
    out = ["## Caveats", ""]
    out.append("- These tables come from `mpm-fem reproduce --quick`: a subset of the meshes of each study. A "
               "verdict judged on the finest mesh a study has can differ from the full record's "
               "(`mpm-fem reproduce --full`), which reaches finer meshes. The quick tier leaves out the studies "
               f"{' and '.join(QUICK_LEAVES_OUT)}: their questions are about the plateau of Sod's particle error, "
               "below its meshes." if is_quick(tables) else "- These tables come from `mpm-fem reproduce --full`.")
    out += not_judged(tables)
    written = code_version(tables)
    rows = tables.get("versions", [])
    behind = sorted({r["table"].split("/")[0] for r in rows if r["code"] != current})
    if current is not None and current != written:
        out.append(f"- **The figures lag the code**: the tables were written by code version {written}, the code "
                   f"is now {current}; `mpm-fem reproduce --full` regenerates them.")
    elif current is not None and behind:
        out.append(f"- **Part of the figures lag the code**: {len(rows) - sum(r['code'] != current for r in rows)} "
                   f"of {len(rows)} tables come from the current code ({current}); the studies "
                   f"{', '.join(behind)} still hold tables of an older code (the versions table, E4); "
                   "`mpm-fem reproduce --full` regenerates them.")
    elif current is not None:
        out.append(f"- The tables were written by the current code ({written}).")
    setting = {r["key"]: r["value"] for r in tables.get("settings", []) if r["table"] == "sod/convergence"}
    if "mpm.ppc" in setting:
        out.append(f"- Sod's convergence study runs {setting['mpm.ppc']} particles per cell at CFL "
                   f"{setting.get('mpm.cfl', '?')} (`sod/convergence.json`); the source prescribes 4-8 per cell and "
                   "states no time step: the claims on Sod state their verdict per setting where the tables hold "
                   "several.")
    return out + [""]


def render(tables: Tables, pages, captions: dict[str, dict] | None = None, current: str | None = None,
           deep: Tables | None = None) -> str:
    """The whole report, from ``tables`` (:func:`mpm_fem.measure.tables.load_tables`), the study ``pages``,
    the figure ``captions`` of each study folder (``{study: {file: caption}}``), the code version now
    (``current``) and the deep tier's tables (``deep``, ``None`` when there are none)."""
    captions = captions or {}
    head = [TITLE, "",
            f"Rendered by `python -m mpm_fem.app.report` from the tables of code version {code_version(tables)}. "
            "Source: L.-T. Tran and M. Berzins, Error Analysis for Material Point Method and a case study from Gas "
            "Dynamics (slides; the claims, the source's tables and the corrections made to them: `docs/claims.md` "
            "of the repository).", "", "## Abstract", "", *abstract(tables),
            "## The source's claims", "", *summary(tables, kind="C"), "",
            "## Extensions", "", *summary(tables, kind="E"), ""]
    for key in KEY_FIGURES:
        study, file = key.split("/")
        if file in captions.get(study, {}):
            head += figure(study, file, captions[study])
    lines = head + caveats(tables, current)
    shown = [page for page in pages if any(t.startswith(page.name + "/") for t in tables)]
    for page in pages:
        lines += (page_section(page, tables, captions.get(page.name, {})) if page in shown
                  else missing_section(page, tables))
    lines += reproduction_section(tables) + deep_section(deep)
    for page in shown:
        lines += appendix_section(page, tables, captions.get(page.name, {}))
    return "\n".join(lines)


def deep_section(deep: Tables | None) -> list[str]:
    """The deep tier's verdicts (``figures/deep/``), or a line saying it holds no tables."""
    lines = ['<a id="deep"></a>', "", "## The deep tier", ""]
    if not deep or not deep.get("versions"):
        return lines + ["`deep/` holds no tables: `mpm-fem reproduce --deep` runs the finest meshes and the long "
                        "sweeps into it, and this section then shows their verdicts.", ""]
    return lines + [f"Verdicts on the deep tier's tables (code version {code_version(deep)}, "
                    f"[deep/REPORT.md](deep/REPORT.md)):", "", *summary(deep, "deep/REPORT.md"), ""]


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
    deep = load_tables(out / "deep") if (out / "deep").is_dir() else None
    text = render(load_tables(out), pages, {p.name: captions_of(out / p.name) for p in pages}, current_code(),
                  deep)
    path = out / "REPORT.md"
    write_atomic(path, text + "\n")
    return path


def reproduce(options) -> Path:
    """Run every study with ``options`` (:class:`mpm_fem.app.study.StudyOptions`), then write the report;
    a folder holding tables of another tier is refused first (:func:`mpm_fem.app.study.check_folder`).
    The cases of all studies run in one pool, the longest first (so no worker idles at the end of a
    study while another has cases left); as soon as the last case of a study is in, a worker writes
    that study's tables and figures from the cache, ahead of the cases still waiting (this process
    does, with one job or a Dask scheduler: :func:`mpm_fem.app.sweep.run_tasks`)."""
    from mpm_fem.app.estimate import describe, estimate, tasks
    from mpm_fem.app.study import check_folder, reproduced, run_study
    from mpm_fem.app.sweep import default_jobs, run_tasks

    check_folder(options)
    studies = reproduced(options.tier)
    if options.progress is not False:
        workers = options.jobs or default_jobs()
        print(describe({name: estimate(name, options) for name in studies}, workers), file=sys.stderr, flush=True)
    planned = sorted(((s, name, t) for name in studies for s, t in tasks(name, options) or ()), key=lambda p: -p[0])
    left = {name: sum(1 for _, n, _ in planned if n == name) for name in studies}
    published = []
    # a study's tables and figures, in a worker: every case is in the cache by then, so it runs none
    writer = replace(options, jobs=1, progress=False)

    def done(k: int):
        name = planned[k][1]
        left[name] -= 1
        if left[name] == 0:
            published.append(name)
            return partial(run_study, name, writer)
        return None

    run_tasks([t for _, _, t in planned], jobs=options.jobs, desc=f"reproduce --{options.tier}",
              scheduler=options.scheduler, progress=options.progress, done=done)
    for name in (n for n in studies if n not in published):  # a study without a cost model, or no case
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
