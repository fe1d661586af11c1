"""Tests of the exact Duffing reference (lindstedt.references.duffing_exact_frequency, duffing_frequency_taylor).

Equation: u'' + omega0**2 u + epsilon c u**3 = 0.  Expectations come from
textbook values (r_1 = 3/8, r_2 = -21/256 or -15/256), sympy's own series of
the elliptic-integral closed form, the theta-function identities evaluated
independently, and direct numerical integration of the ODE with scipy.
"""

from __future__ import annotations

import math
import subprocess
import sys

import mpmath
import numpy as np
import pytest
import sympy
from scipy.integrate import quad, solve_ivp
from sympy import QQ
from sympy.polys.ring_series import (
    rs_mul,
    rs_pow,
    rs_series_inversion,
    rs_series_reversion,
    rs_subs,
)
from sympy.polys.rings import ring

from lindstedt import OrderError, ProblemError
from lindstedt.references import duffing_exact_frequency, duffing_frequency_taylor


def fitted_slope(abscissae: list, ordinates: list) -> float:
    """Least-squares slope of log|ordinate| against log|abscissa|."""
    logs_x = np.array([float(mpmath.log(abs(value))) for value in abscissae])
    logs_y = np.array([float(mpmath.log(abs(value))) for value in ordinates])
    return float(np.polyfit(logs_x, logs_y, 1)[0])


def integrate_duffing(epsilon: float, coefficient: float, omega0: float, peak: float) -> tuple[float, float]:
    """Period and first-harmonic amplitude from a DOP853 integration of the ODE."""

    def right_hand_side(_time, state):
        return [state[1], -(omega0**2) * state[0] - epsilon * coefficient * state[0] ** 3]

    def lowest_point(_time, state):  # u' goes from negative to positive at the other turning point
        return state[1]

    lowest_point.terminal = True
    lowest_point.direction = 1
    solution = solve_ivp(
        right_hand_side,
        (0.0, 1000.0),
        [peak, 0.0],
        method="DOP853",
        rtol=1e-13,
        atol=1e-15,
        events=lowest_point,
        dense_output=True,
    )
    half_period = float(solution.t_events[0][0])
    period = 2 * half_period
    angular_frequency = 2 * np.pi / period
    # u(T - t) = u(t), so the cos coefficient (2/T) int_0^T u cos(omega t) dt is twice the half-period integral.
    integral, _ = quad(
        lambda t: solution.sol(t)[0] * np.cos(angular_frequency * t),
        0.0,
        half_period,
        epsabs=1e-14,
        epsrel=1e-13,
        limit=200,
    )
    return period, 4 * integral / period


# ---------------------------------------------------------------- Taylor series
def test_textbook_first_and_second_coefficients():
    initial = duffing_frequency_taylor(2, "initial")
    harmonic = duffing_frequency_taylor(2, "harmonic")
    assert initial == [1, sympy.Rational(3, 8), sympy.Rational(-21, 256)]
    assert harmonic == [1, sympy.Rational(3, 8), sympy.Rational(-15, 256)]
    assert all(isinstance(value, sympy.Rational) for value in initial + harmonic)


def test_initial_series_matches_sympy_series_of_elliptic_closed_form():
    x = sympy.Symbol("x")
    closed_form = sympy.sqrt(1 + x) * sympy.pi / (2 * sympy.elliptic_k(x / (2 * (1 + x))))
    expansion = sympy.series(closed_form, x, 0, 7).removeO()
    expected = [sympy.expand(expansion).coeff(x, power) for power in range(7)]
    assert duffing_frequency_taylor(6, "initial") == expected


def theta_function_route(order: int, normalization: str) -> list[sympy.Rational]:
    """omega/omega0 in x (or y) from the theta-function identities, with sympy's own ring_series reversion and substitution.

    2K/pi = theta3**2, m = theta2**4/theta3**4 = 16 q psi**4/theta3**4, x = 2m/(1-2m),
    omega/omega0 = (1-2m)**(-1/2)/theta3**2 and the first-harmonic strength y = x/((1+q)**2 psi**4).
    """
    _, q, strength_variable = ring("q, s", QQ)
    precision = order + 1
    theta3 = 1 + 2 * sum(q ** (n * n) for n in range(1, math.isqrt(order) + 1))
    psi = sum(q ** (n * (n + 1)) for n in range(order + 1) if n * (n + 1) <= order)
    parameter = rs_mul(16 * q, rs_mul(rs_pow(psi, 4, q, precision), rs_pow(theta3, -4, q, precision), q, precision), q, precision)
    strength = rs_mul(2 * parameter, rs_series_inversion(1 - 2 * parameter, q, precision), q, precision)
    frequency = rs_mul(rs_pow(1 - 2 * parameter, sympy.Rational(-1, 2), q, precision), rs_pow(theta3, -2, q, precision), q, precision)
    if normalization == "harmonic":
        strength = rs_mul(strength, rs_pow(rs_mul(1 + q, rs_pow(psi, 2, q, precision), q, precision), -2, q, precision), q, precision)
    nome = rs_series_reversion(strength, q, precision, strength_variable)
    composed = rs_subs(frequency, {q: nome}, strength_variable, precision)
    assert all(monomial[0] == 0 for monomial in composed)
    return [QQ.to_sympy(composed.get((0, power), QQ.zero)) for power in range(order + 1)]


