"""The budget study's claims: E1 (the error budget over every combination of the stages, on Sod and
on Burgers) and E2 (the bases), from ``budget/shapley``, ``budget/roundoff`` and ``budget/bases``."""

from __future__ import annotations

import math

from mpm_fem.measure.claims.base import Criterion, Tables, claim
from mpm_fem.measure.claims.rows import CONVERGING_ORDER, FLOOR_ORDER, num, select
from mpm_fem.measure.schema import BUDGET_BASES, BUDGET_ROUNDOFF, BUDGET_SHAPLEY

#: E1: a stage dominates when its Shapley share of v(all MPM) - v(all exact) is at least DOMINANT;
#: the shares close when they add up to one within CLOSURE (the CSV keeps six digits).
DOMINANT, CLOSURE = 0.5, 1e-4
# E2: a basis keeps converging with a last-refinement order of the particle density L1 above C11's
# CONVERGING_ORDER, and P1 has levelled off below C11's FLOOR_ORDER.
SHAPLEY = BUDGET_SHAPLEY.name


def _trend(shares: list[float]) -> str:
    steps = [b - a for a, b in zip(shares, shares[1:], strict=False)]
    if not steps:
        return "one mesh"
    return "grows as h shrinks" if all(d > 0 for d in steps) else "falls as h shrinks" if all(d < 0 for d in steps) \
        else "varies with h"


def budget_verdicts(rows: list[dict], norm: str) -> tuple[dict, bool]:
    """Per basis, at the finest mesh: the stages ranked by Shapley share, the dominant one (the
    largest, when it reaches DOMINANT), the shares of the largest from the coarsest mesh to the
    finest; and whether the shares of every mesh add up to one."""
    out, closes = {}, True
    for basis in dict.fromkeys(r["basis"] for r in rows):
        sub = select(rows, basis=basis, norm=norm)
        hs = sorted({num(r, "h") for r in sub}, reverse=True)
        share = {h: {r["stage"]: num(r, "share") for r in sub if num(r, "h") == h} for h in hs}
        closes &= all(abs(sum(s.values()) - 1) <= CLOSURE for s in share.values())
        ranked = sorted(share[hs[-1]].items(), key=lambda kv: -kv[1])
        out[basis] = {"h": hs[-1], "ranked": ranked, "dominant": ranked[0][0] if ranked[0][1] >= DOMINANT else None,
                      "shares": [share[h].get(ranked[0][0], math.nan) for h in hs]}
    return out, closes


def _e1_text(basis: str, f: dict) -> str:
    """``mpm at h = 0.0025: projection 326% (136% -> 326%, grows as h shrinks); compensated by mass -180%``."""
    (top, v), second = f["ranked"][0], f["ranked"][1]
    head = (f"{top} {v:.0%}" if f["dominant"] else f"shared: {top} {v:.0%} and {second[0]} {second[1]:.0%}")
    also = [f"{s} {x:.0%}" for s, x in f["ranked"][1:] if x >= DOMINANT]
    low = f["ranked"][-1]
    return (f"{basis} at h = {f['h']:g}: {head} ({' -> '.join(f'{x:.0%}' for x in f['shares'])}, {_trend(f['shares'])})"
            + (f", also above half {', '.join(also)}" if also and f["dominant"] else "")
            + (f"; compensated by {low[0]} {low[1]:.0%}" if low[1] < 0 else ""))


def _e1(problem: str) -> Criterion:
    def criterion(t: Tables) -> tuple[str, str]:
        """The sixteen combinations of the four stages in MPM or exact form give each stage's Shapley
        value: its main effect plus an equal share of every interaction it is part of. A negative value
        says that the stage's MPM form compensates the others on average."""
        rows = select(t[SHAPLEY], problem=problem)
        norms = list(dict.fromkeys(r["norm"] for r in rows))
        found, closes = budget_verdicts(rows, norms[0])
        parts = [_e1_text(basis, f) for basis, f in found.items()]
        for norm in norms[1:]:
            other, ok = budget_verdicts(rows, norm)
            closes &= ok
            parts.append(f"{norm} L1: " + ", ".join(f"{b} {f['ranked'][0][0]} {f['ranked'][0][1]:.0%}"
                                                    for b, f in other.items()))
        dominated = sum(f["dominant"] is not None for f in found.values())
        verdict = ("refuted" if not closes else "confirmed" if dominated == len(found) else "partly")
        return verdict, f"{norms[0]} L1, largest Shapley share: " + "; ".join(parts) + (
            "" if closes else "; the shares do not add up to one") + _roundoff_text(t, problem)
    return criterion


