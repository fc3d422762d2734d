"""The 2D claims D1-D7: does the 1D error analysis survive on the plane? From ``plane/*``, written by
``studies/plane.py``.

A *run* is one particle setting (particles per cell per axis ``ppc``, layout and seed: the regular
layout is seed 0) of one basis on one solution; a *series* the runs of one basis and ``ppc`` over the
meshes. Between two successive meshes ``h_c > h_f`` a run's order is

    p = log(E(h_c) / E(h_f)) / log(h_c / h_f),     E the particle displacement L2 at T.

A run *converges* over the last refinement when its last ``p >= CONVERGING_ORDER``, *grows* when ``p <
GROWTH_ORDER`` or when it stops on the finest mesh (a particle inverts: the error has no bound) after
running on the coarser one, and *plateaus* between. A series is judged on the meshes every one of its
runs has, with PLANE_MIN_RUNS runs on PLANE_MIN_MESHES meshes; its behaviour is the one its runs share,
else it is *mixed* (the counts named).
"""

from __future__ import annotations

import math
import statistics

from mpm_fem.measure.claims.base import CONFIRMED, DIFFERS, NOT_MEASURED, PARTLY, REFUTED, Finding, Tables, claim, short
from mpm_fem.measure.claims.lumping import COUNTED, FMPM, recovered_by
from mpm_fem.measure.claims.rows import CONVERGING_ORDER, GROWTH_ORDER, ORDER_TOLERANCE, count_verdict, num, select
from mpm_fem.measure.claims.rules import rule
from mpm_fem.measure.claims.shared import LUMPING_BAND, lumping_sign
from mpm_fem.measure.spread import spread

GROWTH, STAGES_T, SHAPLEY, MASS, FEM, TIME = (f"plane/{t}" for t in ("growth", "stages", "shapley", "mass", "fem",
                                                                     "time"))
MIN_RUNS, MIN_MESHES = int(rule("PLANE_MIN_RUNS")), int(rule("PLANE_MIN_MESHES"))
SEPARATE, E3_FACTOR, FMPM_RECOVERS = rule("SEPARATE"), rule("E3_FACTOR"), rule("FMPM_RECOVERS")
TIME_ORDER, TIME_NEGLIGIBLE = rule("TIME_ORDER_2D"), rule("TIME_NEGLIGIBLE")
SOLUTIONS = ("axis-1e-4", "axis-0.05", "vortex")
CROSSING, CONTROL = "axis-0.05", "axis-1e-4"
SMOOTH = ("bspline", "cubic")
STAGES = ("projection", "mass", "interpolation", "time")


def _ok(row: dict) -> bool:
    return str(row.get("ok", "")) in ("True", "true", "1")


def runs_of(rows: list[dict], **where) -> dict[tuple, list[tuple[float, float]]]:
    """``{(layout, seed): [(h, E), ...]}`` (coarsest first; ``E`` NaN for a run that stopped) of the rows
    matching ``where``."""
    out: dict = {}
    for r in select(rows, **where):
        out.setdefault((r["layout"], str(r["seed"])), []).append((num(r, "h"), num(r, "L2") if _ok(r) else math.nan))
    return {k: sorted(v, reverse=True) for k, v in out.items()}


def orders(points: list[tuple[float, float]]) -> list[float]:
    """The successive orders of one run's ``[(h, E)]`` (coarsest first): ``-inf`` where the finer run stopped
    and the coarser one ran (no bound: it grows), NaN where the coarser one stopped."""
    out = []
    for (hc, ec), (hf, ef) in zip(points, points[1:], strict=False):
        if not math.isfinite(ec):
            out.append(math.nan)
        elif not math.isfinite(ef):
            out.append(-math.inf)
        else:
            out.append(math.log(ec / ef) / math.log(hc / hf))
    return out


def behaviour(p: float) -> str:
    """``converges``, ``plateau`` or ``grows`` of one order (module docstring); ``stop on both meshes`` for NaN
    (the coarser run stopped too: a particle inverted on both)."""
    if math.isnan(p):
        return "stop on both meshes"
    return "converges" if p >= CONVERGING_ORDER else "grows" if p < GROWTH_ORDER else "plateau"


