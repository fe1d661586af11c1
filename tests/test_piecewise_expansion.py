"""Unilateral springs a·(u − b)_+ : exactness, agreement with the exact piecewise-linear period, regimes."""

import mpmath
import numpy as np
import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

import lindstedt
from lindstedt.algebra import contact_ramp_coefficient
from lindstedt.references import piecewise_linear_exact_frequency, piecewise_linear_frequency_taylor

omega0 = sympy.Symbol("omega0", positive=True)


def test_u_plus_exact_second_order_with_symbolic_omega0():
    expansion = lindstedt.expand("Max(0, u)", order=2)
    assert expansion.alpha[1] == sympy.Rational(1, 2)
    assert sympy.simplify(expansion.alpha[2] + sympy.Rational(3, 16) / omega0**2) == 0
    assert sympy.simplify(expansion.omega[2] + 1 / (2 * omega0) ** 3) == 0
    numeric = lindstedt.expand("Max(0, u)", order=2, a0=1, omega0=1)
    assert numeric.alpha[2] == sympy.Rational(-3, 16)
    assert numeric.omega[2] == sympy.Rational(-1, 8)


def test_heaviside_spelling_is_the_same_problem():
    with_max = lindstedt.expand("Max(0, u - 1/2)", order=3, a0=1, omega0=1)
    with_heaviside = lindstedt.expand("(u - 1/2)*Heaviside(u - 1/2)", order=3, a0=1, omega0=1)
    for left, right in zip(with_max.omega, with_heaviside.omega):
        assert sympy.simplify(left - right) == 0


KAPPAS = ["-999/1000", "-9/10", "-1/2", "-1/5", "0", "3/10", "7/10", "19/20", "999/1000"]


@pytest.mark.parametrize("kappa", KAPPAS)
@pytest.mark.parametrize("release", ["13/10", "-4/5"])
def test_float_mode_matches_exact_period_taylor_coefficients(kappa, release):
    # The same exact inputs go to both sides (near |κ| = 1 the ω_k are very sensitive to κ).
    stiffness, linear_frequency = sympy.Rational(17, 10), sympy.Rational(11, 10)
    gap = sympy.Rational(kappa) * abs(sympy.Rational(release))
    expansion = lindstedt.expand(
        f"{stiffness}*Max(0, u - ({gap}))", order=4, a0=release, omega0=linear_frequency, numeric=True, precision=30
    )
    with mpmath.workdps(40):
        def exact(value):
            return mpmath.mpf(value.p) / value.q

        reference = piecewise_linear_frequency_taylor(
            4, a=exact(stiffness), b=exact(gap), a0=exact(sympy.Rational(release)), omega0=exact(linear_frequency), precision=40
        )
        for k in range(1, 5):
            value, error = reference[k]
            ours = mpmath.mpf(sympy.N(expansion.omega[k], 30))
            assert abs(ours - value) <= max(1e-13 * abs(value), 10 * error, 1e-25), (k, ours, value)


@pytest.mark.parametrize("kappa", ["1/3", "-1/2", "0"])
def test_exact_mode_agrees_to_30_digits(kappa):
    expansion = lindstedt.expand(f"Max(0, u - ({kappa}))", order=3, a0=1, omega0=1)
    with mpmath.workdps(50):
        reference = piecewise_linear_frequency_taylor(3, a=1, b=mpmath.mpf(sympy.Rational(kappa)), a0=1, precision=50)
        for k in range(1, 4):
            value, error = reference[k]
            ours = mpmath.mpf(sympy.N(expansion.omega[k], 45))
            assert abs(ours - value) <= max(mpmath.mpf(10) ** -30 * abs(value), 10 * error)


def test_high_precision_mode_keeps_30_digits_near_grazing():
    kappa = sympy.Rational(999, 1000)
    expansion = lindstedt.expand("Max(0, u - 999/1000)", order=4, a0=1, omega0=1, numeric=True, precision=50)
    with mpmath.workdps(60):
        reference = piecewise_linear_frequency_taylor(4, a=1, b=mpmath.mpf(kappa), a0=1, precision=60)
        for k in range(1, 5):
            value, error = reference[k]
            assert abs(mpmath.mpf(sympy.N(expansion.omega[k], 50)) - value) <= max(mpmath.mpf(10) ** -30 * abs(value), 10 * error)


def test_symbolic_kappa_first_order_closed_form():
    b = sympy.Symbol("b", real=True)
    a = sympy.Symbol("a", positive=True)
    a0 = sympy.Symbol("a0", positive=True)
    expansion = lindstedt.expand("a*Max(0, u - b)", order=2, params={"a": a, "b": None})
    omega1 = expansion.omega[1]
    for kappa in (sympy.Rational(1, 3), sympy.Rational(-3, 5)):
        numeric = lindstedt.expand(f"Max(0, u - ({kappa}))", order=1, a0=1, omega0=1).omega[1]
        value = omega1.subs({b: kappa, a0: 1, omega0: 1, a: 1})
        assert abs(sympy.N(value - numeric, 30)) < 1e-28
    # first order in closed form: a (β − κ sin β) / (2π ω0), κ = b/a0, checked against c_1[κ] of the Fourier kernel
    kappa = b / a0
    expected = a * a0 * contact_ramp_coefficient(1, kappa, assume_interior=True) / (2 * omega0 * a0)
    assert sympy.simplify((omega1 - expected).subs({b: sympy.Rational(1, 4) * a0})) == 0


