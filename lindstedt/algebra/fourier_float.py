r"""Fourier coefficients of the contact functions (cos s − κ)_+ and H(cos s − κ) in floating point, vectorised.

The closed forms of :mod:`lindstedt.algebra.fourier` (``c_k[κ]``, ``h_k[κ]``) evaluated
over arrays of κ and harmonics k, accurate to ~1e-16 near grazing contact
(|κ| → 1) and for harmonics up to k ~ 1e6.

Float path (see :func:`contact_ramp_coefficients_float`):

* reflection ``c_k[kappa] = (-1)**k c_k[-kappa] + [k=0](-kappa) + [k=1]`` (from
  ``x = x_+ - (-x)_+`` and ``-cos s = cos(s + pi)``) keeps ``beta <= pi/2``;
* ``beta`` is computed as a double-double: ``2 asin(sqrt((1 - |kappa|)/2))`` for
  ``|kappa| >= 1/2`` (``1 - |kappa|`` is then exact) and ``pi/2 - asin|kappa|``
  otherwise, each ``asin`` refined by one Newton step whose residual
  ``sin(theta) - y`` is formed without cancellation; ``k*beta`` is then reduced
  modulo ``2*pi`` in double-double, so the phase error stays ~1e-16 even for
  ``k = 1e6`` (a plain double ``beta`` would lose ``log10(k)`` digits);
* ``kappa sin x - k sin(beta) cos x`` (``x = k beta``) is rewritten as
  ``P(x) - (1 - kappa) sin x + x Q(beta) cos x`` with ``P(x) = sin x - x cos x`` and
  ``Q(beta) = 1 - sin(beta)/beta`` evaluated by their Taylor series for small
  arguments: every term is then free of catastrophic cancellation.
"""



from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from .._errors import ProblemError
from .fourier import _MAX_EXACT_HARMONIC, ArrayLike

__all__ = ["contact_angle_float", "contact_ramp_coefficients_float", "contact_step_coefficients_float"]

# ---------------------------------------------------------------------------
# float path: double-double helpers
# ---------------------------------------------------------------------------

_SPLITTER = 134217729.0  # 2**27 + 1, Dekker split constant
_TWO_PI_HI = 6.283185307179586
_TWO_PI_LO = 2.4492935982947064e-16
_HALF_PI_HI = 1.5707963267948966
_HALF_PI_LO = 6.123233995736766e-17


