"""The budget study's claims: E1 (the error budget over every combination of the stages, on Sod and
on Burgers: do the stages separate, and which one dominates) from the raw measurements
``budget/subsets`` (with ``budget/roundoff`` beside), and E2 (the bases) from ``budget/bases``."""

from __future__ import annotations

import math

from mpm_fem.measure.claims.base import CONFIRMED, DIFFERS, PARTLY, REFUTED, Criterion, Finding, Tables, claim, short
from mpm_fem.measure.claims.rows import CONVERGING_ORDER, FLOOR_ORDER, failures, num, select, span, successive_orders
from mpm_fem.measure.claims.rules import rule
from mpm_fem.measure.claims.stages import STEP_ORDER, SUBSETS, decomposition, run_label, runs, values
from mpm_fem.measure.schema import BUDGET_BASES, BUDGET_CONTROL, BUDGET_CONTROL_RUNS, BUDGET_READOUT, BUDGET_ROUNDOFF
from mpm_fem.measure.spread import Spread, spread

#: E1 (a): the stages separate when their interactions (the Moebius terms of two stages or more), in
#: total magnitude, are at most SEPARATE of |v(all MPM) - v(all exact)|.
SEPARATE = rule("SEPARATE")
#: E1 (b): no stage is named dominant where the interactions exceed ATTRIBUTABLE times the gap.
ATTRIBUTABLE = rule("ATTRIBUTABLE")
#: E1 (b): the attributions that must name the same largest stage for it to dominate: the Shapley
#: value, and the error removed by each stage when the stages are made exact one after another from
#: all MPM, in the step's order and in its reverse.
SEQUENCES = {"forward": STEP_ORDER, "backward": STEP_ORDER[::-1]}
#: E1 is judged on the particle error: on a jittered layout the nodal read-out is itself a particle
#: quadrature, so the nodal error with every stage exact is not the exact solution's (named in the evidence)
JUDGED_NORM = "particles"
CONTROL, CONTROL_RUNS = BUDGET_CONTROL.name, BUDGET_CONTROL_RUNS.name


def sequential(v: dict, order: tuple) -> dict:
    """The error each stage removes when the stages are made exact one after another in ``order``,
    starting from all MPM: ``v(B) - v(B - {s})``, ``B`` the stages still in MPM form before ``s``;
    they add up to v(all MPM) - v(all exact) in any order."""
    out, still = {}, frozenset(order)
    for s in order:
        out[s] = v[still] - v[still - {s}]
        still = still - {s}
    return out


def stage_findings(rows: list[dict]) -> dict | None:
    """E1's two questions on the ``budget/subsets`` rows of one (problem, h, basis, norm): the
    interactions' total magnitude over |v(all MPM) - v(all exact)| (``interactions``), whether the
    stages separate, the largest stage by each attribution (``tops``: Shapley, forward, backward),
    the dominant stage when they agree and the interactions are at most ATTRIBUTABLE times the gap
    (else None), the largest main effect (``alone``: stage,
    m({s})) and the end points; None when a subset of STEP_ORDER is missing."""
    v, d = values(rows), decomposition(rows)
    if d is None:
        return None
    inter = sum(abs(m) for m in d.interactions().values())
    ratio = inter / abs(d.gap) if d.gap else math.inf
    tops = {"Shapley": max(STEP_ORDER, key=lambda s: d.shapley[s])}
    for name, order in SEQUENCES.items():
        removed = sequential(v, order)
        tops[name] = max(order, key=lambda s: removed[s])
    alone = max(STEP_ORDER, key=lambda s: abs(d.moebius[frozenset({s})]))
    agree = len(set(tops.values())) == 1 and ratio <= ATTRIBUTABLE
    return {"interactions": ratio, "separate": ratio <= SEPARATE, "tops": tops,
            "dominant": tops["Shapley"] if agree else None,
            "alone": (alone, d.moebius[frozenset({alone})]), "mpm": d.total, "exact": d.floor}


