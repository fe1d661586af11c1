"""Validation of Lindstedt–Poincaré expansions against the true solution of

    u'' + ω0² u + ε f(u) = 0,    u(0) = a0 + ε a1,   u'(0) = 0.

Reference (:func:`reference_solution`)
    * continuous piecewise-linear f (unilateral springs ``a·(u − b)_+``, several
      gaps, prestress, a linear part): the closed-form arcs of
      :class:`~lindstedt._flow.ExactFlow`, correct to machine precision.  Writing
      ``f(u) = λ_0 u + μ_0 + Σ_j w_j (u − u_j)_+`` (``u_j`` the breakpoints,
      ``w_j`` the slope jumps) and ``u = x + c`` with
      ``(ω0² + ε λ_0) c = −ε μ_0`` turns the equation into
      ``x'' + (ω0² + ε λ_0) x + ε Σ_j w_j (x − (u_j − c))_+ = 0``, a
      :class:`~lindstedt._system.UnilateralSystem` with ``A = 1``,
      ``b_j = u_j − c``, ``W_j = w_j``.  Should a contact state have a
      non-positive stiffness the flow falls back to DOP853 restarted at every
      breakpoint crossing (one smooth linear law per arc);
    * smooth f: DOP853 (``rtol = 1e-12`` by default, :func:`~lindstedt._flow.smooth_flow`).

Error (:func:`expansion_error`)
    ``e(t) = u_N(t) − u(t)`` for the order-N expansion ``u_N`` (waveforms
    v_0..v_N, frequency through ω_{N+1}), and its phase-plane size
    ``ρ(t) = ((u_N − u)² + ((u_N' − u')/ω0)²)^{1/2}``, which has no zeros at
    the turning points and so grows monotonically with a phase drift.

What is measurable, and what theory predicts
    * Simple contact (or smooth f), order N: ``u_N − u = ε^{N+1} v_{N+1}(ωt)
      + O(ε^{N+2} t)`` — a bounded part plus the drift of the first neglected
      frequency term ω_{N+2}.  Hence ``max_{[0, C/ε]} |e| ~ ε^{N+1}``
      (:func:`fitted_convergence_order`: slope N + 1), and the first time
      ``T_ε`` at which ``ρ`` exceeds ``C ε^{N+1}`` (C above the bounded part)
      is ``(C − |v_{N+1}|)/(|ω_{N+2}| a0) · ε^{-1}``: exponent −1.
    * Grazing, ``|a0| = |b|`` with ``u(0) = a0 + ε a1`` just beyond the gap
      (Prop. 2.3): the expansion is the linear motion
      ``(a0 + ε a1) cos(ω0 t)``.  Each period the mass dips ``ε a1`` into the
      spring during a time ``~ (ε a1/|b|)^{1/2}/ω0``; the force there is
      ``O(ε²)``, and — because the stiffer contact arc is exactly compensated
      at first order by the shift of its centre — the period changes by only
      ``ΔP = O(ε · ε a1 · (ε a1)^{1/2}) = O(ε^{5/2})`` (measured here:
      ``ΔP ≈ −1.88 ε^{5/2}`` for ``a = b = a1 = ω0 = 1``).  So
      ``ρ(t) ≈ |a0| ω0 |ΔP| t / P`` (a staircase: between contacts both
      motions are free at ω0 and ρ is constant): the error stays ``O(ε²)`` exactly while
      ``t = O(ε^{-1/2})``, and ``T_ε`` (first ``ρ > C ε²``) scales like
      ``ε^{-1/2}``.  Pushing the order higher does not help (the true
      correction ε^{5/2} is not analytic), so the grazing threshold is always
      ``C ε²``.

Contact measure (:func:`contact_measure`, Lemma 3.2)
    ``μ_ε(T) = |{t ∈ [0, T] : |u(t) − b| ≤ ε M}|``.  Where ``u − b`` has
    simple roots each crossing contributes ``2 ε M / |u'|``: ``μ_ε(T) = O(ε T)``.
    At a double root (grazing) the band is crossed with ``|u'| ~ ε^{1/2}``:
    ``μ_ε(T) = O(ε^{1/2} T)``.  :func:`fitted_contact_measure_order` fits
    ``log(μ_ε(T)/T)`` against ``log ε`` on the true solutions: slope 1 or 1/2.

Every numerical result is a frozen dataclass with ``success``, ``message``
and counters (samples, reference solves, switches, right-hand-side or gap
evaluations).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, Sequence

import numpy as np
import scipy.optimize
import sympy
from scipy.integrate import solve_ivp

from ._errors import ProblemError, UnsupportedNonlinearityError
from ._expansion import Expansion
from ._flow import ExactFlow, FlowResult, smooth_flow
from ._piecewise_linear import decompose_piecewise_linear
from ._problem import DISPLACEMENT, Oscillator
from ._system import UnilateralSystem

__all__ = [
    "ReferenceSolution",
    "reference_solution",
    "ExpansionError",
    "expansion_error",
    "ConvergenceFit",
    "fitted_convergence_order",
    "ValidityFit",
    "fitted_validity_exponent",
    "ContactMeasure",
    "contact_measure",
    "ContactMeasureFit",
    "fitted_contact_measure_order",
    "LogLogFit",
    "loglog_fit",
]

#: default relative / absolute tolerances of DOP853 for smooth f
DEFAULT_RTOL = 1e-12
DEFAULT_ATOL = 1e-14
#: default samples per linear period 2π/ω0 on error grids
DEFAULT_SAMPLES_PER_PERIOD = 64
#: an error below this many machine epsilons × amplitude is rounding, not truncation
_ROUNDING_FLOOR = 1e3 * np.finfo(float).eps


# --------------------------------------------------------------------------- #
# small shared pieces
# --------------------------------------------------------------------------- #
@dataclass(frozen=True)
class LogLogFit:
    """Least-squares line ``log y = slope · log x + intercept``.

    Attributes
    ----------
    slope, intercept : float
        Fitted coefficients (natural logarithms).
    standard_error : float
        Standard error of the slope, ``(Σr²/(n−2))^{1/2} / (Σ(x − x̄)²)^{1/2}``
        with r the residuals of the logarithms; NaN for two points.
    n_points : int
        Number of points fitted.
    """

    slope: float
    intercept: float
    standard_error: float
    n_points: int


def loglog_fit(x: Sequence[float], y: Sequence[float]) -> LogLogFit:
    """Fit ``log y = slope · log x + intercept`` by least squares.

    Examples
    --------
    >>> fit = loglog_fit([0.1, 0.01, 0.001], [2e-2, 2e-4, 2e-6])
    >>> round(fit.slope, 12), round(math.exp(fit.intercept), 12), fit.standard_error < 1e-12
    (2.0, 2.0, True)
    """
    log_x = np.log(np.asarray(x, dtype=float))
    log_y = np.log(np.asarray(y, dtype=float))
    if log_x.size != log_y.size or log_x.size < 2:
        raise ProblemError("a log-log fit needs at least two (x, y) pairs of equal length")
    if not (np.all(np.isfinite(log_x)) and np.all(np.isfinite(log_y))):
        raise ProblemError("a log-log fit needs positive finite x and y")
    centred = log_x - log_x.mean()
    spread = float(centred @ centred)
    if spread == 0.0:
        raise ProblemError("a log-log fit needs at least two distinct x values")
    slope = float(centred @ (log_y - log_y.mean())) / spread
    intercept = float(log_y.mean() - slope * log_x.mean())
    n = log_x.size
    if n > 2:
        residuals = log_y - (slope * log_x + intercept)
        standard_error = math.sqrt(float(residuals @ residuals) / (n - 2) / spread)
    else:
        standard_error = math.nan
    return LogLogFit(slope, intercept, standard_error, n)


def _as_epsilons(epsilons: Sequence[float]) -> np.ndarray:
    values = np.asarray(epsilons, dtype=float).reshape(-1)
    if values.size < 2 or not np.all(np.isfinite(values)) or np.any(values <= 0):
        raise ProblemError(f"epsilons must be at least two positive finite numbers, got {list(values)}")
    if np.unique(values).size != values.size:
        raise ProblemError("epsilons must be distinct")
    return values


def _as_epsilon(epsilon: Any) -> float:
    try:
        value = float(epsilon)
    except (TypeError, ValueError):
        raise ProblemError(f"epsilon must be a real number, got {epsilon!r}") from None
    if not math.isfinite(value) or value < 0:
        raise ProblemError(f"epsilon must be a finite non-negative number, got {epsilon!r}")
    return value


# --------------------------------------------------------------------------- #
# the numeric problem
# --------------------------------------------------------------------------- #
@dataclass(frozen=True)
class _PiecewiseLaw:
    """f(u) = slopes[j]·u + intercepts[j] on (breakpoints[j−1], breakpoints[j])."""

    breakpoints: tuple[float, ...]
    slopes: tuple[float, ...]
    intercepts: tuple[float, ...]

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


def _numeric_problem(source: Oscillator | Expansion, values: Mapping[Any, Any] | None) -> _NumericProblem:
    problem = _problem_of(source)
    substitution = problem.numeric_substitution(values)
    omega0 = float(problem.omega0.xreplace(substitution))
    a0 = float(problem.a0.xreplace(substitution))
    nonlinearity = sympy.sympify(problem.nonlinearity, strict=True).xreplace(substitution)
    if problem.normalization == "harmonic":
        if not isinstance(source, Expansion):
            raise ProblemError(
                "with normalization='harmonic' a0 is the first-harmonic amplitude, so u(0) depends on ε; "
                "pass the Expansion (its u(0) is used) instead of the Oscillator"
            )
    law = None
    if problem.is_non_smooth:
        try:
            intervals = decompose_piecewise_linear(nonlinearity, DISPLACEMENT)
        except UnsupportedNonlinearityError:
            intervals = None
        if intervals is not None:
            law = _PiecewiseLaw(
                breakpoints=tuple(float(interval.upper) for interval in intervals[:-1]),
                slopes=tuple(float(interval.slope) for interval in intervals),
                intercepts=tuple(float(interval.intercept) for interval in intervals),
            )
    return _NumericProblem(omega0, a0, nonlinearity, law, problem.is_non_smooth)


def _initial_displacement(source: Oscillator | Expansion, numeric: _NumericProblem, epsilon: float,
                          a1: float, values: Mapping[Any, Any] | None) -> float:
    problem = _problem_of(source)
    if problem.normalization == "harmonic":
        assert isinstance(source, Expansion)
        start = float(np.asarray(source.displacement(0.0, epsilon, values)))
    else:
        start = numeric.a0
    return start + epsilon * a1


# --------------------------------------------------------------------------- #
# reference solution
# --------------------------------------------------------------------------- #
@dataclass(frozen=True)
class ReferenceSolution:
    """The true solution of ``u'' + ω0² u + ε f(u) = 0``, ``u(0) = u0``, ``u'(0) = 0``.

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
    """

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

    def state(self, t: Any) -> tuple[np.ndarray, np.ndarray]:
        """Dense output: ``(u(t), u'(t))`` for any times in ``[0, t_final]``, shaped like ``t``."""
        times = np.asarray(t, dtype=float)
        u, v = self._evaluator(times.reshape(-1))
        return u.reshape(times.shape), v.reshape(times.shape)


def _exact_piecewise_flow(law: _PiecewiseLaw, omega0: float, epsilon: float, u0: float,
                          t_end: float) -> tuple[FlowResult, float]:
    """ExactFlow of the shifted system; returns the flow and the shift c (u = x + c)."""
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
    flow = ExactFlow(system, epsilon).solve([u0 - shift], [0.0], t_end)
    return flow, shift


def _piecewise_dop853(law: _PiecewiseLaw, omega0: float, epsilon: float, u0: float, t_end: float,
                      rtol: float, atol: float) -> dict[str, Any]:
    """DOP853 on one linear piece at a time, restarted at each breakpoint crossing."""
    omega2 = omega0 * omega0
    segments: list[tuple[float, float, Any]] = []
    t, u, v = 0.0, u0, 0.0
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
        if region > 0:
            lower = law.breakpoints[region - 1]
            event = lambda _t, y, lower=lower: y[0] - lower  # noqa: E731
            event.terminal, event.direction = True, -1
            events.append(event)
        if region < len(law.breakpoints):
            upper = law.breakpoints[region]
            event = lambda _t, y, upper=upper: y[0] - upper  # noqa: E731
            event.terminal, event.direction = True, 1
            events.append(event)
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
            positions[:], velocities[:] = u0, 0.0
            return positions, velocities
        index = np.clip(np.searchsorted(starts, times, side="right") - 1, 0, len(segments) - 1)
        for k in np.unique(index):
            selected = index == k
            values = segments[k][2](times[selected])
            positions[selected], velocities[selected] = values[0], values[1]
        return positions, velocities

    return {"success": success, "message": message, "t_final": t, "evaluator": evaluator,
            "n_switches": n_switches, "n_evaluations": n_evaluations, "n_arcs": len(segments)}


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
    """The true u(t) of ``u'' + ω0² u + ε f(u) = 0``, ``u(0) = a0 + ε a1``, ``u'(0) = 0``.

    Parameters
    ----------
    source : Oscillator or Expansion
        The problem (an Expansion's problem is used).  With
        ``normalization="harmonic"`` an Expansion is required: its ``u(0)`` at
        this ε is the initial displacement.
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
    """
    eps = _as_epsilon(epsilon)
    times = np.asarray(t, dtype=float)
    if times.size == 0 or not np.all(np.isfinite(times)) or float(times.min()) < 0:
        raise ProblemError("t must be a non-empty array of finite, non-negative times")
    try:
        a1_value = float(a1)
    except (TypeError, ValueError):
        raise ProblemError(f"a1 must be a real number, got {a1!r}") from None
    numeric = _numeric_problem(source, values)
    u0 = _initial_displacement(source, numeric, eps, a1_value, values)
    t_end = float(times.max())
    flow_result: dict[str, Any] | None = None
    if numeric.law is not None:
        try:
            flow, shift = _exact_piecewise_flow(numeric.law, numeric.omega0, eps, u0, t_end)
        except ProblemError as error:
            flow_result = _piecewise_dop853(numeric.law, numeric.omega0, eps, u0, t_end, rtol, atol)
            flow_result["method"] = "DOP853-piecewise"
            flow_result["message"] += f" (exact flow unavailable: {error})"
        else:
            def evaluator(flat: np.ndarray, flow: FlowResult = flow, shift: float = shift) -> tuple[np.ndarray, np.ndarray]:
                x, v = flow.state(flat)
                return x[:, 0] + shift, v[:, 0]

            flow_result = {
                "success": flow.success, "message": flow.message, "method": "exact", "t_final": flow.t_final,
                "evaluator": evaluator, "n_switches": flow.n_switches, "n_evaluations": flow.n_evaluations,
                "n_arcs": flow.n_arcs,
            }
    else:
        function = sympy.lambdify(DISPLACEMENT, numeric.nonlinearity, modules="math")
        flow = smooth_flow(lambda u: float(function(u)), numeric.omega0, eps, u0, 0.0, t_end, rtol, atol)

        def evaluator(flat: np.ndarray, flow: FlowResult = flow) -> tuple[np.ndarray, np.ndarray]:
            x, v = flow.state(flat)
            return x[:, 0], v[:, 0]

        message = flow.message
        if numeric.is_non_smooth:
            message += " (non-smooth f that is not piecewise linear: DOP853 across its kinks, reduced accuracy)"
        flow_result = {
            "success": flow.success, "message": message, "method": "DOP853", "t_final": flow.t_final,
            "evaluator": evaluator, "n_switches": 0, "n_evaluations": flow.n_evaluations, "n_arcs": flow.n_arcs,
        }
    reachable = np.clip(times, 0.0, flow_result["t_final"])
    u, v = flow_result["evaluator"](reachable.reshape(-1))
    return ReferenceSolution(
        success=bool(flow_result["success"]),
        message=str(flow_result["message"]),
        method=flow_result["method"],
        epsilon=eps,
        initial_displacement=u0,
        times=times,
        displacement=u.reshape(times.shape),
        velocity=v.reshape(times.shape),
        t_final=float(flow_result["t_final"]),
        n_switches=int(flow_result["n_switches"]),
        n_evaluations=int(flow_result["n_evaluations"]),
        n_arcs=int(flow_result["n_arcs"]),
        _evaluator=flow_result["evaluator"],
    )


# --------------------------------------------------------------------------- #
# expansion error
# --------------------------------------------------------------------------- #
@dataclass(frozen=True)
class ExpansionError:
    """``e(t) = u_N(t) − u(t)`` on a uniform grid of ``[0, t_end]``.

    Attributes
    ----------
    success : bool
        Whether the reference reached ``t_end`` and every value is finite.
    message : str
        What happened.
    epsilon, t_end, a1 : float
        The inputs.
    times : numpy.ndarray
        The grid (``n_samples`` points, both ends included).
    error : numpy.ndarray
        ``u_N(t) − u(t)`` (signed).
    phase_error : numpy.ndarray
        ``((u_N − u)² + ((u_N' − u')/ω0)²)^{1/2}``, the size of the error in
        the phase plane (no zeros at turning points).
    max_error : float
        ``max |e|`` on the grid.
    time_of_max : float
        Where it is reached.
    max_phase_error : float
        ``max ρ`` on the grid.
    reference_method : str
        How u was computed (see :class:`ReferenceSolution`).
    n_samples, n_switches, n_evaluations : int
        Grid size and the reference's counters.
    """

    success: bool
    message: str
    epsilon: float
    t_end: float
    a1: float
    times: np.ndarray
    error: np.ndarray
    phase_error: np.ndarray
    max_error: float
    time_of_max: float
    max_phase_error: float
    reference_method: str
    n_samples: int
    n_switches: int
    n_evaluations: int


def _approximation(expansion: Expansion, epsilon: float, times: np.ndarray, values: Mapping[Any, Any] | None,
                   a1: float) -> tuple[np.ndarray, np.ndarray]:
    """u_N and u_N' (plus the O(ε) response ε a1 cos(ω t) to the perturbed initial datum)."""
    u = np.asarray(expansion.displacement(times, epsilon, values), dtype=float)
    v = np.asarray(expansion.velocity(times, epsilon, values), dtype=float)
    if a1:
        omega = float(expansion.frequency(epsilon, values, order=expansion.order + 1))
        u = u + epsilon * a1 * np.cos(omega * times)
        v = v - epsilon * a1 * omega * np.sin(omega * times)
    return u, v


def _check_a1(expansion: Expansion, a1: float) -> float:
    try:
        value = float(a1)
    except (TypeError, ValueError):
        raise ProblemError(f"a1 must be a real number, got {a1!r}") from None
    if value and expansion.order > 0 and expansion.regime not in ("grazing", "no contact"):
        raise ProblemError(
            "a1 ≠ 0 adds only the O(ε) response ε a1 cos(ω t), which is consistent for an order-0 expansion "
            "or in the grazing / no-contact regimes (where the expansion is linear); for a "
            f"{expansion.regime!r} expansion of order {expansion.order} expand at the amplitude a0 + ε a1 instead "
            "(symbolic a0 and values={'a0': a0 + eps*a1})"
        )
    return value


def _default_samples(t_end: float, omega0: float, samples_per_period: int = DEFAULT_SAMPLES_PER_PERIOD) -> int:
    return max(1001, int(math.ceil(samples_per_period * t_end * omega0 / (2 * math.pi))) + 1)


def expansion_error(
    expansion: Expansion,
    epsilon: float,
    t_end: float,
    samples: int | None = None,
    *,
    values: Mapping[Any, Any] | None = None,
    a1: float = 0.0,
    rtol: float = DEFAULT_RTOL,
    atol: float = DEFAULT_ATOL,
) -> ExpansionError:
    """Error of the order-N expansion against the true solution on ``[0, t_end]``.

    Parameters
    ----------
    expansion : Expansion
        The approximation ``u_N(t) = Σ_{k≤N} ε^k v_k(ω t)``, ω through ω_{N+1}.
    epsilon : float
        ε > 0.
    t_end : float
        End of the window (> 0).
    samples : int, optional
        Grid points (both ends included).  Default: 64 per linear period
        ``2π/ω0``, at least 1001.
    values : mapping, optional
        Numbers for symbols left free.
    a1 : float
        The true solution starts at ``u(0) = a0 + ε a1``; the approximation
        gains ``ε a1 cos(ω t)``.  Allowed for order 0 and in the grazing and
        no-contact regimes (Prop. 2.3: ``(a0 + ε a1) cos(ω0 t)``), where that is
        the consistent expansion.
    rtol, atol : float
        DOP853 tolerances of the reference for smooth f.

    Returns
    -------
    ExpansionError

    Examples
    --------
    >>> import lindstedt
    >>> e = lindstedt.expand("Max(0, u)", order=1, a0=1, omega0=1)
    >>> result = expansion_error(e, 0.01, 100.0)
    >>> result.success, result.max_error < 2e-4, result.reference_method
    (True, True, 'exact')
    """
    if not isinstance(expansion, Expansion):
        raise ProblemError(f"expansion_error needs an Expansion, got {type(expansion).__name__}")
    eps = _as_epsilon(epsilon)
    a1_value = _check_a1(expansion, a1)
    try:
        t_end_value = float(t_end)
    except (TypeError, ValueError):
        raise ProblemError(f"t_end must be a positive number, got {t_end!r}") from None
    if not (math.isfinite(t_end_value) and t_end_value > 0):
        raise ProblemError(f"t_end must be a positive finite number, got {t_end!r}")
    numeric = _numeric_problem(expansion, values)
    n = _default_samples(t_end_value, numeric.omega0) if samples is None else int(samples)
    if n < 2:
        raise ProblemError(f"samples must be at least 2, got {samples!r}")
    times = np.linspace(0.0, t_end_value, n)
    reference = reference_solution(expansion, eps, times, values=values, a1=a1_value, rtol=rtol, atol=atol)
    u_approx, v_approx = _approximation(expansion, eps, times, values, a1_value)
    error = u_approx - reference.displacement
    phase_error = np.hypot(error, (v_approx - reference.velocity) / numeric.omega0)
    finite = bool(np.all(np.isfinite(error)) and np.all(np.isfinite(phase_error)))
    index = int(np.argmax(np.abs(error))) if finite else 0
    success = reference.success and finite
    if success:
        message = f"max |u_N − u| = {float(np.abs(error[index])):.3e} at t = {times[index]:.6g} ({n} samples)"
    elif not finite:
        message = "non-finite values in the expansion or the reference"
    else:
        message = f"reference failed: {reference.message}"
    return ExpansionError(
        success=success,
        message=message,
        epsilon=eps,
        t_end=t_end_value,
        a1=a1_value,
        times=times,
        error=error,
        phase_error=phase_error,
        max_error=float(np.abs(error[index])),
        time_of_max=float(times[index]),
        max_phase_error=float(np.max(phase_error)) if finite else math.nan,
        reference_method=reference.method,
        n_samples=n,
        n_switches=reference.n_switches,
        n_evaluations=reference.n_evaluations,
    )


# --------------------------------------------------------------------------- #
# convergence order
# --------------------------------------------------------------------------- #
_T_END_RULES: dict[str, Callable[[float], float]] = {
    "1/eps": lambda eps: 1.0 / eps,
    "1/sqrt(eps)": lambda eps: 1.0 / math.sqrt(eps),
    "fixed": lambda eps: 1.0,
}


def _t_end_function(rule: str | Callable[[float], float], constant: float) -> tuple[Callable[[float], float], str]:
    if callable(rule):
        return (lambda eps: float(rule(eps))), getattr(rule, "__name__", "callable")
    if rule not in _T_END_RULES:
        raise ProblemError(f"t_end_rule must be one of {sorted(_T_END_RULES)} or a callable eps -> t_end, got {rule!r}")
    base = _T_END_RULES[rule]
    return (lambda eps: constant * base(eps)), f"{constant:g}*{rule}"


@dataclass(frozen=True)
class ConvergenceFit:
    """Slope of ``log max_{[0, t_end(ε)]} |u_N − u|`` against ``log ε``.

    Attributes
    ----------
    success : bool
        All reference solves succeeded and every error is above rounding.
    message : str
        What happened.
    slope, intercept, standard_error : float
        The least-squares fit (natural logs); ``standard_error`` of the slope
        (NaN for two points).
    expected_slope : int
        N + 1 (simple contact or smooth f; not meaningful at grazing, where the
        error of ``a0 = b`` exactly vanishes).
    epsilons, max_errors, t_ends : numpy.ndarray
        The data.
    t_end_rule : str
        How the windows were chosen.
    n_reference_solves, n_samples, n_switches, n_evaluations : int
        Totals over the ε values.
    """

    success: bool
    message: str
    slope: float
    intercept: float
    standard_error: float
    expected_slope: int
    epsilons: np.ndarray
    max_errors: np.ndarray
    t_ends: np.ndarray
    t_end_rule: str
    n_reference_solves: int
    n_samples: int
    n_switches: int
    n_evaluations: int


def fitted_convergence_order(
    expansion: Expansion,
    epsilons: Sequence[float],
    t_end_rule: str | Callable[[float], float] = "1/eps",
    *,
    t_end_constant: float = 1.0,
    samples_per_period: int = DEFAULT_SAMPLES_PER_PERIOD,
    values: Mapping[Any, Any] | None = None,
    a1: float = 0.0,
    rtol: float = DEFAULT_RTOL,
    atol: float = DEFAULT_ATOL,
) -> ConvergenceFit:
    """Fit the slope of ``log max|u_N − u|`` over ``[0, C/ε]`` against ``log ε``.

    Theory (simple contact or smooth f): ``u_N − u = ε^{N+1} v_{N+1} +
    O(ε^{N+2} t)``, so the slope is ``N + 1`` on windows ``t ≤ C/ε``.

    Parameters
    ----------
    expansion : Expansion
        Order-N expansion.
    epsilons : sequence of float
        At least two distinct positive values (three or more for a standard error).
    t_end_rule : {"1/eps", "1/sqrt(eps)", "fixed"} or callable
        Window length ``C/ε``, ``C/√ε``, ``C``, or any ``eps -> t_end``.
    t_end_constant : float
        The constant C of the named rules.
    samples_per_period : int
        Grid density per linear period.
    values, a1, rtol, atol
        As in :func:`expansion_error`.

    Returns
    -------
    ConvergenceFit

    Examples
    --------
    >>> import lindstedt
    >>> e = lindstedt.expand("Max(0, u - 1/3)", order=1, a0=1, omega0=1)
    >>> fit = fitted_convergence_order(e, [0.04, 0.02, 0.01])
    >>> fit.success, abs(fit.slope - 2) < 0.15
    (True, True)
    """
    if not isinstance(expansion, Expansion):
        raise ProblemError(f"fitted_convergence_order needs an Expansion, got {type(expansion).__name__}")
    eps_values = _as_epsilons(epsilons)
    t_end_of, rule_name = _t_end_function(t_end_rule, float(t_end_constant))
    numeric = _numeric_problem(expansion, values)
    max_errors, t_ends = [], []
    n_samples = n_switches = n_evaluations = 0
    failures = []
    for eps in eps_values:
        t_end = t_end_of(float(eps))
        t_ends.append(t_end)
        samples = _default_samples(t_end, numeric.omega0, samples_per_period)
        result = expansion_error(expansion, float(eps), t_end, samples, values=values, a1=a1, rtol=rtol, atol=atol)
        max_errors.append(result.max_error)
        n_samples += result.n_samples
        n_switches += result.n_switches
        n_evaluations += result.n_evaluations
        if not result.success:
            failures.append(f"ε = {eps:g}: {result.message}")
    errors = np.array(max_errors)
    amplitude = max(abs(numeric.a0), 1e-300)
    floor = _ROUNDING_FLOOR * amplitude
    if not failures and np.any(errors <= floor):
        failures.append(
            f"errors at rounding level (≤ {floor:.1e}) for ε = "
            f"{[float(e) for e in eps_values[errors <= floor]]}: nothing to fit (e.g. grazing with a1 = 0 is exact)"
        )
    if failures:
        fit = LogLogFit(math.nan, math.nan, math.nan, len(eps_values))
        if np.all(errors > 0) and np.all(np.isfinite(errors)):
            fit = loglog_fit(eps_values, errors)
        message = "; ".join(failures)
        success = False
    else:
        fit = loglog_fit(eps_values, errors)
        success = True
        message = (
            f"slope {fit.slope:.4f} ± {fit.standard_error:.2g} over t ≤ {rule_name} "
            f"(expected {expansion.order + 1} for simple contact or smooth f)"
        )
    return ConvergenceFit(
        success=success,
        message=message,
        slope=fit.slope,
        intercept=fit.intercept,
        standard_error=fit.standard_error,
        expected_slope=expansion.order + 1,
        epsilons=eps_values,
        max_errors=errors,
        t_ends=np.array(t_ends),
        t_end_rule=rule_name,
        n_reference_solves=len(eps_values),
        n_samples=n_samples,
        n_switches=n_switches,
        n_evaluations=n_evaluations,
    )


# --------------------------------------------------------------------------- #
# validity exponent
# --------------------------------------------------------------------------- #
@dataclass(frozen=True)
class ValidityFit:
    """Exponent p of the validity time ``T_ε ~ ε^p``.

    ``T_ε`` is the first time the phase-plane error ``ρ(t)`` exceeds
    ``threshold(ε) = C ε^q`` (``q = N + 1``; ``q = 2`` at grazing), located by
    linear interpolation between grid points.

    Attributes
    ----------
    success : bool
        Every ``T_ε`` was found within its horizon and the fit is defined.
    message : str
        What happened.
    exponent, intercept, standard_error : float
        Fit of ``log T_ε = p log ε + intercept`` (natural logs); standard error
        of p (NaN for two points).
    expected_exponent : float
        −1 (simple contact, smooth f) or −1/2 (grazing), from the regime.
    threshold_power : int
        q.
    threshold_constant : float
        C (the calibrated value for ``tolerance_rule="auto"``, NaN for a callable rule).
    epsilons, validity_times, thresholds : numpy.ndarray
        The data (``validity_times`` is NaN where the threshold was never exceeded).
    horizons : numpy.ndarray
        The last window searched for each ε.
    n_reference_solves, n_samples, n_switches, n_evaluations : int
        Totals.
    """

    success: bool
    message: str
    exponent: float
    intercept: float
    standard_error: float
    expected_exponent: float
    threshold_power: int
    threshold_constant: float
    epsilons: np.ndarray
    validity_times: np.ndarray
    thresholds: np.ndarray
    horizons: np.ndarray
    n_reference_solves: int
    n_samples: int
    n_switches: int
    n_evaluations: int


def _first_exceedance(times: np.ndarray, values: np.ndarray, threshold: float) -> float | None:
    above = np.flatnonzero(values > threshold)
    if above.size == 0:
        return None
    k = int(above[0])
    if k == 0:
        return float(times[0])
    # linear interpolation between the last point below and the first above
    fraction = (threshold - values[k - 1]) / (values[k] - values[k - 1])
    return float(times[k - 1] + fraction * (times[k] - times[k - 1]))


def fitted_validity_exponent(
    expansion: Expansion,
    epsilons: Sequence[float],
    tolerance_rule: str | float | Callable[[float], float] = "auto",
    *,
    a1: float = 0.0,
    calibration_periods: float = 2.0,
    calibration_factor: float | None = None,
    horizon: Callable[[float], float] | None = None,
    samples_per_period: int = DEFAULT_SAMPLES_PER_PERIOD,
    values: Mapping[Any, Any] | None = None,
    rtol: float = DEFAULT_RTOL,
    atol: float = DEFAULT_ATOL,
) -> ValidityFit:
    """Fit p in ``T_ε ~ ε^p``, T_ε the first time ``ρ(t) > C ε^q``.

    ``q = N + 1`` for simple contact or smooth f (the error order the
    expansion claims), ``q = 2`` at grazing (Prop. 2.3's ``O(ε²)``).  Theory
    (module docstring): ``p = −1`` for simple contact and smooth f (drift
    ``ε^{N+2} t`` against ``ε^{N+1}``), ``p = −1/2`` at grazing (drift
    ``ε^{5/2} t`` against ``ε²``).  The grazing case needs ``a1`` pushing the
    mass just past the gap (``a0 + ε a1`` farther from 0 than ``a0``);
    otherwise the linear motion is exact.

    Parameters
    ----------
    expansion : Expansion
        The order-N expansion.
    epsilons : sequence of float
        At least two distinct positive values.
    tolerance_rule : "auto", float or callable
        ``"auto"``: ``C = calibration_factor × max_ε max_{t ≤ calibration_periods·P0} ρ / ε^q``
        (so the threshold is above the bounded part of the error for every ε
        and T_ε is decided by the secular drift); a float: that C; a callable:
        ``eps -> threshold`` used as is.
    a1 : float
        ``u(0) = a0 + ε a1`` (see :func:`expansion_error`).
    calibration_periods, calibration_factor : float
        For ``"auto"``; ``P0 = 2π/ω0``.  The factor defaults to 3, and to 10
        at grazing: there ρ is a staircase (it changes only during the short
        contacts, once per period), so ``T_ε`` is quantised to whole periods
        and must span many of them for the fit to be clean.
    horizon : callable, optional
        ``eps -> t_max``, the longest window searched (the window starts at
        16 P0 and doubles).  Default ``400/ε``.
    samples_per_period, values, rtol, atol
        As in :func:`fitted_convergence_order`.

    Returns
    -------
    ValidityFit

    Examples
    --------
    >>> import lindstedt
    >>> e = lindstedt.expand("Max(0, u - 1)", order=1, a0=1, omega0=1)   # grazing
    >>> fit = fitted_validity_exponent(e, [0.02, 0.01, 0.005], a1=1.0)
    >>> fit.success, abs(fit.exponent + 0.5) < 0.15
    (True, True)
    """
    if not isinstance(expansion, Expansion):
        raise ProblemError(f"fitted_validity_exponent needs an Expansion, got {type(expansion).__name__}")
    eps_values = _as_epsilons(epsilons)
    a1_value = _check_a1(expansion, a1)
    numeric = _numeric_problem(expansion, values)
    grazing = expansion.regime == "grazing"
    power = 2 if grazing else expansion.order + 1
    expected = -0.5 if grazing else -1.0
    period = 2 * math.pi / numeric.omega0
    horizon_of = horizon if horizon is not None else (lambda eps: 400.0 / eps)
    counters = {"solves": 0, "samples": 0, "switches": 0, "evaluations": 0}
    if calibration_factor is None:
        calibration_factor = 10.0 if grazing else 3.0

    def errors_on(eps: float, t_end: float) -> ExpansionError:
        samples = _default_samples(t_end, numeric.omega0, samples_per_period)
        result = expansion_error(expansion, eps, t_end, samples, values=values, a1=a1_value, rtol=rtol, atol=atol)
        counters["solves"] += 1
        counters["samples"] += result.n_samples
        counters["switches"] += result.n_switches
        counters["evaluations"] += result.n_evaluations
        return result

    failures: list[str] = []
    # the threshold
    if isinstance(tolerance_rule, str):
        if tolerance_rule != "auto":
            raise ProblemError(f"tolerance_rule must be 'auto', a positive number C or a callable, got {tolerance_rule!r}")
        scaled = []
        for eps in eps_values:
            result = errors_on(float(eps), calibration_periods * period)
            if not result.success:
                failures.append(f"calibration at ε = {eps:g}: {result.message}")
            scaled.append(result.max_phase_error / eps**power)
        constant = calibration_factor * float(np.max(scaled))
        if not constant > 0:
            failures.append("the calibration error is zero: the expansion is exact (grazing needs a1 ≠ 0)")
        threshold_of: Callable[[float], float] = lambda eps: constant * eps**power  # noqa: E731
    elif callable(tolerance_rule):
        constant = math.nan
        threshold_of = lambda eps: float(tolerance_rule(eps))  # noqa: E731
    else:
        constant = float(tolerance_rule)
        if not (math.isfinite(constant) and constant > 0):
            raise ProblemError(f"the threshold constant C must be positive, got {tolerance_rule!r}")
        threshold_of = lambda eps: constant * eps**power  # noqa: E731

    validity_times, thresholds, horizons = [], [], []
    for eps in eps_values:
        threshold = threshold_of(float(eps))
        thresholds.append(threshold)
        t_max = float(horizon_of(float(eps)))
        window = min(16 * period, t_max)
        found = None
        reference_failed = False
        while True:
            result = errors_on(float(eps), window)
            if not result.success:
                failures.append(f"ε = {eps:g}: {result.message}")
                reference_failed = True
                break
            found = _first_exceedance(result.times, result.phase_error, threshold)
            if found is not None or window >= t_max:
                break
            window = min(2 * window, t_max)
        horizons.append(window)
        if found is None:
            validity_times.append(math.nan)
            if not reference_failed:
                failures.append(f"ε = {eps:g}: ρ stayed below {threshold:.3e} up to t = {window:g}")
        else:
            validity_times.append(found)
    times = np.array(validity_times)
    if np.all(np.isfinite(times)) and np.all(times > 0):
        fit = loglog_fit(eps_values, times)
    else:
        fit = LogLogFit(math.nan, math.nan, math.nan, len(eps_values))
    success = not failures and math.isfinite(fit.slope)
    if success:
        message = (
            f"T_ε ~ ε^{fit.slope:.4f} (± {fit.standard_error:.2g}); threshold {constant:.4g}·ε^{power}; "
            f"expected {expected} ({'grazing' if grazing else 'simple contact / smooth'})"
        )
    else:
        message = "; ".join(failures) if failures else "T_ε not positive: cannot fit"
    return ValidityFit(
        success=success,
        message=message,
        exponent=fit.slope,
        intercept=fit.intercept,
        standard_error=fit.standard_error,
        expected_exponent=expected,
        threshold_power=power,
        threshold_constant=constant,
        epsilons=eps_values,
        validity_times=times,
        thresholds=np.array(thresholds),
        horizons=np.array(horizons),
        n_reference_solves=counters["solves"],
        n_samples=counters["samples"],
        n_switches=counters["switches"],
        n_evaluations=counters["evaluations"],
    )


# --------------------------------------------------------------------------- #
# contact measure (Lemma 3.2)
# --------------------------------------------------------------------------- #
@dataclass(frozen=True)
class ContactMeasure:
    """``μ(T) = |{t ∈ [t_0, T] : min_j |u(t) − b_j| ≤ threshold}|``.

    Attributes
    ----------
    success : bool
        False when the grid cannot decide whether an extremum of u enters the
        band (a sampled extremum outside it, but closer than one step's
        variation of u); see ``message``.
    message : str
        What happened.
    measure : float
        μ.
    duration : float
        ``T − t_0``.
    intervals : tuple of (float, float)
        The maximal intervals of the set (merged across levels).
    threshold : float
        The band half-width (ε M).
    levels : tuple of float
        The b_j.
    n_samples : int
        Grid points.
    n_refined : int
        Band edges located by Brent's method on the dense output (0 for samples).
    """

    success: bool
    message: str
    measure: float
    duration: float
    intervals: tuple[tuple[float, float], ...]
    threshold: float
    levels: tuple[float, ...]
    n_samples: int
    n_refined: int

    @property
    def fraction(self) -> float:
        """μ / duration."""
        return self.measure / self.duration if self.duration > 0 else math.nan


def _band_intervals(times: np.ndarray, values: np.ndarray, low: float, high: float,
                    function: Callable[[np.ndarray], np.ndarray] | None, counter: list[int]) -> list[tuple[float, float]]:
    """Intervals where low ≤ u ≤ high; edges by linear interpolation or Brent on ``function``."""
    inside = (values >= low) & (values <= high)
    intervals: list[tuple[float, float]] = []

    def edge(k: int, level: float) -> float:
        t0, t1, u0, u1 = times[k], times[k + 1], values[k], values[k + 1]
        if function is not None and (u0 - level) * (u1 - level) < 0:
            counter[0] += 1
            return float(scipy.optimize.brentq(lambda s: float(function(np.array([s]))[0]) - level, t0, t1,
                                               xtol=4e-16 * max(1.0, abs(t1)), rtol=4 * np.finfo(float).eps))
        return float(t0 + (level - u0) / (u1 - u0) * (t1 - t0)) if u1 != u0 else float(t0)

    segment_low = np.minimum(values[:-1], values[1:])
    segment_high = np.maximum(values[:-1], values[1:])
    for k in np.flatnonzero((segment_high >= low) & (segment_low <= high)):
        u0, u1 = values[k], values[k + 1]
        if inside[k] and inside[k + 1]:
            start, end = times[k], times[k + 1]
        else:
            # the band [low, high] meets the segment [u0, u1] on a sub-interval
            crossings = []
            for level in (low, high):
                if (u0 - level) * (u1 - level) < 0:
                    crossings.append(edge(k, level))
            if inside[k]:
                start, end = times[k], min(crossings) if crossings else times[k + 1]
            elif inside[k + 1]:
                start, end = max(crossings) if crossings else times[k], times[k + 1]
            elif len(crossings) == 2:
                start, end = min(crossings), max(crossings)
            else:
                continue
        if intervals and start <= intervals[-1][1]:
            intervals[-1] = (intervals[-1][0], max(intervals[-1][1], end))
        else:
            intervals.append((float(start), float(end)))
    return intervals


def contact_measure(
    u_values: Any,
    t: Any,
    threshold: float,
    *,
    level: float | Sequence[float] = 0.0,
) -> ContactMeasure:
    """Measure of ``{t : min_j |u(t) − b_j| ≤ threshold}`` (``μ_ε(T)`` of Lemma 3.2 with threshold ε M).

    Parameters
    ----------
    u_values : array_like or callable
        Samples of u on the grid ``t``, or a vectorised dense output
        ``u(times)`` (then the band edges are found by Brent's method on it and
        the grid only brackets them).
    t : array_like
        Increasing grid.  Monotone passages through the band are always caught
        (even within one step); only extrema of u near the band need
        resolving, and the result reports when they are not.
    threshold : float
        The half-width ε M > 0.
    level : float or sequence of float
        The b_j (gaps); the set is the union over j.

    Returns
    -------
    ContactMeasure
        With samples the measure is that of the linear interpolant
        (second-order accurate in the step).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.linspace(0.0, 2 * np.pi, 2001)
    >>> result = contact_measure(np.cos(t), t, 0.01)            # |cos t| ≤ 0.01 near π/2, 3π/2
    >>> bool(abs(result.measure - 4 * np.arcsin(0.01)) < 1e-6)
    True
    >>> dense = contact_measure(np.cos, t, 0.01)
    >>> bool(abs(dense.measure - 4 * np.arcsin(0.01)) < 1e-14), dense.n_refined
    (True, 4)
    """
    times = np.asarray(t, dtype=float).reshape(-1)
    if times.size < 2 or not np.all(np.isfinite(times)) or np.any(np.diff(times) <= 0):
        raise ProblemError("t must be an increasing array of at least two finite times")
    try:
        band = float(threshold)
    except (TypeError, ValueError):
        raise ProblemError(f"threshold must be a positive number, got {threshold!r}") from None
    if not (math.isfinite(band) and band > 0):
        raise ProblemError(f"threshold must be a positive finite number, got {threshold!r}")
    function = u_values if callable(u_values) else None
    values = np.asarray(function(times) if function is not None else u_values, dtype=float).reshape(-1)
    if values.shape != times.shape:
        raise ProblemError(f"u_values has {values.size} entries but t has {times.size}")
    if not np.all(np.isfinite(values)):
        raise ProblemError("u_values must be finite")
    levels = tuple(float(b) for b in np.atleast_1d(np.asarray(level, dtype=float)))
    counter = [0]
    pieces: list[tuple[float, float]] = []
    for b in levels:
        pieces.extend(_band_intervals(times, values, b - band, b + band, function, counter))
    pieces.sort()
    merged: list[tuple[float, float]] = []
    for start, end in pieces:
        if merged and start <= merged[-1][1]:
            merged[-1] = (merged[-1][0], max(merged[-1][1], end))
        else:
            merged.append((start, end))
    measure = float(sum(end - start for start, end in merged))
    # Between samples the set can only be missed near an extremum of u: a sampled
    # local extremum outside the band but closer to it than the one-step variation
    # of u may hide a true extremum inside the band.
    uncertain = 0
    if values.size >= 3:
        left, right = values[1:-1] - values[:-2], values[2:] - values[1:-1]
        extrema = np.flatnonzero(left * right < 0) + 1
        for k in extrema:
            reach = max(abs(values[k] - values[k - 1]), abs(values[k + 1] - values[k]))
            distance = min(abs(values[k] - b) for b in levels) - band
            if 0 < distance <= reach:
                uncertain += 1
    success = uncertain == 0
    if success:
        message = f"μ = {measure:.6e} over {len(merged)} interval(s) of [{times[0]:g}, {times[-1]:g}]"
    else:
        message = (
            f"{uncertain} sampled extrema of u lie just outside the band, within one step's variation of it: "
            "refine t (a short excursion into the band may be missed)"
        )
    return ContactMeasure(
        success=success,
        message=message,
        measure=measure,
        duration=float(times[-1] - times[0]),
        intervals=tuple(merged),
        threshold=band,
        levels=levels,
        n_samples=int(times.size),
        n_refined=counter[0],
    )


@dataclass(frozen=True)
class ContactMeasureFit:
    """Slope of ``log(μ_ε(T)/T)`` against ``log ε`` on true solutions.

    Attributes
    ----------
    success, message
        As usual.
    slope, intercept, standard_error : float
        The fit (1 for simple roots of u − b, 1/2 for a double root).
    expected_slope : float
        1, or 1/2 in the grazing regime.
    epsilons, measures, durations : numpy.ndarray
        The data (``durations`` = T).
    band_constant : float
        M (the band is ε M).
    levels : tuple of float
        The breakpoints b_j of f.
    n_reference_solves, n_samples, n_refined, n_switches : int
        Totals.
    """

    success: bool
    message: str
    slope: float
    intercept: float
    standard_error: float
    expected_slope: float
    epsilons: np.ndarray
    measures: np.ndarray
    durations: np.ndarray
    band_constant: float
    levels: tuple[float, ...]
    n_reference_solves: int
    n_samples: int
    n_refined: int
    n_switches: int


def fitted_contact_measure_order(
    expansion: Expansion,
    epsilons: Sequence[float],
    *,
    band_constant: float = 1.0,
    periods: float = 20.0,
    a1: float = 0.0,
    samples_per_period: int = 512,
    values: Mapping[Any, Any] | None = None,
) -> ContactMeasureFit:
    """Lemma 3.2 on true solutions: fit ``μ_ε(T)/T ~ ε^slope``, ``T = periods · 2π/ω0``.

    ``μ_ε(T) = |{t ≤ T : min_j |u_ε(t) − b_j| ≤ ε M}|`` with ``b_j`` the
    breakpoints of the piecewise-linear f and ``u_ε`` the exact solution from
    ``u(0) = a0 + ε a1``.  Theory: slope 1 where ``u − b`` has simple roots,
    1/2 at grazing (``a0 = b``, double root; then ``a1`` with ``|a1| ≤ M``
    keeps the top of the motion inside the band: its length is
    ``2 (2 ε (M ± a1)/(|b| ω0²))^{1/2}`` per period).

    Parameters
    ----------
    expansion : Expansion
        Of a piecewise-linear problem (gives the problem and the regime).
    epsilons : sequence of float
        At least two distinct positive values.
    band_constant : float
        M.
    periods : float
        T in linear periods.
    a1 : float
        Perturbation of u(0).
    samples_per_period : int
        Grid density bracketing the band edges (edges then refined by Brent).
    values : mapping, optional
        Numbers for symbols left free.

    Returns
    -------
    ContactMeasureFit

    Examples
    --------
    >>> import lindstedt
    >>> e = lindstedt.expand("Max(0, u - 1/3)", order=0, a0=1, omega0=1)
    >>> fit = fitted_contact_measure_order(e, [0.04, 0.02, 0.01])
    >>> fit.success, abs(fit.slope - 1) < 0.05
    (True, True)
    """
    if not isinstance(expansion, Expansion):
        raise ProblemError(f"fitted_contact_measure_order needs an Expansion, got {type(expansion).__name__}")
    eps_values = _as_epsilons(epsilons)
    numeric = _numeric_problem(expansion, values)
    if numeric.law is None or not numeric.law.breakpoints:
        raise ProblemError("the contact measure needs a piecewise-linear f with at least one breakpoint (a gap b)")
    levels = numeric.law.breakpoints
    M = float(band_constant)
    if not (math.isfinite(M) and M > 0):
        raise ProblemError(f"band_constant M must be positive, got {band_constant!r}")
    duration = float(periods) * 2 * math.pi / numeric.omega0
    n = max(1001, int(math.ceil(samples_per_period * float(periods))) + 1)
    times = np.linspace(0.0, duration, n)
    measures, failures = [], []
    n_refined = n_switches = 0
    for eps in eps_values:
        reference = reference_solution(expansion, float(eps), times, values=values, a1=a1)
        n_switches += reference.n_switches
        if not reference.success:
            failures.append(f"ε = {eps:g}: {reference.message}")
        result = contact_measure(lambda s, r=reference: r.state(s)[0], times, float(eps) * M, level=levels)
        n_refined += result.n_refined
        if not result.success:
            failures.append(f"ε = {eps:g}: {result.message}")
        measures.append(result.measure)
    measure_array = np.array(measures)
    expected = 0.5 if expansion.regime == "grazing" else 1.0
    if np.all(measure_array > 0):
        fit = loglog_fit(eps_values, measure_array / duration)
    else:
        fit = LogLogFit(math.nan, math.nan, math.nan, len(eps_values))
        failures.append("μ_ε(T) = 0 for some ε: the motion never comes within ε M of a gap")
    success = not failures
    message = (
        f"μ_ε(T)/T ~ ε^{fit.slope:.4f} (± {fit.standard_error:.2g}), expected {expected}"
        if success
        else "; ".join(failures)
    )
    return ContactMeasureFit(
        success=success,
        message=message,
        slope=fit.slope,
        intercept=fit.intercept,
        standard_error=fit.standard_error,
        expected_slope=expected,
        epsilons=eps_values,
        measures=measure_array,
        durations=np.full(eps_values.size, duration),
        band_constant=M,
        levels=tuple(levels),
        n_reference_solves=len(eps_values),
        n_samples=n * len(eps_values),
        n_refined=n_refined,
        n_switches=n_switches,
    )
