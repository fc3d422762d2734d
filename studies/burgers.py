"""Viscous Burgers: MPM with exact and calculated acceleration beside FEM and the source's table.

``v_t + v v_x = eps v_xx`` on [0, 2] up to T, data from an exact solution; MPM takes the nodal
acceleration from the particles ("calculated") or from the exact solution ("exact"), beside P1 FEM
with consistent and lumped mass on the same mesh. Tables: ``errors``, ``orders`` (C13), ``norms``
(which solution and norm match the source), ``timestep``, ``ppc`` (C3), ``lumping`` (C15), ``diagnosis``."""

from __future__ import annotations

import sys
from collections import defaultdict

import numpy as np

from baselines import fem_burgers
from baselines.exact.burgers import make_solution
from mpm_fem.app import plots
from mpm_fem.app.plots import Curve, Plot
from mpm_fem.app.study import StudyOptions, publish, script_main
from mpm_fem.measure import source
from mpm_fem.measure.claims import BURGERS_SHOWN
from mpm_fem.measure.errors import fitted_order, observed_orders, orders_row
from mpm_fem.measure.schema import BURGERS_LUMPING, BURGERS_ORDERS, BURGERS_PPC
from mpm_fem.problems import burgers

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
# The meshes of each method, by tier: a run costs ~ eps/h^3, so the deep tier takes every method to
# every mesh of the source's table; the full tier every mesh for the rows compared with the source.
MESHES = {
    "deep": {
        "default": {m: H for m in METHODS},
        "other": {m: H for m in METHODS if m != "mpm_calculated_16"},
    },
    "full": {
        "default": {**{m: H[:3] for m in METHODS}, "mpm_calculated": H, "mpm_exact_dt_h": H},
        "other": {**{m: H[:3] for m in METHODS if m != "mpm_calculated_16"}, "mpm_exact_dt_h": H,
                  "fem_consistent": H[:2], "fem_lumped": H[:2]},
    },
}
_MPM = ("mpm_calculated", "mpm_exact")
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
    particles and nodes; the profile at T when ``case["profile"]``. ``dt`` is the run's step, the
    largest it took: the last step, which lands on T, can be a round-off sliver (``dt_min``)."""
    if case["solver"] == "fem":
        solution = make_solution(case["solution"], case["eps"])
        r = fem_burgers.solve(solution, case["h"], T=T, mass=case["mass"], cfl=case["cfl"], cfl_visc=case["cfl_visc"])
        profile = {"profile": _rounded(dict(nodes=r.nodes, nodal_velocity=r.v))} if case.get("profile") else {}
        return {"ok": True, "nodes": fem_burgers.errors(r, solution), "steps": r.steps, "dt": r.dt, **profile}
    settings = burgers.BurgersSettings(**{k: v for k, v in case.items() if k not in ("solver", "profile")})
    try:
        r = burgers.simulate(settings, progress=False)
    except (ArithmeticError, ValueError) as err:
        return {"ok": False, "error": str(err)}
    e = burgers.errors(settings, r)["velocity"]
    out = {"ok": True, "particles": e["particles"], "nodes": e["nodes"], "steps": r.steps, "dt": r.dt_max,
           "dt_min": r.dt_min, "n_p": int(r.particles.n), "wall_s": round(r.wall_s, 2)}
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
    return {"solver": solver, "solution": solution, "eps": eps, "h": h, **(FEM if solver == "fem" else MPM), **fixed,
            **changes}


def _cost(case: dict) -> float:
    """~ particles x steps (or nodes x stages x steps), to start the longest runs first."""
    h, eps = case["h"], case["eps"]
    viscous = eps / (h * h * case.get("cfl_visc", case["cfl"]))
    if case["solver"] == "fem":
        return 3.0 * viscous / h * (2.0 if case["mass"] == "consistent" else 1.0)
    steps = 1.0 / (h * case["cfl"]) if case.get("dt_rule") == "advective" else viscous
    return case["ppc"] * steps / h * case.get("refine", 1) * (3.0 if case.get("basis") == "gimp" else 1.0)


def _plan(tier: str) -> dict:
    quick = tier == "quick"
    q = QUICK if quick else {}
    meshes = MESHES["deep" if tier == "deep" else "full"]
    eps_list, skip, time_h = q.get("eps", EPS), q.get("skip", ()), q.get("TIME_H", TIME_H)
    fem = ("fem_consistent", "fem_lumped")
    kept = lambda m, h: m not in skip and not (quick and (h not in q["H"] or (m in q["short"] and h not in q["H"][:2])))  # noqa: E731
    return {
        "table": {(s, m, e, h): method_case(m, s, e, h) for s in q.get("solutions", SOLUTIONS)
                  for m, hs in meshes["default" if s == DEFAULT else "other"].items()
                  for e in eps_list for h in hs if kept(m, h)},
        "profile": {(m, e): {**method_case(m, DEFAULT, e, PROFILE_H), "profile": True}
                    for e in (EPS[0], EPS[-1]) if e in eps_list for m in METHODS if m not in skip},
        "timestep": {(m, e, k): method_case(m, DEFAULT, e, time_h, **({"refine": k} if k > 1 else {}))
                     for e in q.get("time_eps", (EPS[0], EPS[-1]))
                     for m in q.get("time_methods", _MPM + ("mpm_exact_dt_h",)) for k in REFINE},
        "ppc": {(m, h, n): method_case(m, DEFAULT, EPS[0], h, ppc=n) for m in _MPM for h in q.get("PPC_H", PPC_H)
                for n in q.get("PPC", PPC)},
        "lumping": {**{(m, mass, h): method_case(m, DEFAULT, EPS[0], h, mass=mass, cfl=LUMPING_CFL)
                       for h in q.get("lumping_H", H[:3]) for m in _MPM for mass in ("lumped", "consistent")},
                    **{(m, METHODS[m][2]["mass"], h): method_case(m, DEFAULT, EPS[0], h)
                       for h in q.get("lumping_H", H[:3]) for m in fem}},
        "diagnosis": {(label, h): method_case("mpm_calculated", DEFAULT, EPS[0], h, **changes)
                      for h in q.get("diagnosis_H", H[:3]) for label, changes in DIAGNOSIS.items()},
    }


def run(options: StudyOptions) -> None:
    """Every case in one sweep (shared cases run once, the longest first), then tables and figures."""
    got = options.sweep_plan(NAME, run_case, _plan(options.tier), cost=_cost)
    folder = options.folder(NAME)
    settings = {"quick": options.quick, "mpm": MPM, "fem": FEM, "T": T, "domain": [0, 2], "default_solution": DEFAULT,
                "compared_norm": f"{NORM} over {WHERE}",
                "methods": {k: {"label": v[0], "solver": v[1], "settings": v[2], "source_row": v[3]}
                            for k, v in METHODS.items()},
                "time_steps": {
                    "mpm_calculated and mpm_exact": f"dt = CFL min(h/max|v_p|, h^2/(2 eps)), CFL {MPM['cfl']}",
                    "mpm_exact_dt_h": f"dt = CFL h/max|v_p|, CFL {MPM['cfl']} "
                                      "(no viscous limit: no viscous force computed)",
                    "fem": f"dt = min(cfl h/max|v(x,0)|, cfl_visc h^2/(2 eps)), cfl {FEM['cfl']}, "
                           f"cfl_visc {FEM['cfl_visc']}, SSP-RK3"},
                "source_corrections": "exponents of the entries marked * in docs/claims.md moved by one power of ten",
                "time_h": QUICK["TIME_H"] if options.quick else TIME_H, "problem": burgers.BurgersSettings().as_dict()}
    errors, orders = _errors(got)
    tables = {"errors": errors, BURGERS_ORDERS: orders, "norms": _norms(got),
              "timestep": _timestep(got, settings["time_h"]), BURGERS_PPC: _ppc(got), BURGERS_LUMPING: _lumping(got),
              "diagnosis": _diagnosis(got) if got.get("diagnosis") else []}
    extra = {"timestep": {"refine": list(REFINE), "meaning": "time_error = |E(dt) - E(dt/16)|; time_below_space: time "
                          "error < E(dt/16) (the space error)"}, BURGERS_LUMPING.stem: {"mpm_cfl": LUMPING_CFL},
             "diagnosis": {"diagnosis": dict(DIAGNOSIS), "solution": DEFAULT}}
    publish(folder, tables, settings, extra, PLOTS)
    _profiles(folder / "profiles.png", got)


def _value(r: dict, where: str, norm: str) -> float:
    return r[where][norm] if r.get("ok") and where in r else float("nan")


def _norms_of(r: dict, wheres=("particles", "nodes")) -> dict:
    return {f"{w}_{k}": _value(r, w, k) for w in wheres for k in ("L1", "L2", "max")}


def _errors(got: dict) -> tuple[list, list]:
    rows, order_rows, series = [], [], defaultdict(dict)
    key = lambda kv: (SOLUTIONS.index(kv[0][0]), list(METHODS).index(kv[0][1]), -kv[0][2], -kv[0][3])  # noqa: E731
    for (sol, m, eps, h), r in sorted(got["table"].items(), key=key):
        src = source.burgers_value(METHODS[m][3], eps, h)
        row = {"solution": sol, "method": m, "eps": eps, "h": h, **_norms_of(r)}
        row.update({"source": src if src is not None else "",
                    "source_corrected": "yes" if (METHODS[m][3], eps, h) in CORRECTED else "",
                    f"ratio_{WHERE}_{NORM}": row[f"{WHERE}_{NORM}"] / src if src else "",
                    "steps": r.get("steps", ""), "dt": r.get("dt", ""), "particles": r.get("n_p", ""),
                    "error": r.get("error", "")})
        rows.append(row)
        series[(sol, m, eps)][h] = row
    for (sol, m, eps), by_h in series.items():
        hs = sorted(by_h, reverse=True)
        src = [source.burgers_value(METHODS[m][3], eps, h) for h in hs]
        for where in ("particles", "nodes"):
            for norm in ("L1", "L2", "max"):
                v = np.array([by_h[h][f"{where}_{norm}"] for h in hs])
                if len(hs) > 1 and np.all(np.isfinite(v) & (v > 0)):
                    order_rows.append({"solution": sol, "method": m, "eps": eps, "where": where, "norm": norm,
                                       **orders_row(hs, v),
                                       **({"source_fitted": fitted_order(hs, src)} if None not in src else {})})
    return rows, order_rows


def _norms(got: dict) -> list[dict]:
    """For each solution, MPM method, place and norm: median of measured/source and its spread
    (max/min over the common cells of the table), and the spread over eps on the finest common mesh."""
    groups = defaultdict(list)
    for (sol, m, eps, h), r in got["table"].items():
        src = source.burgers_value(METHODS[m][3], eps, h)
        measured = {} if src is None else {tuple(k.split("_")): v for k, v in _norms_of(r).items()}
        for (where, norm), v in measured.items():
            if np.isfinite(v) and v > 0:
                groups[(sol, m, where, norm)].append((eps, h, v, src))
    rows = []
    for (sol, m, where, norm), vals in sorted(groups.items()):
        ratio = np.array([v / s for _, _, v, s in vals])
        finest = min(h for _, h, _, _ in vals)
        fine = [(v, s) for _, h, v, s in vals if h == finest]
        spread = lambda xs, fine=fine: float(max(xs) / min(xs)) if len(fine) > 1 else ""  # noqa: E731
        rows.append({"solution": sol, "method": m, "where": where, "norm": norm, "cells": len(vals),
                     "median_ratio": float(np.median(ratio)), "ratio_spread": float(ratio.max() / ratio.min()),
                     "log10_ratio_rms": float(np.sqrt(np.mean(np.log10(ratio) ** 2))),
                     "eps_spread_finest": spread([v for v, _ in fine]),
                     "source_eps_spread_finest": spread([s for _, s in fine]),
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
        row["time_below_space"] = (("yes" if abs(row[f"{WHERE}_{NORM}"] - ref) < ref else "no")
                                   if k != REFINE[-1] else "")
        rows.append(row)
    return rows


def _ppc(got: dict) -> list[dict]:
    rows = [{"method": m, "eps": EPS[0], "h": h, "ppc": n, **_norms_of(r), "steps": r.get("steps", ""),
             "error": r.get("error", "")}
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
    rows = [{"variant": label, "changes": repr(DIAGNOSIS[label]), "eps": EPS[0], "h": h, **_norms_of(r),
             "error": r.get("error", "")}
            for (label, h), r in got["diagnosis"].items()]
    for label in DIAGNOSIS:
        sub = sorted((r for r in rows if r["variant"] == label), key=lambda r: -r["h"])
        v = np.array([r[f"{WHERE}_L1"] for r in sub])
        if len(sub) > 1 and np.all(np.isfinite(v) & (v > 0)):
            for r, o in zip(sub[1:], observed_orders([r["h"] for r in sub], v), strict=True):
                r["order_L1"] = float(o)
    return rows


STYLE = {"mpm_calculated": ("o-", "tab:blue"), "mpm_calculated_16": ("o--", "tab:purple"),
         "mpm_exact": ("s-", "tab:orange"), "mpm_exact_dt_h": ("D-", "tab:red"),
         "fem_consistent": ("^--", "tab:green"), "fem_lumped": ("v--", "tab:olive")}


def _curves(methods, label="{m}", y=None, group=(), **where) -> tuple[Curve, ...]:
    """A curve per method in its style (``{m}`` in ``label``: its name); ``y`` defaults to the compared
    norm (FEM: over nodes)."""
    return tuple(Curve(label.replace("{m}", METHODS[m][0]), y or f"{'nodes' if m.startswith('fem') else WHERE}_{NORM}",
                       STYLE[m][0], {**where, "method": m}, group=group, options={"color": STYLE[m][1]})
                 for m in methods)


def _beside_source(**where) -> tuple[Curve, ...]:
    sources = (("exact", "ks", "mpm_exact_dt_h"), ("calculated", "ko", "mpm_calculated"))
    return _curves(METHODS, **where) + tuple(Curve(f"source, {row} a", "source", fmt, {**where, "method": m})
                                             for row, fmt, m in sources)


_ERROR = dict(ylabel=f"velocity error ({NORM}; MPM over {WHERE}, FEM over nodes)", slopes=(1, 2))
PLOTS = (
    Plot("convergence.png", f"Burgers, T = {T}: velocity error against h ({DEFAULT} solution), open black: the source",
         "errors", "h", _beside_source(solution=DEFAULT), split=("eps",), size=(4.2, 4.0), **_ERROR),
    Plot("solutions.png", "Every candidate exact solution: velocity error against h", "errors", "h",
         _beside_source(eps=(EPS[0], EPS[-1])), split=("eps", "solution"), ncols=len(SOLUTIONS), size=(4.2, 3.8),
         **_ERROR),
    Plot("ppc.png", f"C3, Burgers: error against N_p ({DEFAULT}, eps = {EPS[0]})", BURGERS_PPC.stem, "ppc",
         _curves(_MPM, "{m}, h = {h}", group=("h",)), xlabel="particles per cell N_p", ylabel=_ERROR["ylabel"]),
    Plot("lumping.png", f"C15: lumped against consistent mass ({DEFAULT}, eps = {EPS[0]}; MPM CFL {LUMPING_CFL})",
         BURGERS_LUMPING.stem, "h", _curves(_MPM + ("fem_consistent", "fem_lumped"), "{m}, {mass}", "L2", ("mass",)),
         **{**_ERROR, "ylabel": "velocity error (L2)"}),
    Plot("timestep.png", f"Time error at fixed h: dt / {', '.join(map(str, REFINE))}", "timestep", "dt",
         _curves(_MPM + ("mpm_exact_dt_h",), "{m}, eps = {eps}", group=("eps",)),
         xlabel="dt (smallest step of the run)", ylabel=_ERROR["ylabel"]),
    Plot("diagnosis.png", f"Why the calculated acceleration stalls ({DEFAULT}, eps = {EPS[0]}): one change at a time",
         "diagnosis", "h", (Curve("{variant}", f"{WHERE}_L1", "o-", group=("variant",)),),
         ylabel=f"velocity error (L1 over {WHERE})", slopes=(1, 2), size=(6.2, 4.6)),
)


def _profiles(path, got) -> None:
    """Velocity and its error at T on the profile mesh, one row per eps: particles (MPM), nodes (FEM)."""
    xe, exact, rows = np.linspace(0, 2, 2001), {}, {}
    for eps in sorted({e for (_, e) in got["profile"]}, reverse=True):
        v, row = make_solution(DEFAULT, eps).v, f"eps = {eps}"
        exact[row] = {"velocity": (xe, v(xe, T)), "error at T": (xe, 0 * xe)}
        rows[row] = [("exact, t = 0", xe, {"velocity": v(xe, 0.0)}, "k:", {"lw": 0.8})]
        for m in (m for m in METHODS if got["profile"].get((m, eps), {}).get("ok")):
            p, mpm = got["profile"][(m, eps)]["profile"], METHODS[m][1] == "mpm"
            x, u = (np.array(p[k]) for k in (("x", "velocity") if mpm else ("nodes", "nodal_velocity")))
            rows[row].append((METHODS[m][0], x, {"velocity": u, "error at T": u - v(x, T)}, "." if mpm else "-",
                              {"ms" if mpm else "lw": 1.5 if mpm else 0.9, "color": STYLE[m][1]}))
    if rows:
        plots.profile_grid(path, exact, rows,
                           f"{DEFAULT} solution at T = {T}, h = {PROFILE_H}: particles (MPM), nodes (FEM)")


if __name__ == "__main__":
    sys.exit(script_main(NAME))
