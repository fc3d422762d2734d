"""The exact stages of the error budget (E1) and the bases' conservation (E2)."""

from dataclasses import replace
from functools import lru_cache

import numpy as np
import pytest

from baselines.exact import riemann
from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.models.euler import IdealGas
from mpm_fem.core.shape import make_shape
from mpm_fem.core.step import Stages, Walls, explicit_step
from mpm_fem.core.transfer import nodal_internal_force
from mpm_fem.exact_stages import FieldStages
from mpm_fem.exact_stages.projection import exact_projection
from mpm_fem.exact_stages.quadrature import quadrature
from mpm_fem.measure.decomposition import decompose, label
from mpm_fem.measure.timing import field_difference, field_on
from mpm_fem.problems import burgers, sod
from mpm_fem.problems.sod import RiemannFields
from studies import budget as study

SOD = ((1.0, 0.0, 1.0), (0.125, 0.0, 0.1))


class Polynomial:
    """rho = 1 + x + x^2, v = x, sigma = x^3, with a kink-free breakpoint list (tests the splits)."""

    def integrand(self, x, t):
        return 1 + x + x**2, x, x**3

    def breakpoints(self, t):
        return np.array([0.3141, 0.777])


@pytest.mark.parametrize("basis", ["mpm", "bspline", "bspline_gimp"])
def test_exact_projection_integrates_polynomial_fields_to_round_off(basis):
    """m_i = int rho S_i, P_i = int rho v S_i, F_i = -int sigma S_i' against a 200 000-point
    midpoint rule (error ~1e-11) of the same integrands, ``S_i`` the grid functions of the basis
    (the quadratic B-splines for the particle-domain B-spline too)."""
    grid = uniform_grid(0.0, 1.0, 0.1)
    got = exact_projection(grid, basis, Polynomial(), 0.0)
    n = 200_000
    x = (np.arange(n) + 0.5) / n
    w = np.full(n, 1.0 / n)
    shape = make_shape(grid, x, w, "bspline" if basis.startswith("bspline") else basis)
    rho, v, sigma = Polynomial().integrand(x, 0.0)
    want = (shape.scatter(w * rho), shape.scatter(w * rho * v), nodal_internal_force(shape, w, sigma))
    for name, a, b in zip(("m_i", "P_i", "F_i"), (got.m_i, got.P_i, got.F_i), want, strict=False):
        err = np.abs(a - b).max()
        assert err < 1e-9, f"{name} differs from the fine midpoint rule by {err:.2e}"


def test_quadrature_splits_at_nodes_midpoints_and_breakpoints():
    grid = uniform_grid(0.0, 1.0, 0.25)
    x, w = quadrature(grid, [0.3, 1.5, -1.0])
    assert w.sum() == pytest.approx(1.0, rel=1e-14)
    assert x.size == 5 * 9  # 8 half cells, one split at 0.3; points outside the domain are ignored


def test_riemann_reference_fields_are_the_exact_cell_averages():
    """v* = average of u over [x - l, x + l] (pieces cut at the waves), v*_x its difference
    quotient, a* = dv*/dt + v* v*_x with dv*/dt checked by a central difference in t."""
    l = 0.01
    fields = RiemannFields(*SOD, 0.5, 1.4, l)
    x = np.random.default_rng(0).uniform(0, 1, 500)

    def average(t):
        lo, hi = (x - l)[:, None], (x + l)[:, None]
        cuts = np.clip(fields.breakpoints(t)[None, :], lo, hi)
        edges = np.concatenate((lo, cuts, hi), axis=1)
        mids, widths = 0.5 * (edges[:, 1:] + edges[:, :-1]), np.diff(edges, axis=1)
        return (riemann.sample(mids, t, *SOD)[1] * widths).sum(axis=1) / (2 * l)

    t, dt = 0.13, 1e-6
    v, v_x, a = fields.reference(x, t)
    u_hi, u_lo = riemann.sample(x + l, t, *SOD)[1], riemann.sample(x - l, t, *SOD)[1]
    assert np.abs(v - average(t)).max() < 1e-13
    assert np.abs(v_x - (u_hi - u_lo) / (2 * l)).max() < 1e-12
    v_t = (average(t + dt) - average(t - dt)) / (2 * dt)
    assert np.abs(a - (v_t + v * v_x)).max() < 1e-6 * np.abs(a).max()


