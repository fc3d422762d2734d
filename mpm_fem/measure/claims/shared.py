"""What the Sod and the Burgers claims share: the criteria of C3 (particles per cell) and C15 (mass
lumping), each judged per problem (``sod/ppc``, ``burgers/ppc``; ``sod/mass``, ``burgers/lumping``)."""

from __future__ import annotations

import math
from typing import NamedTuple

from mpm_fem.measure.claims.base import DIFFERS, REFUTED
from mpm_fem.measure.claims.rows import count_verdict, saturation, span
from mpm_fem.measure.claims.rules import rule
from mpm_fem.measure.source import OPTIMAL_PPC

#: C3: the fewest particles per cell within SATURATION of the smallest error.
SATURATION = rule("SATURATION")
#: C15: the error with the consistent mass over the error with the lumped mass, all else equal, of one
#: method on one mesh: lumping is a source of error where the consistent mass is clearly better (ratio
#: below LUMPING_BAND), compensating where it is clearly worse (above 1 / LUMPING_BAND), neutral between.
LUMPING_BAND = rule("LUMPING_BAND")


def ppc_claim(groups: dict[str, list[dict]], keys: tuple[str, ...]) -> tuple[str, str]:
    """C3 on one problem: per group (method, mesh) and error ``key``, the fewest N_p near the best."""
    found = {f"{g}, {k.split('_')[0]}": saturation(rows, k, within=SATURATION)
             for g, rows in groups.items() for k in keys}
    hits = sum(OPTIMAL_PPC[0] <= n <= OPTIMAL_PPC[1] for n in found.values())
    return count_verdict(hits, len(found), DIFFERS), (
        f"N_p within {SATURATION:.0%} of the smallest error: " + "; ".join(f"{g}: {n}" for g, n in found.items()))


PPC_RULE = (f"the fewest particles per cell within {SATURATION:.0%} of the smallest error lies in "
            f"[{OPTIMAL_PPC[0]}, {OPTIMAL_PPC[1]}] on every mesh and error -> confirmed, on some -> partly, "
            "on none -> differs")


def lumping_sign(ratios) -> str:
    """What lumping does in one method, from its consistent/lumped ratios on every mesh: ``source of
    error`` (every ratio below LUMPING_BAND), ``compensating`` (every ratio above 1 / LUMPING_BAND),
    ``neutral`` (every ratio between), ``mixed`` (the meshes disagree); ``not measured`` without a ratio."""
    r = [x for x in ratios if math.isfinite(x)]
    if not r:
        return "not measured"
    signs = {"source of error" if x < LUMPING_BAND else "compensating" if x > 1 / LUMPING_BAND else "neutral"
             for x in r}
    return signs.pop() if len(signs) == 1 else "mixed"


def lumping_claim(ratios: dict[str, dict[str, float]], judged: tuple[str, ...]) -> tuple[str, str]:
    """C15 on one problem from ``ratios`` (``{method: {h: consistent / lumped error}}``): each (method
    of ``judged``, mesh) whose ratio is below LUMPING_BAND is a case that holds; the other methods
    (the fixed-mesh FEM) are shown beside. With no case holding, ``differs`` when lumping compensates
    on some judged case, ``refuted`` when it is neutral on all."""
    cases = [x for m in judged for x in ratios.get(m, {}).values() if math.isfinite(x)]
    hits = sum(x < LUMPING_BAND for x in cases)
    verdict = count_verdict(hits, len(cases), DIFFERS if any(x > 1 / LUMPING_BAND for x in cases) else REFUTED)

    def text(m: str) -> str:
        r = ratios[m]
        return (f"{m}: {lumping_sign(r.values())} (consistent/lumped {span(r.values())} at h = "
                f"{span([float(h) for h in r], 'g')})")

    beside = [m for m in ratios if m not in judged]
    return verdict, ("; ".join(text(m) for m in judged if m in ratios)
                     + (f"; beside, on the same meshes: {'; '.join(text(m) for m in beside)}" if beside else "")
                     + f"; source of error below {LUMPING_BAND:g}, compensating above {1 / LUMPING_BAND:.3g}")


class Raised(NamedTuple):
    """Where the consistent mass raises the judged methods' error: on ``meshes`` of ``total`` meshes every
    judged method's consistent/lumped ratio is above 1 / LUMPING_BAND (lumping compensates there), the
    judged ratios spanning ``lo`` to ``hi``."""

    meshes: int
    total: int
    lo: float
    hi: float

    @property
    def everywhere(self) -> bool:
        return self.total > 0 and self.meshes == self.total


def consistent_raises(ratios: dict[str, dict[str, float]], judged: tuple[str, ...]) -> Raised:
    """:class:`Raised` of ``ratios`` (``{method: {h: consistent / lumped error}}``) over the methods of
    ``judged``: a mesh counts when every judged method has a finite ratio there and each is above
    1 / LUMPING_BAND."""
    present = [m for m in judged if ratios.get(m)]
    at: dict[float, list[float]] = {}
    for m in present:
        for h, x in ratios[m].items():
            at.setdefault(float(h), []).append(x)
    measured = {h: xs for h, xs in at.items() if len(xs) == len(present) and all(math.isfinite(x) for x in xs)}
    values = [x for xs in measured.values() for x in xs]
    raised = sum(all(x > 1 / LUMPING_BAND for x in xs) for xs in measured.values())
    return Raised(raised, len(measured), min(values, default=math.nan), max(values, default=math.nan))


LUMPING_RULE = (f"the error with the consistent mass over that with the lumped mass, all else equal, on every mesh: "
                f"lumping is a source of error where the ratio is below {LUMPING_BAND:g} (the consistent mass is "
                f"clearly better), compensating where it is above {1 / LUMPING_BAND:.3g} (clearly worse), neutral "
                "between. Judged on MPM, the source's method (the fixed-mesh FEM shown beside): a source on every "
                "mesh -> confirmed, on some -> partly; on none, compensating on some -> differs; neutral on every "
                "mesh -> refuted")
