"""The report's Method: the problems and their settings with why each is chosen, the terms it uses
(each defined once), the source-matching settings, the verdict words and the rule book, the seeds and
the record; and the appendices of the rule book, the source-matching settings and the deep tier.
Every value is read from the settings recorded beside the tables (``settings``), never typed.
"""

from __future__ import annotations

import json
import re

from mpm_fem.app.markdown import MAX_WORDS, bullets, markdown_table, prose, split_outside
from mpm_fem.app.paper_findings import COUNT_MEANING, _and
from mpm_fem.measure.claims import identification
from mpm_fem.measure.claims.base import PARTLY
from mpm_fem.measure.claims.rows import CONVERGING_ORDER, GROWTH_ORDER
from mpm_fem.measure.claims.rules import RULES, VERDICT_MEANING
from mpm_fem.measure.tables import Tables


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
        "whole table and scored by its misfit, the mean of |log(measured / source)| over the table's entries "
        "(for Burgers plus the spread over eps), against the source's table as corrected (`docs/claims.md`). Its "
        "continuous settings (the CFL numbers, the Burgers solutions' parameters) are fitted by a bracketed "
        "search to a stated tolerance, on part of the table; `misfit_held_out` is the rest (Sod: the L2 column; "
        "Burgers: two of the five eps). The best candidate and those within the rule book's band of it are the "
        "source-matching settings ([their table and the refinement test](APPENDIX.md#identification)).") \
        + identification_lines(tables)


def identification_lines(tables: Tables) -> list[str]:
    """Each problem's identification sentence: a paragraph, or (past a paragraph's length) its first clause
    as the lead and the rest as a list cut at its semicolons, so that no sentence runs over paragraphs."""
    lines = []
    for problem, name in identification.IDENTIFICATION.items():
        text = identification.identification_sentence(tables, problem).strip().rstrip(".") if tables.get(name) else ""
        if not text:
            continue
        text = text[:1].upper() + text[1:]
        if len(text.split()) <= MAX_WORDS:
            lines += prose(text + ".")
            continue
        lead, *rest = split_outside(text)
        lines += prose(lead.rstrip(",;") + ":") + bullets([r.strip() for r in rest])
    return lines


def identification_appendix(tables: Tables) -> list[str]:
    """The source-matching settings of each problem, as a table (the appendix's)."""
    rows = [{"problem": p, **r} for p in identification.IDENTIFICATION
            for r in identification.source_matching(tables, p)]
    return ['<a id="identification"></a>', "", "## Appendix: the source-matching settings", "",
            *prose("The candidates within the rule book's band of the least misfit of each source row (the Method of "
                   "[the report](REPORT.md) defines the misfit)."),
            *(markdown_table(rows) + [""] if rows else ["No identification table in this folder.", ""]),
            *_identification_extras(tables)]


def _identification_extras(tables: Tables) -> list[str]:
    """The refinement test and the per-eps diagnostic's best rows, when the identification wrote them."""
    refinement = tables.get("identification/refinement", [])
    per_eps = [r for r in tables.get("identification/burgers", []) if r.get("fit") == "eps" and str(r["rank"]) == "1"]
    out = []
    if refinement:
        out += [*prose("The refinement test: each problem's best candidate searched again with every tolerance "
                       "halved, from its converged point; `change` is the move of its best misfit."),
                *markdown_table(refinement), ""]
    if per_eps:
        keep = ("source_row", "eps", "solution", "params", "dt_rule", "cfl", "readout", "norm", "misfit")
        out += [*prose("Burgers per eps: the best setting for one row at one eps alone (the exact row's CFL fitted "
                       "again; the calculated row at the whole-table fit's settings)."),
                *markdown_table([{k: r[k] for k in keep} for r in per_eps]), ""]
    return out


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
        ("converges, levels off, grows", f"an order of at least {CONVERGING_ORDER:g} (the converging order) "
         f"converges, one below {GROWTH_ORDER:g} grows, one between them levels off (a plateau; the rule book's "
         "CONVERGING_ORDER and GROWTH_ORDER)"),
        ("methods", "P1: MPM's point-mass linear basis; GIMP, uGIMP: the hat averaged over the particle's domain; "
         "B-spline (C1 quadratic, C2 cubic) and B-spline domain (the quadratic averaged over the particle's "
         "domain); PIC/FLIP: the particle velocity from the grid velocity or its change; XPIC(m): extended PIC of "
         "order m; APIC: affine PIC; FMPM(k): the particle mass matrix's inverse by k terms of its series "
         "(FMPM(1) is the lumped mass); FEM, FV: the fixed-mesh finite element and finite-volume baselines"),
        ("ppc, CFL, eps", "particles per cell; the time step's Courant number; Burgers' viscosity"),
        ("misfit, misfit_raw", "the mean of |log(measured / source)| over a source table's entries, against the "
         "corrected and the printed table"),
    ]
    return markdown_table([{"term": t, "meaning": m} for t, m in rows]) + [""]


def settings_appendix(tables: Tables) -> list[str]:
    """The appendix's table of the problems' settings (:func:`settings_table`)."""
    return ['<a id="appendix-settings"></a>', "", "## Appendix: the problems and their settings", "",
            *settings_table(tables)]


def method(tables: Tables, caveats: list[str]) -> list[str]:
    """The problems and settings, the terms, the source-matching settings, the verdict words and the rule book,
    the seeds, the record."""
    lines = ["## Method", "", *prose(
        "Each study runs its cases, writes its tables with the settings in a JSON file beside each, and draws "
        "its figures; this report only reads them. A claim's verdict is a function of the numbers in these "
        "tables, by the rules below; the tables themselves are in [the appendix](APPENDIX.md)."),
        "### Problems and settings", "", *prose(
            "Sod's shock tube and viscous Burgers in 1D, manufactured solutions of a neo-Hookean solid in 2D; "
            "every setting a study records, with the reason it is chosen, is in "
            "[the appendix](APPENDIX.md#appendix-settings)."), "### Terms", "", *terms(tables)]
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
