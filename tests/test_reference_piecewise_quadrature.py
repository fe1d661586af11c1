"""Quadrature reference for piecewise-analytic f(u) and for orbits with an initial velocity.

Equation: u'' + omega0**2 u + epsilon f(u) = 0, u(0) = a0, u'(0) = v0.

Every expectation is independent of the code under test:

* piecewise-linear springs: the closed-form period already in the package
  (``piecewise_linear_exact_period``, two ellipse arcs) and its Cauchy-integral
  Taylor coefficients; the symmetric two-sided gap from the one-sided period
  (derived below);
* a jump c H(u - b): on each side of b the motion is harmonic (about 0 below b,
  about -epsilon c/omega0**2 above), so the period is a sum of two arccos arcs
  (derived below, with or without an initial velocity);
* omega_1 of the Hertz law u_+**(3/2), of u_+**2 and of u|u| from first-order
  averaging, omega_1 = (1/(2 pi A omega0)) int_0^{2 pi} f(A cos s) cos s ds, in closed
  form with Gamma functions (and cross-checked by mpmath.quad of that integral);
* linear f = u (omega**2 = omega0**2 + epsilon for every orbit) and the Duffing
  elliptic-integral frequency (``duffing_exact_frequency``) at the turning amplitude
  that the energy of (a0, v0) fixes (a biquadratic, solved exactly);
* for a general piecewise f with velocity: the orbit through (a0, v0) is the orbit
  released at rest from its turning point, found here by mpmath.findroot on an energy
  computed by the test's own quadrature;
* a repulsive u**-2 wall: the period as an explicit integral between the roots of a cubic.
"""

from __future__ import annotations

import mpmath
import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st

from lindstedt import ConvergenceError, ProblemError, UnsupportedNonlinearityError
from lindstedt.references import (
    conservative_frequency,
    conservative_period,
    duffing_exact_frequency,
    frequency_taylor_coefficients,
    nonlinearity_breakpoints,
    piecewise_linear_exact_period,
    piecewise_linear_frequency_taylor,
)

U = sympy.Symbol("u")
R = sympy.Rational
DIGITS = 25  # required agreement (relative) at precision 30


def mp(value) -> mpmath.mpf:
    """An exact test value as mpf at the current precision."""
    value = sympy.Rational(value) if not isinstance(value, sympy.Basic) else value
    return mpmath.mpf(int(value.p)) / int(value.q) if isinstance(value, sympy.Rational) else mpmath.mpf(str(sympy.N(value, 80)))


def assert_agrees(value, error, exact, digits=DIGITS):
    """The reference is within its own error estimate and that estimate is below 10**-digits relative."""
    assert abs(value - exact) <= error, (value, exact, error)
    assert error <= mpmath.mpf(10) ** (-digits) * abs(exact), error


# ---------------------------------------------------------------- independent closed forms
def jump_period(epsilon, height, b, a0, omega0, velocity=0):
    """Period for f = height * H(u - b) on an orbit that crosses b.

    V = omega0**2 u**2/2 below b; above b, V = omega0**2 u**2/2 + k (u - b) with k = epsilon*height,
    i.e. omega0**2 (u - centre)**2/2 + floor, centre = -k/omega0**2, floor = -k b - k**2/(2 omega0**2).
    With E = v0**2/2 + V(a0) the two arcs are harmonic with amplitudes sqrt(2E)/omega0 about 0 and
    sqrt(2(E - floor))/omega0 about the centre; each is run through at the angular rate omega0.
    """
    k = epsilon * height
    centre = -k / omega0**2
    floor = -k * b - k**2 / (2 * omega0**2)
    energy = velocity**2 / 2 + omega0**2 * a0**2 / 2 + (k * (a0 - b) if a0 > b else 0)
    free_amplitude = mpmath.sqrt(2 * energy) / omega0
    contact_amplitude = mpmath.sqrt(2 * (energy - floor)) / omega0
    contact_time = 2 * mpmath.acos((b - centre) / contact_amplitude) / omega0
    free_time = 2 * (mpmath.pi - mpmath.acos(b / free_amplitude)) / omega0
    return contact_time + free_time


