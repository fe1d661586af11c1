"""Honest accuracy: error estimates against measured errors, warnings where a series stops holding.

The measured errors come from the exact flow (``lindstedt.validate.expansion_error``, closed-form arcs for
piecewise-linear f, DOP853 at rtol 1e-12 for smooth f) and the closed-form exact period.
"""

from __future__ import annotations

import warnings

import pytest

import lindstedt
from lindstedt import ExpansionValidityWarning, UnilateralSystem
from lindstedt.references import piecewise_linear_exact_frequency
from lindstedt.validate import expansion_error


def _warnings_of(call) -> list[str]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        call()
    return [str(w.message) for w in caught if issubclass(w.category, ExpansionValidityWarning)]


@pytest.mark.parametrize("f, order", [
    # u**3 takes 6–8 s at every order (its references integrate long times): the slow run has them
    pytest.param(f, order, marks=pytest.mark.slow) if f == "u**3" else (f, order)
    for f in ["u**3", "Max(0, u - 1/3)", "Max(0, u + 1)"] for order in (1, 2, 3)])
def test_displacement_error_estimate_bounds_the_measured_error(f, order):
    """On t ≤ 100 and t ≤ 1e4 at ε = 0.01 (1/ε and 100/ε): the estimate is above the error and within a factor 10.

    Where the phase drift dominates (t = 1e4) the error is |a0| |2 sin(δω t/2)| ≤ |a0| δω t, the estimate's main
    term, with δω the next terms of ω: the two agree to the size of the terms after those (measured 2–12 %).  At
    t = 1/ε the neglected waveform term (the last kept one times η̂, a geometric guess) dominates: measured
    ratios 1.2–3.8, deterministic (the reference is the exact flow).
    """
    expansion = lindstedt.expand(f, order=order, a0=1, omega0=1)
    for t_end in (100.0, 1e4):
        measured = expansion_error(expansion, 0.01, t_end).max_error
        estimate = float(expansion.displacement_error_estimate(t_end, 0.01))
        assert measured <= estimate <= 10 * measured, (t_end, measured, estimate)


def test_near_grazing_series_warns_where_more_terms_make_it_worse():
    """(u + 0.999)_+, a0 = 1: for ε < 0 the far turning point rises and reaches the breakpoint −0.999 at
    ε_g = −(a0² − b²)/(a0 − b)² ≈ −5e-4 (V(b) = E with F(u) = (u + 0.999)_+²/2): that grazing limits the radius of
    convergence to |ε_g|, and at ε = 0.01 order 4 is worse than order 2.  Both orders warn there, naming ε_g (the
    short series too, not only once the terms grow); at ε = 2e-4 < |ε_g| neither does."""
    exact = float(piecewise_linear_exact_frequency(0.01, a=1, b="-999/1000", a0=1, precision=30))
    grazing = -(1 - 0.999**2) / 1.999**2
    errors, messages = {}, {}
    for order in (2, 4):
        expansion = lindstedt.expand("Max(0, u + 999/1000)", order=order, a0=1, omega0=1, numeric=True)
        messages[order] = _warnings_of(lambda: errors.__setitem__(order, abs(expansion.frequency(0.01) - exact)))
        assert _warnings_of(lambda: expansion.frequency(2e-4)) == []
    assert errors[4] > errors[2]
    for order in (2, 4):
        assert len(messages[order]) == 1 and "radius of convergence" in messages[order][0], messages[order]
        assert f"at eps = {grazing:.6g}" in messages[order][0]


def test_nnm_evaluators_warn_outside_their_range():
    mode = lindstedt.nnm(UnilateralSystem.chain(2, unilateral=[(0, 0)]), mode=1, a0=1, order=2)
    assert any("not converging" in message for message in _warnings_of(lambda: mode.frequency(10.0)))
    assert any("phase error" in message for message in _warnings_of(lambda: mode.displacement(1e12, 0.01)))
    assert any("not converging" in message for message in _warnings_of(lambda: mode.displacement(1.0, 1e10)))
    assert _warnings_of(lambda: (mode.frequency(0.01), mode.displacement([0.0, 10.0], 0.01))) == []
    # the estimate of the frequency's truncation error is the first neglected term (derived on demand) plus a
    # geometric tail, small at ε = 0.01
    first = abs(float(mode._coefficients[-1])) * 1e-6
    assert first < float(mode.truncation_error_estimate(0.01)) < 1.1 * first


def test_expansion_displacement_warns_beyond_the_validity_time():
    expansion = lindstedt.expand("Max(0, u - 1/3)", order=2, a0=1, omega0=1)
    assert _warnings_of(lambda: expansion.displacement([0.0, 100.0], 0.01)) == []
    assert any("phase error" in message for message in _warnings_of(lambda: expansion.displacement(1e12, 0.01)))