def series(rows: list[dict], **where) -> dict:
    """One series: ``runs`` and ``meshes``, ``judged`` (PLANE_MIN_RUNS runs on PLANE_MIN_MESHES meshes),
    the last orders over the runs (``last``: a :class:`~mpm_fem.measure.spread.Spread` of the finite ones,
    ``-inf`` counted as growing), each run's behaviour counted (``counts``) and the series' ``verdict``
    (the behaviour every run shares, or ``mixed``)."""
    runs = runs_of(rows, **where)
    common = set.intersection(*({h for h, _ in v} for v in runs.values())) if runs else set()
    runs = {k: [(h, e) for h, e in v if h in common] for k, v in runs.items()}
    meshes = len(common)
    last = [orders(v)[-1] for v in runs.values() if len(v) > 1]
    counts: dict = {}
    for p in last:
        counts[behaviour(p)] = counts.get(behaviour(p), 0) + 1
    verdict = next(iter(counts)) if len(counts) == 1 else "mixed"
    return {"runs": len(runs), "meshes": meshes, "judged": len(runs) >= MIN_RUNS and meshes >= MIN_MESHES,
            "last": spread(p for p in last if math.isfinite(p)), "stopped": sum(p == -math.inf for p in last),
            "counts": counts, "verdict": verdict, "finest": min((v[-1][0] for v in runs.values()), default=math.nan)}


def _order_text(s: dict) -> str:
    last = s["last"]
    text = (f"{last.mean:.2f} [{last.lo:.2f}, {last.hi:.2f}]" if last.n > 1 else f"{last.mean:.2f} (one run)"
            if last.n else "-")
    if s["stopped"]:
        text += f", {s['stopped']} stopped (a particle inverted)"
    return text


def _counts_text(counts: dict) -> str:
    return ", ".join(f"{n} {b}" for b, n in counts.items())


def _behaviour_text(s: dict) -> str:
    """The series' behaviour, or for a mixed one its runs by behaviour."""
    return s["verdict"] if s["verdict"] != "mixed" else _counts_text(s["counts"])


def growth_table(rows: list[dict], solution: str) -> tuple[dict, ...]:
    """One row per basis and particles per cell of ``solution``: runs, meshes, the last order over the runs
    and the behaviour."""
    out = []
    for basis in dict.fromkeys(r["basis"] for r in select(rows, solution=solution)):
        for ppc in sorted({int(num(r, "ppc")) for r in select(rows, solution=solution, basis=basis)}):
            s = series(rows, solution=solution, basis=basis, ppc=ppc)
            out.append({"basis": basis, "ppc": f"{ppc}x{ppc}", "runs": s["runs"], "meshes": s["meshes"],
                        "finest h": f"1/{round(1 / s['finest'])}", "last order": _order_text(s),
                        "behaviour": s["verdict"] if s["judged"] else f"{s['verdict']} (not judged)",
                        "runs by behaviour": _counts_text(s["counts"])})
    return tuple(out)


