"""The report's body as a paper: abstract, introduction, method, results, discussion, conclusions.

Every sentence is a template filled from the tables and from what the criteria found
(:meth:`mpm_fem.measure.claims.Claim.finding`): a :class:`~mpm_fem.measure.claims.Finding`'s plain
``sentence`` where the criterion writes one, its small evidence ``table`` where it has one. A finding
without a sentence is said by its evidence's first clause, whole; one without a table shows its
evidence as a list cut at its semicolons. No verdict string is pasted into the abstract or the
conclusions, no key number is cut, and no paragraph passes :data:`mpm_fem.app.markdown.MAX_WORDS`.

:func:`judge` computes every finding once; the sections take its result (``found``: ``{label:
(claim, finding)}``), so that a report renders each criterion once.
"""

from __future__ import annotations

import json
from dataclasses import replace

from mpm_fem.app.discussion import defect_section
from mpm_fem.app.markdown import (
    anchor_of,
    bullets,
    figure,
    markdown_table,
    prose,
    readable,
    sentences,
    split_outside,
)
from mpm_fem.app.pages import Page
from mpm_fem.measure.claims import (
    CLAIMS,
    STATEMENTS,
    Claim,
    Finding,
    claims_of,
    failures,
    identification,
    num,
    select,
    span,
)
from mpm_fem.measure.claims.base import DIFFERS, NOT_MEASURED, PARTLY, REFUTED
from mpm_fem.measure.claims.drift import STUDY, mechanism
from mpm_fem.measure.claims.rules import RULES, VERDICT_MEANING
from mpm_fem.measure.tables import Tables

Found = dict[str, tuple[Claim, Finding]]
#: The findings the abstract states, in this order (label, the subject when the finding has no sentence).
ABSTRACT = ("C11", "C13", "E1 (sod)", "E5")
#: The findings the conclusions state, in this order; the measured ones among them, at most eight.
CONCLUSIONS = ("C11", "C13", "C12", "C15 (sod)", "E1 (sod)", "E3", "E5", "C10", "C3 (sod)")
MAX_CONCLUSIONS = 8
#: Verdicts that depart from the source's statement: the discussion takes each in turn.
DEPARTS = (PARTLY, DIFFERS, REFUTED)
#: Where the discussion measures a discrepancy's mechanism in a section of its own.
MEASURED_ELSEWHERE = {
    "C11": "[The drift study](#drift) below measures what makes the particle error grow on the regular layout, and "
           "[the local defect, accumulated](#defect) traces the growth on every layout to the defect of the rate L_p "
           "at the particles, summed over the steps (E6).",
    "C13": "[The local defect, accumulated](#defect) traces the Burgers stall to the defect of the particle "
           "acceleration, summed over the steps (E6)."}
#: The results' section of the claims on the record itself (E4): they read the tables' stamps.
REPRODUCTION = Page("reproduce", "Reproduction", "Every table carries the version of the code that wrote it; one "
                    "command regenerates them all. Each table's stamp is in the appendix.")


def judge(tables: Tables, left_out: dict[str, str] | None = None) -> Found:
    """Every registered claim's finding on ``tables``, by label, in the order of :data:`CLAIMS`; a finding
    that names no failed run while a table its claim reads holds some gets them named
    (:func:`mpm_fem.measure.claims.failures`), so that no failed run is left out silently. A claim that
    reads a table of ``left_out`` (``{table: its code version}``: another version than the record's,
    :func:`mpm_fem.app.report.of_code`) is not measured, and says why."""
    left_out = left_out or {}
    found = {}
    for c in CLAIMS:
        left = [name for name in c.tables if name in left_out]
        f = (Finding(NOT_MEASURED, "left out: " + ", ".join(f"`{name}.csv` was written by code version "
                                                             f"{left_out[name]}" for name in left)
                     + ", another than the record's") if left else _with_failures(c, c.finding(tables), tables))
        found[c.label] = (c, f)
    return found


