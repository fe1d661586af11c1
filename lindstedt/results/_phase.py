"""The phase and turning-point series of an expansion from general initial data u(0) = u0, u'(0) = v0.

The expansion is released at rest at the orbit's positive turning point ``A(ε) = Σ_k A_k gauge^k``
(:attr:`lindstedt.Expansion.amplitude`), and ``u(t) = v(ω t + φ(ε); ε)`` with the exact phase series
``φ(ε) = Σ_k φ_k gauge^k`` (:attr:`lindstedt.Expansion.phase`): ``v(φ; ε) = u0`` with the sign of
``u'(0) = ω v_s(φ) = v0``, solved order by order from the Taylor expansion of the waveforms v_k at φ_0.

Functions of an :class:`~lindstedt.Expansion`, typed ``Any``: :mod:`lindstedt.results.expansion` imports this
module, never the other way round.
"""

from __future__ import annotations

import math
from typing import Any, Callable

import mpmath
import sympy

from .._errors import UnsupportedNonlinearityError
from .._precision import workdps
from ..problems.oscillator import Oscillator, _decided_sign, reduce_quadratic
from .waveforms import STRAINED_TIME, Waveform

__all__ = ["amplitude_series", "phase_series"]


def amplitude_series(expansion: Any) -> tuple[sympy.Expr, ...]:
    """A_0 … A_N of :attr:`lindstedt.Expansion.amplitude` (indexed by the powers of the gauge)."""
    highest = expansion._steps * expansion.order
    if expansion.problem.normalization == "harmonic":
        return tuple(expansion.waveform(k).value_at_zero() for k in range(highest + 1))
    series = expansion.problem.amplitude_series(expansion.order)
    values = [sympy.Integer(0)] * (highest + 1)
    for k, value in enumerate(series):
        values[expansion._steps * k] = value
    return tuple(values)


def phase_series(expansion: Any) -> tuple[sympy.Expr, ...]:
    """φ_0 … φ_N of :attr:`lindstedt.Expansion.phase` (zeros for a release at rest)."""
    highest = expansion._steps * expansion.order
    if not expansion.problem.has_initial_velocity:
        return tuple(sympy.Integer(0) for _ in range(highest + 1))
    return _phase_coefficients(expansion, highest)


def _series_power(coefficients: list[sympy.Expr], power: int, order: int) -> sympy.Expr:
    """The x^order coefficient of (Σ_{k≥1} coefficients[k] x^k)^power (coefficients[0] is ignored; missing ones
    are zero: for power ≥ 2 the x^order coefficient does not involve coefficients[order])."""
    coefficients = list(coefficients) + [sympy.Integer(0)] * (order + 1 - len(coefficients))
    table = [sympy.Integer(1)] + [sympy.Integer(0)] * order
    for _ in range(power):
        table = [sympy.Add(*[coefficients[k] * table[j - k] for k in range(1, j + 1) if table[j - k] != 0]) for j in range(order + 1)]
    return table[order]


def _at_angle(expression: sympy.Expr, cosine: sympy.Expr, sine: sympy.Expr, angle: sympy.Expr) -> sympy.Expr:
    """An expression in s (polynomial in s, cos(n s), sin(n s)) at s = angle, with cos angle, sin angle given exactly."""
    s = STRAINED_TIME
    if any(atom.args[0] != s for atom in expression.atoms(sympy.cos, sympy.sin) if atom.has(s)):
        expression = sympy.expand_trig(expression)
    return expression.xreplace({sympy.cos(s): cosine, sympy.sin(s): sine}).xreplace({s: angle})


def _tidy(value: sympy.Expr, angle: sympy.Expr) -> sympy.Expr:
    """A phase coefficient as a polynomial in the angle ψ0 (float hierarchies: evaluated)."""
    if value.has(sympy.Float):
        return value.evalf()
    if value.free_symbols:  # symbolic ω0 or parameters: one rational function (the angle is one of its generators)
        return sympy.cancel(value)
    return sympy.collect(sympy.expand(value), angle)


