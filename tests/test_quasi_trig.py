"""Tests of lindstedt._quasi_trig: piecewise quasi-trigonometric calculus and the even periodic solve.

Expectations come from exact identities checked with sympy (substitution back into
the equation, evaluation at the breakpoints), from mpmath quadrature of the
defining integrals, and from sympy's own ``integrate`` used only as a reference.
"""

from __future__ import annotations

import doctest

import mpmath
import numpy as np
import pytest
import sympy
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import lindstedt._quasi_trig as quasi_trig
from lindstedt._errors import ProblemError, ResonanceError
from lindstedt._quasi_trig import (
    S,
    PiecewiseQuasiTrig,
    QuasiTrigPolynomial,
    contact_ramp_function,
    contact_step_function,
    solve_even_periodic,
)

ALPHA0 = sympy.Symbol("alpha0", positive=True)
KAPPA = sympy.Symbol("kappa", real=True)


def exactly_zero(expr: sympy.Expr) -> bool:
    return sympy.simplify(sympy.expand_trig(expr)) == 0


def numeric(expr: sympy.Expr, digits: int = 30) -> mpmath.mpf:
    return mpmath.mpf(sympy.N(expr, digits + 10))


def quad_cosine_coefficient(function, k: int, breakpoints) -> mpmath.mpf:
    """(2/pi) int_0^pi f cos(ks) (1/pi for k = 0) by mpmath.quad split at the breakpoints."""
    weight = 1 / mpmath.pi if k == 0 else 2 / mpmath.pi
    return weight * mpmath.quad(lambda t: function(t) * mpmath.cos(k * t), breakpoints)


def ramp_coefficient_by_sympy(k: int, kappa: sympy.Expr) -> sympy.Expr:
    """Independent exact c_k[kappa] from sympy.integrate of the defining integral."""
    angle = sympy.acos(kappa)
    weight = 1 / sympy.pi if k == 0 else 2 / sympy.pi
    return weight * sympy.integrate((sympy.cos(S) - kappa) * sympy.cos(k * S), (S, 0, angle))


# ---------------------------------------------------------------------------
# single pieces
# ---------------------------------------------------------------------------


def test_parse_round_trip_and_product_to_sum() -> None:
    expr = 3 * S**2 * sympy.cos(2 * S) * sympy.sin(S) - sympy.Rational(1, 2) * sympy.cos(S) ** 3 + 7
    piece = QuasiTrigPolynomial.from_expr(expr, S)
    rebuilt = piece.to_expr(S)
    for point in (sympy.Rational(1, 3), sympy.Rational(5, 2), sympy.Integer(-4)):
        assert abs(sympy.N((rebuilt - expr).subs(S, point), 40)) < 1e-35
    kinds = {kind for (_, kind, _), _ in piece.terms}
    assert kinds == {"cos", "sin"}
    assert all(frequency >= 0 for (_, _, frequency), _ in piece.terms)


@pytest.mark.parametrize(
    "expr",
    [sympy.exp(S), sympy.cos(S / 2), sympy.cos(S + 1), 1 / S, sympy.sqrt(S), sympy.Abs(sympy.cos(S)), sympy.cos(S) ** -1],
)
def test_parse_rejects_non_quasi_trig_expressions(expr: sympy.Expr) -> None:
    with pytest.raises(ProblemError):
        QuasiTrigPolynomial.from_expr(expr, S)


def test_antiderivatives_match_sympy_integrate() -> None:
    for power in range(4):
        for frequency in range(4):
            for trig in (sympy.cos, sympy.sin):
                expr = S**power * trig(frequency * S)
                primitive = QuasiTrigPolynomial.from_expr(expr, S).antiderivative().to_expr(S)
                reference = sympy.integrate(expr, S)
                assert sympy.simplify(sympy.diff(primitive - reference, S)) == 0
                assert QuasiTrigPolynomial.from_expr(primitive, S).derivative() == QuasiTrigPolynomial.from_expr(expr, S)


