"""The remedies study's claim, E5: a remedy removes the MPM plateau (``remedies/errors``), with the
diagnosis of the named remedy from the error budget of its basis (``budget/shapley``)."""

from __future__ import annotations

import math

from mpm_fem.measure.claims.base import CONFIRMED, PARTLY, REFUTED, Finding, Tables, claim, short
from mpm_fem.measure.claims.budget import SUBSETS, e1_result
from mpm_fem.measure.claims.rows import CONVERGING_ORDER, FLOOR_ORDER, failures, num, select, span, successive_orders
from mpm_fem.measure.claims.rules import rule
from mpm_fem.measure.claims.stages import run_label
from mpm_fem.measure.schema import BUDGET_SHAPLEY, REMEDIES_ERRORS, SETTINGS
from mpm_fem.measure.tables import setting

REMEDY_ERRORS = REMEDIES_ERRORS.name
#: E5 on Sod, against the finite-volume reference on the same meshes: a remedy's observed order between
#: two successive meshes is as good as the FV's when it is at least the FV's order there minus
#: ORDER_MARGIN, the width of the band the study leaves undecided between a floor and convergence
#: (rows.py), and not below FLOOR_ORDER.
ORDER_MARGIN = CONVERGING_ORDER - FLOOR_ORDER
#: E5 on Sod: the error stays within a constant factor of the FV's when its ratio to the FV error at the
#: finest mesh is at most FV_DRIFT times the ratio at the coarsest.
FV_DRIFT = rule("FV_DRIFT")
#: The thresholds of :func:`remedy_assessment`'s ``removes_plateau``, as the remedies study records them.
PLATEAU_CRITERION = {"order_margin_to_fv": ORDER_MARGIN, "floor_order": FLOOR_ORDER, "fv_drift": FV_DRIFT,
                     "converging_order_without_fv": CONVERGING_ORDER}
FV_FACTOR = rule("FV_FACTOR")  # the goal on Sod: within this factor of the finite-volume error at every h
BURGERS_ORDER = rule("BURGERS_ORDER")  # the goal on Burgers (4 per cell): fitted order >= this, nodes and particles
REMEDY_MEASURES = ("nodes_L1", "particles_L1")


def _fitted(rows: list[dict], key: str) -> float:
    pts = [(math.log(num(r, "h")), math.log(num(r, key))) for r in rows if num(r, key) > 0]
    if len(pts) < 2:
        return math.nan
    mx, my = sum(p[0] for p in pts) / len(pts), sum(p[1] for p in pts) / len(pts)
    return sum((x - mx) * (y - my) for x, y in pts) / sum((x - mx) ** 2 for x, _ in pts)


def remedy_assessment(rows: list[dict]) -> dict:
    """What E5 asks of one remedy on one problem (rows of one series, any order). Per measure: the
    lowest successive order, the least-squares order and, where every row carries the FV reference's
    error ``fv_L1`` (Sod), the largest ratio to it, the ratio at the finest mesh over that at the
    coarsest (``fv_drift``) and the lowest difference between the remedy's order and the FV's on the
    same pair of meshes (``min_gap_fv``). ``removes_plateau``, over both measures: with the FV
    reference, every successive order as good as the FV's (at least the FV's minus ORDER_MARGIN, and
    at least FLOOR_ORDER) and ``fv_drift`` at most FV_DRIFT; without it (Burgers), every successive
    order at least CONVERGING_ORDER. A failed run (no error) fails every condition it enters."""
    rows = sorted(rows, key=lambda r: -num(r, "h"))
    with_fv = bool(rows) and all(num(r, "fv_L1") > 0 for r in rows)
    fv_orders = successive_orders(rows, "fv_L1") if with_fv else []
    out, removes = {}, len(rows) >= 2
    for m in REMEDY_MEASURES:
        o = successive_orders(rows, m)
        finite = bool(o) and all(math.isfinite(x) for x in o)
        out[f"min_order_{m}"] = min(o) if finite else math.nan
        out[f"fitted_order_{m}"] = _fitted(rows, m)
        if with_fv:
            ratios = [num(r, m) / num(r, "fv_L1") for r in rows]
            gaps = [a - b for a, b in zip(o, fv_orders, strict=True)]
            out[f"max_fv_ratio_{m}"] = max(ratios) if all(math.isfinite(x) for x in ratios) else math.nan
            out[f"fv_drift_{m}"] = ratios[-1] / ratios[0]
            out[f"min_gap_fv_{m}"] = min(gaps) if finite else math.nan
            removes &= finite and all(x >= max(FLOOR_ORDER, f - ORDER_MARGIN)
                                      for x, f in zip(o, fv_orders, strict=True))
            removes &= out[f"fv_drift_{m}"] <= FV_DRIFT
        else:
            out[f"max_fv_ratio_{m}"] = math.nan
            removes &= finite and all(x >= CONVERGING_ORDER for x in o)
    out["removes_plateau"] = bool(removes)
    return out


