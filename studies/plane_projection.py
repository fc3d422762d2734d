"""Projection and particle-quadrature errors on the plane (claims D8, D9; the 2D counterpart of C4-C10).

Caption: the 1D study's smooth fields made 2D on the unit square, ``rho = r(x) r(y)`` with ``r = 1 +
0.5 sin(2 pi s)``, ``v = (sin 2 pi x cos 2 pi y, cos 2 pi x sin 2 pi y)``, ``sigma = -rho^1.4 I + 0.25 sin 2 pi
x sin 2 pi y (e_x e_y + e_y e_x)``, sampled by 2x2 and 4x4 particles per cell on meshes h = 1/4 ... 1/64 in
four layouts: regular midpoints, jittered (one uniform point per sub-cell) and random (``n^2`` uniform
points per cell), both over several seeds (mean and spread reported), and advected (the regular layout
moved by the smooth displacement of :class:`mpm_fem.plane.projection.Displacement`, volumes ``J V_p^0``).
Each nodal projection is compared with the integral it stands in for (:mod:`mpm_fem.plane.projection`),
with the slides' weights ``h^2/N_p^c`` and, for the advected layout, also with the volumes; uGIMP beside
with the volumes. Hickernell's bound with the 2D discrepancy (:mod:`mpm_fem.plane.discrepancy`) is
checked on every cell and interior node.

Tables (``figures/plane_projection/``): ``errors.csv``, ``orders.csv`` (the order in the 1D units: an
extensive nodal error divided by ``h``, and as measured per node), ``bounds.csv``, ``d2.csv``. Figure:
``errors_vs_h.png``.
"""

from __future__ import annotations

import inspect
import sys
from collections import defaultdict

import numpy as np

from mpm_fem.app.plots import Curve, Plot
from mpm_fem.app.study import StudyOptions, publish, script_main
from mpm_fem.measure.claims import BAND_TOLERANCE
from mpm_fem.measure.errors import fitted_order, observed_orders
from mpm_fem.measure.schema import (
    PLANE_PROJECTION_BOUNDS,
    PLANE_PROJECTION_D2,
    PLANE_PROJECTION_ERRORS,
    PLANE_PROJECTION_ORDERS,
)
from mpm_fem.measure.source import PROJECTION_BANDS, band_text
from mpm_fem.plane.discrepancy import discrepancy_d2, quadrature_checks, regular_d2, variations
from mpm_fem.plane.projection import (
    EXACT_ORDER,
    EXTENSIVE,
    LAYOUTS,
    QUANTITIES,
    Displacement,
    cell_of,
    cell_weights,
    exact_sums,
    layout,
    projection_errors,
    smooth_fields,
    unit_square,
)

NAME = "plane_projection"
CELLS = {"quick": (4, 8, 16), "full": (4, 8, 16, 32, 64)}  # h = 1/4 ... 1/64
PPC = (2, 4)
SEEDS = {"quick": 2, "full": 5}
DISPLACEMENT = Displacement()
BANDS, TOLERANCE = PROJECTION_BANDS, BAND_TOLERANCE
#: (weights, basis) of the projections: the slides' point-mass sums with h^2/N_p^c; with the volumes V_p (they
#: differ from h^2/N_p^c only on the advected layout); uGIMP with V_p.
VARIANTS = (("cell", "mpm"), ("volume", "mpm"), ("volume", "gimp"))


def _tier(tier: str) -> str:
    return "quick" if tier == "quick" else "full"  # the deep tier runs the full plan: the study is cheap


def plan(tier: str) -> dict:
    """``{"cases": {(cells, ppc): case}}``: one case a mesh and particle count, every layout and seed in it."""
    t = _tier(tier)
    return {"cases": {(k, n): {"cells": k, "ppc": n, "seeds": SEEDS[t]} for k in CELLS[t] for n in PPC}}


def _settings_of(seeds: int) -> list[tuple[str, int]]:
    return [(lay, s) for lay in LAYOUTS for s in (range(1, seeds + 1) if lay in ("jittered", "random") else (0,))]


