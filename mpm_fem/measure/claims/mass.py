"""C15 from the error budget: is the mass stage (the FE solve with the lumped mass) an error source?

For each run of the point-mass basis (``budget/subsets``: one basis, norm, mesh, and particles per
cell, layout and seed where recorded), with ``v(S)`` the error with the stages of ``S`` in MPM form:

- ``alone``: ``m({mass}) / v(N)``, what the MPM mass stage alone adds to the all-exact error, as a
  fraction of the all-MPM error ``v(N)`` (the all-exact error can be near zero, Burgers');
- ``tangled``: the total magnitude of the interactions the mass stage is part of (the Moebius terms of
  two stages or more that contain it) over ``|m({mass})|``;
- ``shapley``: its Shapley value over ``v(N) - v({})``.

Per norm, mesh and particles per cell the runs (layouts and seeds) give ranges. A case is a *source*
when ``alone`` is at least SOURCE_SHARE over every run, *separable* when ``tangled`` is at most
ATTRIBUTABLE over every run. The consistent/lumped comparison (:mod:`.shared`) is a second reading;
it decides where the direct one cannot: when no case is separable (the direct reading is swamped by
the interactions) and the consistent mass raises every judged method's error on every mesh (ratio
above 1 / LUMPING_BAND: :func:`~.shared.consistent_raises`), lumping compensates: ``differs``.
"""

from __future__ import annotations

import math

from mpm_fem.measure.claims.base import CONFIRMED, DIFFERS, NOT_MEASURED, PARTLY, REFUTED, Finding, Tables, short
from mpm_fem.measure.claims.rows import select
from mpm_fem.measure.claims.rules import rule
from mpm_fem.measure.claims.shared import LUMPING_BAND, consistent_raises, lumping_claim
from mpm_fem.measure.claims.stages import SUBSETS, decomposition, runs
from mpm_fem.measure.spread import Spread, spread

MASS, BASIS = "mass", "mpm"
SOURCE_SHARE, ATTRIBUTABLE = rule("SOURCE_SHARE"), rule("ATTRIBUTABLE")

MASS_RULE = (f"from the error budget (budget/subsets, the point-mass basis): the mass stage in MPM form alone raises "
             f"the all-exact error by at least {SOURCE_SHARE:.0%} of the all-MPM error over every run (layouts, "
             "seeds) -> a source; its "
             f"interactions with the other stages at most {ATTRIBUTABLE:g}x its own effect -> separable. A separable "
             "source on every norm, mesh and particles per cell -> confirmed; a source on some, or a source whose "
             "interactions exceed it -> partly; alone it lowers the error on every case -> differs (it "
             "compensates); otherwise -> refuted. The consistent/lumped comparison beside, as a second reading, which "
             "decides where the direct reading is swamped (separable on no case): the consistent mass raising the "
             f"error of every judged method on every mesh (consistent/lumped above {1 / LUMPING_BAND:.3g}) -> "
             "differs (lumping compensates)")


def mass_stage(rows: list[dict]) -> dict[tuple, dict[str, Spread]]:
    """``{(norm, h, ppc): {"alone", "tangled", "shapley": Spread}}`` over the runs of the point-mass
    basis in one problem's ``budget/subsets`` rows (module docstring)."""
    found: dict[tuple, dict[str, list]] = {}
    for (basis, norm, h, run), sub in runs(rows).items():
        d = decomposition(sub)
        if basis != BASIS or d is None:
            continue
        main = d.moebius[frozenset({MASS})]
        tangled = sum(abs(m) for s, m in d.interactions().items() if MASS in s)
        ppc = run.split(",")[0] if "ppc" in run else ""
        at = found.setdefault((norm, h, ppc), {"alone": [], "tangled": [], "shapley": []})
        at["alone"].append(main / d.total if d.total else math.nan)
        at["tangled"].append(tangled / abs(main) if main else math.inf)
        at["shapley"].append(d.shapley[MASS] / d.gap if d.gap else math.nan)
    return {k: {q: spread(v) for q, v in at.items()} for k, at in found.items()}


#: C15's second reading (consistent against lumped mass) in words, by its verdict (shared.lumping_claim).
_SECOND_READING = {CONFIRMED: "with the consistent mass the error is smaller on every mesh",
                   PARTLY: "with the consistent mass the error is smaller on some meshes",
                   DIFFERS: "yet with the consistent mass the error is larger (lumping compensates)",
                   REFUTED: "and the consistent mass leaves the error as it is"}


