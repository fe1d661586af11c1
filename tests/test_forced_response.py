"""Forced responses: shooting, continuation, bifurcations, branch switching (issue 15).

References are independent of the code under test: the textbook closed form of the forced, damped
linear oscillator (amplitude, phase, Floquet multipliers exp(λT)), finite differences of the period map,
and long-time integration to the steady state by a separate scipy DOP853 integration.
"""

import json
import math
import pickle
import sys

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from lindstedt import LindstedtError, ParameterError, ProblemError, UnilateralSystem
from lindstedt.numerics.forced_response import (
    FrequencyResponse,
    forced_periodic_orbit,
    frequency_response,
    frequency_response_sweep,
    switch_period_doubling,
)
from lindstedt.numerics.forced_smooth import SmoothForcedFlow
from lindstedt.problems.forced import ForcedOscillator, ForcedSystem

# u'' + 2 ζ u' + u + ε u = ε F cos Ωt: a linear oscillator of stiffness 1 + ε
EPS, ZETA, F = 0.5, 0.05, 1.0


@pytest.fixture(scope="module")
def linear_flow():
    return SmoothForcedFlow(ForcedOscillator("u", omega0=1, zeta="1/20", forcing=1), EPS)


def linear_response(omega, scale=1.0):
    """Complex amplitude H with u = Re(H e^{iΩt}) (textbook)."""
    return EPS * F * scale / (1 + EPS - omega**2 + 2j * ZETA * omega)


def linear_multipliers(omega):
    lam = -ZETA + 1j * math.sqrt(1 + EPS - ZETA**2)
    T = 2 * math.pi / omega
    return np.exp(lam * T), np.exp(np.conj(lam) * T)


def steady_state(rhs, z0, omega, periods, marks=()):
    """Long-time DOP853 integration (rtol 1e-12) of an independent right-hand side; states at t = m T."""
    T = 2 * math.pi / omega
    times = [m * T for m in marks] or [periods * T]
    solution = solve_ivp(rhs, (0, periods * T), z0, method="DOP853", rtol=1e-12, atol=1e-13, t_eval=times)
    assert solution.success
    return solution.y.T


# --------------------------------------------------------------------------- #
# the flow
# --------------------------------------------------------------------------- #
def test_flow_implements_the_protocol_and_pickles(linear_flow):
    assert callable(linear_flow.period_map) and callable(linear_flow.sample) and linear_flow.dimension == 2
    again = pickle.loads(pickle.dumps(linear_flow))
    np.testing.assert_array_equal(again.period_map([0.1, 0.2], 1.3).d_state, linear_flow.period_map([0.1, 0.2], 1.3).d_state)


@pytest.mark.parametrize("law", ["u**3", "Max(0, u - 1/5)", "Heaviside(u - 1/5)", "u*Abs(u)", "Max(0, u - 1/5)**(3/2)"])
def test_period_map_derivatives_match_finite_differences(law):
    flow = SmoothForcedFlow(ForcedOscillator(law, omega0=1, zeta="1/20", forcing=1), 0.7)
    z0, omega, s, h = np.array([0.5, 0.1]), 1.3, 1.2, 1e-5
    value = flow.period_map(z0, omega, forcing_scale=s)

    def state(z=z0, w=omega, scale=s):
        return flow.period_map(z, w, forcing_scale=scale, sensitivity=False).state

    jacobian = np.column_stack([(state(z0 + h * e) - state(z0 - h * e)) / (2 * h) for e in np.eye(2)])
    np.testing.assert_allclose(value.d_state, jacobian, atol=1e-7)
    np.testing.assert_allclose(value.d_frequency, (state(w=omega + h) - state(w=omega - h)) / (2 * h), atol=1e-7)
    np.testing.assert_allclose(value.d_forcing, (state(scale=s + h) - state(scale=s - h)) / (2 * h), atol=1e-7)
    if law != "u**3":
        assert value.counters["switches"] >= 1 and value.counters["arcs"] == value.counters["switches"] + 1


