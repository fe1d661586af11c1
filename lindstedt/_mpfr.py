"""Exact conversions between mpmath's binary floats and gmpy2's (MPFR): both are ``(−1)^s · m · 2^e``, so a
conversion moves the mantissa m and the exponent e and rounds nothing where the target's precision holds m (an MPFR
number takes gmpy2's current precision, an mpmath number mpmath's).

Examples
--------
>>> import gmpy2, mpmath
>>> x = mpmath.mpf(-3) / 8
>>> with gmpy2.context(precision=53):
...     y = mpfr_of_mpf(x)
>>> y, mpf_of_mpfr(y) == x, raw_of_mpfr(y) == x._mpf_
(mpfr('-0.375'), True, True)
"""

from __future__ import annotations

from typing import Any

import gmpy2
import mpmath
from mpmath.libmp import from_man_exp

__all__ = ["mpf_of_mpfr", "mpfr_of_mpf", "raw_of_mpfr"]


def mpfr_of_mpf(value: Any) -> Any:
    """An mpmath number (or an element of a sympy ``RealField``, or an int) as a gmpy2 mpfr, exactly."""
    if isinstance(value, int):
        return gmpy2.mpfr(value)
    sign, mantissa, exponent, _ = value._mpf_
    result = gmpy2.mul_2exp(gmpy2.mpfr(mantissa), exponent)
    return -result if sign else result


def raw_of_mpfr(value: Any) -> tuple:
    """A gmpy2 mpfr as mpmath's raw value (``_mpf_`` tuple), exactly."""
    mantissa, exponent = value.as_mantissa_exp()
    return from_man_exp(int(mantissa), int(exponent))


def mpf_of_mpfr(value: Any) -> Any:
    """A gmpy2 mpfr as an mpmath mpf (exact at mpmath's current precision ≥ the mpfr's)."""
    mantissa, exponent = value.as_mantissa_exp()
    return mpmath.mpf((int(mantissa), int(exponent)))