def remedy_budget(t: Tables, remedy: str) -> str:
    """E5's diagnosis of ``remedy`` from the error budget: at the finest Sod mesh the budget ran with
    the remedy's basis (the remedies' settings), the stage whose Shapley share of the remaining
    error ``v(all MPM) - v(all exact)`` (particle density L1) is the largest, and the other shares.
    The budget runs the bases only: a remedy's other options are not in it (the text says so)."""
    options = {r["key"].split(".")[2] for r in t.get(SETTINGS.name, []) if r["table"] == REMEDY_ERRORS
               and r["key"].startswith(f"remedies.{remedy}.")}
    basis = setting(t, REMEDY_ERRORS, f"remedies.{remedy}.basis", "mpm")
    rows = select(t.get(BUDGET_SHAPLEY.name, []), problem="sod", basis=basis, norm="particles")
    if not rows:
        return f"no error budget of its basis {basis}"
    h = min(num(r, "h") for r in rows)
    at = sorted(select(rows, h=h), key=lambda r: -num(r, "share"))
    top = at[0]
    others = [o for o in sorted(options) if o != "basis"]
    return (f"the budget of its basis {basis} at h = {h:g} (particle density L1"
            + (f"; its {', '.join(others)} not in the budget" if others else "")
            + f"): {top['stage']} carries {num(top, 'share'):.0%} of the remaining error v(all MPM) - v(all exact) = "
            f"{num(top, 'mpm_error') - num(top, 'exact_error'):.2g}, then "
            + ", ".join(f"{r['stage']} {num(r, 'share'):.0%}" for r in at[1:]))


def _runs(rows: list[dict], problem: str) -> dict[str, dict[str, list[dict]]]:
    """``{remedy: {run: rows}}`` of ``problem`` (run: particles per cell, layout and seed where the table
    records them, :func:`~.stages.run_label`; one run otherwise)."""
    out: dict[str, dict[str, list[dict]]] = {}
    for r in select(rows, problem=problem):
        out.setdefault(r["remedy"], {}).setdefault(run_label(r), []).append(r)
    return out


def remedy_series(rows: list[dict], problem: str) -> dict[str, list[dict]]:
    """Each remedy's main series: its run on the most meshes (the first such run in the table's order);
    the other runs (other particles per cell, jittered layouts) are read by :func:`_other_runs`."""
    return {name: max(runs.values(), key=len) for name, runs in _runs(rows, problem).items()}


def _other_runs(rows: list[dict], name: str) -> str:
    """The clause on ``name``'s other Sod runs (where the table holds them): their number, meshes and
    the range of their lowest successive orders, nodes and particles; empty without."""
    runs = _runs(rows, "sod").get(name, {})
    main = max(runs.values(), key=len) if runs else []
    others = [v for v in runs.values() if v is not main and len(v) > 1]
    if not others:
        return ""
    lows = [remedy_assessment(v)[f"min_order_{m}"] for v in others for m in REMEDY_MEASURES]
    hs = sorted({num(r, "h") for v in others for r in v}, reverse=True)
    labels = sorted({run_label(v[0]) for v in others})
    return (f"; over {len(others)} more runs ({', '.join(labels)}) on h = {hs[0]:g}..{hs[-1]:g} its lowest "
            f"successive orders {span(lows)}")


