"""E5: does a remedy remove the MPM plateau? The criterion as data, from ``remedies/errors.csv``.

A remedy **removes the plateau** on a problem when the observed order of both error measures, the
L1 norm over the grid nodes and over the particles, stays ``>= 0.8`` between every pair of
successive meshes. The **goal** is a remedy that

- removes the plateau on Sod (density) and comes within 1.5x of the finite-volume reference at
  every ``h``, over nodes and over particles;
- converges at first order or better on Burgers with 4 particles per cell (velocity): the plateau
  removed and the least-squares order over the meshes ``>= 1`` for both measures.

Verdicts: ``confirmed`` (a remedy meets the goal; the evidence names it), ``partly`` (a remedy
removes the plateau on Sod but misses the rest of the goal), ``refuted`` (no remedy removes it;
the evidence names the closest), ``not measured`` (fewer than two meshes). Wall time is not used.
"""

from __future__ import annotations

import numpy as np

PLATEAU_ORDER = 0.8
FV_FACTOR = 1.5
BURGERS_ORDER = 1.0
MEASURES = ("nodes_L1", "particles_L1")


def _series(rows: list[dict], problem: str) -> dict[str, list[dict]]:
    """``{remedy: rows sorted by decreasing h}`` of one problem."""
    out: dict[str, list[dict]] = {}
    for r in rows:
        if r["problem"] == problem:
            out.setdefault(r["remedy"], []).append(r)
    return {k: sorted(v, key=lambda r: -float(r["h"])) for k, v in out.items()}


def _value(row: dict, key: str) -> float:
    v = row.get(key, "")
    return float(v) if v not in ("", None) else float("nan")


def orders(rows: list[dict], measure: str) -> np.ndarray:
    """Observed orders between successive meshes (nan where a run failed)."""
    h = np.array([_value(r, "h") for r in rows])
    e = np.array([_value(r, measure) for r in rows])
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.log(e[:-1] / e[1:]) / np.log(h[:-1] / h[1:])


def assess(rows: list[dict]) -> dict:
    """What E5 asks of one remedy on one problem: the lowest successive order of each measure, the
    least-squares orders, the largest ratio to the FV reference (if there is one)."""
    out = {"meshes": len(rows)}
    for m in MEASURES:
        o = orders(rows, m)
        out[f"min_order_{m}"] = float(np.min(o)) if o.size and not np.isnan(o).any() else float("nan")
        h = np.array([_value(r, "h") for r in rows])
        e = np.array([_value(r, m) for r in rows])
        ok = e > 0
        out[f"fitted_order_{m}"] = float(np.polyfit(np.log(h[ok]), np.log(e[ok]), 1)[0]) if ok.sum() >= 2 else float("nan")
        ratio = np.array([_value(r, m) / _value(r, "fv_L1") for r in rows]) if rows and "fv_L1" in rows[0] else np.array([])
        out[f"max_fv_ratio_{m}"] = float(np.max(ratio)) if ratio.size else float("nan")
    out["removes_plateau"] = all(out[f"min_order_{m}"] >= PLATEAU_ORDER for m in MEASURES)
    return out


def verdict(tables: dict[str, list[dict]]) -> tuple[str, str]:
    """E5 from ``tables["errors"]`` (rows of ``errors.csv``): ``(verdict, evidence)``."""
    rows = tables.get("errors", [])
    sod, burgers = _series(rows, "sod"), _series(rows, "burgers")
    sod = {k: v for k, v in sod.items() if len(v) >= 2}
    if not sod:
        return "not measured", "no Sod remedy was run on two meshes or more"
    scored = []
    for name, series in sod.items():
        s = assess(series)
        fv = all(s[f"max_fv_ratio_{m}"] <= FV_FACTOR for m in MEASURES)
        b = assess(burgers[name]) if len(burgers.get(name, [])) >= 2 else None
        b_ok = b is not None and b["removes_plateau"] and all(b[f"fitted_order_{m}"] >= BURGERS_ORDER for m in MEASURES)
        closeness = (s["removes_plateau"] + fv + b_ok, min(s[f"min_order_{m}"] for m in MEASURES))
        scored.append((closeness, name, s, fv, b, b_ok))
    scored.sort(key=lambda x: (x[0][0], np.nan_to_num(x[0][1], nan=-np.inf)), reverse=True)
    _, name, s, fv, b, b_ok = scored[0]
    hs = sorted({float(r["h"]) for v in sod.values() for r in v}, reverse=True)
    text = (f"{name}: Sod lowest order {s['min_order_nodes_L1']:.2f} (nodes) / {s['min_order_particles_L1']:.2f} "
            f"(particles) over h = {hs[0]:g}..{hs[-1]:g}, at most {s['max_fv_ratio_nodes_L1']:.2f}x / "
            f"{s['max_fv_ratio_particles_L1']:.2f}x the FV error")
    text += (f"; Burgers 4 ppc orders {b['fitted_order_nodes_L1']:.2f} (nodes) / {b['fitted_order_particles_L1']:.2f} "
             f"(particles), lowest successive {min(b['min_order_nodes_L1'], b['min_order_particles_L1']):.2f}"
             if b else "; Burgers not run")
    removers = [n for _, n, sc, *_ in scored if sc["removes_plateau"]]
    if s["removes_plateau"] and fv and b_ok:
        return "confirmed", "meets the goal: " + text
    if removers:
        return "partly", f"removes the Sod plateau: {', '.join(removers)}; closest to the goal: " + text
    return "refuted", "no remedy keeps order >= 0.8 on every Sod mesh; closest: " + text
