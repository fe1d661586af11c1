"""The period map of a harmonically forced system: what shooting, continuation and Floquet analysis need.

For ``z = (X, X')`` and the forcing ``ε s P cos(Ω t)`` (``s`` scales the load of the problem, 1 by
default), the period map over ``k`` forcing periods is

    Π(z0; Ω, s) = z(k T; z0),    T = 2π/Ω,    z(0) = z0,

and a periodic response of period ``k T`` is a fixed point ``Π(z0) = z0``.  Every flow that computes
forced responses (the exact event-driven flow for piecewise-linear laws, the DOP853 flow with its
variational equations for any law) implements :class:`PeriodMap`; the shooting, continuation and
bifurcation code only talk to this interface.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Protocol, runtime_checkable

import numpy as np

__all__ = ["PeriodMap", "PeriodMapValue"]


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
    """

    state: np.ndarray
    d_state: np.ndarray | None = None
    d_frequency: np.ndarray | None = None
    d_forcing: np.ndarray | None = None
    counters: dict[str, int] = field(default_factory=dict)


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
