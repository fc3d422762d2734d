"""Identification: the settings the source leaves unsaid, found from its own tables.

For each of the source's tables the candidates for what the slides do not state run on the table's
meshes, each candidate one setting held fixed over the whole table (never a best fit per mesh or per
eps), and each is scored by its misfit to each source row, the mean ``|log(measured / source)|``
over the table's entries (:func:`mpm_fem.measure.claims.identification.misfit`), against the
corrected table and, beside it, the raw one.

- **Sod** (C11's table, L1 and L2 rows): particles per cell :data:`SOD_PPC` x CFL :data:`SOD_CFL`,
  regular layout, the Sod study's other settings; each run gives the nodal and the particle density,
  in L1 and L2, so a candidate is (ppc, CFL, quantity, norm), scored against both source rows.
  The runs are the Sod study's own cases (``studies.sod.run_case``, its cache): the settings of its
  convergence study are the same cached cases.
- **Burgers** (C13's table, the exact- and the calculated-acceleration rows): the four exact
  solutions; for the exact acceleration the time step proportional to h (``dt_rule`` advective, CFL
  :data:`ADVECTIVE_CFL`) and the stable rule ``dt = CFL min(h/|v|, h^2/(2 eps))`` (CFL
  :data:`EXACT_STABLE_CFL`); for the calculated acceleration the stable rule only (CFL
  :data:`CALCULATED_CFL`: its explicit viscous force needs the viscous limit, and the model refuses dt ~
  h with it); 4, 8 and 16 particles per cell (the stable rule with the exact acceleration at
  :data:`EXACT_STABLE_PPC`); the max, L1 and L2 norms of the velocity error over particles (the Burgers
  study's comparison). The misfit runs over the meshes and the five eps, so the eps trend counts. The
  runs are the Burgers study's cases (``studies.burgers.run_case``, its cache).

Meshes by tier (:data:`SOD_MESHES`, :data:`BURGERS_MESHES`): every candidate of a tier runs on the same
meshes, so that their misfits compare. Full: Sod h >= 0.00125, Burgers h >= 0.0025 (the stable time
step makes a Burgers run cost ~ h^-3). Deep: Sod to h = 0.0003125, Burgers to 0.00125 (0.000625 would
cost about 8 CPU-hours more). Quick: the two coarsest meshes and a few candidates (:data:`QUICK`).

Sizing (the cost models of the Sod and Burgers studies, :mod:`mpm_fem.app.estimate`): the full tier's
candidates as listed cost about 12 CPU-min, of which about 2.5 are cases the Sod and Burgers studies run
anyway. Trimmed to fit: the stable rule runs at two CFL numbers for the calculated acceleration (0.5,
the study's, and 1, the largest stable one; dt ~ h^2 makes the time error small, so the CFL moves little)
and at one (0.5) with 4 and 16 per cell for the exact acceleration, whose dt ~ h rule spans four CFL
numbers; a smaller stable CFL (0.25) would double the cost of its candidates.

Tables: ``sod`` and ``burgers`` (:data:`mpm_fem.measure.schema.IDENTIFICATION_SOD`, ``_BURGERS``).
"""

from __future__ import annotations

import sys

from mpm_fem.app.plots import Curve, Plot
from mpm_fem.app.study import StudyOptions, publish, script_main
from mpm_fem.measure import source
from mpm_fem.measure.claims.identification import candidate_rows, rank
from mpm_fem.measure.claims.rules import rule
from mpm_fem.measure.schema import IDENTIFICATION_BURGERS, IDENTIFICATION_SOD
from studies import burgers as burgers_study
from studies import sod as sod_study

NAME = "identification"
SOD_PPC = (4, 8, 16, 32)
SOD_CFL = (0.025, 0.05, 0.1, 0.2)
SOD_QUANTITIES = ("nodes", "particles")
SOD_NORMS = ("L1", "L2")
SOD_MESHES = {"quick": sod_study.H[:2], "full": sod_study.H[:4], "deep": sod_study.H[:6]}

SOLUTIONS = burgers_study.SOLUTIONS
EPS = burgers_study.EPS
BURGERS_PPC = (4, 8, 16)
ADVECTIVE_CFL = (0.125, 0.25, 0.5, 1.0)
EXACT_STABLE_CFL, EXACT_STABLE_PPC = (0.5,), (4, 16)
CALCULATED_CFL = (0.5, 1.0)
BURGERS_NORMS = ("max", "L1", "L2")
BURGERS_WHERE = "particles"
BURGERS_MESHES = {"quick": source.BURGERS_H[:2], "full": source.BURGERS_H[:3], "deep": source.BURGERS_H[:4]}
#: The quick tier: the two coarsest meshes, two Sod settings at two CFL numbers, and for Burgers the
#: study's CFL at 4 per cell on two solutions (about 3 CPU-s).
QUICK = dict(sod_ppc=(8, 16), sod_cfl=(0.05, 0.1), solutions=("rarefaction", "cole_hopf"), burgers_ppc=(4,),
             advective_cfl=(0.5,), exact_stable_cfl=(), calculated_cfl=(0.5,))

