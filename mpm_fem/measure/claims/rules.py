"""The rule book: every threshold a verdict uses, once, with its meaning and its reason.

A criterion reads its thresholds from :data:`RULES` (by name, :func:`rule`), never from a number
written in its own module (``tests/test_rules.py`` walks the syntax trees of the claims package and
fails on a numeric threshold anywhere else). The report's Method section prints this book as a table.
The same book serves every tier: no tier has a smaller minimum of meshes or runs.

The verdict words, one meaning each (:data:`VERDICT_MEANING`).
"""

from __future__ import annotations

from dataclasses import dataclass

#: One meaning per verdict word, written once; the report's Method section prints them.
VERDICT_MEANING = {
    "confirmed": "the source's statement holds at the source's settings",
    "partly": "the statement holds on some settings or quantities, which the evidence names",
    "differs": "the measured behaviour is another one, which the evidence names",
    "refuted": "the statement's test fails",
    "not measured": "a table the criterion reads is missing or too small to judge",
}


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


# ----------------------------------------------------------------------------- identification (issue 42, A)

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
