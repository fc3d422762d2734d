"""The nodal read-out's own error on Sod (:mod:`mpm_fem.measure.readout`): the exact particle positions
keep the mass coordinate, and on a jittered layout the read-out alone is the nodal error of the budget
with every stage exact (the committed ``budget/subsets``)."""

from __future__ import annotations

import numpy as np
from claim_mutations import TABLES

from mpm_fem.measure.claims import select
from mpm_fem.measure.readout import exact_positions, sod_readout
from mpm_fem.problems import sod


def test_exact_positions_keep_the_mass_coordinate():
    """Ahead of the rarefaction head (x < 0.5 - c_L T = 0.263) and ahead of the shock (x > 0.85) the gas has not
    moved; the diaphragm's point moves with the contact (x = 0.685 at T = 0.2, Toro's test 1)."""
    s = sod.SodSettings()
    x0 = np.array([0.1, 0.25, 0.5, 0.9, 0.99])
    x = exact_positions(s, x0)
    assert np.all(np.abs(x[[0, 1, 3, 4]] - x0[[0, 1, 3, 4]]) < 1e-5), x
    assert abs(x[2] - 0.6854) < 1e-3, x[2]
    assert np.all(np.diff(exact_positions(s, np.linspace(0.001, 0.999, 999))) > 0)


def test_the_jittered_read_out_is_the_all_exact_nodal_error():
    """h = 0.01 and 0.005, 4 per cell, jittered 1: the read-out alone (0.0317, 0.0369 measured on 2026-12-02)
    lies within 5 % of the committed v(all exact) of the nodal norm (0.0310, 0.0371), while on the regular
    layout (16 per cell) it is 0.0013 at h = 0.01: the nodal floor of the jittered budget is the read-out's."""
    rows = select(TABLES["budget/subsets"], problem="sod", basis="mpm", norm="nodes", ppc="4", layout="jittered",
                  seed="1", mpm_stages="none")
    for h in (0.01, 0.005):
        committed = float(select(rows, h=f"{h:g}")[0]["error"])
        measured = sod_readout(h, 4, "jittered", 1)
        assert abs(measured / committed - 1) < 0.05, (h, measured, committed)
    assert sod_readout(0.01, 16) < 0.1 * sod_readout(0.01, 4, "jittered", 1)
