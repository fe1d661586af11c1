"""Tests of the closed-form Fourier kernel (lindstedt.algebra): Fourier coefficients of (cos s - kappa)_+ and H(cos s - kappa).

Every expectation comes from an independent computation: mpmath quadrature of the
defining integrals, sympy's own ``integrate``/``summation``, or a straightforward
closed form evaluated with 120+ digits in the test itself.
"""

from __future__ import annotations

from fractions import Fraction

import mpmath
import numpy as np
import pytest
import sympy

from lindstedt.algebra import (
    SeriesEstimate,
    contact_angle,
    contact_angle_float,
    contact_ramp_coefficient,
    contact_ramp_coefficient_mp,
    contact_ramp_coefficients_float,
    contact_step_coefficient,
    contact_step_coefficient_mp,
    contact_step_coefficients_float,
    ramp_times_cosine_coefficient,
    series_sum,
    step_times_cosine_coefficient,
    sum_cosine_series_at,
)
from lindstedt import ConvergenceError, ProblemError

s = sympy.Symbol("s", real=True)
KAPPA = sympy.Symbol("kappa", real=True)


# ---------------------------------------------------------------------------
# independent references
# ---------------------------------------------------------------------------


def quadrature_coefficient(k: int, kappa: mpmath.mpf, *, ramp: bool, extra_cosine: int = 0) -> mpmath.mpf:
    """(2/pi) int_0^pi f(s) cos(extra s) cos(k s) ds (1/pi for k = 0) by mpmath.quad, at the working precision."""
    angle = mpmath.acos(kappa)

    def integrand(t):
        base = (mpmath.cos(t) - kappa) if ramp else mpmath.mpf(1)
        return base * mpmath.cos(extra_cosine * t) * mpmath.cos(k * t)

    weight = 1 / mpmath.pi if k == 0 else 2 / mpmath.pi
    return weight * mpmath.quad(integrand, [0, angle])


def reference_ramp(k: int, kappa_value: float, digits: int = 120) -> mpmath.mpf:
    """Closed form (derived independently in the test) at ``digits`` digits for |kappa| < 1."""
    with mpmath.workdps(digits):
        kappa = mpmath.mpf(kappa_value)
        angle = mpmath.acos(kappa)
        if k == 0:
            return (mpmath.sin(angle) - kappa * angle) / mpmath.pi
        if k == 1:
            return (angle - mpmath.sin(2 * angle) / 2) / mpmath.pi
        return (
            mpmath.sin((k + 1) * angle) / (k + 1)
            + mpmath.sin((k - 1) * angle) / (k - 1)
            - 2 * kappa * mpmath.sin(k * angle) / k
        ) / mpmath.pi


def reference_step(k: int, kappa_value: float, digits: int = 120) -> mpmath.mpf:
    with mpmath.workdps(digits):
        angle = mpmath.acos(mpmath.mpf(kappa_value))
        return angle / mpmath.pi if k == 0 else 2 * mpmath.sin(k * angle) / (mpmath.pi * k)


def ramp_envelope(k: int, kappa_value: float) -> float:
    """Natural magnitude of c_k: (2/(pi k)) min(k b^3/3, (sin b + 1/k)/k), b = acos|kappa|; |c_k| itself for k <= 1."""
    with mpmath.workdps(40):
        if k <= 1:
            return float(abs(reference_ramp(k, kappa_value)))
        angle = mpmath.acos(abs(mpmath.mpf(kappa_value)))
        return float(2 / (mpmath.pi * k) * min(k * angle**3 / 3, (mpmath.sin(angle) + mpmath.mpf(1) / k) / k))


# ---------------------------------------------------------------------------
# exact symbolic path
# ---------------------------------------------------------------------------

RATIONAL_KAPPAS = [sympy.Integer(0), sympy.Rational(1, 3), sympy.Rational(-1, 2), sympy.Rational(9, 10), sympy.Rational(-7, 10)]


