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

No Lindstedt-Poincare machinery is involved.  Two quadratures are used.

*Analytic f* (a sympy expression without switching functions, or a callable
given without breakpoints).  The inverse-square-root endpoint singularities are
removed by ``u = mid + half sin(theta)``, ``mid = (b_+ + b_-)/2``,
``half = (b_+ - b_-)/2``: since ``E - V(u)`` has simple zeros at both ends,
``R(theta) = (E - V(u))/cos(theta)**2`` is smooth and positive, and

    T = integral_0^{2 pi} half / sqrt(2 R(theta)) d theta

is the integral of a smooth *periodic* function over a full period.  The
trapezoidal rule is then geometrically convergent; the number of nodes is
doubled until two successive results agree, which also gives the error estimate.

*Piecewise-analytic f* (``Max``, ``Min``, ``Abs``, ``Heaviside``, ``sign``,
``Piecewise``, and real powers ``p`` of such pieces, e.g. the Hertz contact
``Max(0, u)**(3/2)``).  The trapezoidal rule is only algebraically convergent
when ``V`` is not analytic on the orbit, so the line is cut at the
*breakpoints*: the zeros of the switching arguments (each must be linear in u,
``alpha u + beta``, once the switches inside it are resolved; anything else —
e.g. ``sign(sin(1/u))`` with infinitely many switches — is refused), and the
real zeros of the polynomial base of a non-integer or negative power (and of the
argument of a logarithm).  Between consecutive breakpoints every switch has a
fixed branch, so f is one analytic expression ``f_k`` there; its antiderivative
``G_k`` is found by sympy (numerically by tanh-sinh where sympy cannot) and the
pieces are joined continuously, ``F = K_k + G_k`` (``F`` is continuous also
where ``f`` jumps).  The orbit ``[b_-, b_+]`` is cut at the breakpoints inside
it and each segment is integrated by tanh-sinh quadrature (``mpmath.quad``,
double-exponentially convergent despite the algebraic endpoint singularities of
``V`` at the breakpoints).  On a segment ``[p, b]`` ending at a turning point
``b`` the square-root singularity is removed by ``u = b - (b - p) s**2``:

    integral_p^b du / sqrt(2 (V(b) - V(u))) = integral_0^1 2 |b - p| / sqrt(2 D(s)/s**2) ds,

``D(s) = V(b) - V(u)``, analytic in s at ``s = 0``; ``D`` is formed as
``omega0**2 (b - u)(b + u)/2 + epsilon (G_k(b) - G_k(u))`` in twice the
working precision (and replaced by its linearisation ``V'(b)(b - u)`` where
``s**2`` is below the working epsilon), so that the cancellation near the
turning point costs no digits.  An orbit inside one piece is cut at its middle.
The error estimate is the sum of the tanh-sinh error estimates.  A non-integrable
singularity of f (``|u - c|**p``, ``p <= -1``) or a region where f is not real
may not be reached by the orbit.

Taylor coefficients of the angular frequency ``omega(epsilon) = 2 pi / T`` at
``epsilon = 0`` are obtained from a Chebyshev interpolant of ``omega`` on a
small real interval ``[-r, r]`` (two nested grids give the error estimate).  For
a piecewise f, ``omega`` is analytic at ``epsilon = 0`` as long as no turning
point of the ``epsilon = 0`` orbit lies on a breakpoint (no grazing); ``r`` is
kept below a quarter of the nearest real epsilon at which a breakpoint becomes
a turning point (there ``V(c) = E``, which is linear in epsilon).
"""

from __future__ import annotations

import bisect
import functools
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from fractions import Fraction
from numbers import Number
from typing import Any, Union

import mpmath
import sympy
from sympy.functions.elementary.integers import RoundFunction

from .._errors import (
    ConvergenceError,
    OrderError,
    ParameterError,
    ProblemError,
    UnsupportedNonlinearityError,
)
from ..problems.parsing import parse_expression, parse_real
from .._precision import locked, workdps

__all__ = [
    "conservative_period",
    "conservative_frequency",
    "frequency_taylor_coefficients",
    "nonlinearity_breakpoints",
    "as_mpmath_number",
]

Nonlinearity = Union[sympy.Expr, Callable[[Any], Any]]

_MAXIMUM_TRAPEZOID_NODES = 2**13
_INITIAL_TRAPEZOID_NODES = 16
_MAXIMUM_CHEBYSHEV_ORDER = 24
# An angular offset that is not a dyadic fraction of 2 pi, so that no node of
# any power-of-two trapezoid grid falls on the turning points theta = +-pi/2.
_NODE_OFFSET_FRACTION = Fraction(1, 7)

_SWITCHING_FUNCTIONS = (sympy.Max, sympy.Min, sympy.Abs, sympy.Heaviside, sympy.sign, sympy.Piecewise)
_REFUSED_FUNCTIONS = (RoundFunction, sympy.frac, sympy.Mod, sympy.DiracDelta)
_MAXIMUM_BREAKPOINTS = 64
_SUPPORTED = (
    "supported: f analytic between finitely many breakpoints, written with Max, Min, Abs, Heaviside, sign "
    "and Piecewise whose arguments and conditions are linear in u (alpha*u + beta once inner switches are "
    "resolved), sums, products and real powers of such pieces (e.g. Max(0, u)**(3/2), u*Abs(u), "
    "Heaviside(u - 1/3)), with at most integrable singularities |u - c|**p, p > -1; a callable f with "
    "breakpoints=[...]"
)


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


class _Potential:
    """``V(u) = omega0**2 u**2/2 + epsilon F(u)`` and its slope, from f."""

    def __init__(self, nonlinearity: Nonlinearity) -> None:
        if isinstance(nonlinearity, sympy.Basic):
            expression = nonlinearity
            free = expression.free_symbols
            variables = [symbol for symbol in free if symbol.name == "u"]
            others = sorted(symbol.name for symbol in free if symbol.name != "u")
            if others:
                raise ParameterError(
                    f"f(u) = {expression} contains the symbols {others} besides u; "
                    "substitute numeric values for them (expr.subs(...)) before calling"
                )
            variable = variables[0] if variables else sympy.Symbol("u")
            dummy = sympy.Dummy("s")
            self._force = sympy.lambdify(variable, expression, modules="mpmath")
            antiderivative = sympy.integrate(expression.subs(variable, dummy), (dummy, 0, variable))
            if antiderivative.has(sympy.Integral) or antiderivative.has(sympy.Piecewise):
                self._antiderivative = self._numerical_antiderivative
            else:
                self._antiderivative = sympy.lambdify(variable, antiderivative, modules="mpmath")
            self.description = f"f(u) = {expression}"
        elif callable(nonlinearity):
            self._force = nonlinearity
            self._antiderivative = self._numerical_antiderivative
            self.description = f"f = {getattr(nonlinearity, '__name__', repr(nonlinearity))}"
        else:
            raise ProblemError(
                f"f must be a sympy expression in the symbol u or a callable on mpmath numbers, "
                f"got {type(nonlinearity).__name__}"
            )

    def _numerical_antiderivative(self, position: Any) -> Any:
        return mpmath.quad(self._force, [0, position], method="gauss-legendre")

    def force(self, position: Any) -> Any:
        return mpmath.mpmathify(self._force(position))

    def antiderivative(self, position: Any) -> Any:
        return mpmath.mpmathify(self._antiderivative(position))

    def value(self, position: Any, epsilon: mpmath.mpf, omega0: mpmath.mpf) -> Any:
        """``V(u) = omega0**2 u**2/2 + epsilon F(u)``."""
        return omega0**2 * position**2 / 2 + epsilon * self.antiderivative(position)

    def slope(self, position: Any, epsilon: mpmath.mpf, omega0: mpmath.mpf) -> Any:
        """``V'(u) = omega0**2 u + epsilon f(u)``."""
        return omega0**2 * position + epsilon * self.force(position)


