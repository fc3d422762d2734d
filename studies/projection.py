"""Projection and particle-quadrature errors (claims C4-C10).

Caption: smooth fields ``rho = 1 + 0.5 sin(2 pi x)``, ``v = sin(2 pi x)``, ``p = rho^1.4`` on [0, 1]
are sampled by ``N_p`` in {1, 2, 4, 8, 16, 32} particles per cell on meshes h = 1/10 ... 1/2560 in
four layouts: regular midpoints, jittered (one uniform point per sub-cell), random (``N_p``
uniform points per cell) - both over several seeds, mean and spread reported - and advected
(regular particles moved by a kinematic MPM run in ``u = 0.1 sin(2 pi x)`` for T = 0.8). Each
nodal projection of the slides is compared with the exact integral it stands in for
(:mod:`mpm_fem.measure.projection`), with the slides' weights ``h/N_p^i`` and, for the advected layout,
also with the volumes ``V_p`` the run carries. Hickernell's ``D2`` and bound
(:mod:`mpm_fem.measure.quadrature`) are measured on every cell.

Tables (``figures/projection/``): ``errors.csv`` (quantity, layout, weights, N_p, h, norm, value,
spread), ``orders.csv`` (least-squares order over all h, the orders between the two coarsest and
the two finest meshes and between every pair of successive meshes, the source's band, inside),
``d2.csv``, ``d2_constant.csv`` (the C of ``D2 ~ [1/(12 N^2) + C h^2]^{1/2}``), ``bounds.csv``
(smallest bound/error ratio). Figures:
``errors_vs_h.png``, ``errors_vs_h_random.png``, ``d2.png``, ``hickernell.png``.
"""

from __future__ import annotations

import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

from mpm_fem.app import plots
from mpm_fem.app.plots import Curve, Plot
from mpm_fem.app.study import StudyOptions, publish, script_main
from mpm_fem.core.grid import uniform_grid
from mpm_fem.measure.claims import BAND_TOLERANCE
from mpm_fem.measure.errors import fitted_order, observed_orders
from mpm_fem.measure.projection import (
    QUANTITIES,
    Advection,
    cell_weights,
    layout,
    projection_errors,
    quadrature_checks,
    smooth_fields,
)
from mpm_fem.measure.quadrature import cell_points, discrepancy_d2, estimate_c, expected_offset, offset_term
from mpm_fem.measure.schema import PROJECTION_BOUNDS, PROJECTION_D2_CONSTANT, PROJECTION_ORDERS
from mpm_fem.measure.source import D2_C, PROJECTION_BANDS, band_text

NAME = "projection"
CELLS = [10 * 2**k for k in range(9)]  # h = 1/10 ... 1/2560
PPC = [1, 2, 4, 8, 16, 32]
LAYOUT_NAMES = ("regular", "jittered", "random", "advected")
SEEDS = 5
QUICK = {"cells": CELLS[:6], "ppc": [1, 4, 16], "seeds": 3}
GAMMA = 1.4
ADVECTION = Advection()
BANDS, TOLERANCE, SLIDES_C = PROJECTION_BANDS, BAND_TOLERANCE, D2_C
#: (weights, basis) of the projections: the slides' point-mass sums with h/N_p^i; with the volumes
#: V_p a run carries (differs from h/N_p^i only once particles moved); GIMP with V_p (E2).
VARIANTS = (("cell", "mpm"), ("volume", "mpm"), ("volume", "gimp"))
SAMPLE = 12  # (bound, error) pairs kept per check and case for the figure


