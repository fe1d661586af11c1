r"""Piecewise quasi-trigonometric calculus on [0, pi] and the even periodic solve.

An even 2*pi-periodic function ``g`` is represented by its restriction to ``[0, pi]``:
breakpoints ``0 = s_0 < s_1 < ... < s_n = pi`` (exact, possibly symbolic such as
``beta = acos(kappa)``) and, on each piece, a finite *quasi-trigonometric polynomial*

.. math::

    g(s) = \sum_{m, j} a_{m j}\, s^m \cos(j s) + b_{m j}\, s^m \sin(j s),

with exact sympy coefficients.  The algebra is closed under sums, products
(product-to-sum), derivatives and antiderivatives (implemented by recursion on
``m``; no ``sympy.integrate``), which gives exact definite integrals and exact
cosine Fourier coefficients ``(2/pi) int_0^pi g(s) cos(k s) ds`` (``1/pi`` for ``k = 0``).

The central operation is the **even periodic solve** of

.. math::

    \alpha_0 \,(v'' + v) = R(s), \qquad v \in C^1, \quad v'(0) = v'(\pi) = 0,

for a piecewise quasi-trigonometric ``R`` whose ``cos s`` coefficient vanishes
(the non-secularity condition of the Lindstedt-Poincare method).  On each piece a
particular solution is found by undetermined coefficients (the resonant forcing
``s^m cos s``, ``s^m sin s`` raises the polynomial degree by one), ``A_i cos s + B_i sin s``
is added, and the C^1 matching conditions are solved exactly by a marching
recursion.  The free ``cos s`` component is fixed by ``v(0)`` or by a zero first
harmonic.

Values at breakpoints are canonicalised by ``expand_trig`` + ``expand``, so that e.g.
``cos(3 acos(kappa))`` becomes ``4 kappa**3 - 3 kappa`` and identities cancel exactly.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Callable, Iterable, Mapping, Sequence, Union

import numpy as np
import sympy

from ._errors import ProblemError, ResonanceError

__all__ = [
    "S",
    "QuasiTrigPolynomial",
    "PiecewiseQuasiTrig",
    "solve_even_periodic",
    "contact_ramp_function",
    "contact_step_function",
]

#: Default independent variable (strained time) used when converting to and from expressions.
S = sympy.Symbol("s", real=True)

TermKey = tuple[int, str, sympy.Expr]
Scalar = Union[int, float, sympy.Expr]
_COS = "cos"
_SIN = "sin"


# ---------------------------------------------------------------------------
# exact canonical forms and decisions
# ---------------------------------------------------------------------------


def _canonical(expr: Scalar) -> sympy.Expr:
    """Canonical exact form: trig of integer multiples expanded, then fully expanded."""
    value = sympy.sympify(expr, strict=True)
    if value.has(sympy.sin, sympy.cos):
        value = sympy.expand_trig(value)
    return sympy.expand(value)


def _is_zero(expr: Scalar) -> bool | None:
    """Decide whether an exact expression vanishes: True, False, or None if undecided.

    A closed number is zero when it vanishes after canonicalisation, or when, at 60
    significant digits, it is below 1e-45 times the sum of the magnitudes of its terms
    (a cancellation that exact nonzero data of moderate size does not produce).
    Symbolic expressions use ``simplify`` and then ``equals``.
    """
    value = _canonical(expr)
    if value == 0:
        return True
    if value.is_number:
        numeric = complex(sympy.N(value, 60))
        scale = sum(abs(complex(sympy.N(term, 30))) for term in sympy.Add.make_args(value))
        return abs(numeric) <= 1e-45 * scale
    if sympy.simplify(value) == 0:
        return True
    return value.equals(0)


def _decide_less(left: sympy.Expr, right: sympy.Expr) -> bool | None:
    relation = sympy.Lt(left, right)
    if relation == sympy.true:
        return True
    if relation == sympy.false:
        return False
    return None


def _same_point(left: sympy.Expr, right: sympy.Expr) -> bool | None:
    if left == right:
        return True
    return _is_zero(left - right)


def _as_scalar(value: Scalar, name: str) -> sympy.Expr:
    try:
        expr = sympy.sympify(value, strict=True)
    except (sympy.SympifyError, TypeError) as exc:
        raise ProblemError(f"{name}={value!r} is not a number or sympy expression") from exc
    if not isinstance(expr, sympy.Expr):
        raise ProblemError(f"{name}={value!r} is not a scalar expression")
    return expr


def _as_frequency(frequency: Scalar) -> sympy.Expr:
    value = sympy.sympify(frequency, strict=True)
    if value.is_number and not value.is_Integer:
        raise ProblemError(f"frequency {frequency!r} is not an integer; quasi-trig terms use cos(j s), sin(j s) with integer j")
    return value


# ---------------------------------------------------------------------------
# one piece: quasi-trigonometric polynomial
# ---------------------------------------------------------------------------


def _sort_key(key: TermKey) -> tuple:
    power, kind, frequency = key
    return (power, kind, sympy.default_sort_key(frequency))


def _normalize_key(power: int, kind: str, frequency: sympy.Expr, coefficient: sympy.Expr) -> tuple[TermKey, sympy.Expr] | None:
    """Fold negative frequencies and drop ``sin(0 s)``; returns None for a vanishing term."""
    if frequency == 0:
        if kind == _SIN:
            return None
        return (power, _COS, sympy.Integer(0)), coefficient
    if frequency.could_extract_minus_sign():
        frequency = -frequency
        if kind == _SIN:
            coefficient = -coefficient
    return (power, kind, frequency), coefficient


def _accumulate(target: dict, key: TermKey, coefficient: sympy.Expr) -> None:
    normalized = _normalize_key(key[0], key[1], sympy.sympify(key[2], strict=True), sympy.sympify(coefficient, strict=True))
    if normalized is None:
        return
    normalized_key, value = normalized
    target[normalized_key] = target.get(normalized_key, sympy.Integer(0)) + value


@dataclass(frozen=True)
class QuasiTrigPolynomial:
    """Finite sum of ``coefficient * s**power * cos(frequency*s)`` / ``sin(frequency*s)`` terms.

    Build it with :meth:`from_expr` or :meth:`from_terms`; the constructor expects
    the canonical ``terms`` tuple of ``((power, kind, frequency), coefficient)``
    pairs (``kind`` is ``"cos"`` or ``"sin"``), sorted and without zero coefficients.

    Attributes
    ----------
    terms : tuple
        ``((power, kind, frequency), coefficient)`` pairs with exact sympy coefficients.

    Examples
    --------
    >>> import sympy
    >>> p = QuasiTrigPolynomial.from_expr(S * sympy.cos(2 * S) + 3, S)
    >>> p.derivative().to_expr(S)
    -2*s*sin(2*s) + cos(2*s)
    >>> (p * p).to_expr(S)
    s**2*cos(4*s)/2 + s**2/2 + 6*s*cos(2*s) + 9
    """

    terms: tuple[tuple[TermKey, sympy.Expr], ...] = ()

    # -- construction -----------------------------------------------------

    @classmethod
    def from_terms(cls, mapping: Mapping[TermKey, Scalar] | Iterable[tuple[TermKey, Scalar]]) -> "QuasiTrigPolynomial":
        """Build from ``{(power, kind, frequency): coefficient}`` (terms are normalised and merged).

        Parameters
        ----------
        mapping : mapping or iterable of pairs
            Keys ``(power, kind, frequency)`` with ``power >= 0`` int, ``kind`` in
            ``{"cos", "sin"}``, integer (or symbolic) ``frequency``.

        Returns
        -------
        QuasiTrigPolynomial

        Examples
        --------
        >>> QuasiTrigPolynomial.from_terms({(1, "sin", -2): 3}).to_expr(S)
        -3*s*sin(2*s)
        """
        items = mapping.items() if isinstance(mapping, Mapping) else mapping
        accumulated: dict = {}
        for key, coefficient in items:
            power, kind, frequency = key
            if isinstance(power, bool) or not isinstance(power, (int, np.integer)) or power < 0:
                raise ProblemError(f"power {power!r} must be a non-negative int")
            if kind not in (_COS, _SIN):
                raise ProblemError(f"kind {kind!r} must be 'cos' or 'sin'")
            _accumulate(accumulated, (int(power), kind, _as_frequency(frequency)), _as_scalar(coefficient, "coefficient"))
        return cls._from_accumulated(accumulated)

    @classmethod
    def _from_accumulated(cls, accumulated: dict) -> "QuasiTrigPolynomial":
        cleaned = []
        for key, coefficient in accumulated.items():
            value = sympy.expand(coefficient)
            if value != 0:
                cleaned.append((key, value))
        cleaned.sort(key=lambda item: _sort_key(item[0]))
        return cls(tuple(cleaned))

    @classmethod
    def constant(cls, value: Scalar) -> "QuasiTrigPolynomial":
        """The constant function ``value``.

        Examples
        --------
        >>> QuasiTrigPolynomial.constant(2).to_expr(S)
        2
        """
        return cls.from_terms({(0, _COS, 0): value})

    @classmethod
    def from_expr(cls, expr: Scalar, variable: sympy.Symbol = S) -> "QuasiTrigPolynomial":
        """Parse a sympy expression built from ``s**m``, ``cos(j s)``, ``sin(j s)`` and constants.

        Products and integer powers of cosines and sines are reduced by product-to-sum.

        Parameters
        ----------
        expr : sympy expression
            Polynomial in ``variable``, ``cos(j*variable)``, ``sin(j*variable)`` (integer ``j``).
        variable : sympy.Symbol, optional
            The independent variable (default :data:`S`).

        Returns
        -------
        QuasiTrigPolynomial

        Raises
        ------
        ProblemError
            If a factor is not of the supported form.

        Examples
        --------
        >>> import sympy
        >>> QuasiTrigPolynomial.from_expr(sympy.cos(S)**2, S).to_expr(S)
        cos(2*s)/2 + 1/2
        """
        total = cls()
        for term in sympy.Add.make_args(sympy.expand(sympy.sympify(expr, strict=True))):
            product = cls.constant(1)
            coefficient = sympy.Integer(1)
            for factor in sympy.Mul.make_args(term):
                if not factor.has(variable):
                    coefficient *= factor
                    continue
                base, exponent = factor.as_base_exp()
                if not (exponent.is_Integer and exponent >= 0):
                    raise ProblemError(
                        f"factor {factor} of {expr} has a non-integer or negative exponent; "
                        "quasi-trig pieces are sums of c*s**m*cos(j*s) and c*s**m*sin(j*s)"
                    )
                product = product * cls._parse_factor(base, variable, expr) ** int(exponent)
            total = total + product.scale(coefficient)
        return total

    @classmethod
    def _parse_factor(cls, base: sympy.Expr, variable: sympy.Symbol, whole: sympy.Expr) -> "QuasiTrigPolynomial":
        if base == variable:
            return cls.from_terms({(1, _COS, 0): 1})
        if isinstance(base, (sympy.cos, sympy.sin)):
            argument = base.args[0]
            frequency = sympy.simplify(argument / variable)
            if frequency.has(variable) or not frequency.is_Integer:
                raise ProblemError(
                    f"{base} in {whole} is not cos(j*s)/sin(j*s) with integer j; "
                    "expand phase shifts with sympy.expand_trig first"
                )
            kind = _COS if isinstance(base, sympy.cos) else _SIN
            return cls.from_terms({(0, kind, frequency): 1})
        raise ProblemError(
            f"factor {base} of {whole} is not s, cos(j*s) or sin(j*s); quasi-trig pieces are sums of "
            "c*s**m*cos(j*s) and c*s**m*sin(j*s) with exact coefficients"
        )

    # -- inspection -----------------------------------------------------------

    def as_dict(self) -> dict:
        """The terms as a ``{(power, kind, frequency): coefficient}`` dict.

        Examples
        --------
        >>> QuasiTrigPolynomial.from_expr(2 * S, S).as_dict()
        {(1, 'cos', 0): 2}
        """
        return dict(self.terms)

    @property
    def is_zero(self) -> bool:
        """True if no term survives (structural, after expansion)."""
        return not self.terms

    @property
    def free_symbols(self) -> set:
        """Free symbols of the coefficients and frequencies."""
        symbols: set = set()
        for (_, _, frequency), coefficient in self.terms:
            symbols |= coefficient.free_symbols | frequency.free_symbols
        return symbols

    def to_expr(self, variable: sympy.Symbol = S) -> sympy.Expr:
        """The piece as a sympy expression in ``variable``.

        Examples
        --------
        >>> t = sympy.Symbol("t")
        >>> QuasiTrigPolynomial.from_terms({(2, "sin", 3): 5}).to_expr(t)
        5*t**2*sin(3*t)
        """
        total = sympy.Integer(0)
        for (power, kind, frequency), coefficient in self.terms:
            trig = sympy.cos(frequency * variable) if kind == _COS else sympy.sin(frequency * variable)
            total += coefficient * variable**power * trig
        return total

    # -- algebra --------------------------------------------------------------

    def _combine(self, other: "QuasiTrigPolynomial", sign: int) -> "QuasiTrigPolynomial":
        accumulated = dict(self.terms)
        for key, coefficient in other.terms:
            accumulated[key] = accumulated.get(key, sympy.Integer(0)) + sign * coefficient
        return QuasiTrigPolynomial._from_accumulated(accumulated)

    def __add__(self, other: object) -> "QuasiTrigPolynomial":
        if isinstance(other, QuasiTrigPolynomial):
            return self._combine(other, 1)
        if isinstance(other, (int, float, sympy.Expr)):
            return self._combine(QuasiTrigPolynomial.constant(other), 1)
        return NotImplemented

    __radd__ = __add__

    def __sub__(self, other: object) -> "QuasiTrigPolynomial":
        if isinstance(other, QuasiTrigPolynomial):
            return self._combine(other, -1)
        if isinstance(other, (int, float, sympy.Expr)):
            return self._combine(QuasiTrigPolynomial.constant(other), -1)
        return NotImplemented

    def __rsub__(self, other: object) -> "QuasiTrigPolynomial":
        return (-self) + other

    def __neg__(self) -> "QuasiTrigPolynomial":
        return self.scale(-1)

    def scale(self, factor: Scalar) -> "QuasiTrigPolynomial":
        """Multiply every coefficient by ``factor`` (a constant expression).

        Examples
        --------
        >>> QuasiTrigPolynomial.from_expr(sympy.cos(S), S).scale(sympy.Symbol("a")).to_expr(S)
        a*cos(s)
        """
        value = _as_scalar(factor, "factor")
        return QuasiTrigPolynomial._from_accumulated({key: coefficient * value for key, coefficient in self.terms})

    def __mul__(self, other: object) -> "QuasiTrigPolynomial":
        if isinstance(other, (int, float, sympy.Expr)):
            return self.scale(other)
        if not isinstance(other, QuasiTrigPolynomial):
            return NotImplemented
        accumulated: dict = {}
        half = sympy.Rational(1, 2)
        for (power_a, kind_a, freq_a), coef_a in self.terms:
            for (power_b, kind_b, freq_b), coef_b in other.terms:
                power = power_a + power_b
                coefficient = coef_a * coef_b * half
                total, difference = freq_a + freq_b, freq_a - freq_b
                if kind_a == _COS and kind_b == _COS:  # cos a cos b = [cos(a-b) + cos(a+b)]/2
                    _accumulate(accumulated, (power, _COS, difference), coefficient)
                    _accumulate(accumulated, (power, _COS, total), coefficient)
                elif kind_a == _SIN and kind_b == _SIN:  # sin a sin b = [cos(a-b) - cos(a+b)]/2
                    _accumulate(accumulated, (power, _COS, difference), coefficient)
                    _accumulate(accumulated, (power, _COS, total), -coefficient)
                elif kind_a == _SIN:  # sin a cos b = [sin(a+b) + sin(a-b)]/2
                    _accumulate(accumulated, (power, _SIN, total), coefficient)
                    _accumulate(accumulated, (power, _SIN, difference), coefficient)
                else:  # cos a sin b = [sin(a+b) - sin(a-b)]/2
                    _accumulate(accumulated, (power, _SIN, total), coefficient)
                    _accumulate(accumulated, (power, _SIN, difference), -coefficient)
        return QuasiTrigPolynomial._from_accumulated(accumulated)

    def __rmul__(self, other: object) -> "QuasiTrigPolynomial":
        if isinstance(other, (int, float, sympy.Expr)):
            return self.scale(other)
        return NotImplemented

    def __pow__(self, exponent: int) -> "QuasiTrigPolynomial":
        if isinstance(exponent, bool) or not isinstance(exponent, int) or exponent < 0:
            raise ProblemError(f"exponent {exponent!r} must be a non-negative int")
        result = QuasiTrigPolynomial.constant(1)
        for _ in range(exponent):
            result = result * self
        return result

    # -- calculus -------------------------------------------------------------

    def derivative(self) -> "QuasiTrigPolynomial":
        """d/ds of the piece.

        Examples
        --------
        >>> import sympy
        >>> QuasiTrigPolynomial.from_expr(S**2 * sympy.sin(S), S).derivative().to_expr(S)
        s**2*cos(s) + 2*s*sin(s)
        """
        accumulated: dict = {}
        for (power, kind, frequency), coefficient in self.terms:
            if power > 0:
                _accumulate(accumulated, (power - 1, kind, frequency), coefficient * power)
            if kind == _COS:
                _accumulate(accumulated, (power, _SIN, frequency), -coefficient * frequency)
            else:
                _accumulate(accumulated, (power, _COS, frequency), coefficient * frequency)
        return QuasiTrigPolynomial._from_accumulated(accumulated)

    def antiderivative(self) -> "QuasiTrigPolynomial":
        """An antiderivative (the one built by integration by parts, no constant added).

        Symbolic frequencies are treated as nonzero.

        Examples
        --------
        >>> import sympy
        >>> QuasiTrigPolynomial.from_expr(S * sympy.cos(S), S).antiderivative().to_expr(S)
        s*sin(s) + cos(s)
        """
        accumulated: dict = {}
        for (power, kind, frequency), coefficient in self.terms:
            for unit_key, unit_coefficient in _unit_antiderivative(power, kind, frequency):
                _accumulate(accumulated, unit_key, coefficient * unit_coefficient)
        return QuasiTrigPolynomial._from_accumulated(accumulated)

    # -- evaluation -----------------------------------------------------------

    def evaluate(self, point: Scalar) -> sympy.Expr:
        """Exact value at ``point`` in canonical form (``expand_trig`` + ``expand``).

        Examples
        --------
        >>> import sympy
        >>> kappa = sympy.Symbol("kappa")
        >>> QuasiTrigPolynomial.from_expr(sympy.cos(3 * S), S).evaluate(sympy.acos(kappa))
        4*kappa**3 - 3*kappa
        """
        value = _as_scalar(point, "point")
        total = sympy.Integer(0)
        for (power, kind, frequency), coefficient in self.terms:
            trig = sympy.cos(frequency * value) if kind == _COS else sympy.sin(frequency * value)
            total += coefficient * value**power * trig
        return _canonical(total)

    def evaluate_float(self, points: np.ndarray, substitutions: Mapping | None = None) -> np.ndarray:
        """Float values at an array of points (coefficients numerically substituted).

        Parameters
        ----------
        points : numpy.ndarray
            Points (any shape).
        substitutions : mapping, optional
            Values for the free symbols of the coefficients.

        Returns
        -------
        numpy.ndarray
            Values with the shape of ``points``.

        Examples
        --------
        >>> import numpy as np
        >>> piece = QuasiTrigPolynomial.from_expr(sympy.Symbol("a") * sympy.cos(S), S)
        >>> piece.evaluate_float(np.array([0.0, np.pi]), {"a": 2.0}).tolist()
        [2.0, -2.0]
        """
        grid = np.asarray(points, dtype=float)
        total = np.zeros_like(grid)
        for (power, kind, frequency), coefficient in self.terms:
            coefficient_value = _float_value(coefficient, substitutions, "coefficient")
            frequency_value = _float_value(frequency, substitutions, "frequency")
            trig = np.cos(frequency_value * grid) if kind == _COS else np.sin(frequency_value * grid)
            total = total + coefficient_value * grid**power * trig
        return total

    def substitute(self, substitutions: Mapping) -> "QuasiTrigPolynomial":
        """Substitute values for symbols in coefficients and frequencies.

        Examples
        --------
        >>> a = sympy.Symbol("a")
        >>> QuasiTrigPolynomial.from_expr(a * sympy.sin(S), S).substitute({a: 3}).to_expr(S)
        3*sin(s)
        """
        accumulated: dict = {}
        for (power, kind, frequency), coefficient in self.terms:
            _accumulate(accumulated, (power, kind, sympy.sympify(frequency, strict=True).subs(substitutions)),
                        coefficient.subs(substitutions))
        return QuasiTrigPolynomial._from_accumulated(accumulated)

    def map_coefficients(self, function: Callable[[sympy.Expr], sympy.Expr]) -> "QuasiTrigPolynomial":
        """Apply ``function`` (e.g. ``sympy.simplify``) to every coefficient."""
        return QuasiTrigPolynomial._from_accumulated({key: function(value) for key, value in self.terms})

    # -- the resonant operator ------------------------------------------------

    def particular_solution(self) -> "QuasiTrigPolynomial":
        """A particular solution ``p`` of ``p'' + p = self`` (integer frequencies only).

        Forcing at frequency 1 gives terms one power of ``s`` higher (resonance).

        Raises
        ------
        ProblemError
            If a frequency is symbolic.

        Examples
        --------
        >>> import sympy
        >>> QuasiTrigPolynomial.from_expr(sympy.cos(S), S).particular_solution().to_expr(S)
        s*sin(s)/2
        """
        accumulated: dict = {}
        for (power, kind, frequency), coefficient in self.terms:
            if not frequency.is_Integer:
                raise ProblemError(
                    f"frequency {frequency} is symbolic; substitute an integer before solving v'' + v = rhs"
                )
            for unit_key, unit_coefficient in _unit_particular(power, kind, int(frequency)):
                _accumulate(accumulated, unit_key, coefficient * unit_coefficient)
        return QuasiTrigPolynomial._from_accumulated(accumulated)


def _float_value(expr: sympy.Expr, substitutions: Mapping | None, what: str) -> float:
    value = expr.subs(substitutions) if substitutions else expr
    try:
        number = complex(sympy.N(value, 20))
    except TypeError as exc:
        raise ProblemError(
            f"{what} {value} still has free symbols {sorted(map(str, value.free_symbols))}; "
            "pass substitutions={symbol: value}"
        ) from exc
    if abs(number.imag) > 1e-14 * max(1.0, abs(number.real)):
        raise ProblemError(f"{what} {value} is not real; check the substitutions")
    return number.real


@lru_cache(maxsize=4096)
def _unit_antiderivative(power: int, kind: str, frequency: sympy.Expr) -> tuple[tuple[TermKey, sympy.Expr], ...]:
    """Antiderivative of ``s**power * cos/sin(frequency s)`` by integration by parts.

    ``int s^m cos(js) = s^m sin(js)/j - (m/j) int s^(m-1) sin(js)`` and
    ``int s^m sin(js) = -s^m cos(js)/j + (m/j) int s^(m-1) cos(js)``; ``j = 0`` gives
    ``s^(m+1)/(m+1)``.
    """
    if frequency == 0:
        return (((power + 1, _COS, sympy.Integer(0)), sympy.Rational(1, power + 1)),)
    terms: list = []
    if kind == _COS:
        terms.append(((power, _SIN, frequency), 1 / frequency))
        if power > 0:
            for key, value in _unit_antiderivative(power - 1, _SIN, frequency):
                terms.append((key, -power * value / frequency))
    else:
        terms.append(((power, _COS, frequency), -1 / frequency))
        if power > 0:
            for key, value in _unit_antiderivative(power - 1, _COS, frequency):
                terms.append((key, power * value / frequency))
    return tuple(terms)


@lru_cache(maxsize=4096)
def _unit_particular(power: int, kind: str, frequency: int) -> tuple[tuple[TermKey, sympy.Expr], ...]:
    """Particular solution of ``p'' + p = s**power * cos/sin(frequency s)``.

    Write the forcing as the real/imaginary part of ``s^m e^{i j s}`` and seek
    ``p = Re/Im(q(s) e^{i j s})``: the polynomial ``q`` solves
    ``q'' + 2 i j q' + (1 - j^2) q = s^m``.  For ``j != 1`` it has degree ``m``
    (back substitution from the top); for ``j = 1`` (resonance) ``q(0) = 0`` and
    degree ``m + 1``.
    """
    imaginary = sympy.I
    q: dict[int, sympy.Expr] = {}
    if frequency != 1:
        shift = sympy.Integer(1 - frequency * frequency)
        for degree in range(power, -1, -1):
            source = sympy.Integer(1 if degree == power else 0)
            value = source - (degree + 2) * (degree + 1) * q.get(degree + 2, 0) - 2 * imaginary * frequency * (degree + 1) * q.get(degree + 1, 0)
            q[degree] = sympy.expand(value / shift)
    else:
        for degree in range(power, -1, -1):
            source = sympy.Integer(1 if degree == power else 0)
            value = source - (degree + 2) * (degree + 1) * q.get(degree + 2, 0)
            q[degree + 1] = sympy.expand(value / (2 * imaginary * (degree + 1)))
    frequency_expr = sympy.Integer(frequency)
    terms: list = []
    for degree, value in q.items():
        real_part, imaginary_part = sympy.re(value), sympy.im(value)
        if kind == _COS:  # Re(q e^{ijs}) = Re q cos - Im q sin
            terms.append(((degree, _COS, frequency_expr), real_part))
            terms.append(((degree, _SIN, frequency_expr), -imaginary_part))
        else:  # Im(q e^{ijs}) = Im q cos + Re q sin
            terms.append(((degree, _COS, frequency_expr), imaginary_part))
            terms.append(((degree, _SIN, frequency_expr), real_part))
    return tuple(terms)


# ---------------------------------------------------------------------------
# piecewise functions on [0, pi]
# ---------------------------------------------------------------------------


def _merge_breakpoints(first: Sequence[sympy.Expr], second: Sequence[sympy.Expr]) -> tuple[sympy.Expr, ...]:
    """Union of two breakpoint lists ``(0, ..., pi)``; interior points are trusted to lie in (0, pi)."""
    interior_first, interior_second = first[1:-1], second[1:-1]
    merged: list = []
    i = j = 0
    while i < len(interior_first) and j < len(interior_second):
        left, right = interior_first[i], interior_second[j]
        if _same_point(left, right) is True:
            merged.append(left)
            i += 1
            j += 1
            continue
        less = _decide_less(left, right)
        if less is None:
            raise ProblemError(
                f"cannot order the breakpoints {left} and {right}; build both operands on the same "
                "breakpoints (PiecewiseQuasiTrig.refine) or substitute numeric parameter values"
            )
        if less:
            merged.append(left)
            i += 1
        else:
            merged.append(right)
            j += 1
    merged.extend(interior_first[i:])
    merged.extend(interior_second[j:])
    return (sympy.Integer(0),) + tuple(merged) + (sympy.pi,)


@dataclass(frozen=True)
class PiecewiseQuasiTrig:
    """Even 2*pi-periodic function given on ``[0, pi]`` by quasi-trigonometric pieces.

    Piece ``i`` holds on ``[breakpoints[i], breakpoints[i+1])`` (the last piece also at pi).

    Attributes
    ----------
    breakpoints : tuple of sympy.Expr
        ``0 = s_0 < s_1 < ... < s_n = pi``; symbolic entries are trusted to be ordered.
    pieces : tuple of QuasiTrigPolynomial
        ``n`` pieces.

    Examples
    --------
    >>> import sympy
    >>> ramp = contact_ramp_function(0)            # (cos s)_+
    >>> ramp.breakpoints
    (0, pi/2, pi)
    >>> ramp.cosine_coefficient(2)
    2/(3*pi)
    >>> (2 * ramp - PiecewiseQuasiTrig.from_expression(sympy.cos(S))).integral()  # int_0^pi |cos s| ds
    2
    """

    breakpoints: tuple[sympy.Expr, ...]
    pieces: tuple[QuasiTrigPolynomial, ...]

    def __post_init__(self) -> None:
        breakpoints = tuple(sympy.sympify(point, strict=True) for point in self.breakpoints)
        object.__setattr__(self, "breakpoints", breakpoints)
        object.__setattr__(self, "pieces", tuple(self.pieces))
        if len(self.pieces) < 1 or len(breakpoints) != len(self.pieces) + 1:
            raise ProblemError(
                f"{len(breakpoints)} breakpoints for {len(self.pieces)} pieces; pass n + 1 breakpoints "
                "0 = s_0 < ... < s_n = pi for n >= 1 pieces"
            )
        if not all(isinstance(piece, QuasiTrigPolynomial) for piece in self.pieces):
            raise ProblemError("pieces must be QuasiTrigPolynomial instances; use PiecewiseQuasiTrig.from_expressions")
        if breakpoints[0] != 0 or _same_point(breakpoints[-1], sympy.pi) is not True:
            raise ProblemError(f"breakpoints must start at 0 and end at pi; got {breakpoints[0]} ... {breakpoints[-1]}")
        for left, right in zip(breakpoints, breakpoints[1:]):
            if left.is_real is False or right.is_real is False:
                raise ProblemError(f"breakpoint {left} or {right} is not real")
            if _decide_less(left, right) is False:
                raise ProblemError(f"breakpoints must increase strictly; {left} is not below {right}")

    # -- construction -----------------------------------------------------

    @classmethod
    def from_expressions(
        cls,
        expressions: Sequence[Scalar],
        interior_breakpoints: Sequence[Scalar] = (),
        variable: sympy.Symbol = S,
    ) -> "PiecewiseQuasiTrig":
        """Build from one expression per piece and the interior breakpoints.

        Parameters
        ----------
        expressions : sequence of sympy expressions
            Piece ``i`` on ``[s_i, s_{i+1}]`` (see :meth:`QuasiTrigPolynomial.from_expr`).
        interior_breakpoints : sequence, optional
            ``s_1 < ... < s_{n-1}`` strictly inside ``(0, pi)``.
        variable : sympy.Symbol, optional
            Variable of the expressions (default :data:`S`).

        Returns
        -------
        PiecewiseQuasiTrig

        Examples
        --------
        >>> import sympy
        >>> g = PiecewiseQuasiTrig.from_expressions([sympy.cos(S), 0], [sympy.pi / 2])
        >>> g.integral()
        1
        """
        pieces = tuple(QuasiTrigPolynomial.from_expr(expr, variable) for expr in expressions)
        points = (sympy.Integer(0),) + tuple(sympy.sympify(point, strict=True) for point in interior_breakpoints) + (sympy.pi,)
        return cls(points, pieces)

    @classmethod
    def from_expression(cls, expr: Scalar, variable: sympy.Symbol = S) -> "PiecewiseQuasiTrig":
        """A single-piece function on ``[0, pi]``."""
        return cls.from_expressions([expr], (), variable)

    @classmethod
    def constant(cls, value: Scalar) -> "PiecewiseQuasiTrig":
        """The constant function ``value``."""
        return cls((sympy.Integer(0), sympy.pi), (QuasiTrigPolynomial.constant(value),))

    # -- structure ------------------------------------------------------------

    @property
    def free_symbols(self) -> set:
        """Free symbols of breakpoints and coefficients."""
        symbols: set = set()
        for point in self.breakpoints:
            symbols |= point.free_symbols
        for piece in self.pieces:
            symbols |= piece.free_symbols
        return symbols

    def refine(self, breakpoints: Sequence[Scalar]) -> "PiecewiseQuasiTrig":
        """The same function on the union of its breakpoints and ``breakpoints``.

        Parameters
        ----------
        breakpoints : sequence
            Extra points strictly inside ``(0, pi)`` (any order).

        Raises
        ------
        ProblemError
            If some pair of breakpoints cannot be ordered.

        Examples
        --------
        >>> import sympy
        >>> PiecewiseQuasiTrig.constant(1).refine([sympy.pi / 3]).breakpoints
        (0, pi/3, pi)
        """
        merged = self.breakpoints
        for point in breakpoints:
            merged = _merge_breakpoints(merged, (sympy.Integer(0), sympy.sympify(point, strict=True), sympy.pi))
        return self._on(merged)

    def _on(self, merged: tuple[sympy.Expr, ...]) -> "PiecewiseQuasiTrig":
        """Re-express the pieces on ``merged``, a refinement of the breakpoints."""
        pieces = []
        source = 0
        for left in merged[:-1]:
            if source + 1 < len(self.pieces) and _same_point(self.breakpoints[source + 1], left) is True:
                source += 1
            pieces.append(self.pieces[source])
        return PiecewiseQuasiTrig(merged, tuple(pieces))

    def _aligned(self, other: "PiecewiseQuasiTrig") -> tuple["PiecewiseQuasiTrig", "PiecewiseQuasiTrig"]:
        if self.breakpoints == other.breakpoints:
            return self, other
        merged = _merge_breakpoints(self.breakpoints, other.breakpoints)
        return self._on(merged), other._on(merged)

    def _map(self, function: Callable[[QuasiTrigPolynomial], QuasiTrigPolynomial]) -> "PiecewiseQuasiTrig":
        return PiecewiseQuasiTrig(self.breakpoints, tuple(function(piece) for piece in self.pieces))

    # -- algebra --------------------------------------------------------------

    def _binary(self, other: object, operation: Callable) -> "PiecewiseQuasiTrig":
        if isinstance(other, (int, float, sympy.Expr)):
            constant = QuasiTrigPolynomial.constant(other)
            return self._map(lambda piece: operation(piece, constant))
        if isinstance(other, QuasiTrigPolynomial):
            return self._map(lambda piece: operation(piece, other))
        if isinstance(other, PiecewiseQuasiTrig):
            left, right = self._aligned(other)
            return PiecewiseQuasiTrig(left.breakpoints, tuple(operation(a, b) for a, b in zip(left.pieces, right.pieces)))
        return NotImplemented

    def __add__(self, other: object) -> "PiecewiseQuasiTrig":
        return self._binary(other, lambda a, b: a + b)

    __radd__ = __add__

    def __sub__(self, other: object) -> "PiecewiseQuasiTrig":
        return self._binary(other, lambda a, b: a - b)

    def __rsub__(self, other: object) -> "PiecewiseQuasiTrig":
        return self._binary(other, lambda a, b: b - a)

    def __neg__(self) -> "PiecewiseQuasiTrig":
        return self._map(lambda piece: -piece)

    def __mul__(self, other: object) -> "PiecewiseQuasiTrig":
        if isinstance(other, (int, float, sympy.Expr)):
            return self._map(lambda piece: piece.scale(other))
        return self._binary(other, lambda a, b: a * b)

    def __rmul__(self, other: object) -> "PiecewiseQuasiTrig":
        if isinstance(other, (int, float, sympy.Expr)):
            return self._map(lambda piece: piece.scale(other))
        if isinstance(other, QuasiTrigPolynomial):
            return self._map(lambda piece: other * piece)
        return NotImplemented

    def derivative(self) -> "PiecewiseQuasiTrig":
        """Piecewise classical derivative (jumps at breakpoints are not represented as deltas).

        Examples
        --------
        >>> contact_ramp_function(0).derivative().pieces[0].to_expr(S)
        -sin(s)
        """
        return self._map(lambda piece: piece.derivative())

    def substitute(self, substitutions: Mapping) -> "PiecewiseQuasiTrig":
        """Substitute values for symbols in breakpoints and coefficients.

        Examples
        --------
        >>> kappa = sympy.Symbol("kappa")
        >>> contact_ramp_function(kappa).substitute({kappa: sympy.Rational(1, 2)}).breakpoints
        (0, pi/3, pi)
        """
        points = tuple(sympy.sympify(point, strict=True).subs(substitutions) for point in self.breakpoints)
        return PiecewiseQuasiTrig(points, tuple(piece.substitute(substitutions) for piece in self.pieces))

    def map_coefficients(self, function: Callable[[sympy.Expr], sympy.Expr]) -> "PiecewiseQuasiTrig":
        """Apply ``function`` to every coefficient of every piece."""
        return self._map(lambda piece: piece.map_coefficients(function))

    def equals(self, other: "PiecewiseQuasiTrig") -> bool | None:
        """Exact equality on ``[0, pi]`` (None if some coefficient difference is undecidable).

        Examples
        --------
        >>> ramp, step = contact_ramp_function(0), contact_step_function(0)
        >>> ramp.equals(step * PiecewiseQuasiTrig.from_expression(sympy.cos(S)))
        True
        """
        difference = self - other
        verdict: bool | None = True
        for piece in difference.pieces:
            for _, coefficient in piece.terms:
                zero = _is_zero(coefficient)
                if zero is False:
                    return False
                if zero is None:
                    verdict = None
        return verdict

    # -- integrals and Fourier coefficients ----------------------------------

    def integral(self, start: int = 0, stop: int | None = None) -> sympy.Expr:
        """Exact ``int_{s_start}^{s_stop} g(s) ds`` between breakpoints (default ``[0, pi]``).

        Parameters
        ----------
        start, stop : int, optional
            Breakpoint indices, ``0 <= start <= stop <= n``.

        Returns
        -------
        sympy.Expr
            Canonical exact value.

        Examples
        --------
        >>> ramp = contact_ramp_function(sympy.Rational(1, 2))
        >>> ramp.integral()
        -pi/6 + sqrt(3)/2
        >>> ramp.integral(1, 2)
        0
        """
        last = len(self.pieces) if stop is None else stop
        if not (0 <= start <= last <= len(self.pieces)):
            raise ProblemError(f"breakpoint indices start={start}, stop={stop} out of range 0..{len(self.pieces)}")
        total = sympy.Integer(0)
        for index in range(start, last):
            primitive = self.pieces[index].antiderivative()
            total += primitive.evaluate(self.breakpoints[index + 1]) - primitive.evaluate(self.breakpoints[index])
        return _canonical(total)

    def cosine_coefficient(self, k: int | sympy.Expr) -> sympy.Expr:
        """Exact cosine Fourier coefficient ``(2/pi) int_0^pi g cos(k s) ds`` (``1/pi`` for k = 0).

        Parameters
        ----------
        k : int or integer sympy Symbol
            Harmonic.  For a symbolic ``k`` the generic formula is returned, valid for
            integers ``k`` larger than every frequency present in the pieces.

        Returns
        -------
        sympy.Expr
            Canonical exact coefficient.

        Examples
        --------
        >>> import sympy
        >>> k = sympy.Symbol("k", integer=True, positive=True)
        >>> PiecewiseQuasiTrig.from_expression(S).cosine_coefficient(k)
        2*(-1)**k/(pi*k**2) - 2/(pi*k**2)
        """
        harmonic = sympy.sympify(k, strict=True)
        if harmonic.is_number:
            if not harmonic.is_Integer or harmonic < 0:
                raise ProblemError(f"harmonic k={k!r} must be a non-negative integer")
        elif harmonic.is_integer is not True or harmonic.could_extract_minus_sign():
            raise ProblemError(f"symbolic harmonic {k!r} must be a non-negative integer symbol (integer=True)")
        weight = sympy.Integer(1) / sympy.pi if harmonic == 0 else 2 / sympy.pi
        cosine = QuasiTrigPolynomial.from_terms({(0, _COS, harmonic): 1})
        product = self * cosine
        return _canonical(weight * product.integral())

    def cosine_coefficients(self, n_max: int) -> tuple[sympy.Expr, ...]:
        """Exact cosine coefficients ``d_0, ..., d_{n_max}``.

        Examples
        --------
        >>> import sympy
        >>> PiecewiseQuasiTrig.from_expression(sympy.cos(S) ** 2).cosine_coefficients(3)
        (1/2, 0, 1/2, 0)
        """
        if isinstance(n_max, bool) or not isinstance(n_max, int) or n_max < 0:
            raise ProblemError(f"n_max={n_max!r} must be a non-negative int")
        return tuple(self.cosine_coefficient(k) for k in range(n_max + 1))

    # -- evaluation -----------------------------------------------------------

    def _reduce_exact(self, point: sympy.Expr) -> sympy.Expr:
        if not point.is_number:
            return point
        reduced = sympy.Abs(point)
        turns = sympy.floor(reduced / (2 * sympy.pi))
        reduced = reduced - 2 * sympy.pi * turns
        if _decide_less(sympy.pi, reduced):
            reduced = 2 * sympy.pi - reduced
        return reduced

    def evaluate(self, point: Scalar) -> sympy.Expr:
        """Exact value at ``point`` (reduced to ``[0, pi]`` by evenness and periodicity).

        At an interior breakpoint the piece to the right is used.

        Raises
        ------
        ProblemError
            If the point cannot be located relative to symbolic breakpoints.

        Examples
        --------
        >>> contact_ramp_function(0).evaluate(-2 * sympy.pi + sympy.pi / 3)
        1/2
        """
        value = self._reduce_exact(_as_scalar(point, "point"))
        if value == 0:
            return self.pieces[0].evaluate(value)
        if _same_point(value, sympy.pi) is True:
            return self.pieces[-1].evaluate(value)
        for index in range(len(self.pieces) - 1, 0, -1):
            left = self.breakpoints[index]
            if _same_point(left, value) is True:
                return self.pieces[index].evaluate(value)
            below = _decide_less(value, left)
            if below is None:
                raise ProblemError(f"cannot locate s = {value} relative to breakpoint {left}; substitute numeric values")
            if not below:
                return self.pieces[index].evaluate(value)
        return self.pieces[0].evaluate(value)

    def breakpoints_float(self, substitutions: Mapping | None = None) -> np.ndarray:
        """Breakpoints as floats (free symbols substituted)."""
        return np.array([_float_value(sympy.sympify(point, strict=True), substitutions, "breakpoint") for point in self.breakpoints])

    def evaluate_float(self, points: object, substitutions: Mapping | None = None) -> np.ndarray:
        """Vectorised float evaluation at any real points (even 2*pi-periodic extension).

        Parameters
        ----------
        points : array_like
            Points of any shape.
        substitutions : mapping, optional
            Numeric values for the free symbols.

        Returns
        -------
        numpy.ndarray

        Examples
        --------
        >>> import numpy as np
        >>> ramp = contact_ramp_function(0)
        >>> ramp.evaluate_float(np.array([0.0, np.pi, -0.5])).round(12).tolist()
        [1.0, 0.0, 0.87758256189]
        """
        grid = np.asarray(points, dtype=float)
        reduced = np.mod(np.abs(grid), 2 * np.pi)
        reduced = np.where(reduced > np.pi, 2 * np.pi - reduced, reduced)
        edges = self.breakpoints_float(substitutions)
        index = np.clip(np.searchsorted(edges, reduced, side="right") - 1, 0, len(self.pieces) - 1)
        result = np.zeros_like(reduced)
        for piece_index, piece in enumerate(self.pieces):
            mask = index == piece_index
            if np.any(mask):
                result[mask] = piece.evaluate_float(reduced[mask], substitutions)
        return result

    def to_piecewise(self, variable: sympy.Symbol = S) -> sympy.Piecewise:
        """The restriction to ``[0, pi]`` as a sympy ``Piecewise`` in ``variable``.

        Examples
        --------
        >>> contact_step_function(0).to_piecewise(S)
        Piecewise((1, s < pi/2), (0, True))
        """
        clauses = [
            (piece.to_expr(variable), variable < right)
            for piece, right in zip(self.pieces[:-1], self.breakpoints[1:-1])
        ]
        clauses.append((self.pieces[-1].to_expr(variable), True))
        return sympy.Piecewise(*clauses)

    def jumps(self, order: int = 0) -> tuple[sympy.Expr, ...]:
        """Left-minus-right jumps of the ``order``-th derivative at the interior breakpoints.

        Examples
        --------
        >>> ramp = contact_ramp_function(0)
        >>> ramp.jumps(0), ramp.jumps(1)
        ((0,), (-1,))
        """
        if isinstance(order, bool) or not isinstance(order, int) or order < 0:
            raise ProblemError(f"order={order!r} must be a non-negative int")
        function = self
        for _ in range(order):
            function = function.derivative()
        return tuple(
            _canonical(function.pieces[index].evaluate(point) - function.pieces[index + 1].evaluate(point))
            for index, point in enumerate(self.breakpoints[1:-1])
        )


# ---------------------------------------------------------------------------
# the even periodic solve
# ---------------------------------------------------------------------------


def solve_even_periodic(
    rhs: PiecewiseQuasiTrig,
    alpha0: Scalar = 1,
    *,
    value_at_zero: Scalar | None = None,
    zero_first_harmonic: bool = False,
    check_secular: bool = True,
) -> PiecewiseQuasiTrig:
    """Even 2*pi-periodic C^1 solution of ``alpha0 (v'' + v) = rhs``.

    Parameters
    ----------
    rhs : PiecewiseQuasiTrig
        Right-hand side; its ``cos s`` Fourier coefficient must vanish.
    alpha0 : number or sympy expression, optional
        Nonzero factor (``omega0**2`` in the Lindstedt-Poincare hierarchy).
    value_at_zero : number or sympy expression, optional
        Impose ``v(0) = value_at_zero``.
    zero_first_harmonic : bool, optional
        Instead impose a vanishing ``cos s`` coefficient of ``v``.  Exactly one of the
        two conditions must be given.
    check_secular : bool, optional
        Verify (exactly) that the ``cos s`` coefficient of ``rhs`` vanishes (default True).

    Returns
    -------
    PiecewiseQuasiTrig
        ``v`` on the breakpoints of ``rhs``; ``v`` and ``v'`` are continuous and
        ``v'(0) = v'(pi) = 0``.

    Raises
    ------
    ResonanceError
        If the secular ``cos s`` coefficient of ``rhs`` is nonzero (or undecidable).
    ProblemError
        If ``alpha0`` is zero or the normalisation is not specified exactly once.

    Examples
    --------
    >>> import sympy
    >>> rhs = PiecewiseQuasiTrig.from_expression(sympy.cos(2 * S))
    >>> solve_even_periodic(rhs, 1, zero_first_harmonic=True).pieces[0].to_expr(S)
    -cos(2*s)/3
    """
    if not isinstance(rhs, PiecewiseQuasiTrig):
        raise ProblemError("rhs must be a PiecewiseQuasiTrig; build it with PiecewiseQuasiTrig.from_expressions")
    factor = _as_scalar(alpha0, "alpha0")
    if _is_zero(factor) is True:
        raise ProblemError("alpha0 = 0: the operator alpha0 (v'' + v) degenerates; pass alpha0 = omega0**2 != 0")
    if (value_at_zero is None) == (not zero_first_harmonic):
        raise ProblemError("fix the free cos s component exactly once: pass value_at_zero=... or zero_first_harmonic=True")
    if check_secular:
        secular = rhs.cosine_coefficient(1)
        verdict = _is_zero(secular)
        if verdict is not True:
            detail = "is nonzero" if verdict is False else "could not be shown to vanish"
            raise ResonanceError(
                f"the secular cos(s) coefficient of the rhs, (2/pi) int_0^pi R cos s ds = {secular}, {detail}; "
                "choose the frequency correction so that it vanishes (or subtract it from the rhs), "
                "or pass check_secular=False if it is known to be zero"
            )
    particular = [piece.particular_solution().scale(1 / factor) for piece in rhs.pieces]
    derivatives = [piece.derivative() for piece in particular]
    cos_coefficients = [sympy.Integer(0)]
    sin_coefficients = [_canonical(-derivatives[0].evaluate(0))]
    for index, point in enumerate(rhs.breakpoints[1:-1]):
        jump = particular[index].evaluate(point) - particular[index + 1].evaluate(point)
        slope_jump = derivatives[index].evaluate(point) - derivatives[index + 1].evaluate(point)
        cosine, sine = _canonical(sympy.cos(point)), _canonical(sympy.sin(point))
        cos_coefficients.append(_canonical(cos_coefficients[-1] + jump * cosine - slope_jump * sine))
        sin_coefficients.append(_canonical(sin_coefficients[-1] + jump * sine + slope_jump * cosine))
    pieces = [
        particular[index] + QuasiTrigPolynomial.from_terms(
            {(0, _COS, 1): cos_coefficients[index], (0, _SIN, 1): sin_coefficients[index]}
        )
        for index in range(len(particular))
    ]
    solution = PiecewiseQuasiTrig(rhs.breakpoints, tuple(pieces))
    if value_at_zero is not None:
        shift = _canonical(_as_scalar(value_at_zero, "value_at_zero") - solution.pieces[0].evaluate(0))
    else:
        shift = _canonical(-solution.cosine_coefficient(1))
    return solution + PiecewiseQuasiTrig.from_expression(shift * sympy.cos(S))


# ---------------------------------------------------------------------------
# contact functions as piecewise quasi-trigonometric functions
# ---------------------------------------------------------------------------


def _contact_breakpoint(kappa: Scalar) -> tuple[sympy.Expr, str]:
    value = _as_scalar(kappa, "kappa")
    if value.is_real is False:
        raise ProblemError(f"kappa={kappa!r} must be real")
    if (value >= 1) == sympy.true:
        return sympy.Integer(0), "none"
    if (value <= -1) == sympy.true:
        return sympy.pi, "all"
    return sympy.acos(value), "partial"


def contact_ramp_function(kappa: Scalar) -> PiecewiseQuasiTrig:
    """``(cos s - kappa)_+`` as a piecewise function with breakpoint ``beta = acos(kappa)``.

    A symbolic kappa is assumed to satisfy ``|kappa| < 1``.

    Examples
    --------
    >>> contact_ramp_function(sympy.Rational(1, 2)).pieces[0].to_expr(S)
    cos(s) - 1/2
    >>> contact_ramp_function(2).pieces
    (QuasiTrigPolynomial(terms=()),)
    """
    point, regime = _contact_breakpoint(kappa)
    value = _as_scalar(kappa, "kappa")
    if regime == "none":
        return PiecewiseQuasiTrig.constant(0)
    if regime == "all":
        return PiecewiseQuasiTrig.from_expression(sympy.cos(S) - value)
    return PiecewiseQuasiTrig.from_expressions([sympy.cos(S) - value, 0], [point])


def contact_step_function(kappa: Scalar) -> PiecewiseQuasiTrig:
    """``H(cos s - kappa)`` as a piecewise function with breakpoint ``beta = acos(kappa)``.

    Examples
    --------
    >>> contact_step_function(0).integral()
    pi/2
    """
    point, regime = _contact_breakpoint(kappa)
    if regime == "none":
        return PiecewiseQuasiTrig.constant(0)
    if regime == "all":
        return PiecewiseQuasiTrig.constant(1)
    return PiecewiseQuasiTrig.from_expressions([1, 0], [point])
