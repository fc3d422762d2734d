"""The rule book: every threshold a verdict uses, once, with its meaning and its reason.

A criterion reads its thresholds from :data:`RULES` (by name, :func:`rule`), never from a number
written in its own module (``tests/test_rules.py`` walks the syntax trees of the claims package and
fails on a numeric threshold anywhere else). The report's Method section prints this book as a table.
The same book serves every tier: no tier has a smaller minimum of meshes or runs.

The verdict words, one meaning each (:data:`VERDICT_MEANING`).
"""

from __future__ import annotations

from dataclasses import dataclass

from mpm_fem.measure.claims.base import DIFFERS, VERDICTS

#: One meaning per verdict word (:data:`~mpm_fem.measure.claims.base.VERDICTS`, in their order), written
#: once; the report's Method section prints them.
VERDICT_MEANING = dict(zip(VERDICTS, (
    "the source's statement holds at the source's settings",
    "the statement holds on some settings or quantities, which the evidence names",
    "the measured behaviour is another one, which the evidence names",
    "the statement's test fails",
    "a table the criterion reads is missing or too small to judge",
), strict=True))


@dataclass(frozen=True)
class Rule:
    """One threshold: its ``name``, ``value``, what it means (``meaning``), why this value
    (``reason``: the source's words, or "the study's" where the slides state no number) and the
    ``claims`` that read it."""

    name: str
    value: float
    meaning: str
    reason: str
    claims: tuple[str, ...]


#: Every rule, by name, in the order the report prints them.
RULES: dict[str, Rule] = {}


def _add(name: str, value: float, meaning: str, reason: str, claims: tuple[str, ...]) -> float:
    if name in RULES:
        raise ValueError(f"rule {name!r} is defined twice")
    RULES[name] = Rule(name, value, meaning, reason, claims)
    return value


def rule(name: str) -> float:
    """The value of rule ``name``; an unknown name is refused."""
    try:
        return RULES[name].value
    except KeyError:
        raise KeyError(f"no rule {name!r} in the rule book; rules: {', '.join(RULES)}") from None


_STUDY = "the study's (the slides state no number)"

# ---------------------------------------------------------------- orders: one meaning of each word
_add("ORDER_TOLERANCE", 0.2,
     "an observed order counts as a stated order n (first order: n = 1) when within this distance of it; a band "
     "[a, b] of the slides widens by it on each side; 'first order' in a convergence claim: an order at least "
     "1 minus it (C1, C5-C10, C13 share this one definition)",
     _STUDY + ": the slides state orders as whole numbers (O(dt), O(h^p) with 1 <= p <= 2) without a tolerance. "
     "0.2 replaces the three the criteria had (+-0.2 in C1, >= 0.7 in C13, +-0.1 in C5-C9): it is about "
     "twice the spread of the fitted first orders over the seeded layouts of the projection study (0.96-1.05, a "
     "spread of 0.09) and less than half the gap to the next half order, so a first-order error never reads as "
     "order 0.5 or 1.5",
     ("C1", "C5", "C6", "C7", "C8", "C9", "C10", "C13", "D8"))
_add("CONVERGING_ORDER", 0.7,
     "an order at or above this counts as converging (the error falls with h) on a problem with a shock and a "
     "contact, whose L1 orders stay below one",
     _STUDY + ": the source's own Sod orders before the plateau are 0.87-0.94; 0.7 lies below them and above "
     "the floor", ("C11", "E2", "E5", "E6a"))
_add("FLOOR_ORDER", 0.5,
     "an order below this counts as a floor: the error no longer falls with h",
     _STUDY + ": the source says the error 'stops converging' without a number; half the order the source "
     "measures before the plateau", ("C11", "C13", "E2", "E5"))
_add("GROWTH_ORDER", 0.0,
     "an order below this: the error grows as h shrinks (a divergence, not a plateau)",
     "the sign of the order: below zero the error is larger on the finer mesh", ("C11", "C13", "E6a"))