def test_particular_solutions_solve_the_forced_oscillator() -> None:
    for power in range(4):
        for frequency in range(5):
            for trig in (sympy.cos, sympy.sin):
                forcing = S**power * trig(frequency * S)
                particular = QuasiTrigPolynomial.from_expr(forcing, S).particular_solution().to_expr(S)
                residual = sympy.diff(particular, S, 2) + particular - forcing
                assert sympy.simplify(residual) == 0, (power, frequency, trig)


def test_resonant_particular_solution_is_secular() -> None:
    particular = QuasiTrigPolynomial.from_expr(S * sympy.cos(S), S).particular_solution()
    assert max(power for (power, _, _), _ in particular.terms) == 2


def test_symbolic_frequency_cannot_be_solved() -> None:
    k = sympy.Symbol("k", integer=True, positive=True)
    piece = QuasiTrigPolynomial.from_terms({(0, "cos", k): 1})
    with pytest.raises(ProblemError, match="symbolic"):
        piece.particular_solution()


def test_evaluate_canonicalises_trigonometric_values() -> None:
    piece = QuasiTrigPolynomial.from_expr(sympy.cos(4 * S) - 8 * sympy.cos(S) ** 4 + 8 * sympy.cos(S) ** 2, S)
    assert piece.evaluate(sympy.acos(KAPPA)) == 1  # cos 4x = 8 cos^4 x - 8 cos^2 x + 1


# ---------------------------------------------------------------------------
# piecewise functions: integrals, coefficients, evaluation
# ---------------------------------------------------------------------------


def _sample_function() -> PiecewiseQuasiTrig:
    return PiecewiseQuasiTrig.from_expressions(
        [S**2 * sympy.cos(3 * S) - 2, sympy.Rational(3, 2) * S * sympy.sin(2 * S) + sympy.cos(S), 5 - S],
        [sympy.acos(sympy.Rational(1, 3)), 2 * sympy.pi / 3],
    )


def _as_mp_function(function: PiecewiseQuasiTrig):
    pieces = [sympy.lambdify(S, piece.to_expr(S), "mpmath") for piece in function.pieces]
    edges = [numeric(point) for point in function.breakpoints]

    def evaluate(t):
        for index in range(len(pieces) - 1, -1, -1):
            if t >= edges[index]:
                return pieces[index](t)
        return pieces[0](t)

    return evaluate, edges


def test_integrals_and_cosine_coefficients_match_quadrature() -> None:
    function = _sample_function()
    with mpmath.workdps(30):
        evaluate, edges = _as_mp_function(function)
        assert abs(numeric(function.integral()) - mpmath.quad(evaluate, edges)) < 1e-25
        assert abs(numeric(function.integral(1, 2)) - mpmath.quad(evaluate, edges[1:3])) < 1e-25
        coefficients = function.cosine_coefficients(6)
        for k, coefficient in enumerate(coefficients):
            assert abs(numeric(coefficient) - quad_cosine_coefficient(evaluate, k, edges)) < 1e-25


def test_integral_index_validation() -> None:
    with pytest.raises(ProblemError):
        _sample_function().integral(2, 1)


def test_symbolic_harmonic_coefficient_reduces_to_integer_values() -> None:
    k = sympy.Symbol("k", integer=True, positive=True)
    function = _sample_function()
    generic = function.cosine_coefficient(k)
    for value in range(4, 9):  # larger than every frequency in the pieces
        difference = generic.subs(k, value) - function.cosine_coefficient(value)
        assert abs(sympy.N(difference, 40)) < 1e-30


