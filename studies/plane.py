"""Does the 1D error analysis survive in 2D? MPM on the plane, stage by stage, beside the FEM.

Three solutions of :mod:`baselines.exact.solids` (:data:`SOLUTIONS`): the axis-aligned
displacement at ``A = 1e-4`` (every particle stays in its cell: the control) and ``A = 0.05``
(particles cross cells), and the generalized vortex at ``A = 0.02`` (at its own amplitude 1 every
basis inverts a particle before ``t = 1/2`` at 2 x 2 particles per cell: :mod:`mpm_fem.plane.run`).
A run is :func:`mpm_fem.plane.run.run` (USL, FLIP, CFL 0.25, the compiled step where it serves it in
the full and deep tiers, the numpy step in the quick tier and wherever a stage is exact or the mass
is not lumped); its error is the particle displacement L2 at T (volume-weighted root mean square,
:mod:`mpm_fem.plane.norms`). Tables, one row per run (the claims: :mod:`mpm_fem.measure.claims.plane`):

    growth      every basis, 2 x 2 and 4 x 4 particles per cell, the regular layout and jittered seeds
                (:data:`SEEDS`), the meshes of :data:`GROWTH_H` (D1)
    stages      point-mass P1 with each stage made exact alone and every stage exact (D2)
    budget      the 16 subsets of {projection, mass, interpolation, time} in MPM form on the two coarsest
                meshes, both amplitudes (the small one the control), and ``shapley``, their decomposition (D3)
    mass        the grid masses lumped, consistent, exact and FMPM(k), k = 1..4 (:mod:`mpm_fem.masses`),
                with the CPU cost of a step (the lumped mass on the compiled step, the others on the numpy
                step) (D4, D5)
    fem         the Q1 FEM on the same meshes (:mod:`baselines.fem_solid`), lumped and consistent (D6)
    time        one mesh, the step alone refined (D7)

"Time exact" is the step refined :data:`K` times (second order in dt: its error falls K^2-fold).
"""

from __future__ import annotations

import importlib
import math
import sys
import time
from typing import NamedTuple

from mpm_fem.app.plots import Curve, Plot
from mpm_fem.app.study import StudyOptions, publish, script_main
from mpm_fem.measure import schema
from mpm_fem.measure.decomposition import decompose, label, subsets

NAME = "plane"


class Solution(NamedTuple):
    """A manufactured solution of the study: its ``problem`` (``axis``, ``vortex``) and ``amplitude``."""

    problem: str
    amplitude: float


SOLUTIONS = {"axis-1e-4": Solution("axis", 1e-4), "axis-0.05": Solution("axis", 0.05),
             "vortex": Solution("vortex", 0.02)}
CONTROL, CROSSING = "axis-1e-4", "axis-0.05"
BASES = ("mpm", "gimp", "bspline", "cubic")
SEEDS = (1, 2, 3, 4, 5)
LAYOUTS = (("regular", 0),) + tuple(("jittered", s) for s in SEEDS)
CFL = 0.25
STAGES = ("projection", "mass", "interpolation", "time")
K = 2  # time exact: the step refined K times
EXACT_FORM = {"projection": {"projection": "exact"}, "mass": {"mass": "exact"},
              "interpolation": {"interpolation": "exact"}, "time": {"refine": K}}
MASSES = ("lumped", "consistent", "exact", "fmpm1", "fmpm2", "fmpm3", "fmpm4")
H = (1 / 8, 1 / 16, 1 / 32, 1 / 64, 1 / 128)
#: per tier: {(basis, ppc, which runs): meshes} of the growth table for every solution ("all": the regular and
#: jittered layouts, "regular": the regular one, "two": the regular layout and seed 1); in the full tier the wider
#: bases run every layout to h = 1/32 and the regular one to 1/64, P1 every layout to 1/64 (the deep tier: every
#: basis and layout to 1/64 at 2x2 and 4x4, P1 to 1/128)
_WIDE = BASES[1:]
GROWTH_H = {"quick": {("mpm", 2, "two"): H[:2]},
            "full": {("mpm", 2, "all"): H[:4], **{(b, 2, "all"): H[:3] for b in _WIDE},
                     **{(b, 2, "regular"): H[3:4] for b in _WIDE}, **{(b, 4, "regular"): H[:3] for b in BASES}},
            "deep": {**{(b, 2, "all"): H[:4] for b in BASES}, **{(b, 4, "all"): H[:4] for b in BASES},
                     ("mpm", 2, "all"): H}}