def _d1(solution: str):
    def criterion(t: Tables) -> Finding:
        """The particle displacement error of every basis under refinement on the regular and five jittered
        layouts: the last order (between the two finest meshes) of each run says whether it converges,
        plateaus or grows. The 1D finding was that point-mass MPM's error grows and the smooth B-splines'
        does not; the verdict says whether both parts hold on this solution."""
        rows = t[GROWTH]
        judged = {(b, p): s for b in dict.fromkeys(r["basis"] for r in select(rows, solution=solution))
                  for p in sorted({int(num(r, "ppc")) for r in select(rows, solution=solution)})
                  for s in [series(rows, solution=solution, basis=b, ppc=p)] if s["judged"]}
        p1 = {p: s for (b, p), s in judged.items() if b == "mpm"}
        if not p1:
            return Finding(NOT_MEASURED, f"no point-mass series with {MIN_RUNS} runs on {MIN_MESHES} meshes")
        grows = [p for p, s in p1.items() if s["verdict"] == "grows"]
        some = [p for p, s in p1.items() if s["counts"].get("grows")]
        smooth_ok = all(judged[(b, p)]["counts"].get("grows", 0) == 0 for b in SMOOTH for p in grows
                        if (b, p) in judged)
        verdict = (CONFIRMED if grows and len(grows) == len(p1) and smooth_ok else PARTLY if some else DIFFERS)
        table = growth_table(rows, solution)
        evidence = "; ".join(f"{b} {p}x{p}: last order {_order_text(s)} over {s['runs']} runs to h = "
                             f"1/{round(1 / s['finest'])}, {_behaviour_text(s)}" for (b, p), s in judged.items())
        first = p1[min(p1)]
        smooth = {b: judged.get((b, min(p1))) for b in SMOOTH}
        sentence = (f"on the {solution} solution point-mass MPM's last order at {min(p1)}x{min(p1)} per cell is "
                    f"{_order_text(first)} ({_counts_text(first['counts'])} of {first['runs']} runs), the cubic "
                    f"B-spline's {_order_text(smooth['cubic']) if smooth['cubic'] else '-'}; P1 grows on "
                    f"{first['counts'].get('grows', 0)} of {first['runs']} runs")
        rest = _counts_text({k: n for k, n in first["counts"].items() if k != "grows"})
        key = short(sentence, f"{solution}: P1 grows on {first['counts'].get('grows', 0)} of {first['runs']} runs"
                              + (f", {rest}" if rest else "") + f"; last order {_order_text(first)}")
        return Finding(verdict, evidence, sentence, table, key=key)
    return criterion


_D1_RULE = (f"per solution, each series of a basis and particles per cell with {MIN_RUNS} runs on {MIN_MESHES} "
            f"meshes: a run converges when its last order is at least {CONVERGING_ORDER:g}, grows when below "
            f"{GROWTH_ORDER:g} or when it stops on the finest mesh, plateaus between. Point-mass P1 grows on every "
            "run of every judged particle count and the B-splines grow on none there -> confirmed; P1 grows on some "
            "runs -> partly; on none -> differs (the 1D growth is absent)")
for _s in SOLUTIONS:
    claim("D1", source="1D: P1's particle error grows at 4-16 per cell; smooth bases remove the growth",
          tables=(GROWTH,), study="plane", problem=_s, thresholds=_D1_RULE)(_d1(_s))


# ---------------------------------------------------------------- D2: where the growth comes from

def stage_cases(rows: list[dict], solution: str) -> dict:
    """From ``plane/stages`` of ``solution``: per mesh pair (coarse, fine), the runs where all MPM grows,
    and per made-exact subset its orders on those runs and whether it turns each into convergence."""
    mpm = {k: orders(v) for k, v in runs_of(rows, solution=solution, made_exact="none").items()}
    hs = sorted({num(r, "h") for r in select(rows, solution=solution)}, reverse=True)
    out = {}
    for j in range(len(hs) - 1):
        growing = [k for k, p in mpm.items() if len(p) > j and p[j] < GROWTH_ORDER]
        exact = {}
        for made in (*STAGES, "all"):
            mine = {k: orders(v) for k, v in runs_of(rows, solution=solution, made_exact=made).items()}
            got = [mine[k][j] for k in growing if k in mine and len(mine[k]) > j]
            every = [p[j] for p in mine.values() if len(p) > j]
            exact[made] = {"orders": spread(p for p in every if math.isfinite(p)),
                           "turns": bool(growing) and len(got) == len(growing)
                           and all(p >= CONVERGING_ORDER for p in got)}
        out[(hs[j], hs[j + 1])] = {"runs": len(mpm), "growing": len(growing),
                                   "mpm": spread(p[j] for p in mpm.values() if len(p) > j and math.isfinite(p[j])),
                                   "exact": exact}
    return out


def _spread_text(s) -> str:
    return f"{s.lo:.2f}..{s.hi:.2f}" if s.n else "-"


def _pair(hc: float, hf: float) -> str:
    return f"h = 1/{round(1 / hc)} -> 1/{round(1 / hf)}"


