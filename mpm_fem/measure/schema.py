"""The tables the claims read, declared once: each table's name and its columns.

A study writes ``figures/<study>/<table>.csv`` and the claims (:mod:`mpm_fem.measure.claims`) read it
as ``tables["<study>/<table>"]``. Both go through the :class:`Table` declared here: the study keys
its rows by the declaration, the writer (:func:`mpm_fem.app.study.write_table`) checks that the
written columns are the declared ones (:meth:`Table.check`), and the claims take the table's name
from it. Renaming a column is then one change here, and a study or claim left behind fails at once
instead of writing a table no claim reads (``tests/test_schema.py`` checks the committed tables
and every column a claim reads against these declarations).

``versions`` and ``settings`` are built from the JSON files by
:func:`mpm_fem.measure.tables.load_tables`, not written by a study; they are declared for the
claims that read them. No project imports.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass


class ColumnsError(ValueError):
    """Rows written to a declared table whose columns are not its declared ones."""


@dataclass(frozen=True)
class Table:
    """A table of ``figures/``: its ``name`` (``"<study>/<table>"``), the ``columns`` every written
    table has, the ``optional`` columns only some runs write (``error`` when a run failed), and the
    ``families`` of columns whose members depend on the meshes run: regular expressions a column
    name matches whole (``order_<h1>_<h2>``, one per pair of successive meshes)."""

    name: str
    columns: tuple[str, ...]
    optional: tuple[str, ...] = ()
    families: tuple[str, ...] = ()

    @property
    def study(self) -> str:
        """The folder of ``figures/`` the table is written to (``"sod"``)."""
        return self.name.partition("/")[0]

    @property
    def stem(self) -> str:
        """The file name without ``.csv`` (``"convergence"``)."""
        return self.name.partition("/")[2]

    def declares(self, column: str) -> bool:
        """Whether ``column`` is one of the table's columns, optional ones and families included."""
        return (column in self.columns or column in self.optional
                or any(re.fullmatch(pattern, column) for pattern in self.families))

    def mismatch(self, columns: Iterable[str]) -> tuple[list[str], list[str]]:
        """``(missing, extra)``: the declared columns absent from ``columns``, and the columns of
        ``columns`` the declaration does not have."""
        columns = list(columns)
        return [c for c in self.columns if c not in columns], [c for c in columns if not self.declares(c)]

    def check(self, rows: list[dict]) -> None:
        """Raise :class:`ColumnsError`, naming the table and the missing and extra columns, unless
        the columns of ``rows`` (every key of every row) are the declared ones."""
        columns = list(dict.fromkeys(key for row in rows for key in row))
        missing, extra = self.mismatch(columns)
        if missing or extra:
            raise ColumnsError(f"table {self.name}: the written columns differ from its declaration in "
                               f"mpm_fem/measure/schema.py: missing {missing or 'none'}, extra {extra or 'none'}")


# ----------------------------------------------------------------------------- projection (C4-C10)

PROJECTION_ORDERS = Table("projection/orders", (
    "quantity", "layout", "weights", "basis", "N_p", "norm", "order", "order_coarse", "order_fine", "successive",
    "band", "inside"))
PROJECTION_BOUNDS = Table("projection/bounds", ("check", "layout", "N_p", "h", "min_ratio", "entries", "holds"))
PROJECTION_D2_CONSTANT = Table("projection/d2_constant", (
    "layout", "N_p", "C", "delta_expected", "source_band", "inside"))

# ----------------------------------------------------------------------------- Sod (C3, C11, C12, C14, C15, E3)

#: One row per setting (``ppc``, ``cfl``) and mesh: the regular layout's errors (``mpm_*``, ``order_*``) beside
#: the source's table, the jittered layouts' mean and range (``jittered_<q>_mean|lo|hi``) and each order's mean
#: and range over every seed run on both meshes (``order_<q>_mean|lo|hi``), FEM and FV on the same mesh.
SOD_CONVERGENCE = Table("sod/convergence", (
    "ppc", "cfl", "h", "source_L1", "source_L2", "source_order_L1",
    "mpm_nodes_L1", "ratio_nodes_L1", "order_nodes_L1", "mpm_nodes_L2", "ratio_nodes_L2", "order_nodes_L2",
    "mpm_particles_L1", "ratio_particles_L1", "order_particles_L1", "mpm_particles_L2", "ratio_particles_L2",
    "mpm_energy_L1", "order_energy_L1", "seeds",
    *(f"{kind}_{q}_{stat}" for q in ("particles_L1", "energy_L1", "nodes_L1") for kind in ("jittered", "order")
      for stat in ("mean", "lo", "hi")),
    "fem_consistent_L1", "order_fem_consistent_L1", "fem_lumped_L1", "order_fem_lumped_L1", "fv_L1", "order_fv_L1",
    "mpm_particles_mean_error_smooth", "mpm_nodes_mean_error_smooth", "mpm_volume_drift", "mpm_head_shift",
    "fem_consistent_head_shift", "mpm_steps", "mpm_particles", "mpm_wall_s", "mpm_energy_drift"))
