"""The contact field (σ² + κ² = 1 built in, lindstedt.algebra.contact_field).

Its arithmetic is checked against mpmath evaluations of the same expressions (no field involved),
and the expansions that run in it against the independent exact frequency of
``u'' + u + ε a (u − b)_+ = 0`` (Cauchy integral of the closed-form period,
:func:`lindstedt.references.piecewise_linear_frequency_taylor`) or, for two springs, the
quadrature reference :func:`lindstedt.references.frequency_taylor_coefficients`.
"""

from __future__ import annotations

import mpmath
import pytest
import sympy

import lindstedt
from lindstedt.algebra import contact_ramp_coefficient
from lindstedt.algebra.contact_field import ContactField, sum_of_products
from lindstedt.references import frequency_taylor_coefficients, piecewise_linear_frequency_taylor

KAPPA = sympy.Symbol("kappa")
SINE = sympy.sqrt(1 - KAPPA**2)
U = sympy.Symbol("u")


def _symbolic_field() -> ContactField:
    return ContactField.for_constants([KAPPA], [sympy.pi, sympy.acos(KAPPA), SINE])


def _value(expression: sympy.Expr, kappa: mpmath.mpf) -> mpmath.mpf:
    """mpmath value of a sympy expression in π, κ, acos κ, sqrt(1 − κ²) (lambdify: no field arithmetic)."""
    return sympy.lambdify(KAPPA, expression, "mpmath")(kappa)


def test_the_relation_holds_and_forms_are_canonical():
    field = _symbolic_field()
    kappa, sine = field.from_sympy(KAPPA), field.from_sympy(SINE)
    assert sine * sine + kappa * kappa == field.one
    assert (sine - kappa) * (sine + kappa) == field.one - 2 * kappa * kappa
    # cos 3β = 4κ³ − 3κ and sin 3β = σ (4κ² − 1), from the Chebyshev recurrence of the evaluation point
    from lindstedt.algebra.branch import EvaluationPoint

    point = EvaluationPoint(field, field.from_sympy(sympy.acos(KAPPA)), kappa, sine)
    assert point.cos_multiple(3) == field.from_sympy(4 * KAPPA**3 - 3 * KAPPA)
    assert point.sin_multiple(3) == field.from_sympy(SINE * (4 * KAPPA**2 - 1))
    # 1/σ and 1/(1 + κ) = (1 − κ)/σ² keep a monomial denominator
    assert len((field.one / sine).den) == 1 and len((field.one / (field.one + kappa)).den) == 1


@pytest.mark.parametrize(
    "numerator, denominator",
    [
        (sympy.pi * KAPPA * SINE + sympy.acos(KAPPA) ** 2 - sympy.Rational(3, 7) * KAPPA, SINE**3 * sympy.pi**2),
        (sympy.acos(KAPPA) - KAPPA * SINE, sympy.pi + KAPPA),  # π + κ is not a unit: the general (gcd) path
        (1 + KAPPA, (1 - KAPPA) * sympy.acos(KAPPA) + SINE),
    ],
)
def test_quotients_agree_with_mpmath(numerator, denominator):
    field = _symbolic_field()
    x, y = field.from_sympy(numerator), field.from_sympy(denominator)
    quotient = x / y
    assert quotient * y == x
    printed = field.to_sympy(quotient)
    with mpmath.workdps(40):
        for kappa in (mpmath.mpf(3) / 10, mpmath.mpf(-5) / 7, mpmath.mpf(9) / 10):
            expected = _value(numerator, kappa) / _value(denominator, kappa)
            assert abs(_value(printed, kappa) - expected) <= mpmath.mpf(10) ** -35 * abs(expected)


@pytest.mark.parametrize("general", [False, True])
def test_sums_of_products_agree_with_mpmath(general):
    # one accumulation over the common denominator (π^m σ^n, or π + κ: the general path), against term-wise values
    field = _symbolic_field()
    terms = [
        (sympy.pi * KAPPA * SINE - sympy.Rational(3, 7), sympy.acos(KAPPA) ** 2 / sympy.pi**3, sympy.Rational(-5, 6)),
        (KAPPA / SINE**3, SINE * KAPPA + sympy.pi, 1 / (sympy.pi + KAPPA) if general else sympy.Rational(1, 24)),
        (sympy.acos(KAPPA) / sympy.pi, 1 - KAPPA**2, sympy.pi * SINE),
        (0, KAPPA, 1),
    ]
    total = sum_of_products(field, [tuple(field.from_sympy(x) for x in triple) for triple in terms])
    assert total == sum((field.from_sympy(a) * field.from_sympy(b) * field.from_sympy(c) for a, b, c in terms), field.zero)
    printed = field.to_sympy(total)
    with mpmath.workdps(40):
        for kappa in (mpmath.mpf(3) / 10, mpmath.mpf(-5) / 7):
            expected = sum(_value(a, kappa) * _value(b, kappa) * _value(c, kappa) for a, b, c in terms)
            assert abs(_value(printed, kappa) - expected) <= mpmath.mpf(10) ** -35 * abs(expected)


def test_powers_beyond_the_packed_exponents_are_refused():
    field = _symbolic_field()
    # one int per monomial, 16 bits per generator: a product takes factors with exponents below 2^14 (so that
    # no sum carries into the next generator) and refuses the others instead of returning a wrong monomial
    power = field.from_sympy(sympy.pi) ** 10000
    square = power * power
    assert field.to_sympy(square) == sympy.pi**20000
    with pytest.raises(OverflowError):
        square * power


