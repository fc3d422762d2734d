"""Viscous Burgers: MPM with exact and calculated acceleration beside FEM (claims C13, C3, C15).

``v_t + v v_x = eps v_xx`` on [0, 2], T = 0.5, eps in {0.045, 0.04, 0.03, 0.02, 0.01}, h = 0.01 ...
0.000625, initial and Dirichlet data from an exact solution (slides, "Burgers' Problem"). MPM (point
mass, USL, lumped mass, 4 particles per cell, reservoir inflow) updates the particle velocity with
the nodal acceleration computed from the particles (``a_i = F_i/m_i``, "calculated") or taken from
the exact solution (``eps v_xx(x_i, t)``, "exact"), beside P1 Galerkin FEM with consistent and
lumped mass on the same mesh (:mod:`baselines.fem_burgers`, SSP-RK3). Errors at T over particles
(weights ``V_p``) and grid nodes, in L1, L2 and max, beside the source's table.

Time steps, the same rule on every mesh: MPM calculated ``dt = 0.5 min(h/max|v_p|, h^2/(2 eps))``
(the explicit-diffusion limit binds for h <= 0.02); MPM exact with that same dt ("exact") and with
the advective limit alone, ``dt = 0.5 h/max|v_p|`` ("exact, dt ~ h"), which it may use because it
computes no viscous force; FEM ``dt = min(0.5 h/max|v|, 0.3 h^2/(2 eps))`` (its defaults).

- ``errors.csv``: C13, every solution, eps, h and method; the source's value and measured/source.
- ``orders.csv``: observed orders between successive meshes and the least-squares order.
- ``norms.csv``: which norm and which solution reproduce the source (median and spread of
  measured/source over the table).
- ``timestep.csv``: the time error at one mesh (dt / 1, 4, 16) against the table's error.
- ``ppc.csv``: C3, error against particles per cell (1 ... 32) on two meshes.
- ``lumping.csv``: C15, MPM with lumped and consistent particle mass beside FEM lumped/consistent.
- ``diagnosis.csv``: why the calculated acceleration stops converging: one setting changed at a time.
"""

from __future__ import annotations

import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

from baselines import fem_burgers
from baselines.exact.burgers import make_solution
from mpm_fem.errors import fitted_order, observed_orders
from mpm_fem.problems import burgers
from mpm_fem import plots, source
from mpm_fem.claims import BURGERS_SHOWN
from mpm_fem.report import Page, View
from mpm_fem.study import StudyOptions, script_main, write_table

NAME = "burgers"
H = (0.01, 0.005, 0.0025, 0.00125, 0.000625)
EPS = (0.045, 0.04, 0.03, 0.02, 0.01)
SOLUTIONS = ("rarefaction", "cole_hopf", "three_exp", "front")
#: The solution, and the norm (the slides do not say which), compared with the source; why: norms.csv.
DEFAULT, WHERE, NORM = BURGERS_SHOWN["solution"], BURGERS_SHOWN["where"], BURGERS_SHOWN["norm"]
SOURCE, CORRECTED = source.BURGERS, source.BURGERS_CORRECTED