def _escape_distances(scale: mpmath.mpf) -> list[mpmath.mpf]:
    """Scan distances: steps of scale/16 up to 4 scale, then geometric steps (factor 5/4) up to 1e12 scale."""
    distances = [scale * k / 16 for k in range(1, 65)]
    distance = distances[-1]
    while distance < scale * mpmath.mpf(10) ** 12:
        distance *= mpmath.mpf(5) / 4
        distances.append(distance)
    return distances


def _smooth_turning_point(
    potential: _Potential,
    epsilon: mpmath.mpf,
    omega0: mpmath.mpf,
    origin: mpmath.mpf,
    direction: int,
    energy: mpmath.mpf,
    scale: mpmath.mpf,
    escape_message: str,
) -> mpmath.mpf:
    """First point past ``origin`` in ``direction`` where ``V`` climbs to ``energy`` (``V(origin) <= energy``)."""

    def excess(position: mpmath.mpf) -> mpmath.mpf:
        return energy - potential.value(position, epsilon, omega0)

    # The first sign change of E - V(u) on the scan brackets the turning point.
    previous = mpmath.mpf(0)
    for current in _escape_distances(scale):
        if excess(origin + direction * current) <= 0:
            break
        previous = current
    else:
        raise ConvergenceError(escape_message)
    # Safeguarded Newton on the bracket [previous, current] of distances.
    low, high = previous, current
    guess = high
    tolerance = mpmath.eps * 8 * max(scale, abs(origin))
    for _ in range(400):
        position = origin + direction * guess
        value = excess(position)
        if value == 0:
            break
        if value > 0:
            low = guess
        else:
            high = guess
        derivative = -direction * potential.slope(position, epsilon, omega0)
        candidate = guess - value / derivative if derivative != 0 else low - 1
        if not low <= candidate <= high:
            candidate = (low + high) / 2
        change = abs(candidate - guess)
        guess = candidate
        if change <= tolerance or high - low <= tolerance:
            break
    else:
        raise ConvergenceError("root finding for a turning point did not converge")
    return origin + direction * guess


def _find_other_turning_point(
    potential: _Potential,
    epsilon: mpmath.mpf,
    a0: mpmath.mpf,
    omega0: mpmath.mpf,
) -> mpmath.mpf:
    """First point b past which the orbit released at rest from a0 cannot go."""
    energy = potential.value(a0, epsilon, omega0)
    initial_slope = potential.slope(a0, epsilon, omega0)
    scale = abs(a0) if a0 != 0 else mpmath.mpf(1)
    if abs(initial_slope) <= mpmath.eps * 1000 * omega0**2 * scale:
        raise ProblemError(
            f"a0 = {mpmath.nstr(a0, 15)} is an equilibrium of u'' + omega0^2 u + epsilon f(u) = 0 "
            f"with {potential.description}: the motion is at rest; choose a0 away from the equilibrium"
        )
    direction = -1 if initial_slope > 0 else 1
    message = (
        f"no second turning point: with epsilon = {mpmath.nstr(epsilon, 15)} and {potential.description}, "
        f"the potential V(u) never climbs back to the release energy V(a0) on the side "
        "the orbit moves to, so the orbit escapes (it does not close); reduce |epsilon| or |a0|"
    )
    return _smooth_turning_point(potential, epsilon, omega0, a0, direction, energy, scale, message)


def _trapezoid_between(
    potential: _Potential,
    epsilon: mpmath.mpf,
    omega0: mpmath.mpf,
    first: mpmath.mpf,
    second: mpmath.mpf,
    energy: mpmath.mpf,
    target_digits: int,
) -> tuple[mpmath.mpf, mpmath.mpf]:
    """Period of the orbit of energy ``energy`` between the turning points ``first`` and ``second``."""
    middle = (first + second) / 2
    half_width = (first - second) / 2
    offset = 2 * mpmath.pi * _NODE_OFFSET_FRACTION.numerator / _NODE_OFFSET_FRACTION.denominator

    def integrand(angle: mpmath.mpf) -> mpmath.mpf:
        position = middle + half_width * mpmath.sin(angle)
        excess = energy - potential.value(position, epsilon, omega0)
        reduced = excess / mpmath.cos(angle) ** 2
        if reduced <= 0:
            raise ConvergenceError(
                "the energy integrand vanished inside the orbit: the orbit is at (or numerically "
                "indistinguishable from) a separatrix; move epsilon or a0 away from it"
            )
        return abs(half_width) / mpmath.sqrt(2 * reduced)

    nodes = _INITIAL_TRAPEZOID_NODES
    total = mpmath.fsum(integrand(offset + 2 * mpmath.pi * j / nodes) for j in range(nodes))
    estimate = 2 * mpmath.pi * total / nodes
    tolerance = mpmath.mpf(10) ** (-target_digits)
    while nodes < _MAXIMUM_TRAPEZOID_NODES:
        # The refined grid adds the midpoints of the current one.
        total += mpmath.fsum(
            integrand(offset + 2 * mpmath.pi * (j + mpmath.mpf(1) / 2) / nodes) for j in range(nodes)
        )
        nodes *= 2
        refined = 2 * mpmath.pi * total / nodes
        difference = abs(refined - estimate)
        estimate = refined
        if difference <= tolerance * abs(refined):
            return refined, difference
    raise ConvergenceError(
        f"the periodic trapezoidal rule did not converge with {nodes} nodes: the orbit is close to a "
        "separatrix (a turning point is nearly an equilibrium), or f is not analytic on the orbit (pass it "
        "as a sympy expression with Max/Abs/Heaviside/..., or give breakpoints=[...] with a callable); "
        "reduce |epsilon| or |a0|"
    )


def _period_by_trapezoid(
    potential: _Potential,
    epsilon: mpmath.mpf,
    a0: mpmath.mpf,
    omega0: mpmath.mpf,
    target_digits: int,
) -> tuple[mpmath.mpf, mpmath.mpf]:
    """Period and error estimate at the current working precision (release at rest)."""
    other_turning_point = _find_other_turning_point(potential, epsilon, a0, omega0)
    energy = potential.value(a0, epsilon, omega0)
    return _trapezoid_between(potential, epsilon, omega0, a0, other_turning_point, energy, target_digits)


def _orbit_scale(a0: mpmath.mpf, velocity: mpmath.mpf, omega0: mpmath.mpf) -> mpmath.mpf:
    """Amplitude ``sqrt(a0**2 + v0**2/omega0**2)`` of the epsilon = 0 orbit (1 if it is the rest point)."""
    amplitude = mpmath.sqrt(a0**2 + (velocity / omega0) ** 2)
    return amplitude if amplitude != 0 else mpmath.mpf(1)


