"""NNM continuation that does not stall: internal-resonance jumps, grazing springs, hard single points.

Expected values come from references independent of the continuation and shooting code:

* the return residual of a direct :class:`lindstedt.numerics.ExactFlow` over one period from each
  accepted release state (the closed-form flow, called here without the shooting code);
* the same return computed by ``scipy.integrate.solve_ivp(DOP853)`` with a restart at every switch
  (a different integrator), and in the slow test the periodic orbit itself re-solved by shooting on
  DOP853 flows (``scipy.optimize.root``), its frequency compared within DOP853's own error estimate
  (the change between rtol = 1e-10 and rtol = 1e-12);
* closed forms: the exact period of ``u'' + u + ε (u − b)_+ = 0``
  (:func:`lindstedt.references.piecewise_linear_exact_frequency`, a quadrature-free formula) and, for a
  chain whose prestressed spring stays engaged, the linear mode of that contact state (linear
  algebra), which gives the modal amplitude at which a spring starts to graze the orbit.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from lindstedt import UnilateralSystem
from lindstedt.numerics import ExactFlow, continue_nnm, nnm_point
from lindstedt.references import piecewise_linear_exact_frequency


# --------------------------------------------------------------------------- #
# independent references
# --------------------------------------------------------------------------- #
def exact_flow_return(system: UnilateralSystem, point) -> float:
    """Relative return error of a direct ExactFlow over one period from the release state."""
    end = ExactFlow(system, point.epsilon).flow_map(point.release_position, point.release_velocity, point.period)
    scale = float(np.max(np.abs(point.release_position)))
    return max(float(np.max(np.abs(end.position - point.release_position))) / scale,
               float(np.max(np.abs(end.velocity - point.release_velocity))) / (point.frequency * scale))


def dop853_flow(system: UnilateralSystem, epsilon: float, x0, v0, t_end: float, rtol: float):
    """DOP853 on M X'' + K X + ε W (A X − b)_+ = 0, terminal events on the gaps, restart at each switch."""
    from scipy.integrate import solve_ivp

    n = system.n_dof
    A, b = np.asarray(system.A, dtype=float), np.asarray(system.b, dtype=float)
    stiffness = np.linalg.solve(system.M, system.K)
    load = np.linalg.solve(system.M, system.W)
    scale = max(float(np.max(np.abs(x0))), 1e-300)

    def rhs(_t, y):
        return np.concatenate([y[n:], -(stiffness @ y[:n]) - epsilon * (load @ np.maximum(A @ y[:n] - b, 0.0))])

    def event(i: int, direction: int):
        def gap(_t, y):
            return A[i] @ y[:n] - b[i]

        gap.terminal, gap.direction = True, direction
        return gap

    y, t, directions = np.concatenate([x0, v0]).astype(float), 0.0, [0] * len(b)
    while t < t_end:
        solution = solve_ivp(rhs, (t, t_end), y, method="DOP853", rtol=rtol, atol=rtol * scale,
                             events=[event(i, directions[i]) for i in range(len(b))])
        if solution.status == 1:
            t, spring = min((times[0], i) for i, times in enumerate(solution.t_events) if len(times))
            y = solution.y_events[spring][0]
            directions = [0] * len(b)
            directions[spring] = -1 if A[spring] @ y[n:] > 0 else 1  # the next crossing of it goes back
        else:
            assert solution.status == 0, solution.message
            y, t = solution.y[:, -1], solution.t[-1]
    return y[:n], y[n:]


def dop853_return(system: UnilateralSystem, point, rtol: float = 1e-12) -> float:
    x, v = dop853_flow(system, point.epsilon, point.release_position, point.release_velocity, point.period, rtol)
    scale = float(np.max(np.abs(point.release_position)))
    return max(float(np.max(np.abs(x - point.release_position))) / scale,
               float(np.max(np.abs(v - point.release_velocity))) / (point.frequency * scale))


def three_spring_chain(n: int) -> UnilateralSystem:
    """The chain of benchmarks/bench_nnm_scaling.py: springs on the first, middle and last mass."""
    return UnilateralSystem.chain(n, unilateral=[(0, 0.1), (n // 2, -0.05), (n - 1, 0.0)])


# --------------------------------------------------------------------------- #
# internal resonances: crossed, not climbed
# --------------------------------------------------------------------------- #
@pytest.fixture(scope="module")
def chain8_branch():
    # before the resonance jumps this branch climbed a resonance tongue (mode-1 share → 0, ε stalled near 0.30)
    system = three_spring_chain(8)
    return system, continue_nnm(system, 1, modal_amplitude=1.0, start=0.0, stop=0.5, max_points=80)


def test_resonance_tongues_are_crossed_and_every_point_is_a_periodic_orbit(chain8_branch):
    system, branch = chain8_branch
    assert branch.success, branch.stop_reason
    eps = branch.epsilons
    assert eps[0] == 0.0 and eps[-1] == 0.5 and np.all(np.diff(eps) > 0)
    assert branch.jumps and "parameter jumps" in branch.stop_reason
    for point in branch.points:
        assert point.success and point.modal_amplitude == pytest.approx(1.0, rel=1e-12)
        assert exact_flow_return(system, point) < 1e-9
    # the points after a jump are orbits of mode 1 (not of the resonant mode) and periodic for DOP853 too
    for k in branch.jumps:
        landed = branch.points[k + 1]
        assert landed.mode_share >= 0.5
        assert dop853_return(system, landed) < 1e-8


def test_nnm_point_routes_agree_with_the_branch(chain8_branch):
    system, branch = chain8_branch
    end = branch.points[-1]
    for route in ("linear", "expansion", None):
        alone = nnm_point(system, 0.5, 1, modal_amplitude=1.0, initial_guess=route)
        assert alone.success, (route, alone.message)
        assert alone.frequency == pytest.approx(end.frequency, rel=1e-10)
        np.testing.assert_allclose(alone.release_position, end.release_position, rtol=0, atol=1e-8)


# --------------------------------------------------------------------------- #
# grazing: a spring starting to touch the orbit
# --------------------------------------------------------------------------- #
def test_grazing_in_modal_amplitude_matches_the_closed_form_period():
    # u'' + u + ε (u − b)_+ = 0: no contact for a0 ≤ b, contact beyond (the graze at a0 = b)
    system, epsilon, gap = UnilateralSystem.one_dof(1, b=0.5), 1.0, 0.5
    branch = continue_nnm(system, 1, parameter="modal_amplitude", epsilon=epsilon, start=0.2, stop=1.0)
    assert branch.success, branch.stop_reason
    values = branch.parameter_values
    assert len(branch.contact_changes) == 1
    k = branch.contact_changes[0]
    assert values[k] <= gap < values[k + 1]
    for a0, point in zip(values, branch.points):
        exact = float(piecewise_linear_exact_frequency(epsilon, a=1, b=gap, a0=a0))
        assert point.frequency == pytest.approx(exact, rel=1e-12)


def test_grazing_of_a_chain_spring_is_located_between_two_points():
    # spring 1 (mass 3, gap −0.1) is engaged at rest; until the orbit reaches x_3 = −0.1 it never switches and
    # the NNM is the linear mode ψ of K + ε e_3 e_3ᵀ about that state's equilibrium X*: X0 = X* + c ψ with
    # u_1(0) = (M φ_1)ᵀ X0 = a0, so the graze is at |c ψ_3| = X*_3 + 0.1 — linear algebra only.
    system, epsilon = UnilateralSystem.chain(3, unilateral=[(0, 0.2), (2, -0.1)]), 0.5
    stiffness = system.K + epsilon * np.outer(system.A[1], system.A[1])
    equilibrium = np.linalg.solve(stiffness, epsilon * system.A[1] * system.b[1])
    import scipy.linalg

    squared, shapes = scipy.linalg.eigh(stiffness, system.M)
    psi = shapes[:, 0]
    row = system.M @ system.modes().shapes[:, 0]
    graze = float(row @ equilibrium) + (equilibrium[2] - system.b[1]) / abs(psi[2]) * abs(float(row @ psi))
    branch = continue_nnm(system, 1, parameter="modal_amplitude", epsilon=epsilon, start=0.1, stop=1.0)
    assert branch.success, branch.stop_reason
    values = branch.parameter_values
    springs = [point.contact_springs for point in branch.points]
    assert springs[0] == () and springs[-1] == (0, 1)
    assert len(branch.contact_changes) == 2
    first = branch.contact_changes[0]
    assert springs[first] == () and springs[first + 1] == (1,)
    assert values[first] <= graze < values[first + 1]
    for a0, point in zip(values[: first + 1], branch.points[: first + 1]):  # before the graze: the linear mode ψ
        assert point.frequency == pytest.approx(math.sqrt(squared[0]), rel=1e-12)
        assert exact_flow_return(system, point) < 1e-10


# --------------------------------------------------------------------------- #
# stopping with a reason
# --------------------------------------------------------------------------- #
def test_a_branch_that_cannot_continue_says_why_and_where():
    # every corrector is cut at one iteration: the step collapses, the one rescue jump fails too
    system = UnilateralSystem.chain(3, unilateral=[(0, 0.0)])
    branch = continue_nnm(system, 1, modal_amplitude=1.0, start=0.0, stop=20.0, step=5.0, min_step=5.0,
                          max_iterations=1)
    assert not branch.success
    assert "below min_step" in branch.stop_reason and "epsilon" in branch.stop_reason
    assert "no parameter jump" in branch.stop_reason
    assert all(point.success for point in branch.points)


# --------------------------------------------------------------------------- #
# the 20-dof chain (issue 13): ε = 0.3 in at most 60 points
# --------------------------------------------------------------------------- #
def dop853_shooting_frequency(system: UnilateralSystem, point, rtol: float) -> float:
    """ω of the periodic orbit re-solved on DOP853 flows: X'(T/2) = 0, u_j(0) = a0, from a perturbed start."""
    import scipy.optimize

    n = system.n_dof
    row = system.M @ system.modes().shapes[:, point.mode - 1]
    a0 = float(row @ point.release_position)
    x_scale = float(np.max(np.abs(point.release_position)))
    columns = np.r_[np.full(n, x_scale), point.period]

    def residual(y):
        x0, half = y[:n] * columns[:n], y[n] * columns[n]
        _, v = dop853_flow(system, point.epsilon, x0, np.zeros(n), half, rtol)
        return np.r_[v / (x_scale * point.frequency), (row @ x0 - a0) / abs(a0)]

    start = np.r_[point.release_position, 0.5 * point.period] / columns
    start = start * (1.0 + 1e-6 * np.cos(np.arange(n + 1)))
    solution = scipy.optimize.root(residual, start, method="hybr", options={"xtol": 1e-13})
    assert float(np.max(np.abs(residual(solution.x)))) < 100 * rtol, solution.message
    return math.pi / (solution.x[n] * columns[n])


