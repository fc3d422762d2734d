"""E3 on Sod: MPM within a constant factor of the fixed-mesh FEM on the same meshes, judged for every
setting of the convergence study over every run (``sod/seeds``: the regular layout and the jittered
ones, paired by seed; :mod:`mpm_fem.measure.spread`), the headline on the settings the source
prescribes (:mod:`.sod_settings`).
"""

from __future__ import annotations

import math

from mpm_fem.measure.claims.base import CONFIRMED, PARTLY, REFUTED, Finding, Tables, claim, short
from mpm_fem.measure.claims.rows import num, select, span
from mpm_fem.measure.claims.rules import rule
from mpm_fem.measure.claims.sod_settings import (
    CONVERGENCE,
    MIN_RUNS,
    SEEDS,
    _label,
    _per_setting,
    _prescribed,
    _settings_text,
    headline,
)
from mpm_fem.measure.source import OPTIMAL_PPC
from mpm_fem.measure.spread import Spread, by_mesh, spread
from mpm_fem.measure.tables import setting

#: E3: MPM's error over the fixed-mesh FEM's (lumped mass, as MPM's) on the finest mesh within E3_FACTOR
#: of that ratio on the coarsest, at the nodes and at the particles.
E3_FACTOR = rule("E3_FACTOR")
E3_WHERE = {"particles": "particles_L1", "nodes": "nodes_L1"}
#: E3: the methods whose density L1 the evidence names on the finest mesh.
SIDE_BY_SIDE = {"MPM nodes": "mpm_nodes_L1", "FEM consistent": "fem_consistent_L1", "FEM lumped": "fem_lumped_L1",
                "FV": "fv_L1"}


def _growth(rows: list[dict], convergence: list[dict], key: str) -> tuple[Spread, float, float]:
    """The spread over seeds of ``(E(h_f) / FEM(h_f)) / (E(h_c) / FEM(h_c))``: the change of MPM's error
    over the lumped FEM's from the coarsest mesh ``h_c`` to the finest ``h_f`` with at least MIN_RUNS runs."""
    fem = {num(r, "h"): num(r, "fem_lumped_L1") for r in convergence}
    meshes = {h: runs for h, runs in by_mesh(rows, key).items() if sum(map(math.isfinite, runs.values())) >= MIN_RUNS}
    if len(meshes) < 2:
        return spread(()), math.nan, math.nan
    coarse, fine = max(meshes), min(meshes)
    fem_change = fem.get(fine, math.nan) / fem.get(coarse, math.nan)
    seeds = sorted(meshes[coarse].keys() & meshes[fine].keys(), key=repr)
    return spread(meshes[fine][k] / meshes[coarse][k] / fem_change for k in seeds), coarse, fine


def _e3_setting(rows: list[dict], n: int, cfl: float, convergence: list[dict]) -> tuple[str, str]:
    found, parts = [], []
    for where, key in E3_WHERE.items():
        g, coarse, fine = _growth(rows, convergence, key)
        if g.n == 0:
            return "not measured", f"fewer than two meshes with {MIN_RUNS} runs"
        which = ("constant" if g.above(1 / E3_FACTOR) and g.below(E3_FACTOR) else "MPM's grows" if g.above(E3_FACTOR)
                 else "FEM's grows" if g.below(1 / E3_FACTOR) else "undecided")
        found.append(which)
        parts.append(f"{where} x{g.text()} ({which})")
    verdict = (CONFIRMED if all(w == "constant" for w in found)
               else REFUTED if all(w.endswith("grows") for w in found) else PARTLY)
    return verdict, ", ".join(parts) + f" from h = {coarse:g} to {fine:g}"


@claim("E3", source="MPM beside fixed-mesh FEM (consistent and lumped) and a finite-volume reference",
       tables=(SEEDS, CONVERGENCE), study="sod",
       thresholds=f"per setting, over the regular and the jittered layouts (paired by seed): MPM's density L1 over "
                  f"the lumped FEM's on the finest mesh with at least {MIN_RUNS} runs within {E3_FACTOR:g}x of that "
                  f"ratio on the coarsest (the change between them in [1/{E3_FACTOR:g}, {E3_FACTOR:g}) over every "
                  "seed), at the nodes and at the particles -> confirmed; both outside over every seed -> refuted, "
                  "saying which error grows; else partly. Headline: the settings with "
                  f"{OPTIMAL_PPC[0]}-{OPTIMAL_PPC[1]} particles per cell, their common verdict, partly when they "
                  "differ")
