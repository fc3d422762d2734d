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
import math
import re
from dataclasses import replace
from typing import NamedTuple

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
from mpm_fem.measure.claims.base import CONFIRMED, DIFFERS, NOT_MEASURED, PARTLY, REFUTED, VERDICTS
from mpm_fem.measure.claims.drift import STUDY, mechanism
from mpm_fem.measure.claims.rows import CONVERGING_ORDER, GROWTH_ORDER
from mpm_fem.measure.claims.rules import RULES, VERDICT_MEANING, rule
from mpm_fem.measure.tables import Tables

Found = dict[str, tuple[Claim, Finding]]
#: The two figures that carry the study, shown on the first screen when the report's folder has them.
KEY_FIGURES = ("sod/convergence.png", "burgers/convergence.png")
#: The findings the abstract states, in this order (label, the subject when the finding has no sentence).
ABSTRACT = ("C11", "C13", "E1 (sod)", "E5")
#: The findings the conclusions state, in this order; the measured ones among them, at most eight.
CONCLUSIONS = ("C11", "C13", "C12", "C15 (sod)", "E1 (sod)", "E3", "E5", "C10", "C3 (sod)")
MAX_CONCLUSIONS = 8
#: Verdicts that depart from the source's statement: the discussion takes each in turn (a claim that holds on
#: some of its cases is counted in its verdict cell, and its results say where).
DEPARTS = (DIFFERS, REFUTED)
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


_TRUE, _FALSE = ("true", "yes", "1"), ("false", "no", "0")
_COUNTED = re.compile(r"\bon (\d+) of (\d+) ([a-z][a-z ]*[a-z])")
#: The verdict cell of a claim that holds on some of its cases: the count, the verdict's meaning in numbers.
COUNT_MEANING = ("holds on k of n", "partly, counted: the statement holds on k of the n cases (settings, layouts, "
                 "meshes, fits) the evidence names, and on no other")


def _plural(noun: str) -> str:
    noun = noun.strip().lower()
    return noun[:-1] + "ies" if noun.endswith("y") else noun if noun.endswith("s") else noun + "s"


def counted(f: Finding) -> str:
    """How many of a finding's cases the statement holds on, ``"holds on 3 of 4 layouts"``: from its table's
    ``holds`` column (or its first yes/no column, or its ``verdict`` column), else from an ``on k of n
    <cases>`` of its sentence or evidence; "" when it states no count."""
    rows = list(f.table)
    if rows:
        columns = list(rows[0])
        flags = [c for c in columns if c == "holds"] + [
            c for c in columns[1:] if all(str(r.get(c, "")).strip().lower() in _TRUE + _FALSE for r in rows)]
        if flags:
            hits = sum(str(r.get(flags[0], "")).strip().lower() in _TRUE for r in rows)
            return f"holds on {hits} of {len(rows)} {_plural(columns[0])}"
        if "verdict" in columns:
            judged = [r for r in rows if r.get("verdict") in VERDICTS and r.get("verdict") != NOT_MEASURED]
            if judged:
                hits = sum(r.get("verdict") == CONFIRMED for r in judged)
                return f"holds on {hits} of {len(judged)} {_plural(columns[0])}"
    for text in (f.sentence, f.evidence):
        m = _COUNTED.search(text or "")
        if m:
            return f"holds on {m.group(1)} of {m.group(2)} {m.group(3)}"
    return ""


def verdict_text(f: Finding) -> str:
    """The verdict cell: the verdict word, or for ``partly`` its count where the finding states one
    (:func:`counted`)."""
    return (counted(f) or f.verdict) if f.verdict == PARTLY else f.verdict


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
    """The source-matching settings in words; their table is in the appendix."""
    lines = ["### The source's unstated settings", ""]
    if not any(tables.get(name) for name in identification.IDENTIFICATION.values()):
        return lines + prose(
            "The slides leave particles per cell, the time step, the norm and the exact solution of Burgers unsaid. "
            "The identification tables (" + ", ".join(f"`{n}.csv`" for n in identification.IDENTIFICATION.values())
            + ") are not in this folder, so every claim is judged at the study's settings above.")
    return lines + prose(
        "For each of the source's tables, each candidate for what the slides leave unsaid is held fixed over the "
        "whole table and scored by its misfit, the mean of |log(measured / source)| over the table's entries: "
        "`misfit` against the source's table as corrected (`docs/claims.md`), `misfit_raw` against the table as "
        "the slides print it. The best candidate and those within the rule book's band of it are the "
        "source-matching settings ([their table](APPENDIX.md#identification)). " + identification_sentence(tables))


