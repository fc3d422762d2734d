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
from collections.abc import Mapping

from mpm_fem.measure.claims.base import Tables
from mpm_fem.measure.claims.rules import rule
from mpm_fem.measure.misfit import misfit
from mpm_fem.measure.misfit import row_misfit as _row_misfit
from mpm_fem.measure.source import BURGERS_H, OPTIMAL_PPC, SOD

#: The source's meshes of each problem's table.
SOURCE_H = {"sod": tuple(SOD), "burgers": BURGERS_H}

#: The identification tables, by problem.
IDENTIFICATION = {"sod": "identification/sod", "burgers": "identification/burgers"}
#: The settings columns of each problem's table, in the order a candidate's label names them.
SETTINGS = {"sod": ("ppc", "cfl", "readout", "norm"),
            "burgers": ("solution", "params", "dt_rule", "cfl", "ppc", "readout", "norm")}
#: The source rows of each problem's table, and how a sentence names them.
SOURCE_ROWS = {"sod": {"L1": "L1 column", "L2": "L2 column"},
               "burgers": {"exact": "exact-acceleration row", "calculated": "calculated-acceleration row"}}
_TITLES = {"sod": "Sod", "burgers": "Burgers"}


def row_misfit(measured: Mapping[tuple, float | None], source: Mapping[tuple, float]) -> float:
    """:func:`mpm_fem.measure.misfit.row_misfit` with the rule book's ``IDENTIFICATION_SPREAD_WEIGHT``."""
    return _row_misfit(measured, source, rule("IDENTIFICATION_SPREAD_WEIGHT"))


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
            and (row is None or r.get("source_row", "") == row)
            and (problem == "sod" or r.get("fit", "table") == "table")]  # Sod's candidates fit no whole table
    return sorted(rows, key=lambda r: float(r.get("rank", "inf") or "inf"))


def _percent(m: float) -> str:
    """A misfit as the mean factor's excess, in per cent: ``exp(misfit) - 1``."""
    return format(math.expm1(m), ".0%").replace("%", " %") if math.isfinite(m) else "no finite factor"


def _setting(problem: str, r: Mapping) -> str:
    """A candidate's settings in words."""
    if problem == "sod":
        where = "nodal" if readout(r) == "nodes" else "particle"
        return f"{where} density {r['norm']} at {r['ppc']} per cell and CFL {float(r['cfl']):.3g}"
    params = "" if r.get("params", "defaults") == "defaults" else f" ({r['params']})"
    return (f"the {r['solution']} solution{params}, {r['norm']} norm over {readout(r)}, {r['ppc']} per cell, "
            f"dt ~ h at CFL {float(r['cfl']):.3g}")


def readout(r: Mapping) -> str:
    """A row's read-out (``particles`` or ``nodes``; tables written before 2026-12-02 name it ``quantity``)."""
    return str(r.get("readout") or r.get("quantity", ""))


def _table_rows(rows: list[dict]) -> list[dict]:
    """Burgers' whole-table candidates (``fit`` = ``table``) by ``table_misfit``, least first."""
    return sorted((r for r in rows if r.get("fit", "table") == "table"), key=_table_misfit)


def _table_misfit(r: Mapping) -> float:
    """A whole-table candidate's misfit (a table written before 2026-12-02: its row's misfit)."""
    return float(r.get("table_misfit") or r["misfit"])


def _sod_sentence(rows: list[dict], limit: float) -> str:
    group = sorted((r for r in rows if r["source_row"] == "L1"), key=lambda r: float(r["misfit"]))
    if not group:
        return ""
    best, m = group[0], float(group[0]["misfit"])
    verb = "is reproduced within" if m <= limit else "is not reproduced: at best within"
    text = f"the source's Sod L1 column {verb} {_percent(m)} by {_setting('sod', best)}"
    if best.get("misfit_held_out", "") != "":
        text += f" (CFL fitted), the L2 column held out within {_percent(float(best['misfit_held_out']))}"
    stated = [r for r in group if OPTIMAL_PPC[0] <= int(float(r["ppc"])) <= OPTIMAL_PPC[1]]
    if stated and stated[0] is not best:
        text += (f"; at the source's {OPTIMAL_PPC[0]}-{OPTIMAL_PPC[1]} per cell within "
                 f"{_percent(float(stated[0]['misfit']))} at best")
    return text