@claim("E5", source="the goal set for the remedies: an MPM variant whose Sod density error keeps converging on "
                    "every mesh, over nodes and over particles, within 1.5x of the FV error at every h, and that "
                    "converges at first order or better on Burgers with 4 particles per cell",
       tables=(REMEDY_ERRORS,), study="remedies",
       thresholds=f"on Sod (run on every mesh of the table) a remedy removes the plateau when, over nodes and over "
                  f"particles, its observed order between every pair of successive meshes is as good as the "
                  f"finite-volume reference's on the same pair (at least the FV's minus {ORDER_MARGIN:.2g}, the "
                  f"study's band between the floor {FLOOR_ORDER} and convergence {CONVERGING_ORDER}, and at least "
                  f"{FLOOR_ORDER}) and its error stays within a constant factor of the FV's (its ratio to the FV "
                  f"error at the finest mesh at most {FV_DRIFT}x that at the coarsest); on Burgers, which has no FV "
                  f"reference, when every successive order is at least {CONVERGING_ORDER}. A remedy that removes "
                  f"it on Sod, stays within {FV_FACTOR}x of the FV error at every h (nodes and particles) and on "
                  f"Burgers removes it with fitted orders >= {BURGERS_ORDER} -> confirmed (named); one that only "
                  "removes the Sod plateau -> partly; none -> refuted. The remedy named meets most of the three "
                  "conditions and, among those, has the smallest largest FV ratio. Wall time enters no verdict. The "
                  "evidence adds which stage carries the largest Shapley share of the named remedy's remaining "
                  "error, from the error budget of its basis at its finest mesh (budget/shapley, when the budget "
                  "was run)")
