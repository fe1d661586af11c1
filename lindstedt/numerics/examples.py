"""The seed's worked example: an N-dof chain ``M X'' + K X + ε W (A X − b)_+ = 0`` with ``W = M φ_1``.

Unit masses and unit springs with both ends fixed, and one unilateral spring on
the first mass whose force acts along the lowest mode shape, so that
``F(X) = (X_1 − β_1)_+ M φ_1`` (:func:`seed_example_system`).  The coupling is
non-symmetric (``W ≠ Aᵀ``): only the first modal coordinate is nonlinear, which
gives closed-form checks of the shooting (the NNM of mode 1 is a one-dof
bilinear oscillator; the NNM of a mode j ≠ 1 keeps the frequency λ_j).

Examples
--------
>>> system = seed_example_system(3)
>>> system.n_dof, system.n_springs, system.symmetric_coupling
(3, 1, False)
"""

from __future__ import annotations

import numpy as np

from .._errors import ProblemError
from ..problems.system import UnilateralSystem

__all__ = ["seed_example_system"]


def seed_example_system(n_dof: int, gap: float = 0.0) -> UnilateralSystem:
    """The seed's N-dof example: a chain with the nonlinearity ``F(X) = (X_1 − β_1)_+ M φ_1``.

    Unit masses and unit springs, both ends fixed (``M = I``, ``K`` tridiagonal
    (2, −1)); one unilateral spring on the first mass, written as a
    :class:`UnilateralSystem` with ``A = e_1ᵀ`` (the first mass's
    displacement), gap ``b = β_1 = gap`` and force distribution
    ``W = M φ_1`` (one column; ``φ_1`` the lowest mode shape, M-normalised,
    positive).  So ``W ≠ Aᵀ``: the coupling is non-symmetric and the system
    has no conserved energy.  In modal coordinates (``X = Φ u``) it reads::

        u_1'' + λ_1² u_1 + ε (Σ_k Φ_1k u_k − β_1)_+ = 0,     u_k'' + λ_k² u_k = 0  (k ≠ 1)

    so only ``u_1`` is nonlinear: the NNM of mode 1 is the one-dof oscillator
    ``u'' + λ_1² u + ε Φ_11 (u − β_1/Φ_11)_+ = 0`` (all other ``u_k = 0``) and the
    NNM of a mode j ≠ 1 keeps ``u_j = a cos(λ_j t)`` exactly, so its frequency is
    exactly ``λ_j`` for every ε, ``u_1`` being the T-periodic forced response.

    The seed does not print β_1; the default ``gap = 0`` (the case b = 0 of its
    Corollary 4.2) is used for its examples here.  With ``gap = 0`` the force is
    positively homogeneous, so the NNM frequency depends on ε only, not on the
    amplitude (energy).

    Parameters
    ----------
    n_dof : int
        Number of masses N ≥ 1.
    gap : float, optional
        β_1 (default 0).

    Examples
    --------
    >>> system = seed_example_system(5)
    >>> system.n_dof, system.symmetric_coupling
    (5, False)
    >>> lam, phi = system.modes()
    >>> bool(np.allclose(phi.T @ system.W[:, 0], [1, 0, 0, 0, 0], atol=1e-15))
    True
    """
    if isinstance(n_dof, bool) or not isinstance(n_dof, (int, np.integer)) or n_dof < 1:
        raise ProblemError(f"n_dof must be a positive integer, got {n_dof!r}")
    chain = UnilateralSystem.chain(int(n_dof))
    shape = chain.modes().shapes[:, 0]
    mass = np.asarray(chain.M, dtype=float)
    row = [[1] + [0] * (int(n_dof) - 1)]
    column = (mass @ shape).reshape(-1, 1).tolist()
    return UnilateralSystem(M=chain.M_exact, K=chain.K_exact, A=row, b=[gap], W=column)