MPM = dict(ppc=4, cfl=0.5, mass="lumped", basis="mpm", scheme="usl", layout="regular")
FEM = dict(cfl=0.5, cfl_visc=0.3)
METHODS = {  # name: (label, solver, settings, the source's row it stands beside)
    "mpm_calculated": ("MPM calculated a", "mpm", {"acceleration": "calculated"}, "calculated"),
    "mpm_calculated_16": ("MPM calculated a, 16 ppc", "mpm", {"acceleration": "calculated", "ppc": 16}, "calculated"),
    "mpm_exact": ("MPM exact a", "mpm", {"acceleration": "exact"}, "exact"),
    "mpm_exact_dt_h": ("MPM exact a, dt ~ h", "mpm", {"acceleration": "exact", "dt_rule": "advective"}, "exact"),
    "fem_consistent": ("FEM consistent", "fem", {"mass": "consistent"}, None),
    "fem_lumped": ("FEM lumped", "fem", {"mass": "lumped"}, None),
}
# The meshes each method runs on. The explicit viscous limit makes a run at h cost ~ eps/h^3
# (h = 0.000625 at eps = 0.045: 2.3e5 steps of 12800 particles); the finest meshes are spent on
# the default solution and on the methods that need them to show their order.
MESHES = {
    "default": {"mpm_calculated": H, "mpm_calculated_16": H[:3], "mpm_exact_dt_h": H, "mpm_exact": H[:3], "fem_consistent": H[:3], "fem_lumped": H[:3]},
    "other": {"mpm_calculated": H[:3], "mpm_exact_dt_h": H, "mpm_exact": H[:3], "fem_consistent": H[:2], "fem_lumped": H[:2]},
}
PPC = (1, 2, 4, 8, 16, 32)
PPC_H = (0.01, 0.0025)
TIME_H = 0.005
REFINE = (1, 4, 16)
LUMPING_CFL = 0.3  # the consistent particle mass needs dt <= h^2/(6 eps): both masses run with CFL 0.3
DIAGNOSIS = {  # label: changes to the calculated-acceleration run
    "MPM: weak force, V_p weights": {},
    "slides' force (second difference)": {"force": "slides"},
    "slides' weights h/N_p^i": {"weights": "cell"},
    "slides' weights and force": {"weights": "cell", "force": "slides"},
    "consistent mass (CFL 0.3)": {"mass": "consistent", "cfl": LUMPING_CFL},
    "GIMP basis": {"basis": "gimp"},
    "16 particles per cell": {"ppc": 16},
    "exact acceleration": {"acceleration": "exact"},
}
QUICK = dict(solutions=(DEFAULT,), eps=(0.045, 0.01), H=H[:3], skip=("mpm_calculated_16",),
             short=("mpm_exact", "fem_consistent", "fem_lumped"), PPC=(2, 4, 8, 16), PPC_H=(0.01,), TIME_H=0.01,
             time_eps=(0.045,), time_methods=("mpm_calculated", "mpm_exact_dt_h"), lumping_H=H[:2], diagnosis_H=())
PROFILE_H = 0.01


# ---------------------------------------------------------------- one case (runs in a worker)

def run_case(case: dict) -> dict:
    """One run. ``case["solver"]``: ``"mpm"`` (fields of ``BurgersSettings``) or ``"fem"``
    (``solution``, ``eps``, ``h``, ``mass``, ``cfl``, ``cfl_visc``). Velocity errors at T over
    particles and nodes; the profile at T when ``case["profile"]``."""
    if case["solver"] == "fem":
        solution = make_solution(case["solution"], case["eps"])
        r = fem_burgers.solve(solution, case["h"], T=0.5, mass=case["mass"], cfl=case["cfl"], cfl_visc=case["cfl_visc"])
        out = {"ok": True, "nodes": fem_burgers.errors(r, solution), "steps": r.steps, "dt": r.dt}
        if case.get("profile"):
            out["profile"] = _rounded(dict(nodes=r.nodes, nodal_velocity=r.v))
        return out
    settings = burgers.BurgersSettings(**{k: v for k, v in case.items() if k not in ("solver", "profile")})
    try:
        r = burgers.simulate(settings, progress=False)
    except (ArithmeticError, ValueError) as err:
        return {"ok": False, "error": str(err)}
    e = burgers.errors(settings, r)["velocity"]
    out = {"ok": True, "particles": e["particles"], "nodes": e["nodes"], "steps": r.steps, "dt": r.dt_min,
           "dt_max": r.dt_max, "n_p": int(r.particles.n), "wall_s": round(r.wall_s, 2)}
    if case.get("profile"):
        order = np.argsort(r.particles.x)
        out["profile"] = _rounded(dict(x=r.particles.x[order], velocity=r.particles.velocity[order],
                                       nodes=r.grid.nodes, nodal_velocity=r.nodal_velocity))
    return out


def _rounded(arrays: dict) -> dict:
    return {k: [float(f"{v:.9g}") for v in np.asarray(a)] for k, a in arrays.items()}


# ---------------------------------------------------------------- the cases

def method_case(method: str, solution: str, eps: float, h: float, **changes) -> dict:
    """The case of ``method`` (a key of :data:`METHODS`) with ``changes`` to its settings."""
    _, solver, fixed, _ = METHODS[method]
    if solver == "fem":
        return {"solver": "fem", "solution": solution, "eps": eps, "h": h, **FEM, **fixed, **changes}
    return {"solver": "mpm", "solution": solution, "eps": eps, "h": h, **MPM, **fixed, **changes}


