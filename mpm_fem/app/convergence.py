"""A convergence study from Python: meshes and seeds run, the errors and observed orders over seeds.

    runs    one row per run (mesh ``h``, ``seed``): its errors ``<where>_<norm>`` (``where``: particles,
            nodes or cells; ``norm``: L1, L2, max) and ``order_<where>_<norm>``, the observed order
            ``log(E(h_prev) / E(h)) / log(h_prev / h)`` against the same seed on the previous mesh
    rows    one row per mesh: for each quantity ``q`` (L1 and L2 of each ``where``) its value for seed 0
            (``q``, NaN when seed 0 was not run), its mean and range over the seeds (``q_mean``,
            ``q_lo``, ``q_hi``), and the observed order's (``order_q``, ``order_q_mean|lo|hi``;
            NaN on the coarsest mesh)
    orders  per quantity, the least-squares order over all meshes fitted for each seed, and their
            mean and range (``mean``, ``lo``, ``hi``, ``runs``)

The seeds follow the studies' convention: seed 0 is the settings' own layout (regular unless set),
seed ``k >= 1`` the jittered layout drawn with seed ``k`` (``seeded``). The statistics are those of
the studies' tables (:mod:`mpm_fem.measure.spread`, :mod:`mpm_fem.measure.seeds`). The runs go
through the studies' sweep (:func:`mpm_fem.app.sweep.run_cases`: worker processes, progress on
stderr, optionally cached); a run that fails (lost positivity) is a row with ``ok`` false and NaN errors.
"""

from __future__ import annotations

import importlib
import math
import time
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

from mpm_fem.measure.seeds import order_spread
from mpm_fem.measure.spread import by_mesh, order_spreads, spread

#: The solvers a convergence study runs, by problem.
SOLVERS = {"sod": ("mpm", "fem", "fv"), "burgers": ("mpm", "fem")}
#: The field whose error a study measures by default.
FIELDS = {"sod": "density", "burgers": "velocity"}
#: The norms of a row's quantities (each run records the maximum as well).
ROW_NORMS = ("L1", "L2")
NORMS = ("L1", "L2", "max")


def measured(case: dict) -> dict:
    """One run of a study, a sweep's case: ``problem``, ``solver``, ``field`` and ``settings`` (the
    keywords of the entry point or baseline). Returns ``ok``, the ``errors`` of ``field``
    (``{where: {norm: E}}``), ``steps`` and ``wall_s``; or ``ok`` false and the ``error``."""
    from mpm_fem.app import references
    from mpm_fem.app.presets import settings_type

    problem, solver, s = case["problem"], case["solver"], dict(case["settings"])
    try:
        start = time.perf_counter()
        if solver == "mpm":
            module = importlib.import_module(f"mpm_fem.problems.{problem}")
            settings = settings_type(problem)(**s)
            result = module.simulate(settings, progress=False)
            errors, steps = module.errors(settings, result), result.steps
        else:
            run = {("sod", "fem"): references.sod_fem, ("sod", "fv"): references.sod_fv,
                   ("burgers", "fem"): references.burgers_fem}[(problem, solver)]
            ref = run(**s)
            errors, steps = ref.errors, ref.steps
        wall = time.perf_counter() - start
    except (ArithmeticError, RuntimeError) as err:  # lost positivity, a non-finite state
        return {"ok": False, "error": str(err)}
    return {"ok": True, "errors": errors[case["field"]], "steps": steps, "wall_s": round(wall, 3)}


@dataclass(frozen=True, repr=False)
class Convergence:
    """The runs of a convergence study and their statistics (module docstring).

    Attributes
    ----------
    problem, solver, field : str
        What ran (``"sod"``, ``"mpm"``, ``"density"``, ...).
    settings : Mapping
        The settings shared by every run (read-only; ``h``, and for MPM ``layout`` and ``seed``, vary).
    hs, seeds : tuple
        The meshes (coarsest first) and the seeds.
    runs, rows : tuple of dict
        One row per run, one row per mesh.
    orders : Mapping
        ``{quantity: {"mean", "lo", "hi", "runs"}}``: the least-squares order over the meshes.
    """

    problem: str
    solver: str
    field: str
    settings: Mapping
    hs: tuple
    seeds: tuple
    runs: tuple
    rows: tuple
    orders: Mapping

    @property
    def quantities(self) -> tuple[str, ...]:
        """The quantities of :attr:`rows` and :attr:`orders`, e.g. ``("particles_L1", ...)``."""
        return tuple(self.orders)

    def __repr__(self) -> str:
        failed = sum(not r["ok"] for r in self.runs)
        q = self.quantities[0] if self.quantities else None
        fitted = (f"; fitted order of {q} {_text(self.orders[q])}" if q else "")
        return (f"Convergence({self.problem} {self.solver}, {self.field}: {len(self.hs)} meshes "
                f"{self.hs[0]:g} to {self.hs[-1]:g} x {_count(len(self.seeds), 'seed')} = {len(self.runs)} runs"
                f"{f', {failed} failed' if failed else ''}{fitted})")

    def table(self, quantity: str | None = None, digits: int = 3) -> str:
        """A text table of one quantity (default: the first) by mesh: seed 0's value and the mean
        and range over the seeds, then the same of the observed order against the previous mesh,
        and the fitted order below."""
        q = quantity or self.quantities[0]
        if q not in self.orders:
            raise ValueError(f"unknown quantity {q!r}; choose one of {', '.join(self.quantities)}")
        lines = [f"{'h':<10}{q + ' (seed 0)':>20}  {'mean [lo, hi]':<28}{'order (seed 0)':>15}  mean [lo, hi]"]
        for row in self.rows:
            values = [_number(row[q], digits), _text(_stats(row, q), digits), _number(row[f"order_{q}"], 2),
                      _text(_stats(row, f"order_{q}"), 2)]
            lines.append(f"{row['h']:<10g}{values[0]:>20}  {values[1]:<28}{values[2]:>15}  {values[3]}".rstrip())
        n = self.orders[q]["runs"]
        lines.append(f"fitted order over {len(self.hs)} meshes: {_text(self.orders[q], 2)} ({_count(n, 'seed')})")
        return "\n".join(lines)


