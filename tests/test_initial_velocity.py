"""General initial data u(0) = u0, u'(0) = v0 (issue 12, item 3): amplitude and phase series.

Every expectation comes from an independent reference, never from the code under test:

* the turning point A(ε) from the energy  ω0² A²/2 + ε F(A) = v0²/2 + ω0² u0²/2 + ε F(u0)
  (Duffing: a quadratic in A², solved in closed form; springs: ``mpmath.findroot``);
* the frequency of that orbit from the exact Duffing Taylor series (elliptic integral,
  :func:`lindstedt.references.duffing_frequency_taylor`) composed with ε A(ε)², and from the
  closed-form period of the piecewise-linear oscillator at the turning point
  (:func:`lindstedt.references.piecewise_linear_exact_frequency`);
* the motion from (u0, v0) by DOP853 (smooth f) or the closed-form arcs of
  :class:`lindstedt.ExactFlow` (unilateral springs), built here from the equation.
"""

from __future__ import annotations

import json

import mpmath
import numpy as np
import pytest
import sympy
from scipy.integrate import solve_ivp

import lindstedt
from lindstedt.references import duffing_frequency_taylor, piecewise_linear_exact_frequency
from lindstedt.validate import expansion_error, fitted_convergence_order, loglog_fit, reference_solution

EPS = sympy.Symbol("epsilon", real=True)  # the expansion variable of lindstedt
EPSILONS = [0.04, 0.02, 0.01]


# --------------------------------------------------------------------------- #
# independent references
# --------------------------------------------------------------------------- #
def duffing_turning_square(u0, v0, omega0, order):
    """A(ε)² of u'' + ω0² u + ε u³ = 0 through (u0, v0): X + ε X²/(2ω0²) = u0² + v0²/ω0² + ε u0⁴/(2ω0²), exactly."""
    right = u0**2 + v0**2 / omega0**2 + EPS * u0**4 / (2 * omega0**2)
    square = omega0**2 * (sympy.sqrt(1 + 2 * EPS * right / omega0**2) - 1) / EPS
    return sympy.series(square, EPS, 0, order + 1).removeO()


def duffing_frequency_coefficients(u0, v0, omega0, order):
    """ω_k of the orbit: ω = ω0 Σ r_k x^k, x = ε A(ε)²/ω0², with the exact r_k of the elliptic integral."""
    r = duffing_frequency_taylor(order, "initial")
    x = EPS * duffing_turning_square(u0, v0, omega0, order) / omega0**2
    omega = sympy.expand(omega0 * sum(r[k] * x**k for k in range(order + 1)))
    return [omega.coeff(EPS, k) for k in range(order + 1)]


def spring_potential(u, b):
    """F(u) = ∫_0^u (x − b)_+ dx for b ≥ 0."""
    return (u - b) ** 2 / 2 if u > b else 0 * u


def spring_turning_point(u0, v0, omega0, b, epsilon):
    """The positive turning point of u'' + ω0² u + ε (u − b)_+ = 0 through (u0, v0), by findroot on the energy."""
    with mpmath.workdps(40):
        u0, v0, omega0, b, eps = (mpmath.mpf(sympy.Rational(x).p) / sympy.Rational(x).q for x in (u0, v0, omega0, b, epsilon))
        energy = v0**2 / 2 + omega0**2 * u0**2 / 2 + eps * spring_potential(u0, b)
        start = mpmath.sqrt(u0**2 + (v0 / omega0) ** 2)
        return mpmath.findroot(lambda a: omega0**2 * a**2 / 2 + eps * spring_potential(a, b) - energy, start)


def duffing_flow(u0, v0, omega0, epsilon, times):
    """u(t) of u'' + ω0² u + ε u³ = 0 from (u0, v0), DOP853."""
    solution = solve_ivp(
        lambda _t, y: [y[1], -(omega0**2) * y[0] - epsilon * y[0] ** 3],
        (0.0, float(times[-1])), [float(u0), float(v0)], method="DOP853", rtol=1e-13, atol=1e-15, t_eval=times,
    )
    assert solution.success
    return solution.y[0]


