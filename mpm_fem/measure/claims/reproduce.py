"""E4: one command regenerates every table from one code version, judged from the ``versions`` table
(:func:`mpm_fem.measure.tables.load_tables`) against the version of the code judging them
(:func:`mpm_fem.measure.version.code_version`), the tier of every table and the tables every
registered claim reads."""

from __future__ import annotations

from mpm_fem.measure import version
from mpm_fem.measure.claims.base import CLAIMS, CONFIRMED, PARTLY, REFUTED, Finding, Tables, claim, short
from mpm_fem.measure.schema import BUILT, VERSIONS


def lag_text(stamp: str, current: str) -> str:
    """The first clause of E4's evidence when the tables' code ``stamp`` is not the ``current`` code's."""
    return f"the figures lag the code: tables from code {stamp}, the current code is {current}"


def _most(values: list[str]) -> str:
    """The most frequent of ``values`` (the first met among equals)."""
    return max(dict.fromkeys(values), key=values.count)


@claim("E4", source="`mpm-fem reproduce` regenerates every table and this report", tables=(VERSIONS.name,),
       study="reproduce",
       thresholds="every table carries one code version, the version of the code that judges them (a hash of the "
                  "syntax trees, docstrings aside, of the code that computes numbers: mpm_fem, baselines and "
                  "studies but the report, its pages and the plots; mpm_fem/measure/version.py), every table one "
                  "tier (quick, full or deep; a table that records none counts as another), and every table a "
                  "claim reads exists -> confirmed; one version that is not the current code's (the figures lag "
                  "the code) or a table missing -> partly; tables from several code versions or of several tiers "
                  "(not the output of one command) -> refuted")
def _e4(t: Tables) -> Finding:
    """The stamp of each table is the version of all the code that wrote it (the case cache is keyed by
    the narrower version of the code a case runs through, :func:`mpm_fem.measure.version.case_version`);
    a change to a docstring, a comment, the report or the plots leaves it. The tier is read as
    :func:`mpm_fem.measure.tables.table_tier` does (tables written before the stamp by their settings)."""
    rows = t[VERSIONS.name]
    codes = [r["code"] for r in rows]
    main = _most(codes)
    current = version.code_version()
    other = [r["table"] for r in rows if r["code"] != main]
    tiers = [r.get("tier", "") or "unstamped" for r in rows]
    tier = _most(tiers)
    mixed = [f"{r['table']} ({found})" for r, found in zip(rows, tiers, strict=True) if found != tier]
    needed = {name for c in CLAIMS for name in c.tables if name not in BUILT}
    missing = sorted(needed - {r["table"] for r in rows})
    verdict = REFUTED if other or mixed else (PARTLY if missing or main != current else CONFIRMED)
    head = (f"{len(rows) - len(other)} of {len(rows)} tables from code {main}, the current code"
            if main == current else lag_text(main, current) + f" ({len(rows) - len(other)} of {len(rows)} tables)")
    head += f", {len(rows) - len(mixed)} of the {tier} tier"
    return Finding(verdict, (head + (f"; other versions: {', '.join(other)}" if other else "")
                             + (f"; other tiers: {', '.join(mixed)}" if mixed else "")
                             + (f"; missing: {', '.join(missing)}" if missing else "")),
                   key=short(head, lag_text(main, current)) if main != current else ())