#: per tier: {solution: (meshes, layouts)} of the stage-exact runs (each costs up to 8x a numpy step per particle)
STAGES_H = {"quick": {}, "full": {"axis-0.05": (H[:3], 1), "axis-1e-4": (H[:2], 1)},
            "deep": {"axis-0.05": (H[:4], 6), "axis-1e-4": (H[:3], 6)}}
BUDGET_H = {"quick": (), "full": H[:2], "deep": H[:2]}
MASS_H = {"quick": H[:2], "full": H[:3], "deep": H[:4]}
EXACT_MASS_H = {"quick": (), "full": H[:2], "deep": H[:4]}
FEM_H = {"quick": H[:2], "full": H[:4], "deep": H[:5]}
TIME_H, TIME_CFL, TIME_REFINES = 1 / 32, 0.8, (1, 2, 4, 8, 16, 32)
QUICK_LAYOUTS = LAYOUTS[:2]


# ---------------------------------------------------------------- the plan

def mpm_case(solution: str, h: float, basis: str = "mpm", ppc: int = 2, layout: str = "regular", seed: int = 0,
             compiled: bool = True, **changes) -> dict:
    """The case of one MPM run: the study's settings with ``changes`` (stage switches, mass, cfl)."""
    s = SOLUTIONS[solution]
    case = {"kind": "mpm", "solution": solution, "problem": s.problem, "amplitude": s.amplitude, "h": h,
            "basis": basis, "ppc": ppc, "layout": layout, "seed": seed, "cfl": CFL, **changes}
    serves = all(case.get(k, v) == v for k, v in
                 {"mass": "lumped", "projection": "mpm", "interpolation": "mpm"}.items())
    case["compiled"] = bool(compiled and serves)
    return case


def _layouts(which: str) -> tuple:
    return QUICK_LAYOUTS if which == "two" else LAYOUTS if which == "all" else LAYOUTS[:1]


def subset_changes(mpm_stages) -> dict:
    """The settings that make every stage not in ``mpm_stages`` exact."""
    return {k: v for s in STAGES if s not in mpm_stages for k, v in EXACT_FORM[s].items()}


def plan(tier: str) -> dict:
    quick = tier == "quick"
    compiled = not quick
    growth = {(sol, basis, ppc, layout, seed, h): mpm_case(sol, h, basis, ppc, layout, seed, compiled)
              for (basis, ppc, which), meshes in GROWTH_H[tier].items() for sol in SOLUTIONS for h in meshes
              for layout, seed in _layouts(which)}
    made_exact = {"none": STAGES, **{s: tuple(x for x in STAGES if x != s) for s in STAGES}, "all": ()}
    stages = {(sol, h, layout, seed, name): mpm_case(sol, h, layout=layout, seed=seed, compiled=compiled,
                                                     **subset_changes(mpm))
              for sol, (meshes, n) in STAGES_H[tier].items() for h in meshes for layout, seed in LAYOUTS[:n]
              for name, mpm in made_exact.items()}
    budget = {(sol, h, label(S)): mpm_case(sol, h, compiled=compiled, **subset_changes(S))
              for sol in (CROSSING, CONTROL) for h in BUDGET_H[tier] for S in subsets(STAGES)}
    mass_solutions = (CROSSING,) if quick else (CROSSING, CONTROL, "vortex")
    mass = {(sol, h, m): mpm_case(sol, h, compiled=compiled, mass=m)
            for sol in mass_solutions for h in MASS_H[tier] for m in (MASSES[:2] if quick else MASSES)
            if m != "exact" or h in EXACT_MASS_H[tier]}
    fem = {(sol, h, m): {"kind": "fem", "solution": sol, "problem": SOLUTIONS[sol].problem,
                         "amplitude": SOLUTIONS[sol].amplitude, "h": h, "mass": m, "cfl": CFL}
           for sol in SOLUTIONS for h in FEM_H[tier] for m in ("lumped", "consistent")}
    timing = {} if quick else {(sol, k): mpm_case(sol, TIME_H, cfl=TIME_CFL, refine=k)
                               for sol in (CROSSING, CONTROL) for k in TIME_REFINES}
    return {"growth": growth, "stages": stages, "budget": budget, "mass": mass, "fem": fem, "time": timing}


