"""Tests of the exact truncated power-series arithmetic (lindstedt.algebra.PowerSeries, binomial_series).

Expectations come from closed forms (binomial coefficients, Catalan numbers,
geometric series) or from sympy's own ``series``, never from the module.
"""

from __future__ import annotations

from fractions import Fraction

import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st

from lindstedt import OrderError, ProblemError
from lindstedt.algebra import PowerSeries, binomial_series

X = sympy.Symbol("x")

small_fractions = st.fractions(min_value=-5, max_value=5, max_denominator=7)
unit_leading_series = st.lists(small_fractions, min_size=5, max_size=5).map(
    lambda tail: PowerSeries([1] + tail, order=5)
)


def sympy_series_coefficients(expression: sympy.Expr, order: int) -> list[sympy.Rational]:
    """Coefficients of x**0..x**order of sympy's own expansion."""
    polynomial = sympy.series(expression, X, 0, order + 1).removeO()
    return [sympy.expand(polynomial).coeff(X, power) for power in range(order + 1)]


def polynomial_coefficients(expression: sympy.Expr, order: int) -> list[sympy.Rational]:
    """Coefficients of x**0..x**order of a polynomial expression, by sympy expansion."""
    polynomial = sympy.Poly(sympy.expand(expression), X)
    return [polynomial.coeff_monomial(X**power) for power in range(order + 1)]


def test_sqrt_matches_binomial_coefficients():
    order = 12
    result = PowerSeries([1, 1], order=order).sqrt()
    expected = [sympy.binomial(sympy.Rational(1, 2), k) for k in range(order + 1)]
    assert [sympy.Rational(c.numerator, c.denominator) for c in result.coefficients] == expected


@pytest.mark.parametrize("exponent", [Fraction(-1, 2), Fraction(1, 3), Fraction(-7, 4), Fraction(5, 1), Fraction(-3, 1)])
def test_power_matches_binomial_coefficients(exponent):
    order = 9
    result = PowerSeries([1, 1], order=order).power(exponent)
    p = sympy.Rational(exponent.numerator, exponent.denominator)
    expected = [sympy.binomial(p, k) for k in range(order + 1)]
    assert [sympy.Rational(c.numerator, c.denominator) for c in result.coefficients] == expected
    assert binomial_series(exponent, order) == result


def test_power_with_exact_rational_leading_root():
    # (9/4 + 3 x + x**2) = (3/2 + x)**2, so the square root is 3/2 + x.
    result = PowerSeries([Fraction(9, 4), 3, 1], order=6).sqrt()
    assert result.coefficients == (Fraction(3, 2), 1, 0, 0, 0, 0, 0)
    # (-8 + ...)**(1/3) uses the real cube root -2.
    cube_root = PowerSeries([-8, 12, -6, 1], order=5).power(Fraction(1, 3))  # (x - 2)**3
    assert cube_root.coefficients == (-2, 1, 0, 0, 0, 0)


def test_inverse_geometric_and_alternating():
    assert PowerSeries([1, -1], order=7).inverse().coefficients == tuple([Fraction(1)] * 8)
    assert PowerSeries([1, 1], order=7).inverse().coefficients == tuple(Fraction((-1) ** k) for k in range(8))
    assert PowerSeries([2, -1], order=4).inverse().coefficients == tuple(Fraction(1, 2 ** (k + 1)) for k in range(5))


def test_compose_matches_closed_form():
    geometric = PowerSeries([1] * 8)  # 1/(1 - y)
    inner = PowerSeries([0] + [(-1) ** (k - 1) for k in range(1, 8)])  # y = x/(1 + x)
    assert geometric.compose(inner).coefficients == (1, 1, 0, 0, 0, 0, 0, 0)  # = 1 + x


def test_reversion_gives_signed_catalan_numbers():
    # y = x + x**2  =>  x = (-1 + sqrt(1 + 4y))/2 = sum (-1)**(n-1) Catalan(n-1) y**n
    order = 12
    inverse = PowerSeries([0, 1, 1], order=order).reversion()
    expected = [0] + [(-1) ** (n - 1) * sympy.catalan(n - 1) for n in range(1, order + 1)]
    assert [sympy.Rational(c.numerator, c.denominator) for c in inverse.coefficients] == expected


def test_reversion_of_sympy_function_matches_sympy_inverse():
    # y = x/(1 - x)**2 (Koebe-like) has inverse x = (1 + 2y - sqrt(1 + 4y))/(2y).
    order = 8
    forward = PowerSeries(sympy_series_coefficients(X / (1 - X) ** 2, order))
    expected = sympy_series_coefficients((1 + 2 * X - sympy.sqrt(1 + 4 * X)) / (2 * X), order)
    assert expected[:3] == [0, 1, -2]
    assert list(forward.reversion().coefficients) == expected


