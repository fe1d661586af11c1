"""Breakpoints of a piecewise-analytic f and its antiderivative piece by piece: the potential V.

Equation implemented::

    V(u) = omega0**2 u**2/2 + epsilon F(u),    F = K_k + G_k  on the k-th piece,  G_k' = f_k,

for f written with ``Max``, ``Min``, ``Abs``, ``Heaviside``, ``sign``, ``Piecewise`` and real powers
``p`` of such pieces (e.g. the Hertz contact ``Max(0, u)**(3/2)``).  The real line is cut at the
*breakpoints*: the zeros of the switching arguments (each must be linear in u, ``alpha u + beta``, once
the switches inside it are resolved; anything else — e.g. ``sign(sin(1/u))`` with infinitely many
switches — is refused), and the real zeros of the polynomial base of a non-integer or negative power
(and of the argument of a logarithm).  Between consecutive breakpoints every switch has a fixed branch,
so f is one analytic expression ``f_k`` there; its antiderivative ``G_k`` is found by sympy (numerically
by quadrature where sympy cannot) and the pieces are joined continuously by the constants ``K_k``
(``F`` is continuous also where ``f`` jumps).  A piece behind a non-integrable singularity of f
(``|u - c|**p``, ``p <= -1``) or where f is not real is marked as unreachable, with the reason.
"""

from __future__ import annotations

import bisect
import functools
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import mpmath
import sympy
from sympy.functions.elementary.integers import RoundFunction

from .._errors import ProblemError, UnsupportedNonlinearityError
from ..problems.parsing import parse_expression, parse_real
from .arguments import real_parameter

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