def _count(n: int, what: str) -> str:
    return f"{n} {what}{'' if n == 1 else 's'}"


def _stats(row: dict, key: str) -> dict:
    return {k: row[f"{key}_{k}"] for k in ("mean", "lo", "hi")}


def _number(value: float, digits: int) -> str:
    return "-" if not math.isfinite(value) else f"{value:.{digits}g}" if digits > 2 else f"{value:.{digits}f}"


def _text(s: Mapping, digits: int = 2) -> str:
    """``mean [lo, hi]``, ``-`` when there is none."""
    if not math.isfinite(s["mean"]):
        return "-"
    return f"{_number(s['mean'], digits)} [{_number(s['lo'], digits)}, {_number(s['hi'], digits)}]"


def run_rows(cases: list[dict], results: list[dict]) -> list[dict]:
    """One row per run: mesh, seed, layout, each error and the observed order against the same seed
    on the previous (coarser) mesh."""
    rows = []
    for case, r in zip(cases, results, strict=True):
        s = case["settings"]
        row = {"h": s["h"], "seed": s.get("seed", 0), "layout": s.get("layout", ""), "ok": bool(r["ok"])}
        errors = r.get("errors", {})
        row.update({f"{w}_{n}": float(e[n]) for w, e in errors.items() for n in NORMS})
        row.update({"steps": r.get("steps"), "wall_s": r.get("wall_s"), "error": r.get("error", "")})
        rows.append(row)
    rows.sort(key=lambda r: (-r["h"], r["seed"]))
    keys = list(dict.fromkeys(f"{w}_{n}" for r in results if r["ok"] for w in r["errors"] for n in NORMS))
    for r in rows:
        for k in keys:
            r.setdefault(k, math.nan)
    previous: dict = {}
    for r in rows:
        before = previous.get(r["seed"])
        for k in keys:
            order = math.nan
            if before is not None and r[k] > 0 and before[k] > 0:
                order = math.log(before[k] / r[k]) / math.log(before["h"] / r["h"])
            r[f"order_{k}"] = order
        previous[r["seed"]] = r
    return rows


def mesh_rows(runs: list[dict], quantities: list[str]) -> list[dict]:
    """One row per mesh (coarsest first): each quantity's seed-0 value, mean and range over the seeds,
    and the same of its observed order (:func:`mpm_fem.measure.spread.order_spreads`)."""
    hs = sorted({r["h"] for r in runs}, reverse=True)
    rows = [{"h": h, "runs": sum(r["ok"] for r in runs if r["h"] == h)} for h in hs]
    for q in quantities:
        values = by_mesh(runs, q)
        orders = {b: s for _, b, s in order_spreads(runs, q)}
        for row in rows:
            h = row["h"]
            level, order = spread(values[h].values()), orders.get(h)
            regular = [r for r in runs if r["h"] == h and r["seed"] == 0]
            row[q] = regular[0][q] if regular else math.nan
            row.update({f"{q}_{k}": getattr(level, k) for k in ("mean", "lo", "hi")})
            row[f"order_{q}"] = regular[0][f"order_{q}"] if regular else math.nan
            row.update({f"order_{q}_{k}": getattr(order, k) if order else math.nan for k in ("mean", "lo", "hi")})
    return rows


def fitted_orders(runs: list[dict], quantities: list[str]) -> dict:
    """Per quantity, the least-squares order of each seed over the meshes, its mean and range
    (:func:`mpm_fem.measure.seeds.order_spread`)."""
    out = {}
    for q in quantities:
        series: dict = {}
        for r in runs:
            series.setdefault(r["seed"], {})[r["h"]] = r[q]
        s = order_spread(series)
        out[q] = MappingProxyType({"mean": s["mean"], "lo": s["lo"], "hi": s["hi"], "runs": len(s["fitted"])})
    return out


def summarise(problem: str, solver: str, field: str, settings: Mapping, cases: list[dict],
              results: list[dict]) -> Convergence:
    """The :class:`Convergence` of ``cases`` and their ``results``."""
    runs = run_rows(cases, results)
    wheres = list(dict.fromkeys(k.rsplit("_", 1)[0] for r in runs for k in r if k.endswith("_L1")
                                and not k.startswith("order_")))
    quantities = [f"{w}_{n}" for w in wheres for n in ROW_NORMS]
    hs = tuple(sorted({r["h"] for r in runs}, reverse=True))
    seeds = tuple(sorted({r["seed"] for r in runs}))
    return Convergence(problem, solver, field, MappingProxyType(dict(settings)), hs, seeds,
                       tuple(MappingProxyType(r) for r in runs),
                       tuple(MappingProxyType(r) for r in mesh_rows(runs, quantities)),
                       MappingProxyType(fitted_orders(runs, quantities)))