def test_exact_and_float_evaluation_with_even_periodic_extension() -> None:
    function = _sample_function()
    piecewise = function.to_piecewise(S)
    points = [sympy.Rational(1, 5), sympy.Rational(3, 2), sympy.Rational(5, 2), sympy.Integer(3)]
    for point in points:
        expected = piecewise.subs(S, point)
        assert sympy.simplify(function.evaluate(point) - expected) == 0
        assert sympy.simplify(function.evaluate(-point) - expected) == 0
        assert sympy.simplify(function.evaluate(point + 4 * sympy.pi) - expected) == 0
    grid = np.linspace(-7.0, 7.0, 301)
    values = function.evaluate_float(grid)
    reduced = np.mod(np.abs(grid), 2 * np.pi)
    reduced = np.where(reduced > np.pi, 2 * np.pi - reduced, reduced)
    expected_values = np.array([float(piecewise.subs(S, float(t))) for t in reduced])
    np.testing.assert_allclose(values, expected_values, rtol=1e-13, atol=1e-13)


def test_float_evaluation_needs_substitutions_for_symbols() -> None:
    ramp = contact_ramp_function(KAPPA)
    with pytest.raises(ProblemError, match="substitutions"):
        ramp.evaluate_float(np.array([0.1]))
    values = ramp.evaluate_float(np.array([0.0, 1.0, 2.0]), {KAPPA: 0.25})
    np.testing.assert_allclose(values, [0.75, np.cos(1.0) - 0.25, 0.0], rtol=1e-15, atol=1e-15)


def test_sum_of_functions_with_different_breakpoints_uses_the_union() -> None:
    first = PiecewiseQuasiTrig.from_expressions([1, S], [sympy.pi / 3])
    second = PiecewiseQuasiTrig.from_expressions([sympy.cos(S), 2], [sympy.pi / 2])
    total = first + second
    assert total.breakpoints == (0, sympy.pi / 3, sympy.pi / 2, sympy.pi)
    assert total.pieces[1].to_expr(S) == S + sympy.cos(S)
    symbolic = contact_ramp_function(KAPPA)
    with pytest.raises(ProblemError, match="cannot order"):
        symbolic + first
    assert (symbolic + 1).breakpoints == symbolic.breakpoints


def test_construction_validation() -> None:
    piece = QuasiTrigPolynomial.constant(1)
    with pytest.raises(ProblemError):
        PiecewiseQuasiTrig((0, 1), (piece,))
    with pytest.raises(ProblemError):
        PiecewiseQuasiTrig((0, 2, 1, sympy.pi), (piece, piece, piece))
    with pytest.raises(ProblemError):
        PiecewiseQuasiTrig((0, sympy.pi), (piece, piece))


# ---------------------------------------------------------------------------
# |cos s| and the contact functions
# ---------------------------------------------------------------------------


def test_absolute_cosine_fourier_series() -> None:
    absolute_cosine = 2 * contact_ramp_function(0) - PiecewiseQuasiTrig.from_expression(sympy.cos(S))
    coefficients = absolute_cosine.cosine_coefficients(12)
    with mpmath.workdps(30):
        for n, coefficient in enumerate(coefficients):
            by_quadrature = quad_cosine_coefficient(lambda t: abs(mpmath.cos(t)), n, [0, mpmath.pi / 2, mpmath.pi])
            assert abs(numeric(coefficient) - by_quadrature) < 1e-25
    # |cos s| = 2/pi - (4/pi) sum_k (-1)^k cos(2ks)/(4k^2 - 1): verified above by quadrature, here exactly.
    assert coefficients[0] == 2 / sympy.pi
    for n in range(1, 13):
        k = n // 2
        expected = -4 * (-1) ** k / (sympy.pi * (4 * k * k - 1)) if n % 2 == 0 else 0
        assert sympy.simplify(coefficients[n] - expected) == 0


