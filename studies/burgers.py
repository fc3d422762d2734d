"""Viscous Burgers: MPM with exact and calculated acceleration beside FEM and the source's table.

``v_t + v v_x = eps v_xx`` on [0, 2] up to T, data from an exact solution; MPM takes the nodal
acceleration from the particles ("calculated", at 4, 8 and 16 particles per cell) or from the exact
solution ("exact"), beside P1 FEM with consistent and lumped mass on the same mesh. The settings C13
judges also run at the largest eps on jittered particle layouts, one per seed of :data:`SEEDS`.
Tables (their rows: :mod:`mpm_fem.measure.burgers_tables`): ``errors``, ``orders`` and ``seeds``
(C13), ``norms`` (which solution and norm match the source), ``timestep``, ``ppc`` (C3), ``lumping``
(C15), ``diagnosis`` (C13's explanation)."""

from __future__ import annotations

import sys
from typing import NamedTuple

import numpy as np

from baselines import fem_burgers
from baselines.exact.burgers import make_solution
from mpm_fem.app import plots
from mpm_fem.app.plots import Curve, Plot
from mpm_fem.app.study import StudyOptions, publish, script_main
from mpm_fem.measure import burgers_tables as tables
from mpm_fem.measure import source
from mpm_fem.measure.claims import BURGERS_SHOWN
from mpm_fem.measure.schema import BURGERS_DIAGNOSIS, BURGERS_LUMPING, BURGERS_ORDERS, BURGERS_PPC, BURGERS_SEEDS
from mpm_fem.problems import burgers

NAME = "burgers"
H = source.BURGERS_H
EPS = (0.045, 0.04, 0.03, 0.02, 0.01)
SOLUTIONS = ("rarefaction", "cole_hopf", "three_exp", "front")
#: The solution, and the norm (the slides do not say which), compared with the source; why: norms.csv.
DEFAULT, WHERE, NORM = BURGERS_SHOWN["solution"], BURGERS_SHOWN["where"], BURGERS_SHOWN["norm"]
SOURCE, CORRECTED = source.BURGERS, source.BURGERS_CORRECTED
T = burgers.BurgersSettings.T
MPM = dict(ppc=4, cfl=0.5, mass="lumped", basis="mpm", scheme="usl", layout="regular", seed=0)
FEM = dict(cfl=0.5, cfl_visc=0.3)
#: The calculated acceleration at each number of particles per cell: the source's 4-8 and 16.
CALCULATED = {4: "mpm_calculated", 8: "mpm_calculated_8", 16: "mpm_calculated_16"}


class Method(NamedTuple):
    """A method of the tables: its label, its solver (``"mpm"`` or ``"fem"``), its settings beside the
    solver's defaults (:data:`MPM`, :data:`FEM`), and the source's row it stands beside (``None``: none)."""

    label: str
    solver: str
    settings: dict
    source_row: str | None


