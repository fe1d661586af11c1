"""Grazing: a breakpoint touched by a turning point of the unperturbed orbit.

References, all independent of the expansion machinery:
* the exact period of the piecewise-linear oscillator as a sum of harmonic arcs, in closed form
  (``lindstedt.references.piecewise_linear_exact_frequency`` for one spring; written out here
  for two springs), evaluated with mpmath at 50 digits, and its series in δ = ε^{1/2} by sympy;
* periodic orbits found by Newton shooting on the exact flow (``lindstedt.nnm_point``).
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
import sympy

import lindstedt
from lindstedt import UnilateralSystem
from lindstedt.references import piecewise_linear_exact_frequency
from lindstedt.validate import expansion_error

EPSILON = sympy.Symbol("epsilon", real=True)


def _fitted_slope(epsilons, errors) -> float:
    """Least-squares slope of log(error) against log(ε)."""
    return float(np.polyfit(np.log(np.asarray(epsilons, dtype=float)), np.log(np.asarray(errors, dtype=float)), 1)[0])


def _truncated(expansion, epsilon: mpmath.mpf, terms: int) -> mpmath.mpf:
    """Σ_{k<terms} ω_k η^k at the working precision, η the expansion's gauge (ε or ε^{1/2})."""
    eta = epsilon if expansion.gauge == EPSILON else mpmath.sqrt(epsilon)
    return mpmath.fsum(mpmath.mpf(str(sympy.N(expansion.omega_correction(k), 60))) * eta**k for k in range(terms))


# --------------------------------------------------------------------------- grazing at the far turning point, 1 dof
def test_far_turning_point_grazing_is_expanded_in_powers_of_sqrt_epsilon():
    expansion = lindstedt.expand("Max(0, u + 1)", order=3, a0=1, omega0=1)
    assert expansion.gauge == sympy.sqrt(EPSILON)
    assert expansion.regime == "grazing" and expansion.validity_exponent == -1
    # the exact series of the closed-form frequency (see the slow test below): 1 + ε/2 − ε²/8 − 8/(3π) ε^{5/2} + ε³/16
    assert expansion.omega == (1, 0, sympy.Rational(1, 2), 0, sympy.Rational(-1, 8), -8 / (3 * sympy.pi), sympy.Rational(1, 16))
    assert expansion.exponents == tuple(sympy.Rational(k, 2) for k in range(7))
    assert expansion.contact_angles == (sympy.pi,)  # the free arc opens at the bottom turning point
    assert expansion.contact_angle_correction(1) == (-2,)  # s* = π − 2 ε^{1/2} + …: the orbit dips 2ε below u = −1


@pytest.mark.slow
def test_far_turning_point_coefficients_equal_the_series_of_the_exact_frequency():
    """Exact: sympy's series in δ of the closed-form frequency (contact arc + free arc), ω0 = 1, a0 = 1."""
    delta = sympy.Symbol("delta", positive=True)
    epsilon = delta**2
    stiffness, center = 1 + epsilon, -epsilon / (1 + epsilon)
    radius = 1 - center
    contact_time = sympy.acos((-1 - center) / radius) / sympy.sqrt(stiffness)
    free_amplitude = sympy.sqrt(1 + stiffness * (radius**2 - (1 + center) ** 2))
    free_time = sympy.acos(1 / free_amplitude)
    series = sympy.series(sympy.pi / (contact_time + free_time), delta, 0, 8).removeO()
    expansion = lindstedt.expand("Max(0, u + 1)", order=3, a0=1, omega0=1)
    for k in range(8):
        assert sympy.simplify(expansion.omega_correction(k) - series.coeff(delta, k)) == 0, k


def test_far_turning_point_error_falls_with_the_gauge_order():
    """Truncation after η^n, η = ε^{1/2}: the error against the exact frequency is O(η^{m}) with m the next nonzero term."""
    expansion = lindstedt.expand("Max(0, u + 1)", order=4, a0=1, omega0=1)
    epsilons = [mpmath.mpf(10) ** -p for p in (6, 7, 8)]
    with mpmath.workdps(60):
        exact = [piecewise_linear_exact_frequency(e, a=1, b=-1, a0=1, omega0=1, precision=60) for e in epsilons]
        # (terms kept, exponent of ε of the first neglected nonzero term).  The term after that one is
        # smaller by |ω_{k+1}/ω_k| ε^{1/2} ≤ 52 × 1e-3 on ε ≤ 1e-6 (worst: ω_3 = 1/16 followed by
        # ω_{7/2} = 152/(15π)), which biases the slope fitted over two decades by at most
        # log(1.052)/log(100) ≈ 0.011: the tolerance 0.05 holds it with room for the rounding of the fit.
        for terms, expected in [(3, 2), (5, 2.5), (6, 3), (7, 3.5)]:
            errors = [abs(_truncated(expansion, e, terms) - x) for e, x in zip(epsilons, exact)]
            assert _fitted_slope(epsilons, errors) == pytest.approx(expected, abs=0.05), terms


