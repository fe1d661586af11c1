"""Readable symbolic output (issue 24, item 5): closed forms in the contact angles, simplified problem headers.

The compact form of a coefficient is checked to be an identity: with κ, β, σ replaced by their definitions it
equals the coefficient the derivation returned (the reference), at several rational parameter values to 60 digits.
ω_1 of the gap is compared exactly with the textbook closed form (β − κ sin β)/(2π ω0), from the first Fourier
coefficient c_1 = (β − κ sin β)/π of the contact ramp (cos s − κ)_+.
"""

from __future__ import annotations

import pytest
import sympy

import lindstedt
from lindstedt.algebra import in_contact_angles
from lindstedt.cli import main

DIGITS = 60
#: The old plain and pretty ω_2 of `lindstedt expand "Max(0, u - b)" --param b` ran to 1,357 and ~15,000 characters.
SHORT = 400
POINTS = ({"b": sympy.Rational(1, 3), "a0": 1, "omega0": 1, "k": 1},
          {"b": sympy.Rational(-2, 7), "a0": sympy.Rational(3, 2), "omega0": sympy.Rational(5, 4), "k": 7},
          {"b": sympy.Rational(9, 10), "a0": sympy.Rational(11, 10), "omega0": 2, "k": sympy.Rational(3, 5)})


def _at(expression, point):
    point = {**point, "kappa": point["b"]}  # a parameter of f named kappa, as in the README
    return expression.subs({symbol: point[symbol.name] for symbol in expression.free_symbols if symbol.name in point})


def _assert_equal(reference, expression):
    """``expression`` equals ``reference`` at every point of POINTS to DIGITS digits."""
    for point in POINTS:
        exact = sympy.N(_at(reference, point), DIGITS)
        value = sympy.N(_at(expression, point), DIGITS)
        assert exact.is_number and abs(value - exact) <= sympy.Float(10) ** (5 - DIGITS) * (1 + abs(exact))


def _assert_identity(originals, form):
    for original, compact in zip(originals, form.forms, strict=True):
        _assert_equal(original, form.restore(compact))


@pytest.mark.parametrize("f, options", [
    ("Max(0, u - b)", {}),
    ("Max(0, u - b)", {"a0": 1}),
    ("Max(0, u - b)**2", {}),
    ("k*Max(0, u - b)", {"params": {"b": None, "k": None}}),
    ("Max(0, u - b)", {"normalization": "harmonic"}),
])
def test_the_compact_form_is_an_identity(f, options):
    options = {"params": {"b": None}, **options}
    expansion = lindstedt.expand(f, order=2, **options)
    form = in_contact_angles(expansion.omega)
    kappa, beta, sigma = (symbol for symbol, _ in form.definitions)
    assert [definition for _, definition in form.definitions][1:] == [sympy.acos(kappa), sympy.sqrt(1 - kappa**2)]
    for compact in form.forms[1:]:
        assert not compact.has(sympy.acos) and compact.has(beta) and len(str(compact)) < SHORT
    _assert_identity(expansion.omega, form)


def test_omega_1_of_the_gap_is_the_textbook_closed_form():
    expansion = lindstedt.expand("Max(0, u - b)", order=1, params={"b": None})
    form = in_contact_angles(expansion.omega)
    (kappa, kappa_definition), (beta, _), (sigma, _) = form.definitions
    a0, b, omega0 = sorted(expansion.problem.free_symbols, key=str)
    assert kappa_definition == b / a0
    assert sympy.simplify(form.forms[1] - (beta - kappa * sigma) / (2 * sympy.pi * omega0)) == 0


def test_expressions_without_a_symbolic_contact_angle_are_left_alone():
    expansion = lindstedt.expand("Max(0, u - 1/3)", order=2, a0=1, omega0=1)
    form = in_contact_angles(expansion.omega)
    assert form.definitions == () and form.forms == expansion.omega


def test_a_parameter_named_kappa_keeps_its_name():
    expansion = lindstedt.expand("Max(0, u - kappa)", order=2, a0=1, omega0=1, params={"kappa": None})
    form = in_contact_angles(expansion.omega)
    names = [symbol.name for symbol, _ in form.definitions]
    assert names == ["kappa_1", "beta", "sigma"] and str(form.definitions[0][1]) == "kappa"
    _assert_identity(expansion.omega, form)


