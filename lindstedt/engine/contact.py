"""The 1-dof contact normal form: u'' + ω0² u + ε f(u) = 0 with f piecewise polynomial.

Problem: ``u(0) = a0``, ``u'(0) = 0`` (or a0 the first-harmonic amplitude),
f a sum of unilateral springs ``a (u − b)_+``, contact laws such as ``(u − b)_+²``
or ``u|u|``, jumps and polynomial terms: one polynomial ``Σ_m c_m u^m`` between
consecutive breakpoints.  With ``w = u/a0``, ``ω = ω0 Ω``, ``ε̂ = ε/ω0²``:

    Ω² w'' + w + ε̂ f̂_p(w) = 0,   f̂_p(w) = f_p(a0 w)/a0 = Σ_m c_m a0^{m−1} w^m on each w-interval,

whose breakpoints ``κ_i = u_i/a0`` are crossed by ``w_0 = cos s`` at the
contact angles ``β_i = arccos κ_i`` when |κ_i| < 1.  This module classifies
the breakpoints against the orbit [−1, 1] (crossing, grazing, never reached,
permanent contact), chooses the coefficient field — exact: the
:class:`~lindstedt.algebra.contact_field.ContactField` of π, β_i and
σ_i = sin β_i with σ_i² + κ_i² = 1 (rational or symbolic gaps), else the general
``QQ(π, κ, β, sin β, …)`` with independent generators; or a ``RealField`` with
guard digits near grazing — and hands the
:class:`~lindstedt.engine.branch_system.BranchSystem` with N = 1 component to the
one branch hierarchy (:mod:`lindstedt.engine.branches`), which solves it order
by order.

The frequency is analytic in ε when no crossing is tangent (|κ_i| ≠ 1): the
validity time is ~ε^{-1}.  A grazing breakpoint (|κ_i| = 1, double root of
w_0 − κ_i) carries no contact at order zero; it is reported with validity
~ε^{-1/2} (seed Prop. 2.3).
"""

from __future__ import annotations

import functools
import operator
from dataclasses import dataclass
from fractions import Fraction
from typing import Any, Sequence

import mpmath
import sympy
from mpmath.libmp import fzero, from_int, from_rational, mpf_acos, mpf_add, mpf_div, mpf_mul, mpf_pi, mpf_pos, mpf_sqrt, \
    round_nearest
from sympy import QQ, RealField
from sympy.polys.polyerrors import CoercionFailed

from .._errors import LindstedtError, ProblemError, UnsupportedNonlinearityError
from ..problems.piecewise_linear import PolynomialInterval, decompose_piecewise
from ..problems.oscillator import DISPLACEMENT, Oscillator
from ..algebra.branch import EvaluationPoint
from ..algebra.contact_field import ContactField
from .branch_system import BranchSystem, ContactState, MovingBoundary
from .branches import BranchHierarchy
from .stretched import VectorArc
from .._precision import LOCK, locked, workdps

__all__ = ["ContactBoundary", "PiecewiseNormalForm", "contact_normal_form", "real_field"]

_ARC_VARIABLE = sympy.Symbol("y", real=True)  # the normalised displacement in an arc's analytic law


def _powers_on_the_displacement(domain: Any, law: Sequence[Any]) -> tuple:
    """The powers m ≥ 2 of a piece's polynomial law as the one element of the branch system, acting on W itself."""
    powers = tuple((power, value) for power, value in enumerate(law) if power >= 2 and value)
    return (((domain.one,), (domain.one,), powers),) if powers else ()


@dataclass(frozen=True)
class ContactBoundary:
    """A breakpoint crossed by w_0 = cos s at the contact angle β = arccos κ (``angle``; None: acos κ, built when
    :attr:`contact_angle` is first read — a float hierarchy never needs the expression)."""

    kappa: sympy.Expr
    angle: sympy.Expr | None
    point: EvaluationPoint
    kappa_element: Any
    sine_element: Any

    @property
    def contact_angle(self) -> sympy.Expr:
        """β = arccos κ as a sympy expression."""
        if self.angle is None:
            object.__setattr__(self, "angle", _contact_angle(self.kappa))
        return self.angle


