"""Compiled evaluators: Expansion.frequency / displacement / velocity / frequency_coefficients.

The evaluators read float parameter values through closed forms compiled once per expansion
(:func:`lindstedt.compiled.family.compile_family`), accepted only where their first-order rounding bound is
at most 1e-13 of the value, with exact series in acos κ (one gap symbol) or the exact expression elsewhere.

References are independent of that code: the exact sympy expressions (``omega_correction``,
``frequency_expr``, ``displacement_expr``) evaluated with mpmath at 50 digits at the exact binary value of
the double inputs, cross-checked at 100 digits (the closed forms cancel at most ~25 digits at κ = ±(1 − 1e-6)
for ω_3 ∝ (1 − κ)^{7/2}, so 50 digits leave > 20 correct).

Tolerances.  ω_k: 1e-13 relative (the acceptance bound of the compiled value; the stable series are validated
to 1e-13 at generation; the exact expression is correctly rounded).  ω(ε) = Σ ω_k ε^k: 2e-13 relative (1e-13
per coefficient plus a few roundings of the Horner sum, |ω_k ε^k| ≤ |ω_0|).  u(t): 1e-12 |a0| (1e-13 from the
waveform data, plus the rounding of ω t (t ≤ 10, ~1e-15 rad) and of ≤ 30 trig terms of size ≤ 1).
"""

from __future__ import annotations

import warnings

import mpmath
import numpy as np
import pytest
import sympy

import lindstedt
from lindstedt import ExpansionValidityWarning, ParameterError, ProblemError
from lindstedt.compiled.family import compile_family
from lindstedt.results.accuracy import series_warning

KAPPAS = [0.3, -0.7, 0.9, 1 - 1e-6, -1 + 1e-6]
NEAR_ENDS = [s * (1 - 10.0**-p) for p in (1, 2, 3, 4, 6, 8) for s in (1, -1)]


@pytest.fixture(scope="module")
def gap3():
    return lindstedt.expand("Max(0, u - kappa)", order=3, a0=1, omega0=1, params={"kappa": None})


@pytest.fixture(scope="module")
def gap2():
    return lindstedt.expand("Max(0, u - kappa)", order=2, a0=1, omega0=1, params={"kappa": None})


def _exact(expression, symbols, digits=50):
    """expression at the exact values of doubles, with mpmath at ``digits`` (checked against twice as many)."""
    function = sympy.lambdify(symbols, expression, "mpmath")

    def value(*numbers):
        with mpmath.workdps(digits):
            low = function(*[mpmath.mpf(float(x)) for x in numbers])
        with mpmath.workdps(2 * digits):
            high = function(*[mpmath.mpf(float(x)) for x in numbers])
        assert abs(low - high) <= mpmath.mpf(10) ** (-25) * abs(high)
        return float(high)

    return value


def test_omega_k_of_a_gap_are_accurate_near_grazing(gap3):
    kappa = gap3.arguments[0]
    points = np.array(KAPPAS + NEAR_ENDS)
    got = gap3.frequency_coefficients({"kappa": points})
    assert got.shape == (4, points.size)
    for k in range(4):
        reference = _exact(gap3.omega_correction(k), [kappa])
        exact = np.array([reference(x) for x in points])
        np.testing.assert_allclose(got[k], exact, rtol=1e-13, atol=0)
    # one kappa at a time gives the same numbers (scalars in, float64 rows out)
    for index, value in enumerate(KAPPAS):
        single = gap3.frequency_coefficients({"kappa": value})
        np.testing.assert_allclose(single, got[:, index], rtol=1e-13, atol=0)


def test_frequency_broadcasts_epsilon_and_kappa(gap3):
    kappa = gap3.arguments[0]
    reference = _exact(gap3.frequency_expr(), [sympy.Symbol("epsilon", real=True), kappa])
    epsilon = np.array([[0.001], [0.01], [0.05]])
    kappas = np.array(KAPPAS)
    with pytest.warns(ExpansionValidityWarning, match="not converging"):  # κ = -1 + 1e-6: a grazing that close
        got = gap3.frequency(epsilon, values={"kappa": kappas})
    assert got.shape == (3, len(KAPPAS))
    exact = np.array([[reference(e, x) for x in KAPPAS] for e in epsilon[:, 0]])
    np.testing.assert_allclose(got, exact, rtol=2e-13, atol=0)
    scalar = gap3.frequency(0.01, values={"kappa": 0.3})
    assert type(scalar) is float
    assert scalar == pytest.approx(reference(0.01, 0.3), rel=2e-13)


