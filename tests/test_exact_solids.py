"""The neo-Hookean manufactured solutions (baselines/exact/solids.py): the closed-form body force
against ``a - Div P / rho0`` by finite differences of the exact displacement, ``F`` and the
velocity against differences, the period, the vortex's free and resting boundary, bad input."""

import numpy as np
import pytest

from baselines.exact.solids import (
    AxisAligned,
    AxisAligned1D,
    GeneralizedVortex,
    Material,
    cauchy_stress,
    first_piola,
)

N = 200


def _points(solution, seed, margin=0.0):
    """``N`` random reference points (seeded) in the solution's body, ``margin`` inside its boundary."""
    rng = np.random.default_rng(seed)
    if isinstance(solution, AxisAligned):
        return rng.uniform(0.0, 2.0, (2, N))
    R = rng.uniform(solution.inner + margin, solution.outer - margin, N)
    theta = rng.uniform(0.0, 2.0 * np.pi, N)
    return solution.centre[0] + R * np.cos(theta), solution.centre[1] + R * np.sin(theta)


def _gradient_fd(solution, X, Y, t, h):
    """``I + Grad u`` by central differences of step ``h``, (n, 2, 2)."""
    u_X = (solution.displacement(X + h, Y, t) - solution.displacement(X - h, Y, t)) / (2 * h)
    u_Y = (solution.displacement(X, Y + h, t) - solution.displacement(X, Y - h, t)) / (2 * h)
    return np.stack([u_X, u_Y], -1).transpose(1, 0, 2) + np.eye(2)


def _body_force_fd(solution, X, Y, t, h):
    """``a - Div P / rho0``: ``a`` by the second difference in time (step ``h / c``), ``Div P`` by central
    differences of ``P(F_fd)`` in X and Y (step ``h``), ``F_fd`` from :func:`_gradient_fd`. (2, n)."""
    m = solution.material
    dt = h / m.c

    def P(X, Y):
        return first_piola(_gradient_fd(solution, X, Y, t, h), m)

    div = ((P(X + h, Y) - P(X - h, Y))[:, :, 0] + (P(X, Y + h) - P(X, Y - h))[:, :, 1]).T / (2 * h)
    u = solution.displacement
    a = (u(X, Y, t + dt) - 2 * u(X, Y, t) + u(X, Y, t - dt)) / dt**2
    return a - div / m.rho0


def _relative_error(solution, X, Y, t, h):
    b = solution.body_force(X, Y, t)
    return np.max(np.abs(_body_force_fd(solution, X, Y, t, h) - b)) / np.max(np.abs(b))


@pytest.mark.parametrize("h", [1e-2, 2.5e-3])
def test_axis_aligned_body_force_equals_differenced_momentum_balance_to_the_predicted_truncation(h):
    # For A -> 0 the solution is a linear wave of wavenumber pi: the nested central differences of
    # Div P carry the factor (sin(pi h)/(pi h))^2 = 1 - (pi h)^2/3, the second difference of u in
    # time (step h/c, wavenumber c pi) 1 - (pi h)^2/12. With D = Div P / rho0 = k a, k = (lam + 2 mu)/E,
    # and b = (1 - k) a, the relative error of b is kappa (pi h)^2, kappa = (k/3 - 1/12) / |1 - k|
    # (1.055 for nu = 0.3); A = 1e-4 adds O(A) relative to that.
    solution = AxisAligned()
    m = solution.material
    k = (m.lam + 2 * m.mu) / m.E
    predicted = (k / 3 - 1 / 12) / abs(1 - k) * (np.pi * h) ** 2
    X, Y = _points(solution, seed=1)
    measured = _relative_error(solution, X, Y, 0.3 * solution.period, h)
    assert 0.97 <= measured / predicted <= 1.03, f"relative error {measured:.4e}, predicted {predicted:.4e}"


