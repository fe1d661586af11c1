"""Exact cosine-polynomial algebra: products, powers, derivatives and the periodic solve."""

import math

import numpy as np
import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st
from sympy import QQ, Rational

from lindstedt import CosineSeries, solve_harmonic_oscillator
from lindstedt.algebra import SecularTermError

s = sympy.Symbol("s", real=True)

fractions = st.fractions(min_value=-5, max_value=5, max_denominator=12)
series_strategy = st.dictionaries(st.integers(0, 6), fractions, max_size=5).map(
    lambda d: CosineSeries(QQ, {n: QQ(v.numerator, v.denominator) for n, v in d.items()})
)


def as_expr(series):
    return series.to_expr(s)


@settings(max_examples=40, deadline=None)
@given(series_strategy, series_strategy)
def test_product_matches_symbolic_product(left, right):
    product = left * right
    difference = sympy.expand(sympy.expand_trig(as_expr(product) - as_expr(left) * as_expr(right)))
    assert sympy.simplify(difference.rewrite(sympy.exp)) == 0


@settings(max_examples=60, deadline=None)
@given(series_strategy, series_strategy, series_strategy)
def test_ring_laws(a, b, c):
    assert a * b == b * a
    assert (a * b) * c == a * (b * c)
    assert a * (b + c) == a * b + a * c
    assert (a - a).is_zero()


@settings(max_examples=60, deadline=None)
@given(series_strategy, series_strategy, st.integers(0, 8))
def test_product_coefficient_is_the_coefficient_of_the_product(a, b, harmonic):
    assert a.product_coefficient(b, harmonic) == (a * b).coefficient(harmonic)


@settings(max_examples=40, deadline=None)
@given(series_strategy, st.floats(-3, 3))
def test_float_evaluation_matches_exact(series, point):
    exact = float(as_expr(series).subs(s, point)) if not series.is_zero() else 0.0
    assert series.evaluate_float(point) == pytest.approx(exact, rel=1e-12, abs=1e-12)


def test_cosine_cubed_is_the_textbook_identity():
    cosine = CosineSeries.cosine(QQ)
    assert (cosine**3).coefficients == {1: QQ(3, 4), 3: QQ(1, 4)}
    assert (cosine**4).coefficients == {0: QQ(3, 8), 2: QQ(1, 2), 4: QQ(1, 8)}


def test_power_matches_repeated_product():
    series = CosineSeries(QQ, {0: QQ(1, 3), 2: QQ(-2), 5: QQ(1, 7)})
    assert series**5 == series * series * series * series * series
    assert series**0 == CosineSeries.constant(QQ, QQ(1))


def test_derivatives():
    series = CosineSeries(QQ, {0: QQ(2), 3: QQ(1, 5)})
    assert series.second_derivative().coefficients == {3: QQ(-9, 5)}
    assert series.derivative().derivative() == series.second_derivative()
    values = np.linspace(0, 2, 7)
    derivative = series.derivative().evaluate_float(values)
    assert np.allclose(derivative, -3 * 0.2 * np.sin(3 * values), rtol=0, atol=1e-15)


@settings(max_examples=40, deadline=None)
@given(series_strategy, fractions)
def test_periodic_solve_satisfies_the_equation_and_the_initial_value(rhs, value):
    rhs = rhs - CosineSeries.cosine(QQ, 1, rhs.coefficient(1))
    alpha0 = QQ(9, 4)
    solution = solve_harmonic_oscillator(rhs, alpha0, value_at_zero=QQ(value.numerator, value.denominator))
    residual = (solution.second_derivative() + solution).scale(alpha0) - rhs
    assert residual.is_zero()
    assert solution.value_at_zero() == QQ(value.numerator, value.denominator)