def test_system_flow_derivatives_and_linear_orbit():
    # springs far away (gap 10): the response is linear, X̂ = (K − Ω²M + iΩC)⁻¹ ε P
    system = UnilateralSystem.chain(2, [(1, 10)])
    problem = ForcedSystem(system, load=[1, 0], rayleigh=("1/50", "1/100"))
    flow = SmoothForcedFlow(problem, 0.3)
    omega = 0.9
    orbit = forced_periodic_orbit(flow, omega)
    X = np.linalg.solve(system.K - omega**2 * system.M + 1j * omega * problem.C, 0.3 * problem.P)
    np.testing.assert_allclose(orbit.harmonic, np.abs(X), rtol=1e-10)
    np.testing.assert_allclose(orbit.state, np.r_[X.real, -omega * X.imag], rtol=1e-9, atol=1e-12)
    # with contact (gap 1/10) the derivatives still match finite differences
    contact = SmoothForcedFlow(ForcedSystem(UnilateralSystem.chain(2, [(1, "1/10")]), load=[1, 0], rayleigh=(0, "1/100")), 2.0)
    z0, h = np.array([0.3, 0.05, 0.0, 0.2]), 1e-6
    value = contact.period_map(z0, omega)
    jacobian = np.column_stack([(contact.period_map(z0 + h * e, omega, sensitivity=False).state
                                 - contact.period_map(z0 - h * e, omega, sensitivity=False).state) / (2 * h) for e in np.eye(4)])
    assert value.counters["switches"] > 0
    np.testing.assert_allclose(value.d_state, jacobian, atol=1e-7)


# --------------------------------------------------------------------------- #
# the linear oscillator: closed form
# --------------------------------------------------------------------------- #
@pytest.mark.parametrize("omega", [0.5, 1.0, 1.22, 2.0])
def test_linear_orbit_matches_closed_form(linear_flow, omega):
    orbit = forced_periodic_orbit(linear_flow, omega, initial_state=[0.0, 0.0])
    H = linear_response(omega)
    assert orbit.success and orbit.stable and orbit.minimal_periods == 1
    assert abs(orbit.amplitude[0] - abs(H)) <= 1e-10 * abs(H)
    assert abs(orbit.maximum[0] - abs(H)) <= 1e-10 * abs(H) and abs(orbit.minimum[0] + abs(H)) <= 1e-10 * abs(H)
    assert abs(orbit.harmonic_cos[0] - H.real) <= 1e-10 * abs(H) and abs(orbit.harmonic_sin[0] + H.imag) <= 1e-10 * abs(H)
    assert abs(orbit.phase[0] - math.atan2(2 * ZETA * omega, 1 + EPS - omega**2)) <= 1e-10
    assert abs(orbit.mean[0]) <= 1e-12
    np.testing.assert_allclose(orbit.state, [H.real, -omega * H.imag], rtol=1e-10, atol=1e-13)
    expected = sorted(linear_multipliers(omega), key=lambda m: m.imag)
    np.testing.assert_allclose(sorted(orbit.multipliers, key=lambda m: m.imag), expected, atol=1e-11)


def test_linear_frequency_response_matches_closed_form(linear_flow):
    response = frequency_response(linear_flow, 0.6, 1.8, tol=1e-11)
    assert response.success and response.message.startswith("reached stop")
    assert response.bifurcations == () and response.stable.all()
    omega = response.frequencies
    assert omega[0] == 0.6 and omega[-1] == 1.8 and np.all(np.diff(omega) > 0)
    H = linear_response(omega)
    error = np.max(np.abs(response.amplitudes[:, 0] - np.abs(H)) / np.abs(H))
    assert error < 1e-9
    exact = np.c_[H.real, -omega * H.imag]
    assert np.max(np.abs(response.states - exact)) < 1e-10 * np.max(np.abs(exact))
    assert response.flow_evaluations >= len(response) and response.steps > 0 and response.evaluations > response.steps


def test_linear_continuation_in_the_load_scale(linear_flow):
    response = frequency_response(linear_flow, 0.5, 2.0, parameter="forcing", frequency=1.1)
    assert response.success and response.parameter == "forcing"
    H = linear_response(1.1, response.forcing_scales)
    np.testing.assert_allclose(response.amplitudes[:, 0], np.abs(H), rtol=1e-9)
    assert np.all(response.frequencies == 1.1)


# --------------------------------------------------------------------------- #
# Duffing: folds, stability against long-time integration
# --------------------------------------------------------------------------- #
DUFFING_EPS = 0.2


@pytest.fixture(scope="module")
def duffing():
    flow = SmoothForcedFlow(ForcedOscillator("u**3", omega0=1, zeta="1/20", forcing=1), DUFFING_EPS, rtol=1e-11)
    return flow, frequency_response(flow, 0.8, 1.6, tol=1e-9)


def duffing_rhs(omega):
    return lambda t, y: [y[1], -0.1 * y[1] - y[0] - DUFFING_EPS * y[0] ** 3 + DUFFING_EPS * math.cos(omega * t)]