def test_vortex_body_force_equals_differenced_momentum_balance_at_second_then_fourth_order():
    # The vortex is no linear wave (rotations of order 1 rad), so no constant is predicted; the
    # differenced balance must converge to the closed form at second order, and its Richardson
    # extrapolation (4 b(h/2) - b(h))/3 at fourth order: a wrong term would leave a plateau instead.
    solution = GeneralizedVortex()
    X, Y = _points(solution, seed=2, margin=0.05)
    t = 0.3
    b = solution.body_force(X, Y, t)
    hs = (1e-2, 5e-3, 2.5e-3)
    fd = [_body_force_fd(solution, X, Y, t, h) for h in hs]
    e = [np.max(np.abs(f - b)) / np.max(np.abs(b)) for f in fd]
    order = np.log2(e[1] / e[2])
    assert 1.9 <= order <= 2.1, f"relative errors {e}, order {order:.3f}"
    richardson = [np.max(np.abs((4 * fd[k + 1] - fd[k]) / 3 - b)) / np.max(np.abs(b)) for k in range(2)]
    order4 = np.log2(richardson[0] / richardson[1])
    assert 3.5 <= order4 <= 4.5 and richardson[1] < 1e-4, f"extrapolated errors {richardson}, order {order4:.3f}"


@pytest.mark.parametrize("solution", [AxisAligned(), GeneralizedVortex()], ids=["axis_aligned", "vortex"])
def test_deformation_gradient_and_time_derivatives_match_differences_of_the_displacement(solution):
    # Central differences of step h: relative truncation (k h)^2 / 6 with k <= 2 pi / w ~ 25 (vortex).
    X, Y = _points(solution, seed=3, margin=0.01)
    t = 0.3 * solution.period
    h = 1e-5
    F = solution.deformation_gradient(X, Y, t)
    assert np.max(np.abs(_gradient_fd(solution, X, Y, t, h) - F)) < 1e-7, "F against Grad u"
    dt = h / solution.material.c
    u = solution.displacement
    v = solution.velocity(X, Y, t)
    v_fd = (u(X, Y, t + dt) - u(X, Y, t - dt)) / (2 * dt)
    assert np.max(np.abs(v_fd - v)) < 1e-7 * np.max(np.abs(v)), "velocity against du/dt"
    a = solution.acceleration(X, Y, t)
    a_fd = (solution.velocity(X, Y, t + dt) - solution.velocity(X, Y, t - dt)) / (2 * dt)
    assert np.max(np.abs(a_fd - a)) < 1e-7 * np.max(np.abs(a)), "acceleration against dv/dt"


@pytest.mark.parametrize("solution", [AxisAligned(), GeneralizedVortex()], ids=["axis_aligned", "vortex"])
def test_fields_repeat_after_one_period_from_their_initial_state(solution):
    X, Y = _points(solution, seed=4)
    T = solution.period
    assert T == pytest.approx(2 / solution.material.c, rel=1e-15)
    t = 0.17 * T
    for field in (solution.displacement, solution.velocity, solution.body_force):
        assert np.allclose(field(X, Y, t + T), field(X, Y, t), rtol=0, atol=1e-12 * np.abs(field(X, Y, t)).max())
    u0 = solution.displacement(X, Y, 0.0)
    if isinstance(solution, GeneralizedVortex):
        assert np.max(np.abs(u0)) == 0.0 and np.max(np.abs(solution.displacement(X, Y, T))) < 1e-14
    else:  # the y wave starts a third of a period ahead
        assert np.max(np.abs(u0[0])) == 0.0
        assert np.allclose(u0[1], solution.amplitude * np.sin(np.pi * Y) * np.sin(2 * np.pi / 3), rtol=1e-15, atol=0)


def test_axis_aligned_period_and_wave_speed_follow_the_material():
    solution = AxisAligned()
    assert solution.material.c == pytest.approx(100.0, rel=1e-15) and solution.period == pytest.approx(0.02, rel=1e-15)
    assert solution.material.mu == pytest.approx(1e4 / 2.6, rel=1e-15)
    assert solution.material.lam == pytest.approx(1e4 * 0.3 / (1.3 * 0.4), rel=1e-15)
    assert GeneralizedVortex().material.c == pytest.approx(1.0, rel=1e-15)


