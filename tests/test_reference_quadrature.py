"""Tests of the quadrature reference (lindstedt.references: conservative_*, frequency_taylor_coefficients).

Equation: u'' + omega0**2 u + epsilon f(u) = 0, u(0) = a0, u'(0) = 0.
Expectations come from exact closed forms (linear f, the Duffing elliptic
integral evaluated here with mpmath.ellipk, the exact Duffing rationals
3/8, -21/256, ... of the independent power-series reference), direct
numerical integration of the ODE with scipy, and the exact scaling law of
the cubic oscillator.
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from lindstedt import ConvergenceError, OrderError, ParameterError, ProblemError
from lindstedt.references import (
    conservative_frequency,
    conservative_period,
    duffing_frequency_taylor,
    frequency_taylor_coefficients,
)

U = sympy.Symbol("u")


def integrated_period(force, epsilon: float, a0: float, omega0: float) -> float:
    """Period from DOP853 (rtol 1e-13): twice the time to the other turning point."""

    def right_hand_side(_time, state):
        return [state[1], -(omega0**2) * state[0] - epsilon * force(state[0])]

    def turning(_time, state):
        return state[1]

    initial_acceleration = -(omega0**2) * a0 - epsilon * force(a0)
    turning.terminal = True
    # Velocity has the sign of the initial acceleration until the other turning point.
    turning.direction = 1 if initial_acceleration < 0 else -1
    solution = solve_ivp(
        right_hand_side, (0.0, 1000.0), [a0, 0.0], method="DOP853", rtol=1e-13, atol=1e-15, events=turning
    )
    return 2 * float(solution.t_events[0][0])


def duffing_period_closed_form(epsilon, a0, omega0, coefficient=1):
    """T = 4 K(m)/Omega, Omega**2 = omega0**2 + lam a0**2, m = lam a0**2/(2 Omega**2)."""
    strength = epsilon * coefficient * a0**2
    contact_square = omega0**2 + strength
    return 4 * mpmath.ellipk(strength / (2 * contact_square)) / mpmath.sqrt(contact_square)


# ------------------------------------------------------------ exact periods
@pytest.mark.parametrize("epsilon", ["-0.8", "0", "0.5", "3"])
def test_linear_nonlinearity_gives_shifted_frequency(epsilon):
    # f = 2u: omega**2 = omega0**2 + 2 epsilon exactly.
    with mpmath.workdps(40):
        frequency, error = conservative_frequency(2 * U, epsilon, a0="0.6", omega0="1.5", precision=30)
        exact = mpmath.sqrt(mpmath.mpf("1.5") ** 2 + 2 * mpmath.mpf(epsilon))
        assert abs(frequency - exact) <= mpmath.mpf(10) ** -28 * exact
        assert error < mpmath.mpf(10) ** -27


@pytest.mark.parametrize("epsilon, a0, omega0", [("0.5", "1", "1"), ("-0.9", "0.7", "1.3"), ("4", "-1.2", "0.8")])
def test_duffing_period_matches_elliptic_integral(epsilon, a0, omega0):
    with mpmath.workdps(40):
        period, error = conservative_period(U**3, epsilon, a0=a0, omega0=omega0, precision=30)
        exact = duffing_period_closed_form(mpmath.mpf(epsilon), mpmath.mpf(a0), mpmath.mpf(omega0))
        assert abs(period - exact) <= error
        assert abs(period - exact) <= mpmath.mpf(10) ** -28 * exact


@pytest.mark.parametrize("epsilon", [-0.4, 0.15, 0.45])
@pytest.mark.parametrize("a0", [0.7, -0.9])
def test_quadratic_period_matches_integration(epsilon, a0):
    period, error = conservative_period(U**2, epsilon, a0=a0, omega0=1.2, precision=20)
    numerical = integrated_period(lambda value: value**2, epsilon, a0, 1.2)
    assert float(period) == pytest.approx(numerical, rel=1e-11, abs=0)
    assert error < 1e-18


@pytest.mark.parametrize("epsilon", [-0.6, 0.3, 1.5])
def test_sine_period_matches_integration(epsilon):
    period, _ = conservative_period(sympy.sin(U), epsilon, a0=1.1, omega0=0.9, precision=20)
    numerical = integrated_period(np.sin, epsilon, 1.1, 0.9)
    assert float(period) == pytest.approx(numerical, rel=1e-11, abs=0)


def test_callable_nonlinearity_matches_expression():
    with mpmath.workdps(30):
        from_expression, _ = conservative_period(sympy.sin(U) + U**2, "-0.3", a0="0.7", precision=25)
        from_callable, error = conservative_period(
            lambda value: mpmath.sin(value) + value**2, "-0.3", a0="0.7", precision=25
        )
        assert abs(from_expression - from_callable) <= mpmath.mpf(10) ** -23
        assert error < mpmath.mpf(10) ** -23


def test_precision_does_not_leak_and_converges():
    global_dps = mpmath.mp.dps
    low, _ = conservative_period(U**2 + U**3, "0.4", a0="0.8", precision=20)
    high, _ = conservative_period(U**2 + U**3, "0.4", a0="0.8", precision=40)
    assert mpmath.mp.dps == global_dps
    with mpmath.workdps(50):
        assert abs(high - low) <= mpmath.mpf(10) ** -19 * high


@settings(max_examples=15, deadline=None)
@given(
    a0=st.floats(min_value=0.2, max_value=2.0) | st.floats(min_value=-2.0, max_value=-0.2),
    omega0=st.floats(min_value=0.5, max_value=2.0),
    strength=st.floats(min_value=-0.6, max_value=1.5),
)
def test_cubic_scaling_law(a0, omega0, strength):
    # u = a0 v, tau = omega0 t turns u'' + omega0^2 u + eps u^3 = 0 into
    # v'' + v + (eps a0^2/omega0^2) v^3 = 0 with v(0) = 1.
    with mpmath.workdps(30):
        epsilon = mpmath.mpf(strength) * mpmath.mpf(omega0) ** 2 / mpmath.mpf(a0) ** 2
        scaled_epsilon = epsilon * mpmath.mpf(a0) ** 2 / mpmath.mpf(omega0) ** 2
        original, error_original = conservative_frequency(U**3, epsilon, a0=a0, omega0=omega0, precision=20)
        reduced, error_reduced = conservative_frequency(U**3, scaled_epsilon, a0=1, omega0=1, precision=20)
        difference = abs(original - mpmath.mpf(omega0) * reduced)
        assert difference <= error_original + omega0 * error_reduced + mpmath.mpf(10) ** -18 * original


# ------------------------------------------------------ Taylor coefficients
def test_duffing_taylor_coefficients_match_exact_rationals():
    a0, omega0 = sympy.Rational(7, 10), sympy.Rational(13, 10)
    order = 8
    coefficients = frequency_taylor_coefficients(U**3, order, a0=a0, omega0=omega0, precision=40)
    rationals = duffing_frequency_taylor(order, "initial")
    with mpmath.workdps(50):
        for power, ((value, error), rational) in enumerate(zip(coefficients, rationals)):
            exact_rational = omega0 * rational * (a0**2 / omega0**2) ** power
            exact = mpmath.mpf(int(exact_rational.p)) / int(exact_rational.q)
            assert abs(value - exact) <= mpmath.mpf(10) ** -20 * abs(exact), power
            assert abs(value - exact) <= error, power  # the error estimate is honest
            assert error <= mpmath.mpf(10) ** -20 * abs(exact), power


def test_quadratic_first_order_coefficient_vanishes_and_second_is_textbook():
    # f = u**2, omega0 = 1: omega = 1 - (5/12) epsilon**2 a0**2 + O(epsilon**3) (classical second-order
    # result; the first-order shift of a quadratic force vanishes because <cos**3> = 0).
    coefficients = frequency_taylor_coefficients(U**2, 3, a0="0.6", omega0=1, precision=30)
    with mpmath.workdps(40):
        assert abs(coefficients[1][0]) <= coefficients[1][1] + mpmath.mpf(10) ** -25
        exact_second = -mpmath.mpf(5) / 12 * mpmath.mpf("0.6") ** 2
        assert abs(coefficients[2][0] - exact_second) <= mpmath.mpf(10) ** -20


def test_invalid_taylor_orders_raise_order_error():
    with pytest.raises(OrderError):
        frequency_taylor_coefficients(U**3, -1, a0=1)
    with pytest.raises(OrderError):
        frequency_taylor_coefficients(U**3, 2.0, a0=1)


# ------------------------------------------------------------------- errors
def test_escaping_orbit_raises_convergence_error():
    # V = u^2/2 + eps u^3/3 has its barrier at u = -1/eps with height 1/(6 eps^2) = 0.463 for
    # eps = 0.6, below the release energy V(1) = 1/2 + 0.6/3 = 0.7: the orbit runs over the barrier.
    with pytest.raises(ConvergenceError, match="escapes"):
        conservative_period(U**2, "0.6", a0=1)


def test_invalid_problems_raise_problem_errors():
    with pytest.raises(ParameterError, match="alpha"):
        conservative_period(sympy.Symbol("alpha") * U**3, "0.1", a0=1)
    with pytest.raises(ProblemError, match="equilibrium"):
        conservative_period(U**3, "0.1", a0=0)
    with pytest.raises(ProblemError, match="omega0"):
        conservative_period(U**3, "0.1", a0=1, omega0=-1)
    with pytest.raises(ProblemError):
        conservative_period("u**3", "0.1", a0=1)
    with pytest.raises(ProblemError):
        conservative_period(U**3, "0.1", a0=1, precision=2)


def test_release_at_rest_is_bit_identical_to_the_analytic_path_before_velocity():
    # The values below were produced by the reference before initial velocities and piecewise f existed
    # (release at rest, periodic trapezoidal rule); velocity=0 must reproduce them bit for bit.
    period = conservative_period(U**3, "0.5", a0="1", omega0="1", precision=30)
    assert [value._mpf_ for value in period] == [
        (0, 6803048952829286136773106771117, -100, 103),
        (0, 2155972272109049503467123800543, -198, 101),
    ]
    frequency = conservative_frequency(U**3, "0.5", a0="1", omega0="1", precision=30, velocity=0)
    assert [value._mpf_ for value in frequency] == [
        (0, 2968283656120665086442050530837, -101, 102),
        (0, 3762746558705279027369083040663, -201, 102),
    ]