def unilateral_turning_point(epsilon, b, a0, velocity, omega0):
    """Positive turning point of f = (u - b)_+ (b >= 0 and an orbit reaching past b), from the energy.

    omega0**2 u**2/2 + epsilon (u - b)**2/2 = E is a quadratic in u; its larger root.
    """
    energy = velocity**2 / 2 + omega0**2 * a0**2 / 2 + (epsilon * (a0 - b) ** 2 / 2 if a0 > b else 0)
    square = omega0**2 + epsilon
    # square u**2 - 2 epsilon b u + epsilon b**2 - 2 E = 0
    return (epsilon * b + mpmath.sqrt(epsilon**2 * b**2 - square * (epsilon * b**2 - 2 * energy))) / square


def averaged_omega1(force, amplitude, omega0, breakpoints=()):
    """omega_1 = (1/(2 pi A omega0)) int_0^{2 pi} f(A cos s) cos s ds, split where A cos s is a breakpoint."""
    points = [mpmath.mpf(0)]
    for point in breakpoints:
        if abs(point) < amplitude:
            angle = mpmath.acos(point / amplitude)
            points += [angle, 2 * mpmath.pi - angle]
    points = sorted(points) + [2 * mpmath.pi]
    integral = mpmath.quad(lambda s: force(amplitude * mpmath.cos(s)) * mpmath.cos(s), points)
    return integral / (2 * mpmath.pi * amplitude * omega0)


# ---------------------------------------------------------------- piecewise-linear springs
@pytest.mark.parametrize(
    "stiffness, gap, expression",
    [
        (1, 0, sympy.Max(0, U)),
        (1, R(1, 3), sympy.Max(0, U - R(1, 3))),
        (2, R(-1, 4), 2 * sympy.Max(0, U + R(1, 4))),
        (R(3, 2), R(1, 5), R(3, 2) * (U - R(1, 5)) * sympy.Heaviside(U - R(1, 5))),
    ],
)
@pytest.mark.parametrize("epsilon, a0, omega0", [("0.5", "1", "1"), ("-0.3", "0.8", "1.3"), ("2.5", "-1.1", "0.9")])
def test_piecewise_linear_period_matches_closed_form(stiffness, gap, expression, epsilon, a0, omega0):
    with mpmath.workdps(50):
        period, error = conservative_period(expression, epsilon, a0=a0, omega0=omega0, precision=30)
        exact = piecewise_linear_exact_period(epsilon, a=stiffness, b=gap, a0=a0, omega0=omega0, precision=45)
        assert_agrees(period, error, exact)


@pytest.mark.parametrize("epsilon, a0", [("0.5", "1"), ("-0.4", "0.9"), ("3", "-0.7")])
def test_two_sided_gap_period(epsilon, a0):
    # f = (u - g)_+ - (-u - g)_+ is odd, so the orbit released at a0 > g is symmetric.  With t_c the time
    # from a0 to the contact boundary g and phi = arccos(g/A_f) on the free ellipse (amplitude A_f):
    # one-sided T_1 = 2 t_c + 2 (pi - phi)/omega0, two-sided T_2 = 4 t_c + 2 (pi - 2 phi)/omega0,
    # hence T_2 = 2 T_1 - 2 pi/omega0.
    gap, omega0 = R(1, 3), R(6, 5)
    expression = sympy.Max(0, U - gap) + sympy.Min(0, U + gap)
    with mpmath.workdps(50):
        period, error = conservative_period(expression, epsilon, a0=a0, omega0=omega0, precision=30)
        one_sided = piecewise_linear_exact_period(epsilon, a=1, b=gap, a0=abs(mpmath.mpf(a0)), omega0=omega0, precision=45)
        exact = 2 * one_sided - 2 * mpmath.pi / mp(omega0)
        assert_agrees(period, error, exact)


def test_piecewise_linear_taylor_coefficients_match_cauchy_reference():
    gap = R(1, 3)
    coefficients = frequency_taylor_coefficients(sympy.Max(0, U - gap), 4, a0=1, omega0=1, precision=30)
    reference = piecewise_linear_frequency_taylor(4, a=1, b=gap, a0=1, omega0=1, precision=45)
    with mpmath.workdps(50):
        for power, ((value, error), (exact, exact_error)) in enumerate(zip(coefficients, reference)):
            assert abs(value - exact) <= error + exact_error, power
            assert error <= mpmath.mpf(10) ** -DIGITS * max(abs(exact), 1), power