METHODS = {
    **{m: Method(f"MPM calculated a, {n} ppc", "mpm", {"acceleration": "calculated", "ppc": n}, "calculated")
       for n, m in CALCULATED.items()},
    "mpm_exact": Method("MPM exact a", "mpm", {"acceleration": "exact"}, "exact"),
    "mpm_exact_dt_h": Method("MPM exact a, dt ~ h", "mpm", {"acceleration": "exact", "dt_rule": "advective"}, "exact"),
    "fem_consistent": Method("FEM consistent", "fem", {"mass": "consistent"}, None),
    "fem_lumped": Method("FEM lumped", "fem", {"mass": "lumped"}, None),
}
#: The jittered layouts' seeds (the regular layout is seed 0), and the settings run on them (C13's).
SEEDS, SEEDED = (1, 2, 3, 4, 5), (*CALCULATED.values(), "mpm_exact_dt_h")
_MORE = ("mpm_calculated_8", "mpm_calculated_16")  # on the default solution only
# The meshes of each method, by tier: a calculated-acceleration run costs ~ ppc eps / h^3. The full
# tier takes every mesh for the rows compared with the source, all but the finest for 8 per cell and
# the calculated acceleration's seeds, and 16 per cell to the third mesh (its regular layout one mesh
# further at the seeds' eps: "headline", the meshes of the seeds' eps where they differ). The deep
# tier takes every method to every mesh of the source's table on the solution compared with the
# source; the other solutions and the seeds stay at the full tier's meshes (what did not fit its
# budget, in the order of value: docs/cluster.md).
# 8 per cell stops one mesh coarser in the full tier than in the deep one: its h = 0.00125 (the table's five eps and
# the seeds) took 4.1 of the full tier's CPU-min, measured 2026-11-28, moved to keep the full tier within its hour.
_SEEDS_DEEP = {**{m: H[:4] for m in SEEDED}, "mpm_calculated_16": H[:3], "mpm_exact_dt_h": H}
_SEEDS_FULL = {**_SEEDS_DEEP, "mpm_calculated_8": H[:3]}
_FULL = {
    "default": {**{m: H[:3] for m in METHODS}, "mpm_calculated": H, "mpm_exact_dt_h": H},
    "headline": {"mpm_calculated_16": H[:4]},
    "other": {**{m: H[:3] for m in METHODS if m not in _MORE}, "mpm_exact_dt_h": H,
              "fem_consistent": H[:2], "fem_lumped": H[:2]},
    "seeds": _SEEDS_FULL,
}
MESHES = {"deep": {"default": {m: H for m in METHODS}, "other": _FULL["other"], "seeds": _SEEDS_DEEP},
          "full": _FULL}
_MPM = ("mpm_calculated", "mpm_exact")
PPC, PPC_H, TIME_H, REFINE, PROFILE_H = (1, 2, 4, 8, 16, 32), (0.01, 0.0025), 0.005, (1, 4, 16), 0.01
LUMPING_CFL = 0.3  # the consistent particle mass needs dt <= h^2/(6 eps): both masses run with CFL 0.3
DIAGNOSIS = {  # label: changes to the calculated-acceleration run
    "MPM: weak force, V_p weights": {}, "slides' force (second difference)": {"force": "slides"},
    "slides' weights h/N_p^i": {"weights": "cell"}, "slides' weights and force": {"weights": "cell", "force": "slides"},
    "consistent mass (CFL 0.3)": {"mass": "consistent", "cfl": LUMPING_CFL}, "GIMP basis": {"basis": "gimp"},
    "16 particles per cell": {"ppc": 16}, "exact acceleration": {"acceleration": "exact"},
}
#: The quick tier: the compared solution at the first eps on the two coarsest meshes (the third, h =
#: 0.0025, cost a third of the study), C15's masses on the coarsest mesh (the consistent mass costs most there);
#: C13 where the quick identification can place it (``C13``: its solutions, 4 per cell, the calculated
#: acceleration and the exact one with dt ~ h, at every eps on those two meshes: the identification's own
#: cases, so none runs twice) and its 4-per-cell settings on the regular layout and every seed of SEEDS
#: (``seeded``; 8 and 16 per cell, which the quick identification does not pick, are left to the full tier);
#: no time-step table (no verdict reads it)
QUICK = dict(solutions=(DEFAULT,), eps=EPS[:1], H=H[:2], skip=_MORE[1:], PPC=(2, 4, 8, 16), PPC_H=(0.01,),
             TIME_H=0.01, time_eps=(0.045,), time_methods=(), lumping_H=H[:1],
             diagnosis_H=(), seeds=SEEDS, seeds_H=H[:2], seeded=("mpm_calculated", "mpm_exact_dt_h"),
             C13=(("rarefaction", "cole_hopf"), ("mpm_calculated", "mpm_exact_dt_h")))


