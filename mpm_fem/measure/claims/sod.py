"""The Sod study's claims: C3 and C15 on Sod, C11 (the error at the particles stops converging or
diverges), C12 (the error at the waves), C14 (new extrema at cell crossings) and E3 (MPM within a
constant factor of the fixed-mesh FEM), from ``sod/*``.

C11, C12 and E3 are judged for every setting of the convergence study (particles per cell, CFL); the
headline verdict is the one on the settings the source prescribes (4-8 particles per cell): their
common verdict, ``partly`` when they differ. C11 and E3 read every run (``sod/seeds``: the regular
layout and the jittered ones) and count an order or a ratio as above or below a threshold only when
its range over the seeds is (:mod:`mpm_fem.measure.spread`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import mpm_fem.measure.claims.shape as shape
from baselines.exact.riemann import wave_positions
from mpm_fem.measure.claims.base import CONFIRMED, DIFFERS, PARTLY, REFUTED, Finding, Tables, claim, short
from mpm_fem.measure.claims.drift import mechanism
from mpm_fem.measure.claims.identification import source_matching
from mpm_fem.measure.claims.mass import MASS_RULE, mass_finding
from mpm_fem.measure.claims.rows import (
    CONVERGING_ORDER,
    FLOOR_ORDER,
    count_verdict,
    failures,
    num,
    saturation,
    select,
    span,
)
from mpm_fem.measure.claims.rules import rule
from mpm_fem.measure.claims.shared import LUMPING_RULE, PPC_RULE, SATURATION, ppc_claim
from mpm_fem.measure.claims.stages import SUBSETS
from mpm_fem.measure.regions import REGION_NAMES
from mpm_fem.measure.schema import (
    DRIFT,
    SOD_CONVERGENCE,
    SOD_EXTREMA,
    SOD_MASS,
    SOD_PPC,
    SOD_REGIONS,
    SOD_SEEDS,
)
from mpm_fem.measure.source import OPTIMAL_PPC, SOD
from mpm_fem.measure.spread import Spread, by_mesh, order_spreads, spread
from mpm_fem.measure.tables import setting
from mpm_fem.problems.sod import SodSettings

CONVERGENCE, SEEDS = SOD_CONVERGENCE.name, SOD_SEEDS.name
#: C11, E3: an order or a ratio is judged only over at least MIN_RUNS runs on each mesh (the regular
#: layout and five jittered ones), and C11 needs FLOOR_MESHES such meshes; its trend is read from the
#: orders between the last FLOOR_STEPS + 1 of them.
MIN_RUNS, FLOOR_MESHES, FLOOR_STEPS = (int(rule(k)) for k in ("MIN_RUNS", "FLOOR_MESHES", "FLOOR_STEPS"))
#: C11: the errors judged (the slides: "the overall error at particles as density, energy") and the
#: one shown beside them (the nodal density, which the source's table follows).
C11_JUDGED = {"particle density": "particles_L1", "particle energy": "energy_L1"}
C11_BESIDE = {"nodal density": "nodes_L1"}
#: C12: the waves (the rarefaction's edges, the contact, the shock front, by their region numbers) carry
#: the error where their error per unit length is at least WAVE_DENSITY times the smooth region's.
WAVE_NAMES = ("rarefaction head", "rarefaction tail", "contact", "shock front")
WAVE_REGIONS = tuple(REGION_NAMES.index(name) for name in WAVE_NAMES)
WAVE_DENSITY = rule("WAVE_DENSITY")
#: C14: a crossing particle becomes a new extremum at least EXTREMA_RATIO times as often as a moving
#: particle that does not cross (``moving_ratio``: its definition of moving is recorded with the table).
EXTREMA_RATIO = rule("EXTREMA_RATIO")
#: E3: MPM's error over the fixed-mesh FEM's (lumped mass, as MPM's) on the finest mesh within E3_FACTOR
#: of that ratio on the coarsest, at the nodes and at the particles.
E3_FACTOR = rule("E3_FACTOR")
E3_WHERE = {"particles": "particles_L1", "nodes": "nodes_L1"}
#: E3: the methods whose density L1 the evidence names on the finest mesh.
SIDE_BY_SIDE = {"MPM nodes": "mpm_nodes_L1", "FEM consistent": "fem_consistent_L1", "FEM lumped": "fem_lumped_L1",
                "FV": "fv_L1"}


class Setting(NamedTuple):
    """A run setting of the Sod tables: particles per cell and CFL number (the key of a per-setting verdict)."""

    ppc: int
    cfl: float


def _settings(rows: list[dict]) -> list[Setting]:
    """The settings of ``rows``, in their order; FEM rows (no ``ppc``) left out."""
    found = dict.fromkeys(Setting(int(num(r, "ppc")), num(r, "cfl")) for r in rows if math.isfinite(num(r, "ppc")))
    return list(found)


def _label(n: int, cfl: float) -> str:
    return f"{n} ppc, CFL {cfl:g}"


def _prescribed(n: int) -> bool:
    return OPTIMAL_PPC[0] <= n <= OPTIMAL_PPC[1]


def headline(verdicts: dict[tuple, str]) -> str:
    """The verdict on the settings the source prescribes (:data:`OPTIMAL_PPC` particles per cell): their
    common verdict when they agree, ``partly`` when they differ, ``not measured`` when none is measured."""
    found = [v for (n, _), v in verdicts.items() if _prescribed(n)]
    measured = set(found) - {"not measured"}
    if not measured:
        return "not measured"
    return found[0] if len(set(found)) == 1 else PARTLY


def _per_setting(criterion, rows: list[dict], *more) -> tuple[dict, dict]:
    verdicts, lines = {}, {}
    for k in _settings(rows):
        verdicts[k], lines[k] = criterion(select(rows, ppc=k.ppc, cfl=k.cfl), k.ppc, k.cfl, *more)
    return verdicts, lines


def _settings_text(verdicts: dict, lines: dict) -> str:
    """One clause per setting, the prescribed ones first."""
    if not verdicts:
        return "no row with a setting (ppc, cfl)"
    order = sorted(verdicts, key=lambda k: (not _prescribed(k.ppc), -k.ppc, k.cfl))
    return "; ".join(f"{_label(*k)}: {verdicts[k]}, {lines[k]}" for k in order)


def _judged_orders(rows: list[dict], key: str) -> list[tuple]:
    """``[(h_1, h_2, Spread)]`` between successive meshes with at least MIN_RUNS runs each."""
    meshes = {h for h, runs in by_mesh(rows, key).items() if sum(map(math.isfinite, runs.values())) >= MIN_RUNS}
    kept = [r for r in rows if num(r, "h") in meshes]
    return [(a, b, o) for a, b, o in order_spreads(kept, key) if o.n >= MIN_RUNS]


def _c11_setting(rows: list[dict], n: int, cfl: float) -> tuple[str, str, dict]:
    """C11 on one setting: the shape of every quantity (:mod:`.shape`), the size of the particle density at
    the coarsest mesh, the verdict and one row of the Finding's table."""
    orders = {name: _judged_orders(rows, key) for name, key in {**C11_JUDGED, **C11_BESIDE}.items()}
    meshes = len(orders["particle density"]) + 1
    row = {"setting": _label(n, cfl)}
    if meshes < FLOOR_MESHES:
        # the cell says why: the sentence may still quote this setting's size against the source's table
        row["verdict"] = f"not measured ({meshes} of the {FLOOR_MESHES} meshes the shape needs have {MIN_RUNS} runs)"
        return "not measured", f"{meshes} meshes with {MIN_RUNS} runs, the shape needs {FLOOR_MESHES}", row
    shapes = {name: shape.shape([o for _, _, o in found]) for name, found in orders.items()}
    h, ratio = shape.size(rows, C11_JUDGED["particle density"], 0)
    judged = [shapes[name] for name in C11_JUDGED]
    levels = all(s == shape.LEVELS for s in judged)
    verdict = (DIFFERS if shape.GROWS in judged or all(s == shape.STALLS for s in judged)
               else CONFIRMED if levels and shape.same_size(ratio)
               else REFUTED if all(s == shape.CONVERGES for s in judged) else PARTLY)
    for name, found in orders.items():
        row[name] = shape.shape_text(shapes[name], found)
    row[f"particle density / source at h = {h:g}"] = ratio.text()
    row["verdict"] = verdict
    text = ", ".join(f"{name} {shape.shape_text(shapes[name], found)} [ranges {_orders_text(found)}]"
                     for name, found in orders.items())
    return verdict, text + f", particle density / source at h = {h:g} {ratio.text()}", row


