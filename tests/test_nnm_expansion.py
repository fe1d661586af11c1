"""NNM by strained coordinates (Theorem 4.1 derived) against numerical NNMs from shooting on the exact flow."""

import json

import numpy as np
import pytest
import sympy
from scipy.optimize import root

import lindstedt
from lindstedt import ProblemError, ResonanceError, UnilateralSystem
from lindstedt.cli import main
from lindstedt.numerics import ExactFlow
from lindstedt.references import release_amplitudes_by_series

EPSILONS = np.geomspace(0.0005, 0.004, 8)  # in units of λ_j² (the small parameter is ε/λ_j²)
#: the a_k are compared to within this many times the reference's own error estimate (propagated + truncation)
SAFETY = 3.0
#: resolving power demanded of the reference: its error bound on a_k below this fraction of max(1, |a_k|)
RESOLUTION = 1e-5
_UNIT_ROUNDOFF = np.finfo(float).eps


def numerical_nnm(system, mode, a0, epsilon, guess_others, guess_period):
    """Periodic orbit released from rest with modal amplitude a0 of `mode`: X'(T/2) = 0 (time-reversal symmetry).

    Returns the frequency, the other modal amplitudes and a first-order bound on their error,
    |J⁻¹| (|r| + η): r is the final residual, J its exact Jacobian (the flow's sensitivity and the
    acceleration at T/2) and η the rounding of the residual's evaluation, i.e. the double-precision
    release state X0 = Φ q (one unit roundoff of |Φ| |q|) and half period propagated through the flow
    (which carries its state in extended precision).  Random probes of F(u ± δ) − F(u) ∓ J δ stay
    below this η (at most 0.7 η on the 5- and 20-mass chains).
    """
    shapes = system.modes().shapes
    size = system.n_dof
    others = [k for k in range(size) if k != mode]
    flow = ExactFlow(system, epsilon)

    def modal_release(unknowns):
        modal = np.zeros(size)
        modal[mode] = a0
        modal[others] = unknowns[:-1]
        return modal

    def residual(unknowns):
        return flow.flow_map(shapes @ modal_release(unknowns), np.zeros(size), unknowns[-1] / 2).velocity

    def linearisation(unknowns):
        out = flow.flow_map(shapes @ modal_release(unknowns), np.zeros(size), unknowns[-1] / 2, sensitivity=True)
        velocity_by_position = out.sensitivity[size:, :size]
        half_period_rate = system.acceleration(out.position, epsilon) / 2
        jacobian = np.column_stack([velocity_by_position @ shapes[:, others], half_period_rate])
        rounding = np.abs(velocity_by_position) @ (_UNIT_ROUNDOFF * (np.abs(shapes) @ np.abs(modal_release(unknowns))))
        rounding += _UNIT_ROUNDOFF * abs(unknowns[-1]) * np.abs(half_period_rate)
        return jacobian, out.velocity, rounding

    solution = root(
        residual, np.r_[guess_others, guess_period], jac=lambda unknowns: linearisation(unknowns)[0], method="hybr", tol=1e-15
    )
    unknowns = solution.x
    jacobian, final, rounding = linearisation(unknowns)
    for _ in range(2):  # Newton polish with the exact Jacobian, kept while it lowers the residual
        candidate = unknowns - np.linalg.solve(jacobian, final)
        polished = linearisation(candidate)
        if not np.max(np.abs(polished[1])) < np.max(np.abs(final)):
            break
        unknowns, (jacobian, final, rounding) = candidate, polished
    assert np.max(np.abs(final)) < 1e-11
    error = np.abs(np.linalg.inv(jacobian)) @ (np.abs(final) + rounding)
    return 2 * np.pi / unknowns[-1], unknowns[:-1], error[:-1]