@pytest.mark.parametrize("solution", [AxisAligned(amplitude=0.05), GeneralizedVortex()], ids=["axis_aligned", "vortex"])
def test_cauchy_stress_is_symmetric_and_equals_piola_push_forward(solution):
    X, Y = _points(solution, seed=5)
    t = 0.3 * solution.period
    F = solution.deformation_gradient(X, Y, t)
    J = np.linalg.det(F)
    sigma = solution.stress(X, Y, t)
    P = solution.first_piola(X, Y, t)
    push = np.einsum("nik,njk->nij", P, F) / J[:, None, None]
    assert np.max(np.abs(sigma - push)) < 1e-12 * np.max(np.abs(sigma)), "sigma = P F^T / J"
    assert np.max(np.abs(sigma - sigma.transpose(0, 2, 1))) < 1e-12 * np.max(np.abs(sigma))


def test_vortex_is_isochoric_with_stress_in_closed_form():
    solution = GeneralizedVortex()
    X, Y = _points(solution, seed=6)
    t = 0.4
    F = solution.deformation_gradient(X, Y, t)
    assert np.max(np.abs(np.linalg.det(F) - 1.0)) < 1e-13
    # sigma = mu [[0, g], [g, g^2]] in (e_r, e_theta) at beta: its trace is mu g^2, its determinant -mu^2 g^2.
    sigma = solution.stress(X, Y, t)
    R = np.hypot(X, Y)
    _, h_R, _ = solution._profile(R)
    g = R * solution.amplitude * np.sin(np.pi * t) * h_R
    mu = solution.material.mu
    assert np.allclose(np.trace(sigma, axis1=1, axis2=2), mu * g**2, rtol=1e-12, atol=1e-12 * mu)
    assert np.allclose(np.linalg.det(sigma), -(mu**2) * g**2, rtol=1e-12, atol=1e-12 * mu**2)


@pytest.mark.parametrize("radius", ["inner", "outer"])
def test_vortex_boundary_circles_are_traction_free_and_at_rest(radius):
    solution = GeneralizedVortex()
    R = getattr(solution, radius)
    theta = np.linspace(0.0, 2.0 * np.pi, 37)
    X, Y = R * np.cos(theta), R * np.sin(theta)
    normal = np.stack([np.cos(theta), np.sin(theta)], -1)
    assert np.all(solution.contains(X, Y))
    for t in (0.13, 0.5, 0.71):
        P = solution.first_piola(X, Y, t)
        traction = np.einsum("nij,nj->ni", P, normal)
        assert np.max(np.abs(traction)) < 1e-12 * solution.material.mu, f"P N at R = {R}, t = {t}"
        assert np.max(np.abs(solution.velocity(X, Y, t))) < 1e-14
        assert np.max(np.abs(solution.displacement(X, Y, t))) < 1e-14


def test_vortex_fields_vanish_outside_the_annulus():
    solution = GeneralizedVortex()
    X = np.array([0.0, 0.5, 1.3, 2.0])
    Y = np.zeros(4)
    assert not np.any(solution.contains(X, Y))
    for field in (solution.displacement, solution.velocity, solution.acceleration, solution.body_force):
        assert np.all(field(X, Y, 0.3) == 0.0)
    assert np.all(solution.deformation_gradient(X, Y, 0.3) == np.eye(2))


