"""Case functions for sweeps: one MPM run from a JSON-able settings dict to a JSON-able result.

They live in the package (not in a script) so that worker processes, local or on a Dask cluster,
import them by name.
"""

from __future__ import annotations


def sod_case(case: dict) -> dict:
    """``{settings of SodSettings}`` -> errors, steps and particle count of one Sod run."""
    from mpm_fem.problems import sod

    settings = sod.SodSettings(**{k: tuple(v) if isinstance(v, list) else v for k, v in case.items()})
    result = sod.simulate(settings, progress=False)
    return {"errors": sod.errors(settings, result), "steps": result.steps, "particles": int(result.particles.n)}


def burgers_case(case: dict) -> dict:
    """``{settings of BurgersSettings}`` -> errors, steps and particle count of one Burgers run."""
    from mpm_fem.problems import burgers

    settings = burgers.BurgersSettings(**case)
    result = burgers.simulate(settings, progress=False)
    return {"errors": burgers.errors(settings, result), "steps": result.steps, "particles": int(result.particles.n)}