def spring_flow(u0, v0, omega0, b, epsilon, times):
    """u(t) of u'' + ω0² u + ε (u − b)_+ = 0 from (u0, v0): closed-form arcs of the exact flow."""
    system = lindstedt.UnilateralSystem.one_dof(omega0, a=1, b=b)
    result = lindstedt.ExactFlow(system, epsilon).solve([float(u0)], [float(v0)], float(times[-1]))
    assert result.success
    return result.state(times)[0][:, 0]


def max_errors(expansion, flow, epsilons=EPSILONS):
    """max |u_N − u| over t ≤ 1/ε for each ε (64 samples per linear period)."""
    errors = []
    for epsilon in epsilons:
        times = np.linspace(0.0, 1.0 / epsilon, int(64 / (2 * np.pi) / epsilon) + 2)
        errors.append(float(np.max(np.abs(expansion.displacement(times, epsilon) - flow(epsilon, times)))))
    return np.array(errors)


# --------------------------------------------------------------------------- #
# the frequency of the orbit through (u0, v0)
# --------------------------------------------------------------------------- #
@pytest.mark.parametrize("u0, v0, omega0", [("3/5", "4/5", 1), ("1/2", "-1", 2), ("-1/3", "1/7", "3/2")])
def test_duffing_frequency_is_the_exact_one_of_the_orbit(u0, v0, omega0):
    u0, v0, omega0 = (sympy.Rational(x) for x in (u0, v0, omega0))
    order = 4
    expansion = lindstedt.expand("u**3", order=order, u0=u0, v0=v0, omega0=omega0)
    expected = duffing_frequency_coefficients(u0, v0, omega0, order)
    for k in range(order + 1):
        assert sympy.simplify(expansion.omega[k] - expected[k]) == 0, k
    # the turning point: A(ε)² against the closed form
    amplitude = expansion.amplitude_expr()
    difference = sympy.expand(amplitude**2 - duffing_turning_square(u0, v0, omega0, order))
    for k in range(order + 1):
        assert sympy.simplify(difference.coeff(EPS, k)) == 0, k


def test_duffing_frequency_with_symbolic_omega0_and_parameter():
    # f = c u³ with symbolic c and omega0: the same coefficients once the numbers are substituted
    expansion = lindstedt.expand("c*u**3", order=3, u0="1/2", v0="1/2", params={"c": None})
    expected = duffing_frequency_coefficients(sympy.Rational(1, 2), sympy.Rational(1, 2), sympy.Integer(3), 3)
    c, omega0 = sympy.Symbol("c", real=True), sympy.Symbol("omega0", positive=True)
    for k in range(4):
        value = expansion.omega[k].subs({c: 1, omega0: 3})
        assert abs(sympy.N(value - expected[k], 40)) < 1e-35, k
    numeric = lindstedt.expand("u**3", order=3, u0="1/2", v0="1/2", omega0=3)
    t = np.linspace(0.0, 20.0, 41)
    assert np.allclose(expansion.displacement(t, 0.05, values={"c": 1, "omega0": 3}), numeric.displacement(t, 0.05),
                       rtol=0, atol=1e-13)


@pytest.mark.parametrize("b", ["0", "1/4"])
@pytest.mark.parametrize("u0, v0", [("3/5", "4/5"), ("-3/5", "-4/5")])
def test_spring_frequency_against_the_exact_period_at_the_turning_point(b, u0, v0):
    order = 2
    expansion = lindstedt.expand(f"Max(0, u - {b})", order=order, u0=u0, v0=v0, omega0=1)
    epsilons = [0.08, 0.04, 0.02]
    frequency_errors, amplitude_errors = [], []
    for epsilon in epsilons:
        turning = spring_turning_point(u0, v0, 1, b, sympy.Rational(epsilon))
        exact = piecewise_linear_exact_frequency(epsilon, a=1, b=sympy.Rational(b), a0=turning, omega0=1, precision=30)
        frequency_errors.append(abs(expansion.frequency(epsilon) - float(exact)))
        amplitude = float(expansion.amplitude_expr().subs(EPS, sympy.Rational(epsilon)))
        amplitude_errors.append(abs(amplitude - float(turning)))
    assert loglog_fit(epsilons, frequency_errors).slope == pytest.approx(order + 1, abs=0.15)
    assert loglog_fit(epsilons, amplitude_errors).slope == pytest.approx(order + 1, abs=0.15)


