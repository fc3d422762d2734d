"""Projection and particle-quadrature errors (claims C4-C10).

Caption: smooth fields ``rho = 1 + 0.5 sin(2 pi x)``, ``v = sin(2 pi x)``, ``p = rho^1.4`` on [0, 1]
are sampled by ``N_p`` in {1, 2, 4, 8, 16, 32} particles per cell on meshes h = 1/10 ... 1/2560 in
four layouts: regular midpoints, jittered (one uniform point per sub-cell), random (``N_p``
uniform points per cell) - both over several seeds, mean and spread reported - and advected
(regular particles moved by a kinematic MPM run in ``u = 0.1 sin(2 pi x)`` for T = 0.8). Each
nodal projection of the slides is compared with the exact integral it stands in for
(:mod:`mpm_fem.projection`), with the slides' weights ``h/N_p^i`` and, for the advected layout,
also with the volumes ``V_p`` the run carries. Hickernell's ``D2`` and bound
(:mod:`mpm_fem.quadrature`) are measured on every cell.

Tables (``figures/projection/``): ``errors.csv`` (quantity, layout, weights, N_p, h, norm, value,
spread), ``orders.csv`` (least-squares order over all h, the orders between the two coarsest and
the two finest meshes and between every pair of successive meshes, the source's band, inside), ``d2.csv``, ``d2_constant.csv`` (the C of
``D2 ~ [1/(12 N^2) + C h^2]^{1/2}``), ``bounds.csv`` (smallest bound/error ratio). Figures:
``errors_vs_h.png``, ``errors_vs_h_random.png``, ``d2.png``, ``hickernell.png``.
"""

from __future__ import annotations

import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

from mpm_fem.errors import fitted_order, observed_orders
from mpm_fem.grid import uniform_grid
from mpm_fem.projection import QUANTITIES, Advection, cell_weights, layout, projection_errors, quadrature_checks, smooth_fields
from mpm_fem.quadrature import cell_points, discrepancy_d2, estimate_c, expected_offset, offset_term
from mpm_fem.study import StudyOptions, read_table, script_main, write_table

NAME = "projection"
CELLS = [10 * 2**k for k in range(9)]  # h = 1/10 ... 1/2560
PPC = [1, 2, 4, 8, 16, 32]
LAYOUT_NAMES = ("regular", "jittered", "random", "advected")
SEEDS = 5
QUICK = {"cells": CELLS[:6], "ppc": [1, 4, 16], "seeds": 3}
GAMMA = 1.4
ADVECTION = Advection()
#: The source's claimed order bands ("Conclusions" slide); E_v1 "is first order in space".
BANDS = {"E_m": (1, 2), "E_P": (1, 2), "E_F": (1, 2), "E_a": (0, 1), "E_a_pred": (0, 1), "E_v": (0, 1),
         "E_v1": (1, 1), "E_VG": "E_v", "E_VG_proj": "E_v"}
#: Least-squares orders within this distance of a band count as inside (sampling noise of the fit).
TOLERANCE = 0.1
SLIDES_C = (0.25, 1 / 3)
#: (weights, basis) of the projections: the slides' point-mass sums with h/N_p^i; with the volumes
#: V_p a run carries (differs from h/N_p^i only once particles moved); GIMP with V_p (E2).
VARIANTS = (("cell", "mpm"), ("volume", "mpm"), ("volume", "gimp"))
SAMPLE = 12  # (bound, error) pairs kept per check and case for the figure
CLAIM_OF = {"E_m": "C5", "E_P": "C6", "E_F": "C7", "E_a": "C8", "E_v": "C9", "E_VG_proj": "C10"}


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


def _band_text(quantity: str) -> str:
    band = BANDS[quantity]
    if isinstance(band, str):
        return f"order of {band}"
    return f"{band[0]}" if band[0] == band[1] else f"[{band[0]}, {band[1]}]"


