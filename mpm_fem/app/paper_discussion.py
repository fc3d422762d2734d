"""The report's Discussion and Conclusions.

The discussion takes each claim whose verdict departs from the source's statement (:data:`DEPARTS`),
with what was measured about why; then the drift study's variants, the defect study
(:mod:`mpm_fem.app.discussion`) and which verdicts the deep tier's finer meshes move. The conclusions
state five to eight findings, each with its number, no verdict string pasted in.
"""

from __future__ import annotations

from mpm_fem.app.markdown import bullets, figure, markdown_table, prose, split_outside
from mpm_fem.app.paper_findings import Found, _and, claim_href, key_text, said, verdict_text
from mpm_fem.app.paper_method import _study_setting
from mpm_fem.app.paper_results import REPRODUCTION
from mpm_fem.measure.claims import STATEMENTS, Claim, identification, num, select, span
from mpm_fem.measure.claims.base import DIFFERS, NOT_MEASURED, REFUTED
from mpm_fem.measure.claims.drift import STUDY, mechanism
from mpm_fem.measure.tables import Tables

#: The findings the conclusions state, in this order; the measured ones among them, at most eight.
CONCLUSIONS = ("C11", "C13", "C12", "C15 (sod)", "E1 (sod)", "E3", "E5", "C10", "C3 (sod)")


MAX_CONCLUSIONS = 8


#: Verdicts that depart from the source's statement: the discussion takes each in turn (a claim that holds on
#: some of its cases is counted in its verdict cell, and its results say where).
DEPARTS = (DIFFERS, REFUTED)


#: Where the discussion measures a discrepancy's mechanism in a section of its own.
MEASURED_ELSEWHERE = {
    "C11": "[The drift study](#drift) below measures what makes the particle error grow on the regular layout, and "
           "[the local defect, accumulated](APPENDIX.md#defect) traces the growth on every layout to the defect of "
           "the rate L_p at the particles, summed over the steps (E6).",
    "C13": "[The local defect, accumulated](APPENDIX.md#defect) traces the Burgers stall to the defect of the particle "
           "acceleration, summed over the steps (E6)."}


def discrepancies(found: Found) -> list[str]:
    """Each claim whose verdict departs from the source's statement: what was measured and why."""
    lines = ["### Where the measurements depart from the source", ""]
    order = list(STATEMENTS)
    departing = sorted(((c, f) for c, f in found.values() if f.verdict in DEPARTS and c.study != REPRODUCTION.name
                        and not c.id.startswith("D")),  # the 2D claims: their own section
                       key=lambda cf: (order.index(cf[0].id), cf[0].problem))
    if not departing:
        return lines + prose("Every measured claim holds at the source's settings.")
    by_id: dict[str, list[Claim]] = {}
    for c, _ in departing:
        by_id.setdefault(c.id, []).append(c)
    for cid, claims in by_id.items():
        labels = _and([f"[{c.label}]({claim_href(c)})" for c in claims])
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
        *drift_section(tables, captions.get("drift", {})), *defect_pointer(tables),
        *deep_changes(found, deep_found, deep_note)]


def defect_pointer(tables: Tables) -> list[str]:
    """The defect study in one paragraph of the discussion: its section is in the appendix."""
    if not tables.get("defect/defect"):
        return []
    return ["### Why the particle error grows: the local defect, accumulated", "", *prose(
        "The defect study measures, at every step, what the particle update takes from the grid against its exact "
        "value and accumulates the difference along each particle's path; its norm predicts the particle error "
        "without reading it. What it predicts, and the closed-form model fitted on it (E6), are in "
        "[the appendix](APPENDIX.md#defect).")]


def conclusions(found: Found, tables: Tables | None = None) -> list[str]:
    """Five to eight findings, each with its number: where the source's tables are reproduced (the
    identification, when its tables are there), then the measured claims of :data:`CONCLUSIONS`."""
    chosen = [found[label] for label in CONCLUSIONS if label in found and found[label][1].verdict != "not measured"]
    reproduced = [identification.identification_sentence(tables, p) for p in identification.IDENTIFICATION
                  if tables is not None and tables.get(identification.IDENTIFICATION[p])]
    # an identification's sentence is its finding, then its particulars after a semicolon: the first only
    items = ([split_outside(r)[0].rstrip(".") + "." for r in reproduced]
             + [said(c, f) for c, f in chosen])[:MAX_CONCLUSIONS]
    return ["## Conclusions", "", *(bullets(items) if items else prose("No claim is measured in this folder.")),
            *prose("Every table behind these findings, each claim's evidence and verdict rule, and the rule book "
                   "are in [the appendix](APPENDIX.md).")]
