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

This module has the exact sympy path and an mpmath path at any precision;
:mod:`lindstedt.algebra.fourier_float` the vectorised float path that stays accurate
near grazing contact (``kappa -> +-1``) and for harmonics up to ``k ~ 1e6``;
:mod:`lindstedt.algebra.series` the accelerated summation of the slowly converging
series built from these coefficients.
"""

from __future__ import annotations

from fractions import Fraction
from typing import Callable, Union

import mpmath
import numpy as np
import sympy

from .._errors import ProblemError
from ..problems.parsing import parse_real
from .._precision import locked, workdps

__all__ = [
    "KappaLike",
    "contact_angle",
    "contact_ramp_coefficient",
    "contact_step_coefficient",
    "ramp_times_cosine_coefficient",
    "step_times_cosine_coefficient",
    "contact_ramp_coefficient_mp",
    "contact_step_coefficient_mp",
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


@locked
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


@locked
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


@locked
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


@locked
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


@locked
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


def _coefficient_mp(k: int, kappa: KappaLike, precision: int, ramp: bool) -> mpmath.mpf:
    if not isinstance(precision, int) or isinstance(precision, bool) or precision < 1:
        raise ProblemError(f"precision={precision!r} must be a positive int number of decimal digits")
    harmonic = _as_harmonic(k)
    with workdps(precision + 10):
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
    with workdps(precision + 15 + lost_digits):
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
    with workdps(precision):
        return +value


@locked
def contact_ramp_coefficient_mp(k: int, kappa: KappaLike, precision: int = 50) -> mpmath.mpf:
    """``c_k[kappa]`` with mpmath, correct to about ``precision`` significant digits.

    Guard digits are added automatically to absorb the cancellation of the closed
    form when ``k * beta`` is small; ``1 - |kappa|`` is formed exactly for int,
    Fraction, sympy Rational and float inputs.

    Parameters
    ----------
    k : int
        Harmonic index ``k >= 0``.
    kappa : int, float, str, Fraction, mpf or sympy number
        Contact threshold (floats are taken at their exact binary value).
    precision : int, optional
        Decimal digits of the result (default 50).

    Returns
    -------
    mpmath.mpf
        The coefficient rounded to ``precision`` digits.

    Examples
    --------
    >>> import mpmath
    >>> with mpmath.workdps(30):
    ...     value = contact_ramp_coefficient_mp(2, 0, precision=30)
    ...     print(mpmath.almosteq(value, 2 / (3 * mpmath.pi), rel_eps=mpmath.mpf(10) ** -29))
    True
    """
    return _coefficient_mp(k, kappa, precision, ramp=True)


@locked
def contact_step_coefficient_mp(k: int, kappa: KappaLike, precision: int = 50) -> mpmath.mpf:
    """``h_k[kappa]`` with mpmath at ``precision`` digits (see :func:`contact_ramp_coefficient_mp`).

    Parameters
    ----------
    k : int
        Harmonic index ``k >= 0``.
    kappa : int, float, str, Fraction, mpf or sympy number
        Contact threshold.
    precision : int, optional
        Decimal digits of the result (default 50).

    Returns
    -------
    mpmath.mpf
        The coefficient.

    Examples
    --------
    >>> contact_step_coefficient_mp(0, 0, precision=20)
    mpf('0.5')
    """
    return _coefficient_mp(k, kappa, precision, ramp=False)


