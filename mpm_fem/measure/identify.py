"""The identification's searches: the source's unstated settings fitted to its own tables.

Pure procedures over a measuring callback (the study supplies it; every run is a cached case), with the
searches of :mod:`mpm_fem.measure.search` and the misfits of :mod:`mpm_fem.measure.claims.identification`.

**Sod** (:func:`fit_sod`): a candidate is (particles per cell, read-out: nodal or particle density),
its CFL fitted by :func:`~mpm_fem.measure.search.bracketed` in ``ln CFL`` to the misfit of its L1 error to
the source's L1 column on every mesh of the fit; the L2 column is held out (the same setting's L2 error
against it).

**Burgers** (:func:`fit_burgers`): a candidate is the whole table: one exact solution with its parameters
(the study's ``PARAMETERS``), particles per cell, read-out and norm, the exact row run
with the exact acceleration and ``dt = CFL_e h/max|v|`` and the calculated row with the calculated
acceleration and the stable ``dt = CFL_c min(h/max|v|, h^2/(2 eps))`` (the explicit viscous force needs the
viscous limit). Its score is the mean of the two rows' :func:`row_misfit` over the fitted eps; the other eps
are held out. The search per solution (:func:`fit_family`): ``CFL_c`` bracketed on :attr:`BurgersSearch.stable_grid`
and ``CFL_e`` on ``advective_grid`` (both reaching CFL <= 0.03), then a coordinate search
(:func:`~mpm_fem.measure.search.coordinate_fit`) over the solution's parameters and ``CFL_e`` (inside a
factor :attr:`BurgersSearch.local` of its bracketed value) until a pass gains less than ``ftol``, the
calculated row held; then ``CFL_c`` refined on the whole table at the fitted parameters.
The read-out and the norm are the best at each point (one run gives them all). The per-eps diagnostic
(:func:`per_eps`): per eps, the exact row alone, its constant fitted again at the table fit's
parameters; the calculated row at the table fit's settings; the read-out and norm the best of that row.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace

from mpm_fem.measure.misfit import misfit, row_misfit
from mpm_fem.measure.search import Coordinate, bracketed, coordinate_fit, fit_scalar

READOUTS = ("particles", "nodes")
NORMS = ("max", "L1", "L2")
#: The source rows of Burgers, and the time-step rule each runs with.
DT_RULES = {"exact": "advective", "calculated": "stable"}


def value(run: Mapping | None, readout: str, norm: str) -> float | None:
    """A run's error by read-out and norm (``None`` for a failed or missing run)."""
    return run[readout][norm] if run and run.get("ok") else None


# ----------------------------------------------------------------------------- Sod

@dataclass(frozen=True)
class SodSearch:
    """The Sod search: particles per cell ``ppc``, the fitted ``meshes``, the bracketing ``grid`` of CFL
    numbers and the tolerance ``xtol`` in ``ln CFL``."""

    ppc: tuple[int, ...]
    meshes: tuple[float, ...]
    grid: tuple[float, ...]
    xtol: float


def sod_misfit(runs: Mapping[float, Mapping | None], source: Mapping[float, tuple], readout: str, column: int) -> float:
    """The misfit of the density error (``readout``, L1 for ``column`` 0, L2 for 1) over the meshes of ``runs``."""
    norm = ("L1", "L2")[column]
    hs = list(runs)
    return misfit([_density(runs[h], readout, norm) for h in hs], [source[h][column] for h in hs])


def _density(run, readout, norm):
    return run["density"][readout][norm] if run and run.get("ok") else None


def fit_sod(measure: Callable[[int, float], Mapping], source: Mapping[float, tuple], search: SodSearch) -> list[dict]:
    """One result per candidate ``(ppc, readout)``: ``{ppc, readout, cfl, misfit, misfit_held_out,
    evaluations}``; ``measure(ppc, cfl)`` gives ``{h: run}`` on ``search.meshes``."""
    out = []
    for n in search.ppc:
        for readout in READOUTS:
            fit = bracketed(lambda c, n=n, r=readout: sod_misfit(measure(n, c), source, r, 0), search.grid,
                            search.xtol, log=True)
            held = sod_misfit(measure(n, fit.x), source, readout, 1)
            out.append({"ppc": n, "readout": readout, "cfl": fit.x, "misfit": fit.value, "misfit_held_out": held,
                        "evaluations": fit.evaluations})
    return out


# ----------------------------------------------------------------------------- Burgers

