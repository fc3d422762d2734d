"""E5: which remedy removes the MPM plateau, and what does accuracy cost?

Sod (the Sod study's MPM settings: 16 particles per cell, CFL 0.05, von Neumann-Richtmyer 0.5 /
2.0, USL, lumped mass; density) and viscous Burgers (rarefaction, eps = 0.045, 4 particles per
cell, calculated acceleration; velocity) with each remedy of :mod:`mpm_fem.core.step` alone and in the
combinations that promise most, errors over grid nodes and over particles:

- ``errors.csv``: every problem, remedy and mesh; observed orders against the previous mesh; on
  Sod the finite-volume reference (MUSCL-Hancock + HLLC) on the same mesh and the ratio to it.
- ``orders.csv``: per problem and remedy, the lowest successive and the fitted orders, the errors
  at the finest mesh, on Sod the FV reference's ratios and orders beside, and whether the plateau is
  removed (E5 criterion, :func:`mpm_fem.measure.claims.remedy_assessment`: on Sod judged against the
  FV reference's own orders on the same meshes, on Burgers against the study's converging order).
- ``cost.csv`` / ``cost.png``: Sod density L1 against particle- (or cell-) steps and against wall
  time, for MPM with each remedy, fixed-mesh P1 FEM (lumped mass) and FV. Wall time is the last
  column: it varies from run to run and no verdict uses it.

Meshes: Sod h = 0.01 ... 0.000625 (the convergence study's first five) in the full tier for every
remedy; the deep tier takes plain MPM and the three remedies that removed the plateau to h = 0.0003125
in the record of 2026-11-26 (``FINEST``: the B-spline domain, alone, with Taylor + volume and with
XPIC(5)) to h = 0.00015625, and the others to 0.0003125. E5 counts a remedy as removing the plateau only if
it ran on every Sod mesh of the table, so the remedies that stop earlier count as not removing it. A
halving of h costs about 4x (twice the particles, twice the steps), so a remedy's finest mesh costs
about three times its coarser ones together: what moved to the deep tier to keep the full one
within its budget (the FINEST ones' h = 0.0003125 cost 11 CPU-min, moved on 2026-11-28). Every remedy of
the full and deep tiers runs the fused compiled step (:mod:`mpm_fem.fused.step`, equal to the numpy
step), all of them in its compiled loop (the Taylor reconstruction, XPIC(m) and the grid volume
included); the quick tier runs the numpy step (``QUICK_KERNEL``), which on its two coarse meshes costs
less than compiling the remedies' variants.
What each run cost is in ``cost.csv`` (``wall_s``, measured in the run that wrote it).
Burgers h = 0.04 ... 0.005 (the viscous step limit makes a halving of h cost 8x).

XPIC(m) (:mod:`mpm_fem.core.xpic`) runs alone (m = 2, 5) and with the particle-domain B-spline, on every
mesh of both problems. APIC (:mod:`mpm_fem.core.transfers.apic`) runs its compiled kernels
on the fused step's per-step path (not the many-step loop: about 2.3 times FLIP's loop per run), the C2
cubic B-spline (the basis ``cubic``) in the loop, both on every mesh.

Particle layouts: beside the runs above (Sod 16 per cell, Burgers 4, the regular layout)
plain MPM (the full tier) and every remedy of a point-mass basis (the deep tier; :data:`LAYOUT_REMEDIES`)
run at 4, 8 and 16 per cell on the regular layout and on the Sod study's five jittered ones (seeds
1-5): the full tier on the two coarsest meshes of each problem (Sod 0.01, 0.005; Burgers 0.04, 0.02),
the deep tier on three (:data:`LAYOUT_H`); ``errors.csv`` names each row's ``ppc``,
``layout`` and ``seed`` and takes the orders within one setting; ``orders.csv``, ``cost.csv`` and the
figures hold the study's own setting.

E5's named remedy where the growth is worst (:data:`NAMED`, :data:`NAMED_PPC`, :data:`NAMED_H`): the
B-spline domain + XPIC(5) and plain MPM beside it at 4 and 8 per cell on the five jittered layouts, on the
two coarsest meshes of each problem in the full tier and on every mesh of the study (Sod h = 0.01 ...
0.000625, Burgers 0.04 ... 0.005) in the deep tier; plain MPM's full-tier runs are the layout runs above.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from baselines import fem_euler, fv_euler
from mpm_fem.app.plots import Curve, Plot
from mpm_fem.app.study import StudyOptions, publish, script_main
from mpm_fem.bases import OutsideGridError
from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.particles import PositivityError
from mpm_fem.measure.claims import PLATEAU_CRITERION, remedy_assessment, successive_orders
from mpm_fem.measure.errors import norms
from mpm_fem.measure.schema import REMEDIES_ERRORS
from mpm_fem.measure.shock_tube import exact_density
from mpm_fem.problems import burgers, sod
from studies.sod import FEM, FV, H
from studies.sod import MPM as SOD_MPM

NAME = "remedies"
SOD_H = H[:7]  # 0.01 ... 0.00015625; each remedy runs the first SOD_MESHES[name] of them (docstring)
BURGERS_H = (0.04, 0.02, 0.01, 0.005)
BURGERS = dict(solution="rarefaction", eps=0.045, ppc=4, acceleration="calculated")
REMEDIES = {
    "MPM": {},
    "B-spline domain": {"basis": "bspline_gimp"},
    "Taylor LS": {"reconstruct": "taylor"},
    "grid volume": {"volume": "grid"},
    "FLIP 0.99": {"flip": 0.99},
    "Taylor + volume": {"reconstruct": "taylor", "volume": "grid"},
    "B-spline domain + Taylor + volume": {"basis": "bspline_gimp", "reconstruct": "taylor", "volume": "grid"},
    "XPIC(2)": {"xpic": 2},
    "XPIC(5)": {"xpic": 5},
    "B-spline domain + XPIC(2)": {"basis": "bspline_gimp", "xpic": 2},
    "B-spline domain + XPIC(5)": {"basis": "bspline_gimp", "xpic": 5},
    "cubic B-spline": {"basis": "cubic"},
    "APIC": {"transfer": "apic"},
}
FINEST = ("MPM", "B-spline domain", "B-spline domain + Taylor + volume", "B-spline domain + XPIC(5)")
#: the full tier's Sod meshes per remedy (docstring)
SOD_MESHES = {name: 5 for name in REMEDIES}
DEEP_SOD_MESHES = {name: 7 if name in FINEST else 6 for name in REMEDIES}
QUICK = dict(SOD_H=(0.02, 0.01), BURGERS_H=BURGERS_H[:2],
             REMEDIES=("MPM", "Taylor LS", "grid volume", "FLIP 0.99", "Taylor + volume", "XPIC(5)"))
#: the quick tier's step: compiling its six remedies' variants costs more than its numpy runs (docstring)
QUICK_KERNEL = {"kernel": "numpy"}


# ---------------------------------------------------------------- one case (runs in a worker)

def run_case(case: dict) -> dict:
    """``case["solver"]``: ``"sod"`` / ``"burgers"`` (MPM with the remedy's settings), ``"fem"`` or
    ``"fv"`` (Sod baselines). Errors, steps, work (particle- or cell-steps) and wall time."""
    start = time.perf_counter()
    solver, h = case["solver"], case["h"]
    if solver in ("fem", "fv"):
        if solver == "fem":
            r = fem_euler.solve(h, mass="lumped", cfl=FEM["cfl"], viscosity=fem_euler.Viscosity(
                FEM["viscosity_linear"], FEM["viscosity_quadratic"], FEM["compression_only"]))
            x, w = r.nodes, uniform_grid(0.0, 1.0, h).lumped_mass
        else:
            r = fv_euler.solve(h, cfl=FV["cfl"], limiter=FV["limiter"])
            x, w = r.centres, np.full(r.centres.size, h)
        e = norms(r.rho - exact_density(x, r.t), w)
        return {"ok": True, "nodes": e, "steps": r.steps, "work": r.steps * x.size,
                "wall_s": time.perf_counter() - start}
    changes = {k: v for k, v in case.items() if k not in ("solver", "h")}
    try:
        if solver == "sod":
            settings = sod.SodSettings(h=h, **changes)
            result = sod.simulate(settings, progress=False)
            e = sod.errors(settings, result)["density"]
        else:
            settings = burgers.BurgersSettings(h=h, **changes)
            result = burgers.simulate(settings, progress=False)
            e = burgers.errors(settings, result)["velocity"]
    except (PositivityError, FloatingPointError, OutsideGridError) as err:  # a particle out: the basis's walls
        return {"ok": False, "error": str(err)}
    n = int(result.particles.n)
    return {"ok": True, "nodes": e["nodes"], "particles": e["particles"], "steps": result.steps, "n_p": n,
            "work": result.steps * n,
            "volume_drift": float(result.particles.volume.sum() - 1.0) if solver == "sod" else "",
            "wall_s": time.perf_counter() - start}


#: E5 over the particle layouts: every remedy at these particles per cell, on the regular layout and
#: the Sod study's jittered ones (``studies.sod.SEEDS``; seed 0 the regular layout)
LAYOUT_PPC = (4, 8, 16)
SEEDS = (1, 2, 3, 4, 5)
LAYOUTS = (("regular", 0),) + tuple(("jittered", s) for s in SEEDS)
#: per tier, the meshes of the layout runs ``{problem: meshes}``: the full tier the two coarsest of each problem
#: (every remedy there costs about 2 CPU-min in all), the deep tier one mesh more; the quick tier plain MPM at the
#: study's particles per cell (``QUICK_LAYOUT``) on its two meshes
LAYOUT_H = {"quick": {"sod": QUICK["SOD_H"], "burgers": QUICK["BURGERS_H"]},
            "full": {"sod": SOD_H[:2], "burgers": BURGERS_H[:2]},
            "deep": {"sod": SOD_H[:3], "burgers": BURGERS_H[:3]}}
QUICK_LAYOUT = {"remedies": ("MPM",), "ppc": {"sod": (SOD_MPM["ppc"],), "burgers": (BURGERS["ppc"],)}}
#: the remedies of the layout runs per tier beyond quick: the full tier plain MPM only, the deep tier every
#: remedy of the P1 hats. A particle-domain B-spline run on a jittered Sod layout stopped with a particle 2e-7
#: beyond the right wall (``OutsideGridError``, recorded as a failed run), and the splines with ghosts folded into
#: the end nodes (the B-spline, the cubic) let a particle at a wall move out (E2's jittered B-spline runs, the
#: cubic on the regular layout); until their walls are fixed those runs stay out of the plan.
LAYOUT_REMEDIES = {"full": ("MPM",),
                   "deep": tuple(n for n, r in REMEDIES.items() if r.get("basis") not in ("bspline_gimp", "cubic"))}


#: E5's named remedy on the jittered layouts (module docstring): the remedies, particles per cell and meshes per tier
NAMED = ("B-spline domain + XPIC(5)", "MPM")
NAMED_PPC = (4, 8)
NAMED_H = {"quick": {}, "full": {"sod": SOD_H[:2], "burgers": BURGERS_H[:2]},
           "deep": {"sod": SOD_H[:5], "burgers": BURGERS_H}}


def _layout_case(problem: str, h: float, name: str, ppc: int, layout: str, seed: int, kernel: dict) -> dict:
    """The case of a remedy at a particle setting: the study's own case at its particles per cell on the regular
    layout (Burgers' names no layout then, as the study's own case)."""
    if problem == "sod":
        return {"solver": "sod", "h": h, **SOD_MPM, "ppc": ppc, "layout": layout, "seed": seed, **REMEDIES[name],
                **kernel}
    jitter = {"layout": layout, "seed": seed} if seed else {}
    return {"solver": "burgers", "h": h, **BURGERS, "ppc": ppc, **jitter, **REMEDIES[name], **kernel}


def _plan(tier: str) -> dict:
    quick = tier == "quick"
    q = QUICK if quick else {}
    names = q.get("REMEDIES", tuple(REMEDIES))
    sod_h, burgers_h = q.get("SOD_H", SOD_H), q.get("BURGERS_H", BURGERS_H)
    meshes, kernel = DEEP_SOD_MESHES if tier == "deep" else SOD_MESHES, QUICK_KERNEL if quick else {}
    sod_h = sod_h[:max(meshes[n] for n in names)]
    layout_names = QUICK_LAYOUT["remedies"] if quick else LAYOUT_REMEDIES[tier]
    return {
        "sod": {(n, h): {"solver": "sod", "h": h, **SOD_MPM, **REMEDIES[n], **kernel}
                for n in names for h in sod_h[:meshes[n]]},
        "burgers": {(n, h): {"solver": "burgers", "h": h, **BURGERS, **REMEDIES[n], **kernel}
                    for n in names for h in burgers_h},
        "fem": {h: {"solver": "fem", "h": h} for h in sod_h},
        "fv": {h: {"solver": "fv", "h": h} for h in sod_h},
        **{f"{problem}_layouts": {(n, h, ppc, lay, s): _layout_case(problem, h, n, ppc, lay, s, kernel)
                                  for n in layout_names for h in hs
                                  for ppc in (QUICK_LAYOUT["ppc"][problem] if quick else LAYOUT_PPC)
                                  for lay, s in LAYOUTS}
           for problem, hs in LAYOUT_H[tier].items()},
        **{f"{problem}_named": {(n, h, ppc, "jittered", s): _layout_case(problem, h, n, ppc, "jittered", s, kernel)
                                for n in NAMED for h in hs for ppc in NAMED_PPC for s in SEEDS}
           for problem, hs in NAMED_H[tier].items()},
    }


#: the seconds every case costs beyond its particle-steps (the worker's call, the cache), in units of :func:`_cost`
CASE_OVERHEAD = 2e6


def _cost(case: dict) -> float:
    """Rough work, to start the longest runs first."""
    h = case["h"]
    if case["solver"] in ("fem", "fv"):
        return 1.0 / h**2
    slow = ({"bspline_gimp": 4.0, "cubic": 1.3}.get(case.get("basis"), 1.0) * (1.0 + 0.3 * case.get("xpic", 0))
            * (2.5 if case.get("transfer") == "apic" else 1.0))  # APIC: the per-step path
    if case["solver"] == "burgers":
        return CASE_OVERHEAD + slow * case["ppc"] * 0.09 / h**3
    return CASE_OVERHEAD + slow * case["ppc"] / (h**2 * case["cfl"])


# ---------------------------------------------------------------- the study

def run(options: StudyOptions) -> None:
    got = options.sweep_plan(NAME, run_case, _plan(options.tier), cost=_cost)
    folder = options.folder(NAME)
    settings = {"sod": SOD_MPM, "burgers": BURGERS, "remedies": REMEDIES, "fem": {"mass": "lumped", **FEM},
                "fv": FV,
                "criterion": PLATEAU_CRITERION, "quick": options.quick,
                "named_layouts": {"remedies": list(NAMED), "ppc": list(NAMED_PPC), "layout": "jittered",
                                  "seeds": list(SEEDS), "h": {p: list(hs) for p, hs in NAMED_H[options.tier].items()}}}
    rows, cost = _errors(got), _cost_rows(got)
    publish(folder, {REMEDIES_ERRORS: rows, "orders": _summary(rows), "cost": cost}, settings, figures=PLOTS)
    _cost_figure(folder, cost)


def _l(result, where, norm):
    return result[where][norm] if result.get("ok") and where in result else float("nan")


def _study_setting(problem: str) -> tuple:
    """``(ppc, layout, seed)`` of the study's own runs of ``problem``."""
    return ((SOD_MPM if problem == "sod" else BURGERS)["ppc"], "regular", 0)


def _series(got, problem: str) -> dict:
    """``{(remedy, ppc, layout, seed): {h: result}}``: the study's own runs first, then the layout runs."""
    out = {}
    for (name, h), r in got[problem].items():
        out.setdefault((name, *_study_setting(problem)), {})[h] = r
    for group in (f"{problem}_layouts", f"{problem}_named"):
        for (name, h, *setting), r in got.get(group, {}).items():
            out.setdefault((name, *setting), {}).setdefault(h, r)
    return out


def _errors(got) -> list[dict]:
    """``errors.csv``: one row per problem, remedy, particle setting (``ppc``, ``layout``, ``seed``) and mesh, the
    orders against the next coarser mesh of the same remedy and setting."""
    rows = []
    for problem in ("sod", "burgers"):
        for (name, ppc, layout, seed), by_h in _series(got, problem).items():
            series = []
            for h in sorted(by_h, reverse=True):
                r = by_h[h]
                row = {"problem": problem, "remedy": name, "ppc": ppc, "layout": layout, "seed": seed, "h": h,
                       "quantity": "density" if problem == "sod" else "velocity"}
                for where in ("nodes", "particles"):
                    for norm in ("L1", "L2"):
                        row[f"{where}_{norm}"] = _l(r, where, norm)
                fv = _l(got["fv"][h], "nodes", "L1") if problem == "sod" else ""
                row.update(fv_L1=fv, ratio_fv_nodes_L1=row["nodes_L1"] / fv if fv else "",
                           ratio_fv_particles_L1=row["particles_L1"] / fv if fv else "",
                           steps=r.get("steps", ""), n_p=r.get("n_p", ""), volume_drift=r.get("volume_drift", ""),
                           error=r.get("error", ""))
                series.append(row)
            for m in ("nodes_L1", "particles_L1"):
                o = successive_orders(series, m)
                for k, row in enumerate(series):
                    row[f"order_{m}"] = float(o[k - 1]) if k else ""
            rows += series
    return rows


def _is_study_setting(row: dict) -> bool:
    return (row["ppc"], row["layout"], row["seed"]) == _study_setting(row["problem"])


def _summary(rows) -> list[dict]:
    """``orders.csv``: per problem and remedy, at the study's own particle setting."""
    rows = [r for r in rows if _is_study_setting(r)]
    out = []
    for problem in ("sod", "burgers"):
        finest = min((r["h"] for r in rows if r["problem"] == problem), default=None)
        for name in dict.fromkeys(r["remedy"] for r in rows if r["problem"] == problem):
            series = [r for r in rows if r["problem"] == problem and r["remedy"] == name]
            if len(series) < 2:
                continue
            s, last = remedy_assessment(series), series[-1]
            verdict = "not run on every mesh" if last["h"] != finest else "yes" if s["removes_plateau"] else "no"
            out.append({"problem": problem, "remedy": name, "h_finest": last["h"],
                        "finest_nodes_L1": last["nodes_L1"], "finest_particles_L1": last["particles_L1"],
                        **{k: s[k] for k in s if not (problem == "burgers" and "fv" in k)},
                        "removes_plateau": verdict})
    return out


def _cost_rows(got) -> list[dict]:
    rows = []
    for (name, h), r in got["sod"].items():
        rows.append({"method": "MPM" if name == "MPM" else f"MPM + {name}", "h": h, "density_L1": _l(r, "nodes", "L1"),
                     "particles_L1": _l(r, "particles", "L1"), "work": r.get("work", ""), "steps": r.get("steps", ""),
                     "wall_s": round(r.get("wall_s", float("nan")), 2)})
    for method, label in (("fem", "FEM P1 lumped"), ("fv", fv_euler.label(FV["limiter"]))):
        for h, r in got[method].items():
            rows.append({"method": label, "h": h, "density_L1": _l(r, "nodes", "L1"), "particles_L1": "",
                         "work": r["work"], "steps": r["steps"], "wall_s": round(r["wall_s"], 2)})
    return rows


_SOD = {"problem": "sod", "ppc": SOD_MPM["ppc"], "seed": 0}
_FV, _BURGERS = {**_SOD, "remedy": "MPM"}, {"problem": "burgers", "ppc": BURGERS["ppc"], "seed": 0}
PLOTS = (
    Plot("errors.png", "E5: L1 error against h for each remedy; Sod density with the FV reference, Burgers velocity",
         REMEDIES_ERRORS.stem, "h", (
             Curve("{remedy}", "nodes_L1", where=_SOD, panel="Sod density, grid nodes", group=("remedy",)),
             Curve("FV reference", "fv_L1", "k--", where=_FV, panel="Sod density, grid nodes"),
             Curve("{remedy}", "particles_L1", where=_SOD, panel="Sod density, particles", group=("remedy",)),
             Curve("FV reference", "fv_L1", "k--", where=_FV, panel="Sod density, particles"),
             Curve("{remedy}", "particles_L1", where=_BURGERS, panel="Burgers velocity, particles",
                   group=("remedy",))),
         ylabel="L1 error", size=(4.6, 3.8), ncols=3),
)


def _cost_figure(folder: Path, cost) -> None:
    """Sod density L1 against work and against wall time, one line per method (``cost.png``)."""
    import matplotlib.pyplot as plt

    from mpm_fem.app import plots

    fig, axes = plt.subplots(1, 2, figsize=(13, 5.2))
    for method in dict.fromkeys(r["method"] for r in cost):
        s = sorted((r for r in cost if r["method"] == method), key=lambda r: -r["h"])
        style = "k*--" if method.startswith("FV") else "ks:" if method.startswith("FEM") else "o-"
        for ax, x in zip(axes, ("work", "wall_s"), strict=True):
            ax.loglog([r[x] for r in s], [r["density_L1"] for r in s], style, ms=3, label=method)
    axes[0].set(xlabel="particle-steps (MPM) or node/cell-steps", ylabel="Sod density L1 (nodes / cells)")
    axes[1].set(xlabel="wall time [s] (one run, shared machine)", ylabel="Sod density L1 (nodes / cells)")
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="center right", fontsize=7)
    fig.tight_layout(rect=(0, 0, 0.78, 1))
    plots.save(fig, folder / "cost.png", caption="E5: Sod density L1 against work and against wall time, one point "
               "per mesh, for MPM with each remedy, fixed-mesh FEM and the FV reference")


#: The cost model of :mod:`mpm_fem.app.estimate`: CPU seconds per unit of :func:`_cost`, from the full
#: tier's cases on the 2-core machine (2026-11-26, from-scratch run: CHANGES.md).
PLAN, COST, SECONDS_PER_COST = _plan, _cost, 1.0e-8

if __name__ == "__main__":
    sys.exit(script_main(NAME))
