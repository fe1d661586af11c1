"""The one damped Newton of the periodic-orbit core: solve ``G(z) = 0`` for every orbit problem of the package.

Every periodic orbit is a zero of a residual ``G(z)`` with an exact Jacobian: the NNM shooting residual
(:class:`~lindstedt.numerics.shooting.NNMShooting`, unknowns ``(X0, T)`` or ``(X0, X1, T)``), the fixed point
``Π(z) − z`` of a forced period map, and either one augmented by the pseudo-arclength constraint
``tᵀ(w − w_k) − h`` (:mod:`lindstedt.numerics.arclength`).  :func:`newton` solves them all:

* the step ``Δ`` solves ``J Δ = −G`` in least squares with the columns scaled by the typical magnitudes of
  the unknowns (Gauss–Newton for a non-square J); a scaled Jacobian with ``σ_min/σ_max < 1e-13`` is singular
  (a fold, a bifurcation or a degenerate amplitude) and ends the solve with the evaluation's own words;
* the step is capped to the evaluation's trust bound (a stiff law can make the flow explode far out) and
  halved until the residual decreases (``max_backtracks`` times; ``accept_last=True`` takes the last halving
  anyway and goes on — the forced fixed point, whose period map has no finer scale to fall back on);
* convergence: ``max|G| ≤ tol`` (the residual rows are scaled by the problem), or a full scaled step
  ``≤ step_tol`` (quadratic convergence puts the next residual far below ``tol``; the caller verifies).

Examples
--------
>>> import numpy as np
>>> outcome = newton(lambda z: Evaluation(True, "", np.array([z[0]**2 - 2.0]), np.array([[2 * z[0]]])),
...                  np.array([1.0]), np.array([1.0]), tol=1e-15, max_iterations=20)
>>> outcome.success, abs(float(outcome.unknowns[0]) - 2**0.5) < 1e-15
(True, True)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from ..limits import checkpoint

__all__ = ["Evaluation", "NewtonOutcome", "newton", "scaled_solve"]

#: a scaled Jacobian whose σ_min/σ_max is below this is singular
SINGULAR_RATIO = 1e-13


@dataclass
class Evaluation:
    """One evaluation of a residual: rows scaled by the problem (``max|residual| ≤ tol`` is convergence).

    ``jacobian`` has the unscaled unknowns as columns; ``step_bound`` caps ``max|Δ|`` of a Newton step from
    this point (a trust region); ``data`` carries what the problem wants back (a period map, a flow's switches).
    """

    success: bool
    message: str
    residual: np.ndarray | None = None
    jacobian: np.ndarray | None = None
    step_bound: float = math.inf
    data: Any = None
    singular: str = ("a fold of the branch in this parameter, a bifurcation (internal resonance λ_k/ω ∈ ℤ) or a "
                     "degenerate amplitude — continue the branch with pseudo-arclength (continue_nnm) or change the "
                     "parameter")

    @property
    def norm(self) -> float:
        return float(np.max(np.abs(self.residual))) if self.residual is not None and self.residual.size else 0.0


@dataclass
class NewtonOutcome:
    """The end of a solve: the unknowns, the last evaluation (its Jacobian serves for tangents) and the scaled
    sizes of the full Newton steps in order (the first one is a predictor's error; their ratios the contraction)."""

    success: bool
    message: str
    unknowns: np.ndarray
    iterations: int
    last: Evaluation | None = None
    steps: tuple[float, ...] = ()


def scaled_solve(matrix: np.ndarray, rhs: np.ndarray, columns: np.ndarray,
                 allow_singular: bool = False) -> tuple[np.ndarray | None, float]:
    """Least-squares solve of ``matrix · Δ = rhs`` with column scaling; ``(Δ, σ_min/σ_max)``, Δ None if singular
    (unless ``allow_singular``: then the minimum-norm step, which has no component along the null space)."""
    scaled = matrix * columns[None, :]
    if not np.all(np.isfinite(scaled)):
        return None, 0.0
    singular_values = np.linalg.svd(scaled, compute_uv=False)
    ratio = float(singular_values[-1] / singular_values[0]) if singular_values[0] > 0 else 0.0
    if ratio < SINGULAR_RATIO and not allow_singular:
        return None, ratio
    step = np.linalg.lstsq(scaled, rhs, rcond=None)[0]
    return step * columns, ratio


def newton(
    evaluate: Callable[[np.ndarray], Evaluation],
    unknowns: np.ndarray,
    columns: np.ndarray,
    *,
    tol: float,
    max_iterations: int,
    step_tol: float | None = None,
    max_backtracks: int = 5,
    accept_last: bool = False,
    allow_singular: bool = False,
    first: Evaluation | None = None,
) -> NewtonOutcome:
    """Damped (Gauss–)Newton on a scaled residual; see the module docstring.

    Parameters
    ----------
    evaluate : callable
        ``evaluate(z) -> Evaluation`` (residual and Jacobian at z).
    unknowns, columns : ndarray
        The start and the typical magnitudes of the unknowns (the steps are measured and solved in ``Δ/columns``).
    tol, max_iterations : float, int
        Convergence ``max|G| ≤ tol``; at most this many Newton steps.
    step_tol : float, optional
        Also converged when a full scaled step is at most this (the caller verifies the final state).
    max_backtracks : int
        Halvings of a step that does not decrease the residual.
    accept_last : bool
        Keep the last halving even when the residual did not decrease (else the solve fails).
    allow_singular : bool
        Take the minimum-norm step where the scaled Jacobian is singular (solving on a singular point on
        purpose: a branch point being located), instead of failing.
    first : Evaluation, optional
        The evaluation at ``unknowns`` when the caller already has it.

    Returns
    -------
    NewtonOutcome

    Examples
    --------
    The intersection of the unit circle with the line ``z0 = z1``, from a guess far out (the first steps are
    cut to the trust bound 1):

    >>> def circle(z):
    ...     return Evaluation(True, "", np.array([z @ z - 1.0, z[0] - z[1]]),
    ...                       np.array([[2 * z[0], 2 * z[1]], [1.0, -1.0]]), step_bound=1.0)
    >>> outcome = newton(circle, np.array([10.0, 3.0]), np.ones(2), tol=1e-14, max_iterations=30)
    >>> outcome.success, np.round(outcome.unknowns, 12).tolist()
    (True, [0.707106781187, 0.707106781187])
    """
    z = np.array(unknowns, dtype=float)
    current = first if first is not None else evaluate(z)
    if not current.success:
        return NewtonOutcome(False, current.message, z, 0, None)
    norm = current.norm
    sizes: list[float] = []
    for iteration in range(1, max_iterations + 2):
        checkpoint("Newton iteration", min(iteration, max_iterations), max_iterations)
        if not math.isfinite(norm):
            return NewtonOutcome(False, f"non-finite residual at iteration {iteration - 1}", z, iteration - 1, current,
                                 tuple(sizes))
        step, ratio = scaled_solve(current.jacobian, -current.residual, columns, allow_singular)
        if norm <= tol:
            # converged: the Newton step already computed polishes the last digits (quadratic convergence)
            polish = step is not None and step_tol is not None and float(np.max(np.abs(step / columns))) <= step_tol
            return NewtonOutcome(True, f"residual {norm:.1e} after {iteration - 1} Newton iterations",
                                 z + step if polish else z, iteration - 1, current, tuple(sizes))
        if iteration > max_iterations:
            break
        if step is None:
            return NewtonOutcome(False, f"singular Jacobian (σ_min/σ_max = {ratio:.1e}) at iteration {iteration}, "
                                 f"residual {norm:.1e}: {current.singular}", z, iteration, current, tuple(sizes))
        size = float(np.max(np.abs(step / columns)))
        sizes.append(size)
        if step_tol is not None and size <= step_tol:
            return NewtonOutcome(True, f"residual {norm:.1e}, last step {size:.1e}", z + step, iteration, current,
                                 tuple(sizes))
        length = float(np.max(np.abs(step)))
        if length > current.step_bound:
            step = step * (current.step_bound / length)
        damping, candidate, trial_norm = 1.0, None, math.inf
        for halving in range(max_backtracks + 1):
            trial = z + damping * step
            candidate = evaluate(trial)
            if candidate.success:
                trial_norm = candidate.norm
                if math.isfinite(trial_norm) and (trial_norm < norm or trial_norm <= tol
                                                  or (accept_last and halving == max_backtracks)):
                    break
            damping *= 0.5
        else:
            last = candidate.message if candidate is not None and not candidate.success else "larger residual"
            return NewtonOutcome(False, f"no convergence: no Newton step decreased the residual at iteration "
                                 f"{iteration} (residual {norm:.1e}; last: {last})", z, iteration, current,
                                 tuple(sizes))
        z, current, norm = trial, candidate, trial_norm
    return NewtonOutcome(False, f"no convergence in {max_iterations} Newton iterations (residual {norm:.1e})", z,
                         max_iterations, current, tuple(sizes))