@claim("D2", source="1D (E6a): the projection made exact stops the growth (Burgers: converges; Sod: short of it)",
       tables=(STAGES_T,), study="plane", problem=CROSSING,
       thresholds=(f"on each mesh pair where all MPM's order is below {GROWTH_ORDER:g} on some run (every layout run, "
                   f"on {MIN_MESHES} meshes at least): a stage is named where making it alone exact gives "
                   f"an order at least {CONVERGING_ORDER:g} on every run where all MPM grows; a stage named on every "
                   "such pair -> confirmed; on some -> partly; on none -> refuted; no growth -> differs"))
def _d2(t: Tables) -> Finding:
    """Point-mass MPM with each stage of the step made exact alone, and every stage exact, on the regular and
    jittered layouts: a stage is named the source of the growth only where making it exact turns the growth
    into convergence on every layout where all MPM grows. The control (the small amplitude, no cell crossed)
    is shown beside."""
    rows = t[STAGES_T]
    runs = runs_of(rows, solution=CROSSING, made_exact="none")
    if not runs or min(len(v) for v in runs.values()) < MIN_MESHES:
        return Finding(NOT_MEASURED, f"no run of all MPM on {MIN_MESHES} meshes in `{STAGES_T}.csv`")
    cases = stage_cases(rows, CROSSING)
    growth = {pair: c for pair, c in cases.items() if c["growing"]}
    named = {pair: [s for s in STAGES if c["exact"][s]["turns"]] for pair, c in growth.items()}
    every = [s for s in STAGES if growth and all(s in named[p] for p in growth)]
    verdict = (DIFFERS if not growth else CONFIRMED if every else PARTLY if any(named.values()) else REFUTED)
    table = []
    for sol in (CROSSING, CONTROL):
        for pair, c in stage_cases(rows, sol).items():
            table.append({"solution": sol, "meshes": _pair(*pair), "all MPM grows on": f"{c['growing']} of {c['runs']}",
                          "all MPM": _spread_text(c["mpm"]),
                          **{f"{s} exact": _spread_text(c["exact"][s]["orders"]) for s in (*STAGES, "all")},
                          "named": ", ".join(named.get(pair, [])) if sol == CROSSING and pair in growth else ""})
    evidence = "; ".join(f"{_pair(*p)}: all MPM grows on {c['growing']} of {c['runs']} runs "
                         f"({_spread_text(c['mpm'])}), named: {', '.join(named[p]) or 'none'}"
                         for p, c in growth.items()) or "all MPM grows on no run"
    if not growth:
        sentence = f"on the {CROSSING} solution point-mass MPM's error does not grow on the stage-exact meshes"
    else:
        pair, c = next(reversed(growth.items()))
        best = max(STAGES, key=lambda s: c["exact"][s]["orders"].lo if c["exact"][s]["orders"].n else -math.inf)
        sentence = (f"on the {CROSSING} solution point-mass MPM's error grows on {c['growing']} of {c['runs']} runs "
                    f"over {_pair(*pair)} (orders {_spread_text(c['mpm'])}); made exact alone, the {best} stage "
                    f"gives orders {_spread_text(c['exact'][best]['orders'])}, every stage exact "
                    f"{_spread_text(c['exact']['all']['orders'])}; a stage alone turns it on "
                    f"{sum(bool(v) for v in named.values())} of {len(named)} mesh pairs")
    terse = (f"P1 grows on {c['growing']} of {c['runs']} runs ({_pair(*pair)}); the {best} stage exact alone: "
             f"{_spread_text(c['exact'][best]['orders'])}") if growth else sentence
    return Finding(verdict, evidence, sentence, tuple(table), key=short(sentence, terse))


# ---------------------------------------------------------------- D3: the budget

@claim("D3", source="1D (E1): the stages separate, and one dominates", tables=(SHAPLEY,), study="plane",
       thresholds=(f"per solution and mesh, the stages separate when the interactions' total magnitude is at most "
                   f"{SEPARATE:g} of the gap |v(all MPM) - v(all exact)|; every solution and mesh -> confirmed, "
                   "some -> partly, none -> refuted; the stage of the largest |Shapley value| named"))
