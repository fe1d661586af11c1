"""Exact period of a conservative oscillator by quadrature of the energy integral.

Equation implemented::

    u'' + omega0**2 u + epsilon f(u) = 0,    u(0) = a0,   u'(0) = v0  (v0 = 0 by default).

The motion conserves the energy ``E = u'**2/2 + V(u)`` with the potential
``V(u) = omega0**2 u**2 / 2 + epsilon F(u)``, ``F' = f`` (the additive constant of
``F`` is immaterial).  The orbit through ``(a0, v0)`` has ``E = v0**2/2 + V(a0)``
and runs between the turning points ``b_- <= a0 <= b_+``, the first points on
either side of ``a0`` with ``V(b) = E`` (they depend on epsilon); for ``v0 = 0``
the release point ``a0`` is itself a turning point.  The period is

    T = 2 integral_{b_-}^{b_+} du / sqrt(2 (E - V(u))).

No Lindstedt-Poincare machinery is involved.  Two quadratures are used, chosen by f:

*Analytic f* (a sympy expression without switching functions, or a callable given without
breakpoints): the periodic trapezoidal rule after ``u = mid + half sin(theta)``, geometrically
convergent (:mod:`.trapezoid`).

*Piecewise-analytic f* (``Max``, ``Min``, ``Abs``, ``Heaviside``, ``sign``, ``Piecewise``, and real
powers of such pieces, e.g. the Hertz contact ``Max(0, u)**(3/2)``), on whose orbit the trapezoidal rule
would only converge algebraically: the line is cut at the breakpoints of f (:mod:`.breakpoints`) and
the orbit is integrated piece by piece by tanh-sinh quadrature (:mod:`.tanh_sinh`).

The Taylor coefficients of ``omega(epsilon) = 2 pi / T`` are in :mod:`.chebyshev`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import mpmath
import sympy

from .._precision import locked, workdps
from .arguments import Nonlinearity, _checked_expression, omega0_parameter, real_parameter, validate_precision
from .breakpoints import (
    _PiecewisePotential,
    _exact_breakpoints,
    _needs_pieces,
    _piecewise_from_callable,
    _piecewise_from_expression,
)
from .tanh_sinh import _period_by_pieces
from .trapezoid import _period_by_trapezoid, _period_by_trapezoid_with_velocity, _Potential

__all__ = ["conservative_period", "conservative_frequency", "nonlinearity_breakpoints"]


def _make_potential(nonlinearity: Nonlinearity, breakpoints: Any = None) -> _Potential | _PiecewisePotential:
    """The potential of f: analytic (trapezoid path) or piecewise analytic (tanh-sinh per piece)."""
    extra = _exact_breakpoints(breakpoints) if breakpoints is not None else None
    if isinstance(nonlinearity, sympy.Basic):
        expression, variable = _checked_expression(nonlinearity)
        if extra is None and not _needs_pieces(expression, variable):
            return _Potential(nonlinearity)
        return _piecewise_from_expression(expression, variable, extra or ())
    if callable(nonlinearity) and extra is not None:
        return _piecewise_from_callable(nonlinearity, extra)
    return _Potential(nonlinearity)


def _period(
    potential: _Potential | _PiecewisePotential,
    epsilon: Any,
    a0: Any,
    omega0: Any,
    precision: int,
    velocity: Any = 0,
) -> tuple[mpmath.mpf, mpmath.mpf]:
    """Period and error at ``precision`` digits (computed with guard digits)."""
    with workdps(precision + 20):
        epsilon_value = real_parameter(epsilon, "epsilon")
        a0_value = real_parameter(a0, "a0")
        omega0_value = omega0_parameter(omega0)
        velocity_value = real_parameter(velocity, "velocity")
        if isinstance(potential, _PiecewisePotential):
            period, difference = _period_by_pieces(
                potential, epsilon_value, a0_value, velocity_value, omega0_value, precision + 5
            )
        elif velocity_value == 0:
            period, difference = _period_by_trapezoid(potential, epsilon_value, a0_value, omega0_value, precision + 5)
        else:
            period, difference = _period_by_trapezoid_with_velocity(
                potential, epsilon_value, a0_value, velocity_value, omega0_value, precision + 5
            )
        error = difference + abs(period) * mpmath.mpf(10) ** (-precision)
    with workdps(precision):
        return +period, +error


@locked
def conservative_period(
    f: Nonlinearity,
    epsilon: Any,
    *,
    a0: Any,
    omega0: Any = 1,
    precision: int = 30,
    velocity: Any = 0,
    breakpoints: Sequence[Any] | None = None,
) -> tuple[mpmath.mpf, mpmath.mpf]:
    """Exact period of ``u'' + omega0**2 u + epsilon f(u) = 0``, ``u(0) = a0``, ``u'(0) = velocity``.

    Parameters
    ----------
    f : sympy expression in the symbol ``u`` or callable
        The nonlinearity, with numeric coefficients only; a callable receives
        and returns mpmath numbers.  An expression may be piecewise analytic:
        ``Max``, ``Min``, ``Abs``, ``Heaviside``, ``sign``, ``Piecewise`` with
        arguments linear in u, and real powers of such pieces (``Max(0, u)**(3/2)``);
        its breakpoints are found from the expression (see
        :func:`nonlinearity_breakpoints`) and the orbit is integrated piece by piece.
    epsilon : real number
        The small parameter (int, float, Fraction, sympy number, string, mpf).
    a0 : real number
        Initial position.
    omega0 : positive real number, optional
        Linear angular frequency.
    precision : int, optional
        Decimal digits of the result.
    velocity : real number, optional
        Initial velocity ``u'(0)`` (default 0: release at rest from the turning
        point ``a0``; the result for 0 is unchanged by this option).
    breakpoints : sequence of real numbers, optional
        Points where f is not analytic, added to those found in an expression.
        A callable f is taken as analytic on the orbit unless breakpoints are
        given; then it is integrated piece by piece like an expression, its
        antiderivative by quadrature (slower: nested quadratures).

    Returns
    -------
    (period, error_estimate) : tuple of mpf
        The error estimate is the quadrature's (last trapezoid refinement
        difference for analytic f, tanh-sinh estimates summed over the pieces
        otherwise) plus a rounding allowance of one unit in the
        ``precision``-th digit.

    Raises
    ------
    ConvergenceError
        If the orbit escapes (does not close) or sits on a separatrix.
    UnsupportedNonlinearityError
        If f switches at infinitely many (or not exactly located) points, or the
        orbit reaches a non-integrable singularity of f or a region where f is
        not real.
    ProblemError
        If the orbit is an equilibrium or the inputs are invalid.

    Examples
    --------
    >>> import sympy
    >>> u = sympy.Symbol("u")
    >>> period, error = conservative_period(u**3, 0, a0=1, precision=20)
    >>> mpmath.nstr(period, 20)  # 2 pi
    '6.2831853071795864769'
    >>> error < 1e-18
    True
    >>> period, error = conservative_period(sympy.Max(0, u), 3, a0=1, precision=20)
    >>> mpmath.nstr(period, 15)  # half a period at omega0 = 1 and half at sqrt(1 + 3): pi + pi/2
    '4.71238898038469'
    >>> period, error = conservative_period(u, 3, a0=0, velocity=2, precision=20)
    >>> mpmath.nstr(period, 15)  # f = u: omega**2 = 1 + 3 for every orbit
    '3.14159265358979'
    """
    precision = validate_precision(precision)
    potential = _make_potential(f, breakpoints)
    return _period(potential, epsilon, a0, omega0, precision, velocity)


@locked
def conservative_frequency(
    f: Nonlinearity,
    epsilon: Any,
    *,
    a0: Any,
    omega0: Any = 1,
    precision: int = 30,
    velocity: Any = 0,
    breakpoints: Sequence[Any] | None = None,
) -> tuple[mpmath.mpf, mpmath.mpf]:
    """Exact angular frequency ``2 pi / T`` and its error estimate.

    Same parameters as :func:`conservative_period`.

    Examples
    --------
    >>> import sympy
    >>> u = sympy.Symbol("u")
    >>> frequency, error = conservative_frequency(u, 3, a0=1, omega0=1, precision=20)
    >>> mpmath.nstr(frequency, 20)  # f = u: linear with omega**2 = 1 + 3
    '2.0'
    """
    precision = validate_precision(precision)
    potential = _make_potential(f, breakpoints)
    with workdps(precision + 10):
        period, period_error = _period(potential, epsilon, a0, omega0, precision + 10, velocity)
        frequency = 2 * mpmath.pi / period
        error = frequency * period_error / period + abs(frequency) * mpmath.mpf(10) ** (-precision)
    with workdps(precision):
        return +frequency, +error


@locked
def nonlinearity_breakpoints(f: Nonlinearity, *, breakpoints: Sequence[Any] | None = None) -> tuple[sympy.Expr, ...]:
    """The breakpoints at which the quadrature reference cuts the orbit (exact, increasing).

    These are the zeros of the switching arguments of ``Max``, ``Min``, ``Abs``,
    ``Heaviside``, ``sign`` and the ``Piecewise`` conditions (each linear in u
    once the switches inside it are resolved), the real zeros of the polynomial
    base of a non-integer or negative power and of the argument of a logarithm,
    and the given ``breakpoints``.  An analytic f has none.

    Raises
    ------
    UnsupportedNonlinearityError
        If a switching argument is not linear in u (e.g. ``Heaviside(sin(u))``,
        ``sign(sin(1/u))``: infinitely many breakpoints) or f uses ``floor``,
        ``Mod``, ``DiracDelta``...

    Examples
    --------
    >>> import sympy
    >>> u = sympy.Symbol("u")
    >>> nonlinearity_breakpoints(sympy.Max(0, u - sympy.Rational(1, 5))**sympy.Rational(3, 2) + sympy.Heaviside(u + 1))
    (-1, 1/5)
    >>> nonlinearity_breakpoints(u**3)
    ()
    """
    potential = _make_potential(f, breakpoints)
    if isinstance(potential, _PiecewisePotential):
        return tuple(potential.cuts)
    return ()