@pytest.mark.parametrize("normalization", ["initial", "harmonic"])
def test_series_match_theta_function_route(normalization):
    # "initial" is computed from 2F1(1/2, 1/2; 1; m) by the reference, so the theta route is independent of it.
    order = 16
    assert duffing_frequency_taylor(order, normalization) == theta_function_route(order, normalization)


def test_series_are_prefixes_of_longer_series():
    for normalization in ("initial", "harmonic"):
        assert duffing_frequency_taylor(15, normalization)[:9] == duffing_frequency_taylor(8, normalization)


@pytest.mark.parametrize("normalization", ["initial", "harmonic"])
def test_order_twenty_from_a_fresh_interpreter_matches_the_theta_route(normalization):
    # computed in a fresh interpreter, so that no series is cached yet; its speed is measured in
    # benchmarks/bench_performance.py, not here (the subprocess timeout only catches a hang: it takes ~1 s)
    script = (
        "from lindstedt.references import duffing_frequency_taylor\n"
        f"print(*duffing_frequency_taylor(20, {normalization!r}), sep='\\n')\n"
    )
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120, check=True)
    fresh = [sympy.Rational(line) for line in result.stdout.split()]
    assert fresh == theta_function_route(20, normalization)


@pytest.mark.parametrize("normalization", ["initial", "harmonic"])
@pytest.mark.parametrize("order", [1, 2, 3, 5, 8, 12])
@pytest.mark.parametrize("sign", [1, -1])
def test_taylor_polynomial_error_has_slope_order_plus_one(order, normalization, sign):
    amplitude, omega0, coefficient = mpmath.mpf("0.7"), mpmath.mpf("1.3"), mpmath.mpf(2)
    rationals = duffing_frequency_taylor(order, normalization)
    strengths = [mpmath.mpf("0.01"), mpmath.mpf("0.02"), mpmath.mpf("0.04")]
    epsilons, errors = [], []
    with mpmath.workdps(50):
        for strength in strengths:
            x = sign * strength
            epsilon = x * omega0**2 / (coefficient * amplitude**2)
            exact = duffing_exact_frequency(
                epsilon,
                amplitude=amplitude,
                omega0=omega0,
                coefficient=coefficient,
                normalization=normalization,
                precision=50,
            )
            polynomial = omega0 * mpmath.fsum(
                mpmath.mpf(int(r.p)) / int(r.q) * x**power for power, r in enumerate(rationals)
            )
            epsilons.append(epsilon)
            errors.append(exact - polynomial)
    slope = fitted_slope(epsilons, errors)
    assert abs(slope - (order + 1)) <= 0.3


# ----------------------------------------------------------- exact frequencies
@pytest.mark.parametrize(
    "epsilon, coefficient, omega0, peak",
    [
        (0.3, 1.0, 1.0, 1.0),
        (0.8, 2.0, 1.3, 0.7),
        (-0.3, 1.0, 1.0, 1.0),
        (-1.5, 1.0, 1.2, 0.8),
        (-1.0, 1.0, 1.0, 0.99),  # near the separatrix: first harmonic 1.14 exceeds the hilltop 1
    ],
)
def test_exact_frequencies_match_direct_integration(epsilon, coefficient, omega0, peak):
    period, first_harmonic = integrate_duffing(epsilon, coefficient, omega0, peak)
    numerical_frequency = 2 * np.pi / period
    initial = duffing_exact_frequency(
        epsilon, amplitude=peak, omega0=omega0, coefficient=coefficient, normalization="initial"
    )
    harmonic = duffing_exact_frequency(
        epsilon, amplitude=first_harmonic, omega0=omega0, coefficient=coefficient, normalization="harmonic"
    )
    assert float(initial) == pytest.approx(numerical_frequency, rel=1e-11, abs=0)
    assert float(harmonic) == pytest.approx(numerical_frequency, rel=1e-10, abs=0)