def test_rational_gaps_share_square_roots_of_primes():
    field = ContactField.for_constants(
        [sympy.Rational(1, 4), sympy.Rational(-1, 2)], [sympy.sqrt(15) / 4, sympy.sqrt(3) / 2, sympy.sqrt(5)]
    )
    root = field.from_sympy
    assert root(sympy.sqrt(3)) * root(sympy.sqrt(5)) == root(sympy.sqrt(15))
    assert root(sympy.sqrt(15) / 4) ** 2 == field.convert(sympy.Rational(15, 16))
    assert root(sympy.acos(sympy.Rational(-1, 4))) == root(sympy.pi - sympy.acos(sympy.Rational(1, 4)))
    assert field.to_sympy(root(sympy.sqrt(15)) / root(sympy.sqrt(3))) == sympy.sqrt(5)
    # the ring depends only on the structure: κ = 1/3 (σ = 2√2/3) and κ = 2/7 (σ = 3√5/7) share it
    first = ContactField.for_constants([sympy.Rational(1, 3)], [])
    second = ContactField.for_constants([sympy.Rational(2, 7)], [])
    assert first.ring is second.ring and first is not second


def _check_against_reference(omegas, reference, tolerance=mpmath.mpf(10) ** -25):
    for k, (omega, (value, error)) in enumerate(zip(omegas, reference)):
        difference = abs(mpmath.mpf(sympy.N(omega, 40)) - value)
        assert difference <= 10 * error + tolerance * max(1, abs(value)), (k, omega, value, error)


@pytest.mark.parametrize("gap", ["3/10", "1/4", "-1/2"])
def test_exact_gap_against_the_exact_period(gap):
    expansion = lindstedt.expand(f"Max(0, u - {gap})", order=6, a0=1, omega0=1)
    assert isinstance(expansion._form.domain, ContactField)
    with mpmath.workdps(40):
        reference = piecewise_linear_frequency_taylor(6, a=1, b=mpmath.mpf(sympy.Rational(gap)), a0=1, precision=40)
        _check_against_reference(expansion.omega, reference)


def test_symbolic_gap_against_the_exact_period():
    expansion = lindstedt.expand("Max(0, u - kappa)", order=4, a0=1, omega0=1, params={"kappa": None})
    assert isinstance(expansion._form.domain, ContactField)
    kappa = next(iter(expansion.omega[1].free_symbols))
    # printed short: with independent generators for κ, acos κ and sqrt(1 − κ²) omega_1..4 had count_ops
    # 16, 270, 2221, 7106; here at least 10 times fewer from omega_3 on
    assert all(sympy.count_ops(omega) <= bound for omega, bound in zip(expansion.omega[1:], (16, 135, 222, 710)))
    with mpmath.workdps(40):
        for gap in (sympy.Rational(3, 10), sympy.Rational(-5, 7), sympy.Rational(9, 10)):
            reference = piecewise_linear_frequency_taylor(4, a=1, b=mpmath.mpf(gap), a0=1, precision=40)
            _check_against_reference([omega.subs(kappa, gap) for omega in expansion.omega], reference)


def test_irrational_gap_falls_back_to_the_general_field():
    expansion = lindstedt.expand("Max(0, u - sqrt(2)/2)", order=3, a0=1, omega0=1)
    assert not isinstance(expansion._form.domain, ContactField)
    with mpmath.workdps(40):
        reference = piecewise_linear_frequency_taylor(3, a=1, b=mpmath.sqrt(2) / 2, a0=1, precision=40)
        _check_against_reference(expansion.omega, reference)


def test_two_springs_first_order_against_the_fourier_closed_form():
    """ω_1 = ½ · first cosine coefficient of f(cos s) = ½ (c_1[1/4] + 2 c_1[1/2]), c_1[κ] = (β − κ sin β)/π."""
    expansion = lindstedt.expand("Max(0, u - 1/4) - 2*Max(0, -u - 1/2)", order=3, a0=1, omega0=1)
    assert isinstance(expansion._form.domain, ContactField)
    first = (contact_ramp_coefficient(1, sympy.Rational(1, 4)) + 2 * contact_ramp_coefficient(1, sympy.Rational(1, 2))) / 2
    assert sympy.simplify(expansion.omega[1] - first) == 0


@pytest.mark.slow
def test_symbolic_gap_order_six_against_the_exact_period():
    expansion = lindstedt.expand("Max(0, u - kappa)", order=6, a0=1, omega0=1, params={"kappa": None})
    kappa = next(iter(expansion.omega[1].free_symbols))
    with mpmath.workdps(40):
        for gap in (sympy.Rational(3, 10), sympy.Rational(-5, 7), sympy.Rational(1, 13)):
            reference = piecewise_linear_frequency_taylor(6, a=1, b=mpmath.mpf(gap), a0=1, precision=40)
            _check_against_reference([omega.subs(kappa, gap) for omega in expansion.omega], reference)


@pytest.mark.slow
def test_exact_gap_order_ten_and_two_springs_order_four():
    expansion = lindstedt.expand("Max(0, u - 3/10)", order=10, a0=1, omega0=1)
    with mpmath.workdps(40):
        reference = piecewise_linear_frequency_taylor(10, a=1, b=mpmath.mpf(3) / 10, a0=1, precision=40)
        _check_against_reference(expansion.omega, reference)
    expansion = lindstedt.expand("Max(0, u - 1/4) - 2*Max(0, -u - 1/2)", order=4, a0=1, omega0=1)
    assert isinstance(expansion._form.domain, ContactField)
    law = sympy.Max(0, U - sympy.Rational(1, 4)) - 2 * sympy.Max(0, -U - sympy.Rational(1, 2))
    with mpmath.workdps(30):
        reference = frequency_taylor_coefficients(law, 4, a0=1, precision=30)
        _check_against_reference(expansion.omega, reference, tolerance=mpmath.mpf(10) ** -20)