def _orders_text(orders: list[tuple]) -> str:
    return ", ".join(o.text() for _, _, o in orders)


def _matching(t: Tables) -> tuple[dict, str]:
    """The source-matching settings of Sod, ``{(ppc, cfl): "nodes L1, rank 1"}``, and where they come
    from: the identification table (``source_matching``), or, without it, the setting and density of
    the convergence table with the smallest mean |log(measured / source)| (said so)."""
    found = {}
    for r in source_matching(t, "sod"):
        found.setdefault(Setting(int(num(r, "ppc")), num(r, "cfl")), f"{r['quantity']} {r['norm']}, rank {r['rank']}")
    if found:
        return found, "the identification table"
    rows, misfit, closest, what = t.get(CONVERGENCE, []), math.inf, None, ""
    for k in _settings(rows):
        for q in ("nodes", "particles"):
            for norm in ("L1", "L2"):
                m = shape.misfit(select(rows, ppc=k.ppc, cfl=k.cfl), f"ratio_{q}_{norm}")
                if math.isfinite(m) and (closest is None or m < misfit):
                    misfit, closest, what = m, k, f"{q} {norm}, closest in {CONVERGENCE}"
    if closest is None:
        return {}, "no identification table and no ratio to the source"
    return {closest: what}, (f"no identification table: the closest setting of the study's "
                             f"({CONVERGENCE}, mean |log ratio| {misfit:.2f})")


