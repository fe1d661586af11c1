"""Problem construction: parsing, validation and typed errors naming the fix."""

import pytest
import sympy

import lindstedt
from lindstedt import OrderError, Oscillator, ParameterError, ProblemError, UnsupportedNonlinearityError


def test_string_and_expression_inputs_agree():
    u = sympy.Symbol("u", real=True)
    from_string = Oscillator("u^3 + c*u**5", a0=1, omega0=2, params={"c": "1/3"})
    from_expression = Oscillator(u**3 + sympy.Symbol("c", real=True) * u**5, a0=1, omega0=2, params={"c": sympy.Rational(1, 3)})
    assert from_string.nonlinearity == from_expression.nonlinearity == u**3 + u**5 / 3


def test_exact_rationals_stay_exact():
    problem = Oscillator("u**3", a0="0.1", omega0="3/2")
    assert problem.a0 == sympy.Rational(1, 10)
    assert problem.omega0 == sympy.Rational(3, 2)


def test_default_symbols_are_symbolic_and_positive():
    problem = Oscillator("u**3")
    assert problem.a0.is_Symbol and problem.omega0.is_positive


@pytest.mark.parametrize(
    "kwargs, error, fragment",
    [
        ({"f": "u**3 + d*u"}, ParameterError, "declare it"),
        ({"f": "u**3", "params": {"c": 1}}, ParameterError, "not used"),
        ({"f": "u**3", "a0": 0}, ProblemError, "a0 = 0"),
        ({"f": "u**3", "omega0": 0}, ProblemError, "positive"),
        ({"f": "u**3", "omega0": -2}, ProblemError, "positive"),
        ({"f": "u**3", "omega0": sympy.Symbol("w")}, ProblemError, "positive=True"),
        ({"f": "u**3 +* 2"}, ProblemError, "cannot parse"),
        ({"f": "u.__class__"}, ProblemError, "not allowed"),
        ({"f": "__import__('os')"}, ProblemError, "not allowed"),
        ({"f": "0"}, ProblemError, "identically zero"),
        ({"f": "u**3", "normalization": "peak"}, ProblemError, "normalization"),
        ({"f": "u**3", "params": {"u": 1}}, ParameterError, "displacement"),
    ],
)
def test_bad_input_raises_typed_errors_that_name_the_fix(kwargs, error, fragment):
    with pytest.raises(error, match=fragment):
        Oscillator(**kwargs)


def test_foreign_symbol_in_expression_is_refused():
    u, z = sympy.Symbol("u", real=True), sympy.Symbol("z")
    with pytest.raises(ParameterError, match="z"):
        Oscillator(u**3 + z * u)


@pytest.mark.parametrize("order", [-1, 101, 10**6, 2.5, True])
def test_bad_orders(order):
    with pytest.raises(OrderError):
        lindstedt.expand("u**3", order=order)


def test_numeric_result_needs_values_for_symbolic_parameters():
    expansion = lindstedt.expand("u**3 + c*u**5", order=2, a0=1, omega0=1, params={"c": None})
    assert expansion.omega[1] == sympy.Rational(3, 8) + sympy.Rational(5, 16) * sympy.Symbol("c", real=True)
    with pytest.raises(ParameterError, match="c"):
        expansion.frequency(0.1)
    assert expansion.frequency(0.1, values={"c": 0}) == pytest.approx(1 + 0.1 * 3 / 8 - 0.01 * 21 / 256, rel=1e-15)
    with pytest.raises(ParameterError, match="not have"):
        expansion.frequency(0.1, values={"c": 0, "zeta": 1})


def test_non_smooth_and_non_analytic_f_are_refused_with_guidance():
    with pytest.raises(UnsupportedNonlinearityError, match="symbol|numeric"):
        lindstedt.expand("sin(u)", order=2)
    with pytest.raises(UnsupportedNonlinearityError, match="analytic"):
        lindstedt.expand("1/u", order=2, a0=1, omega0=1)
    with pytest.raises(UnsupportedNonlinearityError, match="analytic"):
        lindstedt.expand("sqrt(u + 1/2)", order=2, a0=1, omega0=1)


def test_decimal_literals_inside_f_are_exact():
    problem = Oscillator("Max(0, u - 0.3) + 2.5*u**3", a0=1, omega0=1)
    assert problem.f == sympy.Max(0, problem.variable - sympy.Rational(3, 10)) + sympy.Rational(5, 2) * problem.variable**3
