"""The waveform of order N is O(ε^{N+1}) uniformly on t ∈ [0, 1/ε] (fitted convergence order).

References: Duffing's exact solution a·cn(√(ω0² + ε a²) t, m) (scipy's Jacobi
elliptic functions, machine precision) and, for other f, DOP853 at rtol 1e-13.
"""

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.special import ellipj

import lindstedt

EPSILONS = np.geomspace(0.01, 0.04, 5)
SLOPE_BAND = 0.3


def duffing_exact(t, epsilon, amplitude):
    """u'' + u + ε u³ = 0, u(0) = a, u'(0) = 0 (ε > 0): u = a cn(Ω t | m)."""
    frequency_squared = 1 + epsilon * amplitude**2
    parameter = epsilon * amplitude**2 / (2 * frequency_squared)
    cn = ellipj(np.sqrt(frequency_squared) * t, parameter)[1]
    return amplitude * cn


def numerical_solution(f, t, epsilon, amplitude):
    def field(_, state):
        return [state[1], -state[0] - epsilon * f(state[0])]

    solution = solve_ivp(field, (0, t[-1]), [amplitude, 0.0], method="DOP853", t_eval=t, rtol=1e-13, atol=1e-15)
    assert solution.success
    return solution.y[0]


def fitted_slope(errors):
    return np.polyfit(np.log(EPSILONS), np.log(errors), 1)[0]


def test_duffing_reference_is_the_ode_solution():
    t = np.linspace(0, 30, 301)
    assert np.max(np.abs(duffing_exact(t, 0.05, 1.0) - numerical_solution(lambda u: u**3, t, 0.05, 1.0))) < 1e-10


@pytest.mark.parametrize("order", [0, 1, 2, 3])
def test_duffing_waveform_error_scales_like_eps_to_order_plus_one(order):
    expansion = lindstedt.expand("u**3", order=order, a0=1, omega0=1)
    errors = []
    for epsilon in EPSILONS:
        t = np.linspace(0, 1 / epsilon, 4000)
        errors.append(np.max(np.abs(expansion.displacement(t, epsilon) - duffing_exact(t, epsilon, 1.0))))
    assert fitted_slope(errors) == pytest.approx(order + 1, abs=SLOPE_BAND)


@pytest.mark.parametrize(
    "f_text, f_callable, order",
    [("u**2", lambda u: u**2, 2), ("sin(u)", np.sin, 2), ("u**3 + u**5/2", lambda u: u**3 + u**5 / 2, 1)],
)
def test_smooth_waveform_error_scales_like_eps_to_order_plus_one(f_text, f_callable, order):
    expansion = lindstedt.expand(f_text, order=order, a0="0.9", omega0=1)
    errors = []
    for epsilon in EPSILONS:
        t = np.linspace(0, 1 / epsilon, 3000)
        errors.append(np.max(np.abs(expansion.displacement(t, epsilon) - numerical_solution(f_callable, t, epsilon, 0.9))))
    assert fitted_slope(errors) == pytest.approx(order + 1, abs=SLOPE_BAND)


def test_velocity_matches_derivative_of_displacement():
    expansion = lindstedt.expand("u**3", order=2, a0=1, omega0=1)
    t = np.linspace(0, 10, 2001)
    numerical_derivative = np.gradient(expansion.displacement(t, 0.05), t, edge_order=2)
    assert np.max(np.abs(expansion.velocity(t, 0.05) - numerical_derivative)) < 1e-4


@pytest.mark.parametrize("order", [1, 2])
def test_harmonic_normalisation_waveform_converges(order):
    expansion = lindstedt.expand("u**3", order=order, a0=1, omega0=1, normalization="harmonic")
    errors = []
    for epsilon in EPSILONS:
        t = np.linspace(0, 1 / epsilon, 3000)
        release = float(expansion.displacement(0.0, epsilon))
        errors.append(np.max(np.abs(expansion.displacement(t, epsilon) - numerical_solution(lambda u: u**3, t, epsilon, release))))
    assert fitted_slope(errors) == pytest.approx(order + 1, abs=SLOPE_BAND)