def _period_by_trapezoid_with_velocity(
    potential: _Potential,
    epsilon: mpmath.mpf,
    a0: mpmath.mpf,
    velocity: mpmath.mpf,
    omega0: mpmath.mpf,
    target_digits: int,
) -> tuple[mpmath.mpf, mpmath.mpf]:
    """Period of the orbit through (a0, v0), v0 != 0: both turning points from ``V(b) = E``."""
    energy = velocity**2 / 2 + potential.value(a0, epsilon, omega0)
    scale = _orbit_scale(a0, velocity, omega0)
    turning_points = []
    for direction in (1, -1):
        message = (
            f"no turning point on the side u {'>' if direction > 0 else '<'} a0: with epsilon = "
            f"{mpmath.nstr(epsilon, 15)} and {potential.description}, the potential V(u) never climbs to the "
            "energy v0**2/2 + V(a0), so the orbit escapes (it does not close); reduce |epsilon|, |a0| or |v0|"
        )
        turning_points.append(
            _smooth_turning_point(potential, epsilon, omega0, a0, direction, energy, scale, message)
        )
    return _trapezoid_between(potential, epsilon, omega0, turning_points[0], turning_points[1], energy, target_digits)


# ------------------------------------------------------------------ piecewise-analytic f
#: Marks a boundary value of an antiderivative that is infinite (a non-integrable singularity of f).
_SINGULAR = None
_NUMERIC = "numeric"


def _approximate(value: sympy.Expr, digits: int = 60) -> tuple[sympy.Float, sympy.Float]:
    """Real and imaginary part of an exact number, to ``digits`` digits."""
    real_part, imaginary_part = sympy.N(value, digits).as_real_imag()
    return real_part, imaginary_part


def _less(first: sympy.Expr, second: sympy.Expr) -> bool:
    """``first < second`` for exact real numbers (by 60-digit evaluation unless sympy decides exactly)."""
    decided = (second - first).is_positive
    if decided is not None:
        return bool(decided)
    return bool(_approximate(second - first)[0] > 0)


def _sign_at(expression: sympy.Expr, variable: sympy.Symbol, sample: sympy.Expr, f: sympy.Expr) -> int:
    """Sign of a real expression at ``u = sample`` (exact where sympy decides, else 60 digits)."""
    value = expression.subs(variable, sample)
    if value.is_positive:
        return 1
    if value.is_negative:
        return -1
    if value.is_zero:
        return 0
    real_part, imaginary_part = _approximate(value)
    if imaginary_part != 0 and abs(imaginary_part) > 10**-40 * (1 + abs(real_part)):
        raise UnsupportedNonlinearityError(
            f"f = {f}: the switching argument {expression} is not real at u = {sample}; {_SUPPORTED}"
        )
    return (real_part > 0) - (real_part < 0)


def _switch_zero(argument: sympy.Expr, variable: sympy.Symbol, f: sympy.Expr, what: str) -> sympy.Expr | None:
    """Zero of a switching argument that must be linear in u (None if it does not depend on u)."""
    expanded = sympy.expand(argument)
    if not expanded.has(variable):
        return None
    if not expanded.is_polynomial(variable) or sympy.degree(expanded, variable) != 1:
        raise UnsupportedNonlinearityError(
            f"f = {f}: the switching argument {argument} of {what} is not linear in u (it may switch "
            f"infinitely often, or at points that cannot be located exactly); {_SUPPORTED}"
        )
    slope = expanded.coeff(variable, 1)
    intercept = expanded.coeff(variable, 0)
    zero = -intercept / slope
    _, imaginary_part = _approximate(zero)
    if imaginary_part != 0:
        raise UnsupportedNonlinearityError(f"f = {f}: the switching argument {argument} is not real; {_SUPPORTED}")
    return zero


def _real_zeros(base: sympy.Expr, variable: sympy.Symbol) -> list[sympy.Expr]:
    """Real zeros of a polynomial base (of a non-integer or negative power, or of a log); [] otherwise."""
    expanded = sympy.expand(base)
    if not expanded.has(variable) or not expanded.is_polynomial(variable):
        return []
    degree = sympy.degree(expanded, variable)
    if degree == 1:
        zero = -expanded.coeff(variable, 0) / expanded.coeff(variable, 1)
        return [zero] if _approximate(zero)[1] == 0 else []
    try:
        return list(sympy.real_roots(sympy.Poly(expanded, variable)))
    except (sympy.PolynomialError, NotImplementedError, ValueError, TypeError):
        return []


def _is_singular_power(node: sympy.Basic, variable: sympy.Symbol) -> bool:
    """A power of a u-dependent base that is not analytic where its base vanishes."""
    if not isinstance(node, sympy.Pow) or not node.base.has(variable) or node.exp.has(variable):
        return False
    exponent = node.exp
    return bool(exponent.is_number) and not (exponent.is_integer and exponent.is_nonnegative)


class _Resolver:
    """Replaces every switch of f by its branch on an open interval; collects the breakpoints met."""

    def __init__(self, f: sympy.Expr, variable: sympy.Symbol) -> None:
        self.f = f
        self.variable = variable

    def resolve(self, node: sympy.Expr, sample: sympy.Expr, zeros: list[sympy.Expr]) -> sympy.Expr:
        variable = self.variable
        if not node.has(variable) or not node.args:
            return node
        if isinstance(node, _REFUSED_FUNCTIONS):
            raise UnsupportedNonlinearityError(
                f"f = {self.f}: {type(node).__name__} switches infinitely often (or is a distribution); {_SUPPORTED}"
            )
        if isinstance(node, sympy.Piecewise):
            for value, condition in node.args:
                if self.holds(condition, sample, zeros):
                    return self.resolve(value, sample, zeros)
            raise UnsupportedNonlinearityError(
                f"f = {self.f}: the Piecewise {node} is undefined near u = {sample}; end it with (value, True); {_SUPPORTED}"
            )
        args = [self.resolve(argument, sample, zeros) for argument in node.args]
        if isinstance(node, (sympy.Max, sympy.Min)):
            for first in range(len(args)):
                for second in range(first + 1, len(args)):
                    zero = _switch_zero(args[first] - args[second], variable, self.f, type(node).__name__)
                    if zero is not None:
                        zeros.append(zero)
            values = [_approximate(argument.subs(variable, sample))[0] for argument in args]
            pick = max if isinstance(node, sympy.Max) else min
            return args[values.index(pick(values))]
        if isinstance(node, (sympy.Abs, sympy.Heaviside, sympy.sign)):
            argument = args[0]
            zero = _switch_zero(argument, variable, self.f, type(node).__name__)
            if zero is not None:
                zeros.append(zero)
            sign = _sign_at(argument, variable, sample, self.f)
            if isinstance(node, sympy.Abs):
                return sign * argument
            if isinstance(node, sympy.sign):
                return sympy.Integer(sign)
            return sympy.Integer(1) if sign > 0 else sympy.Integer(0) if sign < 0 else sympy.Heaviside(0, *args[1:])
        rebuilt = node.func(*args)
        if _is_singular_power(rebuilt, variable):
            zeros.extend(_real_zeros(rebuilt.base, variable))
        elif isinstance(rebuilt, sympy.log):
            zeros.extend(_real_zeros(rebuilt.args[0], variable))
        return rebuilt

    def holds(self, condition: Any, sample: sympy.Expr, zeros: list[sympy.Expr]) -> bool:
        if condition in (sympy.true, True):
            return True
        if condition in (sympy.false, False):
            return False
        if isinstance(condition, sympy.And):
            return all([self.holds(argument, sample, zeros) for argument in condition.args])  # noqa: C419 (every zero)
        if isinstance(condition, sympy.Or):
            return any([self.holds(argument, sample, zeros) for argument in condition.args])  # noqa: C419 (every zero)
        if isinstance(condition, sympy.Not):
            return not self.holds(condition.args[0], sample, zeros)
        if isinstance(condition, sympy.core.relational.Relational):
            difference = self.resolve(condition.lhs, sample, zeros) - self.resolve(condition.rhs, sample, zeros)
            zero = _switch_zero(difference, self.variable, self.f, "a Piecewise condition")
            if zero is not None:
                zeros.append(zero)
            sign = _sign_at(difference, self.variable, sample, self.f)
            return {
                "<": sign < 0, "<=": sign <= 0, ">": sign > 0, ">=": sign >= 0, "==": sign == 0, "!=": sign != 0,
            }[condition.rel_op]
        raise UnsupportedNonlinearityError(f"f = {self.f}: the Piecewise condition {condition} is not supported; {_SUPPORTED}")


