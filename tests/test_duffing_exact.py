"""Duffing: the engine's ω_k equal the Taylor coefficients of the exact frequency (elliptic K), exactly."""

import pytest
import sympy

import lindstedt
from lindstedt.references import duffing_frequency_taylor

ORDER = 10


@pytest.mark.parametrize("normalization", ["initial", "harmonic"])
def test_duffing_orders_1_to_10_are_the_exact_rationals(normalization):
    reference = duffing_frequency_taylor(ORDER, normalization=normalization)
    expansion = lindstedt.expand("u**3", order=ORDER, a0=1, omega0=1, normalization=normalization)
    assert all(isinstance(value, sympy.Rational) for value in expansion.omega)
    assert list(expansion.omega) == list(reference)


@pytest.mark.parametrize("normalization", ["initial", "harmonic"])
def test_duffing_symbolic_amplitude_and_frequency_give_the_right_powers(normalization):
    reference = duffing_frequency_taylor(6, normalization=normalization)
    a0 = sympy.Symbol("a0", positive=True)
    omega0 = sympy.Symbol("omega0", positive=True)
    c = sympy.Symbol("c", real=True)
    expansion = lindstedt.expand("c*u**3", order=6, params={"c": None}, normalization=normalization)
    for k, value in enumerate(expansion.omega):
        expected = omega0 * reference[k] * (c * a0**2 / omega0**2) ** k
        assert sympy.simplify(value - expected) == 0


def test_textbook_second_order_values():
    a0, omega0 = sympy.Symbol("a0", positive=True), sympy.Symbol("omega0", positive=True)
    initial = lindstedt.expand("u**3", order=2).omega[2]
    harmonic = lindstedt.expand("u**3", order=2, normalization="harmonic").omega[2]
    assert sympy.simplify(initial + sympy.Rational(21, 256) * a0**4 / omega0**3) == 0
    assert sympy.simplify(harmonic + sympy.Rational(15, 256) * a0**4 / omega0**3) == 0


def test_numeric_rational_amplitude_stays_exact():
    reference = duffing_frequency_taylor(8)
    a0, omega0 = sympy.Rational(7, 10), sympy.Rational(13, 10)
    expansion = lindstedt.expand("u**3", order=8, a0="0.7", omega0="1.3")
    for k, value in enumerate(expansion.omega):
        assert value == omega0 * reference[k] * (a0**2 / omega0**2) ** k
