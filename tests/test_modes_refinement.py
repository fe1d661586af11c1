"""The multiprecision refinement of the linear modes at the sizes where its representations change (issue 26).

A chain's bands have constant diagonals: its modes are refined as packed integers, block by block (128 modes), from
LAPACK's MRRR float modes past 256 dof; a consistent-mass chain has a non-identity M with constant diagonals.
Reference, independent of the code under test: the closed-form modes of a Toeplitz tridiagonal pencil
``K = k_s tridiag(−1, 2, −1)``, ``M = (m/6) tridiag(1, 4, 1)`` (or ``m I``): φ_k(i) ∝ sin((i+1)α_k),
α_k = kπ/(N+1), λ_k² = k_s (2 − 2 cos α_k) / (m (4 + 2 cos α_k)/6) (or ``/ m``), normalised by
φᵀMφ = 1 with Σ_i sin²((i+1)α_k) = (N+1)/2.
"""

import mpmath
import numpy as np
import sympy

import lindstedt

DIGITS = 40
TOLERANCE = mpmath.mpf(10) ** (-DIGITS + 2)  # the results are rounded to DIGITS digits


def _closed_form(size, k, dof, consistent):
    """λ_k and φ_k(dof) (k 1-based) of the unit chain, lumped (m I) or consistent mass (tridiag(1, 4, 1)/6)."""
    angle = mpmath.pi * k / (size + 1)
    mass = (4 + 2 * mpmath.cos(angle)) / 6 if consistent else mpmath.mpf(1)  # the Rayleigh quotient's denominator
    frequency = mpmath.sqrt((2 - 2 * mpmath.cos(angle)) / mass)
    return frequency, mpmath.sqrt(2 / ((size + 1) * mass)) * mpmath.sin((dof + 1) * angle)


def _check(system, size, dofs, consistent):
    lambdas, B, G = system.modal_coupling(DIGITS)
    shapes = system.modes().shapes
    with mpmath.workdps(DIGITS + 20):
        for k in range(size):
            frequency, _ = _closed_form(size, k + 1, 0, consistent)
            assert abs(lambdas[k] / frequency - 1) < TOLERANCE
            largest = int(np.argmax(np.abs(shapes[:, k])))  # the sign convention of modes()
            sign = 1 if shapes[largest, k] * _closed_form(size, k + 1, largest, consistent)[1] > 0 else -1
            for i, dof in enumerate(dofs):
                assert abs(B[i][k] - sign * _closed_form(size, k + 1, dof, consistent)[1]) < TOLERANCE
                assert G[k][i] == B[i][k]  # W = Aᵀ


def test_a_300_mass_chain_in_three_blocks_matches_the_closed_form_modes():
    size, dofs = 300, (0, 150, 299)
    _check(lindstedt.UnilateralSystem.chain(size, unilateral=[(d, 0) for d in dofs]), size, dofs, consistent=False)


def test_a_consistent_mass_chain_matches_the_closed_form_modes():
    size, dofs = 40, (0, 13)
    sixth, two_thirds = sympy.Rational(1, 6), sympy.Rational(2, 3)
    M = [[two_thirds if i == j else sixth if abs(i - j) == 1 else 0 for j in range(size)] for i in range(size)]
    K = [[2 if i == j else -1 if abs(i - j) == 1 else 0 for j in range(size)] for i in range(size)]
    A = [[1 if j == dof else 0 for j in range(size)] for dof in dofs]
    _check(lindstedt.UnilateralSystem(M=M, K=K, A=A, b=[0] * len(dofs)), size, dofs, consistent=True)
