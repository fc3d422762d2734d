"""Viscous Burgers: MPM with exact and calculated acceleration beside FEM and the source's table.

``v_t + v v_x = eps v_xx`` on [0, 2] up to T, data from an exact solution. MPM (point mass, USL, lumped
mass, reservoir inflow) takes the nodal acceleration from the particles (``a_i = F_i/m_i``,
"calculated") or from the exact solution ("exact"), beside P1 Galerkin FEM with consistent and lumped
mass on the same mesh (:mod:`baselines.fem_burgers`). Time steps follow one rule on every mesh
(``settings["time_steps"]``). Tables: ``errors`` and ``orders`` (C13), ``norms`` (which solution and
norm match the source), ``timestep`` (time error at one mesh), ``ppc`` (C3), ``lumping`` (C15),
``diagnosis`` (why the calculated acceleration stalls: one setting changed at a time).
"""

from __future__ import annotations

import sys
from collections import defaultdict

import numpy as np

from baselines import fem_burgers
from baselines.exact.burgers import make_solution
from mpm_fem import plots, source
from mpm_fem.claims import BURGERS_SHOWN
from mpm_fem.errors import fitted_order, observed_orders, orders_row
from mpm_fem.plots import Curve, Plot
from mpm_fem.problems import burgers
from mpm_fem.study import StudyOptions, script_main, write_table

NAME = "burgers"
H = source.BURGERS_H
EPS = (0.045, 0.04, 0.03, 0.02, 0.01)
SOLUTIONS = ("rarefaction", "cole_hopf", "three_exp", "front")
#: The solution, and the norm (the slides do not say which), compared with the source; why: norms.csv.
DEFAULT, WHERE, NORM = BURGERS_SHOWN["solution"], BURGERS_SHOWN["where"], BURGERS_SHOWN["norm"]
SOURCE, CORRECTED = source.BURGERS, source.BURGERS_CORRECTED
T = burgers.BurgersSettings.T
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
# The meshes each method runs on. The explicit viscous limit makes a run at h cost ~ eps/h^3; the
# finest meshes are spent on the default solution and on the methods that need them to show their order.
MESHES = {
    "default": {"mpm_calculated": H, "mpm_calculated_16": H[:3], "mpm_exact_dt_h": H, "mpm_exact": H[:3], "fem_consistent": H[:3], "fem_lumped": H[:3]},
    "other": {"mpm_calculated": H[:3], "mpm_exact_dt_h": H, "mpm_exact": H[:3], "fem_consistent": H[:2], "fem_lumped": H[:2]},
}
PPC, PPC_H, TIME_H, REFINE, PROFILE_H = (1, 2, 4, 8, 16, 32), (0.01, 0.0025), 0.005, (1, 4, 16), 0.01
LUMPING_CFL = 0.3  # the consistent particle mass needs dt <= h^2/(6 eps): both masses run with CFL 0.3
DIAGNOSIS = {  # label: changes to the calculated-acceleration run
    "MPM: weak force, V_p weights": {}, "slides' force (second difference)": {"force": "slides"},
    "slides' weights h/N_p^i": {"weights": "cell"}, "slides' weights and force": {"weights": "cell", "force": "slides"},
    "consistent mass (CFL 0.3)": {"mass": "consistent", "cfl": LUMPING_CFL}, "GIMP basis": {"basis": "gimp"},
    "16 particles per cell": {"ppc": 16}, "exact acceleration": {"acceleration": "exact"},
}
QUICK = dict(solutions=(DEFAULT,), eps=(0.045, 0.01), H=H[:3], skip=("mpm_calculated_16",),
             short=("mpm_exact", "fem_consistent", "fem_lumped"), PPC=(2, 4, 8, 16), PPC_H=(0.01,), TIME_H=0.01,
             time_eps=(0.045,), time_methods=("mpm_calculated", "mpm_exact_dt_h"), lumping_H=H[:2], diagnosis_H=())


def run_case(case: dict) -> dict:
    """One run. ``case["solver"]``: ``"mpm"`` (fields of ``BurgersSettings``) or ``"fem"``
    (``solution``, ``eps``, ``h``, ``mass``, ``cfl``, ``cfl_visc``). Velocity errors at T over
    particles and nodes; the profile at T when ``case["profile"]``."""
    if case["solver"] == "fem":
        solution = make_solution(case["solution"], case["eps"])
        r = fem_burgers.solve(solution, case["h"], T=T, mass=case["mass"], cfl=case["cfl"], cfl_visc=case["cfl_visc"])
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


