"""Forced responses: periodic orbits by shooting, frequency-response curves by continuation, bifurcations.

For a harmonically forced, damped system (one degree of freedom
``u'' + 2 ζ ω0 u' + ω0² u + ε f(u) = ε s F cos(Ω t)`` or N degrees of freedom
``M X'' + C X' + K X + ε W (A X − b)_+ = ε s P cos(Ω t)``) seen through its period map
``Π(z0; Ω, s) = z(2πk/Ω)`` (:class:`~lindstedt.numerics._period_map.PeriodMap`, ``z = (X, X')``):

* :func:`forced_periodic_orbit` solves ``Π(z0) − z0 = 0`` by Newton with the exact Jacobian
  ``∂Π/∂z0 − I`` (the monodromy minus the identity), refuses up front a Ω whose period maps would span too
  many natural periods (or lie too far above them), and verifies a converged orbit by an independent
  integration of its period → :class:`ForcedOrbit` with the Floquet
  multipliers (eigenvalues of the monodromy), stability, the extremes, mean and first harmonic of
  every degree of freedom;
* :func:`frequency_response` follows the branch in Ω (or in the load scale s at fixed Ω) by
  pseudo-arclength continuation (Keller: predictor along the unit tangent, Newton corrector on
  ``[Π(z) − z; tᵀ(w − w_pred)] = 0`` in scaled variables, adaptive steps), through folds, and
  locates on it — by regula falsi (Illinois) along the arclength, to ``locate_tol`` — the folds
  (the Ω-component of the tangent changes sign), period doublings (``det(∂Π/∂z0 + I)``
  changes sign: a real multiplier crosses −1) and Neimark–Sacker points (the bialternate test
  ``∏_{i<j}(μ_i μ_j − 1)`` changes sign with a complex pair on the unit circle)
  → :class:`FrequencyResponse` with its :class:`Bifurcation` list;
* :func:`switch_period_doubling` starts the period-2 branch (fixed points of ``Π∘Π``) at a period
  doubling along the eigenvector v of the multiplier −1 and continues it;
* :func:`frequency_response_sweep` computes independent responses (several forcing levels, several
  problems), optionally on an executor.

Examples
--------
>>> from lindstedt.problems.forced import ForcedOscillator
>>> from lindstedt.numerics.forced_smooth import SmoothForcedFlow
>>> flow = SmoothForcedFlow(ForcedOscillator("u", omega0=1, zeta="1/20", forcing=1), 0.5)
>>> orbit = forced_periodic_orbit(flow, 1.0)                       # linear: |H| = ε F/|1 + ε − Ω² + 2iζΩ|
>>> orbit.success, bool(abs(orbit.amplitude[0] - 0.5 / abs(1.5 - 1.0 + 0.1j)) < 1e-10)
(True, True)
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterable
from concurrent.futures import Executor
from functools import partial
from typing import Any

import numpy as np

from .._errors import BudgetError, Cancelled, LindstedtError, ProblemError
from ..limits import checkpoint
from ..problems.forced import ForcedOscillator, ForcedSystem, check_forcing_frequency
from ._period_map import PeriodMap, PeriodMapValue, real_argument
from .forced_results import Bifurcation, ForcedOrbit, FrequencyResponse
from .results import _repetitions
from .forced_setup import (
    _check_cost,
    _check_periods,
    _description,
    _flow_of,
    _linear_guess,
    _multiple_scales_guesses,
    _positive,
    _state,
    _verify,
    forced_flow,
)

__all__ = ["Bifurcation", "ForcedOrbit", "FrequencyResponse", "forced_periodic_orbit", "frequency_response",
           "frequency_response_sweep", "switch_period_doubling"]

_PARAMETERS = ("frequency", "forcing")


# --------------------------------------------------------------------------- #
# one orbit
# --------------------------------------------------------------------------- #
class _Counter:
    """Period maps and flow costs of one computation."""

    def __init__(self, flow: PeriodMap, periods: int) -> None:
        self.flow, self.periods = flow, periods
        self.maps = self.steps = self.evaluations = 0

    def __call__(self, z: np.ndarray, frequency: float, scale: float, sensitivity: bool = True,
                 periods: int | None = None) -> PeriodMapValue:
        self.maps += 1
        value = self.flow.period_map(z, frequency, periods=periods or self.periods, forcing_scale=scale,
                                     sensitivity=sensitivity)
        self.steps += int(value.counters.get("steps", 0))
        self.evaluations += int(value.counters.get("evaluations", 0))
        return value


def _hermite_extreme(t: np.ndarray, x: np.ndarray, v: np.ndarray, sign: float) -> float:
    """``sign · max(sign · X(t))`` of periodic samples, refined by the cubic Hermite interpolant (x, x')."""
    n = len(t)
    h = t[1] - t[0] if n > 1 else 0.0
    j = int(np.argmax(sign * x))
    best = float(sign * x[j])
    if n < 4 or h <= 0:
        return sign * best
    for a in ((j - 1) % n, j):
        b = (a + 1) % n
        y0, y1, d0, d1 = sign * x[a], sign * x[b], sign * v[a] * h, sign * v[b] * h
        # p(s) = h00 y0 + h10 d0 + h01 y1 + h11 d1, p'(s) = c2 s² + c1 s + c0
        c2, c1, c0 = 6 * y0 + 3 * d0 - 6 * y1 + 3 * d1, -6 * y0 - 4 * d0 + 6 * y1 - 2 * d1, d0
        roots = np.roots([c2, c1, c0]) if abs(c2) > 0 else (np.array([-c0 / c1]) if c1 else np.array([]))
        for s in roots:
            if abs(s.imag) < 1e-12 and 0 <= s.real <= 1:
                s = s.real
                p = (2 * s**3 - 3 * s**2 + 1) * y0 + (s**3 - 2 * s**2 + s) * d0 + (-2 * s**3 + 3 * s**2) * y1 \
                    + (s**3 - s**2) * d1
                best = max(best, float(p))
    return sign * best


def _orbit(count: _Counter, z: np.ndarray, frequency: float, scale: float, value: PeriodMapValue, *, success: bool,
           message: str, iterations: int, stability_tol: float, samples: int, epsilon: float | None) -> ForcedOrbit:
    flow, k = count.flow, count.periods
    n = flow.dimension // 2
    residual = float(np.max(np.abs(value.state - z)) / max(float(np.max(np.abs(z))), 1e-300))
    monodromy = value.d_state
    multipliers = np.linalg.eigvals(monodromy) if monodromy is not None else np.array([], dtype=complex)
    multipliers = multipliers[np.argsort(-np.abs(multipliers), kind="stable")].astype(complex)
    nan = np.full(n, np.nan)
    minimal = k
    if success:  # the one minimal-period rule of every periodic orbit (NNMs too): m repetitions of k/m periods
        size = max(float(np.max(np.abs(z))), 1e-300)
        minimal = k // _repetitions((m for m in range(2, k + 1) if k % m == 0), lambda m: float(np.max(np.abs(
            count(z, frequency, scale, sensitivity=False, periods=k // m).state - z))) / size, residual)
        t, Z = flow.sample(z, frequency, periods=k, forcing_scale=scale, samples=samples)
        X, V = Z[:, :n], Z[:, n:]
        maximum = np.array([_hermite_extreme(t, X[:, i], V[:, i], 1.0) for i in range(n)])
        minimum = np.array([_hermite_extreme(t, X[:, i], V[:, i], -1.0) for i in range(n)])
        phase = frequency * t
        mean = X.mean(axis=0)
        a = 2.0 * (np.cos(phase) @ X) / len(t)
        b = 2.0 * (np.sin(phase) @ X) / len(t)
        peak = np.maximum(np.abs(maximum), np.abs(minimum))
    else:
        maximum = minimum = mean = a = b = peak = nan
    return ForcedOrbit(success, message, float(frequency), float(scale), k, minimal, epsilon, np.array(z, dtype=float),
                       multipliers, bool(success and multipliers.size and np.max(np.abs(multipliers)) <= 1 + stability_tol),
                       maximum, minimum, peak, mean, a, b, np.hypot(a, b), residual, iterations, count.maps,
                       count.steps, count.evaluations, monodromy)


#: a Newton step is at most this many times the size of the state (a guard against jumping far out, where a
#: stiff law such as u³ makes the flow explode); halvings of a step that does not lower the residual
_STEP_LIMIT = 2.0
_HALVINGS = 6


def _newton_fixed(count: _Counter, z: np.ndarray, frequency: float, scale: float, tol: float,
                  max_iterations: int) -> tuple[bool, str, np.ndarray, PeriodMapValue | None, int]:
    """Damped Newton on ``Π(z) − z = 0`` with the Jacobian ``∂Π/∂z − I``; (success, message, z, Π at z, iterations).

    Each step is limited to :data:`_STEP_LIMIT` times the size of the state and halved (up to :data:`_HALVINGS`
    times) until the residual decreases; the last trial's period map serves the next iteration.
    """
    identity = np.eye(len(z))
    value = None
    try:
        value = count(z, frequency, scale)
    except (BudgetError, Cancelled):  # the request's budget or cancel: not a failure of this orbit
        raise
    except LindstedtError as error:
        return False, f"the flow failed at the start: {error}", z, value, 0
    for iteration in range(max_iterations + 1):
        checkpoint("Newton iteration", iteration, max_iterations)
        r = value.state - z
        norm = float(np.max(np.abs(r)))
        size = max(float(np.max(np.abs(z))), float(np.max(np.abs(value.state))), 1e-300)
        if not math.isfinite(norm):
            return False, f"the period map is not finite at iteration {iteration}", z, value, iteration
        if norm <= tol * size:
            return True, f"converged: residual {norm / size:.1e} after {iteration} Newton iterations", z, value, iteration
        if iteration == max_iterations:
            break
        try:
            step = np.linalg.solve(value.d_state - identity, -r)
        except np.linalg.LinAlgError:
            return False, f"singular Jacobian ∂Π/∂z − I (a multiplier +1: a fold) at iteration {iteration}", z, value, iteration
        length = float(np.max(np.abs(step)))
        if length > _STEP_LIMIT * size:
            step *= _STEP_LIMIT * size / length
        for halving in range(_HALVINGS + 1):
            trial = z + step
            try:
                trial_value = count(trial, frequency, scale)
            except (BudgetError, Cancelled):  # the request's budget or cancel: not a failure of this orbit
                raise
            except LindstedtError as error:
                if halving == _HALVINGS:
                    return False, f"the flow failed at iteration {iteration}: {error}", z, value, iteration
                step /= 2
                continue
            trial_norm = float(np.max(np.abs(trial_value.state - trial)))
            if math.isfinite(trial_norm) and (trial_norm < norm or halving == _HALVINGS):
                break
            step /= 2
        z, value = trial, trial_value
    return False, f"no convergence: relative residual {norm / size:.1e} after {max_iterations} Newton iterations", z, value, max_iterations


def forced_periodic_orbit(flow: PeriodMap | ForcedOscillator | ForcedSystem, frequency: float, *,
                          epsilon: float | None = None, initial_state: Any = None, periods: int = 1,
                          forcing_scale: float = 1.0, tol: float = 1e-10, max_iterations: int = 20,
                          transient_periods: int = 100, stability_tol: float = 1e-7,
                          samples: int = 512) -> ForcedOrbit:
    """The periodic response ``Π(z0) = z0`` of period ``k T = 2πk/Ω`` by Newton shooting.

    Parameters
    ----------
    flow : PeriodMap, ForcedOscillator or ForcedSystem
        A flow, or a problem with ``epsilon``: its :func:`forced_flow` (exact for piecewise-linear laws).
    epsilon : float, optional
        ε, when ``flow`` is a problem.
    frequency : float
        Ω > 0 (a :class:`~lindstedt.ParameterError` otherwise).
    initial_state : array_like, shape (2N,), optional
        Newton's start.  Default: the harmonic response of the problem linearised about X = 0; if
        Newton fails from there (near a resonance), from each first-order multiple-scales steady state
        (a 1-dof :class:`~lindstedt.ForcedOscillator`, stable states first), and then after
        ``transient_periods`` periods of the flow.
    periods : int
        k.
    forcing_scale : float
        s (the load is ``ε s F cos Ωt``).
    tol : float
        ``|Π(z0) − z0|∞ ≤ tol · |z0|∞``.
    stability_tol : float
        Stable when every ``|μ| ≤ 1 + stability_tol``.
    samples : int
        Samples of the orbit for its extremes, mean and harmonic.

    Returns
    -------
    ForcedOrbit
        ``success=False`` with the reason when Newton does not converge, or when the converged orbit fails the
        independent check: one period integrated again by DOP853 at rtol 1e-13 (atol scaled to the orbit)
        must not move it by more than ``forced_setup.VERIFY_TOL`` = 1e-6 of its size (far above resonance the
        fixed point amplifies the map's errors by ~(Ω/ω0)²) — never raised.

    Raises
    ------
    ParameterError
        Ω not a positive finite number; or, before any integration, Ω so far below the linear frequencies that
        one period map spans more than ``forced_setup.MAX_NATURAL_PERIODS`` natural periods, or more than
        ``forced_setup.MAX_FREQUENCY_RATIO`` above them (the message names the estimate and the way out).

    Examples
    --------
    >>> from lindstedt.problems.forced import ForcedOscillator
    >>> from lindstedt.numerics.forced_smooth import SmoothForcedFlow
    >>> flow = SmoothForcedFlow(ForcedOscillator("u**3", omega0=1, zeta="1/20", forcing=1), 0.2)
    >>> orbit = forced_periodic_orbit(flow, 1.2)
    >>> orbit.success, orbit.stable, round(float(orbit.amplitude[0]), 6)
    (True, True, 0.472228)
    """
    flow = _flow_of(flow, epsilon)
    frequency = check_forcing_frequency(frequency, "frequency")
    k = _check_periods(periods)
    scale = real_argument(forcing_scale, "forcing_scale")
    tol, stability_tol = _positive(tol, "tol"), _positive(stability_tol, "stability_tol")
    _check_cost(flow, frequency, k)
    count = _Counter(flow, k)
    if initial_state is None:
        z = _linear_guess(flow, frequency, scale)
    else:
        z = _state(initial_state, flow.dimension)
    ok, message, z1, value, iterations = _newton_fixed(count, z, frequency, scale, tol, max_iterations)
    if not ok and initial_state is None and k == 1:  # near resonance: start from the multiple-scales states
        first = message
        for guess in _multiple_scales_guesses(flow, frequency, scale):
            ok, message, z1, value, more = _newton_fixed(count, guess, frequency, scale, tol, max_iterations)
            iterations += more
            if ok:
                message = f"{message} (from a multiple-scales steady state; from the linear response: {first})"
                break
        if not ok:
            message = first
    if not ok and transient_periods:
        first = message
        try:
            state = z
            for _ in range(int(transient_periods)):
                state = count(state, frequency, scale, sensitivity=False).state
            ok, message, z1, value, more = _newton_fixed(count, state, frequency, scale, tol, max_iterations)
            iterations += more
            message = f"{message} (after {transient_periods} periods of transient; from the start: {first})"
        except (BudgetError, Cancelled):  # the request's budget or cancel: not a failure of this orbit
            raise
        except LindstedtError as error:
            message = f"{first}; the transient failed: {error}"
    if value is None or value.d_state is None:
        return _orbit(count, z1, frequency, scale, PeriodMapValue(z1 * np.nan), success=False, message=message,
                      iterations=iterations, stability_tol=stability_tol, samples=samples,
                      epsilon=getattr(flow, "epsilon", None))
    if ok:
        ok, note = _verify(flow, z1, frequency, scale, k, value.d_state)
        message = f"{message}; {note}" if ok else f"{note} ({message})"
    return _orbit(count, z1, frequency, scale, value, success=ok, message=message, iterations=iterations,
                  stability_tol=stability_tol, samples=samples, epsilon=getattr(flow, "epsilon", None))


# --------------------------------------------------------------------------- #
# continuation
# --------------------------------------------------------------------------- #
_KINDS = ("fold", "period-doubling", "neimark-sacker")


class _Continuation:
    """Pseudo-arclength continuation of ``Π(z; λ) − z = 0`` in scaled unknowns ``w = (z, λ) / D``."""

    def __init__(self, flow: PeriodMap, parameter: str, fixed: float, periods: int, scales: np.ndarray,
                 options: dict[str, Any]) -> None:
        self.count = _Counter(flow, periods)
        self.flow, self.parameter, self.fixed, self.D, self.options = flow, parameter, fixed, scales, options
        self.identity = np.eye(flow.dimension)
        self.iterations = 0

    def split(self, w: np.ndarray) -> tuple[np.ndarray, float, float]:
        x = w * self.D
        return (x[:-1], float(x[-1]), self.fixed) if self.parameter == "frequency" else (x[:-1], self.fixed, float(x[-1]))

    def evaluate(self, w: np.ndarray) -> tuple[PeriodMapValue, np.ndarray, np.ndarray]:
        z, frequency, scale = self.split(w)
        if not (math.isfinite(frequency) and frequency > 0 and math.isfinite(scale)):
            raise _Stop(f"the branch reaches Ω = {frequency:.6g} ≤ 0" if frequency <= 0 else "non-finite parameter")
        value = self.count(z, frequency, scale)
        Dz = self.D[:-1]
        d_lambda = value.d_frequency if self.parameter == "frequency" else value.d_forcing
        J = np.column_stack([(value.d_state - self.identity) * Dz[None, :], d_lambda * self.D[-1]]) / Dz[:, None]
        return value, (value.state - z) / Dz, J

    def correct(self, predicted: np.ndarray, tangent: np.ndarray) -> tuple[bool, str, np.ndarray, Any, Any]:
        """Newton on ``[G(w); tᵀ(w − w_pred)] = 0``: (ok, message, w, Π at w, scaled Jacobian at w)."""
        w, tol = predicted.copy(), self.options["tol"]
        self.first_correction = 0.0
        for iteration in range(self.options["max_iterations"] + 1):
            try:
                value, G, J = self.evaluate(w)
            except (LindstedtError, _Stop) as error:
                return False, str(error), w, None, None
            self.iterations += 1
            plane = float(tangent @ (w - predicted))
            norm = float(np.max(np.abs(G)))
            if not math.isfinite(norm):
                return False, "non-finite period map", w, None, None
            if norm <= tol and abs(plane) <= 1e3 * tol:
                return True, f"{iteration} iterations", w, value, J
            if iteration == self.options["max_iterations"]:
                break
            try:
                correction = np.linalg.solve(np.vstack([J, tangent]), -np.r_[G, plane])
                if iteration == 0:
                    self.first_correction = float(np.max(np.abs(correction)))
                w = w + correction
            except np.linalg.LinAlgError:
                return False, "singular augmented Jacobian", w, None, None
        return False, f"corrector: no convergence (scaled residual {norm:.1e})", w, None, None

    def rescale(self, w: np.ndarray, t: np.ndarray, peak: float) -> tuple[np.ndarray, np.ndarray]:
        """``(w, t)`` in the scales of a displacement scale ``peak`` (velocities ``peak · D_v / D_x``)."""
        n = self.flow.dimension // 2
        D = self.D.copy()
        D[:2 * n] *= peak / D[0]
        w, t = w * self.D / D, t * self.D / D
        self.D = D
        return w, t / np.linalg.norm(t)

    @staticmethod
    def tangent(J: np.ndarray, reference: np.ndarray) -> np.ndarray:
        t = np.linalg.svd(J)[2][-1]
        return -t if t @ reference < 0 else t

    def tests(self, value: PeriodMapValue, tangent: np.ndarray) -> dict[str, float]:
        M = value.d_state
        mu = np.linalg.eigvals(M)
        if len(mu) >= 4:
            pairs = [mu[i] * mu[j] - 1 for i in range(len(mu)) for j in range(i + 1, len(mu))]
            psi = float(np.real(np.prod(pairs)))
        else:
            psi = float("nan")  # one degree of freedom: a pair on the unit circle means no damping at all
        return {"fold": float(tangent[-1]), "period-doubling": float(np.linalg.det(M + self.identity)),
                "neimark-sacker": psi}

    def orbit(self, w: np.ndarray, value: PeriodMapValue, message: str, iterations: int = 0) -> ForcedOrbit:
        z, frequency, scale = self.split(w)
        return _orbit(self.count, z, frequency, scale, value, success=True, message=message, iterations=iterations,
                      stability_tol=self.options["stability_tol"], samples=self.options["samples"],
                      epsilon=getattr(self.flow, "epsilon", None))

    def locate(self, kind: str, w: np.ndarray, t: np.ndarray, h: float, f0: float, f1: float,
               index: int) -> Bifurcation | None:
        """Regula falsi (Illinois) on the test function along the arclength σ ∈ [0, h] from w."""
        a, fa, b, fb = 0.0, f0, h, f1
        found = None
        for _ in range(self.options["max_locate"]):
            c = b - fb * (b - a) / (fb - fa)
            if not (min(a, b) < c < max(a, b)):
                c = (a + b) / 2
            ok, _, wc, value, J = self.correct(w + c * t, t)
            if not ok:
                return None
            fc = self.tests(value, self.tangent(J, t))[kind]
            found = (wc, value, fc)
            if fc == 0 or abs(b - a) <= self.options["locate_tol"]:
                break
            if fc * fb < 0:
                a, fa = b, fb
            else:
                fa /= 2
            b, fb = c, fc
            if abs(b - a) <= self.options["locate_tol"]:
                break
        wc, value, fc = found
        multipliers = np.linalg.eigvals(value.d_state)
        if kind == "neimark-sacker":
            close = multipliers[np.argmin(np.abs(np.abs(multipliers) - 1))]
            if abs(close.imag) <= 1e-6:
                return None  # a neutral saddle (real μ_i μ_j = 1), not a bifurcation
        orbit = self.orbit(wc, value, "located")
        z, frequency, scale = self.split(wc)
        return Bifurcation(kind, frequency, orbit.amplitude, z, orbit.multipliers, index, scale, fc)


class _Stop(Exception):
    """The branch leaves the admissible parameters (Ω ≤ 0)."""


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
            "samples": int(samples), "max_angle": max_angle, "max_locate": 60}


#: the step aims at this first corrector correction (the predictor's error, scaled)
_PREDICTOR_ERROR = 5e-3


def _next_step(h: float, iterations: int, first_correction: float, options: dict[str, Any]) -> float:
    """Next step: ``h · sqrt(_PREDICTOR_ERROR / first correction)`` kept in [h/2, 2h]; ≤ 0.6 h after ≥ 5 iterations."""
    factor = min(max(math.sqrt(_PREDICTOR_ERROR / first_correction), 0.5), 2.0) if first_correction > 0 else 2.0
    if iterations >= 5:
        factor = min(factor, 0.6)
    return min(max(h * factor, options["min_step"]), options["max_step"])


def _drive(cont: _Continuation, w0: np.ndarray, t0: np.ndarray, first: ForcedOrbit, value0: PeriodMapValue,
           J0: np.ndarray, *, stop: float | None, bounds: tuple[float, float], rejoin: bool, started: float,
           first_message: str = "", callback: Callable[[int, ForcedOrbit], Any] | None = None) -> FrequencyResponse:
    options = cont.options
    report = callback if callback is not None else (lambda index, orbit: None)
    report(0, first)
    w, t, h = w0, t0, options["step"]
    points, arclength, bifurcations = [first], [0.0], []
    tests = cont.tests(value0, cont.tangent(J0, t0) if J0 is not None else t0)
    rejected, message, success = 0, "", False
    lam_scale = cont.D[-1]
    cos_max = math.cos(math.radians(options["max_angle"]))
    half = cont.count.periods // 2
    gap = None
    try:  # a spent budget or a cancel stops the branch where it is: the points so far are kept
        while True:
            checkpoint("continuation point", len(points), options["max_points"])
            if len(points) >= options["max_points"]:
                message = f"max_points = {options['max_points']} reached at {cont.parameter} = {float(w[-1] * lam_scale):.8g}"
                break
            ok, why, w1, value, J = cont.correct(w + h * t, t)
            if ok:
                t1 = cont.tangent(J, t)
                if t1 @ t < cos_max:
                    ok, why = False, f"the tangent turned by more than {options['max_angle']}°"
            if not ok:
                rejected += 1
                h /= 2
                if h < options["min_step"]:
                    message = (f"step size {h:.2e} below min_step {options['min_step']:.2e} at {cont.parameter} = "
                               f"{float(w[-1] * lam_scale):.8g}: {why}")
                    break
                continue
            lam = float(w1[-1] * lam_scale)
            final = stop is not None and (lam - stop) * (stop - float(w0[-1] * lam_scale)) >= 0
            outside = not (bounds[0] <= lam <= bounds[1])
            new_tests = cont.tests(value, t1)
            for kind in _KINDS:
                f0, f1 = tests[kind], new_tests[kind]
                if math.isfinite(f0) and math.isfinite(f1) and f0 * f1 < 0 and (kind != "neimark-sacker" or min(abs(f0), abs(f1)) > 1e-9):
                    found = cont.locate(kind, w, t, h, f0, f1, len(points) - 1)
                    if found is not None:
                        value_at = found.frequency if cont.parameter == "frequency" else found.forcing_scale
                        if bounds[0] <= value_at <= bounds[1]:
                            bifurcations.append(found)
            if final or outside:
                target = stop if final else (bounds[0] if lam < bounds[0] else bounds[1])
                lam0 = float(w[-1] * lam_scale)
                fraction = (target - lam0) / (lam - lam0) if lam != lam0 else 1.0
                guess = cont.split(w + fraction * (w1 - w))[0]
                z_value, frequency, scale = cont.split(np.r_[w1[:-1], target / lam_scale])
                ok, why, z, value, iterations = _newton_fixed(cont.count, guess, frequency, scale, options["tol"],
                                                              options["max_iterations"])
                cont.iterations += iterations
                if ok:
                    points.append(_orbit(cont.count, z, frequency, scale, value, success=True, message=why,
                                         iterations=iterations, stability_tol=options["stability_tol"],
                                         samples=options["samples"], epsilon=getattr(cont.flow, "epsilon", None)))
                    arclength.append(arclength[-1] + h)
                    report(len(points) - 1, points[-1])
                success = ok  # the branch was followed until it left the range, through stop or (past a fold) start
                if not ok:
                    message = f"the last point at {cont.parameter} = {target:.8g} failed: {why}"
                elif final:
                    message = f"reached stop = {target:.8g}"
                elif rejoin:
                    message = f"reached the end of the range, {cont.parameter} = {target:.8g}"
                else:
                    message = (f"the branch turned back at a fold and left the range through start, {cont.parameter} = "
                               f"{target:.8g}; the responses nearer stop = {stop:.8g} lie on another part of the curve: "
                               f"follow them from {stop:.8g} (or over a wider range)")
                break
            points.append(cont.orbit(w1, value, why, 0))
            arclength.append(arclength[-1] + h)
            report(len(points) - 1, points[-1])
            h = _next_step(h, int(why.split()[0]), cont.first_correction, options)
            w, t, tests = w1, t1, new_tests
            peak = float(np.max(points[-1].amplitude))
            if peak > 2 * cont.D[0]:  # the branch grew: rescale so steps stay relative to its size
                w, t = cont.rescale(w, t, peak)
            if rejoin:
                z = cont.split(w)[0]
                delta = z - cont.count(z, cont.split(w)[1], cont.split(w)[2], sensitivity=False, periods=half).state
                if gap is not None and delta @ gap < 0 and len(points) > 2:
                    success = True
                    message = (f"the period-{cont.count.periods} branch rejoins the period-{half} branch between "
                               f"{cont.parameter} = {points[-2].frequency if cont.parameter == 'frequency' else points[-2].forcing_scale:.8g} "
                               f"and {lam:.8g} (another period doubling)")
                    break
                gap = delta
    except (BudgetError, Cancelled) as stopped:
        message, success = f"stopped after {len(points)} point(s): {stopped}", False
    if success:
        disagreement = _verify_branch(cont, points)
        if disagreement:
            success, message = False, f"{disagreement}; {message}"
    return FrequencyResponse(success, (first_message + "; " if first_message else "") + message, cont.parameter,
                             cont.count.periods, getattr(cont.flow, "epsilon", None), _description(cont.flow),
                             tuple(points), np.array(arclength), tuple(bifurcations), cont.iterations + first.newton_iterations,
                             cont.count.maps + first.flow_evaluations, cont.count.steps + first.steps,
                             cont.count.evaluations + first.evaluations, rejected, time.perf_counter() - started,
                             cont.flow, (cont.parameter, cont.fixed, cont.D, bounds))


#: a branch reported a success has this many of its points (evenly spread, the last included) checked by an
#: independent DOP853 period (forced_setup._verify; its first point was checked by forced_periodic_orbit)
_VERIFIED_POINTS = 6


def _verify_branch(cont: _Continuation, points: list[ForcedOrbit]) -> str:
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
    cont = _Continuation(flow, parameter, fixed, k, D, options)
    w0 = np.r_[first.state, start] / D
    value0, _, J0 = cont.evaluate(w0)
    t0 = np.linalg.svd(J0)[2][-1]
    if t0[-1] * (stop - start) < 0:
        t0 = -t0
    lo, hi = min(start, stop), max(start, stop)
    return _drive(cont, w0, t0, first, value0, J0, stop=stop, bounds=(lo, hi), rejoin=False, started=started,
                  callback=callback)


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
    cont = _Continuation(flow, parameter, fixed, 2 * k, D_old, merged)
    single = _Counter(flow, k)
    frequency, scale = (lam_star, fixed) if parameter == "frequency" else (fixed, lam_star)
    monodromy = single(point.state, frequency, scale).d_state
    mu, vectors = np.linalg.eig(monodromy)
    j = int(np.argmin(np.abs(mu + 1)))
    v = np.real(vectors[:, j])
    t0 = np.r_[v / D_old[:-1], 0.0]
    t0 /= np.linalg.norm(t0)
    w_star = np.r_[point.state, lam_star] / D_old
    ok, why, w1, value1, J1 = cont.correct(w_star + amplitude_step * t0, t0)
    if not ok:
        return FrequencyResponse(False, f"no period-{2 * k} orbit next to the period doubling at {parameter} = "
                                 f"{lam_star:.8g}: {why}", parameter, 2 * k, getattr(flow, "epsilon", None),
                                 _description(flow), (), np.array([]), (), cont.iterations, cont.count.maps,
                                 cont.count.steps, cont.count.evaluations, 0, time.perf_counter() - started, flow)
    first = cont.orbit(w1, value1, f"period-{2 * k} orbit next to the period doubling at {parameter} = {lam_star:.8g}")
    t1 = cont.tangent(J1, t0)
    return _drive(cont, w1, t1, first, value1, J1, stop=None, bounds=(lo, hi), rejoin=True, started=started,
                  first_message=f"switched at the period doubling {parameter} = {lam_star:.10g}")


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
    from .._sweep import sweep_map

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