class TableKey(NamedTuple):
    """A case of the ``table`` plan: exact solution, method (:data:`METHODS`), viscosity, mesh."""

    solution: str
    method: str
    eps: float
    h: float


class PpcKey(NamedTuple):
    """A case of the ``ppc`` plan (C3): method, mesh, particles per cell."""

    method: str
    h: float
    ppc: int


class SeedKey(NamedTuple):
    """A case of the ``seeds`` plan: method, viscosity, mesh, layout, seed (0 for the regular layout)."""

    method: str
    eps: float
    h: float
    layout: str
    seed: int


def run_case(case: dict) -> dict:
    """One run. ``case["solver"]``: ``"mpm"`` (fields of ``BurgersSettings``) or ``"fem"``
    (``solution``, ``eps``, ``h``, ``mass``, ``cfl``, ``cfl_visc``). Velocity errors at T over
    particles and nodes; the profile at T when ``case["profile"]``. ``dt`` is the run's step, the
    largest it took: the last step, which lands on T, can be a round-off sliver (``dt_min``)."""
    if case["solver"] == "fem":
        solution = make_solution(case["solution"], case["eps"])
        r = fem_burgers.solve(solution, case["h"], T=T, mass=case["mass"], cfl=case["cfl"], cfl_visc=case["cfl_visc"])
        profile = {"profile": _rounded(dict(nodes=r.nodes, nodal_velocity=r.v))} if case.get("profile") else {}
        return {"ok": True, "nodes": fem_burgers.errors(r, solution), "steps": r.steps, "dt": r.dt, **profile}
    settings = burgers.BurgersSettings(**{k: v for k, v in case.items() if k not in ("solver", "profile")})
    try:
        r = burgers.simulate(settings, progress=False)
    except (ArithmeticError, ValueError) as err:
        return {"ok": False, "error": str(err)}
    e = burgers.errors(settings, r)["velocity"]
    out = {"ok": True, "particles": e["particles"], "nodes": e["nodes"], "steps": r.steps, "dt": r.dt_max,
           "dt_min": r.dt_min, "n_p": int(r.particles.n), "wall_s": round(r.wall_s, 2)}
    if case.get("profile"):
        order = np.argsort(r.particles.x)
        out["profile"] = _rounded(dict(x=r.particles.x[order], velocity=r.particles.velocity[order],
                                       nodes=r.grid.nodes, nodal_velocity=r.nodal_velocity))
    return out


def _rounded(arrays: dict) -> dict:
    return {k: [float(f"{v:.9g}") for v in np.asarray(a)] for k, a in arrays.items()}


def method_case(method: str, solution: str, eps: float, h: float, **changes) -> dict:
    """The case of ``method`` (a key of :data:`METHODS`) with ``changes`` to its settings."""
    solver, fixed = METHODS[method].solver, METHODS[method].settings
    return {"solver": solver, "solution": solution, "eps": eps, "h": h, **(FEM if solver == "fem" else MPM), **fixed,
            **changes}


def _cost(case: dict) -> float:
    """~ particles x steps (or nodes x stages x steps), to start the longest runs first."""
    h, eps = case["h"], case["eps"]
    viscous = eps / (h * h * case.get("cfl_visc", case["cfl"]))
    if case["solver"] == "fem":
        return 3.0 * viscous / h * (2.0 if case["mass"] == "consistent" else 1.0)
    steps = 1.0 / (h * case["cfl"]) if case.get("dt_rule") == "advective" else viscous
    return case["ppc"] * steps / h * case.get("refine", 1) * (3.0 if case.get("basis") == "gimp" else 1.0)


