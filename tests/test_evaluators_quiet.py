"""A symbolic-κ expansion evaluated at parameter values new to it: no warning is lost and no value changes.

The float evaluators decide most calls without computing the orbit's range at the new κ (a table made once per
expansion, :mod:`lindstedt.results._evaluators`); the reference here is the exact range at each κ
(:meth:`lindstedt.Expansion.epsilon_range`, computed from the orbit at that κ) and, for κ ≤ 0, its closed form: the
breakpoint κ of (u − κ)₊ becomes the lower turning point of the orbit through u = 1 at ε = −(1 + κ)/(1 − κ)
(V(κ) = E: κ²/2 = 1/2 + ε (1 − κ)²/2), the nearest singularity of ω(ε).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import lindstedt


@pytest.fixture(scope="module")
def gap() -> lindstedt.Expansion:
    return lindstedt.expand("Max(0, u - kappa)", order=2, a0=1, omega0=1, params={"kappa": None})


def _speaks(expansion: lindstedt.Expansion, epsilon: float, kappa: float) -> bool:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            expansion.frequency(epsilon, values={"kappa": kappa})
        except lindstedt.ParameterError:
            return True
    return any(issubclass(w.category, lindstedt.ExpansionValidityWarning) for w in caught)


def test_closed_form_range_for_negative_gaps(gap: lindstedt.Expansion) -> None:
    for kappa in (-0.9, -0.5, -0.125, 0.0):
        bounds = gap.epsilon_range({"kappa": kappa})
        assert bounds.lower == pytest.approx(-(1 + kappa) / (1 - kappa), rel=1e-9)
        assert bounds.radius == pytest.approx((1 + kappa) / (1 - kappa), rel=1e-9)


def test_no_warning_lost_at_new_kappa(gap: lindstedt.Expansion) -> None:
    """Just beyond the exact quiet radius min(upper, −lower, radius) at 300 κ new to the expansion, on both sides of
    ε = 0, a warning (or the error of no orbit) comes; just inside, none."""
    rng = np.random.default_rng(26)
    for kappa in rng.uniform(-0.99, 0.99, 300):
        kappa = float(kappa)
        bounds = gap.epsilon_range({"kappa": kappa})
        quiet = min(bounds.upper, -bounds.lower, bounds.radius)
        assert _speaks(gap, -1.02 * quiet, kappa)
        assert _speaks(gap, 1.02 * min(bounds.upper, bounds.radius), kappa)
        if quiet > 1e-3:  # inside, with the series' own terms small
            assert not _speaks(gap, 1e-3 * quiet, kappa)


def test_new_kappa_values_match_the_array_path(gap: lindstedt.Expansion) -> None:
    """The same ω_k at 200 new κ one at a time and as one array (the scalar stable series and the NumPy ones)."""
    kappas = np.concatenate([np.linspace(-0.995, 0.995, 190), 1 - 2.0 ** -np.arange(10, 40, 3)])
    table = gap.frequency_coefficients({"kappa": kappas})
    for index, kappa in enumerate(kappas):
        np.testing.assert_allclose(gap.frequency_coefficients({"kappa": float(kappa)}), table[:, index], rtol=2e-14, atol=0)