def test_second_spring_grazing_at_the_bottom_against_the_exact_period():
    """u'' + u + ε(u_+ + min(0, u + 1)) = 0, u(0) = 1: u_+ crosses at π/2, the second spring grazes at π."""
    expansion = lindstedt.expand("Max(0, u) + Min(0, u + 1)", order=4, a0=1, omega0=1)
    assert expansion.gauge == sympy.sqrt(EPSILON) and expansion.contact_angles == (sympy.pi / 2, sympy.pi)

    def exact(epsilon: mpmath.mpf) -> mpmath.mpf:
        stiffness = 1 + epsilon
        upper = (mpmath.pi / 2) / mpmath.sqrt(stiffness)  # u from 1 to 0 with stiffness 1 + ε
        speed = mpmath.sqrt(stiffness)
        free = mpmath.asin(1 / speed)  # u from 0 to −1, no force
        exit_speed = mpmath.sqrt(speed**2 - 1)
        center = -epsilon / stiffness  # u < −1: u'' + (1 + ε) u + ε = 0
        entry = -1 - center
        radius = mpmath.sqrt(entry**2 + exit_speed**2 / stiffness)
        lower = (mpmath.pi / 2 - mpmath.asin(abs(entry) / radius)) / mpmath.sqrt(stiffness)
        return mpmath.pi / (upper + free + lower)

    epsilons = [mpmath.mpf(10) ** -p for p in (4, 5, 6)]
    with mpmath.workdps(50):
        for terms in range(3, 9):
            errors = [abs(_truncated(expansion, e, terms) - exact(e)) for e in epsilons]
            assert _fitted_slope(epsilons, errors) >= terms / 2 - 0.05, terms


def test_release_point_grazing_touches_and_stays_analytic():
    """b = a0 from outside (never in contact) and from inside (always in contact): exact frequencies 1 and √(1+ε)."""
    outside = lindstedt.expand("Max(0, u - 1)", order=3, a0=1, omega0=1)
    assert outside.gauge == EPSILON and outside.omega == (1, 0, 0, 0)
    inside = lindstedt.expand("Max(0, u + 1)", order=3, a0=-1, omega0=1)
    linear = sympy.series(sympy.sqrt(1 + EPSILON), EPSILON, 0, 4).removeO()
    assert inside.gauge == EPSILON and inside.omega == tuple(linear.coeff(EPSILON, k) for k in range(4))


def test_displacement_error_falls_with_the_order_on_the_long_time_scale():
    """Over t ≤ 1/ε against the exact flow; before the gauge every order stalled at ε^{3/2}."""
    epsilons = (1e-2, 3e-3, 1e-3)
    slopes = []
    for order in (1, 2, 3):
        expansion = lindstedt.expand("Max(0, u + 1)", order=order, a0=1, omega0=1)
        errors = [expansion_error(expansion, e, 1 / e).max_error for e in epsilons]
        slopes.append(_fitted_slope(epsilons, errors))
    assert slopes[1] > slopes[0] + 1 and slopes[2] > slopes[1] + 0.8, slopes


def test_negative_epsilon_is_refused_in_the_sqrt_gauge():
    expansion = lindstedt.expand("Max(0, u + 1)", order=2, a0=1, omega0=1)
    with pytest.raises(lindstedt.ParameterError, match="sqrt"):
        expansion.frequency(-0.01)


def test_exports_state_the_gauge():
    expansion = lindstedt.expand("Max(0, u + 1)", order=2, a0=1, omega0=1)
    data = expansion.to_dict()
    assert data["gauge"] == "sqrt(epsilon)" and data["exponents"] == ["0", "1/2", "1", "3/2", "2"]
    assert r"\omega_{3/2}" in expansion.to_latex() and r"O(\varepsilon^{\frac{5}{2}})" in expansion.to_latex()
    code = lindstedt.generate_code(expansion, "frequency", "numpy").compile()
    assert float(code(np.array([0.01]))[0]) == pytest.approx(expansion.frequency(0.01), rel=1e-14)


# --------------------------------------------------------------------------- N dof
def test_nnm_of_one_dof_grazing_in_contact_is_the_linear_spring():
    """Released at the gap from inside: in contact for the whole orbit, ω = √(1 + ε) exactly (30 digits)."""
    result = lindstedt.nnm(UnilateralSystem.one_dof(1, a=1, b=-1), mode=1, a0=-1, order=4)
    taylor = [1, 0.5, -0.125, 0.0625, -0.0390625]  # √(1 + ε)
    assert result.gauge == 1
    for value, expected in zip(result.omega, taylor):
        assert abs(value - expected) < 1e-25


@pytest.mark.parametrize(
    "b, a0",
    [("3/10", 1), ("-3/10", 1), ("3/10", -1), ("2", 1), ("-2", 1), ("-1", -1), ("1", 1), ("-1", 1), ("1", -1)],
)
def test_nnm_and_expand_agree_at_one_dof_in_every_regime(b, a0):
    """Crossing, never/always in contact, release grazing from both sides, far-point grazing: ω coefficients equal."""
    result = lindstedt.nnm(UnilateralSystem.one_dof(1, a=1, b=b), mode=1, a0=a0, order=3)
    expansion = lindstedt.expand(f"Max(0, u - ({b}))", order=3, a0=a0, omega0=1)
    assert len(result.omega) == len(expansion.omega)
    with mpmath.workdps(40):
        for ours, exact in zip(result.omega, expansion.omega):
            exact = mpmath.mpf(str(sympy.N(exact, 40)))
            # nnm works in 30 digits (mode shapes included): 1e-20 leaves ten digits for rounding growth
            assert abs(mpmath.mpf(ours) - exact) <= mpmath.mpf("1e-20") * max(1, abs(exact)), (ours, exact)


