"""What the report shows of each study: its title, a caption in words, and views of its tables.

The report layer's knowledge of the studies, as data: each :class:`View` names a
table written by a study, the rows and columns shown, and the figure shown above it. The figures and
their one-line captions come from the studies themselves (``figures.json`` beside the PNGs, written
when a study draws them). A study without a page here gets its claims, figures and table links.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from mpm_fem.measure.claims import BURGERS_SHOWN
from mpm_fem.measure.regions import REGION_NAMES
from mpm_fem.measure.source import BURGERS


@dataclass(frozen=True)
class View:
    """Rows of ``table`` (``"sod/convergence"``) matching ``where``, in ``columns`` (all when empty),
    under ``caption``, with the ``figure`` (a file in the study's folder) shown above them."""

    table: str
    caption: str
    columns: tuple[str, ...] = ()
    where: dict = field(default_factory=dict)
    figure: str = ""


@dataclass(frozen=True)
class Page:
    """A study's section: ``name`` (its folder), ``title``, ``caption`` (words, no numbers) and the
    ``views`` of its tables."""

    name: str
    title: str
    caption: str
    views: tuple[View, ...] = ()


_SOLUTION, _WHERE, _NORM = BURGERS_SHOWN["solution"], BURGERS_SHOWN["where"], BURGERS_SHOWN["norm"]
_COMPARED = f"{_WHERE}_{_NORM}"
_FIRST_EPS = max(BURGERS["exact"])
_SHAPLEY = ("h", "basis", "stage", "shapley", "share", "removed", "alone", "mpm_error", "exact_error")

PAGES = (
    Page("projection", "Projection and particle quadrature",
         "Smooth fields on the unit interval are sampled by regular, jittered, random and advected particles; each "
         "nodal projection of the slides is compared with the exact integral it stands in for, and Hickernell's "
         "discrepancy and bound are measured on every cell. Orders are least-squares slopes over all meshes.",
         views=(
             View("projection/orders", "Least-squares L1 orders per layout at the middle particle count, point mass "
                  "with the slides' weights",
                  ("quantity", "layout", "N_p", "order", "order_coarse", "order_fine", "band"),
                  {"norm": "L1", "weights": "cell", "basis": "mpm", "N_p": 4}, "errors_vs_h.png"),
             View("projection/orders", "The same with the volumes a run carries and with GIMP, advected particles",
                  ("quantity", "weights", "basis", "N_p", "order", "band"),
                  {"layout": "advected", "norm": "L1", "N_p": 4, "weights": "volume"}),
             View("projection/d2_constant", "The C of the slides' D2 formula fitted per layout and N_p", (), {},
                  "d2.png"),
         )),
    Page("sod", "Sod's shock tube",
         "Density and internal energy error at the final time against the exact Riemann solution, for each setting of "
         "particles per cell and CFL number on every mesh (the same on every mesh, recorded in the JSON beside each "
         "table), with the regular particle layout and jittered ones (one row per run in the seeds table), over "
         "particles and over grid nodes, beside P1 FEM with consistent and lumped mass and a finite-volume reference "
         "on the same mesh, and beside the source's table. An order's range is the range of the orders of every seed "
         "run on both meshes, the regular layout included.",
         views=(
             View("sod/convergence", "Particle density and energy L1 per setting: the regular layout, the jittered "
                  "layouts' mean and range, and each order's range over the seeds", (
                      "ppc", "cfl", "h", "mpm_particles_L1", "order_particles_L1", "jittered_particles_L1_mean",
                      "jittered_particles_L1_lo", "jittered_particles_L1_hi", "order_particles_L1_lo",
                      "order_particles_L1_hi", "mpm_energy_L1", "order_energy_L1", "order_energy_L1_lo",
                      "order_energy_L1_hi"), {}, "convergence.png"),
             View("sod/convergence", "Nodal density L1 per setting beside the source's table, the fixed-mesh FEM and "
                  "the finite-volume reference", (
                      "ppc", "cfl", "h", "source_L1", "mpm_nodes_L1", "ratio_nodes_L1", "order_nodes_L1",
                      "order_nodes_L1_lo", "order_nodes_L1_hi", "source_order_L1", "fem_lumped_L1",
                      "order_fem_lumped_L1", "fv_L1", "order_fv_L1")),
             View("sod/convergence", "What sets the floor: volume gained by the particles, relative drift of the "
                  "total energy, signed mean error in the smooth region, position error of the rarefaction head", (
                      "ppc", "cfl", "h", "mpm_volume_drift", "mpm_energy_drift", "mpm_particles_mean_error_smooth",
                      "mpm_nodes_mean_error_smooth", "mpm_head_shift", "fem_consistent_head_shift")),
             View("sod/regions", "Share of the nodal L1 error by region of the exact solution, per setting",
                  ("ppc", "cfl", "h", "L1") + tuple(f"share_{k}" for k in range(len(REGION_NAMES))),
                  {"method": "MPM nodes"}, "regions.png"),
             View("sod/extrema", "New extrema per particle-step at particles crossing a node, at moving particles that "
                  "do not cross and at every particle that does not cross", (
                      "ppc", "cfl", "h", "crossings_per_step", "moving_share", "density_new_per_step",
                      "density_rate_crossing", "density_rate_moving", "density_moving_ratio", "density_rate_ratio",
                      "energy_rate_crossing", "energy_rate_moving", "energy_moving_ratio"), {}, "extrema.png"),
             View("sod/ppc", "Error against particles per cell", ("h", "ppc", "ok", "nodes_L1", "particles_L1"), {},
                  "ppc.png"),
             View("sod/mass", "Lumped against consistent mass, MPM and FEM"),
             View("sod/plateau", "What moves the floor: one setting changed at a time", (
                 "h", "variant", "ok", "nodes_L1", "nodes_vs_study", "particles_L1", "particles_vs_study",
                 "density_new_extrema_per_step")),
         )),
    Page("burgers", "Viscous Burgers",
         "The viscous Burgers equation with initial and boundary data from an exact solution, MPM with the exact and "
         "with the calculated acceleration (the latter at each number of particles per cell the JSON beside each "
         "table records, the source's among them) beside P1 FEM with consistent and lumped mass, against the "
         "source's table (the corrected entries are marked in the source_corrected column). The settings C13 judges "
         "also run, at the largest eps, on jittered particle layouts, one per seed: each order comes with its mean "
         "and range over the layouts. The solution and norm compared with the source are chosen by the norms table.",
         views=(
             View("burgers/orders", "Least-squares orders of the solution and norm compared with the source: the "
                  "regular layout's (fitted), and the mean and range over the runs of the regular and jittered layouts",
                  ("method", "ppc", "eps", "fitted", "h_range", "runs", "fitted_mean", "fitted_lo", "fitted_hi",
                   "runs_h_range", "source_fitted"),
                  {"solution": _SOLUTION, "where": _WHERE, "norm": _NORM}, "convergence.png"),
             View("burgers/errors", "Errors on every mesh beside the source, largest eps: the regular layout, and the "
                  "mean and range over the layouts", (
                      "method", "h", _COMPARED, "runs", f"{_COMPARED}_mean", f"{_COMPARED}_lo", f"{_COMPARED}_hi",
                      "source", "source_corrected", f"ratio_{_COMPARED}", "steps"),
                  {"solution": _SOLUTION, "eps": _FIRST_EPS}, "seeds.png"),
             View("burgers/norms", "Which solution and norm: median measured/source and spread over eps", (
                 "solution", "method", "median_ratio", "eps_spread_finest", "source_eps_spread_finest"),
                  {"where": _WHERE, "norm": _NORM}, "solutions.png"),
             View("burgers/timestep", "Time error: the time step refined at one mesh", (
                 "method", "eps", "refine", "dt", _COMPARED, f"time_error_{_NORM}", "time_below_space"), {},
                  "timestep.png"),
             View("burgers/ppc", "Error against particles per cell", ("method", "h", "ppc", _COMPARED, "best_ppc"), {},
                  "ppc.png"),
             View("burgers/lumping", "Lumped against consistent mass",
                  ("method", "mass", "h", "where", "L1", "L2", "max"), {}, "lumping.png"),
             View("burgers/diagnosis", "The calculated acceleration with one change at a time (regular layout)",
                  ("variant", "h", f"{_WHERE}_L1", "order_L1"), {}, "diagnosis.png"),
         )),
    Page("identification", "The source's unstated settings, identified from its own tables",
         "For each of the source's tables, every candidate for what the slides leave unsaid runs on the table's "
         "meshes, one setting held fixed over the whole table; its misfit is the mean absolute log ratio of its error "
         "to the source's entry (for Burgers over the meshes and the five eps), against the corrected table and, "
         "beside it, the printed one. The rows shown are the source-matching settings: the least misfit of each "
         "source row and every candidate within the rule book's band of it.",
         views=(
             View("identification/sod", "Sod: the source-matching settings of the L1 and L2 columns",
                  ("source_row", "rank", "ppc", "cfl", "quantity", "norm", "misfit", "misfit_raw", "meshes"),
                  {"matching": "True"}),
             View("identification/burgers", "Burgers: the source-matching settings of the exact- and the "
                  "calculated-acceleration rows", ("source_row", "rank", "solution", "dt_rule", "cfl", "ppc", "norm",
                                                  "misfit", "misfit_raw", "meshes"),
                  {"matching": "True"}),
         )),
    Page("budget", "Error budget (E1) and bases (E2)",
         "Every combination of the four stages in MPM or exact form, on each mesh and basis: the error of each "
         "combination, its exact decomposition into each stage's Shapley value (main effect plus an equal share of "
         "every interaction the stage takes part in) and the interactions; each stage's signed error field and where "
         "along the tube it sits; and Sod with each basis.",
         views=(
             View("budget/shapley", "Sod, particle density L1: each stage's Shapley value and share of v(all MPM) - "
                  "v(all exact); removed and alone are the one-at-a-time views", _SHAPLEY,
                  {"problem": "sod", "norm": "particles"}, "shapley_sod.png"),
             View("budget/shapley", "Sod, nodal density L1", _SHAPLEY, {"problem": "sod", "norm": "nodes"}),
             View("budget/shapley", "Burgers, particle velocity L1", _SHAPLEY, {"problem": "burgers"},
                  "shapley_burgers.png"),
             View("budget/interactions", "Sod, point-mass P1, particles: the interactions (Moebius terms of two and "
                  "more stages)", ("h", "stages", "term", "share"),
                  {"problem": "sod", "basis": "mpm", "norm": "particles"}),
             View("budget/regions", "Sod, point-mass P1: share of each Shapley error field's L1 by region of the exact "
                  "solution (C12)",
                  ("h", "basis", "field", "L1") + tuple(f"share_{n.replace(' ', '_')}" for n in REGION_NAMES),
                  {"basis": "mpm"}, "fields_sod.png"),
             View("budget/bases", "E2: Sod with each basis, MPM stages",
                  ("basis", "h", "ok", "particles_L1", "nodes_L1", "plateau_noise", "plateau_offset"), {},
                  "bases.png"),
         )),
    Page("time", "Time error (C1) and grid crossing (C2)",
         "At a fixed mesh and fixed particles, the time step alone is refined against a much smaller step: the global "
         "error at the final time and the local error of one step from a common state; and the third time derivative "
         "of one particle's position along its path, measured at each node crossing beside the slides' formula.",
         views=(
             View("time/time_order", "Global error against dt: fitted order per problem, basis and quantity",
                  ("problem", "basis", "quantity", "fitted_order"), {"order": ""}, "time_order.png"),
             View("time/local_error", "Local error of one step: fitted order",
                  ("problem", "basis", "quantity", "fitted_order"), {"order": ""}),
             View("time/crossing_summary", "Jump of dA/dt at node crossings, measured against the slides' formula",
                  ("basis", "acceleration", "crossings", "median_ratio", "max_ratio_error", "max_abs_ratio",
                   "median_abs_measured"), {}, "crossing.png"),
         )),
    # --- remedies: E5 ---
    Page("remedies", "Remedies for the plateau (E5)",
         "Sod (the Sod study's MPM settings) and Burgers (the few particles per cell at which its calculated "
         "acceleration stalls; every setting in the JSON beside each table) with each remedy alone and in "
         "combination: the B-spline averaged over the particle domain, the Taylor least-squares stress "
         "reconstruction, the volume reset against the grid and a PIC/FLIP blend. Errors over grid nodes and over "
         "particles; the accuracy per cost beside fixed-mesh FEM and a finite-volume reference.",
         views=(
             View("remedies/orders", "Each remedy by its lowest successive order and its error at the finest mesh", (
                 "problem", "remedy", "min_order_nodes_L1", "min_order_particles_L1", "fitted_order_nodes_L1",
                 "fitted_order_particles_L1", "h_finest", "finest_nodes_L1", "finest_particles_L1",
                 "max_fv_ratio_nodes_L1", "max_fv_ratio_particles_L1", "removes_plateau"), {}, "errors.png"),
             View("remedies/cost", "Accuracy per cost: Sod density L1 against work and wall time (one run each on a "
                  "shared machine; no verdict uses wall time)", ("method", "h", "density_L1", "particles_L1", "work",
                                                                 "wall_s"), {}, "cost.png"),
         )),
    Page("drift", "What makes Sod's particle error grow (C11's mechanism)",
         "Sod with the study's MPM settings and variants that each change one thing: the form of the density update, "
         "the quadrature of the volume rate, the time step, the particles per cell and the volume reset against the "
         "grid, on the regular layout and, for some variants, on jittered layouts. Per variant and mesh: the "
         "particle and nodal density L1 errors, the volume drift (the particles' total volume minus the tube's) and "
         "the successive orders.",
         views=(
             View("drift/drift", "Per variant and mesh, regular layout: errors, volume drift and orders", (
                 "variant", "h", "particles_L1", "nodes_L1", "volume_drift", "order_particles_L1",
                 "order_nodes_L1", "particles_vs_study"), {"layout": "regular"}, "drift.png"),
             View("drift/drift", "The jittered layouts, one row per seed and mesh", (
                 "variant", "seed", "h", "particles_L1", "nodes_L1", "volume_drift", "order_particles_L1"),
                  {"layout": "jittered"}),
         )),
    Page("mechanism", "Where the growth comes from, stage by stage (E6a)",
         "Sod and Burgers at few particles per cell, on the regular layout and jittered ones, with every stage of the "
         "step in MPM form and with each stage alone made exact (the error budget's exact forms): the particle L1 "
         "error on each mesh and its order between successive meshes, per layout; then, per particle count and mesh "
         "pair, the orders' range over the layouts and on how many of the layouts where all MPM grows each subset "
         "converges.",
         views=(
             View("mechanism/summary", "Per particle count, subset and mesh pair: the orders over the layouts, the "
                  "layouts where all MPM grows and those of them where the subset stops the growth or converges", (
                      "problem", "ppc", "made_exact", "h_coarse", "h_fine", "runs", "order_min", "order_mean",
                      "order_max", "order_regular", "mpm_growing", "stops_growth", "converging_where_mpm_grows",
                      "turns_growth"), {}, "growth.png"),
         )),
    Page("lumping", "The grid masses in 1D: lumped, consistent, exact and FMPM(k) (E7)",
         "The same run with each grid mass, all else equal: the lumped mass, the particle mass matrix solved "
         "(consistent), the mass stage made exact, and FMPM(k), the particle mass matrix's inverse by k terms of its "
         "series. Sod with the study's settings (density) and Burgers' compared solution at the first eps with both "
         "accelerations (velocity), over the nodes and over the particles; every run on the numpy step, with its "
         "wall time per step.",
         views=(
             View("lumping/errors", "Per run: the errors over the nodes and the particles, and the wall time per step",
                  ("problem", "acceleration", "h", "mass", "ok", "quantity", "norm", "nodes", "particles", "steps",
                   "step_ms")),
         )),
    Page("defect", "The local defect, accumulated: a prediction of the particle error",
         "The mechanism study's all-MPM runs once more on the numpy step with an observer: at every step the defect "
         "of each quantity the particle update takes from the grid (the particle acceleration, the motion, the rate "
         "L_p) against its exact value at that step, accumulated along each particle's path with the update's own "
         "propagation. The norm of the accumulated defect is the run's predicted particle error, beside the measured "
         "one (Sod: density; Burgers: velocity; the budget's norm).",
         views=(
             View("defect/defect", "Per run: measured and predicted particle L1 errors, their ratio, the part the "
                  "prediction misses and each component", (
                      "problem", "ppc", "layout", "seed", "h", "steps", "measured_L1", "predicted_L1", "ratio",
                      "residual_L1", "acceleration_L1", "velocity_L1", "rate_L1"), {}, "defect.png"),
         )),
)