def _d3(t: Tables) -> Finding:
    """The error budget over all 16 subsets of the four stages in MPM form on the two coarsest meshes (point
    mass, 2x2 per cell, regular layout), with the cells crossed (A = 0.05) and the control (A = 1e-4), where
    every particle stays in its cell and the stages should separate."""
    rows = t[SHAPLEY]
    groups = {}
    for r in rows:
        groups.setdefault((r["solution"], num(r, "h")), {})[r["stage"]] = r
    table, hits = [], 0
    for (sol, h), by in sorted(groups.items(), key=lambda k: (k[0][0], -k[0][1])):
        share = num(by[STAGES[0]], "interactions_share")
        top = max(STAGES, key=lambda s: abs(num(by[s], "shapley")))
        hits += share <= SEPARATE
        table.append({"solution": sol, "h": f"1/{round(1 / h)}", "all MPM": f"{num(by[top], 'mpm_error'):.3g}",
                      "all exact": f"{num(by[top], 'exact_error'):.3g}", "interactions / gap": f"{share:.2f}",
                      **{s: f"{num(by[s], 'share'):.2f}" for s in STAGES}, "largest": top})
    verdict = count_verdict(hits, len(table))
    evidence = "; ".join(f"{r['solution']} h = {r['h']}: interactions {r['interactions / gap']} of the gap, largest "
                         f"{r['largest']} (" + ", ".join(f"{s} {r[s]}" for s in STAGES) + ")" for r in table)
    shown = [r for r in table if r["solution"] == CROSSING] or table
    control = [r for r in table if r["solution"] == CONTROL]
    last = shown[-1]
    sentence = (f"on the two coarsest meshes the stages separate on {hits} of {len(table)} budgets; with cells "
                f"crossed the largest Shapley share is the {last['largest']} stage's ({last[last['largest']]} "
                f"of the gap at h = {last['h']}, interactions {last['interactions / gap']})"
                + (f", in the control the {control[-1]['largest']} stage's (interactions "
                   f"{control[-1]['interactions / gap']})" if control else ""))
    terse = (f"the stages separate on {hits} of {len(table)} budgets; the largest share is the {last['largest']} "
             f"stage's ({last[last['largest']]} of the gap)")
    return Finding(verdict, evidence, sentence, tuple(table), key=short(sentence, terse))


# ---------------------------------------------------------------- D4, D5: the grid masses

def _by_mesh(item) -> tuple:
    """Sort key of ``((solution, h), value)``: by solution, then coarsest first."""
    return item[0][0], -item[0][1]


def _mass_errors(t: Tables) -> dict:
    """``{(solution, h): {mass: E}}`` of ``plane/mass`` (finite errors of the runs that ran)."""
    out: dict = {}
    for r in t[MASS]:
        if _ok(r):
            out.setdefault((r["solution"], num(r, "h")), {})[r["mass"]] = num(r, "L2")
    return out


@claim("D4", source="1D (C15): the consistent mass raises MPM's error 1.2-4x: lumping compensates",
       tables=(MASS,), study="plane",
       thresholds=(f"per solution and mesh, MPM's consistent/lumped error ratio above {1 / LUMPING_BAND:.3g}: "
                   f"lumping compensates; below {LUMPING_BAND:g}: a source of error; every case compensating -> "
                   "confirmed, some -> partly, none with some a source -> differs, all neutral -> refuted"))