def _sorted_unique(points: Iterable[sympy.Expr]) -> list[sympy.Expr]:
    ordered = sorted(points, key=lambda point: _approximate(point)[0])
    unique: list[sympy.Expr] = []
    for point in ordered:
        if unique and abs(_approximate(point - unique[-1])[0]) <= 10**-45 * (1 + abs(_approximate(point)[0])):
            continue
        unique.append(point)
    return unique


def _intervals(cuts: Sequence[sympy.Expr]) -> list[tuple[sympy.Expr | None, sympy.Expr | None]]:
    bounds: list[sympy.Expr | None] = [None, *cuts, None]
    return [(bounds[k], bounds[k + 1]) for k in range(len(cuts) + 1)]


def _sample(lower: sympy.Expr | None, upper: sympy.Expr | None) -> sympy.Expr:
    """A point inside the open interval (lower, upper) (None: unbounded)."""
    if lower is None and upper is None:
        return sympy.Integer(0)
    if lower is None:
        return upper - 1
    if upper is None:
        return lower + 1
    return (lower + upper) / 2


def _interval_text(lower: sympy.Expr | None, upper: sympy.Expr | None) -> str:
    if lower is None and upper is None:
        return "all u"
    if lower is None:
        return f"u < {upper}"
    if upper is None:
        return f"u > {lower}"
    return f"{lower} < u < {upper}"


def _analyse(
    expression: sympy.Expr, variable: sympy.Symbol, extra: Sequence[sympy.Expr]
) -> tuple[list[sympy.Expr], list[sympy.Expr]]:
    """Breakpoints of f and the analytic expression of f between consecutive ones.

    Each round resolves every switch on every interval (the sign of each switching
    argument at an inner point); zeros of arguments that fall strictly inside an
    interval split it and the next round starts.  Nested switches need one round per level.
    """
    resolver = _Resolver(expression, variable)
    cuts = _sorted_unique(extra)
    for _round in range(16):
        found = []
        resolved = []
        for lower, upper in _intervals(cuts):
            zeros: list[sympy.Expr] = []
            resolved.append(resolver.resolve(expression, _sample(lower, upper), zeros))
            for zero in zeros:
                if (lower is None or _less(lower, zero)) and (upper is None or _less(zero, upper)):
                    found.append(zero)
        if not found:
            return cuts, resolved
        cuts = _sorted_unique([*cuts, *found])
        if len(cuts) > _MAXIMUM_BREAKPOINTS:
            raise UnsupportedNonlinearityError(
                f"f = {expression} has more than {_MAXIMUM_BREAKPOINTS} breakpoints; {_SUPPORTED}"
            )
    raise UnsupportedNonlinearityError(f"f = {expression}: the switches are nested too deeply; {_SUPPORTED}")


def _real(value: Any) -> mpmath.mpf:
    """The real part of an mpmath value.

    An antiderivative such as ``log(u - c)`` of a real f is complex on ``u < c`` with a
    constant imaginary part; its real part is then a real antiderivative.
    """
    value = mpmath.mpmathify(value)
    return value.real if isinstance(value, mpmath.mpc) else value


@dataclass
class _Piece:
    """f on one open interval between breakpoints (bounds None: unbounded)."""

    lower: sympy.Expr | None
    upper: sympy.Expr | None
    sample: sympy.Expr
    expression: sympy.Expr | None  # None for a callable f
    force: Callable[[Any], Any]
    primitive: Callable[[Any], Any] | None  # the antiderivative G (None: by quadrature from the sample)
    boundary_primitives: tuple[Any, Any]  # exact G(lower+), G(upper-); _SINGULAR or _NUMERIC
    problem: str | None  # why the orbit may not enter this interval


def _boundary_primitive(antiderivative: sympy.Expr, variable: sympy.Symbol, point: sympy.Expr, direction: str) -> Any:
    """One-sided limit of an antiderivative at a breakpoint (exact), or _SINGULAR if it is infinite."""
    value = antiderivative.subs(variable, point)
    if value.has(sympy.zoo, sympy.oo, -sympy.oo, sympy.nan) or value.is_finite is False:
        try:
            value = sympy.limit(antiderivative, variable, point, dir=direction)
        except (NotImplementedError, ValueError, TypeError):  # pragma: no cover - sympy could not decide
            return _NUMERIC
    if value.has(sympy.zoo, sympy.oo, -sympy.oo, sympy.nan, sympy.AccumBounds) or value.is_finite is False:
        return _SINGULAR
    return sympy.re(value)


def _unavailable(position: Any) -> Any:  # pragma: no cover - blocked pieces are never evaluated
    raise UnsupportedNonlinearityError(f"f is not real and finite at u = {position}; {_SUPPORTED}")


def _symbolic_piece(
    f: sympy.Expr, variable: sympy.Symbol, lower: sympy.Expr | None, upper: sympy.Expr | None, expression: sympy.Expr
) -> _Piece:
    sample = _sample(lower, upper)
    where = _interval_text(lower, upper)
    problem = None
    if expression.has(sympy.zoo, sympy.oo, -sympy.oo, sympy.nan):
        problem = f"f = {f} is infinite for {where}"
    else:
        real_part, imaginary_part = _approximate(expression.subs(variable, sample), 30)
        if not (real_part.is_finite and imaginary_part.is_finite):
            problem = f"f = {f} is infinite for {where}"
        elif imaginary_part != 0 and abs(imaginary_part) > 10**-20 * (1 + abs(real_part)):
            problem = (
                f"f = {f} is not real for {where} (it is {expression} there; write a fractional power of a "
                "base that may change sign as a power of Max(0, ...) or Abs(...))"
            )
    if problem is not None:
        return _Piece(lower, upper, sample, expression, _unavailable, None, (_SINGULAR, _SINGULAR), problem)
    force = sympy.lambdify(variable, expression, modules="mpmath")
    antiderivative = sympy.integrate(expression, variable)
    if antiderivative.has(sympy.Integral, sympy.Piecewise):
        return _Piece(lower, upper, sample, expression, force, None, (_NUMERIC, _NUMERIC), None)
    bounds = (
        _boundary_primitive(antiderivative, variable, lower, "+") if lower is not None else _NUMERIC,
        _boundary_primitive(antiderivative, variable, upper, "-") if upper is not None else _NUMERIC,
    )
    primitive = sympy.lambdify(variable, antiderivative, modules="mpmath")
    return _Piece(lower, upper, sample, expression, force, primitive, bounds, None)


