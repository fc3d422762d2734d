"""C3 and C15 on Sod: the criteria Sod shares with Burgers (:mod:`.shared`, :mod:`.mass`) read on Sod's
tables (``sod/ppc`` and the runs of ``sod/seeds`` for C3, the error budget's subsets and ``sod/mass`` for
C15).
"""

from __future__ import annotations

from mpm_fem.measure.claims.base import DIFFERS, Finding, Tables, claim, short
from mpm_fem.measure.claims.mass import MASS_RULE, mass_finding
from mpm_fem.measure.claims.rows import count_verdict, failures, num, saturation, select, span
from mpm_fem.measure.claims.shared import LUMPING_RULE, PPC_RULE, SATURATION, ppc_claim
from mpm_fem.measure.claims.sod_settings import SEEDS, _settings
from mpm_fem.measure.claims.stages import SUBSETS
from mpm_fem.measure.schema import SOD_MASS, SOD_PPC
from mpm_fem.measure.source import OPTIMAL_PPC


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
