"""The source's claims as data, each with the criterion that turns the tables into a verdict.

A :class:`Claim` holds its statement, the source's number or band, the tables it reads, and its
thresholds, written in words beside the constants the criterion uses. The criterion is a small
function ``criterion(tables) -> (verdict, evidence)``: ``tables`` maps ``"<study>/<table>"`` to rows
as read from the CSVs (:func:`mpm_fem.measure.tables.load_tables`), the verdict is one of :data:`VERDICTS`,
and the evidence is one line formatted from the numbers, its first clause the key number of the
report's summary. A claim whose tables are missing is ``not measured``; no verdict is ever typed.

One module per study registers its claims with :func:`claim` (:mod:`.base`, with :data:`STATEMENTS`
and :data:`CLAIMS`): :mod:`.projection` (C4-C10), :mod:`.sod` (C3, C11, C12, C14, C15, E3),
:mod:`.reproduce` (E4), :mod:`.burgers` (C3, C13, C15), :mod:`.time` (C1, C2), :mod:`.budget` (E1,
E2), :mod:`.remedies` (E5), :mod:`.mechanism` (E6a), :mod:`.model` (E6), :mod:`.lumping` (E7), :mod:`.plane` (D1-D7) and
:mod:`.plane_projection` (D8, D9); :mod:`.shared` holds the criteria of C3 and
C15 that Sod and Burgers share, :mod:`.rows` the helpers that read rows. The tables' names and columns
are declared once, in :mod:`mpm_fem.measure.schema` (the mechanism's in :mod:`.mechanism`, which adds
them to the schema's index). Importing this package registers every claim, in the order above. The
statements and the source's tables, with the corrections made to them, are in ``docs/claims.md``.
"""

from __future__ import annotations

from mpm_fem.measure.claims.base import (
    CLAIMS,
    STATEMENTS,
    VERDICTS,
    Claim,
    Criterion,
    Finding,
    Tables,
    claim,
    claims_of,
)
from mpm_fem.measure.claims.rows import (
    count_verdict,
    failed,
    failure_cause,
    failures,
    num,
    saturation,
    select,
    span,
    successive_orders,
)

# the per-study modules, in the order their claims are registered (CLAIMS keeps that order)
# isort: off
from mpm_fem.measure.claims.projection import BAND_TOLERANCE, JUDGED_LAYOUTS, ORDERS
from mpm_fem.measure.claims.shared import LUMPING_BAND, SATURATION, lumping_sign
from mpm_fem.measure.claims.sod import (
    CONVERGENCE, CONVERGING_ORDER, EXTREMA_RATIO, FLOOR_MESHES, FLOOR_ORDER, FLOOR_STEPS, SIDE_BY_SIDE, WAVE_REGIONS,
    WAVE_DENSITY)
from mpm_fem.measure.claims import reproduce  # noqa: F401  (registers E4)
from mpm_fem.measure.claims.burgers import BURGERS_SHOWN, FIRST_ORDER
from mpm_fem.measure.claims.time import CROSSING_TOLERANCE, GLOBAL_ORDER, LOCAL_ORDER, NO_JUMP
from mpm_fem.measure.claims.budget import (
    ROUNDOFF, SEPARATE, SEQUENCES, STEP_ORDER, SUBSETS, _roundoff_text, budget_findings, sequential, stage_findings)
from mpm_fem.measure.claims.remedies import (
    BURGERS_ORDER, FV_DRIFT, FV_FACTOR, ORDER_MARGIN, PLATEAU_CRITERION, REMEDY_ERRORS, REMEDY_MEASURES,
    remedy_assessment, remedy_budget)
from mpm_fem.measure.claims.mechanism import MECHANISM_MESHES, growth_cases, summary_rows
from mpm_fem.measure.claims.model import model_rows, ppc_needed
from mpm_fem.measure.claims import lumping  # noqa: F401,E402  (registers E7)
from mpm_fem.measure.claims import plane  # noqa: F401,E402  (registers D1-D7)
from mpm_fem.measure.claims import plane_projection  # noqa: F401,E402  (registers D8, D9)
# isort: on

__all__ = [
    "VERDICTS", "STATEMENTS", "Tables", "Criterion", "Claim", "Finding", "CLAIMS", "claim", "claims_of",
    "num", "select", "span", "count_verdict", "saturation", "successive_orders", "failed", "failure_cause", "failures",
    "BAND_TOLERANCE", "JUDGED_LAYOUTS", "ORDERS",
    "SATURATION", "LUMPING_BAND", "lumping_sign",
    "CONVERGENCE", "FLOOR_ORDER", "CONVERGING_ORDER", "FLOOR_MESHES", "FLOOR_STEPS", "WAVE_REGIONS", "WAVE_DENSITY",
    "EXTREMA_RATIO", "SIDE_BY_SIDE",
    "BURGERS_SHOWN", "FIRST_ORDER",
    "GLOBAL_ORDER", "LOCAL_ORDER", "CROSSING_TOLERANCE", "NO_JUMP",
    "SUBSETS", "STEP_ORDER", "SEPARATE", "SEQUENCES", "ROUNDOFF", "budget_findings", "stage_findings", "sequential",
    "_roundoff_text",
    "REMEDY_ERRORS", "ORDER_MARGIN", "FV_DRIFT", "PLATEAU_CRITERION", "FV_FACTOR", "BURGERS_ORDER", "REMEDY_MEASURES",
    "remedy_assessment", "remedy_budget",
    "MECHANISM_MESHES", "growth_cases", "summary_rows", "model_rows", "ppc_needed",
]
