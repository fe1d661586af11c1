"""The exact corrections v_k(s) of an expansion ``u(t) = Σ_k ε^k v_k(ω t)`` (s = ω t, the strained time).

* :class:`Waveform` — smooth f: an even cosine polynomial ``v_k(s) = Σ_n c_n cos(n s)``;
* :class:`PiecewiseWaveform` — piecewise-linear f: one closed-form branch per piece of [0, π] between the
  contact angles β_i, with its cosine coefficients exactly on demand.

Both are built by :meth:`lindstedt.Expansion.waveform`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import sympy

from .._errors import UnsupportedNonlinearityError
from .._precision import locked_methods
from ..algebra.branch import Branch, EvaluationPoint
from ._latex import latex

__all__ = ["PiecewiseWaveform", "STRAINED_TIME", "Waveform"]

STRAINED_TIME = sympy.Symbol("s", real=True)


@locked_methods()
@dataclass(frozen=True)
class Waveform:
    """An exact even cosine polynomial ``v_k(s) = Σ_n c_n cos(n s)``.

    Examples
    --------
    >>> import sympy
    >>> w = Waveform(order=1, coefficients=((1, sympy.Rational(1, 32)), (3, sympy.Rational(-1, 32))))
    >>> w.value_at_zero()
    0
    >>> w.to_expr()
    cos(s)/32 - cos(3*s)/32
    """

    order: int
    coefficients: tuple[tuple[int, sympy.Expr], ...]

    @property
    def harmonics(self) -> tuple[int, ...]:
        """Harmonic numbers present, increasing."""
        return tuple(harmonic for harmonic, _ in self.coefficients)

    def coefficient(self, harmonic: int) -> sympy.Expr:
        """Exact coefficient of ``cos(harmonic s)`` (zero when absent)."""
        return dict(self.coefficients).get(harmonic, sympy.Integer(0))

    def to_expr(self, variable: sympy.Symbol = STRAINED_TIME) -> sympy.Expr:
        """The waveform as a sympy expression in ``variable``."""
        return sympy.Add(*[value * sympy.cos(harmonic * variable) for harmonic, value in self.coefficients])

    def value_at_zero(self) -> sympy.Expr:
        """``v_k(0)`` exactly."""
        return sympy.Add(*[value for _, value in self.coefficients])

    def to_latex(self) -> str:
        """LaTeX of the waveform through sympy's printer."""
        return latex(self.to_expr())


@locked_methods()
@dataclass(frozen=True)
class PiecewiseWaveform:
    """A correction v_k of a piecewise-linear problem, exact and piecewise in closed form.

    The even 2π-periodic function is given by its restriction to [0, π]:
    ``branches[p]`` holds on ``[breakpoints[p-1], breakpoints[p]]`` with
    ``breakpoints`` the contact angles β_i (fixed-s expansion).  Its cosine
    series ``Σ d_n cos(n s)`` is available exactly through
    :meth:`cosine_coefficient`.

    Examples
    --------
    >>> import lindstedt
    >>> v1 = lindstedt.expand("Max(0, u)", order=1, a0=1, omega0=1).waveforms[1]
    >>> v1.breakpoints
    (pi/2,)
    >>> v1.cosine_coefficient(2)
    2/(9*pi)
    """

    order: int
    breakpoints: tuple[sympy.Expr, ...]
    branches: tuple[sympy.Expr, ...]
    _pieces: tuple[Branch, ...] = field(repr=False, compare=False)
    _limits: tuple[EvaluationPoint, ...] = field(repr=False, compare=False)
    _convert: Any = field(repr=False, compare=False)
    # pieces solved on a stretched arc (non-polynomial contact law): their branch is the placeholder
    # Y_k(tau) of :class:`StretchedArcSeries` (no fixed-s closed form)
    stretched: tuple[int, ...] = ()

    def to_expr(self, variable: sympy.Symbol = STRAINED_TIME) -> sympy.Expr:
        """Sympy ``Piecewise`` on [0, π] (extend evenly and 2π-periodically)."""
        conditions = [(branch.subs(STRAINED_TIME, variable), variable <= limit) for branch, limit in zip(self.branches, self.breakpoints)]
        conditions.append((self.branches[-1].subs(STRAINED_TIME, variable), True))
        return sympy.Piecewise(*conditions)

    def cosine_coefficient(self, harmonic: int) -> sympy.Expr:
        """Exact d_n = (2/π) ∫_0^π v_k(s) cos(ns) ds (1/π for n = 0)."""
        if not isinstance(harmonic, int) or harmonic < 0:
            raise ValueError("harmonic must be a non-negative integer")
        if self.stretched:
            raise UnsupportedNonlinearityError(
                "a stretched contact arc has no fixed-s closed form: take the spectrum of Expansion.displacement "
                "(lindstedt.expansion_spectrum) instead of exact cosine coefficients"
            )
        total = None
        for piece, lower, upper in zip(self._pieces, self._limits, self._limits[1:]):
            value = piece.times_cosine(harmonic).integral(lower, upper)
            total = value if total is None else total + value
        weight = sympy.Integer(1 if harmonic == 0 else 2) / sympy.pi
        return sympy.simplify(weight * self._convert(total))

    def cosine_coefficients(self, highest: int) -> tuple[sympy.Expr, ...]:
        """(d_0, …, d_highest)."""
        return tuple(self.cosine_coefficient(n) for n in range(highest + 1))

    def value_at_zero(self) -> sympy.Expr:
        """v_k(0) exactly."""
        return sympy.simplify(self.branches[0].subs(STRAINED_TIME, 0))

    def to_latex(self) -> str:
        """LaTeX (``cases`` on [0, π]) through sympy's printer."""
        return latex(self.to_expr())

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: breakpoints (contact angles) and one sympy-parsable branch per piece."""
        return {
            "order": self.order,
            "interval": "[0, pi], extended evenly and 2*pi-periodically",
            "breakpoints": [sympy.sstr(value) for value in self.breakpoints],
            "pieces": [sympy.sstr(branch) for branch in self.branches],
            **({"stretched_pieces": list(self.stretched)} if self.stretched else {}),
        }
