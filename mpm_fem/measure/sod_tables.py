"""The Sod study's tables, built from its measured runs (:mod:`mpm_fem.measure.shock_tube`).

The runs are keyed as the study plans them: ``regular[(ppc, cfl, h)]`` the regular layout of each
setting (new extrema counted), ``jittered[(ppc, cfl, h, seed)]`` the jittered layouts, ``fem_consistent[h]``,
``fem_lumped[h]`` and ``fv[h]`` the fixed-mesh references. Every MPM run is one row of ``seeds``
(the regular layout as seed 0); ``convergence`` has one row per setting and mesh: the regular
layout's errors beside the source's table, the mean and range of the jittered layouts' errors, and
each observed order with its range over every seed run on both meshes (:mod:`mpm_fem.measure.spread`).
"""

from __future__ import annotations

import math

import numpy as np

from mpm_fem.measure.errors import orders_column
from mpm_fem.measure.regions import REGION_NAMES
from mpm_fem.measure.spread import NONE, by_mesh, order_spreads, spread

#: The errors of a run recorded per seed: column of ``seeds`` -> (field, where, norm) of the result.
SEED_ERRORS = {"particles_L1": ("density", "particles", "L1"), "particles_L2": ("density", "particles", "L2"),
               "nodes_L1": ("density", "nodes", "L1"), "nodes_L2": ("density", "nodes", "L2"),
               "energy_L1": ("energy", "particles", "L1")}
#: The errors whose spread over seeds the convergence table carries (particles first: the source's quantity).
SPREAD_OF = ("particles_L1", "energy_L1", "nodes_L1")
STATS = ("mean", "lo", "hi")

#: the smooth region's column of a run's regions (:data:`REGION_NAMES`)
SMOOTH = REGION_NAMES.index("smooth")


def error(r: dict, field: str = "density", where: str = "nodes", norm: str = "L1") -> float:
    """One norm of a run's error; NaN when the run failed."""
    return r[field][where][norm] if r.get("ok") else math.nan


def _settings(runs: dict) -> list[tuple]:
    """The settings ``(ppc, cfl)`` of ``runs`` (``{(ppc, cfl, h): run}``), in their order."""
    return list(dict.fromkeys((n, cfl) for n, cfl, _ in runs))


def _seed_order(run: tuple) -> tuple:
    """The order of the seeds table: by decreasing ppc, by CFL, by decreasing h, by seed."""
    (n, cfl, h, _, seed), _ = run
    return -n, cfl, -h, seed


def seed_rows(regular: dict, jittered: dict) -> list[dict]:
    """One row per MPM run: the setting, mesh, layout and seed, its errors, volume drift and steps."""
    runs = [((n, cfl, h, "regular", 0), r) for (n, cfl, h), r in regular.items()]
    runs += [((n, cfl, h, "jittered", seed), r) for (n, cfl, h, seed), r in jittered.items()]
    rows = []
    for (n, cfl, h, layout, seed), r in sorted(runs, key=_seed_order):
        rows.append({"h": h, "ppc": n, "cfl": cfl, "layout": layout, "seed": seed, "ok": bool(r.get("ok")),
                     **{k: error(r, *where) for k, where in SEED_ERRORS.items()},
                     "volume_drift": r.get("volume_drift", math.nan), "steps": r.get("steps"),
                     "error": "" if r.get("ok") else r.get("error", "")})
    return rows


def convergence_rows(seeds: list[dict], regular: dict, fem_consistent: dict, fem_lumped: dict, fv: dict,
                     source: dict) -> list[dict]:
    """Per setting and mesh (decreasing ``h``): the source's table, the regular layout's errors, ratios
    to the source and orders; the jittered layouts' mean and range (``jittered_<q>_mean|lo|hi``) and
    the order's mean and range over every seed (``order_<q>_mean|lo|hi``, :data:`SPREAD_OF`); FEM and
    FV on the same mesh; the regular run's diagnostics."""
    rows = []
    for n, cfl in _settings(regular):
        hs = sorted((h for (m, c, h) in regular if (m, c) == (n, cfl)), reverse=True)
        runs = [regular[(n, cfl, h)] for h in hs]
        cols = {f"{w}_{k}": [error(r, "density", w, k) for r in runs]
                for w in ("nodes", "particles") for k in ("L1", "L2")}
        cols["energy_L1"] = [error(r, "energy", "particles") for r in runs]
        cols.update({f"{m}_L1": [error(refs[h], "density", where) for h in hs]
                     for m, refs, where in (("fem_consistent", fem_consistent, "nodes"),
                                            ("fem_lumped", fem_lumped, "nodes"), ("fv", fv, "cells"))})
        orders = {k: orders_column(hs, v) for k, v in cols.items()}
        in_source = [h for h in hs if h in source]
        src_orders = dict(zip(in_source, orders_column(in_source, [source[h][0] for h in in_source]), strict=True))
        mine = [r for r in seeds if (r["ppc"], r["cfl"]) == (n, cfl)]
        jittered = {q: by_mesh([r for r in mine if r["layout"] == "jittered"], q) for q in SPREAD_OF}
        spreads = {q: {b: s for _, b, s in order_spreads(mine, q)} for q in SPREAD_OF}
        for k, (h, r) in enumerate(zip(hs, runs, strict=True)):
            s = dict(zip(("L1", "L2"), source.get(h, ("", "")), strict=True))
            row = {"ppc": n, "cfl": cfl, "h": h, "source_L1": s["L1"], "source_L2": s["L2"],
                   "source_order_L1": src_orders.get(h, "")}
            for key in ("nodes_L1", "nodes_L2", "particles_L1", "particles_L2"):
                ratio = cols[key][k] / s[key[-2:]] if h in source else ""
                row.update({f"mpm_{key}": cols[key][k], f"ratio_{key}": ratio})
                if key != "particles_L2":
                    row[f"order_{key}"] = orders[key][k]
            row.update({"mpm_energy_L1": cols["energy_L1"][k], "order_energy_L1": orders["energy_L1"][k],
                        "seeds": len([x for x in mine if x["h"] == h and x["ok"]])})
            for q in SPREAD_OF:
                level, order = spread(jittered[q].get(h, {}).values()), spreads[q].get(h, NONE)
                row.update({f"jittered_{q}_{stat}": _blank(getattr(level, stat), level.n) for stat in STATS})
                row.update({f"order_{q}_{stat}": _blank(getattr(order, stat), order.n) for stat in STATS})
            for m in ("fem_consistent", "fem_lumped", "fv"):
                row.update({f"{m}_L1": cols[f"{m}_L1"][k], f"order_{m}_L1": orders[f"{m}_L1"][k]})
            row.update(_diagnostics(r, fem_consistent[h]))
            rows.append(row)
    return rows


