"""The Burgers study's tables, from its runs: the rows of ``errors``, ``orders``, ``seeds``, ``norms``,
``timestep``, ``ppc``, ``lumping`` and ``diagnosis`` (``studies/burgers.py`` plans the runs).

A run's result is the dict of ``studies/burgers.run_case``: ``ok``, and for a run that finished the
velocity errors at T over ``particles`` and ``nodes`` (``{"L1", "L2", "max"}`` each; FEM: nodes
only), ``steps``, ``dt``. The *compared* error is the place and norm the tables set beside the
source's (``where``, ``norm``: particles, max). A *seeded* setting has runs on several particle
layouts at each mesh (the regular one, seed 0, and jittered ones); its spread over them is
:mod:`mpm_fem.measure.seeds`'.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Mapping, Sequence

import numpy as np

from mpm_fem.measure import source
from mpm_fem.measure.errors import fitted_order, observed_orders, orders_row
from mpm_fem.measure.seeds import LEVEL, order_spread, spread

WHERES, NORMS = ("particles", "nodes"), ("L1", "L2", "max")
#: The errors whose spread over the runs of a seeded setting the errors table carries (besides the compared one).
SPREAD_ERRORS = ("particles_L1", "nodes_L1")
#: The particle layouts (``mpm_fem.core.particles.seed_positions``) and the orders' intervals, as the
#: JSON beside the seeded tables states them.
LAYOUTS = {"regular": "the midpoints of N_p equal sub-cells of every cell (no random draw)",
           "jittered": "each regular point moved uniformly within its sub-cell (numpy default_rng(seed)); every "
                       "particle's volume h/N_p"}
INTERVAL = ("fitted_lo, fitted_hi: the least and largest of the runs' fitted orders on runs_h_range; fitted_t_lo, "
            f"fitted_t_hi: the Student-t interval of their mean at level {LEVEL}")


def value(r: dict, where: str, norm: str) -> float:
    """The ``norm`` error over ``where`` of run ``r``; NaN when the run failed or has no such error."""
    return r[where][norm] if r.get("ok") and where in r else float("nan")


def norms_of(r: dict, wheres=WHERES) -> dict:
    """``{"<where>_<norm>": error}`` of run ``r`` for every place in ``wheres`` and norm."""
    return {f"{w}_{k}": value(r, w, k) for w in wheres for k in NORMS}


def _positive(v) -> bool:
    return bool(np.all(np.isfinite(v) & (np.asarray(v) > 0)))


def errors_and_orders(table: Mapping, seeds: Mapping, methods: Mapping[str, dict], solutions: Sequence[str],
                      default: str, where: str, norm: str) -> tuple[list[dict], list[dict]]:
    """The ``errors`` and ``orders`` rows.

    ``table``: ``{(solution, method, eps, h): run}`` (``solutions`` in the tables' order); ``seeds``:
    ``{(method, eps, h, layout, seed): run}`` of the ``default`` solution, whose regular runs join the
    table; ``methods``: by name
    (in the tables' order), ``{"source_row": "exact" | "calculated" | None, "ppc": int | ""}``.
    An errors row holds a run's errors beside the source's entry (``source``, the ratio of the compared
    error to it) and, for a seeded setting, ``runs`` and the mean and range (``_mean``, ``_lo``,
    ``_hi``) over its runs of the compared error and of :data:`SPREAD_ERRORS`. An orders row holds the
    regular run's orders over its meshes (:func:`mpm_fem.measure.errors.orders_row`; ``fitted``), the
    source's fitted order where the source has every mesh, and over the runs of a seeded setting
    (``runs`` of them, on the meshes ``runs_h_range`` they share) the mean, range and Student-t
    interval of the runs' fitted orders and the range of each successive order (``order_lo_<h1>_<h2>``,
    ``order_hi_<h1>_<h2>``); a setting of one run has its own order as the mean and no interval."""
    runs = dict(table)
    by_run = defaultdict(dict)  # (method, eps, h) -> {(layout, seed): run}
    for (m, eps, h, layout, seed), r in seeds.items():
        by_run[(m, eps, h)][(layout, seed)] = r
        if layout == "regular":
            runs.setdefault((default, m, eps, h), r)
    compared = f"{where}_{norm}"
    rows, series = [], defaultdict(dict)
    names = list(methods)
    def order(run):  # by solution and method in their orders, then decreasing eps and h
        (sol, m, eps, h), _ = run
        return solutions.index(sol), names.index(m), -eps, -h

    for (sol, m, eps, h), r in sorted(runs.items(), key=order):
        src_row = methods[m]["source_row"]
        src = source.burgers_value(src_row, eps, h)
        row = {"solution": sol, "method": m, "ppc": methods[m]["ppc"], "eps": eps, "h": h, **norms_of(r)}
        row.update({"source": src if src is not None else "",
                    "source_corrected": "yes" if (src_row, eps, h) in source.BURGERS_CORRECTED else "",
                    f"ratio_{compared}": row[compared] / src if src else "",
                    "steps": r.get("steps", ""), "dt": r.get("dt", ""), "particles": r.get("n_p", ""),
                    "error": r.get("error", "")})
        layouts = by_run.get((m, eps, h), {}) if sol == default else {}
        row["runs"] = len(layouts) or 1
        for column in (compared,) + SPREAD_ERRORS:
            s = spread(value(x, *column.split("_")) for x in layouts.values()) if len(layouts) > 1 else {}
            row.update({f"{column}_{k}": s.get(k, "") for k in ("mean", "lo", "hi")})
        rows.append(row)
        series[(sol, m, eps)][h] = row
    orders = []
    for (sol, m, eps), by_h in series.items():
        hs = sorted(by_h, reverse=True)
        src = [source.burgers_value(methods[m]["source_row"], eps, h) for h in hs]
        seeded = {h: layouts for (mm, ee, h), layouts in by_run.items() if (mm, ee) == (m, eps)}
        for w in WHERES:
            for n in NORMS:
                v = np.array([by_h[h][f"{w}_{n}"] for h in hs])
                if len(hs) < 2 or not _positive(v):
                    continue
                row = {"solution": sol, "method": m, "ppc": methods[m]["ppc"], "eps": eps, "where": w, "norm": n,
                       **orders_row(hs, v)}
                if None not in src:
                    row["source_fitted"] = fitted_order(hs, src)
                orders.append({**row, **_order_spread(seeded if sol == default else {}, w, n, row)})
    return rows, orders


def _order_spread(seeded: Mapping[float, Mapping], where: str, norm: str, regular: dict) -> dict:
    """The orders row's columns over the runs of a seeded setting (``{h: {(layout, seed): run}}``)."""
    runs = defaultdict(dict)
    for h, layouts in seeded.items():
        for layout, r in layouts.items():
            runs[layout][h] = value(r, where, norm)
    s = order_spread(runs) if len(runs) > 1 else None
    if s is None or not s["fitted"]:
        return {"runs": 1, "runs_h_range": regular["h_range"], "fitted_mean": regular["fitted"], "fitted_lo": "",
                "fitted_hi": "", "fitted_t_lo": "", "fitted_t_hi": ""}
    pairs = {f"order_{k}_{a}_{b}": p[k] for (a, b), p in s["pairs"].items() for k in ("lo", "hi")}
    return {"runs": s["runs"], "runs_h_range": f"{s['h'][0]}-{s['h'][-1]}", "fitted_mean": s["mean"],
            "fitted_lo": s["lo"], "fitted_hi": s["hi"], "fitted_t_lo": s["t_lo"], "fitted_t_hi": s["t_hi"], **pairs}


def meshes_of(pairs) -> dict:
    """``{name: [h, ...]}``, coarsest first, of the ``(name, h)`` pairs."""
    found = defaultdict(set)
    for name, h in pairs:
        found[name].add(h)
    return {name: sorted(hs, reverse=True) for name, hs in sorted(found.items())}


def seeds_rows(seeds: Mapping, settings: Mapping[str, dict]) -> list[dict]:
    """One row per run of ``seeds`` (``{(method, eps, h, layout, seed): run}``): its settings (the
    method's ``settings``: ``acceleration``, ``dt_rule``, ``ppc``) and its errors."""
    rows = []
    def order(run):  # by method, decreasing eps and h, the regular layout first, by seed
        (m, eps, h, layout, seed), _ = run
        return m, -eps, -h, layout != "regular", seed

    for (m, eps, h, layout, seed), r in sorted(seeds.items(), key=order):
        s = settings[m]
        rows.append({"method": m, "acceleration": s["acceleration"], "dt_rule": s.get("dt_rule", "stable"),
                     "ppc": s["ppc"], "eps": eps, "h": h, "layout": layout, "seed": seed, **norms_of(r),
                     "steps": r.get("steps", ""), "error": r.get("error", "")})
    return rows


def norms_rows(table: Mapping, source_row: Mapping[str, str | None]) -> list[dict]:
    """For each solution, method, place and norm: median of measured/source and its spread (max/min
    over the common cells of the table), and the spread over eps on the finest common mesh."""
    groups = defaultdict(list)
    for (sol, m, eps, h), r in table.items():
        src = source.burgers_value(source_row[m], eps, h)
        measured = {} if src is None else {tuple(k.split("_")): v for k, v in norms_of(r).items()}
        for (where, norm), v in measured.items():
            if np.isfinite(v) and v > 0:
                groups[(sol, m, where, norm)].append((eps, h, v, src))
    rows = []
    for (sol, m, where, norm), vals in sorted(groups.items()):
        ratio = np.array([v / s for _, _, v, s in vals])
        finest = min(h for _, h, _, _ in vals)
        fine = [(v, s) for _, h, v, s in vals if h == finest]
        ratio_of = lambda xs, fine=fine: float(max(xs) / min(xs)) if len(fine) > 1 else ""  # noqa: E731
        rows.append({"solution": sol, "method": m, "where": where, "norm": norm, "cells": len(vals),
                     "median_ratio": float(np.median(ratio)), "ratio_spread": float(ratio.max() / ratio.min()),
                     "log10_ratio_rms": float(np.sqrt(np.mean(np.log10(ratio) ** 2))),
                     "eps_spread_finest": ratio_of([v for v, _ in fine]),
                     "source_eps_spread_finest": ratio_of([s for _, s in fine]), "finest_h": finest})
    return rows


def timestep_rows(runs: Mapping, time_h: float, refine: Sequence[int], where: str, norm: str) -> list[dict]:
    """``runs``: ``{(method, eps, k): run}`` at ``h = time_h`` with ``dt / k`` for ``k`` in ``refine``;
    the time error of each ``dt`` estimated against the finest, ``dt / refine[-1]``."""
    rows = []
    def order(run):  # by method, decreasing eps, increasing refinement
        (m, eps, k), _ = run
        return m, -eps, k

    for (m, eps, k), r in sorted(runs.items(), key=order):
        finest = runs[(m, eps, refine[-1])]
        row = {"method": m, "eps": eps, "h": time_h, "refine": k, "steps": r.get("steps", ""), "dt": r.get("dt", "")}
        for n in NORMS:
            v, ref = value(r, where, n), value(finest, where, n)
            row.update({f"{where}_{n}": v, f"time_error_{n}": abs(v - ref) if k != refine[-1] else ""})
        ref = value(finest, where, norm)
        below = abs(row[f"{where}_{norm}"] - ref) < ref
        row["time_below_space"] = ("yes" if below else "no") if k != refine[-1] else ""
        rows.append(row)
    return rows


def ppc_rows(runs: Mapping, eps: float, where: str, norm: str) -> list[dict]:
    """``runs``: ``{(method, h, ppc): run}``; ``best_ppc``: the particles per cell of the smallest
    compared error of the method and mesh."""
    def order(run):  # by method, decreasing h, increasing ppc
        (m, h, n), _ = run
        return m, -h, n

    rows = [{"method": m, "eps": eps, "h": h, "ppc": n, **norms_of(r), "steps": r.get("steps", ""),
             "error": r.get("error", "")}
            for (m, h, n), r in sorted(runs.items(), key=order)]
    for m, h in {(r["method"], r["h"]) for r in rows}:
        sub = [r for r in rows if r["method"] == m and r["h"] == h and np.isfinite(r[f"{where}_{norm}"])]
        for r in sub:
            r["best_ppc"] = min(sub, key=lambda r: r[f"{where}_{norm}"])["ppc"]
    return rows


def lumping_rows(runs: Mapping, eps: float, where: str) -> list[dict]:
    """``runs``: ``{(method, mass, h): run}``; MPM's errors over ``where``, FEM's over nodes."""
    def place(m):
        return "nodes" if m.startswith("fem") else where

    def order(run):  # by method, mass, decreasing h
        (m, mass, h), _ = run
        return m, mass, -h

    return [{"method": m, "mass": mass, "eps": eps, "h": h, "where": place(m),
             **{k: value(r, place(m), k) for k in NORMS}, "nodes_L2": value(r, "nodes", "L2"), "dt": r.get("dt", ""),
             "error": r.get("error", "")}
            for (m, mass, h), r in sorted(runs.items(), key=order)]


def diagnosis_rows(runs: Mapping, variants: Mapping[str, dict], eps: float, where: str) -> list[dict]:
    """``runs``: ``{(label, h): run}``, one change (``variants[label]``) at a time; ``order_L1``:
    the observed order of the L1 error over ``where`` against the next coarser mesh."""
    rows = [{"variant": label, "changes": repr(variants[label]), "eps": eps, "h": h, **norms_of(r),
             "error": r.get("error", "")} for (label, h), r in runs.items()]
    for label in variants:
        sub = sorted((r for r in rows if r["variant"] == label), key=lambda r: -r["h"])
        v = np.array([r[f"{where}_L1"] for r in sub])
        if len(sub) > 1 and _positive(v):
            for r, o in zip(sub[1:], observed_orders([r["h"] for r in sub], v), strict=True):
                r["order_L1"] = float(o)
    return rows