# ---------------------------------------------------------------------------- a jump
@pytest.mark.parametrize("epsilon", ["0.1", "0.3", "-0.2", "1.5"])
@pytest.mark.parametrize("a0", ["1", "-0.8"])
def test_jump_period_matches_two_harmonic_arcs(epsilon, a0):
    b, omega0 = R(1, 3), R(11, 10)
    with mpmath.workdps(50):
        period, error = conservative_period(sympy.Heaviside(U - b), epsilon, a0=a0, omega0=omega0, precision=30)
        exact = jump_period(mpmath.mpf(epsilon), 1, mp(b), mpmath.mpf(a0), mp(omega0))
        assert_agrees(period, error, exact)


@pytest.mark.slow
def test_jump_frequency_taylor_coefficients_match_closed_form():
    # omega(epsilon) = 2 pi / jump_period is analytic at 0 (the orbit crosses b transversally); its Taylor
    # coefficients from the closed form by mpmath.taylor (numerical differentiation at 80 digits).
    b = R(1, 3)
    coefficients = frequency_taylor_coefficients(sympy.Heaviside(U - b), 3, a0=1, omega0=1, precision=30)
    with mpmath.workdps(80):
        exact = mpmath.taylor(lambda e: 2 * mpmath.pi / jump_period(e, 1, mp(b), mpmath.mpf(1), mpmath.mpf(1)), 0, 3)
        for power, (value, error) in enumerate(coefficients):
            assert abs(value - exact[power]) <= error, power
            assert error <= mpmath.mpf(10) ** -DIGITS, power
        # first-order averaging, by hand: (1/(2 pi)) int_{|s| < arccos b} cos s ds = sqrt(1 - b**2)/pi
        assert abs(exact[1] - mpmath.sqrt(1 - mp(b) ** 2) / mpmath.pi) < mpmath.mpf(10) ** -40


# ---------------------------------------------------------------- first-order averaging
def hertz_omega1(amplitude, omega0):
    # (1/(2 pi A omega0)) int_{-pi/2}^{pi/2} (A cos s)**(3/2) cos s ds = A**(1/2)/(2 pi omega0) * B(1/2, 7/4)
    # with int_{-pi/2}^{pi/2} cos**p = sqrt(pi) Gamma((p+1)/2)/Gamma(p/2 + 1), p = 5/2.
    return mpmath.sqrt(amplitude) * mpmath.gamma(mpmath.mpf(7) / 4) / (2 * mpmath.sqrt(mpmath.pi) * mpmath.gamma(mpmath.mpf(9) / 4) * omega0)


@pytest.mark.parametrize(
    "expression, closed_form, force, a0, omega0",
    [
        # Hertz: omega_1 = Gamma(7/4)/(2 sqrt(pi) Gamma(9/4)) = 0.228828... at A = omega0 = 1
        (sympy.Max(0, U) ** R(3, 2), lambda a, w: hertz_omega1(a, w), lambda x: max(x, 0) ** mpmath.mpf(1.5), 1, 1),
        # u_+**2: (A/(2 pi omega0)) int_{-pi/2}^{pi/2} cos**3 = 2 A/(3 pi omega0)
        pytest.param(
            sympy.Max(0, U) ** 2,
            lambda a, w: 2 * a / (3 * mpmath.pi * w),
            lambda x: max(x, 0) ** 2,
            R(4, 5),
            R(13, 10),
            marks=pytest.mark.slow,
        ),
        # u|u|: (A/(2 pi omega0)) int_0^{2 pi} |cos|**3 = (A/(2 pi omega0)) (8/3) = 4 A/(3 pi omega0)
        (U * sympy.Abs(U), lambda a, w: 4 * a / (3 * mpmath.pi * w), lambda x: x * abs(x), R(4, 5), R(13, 10)),
    ],
    ids=["hertz", "max-squared", "u-abs-u"],
)
def test_first_order_coefficient_from_averaging(expression, closed_form, force, a0, omega0):
    coefficients = frequency_taylor_coefficients(expression, 1, a0=a0, omega0=omega0, precision=30)
    with mpmath.workdps(50):
        exact = closed_form(mp(a0), mp(omega0))
        assert abs(averaged_omega1(force, mp(a0), mp(omega0), [0]) - exact) < mpmath.mpf(10) ** -45
        value, error = coefficients[1]
        assert_agrees(value, error, exact)
        assert_agrees(coefficients[0][0], coefficients[0][1], mp(omega0))