@dataclass(frozen=True)
class PiecewiseNormalForm:
    """Normalised piecewise-linear problem on [0, π] (see module docstring)."""

    domain: Any
    epsilon_scale: sympy.Expr
    generator_values: tuple[tuple[sympy.Symbol, sympy.Expr], ...]
    piece_laws: tuple[tuple[Any, ...], ...]  # per piece in s: f̂(w) = Σ_m law[m] w^m
    boundaries: tuple[ContactBoundary, ...]
    grazing: tuple[sympy.Expr, ...]  # breakpoints κ with |κ| = 1
    regime: str  # "contact", "no contact", "grazing"
    validity_exponent: sympy.Rational
    system: BranchSystem  # what the branch hierarchy solves (N = 1)
    prune_tolerance: float | None = None
    # The assumptions of the derivation (read by Expansion to check numeric ``values``):
    # the sign of a0 it was derived for, and every w-breakpoint κ (increasing) with where it
    # lies relative to the orbit [-1, 1]: "crossing" (|κ| < 1, decided or assumed), "grazing"
    # (|κ| = 1), "above" (κ > 1: never reached) or "below" (κ < -1: permanent contact).
    amplitude_sign: int = 1
    breakpoint_classes: tuple[tuple[sympy.Expr, str], ...] = ()
    gauge: int = 1  # 1: series in ε; 2: in ε^{1/2} (the perturbed orbit crosses a grazing breakpoint)

    def to_expr(self, element: Any) -> sympy.Expr:
        """Domain element -> sympy expression with generators substituted."""
        expression = self.domain.to_sympy(element)
        if self.generator_values:
            expression = expression.xreplace(dict(self.generator_values))
        return expression

    def scaled_expr(self, element: Any, power: int, prefactor: sympy.Expr) -> sympy.Expr:
        """``prefactor · (1/ω0²)^(power/gauge) · element`` in the problem's symbols (η^power = (ε/ω0²)^(power/gauge))."""
        scale = self.epsilon_scale
        if scale is not sympy.S.One:  # 1^r is 1
            scale = scale ** sympy.Rational(power, self.gauge)
        if prefactor is sympy.S.One and scale is sympy.S.One and element:  # ω0 = 1: 1 · 1 · x is x (a zero
            return self.to_expr(element)                                   # Float becomes sympy's 0 in the product)
        return prefactor * scale * self.to_expr(element)


class _ConstantField:
    """Chooses the coefficient domain and converts the constants of the problem into it.

    Exact problems use the :class:`~lindstedt.algebra.contact_field.ContactField` of the crossed
    breakpoints ``kappas`` (σ² + κ² = 1 holds there, denominators stay monomials in π and σ)
    whenever it holds every constant (rational or symbolic gaps, rational laws); anything else
    (an irrational gap, the σ_1 of a crossed grazing point, …) the general
    ``QQ.frac_field(π, κ…, g…)`` with one independent generator per transcendental atom.
    """

    def __init__(self, values: list[sympy.Expr], digits: int | None, kappas: tuple[sympy.Expr, ...] = ()):
        self.numeric = digits is not None or any(v.has(sympy.Float) for v in values)
        self.generators: list[tuple[sympy.Symbol, sympy.Expr]] = []
        self._replacement: dict[sympy.Expr, sympy.Symbol] = {}
        self.contact_field: ContactField | None = None
        if self.numeric:
            self.digits = digits or 30
            self.domain = real_field(self.digits)
            return
        self.digits = None
        try:
            field = ContactField.for_constants(kappas, values)
            for value in values:
                field.from_sympy(value)
        except (CoercionFailed, TypeError, ValueError):  # not representable there: the general field is always exact
            pass
        else:
            self.contact_field = self.domain = field
            return
        pi_generator = sympy.Dummy("pi")
        self._replacement[sympy.pi] = pi_generator
        self.generators.append((pi_generator, sympy.pi))
        symbols: set[sympy.Symbol] = set()
        for value in values:
            symbols |= value.free_symbols
        for symbol in sorted(symbols, key=str):
            self.generators.append((symbol, symbol))
        for value in values:
            self._register(value)
        self.domain = QQ.frac_field(*[generator for generator, _ in self.generators])

    def contact_point(self, kappa: sympy.Expr) -> tuple[sympy.Expr | None, Any, Any, Any]:
        """(acos κ, β, κ, sin β): the contact angle's expression (None where it was not needed: a rational κ in a float
        field) and the elements of the crossing κ; such a κ's from mpmath's acos and square root 64 bits beyond the
        field's precision, rounded once (sympy's evaluation of acos κ and sqrt(1 − κ²), ~0.2 ms, gave the same bits
        on every one of 1200 random κ measured)."""
        if not (self.numeric and isinstance(kappa, sympy.Rational)):
            angle = _contact_angle(kappa)
            return angle, self.convert(angle), self.convert(kappa), self.convert(_contact_sine(kappa, self.numeric))
        p, q = int(kappa.p), int(kappa.q)
        working = self.domain.precision + 64
        angle_value = mpf_acos(from_rational(p, q, working, round_nearest), working, round_nearest)
        sine_value = mpf_div(mpf_sqrt(from_int((q - p) * (q + p)), working, round_nearest), from_int(q), working,
                             round_nearest)
        return None, self.domain.from_raw(angle_value), self.convert(kappa), self.domain.from_raw(sine_value)

    def _register(self, value: sympy.Expr) -> None:
        for atom in sympy.preorder_traversal(value):
            if isinstance(atom, (sympy.acos, sympy.Pow, sympy.asin, sympy.atan)) and atom not in self._replacement:
                if isinstance(atom, sympy.Pow) and atom.exp.is_Integer:
                    continue
                generator = sympy.Dummy("g")
                self._replacement[atom] = generator
                self.generators.append((generator, atom))

    def convert(self, value: sympy.Expr) -> Any:
        value = sympy.sympify(value, strict=True)
        if self.numeric:
            if isinstance(value, sympy.Rational):  # p/q correctly rounded, no sympy evaluation
                return self.domain.dtype(int(value.p)) / int(value.q)
            if value is sympy.pi:
                return self.domain.pi
            return self.domain.convert(sympy.N(value, self.digits + 10))
        if self.contact_field is not None:
            return self.contact_field.from_sympy(value)
        if value.is_Rational:
            return self.domain.convert(value)
        ratio = sympy.simplify(value / sympy.pi) if value.is_number and value.has(sympy.pi) else None
        if ratio is not None and ratio.is_Rational:
            return self.domain.convert(ratio) * self.domain.from_sympy(self._replacement[sympy.pi])
        self._register(value)
        replaced = value.xreplace(self._replacement)
        return self.domain.from_sympy(replaced)


