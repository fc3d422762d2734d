"""Sod's shock tube: MPM beside fixed-mesh FEM, a finite-volume reference and the exact solution.

Density error at T against the exact Riemann solution on every mesh of the source's table, with one
set of MPM settings for every mesh (``MPM``), over particles and over grid nodes (``m_i / int S_i``).
Tables: ``convergence`` (C11, E3), ``regions`` (C12), ``extrema`` (C14), ``ppc`` (C3), ``mass``
(C15), ``plateau`` (what moves the floor: one setting changed at a time).
"""

from __future__ import annotations

import sys

import numpy as np

from baselines import fem_euler, fv_euler
from baselines.exact import riemann
from mpm_fem.app import plots
from mpm_fem.app.plots import Curve, Plot
from mpm_fem.app.study import StudyOptions, publish, script_main
from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.particles import PositivityError
from mpm_fem.measure import shock_tube, source
from mpm_fem.measure.errors import orders_column
from mpm_fem.measure.regions import REGION_NAMES, ExtremaCounter, describe
from mpm_fem.measure.schema import SOD_CONVERGENCE, SOD_EXTREMA, SOD_MASS, SOD_PPC, SOD_REGIONS
from mpm_fem.problems import sod

NAME = "sod"
#: the source's meshes and one finer (full tier); the deep tier adds DEEP_H
H = (0.01, 0.005, 0.0025, 0.00125, 0.000625, 0.0003125, 0.00015625)
DEEP_H = (0.000078125,)
SOURCE = source.SOD
T = sod.SodSettings.T
# One set of MPM settings for every h (never tuned per mesh); why these: ppc.csv and plateau.csv
MPM = dict(ppc=16, cfl=0.05, av_linear=0.5, av_quadratic=2.0, mass="lumped", scheme="usl", basis="mpm",
           layout="regular", seed=0)
# E3: FEM with the baselines.fem_euler defaults (viscosity on every cell); FV with the stronger of its limiters
FEM = dict(cfl=0.3, viscosity_linear=0.1, viscosity_quadratic=1.0, compression_only=False)
FV = dict(cfl=0.8, limiter="mc")
REGION_HALF_WIDTH = 0.02  # every wave, every mesh: two cells of the coarsest mesh on each side
PROFILE_H = (0.01, 0.0025)
PPC = (1, 2, 4, 8, 16, 32)
PPC_H = (0.01, 0.0025, 0.000625)
CONSISTENT_H = H[:4]  # the consistent particle mass costs ~2x: the two finest meshes are left out
PLATEAU_H = (0.0025, 0.00125)
PLATEAU_VARIANTS = {"study settings": {}, "CFL 0.025": {"cfl": 0.025}, "CFL 0.1": {"cfl": 0.1}, "8 ppc": {"ppc": 8},
                    "32 ppc": {"ppc": 32}, "viscosity x0.5": {"av_linear": 0.25, "av_quadratic": 1.0},
                    "viscosity x2": {"av_linear": 1.0, "av_quadratic": 4.0}, "USF": {"scheme": "usf"},
                    "MUSL": {"scheme": "musl"}, "GIMP": {"basis": "gimp"}, "consistent mass": {"mass": "consistent"}}
QUICK = dict(H=H[:3], PPC_H=(0.01,), CONSISTENT_H=H[:2], PLATEAU_H=())


def run_case(case: dict) -> dict:
    """One run, measured (:mod:`mpm_fem.measure.shock_tube`): ``case["solver"]`` is ``"mpm"`` (keys of
    :data:`MPM` and ``h``), ``"fem"`` (``h``, ``mass`` and the keys of :data:`FEM`) or ``"fv"``."""
    h, width, profiles = case["h"], case.get("region_half_width"), case.get("profiles", False)
    if case["solver"] == "fv":
        return shock_tube.fv(fv_euler.solve(h, cfl=case["cfl"], limiter=case["limiter"]), h)
    if case["solver"] == "fem":
        try:
            r = fem_euler.solve(h, mass=case["mass"], cfl=case["cfl"],
                                viscosity=_viscosity(case))
        except fem_euler.PositivityError as err:
            return {"ok": False, "error": str(err)}
        return shock_tube.fem(r, uniform_grid(0.0, 1.0, h).lumped_mass, width, profiles)
    settings = sod.SodSettings(h=h, **{k: case[k] for k in MPM})
    counter = ExtremaCounter(uniform_grid(0.0, 1.0, h))
    try:
        result = sod.simulate(settings, progress=False, observer=counter)
    except (PositivityError, FloatingPointError) as err:
        return {"ok": False, "error": str(err), "steps": counter.steps}
    return shock_tube.mpm(settings, result, sod.errors(settings, result), counter.summary(), width, profiles)


