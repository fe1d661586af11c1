"""Truncated power series in ε shared by the hierarchies (coefficients in a sympy domain).

* ``Ω = sqrt(Σ A_k ε^k)`` with ``A_0 = Ω_0 = 1``:  ``Ω_k = (A_k − Σ_{i=1}^{k−1} Ω_i Ω_{k−i}) / 2``;
* powers of a boundary shift ``δσ(ε) = Σ_{i≥1} σ_i ε^i`` (Taylor expansions about a contact angle).
"""

from __future__ import annotations

from typing import Any, Callable

from sympy import QQ

from .._precision import locked
from ..algebra.branch import domain_constant
from ..algebra.contact_field import sum_of_products
from ..limits import checkpoint

__all__ = ["LazyOrders", "extend_square_root", "shift_powers"]


def extend_square_root(roots: list[Any], squared: Callable[[int], Any], order: int, domain: Any) -> Any:
    """Extend ``roots`` (Ω_0 = 1, Ω_1, …) in place up to ``order`` from ``squared(k) = A_k``; return Ω_order.

    Examples
    --------
    >>> from sympy import QQ
    >>> roots = [QQ(1)]
    >>> print(extend_square_root(roots, lambda k: [QQ(1), QQ(1, 2), QQ(-3, 16)][k], 2, QQ))   # Ω² = 1 + ε/2 − 3ε²/16
    -1/8
    """
    half = domain_constant(domain, QQ(1, 2))
    while len(roots) <= order:
        k = len(roots)
        value = squared(k)
        for i in range(1, k):
            value = value - roots[i] * roots[k - i]
        roots.append(value * half)
    return roots[order]


def shift_powers(shifts: list[Any], order: int, domain: Any, previous: tuple[int, list[list[Any]]] | None = None) -> list[list[Any]]:
    """``[δσ^n]_j`` for n, j ≤ order, where ``shifts[i] = σ_i`` (``shifts[0]`` ignored, missing ones zero).

    ``previous = (len(earlier), table)``: the table of an earlier call whose ``earlier`` is a prefix of
    ``shifts``; its entries involving only shifts known to both calls (``[δσ^n]_j`` needs σ_i, i ≤ j − n + 1)
    are reused, so the hierarchy's table at order N + 1 costs the new column only: O(N²) products, not
    O(N³) (κ = 3/10 to order 10: 495 -> ~130 products of field elements).

    Examples
    --------
    >>> from sympy import QQ
    >>> [str(c) for c in shift_powers([QQ(0), QQ(2)], 2, QQ)[2]]     # (2ε)² = 4ε²
    ['0', '0', '4']
    >>> [str(c) for c in shift_powers([QQ(0), QQ(2), QQ(3)], 3, QQ, (2, shift_powers([QQ(0), QQ(2)], 2, QQ)))[2]]
    ['0', '0', '4', '12']
    """
    zero, one = domain.zero, domain.one
    padded = [zero] + [shifts[i] if i < len(shifts) else zero for i in range(1, order + 1)]
    shifted = [i for i in range(1, order + 1) if padded[i]]  # the σ_i ≠ 0: a zero factor adds nothing to a sum
    known = min(len(shifts), order + 1)
    powers = [[one] + [zero] * order]
    for power in range(1, order + 1):
        last = powers[-1]
        nonzero = [bool(value) for value in last]
        row: list[Any] = []
        if previous is not None and power < len(previous[1]):
            earlier = previous[1][power]
            row = earlier[:max(0, min(order, len(earlier) - 1, min(previous[0], known) + power - 2) + 1)]
        row += [sum_of_products(domain, [(last[j - i], padded[i], one) for i in shifted if i <= j and nonzero[j - i]])
                for j in range(len(row), order + 1)]
        powers.append(row)
    return powers


class LazyOrders:
    """Mixin for hierarchies solved order by order on demand.

    The host defines ``_solve_order(n)`` (which appends A_n to ``_squared``),
    ``_squared = [1]``, ``_frequencies = [1]`` and ``_domain``.  A hierarchy is shared by every
    expansion of its problem (the process-wide cache), so every method that may grow it holds
    :data:`lindstedt._precision.LOCK` (:func:`~lindstedt._precision.locked`): two threads never
    solve the same order at once.
    """

    _squared: list[Any]
    _frequencies: list[Any]
    _domain: Any

    def _ensure(self, order: int) -> None:
        """Solve the orders up to ``order``; after each one a checkpoint of :mod:`lindstedt.limits` (budget,
        cancellation, progress), so a stopped request keeps every order it solved."""
        while len(self._squared) <= order:
            solving = len(self._squared)
            self._solve_order(solving)  # type: ignore[attr-defined]  # defined by the host class
            checkpoint("order", solving, order)

    @locked
    def squared_frequency(self, order: int) -> Any:
        """A_order: coefficient of ε̂^order in Ω² (Ω = ω/ω_0)."""
        self._ensure(order)
        return self._squared[order]

    @locked
    def frequency(self, order: int) -> Any:
        """Ω_order: coefficient of ε̂^order in Ω = sqrt(Σ A_k ε̂^k)."""
        return extend_square_root(self._frequencies, self.squared_frequency, order, self._domain)
