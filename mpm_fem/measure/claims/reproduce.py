"""E4: one command regenerates every table from one code version, judged from the ``versions`` table
(:func:`mpm_fem.measure.tables.load_tables`) against the tables every registered claim reads."""

from __future__ import annotations

from mpm_fem.measure.claims.base import CLAIMS, Tables, claim
from mpm_fem.measure.schema import BUILT, VERSIONS


@claim("E4", source="`mpm-fem reproduce` regenerates every table and this report", tables=(VERSIONS.name,),
       study="reproduce",
       thresholds="every table carries the code version named in the header, and every table a claim reads "
                  "exists -> confirmed; a table from another code version -> refuted; a table missing -> partly")
def _e4(t: Tables) -> tuple[str, str]:
    rows = t[VERSIONS.name]
    codes = [r["code"] for r in rows]
    main = max(set(codes), key=codes.count)
    other = [r["table"] for r in rows if r["code"] != main]
    needed = {name for c in CLAIMS for name in c.tables if name not in BUILT}
    missing = sorted(needed - {r["table"] for r in rows})
    verdict = "refuted" if other else ("partly" if missing else "confirmed")
    return verdict, (f"{len(rows) - len(other)} of {len(rows)} tables from code {main}"
                     + (f"; other versions: {', '.join(other)}" if other else "")
                     + (f"; missing: {', '.join(missing)}" if missing else ""))

