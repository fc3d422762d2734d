"""The 2D Python entry points ``mpm_fem.plane.axis`` / ``.vortex`` (mpm_fem/app/plane_api.py): a tiny run's
errors and CFL number, every bad input refused with ``UsageError`` in one line before any work, the
stability limit the refusal rests on, and ``mpm_fem.plane`` resolving to the checked entry points."""

import sys
import time

import numpy as np
import pytest

import mpm_fem
from mpm_fem.app import plane_api
from mpm_fem.app.guard import UnknownSetting, UsageError
from mpm_fem.bases import plugins, registry
from mpm_fem.plane.model import InversionError
from mpm_fem.plane.run import PlaneSettings, run, setup
from mpm_fem.plane.stability import LUMPED, cfl_limit, linearised_cfl, p_wave_ratio


@pytest.fixture(autouse=True)
def own_registry(monkeypatch):
    """Each test registers into a copy of the registry: no test's basis leaks into another test."""
    monkeypatch.setattr(registry, "_BASES", dict(registry._BASES))
    monkeypatch.setattr(plugins.LOADER, "loaded", {})
    monkeypatch.setattr(plugins.LOADER, "failed", {})


def test_axis_runs_a_tiny_case_with_second_order_displacement_errors_and_the_cfl_it_was_given():
    coarse, fine = mpm_fem.plane.axis(h=1 / 4), mpm_fem.plane.axis(h=1 / 8)
    e = [r.errors["displacement"]["particles"]["L2"] for r in (coarse, fine)]
    ratio = e[0] / e[1]
    # P1, 2 x 2 regular particles, one period: the displacement error is second order in h (ratio 4)
    assert 3.0 <= ratio <= 4.5, f"L2 {e[0]:.3g} at h=1/4, {e[1]:.3g} at h=1/8: ratio {ratio:.3g}"
    assert coarse.cfl == pytest.approx(0.25, rel=1e-12) and coarse.steps == 32, (coarse.cfl, coarse.steps)
    assert coarse.particles.n == 256 and 0 < coarse.errors["acceleration"]["nodes"]["L2"] < np.inf


def test_p1_is_the_point_mass_basis_and_a_package_module_name_basis_runs():
    p1 = mpm_fem.plane.axis(h=1 / 4, basis="p1")
    assert p1.settings.basis == "mpm"
    hats = mpm_fem.plane.axis(h=1 / 4, basis="plugin_bases:Hats")  # tests/plugin_bases.py: P1 under another name
    assert hats.settings.basis == "hats"
    a, b = (r.errors["displacement"]["particles"]["L2"] for r in (p1, hats))
    assert a == pytest.approx(b, rel=1e-12), (a, b)


def test_a_zero_y_amplitude_leaves_the_y_displacement_zero():
    r = mpm_fem.plane.axis(h=1 / 4, amplitude_y=0.0)
    uy = np.abs(r.particles.displacement[:, 1]).max()
    ux = np.abs(r.particles.displacement[:, 0]).max()
    assert uy < 1e-18 and ux > 1e-6, f"max |u_y| = {uy:.3g}, max |u_x| = {ux:.3g}"


@pytest.mark.parametrize("entry, settings, words", [
    ("axis", {"h": 0.3}, "h=0.3 does not divide the domain"),
    ("vortex", {"h": 0.4}, "does not divide the domain"),
    ("axis", {"h": -1.0}, "cell size h must be positive"),
    ("axis", {"h": "fine"}, "h must be a number"),
    ("axis", {"ppc": 0}, "particles per cell per axis must be an integer >= 1"),
    ("axis", {"ppc": 2.5}, "ppc must be an integer"),
    ("axis", {"amplitude": 0.4}, "A pi < 1"),
    ("axis", {"amplitude": -1e-4}, "A pi < 1"),
    ("axis", {"amplitude_y": 0.4}, "A_y pi < 1"),
    ("axis", {"amplitude": float("nan")}, "amplitude must be a finite number"),
    ("vortex", {"amplitude_y": 0.1}, "vortex has none"),
    ("axis", {"cfl": 0.9}, r"must lie in \(0, 0.862\] with the lumped mass and the mpm basis"),
    ("axis", {"cfl": 0.9, "basis": "gimp"}, r"\(0, 0.862\] with the lumped mass and the gimp basis"),
    ("axis", {"cfl": 1.5}, r"the CFL number must lie in \(0, 1\]"),
    ("axis", {"basis": "nope"}, "unknown basis 'nope'"),
    ("axis", {"basis": "plugin_plane_bases:Flat"}, "has no 2D"),
    ("axis", {"mass": "diagonal"}, "unknown mass 'diagonal'"),
    ("axis", {"layout": "random"}, "unknown particle layout 'random'"),
    ("axis", {"seed": -1, "layout": "jittered"}, "seed must be an integer >= 0"),
    ("axis", {"scheme": "usf"}, "the 2D step runs the schemes usl, musl"),
    ("axis", {"flip": 2.0}, r"blend must lie in \[0, 1\]"),
    ("axis", {"T": 0.0}, "final time T must be positive"),
    ("axis", {"h": 1e-5}, r"the run needs about .* over the limit .*\(h=1e-05, ppc=2"),
    ("axis", {"h": 2e-3}, r"over 1 h; pass yes_long=True to run it \(h=0.002"),
])
def test_bad_input_is_refused_in_one_line_before_any_work(monkeypatch, entry, settings, words):
    monkeypatch.setattr(plane_api, "run", lambda s: pytest.fail("the run started"))
    t0 = time.perf_counter()
    with pytest.raises(UsageError, match=words) as refused:
        getattr(mpm_fem.plane, entry)(**{"h": 1 / 4, **settings})
    message = str(refused.value)
    assert "\n" not in message and message.startswith(f"{entry}()"), message
    assert time.perf_counter() - t0 < 5.0, "refused after work"