def intercept_with_error(epsilons, ratios, errors, degree=5):
    """a = lim_{ε→0} ratios(ε) by a least-squares polynomial of `degree` in ε, with its error estimate.

    propagated: |row of the pseudo-inverse| @ errors (the data's own error bounds through the fit);
    truncation: difference from the intercept of the fit of one degree lower (an overestimate for
    the higher degree while the series converges).  Returns (intercept, propagated, truncation).
    """
    scaled = epsilons / np.max(epsilons)  # keeps the Vandermonde matrix well conditioned
    weights = {d: np.linalg.pinv(np.vander(scaled, d + 1, increasing=True))[0] for d in (degree - 1, degree)}
    intercept = weights[degree] @ ratios
    return intercept, np.abs(weights[degree]) @ errors, np.abs(intercept - weights[degree - 1] @ ratios)


def check_against_shooting(system, mode, a0=1.0):
    expansion = lindstedt.nnm(system, mode=mode + 1, a0=a0, order=2)
    omega = np.array([float(value) for value in expansion.omega])
    a_k = np.array([float(value) for value in expansion.a_k])
    # the natural small parameter is ε/λ_j² (the stiffness ratio): scale the grid with it
    epsilons = EPSILONS * omega[0] ** 2
    # ε = 0: the linear mode itself; its other amplitudes q_k(0) are the rounding of the double-precision
    # mode shapes (≈ 1e-15), a constant that q_k(ε)/ε would amplify by 1/ε, so it is subtracted
    _, offset, offset_error = numerical_nnm(system, mode, a0, 0.0, np.zeros(len(a_k)), 2 * np.pi / omega[0])
    frequencies, ratios, errors = [], [], []
    for epsilon in epsilons:
        frequency, modal, error = numerical_nnm(system, mode, a0, epsilon, epsilon * a_k, 2 * np.pi / (omega[0] + epsilon * omega[1]))
        frequencies.append(frequency)
        ratios.append((modal - offset) / epsilon)
        errors.append((error + offset_error) / epsilon)
    frequencies = np.array(frequencies)
    # fit ω(ε) − λ_j = ω1 ε + ω2 ε² + c3 ε³ + … + c5 ε⁵ over the small ε
    design = np.vstack([epsilons**power for power in range(1, 6)]).T
    fitted = np.linalg.lstsq(design, frequencies - omega[0], rcond=None)[0]
    # compared in the dimensionless form Ω_n = ω_n λ_j^(2n−1) (ε/λ_j² is the small parameter)
    for n in (1, 2):
        scale = omega[0] ** (2 * n - 1)
        assert fitted[n - 1] * scale == pytest.approx(omega[n] * scale, abs=1e-6)
    residuals = np.abs(frequencies - (omega[0] + omega[1] * epsilons + omega[2] * epsilons**2))
    slope = np.polyfit(np.log(epsilons), np.log(residuals), 1)[0]
    assert slope == pytest.approx(3, abs=0.25)
    # q_k(ε)/ε = a_k + b_k ε + c_k ε² + …: intercept of a quintic fit over the same ε, to within SAFETY times
    # the reference's own error estimate (shooting error through the fit + truncation of the fit)
    intercepts, propagated, truncation = intercept_with_error(epsilons, np.array(ratios), np.array(errors))
    tolerance = SAFETY * (propagated + truncation)
    # the estimate must leave the comparison able to resolve a relative error of RESOLUTION in a_k
    assert np.max(tolerance) < RESOLUTION * max(1.0, np.max(np.abs(a_k)))
    assert np.all(np.abs(intercepts - a_k) <= tolerance), (intercepts - a_k, propagated, truncation)


@pytest.mark.parametrize(
    "size, springs",
    [
        (2, [(0, 0.0)]),
        (2, [(1, 0.3)]),
        (3, [(0, 0.2), (2, -0.1)]),
        (5, [(0, 0.0), (3, -0.2)]),
    ],
)
def test_chain_every_mode_matches_shooting(size, springs):
    system = UnilateralSystem.chain(size, unilateral=springs)
    for mode in range(size):
        check_against_shooting(system, mode)


@pytest.mark.slow
def test_twenty_masses_every_mode_matches_shooting():
    system = UnilateralSystem.chain(20, unilateral=[(0, 0.1), (10, -0.05), (19, 0.0)])
    for mode in range(20):
        check_against_shooting(system, mode)


