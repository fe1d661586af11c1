"""Analytic branches: quasi-trigonometric functions Σ c · s^m · cos(j s) / s^m · sin(j s).

On one contact state a piecewise-linear oscillator obeys a linear equation
with constant coefficients, so every Lindstedt–Poincaré correction is, on that
state's piece, an *analytic branch*

    B(s) = Σ_{j, m} [ c_{j,m} s^m cos(j s) + d_{j,m} s^m sin(j s) ],

which continues analytically past the piece's ends (that is what lets the
hierarchy expand a contact boundary that moves with ε).  This module gives the
exact calculus of such branches with coefficients in any sympy domain
(``QQ``, a fraction field ``QQ(π, β, …)``, ``RealField``) or in the
:class:`~lindstedt.algebra.contact_field.ContactField` (σ² + κ² = 1 built in):

* sums, scalar multiples, derivatives, products (integer harmonics exactly; the non-integer harmonics
  ``r_k`` of an N-dof system's modal components in a ``RealField``, sums and differences of harmonics
  snapped to a common grid so that one frequency reached by two paths is one term);
* evaluation at a point whose ``cos(j s0)``, ``sin(j s0)`` are known
  (:class:`EvaluationPoint`, using the Chebyshev recurrences from cos s0, sin s0),
  remembered per branch and point (the hierarchy evaluates the derivatives of every
  lower order at the same contact angles again at each new order);
* exact antiderivatives (integration by parts, memoised over ``QQ``);
* the particular solution of ``v'' + v = B`` by undetermined coefficients,
  including the resonant harmonic ``j = 1`` (which raises the power of s).
"""

from __future__ import annotations

from functools import lru_cache
from typing import Any, Iterable, Mapping

import sympy
from sympy import QQ

from .._precision import LOCK
from .contact_field import sum_of_products

__all__ = ["Branch", "EvaluationPoint", "domain_constant"]

# A term key is (harmonic j >= 0, parity 0 = cos / 1 = sin, power m >= 0); (0, 1, m) never occurs.
TermKey = tuple[int, int, int]
_RationalTerms = tuple[tuple[TermKey, Any], ...]


#: a RealField harmonic is snapped to this many bits fewer than the field's precision (to an integer within it)
_SNAP_BITS = 24


#: per domain (by identity): its conversions of small integers and rationals, made once (a float field's
#: ``convert`` is ~2 µs, and the hierarchy asks for the same few constants at every order); bounded
_CONSTANTS: dict[int, tuple[Any, dict]] = {}
_MAX_DOMAINS, _MAX_CONSTANTS = 64, 4096


def domain_constant(domain: Any, value: Any) -> Any:
    """``domain.convert(value)`` for an integer or ``QQ`` ``value``, converted once per domain.

    Examples
    --------
    >>> from sympy import QQ, RealField
    >>> field = RealField(dps=20)
    >>> domain_constant(field, QQ(1, 2)) == field.convert(QQ(1, 2)), str(domain_constant(QQ, 3))
    (True, '3')
    """
    entry = _CONSTANTS.get(id(domain))
    if entry is None or entry[0] is not domain:
        with LOCK:
            if len(_CONSTANTS) >= _MAX_DOMAINS:
                _CONSTANTS.clear()
            entry = _CONSTANTS[id(domain)] = (domain, {})
    table = entry[1]
    result = table.get(value)
    if result is None:
        result = domain.convert(value)
        if len(table) < _MAX_CONSTANTS:
            table[value] = result  # a race stores the same value twice: harmless
    return result


#: per mpmath number type: its subclass whose instances remember their hash (see :func:`key_harmonic`)
_KEY_TYPES: dict[type, type] = {}
#: :func:`_snapped` results by (raw value, precision): a product of branches asks for the same few sums and
#: differences of harmonics term after term; bounded
_SNAPS: dict[tuple, Any] = {}
#: :func:`_resonant` answers for RealField harmonics, by (ν, r and their types); bounded as _SNAPS
_RESONANCES: dict[tuple, bool] = {}
_MAX_SNAPS = 1 << 16


def _remembered_hash(self: Any) -> int:
    return self._hash