def _plan(tier: str) -> dict:
    quick = tier == "quick"
    q = QUICK if quick else {}
    meshes = MESHES["deep" if tier == "deep" else "full"]
    eps_list, skip, time_h = q.get("eps", EPS), q.get("skip", ()), q.get("TIME_H", TIME_H)
    fem = ("fem_consistent", "fem_lumped")
    kept = lambda m, h: m not in skip and not (quick and h not in q["H"])  # noqa: E731
    c13_solutions, c13_methods = q.get("C13", ((), ()))
    return {
        "table": {**{TableKey(s, m, e, h): method_case(m, s, e, h) for s in q.get("solutions", SOLUTIONS)
                     for m, hs in meshes["default" if s == DEFAULT else "other"].items() for e in eps_list
                     for h in (meshes.get("headline", {}).get(m, hs) if (s, e) == (DEFAULT, EPS[0]) else hs)
                     if kept(m, h)},
                  **{TableKey(s, m, e, h): method_case(m, s, e, h) for s in c13_solutions for m in c13_methods
                     for e in EPS for h in q.get("H", ())}},
        "profile": {(m, e): {**method_case(m, DEFAULT, e, PROFILE_H), "profile": True}
                    for e in (EPS[0], EPS[-1]) if e in eps_list for m in METHODS if m not in skip},
        "timestep": {(m, e, k): method_case(m, DEFAULT, e, time_h, **({"refine": k} if k > 1 else {}))
                     for e in q.get("time_eps", (EPS[0], EPS[-1]))
                     for m in q.get("time_methods", _MPM + ("mpm_exact_dt_h",)) for k in REFINE},
        "ppc": {PpcKey(m, h, n): method_case(m, DEFAULT, EPS[0], h, ppc=n) for m in _MPM for h in q.get("PPC_H", PPC_H)
                for n in q.get("PPC", PPC)},
        "lumping": {**{(m, mass, h): method_case(m, DEFAULT, EPS[0], h, mass=mass, cfl=LUMPING_CFL)
                       for h in q.get("lumping_H", H[:3]) for m in _MPM for mass in ("lumped", "consistent")},
                    **{(m, METHODS[m].settings["mass"], h): method_case(m, DEFAULT, EPS[0], h)
                       for h in q.get("lumping_H", H[:3]) for m in fem}},
        "diagnosis": {(label, h): method_case("mpm_calculated", DEFAULT, EPS[0], h, **changes)
                      for h in q.get("diagnosis_H", H[:3]) for label, changes in DIAGNOSIS.items()},
        "seeds": {SeedKey(m, EPS[0], h, layout, seed): method_case(m, DEFAULT, EPS[0], h, layout=layout, seed=seed)
                  for m, hs in meshes["seeds"].items() if m in q.get("seeded", SEEDED)
                  for h in q.get("seeds_H", hs) if h in hs and kept(m, h)
                  for layout, seed in (("regular", 0), *(("jittered", k) for k in q.get("seeds", SEEDS)))},
    }