def _viscosity(fem: dict) -> fem_euler.Viscosity:
    return fem_euler.Viscosity(fem["viscosity_linear"], fem["viscosity_quadratic"], fem["compression_only"])


def mpm_case(h: float, **changes) -> dict:
    """The MPM case at ``h`` with the study settings, ``changes`` applied."""
    return {"solver": "mpm", "h": h, **MPM, **changes, "region_half_width": REGION_HALF_WIDTH,
            "profiles": h in PROFILE_H and not changes}


def fem_case(h: float, mass: str) -> dict:
    return {"solver": "fem", "h": h, "mass": mass, **FEM, "region_half_width": REGION_HALF_WIDTH,
            "profiles": h in PROFILE_H}


def _cost(case: dict) -> float:
    """Particles x steps, to start the longest runs first."""
    if case["solver"] in ("fem", "fv"):
        return 1.0 / case["h"] ** 2
    return case["ppc"] / (case["h"] ** 2 * case["cfl"]) * (2.0 if case["mass"] == "consistent" else 1.0)


def _plan(tier: str) -> dict:
    q = QUICK if tier == "quick" else {}
    hs, ppc_h = q.get("H", H + DEEP_H if tier == "deep" else H), q.get("PPC_H", PPC_H)
    consistent_h, plateau_h = q.get("CONSISTENT_H", CONSISTENT_H), q.get("PLATEAU_H", PLATEAU_H)
    return {
        "mpm": {h: mpm_case(h) for h in hs},
        "mpm_consistent": {h: mpm_case(h, mass="consistent") for h in consistent_h},
        "fem_consistent": {h: fem_case(h, "consistent") for h in hs},
        "fem_lumped": {h: fem_case(h, "lumped") for h in hs},
        "fv": {h: {"solver": "fv", "h": h, **FV} for h in hs},
        "ppc": {(h, n): mpm_case(h, ppc=n) if n != MPM["ppc"] else mpm_case(h) for h in ppc_h for n in PPC},
        "plateau": {(h, name): mpm_case(h, **change) if change else mpm_case(h)
                    for h in plateau_h for name, change in PLATEAU_VARIANTS.items()},
    }


def run(options: StudyOptions) -> None:
    """All cases in one sweep (shared ones run once), then tables and figures."""
    got = options.sweep_plan(NAME, run_case, _plan(options.tier), cost=_cost)
    folder = options.folder(NAME)
    settings = {"mpm": MPM, "fem": {**FEM, "viscosity": _viscosity(FEM).name},
                "fv": {**FV, "scheme": fv_euler.label(FV["limiter"])}, "region_half_width": REGION_HALF_WIDTH, "T": T,
                "quick": options.quick, "problem": sod.SodSettings().as_dict()}
    tables = {SOD_CONVERGENCE: _convergence(got), SOD_REGIONS: _regions(got), SOD_EXTREMA: _extrema(got),
              SOD_PPC: _ppc(got), SOD_MASS: _mass(got), "plateau": _plateau(got) if got["plateau"] else []}
    waves = riemann.wave_positions(T, sod.SodSettings.left, sod.SodSettings.right)
    extra = {SOD_REGIONS.stem: {"regions": describe(REGION_HALF_WIDTH, waves, T)}, SOD_EXTREMA.stem: {
        "rtol": 1e-9, "definition": "new strict local extremum among position-ordered particles"}}
    publish(folder, tables, settings, extra, PLOTS)
    plots.stacked_shares(folder / "regions.png", tables[SOD_REGIONS], REGION_NAMES,
                         f"C12: density L1 error by region of the exact solution at T = {T} "
                         f"(half-width {REGION_HALF_WIDTH})", "share of the density L1 error (total above)")
    _profiles(folder, got)


def _L1(r, where="nodes", norm="L1"):
    return r["density"][where][norm] if r["ok"] else float("nan")