def test_hertz_closed_form_value():
    assert mpmath.nstr(hertz_omega1(mpmath.mpf(1), mpmath.mpf(1)), 6) == "0.228828"


@pytest.mark.slow
@pytest.mark.parametrize(
    "expression, force, breakpoints",
    [
        (sympy.Max(0, U - R(1, 5)) ** R(3, 2), lambda x: max(x - mpmath.mpf(1) / 5, 0) ** mpmath.mpf(1.5), [R(1, 5)]),
        (sympy.Heaviside(U) * U**2, lambda x: x**2 if x > 0 else 0, [0]),
        (sympy.Piecewise((U ** R(-1, 2), U > 0), (0, True)), lambda x: x ** mpmath.mpf(-0.5) if x > 0 else 0, [0]),
    ],
    ids=["hertz-gap", "heaviside-u-squared", "integrable-singularity"],
)
def test_first_order_coefficient_by_averaging_quadrature(expression, force, breakpoints):
    coefficients = frequency_taylor_coefficients(expression, 1, a0=1, omega0=1, precision=30)
    with mpmath.workdps(50):
        exact = averaged_omega1(force, mpmath.mpf(1), mpmath.mpf(1), [mp(point) for point in breakpoints])
        assert_agrees(coefficients[1][0], coefficients[1][1], exact)


@pytest.mark.parametrize("epsilon", ["0.4", "-0.3", "2"])
def test_one_law_written_three_ways_has_one_period(epsilon):
    forms = [sympy.Max(0, U) ** 2, sympy.Heaviside(U) * U**2, sympy.Piecewise((U**2, U > 0), (0, True))]
    with mpmath.workdps(40):
        results = [conservative_period(form, epsilon, a0="0.9", precision=30) for form in forms]
        for period, error in results[1:]:
            assert abs(period - results[0][0]) <= error + results[0][1]


# ----------------------------------------------------------------- initial velocity
def duffing_frequency_with_velocity(epsilon, a0, velocity, omega0):
    """omega of u'' + omega0**2 u + epsilon u**3 = 0 through (a0, v0), at the current precision.

    The turning amplitude solves omega0**2 A**2/2 + epsilon A**4/4 = E (a quadratic in A**2; the root
    continuous at epsilon = 0, written without cancellation), E = v0**2/2 + omega0**2 a0**2/2 + epsilon a0**4/4.
    """
    energy = velocity**2 / 2 + omega0**2 * a0**2 / 2 + epsilon * a0**4 / 4
    amplitude_squared = 4 * energy / (omega0**2 + mpmath.sqrt(omega0**4 + 4 * epsilon * energy))
    return duffing_exact_frequency(
        epsilon, amplitude=mpmath.sqrt(amplitude_squared), omega0=omega0, precision=mpmath.mp.dps
    )


@pytest.mark.parametrize("epsilon, a0, velocity, omega0", [("0.5", "0.3", "0.8", "1.2"), ("-0.7", "0", "1", "1"), ("2", "-0.4", "-0.3", "0.7")])
def test_linear_force_with_velocity(epsilon, a0, velocity, omega0):
    with mpmath.workdps(50):
        frequency, error = conservative_frequency(U, epsilon, a0=a0, velocity=velocity, omega0=omega0, precision=30)
        assert_agrees(frequency, error, mpmath.sqrt(mpmath.mpf(omega0) ** 2 + mpmath.mpf(epsilon)))


@pytest.mark.parametrize("epsilon, a0, velocity, omega0", [("0.5", "0.6", "0.7", "1"), ("-0.3", "0.2", "-0.9", "1.3"), ("2", "0", "1", "1")])
def test_duffing_with_velocity_matches_elliptic_frequency(epsilon, a0, velocity, omega0):
    with mpmath.workdps(60):
        exact = duffing_frequency_with_velocity(*(mpmath.mpf(value) for value in (epsilon, a0, velocity, omega0)))
        frequency, error = conservative_frequency(U**3, epsilon, a0=a0, velocity=velocity, omega0=omega0, precision=30)
        assert_agrees(frequency, error, exact)


