"""The discussion's defect section (mpm_fem.app.discussion): its numbers come from the table handed in,
and a table whose prediction moves against the measured error says so."""

from __future__ import annotations

import pytest

from mpm_fem.app.discussion import defect_growth, defect_section, ratio_span, trend_agreement


def _rows(measured, predicted, layout="jittered", seed=1, defect=(1.0, 2.0, 4.0)):
    """One Sod setting on h = 0.01, 0.005, 0.0025 (coarsest first)."""
    return [{"problem": "sod", "ppc": "4", "layout": layout, "seed": str(seed), "h": str(h), "ok": "True",
             "measured_L1": str(m), "predicted_L1": str(p), "defect_L": str(d)}
            for h, m, p, d in zip((0.01, 0.005, 0.0025), measured, predicted, defect, strict=True)]


def test_a_prediction_that_follows_the_growth_agrees_on_every_pair():
    rows = _rows((1.0, 1.5, 2.0), (0.9, 1.4, 1.9)) + _rows((1.0, 0.5, 0.25), (1.1, 0.6, 0.3), layout="regular", seed=0)
    assert trend_agreement(rows) == (4, 4, 2)
    assert trend_agreement(rows, "jittered") == (2, 2, 2)
    assert ratio_span(rows) == "0.90..1.20"


def test_a_prediction_that_falls_where_the_error_grows_disagrees():
    rows = _rows((1.0, 1.5, 2.0), (2.0, 1.0, 0.5))  # the perturbed table: the predicted trend flipped
    assert trend_agreement(rows) == (0, 2, 2)
    text = "\n".join(defect_section({"defect/defect": rows}, {}))
    assert "moves as the measured error does on 0 of 2 pairs" in text


def test_the_per_step_defect_growth_is_its_order_between_the_coarsest_and_finest_mesh():
    hc, dc, hf, df, order = defect_growth(_rows((1, 1, 1), (1, 1, 1)), "jittered")
    assert (hc, dc, hf, df) == (0.01, 1.0, 0.0025, 4.0) and order == pytest.approx(-1.0)
    text = "\n".join(defect_section({"defect/defect": _rows((1.0, 1.5, 2.0), (0.9, 1.4, 1.9))}, {}))
    assert "grows from 1 at h = 0.01 to 4 at h = 0.0025 on the jittered layouts (order -1.00)" in text


def test_without_the_table_the_section_says_it_is_not_measured():
    assert "is not in this folder" in "\n".join(defect_section({}, {}))
