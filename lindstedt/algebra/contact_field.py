r"""The exact coefficient field of the contact hierarchy: π, the contact angles and their sines, with σ² + κ² = 1.

The 1-dof piecewise hierarchy (:mod:`lindstedt.engine.branches`) works with the
constants of a unilateral spring crossed at the contact angle ``β = arccos κ``:
``π``, ``β``, ``κ = cos β`` and ``σ = sin β = sqrt(1 − κ²)``.  Taking each of them
as an independent generator of a rational function field never uses
``σ² + κ² = 1``: nothing cancels, the expressions and the gcds of the fraction
field grow with every order.  This module gives the field in which that relation
holds identically, with a canonical form and (in the cases the hierarchy meets)
no gcd at all.

The field is the fraction field of

    R = QQ[g_1, …, g_n, x_1, …, x_m] / (x_j² − r_j),   r_j ∈ QQ[g],

a free QQ[g]-module with basis the squarefree monomials in the x_j:

* a symbolic gap (``κ`` a sympy Symbol): the generators ``π, β, σ`` and the
  reduced variable ``x = κ`` with ``κ² = 1 − σ²`` (so ``κ`` appears at most
  linearly, and ``σ`` — by which the contact condition divides — is a monomial);
* a rational gap ``κ = p/q``: ``σ = sqrt(q² − p²)/q`` is a rational multiple of a
  product of square roots of primes; each prime ``ℓ`` gives a reduced variable
  ``x = √ℓ`` with ``x² = ℓ`` (so ``QQ(√ℓ_1, …)``, of degree 2^m, holds every σ
  canonically), and ``β`` is a generator — or a rational multiple of ``π``
  (κ = 0, ±1/2); ``arccos(−κ) = π − arccos κ``;
* any other parameter Symbol is a plain generator.

An element is ``N / D`` with ``N`` reduced (degree ≤ 1 in every x_j), ``D`` free of
the x_j and monic, ``gcd(N, D) = 1`` in ``QQ[g, x]``; this is canonical because the
basis is free and ``QQ[g]`` factorial.  The hierarchy divides only by rationals,
``π`` (the Fredholm pivot ``W'(π)`` of the resonant part is −π/2) and ``σ`` (the
contact condition), so ``D`` stays a *monomial*: sums and products then need only
the monomial content of ``N`` (no polynomial gcd).  Division by any other element
uses the conjugates ``x_j → −x_j`` (``y · ȳ`` is free of ``x_j``), and a
non-monomial denominator falls back to ``PolyElement.cancel``: always exact.

Measured (issue 13, 2 shared cores, gmpy2 ground types, ``expand(...).omega`` in a
fresh process) against the independent-generator fraction field: ``(u − κ)_+``
with symbolic κ to order 5 4.4 s -> 0.5 s, order 6 ~18 s -> ~1 s, and the printed
ω_1 … ω_6 from count_ops 16, 270, 2221, 7106, 19814, 41021 to 9, 39, 115, 227,
384, 602; κ = 3/10 to order 10 ~62 s -> 0.8 s; two springs (u − 1/4)_+ −
2(−u − 1/2)_+ to order 4 4.7 s -> 0.1 s.

Representation (issue 26): an element is stored packed — the numerator as integer
coefficients keyed by one int per monomial (the exponent of generator i in bits
[16 i, 16 i + 16), so a monomial product is one integer addition) over one positive
common denominator, the denominator monomial as one int — and the products are a
loop over pairs of terms with ``x_j² -> r_j`` folded in (:meth:`ContactField._accumulate`);
sympy ring elements only for a non-monomial denominator and for printing
(:mod:`lindstedt.algebra._contact_printing`).  A sum of products over a common
denominator (:func:`sum_of_products`: the Taylor terms at a moving contact point, a
branch's value there) is accumulated and normalized once.  Measured (2 shared cores,
``expand(...).omega`` after a warm-up, CPU, best of 3 fresh processes): κ = 3/10 to
order 10 0.69 s -> 0.25 s (7× the floor of issue 26, the 30-digit Cauchy integral of
the exact period: 35 ms), order 8 0.25 s -> 0.12 s; symbolic κ to order 6 0.59 s ->
0.30 s; two springs to order 4 78 ms -> 57 ms; the printed ω unchanged.  Tried and dropped: numpy
object arrays for the pairs (no faster: the cost is the Python-int products), gmpy2
coefficients (−7 % at 70 bits, +20 % for the symbolic κ), single-digit keys (−12 %
of the loop, at a 2^7 bound on the degrees).

Examples
--------
>>> import sympy
>>> kappa = sympy.Symbol("kappa")
>>> field = ContactField.for_constants([kappa], [sympy.acos(kappa), sympy.sqrt(1 - kappa**2), sympy.pi])
>>> sine, cosine = field.from_sympy(sympy.sqrt(1 - kappa**2)), field.from_sympy(kappa)
>>> sine * sine + cosine * cosine == field.one
True
>>> field.to_sympy((sine - cosine) / sine)
(-kappa + sqrt(1 - kappa**2))/sqrt(1 - kappa**2)
>>> exact = ContactField.for_constants([sympy.Rational(3, 10)], [sympy.sqrt(91) / 10, sympy.acos(sympy.Rational(-3, 10))])
>>> exact.to_sympy(exact.from_sympy(sympy.sqrt(91) / 10) ** 3)
91*sqrt(91)/1000
>>> exact.to_sympy(exact.from_sympy(sympy.acos(sympy.Rational(-3, 10))))
pi - acos(3/10)
"""