def method_case(method: str, solution: str, eps: float, h: float, **changes) -> dict:
    """The case of ``method`` (a key of :data:`METHODS`) with ``changes`` to its settings."""
    _, solver, fixed, _ = METHODS[method]
    return {"solver": solver, "solution": solution, "eps": eps, "h": h, **(FEM if solver == "fem" else MPM), **fixed, **changes}


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
    solutions, eps_list, skip = q.get("solutions", SOLUTIONS), q.get("eps", EPS), q.get("skip", ())
    plan = defaultdict(dict)
    for sol in solutions:
        for m, hs in MESHES["default" if sol == DEFAULT else "other"].items():
            for eps in eps_list:
                for h in hs:
                    if m not in skip and not (quick and (h not in q["H"] or (m in q["short"] and h not in q["H"][:2]))):
                        plan["table"][(sol, m, eps, h)] = method_case(m, sol, eps, h)
    for eps in (e for e in (EPS[0], EPS[-1]) if e in eps_list):
        for m in (m for m in METHODS if m not in skip):
            plan["profile"][(m, eps)] = {**method_case(m, DEFAULT, eps, PROFILE_H), "profile": True}
    for eps in q.get("time_eps", (EPS[0], EPS[-1])):
        for m in q.get("time_methods", ("mpm_calculated", "mpm_exact", "mpm_exact_dt_h")):
            for k in REFINE:
                plan["timestep"][(m, eps, k)] = method_case(m, DEFAULT, eps, q.get("TIME_H", TIME_H), **({"refine": k} if k > 1 else {}))
    for m in ("mpm_calculated", "mpm_exact"):
        for h in q.get("PPC_H", PPC_H):
            for n in q.get("PPC", PPC):
                plan["ppc"][(m, h, n)] = method_case(m, DEFAULT, EPS[0], h, ppc=n)
    for h in q.get("lumping_H", H[:3]):
        for m, mass in [(m, mass) for m in ("mpm_calculated", "mpm_exact") for mass in ("lumped", "consistent")]:
            plan["lumping"][(m, mass, h)] = method_case(m, DEFAULT, EPS[0], h, mass=mass, cfl=LUMPING_CFL)
        for m in ("fem_consistent", "fem_lumped"):
            plan["lumping"][(m, METHODS[m][2]["mass"], h)] = method_case(m, DEFAULT, EPS[0], h)
    for h in q.get("diagnosis_H", H[:3]):
        for label, changes in DIAGNOSIS.items():
            plan["diagnosis"][(label, h)] = method_case("mpm_calculated", DEFAULT, EPS[0], h, **changes)
    return plan


def run(options: StudyOptions) -> None:
    """Every case in one sweep (shared cases run once, the longest first), then tables and figures."""
    got = options.sweep_plan(NAME, run_case, _plan(options.quick), cost=_cost)
    folder = options.folder(NAME)
    settings = {"quick": options.quick, "mpm": MPM, "fem": FEM, "T": T, "domain": [0, 2],
                "default_solution": DEFAULT, "compared_norm": f"{NORM} over {WHERE}",
                "methods": {k: {"label": v[0], "solver": v[1], "settings": v[2], "source_row": v[3]} for k, v in METHODS.items()},
                "time_steps": {
                    "mpm_calculated and mpm_exact": f"dt = CFL min(h/max|v_p|, h^2/(2 eps)), CFL {MPM['cfl']}",
                    "mpm_exact_dt_h": f"dt = CFL h/max|v_p|, CFL {MPM['cfl']} (no viscous limit: no viscous force computed)",
                    "fem": f"dt = min(cfl h/max|v(x,0)|, cfl_visc h^2/(2 eps)), cfl {FEM['cfl']}, cfl_visc {FEM['cfl_visc']}, SSP-RK3"},
                "source_corrections": "exponents of the entries marked * in docs/claims.md moved by one power of ten",
                "time_h": QUICK["TIME_H"] if options.quick else TIME_H, "problem": burgers.BurgersSettings().as_dict()}
    errors, orders = _errors(got)
    tables = {"errors": errors, "orders": orders, "norms": _norms(got), "timestep": _timestep(got, settings["time_h"]),
              "ppc": _ppc(got), "lumping": _lumping(got), "diagnosis": _diagnosis(got) if got.get("diagnosis") else []}
    extra = {"timestep": {"refine": list(REFINE), "meaning": "time_error = |E(dt) - E(dt/16)|; time_below_space: time "
                          "error < E(dt/16) (the space error)"}, "lumping": {"mpm_cfl": LUMPING_CFL},
             "diagnosis": {"diagnosis": dict(DIAGNOSIS), "solution": DEFAULT}}
    for name, rows in tables.items():
        if rows:
            write_table(folder, name, rows, {**settings, **extra.get(name, {})})
    for plot in PLOTS:
        if tables[plot.table]:
            plots.draw(folder, plot, tables[plot.table])
    _profiles(folder / "profiles.png", got)