def _reproduction(t: Tables, matching: dict) -> str:
    """How closely the best source-matching setting of the convergence table reproduces the source: the
    span of its measured/source ratios over the meshes."""
    for (n, cfl), what in matching.items():
        quantity, norm = what.split(",")[0].split()
        rows = select(t.get(CONVERGENCE, []), ppc=n, cfl=cfl)
        ratios = [num(r, f"ratio_{quantity}_{norm}") for r in rows]
        ratios = [x for x in ratios if math.isfinite(x)]
        if ratios:
            where = "nodal" if quantity == "nodes" else "particle"
            text = (f"at {n} per cell and CFL {cfl:g} the {where} density {norm} is {span(ratios)} times the "
                    f"source's on {len(ratios)} meshes (the regular layout)")
            jittered = [(num(r, f"jittered_{quantity}_{norm}_lo") / num(r, f"source_{norm}"),
                         num(r, f"jittered_{quantity}_{norm}_hi") / num(r, f"source_{norm}")) for r in rows]
            jittered = [(lo, hi) for lo, hi in jittered if math.isfinite(lo) and math.isfinite(hi)]
            if jittered:
                text += (f", {min(lo for lo, _ in jittered):.2f} to {max(hi for _, hi in jittered):.2f} times over "
                         f"the jittered layouts on {len(jittered)} meshes")
            return text
    return ""


def _c11_sentence(rows: list[dict], verdicts: dict, reproduction: str) -> str:
    """The plain sentence: what the particle density does at the source's particles per cell, with its
    mean orders from where it departs, and where the source's table is reproduced."""
    prescribed = [k for k in verdicts if _prescribed(k.ppc) and verdicts[k] != "not measured"]
    shapes, tails = {}, []
    for k in prescribed:
        found = _judged_orders(select(rows, ppc=k.ppc, cfl=k.cfl), C11_JUDGED["particle density"])
        shapes[k] = shape.shape([o for _, _, o in found])
        start = shape.growth_start(found)
        tails += [o for h1, _, o in found if shapes[k] != shape.GROWS or h1 <= start]
    if not prescribed:
        return reproduction
    ppcs = "-".join(map(str, sorted({k.ppc for k in prescribed})))
    kinds = set(shapes.values())
    what = {shape.GROWS: "grows under refinement", shape.LEVELS: "converges, then levels off",
            shape.STALLS: "stalls from the coarsest mesh", shape.CONVERGES: "keeps converging"}
    does = what.get(kinds.pop(), "changes order undecidedly") if len(kinds) == 1 else "behaves differently by setting"
    mean = [o.mean for o in tails]
    text = (f"at {ppcs} particles per cell the particle density error {does} (mean orders "
            f"{max(mean):.2f} to {min(mean):.2f})")
    return text + (f"; {reproduction}" if reproduction else "")


@claim("C11", source=f"density L1 {SOD[max(SOD)][0]:.3g} at h = {max(SOD):g}, orders near 0.9 before it levels at "
                     f"{SOD[min(SOD)][0]:.3g}; the error at particles (density, energy) stops converging as h shrinks",
       tables=(SEEDS, CONVERGENCE), study="sod",
       thresholds=f"per setting and quantity, over the regular and the jittered layouts (orders paired by seed, "
                  f"judged between meshes with at least {MIN_RUNS} runs, at least {FLOOR_MESHES} meshes), the "
                  f"source's shape: the first order at least {CONVERGING_ORDER} and the last {FLOOR_STEPS} below "
                  f"{FLOOR_ORDER} over every seed, not all below 0 (levels off). The particle density and energy "
                  f"both level off with the density within {shape.SAME_SIZE:g}x the source's at the coarsest mesh -> "
                  f"confirmed; a judged error whose orders are below 0 over every seed from some refinement on "
                  "(grows: a divergence, not a plateau) or that never converges -> differs; both keep converging "
                  f"-> refuted; else partly; the nodal density beside, not judged. Headline: the settings with "
                  f"{OPTIMAL_PPC[0]}-{OPTIMAL_PPC[1]} particles per cell, their common verdict, partly when they "
                  "differ; the source-matching setting (identification) in its own column")