def budget_findings(rows: list[dict]) -> dict:
    """:func:`stage_findings` of every mesh, per ``(basis, norm, run)`` of one problem's
    ``budget/subsets`` rows (``run``: particles per cell, layout and seed where the table records them,
    :func:`~.stages.run_label`): ``{(basis, norm, run): [(h, findings), ...]}``, coarsest mesh first."""
    out: dict = {}
    for (basis, norm, h, run), sub in runs(rows).items():
        found = stage_findings(sub)
        if found is not None:
            out.setdefault((basis, norm, run), []).append((h, found))
    return {k: sorted(v, key=lambda x: -x[0]) for k, v in out.items()}


def _e1_text(found: dict) -> str:
    """E1's evidence from :func:`budget_findings` (judged at the finest mesh of each basis and norm)."""
    finest = {k: series[-1] for k, series in found.items()}
    n, sep = len(finest), [k for k, (_, f) in finest.items() if f["separate"]]
    dominant = {k: f["dominant"] for k, (_, f) in finest.items() if f["dominant"]}
    hs = span([h for h, _ in finest.values()], "g")
    names = {k: " ".join(p for p in k if p) for k in finest}
    ratios = [f["interactions"] for _, f in finest.values()]
    head = (f"the stages separate in {len(sep)} of {n} bases and runs at h = {hs} (the interactions are "
            f"{span(ratios, '.2g')}x |v(all MPM) - v(all exact)|, at most {SEPARATE:.0%} to separate)")
    by_stage = {}
    for k, s in dominant.items():
        by_stage.setdefault(s, []).append(names[k])
    head += (f"; a dominant stage in {len(dominant)} of {n}: "
             + ("; ".join(f"{s} ({', '.join(ks)})" for s, ks in by_stage.items()) if dominant else "none"))
    tangled = [names[k] for k, (_, f) in finest.items() if f["interactions"] > ATTRIBUTABLE]
    undecided = [f"{names[k]} (" + ", ".join(f"{a} {s}" for a, s in f["tops"].items()) + ")"
                 for k, (_, f) in finest.items() if not f["dominant"] and names[k] not in tangled]
    if tangled:
        head += (f"; no stage named where the interactions exceed {ATTRIBUTABLE:g}x the gap: "
                 + ", ".join(tangled))
    if undecided:
        head += "; the attributions disagree for " + ", ".join(undecided)
    (k0, (h0, f0)) = next(iter(finest.items()))
    stage, effect = f0["alone"]
    head += (f"; e.g. {names[k0]} at h = {h0:g}: {stage} alone adds {effect:.3g} against "
             f"v(all MPM) = {f0['mpm']:.3g} and v(all exact) = {f0['exact']:.3g}")
    trend = ", ".join(f"{names[k]} " + " -> ".join(f"{f['interactions']:.2g}" for _, f in series)
                      for k, series in found.items())
    return head + f"; interactions / |v(all MPM) - v(all exact)| from the coarsest mesh to the finest: {trend}"


def e1_result(rows: list[dict]) -> dict | None:
    """E1's result on one problem's ``budget/subsets`` rows (or the control's ``budget/control``), at the
    finest mesh of every basis and run, on the particle norm (:data:`JUDGED_NORM`): ``cases`` (how many),
    ``separate`` and ``dominant`` (how many), the interactions over the gap
    (``ratios``), the meshes (``h``) and the verdict: ``refuted`` when the stages separate nowhere,
    ``confirmed`` when they separate and one stage dominates everywhere, else ``partly``. None without
    a complete budget. E5 reads it to say what the budget found."""
    found = {k: v for k, v in budget_findings(rows).items() if k[1] == JUDGED_NORM}
    if not found:
        return None
    finest = [series[-1][1] for series in found.values()]
    n, sep = len(finest), sum(f["separate"] for f in finest)
    dom = sum(f["dominant"] is not None for f in finest)
    verdict = REFUTED if sep == 0 else CONFIRMED if sep == dom == n else PARTLY
    return {"cases": n, "separate": sep, "dominant": dom, "ratios": [f["interactions"] for f in finest],
            "h": [series[-1][0] for series in found.values()], "verdict": verdict, "found": found,
            "stages": sorted({f["dominant"] for f in finest if f["dominant"]})}


