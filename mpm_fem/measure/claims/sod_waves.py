"""The Sod study's claims on where the error sits: C12 (the error at the waves) and C14 (new extrema at
cell crossings), from ``sod/regions`` and ``sod/extrema``; C12 is judged for every setting of the
convergence study (:mod:`.sod_settings`).
"""

from __future__ import annotations

from baselines.exact.riemann import wave_positions
from mpm_fem.measure.claims.base import DIFFERS, Finding, Tables, claim, short
from mpm_fem.measure.claims.rows import count_verdict, num, select, span
from mpm_fem.measure.claims.rules import rule
from mpm_fem.measure.claims.sod_settings import _label, _prescribed, _settings, _settings_text, headline
from mpm_fem.measure.regions import REGION_NAMES
from mpm_fem.measure.schema import SOD_EXTREMA, SOD_REGIONS
from mpm_fem.measure.source import OPTIMAL_PPC
from mpm_fem.measure.tables import setting
from mpm_fem.problems.sod import SodSettings

#: C12: the waves (the rarefaction's edges, the contact, the shock front, by their region numbers) carry
#: the error where their error per unit length is at least WAVE_DENSITY times the smooth region's.
WAVE_NAMES = ("rarefaction head", "rarefaction tail", "contact", "shock front")
WAVE_REGIONS = tuple(REGION_NAMES.index(name) for name in WAVE_NAMES)
WAVE_DENSITY = rule("WAVE_DENSITY")
#: C14: a crossing particle becomes a new extremum at least EXTREMA_RATIO times as often as a moving
#: particle that does not cross (``moving_ratio``: its definition of moving is recorded with the table).
EXTREMA_RATIO = rule("EXTREMA_RATIO")


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

