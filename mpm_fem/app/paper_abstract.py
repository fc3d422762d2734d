"""The report's first screen: the abstract and the introduction.

The abstract is five plain sentences, each a finding with its number, formatted from the findings and
the tables: whether Sod's particle error keeps converging (C11), which stage's exact form stops its
growth (E6a, from the mechanism study's summary: :func:`stage_orders`), the remedy (E5), whether the
stages separate (E1) and MPM beside the fixed-mesh FEM on the same meshes (E3). A finding not
measured in the folder is said to be so, by its label. :func:`abstract_sentences` reads the abstract
back from a rendered report (for the tests).
"""

from __future__ import annotations

import math
from typing import NamedTuple

from mpm_fem.app.markdown import prose, readable, sentences
from mpm_fem.app.paper_findings import Found, _and, _clause, _lower, _number, _range, labelled
from mpm_fem.measure.claims import STATEMENTS, num
from mpm_fem.measure.claims.base import NOT_MEASURED
from mpm_fem.measure.claims.rows import CONVERGING_ORDER, GROWTH_ORDER
from mpm_fem.measure.claims.rules import rule
from mpm_fem.measure.tables import Tables

#: The two figures that carry the study, shown on the first screen when the report's folder has them.
KEY_FIGURES = ("sod/convergence.png", "burgers/convergence.png")


def _growth_sentence(tables: Tables, found: Found) -> str:
    """C11 in words: the first clause of its finding, or that it is not measured."""
    c, f = found.get("C11", (None, None))
    if f is None or f.verdict == NOT_MEASURED:
        return ("whether Sod's particle density error keeps converging under refinement is not measured in this "
                "folder (C11)")
    return labelled(f"on Sod {_lower(_clause(f))}", "C11")


class StageOrders(NamedTuple):
    """The stage whose exact form alone gives the particle error the highest lowest order between successive
    meshes (``mechanism/summary``), over the mesh pairs where all MPM grows on some layout (every pair when it
    grows on none): its lowest and highest order there, all MPM's, the pairs and those converging, and the
    coarsest and the finest mesh of those pairs."""

    stage: str
    lo: float
    hi: float
    mpm_lo: float
    mpm_hi: float
    pairs: int
    converging: int
    growing: bool
    coarsest: float = math.nan
    finest: float = math.nan


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
                           sum(x >= CONVERGING_ORDER for x in lows), bool(growing),
                           max(num(r, "h_coarse") for r in mine), min(num(r, "h_fine") for r in mine))
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
        meshes = f"h = {o.coarsest:g} to {o.finest:g}: " if math.isfinite(o.coarsest + o.finest) else ""
        parts.append(f"from [{o.mpm_lo:.2f}, {o.mpm_hi:.2f}] to [{o.lo:.2f}, {o.hi:.2f}] on {problem.capitalize()} "
                     f"({meshes}{reading}{'' if o.growing else '; all MPM does not grow there'})")
    stages = list(dict.fromkeys(o.stage for _, o in found_))
    name = _and([f"the {s} stage" for s in stages]) + (" (a particle quadrature)" if "projection" in stages else "")
    stops = all(o.lo > GROWTH_ORDER for _, o in found_ if o.growing)
    verb = "stops" if stops else "does not stop"
    return labelled(f"Making {name} exact alone, every other stage in MPM form, {verb} "
                    "the growth: the particle error's order between successive meshes (all MPM, then with that stage "
                    f"exact) goes {_and(parts)}", "E6a")


def _remedy_sentence_abstract(found: Found) -> str:
    c, f = found.get("E5", (None, None))
    if f is None or f.verdict == NOT_MEASURED:
        return "Whether a remedy removes the growth is not measured in this folder (E5)"
    tried = f"Of the {len(f.table)} remedies tried, " if f.table else ""
    return labelled(f"{tried}{_lower(_clause(f)) if tried else _clause(f)}", "E5")


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
    column = "MPM/FEM at the particles, finest over coarsest"
    growth = [_number(str(r.get(column, "")).split()[0]) for r in f.table if str(r.get(column, "")).strip()]
    growth = [g for g in growth if math.isfinite(g)]
    trend = ("; so MPM falls further behind the FEM as the mesh is refined" if growth and min(growth) > 1 else
             "; so MPM gains on the FEM as the mesh is refined" if growth and max(growth) < 1 else "")
    return f"On the same meshes {fem}{_lower(key)}{trend} (E3)"


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
    n_one, n_plane = (sum(cid.startswith(k) for cid in STATEMENTS) for k in ("E", "D"))
    return ["## Introduction", "", *prose(
        "Where does the error of the material point method come from? Tran and Berzins' error analysis of explicit "
        "one-dimensional MPM names four sources (projection, finite elements with mass lumping, interpolation, time "
        "integration) and shows that on Sod's shock tube the density error stops "
        "converging as the mesh is refined while on viscous Burgers both accelerations converge at first order. "
        f"We judge the slides' {n_claims} claims, {n_one} extensions in 1D (an error budget "
        "over the stages, smoother bases, MPM beside FEM, remedies, grid masses and more) and "
        f"{n_plane} in 2D by written rules on tables one command regenerates; the tables, each "
        "claim's evidence and the rule book are in [the appendix](APPENDIX.md).")]


def abstract_sentences(text: str) -> list[str]:
    """The sentences of the abstract of a rendered report."""
    body = text.split("## Abstract", 1)[1].split("\n## ", 1)[0].split("\n![", 1)[0]
    return sentences(" ".join(line for line in body.splitlines() if line.strip()))