def identification_appendix(tables: Tables) -> list[str]:
    """The source-matching settings of each problem, as a table (the appendix's)."""
    rows = [{"problem": p, **r} for p in identification.IDENTIFICATION
            for r in identification.source_matching(tables, p)]
    return ['<a id="identification"></a>', "", "## Appendix: the source-matching settings", "",
            *prose("The candidates within the rule book's band of the least misfit of each source row (the Method of "
                   "[the report](REPORT.md) defines the misfit)."),
            *(markdown_table(rows) + [""] if rows else ["No identification table in this folder.", ""])]


def _solutions() -> str:
    """The Burgers solutions and their parameters, from their dataclasses (``baselines.exact.burgers``)."""
    from dataclasses import MISSING, fields

    from baselines.exact.burgers import SOLUTIONS

    parts = []
    for name, cls in SOLUTIONS.items():
        params = [f"{f.name} = {f.default:g}" for f in fields(cls) if f.name != "eps" and f.default is not MISSING]
        doc = (cls.__doc__ or "").split("\n\n")[0].split(", docs/claims.md")[0].split(":")[0].strip()
        doc = doc.split(") ", 1)[-1].replace("``", "")
        parts.append(f"{name} ({doc}" + (f"; {', '.join(params)}" if params else "") + ")")
    return _and(parts)


def _dt_rule(name: str) -> str:
    """The Burgers time-step rule ``name`` as its settings' docstring writes it (:mod:`mpm_fem.problems.burgers`)."""
    from mpm_fem.problems import burgers

    found = re.search(rf'``"{name}"`` \(``(.*?)``', " ".join((burgers.__doc__ or "").split()))
    if not found:
        return name
    rule_text = found.group(1)
    return rule_text if rule_text.startswith("dt") else f"dt = {rule_text}"


def terms(tables: Tables) -> list[str]:
    """The terms the report uses, each defined once: the stages and their exact forms, the time-step rules, the
    Burgers solutions, the layouts and the errors."""
    rows = [
        ("stage", "a part of the explicit MPM step: projection (particles to grid), mass (the finite-element "
         "solve with the lumped mass), interpolation (grid to particles) and time (the time step)"),
        ("exact form of a stage", "the stage with the error it adds removed: projection by the integrals of the "
         "exact fields against each basis function (a quadrature exact to round-off); mass by the solve on exact "
         "data plus the MPM solve's difference; interpolation by the exact field at the particle plus the "
         "interpolated nodal error; time by the extrapolation to dt = zero from runs at dt and dt / K"),
        ("all MPM, all exact", "every stage in its MPM form, every stage in its exact form"),
        ("stable dt rule", f"{_dt_rule('stable')}: the advective and the viscous limits"),
        ("advective dt rule", f"{_dt_rule('advective')}: no viscous limit, so dt ~ h; only with the exact "
         "acceleration"),
        ("exact and calculated acceleration", "the particle acceleration from the exact solution, or from the "
         "grid's viscous force"),
        ("Burgers solutions", _solutions()),
        ("layouts", "regular: equally spaced particles in each cell; jittered: each regular point moved uniformly "
         "within its sub-cell by a seeded generator; random and advected: the projection study's"),
        ("particle error, nodal error", "the L1 norm of the error of the particle values (the piecewise-linear "
         "field through them) or of the grid-node values, against the exact solution"),
        ("order", "p = log(e_coarse / e_fine) / log(h_coarse / h_fine) between successive meshes, or the "
         "least-squares slope where named; negative: the error grows under refinement"),
        ("misfit, misfit_raw", "the mean of |log(measured / source)| over a source table's entries, against the "
         "corrected and the printed table"),
    ]
    return markdown_table([{"term": t, "meaning": m} for t, m in rows]) + [""]


# ----------------------------------------------------------------------------- the sections

