"""The report's 2D section (``mpm_fem.app.paper_plane``): each 2D claim said in words beside its 1D
counterpart, from the findings; no section without a 2D table."""

from __future__ import annotations

from claim_mutations import TABLES
from test_plane_claims import _fem_tables, _growth

from mpm_fem.app import paper_plane
from mpm_fem.app.paper_findings import judge, key_text


def _with_plane(p1_last: float) -> dict:
    return {**TABLES, "plane/growth": _growth(p1_last) + _fem_tables(1.0)["plane/growth"],
            **{k: v for k, v in _fem_tables(1.0).items() if k != "plane/growth"}}


def test_the_section_sets_each_2d_finding_beside_its_1d_counterpart():
    found = judge(_with_plane(-0.5))
    lines = paper_plane.section(found, {"convergence_axis.png": "the caption"})
    text = "\n".join(lines)
    assert "## Two dimensions" in text and "![the caption](plane/convergence_axis.png)" in text
    assert "**D1 (axis-0.05)** (" in text and "axis-0.05: P1 grows on " in text and "last order -0.50 [" in text, text
    assert '<a id="d1-axis-0.05"></a>' in text and "(APPENDIX.md#evidence-d1-axis-0.05)" in text
    e3 = key_text(found["E3"][1], brief=True)
    assert e3 and f"in 1D {e3}" in text, e3
    rows = paper_plane.comparison_rows(found)  # the appendix's table: the full sentences of both
    assert {r["claim"].split("]")[0][1:] for r in rows} >= {"D1 (axis-0.05)", "D6 (vortex)", "D7"}
    d1 = next(r for r in rows if r["claim"].startswith("[D1 (axis-0.05)]"))
    assert d1["in 2D"].startswith("on the axis-0.05 solution point-mass MPM's last order")
    assert "## Appendix: two dimensions beside one" in "\n".join(paper_plane.appendix(found))


def test_a_perturbed_growth_table_changes_the_section():
    grows = "\n".join(paper_plane.section(judge(_with_plane(-0.5)), {}))
    converges = "\n".join(paper_plane.section(judge(_with_plane(2.0)), {}))
    assert "-0.50 [" in grows and "2.00 [" in converges and grows != converges


def test_no_section_without_a_2d_table():
    plain = {k: v for k, v in TABLES.items() if not k.startswith("plane")}  # plane/ and plane_projection/
    assert paper_plane.section(judge(plain), {}) == []
