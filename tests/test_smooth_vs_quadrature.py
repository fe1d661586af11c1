"""Smooth non-Duffing f against the quadrature reference (period from the energy integral), order 6."""

import mpmath
import pytest
import sympy

import lindstedt
from lindstedt.references import frequency_taylor_coefficients

u = sympy.Symbol("u", real=True)
ORDER = 6


@pytest.mark.parametrize(
    "text, expression, a0, omega0",
    [
        ("u**2", u**2, "0.8", "1"),
        ("u**3 + u**5/2", u**3 + u**5 / 2, "0.6", "1.3"),
        ("u**2 - u**4/3", u**2 - u**4 / 3, "0.5", "0.9"),
        ("sin(u)", sympy.sin(u), "0.8", "1"),
        ("exp(u) - 1", sympy.exp(u) - 1, "0.5", "1.2"),
    ],
)
def test_omega_k_match_quadrature_taylor_coefficients(text, expression, a0, omega0):
    expansion = lindstedt.expand(text, order=ORDER, a0=a0, omega0=omega0, precision=40)
    with mpmath.workdps(40):
        reference = frequency_taylor_coefficients(
            expression, ORDER, a0=mpmath.mpf(sympy.Rational(a0)), omega0=mpmath.mpf(sympy.Rational(omega0)), precision=40
        )
        for k in range(1, ORDER + 1):
            value, error = reference[k]
            ours = mpmath.mpf(sympy.N(expansion.omega[k], 40))
            tolerance = max(10 * error, mpmath.mpf(10) ** -18 * abs(value))
            assert abs(ours - value) <= tolerance, (k, ours, value, error)


def test_polynomial_results_are_exact_rationals():
    expansion = lindstedt.expand("u**2", order=4, a0=1, omega0=1)
    assert all(isinstance(value, sympy.Rational) for value in expansion.omega)
    assert expansion.omega[1] == 0  # an even f gives no first-order shift


def test_analytic_results_carry_the_requested_precision():
    expansion = lindstedt.expand("sin(u)", order=3, a0="0.8", omega0=1, precision=50)
    assert all(isinstance(value, sympy.Float) for value in expansion.omega[1:])
    assert expansion.omega[1]._prec >= 160  # 50 digits
