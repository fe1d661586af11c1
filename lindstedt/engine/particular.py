"""Particular solutions of one order of the branch hierarchy (:mod:`lindstedt.engine.branches`):

    v'' + r_k² v = own_k − Σ_S g_k S,

for every component k on one piece, where the shared parts S (rank-one projections c · W, element forces) reach every
component with its own weight; a shared part's solution ``Σ_ν u_ν/(r_k² − ν²)`` is evaluated at the points the
matching needs instead of being formed as one branch per component.
"""

from __future__ import annotations

from bisect import bisect_left, bisect_right
from itertools import repeat
from typing import Any, Iterable, Sequence

import gmpy2

from .._mpfr import mpfr_of_mpf, raw_of_mpfr
from ..algebra.branch import Branch, EvaluationPoint, domain_constant

__all__ = ["Particular", "SharedForcing", "add_scaled", "combination", "subtract_into"]


def add_scaled(terms: dict, pairs: Iterable[tuple[Any, Any]], weight: Any) -> None:
    """terms += weight · value for every (key, value) of ``pairs``, in place."""
    for key, value in pairs:
        value = weight * value
        terms[key] = terms[key] + value if key in terms else value


def combination(domain: Any, branches: Sequence[Branch], weights: Sequence[Any]) -> Branch:
    """Σ_l weights[l] · branches[l], accumulated in one dictionary (a chain of Branch sums would copy O(N²) terms)."""
    terms: dict = {}
    for branch, weight in zip(branches, weights):
        if weight:
            add_scaled(terms, branch.terms.items(), weight)
    return Branch(domain, terms)


def subtract_into(terms: dict, branch: Branch, factor: Any = None) -> None:
    """terms −= factor · branch in place (the terms ``rhs - branch.scale(factor)`` holds, zeros kept: 0 + x is x)."""
    if factor is None:
        for key, value in branch.terms.items():
            terms[key] = terms[key] + -value if key in terms else -value
    elif factor:
        for key, value in branch.terms.items():
            value = -(value * factor)
            terms[key] = terms[key] + value if key in terms else value