def key_harmonic(harmonic: Any) -> Any:
    """A RealField harmonic as term keys hold it: the same number (its type's subclass, the same arithmetic) that
    remembers its hash; an int unchanged.

    A term key is a tuple, whose hash Python recomputes at every dictionary access, and an mpmath number's hash
    is Python code (~1 µs): with N-dof frequencies r_k in the keys, hashing and comparing them was a fifth of an
    order-3 NNM's time (measured, 20-dof Hertz chain).

    Examples
    --------
    >>> from sympy import RealField
    >>> field = RealField(dps=20)
    >>> r = field.convert(2) / field.convert(3)
    >>> keyed = key_harmonic(r)
    >>> keyed == r, hash(keyed) == hash(r), key_harmonic(3)
    (True, True, 3)
    """
    cls = harmonic.__class__
    if cls is int or "_hash" in getattr(cls, "__slots__", ()):
        return harmonic
    keyed_type = _KEY_TYPES.get(cls)
    if keyed_type is None:
        with LOCK:
            keyed_type = _KEY_TYPES.get(cls)
            if keyed_type is None:
                keyed_type = _KEY_TYPES[cls] = type(cls.__name__, (cls,), {"__slots__": ("_hash",),
                                                                         "__hash__": _remembered_hash})
    keyed = object.__new__(keyed_type)
    keyed._mpf_ = harmonic._mpf_
    keyed._hash = hash(harmonic)
    return keyed


def _snapped(harmonic: Any, domain: Any) -> Any:
    """A sum or difference of RealField harmonics on a common grid: the integer it equals to ``_SNAP_BITS`` bits
    below the field's precision, else its value rounded to that many bits fewer (``(r + 1) − 1`` is ``r``), as a
    :func:`key_harmonic` (one object per value, remembered)."""
    raw, precision = harmonic._mpf_, domain.precision
    snapped = _SNAPS.get((raw, precision))
    if snapped is not None:
        return snapped
    from mpmath.libmp import normalize, round_nearest

    nearest = int(round(float(harmonic)))
    if abs(harmonic - nearest) <= abs(harmonic) * 2.0 ** (_SNAP_BITS - precision) + 2.0 ** (-precision):
        snapped = nearest
    else:
        sign, mantissa, exponent, bits = raw
        snapped = key_harmonic(harmonic.context.make_mpf(normalize(sign, mantissa, exponent, bits,
                                                                    precision - _SNAP_BITS, round_nearest)))
    if len(_SNAPS) >= _MAX_SNAPS:
        _SNAPS.clear()
    _SNAPS[(raw, precision)] = snapped  # a race stores an equal value twice: harmless
    return snapped


def _resonant(harmonic: Any, frequency: Any) -> bool:
    """ν = r, exactly or (a RealField harmonic) to the grid of :func:`_snapped` (its spacing, 2^(_SNAP_BITS −
    precision) relative, with a margin of 16: a snapped ν lies up to half a spacing from the r it stands for, and
    treating it as non-resonant would give a particular solution of size 1/(r² − ν²) ~ 1e26 that the homogeneous
    part cancels only in exact arithmetic)."""
    if harmonic.__class__ is int and frequency.__class__ is int:
        return harmonic == frequency
    key = (harmonic, frequency, harmonic.__class__, frequency.__class__)  # a number type is its field's: the precision
    resonant = _RESONANCES.get(key)
    if resonant is None:
        precision = getattr(getattr(frequency, "context", None), "prec", None) or getattr(
            getattr(harmonic, "context", None), "prec", None)
        resonant = harmonic == frequency or (precision is not None and abs(harmonic - frequency)
                                             <= abs(frequency) * 2.0 ** (_SNAP_BITS + 4 - precision))
        if len(_RESONANCES) >= _MAX_SNAPS:
            _RESONANCES.clear()
        _RESONANCES[key] = resonant
    return resonant


def _add_into(target: dict, key: TermKey, value: Any) -> None:
    if key[1] == 1 and not key[0]:
        return  # sin(0 s) = 0
    target[key] = target[key] + value if key in target else value


