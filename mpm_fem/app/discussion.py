"""The discussion's section on the mechanism of the particle error's growth: the local defect accumulated.

:func:`defect_section` states, from the defect study's table (``defect/defect.csv``, :mod:`studies.defect`),
what the accumulated defect predicts: per problem the range of predicted / measured particle L1 error
over the runs, on the coarsest and the finest mesh, and on how many successive mesh pairs the predicted
error moves the way the measured one does (both grow or both fall), the growth of Sod's jittered
layouts among them, and how the defect per step of Sod's rate grows under refinement
(:func:`defect_growth`). Every number is formatted from the rows handed in (:func:`trend_agreement`,
:func:`ratio_span`, :func:`defect_growth`), so the prose and the table cannot disagree.
"""

from __future__ import annotations

import math

from mpm_fem.app.markdown import figure, prose
from mpm_fem.measure.claims import num, ppc_needed, span
from mpm_fem.measure.claims.model import order_text, out_of_sample, remedy_rows
from mpm_fem.measure.tables import Tables

QUANTITY = {"sod": "density", "burgers": "velocity"}


def _ok(rows: list[dict], problem: str) -> list[dict]:
    return [r for r in rows if r.get("problem") == problem and r.get("ok") in ("True", True, "1", 1)
            and num(r, "measured_L1") > 0 and num(r, "predicted_L1") > 0]


def ratio_span(rows: list[dict]) -> str:
    """The range of predicted / measured over ``rows`` (``"0.81-1.01"``), empty for none."""
    return span([num(r, "predicted_L1") / num(r, "measured_L1") for r in rows]) if rows else ""


def _series(rows: list[dict]) -> dict[tuple, list[dict]]:
    """The runs of one setting (ppc, layout, seed), each list ordered from the coarsest mesh."""
    out: dict[tuple, list[dict]] = {}
    for r in rows:
        out.setdefault((r.get("ppc"), r.get("layout"), r.get("seed")), []).append(r)
    return {k: sorted(v, key=lambda r: -num(r, "h")) for k, v in out.items()}


def trend_agreement(rows: list[dict], layout: str | None = None) -> tuple[int, int, int]:
    """``(agreeing, pairs, growing)`` over successive mesh pairs of each setting (on ``layout`` only, if
    given): the pairs where the predicted error moves as the measured one does (both grow under
    refinement, or both fall), all pairs, and the pairs where the measured error grows."""
    agreeing = pairs = growing = 0
    for key, runs in _series(rows).items():
        if layout is not None and key[1] != layout:
            continue
        for coarse, fine in zip(runs, runs[1:], strict=False):
            measured = num(fine, "measured_L1") > num(coarse, "measured_L1")
            predicted = num(fine, "predicted_L1") > num(coarse, "predicted_L1")
            pairs, agreeing, growing = pairs + 1, agreeing + (measured == predicted), growing + measured
    return agreeing, pairs, growing


def defect_growth(rows: list[dict], layout: str, column: str = "defect_L") -> tuple[float, float, float, float, float]:
    """``(h_coarse, mean_coarse, h_fine, mean_fine, order)``: the per-step defect ``column`` averaged over
    the runs of ``layout`` (``rows`` of one problem and particle count) on the coarsest and the finest
    mesh, and its order ``log(mean_c / mean_f) / log(h_c / h_f)`` (negative: it grows under refinement)."""
    there = [r for r in rows if r.get("layout") == layout and num(r, column) > 0]
    hs = sorted({num(r, "h") for r in there})
    if len(hs) < 2:
        return (math.nan,) * 5
    mean = {h: sum(num(r, column) for r in there if num(r, "h") == h) / sum(num(r, "h") == h for r in there)
            for h in (hs[0], hs[-1])}
    order = math.log(mean[hs[-1]] / mean[hs[0]]) / math.log(hs[-1] / hs[0])
    return hs[-1], mean[hs[-1]], hs[0], mean[hs[0]], order


