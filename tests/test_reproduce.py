"""``mpm-fem reproduce --quick`` regenerates the committed numbers of its subset.

The committed ``figures/`` hold the output of ``mpm-fem reproduce --full``. The quick run shares a
subset of its cases; every row of a quick table that has a partner in the committed table (same
key columns) must carry the same numbers to the 6 significant digits the CSV files store
(relative tolerance 1e-5). The runs are deterministic, so anything else is a change of result that
was not committed.
"""

import os
from pathlib import Path

import numpy as np
import pytest

from mpm_fem.app.report import reproduce
from mpm_fem.app.study import NOT_JUDGED, StudyOptions, read_table
from mpm_fem.measure.claims import CLAIMS, STATEMENTS
from mpm_fem.measure.tables import load_tables

FIGURES = Path(__file__).resolve().parent.parent / "figures"
TABLES = {
    "sod/convergence.csv": (("ppc", "cfl", "h"),
                            ("mpm_nodes_L1", "mpm_particles_L1", "fem_lumped_L1", "fem_consistent_L1", "fv_L1")),
    "sod/seeds.csv": (("ppc", "cfl", "h", "layout", "seed"), ("particles_L1", "nodes_L1", "energy_L1")),
    "burgers/errors.csv": (("solution", "method", "eps", "h"), ("particles_L1", "particles_max", "nodes_L1")),
    "projection/errors.csv": (("quantity", "layout", "weights", "basis", "N_p", "h", "norm", "seeds"), ("value",)),
}
RTOL = 1e-5
#: the value of a key column in a table written before the column was (the study's own particle setting)
MISSING = {"layout": lambda row: "regular", "seed": lambda row: "0",
           "ppc": lambda row: "16" if row["problem"] == "sod" else "4"}


def _key(row: dict, keys: tuple) -> tuple:
    return tuple(row[k] if k in row else MISSING[k](row) for k in keys)


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    """The quick reproduction from a folder without ``figures/`` (as after deleting it)."""
    out, elsewhere = tmp_path_factory.mktemp("quick"), tmp_path_factory.mktemp("no-figures")
    here = os.getcwd()
    os.chdir(elsewhere)
    try:
        reproduce(StudyOptions(quick=True, out=out, jobs=2, progress=False))
    finally:
        os.chdir(here)
    return out


def test_quick_judges_the_headline_claims_and_lists_what_it_does_not_judge(quick):
    """C11 and C13 are judged from the quick tier's own runs; every verdict it does not judge is one the
    report lists with the tier that judges it (mpm_fem.app.study.NOT_JUDGED)."""
    tables = load_tables(quick)
    verdicts = {c.label: c.verdict(tables)[0] for c in CLAIMS}
    assert verdicts["C11"] != "not measured" and verdicts["C13"] != "not measured"
    assert {label for label, v in verdicts.items() if v == "not measured"} == set(NOT_JUDGED["quick"])
    text = (quick / "REPORT.md").read_text()
    assert all(f"{c} (the {tier} tier does: " in text for c, (tier, _) in NOT_JUDGED["quick"].items())
    assert {r["tier"] for r in tables["versions"]} == {"quick"}


def test_quick_report_covers_every_claim_and_says_it_is_quick(quick):
    text = (quick / "REPORT.md").read_text()
    assert "reproduce --quick" in text
    for claim in STATEMENTS:  # a claim measured per problem is listed as "[C3 (sod)]"
        assert (f"| {claim} |" in text or f"| [{claim}]" in text or f"| [{claim} (" in text
                or f"**{claim}" in text or f"{claim} (the " in text or f"{claim} (" in text), claim  # D: its section


def test_quick_report_has_no_nan_and_its_first_screen_answers_the_headline_question(quick):
    """No ``nan`` in the quick report or its appendix; its first 40 lines (title and introduction aside) say which
    stage's exact form stops the growth, with its orders, and how MPM compares with the FEM on the same meshes."""
    import re

    for name in ("REPORT.md", "APPENDIX.md"):
        text = (quick / name).read_text()
        hits = re.findall(r".{30}(?<![\w.])nan(?![\w.]).{0,30}", text, re.IGNORECASE)
        assert not hits, (name, hits)
    first = "\n".join((quick / "REPORT.md").read_text().splitlines()[:40]).split("## 1 Introduction")[0]
    assert re.search(r"Making the projection stage \(a particle quadrature\) exact alone, every other stage in MPM "
                     r"form, stops the growth: .*"
                     r"to \[\d\.\d\d, \d\.\d\d\] on Sod \(h = 0\.01 to 0\.005", first), first
    assert re.search(r"fixed-mesh FEM's density error falls on \d+ of \d+ refinements", first), first


@pytest.mark.parametrize("table", TABLES)
def test_quick_run_reproduces_the_committed_numbers(quick, table):
    keys, values = TABLES[table]
    committed = read_table(FIGURES / table)
    index = {_key(r, keys): r for r in committed}
    matched, differ = 0, []
    for row in read_table(quick / table):
        partner = index.get(_key(row, keys))
        if partner is None:
            continue
        matched += 1
        for column in values:
            a, b = row.get(column, ""), partner.get(column, "")
            if a == b:
                continue
            if a == "" or b == "" or not np.isclose(float(a), float(b), rtol=RTOL, atol=0):
                differ.append(f"{dict(zip(keys, (row[k] for k in keys), strict=False))} "
                              f"{column}: quick {a}, committed {b}")
    assert matched > 0, f"no row of the quick {table} is in the committed one"
    assert not differ, f"{len(differ)} of {matched} rows differ, e.g. " + "; ".join(differ[:3])