# ---------------------------------------------------------------- one case

_SETTINGS = ("problem", "amplitude", "h", "basis", "ppc", "layout", "seed", "cfl", "mass", "projection",
             "interpolation", "refine", "compiled", "flip")


def run_case(case: dict) -> dict:
    """One run: ``case["kind"]`` ``"mpm"`` (fields of :class:`mpm_fem.plane.run.PlaneSettings`) or
    ``"fem"`` (:func:`baselines.fem_solid.solve` at the same ``h`` and CFL). A run that stops (a particle
    inverts, a singular mass) is a row with ``ok`` false and its message."""
    if case["kind"] == "fem":
        return _fem_case(case)
    plane_run = importlib.import_module("mpm_fem.plane.run")  # the module (the name ``run`` is this study's)
    from mpm_fem.plane.model import InversionError

    settings = plane_run.PlaneSettings(**{k: case[k] for k in _SETTINGS if k in case})
    cpu = time.process_time()
    try:
        r = plane_run.run(settings)
    except (InversionError, ArithmeticError, ValueError) as err:
        return {"ok": False, "error": " ".join(str(err).split())[:200]}
    cpu = time.process_time() - cpu
    e = r.errors["displacement"]["particles"]
    return {"ok": True, "L2": e["L2"], "Linf": e["Linf"], "L2_max": e["L2_max"],
            "acc_L2": r.errors["acceleration"]["nodes"]["L2"], "steps": r.steps, "dt": r.dt, "cfl_run": r.cfl,
            "n_p": int(r.particles.n), "wall_s": round(r.wall_s, 3), "step_ms": 1e3 * cpu / r.steps,
            "compiled": r.compiled}


def _fem_case(case: dict) -> dict:
    from baselines import fem_solid
    from mpm_fem.plane.run import PlaneSettings, solution_of

    solution = solution_of(PlaneSettings(problem=case["problem"], amplitude=case["amplitude"]))
    cpu = time.process_time()
    try:
        r = fem_solid.solve(solution, case["h"], mass=case["mass"], cfl=case["cfl"])
    except (ArithmeticError, ValueError) as err:
        return {"ok": False, "error": " ".join(str(err).split())[:200]}
    cpu = time.process_time() - cpu
    return {"ok": True, "L2": r.error_L2, "L2_max": r.error_L2_max, "steps": r.steps, "dt": r.dt,
            "step_ms": 1e3 * cpu / r.steps}


# ---------------------------------------------------------------- tables

_RUN = schema.PLANE_RUN


def _row(result: dict) -> dict:
    return {k: result.get(k, "") for k in _RUN}