#: ``measure(row, solution, params, ppc, cfl, eps_list) -> {(eps, h): run}`` on the search's meshes.
Measure = Callable[[str, str, Mapping[str, float], int, float, Sequence[float]], Mapping]


@dataclass(frozen=True)
class BurgersSearch:
    """The Burgers search: the ``solutions`` and the ``parameters`` fitted for each (``{solution: {name:
    (default, Coordinate)}}``), particles per cell, the fitted eps and the held-out ones, the
    bracketing grids of the two time-step constants, their tolerance ``cfl_xtol`` in ``ln CFL``, the
    coordinate search's ``local`` factor, ``ftol`` and ``passes``."""

    solutions: tuple[str, ...]
    parameters: Mapping[str, Mapping[str, tuple[float, Coordinate]]]
    ppc: tuple[int, ...]
    fit_eps: tuple[float, ...]
    held_eps: tuple[float, ...]
    advective_grid: tuple[float, ...]
    stable_grid: tuple[float, ...]
    cfl_xtol: float
    ftol: float
    passes: int = 3
    local: float = 3.0

    def halved(self) -> BurgersSearch:
        """Every tolerance halved (the refinement test)."""
        params = {s: {k: (d, replace(c, xtol=c.xtol / 2)) for k, (d, c) in p.items()}
                  for s, p in self.parameters.items()}
        return replace(self, parameters=params, cfl_xtol=self.cfl_xtol / 2, ftol=self.ftol / 2)


@dataclass(frozen=True)
class FamilyFit:
    """A solution's fitted table: ``params``, the constants ``cfl`` (``{row: CFL}``), particles per cell,
    the best ``readout`` and ``norm``, the table misfit ``value`` on the fitted eps, the evaluations."""

    solution: str
    ppc: int
    params: dict
    cfl: dict
    readout: str
    norm: str
    value: float
    evaluations: int
    rows: dict = field(default_factory=dict)


class BurgersTable:
    """Scores of the Burgers table for one solution and particles per cell: ``errors(row, x, eps)`` the
    measured entries of every read-out and norm at the point ``x`` (``{"cfl_exact", "cfl_calculated",
    parameters}``), ``source`` the source's entries ``{row: {(eps, h): value}}``."""

    def __init__(self, measure: Measure, solution: str, ppc: int, names: Sequence[str], source: Mapping,
                 spread_weight: float):
        self.measure, self.solution, self.ppc, self.names, self.source = measure, solution, ppc, tuple(names), source
        self.spread_weight = spread_weight

    def runs(self, row: str, x: Mapping[str, float], eps: Sequence[float]) -> Mapping:
        params = {k: x[k] for k in self.names}
        return self.measure(row, self.solution, params, self.ppc, x[f"cfl_{row}"], tuple(eps))

    def row(self, row: str, x: Mapping[str, float], eps: Sequence[float], readout: str, norm: str) -> float:
        """:func:`row_misfit` of ``row`` at ``x`` over ``eps`` (the source's entries of those eps)."""
        runs = self.runs(row, x, eps)
        source = {k: v for k, v in self.source[row].items() if k[0] in eps}
        return row_misfit({k: value(runs.get(k), readout, norm) for k in source}, source, self.spread_weight)

    def table(self, x, eps, readout, norm) -> float:
        return sum(self.row(r, x, eps, readout, norm) for r in DT_RULES) / len(DT_RULES)

    def best(self, x, eps, rows=tuple(DT_RULES)) -> tuple[float, str, str]:
        """The least mean misfit of ``rows`` at ``x`` over the read-outs and norms, and where."""
        return min((sum(self.row(r, x, eps, q, n) for r in rows) / len(rows), q, n) for q in READOUTS for n in NORMS)


def _local(x: float, grid: Sequence[float], factor: float, xtol: float) -> Coordinate:
    return Coordinate(max(min(grid), x / factor), min(max(grid), x * factor), xtol, log=True)