@pytest.mark.parametrize("basis", ["mpm", "bspline", "bspline_gimp"])
def test_exact_projection_and_mass_give_the_exact_nodal_values(basis):
    """With the projection and the FE + mass stage exact, the grid holds v(x_i, t) and a(x_i, t)
    (Dirichlet data at the ends) whatever the particles carry."""
    settings = burgers.BurgersSettings(h=0.05, projection="exact", mass="exact", basis=basis)
    grid = uniform_grid(0.0, 2.0, settings.h)
    particles = burgers.initial_particles(settings, grid)
    noisy = particles.replace(velocity=particles.velocity + 0.1 * np.sin(37 * particles.x))
    exact = burgers.exact_fields(settings)
    model = burgers.ViscousBurgers(settings.eps)
    _, state = explicit_step(grid, noisy, model, burgers.Dirichlet(settings.exact.v), 0.1, 1e-3, settings.stages,
                             exact=FieldStages(exact))
    v, _, a = exact.reference(grid.nodes, 0.1)
    inner = slice(1, -1)
    assert np.abs(state.velocity - v).max() < 1e-14
    assert np.abs(state.acceleration[inner] - a[inner]).max() < 1e-12


def test_exact_stages_without_exact_fields_stop_with_a_message():
    grid = uniform_grid(0.0, 1.0, 0.1)
    settings = sod.SodSettings(h=0.1)
    particles = sod.initial_particles(settings, grid)
    with pytest.raises(ValueError, match="exact fields"):
        explicit_step(grid, particles, IdealGas(), Walls(), 0.0, 1e-3, Stages(projection="exact"))
    with pytest.raises(TypeError, match="FieldStages"):  # the fields alone are not the stages the step reaches
        explicit_step(grid, particles, IdealGas(), Walls(), 0.0, 1e-3, Stages(projection="exact"),
                      exact=sod.exact_fields(settings))
    with pytest.raises(ValueError, match="USL and USF"):
        Stages(interpolation="exact", scheme="musl")


# the particle-domain B-spline on the numpy step in the fast set; its compiled plain run (a Burgers loop variant
# of its own, its pass 1 with the stored rows alone 1-1.5 CPU-min of numba on a cold cache) with the slow tests
@pytest.mark.parametrize(("basis", "kernel"), [("mpm", "fused"), ("bspline_gimp", "numpy"),
                                               pytest.param("bspline_gimp", "fused", marks=pytest.mark.slow)])
def test_every_stage_exact_leaves_the_time_error_of_the_step(basis, kernel):
    """Burgers (h = 0.02): with every stage exact the remainder is first order in dt (halves when
    dt halves) and its dt -> 0 extrapolation is below 2% of it: no other error is left. The
    particle-domain B-spline too: its stage switches remove its projection, mass and
    interpolation errors as they do the point-mass ones."""
    base = burgers.BurgersSettings(h=0.02, projection="exact", mass="exact", interpolation="exact", basis=basis,
                                   kernel=kernel)
    runs = {k: burgers.simulate(replace(base, refine=k), progress=False) for k in (1, 2)}
    points = np.linspace(0.1, 1.9, 4001)

    def error_field(result):
        P = result.particles
        order = np.argsort(P.x)
        return np.interp(points, P.x[order], P.velocity[order]) - base.exact.v(points, result.t)

    e1, e2 = error_field(runs[1]), error_field(runs[2])
    l1 = lambda e: float(np.trapezoid(np.abs(e), points))  # noqa: E731
    ratio = l1(e1) / l1(e2)
    assert 1.8 < ratio < 2.2, f"remainder at dt {l1(e1):.3g}, at dt/2 {l1(e2):.3g}: ratio {ratio:.3f}"
    extrapolated = l1(2 * e2 - e1)
    assert extrapolated < 0.02 * l1(e1), f"dt -> 0 remainder {extrapolated:.3g} vs {l1(e1):.3g} at dt"
    mpm = burgers.simulate(burgers.BurgersSettings(h=0.02, basis=basis, kernel=kernel), progress=False)
    assert field_difference(mpm.particles, runs[1].particles, (0.1, 1.9)) > 0.1 * l1(e1) / 1.8


