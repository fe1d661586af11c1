"""Exact period of a general smooth conservative oscillator by quadrature.

Equation implemented::

    u'' + omega0**2 u + epsilon f(u) = 0,    u(0) = a0,   u'(0) = 0.

The motion conserves the energy ``u'**2/2 + V(u)`` with the potential
``V(u) = omega0**2 u**2 / 2 + epsilon F(u)``, ``F' = f``, ``F(0) = 0``.  The
release point ``a0`` is a turning point; the orbit runs (down the slope of
``V``) to the first other point ``b`` with ``V(b) = V(a0)`` and back, so the
period is

    T = 2 |integral_b^a0 du / sqrt(2 (V(a0) - V(u)))|.

No Lindstedt-Poincare machinery is involved.  The inverse-square-root endpoint
singularities are removed by ``u = mid + half sin(theta)`` with
``mid = (a0 + b)/2``, ``half = (a0 - b)/2``: since ``V(a0) - V(u)`` has simple
zeros at both ends, ``R(theta) = (V(a0) - V(u))/cos(theta)**2`` is smooth and
positive, and

    T = integral_0^{2 pi} half / sqrt(2 R(theta)) d theta

is the integral of a smooth *periodic* function over a full period (the
integrand is symmetric about ``theta = pi/2``).  The trapezoidal rule is then
geometrically convergent; the number of nodes is doubled until two successive
results agree, which also gives the error estimate.

Taylor coefficients of the angular frequency ``omega(epsilon) = 2 pi / T`` at
``epsilon = 0`` are obtained from a Chebyshev interpolant of ``omega`` on a
small real interval ``[-r, r]`` (two nested grids give the error estimate).
"""

from __future__ import annotations

from fractions import Fraction
from numbers import Number
from typing import Any, Callable, Union

import mpmath
import sympy

from .._errors import ConvergenceError, OrderError, ParameterError, ProblemError
from ..problems.parsing import parse_real

__all__ = [
    "conservative_period",
    "conservative_frequency",
    "frequency_taylor_coefficients",
    "as_mpmath_number",
]

Nonlinearity = Union[sympy.Expr, Callable[[Any], Any]]

_MAXIMUM_TRAPEZOID_NODES = 2**13
_INITIAL_TRAPEZOID_NODES = 16
_MAXIMUM_CHEBYSHEV_ORDER = 24
# An angular offset that is not a dyadic fraction of 2 pi, so that no node of
# any power-of-two trapezoid grid falls on the turning points theta = +-pi/2.
_NODE_OFFSET_FRACTION = Fraction(1, 7)


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
    with mpmath.workdps(precision):
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

    def excess(position: mpmath.mpf) -> mpmath.mpf:
        return energy - potential.value(position, epsilon, omega0)

    # Scan in steps of |a0|/16 up to 4|a0| from the release point, then in geometric steps
    # (factor 5/4) up to 1e12 |a0|; the first sign change of V(a0) - V(u) brackets b.
    distances = [scale * k / 16 for k in range(1, 65)]
    distance = distances[-1]
    while distance < scale * mpmath.mpf(10) ** 12:
        distance *= mpmath.mpf(5) / 4
        distances.append(distance)
    previous = mpmath.mpf(0)
    for current in distances:
        if excess(a0 + direction * current) <= 0:
            break
        previous = current
    else:
        raise ConvergenceError(
            f"no second turning point: with epsilon = {mpmath.nstr(epsilon, 15)} and {potential.description}, "
            f"the potential V(u) never climbs back to the release energy V(a0) on the side "
            "the orbit moves to, so the orbit escapes; reduce |epsilon| or |a0|"
        )
    # Safeguarded Newton on the bracket [previous, current] of distances.
    low, high = previous, current
    guess = high
    tolerance = mpmath.eps * 8 * max(scale, abs(a0))
    for _ in range(400):
        position = a0 + direction * guess
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
        raise ConvergenceError("root finding for the second turning point did not converge")
    return a0 + direction * guess


def _period_by_trapezoid(
    potential: _Potential,
    epsilon: mpmath.mpf,
    a0: mpmath.mpf,
    omega0: mpmath.mpf,
    target_digits: int,
) -> tuple[mpmath.mpf, mpmath.mpf]:
    """Period and error estimate at the current working precision."""
    other_turning_point = _find_other_turning_point(potential, epsilon, a0, omega0)
    middle = (a0 + other_turning_point) / 2
    half_width = (a0 - other_turning_point) / 2
    energy = potential.value(a0, epsilon, omega0)
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
        "separatrix (the second turning point is nearly an equilibrium); reduce |epsilon| or |a0|"
    )


def _period(
    potential: _Potential,
    epsilon: Any,
    a0: Any,
    omega0: Any,
    precision: int,
) -> tuple[mpmath.mpf, mpmath.mpf]:
    """Period and error at ``precision`` digits (computed with guard digits)."""
    with mpmath.workdps(precision + 20):
        epsilon_value = real_parameter(epsilon, "epsilon")
        a0_value = real_parameter(a0, "a0")
        omega0_value = omega0_parameter(omega0)
        period, difference = _period_by_trapezoid(potential, epsilon_value, a0_value, omega0_value, precision + 5)
        error = difference + abs(period) * mpmath.mpf(10) ** (-precision)
    with mpmath.workdps(precision):
        return +period, +error


