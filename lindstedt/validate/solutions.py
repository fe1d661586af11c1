"""The true solution u(t) of  u'' + ω0² u + ε f(u) = 0,  u(0) = a0 + ε a1,  u'(0) = 0  (or u(0) = u0,
u'(0) = v0 for a problem built from general initial data),  and its exact period.

Reference (:func:`reference_solution`)
    * continuous piecewise-linear f (unilateral springs ``a·(u − b)_+``, several
      gaps, prestress, a linear part): the closed-form arcs of
      :class:`lindstedt.numerics.ExactFlow`, correct to machine precision.  Writing
      ``f(u) = λ_0 u + μ_0 + Σ_j w_j (u − u_j)_+`` (``u_j`` the breakpoints,
      ``w_j`` the slope jumps) and ``u = x + c`` with
      ``(ω0² + ε λ_0) c = −ε μ_0`` turns the equation into
      ``x'' + (ω0² + ε λ_0) x + ε Σ_j w_j (x − (u_j − c))_+ = 0``, a
      :class:`lindstedt.UnilateralSystem` with ``A = 1``,
      ``b_j = u_j − c``, ``W_j = w_j``.  Should a contact state have a
      non-positive stiffness the flow falls back to DOP853 restarted at every
      breakpoint crossing (one smooth linear law per arc);
    * smooth f: DOP853 (``rtol = 1e-12`` by default, :func:`lindstedt.numerics.smooth_flow`).

Period (:func:`exact_period`)
    ``P = 2 t_½`` with ``t_½`` the first positive zero of ``u'``: the motion
    from ``u'(0) = 0`` is even about ``t = 0`` and about every turning point
    (the equation is conservative and reversible).  From ``u'(0) = v0 ≠ 0``:
    ``P = 2 (t_2 − t_1)`` with ``t_1 < t_2`` the first two zeros of ``u'``
    (consecutive turning points).

The private helpers here turn an :class:`~lindstedt.Oscillator` or an
:class:`~lindstedt.Expansion` into floats (ω0, a0, the linear pieces of f) and
check the inputs shared by the rest of :mod:`lindstedt.validate`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, NamedTuple

import numpy as np
import sympy

from .._errors import ProblemError, UnsupportedNonlinearityError
from .._precision import LOCK, locked
from ..render.json import JsonExport
from ..results.expansion import Expansion
from ..numerics.flow import ExactFlow, FlowResult
from ..numerics.smooth import smooth_flow
from ..problems.piecewise_linear import decompose_piecewise_linear
from ..problems.oscillator import DISPLACEMENT, Oscillator
from ..problems.system import UnilateralSystem

__all__ = ["ReferenceSolution", "reference_solution", "ExactPeriod", "exact_period"]

#: default relative / absolute tolerances of DOP853 for smooth f
DEFAULT_RTOL = 1e-12
DEFAULT_ATOL = 1e-14


# --------------------------------------------------------------------------- #
# input checks shared by lindstedt.validate
# --------------------------------------------------------------------------- #
def _as_real(value: Any, name: str) -> float:
    try:
        return float(value)
    except (TypeError, ValueError):
        raise ProblemError(f"{name} must be a real number, got {value!r}") from None


def _as_epsilon(epsilon: Any) -> float:
    value = _as_real(epsilon, "epsilon")
    if not math.isfinite(value) or value < 0:
        raise ProblemError(f"epsilon must be a finite non-negative number, got {epsilon!r}")
    return value


def _as_positive(value: Any, name: str) -> float:
    number = _as_real(value, name)
    if not (math.isfinite(number) and number > 0):
        raise ProblemError(f"{name} must be a positive finite number, got {value!r}")
    return number


def _require_expansion(expansion: Any, caller: str) -> Expansion:
    if not isinstance(expansion, Expansion):
        raise ProblemError(f"{caller} needs an Expansion, got {type(expansion).__name__}")
    return expansion


# --------------------------------------------------------------------------- #
# the numeric problem
# --------------------------------------------------------------------------- #
@dataclass(frozen=True)
class _PiecewiseLaw:
    """f(u) = slopes[j]·u + intercepts[j] on (breakpoints[j−1], breakpoints[j])."""

    breakpoints: tuple[float, ...]
    slopes: tuple[float, ...]
    intercepts: tuple[float, ...]

    @property
    def continuous(self) -> bool:
        """False when f jumps at a breakpoint (a force c·H(u − b)): only the event-driven integration takes it."""
        for point, (s0, s1), (c0, c1) in zip(self.breakpoints, zip(self.slopes, self.slopes[1:]),
                                             zip(self.intercepts, self.intercepts[1:])):
            left, right = s0 * point + c0, s1 * point + c1
            if abs(right - left) > 64 * np.finfo(float).eps * max(1.0, abs(left), abs(right)):
                return False
        return True

    def region(self, u: float, v: float) -> int:
        """Index of the linear piece the motion is in (or entering, on a breakpoint)."""
        index = int(np.searchsorted(self.breakpoints, u, side="right"))
        for j, point in enumerate(self.breakpoints):
            if abs(u - point) <= 8 * np.finfo(float).eps * max(1.0, abs(point)):
                index = j + 1 if v > 0 else j
        return index


@dataclass(frozen=True)
class _NumericProblem:
    omega0: float
    a0: float
    nonlinearity: sympy.Expr  # in DISPLACEMENT only
    law: _PiecewiseLaw | None
    is_non_smooth: bool


def _problem_of(source: Oscillator | Expansion) -> Oscillator:
    if isinstance(source, Expansion):
        return source.problem
    if isinstance(source, Oscillator):
        return source
    raise ProblemError(f"expected an Oscillator or an Expansion, got {type(source).__name__}")


@locked  # the problem's sympy numbers to floats (the integration after it is lock-free)
def _numeric_problem(source: Oscillator | Expansion, values: Mapping[Any, Any] | None) -> _NumericProblem:
    problem = _problem_of(source)
    substitution = problem.numeric_substitution(values)
    omega0 = float(problem.omega0.xreplace(substitution))
    a0 = float(problem.a0.xreplace(substitution))
    nonlinearity = problem.nonlinearity.xreplace(substitution)
    if problem.normalization == "harmonic" and not isinstance(source, Expansion):
        raise ProblemError(
            "with normalization='harmonic' a0 is the first-harmonic amplitude, so u(0) depends on ε; "
            "pass the Expansion (its u(0) is used) instead of the Oscillator"
        )
    law = None
    if problem.is_non_smooth:
        try:
            intervals = decompose_piecewise_linear(nonlinearity, DISPLACEMENT)
        except UnsupportedNonlinearityError:
            pass  # non-smooth but not piecewise linear: DOP853 across the kinks
        else:
            law = _PiecewiseLaw(
                breakpoints=tuple(float(interval.upper) for interval in intervals[:-1]),
                slopes=tuple(float(interval.slope) for interval in intervals),
                intercepts=tuple(float(interval.intercept) for interval in intervals),
            )
    return _NumericProblem(omega0, a0, nonlinearity, law, problem.is_non_smooth)


@locked
def _initial_velocity(source: Oscillator | Expansion) -> float:
    """u'(0): v0 of a problem built from general initial data, else 0 (a release at rest)."""
    problem = _problem_of(source)
    return float(problem.v0) if problem.has_initial_velocity else 0.0


