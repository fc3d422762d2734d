"""The source's unstated settings, identified from its own tables (issue 42, part A).

The identification study (``studies/identification.py``) runs, for each of the source's tables, the
candidates for what the slides leave unsaid (Sod: particles per cell, CFL, nodal or particle density,
L1 or L2; Burgers: the exact solution, the time-step rule and its CFL, particles per cell) and writes
one row per candidate and source row to ``identification/sod`` and ``identification/burgers`` with its
misfit to the corrected source table (the mean ``|log(measured / source)|`` over the meshes, and for
Burgers over the five eps), its ``rank`` and whether it is ``matching`` (within the rule book's
identification band of the best misfit).

The criteria read the result through :func:`source_matching`.
"""

from __future__ import annotations

from mpm_fem.measure.claims.base import Tables

#: The identification tables, by problem.
IDENTIFICATION = {"sod": "identification/sod", "burgers": "identification/burgers"}


def source_matching(tables: Tables, problem: str, row: str | None = None) -> list[dict]:
    """The source-matching candidates of ``problem`` (``"sod"`` or ``"burgers"``): the rows of its
    identification table marked ``matching``, best ``rank`` first, for the source row ``row`` (e.g.
    ``"L1"`` for Sod, ``"calculated"`` for Burgers' calculated-acceleration row) or every row when
    ``None``. Empty when the table is missing: the criteria then say they judged at the study's
    settings."""
    if problem not in IDENTIFICATION:
        raise ValueError(f"problem {problem!r} is not one of {tuple(IDENTIFICATION)}")
    rows = [r for r in tables.get(IDENTIFICATION[problem], []) if str(r.get("matching", "")) == "True"
            and (row is None or r.get("source_row", "") == row)]
    return sorted(rows, key=lambda r: float(r.get("rank", "inf") or "inf"))
