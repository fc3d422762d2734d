"""E6 (:mod:`mpm_fem.measure.claims.model`): the closed-form defect model, its fit, the disjoint fitted and
checked rows, and the verdict on tables built to agree and perturbed to flip it."""

import math

import numpy as np
import pytest

from mpm_fem.measure.claims import CLAIMS
from mpm_fem.measure.claims.model import FIT_H, FIT_PPC, fit_law, fit_model, model_rows, ppc_needed

A, P, B = 0.5, 1.0, 0.002  # the error model the synthetic tables follow
LAWS = {"regular": (1.0, -0.3, 0.5), "jittered": (2.0, -0.4, 0.7)}  # D, q, r
MESHES = {"sod": (0.01, 0.005, 0.0025, 0.00125), "burgers": (0.08, 0.04, 0.02, 0.01)}
LAYOUTS = [("regular", 0)] + [("jittered", s) for s in range(1, 6)]


def _defect(h, n, layout):
    D, q, r = LAWS[layout]
    return D * h**q * n**-r


def _table(exponent=P, scale=None):
    """``defect/defect`` rows whose measured error is ``A h^exponent + B d`` exactly (``scale``: a factor
    per (problem, ppc, layout) on the measured error)."""
    rows = []
    for problem, meshes in MESHES.items():
        driver = "defect_L" if problem == "sod" else "defect_a"
        for n in (4, 8):
            for layout, seed in LAYOUTS:
                for h in meshes:
                    d = _defect(h, n, layout)
                    measured = (A * h**exponent + B * d) * (scale or {}).get((problem, n, layout), 1.0)
                    rows.append({"problem": problem, "ppc": n, "layout": layout, "seed": seed, "h": h, "ok": True,
                                 "measured_L1": measured, driver: d})
    return rows


def _verdict(rows):
    model, constants = model_rows(rows)
    e6 = next(c for c in CLAIMS if c.id == "E6")
    return e6.criterion({"defect/model": model, "defect/model_fit": constants})


def test_the_fit_recovers_the_generating_laws_and_model():
    rows = _table()
    for layout, (D, q, r) in LAWS.items():
        law = fit_law([x for x in rows if x["problem"] == "sod" and x["layout"] == layout], "defect_L")
        assert law.D == pytest.approx(D, rel=1e-10) and law.q == pytest.approx(q, abs=1e-10)
        assert law.r == pytest.approx(r, abs=1e-10)
    model = fit_model(rows, "sod")
    assert model.p == pytest.approx(P, abs=1e-12)
    assert model.A == pytest.approx(A, rel=1e-8) and model.B == pytest.approx(B, rel=1e-8)


def test_fitted_and_checked_rows_are_disjoint_and_a_checked_error_is_never_read():
    rows = _table()
    model, _ = model_rows(rows)
    fitted = {(r["problem"], r["ppc"], r["layout"], r["seed"], r["h"]) for r in model if r["role"] == "fitted"}
    checked = {(r["problem"], r["ppc"], r["layout"], r["seed"], r["h"]) for r in model if r["role"] == "checked"}
    assert fitted and checked and not fitted & checked and len(fitted | checked) == len(rows)
    assert all(k[1] == FIT_PPC and k[4] >= FIT_H[k[0]] for k in fitted)
    changed = [dict(r) for r in rows]
    target = next(r for r in changed if r["problem"] == "sod" and r["ppc"] == 8 and r["h"] == 0.00125)
    target["measured_L1"] *= 10.0
    again, _ = model_rows(changed)
    assert [r["model_L1"] for r in again] == [r["model_L1"] for r in model]  # the prediction did not move


def test_e6_confirmed_on_a_table_that_follows_the_model():
    finding = _verdict(_table())
    assert finding.verdict == "confirmed", finding.evidence
    # out of sample: 8 per cell (two layouts, two problems); 4 per cell is checked one mesh beyond the fit only
    assert "on 4 of 4 settings" in finding.evidence


