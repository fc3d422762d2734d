"""The registry of the claims: their statements, the :class:`Claim` and the :func:`claim` decorator
that registers a criterion in :data:`CLAIMS`.

A :class:`Claim` holds its statement, the source's number or band, the tables it reads, and its
thresholds, written in words beside the constants the criterion uses. The criterion is a small
function ``criterion(tables) -> (verdict, evidence)``: ``tables`` maps ``"<study>/<table>"`` to rows
as read from the CSVs (:func:`mpm_fem.measure.tables.load_tables`), the verdict is one of
:data:`VERDICTS`, and the evidence is one line formatted from the numbers, its first clause the key
number of the report's summary. A claim whose tables are missing is ``not measured``; no verdict is
ever typed. The per-study modules of :mod:`mpm_fem.measure.claims` import this one, never the package.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Mapping
from dataclasses import dataclass

VERDICTS = ("confirmed", "partly", "differs", "refuted", "not measured")
#: The verdicts by name, so that a criterion returns a name, never a typed word
CONFIRMED, PARTLY, DIFFERS, REFUTED, NOT_MEASURED = VERDICTS


def short(*candidates: str) -> tuple[str, ...]:
    """A :attr:`Finding.key`: the short forms of a key number, from the fullest to the tersest (empty
    ones dropped)."""
    return tuple(text for text in candidates if text)
Tables = Mapping[str, list[dict]]
Criterion = Callable[[Tables], "tuple[str, str] | Finding"]

#: Every claim of the source (C) and every extension (E), in the order the report lists them.
STATEMENTS = {
    "C1": "local time error O(dt^2), global O(dt)",
    "C2": "jump of the third time derivative of x_p at a node crossing limits accuracy to first order",
    "C3": "4-8 particles per cell is optimal in 1D",
    "C4": "Hickernell's particle-quadrature bound with D2(P, N)",
    "C5": "nodal mass projection error O(h^p), 1 <= p <= 2",
    "C6": "nodal momentum projection error: same orders as mass",
    "C7": "nodal force projection error: same orders",
    "C8": "nodal acceleration error one order lower, 0 <= p <= 1",
    "C9": "nodal velocity projection error 0 <= p <= 1",
    "C10": "velocity gradient error of the same order as the velocity error",
    "C11": "Sod: the density error stops converging as h shrinks",
    "C12": "Sod: the error sits at the waves (rarefaction edges, contact, shock front)",
    "C13": "Burgers: first order in h, exact and calculated acceleration",
    "C14": "particle density/energy updates create new extrema at cell crossings",
    "C15": "FE + mass lumping is one of the four error sources",
    "E1": "error budget over every combination of the stages: the stages separate, and one dominates",
    "E2": "bases: point-mass P1 vs GIMP vs C1 B-spline",
    "E3": "on the same mesh MPM's error stays within a constant factor of the fixed-mesh FEM's",
    "E4": "one command regenerates every table from one code version, the current code's",
    "E5": "a remedy (particle-domain B-spline, stress reconstruction, volume reset, PIC/FLIP, XPIC, APIC, a cubic "
          "B-spline) removes the MPM plateau",
    "E6a": "the growth of point-mass MPM's particle error under refinement comes from one stage: made exact, it turns "
           "the growth into convergence on every particle layout",
    "E6": "the local defect, accumulated, predicts the particle error: a closed-form model fitted on coarse meshes "
          "predicts the finer meshes and other particle counts within a factor 2, with the measured trend",
    "E7": "1D: an approximate full mass inverse, FMPM(k) with k <= 4, recovers the consistent mass's accuracy on Sod "
          "and Burgers (the 1D counterpart of D5)",
    "D1": "2D: point-mass MPM's particle error grows under refinement, and the smooth B-splines remove the growth "
          "(the 1D finding)",
    "D2": "2D: the growth comes from one stage: made exact alone, it turns the growth into convergence on every "
          "layout (the 1D E6a)",
    "D3": "2D: error budget on the two coarsest meshes: the stages separate, beside the small-amplitude control "
          "(the 1D E1)",
    "D4": "2D: the lumped mass compensates: the consistent mass raises MPM's error (the 1D C15 finding)",
    "D5": "2D: an approximate full mass inverse, FMPM(k) with k <= 4, recovers the consistent mass's accuracy",
    "D6": "2D: on the same mesh MPM's error stays within a constant factor of the Q1 FEM's, with either mass "
          "(the 1D E3)",
    "D7": "2D: time against space on one mesh: with large steps the time error dominates at second order, with "
          "the study's step refining dt changes nothing (Steffen, Kirby & Berzins 2010; the 1D C1)",
    "D8": "2D projection: the nodal mass, momentum and force errors are O(h^p), 1 <= p <= 2, the acceleration and "
          "velocity 0 <= p <= 1, as in 1D (the 1D C5-C9)",
    "D9": "2D: Hickernell's particle-quadrature bound carries over to the plane with the 2D discrepancy (the 1D C4)",
}


@dataclass(frozen=True)
class Finding:
    """What a criterion found: its ``verdict`` (one of :data:`VERDICTS`), the ``evidence`` (one line
    formatted from the numbers, its first clause the key number of the summary), a ``sentence`` in
    plain words for the abstract and the results (formatted from the same numbers by a template, no
    verdict word pasted in; empty when the criterion has none) and a small evidence ``table`` (rows
    of ``{column: value}``, e.g. one row per setting and one column per quantity; empty when none) and the
    runs of its tables that ``failed`` (one line per cause: count, where, cause; :func:`.rows.failures`),
    left out of the verdict and named beside it, never silently; and the ``key`` number's short forms for
    the README's verdict table, whole sentences from the same numbers, the fullest first: the table takes
    the first that fits its cell (empty: the sentence, or the evidence's first clause, serves)."""

    verdict: str
    evidence: str
    sentence: str = ""
    table: tuple[dict, ...] = ()
    failed: tuple[str, ...] = ()
    key: tuple[str, ...] = ()


@dataclass(frozen=True)
class Claim:
    """One claim: ``id`` (``"C5"``), the ``source``'s number or band, the ``tables`` it reads, the
    ``thresholds`` of its verdicts in words, its ``criterion``, the ``study`` whose section shows it,
    the ``problem`` it is measured on when it is measured on several (``"sod"``), and an
    ``explanation`` of what the measurement means (prose without numbers)."""

    id: str
    source: str
    tables: tuple[str, ...]
    thresholds: str
    criterion: Criterion
    study: str
    problem: str = ""
    explanation: str = ""

    @property
    def statement(self) -> str:
        return STATEMENTS[self.id]

    @property
    def label(self) -> str:
        return f"{self.id} ({self.problem})" if self.problem else self.id

    def finding(self, tables: Tables) -> Finding:
        """The criterion's :class:`Finding`; ``not measured`` when a table it reads is missing or empty.
        A criterion may return a :class:`Finding` or a ``(verdict, evidence)`` pair."""
        missing = [name for name in self.tables if not tables.get(name)]
        if missing:
            return Finding(NOT_MEASURED, "no table " + ", ".join(f"`{m}.csv`" for m in missing))
        found = self.criterion(tables)
        if not isinstance(found, Finding):
            found = Finding(*found)
        if found.verdict not in VERDICTS:
            raise ValueError(f"claim {self.label}: verdict {found.verdict!r} is not one of {VERDICTS}")
        return found

    def verdict(self, tables: Tables) -> tuple[str, str]:
        """``(verdict, evidence)`` of :meth:`finding`."""
        found = self.finding(tables)
        return found.verdict, found.evidence


CLAIMS: list[Claim] = []


def claim(id: str, source: str, tables: tuple[str, ...], thresholds: str, study: str,
          problem: str = "") -> Callable[[Criterion], Criterion]:
    """Register the decorated criterion as a :class:`Claim` in :data:`CLAIMS`; the criterion's
    docstring, joined into one line, is the claim's ``explanation``."""
    if id not in STATEMENTS:
        raise ValueError(f"claim id {id!r} is not one of {tuple(STATEMENTS)}")

    def register(criterion: Criterion) -> Criterion:
        explanation = " ".join((inspect.getdoc(criterion) or "").split())
        CLAIMS.append(Claim(id, source, tuple(tables), thresholds, criterion, study, problem, explanation))
        return criterion

    return register


def claims_of(study: str) -> list[Claim]:
    """The registered claims shown in ``study``'s section, in the order of :data:`STATEMENTS`."""
    return sorted((c for c in CLAIMS if c.study == study), key=lambda c: (list(STATEMENTS).index(c.id), c.problem))