def _e5(t: Tables) -> Finding:
    """Each remedy targets a mechanism the slides or the diagnosis name: the particle-domain B-spline the
    force quadrature and the jump of the basis gradient at node crossings, the Taylor reconstruction the
    force quadrature, the volume reset the volume drift, the PIC/FLIP blend and XPIC(m) the noise carried
    by the particle velocities (XPIC filters FLIP's null-space noise without PIC's diffusion). Whether
    these are the error's separate sources is E1's question, and the evidence states E1's answer. The
    contact discontinuity of Sod's tube limits the L1 order of every method, the finite-volume
    reference's too, so a remedy is held to the FV reference's own orders on the same meshes, not to
    first order."""
    rows = t[REMEDY_ERRORS]
    scored, sod = _scored(rows)
    if not scored:
        return "not measured", "no remedy was run on two Sod meshes or more"
    _, name, s, fv, b, b_ok = scored[0]
    own = sorted(sod[name], key=lambda r: -num(r, "h"))
    fv_orders = successive_orders(own, "fv_L1")
    g = {f"{k}_{m}": s.get(f"{k}_{m}", math.nan) for k in ("min_gap_fv", "fv_drift") for m in REMEDY_MEASURES}
    text = (f"{name}: Sod order minus the FV reference's on the same meshes at least "
            f"{g['min_gap_fv_nodes_L1']:+.2f} (nodes) / {g['min_gap_fv_particles_L1']:+.2f} (particles), lowest "
            f"orders {s['min_order_nodes_L1']:.2f} / {s['min_order_particles_L1']:.2f} against the FV's "
            f"{span(fv_orders)}, over h = {num(own[0], 'h'):g}..{num(own[-1], 'h'):g}; at most "
            f"{s['max_fv_ratio_nodes_L1']:.2f}x / {s['max_fv_ratio_particles_L1']:.2f}x the FV error, the ratio at "
            f"the finest mesh {g['fv_drift_nodes_L1']:.2f}x / {g['fv_drift_particles_L1']:.2f}x that at the coarsest")
    text += (f"; Burgers (4 per cell) fitted orders {b['fitted_order_nodes_L1']:.2f} / "
             f"{b['fitted_order_particles_L1']:.2f}, "
             f"lowest successive {min(b['min_order_nodes_L1'], b['min_order_particles_L1']):.2f}"
             if b else "; Burgers not run")
    text += _other_runs(rows, name) + _jittered_clause(rows, name) + "; " + remedy_budget(t, name)
    removers = [f"{n} ({sc['max_fv_ratio_nodes_L1']:.2f}x / {sc['max_fv_ratio_particles_L1']:.2f}x FV)"
                for _, n, sc, *_ in scored if sc["removes_plateau"]]
    why = budget_clause(t)
    table = tuple({"remedy": n, "removes the Sod plateau": str(sc["removes_plateau"]),
                   "lowest Sod order (nodes / particles)": f"{sc['min_order_nodes_L1']:.2f} / "
                                                            f"{sc['min_order_particles_L1']:.2f}",
                   "largest FV ratio": f"{max(sc[f'max_fv_ratio_{m}'] for m in REMEDY_MEASURES):.2f}",
                   "Burgers goal": str(ok)} for _, n, sc, _, _, ok in scored)
    over = f"h = {num(own[0], 'h'):g} to {num(own[-1], 'h'):g}"
    sentence = (f"{name} keeps Sod's density error converging on {over} (lowest orders {s['min_order_nodes_L1']:.2f} "
                f"at the nodes, {s['min_order_particles_L1']:.2f} at the particles) within "
                f"{max(s[f'max_fv_ratio_{m}'] for m in REMEDY_MEASURES):.2f}x the finite-volume error"
                if s["removes_plateau"] else f"no remedy keeps Sod's density error converging on every mesh of "
                f"{over}; the closest is {name}")
    fv_ratio = max(s[f"max_fv_ratio_{m}"] for m in REMEDY_MEASURES)
    key = short(sentence, f"{name} keeps Sod's density error converging on {over}, within {fv_ratio:.2f}x the "
                          "finite-volume error", f"{name} keeps Sod's density error converging on {over} within "
                          f"{fv_ratio:.2f}x the FV error") if s["removes_plateau"] else short(sentence)
    failed = failures(rows, ("problem", "remedy", "h"), REMEDY_ERRORS, flag=None)
    why += "".join(f"; {line} (a failed run fails every condition it enters)" for line in failed)
    if s["removes_plateau"] and fv and b_ok:
        return Finding(CONFIRMED, "meets the goal: " + text + f"; {why}", sentence, table, failed, key)
    if removers:
        return Finding(PARTLY, text + f"; the Sod plateau is removed by {', '.join(removers)}; {why}", sentence,
                       table, failed, key)
    return Finding(REFUTED, f"closest: {text}; no remedy converges as the FV reference does on every Sod mesh; "
                            f"{why}", sentence, table, failed, key)


def _scored(rows: list[dict]) -> tuple[list, dict]:
    """E5's ranking of the remedies on their main series (:func:`remedy_series`), the best first:
    ``[(score, name, Sod assessment, within FV_FACTOR, Burgers assessment, Burgers goal), ...]`` and the
    Sod series of two meshes or more; the score is the conditions met, then the smallest largest FV ratio."""
    sod = {k: v for k, v in remedy_series(rows, "sod").items() if len(v) >= 2}
    burgers = remedy_series(rows, "burgers")
    scored, hs = [], sorted({num(r, "h") for v in sod.values() for r in v}, reverse=True)
    for name, series in sod.items():
        s = remedy_assessment(series)
        s["removes_plateau"] &= {num(r, "h") for r in series} == set(hs)  # a plateau needs every mesh
        fv = all(s[f"max_fv_ratio_{m}"] <= FV_FACTOR for m in REMEDY_MEASURES)
        b = remedy_assessment(burgers[name]) if len(burgers.get(name, [])) >= 2 else None
        b_ok = b is not None and b["removes_plateau"] and all(b[f"fitted_order_{m}"] >= BURGERS_ORDER
                                                              for m in REMEDY_MEASURES)
        worst_fv = max(s[f"max_fv_ratio_{m}"] for m in REMEDY_MEASURES)
        scored.append(((s["removes_plateau"] + fv + b_ok, -worst_fv if math.isfinite(worst_fv) else -math.inf),
                       name, s, fv, b, b_ok))
    scored.sort(key=lambda x: x[0], reverse=True)
    return scored, sod