def _cost(case: dict) -> float:
    """~ particles x steps (or nodes x stages x steps), to start the longest runs first."""
    h, eps = case["h"], case["eps"]
    viscous = eps / (h * h * case.get("cfl_visc", case["cfl"]))
    if case["solver"] == "fem":
        return 3.0 * viscous / h * (2.0 if case["mass"] == "consistent" else 1.0)
    steps = 1.0 / (h * case["cfl"]) if case.get("dt_rule") == "advective" else viscous
    return case["ppc"] * steps / h * case.get("refine", 1) * (3.0 if case.get("basis") == "gimp" else 1.0)


def _plan(quick: bool) -> dict:
    q = QUICK if quick else {}
    solutions, eps_list = q.get("solutions", SOLUTIONS), q.get("eps", EPS)
    plan = defaultdict(dict)
    for sol in solutions:
        meshes = MESHES["default" if sol == DEFAULT else "other"]
        for m, hs in meshes.items():
            if m in q.get("skip", ()):
                continue
            for eps in eps_list:
                for h in hs:
                    if quick and (h not in q["H"] or (m in q["short"] and h not in q["H"][:2])):
                        continue
                    plan["table"][(sol, m, eps, h)] = method_case(m, sol, eps, h)
    for eps in (EPS[0], EPS[-1]):
        if eps in eps_list:
            for m in METHODS:
                if m in q.get("skip", ()):
                    continue
                plan["profile"][(m, eps)] = {**method_case(m, DEFAULT, eps, PROFILE_H), "profile": True}
    time_h = q.get("TIME_H", TIME_H)
    for eps in q.get("time_eps", (EPS[0], EPS[-1])):
        for m in q.get("time_methods", ("mpm_calculated", "mpm_exact", "mpm_exact_dt_h")):
            for k in REFINE:
                plan["timestep"][(m, eps, k)] = method_case(m, DEFAULT, eps, time_h, **({"refine": k} if k > 1 else {}))
    for h in q.get("PPC_H", PPC_H):
        for n in q.get("PPC", PPC):
            for m in ("mpm_calculated", "mpm_exact"):
                plan["ppc"][(m, h, n)] = method_case(m, DEFAULT, EPS[0], h, ppc=n)
    for h in q.get("lumping_H", H[:3]):
        for m in ("mpm_calculated", "mpm_exact"):
            for mass in ("lumped", "consistent"):
                plan["lumping"][(m, mass, h)] = method_case(m, DEFAULT, EPS[0], h, mass=mass, cfl=LUMPING_CFL)
        for m in ("fem_consistent", "fem_lumped"):
            plan["lumping"][(m, METHODS[m][2]["mass"], h)] = method_case(m, DEFAULT, EPS[0], h)
    for h in q.get("diagnosis_H", H[:3]):
        for label, changes in DIAGNOSIS.items():
            plan["diagnosis"][(label, h)] = method_case("mpm_calculated", DEFAULT, EPS[0], h, **changes)
    return plan


# ---------------------------------------------------------------- the study

def run(options: StudyOptions) -> None:
    """Every case in one sweep (shared cases run once, the longest first), then tables and figures."""
    plan = _plan(options.quick)
    got = options.sweep_plan(NAME, run_case, plan, cost=_cost)
    folder = options.folder(NAME)
    settings = {"quick": options.quick, "mpm": MPM, "fem": FEM, "T": burgers.BurgersSettings.T, "domain": [0, 2],
                "default_solution": DEFAULT, "compared_norm": f"{NORM} over {WHERE}",
                "methods": {k: {"label": v[0], "solver": v[1], "settings": v[2], "source_row": v[3]} for k, v in METHODS.items()},
                "time_steps": {
                    "mpm_calculated and mpm_exact": f"dt = CFL min(h/max|v_p|, h^2/(2 eps)), CFL {MPM['cfl']}",
                    "mpm_exact_dt_h": f"dt = CFL h/max|v_p|, CFL {MPM['cfl']} (no viscous limit: no viscous force computed)",
                    "fem": f"dt = min(cfl h/max|v(x,0)|, cfl_visc h^2/(2 eps)), cfl {FEM['cfl']}, cfl_visc {FEM['cfl_visc']}, SSP-RK3"},
                "source_corrections": "exponents of the entries marked * in docs/claims.md moved by one power of ten",
                "time_h": QUICK["TIME_H"] if options.quick else TIME_H,
                "problem": burgers.BurgersSettings().as_dict()}
    _errors(folder, got, settings)
    _norms(folder, got, settings)
    _timestep(folder, got, settings)
    _ppc(folder, got, settings)
    _lumping(folder, got, settings)
    if got.get("diagnosis"):
        _diagnosis(folder, got, settings)
    _figures(folder, got)