def test_displacement_and_velocity_broadcast_over_t_epsilon_and_kappa(gap2):
    kappa = gap2.arguments[0]
    time, epsilon = sympy.Symbol("t", real=True), sympy.Symbol("epsilon", real=True)
    function = sympy.lambdify((time, epsilon, kappa), gap2.displacement_expr(), "mpmath")
    times = np.array([0.0, 1.3, 7.7])[:, None, None]
    epsilons = np.array([0.01, 0.05])[None, :, None]
    kappas = np.array([0.3, -0.7, 0.999])[None, None, :]
    u = gap2.displacement(times, epsilons, {"kappa": kappas})
    v = gap2.velocity(times, epsilons, {"kappa": kappas})
    assert u.shape == v.shape == (3, 2, 3)
    step = mpmath.mpf(10) ** -20  # central difference at 50 digits: error ~ step^2, far below 1e-12
    with mpmath.workdps(50):
        for i, t in enumerate(times.flat):
            for j, e in enumerate(epsilons.flat):
                for k, x in enumerate(kappas.flat):
                    args = [mpmath.mpf(float(e)), mpmath.mpf(float(x))]
                    at = mpmath.mpf(float(t))
                    exact = function(at, *args)
                    slope = (function(at + step, *args) - function(at - step, *args)) / (2 * step)
                    assert abs(u[i, j, k] - float(exact)) <= 1e-12, (t, e, x)
                    assert abs(v[i, j, k] - float(slope)) <= 1e-12, (t, e, x)
    # one number per argument: the same values, as Python floats
    single = gap2.displacement(1.3, 0.05, {"kappa": -0.7})
    assert type(single) is float and single == pytest.approx(u[1, 1, 1], abs=1e-15)


def test_smooth_symbolic_parameters_against_the_exact_closed_form():
    expansion = lindstedt.expand("u**3 + c*u**5", order=3, params={"c": None})
    symbols = expansion.arguments  # a0, c, omega0
    time, epsilon = sympy.Symbol("t", real=True), sympy.Symbol("epsilon", real=True)
    u = _exact(expansion.displacement_expr(), [time, epsilon, *symbols])
    omega = _exact(expansion.frequency_expr(), [epsilon, *symbols])
    values = {"a0": np.array([0.5, 1.0, 2.0]), "c": np.array([-0.5, 0.25, 3.0]), "omega0": 1.5}  # c = 0: 1/c in v_1
    got = expansion.frequency(0.02, values=values)
    got_u = expansion.displacement(2.5, 0.02, values)
    for index in range(3):
        numbers = [values["a0"][index], values["c"][index], 1.5]
        assert got[index] == pytest.approx(omega(0.02, *numbers), rel=2e-13)
        assert got_u[index] == pytest.approx(u(2.5, 0.02, *numbers), abs=1e-12 * numbers[0])


def test_exact_numbers_a_double_cannot_hold_are_evaluated_exactly(gap3):
    kappa = gap3.arguments[0]
    exact = sympy.N(gap3.frequency_expr().xreplace({sympy.Symbol("epsilon", real=True): sympy.Rational(1, 10), kappa: sympy.Rational(3, 10)}), 30)
    assert gap3.frequency(0.1, values={"kappa": "3/10"}) == pytest.approx(float(exact), rel=1e-15)
    # ints and dyadic strings are doubles: the compiled path, the same numbers as floats
    assert gap3.frequency(0.1, values={"kappa": "1/4"}) == gap3.frequency(0.1, values={"kappa": 0.25})
    assert gap3.frequency(0.1, values={"kappa": 0}) == gap3.frequency(0.1, values={"kappa": 0.0})


def test_values_outside_the_derivation_raise_in_arrays_too(gap2):
    with pytest.raises(ParameterError, match="contact"):
        gap2.frequency(0.1, values={"kappa": np.array([0.2, 1.5])})
    with pytest.raises(ParameterError, match="contact"):
        gap2.displacement([0.0, 1.0], 0.1, {"kappa": [0.5, -1.0]})  # grazing at the far turning point
    with pytest.raises(ProblemError):
        gap2.frequency(0.1, values={"kappa": np.array([0.2, np.nan])})
    with pytest.raises(ParameterError, match="kappa"):
        gap2.frequency(0.1)
    with pytest.raises(ParameterError, match="nu"):
        gap2.frequency(0.1, values={"kappa": 0.2, "nu": 1.0})
    symbolic = lindstedt.expand("u**3", order=1)
    with pytest.raises(ParameterError, match="a0 > 0"):
        symbolic.frequency(0.1, values={"a0": np.array([1.0, -1.0]), "omega0": 1.0})
    # the error is raised again (not cached as a success)
    with pytest.raises(ParameterError, match="a0 > 0"):
        symbolic.frequency(0.1, values={"a0": -1.0, "omega0": 1.0})


