"""Period of a conservative oscillator with an analytic f by the periodic trapezoidal rule.

Equation implemented::

    u'' + omega0**2 u + epsilon f(u) = 0,    u(0) = a0,   u'(0) = v0,

    T = 2 integral_{b_-}^{b_+} du / sqrt(2 (E - V(u))),   V(u) = omega0**2 u**2/2 + epsilon F(u),  F' = f,

for an f analytic on the orbit (a sympy expression without switching functions, or a callable given
without breakpoints).  The turning points ``b_- <= a0 <= b_+`` (``V(b) = E = v0**2/2 + V(a0)``; for
``v0 = 0`` the release point ``a0`` is one of them) are bracketed by a scan and found by a safeguarded
Newton iteration.  The inverse-square-root endpoint singularities are removed by ``u = mid + half
sin(theta)``, ``mid = (b_+ + b_-)/2``, ``half = (b_+ - b_-)/2``: since ``E - V(u)`` has simple zeros at
both ends, ``R(theta) = (E - V(u))/cos(theta)**2`` is smooth and positive, and

    T = integral_0^{2 pi} half / sqrt(2 R(theta)) d theta

is the integral of a smooth *periodic* function over a full period.  The trapezoidal rule is then
geometrically convergent; the number of nodes is doubled until two successive results agree, which also
gives the error estimate.
"""

from __future__ import annotations

from fractions import Fraction
from typing import Any

import mpmath
import sympy

from .._errors import ConvergenceError, ProblemError
from .arguments import Nonlinearity, _checked_expression

_MAXIMUM_TRAPEZOID_NODES = 2**13
_INITIAL_TRAPEZOID_NODES = 16
# An angular offset that is not a dyadic fraction of 2 pi, so that no node of
# any power-of-two trapezoid grid falls on the turning points theta = +-pi/2.
_NODE_OFFSET_FRACTION = Fraction(1, 7)


class _Potential:
    """``V(u) = omega0**2 u**2/2 + epsilon F(u)`` and its slope, from f."""

    def __init__(self, nonlinearity: Nonlinearity) -> None:
        if isinstance(nonlinearity, sympy.Basic):
            expression, variable = _checked_expression(nonlinearity)
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
    distance = _turning_distance(lambda d: excess(origin + direction * d),
                                 lambda d: -direction * potential.slope(origin + direction * d, epsilon, omega0),
                                 (previous, current), mpmath.eps * 8 * max(scale, abs(origin)), 400)
    return origin + direction * distance


def _turning_distance(excess: Any, slope: Any, bracket: tuple[mpmath.mpf, mpmath.mpf], tolerance: mpmath.mpf,
                      max_iterations: int) -> mpmath.mpf:
    """The distance d in ``bracket`` where ``excess(d) = E − V`` vanishes (positive before it), by safeguarded
    Newton with the derivative ``slope(d)``: a step leaving the bracket is a bisection (V analytic inside)."""
    low, high = bracket
    guess = high
    for _ in range(max_iterations):
        value = excess(guess)
        if value == 0:
            break
        if value > 0:
            low = guess
        else:
            high = guess
        derivative = slope(guess)
        candidate = guess - value / derivative if derivative != 0 else low - 1
        if not low <= candidate <= high:
            candidate = (low + high) / 2
        change = abs(candidate - guess)
        guess = candidate
        if change <= tolerance or high - low <= tolerance:
            break
    else:
        raise ConvergenceError("root finding for a turning point did not converge")
    return guess


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


def _separatrix_error() -> ConvergenceError:
    """The error of an orbit whose energy integrand vanishes inside it (both quadratures raise it)."""
    return ConvergenceError(
        "the energy integrand vanished inside the orbit: the orbit is at (or numerically "
        "indistinguishable from) a separatrix; move epsilon or a0 away from it"
    )


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
            raise _separatrix_error()
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