def _with_failures(c: Claim, f: Finding, tables: Tables) -> Finding:
    if f.failed:
        return f
    lines = tuple(line for name in c.tables for line in failures(tables.get(name) or [], ("h",), name))
    return replace(f, failed=lines) if lines else f


def first_clause(f: Finding) -> str:
    """The evidence's first clause, whole: the key number of the summary when there is no sentence."""
    return split_outside(f.evidence)[0].rstrip(".") if f.evidence.strip() else ""


#: The longest key number of the README's verdict table, in characters
KEY_CHARS = 120


def key_text(f: Finding, brief: bool = False) -> str:
    """The summary's key number: the finding's sentence, or its evidence's first clause; ``brief``: the
    first of its short forms (:attr:`~mpm_fem.measure.claims.base.Finding.key`) that fits
    :data:`KEY_CHARS` as printed, else its tersest (the README's)."""
    text = readable(f.sentence.strip() or first_clause(f))
    if not brief or len(text) <= KEY_CHARS or not f.key:
        return text
    forms = [readable(k.strip()) for k in f.key]
    return next((k for k in forms if len(k) <= KEY_CHARS), forms[-1])


def said(c: Claim, f: Finding, link: bool = False) -> str:
    """The finding in one sentence with the claim's label (a link to its results when ``link``): its
    plain sentence, or the statement and the evidence's first clause."""
    label = f"[{c.label}](#{anchor_of(c.label)})" if link else c.label
    if f.sentence:
        text = readable(f.sentence.strip().rstrip("."))
        return f"{text[:1].upper()}{text[1:]} ({label})."
    statement = c.statement[0].upper() + c.statement[1:]
    return f"{statement} ({label}): {readable(first_clause(f))}."


# ----------------------------------------------------------------------------- settings

def _study_setting(tables: Tables, study: str, key: str) -> str:
    """Setting ``key`` of the first table of ``study`` that records it ("" when none does)."""
    return next((r["value"] for r in tables.get("settings", []) if r["table"].startswith(study + "/")
                 and r["key"] == key), "")


def _listed(value: str) -> str:
    """A JSON list as words (``[1, 2]`` -> ``1, 2``; ``[[16, 0.05]]`` -> ``16 per cell at CFL 0.05``)."""
    try:
        items = json.loads(value)
    except (ValueError, TypeError):
        return value
    if not isinstance(items, list):
        return value
    if items and all(isinstance(i, list) and len(i) == 2 for i in items):
        return ", ".join(f"{p} per cell at CFL {c}" for p, c in items)
    return ", ".join(map(str, items))


def _and(items: list) -> str:
    """``[a, b, c]`` -> ``"a, b and c"``."""
    items = [str(i) for i in items]
    return ", ".join(items[:-1]) + " and " + items[-1] if len(items) > 1 else "".join(items)


def sod_settings(tables: Tables) -> str:
    """The Sod convergence study's particles per cell and CFL numbers, in words ("" when not recorded):
    ``"16, 8 and 4 particles per cell at CFL 0.05 and 4 at CFL 0.1"``."""
    try:
        pairs = json.loads(_study_setting(tables, "sod", "runs.ppc_cfl"))
        by_cfl = {cfl: [ppc for ppc, c in pairs if c == cfl] for _, cfl in pairs}
    except (ValueError, TypeError):
        return ""
    return _and([f"{_and(ppc)}{' particles per cell' if k == 0 else ''} at CFL {cfl}"
                 for k, (cfl, ppc) in enumerate(by_cfl.items())])