def _value(r: dict, where: str, norm: str) -> float:
    return r[where][norm] if r.get("ok") and where in r else float("nan")


def _source(method: str, eps: float, h: float):
    row = METHODS[method][3]
    if row is None or eps not in SOURCE[row] or h not in H:
        return None
    return SOURCE[row][eps][H.index(h)]


def _errors(folder: Path, got: dict, settings: dict) -> None:
    rows, order_rows = [], []
    series = defaultdict(dict)
    for (sol, m, eps, h), r in sorted(got["table"].items(), key=lambda kv: (SOLUTIONS.index(kv[0][0]), list(METHODS).index(kv[0][1]), -kv[0][2], -kv[0][3])):
        src = _source(m, eps, h)
        row = {"solution": sol, "method": m, "eps": eps, "h": h}
        for where in ("particles", "nodes"):
            for norm in ("L1", "L2", "max"):
                row[f"{where}_{norm}"] = _value(r, where, norm)
        row.update({"source": src if src is not None else "", "source_corrected": "yes" if (METHODS[m][3], eps, h) in CORRECTED else "",
                    f"ratio_{WHERE}_{NORM}": row[f"{WHERE}_{NORM}"] / src if src else "",
                    "steps": r.get("steps", ""), "dt": r.get("dt", ""), "particles": r.get("n_p", ""),
                    "error": r.get("error", "")})
        rows.append(row)
        series[(sol, m, eps)][h] = row
    write_table(folder, "errors", rows, settings)
    for (sol, m, eps), by_h in series.items():
        hs = sorted(by_h, reverse=True)
        for where in ("particles", "nodes"):
            for norm in ("L1", "L2", "max"):
                v = np.array([by_h[h][f"{where}_{norm}"] for h in hs])
                if len(hs) < 2 or not np.all(np.isfinite(v) & (v > 0)):
                    continue
                o = observed_orders(hs, v)
                row = {"solution": sol, "method": m, "eps": eps, "where": where, "norm": norm,
                       "fitted": fitted_order(hs, v), "first": float(o[0]), "last": float(o[-1]),
                       "h_range": f"{hs[0]}-{hs[-1]}"}
                row.update({f"order_{a}_{b}": float(x) for a, b, x in zip(hs[:-1], hs[1:], o)})
                src = [_source(m, eps, h) for h in hs]
                if all(s is not None for s in src):
                    row["source_fitted"] = fitted_order(hs, src)
                order_rows.append(row)
    write_table(folder, "orders", order_rows, settings)


def _norms(folder: Path, got: dict, settings: dict) -> None:
    """For each solution, MPM method, place and norm: median of measured/source and its spread
    (max/min over the common cells of the table), and the spread of the source over eps."""
    groups = defaultdict(list)
    for (sol, m, eps, h), r in got["table"].items():
        src = _source(m, eps, h)
        if src is None:
            continue
        for where in ("particles", "nodes"):
            for norm in ("L1", "L2", "max"):
                v = _value(r, where, norm)
                if np.isfinite(v) and v > 0:
                    groups[(sol, m, where, norm)].append((eps, h, v, src))
    rows = []
    for (sol, m, where, norm), vals in sorted(groups.items()):
        ratio = np.array([v / s for _, _, v, s in vals])
        hs = sorted({h for _, h, _, _ in vals}, reverse=True)
        # how much the error changes with eps on the finest common mesh, measured and in the source
        fine = [(e, v, s) for e, h, v, s in vals if h == hs[-1]]
        rows.append({"solution": sol, "method": m, "where": where, "norm": norm, "cells": len(vals),
                     "median_ratio": float(np.median(ratio)), "ratio_spread": float(ratio.max() / ratio.min()),
                     "log10_ratio_rms": float(np.sqrt(np.mean(np.log10(ratio) ** 2))),
                     "eps_spread_finest": float(max(v for _, v, _ in fine) / min(v for _, v, _ in fine)) if len(fine) > 1 else "",
                     "source_eps_spread_finest": float(max(s for _, _, s in fine) / min(s for _, _, s in fine)) if len(fine) > 1 else "",
                     "finest_h": hs[-1]})
    write_table(folder, "norms", rows, settings)


