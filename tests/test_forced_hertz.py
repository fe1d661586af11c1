"""A forced two-mass chain with a Hertz contact: its folds against a hand-written DOP853 ODE (issue 25).

``M X'' + C X' + K X + ε a f(aᵀX − b) = ε P cos(Ω t)``, ``f(u) = Max(0, u)^{3/2}``: two unit masses between two
walls (``K`` = tridiag(2, −1)), mass 1 meets a Hertz contact across a gap ``b = 1/10`` (``a = e₁``), Rayleigh
damping ``C = (M + K)/100`` (ζ₁ = 0.01 at ω₁ = 1, ζ₂ = 0.0202 at ω₂ = √3), ``ε = 1``, ``P = (1/20, 0)``.  Through
the first resonance the contact stiffens the chain and the response folds twice (a hardening fold pair, at
Ω ≈ 1.0713 and 1.0611, nothing else on [0.95, 1.15]).  A stiffer contact at zero gap forced harder
(``10 Max(0, u)^{3/2}``, ``P = (1, 0)``) has a period-2 window between two period doublings (Ω ≈ 0.9180, 0.9414).

References, none of them the code under test:

* the ODE written out by hand from the matrices and integrated by scipy's DOP853.  The Hertz force is C¹ but its
  derivative ``(3/2) √u`` has an infinite slope where contact begins, so a step across the kink loses the
  method's order (measured: rtol 1e-13 without events closes an orbit to 5e-12, with events to 1e-12).  The
  integration here stops at every crossing of ``aᵀX = b`` (a terminal ``solve_ivp`` event whose direction is the
  side the motion leaves) and restarts there: each step sees one analytic piece.  Its error is measured as the
  difference of two tolerances (rtol 1e-12 against 1e-10), and every tolerance below is built from it;
* its variational equations, written out by hand (the Jacobian ``K + ε a aᵀ (3/2) √((aᵀX − b)_+)`` is continuous
  across the contact, so the monodromy needs no saltation), for the Floquet multipliers.
"""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import lindstedt

M = np.eye(2)
K = np.array([[2.0, -1.0], [-1.0, 2.0]])
C = 0.01 * (M + K)
DIRECTION = np.array([1.0, 0.0])
GAP, EPSILON = 0.1, 1.0
LOAD = np.array([0.05, 0.0])
M_INV = np.linalg.inv(M)

SYSTEM = lindstedt.UnilateralSystem(M=[[1, 0], [0, 1]], K=[[2, -1], [-1, 2]], A=[[1, 0]], b=["1/10"],
                                    laws=["Max(0, u)**(3/2)"])
FORCED = lindstedt.ForcedSystem(SYSTEM, load=["1/20", 0], rayleigh=("1/100", "1/100"))
RANGE = (0.95, 1.15)


# ------------------------------------------------------------------------------------------- the reference ODE
def _rhs(t: float, y: np.ndarray, omega: float) -> np.ndarray:
    x, v = y[:2], y[2:]
    force = max(DIRECTION @ x - GAP, 0.0) ** 1.5
    return np.r_[v, M_INV @ (EPSILON * LOAD * math.cos(omega * t) - K @ x - C @ v - EPSILON * DIRECTION * force)]


def _rhs_variational(t: float, y: np.ndarray, omega: float) -> np.ndarray:
    depth = max(DIRECTION @ y[:2] - GAP, 0.0)
    tangent = K + EPSILON * 1.5 * math.sqrt(depth) * np.outer(DIRECTION, DIRECTION)
    jacobian = np.block([[np.zeros((2, 2)), np.eye(2)], [-M_INV @ tangent, -M_INV @ C]])
    return np.r_[_rhs(t, y[:4], omega), (jacobian @ y[4:].reshape(4, 4)).ravel()]


def _crossing(direction: int):
    def event(t: float, y: np.ndarray, omega: float) -> float:
        return DIRECTION @ y[:2] - GAP

    event.terminal, event.direction = True, direction
    return event


CROSSINGS = {+1: _crossing(+1), -1: _crossing(-1)}