def case(c: dict) -> dict:
    """Every error norm, D2 statistic and bound check of one (layout, N_p, h, seed)."""
    grid = uniform_grid(0.0, 1.0, 1.0 / c["cells"])
    fields = smooth_fields(GAMMA)
    x, V = layout(grid, c["layout"], c["ppc"], c["seed"], ADVECTION, fields.rho)
    weights = {"cell": cell_weights(grid, x), "volume": V}
    errors = {f"{w}:{b}": projection_errors(grid, x, weights[w], fields, b).norms()
              for w, b in VARIANTS if (w, b) != ("volume", "mpm") or c["layout"] == "advected"}
    count = cell_points(grid, x).count
    d2, delta = discrepancy_d2(grid, x), offset_term(grid, x)
    bounds = {}
    for name, check in quadrature_checks(grid, x, fields).items():
        e, b = np.abs(check.error), check.bound
        ok = np.flatnonzero(np.isfinite(b) & (e > 0))
        keep = ok[np.linspace(0, ok.size - 1, min(SAMPLE, ok.size)).astype(int)] if ok.size else ok
        if ok.size:
            keep = np.union1d(keep, ok[np.argmin(b[ok] / e[ok])])
        bounds[name] = {"min_ratio": check.min_ratio, "entries": int(ok.size),
                        "sample": [[float(b[k]), float(e[k])] for k in keep]}
    return {
        "errors": errors,
        "d2": {"mean": float(np.nanmean(d2)), "min": float(np.nanmin(d2)), "max": float(np.nanmax(d2)),
               "delta_mean": float(np.nanmean(delta)), "empty_cells": int((count == 0).sum()),
               "count_min": int(count.min()), "count_max": int(count.max()),
               "volume_sum": float(V.sum())},
        "bounds": bounds,
    }


def cases(options: StudyOptions) -> list[dict]:
    cells, ppc, seeds = (QUICK["cells"], QUICK["ppc"], QUICK["seeds"]) if options.quick else (CELLS, PPC, SEEDS)
    return [{"layout": lay, "ppc": n, "cells": k, "seed": s}
            for lay in LAYOUT_NAMES for n in ppc for k in cells
            for s in (range(seeds) if lay in ("jittered", "random") else (0,))]


def _inside(quantity: str, order: float, reference: dict) -> bool:
    band = BANDS[quantity]
    if isinstance(band, str):
        return abs(order - reference[band]) <= TOLERANCE
    return band[0] - TOLERANCE <= order <= band[1] + TOLERANCE


def _quantities_first(item) -> tuple:
    """The order of the error rows: by quantity (in :data:`QUANTITIES`' order), then by the rest of the key."""
    (quantity, *rest), _ = item
    return (QUANTITIES.index(quantity), *rest)