class _PiecewisePotential:
    """``V(u) = omega0**2 u**2/2 + epsilon F(u)`` for an f that is analytic between breakpoints."""

    def __init__(self, cuts: list[sympy.Expr], pieces: list[_Piece], description: str) -> None:
        self.cuts = cuts
        self.pieces = pieces
        self.description = description
        self._cache: dict[Any, Any] = {}

    def cut_values(self) -> list[mpmath.mpf]:
        """The breakpoints as mpf at the current precision."""
        key = ("cuts", mpmath.mp.prec)
        if key not in self._cache:
            self._cache[key] = [real_parameter(cut, "breakpoint") for cut in self.cuts]
        return self._cache[key]

    def locate(self, position: mpmath.mpf) -> tuple[int, int]:
        """Pieces on the left and right of ``position`` (equal unless it is a breakpoint)."""
        cuts = self.cut_values()
        index = bisect.bisect_left(cuts, position)
        if index < len(cuts) and cuts[index] == position:
            return index, index + 1
        return index, index

    def force(self, piece: int, position: mpmath.mpf) -> mpmath.mpf:
        return _real(self.pieces[piece].force(position))

    def _sample_value(self, piece: int) -> mpmath.mpf:
        key = ("sample", piece, mpmath.mp.prec)
        if key not in self._cache:
            self._cache[key] = real_parameter(self.pieces[piece].sample, "sample point")
        return self._cache[key]

    def primitive(self, piece: int, position: mpmath.mpf) -> mpmath.mpf:
        """An antiderivative G of f on the piece, at ``position`` (inside or on its boundary)."""
        data = self.pieces[piece]
        if data.primitive is not None:
            return _real(data.primitive(position))
        return _real(mpmath.quad(data.force, [self._sample_value(piece), position]))

    def integral(self, piece: int, start: mpmath.mpf, end: mpmath.mpf, end_primitive: Any) -> mpmath.mpf:
        """``G(end) - G(start)`` on one piece; ``end_primitive`` is ``G(end)`` (symbolic pieces)."""
        data = self.pieces[piece]
        if data.primitive is not None:
            return end_primitive - _real(data.primitive(start))
        return _real(mpmath.quad(data.force, [start, end]))

    def boundary_primitive(self, piece: int, side: int) -> mpmath.mpf | None:
        """G at the lower (side -1) or upper (side +1) breakpoint of the piece, from inside; None if infinite."""
        key = ("boundary", piece, side, mpmath.mp.prec)
        if key not in self._cache:
            data = self.pieces[piece]
            exact = data.boundary_primitives[0 if side < 0 else 1]
            cut = self.cut_values()[piece - 1 if side < 0 else piece]
            if exact is _SINGULAR:
                value = None
            elif exact is _NUMERIC:
                value = self.primitive(piece, cut)
                if not mpmath.isfinite(value):
                    value = None
            else:
                value = real_parameter(exact, "boundary value")
            self._cache[key] = value
        return self._cache[key]

    def constants(self, reference: int) -> tuple[list[mpmath.mpf | None], list[str | None]]:
        """``K_k`` with ``F = K_k + G_k`` continuous and ``K_reference = 0``; pieces the orbit cannot reach get
        None and the reason (a non-integrable singularity at the breakpoint, or f not real/finite beyond)."""
        key = ("constants", reference, mpmath.mp.prec)
        if key in self._cache:
            return self._cache[key]
        count = len(self.pieces)
        if self.pieces[reference].problem is not None:
            raise UnsupportedNonlinearityError(
                f"the orbit starts where {self.pieces[reference].problem}; {_SUPPORTED}"
            )
        constants: list[mpmath.mpf | None] = [None] * count
        blocked: list[str | None] = [None] * count
        constants[reference] = mpmath.mpf(0)
        for step in (1, -1):
            piece = reference
            while 0 <= piece + step < count:
                following = piece + step
                cut = self.cuts[piece if step > 0 else piece - 1]
                inside = self.boundary_primitive(piece, step)
                outside = self.boundary_primitive(following, -step)
                reason = None
                if self.pieces[following].problem is not None:
                    reason = self.pieces[following].problem
                elif inside is None or outside is None:
                    reason = f"{self.description} has a non-integrable singularity at u = {cut}"
                if reason is not None:
                    for other in range(following, count) if step > 0 else range(following + 1):
                        blocked[other] = reason
                    break
                constants[following] = constants[piece] + inside - outside
                piece = following
        self._cache[key] = (constants, blocked)
        return constants, blocked


def _checked_expression(expression: sympy.Basic) -> tuple[sympy.Expr, sympy.Symbol]:
    """f with its variable u (other symbols are refused, as by :class:`_Potential`)."""
    free = expression.free_symbols
    variables = [symbol for symbol in free if symbol.name == "u"]
    others = sorted(symbol.name for symbol in free if symbol.name != "u")
    if others:
        raise ParameterError(
            f"f(u) = {expression} contains the symbols {others} besides u; "
            "substitute numeric values for them (expr.subs(...)) before calling"
        )
    return expression, variables[0] if variables else sympy.Symbol("u")


def _needs_pieces(expression: sympy.Expr, variable: sympy.Symbol) -> bool:
    """True if f has a switch or a branch/singular point on the real line (not analytic everywhere)."""
    for node in sympy.preorder_traversal(expression):
        if isinstance(node, _SWITCHING_FUNCTIONS + _REFUSED_FUNCTIONS) and node.has(variable):
            return True
        if _is_singular_power(node, variable) and _real_zeros(node.base, variable):
            return True
        if isinstance(node, sympy.log) and _real_zeros(node.args[0], variable):
            return True
    return False


@functools.lru_cache(maxsize=64)
def _piecewise_from_expression(
    expression: sympy.Expr, variable: sympy.Symbol, extra: tuple[sympy.Expr, ...]
) -> _PiecewisePotential:
    exact = parse_expression(expression, symbols={"u": variable}, what="f")
    cuts, resolved = _analyse(exact, variable, extra)
    pieces = [
        _symbolic_piece(exact, variable, lower, upper, piece_expression)
        for (lower, upper), piece_expression in zip(_intervals(cuts), resolved)
    ]
    return _PiecewisePotential(cuts, pieces, f"f(u) = {exact}")


def _piecewise_from_callable(function: Callable[[Any], Any], extra: tuple[sympy.Expr, ...]) -> _PiecewisePotential:
    cuts = _sorted_unique(extra)
    pieces = [
        _Piece(lower, upper, _sample(lower, upper), None, function, None, (_NUMERIC, _NUMERIC), None)
        for lower, upper in _intervals(cuts)
    ]
    name = getattr(function, "__name__", repr(function))
    return _PiecewisePotential(cuts, pieces, f"f = {name} (breakpoints {[str(cut) for cut in cuts]})")


def _exact_breakpoints(breakpoints: Any) -> tuple[sympy.Expr, ...]:
    if isinstance(breakpoints, (str, bytes)) or not isinstance(breakpoints, Iterable):
        raise ProblemError(f"breakpoints must be a sequence of real numbers, got {breakpoints!r}")
    return tuple(parse_real(point, what="breakpoint") for point in breakpoints)


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


class _PiecewiseOrbit:
    """The potential of one epsilon, with ``F`` normalised on the piece where the orbit starts."""

    def __init__(self, potential: _PiecewisePotential, epsilon: mpmath.mpf, omega0: mpmath.mpf, reference: int) -> None:
        self.potential = potential
        self.epsilon = epsilon
        self.omega0 = omega0
        self.constants, self.blocked = potential.constants(reference)

    def value(self, position: mpmath.mpf, piece: int) -> mpmath.mpf:
        """``V(position)`` with f continued analytically from ``piece``."""
        constant = self.constants[piece]
        return self.omega0**2 * position**2 / 2 + self.epsilon * (constant + self.potential.primitive(piece, position))

    def boundary_value(self, piece: int, side: int) -> mpmath.mpf | None:
        """``V`` at the lower (-1) or upper (+1) breakpoint of ``piece`` from inside (None: infinite)."""
        primitive = self.potential.boundary_primitive(piece, side)
        if primitive is None:
            return None
        position = self.potential.cut_values()[piece - 1 if side < 0 else piece]
        return self.omega0**2 * position**2 / 2 + self.epsilon * (self.constants[piece] + primitive)

    def slope(self, position: mpmath.mpf, piece: int) -> mpmath.mpf:
        return self.omega0**2 * position + self.epsilon * self.potential.force(piece, position)

    def drop(self, turning: mpmath.mpf, turning_primitive: Any, offset: mpmath.mpf, piece: int) -> mpmath.mpf:
        """``V(turning) - V(turning - offset)`` on one piece, without forming either value."""
        position = turning - offset
        change = self.potential.integral(piece, position, turning, turning_primitive)
        return self.omega0**2 * offset * (turning + position) / 2 + self.epsilon * change