def run_case(case: dict) -> dict:
    """Every error norm, D2 statistic and bound check of one mesh and particle count, over the layouts and seeds."""
    grid = unit_square(1.0 / case["cells"])
    fields = smooth_fields()
    exact, V = exact_sums(grid, fields), variations(grid, fields)
    out = []
    for lay, seed in _settings_of(case["seeds"]):
        x, vol, lengths = layout(grid, lay, case["ppc"], seed, DISPLACEMENT)
        weights = {"cell": cell_weights(grid, x), "volume": vol}
        errors = {f"{w}:{b}": projection_errors(grid, x, weights[w], fields, b, lengths, exact).norms()
                  for w, b in VARIANTS if (w, b) != ("volume", "mpm") or lay == "advected"}
        d2 = discrepancy_d2(grid, x)
        count = np.bincount(cell_of(grid, x)[0], minlength=d2.size)
        bounds = {name: {"min_ratio": check.min_ratio, "entries": check.entries}
                  for name, check in quadrature_checks(grid, x, fields, exact, V).items()}
        out.append({"layout": lay, "seed": seed, "errors": errors, "bounds": bounds,
                    "d2": {"mean": float(np.nanmean(d2)), "min": float(np.nanmin(d2)), "max": float(np.nanmax(d2)),
                           "count_min": int(count.min()), "count_max": int(count.max())}})
    return {"settings": out}


def _inside(quantity: str, order: float, reference: dict) -> bool:
    band = BANDS[quantity]
    if isinstance(band, str):
        return abs(order - reference[band]) <= TOLERANCE
    return band[0] - TOLERANCE <= order <= band[1] + TOLERANCE


def tables(results: list[tuple[dict, dict]]) -> dict:
    """Aggregate the cases' results over the seeds into the study's tables."""
    errs, bounds, d2s = defaultdict(list), defaultdict(list), defaultdict(list)
    for c, r in results:
        for s in r["settings"]:
            for variant, qs in s["errors"].items():
                weights, basis = variant.split(":")
                for q, ns in qs.items():
                    for norm, value in ns.items():
                        errs[(q, s["layout"], weights, basis, c["ppc"], c["cells"], norm)].append(value)
            for check, b in s["bounds"].items():
                bounds[(check, s["layout"], c["ppc"], c["cells"])].append(b)
            d2s[(s["layout"], c["ppc"], c["cells"])].append(s["d2"])
    error_rows = []
    for (q, lay, weights, basis, n, k, norm), v in sorted(errs.items(), key=lambda i: (QUANTITIES.index(i[0][0]),
                                                                                        *i[0][1:])):
        v = np.asarray(v)
        error_rows.append({"quantity": q, "layout": lay, "weights": weights, "basis": basis, "ppc": n, "h": 1.0 / k,
                           "norm": norm, "value": float(v.mean()), "spread": float(v.std()), "min": float(v.min()),
                           "max": float(v.max()), "seeds": int(v.size)})
    series = defaultdict(dict)  # (layout, weights, basis, ppc, norm) -> {quantity: (h, values)}
    for row in error_rows:
        h, val = series[(row["layout"], row["weights"], row["basis"], row["ppc"], row["norm"])].setdefault(
            row["quantity"], ([], []))
        h.append(row["h"])
        val.append(row["value"])
    order_rows = []
    for (lay, weights, basis, n, norm), by_q in series.items():
        shift = {q: 1.0 if q in EXTENSIVE else 0.0 for q in QUANTITIES}  # E/h: the 1D units of an extensive error
        fitted = {q: fitted_order(*by_q[q]) - shift[q] for q in by_q}
        for q in QUANTITIES:
            steps = observed_orders(*by_q[q]) - shift[q]
            order_rows.append({"quantity": q, "layout": lay, "weights": weights, "basis": basis, "ppc": n,
                               "norm": norm, "order": fitted[q], "order_per_node": fitted[q] + shift[q],
                               "order_coarse": float(steps[0]), "order_fine": float(steps[-1]),
                               "successive": " ".join(f"{p:.2f}" for p in steps), "band": band_text(q),
                               "inside": "yes" if _inside(q, fitted[q], fitted) else "no"})
    bound_rows = [{"check": check, "layout": lay, "ppc": n, "h": 1.0 / k,
                   "min_ratio": float(min(b["min_ratio"] for b in bs)), "entries": int(sum(b["entries"] for b in bs)),
                   "holds": "yes" if min(b["min_ratio"] for b in bs) >= 1 else "no"}
                  for (check, lay, n, k), bs in sorted(bounds.items())]
    d2_rows = [{"layout": lay, "ppc": n, "h": 1.0 / k, "D2_mean": float(np.mean([d["mean"] for d in ds])),
                "D2_min": float(min(d["min"] for d in ds)), "D2_max": float(max(d["max"] for d in ds)),
                "D2_regular": regular_d2(n), "count_min": int(min(d["count_min"] for d in ds)),
                "count_max": int(max(d["count_max"] for d in ds)), "seeds": len(ds)}
               for (lay, n, k), ds in sorted(d2s.items())]
    return {PLANE_PROJECTION_ERRORS: error_rows, PLANE_PROJECTION_ORDERS: order_rows,
            PLANE_PROJECTION_BOUNDS: bound_rows, PLANE_PROJECTION_D2: d2_rows}