def tables(results: list[tuple[dict, dict]]) -> dict[str, list[dict]]:
    """Aggregate the case results over seeds into the study's tables."""
    errs = defaultdict(list)  # (quantity, layout, weights, basis, N_p, cells, norm) -> values over seeds
    d2s, bounds = defaultdict(list), defaultdict(list)
    for c, r in results:
        for variant, qs in r["errors"].items():
            weights, basis = variant.split(":")
            for q, ns in qs.items():
                for norm, value in ns.items():
                    errs[(q, c["layout"], weights, basis, c["ppc"], c["cells"], norm)].append(value)
        d2s[(c["layout"], c["ppc"], c["cells"])].append(r["d2"])
        for check, b in r["bounds"].items():
            bounds[(check, c["layout"], c["ppc"], c["cells"])].append(b)

    error_rows = []
    by_quantity = sorted(errs.items(), key=_quantities_first)
    for (q, lay, weights, basis, n, k, norm), v in by_quantity:
        v = np.asarray(v)
        error_rows.append({"quantity": q, "layout": lay, "weights": weights, "basis": basis, "N_p": n, "h": 1.0 / k,
                           "norm": norm, "value": float(v.mean()), "spread": float(v.std()), "min": float(v.min()),
                           "max": float(v.max()), "seeds": int(v.size)})

    series = defaultdict(dict)  # (layout, weights, basis, N_p, norm) -> {quantity: (h, values)}
    for row in error_rows:
        key = (row["layout"], row["weights"], row["basis"], row["N_p"], row["norm"])
        h, val = series[key].setdefault(row["quantity"], ([], []))
        h.append(row["h"])
        val.append(row["value"])
    order_rows = []
    for (lay, weights, basis, n, norm), by_q in series.items():
        fitted = {q: fitted_order(*by_q[q]) for q in by_q}
        for q in QUANTITIES:
            h, val = by_q[q]
            steps = observed_orders(h, val)
            order_rows.append({"quantity": q, "layout": lay, "weights": weights, "basis": basis, "N_p": n, "norm": norm,
                               "order": fitted[q], "order_coarse": float(steps[0]), "order_fine": float(steps[-1]),
                               "successive": " ".join(f"{p:.2f}" for p in steps),
                               "band": band_text(q), "inside": "yes" if _inside(q, fitted[q], fitted) else "no"})

    d2_rows = []
    for (lay, n, k), ds in sorted(d2s.items()):
        mean = lambda key, ds=ds: float(np.mean([d[key] for d in ds]))  # noqa: E731
        expected = expected_offset(lay, n) if lay != "advected" else float("nan")
        d2_rows.append({"layout": lay, "N_p": n, "h": 1.0 / k, "D2_mean": mean("mean"),
                        "D2_min": float(min(d["min"] for d in ds)), "D2_max": float(max(d["max"] for d in ds)),
                        "D2_times_N": mean("mean") * n, "delta_mean": mean("delta_mean"), "delta_expected": expected,
                        "empty_cells": int(max(d["empty_cells"] for d in ds)),
                        "count_min": int(min(d["count_min"] for d in ds)),
                        "count_max": int(max(d["count_max"] for d in ds)),
                        "seeds": len(ds)})

    c_rows = []
    for lay in LAYOUT_NAMES:
        for n in sorted({r["N_p"] for r in d2_rows if r["layout"] == lay}):
            rows = [r for r in d2_rows if r["layout"] == lay and r["N_p"] == n]
            h = np.array([r["h"] for r in rows])
            # the slides' literal D2 (offsets in physical units): D2^2 = 1/(12 N^2) + h^2 delta
            literal = np.sqrt(1 / (12.0 * n**2) + h**2 * np.array([r["delta_mean"] for r in rows]))
            c = estimate_c(h, np.full(h.size, n), literal)
            c_rows.append({"layout": lay, "N_p": n, "C": c, "delta_expected": rows[0]["delta_expected"],
                           "source_band": f"[{SLIDES_C[0]:.3g}, {SLIDES_C[1]:.3g}]",
                           "inside": "yes" if SLIDES_C[0] <= c <= SLIDES_C[1] else "no"})

    bound_rows = []
    for (check, lay, n, k), bs in sorted(bounds.items()):
        bound_rows.append({"check": check, "layout": lay, "N_p": n, "h": 1.0 / k,
                           "min_ratio": float(min(b["min_ratio"] for b in bs)),
                           "entries": int(sum(b["entries"] for b in bs)),
                           "holds": "yes" if min(b["min_ratio"] for b in bs) >= 1 else "no"})
    return {"errors": error_rows, PROJECTION_ORDERS.stem: order_rows, "d2": d2_rows,
            PROJECTION_D2_CONSTANT.stem: c_rows, PROJECTION_BOUNDS.stem: bound_rows}