def budget_rows(got: dict) -> tuple[list[dict], list[dict]]:
    """``budget`` (v(S) of every subset ``S`` of MPM stages, per solution and mesh) and ``shapley`` (each
    stage's Shapley value and share of the gap v(all MPM) - v(all exact), and the interactions' total
    magnitude over the gap) from the budget's runs; a group with a failed run has no Shapley rows."""
    rows, groups = [], {}
    for (sol, h, subset), r in got.items():
        rows.append({"solution": sol, "h": h, "mpm_stages": subset, **_row(r)})
        groups.setdefault((sol, h), {})[subset] = r
    shapley = []
    for (sol, h), runs in groups.items():
        if not all(r.get("ok") for r in runs.values()):
            continue
        d = decompose({S: runs[label(S)]["L2"] for S in subsets(STAGES)}, STAGES)
        mixed = sum(abs(m) for m in d.interactions().values())
        shapley += [{"solution": sol, "h": h, "stage": s, "shapley": d.shapley[s], "share": d.shapley[s] / d.gap,
                     "alone": d.moebius[frozenset({s})], "mpm_error": d.total, "exact_error": d.floor,
                     "gap": d.gap, "interactions": mixed, "interactions_share": mixed / abs(d.gap)}
                    for s in STAGES]
    return rows, shapley


def convergence_rows(growth: dict, fem: dict) -> list[dict]:
    """The figures' table: per solution, method (a basis at a particle count, or the FEM with a mass) and
    mesh, the regular layout's L2 and the mean, least and largest L2 over the layouts run."""
    groups: dict = {}
    for (sol, basis, ppc, _layout, seed, h), r in growth.items():
        groups.setdefault((sol, f"{basis} {ppc}x{ppc}", h), []).append((seed, r))
    for (sol, h, mass), r in fem.items():
        groups.setdefault((sol, f"FEM {mass}", h), []).append((0, r))
    out = []
    for (sol, method, h), runs in groups.items():
        ok = [r["L2"] for _, r in runs if r.get("ok")]
        regular = [r["L2"] for seed, r in runs if seed == 0 and r.get("ok")]
        out.append({"solution": sol, "method": method, "h": h, "runs": len(runs), "ok_runs": len(ok),
                    "L2": regular[0] if regular else math.nan, "L2_mean": sum(ok) / len(ok) if ok else math.nan,
                    "L2_lo": min(ok, default=math.nan), "L2_hi": max(ok, default=math.nan)})
    return out


def run(options: StudyOptions) -> None:
    """Every case in one sweep (shared cases run once, the costliest first), then the tables and figures."""
    got = options.sweep_plan(NAME, run_case, plan(options.tier), cost=cost)
    folder = options.folder(NAME)
    key = ("solution", "basis", "ppc", "layout", "seed", "h")
    growth = [{**dict(zip(key, k, strict=True)), **_row(r)} for k, r in got["growth"].items()]
    stage_key = ("solution", "h", "layout", "seed", "made_exact")
    stages = [{**dict(zip(stage_key, k, strict=True)), "basis": "mpm", "ppc": 2, **_row(r)}
              for k, r in got["stages"].items()]
    budget, shapley = budget_rows(got["budget"])
    mass = [{"solution": s, "h": h, "mass": m, "basis": "mpm", **_row(r)} for (s, h, m), r in got["mass"].items()]
    fem = [{"solution": s, "h": h, "mass": m, **_row(r)} for (s, h, m), r in got["fem"].items()]
    timing = [{"solution": s, "h": TIME_H, "cfl": TIME_CFL, "refine": k, "study_cfl": CFL, **_row(r)}
              for (s, k), r in got["time"].items()]
    settings = {"tier": options.tier, "solutions": {k: v._asdict() for k, v in SOLUTIONS.items()}, "cfl": CFL,
                "scheme": "usl", "flip": 1.0, "stages": STAGES, "time_exact": f"the step refined {K} times",
                "error": "particle displacement L2 at T, sqrt(sum V_p |u_p - u|^2 / sum V_p)",
                "layouts": {"regular": [0], "jittered": list(SEEDS)}}
    extra = {"time": {"h": TIME_H, "cfl": TIME_CFL, "refines": list(TIME_REFINES)},
             "stages": {"made_exact": "none: all MPM; a stage: that stage alone exact; all: every stage exact"},
             "mass": {"masses": list(MASSES), "step_ms": "CPU milliseconds per step of the run"}}
    publish(folder, {schema.PLANE_GROWTH: growth, schema.PLANE_STAGES: stages, schema.PLANE_BUDGET: budget,
                     schema.PLANE_SHAPLEY: shapley, schema.PLANE_MASS: mass, schema.PLANE_FEM: fem,
                     schema.PLANE_TIME: timing,
                     schema.PLANE_CONVERGENCE: convergence_rows(got["growth"], got["fem"])},
            settings, extra, PLOTS)
    _stage_bars(folder, shapley, stages)


