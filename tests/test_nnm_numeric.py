"""NNMs of M X'' + K X + ε W (A X − b)_+ = 0 by shooting, against independent references.

Expected values come from computations independent of the shooting (lindstedt.numerics.nnm_point and friends):
the closed-form period of the one-dof piecewise-linear oscillator
(lindstedt.references), the bilinear-oscillator formula
ω = 2 λ ω_c / (λ + ω_c) derived by hand, the first-order averaging coefficient
ω_1 = φ_jᵀ W A φ_j / (4 λ_j) for gaps b = 0 (derived below), central finite
differences, and direct flows of ExactFlow (the ground truth the shooting uses,
called here independently of the shooting code).
"""

from __future__ import annotations

import math
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from lindstedt import UnilateralSystem
from lindstedt.numerics import (
    ContinuationProgress,
    ExactFlow,
    NNMShooting,
    continue_nnm,
    flow_epsilon_derivative,
    nnm_energy,
    nnm_point,
    nnm_sweep,
    seed_example_system,
)
from lindstedt.references import piecewise_linear_exact_frequency


# --------------------------------------------------------------------------- #
# independent references
# --------------------------------------------------------------------------- #
def bilinear_frequency(lam: float, contact_stiffness: float) -> float:
    """u'' + λ² u + k u_+ = 0: half a period at ω_c = sqrt(λ² + k), half at λ."""
    omega_c = math.sqrt(lam * lam + contact_stiffness)
    return 2.0 * lam * omega_c / (lam + omega_c)


def first_order_coefficient(system: UnilateralSystem, mode: int) -> float:
    """ω_1 for gaps b = 0 by averaging.

    With u = a cos s in mode j, the modal force ε φ_jᵀ W (A φ_j a cos s)_+ has the
    cos s coefficient (1/π)∫(c a cos s)_+ cos s ds = c a / 2 per spring
    (c = A_i φ_j, either sign), so ω² = λ_j² + ε φ_jᵀ W A φ_j / 2 + O(ε²).
    """
    lam, phi = system.modes()
    shape = phi[:, mode - 1]
    return float(shape @ system.W @ system.A @ shape) / (4.0 * lam[mode - 1])


def periodicity_error(system: UnilateralSystem, result) -> float:
    """Relative return error of a direct ExactFlow over one period from the release state."""
    flow = ExactFlow(system, result.epsilon)
    end = flow.flow_map(result.release_position, result.release_velocity, result.period)
    scale = np.max(np.abs(result.release_position))
    return max(
        np.max(np.abs(end.position - result.release_position)) / scale,
        np.max(np.abs(end.velocity - result.release_velocity)) / (result.frequency * scale),
    )


# --------------------------------------------------------------------------- #
# one degree of freedom: the exact closed form
# --------------------------------------------------------------------------- #
@pytest.mark.parametrize(
    "omega0, a, b, a0, epsilon",
    [
        (1.0, 1, 0.0, 1.0, 0.5),
        (1.3, 1, 0.2, 1.0, 0.8),
        (1.3, 1, 0.2, -1.5, 0.8),  # released on the free side, contact on the far side
        (0.7, 2, 0.3, 0.9, 0.25),  # (2u − 0.3)_+ = 2 (u − 0.15)_+, W ≠ Aᵀ
        (1.0, 1, -0.4, 1.2, 1.5),  # preloaded
    ],
)
def test_one_dof_frequency_matches_exact_closed_form(omega0, a, b, a0, epsilon):
    system = UnilateralSystem.one_dof(omega0, a=a, b=b)
    result = nnm_point(system, epsilon, 1, modal_amplitude=a0)
    assert result.success, result.message
    exact = float(piecewise_linear_exact_frequency(epsilon, a=a, b=b / a, a0=a0, omega0=omega0))
    assert result.frequency == pytest.approx(exact, rel=1e-12, abs=0)
    assert result.release_position[0] == pytest.approx(a0, rel=1e-14, abs=0)
    assert result.n_switches == 2
    assert result.stable


