"""E6: a closed-form model of point-mass MPM's particle error, built from the local defect, fitted on
some runs of ``defect/defect`` and checked on the others.

The defect study (``studies/defect.py``) measures in every run the mean per-step L1 defect of the
quantity that drives the measured error (:data:`DRIVER`: Sod's density through the rate ``L_p``,
``defect_L``; Burgers' velocity through the particle acceleration, ``defect_a``) and shows that the
accumulated defect is the particle error (its ``ratio``). The model replaces both by closed forms:

    d(h, n, layout) = D h^q n^-r                  (the per-step defect, n particles per cell)
    E(h, n, layout) = A h^p + B d(h, n, layout)   (the particle L1 error)

``D, q, r`` per problem and layout class (regular, jittered) by least squares on ``log d`` over every
run's defect (a defect, never a particle error); ``A, B >= 0`` per problem by non-negative least
squares on the relative misfit ``E / E_measured - 1`` over the *fitted* rows only (``MODEL_FIT_PPC``
particles per cell, ``h >= MODEL_FIT_H_*``), ``p`` the best of ``MODEL_P_STEPS`` orders from
``MODEL_P_MIN`` to ``MODEL_P_MAX``. The *checked* rows (the finer meshes, the other particles per cell)
are disjoint from the fitted ones: their measured error is read only by the verdict. ``A h^p`` is what
converges; ``B d`` is the defect's accumulation, which grows under refinement where ``q < 0``.

Particles per cell needed: the error keeps converging down to ``h`` (``dE/dh > 0``) while
``A p h^(p-1) > B D |q| h^(q-1) n^-r``, i.e. ``n > (B D |q| h^(q-p) / (A p))^(1/r)`` (:func:`ppc_needed`).

E6 counts as predicted only the *out-of-sample* checked rows (:func:`out_of_sample`): those at another
particle count than the fitted rows', and those at the fitting count whose mesh lies at least
``MODEL_OUT_MESHES`` refinements beyond the finest fitted mesh; the mesh next to the fit is a one-step
extrapolation, shown but not counted. Per setting (problem, particles per cell, layout class), on its
out-of-sample rows: it *holds* when ``model / measured`` lies within ``PREDICTION_FACTOR`` on every
such row and the model's trend (error down or up between successive meshes whose finer one is out of
sample) has the measured sign on every seed. A fitted ``p`` on a bound of the orders tried is reported
as a bound (``p >= MODEL_P_MAX``): the fit would move it further (on Sod the converging term only
shapes the coarsest mesh, and a wider search moves p to its new bound with the predictions unchanged).

The same model says which remedies help (:func:`remedy_rows`): the growth is the point-mass
quadrature's defect, so a remedy that changes the quadrature (a particle-domain basis of the registry, or
the reconstructed stress) stops it and one that does not (a transfer, the volume, a point basis) leaves it;
checked against ``remedies/errors`` (each remedy's main series, as E5 reads it: its least successive
particle L1 order at least ``GROWTH_ORDER``: it stops). Every judged setting holds and every remedy
agrees -> confirmed; some of either -> partly; none -> refuted; no setting with ``MODEL_MIN_CHECKED``
out-of-sample rows -> not measured.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import NamedTuple

import numpy as np
from scipy.optimize import nnls

from mpm_fem.bases import get as get_basis
from mpm_fem.measure.claims.base import CONFIRMED, NOT_MEASURED, PARTLY, REFUTED, Finding, Tables, claim, short
from mpm_fem.measure.claims.remedies import REMEDY_ERRORS, remedy_assessment, remedy_series
from mpm_fem.measure.claims.rows import GROWTH_ORDER, failures, num, select, span
from mpm_fem.measure.claims.rules import rule
from mpm_fem.measure.schema import MODEL, MODEL_FIT

#: the mean per-step defect that drives each problem's measured particle error (``defect/defect``'s column)
DRIVER = {"sod": "defect_L", "burgers": "defect_a"}
FACTOR = rule("PREDICTION_FACTOR")
FIT_PPC = int(rule("MODEL_FIT_PPC"))
FIT_H = {"sod": rule("MODEL_FIT_H_SOD"), "burgers": rule("MODEL_FIT_H_BURGERS")}
ORDERS = np.linspace(rule("MODEL_P_MIN"), rule("MODEL_P_MAX"), int(rule("MODEL_P_STEPS")))
MIN_CHECKED = int(rule("MODEL_MIN_CHECKED"))
OUT_MESHES = int(rule("MODEL_OUT_MESHES"))


class Law(NamedTuple):
    """The per-step defect's closed form ``d = D h^q n^-r`` of one problem and layout class."""

    D: float
    q: float
    r: float

    def __call__(self, h, n):
        return self.D * np.asarray(h, float) ** self.q * np.asarray(n, float) ** -self.r