def _blank(value: float, n: int):
    return value if n else ""


def _diagnostics(r: dict, fem: dict) -> dict:
    ok = r.get("ok")
    return {"mpm_particles_mean_error_smooth": r["mean_error"]["particles"][SMOOTH] if ok else "",
            "mpm_nodes_mean_error_smooth": r["mean_error"]["nodes"][SMOOTH] if ok else "",
            "mpm_volume_drift": r.get("volume_drift", ""), "mpm_head_shift": r.get("head_shift", ""),
            "fem_consistent_head_shift": fem.get("head_shift", ""), "mpm_steps": r.get("steps"),
            "mpm_particles": r.get("particles"), "mpm_wall_s": round(r.get("wall_s", math.nan), 2),
            "mpm_energy_drift": r.get("energy_drift", "")}


def region_rows(regular: dict, fem_consistent: dict, fem_lumped: dict) -> list[dict]:
    """The density L1 by region of the exact solution (C12): MPM at the nodes and at the particles for
    every setting, the fixed-mesh FEM at its nodes (``ppc``, ``cfl`` empty)."""
    groups = [(f"MPM {where}", (n, cfl), {h: r for (m, c, h), r in regular.items() if (m, c) == (n, cfl)}, where)
              for n, cfl in _settings(regular) for where in ("nodes", "particles")]
    groups += [(label, ("", ""), runs, "nodes") for label, runs in (("FEM consistent", fem_consistent),
                                                                   ("FEM lumped", fem_lumped))]
    rows = []
    for label, (n, cfl), runs, where in groups:
        for h, r in sorted(runs.items(), reverse=True):
            if r["ok"]:
                parts, total = np.asarray(r["regions"][where]), r["density"][where]["L1"]
                rows.append({"method": label, "ppc": n, "cfl": cfl, "h": h, "L1": total,
                             "sum_of_regions": float(parts.sum()),
                             **{f"L1_{k}_{name.replace(' ', '_')}": float(p)
                                for k, (name, p) in enumerate(zip(REGION_NAMES, parts, strict=True))},
                             **{f"share_{k}": float(p / total) for k, p in enumerate(parts)}})
    return rows


def extrema_rows(regular: dict) -> list[dict]:
    """New extrema of density and energy per setting and mesh (C14): at crossings, at the other
    particles, at the other particles that move; ``<field>_rate_ratio`` crossing / other and
    ``<field>_moving_ratio`` crossing / moving non-crossing."""
    rows = []
    for (n, cfl, h), r in regular.items():
        if not (r["ok"] and r.get("extrema")):
            continue
        x = r["extrema"]
        row = {"ppc": n, "cfl": cfl, "h": h, "steps": x["steps"], "crossings": x["crossings"],
               "crossings_per_step": x["crossings"] / x["steps"], "moving_speed": x["moving_speed"],
               "moving_share": x["moving_steps"] / max(x["particle_steps"] - x["crossings"], 1)}
        for name in ("density", "energy"):
            f = x[name]
            row.update({f"{name}_{k}": f[k] for k in ("new_at_crossing", "new_elsewhere", "new_moving", "new_per_step",
                                                      "max_per_step", "rate_crossing", "rate_elsewhere",
                                                      "rate_moving")})
            row[f"{name}_rate_ratio"] = _ratio(f["rate_crossing"], f["rate_elsewhere"])
            row[f"{name}_moving_ratio"] = _ratio(f["rate_crossing"], f["rate_moving"])
        rows.append(row)
    return rows


def _ratio(a: float, b: float) -> float:
    return a / b if b else math.inf
