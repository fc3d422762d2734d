"""Sod's shock tube: MPM beside fixed-mesh FEM and the exact solution (claims C11, C12, C14, C3, C15).

Density error at T = 0.2 against the exact Riemann solution, for h = 0.01 ... 0.0003125, with one
set of MPM settings for every mesh (``MPM``: 16 particles per cell, CFL 0.05, von Neumann-Richtmyer
viscosity 0.5 / 2.0 in the energy equation, USL, point-mass basis, lumped mass), measured over
particles and over grid nodes (``m_i / int S_i``), beside P1 FEM with consistent and lumped mass
on the same mesh, and the source's table (slides, "Final Error Combination(cont.)").

- ``convergence.csv``: C11, the source's L1/L2 in their own columns, measured/source, orders.
- ``regions.csv``: C12, each region's share of the L1 error (regions of :mod:`mpm_fem.regions`).
- ``extrema.csv``: C14, new density/energy extrema per step, at cell crossings and elsewhere.
- ``ppc.csv``: C3, error against particles per cell (1 ... 32) on three meshes.
- ``mass.csv``: C15, MPM and FEM with lumped and consistent mass on the same meshes.
- ``plateau.csv``: what moves the floor: one setting changed at a time, on two fine meshes.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from baselines import fem_euler, fv_euler
from baselines.exact import riemann
from mpm_fem.errors import norms, observed_orders
from mpm_fem.grid import uniform_grid
from mpm_fem.particles import PositivityError
from mpm_fem.problems import sod
from mpm_fem.regions import REGION_NAMES, ExtremaCounter, l1_by_region, mean_by_region, sod_regions
from mpm_fem import plots, source
from mpm_fem.report import Page, View
from mpm_fem.study import StudyOptions, script_main, write_table

NAME = "sod"
H = (0.01, 0.005, 0.0025, 0.00125, 0.000625, 0.0003125)
SOURCE = source.SOD
T = sod.SodSettings.T
# One set of MPM settings for every h (never tuned per mesh); why these: ppc.csv and plateau.csv
MPM = dict(ppc=16, cfl=0.05, av_linear=0.5, av_quadratic=2.0, mass="lumped", scheme="usl", basis="mpm", layout="regular", seed=0)
FEM = dict(cfl=0.3, viscosity_linear=0.1, viscosity_quadratic=1.0)  # baselines.fem_euler defaults
FV_CFL = 0.8  # baselines.fv_euler default
REGION_HALF_WIDTH = 0.02  # every wave, every mesh: two cells of the coarsest mesh on each side
PROFILE_H = (0.01, 0.0025)
PPC = (1, 2, 4, 8, 16, 32)
PPC_H = (0.01, 0.0025, 0.000625)
CONSISTENT_H = H[:4]  # the consistent particle mass costs ~2x: the two finest meshes are left out
PLATEAU_H = (0.0025, 0.00125)
PLATEAU_VARIANTS = {
    "study settings": {},
    "CFL 0.025": {"cfl": 0.025},
    "CFL 0.1": {"cfl": 0.1},
    "8 ppc": {"ppc": 8},
    "32 ppc": {"ppc": 32},
    "viscosity x0.5": {"av_linear": 0.25, "av_quadratic": 1.0},
    "viscosity x2": {"av_linear": 1.0, "av_quadratic": 4.0},
    "USF": {"scheme": "usf"},
    "MUSL": {"scheme": "musl"},
    "GIMP": {"basis": "gimp"},
    "consistent mass": {"mass": "consistent"},
}
QUICK = dict(H=H[:3], PPC_H=(0.01,), CONSISTENT_H=H[:2], PLATEAU_H=())


# ---------------------------------------------------------------- one case (runs in a worker)

def _exact_density(x, t):
    return riemann.sample(x, t, sod.SodSettings.left, sod.SodSettings.right, x0=0.5, gamma=1.4)[0]


def _first_below(x, rho, level):
    """First ``x`` (linear between points) where ``rho`` drops below ``level``, from the left."""
    k = int(np.argmax(rho < level))
    return float(x[k - 1] + (x[k] - x[k - 1]) * (rho[k - 1] - level) / (rho[k - 1] - rho[k]))


def _head_shift(x, rho, t, level=0.99):
    """Where the computed density first drops below 0.99 minus where the exact one does: the
    position error of the rarefaction head (> 0: the computed head lags behind)."""
    xe = np.linspace(0.2, 0.4, 20001)
    return _first_below(x, rho, level) - _first_below(xe, _exact_density(xe, t), level)


def _profile(values: dict) -> dict:
    return {k: [float(f"{v:.7g}") for v in np.asarray(a)] for k, a in values.items()}


def run_case(case: dict) -> dict:
    """One run: ``case["solver"]`` is ``"mpm"`` (keys of :data:`MPM` and ``h``) or ``"fem"``
    (``h``, ``mass`` and the keys of :data:`FEM`). Returns density errors over particles and
    nodes, the regional L1 split, new-extrema counts (MPM), and profiles when asked for."""
    h = case["h"]
    if case["solver"] == "fem":
        return _run_fem(case)
    if case["solver"] == "fv":
        return _run_fv(case)
    settings = sod.SodSettings(h=h, **{k: case[k] for k in MPM})
    counter = ExtremaCounter(uniform_grid(0.0, 1.0, h))
    try:
        result = sod.simulate(settings, progress=False, observer=counter)
    except (PositivityError, FloatingPointError) as err:
        return {"ok": False, "error": str(err), "steps": counter.steps}
    errors = sod.errors(settings, result)
    P, g = result.particles, result.grid
    regions = sod_regions(riemann.wave_positions(result.t, settings.left, settings.right), case["region_half_width"])
    e_p = P.density - _exact_density(P.x, result.t)
    e_i = result.nodal_density - _exact_density(g.nodes, result.t)
    out = {
        "ok": True,
        "steps": result.steps,
        "wall_s": result.wall_s,
        "particles": int(P.n),
        "density": errors["density"],
        "velocity": errors["velocity"],
        "pressure": errors["pressure"],
        "regions": {
            "particles": l1_by_region(P.x, e_p, P.volume, regions).tolist(),
            "nodes": l1_by_region(g.nodes, e_i, g.lumped_mass, regions).tolist(),
        },
        "mean_error": {
            "particles": mean_by_region(P.x, e_p, P.volume, regions).tolist(),
            "nodes": mean_by_region(g.nodes, e_i, g.lumped_mass, regions).tolist(),
        },
        "extrema": counter.summary(),
        "volume_drift": float(P.volume.sum() - 1.0),
        "head_shift": _head_shift(g.nodes, result.nodal_density, result.t),
    }
    if case.get("profiles"):
        thermal = (settings.gamma - 1.0) * P.density * P.energy
        out["profile"] = _profile(dict(x=P.x, density=P.density, velocity=P.velocity, pressure=thermal,
                                       energy=P.energy, nodes=g.nodes, nodal_density=result.nodal_density,
                                       nodal_velocity=result.nodal_velocity))
    return out


def _run_fem(case: dict) -> dict:
    visc = fem_euler.Viscosity(case["viscosity_linear"], case["viscosity_quadratic"])
    try:
        r = fem_euler.solve(case["h"], mass=case["mass"], cfl=case["cfl"], viscosity=visc)
    except fem_euler.PositivityError as err:
        return {"ok": False, "error": str(err)}
    w = uniform_grid(0.0, 1.0, case["h"]).lumped_mass
    e = r.rho - _exact_density(r.nodes, r.t)
    regions = sod_regions(riemann.wave_positions(r.t, sod.SodSettings.left, sod.SodSettings.right),
                          case["region_half_width"])
    out = {
        "ok": True,
        "steps": r.steps,
        "density": {"nodes": norms(e, w)},
        "regions": {"nodes": l1_by_region(r.nodes, e, w, regions).tolist()},
        "mean_error": {"nodes": mean_by_region(r.nodes, e, w, regions).tolist()},
        "mass": float(np.sum(w * r.rho)),
        "head_shift": _head_shift(r.nodes, r.rho, r.t),
        "settings": r.settings,
    }
    if case.get("profiles"):
        out["profile"] = _profile(dict(x=r.nodes, density=r.rho, velocity=r.u, pressure=r.p, energy=r.e))
    return out


def _run_fv(case: dict) -> dict:
    """The finite-volume reference (MUSCL-Hancock + HLLC) on the cells of the same mesh: cell
    averages against the exact density at the cell centres, weights h."""
    r = fv_euler.solve(case["h"], cfl=case["cfl"])
    e = r.rho - _exact_density(r.centres, r.t)
    return {"ok": True, "steps": r.steps, "density": {"cells": norms(e, np.full(e.size, case["h"]))},
            "mass": float(np.sum(r.rho) * case["h"])}


# ---------------------------------------------------------------- the cases

def mpm_case(h: float, **changes) -> dict:
    """The MPM case at ``h`` with the study settings, ``changes`` applied."""
    return {"solver": "mpm", "h": h, **MPM, **changes, "region_half_width": REGION_HALF_WIDTH,
            "profiles": h in PROFILE_H and not changes}


def fem_case(h: float, mass: str) -> dict:
    return {"solver": "fem", "h": h, "mass": mass, **FEM, "region_half_width": REGION_HALF_WIDTH,
            "profiles": h in PROFILE_H}


def fv_case(h: float) -> dict:
    return {"solver": "fv", "h": h, "cfl": FV_CFL}


def _cost(case: dict) -> float:
    """Particles x steps, to start the longest runs first."""
    if case["solver"] in ("fem", "fv"):
        return 1.0 / case["h"] ** 2
    return case["ppc"] / (case["h"] ** 2 * case["cfl"]) * (2.0 if case["mass"] == "consistent" else 1.0)


def _plan(quick: bool) -> dict:
    q = QUICK if quick else {}
    hs, ppc_h = q.get("H", H), q.get("PPC_H", PPC_H)
    consistent_h, plateau_h = q.get("CONSISTENT_H", CONSISTENT_H), q.get("PLATEAU_H", PLATEAU_H)
    return {
        "mpm": {h: mpm_case(h) for h in hs},
        "mpm_consistent": {h: mpm_case(h, mass="consistent") for h in consistent_h},
        "fem_consistent": {h: fem_case(h, "consistent") for h in hs},
        "fem_lumped": {h: fem_case(h, "lumped") for h in hs},
        "fv": {h: fv_case(h) for h in hs},
        "ppc": {(h, n): mpm_case(h, ppc=n) if n != MPM["ppc"] else mpm_case(h) for h in ppc_h for n in PPC},
        "plateau": {(h, name): mpm_case(h, **change) if change else mpm_case(h)
                    for h in plateau_h for name, change in PLATEAU_VARIANTS.items()},
    }


# ---------------------------------------------------------------- the study

def run(options: StudyOptions) -> None:
    """All cases in one sweep (shared ones run once), then tables and figures."""
    plan = _plan(options.quick)
    got = options.sweep_plan(NAME, run_case, plan, cost=_cost)
    folder = options.folder(NAME)
    settings = {"mpm": MPM, "fem": FEM, "fv": {"cfl": FV_CFL, "scheme": "MUSCL-Hancock + HLLC"}, "region_half_width": REGION_HALF_WIDTH, "T": T,
                "quick": options.quick, "problem": sod.SodSettings().as_dict()}
    _convergence(folder, got, settings)
    _regions(folder, got, settings)
    _extrema(folder, got, settings)
    _ppc(folder, got, settings)
    _mass(folder, got, settings)
    if got["plateau"]:
        _plateau(folder, got, settings)
    _profiles(folder, got)


def _orders(hs, values) -> list:
    """Observed order between each row and the previous one ('' in the first row)."""
    v = np.asarray(values, float)
    if len(v) < 2 or not np.all(v > 0):
        return [""] * len(v)
    return [""] + [float(o) for o in observed_orders(hs, v)]


def _convergence(folder, got, settings) -> None:
    hs = sorted(got["mpm"], reverse=True)
    mpm = [got["mpm"][h] for h in hs]
    d = lambda r, where, norm: r["density"][where][norm] if r["ok"] else float("nan")  # noqa: E731
    cols = {
        "nodes_L1": [d(r, "nodes", "L1") for r in mpm],
        "nodes_L2": [d(r, "nodes", "L2") for r in mpm],
        "particles_L1": [d(r, "particles", "L1") for r in mpm],
        "particles_L2": [d(r, "particles", "L2") for r in mpm],
        "fem_consistent_L1": [d(got["fem_consistent"][h], "nodes", "L1") for h in hs],
        "fem_lumped_L1": [d(got["fem_lumped"][h], "nodes", "L1") for h in hs],
        "fv_L1": [d(got["fv"][h], "cells", "L1") for h in hs],
    }
    orders = {k: _orders(hs, v) for k, v in cols.items()}
    src_orders = {n: _orders(hs, [SOURCE[h][i] for h in hs]) for i, n in enumerate(("L1", "L2"))}
    rows = []
    for k, h in enumerate(hs):
        s1, s2 = SOURCE[h]
        rows.append({
            "h": h,
            "source_L1": s1, "source_L2": s2, "source_order_L1": src_orders["L1"][k],
            "mpm_nodes_L1": cols["nodes_L1"][k], "ratio_nodes_L1": cols["nodes_L1"][k] / s1,
            "order_nodes_L1": orders["nodes_L1"][k],
            "mpm_nodes_L2": cols["nodes_L2"][k], "ratio_nodes_L2": cols["nodes_L2"][k] / s2,
            "order_nodes_L2": orders["nodes_L2"][k],
            "mpm_particles_L1": cols["particles_L1"][k], "ratio_particles_L1": cols["particles_L1"][k] / s1,
            "order_particles_L1": orders["particles_L1"][k],
            "mpm_particles_L2": cols["particles_L2"][k], "ratio_particles_L2": cols["particles_L2"][k] / s2,
            "fem_consistent_L1": cols["fem_consistent_L1"][k], "order_fem_consistent_L1": orders["fem_consistent_L1"][k],
            "fem_lumped_L1": cols["fem_lumped_L1"][k], "order_fem_lumped_L1": orders["fem_lumped_L1"][k],
            "fv_L1": cols["fv_L1"][k], "order_fv_L1": orders["fv_L1"][k],
            "mpm_particles_mean_error_smooth": mpm[k]["mean_error"]["particles"][2] if mpm[k]["ok"] else "",
            "mpm_nodes_mean_error_smooth": mpm[k]["mean_error"]["nodes"][2] if mpm[k]["ok"] else "",
            "mpm_volume_drift": mpm[k].get("volume_drift", ""), "mpm_head_shift": mpm[k].get("head_shift", ""),
            "fem_consistent_head_shift": got["fem_consistent"][h].get("head_shift", ""),
            "mpm_steps": mpm[k].get("steps"), "mpm_particles": mpm[k].get("particles"),
            "mpm_wall_s": round(mpm[k].get("wall_s", float("nan")), 2),
        })
    write_table(folder, "convergence", rows, settings)
    hs_src = list(SOURCE)
    series = {
        "MPM, grid nodes": (hs, cols["nodes_L1"], "o-"),
        "MPM, particles": (hs, cols["particles_L1"], "s-"),
        "FEM consistent": (hs, cols["fem_consistent_L1"], "^--"),
        "FEM lumped": (hs, cols["fem_lumped_L1"], "v--"),
        "FV (MUSCL-Hancock + HLLC)": (hs, cols["fv_L1"], "x-."),
    }
    cons = sorted(got["mpm_consistent"], reverse=True)
    if cons:
        series["MPM consistent mass, nodes"] = (cons, [d(got["mpm_consistent"][h], "nodes", "L1") for h in cons], "d:")
    series["source (slides)"] = (hs_src, [SOURCE[h][0] for h in hs_src], "k*")
    plots.convergence(folder / "convergence.png", series, ylabel="density error (L1)", slopes=(0.5, 1),
                      title=f"Sod, T={T}: density L1 error vs h (MPM {MPM['ppc']} ppc, CFL {MPM['cfl']})")


def _regions(folder, got, settings) -> None:
    rows = []
    methods = [("MPM nodes", got["mpm"], "nodes"), ("MPM particles", got["mpm"], "particles"),
               ("FEM consistent", got["fem_consistent"], "nodes"), ("FEM lumped", got["fem_lumped"], "nodes")]
    for label, group, where in methods:
        for h in sorted(group, reverse=True):
            r = group[h]
            if not r["ok"]:
                continue
            parts = np.asarray(r["regions"][where])
            total = r["density"][where]["L1"]
            row = {"method": label, "h": h, "L1": total, "sum_of_regions": float(parts.sum())}
            row.update({f"L1_{k}_{_slug(n)}": float(p) for k, (n, p) in enumerate(zip(REGION_NAMES, parts))})
            row.update({f"share_{k}": float(p / total) for k, p in enumerate(parts)})
            rows.append(row)
    write_table(folder, "regions", rows, {**settings, "regions": _region_text()})
    _region_figure(folder / "regions.png", rows)


def _slug(name: str) -> str:
    return name.replace(" ", "_")


def _region_text() -> dict:
    w = REGION_HALF_WIDTH
    return {
        "0 undisturbed": f"[0, x_H - {w}) and [x_S + {w}, 1]",
        "1 rarefaction head": f"[x_H - {w}, x_H + {w})",
        "2 smooth": f"[x_H + {w}, x_T - {w}) (fan) and [x_T + {w}, x_C - {w}) (plateau)",
        "3 rarefaction tail": f"[x_T - {w}, x_T + {w})",
        "4 contact": f"[x_C - {w}, x_C + {w})",
        "5 behind shock": f"[x_C + {w}, x_S - {w})",
        "6 shock front": f"[x_S - {w}, x_S + {w})",
        "waves at T=0.2": "x_H = 0.26336, x_T = 0.48595, x_C = 0.68549, x_S = 0.85043",
    }


def _region_figure(path, rows) -> None:
    methods = dict.fromkeys(r["method"] for r in rows)
    groups = {m: [(f"{r['h']:g}", [r[f"share_{k}"] for k in range(len(REGION_NAMES))], r["L1"])
                  for r in rows if r["method"] == m] for m in methods}
    plots.stacked_shares(path, groups, REGION_NAMES, f"C12: density L1 error by region of the exact solution at "
                         f"T = {T} (half-width {REGION_HALF_WIDTH})", "share of the density L1 error (total above)")


def _extrema(folder, got, settings) -> None:
    rows = []
    for h in sorted(got["mpm"], reverse=True):
        r = got["mpm"][h]
        if not r["ok"]:
            continue
        x = r["extrema"]
        row = {"h": h, "steps": x["steps"], "crossings": x["crossings"],
               "crossings_per_step": x["crossings"] / x["steps"]}
        for name in ("density", "energy"):
            f = x[name]
            row.update({
                f"{name}_new_at_crossing": f["new_at_crossing"], f"{name}_new_elsewhere": f["new_elsewhere"],
                f"{name}_new_per_step": f["new_per_step"], f"{name}_max_per_step": f["max_per_step"],
                f"{name}_rate_crossing": f["rate_crossing"], f"{name}_rate_elsewhere": f["rate_elsewhere"],
                f"{name}_rate_ratio": f["rate_crossing"] / f["rate_elsewhere"] if f["rate_elsewhere"] else float("inf"),
            })
        rows.append(row)
    write_table(folder, "extrema", rows, {**settings, "rtol": 1e-9,
                                          "definition": "new strict local extremum among position-ordered particles"})
    hs, styles = [r["h"] for r in rows], {"density": "o-", "energy": "s--"}
    plots.panels(folder / "extrema.png", {
        "new extrema per step": {n: (hs, [r[f"{n}_new_per_step"] for r in rows], f) for n, f in styles.items()},
        "new extrema per particle-step": {
            **{f"{n}: particles crossing a node": (hs, [r[f"{n}_rate_crossing"] for r in rows], f) for n, f in styles.items()},
            **{f"{n}: other particles": (hs, [r[f"{n}_rate_elsewhere"] for r in rows], f, {"alpha": 0.5})
               for n, f in styles.items()}}},
        "h", "new extrema", f"C14: new extrema of particle density / energy (MPM, {MPM['ppc']} ppc, CFL {MPM['cfl']})")


def _ppc(folder, got, settings) -> None:
    rows = []
    for (h, n), r in sorted(got["ppc"].items(), key=lambda kv: (-kv[0][0], kv[0][1])):
        row = {"h": h, "ppc": n, "ok": r["ok"]}
        if r["ok"]:
            row.update({"nodes_L1": r["density"]["nodes"]["L1"], "nodes_L2": r["density"]["nodes"]["L2"],
                        "particles_L1": r["density"]["particles"]["L1"], "particles_L2": r["density"]["particles"]["L2"],
                        "steps": r["steps"], "wall_s": round(r["wall_s"], 2), "error": ""})
        else:
            row.update({"nodes_L1": "", "nodes_L2": "", "particles_L1": "", "particles_L2": "", "steps": r.get("steps"),
                        "wall_s": "", "error": r["error"]})
        rows.append(row)
    write_table(folder, "ppc", rows, settings)
    content = {}
    for where in ("nodes", "particles"):
        panel = content.setdefault(f"over {'grid nodes' if where == 'nodes' else 'particles'}", {})
        for h in sorted({r["h"] for r in rows}, reverse=True):
            ok = [r for r in rows if r["h"] == h and r["ok"]]
            panel[f"h = {h:g}"] = ([r["ppc"] for r in ok], [r[f"{where}_L1"] for r in ok], "o-")
            if h in SOURCE:
                panel[f"source, h = {h:g}"] = ((PPC[0], PPC[-1]), (SOURCE[h][0],) * 2, "k:", {"lw": 0.8})
    plots.panels(folder / "ppc.png", content, "particles per cell N_p", "density error (L1)",
                 "C3: error vs particles per cell (dotted: the source at that h)")


def _mass(folder, got, settings) -> None:
    rows = []
    for h in sorted(got["mpm_consistent"], reverse=True):
        lump, cons = got["mpm"][h], got["mpm_consistent"][h]
        fl, fc = got["fem_lumped"][h], got["fem_consistent"][h]
        L1 = lambda r, where="nodes": r["density"][where]["L1"] if r["ok"] else float("nan")  # noqa: E731
        rows.append({
            "h": h,
            "mpm_lumped_nodes_L1": L1(lump), "mpm_consistent_nodes_L1": L1(cons),
            "mpm_consistent_over_lumped_nodes": L1(cons) / L1(lump),
            "mpm_lumped_particles_L1": L1(lump, "particles"), "mpm_consistent_particles_L1": L1(cons, "particles"),
            "mpm_consistent_over_lumped_particles": L1(cons, "particles") / L1(lump, "particles"),
            "fem_lumped_L1": L1(fl), "fem_consistent_L1": L1(fc), "fem_consistent_over_lumped": L1(fc) / L1(fl),
            "mpm_consistent_error": "" if cons["ok"] else cons["error"],
        })
    write_table(folder, "mass", rows, settings)


def _plateau(folder, got, settings) -> None:
    rows = []
    for (h, name), r in got["plateau"].items():
        base = got["plateau"][(h, "study settings")]
        row = {"h": h, "variant": name, "change": str(PLATEAU_VARIANTS[name]) or "none", "ok": r["ok"]}
        if r["ok"]:
            e = r["density"]
            row.update({"nodes_L1": e["nodes"]["L1"], "particles_L1": e["particles"]["L1"],
                        "nodes_vs_study": e["nodes"]["L1"] / base["density"]["nodes"]["L1"],
                        "particles_vs_study": e["particles"]["L1"] / base["density"]["particles"]["L1"],
                        "nodes_smooth_L1": r["regions"]["nodes"][2], "nodes_behind_shock_L1": r["regions"]["nodes"][5],
                        "particles_behind_shock_L1": r["regions"]["particles"][5],
                        "density_new_extrema_per_step": r["extrema"]["density"]["new_per_step"],
                        "volume_drift": r["volume_drift"], "head_shift": r["head_shift"],
                        "steps": r["steps"], "error": ""})
        else:
            row["error"] = r["error"]
        rows.append(row)
    write_table(folder, "plateau", rows, settings)


def _profiles(folder, got) -> None:
    import matplotlib.pyplot as plt

    t = 0.2
    xe = np.linspace(0, 1, 2001)
    rho, u, p = riemann.sample(xe, t, sod.SodSettings.left, sod.SodSettings.right, x0=0.5, gamma=1.4)
    exact = {"density": rho, "velocity": u, "pressure": p, "energy": p / (0.4 * rho)}
    for h in PROFILE_H:
        m, fc, fl = (got[k].get(h) for k in ("mpm", "fem_consistent", "fem_lumped"))
        if m is None or not m.get("ok") or "profile" not in m:
            continue
        fig, axes = plt.subplots(2, 4, figsize=(16, 6.4), sharex=True)
        for col, name in enumerate(exact):
            for row in range(2):
                axes[row][col].plot(xe, exact[name], "k-", lw=1.0, label="exact")
                axes[row][col].set_title(f"{name}", fontsize=9)
            mp = m["profile"]
            axes[0][col].plot(mp["x"], mp[name], ".", ms=1.5, color="tab:blue", label="MPM particles")
            if name in ("density", "velocity"):
                axes[0][col].plot(mp["nodes"], mp[f"nodal_{name}"], "x", ms=3, color="tab:red", label="MPM grid nodes")
            for r, style, label in ((fc, "^-", "FEM consistent"), (fl, "v-", "FEM lumped")):
                if r is not None and r.get("ok") and "profile" in r:
                    axes[1][col].plot(r["profile"]["x"], r["profile"][name], style, ms=2.5, lw=0.7, label=label)
        axes[0][0].set_ylabel("MPM (16 ppc, CFL 0.05)")
        axes[1][0].set_ylabel("FEM (P1, SSPRK3, CFL 0.3)")
        for ax in axes[1]:
            ax.set_xlabel("x")
        axes[0][0].legend(fontsize=7)
        axes[1][0].legend(fontsize=7)
        fig.suptitle(f"Sod at T = {T}, h = {h:g}: MPM (top) and fixed-mesh FEM (bottom) on the same mesh", fontsize=10)
        fig.tight_layout()
        fig.savefig(folder / f"profiles_h{h:g}.png", dpi=110)
        plt.close(fig)


# ---------------------------------------------------------------- the report page

_CONVERGENCE = ("h", "source_L1", "mpm_nodes_L1", "ratio_nodes_L1", "order_nodes_L1", "source_order_L1",
                "mpm_particles_L1", "order_particles_L1", "fem_consistent_L1", "fem_lumped_L1", "fv_L1", "order_fv_L1")
_FLOOR = ("h", "mpm_volume_drift", "mpm_particles_mean_error_smooth", "mpm_nodes_mean_error_smooth", "mpm_head_shift",
          "fem_consistent_head_shift")
_EXTREMA = ("h", "steps", "crossings_per_step", "density_new_per_step", "density_rate_crossing",
            "density_rate_elsewhere", "density_rate_ratio", "energy_new_per_step", "energy_rate_ratio")
_SHARES = ("method", "h", "L1") + tuple(f"share_{k}" for k in range(len(REGION_NAMES)))
_VARIANTS = ("h", "variant", "ok", "nodes_L1", "nodes_vs_study", "particles_L1", "particles_vs_study",
             "density_new_extrema_per_step")
PAGE = Page(
    NAME, "Sod's shock tube",
    "Density error at the final time against the exact Riemann solution, with one set of MPM settings for every "
    "mesh (recorded in the JSON beside each table), over particles and over grid nodes, beside P1 FEM with "
    "consistent and lumped mass and a finite-volume reference on the same mesh, and beside the source's table.",
    views=(
        View("sod/convergence", "Density L1 against h, beside the source", _CONVERGENCE, {}, "convergence.png"),
        View("sod/convergence", "What sets the floor: volume gained by the particles, signed mean error in the "
             "smooth region, position error of the rarefaction head", _FLOOR),
        View("sod/regions", "Share of the L1 error by region of the exact solution", _SHARES, {}, "regions.png"),
        View("sod/extrema", "New extrema per step, at cell crossings and elsewhere", _EXTREMA, {}, "extrema.png"),
        View("sod/ppc", "Error against particles per cell", ("h", "ppc", "ok", "nodes_L1", "particles_L1"), {},
             "ppc.png"),
        View("sod/mass", "Lumped against consistent mass, MPM and FEM"),
        View("sod/plateau", "What moves the floor: one setting changed at a time", _VARIANTS),
    ),
    figures=tuple((f"profiles_h{h:g}.png", "Profiles against the exact solution, MPM above and FEM below, on the "
                   "mesh named in the file") for h in PROFILE_H),
)


if __name__ == "__main__":
    sys.exit(script_main(NAME))