@lru_cache(maxsize=None)
def _oscillator_inverse(key: TermKey) -> _RationalTerms:
    """Particular solution over QQ of v'' + v = s^m trig_j(s) (one basis term)."""
    harmonic, parity, power = key
    result: dict[TermKey, Any] = {}
    if harmonic == 1:
        # v'' + v = s^m cos s: top term s^{m+1} sin s / (2(m+1)); the residual is (m/2) s^{m-1} sin s.
        # v'' + v = s^m sin s: top term -s^{m+1} cos s / (2(m+1)); the residual is -(m/2) s^{m-1} cos s.
        top = (1, 1 - parity, power + 1)
        sign = 1 if parity == 0 else -1
        _add_into(result, top, QQ(sign, 2 * (power + 1)))
        if power >= 1:
            residual_key = (1, 1 - parity, power - 1)
            residual_coefficient = QQ(sign * power, 2)
            for sub_key, value in _oscillator_inverse(residual_key):
                _add_into(result, sub_key, -residual_coefficient * value)
    else:
        factor = QQ(1, 1 - harmonic * harmonic)
        _add_into(result, key, factor)
        # L[s^m cos js] = (1 - j²) s^m cos js + m(m-1) s^{m-2} cos js - 2 j m s^{m-1} sin js
        # L[s^m sin js] = (1 - j²) s^m sin js + m(m-1) s^{m-2} sin js + 2 j m s^{m-1} cos js
        residuals: list[tuple[TermKey, Any]] = []
        if power >= 2:
            residuals.append(((harmonic, parity, power - 2), QQ(power * (power - 1))))
        if power >= 1 and harmonic:
            sign = -1 if parity == 0 else 1
            residuals.append(((harmonic, 1 - parity, power - 1), QQ(sign * 2 * harmonic * power)))
        for residual_key, coefficient in residuals:
            for sub_key, value in _oscillator_inverse(residual_key):
                _add_into(result, sub_key, -factor * coefficient * value)
    return tuple((k, v) for k, v in result.items() if v)


def _general_oscillator_inverse(key: tuple, frequency: Any, domain: Any, memo: dict) -> dict:
    """Particular solution of v'' + r² v = s^m trig(ν s) with domain coefficients (r = frequency).

    Non-resonant ν ≠ r:  L[s^m c(νs)] = (r² − ν²) s^m c(νs) + m(m−1) s^{m−2} c(νs) ∓ 2νm s^{m−1} c'(νs).
    Resonant ν = r:      top term ± s^{m+1} (sin|cos)(rs) / (2r(m+1)), residual ± (m/(2r)) s^{m−1} (sin|cos)(rs).
    """
    if key in memo:
        return memo[key]
    harmonic, parity, power = key
    result: dict = {}
    if _resonant(harmonic, frequency):
        harmonic = frequency
        top = (harmonic, 1 - parity, power + 1)
        sign = 1 if parity == 0 else -1
        scale = domain.one / (domain_constant(domain, 2 * (power + 1)) * frequency)
        _add_into(result, top, scale * domain_constant(domain, sign))
        if power >= 1:
            residual = domain_constant(domain, sign * power) / (domain_constant(domain, 2) * frequency)
            for sub_key, value in _general_oscillator_inverse((harmonic, 1 - parity, power - 1), frequency, domain, memo).items():
                _add_into(result, sub_key, -residual * value)
    else:
        factor = domain.one / (frequency * frequency - harmonic * harmonic)
        _add_into(result, key, factor)
        residuals = []
        if power >= 2:
            residuals.append(((harmonic, parity, power - 2), domain_constant(domain, power * (power - 1))))
        if power >= 1 and harmonic:
            sign = -1 if parity == 0 else 1
            residuals.append(((harmonic, 1 - parity, power - 1), domain_constant(domain, sign * 2 * power) * harmonic))
        for residual_key, coefficient in residuals:
            for sub_key, value in _general_oscillator_inverse(residual_key, frequency, domain, memo).items():
                _add_into(result, sub_key, -factor * coefficient * value)
    memo[key] = {k: v for k, v in result.items() if v}
    return memo[key]


@lru_cache(maxsize=None)
def _antiderivative(key: TermKey) -> _RationalTerms:
    """An antiderivative over QQ of s^m trig_j(s) (integration by parts)."""
    harmonic, parity, power = key
    result: dict[TermKey, Any] = {}
    if harmonic == 0:
        _add_into(result, (0, 0, power + 1), QQ(1, power + 1))
        return tuple(result.items())
    # ∫ s^m cos js = s^m sin(js)/j - (m/j) ∫ s^{m-1} sin js
    # ∫ s^m sin js = -s^m cos(js)/j + (m/j) ∫ s^{m-1} cos js
    sign = 1 if parity == 0 else -1
    _add_into(result, (harmonic, 1 - parity, power), QQ(sign, harmonic))
    if power >= 1:
        for sub_key, value in _antiderivative((harmonic, 1 - parity, power - 1)):
            _add_into(result, sub_key, QQ(-sign * power, harmonic) * value)
    return tuple((k, v) for k, v in result.items() if v)