def _timestep(folder: Path, got: dict, settings: dict) -> None:
    rows = []
    for (m, eps, k), r in sorted(got["timestep"].items(), key=lambda kv: (kv[0][0], -kv[0][1], kv[0][2])):
        finest = got["timestep"][(m, eps, REFINE[-1])]
        row = {"method": m, "eps": eps, "h": settings.get("time_h", ""), "refine": k, "steps": r.get("steps", ""),
               "dt": r.get("dt", "")}
        for norm in ("L1", "L2", "max"):
            v, ref = _value(r, WHERE, norm), _value(finest, WHERE, norm)
            row[f"{WHERE}_{norm}"] = v
            # the time error of this dt, estimated against dt/16, beside the error it leaves
            row[f"time_error_{norm}"] = abs(v - ref) if k != REFINE[-1] else ""
        ref = _value(finest, WHERE, NORM)
        row["time_below_space"] = ("yes" if abs(row[f"{WHERE}_{NORM}"] - ref) < ref else "no") if k != REFINE[-1] else ""
        rows.append(row)
    write_table(folder, "timestep", rows, {**settings, "refine": list(REFINE), "meaning":
                "time_error = |E(dt) - E(dt/16)|; time_below_space: time error < E(dt/16) (the space error)"})


def _ppc(folder: Path, got: dict, settings: dict) -> None:
    rows = []
    for (m, h, n), r in sorted(got["ppc"].items(), key=lambda kv: (kv[0][0], -kv[0][1], kv[0][2])):
        rows.append({"method": m, "eps": EPS[0], "h": h, "ppc": n, **{f"{w}_{k}": _value(r, w, k)
                     for w in ("particles", "nodes") for k in ("L1", "L2", "max")}, "steps": r.get("steps", ""),
                     "error": r.get("error", "")})
    for m, h in {(r["method"], r["h"]) for r in rows}:
        sub = [r for r in rows if r["method"] == m and r["h"] == h and np.isfinite(r[f"{WHERE}_{NORM}"])]
        best = min(sub, key=lambda r: r[f"{WHERE}_{NORM}"])["ppc"] if sub else ""
        for r in sub:
            r["best_ppc"] = best
    write_table(folder, "ppc", rows, settings)


def _lumping(folder: Path, got: dict, settings: dict) -> None:
    rows = []
    for (m, mass, h), r in sorted(got["lumping"].items(), key=lambda kv: (kv[0][0], kv[0][1], -kv[0][2])):
        where = "nodes" if m.startswith("fem") else WHERE
        rows.append({"method": m, "mass": mass, "eps": EPS[0], "h": h, "where": where,
                     **{k: _value(r, where, k) for k in ("L1", "L2", "max")},
                     "nodes_L2": _value(r, "nodes", "L2"), "dt": r.get("dt", ""), "error": r.get("error", "")})
    write_table(folder, "lumping", rows, {**settings, "mpm_cfl": LUMPING_CFL})


def _diagnosis(folder: Path, got: dict, settings: dict) -> None:
    rows = []
    for (label, h), r in got["diagnosis"].items():
        rows.append({"variant": label, "changes": repr(DIAGNOSIS[label]), "eps": EPS[0], "h": h,
                     **{f"{w}_{k}": _value(r, w, k) for w in ("particles", "nodes") for k in ("L1", "L2", "max")},
                     "error": r.get("error", "")})
    for label in DIAGNOSIS:
        sub = sorted((r for r in rows if r["variant"] == label), key=lambda r: -r["h"])
        v = np.array([r[f"{WHERE}_L1"] for r in sub])
        if len(sub) > 1 and np.all(np.isfinite(v) & (v > 0)):
            for r, o in zip(sub[1:], observed_orders([r["h"] for r in sub], v)):
                r["order_L1"] = float(o)
    write_table(folder, "diagnosis", rows, {**settings, "diagnosis": {k: v for k, v in DIAGNOSIS.items()},
                                            "solution": DEFAULT})


# ---------------------------------------------------------------- figures

STYLE = {"mpm_calculated": ("o-", "tab:blue"), "mpm_calculated_16": ("o--", "tab:purple"), "mpm_exact": ("s-", "tab:orange"),
         "mpm_exact_dt_h": ("D-", "tab:red"), "fem_consistent": ("^--", "tab:green"), "fem_lumped": ("v--", "tab:olive")}