def _sign_of_amplitude(amplitude: sympy.Expr) -> int:
    if amplitude.is_positive:
        return 1
    if amplitude.is_negative:
        return -1
    raise ProblemError(
        f"the sign of a0 = {amplitude} decides which side of the gap the release point is on; "
        "declare it: a0=sympy.Symbol('a0', positive=True) (or negative=True), or pass a number"
    )


def _compare(value: sympy.Expr, bound: int) -> int | None:
    """Sign of value - bound when decidable, else None."""
    if isinstance(value, sympy.Rational):  # p/q − bound has the sign of p − bound·q (q > 0)
        difference = int(value.p) - bound * int(value.q)
        return (difference > 0) - (difference < 0)
    difference = value - bound
    if difference.is_Rational:  # decided: no simplification to try
        return (difference.p > 0) - (difference.p < 0)
    difference = sympy.simplify(difference)
    if difference.is_zero:
        return 0
    if difference.is_positive:
        return 1
    if difference.is_negative:
        return -1
    return None


def _contact_sine(kappa: sympy.Expr, numeric: bool = False) -> sympy.Expr:
    """sin β = sqrt(1 − κ²), without sympy's perfect-power search for rationals with huge denominators, nor for
    a float hierarchy (which only evaluates it)."""
    if kappa.is_Rational and (numeric or kappa.q > 10**12):
        return sympy.Pow(1 - kappa**2, sympy.Rational(1, 2), evaluate=False)
    return sympy.sqrt(1 - kappa**2)


def _turning_points(field: "_ConstantField") -> tuple[EvaluationPoint, EvaluationPoint]:
    """The points s = 0 and s = π; a float field's are made once and shared (the cosines, sines and powers they
    remember do not depend on the problem)."""
    domain = field.domain
    points = domain.__dict__.get("_turning_points") if isinstance(domain, _FloatField) else None
    if points is None:
        points = (EvaluationPoint(domain, domain.zero, domain.one, domain.zero),
                  EvaluationPoint(domain, field.convert(sympy.pi), -domain.one, domain.zero))
        if isinstance(domain, _FloatField):
            domain.__dict__["_turning_points"] = points  # a race makes a second pair: harmless
    return points


