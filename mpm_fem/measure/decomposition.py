"""Exact decomposition of an error over every combination of the stages (E1).

Let ``N`` be the set of the step's stages and ``v(S)`` the error of the run with the stages in
``S`` in their MPM form and the others exact, so ``v(N)`` is the MPM error and ``v({})`` the
error with every stage exact. ``v`` may be a number (an error norm) or an array (a signed error
field on fixed points): every formula below is linear in ``v``.

Moebius (inclusion-exclusion) terms, one per subset ``S``:

    m(S) = sum_{T subset of S} (-1)^{|S| - |T|} v(T),       so that  v(S) = sum_{T subset of S} m(T).

``m({})`` is the all-exact error, ``m({s})`` the main effect of stage ``s`` (its error alone), and
``m(S)`` for ``|S| >= 2`` the interaction of the stages of ``S``: what they do together beyond the
sum of what they do in smaller groups. The terms sum exactly to ``v(N)``.

Shapley value of stage ``s``: its main effect plus an equal share of every interaction it is part of,

    phi_s = sum_{S containing s} m(S) / |S|
          = (1 / |N|!) sum over the orders of N of [v(stages before s, and s) - v(stages before s)],

so ``sum_s phi_s = v(N) - v({})`` in any order of the stages. The values are signed: a negative
``phi_s`` says that the MPM form of stage ``s`` lowers the error on average over the others,
i.e. it compensates them.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from functools import reduce
from itertools import combinations, permutations
from math import factorial

import numpy as np

__all__ = ["Decomposition", "decompose", "subsets", "shapley_by_orders", "label"]


def subsets(stages: Iterable[str]) -> list[frozenset]:
    """Every subset of ``stages``, by size, then in the order the stages are given."""
    stages = tuple(stages)
    if len(set(stages)) != len(stages):
        raise ValueError(f"stage names repeat: {stages}")
    return [frozenset(c) for k in range(len(stages) + 1) for c in combinations(stages, k)]


def label(subset: Iterable[str]) -> str:
    """The stages of ``subset`` sorted and joined with ``+``; ``none`` for the empty set."""
    names = sorted(subset)
    return "+".join(names) if names else "none"


@dataclass(frozen=True)
class Decomposition:
    """``moebius[S]`` for every subset ``S``, ``shapley[s]`` for every stage ``s``, and the end
    points ``total = v(N)`` (every stage MPM) and ``floor = v({})`` (every stage exact)."""

    stages: tuple
    moebius: dict
    shapley: dict
    total: object
    floor: object

    @property
    def gap(self):
        """``v(N) - v({})``: what the Shapley values add up to."""
        return self.total - self.floor

    def interactions(self) -> dict:
        """The Moebius terms of order two and higher."""
        return {S: m for S, m in self.moebius.items() if len(S) >= 2}


def _check(v: Mapping, stages: tuple) -> None:
    missing = [label(S) for S in subsets(stages) if S not in v]
    if missing:
        raise ValueError(f"v is missing {len(missing)} of the {2 ** len(stages)} subsets: {', '.join(missing)}")
    extra = [label(S) for S in v if not set(S) <= set(stages)]
    if extra:
        raise ValueError(f"v has subsets with unknown stages: {', '.join(extra)}")


def decompose(v: Mapping, stages: Iterable[str]) -> Decomposition:
    """Moebius terms and Shapley values of ``v`` (``{frozenset of MPM stages: error}``, every
    subset of ``stages`` present; values numbers or equal-shape arrays)."""
    stages = tuple(stages)
    _check(v, stages)
    all_subsets = subsets(stages)
    value = {S: np.asarray(v[S], dtype=float) for S in all_subsets}
    moebius = {}
    for S in all_subsets:
        terms = [(-1) ** (len(S) - len(T)) * value[T] for T in all_subsets if T <= S]
        moebius[S] = _sum(terms)
    shapley = {s: _sum([moebius[S] / len(S) for S in all_subsets if s in S]) for s in stages}
    total, floor = (_number_or_array(value[S]) for S in (frozenset(stages), frozenset()))
    return Decomposition(stages, _unwrap(moebius), _unwrap(shapley), total, floor)


def shapley_by_orders(v: Mapping, stages: Iterable[str]) -> dict:
    """Shapley values from their definition: the marginal error ``v(B + s) - v(B)`` of each
    stage, with ``B`` the stages before it, averaged over every order of the stages."""
    stages = tuple(stages)
    _check(v, stages)
    out = {s: 0.0 for s in stages}
    for order in permutations(stages):
        before = frozenset()
        for s in order:
            out[s] = out[s] + (np.asarray(v[before | {s}], float) - np.asarray(v[before], float))
            before = before | {s}
    n = factorial(len(stages))
    return {s: _number_or_array(value / n) for s, value in out.items()}


def _sum(terms: list) -> np.ndarray:
    """Sum in the fixed order of the subsets, point by point: a field's sum at a point is the
    scalar sum of its values there, to the last bit."""
    return reduce(np.add, terms)


def _number_or_array(a: np.ndarray):
    return float(a) if a.ndim == 0 else a


def _unwrap(d: dict) -> dict:
    return {k: _number_or_array(a) for k, a in d.items()}


def share_changes(shapley: list[dict], reference: list[dict],
                  key=("problem", "h", "basis", "norm", "stage")) -> list[dict]:
    """Two decompositions of the same runs made with two arithmetics (a budget's Shapley rows and
    its rerun's, each with ``share``, ``mpm_error`` = v(N) and ``exact_error`` = v({})): per row
    present in both, both values (the reference's as ``*_numpy``: the budget's reference arithmetic is
    the numpy step) and the share's change in percentage points, ``100 (share - share_numpy)``: how far
    round-off, grown over the runs, moves the decomposition."""
    at = {tuple(r[k] for k in key): r for r in reference}
    out = []
    for r in shapley:
        x = at.get(tuple(r[k] for k in key))
        if x is not None:
            out.append({**{k: r[k] for k in key}, "share": r["share"], "share_numpy": x["share"],
                        "change_pp": 100 * (r["share"] - x["share"]), "mpm_error": r["mpm_error"],
                        "mpm_error_numpy": x["mpm_error"], "exact_error": r["exact_error"],
                        "exact_error_numpy": x["exact_error"]})
    return out
