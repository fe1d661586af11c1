"""Results of the Lindstedt–Poincaré expansion of ``u'' + ω0² u + ε f(u) = 0``.

An :class:`Expansion` of order N holds, lazily and exactly,

* ``omega`` = (ω_0, …, ω_N): ``ω(ε) = Σ_k ω_k ε^k``;
* ``alpha`` = (α_0, …, α_N): ``ω(ε)² = Σ_k α_k ε^k``;
* ``waveforms`` = (v_0, …, v_N): ``u(t) = Σ_k ε^k v_k(ω t)``, each an exact
  even cosine polynomial :class:`Waveform`.

The numeric evaluator :meth:`Expansion.displacement` pairs the waveforms
v_0 … v_N with the frequency through ω_{N+1} (computed on demand, it needs only
the secular part of the next forcing): that is the consistent truncation whose
error is O(ε^{N+1}) uniformly for t ≤ C/ε.

Numeric evaluation (:meth:`Expansion.frequency`, :meth:`Expansion.displacement`, :meth:`Expansion.velocity`,
:meth:`Expansion.frequency_coefficients`) works on floats computed once per expansion and parameter values and
is vectorised over ε, t and arrays of parameter values.  With free symbols, the closed forms (ω_k, the waveform
coefficients, the contact-angle shifts, the assumptions' signs) are compiled once into one float64 evaluator
with a first-order rounding-error bound (:func:`lindstedt.export.stable.compile_family`); a value is used where
its bound is below 1e-13 (relative for ω_k, of |a0| for u), else replaced by the exact series of a gap
coefficient in acos κ or by the exact expression.  Floats are taken as their exact binary value and checked
against the derivation's assumptions by vectorised sign tests (undecided cases exactly); exact numbers a double
cannot hold (``"3/10"``) are evaluated through the exactly substituted coefficients.  The warnings read ω_{N+1}
(ω_{N+2} for the phase drift) only where they could speak: the exact term is derived where a stand-in as large
as :func:`lindstedt.results.accuracy.next_term_bound` (1000 times the geometric extrapolation of the known
terms) would make them speak; below that, a true term smaller than the stand-in (by a factor >= 9 on 21 test
problems, orders 1-6) cannot change the answer.

General initial data u(0) = u0, u'(0) = v0 (``lindstedt.expand(f, u0=..., v0=...)``): the expansion
is released at rest at the orbit's positive turning point ``A(ε) = Σ A_k ε^k`` (:attr:`Expansion.amplitude`)
and ``u(t) = Σ_k ε^k v_k(ω t + φ(ε))`` with the exact phase series ``φ(ε) = Σ φ_k ε^k``
(:attr:`Expansion.phase`); the evaluators, :meth:`Expansion.displacement_expr` and generated code include it.

JSON schema ``lindstedt.expansion/1`` (:meth:`Expansion.to_dict`)::

    {
      "schema": "lindstedt.expansion/1",
      "problem": {"equation": str, "f": str, "a0": str, "a1": str, "omega0": str,
                  "parameters": {name: str}, "normalization": str},
      "order": int, "normalization": "initial" | "harmonic",
      "gauge": "epsilon" | "sqrt(epsilon)",    # ω(ε) = Σ_k ω_k gauge^k
      "exponents": [str, ...],        # the power of ε of each ω_k: k, or k/2
      "omega": [str, ...],            # ω_0..ω_N (ω_0..ω_2N in the gauge ε^(1/2)), sympy-parsable
      "omega_float": [float | null],  # null where symbolic
      "alpha": [str, ...], "alpha_float": [float | null],
      "omega_next": str,              # ω_{N+1}, used by the displacement evaluator
      "waveforms": [{"order": k, "cosine_coefficients": {"n": str}}]   # optional; piecewise f:
                   [{"order": k, "breakpoints": [str], "pieces": [str], "interval": str}]
      "regime", "validity_exponent", "contact_angles"                   # piecewise f only
      # from u0, v0 only: "problem" also has "u0", "v0"; and
      "solution": str, "amplitude": [str], "amplitude_float": [float | null],   # A_k
      "phase": [str], "phase_float": [float | null]                            # φ_k
    }
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, field
from .._precision import LOCK, cached_property, locked, locked_methods, warn_caller, workdps
from collections import OrderedDict
from typing import Any, Callable, Mapping, NamedTuple, Sequence

import mpmath
import numpy as np
import sympy

from .accuracy import (
    ExpansionValidityWarning,
    branch_bound,
    displacement_error,
    gauge_values,
    next_term_bound,
    phase_warning,
    quiet_radius,
    series_warning,
    series_warning_mask,
)
from .assumptions import DerivationAssumptions, check_names, shown_values
from .orbit_range import OrbitRange, orbit_range, range_function
from .._errors import OrderError, ParameterError, ProblemError, UnsupportedNonlinearityError
from ..export._stable_source import stable_function
from ..export.stable import compile_family
from ..problems.parsing import parse_expression, parse_floats, parse_real
from ..export.json import finite_float
from ._recipe import derived_again
from ..export.display import jupyter_latex, labelled_repr, latex_text, shorten
from ..algebra.branch import Branch, EvaluationPoint
from ..problems.oscillator import Oscillator, _decided_sign, reduce_quadratic
from ..engine.branches import BranchHierarchy, FloatBranches
from ..engine.contact import PiecewiseNormalForm
from ..engine.smooth import MAX_ORDER, NormalForm, SmoothHierarchy
from ._waveform_data import _WAVEFORM_TOLERANCE, _WaveformData, _WaveformLayout
from .stretched_arcs import STRETCHED_TIME, StretchedArcSeries

__all__ = ["Expansion", "ExpansionValidityWarning", "Waveform", "PiecewiseWaveform", "STRAINED_TIME", "EPSILON", "TIME"]



STRAINED_TIME = sympy.Symbol("s", real=True)
EPSILON = sympy.Symbol("epsilon", real=True)
TIME = sympy.Symbol("t", real=True)
SCHEMA = "lindstedt.expansion/1"

_LATEX_NAMES = {"a0": "a_{0}", "omega0": r"\omega_{0}", "epsilon": r"\varepsilon"}


def _latex(expression: sympy.Expr) -> str:
    names = {symbol: _LATEX_NAMES[symbol.name] for symbol in expression.free_symbols if symbol.name in _LATEX_NAMES}
    return sympy.latex(expression, symbol_names=names)


def _equation_latex(problem: Oscillator) -> str:
    r"""``\ddot u + ω0² u + ε f(u) = 0`` with a unit coefficient dropped and parentheses only where needed."""
    u = sympy.Symbol("u")
    stiffness = problem.omega0**2
    if stiffness == 1:
        linear = "u"
    elif stiffness.is_Add:
        linear = r"\left(" + _latex(stiffness) + r"\right) u"
    else:
        linear = _latex(stiffness) + " u"
    force = problem.f.subs(problem.variable, u)
    text = _latex(force)
    if force.is_Add or force.could_extract_minus_sign():
        text = r"\left(" + text + r"\right)"
    return r"\ddot u + " + linear + r" + \varepsilon " + text + " = 0"


def _initial_latex(problem: Oscillator) -> str:
    if problem.has_initial_velocity:
        return r"u(0) = " + _latex(problem.u0) + r",\ \dot u(0) = " + _latex(problem.v0)
    if problem.normalization == "initial":
        release = _latex(problem.a0) + ("" if problem.a1 == 0 else r" + \varepsilon " + _latex(problem.a1))
        return r"u(0) = " + release + r",\ \dot u(0) = 0"
    return r"\dot u(0) = 0,\ " + _latex(problem.a0) + r" = \text{first-harmonic amplitude}"


_LONG_COEFFICIENT = 80  # LaTeX characters: a longer ω_k is written by its name in ω(ε)


def _series_latex(coefficients: Sequence[sympy.Expr], gauge: sympy.Expr, names: Sequence[str] | None = None) -> str:
    r"""Σ_k c_k gauge^k in increasing powers; with ``names``, if one c_k is long, every c_k (k ≥ 1) is written by its name.

    >>> a0 = sympy.Symbol("a0", positive=True)
    >>> _series_latex([a0, sympy.Rational(-1, 2), 0, a0 + 1], EPSILON)
    'a_{0} - \\frac{\\varepsilon}{2} + \\left(a_{0} + 1\\right) \\varepsilon^{3}'
    """
    coefficients = [sympy.sympify(coefficient, strict=True) for coefficient in coefficients]
    by_name = names is not None and any(len(_latex(c)) > _LONG_COEFFICIENT for c in coefficients)
    terms: list[tuple[bool, str]] = []  # (negative, text of the magnitude)
    for k, coefficient in enumerate(coefficients):
        if coefficient == 0:
            continue
        power = gauge**k
        if by_name and (k > 0 or len(_latex(coefficient)) > _LONG_COEFFICIENT):
            text = names[k] + ("" if k == 0 else " " + _latex(power))
            terms.append((False, text))
        elif coefficient.is_Add:
            text = r"\left(" + _latex(coefficient) + r"\right)"
            terms.append((False, text if k == 0 else text + " " + _latex(power)))
        elif coefficient.could_extract_minus_sign():
            terms.append((True, _latex(-coefficient * power)))
        else:
            terms.append((False, _latex(coefficient * power)))
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
        operands = [_latex(parse_expression(piece, symbols=symbols, what="assumption")) for piece in pieces[::2]]
    except Exception:  # not a relation between expressions: keep the words
        return r"\text{" + latex_text(text) + "}"
    if len(operands) < 2:
        return r"\text{" + latex_text(text) + "}"
    latex = operands[0]
    for operator, operand in zip(pieces[1::2], operands[1:]):
        latex += f" {_RELATION_LATEX[operator]} {operand}"
    if reason and "is declared" not in reason:
        latex += r"\ \text{(" + latex_text(reason) + ")}"
    return latex


@locked
def _as_float(expression: sympy.Expr) -> float | None:
    """The float of a numeric coefficient for JSON; None when symbolic, or beyond a float's range (JSON has no inf)."""
    return None if expression.free_symbols else finite_float(expression)


@locked  # sympy's evalf of acos, … sets mpmath's process-wide precision
def _to_float(expression: sympy.Expr) -> float:
    """float() of a numeric expression; NaN where it is not a finite real number (checked by :func:`_finite`)."""
    try:
        return float(expression)
    except (TypeError, ValueError):
        return math.nan