class EvaluationPoint:
    """A point s0 with exact (domain) values of s0^m, cos(j s0) and sin(j s0).

    Parameters
    ----------
    domain : sympy domain
    value, cosine, sine : domain elements
        s0, cos(s0) and sin(s0).

    Examples
    --------
    >>> from sympy import QQ
    >>> point = EvaluationPoint(QQ, QQ(0), QQ(1), QQ(0))
    >>> print(point.cos_multiple(3), point.sin_multiple(3))
    1 0
    """

    def __init__(self, domain: Any, value: Any, cosine: Any, sine: Any):
        self.domain = domain
        self.value = value
        self._cos = [domain.one, cosine]
        self._sin = [domain.zero, sine]
        self._powers = [domain.one]
        self._cache: dict[Any, tuple[Any, Any]] = {}
        # per term key (j, parity, m): (s0^m, cos(j s0) or sin(j s0)), the factors of a term's value there
        self._factors: dict[TermKey, tuple[Any, Any]] = {}

    # The tables only grow, an entry appended complete (cos before sin): a length that covers an index
    # means its entries are final, so reads need no lock; growing takes it (points are shared by threads).
    def power(self, exponent: int) -> Any:
        """s0 ** exponent."""
        if len(self._powers) <= exponent:
            with LOCK:
                while len(self._powers) <= exponent:
                    self._powers.append(self._powers[-1] * self.value)
        return self._powers[exponent]

    def _extend(self, harmonic: int) -> None:
        if len(self._sin) > harmonic:
            return
        with LOCK:
            while len(self._sin) <= harmonic:
                # cos((j+1)x) = 2 cos x cos jx - cos((j-1)x); same recurrence for sin.
                two_cos = self._cos[1] + self._cos[1]
                self._cos.append(two_cos * self._cos[-1] - self._cos[-2])
                self._sin.append(two_cos * self._sin[-1] - self._sin[-2])

    def cos_multiple(self, harmonic: Any) -> Any:
        """cos(harmonic · s0); a non-integer frequency needs a float domain (RealField)."""
        if isinstance(harmonic, int):
            self._extend(harmonic)
            return self._cos[harmonic]
        return self._transcendental(harmonic)[0]

    def sin_multiple(self, harmonic: Any) -> Any:
        """sin(harmonic · s0); a non-integer frequency needs a float domain (RealField)."""
        if isinstance(harmonic, int):
            self._extend(harmonic)
            return self._sin[harmonic]
        return self._transcendental(harmonic)[1]

    def factors(self, key: TermKey) -> tuple[Any, Any]:
        """(s0^m, cos(j s0)) or (s0^m, sin(j s0)) for the term key (j, parity, m), remembered."""
        pair = self._factors.get(key)
        if pair is None:
            harmonic, parity, power = key
            pair = (self.power(power), self.cos_multiple(harmonic) if parity == 0 else self.sin_multiple(harmonic))
            self._factors[key] = pair  # complete when stored: readers need no lock
        return pair

    def _transcendental(self, frequency: Any) -> tuple[Any, Any]:
        context = getattr(self.value, "context", None)
        if context is None:
            raise TypeError("non-integer frequencies can only be evaluated in a float (RealField) domain")
        key = ("frequency", frequency)
        if key not in self._cache:
            argument = frequency * self.value
            self._cache[key] = (context.cos(argument), context.sin(argument))
        return self._cache[key]


