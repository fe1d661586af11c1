"""Stress: large ε (the expansion reports, never a silent wrong number), high orders, high precision."""

import warnings

import mpmath
import numpy as np
import pytest
import sympy

import lindstedt
from lindstedt.references import duffing_exact_frequency, duffing_frequency_taylor


def test_large_epsilon_is_reported_not_silent():
    expansion = lindstedt.expand("u**3", order=8, a0=1, omega0=1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        small = expansion.frequency(0.05)  # well inside the radius: no warning
    assert small == pytest.approx(float(duffing_exact_frequency(0.05, amplitude=1)), rel=1e-12)
    with pytest.warns(lindstedt.ExpansionValidityWarning, match="not converging"):
        expansion.frequency(3.0)


def test_high_order_exact_coefficients_and_speed():
    expansion = lindstedt.expand("u**3", order=30, a0=1, omega0=1)
    assert list(expansion.omega) == duffing_frequency_taylor(30)


def test_high_precision_analytic_f_agrees_between_precisions():
    low = lindstedt.expand("sin(u)", order=4, a0="4/5", omega0=1, precision=30)
    high = lindstedt.expand("sin(u)", order=4, a0="4/5", omega0=1, precision=80)
    for a, b in zip(low.omega, high.omega):
        assert abs(sympy.N(a - b, 80)) < 1e-28


def test_near_grazing_piecewise_float_path_stays_accurate_at_high_order():
    kappa = sympy.Rational(999999, 1000000)
    expansion = lindstedt.expand(f"Max(0, u - ({kappa}))", order=4, a0=1, omega0=1, numeric=True, precision=20)
    from lindstedt.references import piecewise_linear_frequency_taylor

    with mpmath.workdps(60):
        reference = piecewise_linear_frequency_taylor(4, a=1, b=mpmath.mpf(kappa.p) / kappa.q, a0=1, precision=60)
        for k in range(1, 5):
            value, _ = reference[k]
            assert abs(mpmath.mpf(sympy.N(expansion.omega[k], 40)) - value) <= 1e-15 * abs(value)


def test_waveform_evaluation_for_very_long_times_stays_bounded():
    expansion = lindstedt.expand("Max(0, u - 1/3)", order=2, a0=1, omega0=1)
    t = np.linspace(1e6, 1e6 + 50, 1001)
    values = expansion.displacement(t, 0.01)
    assert np.all(np.isfinite(values)) and np.max(np.abs(values)) < 1.1