from __future__ import annotations

from fractions import Fraction
from math import gcd, lcm
from typing import Any, Iterable, Sequence

import sympy
from sympy import QQ
from sympy.polys.orderings import lex
from sympy.polys.polyerrors import CoercionFailed
from sympy.polys.rings import PolyElement, PolyRing

from .._precision import LOCK
from ._contact_printing import to_sympy
from .cosine import power_by_squaring

__all__ = ["ContactElement", "ContactField", "sum_of_products"]

# Positional generator symbols (module-level Dummies: π, the i-th angle β_i, the i-th symbolic sine σ_i, the
# i-th prime root): a ring depends only on the structure of the problem, so a new κ in a warm process reuses
# the ring of the last one (and the caches keyed by it); the field adds what the generators stand for.
_PI = sympy.Dummy("pi")
_ANGLES: dict[int, sympy.Dummy] = {}
_SINES: dict[int, sympy.Dummy] = {}
_ROOTS: dict[int, sympy.Dummy] = {}
_RINGS: dict[tuple, PolyRing] = {}
_FIELDS: dict[tuple, "ContactField"] = {}
_FIELD_CACHE_SIZE = 64
_TRIAL_LIMIT = 2**15  # radicands are factored by trial division up to this (larger factors: primes or squares)
# Packed monomials: the exponent of generator i in bits [i W, (i + 1) W) of one int.  A product (or a sum of
# products over a common denominator) checks that its factors' exponents are below 2^(W − 2), so the sum of two
# (and a shift of the denominator, and the r_j of x_j² -> r_j) never carries into the next generator.
_WIDTH = 16
_MASK = (1 << _WIDTH) - 1
_LIMIT = 1 << (_WIDTH - 2)


def _generator(table: dict, position: int, name: str) -> sympy.Dummy:
    with LOCK:  # the tables are shared by threads building hierarchies at once
        if position not in table:
            table[position] = sympy.Dummy(f"{name}{position}")
        return table[position]


def _ring(symbols: tuple) -> PolyRing:
    with LOCK:  # the tables are shared by threads building hierarchies at once
        if symbols not in _RINGS:
            _RINGS[symbols] = PolyRing(symbols, QQ, lex)
        return _RINGS[symbols]


