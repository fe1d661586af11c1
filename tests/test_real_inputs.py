"""Real inputs only, and the parser's bounds on the expression sympy builds (issue 23, items 1 and 3).

* Every numeric sub-expression of f, of a parameter value or of a matrix entry must be a real number:
  ``sqrt(-1)``, ``log(-1)``, ``acos(2)``, ``(-8)**(1/3)`` (sympy's principal root 1 + i√3) are refused with a
  typed error naming the sub-expression, through the API and the command line.
* The bound on exponents applies after sympy's automatic combination: ``(u**200)**200`` is ``u**40000``.
* ε and t go through the one reading of numbers: None, booleans, NaN, infinities, words and complex numbers are
  refused; exact fractions as strings are read exactly; float arrays stay vectorised.

Expected values are exact or from the literature (Duffing: ω = 1 + 3/8 ε − 21/256 ε² + O(ε³) for u'' + u + ε u³ = 0,
u(0) = 1, u'(0) = 0).
"""

from __future__ import annotations

import subprocess
import sys
from fractions import Fraction

import numpy as np
import pytest
import sympy

import lindstedt
from lindstedt import ParameterError, ProblemError

COMPLEX_CONSTANTS = [
    ("sqrt(-1)*u**3", "sqrt(-1)"),
    ("log(-1)*u**3", "log(-1)"),
    ("u**3 + acos(2)*u", "acos(2)"),
    ("asin(3)*u**3", "asin(3)"),
    ("(-2)**pi*u**3", "(-2)**pi"),
    ("u**3 + sqrt(-1)*sqrt(-1)*u", "sqrt(-1)"),  # real product, complex factor: refused all the same
    ("exp(sqrt(-4))*u**3", "sqrt(-4)"),
    ("Piecewise((u, u > sqrt(-1)), (0, True))", "sqrt(-1)"),
]


@pytest.mark.parametrize("f, part", COMPLEX_CONSTANTS)
def test_a_complex_constant_in_f_is_refused_naming_it(f, part):
    with pytest.raises(ProblemError, match="not a real number") as caught:
        lindstedt.Oscillator(f, a0=1, omega0=1)
    assert repr(part) in str(caught.value)


def test_the_principal_cube_root_of_a_negative_number_is_refused_with_the_real_spelling():
    with pytest.raises(ProblemError, match="not a real number") as caught:
        lindstedt.Oscillator("(-8)**(1/3)*u**3", a0=1, omega0=1)
    assert "-8**(1/3)" in str(caught.value) and "-(8**(1/3))" in str(caught.value)
    # the spelling it suggests is the real cube root: omega_1 = 3/8 * (-2)
    assert lindstedt.expand("-8**(1/3)*u**3", order=1, a0=1, omega0=1).omega[1] == sympy.Rational(-3, 4)
    assert lindstedt.expand("(-8)**2*u**3", order=1, a0=1, omega0=1).omega[1] == 24  # an integer power stays


def test_real_constants_stay_accepted():
    e = lindstedt.expand("acos(1/3)*u**3 + sqrt(2)**2*u**3", order=1, a0=1, omega0=1)
    assert e.omega[1] == sympy.Rational(3, 8) * (sympy.acos(sympy.Rational(1, 3)) + 2)


def test_a_complex_sympy_expression_is_refused():
    u = sympy.Symbol("u")
    with pytest.raises(ProblemError, match="not a real number"):
        lindstedt.Oscillator(sympy.I * u**3, a0=1, omega0=1)
    with pytest.raises(ProblemError, match="not a real number"):
        lindstedt.Oscillator(sympy.acos(2) * u**3, a0=1, omega0=1)


@pytest.mark.parametrize("value", ["sqrt(-1)", "log(-2)", "acos(2)", "(-8)**(1/3)", 1j, sympy.I])
def test_a_complex_parameter_or_amplitude_is_refused(value):
    with pytest.raises(ProblemError):
        lindstedt.Oscillator("c*u**3", a0=1, omega0=1, params={"c": value})
    with pytest.raises(ProblemError):
        lindstedt.Oscillator("u**3", a0=value, omega0=1)


@pytest.mark.parametrize("entry", ["M", "K", "b"])
def test_a_complex_matrix_entry_is_refused(entry):
    data = {"M": [[1, 0], [0, 1]], "K": [[2, -1], [-1, 1]], "A": [[1, 0]], "b": [1]}
    if entry == "b":
        data["b"] = ["log(-2)"]
    else:
        data[entry][1][1] = "sqrt(-1)"
    with pytest.raises(ProblemError, match="not a real number"):
        lindstedt.UnilateralSystem(**data)


NESTED = [
    "(u**200)**200",
    "(((u**200)**200)**200)**200",
    "((u+1)**200)**200",
    "(Max(0, u - 1/5)**200)**200",
    "u**150 * u**150",
    "(2*u**100)**3",
    "u**100 * (u + 1)**150",
    "(u**(1/200))**(1/200)",
]


@pytest.mark.parametrize("f", NESTED)
def test_the_exponent_bound_applies_after_sympy_combines_powers(f):
    with pytest.raises(ProblemError, match="once sympy combines its powers"):
        lindstedt.Oscillator(f, a0=1, omega0=1)


def test_the_degree_bound_holds_in_every_symbol_and_for_sympy_input():
    with pytest.raises(ProblemError, match="degree 40000 in c"):
        lindstedt.Oscillator("(c**200)**200*u**3", a0=1, omega0=1, params={"c": None})
    u = sympy.Symbol("u")
    with pytest.raises(ProblemError, match="degree 40000 in u"):
        lindstedt.Oscillator(u**40000, a0=1, omega0=1)
    with pytest.raises(ProblemError, match="exceeds the bound"):
        lindstedt.Oscillator("E**(100*pi)*u**3", a0=1, omega0=1)


