"""How the references read their arguments: numbers at the working precision, precision and order checks.

Every exact reference (:mod:`.duffing`, :mod:`.piecewise`, :mod:`.quadrature`, :mod:`.chebyshev`) reads a
number ``x`` (int, float, Fraction, sympy number, numeric string, mpmath number) as the mpmath number
``round(x)`` at the mpmath precision in effect — exact inputs are rounded once — and returns ``(value, error)``
pairs rounded to the requested digits with the error grown by that rounding (``error + |value| 10**-precision``).
"""

from __future__ import annotations

from collections.abc import Callable
from fractions import Fraction
from numbers import Number
from typing import Any, Union

import mpmath
import sympy

from .._errors import OrderError, ParameterError, ProblemError
from .._precision import locked, workdps
from ..problems.parsing import parse_real

__all__ = ["as_mpmath_number"]

#: The nonlinearity f of the references: a sympy expression in the symbol u, or a callable on mpmath numbers.
Nonlinearity = Union[sympy.Expr, Callable[[Any], Any]]


@locked
def as_mpmath_number(value: Any, name: str = "value") -> mpmath.mpf | mpmath.mpc:
    """Convert an exact or floating number to an mpmath number at the current precision.

    Accepts ``int``, ``float``, ``complex``, :class:`fractions.Fraction`,
    sympy numbers (``Rational``, ``Float``, ``pi``, ``sqrt(2)``, complex
    constants), numeric strings (``"0.7"``, ``"1/3"``, read by the one parser) and mpmath numbers.  Exact inputs
    are rounded once, at the precision in effect.

    Examples
    --------
    >>> import mpmath, sympy
    >>> with mpmath.workdps(20):
    ...     print(as_mpmath_number(sympy.Rational(1, 3)))
    0.33333333333333333333
    """
    if isinstance(value, bool):
        raise ProblemError(f"{name} must be a number, got the bool {value!r}")
    if isinstance(value, (mpmath.mpf, mpmath.mpc)):
        return value
    if isinstance(value, str):  # user text: read by the one parser, exactly
        value = parse_real(value, what=name)
    if isinstance(value, Fraction):
        return mpmath.mpf(value.numerator) / value.denominator
    if isinstance(value, sympy.Basic):
        if value.free_symbols:
            raise ParameterError(
                f"{name} = {value} contains the symbols {sorted(map(str, value.free_symbols))}; "
                "substitute numeric values first"
            )
        if isinstance(value, sympy.Rational):
            return mpmath.mpf(int(value.p)) / int(value.q)
        evaluated = sympy.N(value, mpmath.mp.dps + 10)
        real_part, imaginary_part = evaluated.as_real_imag()
        real_value = mpmath.mpf(str(sympy.Float(real_part, mpmath.mp.dps + 10)))
        if imaginary_part == 0:
            return real_value
        return mpmath.mpc(real_value, mpmath.mpf(str(sympy.Float(imaginary_part, mpmath.mp.dps + 10))))
    if isinstance(value, Number):
        try:
            return mpmath.mpmathify(value)
        except (TypeError, ValueError) as error:
            raise ProblemError(f"{name} = {value!r} is not a number: {error}") from None
    raise ProblemError(f"{name} must be a number, got {type(value).__name__} {value!r}")


def real_parameter(value: Any, name: str) -> mpmath.mpf:
    """Convert a real, finite number (see :func:`as_mpmath_number`), naming ``name`` on error.

    Examples
    --------
    >>> real_parameter("0.5", "a0")
    mpf('0.5')
    """
    number = as_mpmath_number(value, name)
    if isinstance(number, mpmath.mpc):
        if number.imag != 0:
            raise ProblemError(f"{name} = {value} must be real")
        number = number.real
    if not mpmath.isfinite(number):
        raise ProblemError(f"{name} = {value} must be finite")
    return number


def validate_precision(precision: Any) -> int:
    """Check a requested number of decimal digits (an int >= 5).

    Examples
    --------
    >>> validate_precision(30)
    30
    """
    if isinstance(precision, bool) or not isinstance(precision, int) or not 5 <= precision <= 5000:
        raise ProblemError(f"precision (decimal digits of precision) must be an int between 5 and 5000, got {precision!r}")
    return precision


def omega0_parameter(omega0: Any) -> mpmath.mpf:
    """The linear angular frequency omega0: a real number (see :func:`real_parameter`) that must be positive."""
    value = real_parameter(omega0, "omega0")
    if value <= 0:
        raise ProblemError(f"omega0 = {omega0} must be positive")
    return value


def validate_order(order: Any, maximum: int) -> int:
    """Check a requested Taylor order (an int from 0 to ``maximum``)."""
    if isinstance(order, bool) or not isinstance(order, int) or order < 0:
        raise OrderError(f"order must be a non-negative int, got {order!r}")
    if order > maximum:
        raise OrderError(f"order {order} exceeds the supported maximum {maximum}")
    return order


def rounded_coefficients(results: list[tuple[mpmath.mpf, mpmath.mpf]], precision: int) -> list[tuple[mpmath.mpf, mpmath.mpf]]:
    """``(value, error)`` pairs rounded to ``precision`` digits, each error grown by that rounding.

    Call it at the working precision: rounding the result to precision digits adds up
    to one unit in the last digit.
    """
    results = [(value, error + abs(value) * mpmath.mpf(10) ** (-precision)) for value, error in results]
    with workdps(precision):
        return [(+value, +error) for value, error in results]


def _checked_expression(expression: sympy.Basic) -> tuple[sympy.Expr, sympy.Symbol]:
    """f with its variable u; any other symbol is refused (the references evaluate numbers only)."""
    free = expression.free_symbols
    variables = [symbol for symbol in free if symbol.name == "u"]
    others = sorted(symbol.name for symbol in free if symbol.name != "u")
    if others:
        raise ParameterError(
            f"f(u) = {expression} contains the symbols {others} besides u; "
            "substitute numeric values for them (expr.subs(...)) before calling"
        )
    return expression, variables[0] if variables else sympy.Symbol("u")