@pytest.mark.parametrize("kappa", [sympy.Rational(1, 3), sympy.Rational(-3, 5)])
def test_contact_functions_have_the_expected_coefficients(kappa: sympy.Rational) -> None:
    ramp = contact_ramp_function(kappa)
    step = contact_step_function(kappa)
    for k in range(6):
        assert exactly_zero(ramp.cosine_coefficient(k) - ramp_coefficient_by_sympy(k, kappa))
        weight = 1 / sympy.pi if k == 0 else 2 / sympy.pi
        expected_step = weight * sympy.integrate(sympy.cos(k * S), (S, 0, sympy.acos(kappa)))
        assert exactly_zero(step.cosine_coefficient(k) - expected_step)


def test_contact_functions_outside_the_unit_interval() -> None:
    assert contact_ramp_function(1).integral() == 0
    assert contact_step_function(sympy.Rational(3, 2)).integral() == 0
    assert contact_ramp_function(-2).integral() == 2 * sympy.pi
    assert contact_step_function(-1).integral() == sympy.pi


# ---------------------------------------------------------------------------
# the even periodic solve
# ---------------------------------------------------------------------------


def _contact_rhs(kappa: sympy.Expr) -> tuple[PiecewiseQuasiTrig, sympy.Expr]:
    angle = sympy.acos(kappa)
    first_harmonic = (angle - kappa * sympy.sqrt(1 - kappa**2)) / sympy.pi  # c_1 derived by hand
    rhs = contact_ramp_function(kappa) - PiecewiseQuasiTrig.from_expression(first_harmonic * sympy.cos(S))
    return rhs, first_harmonic


def _check_solution(v: PiecewiseQuasiTrig, rhs: PiecewiseQuasiTrig, alpha0: sympy.Expr) -> None:
    """Substitute back with sympy expressions (not the module's algebra) and check C^1 and evenness."""
    for solution_piece, rhs_piece in zip(v.pieces, rhs.pieces):
        expression = solution_piece.to_expr(S)
        residual = alpha0 * (sympy.diff(expression, S, 2) + expression) - rhs_piece.to_expr(S)
        assert sympy.simplify(residual) == 0
    for index, point in enumerate(v.breakpoints[1:-1]):
        left, right = v.pieces[index].to_expr(S), v.pieces[index + 1].to_expr(S)
        for order in (0, 1):
            jump = (sympy.diff(left, S, order) - sympy.diff(right, S, order)).subs(S, point)
            assert sympy.simplify(sympy.expand_trig(jump)) == 0
    assert sympy.simplify(sympy.diff(v.pieces[0].to_expr(S), S).subs(S, 0)) == 0
    assert sympy.simplify(sympy.diff(v.pieces[-1].to_expr(S), S).subs(S, sympy.pi)) == 0


def test_solve_contact_rhs_exactly_for_rational_kappa() -> None:
    kappa = sympy.Rational(1, 3)
    rhs, _ = _contact_rhs(kappa)
    v = solve_even_periodic(rhs, ALPHA0, zero_first_harmonic=True)
    _check_solution(v, rhs, ALPHA0)
    assert v.jumps(0) == (0,) and v.jumps(1) == (0,)
    coefficients = v.cosine_coefficients(6)
    assert coefficients[1] == 0
    for k in (0, 2, 3, 4, 5, 6):
        expected = ramp_coefficient_by_sympy(k, kappa) / (ALPHA0 * (1 - k**2))
        assert exactly_zero(coefficients[k] - expected)


def test_solve_contact_rhs_with_symbolic_kappa_stays_symbolic() -> None:
    rhs, _ = _contact_rhs(KAPPA)
    v = solve_even_periodic(rhs, ALPHA0, zero_first_harmonic=True)
    assert v.breakpoints[1] == sympy.acos(KAPPA)
    assert KAPPA in v.free_symbols and ALPHA0 in v.free_symbols
    _check_solution(v, rhs, ALPHA0)
    coefficients = v.cosine_coefficients(4)
    assert coefficients[1] == 0
    for value in (sympy.Rational(1, 4), sympy.Rational(-2, 3)):
        for k in (0, 2, 3, 4):
            expected = ramp_coefficient_by_sympy(k, value) / (1 - k**2)
            got = coefficients[k].subs({KAPPA: value, ALPHA0: 1})
            assert abs(sympy.N(got - expected, 40)) < 1e-30


