"""Made-up ``mechanism/growth`` and ``mechanism/summary`` tables, built by the study's and the claim's own
builders from errors with chosen orders: each run's error falls (or grows) between successive meshes at the
order a test sets, ``e(h_f) = e(h_c) (h_f / h_c)^p``."""

from __future__ import annotations

from mpm_fem.measure.claims.mechanism import summary_rows
from mpm_fem.measure.schema import MECHANISM_GROWTH, MECHANISM_SUMMARY
from studies import mechanism as study

MESHES = (0.01, 0.005, 0.0025, 0.00125)
RUNS = study.LAYOUTS  # the regular layout and seeds 1-5
#: all MPM converges on the coarse pair and grows on the two finer ones; only the projection made exact
#: converges where it grows
GROWS = {"none": (0.8, -0.3, -0.4), "projection": (0.9, 0.9, 0.8), "mass": (0.8, -0.2, -0.4),
         "interpolation": (0.8, 0.1, -0.1), "time": (0.8, -0.3, -0.4)}


def got(orders=GROWS, ppcs=(4,), problem="sod", meshes=MESHES, runs=RUNS) -> dict:
    """Results as :func:`studies.mechanism.growth_rows` reads them, ``{(problem, ppc, layout, seed, h,
    case): {"errors": {made_exact: v}}}``, with ``orders[made_exact]`` the orders between successive meshes
    (a function of the run's seed where a test makes one run differ)."""
    out = {}
    for ppc in ppcs:
        for layout, seed in runs:
            for made_exact, p in orders.items():
                p = p(seed) if callable(p) else p
                e = 0.01
                for k, h in enumerate(meshes):
                    if k:
                        e *= (h / meshes[k - 1]) ** p[k - 1]
                    out[(problem, ppc, layout, seed, h, made_exact)] = {"errors": {made_exact: e}}
    return out


def tables(orders=GROWS, problems=("sod",), **kwargs) -> dict:
    """``{"mechanism/growth": rows, "mechanism/summary": rows}`` of ``problems`` as :func:`load_tables` reads
    them (strings)."""
    growth = [r for p in problems for r in study.growth_rows(got(orders, problem=p, **kwargs))]
    as_read = lambda rows: [{k: str(v) for k, v in r.items()} for r in rows]  # noqa: E731
    return {MECHANISM_GROWTH.name: as_read(growth), MECHANISM_SUMMARY.name: as_read(summary_rows(growth))}
