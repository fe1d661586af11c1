"""N-dof NNM expansions at scale: the multiprecision modes, the modal coupling and the compiled waveform.

References, all independent of the code under test:

* the uniform chain's closed-form modes, λ_k = 2 sqrt(k_s/m) sin(kπ/(2(N+1))),
  φ_k(i) = sqrt(2/((N+1) m)) sin((i+1)kπ/(N+1));
* a dense mpmath decomposition (Cholesky + ``mpmath.eigsy``) at 80 digits;
* the completeness relation Σ_k (A φ_k)(φ_kᵀ W) = A M⁻¹ W, exact in sympy (it holds for any
  M-orthonormal basis, so also inside a repeated frequency);
* the first-order frequency ω² = λ_j² + ε α_1, α_1 = (2/(π a0)) ∫_0^π Σ_i G_ji (a0 B_ij cos s − b_i)_+ cos s ds,
  by mpmath quadrature split at the contact angles, with the closed-form chain modes;
* at ε = 0 the NNM is the linear mode, U(t) = a0 e_j cos(λ_j t).
"""

import mpmath
import numpy as np
import pytest
import sympy

import lindstedt

DIGITS = 40
TOLERANCE = mpmath.mpf(10) ** (-DIGITS + 2)  # the results are rounded to DIGITS digits


def _chain_mode(size, k, dof, mass=1, stiffness=1):
    """Closed-form λ_k and φ_k(dof) of the uniform chain (k 1-based)."""
    angle = mpmath.pi * k / (size + 1)
    frequency = 2 * mpmath.sqrt(mpmath.mpf(stiffness) / mass) * mpmath.sin(angle / 2)
    return frequency, mpmath.sqrt(mpmath.mpf(2) / ((size + 1) * mpmath.mpf(mass))) * mpmath.sin((dof + 1) * angle)


def test_chain_coupling_matches_the_closed_form_modes():
    size, dofs = 48, (0, 17, 47)
    system = lindstedt.UnilateralSystem.chain(size, unilateral=[(d, 0) for d in dofs], mass="2/3", stiffness=3)
    lambdas, B, G = system.modal_coupling(DIGITS)
    shapes = system.modes().shapes
    with mpmath.workdps(DIGITS + 20):
        for k in range(size):
            frequency, _ = _chain_mode(size, k + 1, 0, mass=mpmath.mpf(2) / 3, stiffness=3)
            assert abs(lambdas[k] / frequency - 1) < TOLERANCE
            largest = int(np.argmax(np.abs(shapes[:, k])))  # the sign convention of modes()
            sign = 1 if shapes[largest, k] * _chain_mode(size, k + 1, largest)[1] > 0 else -1
            for i, dof in enumerate(dofs):
                _, component = _chain_mode(size, k + 1, dof, mass=mpmath.mpf(2) / 3, stiffness=3)
                assert abs(B[i][k] - sign * component) < TOLERANCE
                assert G[k][i] == B[i][k]  # W = Aᵀ


def _general_system():
    """Banded non-diagonal M, an irrational stiffness, W ≠ Aᵀ, two springs."""
    M = [[2, "1/3", 0, 0, 0, 0], ["1/3", 1, "1/5", 0, 0, 0], [0, "1/5", 3, 0, 0, 0], [0, 0, 0, 1, "1/7", 0], [0, 0, 0, "1/7", 2, "1/2"], [0, 0, 0, 0, "1/2", 1]]
    K = [["sqrt(2)", -1, 0, 0, 0, 0], [-1, 3, -1, 0, 0, 0], [0, -1, "5/2", -1, 0, 0], [0, 0, -1, 4, -1, 0], [0, 0, 0, -1, 2, "-1/3"], [0, 0, 0, 0, "-1/3", 1]]
    A = [[1, 0, 0, 0, "1/2", 0], [0, 0, -1, 0, 0, 2]]
    W = [[1, 0], [0, 0], [0, -1], ["1/3", 0], [0, 0], [0, 1]]
    return lindstedt.UnilateralSystem(M=M, K=K, A=A, b=["1/10", 0], W=W)


