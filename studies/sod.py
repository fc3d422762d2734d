"""Sod's shock tube: MPM beside fixed-mesh FEM, a finite-volume reference and the exact solution.

Density (and, at the particles, internal energy) error at T against the exact Riemann solution on every
mesh of the source's table, over particles and over grid nodes (``m_i / int S_i``), for each setting of
:data:`SETTINGS` (particles per cell, CFL; the same on every mesh), with the regular particle layout and
the jittered ones of :data:`SEEDS`. Tables: ``seeds`` (one row per run) and ``convergence`` (per setting
and mesh, the spread over seeds; C11, E3), ``regions`` (C12), ``extrema`` (C14), ``ppc`` (C3), ``mass``
(C15), ``plateau`` (what moves the floor: one setting of the study's own, :data:`MPM`, changed at a time).
"""

from __future__ import annotations

import sys
from typing import NamedTuple

import numpy as np

from baselines import fem_euler, fv_euler
from baselines.exact import riemann
from mpm_fem.app import plots
from mpm_fem.app.plots import Curve, Plot
from mpm_fem.app.study import StudyOptions, publish, script_main
from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.particles import PositivityError
from mpm_fem.measure import shock_tube, sod_tables, source
from mpm_fem.measure.regions import REGION_NAMES, ExtremaCounter, describe
from mpm_fem.measure.schema import SOD_CONVERGENCE, SOD_EXTREMA, SOD_MASS, SOD_PPC, SOD_REGIONS, SOD_SEEDS
from mpm_fem.problems import sod

NAME = "sod"
#: the source's meshes and one finer; the full tier runs the source's (FULL_H: the finer one cost 7 of its CPU-min
#: with its references, moved to the deep tier on 2026-11-28 to keep the full tier within its hour), the deep tier
#: every one of H and DEEP_H
H = (0.01, 0.005, 0.0025, 0.00125, 0.000625, 0.0003125, 0.00015625)
FULL_H = H[:6]
DEEP_H = (0.000078125,)
SOURCE = source.SOD
T = sod.SodSettings.T
# One set of MPM settings for every h (never tuned per mesh); why these: ppc.csv and plateau.csv
MPM = dict(ppc=16, cfl=0.05, av_linear=0.5, av_quadratic=2.0, mass="lumped", scheme="usl", basis="mpm",
           layout="regular", seed=0)
# E3: FEM with the baselines.fem_euler defaults (viscosity on every cell); FV with the stronger of its limiters
FEM = dict(cfl=0.3, viscosity_linear=0.1, viscosity_quadratic=1.0, compression_only=False)
FV = dict(cfl=0.8, limiter="mc")
REGION_HALF_WIDTH = 0.02  # every wave, every mesh: two cells of the coarsest mesh on each side
#: the regions the plateau table names (columns of a run's ``regions``, :data:`REGION_NAMES`)
SMOOTH, BEHIND_SHOCK = REGION_NAMES.index("smooth"), REGION_NAMES.index("behind shock")
PROFILE_H = (0.01, 0.0025)
PPC = (1, 2, 4, 8, 16, 32)
PPC_H = (0.01, 0.0025, 0.000625)
CONSISTENT_H = H[:4]  # the consistent particle mass costs ~2x: the two finest meshes are left out
PLATEAU_H = (0.0025, 0.00125)
PLATEAU_VARIANTS = {"study settings": {}, "CFL 0.025": {"cfl": 0.025}, "CFL 0.1": {"cfl": 0.1}, "8 ppc": {"ppc": 8},
                    "32 ppc": {"ppc": 32}, "viscosity x0.5": {"av_linear": 0.25, "av_quadratic": 1.0},
                    "viscosity x2": {"av_linear": 1.0, "av_quadratic": 4.0}, "USF": {"scheme": "usf"},
                    "MUSL": {"scheme": "musl"}, "GIMP": {"basis": "gimp"}, "consistent mass": {"mass": "consistent"}}