def fit_family(scores: BurgersTable, search: BurgersSearch, start: Mapping[str, float] | None = None) -> FamilyFit:
    """The whole-table fit of one solution, from ``start`` (default: the solution's default parameters,
    both constants bracketed first). Stages, so that the costly runs are few: ``CFL_c`` bracketed at the
    default parameters (``start``: held), then the parameters and ``CFL_e`` fitted to the table with the
    calculated row's misfits held at that point (the exact row's runs are cheap: its error is the time
    error of dt ~ h), then ``CFL_c`` refined on the whole table at the fitted parameters (the calculated
    row's stable step costs ~ h^-3). The read-out and norm are the whole table's best at every point."""
    params = search.parameters.get(scores.solution, {})
    eps = search.fit_eps
    x = dict(start) if start is not None else {"cfl_exact": 0.5, "cfl_calculated": 0.5,
                                                **{k: d for k, (d, _) in params.items()}}
    table = lambda c: scores.best({**x, "cfl_calculated": c}, eps)[0]  # noqa: E731
    evaluations = 0
    if start is None:
        fit = bracketed(table, search.stable_grid, search.cfl_xtol, log=True)
        x, evaluations = {**x, "cfl_calculated": fit.x}, fit.evaluations
    held = {(q, n): scores.row("calculated", x, eps, q, n) for q in READOUTS for n in NORMS}
    exact = lambda y: min((scores.row("exact", y, eps, q, n) + held[(q, n)]) / 2  # noqa: E731
                          for q in READOUTS for n in NORMS)
    if start is None:
        fit = bracketed(lambda c: exact({**x, "cfl_exact": c}), search.advective_grid, search.cfl_xtol, log=True)
        x, evaluations = {**x, "cfl_exact": fit.x}, evaluations + fit.evaluations
    coordinates = {**{k: c for k, (_, c) in params.items()},
                   "cfl_exact": _local(x["cfl_exact"], search.advective_grid, search.local, search.cfl_xtol)}
    fit = coordinate_fit(exact, x, coordinates, search.ftol, search.passes)
    x, evaluations = {**x, **fit.x}, evaluations + fit.evaluations
    c = _local(x["cfl_calculated"], search.stable_grid, search.local, search.cfl_xtol)
    fit = fit_scalar(lambda v: scores.best({**x, "cfl_calculated": v}, eps)[0], c.lo, c.hi, c.xtol, log=True)
    x, evaluations = {**x, "cfl_calculated": fit.x}, evaluations + fit.evaluations
    value_, readout, norm = scores.best(x, eps)
    return FamilyFit(scores.solution, scores.ppc, {k: x[k] for k in params},
                     {r: x[f"cfl_{r}"] for r in DT_RULES}, readout, norm, value_, evaluations)


def candidate_results(scores: BurgersTable, fit: FamilyFit, search: BurgersSearch) -> list[dict]:
    """Per read-out and norm, at the family's fitted point: each row's misfit on the fitted eps, on the
    held-out eps, and the table misfit (the mean of the rows' fitted misfits)."""
    x = {**fit.params, **{f"cfl_{r}": c for r, c in fit.cfl.items()}}
    out = []
    for readout in READOUTS:
        for norm in NORMS:
            rows = {r: (scores.row(r, x, search.fit_eps, readout, norm),
                        scores.row(r, x, search.held_eps, readout, norm) if search.held_eps else math.nan)
                    for r in DT_RULES}
            table = sum(m for m, _ in rows.values()) / len(rows)
            out += [{"readout": readout, "norm": norm, "source_row": r, "misfit": m, "misfit_held_out": h,
                     "table_misfit": table} for r, (m, h) in rows.items()]
    return out


def per_eps(scores: BurgersTable, fit: FamilyFit, search: BurgersSearch, eps: float) -> list[dict]:
    """The per-eps diagnostic of one solution at one ``eps``: the exact row alone, its constant fitted
    again (bracketed, then Brent) at the table fit's parameters; the calculated row at the table fit's
    point. Each: the best read-out and norm for that row alone, the point, the misfit over the meshes."""
    params = search.parameters.get(scores.solution, {})
    f = lambda x: scores.best(x, (eps,), ("exact",))[0]  # noqa: E731
    x = {**fit.params, **{f"cfl_{r}": c for r, c in fit.cfl.items()}}
    cfl = bracketed(lambda c: f({**x, "cfl_exact": c}), search.advective_grid, search.cfl_xtol, log=True)
    out = []
    for row, point in (("exact", {**x, "cfl_exact": cfl.x}), ("calculated", x)):
        m, readout, norm = scores.best(point, (eps,), (row,))
        out.append({"source_row": row, "eps": eps, "readout": readout, "norm": norm, "misfit": m,
                    "params": {k: point[k] for k in params}, "cfl": point[f"cfl_{row}"],
                    "evaluations": cfl.evaluations if row == "exact" else 0})
    return out
