"""C11's mechanism: what makes Sod's particle density error grow as the mesh is refined?

With the Sod study's MPM settings (``studies.sod.MPM``) the particle density L1 error grows on the
finest meshes of the convergence table while the particle volumes drift from the space they fill
(``sum_p V_p - 1`` grows as h shrinks; ``figures/sod/convergence.csv``). Each variant below changes
one thing against the study settings (``"V + dt int dv/dx"`` one thing against ``"rho/(1+dt L)"``)
on every mesh of ``H``:

- the form of the density update, ``rho (1 - dt L)`` (slides), ``rho / (1 + dt L)``, ``rho exp(-dt L)``
  (:mod:`mpm_fem.core.models.euler`'s ``density_update``);
- the quadrature of the volume rate: ``L_p`` at the particle point, or ``dv_h/dx`` integrated over
  the particle domain (:func:`mpm_fem.core.volume.domain_rate`, the stages' ``volume_rate="domain"``),
  with the slides' form, and with ``rho / (1 + dt D)``, i.e. ``V_p^{n+1} = V_p^n + dt int_{chi_p}
  dv_h/dx dx``, the domain ends moving with the grid velocity;
- the time step (CFL 0.025, 0.1), the particles per cell (8, 32), the grid volume reset (``volume="grid"``).

Table ``drift.csv`` (:data:`mpm_fem.measure.schema.DRIFT`): per variant and mesh the particle and
nodal density L1 errors against the exact Riemann solution, the volume drift ``sum_p V_p - 1``, the
successive orders and the ratio to the study settings on the same mesh. The sentence C11's
explanation quotes is :func:`mpm_fem.measure.claims.drift.mechanism`, formatted from this table.
The density-update and volume-rate options run in the numpy step only
(:func:`mpm_fem.core.step.numpy_only`; ``kernel`` column); the others run the fused compiled step,
which takes the same steps as the numpy step (to round-off on a uniform grid). Neither option
changes the motion (:mod:`mpm_fem.core.models.euler`): their nodal error is the study settings'.

Layouts: every variant runs the regular layout (the study settings'); the seeded variants also run
jittered layouts (``SEEDS``, on ``SEED_H``), which show how far an order from one layout resolves
growth (the ``layout`` and ``seed`` columns).

The issue names ``figures/sod/drift.csv``: the table lives in its own study folder,
``figures/drift/``, so that no two studies write one folder (each study's tables, JSON and case
cache are its own). The full tier runs ``H``; the deep tier adds ``DEEP_H`` for every variant, the
``DEEP_VARIANTS`` on every mesh, and the ``DEEP_SEEDED`` variants' seeds on ``SEED_H``.
"""

from __future__ import annotations

import dataclasses
import sys

from mpm_fem.app.study import StudyOptions, publish, script_main
from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.models.euler import IdealGas
from mpm_fem.core.particles import PositivityError
from mpm_fem.core.step import Walls, numpy_only
from mpm_fem.measure.claims.drift import STUDY
from mpm_fem.measure.claims.rows import successive_orders
from mpm_fem.measure.schema import DRIFT
from mpm_fem.problems import sod
from mpm_fem.run import solve
from studies.sod import MPM

NAME = "drift"
H = (0.005, 0.0025, 0.00125, 0.000625)
DEEP_H = (0.0003125,)
#: The study settings' own options (off): the slides' density update, the point volume rate.
OFF = {"density_update": "linear", "volume_rate": "point"}
VARIANTS = {
    STUDY: {},
    "rho/(1+dt L)": {"density_update": "inverse"},
    "rho exp(-dt L)": {"density_update": "exp"},
    "domain rate, rho(1-dt D)": {"volume_rate": "domain"},
    "V + dt int dv/dx": {"volume_rate": "domain", "density_update": "inverse"},
    "CFL 0.025": {"cfl": 0.025},
    "CFL 0.1": {"cfl": 0.1},
    "8 ppc": {"ppc": 8},
    "32 ppc": {"ppc": 32},
    "grid volume": {"volume": "grid"},
}
#: Deep tier only: the full tier shows the domain rate with ``"V + dt int dv/dx"`` and the forms of the
#: density update with ``"rho/(1+dt L)"`` (the study's cost in the full tier).
DEEP_VARIANTS = ("rho exp(-dt L)", "domain rate, rho(1-dt D)")
#: The layouts beside the regular one: jittered, seeds SEEDS, on the meshes SEED_H, for the variants
#: SEEDED (the deep tier adds DEEP_SEEDED; its seeds stay on SEED_H: at DEEP_H they would cost three times
#: the rest of the deep study).
SEEDS = (1, 2, 3, 4, 5)
SEED_H = (0.00125, 0.000625)
SEEDED = (STUDY, "grid volume")
DEEP_SEEDED = ("V + dt int dv/dx",)
#: The quick tier's cases run on the numpy step (the same steps bit for bit, mpm_fem.run.solve.run): on
#: its two coarsest meshes they cost less than compiling the fused variants they need (the grid volume's
#: alone: 34 CPU-s, docs/performance.md)
QUICK = dict(H=(0.02, 0.01), SEED_H=(0.02, 0.01), SEEDS=SEEDS[:2], SEEDED=(STUDY,), kernel="numpy")