def e1_sentence(problem: str, r: dict) -> str:
    """E1's plain sentence on one problem from :func:`e1_result`."""
    ratios = f"{min(r['ratios']):.2g} to {max(r['ratios']):.2g}"
    problem = problem.capitalize()
    if r["separate"] == 0:
        return (f"on {problem} the four stages of the step do not separate: their interactions are {ratios} times "
                f"the gap between the all-MPM and the all-exact error, so no stage is the error's source alone")
    return (f"on {problem} the stages separate in {r['separate']} of {r['cases']} bases and runs (interactions "
            f"{ratios} times the gap)" + (f"; {', '.join(r['stages'])} dominates where they do" if r["stages"] else ""))


def e1_key(problem: str, r: dict) -> str:
    """E1's key number on one problem from :func:`e1_result`, at most ``KEY_CHARS`` characters."""
    ratios = f"{min(r['ratios']):.2g} to {max(r['ratios']):.2g}"
    if r["separate"] == 0:
        return short(f"on {problem.capitalize()} the stages do not separate: their interactions are {ratios} times the "
                     "gap between all-MPM and all-exact")
    return short(e1_sentence(problem, r), e1_sentence(problem, r).split("; ")[0])


def _e1(problem: str) -> Criterion:
    def criterion(t: Tables) -> Finding:
        """The sixteen combinations of the four stages in MPM or exact form are the raw measurements.
        The stages separate when the error of every combination is close to the all-exact error plus
        the errors each stage adds alone: the Moebius interactions, which measure the departure from
        that sum, are small beside the gap between all MPM and all exact. A stage dominates when the
        Shapley value and the errors removed by making the stages exact one after another, in the
        step's order and in its reverse, name it as the largest and the interactions do not exceed the
        gap; where the interactions are large these attributions are artefacts of the order, and then
        no stage is named."""
        r = e1_result(select(t[SUBSETS], problem=problem))
        if r is None:
            return "not measured", f"no complete set of the {2 ** len(STEP_ORDER)} combinations of {STEP_ORDER}"
        table = tuple({"basis": basis, "norm": norm, "run": run or "regular", "h": f"{series[-1][0]:g}",
                       "interactions / gap": f"{series[-1][1]['interactions']:.2g}",
                       "separate": str(series[-1][1]["separate"]), "dominant": series[-1][1]["dominant"] or "none"}
                      for (basis, norm, run), series in r["found"].items())
        evidence = (_e1_text(r["found"]) + _readout_text(select(t[SUBSETS], problem=problem),
                                                         select(t.get(READOUT) or [], problem=problem))
                    + _roundoff_text(t, problem) + control_clause(t))
        return Finding(r["verdict"], evidence, e1_sentence(problem, r), table, key=e1_key(problem, r))
    return criterion


READOUT = BUDGET_READOUT.name


def _readout_text(rows: list[dict], readout: list[dict] = ()) -> str:
    """The nodal read-out's own error (informative: E1 is judged on :data:`JUDGED_NORM`): at the finest mesh
    of each run with a nodal norm, v(all exact) of the nodes against v(all MPM) and the nodal gap; jittered
    runs and regular ones apart; and, from ``budget/readout`` where given, the read-out of the exact density
    at the exact particle positions on the jittered layouts. Empty without a nodal norm."""
    found = {k: series[-1] for k, series in budget_findings(rows).items() if k[1] != JUDGED_NORM}
    if not found:
        return ""
    parts = []
    for kind, pick in (("jittered", lambda run: "jittered" in run), ("regular", lambda run: "jittered" not in run)):
        at = [f for (_, _, run), (_, f) in found.items() if pick(run)]
        if at:
            parts.append(f"{kind} ({len(at)} run{'s' if len(at) > 1 else ''}) {span([f['exact'] for f in at], '.3g')}"
                         f" against all MPM {span([f['mpm'] for f in at], '.3g')}, a nodal gap of "
                         f"{span([abs(f['mpm'] - f['exact']) for f in at], '.2g')}")
    jittered = [r for r in readout if r.get("layout") == "jittered"]
    if jittered:
        ratio = [num(r, "readout_L1") / num(r, "all_exact_L1") for r in jittered]
        parts.append(f"the read-out alone (the exact density at the exact particle positions, `{READOUT}.csv`) errs by "
                     f"{span([num(r, 'readout_L1') for r in jittered], '.3g')} on the {len(jittered)} jittered runs, "
                     f"{span(ratio, '.2f')}x their v(all exact)")
    return ("; the nodal read-out is itself a particle quadrature, so with every stage exact the nodal error is "
            "not zero (E1 is judged on the particle norm): v(all exact) at the nodes " + "; ".join(parts))