def _has_tables(tables: Tables, study: str) -> bool:
    """Whether ``tables`` hold a table of ``study`` (its appendix is written only then)."""
    return any(rows for name, rows in tables.items() if name.startswith(study + "/"))


def _clause(f: Finding) -> str:
    """The finding's sentence (or evidence) up to its first semicolon, its numbers as prose writes them."""
    text = f.sentence.strip() or f.evidence.strip()
    return readable(split_outside(text)[0].rstrip(".")) if text else ""


def _lower(text: str) -> str:
    return text[:1].lower() + text[1:] if text[1:2].islower() or text[1:2] == " " else text


def _number(text: str) -> float:
    try:
        return float(str(text).strip().lstrip("x"))
    except ValueError:
        return math.nan


def _range(values) -> str:
    v = [x for x in values if math.isfinite(x)]
    if not v:
        return ""
    lo, hi = readable(f"{min(v):.2g}"), readable(f"{max(v):.2g}")
    return lo if lo == hi else f"{lo} to {hi}"


def _growth_sentence(tables: Tables, found: Found) -> str:
    """C11 in words: the first clause of its finding, or that it is not measured."""
    c, f = found.get("C11", (None, None))
    if f is None or f.verdict == NOT_MEASURED:
        return ("whether Sod's particle density error keeps converging under refinement is not measured in this "
                "folder (C11)")
    return f"on Sod {_lower(_clause(f))} (C11)"


class StageOrders(NamedTuple):
    """The stage whose exact form alone gives the particle error the highest lowest order between successive
    meshes (``mechanism/summary``), over the mesh pairs where all MPM grows on some layout (every pair when it
    grows on none): its lowest and highest order there, all MPM's, the pairs and those converging."""

    stage: str
    lo: float
    hi: float
    mpm_lo: float
    mpm_hi: float
    pairs: int
    converging: int
    growing: bool


def stage_orders(tables: Tables, problem: str) -> StageOrders | None:
    """:class:`StageOrders` of ``problem``; ``None`` without the mechanism study's summary."""
    rows = [r for r in tables.get("mechanism/summary", []) if r.get("problem") == problem]
    pair = lambda r: (r["ppc"], r["h_coarse"], r["h_fine"])  # noqa: E731
    mpm = [r for r in rows if r["made_exact"] == "none"]
    growing = {pair(r) for r in mpm if num(r, "mpm_growing") > 0}
    kept = growing or {pair(r) for r in mpm}
    mpm = [r for r in mpm if pair(r) in kept]
    best = None
    for stage in dict.fromkeys(r["made_exact"] for r in rows if r["made_exact"] not in ("none", "all")):
        mine = [r for r in rows if r["made_exact"] == stage and pair(r) in kept]
        lows = [num(r, "order_min") for r in mine]
        if not mine or not all(math.isfinite(x) for x in lows) or (best and min(lows) <= best.lo):
            continue
        best = StageOrders(stage, min(lows), max(num(r, "order_max") for r in mine),
                           min(num(r, "order_min") for r in mpm), max(num(r, "order_max") for r in mpm), len(mine),
                           sum(x >= CONVERGING_ORDER for x in lows), bool(growing))
    return best


def _stage_sentence(tables: Tables, found: Found) -> str:
    """E6a in words: the stage whose exact form stops the growth, and the particle error's orders with every
    stage in MPM form and with that stage alone exact, on each problem."""
    found_ = [(p, o) for p in ("burgers", "sod") if (o := stage_orders(tables, p))]
    if not found_:
        return "Which stage's exact form stops that growth is not measured in this folder (E6a)"
    parts = []
    for problem, o in found_:
        reading = ("a convergence on every layout" if o.converging == o.pairs else
                   f"the growth stopped but short of the converging order {CONVERGING_ORDER:g}" if o.lo > GROWTH_ORDER
                   else "a growth still on some layout")
        parts.append(f"from [{o.mpm_lo:.2f}, {o.mpm_hi:.2f}] to [{o.lo:.2f}, {o.hi:.2f}] on {problem.capitalize()} "
                     f"({reading}{'' if o.growing else '; all MPM does not grow there'})")
    stages = list(dict.fromkeys(o.stage for _, o in found_))
    name = _and([f"the {s} stage" for s in stages]) + (" (a particle quadrature)" if "projection" in stages else "")
    stops = all(o.lo > GROWTH_ORDER for _, o in found_ if o.growing)
    return (f"Making {name} exact alone {'stops' if stops else 'does not stop'} the growth: the particle error's "
            f"order between successive meshes goes {_and(parts)}, with every stage in MPM form and with that stage "
            "exact (E6a)")


