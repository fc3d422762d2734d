"""Observed orders of convergence (the norms of one run are :mod:`mpm_fem.core.norms`).

The observed order between meshes ``h_1 > h_2`` is ``log(E_1/E_2) / log(h_1/h_2)``; over a whole
sweep, the least-squares slope of ``log E`` against ``log h``.
"""

from __future__ import annotations

import numpy as np

from mpm_fem.core.norms import NORMS, norms  # noqa: F401  (the norms of one run; re-exported for the measurements)


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
            **{f"order_{a}_{b}": float(x) for a, b, x in zip(h[:-1], h[1:], o, strict=True)}}