def _advance(y0: np.ndarray, t0: float, t1: float, omega: float, rtol: float, variational: bool = False) -> np.ndarray:
    """DOP853 from t0 to t1, stopped at every contact crossing and restarted there (no step straddles the kink).
    The event looked for is the crossing out of the side the motion is on, so a restart on the switching surface
    does not find the crossing it starts from."""
    y, t = np.asarray(y0, dtype=float), t0
    side = 1 if DIRECTION @ y[:2] > GAP else -1
    while True:
        run = solve_ivp(_rhs_variational if variational else _rhs, (t, t1), y, args=(omega,), method="DOP853",
                        rtol=rtol, atol=1e-2 * rtol, events=CROSSINGS[-side])
        assert run.success, run.message
        if run.status == 0:
            return run.y[:, -1]
        t, y, side = run.t_events[0][-1], run.y_events[0][-1], -side


def _periods(z0: np.ndarray, omega: float, periods: int, rtol: float = 1e-12) -> np.ndarray:
    """The states after 1, 2, …, ``periods`` forcing periods (shape (periods, 4)): the period map iterated."""
    period, states, z = 2.0 * math.pi / omega, [], np.asarray(z0, dtype=float)
    for k in range(periods):
        z = _advance(z, k * period, (k + 1) * period, omega, rtol)
        states.append(z)
    return np.array(states)


def _monodromy(z0: np.ndarray, omega: float, rtol: float = 1e-12) -> np.ndarray:
    end = _advance(np.r_[z0, np.eye(4).ravel()], 0.0, 2.0 * math.pi / omega, omega, rtol, variational=True)
    return end[4:].reshape(4, 4)


def _multipliers(z0: np.ndarray, omega: float, rtol: float = 1e-12) -> np.ndarray:
    """Floquet multipliers from the hand-written variational equations, by decreasing modulus."""
    mu = np.linalg.eigvals(_monodromy(z0, omega, rtol))
    return mu[np.argsort(-np.abs(mu))]


def _closure(z0: np.ndarray, omega: float) -> tuple[float, float]:
    """(|z(T) − z0|∞, the integrator's own error |z_fine(T) − z_coarse(T)|∞, rtol 1e-12 against 1e-10)."""
    fine, coarse = _periods(z0, omega, 1)[0], _periods(z0, omega, 1, rtol=1e-10)[0]
    return float(np.max(np.abs(fine - z0))), float(np.max(np.abs(fine - coarse)))


def _orbit(omega: float, guess=None) -> lindstedt.ForcedOrbit:
    orbit = lindstedt.forced_periodic_orbit(FORCED, omega, epsilon=EPSILON, initial_state=guess)
    assert orbit.success, orbit.message
    return orbit


# ------------------------------------------------------------------------------------------------ the model
def test_hertz_chain_lindstedt_s_equation_is_the_hand_written_one():
    np.testing.assert_array_equal(FORCED.C, C)
    np.testing.assert_array_equal(FORCED.P, LOAD)
    rng = np.random.default_rng(5)
    for x in rng.normal(scale=0.5, size=(8, 2)):  # on both sides of the contact
        expected = -M_INV @ (K @ x + EPSILON * DIRECTION * max(x[0] - GAP, 0.0) ** 1.5)
        np.testing.assert_allclose(SYSTEM.acceleration(x, EPSILON), expected, rtol=1e-14, atol=1e-15)


def _assert_closes(orbit) -> tuple[float, float]:
    """The orbit's state comes back after one period of the independent integration, to what its Newton was asked
    (``|Π(z0) − z0| ≤ 1e-10 |z0|``) plus the integrator's own error; the residual lindstedt reports is the one
    measured here."""
    closure, error = _closure(orbit.state, orbit.frequency)
    size = float(np.max(np.abs(orbit.state)))
    assert closure <= 1e-10 * size + error, (orbit.frequency, closure, error)
    assert abs(closure - orbit.residual * size) <= error + 1e-13, (orbit.frequency, closure, orbit.residual)
    return closure, error


