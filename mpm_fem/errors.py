"""Error norms and observed orders of convergence.

For a pointwise error ``e_k`` with quadrature weights ``w_k`` (particle volumes ``V_p``, or the
nodal weights ``int S_i dx``):

    L1 = sum_k w_k |e_k|,     L2 = (sum_k w_k e_k^2)^{1/2},     max = max_k |e_k|.

The observed order between meshes ``h_1 > h_2`` is ``log(E_1/E_2) / log(h_1/h_2)``; over a whole
sweep, the least-squares slope of ``log E`` against ``log h``.
"""

from __future__ import annotations

import numpy as np

NORMS = ("L1", "L2", "max")


def norms(error: np.ndarray, weights: np.ndarray) -> dict[str, float]:
    """``{"L1", "L2", "max"}`` of ``error`` with quadrature ``weights`` (same shape)."""
    e = np.abs(np.asarray(error, dtype=float))
    w = np.asarray(weights, dtype=float)
    return {"L1": float(np.sum(w * e)), "L2": float(np.sqrt(np.sum(w * e * e))), "max": float(e.max(initial=0.0))}


def observed_orders(h, errors) -> np.ndarray:
    """Orders between successive entries: ``log(E_k/E_{k+1}) / log(h_k/h_{k+1})``."""
    h, e = np.asarray(h, dtype=float), np.asarray(errors, dtype=float)
    return np.log(e[:-1] / e[1:]) / np.log(h[:-1] / h[1:])


def fitted_order(h, errors) -> float:
    """Least-squares slope of ``log E`` against ``log h``."""
    return float(np.polyfit(np.log(np.asarray(h, float)), np.log(np.asarray(errors, float)), 1)[0])


def orders_column(h, errors) -> list:
    """The observed order of each entry against the previous one, as a table column: ``""`` in the
    first row, and in every row when fewer than two errors or a non-positive one make orders undefined."""
    e = np.asarray(errors, dtype=float)
    if e.size < 2 or not np.all(e > 0):
        return [""] * e.size
    return [""] + [float(o) for o in observed_orders(h, e)]


def orders_row(h, errors) -> dict:
    """A row of an orders table: the least-squares order (``fitted``), the first and last observed
    orders, the meshes (``h_range``) and the order between each pair (``order_<h1>_<h2>``)."""
    o = observed_orders(h, errors)
    return {"fitted": fitted_order(h, errors), "first": float(o[0]), "last": float(o[-1]), "h_range": f"{h[0]}-{h[-1]}",
            **{f"order_{a}_{b}": float(x) for a, b, x in zip(h[:-1], h[1:], o)}}