class ErrorModel(NamedTuple):
    """``E = A h^p + B d(h, n, layout)`` of one problem, ``laws`` by layout class."""

    A: float
    p: float
    B: float
    laws: dict

    def __call__(self, h, n, layout: str):
        return self.A * np.asarray(h, float) ** self.p + self.B * self.laws[layout](h, n)


def fitted(row: dict) -> bool:
    """Whether a ``defect/defect`` row is one the model is fitted on (module docstring)."""
    return int(num(row, "ppc")) == FIT_PPC and num(row, "h") >= FIT_H[row["problem"]]


def _ok(rows: Iterable[dict]) -> list[dict]:
    return [r for r in rows if str(r.get("ok")) in ("True", "true", "1") and math.isfinite(num(r, "measured_L1"))]


def fit_law(rows: list[dict], column: str) -> Law:
    """``D, q, r`` by least squares on ``log d = log D + q log h - r log n`` (``r = 0`` with one n)."""
    h, n, d = (np.array([num(r, c) for r in rows]) for c in ("h", "ppc", column))
    one = np.unique(n).size == 1
    columns = [np.ones_like(h), np.log(h)] + ([] if one else [-np.log(n)])
    coef, *_ = np.linalg.lstsq(np.column_stack(columns), np.log(d), rcond=None)
    return Law(float(np.exp(coef[0])), float(coef[1]), float(0) if one else float(coef[2]))


def fit_model(rows: list[dict], problem: str) -> ErrorModel:
    """One problem's :class:`ErrorModel` from its ``defect/defect`` rows (module docstring): the laws on
    every row's defect, ``A, p, B`` on the fitted rows' measured errors only."""
    rows = select(_ok(rows), problem=problem)
    laws = {layout: fit_law(select(rows, layout=layout), DRIVER[problem])
            for layout in sorted({r["layout"] for r in rows})}
    train = [r for r in rows if fitted(r)]
    y = np.array([num(r, "measured_L1") for r in train])
    d = np.array([laws[r["layout"]](num(r, "h"), num(r, "ppc")) for r in train])
    h = np.array([num(r, "h") for r in train])
    best = None
    for p in ORDERS:
        (A, B), misfit = nnls(np.column_stack([h**p, d]) / y[:, None], np.ones_like(y))
        if best is None or misfit < best[0]:
            best = (misfit, float(p), float(A), float(B))
    _, p, A, B = best
    return ErrorModel(A, p, B, laws)


def model_rows(rows: Iterable[dict]) -> tuple[list[dict], list[dict]]:
    """``(defect/model, defect/model_fit)`` from ``defect/defect`` rows: per run its role, measured and
    modelled error and their ratio; per problem and layout the fitted constants."""
    rows = _ok(rows)
    out, constants = [], []
    for problem in sorted({r["problem"] for r in rows}):
        model = fit_model(rows, problem)
        for r in select(rows, problem=problem):
            h, n, layout = num(r, "h"), num(r, "ppc"), r["layout"]
            value = float(model(h, n, layout))
            out.append({"problem": problem, "ppc": int(n), "layout": layout, "seed": int(num(r, "seed")), "h": h,
                        "role": "fitted" if fitted(r) else "checked", "measured_L1": num(r, "measured_L1"),
                        "defect": num(r, DRIVER[problem]), "defect_law": float(model.laws[layout](h, n)),
                        "model_L1": value, "ratio": value / num(r, "measured_L1")})
        for layout, law in model.laws.items():
            constants.append({"problem": problem, "layout": layout, "driver": DRIVER[problem], "D": law.D,
                              "q": law.q, "r": law.r, "A": model.A, "p": model.p, "B": model.B})
    return out, constants