#: the plain MPM series E5 (jittered) reads beside the named remedy
PLAIN = "MPM"


def jittered_runs(rows: list[dict], name: str) -> list[dict]:
    """E5 (jittered): every jittered run of remedy ``name`` on two meshes or more (per problem, particles per
    cell and seed), and plain MPM's on the same setting: ``[{problem, ppc, seed, holds, plain_holds, ratio}]``,
    ``holds`` when :func:`remedy_assessment` finds the plateau removed on the run's meshes (Sod: against the FV
    reference on the same meshes; Burgers: every successive order at least CONVERGING_ORDER), ``ratio`` the
    remedy's particle L1 over plain MPM's at the finest mesh both ran (nan without plain MPM)."""
    out = []
    for problem in ("sod", "burgers"):
        runs = _runs(rows, problem)
        plain = runs.get(PLAIN, {})
        for label, series in runs.get(name, {}).items():
            if "jittered" not in label or len(series) < 2:
                continue
            s = remedy_assessment(series)
            other = plain.get(label, [])
            p = remedy_assessment(other)["removes_plateau"] if len(other) >= 2 else None
            both = sorted({num(r, "h") for r in series} & {num(r, "h") for r in other})
            ratio = (num(_at(series, both[0]), "particles_L1") / num(_at(other, both[0]), "particles_L1")
                     if both else math.nan)
            out.append({"problem": problem, "ppc": series[0].get("ppc", ""), "seed": series[0].get("seed", ""),
                        "meshes": len(series), "holds": s["removes_plateau"], "plain_holds": p, "ratio": ratio,
                        "min_order": min(s["min_order_nodes_L1"], s["min_order_particles_L1"])})
    return out


def _jittered_clause(rows: list[dict], name: str) -> str:
    """E5's clause on ``name``'s jittered runs (:func:`jittered_runs`); empty without them."""
    runs = jittered_runs(rows, name)
    plain = [r["plain_holds"] for r in runs if r["plain_holds"] is not None]
    return (f"; on the jittered layouts (E5 (jittered)) it removes the plateau on {sum(r['holds'] for r in runs)} of "
            f"{len(runs)} runs, plain MPM on {sum(plain)} of {len(plain)}" if runs else "")


def _at(series: list[dict], h: float) -> dict:
    return next(r for r in series if num(r, "h") == h)


@claim("E5", source="the remedy E5 names, where the growth is worst: 4-8 particles per cell on jittered layouts",
       tables=(REMEDY_ERRORS,), study="remedies", problem="jittered",
       thresholds="E5's rule (a remedy removes the plateau: on Sod its successive orders as good as the FV "
                  f"reference's on the same meshes, within {ORDER_MARGIN:.2g} and at least {FLOOR_ORDER}, its FV "
                  f"ratio growing by at most {FV_DRIFT}x; on Burgers every successive order at least "
                  f"{CONVERGING_ORDER}) on each jittered run of the remedy E5 names (problem, particles per cell, "
                  "seed; the meshes of the tier), plain MPM judged beside it on the same runs: the named remedy "
                  "holds on every run -> confirmed, on none -> refuted, otherwise partly (holds on k of n runs)")
