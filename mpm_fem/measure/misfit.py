"""The misfit of measured errors to a source's table: the mean absolute log ratio over paired entries.

The identification (:mod:`mpm_fem.measure.identify`) minimises it; the verdicts
(:mod:`mpm_fem.measure.claims.identification`) report it. No project imports.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence


def misfit(measured: Sequence[float], source: Sequence[float]) -> float:
    """``mean_k |log(measured_k / source_k)|`` over paired entries (same length, at least one);
    ``inf`` when a measured entry is missing, not finite or not positive (a failed run misfits)."""
    if len(measured) != len(source) or not source:
        raise ValueError(f"misfit needs paired, non-empty entries: {len(measured)} measured, {len(source)} source")
    if any(not s > 0 for s in source):
        raise ValueError(f"the source's entries must be positive, got {list(source)}")
    if any(m is None or not math.isfinite(m) or m <= 0 for m in measured):
        return math.inf
    return sum(abs(math.log(m / s)) for m, s in zip(measured, source, strict=True)) / len(source)


def row_misfit(measured: Mapping[tuple, float | None], source: Mapping[tuple, float], spread_weight: float) -> float:
    """A Burgers row's misfit over its entries ``(eps, h)``: :func:`misfit` plus ``spread_weight`` (the rule
    book's ``IDENTIFICATION_SPREAD_WEIGHT``) times the mean over the meshes of ``|log(max_eps m / min_eps m) -
    log(max_eps s / min_eps s)|`` (the spread over eps, so that an error independent of eps, as the
    source's exact row is, counts); one eps: :func:`misfit` alone. ``inf`` when an entry is missing."""
    keys = list(source)
    base = misfit([measured.get(k) for k in keys], [source[k] for k in keys])
    meshes = sorted({h for _, h in keys})
    if not math.isfinite(base) or len({e for e, _ in keys}) < 2:
        return base
    spread = lambda values: math.log(max(values) / min(values))  # noqa: E731
    term = sum(abs(spread([measured[k] for k in keys if k[1] == h]) - spread([source[k] for k in keys if k[1] == h]))
               for h in meshes) / len(meshes)
    return base + spread_weight * term