def test_duffing_folds_are_located(duffing):
    _, response = duffing
    assert response.success
    folds = response.of_kind("fold")
    assert [b.kind for b in response.bifurcations] == ["fold", "fold"]
    up, down = folds
    assert up.frequency > down.frequency  # hardening: the branch turns back at the jump-down, then forward
    for fold in folds:
        # a multiplier +1 at a fold of the period map
        assert np.min(np.abs(fold.multipliers - 1)) < 1e-6
    # between the folds the middle branch is unstable, elsewhere stable
    stable = response.stable
    inside = np.arange(len(response))
    middle = (inside > up.index) & (inside <= down.index)
    assert not stable[middle].any() and stable[~middle].all()
    # the fold is the extremum of Ω along the branch
    omega = response.frequencies
    assert omega[:down.index + 1].max() <= up.frequency + 1e-9 and omega[up.index + 1:].min() >= down.frequency - 1e-9


@pytest.mark.parametrize("omega", [1.0, 1.17, 1.4])
def test_duffing_stable_orbits_agree_with_long_time_integration(duffing, omega):
    flow, response = duffing
    branches = []
    for k in range(len(response) - 1):
        a, b = response.frequencies[k], response.frequencies[k + 1]
        if min(a, b) <= omega <= max(a, b):
            guess = response.states[k] + (omega - a) / (b - a) * (response.states[k + 1] - response.states[k])
            branches.append(forced_periodic_orbit(flow, omega, initial_state=guess, tol=1e-11))
    assert len(branches) == (3 if omega == 1.17 else 1)
    assert all(orbit.success and orbit.minimal_periods == 1 for orbit in branches)
    T = 2 * math.pi / omega
    for orbit in branches:
        if orbit.stable:
            # from a perturbed state, the transient ~ max|μ|^n falls below 1e-11
            n = int(math.log(1e-11) / math.log(orbit.max_abs_multiplier)) + 5
            end = steady_state(duffing_rhs(omega), orbit.state + [2e-2, -1e-2], omega, n)[-1]
            np.testing.assert_allclose(end, orbit.state, atol=2e-8)
        else:
            # from next to the unstable middle orbit the flow leaves it for one of the stable ones
            end = steady_state(duffing_rhs(omega), orbit.state + [1e-6, 0], omega, 400)[-1]
            distances = [np.max(np.abs(end - other.state)) for other in branches]
            assert np.max(np.abs(end - orbit.state)) > 1e-2
            assert min(d for d, other in zip(distances, branches) if other.stable) < 1e-7
    if omega == 1.17:
        amplitudes = sorted(float(o.amplitude[0]) for o in branches)
        stable_by_amplitude = [o.stable for o in sorted(branches, key=lambda o: o.amplitude[0])]
        assert stable_by_amplitude == [True, False, True] and amplitudes[0] < amplitudes[1] < amplitudes[2]
        assert T > 0


# --------------------------------------------------------------------------- #
# period doubling of the bilinear oscillator u'' + 0.1 u' + u + 8 u_+ = 8 cos Ωt
# --------------------------------------------------------------------------- #
PD_EPS = 8.0


@pytest.fixture(scope="module")
def bilinear():
    flow = SmoothForcedFlow(ForcedOscillator("Max(0, u)", omega0=1, zeta="1/20", forcing=1), PD_EPS, rtol=1e-11)
    return flow, frequency_response(flow, 2.2, 2.5, tol=1e-9)


def bilinear_rhs(omega):
    return lambda t, y: [y[1], -0.1 * y[1] - y[0] - PD_EPS * max(0.0, y[0]) + PD_EPS * math.cos(omega * t)]


def test_period_doubling_is_located(bilinear):
    _, response = bilinear
    assert response.success
    assert [b.kind for b in response.bifurcations] == ["period-doubling"]
    pd = response.bifurcations[0]
    assert abs(pd.frequency - 2.33815797) < 1e-6
    assert np.min(np.abs(pd.multipliers + 1)) < 1e-6
    before = response.frequencies <= pd.frequency
    assert response.stable[before].all() and not response.stable[~before].any()
    after = response.points[-1]
    assert after.multipliers[0].real < -1 and abs(after.multipliers[0].imag) == 0


