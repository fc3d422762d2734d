"""The time error of the step (C1) and the jump of d^3 x_p / dt^3 at a node crossing (C2).

C1, ``time_order.csv``: at fixed h and particles, a fixed dt refined 1, 2, 4, 8, 16 times against
dt / 256 (pulse) or dt / 64 (Burgers), for a smooth acoustic pulse in a gas without viscosity
(:class:`mpm_fem.measure.timing.PulseSettings`) and for viscous Burgers (the rarefaction, eps = 0.045,
4 particles per cell, CFL 0.5: the viscous limit fixes dt); ``local_error.csv``: one step from a
common state (T/2) against 256 substeps, for dt/2 ... dt/16. C2, ``crossing.csv``: the jump of
``d^3 x_p / dt^3`` at each node crossing of one particle (Burgers rarefaction, h = 0.02, exact and
calculated acceleration), measured and by the slides' formula (:mod:`mpm_fem.measure.timing`). Every
basis: point-mass P1 ("mpm"), GIMP and the C1 quadratic B-spline ("bspline").
"""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from mpm_fem.app.plots import Curve, Plot, draw, plt, save
from mpm_fem.app.study import StudyOptions, publish, script_main
from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.models.burgers import ViscousBurgers
from mpm_fem.core.step import Dirichlet
from mpm_fem.measure.schema import TIME_CROSSING_SUMMARY, TIME_LOCAL_ERROR, TIME_ORDER
from mpm_fem.measure.timing import (
    PulseSettings,
    Recorder,
    crossing_jumps,
    field_difference,
    local_errors,
    observed_order,
    pulse_setup,
    simulate_pulse,
    state_at,
)
from mpm_fem.problems import burgers
from mpm_fem.run.solve import Problem

NAME = "time"
BASES = ("mpm", "gimp", "bspline")
BURGERS = dict(solution="rarefaction", eps=0.045, ppc=4, cfl=0.5, acceleration="calculated", mass="lumped",
               scheme="usl", layout="regular", seed=0)
PULSE = PulseSettings(h=0.02, ppc=8)
TIME_REFINES = (1, 2, 4, 8, 16)
TIME_REFERENCE = {"pulse": 256, "burgers": 64}
LOCAL_SUBSTEPS = 256
LOCAL_REFINES = (2, 4, 8, 16)  # the full step is pre-asymptotic when a particle crosses a node within it
CROSSING = dict(h=0.02, ppc=4, solution="rarefaction", eps=0.045, cfl=0.05, T=0.3)
CROSSING_PARTICLE = 4 * 27 + 1  # starts at x = 0.565, in the fan; it never leaves before T
#: the quick tier: P1 only (a second basis would compile two more fused variants, 15 CPU-s: docs/performance.md)
QUICK = {"bases": ("mpm",), "refines": (1, 2, 4), "reference": {"pulse": 32, "burgers": 16}}


# ---------------------------------------------------------------- the plan

def plan(tier: str) -> dict:
    quick = tier == "quick"
    bases = QUICK["bases"] if quick else BASES
    refines, reference = (QUICK["refines"], QUICK["reference"]) if quick else (TIME_REFINES, TIME_REFERENCE)
    time = {(problem, basis): {"kind": "time", "problem": problem, "basis": basis, "h": 0.02, "refines": list(refines),
                               "reference": reference[problem]} for problem in ("pulse", "burgers") for basis in bases}
    crossing = {(basis, acc): {"kind": "crossing", "basis": basis, "acceleration": acc}
                for basis in bases for acc in ("exact", "calculated")}
    return {"time": time, "crossing": crossing}


# ---------------------------------------------------------------- one case

def _burgers_setup(base):
    """Problem at the fixed viscous step ``dt = CFL h^2 / (2 eps)``, grid, particles, stages."""
    a, b = base.exact.domain
    dt = base.cfl * base.h**2 / (2 * base.eps)
    problem = Problem(model=ViscousBurgers(base.eps), boundary=Dirichlet(base.exact.v), T=base.T, cfl=1.0, dt=dt,
                      particle_boundary=burgers.Reservoir(base.h / base.ppc, base.exact.v))
    grid = uniform_grid(a, b, base.h)
    return problem, grid, burgers.initial_particles(base, grid), base.stages