def burgers_settings(tables: Tables) -> str:
    """The particles per cell of Burgers' calculated-acceleration runs and its solution, in words."""
    rows = [r for r in tables.get("settings", []) if r["table"] == "burgers/orders" and r["key"].startswith("methods.")]
    methods = {r["key"].split(".")[1] for r in rows}
    value = {r["key"]: r["value"] for r in rows}
    ppc = sorted({int(value[f"methods.{m}.settings.ppc"]) for m in methods
                  if value.get(f"methods.{m}.settings.acceleration") == "calculated"
                  and f"methods.{m}.settings.ppc" in value})
    solution = _study_setting(tables, "burgers", "default_solution")
    if not ppc:
        return ""
    return (f"{_and(ppc)} particles per cell with the calculated acceleration"
            + (f" and the {solution} solution" if solution else ""))


#: The settings the Method section prints: (problem, study, key, what it is, why this value).
SETTINGS = (
    ("Sod", "sod", "problem.T", "final time", "the slides' final time"),
    ("Sod", "sod", "runs.ppc_cfl", "particles per cell and CFL number",
     "the source's range of particles per cell and one setting above it; the slides state no time step"),
    ("Sod", "sod", "runs.jittered_meshes", "meshes h", "the meshes of the source's table"),
    ("Sod", "sod", "mpm.mass", "mass matrix", "the slides' lumped mass"),
    ("Sod", "sod", "mpm.scheme", "update", "the slides' explicit step: the particles updated from the new grid "
     "velocity"),
    ("Sod", "sod", "mpm.basis", "basis", "the slides' point-mass linear hats"),
    ("Sod", "sod", "fv.scheme", "reference beside MPM", "a converging method on the same mesh"),
    ("Burgers", "burgers", "T", "final time", "the slides' final time"),
    ("Burgers", "burgers", "default_solution", "exact solution",
     "the slides name none: the one whose error depends least on eps, as the source's does (the norms table)"),
    ("Burgers", "burgers", "force", "viscous force and particle weights",
     "not the slides' forms: the slides' second difference and weights h/N_p^i make the calculated acceleration's "
     "error grow under refinement (Appendix: burgers/diagnosis)"),
    ("Burgers", "burgers", "compared_norm", "error compared with the source",
     "the slides name none: chosen with the solution by the norms table"),
    ("Projection", "projection", "h", "meshes h", "halving, to fit an order over many meshes"),
    ("Projection", "projection", "N_p", "particles per cell", "around the source's range"),
    ("Projection", "projection", "layouts", "particle layouts", "every layout a run produces"),
    ("Error budget", "budget", "stages", "stages, each in MPM or exact form", "the slides' four error sources"),
    ("Drift", "drift", "variants", "variants, one change each", "each candidate cause of the growth"),
    ("Time", "time", "time_refines", "time-step refinements", "a fixed mesh, the time step alone refined"),
)


def settings_table(tables: Tables) -> list[str]:
    """The settings of :data:`SETTINGS` recorded in the tables' JSON, with why each is chosen."""
    rows = [{"problem": p, "setting": what, "value": _listed(v), "why": why}
            for p, study, key, what, why in SETTINGS if (v := _study_setting(tables, study, key))]
    return markdown_table(rows) + [""] if rows else ["No study's settings are recorded in this folder.", ""]


def seeds_text(tables: Tables) -> str:
    """The seeds convention, from the layouts the convergence studies record."""
    regular = _listed(_study_setting(tables, "sod", "runs.layouts.regular"))
    jittered = _listed(_study_setting(tables, "sod", "runs.layouts.jittered"))
    described = _study_setting(tables, "burgers", "layouts.jittered")
    text = ("Every random choice is made by a seeded generator, so a rerun gives the same numbers. ")
    if regular and jittered:
        text += (f"The convergence studies run the regular layout as seed {regular} and jittered layouts as seeds "
                 f"{jittered}" + (f" ({described})" if described else "") + ". An order or a ratio counts as above "
                 "or below a threshold only when its range over these runs lies on one side of it. ")
    count = _study_setting(tables, "projection", "seeds")
    if count:
        text += f"The projection study averages each random layout over {count} seeds."
    return text


# ----------------------------------------------------------------------------- the source-matching settings