def test_hertz_chain_an_orbit_in_contact_is_the_dop853_steady_state_and_its_multipliers_the_variational_ones():
    omega = 1.0  # below the folds: one response, in contact every period (X1 peaks at 0.35 > b)
    orbit = _orbit(omega)
    assert orbit.stable and orbit.maximum[0] > 2 * GAP
    closure, error = _assert_closes(orbit)  # measured: closure 1.8e-12, error 1.7e-10
    # 30 periods from the orbit: each adds at most closure + error, and the period map contracts (|μ| ≤ 0.94), so
    # the run stays within (closure + error)/(1 − 0.94) ≲ 3e-9 of the state (measured 8.5e-11): the orbit is the
    # DOP853 steady state
    states = _periods(orbit.state, omega, 30)
    assert np.max(np.abs(states - orbit.state)) <= (closure + error) / (1 - 0.94), np.max(np.abs(states - orbit.state))
    mu, coarse = _multipliers(orbit.state, omega), _multipliers(orbit.state, omega, rtol=1e-10)
    spread = float(np.max(np.abs(np.sort_complex(mu) - np.sort_complex(coarse))))  # measured 1.7e-10
    # lindstedt's multipliers are the hand-written monodromy's to within its error (measured 5.7e-13)
    np.testing.assert_allclose(np.sort_complex(orbit.multipliers), np.sort_complex(mu), rtol=0, atol=spread)
    assert abs(mu[0]) < 1


# ------------------------------------------------------------------------------------------- the branch
@pytest.fixture(scope="module")
def hertz() -> lindstedt.FrequencyResponse:
    response = lindstedt.frequency_response(FORCED, *RANGE, epsilon=EPSILON)
    assert response.success, response.message
    return response


def _folds(response: lindstedt.FrequencyResponse) -> tuple:
    folds = [b for b in response.bifurcations if b.kind == "fold"]
    assert len(folds) == 2 and len(response.bifurcations) == 2, response.bifurcations  # nothing else in the range
    return tuple(folds)


@pytest.mark.slow  # ~8 s CPU for the branch (17 s wall; shared by the tests below), ~1 s here
def test_hertz_chain_two_folds_each_with_a_multiplier_one_of_the_hand_written_monodromy(hertz):
    upper, lower = _folds(hertz)  # in branch order: the branch turns back at the upper fold, forward at the lower
    assert lower.frequency < upper.frequency
    omegas = np.asarray(hertz.frequencies)
    assert omegas[: upper.index + 1].max() <= upper.frequency <= omegas[upper.index + 1] + 1e-3
    assert omegas[upper.index + 1: lower.index + 1].min() >= lower.frequency
    for fold in (upper, lower):
        closure, error = _closure(fold.state, fold.frequency)
        assert closure <= 1e-10 * np.max(np.abs(fold.state)) + error, (fold.frequency, closure, error)
        mu = _multipliers(fold.state, fold.frequency)
        # the located point is within locate_tol (1e-9 of scaled arclength) of the fold, where μ crosses 1 linearly
        # in arclength: measured |μ − 1| = 5e-12 (upper), 2.4e-11 (lower), lindstedt's μ the same to 6e-12
        assert abs(mu[0] - 1.0) < 1e-7 and abs(mu[1]) < 0.95, (fold.frequency, mu)
        assert abs(fold.multipliers[0] - mu[0]) < 1e-8


@pytest.mark.slow  # ~3 s: every orbit closed at two tolerances and its multipliers
def test_hertz_chain_every_orbit_closes_and_its_stability_is_the_independent_one(hertz):
    upper, lower = _folds(hertz)
    for k, point in enumerate(hertz.points):
        _assert_closes(point)
        mu = _multipliers(point.state, point.frequency)
        np.testing.assert_allclose(np.sort_complex(point.multipliers), np.sort_complex(mu), atol=1e-8)
        assert point.stable is bool(abs(mu[0]) < 1.0), point.frequency
        # unstable exactly on the middle part, between the folds
        assert point.stable is not (upper.index < k <= lower.index), (k, point.frequency)