def _dense_reference(system, digits):
    with mpmath.workdps(digits):
        number = lambda value: mpmath.mpf(sympy.N(value, digits + 5))  # noqa: E731
        mass = mpmath.matrix([[number(v) for v in row] for row in system.M_exact.tolist()])
        stiffness = mpmath.matrix([[number(v) for v in row] for row in system.K_exact.tolist()])
        inverse_lower = mpmath.inverse(mpmath.cholesky(mass))
        eigenvalues, vectors = mpmath.eigsy(inverse_lower * stiffness * inverse_lower.T)
        shapes = inverse_lower.T * vectors
        order = sorted(range(system.n_dof), key=lambda k: eigenvalues[k])
        return [mpmath.sqrt(eigenvalues[k]) for k in order], [[shapes[row, k] for row in range(system.n_dof)] for k in order]


def test_general_banded_system_matches_a_dense_mpmath_decomposition():
    system = _general_system()
    reference_lambdas, reference_shapes = _dense_reference(system, 80)
    lambdas, B, G = system.modal_coupling(DIGITS)
    frequencies, shapes = system.modes_high_precision(DIGITS)
    float_shapes = system.modes().shapes
    with mpmath.workdps(80):
        A = [[mpmath.mpf(sympy.N(v, 90)) for v in row] for row in system.A_exact.tolist()]
        W = [[mpmath.mpf(sympy.N(v, 90)) for v in row] for row in system.W_exact.tolist()]
        for k, column in enumerate(reference_shapes):
            sign = 1 if sum(float(v) * float_shapes[row, k] for row, v in enumerate(column)) > 0 else -1
            assert abs(lambdas[k] - reference_lambdas[k]) < TOLERANCE
            assert abs(frequencies[k] - reference_lambdas[k]) < TOLERANCE
            for row in range(system.n_dof):
                assert abs(shapes[k][row] - sign * column[row]) < TOLERANCE
            for i in range(system.n_springs):
                assert abs(B[i][k] - sign * mpmath.fdot(A[i], column)) < TOLERANCE
                assert abs(G[k][i] - sign * mpmath.fdot(column, [W[row][i] for row in range(system.n_dof)])) < TOLERANCE


@pytest.mark.parametrize(
    "system",
    [
        _general_system(),
        # a repeated frequency (two identical uncoupled oscillators): the dense mpmath fallback
        lindstedt.UnilateralSystem(M=[[1, 0, 0], [0, 1, 0], [0, 0, 2]], K=[[2, 0, 0], [0, 2, 0], [0, 0, 10]], A=[[1, 1, 0], [0, 1, -1]], b=[0, "1/4"]),
    ],
    ids=["banded", "repeated-frequency"],
)
def test_coupling_satisfies_the_exact_completeness_relation(system):
    exact = system.A_exact * system.M_exact.inv() * system.W_exact
    lambdas, B, G = system.modal_coupling(DIGITS)
    assert lambdas == sorted(lambdas)
    with mpmath.workdps(DIGITS + 10):
        for i in range(system.n_springs):
            for l in range(system.n_springs):
                total = mpmath.fsum(B[i][k] * G[k][l] for k in range(system.n_dof))
                assert abs(total - mpmath.mpf(sympy.N(exact[i, l], DIGITS + 20))) < TOLERANCE


def test_repeated_frequency_values():
    system = lindstedt.UnilateralSystem(M=[[1, 0, 0], [0, 1, 0], [0, 0, 2]], K=[[2, 0, 0], [0, 2, 0], [0, 0, 10]], A=[[1, 1, 0]], b=[0])
    lambdas, _, _ = system.modal_coupling(DIGITS)
    with mpmath.workdps(DIGITS):
        assert [abs(value - reference) < TOLERANCE for value, reference in zip(lambdas, [mpmath.sqrt(2), mpmath.sqrt(2), mpmath.sqrt(5)])] == [True] * 3


def _first_order_alpha(size, springs, mode, a0):
    """α_1 by quadrature with the closed-form chain modes (see the module docstring)."""
    total = mpmath.mpf(0)
    for dof, gap in springs:
        _, phi = _chain_mode(size, mode, dof)
        coupling, gap = a0 * phi, mpmath.mpf(gap)
        law = lambda s: max(coupling * mpmath.cos(s) - gap, 0) * mpmath.cos(s)  # noqa: E731
        points = [0, mpmath.pi]
        if abs(gap) < abs(coupling):
            points.insert(1, mpmath.acos(gap / coupling))
        total += phi * mpmath.quad(law, points)
    return 2 * total / (mpmath.pi * a0)


