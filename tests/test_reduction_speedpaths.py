"""ResidualFlexibility on spectra that stress its iteration: double eigenvalues, a consistent (banded) mass
matrix, a two-dimensional mesh with a wider band, many modes.  Every reference is closed form: the modes of
``tridiag(−1, 2, −1)`` are sines, ``λ_k = 4 sin²(kπ / 2(n + 1))``, and a mass matrix ``tridiag(1, 4, 1)/6``
shares them (``μ_k = (2 + cos(kπ/(n + 1)))/3``), as a grid's Laplacian shares the products of two chains' sines."""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
import scipy.sparse
import sympy

import lindstedt
from lindstedt import ResidualFlexibility, UnilateralSystem


def _second_difference(n: int) -> scipy.sparse.csr_matrix:
    return scipy.sparse.diags([-np.ones(n - 1), 2 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1], format="csr")


def _sine_values(n: int) -> list:
    with mpmath.workdps(50):
        return [4 * mpmath.sin(k * mpmath.pi / (2 * (n + 1))) ** 2 for k in range(1, n + 1)]


def _assert_frequencies(reduced, eigenvalues: list) -> None:
    assert reduced.success, reduced.message
    reference = sorted(eigenvalues)[:reduced.modes]
    with mpmath.workdps(50):
        for frequency, value in zip(reduced.frequencies, reference):
            # the frequencies are rounded to the 30 digits asked for
            assert abs(frequency - mpmath.sqrt(value)) < 1e-29 * mpmath.sqrt(value)


def test_double_eigenvalues_of_two_identical_chains():
    # two uncoupled 30-mass chains: every eigenvalue is double, the Ritz problems hold exact pairs
    n = 30
    K = scipy.sparse.block_diag([_second_difference(n)] * 2, format="csr")
    A = np.zeros((1, 2 * n))
    A[0, 5] = 1
    reduced = ResidualFlexibility(modes=4).reduce((scipy.sparse.identity(2 * n, format="csr"), K), A=A)
    _assert_frequencies(reduced, _sine_values(n) * 2)
    assert reduced.system.n_dof == 5


def test_consistent_mass_matrix_shares_the_sines():
    # M = tridiag(1, 4, 1)/6 (linear elements' consistent mass), K = tridiag(−1, 2, −1): λ_k = 4 sin² / μ_k
    n = 60
    M = sympy.zeros(n, n)
    K = sympy.zeros(n, n)
    for i in range(n):
        M[i, i], K[i, i] = sympy.Rational(2, 3), 2
        if i + 1 < n:
            M[i, i + 1] = M[i + 1, i] = sympy.Rational(1, 6)
            K[i, i + 1] = K[i + 1, i] = -1
    A = sympy.zeros(1, n)
    A[0, n // 3] = 1
    reduced = ResidualFlexibility(modes=6).reduce((M, K), A=A)
    with mpmath.workdps(50):
        values = [4 * mpmath.sin(k * mpmath.pi / (2 * (n + 1))) ** 2 / ((2 + mpmath.cos(k * mpmath.pi / (n + 1))) / 3)
                  for k in range(1, n + 1)]
    _assert_frequencies(reduced, values)


def test_square_grid_with_a_wider_band_and_double_eigenvalues():
    # the 5-point Laplacian of an 8×8 grid (half-bandwidth 8 after reordering): λ = λ_i + λ_j, λ_i = λ_j doubles
    n = 8
    chain = _second_difference(n)
    identity = scipy.sparse.identity(n, format="csr")
    K = (scipy.sparse.kron(chain, identity) + scipy.sparse.kron(identity, chain)).tocsr()
    A = np.zeros((1, n * n))
    A[0, 2 * n + 3] = 1
    reduced = ResidualFlexibility(modes=5).reduce((scipy.sparse.identity(n * n, format="csr"), K), A=A)
    single = _sine_values(n)
    with mpmath.workdps(50):
        values = [a + b for a in single for b in single]
    _assert_frequencies(reduced, values)
    assert reduced.bandwidth >= n - 1


def test_many_modes_of_a_chain_converge():
    # 20 of a 40-mass chain's modes: the top ones converge slowly (a factor ≈ 9 a step in the Ritz values)
    chain = UnilateralSystem.chain(40, unilateral=[(10, 0)])
    reduced = ResidualFlexibility(modes=20).reduce((chain.M_exact, chain.K_exact), A=chain.A_exact)
    _assert_frequencies(reduced, _sine_values(40))


def test_residual_vectors_are_signed_like_the_modes():
    # every basis column (modes and residual vectors) has its first entry of largest magnitude positive
    system = UnilateralSystem.chain(50, unilateral=[(0, sympy.Rational(1, 10)), (25, -sympy.Rational(1, 20)), (49, 0)])
    reduced = ResidualFlexibility(modes=4).reduce((system.M_exact, system.K_exact), A=system.A_exact,
                                                  b=list(system.b_exact))
    basis = reduced.basis
    assert basis.shape == (50, reduced.system.n_dof) and reduced.system.n_dof > 4
    for column in basis.T:
        leading = np.flatnonzero(np.abs(column) >= np.max(np.abs(column)) * (1 - 1e-9))[0]
        assert column[leading] > 0


@pytest.mark.parametrize("modes", [2, 6])
def test_reduced_kept_mode_matches_the_full_chain(modes):
    # ω₀ and ω₁ of the first NNM of a cubic-spring chain: the full 24-dof model's against the reduced model's
    full = UnilateralSystem.chain(24, unilateral=[(6, 0)], elements=[(16, None, "u**3")])
    reference = lindstedt.nnm(full, 1, a0=1, order=1).omega
    reduced = ResidualFlexibility(modes=modes).reduce((full.M_exact, full.K_exact), A=full.A_exact,
                                                      laws=list(full.laws))
    omega = lindstedt.nnm(reduced.system, 1, a0=1, order=1).omega
    for value, expected in zip(omega, reference):
        assert abs(value - expected) < 1e-27 * abs(expected)