def _piecewise_turning_point(
    orbit: _PiecewiseOrbit,
    start: mpmath.mpf,
    piece: int,
    direction: int,
    energy: mpmath.mpf,
    scale: mpmath.mpf,
) -> tuple[mpmath.mpf, int]:
    """First point past ``start`` in ``direction`` with ``V = energy``, and the piece it closes."""
    potential = orbit.potential
    if orbit.constants[piece] is None:
        raise UnsupportedNonlinearityError(
            f"the orbit crosses u = {mpmath.nstr(start, 15)}, beyond which {orbit.blocked[piece]}; {_SUPPORTED}"
        )
    cuts = potential.cut_values()
    events: list[tuple[mpmath.mpf, int | None]] = [(distance, None) for distance in _escape_distances(scale)]
    for index, cut in enumerate(cuts):
        distance = (cut - start) * direction
        if distance > 0:
            events.append((distance, index))
    events.sort(key=lambda event: (event[0], event[1] is None))

    def excess(distance: mpmath.mpf, where: int) -> mpmath.mpf:
        return energy - orbit.value(start + direction * distance, where)

    previous = mpmath.mpf(0)
    bracket = None
    for distance, cut_index in events:
        if distance <= previous:
            continue
        if cut_index is None:
            if excess(distance, piece) <= 0:
                bracket = (previous, distance)
                break
            previous = distance
            continue
        boundary = orbit.boundary_value(piece, direction)
        if boundary is None:
            # A non-integrable singularity at the breakpoint: V is infinite there.  The orbit turns
            # before it if V climbs to the energy on the way (a repulsive wall); else it falls in.
            gap = distance - previous
            last = previous
            for power in range(1, mpmath.mp.prec + 20):
                trial = distance - gap / mpmath.mpf(2) ** power
                if trial >= distance:  # as close to the singular point as the precision allows
                    break
                if excess(trial, piece) <= 0:
                    bracket = (last, trial)
                    break
                last = trial
            if bracket is None:
                raise UnsupportedNonlinearityError(
                    f"the orbit reaches u = {potential.cuts[cut_index]}, where {potential.description} has a "
                    f"non-integrable singularity (epsilon = {mpmath.nstr(orbit.epsilon, 15)}); {_SUPPORTED}"
                )
            break
        if energy - boundary <= 0:
            bracket = (previous, distance)
            break
        following = piece + direction
        if orbit.constants[following] is None:
            raise UnsupportedNonlinearityError(
                f"the orbit (epsilon = {mpmath.nstr(orbit.epsilon, 15)}) crosses u = {potential.cuts[cut_index]}, "
                f"beyond which {orbit.blocked[following]}; {_SUPPORTED}"
            )
        piece = following
        previous = distance
    if bracket is None:
        raise ConvergenceError(
            f"no turning point on the side u {'>' if direction > 0 else '<'} {mpmath.nstr(start, 15)}: with "
            f"epsilon = {mpmath.nstr(orbit.epsilon, 15)} and {potential.description}, the potential V(u) never "
            "climbs back to the energy of the orbit, so the orbit escapes (it does not close); reduce |epsilon| "
            "or the amplitude"
        )
    # Safeguarded Newton inside one piece (V is analytic there).
    low, high = bracket
    guess = high
    tolerance = mpmath.eps * 8 * max(scale, abs(start))
    for _ in range(mpmath.mp.prec + 100):
        position = start + direction * guess
        value = energy - orbit.value(position, piece)
        if value == 0:
            break
        if value > 0:
            low = guess
        else:
            high = guess
        derivative = -direction * orbit.slope(position, piece)
        candidate = guess - value / derivative if derivative != 0 else low - 1
        if not low <= candidate <= high:
            candidate = (low + high) / 2
        change = abs(candidate - guess)
        guess = candidate
        if change <= tolerance or high - low <= tolerance:
            break
    else:
        raise ConvergenceError("root finding for a turning point did not converge")
    return start + direction * guess, piece


def _tanh_sinh(integrand: Callable[[Any], Any], lower: mpmath.mpf, upper: mpmath.mpf, target_digits: int) -> tuple[mpmath.mpf, mpmath.mpf]:
    """Tanh-sinh quadrature with its error estimate; a second try at higher degree, else ConvergenceError."""
    tolerance = mpmath.mpf(10) ** (-target_digits)
    value, error = mpmath.quad(integrand, [lower, upper], method="tanh-sinh", error=True)
    if error > tolerance * abs(value):
        # mpmath's default maximal degree is int(4 + log2(prec/30)) + 2 (prec in bits); allow three more levels.
        degree = int(4 + max(0, mpmath.log(mpmath.mp.prec / 30.0, 2))) + 5
        value, error = mpmath.quad(integrand, [lower, upper], method="tanh-sinh", error=True, maxdegree=degree)
    if error > tolerance * abs(value):
        raise ConvergenceError(
            f"tanh-sinh quadrature did not converge on [{mpmath.nstr(lower, 10)}, {mpmath.nstr(upper, 10)}] "
            f"(estimated error {mpmath.nstr(error, 3)}): f is not analytic between its breakpoints (a callable f "
            "needs breakpoints=[...] at every kink or jump), or the orbit is close to a separatrix"
        )
    return value, error


def _separatrix_error() -> ConvergenceError:
    return ConvergenceError(
        "the energy integrand vanished inside the orbit: the orbit is at (or numerically "
        "indistinguishable from) a separatrix; move epsilon or a0 away from it"
    )


def _turning_segment(
    orbit: _PiecewiseOrbit, turning: mpmath.mpf, other: mpmath.mpf, piece: int, target_digits: int
) -> tuple[mpmath.mpf, mpmath.mpf]:
    """``integral du / sqrt(2 (E - V))`` from ``other`` to the turning point, by ``u = turning - (turning - other) s**2``."""
    working = mpmath.mp.dps
    length = turning - other
    threshold = mpmath.mpf(10) ** (-working)
    with workdps(2 * working):
        symbolic = orbit.potential.pieces[piece].primitive is not None
        turning_primitive = orbit.potential.primitive(piece, turning) if symbolic else None
        limit = orbit.slope(turning, piece) * length  # D(s)/s**2 at s = 0
    if limit <= 0:
        raise _separatrix_error()

    def integrand(s: mpmath.mpf) -> mpmath.mpf:
        with workdps(2 * working):
            square = s * s
            if square <= threshold:
                reduced = limit
            else:
                reduced = orbit.drop(turning, turning_primitive, length * square, piece) / square
            if reduced <= 0:
                raise _separatrix_error()
            return 2 * abs(length) / mpmath.sqrt(2 * reduced)

    return _tanh_sinh(integrand, mpmath.mpf(0), mpmath.mpf(1), target_digits)


