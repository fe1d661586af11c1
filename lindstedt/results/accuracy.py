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
  ``u(t)`` is meaningless once that reaches one radian;
* where nothing but the coefficients is known (the N-dof NNM), :func:`geometric_tail` bounds the whole
  neglected tail by a geometric envelope of ω_1 … ω_{n+1} and estimates the radius of convergence from their
  fastest growth (the 1-dof expansion reads the radius off the law instead:
  :mod:`lindstedt.results.orbit_range`).

:func:`series_warning` and :func:`phase_warning` return the text of an
:class:`ExpansionValidityWarning` (or None); the results emit it.
"""

from __future__ import annotations

import math
from typing import Any, Sequence

import numpy as np

from .._errors import ParameterError

__all__ = [
    "NEXT_TERM_SAFETY",
    "ExpansionValidityWarning",
    "TAIL_SAFETY",
    "branch_bound",
    "displacement_error",
    "geometric_tail",
    "gauge_values",
    "next_term_bound",
    "phase_warning",
    "quiet_radius",
    "radius_warning",
    "series_warning",
    "series_warning_mask",
]


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


def series_warning_mask(coefficients: np.ndarray, last: int, size: np.ndarray) -> np.ndarray:
    """Elementwise: would :func:`series_warning` speak at ``|η| = size``?  ``coefficients`` has shape
    (last + 2, ...) (ω_0 … ω_{last+1}, broadcast against ``size``); the same comparisons in the same order.

    Examples
    --------
    >>> import numpy as np
    >>> series_warning_mask(np.array([1.0, 0.5, 0.25, 0.125, 0.0625]), 3, np.array([0.1, 3.0])).tolist()
    [False, True]
    """
    size = np.abs(np.asarray(size, dtype=float))
    if last < 1:
        return np.zeros(np.broadcast_shapes(size.shape, np.shape(coefficients)[1:]), dtype=bool)
    with np.errstate(all="ignore"):
        terms = [np.abs(coefficients[k]) * size**k for k in range(last + 2)]
        correction = np.zeros_like(terms[0])
        for k in range(1, last + 1):
            correction = correction + coefficients[k] * size**k
        warn = terms[last + 1] > np.maximum(np.abs(correction), 1e-300)
        if last >= 3:
            warn = warn | (np.maximum(terms[last], terms[last + 1]) > np.maximum(terms[last - 2], terms[last - 1]))
    return warn


# |ω_{n+1}| is not derived until it matters: the warnings use it only where it could be large enough to speak.
# Its stand-in is NEXT_TERM_SAFETY times the geometric extrapolation of the known coefficients,
# max_j |ω_j| G^{n+1-j} with G = max_{j<k} (|ω_k|/|ω_j|)^{1/(k-j)} (the fastest growth among them).  Measured
# over 21 problems (polynomial, analytic, gaps near ±1, two-sided, grazing, Hertz; orders 1-6) the true
# |ω_{n+1}| reached at most 112 times the extrapolation (a gap at -0.999 a0, order 2); a factor 1000 keeps a
# margin of 9 over that.
NEXT_TERM_SAFETY = 1000.0


def next_term_bound(coefficients: np.ndarray, safety: float = NEXT_TERM_SAFETY) -> np.ndarray:
    """The stand-in for |ω_{n+1}| from ω_0 … ω_n (axis 0; vectorised over the other axes): ``safety`` times
    the geometric extrapolation of the known coefficients (see :data:`NEXT_TERM_SAFETY`); +inf where fewer
    than two of them are nonzero (nothing to extrapolate from).

    Examples
    --------
    >>> import numpy as np
    >>> float(next_term_bound(np.array([1.0, 0.5, 0.25]), safety=1.0))   # exactly geometric: 0.125
    0.125
    """
    sizes = np.abs(np.asarray(coefficients, dtype=float))
    count = sizes.shape[0]
    if sizes.ndim == 1:  # one coefficient set: plain floats
        values = [float(value) for value in sizes]
        rate = max(
            ((values[k] / values[j]) ** (1.0 / (k - j)) for j in range(count) for k in range(j + 1, count) if values[j] > 0 and values[k] > 0),
            default=0.0,
        )
        return np.float64(safety * max(value * rate ** (count - j) for j, value in enumerate(values)) if rate > 0 else np.inf)
    growth = np.zeros(sizes.shape[1:])
    with np.errstate(all="ignore"):
        for j in range(count):
            for k in range(j + 1, count):
                ratio = np.where((sizes[j] > 0) & (sizes[k] > 0), (sizes[k] / sizes[j]) ** (1.0 / (k - j)), 0.0)
                growth = np.maximum(growth, ratio)
        extrapolated = np.zeros(sizes.shape[1:])
        for j in range(count):
            extrapolated = np.maximum(extrapolated, sizes[j] * growth ** (count - j))
    return np.where(growth > 0, safety * extrapolated, np.inf)


def quiet_radius(coefficients: Sequence[float], last: int) -> float:
    """The largest r such that :func:`series_warning` is silent for every max |η| <= r (coefficients ω_0 …
    ω_{last+1}); 0 if it speaks at every r > 0, +inf if never.

    Between consecutive roots of the compared quantities (|ω_a| r^a = |ω_b| r^b, |ω_{n+1}| r^{n+1} = ±C(r),
    the 1e-300 floor) the answer cannot change, so it is read at one point per interval; the first
    interval that speaks ends the quiet range (shrunk by 1e-6 against rounding in the roots, then checked).

    Examples
    --------
    >>> r = quiet_radius([1.0, 0.5, 0.25, 0.125, 0.0625], 3)     # Σ (η/2)^k: silent up to its radius 2
    >>> 1.9 < r <= 2.0
    True
    """
    values = [float(value) for value in coefficients[: last + 2]]
    if last < 1:
        return math.inf
    sizes = [abs(value) for value in values]

    def speaks(r: float) -> bool:
        return series_warning(values, last, np.array([r]), "eps") is not None

    candidates: list[float] = []
    pairs = [(last + 1, b) for b in range(1, last + 1)]
    if last >= 3:
        pairs += [(a, b) for a in (last, last + 1) for b in (last - 2, last - 1)]
    for a, b in pairs:
        if sizes[a] > 0 and sizes[b] > 0:
            candidates.append((sizes[b] / sizes[a]) ** (1.0 / (a - b)))
    for k in range(last + 2):
        if sizes[k] > 0 and k:
            candidates.append((1e-300 / sizes[k]) ** (1.0 / k))
    correction = np.array([0.0] + values[1 : last + 1])
    for sign in (1.0, -1.0):
        polynomial = correction.copy()
        polynomial = np.append(polynomial, sign * sizes[last + 1])  # |ω_{n+1}| r^{n+1} ± C(r) = 0
        trimmed = np.trim_zeros(polynomial[::-1], "f")
        if trimmed.size > 1:
            for root in np.roots(trimmed):
                if abs(root.imag) <= 1e-9 * abs(root) and root.real > 0:
                    candidates.append(float(root.real))
    points = sorted({c for c in candidates if math.isfinite(c) and c > 0})
    edges = [0.0, *points]
    for low, high in zip(edges, [*points, math.inf]):
        probe = 2 * low + 1 if math.isinf(high) else 0.5 * (low + high)
        if speaks(probe):
            radius = low * (1 - 1e-6)
            while radius > 0 and speaks(radius):  # rounding in a root: step back
                radius *= 0.5
            return radius
    return math.inf


# The growth rate G of the coefficients (fastest among ω_1 … ω_{n+1}) is multiplied by TAIL_SAFETY before it bounds
# the tail.  Measured on the SDND123 system's mode 2 (two unilateral springs, exact ω by continuation + guided
# shooting), a0 in 1.5 … 3 (7 values) and 37 values of ε in 0.1 … 30, orders 2 and 4: with a factor 1 the true
# error exceeded the estimate at 69 of 518 points (by up to 1.16 times, irregular coefficients with cancellations);
# with 1.5 at none, the series being declared beyond its radius (q >= 1) at 191 of them.
TAIL_SAFETY = 1.5


def geometric_tail(coefficients: Sequence[float], last: int, eta: Any, safety: float = TAIL_SAFETY) -> tuple[np.ndarray, float]:
    """(estimate of |Σ_{k>last} ω_k η^k|, radius in η) from ``coefficients`` ω_0 … ω_{last+1} (vectorised over η).

    With G the fastest growth (|ω_k|/|ω_j|)^{1/(k−j)} among ω_1 … ω_{last+1} (ω_0, the linear frequency, sets
    no growth; sizes below 1e-12 of the largest are numerical zeros and set none either), ρ = 1/(``safety`` G) is the estimated radius and q = |η|/ρ; the estimate is the first neglected
    term plus the envelope B q^k of the later ones summed, B = max_j |ω_j| (safety G)^{−j}:

        |ω_{n+1}| |η|^{n+1} + B q^{n+2}/(1 − q),

    +inf where q >= 1 (the series is beyond its estimated radius).

    Examples
    --------
    >>> import numpy as np
    >>> estimate, radius = geometric_tail([1.0, 0.5, 0.25, 0.125], 2, np.array([0.1]), safety=1.0)
    >>> radius, bool(abs(estimate[0] - sum(0.5**k * 0.1**k for k in range(3, 60))) < 1e-15)   # Σ (η/2)^k exactly
    (2.0, True)
    """
    sizes = [abs(float(value)) for value in coefficients[1 : last + 2]]
    # A numerical zero (an exact zero computed in floating point: the N-dof hierarchy carries ~1e-17 absolute noise,
    # e.g. omega_3 = -1.5e-17 at a grazing spring) is no pivot for a growth rate: 0.25/1.5e-17 "grew" 1e16-fold and
    # put the radius at 1e-16.  Sizes below 1e-12 of the largest are zeros.
    floor = 1e-12 * max(sizes, default=0.0)
    sizes = [value if value > floor else 0.0 for value in sizes]
    pairs = [(sizes[k] / sizes[j]) ** (1.0 / (k - j)) for j in range(len(sizes)) for k in range(j + 1, len(sizes)) if sizes[j] > 0 and sizes[k] > 0]
    size = np.abs(np.asarray(eta, dtype=float))
    first = sizes[-1] * size ** (last + 1) if sizes else np.zeros_like(size)
    if not pairs or max(pairs) == 0:
        return np.asarray(first, dtype=float), math.inf
    growth = safety * max(pairs)
    envelope = max(value * growth ** -(j + 1) for j, value in enumerate(sizes))
    q = size * growth
    with np.errstate(all="ignore"):
        tail = np.where(q < 1, envelope * q ** (last + 2) / np.where(q < 1, 1 - q, 1.0), np.inf)
    return np.asarray(first + tail, dtype=float), 1.0 / growth


def radius_warning(radius: float, eta: Any, gauge: str, last: int) -> str | None:
    """The series is beyond its estimated radius (:func:`geometric_tail`) at some of ``eta``, or None."""
    size = np.abs(np.asarray(eta, dtype=float))
    if size.size == 0 or not float(np.max(size)) >= radius:
        return None
    worst = float(np.max(size))
    return (
        f"at {gauge} = {worst:.3g} the series is beyond its estimated radius of convergence {radius:.3g} (from the growth "
        f"of omega_1 … omega_{last + 1}, times a safety of {TAIL_SAFETY}): its truncation error cannot be estimated there; "
        "use a smaller eps or a numerical method (lindstedt.nnm_point, lindstedt.continue_nnm)"
    )


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
