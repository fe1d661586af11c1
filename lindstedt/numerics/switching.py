"""Certified search for the first switch of a contact: the first exit of a gap function from one side of 0.

:func:`_first_exit` works on any gap function h given by evaluators of (h, h', h'')
and of h, with the bounds ``|h″| ≤ G2`` and ``|h‴| ≤ G3`` on the search interval and an
envelope ``h ≥ c − R``.  It advances only by steps that a Taylor minorant proves
root-free (see the docstring of :mod:`lindstedt.numerics.flow`), so no excursion deeper
than the rounding band can be stepped over, then polishes the root with Brent's method.

Inside an arc of :class:`~lindstedt.numerics.ExactFlow` each gap function is
``g(t) = c + Σ_k α_k cos ω_k t + β_k sin ω_k t`` with ``R = Σ R_k``, ``G2 = Σ ω_k² R_k``
and ``G3 = Σ ω_k³ R_k`` (``R_k = hypot(α_k, β_k)``): :func:`_first_exit_trig` builds
those evaluators and bounds.  :class:`~lindstedt.numerics.forced_flow.ForcedFlow` gives
sums of damped exponentials ``c + Re Σ_k γ_k e^{λ_k τ}`` and their bounds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

__all__: list[str] = []

_EPS = float(np.finfo(float).eps)
_TINY = float(np.finfo(float).tiny)
#: safety cap on the root-free steps of one search
_MAX_SEARCH_STEPS = 100_000


class _SearchFailure(Exception):
    pass


@dataclass
class _Counters:
    evaluations: int = 0
    root_solves: int = 0


def _cubic_radius(value: float, slope: float, curvature: float, g3: float) -> float:
    """Lower bound of the smallest positive root of value + slope s + curvature s²/2 − g3 s³/6 (value > 0)."""
    a2, a3 = 0.5 * curvature, g3 / 6.0

    def p(s: float) -> float:
        return value + s * (slope + s * (a2 - a3 * s))

    bound = 2.0 * max(abs(a2) / a3, math.sqrt(abs(slope) / a3), (value / (2.0 * a3)) ** (1.0 / 3.0))
    while p(bound) > 0.0:  # rounding safety; the Fujiwara bound already encloses every root
        bound *= 2.0
    points = []
    discriminant = curvature * curvature + 2.0 * g3 * slope
    if discriminant >= 0.0:
        root = math.sqrt(discriminant)
        points = sorted(s for s in ((curvature - root) / g3, (curvature + root) / g3) if 0.0 < s < bound)
    points.append(bound)
    low = 0.0
    high = bound
    for point in points:
        if p(point) <= 0.0:
            high = point
            break
        low = point
    # p is monotone on [low, high], positive at low and non-positive at high
    while high - low > 1e-6 * high:
        middle = 0.5 * (low + high)
        if p(middle) > 0.0:
            low = middle
        else:
            high = middle
    return low


#: below this many harmonics the trigonometric sums are evaluated with scalar math (less overhead)
_SCALAR_TERMS = 12


def _trig_sum(
    offset: float, cos_coefficients: np.ndarray, sin_coefficients: np.ndarray, omega: np.ndarray, counters: _Counters
) -> tuple[Callable[[float], tuple[float, float, float]], Callable[[float], float]]:
    """Evaluators of h = offset + Σ a_k cos ω_k τ + b_k sin ω_k τ: (h, h', h'') and h alone."""
    if omega.size <= _SCALAR_TERMS:
        terms = list(zip(cos_coefficients.tolist(), sin_coefficients.tolist(), omega.tolist()))

        def derivatives(tau: float) -> tuple[float, float, float]:
            counters.evaluations += 1
            h, h1, h2 = offset, 0.0, 0.0
            for a, b, w in terms:
                c, s = math.cos(w * tau), math.sin(w * tau)
                term = a * c + b * s
                h += term
                h1 += w * (b * c - a * s)
                h2 -= w * w * term
            return h, h1, h2

        def value(tau: float) -> float:
            counters.evaluations += 1
            h = offset
            for a, b, w in terms:
                h += a * math.cos(w * tau) + b * math.sin(w * tau)
            return h

        return derivatives, value
    omega2 = omega * omega

    def derivatives_vectorised(tau: float) -> tuple[float, float, float]:
        counters.evaluations += 1
        phase = omega * tau
        cos, sin = np.cos(phase), np.sin(phase)
        terms = cos_coefficients * cos + sin_coefficients * sin
        return (
            offset + float(terms.sum()),
            float(omega @ (sin_coefficients * cos - cos_coefficients * sin)),
            -float(omega2 @ terms),
        )

    def value_vectorised(tau: float) -> float:
        counters.evaluations += 1
        phase = omega * tau
        return offset + float(cos_coefficients @ np.cos(phase) + sin_coefficients @ np.sin(phase))

    return derivatives_vectorised, value_vectorised


@dataclass(frozen=True)
class _Bracket:
    """A switching time in [low, high]: the root of ``function`` (None: exactly ``low``)."""

    low: float
    high: float
    function: Callable[[float], float] | None

    def polish(self, counters: _Counters) -> float:
        if self.function is None or self.function(self.low) <= 0.0:
            return self.low
        counters.root_solves += 1
        import scipy.optimize  # here, not at module level: import lindstedt stays light
        return scipy.optimize.brentq(
            self.function, self.low, self.high, xtol=_TINY**0.5 + 1e-3 * _EPS * self.high, rtol=4 * _EPS, maxiter=500
        )


def _leave_surface(value: float, slope: float, curvature: float, g2: float, g3: float, band: float) -> float | None:
    """First instant s > 0 certified clearly on the current side, for h starting on its switching surface.

    With h(0) = value (within the band of 0), h'(0) = slope, h''(0) = curvature
    and the bounds |h''| ≤ g2, |h'''| ≤ g3, returns s > 0 with h(s) > band
    (beyond the rounding of h, so h(s) evaluates positive) and h > −band on
    [0, s] (no excursion is skipped), or None when neither minorant proves it
    (the motion onto this side is itself at rounding level: a graze):

    * moving in (slope > 0): the quadratic minorant value + slope s − g2 s²/2 is
      concave, so it is ≥ value on [0, slope/g2], where it reaches
      value + slope²/(2 g2);
    * a grazing entry (curvature > 0, slope ≈ 0): the cubic minorant
      value + slope s + curvature s²/2 − g3 s³/6 is ≥ value + min(slope, 0) s
      on [0, 2 curvature/g3], where it reaches value + slope s + (2/3) curvature³/g3².
    """
    if slope > 0.0:
        s = slope / g2
        if value + 0.5 * slope * s > band:
            return s
    if curvature > 0.0:
        s = 2.0 * curvature / g3
        if value + min(slope, 0.0) * s > -band and value + slope * s + (2.0 / 3.0) * curvature * (curvature / g3) ** 2 > band:
            return s
    return None


def _first_exit(
    offset: float,
    amplitude: float,
    derivatives: Callable[[float], tuple[float, float, float]],
    value: Callable[[float], float],
    g2: float,
    g3: float,
    slow_step: float,
    band: float,
    tau_max: float,
) -> _Bracket | None:
    """Bracket the first switching time of any h with |h''| ≤ g2 and |h'''| ≤ g3 on [0, tau_max].

    ``derivatives(τ)`` returns (h, h', h'') and ``value(τ)`` returns h (the
    function Brent's method polishes); ``h ≥ offset − amplitude`` on [0, tau_max]
    (the envelope); a root-free step shorter than ``slow_step`` (a tenth of the
    fastest time scale of h) is lengthened by the cubic minorant.

    The switching time is the zero of h that starts the first excursion of h
    below −band in (0, tau_max].  Returns None when h > −band on the whole of
    [0, tau_max] — certified by the minorants described in the module
    docstring, so no excursion deeper than band is missed.  Requires h(0) > −band.
    When h(0) ≤ band (the arc starts on the switching surface) the zero at
    τ = 0 is the switch that started the arc and is excluded (see
    :func:`_leave_surface`).  :func:`_first_exit_trig` supplies the evaluators and
    bounds of a trigonometric sum (:class:`~lindstedt.numerics.ExactFlow`);
    :class:`~lindstedt.numerics.forced_flow.ForcedFlow` those of sums of damped exponentials.
    """
    band = max(band, _TINY)
    if offset - amplitude > -band:  # envelope: never reaches −band
        return None
    g2 = max(g2 * (1.0 + 1e-12), _TINY)
    g3 = max(g3 * (1.0 + 1e-12), _TINY)

    tau = 0.0
    h, h1, h2 = derivatives(tau)
    last_nonnegative: float | None = 0.0 if h > band else None
    if last_nonnegative is None:
        # h(0) is within the band of the switching surface (an arc started at a switch, or at t = 0 on the
        # surface): there τ = 0 is the switch just made, so it must not become a bracket end (Brent would
        # return it, and the flow would switch back and forth at this instant, until max_arcs).  The search
        # continues from the first instant certified to be clearly on this side, if the motion onto it is
        # beyond rounding; else τ = 0 is a bracket end only when h is leaving this side (h ≥ 0 > h').
        start = _leave_surface(h, h1, h2, g2, g3, band)
        if start is not None:
            if start >= tau_max:
                return None
            tau = start
            h, h1, h2 = derivatives(tau)
            if h >= 0.0:
                last_nonnegative = tau
        elif h >= 0.0 and h1 < 0.0:
            last_nonnegative = 0.0
    for _ in range(_MAX_SEARCH_STEPS):
        lifted = h + band
        if lifted <= 0.01 * band:  # reached the far side of the band: an excursion
            if last_nonnegative is None:
                return _Bracket(tau, tau, None)
            return _Bracket(last_nonnegative, tau, value)
        # root-free radius of the quadratic minorant lifted + h1 s − g2 s²/2
        root = math.sqrt(h1 * h1 + 2.0 * g2 * lifted)
        step = (h1 + root) / g2 if h1 >= 0.0 else 2.0 * lifted / (root - h1)
        if h1 < 0.0 and -h1 / g2 > step:
            # h is strictly decreasing on [tau, tau + |h1|/g2]: one evaluation decides it
            window_end = min(tau - h1 / g2, tau_max)
            hw, hw1, hw2 = derivatives(window_end)
            if hw + band <= 0.01 * band:
                if h >= 0.0:  # unique zero of h in the window
                    return _Bracket(tau, window_end, value)
                if last_nonnegative is not None:
                    return _Bracket(last_nonnegative, tau, value)
                return _Bracket(tau, window_end, lambda s: value(s) + band)
            if window_end >= tau_max:
                return None
            tau, h, h1, h2 = window_end, hw, hw1, hw2
            if h >= 0.0:
                last_nonnegative = tau
            continue
        if step < slow_step:  # near a tangency: the cubic minorant uses the exact curvature
            step = max(step, _cubic_radius(lifted, h1, h2, g3))
        if tau + step >= tau_max:
            return None
        tau = tau + step
        h, h1, h2 = derivatives(tau)
        if h >= 0.0:
            last_nonnegative = tau
    raise _SearchFailure(
        f"the switch search made {_MAX_SEARCH_STEPS} certified steps without deciding "
        "(a gap function stalls at the rounding band)"
    )

def _first_exit_trig(
    offset: float,
    cos_coefficients: np.ndarray,
    sin_coefficients: np.ndarray,
    omega: np.ndarray,
    band: float,
    tau_max: float,
    counters: _Counters,
) -> _Bracket | None:
    """:func:`_first_exit` for h(τ) = offset + Σ a_k cos ω_k τ + b_k sin ω_k τ.

    With R_k = hypot(a_k, b_k): the envelope Σ R_k and the bounds
    |h''| ≤ Σ ω_k² R_k, |h'''| ≤ Σ ω_k³ R_k (module docstring).
    """
    amplitudes = np.hypot(cos_coefficients, sin_coefficients)
    amplitude = float(amplitudes.sum())
    if offset - amplitude > -max(band, _TINY):  # envelope: decided before any evaluator is built
        return None
    omega2 = omega * omega
    derivatives, value = _trig_sum(offset, cos_coefficients, sin_coefficients, omega, counters)
    return _first_exit(
        offset, amplitude, derivatives, value, float(omega2 @ amplitudes), float((omega2 * omega) @ amplitudes),
        0.1 / float(omega.max()), band, tau_max,
    )


def _earliest_switch(brackets: list[tuple[_Bracket, int]], counters: _Counters) -> tuple[float | None, int | None]:
    """The earliest switching time among the brackets of the surfaces (bracket, index) and its index, or (None, None).

    Only the brackets that can hold the earliest root are polished (in order of
    their low ends; ties go to the lower index).
    """
    best_tau, best = math.inf, None
    for bracket, i in sorted(brackets, key=lambda item: (item[0].low, item[1])):
        if bracket.low > best_tau:
            break
        tau = bracket.polish(counters)
        if tau < best_tau:
            best_tau, best = tau, i
    return (best_tau, best) if best is not None else (None, None)