def _value(r: dict, where: str, norm: str) -> float:
    return r[where][norm] if r.get("ok") and where in r else float("nan")


def _norms_of(r: dict, wheres=("particles", "nodes")) -> dict:
    return {f"{w}_{k}": _value(r, w, k) for w in wheres for k in ("L1", "L2", "max")}


def _source(method: str, eps: float, h: float):
    return source.burgers_value(METHODS[method][3], eps, h)


def _errors(got: dict) -> tuple[list, list]:
    rows, order_rows, series = [], [], defaultdict(dict)
    key = lambda kv: (SOLUTIONS.index(kv[0][0]), list(METHODS).index(kv[0][1]), -kv[0][2], -kv[0][3])  # noqa: E731
    for (sol, m, eps, h), r in sorted(got["table"].items(), key=key):
        src = _source(m, eps, h)
        row = {"solution": sol, "method": m, "eps": eps, "h": h, **_norms_of(r)}
        row.update({"source": src if src is not None else "", "source_corrected": "yes" if (METHODS[m][3], eps, h) in CORRECTED else "",
                    f"ratio_{WHERE}_{NORM}": row[f"{WHERE}_{NORM}"] / src if src else "",
                    "steps": r.get("steps", ""), "dt": r.get("dt", ""), "particles": r.get("n_p", ""), "error": r.get("error", "")})
        rows.append(row)
        series[(sol, m, eps)][h] = row
    for (sol, m, eps), by_h in series.items():
        hs = sorted(by_h, reverse=True)
        src = [_source(m, eps, h) for h in hs]
        for where in ("particles", "nodes"):
            for norm in ("L1", "L2", "max"):
                v = np.array([by_h[h][f"{where}_{norm}"] for h in hs])
                if len(hs) > 1 and np.all(np.isfinite(v) & (v > 0)):
                    order_rows.append({"solution": sol, "method": m, "eps": eps, "where": where, "norm": norm, **orders_row(hs, v),
                                       **({"source_fitted": fitted_order(hs, src)} if None not in src else {})})
    return rows, order_rows


def _norms(got: dict) -> list[dict]:
    """For each solution, MPM method, place and norm: median of measured/source and its spread
    (max/min over the common cells of the table), and the spread over eps on the finest common mesh."""
    groups = defaultdict(list)
    for (sol, m, eps, h), r in got["table"].items():
        src = _source(m, eps, h)
        for (where, norm), v in ({} if src is None else {tuple(k.split("_")): v for k, v in _norms_of(r).items()}).items():
            if np.isfinite(v) and v > 0:
                groups[(sol, m, where, norm)].append((eps, h, v, src))
    rows = []
    for (sol, m, where, norm), vals in sorted(groups.items()):
        ratio = np.array([v / s for _, _, v, s in vals])
        finest = min(h for _, h, _, _ in vals)
        fine = [(v, s) for _, h, v, s in vals if h == finest]
        spread = lambda xs: float(max(xs) / min(xs)) if len(fine) > 1 else ""  # noqa: E731
        rows.append({"solution": sol, "method": m, "where": where, "norm": norm, "cells": len(vals),
                     "median_ratio": float(np.median(ratio)), "ratio_spread": float(ratio.max() / ratio.min()),
                     "log10_ratio_rms": float(np.sqrt(np.mean(np.log10(ratio) ** 2))),
                     "eps_spread_finest": spread([v for v, _ in fine]), "source_eps_spread_finest": spread([s for _, s in fine]),
                     "finest_h": finest})
    return rows