def _inner_segment(
    orbit: _PiecewiseOrbit, lower: mpmath.mpf, upper: mpmath.mpf, piece: int, energy: mpmath.mpf, target_digits: int
) -> tuple[mpmath.mpf, mpmath.mpf]:
    """``integral du / sqrt(2 (E - V))`` between two breakpoints inside the orbit."""
    working = mpmath.mp.dps

    def integrand(position: mpmath.mpf) -> mpmath.mpf:
        with workdps(2 * working):
            excess = energy - orbit.value(position, piece)
            if excess <= 0:
                raise _separatrix_error()
            return 1 / mpmath.sqrt(2 * excess)

    return _tanh_sinh(integrand, lower, upper, target_digits)


def _release_direction(
    potential: _PiecewisePotential, epsilon: mpmath.mpf, a0: mpmath.mpf, omega0: mpmath.mpf, scale: mpmath.mpf
) -> tuple[int, int]:
    """Direction in which the orbit released at rest from a0 moves, and the piece it moves into."""
    left, right = potential.locate(a0)

    def slope(piece: int) -> mpmath.mpf | None:
        if potential.pieces[piece].problem is not None:
            return None
        return omega0**2 * a0 + epsilon * potential.force(piece, a0)

    tolerance = mpmath.eps * 1000 * omega0**2 * scale
    right_slope, left_slope = slope(right), slope(left)
    moves_right = right_slope is not None and right_slope < -tolerance
    moves_left = left_slope is not None and left_slope > tolerance
    if moves_right and moves_left:
        raise ProblemError(
            f"a0 = {mpmath.nstr(a0, 15)} is a peak of the potential at a breakpoint of {potential.description} "
            "(the force jumps there): the motion from rest is ambiguous; choose a0 off the breakpoint"
        )
    if not moves_right and not moves_left:
        if right_slope is None and left_slope is None:
            raise UnsupportedNonlinearityError(f"a0 = {mpmath.nstr(a0, 15)} lies where {potential.pieces[right].problem}; {_SUPPORTED}")
        raise ProblemError(
            f"a0 = {mpmath.nstr(a0, 15)} is an equilibrium of u'' + omega0^2 u + epsilon f(u) = 0 "
            f"with {potential.description}: the motion is at rest; choose a0 away from the equilibrium"
        )
    return (1, right) if moves_right else (-1, left)


def _period_by_pieces(
    potential: _PiecewisePotential,
    epsilon: mpmath.mpf,
    a0: mpmath.mpf,
    velocity: mpmath.mpf,
    omega0: mpmath.mpf,
    target_digits: int,
) -> tuple[mpmath.mpf, mpmath.mpf]:
    """Period and error estimate of the orbit through (a0, v0) for a piecewise-analytic f."""
    scale = _orbit_scale(a0, velocity, omega0)
    working = mpmath.mp.dps
    if velocity == 0:
        direction, reference = _release_direction(potential, epsilon, a0, omega0, scale)
        orbit = _PiecewiseOrbit(potential, epsilon, omega0, reference)
        energy = orbit.value(a0, reference)
        other, other_piece = _piecewise_turning_point(orbit, a0, reference, direction, energy, scale)
        turning = sorted([(a0, reference), (other, other_piece)], key=lambda pair: pair[0])
        with workdps(2 * working):
            energy = orbit.value(a0, reference)
    else:
        left, right = potential.locate(a0)
        reference = right if potential.pieces[right].problem is None else left
        orbit = _PiecewiseOrbit(potential, epsilon, omega0, reference)
        energy = velocity**2 / 2 + orbit.value(a0, reference)
        turning = [
            _piecewise_turning_point(orbit, a0, left, -1, energy, scale),
            _piecewise_turning_point(orbit, a0, right, 1, energy, scale),
        ]
        with workdps(2 * working):
            energy = velocity**2 / 2 + orbit.value(a0, reference)
    (low, low_piece), (high, high_piece) = turning
    cuts = potential.cut_values()
    inner = cuts[low_piece:high_piece]  # the breakpoints strictly inside the orbit
    results = []
    if not inner:
        middle = (low + high) / 2
        results.append(_turning_segment(orbit, low, middle, low_piece, target_digits))
        results.append(_turning_segment(orbit, high, middle, high_piece, target_digits))
    else:
        results.append(_turning_segment(orbit, low, inner[0], low_piece, target_digits))
        for index in range(len(inner) - 1):
            results.append(_inner_segment(orbit, inner[index], inner[index + 1], low_piece + 1 + index, energy, target_digits))
        results.append(_turning_segment(orbit, high, inner[-1], high_piece, target_digits))
    period = 2 * mpmath.fsum(value for value, _ in results)
    error = 2 * mpmath.fsum(error for _, error in results)
    return period, error


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


def _characteristic_epsilon(potential: _Potential, a0: mpmath.mpf, omega0: mpmath.mpf) -> mpmath.mpf:
    """An epsilon scale: omega0**2 over the largest |f(u)/u| on |u| <= 3|a0|/2."""
    amplitude = abs(a0) if a0 != 0 else mpmath.mpf(1)
    largest_ratio = mpmath.mpf(0)
    for fraction in (-3, -2, -1, 1, 2, 3):
        position = amplitude * fraction / 2
        ratio = abs(potential.force(position) / position)
        largest_ratio = max(largest_ratio, ratio)
    if largest_ratio == 0:
        return mpmath.mpf(1)
    return omega0**2 / largest_ratio


def _chebyshev_taylor_coefficients(values: list[mpmath.mpf], radius: mpmath.mpf, order: int) -> list[mpmath.mpf]:
    """Taylor coefficients at 0 of the interpolant through Chebyshev-Lobatto samples.

    ``values[j]`` is the function at ``radius * cos(pi j / n)``, ``j = 0..n``.
    """
    n = len(values) - 1
    chebyshev = []
    for k in range(n + 1):
        total = mpmath.fsum(
            (values[j] / (2 if j in (0, n) else 1)) * mpmath.cospi(mpmath.mpf(j * k) / n) for j in range(n + 1)
        )
        coefficient = 2 * total / n
        if k in (0, n):
            coefficient /= 2
        chebyshev.append(coefficient)
    # Monomial coefficients of T_k(t) by the exact integer recurrence.
    monomials: list[list[int]] = [[1], [0, 1]]
    for k in range(2, n + 1):
        previous, before = monomials[k - 1], monomials[k - 2]
        current = [0] * (k + 1)
        for power, value in enumerate(previous):
            current[power + 1] += 2 * value
        for power, value in enumerate(before):
            current[power] -= value
        monomials.append(current)
    taylor = []
    for power in range(order + 1):
        total = mpmath.fsum(
            chebyshev[k] * monomials[k][power] for k in range(power, n + 1) if monomials[k][power] != 0
        )
        taylor.append(total / radius**power)
    return taylor


def _piecewise_characteristic_epsilon(potential: _PiecewisePotential, scale: mpmath.mpf, omega0: mpmath.mpf) -> mpmath.mpf:
    """An epsilon scale: omega0**2 over the largest |f(u)/u| on |u| <= 3 scale/2 (sampled, both sides of breakpoints)."""
    largest_ratio = mpmath.mpf(0)
    for fraction in (-3, -2, -1, 1, 2, 3):
        position = scale * fraction / 2
        for piece in set(potential.locate(position)):
            if potential.pieces[piece].problem is not None:
                continue
            try:
                ratio = abs(potential.force(piece, position) / position)
            except (ZeroDivisionError, ValueError, TypeError):
                continue
            if mpmath.isfinite(ratio):
                largest_ratio = max(largest_ratio, ratio)
    if largest_ratio == 0:
        return mpmath.mpf(1)
    return omega0**2 / largest_ratio