def conservative_period(
    f: Nonlinearity,
    epsilon: Any,
    *,
    a0: Any,
    omega0: Any = 1,
    precision: int = 30,
) -> tuple[mpmath.mpf, mpmath.mpf]:
    """Exact period of ``u'' + omega0**2 u + epsilon f(u) = 0``, ``u(0) = a0``, ``u'(0) = 0``.

    Parameters
    ----------
    f : sympy expression in the symbol ``u`` or callable
        The nonlinearity, with numeric coefficients only; a callable receives
        and returns mpmath numbers.
    epsilon : real number
        The small parameter (int, float, Fraction, sympy number, string, mpf).
    a0 : real number
        Release position (the motion starts at rest).
    omega0 : positive real number, optional
        Linear angular frequency.
    precision : int, optional
        Decimal digits of the result.

    Returns
    -------
    (period, error_estimate) : tuple of mpf
        The error estimate is the last trapezoid refinement difference plus a
        rounding allowance of one unit in the ``precision``-th digit.

    Raises
    ------
    ConvergenceError
        If the orbit escapes (no second turning point) or sits on a separatrix.
    ProblemError
        If a0 is an equilibrium or the inputs are invalid.

    Examples
    --------
    >>> import sympy
    >>> u = sympy.Symbol("u")
    >>> period, error = conservative_period(u**3, 0, a0=1, precision=20)
    >>> mpmath.nstr(period, 20)  # 2 pi
    '6.2831853071795864769'
    >>> error < 1e-18
    True
    """
    precision = validate_precision(precision)
    potential = _Potential(f)
    return _period(potential, epsilon, a0, omega0, precision)


def conservative_frequency(
    f: Nonlinearity,
    epsilon: Any,
    *,
    a0: Any,
    omega0: Any = 1,
    precision: int = 30,
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
    potential = _Potential(f)
    with mpmath.workdps(precision + 10):
        period, period_error = _period(potential, epsilon, a0, omega0, precision + 10)
        frequency = 2 * mpmath.pi / period
        error = frequency * period_error / period + abs(frequency) * mpmath.mpf(10) ** (-precision)
    with mpmath.workdps(precision):
        return +frequency, +error


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


def frequency_taylor_coefficients(
    f: Nonlinearity,
    order: int,
    *,
    a0: Any,
    omega0: Any = 1,
    precision: int = 40,
) -> list[tuple[mpmath.mpf, mpmath.mpf]]:
    """Taylor coefficients ``omega_k`` of the exact frequency ``omega(epsilon)`` at 0.

    ``omega(epsilon) = sum_k omega_k epsilon**k`` for the oscillator
    ``u'' + omega0**2 u + epsilon f(u) = 0``, ``u(0) = a0``, ``u'(0) = 0``.
    The frequency is sampled (by :func:`conservative_frequency`'s quadrature)
    at the Chebyshev-Lobatto points of a real interval ``[-r, r]`` on which
    the orbit exists, with 33 and 65 points; the Taylor coefficients of the
    65-point interpolant are returned and the difference between the two
    grids, plus a rounding allowance, is the error estimate.  If that estimate
    is not below ``10**(-precision/2)`` relative, ``r`` is reduced.

    Parameters
    ----------
    f : sympy expression in ``u`` or callable
        The nonlinearity (numeric coefficients).
    order : int
        Highest Taylor coefficient wanted (0 <= order <= 24).
    a0, omega0 : real numbers
        Release position and linear frequency (omega0 > 0).
    precision : int, optional
        Working digits of the frequency samples.

    Returns
    -------
    list of (value, error_estimate)
        ``[(omega_0, err_0), ..., (omega_order, err_order)]`` as mpf.

    Examples
    --------
    >>> import sympy
    >>> u = sympy.Symbol("u")
    >>> coefficients = frequency_taylor_coefficients(u**3, 2, a0=1, precision=30)
    >>> [mpmath.nstr(value, 12) for value, error in coefficients]  # 1, 3/8, -21/256
    ['1.0', '0.375', '-0.08203125']
    """
    order = validate_order(order, maximum=_MAXIMUM_CHEBYSHEV_ORDER)
    precision = validate_precision(precision)
    potential = _Potential(f)
    fine_nodes = 64  # the coarse grid is every other node (33 points)
    working_dps = precision + 15
    with mpmath.workdps(working_dps):
        a0_value = real_parameter(a0, "a0")
        omega0_value = omega0_parameter(omega0)
        radius = _characteristic_epsilon(potential, a0_value, omega0_value) / 8
        last_problem = "no attempt made"
        for _attempt in range(6):
            try:
                samples = []
                for j in range(fine_nodes + 1):
                    epsilon = radius * mpmath.cospi(mpmath.mpf(j) / fine_nodes)
                    period, _ = _period(potential, epsilon, a0_value, omega0_value, working_dps)
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