def _settings(case: dict) -> sod.SodSettings:
    return sod.SodSettings(h=case["h"], kernel=case["kernel"], volume=case["volume"], **{k: case[k] for k in MPM})


def _model(case: dict) -> IdealGas:
    return IdealGas(sod.SodSettings.gamma, case["av_linear"], case["av_quadratic"], case["density_update"])


def run_case(case: dict) -> dict:
    """One Sod run with the study settings and the case's changes: MPM as :func:`mpm_fem.problems.sod.simulate`
    runs it, the gas with the case's density update and the stages with its volume rate."""
    settings = _settings(case)
    grid = uniform_grid(*sod.DOMAIN, settings.h)
    problem = solve.Problem(model=_model(case), boundary=Walls(), T=settings.T, cfl=settings.cfl,
                            exact=sod.exact_fields(settings))
    stages = dataclasses.replace(settings.stages, volume_rate=case["volume_rate"])
    try:
        result = solve.run(problem, grid, sod.initial_particles(settings, grid), stages, progress=False,
                           kernel=settings.kernel)
    except (PositivityError, FloatingPointError) as err:
        return {"ok": False, "error": str(err)}
    density = sod.errors(settings, result)["density"]
    return {"ok": True, "particles_L1": density["particles"]["L1"], "nodes_L1": density["nodes"]["L1"],
            "volume_drift": float(result.particles.volume.sum() - 1.0), "steps": result.steps,
            "wall_s": result.wall_s}


def case(h: float, name: str, layout: str = "regular", seed: int = 0) -> dict:
    """The case of variant ``name`` at ``h`` on a layout: the study settings, the variant's changes, and
    the kernel that can take it (the fused one unless :func:`mpm_fem.core.step.numpy_only` says otherwise)."""
    c = {"h": h, **MPM, "volume": "carried", **OFF, **VARIANTS[name], "layout": layout, "seed": seed}
    stages = dataclasses.replace(_settings({**c, "kernel": "fused"}).stages, volume_rate=c["volume_rate"])
    return {**c, "kernel": "numpy" if numpy_only(_model(c), stages) else "fused"}


def _cost(c: dict) -> float:
    """Particles x steps (the numpy step about five times the fused one), to start the longest first."""
    return c["ppc"] / (c["h"] ** 2 * c["cfl"]) * (5.0 if c["kernel"] == "numpy" else 1.0)


def _config(tier: str) -> dict:
    """What the tier runs: the variants and meshes on the regular layout, the seeded variants, their
    seeds and meshes."""
    q = QUICK if tier == "quick" else {}
    deep = tier == "deep"
    return {"variants": [n for n in VARIANTS if deep or n not in DEEP_VARIANTS],
            "h": list(q.get("H", H + DEEP_H if deep else H)),
            "jittered": {"variants": list(q.get("SEEDED", SEEDED + DEEP_SEEDED if deep else SEEDED)),
                         "seeds": list(q.get("SEEDS", SEEDS)), "h": list(q.get("SEED_H", SEED_H))}}


def _plan(tier: str) -> dict:
    """``{"drift": {(h, variant, layout, seed): case}}``: every variant of the tier on the regular layout
    on every mesh of the tier, and the seeded variants on the jittered layouts (:func:`_config`)."""
    c = _config(tier)
    j = c["jittered"]
    plan = {(h, n, "regular", 0): case(h, n) for n in c["variants"] for h in c["h"]}
    plan.update({(h, n, "jittered", s): case(h, n, "jittered", s) for n in j["variants"] for s in j["seeds"]
                 for h in j["h"]})
    kernel = QUICK["kernel"] if tier == "quick" else None
    return {"drift": {k: {**c, "kernel": kernel} if kernel else c for k, c in plan.items()}}


def run(options: StudyOptions) -> None:
    got = options.sweep_plan(NAME, run_case, _plan(options.tier), cost=_cost)["drift"]
    rows, folder = table(got, QUICK["kernel"] if options.tier == "quick" else None), options.folder(NAME)
    config = _config(options.tier)
    publish(folder, {DRIFT: rows}, {"mpm": MPM, "tier": options.tier, **config,
                                    "changes": {n: VARIANTS[n] or "none" for n in config["variants"]},
                                    "T": sod.SodSettings.T})
    figure(folder, rows)