def settings(tier: str) -> dict:
    t = _tier(tier)
    return {
        "tier": tier,
        "fields": {"rho": "r(x) r(y), r a sinusoid of amplitude rho_amplitude about unity",
                   "v": "v_amplitude (sin 2pi x cos 2pi y, cos 2pi x sin 2pi y)",
                   "sigma": "-rho^gamma I + shear sin 2pi x sin 2pi y (e_x e_y + e_y e_x)",
                   "constants": {k: v.default for k, v in inspect.signature(smooth_fields).parameters.items()},
                   "domain": [[0, 1], [0, 1]]},
        "h": [1.0 / k for k in CELLS[t]], "ppc": list(PPC), "layouts": list(LAYOUTS), "seeds": SEEDS[t],
        "random": "n^2 uniform points in every cell", "jitter": 1.0,
        "advection": {"displacement": "A (sin 2pi X sin pi Y, sin pi X sin 2pi Y)", "A": DISPLACEMENT.amplitude,
                      "volumes": "J V_p^0"},
        "weights": {"cell": "h^2 / N_p^c (slides)", "volume": "V_p of the layout"},
        "variants": [f"{w}:{b}" for w, b in VARIANTS],
        "bases": {"mpm": "point mass", "gimp": "uGIMP, the seeded lengths (h/n, h/n)"},
        "nodes": "interior nodes (whole tensor hats); norms weighted by h^2 (nodes, cells) or w_p (particles)",
        "units": "order: an extensive error (E_m, E_P, E_F) divided by h, the 1D units; order_per_node as measured",
        "exact_integrals": f"scikit-fem Gauss order {EXACT_ORDER} on the half cells (plane.exact.cell_quadrature)",
        "discrepancy": "Hickernell's modified L2 discrepancy, the tensor-product extension of the 1D D2",
        "bands": {q: band_text(q) for q in QUANTITIES}, "tolerance": TOLERANCE,
    }


COLORS = {"regular": "tab:blue", "jittered": "tab:orange", "random": "tab:green", "advected": "tab:red"}
PLOTS = (
    Plot("errors_vs_h.png", "2D projection errors against h, 2x2 per cell (mean over seeds), point mass with the "
         "slides' weights h^2/N_p^c; the nodal values as measured", PLANE_PROJECTION_ERRORS.stem, "h",
         tuple(Curve(lay, "value", "o-", {"layout": lay, "weights": "cell", "basis": "mpm", "ppc": 2, "norm": "L1"},
                     options={"color": COLORS[lay]}) for lay in LAYOUTS),
         split=("quantity",), ncols=4, slopes=(1, 2), ylabel="error (L1)", size=(3.6, 3.2)),
)


def run(options: StudyOptions) -> None:
    folder = options.folder(NAME)
    got = options.sweep_plan(NAME, run_case, plan(options.tier), cost)["cases"]
    cases = plan(options.tier)["cases"]
    publish(folder, tables([(cases[k], got[k]) for k in cases]), settings(options.tier), figures=PLOTS)


def cost(case: dict) -> float:
    """Relative cost: the particles and quadrature points of a case, ``cells^2 (ppc^2 layouts + 1)``."""
    return case["cells"] ** 2 * (case["ppc"] ** 2 * (2 + 2 * case["seeds"]) + 16)


#: The cost model of :mod:`mpm_fem.app.estimate`: the full tier (10 cases, cost 1.48e6) took 11.8 CPU-s on the
#: 2-core machine (2026-12-03, from scratch).
PLAN, COST, SECONDS_PER_COST = plan, cost, 11.8 / 1.48e6

if __name__ == "__main__":
    sys.exit(script_main(NAME))
