"""A symbolic-κ expansion evaluated at parameter values new to it: no warning is lost and no value changes.

The float evaluators decide most calls without computing the orbit's range at the new κ (a table of the quiet radius
made once per expansion); the reference here is the exact range at each κ
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


def test_no_warning_lost_next_to_the_regime_ends(gap: lindstedt.Expansion) -> None:
    """Where the quiet radius runs to 0 or ∞ (κ → ∓1) and around the nodes of a uniform grid in
    s = κ/(1 + |κ|) (256 cells, where a tabulated bound would change): a warning just beyond the exact radius
    from the orbit at that κ, none well inside."""
    edges = [sign * (1 - 2.0**-k) for sign in (1, -1) for k in range(1, 27)]  # the exact range resolves 1 + κ > 4e-9
    s = -1 + 2 * np.arange(65, 192) / 256  # the grid nodes with |κ| < 1, approached from both sides
    nodes = s / (1 - np.abs(s))
    for kappa in [*edges, *np.nextafter(nodes, -2), *np.nextafter(nodes, 2)][::2]:
        kappa = float(kappa)
        bounds = gap.epsilon_range({"kappa": kappa})
        quiet = min(bounds.upper, -bounds.lower, bounds.radius)
        if kappa <= 0:  # the closed form (module docstring)
            assert quiet == pytest.approx((1 + kappa) / (1 - kappa), rel=1e-9)
        assert _speaks(gap, -1.02 * quiet, kappa)
        if quiet < 0.5:  # beyond ε = 1/2 the series' own terms speak first
            assert _speaks(gap, 1.02 * quiet, kappa)
        if quiet > 1e-3:
            assert not _speaks(gap, 1e-3 * quiet, kappa)


def test_one_point_frequency_matches_the_exact_coefficients(gap: lindstedt.Expansion) -> None:
    """ω(ε) at κ new to the expansion, one float at a time (the one-pass path), against the 30-digit Cauchy-integral
    coefficients of the exact period: within 1e-13 of the terms plus the reference's own estimate; and the same
    numbers as the array path at the same κ."""
    from lindstedt.references import piecewise_linear_frequency_taylor

    kappas = [-0.95, -0.6180339887, -0.123, 0.0, 0.3, 0.7071067811865476, 0.93, 0.999999]
    epsilon = 0.01
    array = gap.frequency(epsilon, values={"kappa": np.array(kappas)})
    for index, kappa in enumerate(kappas):
        reference = piecewise_linear_frequency_taylor(2, a=1, b=kappa, a0=1, precision=30)
        exact = sum(float(value) * epsilon**k for k, (value, _) in enumerate(reference))
        allowance = sum((1e-13 * abs(float(value)) + float(error)) * epsilon**k for k, (value, error) in enumerate(reference))
        value = gap.frequency(epsilon, values={"kappa": kappa})
        assert abs(value - exact) <= allowance + 4e-16
        assert value == pytest.approx(array[index], rel=1e-14)


def _outcome(expansion: lindstedt.Expansion, epsilon: float, kappa: object) -> tuple[str, float]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            value = float(np.ravel(expansion.frequency(epsilon, values={"kappa": kappa}))[0])
        except lindstedt.ParameterError:
            return "error", float("nan")
    warned = any(issubclass(w.category, lindstedt.ExpansionValidityWarning) for w in caught)
    return ("warning" if warned else "quiet"), value


def test_one_point_path_decides_as_the_array_path(gap: lindstedt.Expansion) -> None:
    """At 300 random (ε, κ), κ new to the expansion, ε on both sides of every radius: one float κ (the one-pass path
    where it applies) and the same κ as a one-element array (the vectorised path) give the same value and the same
    verdict: quiet, a warning, or the error of no orbit."""
    rng = np.random.default_rng(2026)
    verdicts = set()
    for epsilon, kappa in zip(rng.uniform(-0.6, 0.6, 300), rng.uniform(-1.05, 1.05, 300)):
        epsilon, kappa = float(epsilon), float(kappa)
        if abs(kappa) >= 1:  # outside the regime: both raise
            with pytest.raises(lindstedt.ParameterError):
                gap.frequency(epsilon, values={"kappa": kappa})
            continue
        single, array = _outcome(gap, epsilon, kappa), _outcome(gap, epsilon, np.array([kappa]))
        assert single[0] == array[0]
        if single[0] != "error":
            assert single[1] == pytest.approx(array[1], rel=1e-14)
        verdicts.add(single[0])
    assert verdicts == {"quiet", "warning"} or verdicts == {"quiet", "warning", "error"}