#: (source row, dt_rule, the Burgers study's method whose case it changes)
_RULES = {("exact", "advective"): "mpm_exact_dt_h", ("exact", "stable"): "mpm_exact",
          ("calculated", "stable"): "mpm_calculated"}


def burgers_candidates(tier: str) -> list[tuple]:
    """``(source row, solution, dt_rule, cfl, ppc)`` of every Burgers candidate of ``tier``."""
    q = QUICK if tier == "quick" else {}
    out = []
    for solution in q.get("solutions", SOLUTIONS):
        for ppc in q.get("burgers_ppc", BURGERS_PPC):
            out += [("exact", solution, "advective", c, ppc) for c in q.get("advective_cfl", ADVECTIVE_CFL)]
            if ppc in EXACT_STABLE_PPC:
                out += [("exact", solution, "stable", c, ppc) for c in q.get("exact_stable_cfl", EXACT_STABLE_CFL)]
            out += [("calculated", solution, "stable", c, ppc) for c in q.get("calculated_cfl", CALCULATED_CFL)]
    return out


def _burgers_case(row: str, solution: str, dt_rule: str, cfl: float, ppc: int, eps: float, h: float) -> dict:
    """The Burgers study's case (``studies.burgers.method_case``) of one candidate at ``eps`` and ``h``:
    a setting equal to the method's own is left out, so that it is the study's cached case."""
    method = _RULES[(row, dt_rule)]
    base = burgers_study.method_case(method, solution, eps, h)
    return burgers_study.method_case(method, solution, eps, h,
                                     **{k: v for k, v in dict(cfl=cfl, ppc=ppc).items() if base[k] != v})


def plans(tier: str) -> dict[str, dict]:
    """``{study: {group: {label: case}}}``: the cases of ``tier``, by the study whose case function
    (and cache) runs them (``"sod"``, ``"burgers"``)."""
    q = QUICK if tier == "quick" else {}
    sod = {(n, c, h): sod_study._setting_case(h, n, c) for n in q.get("sod_ppc", SOD_PPC)
           for c in q.get("sod_cfl", SOD_CFL) for h in SOD_MESHES[tier]}
    burgers = {(*cand, e, h): _burgers_case(*cand, e, h) for cand in burgers_candidates(tier) for e in EPS
               for h in BURGERS_MESHES[tier]}
    return {"sod": {"candidates": sod}, "burgers": {"candidates": burgers}}


def _meshes(hs) -> str:
    return " ".join(f"{h:g}" for h in hs)


def sod_rows(results: dict, hs) -> list[dict]:
    """The ranked rows of ``identification/sod`` from ``results``, ``{(ppc, cfl, h): Sod run}`` (the
    Sod study's measured runs), on the meshes ``hs``."""
    table = {h: source.SOD[h] for h in hs}
    corrected = {row: {h: v[k] for h, v in table.items()} for k, row in enumerate(SOD_NORMS)}
    rows = []
    for n, c in dict.fromkeys((n, c) for n, c, _ in results):
        for quantity in SOD_QUANTITIES:
            for norm in SOD_NORMS:
                measured = {h: _sod_value(results.get((n, c, h)), quantity, norm) for h in hs}
                settings = dict(ppc=n, cfl=c, quantity=quantity, norm=norm)
                rows += candidate_rows("sod", settings, measured, corrected, corrected, _meshes(hs),
                                       f"{n} ppc, CFL {c:g}, {quantity} {norm}")
    return rank(rows)


def _sod_value(r: dict | None, quantity: str, norm: str) -> float | None:
    return r["density"][quantity][norm] if r and r.get("ok") else None


def burgers_source(hs) -> tuple[dict, dict]:
    """``(corrected, raw)``: the source's Burgers rows on the meshes ``hs``, ``{row: {(eps, h): error}}``;
    the raw table has the slide's printed exponents (each corrected entry x 10)."""
    corrected = {row: {(e, h): source.burgers_value(row, e, h) for e in EPS for h in hs} for row in source.BURGERS}
    printed = lambda row, e, h: 10.0 if (row, e, h) in source.BURGERS_CORRECTED else 1.0  # noqa: E731
    raw = {row: {(e, h): v * printed(row, e, h) for (e, h), v in entries.items()} for row, entries in corrected.items()}
    return corrected, raw


