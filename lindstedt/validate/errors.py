"""The expansion error  e(t) = u_N(t) − u(t)  and its rates in ε: convergence order and validity exponent.

``u_N(t) = Σ_{k≤N} ε^k v_k(ω t)`` is the order-N Lindstedt–Poincaré expansion
of ``u'' + ω0² u + ε f(u) = 0``, ``u(0) = a0 + ε a1``, ``u'(0) = 0``
(waveforms v_0..v_N, frequency through ω_{N+1}); u is the true solution
(:func:`lindstedt.validate.reference_solution`).

Error (:func:`expansion_error`)
    ``e(t) = u_N(t) − u(t)`` and its phase-plane size
    ``ρ(t) = ((u_N − u)² + ((u_N' − u')/ω0)²)^{1/2}``, which has no zeros at
    the turning points and so grows monotonically with a phase drift.

What is measurable, and what theory predicts
    * Simple contact (or smooth f), order N: ``u_N − u = ε^{N+1} v_{N+1}(ωt)
      + O(ε^{N+2} t)`` — a bounded part plus the drift of the first neglected
      frequency term ω_{N+2}.  Hence ``max_{[0, C/ε]} |e| ~ ε^{N+1}``
      (:func:`fitted_convergence_order`: slope N + 1), and the first time
      ``T_ε`` at which ``ρ`` exceeds ``C ε^{N+1}`` (C above the bounded part)
      is ``(C − |v_{N+1}|)/(|ω_{N+2}| a0) · ε^{-1}``: exponent −1
      (:func:`fitted_validity_exponent`).
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

Fits (:func:`loglog_fit`)
    The least-squares line ``log y = slope · log x + intercept`` behind every
    fitted order and exponent of :mod:`lindstedt.validate`.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from functools import partial
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from .._errors import ProblemError
from .._sweep import sweep_map
from ..render.json import JsonExport
from ..results.accuracy import ExpansionValidityWarning
from ..problems.oscillator import Oscillator
from ..results.expansion import Expansion
from .solutions import (
    DEFAULT_ATOL,
    DEFAULT_RTOL,
    _as_epsilon,
    _as_positive,
    _as_real,
    _numeric_problem,
    _require_expansion,
    reference_solution,
)

__all__ = [
    "ExpansionError",
    "expansion_error",
    "ConvergenceFit",
    "fitted_convergence_order",
    "ValidityFit",
    "fitted_validity_exponent",
    "LogLogFit",
    "loglog_fit",
]

#: default samples per linear period 2π/ω0 on error grids
DEFAULT_SAMPLES_PER_PERIOD = 64
#: an error below this many machine epsilons × amplitude is rounding, not truncation
_ROUNDING_FLOOR = 1e3 * np.finfo(float).eps


# --------------------------------------------------------------------------- #
# log-log fits
# --------------------------------------------------------------------------- #
@dataclass(frozen=True, repr=False)
class LogLogFit(JsonExport):
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

    A pure fit of numbers: it has no problem (the fits of the validation
    functions carry theirs).  JSON schema ``lindstedt.loglog-fit/1``.
    """

    SCHEMA = "lindstedt.loglog-fit/1"

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


def _fit_or_nan(epsilons: np.ndarray, y: np.ndarray) -> LogLogFit:
    """:func:`loglog_fit` of y against ε, or an all-NaN fit when some y is not positive and finite."""
    if np.all(y > 0) and np.all(np.isfinite(y)):
        return loglog_fit(epsilons, y)
    return LogLogFit(math.nan, math.nan, math.nan, len(epsilons))


def _as_epsilons(epsilons: Sequence[float]) -> np.ndarray:
    values = np.asarray(epsilons, dtype=float).reshape(-1)
    if values.size < 2 or not np.all(np.isfinite(values)) or np.any(values <= 0):
        raise ProblemError(f"epsilons must be at least two positive finite numbers, got {list(values)}")
    if np.unique(values).size != values.size:
        raise ProblemError("epsilons must be distinct")
    return values