@pytest.mark.parametrize("h", [1e-2, 2.5e-3])
def test_one_dimensional_body_force_equals_differenced_momentum_balance_to_the_predicted_truncation(h):
    # The bar's b is AxisAligned's b_x with F_y = 1: the same linear-wave prediction (module above),
    # with k = (lam + 2 mu)/E the uniaxial-strain modulus over E.
    solution = AxisAligned1D()
    m = solution.material
    k = (m.lam + 2 * m.mu) / m.E
    predicted = (k / 3 - 1 / 12) / abs(1 - k) * (np.pi * h) ** 2
    X = np.random.default_rng(7).uniform(0.0, 2.0, N)
    t = 0.3 * solution.period
    dt = h / m.c
    u = solution.displacement

    def P(X):
        F = 1.0 + (u(X + h, t) - u(X - h, t)) / (2 * h)
        return m.mu * (F - 1 / F) + m.lam * np.log(F) / F

    b_fd = (u(X, t + dt) - 2 * u(X, t) + u(X, t - dt)) / dt**2 - (P(X + h) - P(X - h)) / (2 * h) / m.rho0
    b = solution.body_force(X, t)
    measured = np.max(np.abs(b_fd - b)) / np.max(np.abs(b))
    assert 0.97 <= measured / predicted <= 1.03, f"relative error {measured:.4e}, predicted {predicted:.4e}"
    # P is linear in F - 1 to O(A): the central difference of F carries (pi h)^2 / 6.
    assert np.allclose(solution.first_piola(X, t), P(X), rtol=(np.pi * h) ** 2 / 5), "P(F) against P(F_fd)"


