"""The local defect of the particle update, accumulated over a run, beside the run's particle error.

Each run of the mechanism study's all-MPM setting (:mod:`studies.mechanism`: the budget's Sod and
Burgers, :data:`studies.budget.SOD`, :data:`studies.budget.BURGERS`, point-mass MPM, FLIP, USL, lumped
mass) runs once more on the numpy step with :class:`mpm_fem.measure.defect.DefectObserver`, which measures
at every step the defect of each quantity the particle update takes from the grid against its exact value
at that step (the exact stages' reference fields ``v*``, ``v*_x``, ``a*``): the nodal acceleration ``a_i``
and velocity ``v_i^{n+1}``, the particle acceleration ``sum_i S_ip a_i``, the motion ``sum_i S_ip
v_i^{n+1}`` and the rate ``L_p = sum_i G_ip v_i^{n+1}``; and accumulates them along each particle's path
with the update's own propagation (the equations: :mod:`mpm_fem.measure.defect`). The accumulated defect of
the measured quantity (Sod density: rate + velocity components; Burgers velocity: acceleration + velocity)
is the run's predicted particle error. Predicted and measured errors are in the budget's norm
(:func:`studies.budget.norm_points`: the trapezoid rule over the piecewise-linear particle field minus the
exact solution): ``measured_L1`` is the run's particle error (the mechanism study's v(all MPM) of the same
run to round-off: the numpy step, not the fused one), ``predicted_L1`` the norm of the field through the
accumulated defects, ``ratio`` = predicted / measured. Beside them: ``at_particles_L1`` the norm of the
field through the particle errors ``q_p - q*(x_p)`` (what the prediction predicts), ``residual_L1`` that of
the particle errors minus the accumulated defects (what the prediction misses), ``floor_L1`` the norm's
own error with exact particle values, each component's norm (``acceleration_L1`` in velocity,
``velocity_L1`` in the measured quantity, ``rate_L1`` in density; for Burgers the volume's drift in density
units, outside its prediction) and the per-step L1 norms of the defects averaged over the steps
(``defect_a``, ``defect_v`` over the nodes, weights ``int N_i dx``; ``defect_L`` over the particles,
weights ``V_p``). Table ``defect.csv``, one row per run; figure ``defect.png``.

What the prediction leaves out: the time error of semi-implicit Euler on the exact fields, terms of second
order in the errors, and the response of the grid's values to the error the particles already carry: the
defect is measured on the run's own state, so a defect caused by an earlier error (Burgers' viscosity
diffusing it) is counted as new. The first-order accounting is the limit dt -> 0: on Burgers' coarsest
mesh (h = 0.08, 4 per cell, regular) the ratio is 2.65 at the study's step, 1.69 at dt / 4 and 1.16 at
dt / 16, where its diffusive step (CFL 0.5 of h^2 / (2 eps)) changes the error by O(1) in one step.

Measured on the full tier (CHANGES.md, 2026-11-28): on Sod the accumulated defect predicts the density
error within 0.81-1.01 of the measured on every run, its growth under refinement with it (4 per cell,
jittered, h = 0.00125: 0.81-0.83); the particle errors minus the defects keep 0.12-0.39 of the measured
norm. On Burgers 1.00-1.30 on h = 0.01, 2.3-4.7 on h = 0.08, where the step is the least resolved.

Tiers: the quick tier runs each problem's two coarsest meshes at 4 per cell on the regular layout and seed
1 (seconds). The full tier runs the mechanism study's full settings (4 and 8 per cell, the regular layout
and jittered seeds 1-5, Sod h = 0.01 ... 0.00125, Burgers h = 0.08 ... 0.01, :data:`FULL`; about 4 CPU-min:
the instrumented numpy step is cheap enough to keep the finest mesh); the deep tier adds the mechanism's deep
meshes and 16 per cell.
"""

from __future__ import annotations

import sys
from dataclasses import replace

import numpy as np

from mpm_fem.app.plots import grid_shape, plt, save, slope_guides
from mpm_fem.app.study import StudyOptions, publish, script_main
from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.particles import PositivityError
from mpm_fem.core.step import Dirichlet, Walls
from mpm_fem.measure.claims.model import FIT_PPC, model_rows
from mpm_fem.measure.defect import DefectObserver
from mpm_fem.measure.schema import DEFECT, MODEL, MODEL_FIT
from mpm_fem.measure.timing import field_on
from mpm_fem.problems import burgers, sod
from studies.budget import BURGERS, SOD, _layout_changes, _settings, _steps, norm_points, setting_of
from studies.mechanism import DEEP as MECHANISM_DEEP
from studies.mechanism import FULL as MECHANISM_FULL
from studies.mechanism import LAYOUTS

