"""Which flow computes a forced problem's responses, and where Newton starts.

The problems ``u'' + 2 ζ ω0 u' + ω0² u + ε f(u) = ε s F cos(Ω t)`` (:class:`~lindstedt.ForcedOscillator`) and
``M X'' + C X' + K X + ε W (A X − b)_+ = ε s P cos(Ω t)`` (:class:`~lindstedt.ForcedSystem`):

* :func:`forced_flow` — the exact event-driven :class:`~lindstedt.numerics.ForcedFlow` where the law is
  piecewise linear, the DOP853 :class:`~lindstedt.numerics.SmoothForcedFlow` otherwise;
* the starts of the shooting Newton: the harmonic response of the problem linearised about X = 0, and the
  first-order multiple-scales steady states ``u ≈ A cos(Ωt − γ)`` near a resonance.
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import Any

import numpy as np

from .._errors import LindstedtError, ParameterError, ProblemError
from .._precision import locked
from ..problems.forced import ForcedOscillator, ForcedSystem
from ._period_map import PeriodMap

__all__ = ["forced_flow"]

# --------------------------------------------------------------------------- #
# the flow of a problem
# --------------------------------------------------------------------------- #
def _description(flow: Any) -> Any:
    problem = getattr(flow, "problem", None)
    if isinstance(problem, ForcedSystem):
        return {"kind": "ForcedSystem", **problem.to_json_dict()}
    if isinstance(problem, ForcedOscillator):
        return {"kind": "ForcedOscillator", "description": problem.describe(), "f": str(problem.nonlinearity),
                "omega0": str(problem.omega0), "zeta": str(problem.zeta), "forcing": str(problem.forcing)}
    return {"kind": type(flow).__name__, "description": repr(flow)}


@locked
def forced_flow(problem: ForcedOscillator | ForcedSystem, epsilon: float) -> PeriodMap:
    """The flow that computes ``problem``'s responses: exact where it can be, DOP853 elsewhere.

    A :class:`~lindstedt.ForcedSystem`, or a :class:`~lindstedt.ForcedOscillator` whose f is piecewise linear
    (unilateral springs, gaps, jumps), gets the exact event-driven :class:`~lindstedt.numerics.ForcedFlow`;
    any other f (u³, Hertz contact, …) the DOP853 flow with variational equations
    :class:`~lindstedt.numerics.SmoothForcedFlow`.

    Examples
    --------
    >>> from lindstedt import ForcedOscillator
    >>> type(forced_flow(ForcedOscillator("Max(0, u - 1/10)", omega0=1, zeta="1/50"), 0.5)).__name__
    'ForcedFlow'
    >>> type(forced_flow(ForcedOscillator("u**3", omega0=1, zeta="1/50"), 0.5)).__name__
    'SmoothForcedFlow'
    """
    from .._errors import UnsupportedNonlinearityError
    from .forced_flow import ForcedFlow
    from .forced_smooth import SmoothForcedFlow

    if isinstance(problem, ForcedSystem):
        return ForcedFlow(problem, epsilon)
    if not isinstance(problem, ForcedOscillator):
        raise ProblemError(f"expected a ForcedOscillator or a ForcedSystem, got {type(problem).__name__}")
    try:
        return ForcedFlow(problem, epsilon)
    except UnsupportedNonlinearityError:  # not piecewise linear: integrate
        return SmoothForcedFlow(problem, epsilon)


def _flow_of(flow: Any, epsilon: float | None) -> PeriodMap:
    """A PeriodMap as given, or the :func:`forced_flow` of a problem at ``epsilon``."""
    if isinstance(flow, (ForcedOscillator, ForcedSystem)):
        if epsilon is None:
            raise ProblemError("a problem needs epsilon= (the flow is built at that ε), e.g. epsilon=0.1")
        return forced_flow(flow, epsilon)
    if epsilon is not None:
        raise ProblemError("epsilon= is for a problem; a flow already has its ε")
    return _check_flow(flow)


def _check_flow(flow: Any) -> PeriodMap:
    if not isinstance(flow, PeriodMap):
        raise ProblemError(f"flow must implement lindstedt's PeriodMap (period_map, sample, dimension), got "
                           f"{type(flow).__name__}; e.g. SmoothForcedFlow(problem, epsilon)")
    return flow


def _check_periods(periods: Any) -> int:
    if isinstance(periods, bool) or not isinstance(periods, (int, np.integer)) or periods < 1:
        raise ProblemError(f"periods must be a positive integer, got {periods!r}")
    return int(periods)


def _positive(value: Any, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)) or not (
            math.isfinite(value) and value > 0):
        raise ProblemError(f"{name} must be a positive finite number, got {value!r}")
    return float(value)


def _real(value: Any, name: str) -> float:
    """A finite real number (a float, an int or a numeric string through the one parser), or a
    :class:`ParameterError` naming the form (the one reading of ε, load scales and ranges of the forced numerics)."""
    from ..problems.parsing import parse_float

    if isinstance(value, (np.floating, np.integer)):
        value = value.item()
    try:
        return parse_float(value, what=name)
    except ParameterError:
        raise
    except ProblemError as error:
        raise ParameterError(str(error)) from None


def _state(value: Any, dimension: int, name: str = "initial_state") -> np.ndarray:
    """``dimension`` finite numbers (X, X'), or a :class:`ProblemError` naming the form."""
    try:
        state = np.array(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        state = np.array([])
    if state.shape != (dimension,) or not np.all(np.isfinite(state)):
        raise ProblemError(f"{name} must be {dimension} finite numbers (X, X'), got {value!r}")
    return state


def _linear_guess(flow: Any, frequency: float, scale: float) -> np.ndarray:
    """``z0`` of the harmonic response of the problem linearised about X = 0 (zeros for an unknown flow)."""
    problem, eps = getattr(flow, "problem", None), getattr(flow, "epsilon", None)
    try:
        if isinstance(problem, ForcedOscillator) and eps is not None:
            omega0, zeta, forcing = problem.numeric_coefficients()
            law = getattr(flow, "_law", None)
            slope = law.pieces[law.region(0.0, 1.0)][1](0.0) if type(law).__name__ == "_ScalarLaw" else 0.0
            M, C, K, P = np.eye(1), np.array([[2 * zeta * omega0]]), np.array([[omega0**2 + eps * slope]]), np.array([forcing])
        elif isinstance(problem, ForcedSystem) and eps is not None:
            s = problem.system
            A, b = np.array(s.A, dtype=float).reshape(-1, s.n_dof), np.array(s.b, dtype=float)
            W = np.array(s.W, dtype=float).reshape(s.n_dof, -1)
            M, C, P = s.M, problem.C, problem.P
            K = s.K + eps * (W * (b < 0)) @ A if A.size else s.K
        else:
            return np.zeros(flow.dimension)
        X = np.linalg.solve(K - frequency**2 * M + 1j * frequency * C, eps * scale * P.astype(complex))
        guess = np.concatenate((X.real, -frequency * X.imag))
        return guess if np.all(np.isfinite(guess)) else np.zeros(flow.dimension)
    except (LindstedtError, np.linalg.LinAlgError, TypeError, ValueError, AttributeError, IndexError):
        return np.zeros(flow.dimension)


def _multiple_scales_guesses(flow: Any, frequency: float, scale: float) -> list[np.ndarray]:
    """``z0 = (A cos γ, A Ω sin γ)`` of each first-order multiple-scales steady state ``u ≈ A cos(Ωt − γ)``, the
    stable ones first (1 dof at the problem's own load only; none where the method does not apply)."""
    problem, eps = getattr(flow, "problem", None), getattr(flow, "epsilon", None)
    if not isinstance(problem, ForcedOscillator) or not eps or scale != 1.0:
        return []
    try:
        states = _multiple_scales_curve(problem).steady_states(frequency, eps)
    except LindstedtError:  # e.g. Ω far from ω0, or a law the method does not take
        return []
    ordered = sorted(states, key=lambda state: state.kind != "stable")
    return [np.array([s.amplitude * math.cos(s.phase), s.amplitude * frequency * math.sin(s.phase)]) for s in ordered]


@lru_cache(maxsize=16)
def _multiple_scales_curve(problem: ForcedOscillator) -> Any:
    from ..methods.multiple_scales import MultipleScales

    return MultipleScales(order=1).frequency_response(problem)