def _inside(quantity: str, order: float, reference: dict) -> bool:
    band = BANDS[quantity]
    if isinstance(band, str):
        return abs(order - reference[band]) <= TOLERANCE
    return band[0] - TOLERANCE <= order <= band[1] + TOLERANCE


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
    for (q, lay, weights, basis, n, k, norm), v in sorted(errs.items(), key=lambda kv: (QUANTITIES.index(kv[0][0]),) + kv[0][1:]):
        v = np.asarray(v)
        error_rows.append({"quantity": q, "layout": lay, "weights": weights, "basis": basis, "N_p": n, "h": 1.0 / k, "norm": norm,
                           "value": float(v.mean()), "spread": float(v.std()), "min": float(v.min()),
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
                               "band": _band_text(q), "inside": "yes" if _inside(q, fitted[q], fitted) else "no"})

    d2_rows = []
    for (lay, n, k), ds in sorted(d2s.items()):
        mean = lambda key: float(np.mean([d[key] for d in ds]))  # noqa: E731
        expected = expected_offset(lay, n) if lay != "advected" else float("nan")
        d2_rows.append({"layout": lay, "N_p": n, "h": 1.0 / k, "D2_mean": mean("mean"),
                        "D2_min": float(min(d["min"] for d in ds)), "D2_max": float(max(d["max"] for d in ds)),
                        "D2_times_N": mean("mean") * n, "delta_mean": mean("delta_mean"), "delta_expected": expected,
                        "empty_cells": int(max(d["empty_cells"] for d in ds)),
                        "count_min": int(min(d["count_min"] for d in ds)), "count_max": int(max(d["count_max"] for d in ds)),
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
                           "entries": int(sum(b["entries"] for b in bs)), "holds": "yes" if min(b["min_ratio"] for b in bs) >= 1 else "no"})
    return {"errors": error_rows, "orders": order_rows, "d2": d2_rows, "d2_constant": c_rows, "bounds": bound_rows}


def settings(options: StudyOptions) -> dict:
    cells, ppc, seeds = (QUICK["cells"], QUICK["ppc"], QUICK["seeds"]) if options.quick else (CELLS, PPC, SEEDS)
    return {
        "quick": options.quick,
        "fields": {"rho": "1 + 0.5 sin(2 pi x)", "v": "sin(2 pi x)", "p": f"rho^{GAMMA}", "domain": [0, 1]},
        "h": [1.0 / k for k in cells], "N_p": ppc, "layouts": list(LAYOUT_NAMES), "seeds": seeds,
        "jitter": 1.0,
        "advection": {"velocity": f"{ADVECTION.amplitude} sin(2 pi x)", "T": ADVECTION.T, "cfl": ADVECTION.cfl,
                      "start": "regular", "update": "kinematic MPM (USL positions, V_p *= 1 + dt dv/dx)"},
        "weights": {"cell": "h / N_p^i (slides)", "volume": "V_p carried by the run (= h/N_p for seeded layouts)"},
        "variants": [f"{w}:{b}" for w, b in VARIANTS],
        "bases": {"mpm": "point mass S_i(x_p)", "gimp": "hats averaged over [x_p - V_p/2, x_p + V_p/2]"},
        "nodes": "interior nodes (whole hats); norms weighted by h (nodes, cells) or w_p (particles)",
        "exact_integrals": "Gauss-Legendre, 20 points per cell",
        "bands": {q: _band_text(q) for q in QUANTITIES}, "tolerance": TOLERANCE, "slides_C": list(SLIDES_C),
    }


def run(options: StudyOptions) -> None:
    folder = options.folder(NAME)
    cs = cases(options)
    results = options.sweep(NAME, case, cs)
    t = tables(list(zip(cs, results)))
    s = settings(options)
    for name, rows in t.items():
        write_table(folder, name, rows, s)
    figures(folder, t, [(c, r) for c, r in zip(cs, results)])


# ----------------------------------------------------------------------------- figures

COLORS = {"regular": "tab:blue", "jittered": "tab:orange", "random": "tab:green", "advected": "tab:red"}
TITLES = {"E_m": "mass E_m", "E_P": "momentum E_P", "E_F": "force E_F", "E_a": "acceleration E_a",
          "E_a_pred": "E_a predicted: E_F/m - a E_m/m", "E_v": "velocity E_v", "E_v1": "E_v1 = v(x_i) - P_i/m_i",
          "E_VG": "velocity gradient at particles", "E_VG_proj": "E_VG^i = (E_v^{i+1} - E_v^i)/h"}


def _guides(ax, h, e, slopes=(1, 2)):
    h = np.asarray(h)
    for k in slopes:
        ax.loglog(h, e * (h / h[0]) ** k, ":", color="gray", lw=0.9)
        ax.annotate(f"slope {k}", (h[-1], e * (h[-1] / h[0]) ** k), fontsize=6, color="gray")