def test_two_dof_grazing_spring_against_shooting():
    """Chain of 2, gap −1, mode 1, a0 = √2: the spring touches its gap at the far turning point (was ω_1 = 0)."""
    chain = UnilateralSystem.chain(2, unilateral=[(0, -1)])
    amplitude = math.sqrt(2)
    expansions = [lindstedt.nnm(chain, mode=1, a0=amplitude, order=order) for order in (1, 2, 3)]
    assert expansions[0].gauge == 2 and expansions[0].spring_roots == ("double",)
    assert float(expansions[0].omega[2]) == pytest.approx(0.25, rel=1e-12)  # ω_1 = φ_11²/2 (contact over the orbit)
    epsilons = [1e-2, 3e-3, 1e-3]
    shooting = [lindstedt.nnm_point(chain, e, 1, modal_amplitude=amplitude, tol=1e-13) for e in epsilons]
    assert all(point.success for point in shooting)
    slopes = [_fitted_slope(epsilons, [abs(r.frequency(e) - p.frequency) for e, p in zip(epsilons, shooting)]) for r in expansions]
    # errors O(ε^2), O(ε^{5/2}), O(ε^{7/2}); ε ≤ 1e-2 keeps the next terms below ~10 % of the leading one
    assert slopes == pytest.approx([2.0, 2.5, 3.5], abs=0.15)


# --------------------------------------------------------------------------- release at u(0) = a0 + ε a1 (seed Prop. 2.3)
def test_release_just_inside_a_touched_gap_is_expanded_beyond_the_linear_approximation():
    """(u − 1)_+, u(0) = 1 + ε: the mass starts ε inside the spring, in contact for a time O(ε^{1/2}) per period."""
    inside = lindstedt.expand("Max(0, u - 1)", order=3, a0=1, omega0=1, a1=1)
    assert inside.gauge == sympy.sqrt(EPSILON) and inside.contact_angles == (0,)
    assert inside.omega[:5] == (1, 0, 0, 0, 0)  # no contact at all to O(ε^2): the linear approximation
    epsilons = [mpmath.mpf(10) ** -p for p in (4, 5, 6)]
    with mpmath.workdps(50):
        exact = [piecewise_linear_exact_frequency(e, a=1, b=1, a0=1 + e, omega0=1, precision=50) for e in epsilons]
        linear = [abs(1 - x) for x in exact]
        fifth = [abs(_truncated(inside, e, 6) - x) for e, x in zip(epsilons, exact)]
    # the linear approximation misses an ε^{5/2} term (measured before: ΔT ≈ −1.88 ε^{5/2}); with it the error is O(ε^{7/2})
    # (the η^6 coefficient vanishes; the next one's relative weight ε^{1/2} ≤ 1e-2 biases the slope by < 0.01)
    assert _fitted_slope(epsilons, linear) == pytest.approx(2.5, abs=0.05)
    assert _fitted_slope(epsilons, fifth) == pytest.approx(3.5, abs=0.05)
    outside = lindstedt.expand("Max(0, u - 1)", order=3, a0=1, omega0=1, a1=-1)
    assert outside.gauge == EPSILON and outside.omega == (1, 0, 0, 0)  # released outside: never in contact


def test_release_shift_of_a_crossing_gap_against_the_exact_period():
    """(u − 1/3)_+, u(0) = 1 + ε/5: analytic; the error of the order-N series is O(ε^{N+1})."""
    expansion = lindstedt.expand("Max(0, u - 1/3)", order=3, a0=1, omega0=1, a1="1/5")
    assert expansion.gauge == EPSILON and expansion.problem.a1 == sympy.Rational(1, 5)
    epsilons = [mpmath.mpf(10) ** -p for p in (3, 4, 5)]
    with mpmath.workdps(50):
        exact = [piecewise_linear_exact_frequency(e, a=1, b="1/3", a0=1 + e / 5, omega0=1, precision=50) for e in epsilons]
        for order in (1, 2, 3):
            errors = [abs(_truncated(expansion, e, order + 1) - x) for e, x in zip(epsilons, exact)]
            assert _fitted_slope(epsilons, errors) == pytest.approx(order + 1, abs=0.05), order


def test_validation_starts_the_true_solution_at_the_shifted_release():
    errors = []
    for order in (1, 2, 3):
        expansion = lindstedt.expand("Max(0, u - 1)", order=order, a0=1, omega0=1, a1=1)
        errors.append(expansion_error(expansion, 1e-3, 100.0).max_error)
    assert errors[2] < errors[1] < errors[0] and errors[0] < 1e-6
