"""The settings of the Sod study's tables, shared by its claims (:mod:`.sod`, :mod:`.sod_waves`,
:mod:`.sod_shared`, :mod:`.sod_fem`): a :class:`Setting` (particles per cell, CFL number), a verdict per
setting and the headline verdict on the settings the source prescribes (4-8 particles per cell: their
common verdict, ``partly`` when they differ), and how many runs and meshes a judged order needs.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from mpm_fem.measure.claims.base import PARTLY
from mpm_fem.measure.claims.rows import num, select
from mpm_fem.measure.claims.rules import rule
from mpm_fem.measure.schema import SOD_CONVERGENCE, SOD_SEEDS
from mpm_fem.measure.source import OPTIMAL_PPC

CONVERGENCE, SEEDS = SOD_CONVERGENCE.name, SOD_SEEDS.name
#: C11, E3: an order or a ratio is judged only over at least MIN_RUNS runs on each mesh (the regular
#: layout and five jittered ones), and C11 needs FLOOR_MESHES such meshes; its trend is read from the
#: orders between the last FLOOR_STEPS + 1 of them.
MIN_RUNS, FLOOR_MESHES, FLOOR_STEPS = (int(rule(k)) for k in ("MIN_RUNS", "FLOOR_MESHES", "FLOOR_STEPS"))


class Setting(NamedTuple):
    """A run setting of the Sod tables: particles per cell and CFL number (the key of a per-setting verdict)."""

    ppc: int
    cfl: float


def _settings(rows: list[dict]) -> list[Setting]:
    """The settings of ``rows``, in their order; FEM rows (no ``ppc``) left out."""
    found = dict.fromkeys(Setting(int(num(r, "ppc")), num(r, "cfl")) for r in rows if math.isfinite(num(r, "ppc")))
    return list(found)


def _label(n: int, cfl: float) -> str:
    return f"{n} ppc, CFL {cfl:g}"


def _prescribed(n: int) -> bool:
    return OPTIMAL_PPC[0] <= n <= OPTIMAL_PPC[1]


def headline(verdicts: dict[tuple, str]) -> str:
    """The verdict on the settings the source prescribes (:data:`OPTIMAL_PPC` particles per cell): their
    common verdict when they agree, ``partly`` when they differ, ``not measured`` when none is measured."""
    found = [v for (n, _), v in verdicts.items() if _prescribed(n)]
    measured = set(found) - {"not measured"}
    if not measured:
        return "not measured"
    return found[0] if len(set(found)) == 1 else PARTLY


def _per_setting(criterion, rows: list[dict], *more) -> tuple[dict, dict]:
    verdicts, lines = {}, {}
    for k in _settings(rows):
        verdicts[k], lines[k] = criterion(select(rows, ppc=k.ppc, cfl=k.cfl), k.ppc, k.cfl, *more)
    return verdicts, lines


def _settings_text(verdicts: dict, lines: dict) -> str:
    """One clause per setting, the prescribed ones first."""
    if not verdicts:
        return "no row with a setting (ppc, cfl)"
    order = sorted(verdicts, key=lambda k: (not _prescribed(k.ppc), -k.ppc, k.cfl))
    return "; ".join(f"{_label(*k)}: {verdicts[k]}, {lines[k]}" for k in order)