@pytest.mark.parametrize("kappa", RATIONAL_KAPPAS)
def test_symbolic_coefficients_match_quadrature(kappa: sympy.Rational) -> None:
    with mpmath.workdps(30):
        kappa_mp = mpmath.mpf(kappa.p) / kappa.q
        for k in range(7):
            ramp = sympy.N(contact_ramp_coefficient(k, kappa), 30)
            step = sympy.N(contact_step_coefficient(k, kappa), 30)
            assert abs(mpmath.mpf(ramp) - quadrature_coefficient(k, kappa_mp, ramp=True)) < 1e-25
            assert abs(mpmath.mpf(step) - quadrature_coefficient(k, kappa_mp, ramp=False)) < 1e-25


def test_symbolic_coefficients_at_kappa_zero_equal_sympy_integrals() -> None:
    for k in range(9):
        weight = 1 / sympy.pi if k == 0 else 2 / sympy.pi
        expected_ramp = weight * sympy.integrate(sympy.cos(s) * sympy.cos(k * s), (s, 0, sympy.pi / 2))
        expected_step = weight * sympy.integrate(sympy.cos(k * s), (s, 0, sympy.pi / 2))
        assert sympy.simplify(contact_ramp_coefficient(k, 0) - expected_ramp) == 0
        assert sympy.simplify(contact_step_coefficient(k, 0) - expected_step) == 0


def test_symbolic_kappa_stays_symbolic_and_substitutes_correctly() -> None:
    interior = contact_ramp_coefficient(3, KAPPA, assume_interior=True)
    assert interior.free_symbols == {KAPPA}
    assert interior.has(sympy.acos(KAPPA))
    assert not interior.has(sympy.Piecewise)
    guarded = contact_ramp_coefficient(3, KAPPA)
    assert isinstance(guarded, sympy.Piecewise)
    for value in (sympy.Rational(1, 3), sympy.Rational(-2, 5)):
        assert sympy.simplify(interior.subs(KAPPA, value) - contact_ramp_coefficient(3, value)) == 0
        assert sympy.simplify(guarded.subs(KAPPA, value) - contact_ramp_coefficient(3, value)) == 0
    assert guarded.subs(KAPPA, 2) == 0
    assert contact_ramp_coefficient(0, KAPPA).subs(KAPPA, -3) == 3
    bounded = sympy.Symbol("q", positive=True)  # range unknown above: still guarded
    assert isinstance(contact_step_coefficient(2, bounded), sympy.Piecewise)


@pytest.mark.parametrize("kappa", [1, 2, sympy.Rational(7, 2), 1.0])
def test_kappa_at_or_above_one_gives_zero(kappa: object) -> None:
    for k in range(4):
        assert contact_ramp_coefficient(k, kappa) == 0
        assert contact_step_coefficient(k, kappa) == 0
    assert contact_angle(kappa) == 0


@pytest.mark.parametrize("kappa", [-1, -2, sympy.Rational(-5, 3)])
def test_kappa_at_or_below_minus_one_gives_the_linear_function(kappa: object) -> None:
    value = sympy.sympify(kappa)
    assert contact_ramp_coefficient(0, kappa) == -value
    assert contact_ramp_coefficient(1, kappa) == 1
    assert all(contact_ramp_coefficient(k, kappa) == 0 for k in range(2, 6))
    assert contact_step_coefficient(0, kappa) == 1
    assert all(contact_step_coefficient(k, kappa) == 0 for k in range(1, 6))
    assert contact_angle(kappa) == sympy.pi


def test_kappa_minus_one_is_the_limit_of_the_interior_formula() -> None:
    near = sympy.Rational(-1) + sympy.Rational(1, 10**30)
    for k in range(4):
        assert abs(sympy.N(contact_ramp_coefficient(k, near) - contact_ramp_coefficient(k, -1), 40)) < 1e-20


