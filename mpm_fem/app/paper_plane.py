"""The report's 2D section: does the 1D error analysis survive on the plane?

:data:`PAGE` is the 2D study's page (its title, caption and the views of ``plane/*`` with their
figures); :func:`section` writes ``## Two dimensions``: what was run, the figures (a convergence figure
per solution with every basis, both amplitudes, the spread over the layouts and the FEM beside it; the
stage bars with their control; the grid masses with their cost; time against space), then one sentence
per claim D1-D9 setting the 2D finding beside its 1D counterpart (:data:`COUNTERPARTS`), from the
findings the report judged once (``found``). No number is typed: every one comes from a finding.
"""

from __future__ import annotations

from mpm_fem.app.markdown import anchor_of, figure, markdown_table, prose, readable
from mpm_fem.app.pages import Page, View
from mpm_fem.app.paper_findings import APPENDIX_FILE, Found, claim_href, key_text, verdict_text

PAGE = Page("plane", "Two dimensions: the stage-by-stage analysis on the plane",
            "Point-mass MPM, uGIMP and the quadratic and cubic B-splines run the axis-aligned manufactured solution "
            "of a neo-Hookean solid at a small amplitude, where every particle stays in its cell, and a large one, "
            "where particles cross cells, and the generalized vortex, beside the Q1 FEM on the same mesh; the error "
            "is the particle displacement L2 at the final time.",
            views=(
                View("plane/convergence", "The particle displacement L2 per solution, method and mesh: the regular "
                     "layout and the range over the layouts run", ("solution", "method", "h", "runs", "L2",
                                                                   "L2_lo", "L2_hi"), {}, "convergence_axis.png"),
                View("plane/convergence", "The vortex", ("method", "h", "runs", "L2", "L2_lo", "L2_hi"),
                     {"solution": "vortex"}, "convergence_vortex.png"),
                View("plane/stages", "Point-mass P1 with each stage made exact alone and every stage exact",
                     ("solution", "h", "layout", "seed", "made_exact", "ok", "L2")),
                View("plane/shapley", "The error budget's decomposition on the two coarsest meshes",
                     ("solution", "h", "stage", "shapley", "share", "alone", "interactions_share"), {}, "stages.png"),
                View("plane/mass", "The grid masses: error and CPU cost per step", ("solution", "h", "mass", "ok",
                                                                                    "L2", "step_ms"), {}, "mass.png"),
                View("plane/fem", "The Q1 FEM on the same meshes", ("solution", "h", "mass", "ok", "L2")),
                View("plane/time", "The step alone refined on one mesh", ("solution", "refine", "cfl_run", "dt",
                                                                         "L2"), {}, "time.png"),
            ))

#: Each 2D claim and the 1D findings it is set beside (their labels), with the words that introduce them.
COUNTERPARTS = {
    "D1": (("E6a (burgers)", "E6a (sod)", "E2"), "in 1D"),
    "D2": (("E6a (burgers)", "E6a (sod)"), "in 1D"),
    "D3": (("E1 (sod)", "E1 (burgers)"), "the 1D budget:"),
    "D4": (("C15 (burgers)", "C15 (sod)"), "in 1D"),
    "D5": (("E7 (sod)", "E7 (burgers)"), "in 1D"),
    "D6": (("E3",), "in 1D"),
    "D7": (("C1",), "in 1D"),
    "D8": (("C5", "C7", "C8", "C9"), "in 1D"),
    "D9": (("C4",), "in 1D"),
}
#: The figures of the section, in order: (file, what it shows).
FIGURES = ("convergence_axis.png", "stages.png")  # the others in the appendix with the studies' pages


def _said(f) -> str:
    text = (f.sentence or f.evidence.split(";")[0]).strip().rstrip(".")
    return readable(text)


def comparison_rows(found: Found) -> list[dict]:
    """One row per 2D claim: its verdict, the 2D finding in words and the 1D finding it is set beside."""
    rows = []
    for label, (c, f) in found.items():
        if not c.id.startswith("D"):
            continue
        ones, _ = COUNTERPARTS.get(c.id, ((), ""))
        beside = [f"{one}: {_said(found[one][1])}" for one in ones if one in found and found[one][1].sentence]
        rows.append({"claim": f"[{label}]({claim_href(c, APPENDIX_FILE)})", "verdict": verdict_text(f),
                     "in 2D": _said(f), "in 1D": "; ".join(beside) or "no 1D counterpart measured"})
    return rows


def sentences_per_claim(found: Found) -> list[str]:
    """A paragraph per 2D claim (its anchor first): its verdict and key number, then (once per claim) the key
    number of the 1D finding it is set beside, and the link to its evidence in the appendix (the full
    sentences of both are in the appendix's table)."""
    out, set_beside = [], set()
    for label, (c, f) in found.items():
        if not c.id.startswith("D") or f.verdict == "not measured":
            continue
        ones, words = COUNTERPARTS.get(c.id, ((), ""))
        beside = [key_text(found[one][1], brief=True) for one in ones if one in found and found[one][1].sentence
                  and c.id not in set_beside]
        set_beside.add(c.id)  # a claim judged per solution is set beside its 1D counterpart once
        text = (f"**{label}** ({verdict_text(f)}): {key_text(f, brief=True)}"
                + (f"; {words} {beside[0]}" if beside else "")
                + f" ([evidence](APPENDIX.md#evidence-{anchor_of(label)})).")
        out += [f'<a id="{anchor_of(label)}"></a>', "", *prose(text)]
    return out


def section(found: Found, captions: dict) -> list[str]:
    """``## Two dimensions``: the question, the figures of ``plane`` (``captions``: its ``{file: caption}``)
    and a sentence per 2D claim beside its 1D counterpart; nothing when no 2D claim was judged. The table of
    both is in the appendix (:func:`appendix`)."""
    rows = comparison_rows(found)
    if not rows or all(r["verdict"] == "not measured" for r in rows):
        return []
    lines = ['<a id="two-dimensions"></a>', "", "## Two dimensions", "", *prose(
        "Do the 1D findings hold on the plane? " + PAGE.caption + " Each claim D1-D9 below is judged from the "
        "2D studies' tables by the same rule book and set beside its 1D counterpart; the table of both, and the "
        "studies' tables, are in [the appendix](APPENDIX.md#appendix-two-dimensions).")]
    for file in FIGURES:
        if file in captions:
            lines += figure(PAGE.name, file, captions)
    return lines + sentences_per_claim(found)


def appendix(found: Found) -> list[str]:
    """The appendix's table of every 2D claim beside its 1D counterpart (:func:`comparison_rows`)."""
    rows = comparison_rows(found)
    if not rows:
        return []
    return ['<a id="appendix-two-dimensions"></a>', "", "## Appendix: two dimensions beside one", "",
            *prose("Each 2D claim's finding in words beside the 1D finding it is set beside."),
            *markdown_table(rows, ("claim", "verdict", "in 2D", "in 1D")), ""]