def _timestep(got: dict, time_h: float) -> list[dict]:
    rows = []
    for (m, eps, k), r in sorted(got["timestep"].items(), key=lambda kv: (kv[0][0], -kv[0][1], kv[0][2])):
        finest = got["timestep"][(m, eps, REFINE[-1])]
        row = {"method": m, "eps": eps, "h": time_h, "refine": k, "steps": r.get("steps", ""), "dt": r.get("dt", "")}
        for norm in ("L1", "L2", "max"):  # the time error of this dt, estimated against dt/16
            v, ref = _value(r, WHERE, norm), _value(finest, WHERE, norm)
            row.update({f"{WHERE}_{norm}": v, f"time_error_{norm}": abs(v - ref) if k != REFINE[-1] else ""})
        ref = _value(finest, WHERE, NORM)
        row["time_below_space"] = ("yes" if abs(row[f"{WHERE}_{NORM}"] - ref) < ref else "no") if k != REFINE[-1] else ""
        rows.append(row)
    return rows


def _ppc(got: dict) -> list[dict]:
    rows = [{"method": m, "eps": EPS[0], "h": h, "ppc": n, **_norms_of(r), "steps": r.get("steps", ""), "error": r.get("error", "")}
            for (m, h, n), r in sorted(got["ppc"].items(), key=lambda kv: (kv[0][0], -kv[0][1], kv[0][2]))]
    for m, h in {(r["method"], r["h"]) for r in rows}:
        sub = [r for r in rows if r["method"] == m and r["h"] == h and np.isfinite(r[f"{WHERE}_{NORM}"])]
        for r in sub:
            r["best_ppc"] = min(sub, key=lambda r: r[f"{WHERE}_{NORM}"])["ppc"]
    return rows


def _lumping(got: dict) -> list[dict]:
    return [{"method": m, "mass": mass, "eps": EPS[0], "h": h, "where": "nodes" if m.startswith("fem") else WHERE,
             **{k: _value(r, "nodes" if m.startswith("fem") else WHERE, k) for k in ("L1", "L2", "max")},
             "nodes_L2": _value(r, "nodes", "L2"), "dt": r.get("dt", ""), "error": r.get("error", "")}
            for (m, mass, h), r in sorted(got["lumping"].items(), key=lambda kv: (kv[0][0], kv[0][1], -kv[0][2]))]


def _diagnosis(got: dict) -> list[dict]:
    rows = [{"variant": label, "changes": repr(DIAGNOSIS[label]), "eps": EPS[0], "h": h, **_norms_of(r), "error": r.get("error", "")}
            for (label, h), r in got["diagnosis"].items()]
    for label in DIAGNOSIS:
        sub = sorted((r for r in rows if r["variant"] == label), key=lambda r: -r["h"])
        v = np.array([r[f"{WHERE}_L1"] for r in sub])
        if len(sub) > 1 and np.all(np.isfinite(v) & (v > 0)):
            for r, o in zip(sub[1:], observed_orders([r["h"] for r in sub], v)):
                r["order_L1"] = float(o)
    return rows


STYLE = {"mpm_calculated": ("o-", "tab:blue"), "mpm_calculated_16": ("o--", "tab:purple"), "mpm_exact": ("s-", "tab:orange"),
         "mpm_exact_dt_h": ("D-", "tab:red"), "fem_consistent": ("^--", "tab:green"), "fem_lumped": ("v--", "tab:olive")}


def _curves(methods, label="{}", y=None, **where) -> tuple[Curve, ...]:
    """A curve per method, in its style; ``y`` defaults to the compared norm (FEM: over nodes)."""
    return tuple(Curve(label.format(METHODS[m][0]), y or f"{'nodes' if m.startswith('fem') else WHERE}_{NORM}", STYLE[m][0],
                       {**where, "method": m}, options={"color": STYLE[m][1]}) for m in methods)


_BESIDE_SOURCE = _curves(METHODS) + (Curve("source, exact a", "source", "ks", {"method": "mpm_exact_dt_h"}),
                                     Curve("source, calculated a", "source", "ko", {"method": "mpm_calculated"}))