def _panels(path, series_of, title):
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 3, figsize=(12, 10.5))
    for ax, q in zip(axes.ravel(), QUANTITIES):
        top = 0.0
        for label, (h, v, style, color) in series_of(q).items():
            ax.loglog(h, v, style, color=color, label=label, ms=3.5, lw=1.1)
            top = max(top, v[0])
        if top > 0:
            _guides(ax, h, top * 1.5)
        ax.set_title(TITLES[q], fontsize=9)
        ax.set_xlabel("h")
        ax.set_ylabel("error (L1 over nodes)" if q != "E_VG" else "error (L1 over particles)")
    axes[0][0].legend(fontsize=7)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def figures(folder: Path, t: dict, results: list) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = [r for r in t["errors"] if r["norm"] == "L1"]
    ppcs = sorted({r["N_p"] for r in rows})
    n_show = 4 if 4 in ppcs else ppcs[len(ppcs) // 2]

    def by_layout(q):
        out = {}
        for lay in LAYOUT_NAMES:
            for (weights, basis), style in ((("cell", "mpm"), "o-"), (("volume", "mpm"), "s--"), (("volume", "gimp"), "^:")):
                if basis == "gimp" and lay not in ("advected", "random"):
                    continue
                sel = [r for r in rows if r["quantity"] == q and r["layout"] == lay and r["weights"] == weights
                       and r["basis"] == basis and r["N_p"] == n_show]
                if sel:
                    label = lay + {("cell", "mpm"): "", ("volume", "mpm"): ", V_p weights",
                                   ("volume", "gimp"): ", GIMP, V_p"}[(weights, basis)]
                    out[label] = ([r["h"] for r in sel], [r["value"] for r in sel], style, COLORS[lay])
        return out

    _panels(folder / "errors_vs_h.png", by_layout,
            f"Projection errors vs h, N_p = {n_show} (mean over seeds): point mass with the slides' weights h/N_p^i "
            "unless marked")
    cmap = plt.get_cmap("viridis")

    def by_ppc(q):
        out = {}
        for j, n in enumerate(ppcs):
            sel = [r for r in rows if r["quantity"] == q and r["layout"] == "random" and r["N_p"] == n and r["basis"] == "mpm"]
            out[f"N_p = {n}"] = ([r["h"] for r in sel], [r["value"] for r in sel], "o-", cmap(j / max(1, len(ppcs) - 1)))
        return out

    _panels(folder / "errors_vs_h_random.png", by_ppc, "Projection errors vs h, random layouts (mean over seeds)")

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
    a1.set_title("D2 vs N_p; lines: closed forms (3) with the expected offsets", fontsize=9)
    a1.legend(fontsize=7)
    hh = np.array(sorted({r["h"] for r in d2}))
    for c, ls in zip(SLIDES_C, ("--", "-.")):
        a2.loglog(hh, np.sqrt(1 / (12 * n_show**2) + c * hh**2), ls, color="gray", lw=0.9,
                  label=f"slides: [1/(12N^2) + {c:.3g} h^2]^1/2")
    a2.set_xlabel("h")
    a2.set_ylabel(f"mean D2 over cells (N_p = {n_show})")
    a2.set_title("D2 vs h: scale-free, no h-dependence", fontsize=9)
    a2.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(folder / "d2.png", dpi=110)
    plt.close(fig)

    # measured quadrature error against Hickernell's bound
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.2))
    labels = {"cell_rho": "cell mean of rho: bound (1)", "node_m": "nodal mass E_m^i: two-cell bound",
              "node_F": "nodal force E_F^i: two-cell bound"}
    smallest = {r["check"]: min(x["min_ratio"] for x in t["bounds"] if x["check"] == r["check"]) for r in t["bounds"]}
    for ax, check in zip(axes, labels):
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
    fig.tight_layout()
    fig.savefig(folder / "hickernell.png", dpi=110)
    plt.close(fig)


# ----------------------------------------------------------------------------- report

def _orders(folder: Path) -> list[dict]:
    return read_table(folder / "orders.csv")


def _pick(rows, **kw):
    return [r for r in rows if all(str(r[k]) == str(v) for k, v in kw.items())]


def _range(rows, quantity, lay, norm="L1", weights="cell", basis="mpm"):
    vals = [float(r["order"]) for r in _pick(rows, quantity=quantity, layout=lay, norm=norm, weights=weights, basis=basis)]
    return (min(vals), max(vals)) if vals else (float("nan"), float("nan"))


COLUMNS = (("regular", "cell", "mpm", "regular"), ("jittered", "cell", "mpm", "jittered"),
           ("random", "cell", "mpm", "random"), ("advected", "cell", "mpm", "advected, h/N_p^i"),
           ("advected", "volume", "mpm", "advected, V_p"), ("advected", "volume", "gimp", "advected, GIMP V_p"),
           ("random", "volume", "gimp", "random, GIMP V_p"))