#: One row per MPM run of the convergence study: the regular layout (seed 0) and the jittered ones.
SOD_SEEDS = Table("sod/seeds", (
    "h", "ppc", "cfl", "layout", "seed", "ok", "particles_L1", "particles_L2", "nodes_L1", "nodes_L2", "energy_L1",
    "volume_drift", "steps", "error"))
#: ``ppc`` and ``cfl`` empty for the fixed-mesh FEM.
SOD_REGIONS = Table("sod/regions", (
    "method", "ppc", "cfl", "h", "L1", "sum_of_regions",
    "L1_0_undisturbed", "L1_1_rarefaction_head", "L1_2_smooth", "L1_3_rarefaction_tail", "L1_4_contact",
    "L1_5_behind_shock", "L1_6_shock_front",
    "share_0", "share_1", "share_2", "share_3", "share_4", "share_5", "share_6"))
SOD_EXTREMA = Table("sod/extrema", (
    "ppc", "cfl", "h", "steps", "crossings", "crossings_per_step", "moving_speed", "moving_share",
    *(f"{name}_{k}" for name in ("density", "energy") for k in (
        "new_at_crossing", "new_elsewhere", "new_moving", "new_per_step", "max_per_step", "rate_crossing",
        "rate_elsewhere", "rate_moving", "rate_ratio", "moving_ratio"))))
SOD_PPC = Table("sod/ppc", (
    "h", "ppc", "ok", "nodes_L1", "nodes_L2", "particles_L1", "particles_L2", "steps", "wall_s", "error"))
SOD_MASS = Table("sod/mass", (
    "h", "mpm_lumped_nodes_L1", "mpm_consistent_nodes_L1", "mpm_consistent_over_lumped_nodes",
    "mpm_lumped_particles_L1", "mpm_consistent_particles_L1", "mpm_consistent_over_lumped_particles",
    "fem_lumped_L1", "fem_consistent_L1", "fem_consistent_over_lumped", "mpm_consistent_error"))

# ----------------------------------------------------------------------------- Burgers (C3, C13, C15)

#: One row per series (solution, method, eps) and error: the regular layout's orders on its meshes
#: (``fitted``, ``first``, ``last``, ``h_range``, ``order_<h1>_<h2>``) and, over the ``runs`` of the
#: series (the regular and jittered layouts; one where only the regular runs) on the meshes they share
#: (``runs_h_range``), the mean of their fitted orders, its range (``fitted_lo``, ``fitted_hi``) and
#: Student-t interval (``fitted_t_lo``, ``fitted_t_hi``; empty for one run), and the range of each
#: successive order (``order_lo_<h1>_<h2>``, ``order_hi_<h1>_<h2>``, series of several runs).
#: ``source_fitted`` only where the source's table has every mesh of the series.
BURGERS_ORDERS = Table("burgers/orders", (
    "solution", "method", "ppc", "eps", "where", "norm", "fitted", "first", "last", "h_range", "runs", "runs_h_range",
    "fitted_mean", "fitted_lo", "fitted_hi", "fitted_t_lo", "fitted_t_hi"),
    optional=("source_fitted",),
    families=(r"order_[0-9.e+-]+_[0-9.e+-]+", r"order_(lo|hi)_[0-9.e+-]+_[0-9.e+-]+"))
#: One row per run of the settings C13 judges on several particle layouts (``layout``, ``seed``).
BURGERS_SEEDS = Table("burgers/seeds", (
    "method", "acceleration", "dt_rule", "ppc", "eps", "h", "layout", "seed", "particles_L1", "particles_L2",
    "particles_max", "nodes_L1", "nodes_L2", "nodes_max", "steps", "error"))