@settings(max_examples=20, deadline=None)
@given(unit_leading_series, unit_leading_series)
def test_multiplication_and_composition_agree_with_sympy(first, second):
    order = 5
    product = first * second
    expected_product = polynomial_coefficients(first.to_expression(X) * second.to_expression(X), order)
    assert list(product.coefficients) == expected_product
    inner = second - second.coefficients[0]  # zero constant term
    composed = first.compose(inner)
    expected_composition = polynomial_coefficients(first.to_expression(inner.to_expression(X)), order)
    assert list(composed.coefficients) == expected_composition


@settings(max_examples=25, deadline=None)
@given(unit_leading_series)
def test_inverse_times_series_is_one(series):
    product = series * series.inverse()
    assert product.coefficients == (1, 0, 0, 0, 0, 0)
    assert (1 / series) == series.inverse()


@settings(max_examples=30, deadline=None)
@given(unit_leading_series, small_fractions, small_fractions)
def test_power_laws(series, first_exponent, second_exponent):
    combined = series.power(first_exponent) * series.power(second_exponent)
    assert combined == series.power(first_exponent + second_exponent)
    assert series.sqrt() * series.sqrt() == series


@settings(max_examples=30, deadline=None)
@given(st.lists(small_fractions, min_size=5, max_size=5), st.fractions(min_value=Fraction(1, 4), max_value=4, max_denominator=5))
def test_reversion_is_two_sided_inverse(tail, linear):
    forward = PowerSeries([0, linear] + tail[:4], order=5)
    inverse = forward.reversion()
    identity = (0, 1, 0, 0, 0, 0)
    assert forward.compose(inverse).coefficients == identity
    assert inverse.compose(forward).coefficients == identity


def test_sympy_coefficients_give_same_results_as_fractions():
    fraction_series = PowerSeries([1, Fraction(1, 3), Fraction(-2, 5)], order=6)
    sympy_series = PowerSeries([1, sympy.Rational(1, 3), sympy.Rational(-2, 5)], order=6)
    assert sympy_series.uses_sympy and not fraction_series.uses_sympy
    for operation in (
        lambda s: s.sqrt(),
        lambda s: s.inverse(),
        lambda s: s.power(Fraction(-3, 2)),
        lambda s: (s - 1).reversion(),
        lambda s: s.compose(s - 1),
    ):
        fraction_result, sympy_result = operation(fraction_series), operation(sympy_series)
        assert sympy_result.uses_sympy
        assert all(isinstance(c, sympy.Rational) for c in sympy_result.coefficients)
        assert fraction_result == sympy_result
    mixed = fraction_series * sympy_series
    assert mixed.uses_sympy


def test_truncation_order_of_results():
    long_series = PowerSeries([1, 2, 3, 4, 5, 6])
    short_series = PowerSeries([1, 1, 1])
    assert (long_series * short_series).order == 2
    assert (long_series + short_series).order == 2
    assert long_series.compose(PowerSeries([0, 1, 1])).order == 2
    assert PowerSeries([1], order=3).coefficients == (1, 0, 0, 0)
    assert long_series.truncate(1).coefficients == (1, 2)


def test_scalar_operations_and_evaluation():
    series = PowerSeries([1, 2, 3])
    assert (2 * series).coefficients == (2, 4, 6)
    assert (series / 2).coefficients == (Fraction(1, 2), 1, Fraction(3, 2))
    assert (1 - series).coefficients == (0, -2, -3)
    assert (series**2).coefficients == (1, 4, 10)
    assert series.evaluate(Fraction(1, 2)) == Fraction(11, 4)
    assert series.to_expression(X) == 1 + 2 * X + 3 * X**2
    assert PowerSeries.variable(2).coefficients == (0, 1, 0)


@pytest.mark.parametrize(
    "action",
    [
        lambda: PowerSeries([0, 1]).inverse(),
        lambda: PowerSeries([1, 1]).compose(PowerSeries([1, 1])),
        lambda: PowerSeries([1, 1, 1]).reversion(),
        lambda: PowerSeries([0, 0, 1]).reversion(),
        lambda: PowerSeries([2, 1]).sqrt(),
        lambda: PowerSeries([-4, 1]).sqrt(),
        lambda: PowerSeries([0, 1]).power(Fraction(1, 2)),
        lambda: PowerSeries([0.5, 1]),
        lambda: PowerSeries([sympy.sqrt(2), 1]),
        lambda: PowerSeries([1, 1]).power(0.5),
    ],
)
def test_invalid_operations_raise_problem_error(action):
    with pytest.raises(ProblemError):
        action()


@pytest.mark.parametrize(
    "action",
    [
        lambda: PowerSeries([1], order=-1),
        lambda: PowerSeries([1], order=2.0),
        lambda: PowerSeries([1, 2]).truncate(5),
        lambda: PowerSeries([0], order=0).reversion(),
    ],
)
def test_invalid_orders_raise_order_error(action):
    with pytest.raises(OrderError):
        action()
