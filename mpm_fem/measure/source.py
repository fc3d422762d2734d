"""The source's numbers: the tables and bands of Tran & Berzins' slides, as corrected in ``docs/claims.md``.

Studies write these beside the measured values, and :mod:`mpm_fem.measure.claims` judges against them. No
project imports: the source's tables are data, shared by the measurement and study layers.
"""

from __future__ import annotations

#: Sod's shock tube, density error at T = 0.2 (slides, "Final Error Combination(cont.)"): h -> (L1, L2).
SOD = {
    0.01: (0.00830833, 0.0158701),
    0.005: (0.00433578, 0.0104553),
    0.0025: (0.00230507, 0.0075895),
    0.00125: (0.00126351, 0.0057596),
    0.000625: (0.00109963, 0.0061870),
    0.0003125: (0.00101256, 0.0062115),
}

#: Burgers at T = 0.5 (slides, "Burgers' Problem(cont.)"): row -> eps -> errors on ``BURGERS_H``.
BURGERS_H = (0.01, 0.005, 0.0025, 0.00125, 0.000625)
_BURGERS_ROWS = {  # eps: (exact acceleration, calculated acceleration), each on BURGERS_H
    0.045: ((2.67e-4, 1.24e-4, 6.07e-5, 3.03e-5, 1.52e-5), (9.82e-4, 5.39e-4, 2.84e-4, 1.42e-4, 7.09e-5)),
    0.04: ((2.67e-4, 1.25e-4, 6.09e-5, 3.06e-5, 1.53e-5), (8.54e-4, 4.61e-4, 2.35e-4, 1.17e-4, 5.86e-5)),
    0.03: ((2.78e-4, 1.27e-4, 6.19e-5, 3.09e-5, 1.55e-5), (5.97e-4, 3.20e-4, 1.61e-4, 8.05e-5, 4.03e-5)),
    0.02: ((2.97e-4, 1.24e-4, 6.16e-5, 3.10e-5, 1.55e-5), (3.73e-4, 1.93e-4, 9.91e-5, 4.95e-5, 2.47e-5)),
    0.01: ((5.34e-4, 1.58e-4, 6.18e-5, 3.10e-5, 1.55e-5), (4.12e-4, 1.51e-4, 6.52e-5, 3.20e-5, 1.60e-5)),
}
BURGERS = {row: {eps: values[k] for eps, values in _BURGERS_ROWS.items()}
           for k, row in enumerate(("exact", "calculated"))}
#: (row, eps, h) of the entries whose exponent the slide misprints; corrected by one power of ten
#: to the sequence they belong to (``docs/claims.md``, "Corrections").
BURGERS_CORRECTED = {("exact", e, 0.0025) for e in (0.04, 0.03, 0.02, 0.01)} | {
    ("calculated", 0.03, 0.00125), ("calculated", 0.03, 0.000625), ("calculated", 0.02, 0.00125),
    ("calculated", 0.02, 0.000625), ("calculated", 0.01, 0.00125)}

#: The order bands of the projection errors ("Conclusions" slide); a string names the quantity whose
#: order the band follows. E_v1 "is first order in space".
PROJECTION_BANDS = {"E_m": (1, 2), "E_P": (1, 2), "E_F": (1, 2), "E_a": (0, 1), "E_a_pred": (0, 1), "E_v": (0, 1),
                    "E_v1": (1, 1), "E_VG": "E_v", "E_VG_proj": "E_v"}
#: The slides' constant C of ``D2 ~ [1/(12 N^2) + C h^2]^{1/2}``: 1/4 <= C <= 1/3.
D2_C = (0.25, 1 / 3)
#: The particles per cell the slides call optimal in 1D (C3).
OPTIMAL_PPC = (4, 8)


def band_text(quantity: str) -> str:
    """The source's band of a projection error, as printed: ``[1, 2]``, ``1`` or ``order of E_v``."""
    band = PROJECTION_BANDS[quantity]
    if isinstance(band, str):
        return f"order of {band}"
    return f"{band[0]}" if band[0] == band[1] else f"[{band[0]}, {band[1]}]"


def burgers_value(row: str | None, eps: float, h: float) -> float | None:
    """The source's Burgers error of ``row`` (``"exact"``, ``"calculated"``) at ``eps`` and ``h``;
    ``None`` where the table has no entry."""
    if row is None or eps not in BURGERS[row] or h not in BURGERS_H:
        return None
    return BURGERS[row][eps][BURGERS_H.index(h)]