@pytest.mark.slow
def test_twenty_dof_chain_reaches_epsilon_three_tenths():
    system = three_spring_chain(20)
    branch = continue_nnm(system, 1, modal_amplitude=1.0, start=0.0, stop=0.3)
    assert branch.success, branch.stop_reason
    assert branch.epsilons[-1] == 0.3 and len(branch) <= 60
    for point in branch.points:
        assert point.success and point.floquet_multipliers is not None
        assert exact_flow_return(system, point) < 1e-9
        assert point.mode_share >= 0.5
    # a second reference: the orbit at ε = 0.3 re-solved by shooting on DOP853 flows
    end = branch.points[-1]
    coarse, fine = (dop853_shooting_frequency(system, end, rtol) for rtol in (1e-10, 1e-12))
    assert abs(fine - end.frequency) <= max(10 * abs(fine - coarse), 1e-12 * fine)
    # single points from the expansion predictor (and, beyond its validity, by continuation in ε)
    for epsilon in (0.1, 0.2, 0.3):
        alone = nnm_point(system, epsilon, 1, modal_amplitude=1.0)
        assert alone.success, alone.message
        assert exact_flow_return(system, alone) < 1e-9
        assert dop853_return(system, alone) < 1e-8
    assert alone.frequency == pytest.approx(end.frequency, rel=1e-10)