# ---------------------------------------------------------------- figures

_COLOURS = {"mpm": "tab:blue", "gimp": "tab:orange", "bspline": "tab:green", "cubic": "tab:red"}


def _convergence_curves(solutions: tuple[str, ...]) -> tuple[Curve, ...]:
    curves = []
    for basis, colour in _COLOURS.items():
        for ppc, fmt in ((2, "o-"), (4, "s--")):
            where = {"solution": solutions, "method": f"{basis} {ppc}x{ppc}"}
            curves.append(Curve(f"{basis} {ppc}x{ppc}", "L2", fmt, where, options={"color": colour}))
            if ppc == 2:
                curves += [Curve(f"_{basis} {k}", f"L2_{k}", ":", where, options={"color": colour, "lw": 0.7})
                           for k in ("lo", "hi")]
    curves += [Curve(f"FEM {m}", "L2", fmt, {"solution": solutions, "method": f"FEM {m}"})
               for m, fmt in (("lumped", "k^-"), ("consistent", "kv--"))]
    return tuple(curves)


_YLABEL = "displacement error (particle L2 at T)"
PLOTS = (
    Plot("convergence_axis.png", "Axis-aligned solution, both amplitudes: every basis at 2x2 (solid; dotted: the "
         "least and largest over the regular and five jittered layouts) and 4x4 (dashed) per cell, the Q1 FEM "
         "(black)", "convergence", "h", _convergence_curves(("axis-1e-4", "axis-0.05")), ylabel=_YLABEL,
         slopes=(1, 2), split=("solution",), size=(4.6, 4.0)),
    Plot("convergence_vortex.png", f"Generalized vortex (A = {SOLUTIONS['vortex'].amplitude:g}): every basis at "
         "2x2 (solid; dotted: the least and largest over the layouts) and 4x4 (dashed) per cell, the Q1 FEM (black)",
         "convergence", "h", _convergence_curves(("vortex",)), ylabel=_YLABEL, slopes=(1, 2), size=(5.6, 4.4)),
    Plot("mass.png", "Point-mass P1, regular layout: the grid masses, lumped, consistent, exact and FMPM(k)",
         "mass", "h", tuple(Curve("{mass}", "L2", "o-", {"ok": True}, group=("mass",)) for _ in (0,)),
         ylabel=_YLABEL, slopes=(1, 2), split=("solution",), size=(4.6, 4.0)),
    Plot("mass_cost.png", "The CPU cost of one step with each grid mass (point-mass P1, regular layout; the lumped "
         "mass on the compiled step, the others on the numpy step)", "mass",
         "h", (Curve("{mass}", "step_ms", "o-", {"ok": True, "solution": CROSSING}, group=("mass",)),),
         ylabel="CPU ms per step", size=(5.6, 4.4)),
    Plot("time.png", f"The step alone refined on h = 1/{round(1 / TIME_H)} (CFL {TIME_CFL} / refine)", "time", "dt",
         (Curve("{solution}", "L2", "o-", {"ok": True}, group=("solution",)),), xlabel="dt", ylabel=_YLABEL,
         slopes=(2,), size=(5.6, 4.4)),
)


