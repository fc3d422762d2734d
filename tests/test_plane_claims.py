"""The 2D claims D1-D7 (``mpm_fem.measure.claims.plane``) follow their numbers: each verdict on a small
table made here, and the same table perturbed so that the verdict flips."""

from __future__ import annotations

import math

import pytest
from claim_mutations import claim_named, judge, mutate

from mpm_fem.measure.claims.plane import orders, series

H = (1 / 8, 1 / 16, 1 / 32)
LAYOUTS = [("regular", 0)] + [("jittered", s) for s in range(1, 6)]


def _growth(p1_last: float, smooth_last: float = 2.0, solution: str = "axis-0.05") -> list[dict]:
    """P1 and the cubic B-spline on six layouts and three meshes: order 2 over the first refinement, then
    ``p1_last`` (P1) or ``smooth_last`` (cubic), the seeds spread by a few per cent."""
    rows = []
    for basis, last in (("mpm", p1_last), ("cubic", smooth_last)):
        for layout, seed in LAYOUTS:
            e = 1e-3 * (1 + 0.01 * seed)
            for k, h in enumerate(H):
                if k:
                    e /= 2.0 ** (2.0 if k == 1 else last)
                rows.append({"solution": solution, "basis": basis, "ppc": "2", "layout": layout, "seed": str(seed),
                             "h": repr(h), "ok": "True", "L2": repr(e)})
    return rows


def _tables(**parts) -> dict:
    return {f"plane/{k}": v for k, v in parts.items()}


def test_an_order_is_minus_infinity_where_the_finer_run_stopped():
    assert orders([(0.1, 1.0), (0.05, 0.25), (0.025, math.nan)]) == [pytest.approx(2.0), -math.inf]


def test_a_mixed_series_is_said_by_its_runs_and_one_finite_order_is_not_a_spread():
    """Five of six P1 runs stop on the two finest meshes (a particle inverted on both), one grows: the key
    says the runs by behaviour, not "mixed", and the one finite order is not given a spread."""
    rows = _growth(-0.5)
    coarse = max(float(r["h"]) for r in rows)
    for r in rows:
        if r["basis"] == "mpm" and r["seed"] != "0" and float(r["h"]) < coarse:
            r["ok"], r["L2"] = "False", ""
    found = claim_named("D1 (axis-0.05)").finding(_tables(growth=rows))
    assert found.verdict == "partly", found
    assert found.key[-1].startswith("axis-0.05: P1 grows on 1 of 6 runs, 5 stop on both meshes; last order -0.50 "
                                    "(one run)"), found.key
    assert "mixed" not in found.key[-1] and "mixed" not in found.evidence.split(";")[0]


def test_a_series_is_judged_on_the_meshes_every_run_has():
    rows = _growth(-0.5) + [{"solution": "axis-0.05", "basis": "mpm", "ppc": "2", "layout": "regular", "seed": "0",
                              "h": repr(1 / 64), "ok": "True", "L2": "1.0"}]
    s = series(rows, solution="axis-0.05", basis="mpm", ppc=2)
    assert s["meshes"] == 3 and s["judged"] and s["verdict"] == "grows", s
    assert s["last"].mean == pytest.approx(-0.5, abs=1e-9)


def test_d1_confirms_growth_of_p1_with_smooth_bases_converging_and_differs_without_growth():
    growing = _tables(growth=_growth(-0.5))
    assert judge("D1 (axis-0.05)", growing)[0] == "confirmed"
    converging = mutate(growing, "plane/growth", {"basis": "mpm", "h": repr(1 / 32)},
                        L2=lambda r: float(r["L2"]) / 2.0 ** 2.5)
    verdict, evidence = judge("D1 (axis-0.05)", converging)
    assert verdict == "differs", evidence
    one_seed = mutate(growing, "plane/growth", {"basis": "mpm", "h": repr(1 / 32), "seed": "3"},
                      L2=lambda r: float(r["L2"]) / 2.0 ** 2.5)
    assert judge("D1 (axis-0.05)", one_seed)[0] == "partly"


def test_d1_counts_a_run_that_inverts_on_the_finest_mesh_as_growing():
    tables = _tables(growth=_growth(2.0))
    stopped = mutate(tables, "plane/growth", {"basis": "mpm", "h": repr(1 / 32)}, ok="False", L2="")
    assert judge("D1 (axis-0.05)", tables)[0] == "differs"
    assert judge("D1 (axis-0.05)", stopped)[0] == "confirmed"


def test_d1_needs_six_runs():
    rows = [r for r in _growth(-0.5) if r["seed"] in ("0", "1", "2")]
    assert judge("D1 (axis-0.05)", _tables(growth=rows))[0] == "not measured"


def _stages(projection_last: float) -> list[dict]:
    """All MPM grows over the last refinement (order -0.5) on two layouts; the projection made exact gives
    ``projection_last`` there, the other stages -0.3."""
    rows = []
    last = {"none": -0.5, "projection": projection_last, "mass": -0.3, "interpolation": -0.3, "time": -0.3,
            "all": 2.0}
    for made, p in last.items():
        for layout, seed in LAYOUTS[:2]:
            e = 1e-3
            for k, h in enumerate(H):
                if k:
                    e /= 2.0 ** (2.0 if k == 1 else p)
                rows.append({"solution": "axis-0.05", "h": repr(h), "layout": layout, "seed": str(seed),
                             "made_exact": made, "ok": "True", "L2": repr(e)})
    return rows