class _FloatField(RealField):
    """``RealField`` with the fused ``sum_of_products`` of :func:`~lindstedt.algebra.contact_field.sum_of_products`:
    Σ a·b·c added in order on mpmath's raw values, each product and sum rounded to the field's precision as the
    element arithmetic rounds it (the same bits), a factor that is the field's one skipped (multiplying an element
    of the field by 1 rounds nothing).  Measured: ~0.2 µs per product or sum against ~0.5 µs through mpf objects."""

    def __hash__(self) -> int:  # equal to RealField of its precision (RealField.__eq__), so hashed as one
        return hash(("RealField", self._dtype, self.precision))

    def sum_of_products(self, triples: Sequence[tuple[Any, Any, Any]]) -> Any:
        prec, rounding = self._context._prec_rounding
        one = self.one
        total = fzero
        for a, b, c in triples:
            value = a._mpf_
            if b is not one:
                value = mpf_mul(value, b._mpf_, prec, rounding)
                if c is not one:
                    value = mpf_mul(value, c._mpf_, prec, rounding)
            elif c is not one:
                value = mpf_mul(value, c._mpf_, prec, rounding)
            else:
                total = mpf_add(total, value, prec, rounding)
                continue
            # a product is rounded to the field's precision already: 0 + it is itself (mpf_add would normalize it)
            total = value if total is fzero else mpf_add(total, value, prec, rounding)
        return self._context.make_mpf(total)

    def to_sympy(self, element: Any) -> sympy.Float:
        """``Float(element, dps)`` built from the raw value (the same number: an element has the field's precision)."""
        precision = self.__dict__.get("_float_precision")
        if precision is None:
            precision = self.__dict__["_float_precision"] = mpmath.libmp.dps_to_prec(self.dps)
        return sympy.Float._new(mpf_pos(element._mpf_, precision, round_nearest), precision, zero=False)

    def from_raw(self, value: tuple) -> Any:
        """The element nearest to mpmath's raw value ``value`` (any precision)."""
        return self._context.make_mpf(mpf_pos(value, self._context.prec, round_nearest))

    @property
    def pi(self) -> Any:
        """π rounded to the field's precision, made once per field."""
        value = self.__dict__.get("_pi")
        if value is None:
            value = self.__dict__["_pi"] = self.from_raw(mpf_pi(self._context.prec + 64, round_nearest))
        return value


_REAL_FIELDS: dict[int, Any] = {}


def real_field(digits: int) -> Any:
    """``RealField(dps=digits)`` (:class:`_FloatField`), made once per digits (each makes its own mpmath context,
    ~0.5 ms)."""
    field = _REAL_FIELDS.get(digits)
    if field is None:
        with LOCK:
            field = _REAL_FIELDS.get(digits)
            if field is None:
                field = _REAL_FIELDS[digits] = _FloatField(dps=digits)
    return field


_HALF = sympy.Rational(1, 2)


def _contact_angle(kappa: sympy.Expr) -> sympy.Expr:
    """acos κ as sympy evaluates it; a rational 0 < κ < 1 other than 1/2 has no special value nor a sign to
    extract, so its ``acos`` is built unevaluated (the same object, without the ~35 µs of the evaluation's checks)."""
    if kappa.is_Rational and 0 < kappa < 1 and kappa != _HALF:
        return sympy.acos(kappa, evaluate=False)
    return sympy.acos(kappa)


def _guard_digits(kappas: list[sympy.Expr], order: int) -> int:
    """Extra working digits for a float hierarchy near grazing.

    Near |κ| = 1 the contact angle margin m = min(β, π − β) is small and the
    order-k corrections are O(m^{2k+1}) differences of O(1) terms, so about
    (2k + 3)·log10(1/m) digits cancel; they are added to the working precision.
    """
    # |κ| ≤ 1/2 keeps the margin above π/3 > 1, which adds nothing: decided without evaluating acos κ
    kappas = [kappa for kappa in kappas if kappa.is_number and not (kappa.is_Rational and 2 * abs(int(kappa.p)) <= kappa.q)]
    if not kappas:
        return 0
    margin = mpmath.mpf(1)
    with workdps(50):
        for kappa in kappas:
            angle = mpmath.acos(mpmath.mpf(kappa.p) / kappa.q if kappa.is_Rational else mpmath.mpf(sympy.N(kappa, 60)))
            margin = min(margin, angle, mpmath.pi - angle)
        if margin <= 0:
            return 0
        return int(mpmath.ceil((2 * order + 5) * max(0, -mpmath.log10(margin))))


#: f with its parameters symbolic → its polynomial intervals (None: not decomposable so, or not polynomial on every
#: piece); read by :func:`_intervals` for every numeric value of the parameters
_SYMBOLIC_INTERVALS: dict[sympy.Expr, list[PolynomialInterval] | None] = {}