def test_duffing_taylor_coefficients_with_velocity():
    a0, velocity, omega0 = mpmath.mpf("0.6"), mpmath.mpf("0.8"), mpmath.mpf("1.1")
    coefficients = frequency_taylor_coefficients(U**3, 3, a0=a0, velocity=velocity, omega0=omega0, precision=30)
    with mpmath.workdps(80):
        exact = mpmath.taylor(lambda e: duffing_frequency_with_velocity(e, a0, velocity, omega0), 0, 3)
        # first order: 3 A**2/(8 omega0) with A**2 = a0**2 + v0**2/omega0**2
        assert abs(exact[1] - 3 * (a0**2 + velocity**2 / omega0**2) / (8 * omega0)) < mpmath.mpf(10) ** -40
        for power, (value, error) in enumerate(coefficients):
            assert abs(value - exact[power]) <= error, power
            assert error <= mpmath.mpf(10) ** -DIGITS * abs(exact[power]), power


@pytest.mark.parametrize("epsilon, a0, velocity", [("0.6", "0.2", "0.9"), ("-0.25", "1", "0.5"), ("1.5", "-0.5", "-1.2")])
def test_unilateral_spring_with_velocity_matches_closed_form(epsilon, a0, velocity):
    gap, omega0 = R(1, 4), R(9, 10)
    with mpmath.workdps(50):
        turning = unilateral_turning_point(mpmath.mpf(epsilon), mp(gap), mpmath.mpf(a0), mpmath.mpf(velocity), mp(omega0))
        exact = piecewise_linear_exact_period(epsilon, a=1, b=gap, a0=turning, omega0=omega0, precision=45)
        period, error = conservative_period(
            sympy.Max(0, U - gap), epsilon, a0=a0, velocity=velocity, omega0=omega0, precision=30
        )
        assert_agrees(period, error, exact)


@pytest.mark.parametrize("epsilon, a0, velocity", [("0.4", "0.5", "0.6"), ("-0.3", "1", "0.2"), ("2", "-0.6", "0.9")])
def test_jump_with_velocity_matches_two_harmonic_arcs(epsilon, a0, velocity):
    b, omega0, height = R(1, 3), R(1), R(3, 2)
    with mpmath.workdps(50):
        period, error = conservative_period(
            height * sympy.Heaviside(U - b), epsilon, a0=a0, velocity=velocity, omega0=omega0, precision=30
        )
        exact = jump_period(mpmath.mpf(epsilon), mp(height), mp(b), mpmath.mpf(a0), mp(omega0), mpmath.mpf(velocity))
        assert_agrees(period, error, exact)


PIECEWISE_LAWS = {
    "hertz": (sympy.Max(0, U) ** R(3, 2), lambda x: max(x, 0) ** mpmath.mpf(1.5), [0]),
    "hertz-gap": (sympy.Max(0, U - R(1, 5)) ** R(3, 2), lambda x: max(x - mpmath.mpf(1) / 5, 0) ** mpmath.mpf(1.5), [R(1, 5)]),
    "u-abs-u": (U * sympy.Abs(U), lambda x: x * abs(x), [0]),
    "jump": (sympy.Heaviside(U - R(1, 3)), lambda x: 1 if x > mpmath.mpf(1) / 3 else 0, [R(1, 3)]),
}