def test_expand_prints_omega_2_of_a_symbolic_gap_in_the_contact_angles(capsys):
    assert main(["expand", "Max(0, u - b)", "--param", "b", "--format", "plain"]) == 0
    lines = capsys.readouterr().out.splitlines()
    where = [line for line in lines if line.lstrip().startswith("where")]
    assert where == ["  where kappa = b/a0, beta = acos(kappa), sigma = sqrt(1 - kappa**2)"]
    omega_2 = next(line for line in lines if line.startswith("  omega_2 = "))
    assert len(omega_2) < SHORT and "acos" not in omega_2 and all(name in omega_2 for name in ("beta", "kappa", "sigma"))
    # the printed text, read back with the printed definitions, is the expansion's omega_2
    expansion = lindstedt.expand("Max(0, u - b)", order=2, params={"b": None})
    names = {symbol.name: symbol for symbol in expansion.problem.free_symbols}
    kappa, beta, sigma = sympy.symbols("kappa beta sigma")
    printed = sympy.sympify(omega_2.split(" = ", 1)[1], locals={**names, "kappa": kappa, "beta": beta, "sigma": sigma})
    restored = printed.subs(sigma, sympy.sqrt(1 - kappa**2)).subs(beta, sympy.acos(kappa)).subs(kappa, names["b"] / names["a0"])
    _assert_equal(expansion.omega[2], restored)


def test_pretty_expand_prints_the_definitions_once_and_a_short_omega_2(capsys):
    assert main(["expand", "Max(0, u - b)", "--param", "b"]) == 0
    text = capsys.readouterr().out
    blocks = text.split("\n")
    assert sum("where" in line for line in blocks) == 1
    where = next(index for index, line in enumerate(blocks) if "where" in line)
    assert all(symbol in "\n".join(blocks[where - 2:where + 2]) for symbol in ("κ", "β = acos(κ)", "σ", "a₀"))
    start = next(index for index, line in enumerate(blocks) if "ω₂ =" in line) - 1  # the numerator's line above
    omega_2 = "\n".join(blocks[start:])
    assert len(omega_2) < SHORT and "acos" not in omega_2 and "β" in omega_2
    assert len(text) < 1200  # the whole output (it was 16,887 characters)


@pytest.mark.parametrize("problem, header", [
    (lambda: lindstedt.ForcedOscillator("u**3", omega0=1, zeta="1/100"),
     "u'' + u'/50 + u + eps*(u**3) = eps*cos(Omega*t)"),
    (lambda: lindstedt.ForcedOscillator("Max(0, u - b)", omega0=2, zeta="1/20", forcing="-1/2", params={"b": "1/5"}),
     "u'' + u'/5 + 4*u + eps*(Max(0, u - 1/5)) = -eps*cos(Omega*t)/2"),
    (lambda: lindstedt.ForcedOscillator("u**3", omega0=1),
     "u'' + u + eps*(u**3) = eps*cos(Omega*t)"),
    (lambda: lindstedt.Oscillator("u**3", a0=1, omega0=2, a1="-1/10"),
     "u'' + 4*u + eps*(u**3) = 0, u(0) = 1 - eps/10 [initial]"),
    (lambda: lindstedt.Oscillator("u**3", a0=1, omega0=1),
     "u'' + u + eps*(u**3) = 0, u(0) = 1 [initial]"),
])
def test_problem_headers_are_simplified(problem, header):
    assert problem().describe() == header


def test_the_forced_command_prints_the_simplified_header(capsys):
    assert main(["forced", "u**3", "--eps", "0.1", "--omega0", "1", "--zeta", "1/100", "--method", "multiple-scales",
                 "--from", "0.9", "--to", "1.1", "--format", "plain"]) == 0
    assert "  problem=\"u'' + u'/50 + u + eps*(u**3) = eps*cos(Omega*t)\"," in capsys.readouterr().out.splitlines()