def _intervals(problem: Oscillator) -> list[PolynomialInterval]:
    """``decompose_piecewise(problem.nonlinearity)``: for rational parameter values, the decomposition of f with its
    parameters symbolic (made once per f) with the values put in, when that decomposition exists and every piece is
    polynomial — the breakpoints it orders and the signs it decides hold for every real value, so it is the same
    (trailing zero coefficients above degree 1 dropped, as the direct decomposition has none)."""
    values = {symbol: value for symbol, value in problem.params if value != symbol}
    if values and all(isinstance(value, sympy.Rational) for value in values.values()):
        if problem.f not in _SYMBOLIC_INTERVALS:
            try:
                symbolic = decompose_piecewise(problem.f, DISPLACEMENT)
            except LindstedtError:  # e.g. two symbolic gaps that only numbers order
                symbolic = None
            if symbolic is not None and any(interval.fractional or interval.analytic != 0 for interval in symbolic):
                symbolic = None
            if len(_SYMBOLIC_INTERVALS) >= 64:
                _SYMBOLIC_INTERVALS.clear()
            _SYMBOLIC_INTERVALS[problem.f] = symbolic
        symbolic = _SYMBOLIC_INTERVALS[problem.f]
        intervals = []
        def put(value: sympy.Expr) -> sympy.Expr:
            """value.xreplace(values): read directly for a number or a symbol, and for a sum or product of such
            (the Rational that Add or Mul of numbers evaluates to, from Rational arithmetic)."""
            if value.is_Rational:
                return value
            if value.is_Symbol:
                return values.get(value, value)
            if value.is_Mul or value.is_Add:
                parts = [part if part.is_Rational else values.get(part) for part in value.args]
                if all(isinstance(part, sympy.Rational) for part in parts):
                    return functools.reduce(operator.mul if value.is_Mul else operator.add, parts)
            return value.xreplace(values)

        for interval in symbolic or ():
            lower, upper = (None if end is None else put(end) for end in (interval.lower, interval.upper))
            coefficients = [put(coefficient) for coefficient in interval.coefficients]
            while len(coefficients) > 2 and coefficients[-1] == 0:
                coefficients.pop()
            if not all(isinstance(value, sympy.Rational) for value in [lower, upper, *coefficients] if value is not None):
                break
            intervals.append(PolynomialInterval(lower, upper, tuple(coefficients)))
        else:
            if symbolic:
                return intervals
    return decompose_piecewise(problem.nonlinearity, DISPLACEMENT)