def test_twenty_masses_two_modes_match_shooting():
    system = UnilateralSystem.chain(20, unilateral=[(0, 0.1), (10, -0.05), (19, 0.0)])
    for mode in (0, 19):
        check_against_shooting(system, mode)


@pytest.mark.parametrize("stiffness, gap, release, omega0", [(1, 0, 1, 1), ("17/10", "3/10", "13/10", "11/10"), (2, "-1/4", "-3/5", "1/2")])
def test_one_dof_limit_reproduces_the_scalar_engine(stiffness, gap, release, omega0):
    system = UnilateralSystem(M=[[1]], K=[[f"({omega0})**2" if isinstance(omega0, str) else omega0**2]], A=[[1]], b=[gap], W=[[stiffness]])
    result = lindstedt.nnm(system, mode=1, a0=release, order=3)
    scalar = lindstedt.expand(f"({stiffness})*Max(0, u - ({gap}))", order=3, a0=release, omega0=omega0, numeric=True)
    for ours, theirs in zip(result.omega, scalar.omega):
        assert float(ours) == pytest.approx(float(theirs), rel=1e-20, abs=1e-25)


@pytest.mark.parametrize(
    "springs, mode, amplitude",
    [
        ([(0, 0.0)], 2, 0.8),
        pytest.param([(0, 0.2), (2, -0.1)], 1, 1.0, marks=pytest.mark.slow),
        pytest.param([(1, 0.05)], 3, -0.7, marks=pytest.mark.slow),
    ],
)
def test_a_k_match_the_fourier_series_of_corollary_4_2(springs, mode, amplitude):
    # independent route: the Fourier series of the contact functions summed with acceleration
    system = UnilateralSystem.chain(3, unilateral=springs)
    result = lindstedt.nnm(system, mode=mode, a0=amplitude, order=1)
    series = release_amplitudes_by_series(system, mode, amplitude)
    for (value, error), closed_form in zip(series, result.a_k):
        assert error < 1e-12
        assert float(value) == pytest.approx(float(closed_form), rel=1e-11, abs=1e-13)


def test_internal_resonance_raises_and_near_resonance_is_reported():
    resonant = UnilateralSystem(M=[[1, 0], [0, 1]], K=[[1, 0], [0, 4]], A=[[1, 1]], b=[0])
    with pytest.raises(ResonanceError, match="harmonic 2"):
        lindstedt.nnm(resonant, mode=1, a0=1)
    assert len(lindstedt.nnm(resonant, mode=2, a0=1).omega) == 3  # mode 2: λ1/λ2 = 1/2 is not an integer
    near = UnilateralSystem(M=[[1, 0], [0, 1]], K=[[1, 0], [0, "4.00004"]], A=[[1, 1]], b=["1/10"])
    result = lindstedt.nnm(near, mode=1, a0=1)
    (mode, harmonic, divisor), = result.small_divisors
    assert (mode, harmonic) == (2, 2) and divisor == pytest.approx(4e-5, rel=1e-3)
    reference = lindstedt.nnm(near, mode=1, a0=1, precision=60)
    for ours, accurate in zip(result.omega, reference.omega):
        assert abs(float(ours) - float(accurate)) <= 1e-12 * max(1.0, abs(float(accurate)))


def test_validity_reports_root_multiplicity():
    system = UnilateralSystem.chain(2, unilateral=[(0, 0.1)])
    shapes = system.modes().shapes
    simple = lindstedt.nnm(system, mode=1, a0=1)
    assert simple.spring_roots == ("simple",) and simple.validity_exponent == -1
    grazing_amplitude = 0.1 / shapes[0, 0]
    grazing = lindstedt.nnm(system, mode=1, a0=grazing_amplitude)
    assert grazing.spring_roots == ("double",) and str(grazing.validity_exponent) == "-1/2"
    free = lindstedt.nnm(system, mode=1, a0=grazing_amplitude / 2)
    assert free.spring_roots == ("none",)
    assert [float(value) for value in free.omega[1:]] == [0.0, 0.0]