def test_one_dof_energy_parametrisation_matches_closed_form():
    system = UnilateralSystem.one_dof(1.0, a=1, b=0.25)
    epsilon, a0 = 0.6, 0.9
    energy = 0.5 * a0**2 + 0.5 * epsilon * (a0 - 0.25) ** 2  # conserved energy at the turning point
    result = nnm_point(system, epsilon, 1, energy=energy)
    assert result.success, result.message
    assert result.release_position[0] == pytest.approx(a0, rel=1e-12)
    exact = float(piecewise_linear_exact_frequency(epsilon, a=1, b=0.25, a0=a0, omega0=1.0))
    assert result.frequency == pytest.approx(exact, rel=1e-12, abs=0)


def test_one_dof_first_taylor_coefficient_from_two_epsilons():
    """ω(ε) = ω0 + ε ω1 + …: Richardson from two ε vs the reference's exact ω1 (gap ≠ 0)."""
    from lindstedt.references import piecewise_linear_frequency_taylor

    omega0, b, a0 = 1.2, 0.3, 1.0
    system = UnilateralSystem.one_dof(omega0, a=1, b=b)
    coefficients = piecewise_linear_frequency_taylor(2, a=1, b=b, a0=a0, omega0=omega0)
    omega1 = float(coefficients[1][0])  # (value, error bound)
    epsilon = 1e-3
    slopes = [(nnm_point(system, e, 1, modal_amplitude=a0).frequency - omega0) / e for e in (epsilon, 2 * epsilon)]
    assert 2 * slopes[0] - slopes[1] == pytest.approx(omega1, rel=1e-5, abs=1e-9)


# --------------------------------------------------------------------------- #
# several degrees of freedom, small ε
# --------------------------------------------------------------------------- #
@pytest.mark.parametrize("n_masses, springs", [(2, [(0, 0.0)]), (3, [(0, 0.0)]), (3, [(1, 0.0), (2, 0.0, -1)])])
def test_small_epsilon_frequency_shift_is_first_order(n_masses, springs):
    system = UnilateralSystem.chain(n_masses, unilateral=springs)
    lam = system.modes().frequencies
    for mode in range(1, n_masses + 1):
        omega1 = first_order_coefficient(system, mode)
        if abs(omega1) < 1e-12:
            continue  # the spring sits on a node of this mode
        epsilons = np.array([1e-3, 2e-3, 4e-3, 8e-3])
        frequencies = np.array([nnm_point(system, e, mode, modal_amplitude=1.0).frequency for e in epsilons])
        shifts = frequencies - lam[mode - 1]
        slope = np.polyfit(np.log(epsilons), np.log(np.abs(shifts)), 1)[0]
        assert slope == pytest.approx(1.0, abs=0.01)
        # the ε-expansion coefficient vs a Richardson finite-difference estimate from two ε
        ratios = shifts / epsilons
        estimate = 2 * ratios[0] - ratios[1]
        assert estimate == pytest.approx(omega1, rel=1e-5, abs=0)


def test_linear_limit_epsilon_zero_gives_linear_frequencies_exactly():
    system = UnilateralSystem.chain(3, unilateral=[(0, 0.0)])
    lam, phi = system.modes()
    for mode in (1, 2, 3):
        result = nnm_point(system, 0.0, mode, modal_amplitude=0.7)
        assert result.success, result.message
        assert result.frequency == pytest.approx(lam[mode - 1], rel=1e-14, abs=0)
        np.testing.assert_allclose(result.release_position, 0.7 * phi[:, mode - 1], rtol=0, atol=1e-14)
        assert result.mode_share == pytest.approx(1.0, abs=1e-14)