def _growth_sentence(rows: list[dict]) -> str:
    """Sod's per-step rate defect on the coarsest and finest mesh at the smallest particle count."""
    ok = _ok(rows, "sod")
    if not ok:
        return ""
    ppc = min(int(num(r, "ppc")) for r in ok)
    mine = [r for r in ok if int(num(r, "ppc")) == ppc]
    parts = []
    for layout in ("jittered", "regular"):
        hc, dc, hf, df, order = defect_growth(mine, layout)
        if math.isfinite(order):
            parts.append(f"{dc:.3g} at h = {hc:g} to {df:.3g} at h = {hf:g} on the {layout} layout"
                         f"{'s' if layout == 'jittered' else ''} (order {order:.2f})")
    if not parts:
        return ""
    return ("The accumulated defect is a sum of dt times the defect of each step, and dt times the number of "
            "steps is T on every mesh: more steps alone do not make it grow; a defect per step that grows under "
            "refinement (or parts of it that stop cancelling) does. On Sod "
            f"at {ppc} per cell the rate's defect averaged over the particles and the steps grows from "
            + " and from ".join(parts) + ".")


def _problem_sentence(rows: list[dict], problem: str) -> str:
    ok = _ok(rows, problem)
    if not ok:
        return ""
    hs = sorted({num(r, "h") for r in ok})
    coarse, fine = [r for r in ok if num(r, "h") == hs[-1]], [r for r in ok if num(r, "h") == hs[0]]
    agreeing, pairs, growing = trend_agreement(ok)
    j_agree, j_pairs, j_growing = trend_agreement(ok, "jittered")
    text = (f"On {problem.capitalize()} ({QUANTITY.get(problem, '')} error, {len(ok)} runs) the accumulated "
            f"defect is {ratio_span(ok)} of the measured particle error: {ratio_span(coarse)} on the coarsest mesh "
            f"(h = {hs[-1]:g}) and {ratio_span(fine)} on the finest (h = {hs[0]:g}). Between successive meshes "
            f"it moves as the measured error does on {agreeing} of {pairs} pairs; the measured error grows on "
            f"{growing} of them")
    if j_pairs:
        text += (f", {j_growing} of the jittered layouts' {j_pairs}, where the prediction follows the measured "
                 f"trend on {j_agree}")
    return text + "."


def defect_section(tables: Tables, captions: dict) -> list[str]:
    """The defect study as a section of the discussion: what the accumulated defect predicts."""
    lines = ['<a id="defect"></a>', "", "### Why the particle error grows: the local defect, accumulated", ""]
    rows = tables.get("defect/defect", [])
    if not rows:
        return lines + prose("The defect study's table (`defect/defect.csv`) is not in this folder: the "
                             "accumulated defect of the particle update is not measured here.")
    lines += prose(
        "The defect study runs the mechanism study's all-MPM settings once more with an observer that measures, "
        "at every step, what the particle update takes from the grid (the particle acceleration, the motion and "
        "the rate L_p) against its exact value at that step, and accumulates the difference along each particle's "
        "path with the update's own propagation (the density through 1 - dt L_p). The norm of the accumulated "
        "defect is a prediction of the particle error that never reads the particles' error itself. "
        + " ".join(s for s in (_problem_sentence(rows, p) for p in QUANTITY) if s)
        + " Where the ratio stays near one the particle error is the local defect of the grid's values at the "
        "particles, summed over the steps. " + _growth_sentence(rows)
        + " Where the ratio exceeds one (Burgers' coarsest meshes, whose diffusive step changes the error by "
        "order one in a step) the first-order accounting overshoots.")
    if "defect.png" in captions:
        lines += figure("defect", "defect.png", captions)
    return lines + model_paragraph(tables, captions, brief=True)


#: the meshes at which the model's particles per cell needed are stated
NEEDED_AT = (0.000625, 0.0003125)