BURGERS_PPC = Table("burgers/ppc", (
    "method", "eps", "h", "ppc", "particles_L1", "particles_L2", "particles_max", "nodes_L1", "nodes_L2", "nodes_max",
    "steps", "error", "best_ppc"))
BURGERS_LUMPING = Table("burgers/lumping", (
    "method", "mass", "eps", "h", "where", "L1", "L2", "max", "nodes_L2", "dt", "error"))
#: The 1D grid masses (lumped, consistent, exact and FMPM(k)) on Sod (density L1) and Burgers (velocity L2, both
#: accelerations; ``acceleration`` empty on Sod), every run on the numpy step; ``step_ms`` its wall time per step.
LUMPING_ERRORS = Table("lumping/errors", (
    "problem", "acceleration", "h", "mass", "ok", "quantity", "norm", "nodes", "particles", "steps", "step_ms"),
    optional=("error",))
#: One change at a time to the calculated-acceleration run (``variant``, ``changes``); ``order_L1``:
#: the observed order of the particles' L1 error against the next coarser mesh (absent on one mesh).
BURGERS_DIAGNOSIS = Table("burgers/diagnosis", (
    "variant", "changes", "eps", "h", "particles_L1", "particles_L2", "particles_max", "nodes_L1", "nodes_L2",
    "nodes_max", "error"), optional=("order_L1",))

# ----------------------------------------------------------------------------- time (C1, C2)

TIME_ORDER = Table("time/time_order", (
    "problem", "basis", "quantity", "refine", "dt", "error", "order", "fitted_order"))
TIME_LOCAL_ERROR = Table("time/local_error", ("problem", "basis", "quantity", "dt", "error", "order", "fitted_order"))
#: Per basis and acceleration; C2's second half beside the jump (optional: absent from tables written before it):
#: ``jump_ratio`` (median |measured jump| / |the slides' P1 formula|), the basis's global orders in dt of the particle
#: velocity (``order_dt_pulse``, ``order_dt_burgers``: ``time_order``) and ``order_dt_spread`` (the widest range of
#: its successive orders in dt).
TIME_CROSSING_SUMMARY = Table("time/crossing_summary", (
    "basis", "acceleration", "crossings", "median_ratio", "max_ratio_error", "max_abs_ratio", "median_abs_measured"),
    optional=("jump_ratio", "order_dt_pulse", "order_dt_burgers", "order_dt_spread"))

# ----------------------------------------------------------------------------- budget (E1, E2; E5)

#: The particle setting of a run (since 2026-11-28): particles per cell, ``"regular"`` or ``"jittered"``, the
#: seed (0 for the regular layout). Optional in the budget's and the remedies' tables: those written before it
#: lack them (every row then has the study's own setting); every row of a table written since has them.
PARTICLE_SETTING = ("ppc", "layout", "seed")

#: v(S), the error with the stages of ``mpm_stages`` (``+``-joined, ``none`` for the empty set) in
#: MPM form and the others exact: the raw measurements of the budget, which E1 reads.
BUDGET_SUBSETS = Table("budget/subsets", ("problem", "h", "basis", "norm", "mpm_stages", "error"),
                       optional=PARTICLE_SETTING)
#: E1's control (the bar, no node crossing: ``mpm_fem.measure.control``): v(S) as in ``budget/subsets``
BUDGET_CONTROL = Table("budget/control", ("problem", "h", "basis", "norm", "mpm_stages", "error"),
                       optional=PARTICLE_SETTING)
#: one row per control run: the interactions of v and of the fields over the gap, the nodal read-out's own error
BUDGET_CONTROL_RUNS = Table("budget/control_runs", (
    "problem", "h", "basis", "ppc", "layout", "seed", "interactions", "field_interactions", "readout",
    "readout_relative", "wall_s"))
#: per Sod budget of P1: the nodal read-out's own error (exact density, exact positions) beside v(all exact), v(all MPM)
BUDGET_READOUT = Table("budget/readout", ("problem", "h", "basis", "ppc", "layout", "seed", "readout_L1",
                                          "all_exact_L1", "all_mpm_L1"))
BUDGET_SHAPLEY = Table("budget/shapley", (
    "problem", "h", "basis", "norm", "stage", "shapley", "share", "removed", "alone", "mpm_error", "exact_error"),
    optional=PARTICLE_SETTING)