#: the convergence study's MPM settings, (particles per cell, CFL): the study's own first (on every mesh), the
#: source's 4-8 per cell at the study's CFL and 4 per cell at the CLI's default CFL (down to the last of SEED_H)
SETTINGS = ((MPM["ppc"], MPM["cfl"]), (8, MPM["cfl"]), (4, MPM["cfl"]), (4, sod.SodSettings.cfl))
SEEDS = (1, 2, 3, 4, 5)  # the jittered layouts' seeds, beside the regular layout (seed 0)
SEED_H = H[:6]  # the jittered layouts' meshes, in every tier
#: the settings the deep tier runs on every mesh (16 and 4 per cell at the study's CFL); the others run to H's finest
DEEP_SETTINGS = (SETTINGS[0], (4, MPM["cfl"]))
#: C14: a particle moves when |v_p| exceeds this fraction of the smaller sound speed of the two initial states
MOVING_FRACTION = 0.01
_GAS = sod.SodSettings()
MOVING_SPEED = MOVING_FRACTION * min((_GAS.gamma * p / rho) ** 0.5 for rho, _, p in (_GAS.left, _GAS.right))
#: the quick tier. Its convergence study runs two settings, ``{setting: (meshes, meshes of the jittered
#: layouts)}``: the study's own on its meshes, regular layout only, and the cheapest setting the source states
#: (4 per cell at the command line's CFL, 0.1) with the regular layout and the five seeds on the meshes C11
#: needs (at least FLOOR_MESHES = 5 with MIN_RUNS = 6 runs each: mpm_fem/measure/claims/sod.py). The other
#: settings of SETTINGS run from the full tier on (at fewer meshes C11 would not judge them).
QUICK = dict(H=H[:3], PPC_H=(0.01,), CONSISTENT_H=H[:1], PLATEAU_H=(),
             SETTINGS={SETTINGS[0]: (H[:3], ()), SETTINGS[3]: (H[:5], H[:5])})


def run_case(case: dict) -> dict:
    """One run, measured (:mod:`mpm_fem.measure.shock_tube`): ``case["solver"]`` is ``"mpm"`` (keys of
    :data:`MPM` and ``h``; ``extrema``: count new extrema, :class:`ExtremaCounter`), ``"fem"`` (``h``,
    ``mass`` and the keys of :data:`FEM`) or ``"fv"``."""
    h, width, profiles = case["h"], case.get("region_half_width"), case.get("profiles", False)
    if case["solver"] == "fv":
        return shock_tube.fv(fv_euler.solve(h, cfl=case["cfl"], limiter=case["limiter"]), h)
    if case["solver"] == "fem":
        try:
            r = fem_euler.solve(h, mass=case["mass"], cfl=case["cfl"],
                                viscosity=_viscosity(case))
        except fem_euler.PositivityError as err:
            return {"ok": False, "error": str(err)}
        return shock_tube.fem(r, uniform_grid(0.0, 1.0, h).lumped_mass, width, profiles)
    settings = sod.SodSettings(h=h, **{k: case[k] for k in MPM})
    counter = ExtremaCounter(uniform_grid(0.0, 1.0, h), moving_speed=MOVING_SPEED) if case["extrema"] else None
    try:
        result = sod.simulate(settings, progress=False, observer=counter)
    except (PositivityError, FloatingPointError) as err:
        return {"ok": False, "error": str(err), "steps": counter.steps if counter else None}
    return shock_tube.mpm(settings, result, sod.errors(settings, result), counter and counter.summary(), width,
                          profiles)


def _viscosity(fem: dict) -> fem_euler.Viscosity:
    return fem_euler.Viscosity(fem["viscosity_linear"], fem["viscosity_quadratic"], fem["compression_only"])


def mpm_case(h: float, **changes) -> dict:
    """The MPM case at ``h`` with the study settings, ``changes`` applied; new extrema counted on a
    regular layout (``extrema``)."""
    case = {"solver": "mpm", "h": h, **MPM, **changes, "region_half_width": REGION_HALF_WIDTH}
    return {**case, "profiles": h in PROFILE_H and not changes, "extrema": case["layout"] == "regular"}


def _setting_case(h: float, ppc: int, cfl: float, **changes) -> dict:
    """The case of one setting of :data:`SETTINGS` (the study's own case for the study's settings)."""
    return mpm_case(h, **{k: v for k, v in dict(ppc=ppc, cfl=cfl, **changes).items() if MPM.get(k) != v})


def fem_case(h: float, mass: str) -> dict:
    return {"solver": "fem", "h": h, "mass": mass, **FEM, "region_half_width": REGION_HALF_WIDTH,
            "profiles": h in PROFILE_H}