@pytest.mark.parametrize("m", [0, 1, 2, 3])
def test_products_with_cosines_match_quadrature(m: int) -> None:
    kappa = sympy.Rational(1, 3)
    with mpmath.workdps(30):
        kappa_mp = mpmath.mpf(1) / 3
        for k in range(6):
            ramp = mpmath.mpf(sympy.N(ramp_times_cosine_coefficient(k, kappa, m), 30))
            step = mpmath.mpf(sympy.N(step_times_cosine_coefficient(k, kappa, m), 30))
            assert abs(ramp - quadrature_coefficient(k, kappa_mp, ramp=True, extra_cosine=m)) < 1e-25
            assert abs(step - quadrature_coefficient(k, kappa_mp, ramp=False, extra_cosine=m)) < 1e-25


@pytest.mark.parametrize("bad", [-1, 1.5, True, "2", sympy.Symbol("k")])
def test_bad_harmonic_index_raises(bad: object) -> None:
    with pytest.raises(ProblemError):
        contact_ramp_coefficient(bad, 0)


def test_complex_kappa_raises() -> None:
    with pytest.raises(ProblemError, match="not real"):
        contact_ramp_coefficient(1, sympy.I)


# ---------------------------------------------------------------------------
# float path
# ---------------------------------------------------------------------------

GRAZING = 1 - 1e-12
HARMONICS = np.array([0, 1, 2, 3, 4, 5, 7, 10, 100, 1000, 12345, 10**5, 999_999, 10**6])


def _special_kappas() -> np.ndarray:
    rng = np.random.default_rng(20240611)
    return np.concatenate(
        [
            [GRAZING, -GRAZING, 0.0, 0.5, -0.5, np.nextafter(0.5, 0.0), 1 / 3, 1 - 2.0**-52, -1 + 2.0**-53, 1e-300],
            rng.uniform(-1, 1, 12),
            1 - 10 ** rng.uniform(-15, -1, 8),
            -1 + 10 ** rng.uniform(-15, -1, 8),
        ]
    )


def test_ramp_float_at_grazing_keeps_twelve_digits() -> None:
    for kappa in (GRAZING, -GRAZING):
        values = contact_ramp_coefficients_float(kappa, HARMONICS)
        for k, value in zip(HARMONICS, values):
            expected = reference_ramp(int(k), kappa)
            assert expected != 0
            assert abs(value - expected) <= 1e-12 * abs(expected), (kappa, k)


def test_ramp_float_matches_high_precision_everywhere() -> None:
    kappas = _special_kappas()
    table = contact_ramp_coefficients_float(kappas[:, None], HARMONICS[None, :])
    assert table.shape == (kappas.size, HARMONICS.size)
    for row, kappa in enumerate(kappas):
        for column, k in enumerate(HARMONICS):
            expected = reference_ramp(int(k), kappa)
            scale = ramp_envelope(int(k), kappa)
            error = abs(table[row, column] - expected)
            assert error <= 1e-13 * scale, (kappa, k, error / scale)
            if abs(expected) > 0.1 * scale:
                assert error <= 1e-13 * abs(expected), (kappa, k)


def test_step_float_matches_high_precision_everywhere() -> None:
    kappas = _special_kappas()
    table = contact_step_coefficients_float(kappas[:, None], HARMONICS[None, :])
    for row, kappa in enumerate(kappas):
        for column, k in enumerate(HARMONICS):
            expected = reference_step(int(k), kappa)
            scale = 2 / (np.pi * max(int(k), 1))
            assert abs(table[row, column] - expected) <= 1e-14 * scale, (kappa, k)
    grazing = contact_step_coefficients_float(GRAZING, HARMONICS)
    for k, value in zip(HARMONICS, grazing):
        expected = reference_step(int(k), GRAZING)
        assert abs(value - expected) <= 1e-13 * abs(expected)


def test_float_angle_is_accurate_near_both_ends() -> None:
    kappas = np.array([GRAZING, -GRAZING, 0.0, 0.3, -0.9, 1.0, -1.0, 1.5, -7.0])
    angles = contact_angle_float(kappas)
    with mpmath.workdps(40):
        for kappa, angle in zip(kappas, angles):
            expected = mpmath.acos(mpmath.mpf(min(max(kappa, -1.0), 1.0)))
            assert abs(angle - expected) <= 2.3e-16 * abs(expected)


