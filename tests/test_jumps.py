"""Forces that jump: u'' + u + ε c H(u − b) = 0 (and sign(u)), u(0) = a0, u'(0) = 0.

Independent references: the exact period as a sum of harmonic arcs (on each side of the jump the motion is
harmonic with ω = 1 about its own centre), written out here and evaluated with mpmath at 50 digits; and the
event-driven DOP853 reference of ``lindstedt.validate`` (the exact-flow reference represents springs only).
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
import sympy

import lindstedt
from lindstedt.validate import exact_period


def _period_heaviside(epsilon: mpmath.mpf, b: mpmath.mpf) -> mpmath.mpf:
    """H(u − b), a0 = 1, |b| < 1: above b the centre is −ε, below it 0."""
    amplitude = 1 + epsilon  # u + ε from 1 + ε down to b + ε
    upper = mpmath.acos((b + epsilon) / amplitude)
    speed = mpmath.sqrt(amplitude**2 - (b + epsilon) ** 2)
    radius = mpmath.sqrt(b**2 + speed**2)  # below b: harmonic about 0
    return 2 * upper + 2 * mpmath.pi - 2 * mpmath.acos(b / radius)


def _period_sign(epsilon: mpmath.mpf) -> mpmath.mpf:
    """sign(u), a0 = 1: centres −ε above 0 and +ε below; symmetric quarter arcs."""
    return 4 * mpmath.acos(epsilon / (1 + epsilon))


def _period_heaviside_grazing(epsilon: mpmath.mpf) -> mpmath.mpf:
    """H(u + 1), a0 = 1: the force acts over the whole orbit except past the far turning point, which the
    perturbed orbit (centre −ε, minimum −1 − 2ε) passes: a free arc below u = −1."""
    amplitude = 1 + epsilon
    upper = mpmath.acos((-1 + epsilon) / amplitude)
    speed = mpmath.sqrt(amplitude**2 - (1 - epsilon) ** 2)
    radius = mpmath.sqrt(1 + speed**2)
    return 2 * upper + 2 * mpmath.acos(1 / radius)


def _slope(epsilons, errors) -> float:
    return float(np.polyfit(np.log(np.asarray(epsilons, dtype=float)), np.log(np.asarray(errors, dtype=float)), 1)[0])


def _truncated(expansion, epsilon: mpmath.mpf, terms: int) -> mpmath.mpf:
    eta = epsilon if expansion.gauge == sympy.Symbol("epsilon", real=True) else mpmath.sqrt(epsilon)
    return mpmath.fsum(mpmath.mpf(str(sympy.N(expansion.omega_correction(k), 60))) * eta**k for k in range(terms))


@pytest.mark.parametrize(
    "f, period",
    [
        ("Heaviside(u)", lambda e: _period_heaviside(e, mpmath.mpf(0))),
        ("Heaviside(u - 1/3)", lambda e: _period_heaviside(e, mpmath.mpf(1) / 3)),
        ("Heaviside(u + 1/2)", lambda e: _period_heaviside(e, -mpmath.mpf(1) / 2)),
        ("sign(u)", _period_sign),
    ],
)
def test_jump_expansion_error_is_order_n_plus_one(f, period):
    """ω is analytic (the jump is crossed transversally): truncation after ε^N errs by O(ε^{N+1})."""
    expansion = lindstedt.expand(f, order=4, a0=1, omega0=1)
    assert expansion.regime == "contact" and expansion.gauge == sympy.Symbol("epsilon", real=True)
    epsilons = [mpmath.mpf(10) ** -p for p in (3, 4, 5)]
    with mpmath.workdps(50):
        exact = [2 * mpmath.pi / period(e) for e in epsilons]
        for order in (1, 2, 3, 4):
            errors = [abs(_truncated(expansion, e, order + 1) - x) for e, x in zip(epsilons, exact)]
            # the next term's relative weight is ≲ ε ≤ 1e-3 over the fit: slope bias < 0.01
            assert _slope(epsilons, errors) == pytest.approx(order + 1, abs=0.05), (f, order)


def test_first_correction_of_a_unit_jump_is_one_over_pi():
    """ω_1 = 1/(π a0) for H(u): the arc above 0 is shortened by 2ε/a0 to first order (closed form above)."""
    assert lindstedt.expand("Heaviside(u)", order=1, a0=1, omega0=1).omega[1] == 1 / sympy.pi


def test_jump_touched_at_the_far_turning_point_is_expanded_in_sqrt_epsilon():
    expansion = lindstedt.expand("Heaviside(u + 1)", order=3, a0=1, omega0=1)
    assert expansion.gauge == sympy.sqrt(sympy.Symbol("epsilon", real=True)) and expansion.contact_angles == (sympy.pi,)
    epsilons = [mpmath.mpf(10) ** -p for p in (5, 6, 7)]
    with mpmath.workdps(50):
        exact = [2 * mpmath.pi / _period_heaviside_grazing(e) for e in epsilons]
        previous = 0.0
        for terms in (3, 4, 5, 6, 7):
            errors = [abs(_truncated(expansion, e, terms) - x) for e, x in zip(epsilons, exact)]
            slope = _slope(epsilons, errors)
            assert slope >= terms / 2 - 0.05 and slope >= previous - 0.05, (terms, slope)
            previous = slope


def test_validation_reference_takes_the_jump():
    """The event-driven reference (not the spring-only exact flow) against the closed-form period."""
    result = exact_period(lindstedt.Oscillator("Heaviside(u)", a0=1, omega0=1), 0.01)
    with mpmath.workdps(30):
        expected = float(_period_heaviside(mpmath.mpf("0.01"), mpmath.mpf(0)))
    assert "DOP853" in result.message
    assert result.period == pytest.approx(expected, rel=1e-10)  # DOP853 at rtol 1e-12 over one period
