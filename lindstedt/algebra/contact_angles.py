r"""Closed forms of a piecewise expansion written in its contact angles: κ, β = arccos κ, σ = sqrt(1 − κ²).

The coefficients ω_k of ``u'' + ω0² u + ε f(u) = 0`` with a symbolic breakpoint
(``f = (u − b)_+``, ...) are exact closed forms in ``arccos(b/a0)`` and powers of
``sqrt(1 − b²/a0²)``; printed as they come out of the hierarchy they run to
thousands of characters.  With one symbol per contact point,

    κ = b/a0,    β = arccos κ  (the contact angle),    σ = sqrt(1 − κ²) = sin β,

and the relation ``σ² = 1 − κ²`` used to reduce every power of σ to degree ≤ 1
in the numerator (σ only as a monomial in the denominator), the same
coefficient is a short polynomial in β, κ, σ and π over a monomial: e.g. for
``f = (u − b)_+``, ``ω_1 = (β − κσ)/(2π ω0)``.

The rewrite is an identity: each step is a substitution of a definition or a
reduction modulo ``σ² − (1 − κ²)``, so putting the definitions back
(:meth:`ContactAngleForm.restore`) gives the original coefficient.  Any text or
LaTeX output can print :attr:`ContactAngleForm.forms` after the definitions.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Sequence

import sympy

__all__ = ["ContactAngleForm", "in_contact_angles"]

#: The names of the three symbols of a contact point (printed κ, β, σ).
NAMES = ("kappa", "beta", "sigma")


@dataclass(frozen=True)
class ContactAngleForm:
    """Expressions rewritten in the contact-angle symbols, with the symbols' definitions.

    Attributes
    ----------
    definitions : tuple of (Symbol, Expr)
        ``(κ, b/a0), (β, acos(κ)), (σ, sqrt(1 − κ²))`` for each contact point, in order; empty when
        nothing was rewritten (no arccos of a symbolic argument).
    forms : tuple of Expr
        The expressions, in the same order as given, in κ, β, σ (the given ones where nothing applies).
    """

    definitions: tuple[tuple[sympy.Symbol, sympy.Expr], ...]
    forms: tuple[sympy.Expr, ...]

    def restore(self, expression: sympy.Expr) -> sympy.Expr:
        """``expression`` with the definitions put back (σ, then β, then κ): in the original symbols.

        Examples
        --------
        >>> b, a0 = sympy.symbols("b a0", positive=True)
        >>> expression = sympy.acos(b / a0) - b / a0 * sympy.sqrt(1 - b**2 / a0**2)
        >>> form = in_contact_angles([expression])
        >>> form.forms[0]
        beta - kappa*sigma
        >>> sympy.simplify(form.restore(form.forms[0]) - expression)
        0
        """
        for symbol, definition in reversed(self.definitions):
            expression = expression.subs(symbol, definition)
        return expression


def in_contact_angles(expressions: Sequence[sympy.Expr]) -> ContactAngleForm:
    r"""Rewrite closed forms in κ_i = (the argument of each symbolic arccos), β_i = acos κ_i, σ_i = sqrt(1 − κ_i²).

    Each distinct ``acos(X)`` with free symbols in ``X`` is a contact point: ``X = κ`` is solved for one
    symbol of ``X`` (a parameter before ``a0`` and ``omega0``), substituted, and then ``acos κ → β``,
    ``(c (1 − κ²))^(n/2) → c^(n/2) σ^n`` (c > 0), and each numerator and denominator is reduced modulo
    ``σ² = 1 − κ²`` (σ leaves a monomial denominator).  The result is exact: :meth:`ContactAngleForm.restore`
    gives back the given expressions.  Symbol names already used by the expressions are not reused
    (``kappa`` becomes ``kappa_1``, …).

    Parameters
    ----------
    expressions : sequence of sympy expressions
        E.g. the ω_k of an :class:`~lindstedt.Expansion` of a piecewise nonlinearity with a symbolic gap.

    Returns
    -------
    ContactAngleForm
        The definitions (empty when no expression has an arccos of a symbolic argument) and the forms.

    Examples
    --------
    >>> import lindstedt
    >>> expansion = lindstedt.expand("Max(0, u - b)", order=2, params={"b": None})
    >>> form = in_contact_angles(expansion.omega)
    >>> form.definitions
    ((kappa, b/a0), (beta, acos(kappa)), (sigma, sqrt(1 - kappa**2)))
    >>> form.forms[1]
    (beta - kappa*sigma)/(2*pi*omega0)
    """
    expressions = tuple(sympy.sympify(expression, strict=True) for expression in expressions)
    arguments: list[sympy.Expr] = []
    for expression in expressions:
        for atom in sorted(expression.atoms(sympy.acos), key=sympy.default_sort_key):
            if atom.args[0].free_symbols and atom.args[0] not in arguments:
                arguments.append(atom.args[0])
    used = set().union(*(expression.free_symbols for expression in expressions)) if expressions else set()
    points = []
    for index, argument in enumerate(arguments, 1):
        solved = _solve_for_symbol(argument, [point[3] for point in points])
        if solved is None:
            continue
        suffix = "" if len(arguments) == 1 else f"_{index}"
        kappa, beta, sigma = (_fresh(name + suffix, used, assumption)
                              for name, assumption in zip(NAMES, ({"real": True}, {"positive": True}, {"positive": True})))
        symbol, value = solved
        points.append((kappa, beta, sigma, symbol, value(kappa), argument))
    if not points:
        return ContactAngleForm((), expressions)
    definitions: list[tuple[sympy.Symbol, sympy.Expr]] = []
    for kappa, beta, sigma, _, _, argument in points:
        definitions += [(kappa, argument), (beta, sympy.acos(kappa)), (sigma, sympy.sqrt(1 - kappa**2))]
    return ContactAngleForm(tuple(definitions), tuple(_rewrite(expression, points) for expression in expressions))


def _fresh(name: str, used: set, assumptions: dict) -> sympy.Symbol:
    """A symbol named ``name`` (then ``name_1``, ``name_2``, … ) whose name no symbol in ``used`` has."""
    names = {symbol.name for symbol in used}
    candidate, count = name, 0
    while candidate in names:
        count += 1
        candidate = f"{name}_{count}"
    symbol = sympy.Symbol(candidate, **assumptions)
    used.add(symbol)
    return symbol


def _solve_for_symbol(argument: sympy.Expr, taken: list[sympy.Symbol]) -> tuple[sympy.Symbol, Callable] | None:
    """(s, κ ↦ the value of s where argument = κ) for one symbol s of ``argument`` not solved for yet
    (parameters before a0 and omega0), or None."""
    kappa = sympy.Dummy("kappa")
    symbols = sorted(argument.free_symbols - set(taken), key=lambda s: (s.name in ("a0", "omega0"), s.name))
    for symbol in symbols:
        solutions = sympy.solve(argument - kappa, symbol)
        if len(solutions) == 1 and sympy.cancel(argument.subs(symbol, solutions[0]) - kappa) == 0:
            return symbol, lambda new, solution=solutions[0]: solution.subs(kappa, new)
    return None


def _rewrite(expression: sympy.Expr, points: list) -> sympy.Expr:
    """One expression in the points' κ, β, σ, reduced modulo σ² = 1 − κ²."""
    for kappa, beta, sigma, symbol, value, _ in points:
        expression = expression.subs(symbol, value)
        expression = expression.replace(lambda x: isinstance(x, sympy.acos) and x.args[0] == kappa, lambda x: beta)
        expression = expression.replace(
            lambda x, k=kappa: _sigma_multiple(x, k) is not None,
            lambda x, k=kappa, s=sigma: _sigma_multiple(x, k) ** x.exp * s ** int(2 * x.exp),
        )
    numerator, denominator = sympy.fraction(sympy.together(expression))
    for kappa, _, sigma, _, _, _ in points:
        relation = sigma**2 - (1 - kappa**2)
        power = max(sympy.degree(denominator, sigma), 0)
        numerator = sympy.rem(sympy.expand(numerator * sigma**power), relation, sigma)
        denominator = sympy.rem(sympy.expand(denominator * sigma**power), relation, sigma)
    numerator, denominator = sympy.fraction(sympy.cancel(numerator / denominator))
    generators = [symbol for kappa, beta, sigma, *_ in points for symbol in (beta, sigma)]
    numerator = sympy.collect(sympy.expand(numerator), generators, sympy.factor)
    for kappa, _, sigma, _, _, _ in points:
        numerator = numerator.subs((kappa - 1) * (kappa + 1), -(sigma**2))
    return numerator / sympy.factor(denominator)


def _sigma_multiple(power: sympy.Expr, kappa: sympy.Symbol) -> sympy.Expr | None:
    """c when ``power`` is (c (1 − κ²))^(n/2) with c > 0 free of κ (it is then c^(n/2) σ^n), else None."""
    if not (power.is_Pow and power.base.is_Add and (2 * power.exp).is_integer and power.base.has(kappa)):
        return None
    ratio = sympy.cancel(power.base / (1 - kappa**2))
    return ratio if ratio.is_positive and not ratio.has(kappa) else None