def time_case(case: dict) -> dict:
    """C1 at fixed h: global error of a fixed dt refined ``refines`` times against ``reference``,
    and the local error of one step from the state at T/2."""
    basis, refines, reference = case["basis"], case["refines"], case["reference"]
    rows = []
    if case["problem"] == "pulse":
        base = replace(PULSE, basis=basis)
        ref = simulate_pulse(replace(base, refine=reference)).particles
        for k in refines:
            P = simulate_pulse(replace(base, refine=k)).particles
            rows.append({"refine": k, "dt": base.dt / k, **{q: float(np.abs(getattr(P, q) - getattr(ref, q)).mean())
                                                           for q in ("x", "velocity", "density")}})
        setup = pulse_setup(base)
    else:
        base = burgers.BurgersSettings(h=case["h"], basis=basis, **BURGERS)
        ref = burgers.simulate(replace(base, refine=reference), progress=False).particles
        a, b = base.exact.domain
        for k in refines:
            result = burgers.simulate(replace(base, refine=k), progress=False)
            if result.dt_max > result.dt_min * (1 + 1e-9) and result.t - result.dt_min < base.T * (1 - 1e-9):
                raise RuntimeError("the Burgers time step is not fixed: the advective limit binds")
            rows.append({"refine": k, "dt": result.dt_max, "velocity": field_difference(
                result.particles, ref, (a + 0.05 * (b - a), b - 0.05 * (b - a)), "velocity")})
        setup = _burgers_setup(base)
    problem, grid, particles, stages = setup
    dt0 = problem.dt
    t_mid = round(0.5 * problem.T / dt0) * dt0
    mid = state_at(problem, grid, particles, stages, t_mid)
    local = local_errors(problem, grid, mid, stages, t_mid, [dt0 / k for k in LOCAL_REFINES], LOCAL_SUBSTEPS)
    return {"global": rows, "local": local}


def crossing_case(case: dict) -> dict:
    """C2: one particle's path through the fan of the Burgers rarefaction; the jump of
    ``dA/dt`` at each node crossing, measured and predicted."""
    settings = burgers.BurgersSettings(basis=case["basis"], acceleration=case["acceleration"], **CROSSING)
    recorder = Recorder(CROSSING_PARTICLE)
    result = burgers.simulate(settings, progress=False, observer=recorder)
    track = recorder.track()
    rounded = lambda a: [float(f"{v:.8g}") for v in a]  # noqa: E731
    return {"rows": crossing_jumps(track, result.grid.nodes),
            "trace": {"t": rounded(track.t), "A": rounded(track.A), "x": rounded(track.x)}}


def run_case(case: dict) -> dict:
    return {"time": time_case, "crossing": crossing_case}[case["kind"]](case)


def run(options: StudyOptions) -> None:
    """Every case in one sweep, then the tables and figures."""
    got = options.sweep_plan(NAME, run_case, plan(options.tier))
    folder = options.folder(NAME)
    settings = {"burgers": BURGERS, "quick": options.quick, "pulse": PULSE.as_dict(), "crossing": CROSSING,
                "crossing_particle": CROSSING_PARTICLE, "time_refines": TIME_REFINES,
                "time_reference": TIME_REFERENCE, "local_substeps": LOCAL_SUBSTEPS, "local_refines": LOCAL_REFINES}
    rows, local_rows = time_rows(got["time"])
    crossings = crossing_rows(got["crossing"])
    publish(folder, {TIME_ORDER: rows, TIME_LOCAL_ERROR: local_rows, "crossing": crossings,
                     TIME_CROSSING_SUMMARY: crossing_summary(crossings, rows)}, settings)
    draw(folder, TIME_PLOT, rows + [{**r, "quantity": "local " + r["quantity"]} for r in local_rows])
    crossing_figure(folder / "crossing.png", got["crossing"], crossings)


# ---------------------------------------------------------------- tables

def _orders(rows: list[dict], q: str) -> tuple[list, float]:
    """Orders between successive steps and the least-squares order of ``q`` against ``dt``."""
    dts, errs = [r["dt"] for r in rows], [r[q] for r in rows]
    return [""] + [float(o) for o in observed_order(dts, errs)], float(np.polyfit(np.log(dts), np.log(errs), 1)[0])


def time_rows(got: dict) -> tuple[list, list]:
    """``time_order``: one row per problem, basis, quantity and dt (global error); ``local_error``:
    the same for one step from T/2."""
    rows, local_rows = [], []
    for (problem, basis), r in got.items():
        for table, runs, quantities in ((rows, r["global"], ("x", "velocity", "density")),
                                        (local_rows, r["local"], ("x", "velocity"))):
            for q in (q for q in quantities if q in runs[0]):
                orders, fit = _orders(runs, q)
                table += [{"problem": problem, "basis": basis, "quantity": q,
                           **({"refine": row["refine"]} if "refine" in row else {}),
                           "dt": row["dt"], "error": row[q], "order": o, "fitted_order": fit}
                          for row, o in zip(runs, orders, strict=True)]
    return rows, local_rows


def crossing_rows(got: dict) -> list[dict]:
    """One row per node crossing: measured and predicted jump of dA/dt, and their ratio."""
    return [{"basis": basis, "acceleration": acc, **row,
             "ratio": row["measured"] / row["predicted"] if row["predicted"] else float("nan")}
            for (basis, acc), r in got.items() for row in r["rows"]]