_add("MIN_RUNS", 6,
     "the runs (the regular layout and five jittered seeds) an order or a ratio is judged over, on each mesh",
     _STUDY + ": the regular layout and the five jittered seeds the convergence study runs", ("C11", "E3", "E6a"))
_add("FLOOR_MESHES", 5,
     "the meshes with MIN_RUNS runs C11 needs: converging orders first, then a levelling",
     "the source's Sod table has six meshes, the first three orders converging; five meshes give four orders, "
     "room for two converging and two levelling", ("C11",))
_add("FLOOR_STEPS", 2,
     "the last orders C11 reads the levelling (or the growth) from",
     _STUDY + ": the source's table levels over its last two refinements (0.00125 -> 0.000625 -> 0.0003125)",
     ("C11",))
_add("SAME_SIZE", 2.0,
     "C11: the measured error at the coarsest mesh is of the source's size when within this factor of it",
     _STUDY + ": the slides give the values, not a tolerance; a factor two separates 'the same size' from the "
     "1.7-35x discrepancies measured", ("C11",))

# ---------------------------------------------------------------- particles per cell, mass, waves, extrema
_add("SATURATION", 0.05,
     "C3: the fewest particles per cell whose error is within this fraction of the smallest one",
     _STUDY + ": the slides say '4-8 particles per cell is optimal' without a tolerance", ("C3",))
_add("LUMPING_BAND", 0.9,
     "C15 (second reading): a consistent/lumped error ratio below this means lumping is a source of error, above "
     "its inverse that it compensates; above its inverse on every mesh where the direct reading is swamped: C15 "
     + DIFFERS,
     _STUDY + ": the slides name FE + mass lumping a source without a size; a 10 % change is well outside the "
     "spread over meshes of the FEM's own ratio (0.996-0.998)", ("C15",))
_add("SOURCE_SHARE", 0.1,
     "C15: the mass stage (the FE solve with the lumped mass) is an error source when its MPM form alone raises "
     "the all-exact error by at least this fraction of the all-MPM error",
     _STUDY + ": the slides list FE + mass lumping among four sources without a size; a tenth of MPM's error", ("C15",))
_add("WAVE_DENSITY", 2.0,
     "C12: the named wave regions (rarefaction edges, contact, shock front) carry the error when their error per "
     "unit length is at least this factor times that of the smooth region between them",
     _STUDY + ": the slides say where the error sits (rarefaction edges, contact, shock front), not how much of "
     "it; ranking the regions by error per unit length judges that statement, and twice the smooth region's "
     "is the study's reading of 'sits at'", ("C12",))
_add("EXTREMA_RATIO", 2.0,
     "C14: a crossing particle becomes a new extremum at least this many times as often as a moving one that "
     "does not cross",
     _STUDY + ": the slides say new extrema appear at cell crossings; twice the background rate", ("C14",))

# ---------------------------------------------------------------- time
_add("CROSSING_TOLERANCE", 0.1,
     "C2: P1's measured jump of d^3x_p/dt^3 matches the slides' formula when every measured/predicted ratio is "
     "within this of one", _STUDY + ": the formula is exact; 10 % allows the finite-difference estimate",
     ("C2",))
_add("NO_JUMP", 0.1,
     "C2: a C1 basis has no jump when its |measured| stays below this fraction of the P1 formula",
     _STUDY + ": the slides say the C1 bases have no jump; an order of magnitude below P1's", ("C2",))

# ---------------------------------------------------------------- the error budget and the bases
_add("SEPARATE", 0.25,
     "E1: the stages separate when the interactions, in total magnitude, are at most this fraction of the gap "
     "|v(all MPM) - v(all exact)|", _STUDY + ": a quarter of the gap leaves each main effect readable", ("E1",))
