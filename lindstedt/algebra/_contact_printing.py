r"""The printed form of an element N / D of the contact field (:mod:`lindstedt.algebra.contact_field`).

σ goes back to degree ≤ 1: ``σ² -> 1 − κ²`` in the numerator, ``σ^b`` of the denominator to ``(1 − κ²)^(b/2)``
with the factors ``1 ∓ κ`` that divide the numerator cancelled; the terms are collected by their powers of π and
β, each coefficient factored over QQ in κ (and split by its power of σ), over one integer denominator.  N and D are
sympy ring elements (:attr:`ContactElement.num`, :attr:`ContactElement.den`) of the field's ring.
"""

from __future__ import annotations

from typing import Any

import sympy
from sympy import QQ
from sympy.polys.rings import PolyElement

__all__ = ["to_sympy"]

_SHORT = 12  # numerators of at most this many terms print both ways (σ kept in the denominator or not)


def _sine_reduced(field: Any, numerator: PolyElement, denominator: PolyElement, keep_sine: bool = True) -> tuple:
    """Rewrite N / D for printing: σ² -> 1 − κ² in N, σ^b in D -> σ^(b mod 2) (1 − κ²)^(b // 2).

    Returns ``(N', D', factors)``: ``N'`` of degree ≤ 1 in every σ, ``D'`` free of σ and ``factors`` the list of
    ``(base, exponent)`` of the (1 − κ²), or of (1 − κ) and (1 + κ) apart, left after cancelling those dividing ``N'``.
    """
    ring = field.ring
    factors = []
    for kappa_index, rhs in field.reduced:
        if not isinstance(rhs, PolyElement):
            continue
        sine_index = [i for i, exponent in enumerate(max(rhs.monoms())) if exponent][0]
        kappa = ring.gens[kappa_index]
        one_minus = ring.one - kappa**2
        exponent = 0
        if len(denominator) == 1:
            [(monom, coefficient)] = denominator.items()
            exponent = monom[sine_index]
            if exponent:  # an odd power keeps one σ in the denominator
                denominator = ring.dtype({monom[:sine_index] + (exponent % 2 if keep_sine else 0,) + monom[sine_index + 1:]: coefficient})
                if exponent % 2 and not keep_sine:
                    numerator = numerator * ring.gens[sine_index]
                    exponent += 1
        groups: dict[int, dict] = {}
        for monom, value in numerator.items():
            quotient, remainder = divmod(monom[sine_index], 2)
            groups.setdefault(quotient, {})[monom[:sine_index] + (remainder,) + monom[sine_index + 1:]] = value
        numerator = ring.zero
        for quotient, terms in groups.items():
            numerator = numerator + ring.dtype(terms) * one_minus**quotient
        powers = []
        for base in (ring.one - kappa, ring.one + kappa):
            power = exponent // 2
            while power:
                quotient, remainder = numerator.div(base)
                if remainder:
                    break
                numerator, power = quotient, power - 1
            powers.append(power)
        if powers[0] == powers[1] and powers[0]:
            factors.append((one_minus, powers[0]))
        else:
            factors += [(base, power) for base, power in zip((ring.one - kappa, ring.one + kappa), powers) if power]
    return numerator, denominator, factors


def to_sympy(field: Any, numerator: PolyElement, denominator: PolyElement) -> sympy.Expr:
    """The printed form.  An odd power of σ in the denominator is multiplied into the numerator (shorter for
    the frequency corrections: count_ops 115 against 122 for ω_3, 602 against 651 for ω_6 of (u − κ)_+), or,
    for a short numerator, kept as one σ there when that prints shorter (``(σ − κ)/σ``)."""
    if not field._sines or denominator == field._poly_one:
        return _printed(field, *_sine_reduced(field, numerator, denominator, True))
    expression = _printed(field, *_sine_reduced(field, numerator, denominator, False))
    if len(numerator) <= _SHORT:
        other = _printed(field, *_sine_reduced(field, numerator, denominator, True))
        if sympy.count_ops(other) < sympy.count_ops(expression):
            return other
    return expression


def _printed(field: Any, numerator: PolyElement, denominator: PolyElement, factors: list) -> sympy.Expr:
    """Σ over the monomials in π and the angles β of (their powers) × (the factored coefficient in κ, σ, …) / denominator."""
    values = field.values
    common, numerator = numerator.clear_denoms()  # integer coefficients over one common denominator
    outer = list(field._outer)
    inner = [i for i in range(len(field.symbols)) if i not in outer]
    groups: dict[tuple, dict] = {}
    for monom, value in numerator.items():
        groups.setdefault(tuple(monom[i] for i in outer), {})[tuple(monom[i] for i in inner)] = value
    sines = list(field._sines)
    ring = field.ring
    width = len(field.symbols)

    def _embed(monom: tuple) -> tuple:  # inner monomial -> full monomial (outer exponents zero)
        full = [0] * width
        for i, e in zip(inner, monom):
            full[i] = e
        return tuple(full)

    def _strip(monom: tuple) -> tuple:  # drop the sines (their powers are 0 or 1, printed apart)
        return tuple(0 if i in sines else e for i, e in enumerate(monom))
    terms = []
    for outer_monom, coefficient in groups.items():
        head = sympy.Mul(*[values[i] ** e for i, e in zip(outer, outer_monom)])
        # split by the powers (0 or 1) of the sines, factor each polynomial in the remaining inner generators
        by_sine: dict[tuple, dict] = {}
        for monom, value in coefficient.items():
            key = tuple(monom[inner.index(i)] for i in sines)
            by_sine.setdefault(key, {})[monom] = value
        parts = []
        for key, part in by_sine.items():
            polynomial = ring.dtype({_embed(monom): value for monom, value in part.items() if True})
            sine = sympy.Mul(*[values[i] ** e for i, e in zip(sines, key)])
            if len(part) > 1 and sines:  # factor over QQ in the ring: (κ − 1)(κ + 1)², … (far cheaper than sympy.factor)
                sine_free = ring.dtype({_strip(monom): value for monom, value in polynomial.items()})
                content, factors_list = sine_free.factor_list()
                parts.append(sine * QQ.to_sympy(content) * sympy.Mul(*[f.as_expr(*values) ** e for f, e in factors_list]))
            else:
                parts.append(polynomial.as_expr(*values))
        terms.append(head * sympy.Add(*parts))
    bottom = QQ.to_sympy(common) * denominator.as_expr(*values)
    for base, power in factors:
        bottom = bottom * base.as_expr(*values) ** power
    return sympy.Add(*terms) / bottom
