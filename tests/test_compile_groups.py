"""benchmarks/compile_groups.py measures the compile of every kernel variant a kernel group's cases run through:
per group it runs the cheapest case of each kind, so that cases of one group that run different kernels (the
mechanism study's stages made exact) are all met, with the function ``reproduce`` runs them with. No case runs
here: the plan only."""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))

import compile_groups  # noqa: E402


def test_a_kind_is_the_cases_string_settings_not_its_numbers():
    case = {"kind": "mechanism", "problem": "sod", "h": 0.01, "made_exact": "mass", "seed": 2, "layout": "jittered"}
    assert compile_groups.signature(case) == (("kind", "mechanism"), ("layout", "jittered"), ("made_exact", "mass"),
                                              ("problem", "sod"))


def test_each_mechanism_group_runs_every_stage_made_exact_on_the_numpy_step():
    """The quick tier's mechanism groups (one a problem) run through run_numpy_case, and their cases cover
    every subset of the study's CASES (the exact projection compiles the exact quadrature, the time case none),
    each at its cheapest mesh."""
    from studies import mechanism

    found = compile_groups.groups("quick", ["mechanism"], method=False)
    assert len(found) == 2 and all(g["fn"] == "run_numpy_case" for g in found.values()), found
    for group in found.values():
        assert {c["made_exact"] for c in group["cases"]} == set(mechanism.CASES)
        assert all(c["kernel"] == "numpy" for c in group["cases"])
        sod = [c for c in group["cases"] if c["problem"] == "sod"]
        assert all(c["h"] == 0.01 for c in sod)
