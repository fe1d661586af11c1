"""Honest accuracy of a truncated series ω(ε) = Σ_{k≤n} ω_k η^k (η = ε or ε^{1/2}) and of its waveform.

Read off the coefficients the expansion already has (ω_0 … ω_{n+1}):

* the **first neglected term** |ω_{n+1} η^{n+1}| estimates the frequency's truncation error
  while the series converges;
* the series has **left its disc of convergence** where its terms |ω_k η^k| stop falling:
  a grazing nearby (the orbit reaching a breakpoint tangentially at some ε_g) is a
  singularity of ω(ε) at ε_g, and beyond it every order makes the value worse.  The terms
  are compared in pairs (the last two kept and the next one against the two before), which
  is robust to the interleaved analytic and non-analytic terms of the gauge ε^{1/2};
* over time the waveform's error is dominated by the phase drift δω t (δω the first neglected terms), so
  ``u(t)`` is meaningless once that reaches one radian.

:func:`series_warning` and :func:`phase_warning` return the text of an
:class:`ExpansionValidityWarning` (or None); the results emit it.
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from .._errors import ParameterError

__all__ = ["ExpansionValidityWarning", "branch_bound", "displacement_error", "gauge_values", "phase_warning", "series_warning"]


class ExpansionValidityWarning(UserWarning):
    """A numeric evaluation outside the range where the truncated series is meaningful."""


def series_warning(coefficients: Sequence[float], last: int, eta: np.ndarray, gauge: str) -> str | None:
    """Why ``Σ_{k≤last} ω_k η^k`` should not be trusted at some of ``eta`` (``coefficients`` run to last + 1), or None.

    Examples
    --------
    >>> import numpy as np
    >>> series_warning([1.0, 0.5, 0.25, 0.125, 0.0625], 3, np.array([0.1]), "eps") is None   # Σ (η/2)^k, η < 2
    True
    >>> "radius" in series_warning([1.0, 0.5, 0.25, 0.125, 0.0625], 3, np.array([3.0]), "eps")
    True
    """
    if last < 1 or eta.size == 0:
        return None
    worst = float(np.max(np.abs(eta)))
    terms = [abs(float(value)) * worst**k for k, value in enumerate(coefficients[: last + 2])]
    correction = abs(sum(float(value) * worst**k for k, value in enumerate(coefficients[1 : last + 1], start=1)))
    if last >= 3 and max(terms[last], terms[last + 1]) > max(terms[last - 2], terms[last - 1]):
        return (
            f"at {gauge} = {worst:.3g} the series is not converging: its terms grow (|omega_k {gauge}^k| = "
            + ", ".join(f"{term:.2g}" for term in terms[1:])
            + "): eps is beyond the radius of convergence (a grazing or another singularity of omega(eps) is that "
            "close) and no truncation is reliable; use a smaller eps or a numerical method "
            "(lindstedt.reference_solution, lindstedt.nnm_point)"
        )
    if terms[last + 1] > max(correction, 1e-300):
        return (
            f"at {gauge} = {worst:.3g} the next term omega_{last + 1} {gauge}^{last + 1} = {terms[last + 1]:.3g} is larger "
            "than the whole correction: the series is not converging there; use a smaller eps or a numerical method "
            "(lindstedt.reference_solution, lindstedt.nnm_point)"
        )
    return None


def phase_warning(drift_rate: float, times: np.ndarray) -> str | None:
    """The phase drift δω t (``drift_rate`` δω: the first neglected terms of the frequency used) reaches one radian
    at some of ``times``: the waveform is meaningless there."""
    if times.size == 0:
        return None
    latest = float(np.max(np.abs(times)))
    drift = abs(float(drift_rate)) * latest
    if not drift < 1.0:
        return (
            f"at t = {latest:.3g} the phase error of the truncated frequency, (first neglected terms of omega) t = "
            f"{drift:.3g} rad, is not small: the waveform holds on t << {1 / max(abs(float(drift_rate)), 1e-300):.3g} "
            "only; use a higher order, a smaller eps or lindstedt.reference_solution"
        )
    return None


def branch_bound(order_terms: Sequence, angles: Sequence[float]) -> float:
    """max_{s∈[0,π]} |W_n(s)| from its float terms ``[piece][component] -> (ν, parity, m, c)``, piece p on
    [angles[p−1], angles[p]] (0 and π at the ends), sampled at 65 points per piece (the terms are smooth
    on each piece; the sampled maximum is an estimate, not a bound)."""
    limits = [0.0, *[float(angle) for angle in angles], float(np.pi)]
    largest = 0.0
    for piece, (lower, upper) in zip(order_terms, zip(limits, limits[1:])):
        s = np.linspace(lower, upper, 65)
        for component in piece:
            total = np.zeros_like(s)
            for frequency, parity, power, value in component:
                total += value * s**power * (np.cos(frequency * s) if parity == 0 else np.sin(frequency * s))
            largest = max(largest, float(np.max(np.abs(total))))
    return largest


def displacement_error(amplitude: float, frequency_error: float, times: np.ndarray, neglected_term: float) -> np.ndarray:
    """Estimated |u(t) − u_n(t)|: the phase drift |a0| δω t (``frequency_error`` δω: the first neglected terms of
    the frequency used) plus ``neglected_term``, the size of the first neglected waveform term (the callers take
    the last kept one, |a0| η̂^n max|W_n|, times η̂)."""
    return abs(amplitude) * abs(frequency_error) * np.abs(times) + neglected_term


def gauge_values(epsilon: Any, steps: int, negative_hint: str) -> np.ndarray:
    """The gauge η at ε: ε itself (``steps`` = 1) or √ε (``steps`` = 2, which holds for ε ≥ 0 only: the perturbed
    orbit crosses the grazing breakpoint for ε > 0; ``negative_hint`` says what to use for ε < 0)."""
    points = np.asarray(epsilon, dtype=float)
    if steps == 1:
        return points
    if np.any(points < 0):
        raise ParameterError(
            "this expansion is in powers of sqrt(epsilon) (a grazing breakpoint that the perturbed orbit passes): "
            f"it holds for epsilon >= 0; for epsilon < 0 {negative_hint}"
        )
    return np.sqrt(points)