def settings(options: StudyOptions) -> dict:
    cells, ppc, seeds = (QUICK["cells"], QUICK["ppc"], QUICK["seeds"]) if options.quick else (CELLS, PPC, SEEDS)
    return {
        "quick": options.quick,
        "fields": {"rho": "1 + 0.5 sin(2 pi x)", "v": "sin(2 pi x)", "p": f"rho^{GAMMA}", "domain": [0, 1]},
        "h": [1.0 / k for k in cells], "N_p": ppc, "layouts": list(LAYOUT_NAMES), "seeds": seeds,
        "jitter": 1.0,
        "advection": {"velocity": f"{ADVECTION.amplitude} sin(2 pi x)", "T": ADVECTION.T, "cfl": ADVECTION.cfl,
                      "start": "regular", "update": "kinematic MPM (USL positions, V_p *= 1+dt dv/dx)"},
        "weights": {"cell": "h / N_p^i (slides)", "volume": "V_p carried by the run (= h/N_p for seeded layouts)"},
        "variants": [f"{w}:{b}" for w, b in VARIANTS],
        "bases": {"mpm": "point mass S_i(x_p)", "gimp": "hats averaged over [x_p - V_p/2, x_p + V_p/2]"},
        "nodes": "interior nodes (whole hats); norms weighted by h (nodes, cells) or w_p (particles)",
        "exact_integrals": "Gauss-Legendre, 20 points per cell",
        "bands": {q: band_text(q) for q in QUANTITIES}, "tolerance": TOLERANCE, "slides_C": list(SLIDES_C),
    }


def run(options: StudyOptions) -> None:
    folder = options.folder(NAME)
    cs = cases(options)
    results = options.sweep(NAME, case, cs)
    t = tables(list(zip(cs, results, strict=True)))
    s = settings(options)
    declared = {table.stem: table for table in (PROJECTION_ORDERS, PROJECTION_D2_CONSTANT, PROJECTION_BOUNDS)}
    publish(folder, {declared.get(name, name): rows for name, rows in t.items()}, s)
    figures(folder, t, [(c, r) for c, r in zip(cs, results, strict=True)])


# ----------------------------------------------------------------------------- figures

COLORS = {"regular": "tab:blue", "jittered": "tab:orange", "random": "tab:green", "advected": "tab:red"}

N_SHOW = 4  # the particle count of the per-layout figure (in every plan)
_VARIANT = {("cell", "mpm"): ("", "o-"), ("volume", "mpm"): (", V_p weights", "s--"),
            ("volume", "gimp"): (", GIMP, V_p", "^:")}
_PANELS = dict(split=("quantity",), ncols=3, slopes=(1, 2), ylabel="error (L1; E_VG over particles)", size=(4.0, 3.5))
PLOTS = (
    Plot("errors_vs_h.png", f"Projection errors against h, N_p = {N_SHOW} (mean over seeds): point mass with the "
         "slides' weights h/N_p^i unless marked", "errors", "h", tuple(
             Curve(lay + suffix, "value", fmt, {"layout": lay, "weights": w, "basis": b, "N_p": N_SHOW, "norm": "L1"},
                   options={"color": COLORS[lay]})
             for lay in LAYOUT_NAMES for (w, b), (suffix, fmt) in _VARIANT.items()
             if b == "mpm" or lay in ("advected", "random")),
         **_PANELS),
    Plot("errors_vs_h_random.png", "Projection errors against h, random layouts (mean over seeds), one line per N_p",
         "errors", "h", (Curve("N_p = {N_p}", "value", "o-", {"layout": "random", "basis": "mpm", "norm": "L1"},
                               group=("N_p",)),),
         **_PANELS),
)