def identification_sentence(tables: Tables) -> str:
    """Where the source's tables are reproduced: the identification module's sentence of each problem
    (:func:`mpm_fem.measure.claims.identification.identification_sentence`); "" without the
    identification tables."""
    parts = [identification.identification_sentence(tables, problem).strip().rstrip(".")
             for problem in identification.IDENTIFICATION if tables.get(identification.IDENTIFICATION[problem])]
    parts = [p for p in parts if p]
    if not parts:
        return ""
    joined = "; ".join(p if k == 0 or p[1:2].isupper() else p[0].lower() + p[1:] for k, p in enumerate(parts))
    return joined[0].upper() + joined[1:] + "."


def identification_section(tables: Tables) -> list[str]:
    lines = ["### The source's unstated settings", ""]
    if not any(tables.get(name) for name in identification.IDENTIFICATION.values()):
        return lines + prose(
            "The slides leave particles per cell, the time step, the norm and the exact solution of Burgers unsaid. "
            "The identification tables (" + ", ".join(f"`{n}.csv`" for n in identification.IDENTIFICATION.values())
            + ") are not in this folder, so every claim is judged at the study's settings above.")
    lines += prose("For each of the source's tables, each candidate for what the slides leave unsaid is held fixed "
                   "over the whole table and its misfit to the corrected source table measured; the best candidate "
                   "and those within the rule book's band of it are the source-matching settings. "
                   + identification_sentence(tables))
    rows = [{"problem": p, **r} for p in identification.IDENTIFICATION
            for r in identification.source_matching(tables, p)]
    return lines + (markdown_table(rows) + [""] if rows else [])


# ----------------------------------------------------------------------------- the sections

def _has_tables(tables: Tables, study: str) -> bool:
    """Whether ``tables`` hold a table of ``study`` (its appendix is written only then)."""
    return any(rows for name, rows in tables.items() if name.startswith(study + "/"))


def abstract(tables: Tables, found: Found) -> list[str]:
    """Four to six plain sentences: what was reproduced, where the source's Sod table is reproduced
    (when the identification tables are there), what differs (C11, C13), what the error budget finds
    about the stages (E1) and the remedy (E5)."""
    n_claims = sum(cid.startswith("C") for cid in STATEMENTS)
    first = ("We reproduce Tran and Berzins' error analysis of explicit one-dimensional MPM on smooth projections, "
             f"Sod's shock tube and viscous Burgers, and judge the source's {n_claims} claims and "
             f"{len(STATEMENTS) - n_claims} extensions from the measured tables.")
    sod = identification.identification_sentence(tables, "sod") if tables.get(identification.IDENTIFICATION["sod"]) \
        else ""
    said_ = [said(*found[label]) for label in ABSTRACT if label in found]
    return ["## Abstract", "", *prose(" ".join(s for s in (first, sod) if s)), *prose(" ".join(said_[:2])),
            *prose(" ".join(said_[2:]))]


def introduction(found: Found) -> list[str]:
    n_claims = sum(cid.startswith("C") for cid in STATEMENTS)
    return ["## Introduction", "", *prose(
        "Where does the error of the material point method come from? Tran and Berzins' error analysis of explicit "
        "one-dimensional MPM names four sources (projection, finite elements with mass lumping, interpolation, time "
        "integration) and shows that on Sod's shock tube the density error stops "
        "converging as the mesh is refined while on viscous Burgers both accelerations converge at first order. "
        f"We restate the slides as {n_claims} claims, measure each on tables that one command regenerates, and "
        f"judge it by a written rule. The study adds {len(STATEMENTS) - n_claims} extensions (E1-E5: an "
        "error budget over the stages, smoother bases, MPM beside FEM on one mesh, reproducibility, remedies) and "
        "a drift study of why Sod's particle error grows.")]


