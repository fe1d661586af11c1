"""Numeric ``values=`` are checked against the assumptions an expansion was derived under.

A symbolic derivation holds only in the regime it assumed: a0 > 0 for the default
(positive) symbol a0, ω0 > 0, and for piecewise-linear f the side of the release
point and where every breakpoint lies relative to the orbit (|κ| < 1: contact).
Values outside raise a typed error naming that regime and the fix; values inside
agree with the expansion derived with the numbers substituted.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st

import lindstedt
from lindstedt import Expansion, ParameterError, ProblemError
from lindstedt.references import piecewise_linear_exact_frequency

HALF = sympy.Rational(1, 2)


@pytest.fixture(scope="module")
def gap_half() -> Expansion:
    """Max(0, u - 1/2) with symbolic a0 and omega0 (derived for a0 > 0 and contact 1/2 < a0)."""
    return lindstedt.expand("Max(0, u - 1/2)", order=2)


@pytest.fixture(scope="module")
def symbolic_gap() -> Expansion:
    """Max(0, u - b) with symbolic a0, omega0 and gap b (derived for -a0 < b < a0)."""
    return lindstedt.expand("Max(0, u - b)", order=2, params={"b": None})


# -- the reported example -------------------------------------------------------------------------
def test_negative_release_point_is_outside_the_symbolic_derivation(gap_half: Expansion) -> None:
    with pytest.raises(ParameterError) as caught:
        gap_half.frequency(0.1, values={"a0": -1, "omega0": 1})
    message = str(caught.value)
    assert "a0 > 0" in message and "contact" in message and "1/2 < a0" in message
    assert "lindstedt.expand('Max(0, u - 1/2)', order=2, a0=-1, omega0=1)" in message
    # the error is not cached as a success: a second call raises again
    with pytest.raises(ParameterError):
        gap_half.frequency(0.1, values={"a0": -1, "omega0": 1})


@pytest.mark.parametrize("method", ["frequency", "truncation_error_estimate", "displacement", "velocity"])
def test_every_evaluator_checks_values(gap_half: Expansion, method: str) -> None:
    values = {"a0": -1, "omega0": 1}
    with pytest.raises(ParameterError, match="a0 > 0"):
        if method in ("displacement", "velocity"):
            getattr(gap_half, method)(np.linspace(0, 5, 7), 0.1, values)
        else:
            getattr(gap_half, method)(0.1, values=values)


def test_rederived_expansion_matches_the_closed_form_period() -> None:
    """Re-derived at a0 = -1 the expansion converges to the exact frequency (harmonic arcs joined at u = b)."""
    epsilon = 0.1
    exact = float(piecewise_linear_exact_frequency(epsilon, a=1, b=HALF, a0=-1, omega0=1))
    assert exact == pytest.approx(1.00941327, abs=1e-8)
    errors = []
    for order in range(1, 5):
        expansion = lindstedt.expand("Max(0, u - 1/2)", order=order, a0=-1, omega0=1)
        error = abs(expansion.frequency(epsilon) - exact)
        # the truncation error is of the size of the first neglected term
        assert error <= 2 * float(expansion.truncation_error_estimate(epsilon))
        errors.append(error)
    assert all(later < earlier / 5 for earlier, later in zip(errors, errors[1:]))
    assert errors[-1] < 1e-7
    # the value the order-2 symbolic expansion used to return (1.0370) is far outside its tolerance
    assert abs(1.0370170719106733 - exact) > 1000 * errors[1]


def test_symbolic_expansion_with_negative_symbol_amplitude_covers_the_other_side() -> None:
    """a0 = -A (A > 0) is derived for the release point on the negative side: contact needs A > 1/2."""
    amplitude = sympy.Symbol("A", positive=True)
    expansion = lindstedt.expand("Max(0, u - 1/2)", order=2, a0=-amplitude)
    derived = lindstedt.expand("Max(0, u - 1/2)", order=2, a0=-1, omega0=1)
    assert expansion.frequency(0.1, values={"A": 1, "omega0": 1}) == pytest.approx(derived.frequency(0.1), rel=1e-13)
    with pytest.raises(ParameterError, match="A > 0"):
        expansion.frequency(0.1, values={"A": -1, "omega0": 1})
    with pytest.raises(ParameterError, match="contact"):
        expansion.frequency(0.1, values={"A": "1/4", "omega0": 1})


# -- values inside the derived regime ------------------------------------------------------------
def test_values_in_regime_agree_with_the_expansion_derived_with_the_numbers(gap_half: Expansion) -> None:
    values = {"a0": sympy.Rational(3, 2), "omega0": 2}
    derived = lindstedt.expand("Max(0, u - 1/2)", order=2, a0=sympy.Rational(3, 2), omega0=2)
    substitution = {sympy.Symbol("a0", positive=True): values["a0"], sympy.Symbol("omega0", positive=True): values["omega0"]}
    for k in range(4):
        assert float(gap_half.omega_correction(k).xreplace(substitution)) == pytest.approx(
            float(derived.omega_correction(k)), rel=1e-13, abs=1e-15
        )
    epsilon = 0.05
    assert gap_half.frequency(epsilon, values=values) == pytest.approx(derived.frequency(epsilon), rel=1e-13)
    assert gap_half.truncation_error_estimate(epsilon, values=values) == pytest.approx(
        float(derived.truncation_error_estimate(epsilon)), rel=1e-12
    )
    times = np.linspace(0.0, 20.0, 401)
    np.testing.assert_allclose(gap_half.displacement(times, epsilon, values), derived.displacement(times, epsilon), rtol=0, atol=1e-13)
    np.testing.assert_allclose(gap_half.velocity(times, epsilon, values), derived.velocity(times, epsilon), rtol=0, atol=1e-12)


def test_exactly_equal_coefficients_for_a_symbolic_stiffness() -> None:
    symbolic = lindstedt.expand("Max(0, u)", order=3)
    derived = lindstedt.expand("Max(0, u)", order=3, a0=2, omega0=3)
    substitution = {sympy.Symbol("a0", positive=True): 2, sympy.Symbol("omega0", positive=True): 3}
    for k in range(4):
        assert sympy.simplify(symbolic.omega_correction(k).xreplace(substitution) - derived.omega_correction(k)) == 0
    assert symbolic.frequency(0.1, values={"a0": 2, "omega0": 3}) == pytest.approx(derived.frequency(0.1), rel=1e-14)


def test_smooth_values_as_before() -> None:
    expansion = lindstedt.expand("u**3", order=2)
    assert round(expansion.frequency(0.1, values={"a0": 1, "omega0": 1}), 12) == 1.0366796875
    times = np.linspace(0, 10, 11)
    derived = lindstedt.expand("u**3", order=2, a0=2, omega0=3)
    np.testing.assert_allclose(
        expansion.displacement(times, 0.1, {"a0": 2, "omega0": 3}), derived.displacement(times, 0.1), rtol=1e-13, atol=1e-14
    )
    # a real parameter may take any real value, zero included
    with_parameter = lindstedt.expand("u**3 + c*u**5", order=2, a0=1, omega0=1, params={"c": None})
    assert with_parameter.frequency(0.1, values={"c": 0}) == pytest.approx(1 + 0.1 * 3 / 8 - 0.01 * 21 / 256, rel=1e-15)
    assert math.isfinite(with_parameter.frequency(0.1, values={"c": -2}))


def test_smooth_negative_amplitude_is_outside_a_positive_symbol() -> None:
    expansion = lindstedt.expand("u**3", order=2)
    with pytest.raises(ParameterError, match=r"a0 > 0") as caught:
        expansion.frequency(0.1, values={"a0": -1, "omega0": 1})
    assert "a0=-1" in str(caught.value)


# -- symbolic gaps: the contact regime -----------------------------------------------------------
def test_symbolic_gap_inside_the_orbit_agrees(symbolic_gap: Expansion) -> None:
    values = {"a0": 1, "omega0": 1, "b": sympy.Rational(1, 3)}
    derived = lindstedt.expand("Max(0, u - 1/3)", order=2, a0=1, omega0=1)
    assert symbolic_gap.frequency(0.1, values=values) == pytest.approx(derived.frequency(0.1), rel=1e-13)
    negative_gap = {"a0": 1, "omega0": 1, "b": sympy.Rational(-1, 3)}  # prestress inside the orbit: still crossing
    derived_prestress = lindstedt.expand("Max(0, u + 1/3)", order=2, a0=1, omega0=1)
    assert symbolic_gap.frequency(0.1, values=negative_gap) == pytest.approx(derived_prestress.frequency(0.1), rel=1e-13)


@pytest.mark.parametrize(
    "gap, regime",
    [
        (2, "never reached"),  # b > a0: the spring is never touched
        (1, "grazing"),  # b = a0: grazing, a different regime
        (-1, "grazing"),  # b = -a0: grazing at the far turning point
        (-3, "permanent contact"),  # b < -a0: always in contact
        ("0.75", "contact"),
    ],
)
def test_symbolic_gap_outside_the_contact_regime_raises(symbolic_gap: Expansion, gap, regime: str) -> None:
    values = {"a0": sympy.Rational(1, 2) if gap == "0.75" else 1, "omega0": 1, "b": gap}
    with pytest.raises(ParameterError) as caught:
        symbolic_gap.frequency(0.1, values=values)
    message = str(caught.value)
    assert "-a0 < b < a0" in message and "re-derive" in message
    # the fix it names works and gives the right regime
    numbers = {"a0": values["a0"], "omega0": 1, "params": {"b": gap}}
    rederived = lindstedt.expand("Max(0, u - b)", order=2, **numbers)
    expected = {"never reached": "no contact", "grazing": "grazing", "permanent contact": "contact", "contact": "no contact"}
    assert rederived.regime == expected[regime]


def test_spring_on_the_negative_side_with_symbolic_gap() -> None:
    expansion = lindstedt.expand("Max(0, -u - b)", order=2, params={"b": None})
    derived = lindstedt.expand("Max(0, -u - 1/4)", order=2, a0=1, omega0=1)
    assert expansion.frequency(0.1, values={"a0": 1, "omega0": 1, "b": "1/4"}) == pytest.approx(derived.frequency(0.1), rel=1e-13)
    with pytest.raises(ParameterError, match="contact"):
        expansion.frequency(0.1, values={"a0": 1, "omega0": 1, "b": 2})


def test_numeric_amplitude_with_symbolic_gap_grazing_boundary() -> None:
    expansion = lindstedt.expand("Max(0, u - b)", order=1, a0=2, params={"b": None})
    assert math.isfinite(expansion.frequency(0.1, values={"omega0": 1, "b": "1.999"}))
    with pytest.raises(ParameterError, match="grazing|contact"):
        expansion.frequency(0.1, values={"omega0": 1, "b": 2})


# -- omega0, non-numbers -------------------------------------------------------------------------
@pytest.mark.parametrize("omega0", [0, -1])
@pytest.mark.parametrize("f", ["Max(0, u - 1/2)", "u**3"])
def test_non_positive_omega0_raises(f: str, omega0: int) -> None:
    expansion = lindstedt.expand(f, order=2)
    with pytest.raises(ProblemError, match="omega0"):
        expansion.frequency(0.1, values={"a0": 1, "omega0": omega0})


def test_zero_amplitude_raises() -> None:
    expansion = lindstedt.expand("u**3", order=2)
    with pytest.raises(ProblemError, match="a0"):
        expansion.frequency(0.1, values={"a0": 0, "omega0": 1})


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), -float("inf"), 1 + 1j, complex(0, 1), sympy.nan, sympy.zoo, sympy.I])
@pytest.mark.parametrize("name", ["a0", "omega0"])
def test_nan_inf_complex_raise(gap_half: Expansion, bad, name: str) -> None:
    values = {"a0": 1, "omega0": 1, name: bad}
    with pytest.raises(ProblemError):
        gap_half.frequency(0.1, values=values)
    with pytest.raises(ProblemError):
        gap_half.displacement([0.0, 1.0], 0.1, values)


def test_nan_gap_raises(symbolic_gap: Expansion) -> None:
    with pytest.raises(ProblemError):
        symbolic_gap.frequency(0.1, values={"a0": 1, "omega0": 1, "b": float("nan")})


# -- cost: validated once per values --------------------------------------------------------------
def test_values_are_validated_once_per_values(monkeypatch: pytest.MonkeyPatch) -> None:
    expansion = lindstedt.expand("Max(0, u - 1/2)", order=1)
    calls = []
    original = lindstedt.Oscillator.numeric_substitution

    def counting(self, values=None):  # the values are read (and then checked) only on a cache miss
        calls.append(dict(values or {}))
        return original(self, values)

    monkeypatch.setattr(lindstedt.Oscillator, "numeric_substitution", counting)
    values = {"a0": 1, "omega0": 1}
    for _ in range(3):
        expansion.frequency(0.1, values=values)
        expansion.displacement(np.linspace(0, 1, 5), 0.1, values)
        expansion.velocity(0.5, 0.1, values)
        expansion.truncation_error_estimate(0.1, values=values)
    assert len(calls) == 1
    expansion.frequency(0.1, values={"a0": 2, "omega0": 1})
    assert len(calls) == 2


# -- property: symbolic + values == derived with the numbers ------------------------------------
@settings(max_examples=12, deadline=None)
@given(st.fractions(min_value=Fraction(21, 40), max_value=Fraction(4), max_denominator=40))
def test_symbolic_amplitude_in_regime_equals_derivation_with_the_number(gap_half: Expansion, amplitude: Fraction) -> None:
    value = sympy.Rational(amplitude.numerator, amplitude.denominator)
    derived = lindstedt.expand("Max(0, u - 1/2)", order=2, a0=value, omega0=1)
    values = {"a0": value, "omega0": 1}
    for epsilon in (0.01, 0.1):
        assert gap_half.frequency(epsilon, values=values) == pytest.approx(derived.frequency(epsilon), rel=1e-12)
    times = np.linspace(0.0, 12.0, 25)
    np.testing.assert_allclose(
        gap_half.displacement(times, 0.1, values), derived.displacement(times, 0.1), rtol=1e-12, atol=1e-12 * float(value)
    )


@settings(max_examples=12, deadline=None)
@given(st.fractions(min_value=Fraction(-19, 20), max_value=Fraction(19, 20), max_denominator=20))
def test_symbolic_gap_in_regime_equals_derivation_with_the_number(symbolic_gap: Expansion, gap: Fraction) -> None:
    value = sympy.Rational(gap.numerator, gap.denominator)
    derived = lindstedt.expand("Max(0, u - b)", order=2, a0=1, omega0=1, params={"b": value})
    assert symbolic_gap.frequency(0.1, values={"a0": 1, "omega0": 1, "b": value}) == pytest.approx(derived.frequency(0.1), rel=1e-12)
