"""Which flow computes a forced problem's responses, and where Newton starts.

The problems ``u'' + 2 ζ ω0 u' + ω0² u + ε f(u) = ε s F cos(Ω t)`` (:class:`~lindstedt.ForcedOscillator`) and
``M X'' + C X' + K X + ε W (A X − b)_+ = ε s P cos(Ω t)`` (:class:`~lindstedt.ForcedSystem`):

* :func:`forced_flow` — the exact event-driven :class:`~lindstedt.numerics.ForcedFlow` where the law is
  piecewise linear, the DOP853 :class:`~lindstedt.numerics.SmoothForcedFlow` otherwise;
* the starts of the shooting Newton: the harmonic response of the problem linearised about X = 0, and the
  first-order multiple-scales steady states ``u ≈ A cos(Ωt − γ)`` near a resonance;
* the cost check before any integration (:data:`MAX_NATURAL_PERIODS`, :data:`MAX_FREQUENCY_RATIO`: Ω far below or
  far above the linear frequencies is refused with the estimate) and the independent verification of a
  converged orbit (:data:`VERIFY_TOL`).
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
from ..limits import Estimate

__all__ = ["MAX_FREQUENCY_RATIO", "MAX_NATURAL_PERIODS", "VERIFY_TOL", "forced_flow"]

#: a period map (k forcing periods 2πk/Ω) spanning more than this many natural periods ``k·max(1, ω_max/Ω)`` is
#: refused before any integration (Ω far below the linear frequencies).  Measured costs per natural period:
#: DOP853 (SmoothForcedFlow, rtol 1e-12, with sensitivities) ≈ 35 steps ≈ 2.5 ms; the exact ForcedFlow ≈ 2 switches
#: per breakpoint ≈ 0.2 ms; so the bound is ≈ 2.5 s per DOP853 period map, and Newton takes ~3–10 maps
MAX_NATURAL_PERIODS = 1000
#: Ω above this many times the lowest linear frequency is refused: there one period is ≈ I (monodromy
#: ``≈ I + A·2π/Ω``), so the fixed point ``(I − ∂Π/∂z)⁻¹`` amplifies every rounding error of the map by ~Ω/ω0
#: — in relative terms about ``rtol·(Ω/ω0)²`` (measured for ``Max(0, u − 1)``, exact flow: 4e-5 at Ω/ω0 = 1e6,
#: 0.4 at 1e8; the check of :data:`VERIFY_TOL` reports such orbits as failures); the response there is the
#: inertia-dominated ``u ≈ −εF cos Ωt/Ω²``
MAX_FREQUENCY_RATIO = 1e6
#: A static response ε·|F|/ω_min² (of the forcing alone) above this is refused: the float flows, their events and
#: Newton's scaling cannot follow a motion of that size (ε or F far outside a weakly nonlinear oscillation)
MAX_RESPONSE = 1e100
#: a converged orbit is verified by a second, independent integration of its period (DOP853 at rtol
#: :data:`_VERIFY_RTOL` with atol scaled to the orbit): the Newton correction that map asks for,
#: ``(∂Π/∂z − I)⁻¹ (Π₂(z) − z)``, relative to the orbit's displacements D and velocities D·max(Ω, ω), must be ≤ this
VERIFY_TOL = 1e-6
_VERIFY_RTOL = 1e-13
#: DOP853 steps and seconds per natural period of one period map (the estimate's calibration, see above)
_STEPS_PER_NATURAL_PERIOD, _SECONDS_PER_NATURAL_PERIOD = 35, 2.5e-3

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

    A :class:`~lindstedt.ForcedSystem` of unilateral springs or of continuous piecewise-linear laws that vanish at
    a breakpoint (gaps, stops, dead zones: :attr:`UnilateralSystem.ramp_equivalent`), or a
    :class:`~lindstedt.ForcedOscillator` whose f is piecewise linear (unilateral springs, gaps, jumps), gets the exact
    event-driven
    :class:`~lindstedt.numerics.ForcedFlow`; any other law (u³, Hertz contact, …, on one degree of freedom or on
    the elements of a system) the DOP853 flow with variational equations
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
        exact = problem.system.ramp_equivalent  # continuous piecewise-linear laws are sums of unilateral springs
        if exact is None:
            return SmoothForcedFlow(problem, epsilon)
        if exact[0] is not problem.system:  # the same forced problem on the springs' form of the laws
            problem = ForcedSystem(exact[0], problem.P_exact,
                                   C=problem.C_exact if problem.C_exact is not None else problem.C.tolist())
        return ForcedFlow(problem, epsilon)
    if not isinstance(problem, ForcedOscillator):
        raise ProblemError(f"expected a ForcedOscillator or a ForcedSystem, got {type(problem).__name__}")
    try:
        return ForcedFlow(problem, epsilon)
    except UnsupportedNonlinearityError:  # not piecewise linear: integrate
        return SmoothForcedFlow(problem, epsilon)


def _linear_frequencies(flow: Any) -> tuple[float, float] | None:
    """(lowest, highest) frequency of the flow's linear pieces (its ``linear_frequencies()``); None for a flow that
    does not report them (nothing is known about its cost)."""
    report = getattr(flow, "linear_frequencies", None)
    return report() if callable(report) else None


def _check_cost(flow: Any, frequency: float, periods: int, name: str = "frequency") -> None:
    """Refuse, before integrating, a forcing frequency whose period maps cost more than :data:`MAX_NATURAL_PERIODS`
    natural periods, or that lies more than :data:`MAX_FREQUENCY_RATIO` above the linear frequencies
    (a :class:`ParameterError` naming the estimate and what to do instead)."""
    bounds = _linear_frequencies(flow)
    if bounds is None:
        return
    low, high = bounds
    _check_scales(flow, low)
    natural = periods * max(1.0, high / frequency)
    if natural > MAX_NATURAL_PERIODS:
        raise ParameterError(
            f"{name} Ω = {frequency:.3g} is far below the linear frequencies (Ω/ω_max = {frequency / high:.1e}): one "
            f"period map ({periods} forcing period{'s' * (periods > 1)}) spans ~{natural:.1e} natural periods "
            f"(~{natural * _STEPS_PER_NATURAL_PERIOD:.1e} DOP853 steps or switches, ~{natural * _SECONDS_PER_NATURAL_PERIOD:.1e} s, "
            f"and Newton needs several), above the limit of {MAX_NATURAL_PERIODS} natural periods "
            "(lindstedt.numerics.forced_setup.MAX_NATURAL_PERIODS); for Ω ≪ ω0 the response is quasi-static, the "
            "static equilibrium under the slowly varying load ε F cos Ωt; choose Ω ≥ "
            f"{periods * high / MAX_NATURAL_PERIODS:.3g}")
    if frequency / low > MAX_FREQUENCY_RATIO:
        raise ParameterError(
            f"{name} Ω = {frequency:.3g} is far above the linear frequencies (Ω/ω_min = {frequency / low:.1e} > "
            f"{MAX_FREQUENCY_RATIO:.0e}, lindstedt.numerics.forced_setup.MAX_FREQUENCY_RATIO): one period is ≈ the "
            f"identity and the periodic orbit is ill-conditioned by ~Ω/ω; the response there is inertia-dominated, "
            f"u ≈ −ε F cos(Ωt)/Ω² (size ~ε F/Ω²); choose Ω ≤ {MAX_FREQUENCY_RATIO * low:.3g}")
    orbit_estimate(flow, frequency, periods * max(1.0, low / frequency), natural).check()


#: CPU seconds of one exact event-driven period map of an N-dof ForcedSystem near resonance: a + b·N²
#: (measured on chains with two springs, N = 2…100: 0.8 ms, 1.8 ms, 24 ms, 145 ms)
_EXACT_SYSTEM_MAP = (8e-4, 1.5e-5)
#: the exact flow of one oscillator: CPU seconds per natural period (≈ 2 switches per breakpoint)
_EXACT_SECONDS_PER_NATURAL_PERIOD = 2e-4


def orbit_estimate(flow: Any, frequency: float, slow_periods: float, natural: float, newton_maps: int = 12) -> Estimate:
    """The :class:`~lindstedt.limits.Estimate` of one forced periodic orbit: ``newton_maps`` period maps (Newton's
    iterations and the verification), each spanning ``slow_periods`` periods of the slowest linear mode and
    ``natural`` of the fastest."""
    from .forced_smooth import SmoothForcedFlow

    n = getattr(flow, "dimension", 2) // 2
    if isinstance(flow, SmoothForcedFlow):  # measured for N = 1; the variational equations grow as N²
        per_map, kind = natural * _SECONDS_PER_NATURAL_PERIOD * n * n, "DOP853 flow"
    elif n > 1:
        per_map, kind = (_EXACT_SYSTEM_MAP[0] + _EXACT_SYSTEM_MAP[1] * n * n) * slow_periods, "exact flow"
    else:
        per_map, kind = natural * _EXACT_SECONDS_PER_NATURAL_PERIOD, "exact flow"
    return Estimate(task=f"forced periodic orbit at Ω = {frequency:.6g} ({kind})", seconds=newton_maps * per_map,
                    memory_mb=max(1.0, 8e-5 * n * n),
                    drivers=(("degrees of freedom", n), ("natural periods per map", round(natural, 1))),
                    advice="force nearer the linear frequencies, or reduce the model")


def _check_scales(flow: Any, low: float) -> None:
    """Refuse a problem whose damping or static response lies beyond what the float flows follow (see
    :data:`MAX_FREQUENCY_RATIO`, :data:`MAX_RESPONSE`), with the reason and the way out."""
    problem, eps = flow.problem, float(flow.epsilon)
    if isinstance(problem, ForcedOscillator):
        omega0, zeta, forcing = problem.numeric_coefficients()
        if zeta > MAX_FREQUENCY_RATIO:
            raise ParameterError(f"ζ = {zeta:.3g} is above {MAX_FREQUENCY_RATIO:.0e} "
                                 "(lindstedt.numerics.forced_setup.MAX_FREQUENCY_RATIO): the damping rate 2ζω0 dwarfs "
                                 "the natural frequency, the motion is quasi-static (overdamped) and the flow stiff; "
                                 "give ζ of order one or less")
        load = abs(forcing)
    else:
        load = float(np.max(np.abs(problem.P)))
    response = abs(eps) * load / (low * low) if low > 0 else math.inf
    if not response <= MAX_RESPONSE:
        raise ParameterError(f"the static response to the forcing, ε·|F|/ω² ≈ {response:.1e}, is above "
                             f"{MAX_RESPONSE:.0e} (lindstedt.numerics.forced_setup.MAX_RESPONSE), beyond what the float "
                             "flows follow; rescale the problem (units in which ε, F and the response are of order one)")


def _verify(flow: Any, z: np.ndarray, frequency: float, scale: float, periods: int,
            monodromy: np.ndarray) -> tuple[bool, str]:
    """(agrees, note): the orbit z checked by an independent integration of its period (see :data:`VERIFY_TOL`);
    a flow not of the package, or a reference that cannot run (a sliding motion), is noted, not failed."""
    from .forced_smooth import SmoothForcedFlow

    problem, eps = getattr(flow, "problem", None), getattr(flow, "epsilon", None)
    bounds = _linear_frequencies(flow)
    if not isinstance(problem, (ForcedOscillator, ForcedSystem)) or eps is None or bounds is None:
        return True, "not verified independently (a flow of unknown kind)"
    n = len(z) // 2
    rate = max(frequency, bounds[1])
    size = max(float(np.max(np.abs(z[:n]))), float(np.max(np.abs(z[n:]))) / rate, 1e-300)
    try:
        rtol = min(_VERIFY_RTOL, getattr(flow, "rtol", 1.0) / 10)
        reference = SmoothForcedFlow(problem, eps, rtol=max(rtol, 2.5e-14), atol=max(rtol, 2.5e-14) * min(size, size * rate))
        image = reference.period_map(z, frequency, periods=periods, forcing_scale=scale, sensitivity=False).state
        correction = np.linalg.solve(monodromy - np.eye(len(z)), z - image)
    except (LindstedtError, np.linalg.LinAlgError) as error:
        return True, f"not verified independently (the DOP853 check could not run: {error})"
    error = max(float(np.max(np.abs(correction[:n]))) / size, float(np.max(np.abs(correction[n:]))) / (size * rate))
    if not math.isfinite(error) or error > VERIFY_TOL:
        return False, (f"the independent check (one period by DOP853, rtol {reference.rtol:.0e}) moves the orbit by "
                       f"{error:.1e} of its size (> {VERIFY_TOL:.0e}): the orbit is not trustworthy here"
                       + (f" (Ω/ω = {frequency / bounds[0]:.1e}: integration and rounding errors are amplified by ~(Ω/ω)²)"
                          if frequency > 100 * bounds[1] else ""))
    return True, f"verified by an independent DOP853 period (agrees to {error:.1e})"


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
    except (LindstedtError, np.linalg.LinAlgError, TypeError, ValueError, AttributeError, IndexError, OverflowError):
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