_add("ATTRIBUTABLE", 1.0,
     "E1: a dominant stage is named only where the interactions are at most this multiple of the gap; C15: the "
     "mass stage's direct reading is separable where its interactions are at most this multiple of its own effect "
     "(separable nowhere: swamped, and the consistent/lumped reading decides)",
     _STUDY + ": where the interactions exceed the gap itself, any attribution to one stage is an artefact of "
     "the order of replacement", ("E1", "C15"))

# ---------------------------------------------------------------- MPM against the fixed-mesh FEM
_add("E3_FACTOR", 1.5,
     "E3: MPM's error over the fixed-mesh FEM's stays within a constant factor when its change from the "
     "coarsest mesh to the finest lies within [1/this, this]", _STUDY, ("E3",))

# ---------------------------------------------------------------- the remedies
_add("FV_DRIFT", 1.5,
     "E5: a remedy's error stays within a constant factor of the FV's when its ratio to the FV error at the "
     "finest mesh is at most this times that at the coarsest", _STUDY, ("E5",))
_add("FV_FACTOR", 1.5,
     "E5: the goal on Sod, within this factor of the finite-volume error at every h",
     "the goal set for the remedies (the brief)", ("E5",))
_add("BURGERS_ORDER", 1.0,
     "E5: the goal on Burgers (4 per cell), a fitted order at least this at the nodes and at the particles",
     "the goal set for the remedies (the brief): first order, as the slides state for Burgers", ("E5",))

# ---------------------------------------------------------------- the mechanism (drift study, C11's explanation)
_add("REDUCED", 0.5,
     "C11's mechanism: a variant whose error still grows reduces the growth when its order is at least this "
     "times the study settings' (both negative: at most half as fast)", _STUDY, ("C11",))
_add("SAME_NODES", 1e-3,
     "C11's mechanism: nodal errors within this relative distance count as the same motion",
     _STUDY + ": far above round-off, far below the changes a variant makes", ("C11",))


_add("MECHANISM_MESHES", 4,
     "E6a: the meshes every run of a particles-per-cell value needs before its growth is decomposed by stage",
     "E6a asks for at least four meshes: three successive orders, so that a growth and what removes it are "
     "seen over more than one refinement", ("E6a",))
_add("PREDICTION_FACTOR", 2.0,
     "E6: the model predicts a run's particle error when model / measured lies in [1/factor, factor]",
     "E6 asks for a factor of 2: a model of the error's size and trend, not of its digits", ("E6",))
_add("MODEL_FIT_PPC", 4,
     "E6: the particles per cell of the rows the error model is fitted on (the others are checked)",
     "E6: fitted at one particles-per-cell value, checked on the other", ("E6",))
_add("MODEL_FIT_H_SOD", 0.0025,
     "E6: on Sod the model is fitted on the meshes h >= this at MODEL_FIT_PPC (the finer meshes are checked)",
     "E6: fitted on h >= 0.0025, checked on the finer meshes", ("E6",))
_add("MODEL_FIT_H_BURGERS", 0.02,
     "E6: on Burgers the model is fitted on the meshes h >= this at MODEL_FIT_PPC",
     "E6: fitted on h >= 0.02 (Burgers' meshes are eight times coarser than Sod's)", ("E6",))
_add("MODEL_P_MIN", 0.5,
     "E6: the smallest order p of the model's converging term A h^p tried in the fit",
     _STUDY + ": half order, the L1 order of a smeared contact discontinuity", ("E6",))
_add("MODEL_P_MAX", 2.0,
     "E6: the largest order p of the converging term tried",
     _STUDY + ": second order, the best a smooth region gives with linear elements; a fitted p on this bound is "
     "reported as a bound (p >= it), not as an order", ("E6",))
_add("MODEL_P_STEPS", 31,
     "E6: the orders p tried, evenly spaced from MODEL_P_MIN to MODEL_P_MAX (a step of 0.05)",
     _STUDY + ": finer than the orders' spread over the seeds", ("E6",))