def method(tables: Tables, caveats: list[str]) -> list[str]:
    """The problems and settings, the source-matching settings, the rule book, the seeds, the record."""
    lines = ["## Method", "", *prose(
        "Each study runs its cases, writes its tables with the settings in a JSON file beside each, and draws "
        "its figures; this report only reads them. A claim's verdict is a function of the numbers in these "
        "tables, by the rules below."),
        "### Problems and settings", "", *settings_table(tables)]
    lines += identification_section(tables)
    lines += ["### Verdicts and the rule book", "", *prose(
        "Each verdict word has one meaning. The thresholds every criterion reads are in one rule book "
        "(`mpm_fem/measure/claims/rules.py`); each claim's rule in words is in Appendix A."), *markdown_table(
        [{"verdict": v, "meaning": m} for v, m in VERDICT_MEANING.items()]), ""]
    if RULES:
        lines += markdown_table([{"rule": r.name, "value": f"{r.value:g}", "meaning": r.meaning, "reason": r.reason,
                                  "claims": ", ".join(r.claims)} for r in RULES.values()]) + [""]
    else:
        lines += prose("The rule book holds no threshold yet: each criterion still reads its own constants, which "
                       "Appendix A states beside each claim's rule.")
    return lines + ["### Seeds", "", *prose(seeds_text(tables)), "### The record", "", *caveats, "",
                    *prose(deep_text())]


def deep_text() -> str:
    """What the deep tier adds to the full one, per study, from the studies' plans and cost models."""
    from mpm_fem.app.estimate import added
    from mpm_fem.app.study import STUDIES

    found = added(STUDIES)
    if not found:
        return "The deep tier adds no case to the full tier."
    total = sum(a.seconds for a in found.values()) / 60
    parts = [f"{name}, {a.cases} cases (~{a.seconds / 60:.0f} CPU-min; h = {', '.join(f'{h:g}' for h in a.meshes)})"
             for name, a in found.items()]
    return (f"To keep the full tier within its time budget, the deep tier (`mpm-fem reproduce --deep`) holds "
            f"the finest meshes and the longest sweeps, about {total:.0f} CPU-min more by the cost models: "
            + "; ".join(parts) + ".")


def evidence(f: Finding) -> list[str]:
    """The evidence as its small table, or (a criterion without one) as a list cut at its semicolons."""
    if f.table:
        columns = list(dict.fromkeys(k for row in f.table for k in row))
        return markdown_table(list(f.table), columns) + [""]
    return bullets(split_outside(f.evidence))


def claim_section(c: Claim, f: Finding, figure_lines: list[str] = (), appendix: str = "",
                  linked: bool = True) -> list[str]:
    """A claim in the results: statement, verdict, its sentence, one figure, the evidence, the links (to its
    tables only when ``linked``: a study not in the folder has none to link to)."""
    tables = ", ".join(f"[{t}.csv]({t}.csv)" for t in c.tables if "/" in t and linked)
    links = (f"Tables: {tables}. " if tables else "") + f"Rule and reasons: [Appendix A](#rule-{anchor_of(c.label)})" \
        + (f"; all of the study's tables: [appendix](#{appendix})." if appendix else ".")
    return [f'<a id="{anchor_of(c.label)}"></a>', "", f"#### {c.label}: {c.statement}", "",
            f"**{f.verdict}**. Source: {c.source}.", "",
            *([f.sentence.strip(), ""] if f.sentence else []), *figure_lines, *evidence(f), *failed_runs(f), links, ""]


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


def verdict_counts(found: Found) -> str:
    """How many of the source's claims and of the extensions got each verdict, in words."""
    def counted(kind: str) -> str:
        verdicts = [f.verdict for c, f in found.values() if c.id.startswith(kind)]
        return ", ".join(f"{verdicts.count(v)} {v}" for v in VERDICT_MEANING if v in verdicts)
    return (f"The verdicts on the source's claims: {counted('C')}; on the extensions: {counted('E')}. "
            "The two tables below list them with each finding's key number, the source's claims first; the "
            "subsections give each claim's evidence.")