@locked
def contact_normal_form(problem: Oscillator, digits: int | None = None, order_hint: int = 4) -> PiecewiseNormalForm:
    """Build the normalised piecewise problem.

    ``digits`` selects a numeric ``RealField`` (also chosen automatically when
    the inputs contain floats); otherwise the hierarchy is exact.  In the
    numeric case guard digits are added near grazing (see :func:`_guard_digits`)
    so that ``digits`` stay correct up to order ``order_hint``.
    """
    intervals = _intervals(problem)
    amplitude = problem.a0
    sign = _sign_of_amplitude(amplitude)
    # w-breakpoints κ_i = u_i / a0, and the law f̂(w) = f(a0 w)/a0 = Σ_m c_m a0^{m−1} w^m on each interval.
    # A fractional term c |u − b|^p becomes c |a0|^p |w − κ|^p / a0, κ = b/a0.
    w_intervals: list[tuple[sympy.Expr | None, sympy.Expr | None, tuple[sympy.Expr, ...], tuple]] = []
    unit = amplitude is sympy.S.One  # a0 = 1: w = u (every product and quotient by a0 below would return its operand)
    for interval in intervals:
        lower, upper = interval.lower, interval.upper
        if unit:
            law, fractional = tuple(interval.coefficients), tuple(interval.fractional)
        else:
            lower = None if lower is None else lower / amplitude
            upper = None if upper is None else upper / amplitude
            law = tuple(coefficient * amplitude ** (power - 1) for power, coefficient in enumerate(interval.coefficients))
            fractional = tuple(
                (coefficient * abs(amplitude) ** exponent / amplitude, point / amplitude, exponent)
                for coefficient, point, exponent in interval.fractional
            )
        if sign < 0:
            lower, upper = upper, lower
        analytic = interval.analytic
        if analytic != 0:
            analytic = analytic.subs(DISPLACEMENT, amplitude * _ARC_VARIABLE) / amplitude  # g(w) = g_u(a0 w)/a0
        w_intervals.append((lower, upper, law, fractional, analytic))
    if sign < 0:
        w_intervals.reverse()
    # Breakpoints in w, increasing; classify each against the orbit [-1, 1].
    kappas = [upper for (_, upper, _, _, _) in w_intervals[:-1]]
    crossing: list[int] = []
    grazing: list[sympy.Expr] = []
    classes: list[tuple[sympy.Expr, str]] = []
    for index, kappa in enumerate(kappas):
        below, above = _compare(kappa, -1), _compare(kappa, 1)
        if below is None or above is None:
            if len(kappas) > 1:
                raise ProblemError(
                    f"cannot decide whether the breakpoint kappa = {kappa} lies inside (-1, 1); give numeric gaps"
                )
            crossing.append(index)  # a single symbolic gap: the contact case |kappa| < 1 is assumed
            classes.append((kappa, "crossing"))
            continue
        if below == 0 or above == 0:
            grazing.append(kappa)
            classes.append((kappa, "grazing"))
        elif below > 0 and above < 0:
            crossing.append(index)
            classes.append((kappa, "crossing"))
        else:
            classes.append((kappa, "above" if above > 0 else "below"))
    # Pieces in s: w_0 = cos s decreases from 1 to -1, so the crossings are met from the largest κ down.
    crossing_kappas = [kappas[i] for i in crossing]
    interval_of = []  # interval index (in w order) for each piece in s
    # the interval containing w slightly below 1:
    top_interval = len(w_intervals) - 1
    for index, kappa in enumerate(kappas):
        if _compare(kappa, 1) in (0, 1):
            top_interval = index
            break
    current = top_interval
    interval_of.append(current)
    for index in reversed(crossing):
        current = index  # crossing κ_index moves from interval index+1 down to index
        interval_of.append(current)
    form = _assemble(problem, w_intervals, interval_of, crossing_kappas, (), grazing, classes, sign, digits, order_hint)
    crossed = []
    first_order = BranchHierarchy(form.system, problem.normalization).branches(1) if grazing else None
    for kappa in grazing:
        # The orbit's turning point w0 = κ = ±1 touches the breakpoint: does the order-one orbit pass it?
        # The gap W − κ near β has the double root of W_0 plus ε̂ W_1(β): with η = ε̂^{1/2} and s* = β + σ_1 η + …,
        # W_1(β) + W_0''(β) σ_1²/2 = 0, W_0''(β) = −κ, so σ_1² = 2 W_1(β)/κ: a real crossing iff σ_1² > 0.
        top = kappa > 0
        piece = 0 if top else len(form.system.states) - 1
        point = form.system.zero_point if top else form.system.pi_point
        squared = 2 * form.to_expr(first_order[piece][0].evaluate(point)) / kappa
        if squared.is_positive:
            interval = kappas.index(kappa) + (1 if top else 0)
            crossed.append((kappa, interval, (1 if top else -1) * sympy.sqrt(squared)))
        elif squared.is_positive is None and not squared.is_zero and not squared.is_negative:
            raise ProblemError(
                f"grazing at kappa = {kappa}: cannot decide whether the perturbed orbit crosses the breakpoint "
                f"(sigma_1^2 = {squared}); give numeric values for the parameters"
            )
    if crossed:
        form = _assemble(problem, w_intervals, interval_of, crossing_kappas, tuple(crossed), grazing, classes, sign, digits, order_hint)
    return form