class SettingKey(NamedTuple):
    """A case of the ``settings`` plan: particles per cell, CFL, mesh (the regular layout)."""

    ppc: int
    cfl: float
    h: float


class PpcKey(NamedTuple):
    """A case of the ``ppc`` plan (C3): mesh, particles per cell (the study's other settings)."""

    h: float
    ppc: int


class SeedKey(NamedTuple):
    """A case of the ``seeds`` plan: particles per cell, CFL, mesh, seed of the jittered layout."""

    ppc: int
    cfl: float
    h: float
    seed: int


def _cost(case: dict) -> float:
    """Particles x steps, to start the longest runs first."""
    if case["solver"] in ("fem", "fv"):
        return 1.0 / case["h"] ** 2
    return case["ppc"] / (case["h"] ** 2 * case["cfl"]) * (2.0 if case["mass"] == "consistent" else 1.0)


def _plan(tier: str) -> dict:
    q = QUICK if tier == "quick" else {}
    hs, ppc_h = q.get("H", H + DEEP_H if tier == "deep" else FULL_H), q.get("PPC_H", PPC_H)
    consistent_h, plateau_h = q.get("CONSISTENT_H", CONSISTENT_H), q.get("PLATEAU_H", PLATEAU_H)

    def meshes(setting):
        if setting == SETTINGS[0] or (tier == "deep" and setting in DEEP_SETTINGS):
            return hs
        return H if tier == "deep" else SEED_H

    # {setting: (its meshes, the meshes of its jittered layouts)}; the fixed-mesh references on every mesh
    runs = q.get("SETTINGS", {setting: (meshes(setting), SEED_H) for setting in SETTINGS})
    refs = sorted(set(hs).union(*(m for m, _ in runs.values())), reverse=True)
    return {
        "mpm": {h: mpm_case(h) for h in hs},
        "settings": {SettingKey(n, cfl, h): _setting_case(h, n, cfl) for (n, cfl), (ms, _) in runs.items() for h in ms},
        "seeds": {SeedKey(n, cfl, h, seed): _setting_case(h, n, cfl, layout="jittered", seed=seed)
                  for (n, cfl), (_, jittered) in runs.items() for h in jittered for seed in SEEDS},
        "mpm_consistent": {h: mpm_case(h, mass="consistent") for h in consistent_h},
        "fem_consistent": {h: fem_case(h, "consistent") for h in refs},
        "fem_lumped": {h: fem_case(h, "lumped") for h in refs},
        "fv": {h: {"solver": "fv", "h": h, **FV} for h in refs},
        "ppc": {PpcKey(h, n): mpm_case(h, ppc=n) if n != MPM["ppc"] else mpm_case(h) for h in ppc_h for n in PPC},
        "plateau": {(h, name): mpm_case(h, **change) if change else mpm_case(h)
                    for h in plateau_h for name, change in PLATEAU_VARIANTS.items()},
    }


