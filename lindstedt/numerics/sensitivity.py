"""Exact derivatives of the flow of ``M X'' + K X + ε W (A X − b)_+ = 0``: in the initial state and in ε.

The flow of the piecewise-linear system (:class:`lindstedt.numerics.ExactFlow`)
is a chain of closed-form arcs, one per contact state S, each a sum of
harmonics about the state's equilibrium.  Its derivatives are exact too:

* ``∂(X, X')(t)/∂(X0, V0)`` — the state transition matrix, the product of the
  arcs' transition matrices (the saltation matrices are the identity: the
  vector field is continuous across the switching surfaces); over one period
  it is the monodromy matrix;
* ``∂(X, X')(t)/∂ε`` — the solution z of the variational equation
  ``z' = J(t) z + (0, −M⁻¹ W (A X − b)_+)``, ``z(0) = 0``, whose forcing on each
  arc is a constant plus harmonics of the arc's own frequencies, so the
  Duhamel integral is summed in closed form (``ExactFlow._epsilon_derivative``,
  given by :meth:`ExactFlow.period_map` with ``d_epsilon=True`` and by
  :func:`flow_epsilon_derivative`).

No finite differences are used.  These are the Jacobians of the NNM shooting
(:mod:`lindstedt.numerics.shooting`).

Examples
--------
>>> system = UnilateralSystem.one_dof(1)          # u'' + u + ε u_+ = 0
>>> state, sensitivity, d_eps = flow_epsilon_derivative(system, 2.0, [-1.0], [0.0], np.pi / 2)
>>> np.round(sensitivity + 0.0, 12).tolist(), float(d_eps[0])  # u = −cos t, no contact yet: the linear flow
([[0.0, 1.0], [-1.0, 0.0]], 0.0)
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .._errors import ConvergenceError, ProblemError
from ._period_map import PeriodMapValue
from .flow import ExactFlow
from ..problems.parsing import parse_float
from ..problems.system import UnilateralSystem

__all__ = ["flow_epsilon_derivative"]


def _check_epsilon(epsilon: Any) -> float:
    return parse_float(epsilon, what="epsilon")


def _map_over(flow: Any, x0: np.ndarray, v0: np.ndarray, t: float, *, sensitivity: bool,
              d_epsilon: bool) -> PeriodMapValue | str:
    """The state after time t of a free flow (``advance`` of :class:`ExactFlow` or of
    :class:`~lindstedt.numerics.SmoothForcedFlow`, the autonomous period map), or the failure's words."""
    try:
        return flow.advance(np.r_[x0, v0], t, sensitivity=sensitivity, d_epsilon=d_epsilon)
    except ConvergenceError as error:
        return str(error)
    except ProblemError as error:
        return f"the flow failed: {error}"


def flow_epsilon_derivative(
    system: UnilateralSystem, epsilon: float, x0: Any, v0: Any, t: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """State at time t with its exact derivatives ``∂(X, X')/∂(X0, V0)`` and ``∂(X, X')/∂ε``.

    Returns
    -------
    (state, sensitivity, d_epsilon) : numpy.ndarray
        Shapes (2N,), (2N, 2N), (2N,).

    Raises
    ------
    ConvergenceError
        When the flow fails.

    Examples
    --------
    >>> system = UnilateralSystem.one_dof(1)          # u'' + u + ε u_+ = 0
    >>> state, _, d_eps = flow_epsilon_derivative(system, 0.0, [1.0], [0.0], np.pi / 2)
    >>> round(float(d_eps[0]), 12)                    # ∂u/∂ε = −(t/2) sin t at ε = 0, t = π/2
    -0.785398163397
    """
    flow = ExactFlow(system, _check_epsilon(epsilon))
    n = system.n_dof
    x0 = np.asarray(x0, dtype=float).reshape(n)
    v0 = np.asarray(v0, dtype=float).reshape(n)
    value = _map_over(flow, x0, v0, float(t), sensitivity=True, d_epsilon=True)
    if isinstance(value, str):
        raise ConvergenceError(value)
    return value.state, value.d_state, value.d_epsilon