def _c11(t: Tables) -> Finding:
    """The orders are paired by seed: each run of a layout on one mesh with the run of the same seed on
    the next mesh, the regular layout being seed 0; the range over seeds holds the order of every layout.
    A plateau and a growing error are different behaviours: only the first is the source's. The
    mechanism of the growth is the drift study's finding, quoted from its table (not judged here)."""
    rows = t[SEEDS]
    verdicts, lines, table = {}, {}, []
    for k in _settings(rows):
        verdicts[k], lines[k], row = _c11_setting(select(rows, ppc=k.ppc, cfl=k.cfl), k.ppc, k.cfl)
        table.append(row)
    matching, whence = _matching(t)
    for row, k in zip(table, verdicts, strict=True):
        row["source-matching"] = matching.get(k, "")
    table += [{"setting": _label(*k), "verdict": "not run in sod/seeds", "source-matching": v}
              for k, v in matching.items() if k not in verdicts]
    reproduction = _reproduction(t, matching)
    density = [f"{v} ({k.ppc} ppc at CFL {k.cfl:g})" for k, v in verdicts.items() if _prescribed(k.ppc)]
    evidence = (f"particle density at {OPTIMAL_PPC[0]}-{OPTIMAL_PPC[1]} per cell: "
                + ", ".join(density) + "; " + _settings_text(verdicts, lines)
                + f"; source-matching settings from {whence}: "
                + (", ".join(f"{_label(*k)} ({v})" for k, v in matching.items()) or "none")
                + (f"; {reproduction}" if reproduction else "")
                + f". Mechanism ({DRIFT.name}): {mechanism(t)}")
    sentence = _c11_sentence(rows, verdicts, reproduction)
    return Finding(headline(verdicts), evidence, sentence, tuple(table), key=short(sentence, sentence.split("; ")[0]))


def region_lengths(t: Tables) -> dict[int, float] | None:
    """The length of each region of ``sod/regions`` (:mod:`mpm_fem.measure.regions`), from the exact wave
    positions at the recorded ``T`` and the recorded half-width; None when the half-width is not recorded."""
    w = num({"w": setting(t, SOD_REGIONS.name, "region_half_width")}, "w")
    if not w > 0:
        return None
    gas = SodSettings()
    waves = wave_positions(num({"T": setting(t, SOD_REGIONS.name, "T", str(gas.T))}, "T"), gas.left, gas.right)
    head, tail, contact, shock = (waves[k] for k in ("rarefaction_head", "rarefaction_tail", "contact", "shock"))
    wave = w + w
    # the tube is [0, 1]: the undisturbed gas lies left of the head and right of the shock
    return {REGION_NAMES.index("undisturbed"): (head - w) + (1 - (shock + w)),
            REGION_NAMES.index("smooth"): contact - head - wave - wave, REGION_NAMES.index("behind shock"):
            shock - contact - wave, **{REGION_NAMES.index(name): wave for name in WAVE_NAMES}}


def _density(row: dict, regions, lengths: dict) -> float:
    """The error per unit length of ``regions`` together in one row of ``sod/regions``."""
    return sum(num(row, f"share_{k}") for k in regions) * num(row, "L1") / sum(lengths[k] for k in regions)


_SMOOTH = (REGION_NAMES.index("smooth"),)


@claim("C12", source="regions 1 and 3 rarefaction edges, 4 contact, 6 shock front, 2 smooth, 5 behind the shock",
       tables=(SOD_REGIONS.name,), study="sod",
       thresholds=f"per setting, the named wave regions ({', '.join(WAVE_NAMES)}) carry the error on a mesh when "
                  f"their error per unit length is at least {WAVE_DENSITY:g}x the smooth region's (MPM nodal L1, "
                  "regular layout; the threshold is the study's, the slides state none) on every mesh -> confirmed, "
                  f"on some -> partly, on none -> differs. Headline: the settings with {OPTIMAL_PPC[0]}-"
                  f"{OPTIMAL_PPC[1]} particles per cell, their common verdict, partly when they differ; the waves' "
                  "share of the error beside")