# --------------------------------------------------------------------------- #
# expansion error
# --------------------------------------------------------------------------- #
@dataclass(frozen=True, repr=False)
class ExpansionError(JsonExport):
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
    problem : Oscillator
        The problem of the expansion (exported as its description).

    JSON schema ``lindstedt.expansion-error/1`` (:meth:`to_json`).
    """

    SCHEMA = "lindstedt.expansion-error/1"

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
    problem: Oscillator | None = field(default=None, repr=False, compare=False)


def _approximation(expansion: Expansion, epsilon: float, times: np.ndarray, values: Mapping[Any, Any] | None,
                   a1: float) -> tuple[np.ndarray, np.ndarray]:
    """u_N and u_N' (plus the O(ε) response ε a1 cos(ω t) to the perturbed initial datum).

    Measuring the error where the expansion stops holding is the point here: its validity warnings are silenced.
    """
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ExpansionValidityWarning)
        u = np.asarray(expansion.displacement(times, epsilon, values), dtype=float)
        v = np.asarray(expansion.velocity(times, epsilon, values), dtype=float)
    if a1:
        omega = float(expansion.frequency(epsilon, values, order=expansion.order + 1))
        u = u + epsilon * a1 * np.cos(omega * times)
        v = v - epsilon * a1 * omega * np.sin(omega * times)
    return u, v


def _check_a1(expansion: Expansion, a1: float) -> float:
    value = _as_real(a1, "a1")
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
    _require_expansion(expansion, "expansion_error")
    eps = _as_epsilon(epsilon)
    a1_value = _check_a1(expansion, a1)
    t_end_value = _as_positive(t_end, "t_end")
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
        problem=expansion.problem,
    )


def _error_task(window: tuple[float, float], *, expansion: Expansion, omega0: float, samples_per_period: int,
                options: dict[str, Any]) -> ExpansionError:
    """:func:`expansion_error` over ``window = (ε, t_end)`` (module level: picklable for process pools)."""
    eps, t_end = window
    return expansion_error(expansion, eps, t_end, _default_samples(t_end, omega0, samples_per_period), **options)


def _validity_task(window: tuple[float, float, float], *, period: float, **run: Any) -> tuple[float | None, float, list[ExpansionError]]:
    """The first time ρ exceeds the threshold at one ε: windows from 16 P0, doubled up to ``t_max``.

    Returns (the time or None, the last window, the error runs made).
    """
    eps, threshold, t_max = window
    span = min(16 * period, t_max)
    runs = []
    while True:
        result = _error_task((eps, span), **run)
        runs.append(result)
        if not result.success:
            return None, span, runs
        found = _first_exceedance(result.times, result.phase_error, threshold)
        if found is not None or span >= t_max:
            return found, span, runs
        span = min(2 * span, t_max)


class _ErrorRuns:
    """:func:`expansion_error` on windows of one expansion, ``samples_per_period`` per linear period, with totals;
    the windows of one call run on ``executor`` when given (:func:`lindstedt._sweep.sweep_map`)."""

    def __init__(self, expansion: Expansion, omega0: float, samples_per_period: int, values: Mapping[Any, Any] | None,
                 a1: float, rtol: float, atol: float, executor: Any = None, progress: Any = None) -> None:
        self.run = {"expansion": expansion, "omega0": omega0, "samples_per_period": samples_per_period,
                    "options": {"values": values, "a1": a1, "rtol": rtol, "atol": atol}}
        self.executor, self.progress = executor, progress
        self.solves = self.samples = self.switches = self.evaluations = 0

    def _count(self, result: ExpansionError) -> None:
        self.solves += 1
        self.samples += result.n_samples
        self.switches += result.n_switches
        self.evaluations += result.n_evaluations

    def map(self, windows: Sequence[tuple[float, float]]) -> list[ExpansionError]:
        """One :func:`expansion_error` per ``(ε, t_end)``, in order."""
        results = sweep_map(partial(_error_task, **self.run), windows, executor=self.executor, progress=self.progress,
                            description="expansion errors")
        for result in results:
            self._count(result)
        return results

    def first_exceedances(self, windows: Sequence[tuple[float, float, float]], period: float
                          ) -> list[tuple[float | None, float, ExpansionError]]:
        """Per ``(ε, threshold, t_max)``: (first time ρ > threshold or None, last window, last run)."""
        outcomes = sweep_map(partial(_validity_task, period=period, **self.run), windows, executor=self.executor,
                             progress=self.progress, description="validity times")
        found = []
        for time_found, span, runs in outcomes:
            for result in runs:
                self._count(result)
            found.append((time_found, span, runs[-1]))
        return found

    def totals(self) -> dict[str, int]:
        """The counters, as the ``n_*`` fields of the fit results."""
        return {"n_reference_solves": self.solves, "n_samples": self.samples, "n_switches": self.switches,
                "n_evaluations": self.evaluations}


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


@dataclass(frozen=True, repr=False)
class ConvergenceFit(JsonExport):
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
    problem : Oscillator
        The problem of the expansion (exported as its description).

    JSON schema ``lindstedt.convergence-fit/1`` (:meth:`to_json`).
    """

    SCHEMA = "lindstedt.convergence-fit/1"

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
    problem: Oscillator | None = field(default=None, repr=False, compare=False)


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
    executor: Any = None,
    progress: Any = None,
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
    executor, progress
        Run the ε values on any ``concurrent.futures``-style executor (a process pool, a Dask cluster),
        with a tqdm bar (``True``) or a callable ``progress(index, (ε, t_end), result)``.

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
    _require_expansion(expansion, "fitted_convergence_order")
    eps_values = _as_epsilons(epsilons)
    t_end_of, rule_name = _t_end_function(t_end_rule, float(t_end_constant))
    numeric = _numeric_problem(expansion, values)
    runs = _ErrorRuns(expansion, numeric.omega0, samples_per_period, values, a1, rtol, atol, executor, progress)
    t_ends = [t_end_of(float(eps)) for eps in eps_values]
    results = runs.map([(float(eps), t_end) for eps, t_end in zip(eps_values, t_ends)])
    max_errors = [result.max_error for result in results]
    failures = [f"ε = {eps:g}: {result.message}" for eps, result in zip(eps_values, results) if not result.success]
    errors = np.array(max_errors)
    amplitude = max(abs(numeric.a0), 1e-300)
    floor = _ROUNDING_FLOOR * amplitude
    if not failures and np.any(errors <= floor):
        failures.append(
            f"errors at rounding level (≤ {floor:.1e}) for ε = "
            f"{[float(e) for e in eps_values[errors <= floor]]}: nothing to fit (e.g. grazing with a1 = 0 is exact)"
        )
    fit = _fit_or_nan(eps_values, errors)
    message = "; ".join(failures) if failures else (
        f"slope {fit.slope:.4f} ± {fit.standard_error:.2g} over t ≤ {rule_name} "
        f"(expected {expansion.order + 1} for simple contact or smooth f)"
    )
    return ConvergenceFit(
        success=not failures,
        message=message,
        slope=fit.slope,
        intercept=fit.intercept,
        standard_error=fit.standard_error,
        expected_slope=expansion.order + 1,
        epsilons=eps_values,
        max_errors=errors,
        t_ends=np.array(t_ends),
        t_end_rule=rule_name,
        **runs.totals(),
        problem=expansion.problem,
    )