def results(tables: Tables, found: Found, pages: list[Page], captions: dict, summary) -> list[str]:
    """Every claim in the order of its study's page: the studies without a table say so."""
    lines = ["## Results", "", *prose(verdict_counts(found)), "*The source's claims.*", "",
             *summary("C"), "", "*The extensions.*", "", *summary("E"), ""]
    shown = [p for p in [*pages, REPRODUCTION] if claims_of(p.name)]
    for page in shown:
        present = any(tables.get(t) for c in claims_of(page.name) for t in c.tables) \
            and (page is REPRODUCTION or _has_tables(tables, page.name))
        lines += [f'<a id="{page.name}"></a>', "", f"### {page.title}", "",
                  *prose(page.caption if present else
                         f"No table of the study `{page.name}` in this folder: its claims are not measured here.")]
        for c in claims_of(page.name):
            f = found[c.label][1]
            lines += claim_section(c, f, claim_figure(c, page, captions.get(page.name, {})) if present else [],
                                   ("appendix-stamps" if page is REPRODUCTION else f"appendix-{page.name}")
                                   if present else "", linked=present)
    return lines


def discrepancies(found: Found) -> list[str]:
    """Each claim whose verdict departs from the source's statement: what was measured and why."""
    lines = ["### Where the measurements depart from the source", ""]
    order = list(STATEMENTS)
    departing = sorted(((c, f) for c, f in found.values() if f.verdict in DEPARTS and c.study != REPRODUCTION.name),
                       key=lambda cf: (order.index(cf[0].id), cf[0].problem))
    if not departing:
        return lines + prose("Every measured claim holds at the source's settings.")
    for c, f in departing:
        lines += prose(" ".join(s for s in (said(c, f, link=True), c.explanation, MEASURED_ELSEWHERE.get(c.id, ""))
                                if s))
    return lines


def _drift_rows(rows: list[dict]) -> list[dict]:
    """Per variant, the regular layout's finest mesh, and the jittered layouts' range over seeds there."""
    out = []
    regular = [r for r in rows if r.get("layout", "regular") == "regular" and num(r, "particles_L1") > 0]
    for variant in dict.fromkeys(r["variant"] for r in regular):
        finest = min(select(regular, variant=variant), key=lambda r: num(r, "h"))
        out.append({"variant": variant, "layout": "regular", "h": finest["h"],
                    "order of the particle error": finest.get("order_particles_L1", ""),
                    "volume drift": finest.get("volume_drift", ""),
                    "particle error / study settings'": finest.get("particles_vs_study", "")})
        seeded = [r for r in rows if r.get("layout", "regular") != "regular" and r["variant"] == variant
                  and num(r, "particles_L1") > 0]
        if seeded:
            h = min(num(r, "h") for r in seeded)
            there = [r for r in seeded if num(r, "h") == h and r.get("order_particles_L1", "") != ""]
            if there:
                out.append({"variant": variant, "layout": f"jittered, {len(there)} seeds", "h": f"{h:g}",
                            "order of the particle error": span([num(r, "order_particles_L1") for r in there]),
                            "volume drift": span([num(r, "volume_drift") for r in there], ".2g"),
                            "particle error / study settings'": ""})
    return out


def drift_section(tables: Tables, captions: dict) -> list[str]:
    """The drift study as a section: what each variant changes, its order and drift, the mechanism."""
    lines = ['<a id="drift"></a>', "", "### What makes Sod's particle error grow: the drift study", ""]
    rows = tables.get("drift/drift", [])
    if not rows:
        return lines + prose("The drift study's table (`drift/drift.csv`) is not in this folder: the mechanism of "
                             "the growth of Sod's particle error is not measured here.")
    ppc, cfl = _study_setting(tables, "drift", "mpm.ppc"), _study_setting(tables, "drift", "mpm.cfl")
    lines += prose(f"Each variant changes one thing against the {STUDY} of Sod's study"
                   + (f" ({ppc} particles per cell at CFL {cfl})" if ppc and cfl else "")
                   + ": the density update, the quadrature of the volume rate, the time step, the particles per "
                   "cell or the volume reset against the grid. The table gives, per variant, the order of the "
                   "particle density L1 error into its finest mesh and the volume drift there.")
    lines += markdown_table(_drift_rows(rows)) + [""]
    if "drift.png" in captions:
        lines += figure("drift", "drift.png", captions)
    return lines + prose(mechanism(tables))