def _stage_bars(folder, shapley: list[dict], stages: list[dict]) -> None:
    """``stages.png``: per solution and mesh the Shapley value of each stage (bars) and the errors with each
    stage alone exact (the regular layout), beside the control."""
    from mpm_fem.app.plots import grid_shape, plt, save

    panels = sorted({(r["solution"], r["h"]) for r in shapley}, key=lambda k: (k[0], -k[1]))
    if not panels:
        return
    nrows, ncols = grid_shape(len(panels), (4.2, 3.6))
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.2 * ncols, 3.6 * nrows), squeeze=False)
    colours = {"projection": "tab:blue", "mass": "tab:orange", "interpolation": "tab:green", "time": "tab:red"}
    for ax, (sol, h) in zip(axes.ravel(), panels, strict=False):
        sub = {r["stage"]: r for r in shapley if (r["solution"], r["h"]) == (sol, h)}
        gap = sub[STAGES[0]]["gap"]
        ax.bar(range(len(STAGES)), [sub[s]["shapley"] / gap for s in STAGES], color=[colours[s] for s in STAGES])
        ax.axhline(0, color="k", lw=0.5)
        ax.set_xticks(range(len(STAGES)), STAGES, fontsize=7)
        role = "control" if sol == CONTROL else "cells crossed"
        ax.set(ylabel="Shapley share of the gap", title=f"{sol} ({role}), h = 1/{round(1 / h)}: interactions "
                                                        f"{sub[STAGES[0]]['interactions_share']:.2f} of the gap")
        ax.title.set_fontsize(8)
    for ax in axes.ravel()[len(panels):]:
        ax.set_visible(False)
    save(fig, folder / "stages.png", caption="Each stage's Shapley share of the gap v(all MPM) - v(all exact) of the "
                                             "particle displacement L2 (point-mass P1, 2x2 per cell, regular layout), "
                                             f"cells crossed (A = {SOLUTIONS[CROSSING].amplitude:g}) beside the "
                                             f"control (A = {SOLUTIONS[CONTROL].amplitude:g})")


# ---------------------------------------------------------------- the cost model

#: CPU seconds per particle-step by kernel (P1 / the wider rows) and by exact stage or mass, and per node-step of
#: the FEM: measured on the 2-core machine under load (2026-12-02: h = 1/8 ... 1/64, 2x2 per cell)
PER_PARTICLE_STEP = {"compiled": {"mpm": 1.5e-7, "wide": 3.3e-7}, "numpy": 6.5e-7, "consistent": 1.3e-6,
                     "fmpm": 1.1e-6, "exact": 6.5e-6, "interpolation": 1.9e-6}
PER_NODE_STEP = {"lumped": 6.5e-7, "consistent": 8.5e-7}
PER_STEP = 2e-3


def cost(case: dict) -> float:
    """Estimated CPU seconds of a case: steps x (particles x the per-particle-step cost + PER_STEP)."""
    s = SOLUTIONS[case["solution"]]
    T, c, share = (0.02, 100.0, 1.0) if s.problem == "axis" else (1.0, 1.0, 0.35)
    side = 2.0 if s.problem == "axis" else 3.0
    cells = (side / case["h"]) ** 2
    steps = math.ceil(T * c * case.get("refine", 1) / (case["cfl"] * case["h"]))
    if case["kind"] == "fem":
        return steps * (share * cells * PER_NODE_STEP[case["mass"]] + PER_STEP)
    n = share * cells * case["ppc"] ** 2
    if case.get("compiled"):
        a = PER_PARTICLE_STEP["compiled"]["mpm" if case["basis"] == "mpm" else "wide"]
    elif "exact" in (case.get("projection"), case.get("mass")):
        a = PER_PARTICLE_STEP["exact"]
    elif case.get("interpolation") == "exact":
        a = PER_PARTICLE_STEP["interpolation"]
    elif case.get("mass", "lumped") != "lumped":
        a = PER_PARTICLE_STEP["fmpm" if case["mass"].startswith("fmpm") else "consistent"]
    else:
        a = PER_PARTICLE_STEP["numpy"]
    return steps * (n * a + PER_STEP)


#: The cost model of :mod:`mpm_fem.app.estimate`: :func:`cost` is in CPU seconds.
PLAN, COST, SECONDS_PER_COST = plan, cost, 1.0

if __name__ == "__main__":
    sys.exit(script_main(NAME))