def _grazing_epsilon(
    potential: _PiecewisePotential, a0: mpmath.mpf, velocity: mpmath.mpf, omega0: mpmath.mpf
) -> mpmath.mpf:
    """Smallest |epsilon| at which a breakpoint c can become a turning point (``V(c) = E``, linear in epsilon).

    ``omega0**2 c**2/2 + epsilon F(c) = v0**2/2 + omega0**2 a0**2/2 + epsilon F(a0)`` gives
    ``epsilon_c = omega0**2 (A**2 - c**2) / (2 (F(c) - F(a0)))``, ``A**2 = a0**2 + v0**2/omega0**2``.
    Raises ProblemError if a turning point of the epsilon = 0 orbit is a breakpoint (grazing: omega is not
    analytic at epsilon = 0).
    """
    amplitude = mpmath.sqrt(a0**2 + (velocity / omega0) ** 2)
    cuts = potential.cut_values()
    for cut in cuts:
        if abs(abs(cut) - amplitude) <= mpmath.eps * 1000 * max(amplitude, 1):
            raise ProblemError(
                f"grazing: the turning point {mpmath.nstr(cut, 15)} of the epsilon = 0 orbit (amplitude "
                f"sqrt(a0**2 + v0**2/omega0**2) = {mpmath.nstr(amplitude, 15)}) is a breakpoint of "
                f"{potential.description}, so omega(epsilon) is not analytic at epsilon = 0 (no Taylor series); "
                "choose the orbit so that no turning point lies on a breakpoint"
            )
    left, right = potential.locate(a0)
    reference = right if potential.pieces[right].problem is None else left
    constants, _ = potential.constants(reference)
    start = constants[reference] + potential.primitive(reference, a0)
    nearest = mpmath.inf
    for index, cut in enumerate(cuts):
        for piece, side in ((index, 1), (index + 1, -1)):
            if constants[piece] is None:
                continue
            primitive = potential.boundary_primitive(piece, side)
            if primitive is None:
                continue
            change = constants[piece] + primitive - start
            if change != 0:
                nearest = min(nearest, abs(omega0**2 * (amplitude**2 - cut**2) / (2 * change)))
            break
    return nearest


@locked
def frequency_taylor_coefficients(
    f: Nonlinearity,
    order: int,
    *,
    a0: Any,
    omega0: Any = 1,
    precision: int = 40,
    velocity: Any = 0,
    breakpoints: Sequence[Any] | None = None,
) -> list[tuple[mpmath.mpf, mpmath.mpf]]:
    """Taylor coefficients ``omega_k`` of the exact frequency ``omega(epsilon)`` at 0.

    ``omega(epsilon) = sum_k omega_k epsilon**k`` for the oscillator
    ``u'' + omega0**2 u + epsilon f(u) = 0``, ``u(0) = a0``, ``u'(0) = velocity``.
    The frequency is sampled (by :func:`conservative_frequency`'s quadrature)
    at the Chebyshev-Lobatto points of a real interval ``[-r, r]`` on which
    the orbit exists, with 33 and 65 points; the Taylor coefficients of the
    65-point interpolant are returned and the difference between the two
    grids, plus a rounding allowance, is the error estimate.  If that estimate
    is not below ``10**(-precision/2)`` relative, ``r`` is reduced.  For a
    piecewise f, ``r`` starts below a quarter of the nearest epsilon at which a
    breakpoint becomes a turning point, so the orbit keeps its pieces on
    ``[-r, r]``; an orbit that escapes at ``+-r`` (a softening spring) also
    reduces ``r``.

    Parameters
    ----------
    f : sympy expression in ``u`` or callable
        The nonlinearity (numeric coefficients), as for :func:`conservative_period`.
    order : int
        Highest Taylor coefficient wanted (0 <= order <= 24).
    a0, omega0 : real numbers
        Initial position and linear frequency (omega0 > 0).
    precision : int, optional
        Working digits of the frequency samples.
    velocity : real number, optional
        Initial velocity (default 0).
    breakpoints : sequence of real numbers, optional
        As for :func:`conservative_period`.

    Returns
    -------
    list of (value, error_estimate)
        ``[(omega_0, err_0), ..., (omega_order, err_order)]`` as mpf.

    Raises
    ------
    ProblemError
        If a turning point of the epsilon = 0 orbit lies on a breakpoint of f
        (grazing: omega is not analytic at epsilon = 0).
    ConvergenceError
        If no interval ``[-r, r]`` gives agreeing interpolants.

    Examples
    --------
    >>> import sympy
    >>> u = sympy.Symbol("u")
    >>> coefficients = frequency_taylor_coefficients(u**3, 2, a0=1, precision=30)
    >>> [mpmath.nstr(value, 12) for value, error in coefficients]  # 1, 3/8, -21/256
    ['1.0', '0.375', '-0.08203125']
    >>> coefficients = frequency_taylor_coefficients(sympy.Max(0, u), 2, a0=1, precision=12)
    >>> [mpmath.nstr(value, 8) for value, error in coefficients]  # 1, 1/4, -1/8 (unilateral spring)
    ['1.0', '0.25', '-0.125']
    """
    order = validate_order(order, maximum=_MAXIMUM_CHEBYSHEV_ORDER)
    precision = validate_precision(precision)
    potential = _make_potential(f, breakpoints)
    fine_nodes = 64  # the coarse grid is every other node (33 points)
    working_dps = precision + 15
    with workdps(working_dps):
        a0_value = real_parameter(a0, "a0")
        omega0_value = omega0_parameter(omega0)
        velocity_value = real_parameter(velocity, "velocity")
        if isinstance(potential, _PiecewisePotential):
            scale = _orbit_scale(a0_value, velocity_value, omega0_value)
            radius = min(
                _piecewise_characteristic_epsilon(potential, scale, omega0_value) / 8,
                _grazing_epsilon(potential, a0_value, velocity_value, omega0_value) / 4,
            )
        elif velocity_value == 0:
            radius = _characteristic_epsilon(potential, a0_value, omega0_value) / 8
        else:
            scale = _orbit_scale(a0_value, velocity_value, omega0_value)
            radius = _characteristic_epsilon(potential, scale, omega0_value) / 8
        last_problem = "no attempt made"
        for _attempt in range(6):
            try:
                samples = []
                for j in range(fine_nodes + 1):
                    epsilon = radius * mpmath.cospi(mpmath.mpf(j) / fine_nodes)
                    period, _ = _period(potential, epsilon, a0_value, omega0_value, working_dps, velocity_value)
                    samples.append(2 * mpmath.pi / period)
            except ConvergenceError as error:
                last_problem = str(error)
                radius /= 4
                continue
            fine = _chebyshev_taylor_coefficients(samples, radius, order)
            coarse = _chebyshev_taylor_coefficients(samples[::2], radius, order)
            magnitude = max(abs(value) for value in samples)
            results = []
            acceptable = True
            for power in range(order + 1):
                rounding = magnitude * mpmath.mpf(10) ** (-working_dps + 3) * fine_nodes**2 / radius**power
                error = abs(fine[power] - coarse[power]) + rounding
                results.append((fine[power], error))
                if error > mpmath.mpf(10) ** (-(precision // 2)) * max(magnitude / radius**power, abs(fine[power])):
                    acceptable = False
            if acceptable:
                return rounded_coefficients(results, precision)
            last_problem = "Chebyshev grids of 33 and 65 points disagree (the interval reaches a singularity)"
            radius /= 4
    raise ConvergenceError(
        f"could not obtain Taylor coefficients of omega(epsilon) for {potential.description}: {last_problem}; "
        "check that a periodic orbit exists for small |epsilon|"
    )