@locked
def _initial_displacement(source: Oscillator | Expansion, numeric: _NumericProblem, epsilon: float,
                          a1: float, values: Mapping[Any, Any] | None) -> float:
    problem = _problem_of(source)
    if problem.has_initial_velocity:
        return float(problem.u0) + epsilon * a1  # u(0) = u0 exactly (a0 is the orbit's turning point)
    if problem.normalization == "harmonic":
        assert isinstance(source, Expansion)
        start = float(np.asarray(source.displacement(0.0, epsilon, values)))
    else:
        substitution = problem.numeric_substitution(values)
        start = numeric.a0 + epsilon * float(problem.a1.xreplace(substitution))  # the problem's own u(0) = a0 + ε a1
    return start + epsilon * a1


# --------------------------------------------------------------------------- #
# reference solution
# --------------------------------------------------------------------------- #
@dataclass(frozen=True, repr=False)
class ReferenceSolution(JsonExport):
    """The true solution of ``u'' + ω0² u + ε f(u) = 0``, ``u(0) = u0``, ``u'(0) = v0`` (0 unless the problem has v0).

    Attributes
    ----------
    success : bool
        Whether the flow reached the last requested time.
    message : str
        What happened.
    method : str
        ``"exact"`` (closed-form arcs), ``"DOP853"`` (smooth f) or
        ``"DOP853-piecewise"`` (restarted at every breakpoint crossing).
    epsilon, initial_displacement : float
        ε and u(0).
    initial_velocity : float
        u'(0) (0 for a release at rest).
    times, displacement, velocity : numpy.ndarray
        The requested times and u, u' there.
    t_final : float
        The dense output :meth:`state` is defined on ``[0, t_final]``.
    n_switches : int
        Breakpoint crossings (contact changes).
    n_evaluations : int
        Gap-function evaluations (exact flow) or right-hand-side evaluations (DOP853).
    n_arcs : int
        Closed-form arcs or DOP853 restarts.
    problem : Oscillator
        The problem solved (exported as its description).

    JSON schema ``lindstedt.reference-solution/1`` (:meth:`to_json`; the
    dense output is not exported).
    """

    SCHEMA = "lindstedt.reference-solution/1"

    success: bool
    message: str
    method: str
    epsilon: float
    initial_displacement: float
    times: np.ndarray
    displacement: np.ndarray
    velocity: np.ndarray
    t_final: float
    n_switches: int
    n_evaluations: int
    n_arcs: int
    _evaluator: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]] = field(repr=False, compare=False)
    problem: Oscillator | None = field(default=None, repr=False, compare=False)
    initial_velocity: float = 0.0

    def state(self, t: Any) -> tuple[np.ndarray, np.ndarray]:
        """Dense output: ``(u(t), u'(t))`` for any times in ``[0, t_final]``, shaped like ``t``."""
        times = np.asarray(t, dtype=float)
        u, v = self._evaluator(times.reshape(-1))
        return u.reshape(times.shape), v.reshape(times.shape)