def test_e6_partly_when_one_setting_is_three_times_off():
    finding = _verdict(_table(scale={("sod", 8, "jittered"): 3.0}))
    assert finding.verdict == "partly", finding.evidence
    assert "not on sod, 8 ppc, jittered" in finding.evidence


def test_e6_refuted_when_the_model_has_the_wrong_exponent_in_h():
    """Rows whose error grows like h^-1 where the model (fitted on the coarse meshes) cannot follow it."""
    rows = _table()
    for r in rows:
        fine = r["h"] < FIT_H[r["problem"]] or r["ppc"] != FIT_PPC
        r["measured_L1"] = r["measured_L1"] * (FIT_H[r["problem"]] / r["h"]) ** 2 if fine else r["measured_L1"]
    finding = _verdict(rows)
    assert finding.verdict == "refuted", finding.evidence


def test_e6_not_measured_without_checked_rows():
    rows = [r for r in _table() if r["ppc"] == FIT_PPC and r["h"] >= FIT_H[r["problem"]]]
    assert _verdict(rows).verdict == "not measured"


def test_ppc_needed_is_where_the_model_stops_converging():
    row = {"A": A, "p": P, "B": B, "D": 2.0, "q": -0.4, "r": 0.7}
    h = 0.001
    n = ppc_needed(row, h)

    def slope(n):  # dE/dh of A h^p + B D h^q n^-r at h
        return A * P * h ** (P - 1) + B * 2.0 * -0.4 * h ** -1.4 * n**-0.7

    assert slope(n) == pytest.approx(0.0, abs=1e-9) and slope(1.01 * n) > 0 > slope(0.99 * n)
    assert ppc_needed({**row, "q": 0.1}, h) == 0.0 and math.isinf(ppc_needed({**row, "r": 0.0}, h))
    assert ppc_needed(row, h / 2) > n  # a finer mesh needs more particles


def test_the_real_table_gives_a_verdict_from_its_numbers():
    """On the committed record (if present): a verdict word, and its settings table from the model rows."""
    import csv
    from pathlib import Path

    path = Path(__file__).parents[1] / "figures" / "defect" / "defect.csv"
    if not path.exists():
        pytest.skip("no committed defect table")
    rows = list(csv.DictReader(path.open()))
    finding = _verdict(rows)
    assert finding.verdict in ("confirmed", "partly", "refuted")
    assert all(np.isfinite(float(r["model_L1"])) for r in model_rows(rows)[0])


def _remedies(order_of):
    """``remedies/errors`` and its settings for three remedies: MPM, the particle-domain B-spline (a change of
    the quadrature) and XPIC(5) (a transfer), each a series on two Sod meshes whose particle L1 order is
    ``order_of[name]``."""
    rows = [{"problem": "sod", "remedy": name, "h": h, "ok": True, "nodes_L1": 0.01 * (h / 0.01) ** order,
             "particles_L1": 0.01 * (h / 0.01) ** order}
            for name, order in order_of.items() for h in (0.01, 0.005)]
    settings = [{"table": "remedies/errors", "key": "remedies.B-spline domain.basis", "value": "bspline_gimp"},
                {"table": "remedies/errors", "key": "remedies.XPIC(5).xpic", "value": "5"}]
    return {"remedies/errors": rows, "settings": settings}


def test_e6_reads_which_remedies_stop_the_growth():
    from mpm_fem.measure.claims.model import remedy_rows

    model, constants = model_rows(_table())
    e6 = next(c for c in CLAIMS if c.id == "E6")
    agreeing = _remedies({"MPM": -0.3, "B-spline domain": 0.9, "XPIC(5)": -0.4})
    rows = remedy_rows(agreeing)
    assert [r["changes the quadrature"] for r in rows] == ["no", "yes", "no"] and all(r["agrees"] for r in rows)
    tables = {"defect/model": model, "defect/model_fit": constants}
    assert e6.criterion({**tables, **agreeing}).verdict == "confirmed"
    wrong = e6.criterion({**tables, **_remedies({"MPM": -0.3, "B-spline domain": -0.2, "XPIC(5)": -0.4})})
    assert wrong.verdict == "partly" and "not on sod B-spline domain (-0.20)" in wrong.evidence