# --------------------------------------------------------------------------- #
# the motion against the exact flow, t <= 1/eps
# --------------------------------------------------------------------------- #
@pytest.mark.parametrize("v0", ["4/5", "-4/5"])
def test_duffing_displacement_converges_at_order_n_plus_one(v0):
    order = 2
    expansion = lindstedt.expand("u**3", order=order, u0="3/5", v0=v0, omega0=1)
    errors = max_errors(expansion, lambda eps, t: duffing_flow(0.6, float(sympy.Rational(v0)), 1.0, eps, t))
    assert loglog_fit(EPSILONS, errors).slope == pytest.approx(order + 1, abs=0.15)
    assert errors[-1] < 1e-6


@pytest.mark.parametrize("u0, v0", [("3/5", "4/5"), ("3/5", "-4/5"), ("-3/5", "4/5"), ("1/4", "-1")])
def test_gap_displacement_converges_at_order_n_plus_one(u0, v0):
    # ("1/4", -1): u0 on the breakpoint, the phase is the moving contact angle itself
    order = 2
    expansion = lindstedt.expand("Max(0, u - 1/4)", order=order, u0=u0, v0=v0, omega0=1)
    start, speed = float(sympy.Rational(u0)), float(sympy.Rational(v0))
    errors = max_errors(expansion, lambda eps, t: spring_flow(start, speed, 1.0, 0.25, eps, t))
    assert loglog_fit(EPSILONS, errors).slope == pytest.approx(order + 1, abs=0.15)
    assert errors[-1] < 1e-6


def test_unilateral_spring_kicked_from_equilibrium_order_three():
    order = 3
    expansion = lindstedt.expand("Max(0, u)", order=order, u0=0, v0=-1, omega0=2)
    assert expansion.phase[0] == sympy.pi / 2
    errors = max_errors(expansion, lambda eps, t: spring_flow(0.0, -1.0, 2.0, 0.0, eps, t))
    assert loglog_fit(EPSILONS, errors).slope == pytest.approx(order + 1, abs=0.2)


def test_validate_compares_against_the_flow_from_u0_v0():
    expansion = lindstedt.expand("Max(0, u - 1/4)", order=2, u0="3/5", v0="-4/5", omega0=1)
    reference = reference_solution(expansion, 0.02, [0.0, 3.0])
    assert reference.initial_displacement == 0.6 and reference.initial_velocity == -0.8
    times = np.array([0.0, 3.0])
    assert np.allclose(reference.displacement, spring_flow(0.6, -0.8, 1.0, 0.25, 0.02, times), rtol=0, atol=1e-13)
    fit = fitted_convergence_order(expansion, EPSILONS)
    assert fit.success and fit.slope == pytest.approx(3, abs=0.15)
    error = expansion_error(expansion, 0.02, 50.0)
    independent = max_errors(expansion, lambda eps, t: spring_flow(0.6, -0.8, 1.0, 0.25, eps, t), [0.02])[0]
    assert error.success and error.max_error < 2 * independent + 1e-12
    smooth = lindstedt.expand("u**3", order=1, u0="-1/2", v0="1/3", omega0=1)
    reference = reference_solution(smooth, 0.1, [0.0, 2.0])
    assert np.allclose(reference.displacement, duffing_flow(-0.5, 1 / 3, 1.0, 0.1, np.array([0.0, 2.0])), rtol=0, atol=1e-10)


def test_exact_period_from_a_moving_start():
    problem = lindstedt.Oscillator("Max(0, u - 1/4)", u0="-3/5", v0="4/5", omega0=1)
    epsilon = 0.3
    period = lindstedt.validate.exact_period(problem, epsilon)
    turning = spring_turning_point("-3/5", "4/5", 1, "1/4", sympy.Rational(3, 10))
    exact = piecewise_linear_exact_frequency(epsilon, a=1, b=sympy.Rational(1, 4), a0=turning, omega0=1)
    assert period.success and period.period == pytest.approx(2 * np.pi / float(exact), rel=1e-11)


