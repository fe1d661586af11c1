"""Piecewise(...) as input: a string (through the one parser) or a sympy object, for piecewise-linear f.

The reference for each case is the same law written with Max/Heaviside/sign, whose expansion is checked
against exact periods elsewhere (tests/test_piecewise_expansion.py, tests/test_jumps.py): equal exactly.
"""

from __future__ import annotations

import pytest
import sympy

import lindstedt

U = sympy.Symbol("u", real=True)


@pytest.mark.parametrize(
    "piecewise, same",
    [
        ("Piecewise((u, u > 0), (0, True))", "Max(0, u)"),
        ("Piecewise((0, u < 1/3), (2*u - 2/3, True))", "2*Max(0, u - 1/3)"),
        ("Piecewise((-1, u < 0), (1, True))", "sign(u)"),
        ("Piecewise((0, u <= -1/2), (1, True))", "Heaviside(u + 1/2)"),
        ("Piecewise((u + 1, u < -1), (0, u < 1/2), (u - 1/2, True))", "Min(0, u + 1) + Max(0, u - 1/2)"),
    ],
)
def test_piecewise_string_equals_the_same_law_written_with_switches(piecewise, same):
    ours = lindstedt.expand(piecewise, order=3, a0=1, omega0=1)
    reference = lindstedt.expand(same, order=3, a0=1, omega0=1)
    assert ours.gauge == reference.gauge and len(ours.omega) == len(reference.omega)
    assert [sympy.simplify(a - b) for a, b in zip(ours.omega, reference.omega)] == [0] * len(reference.omega)
    assert ours.contact_angles == reference.contact_angles


def test_piecewise_sympy_object_and_symbolic_gap():
    b = sympy.Symbol("b", real=True)
    from_object = lindstedt.expand(sympy.Piecewise((0, U < sympy.Rational(1, 3)), (U - sympy.Rational(1, 3), True)), order=2, a0=1, omega0=1)
    assert from_object.omega == lindstedt.expand("Max(0, u - 1/3)", order=2, a0=1, omega0=1).omega
    symbolic = lindstedt.expand("Piecewise((0, u < b), (u - b, True))", order=1, params={"b": None})
    reference = lindstedt.expand("Max(0, u - b)", order=1, params={"b": None})
    assert sympy.simplify(symbolic.omega[1] - reference.omega[1].subs(sympy.Symbol("b", real=True), b)) == 0


@pytest.mark.parametrize(
    "text, fragment",
    [
        ("u > 0", "comparisons"),
        ("(u, 1)", "tuples"),
        ("Piecewise((u, 0 < u < 1), (0, True))", "one comparison"),
        ("Piecewise((u, u == 0), (0, True))", "one comparison"),
        ("Piecewise((u, True), (0, u > 0))", "only the last"),
        ("Piecewise(u, u > 0)", "pair"),
        ("Piecewise((u, u > 0, 1), (0, True))", "pair"),
        ("Piecewise((u, u > 0) and (0, True))", "pair"),
        ("Piecewise((u, (u > 0) or (u < -1)), (0, True))", "one comparison"),
    ],
)
def test_the_parser_accepts_comparisons_only_as_piecewise_conditions(text, fragment):
    with pytest.raises(lindstedt.ProblemError, match=fragment):
        lindstedt.Oscillator(text)


def test_piecewise_must_cover_the_orbit():
    with pytest.raises(lindstedt.UnsupportedNonlinearityError, match="undefined"):
        lindstedt.expand("Piecewise((u, u > 0))", order=1, a0=1, omega0=1)
    with pytest.raises(lindstedt.UnsupportedNonlinearityError, match="holds a turning point"):
        lindstedt.expand("Piecewise((0, u < 0), (sin(u), u < 1/2), (0, True))", order=1, a0=1, omega0=1)