def _remedy_sentence_abstract(found: Found) -> str:
    c, f = found.get("E5", (None, None))
    if f is None or f.verdict == NOT_MEASURED:
        return "Whether a remedy removes the growth is not measured in this folder (E5)"
    tried = f"Of the {len(f.table)} remedies tried, " if f.table else ""
    return f"{tried}{_lower(_clause(f)) if tried else _clause(f)} (E5)"


def _separation_sentence(found: Found) -> str:
    """E1 in words: the interactions over the gap on each problem, from the findings' tables."""
    parts, separate = [], True
    for problem in ("sod", "burgers"):
        c, f = found.get(f"E1 ({problem})", (None, None))
        if f is None or f.verdict == NOT_MEASURED or not f.table:
            continue
        values = [_number(r.get("interactions / gap", "")) for r in f.table]
        separate = separate and all(v <= rule("SEPARATE") for v in values if math.isfinite(v))
        parts.append((problem.capitalize(), _range(values)))
    if not parts:
        return "Whether the stages of the step separate is not measured in this folder (E1)"
    verb = "separate" if separate else "do not separate"
    first, *others = parts
    return (f"Over every combination of the four stages in MPM or exact form the stages {verb}: their interactions "
            f"are {first[1]} times the gap between the all-MPM and the all-exact error on {first[0]}"
            + "".join(f" and {r} times on {p}" for p, r in others) + " (E1)")


def _fem_sentence(tables: Tables, found: Found) -> str:
    """E3 in words: the fixed-mesh FEM's orders on the same meshes beside MPM's ratio to it."""
    c, f = found.get("E3", (None, None))
    if f is None or f.verdict == NOT_MEASURED:
        return "How MPM's error compares with the fixed-mesh FEM's on the same mesh is not measured in this folder (E3)"
    orders = [num(r, "order_fem_lumped_L1") for r in tables.get("sod/convergence", [])]
    orders = [o for o in orders if math.isfinite(o)]
    fem = (f"the fixed-mesh FEM's density error falls on {sum(o > GROWTH_ORDER for o in orders)} of {len(orders)} "
           f"refinements (orders {min(orders):.2f} to {max(orders):.2f}), while " if orders else "")
    key = readable(f.key[0]) if f.key else _clause(f)
    return f"On the same meshes {fem}{_lower(key)} (E3)"


def abstract(tables: Tables, found: Found) -> list[str]:
    """Five plain sentences, each a finding with its number: the particle error's growth (C11), the stage whose
    exact form stops it (E6a), the remedy (E5), whether the stages separate (E1), MPM beside the fixed-mesh FEM
    (E3)."""
    first = ("Reproducing Tran and Berzins' error analysis of explicit one-dimensional MPM on Sod's shock tube and "
             f"viscous Burgers, we find that {_growth_sentence(tables, found)}.")
    rest = [_stage_sentence(tables, found), _remedy_sentence_abstract(found), _separation_sentence(found),
            _fem_sentence(tables, found)]
    return ["## Abstract", "", *prose(" ".join([first] + [s + "." for s in rest]))]


def introduction(found: Found) -> list[str]:
    n_claims = sum(cid.startswith("C") for cid in STATEMENTS)
    return ["## Introduction", "", *prose(
        "Where does the error of the material point method come from? Tran and Berzins' error analysis of explicit "
        "one-dimensional MPM names four sources (projection, finite elements with mass lumping, interpolation, time "
        "integration) and shows that on Sod's shock tube the density error stops "
        "converging as the mesh is refined while on viscous Burgers both accelerations converge at first order. "
        f"We judge the slides' {n_claims} claims and {len(STATEMENTS) - n_claims} extensions (an error budget "
        "over the stages, smoother bases, MPM beside FEM on one mesh, reproducibility, remedies, the growth's "
        "stage and its defect model) by written rules on tables one command regenerates; the tables, each "
        "claim's evidence and the rule book are in [the appendix](APPENDIX.md).")]