def test_every_stage_exact_sod_remainder_is_first_order_in_h():
    """Sod (8 particles per cell, CFL 0.1): every stage exact at dt and dt/2; the dt -> 0
    remainder comes from averaging the exact fields over one cell at the waves, O(h)."""
    out = []
    for h in (0.02, 0.01):
        base = sod.SodSettings(h=h, ppc=8, cfl=0.1, projection="exact", mass="exact", interpolation="exact")
        L1 = [sod.errors(base, sod.simulate(replace(base, refine=k), progress=False))["density"]["particles"]["L1"]
              for k in (1, 2)]
        out.append(2 * L1[1] - L1[0])
    order = np.log2(out[0] / out[1])
    assert 0.7 < order < 1.3, f"all-exact remainders {out}, order {order:.3f}"


@pytest.mark.parametrize("basis", ["mpm", "gimp", "bspline"])
def test_bases_keep_partition_of_unity_and_conservation_in_a_step(basis):
    """Sod, one step: total mass is the nodal mass (partition of unity), the nodal forces sum to
    zero (sum_i G_ip = 0), and the particle momentum changes by dt sum_i m_i a_i: only the wall
    nodes' forces, which the walls cancel, act on the gas."""
    settings = sod.SodSettings(h=0.02, ppc=4, basis=basis)
    grid = uniform_grid(0.0, 1.0, settings.h)
    particles = sod.initial_particles(settings, grid)
    moved = particles.replace(velocity=0.05 * np.sin(6 * particles.x))
    dt = 1e-3
    new, state = explicit_step(grid, moved, IdealGas(), Walls(), 0.0, dt, settings.stages)
    shape = make_shape(grid, moved.x, moved.volume, basis)
    F = nodal_internal_force(shape, moved.volume, -moved.pressure)
    scale = np.abs(F).max()
    assert abs(F.sum()) < 1e-12 * scale, f"sum of nodal forces {F.sum():.3e}"
    assert state.mass.sum() == pytest.approx(moved.mass.sum(), rel=1e-14)
    dP = (new.mass * new.velocity).sum() - (moved.mass * moved.velocity).sum()
    assert dP == pytest.approx(dt * (state.mass * state.acceleration).sum(), rel=1e-12, abs=1e-15)
    walls = grid.boundary_nodes
    assert dP == pytest.approx(-dt * F[walls].sum(), rel=1e-10)
    assert new.mass.sum() == moved.mass.sum()


# ---------------------------------------------------------------- E1: every subset of the stages

ALL, NONE = frozenset(study.STAGES), frozenset()
SMALL = {"sod": (0.05, {"ppc": 4, "cfl": 0.1}), "burgers": (0.05, {})}


@lru_cache(maxsize=None)
def _small(problem: str):
    h, settings = SMALL[problem]
    return problem, h, study.subset_fields(problem, h, "mpm", settings)


@pytest.fixture(params=sorted(SMALL))
def small(request):
    """The sixteen subsets of a small real case: Sod (h = 0.05, 4 particles per cell), Burgers (h = 0.05)."""
    return _small(request.param)