def test_powers_up_to_the_bound_stay_accepted():
    f = lindstedt.Oscillator("(u**10)**20", a0=1, omega0=1).f
    (u,) = f.free_symbols
    assert f == u**200
    g = lindstedt.Oscillator("u**100*u**100 + c*u**3", a0=1, omega0=1, params={"c": None}).f
    assert sympy.Poly(g, u).degree() == 200 and g.coeff(u, 200) == 1


# ----------------------------------------------------------------------------------------------- ε and t
@pytest.fixture(scope="module")
def duffing():
    return lindstedt.expand("u**3", order=2, a0=1, omega0=1)


@pytest.fixture(scope="module")
def mode():
    return lindstedt.nnm(lindstedt.UnilateralSystem.one_dof(1, a=1, b=0), mode=1, a0=1, order=2)


BAD_NUMBERS = [None, True, False, "nan", "inf", "-inf", "1e400", "abc", "u", 1j, float("nan"), float("inf"), 10**400,
               [0.1, None], np.array([0.1, np.nan]), np.array([True])]


@pytest.mark.parametrize("value", BAD_NUMBERS, ids=repr)
def test_a_bad_epsilon_is_a_typed_error(duffing, mode, value):
    calls = [duffing.frequency, duffing.truncation_error_estimate, lambda eps: duffing.displacement(1.0, eps),
             lambda eps: duffing.velocity(1.0, eps), mode.frequency, mode.truncation_error_estimate,
             lambda eps: mode.displacement(1.0, eps)]
    for call in calls:
        with pytest.raises(ParameterError, match="epsilon"):
            call(value)


@pytest.mark.parametrize("value", BAD_NUMBERS, ids=repr)
def test_a_bad_time_is_a_typed_error(duffing, mode, value):
    for call in (lambda t: duffing.displacement(t, 0.1), lambda t: duffing.displacement_error_estimate(t, 0.1),
                 lambda t: mode.modal_displacement(t, 0.1)):
        with pytest.raises(ParameterError, match="t"):
            call(value)


def _duffing_frequency(eps: Fraction) -> Fraction:
    return 1 + Fraction(3, 8) * eps - Fraction(21, 256) * eps**2


def test_exact_fractions_are_read_exactly(duffing):
    expected = float(_duffing_frequency(Fraction(1, 8)))
    assert duffing.frequency("1/8") == pytest.approx(expected, rel=4e-16, abs=0)
    assert duffing.frequency(Fraction(1, 8)) == pytest.approx(expected, rel=4e-16, abs=0)
    assert duffing.frequency("1/10") == duffing.frequency(0.1)
    assert duffing.displacement("0", "1/8") == duffing.displacement(0.0, 0.125) == 1.0  # u(0) = a0


def test_arrays_stay_vectorised(duffing, mode):
    eps = np.array([0.0, 0.05, 0.125])
    expected = [float(_duffing_frequency(Fraction(x))) for x in eps]
    assert duffing.frequency(eps) == pytest.approx(expected, rel=4e-16, abs=0)
    assert duffing.frequency([0, "1/20", 0.125]) == pytest.approx(expected, rel=4e-16, abs=0)
    assert np.array_equal(mode.frequency(eps), [mode.frequency(x) for x in eps])
    times = np.linspace(0.0, 3.0, 5)
    assert np.array_equal(duffing.displacement(times, 0.1), [duffing.displacement(t, 0.1) for t in times])


def test_one_epsilon_where_the_api_takes_one(duffing, mode):
    with pytest.raises(ParameterError, match="one number"):
        duffing.displacement_error_estimate(1.0, np.array([0.1, 0.2]))
    with pytest.raises(ParameterError, match="one number"):
        mode.release_state([0.1, 0.2])


# ----------------------------------------------------------------------------------------------- command line
def _cli(*arguments: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "lindstedt", *arguments], capture_output=True, text=True, timeout=120)


@pytest.mark.parametrize("arguments, expected", [
    (["expand", "sqrt(-1)*u**3", "--a0", "1", "--omega0", "1"], "'sqrt(-1)' is not a real number"),
    (["expand", "(-8)**(1/3)*u**3", "--a0", "1", "--omega0", "1"], "-8**(1/3)"),
    (["expand", "c*u**3", "--param", "c=log(-1)", "--a0", "1", "--omega0", "1"], "'log(-1)' is not a real number"),
    (["expand", "u**3", "--a0", "acos(2)", "--omega0", "1"], "'acos(2)' is not a real number"),
    (["expand", "(u**200)**200", "--a0", "1", "--omega0", "1"], "degree 40000"),
    (["expand", "((u+1)**200)**200", "--a0", "1", "--omega0", "1"], "degree 40000"),
    (["expand", "u**3", "--a0", "1", "--omega0", "1", "--eps", "nan"], "--eps"),
    (["expand", "u**3", "--a0", "1", "--omega0", "1", "--eps", "1e400"], "--eps"),
    (["expand", "u**3", "--a0", "1", "--omega0", "1", "--eps", "sqrt(-1)"], "not a real number"),
])
def test_the_command_line_refuses_with_one_error_line(arguments, expected):
    result = _cli(*arguments)
    assert result.returncode == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:") and expected in lines[0], result.stderr
    assert "Traceback" not in result.stderr


def test_the_command_line_reads_an_exact_epsilon():
    result = _cli("expand", "u**3", "--a0", "1", "--omega0", "1", "--eps", "1/8", "--format", "plain")
    assert result.returncode == 0, result.stderr
    assert f"omega(0.125) = {float(_duffing_frequency(Fraction(1, 8)))!r}" in result.stdout