def control_result(t: Tables) -> dict | None:
    """E1's result on the control (:func:`e1_result` of ``budget/control``), with the run table's field
    interactions (``field``), nodal read-out errors (``readout``: ``{"regular"|"jittered": [relative]}``) and
    the largest main effect over the gap (``alone``, the same keys); None without the control."""
    r = e1_result(t.get(CONTROL) or [])
    if r is None:
        return None
    runs_ = t.get(CONTROL_RUNS) or []
    finest = min((num(x, "h") for x in runs_), default=math.nan)
    at = [x for x in runs_ if num(x, "h") == finest]
    r["field"] = [num(x, "field_interactions") for x in at]
    r["readout"] = {k: [num(x, "readout_relative") for x in at if (x["layout"] == "jittered") == (k == "jittered")]
                    for k in ("regular", "jittered")}
    r["alone"] = {k: [abs(f["alone"][1]) / abs(f["mpm"] - f["exact"]) for (_, _, run), series in r["found"].items()
                      for f in [series[-1][1]] if f["mpm"] != f["exact"] and ("jittered" in run) == (k == "jittered")]
                  for k in ("regular", "jittered")}
    return r


def control_clause(t: Tables) -> str:
    """The clause E1's evidence on Sod and Burgers adds from the control: whether the decomposition separates
    the stages on a problem without node crossings; empty without the control."""
    r = control_result(t)
    if r is None:
        return ""
    ratios = f"{min(r['ratios']):.2g}-{max(r['ratios']):.2g}x"
    if r["separate"] == r["cases"]:
        return (f"; on the control without node crossings (E1 (control)) the stages separate (interactions {ratios} "
                "the gap), so the decomposition can separate them and the interactions here are the problem's")
    return (f"; on the control without node crossings (E1 (control)) the stages separate in {r['separate']} of "
            f"{r['cases']} runs (interactions {ratios} the gap), so interactions of this size do not need node "
            "crossings")


@claim("E1", source="the four error sources of the slides, on a control the decomposition should separate",
       tables=(CONTROL,), study="budget", problem="control",
       thresholds=f"the rule of E1 on Sod and Burgers (interactions at most {SEPARATE:.0%} of the gap: separate; "
                  f"a dominant stage named where the attributions agree and the interactions are at most "
                  f"{ATTRIBUTABLE:g}x the gap), on the control's particle norm at its finest mesh, every run "
                  "(particles per cell, layout, seed): every run separates and one stage dominates -> confirmed; "
                  "none separates -> refuted (a finding about the decomposition, not the problem); otherwise "
                  "partly. Read from budget/control")