def _fmt(rows, q, lay, weights="cell", basis="mpm"):
    a, b = _range(rows, q, lay, weights=weights, basis=basis)
    lo, hi = f"{a:.2f}", f"{b:.2f}"
    return lo if lo == hi else f"{lo}..{hi}"


def _coarse(rows, q, layouts):
    """Largest order between the two coarsest meshes (L1, point mass, h/N_p^i) over N_p and ``layouts``."""
    vals = [float(r["order_coarse"]) for r in rows if r["quantity"] == q and r["layout"] in layouts
            and r["norm"] == "L1" and r["weights"] == "cell" and r["basis"] == "mpm"]
    return max(vals) if vals else float("nan")


def claims(folder: Path) -> list[dict]:
    """Verdicts on C4-C10 from the written tables (least-squares L1 orders, range over N_p)."""
    folder = Path(folder)
    if not (folder / "orders.csv").exists():
        return []
    o = _orders(folder)
    bounds = read_table(folder / "bounds.csv")
    c_vals = [float(r["C"]) for r in read_table(folder / "d2_constant.csv")]
    f = lambda q, lay, w="cell", b="mpm": _fmt(o, q, lay, w, b)  # noqa: E731
    ratio = min(float(r["min_ratio"]) for r in bounds)
    out = [{"id": "C4", "verdict": "partly",
            "evidence": f"the bound holds on every cell and node of every layout (smallest bound/error {ratio:.3g}); "
                        f"but D2 ~ [1/(12N^2) + C h^2]^1/2 mixes units: measured C in [{min(c_vals):.3g}, "
                        f"{max(c_vals):.3g}], not [1/4, 1/3], and the scale-free D2 does not depend on h"}]
    seeded = ("jittered", "random")
    for q in ("E_m", "E_P", "E_F"):
        text = (f"first order: random {f(q, 'random')}, jittered {f(q, 'jittered')}, advected {f(q, 'advected')}; "
                f"second order only between the two coarsest meshes of the advected layout (up to "
                f"{_coarse(o, q, ('advected',)):.2f}; seeded layouts at most {_coarse(o, q, seeded):.2f}); "
                f"regular midpoints {f(q, 'regular')}, better than claimed")
        if q == "E_F":
            text += (f"; but with the volumes V_p a run carries the force does not converge "
                     f"({f(q, 'advected', 'volume')}); GIMP with V_p: {f(q, 'advected', 'volume', 'gimp')}")
        out.append({"id": CLAIM_OF[q], "verdict": "partly" if q == "E_F" else "confirmed", "evidence": text})
    out.append({"id": "C8", "verdict": "partly",
                "evidence": f"one order below E_F as claimed: random {f('E_a', 'random')}, jittered {f('E_a', 'jittered')}, "
                            f"regular {f('E_a', 'regular')}; with V_p weights still one below E_F but outside the band: "
                            f"E_a grows like 1/h ({f('E_a', 'advected', 'volume')}); GIMP with V_p: "
                            f"{f('E_a', 'advected', 'volume', 'gimp')}"})
    out.append({"id": "C9", "verdict": "confirmed",
                "evidence": f"E_v: random {f('E_v', 'random')}, jittered {f('E_v', 'jittered')}, advected "
                            f"{f('E_v', 'advected')}; regular {f('E_v', 'regular')} (better); E_v1 is second order at "
                            f"interior nodes ({f('E_v1', 'regular')}), not first as the slides say (first order only "
                            f"at a wall's cut hat)"})
    out.append({"id": "C10", "verdict": "refuted",
                "evidence": f"(E_v^(i+1) - E_v^i)/h: random {f('E_VG_proj', 'random')}, jittered "
                            f"{f('E_VG_proj', 'jittered')}, advected {f('E_VG_proj', 'advected')}: one order below E_v, "
                            f"because E_v^i is not smooth in i; the same order only for regular midpoints "
                            f"({f('E_VG_proj', 'regular')})"})
    return out


