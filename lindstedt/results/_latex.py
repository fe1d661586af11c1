"""LaTeX of an expansion of ``u'' + ω0² u + ε f(u) = 0``: the equation, the derivation's assumptions, the ω_k and
ω(ε) = Σ_k ω_k ε^k, the turning point A(ε) and phase φ(ε) from (u0, v0), optionally the waveforms v_k(s)
(:meth:`lindstedt.Expansion.to_latex`, whose fragment Jupyter shows through ``_repr_latex_``).

Functions of an :class:`~lindstedt.Expansion`, typed ``Any``: :mod:`lindstedt.results.expansion` imports this
module, never the other way round.
"""

from __future__ import annotations

import re
from typing import Any, Mapping, Sequence

import sympy

from ..render.display import latex_text
from ._readable import readable_coefficients
from ..problems.oscillator import Oscillator
from ..problems.parsing import parse_expression

__all__ = ["expansion_latex", "latex"]

_LATEX_NAMES = {"a0": "a_{0}", "omega0": r"\omega_{0}", "epsilon": r"\varepsilon"}


def latex(expression: sympy.Expr) -> str:
    names = {symbol: _LATEX_NAMES[symbol.name] for symbol in expression.free_symbols if symbol.name in _LATEX_NAMES}
    return sympy.latex(expression, symbol_names=names)


def _equation_latex(problem: Oscillator) -> str:
    r"""``\ddot u + ω0² u + ε f(u) = 0`` with a unit coefficient dropped and parentheses only where needed."""
    u = sympy.Symbol("u")
    stiffness = problem.omega0**2
    if stiffness == 1:
        linear = "u"
    elif stiffness.is_Add:
        linear = r"\left(" + latex(stiffness) + r"\right) u"
    else:
        linear = latex(stiffness) + " u"
    force = problem.f.subs(problem.variable, u)
    text = latex(force)
    if force.is_Add or force.could_extract_minus_sign():
        text = r"\left(" + text + r"\right)"
    return r"\ddot u + " + linear + r" + \varepsilon " + text + " = 0"


def _initial_latex(problem: Oscillator) -> str:
    if problem.has_initial_velocity:
        return r"u(0) = " + latex(problem.u0) + r",\ \dot u(0) = " + latex(problem.v0)
    if problem.normalization == "initial":
        release = latex(problem.a0) + ("" if problem.a1 == 0 else r" + \varepsilon " + latex(problem.a1))
        return r"u(0) = " + release + r",\ \dot u(0) = 0"
    return r"\dot u(0) = 0,\ " + latex(problem.a0) + r" = \text{first-harmonic amplitude}"


_LONG_COEFFICIENT = 80  # LaTeX characters: a longer ω_k is written by its name in ω(ε)


def _series_latex(coefficients: Sequence[sympy.Expr], gauge: sympy.Expr, names: Sequence[str] | None = None) -> str:
    r"""Σ_k c_k gauge^k in increasing powers; with ``names``, if one c_k is long, every c_k (k ≥ 1) is written by its name.

    >>> a0 = sympy.Symbol("a0", positive=True)
    >>> _series_latex([a0, sympy.Rational(-1, 2), 0, a0 + 1], sympy.Symbol("epsilon"))
    'a_{0} - \\frac{\\varepsilon}{2} + \\left(a_{0} + 1\\right) \\varepsilon^{3}'
    """
    coefficients = [sympy.sympify(coefficient, strict=True) for coefficient in coefficients]
    by_name = names is not None and any(len(latex(c)) > _LONG_COEFFICIENT for c in coefficients)
    terms: list[tuple[bool, str]] = []  # (negative, text of the magnitude)
    for k, coefficient in enumerate(coefficients):
        if coefficient == 0:
            continue
        power = gauge**k
        if by_name and (k > 0 or len(latex(coefficient)) > _LONG_COEFFICIENT):
            text = names[k] + ("" if k == 0 else " " + latex(power))
            terms.append((False, text))
        elif coefficient.is_Add:
            text = r"\left(" + latex(coefficient) + r"\right)"
            terms.append((False, text if k == 0 else text + " " + latex(power)))
        elif coefficient.could_extract_minus_sign():
            terms.append((True, latex(-coefficient * power)))
        else:
            terms.append((False, latex(coefficient * power)))
    if not terms:
        return "0"
    negative, first = terms[0]
    text = ("- " if negative else "") + first
    for negative, term in terms[1:]:
        text += (" - " if negative else " + ") + term
    return text