NAME = "defect"
BASIS = "mpm"
#: the quantity each problem's particle error measures (the budget's)
QUANTITY = {"sod": "density", "burgers": "velocity"}
QUICK = {"ppc": (4,), "h": {"sod": (0.02, 0.01), "burgers": (0.08, 0.04)}, "layouts": LAYOUTS[:2]}
FULL = {"ppc": MECHANISM_FULL["ppc"], "h": MECHANISM_FULL["h"], "layouts": LAYOUTS}
DEEP = {"ppc": MECHANISM_DEEP["ppc"], "h": MECHANISM_DEEP["h"], "layouts": LAYOUTS}
TIERS = {"quick": QUICK, "full": FULL, "deep": DEEP}


def _case(problem: str, h: float, ppc: int, layout: str, seed: int) -> dict:
    return {"kind": "defect", "problem": problem, "h": h, "basis": BASIS, **_layout_changes(problem, ppc, layout, seed)}


def plan(tier: str) -> dict:
    """``{"defect": {(problem, ppc, layout, seed, h): case}}`` of the tier (:data:`TIERS`)."""
    t = TIERS[tier]
    return {"defect": {(p, n, lay, s, h): _case(p, h, n, lay, s) for p, meshes in t["h"].items()
                       for n in t["ppc"] for lay, s in t["layouts"] for h in meshes}}


#: CPU milliseconds per step of an instrumented run (the numpy step and the observer), ``a + b N`` for ``N``
#: particles, per problem: scaled to the full tier's 96 runs on the 2-core machine shared with another job
#: (3.75 CPU-min, CHANGES.md)
STEP_MS = {"sod": (0.55, 1.8e-4), "burgers": (1.45, 2.4e-4)}


def cost(case: dict) -> float:
    """Estimated CPU milliseconds of a case (:data:`STEP_MS`)."""
    problem, h = case["problem"], case["h"]
    a, b = STEP_MS[problem]
    length = 1.0 if problem == "sod" else 2.0
    return _steps(problem, h) * (a + b * setting_of(problem, case)["ppc"] * length / h)


# ---------------------------------------------------------------- one case

def instrument(problem: str, settings) -> tuple[DefectObserver, object]:
    """The observer of a run of ``problem`` with ``settings`` and the problem's module: the exact fields and
    grid boundary rule the run uses, and the slope of the measured quantity's exact field (Sod: the density's
    averaged over the exact stages' cell, ``(rho(x + l) - rho(x - l)) / (2 l)``, as ``v*_x`` is; Burgers:
    ``v_x``)."""
    module = sod if problem == "sod" else burgers
    fields = module.exact_fields(settings)
    if problem == "sod":
        grid, boundary, l = uniform_grid(*sod.DOMAIN, settings.h), Walls(), fields.half_width

        def slope(x, t):
            return (fields.integrand(x + l, t)[0] - fields.integrand(x - l, t)[0]) / (2 * l)
    else:
        grid, boundary = uniform_grid(*settings.exact.domain, settings.h), Dirichlet(settings.exact.v)
        slope = fields.velocity_gradient
    return DefectObserver(grid, boundary, fields, settings.stages, QUANTITY[problem], slope), module


def run_case(case: dict) -> dict:
    """One instrumented run: its measured and predicted particle errors and the components (module docstring)."""
    problem, h = case["problem"], case["h"]
    changes = {k: case[k] for k in ("ppc", "layout", "seed") if k in case}
    settings = replace(_settings(problem, h, BASIS, changes), kernel="numpy")
    observer, module = instrument(problem, settings)
    try:
        result = module.simulate(settings, progress=False, observer=observer)
    except (PositivityError, FloatingPointError, ValueError) as err:
        return {"ok": False, "error": str(err)}
    observer.finish(result.t)
    return {"ok": True, "steps": result.steps, "wall_s": result.wall_s,
            **norms(problem, settings, result.particles, result.t, observer)}


