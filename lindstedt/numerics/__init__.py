"""Numerical ground truth: the exact flow of ``M X'' + K X + ε W (A X − b)_+ = 0`` and NNMs by shooting.

Exact piecewise-linear flow
    For fixed ε and a fixed contact state S (the springs with ``A_i X − b_i > 0``)
    the system is linear, ``M X'' + (K + ε W_S A_S) X = ε W_S b_S``, so between
    two switches the motion is a closed-form sum of harmonics about the
    state's equilibrium ``X*_S``:
    ``X(t) = X*_S + P_S (q0 cos ω t + (p0/ω) sin ω t)``.
    :class:`ExactFlow` chains these arcs through certified switch searches
    (:meth:`ExactFlow.solve` → :class:`FlowResult` with its
    :class:`SwitchEvent` list and dense output; :meth:`ExactFlow.flow_map` →
    :class:`FlowMapResult` with the exact sensitivity ``∂(X, X')/∂(X0, V0)``);
    :func:`smooth_flow` integrates ``u'' + ω0² u + ε f(u) = 0`` by DOP853 for
    nonlinearities without a closed form.

Nonlinear normal modes by shooting
    A nonlinear normal mode of mode j is a periodic orbit growing out of the
    linear mode ``φ_j`` (``K φ_j = λ_j² M φ_j``).  :class:`NNMShooting` holds the
    residuals (``X'(T/2) = 0`` from rest, or ``X(T) − X0, X'(T) − X1`` with a
    phase condition, plus an amplitude condition) and their exact Jacobian
    (the state transition matrix; :func:`flow_epsilon_derivative` gives
    ``∂(X, X')/∂ε`` by a closed-form Duhamel integral).
    :func:`nnm_point` solves for one orbit (:class:`NNMResult`: frequency,
    release point, Floquet multipliers; from the linear mode, the
    strained-coordinates expansion :func:`lindstedt.nnm`, or by continuation
    in ε where neither converges), :func:`continue_nnm` follows a branch in ε,
    the energy or the modal amplitude by pseudo-arclength continuation,
    crossing internal-resonance tongues by parameter jumps
    (:class:`NNMBranch`, progress reported as :class:`ContinuationProgress`),
    :func:`nnm_sweep` solves independent points; :func:`nnm_energy` is the
    energy that parametrises them and :func:`seed_example_system` the seed's
    N-dof example.

Forced and damped responses
    ``u'' + 2ζω0 u' + ω0² u + ε f(u) = ε F cos Ωt`` and ``M X'' + C X' + K X + ε W (A X − b)_+ = ε P cos Ωt``
    (:class:`lindstedt.ForcedOscillator`, :class:`lindstedt.ForcedSystem`): the exact event-driven
    :class:`ForcedFlow` (piecewise-linear laws) and the DOP853 :class:`SmoothForcedFlow` (any law) share the
    :class:`PeriodMap` interface (the period map Π with its monodromy and its derivatives in Ω and in the load);
    :func:`forced_flow` picks the exact one where it applies.  :func:`forced_periodic_orbit` shoots one
    periodic response (:class:`ForcedOrbit`: amplitudes, first harmonics, Floquet multipliers);
    :func:`frequency_response` follows a branch in Ω or in the load by pseudo-arclength continuation through
    folds and locates folds, branch points, period doublings and Neimark–Sacker points (:class:`FrequencyResponse`,
    :class:`Bifurcation`); :func:`switch_period_doubling` continues the period-2 branch;
    :func:`frequency_response_sweep` runs families on any executor.

The systems themselves are :class:`lindstedt.UnilateralSystem`.

Layout (the pipeline, in order)
    the flows, each behind the one :class:`PeriodMap` protocol: the exact free flow (:class:`ExactFlow`, in
    :mod:`~lindstedt.numerics.flow`, its results in ``flow_results``; switch search in ``switching``; the
    ε-derivative in :mod:`~lindstedt.numerics.sensitivity`; DOP853 for smooth f in ``smooth``), the exact forced
    flow (``forced_flow``) and the DOP853 forced flow (``forced_smooth``) →
    the periodic-orbit core: one damped Newton (:mod:`~lindstedt.numerics.newton`) and one continuation driver
    with the test functions of folds, branch points, period doublings and Neimark–Sacker points
    (:mod:`~lindstedt.numerics.arclength`) →
    the orbit problems on it: NNM shooting (:mod:`~lindstedt.numerics.shooting`: residual, Jacobian,
    :func:`nnm_energy`), NNM branches (``nnm_branch``: the steppers "arclength", "natural", "seed") and their
    entry points (:mod:`~lindstedt.numerics.continuation`: :func:`nnm_point`, :func:`continue_nnm`,
    :func:`nnm_sweep`); forced orbits (``forced_orbit``) and branches (:mod:`~lindstedt.numerics.forced_response`);
    :mod:`~lindstedt.numerics.results` and ``forced_results`` hold the result types and
    :mod:`~lindstedt.numerics.examples` the seed's example system.

Examples
--------
>>> import numpy as np
>>> import lindstedt
>>> from lindstedt.numerics import ExactFlow, nnm_point
>>> system = lindstedt.UnilateralSystem.one_dof(1)          # u'' + u + ε u_+ = 0
>>> result = ExactFlow(system, epsilon=3.0).solve([1.0], [0.0], t_end=10.0)
>>> result.n_switches, [event.direction for event in result.events[:2]]
(4, [-1, 1])
>>> orbit = nnm_point(system, 3.0, 1, modal_amplitude=1.0)  # ω = 2 ω0 ω_c / (ω0 + ω_c), ω_c = 2
>>> orbit.success, bool(abs(orbit.frequency - 4 / 3) < 1e-12)
(True, True)
"""

from .flow import ExactFlow, FlowMapResult, FlowResult, SwitchEvent
from ._period_map import PeriodMap, PeriodMapValue
from .forced_flow import ForcedFlow
from .forced_smooth import SmoothForcedFlow
from .forced_results import Bifurcation, ForcedOrbit, FrequencyResponse
from .forced_setup import forced_flow
from .forced_response import (
    forced_periodic_orbit,
    frequency_response,
    frequency_response_sweep,
    switch_period_doubling,
)
from .smooth import smooth_flow
from .continuation import continue_nnm, nnm_point, nnm_sweep
from .examples import seed_example_system
from .results import ContinuationProgress, NNMBranch, NNMResult, to_dataframe
from .sensitivity import flow_epsilon_derivative
from .shooting import NNMShooting, nnm_energy

__all__ = [
    "ExactFlow",
    "FlowResult",
    "FlowMapResult",
    "SwitchEvent",
    "smooth_flow",
    "NNMShooting",
    "flow_epsilon_derivative",
    "nnm_point",
    "NNMResult",
    "continue_nnm",
    "NNMBranch",
    "ContinuationProgress",
    "nnm_sweep",
    "nnm_energy",
    "seed_example_system",
    "to_dataframe",
    "ForcedFlow",
    "SmoothForcedFlow",
    "PeriodMap",
    "PeriodMapValue",
    "forced_flow",
    "forced_periodic_orbit",
    "frequency_response",
    "frequency_response_sweep",
    "switch_period_doubling",
    "ForcedOrbit",
    "FrequencyResponse",
    "Bifurcation",
]