def run(options: StudyOptions) -> None:
    """Every case in one sweep (shared cases run once, the longest first), then tables and figures."""
    got = options.sweep_plan(NAME, run_case, _plan(options.tier), cost=_cost)
    folder = options.folder(NAME)
    full = {m: {**(MPM if v.solver == "mpm" else FEM), **v.settings} for m, v in METHODS.items()}
    settings = {"quick": options.quick, "tier": options.tier, "T": T, "domain": [0, 2], "default_solution": DEFAULT,
                "compared_norm": f"{NORM} over {WHERE}",
                "methods": {m: {"label": v.label, "solver": v.solver, "settings": full[m], "source_row": v.source_row}
                            for m, v in METHODS.items()},
                "force": f"{burgers.BurgersSettings.force} (the viscous force in weak form, weights V_p = "
                         f"{burgers.BurgersSettings.weights}); the slides' second difference and weights h/N_p^i: "
                         "the diagnosis table",
                "time_steps": {
                    "mpm_calculated* and mpm_exact": f"dt = CFL min(h/max|v_p|, h^2/(2 eps)), CFL {MPM['cfl']}",
                    "mpm_exact_dt_h": f"dt = CFL h/max|v_p|, CFL {MPM['cfl']} "
                                      "(no viscous limit: no viscous force computed)",
                    "fem": f"dt = min(cfl h/max|v(x,0)|, cfl_visc h^2/(2 eps)), cfl {FEM['cfl']}, "
                           f"cfl_visc {FEM['cfl_visc']}, SSP-RK3"},
                "source_corrections": "exponents of the entries marked * in docs/claims.md moved by one power of ten"}
    methods = {m: {"source_row": v.source_row, "ppc": full[m].get("ppc", "")} for m, v in METHODS.items()}
    errors, orders = tables.errors_and_orders(got["table"], got["seeds"], methods, SOLUTIONS, DEFAULT, WHERE, NORM)
    time_h = QUICK["TIME_H"] if options.quick else TIME_H
    rows = {"errors": errors, BURGERS_ORDERS: orders, BURGERS_SEEDS: tables.seeds_rows(got["seeds"], full),
            "norms": tables.norms_rows(got["table"], {m: v.source_row for m, v in METHODS.items()}),
            "timestep": tables.timestep_rows(got["timestep"], time_h, REFINE, WHERE, NORM),
            BURGERS_PPC: tables.ppc_rows(got["ppc"], EPS[0], WHERE, NORM),
            BURGERS_LUMPING: tables.lumping_rows(got["lumping"], EPS[0], WHERE),
            BURGERS_DIAGNOSIS: tables.diagnosis_rows(got["diagnosis"], DIAGNOSIS, EPS[0], WHERE)}
    seeded = {"layouts": tables.LAYOUTS, "seeds": sorted({k.seed for k in got["seeds"]}), "eps": EPS[0],
              "solution": DEFAULT, "meshes": tables.meshes_of({(k.method, k.h) for k in got["seeds"]})}
    extra = {"errors": {"meshes": tables.meshes_of({(f"{k.solution}/{k.method}", k.h) for k in got["table"]})},
             BURGERS_ORDERS.stem: {"seeds": seeded, "interval": tables.INTERVAL}, BURGERS_SEEDS.stem: seeded,
             "timestep": {"h": time_h, "refine": list(REFINE),
                          "meaning": "time_error = |E(dt) - E(dt/16)|; time_below_space: time error < E(dt/16) "
                                     "(the space error)"},
             BURGERS_PPC.stem: {"eps": EPS[0], "solution": DEFAULT,
                                "meshes": tables.meshes_of({(k.method, k.h) for k in got["ppc"]})},
             BURGERS_LUMPING.stem: {"mpm_cfl": LUMPING_CFL, "eps": EPS[0], "solution": DEFAULT},
             BURGERS_DIAGNOSIS.stem: {"diagnosis": dict(DIAGNOSIS), "base": "mpm_calculated", "eps": EPS[0],
                                      "solution": DEFAULT}}
    publish(folder, rows, settings, extra, PLOTS)
    _profiles(folder / "profiles.png", got)


#: Each method's marker and line, and its colour in every figure; a second grouping of the curves (the
#: mesh, eps, mass) is drawn in the line styles of LINES, the colour kept.
class Style(NamedTuple):
    """A method's curves: matplotlib's format (marker and line) and colour."""

    fmt: str
    color: str


STYLE = {"mpm_calculated": Style("o-", "tab:blue"), "mpm_calculated_8": Style("o-.", "tab:cyan"),
         "mpm_calculated_16": Style("o--", "tab:purple"), "mpm_exact": Style("s-", "tab:orange"),
         "mpm_exact_dt_h": Style("D-", "tab:red"), "fem_consistent": Style("^--", "tab:green"),
         "fem_lumped": Style("v--", "tab:olive")}
LINES = ("-", "--", ":")
#: The diagnosis' variants' colours: a method's for the variant that is one (the first, the last two).
_VARIANT_COLOURS = dict(zip(DIAGNOSIS, (STYLE["mpm_calculated"].color, "tab:brown", "tab:pink", "tab:gray", "black",
                                        "gold", STYLE["mpm_calculated_16"].color, STYLE["mpm_exact"].color),
                             strict=True))