@pytest.mark.parametrize("mode", [1, 40])
def test_first_order_frequency_matches_the_quadrature(mode):
    size, springs = 40, [(0, "1/10"), (20, "-1/20"), (39, 0)]
    system = lindstedt.UnilateralSystem.chain(size, unilateral=springs)
    expansion = lindstedt.nnm(system, mode=mode, a0=1, order=1)
    with mpmath.workdps(40):
        reference = _first_order_alpha(size, [(d, sympy.Rational(g)) for d, g in springs], mode, 1)
        lam, _ = _chain_mode(size, mode, 0)
        assert abs(expansion.alpha[1] - reference) < mpmath.mpf(10) ** -26 * abs(reference)
        assert abs(expansion.omega[1] - reference / (2 * lam)) < mpmath.mpf(10) ** -26 * abs(reference / lam)
        assert abs(expansion.omega[0] - lam) < mpmath.mpf(10) ** -28


def test_compiled_waveform_is_the_linear_mode_at_zero_epsilon_and_broadcasts_over_epsilon():
    size, mode = 30, 4
    system = lindstedt.UnilateralSystem.chain(size, unilateral=[(0, "1/10"), (15, "-1/20"), (29, 0)])
    expansion = lindstedt.nnm(system, mode=mode, a0=0.5, order=2)
    times = np.linspace(0.0, 40.0, 9)
    linear = np.zeros((times.size, size))
    linear[:, mode - 1] = 0.5 * np.cos(float(_chain_mode(size, mode, 0)[0]) * times)
    assert np.max(np.abs(expansion.modal_displacement(times, 0.0) - linear)) < 1e-14
    epsilons = np.array([0.0, 0.002, 0.005])
    table = expansion.modal_displacement(times[None, :], epsilons[:, None])
    assert table.shape == (3, times.size, size)
    for row, epsilon in enumerate(epsilons):
        assert np.array_equal(table[row], expansion.modal_displacement(times, epsilon))
    physical = expansion.displacement(times, 0.005)
    assert np.allclose(physical, expansion.modal_displacement(times, 0.005) @ system.modes().shapes.T, rtol=0, atol=1e-15)
    assert np.allclose(expansion.displacement(0.0, 0.005), expansion.release_state(0.005), rtol=0, atol=1e-12)


@pytest.mark.parametrize("digits", [0, -3, 2.5, True, "30"])
def test_bad_digits_raise_typed_errors(digits):
    system = lindstedt.UnilateralSystem.chain(3, unilateral=[(0, 0)])
    with pytest.raises(lindstedt.ProblemError, match="digits must be a positive integer"):
        system.modal_coupling(digits)
    with pytest.raises(lindstedt.ProblemError, match="digits must be a positive integer"):
        system.modes_high_precision(digits)


@pytest.mark.slow
@pytest.mark.parametrize("mode", [1, 60])
def test_sixty_masses_second_order_matches_shooting(mode):
    """ω(ε) − (ω_0 + ω_1 ε + ω_2 ε²) against the periodic orbit of the exact flow falls as ε³."""
    system = lindstedt.UnilateralSystem.chain(60, unilateral=[(0, 0.1), (30, -0.05), (59, 0.0)])
    expansion = lindstedt.nnm(system, mode=mode, a0=1.0, order=2)
    omega = [float(value) for value in expansion.omega]
    epsilons = np.geomspace(0.004, 0.016, 3) * omega[0] ** 2
    residuals = []
    for epsilon in epsilons:
        point = lindstedt.nnm_point(system, epsilon, mode, modal_amplitude=1.0)
        assert point.success, point.message
        residuals.append(abs(point.frequency - (omega[0] + omega[1] * epsilon + omega[2] * epsilon**2)))
    assert np.polyfit(np.log(epsilons), np.log(residuals), 1)[0] == pytest.approx(3, abs=0.3)