# --------------------------------------------------------------------------- #
# validity exponent
# --------------------------------------------------------------------------- #
@dataclass(frozen=True, repr=False)
class ValidityFit(JsonExport):
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
    problem : Oscillator
        The problem of the expansion (exported as its description).

    JSON schema ``lindstedt.validity-fit/1`` (:meth:`to_json`).
    """

    SCHEMA = "lindstedt.validity-fit/1"

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
    problem: Oscillator | None = field(default=None, repr=False, compare=False)


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
    executor: Any = None,
    progress: Any = None,
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
    samples_per_period, values, rtol, atol, executor, progress
        As in :func:`fitted_convergence_order` (the calibration runs and the searches of the ε values are
        the tasks).

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
    _require_expansion(expansion, "fitted_validity_exponent")
    eps_values = _as_epsilons(epsilons)
    a1_value = _check_a1(expansion, a1)
    numeric = _numeric_problem(expansion, values)
    grazing = expansion.regime == "grazing"
    power = 2 if grazing else expansion.order + 1
    expected = -0.5 if grazing else -1.0
    period = 2 * math.pi / numeric.omega0
    horizon_of = horizon if horizon is not None else (lambda eps: 400.0 / eps)
    if calibration_factor is None:
        calibration_factor = 10.0 if grazing else 3.0
    errors_on = _ErrorRuns(expansion, numeric.omega0, samples_per_period, values, a1_value, rtol, atol, executor, progress)

    failures: list[str] = []
    # the threshold
    if isinstance(tolerance_rule, str):
        if tolerance_rule != "auto":
            raise ProblemError(f"tolerance_rule must be 'auto', a positive number C or a callable, got {tolerance_rule!r}")
        scaled = []
        for eps, result in zip(eps_values, errors_on.map([(float(eps), calibration_periods * period) for eps in eps_values])):
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
        constant = _as_positive(tolerance_rule, "the threshold constant C")
        threshold_of = lambda eps: constant * eps**power  # noqa: E731

    thresholds = [threshold_of(float(eps)) for eps in eps_values]
    searches = errors_on.first_exceedances(
        [(float(eps), threshold, float(horizon_of(float(eps)))) for eps, threshold in zip(eps_values, thresholds)], period
    )
    validity_times, horizons = [], []
    for eps, threshold, (found, window, last) in zip(eps_values, thresholds, searches):
        horizons.append(window)
        if not last.success:
            failures.append(f"ε = {eps:g}: {last.message}")
        elif found is None:
            failures.append(f"ε = {eps:g}: ρ stayed below {threshold:.3e} up to t = {window:g}")
        validity_times.append(math.nan if found is None else found)
    times = np.array(validity_times)
    fit = _fit_or_nan(eps_values, times)
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
        **errors_on.totals(),
        problem=expansion.problem,
    )