def method(tables: Tables, caveats: list[str]) -> list[str]:
    """The problems and settings, the terms, the source-matching settings, the verdict words and the rule book,
    the seeds, the record."""
    lines = ["## Method", "", *prose(
        "Each study runs its cases, writes its tables with the settings in a JSON file beside each, and draws "
        "its figures; this report only reads them. A claim's verdict is a function of the numbers in these "
        "tables, by the rules below; the tables themselves are in [the appendix](APPENDIX.md)."),
        "### Problems and settings", "", *settings_table(tables), "### Terms", "", *terms(tables)]
    lines += identification_section(tables)
    vocabulary = [{"verdict": v, "meaning": m} for v, m in VERDICT_MEANING.items()]
    vocabulary.insert(list(VERDICT_MEANING).index(PARTLY) + 1, dict(zip(("verdict", "meaning"), COUNT_MEANING,
                                                                        strict=True)))
    lines += ["### Verdicts and the rule book", "", *prose(
        "Each verdict word has one meaning, below; a claim that holds on some of its cases states how many in "
        f"its verdict cell. The {len(RULES)} thresholds every criterion reads are in one rule book "
        "(`mpm_fem/measure/claims/rules.py`), printed with the reason for each value in "
        "[the appendix](APPENDIX.md#rule-book); each claim's rule in words is there too "
        "([the verdict rules](APPENDIX.md#appendix-rules))."), *markdown_table(vocabulary), ""]
    return lines + ["### Seeds", "", *prose(seeds_text(tables)), "### The record", "", *caveats, "",
                    *prose("The deep tier (`mpm-fem reproduce --deep`) holds the finest meshes and the longest "
                           "sweeps ([what it adds](APPENDIX.md#deep-tier)).")]


def rule_book() -> list[str]:
    """The rule book as a table (the appendix's)."""
    lines = ['<a id="rule-book"></a>', "", "## Appendix: the rule book", ""]
    if not RULES:
        return lines + prose("The rule book holds no threshold yet: each criterion still reads its own constants.")
    return lines + markdown_table([{"rule": r.name, "value": f"{r.value:g}", "meaning": r.meaning, "reason": r.reason,
                                    "claims": ", ".join(r.claims)} for r in RULES.values()]) + [""]


def deep_tier_appendix() -> list[str]:
    """What the deep tier adds, as an appendix of its own."""
    return ['<a id="deep-tier"></a>', "", "## Appendix: what the deep tier adds", "", *prose(deep_text())]


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
    """A claim in the results: statement, verdict and source (a one-row table), its finding in words, one
    figure, the failed runs, and the links to its evidence, its rule and (``linked``: a study in the folder)
    its study's tables in the appendix."""
    text = f.sentence.strip() or first_clause(f)
    links = (f"Evidence: [table](APPENDIX.md#evidence-{anchor_of(c.label)}), "
             f"[rule](APPENDIX.md#rule-{anchor_of(c.label)})"
             + (f", [study](APPENDIX.md#{appendix})." if appendix and linked else "."))
    return [f'<a id="{anchor_of(c.label)}"></a>', "", f"#### {c.label}: {c.statement}", "",
            *markdown_table([{"verdict": verdict_text(f), "source": c.source}]), "",
            *([readable(text[:1].upper() + text[1:]).rstrip(".") + ".", ""] if text else []), *figure_lines,
            *failed_runs(f), links, ""]


def evidence_section(c: Claim, f: Finding) -> list[str]:
    """A claim's evidence in the appendix: its finding, its small table (or its evidence as a list), the
    failed runs, and the link back to its results."""
    return [f'<a id="evidence-{anchor_of(c.label)}"></a>', "", f"#### {c.label}: {c.statement}", "",
            *markdown_table([{"verdict": verdict_text(f), "source": c.source}]), "", *evidence(f), *failed_runs(f),
            f"In the report: [{c.label}](REPORT.md#{anchor_of(c.label)}).", ""]


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
        if source or extensions:
            rows.append({"verdict": COUNT_MEANING[0] if v == PARTLY else v, "the source's claims": source,
                         "the extensions": extensions})
    return markdown_table(rows) + [""]