def figures(folder: Path, t: dict, results: list) -> None:
    import matplotlib.pyplot as plt

    for plot in PLOTS:
        plots.draw(folder, plot, t[plot.table])
    ppcs, n_show = sorted({r["N_p"] for r in t["errors"]}), N_SHOW
    # D2 against N_p (finest mesh) and against h (N_p shown above)
    d2 = t["d2"]
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
    finest = min(r["h"] for r in d2)
    for lay in LAYOUT_NAMES:
        sel = [r for r in d2 if r["layout"] == lay and r["h"] == finest]
        rms = [np.sqrt(1 / (12 * r["N_p"] ** 2) + r["delta_mean"]) for r in sel]
        a1.loglog([r["N_p"] for r in sel], rms, "o", color=COLORS[lay], label=lay)
        if lay in ("jittered", "random"):
            n = np.array(ppcs, float)
            a1.loglog(n, np.sqrt(1 / (12 * n**2) + np.array([expected_offset(lay, int(k)) for k in n])), "-",
                      color=COLORS[lay], lw=0.8)
        sel = [r for r in d2 if r["layout"] == lay and r["N_p"] == n_show]
        a2.loglog([r["h"] for r in sel], [r["D2_mean"] for r in sel], "o-", color=COLORS[lay], label=lay)
    n = np.array(ppcs, float)
    a1.loglog(n, 1 / (np.sqrt(12) * n), "k-", lw=0.8, label="1/(sqrt(12) N) (regular midpoints)")
    a1.set_xlabel("particles per cell N_p")
    a1.set_ylabel(f"root mean square D2 over cells (h = 1/{round(1 / finest)})")
    a1.set_title("D2 vs N_p; lines: the closed forms with the expected offsets", fontsize=9)
    a1.legend(fontsize=7)
    hh = np.array(sorted({r["h"] for r in d2}))
    for c, ls in zip(SLIDES_C, ("--", "-."), strict=True):
        a2.loglog(hh, np.sqrt(1 / (12 * n_show**2) + c * hh**2), ls, color="gray", lw=0.9,
                  label=f"slides: [1/(12N^2) + {c:.3g} h^2]^1/2")
    a2.set_xlabel("h")
    a2.set_ylabel(f"mean D2 over cells (N_p = {n_show})")
    a2.set_title("D2 vs h: scale-free, no h-dependence", fontsize=9)
    a2.legend(fontsize=7)
    plots.save(fig, folder / "d2.png",
               caption="D2 against N_p and against h, beside the closed forms and the slides' formula")

    # measured quadrature error against Hickernell's bound
    fig, axes = plt.subplots(1, 3, figsize=(13, 5.2))
    labels = {"cell_rho": "cell mean of rho: bound (1)", "node_m": "nodal mass E_m^i: two-cell bound",
              "node_F": "nodal force E_F^i: two-cell bound"}
    bounds = t[PROJECTION_BOUNDS.stem]
    smallest = {r["check"]: min(x["min_ratio"] for x in bounds if x["check"] == r["check"]) for r in bounds}
    for ax, check in zip(axes, labels, strict=True):
        lo, hi = np.inf, 0.0
        for lay in LAYOUT_NAMES:
            pts = np.array([p for c, r in results if c["layout"] == lay for p in r["bounds"][check]["sample"]])
            if pts.size:
                ax.loglog(pts[:, 0], pts[:, 1], ".", ms=2, color=COLORS[lay], label=lay, alpha=0.6)
                lo, hi = min(lo, pts[:, 0].min()), max(hi, pts[:, 0].max())
        if hi > 0:
            ax.loglog([lo, hi], [lo, hi], "k-", lw=0.8, label="error = bound")
            ax.set_ylim(bottom=lo * 1e-6)  # errors below this are round-off of symmetric cancellations
        ax.set_xlabel("Hickernell bound")
        ax.set_ylabel("|measured error|")
        ax.set_title(f"{labels[check]}\nsmallest bound/error = {smallest[check]:.3g}", fontsize=9)
        ax.legend(fontsize=7, markerscale=3)
    plots.save(fig, folder / "hickernell.png",
               caption="Measured quadrature error against Hickernell's bound on every cell and node")


#: The cost model of :mod:`mpm_fem.app.estimate`: a case is a fraction of a second (the full tier,
#: 648 cases, took 27.3 CPU-s on the 2-core machine in a from-scratch run on 2026-11-26).
PLAN = lambda tier: {"cases": {k: c for k, c in enumerate(cases(StudyOptions(quick=tier == "quick")))}}  # noqa: E731
COST = lambda case: 1.0  # noqa: E731
SECONDS_PER_COST = 27.3 / 648
run_case = case

if __name__ == "__main__":
    sys.exit(script_main(NAME))