@pytest.mark.slow  # ~5 s: runs from the orbits next to each fold and from rest far from them
def test_hertz_chain_orbits_near_each_fold_are_the_steady_states_of_the_ode(hertz):
    upper, lower = _folds(hertz)
    # the last stable orbits before each fold (on the upper part, |μ| = 0.97; on the lower part, 0.94)
    for point in (hertz.points[upper.index], hertz.points[lower.index + 1]):
        assert point.stable and abs(point.frequency - 0.5 * (upper.frequency + lower.frequency)) < 0.01
        closure, error = _closure(point.state, point.frequency)
        rho = float(abs(_multipliers(point.state, point.frequency)[0]))
        states = _periods(point.state, point.frequency, 60)
        drift = float(np.max(np.abs(states - point.state)))
        assert drift <= 3 * (closure + error) / (1 - rho), (point.frequency, drift, closure, error, rho)
        assert drift < 1e-8


@pytest.mark.slow  # ~15 s CPU (30 s wall, shared machine): 3 orbits, 2 runs off the saddle, a run from rest
def test_hertz_chain_between_the_folds_two_stable_responses_and_a_saddle(hertz):
    upper, lower = _folds(hertz)
    omega = 0.5 * (upper.frequency + lower.frequency)
    guesses = [hertz.states[upper.index], hertz.states[(upper.index + lower.index + 1) // 2],
               hertz.states[lower.index + 1]]
    orbits = [_orbit(omega, guess) for guess in guesses]
    states = np.array([orbit.state for orbit in orbits])
    assert min(np.max(np.abs(states[i] - states[j])) for i, j in ((0, 1), (1, 2), (0, 2))) > 0.05  # three distinct
    multipliers = [_multipliers(state, omega) for state in states]
    assert [bool(abs(mu[0]) < 1) for mu in multipliers] == [True, False, True] == [o.stable for o in orbits]
    saddle = multipliers[1]
    assert abs(saddle[0].imag) < 1e-12 and saddle[0].real > 1.02 and abs(saddle[1]) < 1  # one real multiplier > 1
    # off the saddle along its unstable direction (of the hand-written monodromy): one side lands on the upper
    # response, the other on the lower one — the two attractors the folds bound, each reached by a transient
    values, vectors = np.linalg.eig(_monodromy(states[1], omega))
    direction = np.real(vectors[:, np.argmax(np.abs(values))])
    # (the saddle's μ = 1.04 takes ~120 periods to grow 1e-3 to 0.1; then |μ| = 0.94 contracts onto the response)
    ends = [_periods(states[1] + sign * 1e-3 * direction / np.max(np.abs(direction)), omega, 450, rtol=1e-10)[-1]
            for sign in (1, -1)]
    landed = sorted(int(np.argmin([np.max(np.abs(end - states[i])) for i in range(3)])) for end in ends)
    assert landed == [0, 2], landed
    for end in ends:
        assert min(np.max(np.abs(end - states[i])) for i in (0, 2)) < 1e-6
    # from rest the chain settles on the lower response (the upper one needs a large enough start)
    assert np.max(np.abs(_periods(np.zeros(4), omega, 300, rtol=1e-10)[-1] - states[2])) < 1e-6


@pytest.mark.slow  # ~15 s CPU (31 s wall): 4 orbits, four 300-period runs
def test_hertz_chain_each_fold_bounds_its_response_a_run_past_it_jumps(hertz):
    upper, lower = _folds(hertz)
    delta = 2e-3
    for fold, outward, other in ((upper, +1, hertz.states[lower.index + 1]), (lower, -1, hertz.states[upper.index])):
        # δ inside: the response continued from the fold's state is there, stable, beside the other one, and a
        # run from it stays on it
        inside = _orbit(fold.frequency - outward * delta, fold.state)
        beside = _orbit(inside.frequency, other)
        assert inside.stable and beside.stable and np.max(np.abs(inside.state - beside.state)) > 0.1
        # (to the rtol-1e-10 run's error over the contraction, measured ≤ 1.2e-8; a jump would move it by > 0.1)
        assert np.max(np.abs(_periods(inside.state, inside.frequency, 300, rtol=1e-10)[-1] - inside.state)) < 1e-6
        # δ outside: that part of the branch is gone; the run from the fold's state goes to the other response
        omega = fold.frequency + outward * delta
        target = _orbit(omega, other)
        assert target.stable and np.max(np.abs(target.state - fold.state)) > 0.1
        end = _periods(fold.state, omega, 300, rtol=1e-10)[-1]
        assert np.max(np.abs(end - target.state)) < 1e-6, (omega, np.max(np.abs(end - target.state)))


# ------------------------------------------------------------------------------- a period doubling, stiffer
#: A stiffer contact at zero gap, forced harder: ``f(u) = 10 Max(0, u)^{3/2}``, b = 0, P = (1, 0) (same M, K, C).
#: Below the first resonance the response doubles its period between two period-doubling points.
STIFF = lindstedt.ForcedSystem(
    lindstedt.UnilateralSystem(M=[[1, 0], [0, 1]], K=[[2, -1], [-1, 2]], A=[[1, 0]], b=[0],
                               laws=["10*Max(0, u)**(3/2)"]),
    load=[1, 0], rayleigh=("1/100", "1/100"))


def _stiff_rhs(t: float, y: np.ndarray, omega: float) -> np.ndarray:
    x, v = y[:2], y[2:]
    force = 10.0 * max(DIRECTION @ x, 0.0) ** 1.5
    return np.r_[v, M_INV @ (np.array([1.0, 0.0]) * math.cos(omega * t) - K @ x - C @ v - DIRECTION * force)]


def _stiff_rhs_variational(t: float, y: np.ndarray, omega: float) -> np.ndarray:
    tangent = K + 15.0 * math.sqrt(max(DIRECTION @ y[:2], 0.0)) * np.outer(DIRECTION, DIRECTION)
    jacobian = np.block([[np.zeros((2, 2)), np.eye(2)], [-M_INV @ tangent, -M_INV @ C]])
    return np.r_[_stiff_rhs(t, y[:4], omega), (jacobian @ y[4:].reshape(4, 4)).ravel()]


@pytest.mark.slow  # ~35 s CPU (73 s wall): the branch over [0.90, 0.96] and three 300-period runs
def test_hertz_stiff_chain_the_period_doubles_between_two_period_doubling_points(monkeypatch):
    response = lindstedt.frequency_response(STIFF, 0.90, 0.96, epsilon=EPSILON)
    assert response.success, response.message
    assert [b.kind for b in response.bifurcations] == ["period-doubling"] * 2
    first, second = response.bifurcations
    # the hand-written field of this system, the same event-split integration (the contact at b = 0)
    monkeypatch.setattr(sys.modules[__name__], "GAP", 0.0)
    monkeypatch.setattr(sys.modules[__name__], "_rhs", _stiff_rhs)
    monkeypatch.setattr(sys.modules[__name__], "_rhs_variational", _stiff_rhs_variational)
    for point in (first, second):  # a multiplier −1 of the hand-written monodromy at each located point
        mu = _multipliers(point.state, point.frequency)
        assert abs(mu[0] + 1.0) < 1e-4 and abs(mu[1]) < 0.95, (point.frequency, mu)
    # runs sampled once a forcing period, from the period-1 orbit pushed 1e-3 along the eigenvector of the
    # multiplier of largest modulus: period 2 between the points, period 1 on either side of them
    for omega, doubled in ((first.frequency - 0.008, False), (0.5 * (first.frequency + second.frequency), True),
                           (second.frequency + 0.008, False)):
        orbit = lindstedt.forced_periodic_orbit(STIFF, omega, epsilon=EPSILON, initial_state=first.state)
        assert orbit.success and orbit.stable is not doubled
        values, vectors = np.linalg.eig(_monodromy(orbit.state, omega))
        direction = np.real(vectors[:, np.argmax(np.abs(values))])
        states = _periods(orbit.state + 1e-3 * direction / np.max(np.abs(direction)), omega, 300, rtol=1e-10)
        once, twice = (float(np.max(np.abs(states[-1] - states[-1 - k]))) for k in (1, 2))
        assert twice < 1e-6, (omega, twice)
        assert (once > 0.1) is doubled, (omega, once)