def _stretched_arcs(problem: Oscillator, w_intervals: list, interval_of: list[int], fractional_pieces: list[int],
                    crossing_kappas: list[sympy.Expr], grazing: list, field: "_ConstantField") -> tuple:
    """(first, last): the pieces with a fractional power law c |w − κ|^p (or an analytic law) as stretched arcs — the
    one arc implementation, :class:`~lindstedt.engine.stretched.VectorArc`, with one component (coupling and force
    direction (1,), the rest of the law one analytic expression of W) — or None.

    The first piece holds the release point w = 1, the last one the far turning point; there the arc is
    read backwards, Y = −W, whose law is −f̂(−Y) = −Σ c_m (−Y)^m − c (Y + κ)^p (contact point −κ).
    """
    supported = (
        "a fractional power law (Hertz c*Max(0, u - b)**(3/2)) or a non-polynomial analytic law is supported on a "
        "contact arc that holds a turning point of the orbit (u = a0 or the far side), with the other pieces "
        "polynomial; give numeric values"
    )
    last = len(interval_of) - 1
    if grazing or not crossing_kappas or any(piece not in (0, last) for piece in fractional_pieces):
        raise UnsupportedNonlinearityError(f"f = {problem.f}: {supported}")
    if fractional_pieces == [0, last] and len(crossing_kappas) < 2:
        raise UnsupportedNonlinearityError(f"f = {problem.f}: fractional laws on both sides of one breakpoint; {supported}")
    if problem.normalization != "initial":
        raise UnsupportedNonlinearityError(f"f = {problem.f}: a fractional power law needs normalization='initial' (a0 is the release point)")
    if not field.numeric:
        raise ProblemError(f"f = {problem.f}: a non-polynomial contact law is expanded numerically; pass numeric=True (and precision=...)")
    digits = field.digits + 10
    ordered = sorted(crossing_kappas, key=lambda k: -k if k.is_number else 0)

    def number(value: sympy.Expr) -> mpmath.mpf:
        if not value.is_number:
            raise UnsupportedNonlinearityError(f"f = {problem.f}: {supported} (got the symbolic {value})")
        with workdps(digits):
            return mpmath.mpf(sympy.N(value, digits))

    arcs = []
    for which, piece in enumerate((0, last)):
        _, _, polynomial, fractional, analytic = w_intervals[interval_of[piece]]
        if piece not in fractional_pieces:
            arcs.append(None)
            continue
        kappa = ordered[0] if which == 0 else ordered[-1]
        if len(fractional) > 1 or (fractional and sympy.simplify(fractional[0][1] - kappa) != 0):
            raise UnsupportedNonlinearityError(f"f = {problem.f}: {supported}")
        coefficient, exponent = (fractional[0][0], fractional[0][2]) if fractional else (sympy.S.Zero, None)
        # the rest of the law, polynomial part included, is one analytic expression g(y) for the arc
        law = analytic + sum((value * _ARC_VARIABLE**power for power, value in enumerate(polynomial)), sympy.S.Zero)
        if which == 1:  # Y = −W: the law −f̂(−Y), contact point −κ
            coefficient, kappa = -coefficient, -kappa
            law = -law.subs(_ARC_VARIABLE, -_ARC_VARIABLE)
        if law.free_symbols - {_ARC_VARIABLE}:
            raise UnsupportedNonlinearityError(f"f = {problem.f}: {supported} (got the symbols {law.free_symbols - {_ARC_VARIABLE}})")
        if analytic != 0:
            _check_analytic_on_arc(law, kappa, problem)
        power = None if exponent is None else Fraction(int(exponent.p), int(exponent.q))
        rest = () if law == 0 else (((1,), (1,), (sympy.expand(law), _ARC_VARIABLE)),)  # g(y) acting on y = W
        arcs.append(VectorArc((1,), 0, (1,), (1,), number(kappa), power, number(coefficient), ((0,), (), ()),
                              field.digits, rest))
    return tuple(arcs)


def _check_analytic_on_arc(law: sympy.Expr, kappa: sympy.Expr, problem: Oscillator) -> None:
    """The analytic part of an arc's law must be continuous on the arc's range [κ, 1] of Y (closed)."""
    arc = sympy.Interval(kappa, 1)
    try:
        domain = sympy.calculus.util.continuous_domain(law, _ARC_VARIABLE, arc)
    except (NotImplementedError, TypeError, ValueError):  # undecided: the arc's own finiteness check decides
        return
    if domain != arc:
        raise UnsupportedNonlinearityError(
            f"f = {problem.f}: its law {law} (in w = u/a0 on the contact arc) is not analytic on the whole arc "
            f"[{kappa}, 1]; a non-polynomial piece must be analytic up to its breakpoint"
        )