ROUNDOFF = BUDGET_ROUNDOFF.name


def _roundoff_text(t: Tables, problem: str) -> str:
    """How far round-off moves the shares (``budget/roundoff``, where the budget ran on both
    arithmetics): the largest change of any share per mesh, in percentage points; informative, not
    part of the verdict."""
    rows = select(t.get(ROUNDOFF) or [], problem=problem)
    if not rows:
        return ""
    hs = sorted({num(r, "h") for r in rows}, reverse=True)
    worst = [max(abs(num(r, "change_pp")) for r in rows if num(r, "h") == h) for h in hs]
    bases = ", ".join(dict.fromkeys(r["basis"] for r in rows))
    return (f"; round-off ({bases}, the numpy step's arithmetic against the fused step's, `{ROUNDOFF}.csv`) moves "
            f"the shares by at most {' / '.join(f'{w:.2g}' for w in worst)} percentage points at h = "
            + " / ".join(f"{h:g}" for h in hs))


_E1_RULE = (f"the Shapley shares of every mesh add up to one (within {CLOSURE:g}) and at the finest mesh one stage "
            f"carries at least {DOMINANT:.0%} of v(all MPM) - v(all exact) for every basis -> confirmed; for some "
            "bases the error is shared -> partly; shares that do not add up -> refuted")
for _problem in ("sod", "burgers"):
    claim("E1", source="the four error sources of the slides (projection, FE + mass lumping, interpolation, time)",
          tables=(SHAPLEY,), study="budget", problem=_problem, thresholds=_E1_RULE)(_e1(_problem))


@claim("E2", source="whether a smooth basis removes the stagnation of C11", tables=(BUDGET_BASES.name,), study="budget",
       thresholds=f"P1's particle density L1 order over the last refinement is below {FLOOR_ORDER} and a C1 basis "
                  f"keeps it above {CONVERGING_ORDER} -> confirmed; a C1 basis above P1 -> partly; none above P1 -> "
                  "refuted; P1 not levelled off -> differs")
def _e2(t: Tables) -> tuple[str, str]:
    rows = select(t[BUDGET_BASES.name], ok="True")
    last = {}
    for basis in dict.fromkeys(r["basis"] for r in rows):
        sub = sorted(select(rows, basis=basis), key=lambda r: -num(r, "h"))[-2:]
        if len(sub) == 2:
            last[basis] = ({k: math.log(num(sub[0], k) / num(sub[1], k)) / math.log(num(sub[0], "h") / num(sub[1], "h"))
                            for k in ("particles_L1", "nodes_L1")}
                           | {"h": sub[1]["h"], "noise": num(sub[1], "plateau_noise")})
    if "mpm" not in last or len(last) < 2:
        return "not measured", "fewer than two meshes or no point-mass row"
    p1, smooth = last["mpm"]["particles_L1"], {b: v["particles_L1"] for b, v in last.items() if b != "mpm"}
    verdict = ("differs" if p1 >= FLOOR_ORDER else "confirmed" if max(smooth.values()) > CONVERGING_ORDER
               else "partly" if max(smooth.values()) > p1 else "refuted")
    return verdict, ("last-refinement order of the particle density L1: "
                     + ", ".join(f"{b} {v['particles_L1']:.2f}" for b, v in last.items())
                     + "; nodes " + ", ".join(f"{b} {v['nodes_L1']:.2f}" for b, v in last.items())
                     + f"; plateau std(v_p) at h = {last['mpm']['h']}: "
                     + ", ".join(f"{b} {v['noise']:.3g}" for b, v in last.items()))