def test_cosine_coefficients_of_v1_match_the_fourier_kernel():
    # v1'' + v1 = -(a a0/ω0²)[(cos s − κ)_+ − c_1 cos s]: d_k = −a a0 c_k / (ω0² (1 − k²)), k ≠ 1
    kappa = sympy.Rational(1, 3)
    v1 = lindstedt.expand("2*Max(0, u - 1/3)", order=1, a0=1, omega0=1).waveforms[1]
    for k in (0, 2, 3, 5):
        expected = -2 * contact_ramp_coefficient(k, kappa) / (1 - k**2)
        assert abs(sympy.N(v1.cosine_coefficient(k) - expected, 30)) < 1e-28


def test_regimes_no_contact_and_grazing():
    free = lindstedt.expand("Max(0, u - 2)", order=3, a0=1, omega0=1)
    assert free.regime == "no contact"
    assert free.omega == (1, 0, 0, 0)
    grazing = lindstedt.expand("Max(0, u - 1)", order=2, a0=1, omega0=1)
    assert grazing.regime == "grazing"
    assert grazing.validity_exponent == sympy.Rational(-1, 2)
    assert grazing.omega == (1, 0, 0)
    contact = lindstedt.expand("Max(0, u - 1/2)", order=1, a0=1, omega0=1)
    assert contact.regime == "contact" and contact.validity_exponent == -1
    always = lindstedt.expand("Max(0, u + 2)", order=3, a0=1, omega0=1)  # permanently compressed: linear
    expected = sympy.series(sympy.sqrt(1 + sympy.Symbol("e")), sympy.Symbol("e"), 0, 4).removeO()
    assert [always.omega[k] for k in range(4)] == [expected.coeff(sympy.Symbol("e"), k) for k in range(4)]


def test_two_springs_and_sign_symmetry():
    # a stop on each side: f = Max(0, u - 1/4) - 2 Max(0, -u - 1/2) (both restoring).  The mirror
    # u -> -u maps f(u) to -f(-u) = 2 Max(0, u - 1/2) - Max(0, -u - 1/4) and a0 to -a0.
    left = lindstedt.expand("Max(0, u - 1/4) - 2*Max(0, -u - 1/2)", order=2, a0=1, omega0=1)
    mirrored = lindstedt.expand("2*Max(0, u - 1/2) - Max(0, -u - 1/4)", order=2, a0=-1, omega0=1)
    for a, b in zip(left.omega, mirrored.omega):
        assert abs(sympy.N(a - b, 30)) < 1e-28


def exact_frequency_by_integration(rhs, release, epsilon):
    def field(_, state):
        return [state[1], -state[0] - epsilon * rhs(state[0])]

    def turning(_, state):
        return state[1]

    turning.direction = 1 if release > 0 else -1  # velocity crosses zero again after half a period
    solution = solve_ivp(field, (0, 20), [release, 0.0], method="DOP853", rtol=1e-12, atol=1e-14, events=turning)
    half_period = solution.t_events[0][0]
    return np.pi / half_period


def test_two_springs_frequency_converges_at_the_right_order():
    text = "Max(0, u - 1/4) - 2*Max(0, -u - 1/2)"
    expansion = lindstedt.expand(text, order=3, a0=1, omega0=1, numeric=True)

    def force(value):
        return max(0.0, value - 0.25) - 2 * max(0.0, -value - 0.5)

    epsilons = np.geomspace(0.02, 0.08, 5)
    errors = [abs(expansion.frequency(e) - exact_frequency_by_integration(force, 1.0, e)) for e in epsilons]
    slope = np.polyfit(np.log(epsilons), np.log(errors), 1)[0]
    assert slope == pytest.approx(4, abs=0.3)


@settings(max_examples=15, deadline=None)
@given(
    kappa=st.floats(-0.95, 0.95),
    scale=st.floats(0.3, 3.0),
    sign=st.sampled_from([1, -1]),
)
def test_frequency_depends_on_b_and_a0_only_through_kappa_and_sign(kappa, scale, sign):
    # (u − b)_+ is homogeneous of degree one: scaling a0 and b together leaves every ω_k unchanged.
    base = lindstedt.expand(f"Max(0, u - ({kappa}))", order=2, a0=sign, omega0=1, numeric=True)
    scaled = lindstedt.expand(f"Max(0, u - ({kappa * scale}))", order=2, a0=sign * scale, omega0=1, numeric=True)
    for a, b in zip(base.omega, scaled.omega):
        assert float(a) == pytest.approx(float(b), rel=1e-12, abs=1e-14)