def _e1_control(t: Tables) -> Finding:
    """The control is the neo-Hookean bar of the 1D control at amplitude 1e-4: its particles move 1e-4 of the
    domain, so none crosses a node, and the step is linear to that amplitude. If the interactions of the
    stages came from the crossings, the stages would separate here. The field interactions (the Moebius
    terms of the error fields themselves, in the same norm) tell the interactions of the physics from those
    of the norm, which is not additive. The nodal read-out of exact particle data is measured beside it: on
    a jittered layout it is a particle quadrature with an error of its own."""
    r = control_result(t)
    if r is None:
        return "not measured", f"no complete set of the {2 ** len(STEP_ORDER)} combinations on the control"
    table = tuple({"run": run or "regular", "h": f"{series[-1][0]:g}",
                   "interactions / gap": f"{series[-1][1]['interactions']:.2g}",
                   "separate": str(series[-1][1]["separate"]), "dominant": series[-1][1]["dominant"] or "none"}
                  for (_, _, run), series in r["found"].items())
    ratios = f"{min(r['ratios']):.2g} to {max(r['ratios']):.2g}"
    field = f"{min(r['field']):.2g} to {max(r['field']):.2g}" if r["field"] else "not measured"
    readout = "; ".join(f"{k} {span(v, '.2%')}" for k, v in r["readout"].items() if v)
    alone = "; ".join(f"{k} {span(v, '.2g')}" for k, v in r["alone"].items() if v)
    together = ("; on the regular layout the error appears only when several stages are in MPM form together"
                if r["alone"]["regular"] and max(r["alone"]["regular"]) <= SEPARATE else "")
    evidence = (f"the stages separate in {r['separate']} of {r['cases']} runs of the bar (no node crossing) at h = "
                f"{span(r['h'], 'g')}: the interactions are {ratios}x |v(all MPM) - v(all exact)| (at most "
                f"{SEPARATE:.0%} to separate), those of the error fields themselves {field}x; the largest stage "
                f"alone (its main effect) over the gap: {alone}{together}; " + _e1_text(r["found"]).split("; ", 1)[1]
                + (f"; the nodal read-out of exact particle data (velocity, exact positions) errs by {readout} of the "
                   "velocity" if readout else ""))
    sentence = (f"on a control without node crossings (the neo-Hookean bar at amplitude 1e-4) the stages separate in "
                f"{r['separate']} of {r['cases']} runs (interactions {ratios} times the gap)")
    return Finding(r["verdict"], evidence, sentence, table,
                   key=short(sentence, f"on the control without node crossings the stages separate in {r['separate']}"
                                       f" of {r['cases']} runs (interactions {ratios}x the gap)"))


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


_E1_RULE = (f"at the finest mesh of every basis and norm, (a) the interactions of the stages (the Moebius terms of two "
            f"stages or more), in total magnitude, are at most {SEPARATE:.0%} of |v(all MPM) - v(all exact)| (the "
            "stages separate) and (b) the Shapley value and the sequential replacement (the stages made exact one "
            f"after another from all MPM, in the step's order {' -> '.join(STEP_ORDER)} and in its reverse) name the "
            f"same largest stage, with the interactions at most {ATTRIBUTABLE:g}x the gap (it dominates) -> "
            "confirmed; the stages separate nowhere -> refuted (no stage named); otherwise partly. Read from "
            "budget/subsets, the value of every combination")
for _problem in ("sod", "burgers"):
    claim("E1", source="the four error sources of the slides (projection, FE + mass lumping, interpolation, time)",
          tables=(SUBSETS,), study="budget", problem=_problem, thresholds=_E1_RULE)(_e1(_problem))


FLOOR_STEPS = int(rule("FLOOR_STEPS"))


def _tail_orders(rows: list[dict], key: str) -> list[Spread]:
    """The orders of ``key`` over the last FLOOR_STEPS refinements of one basis, each a range over its
    runs (particles per cell, layout and seed where the table records them; one run otherwise)."""
    per_run: dict[str, list[dict]] = {}
    for r in rows:
        per_run.setdefault(run_label(r), []).append(r)
    series = [successive_orders(sorted(v, key=lambda r: -num(r, "h")), key)[-FLOOR_STEPS:] for v in per_run.values()]
    steps = min(map(len, series), default=0)
    return [spread(s[len(s) - steps + k] for s in series) for k in range(steps)]


@claim("E2", source="whether a smooth basis removes the stagnation of C11", tables=(BUDGET_BASES.name,), study="budget",
       thresholds=f"over the last {FLOOR_STEPS} refinements (each order a range over the runs: particles per cell, "
                  f"layouts and seeds where the table holds them): P1's particle density L1 orders all below "
                  f"{FLOOR_ORDER} and a C1 basis's all at least {CONVERGING_ORDER} -> confirmed; a C1 basis above P1 "
                  "on every one -> partly; none above P1 -> refuted; P1 not levelled off -> differs")