def model_paragraph(tables: Tables, captions: dict, brief: bool = False) -> list[str]:
    """The closed-form defect model (E6): its constants, its checked rows' ratios and the particles per
    cell it says keep the error converging, each number from ``defect/model`` and ``defect/model_fit``;
    ``brief``: without the constants and the counts per problem (the appendix's
    :func:`model_appendix` has them)."""
    model, fit = tables.get("defect/model", []), tables.get("defect/model_fit", [])
    if not model or not fit:
        return []
    parts = []
    out = {id(r) for r, m in zip(model, out_of_sample(model), strict=True) if m}
    for problem in ("sod", "burgers"):
        rows = [r for r in fit if r["problem"] == problem]
        checked = [num(r, "ratio") for r in model if r["problem"] == problem and id(r) in out]
        near = [num(r, "ratio") for r in model if r["problem"] == problem and r["role"] == "checked"
                and id(r) not in out]
        if not rows or not checked:
            continue
        laws = "; ".join(f"{r['layout']} d = {num(r, 'D'):.3g} h^{num(r, 'q'):.2f} n^-{num(r, 'r'):.2f}" for r in rows)
        needed = "; ".join(f"{r['layout']} " + ", ".join(f"{ppc_needed(r, h):.3g} at h = {h:g}" for h in NEEDED_AT)
                           for r in rows)
        parts.append(f"On {problem.capitalize()} ({rows[0]['driver']}): {laws}; E = {num(rows[0], 'A'):.3g} "
                     f"h^{num(rows[0], 'p'):.2f} + {num(rows[0], 'B'):.3g} d ({order_text(rows)}); out of sample "
                     f"model / measured {span(checked)}"
                     + (f", on the mesh next to the fit (not counted) {span(near)}" if near else "")
                     + f". Particles per cell it needs to keep converging: {needed}.")
    lines = ["", "#### A closed-form model of the growth (E6)", ""]
    lines += prose(
        "The defect's mean per step, d, is fitted as a power law in h and in the particles per cell n on every run "
        "(a defect, not an error), and the particle error as a converging term plus the accumulated defect, "
        "E = A h^p + B d, on the coarse meshes at 4 per cell only; 8 per cell and the meshes two refinements or "
        "more beyond the fit are predicted out of sample, and only those count (`defect/model.csv`, E6). "
        + (" ".join(parts) if not brief else "Its constants, checks and counts per problem: "
           "[the appendix](APPENDIX.md#defect-model).") + " The defect falls slowly with the particles per cell "
        "(r below one) and grows under refinement (q below zero), so the particles needed to keep converging "
        "grow faster than 1/h: the model says point-mass MPM cannot be kept converging by adding particles at "
        "any practical count on these layouts. Those counts are extrapolations far beyond the 4 and 8 per cell "
        "the model was fitted and checked on, and its converging term's order p is the fit's choice among the "
        "orders tried (`MODEL_P_MIN` to `MODEL_P_MAX` in the rule book; on a bound, a bound): read them as orders of "
        "magnitude. "
        + _remedy_sentence(tables))
    if "model.png" in captions and not brief:
        lines += figure("defect", "model.png", captions)
    return lines


def model_appendix(tables: Tables, captions: dict) -> list[str]:
    """The closed-form defect model in full, as an appendix of its own (nothing without its tables)."""
    body = model_paragraph(tables, captions)
    if not body:
        return []
    return ['<a id="defect-model"></a>', "", "## Appendix: the closed-form defect model (E6)", "",
            *[line for line in body if not line.startswith("####")][2:]]


def _remedy_sentence(tables: Tables) -> str:
    """What the model says of the remedies (E6's second part), from ``remedies/orders``: the count it gets
    right and the ones it gets wrong, with their least particle order."""
    rows = remedy_rows(tables)
    if not rows:
        return "The remedies' table is not in this folder: the model's reading of the remedies is not checked here."
    wrong = [f"{r['remedy']} on {r['problem'].capitalize()} ({r['least particle order']:.2f})"
             for r in rows if not r["agrees"]]
    return (f"The same mechanism says which remedies stop the growth: those that change the quadrature (a "
            f"particle-domain basis, the reconstructed stress), not those that change the transfer, the volume or "
            f"the particle count. Against the remedies' runs (E5; not fitted to them) it is right on "
            f"{sum(r['agrees'] for r in rows)} of {len(rows)}"
            + (f"; it misses {', '.join(wrong)}, which stop the growth without changing the quadrature"
               if wrong else "") + ".")