def test_no_contact_gives_linear_mode_and_says_so():
    system = UnilateralSystem.chain(3, unilateral=[(0, 0.5)])
    lam, phi = system.modes()
    result = nnm_point(system, 0.8, 2, energy=0.05)  # amplitude ~ 0.16 < gap 0.5
    assert result.success
    assert result.n_switches == 0 and not result.contact
    assert "no contact" in result.message
    assert result.frequency == pytest.approx(lam[1], rel=1e-14, abs=0)
    # multipliers of the linear flow: exp(±i λ_k T)
    expected = np.exp(1j * np.outer([1, -1], lam).ravel() * result.period)
    found = result.floquet_multipliers
    for value in expected:
        assert np.min(np.abs(found - value)) < 1e-10


# --------------------------------------------------------------------------- #
# exact Jacobians
# --------------------------------------------------------------------------- #
@pytest.mark.parametrize("formulation", ["symmetric", "full"])
@pytest.mark.parametrize(
    "system, amplitude",
    [
        (UnilateralSystem.chain(3, unilateral=[(0, 0.05), (2, 0.05, -1)]), {"energy": 0.3}),
        (seed_example_system(4, gap=0.02), {"modal_amplitude": 0.6}),
        (UnilateralSystem.chain(2, unilateral=[(1, -0.1)]), {"energy_per_epsilon": 0.8}),
    ],
)
def test_jacobian_matches_central_differences(formulation, system, amplitude):
    problem = NNMShooting(system, 2, formulation=formulation, **amplitude)
    epsilon = 0.7
    rng = np.random.default_rng(3)
    unknowns = problem.initial_guess(epsilon)
    unknowns = unknowns + 0.02 * np.abs(unknowns).max() * rng.standard_normal(unknowns.size)
    jacobian, d_epsilon = problem.jacobian(unknowns, epsilon)
    numeric = np.empty_like(jacobian)
    for i in range(unknowns.size):
        step = 1e-6 * max(1.0, abs(unknowns[i]))
        plus, minus = unknowns.copy(), unknowns.copy()
        plus[i] += step
        minus[i] -= step
        numeric[:, i] = (problem.residual(plus, epsilon) - problem.residual(minus, epsilon)) / (2 * step)
    np.testing.assert_allclose(jacobian, numeric, rtol=0, atol=1e-7 * np.abs(jacobian).max())
    step = 1e-6
    numeric_eps = (problem.residual(unknowns, epsilon + step) - problem.residual(unknowns, epsilon - step)) / (2 * step)
    np.testing.assert_allclose(d_epsilon, numeric_eps, rtol=0, atol=1e-7 * max(1.0, np.abs(d_epsilon).max()))


def test_flow_epsilon_derivative_matches_central_differences():
    system = UnilateralSystem.chain(3, unilateral=[(0, 0.1), (2, -0.05, -1)])
    x0, v0 = np.array([0.5, -0.2, 0.3]), np.array([0.1, 0.4, -0.3])
    _, _, derivative = flow_epsilon_derivative(system, 0.4, x0, v0, 17.3)
    h = 1e-5
    plus = flow_epsilon_derivative(system, 0.4 + h, x0, v0, 17.3)[0]
    minus = flow_epsilon_derivative(system, 0.4 - h, x0, v0, 17.3)[0]
    np.testing.assert_allclose(derivative, (plus - minus) / (2 * h), rtol=0, atol=1e-8 * np.abs(derivative).max())


# --------------------------------------------------------------------------- #
# formulations agree, residuals hold
# --------------------------------------------------------------------------- #
@pytest.mark.parametrize("mode", [1, 2, 3])
def test_symmetric_and_full_formulations_agree(mode):
    system = UnilateralSystem.chain(3, unilateral=[(0, 0.05), (2, 0.0, -1)])
    symmetric = nnm_point(system, 0.6, mode, energy=0.4, formulation="symmetric")
    full = nnm_point(system, 0.6, mode, energy=0.4, formulation="full")
    assert symmetric.success and full.success, (symmetric.message, full.message)
    assert full.frequency == pytest.approx(symmetric.frequency, rel=1e-11, abs=0)
    scale = np.abs(symmetric.release_position).max()
    np.testing.assert_allclose(full.release_position, symmetric.release_position, rtol=0, atol=1e-9 * scale)
    np.testing.assert_allclose(full.release_velocity, 0.0, rtol=0, atol=1e-9 * scale * symmetric.frequency)
    assert periodicity_error(system, symmetric) < 1e-10
    assert periodicity_error(system, full) < 1e-10
    nontrivial = lambda r: np.sort(np.abs(r.floquet_multipliers[2:] - 1))  # noqa: E731
    np.testing.assert_allclose(nontrivial(full), nontrivial(symmetric), rtol=0, atol=1e-7)


