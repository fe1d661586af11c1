"""Exact flow of M X'' + K X + ε W (A X − b)_+ = 0 against independent references.

Every expected value is computed here, independently of lindstedt.numerics.ExactFlow: closed
forms derived by hand for one degree of freedom, a modal closed form of the
free (linear) flight built with numpy, and scipy's DOP853 on a right-hand side
written in this file.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
import scipy.linalg
import scipy.special
import sympy
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from lindstedt import ProblemError, UnilateralSystem
from lindstedt.numerics import ExactFlow, smooth_flow


# --------------------------------------------------------------------------- #
# independent references
# --------------------------------------------------------------------------- #
def reference_rhs(M, K, A, b, W, eps):
    """First-order right-hand side written from the equation, for solve_ivp."""
    M, K, A, b, W = (np.asarray(z, dtype=float) for z in (M, K, A, b, W))
    n = M.shape[0]

    def rhs(_t, y):
        x, v = y[:n], y[n:]
        force = K @ x + eps * W @ np.maximum(A @ x - b, 0.0)
        return np.concatenate([v, -np.linalg.solve(M, force)])

    return rhs


def energy(M, K, A, b, eps, x, v):
    """E = ½ vᵀMv + ½ xᵀKx + ½ ε Σ (A x − b)_+² for rows of x, v."""
    x, v = np.atleast_2d(x), np.atleast_2d(v)
    gaps = np.maximum(x @ np.asarray(A, float).T - np.asarray(b, float), 0.0)
    return 0.5 * np.einsum("ti,ij,tj->t", v, M, v) + 0.5 * np.einsum("ti,ij,tj->t", x, K, x) + 0.5 * eps * np.sum(gaps**2, axis=1)


def linear_flight(M, K, x0, v0):
    """Closed form of M x'' + K x = 0 from (x0, v0), built with scipy.linalg.eigh."""
    squared, phi = scipy.linalg.eigh(K, M)
    omega = np.sqrt(squared)
    q0, p0 = phi.T @ M @ x0, phi.T @ M @ v0

    def position(t):
        t = np.asarray(t, dtype=float)[..., None]
        return (q0 * np.cos(omega * t) + p0 / omega * np.sin(omega * t)) @ phi.T

    def velocity(t):
        t = np.asarray(t, dtype=float)[..., None]
        return (p0 * np.cos(omega * t) - q0 * omega * np.sin(omega * t)) @ phi.T

    return position, velocity


class OneDofPiecewise:
    """u'' + ω0² u + ε (a u − b)_+ = 0 started at rest at u = −U < s = b/a (derived by hand).

    Free arcs: u = −U cos(ω0 t) until u = s at ω0 t1 = π − arccos(s/U), speed
    v1 = ω0 √(U² − s²).  Contact arcs: u'' + Ω² u = ε b, Ω² = ω0² + ε a, about
    u_c = ε b/Ω²; with s − u_c = R cos φ, v1/Ω = R sin φ the contact lasts 2φ/Ω.
    By symmetry the period is P = 2 t1 + 2φ/Ω.
    """

    def __init__(self, omega0, a, b, eps, U):
        self.omega0, self.U, self.eps = omega0, U, eps
        self.s = b / a
        self.Omega = math.sqrt(omega0**2 + eps * a)
        self.u_c = eps * b / self.Omega**2
        self.t1 = (math.pi - math.acos(self.s / U)) / omega0
        self.v1 = omega0 * math.sqrt(U**2 - self.s**2)
        self.phi = math.atan2(self.v1 / self.Omega, self.s - self.u_c)
        self.contact = 2 * self.phi / self.Omega
        self.period = 2 * self.t1 + self.contact

    def position(self, t):
        t = np.asarray(t, dtype=float)
        local = np.mod(t, self.period)
        free_first = -self.U * np.cos(self.omega0 * local)
        tau = local - self.t1
        in_contact = self.u_c + (self.s - self.u_c) * np.cos(self.Omega * tau) + self.v1 / self.Omega * np.sin(self.Omega * tau)
        free_second = -self.U * np.cos(self.omega0 * (self.period - local))
        return np.where(local < self.t1, free_first, np.where(local < self.t1 + self.contact, in_contact, free_second))


# --------------------------------------------------------------------------- #
# one degree of freedom
# --------------------------------------------------------------------------- #
@pytest.mark.parametrize(
    ("omega0", "a", "b", "eps", "U"),
    [(1.0, 1.0, 0.0, 0.3, 1.0), (1.3, 2.0, 0.4, 1.7, 0.9), (0.7, 0.5, -0.1, 5.0, 2.0)],
)
def test_one_dof_matches_hand_derived_closed_form(omega0, a, b, eps, U):
    reference = OneDofPiecewise(omega0, a, b, eps, U)
    n_periods = 300
    t_end = n_periods * reference.period
    result = ExactFlow(UnilateralSystem.one_dof(omega0, a, b), eps).solve([-U], [0.0], t_end)
    assert result.success, result.message
    enter = np.array([e.time for e in result.events if e.direction == 1])
    leave = np.array([e.time for e in result.events if e.direction == -1])
    k = np.arange(n_periods)
    np.testing.assert_allclose(enter, reference.t1 + k * reference.period, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(leave, reference.t1 + reference.contact + k * reference.period, rtol=1e-12, atol=1e-12)
    assert result.n_switches == 2 * n_periods and all(e.spring == 0 for e in result.events)
    t = np.linspace(0, t_end, 50_001)
    position, _ = result.state(t)
    # (the reference carries the rounding of mod(t, P), about eps·t·|u'| ≈ 3e-13 here)
    np.testing.assert_allclose(position[:, 0], reference.position(t), rtol=0, atol=1e-12)


def test_one_dof_paper_frequency():
    # u'' + ω0² u + ε u_+ = 0: P(ε) = (1 + (1 + ε/ω0²)^(-1/2)) π/ω0 (seed paper, section 2)
    omega0, eps = 1.4, 0.9
    period = (1 + (1 + eps / omega0**2) ** -0.5) * math.pi / omega0
    result = ExactFlow(UnilateralSystem.one_dof(omega0), eps).solve([0.8], [0.0], 50 * period)
    position, velocity = result.state(period * np.arange(51))
    np.testing.assert_allclose(position[:, 0], 0.8, rtol=0, atol=1e-13)
    np.testing.assert_allclose(velocity[:, 0], 0.0, rtol=0, atol=1e-13)


def test_switch_exactly_at_time_zero_uses_the_direction_of_motion():
    omega0, eps, gap = 1.0, 3.0, 0.5
    flow = ExactFlow(UnilateralSystem.one_dof(omega0, 1, gap), eps)
    Omega, u_c = 2.0, eps * gap / 4.0
    # entering: in contact first, u = u_c + (gap − u_c) cos Ωt + (v/Ω) sin Ωt
    entering = flow.solve([gap], [0.3], 0.5)
    assert entering.contact_states[0] == (0,)
    t = np.linspace(0, 0.5, 11)
    np.testing.assert_allclose(
        entering.state(t)[0][:, 0], u_c + (gap - u_c) * np.cos(Omega * t) + 0.3 / Omega * np.sin(Omega * t), rtol=0, atol=1e-15
    )
    # leaving: free first
    leaving = flow.solve([gap], [-0.3], 0.5)
    assert leaving.contact_states[0] == () and leaving.n_switches == 0
    np.testing.assert_allclose(leaving.state(t)[0][:, 0], gap * np.cos(t) - 0.3 * np.sin(t), rtol=0, atol=1e-15)
    # at rest on the surface, pulled back by the linear spring: a graze, not a switch
    resting = flow.solve([gap], [0.0], 30.0)
    assert resting.n_switches == 0
    np.testing.assert_allclose(resting.state(t * 60)[0][:, 0], gap * np.cos(t * 60), rtol=0, atol=1e-14)


def test_grazing_exactly_at_the_maximum_one_dof():
    # u = g sin t touches the gap g exactly at its maxima: no switch, ever
    for gap in (1.0, 0.3, 1 / 3, 0.7):
        result = ExactFlow(UnilateralSystem.one_dof(1.0, 1, gap), 2.0).solve([0.0], [gap], 200 * np.pi)
        assert result.n_switches == 0 and result.contact_states == ((),)
        t = np.linspace(0, 200 * np.pi, 20_001)
        np.testing.assert_allclose(result.state(t)[0][:, 0], gap * np.sin(t), rtol=0, atol=1e-13)


def test_near_double_crossing_one_dof_is_found():
    # amplitude g(1 + d): the gap is positive for ~2√(2d) only
    omega0, eps, gap, d = 1.0, 2.0, 1.0, 1e-10
    U = gap * (1 + d)
    t_in = math.asin(gap / U) / omega0
    v_in = omega0 * math.sqrt(U**2 - gap**2)
    Omega = math.sqrt(omega0**2 + eps)
    u_c = eps * gap / Omega**2
    t_out = t_in + 2 * math.atan2(v_in / Omega, gap - u_c) / Omega
    assert t_out - t_in < 1e-4
    coarse = np.linspace(0, 3, 3 * 64 + 1)  # a sampler with 64 points per unit time misses it
    assert np.all(U * np.sin(coarse) - gap < 0)
    result = ExactFlow(UnilateralSystem.one_dof(omega0, 1, gap), eps).solve([0.0], [U], 3.0)
    assert [(e.direction, e.spring) for e in result.events] == [(1, 0), (-1, 0)]
    # root conditioning: |g'| ≈ √(2d) so times are good to ~eps/√(2d)
    assert result.events[0].time == pytest.approx(t_in, abs=1e-10)
    assert result.events[1].time == pytest.approx(t_out, abs=1e-10)


def test_near_double_crossing_inside_a_three_dof_free_flight():
    M, K = np.eye(3), 2 * np.eye(3) - np.eye(3, k=1) - np.eye(3, k=-1)
    eps, delta = 0.8, 1e-9
    # state at the top of a free excursion of x_0: velocity with (A v) = 0, A a < 0
    x_top = np.array([0.6, 0.1, -0.2])
    v_top = np.array([0.0, 0.4, 0.3])
    assert (-(K @ x_top))[0] < 0
    gap = x_top[0] - delta
    back = 1.7
    position, velocity = linear_flight(M, K, x_top, -v_top)  # time reversal of the free flight
    x0, v0 = position(back), -velocity(back)
    forward_x, forward_v = linear_flight(M, K, x0, v0)
    samples = np.linspace(0, back - 0.05, 2000)
    assert np.max(forward_x(samples)[:, 0] - gap) < -1e-4  # no earlier contact
    g = lambda t: forward_x(t)[0] - gap  # noqa: E731
    t_in = brentq(g, back - 0.05, back, xtol=1e-15, rtol=1e-15)
    K_c = K + eps * np.outer([1, 0, 0], [1, 0, 0])
    x_eq = np.linalg.solve(K_c, eps * gap * np.array([1.0, 0, 0]))
    contact_x, _ = linear_flight(M, K_c, forward_x(t_in) - x_eq, forward_v(t_in))
    h = lambda s: contact_x(s)[0] + x_eq[0] - gap  # noqa: E731
    duration = brentq(h, 1e-7, 2 * (back - t_in) + 1e-3, xtol=1e-15, rtol=1e-15)
    system = UnilateralSystem(M=M, K=K, A=[[1, 0, 0]], b=[gap])
    result = ExactFlow(system, eps).solve(x0, v0, back + 0.5)
    events = [(e.time, e.direction) for e in result.events if e.time < back + 0.5]
    assert [direction for _, direction in events[:2]] == [1, -1]
    assert duration < 2e-4
    assert events[0][0] == pytest.approx(t_in, abs=1e-10)
    assert events[1][0] == pytest.approx(t_in + duration, abs=1e-10)


def test_tangency_inside_a_two_mode_free_flight_is_not_a_switch():
    # x_0(t) = (cos(t−t*) − 0.2 cos(√3 (t−t*)))/√2 has a local maximum at t* (value 0.8/√2),
    # below its global maximum 1.2/√2: the envelope test cannot exclude it.
    M, K = np.eye(2), np.array([[2.0, -1.0], [-1.0, 2.0]])
    t_star = 3.0
    r2 = math.sqrt(2)
    s3 = math.sqrt(3)

    def x_mass0(t):
        return (np.cos(t - t_star) - 0.2 * np.cos(s3 * (t - t_star))) / r2

    gap = 0.8 / r2
    x0 = np.array([(math.cos(-t_star) - 0.2 * math.cos(-s3 * t_star)), (math.cos(-t_star) + 0.2 * math.cos(-s3 * t_star))]) / r2
    v0 = np.array([(-math.sin(-t_star) + 0.2 * s3 * math.sin(-s3 * t_star)), (-math.sin(-t_star) - 0.2 * s3 * math.sin(-s3 * t_star))]) / r2
    flight_x, _ = linear_flight(M, K, x0, v0)
    np.testing.assert_allclose(flight_x(np.linspace(0, 10, 7))[:, 0], x_mass0(np.linspace(0, 10, 7)), atol=1e-14)
    # first genuine crossing after the tangency, from the closed form
    t = np.linspace(t_star + 0.1, 40, 400_001)
    above = np.flatnonzero(x_mass0(t) - gap > 0)
    assert above.size, "the test needs a genuine contact after the tangency"
    first = brentq(lambda s: x_mass0(s) - gap, t[above[0] - 1], t[above[0]], xtol=1e-15, rtol=1e-15)
    assert np.max(x_mass0(np.linspace(0, t_star - 0.1, 5000)) - gap) < 0
    system = UnilateralSystem(M=M, K=K, A=[[1, 0]], b=[gap])
    result = ExactFlow(system, 1.5).solve(x0, v0, first + 0.01)
    assert result.events[0].direction == 1
    assert result.events[0].time == pytest.approx(first, abs=1e-11)
    samples = np.linspace(0, first, 3001)
    np.testing.assert_allclose(result.state(samples)[0][:, 0], x_mass0(samples), rtol=0, atol=1e-14)
    assert result.n_evaluations < 200  # the tangency does not stall the search (13 evaluations here)


# --------------------------------------------------------------------------- #
# N degrees of freedom
# --------------------------------------------------------------------------- #
def test_energy_conserved_over_a_thousand_periods():
    system = UnilateralSystem.chain(3, [(0, 0.05), (2, 0.0, -1)])
    eps = 2.0
    x0, v0 = np.array([0.3, -0.1, 0.2]), np.array([0.1, 0.25, -0.3])
    t_end = 1000 * 2 * np.pi / system.modes().frequencies[0]
    result = ExactFlow(system, eps).solve(x0, v0, t_end)
    assert result.success and result.n_switches > 2000
    M, K, A, b = np.eye(3), system.K, [[1, 0, 0], [0, 0, -1]], [0.05, 0.0]
    E0 = energy(M, K, A, b, eps, x0, v0)[0]
    times = np.concatenate([np.linspace(0, t_end, 20_001), [e.time for e in result.events]])
    X, V = result.state(times)
    drift = np.max(np.abs(energy(M, K, A, b, eps, X, V) - E0)) / E0
    assert drift <= 1e-12


@pytest.mark.parametrize(
    ("n", "springs", "eps", "x0", "v0"),
    [
        (3, [(0, 0.05), (2, -0.02, -1)], 1.5, [0.3, -0.1, 0.2], [0.1, 0.0, -0.3]),
        (5, [(0, 0.05), (4, 0.02, -1), (2, 0.0)], 0.7, [0.3, -0.1, 0.2, 0.05, -0.2], [0.1, 0.0, -0.3, 0.2, 0.0]),
    ],
)
def test_chains_agree_with_dop853(n, springs, eps, x0, v0):
    system = UnilateralSystem.chain(n, springs)
    A = np.zeros((len(springs), n))
    b = np.zeros(len(springs))
    for i, spec in enumerate(springs):
        A[i, spec[0]] = spec[2] if len(spec) == 3 else 1
        b[i] = spec[1]
    K = 2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1)
    t_end = 30.0
    rhs = reference_rhs(np.eye(n), K, A, b, A.T, eps)
    reference = solve_ivp(rhs, (0, t_end), np.concatenate([x0, v0]), method="DOP853", rtol=1e-12, atol=1e-14, dense_output=True)
    result = ExactFlow(system, eps).solve(x0, v0, t_end)
    assert result.success and result.n_switches > 5
    t = np.linspace(0, t_end, 3001)
    X, V = result.state(t)
    Y = reference.sol(t)
    np.testing.assert_allclose(X, Y[:n].T, rtol=0, atol=1e-8)
    np.testing.assert_allclose(V, Y[n:].T, rtol=0, atol=1e-8)


def test_non_symmetric_force_distribution_agrees_with_dop853():
    M = np.array([[2.0, 0.3], [0.3, 1.0]])
    K = np.array([[3.0, -1.0], [-1.0, 2.0]])
    A = np.array([[1.0, 0.5], [0.0, -1.0]])
    b = np.array([0.1, 0.05])
    W = np.array([[2.0, 0.0], [0.5, -0.7]])
    eps, t_end = 0.9, 25.0
    system = UnilateralSystem(M=M, K=K, A=A, b=b, W=W)
    assert not system.symmetric_coupling
    x0, v0 = [0.4, -0.2], [0.0, 0.5]
    reference = solve_ivp(reference_rhs(M, K, A, b, W, eps), (0, t_end), np.concatenate([x0, v0]), method="DOP853", rtol=1e-12, atol=1e-14, dense_output=True)
    result = ExactFlow(system, eps).solve(x0, v0, t_end)
    assert result.success and result.n_states_visited >= 3
    t = np.linspace(0, t_end, 1001)
    np.testing.assert_allclose(np.hstack(result.state(t)), reference.sol(t).T, rtol=0, atol=1e-8)


def test_state_without_real_vibration_is_reported():
    # ε W_S A_S = ε [[0, 1], [−1, 0]]: M⁻¹ K_S has eigenvalues 1 ± iε
    system = UnilateralSystem(M=np.eye(2), K=np.eye(2), A=np.eye(2), b=[0, 0], W=[[0, 1], [-1, 0]])
    with pytest.raises(ProblemError, match="complex eigenvalues"):
        ExactFlow(system, 0.5).solve([1.0, 1.0], [0.0, 0.0], 1.0)


def test_simultaneous_switches_of_symmetric_springs():
    # in-phase motion of a symmetric 2-mass chain: both springs switch at the same instants
    system = UnilateralSystem.chain(2, [(0, 0.1), (1, 0.1)])
    x0, v0, eps, t_end = np.array([0.5, 0.5]), np.zeros(2), 1.0, 40.0
    result = ExactFlow(system, eps).solve(x0, v0, t_end)
    times = np.array([e.time for e in result.events])
    assert result.n_switches == 2 * result.n_arcs - 2 and np.all(times[0::2] == times[1::2])
    reference = solve_ivp(
        reference_rhs(np.eye(2), system.K, np.eye(2), [0.1, 0.1], np.eye(2), eps),
        (0, t_end), np.concatenate([x0, v0]), method="DOP853", rtol=1e-12, atol=1e-14, dense_output=True,
    )
    t = np.linspace(0, t_end, 801)
    np.testing.assert_allclose(result.state(t)[0], reference.sol(t)[:2].T, rtol=0, atol=1e-8)
    # in phase each mass obeys u'' + u + ε (u − 0.1)_+ = 0 (the middle spring stays unstretched):
    # contact arcs u = u_c + (0.5 − u_c) cos Ωt about u_c = 0.1 ε/Ω², Ω² = 1 + ε, from rest at 0.5
    Omega = math.sqrt(1 + eps)
    u_c = 0.1 * eps / Omega**2
    duration = 2 * math.acos((0.1 - u_c) / (0.5 - u_c)) / Omega
    switches = times[0::2]  # leave, enter, leave, ...
    np.testing.assert_allclose(switches[0], duration / 2, rtol=1e-13)
    np.testing.assert_allclose(switches[2::2] - switches[1:-1:2], duration, rtol=1e-12)


def free_flight_reference(M, K, x0, v0, t, precision=40):
    """X(t) of M X'' + K X = 0 in mpmath: y = Lᵀ X (M = L Lᵀ) obeys y'' + L⁻¹ K L⁻ᵀ y = 0, solved by eigsy."""
    n = len(x0)
    with mpmath.workdps(precision):
        lower = mpmath.cholesky(mpmath.matrix(np.asarray(M).tolist()))
        inverse = mpmath.inverse(lower)
        symmetric = inverse * mpmath.matrix(np.asarray(K).tolist()) * inverse.T
        values, vectors = mpmath.eigsy((symmetric + symmetric.T) / 2)
        q0 = vectors.T * (lower.T * mpmath.matrix(list(x0)))
        p0 = vectors.T * (lower.T * mpmath.matrix(list(v0)))
        q = mpmath.matrix(n, 1)
        for k in range(n):
            omega = mpmath.sqrt(values[k])
            q[k] = q0[k] * mpmath.cos(omega * t) + p0[k] / omega * mpmath.sin(omega * t)
        x = inverse.T * (vectors * q)
        return np.array([float(x[i]) for i in range(n)])


@pytest.mark.skipif(np.finfo(np.longdouble).eps >= np.finfo(float).eps, reason="no extended precision here")
def test_clustered_modes_reach_extended_precision():
    # a double and a near-double eigenvalue: with double-precision eigenvectors alone the free flight is off by
    # ~1e-14 at t = 1000; the extended-precision modal refinement keeps it within rounding of the exact solution
    rng = np.random.default_rng(7)
    B = rng.normal(size=(5, 5))
    M = B @ B.T + 5 * np.eye(5)
    Q, _ = np.linalg.qr(rng.normal(size=(5, 5)))
    K = Q @ np.diag([1.0, 1.0, 2.0, 3.0, 3.0 + 1e-12]) @ Q.T
    K = (K + K.T) / 2
    system = UnilateralSystem(M=M, K=K, A=[[1, 0, 0, 0, 0]], b=[1e6])  # W = Aᵀ; the spring is never reached
    for seed in range(3):
        state = np.random.default_rng(seed).normal(size=10)
        result = ExactFlow(system, 0.5).solve(state[:5], state[5:], 1000.0)
        assert result.success and result.n_switches == 0 and result.n_arcs > 10
        times = np.linspace(0.0, 1000.0, 5)
        for t, position in zip(times, result.state(times)[0]):
            exact = free_flight_reference(M, K, state[:5], state[5:], t)
            assert np.max(np.abs(position - exact)) < 4 * np.finfo(float).eps * np.max(np.abs(exact))


def test_unstable_contact_state_is_reported():
    system = UnilateralSystem(M=[[1]], K=[[1]], A=[[1]], b=[0])
    with pytest.raises(ProblemError, match="non-positive squared frequency"):
        ExactFlow(system, -2.0).solve([1.0], [0.0], 1.0)


def test_long_free_flight_without_contact():
    # the gap is never reached: one state, arcs restarted only to keep ω t small
    system = UnilateralSystem.chain(2, [(0, 10.0)])
    x0, v0 = np.array([0.5, -0.25]), np.array([0.0, 0.3])
    t_end = 1000 * 2 * np.pi
    result = ExactFlow(system, 1.0).solve(x0, v0, t_end)
    assert result.n_switches == 0 and result.n_root_solves == 0
    position, _ = linear_flight(np.eye(2), system.K, x0, v0)
    t = np.linspace(0, t_end, 10_001)
    np.testing.assert_allclose(result.state(t)[0], position(t), rtol=0, atol=1e-11)


def test_system_without_unilateral_springs_is_linear():
    system = UnilateralSystem(M=[[2, 0.5], [0.5, 1]], K=[[3, -1], [-1, 2]])
    x0, v0 = np.array([0.2, -0.7]), np.array([1.0, 0.1])
    result = ExactFlow(system, 5.0).solve(x0, v0, 200.0)
    assert result.success and result.n_switches == 0 and result.contact_states == ((),)
    position, velocity = linear_flight(system.M, system.K, x0, v0)
    t = np.linspace(0, 200.0, 2001)
    np.testing.assert_allclose(result.state(t)[0], position(t), rtol=0, atol=1e-13)
    np.testing.assert_allclose(result.state(t)[1], velocity(t), rtol=0, atol=1e-13)


def test_sensitivity_matches_central_finite_differences():
    system = UnilateralSystem.chain(3, [(0, 0.05), (2, 0.0, -1)])
    flow = ExactFlow(system, 2.0)
    x0, v0 = np.array([0.3, -0.1, 0.2]), np.array([0.1, 0.25, -0.3])
    t = 12.0
    out = flow.flow_map(x0, v0, t, sensitivity=True)
    assert out.success and out.n_switches >= 4
    reference = flow.solve(x0, v0, t)
    np.testing.assert_allclose(out.position, reference.position, rtol=0, atol=0)
    y0 = np.concatenate([x0, v0])
    step = 1e-6
    columns = []
    for j in range(6):
        shift = np.zeros(6)
        shift[j] = step
        plus = flow.flow_map((y0 + shift)[:3], (y0 + shift)[3:], t)
        minus = flow.flow_map((y0 - shift)[:3], (y0 - shift)[3:], t)
        columns.append((np.concatenate([plus.position, plus.velocity]) - np.concatenate([minus.position, minus.velocity])) / (2 * step))
    np.testing.assert_allclose(out.sensitivity, np.array(columns).T, rtol=0, atol=1e-9)  # FD error ≈ 5e-11
    # Liouville: the flow of a Hamiltonian system preserves volume
    assert np.linalg.det(out.sensitivity) == pytest.approx(1.0, abs=1e-10)


def test_result_counters_and_events_are_consistent():
    system = UnilateralSystem.chain(2, [(0, 0.1), (1, 0.1, -1)])
    result = ExactFlow(system, 1.0).solve([0.5, 0.0], [0.0, 0.0], 40.0)
    assert result.success and "reached" in result.message
    assert result.n_switches == len(result.events) > 0
    assert result.n_arcs == result.n_switches + 1
    assert result.n_root_solves >= 1 and result.n_evaluations > 0
    assert result.n_decompositions == result.n_states_visited == len(set(result.contact_states))
    times = [e.time for e in result.events]
    assert times == sorted(times)
    X, _ = result.state(times)
    for event, x in zip(result.events, X):  # every event sits on its switching surface
        a_row = system.A[event.spring]
        assert abs(a_row @ x - system.b[event.spring]) < 1e-14
    assert result.state(3.0)[0].shape == (2,) and result.state(np.zeros((4, 5)))[0].shape == (4, 5, 2)


@pytest.mark.parametrize(
    ("call", "fragment"),
    [
        (lambda f: f.solve([1.0], [0.0], 1.0), "must have 2 entries"),
        (lambda f: f.solve([1.0, float("nan")], [0.0, 0.0], 1.0), "finite"),
        (lambda f: f.solve([1.0, 0.0], [0.0, 0.0], -1.0), "reversibility"),
        (lambda f: f.solve([1.0, 0.0], [0.0, 0.0], 1.0).state(2.0), "defined on"),
    ],
)
def test_bad_flow_input(call, fragment):
    flow = ExactFlow(UnilateralSystem.chain(2, [(0, 0.1)]), 1.0)
    with pytest.raises(ProblemError, match=fragment):
        call(flow)


def test_bad_flow_construction():
    with pytest.raises(ProblemError, match="needs a UnilateralSystem"):
        ExactFlow({"M": [[1]]}, 1.0)
    with pytest.raises(ProblemError, match="finite"):
        ExactFlow(UnilateralSystem.one_dof(1), float("nan"))


# --------------------------------------------------------------------------- #
# property tests
# --------------------------------------------------------------------------- #
_PROPERTY_SYSTEM = UnilateralSystem.chain(3, [(0, 0.05), (1, 0.1, -1), (2, 0.0)])
_PROPERTY_FLOW = ExactFlow(_PROPERTY_SYSTEM, 1.3)
states = st.lists(st.floats(-0.5, 0.5, allow_subnormal=False), min_size=6, max_size=6).map(np.array)


@settings(max_examples=30, deadline=None)
@given(states)
def test_time_reversal_returns_to_the_start(y0):
    x0, v0 = y0[:3], y0[3:]
    forward = _PROPERTY_FLOW.flow_map(x0, v0, 15.0)
    backward = _PROPERTY_FLOW.flow_map(forward.position, -forward.velocity, 15.0)
    np.testing.assert_allclose(backward.position, x0, rtol=0, atol=1e-10)
    np.testing.assert_allclose(-backward.velocity, v0, rtol=0, atol=1e-10)


@settings(max_examples=30, deadline=None)
@given(states)
def test_energy_conserved_for_random_initial_states(y0):
    x0, v0 = y0[:3], y0[3:]
    result = _PROPERTY_FLOW.solve(x0, v0, 60.0)
    A, b = _PROPERTY_SYSTEM.A, _PROPERTY_SYSTEM.b
    E0 = energy(np.eye(3), _PROPERTY_SYSTEM.K, A, b, 1.3, x0, v0)[0]
    X, V = result.state(np.linspace(0, 60.0, 601))
    E = energy(np.eye(3), _PROPERTY_SYSTEM.K, A, b, 1.3, X, V)
    assert np.max(np.abs(E - E0)) <= 1e-13 * max(E0, 1e-3)


# --------------------------------------------------------------------------- #
# smooth fallback
# --------------------------------------------------------------------------- #
def test_smooth_flow_duffing_matches_jacobi_elliptic_solution():
    # u'' + u + ε u³ = 0, u(0) = A, u'(0) = 0:  u = A cn(ω t, m), ω² = 1 + εA², m = εA²/(2ω²)
    eps, amplitude = 0.8, 1.2
    omega = math.sqrt(1 + eps * amplitude**2)
    m = eps * amplitude**2 / (2 * omega**2)
    result = smooth_flow(lambda u: u**3, 1.0, eps, amplitude, 0.0, 40.0)
    assert result.success and result.method == "DOP853" and result.n_evaluations > 0
    t = np.linspace(0, 40.0, 801)
    _, cn, _, _ = scipy.special.ellipj(omega * t, m)
    np.testing.assert_allclose(result.state(t)[0][:, 0], amplitude * cn, rtol=0, atol=1e-10)
    upward = [e.time for e in result.events if e.spring == 0 and e.direction == 1]
    period = 4 * scipy.special.ellipk(m) / omega
    np.testing.assert_allclose(np.diff(upward), period, rtol=1e-10)


def test_smooth_flow_accepts_strings_and_agrees_with_exact_flow_for_the_kink():
    omega0, eps = 1.0, 0.5
    exact = ExactFlow(UnilateralSystem.one_dof(omega0), eps).solve([1.0], [0.0], 30.0)
    fallback = smooth_flow("Max(u, 0)", omega0, eps, 1.0, 0.0, 30.0)
    t = np.linspace(0, 30, 301)
    np.testing.assert_allclose(fallback.state(t)[0], exact.state(t)[0], rtol=0, atol=1e-8)
    with pytest.raises(ProblemError, match="omega0 must be positive"):
        smooth_flow(lambda u: u, 0.0, 1.0, 1.0, 0.0, 1.0)
    with pytest.raises(ProblemError, match="substitute every parameter"):
        smooth_flow(sympy.sympify("c*u**3"), 1.0, 1.0, 1.0, 0.0, 1.0)


def test_shallow_contact_excursion_is_one_engagement_and_one_release():
    # (regression: after engaging on an excursion 1e-12 to 1e-7 deep the flow switched in and out at the entry
    # instant until max_arcs — the first certified step of the contact arc crossed the whole excursion, and the
    # root solve on [0, step] returned the entry, τ = 0, again)
    # u'' + u + (u − b)_+ = 0 from rest at u = −1 with b = 1 − 1e-7: free u = −cos t reaches b at t_in = π − arccos b
    # with u' = sin t_in; in contact u − b/2 = A_c cos(√2 (t − t_peak)) about the equilibrium b/2, symmetric
    b = 1 - 1e-7
    t_in = math.pi - math.acos(b)
    speed = math.sin(t_in)
    amplitude = math.hypot(b / 2, speed / math.sqrt(2))
    t_out = t_in + 2 * math.acos((b / 2) / amplitude) / math.sqrt(2)
    result = ExactFlow(UnilateralSystem.one_dof(1, b=b), 1.0, max_arcs=1000).solve([-1.0], [0.0], 5.0)
    assert result.success, result.message
    assert [e.direction for e in result.events] == [1, -1]
    assert result.events[0].time == pytest.approx(t_in, abs=1e-11)
    assert result.events[1].time == pytest.approx(t_out, abs=1e-9)


@settings(max_examples=40, deadline=None)
@given(st.floats(-14, -5), st.floats(1e-3, 1), st.floats(0.5, 2))
def test_shallow_contact_excursions_switch_once_in_and_once_out_per_period(log_depth, eps, omega0):
    # u'' + ω0² u + ε (u − b)_+ = 0 from rest at u = −1, gap b = 1 − 10^log_depth: every period the free motion
    # reaches b by 10^log_depth (the spring's force ε (u − b)_+ is then tiny, so the excursion stays that deep)
    system = UnilateralSystem.one_dof(omega0, 1, 1 - 10**log_depth)
    w2, b = float(system.K[0, 0]), float(system.b[0])
    reference = OneDofPiecewise(math.sqrt(w2), 1.0, b, eps, 1.0)  # period P = 2 t1 + contact (hand-derived)
    n_periods = 6
    result = ExactFlow(system, eps, max_arcs=200).solve([-1.0], [0.0], n_periods * reference.period + reference.t1 / 2)
    assert result.success, result.message
    directions = [e.direction for e in result.events]
    assert directions == [1, -1] * (len(directions) // 2)  # enter, leave, enter, ...
    # contact k lasts [t1, t1 + contact] + k P (none in the last half free arc)
    per_period = np.bincount([int(e.time // reference.period) for e in result.events], minlength=n_periods + 1)
    depth = 1 - b
    band = 64 * np.finfo(float).eps * 2  # the search's rounding band: excursions shallower are grazes (no switch)
    if depth > 16 * band:
        assert per_period.tolist() == [2] * n_periods + [0]
    else:  # a graze either way, but the same every period
        assert per_period.tolist() in ([2] * n_periods + [0], [0] * (n_periods + 1))
    # E = ½ v² + ½ ω0² u² + ½ ε (u − b)_+², at the switches and in between
    times = np.concatenate([np.linspace(0, result.t_final, 2001), [e.time for e in result.events]])
    X, V = result.state(times)
    u, v = X[:, 0], V[:, 0]
    E0 = 0.5 * w2
    E = 0.5 * v**2 + 0.5 * w2 * u**2 + 0.5 * eps * np.maximum(u - b, 0.0) ** 2
    assert np.max(np.abs(E - E0)) <= 3e-15 * E0


@pytest.mark.parametrize(("n", "eps", "depth"), [(2, 0.1, 1e-10), (3, 0.7, 1e-12)])
def test_shallow_contacts_of_a_chain_agree_with_dop853(n, eps, depth):
    # the chain released from rest in its first linear mode, −0.5 φ1 / φ1[0]; the stop on mass 0 at
    # 0.5 (1 − depth) is reached by `depth` once per period (the contacts excite the other modes at
    # O(ε depth^(3/2)) only), for 30 periods
    K = 2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1)
    squared, phi = np.linalg.eigh(K)
    x0, v0 = -0.5 * phi[:, 0] / phi[0, 0], np.zeros(n)
    system = UnilateralSystem.chain(n, [(0, 0.5 * (1 - depth))])
    A, b = system.A, system.b
    n_periods = 30
    period = 2 * np.pi / math.sqrt(squared[0])
    t_end = n_periods * period
    result = ExactFlow(system, eps, max_arcs=1000).solve(x0, v0, t_end)
    assert result.success, result.message
    assert [e.direction for e in result.events] == [1, -1] * n_periods
    assert np.bincount([int(e.time // period) for e in result.events]).tolist() == [2] * n_periods
    t = np.linspace(0, t_end, 3001)
    rhs = reference_rhs(np.eye(n), K, A, b, A.T, eps)
    y0 = np.concatenate([x0, v0])
    runs = {
        rtol: solve_ivp(rhs, (0, t_end), y0, method="DOP853", rtol=rtol, atol=rtol / 100, dense_output=True).sol(t).T
        for rtol in (1e-11, 1e-12)
    }
    # DOP853's error shrinks ~10× per decade of rtol here (the kink of the force is ε·depth small), so
    # |y(1e-11) − y(1e-12)| ≈ the error of the 1e-11 run ≈ 10× that of the 1e-12 run
    estimate = np.max(np.abs(runs[1e-11] - runs[1e-12]))
    assert estimate < 1e-9
    assert np.max(np.abs(np.hstack(result.state(t)) - runs[1e-12])) <= 0.5 * estimate
    E = energy(np.eye(n), K, A, b, eps, *result.state(np.concatenate([t, [e.time for e in result.events]])))
    assert np.max(np.abs(E - E[0])) <= 4e-15 * E[0]


# --------------------------------------------------------------------------- #
# the certified switch search against brute force
# --------------------------------------------------------------------------- #
# Free flight of M = I, K = diag(ω_k²) from X(0) = −a, X'(0) = −b ω (k modes) with one spring A = [1 … 1],
# gap b = offset: the spring's watch function b − A X(t) is h(t) = offset + Σ a_k cos ω_k t + b_k sin ω_k t,
# and the first switch of ExactFlow is the first zero of h that starts an excursion below the rounding band.
@settings(max_examples=60, deadline=None)
@given(
    st.integers(min_value=1, max_value=4).flatmap(
        lambda k: st.tuples(
            st.lists(st.floats(-1, 1), min_size=k, max_size=k),
            st.lists(st.floats(-1, 1), min_size=k, max_size=k),
            st.lists(st.floats(0.3, 3.0), min_size=k, max_size=k),
        )
    ),
    st.floats(0, 1, exclude_max=True),
    st.sampled_from([-1e-3, -1e-6, -1e-9, 1e-9, 1e-6]),
)
def test_switch_search_never_misses_an_excursion(coefficients, which, depth):
    from scipy.optimize import minimize_scalar

    a, b, omega = (np.array(c) for c in coefficients)
    scale = float(np.hypot(a, b).sum())
    assume(scale > 0.05)
    T = 20.0

    def S(t):
        t = np.asarray(t, dtype=float)[..., None]
        return (a * np.cos(omega * t) + b * np.sin(omega * t)).sum(axis=-1)

    grid = np.linspace(0, T, 200_001)
    values = S(grid)
    interior = np.flatnonzero((values[1:-1] < values[:-2]) & (values[1:-1] <= values[2:])) + 1
    assume(interior.size > 0)
    minima = []
    for k in interior:
        found = minimize_scalar(lambda t: float(S(t)), bounds=(grid[k - 1], grid[k + 1]), method="bounded", options={"xatol": 1e-12})
        minima.append((found.x, float(S(found.x))))
    chosen = minima[int(which * len(minima))]
    offset = -chosen[1] + depth * scale  # the chosen minimum of h = offset + S sits at depth·scale
    h = lambda t: offset + S(t)  # noqa: E731
    assume(h(0.0) > 1e-3 * scale)  # the search starts on its own side
    band = 64 * np.finfo(float).eps * scale  # the flow's band is 64 eps (|offset| + scale), never narrower
    levels = [(t, offset + value) for t, value in minima] + [(T, float(h(T)))]
    # skip an excursion in the grey zone between rounding and a clear crossing
    assume(not any(-1e-11 * scale < level < -0.5 * band for _, level in levels))
    deep = [t for t, level in levels if level <= -1e-11 * scale]
    n = len(omega)
    system = UnilateralSystem(M=np.eye(n), K=np.diag(omega**2), A=[np.ones(n)], b=[offset])
    # only the first switch is checked (what follows a shallow contact is test_shallow_contact_excursion_...)
    result = ExactFlow(system, 1.0, max_arcs=200).solve(-a, -b * omega, T)
    if not deep:
        assert result.success and result.n_switches == 0
        return
    first_deep = min(deep)
    before = np.flatnonzero((grid < first_deep) & (h(grid) >= 0))
    expected = brentq(lambda t: float(h(t)), grid[before[-1]], first_deep, xtol=1e-15, rtol=1e-15)
    assert result.n_switches >= 1
    first = result.events[0]
    assert first.spring == 0 and first.direction == 1
    assert first.time == pytest.approx(expected, abs=1e-8)
    assert abs(float(h(first.time))) <= 1e-13 * scale
