"""Frequency responses: branches of forced periodic orbits by the core's continuation driver, with bifurcations.

For a harmonically forced, damped system (one degree of freedom
``u'' + 2 ζ ω0 u' + ω0² u + ε f(u) = ε s F cos(Ω t)`` or N degrees of freedom
``M X'' + C X' + K X + ε W (A X − b)_+ = ε s P cos(Ω t)``) seen through its period map
``Π(z0; Ω, s) = z(2πk/Ω)`` (:class:`~lindstedt.numerics._period_map.PeriodMap`, ``z = (X, X')``):

* :func:`frequency_response` follows the branch of fixed points ``Π(z; λ) − z = 0`` in λ = Ω (or in the load
  scale s at fixed Ω) by the one pseudo-arclength driver of the periodic-orbit core
  (:class:`~lindstedt.numerics.arclength.Arclength`: predictor along the unit tangent, the core's Newton as
  corrector, adaptive steps), through folds, and locates on it — by regula falsi (Illinois) along the
  arclength, to ``locate_tol`` — folds, branch points, period doublings (``det(∂Π/∂z0 + I)`` changes sign: a
  real multiplier crosses −1) and Neimark–Sacker points (the bialternate product ``∏_{i<j}(μ_i μ_j − 1)``
  changes sign with a complex pair on the unit circle) → :class:`FrequencyResponse` with its
  :class:`Bifurcation` list;
* :func:`switch_period_doubling` starts the period-2 branch (fixed points of ``Π∘Π``) at a period doubling
  along the eigenvector v of the multiplier −1 and continues it;
* :func:`frequency_response_sweep` computes independent responses (several forcing levels, several
  problems), optionally on an executor.

One orbit is :func:`~lindstedt.numerics.forced_orbit.forced_periodic_orbit`'s (re-exported here).

Examples
--------
>>> from lindstedt.problems.forced import ForcedOscillator
>>> from lindstedt.numerics.forced_smooth import SmoothForcedFlow
>>> flow = SmoothForcedFlow(ForcedOscillator("u**3", omega0=1, zeta="1/20", forcing=1), 0.2, rtol=1e-10)
>>> response = frequency_response(flow, 0.8, 1.4, tol=1e-8)
>>> response.success, [b.kind for b in response.bifurcations]
(True, ['fold', 'fold'])
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterable
from concurrent.futures import Executor
from dataclasses import replace
from functools import partial
from typing import Any

import numpy as np

from .._errors import BudgetError, Cancelled, LindstedtError, ProblemError
from .._sweep import sweep_map
from ..problems.forced import ForcedOscillator, ForcedSystem, check_forcing_frequency
from ._period_map import PeriodMap, real_argument
from .arclength import Arclength, Attempt, drive
from .forced_orbit import _Counter, _fixed_point, _orbit, forced_periodic_orbit
from .forced_results import Bifurcation, ForcedOrbit, FrequencyResponse
from .forced_setup import _check_cost, _check_periods, _description, _flow_of, _positive, _verify, forced_flow
from .newton import Evaluation, NewtonOutcome

__all__ = ["Bifurcation", "ForcedOrbit", "FrequencyResponse", "forced_periodic_orbit", "frequency_response",
           "frequency_response_sweep", "switch_period_doubling"]

_PARAMETERS = ("frequency", "forcing")


# --------------------------------------------------------------------------- #
# the branch
# --------------------------------------------------------------------------- #
class _ForcedBranch(Arclength):
    """The core's pseudo-arclength stepper on ``G(w) = (Π(z; λ) − z)/D_z``, ``w = (z, λ)``, scales D.

    The rows and columns are scaled by D: displacements by the first orbit's peak, velocities by that times Ω,
    λ by the range; D grows with the branch (rescaled when the peak doubles).  A step across the end of the
    range lands on it by the fixed-point Newton; with ``rejoin`` (a period-2k branch) the branch ends where it
    meets the period-k branch again (the sign of ``z − Π^k(z)`` along the period-2k eigen-direction flips).
    """

    predictor_error = 5e-3

    def __init__(self, flow: PeriodMap, parameter: str, fixed: float, periods: int, scales: np.ndarray,
                 options: dict[str, Any], *, start: float, stop: float | None, bounds: tuple[float, float],
                 rejoin: bool, direction: float) -> None:
        end = stop if stop is not None else (bounds[1] if direction > 0 else bounds[0])
        super().__init__(start, end, step=options["step"], min_step=options["min_step"], max_step=options["max_step"],
                         max_halvings=0)
        self.count = _Counter(flow, periods)
        self.flow, self.parameter, self.fixed, self.D, self.options = flow, parameter, fixed, scales, options
        self.label = parameter
        self.final_stop, self.bounds, self.rejoin = stop, bounds, rejoin
        self.identity = np.eye(flow.dimension)
        self.tol, self.max_iterations, self.locate_tol = options["tol"], options["max_iterations"], options["locate_tol"]
        self.max_turn = math.cos(math.radians(options["max_angle"]))
        self.arclength = [0.0]
        self.gap: np.ndarray | None = None
        self.landed: float | None = None

    def unknowns_of(self, point: ForcedOrbit, value: float) -> np.ndarray:
        return np.r_[point.state, value]

    def split(self, w: np.ndarray) -> tuple[np.ndarray, float, float]:
        lam = float(w[-1])
        return (w[:-1], lam, self.fixed) if self.parameter == "frequency" else (w[:-1], self.fixed, lam)

    # ------------------------------------------------------------ hooks of the core
    def evaluate(self, w: np.ndarray) -> Evaluation:
        z, frequency, scale = self.split(w)
        if not (math.isfinite(frequency) and frequency > 0 and math.isfinite(scale)):
            return Evaluation(False, f"the branch reaches Ω = {frequency:.6g} ≤ 0" if frequency <= 0
                              else "non-finite parameter")
        try:
            value = self.count(z, frequency, scale)
        except (BudgetError, Cancelled):
            raise
        except LindstedtError as error:
            return Evaluation(False, str(error))
        Dz = self.D[:-1]
        d_lambda = value.d_frequency if self.parameter == "frequency" else value.d_forcing
        jacobian = np.column_stack([value.d_state - self.identity, d_lambda]) / Dz[:, None]
        return Evaluation(True, "", (value.state - z) / Dz, jacobian, data=value,
                          singular="singular augmented Jacobian")

    def scales_of(self, w: np.ndarray, evaluation: Evaluation) -> np.ndarray:
        return self.D

    def verify(self, w: np.ndarray, outcome: NewtonOutcome) -> tuple[Any, str]:
        return self.orbit(w, outcome.last.data.data, f"{outcome.iterations} iterations"), ""

    def multipliers(self, point: Any, evaluation: Evaluation) -> np.ndarray:
        return np.linalg.eigvals(evaluation.data.d_state)

    def land(self, value: float, guess: np.ndarray) -> tuple[Any, int, str]:
        _, frequency, scale = self.split(np.r_[guess, value])
        ok, why, z, period_map, iterations = _fixed_point(self.count, guess, frequency, scale, self.options["tol"],
                                                          self.options["max_iterations"])
        if not ok:
            return None, iterations, why
        self.landed = value
        return _orbit(self.count, z, frequency, scale, period_map, success=True, message=why, iterations=iterations,
                      stability_tol=self.options["stability_tol"], samples=self.options["samples"],
                      epsilon=getattr(self.flow, "epsilon", None)), iterations, why

    def boundary(self, value: float) -> float | None:
        stop, (lo, hi) = self.final_stop, self.bounds
        if stop is not None and (value - stop) * (stop - self.start) >= 0:
            return stop
        if not lo <= value <= hi:
            return lo if value < lo else hi
        return None

    def admissible(self, value: float, within: float | None) -> bool:
        return self.bounds[0] <= value <= self.bounds[1]

    def complete_at(self, point: ForcedOrbit, w: np.ndarray, values: list[float]) -> str | None:
        """With ``rejoin``: the message when the period-2k branch has met the period-k branch again."""
        if not self.rejoin:
            return None
        z, frequency, scale = self.split(w)
        half = self.count.periods // 2
        delta = z - self.count(z, frequency, scale, sensitivity=False, periods=half).state
        rejoined = self.gap is not None and delta @ self.gap < 0 and len(values) >= 2
        self.gap = delta
        if not rejoined:
            return None
        return (f"the period-{self.count.periods} branch rejoins the period-{half} branch between {self.parameter} = "
                f"{values[-1]:.8g} and {float(w[-1]):.8g} (another period doubling)")

    def bifurcation(self, kind: str, w: np.ndarray, evaluation: Evaluation, test: float,
                    index: int) -> Bifurcation | None:
        multipliers = np.linalg.eigvals(evaluation.data.d_state)
        if kind == "neimark-sacker":
            close = multipliers[np.argmin(np.abs(np.abs(multipliers) - 1))]
            if abs(close.imag) <= 1e-6:
                return None  # a neutral saddle (real μ_i μ_j = 1), not a bifurcation
        orbit = self.orbit(w, evaluation.data, "located")
        z, frequency, scale = self.split(w)
        return Bifurcation(kind, frequency, orbit.amplitude, z, orbit.multipliers, index, scale, test)

    def accept(self, attempt: Attempt) -> None:
        used = self.step
        super().accept(attempt)
        self.arclength.append(self.arclength[-1] + used)
        if attempt.complete:
            return
        peak = float(np.max(attempt.point.amplitude))
        if peak > 2 * self.D[0]:  # the branch grew: rescale so steps stay relative to its size
            n = self.flow.dimension // 2
            D = self.D.copy()
            D[:2 * n] *= peak / D[0]
            unit = self.tangent * self.D / D
            self.D, self.scales, self.tangent = D, D, unit / np.linalg.norm(unit)

    def reached(self, points: list[Any], values: list[float], attempt: Attempt) -> str:
        if attempt.reason:
            return attempt.reason
        target = self.landed
        if self.final_stop is not None and target == self.final_stop:
            return f"reached stop = {target:.8g}"
        if self.rejoin:
            return f"reached the end of the range, {self.parameter} = {target:.8g}"
        return (f"the branch turned back at a fold and left the range through start, {self.parameter} = "
                f"{target:.8g}; the responses nearer stop = {self.final_stop:.8g} lie on another part of the curve: "
                f"follow them from {self.final_stop:.8g} (or over a wider range)")

    # ------------------------------------------------------------ the result
    def orbit(self, w: np.ndarray, value: Any, message: str, iterations: int = 0) -> ForcedOrbit:
        z, frequency, scale = self.split(w)
        return _orbit(self.count, z, frequency, scale, value, success=True, message=message, iterations=iterations,
                      stability_tol=self.options["stability_tol"], samples=self.options["samples"],
                      epsilon=getattr(self.flow, "epsilon", None))

    def assemble(self, points: list[Any], values: list[float], reason: str, success: bool, rejected: int,
                 iterations: int, started: float) -> FrequencyResponse:
        first = points[0]
        if success:
            disagreement = _verify_branch(self, points)
            if disagreement:
                success, reason = False, f"{disagreement}; {reason}"
        message = (self.first_message + "; " if self.first_message else "") + reason
        return FrequencyResponse(success, message, self.parameter, self.count.periods,
                                 getattr(self.flow, "epsilon", None), _description(self.flow), tuple(points),
                                 np.array(self.arclength[:len(points)]), tuple(self.bifurcations),
                                 iterations, self.count.maps + first.flow_evaluations,
                                 self.count.steps + first.steps, self.count.evaluations + first.evaluations, rejected,
                                 time.perf_counter() - started, self.flow,
                                 (self.parameter, self.fixed, self.D, self.bounds))

    first_message = ""


def _options(tol: float, step: float, min_step: float, max_step: float, max_points: int, max_iterations: int,
             stability_tol: float, locate_tol: float, samples: int, max_angle: float) -> dict[str, Any]:
    for value, name in ((tol, "tol"), (step, "step"), (min_step, "min_step"), (max_step, "max_step"),
                        (stability_tol, "stability_tol"), (locate_tol, "locate_tol"), (max_angle, "max_angle")):
        _positive(value, name)
    if not min_step <= step <= max_step:
        raise ProblemError(f"need min_step ≤ step ≤ max_step, got {min_step}, {step}, {max_step}")
    for value, name in ((max_points, "max_points"), (max_iterations, "max_iterations"), (samples, "samples")):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 2:
            raise ProblemError(f"{name} must be an integer ≥ 2, got {value!r}")
    return {"tol": tol, "step": step, "min_step": min_step, "max_step": max_step, "max_points": int(max_points),
            "max_iterations": int(max_iterations), "stability_tol": stability_tol, "locate_tol": locate_tol,
            "samples": int(samples), "max_angle": max_angle}


#: a branch reported a success has this many of its points (evenly spread, the last included) checked by an
#: independent DOP853 period (forced_setup._verify; its first point was checked by forced_periodic_orbit)
_VERIFIED_POINTS = 6


def _verify_branch(cont: _ForcedBranch, points: list[ForcedOrbit]) -> str:
    """'' if the sampled points of the branch agree with an independent integration, else what disagreed."""
    if len(points) < 2:
        return ""
    picked = sorted({round(k * (len(points) - 1) / (_VERIFIED_POINTS - 1)) for k in range(1, _VERIFIED_POINTS)})
    try:
        for index in picked:
            orbit = points[index]
            if orbit.monodromy is None:
                continue
            ok, note = _verify(cont.flow, orbit.state, orbit.frequency, orbit.forcing_scale, cont.count.periods,
                               orbit.monodromy)
            if not ok:
                return f"point {index} (Ω = {orbit.frequency:.8g}) fails the independent check: {note}"
    except (BudgetError, Cancelled) as stopped:
        return f"the branch was not verified independently: {stopped}"
    return ""


def _scales(flow: PeriodMap, orbit: ForcedOrbit, frequency: float, span: float, amplitude_scale: float | None) -> np.ndarray:
    n = flow.dimension // 2
    dx = float(amplitude_scale) if amplitude_scale is not None else float(np.max(orbit.amplitude))
    if not (math.isfinite(dx) and dx > 0):
        dx = max(float(np.max(np.abs(orbit.state))), 1e-12)
    return np.r_[np.full(n, dx), np.full(n, dx * frequency), span]


def frequency_response(flow: PeriodMap | ForcedOscillator | ForcedSystem, start: float, stop: float, *,
                       epsilon: float | None = None, initial_state: Any = None,
                       parameter: str = "frequency", frequency: float | None = None, forcing_scale: float = 1.0,
                       periods: int = 1, step: float = 0.02, min_step: float = 1e-7, max_step: float = 0.5,
                       max_points: int = 1000, tol: float = 1e-10, max_iterations: int = 10,
                       stability_tol: float = 1e-7, locate_tol: float = 1e-9, samples: int = 512,
                       max_angle: float = 30.0, amplitude_scale: float | None = None,
                       transient_periods: int = 100,
                       callback: Callable[[int, ForcedOrbit], Any] | None = None) -> FrequencyResponse:
    """The branch of periodic responses from ``start`` to ``stop`` in Ω (or in s), through folds, with bifurcations.

    Parameters
    ----------
    flow : PeriodMap, ForcedOscillator or ForcedSystem
        A flow, or a problem with ``epsilon``: its :func:`forced_flow` (exact for piecewise-linear laws).
    epsilon : float, optional
        ε, when ``flow`` is a problem.
    start, stop : float
        Range of Ω (``parameter="frequency"``; both > 0) or of the load scale s (``"forcing"``).
    initial_state : array_like, optional
        Guess of the first orbit (see :func:`forced_periodic_orbit`).
    parameter : {"frequency", "forcing"}
    frequency : float
        The fixed Ω when ``parameter="forcing"``.
    forcing_scale : float
        The fixed s when ``parameter="frequency"``.
    periods : int
        k (orbits of period k T).
    step, min_step, max_step : float
        Scaled arclength steps (the unknowns are scaled by the first orbit's peak, ``amplitude_scale``
        if given, velocities by that times Ω, and the parameter by ``|stop − start|``): ×1.5 after
        ≤ 2 corrector iterations, ×0.6 after ≥ 5, halved after a failure or a turn of the tangent by
        more than ``max_angle`` degrees.
    tol : float
        Scaled residual of the corrector (and of the first and last points, relative).
    locate_tol : float
        The bifurcations are located to this scaled arclength.
    stability_tol, samples, max_iterations, transient_periods, max_points
        See :func:`forced_periodic_orbit` (for the first point and every corrector); at most
        ``max_points`` points.
    callback : callable, optional
        ``callback(index, orbit)`` after every accepted point (the first is index 0), e.g. to show
        progress; its return value is ignored.

    Returns
    -------
    FrequencyResponse
        ``success=True`` once the branch leaves the range: through ``stop``, or past a fold back through
        ``start`` (in either direction of Ω; the message says which).  ``success=False`` and the reason
        when the first point fails, the steps collapse, the branch reaches Ω ≤ 0, or ``max_points`` is
        reached.

    Raises
    ------
    ProblemError, ParameterError
        For invalid arguments (Ω ≤ 0, ``start == stop``, an unknown ``parameter``, …), and before any
        integration for a range reaching Ω far below or far above the linear frequencies (see
        :func:`forced_periodic_orbit`).

    Examples
    --------
    >>> from lindstedt.problems.forced import ForcedOscillator
    >>> from lindstedt.numerics.forced_smooth import SmoothForcedFlow
    >>> flow = SmoothForcedFlow(ForcedOscillator("u**3", omega0=1, zeta="1/20", forcing=1), 0.2, rtol=1e-10)
    >>> response = frequency_response(flow, 0.8, 1.4, tol=1e-8)
    >>> response.success, [b.kind for b in response.bifurcations]
    (True, ['fold', 'fold'])
    >>> [round(b.frequency, 4) for b in response.bifurcations]    # the jump-up and jump-down frequencies
    [1.1966, 1.1455]
    """
    started = time.perf_counter()
    flow = _flow_of(flow, epsilon)
    if parameter not in _PARAMETERS:
        raise ProblemError(f"parameter must be one of {_PARAMETERS}, got {parameter!r}")
    k = _check_periods(periods)
    options = _options(tol, step, min_step, max_step, max_points, max_iterations, stability_tol, locate_tol, samples,
                       max_angle)
    if parameter == "frequency":
        start, stop = check_forcing_frequency(start, "start"), check_forcing_frequency(stop, "stop")
        if frequency is not None:
            raise ProblemError("parameter='frequency' varies Ω: do not also pass frequency=")
        for end, name in ((min(start, stop), "start" if start < stop else "stop"),
                          (max(start, stop), "stop" if start < stop else "start")):
            _check_cost(flow, end, k, name)
        fixed = real_argument(forcing_scale, "forcing_scale")
        first = forced_periodic_orbit(flow, start, initial_state=initial_state, periods=k, forcing_scale=fixed, tol=tol,
                                      max_iterations=max_iterations, transient_periods=transient_periods,
                                      stability_tol=stability_tol, samples=samples)
        omega = start
    else:
        if frequency is None:
            raise ProblemError("parameter='forcing' varies the load scale s at a fixed Ω: pass frequency=")
        fixed = omega = check_forcing_frequency(frequency, "frequency")
        start, stop = real_argument(start, "start"), real_argument(stop, "stop")
        first = forced_periodic_orbit(flow, omega, initial_state=initial_state, periods=k, forcing_scale=start, tol=tol,
                                      max_iterations=max_iterations, transient_periods=transient_periods,
                                      stability_tol=stability_tol, samples=samples)
    if start == stop:
        raise ProblemError(f"start == stop = {start}: give a range to follow (or use forced_periodic_orbit)")
    if not first.success:
        return FrequencyResponse(False, f"first point failed: {first.message}", parameter, k,
                                 getattr(flow, "epsilon", None), _description(flow), (), np.array([]), (),
                                 first.newton_iterations, first.flow_evaluations, first.steps, first.evaluations, 0,
                                 time.perf_counter() - started, flow)
    D = _scales(flow, first, omega, abs(stop - start), amplitude_scale)
    stepper = _ForcedBranch(flow, parameter, fixed, k, D, options, start=start, stop=stop,
                            bounds=(min(start, stop), max(start, stop)), rejoin=False, direction=stop - start)
    notify = None if callback is None else (lambda index, value, orbit: callback(index, orbit) and False)
    return drive(stepper, first, start, options["max_points"], iterations=first.newton_iterations, notify=notify,
                 started=started)


def switch_period_doubling(response: FrequencyResponse, index: int = 0, *, stop: float | None = None,
                           amplitude_step: float = 0.02, **options: Any) -> FrequencyResponse:
    """The period-2k branch born at the ``index``-th period doubling of ``response``, by continuation of ``Π∘Π``.

    The first step leaves the period-k orbit z* along the eigenvector v of the multiplier −1
    (predictor ``(z*, λ*) + h (v, 0)``, corrector in the plane ⟂ (v, 0): it lands on the new branch on
    either side of the pitchfork of ``Π∘Π``), then the branch is continued as in
    :func:`frequency_response` until it leaves ``[start, stop]`` of the range (``stop`` given: the
    parameter range between λ* and ``stop``; default: the range of ``response``), or rejoins the
    period-k branch (at another period doubling).

    Parameters
    ----------
    response : FrequencyResponse
    index : int
        Which of ``response.of_kind("period-doubling")``.
    amplitude_step : float
        The first step (scaled arclength along v).
    **options
        As for :func:`frequency_response` (``step``, ``tol``, ``max_points``, …).

    Examples
    --------
    >>> import numpy as np
    >>> from lindstedt.problems.forced import ForcedOscillator
    >>> from lindstedt.numerics.forced_smooth import SmoothForcedFlow
    >>> problem = ForcedOscillator("Max(0, u)", omega0=1, zeta="1/50", forcing=1)   # bilinear, stiffness ratio 9
    >>> flow = SmoothForcedFlow(problem, 8.0, rtol=1e-10)
    >>> response = frequency_response(flow, 2.2, 2.5, tol=1e-8)
    >>> [(b.kind, round(b.frequency, 6)) for b in response.bifurcations]
    [('period-doubling', 2.33598)]
    >>> branch = switch_period_doubling(response, 0, tol=1e-8)
    >>> branch.success, branch.periods, branch.points[-1].minimal_periods, bool(branch.stable.all())
    (True, 2, 2, True)
    """
    started = time.perf_counter()
    doublings = response.of_kind("period-doubling")
    if isinstance(index, bool) or not isinstance(index, (int, np.integer)) or not 0 <= index < len(doublings):
        raise ProblemError(f"index must pick one of the {len(doublings)} period doublings of the response, got {index!r}")
    if response.flow is None or response._scales is None:
        raise ProblemError("the response does not keep its flow: compute it with frequency_response")
    point = doublings[index]
    parameter, fixed, D_old, bounds = response._scales
    flow, k = response.flow, response.periods
    defaults = {"tol": 1e-10, "step": 0.02, "min_step": 1e-7, "max_step": 0.5, "max_points": 1000,
                "max_iterations": 10, "stability_tol": 1e-7, "locate_tol": 1e-9, "samples": 512, "max_angle": 30.0}
    unknown = set(options) - set(defaults)
    if unknown:
        raise ProblemError(f"unknown option(s) {sorted(unknown)}; allowed: {sorted(defaults)}")
    merged = _options(**{**defaults, **options})
    lam_star = point.frequency if parameter == "frequency" else point.forcing_scale
    values = response.parameter_values
    if stop is None:
        lo, hi = float(values.min()), float(values.max())
    else:
        lo, hi = min(lam_star, float(stop)), max(lam_star, float(stop))
    frequency, scale = (lam_star, fixed) if parameter == "frequency" else (fixed, lam_star)
    monodromy = _Counter(flow, k)(point.state, frequency, scale).d_state
    mu, vectors = np.linalg.eig(monodromy)
    v = np.real(vectors[:, int(np.argmin(np.abs(mu + 1)))])
    t0 = np.r_[v / D_old[:-1], 0.0]
    t0 /= np.linalg.norm(t0)
    stepper = _ForcedBranch(flow, parameter, fixed, 2 * k, D_old, merged, start=lam_star, stop=None, bounds=(lo, hi),
                            rejoin=True, direction=1.0)
    outcome = stepper.branch_off(np.r_[point.state, lam_star], t0, amplitude_step)
    if not outcome.success:
        return FrequencyResponse(False, f"no period-{2 * k} orbit next to the period doubling at {parameter} = "
                                 f"{lam_star:.8g}: {outcome.message}", parameter, 2 * k, getattr(flow, "epsilon", None),
                                 _description(flow), (), np.array([]), (), outcome.iterations, stepper.count.maps,
                                 stepper.count.steps, stepper.count.evaluations, 0, time.perf_counter() - started, flow)
    w1 = outcome.unknowns
    first = stepper.orbit(w1, outcome.last.data.data,
                          f"period-{2 * k} orbit next to the period doubling at {parameter} = {lam_star:.8g}")
    first = replace(first, newton_iterations=outcome.iterations, flow_evaluations=0, steps=0, evaluations=0)
    stepper.first_message = f"switched at the period doubling {parameter} = {lam_star:.10g}"
    lam1 = float(w1[-1])
    stepper.direction = 1.0 if lam1 >= lam_star else -1.0
    return drive(stepper, first, lam1, merged["max_points"], iterations=outcome.iterations, started=started)


# --------------------------------------------------------------------------- #
# families
# --------------------------------------------------------------------------- #
def _sweep_task(job: tuple[Any, float | None], *, start: float, stop: float, epsilon: float | None,
                flow_factory: Callable[..., PeriodMap] | None, options: dict[str, Any]) -> FrequencyResponse:
    item, scale = job
    if isinstance(item, (ForcedOscillator, ForcedSystem)):
        if epsilon is None:
            raise ProblemError("a problem needs epsilon= to build its flow (SmoothForcedFlow(problem, epsilon))")
        item = (flow_factory or forced_flow)(item, epsilon)
    if scale is not None:
        options = {**options, "forcing_scale": scale}
    return frequency_response(item, start, stop, **options)


def frequency_response_sweep(flows_or_problems: Any, start: float, stop: float, *, epsilon: float | None = None,
                             forcing_scales: Iterable[float] | None = None,
                             flow_factory: Callable[..., PeriodMap] | None = None, executor: Executor | None = None,
                             progress: bool | Callable[[int, Any, FrequencyResponse], Any] | None = None,
                             **options: Any) -> list[FrequencyResponse]:
    """Independent frequency responses (a family), optionally in parallel; results in input order.

    Parameters
    ----------
    flows_or_problems : PeriodMap, ForcedOscillator, ForcedSystem or a sequence of them
        A problem gets the flow ``flow_factory(problem, epsilon)``, by default :func:`forced_flow` (the exact
        ``ForcedFlow`` for piecewise-linear laws, DOP853 otherwise).
    start, stop : float
        As for :func:`frequency_response`.
    forcing_scales : iterable of float, optional
        One response per load scale s of the single flow or problem given (forcing levels).
    executor : concurrent.futures.Executor, optional
        Any executor (thread or process pool, ``distributed.Client(...).get_executor()``); default serial
        (the loop of :func:`lindstedt._sweep.sweep_map`, as for :func:`~lindstedt.numerics.nnm_sweep`).
    progress : bool or callable, optional
        ``True``: a tqdm bar; a callable gets ``progress(index, (item, scale), response)`` as each one finishes.
    **options
        Passed to :func:`frequency_response`.

    Examples
    --------
    >>> from concurrent.futures import ThreadPoolExecutor
    >>> from lindstedt.problems.forced import ForcedOscillator
    >>> problem = ForcedOscillator("u", omega0=1, zeta="1/10", forcing=1)
    >>> with ThreadPoolExecutor(2) as pool:
    ...     family = frequency_response_sweep(problem, 0.8, 1.2, epsilon=0.1, forcing_scales=[1, 2], executor=pool,
    ...                                       tol=1e-9)
    >>> [r.success for r in family], bool(abs(family[1].amplitudes.max() / family[0].amplitudes.max() - 2) < 1e-8)
    ([True, True], True)
    """
    single = isinstance(flows_or_problems, (ForcedOscillator, ForcedSystem, PeriodMap))
    items = [flows_or_problems] if single else list(flows_or_problems)
    if forcing_scales is not None:
        if len(items) != 1:
            raise ProblemError("forcing_scales= needs a single flow or problem (one response per load scale)")
        jobs: list[tuple[Any, float | None]] = [(items[0], float(scale)) for scale in forcing_scales]
    else:
        jobs = [(item, None) for item in items]
    task = partial(_sweep_task, start=start, stop=stop, epsilon=epsilon, flow_factory=flow_factory, options=options)
    return sweep_map(task, jobs, executor=executor, progress=progress, description="frequency_response_sweep")