def _d4(t: Tables) -> Finding:
    """Point-mass MPM with the particle mass matrix solved (consistent) against its row sums (lumped), all else
    equal, on each mesh; the fixed-mesh Q1 FEM's ratio on the same mesh shown beside."""
    errors = _mass_errors(t)
    ratios = {k: e["consistent"] / e["lumped"] for k, e in errors.items() if {"consistent", "lumped"} <= set(e)}
    fem = {}
    for r in t.get(FEM, []):
        if _ok(r):
            fem.setdefault((r["solution"], num(r, "h")), {})[r["mass"]] = num(r, "L2")
    hits = sum(x > 1 / LUMPING_BAND for x in ratios.values())
    below = any(x < LUMPING_BAND for x in ratios.values())
    verdict = count_verdict(hits, len(ratios), DIFFERS if below else REFUTED)
    table = tuple({"solution": s, "h": f"1/{round(1 / h)}", "MPM consistent / lumped": f"{x:.3g}",
                   "FEM consistent / lumped": (f"{fem[(s, h)]['consistent'] / fem[(s, h)]['lumped']:.3g}"
                                               if {"consistent", "lumped"} <= set(fem.get((s, h), {})) else "-"),
                   "reading": lumping_sign([x])} for (s, h), x in sorted(ratios.items(), key=_by_mesh))
    by_solution = {s: [x for (q, _), x in ratios.items() if q == s] for s in dict.fromkeys(s for s, _ in ratios)}
    evidence = "; ".join(f"{s}: {lumping_sign(v)} (consistent/lumped {min(v):.3g}..{max(v):.3g})"
                         for s, v in by_solution.items())
    sentence = (f"in 2D the consistent mass changes point-mass MPM's error by a factor "
                f"{min(ratios.values()):.2f} to {max(ratios.values()):.2f}: lumping compensates on {hits} of "
                f"{len(ratios)} solutions and meshes") if ratios else ""
    terse = (f"the consistent mass changes P1's error {min(ratios.values()):.2f} to {max(ratios.values()):.2f}x; "
             f"lumping compensates on {hits} of {len(ratios)}") if ratios else ""
    return Finding(verdict, evidence or "no ratio", sentence, table, key=short(sentence, terse))


def mass_costs(t: Tables, reference: str = "consistent") -> dict[str, tuple[float, bool]]:
    """Each mass's CPU cost per step over the ``reference`` mass's (the median over the solutions and meshes of
    ``plane/mass``), and whether it ran on the compiled step (the lumped mass, where the table says so)."""
    per: dict = {}
    compiled: dict = {}
    for r in t[MASS]:
        if _ok(r):
            per.setdefault((r["solution"], num(r, "h")), {})[r["mass"]] = num(r, "step_ms")
            compiled[r["mass"]] = str(r.get("compiled", "")) in ("True", "true", "1")
    ratios: dict = {}
    for by in per.values():
        for m, ms in by.items():
            if by.get(reference, 0) > 0:
                ratios.setdefault(m, []).append(ms / by[reference])
    return {m: (statistics.median(v), compiled[m]) for m, v in ratios.items()}


@claim("D5", source="Nairn & Hammerquist (CMAME 2021): FMPM(k) approaches the consistent mass as k grows",
       tables=(MASS,), study="plane",
       thresholds=(f"per solution and mesh, FMPM(k) recovers the consistent mass's accuracy when |E_FMPM(k) / "
                   f"E_consistent - 1| <= {FMPM_RECOVERS:g} for some 2 <= k <= 4 (FMPM(1) is the lumped mass, shown, "
                   "not counted); every case -> confirmed, some -> partly, none -> refuted"))
def _d5(t: Tables) -> Finding:
    """FMPM(k), the truncated series of the particle mass matrix's inverse (k terms, k - 1 extrapolations a
    solve), in the FLIP step of the study, against the consistent mass it approximates; the cost of each mass
    per step against the consistent one's is measured in the same runs (both on the numpy step)."""
    errors = _mass_errors(t)
    table, hits = [], 0
    for (s, h), e in sorted(errors.items(), key=_by_mesh):
        if "consistent" not in e or not any(m in e for m in COUNTED):
            continue
        rel = {m: e[m] / e["consistent"] for m in FMPM if m in e}
        first = recovered_by(rel)
        hits += bool(first)
        table.append({"solution": s, "h": f"1/{round(1 / h)}",
                      "lumped / consistent": f"{e['lumped'] / e['consistent']:.3g}",
                      **{f"{m} / consistent": f"{x:.3g}" for m, x in rel.items()}, "recovered by": first or "none"})
    if not table:
        return Finding(NOT_MEASURED, "no FMPM runs beside the consistent mass")
    cost = mass_costs(t)
    cost_text = ", ".join(f"{m} {x:.2g}x" + (" (compiled step)" if fast else "")
                          for m, (x, fast) in cost.items() if m != "consistent")
    verdict = count_verdict(hits, len(table))
    evidence = (f"recovered on {hits} of {len(table)}: " + "; ".join(f"{r['solution']} h = {r['h']}: "
                                                                     f"{r['recovered by']}" for r in table)
                + f"; CPU per step over the consistent mass's: {cost_text}")
    sentence = (f"FMPM(k) with 2 <= k <= 4 comes within {FMPM_RECOVERS:.0%} of the consistent mass's error on "
                f"{hits} of {len(table)} solutions and meshes; against a step with the consistent mass a step costs "
                f"{cost_text}")
    fmpm = [x for m, (x, _) in cost.items() if m in COUNTED]
    terse = (f"FMPM(2-4) within {FMPM_RECOVERS:.0%} of the consistent mass's error on {hits} of {len(table)}"
             + (f", at {min(fmpm):.2g}-{max(fmpm):.2g}x its cost per step" if fmpm else ""))
    return Finding(verdict, evidence, sentence, tuple(table), key=short(sentence, terse))


