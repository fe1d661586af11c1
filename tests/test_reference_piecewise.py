"""Tests of the piecewise-linear reference (lindstedt.references.piecewise_linear_*).

Equation: u'' + omega0**2 u + epsilon a (u - b)_+ = 0, u(0) = a0, u'(0) = 0.
Expectations come from the textbook bilinear-oscillator frequency
2 omega0 Omega/(omega0 + Omega) (b = 0), the exact one-region frequencies,
its hand-derived Taylor coefficients a/(4 omega0) and -a**2/(8 omega0**3),
direct segment-by-segment DOP853 integration of the ODE, and the exact scaling
symmetry of the equation.
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from lindstedt import OrderError, ProblemError
from lindstedt.references import (
    piecewise_linear_exact_frequency,
    piecewise_linear_exact_period,
    piecewise_linear_frequency_taylor,
    piecewise_linear_frequency_taylor_symbolic,
)


def integrated_period(epsilon: float, a: float, b: float, a0: float, omega0: float) -> float:
    """Period by DOP853 (rtol 1e-12), restarting at every crossing of u = b.

    The integrator never steps across the kink; the half period is the time to
    the other turning point (time reversibility of the conservative motion).
    """
    stiffness = epsilon * a

    def free(_time, state):
        return [state[1], -(omega0**2) * state[0]]

    def contact(_time, state):
        return [state[1], -(omega0**2) * state[0] - stiffness * (state[0] - b)]

    def crossing(_time, state):
        return state[0] - b

    def turning(_time, state):
        return state[1]

    initial_acceleration = -(omega0**2) * a0 - stiffness * max(a0 - b, 0.0)
    turning.terminal = True
    turning.direction = 1 if initial_acceleration < 0 else -1
    crossing.terminal = True
    in_contact = a0 > b or (a0 == b and initial_acceleration > 0)
    time, state = 0.0, [a0, 0.0]
    for _segment in range(10):
        crossing.direction = -1 if in_contact else 1  # leaving the current region
        solution = solve_ivp(
            contact if in_contact else free,
            (time, time + 1000.0),
            state,
            method="DOP853",
            rtol=1e-12,
            atol=1e-14,
            max_step=0.01,  # short enough that brief near-grazing contact arcs are not stepped over
            events=[crossing, turning],
        )
        if solution.t_events[1].size:
            return 2 * float(solution.t_events[1][0])
        time = float(solution.t_events[0][0])
        state = [b, float(solution.y_events[0][0][1])]
        in_contact = not in_contact
    raise AssertionError("no turning point found")


def bilinear_frequency(epsilon, a, omega0):
    """b = 0: half the period at omega0, half at Omega, so omega = 2 omega0 Omega/(omega0 + Omega)."""
    contact_frequency = mpmath.sqrt(omega0**2 + epsilon * a)
    return 2 * omega0 * contact_frequency / (omega0 + contact_frequency)


def fitted_slope(abscissae, ordinates) -> float:
    logs_x = np.array([float(mpmath.log(abs(value))) for value in abscissae])
    logs_y = np.array([float(mpmath.log(abs(value))) for value in ordinates])
    return float(np.polyfit(logs_x, logs_y, 1)[0])


# ------------------------------------------------------------ b = 0, exact
def test_symbolic_b_zero_first_and_second_coefficients():
    epsilon, a = sympy.Symbol("epsilon"), sympy.Symbol("a")
    omega0 = sympy.Symbol("omega0", positive=True)
    series = piecewise_linear_frequency_taylor_symbolic(4, epsilon=epsilon, a=a, omega0=omega0)
    polynomial = sympy.Poly(series, epsilon)
    assert polynomial.coeff_monomial(1) == omega0
    assert sympy.simplify(polynomial.coeff_monomial(epsilon) - a / (4 * omega0)) == 0
    assert sympy.simplify(polynomial.coeff_monomial(epsilon**2) + a**2 / (8 * omega0**3)) == 0
    # a = 1: -1/(2 omega0)**3
    assert sympy.simplify(polynomial.coeff_monomial(epsilon**2).subs(a, 1) + 1 / (2 * omega0) ** 3) == 0
    assert polynomial.degree() == 4


def test_symbolic_series_matches_numerical_cauchy_coefficients():
    order = 10
    epsilon, a = sympy.Symbol("epsilon"), sympy.Symbol("a")
    omega0 = sympy.Symbol("omega0", positive=True)
    series = piecewise_linear_frequency_taylor_symbolic(order, epsilon=epsilon, a=a, omega0=omega0)
    numeric_a, numeric_omega0 = sympy.Rational(17, 10), sympy.Rational(11, 10)
    polynomial = sympy.Poly(series.subs({a: numeric_a, omega0: numeric_omega0}), epsilon)
    coefficients = piecewise_linear_frequency_taylor(order, a=numeric_a, b=0, a0="-0.8", omega0=numeric_omega0, precision=40)
    with mpmath.workdps(50):
        for power, (value, error) in enumerate(coefficients):
            exact = polynomial.coeff_monomial(epsilon**power)
            exact_value = mpmath.mpf(int(exact.p)) / int(exact.q)
            assert abs(value - exact_value) <= error + mpmath.mpf(10) ** -36 * abs(exact_value), power
            assert error <= mpmath.mpf(10) ** -30 * max(abs(exact_value), 1), power


@pytest.mark.parametrize("epsilon", ["0.5", "-0.5", "3"])
@pytest.mark.parametrize("a0", ["1", "-2.5"])
def test_b_zero_is_the_bilinear_frequency(epsilon, a0):
    with mpmath.workdps(40):
        frequency = piecewise_linear_exact_frequency(epsilon, a="1.3", b=0, a0=a0, omega0="0.9")
        exact = bilinear_frequency(mpmath.mpf(epsilon), mpmath.mpf("1.3"), mpmath.mpf("0.9"))
        assert abs(frequency - exact) <= mpmath.mpf(10) ** -29 * exact


def test_complex_epsilon_continues_the_bilinear_frequency():
    with mpmath.workdps(40):
        for point in (mpmath.mpc("0.2", "0.3"), mpmath.mpc("-0.1", "-0.4")):
            frequency = piecewise_linear_exact_frequency(point, a=1, b=0, a0="0.5", omega0=1)
            exact = bilinear_frequency(point, 1, 1)
            assert abs(frequency - exact) <= mpmath.mpf(10) ** -29


# ----------------------------------------------------- periods vs the ODE
@pytest.mark.parametrize("kappa", [-0.9, -0.3, 0.0, 0.5, 0.99])
@pytest.mark.parametrize("a0_sign", [1, -1])
@pytest.mark.parametrize("epsilon", [0.6, -0.35])
def test_period_matches_direct_integration(kappa, a0_sign, epsilon):
    a, omega0, magnitude = 1.7, 1.1, 0.8
    a0, b = a0_sign * magnitude, kappa * magnitude
    period = piecewise_linear_exact_period(epsilon, a=a, b=b, a0=a0, omega0=omega0)
    numerical = integrated_period(epsilon, a, b, a0, omega0)
    assert float(period) == pytest.approx(numerical, rel=1e-9, abs=0)


def test_prestressed_orbit_leaves_contact_when_the_centre_moves():
    # b = -3 < -|a0| but eps a = 1 shifts the contact centre to u_e = -3/1.49: the orbit
    # (symmetric about u_e) reaches 2 u_e - a0 = -5.2 < b and enters the free region.
    period = piecewise_linear_exact_period(0.5, a=2, b=-3, a0=1.2, omega0=0.7)
    numerical = integrated_period(0.5, 2.0, -3.0, 1.2, 0.7)
    assert float(period) == pytest.approx(numerical, rel=1e-9, abs=0)
    assert float(period) > 2 * np.pi / np.sqrt(0.49 + 1.0) * (1 + 1e-3)


@pytest.mark.parametrize("kappa, a0", [(-0.999, 1.0), (0.999, 1.0), (0.999, -1.0), (-0.999, -1.0)])
def test_near_grazing_period_matches_direct_integration(kappa, a0):
    for epsilon in (0.6, 0.05, -0.3):
        period = piecewise_linear_exact_period(epsilon, a=1, b=kappa * abs(a0), a0=a0)
        numerical = integrated_period(epsilon, 1.0, kappa * abs(a0), a0, 1.0)
        assert float(period) == pytest.approx(numerical, rel=1e-9, abs=0)
        # The brief contact really changes the period (it is not the free 2 pi).
        assert abs(numerical / (2 * np.pi) - 1) > 1e-7


def test_single_region_regimes_are_exact():
    with mpmath.workdps(40):
        # b > |a0|, released in the free region: never reaches b, for any epsilon (even omega0^2 + eps a < 0).
        for epsilon in ("0.5", "-3", "-100"):
            frequency = piecewise_linear_exact_frequency(epsilon, a=1, b="1.5", a0="-1.2", omega0="0.7")
            assert abs(frequency - mpmath.mpf("0.7")) <= mpmath.mpf(10) ** -29
        # b < -|a0| and small |eps| (other turning point 2 u_e - a0 stays above b): always in contact,
        # omega = sqrt(omega0^2 + eps a).
        for epsilon in ("0.05", "-0.1"):
            frequency = piecewise_linear_exact_frequency(epsilon, a=2, b=-3, a0="1.2", omega0="0.7")
            exact = mpmath.sqrt(mpmath.mpf("0.49") + 2 * mpmath.mpf(epsilon))
            assert abs(frequency - exact) <= mpmath.mpf(10) ** -29
        # Grazing at b = -a0 with a softening contact spring: the orbit stays in contact.
        frequency = piecewise_linear_exact_frequency("-0.2", a=1, b=-1, a0=1, omega0=1)
        assert abs(frequency - mpmath.sqrt(mpmath.mpf("0.8"))) <= mpmath.mpf(10) ** -29
        # Grazing at b = |a0| released at the top: touches b with zero speed, omega = omega0.
        for a0 in (-1, 1):
            frequency = piecewise_linear_exact_frequency("0.7", a=1, b=1, a0=a0, omega0=1)
            assert abs(frequency - 1) <= mpmath.mpf(10) ** -29


# ------------------------------------------------------ Taylor coefficients
def grazing_scale(kappa: float, a0_sign: int) -> float:
    """Distance (in epsilon a/omega0^2) to grazing: (1 + kappa)/(1 - kappa) when released in contact."""
    if a0_sign > 0 and kappa < 1:
        return min(1.0, (1 + kappa) / (1 - kappa))
    return 1.0


@pytest.mark.parametrize("kappa", [-0.9, -0.3, 0.0, 0.5, 0.99, -0.999, 0.999])
@pytest.mark.parametrize("a0_sign", [1, -1])
def test_taylor_polynomial_error_has_slope_order_plus_one(kappa, a0_sign):
    a, omega0, magnitude = mpmath.mpf("1.3"), mpmath.mpf("0.9"), mpmath.mpf("0.8")
    a0, b = a0_sign * magnitude, kappa * magnitude
    coefficients = piecewise_linear_frequency_taylor(5, a=a, b=b, a0=a0, omega0=omega0, precision=40)
    scale = grazing_scale(kappa, a0_sign) * omega0**2 / a
    with mpmath.workdps(40):
        for order in range(0, 6):
            for sign in (1, -1):
                epsilons, errors = [], []
                for fraction in ("0.005", "0.01", "0.02"):
                    epsilon = sign * scale * mpmath.mpf(fraction)
                    exact = piecewise_linear_exact_frequency(epsilon, a=a, b=b, a0=a0, omega0=omega0, precision=40)
                    polynomial = mpmath.fsum(value * epsilon**power for power, (value, _) in enumerate(coefficients[: order + 1]))
                    epsilons.append(epsilon)
                    errors.append(exact - polynomial)
                slope = fitted_slope(epsilons, errors)
                assert abs(slope - (order + 1)) <= 0.3, (order, sign, slope)


def test_single_region_taylor_coefficients():
    free = piecewise_linear_frequency_taylor(3, a=1, b=2, a0=1, omega0="0.5")
    assert [value for value, _ in free] == [mpmath.mpf("0.5"), 0, 0, 0]
    contact = piecewise_linear_frequency_taylor(3, a=1, b=-2, a0=1, omega0=1)
    expected = [1, mpmath.mpf(1) / 2, -mpmath.mpf(1) / 8, mpmath.mpf(1) / 16]  # sqrt(1 + eps)
    for (value, error), exact in zip(contact, expected):
        assert abs(value - exact) <= error + mpmath.mpf(10) ** -38


def test_grazing_taylor_raises_problem_error():
    with pytest.raises(ProblemError, match="grazing"):
        piecewise_linear_frequency_taylor(3, a=1, b=-1, a0=1)
    with pytest.raises(ProblemError, match="grazing"):
        piecewise_linear_frequency_taylor(3, a=1, b="0.7", a0="-0.7")


# --------------------------------------------------------------- precision
@pytest.mark.parametrize("kappa", [-0.3, 0.5])
def test_higher_precision_agrees_and_does_not_leak(kappa):
    global_dps = mpmath.mp.dps
    low = piecewise_linear_exact_frequency("0.37", a="1.3", b=kappa, a0=1, omega0="0.9", precision=30)
    high = piecewise_linear_exact_frequency("0.37", a="1.3", b=kappa, a0=1, omega0="0.9", precision=50)
    low_taylor = piecewise_linear_frequency_taylor(3, a="1.3", b=kappa, a0=-1, omega0="0.9", precision=30)
    high_taylor = piecewise_linear_frequency_taylor(3, a="1.3", b=kappa, a0=-1, omega0="0.9", precision=50)
    assert mpmath.mp.dps == global_dps
    with mpmath.workdps(60):
        assert abs(high - low) <= mpmath.mpf(10) ** -28 * high
        assert abs(high - low) > 0
        for (low_value, _), (high_value, _) in zip(low_taylor, high_taylor):
            assert abs(high_value - low_value) <= mpmath.mpf(10) ** -28 * max(abs(high_value), 1)


# ---------------------------------------------------------------- symmetry
@settings(max_examples=40, deadline=None)
@given(
    kappa=st.floats(min_value=-2.0, max_value=2.0),
    magnitude=st.floats(min_value=0.1, max_value=5.0),
    a0_sign=st.sampled_from([1, -1]),
    strength=st.floats(min_value=-0.9, max_value=3.0),
    a=st.floats(min_value=-2.0, max_value=2.0).filter(lambda value: abs(value) > 0.05),
    omega0=st.floats(min_value=0.3, max_value=3.0),
    other_magnitude=st.floats(min_value=0.1, max_value=5.0),
)
def test_frequency_depends_on_b_and_a0_only_through_kappa_and_sign(
    kappa, magnitude, a0_sign, strength, a, omega0, other_magnitude
):
    # (u - b)_+ is homogeneous of degree 1: u = |a0| v maps the problem to b/|a0|, sign(a0) with the
    # same epsilon; tau = omega0 t then gives omega0 * omega(epsilon a/omega0^2; a=1, omega0=1).
    # Each 30-digit reference value carries its own error estimate: its distance to the same closed form
    # at 50 digits (near grazing, |kappa| -> 1, the arccos terms amplify rounding far beyond 1e-30), plus
    # the final rounding to 30 digits.
    def reference(*arguments, **keywords):
        low = piecewise_linear_exact_frequency(*arguments, precision=30, **keywords)
        high = piecewise_linear_exact_frequency(*arguments, precision=50, **keywords)
        with mpmath.workdps(60):
            return low, abs(high - low) + mpmath.mpf(10) ** -30 * abs(low)

    with mpmath.workdps(40):
        kappa_value, strength_value = mpmath.mpf(kappa), mpmath.mpf(strength)
        epsilon = strength_value * mpmath.mpf(omega0) ** 2 / mpmath.mpf(a)
        magnitude_value, other_value = mpmath.mpf(magnitude), mpmath.mpf(other_magnitude)
        original, original_error = reference(epsilon, a=a, b=kappa_value * magnitude_value, a0=a0_sign * magnitude_value, omega0=omega0)
        rescaled, rescaled_error = reference(epsilon, a=a, b=kappa_value * other_value, a0=a0_sign * other_value, omega0=omega0)
        reduced, reduced_error = reference(strength_value, a=1, b=kappa_value, a0=a0_sign, omega0=1)
    with mpmath.workdps(60):
        assert abs(original - rescaled) <= original_error + rescaled_error
        assert abs(original - mpmath.mpf(omega0) * reduced) <= original_error + mpmath.mpf(omega0) * reduced_error
        # the estimates are estimates, not loose bounds: away from grazing they are at the rounding level
        if abs(abs(kappa_value) - 1) > mpmath.mpf("0.01"):
            assert original_error <= mpmath.mpf(10) ** -28 * abs(original)


# ------------------------------------------------------------------ errors
def test_invalid_problems_raise_problem_errors():
    with pytest.raises(ProblemError, match="omega0\\*\\*2 \\+ epsilon\\*a"):
        piecewise_linear_exact_frequency(-2, a=1, b=0, a0=1)  # contact region unstable and reached
    with pytest.raises(ProblemError, match="equilibrium"):
        piecewise_linear_exact_frequency("0.5", a=1, b="0.3", a0=0)
    with pytest.raises(ProblemError, match="equilibrium"):
        # b < 0: equilibrium u_e = eps a b/(omega0^2 + eps a) = 1 * (-1)/2.
        piecewise_linear_exact_frequency(1, a=1, b=-1, a0="-0.5")
    with pytest.raises(ProblemError, match="omega0"):
        piecewise_linear_exact_frequency("0.5", a=1, b=0, a0=1, omega0=0)
    with pytest.raises(ProblemError, match="disc"):
        piecewise_linear_exact_frequency(mpmath.mpc(0, 2), a=1, b=0, a0=1)  # beyond Omega = 0 at |eps| = 1
    with pytest.raises(ProblemError, match="grazing"):
        piecewise_linear_exact_frequency(mpmath.mpc(0, "0.01"), a=1, b=1, a0=1)
    with pytest.raises(OrderError):
        piecewise_linear_frequency_taylor(-1, a=1, b=0, a0=1)
    with pytest.raises(OrderError):
        piecewise_linear_frequency_taylor_symbolic(1.5)