def _c12(t: Tables) -> Finding:
    """The slides say where the error sits, not how much of it: the regions are ranked by their error per
    unit length, so that a long smooth region does not outweigh a narrow wave by its length alone."""
    lengths = region_lengths(t)
    if lengths is None:
        return Finding("not measured", f"no region half-width recorded with {SOD_REGIONS.name}")
    rows = select(t[SOD_REGIONS.name], method="MPM nodes")
    verdicts, lines, table = {}, {}, []
    for k in _settings(rows):
        mine = sorted(select(rows, ppc=k.ppc, cfl=k.cfl), key=lambda r: -num(r, "h"))
        factors = [_density(r, WAVE_REGIONS, lengths) / _density(r, _SMOOTH, lengths) for r in mine]
        hits = sum(f >= WAVE_DENSITY for f in factors)
        verdicts[k] = count_verdict(hits, len(mine), DIFFERS)
        share = [sum(num(r, f"share_{region}") for region in WAVE_REGIONS) for r in mine]
        ranked = sorted(lengths, key=lambda region: -_density(mine[-1], (region,), lengths))
        lines[k] = (f"the waves' error per unit length {span(factors, '.1f')}x the smooth region's, at least "
                    f"{WAVE_DENSITY:g} on {hits} of {len(mine)} meshes; share of the nodal L1 "
                    f"{share[0]:.0%} at h = {mine[0]['h']} -> {share[-1]:.0%} at h = {mine[-1]['h']}; ranked "
                    f"by error per unit length at h = {mine[-1]['h']}: " + ", ".join(REGION_NAMES[r] for r in ranked))
        table.append({"setting": _label(*k), "waves / smooth per unit length": span(factors, ".1f"),
                      "waves' share": f"{share[0]:.0%} -> {share[-1]:.0%}", "meshes": f"{hits} of {len(mine)}",
                      "verdict": verdicts[k]})
    head = [r for r, k in zip(table, verdicts, strict=True) if _prescribed(k.ppc)]
    sentence = ("the error per unit length at the waves is " + ", ".join(
        f"{r['waves / smooth per unit length']} ({r['setting']})" for r in head) + " times the smooth region's")
    waves = [float(x) for r in head for x in r["waves / smooth per unit length"].split("..") if x != "-"]
    key = short(sentence, f"the error per unit length at the waves is {span(waves, '.1f')} times the smooth region's "
                          f"at {OPTIMAL_PPC[0]}-{OPTIMAL_PPC[1]} per cell" if waves else sentence)
    return Finding(headline(verdicts), "the waves' error per unit length over the smooth region's at "
                   f"{OPTIMAL_PPC[0]}-{OPTIMAL_PPC[1]} per cell: " + ", ".join(
                       f"{r['waves / smooth per unit length']} ({r['setting']})" for r in head)
                   + "; " + _settings_text(verdicts, lines), sentence, tuple(table), key=key)


@claim("C14", source="new extrema appear where particles cross cells", tables=(SOD_EXTREMA.name,), study="sod",
       thresholds=f"a particle crossing a node becomes a new density extremum at least {EXTREMA_RATIO:g}x as often "
                  "per particle-step as a moving particle that does not cross, on every setting and mesh -> "
                  "confirmed, on some -> partly, on none -> refuted; the same for the energy, and the rate against "
                  "every particle that does not cross (those at rest included), reported beside")