def ppc_needed(constants: dict, h: float) -> float:
    """The particles per cell above which the model's error still converges at ``h`` (module docstring),
    from one ``defect/model_fit`` row; ``inf`` when the defect law does not fall with n, 0 when it does
    not grow under refinement."""
    A, p, B, D, q, r = (num(constants, c) for c in ("A", "p", "B", "D", "q", "r"))
    if q >= 0 or B <= 0:
        return float(0)
    if A <= 0 or r <= 0:
        return math.inf
    return float((B * D * -q * h ** (q - p) / (A * p)) ** (1 / r))


def _settings(rows: list[dict]) -> dict:
    groups: dict[tuple, list[dict]] = {}
    for r in rows:
        groups.setdefault((r["problem"], int(num(r, "ppc")), r["layout"]), []).append(r)
    return groups


def out_of_sample(rows: list[dict]) -> list[bool]:
    """Per ``defect/model`` row, whether it is out of sample (module docstring): a checked row at a particle
    count no fitted row of its problem has, or one whose mesh lies at least OUT_MESHES refinements (of its
    problem's meshes) beyond the finest fitted mesh."""
    fit: dict[str, set] = {}
    meshes: dict[str, list[float]] = {}
    for r in rows:
        meshes.setdefault(r["problem"], []).append(num(r, "h"))
        if r["role"] == "fitted":
            fit.setdefault(r["problem"], set()).add(int(num(r, "ppc")))
    order = {p: sorted(set(hs), reverse=True) for p, hs in meshes.items()}
    finest = {p: max((order[p].index(num(r, "h")) for r in rows if r["problem"] == p and r["role"] == "fitted"),
                     default=-OUT_MESHES) for p in order}
    return [r["role"] == "checked" and (int(num(r, "ppc")) not in fit.get(r["problem"], set())
                                        or order[r["problem"]].index(num(r, "h")) - finest[r["problem"]] >= OUT_MESHES)
            for r in rows]


def setting_holds(rows: list[dict], counted: list[bool] | None = None) -> tuple[bool, float, float, int, int]:
    """``(holds, ratio_lo, ratio_hi, trends_right, trends)`` of one setting's model rows (module
    docstring) over the rows ``counted`` marks (default: the checked rows): their ratios and the trends
    between successive meshes of each seed whose finer mesh is counted."""
    counted = [r["role"] == "checked" for r in rows] if counted is None else counted
    mark = {id(r): c for r, c in zip(rows, counted, strict=True)}
    ratios = [num(r, "ratio") for r in rows if mark[id(r)]]
    right = total = 0
    for seed in {int(num(r, "seed")) for r in rows}:
        runs = sorted((r for r in rows if int(num(r, "seed")) == seed), key=lambda r: -num(r, "h"))
        for coarse, fine in zip(runs, runs[1:], strict=False):
            if not mark[id(fine)]:
                continue
            total += 1
            measured = num(fine, "measured_L1") - num(coarse, "measured_L1")
            modelled = num(fine, "model_L1") - num(coarse, "model_L1")
            right += measured * modelled > 0
    within = all(1 / FACTOR <= x <= FACTOR for x in ratios)
    return within and right == total, min(ratios, default=math.nan), max(ratios, default=math.nan), right, total