def mass_finding(t: Tables, problem: str, ratios: dict[str, dict[str, float]] | None, judged: tuple[str, ...],
                 sentence_name: str, missing: str = "") -> Finding:
    """C15 on ``problem`` from the budget's mass stage, with the consistent/lumped ``ratios`` (``{method:
    {h: consistent / lumped error}}``, the methods of ``judged`` judged; ``None`` when their table is
    missing, said by ``missing``) as the second reading (module docstring)."""
    second = lumping_claim(ratios, judged) if ratios is not None else (NOT_MEASURED, missing)
    second_verdict, second_evidence = second
    raised = consistent_raises(ratios or {}, judged)
    cases = mass_stage(select(t[SUBSETS], problem=problem))
    if not cases:
        return Finding(NOT_MEASURED, f"no complete budget of the {BASIS} basis on {problem}")
    source = {k: c["alone"].above(SOURCE_SHARE) for k, c in cases.items()}
    separable = {k: c["tangled"].below(ATTRIBUTABLE) or c["tangled"].hi == ATTRIBUTABLE for k, c in cases.items()}
    lowers = all(c["alone"].below(0) for c in cases.values())
    n, hits = len(cases), sum(source.values())
    swamped_and_raised = not any(separable.values()) and raised.everywhere
    verdict = (CONFIRMED if hits == n and all(separable.values()) else DIFFERS if swamped_and_raised else
               PARTLY if hits else DIFFERS if lowers else REFUTED)
    table = tuple({"norm": norm, "h": f"{h:g}", "ppc": ppc or "study's", "mass alone / all-MPM":
                   _text(c["alone"], ".2f"), "its interactions / its effect": _text(c["tangled"], ".2g"),
                   "Shapley / gap": _text(c["shapley"], ".2f")} for (norm, h, ppc), c in cases.items())
    alone = [c["alone"] for c in cases.values()]
    tangled = [c["tangled"] for c in cases.values()]
    lo, hi = min(a.lo for a in alone), max(a.hi for a in alone)
    t_lo, t_hi = _times(min(x.lo for x in tangled)), _times(max(x.hi for x in tangled))
    methods = " and ".join(judged)
    raised_text = (f"on {raised.meshes} of {raised.total} meshes the consistent mass raises MPM's error "
                   f"{raised.lo:.2f}-{raised.hi:.2f}x ({methods}, each above {1 / LUMPING_BAND:.3g}x): lumping "
                   "compensates")
    direct = (f"the mass stage alone adds {lo:.0%} to {hi:.0%} of the all-MPM error to the all-exact one (a "
              f"source on {hits} of {n} norms and meshes, at least {SOURCE_SHARE:.0%}); its interactions are "
              f"{t_lo}-{t_hi}x its own effect (separable at most {ATTRIBUTABLE:g}x on "
              f"{sum(separable.values())} of {n}); "
              + "; ".join(f"{r['norm']} h = {r['h']}: alone {r['mass alone / all-MPM']}, interactions "
                          f"{r['its interactions / its effect']}, Shapley {r['Shapley / gap']}" for r in table))
    second_text = f"Second reading, consistent against lumped mass ({second_verdict}): {second_evidence}"
    if swamped_and_raised and verdict == DIFFERS:
        evidence = (f"{raised_text}; the direct reading is swamped (separable on none of {n} norms and meshes): "
                    f"{direct}. {second_text}")
        sentence = (f"on {sentence_name} the consistent mass raises MPM's error {raised.lo:.2f} to {raised.hi:.2f} "
                    f"times on {raised.meshes} of {raised.total} meshes: lumping compensates; in the error budget "
                    f"the lumped-mass FE stage's own effect ({lo:.0%} to {hi:.0%} of MPM's error) is swamped by "
                    f"its interactions with the other stages ({t_lo} to {t_hi} times that effect)")
        key = short(f"on {sentence_name} the consistent mass raises MPM's error {raised.lo:.2f} to {raised.hi:.2f} "
                    f"times on {raised.meshes} of {raised.total} meshes: lumping compensates")
        return Finding(verdict, evidence, sentence, table, key=key)
    evidence = f"{direct}. {second_text}"
    if hits:
        sentence = (f"on {sentence_name} the lumped-mass FE stage alone adds {lo:.0%} to {hi:.0%} of MPM's error to "
                    f"the error with every stage exact, but its interactions with the other stages are {t_lo} "
                    f"to {t_hi} times that effect")
        key = short(f"on {sentence_name} the lumped-mass FE stage alone adds {lo:.0%} to {hi:.0%} of MPM's error; its "
                    f"interactions are {t_lo} to {t_hi} times that", sentence.split(", but ")[0])
    else:
        sentence = (f"on {sentence_name} the lumped-mass FE stage alone changes the all-exact error by {lo:.0%} to "
                    f"{hi:.0%} of MPM's error")
        key = short(sentence)
    sentence += "; " + _SECOND_READING.get(second_verdict, "consistent against lumped mass not measured")
    if raised.meshes and second_verdict == PARTLY:
        sentence += f" (on {raised.meshes} of {raised.total} meshes the consistent mass raises MPM's error)"
    return Finding(verdict, evidence, sentence, table, key=key)


def _times(x: float) -> str:
    """A factor in two significant digits, a whole number where that would need an exponent (``6.3``, ``650``)."""
    short = f"{x:.2g}"
    return f"{x:.0f}" if "e+" in short else short


def _text(s: Spread, fmt: str) -> str:
    """One number when the runs agree (one run), else ``mean [lo, hi]``."""
    return format(s.mean, fmt) if s.lo == s.hi else s.text(fmt)
