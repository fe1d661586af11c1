"""Stretched contact arcs of an expansion as results: the arc-length series s*(ε), μ and Y_n(τ).

On a piece that holds a turning point and a non-polynomial contact law (Hertz c|u − b|^p, analytic laws),
the engine (:mod:`lindstedt.engine.stretched`) solves Ω² w'' + w + ε̂ f̂(w) = 0 in the stretched time
τ = s/s*(ε) ∈ [0, 1] with Y(τ) = Σ_n ε̂^n Y_n(τ); this module is its exported, evaluable form
(Chebyshev coefficients of Y_n and dY_n/dτ in v = (1 − τ)^{1/d}, schema ``lindstedt.stretched-arc/1``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import mpmath
import numpy as np
import sympy

from .._errors import OrderError
from ..engine.stretched import FloatArc
from ..render.display import DIGITS, format_number, format_vector, jupyter_latex, labelled_repr
from ..render.json import JsonExport
from .._precision import locked_methods, workdps

__all__ = ["STRETCHED_TIME", "StretchedArcSeries", "arc_series"]


STRETCHED_TIME = sympy.Symbol("tau", nonnegative=True)


def _chebyshev_sum(coefficients: list[Any], x: Any) -> Any:
    """Σ_k c_k T_k(x) by Clenshaw's recurrence (mpmath numbers)."""
    later, latest = 0, 0
    for coefficient in reversed(coefficients[1:]):
        later, latest = coefficient + 2 * x * later - latest, later
    return coefficients[0] + x * later - latest


