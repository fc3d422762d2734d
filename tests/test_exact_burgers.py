"""The exact viscous Burgers solutions: the PDE, the closed-form derivatives, the data."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import trapezoid
from scipy.special import erfc

from baselines.exact.burgers import SOLUTIONS, ColeHopfWave, Rarefaction, make_solution

NAMES = sorted(SOLUTIONS)
EPS = [0.045, 0.01]
X = np.linspace(0.0, 2.0, 1001)[:, None]
T = np.linspace(0.0, 0.5, 26)[None, :]


def _residual_and_scale(solution, x, t):
    v, v_x, v_xx, v_t = solution.fields(x, t)
    residual = v_t + v * v_x - solution.eps * v_xx
    scale = np.abs(v_t) + np.abs(v * v_x) + np.abs(solution.eps * v_xx)
    return residual, scale


@pytest.mark.parametrize("eps", EPS)
@pytest.mark.parametrize("name", NAMES)
def test_closed_form_derivatives_satisfy_burgers_to_round_off(name, eps):
    residual, scale = _residual_and_scale(make_solution(name, eps), X, T)
    worst = np.max(np.abs(residual) / (scale + 1e-300))
    assert np.all(np.abs(residual) <= 1e-13 * scale + 1e-15 * scale.max()), f"{name} eps={eps}: {worst:.2e}"


@pytest.mark.parametrize("eps", EPS)
@pytest.mark.parametrize("name", NAMES)
def test_closed_form_derivatives_match_centred_differences(name, eps):
    # Step 1e-5: truncation (h/width)^2 <= 1e-6 for fronts of width >= 4 eps = 0.04; round-off
    # of the second difference ~ 1e-16 |v| / h^2 = 1e-6 |v|.
    h = 1e-5
    solution = make_solution(name, eps)
    v, v_x, v_xx, v_t = solution.fields(X, T)
    v_plus, v_minus = solution.v(X + h, T), solution.v(X - h, T)
    checks = [
        ("v_x", (v_plus - v_minus) / (2 * h), v_x, 1e-6),
        ("v_xx", (v_plus - 2 * v + v_minus) / h**2, v_xx, 2e-5),
        ("v_t", (solution.v(X, T + h) - solution.v(X, T - h)) / (2 * h), v_t, 1e-6),
    ]
    for label, difference, closed_form, tolerance in checks:
        error = np.max(np.abs(difference - closed_form)) / np.max(np.abs(closed_form))
        assert error < tolerance, f"{name} eps={eps} {label}: relative max error {error:.2e}"


@pytest.mark.parametrize("eps", EPS + [1e-3])
@pytest.mark.parametrize("name", NAMES)
def test_no_overflow_nan_or_inf_on_the_domain_for_t_in_0_to_half(name, eps):
    solution = make_solution(name, eps)
    x = np.linspace(*solution.domain, 2001)[:, None]
    with np.errstate(over="raise", invalid="raise", divide="raise"):
        for field in solution.fields(x, T):
            assert field.shape == (2001, T.size)
            assert np.all(np.isfinite(field)), f"{name} eps={eps}"


@settings(max_examples=100, derandomize=True, deadline=None)
@given(
    name=st.sampled_from(NAMES),
    eps=st.floats(0.005, 0.05),
    x=st.floats(0.0, 2.0),
    t=st.floats(0.0, 0.5),
)
def test_burgers_residual_vanishes_at_random_points(name, eps, x, t):
    residual, scale = _residual_and_scale(make_solution(name, eps), x, t)
    assert abs(residual) <= 1e-13 * scale + 1e-300, f"{name} eps={eps} x={x} t={t}: {residual} vs {scale}"


@pytest.mark.parametrize("eps", EPS)
def test_front_is_the_tanh_profile(eps):
    expected = 0.5 - 0.5 * np.tanh((X - 0.75 - T / 2) / (4 * eps))
    np.testing.assert_allclose(make_solution("front", eps).v(X, T), expected, rtol=1e-13, atol=1e-15)


def test_three_exp_is_berzins_formula_where_it_can_be_evaluated_directly():
    eps = 0.045  # exponents <= 0.5/eps * 2 ~ 22: the unshifted formula does not overflow
    a = 0.05 / eps * (X - 0.5 + 4.95 * T)
    b = 0.25 / eps * (X - 0.5 + 0.75 * T)
    c = 0.5 / eps * (X - 0.375)
    expected = (0.1 * np.exp(-a) + 0.5 * np.exp(-b) + np.exp(-c)) / (np.exp(-a) + np.exp(-b) + np.exp(-c))
    np.testing.assert_allclose(make_solution("three_exp", eps).v(X, T), expected, rtol=1e-13)


@pytest.mark.parametrize("eps", EPS)
def test_cole_hopf_wave_vanishes_at_both_ends_and_is_odd_about_x_1(eps):
    solution = make_solution("cole_hopf", eps)
    t = T.ravel()
    np.testing.assert_allclose(solution.v(0.0, t), 0.0, atol=1e-15)
    np.testing.assert_allclose(solution.v(2.0, t), 0.0, atol=1e-15)
    x = np.linspace(0.0, 1.0, 11)
    np.testing.assert_allclose(solution.v(1.0 + x, 0.3), -solution.v(1.0 - x, 0.3), atol=1e-15)
    bound = 2 * eps * np.pi / np.sqrt(solution.A**2 - 1)
    assert np.max(np.abs(solution.v(X, T))) <= bound * (1 + 1e-12)


@pytest.mark.parametrize("eps", EPS)
def test_rarefaction_tends_to_the_step_states_at_the_ends(eps):
    solution = make_solution("rarefaction", eps)
    assert solution.v(0.0, 0.0) == pytest.approx(0.5, abs=1e-12)
    assert solution.v(2.0, 0.0) == pytest.approx(1.0, abs=1e-12)
    v = solution.v(X, T)
    assert v.min() >= 0.5 and v.max() <= 1.0
    assert np.all(np.diff(v, axis=0) >= 0.0), "the rarefaction is monotone in x"


def test_rarefaction_is_the_cole_hopf_integral_of_the_step():
    # phi(x, s) = int G(x - y, s) phi0(y) dy by the trapezoid rule, phi0 = exp(-int_0.5^y v0 / 2eps),
    # and v = -2 eps phi_x / phi with phi_x = int G_x phi0: independent of the closed form.
    eps, t = 0.045, 0.2
    solution = Rarefaction(eps)
    s = solution.t0 + t
    x = np.linspace(0.0, 2.0, 9)[:, None]
    y = x + np.linspace(-1.5, 1.5, 30001)[None, :]
    phi0 = np.exp(-np.where(y < 0.5, 0.5, 1.0) * (y - 0.5) / (2 * eps))
    kernel = np.exp(-((x - y) ** 2) / (4 * eps * s))
    phi = trapezoid(kernel * phi0, y, axis=1)
    phi_x = trapezoid(-(x - y) / (2 * eps * s) * kernel * phi0, y, axis=1)
    np.testing.assert_allclose(solution.v(x.ravel(), t), -2 * eps * phi_x / phi, rtol=1e-8)


def test_rarefaction_tends_to_the_inviscid_fan_as_eps_vanishes():
    solution = Rarefaction(1e-5)
    s = solution.t0 + 0.45
    xi = np.linspace(0.55 * s, 0.95 * s, 9)
    np.testing.assert_allclose(solution.v(0.5 + xi, 0.45), xi / s, atol=1e-3)


def test_rarefaction_closed_form_matches_naive_erfc_form_at_moderate_eps():
    eps = 0.045
    solution = Rarefaction(eps)
    s, xi = solution.t0 + T, X - 0.5
    root = np.sqrt(4 * eps * s)
    phi_l = np.exp(-0.5 * xi / (2 * eps) + 0.25 * s / (4 * eps)) * erfc((xi - 0.5 * s) / root)
    phi_r = np.exp(-1.0 * xi / (2 * eps) + 1.0 * s / (4 * eps)) * erfc(-(xi - 1.0 * s) / root)
    np.testing.assert_allclose(solution.v(X, T), (0.5 * phi_l + 1.0 * phi_r) / (phi_l + phi_r), rtol=1e-12)


def test_fields_returns_the_four_methods_values():
    solution = make_solution("rarefaction", 0.02)
    x, t = np.linspace(0.0, 2.0, 7), 0.3
    methods = (solution.v, solution.v_x, solution.v_xx, solution.v_t)
    for together, method in zip(solution.fields(x, t), methods, strict=False):
        np.testing.assert_array_equal(together, method(x, t))


def test_registry_and_attributes():
    assert set(SOLUTIONS) == {"front", "three_exp", "cole_hopf", "rarefaction"}
    for name, cls in SOLUTIONS.items():
        solution = make_solution(name, 0.02)
        assert isinstance(solution, cls) and solution.name == name and solution.domain == (0.0, 2.0)
        with pytest.raises(AttributeError):
            solution.eps = 0.03  # frozen
    assert make_solution("front", 0.02, x0=0.5).x0 == 0.5
    assert make_solution("cole_hopf", 0.02, A=3.0).A == 3.0


def test_unknown_name_raises_and_lists_the_valid_names():
    with pytest.raises(ValueError, match="cole_hopf.*front.*rarefaction.*three_exp"):
        make_solution("sine", 0.01)


def test_unknown_parameter_raises():
    with pytest.raises(ValueError, match="unknown parameter.*valid: x0"):
        make_solution("front", 0.01, A=2.0)


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("eps", [0.0, -0.01, np.nan])
def test_non_positive_eps_raises(name, eps):
    with pytest.raises(ValueError, match="eps > 0"):
        make_solution(name, eps)


def test_parameters_outside_their_range_raise():
    with pytest.raises(ValueError, match="A must be > 1"):
        ColeHopfWave(0.01, A=1.0)
    with pytest.raises(ValueError, match="t0 must be > 0"):
        Rarefaction(0.01, t0=0.0)


@pytest.mark.parametrize("name", sorted(SOLUTIONS))
def test_the_velocity_alone_is_the_first_field_bit_for_bit(name):
    """``v`` skips the derivatives (the runs call it for the Dirichlet data every step) and gives
    the same floats as ``fields(x, t)[0]``: at the ends, inside, outside the domain, scalars, t = 0."""
    rng = np.random.default_rng(3)
    for eps in (0.045, 0.01):
        solution = make_solution(name, eps)
        for t in (0.0, *rng.uniform(0.0, 0.5, 20)):
            for x in (np.array([0.0, 2.0]), rng.uniform(-0.5, 2.5, 33), 1.0):
                v, first = solution.v(x, t), solution.fields(x, t)[0]
                assert np.shape(v) == np.shape(first) and np.array_equal(v, first)
