"""The error budget's raw measurements, grouped into runs: the stages of the step and the values
``v(S)`` of every combination of them (``budget/subsets``), per basis, norm, mesh and run (particles
per cell, layout and seed where the table records them). Shared by E1 (:mod:`.budget`) and C15
(:mod:`.mass`); no claim is registered here."""

from __future__ import annotations

from mpm_fem.measure.claims.rows import num
from mpm_fem.measure.decomposition import Decomposition, decompose
from mpm_fem.measure.schema import BUDGET_SUBSETS

SUBSETS = BUDGET_SUBSETS.name
#: The stages in the order the step runs them (projection to the grid, the FE solve with the lumped
#: mass, the interpolation back to the particles, the time update); the budget's stages.
STEP_ORDER = ("projection", "mass", "interpolation", "time")


def subset(label: str) -> frozenset:
    """The stages of a ``mpm_stages`` label (``"none"``, ``"projection+mass"``)."""
    return frozenset() if label == "none" else frozenset(label.split("+"))


def run_label(row: dict) -> str:
    """The run of a row beyond its basis, norm and mesh: ``"8 ppc, jittered 3"``; empty when the table
    records no particles per cell, layout or seed (the budget's one regular run)."""
    parts = [f"{row['ppc']} ppc"] if row.get("ppc", "") != "" else []
    if row.get("layout", "") not in ("", "regular"):
        parts.append(f"{row['layout']} {row.get('seed', '')}".strip())
    return ", ".join(parts)


def values(rows: list[dict]) -> dict[frozenset, float]:
    """``{stages in MPM form: error}`` of the rows of one run."""
    return {subset(r["mpm_stages"]): num(r, "error") for r in rows}


def decomposition(rows: list[dict]) -> Decomposition | None:
    """The decomposition of one run's rows; None when a combination of STEP_ORDER is missing."""
    try:
        return decompose(values(rows), STEP_ORDER)
    except ValueError:
        return None


def runs(rows: list[dict]) -> dict[tuple, list[dict]]:
    """``{(basis, norm, h, run label): rows}`` of ``budget/subsets`` rows of one problem."""
    out: dict[tuple, list[dict]] = {}
    for r in rows:
        out.setdefault((r["basis"], r["norm"], num(r, "h"), run_label(r)), []).append(r)
    return out