def order_text(fit: list[dict]) -> str:
    """The converging term's order ``p`` per problem of ``defect/model_fit`` rows, a bound where it sits on a
    bound of the orders tried (``"sod p >= 2.00, on the search's upper bound"``)."""
    step = (ORDERS[-1] - ORDERS[0]) / max(len(ORDERS) - 1, 1)
    parts = []
    for problem in dict.fromkeys(r["problem"] for r in fit):
        p = num(next(r for r in fit if r["problem"] == problem), "p")
        if p >= ORDERS[-1] - step / 2:
            parts.append(f"{problem} p >= {p:.2f}, on the search's upper bound")
        elif p <= ORDERS[0] + step / 2:
            parts.append(f"{problem} p <= {p:.2f}, on the search's lower bound")
        else:
            parts.append(f"{problem} p = {p:.2f}")
    return ", ".join(parts)


def remedy_rows(t: Tables) -> list[dict]:
    """Per problem and remedy of ``remedies/errors`` with a finite particle order (its main series, as E5
    reads it): whether the model says it helps (it changes the quadrature: a particle-domain basis, or
    ``reconstruct`` other than ``none``, read from the table's settings), whether it stops the growth (its
    least successive particle L1 order >= ``GROWTH_ORDER``), and whether the two agree."""
    settings = {r["key"]: r["value"] for r in t.get("settings", []) if r["table"] == REMEDY_ERRORS}
    rows, out = t.get(REMEDY_ERRORS, []), []
    for problem in ("sod", "burgers"):
        for name, series in remedy_series(rows, problem).items():
            order = remedy_assessment(series)["min_order_particles_L1"]
            if math.isfinite(order):
                out.append(_remedy_row(problem, name, order, settings))
    return out


def _remedy_row(problem: str, name: str, order: float, settings: dict) -> dict:
    """One remedy's row of :func:`remedy_rows` (``settings``: the remedies table's, flattened)."""
    basis = settings.get(f"remedies.{name}.basis", "mpm")
    helps = get_basis(basis).domain is True or settings.get(f"remedies.{name}.reconstruct", "none") != "none"
    stops = order >= GROWTH_ORDER
    return {"problem": problem, "remedy": name, "changes the quadrature": "yes" if helps else "no",
            "least particle order": order, "stops the growth": "yes" if stops else "no", "agrees": helps == stops}


def _e6(t: Tables) -> Finding:
    """A closed-form model built from the local defect (a converging term plus the per-step defect's
    closed form in h, particles per cell and layout) is fitted on the coarser meshes at one number of
    particles per cell and predicts the particle error out of sample (the other number of particles per
    cell, and meshes two refinements or more beyond the fit): within a factor and with the right trend
    under refinement on every seed, per setting. The mesh next to the fit is shown, not counted."""
    rows = t[MODEL.name]
    marks = out_of_sample(rows)
    out = {id(r) for r, m in zip(rows, marks, strict=True) if m}
    settings = _settings(rows)
    groups = {k: g for k, g in settings.items() if sum(id(r) in out for r in g) >= MIN_CHECKED}
    if not groups:
        return Finding(NOT_MEASURED, f"no setting with {MIN_CHECKED} out-of-sample rows (another particle count, or "
                                     f"{OUT_MESHES} meshes or more beyond the fit) in `{MODEL.name}.csv`")
    table, held = [], []
    for (problem, ppc, layout), g in sorted(groups.items()):
        holds, lo, hi, right, total = setting_holds(g, [id(r) in out for r in g])
        held.append(holds)
        table.append({"setting": f"{problem}, {ppc} ppc, {layout}", "out-of-sample rows": sum(id(r) in out for r in g),
                      "model / measured": span([lo, hi]), "trend right": f"{right} of {total}",
                      "holds": "yes" if holds else "no"})
    near = _near(settings, out)
    remedies = remedy_rows(t)
    agree = [r for r in remedies if r["agrees"]]
    wrong = [f"{r['problem']} {r['remedy']} ({r['least particle order']:.2f})" for r in remedies if not r["agrees"]]
    verdict = (CONFIRMED if all(held) and len(agree) == len(remedies) else
               PARTLY if any(held) or agree else REFUTED)
    good = [row["setting"] for row, h in zip(table, held, strict=True) if h]
    bad = [f"{row['setting']} ({row['model / measured']}, trend {row['trend right']})"
           for row, h in zip(table, held, strict=True) if not h]
    orders = order_text(t.get(MODEL_FIT.name, []))
    evidence = (f"out of sample (another particle count than the fit's, or {OUT_MESHES} meshes or more beyond it) the "
                f"model predicts within {FACTOR:g}x with the measured trend on {sum(held)} of {len(held)} settings"
                + (f": {'; '.join(good)}" if good else "") + (f"; not on {'; '.join(bad)}" if bad else "")
                + (f"; in sample or one mesh beyond the fit, not counted: {near}" if near else "")
                + (f"; the converging term's order: {orders}" if orders else "")
                + (f"; which remedies stop the growth (they change the quadrature): right on {len(agree)} of "
                   f"{len(remedies)} remedies" + (f", not on {', '.join(wrong)}" if wrong else "") if remedies else
                   "; the remedies table is not here"))
    failed = failures(t.get(REMEDY_ERRORS, []), ("problem", "remedy", "h"), REMEDY_ERRORS, flag=None)
    evidence += "".join(f"; {line} (a remedy without a particle order on every mesh is left out)" for line in failed)
    sentence = (f"fitted on the coarse meshes at {FIT_PPC} per cell, the defect model predicts the particle error out "
                f"of sample (the other particle count, or {OUT_MESHES} meshes or more beyond the fit) within "
                f"{FACTOR:g}x, with the measured trend, on {sum(held)} of {len(held)} settings"
                + (f" ({'; '.join(good)})" if good and bad else "")
                + (f"; it says which remedies stop the growth on {len(agree)} of {len(remedies)}" if remedies else ""))
    key = short(sentence, f"out of sample the defect model predicts the particle error within {FACTOR:g}x with the "
                          f"measured trend on {sum(held)} of {len(held)} settings")
    return Finding(verdict, evidence, sentence, tuple(table), failed, key)