@locked_methods()
@dataclass(frozen=True)
class StretchedArcSeries(JsonExport):
    """A contact arc with a non-polynomial law (Hertz, analytic), expanded in its own stretched time.

    On the arc, ``u = sign · a0 · Σ_n ε̂^n Y_n(τ)`` with ``ε̂ = ε/ω0²`` (``gauge``'s variable),
    ``τ = s/ℓ(ε)`` (``side = "release"``: the arc holds u(0); ``sign = +1``) or
    ``τ = (π − s)/ℓ(ε)`` (``side = "far"``: the far turning point; ``sign = −1``), where
    ``ℓ(ε) = Σ_n ℓ_n ε̂^n`` is the arc's half-length in strained time and
    ``Y_n(τ) = Σ_k c_{n,k} T_k(2 (1 − τ)^{1/d} − 1)`` (Chebyshev polynomials T_k).  The
    contact ends at τ = 1 for every ε, where Y = ``contact_point``.  ``mu`` are the
    coefficients of μ = Ω²/ℓ², Ω = ω/ω0.  Numbers at the expansion's working precision.

    Examples
    --------
    >>> import lindstedt
    >>> arc = lindstedt.expand("Max(0, u)**(3/2)", order=1, a0=1, omega0=1, precision=20).stretched_arcs[0]
    >>> arc.side, arc.denominator, round(float(arc.length[0]), 12)
    ('release', 2, 1.570796326795)
    """

    SCHEMA: ClassVar[str] = "lindstedt.stretched-arc/1"

    side: str
    sign: int
    denominator: int
    exponent: str | None
    contact_point: Any
    length: tuple[Any, ...]
    mu: tuple[Any, ...]
    chebyshev: tuple[tuple[Any, ...], ...]
    slope_chebyshev: tuple[tuple[Any, ...], ...]
    digits: int

    def fixed_s_derivative(self, strained_time: Any, order: int, times: int) -> Any:
        """``[ε̂^order] ∂^times/∂s^times`` of the normalised displacement ``sign · Σ_n ε̂^n Y_n(τ(s))`` at an interior s.

        Inside the arc (away from its moving end) the fixed-s expansion exists: it is what the phase
        of an orbit that starts in contact needs.  Mixed derivatives by ``mpmath.diff`` on the series
        truncated at ``order`` (exact through ε̂^order), at the arc's working precision.
        """
        if order >= len(self.chebyshev):
            raise OrderError(f"the stretched arc is known through order {len(self.chebyshev) - 1}, not {order}")
        with workdps(self.digits + 15):
            rows = [[mpmath.mpf(c) for c in row] for row in self.chebyshev[: order + 1]]
            lengths = [mpmath.mpf(value) for value in self.length[: order + 1]]

            def displacement(s: Any, scaled: Any) -> Any:
                length = mpmath.polyval(lengths[::-1], scaled)
                tau = (s if self.side == "release" else mpmath.pi - s) / length
                x = 2 * (1 - tau) ** (mpmath.mpf(1) / self.denominator) - 1
                total = mpmath.polyval([_chebyshev_sum(row, x) for row in rows][::-1], scaled)
                return self.sign * total

            value = mpmath.diff(displacement, (mpmath.mpf(strained_time), 0), (times, order)) / mpmath.factorial(order)
        return +value

    def value(self, tau: float, epsilon: float, omega0: float = 1.0) -> float:
        """Σ_n ε̂^n Y_n(τ) in float arithmetic (the normalised displacement on the arc, before sign · a0)."""
        values = [[float(c) for c in row] for row in self.chebyshev]
        weights = (epsilon / omega0**2) ** np.arange(len(values))
        return float(FloatArc(self.denominator, values, values).evaluate(np.asarray(tau, dtype=float), weights, False))

    def to_latex(self) -> str:
        """The representation on the arc, as a LaTeX sentence."""
        variable = r"s/\ell(\varepsilon)" if self.side == "release" else r"(\pi - s)/\ell(\varepsilon)"
        power = "" if self.exponent is None else rf", contact law $\propto |u - b|^{{{self.exponent}}}$"
        sign = "" if self.sign > 0 else "-"
        length = ""
        for n, value in enumerate(self.length):  # increasing powers of ε̂, signs folded into the joins
            monomial = "" if n == 0 else r"\,\hat\varepsilon" if n == 1 else rf"\,\hat\varepsilon^{{{n}}}"
            term = mpmath.nstr(abs(value), 12) + monomial
            length += ("- " if value < 0 else "") + term if not length else (" - " if value < 0 else " + ") + term
        return (
            rf"Stretched contact arc ({self.side} side{power}): $u = {sign}a_0 \sum_n \hat\varepsilon^n Y_n(\tau)$, "
            rf"$\tau = {variable}$, $\hat\varepsilon = \varepsilon/\omega_0^2$, $\ell(\varepsilon) = {length} + \dots$, "
            rf"$Y_n(\tau) = \sum_k c_{{n,k}} T_k\bigl(2 (1 - \tau)^{{1/{self.denominator}}} - 1\bigr)$ "
            rf"({len(self.chebyshev[0])} Chebyshev coefficients per order, {self.digits} digits; see to_json)."
        )

    def _repr_latex_(self) -> str:
        """Jupyter's rendering: the :meth:`to_latex` sentence (inline math)."""
        return jupyter_latex(self.to_latex())

    def __repr__(self) -> str:
        """The arc's side, law and lengths to 10 digits; the Chebyshev tables by their size (``.chebyshev`` holds them).

        Examples
        --------
        >>> import lindstedt
        >>> arc = lindstedt.expand("Max(0, u)**(3/2)", order=1, a0=1, omega0=1, precision=20).stretched_arcs[0]
        >>> print(repr(arc))
        StretchedArcSeries(
          side='release',
          sign=1,
          d=2,
          exponent='3/2',
          contact_point=0.0,
          length=[1.570796327, -0.3594420704],
          mu=[0.4052847346, 0.3709618659],
          chebyshev=<2 orders x 64 coefficients; see .chebyshev>,
          digits=20,
        )
        """
        orders, size = len(self.chebyshev), len(self.chebyshev[0]) if self.chebyshev else 0
        return labelled_repr("StretchedArcSeries", [
            ("side", repr(self.side)),
            ("sign", str(self.sign)),
            ("d", str(self.denominator)),
            ("exponent", repr(self.exponent)),
            ("contact_point", format_number(self.contact_point)),
            ("length", format_vector(self.length, DIGITS)),
            ("mu", format_vector(self.mu, DIGITS)),
            ("chebyshev", f"<{orders} orders x {size} coefficients; see .chebyshev>"),
            ("digits", str(self.digits)),
        ])

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: every number as a decimal string at the working precision."""
        def text(value: Any) -> str:
            return mpmath.nstr(value, self.digits, min_fixed=-1, max_fixed=1) if not isinstance(value, str) else value

        return {
            "schema": self.SCHEMA,
            "representation": "u = sign*a0*sum_n epsh**n * sum_k c[n][k]*T_k(2*(1 - tau)**(1/d) - 1), epsh = epsilon/omega0**2, "
                              "tau = s/length (release side) or (pi - s)/length (far side), length = sum_n length[n]*epsh**n",
            "side": self.side,
            "sign": self.sign,
            "d": self.denominator,
            "exponent": self.exponent,
            "contact_point": text(self.contact_point),
            "length": [text(value) for value in self.length],
            "mu": [text(value) for value in self.mu],
            "chebyshev": [[text(value) for value in row] for row in self.chebyshev],
            "slope_chebyshev": [[text(value) for value in row] for row in self.slope_chebyshev],
        }


def arc_series(hierarchy: Any, arcs: tuple[Any, Any], highest: int) -> tuple[StretchedArcSeries, ...]:
    """The stretched arcs of a 1-dof piecewise hierarchy through order ``highest`` of the gauge (``arcs``: the
    engine's one-component :class:`~lindstedt.engine.stretched.VectorArc` at the release and at the far turning point,
    None where the piece is polynomial)."""
    result = []
    for which, arc in enumerate(arcs):
        if arc is None:
            continue
        lengths = tuple(hierarchy.arc_length(which, n) for n in range(highest + 1))  # mpf already: mpmath.mpf() would round to mp.prec
        series = [arc.series(n, arc.mode) for n in range(highest + 1)]  # the oscillator's one component
        result.append(StretchedArcSeries(
            side="release" if which == 0 else "far",
            sign=1 if which == 0 else -1,
            denominator=arc.denominator,
            exponent=None if arc.exponent is None else str(arc.exponent),
            contact_point=arc.kappa,
            length=lengths,
            mu=tuple(arc.mu(n) for n in range(highest + 1)),
            chebyshev=tuple(tuple(values) for values, _ in series),
            slope_chebyshev=tuple(tuple(slopes) for _, slopes in series),
            digits=arc.digits,
        ))
    return tuple(result)