def test_series_warning_matches_the_full_coefficients():
    """The warning reads ω_{N+1} only where it could speak; it must speak exactly where series_warning does with
    the exact ω_0 … ω_{N+1} (computed here from the exact expressions)."""
    for f, options in [("Max(0, u - 3/10)", {}), ("Max(0, u + 999/1000)", {"numeric": True}), ("u**2", {})]:
        for order in (1, 2, 3):
            expansion = lindstedt.expand(f, order=order, a0=1, omega0=1, **options)
            exact = [float(expansion.omega_correction(k)) for k in range(order + 2)]
            bounds = expansion.epsilon_range()
            for epsilon in np.geomspace(1e-3, 30, 23):
                try:  # the orbit's range speaks first (issue 22): no orbit, another regime, beyond the radius
                    expected = bounds.judge(np.array([epsilon]), "epsilon")
                except ParameterError:
                    with pytest.raises(ParameterError):
                        expansion.frequency(float(epsilon))
                    continue
                expected = expected or series_warning(exact, order, np.array([epsilon]), "epsilon")
                with warnings.catch_warnings(record=True) as caught:
                    warnings.simplefilter("always")
                    expansion.frequency(float(epsilon))
                    expansion.frequency(float(epsilon))  # the scalar fast path, once enabled
                messages = [str(w.message) for w in caught if issubclass(w.category, ExpansionValidityWarning)]
                assert messages == ([expected] * 2 if expected else []), (f, order, epsilon)


def test_warnings_of_vectorised_calls():
    expansion = lindstedt.expand("Max(0, u + 999/1000)", order=2, a0=1, omega0=1, numeric=True)
    with pytest.warns(ExpansionValidityWarning, match="not converging"):
        expansion.frequency(np.array([0.001, 0.5]))
    with pytest.warns(ExpansionValidityWarning, match="phase error"):  # inside the radius 5e-4 of that grazing
        expansion.displacement(np.array([0.0, 1e12]), np.array([0.0001, 0.0002]))
    gap = lindstedt.expand("Max(0, u - b)", order=2, a0=1, omega0=1, params={"b": None})
    values = {"b": np.array([0.3, -0.999])}  # the second is near grazing (at eps = -5e-4): radius 5e-4
    with pytest.warns(ExpansionValidityWarning, match="not converging"):
        gap.frequency(0.3, values=values)
    with pytest.warns(ExpansionValidityWarning, match="not converging"):
        gap.frequency(np.array([0.0001, 0.3]), values=values)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ExpansionValidityWarning)
        gap.frequency(np.array([0.3, 0.0001]), values=values)  # each epsilon with its own b: both inside


def test_bounded_family_bounds_hold():
    """The first-order bound of compile_family is above the actual float64 error of the closed forms, measured
    against mpmath at 60 digits (ω_1 … ω_3 of a gap, the worst cancellation near κ = ±1, and a rational
    function of two symbols)."""
    expansion = lindstedt.expand("Max(0, u - kappa)", order=3, a0=1, omega0=1, params={"kappa": None})
    kappa = expansion.arguments[0]
    expressions = [expansion.omega_correction(k) for k in (1, 2, 3)]
    family = compile_family(expressions, (kappa,))
    points = np.array([-0.999999, -0.9, -0.5, 0.0, 0.3, 0.7, 0.99, 0.999999])
    values, bounds = family(points)
    for row, expression in enumerate(expressions):
        reference = _exact(expression, [kappa], digits=60)
        errors = np.abs(values[row] - [reference(x) for x in points])
        assert np.all(errors <= bounds[row]), (row, errors, bounds[row])
    a, b = sympy.symbols("a b", real=True)
    rational = (a**3 - b**3) / (a - b) - (a**2 + a * b)  # = b^2, cancelling badly near a = b
    values, bounds = compile_family([rational], (a, b))(np.array([1.0, 1.0 + 2**-40]), np.array([1e-3, 1.0]))
    assert np.all(np.abs(values[0] - [1e-6, 1.0]) <= bounds[0])