def _near(settings: dict, out: set) -> str:
    """The settings whose checked rows are all in sample or one mesh beyond the fit, with whether the model
    holds there (shown beside the verdict, never counted)."""
    parts = []
    for (problem, ppc, layout), g in sorted(settings.items()):
        near = [r["role"] == "checked" and id(r) not in out for r in g]
        if any(near) and not any(id(r) in out for r in g):
            _, lo, hi, right, total = setting_holds(g, near)
            hs = ", ".join(f"{h:g}" for h in sorted({num(r, "h") for r, n in zip(g, near, strict=True) if n}))
            parts.append(f"{problem}, {ppc} ppc, {layout} at h = {hs} (model / measured {span([lo, hi])}, trend "
                         f"{right} of {total})")
    return "; ".join(parts)


_E6_RULE = (f"only out-of-sample rows count: another particle count than the fit's, or a mesh at least {OUT_MESHES} "
            "refinements beyond the finest fitted mesh (MODEL_OUT_MESHES; the mesh next to the fit is shown, not "
            f"counted); per setting (problem, particles per cell, layout class) with {MIN_CHECKED} out-of-sample rows: "
            f"model / measured within [1/{FACTOR:g}, {FACTOR:g}] on every out-of-sample row and the model's trend "
            "between successive meshes (finer one out of sample) of the measured sign on every seed -> the setting "
            "holds; a fitted order p on a bound of the orders tried is reported as a bound; per remedy of "
            "remedies/errors: it changes the quadrature (a particle-domain basis or the reconstructed stress) exactly "
            f"when its least particle order is at least {GROWTH_ORDER:g} -> it agrees; every setting holds and every "
            "remedy agrees -> confirmed; some of either -> partly; none -> refuted. Fitted on h >= MODEL_FIT_H_SOD "
            "(MODEL_FIT_H_BURGERS) at MODEL_FIT_PPC per cell; read from defect/model and remedies/errors")
claim("E6", source="E6's question: does the accumulated quadrature defect, in closed form, predict the particle "
                   "error and its growth?", tables=(MODEL.name, MODEL_FIT.name), study="defect",
      thresholds=_E6_RULE)(_e6)
