"""The source's unstated settings, identified from its own tables.

The identification study (``studies/identification.py``) runs, for each of the source's tables, the
candidates for what the slides leave unsaid (Sod: particles per cell, CFL, nodal or particle density,
L1 or L2; Burgers: the exact solution, the time-step rule and its CFL, particles per cell, the norm) and
writes one row per candidate and source row to ``identification/sod`` and ``identification/burgers``.

A candidate is one setting held fixed over the whole source table, never a best fit per mesh or per
eps. Its misfit to a source row with entries ``s_k`` (the meshes, and for Burgers the five eps) is

    misfit = mean_k |log(m_k / s_k)|,

``m_k`` the candidate's measured error at entry ``k``: 0 for an exact match, ``log 2`` for a factor of
two throughout. ``misfit`` is against the corrected table (``source_corrected``), ``misfit_raw``
against the table as the slides print it. ``rank`` orders the candidates of one source row (1: the
least misfit) and ``matching`` marks every candidate within the rule book's ``IDENTIFICATION_BAND``
of the least misfit: the source-matching settings.

The criteria read the result through :func:`source_matching`; :func:`identification_sentence` says
in words whether and where the source's table is reproduced.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

from mpm_fem.measure.claims.base import Tables
from mpm_fem.measure.claims.rules import rule
from mpm_fem.measure.source import BURGERS_H, OPTIMAL_PPC, SOD

#: The source's meshes of each problem's table.
SOURCE_H = {"sod": tuple(SOD), "burgers": BURGERS_H}

#: The identification tables, by problem.
IDENTIFICATION = {"sod": "identification/sod", "burgers": "identification/burgers"}
#: The settings columns of each problem's table, in the order a candidate's label names them.
SETTINGS = {"sod": ("ppc", "cfl", "quantity", "norm"), "burgers": ("solution", "dt_rule", "cfl", "ppc", "norm")}
#: The source rows of each problem's table, and how a sentence names them.
SOURCE_ROWS = {"sod": {"L1": "L1 column", "L2": "L2 column"},
               "burgers": {"exact": "exact-acceleration row", "calculated": "calculated-acceleration row"}}
_TITLES = {"sod": "Sod", "burgers": "Burgers"}


def misfit(measured: Sequence[float], source: Sequence[float]) -> float:
    """``mean_k |log(measured_k / source_k)|`` over paired entries (same length, at least one);
    ``inf`` when a measured entry is missing, not finite or not positive (a failed run misfits)."""
    if len(measured) != len(source) or not source:
        raise ValueError(f"misfit needs paired, non-empty entries: {len(measured)} measured, {len(source)} source")
    if any(not s > 0 for s in source):
        raise ValueError(f"the source's entries must be positive, got {list(source)}")
    if any(m is None or not math.isfinite(m) or m <= 0 for m in measured):
        return math.inf
    return sum(abs(math.log(m / s)) for m, s in zip(measured, source, strict=True)) / len(source)


def candidate_rows(problem: str, settings: Mapping[str, object], measured: Mapping[object, float],
                   corrected: Mapping[str, Mapping[object, float]], raw: Mapping[str, Mapping[object, float]],
                   meshes: str, label: str) -> list[dict]:
    """One row per source row of ``corrected`` for one candidate: its ``settings`` (the columns of
    :data:`SETTINGS`), its misfit over every entry of that source row (``measured`` and the rows map
    the same entry keys, e.g. ``h`` or ``(eps, h)``; an entry the candidate lacks makes it ``inf``),
    the misfit against ``raw`` beside it, and ``meshes`` (text). ``rank`` and ``matching`` are filled
    by :func:`rank`."""
    rows = []
    for source_row, entries in corrected.items():
        keys = list(entries)
        values = [measured.get(k) for k in keys]
        rows.append({"problem": problem, "candidate": label, **{c: settings[c] for c in SETTINGS[problem]},
                     "source_row": source_row, "misfit": misfit(values, [entries[k] for k in keys]),
                     "misfit_raw": misfit(values, [raw[source_row][k] for k in keys]), "meshes": meshes,
                     "rank": 0, "matching": "False"})
    return rows


def rank(rows: list[dict]) -> list[dict]:
    """``rows`` ordered by source row and misfit, with ``rank`` (1, 2, ... within a source row; ties
    keep their order) and ``matching`` (``"True"`` within ``IDENTIFICATION_BAND`` of the row's least
    finite misfit, ``"False"`` otherwise and for every infinite misfit)."""
    band = rule("IDENTIFICATION_BAND")
    out = []
    for source_row in dict.fromkeys(r["source_row"] for r in rows):
        group = sorted((r for r in rows if r["source_row"] == source_row), key=lambda r: float(r["misfit"]))
        best = float(group[0]["misfit"])
        for k, r in enumerate(group, 1):
            m = float(r["misfit"])
            out.append({**r, "rank": k, "matching": str(math.isfinite(m) and m - best <= band)})
    return out


def source_matching(tables: Tables, problem: str, row: str | None = None) -> list[dict]:
    """The source-matching candidates of ``problem`` (``"sod"`` or ``"burgers"``): the rows of its
    identification table marked ``matching``, best ``rank`` first, for the source row ``row`` (e.g.
    ``"L1"`` for Sod, ``"calculated"`` for Burgers' calculated-acceleration row) or every row when
    ``None``. Empty when the table is missing: the criteria then say they judged at the study's
    settings."""
    if problem not in IDENTIFICATION:
        raise ValueError(f"problem {problem!r} is not one of {tuple(IDENTIFICATION)}")
    rows = [r for r in tables.get(IDENTIFICATION[problem], []) if str(r.get("matching", "")) == "True"
            and (row is None or r.get("source_row", "") == row)]
    return sorted(rows, key=lambda r: float(r.get("rank", "inf") or "inf"))


def _percent(m: float) -> str:
    """A misfit as the mean factor's excess, in per cent: ``exp(misfit) - 1``."""
    return format(math.expm1(m), ".0%").replace("%", " %") if math.isfinite(m) else "no finite factor"


def _setting(problem: str, r: Mapping) -> str:
    """A candidate's settings in words."""
    if problem == "sod":
        where = "nodal" if r["quantity"] == "nodes" else "particle"
        return f"{where} density {r['norm']} at {r['ppc']} per cell and CFL {r['cfl']}"
    rule_text = "dt ~ h" if r["dt_rule"] == "advective" else "the stable dt"
    return f"the {r['solution']} solution, {r['norm']} norm, {r['ppc']} per cell, {rule_text} at CFL {r['cfl']}"


def identification_sentence(tables: Tables, problem: str) -> str:
    """In words, from ``problem``'s identification table: per source row, whether the source's table
    is reproduced (its least misfit within ``IDENTIFICATION_REPRODUCED``) and where (the best
    candidate), as the mean factor's excess ``exp(misfit) - 1``; for Sod also the best candidate at the
    source's stated 4-8 particles per cell. Empty when the table is missing."""
    rows = tables.get(IDENTIFICATION.get(problem, ""), [])
    if not rows:
        return ""
    limit, parts = rule("IDENTIFICATION_REPRODUCED"), []
    for source_row, name in SOURCE_ROWS[problem].items():
        group = sorted((r for r in rows if r["source_row"] == source_row), key=lambda r: float(r["misfit"]))
        if not group:
            continue
        best, m = group[0], float(group[0]["misfit"])
        verb = "is reproduced within" if m <= limit else "is not reproduced: at best within"
        text = f"the source's {_TITLES[problem]} {name} {verb} {_percent(m)} by {_setting(problem, best)}"
        if problem == "sod":
            stated = [r for r in group if OPTIMAL_PPC[0] <= int(float(r["ppc"])) <= OPTIMAL_PPC[1]]
            if stated and stated[0] is not best:
                text += (f", at the source's {OPTIMAL_PPC[0]}-{OPTIMAL_PPC[1]} per cell within "
                         f"{_percent(float(stated[0]['misfit']))} at best")
        parts.append(text)
    if not parts:
        return ""
    meshes = sorted({float(h) for r in rows for h in str(r.get("meshes", "")).split()}, reverse=True)
    layout = next((r["value"] for r in tables.get("settings", []) if r["table"] == IDENTIFICATION[problem]
                   and r["key"] == "layout"), "")
    where = (f" ({f'the {layout} layout, ' if layout else ''}on {len(meshes)} of the source's "
             f"{len(SOURCE_H[problem])} meshes, h = {meshes[0]:g} to {meshes[-1]:g})") if meshes else ""
    text = "; ".join(parts) + where + "."
    return text[0].upper() + text[1:]