def test_period_two_branch_against_long_time_integration(bilinear):
    flow, response = bilinear
    branch = switch_period_doubling(response, 0, stop=2.5, tol=1e-9)
    assert branch.success and branch.periods == 2
    assert all(p.minimal_periods == 2 for p in branch.points)
    pd = response.bifurcations[0]
    assert branch.frequencies.min() >= pd.frequency - 1e-9  # supercritical: on the side where period 1 is unstable
    omega = 2.45
    nearest = branch.states[np.argmin(np.abs(branch.frequencies - omega))]
    orbit = forced_periodic_orbit(flow, omega, initial_state=nearest, periods=2, tol=1e-11)
    assert orbit.success and orbit.minimal_periods == 2 and orbit.stable
    once = flow.period_map(orbit.state, omega, sensitivity=False).state
    twice = flow.period_map(once, omega, sensitivity=False).state
    assert np.max(np.abs(once - orbit.state)) > 0.5  # Π(z) ≠ z
    np.testing.assert_allclose(twice, orbit.state, atol=1e-9)  # Π∘Π(z) = z
    period_one = forced_periodic_orbit(flow, omega, tol=1e-11)
    assert period_one.success and not period_one.stable and period_one.multipliers[0].real < -1
    # the flow from rest settles on the period-2 orbit: alternately z* and Π(z*)
    ends = steady_state(bilinear_rhs(omega), [0.0, 0.0], omega, 300, marks=(298, 299, 300))
    first = ends[0] if np.max(np.abs(ends[0] - orbit.state)) < np.max(np.abs(ends[0] - once)) else ends[1]
    np.testing.assert_allclose(first, orbit.state, atol=1e-7)
    np.testing.assert_allclose(ends[2], ends[0], atol=1e-7)
    assert np.max(np.abs(ends[1] - ends[0])) > 0.5


def test_period_doubling_agrees_with_the_exact_flow(bilinear):
    """The exact event-driven flow (closed-form arcs) through the same PeriodMap interface."""
    forced_flow = pytest.importorskip("lindstedt.numerics.forced_flow")
    _, response = bilinear
    exact = forced_flow.ForcedFlow(ForcedOscillator("Max(0, u)", omega0=1, zeta="1/20", forcing=1), PD_EPS)
    reference = frequency_response(exact, 2.2, 2.5, tol=1e-9)
    assert [b.kind for b in reference.bifurcations] == ["period-doubling"]
    assert abs(reference.bifurcations[0].frequency - response.bifurcations[0].frequency) < 1e-9
    np.testing.assert_allclose(reference.bifurcations[0].state, response.bifurcations[0].state, atol=1e-8)


# --------------------------------------------------------------------------- #
# bad input, failures, exports
# --------------------------------------------------------------------------- #
def test_invalid_arguments_raise_typed_errors(linear_flow):
    with pytest.raises(ParameterError):
        forced_periodic_orbit(linear_flow, 0.0)
    with pytest.raises(ParameterError):
        forced_periodic_orbit(linear_flow, -1.0)
    with pytest.raises(ParameterError):
        frequency_response(linear_flow, -0.5, 1.0)
    with pytest.raises(ProblemError, match="start == stop"):
        frequency_response(linear_flow, 1.0, 1.0)
    with pytest.raises(ProblemError, match="parameter"):
        frequency_response(linear_flow, 0.5, 1.0, parameter="amplitude")
    with pytest.raises(ProblemError, match="frequency="):
        frequency_response(linear_flow, 0.5, 1.0, parameter="forcing")
    with pytest.raises(ProblemError, match="periods"):
        forced_periodic_orbit(linear_flow, 1.0, periods=0)
    with pytest.raises(ProblemError, match="PeriodMap"):
        forced_periodic_orbit(object(), 1.0)
    with pytest.raises(ProblemError, match="initial_state"):
        forced_periodic_orbit(linear_flow, 1.0, initial_state=[1.0])
    with pytest.raises(ProblemError, match="step"):
        frequency_response(linear_flow, 0.5, 1.0, step=1.0, max_step=0.5)
    with pytest.raises(ProblemError):
        SmoothForcedFlow(ForcedOscillator("u**3", omega0=1), float("nan"))
    with pytest.raises(LindstedtError):
        SmoothForcedFlow(ForcedOscillator("u**3"), 1.0)  # omega0 symbolic: needs a value
    with pytest.raises(ProblemError, match="epsilon"):
        frequency_response_sweep([ForcedOscillator("u", omega0=1)], 0.5, 1.0)


def test_non_convergence_is_reported_not_raised(linear_flow):
    orbit = forced_periodic_orbit(linear_flow, 1.0, initial_state=[50.0, -40.0], max_iterations=0, transient_periods=0)
    assert not orbit.success and "no convergence" in orbit.message and np.isnan(orbit.amplitude).all()
    short = frequency_response(linear_flow, 0.6, 1.8, max_points=3)
    assert not short.success and "max_points" in short.message and len(short) == 3
    hard = SmoothForcedFlow(ForcedOscillator("u**3", omega0=1, zeta="1/20", forcing=1), DUFFING_EPS, rtol=1e-9)
    failed = frequency_response(hard, 1.17, 1.3, initial_state=[5.0, 5.0], max_iterations=2, transient_periods=0)
    assert not failed.success and failed.message.startswith("first point failed") and len(failed) == 0