def _two_sum(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Knuth's error-free sum: ``a + b = total + error`` exactly."""
    total = a + b
    b_virtual = total - a
    error = (a - (total - b_virtual)) + (b - b_virtual)
    return total, error


def _split(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Dekker split of ``a`` into two 26-bit halves."""
    scaled = _SPLITTER * a
    high = scaled - (scaled - a)
    return high, a - high


_TWO_PI_SPLIT = _split(np.float64(_TWO_PI_HI))


def _two_prod(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Dekker's error-free product: ``a * b = product + error`` exactly."""
    product = a * b
    a_high, a_low = _split(a)
    b_high, b_low = _split(b)
    error = ((a_high * b_high - product) + a_high * b_low + a_low * b_high) + a_low * b_low
    return product, error


def _two_prod_split(a: np.ndarray, b_high: float, b_low: float) -> tuple[np.ndarray, np.ndarray]:
    """Error-free product with a constant whose Dekker split is precomputed."""
    product = a * (b_high + b_low)
    a_high, a_low = _split(a)
    error = ((a_high * b_high - product) + a_high * b_low + a_low * b_high) + a_low * b_low
    return product, error


def _horner(coefficients: tuple[float, ...], x: np.ndarray) -> np.ndarray:
    result = np.full_like(x, coefficients[-1])
    for coefficient in coefficients[-2::-1]:
        result *= x
        result += coefficient
    return result


# (sin t - t + t^3/6 - t^5/120) / t^7 = sum_n (-1)^(n+1) t^(2n) / (2n+7)!
_SINE_TAIL7 = tuple((-1) ** (n + 1) / math.factorial(2 * n + 7) for n in range(8))
# (t - sin t) / t^3 = sum_n (-1)^n t^(2n) / (2n+3)!
_SINE_DEFECT3 = tuple((-1) ** n / math.factorial(2 * n + 3) for n in range(11))
# (sin t - t cos t) / t^3 = sum_n (-1)^n (2n+2) t^(2n) / (2n+3)!
_SINE_MINUS_TCOS3 = tuple((-1) ** n * (2 * n + 2) / math.factorial(2 * n + 3) for n in range(11))


def _dd_divide_by(high: np.ndarray, low: np.ndarray, divisor: float) -> tuple[np.ndarray, np.ndarray]:
    """Double-double ``(high + low) / divisor`` for an exact integer divisor below 2**26."""
    quotient = high / divisor
    quotient_high, quotient_low = _split(quotient)
    remainder = (high - quotient_high * divisor) - quotient_low * divisor  # exact
    return quotient, (remainder + low) / divisor


def _asin_double_double(target_hi: np.ndarray, target_lo: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """Double-double arcsin of ``target_hi + target_lo`` for targets in [0, 1/2].

    One Newton step on ``sin(theta) = target`` from the libm value.  The residual
    ``sin(theta_hi) - target`` is ``(theta_hi - target_hi) - theta^3/6 + theta^5/120 + tail``:
    the first difference is exact (Sterbenz), ``theta^3/6`` and ``theta^5/120`` are
    double-doubles whose leading parts cancel exactly against it, so the residual
    (about one ulp of theta) is obtained to ~1e-21 relative to theta.
    """
    theta_hi = np.arcsin(target_hi)
    square_hi, square_lo = _two_prod(theta_hi, theta_hi)
    cube_hi, cube_lo = _two_prod(square_hi, theta_hi)
    cube_lo += square_lo * theta_hi
    fifth_hi, fifth_lo = _two_prod(cube_hi, square_hi)
    fifth_lo += cube_hi * square_lo + cube_lo * square_hi
    sixth_hi, sixth_lo = _dd_divide_by(cube_hi, cube_lo, 6.0)
    term5_hi, term5_lo = _dd_divide_by(fifth_hi, fifth_lo, 120.0)
    tail = fifth_hi * square_hi * _horner(_SINE_TAIL7, square_hi)
    residual = (((theta_hi - target_hi) - sixth_hi) + term5_hi) + ((term5_lo - sixth_lo) + tail)
    if target_lo is not None:
        residual -= target_lo
    theta_lo = -residual / np.cos(theta_hi)
    return theta_hi, theta_lo


@dataclass(frozen=True)
class _AngleData:
    """Contact-angle data for ``a = |kappa|`` in [0, 1]: ``beta = angle_hi + angle_lo``."""

    angle_hi: np.ndarray
    angle_lo: np.ndarray
    one_minus_kappa: np.ndarray
    sine_of_angle: np.ndarray

    def broadcast_to(self, shape: tuple[int, ...]) -> "_AngleData":
        return _AngleData(*(np.broadcast_to(field, shape) for field in
                            (self.angle_hi, self.angle_lo, self.one_minus_kappa, self.sine_of_angle)))

    def select(self, mask: np.ndarray | None) -> "_AngleData":
        if mask is None:
            return self
        return _AngleData(self.angle_hi[mask], self.angle_lo[mask], self.one_minus_kappa[mask],
                          self.sine_of_angle[mask])


def _angle_data(absolute_kappa: np.ndarray) -> _AngleData:
    """Double-double ``beta = arccos(a)`` (relative error ~1e-21) for ``a`` in [0, 1]."""
    absolute_kappa = np.asarray(absolute_kappa, dtype=float)
    angle_hi = np.empty_like(absolute_kappa)
    angle_lo = np.empty_like(absolute_kappa)
    near_grazing = absolute_kappa >= 0.5
    # a >= 1/2: beta = 2 asin(sqrt((1 - a)/2)); 1 - a is exact (Sterbenz).
    if np.any(near_grazing):
        half_gap = 0.5 * (1.0 - absolute_kappa[near_grazing])
        root_hi = np.sqrt(half_gap)
        square_hi, square_lo = _two_prod(root_hi, root_hi)
        with np.errstate(divide="ignore", invalid="ignore"):
            root_lo = np.where(root_hi > 0.0, ((half_gap - square_hi) - square_lo) / (2.0 * root_hi), 0.0)
        theta_hi, theta_lo = _asin_double_double(root_hi, root_lo)
        angle_hi[near_grazing] = 2.0 * theta_hi
        angle_lo[near_grazing] = 2.0 * theta_lo
    # a < 1/2: beta = pi/2 - asin(a), with pi/2 as a double-double.
    central = ~near_grazing
    if np.any(central):
        phi_hi, phi_lo = _asin_double_double(absolute_kappa[central], None)
        high, low = _two_sum(np.full_like(phi_hi, _HALF_PI_HI), -phi_hi)
        high, low = _two_sum(high, low + (_HALF_PI_LO - phi_lo))
        angle_hi[central] = high
        angle_lo[central] = low
    one_minus_kappa = 1.0 - absolute_kappa
    sine_of_angle = np.sqrt(one_minus_kappa * (1.0 + absolute_kappa))
    return _AngleData(angle_hi, angle_lo, one_minus_kappa, sine_of_angle)


def _phase_sin_cos(
    harmonic: np.ndarray, angle_hi: np.ndarray, angle_lo: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return ``(x, sin x, cos x)`` for ``x = k * beta``, reducing the phase modulo 2 pi in double-double."""
    phase_hi, phase_lo = _two_prod(harmonic, angle_hi)
    phase_lo += harmonic * angle_lo
    turns = np.rint(phase_hi * (1.0 / _TWO_PI_HI))
    turn_hi, turn_lo = _two_prod_split(turns, *_TWO_PI_SPLIT)
    reduced_hi = phase_hi - turn_hi  # exact (Sterbenz)
    reduced_lo = (phase_lo - turn_lo) - turns * _TWO_PI_LO
    reduced_hi, reduced_lo = _two_sum(reduced_hi, reduced_lo)
    sine_hi = np.sin(reduced_hi)
    cosine_hi = np.cos(reduced_hi)
    sine = sine_hi + cosine_hi * reduced_lo
    cosine = cosine_hi - sine_hi * reduced_lo
    return phase_hi, sine, cosine


def _sine_minus_t_cosine(t: np.ndarray, sine: np.ndarray, cosine: np.ndarray) -> np.ndarray:
    """``sin t - t cos t`` without cancellation for small ``t >= 0`` (Taylor series below 1)."""
    result = sine - t * cosine
    small = t < 1.0
    if np.any(small):
        t_small = t[small]
        result[small] = t_small**3 * _horner(_SINE_MINUS_TCOS3, t_small * t_small)
    return result


def _one_minus_sinc(t: np.ndarray, sine: np.ndarray) -> np.ndarray:
    """``1 - sin(t)/t`` without cancellation for small ``t >= 0`` (Taylor series below 1)."""
    small = t < 1.0
    with np.errstate(divide="ignore", invalid="ignore"):
        result = 1.0 - sine / t
    if np.any(small):
        t_small = t[small]
        result[small] = t_small * t_small * _horner(_SINE_DEFECT3, t_small * t_small)
    return result


def _validated_float_inputs(kappa: ArrayLike, harmonics: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    kappa_array = np.asarray(kappa, dtype=float)
    if np.any(np.isnan(kappa_array)):
        raise ProblemError("kappa contains NaN; pass finite real thresholds kappa = b/|a0|")
    harmonic_array = np.asarray(harmonics)
    if harmonic_array.dtype == bool or not (
        np.issubdtype(harmonic_array.dtype, np.integer) or np.issubdtype(harmonic_array.dtype, np.floating)
    ):
        raise ProblemError("harmonics must be an integer array (k = 0, 1, 2, ...); pass e.g. numpy.arange(n)")
    harmonic_float = harmonic_array.astype(float)
    if np.any(~np.isfinite(harmonic_float)) or np.any(harmonic_float != np.floor(harmonic_float)):
        raise ProblemError("harmonics must hold whole numbers; pass integer harmonic indices k >= 0")
    if np.any(harmonic_float < 0):
        raise ProblemError("harmonics must be non-negative; cosine harmonics are indexed by k >= 0")
    if np.any(harmonic_float > _MAX_EXACT_HARMONIC):
        raise ProblemError("harmonics above 2**53 are not exactly representable; use contact_ramp_coefficient_mp")
    return kappa_array, harmonic_float


def contact_angle_float(kappa: ArrayLike) -> np.ndarray:
    """Contact angle ``beta = arccos(kappa)`` in double precision, clamped to ``[0, pi]``.

    Computed from a double-double ``arccos(|kappa|)`` (half-angle form
    ``2 asin(sqrt((1 - |kappa|)/2))`` near grazing) and reflected for negative kappa,
    so ``beta`` is correctly rounded up to rare ties, including near ``kappa = +-1``.

    Parameters
    ----------
    kappa : array_like of float
        Contact thresholds.

    Returns
    -------
    numpy.ndarray
        ``beta`` with the shape of ``kappa``.

    Examples
    --------
    >>> import mpmath
    >>> beta = float(contact_angle_float(1 - 2.0**-40))
    >>> beta == float(mpmath.acos(1 - mpmath.mpf(2) ** -40))
    True
    """
    kappa_array, _ = _validated_float_inputs(kappa, 0)
    clipped = np.clip(np.atleast_1d(kappa_array), -1.0, 1.0)
    data = _angle_data(np.abs(clipped))
    negative = clipped < 0
    high = np.where(negative, 2.0 * _HALF_PI_HI - data.angle_hi, data.angle_hi)
    low = np.where(negative, 2.0 * _HALF_PI_LO - data.angle_lo, data.angle_lo)
    return (high + low).reshape(kappa_array.shape)


def _general_ramp(data: _AngleData, harmonic: np.ndarray) -> np.ndarray:
    """c_k[a], k >= 2: 2 [P(x) - (1-a) sin x + x Q(beta) cos x] / (pi k (k^2-1)), x = k beta."""
    phase, sine, cosine = _phase_sin_cos(harmonic, data.angle_hi, data.angle_lo)
    numerator = _sine_minus_t_cosine(phase, sine, cosine)
    numerator -= data.one_minus_kappa * sine
    numerator += phase * _one_minus_sinc(data.angle_hi, data.sine_of_angle) * cosine
    return 2.0 * numerator / (math.pi * harmonic * ((harmonic - 1.0) * (harmonic + 1.0)))


def _fill_by_harmonic(
    harmonic: np.ndarray,
    data: _AngleData,
    low_order: dict[int, Callable[[_AngleData], np.ndarray]],
    general: Callable[[_AngleData, np.ndarray], np.ndarray],
) -> np.ndarray:
    """Evaluate ``general`` for k not in ``low_order`` and the special formulas elsewhere."""
    result = np.empty(harmonic.shape)
    special = np.zeros(harmonic.shape, dtype=bool)
    for order, formula in low_order.items():
        mask = harmonic == order
        if np.any(mask):
            result[mask] = formula(data.select(mask))
            special |= mask
    if not np.any(special):
        return general(data.select(None), harmonic)
    rest = ~special
    if np.any(rest):
        result[rest] = general(data.select(rest), harmonic[rest])
    return result


def _ramp_magnitude(data: _AngleData, harmonic: np.ndarray) -> np.ndarray:
    """c_k[a] for a = |kappa| in [0, 1] (arrays of equal shape)."""
    def mean_value(part: _AngleData) -> np.ndarray:  # (sin b - a b)/pi = P(b)/pi since cos b = a
        cosine = 1.0 - part.one_minus_kappa
        return _sine_minus_t_cosine(part.angle_hi, part.sine_of_angle.copy(), cosine) / math.pi

    def first(part: _AngleData) -> np.ndarray:  # (b - sin b cos b)/pi = z Q(z) / (2 pi), z = 2b
        doubled = 2.0 * part.angle_hi
        sine_doubled = 2.0 * part.sine_of_angle * (1.0 - part.one_minus_kappa)
        return doubled * _one_minus_sinc(doubled, sine_doubled) / (2.0 * math.pi)

    return _fill_by_harmonic(harmonic, data, {0: mean_value, 1: first}, _general_ramp)


def _step_magnitude(data: _AngleData, harmonic: np.ndarray) -> np.ndarray:
    """h_k[a] for a = |kappa| in [0, 1] (arrays of equal shape)."""
    def mean_value(part: _AngleData) -> np.ndarray:
        return (part.angle_hi + part.angle_lo) / math.pi

    def general(part: _AngleData, k: np.ndarray) -> np.ndarray:
        _, sine, _ = _phase_sin_cos(k, part.angle_hi, part.angle_lo)
        return 2.0 * sine / (math.pi * k)

    return _fill_by_harmonic(harmonic, data, {0: mean_value}, general)


def _prepare(kappa: ArrayLike, harmonics: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray, _AngleData]:
    """Validate, compute the angle data once per kappa, and broadcast against the harmonics."""
    kappa_array, harmonic_float = _validated_float_inputs(kappa, harmonics)
    kappa_array, harmonic_float = np.atleast_1d(kappa_array), np.atleast_1d(harmonic_float)
    clipped = np.clip(kappa_array, -1.0, 1.0)
    data = _angle_data(np.abs(clipped))
    shape = np.broadcast_shapes(kappa_array.shape, harmonic_float.shape)
    harmonic_b = np.broadcast_to(harmonic_float, shape)
    return np.broadcast_to(kappa_array, shape), harmonic_b, np.broadcast_to(clipped, shape), data.broadcast_to(shape)


def _output_shape(kappa: ArrayLike, harmonics: ArrayLike) -> tuple[int, ...]:
    return np.broadcast_shapes(np.shape(kappa), np.shape(harmonics))


def contact_ramp_coefficients_float(kappa: ArrayLike, harmonics: ArrayLike) -> np.ndarray:
    """Vectorised, cancellation-free ``c_k[kappa]`` in double precision.

    ``kappa`` and ``harmonics`` broadcast against each other (use
    ``kappa[:, None]`` and ``harmonics[None, :]`` for a table); the contact angle
    is computed once per kappa.

    Parameters
    ----------
    kappa : array_like of float
        Contact thresholds (any real; ``|kappa| >= 1`` handled exactly, NaN rejected).
    harmonics : array_like of int
        Harmonic indices ``k >= 0``.

    Returns
    -------
    numpy.ndarray
        ``c_k[kappa]`` with the broadcast shape.  Accuracy: a few 1e-15 relative to
        the natural scale ``(2/(pi k)) min(k beta^3/3, (sin beta + 1/k)/k)`` of ``c_k``
        (beta taken in [0, pi/2] after reflection), including ``kappa = +-(1 - 1e-12)``
        and ``k`` up to ``1e6``.

    Raises
    ------
    ProblemError
        If kappa contains NaN or harmonics are not non-negative integers.

    Examples
    --------
    >>> import numpy as np
    >>> c = contact_ramp_coefficients_float(0.0, np.arange(4))
    >>> np.allclose(c, [1 / np.pi, 0.5, 2 / (3 * np.pi), 0.0], rtol=0, atol=1e-15)
    True
    >>> contact_ramp_coefficients_float([2.0, -2.0], 0).tolist()
    [0.0, 2.0]
    """
    kappa_b, harmonic_b, clipped, data = _prepare(kappa, harmonics)
    result = _ramp_magnitude(data, np.ascontiguousarray(harmonic_b))
    negative = clipped < 0
    if np.any(negative):
        # c_k[kappa] = (-1)^k c_k[-kappa] + [k = 0](-kappa) + [k = 1]
        k_negative = harmonic_b[negative]
        reflected = np.where(np.mod(k_negative, 2.0) == 0.0, 1.0, -1.0) * result[negative]
        reflected += np.where(k_negative == 0, -clipped[negative], 0.0) + np.where(k_negative == 1, 1.0, 0.0)
        result[negative] = reflected
    result[kappa_b >= 1.0] = 0.0
    below = kappa_b <= -1.0
    if np.any(below):
        k_below = harmonic_b[below]
        result[below] = np.where(k_below == 0, -kappa_b[below], np.where(k_below == 1, 1.0, 0.0))
    return result.reshape(_output_shape(kappa, harmonics))


def contact_step_coefficients_float(kappa: ArrayLike, harmonics: ArrayLike) -> np.ndarray:
    """Vectorised ``h_k[kappa]`` (Heaviside step coefficients) in double precision.

    Parameters
    ----------
    kappa : array_like of float
        Contact thresholds (``|kappa| >= 1`` handled exactly, NaN rejected).
    harmonics : array_like of int
        Harmonic indices ``k >= 0``; broadcasts against ``kappa``.

    Returns
    -------
    numpy.ndarray
        ``h_k[kappa]`` with the broadcast shape (accuracy a few 1e-15 relative to
        the scale ``2/(pi k)``, ``k`` up to ``1e6``).

    Examples
    --------
    >>> import numpy as np
    >>> h = contact_step_coefficients_float(0.0, np.arange(4))
    >>> np.allclose(h, [0.5, 2 / np.pi, 0.0, -2 / (3 * np.pi)], rtol=0, atol=1e-15)
    True
    """
    kappa_b, harmonic_b, clipped, data = _prepare(kappa, harmonics)
    result = _step_magnitude(data, np.ascontiguousarray(harmonic_b))
    negative = clipped < 0
    if np.any(negative):
        # h_k[kappa] = [k = 0] - (-1)^k h_k[-kappa]
        k_negative = harmonic_b[negative]
        sign = np.where(np.mod(k_negative, 2.0) == 0.0, 1.0, -1.0)
        result[negative] = np.where(k_negative == 0, 1.0 - result[negative], -sign * result[negative])
    result[kappa_b >= 1.0] = 0.0
    below = kappa_b <= -1.0
    if np.any(below):
        result[below] = np.where(harmonic_b[below] == 0, 1.0, 0.0)
    return result.reshape(_output_shape(kappa, harmonics))