def deep_changes(found: Found, deep_found: Found | None, note: str = "") -> list[str]:
    """One sentence per verdict that moves between the full and the deep tier's tables (a move to or from
    ``not measured`` is a table not run or left out, no finding); ``note``: the sentence on a deep tier
    whose tables were left out (another code version than the record's), said instead."""
    lines = ["### What the deep tier changes", ""]
    if note:
        return lines + prose(note)
    if deep_found is None:
        return lines + prose("`deep/` holds no tables: `mpm-fem reproduce --deep` runs the finest meshes and the "
                             "long sweeps into it, and this section then says which verdicts move.")
    moves = [(c, f, deep_found[label][1]) for label, (c, f) in found.items()
             if label in deep_found and deep_found[label][1].verdict != f.verdict
             and NOT_MEASURED not in (f.verdict, deep_found[label][1].verdict)]
    if not moves:
        return lines + prose("No verdict moves between the full tier's tables and the deep tier's finer meshes "
                             "and longer sweeps ([the deep tier's verdicts](#deep)).")
    return lines + prose(" ".join(
        f"{c.label} ({c.statement}) moves from *{f.verdict}* to *{d.verdict}* on the deep tier: {key_text(d)}."
        for c, f, d in moves))


def discussion(tables: Tables, found: Found, captions: dict, deep_found: Found | None,
               deep_note: str = "") -> list[str]:
    return ["## Discussion", "", *prose(
        "Each claim whose measured behaviour departs from the source's statement, with what the study measured "
        "about why; then the drift study, which measures the mechanism of the growth of Sod's particle error, the "
        "defect study, which predicts that error from the local defect of each step, and what the deep tier's "
        "finer meshes change."), *discrepancies(found),
        *drift_section(tables, captions.get("drift", {})), *defect_section(tables, captions.get("defect", {})),
        *deep_changes(found, deep_found, deep_note)]


def conclusions(found: Found, tables: Tables | None = None) -> list[str]:
    """Five to eight findings, each with its number: where the source's tables are reproduced (the
    identification, when its tables are there), then the measured claims of :data:`CONCLUSIONS`."""
    chosen = [found[label] for label in CONCLUSIONS if label in found and found[label][1].verdict != "not measured"]
    reproduced = [identification.identification_sentence(tables, p) for p in identification.IDENTIFICATION
                  if tables is not None and tables.get(identification.IDENTIFICATION[p])]
    items = (reproduced + [said(c, f) for c, f in chosen])[:MAX_CONCLUSIONS]
    return ["## Conclusions", "", *(bullets(items) if items else prose("No claim is measured in this folder."))]


def numbered(lines: list[str]) -> list[str]:
    """``lines`` with the sections after the abstract and before the appendices numbered: ``## Method``
    becomes ``## 2 Method``, its ``### Seeds`` ``### 2.4 Seeds``."""
    out, section, sub, body = [], 0, 0, False
    for line in lines:
        if line.startswith("## "):
            if line.startswith("## Appendix") or line == "## Abstract":
                body = False
            else:
                section, sub, body = section + 1, 0, True
                line = f"## {section} {line[3:]}"
        elif line.startswith("### ") and body:
            sub += 1
            line = f"### {section}.{sub} {line[4:]}"
        out.append(line)
    return out


def abstract_sentences(text: str) -> list[str]:
    """The sentences of the abstract of a rendered report."""
    body = text.split("## Abstract", 1)[1].split("\n## ", 1)[0].split("\n![", 1)[0]
    return sentences(" ".join(line for line in body.splitlines() if line.strip()))