def _phase_coefficients(expansion: Any, highest: int) -> tuple[sympy.Expr, ...]:
    """φ_0 … φ_highest of the orbit through (u0, v0), v0 ≠ 0 (see :attr:`Expansion.phase`)."""
    problem = expansion.problem
    start, speed, omega0, amplitude = problem.u0, abs(problem.v0), problem.omega0, problem.a0
    sign = -1 if problem.v0 > 0 else 1  # φ = ∓ψ: v0 > 0 means the orbit is before its positive turning point
    angle = sympy.atan2(speed / omega0, start)  # ψ0 in (0, π)
    # Symbolic ω0 or parameters: compute in K(a), a = A0 (a² = u0² + v0²/ω0²), so that no radicals pile up.
    to_field, reduce, output = _quadratic_field(problem) if problem.free_symbols else (None, None, None)
    a = amplitude if to_field is None else to_field(amplitude)
    cosine, sine = start / a, speed / (omega0 * a)  # cos ψ0, sin ψ0 > 0
    piece = 0
    arc_derivative: Callable[[int, int], sympy.Expr] | None = None  # v_k^{(m)}(ψ0) when ψ0 is on a stretched arc
    if expansion.is_piecewise:
        for index, boundary in enumerate(expansion._form.boundaries):  # by increasing angle, i.e. decreasing κ
            side = _decided_sign(sympy.simplify(boundary.kappa - cosine), "u0 against a breakpoint")
            if side == 0:  # u0 on a crossed breakpoint: ψ(ε) is the moving contact angle s*(ε)
                shifts = [expansion.contact_angle_correction(k)[index] for k in range(1, highest + 1)]
                return tuple(sign * value for value in (expansion.contact_angles[index], *shifts))
            piece += side > 0
        arcs = expansion._form.system.arcs
        last = len(expansion._form.boundaries)
        if (piece == 0 and arcs[0] is not None) or (piece == last and arcs[1] is not None):
            # u0 on a stretched contact arc: inside it the fixed-s expansion exists, numerically
            arc = next(item for item in expansion.stretched_arcs if item.side == ("release" if piece == 0 else "far"))
            if problem.free_symbols:
                raise UnsupportedNonlinearityError("an orbit that starts on a stretched contact arc needs numeric omega0 and parameters")
            with workdps(arc.digits + 10):
                numeric_angle = mpmath.mpf(sympy.N(angle, arc.digits + 10))

            def on_arc(k: int, m: int) -> sympy.Expr:
                scale = amplitude * omega0 ** (-2 * k)  # v_k = a0 ω0^{-2k} [ε̂^k] W
                return scale * sympy.Float(arc.fixed_s_derivative(numeric_angle, k, m), arc.digits)

            arc_derivative = on_arc
    waveforms: dict[int, Any] = {}
    derivatives: dict[tuple[int, int], sympy.Expr] = {}

    def derivative(k: int, m: int) -> sympy.Expr:
        """v_k^{(m)}(ψ0), exact (the branch of the piece containing ψ0 for piecewise f; numeric on a stretched arc)."""
        if (k, m) not in derivatives and arc_derivative is not None:
            derivatives[k, m] = arc_derivative(k, m)
        if (k, m) not in derivatives:
            if k not in waveforms:
                waveforms[k] = expansion.waveform(k)
            waveform = waveforms[k]
            if isinstance(waveform, Waveform):
                total = sympy.Integer(0)
                for harmonic, value in waveform.coefficients:
                    value = value if to_field is None else to_field(value)
                    cos_n = sympy.chebyshevt(harmonic, cosine)
                    sin_n = sine * sympy.chebyshevu(harmonic - 1, cosine) if harmonic else sympy.Integer(0)
                    trig = (cos_n, -sin_n, -cos_n, sin_n)[m % 4]
                    total += value * harmonic**m * trig
            else:
                branch = sympy.diff(waveform.branches[piece], STRAINED_TIME, m)
                if to_field is not None:
                    branch = to_field(branch)
                total = _at_angle(branch, cosine, sine, angle)
            derivatives[k, m] = reduce(total) if reduce is not None else total
        return derivatives[k, m]

    psi: list[sympy.Expr] = [angle]
    slope = -speed / omega0  # v_0'(ψ0) = −A0 sin ψ0
    for n in range(1, highest + 1):
        total = derivative(n, 0)
        for k in range(0, n):
            for m in range(1, n - k + 1):
                if k == 0 and m == 1:
                    continue  # the unknown ψ_n
                power = _series_power(psi, m, n - k)
                if power != 0:
                    total += derivative(k, m) * power / math.factorial(m)
        psi.append(_tidy(-total / slope, angle) if reduce is None else reduce(-total / slope))
    if output is not None:
        psi = [output(value) for value in psi]
    return tuple(sign * value for value in psi)


def _quadratic_field(problem: Oscillator) -> tuple[Callable, Callable, Callable] | tuple[None, None, None]:
    """(to_field, reduce, output) for arithmetic in K(a), a = A0 = (u0² + v0²/ω0²)^{1/2} of a symbolic problem:
    ``to_field`` writes the half-integer powers of A0's radicand through a, ``reduce`` gives the canonical
    P + Q a, ``output`` puts A0 back.  (None, None, None) when A0 is not one square root times a rational factor."""
    amplitude = problem.a0
    roots = [atom for atom in amplitude.atoms(sympy.Pow) if atom.exp == sympy.Rational(1, 2)]
    if len(roots) != 1:
        return None, None, None
    base = roots[0].base
    factor = sympy.cancel(amplitude / roots[0])  # A0 = sqrt(base)·factor
    if factor.has(base):
        return None, None, None
    generator = sympy.Dummy("A0", positive=True)
    square = sympy.expand(problem.u0**2 + problem.v0**2 / problem.omega0**2)

    def to_field(expression: sympy.Expr) -> sympy.Expr:
        powers = {
            atom: (generator / factor) ** int(2 * atom.exp)
            for atom in expression.atoms(sympy.Pow)
            if atom.base == base and (2 * atom.exp).is_Integer and not atom.exp.is_Integer
        }
        return expression.xreplace(powers) if powers else expression

    def reduce(expression: sympy.Expr) -> sympy.Expr:
        return reduce_quadratic(expression, generator, square)

    def output(expression: sympy.Expr) -> sympy.Expr:
        return expression.xreplace({generator: amplitude})

    return to_field, reduce, output
