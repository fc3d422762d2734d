"""The grid masses in 1D: lumped, consistent, exact and FMPM(k), on Sod and on Burgers (E7).

Each mass of :data:`MASSES` (``Stages.mass``: :mod:`mpm_fem.core.transfer` reads FMPM(k) from the
grid-mass registry, :mod:`mpm_fem.masses`) runs the same case, all else equal:

    sod       the Sod study's own MPM settings (16 per cell, CFL 0.05, its viscosity), density L1
    burgers   the Burgers study's compared solution at eps = 0.045, 4 per cell, both accelerations,
              CFL 0.3 (the consistent particle mass's stable step with the calculated acceleration:
              C15's setting), velocity L2

on the meshes of :data:`H`, over the nodes (``m_i / int S_i``, resp. ``v_i``) and over the particles.
Every run takes the numpy step (``kernel="numpy"``: the fused step has no FMPM), so that ``step_ms``,
its wall time per step, compares the masses' costs on one implementation. Table ``errors``
(``lumping/errors``); the verdict: :mod:`mpm_fem.measure.claims.lumping`.
"""

from __future__ import annotations

import sys

from mpm_fem.app.study import StudyOptions, publish, script_main
from mpm_fem.core.particles import PositivityError
from mpm_fem.measure.schema import LUMPING_ERRORS
from mpm_fem.problems import burgers, sod
from studies import burgers as burgers_study
from studies import sod as sod_study

NAME = "lumping"
MASSES = ("lumped", "consistent", "exact", "fmpm1", "fmpm2", "fmpm3", "fmpm4")
#: the meshes: Burgers' third (h = 0.0025) would cost 16 CPU-min (its step ~ h^2), in the deep tier
H = {"sod": (0.01, 0.005, 0.0025), "burgers": (0.01, 0.005)}
DEEP_H = {"sod": (0.01, 0.005, 0.0025, 0.00125), "burgers": (0.01, 0.005, 0.0025)}
ACCELERATIONS = {"sod": ("",), "burgers": ("calculated", "exact")}
#: Sod: the study's MPM settings (but the mass and the kernel); Burgers: its compared solution, first eps, C15's CFL
SOD = {k: v for k, v in sod_study.MPM.items() if k != "mass"}
BURGERS = {**{k: v for k, v in burgers_study.MPM.items() if k != "mass"}, "solution": burgers_study.DEFAULT,
           "eps": burgers_study.EPS[0], "cfl": burgers_study.LUMPING_CFL}
MEASURED = {"sod": ("density", "L1"), "burgers": ("velocity", "L2")}
#: the quick tier: the coarsest mesh, the lumped, consistent and FMPM(2) masses, Sod and Burgers' exact acceleration
QUICK = {"H": {"sod": (0.01,), "burgers": (0.01,)}, "masses": ("lumped", "consistent", "fmpm2"),
         "accelerations": {"sod": ("",), "burgers": ("exact",)}}


def case(problem: str, acceleration: str, h: float, mass: str) -> dict:
    """The run of ``mass`` on ``problem`` at ``h`` (``acceleration`` for Burgers, ``""`` for Sod)."""
    fixed = SOD if problem == "sod" else {**BURGERS, "acceleration": acceleration}
    return {"problem": problem, "h": h, "mass": mass, "kernel": "numpy", **fixed}


def plan(tier: str) -> dict:
    q = QUICK if tier == "quick" else {}
    hs = q.get("H", DEEP_H if tier == "deep" else H)
    masses, accelerations = q.get("masses", MASSES), q.get("accelerations", ACCELERATIONS)
    return {"runs": {(p, a, h, m): case(p, a, h, m) for p in hs for a in accelerations[p] for h in hs[p]
                     for m in masses}}


def run_case(case: dict) -> dict:
    """One run, measured: the errors over the nodes and over the particles, its steps and wall time per step. A run
    the method stops (lost positivity, a singular mass matrix, a non-finite state) is a row naming why."""
    settings = dict(case)
    problem = settings.pop("problem")
    module, make = (sod, sod.SodSettings) if problem == "sod" else (burgers, burgers.BurgersSettings)
    run_settings = make(**settings)
    try:
        result = module.simulate(run_settings, progress=False)
    except (PositivityError, FloatingPointError) as err:
        return {"ok": False, "error": str(err)}
    quantity, norm = MEASURED[problem]
    errors = module.errors(run_settings, result)[quantity]
    return {"ok": True, "nodes": errors["nodes"][norm], "particles": errors["particles"][norm], "steps": result.steps,
            "step_ms": 1e3 * result.wall_s / max(result.steps, 1)}


def rows(got: dict) -> list[dict]:
    """One row per run of :func:`plan`'s ``runs`` (a failed run too, with its ``error``)."""
    out = []
    for (problem, acceleration, h, mass), r in got.items():
        quantity, norm = MEASURED[problem]
        row = {"problem": problem, "acceleration": acceleration, "h": h, "mass": mass, "ok": r["ok"],
               "quantity": quantity, "norm": norm, "nodes": r.get("nodes", ""), "particles": r.get("particles", ""),
               "steps": r.get("steps", ""), "step_ms": round(r["step_ms"], 4) if r["ok"] else ""}
        if not r["ok"]:
            row["error"] = r["error"]
        out.append(row)
    return out


def run(options: StudyOptions) -> None:
    got = options.sweep_plan(NAME, run_case, plan(options.tier), cost=cost)
    settings = {"quick": options.quick, "tier": options.tier, "masses": list(MASSES), "sod": SOD, "burgers": BURGERS,
                "measured": {p: f"{q} {n}" for p, (q, n) in MEASURED.items()}, "kernel": "numpy",
                "step_ms": "the run's wall time over its steps, on the numpy step"}
    publish(options.folder(NAME), {LUMPING_ERRORS: rows(got["runs"])}, settings)


#: CPU seconds per particle-step of the lumped numpy step, and each mass's cost over it (measured 2026-12-03 at
#: h = 0.01 on the 2-core machine: Sod 0.53 s, Burgers 0.49 s a run; the exact mass stage assembles the FE mass of
#: the exact fields every step)
PER_UNIT = {"sod": 1.66e-7, "burgers": 2.7e-6}
FACTOR = {"sod": {"lumped": 1.0, "exact": 27.0}, "burgers": {"lumped": 1.0, "exact": 3.5}}
COUPLED = {"sod": 1.4, "burgers": 2.0}  # the consistent mass and FMPM(k)


def cost(case: dict) -> float:
    """Estimated CPU seconds: ~ particle-steps (Sod ``ppc / (h^2 CFL)``; Burgers ``ppc eps / h^3``, the viscous
    limit sets its step) times :data:`PER_UNIT` and the mass's factor."""
    h, p = case["h"], case["problem"]
    base = case["ppc"] / (h * h * case["cfl"]) if p == "sod" else case["ppc"] * case["eps"] / h**3
    return base * PER_UNIT[p] * FACTOR[p].get(case["mass"], COUPLED[p])


PLAN, COST, SECONDS_PER_COST = plan, cost, 1.0

if __name__ == "__main__":
    sys.exit(script_main(NAME))