def _convergence(got) -> list[dict]:
    hs = sorted(got["mpm"], reverse=True)
    mpm = [got["mpm"][h] for h in hs]
    cols = {f"{w}_{n}": [_L1(r, w, n) for r in mpm] for w in ("nodes", "particles") for n in ("L1", "L2")}
    cols.update({f"{m}_L1": [_L1(got[m][h], where) for h in hs]
                 for m, where in (("fem_consistent", "nodes"), ("fem_lumped", "nodes"), ("fv", "cells"))})
    orders = {k: orders_column(hs, v) for k, v in cols.items()}
    in_source = [h for h in hs if h in SOURCE]  # meshes finer than the source's have no source value
    src_orders = dict(zip(in_source, orders_column(in_source, [SOURCE[h][0] for h in in_source]), strict=True))
    rows = []
    for k, (h, r) in enumerate(zip(hs, mpm, strict=True)):
        s = dict(zip(("L1", "L2"), SOURCE.get(h, ("", "")), strict=True))
        row = {"h": h, "source_L1": s["L1"], "source_L2": s["L2"], "source_order_L1": src_orders.get(h, "")}
        for key in ("nodes_L1", "nodes_L2", "particles_L1", "particles_L2"):
            row.update({f"mpm_{key}": cols[key][k], f"ratio_{key}": cols[key][k] / s[key[-2:]] if h in SOURCE else ""})
            if key != "particles_L2":
                row[f"order_{key}"] = orders[key][k]
        for m in ("fem_consistent", "fem_lumped", "fv"):
            row.update({f"{m}_L1": cols[f"{m}_L1"][k], f"order_{m}_L1": orders[f"{m}_L1"][k]})
        row.update({
            "mpm_particles_mean_error_smooth": r["mean_error"]["particles"][2] if r["ok"] else "",
            "mpm_nodes_mean_error_smooth": r["mean_error"]["nodes"][2] if r["ok"] else "",
            "mpm_volume_drift": r.get("volume_drift", ""), "mpm_head_shift": r.get("head_shift", ""),
            "fem_consistent_head_shift": got["fem_consistent"][h].get("head_shift", ""),
            "mpm_steps": r.get("steps"), "mpm_particles": r.get("particles"),
            "mpm_wall_s": round(r.get("wall_s", float("nan")), 2), "mpm_energy_drift": r.get("energy_drift", "")})
        rows.append(row)
    return rows


def _regions(got) -> list[dict]:
    rows = []
    for label, group, where in (("MPM nodes", "mpm", "nodes"), ("MPM particles", "mpm", "particles"),
                                ("FEM consistent", "fem_consistent", "nodes"), ("FEM lumped", "fem_lumped", "nodes")):
        for h, r in sorted(got[group].items(), reverse=True):
            if r["ok"]:
                parts, total = np.asarray(r["regions"][where]), r["density"][where]["L1"]
                rows.append({"method": label, "h": h, "L1": total, "sum_of_regions": float(parts.sum()),
                             **{f"L1_{k}_{n.replace(' ', '_')}": float(p)
                                for k, (n, p) in enumerate(zip(REGION_NAMES, parts, strict=True))},
                             **{f"share_{k}": float(p / total) for k, p in enumerate(parts)}})
    return rows


def _extrema(got) -> list[dict]:
    rows = []
    for h, r in sorted(got["mpm"].items(), reverse=True):
        if r["ok"]:
            x = r["extrema"]
            row = {"h": h, "steps": x["steps"], "crossings": x["crossings"],
                   "crossings_per_step": x["crossings"] / x["steps"]}
            for name in ("density", "energy"):
                f = x[name]
                row.update({f"{name}_{k}": f[k] for k in ("new_at_crossing", "new_elsewhere", "new_per_step",
                                                          "max_per_step", "rate_crossing", "rate_elsewhere")})
                row[f"{name}_rate_ratio"] = (f["rate_crossing"] / f["rate_elsewhere"] if f["rate_elsewhere"]
                                             else float("inf"))
            rows.append(row)
    return rows


def _ppc(got) -> list[dict]:
    rows = []
    for (h, n), r in sorted(got["ppc"].items(), key=lambda kv: (-kv[0][0], kv[0][1])):
        ok = r["ok"]
        rows.append({"h": h, "ppc": n, "ok": ok,
                     **{f"{w}_{k}": _L1(r, w, k) if ok else "" for w in ("nodes", "particles") for k in ("L1", "L2")},
                     "steps": r.get("steps"), "wall_s": round(r["wall_s"], 2) if ok else "",
                     "error": "" if ok else r["error"]})
    return rows


def _mass(got) -> list[dict]:
    rows = []
    for h in sorted(got["mpm_consistent"], reverse=True):
        lump, cons, fl, fc = got["mpm"][h], got["mpm_consistent"][h], got["fem_lumped"][h], got["fem_consistent"][h]
        rows.append({
            "h": h, "mpm_lumped_nodes_L1": _L1(lump), "mpm_consistent_nodes_L1": _L1(cons),
            "mpm_consistent_over_lumped_nodes": _L1(cons) / _L1(lump),
            "mpm_lumped_particles_L1": _L1(lump, "particles"), "mpm_consistent_particles_L1": _L1(cons, "particles"),
            "mpm_consistent_over_lumped_particles": _L1(cons, "particles") / _L1(lump, "particles"),
            "fem_lumped_L1": _L1(fl), "fem_consistent_L1": _L1(fc), "fem_consistent_over_lumped": _L1(fc) / _L1(fl),
            "mpm_consistent_error": "" if cons["ok"] else cons["error"]})
    return rows