def _series(points, m, label, norm=NORM, **options):
    """``{label: (x, error, fmt, options)}`` of method ``m`` from ``points = [(x, result)]``."""
    where = "nodes" if m.startswith("fem") else WHERE
    pts = sorted(points)
    style, color = STYLE[m]
    return {label: ([x for x, _ in pts], [_value(r, where, norm) for _, r in pts], style, {"color": color, **options})}


def _convergence_panel(got, sol, eps) -> dict:
    panel = {}
    for m, (label, solver, _, _) in METHODS.items():
        pts = [(h, r) for (s, mm, e, h), r in got["table"].items() if (s, mm, e) == (sol, m, eps)]
        if pts:
            panel.update(_series(pts, m, label + (" (nodes)" if solver == "fem" else "")))
    for row, marker in (("exact", "ks"), ("calculated", "ko")):
        panel[f"source, {row} a"] = (H, SOURCE[row][eps], marker, {"mfc": "none", "ms": 6})
    return panel


def _figures(folder: Path, got: dict) -> None:
    ylabel = f"velocity error ({NORM}; MPM over {WHERE})"
    eps_shown = sorted({e for (_, _, e, _) in got["table"]}, reverse=True)
    plots.panels(folder / "convergence.png", {f"{DEFAULT}, eps = {e}": _convergence_panel(got, DEFAULT, e) for e in eps_shown},
                 "h", ylabel, f"Burgers, T = {burgers.BurgersSettings.T}: velocity error vs h ({DEFAULT} solution); "
                 "open black: the source's table", slopes=(1, 2))
    sols = [s for s in SOLUTIONS if any(k[0] == s for k in got["table"])]
    shown = [e for e in (EPS[0], EPS[-1]) if e in eps_shown]
    plots.panels(folder / "solutions.png", {f"{s}, eps = {e}": _convergence_panel(got, s, e) for e in shown for s in sols},
                 "h", ylabel, "Every candidate exact solution: velocity error vs h", ncols=len(sols), slopes=(1, 2))
    _profile_figure(folder / "profiles.png", got)
    by = lambda table, keep: {k: r for k, r in got[table].items() if keep(k)}  # noqa: E731
    plots.panels(folder / "ppc.png", {f"C3, Burgers: error vs N_p ({DEFAULT}, eps = {EPS[0]})": {
        k: v for m, h in sorted({(m, h) for (m, h, _) in got["ppc"]}) for k, v in _series(
            [(n, r) for (mm, hh, n), r in got["ppc"].items() if (mm, hh) == (m, h)], m, f"{METHODS[m][0]}, h = {h}",
            alpha=1.0 if h == max(PPC_H) else 0.6).items()}}, "particles per cell N_p", f"velocity error ({NORM} over {WHERE})")
    plots.panels(folder / "lumping.png", {f"C15: lumped vs consistent mass ({DEFAULT}, eps = {EPS[0]}; MPM CFL {LUMPING_CFL})": {
        k: v for m, mass in sorted({(m, mass) for (m, mass, _) in got["lumping"]}) for k, v in _series(
            [(h, r) for (mm, ms, h), r in by("lumping", lambda k: k[:2] == (m, mass)).items()], m,
            f"{METHODS[m][0]}, {mass}", "L2", mfc="none" if mass == "lumped" else None).items()}},
        "h", f"velocity error (L2; MPM over {WHERE}, FEM over nodes)", slopes=(1, 2))
    plots.panels(folder / "timestep.png", {f"Time error at fixed h: dt / {', '.join(map(str, REFINE))}": {
        k: v for m, eps in sorted({(m, e) for (m, e, _) in got["timestep"]}) for k, v in _series(
            [(r["dt"], r) for (mm, e, _), r in got["timestep"].items() if (mm, e) == (m, eps) and r.get("ok")], m,
            f"{METHODS[m][0]}, eps = {eps}", alpha=1.0 if eps == EPS[0] else 0.6).items()}},
        "dt (smallest step of the run)", f"velocity error ({NORM} over {WHERE})")
    if got.get("diagnosis"):
        plots.panels(folder / "diagnosis.png", {
            f"Why the calculated acceleration stalls ({DEFAULT}, eps = {EPS[0]}): one change at a time": {
                label: ([h for h, _ in pts], [_value(r, WHERE, "L1") for _, r in pts], "o-") for label in DIAGNOSIS
                for pts in [sorted((h, r) for (lab, h), r in got["diagnosis"].items() if lab == label)]}},
            "h", f"velocity error (L1 over {WHERE})", slopes=(1, 2), size=(6.2, 4.6))