def test_zero_epsilon_and_amplitude_sign():
    assert duffing_exact_frequency(0, amplitude=2, omega0=3) == 3
    for normalization in ("initial", "harmonic"):
        positive = duffing_exact_frequency("0.4", amplitude="0.9", normalization=normalization)
        negative = duffing_exact_frequency("0.4", amplitude="-0.9", normalization=normalization)
        assert positive == negative


def test_epsilon_and_coefficient_enter_as_a_product():
    first = duffing_exact_frequency("0.6", amplitude=1, coefficient=1)
    second = duffing_exact_frequency("0.3", amplitude=1, coefficient=2)
    assert abs(first - second) <= mpmath.mpf(10) ** -29


@pytest.mark.parametrize("normalization", ["initial", "harmonic"])
@pytest.mark.parametrize("epsilon", ["0.37", "-0.45"])
def test_higher_precision_agrees_and_does_not_leak(normalization, epsilon):
    global_dps = mpmath.mp.dps
    low = duffing_exact_frequency(epsilon, amplitude="0.9", omega0="1.1", normalization=normalization, precision=30)
    high = duffing_exact_frequency(epsilon, amplitude="0.9", omega0="1.1", normalization=normalization, precision=50)
    assert mpmath.mp.dps == global_dps
    with mpmath.workdps(60):
        assert abs(high - low) <= mpmath.mpf(10) ** -28 * abs(high)
        assert abs(high - low) > 0  # the two really are computed at different precisions


@pytest.mark.parametrize("harmonic_amplitude", ["1.27", "1.2732"])
def test_softening_harmonic_amplitude_close_to_square_wave_limit(harmonic_amplitude):
    # Supremum 4/pi = 1.27324: the turning point is within ~1e-18 (resp. ~1e-70) of the hilltop.
    low = duffing_exact_frequency(-1, amplitude=harmonic_amplitude, normalization="harmonic", precision=30)
    high = duffing_exact_frequency(-1, amplitude=harmonic_amplitude, normalization="harmonic", precision=50)
    with mpmath.workdps(60):
        assert abs(high - low) <= mpmath.mpf(10) ** -28 * high
    near_limit = duffing_exact_frequency(-1, amplitude="1.2", normalization="harmonic")
    assert 0 < low < near_limit  # the period diverges towards the separatrix


def test_initial_amplitude_extremely_close_to_separatrix_keeps_precision():
    with mpmath.workdps(80):
        epsilon = -(1 - mpmath.mpf(10) ** -40)
        low = duffing_exact_frequency(epsilon, amplitude=1, precision=30)
        high = duffing_exact_frequency(epsilon, amplitude=1, precision=50)
        assert abs(high - low) <= mpmath.mpf(10) ** -28 * high


def test_softening_close_to_separatrix_still_periodic():
    # x = -(1 - 1e-8): period ~ (4/Omega) K(m) grows logarithmically; compare with the
    # m -> -infinity asymptotics K(m) ~ log(4 sqrt(-m))/sqrt(-m) to leading order.
    with mpmath.workdps(40):
        x = -(1 - mpmath.mpf(10) ** -8)
        frequency = duffing_exact_frequency(x, amplitude=1, precision=30)
        parameter = x / (2 * (1 + x))
        asymptotic_period = 4 * mpmath.log(4 * mpmath.sqrt(-parameter)) / mpmath.sqrt(-parameter) / mpmath.sqrt(1 + x)
        assert abs(2 * mpmath.pi / frequency / asymptotic_period - 1) < 1e-6


def test_errors_name_the_problem():
    with pytest.raises(ProblemError, match="hilltop"):
        duffing_exact_frequency(-1, amplitude=1)  # x = -1: release on the unstable equilibrium
    with pytest.raises(ProblemError, match="hilltop"):
        duffing_exact_frequency(-2, amplitude=1)
    with pytest.raises(ProblemError, match="supremum"):
        duffing_exact_frequency(-1, amplitude="1.3", normalization="harmonic")  # > 4/pi
    with pytest.raises(ProblemError, match="normalization"):
        duffing_exact_frequency(0.1, amplitude=1, normalization="peak")
    with pytest.raises(ProblemError, match="omega0"):
        duffing_exact_frequency(0.1, amplitude=1, omega0=0)
    with pytest.raises(ProblemError):
        duffing_exact_frequency(0.1j, amplitude=1)
    with pytest.raises(OrderError):
        duffing_frequency_taylor(-1)
    with pytest.raises(OrderError):
        duffing_frequency_taylor(2.5)
    with pytest.raises(ProblemError, match="normalization"):
        duffing_frequency_taylor(3, "amplitude")
