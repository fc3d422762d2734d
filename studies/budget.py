"""Where the MPM error comes from: the error budget over every combination of the stages (E1), and
the bases (E2).

Sod's tube (16 particles per cell, CFL 0.05, von Neumann-Richtmyer viscosity 0.5 / 2.0,
USL, lumped mass) and viscous Burgers (the rarefaction, eps = 0.045, 4 particles per cell, CFL
0.5, calculated acceleration) are run for each mesh and basis (point-mass P1 "mpm", GIMP, the C1
quadratic B-spline "bspline", and E5's closest remedy, the B-spline averaged over the particle
domain "bspline_gimp", whose exact stages use the same quadratic B-splines) with every subset ``S`` of
the four stages {projection, mass
(FE + mass lumping), interpolation, time} in MPM form and the others in their exact form
(:mod:`mpm_fem.exact_stages.stage`). The error field ``e_S(x)`` is the piecewise-linear field through
the particle values (Sod density, Burgers velocity) minus the exact solution, on fixed points
(Burgers: 5% margins off each end, where the inflow reservoir acts); for Sod also the nodal
density error ``e_i``. *Time exact* is the dt -> 0 Richardson extrapolation of the runs at the
step ``dt`` and ``dt / K`` (``K = 2``, every step divided), point by point, the time error
being first order in dt (C1):

    e_{S without time} = (K e_{S, dt/K} - e_{S, dt}) / (K - 1),     e_{S with time} = e_{S, dt},

so eight runs at dt and eight at dt/K make all sixteen subsets. ``v(S)`` is the L1 norm of
``e_S`` (particles: trapezoid rule over the points; nodes: weights ``int S_i dx``). Its Moebius
terms and Shapley values (:mod:`mpm_fem.measure.decomposition`) decompose ``v(all MPM) - v(all exact)``
exactly; applied to the fields they give each stage's signed error field, which adds up to
``e_MPM - e_exact`` at every point.

Meshes: Sod h = 0.01 ... 0.0025 for every basis (three meshes give each basis's budget a trend, not
only a change; :data:`FINEST`), the deep tier adds h = 0.00125 for every basis and P1 at h = 0.000625
(:data:`DEEP`); Burgers 0.04 ... 0.01. A Sod case is 16 runs, all on the fused step (:mod:`mpm_fem.fused`):
the fourteen with an exact stage run its compiled particle passes around the numpy step's grid stage
(:mod:`mpm_fem.exact_stages`). What each run cost is in ``runs.csv`` (``wall_s``); the measured costs,
and why the tiers stop where they do, are in ``docs/performance.md``.
Round-off: the subsets with the exact mass stage and the MPM projection (``v_i = v*_i + solve(MPM) -
solve(exact)``) amplify it; ``roundoff.csv`` measures the spread: P1's Sod budget runs a second time on
the numpy step (the reference arithmetic), each Shapley share given from both in percentage points.
E2: Sod, each basis in MPM form (the fused step), h = 0.01 ... 0.0003125.

Particle layouts: the budget and E2 above run the study's own particles (Sod 16 per cell,
Burgers 4, the regular layout); beside them both run at 4, 8 and 16 per cell on the regular layout
and on the Sod study's five jittered ones (seeds 1-5), every row of the tables naming its ``ppc``,
``layout`` and ``seed``: the full tier P1's budget on the two coarsest meshes of each problem (Sod
0.01, 0.005; Burgers 0.04, 0.02) and E2's four bases (P1, GIMP, the B-spline, the cubic B-spline) on
h = 0.01 ... 0.0025; the deep tier adds the other three budget bases' budgets on those meshes, P1's
on Sod h = 0.0025 and Burgers h = 0.01, and E2's on h = 0.00125 and 0.000625 (:data:`LAYOUT_H`,
:data:`BASES_LAYOUT_H`; the cost model: :data:`BUDGET_STEP_MS`).

``readout.csv``: the nodal read-out's own error on Sod (:mod:`mpm_fem.measure.readout`: the exact density
at the exact particle positions, read out as the study reads the nodes) beside v(all exact) of the nodal norm.

E1's control (:func:`control_case`, ``control.csv`` and ``control_runs.csv``): the same budget on a problem
without node crossings, the neo-Hookean bar of the 1D control at amplitude 1e-4 (P1, lumped mass, FLIP,
cfl 0.25, one period; :mod:`mpm_fem.measure.control`, :mod:`mpm_fem.run.bar_stages`), on h = 1/8, 1/16,
1/32 at 4 and 8 per cell on the regular layout and the five jittered ones (full and deep tiers; the quick
tier runs none). Its cases run through their own case function in a second sweep, so that the cached
budget cases keep their key; their cost is not in the study's estimate.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from baselines.exact import riemann
from mpm_fem.app.plots import Curve, Plot, grid_shape, plt, save
from mpm_fem.app.study import StudyOptions, publish, script_main
from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.particles import PositivityError
from mpm_fem.measure import schema
from mpm_fem.measure.decomposition import decompose, label, share_changes, subsets
from mpm_fem.measure.regions import REGION_NAMES, l1_by_region, plateau_velocity, sod_regions
from mpm_fem.measure.timing import field_on
from mpm_fem.problems import burgers, sod
from mpm_fem.run.bar_stages import ControlSettings

NAME = "budget"
BASES = ("mpm", "gimp", "bspline", "cubic")  # E2's bases
#: the budget's bases: P1, GIMP, the C1 B-spline and the closest remedy of E5, the B-spline averaged over the
#: particle domain (the cubic B-spline, in E2, has no budget: its cost is in docs/performance.md)
BUDGET_BASES = ("mpm", "gimp", "bspline", "bspline_gimp")
STAGES = ("projection", "mass", "interpolation", "time")
EXACT_FORM = {"projection": {"projection": "exact"}, "mass": {"mass": "exact"},
              "interpolation": {"interpolation": "exact"}}
K = 2  # time exact: dt -> 0 from dt and dt / K
#: what a case may change of the study's settings: the step (``roundoff.csv``), the particles (E1, E2 over layouts)
CASE_SETTINGS = ("kernel", "ppc", "layout", "seed")
SOD = dict(ppc=16, cfl=0.05, av_linear=0.5, av_quadratic=2.0, mass="lumped", scheme="usl", layout="regular", seed=0)
BURGERS = dict(solution="rarefaction", eps=0.045, ppc=4, cfl=0.5, acceleration="calculated", mass="lumped",
               scheme="usl", layout="regular", seed=0)
H = {"sod": (0.01, 0.005, 0.0025, 0.00125), "burgers": (0.04, 0.02, 0.01)}
#: the deep tier's further budgets, (problem, h, basis): every basis on Sod's finest mesh of H, P1 one mesh finer
DEEP = (("sod", 0.00125, "mpm"), ("sod", 0.000625, "mpm"), ("sod", 0.00125, "gimp"), ("sod", 0.00125, "bspline"),
        ("sod", 0.00125, "bspline_gimp"))
#: (problem, basis): the full tier's finest budget mesh where it stops above H's finest (docs/performance.md)
FINEST = {("sod", b): 0.0025 for b in ("mpm", "gimp", "bspline", "bspline_gimp")}
BASES_H = (0.01, 0.005, 0.0025, 0.00125, 0.000625, 0.0003125)  # E2: Sod with each basis, MPM stages only (fused)
REGION_HALF_WIDTH = 0.02  # C12's regions (the Sod study)
FIELD_POINTS = 2001  # the Shapley fields kept for the figure
#: the quick tier: P1 on one coarse mesh a problem (E1 is judged on the finest mesh of each basis)
QUICK = {"h": {"sod": (0.02,), "burgers": (0.04,)}, "bases": ("mpm",), "bases_h": ()}
GAP = "all MPM - all exact"
#: (problem, basis) whose budget also runs on the numpy step (``roundoff.csv``, module docstring): the full tier
#: on the meshes of ROUNDOFF_H, the deep tier on every mesh, the quick tier on none (docs/performance.md)
ROUNDOFF, ROUNDOFF_H = ("sod", "mpm"), H["sod"][:2]
COLORS = {"projection": "tab:blue", "mass": "tab:orange", "interpolation": "tab:green", "time": "tab:red"}


# ---------------------------------------------------------------- the plan

#: E1 and E2 over the particle layouts: particles per cell, and the Sod study's jittered layouts
#: (``studies.sod.SEEDS``) beside the regular one (seed 0), every particle count with every layout
LAYOUT_PPC = (4, 8, 16)
SEEDS = (1, 2, 3, 4, 5)
LAYOUTS = (("regular", 0),) + tuple(("jittered", s) for s in SEEDS)
#: per tier, ``{(problem, basis): meshes}`` of the budgets run at every LAYOUT_PPC and layout: the full tier P1 on
#: the two coarsest meshes of each problem, the deep tier the other bases on those meshes and P1's on the next finer
#: one, the quick tier none (the costs that set this: docs/performance.md)
LAYOUT_H = {"quick": {},
            "full": {("sod", "mpm"): H["sod"][:2], ("burgers", "mpm"): H["burgers"][:2]},
            "deep": {**{("sod", b): H["sod"][:2] for b in BUDGET_BASES}, ("sod", "mpm"): H["sod"][:3],
                     **{("burgers", b): H["burgers"][:2] for b in BUDGET_BASES}, ("burgers", "mpm"): H["burgers"]}}
#: per tier, the meshes of E2's bases run at every LAYOUT_PPC and layout (the full tier: the three coarsest, two
#: refinements; the deep tier two more)
BASES_LAYOUT_H = {"quick": (), "full": BASES_H[:3], "deep": BASES_H[:5]}


def _layout_changes(problem: str, ppc: int, layout: str, seed: int) -> dict:
    """The settings a budget case adds to the study's own (:data:`SOD`, :data:`BURGERS`): none for the
    study's particle count on the regular layout, so that the study's case is the same case."""
    default = SOD if problem == "sod" else BURGERS
    return {**({"ppc": ppc} if ppc != default["ppc"] else {}), **({"layout": layout, "seed": seed} if seed else {})}


def setting_of(problem: str, case: dict) -> dict:
    """``{ppc, layout, seed}`` of a case (the study's own where the case names none)."""
    default = SOD if problem == "sod" else BURGERS
    return {k: case.get(k, default[k]) for k in ("ppc", "layout", "seed")}


def plan(tier: str) -> dict:
    quick = tier == "quick"
    hs, bases = (QUICK["h"], QUICK["bases"]) if quick else (H, BUDGET_BASES)
    keys = [(p, h, b) for p, meshes in hs.items() for h in meshes for b in bases if h >= FINEST.get((p, b), 0)]
    keys += [k for k in DEEP if k not in keys] if tier == "deep" else []
    budget = {(p, h, b): {"kind": "budget", "problem": p, "h": h, "basis": b, "K": K} for p, h, b in keys}
    e2 = {(h, b): {"kind": "bases", "h": h, "basis": b}
          for h in (QUICK["bases_h"] if quick else BASES_H) for b in BASES}
    roundoff = {(p, h, b): {**case, "kernel": "numpy"} for (p, h, b), case in budget.items()
                if (p, b) == ROUNDOFF and not quick and (tier == "deep" or h in ROUNDOFF_H)}
    layouts = {(p, h, b, n, lay, s): {"kind": "budget", "problem": p, "h": h, "basis": b, "K": K,
                                       **_layout_changes(p, n, lay, s)}
               for (p, b), meshes in LAYOUT_H[tier].items() for h in meshes
               for n in LAYOUT_PPC for lay, s in LAYOUTS}
    bases_layouts = {(h, b, n, lay, s): {"kind": "bases", "h": h, "basis": b, **_layout_changes("sod", n, lay, s)}
                     for h in BASES_LAYOUT_H[tier] for b in BASES for n in LAYOUT_PPC for lay, s in LAYOUTS}
    return {"budget": budget, "bases": e2, "roundoff": roundoff, "layouts": layouts, "bases_layouts": bases_layouts}


#: E1's control (module docstring): its meshes, particles per cell and layouts per tier, and its settings
CONTROL_H = {"quick": (), "full": (1 / 8, 1 / 16, 1 / 32), "deep": (1 / 8, 1 / 16, 1 / 32)}
CONTROL_PPC = (4, 8)
CONTROL = dict(amplitude=1e-4, cfl=0.25, K=2)


def control_plan(tier: str) -> dict:
    """``{(h, ppc, layout, seed): case}`` of the control at ``tier``."""
    return {(h, n, lay, s): {"kind": "control", "h": h, "ppc": n, "layout": lay, "seed": s, **CONTROL}
            for h in CONTROL_H[tier] for n in CONTROL_PPC for lay, s in LAYOUTS}


def control_case(case: dict) -> dict:
    """One control run's budget (:func:`mpm_fem.measure.control.control_budget`) and its wall time."""
    import time

    from mpm_fem.measure.control import control_budget

    start = time.perf_counter()
    settings = ControlSettings(h=case["h"], ppc=case["ppc"], layout=case["layout"], seed=case["seed"],
                               amplitude=case["amplitude"], cfl=case["cfl"])
    return {"ok": True, **control_budget(settings, case["K"]), "wall_s": time.perf_counter() - start}


def control_rows(got: dict) -> tuple[list[dict], list[dict]]:
    """``control.csv`` (v(S) per run and subset, the columns of ``subsets.csv``) and ``control_runs.csv``."""
    subsets_, runs_ = [], []
    for (h, n, lay, s), r in got.items():
        key = {"problem": "bar", "h": h, "basis": "mpm", "ppc": n, "layout": lay, "seed": s}
        subsets_ += [{**key, "norm": "particles", "mpm_stages": S, "error": v} for S, v in r["subsets"].items()]
        runs_.append({**key, **{k: r[k] for k in ("interactions", "field_interactions", "readout",
                                                 "readout_relative", "wall_s")}})
    return subsets_, runs_


def readout_rows(got: dict) -> list[dict]:
    """``readout.csv``: per Sod budget of P1 (every particle setting), the nodal read-out's own error
    (:func:`mpm_fem.measure.readout.sod_readout`: exact density, exact particle positions) beside v(all exact)
    and v(all MPM) of the nodal norm; a few CPU-s in all, computed here, not cached."""
    from mpm_fem.measure.readout import sod_readout

    rows = []
    for (p, h, b, *setting), r in ((k if len(k) == 6 else _full_key(k), r) for k, r in got.items()):
        if p != "sod" or b != "mpm" or "nodes" not in r["subsets"]:
            continue
        n, lay, seed = setting
        v = r["subsets"]["nodes"]
        rows.append({"problem": p, "h": h, "basis": b, "ppc": n, "layout": lay, "seed": seed,
                     "readout_L1": sod_readout(h, n, lay, seed, b), "all_exact_L1": v["none"],
                     "all_mpm_L1": v[label(STAGES)]})
    return rows


#: CPU milliseconds per step of a budget run, ``a + b N`` for ``N`` particles, per (problem, basis): a least-squares
#: fit to the full tier's runs (``runs.csv`` of 2026-11-26, 2-core machine); the ``a`` of Sod is the numpy grid stage
#: of the exact-stage runs, of Burgers the numpy step
BUDGET_STEP_MS = {("sod", "mpm"): (0.29, 7.9e-5), ("sod", "gimp"): (0.06, 1.8e-4), ("sod", "bspline"): (0.16, 2.0e-4),
                  ("sod", "bspline_gimp"): (0.08, 2.1e-4), ("burgers", "mpm"): (0.53, 1.9e-3),
                  ("burgers", "gimp"): (0.74, 3.1e-3), ("burgers", "bspline"): (0.68, 2.7e-3),
                  ("burgers", "bspline_gimp"): (0.89, 2.9e-3)}
#: the same for E2's runs (MPM stages only, the fused step: ``bases.csv`` of 2026-11-26)
BASES_STEP_MS = {"mpm": (0.016, 3.9e-5), "gimp": (0.016, 6.8e-5), "bspline": (0.016, 5.8e-5),
                 "cubic": (0.016, 7.5e-5)}  # cubic: 1.3x the B-spline's per particle (its first runs, 2026-11-28)
NUMPY_STEP_COST = 1.7  # a roundoff.csv case (the numpy step) against the same case fused


def _steps(problem: str, h: float) -> float:
    """Steps of one run at dt: Sod's CFL step (943 at h = 0.01), Burgers' viscous one (dt = CFL h^2 / (2 eps))."""
    return 9.5 / h if problem == "sod" else burgers.BurgersSettings.T * 2 * BURGERS["eps"] / (BURGERS["cfl"] * h**2)


def cost(case: dict) -> float:
    """Estimated CPU milliseconds of a case, from the measured cost per step (:data:`BUDGET_STEP_MS`,
    :data:`BASES_STEP_MS`): 24 steps' worth per step at dt for a budget (its 16 runs, half of them at dt / K)."""
    problem = "sod" if case["kind"] == "bases" else case["problem"]
    n = case.get("ppc", (SOD if problem == "sod" else BURGERS)["ppc"]) / case["h"]
    if case["kind"] == "bases":
        a, b = BASES_STEP_MS[case["basis"]]
        return _steps("sod", case["h"]) * (a + b * n)
    a, b = BUDGET_STEP_MS[(problem, case["basis"])]
    numpy = NUMPY_STEP_COST if case.get("kernel") == "numpy" else 1.0
    return 24 * _steps(problem, case["h"]) * (a + b * n) * numpy


# ---------------------------------------------------------------- one case

def _settings(problem: str, h: float, basis: str, changes: dict):
    kind, default = (sod.SodSettings, SOD) if problem == "sod" else (burgers.BurgersSettings, BURGERS)
    return kind(h=h, basis=basis, **{**default, **changes})


def _run(problem: str, settings, points: np.ndarray) -> tuple[dict, dict]:
    """One run: its row, and its error fields (particle field on ``points``; Sod: nodal error)."""
    try:
        result = (sod if problem == "sod" else burgers).simulate(settings, progress=False)
    except (PositivityError, FloatingPointError, ValueError) as err:
        return {"ok": False, "error": str(err)}, {}
    P, nodes = result.particles, result.grid.nodes
    if problem == "sod":
        fields = {"particles": field_on(points, P.x, P.density) - sod.exact(settings, points, result.t)[0],
                  "nodes": result.nodal_density - sod.exact(settings, nodes, result.t)[0]}
        extra = plateau_velocity(P.x, P.velocity, _sod_waves(), 3 * settings.h)  # the study's T and states
    else:
        fields, extra = {"particles": field_on(points, P.x, P.velocity) - settings.exact.v(points, result.t)}, {}
    errors = (sod if problem == "sod" else burgers).errors(settings, result)[
        "density" if problem == "sod" else "velocity"]
    return {"ok": True, "steps": result.steps, "wall_s": result.wall_s, "particles_L1": errors["particles"]["L1"],
            "nodes_L1": errors["nodes"]["L1"], **extra}, fields


def norm_points(problem: str, settings) -> tuple[np.ndarray, np.ndarray]:
    """The points of the budget's particle norm and their trapezoid weights, both (n,): equal spacing
    over Sod's domain, or Burgers' domain without 5 % at each end, at least 4 points per particle
    (and 4001)."""
    a, b = sod.DOMAIN if problem == "sod" else settings.exact.domain
    margin = 0.0 if problem == "sod" else 0.05 * (b - a)
    points = np.linspace(a + margin, b - margin, max(4001, 4 * round((b - a) / settings.h) * settings.ppc + 1))
    return points, np.r_[0, np.diff(points) / 2] + np.r_[np.diff(points) / 2, 0]


def subset_fields(problem: str, h: float, basis: str, settings: dict | None = None) -> tuple:
    """Error fields of the sixteen subsets (module docstring): ``(fields, weights, points, runs)``
    with ``fields[S][norm]`` and the norm's quadrature ``weights[norm]``; ``fields`` is None when a
    run fails. ``settings`` replace the study's (tests run small cases)."""
    points, trapezoid = norm_points(problem, _settings(problem, h, basis, settings or {}))
    weights = {"particles": trapezoid}
    if problem == "sod":
        weights["nodes"] = uniform_grid(*sod.DOMAIN, h).lumped_mass
    runs, e = [], {}
    for S3 in subsets(STAGES[:3]):
        changes = {k: v for s in STAGES[:3] if s not in S3 for k, v in EXACT_FORM[s].items()}
        for refine in (1, K):
            row, e[(S3, refine)] = _run(problem, _settings(problem, h, basis, {**(settings or {}), **changes,
                                                                               "refine": refine}), points)
            runs.append({"mpm_stages": label(S3), "refine": refine, **row})
            if not row["ok"]:
                return None, weights, points, runs
    fields = {S: {norm: e[(S - {"time"}, 1)][norm] if "time" in S else (K * e[(S, K)][norm] - e[(S, 1)][norm]) / (K - 1)
                  for norm in weights} for S in subsets(STAGES)}
    return fields, weights, points, runs


def budget_case(case: dict) -> dict:
    """One (problem, h, basis): v(S) per norm and subset, the runs, the Shapley error fields
    (sampled for the figure) and, for Sod, their L1 by region."""
    problem, h, basis = case["problem"], case["h"], case["basis"]
    changes = {k: case[k] for k in CASE_SETTINGS if k in case}
    fields, weights, points, runs = subset_fields(problem, h, basis, changes)
    if fields is None:
        return {"ok": False, "runs": runs}
    out = {"ok": True, "runs": runs, "subsets": {norm: {label(S): float(np.sum(w * np.abs(f[norm])))
                                                         for S, f in fields.items()} for norm, w in weights.items()}}
    d = decompose({S: f["particles"] for S, f in fields.items()}, STAGES)
    shown = {**d.shapley, GAP: d.gap}
    step = max(1, points.size // FIELD_POINTS)
    out["fields"] = {k: [float(f"{v:.6g}") for v in f[::step]] for k, f in {"x": points, **shown}.items()}
    if problem == "sod":
        regions = sod_regions(_sod_waves(), REGION_HALF_WIDTH)
        out["regions"] = {k: l1_by_region(points, f, weights["particles"], regions).tolist() for k, f in shown.items()}
    return out


def _sod_waves() -> dict:
    s = sod.SodSettings()
    return riemann.wave_positions(s.T, s.left, s.right)


def bases_case(case: dict) -> dict:
    """E2: Sod with the MPM stages and one basis: density errors and the plateau velocity noise."""
    changes = {k: case[k] for k in CASE_SETTINGS if k in case}
    return _run("sod", _settings("sod", case["h"], case["basis"], changes), np.linspace(0, 1, 11))[0]


def run_case(case: dict) -> dict:
    return {"budget": budget_case, "bases": bases_case}[case["kind"]](case)


# ---------------------------------------------------------------- tables

def run(options: StudyOptions) -> None:
    """Every case in one sweep (longest first), then the tables and figures."""
    got = options.sweep_plan(NAME, run_case, plan(options.tier), cost=cost)
    folder = options.folder(NAME)
    settings = {"sod": SOD, "burgers": BURGERS, "K": K, "stages": STAGES, "exact_form": EXACT_FORM,
                "region_half_width": REGION_HALF_WIDTH, "quick": options.quick,
                "layouts": {"ppc": list(LAYOUT_PPC), "regular": [0], "jittered": list(SEEDS),
                            "budgets": {f"{p} {b}": list(hs) for (p, b), hs in LAYOUT_H[options.tier].items()},
                            "bases_h": list(BASES_LAYOUT_H[options.tier])}}
    study = {key: r for key, r in got["budget"].items() if r["ok"]}  # the study's settings, in the plan's order
    every = {_full_key(key): r for key, r in got["budget"].items()}
    for key, r in got["layouts"].items():
        every.setdefault(key, r)
    ok = {key: r for key, r in every.items() if r["ok"]}
    rows = subset_rows(ok)
    shapley, interactions = decomposition_rows(rows)
    own = [r for r in shapley if _is_study_setting(r)]
    reference = decomposition_rows(subset_rows({k: r for k, r in got["roundoff"].items() if r["ok"] and k in study}))[0]
    readout = readout_rows(ok)
    control, control_runs = control_rows(options.sweep_plan(NAME, control_case, {"control": control_plan(options.tier)},
                                                            cost=lambda c: c["ppc"] / c["h"] ** 2)["control"])
    settings["control"] = {"h": list(CONTROL_H[options.tier]), "ppc": list(CONTROL_PPC), **CONTROL}
    bases = {(h, b, SOD["ppc"], "regular", 0): r for (h, b), r in got["bases"].items()}
    for key, r in got["bases_layouts"].items():
        bases.setdefault(key, r)
    publish(folder, {schema.BUDGET_SUBSETS: rows, schema.BUDGET_SHAPLEY: shapley, "interactions": interactions,
                     "regions": region_rows(ok),
                     "runs": [{**_key_columns(key), **x} for key, r in every.items() for x in r["runs"]],
                     schema.BUDGET_BASES: [{"h": h, "basis": b, "ppc": n, "layout": lay, "seed": s, **r}
                                           for (h, b, n, lay, s), r in bases.items()],
                     schema.BUDGET_ROUNDOFF: share_changes(own, reference), schema.BUDGET_CONTROL: control,
                     schema.BUDGET_CONTROL_RUNS: control_runs, schema.BUDGET_READOUT: readout}, settings,
            figures=(BASES_PLOT,))
    for problem in sorted({r["problem"] for r in own}):
        shapley_figure(folder / f"shapley_{problem}.png", [r for r in own if r["problem"] == problem])
        finest = {b: min(h for p, h, bb in study if p == problem and bb == b) for p, _, b in study if p == problem}
        fields_figure(folder / f"fields_{problem}.png", problem,
                      {b: (h, study[(problem, h, b)]["fields"]) for b, h in finest.items()})


#: the columns of a budget's particle setting (its key's last three entries; the study's own for a key of three)
SETTING_COLUMNS = ("ppc", "layout", "seed")


def _full_key(key: tuple) -> tuple:
    """``(problem, h, basis, ppc, layout, seed)`` of a plan key of the study's settings, ``(problem, h, basis)``."""
    p, h, b = key
    default = SOD if p == "sod" else BURGERS
    return (p, h, b, default["ppc"], "regular", 0)


def _is_study_setting(row: dict) -> bool:
    """Whether a row is at the study's own particle setting (every row without the setting columns is)."""
    default = SOD if row["problem"] == "sod" else BURGERS
    return all(str(row.get(c, default[c])) == str(default[c]) for c in SETTING_COLUMNS)


def _key_columns(key: tuple) -> dict:
    """The columns of a budget key: problem, h, basis and, for a key of six, ppc, layout, seed."""
    return dict(zip(("problem", "h", "basis", *SETTING_COLUMNS), key, strict=False))


def subset_rows(got: dict) -> list[dict]:
    """``subsets.csv``: v(S) for every problem, h, basis (particle setting, when the keys name it), norm and subset S
    of the MPM stages."""
    return [{**_key_columns(key), "norm": norm, "mpm_stages": subset, "error": v}
            for key, r in got.items() for norm, values in r["subsets"].items() for subset, v in values.items()]


def decomposition_rows(rows: list[dict]) -> tuple[list, list]:
    """``shapley.csv`` and ``interactions.csv`` from ``subsets.csv``: the decomposition of each
    (problem, h, basis, particle setting where the rows have one, norm) group; shares are of
    v(all MPM) - v(all exact)."""
    groups, keys = {}, {}
    for r in rows:
        key = {"problem": r["problem"], "h": r["h"], "basis": r["basis"],
               **{c: r[c] for c in SETTING_COLUMNS if c in r}, "norm": r["norm"]}
        group = tuple(key.values())
        keys[group] = key
        groups.setdefault(group, {})[r["mpm_stages"]] = float(r["error"])
    shapley, interactions = [], []
    for group, values in groups.items():
        v = {S: values[label(S)] for S in subsets(STAGES)}
        d, key, full = decompose(v, STAGES), keys[group], frozenset(STAGES)
        shapley += [{**key, "stage": s, "shapley": d.shapley[s], "share": d.shapley[s] / d.gap,
                     "removed": v[full] - v[full - {s}], "alone": d.moebius[frozenset({s})],
                     "mpm_error": d.total, "exact_error": d.floor} for s in STAGES]
        interactions += [{**key, "stages": label(S), "order": len(S), "term": m, "share": m / d.gap}
                         for S, m in d.interactions().items()]
    return shapley, interactions


def region_rows(got: dict) -> list[dict]:
    """``regions.csv``: L1 of each Shapley error field (particles) and its share in each region of C12."""
    return [{**_key_columns(key), "field": name, "L1": sum(parts),
             **{f"share_{n.replace(' ', '_')}": x / sum(parts) for n, x in zip(REGION_NAMES, parts, strict=True)}}
            for key, r in got.items() for name, parts in r.get("regions", {}).items()]


# ---------------------------------------------------------------- figures

BASES_PLOT = Plot("bases.png", f"E2: Sod density L1 with each basis, MPM stages, {SOD['ppc']} per cell, regular "
                 "layout", schema.BUDGET_BASES.stem, "h", (
    Curve("{basis}, nodes", "nodes_L1", "o-", {"ok": True, "ppc": SOD["ppc"], "seed": 0}, group=("basis",)),
    Curve("{basis}, particles", "particles_L1", "s--", {"ok": True, "ppc": SOD["ppc"], "seed": 0}, group=("basis",))),
    ylabel="density L1", slopes=(1,))


def shapley_figure(path: Path, rows: list[dict]) -> None:
    """Per mesh: v(all exact) as a grey bar, beside it each stage's Shapley value stacked from that
    floor (up when positive, down when negative), ending at v(all MPM) (black mark)."""
    norms = list(dict.fromkeys(r["norm"] for r in rows))
    bases = [b for b in BUDGET_BASES if any(r["basis"] == b for r in rows)]
    pairs = [(norm, basis) for norm in norms for basis in bases]
    nrows, ncols = grid_shape(len(pairs), (4.2, 3.6))
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.2 * ncols, 3.6 * nrows), squeeze=False)
    for ax in axes.ravel()[len(pairs):]:
        ax.set_visible(False)
    for ax, (norm, basis) in zip(axes.ravel(), pairs, strict=False):
        sub = [r for r in rows if r["norm"] == norm and r["basis"] == basis]
        hs = sorted({r["h"] for r in sub}, reverse=True)
        for j, h in enumerate(hs):
            at = {r["stage"]: r for r in sub if r["h"] == h}
            floor = up = down = at[STAGES[0]]["exact_error"]
            ax.bar(j - 0.25, floor, width=0.3, color="lightgray", label="all exact" if j == 0 else None)
            for s in STAGES:
                x = at[s]["shapley"]
                ax.bar(j + 0.1, x, bottom=up if x >= 0 else down, width=0.4, color=COLORS[s],
                       label=s if j == 0 else None)
                up, down = (up + x, down) if x >= 0 else (up, down + x)
            ax.plot([j - 0.4, j + 0.3], [at[STAGES[0]]["mpm_error"]] * 2, "k-", lw=2,
                    label="all MPM" if j == 0 else None)
        ax.axhline(0, color="k", lw=0.5)
        ax.set_xticks(range(len(hs)), [f"{h:g}" for h in hs])
        ax.set(xlabel="h", ylabel=f"{norm} L1 error", title=f"{rows[0]['problem']}, {basis}, {norm}")
    axes[0][0].legend(fontsize=7)
    save(fig, path, caption=f"{rows[0]['problem']}: v(all exact) as the grey floor, each stage's Shapley value "
                            "stacked on it (signed), ending at v(all MPM) (black mark)")


