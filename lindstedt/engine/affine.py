"""Exact linear algebra of one order of the branch hierarchy: values affine in the order's unknowns, and the
Gaussian elimination that fixes them (:mod:`lindstedt.engine.branches`).

Every condition of order n — the slopes at 0 and π, the matching at the moving boundaries, the contact conditions
and the normalisation — is affine in the unknowns ``(A_n, c_k …)``: ``base + Σ coefficient · unknown``.
"""

from __future__ import annotations

from typing import Any, Sequence

import mpmath
from mpmath.libmp import fzero, mpf_abs, mpf_cmp, mpf_mul

from .._errors import ResonanceError

__all__ = ["solve_linear"]


class _Affine:
    """A value of order n, affine in the unknowns (A_n, c_1 … c_N): base + Σ coefficient·unknown.

    Sparse: ``terms`` maps an unknown's index to its coefficient (absent: zero) — most values involve one or two
    of the unknowns; a zero is never multiplied or added (``0 · x`` and ``0 + x`` are exact, so the values are those
    of the dense arithmetic, bit for bit in a float field, and ``value`` adds in the unknowns' order as it did).
    """

    __slots__ = ("base", "terms")

    def __init__(self, base: Any, terms: dict[int, Any]):
        self.base = base
        self.terms = terms

    # A zero coefficient (a value of a zero function, e.g. s sin s at 0) is dropped where it is met: absent is zero.
    def __add__(self, other: "_Affine") -> "_Affine":
        terms = dict(self.terms)
        for index, value in other.terms.items():
            if value:
                terms[index] = terms[index] + value if index in terms else value
        return _Affine(_plus(self.base, other.base), terms)

    def __sub__(self, other: "_Affine") -> "_Affine":
        terms = dict(self.terms)
        for index, value in other.terms.items():
            if value:
                terms[index] = terms[index] - value if index in terms else -value
        base, subtracted = self.base, other.base
        return _Affine((base - subtracted if base else -subtracted) if subtracted else base, terms)

    def scale(self, factor: Any) -> "_Affine":
        if not factor:
            return _Affine(factor, {})
        base = self.base
        return _Affine(base * factor if base else base,
                       {index: value * factor for index, value in self.terms.items() if value})

    def shift(self, constant: Any) -> "_Affine":
        return _Affine(_plus(self.base, constant), dict(self.terms))

    def value(self, unknowns: Sequence[Any]) -> Any:
        total = self.base
        terms = self.terms
        for index in sorted(terms):
            coefficient = terms[index]
            if coefficient:
                product = coefficient * unknowns[index]
                total = total + product if total else product
        return total

    def dense(self, count: int, zero: Any) -> list[Any]:
        """The coefficients of the first ``count`` unknowns as a list (zeros included)."""
        return [self.terms.get(index, zero) for index in range(count)]


def _plus(a: Any, b: Any) -> Any:
    """a + b, without adding a zero."""
    if not b:
        return a
    return a + b if a else b


#: 10^−(digits − 3) per working digits: the singularity threshold of :func:`solve_linear` relative to the largest entry
_THRESHOLDS: dict[int, Any] = {}


def solve_linear(matrix: list[list[Any]], vector: list[Any], domain: Any, order: int) -> list[Any]:
    """Gaussian elimination in ``domain``: partial pivoting for floats, first nonzero pivot when exact.

    Kept because measured (40 digits, random systems of the package's sizes N + 1 = 3, 6, 21):
    61 µs, 0.94 ms, 10 ms here against 5.7, 5.6 and 26 ms for ``mpmath.lu_solve`` with the
    conversions to and from mpf matrices (whose naive round trip through ``RealField.convert``
    also fell to 1e-16); exact 2 × 2 over ``QQ(p, k)``: 1.5 ms here, 1.4 ms ``DomainMatrix.lu_solve``
    (which does not pivot for size, so it cannot serve the float case).
    """
    size = len(vector)
    rows = [row[:] + [value] for row, value in zip(matrix, vector)]
    exact = domain.is_Exact
    threshold = None
    if not exact:
        # magnitudes compared on mpmath's raw values (the decisions max() and > take on the elements)
        scale = fzero
        for row in matrix:
            for entry in row:
                magnitude = mpf_abs(entry._mpf_)
                if mpf_cmp(magnitude, scale) > 0:
                    scale = magnitude
        relative = _THRESHOLDS.get(domain.dps)
        if relative is None:
            if len(_THRESHOLDS) >= 256:
                _THRESHOLDS.clear()
            relative = _THRESHOLDS[domain.dps] = mpmath.mpf(10) ** (-(domain.dps - 3))
        prec, rounding = domain.one.context._prec_rounding
        threshold = mpf_mul(scale if scale != fzero else domain.one._mpf_, relative._mpf_, prec, rounding)
    for column in range(size):
        if exact:
            pivot = next((r for r in range(column, size) if rows[r][column]), None)
        else:
            pivot, largest = column, mpf_abs(rows[column][column]._mpf_)
            for r in range(column + 1, size):
                magnitude = mpf_abs(rows[r][column]._mpf_)
                if mpf_cmp(magnitude, largest) > 0:
                    pivot, largest = r, magnitude
            pivot = pivot if mpf_cmp(largest, threshold) > 0 else None
        if pivot is None:
            raise ResonanceError(f"the order-{order} matching system is singular (internal resonance or tangent contact)")
        rows[column], rows[pivot] = rows[pivot], rows[column]
        for r in range(column + 1, size):
            factor = rows[r][column] / rows[column][column]
            if factor:
                rows[r] = [a - factor * b for a, b in zip(rows[r], rows[column])]
    solution = [domain.zero] * size
    for r in range(size - 1, -1, -1):
        total = rows[r][size]
        for c in range(r + 1, size):
            total = total - rows[r][c] * solution[c]
        solution[r] = total / rows[r][r]
    return solution
