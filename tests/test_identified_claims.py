"""C11 (nodes) and C13 judged at the identified settings (``identification/identified``): each verdict
on a table made to show it, and a perturbed table that flips it."""

from __future__ import annotations

import math

import pytest

from mpm_fem.measure import source
from mpm_fem.measure.claims.base import CONFIRMED, DIFFERS, NOT_MEASURED, PARTLY
from mpm_fem.measure.claims.burgers import _c13_identified
from mpm_fem.measure.claims.identified import burgers_orders, nodal_plateau, source_steps
from mpm_fem.measure.claims.rules import rule

HS = (0.01, 0.005, 0.0025, 0.00125, 0.000625)
SEEDS = (0, 1, 2, 3, 4, 5)


def _sod(errors, seeds=SEEDS, noise=0.0):
    """Identified Sod rows: nodal L1 ``errors[k]`` on mesh HS[k] for every seed (seed s: x (1 + noise s))."""
    return [{"problem": "sod", "source_row": "L1", "setting": "16 ppc, nodes L1, CFL 0.07", "readout": "nodes",
             "norm": "L1", "layout": "regular" if s == 0 else "jittered", "seed": s, "eps": "", "h": h,
             "error": e * (1 + noise * s) if k == len(HS) - 1 else e, "source": source.SOD[h][0],
             "ratio": e / source.SOD[h][0]} for s in seeds for k, (h, e) in enumerate(zip(HS, errors, strict=True))]


SOURCE_L1 = [source.SOD[h][0] for h in HS]


def test_the_source_itself_converges_then_levels_on_these_meshes():
    steps = source_steps(list(HS))
    assert steps["levels"] == [(0.00125, 0.000625)] and len(steps["converges"]) == 3


def test_the_nodal_plateau_is_confirmed_where_every_seed_levels_and_flips_when_one_keeps_converging():
    found = nodal_plateau(_sod(SOURCE_L1))
    assert found.verdict == CONFIRMED, found.evidence
    keeps = SOURCE_L1[:-1] + [SOURCE_L1[-2] / 2]  # first order on the source's levelling step
    assert nodal_plateau(_sod(keeps)).verdict == DIFFERS
    # one seed's last error moved so far that its order crosses FLOOR_ORDER: partly
    cross = 2 ** -rule("FLOOR_ORDER") * 0.8  # order log2(1/0.8 * 2^0.5) > FLOOR_ORDER on the noisy seeds
    mixed = _sod(SOURCE_L1, noise=(cross * SOURCE_L1[-2] / SOURCE_L1[-1] - 1) / 5)
    assert nodal_plateau(mixed).verdict == PARTLY
    assert nodal_plateau(_sod(SOURCE_L1, seeds=SEEDS[:3])).verdict == NOT_MEASURED  # too few runs a mesh


def _burgers(order_exact: float, order_calculated: float):
    rows = []
    for row, p in (("exact", order_exact), ("calculated", order_calculated)):
        for layout, seed, eps in (("regular", 0, 0.045), ("regular", 0, 0.01), *(("jittered", k, 0.045)
                                                                                  for k in (1, 2))):
            rows += [{"problem": "burgers", "source_row": row, "setting": "rarefaction (t0=0.1)", "readout": "nodes",
                      "norm": "max", "layout": layout, "seed": seed, "eps": eps, "h": h,
                      "error": 1e-3 * (h / 0.01) ** (p + 0.01 * seed), "source": 1e-3, "ratio": 1.0}
                     for h in (0.01, 0.005, 0.0025)]
    return rows


def test_c13_at_the_identified_solution_reads_both_accelerations_and_flips():
    rows = _burgers(1.0, 0.98)
    assert burgers_orders(rows, "exact") == pytest.approx([1.0, 1.0, 1.01, 1.02])
    assert _c13_identified(rows, None).verdict == CONFIRMED
    assert _c13_identified(_burgers(1.0, 0.3), None).verdict == PARTLY  # the calculated row below first order
    assert _c13_identified(_burgers(0.2, 0.3), None).verdict == DIFFERS
    found = _c13_identified(rows, None)
    assert "0.98" in found.sentence and "identified" in found.sentence
    assert _c13_identified([r for r in rows if r["h"] == 0.01], None).verdict == NOT_MEASURED
    assert not math.isnan(burgers_orders(rows, "calculated")[0])
