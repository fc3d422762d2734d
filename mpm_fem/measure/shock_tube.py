"""Measurements of a computed Sod solution, the same for MPM, fixed-mesh FEM and finite volumes.

The density error ``e = rho - rho_exact(x, t)`` against the exact Riemann solution at the points of
each method (particles with weights ``V_p``, grid nodes with ``int S_i dx``, cells with ``h``), its
norms (:mod:`mpm_fem.measure.errors`), its L1 and signed mean by region of the exact solution (C12,
:mod:`mpm_fem.measure.regions`), and the position error of the rarefaction head. At the particles
also the specific internal energy error ``e_p - p(x_p)/((gamma - 1) rho(x_p))`` (weights ``V_p``).
Every result is a JSON-able dict, as a sweep stores it.
"""

from __future__ import annotations

import numpy as np

from baselines.exact import riemann
from mpm_fem.measure.errors import norms
from mpm_fem.measure.regions import by_region, head_shift, sod_regions
from mpm_fem.problems.sod import SodSettings, conservation


def exact_density(x, t: float = SodSettings.T):
    """The exact density of Sod's tube at ``x`` and time ``t``."""
    return riemann.sample(x, t, SodSettings.left, SodSettings.right, x0=0.5, gamma=1.4)[0]


def exact_energy(x, t: float = SodSettings.T, gamma: float = 1.4):
    """The exact specific internal energy ``p / ((gamma - 1) rho)`` of Sod's tube at ``x`` and ``t``."""
    rho, _, p = riemann.sample(x, t, SodSettings.left, SodSettings.right, x0=0.5, gamma=gamma)
    return p / ((gamma - 1.0) * rho)


def measure(x, rho, weights, t: float, half_width: float) -> tuple[np.ndarray, dict]:
    """The density error at ``x`` and its ``{"L1", "mean"}`` by region of half-width ``half_width``."""
    e = rho - exact_density(x, t)
    regions = sod_regions(riemann.wave_positions(t, SodSettings.left, SodSettings.right), half_width)
    return e, by_region(x, e, weights, regions)


def _profile(values: dict) -> dict:
    return {k: [float(f"{v:.7g}") for v in np.asarray(a)] for k, a in values.items()}


def mpm(settings: SodSettings, result, errors: dict, extrema: dict, half_width: float, profiles: bool) -> dict:
    """An MPM run measured: norms over particles and nodes (``errors``, from the problem), the norms
    of the particles' internal energy error (``energy``), the error by region at both, the new
    extrema counted during the run (``extrema``: ``None`` when not counted), the particles' volume gain, the
    relative drift of the total energy (:func:`mpm_fem.problems.sod.conservation`), the head shift at
    the nodes and, when asked for, the profiles."""
    P, g, t = result.particles, result.grid, result.t
    split = {"particles": measure(P.x, P.density, P.volume, t, half_width)[1],
             "nodes": measure(g.nodes, result.nodal_density, g.lumped_mass, t, half_width)[1]}
    out = {"ok": True, "steps": result.steps, "wall_s": result.wall_s, "particles": int(P.n),
           **{k: errors[k] for k in ("density", "velocity", "pressure")},
           "energy": {"particles": norms(P.energy - exact_energy(P.x, t, settings.gamma), P.volume)},
           "regions": {k: s["L1"] for k, s in split.items()}, "mean_error": {k: s["mean"] for k, s in split.items()},
           "extrema": extrema, "volume_drift": float(P.volume.sum() - 1.0),
           "energy_drift": conservation(settings, result)["relative_change"]["energy"],
           "head_shift": head_shift(g.nodes, result.nodal_density, lambda x: exact_density(x, t))}
    if profiles:
        out["profile"] = _profile(dict(x=P.x, density=P.density, velocity=P.velocity, energy=P.energy,
                                       pressure=(settings.gamma - 1.0) * P.density * P.energy, nodes=g.nodes,
                                       nodal_density=result.nodal_density, nodal_velocity=result.nodal_velocity))
    return out


def fem(r, weights, half_width: float, profiles: bool) -> dict:
    """A fixed-mesh FEM run (:func:`baselines.fem_euler.solve`) measured at its nodes."""
    e, split = measure(r.nodes, r.rho, weights, r.t, half_width)
    out = {"ok": True, "steps": r.steps, "density": {"nodes": norms(e, weights)}, "regions": {"nodes": split["L1"]},
           "mean_error": {"nodes": split["mean"]}, "mass": float(np.sum(weights * r.rho)),
           "head_shift": head_shift(r.nodes, r.rho, lambda x: exact_density(x, r.t)), "settings": r.settings}
    if profiles:
        out["profile"] = _profile(dict(x=r.nodes, density=r.rho, velocity=r.u, pressure=r.p, energy=r.e))
    return out


def fv(r, h: float) -> dict:
    """A finite-volume run (:func:`baselines.fv_euler.solve`): cell averages against the exact density
    at the cell centres, weights ``h``."""
    e = r.rho - exact_density(r.centres, r.t)
    return {"ok": True, "steps": r.steps, "density": {"cells": norms(e, np.full(e.size, h))},
            "mass": float(np.sum(r.rho) * h)}