@settings(max_examples=10, deadline=None)
@given(kappa=st.floats(-0.9, 0.9), frequency=st.floats(0.5, 3.0))
def test_omega0_scaling(kappa, frequency):
    # u'' + ω0² u + ε f(u) = 0 is ω0 × (the ω0 = 1 problem with ε/ω0²): ω_k = ω0^{1-2k} ω_k(ω0 = 1)
    unit = lindstedt.expand(f"Max(0, u - ({kappa}))", order=3, a0=1, omega0=1, numeric=True)
    other = lindstedt.expand(f"Max(0, u - ({kappa}))", order=3, a0=1, omega0=frequency, numeric=True)
    for k in range(4):
        assert float(other.omega[k]) == pytest.approx(frequency ** (1 - 2 * k) * float(unit.omega[k]), rel=1e-12)


def test_frequency_matches_exact_closed_form_with_fitted_order():
    expansion = lindstedt.expand("Max(0, u - 3/10)", order=4, a0=1, omega0=1, numeric=True)
    epsilons = np.geomspace(0.01, 0.05, 5)
    errors = [abs(expansion.frequency(e) - float(piecewise_linear_exact_frequency(e, a=1, b=0.3, a0=1))) for e in epsilons]
    slope = np.polyfit(np.log(epsilons), np.log(errors), 1)[0]
    assert slope == pytest.approx(5, abs=0.3)


@pytest.mark.parametrize("order", [1, 2])
def test_piecewise_waveform_error_scales_like_eps_to_order_plus_one(order):
    expansion = lindstedt.expand("Max(0, u - 1/5)", order=order, a0=1, omega0=1)
    epsilons = np.geomspace(0.01, 0.04, 5)
    errors = []
    for epsilon in epsilons:
        t = np.linspace(0, 1 / epsilon, 3000)

        def field(_, state, epsilon=epsilon):
            return [state[1], -state[0] - epsilon * max(0.0, state[0] - 0.2)]

        exact = solve_ivp(field, (0, t[-1]), [1.0, 0.0], method="DOP853", t_eval=t, rtol=1e-12, atol=1e-14).y[0]
        errors.append(np.max(np.abs(expansion.displacement(t, epsilon) - exact)))
    slope = np.polyfit(np.log(epsilons), np.log(errors), 1)[0]
    assert slope == pytest.approx(order + 1, abs=0.3)


def test_bad_piecewise_inputs():
    # a force that jumps (Heaviside(u - 1/2)) is supported since issue 12 (tests/test_jumps.py); nesting is not
    with pytest.raises(lindstedt.UnsupportedNonlinearityError, match="nested"):
        lindstedt.expand("Max(0, Max(0, u) - 1/2)", order=1, a0=1, omega0=1)
    # polynomial pieces (Max(0, u)**2) are supported since issue 12 (tests/test_piecewise_polynomial.py), and
    # non-polynomial ones on an arc that holds a turning point (tests/test_hertz.py); not in the middle of the orbit
    with pytest.raises(lindstedt.UnsupportedNonlinearityError, match="holds a turning point"):
        lindstedt.expand("Max(0, u)*exp(u)*Heaviside(1/2 - u)", order=1, a0=1, omega0=1)
    with pytest.raises(lindstedt.ProblemError, match="sign of a0"):
        lindstedt.expand("Max(0, u)", order=1, a0=sympy.Symbol("A", real=True))
    # the float field holds numbers: a symbolic a0 or gap with numeric=True is refused by name (it raised sympy's
    # CoercionFailed before); a symbolic omega0 is fine, it scales out
    with pytest.raises(lindstedt.ProblemError, match="numeric values for a0"):
        lindstedt.expand("Max(0, u - 1/3)", order=2, numeric=True)
    with pytest.raises(lindstedt.ProblemError, match="numeric values for a0, kappa"):
        lindstedt.expand("Max(0, u - kappa)", order=2, params={"kappa": None}, numeric=True)
    omega0 = sympy.Symbol("omega0", positive=True)
    scaled = lindstedt.expand("Max(0, u - 1/3)", order=2, a0=1, numeric=True).omega
    unit = lindstedt.expand("Max(0, u - 1/3)", order=2, a0=1, omega0=1, numeric=True).omega
    assert [sympy.expand(value * omega0 ** (2 * k - 1)) for k, value in enumerate(scaled)] == list(unit)


@pytest.mark.parametrize("kappa", ["1 - 1/10**12", "-1 + 1/10**12", "1 - 1/10**6"])
def test_float_path_keeps_12_digits_next_to_grazing(kappa):
    # ω2 is ~1e-31 at κ = 1 − 1e-12: a difference of O(1) terms; guard digits must absorb the cancellation.
    exact_kappa = sympy.sympify(kappa)
    expansion = lindstedt.expand(f"Max(0, u - ({exact_kappa}))", order=2, a0=1, omega0=1, numeric=True, precision=16)
    with mpmath.workdps(80):
        reference = piecewise_linear_frequency_taylor(2, a=1, b=mpmath.mpf(exact_kappa.p) / exact_kappa.q, a0=1, precision=80)
        for k in (1, 2):
            value, error = reference[k]
            assert error < 1e-40 * abs(value)
            assert abs(mpmath.mpf(sympy.N(expansion.omega[k], 40)) - value) <= 1e-12 * abs(value)