def _trends(identified: list[dict], row: str) -> str:
    """The identified Burgers setting's measured/source ratio of ``row`` on the regular layout: by mesh at
    the largest eps, and by eps on the coarsest mesh."""
    found = [r for r in identified if r.get("problem") == "burgers" and r["source_row"] == row
             and r["layout"] == "regular"]
    if not found:
        return ""
    coarse, largest = max(float(r["h"]) for r in found), max(float(r["eps"]) for r in found)
    by_h = {float(r["h"]): float(r["ratio"]) for r in found if float(r["eps"]) == largest}
    by_eps = {float(r["eps"]): float(r["ratio"]) for r in found if float(r["h"]) == coarse}
    meshes = ", ".join(f"{by_h[h]:.2f} at h = {h:g}" for h in sorted(by_h, reverse=True))
    viscosities = ", ".join(f"{by_eps[e]:.2f} at eps {e:g}" for e in sorted(by_eps, reverse=True))
    return f"{row}-row error / source's {meshes} (eps {largest:g}) and {viscosities} (h = {coarse:g})"


def _burgers_sentence(rows: list[dict], tables: Tables, limit: float) -> str:
    table = _table_rows(rows) if "fit" in rows[0] else []  # a table before 2026-12-02 fitted no whole table
    if not table:
        return ""
    best = table[0]
    m = _table_misfit(best)
    pair = {r["source_row"]: r for r in table if r["candidate"] == best["candidate"]}
    if set(pair) != {"exact", "calculated"}:  # a table of one row per candidate (before 2026-12-02)
        return ""
    verb = "is reproduced within" if m <= limit else "is not reproduced by one setting: at best within"
    text = (f"the source's Burgers table (both rows) {verb} {_percent(m)} by {_setting('burgers', pair['exact'])} "
            f"for the exact row and the stable dt at CFL {float(pair['calculated']['cfl']):.3g} for the calculated "
            f"one (exact row {_percent(float(pair['exact']['misfit']))}, calculated "
            f"{_percent(float(pair['calculated']['misfit']))}; held out ({best.get('held_out', '')}) "
            f"{_percent(float(pair['exact']['misfit_held_out']))} and "
            f"{_percent(float(pair['calculated']['misfit_held_out']))})")
    if m > limit:
        families = {}
        for r in table:
            families.setdefault(r["solution"], _table_misfit(r))
        worse = max(pair, key=lambda k: float(pair[k]["misfit"]))
        trend = _trends(tables.get("identification/identified", []), worse)
        text += (f"; the closest family is the {best['solution']} solution, the others at best within "
                 + ", ".join(f"{_percent(v)} ({k})" for k, v in families.items() if k != best["solution"])
                 + f"; what keeps it off is its {worse} row" + (f", rerun: {trend}, where the source's falls at "
                                                                "first order in h"
                                                                if trend else ""))
    diagnostic = [r for r in rows if r.get("fit") == "eps" and str(r.get("rank")) == "1"]
    if diagnostic:
        per = {}
        for r in diagnostic:
            per.setdefault(r["source_row"], []).append(f"{_percent(float(r['misfit']))} at eps {float(r['eps']):g} "
                                                       f"({r['solution']})")
        text += "; one row at one eps alone: " + "; ".join(f"{k} row {', '.join(v)}" for k, v in per.items())
    return text


def identification_sentence(tables: Tables, problem: str) -> str:
    """In words, from ``problem``'s identification table: whether the source's table is reproduced (the
    least misfit within ``IDENTIFICATION_REPRODUCED``) and where (the best candidate), as the mean factor's
    excess ``exp(misfit) - 1``, with the held-out misfit; Sod: the L1 column and, beside it, the best at
    the source's 4-8 per cell; Burgers: the whole table, the closest family and its trend over eps when
    it is not reproduced, and the per-eps diagnostic; the refinement test's change. Empty when the table
    is missing."""
    rows = tables.get(IDENTIFICATION.get(problem, ""), [])
    if not rows:
        return ""
    limit = rule("IDENTIFICATION_REPRODUCED")
    text = _sod_sentence(rows, limit) if problem == "sod" else _burgers_sentence(rows, tables, limit)
    if not text:
        return ""
    meshes = sorted({float(h) for r in rows for h in str(r.get("meshes", "")).split()}, reverse=True)
    layout = next((r["value"] for r in tables.get("settings", []) if r["table"] == IDENTIFICATION[problem]
                   and r["key"] == "layout"), "")
    where = (f" (the search on {f'the {layout} layout and ' if layout else ''}{len(meshes)} of the source's "
             f"{len(SOURCE_H[problem])} meshes, h = {meshes[0]:g} to {meshes[-1]:g})") if meshes else ""
    refined = [r for r in tables.get("identification/refinement", []) if r.get("problem") == problem
               and r.get("tolerance") == "halved"]
    if refined:
        change, limit = float(refined[0]["change"]), rule("IDENTIFICATION_REFINED")
        converged = "below {limit:g}: converged" if change < limit else "not below {limit:g}: not converged"
        text += (f"; halving every tolerance of the search moves its best misfit by {change:.3f} "
                 f"({converged.format(limit=limit)})")
    text = text + where + "."
    return text[0].upper() + text[1:]
