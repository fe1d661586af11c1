r"""Closed-form Fourier coefficients of the contact functions of a unilateral spring.

For the oscillator ``u'' + omega0**2 u + eps * a * (u - b)_+ = 0`` expanded in
strained coordinates around ``v0 = a0 cos s`` (``a0 > 0``; for ``a0 < 0`` replace
``c_k`` by ``(-1)**k c_k``), the nonlinearity produces the even 2*pi-periodic
*contact functions* (with ``kappa = b / |a0|``)

.. math::

    (\cos s - \kappa)_+ = \sum_{k \ge 0} c_k[\kappa] \cos(k s), \qquad
    H(\cos s - \kappa)  = \sum_{k \ge 0} h_k[\kappa] \cos(k s),

where ``c_0``, ``h_0`` are mean values and, for ``k >= 1``,
``c_k = (2/pi) int_0^beta (cos s - kappa) cos(k s) ds`` with the *contact angle*
``beta = arccos(kappa)`` in ``[0, pi]``.  Derived closed forms (``sin beta = sqrt(1 - kappa**2)``):

.. math::

    c_0 = \frac{\sin\beta - \kappa\beta}{\pi}, \quad
    c_1 = \frac{\beta - \kappa\sin\beta}{\pi}, \quad
    c_k = \frac{2\,(\kappa \sin k\beta - k \sin\beta \cos k\beta)}{\pi k (k^2 - 1)}
          = \frac{2}{\pi k}\int_0^\beta \sin t \,\sin k t\, dt \quad (k \ge 2),

    h_0 = \frac{\beta}{\pi}, \qquad h_k = \frac{2 \sin k\beta}{\pi k} \quad (k \ge 1).

Outside ``(-1, 1)``: ``kappa >= 1`` gives identically zero functions; ``kappa <= -1``
gives ``(cos s - kappa)_+ = cos s - kappa`` and ``H = 1``.

The module offers an exact sympy path, a vectorised float path that stays accurate
near grazing contact (``kappa -> +-1``) and for harmonics up to ``k ~ 1e6``, an
mpmath path at any precision, and accelerated summation of the slowly converging
series built from these coefficients.

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
from fractions import Fraction
from typing import Callable, Iterator, Union

import mpmath
import numpy as np
import sympy

from ._errors import ConvergenceError, ProblemError
from ._parsing import parse_real

__all__ = [
    "contact_angle",
    "contact_angle_float",
    "contact_ramp_coefficient",
    "contact_step_coefficient",
    "ramp_times_cosine_coefficient",
    "step_times_cosine_coefficient",
    "contact_ramp_coefficients_float",
    "contact_step_coefficients_float",
    "contact_ramp_coefficient_mp",
    "contact_step_coefficient_mp",
    "SeriesEstimate",
    "series_sum",
    "sum_cosine_series_at",
]

KappaLike = Union[int, float, Fraction, sympy.Expr, str]
ArrayLike = Union[float, int, np.ndarray, list, tuple]

_MAX_EXACT_HARMONIC = 2**53


# ---------------------------------------------------------------------------
# input validation
# ---------------------------------------------------------------------------


def _as_harmonic(k: object, name: str = "k") -> int:
    """Return ``k`` as a non-negative Python int, or raise ProblemError."""
    if isinstance(k, bool):
        raise ProblemError(f"harmonic index {name}={k!r} is a bool; pass a non-negative integer such as 0, 1, 2")
    if isinstance(k, (int, np.integer)):
        value = int(k)
    elif isinstance(k, sympy.Basic) and k.is_Integer:
        value = int(k)
    else:
        raise ProblemError(
            f"harmonic index {name}={k!r} is not an integer; pass a non-negative int "
            "(use the quasi-trigonometric calculus for a symbolic harmonic)"
        )
    if value < 0:
        raise ProblemError(f"harmonic index {name}={value} is negative; cosine harmonics are indexed by k >= 0")
    return value


def _as_sympy_kappa(kappa: KappaLike) -> sympy.Expr:
    """Sympify ``kappa`` and check that it can be real."""
    if isinstance(kappa, Fraction):
        kappa = sympy.Rational(kappa.numerator, kappa.denominator)
    if isinstance(kappa, str):  # user text: read by the one parser
        return parse_real(kappa, what="kappa")
    try:
        value = sympy.sympify(kappa, strict=True)
    except (sympy.SympifyError, TypeError) as exc:
        raise ProblemError(f"kappa={kappa!r} is not a number or sympy expression; pass e.g. sympy.Rational(1, 3)") from exc
    if not isinstance(value, sympy.Expr):
        raise ProblemError(f"kappa={kappa!r} is not a scalar expression; pass a real number or real sympy expression")
    if value.is_real is False or value.has(sympy.zoo, sympy.nan):
        raise ProblemError(f"kappa={kappa!r} is not real; kappa = b/|a0| must be a real number")
    return value


def _interior_status(kappa: sympy.Expr) -> str:
    """Classify kappa as 'above' (>= 1), 'below' (<= -1), 'interior' or 'unknown'."""
    if (kappa >= 1) == sympy.true:
        return "above"
    if (kappa <= -1) == sympy.true:
        return "below"
    if (kappa < 1) == sympy.true and (kappa > -1) == sympy.true:
        return "interior"
    return "unknown"


# ---------------------------------------------------------------------------
# exact symbolic path
# ---------------------------------------------------------------------------


def contact_angle(kappa: KappaLike) -> sympy.Expr:
    """Exact contact angle ``beta = arccos(kappa)`` clamped to ``[0, pi]``.

    Parameters
    ----------
    kappa : number or sympy expression
        Contact threshold ``b / |a0|``.  ``kappa >= 1`` gives 0, ``kappa <= -1`` gives pi.

    Returns
    -------
    sympy.Expr
        ``acos(kappa)``; for a symbolic kappa of unknown range, ``acos(kappa)`` itself
        (the caller asserts ``|kappa| < 1``).

    Examples
    --------
    >>> import sympy
    >>> contact_angle(sympy.Rational(1, 2))
    pi/3
    >>> contact_angle(3)
    0
    """
    value = _as_sympy_kappa(kappa)
    status = _interior_status(value)
    if status == "above":
        return sympy.Integer(0)
    if status == "below":
        return sympy.pi
    return sympy.acos(value)


def _ramp_interior(k: int, kappa: sympy.Expr) -> sympy.Expr:
    contact_angle_value = sympy.acos(kappa)
    sine_of_angle = sympy.sqrt(1 - kappa**2)
    if k == 0:
        return (sine_of_angle - kappa * contact_angle_value) / sympy.pi
    if k == 1:
        return (contact_angle_value - kappa * sine_of_angle) / sympy.pi
    numerator = kappa * sympy.sin(k * contact_angle_value) - k * sine_of_angle * sympy.cos(k * contact_angle_value)
    return 2 * numerator / (sympy.pi * k * (k * k - 1))


def _ramp_below(k: int, kappa: sympy.Expr) -> sympy.Expr:
    if k == 0:
        return -kappa
    if k == 1:
        return sympy.Integer(1)
    return sympy.Integer(0)


def _step_interior(k: int, kappa: sympy.Expr) -> sympy.Expr:
    contact_angle_value = sympy.acos(kappa)
    if k == 0:
        return contact_angle_value / sympy.pi
    return 2 * sympy.sin(k * contact_angle_value) / (sympy.pi * k)


def _step_below(k: int, kappa: sympy.Expr) -> sympy.Expr:
    return sympy.Integer(1) if k == 0 else sympy.Integer(0)


def _dispatch(
    k: int,
    kappa: sympy.Expr,
    interior: Callable[[int, sympy.Expr], sympy.Expr],
    below: Callable[[int, sympy.Expr], sympy.Expr],
    assume_interior: bool,
) -> sympy.Expr:
    status = _interior_status(kappa)
    if status == "above":
        return sympy.Integer(0)
    if status == "below":
        return below(k, kappa)
    if status == "interior" or assume_interior:
        return interior(k, kappa)
    return sympy.Piecewise(
        (sympy.Integer(0), kappa >= 1),
        (below(k, kappa), kappa <= -1),
        (interior(k, kappa), True),
    )


def contact_ramp_coefficient(k: int, kappa: KappaLike, *, assume_interior: bool = False) -> sympy.Expr:
    """Exact cosine coefficient ``c_k[kappa]`` of ``(cos s - kappa)_+``.

    Parameters
    ----------
    k : int
        Harmonic index ``k >= 0`` (``c_0`` is the mean value).
    kappa : number or sympy expression
        Contact threshold.  Numbers with ``|kappa| >= 1`` route to the exact
        degenerate values; a symbolic kappa of unknown range yields a ``Piecewise``.
    assume_interior : bool, optional
        If True, return the ``|kappa| < 1`` formula without a ``Piecewise`` wrapper
        for symbolic kappa.

    Returns
    -------
    sympy.Expr
        Expression in ``acos(kappa)`` and ``sqrt(1 - kappa**2)``.

    Examples
    --------
    >>> import sympy
    >>> contact_ramp_coefficient(0, 0)
    1/pi
    >>> contact_ramp_coefficient(2, 0)
    2/(3*pi)
    >>> kappa = sympy.Symbol("kappa")
    >>> contact_ramp_coefficient(1, kappa, assume_interior=True)
    (-kappa*sqrt(1 - kappa**2) + acos(kappa))/pi
    """
    harmonic = _as_harmonic(k)
    return _dispatch(harmonic, _as_sympy_kappa(kappa), _ramp_interior, _ramp_below, assume_interior)


def contact_step_coefficient(k: int, kappa: KappaLike, *, assume_interior: bool = False) -> sympy.Expr:
    """Exact cosine coefficient ``h_k[kappa]`` of the Heaviside step ``H(cos s - kappa)``.

    Parameters
    ----------
    k : int
        Harmonic index ``k >= 0``.
    kappa : number or sympy expression
        Contact threshold (see :func:`contact_ramp_coefficient`).
    assume_interior : bool, optional
        Return the ``|kappa| < 1`` formula for a symbolic kappa.

    Returns
    -------
    sympy.Expr
        ``acos(kappa)/pi`` for ``k = 0`` and ``2 sin(k acos(kappa)) / (pi k)`` otherwise.

    Examples
    --------
    >>> contact_step_coefficient(0, 0)
    1/2
    >>> contact_step_coefficient(3, 0)
    -2/(3*pi)
    """
    harmonic = _as_harmonic(k)
    return _dispatch(harmonic, _as_sympy_kappa(kappa), _step_interior, _step_below, assume_interior)


def _product_coefficient(
    coefficient: Callable[[int], sympy.Expr], k: int, m: int
) -> sympy.Expr:
    """k-th cosine coefficient of g(s) cos(m s) from the coefficients of g."""
    if m == 0:
        return coefficient(k)
    if k == 0:
        return coefficient(m) / 2
    difference = abs(k - m)
    low = 2 * coefficient(0) if difference == 0 else coefficient(difference)
    return (coefficient(k + m) + low) / 2


def ramp_times_cosine_coefficient(
    k: int, kappa: KappaLike, m: int, *, assume_interior: bool = False
) -> sympy.Expr:
    """Exact k-th cosine coefficient of ``(cos s - kappa)_+ * cos(m s)``.

    By product-to-sum, for ``m >= 1``: ``e_0 = c_m / 2`` and, for ``k >= 1``,
    ``e_k = (c_{k+m} + c_{|k-m|}) / 2`` with ``c_0`` counted twice when ``k = m``.

    Parameters
    ----------
    k : int
        Harmonic index of the product, ``k >= 0``.
    kappa : number or sympy expression
        Contact threshold.
    m : int
        Frequency of the cosine factor, ``m >= 0``.
    assume_interior : bool, optional
        See :func:`contact_ramp_coefficient`.

    Returns
    -------
    sympy.Expr
        The coefficient (mean value for ``k = 0``).

    Examples
    --------
    >>> import sympy
    >>> sympy.simplify(ramp_times_cosine_coefficient(0, 0, 1))
    1/4
    """
    harmonic = _as_harmonic(k)
    frequency = _as_harmonic(m, "m")
    value = _as_sympy_kappa(kappa)
    return _product_coefficient(
        lambda n: contact_ramp_coefficient(n, value, assume_interior=assume_interior), harmonic, frequency
    )


def step_times_cosine_coefficient(
    k: int, kappa: KappaLike, m: int, *, assume_interior: bool = False
) -> sympy.Expr:
    """Exact k-th cosine coefficient of ``H(cos s - kappa) * cos(m s)``.

    Parameters
    ----------
    k : int
        Harmonic index of the product, ``k >= 0``.
    kappa : number or sympy expression
        Contact threshold.
    m : int
        Frequency of the cosine factor, ``m >= 0``.
    assume_interior : bool, optional
        See :func:`contact_step_coefficient`.

    Returns
    -------
    sympy.Expr
        The coefficient (mean value for ``k = 0``).

    Examples
    --------
    >>> step_times_cosine_coefficient(1, 0, 1)
    1/2
    """
    harmonic = _as_harmonic(k)
    frequency = _as_harmonic(m, "m")
    value = _as_sympy_kappa(kappa)
    return _product_coefficient(
        lambda n: contact_step_coefficient(n, value, assume_interior=assume_interior), harmonic, frequency
    )


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


# ---------------------------------------------------------------------------
# mpmath path
# ---------------------------------------------------------------------------


def _exact_kappa_parts(kappa: KappaLike) -> tuple[int, object, object]:
    """Return (sign, |kappa|, 1 - |kappa|) as mpmath numbers at the current precision.

    Rationals and floats give ``1 - |kappa|`` without cancellation error.
    """
    if isinstance(kappa, bool):
        raise ProblemError("kappa must be a real number, not a bool")
    if isinstance(kappa, sympy.Basic):
        value = _as_sympy_kappa(kappa)
        if value.free_symbols:
            raise ProblemError(f"kappa={kappa} is symbolic; the mpmath path needs a number (use contact_ramp_coefficient)")
        if value.is_Rational:
            kappa = Fraction(int(value.p), int(value.q))
        else:
            kappa = mpmath.mpf(sympy.N(value, mpmath.mp.dps + 20))
    if isinstance(kappa, Fraction) or isinstance(kappa, int):
        fraction = Fraction(kappa)
        sign = -1 if fraction < 0 else 1
        magnitude = abs(fraction)
        gap = 1 - magnitude
        return (
            sign,
            mpmath.mpf(magnitude.numerator) / magnitude.denominator,
            mpmath.mpf(gap.numerator) / gap.denominator,
        )
    try:
        value_mp = mpmath.mpf(kappa)
    except (TypeError, ValueError) as exc:
        raise ProblemError(f"kappa={kappa!r} is not a real number; pass an int, float, Fraction, str or mpf") from exc
    if mpmath.isnan(value_mp):
        raise ProblemError("kappa is NaN; pass a finite real threshold")
    sign = -1 if value_mp < 0 else 1
    magnitude = abs(value_mp)
    return sign, magnitude, mpmath.fsub(1, magnitude, exact=True)


def _coefficient_mp(k: int, kappa: KappaLike, dps: int, ramp: bool) -> mpmath.mpf:
    if not isinstance(dps, int) or isinstance(dps, bool) or dps < 1:
        raise ProblemError(f"dps={dps!r} must be a positive int number of decimal digits")
    harmonic = _as_harmonic(k)
    with mpmath.workdps(dps + 10):
        sign, magnitude, gap = _exact_kappa_parts(kappa)
        if gap <= 0:  # |kappa| >= 1
            if sign > 0:
                return mpmath.mpf(0)
            if ramp:
                return +(magnitude if harmonic == 0 else mpmath.mpf(1 if harmonic == 1 else 0))
            return mpmath.mpf(1 if harmonic == 0 else 0)
        angle_estimate = 2 * mpmath.asin(mpmath.sqrt(gap / 2))
        phase_estimate = angle_estimate * max(harmonic, 1)
        lost_digits = 0 if phase_estimate >= 1 else int(-2 * mpmath.log10(phase_estimate)) + 1
    with mpmath.workdps(dps + 15 + lost_digits):
        sign, magnitude, gap = _exact_kappa_parts(kappa)
        angle = 2 * mpmath.asin(mpmath.sqrt(gap / 2))
        sine_of_angle = mpmath.sqrt(gap * (1 + magnitude))
        pi = mpmath.pi
        if ramp:
            if harmonic == 0:
                value = (sine_of_angle - magnitude * angle) / pi
            elif harmonic == 1:
                value = (angle - magnitude * sine_of_angle) / pi
            else:
                value = (
                    2
                    * (magnitude * mpmath.sin(harmonic * angle) - harmonic * sine_of_angle * mpmath.cos(harmonic * angle))
                    / (pi * harmonic * (harmonic * harmonic - 1))
                )
            if sign < 0:
                value = (-1) ** harmonic * value + (magnitude if harmonic == 0 else 0) + (1 if harmonic == 1 else 0)
        else:
            value = angle / pi if harmonic == 0 else 2 * mpmath.sin(harmonic * angle) / (pi * harmonic)
            if sign < 0:
                value = 1 - value if harmonic == 0 else -((-1) ** harmonic) * value
    with mpmath.workdps(dps):
        return +value


def contact_ramp_coefficient_mp(k: int, kappa: KappaLike, dps: int = 50) -> mpmath.mpf:
    """``c_k[kappa]`` with mpmath, correct to about ``dps`` significant digits.

    Guard digits are added automatically to absorb the cancellation of the closed
    form when ``k * beta`` is small; ``1 - |kappa|`` is formed exactly for int,
    Fraction, sympy Rational and float inputs.

    Parameters
    ----------
    k : int
        Harmonic index ``k >= 0``.
    kappa : int, float, str, Fraction, mpf or sympy number
        Contact threshold (floats are taken at their exact binary value).
    dps : int, optional
        Decimal digits of the result (default 50).

    Returns
    -------
    mpmath.mpf
        The coefficient rounded to ``dps`` digits.

    Examples
    --------
    >>> import mpmath
    >>> with mpmath.workdps(30):
    ...     value = contact_ramp_coefficient_mp(2, 0, dps=30)
    ...     print(mpmath.almosteq(value, 2 / (3 * mpmath.pi), rel_eps=mpmath.mpf(10) ** -29))
    True
    """
    return _coefficient_mp(k, kappa, dps, ramp=True)


def contact_step_coefficient_mp(k: int, kappa: KappaLike, dps: int = 50) -> mpmath.mpf:
    """``h_k[kappa]`` with mpmath at ``dps`` digits (see :func:`contact_ramp_coefficient_mp`).

    Parameters
    ----------
    k : int
        Harmonic index ``k >= 0``.
    kappa : int, float, str, Fraction, mpf or sympy number
        Contact threshold.
    dps : int, optional
        Decimal digits of the result (default 50).

    Returns
    -------
    mpmath.mpf
        The coefficient.

    Examples
    --------
    >>> contact_step_coefficient_mp(0, 0, dps=20)
    mpf('0.5')
    """
    return _coefficient_mp(k, kappa, dps, ramp=False)


# ---------------------------------------------------------------------------
# accelerated summation of slowly converging series (mpmath.nsum)
# ---------------------------------------------------------------------------
#
# The extrapolation itself is mpmath.nsum (Richardson + Shanks).  What remains here is
# what nsum (mpmath 1.3) does not do, each part measured on the package's own sums
# (those of tests/test_contact_fourier.py, the a_k of
# _nnm_expansion.release_amplitudes_by_series, the omega2 series of
# benchmarks/bench_unilateral.py; errors against closed forms):
#
# * vanishing terms are skipped (_Blocks).  nsum stops as soon as the last term of a
#   batch (indices 9, 29, 59, ...) is below its tolerance, so a series whose odd terms
#   vanish comes back as a 10-term partial sum with no warning: error 7.4e-3 for the
#   |cos s| series, 4.3e-4 for the ramp series at kappa = 0, 6.2e-6 for the a_k of a
#   spring with zero gap, 2.5e-7 for the benchmark series at kappa = 0.
# * an error estimate.  nsum returns none (``error=True`` is silently ignored) and its
#   stopping rule can be met far from the limit (benchmark series, kappa = 3/10, 20
#   digits: successive Shanks values agree to 8e-24, the value is off by 1.5e-21).
#   When the rule is met, a second nsum at 10 more digits must agree (it has to meet a
#   10**10 finer tolerance).  When max_terms is reached (the a_k and benchmark series),
#   the values scatter erratically with the number of terms (a_k, two springs, error
#   after 360/450/550/660 terms: 2e-28, -7e-27, -2e-27, 5e-28): the estimate is twice
#   the largest distance to the values from 1/2 and 3/4 of the terms (one distance
#   alone gave 2.4e-28 for an actual 4.6e-28; without the factor 2, 5.8e-28 for 6.7e-28
#   on the a_k of a spring with zero gap).
# * Levin is not in the default methods: "r+s+l" took 3.5x as long on the a_k series
#   (7.4 s vs 2.1 s), 1.4x-3.5x on the others, and was never more accurate.
#
# Against the former hand-written Richardson/Shanks/Levin driver (same sums, same
# tolerances, 22 sums): as accurate or more on all; 1.3x-35x faster on the sums of the
# tests (e.g. 0.40 s vs 0.81 s for the ramp series at kappa = 0.9, s = 0; slower only on
# a 3-term finite series, 4.6 ms vs 2.8 ms), 0.6x-2.2x on the a_k and benchmark series
# (slower on the benchmark series at kappa = -7/10, 20 digits, 3.5 s vs 2.0 s: nsum's
# stopping rule is met there 3.5e-21 away from the limit and the check costs a run).
# That driver's estimate was below the actual error on 4 of the 22 (e.g. 6.7e-28
# claimed, 2.0e-27 actual), this one's on none.


@dataclass(frozen=True)
class SeriesEstimate:
    """Value of an infinite series with an error estimate.

    Unpacks as ``value, error_estimate = estimate``.

    Attributes
    ----------
    value : mpmath.mpf
        Accelerated estimate of the sum (``mpmath.nsum``).
    error_estimate : mpmath.mpf
        Estimated absolute error: the disagreement of ``nsum`` at ``dps`` and at
        ``dps + 10`` digits when its stopping rule is met, otherwise twice the largest
        distance of its value to those from 1/2 and 3/4 of ``max_terms``; never below
        ``10**-dps * max(|value|, 1)``.
    terms_used : int
        Number of terms evaluated in the run that delivered the value.
    method : str
        The ``nsum`` method and whether its stopping rule was met
        (``"converged"``) or ``max_terms`` was reached (``"max_terms reached"``).
    """

    value: mpmath.mpf
    error_estimate: mpmath.mpf
    terms_used: int
    method: str

    def __iter__(self) -> Iterator[mpmath.mpf]:
        yield self.value
        yield self.error_estimate


_METHODS = ("richardson", "shanks", "levin")
_DEFAULT_METHODS = ("richardson", "shanks")
_TERMINATION_RUN = 64  # consecutive negligible blocks taken as the end of a finite series
_EXTRA_DIGITS = 10  # precision of the confirming nsum run
_CHECKPOINTS = (2, 4 / 3)  # best-effort runs are compared with runs on max_terms / 2 and 3 max_terms / 4
_SCATTER_FACTOR = 2  # the best-effort value may lie on the far side of the limit from the others


def _to_mpf(value: object) -> mpmath.mpf:
    if isinstance(value, sympy.Basic):
        return mpmath.mpf(sympy.N(value, mpmath.mp.dps + 5))
    if isinstance(value, Fraction):
        return mpmath.mpf(value.numerator) / value.denominator
    if isinstance(value, (mpmath.mpf, mpmath.mpc)):
        return value
    return mpmath.mpf(value)


class _Blocks:
    """The series as nsum sees it: block sums, negligible blocks skipped, cached.

    ``self(j)`` is the j-th block sum of magnitude above ``negligible`` times the
    largest so far; after ``_TERMINATION_RUN`` negligible blocks in a row the series
    is taken as finite and every further term is 0 (nonzero terms reappearing later
    would be missed).  ``requested`` counts the terms nsum asked for.
    """

    def __init__(self, term: Callable[[int], object], start: int, block: int, negligible: mpmath.mpf) -> None:
        self.term, self.start, self.index, self.block, self.negligible = term, start, start, block, negligible
        self.sums: list = []
        self.largest = mpmath.mpf(0)
        self.run = 0
        self.requested = 0

    def __call__(self, j: object) -> mpmath.mpf:
        j = int(j)
        self.requested = max(self.requested, j + 1)
        while len(self.sums) <= j and self.run < _TERMINATION_RUN:
            total = mpmath.fsum(_to_mpf(self.term(self.index + offset)) for offset in range(self.block))
            self.index += self.block
            self.largest = max(self.largest, abs(total))
            if self.sums and abs(total) <= self.negligible * self.largest:
                self.run += 1
                continue
            self.run = 0
            self.sums.append(total)
        return self.sums[j] if j < len(self.sums) else mpmath.mpf(0)

    def budget(self, max_blocks: int) -> int:
        """How many nonvanishing blocks ``max_blocks`` evaluated blocks give (from the first 40).

        The probe is discarded: nsum evaluates the terms at its own, higher precision.
        """
        while (self.index - self.start) // self.block < min(max_blocks, 40) and self.run < _TERMINATION_RUN:
            self(len(self.sums))
        evaluated = max((self.index - self.start) // self.block, 1)
        nonvanishing = len(self.sums)
        self.sums, self.index, self.largest, self.run = [], self.start, mpmath.mpf(0), 0
        return max(20, max_blocks * nonvanishing // evaluated)

    def nsum(self, maxterms: int, method: str) -> tuple[mpmath.mpf, bool]:
        """nsum's value from at most about ``maxterms`` blocks, and whether its stopping rule was met."""
        self.requested = 0
        value = mpmath.nsum(self, [0, mpmath.inf], method=method, maxterms=maxterms)
        return value, self.requested < maxterms