# --------------------------------------------------------------------------- #
# v0 = 0 is today's release at rest, exactly
# --------------------------------------------------------------------------- #
@pytest.mark.parametrize("f, u0", [("u**3", "3/5"), ("Max(0, u - 1/4)", "3/5"), ("Max(0, u - 1/4)", "-1"), ("sin(u)", "1/2")])
def test_zero_velocity_is_the_release_at_rest(f, u0):
    rest = lindstedt.expand(f, order=2, a0=u0, omega0=1)
    for moving in (lindstedt.expand(f, order=2, u0=u0, v0=0, omega0=1), lindstedt.expand(f, order=2, u0=u0, omega0=1)):
        assert moving == rest and moving.problem == rest.problem
        assert moving.omega == rest.omega and moving.waveforms == rest.waveforms
        assert moving.problem.u0 is None and moving.problem.v0 is None and not moving.problem.has_initial_velocity
        t = np.linspace(0.0, 30.0, 61)
        assert np.array_equal(moving.displacement(t, 0.05), rest.displacement(t, 0.05))
        assert moving.to_json() == rest.to_json() and moving.summary() == rest.summary()
        assert moving.phase == (0, 0, 0)
    assert lindstedt.Oscillator(f, u0=u0, v0="0") == lindstedt.Oscillator(f, a0=u0)


# --------------------------------------------------------------------------- #
# results, exports, code
# --------------------------------------------------------------------------- #
def test_results_show_initial_data_amplitude_and_phase():
    expansion = lindstedt.expand("Max(0, u - 1/4)", order=2, u0="3/5", v0="4/5", omega0=1)
    assert expansion.amplitude[0] == 1 and expansion.phase[0] == -sympy.atan(sympy.Rational(4, 3))
    data = json.loads(expansion.to_json())
    assert data["problem"]["u0"] == "3/5" and data["problem"]["v0"] == "4/5"
    assert len(data["amplitude"]) == len(data["phase"]) == 3 and None not in data["phase_float"]
    assert data["phase_float"][0] == pytest.approx(-np.arctan(4 / 3))
    latex = expansion.to_latex()
    assert r"\dot u(0) = \frac{4}{5}" in latex and r"\varphi(\varepsilon)" in latex and "A(\\varepsilon)" in latex
    summary = expansion.summary()
    assert "u'(0) = 4/5" in summary and "phi_2" in summary and "A_1" in summary


@pytest.mark.parametrize("f", ["u**3", "Max(0, u - 1/4)"])
def test_generated_code_and_lambdify_include_the_phase(f):
    expansion = lindstedt.expand(f, order=2, u0="-3/5", v0="4/5", omega0=1)
    t = np.linspace(0.0, 40.0, 81)
    code = lindstedt.generate_code(expansion, "displacement", "numpy")
    namespace = {"numpy": np}
    exec(code.source, namespace)  # noqa: S102 - generated by the package under test
    assert np.allclose(namespace[code.function_name](t, 0.05), expansion.displacement(t, 0.05), rtol=0, atol=1e-12)
    assert np.allclose(expansion.lambdify("displacement")(t, 0.05), expansion.displacement(t, 0.05), rtol=0, atol=1e-12)
    assert abs(float(expansion.displacement(0.0, 0.05)) + 0.6) < 1e-3


def test_cache_distinguishes_initial_data_on_one_circle():
    # (3/5, 4/5) and (4/5, 3/5) share A0 = 1 but not the energy of f: A_1, ω_2 differ
    first = lindstedt.expand("u**3", order=2, u0="3/5", v0="4/5", omega0=1)
    second = lindstedt.expand("u**3", order=2, u0="4/5", v0="3/5", omega0=1)
    assert first.problem.a0 == second.problem.a0 == 1
    for expansion, (u0, v0) in ((first, (sympy.Rational(3, 5), sympy.Rational(4, 5))), (second, (sympy.Rational(4, 5), sympy.Rational(3, 5)))):
        assert list(expansion.omega) == duffing_frequency_coefficients(u0, v0, 1, 2)
    assert first.omega[2] != second.omega[2]
    higher = lindstedt.expand("u**3", order=4, u0="3/5", v0="4/5", omega0=1)
    assert list(higher.omega) == duffing_frequency_coefficients(sympy.Rational(3, 5), sympy.Rational(4, 5), 1, 4)
    with pytest.raises(lindstedt.OrderError, match="order="):
        first.omega_correction(first.order + 3)


