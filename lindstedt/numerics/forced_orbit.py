"""One forced periodic orbit: the fixed point ``Π(z0) = z0`` of the period map, by the core's Newton.

For a harmonically forced, damped system (one degree of freedom
``u'' + 2 ζ ω0 u' + ω0² u + ε f(u) = ε s F cos(Ω t)`` or N degrees of freedom
``M X'' + C X' + K X + ε W (A X − b)_+ = ε s P cos(Ω t)``) seen through its period map
``Π(z0; Ω, s) = z(2πk/Ω)`` (:class:`~lindstedt.numerics._period_map.PeriodMap`, ``z = (X, X')``),
:func:`forced_periodic_orbit` solves ``Π(z0) − z0 = 0`` by the one damped Newton of the periodic-orbit core
(:func:`~lindstedt.numerics.newton.newton`) with the exact Jacobian ``∂Π/∂z0 − I`` (the monodromy minus the
identity), refuses up front a Ω whose period maps would span too many natural periods (or lie too far above
them), and verifies a converged orbit by an independent integration of its period → :class:`ForcedOrbit`
with the Floquet multipliers (eigenvalues of the monodromy), stability, the extremes, mean and first harmonic
of every degree of freedom.  Branches of such orbits are :mod:`lindstedt.numerics.forced_response`'s.

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

from typing import Any

import numpy as np

from .._errors import BudgetError, Cancelled, LindstedtError
from ..problems.forced import ForcedOscillator, ForcedSystem, check_forcing_frequency
from ._period_map import PeriodMap, PeriodMapValue, real_argument
from .forced_results import ForcedOrbit
from .newton import Evaluation, newton
from .results import _repetitions
from .forced_setup import (
    _check_cost,
    _check_periods,
    _flow_of,
    _linear_guess,
    _multiple_scales_guesses,
    _positive,
    _state,
    _verify,
)

__all__ = ["forced_periodic_orbit"]


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


def _fixed_point(count: _Counter, z: np.ndarray, frequency: float, scale: float, tol: float,
                 max_iterations: int) -> tuple[bool, str, np.ndarray, PeriodMapValue | None, int]:
    """``Π(z) − z = 0`` by the core's damped Newton; (success, message, z, Π at z, iterations).

    The residual is relative to the size ``max(|z|, |Π(z)|)`` of the state; each step is limited to
    :data:`_STEP_LIMIT` times that size and halved (up to :data:`_HALVINGS` times) until the residual decreases,
    the last halving kept anyway (the period map has no finer scale to fall back on).
    """
    identity = np.eye(len(z))

    def evaluate(state: np.ndarray) -> Evaluation:
        try:
            value = count(state, frequency, scale)
        except (BudgetError, Cancelled):  # the request's budget or cancel: not a failure of this orbit
            raise
        except LindstedtError as error:
            return Evaluation(False, f"the flow failed: {error}")
        size = max(float(np.max(np.abs(state))), float(np.max(np.abs(value.state))), 1e-300)
        return Evaluation(True, "", (value.state - state) / size, (value.d_state - identity) / size,
                          _STEP_LIMIT * size, value, "∂Π/∂z − I has a multiplier +1 (a fold)")

    outcome = newton(evaluate, z, np.ones(len(z)), tol=tol, max_iterations=max_iterations, max_backtracks=_HALVINGS,
                     accept_last=True)
    value = outcome.last.data if outcome.last is not None else None
    message = f"converged: {outcome.message}" if outcome.success else outcome.message
    return outcome.success, message, outcome.unknowns, value, outcome.iterations


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
    ok, message, z1, value, iterations = _fixed_point(count, z, frequency, scale, tol, max_iterations)
    if not ok and initial_state is None and k == 1:  # near resonance: start from the multiple-scales states
        first = message
        for guess in _multiple_scales_guesses(flow, frequency, scale):
            ok, message, z1, value, more = _fixed_point(count, guess, frequency, scale, tol, max_iterations)
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
            ok, message, z1, value, more = _fixed_point(count, state, frequency, scale, tol, max_iterations)
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