def test_exports(linear_flow):
    response = frequency_response(linear_flow, 0.9, 1.1, tol=1e-9)
    data = json.loads(response.to_json())
    assert data["schema"] == "lindstedt.frequency-response/1" and data["success"] is True
    assert data["description"]["kind"] == "ForcedOscillator" and "flow" not in data
    assert data["points"][0]["schema"] == "lindstedt.forced-orbit/1" and len(data["points"]) == len(response)
    assert len(data["points"][0]["multipliers"][0]) == 2  # complex as [re, im]
    orbit_data = json.loads(response.points[0].to_json())
    assert orbit_data["frequency"] == 0.9 and "monodromy" not in orbit_data
    text = repr(response)
    assert "FrequencyResponse(" in text and "points=" in text and len(text) < 2000
    assert "<table" in response._repr_html_() and "<table" in response.points[0]._repr_html_()
    assert "ForcedOrbit(" in repr(response.points[0])
    table = response.to_dataframe()
    assert list(table.columns[:4]) == ["frequency", "forcing_scale", "stable", "max_abs_multiplier"]
    assert {"amplitude_1", "harmonic_1", "mean_1", "bifurcation_after"} <= set(table.columns) and len(table) == len(response)


def test_dataframe_without_pandas_names_the_extra(linear_flow, monkeypatch):
    response = frequency_response(linear_flow, 0.9, 1.0, tol=1e-8)
    monkeypatch.setitem(sys.modules, "pandas", None)
    with pytest.raises(LindstedtError, match=r"pip install 'lindstedt\[pandas\]'"):
        response.to_dataframe()


def test_sweep_over_forcing_levels_and_problems():
    problem = ForcedOscillator("u**3", omega0=1, zeta="1/10", forcing=1)
    seen = []
    family = frequency_response_sweep(problem, 0.9, 1.3, epsilon=0.1, forcing_scales=[0.5, 1.0], tol=1e-8,
                                      progress=lambda index, job, result: seen.append(index))
    assert sorted(seen) == [0, 1] and all(isinstance(r, FrequencyResponse) and r.success for r in family)
    assert family[1].amplitudes.max() > family[0].amplitudes.max()
    with pytest.raises(ProblemError, match="single"):
        frequency_response_sweep([problem, problem], 0.9, 1.3, epsilon=0.1, forcing_scales=[1.0])


def test_neimark_sacker_on_a_two_dof_chain():
    # M X'' + C X' + K X + ε (X_2 − 1/10)_+ = ε P cos Ωt, chain of 2 masses, ε = 2: a complex pair leaves the unit circle
    problem = ForcedSystem(UnilateralSystem.chain(2, [(1, "1/10")]), load=[1, 0], rayleigh=(0, "1/50"))
    response = frequency_response(SmoothForcedFlow(problem, 2.0, rtol=1e-10), 0.95, 1.0, tol=1e-9)
    assert response.success
    found = response.of_kind("neimark-sacker")
    assert len(found) == 2
    for point in found:
        pair = point.multipliers[np.argsort(np.abs(np.abs(point.multipliers) - 1))[:2]]
        assert np.all(np.abs(np.abs(pair) - 1) < 1e-7) and abs(pair[0].imag) > 0.1
    first, second = found
    stable = response.stable
    assert stable[first.index] and not stable[first.index + 1] and not stable[second.index] and stable[second.index + 1]


def test_a_motion_stuck_on_a_force_jump_is_a_convergence_error_not_a_hang():
    # ε·2·H(u) pushes back at u = 0 from both sides once u' = 0 there: a sliding motion, which the flow does not follow
    from lindstedt import ConvergenceError
    from lindstedt.numerics import SmoothForcedFlow

    flow = SmoothForcedFlow(ForcedOscillator("2*Heaviside(u)", omega0=1, zeta="1/10", forcing=1), 0.5)
    with pytest.raises(ConvergenceError, match="sticks on a breakpoint"):
        flow.period_map([0.0, 0.0], 1.0)


def test_spectrum_checks_the_point_and_the_degree_of_freedom():
    problem = ForcedOscillator("u", omega0=1, zeta="1/20", forcing=1)
    response = frequency_response(problem, 0.9, 1.1, epsilon=0.1)
    with pytest.raises(ProblemError, match="dof must be"):
        response.spectrum(0, dof=1)  # would be the velocity u' of a 1-dof orbit
    with pytest.raises(ProblemError, match="index must be"):
        response.spectrum(len(response))