class Branch:
    """Quasi-trigonometric function ``Σ c · s^m · cos(j s)`` + ``Σ d · s^m · sin(j s)``.

    Examples
    --------
    >>> from sympy import QQ
    >>> cosine = Branch.cosine(QQ)
    >>> particular = cosine.oscillator_particular_solution()   # v'' + v = cos s
    >>> particular.terms == {(1, 1, 1): QQ(1, 2)}            # s sin(s) / 2
    True
    """

    __slots__ = ("domain", "terms", "_values")

    def __init__(self, domain: Any, terms: Mapping[TermKey, Any] | None = None):
        self.domain = domain
        self.terms = {key: value for key, value in (terms or {}).items() if value and not (key[1] == 1 and not key[0])}
        # values at evaluation points, kept with the branch: the hierarchy evaluates the same (memoised)
        # derivatives of lower orders at the same contact angles at every later order
        self._values: dict[EvaluationPoint, Any] = {}

    @classmethod
    def cosine(cls, domain: Any, harmonic: int = 1, amplitude: Any = None) -> "Branch":
        """amplitude · cos(harmonic s)."""
        return cls(domain, {(harmonic, 0, 0): domain.one if amplitude is None else amplitude})

    @classmethod
    def sine(cls, domain: Any, harmonic: int = 1, amplitude: Any = None) -> "Branch":
        """amplitude · sin(harmonic s)."""
        return cls(domain, {(harmonic, 1, 0): domain.one if amplitude is None else amplitude})

    @classmethod
    def constant(cls, domain: Any, value: Any) -> "Branch":
        """The constant ``value``."""
        return cls(domain, {(0, 0, 0): value})

    def is_zero(self) -> bool:
        """True when there are no terms."""
        return not self.terms

    # A branch's terms never hold sin(0 s) (the constructor drops it), and sums, differences and derivatives of such
    # terms make none: the loops below add into their dictionaries directly (cancelled terms dropped by Branch()).
    def __add__(self, other: "Branch") -> "Branch":
        result = dict(self.terms)
        for key, value in other.terms.items():
            result[key] = result[key] + value if key in result else value
        return Branch(self.domain, result)

    def __neg__(self) -> "Branch":
        return Branch(self.domain, {key: -value for key, value in self.terms.items()})

    def __sub__(self, other: "Branch") -> "Branch":
        result = dict(self.terms)
        for key, value in other.terms.items():
            result[key] = result[key] + -value if key in result else -value
        return Branch(self.domain, result)

    def scale(self, factor: Any) -> "Branch":
        """Multiply by the domain element ``factor``."""
        if not factor:
            return Branch(self.domain)
        return Branch(self.domain, {key: value * factor for key, value in self.terms.items()})

    def _from_rational(self, rational_terms: Iterable[tuple[TermKey, Any]], factor: Any, into: dict) -> None:
        domain = self.domain
        for key, value in rational_terms:  # keys of _oscillator_inverse / _antiderivative: no sin(0 s)
            term = factor * domain_constant(domain, value)
            into[key] = into[key] + term if key in into else term

    def derivative(self) -> "Branch":
        """d/ds, exactly."""
        result: dict[TermKey, Any] = {}
        domain = self.domain
        for (harmonic, parity, power), value in self.terms.items():
            if power:  # a factor 1 changes nothing (not even a float's rounding): not multiplied
                term = value if power == 1 else value * domain_constant(domain, power)
                key = (harmonic, parity, power - 1)
                result[key] = result[key] + term if key in result else term
            if harmonic:
                if harmonic.__class__ is int and harmonic == 1:
                    term = value if parity else -value
                else:
                    factor = domain_constant(domain, harmonic) if isinstance(harmonic, int) else harmonic
                    term = value * factor if parity else -(value * factor)
                key = (harmonic, 1 - parity, power)
                result[key] = result[key] + term if key in result else term
        return Branch(domain, result)

    def __mul__(self, other: "Branch") -> "Branch":
        """Product of two branches (product-to-sum; powers of s add; RealField harmonics snapped, :func:`_snapped`).

        Examples
        --------
        >>> import sympy
        >>> square = Branch.cosine(sympy.QQ) * Branch.cosine(sympy.QQ)      # cos² s = (1 + cos 2s)/2
        >>> square.to_expr(sympy.Symbol("s"))
        cos(2*s)/2 + 1/2
        """
        result: dict[TermKey, Any] = {}
        half = domain_constant(self.domain, QQ(1, 2))
        for (j, parity, power), value in self.terms.items():
            for (k, other_parity, other_power), other_value in other.terms.items():
                product = value * other_value * half
                exponent = power + other_power
                if isinstance(j, int) and isinstance(k, int):
                    difference, total = j - k, j + k
                    negative, difference = difference < 0, abs(difference)
                else:  # |j − k| snapped (the same grid point as j − k's, mirrored), so that it stays a key harmonic
                    difference, total = j - k, _snapped(j + k, self.domain)
                    negative = difference._mpf_[0] == 1 and difference._mpf_[1] != 0
                    difference = _snapped(-difference if negative else difference, self.domain)
                    negative = negative and difference != 0
                # cos·cos = (cos(j−k) + cos(j+k))/2; sin·sin = (cos(j−k) − cos(j+k))/2;
                # sin_j·cos_k = (sin(j+k) + sin(j−k))/2; cos_j·sin_k = (sin(j+k) − sin(j−k))/2
                if parity == other_parity:
                    _add_into(result, (difference, 0, exponent), product)
                    _add_into(result, (total, 0, exponent), product if parity == 0 else -product)
                else:
                    sine_sign = 1 if parity == 1 else -1  # sign of sin(j−k) in the sum
                    if negative:
                        sine_sign = -sine_sign
                    _add_into(result, (total, 1, exponent), product)
                    _add_into(result, (difference, 1, exponent), product if sine_sign > 0 else -product)
        return Branch(self.domain, result)

    def times_cosine(self, harmonic: int) -> "Branch":
        """Product with cos(harmonic · s) (product-to-sum)."""
        result: dict[TermKey, Any] = {}
        half = domain_constant(self.domain, QQ(1, 2))
        for (j, parity, power), value in self.terms.items():
            half_value = value * half
            _add_into(result, (j + harmonic, parity, power), half_value)
            difference = j - harmonic
            if difference >= 0:
                _add_into(result, (difference, parity, power), half_value)
            else:  # sin(-x) = -sin(x)
                _add_into(result, (-difference, parity, power), half_value if parity == 0 else -half_value)
        return Branch(self.domain, result)

    def oscillator_particular_solution(self, frequency: Any = None, memos: dict | None = None) -> "Branch":
        """A particular solution of ``v'' + r² v = self`` (r = ``frequency``, default 1).

        Forcing at the resonant frequency ν = r raises the power of s (secular growth
        on a bounded piece is fine: the pieces are joined by matching conditions).
        ``memos`` (a dict of this domain, kept by the caller) remembers the particular solution of each term per r
        across calls: an N-dof hierarchy solves every component on every piece at every order with the harmonics of
        the same few forcings (20-dof chain, order 3, one memo per order: 69 % of the lookups answered from it, 26 % with
        one per call).
        """
        result: dict[TermKey, Any] = {}
        unit = frequency is None or (isinstance(frequency, int) and frequency == 1)
        if unit and all(isinstance(key[0], int) for key in self.terms):
            for key, value in self.terms.items():
                self._from_rational(_oscillator_inverse(key), value, result)
            return Branch(self.domain, result)
        if unit:
            frequency = 1  # an int: resonant terms keep the integer harmonic 1 (its cosines from the exact tables)
        memo = {} if memos is None else memos.setdefault(frequency, {})
        for key, value in self.terms.items():
            for sub_key, sub_value in _general_oscillator_inverse(key, frequency, self.domain, memo).items():
                _add_into(result, sub_key, value * sub_value)
        return Branch(self.domain, result)

    def antiderivative(self) -> "Branch":
        """An antiderivative (constant of integration zero)."""
        result: dict[TermKey, Any] = {}
        for key, value in self.terms.items():
            self._from_rational(_antiderivative(key), value, result)
        return Branch(self.domain, result)

    def evaluate(self, point: EvaluationPoint) -> Any:
        """Exact value at ``point`` (remembered per point: a branch is not changed after construction)."""
        cached = self._values.get(point)
        if cached is not None:
            return cached
        triples = []
        known, factors = point._factors, point.factors
        for key, value in self.terms.items():
            pair = known.get(key) or factors(key)
            if pair[1]:
                triples.append((value, pair[0], pair[1]))
        total = sum_of_products(self.domain, triples)
        self._values[point] = total
        return total

    def integral(self, lower: EvaluationPoint, upper: EvaluationPoint) -> Any:
        """∫_lower^upper of the branch, exactly."""
        primitive = self.antiderivative()
        return primitive.evaluate(upper) - primitive.evaluate(lower)

    def to_expr(self, variable: sympy.Symbol, to_sympy: Any = None) -> sympy.Expr:
        """Sympy expression in ``variable`` (``to_sympy`` converts coefficients)."""
        convert = to_sympy or self.domain.to_sympy
        terms = []
        for (harmonic, parity, power), value in self.terms.items():
            trig = sympy.cos(harmonic * variable) if parity == 0 else sympy.sin(harmonic * variable)
            terms.append(convert(value) * variable**power * trig)
        return sympy.Add(*terms)

    def __repr__(self) -> str:
        return f"Branch({self.terms})"