def test_energy_is_the_conserved_energy_for_symmetric_coupling():
    system = UnilateralSystem.chain(2, unilateral=[(0, 0.1)])
    result = nnm_point(system, 0.9, 1, energy=0.5)
    flow = ExactFlow(system, 0.9)
    trajectory = flow.solve(result.release_position, result.release_velocity, result.period)
    X, V = trajectory.state(np.linspace(0, result.period, 17))
    np.testing.assert_allclose(system.energy(X, V, 0.9), 0.5, rtol=1e-12, atol=0)
    assert nnm_energy(system, X[5], V[5], 0.9) == pytest.approx(0.5, rel=1e-12)


# --------------------------------------------------------------------------- #
# continuation
# --------------------------------------------------------------------------- #
def test_arclength_branch_is_smooth_and_every_point_is_periodic():
    system = UnilateralSystem.chain(3, unilateral=[(0, 0.0)])
    seen: list[ContinuationProgress] = []
    branch = continue_nnm(system, 1, modal_amplitude=1.0, start=0.0, stop=1.0, callback=seen.append)
    assert branch.success, branch.stop_reason
    assert len(branch) == len(seen) and [p.index for p in seen] == list(range(len(branch)))
    eps, omega = branch.epsilons, branch.frequencies
    assert eps[0] == 0.0 and eps[-1] == 1.0 and np.all(np.diff(eps) > 0)
    assert omega[0] == pytest.approx(system.modes().frequencies[0], rel=1e-14)
    for point in branch.points:
        assert point.success and point.modal_amplitude == pytest.approx(1.0, rel=1e-12)
        assert periodicity_error(system, point) < 1e-10
    # smooth: a cubic spline through every other point predicts the rest
    from scipy.interpolate import CubicSpline

    spline = CubicSpline(eps[::2], omega[::2])
    inner = np.arange(1, len(eps) - 1, 2)
    inner = inner[eps[inner] < eps[::2][-1]]
    np.testing.assert_allclose(spline(eps[inner]), omega[inner], rtol=2e-5, atol=0)
    # independent point solves agree with the branch
    for index in (len(branch) // 2, len(branch) - 1):
        alone = nnm_point(system, eps[index], 1, modal_amplitude=1.0)
        assert alone.frequency == pytest.approx(omega[index], rel=1e-11)


def test_arclength_in_energy_with_gap_reports_contact_onset():
    system = UnilateralSystem.chain(2, unilateral=[(0, 0.2)])
    branch = continue_nnm(system, 1, parameter="energy", epsilon=1.0, start=0.005, stop=0.2)
    assert branch.success, branch.stop_reason
    assert not branch.points[0].contact and branch.points[-1].contact
    assert len(branch.contact_changes) == 1
    lam = system.modes().frequencies[0]
    before = branch.frequencies[: branch.contact_changes[0] + 1]
    np.testing.assert_allclose(before, lam, rtol=1e-13, atol=0)
    assert branch.frequencies[-1] > lam


def test_arclength_and_seed_baseline_follow_the_same_branch_with_fewer_flows():
    system = seed_example_system(5)
    lam, phi = system.modes()
    c = 0.03002 / 0.063
    arclength = continue_nnm(system, 1, energy_per_epsilon=c, start=0.02, stop=0.26, step=0.1)
    seed = continue_nnm(system, 1, energy_per_epsilon=c, start=0.02, stop=0.26, method="seed", step=0.03)
    assert arclength.success and seed.success, (arclength.stop_reason, seed.stop_reason)
    # both are the seed system's mode-1 NNM: the bilinear oscillator with contact stiffness ε Φ_11
    for branch in (arclength, seed):
        exact = [bilinear_frequency(lam[0], e * phi[0, 0]) for e in branch.epsilons]
        np.testing.assert_allclose(branch.frequencies, exact, rtol=1e-11, atol=0)
    assert arclength.frequencies[-1] == pytest.approx(seed.frequencies[-1], rel=1e-11)
    # hybr without Jacobian pays ≥ 2N + 1 = 11 flows per point for its difference Jacobian alone
    per_point = lambda b: b.flow_evaluations / len(b)  # noqa: E731
    assert per_point(seed) > 11 and per_point(arclength) * 4 < per_point(seed)
    assert arclength.flow_evaluations < seed.flow_evaluations


def test_natural_continuation_matches_arclength():
    system = UnilateralSystem.chain(2, unilateral=[(0, 0.0)])
    natural = continue_nnm(system, 2, energy=0.3, start=0.0, stop=0.8, method="natural", step=0.1)
    arclength = continue_nnm(system, 2, energy=0.3, start=0.0, stop=0.8)
    assert natural.success and arclength.success
    assert len(natural) == 9
    assert natural.frequencies[-1] == pytest.approx(arclength.frequencies[-1], rel=1e-11)


def test_callback_can_stop_the_continuation():
    system = UnilateralSystem.chain(2, unilateral=[(0, 0.0)])
    branch = continue_nnm(system, 1, modal_amplitude=1.0, start=0.0, stop=1.0, callback=lambda p: p.index >= 2)
    assert not branch.success and branch.stop_reason == "callback requested stop"
    assert len(branch) == 3


# --------------------------------------------------------------------------- #
# failure modes
# --------------------------------------------------------------------------- #
def test_impossible_energy_reports_failure():
    system = UnilateralSystem.chain(2, unilateral=[(0, 0.0)])
    result = nnm_point(system, 0.5, 1, energy=-1.0)
    assert not result.success and "impossible energy" in result.message
    assert math.isnan(result.frequency)
    branch = continue_nnm(system, 1, energy_per_epsilon=0.5, start=0.0, stop=1.0)
    assert not branch.success and branch.stop_reason.startswith("first point failed: impossible energy")


def test_no_convergence_is_reported():
    system = UnilateralSystem.chain(3, unilateral=[(0, 0.0)])
    result = nnm_point(system, 3.0, 1, modal_amplitude=1.0, max_iterations=1)
    assert not result.success and "no convergence" in result.message


def test_too_large_step_is_reported():
    system = UnilateralSystem.chain(3, unilateral=[(0, 0.0)])
    branch = continue_nnm(system, 1, modal_amplitude=1.0, start=0.0, stop=20.0, method="natural", step=20.0,
                          max_halvings=0, max_iterations=2)
    assert not branch.success and "halved 0 times without convergence" in branch.stop_reason
    assert len(branch) == 1
    arclength = continue_nnm(system, 1, modal_amplitude=1.0, start=0.0, stop=20.0, step=5.0, min_step=5.0,
                             max_iterations=2)
    assert not arclength.success and "below min_step" in arclength.stop_reason


def test_singular_jacobian_is_reported():
    # released at rest exactly at the equilibrium: the energy row ∂E/∂X0 = K X0 and ∂X'(T/2)/∂T vanish
    system = UnilateralSystem.chain(2, unilateral=[(0, 0.0)])
    result = nnm_point(system, 0.5, 1, energy=0.2, initial_guess=(np.zeros(2), 2 * np.pi))
    assert not result.success and "singular Jacobian" in result.message
    assert result.flow_evaluations == 1


# --------------------------------------------------------------------------- #
# sweeps
# --------------------------------------------------------------------------- #
def test_executor_sweep_equals_serial_in_input_order():
    system = UnilateralSystem.chain(3, unilateral=[(0, 0.05)])
    values = [0.3, 0.05, 0.2, 0.0, 0.1]
    serial = nnm_sweep(system, 2, values, energy=0.2)
    with ThreadPoolExecutor(max_workers=3) as pool:
        threaded = nnm_sweep(system, 2, values, energy=0.2, executor=pool)
    assert [r.epsilon for r in threaded] == values
    np.testing.assert_array_equal([r.frequency for r in threaded], [r.frequency for r in serial])
    np.testing.assert_array_equal(np.array([r.release_position for r in threaded]),
                                  np.array([r.release_position for r in serial]))
    energies = [0.05, 0.4, 0.2]
    with ThreadPoolExecutor(max_workers=2) as pool:
        by_energy = nnm_sweep(system, 1, energies, parameter="energy", epsilon=0.5, executor=pool)
    assert [r.energy for r in by_energy] == pytest.approx(energies, rel=1e-12)


# --------------------------------------------------------------------------- #
# the seed's examples
# --------------------------------------------------------------------------- #
def test_seed_example_system_structure():
    system = seed_example_system(5, gap=0.1)
    lam, phi = system.modes()
    np.testing.assert_allclose(phi.T @ system.W[:, 0], np.eye(5)[0], rtol=0, atol=1e-15)
    assert system.A.tolist() == [[1.0, 0.0, 0.0, 0.0, 0.0]] and system.b.tolist() == [0.1]
    assert not system.symmetric_coupling


@pytest.mark.parametrize(
    "n_dof, mode, epsilon, energy",
    [
        (5, 1, 0.063, 0.03002),
        (5, 1, 0.123 / (0.03002 / 0.063), 0.123),
        (20, 20, 0.272, 0.129),
        (20, 1, 0.29 / (0.129 / 0.272), 0.29),
        (20, 2, 0.28 / (0.129 / 0.272), 0.28),
    ],
)
def test_seed_examples_converge(n_dof, mode, epsilon, energy):
    system = seed_example_system(n_dof)
    lam, phi = system.modes()
    result = nnm_point(system, epsilon, mode, energy=energy)
    assert result.success, result.message
    assert result.energy == pytest.approx(energy, rel=1e-12)
    if mode == 1:  # u_k = 0 for k ≠ 1: the bilinear oscillator
        assert result.frequency == pytest.approx(bilinear_frequency(lam[0], epsilon * phi[0, 0]), rel=1e-12)
    else:  # u_j is exactly linear: ω = λ_j
        assert result.frequency == pytest.approx(lam[mode - 1], rel=1e-13)
    assert result.contact and result.stable
    assert periodicity_error(system, result) < 1e-10


@pytest.mark.slow
def test_twenty_dof_branch_arclength_needs_ten_times_fewer_flows_than_the_seed_algorithm():
    system = seed_example_system(20)
    lam, phi = system.modes()
    c = 0.129 / 0.272
    arclength = continue_nnm(system, 1, energy_per_epsilon=c, start=0.02, stop=0.6, step=0.045, max_step=0.045)
    seed = continue_nnm(system, 1, energy_per_epsilon=c, start=0.02, stop=0.6, method="seed",
                        step=0.58 / (len(arclength) - 1))
    assert arclength.success and seed.success
    assert abs(len(seed) - len(arclength)) <= 1
    assert seed.flow_evaluations >= 10 * arclength.flow_evaluations
    for branch in (arclength, seed):
        exact = [bilinear_frequency(lam[0], e * phi[0, 0]) for e in branch.epsilons]
        np.testing.assert_allclose(branch.frequencies, exact, rtol=1e-11, atol=0)


def test_natural_continuation_stops_with_a_reason_where_the_step_collapses():
    # past eps ~ 6 the seed's 5-dof example has no vibrating contact state: accepted points kept resetting the
    # halving count, the step shrank until two accepted values coincided and the secant guess divided by zero
    branch = continue_nnm(seed_example_system(5), 1, method="natural", formulation="full", energy=0.5, start=0.5, stop=20, step=0.5)
    assert not branch.success and "below min_step" in branch.stop_reason
    assert all(point.success for point in branch.points)
    assert branch.epsilons[-1] < 6.1