def test_d2_names_the_stage_whose_exact_form_turns_the_growth_into_convergence():
    good = _tables(stages=_stages(1.8))
    verdict, evidence = judge("D2 (axis-0.05)", good)
    assert verdict == "confirmed" and "named: projection" in evidence, evidence
    bad = mutate(good, "plane/stages", {"made_exact": "projection", "h": repr(1 / 32), "seed": "1"},
                 L2=lambda r: float(r["L2"]) * 4.0)
    assert judge("D2 (axis-0.05)", bad)[0] == "refuted"


def _shapley(interactions: float) -> list[dict]:
    return [{"solution": sol, "h": repr(h), "stage": s, "shapley": repr(x), "share": repr(x), "mpm_error": "1.0",
             "exact_error": "0.0", "gap": "1.0", "interactions": repr(interactions),
             "interactions_share": repr(interactions)}
            for sol in ("axis-0.05", "axis-1e-4") for h in H[:2]
            for s, x in zip(("projection", "mass", "interpolation", "time"), (0.7, 0.1, 0.1, 0.1), strict=True)]


def test_d3_the_stages_separate_when_the_interactions_are_small():
    good = _tables(shapley=_shapley(0.1))
    verdict, evidence = judge("D3", good)
    assert verdict == "confirmed" and "largest projection" in evidence, evidence
    bad = mutate(good, "plane/shapley", {"solution": "axis-0.05"}, interactions_share=0.9)
    assert judge("D3", bad)[0] == "partly"
    assert judge("D3", _tables(shapley=_shapley(0.9)))[0] == "refuted"


def _mass(consistent: float, fmpm: tuple[float, ...] = (1.0, 1.2, 1.1, 1.05)) -> list[dict]:
    """Lumped error 1, consistent ``consistent``, FMPM(k) ``consistent`` times ``fmpm[k - 1]``."""
    errors = {"lumped": 1.0, "consistent": consistent, "exact": 0.5,
              **{f"fmpm{k}": consistent * f for k, f in enumerate(fmpm, 1)}}
    return [{"solution": "axis-0.05", "h": repr(h), "mass": m, "basis": "mpm", "ok": "True", "L2": repr(e * h),
             "step_ms": repr(1.0 + k)} for h in H for k, (m, e) in enumerate(errors.items())]


def test_d4_lumping_compensates_when_the_consistent_mass_raises_the_error():
    raised = _tables(mass=_mass(1.5))
    assert judge("D4", raised)[0] == "confirmed"
    assert judge("D4", _tables(mass=_mass(0.5)))[0] == "differs"
    assert judge("D4", _tables(mass=_mass(1.0)))[0] == "refuted"


def test_d5_fmpm_recovers_the_consistent_mass_within_the_rule():
    near = _tables(mass=_mass(1.5, (1.5 ** -1, 1.2, 1.05, 1.01)))
    verdict, evidence = judge("D5", near)
    assert verdict == "confirmed" and "fmpm3" in evidence, evidence
    far = _tables(mass=_mass(1.5, (1.5 ** -1, 1.4, 1.3, 1.2)))
    assert judge("D5", far)[0] == "refuted"
    lumped_near = _tables(mass=_mass(1.05, (1.05 ** -1, 1.4, 1.3, 1.2)))  # FMPM(1) is the lumped mass: not counted
    assert judge("D5", lumped_near)[0] == "refuted"


def _fem_tables(mpm_factor: float) -> dict:
    """FEM errors h^2, MPM lumped ``3 h^2`` times ``mpm_factor`` per refinement, consistent 2x the FEM."""
    growth = [{"solution": "vortex", "basis": "mpm", "ppc": "2", "layout": "regular", "seed": "0", "h": repr(h),
               "ok": "True", "L2": repr(3 * h * h * mpm_factor ** k)} for k, h in enumerate(H)]
    fem = [{"solution": "vortex", "h": repr(h), "mass": m, "ok": "True", "L2": repr(h * h)}
           for h in H for m in ("lumped", "consistent")]
    mass = [{"solution": "vortex", "h": repr(h), "mass": "consistent", "ok": "True", "L2": repr(2 * h * h)} for h in H]
    return _tables(growth=growth, fem=fem, mass=mass)


def test_d6_a_constant_ratio_to_the_fem_and_a_growing_one():
    assert judge("D6 (vortex)", _fem_tables(1.0))[0] == "confirmed"
    assert judge("D6 (vortex)", _fem_tables(2.0))[0] == "partly"


def _time(space: float, order: float, study_change: float) -> list[dict]:
    """The error at refine k: ``space + c (dt_k)^order`` with the time error at CFL 0.8 twice the space error,
    the run at CFL 0.2 moved by ``study_change`` of the finest."""
    rows = []
    for k in (1, 2, 4, 8, 16, 32):
        e = space + 2 * space * k ** -order
        if k == 4:
            e = space * (1 + study_change)
        rows.append({"solution": "axis-0.05", "refine": str(k), "cfl_run": "0.8", "study_cfl": "0.25", "ok": "True",
                     "L2": repr(e)})
    return rows


def test_d7_time_against_space_follows_its_parts():
    assert judge("D7", _tables(time=_time(1e-3, 2.0, 0.02)))[0] == "confirmed"
    assert judge("D7", _tables(time=_time(1e-3, 1.0, 0.02)))[0] == "partly"
    assert judge("D7", _tables(time=_time(1e-3, 1.0, 0.5)))[0] == "refuted"