def test_solve_with_value_at_zero() -> None:
    kappa = sympy.Rational(-1, 2)
    rhs, _ = _contact_rhs(kappa)
    a1 = sympy.Rational(7, 5)
    v = solve_even_periodic(rhs, 2, value_at_zero=a1)
    assert v.evaluate(0) == a1
    _check_solution(v, rhs, sympy.Integer(2))
    reference = solve_even_periodic(rhs, 2, zero_first_harmonic=True)
    difference = v - reference  # differs by a multiple of cos s only
    shift = difference.pieces[0].as_dict()[(0, "cos", 1)]
    assert all(piece.as_dict() == {(0, "cos", 1): shift} for piece in difference.pieces)


def test_solve_absolute_cosine_case() -> None:
    # kappa = 0: (cos s)_+ - cos(s)/2 = |cos s|/2, so d_k = c_k / (alpha0 (1 - k^2)) with c_k of |cos s|/2.
    rhs, first_harmonic = _contact_rhs(sympy.Integer(0))
    assert first_harmonic == sympy.Rational(1, 2)
    v = solve_even_periodic(rhs, ALPHA0, zero_first_harmonic=True)
    _check_solution(v, rhs, ALPHA0)
    coefficients = v.cosine_coefficients(8)
    with mpmath.workdps(30):
        for n in (0, 2, 3, 4, 6, 8):
            half_abs = quad_cosine_coefficient(lambda t: abs(mpmath.cos(t)) / 2, n, [0, mpmath.pi / 2, mpmath.pi])
            assert abs(numeric(coefficients[n].subs(ALPHA0, 1)) - half_abs / (1 - n * n)) < 1e-25


def test_secular_rhs_raises_resonance_error_naming_the_coefficient() -> None:
    with pytest.raises(ResonanceError, match=r"secular cos\(s\) coefficient"):
        solve_even_periodic(contact_ramp_function(sympy.Rational(1, 3)), 1, zero_first_harmonic=True)
    with pytest.raises(ResonanceError):
        solve_even_periodic(PiecewiseQuasiTrig.from_expression(S * sympy.sin(S)), 1, value_at_zero=0)


def test_solve_argument_validation() -> None:
    rhs = PiecewiseQuasiTrig.from_expression(sympy.cos(2 * S))
    with pytest.raises(ProblemError, match="exactly once"):
        solve_even_periodic(rhs, 1)
    with pytest.raises(ProblemError, match="exactly once"):
        solve_even_periodic(rhs, 1, value_at_zero=0, zero_first_harmonic=True)
    with pytest.raises(ProblemError, match="alpha0"):
        solve_even_periodic(rhs, 0, zero_first_harmonic=True)
    with pytest.raises(ProblemError):
        solve_even_periodic(sympy.cos(S), 1, zero_first_harmonic=True)


# ---------------------------------------------------------------------------
# property tests
# ---------------------------------------------------------------------------

BREAKPOINT_SETS = [
    (sympy.pi / 3,),
    (sympy.pi / 4, 2 * sympy.pi / 3),
    (sympy.pi / 2,),
]
small_rational = st.fractions(min_value=-3, max_value=3, max_denominator=4).map(lambda f: sympy.Rational(f.numerator, f.denominator))
term_strategy = st.tuples(st.integers(0, 2), st.sampled_from(["cos", "sin"]), st.integers(0, 3), small_rational)


@st.composite
def pieces(draw) -> QuasiTrigPolynomial:
    terms = draw(st.lists(term_strategy, min_size=1, max_size=3))
    return QuasiTrigPolynomial.from_terms([((power, kind, frequency), value) for power, kind, frequency, value in terms])


