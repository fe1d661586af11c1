"""Exact truncated power series over the rationals.

A :class:`PowerSeries` is ``c_0 + c_1 x + ... + c_n x**n + O(x**(n+1))`` whose
coefficients are exact rationals, held either as :class:`fractions.Fraction`
(fast, the default) or as :class:`sympy.Rational`.  It provides the arithmetic
needed to build exact Taylor expansions of closed-form references:
addition, multiplication, the reciprocal, composition, reversion (the
compositional inverse), square roots and arbitrary rational powers.

Every operation is exact; the truncation order of a result is the smallest
order that its operands determine (for example ``f * g`` is known to order
``min(f.order, g.order)``).

Algorithms
----------
* reciprocal: the recurrence ``b_n = -(1/c_0) sum_{k=1..n} c_k b_{n-k}``;
* rational power ``c**p``: J. C. P. Miller's recurrence
  ``n c_0 b_n = sum_{k=1..n} ((p + 1) k - n) c_k b_{n-k}``, which follows from
  ``c b' = p c' b`` for ``b = c**p``;
* composition ``f(g(x))`` with ``g(0) = 0``: Horner's scheme;
* reversion: Lagrange inversion, ``[x^n] g = (1/n) [w^(n-1)] (w/f(w))**n``.
"""

from __future__ import annotations

import math
from fractions import Fraction
from numbers import Rational as _AbstractRational
from typing import Any, Iterable, Union

import sympy

from ._errors import OrderError, ProblemError

__all__ = ["PowerSeries", "binomial_series"]

Coefficient = Union[Fraction, sympy.Rational]

_MAXIMUM_ORDER = 10_000


def _is_sympy_number(value: Any) -> bool:
    return isinstance(value, sympy.Basic)


def _to_fraction(value: Any) -> Fraction:
    """Convert an exact rational (int, Fraction, sympy Rational) to a Fraction."""
    if isinstance(value, bool):
        raise ProblemError(f"power-series coefficient {value!r} is a bool; pass an int or a Fraction")
    if isinstance(value, Fraction):
        return value
    if isinstance(value, int):
        return Fraction(value)
    if isinstance(value, sympy.Basic):
        if isinstance(value, sympy.Rational):
            return Fraction(int(value.p), int(value.q))
        raise ProblemError(
            f"power-series coefficient {value!r} is not an exact rational; "
            "pass sympy.Rational / Integer values (use sympy.nsimplify to convert)"
        )
    if isinstance(value, _AbstractRational):
        return Fraction(int(value.numerator), int(value.denominator))
    raise ProblemError(
        f"power-series coefficient {value!r} of type {type(value).__name__} is not an exact "
        "rational; use int, fractions.Fraction or sympy.Rational (floats are not exact)"
    )


def _to_sympy_rational(value: Any) -> sympy.Rational:
    fraction = _to_fraction(value)
    return sympy.Rational(fraction.numerator, fraction.denominator)


def _validate_order(order: Any) -> int:
    if isinstance(order, bool) or not isinstance(order, int):
        raise OrderError(f"series order must be an int, got {order!r}")
    if order < 0:
        raise OrderError(f"series order must be >= 0, got {order}")
    if order > _MAXIMUM_ORDER:
        raise OrderError(f"series order {order} exceeds the supported maximum {_MAXIMUM_ORDER}")
    return order