def run(options: StudyOptions) -> None:
    """All cases in one sweep (shared ones run once), then tables and figures."""
    got = options.sweep_plan(NAME, run_case, _plan(options.tier), cost=_cost)
    folder = options.folder(NAME)
    settings = {"mpm": MPM, "fem": {**FEM, "viscosity": _viscosity(FEM).name},
                "fv": {**FV, "scheme": fv_euler.label(FV["limiter"])}, "region_half_width": REGION_HALF_WIDTH, "T": T,
                "quick": options.quick, "tier": options.tier,
                "problem": {k: getattr(_GAS, k) for k in ("gamma", "left", "right", "x0", "T")}}
    seeds = sod_tables.seed_rows(got["settings"], got["seeds"])
    refs = (got["fem_consistent"], got["fem_lumped"])
    tables = {SOD_CONVERGENCE: sod_tables.convergence_rows(seeds, got["settings"], *refs, got["fv"], SOURCE),
              SOD_SEEDS: seeds, SOD_REGIONS: sod_tables.region_rows(got["settings"], *refs),
              SOD_EXTREMA: sod_tables.extrema_rows(got["settings"]), SOD_PPC: _ppc(got), SOD_MASS: _mass(got),
              "plateau": _plateau(got) if got["plateau"] else []}
    waves = riemann.wave_positions(T, sod.SodSettings.left, sod.SodSettings.right)
    runs = {"runs": {"ppc_cfl": [list(x) for x in dict.fromkeys((k.ppc, k.cfl) for k in got["settings"])],
                     "other settings": "as in mpm",
                     "layouts": {"regular": [0], "jittered": sorted({k.seed for k in got["seeds"]})},
                     "jittered_meshes": sorted({k.h for k in got["seeds"]}, reverse=True)}}
    extra = {SOD_CONVERGENCE.stem: runs, SOD_SEEDS.stem: runs,
             SOD_REGIONS.stem: {**runs, "regions": describe(REGION_HALF_WIDTH, waves, T)},
             SOD_EXTREMA.stem: {**runs, "rtol": 1e-9, "moving": f"|v_p| > {MOVING_FRACTION:g} x the smaller sound "
                                f"speed of the initial states = {MOVING_SPEED:.6g}", "definition":
                                "new strict local extremum among position-ordered particles"},
             SOD_PPC.stem: {"ppc": list(PPC), "other settings": "as in mpm"},
             "plateau": {"variants": {k: v or "none" for k, v in PLATEAU_VARIANTS.items()}}}
    publish(folder, tables, settings, extra, PLOTS)
    shown = [r for r in tables[SOD_REGIONS] if (r["ppc"], r["cfl"]) in (("", ""), (MPM["ppc"], MPM["cfl"]))]
    plots.stacked_shares(folder / "regions.png", shown,
                         REGION_NAMES, f"C12: density L1 error by region of the exact solution at T = {T} "
                         f"(half-width {REGION_HALF_WIDTH}), MPM at {MPM['ppc']} per cell",
                         "share of the density L1 error (total above)")
    _profiles(folder, got)


def _L1(r, where="nodes", norm="L1"):
    return r["density"][where][norm] if r["ok"] else float("nan")


def _ppc(got) -> list[dict]:
    rows = []
    for k in sorted(got["ppc"], key=lambda k: (-k.h, k.ppc)):
        r = got["ppc"][k]
        ok = r["ok"]
        rows.append({"h": k.h, "ppc": k.ppc, "ok": ok,
                     **{f"{w}_{k}": _L1(r, w, k) if ok else "" for w in ("nodes", "particles") for k in ("L1", "L2")},
                     "steps": r.get("steps"), "wall_s": round(r["wall_s"], 2) if ok else "",
                     "error": "" if ok else r["error"]})
    return rows


def _mass(got) -> list[dict]:
    rows = []
    for h in sorted(got["mpm_consistent"], reverse=True):
        lump, cons, fl, fc = got["mpm"][h], got["mpm_consistent"][h], got["fem_lumped"][h], got["fem_consistent"][h]
        rows.append({
            "h": h, "mpm_lumped_nodes_L1": _L1(lump), "mpm_consistent_nodes_L1": _L1(cons),
            "mpm_consistent_over_lumped_nodes": _L1(cons) / _L1(lump),
            "mpm_lumped_particles_L1": _L1(lump, "particles"), "mpm_consistent_particles_L1": _L1(cons, "particles"),
            "mpm_consistent_over_lumped_particles": _L1(cons, "particles") / _L1(lump, "particles"),
            "fem_lumped_L1": _L1(fl), "fem_consistent_L1": _L1(fc), "fem_consistent_over_lumped": _L1(fc) / _L1(fl),
            "mpm_consistent_error": "" if cons["ok"] else cons["error"]})
    return rows


def _plateau(got) -> list[dict]:
    rows = []
    for (h, name), r in got["plateau"].items():
        base = got["plateau"][(h, "study settings")]
        row = {"h": h, "variant": name, "change": str(PLATEAU_VARIANTS[name]) or "none", "ok": r["ok"]}
        if r["ok"]:
            row.update({"nodes_L1": _L1(r), "particles_L1": _L1(r, "particles"), "nodes_vs_study": _L1(r) / _L1(base),
                        "particles_vs_study": _L1(r, "particles") / _L1(base, "particles"),
                        "nodes_smooth_L1": r["regions"]["nodes"][SMOOTH],
                        "nodes_behind_shock_L1": r["regions"]["nodes"][BEHIND_SHOCK],
                        "particles_behind_shock_L1": r["regions"]["particles"][BEHIND_SHOCK],
                        "density_new_extrema_per_step": r["extrema"]["density"]["new_per_step"],
                        "volume_drift": r["volume_drift"], "head_shift": r["head_shift"], "steps": r["steps"],
                        "error": ""})
        else:
            row["error"] = r["error"]
        rows.append(row)
    return rows