def _y(m: str) -> str:
    """The compared error's column (FEM: over nodes)."""
    return f"{'nodes' if m.startswith('fem') else WHERE}_{NORM}"


def _curves(methods, label="{m}", y=None, by="", values=(), **where) -> tuple[Curve, ...]:
    """A curve per method in its style (``{m}`` in ``label``: its name), and per value ``v`` of column
    ``by`` in ``values`` (``{v}`` in ``label``) in the line styles of :data:`LINES`; ``y`` defaults to
    the compared error."""
    return tuple(Curve(label.format(m=METHODS[m].label, v=v), y or _y(m),
                       STYLE[m].fmt if not by else STYLE[m].fmt[0] + LINES[k % len(LINES)],
                       {**where, "method": m, **({by: v} if by else {})}, options={"color": STYLE[m].color})
                 for m in methods for k, v in enumerate(values or ("",)))


def _sources(methods, **where) -> tuple[Curve, ...]:
    """The source's entries beside ``methods`` (open black: squares for the exact, circles for the
    calculated acceleration)."""
    rows = {m: METHODS[m].source_row for m in methods}
    return tuple(Curve(f"source, {rows[m]} a", "source", "ks" if rows[m] == "exact" else "ko", {**where, "method": m})
                 for m in methods)


def _range(m: str, labels=("_{m} mean", "_{m} lo", "_{m} hi"), panel: str = "", **where) -> tuple[Curve, ...]:
    """The mean (crosses) and the least and largest (dotted) compared error over the runs of seeded
    ``m``, labelled ``labels`` (``{m}``: its name; a label from ``_`` stays out of the legend)."""
    return tuple(Curve(label.format(m=METHODS[m].label), f"{_y(m)}_{k}", fmt, {**where, "method": m}, panel,
                       options={"color": STYLE[m].color, "lw": 0.8})
                 for label, k, fmt in zip(labels, ("mean", "lo", "hi"), ("+", ":", ":"), strict=True))


def _seed_panel(m: str) -> tuple[Curve, ...]:
    """The panel of seeded ``m``: its regular layout's run, the mean and range over its runs, the source."""
    name, row, where = METHODS[m].label, METHODS[m].source_row, {"method": m, "solution": DEFAULT, "eps": EPS[0]}
    return (Curve("regular layout", _y(m), STYLE[m].fmt, where, name, options={"color": STYLE[m].color}),
            *_range(m, ("mean over the layouts", "least", "largest"), name, solution=DEFAULT, eps=EPS[0]),
            Curve(f"source, {row} a", "source", "ks" if row == "exact" else "ko", where, name))