def test_small_case_has_every_subset_and_its_shapley_values_add_up(small):
    """v(S) = L1 of e_S; the four Shapley values sum to v(all MPM) - v(all exact) within 1e-12
    relative, the Moebius terms to v(all MPM), in the table rows too."""
    problem, h, (fields, weights, points, runs) = small
    assert fields is not None and len(fields) == 16 and len(runs) == 16 and all(r["ok"] for r in runs)
    assert set(weights) == ({"particles", "nodes"} if problem == "sod" else {"particles"})
    for norm, w in weights.items():
        v = {S: float(np.sum(w * np.abs(f[norm]))) for S, f in fields.items()}
        d = decompose(v, study.STAGES)
        gap = v[ALL] - v[NONE]
        assert abs(gap) > 0.1 * v[ALL], f"{problem} {norm}: the stages change nothing? {v}"
        assert abs(sum(d.shapley.values()) - gap) <= 1e-12 * abs(gap)
        assert abs(sum(d.moebius.values()) - v[ALL]) <= 1e-12 * v[ALL]
    got = {(problem, h, "mpm"): {"subsets": {norm: {label(S): float(np.sum(w * np.abs(f[norm])))
                                                    for S, f in fields.items()}
                                             for norm, w in weights.items()}}}
    rows = study.subset_rows(got)
    assert (len(rows) == 16 * len(weights)
            and {r["mpm_stages"] for r in rows} >= {"none", "interpolation+mass+projection+time"})
    shapley, interactions = study.decomposition_rows(rows)
    for norm in weights:
        group = [r for r in shapley if r["norm"] == norm]
        assert (abs(sum(r["shapley"] for r in group) - (group[0]["mpm_error"] - group[0]["exact_error"]))
                <= 1e-12 * group[0]["mpm_error"])
        assert sum(r["share"] for r in group) == pytest.approx(1.0, abs=1e-12)
        assert len([r for r in interactions if r["norm"] == norm]) == 11


def test_small_case_field_decomposition_adds_exactly_at_every_point(small):
    """The Shapley error fields add up to e_MPM - e_exact point by point (round-off only)."""
    _, _, (fields, weights, _, _) = small
    for norm in weights:
        d = decompose({S: f[norm] for S, f in fields.items()}, study.STAGES)
        gap = fields[ALL][norm] - fields[NONE][norm]
        assert np.abs(sum(d.shapley.values()) - gap).max() <= 1e-14 * np.abs(gap).max()


def test_time_exact_is_the_dt_to_zero_extrapolation():
    """Burgers, every stage exact: the run at dt keeps the time error of the step, which the
    extrapolation from dt and dt/2 removes to below 5% (the remainder is O(dt^2))."""
    _, _, (fields, weights, _, _) = _small("burgers")
    l1 = lambda S: float(np.sum(weights["particles"] * np.abs(fields[S]["particles"])))  # noqa: E731
    assert l1(NONE) < 0.05 * l1(frozenset({"time"})), (l1(NONE), l1(frozenset({"time"})))


# the numpy step in the fast set; the compiled runs (the particle-domain B-spline's Sod loop and exact stages,
# its pass 1 with the stored rows alone 1-1.5 CPU-min of numba on a cold cache) with the slow tests
@pytest.mark.parametrize("kernel", ["numpy", pytest.param("fused", marks=pytest.mark.slow)])
def test_the_particle_domain_bspline_runs_every_subset_and_its_shapley_values_add_up(kernel):
    """E5's closest remedy, the B-spline averaged over the particle domain, in the budget: the
    sixteen subsets run (Sod, h = 0.05), its stages change the error, the Shapley values add up to
    v(all MPM) - v(all exact), and its all-MPM run is the remedy's plain run, bit for bit."""
    h, settings = SMALL["sod"]
    settings = {**settings, "kernel": kernel}
    fields, weights, points, runs = study.subset_fields("sod", h, "bspline_gimp", settings)
    assert fields is not None and all(r["ok"] for r in runs)
    for norm, w in weights.items():
        v = {S: float(np.sum(w * np.abs(f[norm]))) for S, f in fields.items()}
        gap = v[ALL] - v[NONE]
        assert abs(gap) > 0.1 * v[ALL], f"{norm}: the stages change nothing? {v}"
        assert abs(sum(decompose(v, study.STAGES).shapley.values()) - gap) <= 1e-12 * abs(gap)
    plain = sod.simulate(sod.SodSettings(h=h, basis="bspline_gimp", **{**study.SOD, **settings}), progress=False)
    exact = sod.exact(sod.SodSettings(), points, plain.t)[0]
    np.testing.assert_array_equal(field_on(points, plain.particles.x, plain.particles.density) - exact,
                                  fields[ALL]["particles"])
    plan = study.plan("full")["budget"]
    assert ({h for p, h, b in plan if (p, b) == ("sod", "bspline_gimp")}
            == {h for p, h, b in plan if (p, b) == ("sod", "bspline")})