WHY = """Why:

- Regular midpoints have the smallest discrepancy, D2 = 1/(sqrt(12) N_p) exactly (every cell, every h; `d2.csv`),
  yet Hickernell's bound gives them only first order: D2 bounds the worst integrand with a given ||f'||.
  They do better because the midpoint rule integrates linear functions exactly and the errors of the
  two halves of a whole hat cancel at leading order: E_m, E_P, E_F are O(h^3) and a_i, v_i O(h^2).
- For the other layouts D2 is scale-free: it depends on the pattern of the points in the cell, not on h,
  so E_m <= D2 h (|rho(xi_1)| + |rho(xi_2)|) is exactly first order and the bound is nearly sharp
  (`hickernell.png`). In the slides' (3) the offsets are in physical units while 1/(12N^2) is not: the
  "C h^2" term is then h^2 times the mean squared offset in cell units, and the measured C (closed forms:
  jittered 1/(12 N^2), random 1/(6(N+1)) + (N-1)/(12N^2(N+1))) stays below 0.09, far from [1/4, 1/3].
  The only h-dependence of D2 seen is on the advected layout between h = 1/10 and 1/20, where the coarse
  cells do not resolve the deformation; that is where the only second-order steps appear.
- Acceleration and velocity are ratios with m_i = O(h): E_F/m_i is O(1) for a first-order E_F, hence
  order 0. The velocity does better, order 1: P_i/m_i is a weighted mean of v_p near x_i, and the
  quadrature error of S_i rho (v - v_i) is one order smaller than that of S_i rho.
- E_v^i is O(h) but, for jittered, random and advected particles, uncorrelated from node to node, so
  (E_v^(i+1) - E_v^i)/h is O(1): the slides' argument for C10 assumes E_v^i = C h^p with C smooth in i,
  which only the regular layout satisfies. Through dv/dx this O(1) error enters the density and energy
  updates of every step (the Sod study's stagnation).
- With the volumes V_p that a run carries instead of h/N_p^i, a particle whose volume straddles a node
  puts all of p_p V_p into one cell: the force quadrature is off by O(p V_p/h) = O(p/N_p) and E_a grows
  like 1/h. GIMP, whose G_ip is continuous in x_p, restores a converging force with V_p once N_p >= 8,
  where the particle domains tile the line; with fewer particles the volumes the run updates drift from
  a tiling (gaps and overlaps that do not shrink with h) and GIMP stalls too, as it does on seeded random
  layouts, whose domains overlap. Each basis needs its own consistency: equal weights per cell for the
  point-mass sums, particle domains that tile the line for GIMP.
"""


def report(folder: Path) -> str:
    folder = Path(folder)
    lines = ['## Projection and particle quadrature (C4-C10)', ""]
    if not (folder / "orders.csv").exists():
        return "\n".join(lines + ["Not run yet: `mpm-fem study projection`.", ""])
    o = _orders(folder)
    hs = sorted({float(r["h"]) for r in read_table(folder / "d2.csv")})
    lines += [f"Smooth fields on [0, 1] (`rho = 1 + 0.5 sin 2 pi x`, `v = sin 2 pi x`, `p = rho^1.4`), h = 1/{round(1 / hs[-1])} "
              f"... 1/{round(1 / hs[0])}, errors at interior nodes, L1 norms; least-squares orders over all meshes, "
              "range over N_p. Point-mass sums with the slides' weights h/N_p^i unless marked; `V_p`: the volumes "
              "a run carries; GIMP: hats averaged over the particle domains. Tables and figures in "
              "`figures/projection/` (`errors_vs_h.png`, `errors_vs_h_random.png`, `d2.png`, `hickernell.png`).", "",
              "| quantity | source's band | " + " | ".join(c[3] for c in COLUMNS) + " |",
              "|---|---|" + "---|" * len(COLUMNS)]
    for q in QUANTITIES:
        lines.append(f"| {q} | {_band_text(q)} | " + " | ".join(_fmt(o, q, *c[:3]) for c in COLUMNS) + " |")
    c_rows = read_table(folder / "d2_constant.csv")
    lines += ["", "The C of `D2 ~ [1/(12 N^2) + C h^2]^1/2` (slides: 1/4 <= C <= 1/3), fitted per layout:", "",
              "| layout | " + " | ".join(f"N_p={r['N_p']}" for r in c_rows if r["layout"] == "random") + " |",
              "|---|" + "---|" * sum(r["layout"] == "random" for r in c_rows)]
    for lay in LAYOUT_NAMES:
        lines.append(f"| {lay} | " + " | ".join(f"{float(r['C']):.3g}" for r in c_rows if r["layout"] == lay) + " |")
    lines += ["", WHY, "Verdicts:", ""]
    lines += [f"- **{c['id']}** {c['verdict']}: {c['evidence']}" for c in claims(folder)]
    return "\n".join(lines + [""])


if __name__ == "__main__":
    sys.exit(script_main(NAME))