def _e2(t: Tables) -> Finding:
    rows = select(t[BUDGET_BASES.name], ok="True")
    tails = {b: {k: _tail_orders(select(rows, basis=b), k) for k in ("particles_L1", "nodes_L1")}
             for b in dict.fromkeys(r["basis"] for r in rows)}
    tails = {b: v for b, v in tails.items() if len(v["particles_L1"]) == FLOOR_STEPS}
    if "mpm" not in tails or len(tails) < 2:
        return Finding("not measured", f"fewer than {FLOOR_STEPS + 1} meshes or no point-mass row")
    p1 = tails["mpm"]["particles_L1"]
    smooth = {b: v["particles_L1"] for b, v in tails.items() if b != "mpm"}
    converges = [b for b, o in smooth.items() if all(x.above(CONVERGING_ORDER) for x in o)]
    above = [b for b, o in smooth.items() if all(x.lo > y.hi for x, y in zip(o, p1, strict=True))]
    verdict = (DIFFERS if not all(x.below(FLOOR_ORDER) for x in p1) else CONFIRMED if converges
               else PARTLY if above else REFUTED)
    runs_n = max(x.n for x in p1)
    finest = sorted(rows, key=lambda r: num(r, "h"))[0]["h"]
    noise = {b: span([num(r, "plateau_noise") for r in select(rows, basis=b, h=finest)], ".3g") for b in tails}
    table = tuple({"basis": b, "particle density orders": ", ".join(o.text() if o.n > 1 else f"{o.mean:.2f}"
                                                                    for o in v["particles_L1"]),
                   "nodal density orders": ", ".join(f"{o.mean:.2f}" for o in v["nodes_L1"]),
                   f"plateau std(v_p) at h = {finest}": noise[b]} for b, v in tails.items())
    sentence = (f"over the last {FLOOR_STEPS} refinements the particle density error's order is "
                + ", ".join(f"{r['particle density orders']} with {_BASIS_NAMES.get(r['basis'], r['basis'])}"
                            for r in table))
    bases = t[BUDGET_BASES.name]
    failed = tuple(line for b in dict.fromkeys(r["basis"] for r in bases)
                   for line in failures(select(bases, basis=b), ("ppc", "h"), f"{BUDGET_BASES.name} {b}"))
    failed_text = "".join(f"; {line} (left out)" for line in failed)
    return Finding(verdict, (f"particle density L1 orders over the last {FLOOR_STEPS} refinements ({runs_n} run"
                             f"{'s' if runs_n > 1 else ''} each): "
                             + "; ".join(f"{r['basis']} {r['particle density orders']}"
                                         for r in table)
                             + "; nodes " + "; ".join(f"{r['basis']} {r['nodal density orders']}" for r in table)
                             + f"; plateau std(v_p) at h = {finest}: "
                             + ", ".join(f"{b} {v}" for b, v in noise.items()) + failed_text),
                   sentence, table, failed, short(
                       sentence, f"over the last {FLOOR_STEPS} refinements the particle density order is "
                       + ", ".join(f"{', '.join(f'{o.mean:.2f}' for o in v['particles_L1'])} with "
                                   f"{_BASIS_NAMES.get(b, b)}" for b, v in tails.items()),
                       f"particle density orders, last {FLOOR_STEPS} refinements: "
                       + ", ".join(f"{', '.join(f'{o.mean:.2f}' for o in v['particles_L1'])} "
                                   f"({_BASIS_NAMES.get(b, b).removeprefix('the ')})" for b, v in tails.items()),
                       f"particle density orders, last {FLOOR_STEPS} refinements: "
                       + ", ".join(f"{_SHORT_NAMES.get(b, b)} {'/'.join(f'{o.mean:.2f}' for o in v['particles_L1'])}"
                                   for b, v in tails.items())))


_SHORT_NAMES = {"mpm": "P1", "gimp": "GIMP", "bspline": "C1", "bspline_gimp": "C1 domain", "cubic": "C2"}
_BASIS_NAMES = {"mpm": "P1", "gimp": "GIMP", "bspline": "the C1 B-spline",
                "bspline_gimp": "the particle-domain B-spline", "cubic": "the C2 cubic B-spline"}