def _e3(t: Tables) -> Finding:
    """MPM and the fixed-mesh FEM run on the same meshes with the same lumped mass, each with its own
    artificial viscosity and time step (the FEM's on every cell at CFL 0.3, MPM's in compression at CFL
    0.05: the settings table), so their ratio compares the two methods as each is run, not the particles
    alone. MPM's error is read at the particles and at the nodes, the FEM's at its nodes. Each change is a
    range over the runs (the regular layout and the jittered seeds, paired by seed)."""
    verdicts, lines = _per_setting(_e3_setting, t[SEEDS], t[CONVERGENCE])
    fv = setting(t, CONVERGENCE, "fv.scheme", "FV") + ("" if setting(t, CONVERGENCE, "fv.limiter")
                                                       else ", limiter not recorded")
    fem = "FEM: " + setting(t, CONVERGENCE, "fem.viscosity", "viscosity variant not recorded")
    last = min(t[CONVERGENCE], key=lambda r: num(r, "h"))
    rows = t[SEEDS]
    growth = {k: _growth(select(rows, ppc=k.ppc, cfl=k.cfl), t[CONVERGENCE], E3_WHERE["particles"])[0]
              for k in verdicts if _prescribed(k.ppc)}
    table = []
    for k in verdicts:
        row = {"setting": _label(*k)}
        for where, key in E3_WHERE.items():
            g, coarse, fine = _growth(select(rows, ppc=k.ppc, cfl=k.cfl), t[CONVERGENCE], key)
            row[f"MPM/FEM at the {where}, finest over coarsest"] = g.text()
        row["verdict"] = verdicts[k]
        table.append(row)
    meshes = [h for k in growth for h in _growth(select(rows, ppc=k.ppc, cfl=k.cfl), t[CONVERGENCE],
                                                  E3_WHERE["particles"])[1:] if math.isfinite(h)]
    where = f" from h = {max(meshes):g} to {min(meshes):g}" if meshes else ""
    sentence = (f"on the same meshes{where} MPM's particle density error over the fixed-mesh FEM's changes by a "
                f"factor {span([g.mean for g in growth.values()], '.1f')} at {OPTIMAL_PPC[0]}-{OPTIMAL_PPC[1]} "
                f"particles per cell (mean over the layouts; {min(g.lo for g in growth.values()):.1f} to "
                f"{max(g.hi for g in growth.values()):.1f} over every layout; a constant factor would stay within "
                f"{E3_FACTOR:g})")
    return Finding(headline(verdicts), (
        f"MPM/FEM particle error, finest over coarsest mesh at {OPTIMAL_PPC[0]}-{OPTIMAL_PPC[1]} per cell: "
        + ", ".join(f"x{g.text()} ({k.ppc} ppc at CFL {k.cfl:g})" for k, g in growth.items()) + "; "
        + _settings_text(verdicts, lines)
        + f"; density L1 at h = {last['h']} ({_label(int(num(last, 'ppc')), num(last, 'cfl'))}, regular): "
        + ", ".join(f"{m} {num(last, c):.3g}" for m, c in SIDE_BY_SIDE.items()) + f"; FV: {fv}; {fem}"),
        sentence, tuple(table), key=short(
            f"MPM's particle density error over the fixed-mesh FEM's changes by a factor "
            f"{span([g.mean for g in growth.values()], '.1f')}{where} at {OPTIMAL_PPC[0]}-{OPTIMAL_PPC[1]} per cell",
            f"MPM's particle density error over the fixed-mesh FEM's changes by a factor "
            f"{span([g.mean for g in growth.values()], '.1f')} at {OPTIMAL_PPC[0]}-{OPTIMAL_PPC[1]} per cell"))
