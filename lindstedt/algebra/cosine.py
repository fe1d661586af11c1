"""Exact algebra of even 2π-periodic cosine polynomials.

The objects are finite sums ``v(s) = Σ_n c_n cos(n s)`` (``CosineSeries``) and
their derivatives ``Σ_n c_n sin(n s)`` (``SineSeries``), with coefficients in a
sympy *domain* (``QQ``, a polynomial ring ``QQ[r1, ...]``, or a
``RealField`` of a chosen precision).  Products use the product-to-sum rule

    cos(m s) cos(n s) = ½ [cos((m + n) s) + cos(|m − n| s)],

and the one differential equation the Lindstedt–Poincaré hierarchy needs is
solved in closed form:

    α0 (v'' + v) = r(s),   r even, 2π-periodic, with zero cos(s) coefficient,

whose even periodic solutions are ``v = Σ_{n≠1} r_n / (α0 (1 − n²)) cos(n s)
+ C cos(s)`` with ``C`` fixed by a normalisation (``v(0)`` given, or zero
first-harmonic coefficient).  No ``dsolve`` and no ``simplify`` are used: all
work is domain arithmetic on dictionaries, which is where the speed comes from.
"""

from __future__ import annotations

from typing import Any, Callable, Iterable, Mapping

import gmpy2
import numpy as np
import sympy
from sympy import Rational

from .._errors import LindstedtError
from .._precision import locked, locked_methods, workprec

# Series at least this long multiply through one integer product (_doubled_product_sum) rather than the
# pairwise loop: the crossover measured here is near 8 terms for gmpy rationals and 32 for mpf floats.
_DENSE_EXACT_TERMS = 8
_DENSE_FLOAT_TERMS = 32

__all__ = ["CosineSeries", "SineSeries", "solve_harmonic_oscillator"]

DomainElement = Any