def test_one_dimensional_bar_is_the_x_part_of_the_axis_aligned_solution():
    bar, plane = AxisAligned1D(amplitude=0.05), AxisAligned(amplitude=0.05)
    X = np.linspace(0.0, 2.0, 41)
    t = 0.37 * bar.period
    Y = np.full_like(X, 0.5)  # F_y = 1 at Y = 1/2
    assert np.allclose(bar.displacement(X, t), plane.displacement(X, Y, t)[0], rtol=0, atol=1e-15)
    assert np.allclose(bar.body_force(X, t), plane.body_force(X, Y, t)[0], rtol=1e-12, atol=1e-12)
    assert np.allclose(bar.first_piola(X, t), plane.first_piola(X, Y, t)[:, 0, 0], rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize(
    "make, words",
    [
        (lambda: Material(-1.0, 0.3, 1.0), "E > 0"),
        (lambda: Material(1.0, 0.5, 1.0), "nu < 0.5"),
        (lambda: Material(1.0, 0.3, 0.0), "rho0 > 0"),
        (lambda: AxisAligned(amplitude=0.4), "A pi < 1"),
        (lambda: AxisAligned1D(amplitude=-1.0), "A pi < 1"),
        (lambda: GeneralizedVortex(inner=1.3), "inner < outer"),
    ],
)
def test_bad_input_is_refused_with_a_message(make, words):
    with pytest.raises(ValueError, match=words.replace("(", r"\(")):
        make()


def test_stress_refuses_an_inverted_deformation_gradient():
    F = np.array([[[1.0, 0.0], [0.0, -0.5]]])
    for stress in (first_piola, cauchy_stress):
        with pytest.raises(ValueError, match="det F must be > 0"):
            stress(F, Material(1.0, 0.3, 1.0))


@pytest.mark.parametrize("solution", [AxisAligned(amplitude=0.05), AxisAligned(amplitude=0.05, amplitude_y=0.02),
                                      GeneralizedVortex(), GeneralizedVortex(amplitude=0.3)],
                         ids=["axis_aligned", "axis_aligned_two_amplitudes", "vortex", "vortex_small"])
@pytest.mark.parametrize("phase", [0.0, 0.3, 0.5])
def test_velocity_gradient_is_the_differenced_rate_of_F_times_its_inverse(solution, phase):
    # Central differences of F in time, step dt = 1e-6 / c: relative truncation (c pi dt)^2 / 6 ~ 2e-12,
    # round-off ~ 1e-16 / dt ~ 1e-10 relative; so agreement to 1e-7 of the largest |L| (phase 0.5:
    # alpha_t = 0, L is the shear rate alone).
    X, Y = _points(solution, seed=7, margin=0.01)
    t = phase * solution.period
    dt = 1e-6 / solution.material.c
    F = solution.deformation_gradient
    L_fd = (F(X, Y, t + dt) - F(X, Y, t - dt)) / (2 * dt) @ np.linalg.inv(F(X, Y, t))
    L = solution.velocity_gradient(X, Y, t)
    scale = np.max(np.abs(L_fd))
    assert L.shape == (N, 2, 2) and scale > 0
    worst = np.max(np.abs(L - L_fd)) / scale
    assert worst < 1e-7, f"|L - L_fd| / max|L_fd| = {worst:.3g}"


def test_velocity_gradient_of_the_vortex_has_the_trace_of_an_isochoric_motion_and_vanishes_outside():
    solution = GeneralizedVortex()
    X, Y = _points(solution, seed=8)
    L = solution.velocity_gradient(X, Y, 0.3)
    trace = np.abs(L[:, 0, 0] + L[:, 1, 1]).max()
    assert trace < 1e-12 * np.abs(L).max(), f"tr L = {trace:.3g} (d J / dt = J tr L = 0)"
    outside = solution.velocity_gradient(np.array([0.0, 0.5, 1.4]), np.array([0.0, 0.0, 0.0]), 0.3)
    assert np.all(outside == 0.0), outside


def test_axis_aligned_y_amplitude_sets_the_y_part_alone_and_zero_turns_it_off():
    both, x_only, bar = AxisAligned(amplitude=0.05), AxisAligned(amplitude=0.05, amplitude_y=0.0), AxisAligned1D(0.05)
    other = AxisAligned(amplitude=0.05, amplitude_y=0.01)
    X, Y = _points(both, seed=9)
    t = 0.3 * both.period
    assert np.all(x_only.displacement(X, Y, t)[1] == 0.0) and np.all(x_only.body_force(X, Y, t)[1] == 0.0)
    assert np.allclose(x_only.displacement(X, Y, t)[0], bar.displacement(X, t), rtol=1e-14, atol=0)
    assert np.allclose(x_only.body_force(X, Y, t)[0], bar.body_force(X, t), rtol=1e-12, atol=1e-15)
    assert np.array_equal(other.displacement(X, Y, t)[0], both.displacement(X, Y, t)[0])
    ratio = other.displacement(X, Y, t)[1] / both.displacement(X, Y, t)[1]
    assert np.allclose(ratio, 0.2, rtol=1e-12), ratio[:3]
    assert AxisAligned(amplitude=0.05, amplitude_y=None).amplitudes == (0.05, 0.05)


@pytest.mark.parametrize("h", [1e-2, 2.5e-3])
def test_axis_aligned_body_force_with_two_amplitudes_equals_the_differenced_balance(h):
    # As for one amplitude (the linear-wave truncation kappa (pi h)^2 of each component), O(A) besides.
    solution = AxisAligned(amplitude=1e-4, amplitude_y=3e-5)
    m = solution.material
    k = (m.lam + 2 * m.mu) / m.E
    predicted = (k / 3 - 1 / 12) / abs(1 - k) * (np.pi * h) ** 2
    X, Y = _points(solution, seed=10)
    b = solution.body_force(X, Y, 0.3 * solution.period)
    fd = _body_force_fd(solution, X, Y, 0.3 * solution.period, h)
    for c in range(2):
        measured = np.max(np.abs(fd[c] - b[c])) / np.max(np.abs(b[c]))
        assert 0.97 <= measured / predicted <= 1.03, f"component {c}: {measured:.4e}, predicted {predicted:.4e}"


def test_a_y_amplitude_that_inverts_F_is_refused():
    with pytest.raises(ValueError, match=r"A_y pi < 1"):
        AxisAligned(amplitude_y=0.4)
    with pytest.raises(ValueError, match=r"A_y pi < 1"):
        AxisAligned(amplitude_y=-0.01)