def _c14(t: Tables) -> Finding:
    """The exact density is monotone in each region, so every new extremum is spurious. A particle at
    rest ahead of the waves never crosses and never becomes an extremum: comparing with every
    particle that does not cross would count those as evidence, so the comparison is with the moving ones."""
    rows = t[SOD_EXTREMA.name]
    hits = sum(num(r, "density_moving_ratio") >= EXTREMA_RATIO for r in rows)
    table = tuple({"setting": _label(n, cfl),
                   "density": span([num(r, "density_moving_ratio") for r in select(rows, ppc=n, cfl=cfl)], ".1f"),
                   "energy": span([num(r, "energy_moving_ratio") for r in select(rows, ppc=n, cfl=cfl)], ".1f")}
                  for n, cfl in _settings(rows))
    sentence = (f"a particle crossing a node becomes a new density extremum "
                f"{span([num(r, 'density_moving_ratio') for r in rows], '.1f')} times as often as a moving particle "
                f"that does not cross, at least {EXTREMA_RATIO:g} times on {hits} of {len(rows)} settings and meshes "
                "(regular layout)")
    key = short(sentence, f"a particle crossing a node becomes a new density extremum "
                          f"{span([num(r, 'density_moving_ratio') for r in rows], '.1f')} times as often as a moving "
                          f"one that does not, at least {EXTREMA_RATIO:g}x on {hits} of {len(rows)}",
                f"crossing a node makes a particle a new density extremum "
                f"{span([num(r, 'density_moving_ratio') for r in rows], '.1f')} times as often as moving ones that "
                "do not")
    per_setting = "; ".join(
        f"{_label(n, cfl)}: density {span([num(r, 'density_moving_ratio') for r in mine], '.1f')}, energy "
        f"{span([num(r, 'energy_moving_ratio') for r in mine], '.1f')}"
        for n, cfl in _settings(rows) for mine in [select(rows, ppc=n, cfl=cfl)])
    return Finding(count_verdict(hits, len(rows)), (
        f"crossing / moving non-crossing rate of new density extrema "
        f"{span([num(r, 'density_moving_ratio') for r in rows], '.1f')}, at least {EXTREMA_RATIO:g} on {hits} of "
        f"{len(rows)} settings and meshes; {per_setting}; against every non-crossing particle (at rest included): "
        f"density {span([num(r, 'density_rate_ratio') for r in rows], '.0f')}; moving particles "
        f"{span([num(r, 'moving_share') for r in rows], '.0%')} of the non-crossing particle-steps (|v_p| > "
        f"{num(rows[0], 'moving_speed'):.3g}); the regular layout only (sod/extrema holds no seeds)"),
        sentence, table, key=key)


def _seeded_saturation(rows: list[dict], key: str) -> dict[float, list[int]]:
    """``{h: [fewest particles per cell within SATURATION of the smallest error, per run]}`` over the
    runs of ``sod/seeds`` (the regular layout and each jittered seed) at the CFL shared by the most
    particles-per-cell settings; only meshes where every run holds every such setting."""
    cfls = {}
    for n, cfl in _settings(rows):
        cfls.setdefault(cfl, set()).add(n)
    if not cfls:
        return {}
    cfl = max(cfls, key=lambda c: len(cfls[c]))
    ppcs = cfls[cfl]
    found: dict[float, list[int]] = {}
    for h in sorted({num(r, "h") for r in rows}, reverse=True):
        at = select(rows, cfl=cfl, h=h)
        per_seed = {}
        for r in at:
            per_seed.setdefault(r["seed"], []).append(r)
        runs = [v for v in per_seed.values() if {int(num(r, "ppc")) for r in v} == ppcs]
        if runs and len(runs) == len(per_seed):
            found[h] = [saturation(v, key, SATURATION) for v in runs]
    return found


@claim("C3", source=f"{OPTIMAL_PPC[0]}-{OPTIMAL_PPC[1]} particles per cell", tables=(SOD_PPC.name,), study="sod",
       problem="sod", thresholds=PPC_RULE + "; where sod/seeds holds several particles per cell on the regular and "
       "the jittered layouts, each of its meshes and errors is one more case, holding when the fewest particles "
       "per cell near the smallest error lies in the range on every run")
def _c3_sod(t: Tables) -> Finding:
    ok = select(t[SOD_PPC.name], ok="True")
    groups = {f"h = {h}": select(ok, h=h) for h in dict.fromkeys(r["h"] for r in ok)}
    verdict, evidence = ppc_claim(groups, ("nodes_L1", "particles_L1"))
    seeds = t.get(SEEDS) or []
    table = [{"run": "regular (sod/ppc)", "case": f"{g}, {k.split('_')[0]}",
              "fewest near the smallest": str(saturation(rows, k, SATURATION))}
             for g, rows in groups.items() for k in ("nodes_L1", "particles_L1")]
    seeded = {k: _seeded_saturation(seeds, k) for k in ("nodes_L1", "particles_L1")}
    cases = [(k, h, ns) for k, by_h in seeded.items() for h, ns in by_h.items()]
    if cases:
        held = sum(all(OPTIMAL_PPC[0] <= n <= OPTIMAL_PPC[1] for n in ns) for _, _, ns in cases)
        base = sum(OPTIMAL_PPC[0] <= int(r["fewest near the smallest"]) <= OPTIMAL_PPC[1] for r in table)
        verdict = count_verdict(base + held, len(table) + len(cases), DIFFERS)
        evidence += ("; over the regular and jittered layouts (sod/seeds), the fewest per cell near the smallest "
                     "error, its range over the runs: " + "; ".join(
                         f"h = {h:g}, {k.split('_')[0]}: {span(ns, 'g')}" for k, h, ns in cases))
        table += [{"run": f"{len(ns)} runs (sod/seeds)", "case": f"h = {h:g}, {k.split('_')[0]}",
                   "fewest near the smallest": span(ns, "g")} for k, h, ns in cases]
    else:
        evidence += "; sod/seeds holds no range over layouts: the regular layout only"
    inside = [r for r in table if all(OPTIMAL_PPC[0] <= float(x) <= OPTIMAL_PPC[1]
                                      for x in r["fewest near the smallest"].split(".."))]
    sentence = (f"on Sod the fewest particles per cell within {SATURATION:.0%} of the smallest error lie in the "
                f"source's {OPTIMAL_PPC[0]}-{OPTIMAL_PPC[1]} on {len(inside)} of {len(table)} meshes and errors")
    key = short(sentence, f"on Sod the fewest particles per cell within {SATURATION:.0%} of the smallest error lie in "
                          f"{OPTIMAL_PPC[0]}-{OPTIMAL_PPC[1]} on {len(inside)} of {len(table)} meshes and errors")
    failed = (failures(t[SOD_PPC.name], ("ppc", "h"), SOD_PPC.name)
              + failures(seeds, ("ppc", "cfl", "layout", "h"), SEEDS))
    evidence += "".join(f"; {line} (left out)" for line in failed)
    return Finding(verdict, evidence, sentence, tuple(table), failed, key)