@locked_methods()
class _TrigonometricSeries:
    """Shared machinery of cosine and sine series (dictionary of harmonics)."""

    __slots__ = ("domain", "_coefficients")
    _basis: Callable[[Any], Any]
    _numpy_basis: Callable[[np.ndarray], np.ndarray]

    def __init__(self, domain: Any, coefficients: Mapping[int, DomainElement] | None = None):
        self.domain = domain
        cleaned: dict[int, DomainElement] = {}
        for harmonic, value in (coefficients or {}).items():
            if harmonic < 0:
                raise ValueError(f"harmonic index must be >= 0, got {harmonic}")
            if value:
                cleaned[int(harmonic)] = value
        self._coefficients = cleaned

    # -- read access -------------------------------------------------------------
    @property
    def coefficients(self) -> dict[int, DomainElement]:
        """A copy of the nonzero coefficients, keyed by harmonic number."""
        return dict(self._coefficients)

    def coefficient(self, harmonic: int) -> DomainElement:
        """Coefficient of harmonic ``harmonic`` (the domain's zero if absent)."""
        return self._coefficients.get(harmonic, self.domain.zero)

    @property
    def harmonics(self) -> list[int]:
        """Sorted harmonic numbers with a nonzero coefficient."""
        return sorted(self._coefficients)

    @property
    def degree(self) -> int:
        """Highest harmonic present (−1 for the zero series)."""
        return max(self._coefficients, default=-1)

    def is_zero(self) -> bool:
        """True when every coefficient vanishes."""
        return not self._coefficients

    def __len__(self) -> int:
        return len(self._coefficients)

    def __eq__(self, other: object) -> bool:
        if type(other) is not type(self):
            return NotImplemented
        return self._coefficients == other._coefficients  # type: ignore[attr-defined]

    def __hash__(self) -> int:
        return hash((type(self).__name__, tuple(sorted(self._coefficients.items(), key=lambda kv: kv[0]))))

    # -- linear structure ----------------------------------------------------------
    def _new(self, coefficients: Mapping[int, DomainElement]):
        return type(self)(self.domain, coefficients)

    def __add__(self, other):
        if type(other) is not type(self):
            return NotImplemented
        result = dict(self._coefficients)
        for harmonic, value in other._coefficients.items():
            result[harmonic] = result.get(harmonic, self.domain.zero) + value
        return self._new(result)

    def __sub__(self, other):
        if type(other) is not type(self):
            return NotImplemented
        return self + (-other)

    def __neg__(self):
        return self._new({n: -c for n, c in self._coefficients.items()})

    def scale(self, factor: DomainElement):
        """Multiply every coefficient by the domain element ``factor``."""
        if not factor:
            return self._new({})
        return self._new({n: c * factor for n, c in self._coefficients.items()})

    def pruned(self, tolerance: float):
        """Drop coefficients whose magnitude is below ``tolerance`` (float domains)."""
        return self._new({n: c for n, c in self._coefficients.items() if abs(c) > tolerance})

    # -- conversion and evaluation ---------------------------------------------------
    def to_expr(self, variable: sympy.Symbol, to_sympy: Callable[[DomainElement], sympy.Expr] | None = None) -> sympy.Expr:
        """The series as a sympy expression in ``variable``."""
        convert = to_sympy or self.domain.to_sympy
        return sympy.Add(*[convert(c) * type(self)._basis(n * variable) for n, c in sorted(self._coefficients.items())])

    def float_coefficients(self, to_float: Callable[[DomainElement], float] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Arrays ``(harmonics, coefficients)`` in float64 for fast evaluation."""
        convert = to_float or (lambda c: float(self.domain.to_sympy(c)))
        items = sorted(self._coefficients.items())
        harmonics = np.array([n for n, _ in items], dtype=float)
        values = np.array([convert(c) for _, c in items], dtype=float)
        return harmonics, values

    def evaluate_float(self, s: Any, to_float: Callable[[DomainElement], float] | None = None) -> np.ndarray:
        """Evaluate at float ``s`` (scalar or array), vectorised with numpy."""
        harmonics, values = self.float_coefficients(to_float)
        points = np.asarray(s, dtype=float)
        if harmonics.size == 0:
            return np.zeros_like(points)
        return np.tensordot(type(self)._numpy_basis(np.multiply.outer(points, harmonics)), values, axes=([-1], [0]))


@locked_methods()
class CosineSeries(_TrigonometricSeries):
    """Even cosine polynomial ``Σ_n c_n cos(n s)`` with coefficients in a sympy domain.

    Parameters
    ----------
    domain : sympy domain
        Where the coefficients live (``QQ``, ``QQ[r]``, ``RealField(...)``).
    coefficients : mapping int -> domain element
        Coefficient of ``cos(n s)`` for harmonic ``n >= 0``; zeros are dropped.

    Examples
    --------
    >>> from sympy import QQ
    >>> c = CosineSeries.cosine(QQ)
    >>> (c ** 3).coefficients == {1: QQ(3, 4), 3: QQ(1, 4)}
    True
    """

    __slots__ = ("_integer_form",)  # the _IntegerForm of a rational series, cached by its first product
    _basis = staticmethod(sympy.cos)
    _numpy_basis = staticmethod(np.cos)

    @classmethod
    def constant(cls, domain: Any, value: DomainElement) -> "CosineSeries":
        """The constant function ``value``."""
        return cls(domain, {0: value})

    @classmethod
    def cosine(cls, domain: Any, harmonic: int = 1, amplitude: DomainElement | None = None) -> "CosineSeries":
        """``amplitude · cos(harmonic · s)`` (amplitude defaults to one)."""
        return cls(domain, {harmonic: domain.one if amplitude is None else amplitude})

    def __mul__(self, other):
        if isinstance(other, CosineSeries):
            return self._product(other)
        if isinstance(other, _TrigonometricSeries):
            return NotImplemented
        return self.scale(other)

    __rmul__ = __mul__

    def _product(self, other: "CosineSeries") -> "CosineSeries":
        shorter = min(len(self._coefficients), len(other._coefficients))
        if self.domain.is_Exact:
            if shorter >= _DENSE_EXACT_TERMS and self.domain.is_QQ:
                return self._rational_product(other)
        elif shorter >= _DENSE_FLOAT_TERMS:
            return self._fixed_point_product(other)
        half = _half(self.domain)
        accumulated: dict[int, DomainElement] = {}
        zero = self.domain.zero
        for m, a in self._coefficients.items():
            for n, b in other._coefficients.items():
                product = a * b
                total = m + n
                accumulated[total] = accumulated.get(total, zero) + product
                difference = m - n if m >= n else n - m
                accumulated[difference] = accumulated.get(difference, zero) + product
        return CosineSeries(self.domain, {n: c * half for n, c in accumulated.items()})

    def _rational_product(self, other: "CosineSeries") -> "CosineSeries":
        """The product of two rational series through one integer product-to-sum (:func:`sum_of_products`)."""
        return sum_of_products([(self, other)], self.domain)

    def _fixed_point_product(self, other: "CosineSeries") -> "CosineSeries":
        """The product of two long float series through one exact integer product-to-sum.

        Each coefficient m·2^e (mpf mantissa and exponent) becomes the integer m·2^(e − e_min) of its
        series, exactly; :func:`_doubled_product_sum` sums over m + n and |m − n| without rounding, and
        each result is rounded once to the domain.  So it is at least as accurate as the pairwise mpf
        loop (whose sums round at every step) and faster: 1/(1−u) − 1 − u at a0 = 0.99, order 6,
        30 digits took 25.9 s with the loop (two 600-term series: 1.08 s per product) and 2.8 s with
        this integer product.
        """
        import mpmath

        def integers(series: "CosineSeries") -> tuple[dict[int, int], int]:
            parts = {}  # harmonic: (signed mantissa, exponent), from the mpf's (sign, man, exp, bc)
            for harmonic, value in series._coefficients.items():
                sign, mantissa, exponent, _ = value._mpf_  # not mpmath.mpf(value): that rounds to mp.prec
                if mantissa:
                    parts[harmonic] = (-int(mantissa) if sign else int(mantissa), exponent)
            lowest = min((exponent for _, exponent in parts.values()), default=0)
            return {harmonic: mantissa << (exponent - lowest) for harmonic, (mantissa, exponent) in parts.items()}, lowest

        (first, first_exponent), (second, second_exponent) = integers(self), integers(other)
        first, second = _IntegerForm(first), _IntegerForm(second)
        exponent = first_exponent + second_exponent - 1  # the 1/2 of the product-to-sum rule
        dtype = self.domain.dtype
        with workprec(self.domain.precision):  # the one rounding, to the domain's precision
            result = {n: dtype(mpmath.mpf((total, exponent))) for n, total in _doubled_product_sum([(first, second, 1)]).items()}
        return CosineSeries(self.domain, result)

    def product_coefficient(self, other: "CosineSeries", harmonic: int) -> DomainElement:
        """Coefficient of ``cos(harmonic s)`` in ``self * other`` without forming the product.

        This is what makes the frequency correction of the next order cheap:
        only the secular (``harmonic = 1``) coefficient is needed.
        """
        zero = self.domain.zero
        total = zero
        other_coefficients = other._coefficients
        for m, a in self._coefficients.items():
            for n in {harmonic - m, m - harmonic, m + harmonic}:
                if n < 0 or n not in other_coefficients:
                    continue
                b = other_coefficients[n]
                # cos(m s) cos(n s) contributes ½ to harmonic m+n and ½ to |m-n|.
                weight = (1 if m + n == harmonic else 0) + (1 if abs(m - n) == harmonic else 0)
                if weight:
                    total = total + a * b * weight
        return total * _half(self.domain)

    def __pow__(self, exponent: int) -> "CosineSeries":
        if not isinstance(exponent, int) or exponent < 0:
            raise ValueError("CosineSeries powers must be non-negative integers")
        return power_by_squaring(self, exponent, CosineSeries.constant(self.domain, self.domain.one))

    def second_derivative(self) -> "CosineSeries":
        """``d²/ds²``: multiplies ``c_n`` by ``−n²``."""
        if self.domain.is_QQ:  # a rational times a Python int: no domain conversion per coefficient
            return self._new({n: c * (-n * n) for n, c in self._coefficients.items()})
        return self._new({n: c * self.domain.convert(-n * n) for n, c in self._coefficients.items()})

    def derivative(self) -> "SineSeries":
        """``d/ds Σ c_n cos(ns) = Σ (−n c_n) sin(ns)``."""
        return SineSeries(self.domain, {n: c * self.domain.convert(-n) for n, c in self._coefficients.items() if n})

    def value_at_zero(self) -> DomainElement:
        """``v(0) = Σ c_n`` exactly."""
        total = self.domain.zero
        for c in self._coefficients.values():
            total = total + c
        return total

    def __repr__(self) -> str:
        terms = " + ".join(f"({c})*cos({n}s)" for n, c in sorted(self._coefficients.items()))
        return f"CosineSeries({terms or '0'})"


@locked_methods()
class SineSeries(_TrigonometricSeries):
    """Odd sine polynomial ``Σ_n c_n sin(n s)`` (derivatives of cosine series).

    Examples
    --------
    >>> from sympy import QQ
    >>> CosineSeries.cosine(QQ, 2).derivative().coefficients == {2: QQ(-2)}
    True
    """

    __slots__ = ()
    _basis = staticmethod(sympy.sin)
    _numpy_basis = staticmethod(np.sin)

    def derivative(self) -> CosineSeries:
        """``d/ds Σ c_n sin(ns) = Σ n c_n cos(ns)``."""
        return CosineSeries(self.domain, {n: c * self.domain.convert(n) for n, c in self._coefficients.items()})

    def __repr__(self) -> str:
        terms = " + ".join(f"({c})*sin({n}s)" for n, c in sorted(self._coefficients.items()))
        return f"SineSeries({terms or '0'})"


class SecularTermError(LindstedtError):
    """The right-hand side of the periodic solve still contains a cos(s) term."""


@locked
def solve_harmonic_oscillator(
    right_hand_side: CosineSeries,
    alpha0: DomainElement,
    *,
    value_at_zero: DomainElement | None = None,
    first_harmonic: DomainElement | None = None,
) -> CosineSeries:
    """Even 2π-periodic solution of ``α0 (v'' + v) = rhs``.

    Parameters
    ----------
    right_hand_side : CosineSeries
        Must have a zero ``cos(s)`` coefficient (no secular term).
    alpha0 : domain element
        The nonzero factor ``α0 = ω0²``.
    value_at_zero, first_harmonic : domain element, exactly one of them
        Fix the free homogeneous part ``C cos(s)``: either ``v(0)`` equals
        ``value_at_zero`` ("initial" normalisation) or the ``cos(s)``
        coefficient of ``v`` equals ``first_harmonic`` ("harmonic" one).

    Returns
    -------
    CosineSeries
        ``v = Σ_{n≠1} rhs_n / (α0 (1 − n²)) cos(ns) + C cos(s)``.

    Raises
    ------
    SecularTermError
        If the right-hand side has a nonzero ``cos(s)`` coefficient.

    Examples
    --------
    >>> from sympy import QQ
    >>> rhs = CosineSeries.cosine(QQ, 3)
    >>> v = solve_harmonic_oscillator(rhs, QQ(1), value_at_zero=QQ(0))
    >>> v.coefficients == {3: QQ(-1, 8), 1: QQ(1, 8)}
    True
    """
    if (value_at_zero is None) == (first_harmonic is None):
        raise ValueError("give exactly one of value_at_zero and first_harmonic")
    domain = right_hand_side.domain
    if right_hand_side.coefficient(1):
        raise SecularTermError(
            "the right-hand side has a secular cos(s) coefficient "
            f"{right_hand_side.coefficient(1)}; choose the frequency correction that removes it"
        )
    inverse_alpha0 = domain.one / alpha0 if alpha0 != domain.one else domain.one
    particular: dict[int, DomainElement] = {}
    # 1/(1 − n²) as a gmpy rational over QQ (sympy's convert of a Rational: 13 % of Duffing order 100)
    divisor = (lambda n: domain.dtype(1, 1 - n * n)) if domain.is_QQ else (lambda n: domain.convert(Rational(1, 1 - n * n)))
    for harmonic, value in right_hand_side._coefficients.items():
        particular[harmonic] = value * inverse_alpha0 * divisor(harmonic)
    if first_harmonic is not None:
        particular[1] = first_harmonic
    else:
        total = domain.zero
        for value in particular.values():
            total = total + value
        particular[1] = value_at_zero - total
    return CosineSeries(domain, particular)


def _half(domain: Any) -> DomainElement:
    """½ in ``domain``; over ``QQ`` a gmpy rational directly (sympy's convert of a Rational cost a third of
    Duffing at order 10)."""
    return domain.dtype(1, 2) if domain.is_QQ else domain.convert(Rational(1, 2))


def power_by_squaring(base: Any, exponent: int, one: Any) -> Any:
    """``base ** exponent`` (exponent ≥ 0) by repeated squaring: ~2 log2(exponent) products."""
    result = one
    while exponent:
        if exponent & 1:
            result = result * base
        exponent >>= 1
        if exponent:
            base = base * base
    return result


def sum_series(terms: Iterable[CosineSeries], domain: Any) -> CosineSeries:
    """Sum of cosine series (the zero series for an empty iterable)."""
    accumulated: dict[int, DomainElement] = {}
    zero = domain.zero
    for term in terms:
        for harmonic, value in term._coefficients.items():
            accumulated[harmonic] = accumulated.get(harmonic, zero) + value
    return CosineSeries(domain, accumulated)


def _pack(values: list[int], bits: int) -> Any:
    """``Σ_i values[i] 2^(bits·i)`` for signed integers: two ``gmpy2.pack`` of the positive and negative parts.

    Measured at Duffing order 100: ``int.to_bytes`` and ``bytes.join`` (the packing before gmpy2.pack)
    took 34 % of the run.
    """
    return gmpy2.pack([v if v > 0 else 0 for v in values], bits) - gmpy2.pack([-v if v < 0 else 0 for v in values], bits)


def _unpack(total: Any, count: int, bits: int) -> list[Any]:
    """The ``count`` signed digits ``d_i`` (|d_i| < 2^(bits−1)) of ``total = Σ_i d_i 2^(bits·i)``.

    Every digit is lifted by 2^(bits−1) (one packed constant), which makes them the unsigned digits
    ``gmpy2.unpack`` reads; each lifted digit is nonzero, so exactly ``count`` come back.
    """
    half = 1 << (bits - 1)
    return [digit - half for digit in gmpy2.unpack(total + gmpy2.pack([half] * count, bits), bits)]


def _digit_bits(bits: int) -> int:
    """``bits`` rounded up to one of eight widths per octave (a packed form then serves many sums, ≤ 12.5 % wider)."""
    step = 1 << max(bits.bit_length() - 4, 3)
    return -(-bits // step) * step


class _IntegerForm:
    """A rational series as integers over one denominator, with its packed forms (cached on the series).

    ``values[i]`` is ``L c_n`` for ``n = stride·i + offset``; ``stride`` is 2 when every harmonic has
    one parity (Duffing's odd waveforms and even powers), which halves the packed integers.  A
    waveform enters ~2N products and N linear combinations up to order N: it is packed once per
    digit width (:func:`_digit_bits`) and direction, not once per product.
    """

    __slots__ = ("denominator", "bits", "stride", "offset", "values", "_packed")

    def __init__(self, coefficients: Mapping[int, Any]):
        common = 1
        for value in coefficients.values():
            common = gmpy2.lcm(common, value.denominator)
        parities = {n & 1 for n in coefficients}
        self.stride, self.offset = (2, parities.pop()) if len(parities) == 1 else (1, 0)
        self.denominator = common
        self.values = self._dense(coefficients, self.stride, self.offset)
        self.bits = max(abs(v) for v in self.values).bit_length()
        self._packed: dict[tuple[int, int, bool], Any] = {}

    def _dense(self, coefficients: Mapping[int, Any], stride: int, offset: int) -> list[Any]:
        values = [0] * ((max(coefficients) - offset) // stride + 1)
        common = self.denominator
        for n, value in coefficients.items():
            values[(n - offset) // stride] = value.numerator * (common // value.denominator)
        return values

    def packed_length(self, stride: int) -> int:
        """Entries of the dense vector at ``stride``."""
        return len(self.values) if stride == self.stride else self.offset + 2 * len(self.values) - 1

    def packed(self, bits: int, stride: int, reverse: bool = False) -> tuple[Any, int]:
        """(packed integer, length) of the values at ``stride`` (1 unpacks a stride-2 form), reversed if asked."""
        key = (bits, stride, reverse)
        if key not in self._packed:
            values = self.values
            if stride != self.stride:  # stride 1 from stride 2: interleave zeros
                values = [0] * (self.offset + 2 * len(self.values) - 1)
                values[self.offset::2] = self.values
            self._packed[key] = (_pack(values[::-1] if reverse else values, bits), len(values))
        return self._packed[key]


def _integer_form(series: CosineSeries) -> _IntegerForm:
    try:
        return series._integer_form
    except AttributeError:
        series._integer_form = _IntegerForm(series._coefficients)
        return series._integer_form


def sum_of_products(pairs: Iterable[tuple[CosineSeries, CosineSeries]], domain: Any) -> CosineSeries:
    """``Σ_j a_j b_j`` for cosine series ``(a_j, b_j)``: one exact integer computation for rational series.

    Over ``QQ`` every series is put over the lcm of its denominators (:class:`_IntegerForm`), the
    products of a sum are scaled to one common denominator, multiplied as packed integers (Kronecker
    substitution, :func:`_doubled_product_sum`) and added, and the digits are read back and reduced
    once per sum — not once per product.  Other domains (and short rational series, where the loop
    is faster) sum the products.
    """
    pairs = [(a, b) for a, b in pairs if a._coefficients and b._coefficients]
    if not domain.is_QQ or not pairs or max(min(len(a._coefficients), len(b._coefficients)) for a, b in pairs) < _DENSE_EXACT_TERMS:
        return sum_series((a * b for a, b in pairs), domain)
    forms = [(_integer_form(a), _integer_form(b)) for a, b in pairs]
    denominator = 1
    for first, second in forms:
        denominator = gmpy2.lcm(denominator, first.denominator * second.denominator)
    doubled = _doubled_product_sum([(a, b, denominator // (a.denominator * b.denominator)) for a, b in forms])
    dtype, twice = domain.dtype, 2 * denominator
    return CosineSeries(domain, {n: dtype(total, twice) for n, total in doubled.items()})


def linear_combination(factors: list[DomainElement], terms: list[CosineSeries], domain: Any) -> CosineSeries:
    """``Σ_j factors[j] · terms[j]``; over ``QQ`` one packed integer sum read back once (the waveform's
    ``Σ_i A_i w''_{k−i}``: at Duffing order 100 the series-by-series sum took a third of the run)."""
    pairs = [(factor, term) for factor, term in zip(factors, terms) if factor and term._coefficients]
    if not domain.is_QQ or len(pairs) < 2:
        return sum_series((term.scale(factor) for factor, term in pairs), domain)
    forms = [(factor, _integer_form(term)) for factor, term in pairs]
    stride = 2 if len({(form.stride, form.offset) for _, form in forms}) == 1 and forms[0][1].stride == 2 else 1
    offset = forms[0][1].offset if stride == 2 else 0
    denominator = 1
    for factor, form in forms:
        denominator = gmpy2.lcm(denominator, factor.denominator * form.denominator)
    scales = [factor.numerator * (denominator // (factor.denominator * form.denominator)) for factor, form in forms]
    bound = max(scale.bit_length() + form.bits for scale, (_, form) in zip(scales, forms)) + len(forms).bit_length() + 1
    bits = _digit_bits(bound)
    total, length = 0, 0
    for scale, (_, form) in zip(scales, forms):
        packed, size = form.packed(bits, stride)
        total += packed * scale
        length = max(length, size)
    dtype = domain.dtype
    return CosineSeries(domain, {stride * index + offset: dtype(value, denominator)
                                 for index, value in enumerate(_unpack(total, length, bits)) if value})


def _doubled_product_sum(terms: list[tuple[_IntegerForm, _IntegerForm, Any]]) -> dict[int, Any]:
    """``Σ_j scale_j · 2 (a_j · b_j)`` for integer cosine series: sums over m + n and |m − n| = k.

    Kronecker substitution: each vector is packed into one integer (digits wide enough for every
    signed sum), so a convolution is one multiplication — GMP's subquadratic one — and the
    correlation (|m − n|) is the convolution with the second vector reversed.  Terms whose
    harmonics share a layout are added as packed integers and read back once; the packed forms
    are cached on the series (:class:`_IntegerForm`): at Duffing order 100 (7,100 products) the
    operands are packed ~5,000 times instead of 21,300.  What is left there is GMP's
    multiplications, ~0.15 s of the 0.3 s (products of ~n/2 entries of ~5n bits, ~1.5n per order n).

    Tried and measured slower at orders ≤ 100 (``MAX_ORDER``): relaxed multiplication in the
    order index (pairs (i, j) tiled by squares computed once each, van der Hoeven's tiling cut at
    the requested order): as one bivariate Kronecker product per square, 0.52 s against 0.30 s at
    order 100 (the order slots double both operands); by Karatsuba on the packed series, 0.32 s
    (the squares' multiplications halve, their common denominators and read-backs eat the gain).
    """
    groups: dict[tuple[int, int, int], list[tuple[_IntegerForm, _IntegerForm, Any]]] = {}
    for a, b, scale in terms:
        stride = 2 if a.stride == b.stride == 2 else 1
        groups.setdefault((stride, a.offset if stride == 2 else 0, b.offset if stride == 2 else 0), []).append((a, b, scale))
    result: dict[int, Any] = {}
    for (stride, a_offset, b_offset), members in groups.items():
        a_length = max(a.packed_length(stride) for a, _, _ in members)
        b_length = max(b.packed_length(stride) for _, b, _ in members)
        bound = max(a.bits + b.bits + scale.bit_length() for a, b, scale in members)
        bits = _digit_bits(bound + min(a_length, b_length).bit_length() + len(members).bit_length() + 1)
        sums = correlation = 0
        for a, b, scale in members:
            packed_a, _ = a.packed(bits, stride)
            packed_b, _ = b.packed(bits, stride)
            reversed_b, length = b.packed(bits, stride, reverse=True)
            term, mirrored = packed_a * packed_b, packed_a * reversed_b
            if scale != 1:
                term, mirrored = term * scale, mirrored * scale
            sums += term
            # b reversed at its own length, aligned to the group's longest b
            correlation += mirrored << (bits * (b_length - length)) if length != b_length else mirrored
        _fold(sums, correlation, a_length, b_length, bits, stride, a_offset, b_offset, result)
    return {n: value for n, value in result.items() if value}


def _fold(sums: Any, correlation: Any, a_length: int, b_length: int, bits: int, stride: int, a_offset: int, b_offset: int,
          result: dict[int, Any]) -> None:
    """Add the digits of a packed convolution and correlation to ``result`` (harmonic: doubled product).

    Sum digit i is harmonic stride·i + a_offset + b_offset; correlation digit i is |stride·i + shift|
    (b reversed at ``b_length``), its negative part folding back.  Dense lists, no dictionary per digit.
    """
    count = a_length + b_length - 1
    dense = [0] * (stride * (count - 1) + a_offset + b_offset + 1)
    dense[a_offset + b_offset::stride] = _unpack(sums, count, bits)
    mirrored = _unpack(correlation, count, bits)
    shift = a_offset - b_offset - stride * (b_length - 1)
    first = -(shift // stride)  # first digit with stride·i + shift >= 0
    positive, negative = mirrored[first:], mirrored[:first][::-1]
    start = stride * first + shift
    dense[start:start + stride * len(positive):stride] = [x + y for x, y in zip(dense[start::stride], positive)]
    if negative:  # harmonics −(stride·i + shift) for i = first − 1, first − 2, …
        start = -(stride * (first - 1) + shift)
        dense[start:start + stride * len(negative):stride] = [x + y for x, y in zip(dense[start::stride], negative)]
    for harmonic, value in enumerate(dense):
        if value:
            result[harmonic] = result.get(harmonic, 0) + value