def norms(problem: str, settings, particles, t: float, observer: DefectObserver) -> dict:
    """The measured and predicted particle errors, the components and the mean defects of a finished run."""
    points, weights = norm_points(problem, settings)
    x = particles.x

    def exact(y):
        return sod.exact(settings, y, t)[0] if problem == "sod" else settings.exact.v(y, t)

    def l1(values):  # the budget's norm of the piecewise-linear field through (x_p, values)
        return float(np.sum(weights * np.abs(values)))

    q = particles.density if problem == "sod" else particles.velocity
    q_star, on_points = exact(x), exact(points)
    measured, predicted = l1(field_on(points, x, q) - on_points), l1(field_on(points, x, observer.predicted()))
    mean = observer.mean_defects()
    return {"measured_L1": measured, "predicted_L1": predicted, "ratio": predicted / measured,
            "at_particles_L1": l1(field_on(points, x, q - q_star)),
            "residual_L1": l1(field_on(points, x, q - q_star - observer.predicted())),
            "floor_L1": l1(field_on(points, x, q_star) - on_points),
            **{f"{c}_L1": l1(field_on(points, x, v)) for c, v in observer.carried.items()},
            "defect_a": mean["a"], "defect_v": mean["v"], "defect_L": mean["L"]}


# ---------------------------------------------------------------- table

def rows_of(got: dict) -> list[dict]:
    """``defect.csv`` from ``{(problem, ppc, layout, seed, h): result}``, one row per run."""
    return [{"problem": p, "basis": BASIS, "ppc": n, "layout": lay, "seed": s, "h": h, **r}
            for (p, n, lay, s, h), r in got.items()]


def run(options: StudyOptions) -> None:
    got = options.sweep_plan(NAME, run_case, plan(options.tier), cost=cost)["defect"]
    rows = rows_of(got)
    t = TIERS[options.tier]
    settings = {"sod": SOD, "burgers": BURGERS, "basis": BASIS, "kernel": "numpy", "quantity": QUANTITY,
                "ppc": list(t["ppc"]), "h": {p: list(hs) for p, hs in t["h"].items()},
                "layouts": [f"{lay} {s}" for lay, s in t["layouts"]]}
    folder = options.folder(NAME)
    model, constants = model_rows(rows) if any(r["ok"] for r in rows) else ([], [])
    publish(folder, {DEFECT: rows, MODEL: model, MODEL_FIT: constants}, settings)
    figure(folder, [r for r in rows if r["ok"]])
    figure(folder, model, ("model_L1", "model"), "model.png",
           "The measured particle L1 error and the closed-form defect model's (E6, fitted on the coarse meshes at "
           f"{FIT_PPC} per cell) against h, jittered layouts' mean and regular")


# ---------------------------------------------------------------- figure

def figure(folder, rows: list[dict], predicted=("predicted_L1", "predicted"), name="defect.png",
           caption="The measured particle L1 error and the accumulated defect's prediction against h, jittered "
                   "layouts' mean and regular") -> None:
    """``defect.png`` (or ``name``): per problem and particles per cell, the measured (solid) and predicted
    (dashed; the column ``predicted[0]``, labelled ``predicted[1]``) particle L1 error against h (log-log): the
    jittered layouts' mean and the regular layout (dotted)."""
    from matplotlib.ticker import NullFormatter

    panels = sorted({(r["problem"], r["ppc"]) for r in rows}, key=lambda k: (k[0] != "sod", k[1]))
    if not panels:
        return
    nrows, ncols = grid_shape(len(panels), (4.2, 3.6))
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.2 * ncols, 3.6 * nrows), squeeze=False)
    for ax in axes.ravel()[len(panels):]:
        ax.set_visible(False)
    for ax, (p, n) in zip(axes.ravel(), panels, strict=False):
        sub = [r for r in rows if (r["problem"], r["ppc"]) == (p, n)]
        hs = sorted({r["h"] for r in sub})
        for column, color in (("measured_L1", "k"), (predicted[0], "tab:red")):
            label = "measured" if column == "measured_L1" else predicted[1]
            for layout, style in (("jittered", "o-"), ("regular", "s:")):
                values = [[r[column] for r in sub if r["h"] == h and r["layout"] == layout] for h in hs]
                if all(values):
                    ax.loglog(hs, [np.mean(v) for v in values], style if label == "measured" else style.replace(
                        "-", "--"), ms=3, lw=1.1, color=color, label=f"{label}, {layout}")
        slope_guides(ax, hs, min(r["measured_L1"] for r in sub), (1,))
        ax.set_xticks(hs, [f"{h:g}" for h in hs])
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set(xlabel="h", ylabel=f"particle {QUANTITY[p]} error (L1)", title=f"{p}, {n} per cell")
    axes[0][0].legend(fontsize=7)
    save(fig, folder / name, caption=caption)


#: The cost model of :mod:`mpm_fem.app.estimate`: :func:`cost` is in CPU milliseconds (:data:`STEP_MS`).
PLAN, COST, SECONDS_PER_COST = plan, cost, 1e-3

if __name__ == "__main__":
    sys.exit(script_main(NAME))