def crossing_summary(rows: list[dict], time_order: list[dict] = ()) -> list[dict]:
    """Per basis and acceleration: the crossings, the median and worst measured/predicted ratio, the
    median size of the measured jump and C2's second half beside it: ``jump_ratio``, the median over the
    crossings of |measured jump| / |the slides' P1 formula| (P1 with the exact acceleration: about 1; a C1
    basis: its jump relative to P1's), and, from ``time_order`` (the global error of the particle velocity
    at fixed h, :func:`time_rows`), the basis's least-squares global order in dt on the pulse and on
    Burgers (calculated acceleration) and the widest range of its successive orders in dt over the two
    problems (``order_dt_spread``: how unevenly the error falls as dt is refined); empty where
    ``time_order`` has no such rows."""
    fits, spread = {}, {}
    for r in time_order:
        if r["quantity"] == "velocity":
            fits[(r["basis"], r["problem"])] = r["fitted_order"]
            orders = spread.setdefault(r["basis"], {}).setdefault(r["problem"], [])
            orders += [r["order"]] if r["order"] != "" else []
    out = []
    for basis, acc in dict.fromkeys((r["basis"], r["acceleration"]) for r in rows):
        sub = [r for r in rows if (r["basis"], r["acceleration"]) == (basis, acc)]
        ratio = np.array([r["ratio"] for r in sub])
        widths = [max(o) - min(o) for o in spread.get(basis, {}).values() if o]
        out.append({"basis": basis, "acceleration": acc, "crossings": len(sub), "median_ratio": float(np.median(ratio)),
                    "max_ratio_error": float(np.max(np.abs(ratio - 1))), "max_abs_ratio": float(np.max(np.abs(ratio))),
                    "median_abs_measured": float(np.median(np.abs([r["measured"] for r in sub]))),
                    "jump_ratio": float(np.median(np.abs(ratio))),
                    "order_dt_pulse": fits.get((basis, "pulse"), ""),
                    "order_dt_burgers": fits.get((basis, "burgers"), ""),
                    "order_dt_spread": float(max(widths)) if widths else ""})
    return out


# ---------------------------------------------------------------- figures

GLOBAL_SLOPE, LOCAL_SLOPE = 1, 2  # C1: the orders in dt the guides show
LOCAL_PANEL = f"one step: local error of x_p (slope {LOCAL_SLOPE})"
TIME_PLOT = Plot("time_order.png", "C1: error against dt at fixed h and particles", TIME_ORDER.stem, "dt", tuple(
    Curve(label, "error", fmt, where, panel, ("basis",)) for label, fmt, where, panel in (
        ("{basis}", "o-", {"problem": "pulse", "quantity": "velocity"},
         f"pulse: global velocity error (slope {GLOBAL_SLOPE})"),
        ("{basis}", "o-", {"problem": "burgers", "quantity": "velocity"},
         f"Burgers: global velocity error (slope {GLOBAL_SLOPE})"),
        ("pulse, {basis}", "o-", {"problem": "pulse", "quantity": "local x"}, LOCAL_PANEL),
        ("Burgers, {basis}", "s--", {"problem": "burgers", "quantity": "local x"}, LOCAL_PANEL))),
    xlabel="dt", ylabel="error", slopes=(GLOBAL_SLOPE, LOCAL_SLOPE))

def crossing_figure(path: Path, got: dict, rows: list[dict]) -> None:
    """dA/dt along the particle's path (exact acceleration) and A itself (calculated), node crossings dotted."""
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.4))
    for ax, acc in zip(axes, ("exact", "calculated"), strict=True):
        for basis in (b for b in BASES if (b, acc) in got):
            t, A = (np.asarray(got[(basis, acc)]["trace"][k]) for k in ("t", "A"))
            if acc == "exact":  # d^3 x_p/dt^3 = dA/dt, by differences of successive steps
                ax.plot(0.5 * (t[1:] + t[:-1]), np.diff(A) / np.diff(t), "-", lw=1, label=basis)
            else:
                ax.plot(t, A, "-", lw=0.8, label=basis)
        for r in rows:
            if r["basis"] == "mpm" and r["acceleration"] == acc:
                ax.axvline(r["t_cross"], color="gray", lw=0.5, ls=":")
        ax.set_xlabel("t")
        ax.set_ylabel("dA/dt = d^3 x_p / dt^3" if acc == "exact" else "A = sum_i S_ip a_i = d^2 x_p / dt^2")
        ax.set_title("C2, exact nodal acceleration: P1 jumps at every node crossing (dotted)" if acc == "exact" else
                     "calculated acceleration: a_i jumps when any particle crosses a node", fontsize=8)
        ax.legend(fontsize=7)
    save(fig, path, caption="C2: dA/dt along one particle's path (exact acceleration; P1 jumps at each node crossing, "
                            "dotted) and A itself (calculated acceleration)")


#: The cost model of :mod:`mpm_fem.app.estimate`: the full tier's 12 cases took 9.3 CPU-s (2026-11-26: CHANGES.md).
PLAN, COST, SECONDS_PER_COST = plan, (lambda case: 1.0), 0.8

if __name__ == "__main__":
    sys.exit(script_main(NAME))
