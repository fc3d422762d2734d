"""What the Sod and the Burgers claims share: the criteria of C3 (particles per cell) and C15 (mass
lumping), each judged per problem (``sod/ppc``, ``burgers/ppc``; ``sod/mass``, ``burgers/lumping`` and
the budget's ``budget/shapley``)."""

from __future__ import annotations

from mpm_fem.measure.claims.rows import count_verdict, num, saturation, select
from mpm_fem.measure.source import OPTIMAL_PPC

#: C3: the fewest particles per cell within SATURATION of the smallest error.
SATURATION = 0.05
#: C15: lumping is an error source where the consistent mass lowers the error below LUMPING_GAIN x lumped;
#: the budget's mass stage (FE + mass lumping) is one where its Shapley share of v(all MPM) - v(all exact),
#: in magnitude, reaches MASS_SHARE at the finest mesh of a basis (either sign: adding or compensating).
LUMPING_GAIN, MASS_SHARE = 0.9, 0.1


def ppc_claim(groups: dict[str, list[dict]], keys: tuple[str, ...]) -> tuple[str, str]:
    """C3 on one problem: per group (method, mesh) and error ``key``, the fewest N_p near the best."""
    found = {f"{g}, {k.split('_')[0]}": saturation(rows, k, within=SATURATION)
             for g, rows in groups.items() for k in keys}
    hits = sum(OPTIMAL_PPC[0] <= n <= OPTIMAL_PPC[1] for n in found.values())
    return count_verdict(hits, len(found), "differs"), (
        f"N_p within {SATURATION:.0%} of the smallest error: " + "; ".join(f"{g}: {n}" for g, n in found.items()))


PPC_RULE = (f"the fewest particles per cell within {SATURATION:.0%} of the smallest error lies in "
            f"[{OPTIMAL_PPC[0]}, {OPTIMAL_PPC[1]}] on every mesh and error -> confirmed, on some -> partly, "
            "on none -> differs")


def mass_shares(rows: list[dict]) -> dict[str, float]:
    """The budget's Shapley share of the mass stage at the finest mesh of each basis and norm
    (``budget/shapley`` rows of one problem), keyed ``"<basis> <norm> h = <h>"``."""
    out = {}
    for basis, norm in dict.fromkeys((r["basis"], r["norm"]) for r in rows):
        sub = select(rows, basis=basis, norm=norm, stage="mass")
        finest = min(sub, key=lambda r: num(r, "h"))
        out[f"{basis} {norm} h = {finest['h']}"] = num(finest, "share")
    return out


def lumping_claim(ratios: dict[str, float], shares: dict[str, float]) -> tuple[str, str]:
    """C15 on one problem: every consistent/lumped ratio below LUMPING_GAIN and every mass-stage share
    at least MASS_SHARE in magnitude count as cases that hold."""
    hits = sum(v < LUMPING_GAIN for v in ratios.values()) + sum(abs(v) >= MASS_SHARE for v in shares.values())
    return count_verdict(hits, len(ratios) + len(shares), "differs"), (
        "consistent/lumped error: " + ", ".join(f"{k} {v:.2f}" for k, v in ratios.items())
        + "; Shapley share of the mass stage at the finest budget mesh: "
        + (", ".join(f"{k} {v:.0%}" for k, v in shares.items()) or "-"))


LUMPING_RULE = (f"the consistent mass lowers the error below {LUMPING_GAIN} x the lumped one for every method and "
                f"mesh, and the error budget's mass stage (FE + mass lumping) carries a Shapley share of at least "
                f"{MASS_SHARE:.0%} (in magnitude: adding to the error or compensating the other stages) of v(all MPM) "
                "- v(all exact) at the finest mesh of every basis and norm -> confirmed; some of these -> partly; "
                "none -> differs")