def _series_core(
    term: Callable[[int], object],
    start: int,
    dps: int,
    tolerance: object | None,
    max_terms: int,
    block_size: int,
    methods: tuple[str, ...],
) -> SeriesEstimate:
    if not isinstance(dps, int) or isinstance(dps, bool) or dps < 5:
        raise ProblemError(f"dps={dps!r} must be an int >= 5")
    start_index = _as_harmonic(start, "start")
    block = _as_harmonic(block_size, "block_size")
    if block < 1:
        raise ProblemError("block_size must be >= 1")
    if not isinstance(max_terms, int) or isinstance(max_terms, bool) or max_terms < 20 * block:
        raise ProblemError(f"max_terms={max_terms!r} must be an int >= 20 * block_size")
    unknown = set(methods) - set(_METHODS)
    if not methods or unknown:
        raise ProblemError(f"methods must be a non-empty subset of {_METHODS}; got {methods!r}")
    method = "+".join(methods)
    maxterms = max_terms // block

    def run(digits: int) -> tuple[mpmath.mpf, bool, mpmath.mpf, _Blocks]:
        # nsum at `digits`; when its stopping rule is not met, twice the spread of its
        # values from fewer terms (same cached blocks) is the error estimate
        with mpmath.workdps(digits):
            blocks = _Blocks(term, start_index, block, mpmath.mpf(10) ** -(dps + 3))
            budget = blocks.budget(maxterms)
            value, converged = blocks.nsum(budget, method)
            spread = mpmath.mpf(0)
            if not converged:
                for fraction in _CHECKPOINTS:
                    shorter, _ = blocks.nsum(int(budget / fraction), method)
                    spread = max(spread, _SCATTER_FACTOR * abs(value - shorter))
            return value, converged, spread, blocks

    value, converged, error, blocks = run(dps)
    if converged:  # confirm with 10 more digits: nsum then has to agree to a 10**10 finer tolerance
        first = value
        value, converged, spread, blocks = run(dps + _EXTRA_DIGITS)
        with mpmath.workdps(dps + _EXTRA_DIGITS):
            error = max(abs(value - first), spread)
    with mpmath.workdps(dps):
        target = mpmath.mpf(10) ** (-(dps // 2)) if tolerance is None else mpmath.mpf(tolerance)
        error = max(error, mpmath.mpf(10) ** (-dps) * max(abs(value), 1))
        if not mpmath.isfinite(error) or error > target:
            raise ConvergenceError(
                f"series did not converge to tolerance {mpmath.nstr(target, 3)}: best estimate "
                f"{mpmath.nstr(value, 15)} with estimated error {mpmath.nstr(error, 3)} after "
                f"{blocks.index - start_index} terms; raise max_terms, loosen tolerance, pass block_size equal to the "
                "period of any exact periodic pattern in the terms, or subtract the slowly converging part analytically"
            )
        status = "converged" if converged else "max_terms reached"
        return SeriesEstimate(+value, +error, blocks.index - start_index, f"nsum {method}, {status}")


def series_sum(
    term_function: Callable[[int], object],
    start: int = 0,
    dps: int = 30,
    *,
    tolerance: object | None = None,
    max_terms: int = 600,
    block_size: int = 1,
    methods: tuple[str, ...] = _DEFAULT_METHODS,
) -> SeriesEstimate:
    """Sum ``sum_{k >= start} term_function(k)`` with convergence acceleration (``mpmath.nsum``).

    ``mpmath.nsum`` (Richardson and Shanks by default) sums the series; terms that
    vanish (e.g. every odd coefficient of an even function of ``cos(s)``) are skipped.
    The error estimate: when nsum's stopping rule is met, the disagreement with a
    second nsum at ``dps + 10`` digits; when ``max_terms`` is reached first, twice the
    largest distance of nsum's value to those from 1/2 and 3/4 of ``max_terms``; never
    below ``10**-dps * max(|value|, 1)``.

    Parameters
    ----------
    term_function : callable
        ``term_function(k)`` for int ``k``; returns an mpmath/int/float/Fraction/sympy number.
        It is evaluated under the working precision set here (``mp.workdps``).
    start : int, optional
        First index (default 0).
    dps : int, optional
        Decimal digits of the computation (default 30).
    tolerance : number, optional
        Absolute tolerance on the error estimate; default ``10**-(dps//2)``.
    max_terms : int, optional
        Terms evaluated per nsum run (default 600; nsum completes its last batch of
        terms, up to 10% more).
    block_size : int, optional
        Sum the terms in blocks of this size before extrapolating; set it to the period
        of an exact periodic sign/zero pattern (e.g. 3 for ``cos(2 pi k / 3)`` factors).
    methods : tuple of str, optional
        Subset of ``("richardson", "shanks", "levin")`` passed to nsum
        (default ``("richardson", "shanks")``).

    Returns
    -------
    SeriesEstimate
        ``(value, error_estimate)`` plus diagnostics.

    Raises
    ------
    ConvergenceError
        If the estimated error exceeds ``tolerance``.

    Examples
    --------
    >>> import mpmath
    >>> value, error = series_sum(lambda k: mpmath.mpf(1) / k**2, start=1, dps=20)
    >>> with mpmath.workdps(20):
    ...     print(abs(value - mpmath.pi**2 / 6) < 1e-18, error < 1e-9)
    True True
    """
    return _series_core(term_function, start, dps, tolerance, max_terms, block_size, tuple(methods))


def sum_cosine_series_at(
    coefficients_function: Callable[[int], object],
    s: object,
    start: int = 0,
    dps: int = 30,
    *,
    tolerance: object | None = None,
    max_terms: int = 600,
    block_size: int = 1,
    methods: tuple[str, ...] = _DEFAULT_METHODS,
) -> SeriesEstimate:
    """Evaluate the cosine series ``sum_{k >= start} d_k cos(k s)`` with acceleration.

    Intended for coefficients ``d_k ~ k^{-p}`` (``p > 1``), possibly oscillating like the
    contact coefficients ``c_k[kappa]``.  Convergence is slow, and acceleration weak,
    at points ``s`` where the sum has a kink (e.g. ``s = beta`` for ``(cos s - kappa)_+``);
    there the error estimate grows or ConvergenceError is raised.

    Parameters
    ----------
    coefficients_function : callable
        ``d(k)`` for int ``k``.
    s : number
        Evaluation point (mpmath, float, str, Fraction or sympy number).
    start : int, optional
        First harmonic (default 0).
    dps : int, optional
        Decimal digits (default 30).
    tolerance, max_terms, block_size, methods
        As in :func:`series_sum`.

    Returns
    -------
    SeriesEstimate
        ``(value, error_estimate)`` plus diagnostics.

    Raises
    ------
    ConvergenceError
        If the estimated error exceeds ``tolerance``.

    Examples
    --------
    >>> import mpmath
    >>> estimate = sum_cosine_series_at(lambda k: contact_ramp_coefficient_mp(k, 0, 40), 0.5, dps=20)
    >>> bool(abs(estimate.value - mpmath.cos(0.5)) < 1e-15)
    True
    """
    def term(k: int) -> object:
        angle = _to_mpf(s)
        return _to_mpf(coefficients_function(k)) * mpmath.cos(k * angle)

    return _series_core(term, start, dps, tolerance, max_terms, block_size, tuple(methods))
