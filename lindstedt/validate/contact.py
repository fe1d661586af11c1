"""The contact measure  μ_ε(T) = |{t ∈ [0, T] : |u(t) − b| ≤ ε M}|  of Lemma 3.2, and its order in ε.

Where ``u − b`` has simple roots each crossing of the band contributes
``2 ε M / |u'|``: ``μ_ε(T) = O(ε T)``.  At a double root (grazing) the band
is crossed with ``|u'| ~ ε^{1/2}``: ``μ_ε(T) = O(ε^{1/2} T)``.

:func:`contact_measure` measures the set for samples or a dense output of u
(several gaps b_j: the union of the bands); :func:`fitted_contact_measure_order`
fits ``log(μ_ε(T)/T)`` against ``log ε`` on the true solutions
(:func:`lindstedt.validate.reference_solution`): slope 1, or 1/2 at grazing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from .._errors import ProblemError
from ..render.json import JsonExport
from ..problems.oscillator import Oscillator
from ..results.expansion import Expansion
from .errors import _as_epsilons, _fit_or_nan
from .solutions import _as_positive, _numeric_problem, _require_expansion, reference_solution

__all__ = ["ContactMeasure", "contact_measure", "ContactMeasureFit", "fitted_contact_measure_order"]


@dataclass(frozen=True, repr=False)
class ContactMeasure(JsonExport):
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

    Measured on given samples or a given function: it has no problem (the
    fit :class:`ContactMeasureFit` carries its).  JSON schema
    ``lindstedt.contact-measure/1`` (:meth:`to_json`).
    """

    SCHEMA = "lindstedt.contact-measure/1"

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


def _merged(pieces: Sequence[tuple[float, float]]) -> list[tuple[float, float]]:
    """The union of intervals sorted by their start, as maximal intervals."""
    merged: list[tuple[float, float]] = []
    for start, end in pieces:
        if merged and start <= merged[-1][1]:
            merged[-1] = (merged[-1][0], float(max(merged[-1][1], end)))
        else:
            merged.append((float(start), float(end)))
    return merged


def _band_intervals(times: np.ndarray, values: np.ndarray, low: float, high: float,
                    function: Callable[[np.ndarray], np.ndarray] | None, counter: list[int]) -> list[tuple[float, float]]:
    """Intervals where low ≤ u ≤ high; edges by linear interpolation or Brent on ``function``."""
    inside = (values >= low) & (values <= high)
    pieces: list[tuple[float, float]] = []

    def edge(k: int, level: float) -> float:
        """Where u crosses ``level`` strictly inside the step from times[k] to times[k + 1]."""
        t0, t1, u0, u1 = times[k], times[k + 1], values[k], values[k + 1]
        if function is None:
            return float(t0 + (level - u0) / (u1 - u0) * (t1 - t0))
        counter[0] += 1
        import scipy.optimize  # here, not at module level: import lindstedt stays light
        return float(scipy.optimize.brentq(lambda s: float(function(np.array([s]))[0]) - level, t0, t1,
                                           xtol=4e-16 * max(1.0, abs(t1)), rtol=4 * np.finfo(float).eps))

    segment_low = np.minimum(values[:-1], values[1:])
    segment_high = np.maximum(values[:-1], values[1:])
    for k in np.flatnonzero((segment_high >= low) & (segment_low <= high)):
        u0, u1 = values[k], values[k + 1]
        if inside[k] and inside[k + 1]:
            start, end = times[k], times[k + 1]
        else:
            # the band [low, high] meets the segment [u0, u1] on a sub-interval
            crossings = [edge(k, level) for level in (low, high) if (u0 - level) * (u1 - level) < 0]
            if inside[k]:
                start, end = times[k], min(crossings) if crossings else times[k + 1]
            elif inside[k + 1]:
                start, end = max(crossings) if crossings else times[k], times[k + 1]
            elif len(crossings) == 2:
                start, end = min(crossings), max(crossings)
            else:
                continue
        pieces.append((start, end))
    return _merged(pieces)  # segments come in time order


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
    band = _as_positive(threshold, "threshold")
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
    merged = _merged(sorted(pieces))
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


@dataclass(frozen=True, repr=False)
class ContactMeasureFit(JsonExport):
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
    problem : Oscillator
        The problem of the expansion (exported as its description).

    JSON schema ``lindstedt.contact-measure-fit/1`` (:meth:`to_json`).
    """

    SCHEMA = "lindstedt.contact-measure-fit/1"

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
    problem: Oscillator | None = field(default=None, repr=False, compare=False)


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
    _require_expansion(expansion, "fitted_contact_measure_order")
    eps_values = _as_epsilons(epsilons)
    numeric = _numeric_problem(expansion, values)
    if numeric.law is None or not numeric.law.breakpoints:
        raise ProblemError("the contact measure needs a piecewise-linear f with at least one breakpoint (a gap b)")
    levels = numeric.law.breakpoints
    M = _as_positive(band_constant, "band_constant M")
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
    fit = _fit_or_nan(eps_values, measure_array / duration)
    if not np.all(measure_array > 0):
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
        problem=expansion.problem,
    )
