"""A harness for mutation tests of claim criteria: perturb a table, re-judge, compare verdicts.

Usage in a test module (``tests/`` is on the path when pytest runs)::

    from claim_mutations import TABLES, judge, mutate

    def test_c14_follows_its_numbers():
        fail = mutate(TABLES, "sod/extrema", density_moving_ratio=1.0)
        ok = mutate(TABLES, "sod/extrema", density_moving_ratio=30.0)
        assert_flips("C14", fail, ok)

``mutate`` returns a copy of the tables in which the rows of one table that match ``where`` get new
values: a constant, or a function of the row (``lambda r: float(r["x"]) * 2``). Values are written
as strings, as the CSVs hold them.
"""

from __future__ import annotations

import copy
from pathlib import Path

from mpm_fem.measure.claims import CLAIMS, select
from mpm_fem.measure.tables import load_tables

#: The committed tables of the full reproduction.
TABLES = load_tables(Path(__file__).resolve().parent.parent / "figures")


def claim_named(label: str):
    """The registered claim with this label (``"C5"``, ``"C3 (sod)"``)."""
    found = [c for c in CLAIMS if c.label == label]
    if not found:
        raise KeyError(f"no registered claim {label!r}")
    return found[0]


def judge(label: str, tables) -> tuple[str, str]:
    return claim_named(label).verdict(tables)


def mutate(tables, table: str, where: dict | None = None, **changes):
    """A copy of ``tables`` with ``changes`` applied to the rows of ``table`` matching ``where``."""
    out = copy.deepcopy(dict(tables))
    matching = select(out[table], **(where or {}))
    if not matching:
        raise ValueError(f"no row of {table!r} matches {where}")
    for row in matching:
        for key, value in changes.items():
            new = value(row) if callable(value) else value
            row[key] = new if isinstance(new, str) else repr(float(new)) if isinstance(new, float) else str(new)
    return out


def assert_flips(label: str, failing, passing, passing_verdict: str = "confirmed") -> None:
    """The claim's verdict on ``passing`` is ``passing_verdict`` and differs on ``failing``."""
    bad, good = judge(label, failing), judge(label, passing)
    assert good[0] == passing_verdict, (label, good)
    assert bad[0] not in (passing_verdict, "not measured"), (label, bad)