def _plateau(got) -> list[dict]:
    rows = []
    for (h, name), r in got["plateau"].items():
        base = got["plateau"][(h, "study settings")]
        row = {"h": h, "variant": name, "change": str(PLATEAU_VARIANTS[name]) or "none", "ok": r["ok"]}
        if r["ok"]:
            row.update({"nodes_L1": _L1(r), "particles_L1": _L1(r, "particles"), "nodes_vs_study": _L1(r) / _L1(base),
                        "particles_vs_study": _L1(r, "particles") / _L1(base, "particles"),
                        "nodes_smooth_L1": r["regions"]["nodes"][2], "nodes_behind_shock_L1": r["regions"]["nodes"][5],
                        "particles_behind_shock_L1": r["regions"]["particles"][5],
                        "density_new_extrema_per_step": r["extrema"]["density"]["new_per_step"],
                        "volume_drift": r["volume_drift"], "head_shift": r["head_shift"], "steps": r["steps"],
                        "error": ""})
        else:
            row["error"] = r["error"]
        rows.append(row)
    return rows


_STYLES = {"density": "o-", "energy": "s--"}
PLOTS = (
    Plot("convergence.png", f"Sod, T = {T}: density L1 error against h, beside the source's table",
         SOD_CONVERGENCE.stem, "h", (
        Curve("MPM, grid nodes", "mpm_nodes_L1"), Curve("MPM, particles", "mpm_particles_L1", "s-"),
        Curve("FEM consistent", "fem_consistent_L1", "^--"), Curve("FEM lumped", "fem_lumped_L1", "v--"),
        Curve(fv_euler.label(FV["limiter"]), "fv_L1", "x-."), Curve("source (slides)", "source_L1", "k*")),
        ylabel="density error (L1)", slopes=(0.5, 1)),
    Plot("extrema.png", "C14: new extrema of particle density and energy, per step and per particle-step",
         SOD_EXTREMA.stem, "h",
         tuple(Curve(n, f"{n}_new_per_step", f, panel="new extrema per step") for n, f in _STYLES.items())
         + tuple(Curve(f"{n}: {who}", f"{n}_rate_{k}", f, panel="new extrema per particle-step", options=o)
                 for n, f in _STYLES.items() for k, who, o in (("crossing", "particles crossing a node", {}),
                                                               ("elsewhere", "other particles", {"alpha": 0.5}))),
         ylabel="new extrema", size=(4.5, 3.6)),
    Plot("ppc.png", "C3: density error against particles per cell, one line per mesh", SOD_PPC.stem, "ppc", tuple(
        Curve("h = {h}", f"{w}_L1", panel=f"over {name}", group=("h",), where={"ok": True})
        for w, name in (("nodes", "grid nodes"), ("particles", "particles"))),
        xlabel="particles per cell N_p", ylabel="density error (L1)", size=(4.5, 3.6)),
)


def _profiles(folder, got) -> None:
    xe = np.linspace(0, 1, 2001)
    rho, u, p = riemann.sample(xe, T, sod.SodSettings.left, sod.SodSettings.right, x0=0.5, gamma=1.4)
    exact = {k: (xe, v) for k, v in (("density", rho), ("velocity", u), ("pressure", p), ("energy", p / (0.4 * rho)))}
    for h in PROFILE_H:
        m, fc, fl = (got[k].get(h) for k in ("mpm", "fem_consistent", "fem_lumped"))
        if m is None or not m.get("ok") or "profile" not in m:
            continue
        mp = m["profile"]
        nodal = {"density": mp["nodal_density"], "velocity": mp["nodal_velocity"]}
        fem = [(label, r["profile"]["x"], r["profile"], fmt, {"ms": 2.5, "lw": 0.7}) for r, fmt, label in
               ((fc, "^-", "FEM consistent"), (fl, "v-", "FEM lumped"))
               if r is not None and r.get("ok") and "profile" in r]
        plots.profile_grid(folder / f"profiles_h{h:g}.png", exact, {
            f"MPM ({MPM['ppc']} ppc, CFL {MPM['cfl']})": [
                ("MPM particles", mp["x"], mp, ".", {"ms": 1.5, "color": "tab:blue"}),
                ("MPM grid nodes", mp["nodes"], nodal, "x", {"ms": 3, "color": "tab:red"})],
            f"FEM (P1, SSPRK3, CFL {FEM['cfl']})": fem},
            f"Sod at T = {T}, h = {h:g}: MPM (top) and fixed-mesh FEM (bottom) on the same mesh")


if __name__ == "__main__":
    sys.exit(script_main(NAME))
