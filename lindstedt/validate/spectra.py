"""Line spectra of periodic solutions of  u'' + ω0² u + ε f(u) = 0,  labelled in harmonics (figure 2 of the seed).

For a T-periodic signal ``u(t) = c_0 + Σ_{k≥1} c_k cos(kΩt) + s_k sin(kΩt)``
(``Ω = 2π/T``) sampled at ``n`` equally spaced points over ``m`` whole periods,
``t_j = j·mT/n`` (the end point excluded), the discrete Fourier transform
``û_l = Σ_j u(t_j) e^{−2πi jl/n}`` is, for ``n > 2mK`` (K the highest
harmonic present),

    û_0 = n c_0,     û_{km} = (n/2)(c_k − i s_k),     û_l = 0 otherwise,

so harmonic k sits exactly on bin ``l = km`` and every other bin is zero up to
rounding and aliasing (the spectrum is *line* shaped — no leakage).  The
normalised amplitudes returned are ``|c_0|`` and ``|c_k − i s_k|`` (the
one-sided amplitude), and the plotted quantity of the seed's figure 2 is
``log10(|û|/max|û|)``.

When the window is not a whole number of periods, a Hann window spreads each
line over three bins (amplitudes corrected by the window's coherent gain 1/2)
and peaks are found as local maxima.  Peaks are labelled by the nearest
multiple ``k`` of the fundamental Ω when within half a bin of it
(``label = None`` otherwise).

Helpers: :func:`expansion_spectrum` samples ``Σ_k ε^k v_k(ωt)`` over whole
periods of its own ω(ε); :func:`exact_spectrum` samples the true solution
(:func:`lindstedt.validate.reference_solution`) over whole periods of its
exact period (:func:`lindstedt.validate.exact_period`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any, Mapping, Sequence

import numpy as np

from .._errors import ProblemError
from ..render.json import JsonExport
from ..results.expansion import Expansion
from ..problems.oscillator import Oscillator
from .solutions import (
    DEFAULT_ATOL,
    DEFAULT_RTOL,
    _as_positive,
    _problem_of,
    _require_expansion,
    exact_period,
    reference_solution,
)

__all__ = ["SpectralPeak", "Spectrum", "spectrum", "expansion_spectrum", "exact_spectrum"]

WINDOWS = ("rectangular", "hann")
#: log10 of the relative amplitude below which a local maximum is not reported as a peak
DEFAULT_PEAK_FLOOR = -10.0
#: the floor used instead of log10(0)
_LOG_FLOOR = -300.0


@dataclass(frozen=True, repr=False)
class SpectralPeak(JsonExport):
    """One line of the spectrum.

    Attributes
    ----------
    label : int or None
        Harmonic number k (the peak is at k × the fundamental), or None.
    bin : int
        DFT bin index.
    angular_frequency : float
        Its angular frequency (rad per unit time).
    amplitude : float
        One-sided amplitude (``|c_0|`` for the mean, ``|c_k − i s_k|`` otherwise).
    log10_relative : float
        ``log10(amplitude / largest amplitude)``.

    A line of a :class:`Spectrum` (whose problem it shares).  JSON schema
    ``lindstedt.spectral-peak/1`` (:meth:`to_json`).
    """

    SCHEMA = "lindstedt.spectral-peak/1"

    label: int | None
    bin: int
    angular_frequency: float
    amplitude: float
    log10_relative: float


@dataclass(frozen=True, repr=False)
class Spectrum(JsonExport):
    """One-sided amplitude spectrum of uniformly sampled data.

    Attributes
    ----------
    success : bool
        False if the inputs were inconsistent with the method (see ``message``).
    message : str
        What was done.
    angular_frequencies : numpy.ndarray
        ``2π l / duration`` for the bins ``l = 0 … n//2``.
    amplitudes : numpy.ndarray
        One-sided amplitudes (see the module docstring; window gain corrected).
    coefficients : numpy.ndarray (complex)
        ``c_0`` and ``c_k − i s_k`` per bin (phase relative to the first sample).
    log10_relative : numpy.ndarray
        ``log10(amplitude / max amplitude)`` (−300 where the amplitude is 0).
    fundamental : float or None
        Ω, the angular frequency of the fundamental (given, or from ``periods``).
    peaks : tuple of SpectralPeak
        Local maxima above ``peak_floor``, by increasing frequency.
    window : str
        ``"rectangular"`` or ``"hann"``.
    duration : float
        Length of the sampled window.
    periods : float or None
        Number of fundamental periods in the window, when known.
    n_samples : int
        Samples transformed.
    problem : Oscillator or None
        The problem whose solution (or expansion) was sampled; None for
        :func:`spectrum` of given samples.  Exported as its description.

    JSON schema ``lindstedt.spectrum/1`` (:meth:`to_json`; complex
    coefficients as ``[real, imag]`` pairs).
    """

    SCHEMA = "lindstedt.spectrum/1"

    success: bool
    message: str
    angular_frequencies: np.ndarray
    amplitudes: np.ndarray
    coefficients: np.ndarray
    log10_relative: np.ndarray
    fundamental: float | None
    peaks: tuple[SpectralPeak, ...]
    window: str
    duration: float
    periods: float | None
    n_samples: int
    problem: Oscillator | None = field(default=None, repr=False, compare=False)

    @property
    def harmonic_numbers(self) -> np.ndarray:
        """Bin frequencies in units of the fundamental (NaN if it is unknown)."""
        if self.fundamental is None:
            return np.full(self.angular_frequencies.shape, np.nan)
        return self.angular_frequencies / self.fundamental

    @property
    def labels(self) -> tuple[int | None, ...]:
        """The peak labels, e.g. ``(0, 1, 2, 4)``."""
        return tuple(peak.label for peak in self.peaks)

    def harmonic_bin(self, k: int) -> int:
        """The bin of harmonic k (nearest bin to k Ω)."""
        if self.fundamental is None:
            raise ProblemError("this spectrum has no fundamental frequency: pass fundamental= or periods=")
        spacing = 2 * math.pi / self.duration
        index = int(round(k * self.fundamental / spacing))
        if not 0 <= index < self.amplitudes.size:
            raise ProblemError(f"harmonic {k} lies beyond the Nyquist frequency of these samples")
        return index

    def harmonic_amplitude(self, k: int) -> float:
        """One-sided amplitude at harmonic k (``|c_0|`` for k = 0)."""
        return float(self.amplitudes[self.harmonic_bin(k)])

    def cosine_coefficient(self, k: int) -> float:
        """``c_k`` (real part of the coefficient at harmonic k; exact for whole periods)."""
        return float(self.coefficients[self.harmonic_bin(k)].real)


def spectrum(
    samples: Sequence[float],
    duration: float,
    *,
    periods: float | None = None,
    fundamental: float | None = None,
    window: str | None = None,
    peak_floor: float = DEFAULT_PEAK_FLOOR,
) -> Spectrum:
    """Amplitude spectrum of samples ``u(j·duration/n)``, ``j = 0 … n−1``.

    Parameters
    ----------
    samples : array_like, shape (n,)
        Equally spaced samples, the end point of the window excluded.
    duration : float
        Window length ``n·Δt``.
    periods : float, optional
        Number of fundamental periods in the window; gives
        ``fundamental = 2π periods/duration``.  A whole number selects the
        exact line spectrum (rectangular window).
    fundamental : float, optional
        Angular frequency Ω of the fundamental (instead of ``periods``).
    window : {"rectangular", "hann"}, optional
        Default: rectangular for a whole number of periods, Hann otherwise.
    peak_floor : float
        Peaks with ``log10_relative`` below this are not reported.

    Returns
    -------
    Spectrum

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(64) * 2 * np.pi / 64                    # one period of cos t
    >>> result = spectrum(0.5 + np.cos(t) + 0.25 * np.cos(3 * t), 2 * np.pi, periods=1)
    >>> result.labels, [round(p.amplitude, 12) for p in result.peaks]
    ((0, 1, 3), [0.5, 1.0, 0.25])
    >>> round(result.cosine_coefficient(3), 12), result.harmonic_amplitude(2) < 1e-15
    (0.25, True)
    """
    values = np.asarray(samples, dtype=float).reshape(-1)
    n = values.size
    if n < 4:
        raise ProblemError(f"a spectrum needs at least 4 samples, got {n}")
    if not np.all(np.isfinite(values)):
        raise ProblemError("samples must be finite")
    length = _as_positive(duration, "duration")
    if periods is not None and fundamental is not None:
        raise ProblemError("give either periods= or fundamental=, not both")
    # cycles: the number of fundamental periods in the window, when known
    cycles: float | None = None
    fundamental_value: float | None = None
    if periods is not None:
        cycles = _as_positive(periods, "periods")
        fundamental_value = 2 * math.pi * cycles / length
    elif fundamental is not None:
        fundamental_value = _as_positive(fundamental, "fundamental (an angular frequency)")
        cycles = fundamental_value * length / (2 * math.pi)
    whole = cycles is not None and abs(cycles - round(cycles)) <= 1e-9 * max(1.0, cycles)
    if window is None:
        window = "rectangular" if whole else "hann"
    if window not in WINDOWS:
        raise ProblemError(f"window must be one of {WINDOWS}, got {window!r}")
    if window == "hann":
        weights = 0.5 - 0.5 * np.cos(2 * np.pi * np.arange(n) / n)  # periodic Hann, coherent gain 1/2
        gain = 0.5
    else:
        weights = np.ones(n)
        gain = 1.0
    transform = np.fft.rfft(values * weights)
    scale = np.full(transform.size, 2.0 / (n * gain))
    scale[0] = 1.0 / (n * gain)
    if n % 2 == 0:
        scale[-1] = 1.0 / (n * gain)  # the Nyquist bin is not doubled
    coefficients = transform * scale
    amplitudes = np.abs(coefficients)
    largest = float(amplitudes.max())
    with np.errstate(divide="ignore"):
        relative = np.where(amplitudes > 0, np.log10(amplitudes / largest) if largest > 0 else _LOG_FLOOR, _LOG_FLOOR)
    frequencies = 2 * np.pi * np.arange(transform.size) / length
    # peaks above the floor: every harmonic bin of a line spectrum (whole periods,
    # rectangular window: lines do not leak), and local maxima elsewhere
    # (on |û| itself: the one-sided doubling would make the leakage of the mean into
    # bin 1 under a Hann window as large as the mean)
    padded = np.concatenate([[-np.inf], np.abs(transform), [-np.inf]])
    is_peak = (padded[1:-1] > padded[:-2]) & (padded[1:-1] >= padded[2:])
    if window == "rectangular" and whole:
        is_peak |= np.arange(transform.size) % int(round(cycles)) == 0
    is_peak &= relative >= peak_floor
    spacing = 2 * math.pi / length
    peaks = []
    for index in np.flatnonzero(is_peak):
        label = None
        if fundamental_value is not None:
            k = int(round(frequencies[index] / fundamental_value))
            if abs(frequencies[index] - k * fundamental_value) <= 0.5 * spacing + 1e-12 * frequencies[index]:
                label = k
        peaks.append(SpectralPeak(label, int(index), float(frequencies[index]), float(amplitudes[index]), float(relative[index])))
    unlabelled = sum(1 for peak in peaks if peak.label is None and fundamental_value is not None)
    message = (
        f"{n} samples, {window} window, {len(peaks)} peaks above 10^{peak_floor:g}"
        + (f", {unlabelled} not at a harmonic" if unlabelled else "")
    )
    return Spectrum(
        success=largest > 0,
        message=message if largest > 0 else "all samples are zero",
        angular_frequencies=frequencies,
        amplitudes=amplitudes,
        coefficients=coefficients,
        log10_relative=relative,
        fundamental=fundamental_value,
        peaks=tuple(peaks),
        window=window,
        duration=length,
        periods=cycles,
        n_samples=n,
    )


def _check_sampling(periods: int, samples_per_period: int) -> tuple[int, int]:
    if isinstance(periods, bool) or int(periods) != periods or periods < 1:
        raise ProblemError(f"periods must be a positive integer, got {periods!r}")
    if isinstance(samples_per_period, bool) or int(samples_per_period) != samples_per_period or samples_per_period < 8:
        raise ProblemError(f"samples_per_period must be an integer ≥ 8, got {samples_per_period!r}")
    return int(periods), int(samples_per_period)


def _window_times(duration: float, periods: int, samples_per_period: int) -> np.ndarray:
    """``samples_per_period`` equally spaced times per period over ``[0, duration)``."""
    n = periods * samples_per_period
    return np.arange(n) * (duration / n)


def _with_message(result: Spectrum, prefix: str, success: bool = True, problem: Oscillator | None = None) -> Spectrum:
    return replace(result, message=prefix + result.message, success=result.success and success, problem=problem)


def expansion_spectrum(
    expansion: Expansion,
    epsilon: float,
    *,
    values: Mapping[Any, Any] | None = None,
    periods: int = 1,
    samples_per_period: int = 512,
    peak_floor: float = DEFAULT_PEAK_FLOOR,
) -> Spectrum:
    """Spectrum of ``u_N(t) = Σ_{k≤N} ε^k v_k(ω t)`` over whole periods ``2π/ω(ε)``.

    ω(ε) is the expansion's frequency through ω_{N+1} (the one
    :meth:`~lindstedt.Expansion.displacement` uses), so the window holds
    exactly ``periods`` periods and harmonic k lands on bin ``k·periods``;
    its cosine coefficient is ``Σ_j ε^j d_{j,k}`` up to aliasing from
    harmonics beyond ``samples_per_period/2``.

    Examples
    --------
    >>> import lindstedt
    >>> e = lindstedt.expand("Max(0, u)", order=1, a0=1, omega0=1)
    >>> s = expansion_spectrum(e, 0.1, peak_floor=-8)
    >>> s.labels[:5]                                  # mean, fundamental, even harmonics
    (0, 1, 2, 4, 6)
    >>> bool(abs(s.cosine_coefficient(0) - 0.1 * (-1 / np.pi)) < 1e-8)     # ε d_0, d_0 = −1/π
    True

    (``u_N`` switches branches at the moving contact angle ``β + σ_1 ε``, so
    it differs from the Fourier series of ``v_0 + ε v_1`` by ``O(ε^5)`` here.)
    """
    _require_expansion(expansion, "expansion_spectrum")
    periods, samples_per_period = _check_sampling(periods, samples_per_period)
    omega = float(expansion.frequency(float(epsilon), values, order=expansion.order + 1))
    if not omega > 0:
        raise ProblemError(f"ω(ε) = {omega} is not positive at ε = {epsilon}: ε is too large for this expansion")
    duration = periods * 2 * math.pi / omega
    times = _window_times(duration, periods, samples_per_period)
    samples = np.asarray(expansion.displacement(times, float(epsilon), values), dtype=float)
    result = spectrum(samples, duration, periods=periods, peak_floor=peak_floor)
    return _with_message(result, f"expansion of order {expansion.order} at ε = {epsilon:g}, ω = {omega:.15g}; ",
                         problem=expansion.problem)


def exact_spectrum(
    source: Oscillator | Expansion,
    epsilon: float,
    *,
    values: Mapping[Any, Any] | None = None,
    a1: float = 0.0,
    periods: int = 1,
    samples_per_period: int = 512,
    peak_floor: float = DEFAULT_PEAK_FLOOR,
    rtol: float = DEFAULT_RTOL,
    atol: float = DEFAULT_ATOL,
) -> Spectrum:
    """Spectrum of the true solution over whole periods of its exact period.

    Examples
    --------
    >>> import lindstedt
    >>> s = exact_spectrum(lindstedt.Oscillator("u**3", a0=1, omega0=1), 0.1, samples_per_period=64)
    >>> s.labels                                             # odd harmonics only
    (1, 3, 5, 7)
    """
    problem = _problem_of(source)
    periods, samples_per_period = _check_sampling(periods, samples_per_period)
    period = exact_period(source, epsilon, values=values, a1=a1, rtol=rtol, atol=atol)
    if not math.isfinite(period.period):
        raise ProblemError(f"cannot sample whole periods: {period.message}")
    duration = periods * period.period
    times = _window_times(duration, periods, samples_per_period)
    reference = reference_solution(source, epsilon, times, values=values, a1=a1, rtol=rtol, atol=atol)
    result = spectrum(reference.displacement, duration, periods=periods, peak_floor=peak_floor)
    prefix = f"exact solution of {problem.describe()} at ε = {epsilon:g}, P = {period.period:.16g}; "
    return _with_message(result, prefix, reference.success and period.success, problem=problem)