def test_periodic_solve_harmonic_normalisation_and_secular_error():
    rhs = CosineSeries(QQ, {0: QQ(1), 3: QQ(2)})
    solution = solve_harmonic_oscillator(rhs, QQ(1), first_harmonic=QQ(0))
    assert solution.coefficients == {0: QQ(1), 3: QQ(-1, 4)}
    with pytest.raises(SecularTermError, match="secular"):
        solve_harmonic_oscillator(CosineSeries.cosine(QQ), QQ(1), value_at_zero=QQ(0))
    with pytest.raises(ValueError, match="exactly one"):
        solve_harmonic_oscillator(rhs, QQ(1))


def test_polynomial_ring_coefficients():
    ring = QQ[sympy.Symbol("r")]
    (r,) = ring.gens
    series = CosineSeries(ring, {1: r, 2: ring.convert(Rational(1, 2))})
    squared = series * series
    assert squared.coefficient(0) == r**2 * ring.convert(Rational(1, 2)) + ring.convert(Rational(1, 8))
    assert math.isclose(float(ring.to_sympy(squared.coefficient(4))), 1 / 8)


def test_long_float_products_are_exact_up_to_one_rounding():
    # float series of 40+ terms multiply by an exact integer convolution: each coefficient is the exact
    # sum rounded once, whatever the cancellation (checked against the same sum at 300 digits)
    import mpmath
    from sympy import RealField

    domain = RealField(dps=40)
    with mpmath.workdps(60):
        first = CosineSeries(domain, {k: domain.dtype((-1) ** k * mpmath.mpf(7) ** k / mpmath.mpf(5) ** k / 3) for k in range(50)})
        second = CosineSeries(domain, {k: domain.dtype(mpmath.mpf(3) ** -k * (1 + mpmath.mpf(k) / 11)) for k in range(45)})
    product = first * second
    with mpmath.workdps(300):
        exact: dict[int, mpmath.mpf] = {}
        for m, a in first.coefficients.items():
            for n, b in second.coefficients.items():
                for harmonic in (m + n, abs(m - n)):  # cos(ms) cos(ns) = (cos((m+n)s) + cos((m−n)s))/2
                    exact[harmonic] = exact.get(harmonic, 0) + mpmath.mpf(a) * mpmath.mpf(b) / 2
        for harmonic, value in exact.items():
            assert abs(mpmath.mpf(product.coefficient(harmonic)) - value) <= abs(value) * mpmath.mpf(2) ** -(domain.precision - 1)


def _product_to_sum(first: dict, second: dict) -> dict:
    """cos(ms) cos(ns) = (cos((m+n)s) + cos(|m−n|s))/2, summed pairwise in exact Fractions."""
    from fractions import Fraction

    result: dict[int, Fraction] = {}
    for m, a in first.items():
        for n, b in second.items():
            for harmonic in (m + n, abs(m - n)):
                result[harmonic] = result.get(harmonic, Fraction(0)) + Fraction(a) * Fraction(b) / 2
    return {n: value for n, value in result.items() if value}


long_rationals = st.dictionaries(
    st.integers(0, 80),
    st.fractions(max_denominator=10**30).filter(lambda value: abs(value) < 10**40),
    min_size=8,
    max_size=40,
)


@settings(max_examples=60, deadline=None)
@given(long_rationals, long_rationals, st.sampled_from([None, 0, 1]), st.sampled_from([None, 0, 1]))
def test_long_rational_products_equal_the_product_to_sum_rule(first, second, first_parity, second_parity):
    # series of 8+ terms multiply through one packed-integer product; one parity (Duffing's odd
    # waveforms) is packed at half length: both must equal the pairwise definition exactly
    def restrict(values, parity):
        return values if parity is None else {2 * (n // 2) + parity: v for n, v in values.items()}

    first, second = restrict(first, first_parity), restrict(second, second_parity)

    def series(values):
        return CosineSeries(QQ, {n: QQ(v.numerator, v.denominator) for n, v in values.items()})

    product = series(first) * series(second)
    expected = _product_to_sum(first, second)
    assert {n: (int(c.numerator), int(c.denominator)) for n, c in product.coefficients.items()} == {
        n: (v.numerator, v.denominator) for n, v in expected.items()
    }
