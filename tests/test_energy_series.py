"""The exact energy-integral series of a polynomial oscillator (lindstedt.references.conservative_frequency_series).

The reference is checked against routes of its own — the binomial series of sqrt(ω0² + εc) for f = c u, the
elliptic series of the Duffing oscillator, the quadrature of the period — and then the engine's ω_k are
compared with it exactly, for polynomials with even and odd terms (asymmetric orbits), f(0) ≠ 0, a0 ≠ 1 and
an irrational ω0.
"""

from __future__ import annotations

import mpmath
import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st

import lindstedt
from lindstedt.references import (
    conservative_frequency,
    conservative_frequency_series,
    duffing_frequency_taylor,
)

EPSILON = sympy.Symbol("epsilon")


@pytest.mark.parametrize("c, omega0", [(1, 1), (3, 2), (sympy.Rational(-1, 2), sympy.sqrt(3))])
def test_linear_f_gives_the_binomial_series(c, omega0):
    """f = c u: ω = sqrt(ω0² + ε c) exactly; its Taylor coefficients from sympy's series."""
    exact = sympy.series(sympy.sqrt(omega0**2 + c * EPSILON), EPSILON, 0, 13).removeO()
    expected = [sympy.expand(exact.coeff(EPSILON, k)) for k in range(13)]
    got = conservative_frequency_series(sympy.Symbol("u") * c, 12, omega0=omega0)
    assert [sympy.expand(value) for value in got] == expected


def test_duffing_is_the_elliptic_series():
    """Two independent exact references of u'' + u + ε u³ = 0, u(0) = 1, agree to order 80."""
    assert list(conservative_frequency_series("u**3", 80)) == list(duffing_frequency_taylor(80))


def test_the_series_sums_to_the_quadrature_of_the_period():
    """f = u² + u³ (asymmetric orbit), ε = 1/1000: Σ ω_k ε^k against the 40-digit energy-integral quadrature.

    The tail after order 12 is bounded by twice its first term (the terms' ratio is below 1/2 here, checked).
    """
    order, epsilon = 12, mpmath.mpf(1) / 1000
    series = conservative_frequency_series("u**2 + u**3", order + 2, a0="1/2")
    with mpmath.workdps(40):
        terms = [mpmath.mpf(int(w.p)) / int(w.q) * epsilon**k for k, w in enumerate(series)]
        assert abs(terms[order + 2]) < abs(terms[order + 1]) / 2
        value, error = conservative_frequency(sympy.Symbol("u") ** 2 + sympy.Symbol("u") ** 3, epsilon, a0=sympy.Rational(1, 2),
                                              precision=40)
        assert error < mpmath.mpf(10) ** -35
        assert abs(sum(terms[: order + 1]) - value) <= 2 * abs(terms[order + 1]) + error
        assert abs(sum(terms[: order + 1]) - value) > abs(terms[order + 1]) / 2  # the truncation is what is left


CASES = [
    ("u**2", 1, 1, 14),
    ("u**2 + u**3", "1/2", 2, 12),
    ("3*u**5 - u**2", "3/2", 1, 10),
    ("2 + u**2", 1, 1, 10),  # f(0) ≠ 0: the centre moves, the release point stays a turning point
    ("u**4 - u/3", 1, "sqrt(2)", 10),
    ("-u**3", "1/3", 1, 16),  # softening
    ("u**3", 1, 1, 40),
    ("u**2 + u**3", 1, 1, 60),  # an asymmetric orbit at high order: 60 exact rationals of ~300 digits each
]


@pytest.mark.parametrize("f, a0, omega0, order", CASES)
def test_engine_equals_the_energy_series_exactly(f, a0, omega0, order):
    engine = lindstedt.expand(f, order=order, a0=a0, omega0=omega0).omega
    reference = conservative_frequency_series(f, order, a0=a0, omega0=omega0)
    assert [sympy.expand(a - b) for a, b in zip(engine, reference)] == [0] * (order + 1)


@settings(max_examples=25, deadline=None)
@given(
    coefficients=st.lists(st.integers(-3, 3), min_size=1, max_size=5).filter(any),
    a0=st.sampled_from(["1/2", "1", "2", "-3/4"]),
)
def test_engine_equals_the_energy_series_for_random_polynomials(coefficients, a0):
    f = " + ".join(f"({c})*u**{m}" for m, c in enumerate(coefficients) if c)
    engine = lindstedt.expand(f, order=6, a0=a0, omega0=1).omega
    assert list(engine) == list(conservative_frequency_series(f, 6, a0=a0))


@pytest.mark.parametrize(
    "f, kwargs, error",
    [
        ("sin(u)", {}, lindstedt.UnsupportedNonlinearityError),
        ("u**(1/2)", {}, lindstedt.UnsupportedNonlinearityError),
        ("u**2 + k*u", {}, lindstedt.ParameterError),
        ("u**3", {"a0": 0}, lindstedt.ProblemError),
        ("u**3", {"a0": "sqrt(2)"}, lindstedt.ProblemError),
        ("u**3", {"omega0": -1}, lindstedt.ProblemError),
        ("u**3", {"omega0": "2**(1/3)"}, lindstedt.ProblemError),
    ],
)
def test_refused_inputs_name_the_fix(f, kwargs, error):
    with pytest.raises(error):
        conservative_frequency_series(f, 3, **kwargs)


def test_order_is_checked():
    with pytest.raises(lindstedt.OrderError):
        conservative_frequency_series("u**3", 401)
    with pytest.raises(lindstedt.OrderError):
        conservative_frequency_series("u**3", -1)