BUDGET_ROUNDOFF = Table("budget/roundoff", (
    "problem", "h", "basis", "norm", "stage", "share", "share_numpy", "change_pp", "mpm_error", "mpm_error_numpy",
    "exact_error", "exact_error_numpy"))
#: ``error`` only when a run failed (its row then has no errors).
BUDGET_BASES = Table("budget/bases", (
    "h", "basis", "ok", "steps", "wall_s", "particles_L1", "nodes_L1", "plateau_noise", "plateau_offset"),
    optional=("error", *PARTICLE_SETTING))

# ----------------------------------------------------------------------------- remedies (E5)

REMEDIES_ERRORS = Table("remedies/errors", (
    "problem", "remedy", "h", "quantity", "nodes_L1", "nodes_L2", "particles_L1", "particles_L2", "fv_L1",
    "ratio_fv_nodes_L1", "ratio_fv_particles_L1", "steps", "n_p", "volume_drift", "error", "order_nodes_L1",
    "order_particles_L1"), optional=PARTICLE_SETTING)

# ----------------------------------------------------------------------------- drift (C11's mechanism)

#: One row per variant, layout, seed and mesh; ``error`` only when a run failed (its row then has no errors).
DRIFT = Table("drift/drift", (
    "h", "variant", "layout", "seed", "change", "kernel", "ok", "particles_L1", "nodes_L1", "volume_drift",
    "abs_volume_drift", "particles_vs_study", "order_particles_L1", "order_nodes_L1", "steps"), optional=("error",))

# ----------------------------------------------------------------------------- identification

#: One row per candidate (one setting held fixed over the source's table, its continuous settings fitted
#: by a bracketed search, :mod:`mpm_fem.measure.search`) and source row: ``readout`` (particles or
#: nodes), the fitted time-step constant ``cfl``, ``misfit`` on the fitted part of the table
#: (mean |log(measured/source)|, for Burgers plus the spread over eps), ``misfit_held_out`` on the rest,
#: ``misfit_raw`` against the table as printed, the ``rank`` and ``matching`` (within the band). Sod
#: fits the L1 column and holds out L2; Burgers' ``fit`` is ``table`` (one candidate for both rows, ranked
#: by ``table_misfit``, the held-out part some eps) or ``eps`` (the per-eps diagnostic: the best setting
#: for one row at one ``eps``).
_IDENTIFIED = ("source_row", "misfit", "misfit_held_out", "misfit_raw", "meshes", "rank", "matching")
IDENTIFICATION_SOD = Table("identification/sod", ("problem", "candidate", "ppc", "cfl", "readout", "norm",
                                                  "held_out", *_IDENTIFIED))
IDENTIFICATION_BURGERS = Table("identification/burgers", (
    "problem", "fit", "candidate", "solution", "params", "dt_rule", "cfl", "ppc", "readout", "norm", "eps",
    "table_misfit", "held_out", *_IDENTIFIED))
#: The refinement test: per problem, the best candidate's search at the stated tolerances and with them
#: halved (restarted from the converged point), its best misfit and the change.
IDENTIFICATION_REFINEMENT = Table("identification/refinement", (
    "problem", "candidate", "tolerance", "cfl_xtol", "param_xtol", "misfit", "change", "evaluations"))
#: The identified settings rerun: per problem, source row, layout and seed (0 the regular layout), eps (Burgers)
#: and mesh, the error at the identified setting beside the source's.
IDENTIFICATION_IDENTIFIED = Table("identification/identified", (
    "problem", "source_row", "setting", "readout", "norm", "layout", "seed", "eps", "h", "error", "source",
    "ratio"))

#: One row per problem, basis, run, subset and pair of successive meshes: v(S) on both and the order.
MECHANISM_GROWTH = Table("mechanism/growth", (
    "problem", "basis", "ppc", "layout", "seed", "made_exact", "mpm_stages", "h_coarse", "h_fine", "error_coarse",
    "error_fine", "order"))
#: One row per problem, basis, particles per cell, subset and mesh pair: the orders over the runs
#: (``order_regular`` the regular layout's), the runs on which all MPM grows (``mpm_growing``), and of
#: those the runs on which this subset stops the growth (``stops_growth``) and converges
#: (``converging_where_mpm_grows``); ``turns_growth``: it converges on every one of them.
MECHANISM_SUMMARY = Table("mechanism/summary", (
    "problem", "basis", "ppc", "made_exact", "mpm_stages", "h_coarse", "h_fine", "runs", "order_min", "order_mean",
    "order_max", "order_regular", "mpm_growing", "stops_growth", "converging_where_mpm_grows", "turns_growth"))