_RELATION = re.compile(r"\s(<=|>=|!=|<|>|=)\s")
_RELATION_LATEX = {"<": "<", ">": ">", "=": "=", "<=": r"\le", ">=": r"\ge", "!=": r"\ne"}


def _assumption_latex(text: str, symbols: Mapping[str, sympy.Symbol]) -> str:
    r"""One assumption of :class:`DerivationAssumptions` (``"-a0 < b < a0 (contact: …)"``) as LaTeX.

    The relation is read back through the package's whitelist parser and printed by sympy; the reason
    in parentheses is kept as text, except the self-evident "is declared positive".  What cannot be
    read is shown as text.

    >>> a0, b = sympy.Symbol("a0", positive=True), sympy.Symbol("b", real=True)
    >>> _assumption_latex("-a0 < b < a0 (contact: the orbit crosses u = b)", {"a0": a0, "b": b})
    '- a_{0} < b < a_{0}\\ \\text{(contact: the orbit crosses u = b)}'
    """
    relation, _, reason = text.partition(" (")
    reason = reason[:-1] if reason.endswith(")") else reason
    pieces = _RELATION.split(relation)
    try:
        operands = [latex(parse_expression(piece, symbols=symbols, what="assumption")) for piece in pieces[::2]]
    except Exception:  # not a relation between expressions: keep the words
        return r"\text{" + latex_text(text) + "}"
    if len(operands) < 2:
        return r"\text{" + latex_text(text) + "}"
    result = operands[0]
    for operator, operand in zip(pieces[1::2], operands[1:]):
        result += f" {_RELATION_LATEX[operator]} {operand}"
    if reason and "is declared" not in reason:
        result += r"\ \text{(" + latex_text(reason) + ")}"
    return result


def expansion_latex(expansion: Any, waveforms: bool) -> str:
    r"""The ``align*`` fragment of :meth:`lindstedt.Expansion.to_latex` (waveforms only when asked)."""
    problem = expansion.problem
    lines = [r"& " + _equation_latex(problem) + r",\quad " + _initial_latex(problem)]
    assumptions = _assumptions_latex(expansion)
    if assumptions:
        lines.append(r"& " + assumptions)
    definitions, omega, amplitude, phase = readable_coefficients(expansion)
    if definitions:
        lines.append(r"& \text{where } " + r",\ ".join(f"{latex(symbol)} = {latex(value)}" for symbol, value in definitions))
    for exponent, value in zip(expansion.exponents, omega):  # ω_{k/2} multiplies ε^{k/2} in the gauge sqrt(ε)
        lines.append(rf"\omega_{{{exponent}}} &= {latex(value)}")
    remainder = rf" + O(\varepsilon^{{{latex(sympy.Rational(expansion._steps * expansion.order + 1, expansion._steps))}}})"
    names = [rf"\omega_{{{exponent}}}" for exponent in expansion.exponents]
    lines.append(r"\omega(\varepsilon) &= " + _series_latex(omega, expansion.gauge, names) + remainder)
    if problem.has_initial_velocity:
        lines.append(r"u(t) &= v(\omega t + \varphi(\varepsilon); \varepsilon),\quad v(0; \varepsilon) = A(\varepsilon)")
        lines.append(r"A(\varepsilon) &= " + _series_latex(amplitude, expansion.gauge) + remainder)
        lines.append(r"\varphi(\varepsilon) &= " + _series_latex(phase, expansion.gauge) + remainder)
    if waveforms:
        for waveform in expansion.waveforms:
            lines.append(rf"v_{{{waveform.order}}}(s) &= {waveform.to_latex()}")
    header = f"% lindstedt: {problem.describe()}\n"
    body = header + "\\begin{align*}\n" + " \\\\\n".join(lines) + "\n\\end{align*}\n"
    if waveforms and expansion.stretched_arcs:  # the arcs' own expansion, in stretched time
        body += "\n".join(arc.to_latex() for arc in expansion.stretched_arcs) + "\n"
    return body


def _assumptions_latex(expansion: Any) -> str:
    r"""``\text{assuming } …`` : the derivation's assumptions on free symbols and, for piecewise f, the regime."""
    symbols = {symbol.name: symbol for symbol in expansion.problem.free_symbols}
    parts = [_assumption_latex(assumption.text, symbols) for assumption in expansion._assumptions.assumptions]
    text = r"\text{assuming } " + r",\ ".join(parts) if parts else ""
    if expansion.is_piecewise:
        regime = rf"\text{{regime: {latex_text(expansion.regime)}, valid for }} t = O(\varepsilon^{{{latex(expansion.validity_exponent)}}})"
        text = text + r";\quad " + regime if text else regime
    return text