# ---------------------------------------------------------------- D6: MPM against the FEM

def fem_ratios(t: Tables, solution: str) -> dict[str, dict[float, float]]:
    """``{mass: {h: E_MPM / E_FEM}}`` for point-mass MPM (2x2, regular layout: lumped from ``plane/growth``,
    consistent from ``plane/mass``) against the Q1 FEM with the same mass on the same mesh."""
    fem = {(r["mass"], num(r, "h")): num(r, "L2") for r in select(t[FEM], solution=solution) if _ok(r)}
    mpm = {("lumped", num(r, "h")): num(r, "L2") for r in select(t[GROWTH], solution=solution, basis="mpm", ppc=2,
                                                                 seed=0) if _ok(r)}
    mpm.update({("consistent", num(r, "h")): num(r, "L2") for r in select(t.get(MASS, []), solution=solution,
                                                                           mass="consistent") if _ok(r)})
    out: dict = {}
    for (m, h), e in mpm.items():
        if (m, h) in fem:
            out.setdefault(m, {})[h] = e / fem[(m, h)]
    return {m: dict(sorted(v.items(), reverse=True)) for m, v in out.items()}


def _d6(solution: str):
    def criterion(t: Tables) -> Finding:
        """Point-mass MPM's particle error over the Q1 FEM's (total Lagrangian, central differences, the same
        body force and CFL) on the same mesh, with the lumped and with the consistent mass: a constant factor
        when the ratio moves by at most E3_FACTOR from the coarsest mesh to the finest."""
        ratios = {m: v for m, v in fem_ratios(t, solution).items() if len(v) >= MIN_MESHES}
        if not ratios:
            return Finding(NOT_MEASURED, f"no MPM and FEM errors on {MIN_MESHES} common meshes")
        change = {m: list(v.values())[-1] / list(v.values())[0] for m, v in ratios.items()}
        reading = {m: "constant" if 1 / E3_FACTOR <= c <= E3_FACTOR else "grows" if c > E3_FACTOR else "shrinks"
                   for m, c in change.items()}
        hits = sum(r == "constant" for r in reading.values())
        verdict = count_verdict(hits, len(reading), DIFFERS)
        table = tuple({"mass": m, **{f"h = 1/{round(1 / h)}": f"{x:.3g}" for h, x in v.items()},
                       "finest / coarsest": f"{change[m]:.3g}", "reading": reading[m]} for m, v in ratios.items())
        evidence = "; ".join(f"{m}: MPM/FEM {', '.join(f'{x:.3g}' for x in v.values())} from h = "
                             f"1/{round(1 / next(iter(v)))} to 1/{round(1 / list(v)[-1])}, x{change[m]:.3g}: "
                             f"{reading[m]}"
                             for m, v in ratios.items())
        sentence = (f"on the {solution} solution MPM's error over the FEM's on the same mesh moves by a factor "
                    + " and ".join(f"{change[m]:.2f} ({m} mass, {reading[m]})" for m in ratios)
                    + " from the coarsest mesh to the finest")
        terse = "MPM / FEM moves by " + ", ".join(f"{change[m]:.3g}x ({m}, {reading[m]})" for m in ratios)
        return Finding(verdict, evidence, sentence, table, key=short(sentence, terse))
    return criterion