def _integer_root(value: int, degree: int) -> int | None:
    """Return the exact non-negative ``degree``-th root of ``value >= 0`` or None."""
    if value < 0:
        return None
    if value < 2:
        return value
    if degree == 2:
        root = math.isqrt(value)
    else:
        # Integer Newton iteration started above the root decreases to floor(root).
        root = 1 << -(-value.bit_length() // degree)
        while True:
            better = ((degree - 1) * root + value // root ** (degree - 1)) // degree
            if better >= root:
                break
            root = better
    return root if root**degree == value else None


def _exact_rational_power(base: Fraction, exponent: Fraction) -> Fraction | None:
    """``base**exponent`` if it is rational (real), else None."""
    if exponent.denominator == 1:
        if base == 0 and exponent < 0:
            return None
        return base ** int(exponent)
    degree = exponent.denominator
    sign = 1
    if base < 0:
        if degree % 2 == 0:
            return None
        sign = -1
    numerator_root = _integer_root(abs(base.numerator), degree)
    denominator_root = _integer_root(base.denominator, degree)
    if numerator_root is None or denominator_root is None:
        return None
    root = Fraction(sign * numerator_root, denominator_root)
    if root == 0 and exponent < 0:
        return None
    return root ** exponent.numerator


class PowerSeries:
    """Exact truncated power series ``sum_{k=0..order} c_k x**k + O(x**(order+1))``.

    Parameters
    ----------
    coefficients : sequence of exact rationals
        ``c_0, c_1, ...`` as ``int``, :class:`fractions.Fraction` or
        :class:`sympy.Rational`.  Missing coefficients up to ``order`` are zero;
        coefficients beyond ``order`` are dropped.
    order : int, optional
        Truncation order ``n`` (the highest power kept).  Defaults to
        ``len(coefficients) - 1``.
    use_sympy : bool, optional
        Hold coefficients as :class:`sympy.Rational` instead of
        :class:`fractions.Fraction`.  Defaults to True if any input coefficient
        is a sympy number.  Operations mixing the two kinds give sympy series.

    Examples
    --------
    >>> from fractions import Fraction
    >>> one_plus_x = PowerSeries([1, 1], order=4)
    >>> one_plus_x.sqrt().coefficients
    (Fraction(1, 1), Fraction(1, 2), Fraction(-1, 8), Fraction(1, 16), Fraction(-5, 128))
    >>> (one_plus_x.inverse() * one_plus_x).coefficients
    (Fraction(1, 1), Fraction(0, 1), Fraction(0, 1), Fraction(0, 1), Fraction(0, 1))
    >>> PowerSeries([0, 1, 1], order=4).reversion().coefficients  # x + x**2 -> Catalan
    (Fraction(0, 1), Fraction(1, 1), Fraction(-1, 1), Fraction(2, 1), Fraction(-5, 1))
    """

    __slots__ = ("_coefficients", "_order", "_use_sympy")

    def __init__(
        self,
        coefficients: Iterable[Any],
        order: int | None = None,
        *,
        use_sympy: bool | None = None,
    ) -> None:
        values = list(coefficients)
        if order is None:
            if not values:
                raise ProblemError("an empty coefficient list needs an explicit order")
            order = len(values) - 1
        order = _validate_order(order)
        if use_sympy is None:
            use_sympy = any(_is_sympy_number(value) for value in values)
        fractions_ = [_to_fraction(value) for value in values[: order + 1]]
        fractions_ += [Fraction(0)] * (order + 1 - len(fractions_))
        if use_sympy:
            self._coefficients: tuple[Coefficient, ...] = tuple(
                sympy.Rational(value.numerator, value.denominator) for value in fractions_
            )
        else:
            self._coefficients = tuple(fractions_)
        self._order = order
        self._use_sympy = bool(use_sympy)

    # ------------------------------------------------------------------ basics
    @classmethod
    def _raw(cls, coefficients: list[Any], order: int, use_sympy: bool) -> "PowerSeries":
        """Build without validation from coefficients already of the right kind."""
        series = object.__new__(cls)
        series._coefficients = tuple(coefficients[: order + 1])
        series._order = order
        series._use_sympy = use_sympy
        return series

    @classmethod
    def variable(cls, order: int, *, use_sympy: bool = False) -> "PowerSeries":
        """The series ``x`` truncated at ``order``.

        Examples
        --------
        >>> PowerSeries.variable(3).coefficients
        (Fraction(0, 1), Fraction(1, 1), Fraction(0, 1), Fraction(0, 1))
        """
        order = _validate_order(order)
        return cls([0, 1][: order + 1], order, use_sympy=use_sympy)

    @classmethod
    def constant(cls, value: Any, order: int, *, use_sympy: bool | None = None) -> "PowerSeries":
        """The constant series ``value + 0 x + ...`` truncated at ``order``.

        Examples
        --------
        >>> PowerSeries.constant(3, 2).coefficients
        (Fraction(3, 1), Fraction(0, 1), Fraction(0, 1))
        """
        return cls([value], order, use_sympy=use_sympy)

    @property
    def coefficients(self) -> tuple[Coefficient, ...]:
        """The coefficients ``c_0 .. c_order``."""
        return self._coefficients

    @property
    def order(self) -> int:
        """The truncation order (the highest power of x that is known)."""
        return self._order

    @property
    def uses_sympy(self) -> bool:
        """True if the coefficients are sympy Rationals, False for Fractions."""
        return self._use_sympy

    def __len__(self) -> int:
        return self._order + 1

    def __getitem__(self, index: int) -> Coefficient:
        return self._coefficients[index]

    def __repr__(self) -> str:
        terms = ", ".join(str(value) for value in self._coefficients)
        return f"PowerSeries([{terms}], order={self._order})"

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, PowerSeries):
            return NotImplemented
        return self._order == other._order and all(
            _to_fraction(left) == _to_fraction(right)
            for left, right in zip(self._coefficients, other._coefficients)
        )

    def __hash__(self) -> int:
        return hash((self._order, tuple(_to_fraction(value) for value in self._coefficients)))

    def _zero(self) -> Coefficient:
        return sympy.Integer(0) if self._use_sympy else Fraction(0)

    def _one(self) -> Coefficient:
        return sympy.Integer(1) if self._use_sympy else Fraction(1)

    def _convert(self, value: Any) -> Coefficient:
        return _to_sympy_rational(value) if self._use_sympy else _to_fraction(value)

    def truncate(self, order: int) -> "PowerSeries":
        """Drop the terms above ``order`` (which must not exceed ``self.order``).

        Examples
        --------
        >>> PowerSeries([1, 2, 3]).truncate(1).coefficients
        (Fraction(1, 1), Fraction(2, 1))
        """
        order = _validate_order(order)
        if order > self._order:
            raise OrderError(
                f"cannot truncate a series known to order {self._order} at the higher order {order}"
            )
        return PowerSeries._raw(list(self._coefficients), order, self._use_sympy)

    def as_sympy(self) -> "PowerSeries":
        """The same series with sympy Rational coefficients."""
        if self._use_sympy:
            return self
        return PowerSeries(self._coefficients, self._order, use_sympy=True)

    def as_fractions(self) -> "PowerSeries":
        """The same series with :class:`fractions.Fraction` coefficients."""
        if not self._use_sympy:
            return self
        return PowerSeries(self._coefficients, self._order, use_sympy=False)

    def to_expression(self, symbol: sympy.Symbol) -> sympy.Expr:
        """The truncated polynomial ``sum c_k symbol**k`` as a sympy expression.

        Examples
        --------
        >>> import sympy
        >>> x = sympy.Symbol("x")
        >>> PowerSeries([1, 0, -1]).to_expression(x)
        1 - x**2
        """
        return sympy.Add(
            *(_to_sympy_rational(value) * symbol**power for power, value in enumerate(self._coefficients))
        )

    # --------------------------------------------------------------- coercion
    def _coerce(self, other: Any) -> tuple["PowerSeries", "PowerSeries"]:
        """Bring ``self`` and ``other`` (series or scalar) to a common kind and order."""
        if isinstance(other, PowerSeries):
            use_sympy = self._use_sympy or other._use_sympy
            left = self.as_sympy() if use_sympy else self
            right = other.as_sympy() if use_sympy else other
            order = min(left._order, right._order)
            if left._order != order:
                left = left.truncate(order)
            if right._order != order:
                right = right.truncate(order)
            return left, right
        use_sympy = self._use_sympy or _is_sympy_number(other)
        left = self.as_sympy() if use_sympy else self
        return left, PowerSeries.constant(other, self._order, use_sympy=use_sympy)

    # ------------------------------------------------------------- arithmetic
    def __add__(self, other: Any) -> "PowerSeries":
        try:
            left, right = self._coerce(other)
        except ProblemError:
            return NotImplemented
        values = [a + b for a, b in zip(left._coefficients, right._coefficients)]
        return PowerSeries._raw(values, left._order, left._use_sympy)

    __radd__ = __add__

    def __neg__(self) -> "PowerSeries":
        return PowerSeries._raw([-value for value in self._coefficients], self._order, self._use_sympy)

    def __sub__(self, other: Any) -> "PowerSeries":
        try:
            left, right = self._coerce(other)
        except ProblemError:
            return NotImplemented
        values = [a - b for a, b in zip(left._coefficients, right._coefficients)]
        return PowerSeries._raw(values, left._order, left._use_sympy)

    def __rsub__(self, other: Any) -> "PowerSeries":
        return (-self).__add__(other)

    def __mul__(self, other: Any) -> "PowerSeries":
        if not isinstance(other, PowerSeries):
            try:
                left, _ = self._coerce(other)
                scalar = left._convert(other)
            except ProblemError:
                return NotImplemented
            return PowerSeries._raw([value * scalar for value in left._coefficients], left._order, left._use_sympy)
        left, right = self._coerce(other)
        order = left._order
        first, second = left._coefficients, right._coefficients
        nonzero_second = [(index, value) for index, value in enumerate(second) if value != 0]
        values = [left._zero()] * (order + 1)
        for i, a_value in enumerate(first):
            if a_value == 0:
                continue
            for j, b_value in nonzero_second:
                if i + j > order:
                    break
                values[i + j] += a_value * b_value
        return PowerSeries._raw(values, order, left._use_sympy)

    __rmul__ = __mul__

    def __truediv__(self, other: Any) -> "PowerSeries":
        if isinstance(other, PowerSeries):
            return self * other.inverse()
        try:
            left, _ = self._coerce(other)
            scalar = left._convert(other)
        except ProblemError:
            return NotImplemented
        if scalar == 0:
            raise ZeroDivisionError("division of a power series by zero")
        return PowerSeries._raw([value / scalar for value in left._coefficients], left._order, left._use_sympy)

    def __rtruediv__(self, other: Any) -> "PowerSeries":
        return self.inverse() * other

    def __pow__(self, exponent: Any) -> "PowerSeries":
        return self.power(exponent)

    # ------------------------------------------------------ series operations
    def inverse(self) -> "PowerSeries":
        """The reciprocal ``1/f``; needs ``c_0 != 0``.

        Examples
        --------
        >>> PowerSeries([1, -1], order=3).inverse().coefficients  # 1/(1-x)
        (Fraction(1, 1), Fraction(1, 1), Fraction(1, 1), Fraction(1, 1))
        """
        coefficients = self._coefficients
        leading = coefficients[0]
        if leading == 0:
            raise ProblemError(
                "cannot invert a power series with zero constant term; "
                "factor out the leading power of x first"
            )
        inverse_leading = self._one() / leading
        values = [inverse_leading]
        for n in range(1, self._order + 1):
            total = self._zero()
            for k in range(1, n + 1):
                if coefficients[k] != 0:
                    total += coefficients[k] * values[n - k]
            values.append(-total * inverse_leading)
        return PowerSeries._raw(values, self._order, self._use_sympy)

    def power(self, exponent: Any) -> "PowerSeries":
        """``f**p`` for a rational exponent ``p`` (int, Fraction or sympy Rational).

        For non-integer ``p`` (or negative ``p``) the constant term must be
        nonzero and ``c_0**p`` must be rational; the principal real root is
        used.

        Examples
        --------
        >>> from fractions import Fraction
        >>> PowerSeries([1, 1], order=3).power(Fraction(-1, 2)).coefficients
        (Fraction(1, 1), Fraction(-1, 2), Fraction(3, 8), Fraction(-5, 16))
        >>> PowerSeries([4, 4, 1], order=3).power(Fraction(1, 2)).coefficients  # (2 + x)**2
        (Fraction(2, 1), Fraction(1, 1), Fraction(0, 1), Fraction(0, 1))
        """
        if isinstance(exponent, float):
            raise ProblemError(f"exponent {exponent!r} is a float; pass an exact Fraction or sympy.Rational")
        exponent_fraction = _to_fraction(exponent)
        if exponent_fraction.denominator == 1 and exponent_fraction >= 0:
            return self._nonnegative_integer_power(int(exponent_fraction))
        coefficients = self._coefficients
        leading = coefficients[0]
        if leading == 0:
            raise ProblemError(
                f"cannot raise a power series with zero constant term to the power {exponent_fraction}; "
                "factor out the leading power of x first"
            )
        leading_power = _exact_rational_power(_to_fraction(leading), exponent_fraction)
        if leading_power is None:
            raise ProblemError(
                f"the constant term {leading} has no rational {exponent_fraction} power; "
                "rescale the series so that its constant term is 1 (or an exact power)"
            )
        p = self._convert(exponent_fraction)
        values = [self._convert(leading_power)]
        for n in range(1, self._order + 1):
            total = self._zero()
            for k in range(1, n + 1):
                if coefficients[k] != 0:
                    total += ((p + 1) * k - n) * coefficients[k] * values[n - k]
            values.append(total / (n * leading))
        return PowerSeries._raw(values, self._order, self._use_sympy)

    def _nonnegative_integer_power(self, exponent: int) -> "PowerSeries":
        result = PowerSeries.constant(1, self._order, use_sympy=self._use_sympy)
        base = self
        while exponent:
            if exponent & 1:
                result = result * base
            exponent >>= 1
            if exponent:
                base = base * base
        return result

    def sqrt(self) -> "PowerSeries":
        """The principal square root; needs a constant term that is a rational square.

        Examples
        --------
        >>> PowerSeries([1, 0, 1], order=4).sqrt().coefficients  # sqrt(1 + x**2)
        (Fraction(1, 1), Fraction(0, 1), Fraction(1, 2), Fraction(0, 1), Fraction(-1, 8))
        """
        return self.power(Fraction(1, 2))

    def compose(self, inner: "PowerSeries") -> "PowerSeries":
        """``f(g(x))`` for an inner series ``g`` with ``g(0) = 0``.

        Examples
        --------
        >>> geometric = PowerSeries([1, 1, 1, 1])             # 1/(1 - y)
        >>> inner = PowerSeries([0, 1, -1, 1])                # y = x/(1 + x)
        >>> geometric.compose(inner).coefficients             # = 1 + x
        (Fraction(1, 1), Fraction(1, 1), Fraction(0, 1), Fraction(0, 1))
        """
        if not isinstance(inner, PowerSeries):
            raise ProblemError(f"compose needs a PowerSeries as inner series, got {type(inner).__name__}")
        outer, inner_series = self._coerce(inner)
        if inner_series._coefficients[0] != 0:
            raise ProblemError(
                "the inner series of a composition must have zero constant term "
                f"(got {inner_series._coefficients[0]}); expand the outer series about that value first"
            )
        order = outer._order
        result = PowerSeries.constant(outer._coefficients[order], order, use_sympy=outer._use_sympy)
        for index in range(order - 1, -1, -1):
            result = result * inner_series + outer._coefficients[index]
        return result

    def reversion(self) -> "PowerSeries":
        """The compositional inverse ``g`` with ``f(g(x)) = x``; needs ``c_0 = 0``, ``c_1 != 0``.

        Examples
        --------
        >>> PowerSeries([0, 1, -1, 1, -1]).reversion().coefficients  # x/(1+x) -> x/(1-x)
        (Fraction(0, 1), Fraction(1, 1), Fraction(1, 1), Fraction(1, 1), Fraction(1, 1))
        """
        coefficients = self._coefficients
        if self._order < 1:
            raise OrderError("reversion needs a series known at least to order 1")
        if coefficients[0] != 0:
            raise ProblemError(
                f"reversion needs a zero constant term, got {coefficients[0]}; subtract it first"
            )
        if coefficients[1] == 0:
            raise ProblemError(
                "reversion needs a nonzero linear coefficient (the series is not locally invertible)"
            )
        order = self._order
        # h(w) = w / f(w) = 1 / (c_1 + c_2 w + ...), known to order - 1.
        shifted = PowerSeries._raw(list(coefficients[1:]), order - 1, self._use_sympy)
        quotient = shifted.inverse()
        values = [self._zero()]
        quotient_power = PowerSeries.constant(1, order - 1, use_sympy=self._use_sympy)
        for n in range(1, order + 1):
            quotient_power = quotient_power * quotient
            values.append(quotient_power._coefficients[n - 1] / n)
        return PowerSeries._raw(values, order, self._use_sympy)

    def evaluate(self, point: Any) -> Any:
        """Evaluate the truncated polynomial at ``point`` (any number type) by Horner.

        Examples
        --------
        >>> from fractions import Fraction
        >>> PowerSeries([1, 2, 3]).evaluate(Fraction(1, 2))
        Fraction(11, 4)
        """
        result: Any = 0
        for value in reversed(self._coefficients):
            result = result * point + value
        return result


def binomial_series(exponent: Any, order: int) -> PowerSeries:
    """The series of ``(1 + x)**exponent`` with exact binomial coefficients.

    Examples
    --------
    >>> from fractions import Fraction
    >>> binomial_series(Fraction(1, 2), 3).coefficients
    (Fraction(1, 1), Fraction(1, 2), Fraction(-1, 8), Fraction(1, 16))
    """
    order = _validate_order(order)
    exponent_fraction = _to_fraction(exponent)
    values = [Fraction(1)]
    for k in range(1, order + 1):
        values.append(values[-1] * (exponent_fraction - k + 1) / k)
    return PowerSeries(values, order)