class SharedForcing:
    """A part S of an order's right-hand sides that every component k receives with its own weight, −g_k S: a
    rank-one projection ``c · W`` or an element's force (the laws couple the components only through them).

    A component's particular solution of ``v'' + r_k² v = S`` has, for the terms ``a cos(ν s) + b sin(ν s)`` of a
    harmonic ν ≠ r_k, the terms ``(a cos(ν s) + b sin(ν s)) / (r_k² − ν²)``: its values and slopes at a point are
    ``Σ_ν u_ν / (r_k² − ν²)`` over ``u_ν = a cos(ν s0) + b sin(ν s0)`` (or their slope), formed once per point for
    every component — O(|S|) per component and point in gmpy2 at the field's precision (each product and quotient
    rounded as the field rounds it, the sum correctly rounded), no branch per component.  The other terms (powers
    of s, ν near r_k) go to the component's own right-hand side.  Float fields only (with ``from_raw``).
    """

    __slots__ = ("domain", "precision", "groups", "floats", "squares", "others", "_products")

    def __init__(self, domain: Any, branch: Branch):
        self.domain = domain
        self.precision = domain.precision
        groups: dict[Any, list[tuple[Any, Any]]] = {}  # per harmonic ν: its power-0 terms (key, coefficient)
        for key, value in branch.terms.items():
            if not key[2]:
                groups.setdefault(key[0], []).append((key, value))
        self.groups = list(groups.values())
        self.floats = sorted((float(harmonic), g) for g, harmonic in enumerate(groups))  # (ν, group) by ν
        with gmpy2.context(precision=self.precision):
            self.squares = [mpfr_of_mpf(harmonic * harmonic) for harmonic in groups]  # ν² rounded as the field rounds it
        self.others = [(key, value) for key, value in branch.terms.items() if key[2]]
        self._products: dict[tuple[EvaluationPoint, bool], list[Any]] = {}

    def near(self, ratio: float, distance: float) -> list[int]:
        """The groups whose harmonic ν has |ν − r| ≤ distance (bisection of the sorted harmonics)."""
        start = bisect_left(self.floats, (ratio - distance, -1))
        stop = bisect_right(self.floats, (ratio + distance, len(self.floats)))
        return [g for _, g in self.floats[start:stop]]

    def inverses(self, ratio: Any, near: list[int]) -> list[Any]:
        """``1/(r² − ν²)`` for every harmonic (mpfr; zero for the groups ``near``, solved by the component)."""
        with gmpy2.context(precision=self.precision):
            squared = mpfr_of_mpf(ratio * ratio)
            result = list(map(gmpy2.div, repeat(gmpy2.mpfr(1), len(self.squares)), map(gmpy2.sub, repeat(squared),
                                                                                          self.squares)))
            for g in near:
                result[g] = gmpy2.mpfr(0)
        return result

    def products(self, point: EvaluationPoint, slope: bool) -> list[Any]:
        """``u_ν`` = Σ a trig(ν s0) (``slope``: Σ a trig'(ν s0)) for every harmonic (mpfr), remembered per point."""
        key = (point, slope)
        cached = self._products.get(key)
        if cached is None:
            cached = []
            for group in self.groups:
                total = None
                for (harmonic, parity, _), value in group:
                    if slope:  # (cos ν s)' = −ν sin ν s, (sin ν s)' = ν cos ν s
                        trig = point.sin_multiple(harmonic) if parity == 0 else point.cos_multiple(harmonic)
                        factor = domain_constant(self.domain, harmonic) if isinstance(harmonic, int) else harmonic
                        product = -(value * factor * trig) if parity == 0 else value * factor * trig
                    else:
                        product = value * (point.cos_multiple(harmonic) if parity == 0 else point.sin_multiple(harmonic))
                    total = product if total is None else total + product
                cached.append(total)
            with gmpy2.context(precision=self.precision):
                cached = [mpfr_of_mpf(product) for product in cached]
            self._products[key] = cached
        return cached

    def solution_at(self, inverses: list[Any], point: EvaluationPoint, slope: bool) -> Any:
        """Σ_ν u_ν/(r² − ν²) at ``point`` (a field element) for the inverses of one component."""
        with gmpy2.context(precision=self.precision):
            total = gmpy2.fsum(map(gmpy2.mul, self.products(point, slope), inverses))
        return self.domain.from_raw(raw_of_mpfr(total))


class Particular:
    """A particular solution of ``v'' + r_k² v = own − Σ_S g_k S`` for one component k on one piece (the shared parts
    S as :class:`SharedForcing`): its values and slopes at points for the order's matching, and its branch, formed
    only when the order's branches are asked for (the frequency needs none of the highest order's)."""

    __slots__ = ("domain", "own", "shared", "_slope")

    def __init__(self, domain: Any, own: Branch, shared: list[tuple[Any, SharedForcing, list[Any]]]):
        self.domain = domain
        self.own = own  # the particular solution of the component's own right-hand side
        self.shared = shared  # (−g_k, S, the inverses 1/(r_k² − ν²) of S's harmonics, zero where solved in own)
        self._slope: Branch | None = None

    def value(self, point: EvaluationPoint, slope: bool) -> Any:
        """The particular solution (``slope``: its derivative) at ``point``."""
        if slope:
            if self._slope is None:
                self._slope = self.own.derivative()
            total = self._slope.evaluate(point)
        else:
            total = self.own.evaluate(point)
        for weight, forcing, inverses in self.shared:
            total = total + weight * forcing.solution_at(inverses, point, slope)
        return total

    def branch(self) -> Branch:
        """The particular solution as a branch."""
        if not self.shared:
            return self.own
        terms = dict(self.own.terms)
        domain = self.domain
        for weight, forcing, inverses in self.shared:
            for group, inverse in zip(forcing.groups, inverses):
                if inverse:
                    inverse = domain.from_raw(raw_of_mpfr(inverse))
                    for key, value in group:
                        value = weight * (value * inverse)
                        terms[key] = terms[key] + value if key in terms else value
        return Branch(domain, terms)
