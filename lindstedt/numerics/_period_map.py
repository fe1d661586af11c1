"""The period map: the one protocol through which the periodic-orbit core sees every flow.

For ``z = (X, X')`` and the forcing ``ε s P cos(Ω t)`` (``s`` scales the load of the problem, 1 by
default), the period map over ``k`` forcing periods is

    Π(z0; Ω, s) = z(k T; z0),    T = 2π/Ω,    z(0) = z0,

and a periodic response of period ``k T`` is a fixed point ``Π(z0) = z0``.  Every flow implements
:class:`PeriodMap`: the exact event-driven flows for piecewise-linear laws (forced, :class:`ForcedFlow`, and
free, :class:`ExactFlow`, where Ω is the orbit's own frequency, the load is absent and the map also gives
``∂Π/∂ε``) and the DOP853 flow with its variational equations for any law (:class:`SmoothForcedFlow`); the
shooting of forced orbits and of NNMs, the continuation and the bifurcation code talk to this interface.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Protocol, Sequence, runtime_checkable

import numpy as np

from .._errors import LindstedtError, ParameterError, ProblemError
from ..problems.forced import ForcedOscillator, ForcedSystem
from ..problems.system import UnilateralSystem

__all__ = ["PeriodMap", "PeriodMapValue", "linear_frequency_bounds", "real_argument"]


@dataclass(frozen=True)
class PeriodMapValue:
    """``Π(z0; Ω, s)`` and its derivatives.

    Attributes
    ----------
    state : numpy.ndarray, shape (2N,)
        ``z(kT)``.
    d_state : numpy.ndarray, shape (2N, 2N) or None
        ``∂Π/∂z0``: the monodromy matrix (with the saltation matrices of the switches where the
        vector field jumps); its eigenvalues are the Floquet multipliers.  None without sensitivities.
    d_frequency : numpy.ndarray, shape (2N,) or None
        ``∂Π/∂Ω`` at fixed z0 (the period ``kT = 2πk/Ω`` moves with Ω: included).
    d_forcing : numpy.ndarray, shape (2N,) or None
        ``∂Π/∂s`` at fixed z0 and Ω.
    counters : dict
        Cost counters (e.g. ``arcs``, ``switches``, ``steps``, ``evaluations``).
    d_epsilon : numpy.ndarray, shape (2N,) or None
        ``∂Π/∂ε`` at fixed z0 and Ω, from the flows that give it when asked (the exact free flow:
        continuation of NNMs in ε).
    """

    state: np.ndarray
    d_state: np.ndarray | None = None
    d_frequency: np.ndarray | None = None
    d_forcing: np.ndarray | None = None
    counters: dict[str, int] = field(default_factory=dict)
    d_epsilon: np.ndarray | None = None


@runtime_checkable
class PeriodMap(Protocol):
    """A forced flow seen through its period map (see the module docstring)."""

    #: 2N, the size of z = (X, X')
    dimension: int

    def period_map(
        self, state0: Any, frequency: float, *, periods: int = 1, forcing_scale: float = 1.0, sensitivity: bool = True
    ) -> PeriodMapValue:
        """``Π(z0; Ω, s)`` over ``periods`` forcing periods, with its derivatives when ``sensitivity``."""
        ...

    def sample(
        self, state0: Any, frequency: float, *, periods: int = 1, forcing_scale: float = 1.0, samples: int = 256
    ) -> tuple[np.ndarray, np.ndarray]:
        """``(t, z(t))`` at ``samples`` equally spaced times of ``[0, k T)`` (z has shape (samples, 2N)).

        Used for amplitudes, harmonics and spectra of a periodic response.
        """
        ...


def linear_frequency_bounds(problem: Any, epsilon: float, slopes: Sequence[float] = ()) -> tuple[float, float] | None:
    """(lowest, highest) frequency of the linear pieces of a forced problem, ``ω² = eig(M⁻¹(K + ε·slope))``: for an
    oscillator ``ω0² + ε·slope`` over 0 and its law's ``slopes``, for a system (forced or free) K and K + ε W diag(s) A with the
    steepest slope s of each element's law (``slopes``, one per element; 1 for unilateral springs); None when
    they cannot be formed (symbols left, a singular M).  A square beyond the float range is an infinite frequency.

    Every flow of the package reports its own (``linear_frequencies()``): the cost checks and step sizes use them.

    Examples
    --------
    >>> from lindstedt import ForcedOscillator
    >>> linear_frequency_bounds(ForcedOscillator("Max(0, u - 1/5)", omega0=1, zeta="1/50"), 3.0, [1.0])
    (1.0, 2.0)
    """
    try:
        if isinstance(problem, ForcedOscillator):
            omega0 = problem.numeric_coefficients()[0]
            squares = [omega0 * omega0 + epsilon * slope for slope in (0.0, *slopes)]
        elif isinstance(problem, (ForcedSystem, UnilateralSystem)):
            s = problem.system if isinstance(problem, ForcedSystem) else problem
            A = np.array(s.A, dtype=float).reshape(-1, s.n_dof)
            W = np.array(s.W, dtype=float).reshape(s.n_dof, -1)
            steepest = np.asarray(slopes, dtype=float) if len(slopes) == A.shape[0] else np.ones(A.shape[0])
            stiffnesses = [s.K] + ([s.K + epsilon * (W * steepest) @ A] if A.size else [])
            squares = [float(x) for K in stiffnesses for x in np.linalg.eigvals(np.linalg.solve(s.M, K)).real]
        else:
            return None
    except (LindstedtError, np.linalg.LinAlgError, TypeError, ValueError, OverflowError):
        return None
    roots = [math.sqrt(abs(x)) for x in squares if x != 0.0 and not math.isnan(x)]
    return (min(roots), max(roots)) if roots else None


def real_argument(value: Any, name: str) -> float:
    """A finite real number (a float, an int or a numeric string through the one parser), or a
    :class:`ParameterError` naming the form (the one reading of ε, load scales and ranges of the forced numerics).

    Examples
    --------
    >>> real_argument("1/4", "epsilon")
    0.25
    """
    from ..problems.parsing import parse_float

    if isinstance(value, (np.floating, np.integer)):
        value = value.item()
    try:
        return parse_float(value, what=name)
    except ParameterError:
        raise
    except ProblemError as error:
        raise ParameterError(str(error)) from None
