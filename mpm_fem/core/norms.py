"""The discrete norms a run reports of its pointwise error.

For an error ``e_k`` with quadrature weights ``w_k`` (particle volumes ``V_p``, or the nodal
weights ``int S_i dx``):

    L1 = sum_k w_k |e_k|,     L2 = (sum_k w_k e_k^2)^{1/2},     max = max_k |e_k|.

They belong to the core because a problem set-up states its own error (``problems.sod.errors``);
the comparisons between runs (observed orders) are measurements, in :mod:`mpm_fem.measure.errors`.
"""

from __future__ import annotations

import numpy as np

NORMS = ("L1", "L2", "max")


def norms(error: np.ndarray, weights: np.ndarray) -> dict[str, float]:
    """``{"L1", "L2", "max"}`` of ``error`` with quadrature ``weights`` (same shape)."""
    e = np.abs(np.asarray(error, dtype=float))
    w = np.asarray(weights, dtype=float)
    return {"L1": float(np.sum(w * e)), "L2": float(np.sqrt(np.sum(w * e * e))), "max": float(e.max(initial=0.0))}