@claim("C15", source="one of four error sources", tables=(SUBSETS,), study="sod", problem="sod",
       thresholds=MASS_RULE + ". Second reading: " + LUMPING_RULE
       + " (Sod: density L1, MPM over nodes and over particles, FEM over nodes)")
def _c15_sod(t: Tables) -> Finding:
    """The direct measurement: the error budget's mass stage, alone and in its interactions with the
    other stages. The second reading compares the same run with the consistent and with the lumped
    mass: in MPM the consistent particle mass matrix spreads the noise of the node crossings over the
    grid instead of removing it; the fixed-mesh FEM, free of that noise, shows what the mass matrix
    alone does. Where the interactions swamp the direct measurement on every norm and mesh, the second
    reading decides."""
    rows = t.get(SOD_MASS.name) or []
    ratios = {label: {r["h"]: num(r, key) for r in rows}
              for label, key in (("MPM nodes", "mpm_consistent_over_lumped_nodes"),
                                 ("MPM particles", "mpm_consistent_over_lumped_particles"),
                                 ("FEM", "fem_consistent_over_lumped"))}
    return mass_finding(t, "sod", ratios if rows else None, ("MPM nodes", "MPM particles"), "Sod",
                        f"no table `{SOD_MASS.name}.csv`")


def _growth(rows: list[dict], convergence: list[dict], key: str) -> tuple[Spread, float, float]:
    """The spread over seeds of ``(E(h_f) / FEM(h_f)) / (E(h_c) / FEM(h_c))``: the change of MPM's error
    over the lumped FEM's from the coarsest mesh ``h_c`` to the finest ``h_f`` with at least MIN_RUNS runs."""
    fem = {num(r, "h"): num(r, "fem_lumped_L1") for r in convergence}
    meshes = {h: runs for h, runs in by_mesh(rows, key).items() if sum(map(math.isfinite, runs.values())) >= MIN_RUNS}
    if len(meshes) < 2:
        return spread(()), math.nan, math.nan
    coarse, fine = max(meshes), min(meshes)
    fem_change = fem.get(fine, math.nan) / fem.get(coarse, math.nan)
    seeds = sorted(meshes[coarse].keys() & meshes[fine].keys(), key=repr)
    return spread(meshes[fine][k] / meshes[coarse][k] / fem_change for k in seeds), coarse, fine


def _e3_setting(rows: list[dict], n: int, cfl: float, convergence: list[dict]) -> tuple[str, str]:
    found, parts = [], []
    for where, key in E3_WHERE.items():
        g, coarse, fine = _growth(rows, convergence, key)
        if g.n == 0:
            return "not measured", f"fewer than two meshes with {MIN_RUNS} runs"
        which = ("constant" if g.above(1 / E3_FACTOR) and g.below(E3_FACTOR) else "MPM's grows" if g.above(E3_FACTOR)
                 else "FEM's grows" if g.below(1 / E3_FACTOR) else "undecided")
        found.append(which)
        parts.append(f"{where} x{g.text()} ({which})")
    verdict = (CONFIRMED if all(w == "constant" for w in found)
               else REFUTED if all(w.endswith("grows") for w in found) else PARTLY)
    return verdict, ", ".join(parts) + f" from h = {coarse:g} to {fine:g}"