#: One row per run (:mod:`mpm_fem.measure.defect`): the measured particle L1 error and
#: the accumulated defect's (``predicted_L1``), their ratio, the components' norms and the mean per-step
#: defects; ``error`` when the run failed.
DEFECT = Table("defect/defect", (
    "problem", "basis", "ppc", "layout", "seed", "h", "ok"), optional=(
    "error", "steps", "wall_s", "measured_L1", "predicted_L1", "ratio", "at_particles_L1", "residual_L1", "floor_L1",
    "acceleration_L1", "velocity_L1", "rate_L1", "defect_a", "defect_v", "defect_L"))

#: One row per run of ``defect/defect`` (E6, :mod:`mpm_fem.measure.claims.model`): whether the error model
#: was fitted on it (``role`` fitted or checked), its measured particle error, its driving defect, the
#: defect law's value and the model's error, and model / measured.
MODEL = Table("defect/model", ("problem", "ppc", "layout", "seed", "h", "role", "measured_L1", "defect",
                               "defect_law", "model_L1", "ratio"))
#: One row per problem and layout class: the defect law ``d = D h^q n^-r`` and the error model ``A h^p + B d``.
MODEL_FIT = Table("defect/model_fit", ("problem", "layout", "driver", "D", "q", "r", "A", "p", "B"))

# ----------------------------------------------------------------------------- plane (D1-D7)

#: What every 2D run writes (``studies.plane``): ``ok``, the particle displacement errors at T (``L2``, ``Linf``,
#: ``L2_max`` over time), the nodal acceleration's ``acc_L2``, the steps, ``dt``, the CFL run (``cfl_run``), the
#: particles, the wall and CPU time per step (``step_ms``) and whether the compiled step ran; ``error`` names the
#: cause of a failed run (its row then has no errors).
PLANE_RUN = ("ok", "error", "L2", "Linf", "L2_max", "acc_L2", "steps", "dt", "cfl_run", "n_p", "wall_s", "step_ms",
             "compiled")
#: D1, D6: per solution, basis, particles per cell (per axis), layout, seed and mesh.
PLANE_GROWTH = Table("plane/growth", ("solution", "basis", "ppc", "layout", "seed", "h", *PLANE_RUN))
#: D2: per solution, mesh, layout and seed, each stage made exact alone (``none``: all MPM; ``all``: every one).
PLANE_STAGES = Table("plane/stages", ("solution", "h", "layout", "seed", "made_exact", "basis", "ppc", *PLANE_RUN))
#: D3: v(S) of every subset of stages in MPM form, per solution and mesh, and each stage's Shapley value.
PLANE_BUDGET = Table("plane/budget", ("solution", "h", "mpm_stages", *PLANE_RUN))
PLANE_SHAPLEY = Table("plane/shapley", ("solution", "h", "stage", "shapley", "share", "alone", "mpm_error",
                                        "exact_error", "gap", "interactions", "interactions_share"))
#: D4, D5: per solution, mesh and grid mass (``mpm_fem.masses``), point-mass MPM at 2x2 per cell.
PLANE_MASS = Table("plane/mass", ("solution", "h", "mass", "basis", *PLANE_RUN))
#: D4, D6: the Q1 FEM on the same mesh, per solution, mesh and mass.
PLANE_FEM = Table("plane/fem", ("solution", "h", "mass", *PLANE_RUN))
#: D7: one mesh, the step refined ``refine`` times from CFL ``cfl``.
PLANE_TIME = Table("plane/time", ("solution", "h", "cfl", "refine", "study_cfl", *PLANE_RUN))
#: The figures' table: per solution, method and mesh, the regular layout's L2 and its spread over the layouts.
PLANE_CONVERGENCE = Table("plane/convergence", ("solution", "method", "h", "runs", "ok_runs", "L2", "L2_mean",
                                                "L2_lo", "L2_hi"))

# ----------------------------------------------------------------------------- plane projection (D8, D9)