def _finite(numbers: np.ndarray, substitution: Mapping[sympy.Symbol, sympy.Expr]) -> np.ndarray:
    if not np.all(np.isfinite(numbers)):
        given = shown_values(substitution)
        raise ParameterError(
            f"the expansion's coefficients are singular or not real at {given or 'these values'}: the values are at a "
            "degenerate point of the symbolic derivation; re-derive with the numbers substituted "
            "(lindstedt.expand(..., a0=..., params=...))"
        )
    return numbers


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
        return _latex(self.to_expr())


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
        return _latex(self.to_expr())

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: breakpoints (contact angles) and one sympy-parsable branch per piece."""
        return {
            "order": self.order,
            "interval": "[0, pi], extended evenly and 2*pi-periodically",
            "breakpoints": [sympy.sstr(value) for value in self.breakpoints],
            "pieces": [sympy.sstr(branch) for branch in self.branches],
            **({"stretched_pieces": list(self.stretched)} if self.stretched else {}),
        }


def _series_power(coefficients: list[sympy.Expr], power: int, order: int) -> sympy.Expr:
    """The x^order coefficient of (Σ_{k≥1} coefficients[k] x^k)^power (coefficients[0] is ignored; missing ones
    are zero: for power ≥ 2 the x^order coefficient does not involve coefficients[order])."""
    coefficients = list(coefficients) + [sympy.Integer(0)] * (order + 1 - len(coefficients))
    table = [sympy.Integer(1)] + [sympy.Integer(0)] * order
    for _ in range(power):
        table = [sympy.Add(*[coefficients[k] * table[j - k] for k in range(1, j + 1) if table[j - k] != 0]) for j in range(order + 1)]
    return table[order]


def _at_angle(expression: sympy.Expr, cosine: sympy.Expr, sine: sympy.Expr, angle: sympy.Expr) -> sympy.Expr:
    """An expression in s (polynomial in s, cos(n s), sin(n s)) at s = angle, with cos angle, sin angle given exactly."""
    s = STRAINED_TIME
    if any(atom.args[0] != s for atom in expression.atoms(sympy.cos, sympy.sin) if atom.has(s)):
        expression = sympy.expand_trig(expression)
    return expression.xreplace({sympy.cos(s): cosine, sympy.sin(s): sine}).xreplace({s: angle})


def _tidy(value: sympy.Expr, angle: sympy.Expr) -> sympy.Expr:
    """A phase coefficient as a polynomial in the angle ψ0 (float hierarchies: evaluated)."""
    if value.has(sympy.Float):
        return value.evalf()
    if value.free_symbols:  # symbolic ω0 or parameters: one rational function (the angle is one of its generators)
        return sympy.cancel(value)
    return sympy.collect(sympy.expand(value), angle)


def _phase_coefficients(expansion: "Expansion", highest: int) -> tuple[sympy.Expr, ...]:
    """φ_0 … φ_highest of the orbit through (u0, v0), v0 ≠ 0 (see :attr:`Expansion.phase`)."""
    problem = expansion.problem
    start, speed, omega0, amplitude = problem.u0, abs(problem.v0), problem.omega0, problem.a0
    sign = -1 if problem.v0 > 0 else 1  # φ = ∓ψ: v0 > 0 means the orbit is before its positive turning point
    angle = sympy.atan2(speed / omega0, start)  # ψ0 in (0, π)
    # Symbolic ω0 or parameters: compute in K(a), a = A0 (a² = u0² + v0²/ω0²), so that no radicals pile up.
    to_field, reduce, output = _quadratic_field(problem) if problem.free_symbols else (None, None, None)
    a = amplitude if to_field is None else to_field(amplitude)
    cosine, sine = start / a, speed / (omega0 * a)  # cos ψ0, sin ψ0 > 0
    piece = 0
    arc_derivative: Callable[[int, int], sympy.Expr] | None = None  # v_k^{(m)}(ψ0) when ψ0 is on a stretched arc
    if expansion.is_piecewise:
        for index, boundary in enumerate(expansion._form.boundaries):  # by increasing angle, i.e. decreasing κ
            side = _decided_sign(sympy.simplify(boundary.kappa - cosine), "u0 against a breakpoint")
            if side == 0:  # u0 on a crossed breakpoint: ψ(ε) is the moving contact angle s*(ε)
                shifts = [expansion.contact_angle_correction(k)[index] for k in range(1, highest + 1)]
                return tuple(sign * value for value in (expansion.contact_angles[index], *shifts))
            piece += side > 0
        arcs = expansion._form.system.arcs
        last = len(expansion._form.boundaries)
        if (piece == 0 and arcs[0] is not None) or (piece == last and arcs[1] is not None):
            # u0 on a stretched contact arc: inside it the fixed-s expansion exists, numerically
            arc = next(item for item in expansion.stretched_arcs if item.side == ("release" if piece == 0 else "far"))
            if problem.free_symbols:
                raise UnsupportedNonlinearityError("an orbit that starts on a stretched contact arc needs numeric omega0 and parameters")
            with workdps(arc.digits + 10):
                numeric_angle = mpmath.mpf(sympy.N(angle, arc.digits + 10))

            def arc_derivative(k: int, m: int) -> sympy.Expr:
                scale = amplitude * omega0 ** (-2 * k)  # v_k = a0 ω0^{-2k} [ε̂^k] W
                return scale * sympy.Float(arc.fixed_s_derivative(numeric_angle, k, m), arc.digits)
    waveforms: dict[int, Any] = {}
    derivatives: dict[tuple[int, int], sympy.Expr] = {}

    def derivative(k: int, m: int) -> sympy.Expr:
        """v_k^{(m)}(ψ0), exact (the branch of the piece containing ψ0 for piecewise f; numeric on a stretched arc)."""
        if (k, m) not in derivatives and arc_derivative is not None:
            derivatives[k, m] = arc_derivative(k, m)
        if (k, m) not in derivatives:
            if k not in waveforms:
                waveforms[k] = expansion.waveform(k)
            waveform = waveforms[k]
            if isinstance(waveform, Waveform):
                total = sympy.Integer(0)
                for harmonic, value in waveform.coefficients:
                    value = value if to_field is None else to_field(value)
                    cos_n = sympy.chebyshevt(harmonic, cosine)
                    sin_n = sine * sympy.chebyshevu(harmonic - 1, cosine) if harmonic else sympy.Integer(0)
                    trig = (cos_n, -sin_n, -cos_n, sin_n)[m % 4]
                    total += value * harmonic**m * trig
            else:
                branch = sympy.diff(waveform.branches[piece], STRAINED_TIME, m)
                if to_field is not None:
                    branch = to_field(branch)
                total = _at_angle(branch, cosine, sine, angle)
            derivatives[k, m] = reduce(total) if reduce is not None else total
        return derivatives[k, m]

    psi: list[sympy.Expr] = [angle]
    slope = -speed / omega0  # v_0'(ψ0) = −A0 sin ψ0
    for n in range(1, highest + 1):
        total = derivative(n, 0)
        for k in range(0, n):
            for m in range(1, n - k + 1):
                if k == 0 and m == 1:
                    continue  # the unknown ψ_n
                power = _series_power(psi, m, n - k)
                if power != 0:
                    total += derivative(k, m) * power / math.factorial(m)
        psi.append(_tidy(-total / slope, angle) if reduce is None else reduce(-total / slope))
    if output is not None:
        psi = [output(value) for value in psi]
    return tuple(sign * value for value in psi)


def _quadratic_field(problem: Oscillator) -> tuple[Callable, Callable, Callable] | tuple[None, None, None]:
    """(to_field, reduce, output) for arithmetic in K(a), a = A0 = (u0² + v0²/ω0²)^{1/2} of a symbolic problem:
    ``to_field`` writes the half-integer powers of A0's radicand through a, ``reduce`` gives the canonical
    P + Q a, ``output`` puts A0 back.  (None, None, None) when A0 is not one square root times a rational factor."""
    amplitude = problem.a0
    roots = [atom for atom in amplitude.atoms(sympy.Pow) if atom.exp == sympy.Rational(1, 2)]
    if len(roots) != 1:
        return None, None, None
    base = roots[0].base
    factor = sympy.cancel(amplitude / roots[0])  # A0 = sqrt(base)·factor
    if factor.has(base):
        return None, None, None
    generator = sympy.Dummy("A0", positive=True)
    square = sympy.expand(problem.u0**2 + problem.v0**2 / problem.omega0**2)

    def to_field(expression: sympy.Expr) -> sympy.Expr:
        powers = {
            atom: (generator / factor) ** int(2 * atom.exp)
            for atom in expression.atoms(sympy.Pow)
            if atom.base == base and (2 * atom.exp).is_Integer and not atom.exp.is_Integer
        }
        return expression.xreplace(powers) if powers else expression

    def reduce(expression: sympy.Expr) -> sympy.Expr:
        return reduce_quadratic(expression, generator, square)

    def output(expression: sympy.Expr) -> sympy.Expr:
        return expression.xreplace({generator: amplitude})

    return to_field, reduce, output


_COEFFICIENT_TOLERANCE = 1e-13  # relative rounding bound accepted for a compiled ω_k, φ_k
_WARNING_TOLERANCE = 1e-3  # ... for ω_{N+1}, ω_{N+2} when only a warning reads them
_STABLE_AFTER = 4  # exact evaluations of one ω_k before its stable series is generated (≈ 0.1-0.4 s)
_MEMORY = 64  # scalar parameter points whose float data an expansion keeps
_RANGE_MEMORY = 4096  # parameter points whose OrbitRange an expansion keeps (small objects)


class _Point(NamedTuple):
    """Parameter values as floats, in the order of Expansion.arguments, with the float data computed for them."""

    arrays: tuple[Any, ...]  # float or float array per argument
    shape: tuple[int, ...]  # their broadcast shape (() for scalars)
    cache: dict[Any, Any]  # checked flag, compiled values (kept for the last _MEMORY scalar points)


def _binary_value(value: sympy.Expr) -> float | None:
    """The double equal to the exact number ``value``, or None."""
    if not value.is_Rational:
        return None
    number = float(value)
    return number if sympy.Rational(number) == value else None


def _horner(points: Any, coefficients: np.ndarray) -> Any:
    """Σ_k c_k x^k by Horner's rule, c_k of shape P broadcast against x (as numpy's polyval for one P)."""
    if coefficients.ndim == 1 and not np.ndim(points):  # plain floats: the same operations, without numpy's overhead
        x, total = float(points), 0.0
        for coefficient in coefficients[::-1].tolist():
            total = total * x + coefficient
        return np.float64(total)
    result = coefficients[-1] + 0 * points
    for coefficient in coefficients[-2::-1]:
        result = result * points + coefficient
    return result


@locked_methods("frequency", "displacement", "velocity")  # float evaluators: each locks its own slow part
@dataclass(frozen=True)
class Expansion:
    """Lindstedt–Poincaré expansion of an :class:`~lindstedt.Oscillator` to a given order.

    Everything is computed on first access and cached; the object itself is
    frozen and keeps a reference to its problem.

    Examples
    --------
    >>> import lindstedt
    >>> expansion = lindstedt.expand("u**3", order=2)
    >>> expansion.omega[2]
    -21*a0**4/(256*omega0**3)
    >>> round(expansion.frequency(0.1, values={"a0": 1, "omega0": 1}), 12)
    1.0366796875
    """

    problem: Oscillator
    order: int
    _hierarchy: SmoothHierarchy | BranchHierarchy = field(repr=False, compare=False)
    _form: NormalForm | PiecewiseNormalForm = field(repr=False, compare=False)
    #: (precision, numeric) of the LindstedtPoincare that derived it: how a process that unpickles it re-derives it
    _method: Any = field(default=None, repr=False, compare=False)  # the method that derived it: its recipe

    def __reduce__(self) -> tuple[Any, tuple[Any, ...]]:
        """Pickled as its recipe (problem, order, method): the receiving process re-derives it (lazily, cached
        there), so expansions travel to process pools and Dask workers.

        Examples
        --------
        >>> import pickle, lindstedt
        >>> e = lindstedt.expand("Max(0, u - 1/3)", order=2, a0=1, omega0=1)
        >>> pickle.loads(pickle.dumps(e)).omega == e.omega
        True
        """
        if self._method is None:
            raise TypeError("an Expansion built without its method cannot be pickled; derive it with lindstedt.expand")
        return derived_again, (self._method, self.problem, self.order)

    @property
    def is_piecewise(self) -> bool:
        """True for piecewise-linear f (unilateral springs)."""
        return self._form.regime != "smooth"

    @property
    def regime(self) -> str:
        """``"smooth"``, or for piecewise f: ``"contact"``, ``"no contact"`` or ``"grazing"``."""
        return self._form.regime

    @property
    def validity_exponent(self) -> sympy.Rational:
        """p in the validity time T_ε ~ ε^p: −1 (simple roots of v0 − b), −1/2 (grazing, double root)."""
        return self._form.validity_exponent

    @property
    def gauge(self) -> sympy.Expr:
        """The expansion variable: ``epsilon``, or ``sqrt(epsilon)`` when the perturbed orbit crosses a
        breakpoint that the unperturbed orbit only touches (grazing: ω(ε) is not analytic at 0).

        Every sequence of coefficients (``omega``, ``alpha``, ``waveforms``, the index of
        :meth:`omega_correction`) runs over the powers of the gauge: ω(ε) = Σ_k ω_k gauge^k,
        k = 0 … gauge-order of ε^N (2N for ``sqrt(epsilon)``).

        Examples
        --------
        >>> import lindstedt
        >>> e = lindstedt.expand("Max(0, u + 1)", order=3, a0=1, omega0=1)   # grazing at the far turning point
        >>> e.gauge, e.omega[5]
        (sqrt(epsilon), -8/(3*pi))
        """
        return EPSILON if self._steps == 1 else EPSILON ** sympy.Rational(1, self._steps)

    @property
    def _steps(self) -> int:
        """Powers of the gauge per power of ε (1, or 2 for the gauge ε^{1/2})."""
        return getattr(self._form, "gauge", 1)

    @property
    def exponents(self) -> tuple[sympy.Rational, ...]:
        """The power of ε of each entry of ``omega`` (k/2 in the gauge sqrt(epsilon))."""
        return tuple(sympy.Rational(k, self._steps) for k in range(self._steps * self.order + 1))

    @property
    def contact_angles(self) -> tuple[sympy.Expr, ...]:
        """β_i = arccos κ_i of the contact boundaries crossed by v_0 (empty for smooth f)."""
        return tuple(boundary.contact_angle for boundary in self._form.boundaries)

    def contact_angle_correction(self, order: int) -> tuple[sympy.Expr, ...]:
        """σ_{i,order}: the ε^order coefficient of the moving contact angles s_i*(ε) (empty for smooth f)."""
        if not self._form.boundaries:
            return ()
        self._check(order)
        return tuple(self._to_expr(value, order, sympy.Integer(1)) for value in self._hierarchy.boundary_shift(order))

    # -- exact quantities ---------------------------------------------------------------
    def _to_expr(self, element: Any, power: int, prefactor: sympy.Expr) -> sympy.Expr:
        """prefactor · (ε̂/ε)^power · element: a coefficient of the normalised hierarchy in the problem's units."""
        return self._form.scaled_expr(element, power, prefactor)

    def _check(self, order: int, frequency: bool = False) -> None:
        highest = self._steps * (MAX_ORDER + 1)
        if isinstance(order, bool) or not isinstance(order, int) or order < 0 or order > highest:
            raise OrderError(f"correction index must be an integer in [0, {highest}], got {order!r}")
        released = self.problem.release_order
        # from (u0, v0) the engine knows the turning point through A_M: waveforms and contact angles through the
        # gauge index s·M, ω and α (which need the waveforms before them) through s·M + 1
        reach = None if released is None else self._steps * released + (1 if frequency else 0)
        if reach is not None and order > reach:
            raise OrderError(
                f"correction index {order} is beyond what the turning-point series A_1 … A_{released} of this expansion "
                f"from (u0, v0) determines (index {reach}); expand to a higher order: "
                f"lindstedt.expand(..., order={max(self.order, -(-(order - (1 if frequency else 0)) // self._steps) - 1)})"
            )

    def omega_correction(self, order: int) -> sympy.Expr:
        """Exact ω_order (any order, computed lazily; beyond ``self.order`` allowed, from (u0, v0) up to order + 1)."""
        self._check(order, frequency=True)
        return self._to_expr(self._hierarchy.frequency(order), order, self.problem.omega0)

    def alpha_correction(self, order: int) -> sympy.Expr:
        """Exact α_order, the ε^order coefficient of ω²."""
        self._check(order, frequency=True)
        return self._to_expr(self._hierarchy.squared_frequency(order), order, self.problem.omega0**2)

    def waveform(self, order: int) -> Waveform | PiecewiseWaveform:
        """Exact v_order(s): a :class:`Waveform` (smooth f) or :class:`PiecewiseWaveform`.

        A piece on a stretched contact arc (non-polynomial contact law) holds the placeholder
        ``Y_order(tau)``: its expansion is :attr:`stretched_arcs`.
        """
        self._check(order)
        if self.is_piecewise:
            form = self._form
            pieces = tuple(components[0] for components in self._hierarchy.branches(order))
            scale = self.problem.a0 * form.epsilon_scale**order
            branches = [scale * piece.to_expr(STRAINED_TIME, form.to_expr) for piece in pieces]
            stretched = self._stretched_pieces
            for piece in stretched:
                branches[piece] = sympy.Function(f"Y_{order}")(STRETCHED_TIME)
            branches = tuple(branches)
            limits = (form.system.zero_point, *[b.point for b in form.boundaries], form.system.pi_point)
            return PiecewiseWaveform(
                order=order,
                breakpoints=self.contact_angles,
                branches=branches,
                _pieces=pieces,
                _limits=limits,
                _convert=lambda element, scale=scale: scale * form.to_expr(element),
                stretched=stretched,
            )
        series = self._hierarchy.waveform(order)
        coefficients = tuple(
            (harmonic, self._to_expr(series.coefficient(harmonic), order, self.problem.a0)) for harmonic in series.harmonics
        )
        return Waveform(order=order, coefficients=coefficients)

    @property
    def _stretched_pieces(self) -> tuple[int, ...]:
        if not self.is_piecewise:
            return ()
        first, last = self._form.system.arcs
        return tuple(piece for piece, arc in ((0, first), (len(self._form.system.states) - 1, last)) if arc is not None)

    @cached_property
    def stretched_arcs(self) -> tuple[StretchedArcSeries, ...]:
        """The contact arcs expanded in stretched time (non-polynomial contact laws; empty otherwise)."""
        if not self.is_piecewise:
            return ()
        result = []
        highest = self._steps * self.order
        hierarchy = self._hierarchy
        for which, arc in enumerate(self._form.system.arcs):
            if arc is None:
                continue
            lengths = tuple(hierarchy.arc_length(which, n) for n in range(highest + 1))  # mpf already: mpmath.mpf() would round to mp.prec
            series = [arc.series(n) for n in range(highest + 1)]
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

    def _solve_through(self, highest: int) -> int:
        """Solve the hierarchy through order ``highest`` in one pass (so that its checkpoints report progress
        against the whole request, see :mod:`lindstedt.limits`); returns ``highest``."""
        self._hierarchy.squared_frequency(highest)
        return highest

    @cached_property
    def omega(self) -> tuple[sympy.Expr, ...]:
        """(ω_0, …, ω_N), exact."""
        self._solve_through(self._steps * self.order)
        return tuple(self.omega_correction(k) for k in range(self._steps * self.order + 1))

    @cached_property
    def alpha(self) -> tuple[sympy.Expr, ...]:
        """(α_0, …, α_N) with ω² = Σ α_k ε^k, exact."""
        self._solve_through(self._steps * self.order)
        return tuple(self.alpha_correction(k) for k in range(self._steps * self.order + 1))

    @cached_property
    def waveforms(self) -> tuple[Waveform | PiecewiseWaveform, ...]:
        """(v_0, …, v_N), exact cosine polynomials."""
        self._solve_through(self._steps * self.order)
        return tuple(self.waveform(k) for k in range(self._steps * self.order + 1))

    @cached_property
    def amplitude(self) -> tuple[sympy.Expr, ...]:
        """(A_0, …, A_N): the turning point ``v(0; ε) = Σ_k A_k gauge^k`` the expansion is released at, exact.

        General initial data (u0, v0): the positive turning point of the orbit through them, from
        the energy (:meth:`Oscillator.amplitude_series`).  A release at rest: ``(a0, a1, 0, …)``;
        ``"harmonic"`` normalization: ``v_k(0)``.  Indexed like :attr:`omega` (powers of the gauge).

        Examples
        --------
        >>> import lindstedt
        >>> lindstedt.expand("Max(0, u - 1/4)", order=2, u0="3/5", v0="4/5", omega0=1).amplitude
        (1, -11/50, 88/625)
        """
        highest = self._steps * self.order
        if self.problem.normalization == "harmonic":
            return tuple(self.waveform(k).value_at_zero() for k in range(highest + 1))
        series = self.problem.amplitude_series(self.order)
        values = [sympy.Integer(0)] * (highest + 1)
        for k, value in enumerate(series):
            values[self._steps * k] = value
        return tuple(values)

    @cached_property
    def phase(self) -> tuple[sympy.Expr, ...]:
        """(φ_0, …, φ_N): the phase ``φ(ε) = Σ_k φ_k gauge^k`` of ``u(t) = v(ω t + φ(ε); ε)``, exact.

        Zero for a release at rest.  From (u0, v0): ``v(φ; ε) = u0`` with the sign of
        ``u'(0) = ω v_s(φ) = v0``, i.e. ``φ_0 = atan2(−v0/ω0, u0)`` and φ_k from the Taylor
        expansion of the waveforms at φ_0: with ψ = ``|φ|`` = ψ_0 + Δ, Δ = Σ_{k≥1} ψ_k gauge^k,
        ``Σ_{k,m} v_k^{(m)}(ψ_0) [Δ^m]_{n−k}/m! = 0`` at order n ≥ 1, which is linear in ψ_n
        through ``v_0'(ψ_0) = −|v0|/ω0``.  For piecewise f the branch of the piece that
        contains ψ_0 is used (its analytic continuation); if u0 sits on a crossed breakpoint
        the phase is the moving contact angle itself, ψ = s*(ε) (:meth:`contact_angle_correction`).

        Examples
        --------
        >>> import lindstedt
        >>> e = lindstedt.expand("u**3", order=1, u0=0, v0=1, omega0=1)   # kicked from equilibrium
        >>> e.phase
        (-pi/2, 0)
        """
        highest = self._steps * self.order
        if not self.problem.has_initial_velocity:
            return tuple(sympy.Integer(0) for _ in range(highest + 1))
        return _phase_coefficients(self, highest)

    @cached_property
    def omega_next(self) -> sympy.Expr:
        """ω_{N+1}: the frequency term the displacement evaluator pairs with v_0..v_N."""
        return self.omega_correction(self._steps * self.order + 1)

    # -- numeric evaluation ---------------------------------------------------------------
    def _substitution(self, values: Mapping[Any, Any] | None) -> dict[sympy.Symbol, sympy.Expr]:
        """The numeric substitution for ``values``, checked against the derivation's assumptions.

        Checked once per values (cached with the float data): repeated evaluations pay nothing.
        """
        key = ("substitution", self._values_key(values))
        if key not in self._float_cache:  # numeric_substitution names an unknown value (check_names) or a missing one
            self._float_cache[key] = self._assumptions.check(self.problem.numeric_substitution(values))
        return self._float_cache[key]

    @cached_property
    def _assumptions(self) -> DerivationAssumptions:
        return DerivationAssumptions(self.problem, self._form, self.order)

    def _floats(self, expressions: list[sympy.Expr], values: Mapping[Any, Any] | None) -> np.ndarray:
        substitution = self._substitution(values)
        return _finite(np.array([_to_float(e.xreplace(substitution)) for e in expressions], dtype=float), substitution)

    def frequency(self, epsilon: Any, values: Mapping[Any, Any] | None = None, *, order: int | None = None) -> Any:
        """ω(ε) = Σ_{k≤order} ω_k ε^k as float (vectorised over ``epsilon`` and over arrays in ``values``).

        Evaluated from float coefficients computed once per expansion and parameter values (compiled
        closed forms for free symbols, accepted only where their rounding-error bound is below 1e-13
        relative; stable series or exact evaluation elsewhere, see :meth:`frequency_coefficients`).
        Judged against :meth:`epsilon_range`: raises :class:`~lindstedt.ParameterError` at an ε where no
        periodic orbit exists (the motion escapes, a contact piece loses its stiffness, the release point is an
        equilibrium); warns (:class:`ExpansionValidityWarning`) where the orbit has left the contact regime the
        expansion was derived for, where ε is beyond the series' radius of convergence, or where its terms stop
        decreasing.

        Parameters
        ----------
        epsilon : float or array
            Read by the one reading of numbers: exact strings such as ``"1/10"`` are accepted; None, booleans,
            NaN, infinities, complex numbers and words raise :class:`~lindstedt.ParameterError`.
        values : mapping, optional
            Numbers for the symbols left free (a0, omega0, parameters); float arrays are broadcast
            against ``epsilon`` and each other.  Floats are used as they are; other numbers (ints,
            fractions, strings) are read exactly, and a value a double cannot hold exactly is evaluated
            through the exact coefficients.
        order : int, optional
            Truncation order (default: the expansion's order).

        Examples
        --------
        >>> import lindstedt, numpy as np
        >>> e = lindstedt.expand("Max(0, u - kappa)", order=2, a0=1, omega0=1, params={"kappa": None})
        >>> eps, kappa = np.array([0.01, 0.1]), np.array([0.3, -0.5])
        >>> both = e.frequency(eps, values={"kappa": kappa})       # element by element
        >>> bool(np.all(both == [e.frequency(x, values={"kappa": y}) for x, y in zip(eps, kappa)]))
        True
        """
        fast = self.__dict__.get("_fast_frequency")
        if fast is not None and values is None and order is None and type(epsilon) is float:
            coefficients, radius = fast
            if -radius <= epsilon <= radius:  # no warning possible there (see _set_fast_frequency)
                total = 0.0
                for coefficient in coefficients:
                    total = total * epsilon + coefficient
                return total
        return self._frequency(epsilon, values, order)

    @locked
    def _frequency(self, epsilon: Any, values: Mapping[Any, Any] | None, order: int | None) -> Any:
        epsilon = parse_floats(epsilon, what="epsilon")
        last = self._steps * (self.order if order is None else order)
        point = self._read(values)
        if point is None:
            return self._frequency_exact(epsilon, values, last)
        coefficients = self._omega_values(last, point)
        points = self._gauge_values(epsilon)
        result = _horner(points, coefficients)
        message = self._range_message(epsilon, point, values) or self._series_message(coefficients, last, points, point)
        if message:
            warn_caller(ExpansionValidityWarning(message))
        if values is None and order is None and not point.arrays and self._steps == 1 and not message:
            self._set_fast_frequency(coefficients, last)
        return float(result) if np.ndim(result) == 0 else result

    def _frequency_exact(self, epsilon: Any, values: Mapping[Any, Any] | None, last: int) -> Any:
        """ω(ε) from the exactly substituted coefficients (values a double cannot hold)."""
        coefficients = self._frequency_coefficients(last + 1, values)
        points = self._gauge_values(epsilon)
        result = np.polynomial.polynomial.polyval(points, coefficients[: last + 1])
        message = self._range_message(epsilon, None, values) or series_warning(coefficients, last, points, str(self.gauge))
        if message:
            warn_caller(ExpansionValidityWarning(message))
        return float(result) if np.ndim(result) == 0 else result

    def frequency_coefficients(self, values: Mapping[Any, Any] | None = None, *, order: int | None = None) -> np.ndarray:
        """ω_0 … ω_n as floats (n the gauge index of ε^order), vectorised over arrays in ``values``:
        shape ``(n + 1,) + broadcast shape``.

        With free symbols each ω_k is a compiled closed form, accepted where its first-order
        rounding-error bound is at most 1e-13 of its value; elsewhere (a closed form that cancels,
        e.g. near a grazing gap κ → ±1) it comes from exact series in acos κ (one gap symbol,
        :mod:`lindstedt.export.stable`, relative error ≤ 1e-13) or from the exact expression.

        Examples
        --------
        >>> import lindstedt
        >>> e = lindstedt.expand("Max(0, u - kappa)", order=2, a0=1, omega0=1, params={"kappa": None})
        >>> e.frequency_coefficients({"kappa": [0.0, 0.999999]}).shape
        (3, 2)
        >>> float(e.frequency_coefficients({"kappa": 0.0})[1])      # omega_1 = 1/4 at kappa = 0
        0.25
        """
        last = self._steps * (self.order if order is None else order)
        point = self._read(values)
        if point is None:
            return self._frequency_coefficients(last, values)[: last + 1].copy()
        return self._omega_values(last, point).copy()

    def truncation_error_estimate(self, epsilon: Any, values: Mapping[Any, Any] | None = None, *, order: int | None = None) -> Any:
        """``|ω_{order+1} ε^{order+1}|``: the size of the first neglected term of ω(ε) (vectorised).

        Examples
        --------
        >>> import lindstedt
        >>> e = lindstedt.expand("u**3", order=1, a0=1, omega0=1)
        >>> round(float(e.truncation_error_estimate(0.1)), 12)     # |omega_2| eps^2 = 21/256 * 0.01
        0.0008203125
        """
        epsilon = parse_floats(epsilon, what="epsilon")
        last = self._steps * (self.order if order is None else order)
        point = self._read(values)
        if point is None:
            coefficient = self._frequency_coefficients(last + 1, values)[last + 1]
        else:  # vectorised over parameter arrays too
            coefficient = self._omega_values(last + 1, point)[last + 1]
        estimate = np.abs(coefficient * self._gauge_values(epsilon) ** (last + 1))
        message = self._range_message(epsilon, point, values)
        if message:
            warn_caller(ExpansionValidityWarning(message))
        return estimate

    def displacement_error_estimate(self, t: Any, epsilon: float, values: Mapping[Any, Any] | None = None) -> np.ndarray:
        """Estimated error of :meth:`displacement` at ``t`` (vectorised): the phase drift ``|a0| δω t``, δω the terms of ω
        after ω_{n+1} (which the displacement uses) through one more power of ε, plus the first neglected waveform
        term (the last kept one times η̂).

        Examples
        --------
        >>> import lindstedt
        >>> e = lindstedt.expand("u**3", order=2, a0=1, omega0=1)
        >>> bool(e.displacement_error_estimate(10.0, 0.01) < 1e-5 < e.displacement_error_estimate(1e6, 0.01))
        True
        """
        t, epsilon = parse_floats(t, what="t"), parse_floats(epsilon, what="epsilon", scalar=True)
        scale, amplitude, branches = self._float_branches(values)
        last = self._steps * self.order
        eta = float(self._gauge_values(float(epsilon)))
        message = self._range_message(epsilon, None, values)
        if message:
            warn_caller(ExpansionValidityWarning(message))
        # The displacement pairs v_0 … v_n with ω through ω_{n+1}: its phase drifts with the next terms, one power of ε
        # of them (two in the gauge ε^{1/2}, whose analytic and non-analytic terms interleave).
        coefficients = self._frequency_coefficients(last + 1 + self._steps, values)
        frequency_error = sum(abs(coefficients[k]) * abs(eta) ** k for k in range(last + 2, last + 2 + self._steps))
        scaled = abs(scale) ** (1 / self._steps) * eta  # η̂, the normalised gauge of the waveforms
        neglected = abs(amplitude) * scaled ** (last + 1) * branch_bound(branches.terms[last], branches.shifts[0])
        return displacement_error(amplitude, frequency_error, np.asarray(t, dtype=float), neglected)

    def epsilon_range(self, values: Mapping[Any, Any] | None = None) -> OrbitRange | None:
        """How far in ε the derivation holds at these parameter values (one point): the open interval
        ``(lower, upper)`` on which the true orbit through the release state keeps the contact regime the
        expansion was derived for, and ``radius``, the distance to the nearest singularity of ω(ε) the law gives
        (see :mod:`lindstedt.results.orbit_range`).

        Computed for every law (pieces that are not polynomials — sin u, Hertz — numerically, their radius from
        the real events only); None for a release shifted by ε a1 and the "harmonic" normalization.

        The evaluators (:meth:`frequency`, :meth:`displacement`, :meth:`velocity`, the error estimates) raise
        a :class:`~lindstedt.ParameterError` at an ε where no periodic orbit exists (the motion escapes over a
        separatrix, a contact state with ω0² + ε·slope ≤ 0 it cannot leave, the release point an equilibrium)
        and warn (:class:`ExpansionValidityWarning`, naming the bound) at an ε outside ``(lower, upper)`` or at
        ``|ε| >= radius``.

        Examples
        --------
        >>> import lindstedt
        >>> duffing = lindstedt.expand("u**3", order=2, a0=1, omega0=1)
        >>> bounds = duffing.epsilon_range()          # softening past eps a0**2 = -omega0**2: the separatrix
        >>> round(bounds.lower, 12), bounds.upper, round(bounds.radius, 12)
        (-1.0, inf, 1.0)
        >>> lindstedt.expand("Max(0, u + 3/2)", order=2, a0=1, omega0=1).epsilon_range().upper   # leaves contact
        0.2
        """
        point = self._read(values)
        if point is not None and point.shape:
            raise ParameterError("epsilon_range takes one parameter point: give scalar values")
        return self._range_at(self._range_arguments(point, values))

    @cached_property
    def _range_source(self) -> Callable[..., tuple[Any, ...]] | None:
        return range_function(self.problem, self._symbols)

    def _range_arguments(self, point: "_Point | None", values: Mapping[Any, Any] | None) -> tuple[float, ...]:
        if point is not None:
            return tuple(float(value) for value in point.arrays)
        substitution = self._substitution(values)
        return tuple(float(substitution[symbol]) for symbol in self._symbols)

    def _range_at(self, arguments: tuple[float, ...]) -> OrbitRange | None:
        """The :class:`OrbitRange` at float parameter values (about 1.6 ms each; the last _RANGE_MEMORY points kept, so
        that a repeated sweep over an array of parameter values pays it once)."""
        source = self._range_source
        if source is None:
            return None
        memory = self._float_cache.setdefault("ranges", OrderedDict())
        if arguments not in memory:
            memory[arguments] = orbit_range(*source(*arguments), self._steps)
            if len(memory) > _RANGE_MEMORY:
                memory.popitem(last=False)
        return memory[arguments]

    def _range_message(self, epsilon: Any, point: "_Point | None", values: Mapping[Any, Any] | None) -> str | None:
        """Raise where no periodic orbit exists at some ε; else the warning for ε outside the derivation's regime
        or beyond the radius of convergence (see :meth:`epsilon_range`), or None."""
        if self._range_source is None:
            return None
        gauge = self._gauge_text
        if point is None or not point.shape:
            bounds = self._range_at(self._range_arguments(point, values))
            return bounds.judge(epsilon, gauge)
        arrays = np.broadcast_arrays(np.asarray(epsilon, dtype=float), *[np.asarray(value, dtype=float) for value in point.arrays])
        columns = np.stack([array.reshape(-1) for array in arrays[1:]], axis=1)
        epsilons = arrays[0].reshape(-1)
        unique, inverse = np.unique(columns, axis=0, return_inverse=True)
        for index, row in enumerate(unique):
            message = self._range_at(tuple(float(value) for value in row)).judge(epsilons[inverse.reshape(-1) == index], gauge)
            if message:
                given = ", ".join(f"{name} = {value:.6g}" for name, value in zip(self._argument_names, row))
                return f"at {given}: {message}"
        return None

    def _gauge_values(self, epsilon: Any) -> np.ndarray:
        """The gauge at ε (ε itself, or √ε: then ε must not be negative)."""
        return gauge_values(
            epsilon, self._steps, "the orbit stays on its side and the frequency is analytic: use "
            "lindstedt.reference_solution, or expand the problem with f replaced by -f at -epsilon"
        )

    @cached_property
    def _float_cache(self) -> dict[Any, Any]:
        return {}

    @staticmethod
    def _values_key(values: Mapping[Any, Any] | None) -> tuple[tuple[str, str], ...]:
        return tuple(sorted((str(k), str(v)) for k, v in (values or {}).items()))

    def _cached(self, tag: Any, values: Mapping[Any, Any] | None, compute: Any) -> Any:
        """Float data that depends only on the parameter values, computed once per values (ε-independent).

        ``compute`` goes through :meth:`_substitution`, which checks the values against the
        derivation's assumptions once per values.
        """
        key = (tag, self._values_key(values))
        if key not in self._float_cache:
            self._float_cache[key] = compute()
        return self._float_cache[key]

    def _frequency_coefficients(self, highest: int, values: Mapping[Any, Any] | None) -> np.ndarray:
        """Float ω_0..ω_highest for these values (cached: repeated evaluations cost microseconds)."""
        return self._cached(("omega", highest), values, lambda: self._floats([self.omega_correction(k) for k in range(highest + 1)], values))

    def _float_branches(self, values: Mapping[Any, Any] | None) -> tuple[float, float, FloatBranches]:
        """ε̂/ε, a0 and the float branches of v_0..v_N for these values (cached per values)."""

        def compute() -> tuple[float, float, FloatBranches]:
            substitution = self._substitution(values)
            form = self._form

            def to_float(element: Any) -> float:
                return _to_float(form.to_expr(element).xreplace(substitution))

            branches = self._hierarchy.float_branches(self._steps * self.order, to_float)
            numbers = [term[3] for order in branches.terms for piece in order for component in piece for term in component]
            _finite(np.array(numbers + [value for order in branches.shifts for value in order], dtype=float), substitution)
            scale = float(form.epsilon_scale.xreplace(substitution))
            return scale, float(self.problem.a0.xreplace(substitution)), branches

        return self._cached("branches", values, compute)

    def _at_epsilon(self, epsilon: float, values: Mapping[Any, Any] | None) -> tuple[float, float, str | None, float]:
        """Per ε (cached): the gauge η, the frequency ω through ω_{n+1}, the series' warning (or None) and the
        phase drift rate |ω_{n+2} η^{n+2}| (the frequency is used through ω_{n+1})."""

        def compute() -> tuple[float, float, str | None, float]:
            gauge = float(self._gauge_values(epsilon))
            last = self._steps * self.order
            coefficients = self._frequency_coefficients(last + 2, values)
            frequency = float(np.polynomial.polynomial.polyval(gauge, coefficients[: last + 2]))
            message = series_warning(coefficients[: last + 2], last, np.array([gauge]), str(self.gauge))
            return gauge, frequency, message, abs(float(coefficients[last + 2])) * abs(gauge) ** (last + 2)

        # one slot per values: repeated evaluations at one ε hit it, a sweep over ε does not grow the cache
        key = ("at", self._values_key(values))
        cached = self._float_cache.get(key)
        if cached is None or cached[0] != epsilon:
            cached = self._float_cache[key] = (epsilon, compute())
        return cached[1]

    def _evaluate(self, t: Any, epsilon: Any, values: Mapping[Any, Any] | None, derivative: bool) -> Any:
        t, epsilon = parse_floats(t, what="t"), parse_floats(epsilon, what="epsilon")
        with LOCK:  # the values read, the float data (compiled on first use) and the warnings: sympy on a slow path
            point = self._read(values)
            if point is None or self._stretched_pieces:
                return self._evaluate_exact(t, epsilon, values, derivative)
            last = self._steps * self.order
            coefficients = self._omega_values(last + 1, point)  # the frequency through ω_{N+1}
            eta = self._gauge_values(epsilon)
            times = np.asarray(t, dtype=float)
            frequency = _horner(eta, coefficients)
            message = self._range_message(epsilon, point, values) or self._series_message(
                coefficients[: last + 1], last, eta, point, coefficients[last + 1])
            if message is None:
                message = self._drift_message(coefficients, last, eta, times, point)
            if message:
                warn_caller(ExpansionValidityWarning(message))
            phase = _horner(eta, self._phase_values(point)) if self.problem.has_initial_velocity else None
            layout = self._waveform_layout
            data = self._waveform_data(point, float(np.max(np.abs(eta))) if eta.size else 0.0)  # accurate for the largest |η|
        # floats only from here: the waveform over the times runs lock-free (numpy releases the GIL on large arrays)
        strained = times * frequency if phase is None else times * frequency + phase
        scaled = data.scale ** (1 / self._steps) * eta
        result = data.amplitude * layout.evaluate(data, strained, scaled, derivative)
        if derivative:
            result = result * frequency
        return result if result.ndim else float(result)

    def _evaluate_exact(self, t: Any, epsilon: Any, values: Mapping[Any, Any] | None, derivative: bool) -> Any:
        """The evaluator on exactly substituted data (values a double cannot hold; stretched contact arcs)."""
        if np.ndim(epsilon):
            raise ProblemError(
                "epsilon must be one number here (exact parameter values or a stretched contact arc); "
                "loop over epsilon, or give the parameter values as floats"
            )
        scale, amplitude, branches = self._float_branches(values)
        gauge, frequency, message, drift = self._at_epsilon(float(epsilon), values)
        times = np.asarray(t, dtype=float)
        message = self._range_message(epsilon, None, values) or message
        if message is None:
            message = phase_warning(drift, times)
        if message:
            warn_caller(ExpansionValidityWarning(message))
        strained = times * frequency + self._phase_value(gauge, values)
        result = amplitude * branches.evaluate(strained, scale ** (1 / self._steps) * gauge, derivative)[..., 0]
        if derivative:
            result = result * frequency
        return result if result.ndim else float(result)

    def _phase_value(self, gauge: float, values: Mapping[Any, Any] | None) -> float:
        """φ(ε) = Σ_{k≤N} φ_k gauge^k as a float (0 for a release at rest)."""
        if not self.problem.has_initial_velocity:
            return 0.0
        coefficients = self._cached("phase", values, lambda: self._floats(list(self.phase), values))
        return float(np.polynomial.polynomial.polyval(gauge, coefficients))

    # -- compiled evaluation: float data once per expansion and parameter values -----------------------
    @cached_property
    def _symbols(self) -> tuple[sympy.Symbol, ...]:
        """:attr:`arguments`, computed once."""
        return self.arguments

    @cached_property
    def _gauge_text(self) -> str:
        return str(self.gauge)

    @cached_property
    def _argument_names(self) -> tuple[str, ...]:
        return tuple(symbol.name for symbol in self._symbols)

    def _read(self, values: Mapping[Any, Any] | None) -> "_Point | None":
        """The parameter values as floats in the order of :attr:`arguments` (float arrays kept), checked against
        the derivation's assumptions; None when an exact number a double cannot hold is among them (then the
        exact path evaluates).

        Floats are taken as they are (their exact binary value, as the exact reader takes them) and checked by
        vectorised float tests (:meth:`_check_point`); other numbers go through the problem's reader and the
        exact check, once per values."""
        names = self._argument_names
        if not values:
            if names:
                self.problem.numeric_substitution(values)  # raises: values needed
            return self._no_parameters
        check_names(values, names)
        floats: dict[str, Any] = {}
        scalar = True
        for key, value in values.items():
            name = key.name if isinstance(key, sympy.Symbol) else str(key)
            if isinstance(value, float):
                if not math.isfinite(value):
                    parse_real(value, what=name)  # raises
                floats[name] = float(value)
            elif isinstance(value, (np.ndarray, list, tuple)) and np.asarray(value).dtype.kind in "fiu":
                array = floats[name] = np.asarray(value, dtype=float)
                if not np.all(np.isfinite(array)):
                    parse_real(float(array[~np.isfinite(array)].flat[0]), what=name)  # raises
                scalar = False
            else:
                return self._read_exact(values)
        if len(floats) != len(names) or len(values) != len(names) or any(name not in floats for name in names):
            self.problem.numeric_substitution({key: 0 for key in values})  # names the missing or unknown ones
            raise ParameterError(f"values must name {', '.join(names)} once each")
        arrays = tuple(floats[name] for name in names)
        if scalar:
            point = self._remembered(("float", arrays), arrays)
        else:
            point = _Point(arrays, np.broadcast_shapes(*[np.shape(value) for value in arrays]), {})
        self._check_point(point)
        return point

    @cached_property
    def _no_parameters(self) -> "_Point":
        return _Point((), (), {"checked": True})

    def _remembered(self, key: Any, arrays: tuple[float, ...]) -> "_Point":
        """The scalar point ``arrays`` with its cache (the last _MEMORY points are kept)."""
        memory = self._float_cache.setdefault("memory", OrderedDict())
        point = memory.get(key)
        if point is None:
            point = memory[key] = _Point(arrays, (), {})
            if len(memory) > _MEMORY:
                memory.popitem(last=False)
        return point

    def _read_exact(self, values: Mapping[Any, Any]) -> "_Point | None":
        """Exact numbers: read and checked exactly (once per values); the compiled path if doubles hold them."""
        key = ("exact", self._values_key(values))
        memory = self._float_cache.setdefault("memory", OrderedDict())
        if key in memory:
            return memory[key]
        substitution = self._substitution(values)
        numbers = [_binary_value(substitution[symbol]) for symbol in self._symbols]
        point = None
        if all(number is not None for number in numbers):
            point = self._remembered(("float", tuple(numbers)), tuple(numbers))
            point.cache["checked"] = True
        memory[key] = point
        return point

    def _check_point(self, point: "_Point") -> None:
        """The derivation's assumptions on float parameter values: vectorised sign tests with a rounding
        bound (evaluated with ω_0 … ω_M in one compiled family); an undecided or violated element is checked
        exactly, which raises the ParameterError naming the regime."""
        if point.cache.get("checked"):
            return
        family, conditions, highest = self._core
        values, bounds = family(*point.arrays) if family is not None else (None, None)
        if values is None and conditions:
            violated, undecided = np.zeros(point.shape, dtype=bool), np.ones(point.shape, dtype=bool)
        else:
            violated, undecided = self._assumptions.float_verdict(
                None if values is None else values[:conditions], None if bounds is None else bounds[:conditions], point.arrays
            )
        for index in [*np.flatnonzero(violated)[:1], *np.flatnonzero(undecided)]:
            self._assumptions.check(self.problem.numeric_substitution(self._values_at(point, int(index))))
        if values is not None:
            point.cache["core"] = (values[conditions:], bounds[conditions:], highest)
        point.cache["checked"] = True

    @property
    def _core(self) -> tuple[Any, int, int]:
        """(family, number of assumption conditions, M): one compiled family for the assumptions' conditions
        and ω_0 … ω_M (M = N, or N + 1 once ω_{N+1} is derived), evaluated once per new parameter point."""
        highest = self._steps * self.order + (1 if self._omega_known(self._steps * self.order + 1) else 0)
        conditions = self._assumptions.float_conditions

        def expressions() -> list[sympy.Expr]:
            return [*conditions, *[self._omega_expr(k) for k in range(highest + 1)]]

        return self._family(("core", highest), expressions), len(conditions), highest

    def _values_at(self, point: "_Point", index: int) -> dict[str, float]:
        return {name: float(np.broadcast_to(value, point.shape).flat[index]) for name, value in zip(self._argument_names, point.arrays)}

    def _exact_at(self, expression: sympy.Expr, point: "_Point", index: int) -> float:
        """The exact value of ``expression`` at element ``index`` of the point (its doubles read exactly)."""
        substitution = {
            symbol: sympy.Rational(float(np.broadcast_to(value, point.shape).flat[index]))
            for symbol, value in zip(self._symbols, point.arrays)
        }
        return _to_float(expression.xreplace(substitution))

    def _family(self, tag: Any, expressions: Callable[[], list[sympy.Expr]]) -> Any:
        """The compiled :class:`~lindstedt.export.stable.BoundedFamily` of some expressions (None: not compilable)."""
        families = self._float_cache.setdefault("families", {})
        if tag not in families:
            families[tag] = compile_family(expressions(), self._symbols)
        return families[tag]

    def _omega_expr(self, k: int) -> sympy.Expr:
        cache = self._float_cache.setdefault("omega expressions", {})
        if k not in cache:
            cache[k] = self.omega_correction(k)
        return cache[k]

    def _omega_known(self, k: int) -> bool:
        """Whether ω_k costs nothing more to derive (within the expansion's order, or derived already)."""
        return k <= self._steps * self.order or k in self._float_cache.get("omega expressions", {}) or (
            k == self._steps * self.order + 1 and "omega_next" in self.__dict__
        )

    def _omega_values(self, highest: int, point: "_Point", tolerance: float = _COEFFICIENT_TOLERANCE) -> np.ndarray:
        """Float ω_0 … ω_highest at the point, shape (highest + 1,) + point shape (see :meth:`frequency_coefficients`)."""
        key = ("omega", highest, tolerance)
        cache = point.cache
        if key in cache:
            return cache[key]
        if not self._symbols:
            constants = self._float_cache.setdefault("omega floats", {})
            for k in range(highest + 1):
                if k not in constants:
                    constants[k] = _to_float(self._omega_expr(k))
            rows = np.array([constants[k] for k in range(highest + 1)])
        else:
            core = cache.get("core")
            done = -1
            parts = []
            if core is not None:
                values, bounds, done = core
                done = min(done, highest)
                parts.append(self._accepted(values[: done + 1], bounds[: done + 1], range(done + 1), point, tolerance))
            for k in range(done + 1, highest + 1):
                family = self._family(("omega", k), lambda k=k: [self._omega_expr(k)])
                values, bounds = family(*point.arrays) if family is not None else (None, None)
                parts.append(self._accepted(values, bounds, [k], point, tolerance))
            rows = np.concatenate(parts)
        if not np.all(np.isfinite(rows)):
            columns = rows.reshape(rows.shape[0], -1)
            index = int(np.flatnonzero(~np.all(np.isfinite(columns), axis=0))[0])
            _finite(rows, self.problem.numeric_substitution(self._values_at(point, index)) if point.arrays else {})
        cache[key] = rows
        return rows

    def _accepted(self, values: np.ndarray | None, bounds: np.ndarray | None, indices: Any, point: "_Point", tolerance: float) -> np.ndarray:
        """Compiled ω_k where the rounding bound is at most ``tolerance`` of the value; elsewhere the stable
        series (one gap symbol, generated once a few points needed it) or the exact expression."""
        indices = list(indices)
        if values is None:
            values = np.full((len(indices), *point.shape), np.nan)
            bad = np.ones(values.shape, dtype=bool)
        else:
            bad = ~(bounds <= tolerance * np.abs(values))
            if not bad.any():
                return values
            values = values.copy()
        if bad.any():
            flat_values, flat_bad = values.reshape(len(indices), -1), bad.reshape(len(indices), -1)
            for row, k in enumerate(indices):
                self._repair(flat_values[row], flat_bad[row], k, point)
        return values

    def _repair(self, values: np.ndarray, bad: np.ndarray, k: int, point: "_Point") -> None:
        if not bad.any():
            return
        counts = self._float_cache.setdefault("repairs", {})
        counts[k] = counts.get(k, 0) + int(bad.sum())
        stable = self._stable_omega(k) if counts[k] >= _STABLE_AFTER else None
        if stable is not None:
            fixed = np.broadcast_to(np.asarray(stable(*point.arrays), dtype=float), point.shape).reshape(-1)
            usable = bad & np.isfinite(fixed)
            values[usable] = fixed[usable]
            bad = bad & ~usable
        for index in np.flatnonzero(bad):
            values[index] = self._exact_at(self._omega_expr(k), point, int(index))

    def _stable_omega(self, k: int) -> Callable[[Any], np.ndarray] | None:
        cache = self._float_cache.setdefault("stable", {})
        if k not in cache:
            cache[k] = stable_function(self._omega_expr(k), self._symbols[0]) if len(self._symbols) == 1 else None
        return cache[k]

    def _phase_values(self, point: "_Point") -> np.ndarray:
        """Float φ_0 … φ_N at the point (from (u0, v0); accepted like ω_k, exact where the bound is too large)."""
        if "phase" in point.cache:
            return point.cache["phase"]
        phase = list(self.phase)
        if not self._symbols:
            values = self._float_cache.get("phase floats")
            if values is None:
                values = self._float_cache["phase floats"] = _finite(np.array([_to_float(value) for value in phase]), {})
        else:
            family = self._family("phase", lambda: phase)
            values, bounds = family(*point.arrays) if family is not None else (np.full((len(phase), *point.shape), np.nan), None)
            bad = np.ones(values.shape, dtype=bool) if bounds is None else ~(bounds <= _COEFFICIENT_TOLERANCE * np.abs(values))
            flat_values, flat_bad = values.reshape(len(phase), -1), bad.reshape(len(phase), -1)
            for row, expression in enumerate(phase):
                for index in np.flatnonzero(flat_bad[row]):
                    flat_values[row, index] = self._exact_at(expression, point, int(index))
        point.cache["phase"] = values
        return values

    @cached_property
    def _waveform_layout(self) -> "_WaveformLayout":
        """Where each float of the displacement lives (a0, ε̂/ε, contact-angle shifts, the coefficient matrices of
        the branches), and their closed forms compiled once (or their floats, without free symbols)."""
        if not self._symbols:
            scale, amplitude, branches = self._float_branches(None)
            return _WaveformLayout.build(branches, amplitude, scale, ())
        branches = self._hierarchy.float_branches(self._steps * self.order, self._form.to_expr)
        return _WaveformLayout.build(branches, self.problem.a0, self._form.epsilon_scale, self._symbols)

    def _waveform_data(self, point: "_Point", largest: float) -> "_WaveformData":
        """The displacement's float data at the point, good for |η| up to ``largest``: compiled values where
        their rounding bound keeps u within _WAVEFORM_TOLERANCE |a0| at η̂ = (ε̂/ε)^(1/s) η, exact elsewhere."""
        layout = self._waveform_layout
        compiled = point.cache.get("waveform")
        if compiled is None:
            if layout.constants is not None:
                values, errors = layout.constants, np.zeros(layout.orders)
            elif layout.family is None:
                values = np.full((len(layout.expressions), *point.shape), np.nan)
                errors = np.full((layout.orders, *point.shape), np.inf)
            else:
                values, bounds = layout.family(*point.arrays)
                errors = layout.errors(values, bounds)
            compiled = point.cache["waveform"] = (values, errors, {})
        values, errors, repaired = compiled
        if layout.constants is None:
            size = np.abs(values[1]) ** (1 / self._steps) * largest
            powers = size[None] ** np.arange(layout.orders).reshape(-1, *[1] * np.ndim(size))
            bad = np.broadcast_to(~(np.sum(powers * errors, axis=0) <= _WAVEFORM_TOLERANCE), point.shape)
            missing = [int(index) for index in np.flatnonzero(bad) if int(index) not in repaired]
            if missing:
                values = values.copy()  # never in place: a lock-free evaluation may be reading the last data
                flat = values.reshape(len(layout.expressions), -1)
                for index in missing:
                    flat[:, index] = [self._exact_at(expression, point, index) for expression in layout.expressions]
                    repaired[index] = True
                if not np.all(np.isfinite(flat[:, missing])):
                    _finite(flat[:, missing], self.problem.numeric_substitution(self._values_at(point, missing[0])))
                point.cache["waveform"] = (values, errors, repaired)
                point.cache.pop("unpacked", None)
        unpacked = point.cache.get("unpacked")
        if unpacked is None:
            if not np.all(np.isfinite(values)):
                columns = values.reshape(values.shape[0], -1)
                index = int(np.flatnonzero(~np.all(np.isfinite(columns), axis=0))[0])
                _finite(values, self.problem.numeric_substitution(self._values_at(point, index)) if point.arrays else {})
            unpacked = point.cache["unpacked"] = layout.unpack(values)
        return unpacked

    def _series_message(self, coefficients: np.ndarray, last: int, eta: np.ndarray, point: "_Point",
                        following: np.ndarray | None = None) -> str | None:
        """:func:`series_warning` for ω_0 … ω_last at these gauge values, deriving ω_{last+1} only where it could
        make the warning speak (if ``following`` is not given and it is not derived yet): below the radius where
        a next term as large as :func:`next_term_bound` would speak, it cannot."""
        if last < 1 or eta.size == 0:
            return None
        gauge = self._gauge_text
        if following is None and self._omega_known(last + 1):
            following = self._omega_values(last + 1, point, _WARNING_TOLERANCE)[last + 1]
        if not point.shape:  # one coefficient set: the largest |η| decides, as series_warning reads it
            if following is None:
                size = np.array([float(np.max(np.abs(eta)))])
                if series_warning([*coefficients.tolist(), float(next_term_bound(coefficients))], last, size, gauge) is None:
                    return None
                following = self._omega_values(last + 1, point, _WARNING_TOLERANCE)[last + 1]
            return series_warning([*coefficients.tolist(), float(following)], last, np.asarray(eta), gauge)
        size = np.abs(eta)  # one coefficient set per element: each element is judged at its own |η|
        if following is None:
            stand_in = next_term_bound(coefficients)
            if not series_warning_mask(np.concatenate([coefficients, stand_in[None]]), last, size).any():
                return None
            following = self._omega_values(last + 1, point, _WARNING_TOLERANCE)[last + 1]
        table = np.concatenate([coefficients, np.asarray(following)[None]])
        speaking = series_warning_mask(table, last, size)
        if not speaking.any():
            return None
        index = int(np.argmax(speaking))
        rows = table.reshape(table.shape[0], *[1] * (speaking.ndim - table.ndim + 1), *table.shape[1:])
        column = np.broadcast_to(rows, (table.shape[0], *speaking.shape)).reshape(table.shape[0], -1)[:, index]
        return series_warning(list(column), last, np.array([np.broadcast_to(size, speaking.shape).flat[index]]), gauge)

    def _drift_message(self, coefficients: np.ndarray, last: int, eta: np.ndarray, times: np.ndarray, point: "_Point") -> str | None:
        """:func:`phase_warning` with the drift rate |ω_{last+2} η^{last+2}|; ω_{last+2} is derived only if a next
        term as large as :func:`next_term_bound` could make the drift reach one radian at these times."""
        if times.size == 0:
            return None
        power = np.abs(eta) ** (last + 2)
        longest = float(np.max(np.abs(times)))
        if not self._omega_known(last + 2):
            stand_in = next_term_bound(coefficients[: last + 2])
            if not float(np.max(stand_in * power)) * longest >= 1.0:
                return None
        rate = np.abs(self._omega_values(last + 2, point, _WARNING_TOLERANCE)[last + 2]) * power
        if not np.shape(rate):
            return phase_warning(float(rate), times)
        drift = np.abs(rate * times) if times.ndim else np.abs(rate) * longest
        index = int(np.argmax(drift))
        broadcast = np.broadcast_to(times, drift.shape) if times.ndim else np.full(drift.shape, longest)
        return phase_warning(float(np.broadcast_to(rate, drift.shape).flat[index]), np.array([broadcast.flat[index]]))

    def _set_fast_frequency(self, coefficients: np.ndarray, last: int) -> None:
        """Enable the scalar fast path of :meth:`frequency` (no free symbols, gauge ε): Horner in Python floats
        for |ε| up to the radius below which no warning can speak (with the next term, or its stand-in while
        ω_{N+1} is not derived: beyond that radius the general path derives it)."""
        known = self._omega_known(last + 1)
        current = self.__dict__.get("_fast_frequency_known")
        if current is not None and current >= known:
            return
        if known:
            following = float(self._omega_values(last + 1, self._no_parameters, _WARNING_TOLERANCE)[last + 1])
        else:
            following = float(next_term_bound(coefficients))
        radius = quiet_radius([*coefficients, following], last)
        bounds = self._range_at(())
        if bounds is not None:  # strictly inside the orbit's range and the disc of convergence
            radius = min(radius, bounds.radius, bounds.upper, -bounds.lower) * (1 - 1e-9)
        self.__dict__["_fast_frequency"] = (tuple(float(value) for value in coefficients[::-1]), radius)
        self.__dict__["_fast_frequency_known"] = known

    def displacement(self, t: Any, epsilon: Any, values: Mapping[Any, Any] | None = None) -> np.ndarray:
        """u(t) ≈ Σ_{k≤N} ε^k v_k(ω t + φ(ε)), ω through ω_{N+1}, φ through φ_N; vectorised over ``t``,
        ``epsilon`` and arrays in ``values`` (broadcast together).

        The phase φ(ε) is zero for a release at rest (see :attr:`phase` for initial data u0, v0).

        For piecewise-linear f the branches are used up to the *moving* contact
        angles s_i*(ε) = β_i + Σ σ_{i,k} ε^k, so the error stays O(ε^{N+1}).

        The waveform coefficients are evaluated once per parameter values (compiled closed forms, accepted
        where their rounding bound keeps u within ``1e-13 |a0|``, exact elsewhere); see :meth:`frequency`
        for how ``values`` are read.

        Examples
        --------
        >>> import lindstedt, numpy as np
        >>> e = lindstedt.expand("u**3", order=1, a0=1, omega0=1)
        >>> float(e.displacement(0.0, 0.1))
        1.0
        >>> e.displacement(np.array([0.0, np.pi]), np.array([0.1, 0.0]))   # u(0) = a0; at eps = 0, u(pi) = -a0
        array([ 1., -1.])
        """
        return self._evaluate(t, epsilon, values, derivative=False)

    def velocity(self, t: Any, epsilon: Any, values: Mapping[Any, Any] | None = None) -> np.ndarray:
        """u'(t) of the same approximation as :meth:`displacement` (vectorised the same way)."""
        return self._evaluate(t, epsilon, values, derivative=True)

    # -- symbolic views and exports -------------------------------------------------------
    def frequency_expr(self, order: int | None = None) -> sympy.Expr:
        """ω(ε) truncated at ``order`` as a sympy polynomial in ``epsilon``."""
        last = self._steps * (self.order if order is None else order)
        return sympy.Add(*[self.omega_correction(k) * self.gauge**k for k in range(last + 1)])

    def phase_expr(self, order: int | None = None) -> sympy.Expr:
        """φ(ε) truncated at ``order`` as a sympy polynomial in ``epsilon`` (0 for a release at rest)."""
        last = self._steps * (self.order if order is None else order)
        if not self.problem.has_initial_velocity:
            return sympy.Integer(0)
        if last > self._steps * self.order:
            raise OrderError(f"the phase series holds orders up to {self.order}; expand to a higher order")
        return sympy.Add(*[self.phase[k] * self.gauge**k for k in range(last + 1)])

    def amplitude_expr(self, order: int | None = None) -> sympy.Expr:
        """A(ε), the turning point the expansion is released at, truncated at ``order`` (see :attr:`amplitude`)."""
        last = self._steps * (self.order if order is None else order)
        if last > self._steps * self.order:
            raise OrderError(f"the amplitude series holds orders up to {self.order}; expand to a higher order")
        return sympy.Add(*[self.amplitude[k] * self.gauge**k for k in range(last + 1)])

    def displacement_expr(self, derivative: bool = False) -> sympy.Expr:
        """u(t; ε) = Σ_{k≤N} ε^k v_k(ω t + φ(ε)) with ω through ω_{N+1}, as a sympy expression (its time derivative
        u'(t) with ``derivative=True``, as :meth:`velocity` evaluates it).

        For piecewise-linear f the strained time is folded to [0, π]
        (evenness, 2π-periodicity) and the pieces end at the moving contact
        angles s_i*(ε) = β_i + Σ_{k≤N} σ_{i,k} ε^k, as in :meth:`displacement`.
        """
        if self._stretched_pieces:
            raise UnsupportedNonlinearityError(
                "a stretched contact arc (non-polynomial contact law) has no closed-form displacement: evaluate it with "
                "Expansion.displacement, or export Expansion.stretched_arcs (Chebyshev coefficients) with to_json"
            )
        frequency = self.frequency_expr(self.order) + self.omega_next * self.gauge ** (self._steps * self.order + 1)
        strained = frequency * TIME + self.phase_expr()
        if not self.is_piecewise:
            displacement = sympy.Add(*[EPSILON**w.order * w.to_expr(strained) for w in self.waveforms])
            return sympy.diff(displacement, TIME) if derivative else displacement
        folded = sympy.Abs(sympy.Mod(strained + sympy.pi, 2 * sympy.pi) - sympy.pi)
        pieces = [sympy.Add(*[self.gauge**w.order * w.branches[p] for w in self.waveforms]) for p in range(len(self.waveforms[0].branches))]
        if derivative:  # d/dt v(|s|) = ω sign(s) v'(|s|), s the strained time folded to (−π, π]
            pieces = [frequency * sympy.sign(sympy.Mod(strained + sympy.pi, 2 * sympy.pi) - sympy.pi) * sympy.diff(piece, STRAINED_TIME)
                      for piece in pieces]
        boundaries = [
            sympy.Add(*[self.gauge**k * self.contact_angle_correction(k)[index] for k in range(1, self._steps * self.order + 1)], angle)
            for index, angle in enumerate(self.contact_angles)
        ]
        conditions = [(piece.subs(STRAINED_TIME, folded), folded <= boundary) for piece, boundary in zip(pieces, boundaries)]
        conditions.append((pieces[-1].subs(STRAINED_TIME, folded), True))
        return sympy.Piecewise(*conditions)

    @property
    def arguments(self) -> tuple[sympy.Symbol, ...]:
        """Free symbols of the results (sorted by name): the trailing arguments of :meth:`lambdify`."""
        return tuple(sorted(self.problem.free_symbols, key=lambda symbol: symbol.name))

    def lambdify(self, quantity: str = "displacement", modules: str = "numpy") -> Callable[..., Any]:
        """A vectorised numeric function generated through ``sympy.lambdify``.

        ``quantity="displacement"`` gives ``u(t, epsilon, *arguments)``;
        ``quantity="velocity"`` gives ``u'(t, epsilon, *arguments)``;
        ``quantity="frequency"`` gives ``omega(epsilon, *arguments)``.
        The generated functions do not check ε against the expansion's range (:meth:`epsilon_range`).

        Examples
        --------
        >>> import lindstedt, numpy as np
        >>> e = lindstedt.expand("u**3", order=2, a0=1, omega0=1)
        >>> omega = e.lambdify("frequency")
        >>> round(float(omega(0.1)), 12)
        1.0366796875
        """
        if quantity in ("displacement", "velocity"):
            expression = self.displacement_expr(derivative=quantity == "velocity")
            return _lambdify((TIME, EPSILON, *self.arguments), expression, modules)
        if quantity == "frequency":
            return _lambdify((EPSILON, *self.arguments), self.frequency_expr(), modules)
        raise ProblemError(f"quantity must be 'displacement', 'velocity' or 'frequency', got {quantity!r}")

    def to_latex(self, *, waveforms: bool = False) -> str:
        r"""A LaTeX fragment (``align*``): the equation, what the derivation assumed, the ω_k, ω(ε), optionally the v_k.

        Series are written in increasing powers of ε; a coefficient longer than a line is referred to
        by its name ω_k in ω(ε) (its closed form is on its own line above).  The assumptions are those
        :meth:`frequency` checks values against (the signs of the free symbols, the contact regime such
        as ``|b| < a0`` for a gap b), plus the regime and validity time of a piecewise f.  Waveform LaTeX
        is built only when ``waveforms=True``.

        Examples
        --------
        >>> import lindstedt
        >>> print(lindstedt.expand("u**3", order=2, a0=1, omega0=1).to_latex())  # doctest: +NORMALIZE_WHITESPACE
        % lindstedt: u'' + u + eps*(u**3) = 0, u(0) = 1 [initial]
        \begin{align*}
        & \ddot u + u + \varepsilon u^{3} = 0,\quad u(0) = 1,\ \dot u(0) = 0 \\
        \omega_{0} &= 1 \\
        \omega_{1} &= \frac{3}{8} \\
        \omega_{2} &= - \frac{21}{256} \\
        \omega(\varepsilon) &= 1 + \frac{3 \varepsilon}{8} - \frac{21 \varepsilon^{2}}{256} + O(\varepsilon^{3})
        \end{align*}
        """
        problem = self.problem
        lines = [r"& " + _equation_latex(problem) + r",\quad " + _initial_latex(problem)]
        assumptions = self._assumptions_latex()
        if assumptions:
            lines.append(r"& " + assumptions)
        for exponent, value in zip(self.exponents, self.omega):  # ω_{k/2} multiplies ε^{k/2} in the gauge sqrt(ε)
            lines.append(rf"\omega_{{{exponent}}} &= {_latex(value)}")
        remainder = rf" + O(\varepsilon^{{{_latex(sympy.Rational(self._steps * self.order + 1, self._steps))}}})"
        names = [rf"\omega_{{{exponent}}}" for exponent in self.exponents]
        lines.append(r"\omega(\varepsilon) &= " + _series_latex(self.omega, self.gauge, names) + remainder)
        if problem.has_initial_velocity:
            lines.append(r"u(t) &= v(\omega t + \varphi(\varepsilon); \varepsilon),\quad v(0; \varepsilon) = A(\varepsilon)")
            lines.append(r"A(\varepsilon) &= " + _series_latex(self.amplitude, self.gauge) + remainder)
            lines.append(r"\varphi(\varepsilon) &= " + _series_latex(self.phase, self.gauge) + remainder)
        if waveforms:
            for waveform in self.waveforms:
                lines.append(rf"v_{{{waveform.order}}}(s) &= {waveform.to_latex()}")
        header = f"% lindstedt: {problem.describe()}\n"
        body = header + "\\begin{align*}\n" + " \\\\\n".join(lines) + "\n\\end{align*}\n"
        if waveforms and self.stretched_arcs:  # the arcs' own expansion, in stretched time
            body += "\n".join(arc.to_latex() for arc in self.stretched_arcs) + "\n"
        return body

    def _assumptions_latex(self) -> str:
        r"""``\text{assuming } …`` : the derivation's assumptions on free symbols and, for piecewise f, the regime."""
        symbols = {symbol.name: symbol for symbol in self.problem.free_symbols}
        parts = [_assumption_latex(assumption.text, symbols) for assumption in self._assumptions.assumptions]
        text = r"\text{assuming } " + r",\ ".join(parts) if parts else ""
        if self.is_piecewise:
            regime = rf"\text{{regime: {latex_text(self.regime)}, valid for }} t = O(\varepsilon^{{{_latex(self.validity_exponent)}}})"
            text = text + r";\quad " + regime if text else regime
        return text

    # -- display -----------------------------------------------------------------------------
    def _repr_latex_(self) -> str:
        """Jupyter's rendering: :meth:`to_latex` (without waveforms) as display math."""
        return jupyter_latex(self.to_latex())

    def __repr__(self) -> str:
        """The problem, the order and ω_k (each cut to a few hundred characters; ``.omega[k]`` is the full one)."""
        fields = [("problem", repr(self.problem.describe())), ("order", str(self.order))]
        try:
            if self._steps != 1:
                fields.append(("gauge", str(self.gauge)))
            omega = ", ".join(shorten(sympy.sstr(value), 160, f".omega[{k}]") for k, value in enumerate(self.omega))
            fields.append(("omega", f"({omega})"))
            if self.is_piecewise:
                fields.append(("regime", repr(self.regime)))
        except Exception as error:  # a repr never raises: show why the coefficients are missing
            fields.append(("omega", f"<not available: {type(error).__name__}: {shorten(str(error), 120)}>"))
        return labelled_repr("Expansion", fields, field_limit=1200)

    def to_dict(self, *, waveforms: bool = True) -> dict[str, Any]:
        """The documented JSON-ready dictionary (schema ``lindstedt.expansion/1``)."""
        problem = self.problem
        data: dict[str, Any] = {
            "schema": SCHEMA,
            "problem": {
                "equation": "u'' + omega0**2*u + epsilon*f(u) = 0, u(0) = a0 + epsilon*a1, u'(0) = 0",
                "f": sympy.sstr(problem.f),
                "a0": sympy.sstr(problem.a0),
                "a1": sympy.sstr(problem.a1),
                "omega0": sympy.sstr(problem.omega0),
                "parameters": {str(symbol): sympy.sstr(value) for symbol, value in problem.params},
                "normalization": problem.normalization,
            },
            "order": self.order,
            "normalization": problem.normalization,
            "gauge": sympy.sstr(self.gauge),
            "exponents": [str(value) for value in self.exponents],
            "omega": [sympy.sstr(value) for value in self.omega],
            "omega_float": [_as_float(value) for value in self.omega],
            "alpha": [sympy.sstr(value) for value in self.alpha],
            "alpha_float": [_as_float(value) for value in self.alpha],
            "omega_next": sympy.sstr(self.omega_next),
        }
        if problem.has_initial_velocity:
            data["problem"]["equation"] = "u'' + omega0**2*u + epsilon*f(u) = 0, u(0) = u0, u'(0) = v0"
            data["problem"]["u0"] = sympy.sstr(problem.u0)
            data["problem"]["v0"] = sympy.sstr(problem.v0)
            data["solution"] = "u(t) = v(omega*t + phase; epsilon), v(0; epsilon) = amplitude (positive turning point)"
            data["amplitude"] = [sympy.sstr(value) for value in self.amplitude]
            data["amplitude_float"] = [_as_float(value) for value in self.amplitude]
            data["phase"] = [sympy.sstr(value) for value in self.phase]
            data["phase_float"] = [_as_float(value) for value in self.phase]
        if waveforms:
            data["waveforms"] = [
                w.to_dict()
                if isinstance(w, PiecewiseWaveform)
                else {"order": w.order, "cosine_coefficients": {str(n): sympy.sstr(c) for n, c in w.coefficients}}
                for w in self.waveforms
            ]
        if self.is_piecewise:
            data["regime"] = self.regime
            data["validity_exponent"] = str(self.validity_exponent)
            data["contact_angles"] = [sympy.sstr(value) for value in self.contact_angles]
        if waveforms and self.stretched_arcs:
            data["stretched_arcs"] = [arc.to_dict() for arc in self.stretched_arcs]
        return data

    def to_json(self, *, waveforms: bool = True, indent: int | None = 2) -> str:
        """JSON text of :meth:`to_dict`."""
        return json.dumps(self.to_dict(waveforms=waveforms), indent=indent, allow_nan=False)

    def summary(self) -> str:
        """Plain-text summary: the problem and ω_0..ω_N."""
        lines = [self.problem.describe()]
        if self._steps != 1:
            lines.append(f"  omega(eps) = sum_k omega_k {self.gauge}**k (grazing: not analytic in eps)")
        for k, value in enumerate(self.omega):
            lines.append(f"  omega_{k} = {value}")
        if self.problem.has_initial_velocity:
            lines.append("  u(t) = v(omega*t + phi(eps); eps), released at the turning point A(eps) = v(0; eps) > 0")
            lines += [f"  A_{k} = {value}" for k, value in enumerate(self.amplitude)]
            lines += [f"  phi_{k} = {value}" for k, value in enumerate(self.phase)]
        return "\n".join(lines)


def _lambdify(arguments: tuple, expression: sympy.Expr, modules: Any) -> Callable[..., Any]:
    """``sympy.lambdify``; for NumPy with its printer's default settings except the order of terms, which the
    default printer sorts by evaluating every term numerically (8× the time for closed forms in arccos of an
    irrational contact point: 7.8 s → 1.0 s for ``Max(0, u - acos(1/3)/2)`` at order 2, measured)."""
    if modules != "numpy":
        return sympy.lambdify(arguments, expression, modules=modules)
    from sympy.printing.numpy import NumPyPrinter

    printer = NumPyPrinter({"fully_qualified_modules": False, "inline": True, "allow_unknown_functions": True,
                            "user_functions": {}, "order": "none"})
    return sympy.lambdify(arguments, expression, modules=modules, printer=printer)
