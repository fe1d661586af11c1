"""All modes excited, first order (Theorem 4.3): λ_k¹ against closed forms, the 1-dof expansion and simulation."""

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

import lindstedt
from lindstedt import ProblemError, UnilateralSystem, all_modes_first_order
from lindstedt.numerics import ExactFlow


def test_zero_gaps_closed_form_is_a_kk_over_4_lambda_k():
    system = UnilateralSystem.chain(3, unilateral=[(0, 0), (2, 0)])
    modes = system.modes()
    coupling = np.asarray(system.A, float) @ modes.shapes
    forcing = modes.shapes.T @ np.asarray(system.W, float)
    result = all_modes_first_order(system, [1.0, 0.7, 0.2])
    expected = np.diag(forcing @ coupling) / (4 * modes.frequencies)
    assert [value for value, _ in result.corrections] == pytest.approx(expected, rel=1e-14)
    assert set(result.methods) == {"closed form (zero gaps)"}


def test_average_converges_to_the_closed_form_as_the_gap_vanishes():
    closed = all_modes_first_order(UnilateralSystem.chain(2, unilateral=[(0, 0)]), [1.0, 0.5])
    averaged = all_modes_first_order(UnilateralSystem.chain(2, unilateral=[(0, 1e-12)]), [1.0, 0.5])
    for (exact, _), (value, error) in zip(closed.corrections, averaged.corrections):
        assert abs(value - exact) <= max(3 * error, 1e-9)


@pytest.mark.parametrize("stiffness, gap, release, omega0", [(1.7, 0.3, 1.3, 1.1), (2.0, -0.25, -0.6, 0.5)])
def test_one_dof_average_equals_the_first_order_expansion(stiffness, gap, release, omega0):
    result = all_modes_first_order(UnilateralSystem.one_dof(omega0, a=stiffness, b=gap), [release])
    value, error = result.corrections[0]
    reference = float(lindstedt.expand(f"Max(0, {stiffness}*u - ({gap}))", order=1, a0=release, omega0=omega0, numeric=True).omega[1])
    assert abs(value - reference) <= 3 * error and error < 1e-5


def _spectral_peak(signal, times, guess):
    window = np.sin(np.pi * times / times[-1]) ** 2
    search = minimize_scalar(
        lambda w: -abs(np.trapezoid(signal * window * np.exp(-1j * w * times), times)),
        bracket=(guess - 2e-3, guess, guess + 2e-3),
        tol=1e-12,
    )
    return search.x


@pytest.mark.slow  # long exact-flow simulations of every mode (6 s)
def test_frequency_shifts_match_simulation_of_the_exact_flow():
    system = UnilateralSystem.chain(3, unilateral=[(0, 0.3), (2, -0.2)])
    amplitudes = np.array([1.0, 0.5, 0.3])
    predicted = all_modes_first_order(system, amplitudes)
    modes = system.modes()
    mass = np.asarray(system.M, float)
    estimates = []
    for epsilon in (0.005, 0.01):
        times = np.linspace(0, 4000, 400001)
        states, _ = ExactFlow(system, epsilon).solve(modes.shapes @ amplitudes, np.zeros(3), times[-1]).state(times)
        modal = modes.shapes.T @ mass @ states.T
        estimates.append(
            [(_spectral_peak(modal[k], times, modes.frequencies[k] + epsilon * predicted.corrections[k][0]) - modes.frequencies[k]) / epsilon for k in range(3)]
        )
    extrapolated = 2 * np.array(estimates[0]) - np.array(estimates[1])  # (Ω − λ)/ε = λ¹ + O(ε)
    assert extrapolated == pytest.approx([value for value, _ in predicted.corrections], abs=1e-3)


def test_polarisation_and_bad_input():
    system = UnilateralSystem.chain(2, unilateral=[(0, 0.1)])
    polarised = all_modes_first_order(system, [0.0, 1.0])
    assert polarised.polarised_mode == 2 and "nnm" in polarised.message
    assert polarised.methods[0] == "not excited"
    with pytest.raises(ProblemError, match="one modal amplitude per mode"):
        all_modes_first_order(system, [1.0])
    with pytest.raises(ProblemError, match="not all zero"):
        all_modes_first_order(system, [0.0, 0.0])