def test_the_roundoff_table_compares_the_two_arithmetics():
    """``roundoff.csv``: P1's Sod budget runs again on the numpy step; each share from both, the
    change in percentage points; E1's evidence names the largest change per mesh."""
    from mpm_fem.measure.claims import _roundoff_text
    from mpm_fem.measure.decomposition import share_changes
    from studies.budget import ROUNDOFF, ROUNDOFF_H, plan

    cases = plan("full")["roundoff"]
    assert cases and all(key[::2] == ROUNDOFF and case["kernel"] == "numpy" for key, case in cases.items())
    assert set(cases) == {k for k in plan("full")["budget"] if k[::2] == ROUNDOFF and k[1] in ROUNDOFF_H}
    assert set(plan("deep")["roundoff"]) == {k for k in plan("deep")["budget"] if k[::2] == ROUNDOFF}
    key = {"problem": "sod", "h": 0.01, "basis": "mpm", "norm": "particles"}
    fused = [{**key, "stage": "mass", "share": -0.5, "mpm_error": 2.0, "exact_error": 1.0},
             {**key, "stage": "time", "share": 0.25, "mpm_error": 2.0, "exact_error": 1.0},
             {**key, "basis": "gimp", "stage": "mass", "share": 0.1, "mpm_error": 2.0, "exact_error": 1.0}]
    numpy = [{**key, "stage": "mass", "share": -0.48, "mpm_error": 2.1, "exact_error": 1.0},
             {**key, "stage": "time", "share": 0.25, "mpm_error": 2.1, "exact_error": 1.0}]
    rows = share_changes(fused, numpy)
    assert [r["stage"] for r in rows] == ["mass", "time"]  # the GIMP row ran on one arithmetic only
    assert rows[0]["change_pp"] == pytest.approx(-2.0) and rows[1]["change_pp"] == 0.0
    assert rows[0]["mpm_error_numpy"] == 2.1
    text = _roundoff_text({"budget/roundoff": [{k: str(v) for k, v in r.items()} for r in rows]}, "sod")
    assert "at most 2 percentage points at h = 0.01" in text
    assert _roundoff_text({}, "sod") == "" and _roundoff_text({"budget/roundoff": rows}, "burgers") == ""


# ---------------------------------------------------------------- E1, E2 over particle layouts

def test_the_layout_budgets_cover_every_particle_count_and_seed_on_the_two_coarsest_meshes():
    """Full tier: P1's budget on the two coarsest meshes of each problem and E2's bases on the three coarsest, at
    4, 8 and 16 per cell on the regular layout and the Sod study's five jittered seeds; the study's own setting is
    the study's own case (the same dict, run once); the deep tier holds the full one's; the quick tier none."""
    from studies import sod as sod_study

    assert study.SEEDS == sod_study.SEEDS and study.LAYOUT_PPC == (4, 8, 16)
    full, deep, quick = (study.plan(t) for t in ("full", "deep", "quick"))
    settings = {(n, lay, s) for n in study.LAYOUT_PPC for lay, s in study.LAYOUTS}
    assert len(settings) == 18 and ("regular", 0) in study.LAYOUTS
    for problem in ("sod", "burgers"):
        meshes = study.H[problem][:2]
        got = {(h, n, lay, s) for p, h, b, n, lay, s in full["layouts"] if (p, b) == (problem, "mpm")}
        assert got == {(h, *x) for h in meshes for x in settings}, problem
        own = study.SOD if problem == "sod" else study.BURGERS
        for h in meshes:
            assert full["layouts"][(problem, h, "mpm", own["ppc"], "regular", 0)] == full["budget"][(problem, h, "mpm")]
    assert {(h, b) for h, b, *_ in full["bases_layouts"]} == {(h, b) for h in study.BASES_H[:3] for b in study.BASES}
    assert full["bases_layouts"][(0.01, "gimp", 16, "regular", 0)] == full["bases"][(0.01, "gimp")]
    case = full["layouts"][("sod", 0.01, "mpm", 4, "jittered", 3)]
    assert (case["ppc"], case["layout"], case["seed"]) == (4, "jittered", 3)
    assert set(full["layouts"]) <= set(deep["layouts"]) and set(full["bases_layouts"]) <= set(deep["bases_layouts"])
    assert not quick["layouts"] and not quick["bases_layouts"]