_JITTERED = {"color": "tab:purple", "lw": 0.7}
_SETTING = ("ppc", "cfl")
PLOTS = (
    Plot("convergence.png", f"Sod, T = {T}: density L1 against h per setting, the regular layout and the jittered "
         "ones (mean, range), beside the source's table", SOD_CONVERGENCE.stem, "h", (
        Curve("MPM particles, regular", "mpm_particles_L1", "s-"), Curve("MPM nodes, regular", "mpm_nodes_L1"),
        Curve("MPM particles, jittered: mean", "jittered_particles_L1_mean", "d-", options=_JITTERED),
        *(Curve(f"MPM particles, jittered: {k}", f"jittered_particles_L1_{k}", ":", options=_JITTERED)
          for k in ("lo", "hi")),
        Curve("FEM lumped", "fem_lumped_L1", "v--"), Curve(fv_euler.label(FV["limiter"]), "fv_L1", "x-."),
        Curve("source (slides)", "source_L1", "k*")),
        ylabel="density error (L1)", slopes=(0.5, 1), split=_SETTING, ncols=2, size=(4.6, 3.8)),
    Plot("extrema.png", "C14: new extrema per particle-step, at particles crossing a node and at moving particles "
         "that do not cross, per setting (particles per cell, CFL)", SOD_EXTREMA.stem, "h", tuple(
        Curve(f"{{ppc}} ppc, CFL {{cfl}}: {who}", f"{name}_rate_{k}", fmt, panel=name, group=_SETTING)
        for name in ("density", "energy")
        for k, who, fmt in (("crossing", "crossing", "o-"), ("moving", "moving, not crossing", "s:"))),
         ylabel="new extrema per particle-step", size=(4.8, 3.8)),
    Plot("ppc.png", "C3: density error against particles per cell, one line per mesh", SOD_PPC.stem, "ppc", tuple(
        Curve("h = {h}", f"{w}_L1", panel=f"over {name}", group=("h",), where={"ok": True})
        for w, name in (("nodes", "grid nodes"), ("particles", "particles"))),
        xlabel="particles per cell N_p", ylabel="density error (L1)", size=(4.5, 3.6)),
)


def _profiles(folder, got) -> None:
    xe = np.linspace(0, 1, 2001)
    rho, u, p = riemann.sample(xe, T, sod.SodSettings.left, sod.SodSettings.right, x0=0.5, gamma=1.4)
    exact = {k: (xe, v) for k, v in (("density", rho), ("velocity", u), ("pressure", p), ("energy", p / (0.4 * rho)))}
    for h in PROFILE_H:
        m, fc, fl = (got[k].get(h) for k in ("mpm", "fem_consistent", "fem_lumped"))
        if m is None or not m.get("ok") or "profile" not in m:
            continue
        mp = m["profile"]
        nodal = {"density": mp["nodal_density"], "velocity": mp["nodal_velocity"]}
        fem = [(label, r["profile"]["x"], r["profile"], fmt, {"ms": 2.5, "lw": 0.7}) for r, fmt, label in
               ((fc, "^-", "FEM consistent"), (fl, "v-", "FEM lumped"))
               if r is not None and r.get("ok") and "profile" in r]
        plots.profile_grid(folder / f"profiles_h{h:g}.png", exact, {
            f"MPM ({MPM['ppc']} ppc, CFL {MPM['cfl']})": [
                ("MPM particles", mp["x"], mp, ".", {"ms": 1.5, "color": "tab:blue"}),
                ("MPM grid nodes", mp["nodes"], nodal, "x", {"ms": 3, "color": "tab:red"})],
            f"FEM (P1, SSPRK3, CFL {FEM['cfl']})": fem},
            f"Sod at T = {T}, h = {h:g}: MPM (top) and fixed-mesh FEM (bottom) on the same mesh")


#: The cost model of :mod:`mpm_fem.app.estimate`: CPU seconds per unit of :func:`_cost`, from the full
#: tier's cases on the 2-core machine (2026-11-26, from-scratch run: CHANGES.md).
PLAN, COST, SECONDS_PER_COST = _plan, _cost, 2.0e-8

if __name__ == "__main__":
    sys.exit(script_main(NAME))