def test_float_path_routes_outside_the_unit_interval() -> None:
    kappas = np.array([1.0, 1.5, np.inf, -1.0, -2.5])
    ramp = contact_ramp_coefficients_float(kappas[:, None], np.arange(4)[None, :])
    np.testing.assert_array_equal(ramp[:3], 0.0)
    np.testing.assert_array_equal(ramp[3], [1.0, 1.0, 0.0, 0.0])
    np.testing.assert_array_equal(ramp[4], [2.5, 1.0, 0.0, 0.0])
    step = contact_step_coefficients_float(kappas[:, None], np.arange(3)[None, :])
    np.testing.assert_array_equal(step[:3], 0.0)
    np.testing.assert_array_equal(step[3:], [[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    assert not np.any(np.isnan(ramp)) and not np.any(np.isnan(step))


def test_float_broadcasting_matches_scalar_calls() -> None:
    kappas = np.array([-0.3, 0.2, 0.999])
    harmonics = np.array([0, 1, 6, 50])
    table = contact_ramp_coefficients_float(kappas[:, None], harmonics[None, :])
    for row, kappa in enumerate(kappas):
        for column, k in enumerate(harmonics):
            assert table[row, column] == contact_ramp_coefficients_float(kappa, k)
    assert contact_ramp_coefficients_float(kappas, 3).shape == (3,)
    assert contact_step_coefficients_float(0.1, harmonics).shape == (4,)


@pytest.mark.parametrize(
    ("kappa", "harmonics"),
    [(np.nan, 2), (0.1, -1), (0.1, 1.5), (0.1, np.array([True])), (0.1, "3"), (0.1, 2.0**60)],
)
def test_float_path_rejects_bad_input(kappa: object, harmonics: object) -> None:
    with pytest.raises(ProblemError):
        contact_ramp_coefficients_float(kappa, harmonics)


def test_float_symbolic_agreement_on_rationals() -> None:
    for kappa in RATIONAL_KAPPAS:
        values = contact_ramp_coefficients_float(float(kappa), np.arange(8))
        steps = contact_step_coefficients_float(float(kappa), np.arange(8))
        for k in range(8):
            assert abs(values[k] - float(sympy.N(contact_ramp_coefficient(k, kappa), 20))) <= 1e-15
            assert abs(steps[k] - float(sympy.N(contact_step_coefficient(k, kappa), 20))) <= 1e-15


# ---------------------------------------------------------------------------
# mpmath path
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("k", [0, 1, 2, 5, 1000])
def test_mp_path_matches_symbolic_at_fifty_digits(k: int) -> None:
    for kappa in (sympy.Rational(1, 3), sympy.Rational(-7, 10)):
        with mpmath.workdps(60):
            ramp = mpmath.mpf(sympy.N(contact_ramp_coefficient(k, kappa), 70))
            step = mpmath.mpf(sympy.N(contact_step_coefficient(k, kappa), 70))
            got_ramp = contact_ramp_coefficient_mp(k, kappa, precision=50)
            got_step = contact_step_coefficient_mp(k, Fraction(kappa.p, kappa.q), precision=50)
            assert abs(got_ramp - ramp) <= mpmath.mpf(10) ** -49 * abs(ramp)
            assert abs(got_step - step) <= mpmath.mpf(10) ** -49 * abs(step)


def test_mp_path_near_grazing_with_exact_rational() -> None:
    kappa = Fraction(1) - Fraction(1, 10**30)
    for k in (0, 1, 2, 7, 10**6):
        got = contact_ramp_coefficient_mp(k, kappa, precision=40)
        with mpmath.workdps(300):
            exact_kappa = mpmath.mpf(kappa.numerator) / kappa.denominator
            angle = mpmath.acos(exact_kappa)
            if k == 0:
                expected = (mpmath.sin(angle) - exact_kappa * angle) / mpmath.pi
            elif k == 1:
                expected = (angle - mpmath.sin(2 * angle) / 2) / mpmath.pi
            else:
                expected = (
                    mpmath.sin((k + 1) * angle) / (k + 1) + mpmath.sin((k - 1) * angle) / (k - 1)
                    - 2 * exact_kappa * mpmath.sin(k * angle) / k
                ) / mpmath.pi
            assert abs(got - expected) <= mpmath.mpf(10) ** -39 * abs(expected), k
    negative = contact_ramp_coefficient_mp(3, -kappa, precision=40)
    assert abs(negative + contact_ramp_coefficient_mp(3, kappa, precision=40)) <= mpmath.mpf(10) ** -39 * abs(negative)


def test_mp_path_float_input_uses_exact_binary_value() -> None:
    got = contact_ramp_coefficient_mp(4, GRAZING, precision=30)
    expected = reference_ramp(4, GRAZING, digits=150)
    with mpmath.workdps(40):
        assert abs(got - expected) <= mpmath.mpf(10) ** -29 * abs(expected)


def test_mp_path_outside_unit_interval_and_bad_input() -> None:
    assert contact_ramp_coefficient_mp(0, 1, precision=20) == 0
    assert contact_ramp_coefficient_mp(0, -2, precision=20) == 2
    assert contact_ramp_coefficient_mp(1, "-1", precision=20) == 1
    assert contact_step_coefficient_mp(0, -1.5, precision=20) == 1
    assert contact_step_coefficient_mp(3, 4, precision=20) == 0
    with pytest.raises(ProblemError):
        contact_ramp_coefficient_mp(1, "nan", precision=20)
    with pytest.raises(ProblemError):
        contact_ramp_coefficient_mp(1, 0.5, precision=0)
    with pytest.raises(ProblemError):
        contact_ramp_coefficient_mp(1, KAPPA, precision=20)


# ---------------------------------------------------------------------------
# series acceleration
# ---------------------------------------------------------------------------


def _closed_form_ramp_mp(kappa: mpmath.mpf):
    angle = mpmath.acos(kappa)
    sine = mpmath.sin(angle)

    def coefficient(k: int) -> mpmath.mpf:
        if k == 0:
            return (sine - kappa * angle) / mpmath.pi
        if k == 1:
            return (angle - kappa * sine) / mpmath.pi
        return 2 * (kappa * mpmath.sin(k * angle) - k * sine * mpmath.cos(k * angle)) / (mpmath.pi * k * (k * k - 1))

    return coefficient


def test_series_sum_of_squared_odd_denominators_matches_sympy_summation() -> None:
    # sympy.summation returns nan for this sum directly; split it by partial fractions,
    # 1/(4k^2-1)^2 = [1/(2k-1)^2 + 1/(2k+1)^2 + 1/(2k+1) - 1/(2k-1)] / 4, and let sympy sum the parts.
    k = sympy.Symbol("k", integer=True, positive=True)
    n = sympy.Symbol("n", integer=True, positive=True)
    squares = sympy.summation(1 / (2 * k - 1) ** 2 + 1 / (2 * k + 1) ** 2, (k, 1, sympy.oo))
    telescoping = sympy.limit(sympy.summation(1 / (2 * k + 1) - 1 / (2 * k - 1), (k, 1, n)), n, sympy.oo)
    exact = (squares + telescoping) / 4
    assert sympy.simplify(sympy.apart(1 / (4 * k**2 - 1) ** 2, k) - (
        1 / (2 * k - 1) ** 2 + 1 / (2 * k + 1) ** 2 + 1 / (2 * k + 1) - 1 / (2 * k - 1)) / 4) == 0
    estimate = series_sum(lambda n: mpmath.mpf(1) / (4 * n * n - 1) ** 2, start=1, precision=30)
    assert isinstance(estimate, SeriesEstimate)
    value, error = estimate
    with mpmath.workdps(40):
        truth = mpmath.mpf(sympy.N(exact, 45))
        assert abs(value - truth) <= max(error, mpmath.mpf(10) ** -29)
        assert error <= mpmath.mpf(10) ** -15
        assert abs(value - truth) <= mpmath.mpf(10) ** -25


def test_series_sum_of_inverse_cubes_matches_zeta() -> None:
    value, error = series_sum(lambda n: mpmath.mpf(1) / n**3, start=1, precision=25)
    with mpmath.workdps(30):
        assert abs(value - mpmath.zeta(3)) <= max(error, mpmath.mpf(10) ** -24)
        assert abs(value - mpmath.zeta(3)) <= mpmath.mpf(10) ** -20


@pytest.mark.parametrize(
    ("kappa", "point"),
    [("1/3", "0.7"), ("0.9", "2"), ("-0.3", "1.0"), ("0.9", "0")],
)
def test_cosine_series_of_ramp_coefficients_reproduces_the_ramp(kappa: str, point: str) -> None:
    with mpmath.workdps(40):
        kappa_mp = mpmath.mpf(Fraction(kappa).numerator) / Fraction(kappa).denominator
        point_mp = mpmath.mpf(point)
        coefficient = _closed_form_ramp_mp(kappa_mp)
        expected = max(mpmath.cos(point_mp) - kappa_mp, 0)
    estimate = sum_cosine_series_at(coefficient, point_mp, precision=20)
    with mpmath.workdps(40):
        actual_error = abs(estimate.value - expected)
        assert actual_error <= max(estimate.error_estimate, mpmath.mpf(10) ** -19)
        assert actual_error <= mpmath.mpf(10) ** -15


def test_cosine_series_of_absolute_cosine_with_vanishing_odd_terms() -> None:
    # |cos s| = 2/pi - (4/pi) sum_k (-1)^k cos(2 k s)/(4k^2 - 1) (a textbook series).
    def coefficient(n: int) -> mpmath.mpf:
        if n == 0:
            return 2 / mpmath.pi
        if n % 2:
            return mpmath.mpf(0)
        k = n // 2
        return -4 * (-1) ** k / (mpmath.pi * (4 * k * k - 1))

    estimate = sum_cosine_series_at(coefficient, "0.3", precision=20)
    with mpmath.workdps(30):
        assert abs(estimate.value - abs(mpmath.cos(mpmath.mpf("0.3")))) <= mpmath.mpf(10) ** -15


def test_exact_period_three_pattern_needs_blocks() -> None:
    kappa = mpmath.mpf(-0.5)  # beta = 2 pi / 3: c_k cos(0) has an exact period-3 pattern
    with mpmath.workdps(40):
        coefficient = _closed_form_ramp_mp(kappa)
    value, error = sum_cosine_series_at(coefficient, 0, precision=20, block_size=3)
    with mpmath.workdps(30):
        assert abs(value - mpmath.mpf("1.5")) <= max(error, mpmath.mpf(10) ** -19)
        assert abs(value - mpmath.mpf("1.5")) <= mpmath.mpf(10) ** -15


@pytest.mark.slow
def test_kink_point_is_reported_as_not_converged() -> None:
    kappa = mpmath.mpf(1) / 3
    with mpmath.workdps(40):
        coefficient = _closed_form_ramp_mp(kappa)
        kink = mpmath.acos(kappa)
    with pytest.raises(ConvergenceError, match="did not converge"):
        sum_cosine_series_at(coefficient, kink, precision=20, max_terms=300)


def test_divergent_series_raises_convergence_error() -> None:
    with pytest.raises(ConvergenceError):
        series_sum(lambda n: mpmath.mpf((-1) ** (n // 7)) * n, start=1, precision=10, max_terms=200)


@pytest.mark.parametrize(
    "kwargs",
    [{"precision": 3}, {"methods": ("euler",)}, {"methods": ()}, {"block_size": 0}, {"start": -1}, {"max_terms": 10}],
)
def test_series_sum_rejects_bad_options(kwargs: dict) -> None:
    with pytest.raises(ProblemError):
        series_sum(lambda n: mpmath.mpf(1) / (n + 1) ** 2, **kwargs)


def test_finite_cosine_series_terminates() -> None:
    # cos(s)^2 = 1/2 + cos(2 s)/2: all further coefficients vanish identically
    coefficients = {0: mpmath.mpf(1) / 2, 2: mpmath.mpf(1) / 2}
    value, error = sum_cosine_series_at(lambda k: coefficients.get(k, 0), "0.3", precision=20)
    with mpmath.workdps(30):
        assert abs(value - mpmath.cos(mpmath.mpf("0.3")) ** 2) <= mpmath.mpf(10) ** -19
        assert error <= mpmath.mpf(10) ** -15


def test_geometric_series() -> None:
    value, error = series_sum(lambda k: mpmath.mpf(-2) ** -k, precision=25)
    with mpmath.workdps(30):
        assert abs(value - mpmath.mpf(2) / 3) <= max(error, mpmath.mpf(10) ** -24)
        assert abs(value - mpmath.mpf(2) / 3) <= mpmath.mpf(10) ** -22


def _clausen_four(theta: mpmath.mpf) -> mpmath.mpf:
    # sum_{k >= 1} cos(k theta) / k^4 for 0 <= theta <= 2 pi (Bernoulli polynomial B_4)
    return mpmath.pi**4 / 90 - mpmath.pi**2 * theta**2 / 12 + mpmath.pi * theta**3 / 12 - theta**4 / 48


@pytest.mark.parametrize(("theta", "max_terms"), [(1, 200), (2, 300)])
def test_error_estimate_bounds_the_error_when_max_terms_is_reached(theta: int, max_terms: int) -> None:
    # A monotone plus an oscillating k^-4 tail (like the omega2 series of the benchmark):
    # nsum's stopping rule is not met, its best values scatter, and the estimate must
    # still bound the actual error (a driver comparing two runs claimed 1.1e-10 for 1.3e-10).
    with mpmath.workdps(50):
        exact = _clausen_four(mpmath.mpf(0)) + _clausen_four(mpmath.mpf(theta))

    def term(k: int) -> mpmath.mpf:
        return (1 + mpmath.cos(k * theta)) / mpmath.mpf(k) ** 4

    estimate = series_sum(term, start=1, precision=20, max_terms=max_terms, tolerance=1e-6)
    assert estimate.method.endswith("max_terms reached")
    with mpmath.workdps(50):
        actual_error = abs(estimate.value - exact)
    assert actual_error <= estimate.error_estimate <= mpmath.mpf(10) ** -7


def test_vanishing_odd_terms_do_not_stop_the_summation() -> None:
    # kappa = 0: c_k vanishes for odd k >= 3, so the 10th term is 0; summing stops there
    # unless vanishing terms are skipped (a 10-term partial sum is off by 4e-4).
    def coefficient(k: int) -> mpmath.mpf:
        return contact_ramp_coefficient_mp(k, 0, precision=40)

    estimate = sum_cosine_series_at(coefficient, "0.5", precision=20)
    with mpmath.workdps(40):
        actual_error = abs(estimate.value - mpmath.cos(mpmath.mpf("0.5")))
    assert estimate.terms_used > 100
    assert actual_error <= estimate.error_estimate <= mpmath.mpf(10) ** -15


def test_working_precision_is_set_inside_and_does_not_leak() -> None:
    seen = []

    def term(k: int) -> mpmath.mpf:
        assert isinstance(k, int)
        seen.append(mpmath.mp.dps)
        return mpmath.mpf(1) / k**2

    before = mpmath.mp.dps
    value, error = series_sum(term, start=1, precision=40)
    assert mpmath.mp.dps == before
    assert min(seen) >= 40
    with mpmath.workdps(60):
        assert abs(value - mpmath.pi**2 / 6) <= max(error, mpmath.mpf(10) ** -39)
        assert abs(value - mpmath.pi**2 / 6) <= mpmath.mpf(10) ** -35
