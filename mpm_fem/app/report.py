"""``REPORT.md``, rendered from the claims (:mod:`mpm_fem.measure.claims`) and the tables, never typed.

The report reads as a paper (:mod:`mpm_fem.app.paper` writes its body). Its first screen: the
title, a warning when the figures lag the code, the abstract and the two figures that carry the
study. Then the introduction, the method (settings, the source-matching settings, the rule book,
the seeds, the record's caveats), the results (the verdict tables, then one subsection per claim),
the discussion (each discrepancy, the drift study, what the deep tier changes) and the
conclusions. The appendices: each claim's verdict rule, each study's tables and figures
(:class:`~mpm_fem.app.pages.Page`, :data:`mpm_fem.app.pages.PAGES`), the code version of each
table (E4) and the deep tier's verdicts when ``<out>/deep/`` holds tables. Every number comes from
the tables it was rendered from, so rendering the committed tables again gives the same bytes:
``python -m mpm_fem.app.report [--out figures]``.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from dataclasses import replace
from functools import partial
from pathlib import Path
from typing import Any, NamedTuple

from mpm_fem.app import paper, paper_plane
from mpm_fem.app.discussion import model_appendix
from mpm_fem.app.markdown import anchor_of, bullets, cell, figure, markdown_table, prose  # noqa: F401  (cell: interface)
from mpm_fem.app.output import write_atomic
from mpm_fem.app.pages import PAGES, Page, View  # noqa: F401  (View: part of this module's interface)
from mpm_fem.app.paper import Found, judge, key_text, verdict_text
from mpm_fem.app.paper_findings import APPENDIX_FILE, REPORT_FILE, claim_href
from mpm_fem.app.plots import CAPTIONS
from mpm_fem.app.study import NOT_JUDGED, QUICK_LEAVES_OUT
from mpm_fem.measure.claims import STATEMENTS, Claim, select
from mpm_fem.measure.tables import Tables, load_tables
from mpm_fem.measure.version import code_version as current_code

TITLE = "# mpm-fem: where does the error of MPM come from?"
#: Views longer than this are cut, with a pointer to the whole CSV.
MAX_ROWS = 40


# ----------------------------------------------------------------------------- tables and appendices

def code_version(tables: Tables) -> str:
    """The code version most tables were written by (E4 names any other)."""
    codes = [r["code"] for r in tables.get("versions", [])]
    return max(set(codes), key=codes.count) if codes else "none"


#: The tables built from the JSON beside every table (:func:`mpm_fem.measure.tables.load_tables`): kept
#: whole, so that E4 sees the stamp of every table, those left out too.
META = ("versions", "settings")


def of_code(tables: Tables, code: str) -> tuple[Tables, dict[str, str]]:
    """``tables`` without every table whose code stamp is not ``code`` (its settings rows too; the
    ``versions`` table kept whole), and ``{table: its code}`` of the tables left out: a report shows the
    tables of one code version only."""
    stamp = {r["table"]: r["code"] for r in tables.get("versions", [])}
    left = {name: stamp[name] for name in tables if name not in META and stamp.get(name, code) != code}
    kept = {name: rows for name, rows in tables.items() if name not in left}
    if "settings" in kept:
        kept["settings"] = [r for r in kept["settings"] if r.get("table") not in left]
    return kept, left


def is_quick(tables: Tables) -> bool:
    return any(r.get("tier") == "quick" for r in tables.get("versions", []))


def not_judged(tables: Tables) -> list[str]:
    """A caveat line per tier of the tables: the verdicts it does not judge (:data:`NOT_JUDGED`) and
    the tier that judges each."""
    found = dict.fromkeys(r.get("tier") for r in tables.get("versions", []))
    return [f"- The {tier} tier does not judge " + "; ".join(f"{c} (the {by} tier does: {why})"
                                                            for c, (by, why) in NOT_JUDGED[tier].items()) + "."
            for tier in found if NOT_JUDGED.get(tier)]


def anchor(claim: Claim) -> str:
    return anchor_of(claim.label)


def summary(found: Found, link: str = "", kind: str = "", brief: bool = False, statements: bool = True) -> list[str]:
    """The verdict table: every claim, its verdict, key number (the finding's sentence, or its evidence's
    first clause, whole; ``brief``: its short form, at most ``KEY_CHARS`` characters, where it has one) and
    section (``link`` prefixes the anchors, e.g. ``figures/REPORT.md`` from the README); ``kind`` ``"C"``
    (the source's claims) or ``"E"`` (the extensions) keeps those only; ``statements``: with each claim's
    statement (the report's results give it in each claim's heading instead)."""
    lines = ["| claim | statement | verdict | key number |", "|---|---|---|---|"]
    for cid, statement in STATEMENTS.items():
        if not cid.startswith(kind):
            continue
        listed = sorted(((c, f) for c, f in found.values() if c.id == cid), key=lambda cf: cf[0].problem)
        if not listed:
            lines.append(f"| {cid} | {statement} | not measured | no criterion registered |")
        for c, f in listed:
            href = claim_href(c, None, link.removesuffix(REPORT_FILE)) if link else claim_href(c)
            lines.append(f"| [{c.label}]({href}) | {cell(statement)} | **{verdict_text(f)}** | "
                         f"{cell(key_text(f, brief))} |")
    if not statements:
        return [lines[0].replace(" statement |", ""), "|---|---|---|"] + [
            " | ".join(cells for k, cells in enumerate(line.split(" | ")) if k != 1) for line in lines[2:]]
    return lines


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


def appendix_section(letter: str, page: Page, tables: Tables, captions: dict) -> list[str]:
    """A study's tables and every figure it drew."""
    lines = [f'<a id="appendix-{page.name}"></a>', "", f"## Appendix {letter}: {page.title}", "",
             *prose(page.caption), f"The tables and figures of the study `{page.name}`, with the settings of each in "
             "the JSON beside it.", ""]
    for v in page.views:
        lines += view_section(page, v, tables, captions)
    shown = {v.figure for v in page.views}
    for file in captions:
        if file not in shown:
            lines += figure(page.name, file, captions)
    own = sorted(t for t in tables if t.startswith(page.name + "/"))
    return lines + ["All tables, with their settings in the JSON beside each: "
                    + ", ".join(f"[{t.split('/')[1]}.csv]({t}.csv)" for t in own) + ".", ""]


def rules_appendix(found: Found) -> list[str]:
    """Appendix A: each claim's source, verdict rule in words and the reason its criterion gives."""
    lines = ['<a id="appendix-rules"></a>', "", "## Appendix A: the verdict rule of each claim", "",
             "Each claim's rule in words, as its criterion applies it, the reason the criterion gives, and the "
             "evidence in full where the results show it as a table.", ""]
    order = list(STATEMENTS)
    for c, f in sorted(found.values(), key=lambda cf: (order.index(cf[0].id), cf[0].problem)):
        items = [f"Source: {c.source}.", f"Verdict rule: {c.thresholds}."]
        items += [f"Why: {c.explanation}"] if c.explanation else []
        # the results show a finding's small table; its whole evidence line stays readable here
        items += [f"The evidence in full: {f.evidence}."] if f.table else []
        items += [f"In the report: [{c.label}]({claim_href(c, APPENDIX)}); its evidence: "
                  f"[table](#evidence-{anchor(c)})."]
        lines += [f'<a id="rule-{anchor(c)}"></a>', "", f"#### {c.label}: {c.statement}", "", *bullets(items)]
    return lines


def stamps_appendix(letter: str, tables: Tables) -> list[str]:
    """The code version each table was written by (E4's evidence)."""
    rows = tables.get("versions", [])
    lines = ['<a id="appendix-stamps"></a>', "", f"## Appendix {letter}: the code version of each table", ""]
    if not rows:
        return lines + ["No table in this folder.", ""]
    return lines + [f"The stamp (code version and tier) of each of the {len(rows)} tables (E4).", "",
                    *markdown_table(rows, ("table", "code", "tier")), ""]


def deep_left_out(deep: Tables | None, left: dict[str, str], record: str, current: str | None) -> str:
    """The one sentence on a deep tier whose tables were all left out (another code version than the
    record's): that it exists, how to run it, and when its tables enter the report; "" otherwise."""
    if not deep or not left or any(name not in META and name not in left for name in deep):
        return ""
    codes = ", ".join(sorted(set(left.values())))
    when = (f"at the current code ({record})" if current in (None, record) else
            f"at the code version of this record's tables ({record}; the record itself lags the current code "
            f"{current}, so `mpm-fem reproduce --full` first)")
    return (f"The deep tier exists (`deep/`: {len(left)} tables of the finest meshes and the longest sweeps), but its "
            f"tables were written by code version {codes}, not this record's {record}, so they are left out of this "
            f"report and change no verdict; they enter it when `mpm-fem reproduce --deep` regenerates them {when}.")


def deep_appendix(letter: str, deep: Tables | None, deep_found: Found | None, note: str = "") -> list[str]:
    """The deep tier's verdict table (``figures/deep/``, its tables of the record's code version only), or
    the sentence ``note`` on a deep tier left out, or a line saying it holds no tables."""
    lines = ['<a id="deep"></a>', "", f"## Appendix {letter}: the deep tier's verdicts", ""]
    if note:
        return lines + [note, ""]
    if deep_found is None:
        return lines + ["`deep/` holds no tables: `mpm-fem reproduce --deep` runs the finest meshes and the long "
                        "sweeps into it, and this appendix then shows their verdicts.", ""]
    return lines + [f"Verdicts on the deep tier's tables (code version {code_version(deep)}, "
                    f"[deep/REPORT.md](deep/REPORT.md)):", "", *summary(deep_found, "deep/REPORT.md"), ""]


KEY_FIGURES = paper.KEY_FIGURES


def lag_note(tables: Tables, current: str | None) -> list[str]:
    """The first screen's warning when the tables were written by another code version than ``current``."""
    written = code_version(tables)
    if current is None or current == written:
        return []
    return [f"**The figures lag the code**: the tables were written by code version {written}, the code is now "
            f"{current}; `mpm-fem reproduce --full` regenerates them.", ""]


def caveats(tables: Tables, current: str | None) -> list[str]:
    """What a reader must know before the numbers, as a list: the tier, the study's settings that differ
    from the source's, and whether the figures lag the code (``current``: the code version now, if known)."""
    out = []
    quick = ("- These tables come from `mpm-fem reproduce --quick`: a subset of the meshes of each study. A "
             "verdict judged on the finest mesh a study has can differ from the full record's "
             "(`mpm-fem reproduce --full`), which reaches finer meshes. The quick tier leaves out the studies "
             f"{', '.join(QUICK_LEAVES_OUT)}: they ask about the plateau of Sod's particle error, below its meshes, "
             "and the budget's fused exact-stage kernels take about a minute to compile; the mechanism study runs a "
             "small stage-exact set (two meshes a problem, each stage alone exact and every stage exact) on the "
             "numpy step.")
    out.append(quick if is_quick(tables) else "- These tables come from `mpm-fem reproduce --full`.")
    out += not_judged(tables)
    written = code_version(tables)
    rows = tables.get("versions", [])
    others = [r["table"] for r in rows if r["code"] != written]
    if current is not None and current != written:
        out.append("- " + lag_note(tables, current)[0])
    elif current is not None:
        out.append(f"- The tables were written by the current code ({written}).")
    if others:
        out.append(f"- **{len(others)} of {len(rows)} tables are left out of this report**: written by another code "
                   f"version than the record's {written} ({', '.join(others)}; "
                   "[the stamps](APPENDIX.md#appendix-stamps), E4), "
                   "so the claims that read them are not measured here; `mpm-fem reproduce --full` regenerates them.")
    setting = {r["key"]: r["value"] for r in tables.get("settings", []) if r["table"] == "sod/convergence"}
    if "mpm.ppc" in setting:
        out.append(f"- The studies that run Sod at one setting (the error budget, the bases, the remedies, the drift "
                   f"study) use {setting['mpm.ppc']} particles per cell at CFL {setting.get('mpm.cfl', '?')} "
                   "(`sod/convergence.json`); the source prescribes 4-8 per cell and states no time step, and the "
                   "claims on Sod state their verdict per setting where the tables hold several.")
    return out


def lettered(lines: list[str]) -> list[str]:
    """``lines`` with every ``## Appendix ...`` heading lettered in order: A, B, C..."""
    letters = iter("ABCDEFGHIJKLMNOPQRSTUVWXYZ")
    return [f"## Appendix {next(letters)}: {APPENDIX_HEADING.match(line).group(1)}" if APPENDIX_HEADING.match(line)
            else line for line in lines]


APPENDIX_HEADING = re.compile(r"^## Appendix(?: [A-Z]?)?: (.*)$")
#: The file of the appendices, beside ``REPORT.md``.
APPENDIX = APPENDIX_FILE


class Rendered(NamedTuple):
    """The report's main text (``REPORT.md``) and its appendices (``APPENDIX.md``)."""

    report: str
    appendix: str


def render_both(tables: Tables, pages, captions: dict[str, dict] | None = None, current: str | None = None,
                deep: Tables | None = None) -> Rendered:
    """The report and its appendices, from ``tables`` (:func:`mpm_fem.measure.tables.load_tables`), the study
    ``pages``, the figure ``captions`` of each study folder (``{study: {file: caption}}``), the code version now
    (``current``) and the deep tier's tables (``deep``, ``None`` when there are none)."""
    captions = captions or {}
    record = code_version(tables)
    everything = tables
    tables, left = of_code(tables, record)
    found = judge(tables, left)
    deep_tables, deep_left = of_code(deep, record) if deep else ({}, {})
    measured = any(rows for name, rows in deep_tables.items() if name not in META)
    deep_found = judge(deep_tables, deep_left) if measured else None
    note = deep_left_out(deep, deep_left, record, current)
    lines = [TITLE, "",
             f"Rendered by `python -m mpm_fem.app.report` from the tables of code version {code_version(tables)}. "
             "Source: L.-T. Tran and M. Berzins, Error Analysis for Material Point Method and a case study from Gas "
             "Dynamics (slides; the claims, the source's tables and the corrections made to them: `docs/claims.md` "
             f"of the repository). The tables, the evidence and the rule book: [{APPENDIX}]({APPENDIX}).", "",
             *lag_note(tables, current), *paper.abstract(tables, found)]
    for key in KEY_FIGURES:
        study, file = key.split("/")
        if file in captions.get(study, {}):
            lines += figure(study, file, captions[study])
    lines += paper.introduction(found) + paper.method(tables, caveats(everything, current))
    lines += paper.results(tables, found, pages, captions, partial(summary, found, "", brief=True, statements=False))
    lines += paper_plane.section(found, captions.get(paper_plane.PAGE.name, {}))
    lines += paper.discussion(tables, found, captions, deep_found, note) + paper.conclusions(found, tables)
    extra = [TITLE.replace("?", "? Appendix"), "",
             f"The appendix of [REPORT.md](REPORT.md), rendered with it from the tables of code version "
             f"{code_version(tables)}: each claim's verdict rule and evidence, the rule book, the source-matching "
             "settings, every study's tables and figures, the code version of each table and the deep tier.", ""]
    extra += rules_appendix(found) + paper.rule_book() + paper.evidence_appendix(found)
    extra += paper.further_results(tables, found, pages, captions)
    extra += paper.settings_appendix(tables)
    extra += paper_plane.appendix(found)
    extra += paper.identification_appendix(tables) + paper.defect_section(tables, captions.get("defect", {}))
    extra += model_appendix(tables, captions.get("defect", {}))
    shown = [page for page in pages if any(t.startswith(page.name + "/") for t in tables)]
    for page in shown:
        extra += appendix_section("", page, tables, captions.get(page.name, {}))
    extra += paper.deep_tier_appendix() + stamps_appendix("", tables) + deep_appendix("", deep_tables, deep_found,
                                                                                        note)
    return Rendered("\n".join(paper.numbered(lines)), "\n".join(lettered(extra)))


def render(tables: Tables, pages, captions: dict[str, dict] | None = None, current: str | None = None,
           deep: Tables | None = None) -> str:
    """The report's main text (:func:`render_both`)."""
    return render_both(tables, pages, captions, current, deep).report


# ----------------------------------------------------------------------------- the command

def study_pages(folder: Path) -> list[Page]:
    """The pages of :data:`mpm_fem.app.pages.PAGES`, then a plain page for every other study folder."""
    named = {p.name for p in (*PAGES, paper_plane.PAGE)}
    others = [Page(d.name, d.name, "Tables and figures of this study.") for d in sorted(Path(folder).iterdir())
              if d.is_dir() and d.name not in named and any(d.glob("*.csv"))]
    return [*PAGES, paper_plane.PAGE, *others]


def write_report(out: Path, pages: list[Page] | None = None) -> Path:
    """Render ``<out>/REPORT.md`` and ``<out>/APPENDIX.md`` from the tables and figure captions in ``out``;
    returns the report's path."""
    out = Path(out)
    pages = study_pages(out) if pages is None else pages
    deep = load_tables(out / "deep") if (out / "deep").is_dir() else None
    both = render_both(load_tables(out), pages, {p.name: captions_of(out / p.name) for p in pages}, current_code(),
                       deep)
    write_atomic(out / APPENDIX, both.appendix + "\n")
    path = out / "REPORT.md"
    write_atomic(path, both.report + "\n")
    return path


class Planned(NamedTuple):
    """A case of ``reproduce``'s one sweep: its estimated cost, its study and its task."""

    cost: float
    study: str
    task: Any


def reproduce(options) -> Path:
    """Run every study with ``options`` (:class:`mpm_fem.app.study.StudyOptions`), then write the report;
    a folder holding tables of another tier is refused first (:func:`mpm_fem.app.study.check_folder`).
    The cases of all studies run in one pool, the studies in order of their estimated cost and each one's
    cases the longest first (so no worker idles at the end of a study while another has cases left, and a
    cheap study's tables are written while the costly ones run); as soon as the last case of a study is in, a
    worker writes
    that study's tables and figures from the cache, ahead of the cases still waiting (this process
    does, with one job or a Dask scheduler: :func:`mpm_fem.app.sweep.run_tasks`)."""
    from mpm_fem.app.case_tasks import compiles, estimate, tasks
    from mpm_fem.app.estimate import describe
    from mpm_fem.app.study import check_folder, reproduced, run_study
    from mpm_fem.app.sweep import default_jobs, run_tasks

    check_folder(options)
    studies = reproduced(options.tier)
    # a variant two studies run through is compiled once: priced in the first study that meets it
    if options.progress is not False:
        workers, seen = options.jobs or default_jobs(), set()
        print(describe({name: estimate(name, options, seen) for name in studies}, workers), file=sys.stderr,
              flush=True)
    seen = set()
    found = {name: tasks(name, options, seen) or [] for name in studies}
    carries = {name: compiles(name, options, found[name]) or [False] * len(found[name]) for name in studies}
    total = {name: sum(s for s, _ in found[name]) for name in studies}
    # first the cases that compile kernels, the longest first, so that the compiles (most of a cold run) start
    # early and overlap; then the studies in order of their total cost, each one's cases the longest first: a
    # cheap study's tables and figures are written while the costly studies' cases run, not after the last case
    keyed = [((0, 0.0, -s) if carrier else (1, total[name], -s), Planned(s, name, t))
             for name in studies for (s, t), carrier in zip(found[name], carries[name], strict=True)]
    planned = [p for _, p in sorted(keyed, key=lambda kp: kp[0])]
    left = {name: sum(1 for p in planned if p.study == name) for name in studies}
    published = []
    # a study's tables and figures, in a worker: every case is in the cache by then, so it runs none
    writer = replace(options, jobs=1, progress=False)

    def done(k: int):
        name = planned[k].study
        left[name] -= 1
        if left[name] == 0:
            published.append(name)
            return partial(run_study, name, writer)
        return None

    run_tasks([p.task for p in planned], jobs=options.jobs, desc=f"reproduce --{options.tier}",
              scheduler=options.scheduler, progress=options.progress, done=done, costs=[p.cost for p in planned])
    for name in (n for n in studies if n not in published):  # a study without a cost model, or no case
        run_study(name, options)
    return write_report(options.out)


README_BEGIN = "<!-- results in brief: generated by `python -m mpm_fem.app.report --readme README.md` -->"
README_END = "<!-- end of the results in brief -->"


def results_in_brief(tables: Tables, report: str = "figures/REPORT.md") -> str:
    """README's "Results in brief": the summary of the report with the short key numbers, its links
    pointing into ``report``."""
    kept, left = of_code(tables, code_version(tables))
    return "\n".join([README_BEGIN, f"Verdicts computed from the committed tables (code version "
                      f"{code_version(tables)}); each claim links to its section of `{report}`.", "",
                      *summary(judge(kept, left), report, brief=True), README_END])


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