def burgers_rows(results: dict, hs) -> list[dict]:
    """The ranked rows of ``identification/burgers`` from ``results``, ``{(row, solution, dt_rule, cfl,
    ppc, eps, h): Burgers run}``, on the meshes ``hs``: each candidate against its own source row."""
    corrected, raw = burgers_source(hs)
    rows = []
    for cand in dict.fromkeys(k[:5] for k in results):
        row, solution, dt_rule, cfl, ppc = cand
        for norm in BURGERS_NORMS:
            measured = {(e, h): _burgers_value(results.get((*cand, e, h)), norm) for e in EPS for h in hs}
            settings = dict(solution=solution, dt_rule=dt_rule, cfl=cfl, ppc=ppc, norm=norm)
            rows += candidate_rows("burgers", settings, measured, {row: corrected[row]}, {row: raw[row]},
                                   _meshes(hs), f"{solution}, {dt_rule} dt CFL {cfl:g}, {ppc} ppc, {norm}")
    return rank(rows)


def _burgers_value(r: dict | None, norm: str) -> float | None:
    return r[BURGERS_WHERE][norm] if r and r.get("ok") else None


def run(options: StudyOptions) -> None:
    """The candidates' cases through the Sod and Burgers studies (their caches), then the tables and figures."""
    tier = options.tier
    got = {study: options.sweep_plan(study, module.run_case, plans(tier)[study], cost=module._cost)["candidates"]
           for study, module in SWEEPS.items()}
    settings = {"tier": tier, "quick": options.quick, "band": rule("IDENTIFICATION_BAND"),
                "misfit": "mean |log(measured / source)| over the source's entries on the tier's meshes (Burgers: "
                          "and the five eps); misfit against the corrected table, misfit_raw against the printed one",
                "matching": "misfit within the band of the least misfit of the same source row"}
    extra = {IDENTIFICATION_SOD.stem: {"meshes": list(SOD_MESHES[tier]), "other settings": "as in the Sod study's mpm",
                                       "layout": "regular"},
             IDENTIFICATION_BURGERS.stem: {"meshes": list(BURGERS_MESHES[tier]), "eps": list(EPS),
                                           "where": BURGERS_WHERE, "other settings": "as in the Burgers study's mpm",
                                           "raw": "the entries of source.BURGERS_CORRECTED with the exponent the slide "
                                                  "prints (one power of ten up)"}}
    tables = {IDENTIFICATION_SOD: sod_rows(got["sod"], SOD_MESHES[tier]),
              IDENTIFICATION_BURGERS: burgers_rows(got["burgers"], BURGERS_MESHES[tier])}
    publish(options.folder(NAME), tables, settings, extra, PLOTS)


#: The studies whose case functions, caches and cost models run the identification's cases.
SWEEPS = {"sod": sod_study, "burgers": burgers_study}

PLOTS = (
    Plot("sod.png", "Sod: each candidate's misfit to the source's L1 and L2 columns (mean |log(measured/source)| "
         "over the meshes) against its rank; one series per quantity and norm", IDENTIFICATION_SOD.stem, "rank", (
        Curve("{quantity} {norm}", "misfit", "o", group=("quantity", "norm")),),
         xlabel="rank", ylabel="misfit", split=("source_row",), size=(4.6, 3.8)),
    Plot("burgers.png", "Burgers: each candidate's misfit to the source's rows (mean |log(measured/source)| over the "
         "meshes and the five eps) against its rank; circles the stable dt, triangles dt ~ h",
         IDENTIFICATION_BURGERS.stem, "rank", tuple(
             Curve(f"{solution}, {name}", "misfit", marker, where={"dt_rule": dt_rule, "solution": solution},
                   options={"color": colour})
             for dt_rule, name, marker in (("stable", "stable dt", "o"), ("advective", "dt ~ h", "^"))
             for solution, colour in zip(SOLUTIONS, ("tab:blue", "tab:orange", "tab:green", "tab:red"), strict=True)),
         xlabel="rank", ylabel="misfit", split=("source_row",), size=(4.6, 3.8)),
)

#: The cost model of :mod:`mpm_fem.app.estimate`: the cases of a tier by study (each study's own
#: COST and SECONDS_PER_COST price them; a case that study's own plan holds is counted there).
PLANS = plans


if __name__ == "__main__":
    sys.exit(script_main(NAME))