@st.composite
def piecewise_functions(draw, breakpoints=None) -> PiecewiseQuasiTrig:
    interior = draw(st.sampled_from(BREAKPOINT_SETS)) if breakpoints is None else breakpoints
    drawn = [draw(pieces()) for _ in range(len(interior) + 1)]
    return PiecewiseQuasiTrig((sympy.Integer(0),) + tuple(interior) + (sympy.pi,), tuple(drawn))


def _remove_secular(function: PiecewiseQuasiTrig) -> PiecewiseQuasiTrig:
    return function - PiecewiseQuasiTrig.from_expression(function.cosine_coefficient(1) * sympy.cos(S))


PROPERTY_SETTINGS = settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
GRID = np.linspace(-4.0, 10.0, 97)


@PROPERTY_SETTINGS
@given(pieces(), pieces())
def test_product_commutes_and_obeys_the_product_rule(first: QuasiTrigPolynomial, second: QuasiTrigPolynomial) -> None:
    assert first * second == second * first
    assert (first * second).derivative() == first.derivative() * second + first * second.derivative()
    grid = np.linspace(-2.0, 5.0, 41)
    np.testing.assert_allclose(
        (first * second).evaluate_float(grid),
        first.evaluate_float(grid) * second.evaluate_float(grid),
        rtol=1e-12,
        atol=1e-12,
    )


@PROPERTY_SETTINGS
@given(piecewise_functions())
def test_integral_is_additive_over_pieces(function: PiecewiseQuasiTrig) -> None:
    total = function.integral()
    parts = sum((function.integral(index, index + 1) for index in range(len(function.pieces))), sympy.Integer(0))
    assert sympy.expand(total - parts) == 0


@PROPERTY_SETTINGS
@given(st.data())
def test_solve_is_linear(data) -> None:
    interior = data.draw(st.sampled_from(BREAKPOINT_SETS))
    first = _remove_secular(data.draw(piecewise_functions(interior)))
    second = _remove_secular(data.draw(piecewise_functions(interior)))
    weight_a, weight_b = data.draw(small_rational), data.draw(small_rational)
    combined = solve_even_periodic(weight_a * first + weight_b * second, 3, zero_first_harmonic=True)
    separate_a = solve_even_periodic(first, 3, zero_first_harmonic=True)
    separate_b = solve_even_periodic(second, 3, zero_first_harmonic=True)
    expected = float(weight_a) * separate_a.evaluate_float(GRID) + float(weight_b) * separate_b.evaluate_float(GRID)
    np.testing.assert_allclose(combined.evaluate_float(GRID), expected, rtol=1e-11, atol=1e-11)
    assert combined.equals(weight_a * separate_a + weight_b * separate_b) is True


@PROPERTY_SETTINGS
@given(piecewise_functions())
def test_solution_is_c1_and_solves_the_equation(function: PiecewiseQuasiTrig) -> None:
    rhs = _remove_secular(function)
    v = solve_even_periodic(rhs, sympy.Rational(5, 2), value_at_zero=1)
    residual = sympy.Rational(5, 2) * (v.derivative().derivative() + v) - rhs
    assert all(piece.is_zero for piece in residual.pieces)
    assert all(jump == 0 for jump in v.jumps(0) + v.jumps(1))
    assert v.pieces[0].derivative().evaluate(0) == 0
    assert v.pieces[-1].derivative().evaluate(sympy.pi) == 0
    assert v.evaluate(0) == 1
    # float cross-check of C^1 continuity with finite differences across each breakpoint
    for point in v.breakpoints_float()[1:-1]:
        left, right = v.evaluate_float(np.array([point - 1e-7, point + 1e-7]))
        assert abs(left - right) <= 1e-5 * max(1.0, abs(left))


def test_module_examples_run() -> None:
    failures, attempted = doctest.testmod(quasi_trig, optionflags=doctest.ELLIPSIS)
    assert attempted > 10
    assert failures == 0