def fields_figure(path: Path, problem: str, fields: dict) -> None:
    """Each stage's Shapley error field against x at the finest mesh of each basis (Sod: the wave
    positions dotted); the thin black line is e_MPM - e_exact, their sum."""
    fig, axes = plt.subplots(len(fields), 1, figsize=(10, 2.6 * len(fields)), squeeze=False)
    for ax, (basis, (h, f)) in zip(axes[:, 0], fields.items(), strict=True):
        for s in STAGES:
            ax.plot(f["x"], f[s], "-", lw=0.8, color=COLORS[s], label=s)
        ax.plot(f["x"], f[GAP], "k-", lw=0.4, label=GAP)
        for w in ("rarefaction_head", "rarefaction_tail", "contact", "shock") if problem == "sod" else ():
            ax.axvline(_sod_waves()[w], color="gray", ls=":", lw=0.8)
        ax.set(xlabel="x", ylabel="Shapley error field", title=f"{problem}, {basis}, h = {h:g}: error field by stage")
    axes[0, 0].legend(fontsize=7, ncol=5)
    save(fig, path, caption=f"{problem}: each stage's Shapley error field at the finest mesh of each basis; they "
                            "add up to e_MPM - e_exact (black) at every point"
                            + (", waves dotted" if problem == "sod" else ""))


#: The cost model of :mod:`mpm_fem.app.estimate`: :func:`cost` is in CPU milliseconds, from the full tier's runs
#: on the 2-core machine (2026-11-26, from-scratch run: CHANGES.md).
PLAN, COST, SECONDS_PER_COST = plan, cost, 1e-3

if __name__ == "__main__":
    sys.exit(script_main(NAME))