@claim("E3", source="MPM beside fixed-mesh FEM (consistent and lumped) and a finite-volume reference",
       tables=(SEEDS, CONVERGENCE), study="sod",
       thresholds=f"per setting, over the regular and the jittered layouts (paired by seed): MPM's density L1 over "
                  f"the lumped FEM's on the finest mesh with at least {MIN_RUNS} runs within {E3_FACTOR:g}x of that "
                  f"ratio on the coarsest (the change between them in [1/{E3_FACTOR:g}, {E3_FACTOR:g}) over every "
                  "seed), at the nodes and at the particles -> confirmed; both outside over every seed -> refuted, "
                  "saying which error grows; else partly. Headline: the settings with "
                  f"{OPTIMAL_PPC[0]}-{OPTIMAL_PPC[1]} particles per cell, their common verdict, partly when they "
                  "differ")
def _e3(t: Tables) -> Finding:
    """MPM and the fixed-mesh FEM run on the same meshes with the same lumped mass, each with its own
    artificial viscosity and time step (the FEM's on every cell at CFL 0.3, MPM's in compression at CFL
    0.05: the settings table), so their ratio compares the two methods as each is run, not the particles
    alone. MPM's error is read at the particles and at the nodes, the FEM's at its nodes. Each change is a
    range over the runs (the regular layout and the jittered seeds, paired by seed)."""
    verdicts, lines = _per_setting(_e3_setting, t[SEEDS], t[CONVERGENCE])
    fv = setting(t, CONVERGENCE, "fv.scheme", "FV") + ("" if setting(t, CONVERGENCE, "fv.limiter")
                                                       else ", limiter not recorded")
    fem = "FEM: " + setting(t, CONVERGENCE, "fem.viscosity", "viscosity variant not recorded")
    last = min(t[CONVERGENCE], key=lambda r: num(r, "h"))
    rows = t[SEEDS]
    growth = {k: _growth(select(rows, ppc=k.ppc, cfl=k.cfl), t[CONVERGENCE], E3_WHERE["particles"])[0]
              for k in verdicts if _prescribed(k.ppc)}
    table = []
    for k in verdicts:
        row = {"setting": _label(*k)}
        for where, key in E3_WHERE.items():
            g, coarse, fine = _growth(select(rows, ppc=k.ppc, cfl=k.cfl), t[CONVERGENCE], key)
            row[f"MPM/FEM at the {where}, finest over coarsest"] = g.text()
        row["verdict"] = verdicts[k]
        table.append(row)
    meshes = [h for k in growth for h in _growth(select(rows, ppc=k.ppc, cfl=k.cfl), t[CONVERGENCE],
                                                  E3_WHERE["particles"])[1:] if math.isfinite(h)]
    where = f" from h = {max(meshes):g} to {min(meshes):g}" if meshes else ""
    sentence = (f"on the same meshes{where} MPM's particle density error over the fixed-mesh FEM's changes by a "
                f"factor {span([g.mean for g in growth.values()], '.1f')} at {OPTIMAL_PPC[0]}-{OPTIMAL_PPC[1]} "
                f"particles per cell (mean over the layouts; {min(g.lo for g in growth.values()):.1f} to "
                f"{max(g.hi for g in growth.values()):.1f} over every layout; a constant factor would stay within "
                f"{E3_FACTOR:g})")
    return Finding(headline(verdicts), (
        f"MPM/FEM particle error, finest over coarsest mesh at {OPTIMAL_PPC[0]}-{OPTIMAL_PPC[1]} per cell: "
        + ", ".join(f"x{g.text()} ({k.ppc} ppc at CFL {k.cfl:g})" for k, g in growth.items()) + "; "
        + _settings_text(verdicts, lines)
        + f"; density L1 at h = {last['h']} ({_label(int(num(last, 'ppc')), num(last, 'cfl'))}, regular): "
        + ", ".join(f"{m} {num(last, c):.3g}" for m, c in SIDE_BY_SIDE.items()) + f"; FV: {fv}; {fem}"),
        sentence, tuple(table), key=short(
            f"MPM's particle density error over the fixed-mesh FEM's changes by a factor "
            f"{span([g.mean for g in growth.values()], '.1f')}{where} at {OPTIMAL_PPC[0]}-{OPTIMAL_PPC[1]} per cell",
            f"MPM's particle density error over the fixed-mesh FEM's changes by a factor "
            f"{span([g.mean for g in growth.values()], '.1f')} at {OPTIMAL_PPC[0]}-{OPTIMAL_PPC[1]} per cell"))