def table(got: dict, kernel: str | None = None) -> list[dict]:
    """The rows of ``drift.csv`` from ``{(h, variant, layout, seed): result}``: by variant, layout and
    seed, then by decreasing h; orders between successive meshes of one series, the ratio to the study
    settings on the same mesh and layout; ``kernel``: the step every case ran on (default: each case's own)."""
    rows = []
    series = dict.fromkeys((n, layout, seed) for n in VARIANTS for (_, v, layout, seed) in sorted(got, key=_order)
                           if v == n)
    for name, layout, seed in series:
        runs = sorted(((h, r) for (h, n, lay, s), r in got.items() if (n, lay, s) == (name, layout, seed)),
                      key=lambda hr: -hr[0])
        out = []
        for h, r in runs:
            row = {"h": h, "variant": name, "layout": layout, "seed": seed,
                   "change": str(VARIANTS[name]) if VARIANTS[name] else "none",
                   "kernel": kernel or case(h, name, layout, seed)["kernel"], "ok": r["ok"],
                   "steps": r.get("steps", "")}
            if r["ok"]:
                base = got.get((h, STUDY, layout, seed), {})
                row.update(particles_L1=r["particles_L1"], nodes_L1=r["nodes_L1"], volume_drift=r["volume_drift"],
                           abs_volume_drift=abs(r["volume_drift"]),
                           particles_vs_study=r["particles_L1"] / base["particles_L1"] if base.get("ok") else "")
            else:
                row.update({k: "" for k in ("particles_L1", "nodes_L1", "volume_drift", "abs_volume_drift",
                                            "particles_vs_study")}, error=r["error"])
            out.append(row)
        for key in ("particles_L1", "nodes_L1"):
            orders = successive_orders([{k: str(v) for k, v in row.items()} for row in out], key)
            for k, row in enumerate(out):
                row[f"order_{key}"] = orders[k - 1] if k else ""
        rows += out
    return rows


def _order(key: tuple) -> tuple:
    """Regular before jittered, then by seed."""
    _, _, layout, seed = key
    return layout != "regular", seed


_PANELS = (("particles_L1", "particle density L1"), ("nodes_L1", "nodal density L1"),
           ("abs_volume_drift", "|sum of particle volumes - 1|"))
#: Line style per variant: the study settings black, the density forms dashed, the volume rate solid,
#: the time step and the particles per cell dotted, the grid volume dash-dotted.
STYLES = {STUDY: "ko-", "rho/(1+dt L)": "v--", "rho exp(-dt L)": "^--", "domain rate, rho(1-dt D)": "s-",
          "V + dt int dv/dx": "D-", "CFL 0.025": "<:", "CFL 0.1": ">:", "8 ppc": "x:", "32 ppc": "+:",
          "grid volume": "o-."}
CAPTION = ("C11's mechanism: Sod's particle density L1 error, nodal density L1 error and volume drift against h, "
           "one line per variant of the study settings")


def figure(folder, rows: list[dict]) -> None:
    """``drift.png``: three log-log panels against h (particle L1, nodal L1, ``|sum_p V_p - 1|``), one
    line per variant on the regular layout (:data:`STYLES`), its jittered seeds as dots of its colour,
    the legend in the fourth place of the grid."""
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter

    from mpm_fem.app import plots

    fig, axes = plt.subplots(2, 2, figsize=(9.6, 7.6))
    for name in VARIANTS:
        ok = [r for r in rows if r["variant"] == name and r["ok"]]
        line = sorted((r for r in ok if r["layout"] == "regular"), key=lambda r: r["h"])
        dots = [r for r in ok if r["layout"] != "regular"]
        for ax, (y, _) in zip(axes.ravel(), _PANELS, strict=False):
            drawn = ax.loglog([r["h"] for r in line], [r[y] for r in line], STYLES.get(name, "o-"), ms=4, lw=1.1,
                              mfc="none", label=name)
            if dots:
                ax.loglog([r["h"] for r in dots], [r[y] for r in dots], ".", ms=3, alpha=0.6,
                          color=drawn[0].get_color() if drawn else None)
    for ax, (_, title) in zip(axes.ravel(), _PANELS, strict=False):
        ax.set(title=title, xlabel="h")
        ax.title.set_fontsize(9)
        ax.xaxis.set_minor_formatter(NullFormatter())
    axes[1, 1].axis("off")
    axes[1, 1].legend(*axes[0, 0].get_legend_handles_labels(), loc="center", fontsize=8,
                      title="variant, regular layout (dots: jittered seeds)", title_fontsize=8)
    plots.save(fig, folder / "drift.png", CAPTION)


#: The cost model of :mod:`mpm_fem.app.estimate`: CPU seconds per unit of :func:`_cost`, from the full
#: tier's cases on the 2-core machine (2026-11-26, from-scratch run: CHANGES.md).
PLAN, COST, SECONDS_PER_COST = _plan, _cost, 1.6e-8

if __name__ == "__main__":
    sys.exit(script_main(NAME))