def _e5_jittered(t: Tables) -> Finding:
    """E5 names its remedy from the study's own setting (16 per cell on Sod, the regular layout). The growth
    of the particle error is worst at few particles per cell on irregular layouts, where the force
    quadrature errs most: the named remedy is judged again there, with plain MPM beside it on the same
    runs, so that a run both pass says the meshes are too coarse to show the plateau."""
    rows = t[REMEDY_ERRORS]
    scored, _ = _scored(rows)
    if not scored:
        return "not measured", "no remedy was run on two Sod meshes or more"
    name = scored[0][1]
    runs = jittered_runs(rows, name)
    if not runs:
        return "not measured", f"{name}, the remedy E5 names, was not run on a jittered layout on two meshes"
    k, n = sum(r["holds"] for r in runs), len(runs)
    plain = [r["plain_holds"] for r in runs if r["plain_holds"] is not None]
    hs = sorted({num(r, "h") for r in rows if r["remedy"] == name and r.get("layout") == "jittered"}, reverse=True)
    verdict = CONFIRMED if k == n else REFUTED if k == 0 else PARTLY
    per = "; ".join(f"{p} {ppc} per cell {sum(r['holds'] for r in runs if (r['problem'], str(r['ppc'])) == (p, ppc))}"
                    f" of {sum((r['problem'], str(r['ppc'])) == (p, ppc) for r in runs)}"
                    for p, ppc in dict.fromkeys((r["problem"], str(r["ppc"])) for r in runs))
    ratios = [r["ratio"] for r in runs]
    evidence = (f"{name} removes the plateau on {k} of {n} jittered runs ({per}) on h = {hs[0]:g}..{hs[-1]:g}, "
                f"plain MPM on {sum(plain)} of {len(plain)} of the same runs; the remedy's particle L1 over plain "
                f"MPM's at the finest mesh {span(ratios, '.2f')}; lowest successive order "
                f"{span([r['min_order'] for r in runs], '.2f')}")
    if plain and sum(plain) == len(plain):
        evidence += "; plain MPM passes on every run too, so these meshes do not reach the plateau"
    table = tuple({"run": f"{r['problem']} {r['ppc']} per cell, jittered {r['seed']}", "holds": str(r["holds"]),
                   "plain MPM holds": str(r["plain_holds"]), "L1 / plain MPM": f"{r['ratio']:.2f}",
                   "lowest order": f"{r['min_order']:.2f}"} for r in runs)
    sentence = (f"at 4-8 particles per cell on jittered layouts {name} removes the plateau on {k} of {n} runs, "
                f"plain MPM on {sum(plain)} of {len(plain)}")
    failed = failures([r for r in rows if r["remedy"] in (name, PLAIN) and r.get("layout") == "jittered"],
                      ("problem", "remedy", "h"), REMEDY_ERRORS, flag=None)
    return Finding(verdict, evidence + "".join(f"; {line}" for line in failed), sentence, table, failed,
                   short(sentence, f"{name} removes the plateau on {k} of {n} jittered runs"))


def budget_clause(t: Tables) -> str:
    """What the error budget found, from E1's result on Sod (:func:`~.budget.e1_result`), in the words
    E5's evidence uses: never that the remedies attack separate sources when the stages do not separate."""
    r = e1_result(select(t.get(SUBSETS) or [], problem="sod"))
    if r is None:
        return "the error budget (E1) was not run, so no remedy is tied to a stage of it"
    if r["separate"] == 0:
        return (f"the error budget's stages do not separate (E1: interactions {min(r['ratios']):.2g}-"
                f"{max(r['ratios']):.2g}x the gap), so no remedy is tied to one stage: each is judged by the "
                "plateau it should remove")
    return (f"the error budget's stages separate in {r['separate']} of {r['cases']} bases and runs (E1)"
            + (f", {', '.join(r['stages'])} dominating there" if r["stages"] else ", no stage dominating"))