def _assemble(
    problem: Oscillator,
    w_intervals: list,
    interval_of: list[int],
    crossing_kappas: list[sympy.Expr],
    crossed: tuple,
    grazing: list[sympy.Expr],
    classes: list,
    sign: int,
    digits: int | None,
    order_hint: int,
) -> PiecewiseNormalForm:
    """The normal form with its coefficient field; ``crossed`` lists the grazing breakpoints
    (κ, interval beyond, σ_1) that the perturbed orbit passes (gauge η = ε̂^{1/2})."""
    # pieces whose law is not polynomial: a fractional power of the distance to a breakpoint, or an analytic part
    fractional_pieces = [piece for piece, interval_index in enumerate(interval_of)
                         if w_intervals[interval_index][3] or w_intervals[interval_index][4] != 0]
    if fractional_pieces and crossed:
        raise UnsupportedNonlinearityError(f"f = {problem.f}: a fractional power law at a grazing breakpoint is not supported")
    top = [item for item in crossed if item[0] > 0]
    bottom = [item for item in crossed if item[0] < 0]
    interval_of = [item[1] for item in top] + list(interval_of) + [item[1] for item in bottom]
    laws = [value for interval_index in interval_of for value in w_intervals[interval_index][2]]
    # u(0) = a0 (1 + Σ ε̂^n W_n(0)), ε̂ = ε/ω0²
    releases = [shift * problem.omega0 ** (2 * n) / problem.a0 for n, shift in enumerate(problem.release_shifts, 1)]
    shifts = [item[2] for item in crossed]
    # arccos κ and sin β hold a float exactly when κ does; a float field needs none of them
    numeric = digits is not None or any(value.has(sympy.Float) for value in laws + crossing_kappas + shifts + releases)
    angles = [] if numeric else [value for kappa in crossing_kappas for value in (kappa, _contact_angle(kappa), _contact_sine(kappa))]
    values = laws + angles + shifts + releases
    if numeric:
        # a float field holds numbers only; ω0 alone may stay symbolic (ε̂ = ε/ω0² scales it out)
        unknown = set().union(*(getattr(value, "free_symbols", ()) for value in values)) - problem.omega0.free_symbols
        if unknown:
            names = ", ".join(sorted(str(symbol) for symbol in unknown))
            raise ProblemError(
                f"f = {problem.f} is expanded in floating point (numeric=True, or a float in the data), which needs "
                f"numeric values for {names}; give them (a0=..., params={{...}}) or drop numeric=True and use exact numbers"
            )
        digits = (digits or 30) + _guard_digits(crossing_kappas, order_hint)
        # a nonlinear polynomial law loses about half a digit per order to cancellation in the branch products
        # (measured: (u - 1/3)_+^2 at 30 digits, ω_6 to 9e-27 relative without this): one guard digit per order
        if any(any(value != 0 for value in w_intervals[index][2][2:]) for index in interval_of):
            digits += order_hint
    field = _ConstantField(values, digits, tuple(crossing_kappas))
    domain = field.domain
    piece_laws = [tuple(field.convert(value) for value in w_intervals[interval_index][2]) for interval_index in interval_of]
    arcs = _stretched_arcs(problem, w_intervals, interval_of, fractional_pieces, crossing_kappas, grazing, field) if fractional_pieces else (None, None)
    zero, pi_point = _turning_points(field)
    boundaries, moving = [], []
    for kappa, _, first_shift in top:
        boundaries.append(ContactBoundary(kappa, sympy.Integer(0), zero, domain.one, domain.zero))
        moving.append(MovingBoundary(zero, (domain.one,), domain.zero, field.convert(first_shift)))
    for kappa in sorted(crossing_kappas, key=lambda k: -k if k.is_number else 0):
        angle, angle_element, kappa_element, sine_element = field.contact_point(kappa)
        point = EvaluationPoint(domain, angle_element, kappa_element, sine_element)
        boundaries.append(ContactBoundary(kappa, angle, point, kappa_element, sine_element))
        moving.append(MovingBoundary(point, (domain.one,), sine_element))
    for kappa, _, first_shift in bottom:
        boundaries.append(ContactBoundary(kappa, sympy.pi, pi_point, -domain.one, domain.zero))
        moving.append(MovingBoundary(pi_point, (domain.one,), domain.zero, field.convert(first_shift)))
    gauge = 2 if crossed else 1
    system = BranchSystem(
        domain=domain,
        ratios=(None,),
        mode=0,
        states=tuple(
            ContactState(((law[1],),), (law[0],), _powers_on_the_displacement(domain, law)) for law in piece_laws
        ),
        boundaries=tuple(moving),
        zero_point=zero,
        pi_point=pi_point,
        release=tuple(field.convert(release) for release in releases),
        gauge=gauge,
        arcs=arcs,
    )
    if grazing:
        regime = "grazing"
    elif all(not value for law in piece_laws for value in law) and not any(arcs):  # a stretched (Hertz) arc is contact
        regime = "no contact"
    else:
        regime = "contact"
    # The expansion in η = ε̂^{1/2} past a crossed grazing point holds on t ≲ 1/ε like the analytic one; a
    # grazing breakpoint that the orbit only touches keeps the linear-approximation time scale ε^{-1/2}.
    validity = sympy.Rational(-1, 2) if grazing and not crossed else sympy.Integer(-1)
    return PiecewiseNormalForm(
        domain=domain,
        epsilon_scale=1 / problem.omega0**2,
        generator_values=tuple(field.generators),
        piece_laws=tuple(piece_laws),
        boundaries=tuple(boundaries),
        grazing=tuple(grazing),
        regime=regime,
        validity_exponent=validity,
        system=system,
        prune_tolerance=None if not field.numeric else 0.0,
        amplitude_sign=sign,
        breakpoint_classes=tuple(classes),
        gauge=gauge,
    )