_ERROR = dict(ylabel=f"velocity error ({NORM})", slopes=(1, 2))
_OVER = f"{NORM} velocity error over {WHERE} (MPM) or nodes (FEM)"
_RANGE = "crosses and dotted: mean and range over the layouts"
PLOTS = (
    Plot("convergence.png", f"Burgers, T = {T}, {DEFAULT} solution: {_OVER} against h; open black: the source; "
         f"{_RANGE}", "errors", "h",
         _curves(METHODS, solution=DEFAULT) + tuple(c for m in SEEDED for c in _range(m, solution=DEFAULT))
         + _sources(("mpm_exact_dt_h", "mpm_calculated"), solution=DEFAULT),
         split=("eps",), ncols=3, size=(4.2, 4.0), **_ERROR),
    Plot("seeds.png", f"C13's settings, eps = {EPS[0]}: the regular layout, and the mean and range over the layouts",
         "errors", "h", tuple(c for m in SEEDED for c in _seed_panel(m)), ncols=2, size=(4.6, 3.8),
         **{**_ERROR, "ylabel": f"velocity error ({NORM} over {WHERE})"}),
    Plot("solutions.png", f"Every candidate exact solution: {_OVER} against h", "errors", "h",
         _curves(METHODS, eps=EPS[::4]) + _sources(("mpm_exact_dt_h", "mpm_calculated"), eps=EPS[::4]),
         split=("eps", "solution"), ncols=len(SOLUTIONS), size=(4.2, 3.8), **_ERROR),
    Plot("ppc.png", f"C3, Burgers: error against N_p ({DEFAULT}, eps = {EPS[0]})", BURGERS_PPC.stem, "ppc",
         _curves(_MPM, "{m}, h = {v}", by="h", values=PPC_H), xlabel="particles per cell N_p",
         ylabel=f"velocity error ({NORM} over {WHERE})"),
    Plot("lumping.png", f"C15: lumped against consistent mass ({DEFAULT}, eps = {EPS[0]}; MPM CFL {LUMPING_CFL})",
         BURGERS_LUMPING.stem, "h", _curves(_MPM + ("fem_consistent", "fem_lumped"), "{m}, {v}", "L2", "mass",
                                            ("consistent", "lumped")),
         size=(6.2, 4.2), **{**_ERROR, "ylabel": "velocity error (L2)"}),
    Plot("timestep.png", f"Time error at fixed h: dt / {', '.join(map(str, REFINE))}", "timestep", "dt",
         _curves(_MPM + ("mpm_exact_dt_h",), "{m}, eps = {v}", by="eps", values=(EPS[0], EPS[-1])),
         xlabel="dt (smallest step of the run)", ylabel=f"velocity error ({NORM} over {WHERE})", size=(6.2, 4.2)),
    Plot("diagnosis.png", f"The calculated acceleration ({DEFAULT}, eps = {EPS[0]}): one change at a time",
         BURGERS_DIAGNOSIS.stem, "h",
         tuple(Curve(label, f"{WHERE}_L1", "o-", {"variant": label}, options={"color": colour})
               for label, colour in _VARIANT_COLOURS.items()),
         ylabel=f"velocity error (L1 over {WHERE})", slopes=(1, 2), size=(6.2, 4.6)),
)


def _profiles(path, got) -> None:
    """Velocity and its error at T on the profile mesh, one row per eps: particles (MPM), nodes (FEM)."""
    xe, exact, rows = np.linspace(0, 2, 2001), {}, {}
    for eps in sorted({e for (_, e) in got["profile"]}, reverse=True):
        v, row = make_solution(DEFAULT, eps).v, f"eps = {eps}"
        exact[row] = {"velocity": (xe, v(xe, T)), "error at T": (xe, 0 * xe)}
        rows[row] = [("exact, t = 0", xe, {"velocity": v(xe, 0.0)}, "k:", {"lw": 0.8})]
        for m in (m for m in METHODS if got["profile"].get((m, eps), {}).get("ok")):
            p, mpm = got["profile"][(m, eps)]["profile"], METHODS[m].solver == "mpm"
            x, u = (np.array(p[k]) for k in (("x", "velocity") if mpm else ("nodes", "nodal_velocity")))
            rows[row].append((METHODS[m].label, x, {"velocity": u, "error at T": u - v(x, T)}, "." if mpm else "-",
                              {"ms" if mpm else "lw": 1.5 if mpm else 0.9, "color": STYLE[m].color}))
    if rows:
        plots.profile_grid(path, exact, rows,
                           f"{DEFAULT} solution at T = {T}, h = {PROFILE_H}: particles (MPM), nodes (FEM)")


#: The cost model of :mod:`mpm_fem.app.estimate`: CPU seconds per unit of :func:`_cost`, from the full
#: tier's cases on the 2-core machine (2026-11-26, from-scratch run: CHANGES.md).
PLAN, COST, SECONDS_PER_COST = _plan, _cost, 9.0e-8

if __name__ == "__main__":
    sys.exit(script_main(NAME))
