"""E1's control: the error budget of the bar (:mod:`mpm_fem.run.bar_stages`), a problem without node
crossings, over the sixteen subsets of the four stages {projection, mass, interpolation, time}.

As the budget study's (``studies/budget.py``): eight runs at ``dt`` and eight at ``dt / K`` (every
step divided) give every subset ``S`` of the MPM stages; *time exact* is the extrapolation dt -> 0
of the particle error fields ``e_p`` (n_p,), point by point, for the bar's time error of order
``p = TIME_ORDER`` (leapfrog):

    e_{S without time} = (K^p e_{S, dt/K} - e_{S, dt}) / (K^p - 1),     e_{S with time} = e_{S, dt},

and ``v(S)`` is the L1 of ``e_S`` over the reference volumes. The Moebius terms of ``v``
(:mod:`mpm_fem.measure.decomposition`) are the budget's interactions; those of the fields
themselves, measured in the same L1 (``field_interactions``: the sum of the L1 of the field terms
of two stages or more over the L1 of ``e_MPM - e_exact``), say whether the stages add as fields,
so that what the norm adds (an L1 of a sum is not the sum of the L1s) is told apart. No project
import above the measurement layer.
"""

from __future__ import annotations

import numpy as np

from mpm_fem.measure.decomposition import decompose, label, subsets
from mpm_fem.run.bar_stages import TIME_ORDER, BarStages, ControlSettings, l1, readout_errors, run_control

STAGES = ("projection", "mass", "interpolation", "time")
#: each stage's exact form (:class:`~mpm_fem.run.bar_stages.BarStages`)
EXACT_FORM = {"projection": "exact", "mass": "exact", "interpolation": "exact"}
MPM_FORM = {"projection": "mpm", "mass": "lumped", "interpolation": "mpm"}


def subset_fields(s: ControlSettings, K: int = 2) -> dict[frozenset, np.ndarray]:
    """``{S: e_S}`` (each (n_p,)) for the sixteen subsets ``S`` of the MPM stages (module docstring)."""
    e = {}
    for S3 in subsets(STAGES[:3]):
        forms = {s_: (MPM_FORM if s_ in S3 else EXACT_FORM)[s_] for s_ in STAGES[:3]}
        for refine in (1, K):
            e[(S3, refine)] = run_control(s, BarStages(**forms, refine=refine))
    q = K**TIME_ORDER
    return {S: e[(S - {"time"}, 1)] if "time" in S else (q * e[(S, K)] - e[(S, 1)]) / (q - 1) for S in subsets(STAGES)}


def control_budget(s: ControlSettings, K: int = 2) -> dict:
    """One control run's budget: ``subsets`` ``{label: v(S)}``, ``interactions`` (the Moebius terms
    of ``v`` of two stages or more, in total magnitude, over ``|v(all MPM) - v(all exact)|``),
    ``field_interactions`` (module docstring) and the nodal read-out's own error ``readout`` and
    ``readout_relative`` (:func:`~mpm_fem.run.bar_stages.readout_errors`)."""
    fields = subset_fields(s, K)
    v = {S: l1(s, f) for S, f in fields.items()}
    d = decompose(v, STAGES)
    f = decompose(fields, STAGES)
    readout, relative = readout_errors(s)
    return {"subsets": {label(S): x for S, x in v.items()},
            "interactions": sum(abs(m) for m in d.interactions().values()) / abs(d.gap),
            "field_interactions": sum(l1(s, m) for m in f.interactions().values()) / l1(s, f.gap),
            "readout": readout, "readout_relative": relative}