_add("MODEL_OUT_MESHES", 2,
     "E6: a checked row at the fitting particle count is out of sample when its mesh lies at least this many "
     "refinements beyond the finest fitted mesh (a row at another particle count always is); only out-of-sample "
     "rows are counted as predicted",
     _STUDY + ": the mesh next to the fit is an extrapolation of one step, which any smooth fit through the fitted "
     "meshes makes well; a prediction is tested two steps out", ("E6",))
_add("MODEL_MIN_CHECKED", 3,
     "E6: the out-of-sample rows a setting (problem, particles per cell, layout) needs before it is judged",
     _STUDY + ": a trend needs two meshes and a factor more than one row", ("E6",))


# ----------------------------------------------------------------------------- the plane (2D)
_add("PLANE_MIN_RUNS", 6,
     "D1: the runs (the regular layout and five jittered seeds) a 2D series needs on every mesh before its "
     "behaviour under refinement is judged",
     _STUDY + ": the regular layout and the five jittered seeds of the 1D studies (MIN_RUNS)", ("D1",))
_add("PLANE_MIN_MESHES", 3,
     "D1, D2, D6: the meshes a 2D series needs: two successive orders, so that a growth is seen over the last "
     "refinement with one before it",
     _STUDY + ": the full tier's 4x4 and stage-exact series stop at h = 1/32 (three meshes from h = 1/8)",
     ("D1", "D2", "D6"))
_add("FMPM_RECOVERS", 0.1,
     "D5, E7: FMPM(k) recovers the consistent mass's accuracy on a mesh when its particle error is within this "
     "fraction of the consistent mass's",
     _STUDY + ": the question is whether the approximate inverse 'recovers' the consistent mass's accuracy; "
     "10 % is well inside the factors between the masses", ("D5", "E7"))
_add("TIME_ORDER_2D", 2.0,
     "D7: the order in dt of the 2D step's time error (central differences, the velocity at half steps, "
     "started at t = -dt/2), counted within ORDER_TOLERANCE",
     "Steffen, Kirby & Berzins (IJNME 82 (2010) 1207): with large time steps the time error dominates and "
     "converges at second order", ("D7",))
_add("TIME_NEGLIGIBLE", 0.1,
     "D7: at the study's time step refining dt changes nothing when the error moves by at most this fraction "
     "from the study's step to the finest",
     _STUDY + ": Steffen, Kirby & Berzins say that with small steps refining the step changes nothing; a tenth "
     "of the error", ("D7",))

# ----------------------------------------------------------------------------- identification

_add("IDENTIFICATION_BAND", 0.05,
     "a candidate setting matches the source when its misfit (mean |log(measured/source)| over the source's "
     "table) is at most this much above the least misfit of the same source row",
     "the study's (the slides state no tolerance): 0.05 in the mean log is about 5 % in the mean factor, taken as "
     "too small a difference to prefer one unstated setting over another", ("C11", "C13"))
_add("IDENTIFICATION_REPRODUCED", 0.1,
     "the source's table is reproduced by a candidate whose misfit is at most this (a mean factor within about "
     "10 %)",
     "the study's (the slides state no tolerance): the goal is the source's behaviour, not its digits; a mean "
     "factor within 10 % is read as the same table", ("C11", "C13"))
_add("IDENTIFICATION_SPREAD_WEIGHT", 1.0,
     "the weight of the spread over eps in a Burgers row's misfit: the mean |log(measured/source)| plus this "
     "times the mean over the meshes of |log(measured max/min over eps) - log(source max/min over eps)|",
     "the study's: the source's exact row is about the same at every eps (its spread over eps is small), so that "
     "independence counts as much as the size; weight 1 puts a factor in the spread on a par with a factor in "
     "every entry", ("C13",))
_add("IDENTIFICATION_REFINED", 0.05,
     "the refinement test: halving every tolerance of the search (restarted at the converged point) moves the "
     "best misfit by less than this",
     "the study's: the band within which two misfits are not told apart (IDENTIFICATION_BAND)", ("C11", "C13"))