def turning_point_by_findroot(force, breakpoints, epsilon, a0, velocity, omega0):
    """Positive turning point: V(u) = E with V from the test's own quadrature of f (split at the breakpoints)."""

    def potential(x):
        points = sorted({mpmath.mpf(0), x, *[p for p in breakpoints if min(0, x) < p < max(0, x)]})
        integral = mpmath.quad(force, points) if x >= 0 else -mpmath.quad(force, points)
        return omega0**2 * x**2 / 2 + epsilon * integral

    energy = velocity**2 / 2 + potential(a0)
    guess = mpmath.sqrt(2 * energy) / omega0
    return mpmath.findroot(lambda x: potential(x) - energy, guess, tol=mpmath.mpf(10) ** (-2 * mpmath.mp.dps // 3))


@pytest.mark.parametrize("law", sorted(PIECEWISE_LAWS))
@pytest.mark.parametrize("epsilon, a0, velocity", [("0.4", "0.5", "0.6"), ("-0.3", "-0.2", "1.1")])
def test_orbit_with_velocity_equals_orbit_from_its_turning_point(law, epsilon, a0, velocity):
    expression, force, breakpoints = PIECEWISE_LAWS[law]
    with mpmath.workdps(45):
        points = [mp(point) for point in breakpoints]
        turning = turning_point_by_findroot(force, points, mpmath.mpf(epsilon), mpmath.mpf(a0), mpmath.mpf(velocity), mpmath.mpf(1))
        moving, moving_error = conservative_period(expression, epsilon, a0=a0, velocity=velocity, precision=30)
        resting, resting_error = conservative_period(expression, epsilon, a0=turning, precision=30)
        assert abs(moving - resting) <= moving_error + resting_error + mpmath.mpf(10) ** -28
        assert moving_error <= mpmath.mpf(10) ** -DIGITS * moving


@pytest.mark.slow
def test_hertz_first_order_coefficient_with_velocity():
    # The first-order average only sees the epsilon = 0 amplitude A = sqrt(a0**2 + v0**2/omega0**2) = 1.
    coefficients = frequency_taylor_coefficients(sympy.Max(0, U) ** R(3, 2), 1, a0="0.6", velocity="0.8", precision=30)
    with mpmath.workdps(50):
        assert_agrees(coefficients[1][0], coefficients[1][1], hertz_omega1(mpmath.mpf(1), mpmath.mpf(1)))


def test_velocity_zero_is_the_release_at_rest():
    for expression in (U**3, sympy.Max(0, U) ** R(3, 2)):
        assert conservative_period(expression, "0.3", a0="0.9", precision=25) == conservative_period(
            expression, "0.3", a0="0.9", velocity=0, precision=25
        )


# ------------------------------------------------------------- honesty and precision
@pytest.mark.parametrize("precision", [5, 10, 15, 20, 40])
def test_error_estimates_are_honest_at_every_precision(precision):
    with mpmath.workdps(precision + 30):
        b = R(1, 3)
        period, error = conservative_period(sympy.Max(0, U - b), "0.7", a0=1, precision=precision)
        exact = piecewise_linear_exact_period("0.7", a=1, b=b, a0=1, precision=precision + 25)
        assert abs(period - exact) <= error
        assert error <= 10 * mpmath.mpf(10) ** (-precision) * exact
        period, error = conservative_period(sympy.Heaviside(U - b), "0.4", a0="0.9", velocity="0.3", precision=precision)
        exact = jump_period(mpmath.mpf("0.4"), 1, mp(b), mpmath.mpf("0.9"), mpmath.mpf(1), mpmath.mpf("0.3"))
        assert abs(period - exact) <= error
        assert error <= 10 * mpmath.mpf(10) ** (-precision) * exact


@settings(max_examples=12, deadline=None)
@given(
    a0=st.floats(min_value=0.3, max_value=2.0),
    omega0=st.floats(min_value=0.5, max_value=2.0),
    strength=st.floats(min_value=-0.4, max_value=2.0),
)
def test_hertz_scaling_law(a0, omega0, strength):
    # u = a0 v, tau = omega0 t turn u'' + omega0**2 u + eps u_+**(3/2) = 0 into
    # v'' + v + (eps sqrt(a0)/omega0**2) v_+**(3/2) = 0 with v(0) = 1, and T = T_v/omega0.
    hertz = sympy.Max(0, U) ** R(3, 2)
    with mpmath.workdps(40):
        epsilon = mpmath.mpf(strength) * mpmath.mpf(omega0) ** 2 / mpmath.sqrt(mpmath.mpf(a0))
        scaled = epsilon * mpmath.sqrt(mpmath.mpf(a0)) / mpmath.mpf(omega0) ** 2
        original, original_error = conservative_period(hertz, epsilon, a0=a0, omega0=omega0, precision=20)
        reduced, reduced_error = conservative_period(hertz, scaled, a0=1, omega0=1, precision=20)
        assert abs(original - reduced / mpmath.mpf(omega0)) <= original_error + reduced_error / mpmath.mpf(omega0)


@settings(max_examples=15, deadline=None)
@given(
    epsilon=st.floats(min_value=-0.5, max_value=3.0),
    gap=st.fractions(min_value=-1, max_value=1, max_denominator=12),
    a0=st.floats(min_value=0.1, max_value=2.0) | st.floats(min_value=-2.0, max_value=-0.1),
    omega0=st.floats(min_value=0.8, max_value=1.5),
)
def test_unilateral_spring_closed_form_property(epsilon, gap, a0, omega0):
    gap = R(gap.numerator, gap.denominator)
    with mpmath.workdps(40):
        exact = piecewise_linear_exact_period(epsilon, a=1, b=gap, a0=a0, omega0=omega0, precision=35)
        period, error = conservative_period(sympy.Max(0, U - gap), epsilon, a0=a0, omega0=omega0, precision=20)
        assert abs(period - exact) <= error
        assert error <= mpmath.mpf(10) ** -18 * exact


@settings(max_examples=15, deadline=None)
@given(
    epsilon=st.floats(min_value=-0.25, max_value=3.0),
    a0=st.floats(min_value=0.5, max_value=2.0) | st.floats(min_value=-2.0, max_value=-0.5),
    velocity=st.floats(min_value=-1.0, max_value=1.0),
)
def test_jump_closed_form_property(epsilon, a0, velocity):
    b = R(1, 4)
    with mpmath.workdps(40):
        period, error = conservative_period(sympy.Heaviside(U - b), epsilon, a0=a0, velocity=velocity, precision=20)
        exact = jump_period(mpmath.mpf(epsilon), 1, mp(b), mpmath.mpf(a0), mpmath.mpf(1), mpmath.mpf(velocity))
        assert abs(period - exact) <= error
        assert error <= mpmath.mpf(10) ** -18 * exact


def test_precision_does_not_leak():
    global_dps = mpmath.mp.dps
    conservative_period(sympy.Max(0, U) ** R(3, 2), "0.4", a0=1, velocity="0.2", precision=40)
    conservative_period(U**3, "0.4", a0=1, velocity="0.2", precision=40)
    assert mpmath.mp.dps == global_dps


# ----------------------------------------------------------- singular f, walls, callables
def test_repulsive_inverse_square_wall():
    # f = u**-2 for u > 0 (0 below), epsilon = -2/5: V = u**2/2 + (2/5)/u + const, a repulsive wall at u = 0
    # that the orbit never reaches.  Released at rest from 1: E - V = 0.9 - u**2/2 - 0.4/u vanishes at
    # u = 1 and at r = (-1 + sqrt(4.2))/2, and 2 (E - V) = (1 - u)(u - r)(u + s)/u with s = (1 + sqrt(4.2))/2.
    # With u = r + (1 - r) sin(theta)**2, T = 2 int_r^1 sqrt(u/((1 - u)(u - r)(u + s))) du
    # = 4 int_0^{pi/2} sqrt(u/(u + s)) d theta, a smooth integrand.
    expression = sympy.Piecewise((U**-2, U > 0), (0, True))
    with mpmath.workdps(50):
        r = (-1 + mpmath.sqrt(mpmath.mpf("4.2"))) / 2
        s = (1 + mpmath.sqrt(mpmath.mpf("4.2"))) / 2

        def integrand(theta):
            position = r + (1 - r) * mpmath.sin(theta) ** 2
            return mpmath.sqrt(position / (position + s))

        exact = 4 * mpmath.quad(integrand, [0, mpmath.pi / 2])
        period, error = conservative_period(expression, "-0.4", a0=1, precision=30)
        assert_agrees(period, error, exact)


def test_callable_with_breakpoints_matches_expression():
    with mpmath.workdps(30):
        expected, _ = conservative_period(sympy.Max(0, U) ** R(3, 2), "0.4", a0=1, precision=20)
        period, error = conservative_period(
            lambda x: max(x, 0) ** mpmath.mpf(1.5), "0.4", a0=1, precision=10, breakpoints=[0]
        )
        assert abs(period - expected) <= error
        assert error < mpmath.mpf(10) ** -9 * expected


# ------------------------------------------------------------------------ breakpoints
def test_breakpoints_are_found_from_the_expression():
    assert nonlinearity_breakpoints(U**3 + sympy.sin(U)) == ()
    assert nonlinearity_breakpoints(sympy.Max(0, U - R(1, 5)) ** R(3, 2) + sympy.Heaviside(U + 1)) == (-1, R(1, 5))
    assert nonlinearity_breakpoints(sympy.Max(0, sympy.Abs(U) - R(1, 2))) == (R(-1, 2), 0, R(1, 2))
    assert nonlinearity_breakpoints(sympy.Piecewise((U, (U > 1) & (U < 2)), (0, True)) + sympy.sign(3 * U - 1)) == (
        R(1, 3),
        1,
        2,
    )
    assert nonlinearity_breakpoints(sympy.sqrt(1 - U**2)) == (-1, 1)  # branch points of a fractional power
    assert nonlinearity_breakpoints(sympy.Max(0, U) ** 2, breakpoints=["1/2"]) == (0, R(1, 2))
    assert nonlinearity_breakpoints(sympy.Max(0, U - sympy.sqrt(2) / 3)) == (sympy.sqrt(2) / 3,)


# ---------------------------------------------------------------------------- errors
@pytest.mark.parametrize(
    "expression",
    [sympy.sign(sympy.sin(1 / U)), sympy.Heaviside(sympy.sin(U)), sympy.Max(0, U**2 - 1), sympy.floor(U)],
    ids=["sign-sin-1/u", "heaviside-sin", "nonlinear-argument", "floor"],
)
def test_infinitely_many_or_nonlinear_switches_are_refused(expression):
    with pytest.raises(UnsupportedNonlinearityError, match="supported: f analytic between finitely many breakpoints"):
        conservative_period(expression, "0.1", a0=1)


def test_non_integrable_singularity_on_the_orbit_is_refused():
    with pytest.raises(UnsupportedNonlinearityError, match="non-integrable singularity") as caught:
        conservative_period(sympy.Piecewise((U**-2, U > 0), (0, True)), "0.4", a0=1)
    assert "p > -1" in str(caught.value)
    with pytest.raises(UnsupportedNonlinearityError, match="non-integrable singularity"):
        conservative_period(sympy.Max(0, U) ** -2, "0.4", a0=1)


def test_orbit_into_a_region_where_f_is_not_real_is_refused():
    with pytest.raises(UnsupportedNonlinearityError, match="not real for u < 0"):
        conservative_period(U ** R(3, 2), "0.4", a0=1)


def test_escaping_orbits_raise_convergence_error():
    # u_+**2 with epsilon = -0.6: the barrier of V = u**2/2 - 0.2 u**3 on u > 0 has height 0.463 at u = 5/3,
    # below the energy 1/2 of the orbit released from -1 (or launched from 0 with speed 1).
    with pytest.raises(ConvergenceError, match="escapes"):
        conservative_period(sympy.Max(0, U) ** 2, "-0.6", a0=-1)
    with pytest.raises(ConvergenceError, match="escapes"):
        conservative_period(sympy.Max(0, U) ** 2, "-0.6", a0=0, velocity=1)
    with pytest.raises(ConvergenceError, match="escapes"):
        conservative_period(U**2, "-0.6", a0=0, velocity=1)


def test_grazing_orbits_have_no_taylor_series():
    with pytest.raises(ProblemError, match="grazing"):
        frequency_taylor_coefficients(sympy.Max(0, U - 1), 2, a0=1)
    with pytest.raises(ProblemError, match="grazing"):  # turning amplitude sqrt(0.6**2 + 0.8**2) = 1
        frequency_taylor_coefficients(sympy.Max(0, U - 1), 2, a0="0.6", velocity="0.8")


def test_bad_inputs_are_problem_errors():
    with pytest.raises(ProblemError, match="equilibrium"):
        conservative_period(sympy.Max(0, U), "0.3", a0=0)
    with pytest.raises(ProblemError, match="breakpoints"):
        conservative_period(sympy.Max(0, U), "0.3", a0=1, breakpoints=5)
    with pytest.raises(ProblemError):
        conservative_period(sympy.Max(0, U), "0.3", a0=1, breakpoints=["one half"])
    with pytest.raises(ProblemError, match="velocity"):
        conservative_period(sympy.Max(0, U), "0.3", a0=1, velocity="nan")
