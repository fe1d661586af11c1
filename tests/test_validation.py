"""Validation tools (lindstedt.validate) against independent references and theory.

Expected values come from closed forms derived by hand in this file (the
piecewise-harmonic motion of u'' + ω0² u + ε a (u − b)_+ = 0, its period at
grazing), from scipy (elliptic integrals, DOP853 on a right-hand side written
here), and from the asymptotic theory of the seed (Prop. 2.2–2.3, Lemma 3.2):

* order-N expansion, simple contact or smooth f: max error on [0, 1/ε] ~ ε^{N+1};
  validity time T_ε (first time the phase-plane error exceeds C ε^{N+1}) ~ ε^{-1};
* grazing (a0 = b, u(0) = a0 + ε a1): period defect ΔP ~ ε^{5/2}, hence
  T_ε (error > C ε²) ~ ε^{-1/2};
* contact measure μ_ε(T)/T ~ ε (simple roots of u − b), ~ ε^{1/2} (double root).

Fitted slopes are tested in stated bands: ±0.1 for convergence orders and
validity exponents, ±0.02 for the contact-measure slopes (measured values are
recorded next to each test).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.special
from scipy.integrate import solve_ivp

import lindstedt
from lindstedt import ProblemError
from lindstedt.validate import (
    contact_measure,
    expansion_error,
    fitted_contact_measure_order,
    fitted_convergence_order,
    fitted_validity_exponent,
    loglog_fit,
    reference_solution,
)


# --------------------------------------------------------------------------- #
# independent references
# --------------------------------------------------------------------------- #
def unilateral_closed_form(t, a0, omega0, eps):
    """u'' + ω0² u + ε u_+ = 0, u(0) = a0 > 0, u'(0) = 0, written by hand (one period, then periodic).

    Contact (u > 0): u = a0 cos(ω' t), ω'² = ω0² + ε, until t1 = π/(2ω').
    Free (u < 0): u = −(a0 ω'/ω0) sin(ω0 (t − t1)) for a half period π/ω0.
    Period P = π/ω' + π/ω0; u is even about t = 0.
    """
    omega_c = math.sqrt(omega0**2 + eps)
    t1 = math.pi / (2 * omega_c)
    period = math.pi / omega_c + math.pi / omega0
    s = np.mod(np.asarray(t, dtype=float) + period / 2, period) - period / 2  # fold to [−P/2, P/2)
    s = np.abs(s)
    contact = a0 * np.cos(omega_c * s)
    free = -(a0 * omega_c / omega0) * np.sin(omega0 * (s - t1))
    return np.where(s <= t1, contact, free), period


def grazing_period(eps, a=1.0, b=1.0, a1=1.0, omega0=1.0):
    """Exact period of u'' + ω0² u + ε a (u − b)_+ = 0 from u(0) = A = b + ε a1 > b > 0, u'(0) = 0.

    In contact the motion is harmonic at ω'² = ω0² + ε a about u* = ε a b/ω'²;
    it leaves u = b after t_c = arccos((b − u*)/(A − u*))/ω' with speed
    v_b² = ω'²((A − u*)² − (b − u*)²); the free arc has amplitude
    R = (b² + v_b²/ω0²)^{1/2} and lasts (2π − 2 arccos(b/R))/ω0.  The arccos of
    numbers near 1 are written as 2 arctan(((1 − c)/(1 + c))^{1/2}) with 1 − c
    formed without cancellation.
    """
    big_a = b + eps * a1
    omega_c2 = omega0**2 + eps * a
    centre = eps * a * b / omega_c2
    one_minus_c = (big_a - b) / (big_a - centre)
    contact_angle = 2 * math.atan(math.sqrt(one_minus_c / (2 - one_minus_c)))
    v_b2 = omega_c2 * (big_a - b) * (big_a + b - 2 * centre)
    radius = math.sqrt(b * b + v_b2 / omega0**2)
    one_minus_free = (v_b2 / omega0**2) / (radius + b) / radius
    free_angle = 2 * math.atan(math.sqrt(one_minus_free / (2 - one_minus_free)))
    return 2 * contact_angle / math.sqrt(omega_c2) + (2 * math.pi - 2 * free_angle) / omega0


def duffing_period(a0, eps, omega0=1.0):
    """Exact period of u'' + ω0² u + ε u³ = 0 from (a0, 0): 4 K(m)/Ω, Ω² = ω0² + ε a0², m = ε a0²/(2Ω²)."""
    big_omega2 = omega0**2 + eps * a0**2
    return 4 * scipy.special.ellipk(eps * a0**2 / (2 * big_omega2)) / math.sqrt(big_omega2)


def dop853(force, eps, u0, t_end, omega0=1.0):
    """scipy DOP853 on u'' = −ω0² u − ε force(u), tight tolerances (a kink costs accuracy ~1e-10)."""

    def rhs(_t, y):
        return [y[1], -omega0**2 * y[0] - eps * force(y[0])]

    return solve_ivp(rhs, (0.0, t_end), [u0, 0.0], method="DOP853", rtol=1e-13, atol=1e-15, dense_output=True).sol


# --------------------------------------------------------------------------- #
# reference_solution
# --------------------------------------------------------------------------- #
@pytest.mark.parametrize("eps", [0.01, 0.3, 3.0])
def test_reference_matches_hand_closed_form_for_u_plus(eps):
    t = np.linspace(0.0, 40.0, 4001)
    reference = reference_solution(lindstedt.Oscillator("Max(0, u)", a0="3/2", omega0=2), eps, t)
    expected, _ = unilateral_closed_form(t, 1.5, 2.0, eps)
    assert reference.success and reference.method == "exact"
    assert np.max(np.abs(reference.displacement - expected)) < 1e-13
    assert reference.n_switches == np.count_nonzero(np.diff(np.sign(expected)) != 0)


def test_reference_conserves_energy_with_gap_and_expansion_symbols():
    # a (u − b)_+ with a = 2, b = 1/3, symbolic a0 and omega0 given by values
    expansion = lindstedt.expand("a*Max(0, u - b)", order=1, params={"a": 2, "b": "1/3"})
    eps, a, b = 0.2, 2.0, 1.0 / 3.0
    t = np.linspace(0.0, 200.0, 20001)
    reference = reference_solution(expansion, eps, t, values={"a0": 1, "omega0": "3/2"})
    u, v = reference.displacement, reference.velocity
    energy = 0.5 * v**2 + 0.5 * 2.25 * u**2 + 0.5 * eps * a * np.maximum(u - b, 0.0) ** 2
    assert reference.initial_displacement == 1.0
    assert np.max(np.abs(energy - energy[0])) < 1e-13
    # first contact arc by hand: u = u* + (1 − u*) cos(ω' t), ω'² = ω0² + εa, u* = εab/ω'²
    omega_c = math.sqrt(2.25 + eps * a)
    centre = eps * a * b / omega_c**2
    early = t < 0.3
    assert np.max(np.abs(u[early] - (centre + (1 - centre) * np.cos(omega_c * t[early])))) < 1e-14


@pytest.mark.parametrize(
    "f, force, eps, u0, method",
    [
        # linear part, constant, springs on both sides (shifted coordinates, W ≠ Aᵀ)
        ("u/2 + 3*Max(0, u - 1/3) + Max(0, -u - 1/2) - 1/5",
         lambda u: u / 2 + 3 * max(0.0, u - 1 / 3) + max(0.0, -u - 0.5) - 0.2, 0.3, 1.0, "exact"),
        ("-Max(0, u - 1/2)/2", lambda u: -0.5 * max(0.0, u - 0.5), 0.3, 1.0, "exact"),  # softening spring
        ("Abs(u)", lambda u: abs(u), 0.2, 1.0, "exact"),
        # contact stiffness 1 − 2 < 0: no closed-form modes, DOP853 restarted at the breakpoint
        ("-4*Max(0, u - 1/2)", lambda u: -4 * max(0.0, u - 0.5), 0.5, 0.6, "DOP853-piecewise"),
    ],
)
def test_reference_for_general_piecewise_linear_f(f, force, eps, u0, method):
    t = np.linspace(0.0, 60.0, 3001)
    reference = reference_solution(lindstedt.Oscillator(f, a0=u0, omega0=1), eps, t)
    expected = dop853(force, eps, u0, 60.0)(t)[0]
    assert reference.success and reference.method == method
    assert reference.n_switches > 10
    assert np.max(np.abs(reference.displacement - expected)) < 1e-8  # the independent DOP853 crosses kinks


def test_reference_duffing_returns_after_the_elliptic_period():
    eps, a0 = 0.3, 1.2
    period = duffing_period(a0, eps)
    reference = reference_solution(lindstedt.Oscillator("u**3", a0="1.2", omega0=1), eps, [period / 2, period, 10 * period])
    assert reference.method == "DOP853" and reference.success
    assert abs(reference.displacement[1] - a0) < 1e-10
    assert abs(reference.displacement[2] - a0) < 1e-9
    assert abs(reference.velocity[0]) < 1e-10  # turning point at half period


def test_reference_initial_offset_and_errors():
    problem = lindstedt.Oscillator("Max(0, u - 1)", a0=1, omega0=1)
    assert reference_solution(problem, 0.01, [0.0], a1=2.0).initial_displacement == pytest.approx(1.02, abs=1e-15)
    with pytest.raises(ProblemError, match="harmonic"):
        reference_solution(lindstedt.Oscillator("u**3", a0=1, omega0=1, normalization="harmonic"), 0.1, [1.0])
    with pytest.raises(ProblemError, match="non-negative"):
        reference_solution(problem, 0.1, [-1.0])
    with pytest.raises(lindstedt.ParameterError):
        reference_solution(lindstedt.Oscillator("Max(0, u)"), 0.1, [1.0])


# --------------------------------------------------------------------------- #
# expansion_error and convergence orders
# --------------------------------------------------------------------------- #
def test_expansion_error_against_hand_closed_form():
    expansion = lindstedt.expand("Max(0, u)", order=1, a0=1, omega0=1)
    eps, t_end = 0.05, 60.0
    result = expansion_error(expansion, eps, t_end, 6001)
    exact, _ = unilateral_closed_form(result.times, 1.0, 1.0, eps)
    independent = expansion.displacement(result.times, eps) - exact
    assert result.success and result.reference_method == "exact"
    assert result.n_samples == 6001 and result.times[-1] == t_end
    assert np.max(np.abs(result.error - independent)) < 1e-13
    assert result.max_error == pytest.approx(np.max(np.abs(independent)), abs=1e-13)
    assert np.all(result.phase_error >= np.abs(result.error) - 1e-16)
    assert result.max_error < 5 * eps**2  # order 1: O(ε²) on t ≤ C/ε


@pytest.mark.parametrize(
    "f, a0, order, epsilons, measured",
    [
        ("Max(0, u)", 1, 0, [0.04, 0.02, 0.01, 0.005], 0.988),
        ("Max(0, u)", 1, 1, [0.04, 0.02, 0.01, 0.005], 1.978),
        ("Max(0, u)", 1, 2, [0.04, 0.02, 0.01, 0.005], 2.975),
        ("Max(0, u - 1/3)", 1, 2, [0.04, 0.02, 0.01, 0.005], 2.985),
        ("Max(0, u - 1/3)", -1, 1, [0.04, 0.02, 0.01, 0.005], 1.974),
        ("u**3", 1, 1, [0.08, 0.04, 0.02, 0.01], 1.954),
    ],
)
def test_convergence_order_is_N_plus_one(f, a0, order, epsilons, measured):
    expansion = lindstedt.expand(f, order=order, a0=a0, omega0=1)
    fit = fitted_convergence_order(expansion, epsilons)  # windows [0, 1/ε]
    assert fit.success, fit.message
    assert abs(fit.slope - (order + 1)) < 0.1  # theory: N + 1 (measured value in the parameters)
    assert fit.standard_error < 0.02
    assert fit.n_reference_solves == len(epsilons) and fit.n_samples > 0
    assert np.allclose(fit.t_ends, 1 / np.asarray(epsilons))


def test_convergence_order_reports_exact_grazing_as_unfittable():
    # a0 = b exactly: the mass only touches the spring, the linear motion is exact
    expansion = lindstedt.expand("Max(0, u - 1)", order=1, a0=1, omega0=1)
    fit = fitted_convergence_order(expansion, [0.02, 0.01])
    assert not fit.success and "rounding" in fit.message
    assert np.all(fit.max_errors < 1e-13)


def test_a1_rejected_where_first_order_response_is_inconsistent():
    with pytest.raises(ProblemError, match="a0 \\+ ε a1"):
        expansion_error(lindstedt.expand("Max(0, u)", order=1, a0=1, omega0=1), 0.01, 10.0, a1=1.0)


def test_loglog_fit_standard_error():
    fit = loglog_fit([1.0, 2.0, 4.0], [1.0, 2.0, 8.0])
    # by hand: x = (0, l, 2l), y = (0, l, 3l), l = ln 2: slope 3/2, intercept −l/6,
    # residuals (1/6, −1/3, 1/6) l, so SE² = (l²/6)/(3 − 2)/(Σ(x − x̄)² = 2 l²) = 1/12
    assert fit.slope == pytest.approx(1.5, abs=1e-14)
    assert fit.intercept == pytest.approx(-math.log(2) / 6, abs=1e-14)
    assert fit.standard_error == pytest.approx(math.sqrt(1 / 12), rel=1e-12)
    assert math.isnan(loglog_fit([1.0, 2.0], [1.0, 3.0]).standard_error)


# --------------------------------------------------------------------------- #
# validity exponents
# --------------------------------------------------------------------------- #
@pytest.mark.parametrize(
    "f, order, measured",
    [("Max(0, u)", 0, -0.984), ("Max(0, u - 1/3)", 1, -0.985)],
)
def test_validity_exponent_simple_contact_is_minus_one(f, order, measured):
    expansion = lindstedt.expand(f, order=order, a0=1, omega0=1)
    fit = fitted_validity_exponent(expansion, [0.04, 0.02, 0.01, 0.005])
    assert fit.success, fit.message
    assert abs(fit.exponent + 1.0) < 0.1  # theory: drift ε^{N+2} t against ε^{N+1}
    assert fit.threshold_power == order + 1
    assert np.all(fit.validity_times > 0) and np.all(np.diff(fit.validity_times) > 0)


def test_grazing_period_defect_scales_like_eps_to_five_halves():
    epsilons = np.array([1e-2, 3e-3, 1e-3, 3e-4, 1e-4])
    defects = np.array([abs(grazing_period(eps) - 2 * math.pi) for eps in epsilons])
    fit = loglog_fit(epsilons, defects)
    assert abs(fit.slope - 2.5) < 0.02  # measured 2.49…
    # and the closed form agrees with the exact flow: after 10 periods the motion is back at u(0)
    eps = 0.01
    period = grazing_period(eps)
    reference = reference_solution(lindstedt.Oscillator("Max(0, u - 1)", a0=1, omega0=1), eps, [10 * period], a1=1.0)
    assert abs(reference.displacement[0] - 1.01) < 1e-13 and abs(reference.velocity[0]) < 1e-12


@pytest.mark.parametrize("a0, a1", [(1, 1.0), (-1, -1.0)])
def test_validity_exponent_grazing_is_minus_one_half(a0, a1):
    expansion = lindstedt.expand("Max(0, u - 1)", order=1, a0=a0, omega0=1)
    epsilons = [0.01, 0.005, 0.0025, 0.00125]
    fit = fitted_validity_exponent(expansion, epsilons, a1=a1)
    assert fit.success, fit.message
    assert abs(fit.exponent + 0.5) < 0.1  # measured −0.497 (a0 = 1), −0.487 (a0 = −1)
    assert fit.threshold_power == 2


def test_grazing_validity_time_predicted_by_the_period_defect():
    # ρ(t) ≈ |A| ω0 |ΔP| (number of contacts): first exceedance of C ε² after
    # n = C ε²/(A |ΔP|) periods, to within one period (ρ is a staircase)
    constant = 10.0
    epsilons = [0.01, 0.0025]
    expansion = lindstedt.expand("Max(0, u - 1)", order=1, a0=1, omega0=1)
    fit = fitted_validity_exponent(expansion, epsilons, constant, a1=1.0)
    assert fit.success, fit.message
    for eps, measured in zip(epsilons, fit.validity_times):
        period = grazing_period(eps)
        predicted = constant * eps**2 / ((1 + eps) * abs(period - 2 * math.pi)) * period
        assert abs(measured - predicted) < period + 0.03 * predicted


def test_validity_exponent_duffing_is_minus_one():
    fit = fitted_validity_exponent(lindstedt.expand("u**3", order=1, a0=1, omega0=1), [0.08, 0.04, 0.02])
    assert fit.success, fit.message
    assert abs(fit.exponent + 1.0) < 0.1  # measured −0.985


# --------------------------------------------------------------------------- #
# contact measure (Lemma 3.2)
# --------------------------------------------------------------------------- #
def test_contact_measure_of_cosine_samples_and_dense():
    t = np.linspace(0.0, 4 * np.pi, 4001)
    exact = 8 * np.arcsin(0.02)  # |cos t| ≤ 0.02: four crossings of width 2 arcsin(0.02)
    sampled = contact_measure(np.cos(t), t, 0.02)
    dense = contact_measure(np.cos, t, 0.02)
    assert sampled.success and dense.success
    assert abs(sampled.measure - exact) < 1e-6  # linear interpolation, step 3e-3
    assert abs(dense.measure - exact) < 1e-14
    assert dense.n_refined == 8 and len(dense.intervals) == 4
    # two levels: |cos t − 1/2| ≤ 0.02 or |cos t + 1/2| ≤ 0.02, eight crossings each way
    both = contact_measure(np.cos, t, 0.02, level=[0.5, -0.5])
    width = (np.arccos(0.48) - np.arccos(0.52)) + (np.arccos(-0.52) - np.arccos(-0.48))
    assert abs(both.measure - 4 * width) < 1e-13


def test_contact_measure_crossing_within_one_step_and_unresolved_extremum():
    # a steep crossing inside one grid step is still measured
    t = np.linspace(-1.0, 1.0, 3)
    assert contact_measure(lambda s: 10 * s, t, 0.1).measure == pytest.approx(0.02, abs=1e-15)
    # the top of cos (value 1) lies 0.001 below the band [1.001, 1.021]
    coarse = np.linspace(-1.0, 7.0, 26)
    fine = np.linspace(-1.0, 7.0, 4001)
    assert not contact_measure(np.cos, coarse, 0.01, level=1.011).success
    result = contact_measure(np.cos, fine, 0.01, level=1.011)
    assert result.success and result.measure == 0.0


def test_contact_measure_of_true_u_plus_solution_over_one_period():
    # by hand (closed form above): each zero crossing spends arcsin(εM/a0)/ω' on the
    # contact side and arcsin(εM ω0/(a0 ω'))/ω0 on the free side of the band
    eps, M, a0, omega0 = 0.05, 1.5, 1.0, 1.0
    omega_c = math.sqrt(omega0**2 + eps)
    _, period = unilateral_closed_form([0.0], a0, omega0, eps)
    expected = 2 * (math.asin(eps * M / a0) / omega_c + math.asin(eps * M * omega0 / (a0 * omega_c)) / omega0)
    t = np.linspace(0.0, period, 2001)
    reference = reference_solution(lindstedt.Oscillator("Max(0, u)", a0=1, omega0=1), eps, t)
    result = contact_measure(lambda s: reference.state(s)[0], t, eps * M)
    assert result.success
    assert abs(result.measure - expected) < 1e-12


def test_contact_measure_slopes_simple_root_and_grazing():
    epsilons = [0.04, 0.02, 0.01, 0.005]
    simple = fitted_contact_measure_order(lindstedt.expand("Max(0, u - 1/3)", order=0, a0=1, omega0=1), epsilons)
    assert simple.success, simple.message
    assert abs(simple.slope - 1.0) < 0.02  # measured 0.996
    grazing_expansion = lindstedt.expand("Max(0, u - 1)", order=0, a0=1, omega0=1)
    grazing = fitted_contact_measure_order(grazing_expansion, epsilons, a1=0.5)
    assert grazing.success, grazing.message
    assert abs(grazing.slope - 0.5) < 0.02  # measured 0.498
    assert grazing.expected_slope == 0.5 and simple.expected_slope == 1.0
    # a1 = 0: the true motion is cos t, the set is |t − 2πk| ≤ arccos(1 − ε) exactly
    exact = fitted_contact_measure_order(grazing_expansion, epsilons, periods=20)
    assert np.allclose(exact.measures, 20 * 2 * np.arccos(1 - np.asarray(epsilons)), rtol=0, atol=1e-12)