# --------------------------------------------------------------------------- #
# bad input
# --------------------------------------------------------------------------- #
@pytest.mark.parametrize(
    "arguments, match",
    [
        ({"u0": 0, "v0": 0}, "rest state"),
        ({"u0": 0, "v0": "0.0"}, "rest state"),
        ({"u0": 1, "v0": 1j}, "real"),
        ({"u0": 1, "v0": "nan"}, "finite real number"),
        ({"u0": "x", "v0": 1}, "u0"),
        ({"u0": float("inf"), "v0": 1}, "finite"),
        ({"u0": 1, "v0": 1, "normalization": "harmonic"}, "normalization='initial'"),
        ({"v0": 1, "normalization": "harmonic"}, "normalization='initial'"),
        ({"a0": 1, "u0": 1}, "either a0"),
        ({"a0": 1, "v0": 1}, "either a0"),
        ({"u0": 1, "v0": 1, "a1": "1/2"}, "remove a1"),
    ],
)
def test_bad_initial_data_are_typed_errors_naming_the_fix(arguments, match):
    with pytest.raises(lindstedt.ProblemError, match=match):
        lindstedt.expand("u**3", order=1, omega0=1, **arguments)


@pytest.mark.parametrize(
    "f, u0, v0",
    [("Max(0, u - 1/4)**(3/2)", "3/5", "4/5"), ("Max(0, u)**(3/2)", "3/5", "-1/2"), ("Max(0, u - 1/5)*exp(u)", "1/2", "3/5")],
)
def test_an_orbit_that_starts_on_a_stretched_contact_arc(f, u0, v0):
    # u0 inside a Hertz / analytic contact: the phase comes from the arc's fixed-s expansion (numeric)
    from lindstedt.references import conservative_frequency
    from lindstedt.validate import fitted_convergence_order

    expansion = lindstedt.expand(f, order=2, u0=u0, v0=v0, omega0=1, precision=20)
    epsilons = [0.04, 0.02, 0.01]
    errors = [abs(float(expansion.frequency(e)) - float(conservative_frequency(expansion.problem.nonlinearity, e, a0=u0,
                                                                                velocity=v0, precision=20)[0]))
              for e in epsilons]
    assert np.polyfit(np.log(epsilons), np.log(errors), 1)[0] == pytest.approx(3, abs=0.3)
    assert float(expansion.displacement(0.0, 0.03)) == pytest.approx(float(sympy.Rational(u0)), abs=5e-6)  # O(ε^3)
    fit = fitted_convergence_order(expansion, np.geomspace(0.02, 0.08, 4))
    assert fit.success and fit.slope == pytest.approx(3, abs=0.3)


@pytest.mark.parametrize(
    "argv",
    [
        ["expand", "u**3", "--u0", "0", "--v0", "0"],
        ["expand", "u**3", "--a0", "1", "--v0", "1"],
        ["expand", "u**3", "--u0", "1", "--v0", "1", "--normalization", "harmonic"],
        ["expand", "u**3", "--u0", "1", "--v0", "nan"],
    ],
)
def test_cli_bad_initial_data_print_one_error_line(argv, capsys):
    from lindstedt.cli import main

    assert main(argv) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and captured.out == ""


def test_cli_expands_from_u0_v0(capsys):
    from lindstedt.cli import main

    assert main(["expand", "u**3", "--order", "1", "--omega0", "1", "--u0", "3/5", "--v0", "4/5", "--format", "json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["amplitude"] == ["1", "-136/625"] and data["phase"][0] == "-atan(4/3)"
