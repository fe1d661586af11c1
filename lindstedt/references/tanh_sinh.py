"""Period of a conservative oscillator with a piecewise-analytic f by tanh-sinh quadrature piece by piece.

Equation implemented::

    u'' + omega0**2 u + epsilon f(u) = 0,    u(0) = a0,   u'(0) = v0,

    T = 2 integral_{b_-}^{b_+} du / sqrt(2 (E - V(u))),

with ``V`` joined continuously across the breakpoints of f (:mod:`.breakpoints`).  The turning points are
found piece by piece (a scan that stops at each breakpoint, then a safeguarded Newton iteration inside one
piece, where V is analytic).  The orbit ``[b_-, b_+]`` is cut at the breakpoints inside it and each
segment is integrated by tanh-sinh quadrature (``mpmath.quad``, double-exponentially convergent despite
the algebraic endpoint singularities of ``V`` at the breakpoints).  On a segment ``[p, b]`` ending at a
turning point ``b`` the square-root singularity is removed by ``u = b - (b - p) s**2``:

    integral_p^b du / sqrt(2 (V(b) - V(u))) = integral_0^1 2 |b - p| / sqrt(2 D(s)/s**2) ds,

``D(s) = V(b) - V(u)``, analytic in s at ``s = 0``; ``D`` is formed as
``omega0**2 (b - u)(b + u)/2 + epsilon (G_k(b) - G_k(u))`` in twice the working precision (and replaced by
its linearisation ``V'(b)(b - u)`` where ``s**2`` is below the working epsilon), so that the cancellation
near the turning point costs no digits.  An orbit inside one piece is cut at its middle.  The error
estimate is the sum of the tanh-sinh error estimates.  A non-integrable singularity of f or a region
where f is not real may not be reached by the orbit.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import mpmath

from .._errors import ConvergenceError, ProblemError, UnsupportedNonlinearityError
from .._precision import workdps
from .breakpoints import _SUPPORTED, _PiecewisePotential
from .trapezoid import _escape_distances, _orbit_scale, _separatrix_error, _turning_distance


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
    distance = _turning_distance(lambda d: energy - orbit.value(start + direction * d, piece),
                                 lambda d: -direction * orbit.slope(start + direction * d, piece), bracket,
                                 mpmath.eps * 8 * max(scale, abs(start)), mpmath.mp.prec + 100)
    return start + direction * distance, piece


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