def _squarefree_primes(value: sympy.Rational) -> tuple[sympy.Rational, tuple[int, ...]] | None:
    """sqrt(value) = factor · Π sqrt(ℓ) for a positive rational: (factor, primes ℓ), or None when the
    radicand does not factor quickly (trial division to 2^15, then the cofactors must be primes or squares)."""
    product = int(value.p) * int(value.q)  # sqrt(p/q) = sqrt(p q)/q
    factor, primes = sympy.Rational(1, int(value.q)), []
    for prime, exponent in sympy.factorint(product, limit=_TRIAL_LIMIT).items():
        if prime > _TRIAL_LIMIT and not sympy.isprime(prime):
            root, exact = sympy.integer_nthroot(prime, 2)
            if not (exact and sympy.isprime(root)):
                return None
            prime, exponent = root, 2 * exponent
        factor *= sympy.Integer(prime) ** (exponent // 2)
        if exponent % 2:
            primes.append(int(prime))
    return factor, tuple(sorted(primes))


class _Unrepresentable(CoercionFailed):
    """A constant outside the field (the caller falls back to a general field)."""


class ContactField:
    """The fraction field of QQ[g][x]/(x_j² − r_j) described in the module docstring; quacks like a sympy domain.

    Build it with :meth:`for_constants`; elements are :class:`ContactElement`.

    Parameters
    ----------
    symbols : tuple of sympy.Symbol
        The ring's generators, plain ones first.
    reduced : tuple of (int, Any)
        ``(index, r)`` per reduced variable ``x = symbols[index]``, ``x² = r`` with ``r``
        a rational or a ring element free of every reduced variable.
    values : tuple of sympy.Expr
        What each generator stands for (``to_sympy`` substitutes them).
    """

    is_Exact = True
    is_QQ = False
    is_ZZ = False
    is_Field = True
    is_Numerical = False
    is_RealField = False
    has_assoc_Ring = False
    rep = "ContactField"

    def __init__(self, symbols: tuple, reduced: tuple, values: tuple):
        self.symbols = symbols
        self.ring = _ring(symbols)
        self.values = values
        ring = self.ring
        self.reduced = tuple(
            (index, rhs if isinstance(rhs, PolyElement) else QQ.convert(rhs)) for index, rhs in reduced
        )
        self._poly_one = ring.one
        self.dtype = ContactElement
        self._shifts = tuple(_WIDTH * i for i in range(len(symbols)))
        reduced_indices = {index for index, _ in self.reduced}
        self._plain_shifts = tuple(shift for i, shift in enumerate(self._shifts) if i not in reduced_indices)
        self._guards = sum(3 << (shift + _WIDTH - 2) for shift in self._shifts)  # exponents ≥ 2^(W − 2)
        self._singles = sum(1 << self._shifts[index] for index, _ in self.reduced)  # x_j of every reduced variable
        self._squares = self._square_table(self.reduced)
        self.zero = ContactElement(self, {}, 1, 0)
        self.one = ContactElement(self, {0: 1}, 1, 0)
        self._atoms: dict[sympy.Expr, ContactElement] = {}
        self._outer: tuple[int, ...] = (0,)  # π and the angles: the printed form collects their powers
        self._sines: tuple[int, ...] = ()  # the σ of symbolic breakpoints
        self._roots: dict[int, int] = {}  # prime ℓ -> index of √ℓ

    # -- construction ------------------------------------------------------------------------------
    @classmethod
    def for_constants(cls, kappas: Sequence[sympy.Expr], constants: Iterable[sympy.Expr]) -> "ContactField":
        """The field holding the contact angles of ``kappas`` and every constant; raises CoercionFailed if none does.

        ``kappas`` are the crossed breakpoints (rationals in (−1, 1) or Symbols); ``constants``
        may contain rationals, π, parameter Symbols, ``acos`` of a breakpoint, ``sqrt(1 − κ²)`` of a
        symbolic one and square roots of rationals, combined by +, ·, integer powers.
        """
        symbolic = []
        for kappa in kappas:
            kappa = sympy.sympify(kappa, strict=True)
            if isinstance(kappa, sympy.Symbol):
                symbolic.append(kappa)
            elif not kappa.is_Rational:
                raise _Unrepresentable(f"breakpoint {kappa} is neither rational nor a symbol")
        constants = [sympy.sympify(value, strict=True) for value in constants]
        angles: list[Any] = []  # keys of _ANGLES
        primes: set[int] = set()
        parameters: set[sympy.Symbol] = set()
        for kappa in kappas:
            kappa = sympy.sympify(kappa, strict=True)
            if kappa.is_Rational:
                constants += [sympy.acos(kappa), sympy.sqrt(1 - kappa**2)]
        for value in constants:
            for node in sympy.preorder_traversal(value):
                if node is sympy.pi:
                    continue
                if isinstance(node, sympy.Symbol):
                    if node not in symbolic:
                        parameters.add(node)
                elif isinstance(node, sympy.acos):
                    argument = node.args[0]
                    if argument in symbolic:
                        key = argument
                    elif argument.is_Rational and -1 < argument < 1:
                        key = abs(argument)
                    else:
                        raise _Unrepresentable(f"{node} is not the contact angle of a breakpoint")
                    if key not in angles:
                        angles.append(key)
                elif isinstance(node, sympy.Pow) and not node.exp.is_Integer:
                    if not (node.exp.is_Rational and node.exp.q == 2):
                        raise _Unrepresentable(f"{node}: only square roots are represented")
                    base = node.base
                    if base.is_Rational and base > 0:
                        split = _squarefree_primes(base)
                        if split is None:
                            raise _Unrepresentable(f"{node}: radicand does not factor quickly")
                        primes.update(split[1])
                    elif not any(base == 1 - kappa**2 for kappa in symbolic):
                        raise _Unrepresentable(f"{node} is not sqrt(1 - kappa**2) of a symbolic breakpoint")
                elif isinstance(node, (sympy.Function, sympy.Float, sympy.NumberSymbol)) or node is sympy.I or getattr(node, "is_infinite", False):
                    raise _Unrepresentable(f"{node} is not represented in the contact field")
        plain: list[sympy.Symbol] = [_PI]  # π is always a generator (the point s = π)
        values: list[sympy.Expr] = [sympy.pi]
        rational_angles = sorted((k for k in angles if not isinstance(k, sympy.Symbol)), key=lambda k: (k.q, k.p))
        angle_index: dict[Any, int] = {}
        for key in rational_angles + list(symbolic):
            angle_index[key] = len(plain)
            plain.append(_generator(_ANGLES, len(angle_index), "beta"))
            values.append(sympy.acos(key))
        sine_index: dict[sympy.Symbol, int] = {}
        for kappa in symbolic:
            sine_index[kappa] = len(plain)
            plain.append(_generator(_SINES, len(sine_index), "sigma"))
            values.append(sympy.sqrt(1 - kappa**2))
        for symbol in sorted(parameters, key=str):
            plain.append(symbol)
            values.append(symbol)
        primes_sorted = sorted(primes)
        symbols = tuple(plain + list(symbolic) + [_generator(_ROOTS, i + 1, "root") for i in range(len(primes_sorted))])
        values += list(symbolic) + [sympy.sqrt(prime) for prime in primes_sorted]
        key = (symbols, tuple(values))
        field = _FIELDS.get(key)
        if field is not None:
            return field
        ring = _ring(symbols)
        reduced = [(len(plain) + i, ring.one - ring.gens[sine_index[kappa]] ** 2) for i, kappa in enumerate(symbolic)]  # κ² = 1 − σ²
        reduced += [(len(plain) + len(symbolic) + i, prime) for i, prime in enumerate(primes_sorted)]  # (√ℓ)² = ℓ
        field = cls(symbols, tuple(reduced), tuple(values))
        field._outer = tuple([0] + sorted(angle_index.values()))
        field._sines = tuple(sine_index.values())
        field._roots = {prime: len(plain) + len(symbolic) + i for i, prime in enumerate(primes_sorted)}
        gens = ring.gens
        atoms = field._atoms
        atoms[sympy.pi] = field._poly(gens[0])
        for key_, index in angle_index.items():
            atoms[sympy.acos(key_)] = field._poly(gens[index])
            if not isinstance(key_, sympy.Symbol):
                atoms[sympy.acos(-key_)] = field._poly(gens[0] - gens[index])  # arccos(−κ) = π − arccos κ
        for i, kappa in enumerate(symbolic):
            atoms[sympy.sqrt(1 - kappa**2)] = field._poly(gens[sine_index[kappa]])
            atoms[kappa] = field._poly(gens[len(plain) + i])
        for symbol in parameters:
            atoms[symbol] = field._poly(gens[symbols.index(symbol)])
        with LOCK:  # the tables are shared by threads building hierarchies at once
            _FIELDS[key] = field
            while len(_FIELDS) > _FIELD_CACHE_SIZE:  # oldest first (dicts keep insertion order)
                del _FIELDS[next(iter(_FIELDS))]
        return field

    def _poly(self, polynomial: PolyElement) -> "ContactElement":
        return self._element(*self._from_poly(polynomial))

    def __repr__(self) -> str:
        names = ", ".join(str(value) for value in self.values)
        return f"ContactField({names})"

    def __str__(self) -> str:
        return self.__repr__()

    # -- conversion ---------------------------------------------------------------------------------
    def convert(self, value: Any, base: Any = None) -> "ContactElement":
        """An int, a rational (gmpy2/Python/sympy/Fraction), an element, or a sympy expression -> element."""
        if isinstance(value, ContactElement):
            return value
        if isinstance(value, (int, Fraction)) or QQ.of_type(value):
            return self._rational(value)
        if isinstance(value, sympy.Basic):
            return self.from_sympy(value)
        raise CoercionFailed(f"cannot convert {value!r} to {self}")

    def from_sympy(self, expression: sympy.Expr) -> "ContactElement":
        """A sympy expression in π, the contact angles, their sines and the parameters -> element."""
        expression = sympy.sympify(expression, strict=True)
        if expression.is_Rational:
            return self._rational(expression)
        atom = self._atoms.get(expression)
        if atom is not None:
            return atom
        if expression.is_Add:
            total = self.zero
            for term in expression.args:
                total = total + self.from_sympy(term)
            return total
        if expression.is_Mul:
            total = self.one
            for factor in expression.args:
                total = total * self.from_sympy(factor)
            return total
        if expression.is_Pow:
            base, exponent = expression.args
            if exponent.is_Integer:
                return self.from_sympy(base) ** int(exponent)
            if exponent.is_Rational and exponent.q == 2:
                if base.is_Rational and base > 0:
                    split = _squarefree_primes(base)
                    if split is not None and all(prime in self._roots for prime in split[1]):
                        root = self.ring.ground_new(QQ.convert(split[0]))
                        for prime in split[1]:
                            root = root * self.ring.gens[self._roots[prime]]
                        return self._poly(root) ** int(exponent.p)
                square = self._atoms.get(sympy.sqrt(base))
                if square is not None:
                    return square ** int(exponent.p)
        raise _Unrepresentable(f"{expression} is not in {self}")

    def to_sympy(self, element: "ContactElement") -> sympy.Expr:
        """The element as a sympy expression in π, arccos κ, sqrt(1 − κ²), κ and the parameters.

        Written ``Σ_{i,j} π^i β^j c_ij / d`` with ``c_ij`` collected over the remaining generators
        (each a short polynomial in κ and σ) and ``d`` the rational part of the denominator.
        """
        return to_sympy(self, element.num, element.den)

    def of_type(self, value: Any) -> bool:
        return isinstance(value, ContactElement) and value.field is self

    def is_zero(self, value: "ContactElement") -> bool:
        return not value

    def is_one(self, value: "ContactElement") -> bool:
        return value == self.one

    # -- the packed form: a monomial is one int (exponent i in bits [i W, (i + 1) W)), a numerator a dict ----
    def _pack(self, monom: tuple) -> int:
        key = 0
        for shift, exponent in zip(self._shifts, monom):
            key |= exponent << shift
        return key

    def _unpack(self, key: int) -> tuple:
        mask = _MASK
        return tuple((key >> shift) & mask for shift in self._shifts)

    def _from_poly(self, polynomial: PolyElement) -> tuple[dict, int]:
        """A ring element -> (integer coefficients by packed monomial, positive common denominator)."""
        if not polynomial:
            return {}, 1
        items = [(self._pack(monom), value) for monom, value in polynomial.items()]
        if any(exponent >= _LIMIT for monom in polynomial for exponent in monom):
            raise OverflowError(f"a power above {_LIMIT - 1} in the contact field")
        scale = lcm(*(int(value.denominator) for _, value in items))
        return {key: int(value.numerator) * (scale // int(value.denominator)) for key, value in items}, scale

    def _to_poly(self, terms: dict, scale: int) -> PolyElement:
        unpack = self._unpack
        return self.ring.dtype({unpack(key): QQ(value, scale) for key, value in terms.items()})

    def _element(self, terms: dict, scale: int, monomial: int = 0) -> "ContactElement":
        """terms / (scale · x^monomial), monomial free of reduced variables, terms without zeros -> canonical."""
        if not terms:
            return self.zero
        if monomial:  # the monomial content common to the numerator and the denominator
            common = 0
            for shift in self._plain_shifts:
                power = (monomial >> shift) & _MASK
                if power and all((key >> shift) & _MASK for key in terms):
                    common |= min(power, min((key >> shift) & _MASK for key in terms)) << shift
            if common:
                terms = {key - common: value for key, value in terms.items()}
                monomial -= common
        if scale != 1:
            divisor = gcd(scale, *terms.values())
            if divisor != 1:
                terms = {key: value // divisor for key, value in terms.items()}
                scale //= divisor
        return ContactElement(self, terms, scale, monomial)

    def _rational(self, value: Any) -> "ContactElement":
        value = QQ.convert(value)
        if not value:
            return self.zero
        return ContactElement(self, {0: int(value.numerator)}, int(value.denominator), 0)

    def _product(self, first: dict, second: dict) -> dict:
        """The product of two reduced integer numerators, reduced (x_j² -> r_j), without zero terms."""
        terms: dict = {}
        self._accumulate(terms, first, second, 1, 0)
        if 0 in terms.values():
            terms = {key: value for key, value in terms.items() if value}
        return terms

    def _accumulate(self, terms: dict, first: dict, second: dict, factor: int, shift: int) -> None:
        """terms += factor · x^shift · first · second, reduced (x_j² -> r_j); integer numerators, packed keys.

        The terms of each factor are grouped by their reduced variables; a pair of groups sharing the set J
        multiplies by Π_{j ∈ J} r_j on the way (its terms as (monomial offset, factor), x_j² taken out), so the
        result is reduced when the loop ends.  Measured (issue 26, κ = 3/10 to order 10: 3459 products, 640k
        pairs of terms, 70-bit coefficients): this loop over packed monomials (a monomial product is one int
        addition) and Python ints 0.11 s; with a reduction pass after it 0.15 s; sympy's PolyElement product
        and reduction ~0.55 s.
        """
        if len(first) < len(second):
            first, second = second, first
        guards = self._guards
        reduced = self._singles | guards  # a group with a guard bit: an exponent ≥ 2^(W − 2), the sums could carry
        groups: dict = {}
        for key, value in first.items():
            part = key & reduced
            if part in groups:
                groups[part].append((key, value))
            else:
                groups[part] = [(key, value)]
        other_groups: dict = {}
        for key, value in second.items():
            part = key & reduced
            if factor != 1:
                value *= factor
            if part in other_groups:
                other_groups[part].append((key, value))
            else:
                other_groups[part] = [(key, value)]
        if any(part & guards for part in groups) or any(part & guards for part in other_groups) or shift & guards:
            raise OverflowError(f"a power above {_LIMIT - 1} in the contact field")
        squares = self._squares
        for part, group in groups.items():
            for other_part, pairs in other_groups.items():
                for offset, multiplier in squares[part & other_part]:
                    offset += shift
                    for key, value in group:
                        key += offset
                        value *= multiplier
                        for other, coefficient in pairs:
                            target = key + other
                            if target in terms:
                                terms[target] += value * coefficient
                            else:
                                terms[target] = value * coefficient

    def sum_of_products(self, triples: Iterable[tuple]) -> "ContactElement":
        """Σ a · b · c over ``triples`` in one accumulation over the common denominator, normalized once.

        Measured (issue 26): the Taylor terms of the branches at a moving contact point, Σ_j ∂^t W_j(β) [δσ^t]_{n−j}
        / t!, all over π^n, for (u − 3/10)₊ to order 10: 750 products, each else normalized, scaled by 1/t!
        and added (three passes over its terms and two gcds).
        """
        triples = [(self.convert(a), self.convert(b), self.convert(c)) for a, b, c in triples]
        if any(x.monomial is None for triple in triples for x in triple):  # a general denominator: one by one
            total = self.zero
            for a, b, c in triples:
                total = total + a * b * c
            return total
        items = []
        for a, b, c in triples:
            if not (c.monomial == 0 and len(c.terms) == 1 and 0 in c.terms):
                b, c = b * c, self.one
            if a.terms and b.terms and c.terms:
                items.append((a.terms, b.terms, c.terms[0], a.scale * b.scale * c.scale, a.monomial + b.monomial))
        if not items:
            return self.zero
        scale = lcm(*(item[3] for item in items))
        monomial = 0
        for shift in self._plain_shifts:
            monomial |= max((item[4] >> shift) & _MASK for item in items) << shift
        terms: dict = {}
        for first, second, numerator, denominator, own in items:
            self._accumulate(terms, first, second, numerator * (scale // denominator), monomial - own)
        if 0 in terms.values():
            terms = {key: value for key, value in terms.items() if value}
        return self._element(terms, scale, monomial)

    def _square_table(self, reduced: tuple) -> dict:
        """For every set J of reduced variables (the OR of their bits): Π_{j ∈ J} r_j / x_j² as a list of
        (packed monomial offset, integer factor); the r_j of the fields built here are integral."""
        table: dict = {0: [(0, 1)]}
        for index, rhs in reduced:
            terms, scale = self._from_poly(rhs if isinstance(rhs, PolyElement) else self.ring.ground_new(rhs))
            if scale != 1:
                raise ValueError(f"x**2 = {rhs}: the reduced variables need an integral square")
            single, square = 1 << self._shifts[index], 2 << self._shifts[index]
            for part, product in list(table.items()):
                combined: dict = {}
                for offset, factor in product:
                    for monomial, value in terms.items():
                        combined[offset + monomial - square] = combined.get(offset + monomial - square, 0) + factor * value
                table[part | single] = [(offset, factor) for offset, factor in combined.items() if factor]
        return table

    # -- canonical forms ----------------------------------------------------------------------------
    def _normal(self, numerator: PolyElement, denominator: PolyElement) -> "ContactElement":
        """Canonical N / D for any D free of the reduced variables (the general path: polynomial gcd)."""
        if not numerator:
            return self.zero
        if len(denominator) != 1:
            numerator, denominator = numerator.cancel(denominator)
            leading = denominator.LC
            if leading != QQ.one:
                numerator, denominator = numerator.quo_ground(leading), denominator.quo_ground(leading)
        if len(denominator) == 1:
            [(monom, coefficient)] = denominator.items()
            terms, scale = self._from_poly(numerator.quo_ground(coefficient))
            return self._element(terms, scale, self._pack(monom))
        terms, scale = self._from_poly(numerator)
        return ContactElement(self, terms, scale, None, self._from_poly(denominator))

    def _inverse(self, element: "ContactElement") -> "ContactElement":
        if not element:
            raise ZeroDivisionError("division by zero in the contact field")
        numerator = element.terms
        cofactor = {0: 1}
        for index, _ in self.reduced:  # multiply by the conjugates: y ȳ is free of x_index
            single = 1 << self._shifts[index]
            if any(key & single for key in numerator):
                conjugate = {key: -value if key & single else value for key, value in numerator.items()}
                cofactor = self._product(cofactor, conjugate)
                numerator = self._product(numerator, conjugate)
        # 1/y = scale D ȳ / N(y), N(y) free of the reduced variables (D is, so D ȳ stays reduced)
        if len(numerator) == 1 and element.monomial is not None:
            [(key, value)] = numerator.items()
            factor = element.scale if value > 0 else -element.scale
            shift = element.monomial
            return self._element({other + shift: coefficient * factor for other, coefficient in cofactor.items()}, abs(value), key)
        return self._normal(self._to_poly(cofactor, 1) * element.den * QQ(element.scale), self._to_poly(numerator, 1))


class ContactElement:
    """An element N/D of a :class:`ContactField` (canonical; immutable by convention).

    Stored packed: ``terms`` (integer coefficients by packed monomial) over the positive integer ``scale``,
    with gcd(scale, coefficients) = 1, and the denominator monomial ``monomial`` (packed, 0 for 1) — or,
    rarely, ``monomial = None`` and ``general = (terms, scale)`` a monic non-monomial denominator.
    ``num`` and ``den`` give them as ring elements.
    """

    __slots__ = ("field", "terms", "scale", "monomial", "general", "_hash")

    def __init__(self, field: ContactField, terms: dict, scale: int, monomial: int | None, general: tuple | None = None):
        self.field = field
        self.terms = terms
        self.scale = scale
        self.monomial = monomial
        self.general = general
        self._hash: int | None = None

    @property
    def num(self) -> PolyElement:
        """The numerator N (reduced, coprime to D) as a ring element."""
        return self.field._to_poly(self.terms, self.scale)

    @property
    def den(self) -> PolyElement:
        """The monic denominator D (free of the reduced variables) as a ring element."""
        if self.monomial is None:
            return self.field._to_poly(*self.general)
        return self.field.ring.dtype({self.field._unpack(self.monomial): QQ.one})

    def _coerce(self, other: Any) -> "ContactElement":
        if isinstance(other, ContactElement):
            return other
        return self.field.convert(other)

    def __bool__(self) -> bool:
        return bool(self.terms)

    def __eq__(self, other: Any) -> bool:
        try:
            other = self._coerce(other)
        except CoercionFailed:
            return NotImplemented
        return (self.terms == other.terms and self.scale == other.scale and self.monomial == other.monomial
                and self.general == other.general)

    def __ne__(self, other: Any) -> bool:
        result = self.__eq__(other)
        return result if result is NotImplemented else not result

    def __hash__(self) -> int:
        if self._hash is None:
            general = None if self.general is None else (frozenset(self.general[0].items()), self.general[1])
            self._hash = hash((frozenset(self.terms.items()), self.scale, self.monomial, general))
        return self._hash

    def __neg__(self) -> "ContactElement":
        return ContactElement(self.field, {key: -value for key, value in self.terms.items()}, self.scale, self.monomial, self.general)

    def __pos__(self) -> "ContactElement":
        return self

    def __add__(self, other: Any) -> "ContactElement":
        if other.__class__ is not ContactElement:
            other = self.field.convert(other)
        field = self.field
        if not other.terms:
            return self
        if not self.terms:
            return other
        first, second = self.monomial, other.monomial
        if first is None or second is None:
            return field._normal(self.num * other.den + other.num * self.den, self.den * other.den)
        if first == second:
            common = first
            left, right = self.terms, other.terms
        else:  # over the lcm of the denominator monomials
            common = 0
            for shift in field._plain_shifts:
                common |= max((first >> shift) & _MASK, (second >> shift) & _MASK) << shift
            guards = field._guards
            if common & guards or any(key & guards for key in self.terms) or any(key & guards for key in other.terms):
                raise OverflowError(f"a power above {_LIMIT - 1} in the contact field")
            left = {key + common - first: value for key, value in self.terms.items()}
            right = {key + common - second: value for key, value in other.terms.items()}
        scale, other_scale = self.scale, other.scale
        if scale == other_scale:
            terms = dict(left)
            for key, value in right.items():
                if key in terms:
                    terms[key] += value
                else:
                    terms[key] = value
        else:
            divisor = gcd(scale, other_scale)
            factor, other_factor = other_scale // divisor, scale // divisor
            scale *= factor
            terms = {key: value * factor for key, value in left.items()}
            for key, value in right.items():
                if key in terms:
                    terms[key] += value * other_factor
                else:
                    terms[key] = value * other_factor
        if 0 in terms.values():
            terms = {key: value for key, value in terms.items() if value}
        return field._element(terms, scale, common)

    __radd__ = __add__

    def __sub__(self, other: Any) -> "ContactElement":
        return self + (-self._coerce(other))

    def __rsub__(self, other: Any) -> "ContactElement":
        return self._coerce(other) + (-self)

    def __mul__(self, other: Any) -> "ContactElement":
        if other.__class__ is not ContactElement:
            other = self.field.convert(other)
        field = self.field
        if not self.terms or not other.terms:
            return field.zero
        a, b = self, other
        if len(b.terms) > len(a.terms):
            a, b = b, a
        if not (b.monomial == 0 and len(b.terms) == 1 and 0 in b.terms) and a.monomial == 0 and len(a.terms) == 1 and 0 in a.terms:
            a, b = b, a
        if b.monomial == 0 and len(b.terms) == 1 and 0 in b.terms:  # a rational factor: no gcd of the product
            factor, other_scale = b.terms[0], b.scale
            first = gcd(factor, a.scale)  # gcd(a's coefficients, a.scale) = 1 = gcd(factor, other_scale)
            second = gcd(other_scale, *a.terms.values()) if other_scale != 1 else 1
            factor //= first
            if second == 1:
                terms = {key: value * factor for key, value in a.terms.items()}
            else:
                terms = {key: value // second * factor for key, value in a.terms.items()}
            return ContactElement(field, terms, (a.scale // first) * (other_scale // second), a.monomial, a.general)
        terms = field._product(a.terms, b.terms)
        if a.monomial is None or b.monomial is None:
            return field._normal(field._to_poly(terms, a.scale * b.scale), a.den * b.den)
        return field._element(terms, a.scale * b.scale, a.monomial + b.monomial)

    __rmul__ = __mul__

    def __truediv__(self, other: Any) -> "ContactElement":
        if other.__class__ is not ContactElement:
            other = self.field.convert(other)
        if other.monomial == 0 and len(other.terms) == 1 and 0 in other.terms:  # a rational divisor
            value = other.terms[0]
            return self * ContactElement(self.field, {0: other.scale if value > 0 else -other.scale}, abs(value), 0)
        return self * self.field._inverse(other)

    def __rtruediv__(self, other: Any) -> "ContactElement":
        return self._coerce(other) * self.field._inverse(self)

    def __pow__(self, exponent: int) -> "ContactElement":
        if not isinstance(exponent, int):
            raise TypeError("ContactElement powers must be integers")
        if exponent < 0:
            return self.field._inverse(self) ** (-exponent)
        return power_by_squaring(self, exponent, self.field.one)

    def __repr__(self) -> str:
        return str(self.field.to_sympy(self))

    __str__ = __repr__


def sum_of_products(domain: Any, triples: list[tuple[Any, Any, Any]]) -> Any:
    """``Σ a · b · c`` over ``triples``, added in their order; a domain with its own ``sum_of_products``
    (:class:`ContactField`: one accumulation, normalized once) uses it.

    Examples
    --------
    >>> from sympy import QQ
    >>> print(sum_of_products(QQ, [(QQ(1), QQ(2), QQ(3)), (QQ(1, 2), QQ(1, 3), QQ(6))]))
    7
    """
    fused = getattr(domain, "sum_of_products", None)
    if fused is not None:
        return fused(triples)
    total = domain.zero
    for a, b, c in triples:
        total = total + a * b * c
    return total