def _profile_figure(path, got) -> None:
    import matplotlib.pyplot as plt

    eps_list = sorted({e for (_, e) in got["profile"]}, reverse=True)
    if not eps_list:
        return
    T = burgers.BurgersSettings.T
    fig, axes = plt.subplots(2, len(eps_list), figsize=(6.5 * len(eps_list), 6.5), squeeze=False, sharex=True)
    for j, eps in enumerate(eps_list):
        exact, xe = make_solution(DEFAULT, eps), np.linspace(0, 2, 2001)
        axes[0][j].plot(xe, exact.v(xe, T), "k-", lw=1, label=f"exact, T = {T}")
        axes[0][j].plot(xe, exact.v(xe, 0.0), "k:", lw=0.8, label="exact, t = 0")
        for m, (label, solver, _, _) in METHODS.items():
            r = got["profile"].get((m, eps))
            if not r or not r.get("ok"):
                continue
            p, color = r["profile"], STYLE[m][1]
            if solver == "mpm":
                x, v = np.array(p["x"]), np.array(p["velocity"])
                axes[0][j].plot(x, v, ".", ms=1.5, color=color, label=f"{label}, particles")
                axes[1][j].plot(x, v - exact.v(x, T), ".", ms=1.5, color=color, label=label)
            else:
                x, v = np.array(p["nodes"]), np.array(p["nodal_velocity"])
                axes[1][j].plot(x, v - exact.v(x, T), "-", lw=0.9, color=color, label=f"{label}, nodes")
        axes[0][j].set(title=f"{DEFAULT}, eps = {eps}, h = {PROFILE_H}", ylabel="velocity")
        axes[1][j].set(ylabel="error v - v_exact at T", xlabel="x")
        axes[0][j].legend(fontsize=6, markerscale=4)
        axes[1][j].legend(fontsize=6, markerscale=4)
    plots.save(fig, path)


# ---------------------------------------------------------------- report

# ---------------------------------------------------------------- the report page

_SHOWN = {"solution": DEFAULT, "eps": EPS[0]}
PAGE = Page(
    NAME, "Viscous Burgers",
    "The viscous Burgers equation with initial and boundary data from an exact solution, MPM with the exact and "
    "with the calculated acceleration beside P1 FEM with consistent and lumped mass, against the source's table "
    "(entries corrected as listed in the claims document marked in the source_corrected column). The solution and "
    "norm compared with the source are chosen by the norms table.",
    views=(
        View("burgers/orders", "Least-squares orders of the solution and norm compared with the source",
             ("method", "eps", "fitted", "first", "last", "h_range", "source_fitted"),
             {"solution": DEFAULT, "where": WHERE, "norm": NORM}, "convergence.png"),
        View("burgers/errors", "Errors on every mesh beside the source, first eps",
             ("method", "h", f"{WHERE}_{NORM}", "source", "source_corrected", f"ratio_{WHERE}_{NORM}", "steps"),
             _SHOWN),
        View("burgers/norms", "Which solution and norm: median measured/source and spread over eps",
             ("solution", "method", "median_ratio", "eps_spread_finest", "source_eps_spread_finest"),
             {"where": WHERE, "norm": NORM}, "solutions.png"),
        View("burgers/timestep", "Time error: the time step refined at one mesh",
             ("method", "eps", "refine", "dt", f"{WHERE}_{NORM}", f"time_error_{NORM}", "time_below_space"), {},
             "timestep.png"),
        View("burgers/ppc", "Error against particles per cell",
             ("method", "h", "ppc", f"{WHERE}_{NORM}", "best_ppc"), {}, "ppc.png"),
        View("burgers/lumping", "Lumped against consistent mass", ("method", "mass", "h", "where", "L1", "L2", "max"),
             {}, "lumping.png"),
        View("burgers/diagnosis", "Why the calculated acceleration stalls: one change at a time",
             ("variant", "h", f"{WHERE}_L1", "order_L1"), {}, "diagnosis.png"),
    ),
    figures=(("profiles.png", "Profiles against the exact solution on the coarsest mesh"),),
)


if __name__ == "__main__":
    sys.exit(script_main(NAME))