for _s in SOLUTIONS:
    claim("D6", source="1D (E3): MPM's error over the FEM's", tables=(GROWTH, FEM), study="plane", problem=_s,
          thresholds=(f"per mass with {MIN_MESHES} common meshes, the MPM/FEM ratio's change from the coarsest mesh "
                      f"to the finest within [1/{E3_FACTOR:g}, {E3_FACTOR:g}]: a constant factor; above: it grows; "
                      "every mass constant -> confirmed, some -> partly, none -> differs"))(_d6(_s))


# ---------------------------------------------------------------- D7: time against space

@claim("D7", source="Steffen, Kirby & Berzins (IJNME 82 (2010) 1207): large steps, time error dominates at second "
                    "order; small steps, refining dt changes nothing", tables=(TIME,), study="plane",
       thresholds=(f"per solution on one mesh, the step refined alone from CFL 0.8: the time error d_k = |E_k - "
                   f"E_finest| "
                   f"at the largest step exceeds E_finest and falls at order {TIME_ORDER:g} +- {ORDER_TOLERANCE:g} "
                   f"from the largest step to the next; at the study's step (CFL 0.25 or the largest below it) "
                   f"|E_k / E_finest - 1| <= {TIME_NEGLIGIBLE:g}; both parts on every solution -> confirmed, some "
                   "parts -> partly, none -> refuted"))
def _d7(t: Tables) -> Finding:
    """The same mesh and particles with the time step alone divided 1 to 32 times from CFL 0.8: the error's
    change against the finest step is the time error, the finest step's error the space error."""
    table, hits, parts = [], 0, 0
    for sol in dict.fromkeys(r["solution"] for r in t[TIME]):
        rows = sorted((r for r in select(t[TIME], solution=sol) if _ok(r)), key=lambda r: num(r, "refine"))
        if len(rows) < MIN_MESHES:
            continue
        E = [num(r, "L2") for r in rows]
        cfl = [num(r, "cfl_run") / num(r, "refine") for r in rows]
        d = [abs(e - E[-1]) for e in E[:-1]]
        order = math.log(d[0] / d[1]) / math.log(num(rows[1], "refine") / num(rows[0], "refine")) \
            if d[0] > 0 and d[1] > 0 else math.nan
        large = d[0] > E[-1] and abs(order - TIME_ORDER) <= ORDER_TOLERANCE
        study = next((k for k, c in enumerate(cfl) if c <= num(rows[0], "study_cfl")), len(E) - 1)
        small = abs(E[study] / E[-1] - 1) <= TIME_NEGLIGIBLE
        hits, parts = hits + large + small, parts + len((large, small))
        table.append({"solution": sol, "time error at CFL 0.8 / space error": f"{d[0] / E[-1]:.3g}",
                      "time order at the largest step": f"{order:.2f}",
                      "study step change": f"{E[study] / E[-1] - 1:+.3f} (CFL {cfl[study]:.3g})",
                      "large steps": "holds" if large else "does not hold", "small steps": "holds" if small else
                      "does not hold"})
    if not table:
        return Finding(NOT_MEASURED, "no time series")
    verdict = count_verdict(hits, parts)
    evidence = "; ".join(f"{r['solution']}: time/space error at CFL 0.8 {r['time error at CFL 0.8 / space error']}, "
                         f"order {r['time order at the largest step']}, at the study's step "
                         f"{r['study step change']}" for r in table)
    sentence = (f"with the time step alone refined on one mesh the readings hold on {hits} of {parts} readings: "
                + "; ".join(
        f"{r['solution']}: the time error at CFL 0.8 is {r['time error at CFL 0.8 / space error']} times the space "
        f"error and falls at order {r['time order at the largest step']}, and at the study's step refining moves "
        f"the error by {r['study step change'].split(' ')[0]}" for r in table))
    terse = f"time against space on one mesh: {hits} of {parts} readings hold; " + "; ".join(
        f"{r['solution']} order {r['time order at the largest step']}" for r in table)
    return Finding(verdict, evidence, sentence, tuple(table), key=short(sentence, terse))