class _Outcome(NamedTuple):
    """What one way of computing the true solution produced (the fields of ReferenceSolution it decides)."""

    success: bool
    message: str
    method: str
    t_final: float
    evaluator: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]
    n_switches: int
    n_evaluations: int
    n_arcs: int


def _flow_outcome(flow: FlowResult, method: str, message: str, n_switches: int,
                  shift: float | None = None) -> _Outcome:
    """A one-degree-of-freedom FlowResult as an outcome in u (``u = x + shift``)."""

    def evaluator(flat: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        x, v = flow.state(flat)
        return (x[:, 0] if shift is None else x[:, 0] + shift), v[:, 0]

    return _Outcome(flow.success, message, method, flow.t_final, evaluator, n_switches, flow.n_evaluations, flow.n_arcs)


def _exact_piecewise_flow(law: _PiecewiseLaw, omega0: float, epsilon: float, u0: float,
                          t_end: float, v0: float = 0.0) -> tuple[FlowResult, float]:
    """ExactFlow of the shifted system; returns the flow and the shift c (u = x + c)."""
    if not law.continuous:
        raise ProblemError("f jumps at a breakpoint, which no spring of the exact flow represents")
    stiffness = omega0**2 + epsilon * law.slopes[0]
    if not stiffness > 0:
        raise ProblemError(f"ω0² + ε λ_0 = {stiffness} is not positive")
    shift = -epsilon * law.intercepts[0] / stiffness
    jumps = [right - left for left, right in zip(law.slopes, law.slopes[1:])]
    active = [(point - shift, jump) for point, jump in zip(law.breakpoints, jumps) if jump != 0.0]
    if not active:
        system = UnilateralSystem(M=[[1]], K=[[stiffness]])
    elif len(active) == 1 and active[0][1] > 0:
        gap, jump = active[0]
        # w (x − g)_+ = (w x − w g)_+ for w > 0: the convention of UnilateralSystem.one_dof
        system = UnilateralSystem(M=[[1]], K=[[stiffness]], A=[[jump]], b=[jump * gap], W=[[1]])
    else:
        system = UnilateralSystem(
            M=[[1]], K=[[stiffness]], A=[[1]] * len(active), b=[gap for gap, _ in active], W=[[jump for _, jump in active]]
        )
    flow = ExactFlow(system, epsilon).solve([u0 - shift], [v0], t_end)
    return flow, shift


def _piecewise_dop853(law: _PiecewiseLaw, omega0: float, epsilon: float, u0: float, t_end: float,
                      rtol: float, atol: float, v0: float = 0.0) -> _Outcome:
    """DOP853 on one linear piece at a time, restarted at each breakpoint crossing."""
    omega2 = omega0 * omega0
    segments: list[tuple[float, float, Any]] = []
    t, u, v = 0.0, u0, v0
    n_evaluations = n_switches = 0
    success, message = True, ""
    max_segments = 1_000_000
    while t < t_end:
        if len(segments) >= max_segments:
            success, message = False, f"stopped at t = {t} after {max_segments} arcs"
            break
        region = law.region(u, v)
        slope, intercept = law.slopes[region], law.intercepts[region]

        def rhs(_t: float, y: np.ndarray, slope: float = slope, intercept: float = intercept) -> list[float]:
            return [y[1], -omega2 * y[0] - epsilon * (slope * y[0] + intercept)]

        events = []
        # leaving the piece: down through its lower breakpoint or up through its upper one
        for index, direction in ((region - 1, -1), (region, 1)):
            if 0 <= index < len(law.breakpoints):
                event = lambda _t, y, level=law.breakpoints[index]: y[0] - level  # noqa: E731
                event.terminal, event.direction = True, direction
                events.append(event)
        from scipy.integrate import solve_ivp  # here, not at module level: import lindstedt stays light
        solution = solve_ivp(rhs, (t, t_end), [u, v], method="DOP853", rtol=rtol, atol=atol,
                             dense_output=True, events=events or None)
        n_evaluations += int(solution.nfev)
        if not solution.success:
            success, message = False, f"DOP853 failed at t = {t}: {solution.message}"
            break
        segments.append((t, float(solution.t[-1]), solution.sol))
        t_new = float(solution.t[-1])
        u, v = float(solution.y[0, -1]), float(solution.y[1, -1])
        if solution.status == 1:
            n_switches += 1
            # put the state exactly on the breakpoint it reached
            crossed = [point for point in law.breakpoints if abs(u - point) <= 1e-9 * max(1.0, abs(point))]
            if crossed:
                u = crossed[0]
            if t_new <= t:  # no progress: a tangency at the breakpoint
                success, message = False, f"stalled at a tangency with a breakpoint at t = {t}"
                break
        t = t_new
    if success:
        message = f"reached t_end = {t_end} with {n_switches} breakpoint crossings in {len(segments)} DOP853 arcs"
    starts = np.array([start for start, _, _ in segments])

    def evaluator(times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        positions = np.empty(times.size)
        velocities = np.empty(times.size)
        if not segments:
            positions[:], velocities[:] = u0, v0
            return positions, velocities
        index = np.clip(np.searchsorted(starts, times, side="right") - 1, 0, len(segments) - 1)
        for k in np.unique(index):
            selected = index == k
            values = segments[k][2](times[selected])
            positions[selected], velocities[selected] = values[0], values[1]
        return positions, velocities

    return _Outcome(success, message, "DOP853-piecewise", t, evaluator, n_switches, n_evaluations, len(segments))


def reference_solution(
    source: Oscillator | Expansion,
    epsilon: float,
    t: Any,
    *,
    values: Mapping[Any, Any] | None = None,
    a1: float = 0.0,
    rtol: float = DEFAULT_RTOL,
    atol: float = DEFAULT_ATOL,
) -> ReferenceSolution:
    """The true u(t) of ``u'' + ω0² u + ε f(u) = 0``, ``u(0) = a0 + ε a1``, ``u'(0) = 0``
    (``u(0) = u0 + ε a1``, ``u'(0) = v0`` for a problem built from general initial data).

    Parameters
    ----------
    source : Oscillator or Expansion
        The problem (an Expansion's problem is used).  With
        ``normalization="harmonic"`` an Expansion is required: its ``u(0)`` at
        this ε is the initial displacement.  A problem from ``u0``, ``v0`` starts there.
    epsilon : float
        The small parameter ε ≥ 0.
    t : float or array_like
        Times (≥ 0) at which u and u' are returned; the flow runs to ``max(t)``.
    values : mapping, optional
        Numbers for symbols left free (a0, omega0, parameters).
    a1 : float
        Perturbation of the initial displacement (Prop. 2.2–2.3 of the seed).
    rtol, atol : float
        DOP853 tolerances (smooth f and the piecewise fallback).

    Returns
    -------
    ReferenceSolution
        Piecewise-linear f: closed-form arcs at machine precision
        (``method="exact"``); smooth f: DOP853 (``method="DOP853"``).

    Examples
    --------
    >>> import lindstedt, numpy as np
    >>> ref = reference_solution(lindstedt.Oscillator("Max(0, u)", a0=1, omega0=1), 3.0, [0.0, np.pi / 4])
    >>> ref.method, [round(float(x), 12) for x in ref.displacement]   # contact arc: cos(2t)
    ('exact', [1.0, 0.0])
    >>> duffing = reference_solution(lindstedt.Oscillator("u**3", a0=1, omega0=1), 0.0, [np.pi])
    >>> duffing.method, abs(float(duffing.displacement[0]) + 1.0) < 1e-10
    ('DOP853', True)
    >>> kicked = reference_solution(lindstedt.Oscillator("Max(0, u)", u0=0, v0=1, omega0=1), 3.0, [np.pi / 4])
    >>> round(float(kicked.displacement[0]), 12), kicked.initial_velocity   # contact arc: sin(2t)/2
    (0.5, 1.0)
    """
    eps = _as_epsilon(epsilon)
    times = np.asarray(t, dtype=float)
    if times.size == 0 or not np.all(np.isfinite(times)) or float(times.min()) < 0:
        raise ProblemError("t must be a non-empty array of finite, non-negative times")
    a1_value = _as_real(a1, "a1")
    numeric = _numeric_problem(source, values)
    u0 = _initial_displacement(source, numeric, eps, a1_value, values)
    v0 = _initial_velocity(source)
    t_end = float(times.max())
    if numeric.law is not None:
        try:
            flow, shift = _exact_piecewise_flow(numeric.law, numeric.omega0, eps, u0, t_end, v0)
        except ProblemError as error:
            outcome = _piecewise_dop853(numeric.law, numeric.omega0, eps, u0, t_end, rtol, atol, v0)
            outcome = outcome._replace(message=f"{outcome.message} (exact flow unavailable: {error})")
        else:
            outcome = _flow_outcome(flow, "exact", flow.message, flow.n_switches, shift)
    else:
        with LOCK:  # printing the expression evaluates its numbers (sympy)
            function = sympy.lambdify(DISPLACEMENT, numeric.nonlinearity, modules="math")
        flow = smooth_flow(lambda u: float(function(u)), numeric.omega0, eps, u0, v0, t_end, rtol, atol)
        message = flow.message
        if numeric.is_non_smooth:
            message += " (non-smooth f that is not piecewise linear: DOP853 across its kinks, reduced accuracy)"
        outcome = _flow_outcome(flow, "DOP853", message, 0)
    reachable = np.clip(times, 0.0, outcome.t_final)
    u, v = outcome.evaluator(reachable.reshape(-1))
    return ReferenceSolution(
        success=bool(outcome.success),
        message=str(outcome.message),
        method=outcome.method,
        epsilon=eps,
        initial_displacement=u0,
        times=times,
        displacement=u.reshape(times.shape),
        velocity=v.reshape(times.shape),
        t_final=float(outcome.t_final),
        n_switches=int(outcome.n_switches),
        n_evaluations=int(outcome.n_evaluations),
        n_arcs=int(outcome.n_arcs),
        _evaluator=outcome.evaluator,
        problem=_problem_of(source),
        initial_velocity=v0,
    )


# --------------------------------------------------------------------------- #
# exact period
# --------------------------------------------------------------------------- #
@dataclass(frozen=True, repr=False)
class ExactPeriod(JsonExport):
    """Exact period of the true solution.

    Attributes
    ----------
    success, message
        As usual.
    period : float
        ``P = 2 t_½`` with ``t_½`` the first positive zero of u'.
    half_period : float
        ``t_½``.
    n_root_evaluations : int
        Dense-output evaluations used by Brent's method.
    reference_method : str
        How the true solution was computed.
    problem : Oscillator
        The problem solved (exported as its description).

    JSON schema ``lindstedt.exact-period/1`` (:meth:`to_json`).
    """

    SCHEMA = "lindstedt.exact-period/1"

    success: bool
    message: str
    period: float
    half_period: float
    n_root_evaluations: int
    reference_method: str
    problem: Oscillator | None = field(default=None, repr=False, compare=False)


def exact_period(
    source: Oscillator | Expansion,
    epsilon: float,
    *,
    values: Mapping[Any, Any] | None = None,
    a1: float = 0.0,
    rtol: float = DEFAULT_RTOL,
    atol: float = DEFAULT_ATOL,
) -> ExactPeriod:
    """Period of the true solution: twice the first positive zero of u'.

    The motion from ``u'(0) = 0`` is even about ``t = 0`` and about each
    turning point (the equation is conservative and reversible), so the
    second turning point is at half the period.  From ``u'(0) = v0 ≠ 0`` (a problem
    built from u0, v0) the half period is the time between the first two zeros of u'.

    Examples
    --------
    >>> import lindstedt
    >>> p = exact_period(lindstedt.Oscillator("Max(0, u)", a0=1, omega0=1), 3.0)
    >>> round(p.period, 12) == round(np.pi / 2 + np.pi, 12)      # π/ω' + π/ω0 with ω' = 2
    True
    >>> kicked = exact_period(lindstedt.Oscillator("Max(0, u)", u0="-1/2", v0=1, omega0=1), 3.0)
    >>> round(kicked.period, 12) == round(np.pi / 2 + np.pi, 12)  # the same orbit family: P does not depend on the amplitude
    True
    """
    numeric = _numeric_problem(source, values)
    linear_period = 2 * math.pi / numeric.omega0
    horizon = 2.0 * linear_period
    reference = reference_solution(source, epsilon, [horizon], values=values, a1=a1, rtol=rtol, atol=atol)
    grid = np.linspace(0.0, horizon, 2049)
    _, velocity = reference.state(grid)
    start_sign = np.sign(velocity[1:8][np.nonzero(velocity[1:8])[0][0]]) if np.any(velocity[1:8]) else 0.0
    changes = np.flatnonzero(np.sign(velocity[1:]) == -start_sign)
    counter = [0]

    def speed(t: float) -> float:
        counter[0] += 1
        return float(reference.state(np.array([t]))[1][0])

    moving = _initial_velocity(source) != 0.0
    if moving:  # from u'(0) ≠ 0: the first two zeros of u' are consecutive turning points
        start_sign = np.sign(velocity[0])
        first = np.flatnonzero(np.sign(velocity[1:]) == -start_sign)
        second = np.flatnonzero(np.sign(velocity[1:]) == start_sign)
        second = second[second > first[0]] if first.size else second[:0]
        changes = second
    if start_sign == 0 or changes.size == 0:
        return ExactPeriod(False, "u' has no positive zero within two linear periods (rest state or too large ε?)",
                           math.nan, math.nan, counter[0], reference.method, problem=_problem_of(source))

    def zero(index: int) -> float:
        import scipy.optimize  # here, not at module level: import lindstedt stays light
        return float(scipy.optimize.brentq(speed, grid[index], grid[index + 1], xtol=1e-15, rtol=4 * np.finfo(float).eps))

    half = zero(int(changes[0]))
    if moving:
        half -= zero(int(first[0]))
    return ExactPeriod(
        success=reference.success,
        message=f"P = {2 * half:.16g} ({reference.method}); {reference.message}",
        period=2 * half,
        half_period=half,
        n_root_evaluations=counter[0],
        reference_method=reference.method,
        problem=_problem_of(source),
    )