_ERROR = f"velocity error ({NORM}; MPM over {WHERE}, FEM over nodes)"
PLOTS = (
    Plot("convergence.png", f"Burgers, T = {T}: velocity error against h ({DEFAULT} solution), open black: the source",
         "errors", "h", tuple(Curve(c.label, c.y, c.fmt, {**c.where, "solution": DEFAULT}, options=c.options) for c in _BESIDE_SOURCE),
         ylabel=_ERROR, slopes=(1, 2), split=("eps",), size=(4.2, 4.0)),
    Plot("solutions.png", "Every candidate exact solution: velocity error against h", "errors", "h",
         tuple(Curve(c.label, c.y, c.fmt, {**c.where, "eps": (EPS[0], EPS[-1])}, options=c.options) for c in _BESIDE_SOURCE),
         ylabel=_ERROR, slopes=(1, 2), split=("eps", "solution"), ncols=len(SOLUTIONS), size=(4.2, 3.8)),
    Plot("ppc.png", f"C3, Burgers: error against N_p ({DEFAULT}, eps = {EPS[0]})", "ppc", "ppc",
         tuple(Curve(f"{METHODS[m][0]}, h = {{h}}", f"{WHERE}_{NORM}", STYLE[m][0], {"method": m}, group=("h",),
                     options={"color": STYLE[m][1]}) for m in ("mpm_calculated", "mpm_exact")),
         xlabel="particles per cell N_p", ylabel=f"velocity error ({NORM} over {WHERE})"),
    Plot("lumping.png", f"C15: lumped against consistent mass ({DEFAULT}, eps = {EPS[0]}; MPM CFL {LUMPING_CFL})", "lumping",
         "h", tuple(Curve(f"{METHODS[m][0]}, {mass}", "L2", ("-" if mass == "consistent" else ":") + STYLE[m][0][0],
                          {"method": m, "mass": mass}, options={"color": STYLE[m][1]})
                    for m in METHODS if m != "mpm_calculated_16" and m != "mpm_exact_dt_h" for mass in ("consistent", "lumped")),
         ylabel=f"velocity error (L2; MPM over {WHERE}, FEM over nodes)", slopes=(1, 2)),
    Plot("timestep.png", f"Time error at fixed h: dt / {', '.join(map(str, REFINE))}", "timestep", "dt",
         tuple(Curve(f"{METHODS[m][0]}, eps = {{eps}}", f"{WHERE}_{NORM}", STYLE[m][0], {"method": m}, group=("eps",),
                     options={"color": STYLE[m][1]}) for m in ("mpm_calculated", "mpm_exact", "mpm_exact_dt_h")),
         xlabel="dt (smallest step of the run)", ylabel=f"velocity error ({NORM} over {WHERE})"),
    Plot("diagnosis.png", f"Why the calculated acceleration stalls ({DEFAULT}, eps = {EPS[0]}): one change at a time",
         "diagnosis", "h", (Curve("{variant}", f"{WHERE}_L1", "o-", group=("variant",)),),
         ylabel=f"velocity error (L1 over {WHERE})", slopes=(1, 2), size=(6.2, 4.6)),
)


def _profiles(path, got) -> None:
    """Velocity and its error at T on the profile mesh, one row per eps shown."""
    eps_list = sorted({e for (_, e) in got["profile"]}, reverse=True)
    xe, exact, rows = np.linspace(0, 2, 2001), {}, {}
    for eps in eps_list:
        v = make_solution(DEFAULT, eps).v
        exact[f"eps = {eps}"] = {"velocity": (xe, v(xe, T)), "error v - v_exact at T": (xe, 0 * xe)}
        rows[f"eps = {eps}"] = [("exact, t = 0", xe, {"velocity": v(xe, 0.0)}, "k:", {"lw": 0.8})] + [
            (METHODS[m][0], x, {"velocity": u, "error v - v_exact at T": u - v(x, T)}, "." if METHODS[m][1] == "mpm" else "-",
             {"ms": 1.5, "color": STYLE[m][1]} if METHODS[m][1] == "mpm" else {"lw": 0.9, "color": STYLE[m][1]})
            for m in METHODS if got["profile"].get((m, eps), {}).get("ok")
            for p in [got["profile"][(m, eps)]["profile"]]
            for x, u in [(np.array(p["x"]), np.array(p["velocity"])) if "x" in p else (np.array(p["nodes"]), np.array(p["nodal_velocity"]))]]
    if rows:
        plots.profile_grid(path, exact, rows, f"{DEFAULT} solution at T = {T}, h = {PROFILE_H}: particles (MPM), nodes (FEM)")



if __name__ == "__main__":
    sys.exit(script_main(NAME))
