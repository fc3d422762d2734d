"""Made-up Sod runs turned into the Sod study's tables, for the tests of the Sod claims.

``made_up_tables(model)`` builds the runs of the study's plan (every setting of ``studies.sod.SETTINGS``
on ``MESHES``, the regular layout and the jittered seeds), each with the errors ``model`` gives,
builds the tables with the study's own builders (:mod:`mpm_fem.measure.sod_tables`), writes them
through their declarations into a folder and reads them back with
:func:`mpm_fem.measure.tables.load_tables`: the claims then read strings, as from the committed CSVs.

``model(quantity, ppc, cfl, h, seed) -> error`` for the quantities ``particles``, ``nodes``,
``energy`` and ``fem`` (the fixed-mesh FEM, seed ``None``). The default :func:`diverging` has the
shape measured on Sod: first order, then a particle error that grows below h = 0.00125.
"""

from __future__ import annotations

import math
import tempfile
from pathlib import Path

from mpm_fem.app.study import publish
from mpm_fem.measure import sod_tables as builders
from mpm_fem.measure.regions import REGION_NAMES
from mpm_fem.measure.schema import SOD_CONVERGENCE, SOD_EXTREMA, SOD_REGIONS, SOD_SEEDS
from mpm_fem.measure.tables import load_tables
from studies import sod as study

MESHES = study.H[:6]
#: the share of each region of the exact solution in a run's L1 error: the waves (1, 3, 4, 6) carry 60%
SHARES = (0.1, 0.15, 0.25, 0.1, 0.2, 0.05, 0.15)


def _noise(seed, h: float) -> float:
    """A fixed relative deviation per seed and mesh, within +-2% (none for the regular layout)."""
    return 0.0 if seed in (None, 0) else 0.02 * math.sin(7.0 * seed + 3.0 * math.log(h))


def diverging(quantity: str, ppc: int, cfl: float, h: float, seed) -> float:
    """First order down to h = 0.00125, then (particles, energy) growing as h^-0.5; nodes level off."""
    base = {"particles": 1.2, "nodes": 1.0, "energy": 3.0, "fem": 1.1}[quantity] * h
    if quantity in ("particles", "energy") and h < 0.00125:
        base = {"particles": 1.2, "energy": 3.0}[quantity] * 0.00125 * (0.00125 / h) ** 0.5
    if quantity == "nodes" and h < 0.00125:
        base = 0.00125
    return base * (1.0 + _noise(seed, h))


def _run(model, ppc, cfl, h, seed, extrema: dict | None) -> dict:
    e = {q: model(q, ppc, cfl, h, seed) for q in ("particles", "nodes", "energy")}
    return {"ok": True, "steps": 100, "particles": int(ppc / h), "wall_s": 0.1, "volume_drift": 0.0,
            "energy_drift": 0.0, "head_shift": 0.0,
            "density": {w: {"L1": e[w], "L2": 2 * e[w], "max": 3 * e[w]} for w in ("particles", "nodes")},
            "energy": {"particles": {"L1": e["energy"], "L2": 2 * e["energy"], "max": 0.0}},
            "regions": {w: [s * e[w] for s in SHARES] for w in ("particles", "nodes")},
            "mean_error": {w: [0.0] * len(REGION_NAMES) for w in ("particles", "nodes")}, "extrema": extrema}


def extrema(crossing: float = 0.004, moving: float = 0.001, resting: float = 0.0) -> dict:
    """A counter's summary: new density and energy extrema per crossing, per moving and per resting
    non-crossing particle-step (1000 steps, 100 crossings and 3000 moving of 10000 non-crossing)."""
    steps, crossings, moving_steps, staying = 1000, 100, 3000, 10000
    fields = {}
    for name in ("density", "energy"):
        c, m = crossing * crossings, moving * moving_steps
        s = m + resting * (staying - moving_steps)
        fields[name] = {"new_at_crossing": c, "new_elsewhere": s, "new_moving": m, "new_per_step": (c + s) / steps,
                        "max_per_step": 3, "rate_crossing": crossing, "rate_elsewhere": s / staying,
                        "rate_moving": moving}
    return {"steps": steps, "crossings": crossings, "particle_steps": staying + crossings, "moving_speed": 0.0106,
            "moving_steps": moving_steps, **fields}


def made_up_tables(model=diverging, meshes=MESHES, seeds=study.SEEDS, counter=extrema) -> dict:
    """The Sod tables of made-up runs (module docstring), as :func:`load_tables` reads them."""
    regular = {(n, cfl, h): _run(model, n, cfl, h, 0, counter()) for n, cfl in study.SETTINGS for h in meshes}
    jittered = {(n, cfl, h, s): _run(model, n, cfl, h, s, None)
                for n, cfl in study.SETTINGS for h in meshes for s in seeds}
    fem = {h: {"ok": True, "density": {"nodes": {"L1": model("fem", 0, 0, h, None)}}, "head_shift": 0.0,
               "regions": {"nodes": [s * model("fem", 0, 0, h, None) for s in SHARES]}} for h in meshes}
    fv = {h: {"ok": True, "density": {"cells": {"L1": 0.5 * model("fem", 0, 0, h, None)}}} for h in meshes}
    seed_rows = builders.seed_rows(regular, jittered)
    tables = {SOD_SEEDS: seed_rows,
              SOD_CONVERGENCE: builders.convergence_rows(seed_rows, regular, fem, fem, fv, study.SOURCE),
              SOD_REGIONS: builders.region_rows(regular, fem, fem), SOD_EXTREMA: builders.extrema_rows(regular)}
    settings = {"fv": {"scheme": "FV MUSCL-HLLC (MC)", "limiter": "mc"}, "fem": {"viscosity": "viscosity everywhere"},
                "region_half_width": study.REGION_HALF_WIDTH, "T": study.T}
    with tempfile.TemporaryDirectory() as folder:
        (Path(folder) / "sod").mkdir()
        publish(Path(folder) / "sod", tables, settings)
        return load_tables(Path(folder))