def results(tables: Tables, found: Found, pages: list[Page], captions: dict, summary) -> list[str]:
    """Every claim in the order of its study's page: the studies without a table say so. A figure is shown
    once, at the first claim that reads it; every claim's evidence table is in the appendix."""
    lines = ["## Results", "", *prose(
        "The verdicts, counted, then every claim with its key number, the source's claims first; the subsections "
        "say each finding in words, and each claim's evidence is a table of "
        "[the appendix](APPENDIX.md#appendix-evidence)."), *verdict_counts(found),
        "*The source's claims.*", "", *summary("C"), "", "*The extensions.*", "", *summary("E"), ""]
    shown_pages = [p for p in [*pages, REPRODUCTION] if claims_of(p.name)]
    drawn = set(KEY_FIGURES)  # the first screen shows these
    for page in shown_pages:
        present = any(tables.get(t) for c in claims_of(page.name) for t in c.tables) \
            and (page is REPRODUCTION or _has_tables(tables, page.name))
        lines += [f'<a id="{page.name}"></a>', "", f"### {page.title}", "",
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


def discrepancies(found: Found) -> list[str]:
    """Each claim whose verdict departs from the source's statement: what was measured and why."""
    lines = ["### Where the measurements depart from the source", ""]
    order = list(STATEMENTS)
    departing = sorted(((c, f) for c, f in found.values() if f.verdict in DEPARTS and c.study != REPRODUCTION.name),
                       key=lambda cf: (order.index(cf[0].id), cf[0].problem))
    if not departing:
        return lines + prose("Every measured claim holds at the source's settings.")
    by_id: dict[str, list[Claim]] = {}
    for c, _ in departing:
        by_id.setdefault(c.id, []).append(c)
    for cid, claims in by_id.items():
        labels = _and([f"[{c.label}](#{anchor_of(c.label)})" for c in claims])
        lead = f"{labels} ({STATEMENTS[cid]}; the finding is in the results)."
        lines += prose(" ".join(s for s in (lead, claims[0].explanation, MEASURED_ELSEWHERE.get(cid, "")) if s))
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
                             "and longer sweeps ([the deep tier's verdicts](APPENDIX.md#deep)).")
    return lines + prose("The verdicts that move on the deep tier's finer meshes and longer sweeps "
                         "([the deep tier's verdicts](APPENDIX.md#deep)):") + markdown_table(
        [{"claim": c.label, "full tier": verdict_text(f), "deep tier": verdict_text(d), "deep tier's finding":
          key_text(d, brief=True)} for c, f, d in moves]) + [""]


def discussion(tables: Tables, found: Found, captions: dict, deep_found: Found | None,
               deep_note: str = "") -> list[str]:
    return ["## Discussion", "", *prose(
        "Each claim whose measured behaviour departs from the source's statement, with what the study measured "
        "about why; then the drift study, which measures the mechanism of the growth of Sod's particle error, the "
        "defect study, which predicts that error from the local defect of each step, and what the deep tier's "
        "finer meshes change. The tables behind each are in [the appendix](APPENDIX.md)."), *discrepancies(found),
        *drift_section(tables, captions.get("drift", {})), *defect_section(tables, captions.get("defect", {})),
        *deep_changes(found, deep_found, deep_note)]


def conclusions(found: Found, tables: Tables | None = None) -> list[str]:
    """Five to eight findings, each with its number: where the source's tables are reproduced (the
    identification, when its tables are there), then the measured claims of :data:`CONCLUSIONS`."""
    chosen = [found[label] for label in CONCLUSIONS if label in found and found[label][1].verdict != "not measured"]
    reproduced = [identification.identification_sentence(tables, p) for p in identification.IDENTIFICATION
                  if tables is not None and tables.get(identification.IDENTIFICATION[p])]
    items = (reproduced + [said(c, f) for c, f in chosen])[:MAX_CONCLUSIONS]
    return ["## Conclusions", "", *(bullets(items) if items else prose("No claim is measured in this folder.")),
            *prose("Every table behind these findings, each claim's evidence and verdict rule, and the rule book "
                   "are in [the appendix](APPENDIX.md).")]


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