#: ``studies.plane_projection``: the 2D projection errors (``mpm_fem.plane.projection``) per quantity, layout,
#: weights, basis, particles per cell per axis ``ppc``, mesh and norm, the mean over the seeds and its spread.
PLANE_PROJECTION_ERRORS = Table("plane_projection/errors", (
    "quantity", "layout", "weights", "basis", "ppc", "h", "norm", "value", "spread", "min", "max", "seeds"))
#: D8: the least-squares order over every mesh of the mean error, ``order`` in the 1D units (an extensive error,
#: ``E_m``, ``E_P``, ``E_F``, divided by ``h``: one order below ``order_per_node``, the order of the nodal values
#: as measured), the orders between the two coarsest and the two finest meshes and between successive meshes,
#: the source's band and whether ``order`` lies in it.
PLANE_PROJECTION_ORDERS = Table("plane_projection/orders", (
    "quantity", "layout", "weights", "basis", "ppc", "norm", "order", "order_per_node", "order_coarse",
    "order_fine", "successive", "band", "inside"))
#: D9: per check (``cell_rho``, ``node_m``, ``node_F``), layout, ``ppc`` and mesh, the smallest bound/error over
#: every entry of every seed, the entries and whether the bound holds on all of them.
PLANE_PROJECTION_BOUNDS = Table("plane_projection/bounds", (
    "check", "layout", "ppc", "h", "min_ratio", "entries", "holds"))
#: The 2D discrepancy (``mpm_fem.plane.discrepancy``) per layout, ``ppc`` and mesh: mean, min and max over the
#: cells and seeds, the regular pattern's closed form beside, and the cells' particle counts.
PLANE_PROJECTION_D2 = Table("plane_projection/d2", (
    "layout", "ppc", "h", "D2_mean", "D2_min", "D2_max", "D2_regular", "count_min", "count_max", "seeds"))

# ----------------------------------------------------------------------------- built by load_tables (E3, E4, E5)

#: One row per table: the code version that wrote it and its tier (:func:`mpm_fem.measure.tables.table_tier`;
#: ``quick``: the legacy flag, ``True``/``False`` as recorded in its settings).
VERSIONS = Table("versions", ("table", "code", "quick", "tier"))
SETTINGS = Table("settings", ("table", "key", "value"))

#: Every declared table a study writes, by name.
TABLES: dict[str, Table] = {t.name: t for t in (
    PROJECTION_ORDERS, PROJECTION_BOUNDS, PROJECTION_D2_CONSTANT,
    SOD_CONVERGENCE, SOD_SEEDS, SOD_REGIONS, SOD_EXTREMA, SOD_PPC, SOD_MASS,
    BURGERS_ORDERS, BURGERS_SEEDS, BURGERS_PPC, BURGERS_LUMPING, BURGERS_DIAGNOSIS,
    TIME_ORDER, TIME_LOCAL_ERROR, TIME_CROSSING_SUMMARY,
    BUDGET_SUBSETS, BUDGET_SHAPLEY, BUDGET_ROUNDOFF, BUDGET_BASES, BUDGET_CONTROL, BUDGET_CONTROL_RUNS,
    BUDGET_READOUT,
    REMEDIES_ERRORS,
    DRIFT,
    IDENTIFICATION_SOD, IDENTIFICATION_BURGERS, IDENTIFICATION_REFINEMENT, IDENTIFICATION_IDENTIFIED,
    MECHANISM_GROWTH, MECHANISM_SUMMARY, DEFECT, MODEL, MODEL_FIT, LUMPING_ERRORS,
    PLANE_GROWTH, PLANE_STAGES, PLANE_BUDGET, PLANE_SHAPLEY, PLANE_MASS, PLANE_FEM, PLANE_TIME, PLANE_CONVERGENCE,
    PLANE_PROJECTION_ERRORS, PLANE_PROJECTION_ORDERS, PLANE_PROJECTION_BOUNDS, PLANE_PROJECTION_D2)}
#: The tables :func:`mpm_fem.measure.tables.load_tables` builds from the JSON files, by name.
BUILT: dict[str, Table] = {t.name: t for t in (VERSIONS, SETTINGS)}


def declared(name: str) -> Table:
    """The declaration of table ``name`` (written or built); ``KeyError`` naming it when there is none."""
    try:
        return {**TABLES, **BUILT}[name]
    except KeyError:
        raise KeyError(f"table {name!r} is not declared in mpm_fem/measure/schema.py") from None