def test_an_unknown_keyword_is_an_unknown_setting_with_the_closest_name():
    with pytest.raises(UnknownSetting, match="'amplitud'; did you mean amplitude") as refused:
        mpm_fem.plane.axis(h=1 / 4, amplitud=1e-4)
    assert isinstance(refused.value, TypeError) and isinstance(refused.value, ValueError)
    with pytest.raises(UnknownSetting, match="'problem'"):
        mpm_fem.plane.vortex(problem="axis")


def test_a_particle_that_inverts_stops_the_run_naming_the_step_and_the_particle():
    # the vortex's own amplitude 1 at 2 x 2 particles per cell: every basis loses a particle before t = 1/2
    with pytest.raises(InversionError, match=r"<= 0 at step \d+ \(t=0\.\d+\) in particle \d+") as stopped:
        mpm_fem.plane.vortex(h=1 / 8)
    assert not isinstance(stopped.value, UsageError) and stopped.value.t < 0.5, stopped.value


def test_the_lumped_cfl_limit_is_the_linearised_steps_and_a_run_above_it_inverts():
    # the linearised step's limit 2 c / (h omega_max) with the lumped mass and P1 is h / c_p (the
    # textbook explicit limit with the P-wave speed) at every regular layout; the table holds it
    s = PlaneSettings(h=1 / 4)
    solution, grid, (X, V0, lengths), _ = setup(s)
    m = solution.material
    measured = linearised_cfl(grid, "mpm", "lumped", m, X, V0, lengths) / p_wave_ratio(m)
    assert measured == pytest.approx(LUMPED["mpm"], abs=1e-3), f"P1: {measured:.5f} h / c_p"
    # the quadratic B-spline's limit is above every CFL number a run takes (1): not a refusal
    bspline = linearised_cfl(grid, "bspline", "lumped", m, X, V0, lengths)
    assert 1.0 < bspline and abs(bspline / p_wave_ratio(m) / LUMPED["bspline"] - 1) < 0.05, bspline
    limit = cfl_limit("mpm", "lumped", m)
    assert limit == pytest.approx(np.sqrt(m.E / (m.lam + 2 * m.mu)), rel=1e-12) and 0.86 < limit < 0.87
    assert cfl_limit("mpm", "consistent", m) is None and cfl_limit("cubic", "lumped", m) > 1.0
    with pytest.raises(InversionError):  # the unchecked run above the limit: the instability is real
        run(PlaneSettings(h=1 / 4, cfl=0.9, T=0.1))


def test_the_estimate_counts_the_particles_nodes_and_steps_of_the_run():
    for entry, settings in (("axis", {"h": 1 / 4}), ("vortex", {"h": 1 / 8, "amplitude": 0.01})):
        s, cost = plane_api.checked(entry, settings)
        r = run(s)
        assert cost.steps == r.steps and cost.nodes == r.grid.n_nodes, (cost, r)
        assert abs(cost.particles / r.particles.n - 1) < 0.03, (cost.particles, r.particles.n)
        assert cost.kernel == "numpy" and 0 < cost.seconds < 1 and cost.bytes > 0


def test_mpm_fem_plane_is_the_checked_entry_points_even_after_the_package_is_imported():
    import mpm_fem.plane.grid as grid_module  # binds the package under mpm_fem.plane: ignored
    from mpm_fem.plane import PlaneSettings as from_package

    assert mpm_fem.plane is plane_api and mpm_fem.plane.axis is plane_api.axis
    assert mpm_fem.plane.vortex is plane_api.vortex
    assert mpm_fem.plane.PlaneSettings is from_package and grid_module is sys.modules["mpm_fem.plane.grid"]
    assert mpm_fem.plane.step is sys.modules["mpm_fem.plane"].step
    with pytest.raises(AttributeError):
        mpm_fem.plane.no_such_name  # noqa: B018