# --------------------------------------------------------------------------- #
# the seed's example system: mode 1 is the bilinear oscillator (closed form)
# --------------------------------------------------------------------------- #
def bilinear_frequency(lam: float, contact_stiffness: float) -> float:
    """u'' + λ² u + k u_+ = 0: half a period at ω_c = sqrt(λ² + k), half at λ."""
    omega_c = math.sqrt(lam * lam + contact_stiffness)
    return 2.0 * lam * omega_c / (lam + omega_c)


@pytest.mark.parametrize("epsilon", [0.3, 1.0, 3.0])
def test_expansion_route_on_the_seed_system_matches_the_bilinear_closed_form(epsilon):
    # W ≠ Aᵀ, energy amplitude E = c ε; at ε = 3 the expansion's period is off by a factor ≈ 3 and Newton
    # from it lands on the orbit run three times: it must be recognised and re-solved at its own period
    from lindstedt.numerics import seed_example_system

    system = seed_example_system(5)
    lam, phi = system.modes()
    result = nnm_point(system, epsilon, 1, energy_per_epsilon=0.129 / 0.272, initial_guess="expansion")
    assert result.success, result.message
    assert result.frequency == pytest.approx(bilinear_frequency(lam[0], epsilon * phi[0, 0]), rel=1e-12)
    assert exact_flow_return(system, result) < 1e-10