def test_the_cost_model_reproduces_the_measured_budgets():
    """The per-step model (BUDGET_STEP_MS) against the full tier's measured budgets (runs.csv of 2026-11-26): P1's
    Sod budget at h = 0.01 took 8.3 CPU-s, at 0.00125 258; Burgers at 0.01 28.8. Within 30 %."""
    for key, seconds in ((("sod", 0.01, "mpm"), 8.3), (("sod", 0.00125, "mpm"), 258.0),
                         (("burgers", 0.01, "mpm"), 28.8), (("sod", 0.005, "gimp"), 32.0)):
        got = study.cost(study.plan("deep")["budget"][key]) * study.SECONDS_PER_COST
        assert 0.7 < got / seconds < 1.3, (key, got, seconds)
    cheaper = study.cost({"kind": "budget", "problem": "sod", "h": 0.01, "basis": "mpm", "ppc": 4})
    assert 0.6 < cheaper / study.cost({"kind": "budget", "problem": "sod", "h": 0.01, "basis": "mpm"}) < 0.9


@pytest.fixture(scope="module")
def jittered_budget():
    """Sod's small budget (h = 0.05, 4 per cell, the study's CFL) on the regular layout and on the jittered one of
    seed 1, through the study's case function."""
    h = SMALL["sod"][0]
    cases = {("sod", h, "mpm", 4, lay, s): {"kind": "budget", "problem": "sod", "h": h, "basis": "mpm", "K": study.K,
                                            "ppc": 4, **({"layout": lay, "seed": s} if s else {})}
             for lay, s in (("regular", 0), ("jittered", 1))}
    return {key: study.budget_case(case) for key, case in cases.items()}


def test_a_jittered_budget_runs_every_subset_and_its_rows_name_the_setting(jittered_budget):
    """The case function takes the particle setting (the jittered run differs from the regular one, within a
    factor 3 in v(all MPM)); the subset and Shapley rows carry ppc, layout and seed, the declared columns."""
    from mpm_fem.measure.schema import BUDGET_SHAPLEY, BUDGET_SUBSETS

    assert all(r["ok"] for r in jittered_budget.values())
    rows = study.subset_rows(jittered_budget)
    BUDGET_SUBSETS.check(rows)
    assert {(r["ppc"], r["layout"], r["seed"]) for r in rows} == {(4, "regular", 0), (4, "jittered", 1)}
    shapley, _ = study.decomposition_rows(rows)
    BUDGET_SHAPLEY.check(shapley)
    mpm = {(r["layout"], r["norm"]): r["mpm_error"] for r in shapley if r["stage"] == "mass"}
    for norm in ("particles", "nodes"):
        ratio = mpm[("jittered", norm)] / mpm[("regular", norm)]
        assert ratio != 1.0 and 1 / 3 < ratio < 3, (norm, ratio)
    for layout in ("regular", "jittered"):
        group = [r for r in shapley if r["layout"] == layout and r["norm"] == "particles"]
        assert sum(r["share"] for r in group) == pytest.approx(1.0, abs=1e-12)