def test_json_and_cli(tmp_path, capsys):
    path = tmp_path / "system.json"
    path.write_text(json.dumps({"M": [[1, 0], [0, 1]], "K": [[2, -1], [-1, 2]], "A": [[1, 0]], "b": ["1/10"]}))
    assert main(["nnm", str(path), "--mode", "1", "--a0", "1", "--format", "json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert set(data) >= {"lambda", "omega", "a_k", "validity"}
    assert data["lambda"] == pytest.approx([1.0, 3**0.5], rel=1e-15)
    assert len(data["omega"]) == 3 and len(data["a_k"]) == 1
    assert main(["nnm", str(path), "--mode", "3", "--a0", "1"]) == 2
    assert "mode must be" in capsys.readouterr().err
    assert main(["nnm", str(tmp_path / "missing.json"), "--mode", "1", "--a0", "1"]) == 2


@pytest.mark.parametrize(
    "kwargs, fragment",
    [
        ({"M": [[1, 2], [0, 1]], "K": [[1, 0], [0, 1]], "A": [[1, 0]], "b": [0]}, "symmetric"),
        ({"M": [[1, 0], [0, 1]], "K": [[1, 0], [0, -1]], "A": [[1, 0]], "b": [0]}, "positive definite"),
        ({"M": [[1, 0], [0, 1]], "K": [[1, 0], [0, 2]], "A": [[1, 0, 0]], "b": [0]}, "A"),
    ],
)
def test_bad_systems_raise_typed_errors(kwargs, fragment):
    with pytest.raises(ProblemError, match=fragment):
        UnilateralSystem(**kwargs)


def test_bad_nnm_arguments():
    system = UnilateralSystem.chain(2, unilateral=[(0, 0)])
    with pytest.raises(ProblemError, match="mode"):
        lindstedt.nnm(system, mode=0, a0=1)
    with pytest.raises(ProblemError, match="a0 = 0"):
        lindstedt.nnm(system, mode=1, a0=0)


@pytest.mark.parametrize("mode", [1, 2])
def test_nnm_waveform_error_is_second_order_over_one_over_epsilon(mode):
    # Theorem 4.1: X(t) = Φ[v⁰ + ε v¹](ω t) + O(ε²) on t ≤ C/ε, released at the expansion's own release state
    system = UnilateralSystem.chain(3, unilateral=[(0, 0.1), (2, -0.05)])
    expansion = lindstedt.nnm(system, mode=mode, a0=1.0, order=2)
    scale = float(expansion.omega[0]) ** 2
    epsilons = np.geomspace(0.01, 0.04, 4) * scale
    errors = []
    for epsilon in epsilons:
        times = np.linspace(0, 1 / epsilon, 3000)
        exact, _ = ExactFlow(system, epsilon).solve(expansion.release_state(epsilon), np.zeros(3), times[-1]).state(times)
        errors.append(np.max(np.abs(expansion.displacement(times, epsilon) - exact)))
    assert np.polyfit(np.log(epsilons), np.log(errors), 1)[0] == pytest.approx(2, abs=0.3)


def test_nnm_problem_is_validated_and_kept_by_its_result():
    chain = UnilateralSystem.chain(2, unilateral=[(0, 0.0)])
    problem = lindstedt.NNMProblem(chain, mode=2, a0="3/4", a1=0.5)
    assert problem.a0 == sympy.Rational(3, 4) and problem.a1 == sympy.Rational(1, 2)
    result = lindstedt.StrainedCoordinatesNNM(precision=30).expand(problem, order=2)
    assert result.problem is problem and result.system is chain and result.mode == 2 and result.a0 == 0.75
    assert result.omega == lindstedt.nnm(chain, mode=2, a0="3/4", a1=0.5, order=2).omega
    for bad in ({"mode": 0}, {"mode": 3}, {"mode": True}, {"a0": 0}, {"a0": "nan"}, {"a1": "x"}):
        with pytest.raises(ProblemError):
            lindstedt.NNMProblem(**{"system": chain, "mode": 1, "a0": 1, **bad})
    with pytest.raises(ProblemError):
        lindstedt.NNMProblem("system.json", mode=1, a0=1)
