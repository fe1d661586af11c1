"""Lindstedt–Poincaré hierarchy for piecewise-linear f, with moving contact boundaries.

Problem: ``u'' + ω0² u + ε f(u) = 0``, ``u(0) = a0``, ``u'(0) = 0``, with f
continuous and piecewise linear (unilateral springs ``a (u − b)_+``).

**Normal form.**  With ``w = u/a0``, ``ω = ω0 Ω``, ``ε̂ = ε/ω0²``:
``Ω² w'' + w + ε̂ f̂(w) = 0`` where ``f̂(w) = λ_j w + μ_j/a0`` on the w-interval
j between breakpoints ``κ_i = u_i/a0``.  At ε = 0, ``w_0 = cos s`` crosses
``κ_i`` (|κ_i| < 1) at the contact angle ``β_i = arccos κ_i``; the ε-dependent
crossing is ``s_i*(ε) = β_i + Σ_k σ_{i,k} ε̂^k``.

**Branches.**  On the piece p of [0, π] between consecutive crossings the
equation is linear, ``Ω² W'' + (1 + ε̂ ℓ_p) W = −ε̂ m_p``, so the solution is an
analytic branch ``W^p(s, ε̂) = Σ_k ε̂^k W_k^p(s)`` (quasi-trigonometric, see
:mod:`lindstedt.algebra.branch`), continued analytically past β_i.  Order k gives

    W_k^p'' + W_k^p = A_k cos s − Σ_{i=1}^{k−1} A_i W_{k−i}^p'' − ℓ_p W_{k−1}^p − m_p [k = 1],

with ``Ω² = Σ A_k ε̂^k``.  The unknowns of order k — the homogeneous parts
``c_p cos s + d_p sin s``, ``A_k`` and the boundary terms ``σ_{i,k}`` — follow
from: evenness ``W'(0) = 0``, ``W'(π) = 0``; at every moving boundary
``W^p(s_i*) = κ_i`` and C¹ matching ``W^p = W^{p+1}``, ``W^p' = W^{p+1}'`` — all
expanded in ε̂ by Taylor series about β_i, so the integrals and values with
moving limits are closed forms; and the normalisation (``W_k(0) = 0``, or zero
first-harmonic coefficient of the exact W including the moving-boundary
terms).  The Fredholm alternative (solvability of ``v'' + v = r`` with
``v'(0) = v'(π) = 0``) is what fixes ``A_k``: it is the secular condition.

The frequency is analytic in ε when no crossing is tangent (|κ_i| ≠ 1): the
validity time is ~ε^{-1}.  A grazing breakpoint (|κ_i| = 1, double root of
w_0 − κ_i) carries no contact at order zero; it is reported with validity
~ε^{-1/2} (seed Prop. 2.3).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import mpmath
import sympy
from sympy import QQ, RealField

from .algebra.branch import Branch, EvaluationPoint
from ._errors import ProblemError
from ._piecewise_linear import decompose_piecewise_linear
from ._problem import DISPLACEMENT, Oscillator
from ._series_algebra import LazyOrders, shift_powers

__all__ = ["ContactBoundary", "PiecewiseNormalForm", "PiecewiseHierarchy", "piecewise_normal_form"]


@dataclass(frozen=True)
class ContactBoundary:
    """A breakpoint crossed by w_0 = cos s at the contact angle β = arccos κ."""

    kappa: sympy.Expr
    contact_angle: sympy.Expr
    point: EvaluationPoint
    kappa_element: Any
    sine_element: Any


@dataclass(frozen=True)
class PiecewiseNormalForm:
    """Normalised piecewise-linear problem on [0, π] (see module docstring)."""

    domain: Any
    epsilon_scale: sympy.Expr
    generator_values: tuple[tuple[sympy.Symbol, sympy.Expr], ...]
    piece_coefficients: tuple[tuple[Any, Any], ...]  # (ℓ_p, m_p) per piece in s
    boundaries: tuple[ContactBoundary, ...]
    grazing: tuple[sympy.Expr, ...]  # breakpoints κ with |κ| = 1
    regime: str  # "contact", "no contact", "grazing"
    validity_exponent: sympy.Rational
    zero_point: EvaluationPoint
    pi_point: EvaluationPoint
    prune_tolerance: float | None = None
    # The assumptions of the derivation (read by Expansion to check numeric ``values``):
    # the sign of a0 it was derived for, and every w-breakpoint κ (increasing) with where it
    # lies relative to the orbit [-1, 1]: "crossing" (|κ| < 1, decided or assumed), "grazing"
    # (|κ| = 1), "above" (κ > 1: never reached) or "below" (κ < -1: permanent contact).
    amplitude_sign: int = 1
    breakpoint_classes: tuple[tuple[sympy.Expr, str], ...] = ()

    def to_expr(self, element: Any) -> sympy.Expr:
        """Domain element -> sympy expression with generators substituted."""
        expression = self.domain.to_sympy(element)
        if self.generator_values:
            expression = expression.xreplace(dict(self.generator_values))
        return expression


class _ConstantField:
    """Chooses the coefficient domain and converts the constants of the problem into it."""

    def __init__(self, values: list[sympy.Expr], digits: int | None):
        self.numeric = digits is not None or any(v.has(sympy.Float) for v in values)
        self.generators: list[tuple[sympy.Symbol, sympy.Expr]] = []
        self._replacement: dict[sympy.Expr, sympy.Symbol] = {}
        if self.numeric:
            self.digits = digits or 30
            self.domain = RealField(dps=self.digits)
            return
        self.digits = None
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
            return self.domain.convert(sympy.N(value, self.digits + 10))
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
    difference = sympy.simplify(value - bound)
    if difference.is_zero:
        return 0
    if difference.is_positive:
        return 1
    if difference.is_negative:
        return -1
    return None


def _contact_sine(kappa: sympy.Expr) -> sympy.Expr:
    """sin β = sqrt(1 − κ²), without sympy's perfect-power search for rationals with huge denominators."""
    if kappa.is_Rational and kappa.q > 10**12:
        return sympy.Pow(1 - kappa**2, sympy.Rational(1, 2), evaluate=False)
    return sympy.sqrt(1 - kappa**2)


def _guard_digits(kappas: list[sympy.Expr], order: int) -> int:
    """Extra working digits for a float hierarchy near grazing.

    Near |κ| = 1 the contact angle margin m = min(β, π − β) is small and the
    order-k corrections are O(m^{2k+1}) differences of O(1) terms, so about
    (2k + 3)·log10(1/m) digits cancel; they are added to the working precision.
    """
    margin = mpmath.mpf(1)
    with mpmath.workdps(50):
        for kappa in kappas:
            if not kappa.is_number:
                continue
            angle = mpmath.acos(mpmath.mpf(sympy.N(kappa, 60)))
            margin = min(margin, angle, mpmath.pi - angle)
        if margin <= 0:
            return 0
        return int(mpmath.ceil((2 * order + 5) * max(0, -mpmath.log10(margin))))


def piecewise_normal_form(problem: Oscillator, digits: int | None = None, order_hint: int = 4) -> PiecewiseNormalForm:
    """Build the normalised piecewise problem.

    ``digits`` selects a numeric ``RealField`` (also chosen automatically when
    the inputs contain floats); otherwise the hierarchy is exact.  In the
    numeric case guard digits are added near grazing (see :func:`_guard_digits`)
    so that ``digits`` stay correct up to order ``order_hint``.
    """
    intervals = decompose_piecewise_linear(problem.nonlinearity, DISPLACEMENT)
    amplitude = problem.a0
    sign = _sign_of_amplitude(amplitude)
    # w-breakpoints κ_i = u_i / a0, and the linear law f̂(w) = λ w + μ/a0 on each interval.
    w_intervals: list[tuple[sympy.Expr | None, sympy.Expr | None, sympy.Expr, sympy.Expr]] = []
    for interval in intervals:
        lower = None if interval.lower is None else interval.lower / amplitude
        upper = None if interval.upper is None else interval.upper / amplitude
        if sign < 0:
            lower, upper = upper, lower
        w_intervals.append((lower, upper, interval.slope, interval.intercept / amplitude))
    if sign < 0:
        w_intervals.reverse()
    # Breakpoints in w, increasing; classify each against the orbit [-1, 1].
    kappas = [upper for (_, upper, _, _) in w_intervals[:-1]]
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
    values: list[sympy.Expr] = []
    for interval_index in interval_of:
        _, _, slope, intercept = w_intervals[interval_index]
        values += [slope, intercept]
    for kappa in crossing_kappas:
        values += [kappa, sympy.acos(kappa), _contact_sine(kappa)]
    numeric = digits is not None or any(value.has(sympy.Float) for value in values)
    if numeric:
        digits = (digits or 30) + _guard_digits(crossing_kappas, order_hint)
    field = _ConstantField(values, digits)
    domain = field.domain
    piece_coefficients = []
    for interval_index in interval_of:
        _, _, slope, intercept = w_intervals[interval_index]
        piece_coefficients.append((field.convert(slope), field.convert(intercept)))
    boundaries = []
    for kappa in sorted(crossing_kappas, key=lambda k: -k if k.is_number else 0):
        angle = sympy.acos(kappa)
        kappa_element = field.convert(kappa)
        sine_element = field.convert(_contact_sine(kappa))
        point = EvaluationPoint(domain, field.convert(angle), kappa_element, sine_element)
        boundaries.append(ContactBoundary(kappa, angle, point, kappa_element, sine_element))
    zero = EvaluationPoint(domain, domain.zero, domain.one, domain.zero)
    pi_point = EvaluationPoint(domain, field.convert(sympy.pi), -domain.one, domain.zero)
    if grazing:
        regime = "grazing"
    elif all(not ell and not m for ell, m in piece_coefficients):
        regime = "no contact"
    else:
        regime = "contact"
    validity = sympy.Rational(-1, 2) if grazing else sympy.Integer(-1)
    return PiecewiseNormalForm(
        domain=domain,
        epsilon_scale=1 / problem.omega0**2,
        generator_values=tuple(field.generators),
        piece_coefficients=tuple(piece_coefficients),
        boundaries=tuple(boundaries),
        grazing=tuple(grazing),
        regime=regime,
        validity_exponent=validity,
        zero_point=zero,
        pi_point=pi_point,
        prune_tolerance=None if not field.numeric else 0.0,
        amplitude_sign=sign,
        breakpoint_classes=tuple(classes),
    )


class _Affine:
    """base + a·A_k + c·c_1: a value of order k that is affine in the two global unknowns."""

    __slots__ = ("base", "a", "c")

    def __init__(self, base: Any, a: Any, c: Any):
        self.base, self.a, self.c = base, a, c

    def __add__(self, other: "_Affine") -> "_Affine":
        return _Affine(self.base + other.base, self.a + other.a, self.c + other.c)

    def __sub__(self, other: "_Affine") -> "_Affine":
        return _Affine(self.base - other.base, self.a - other.a, self.c - other.c)

    def scale(self, factor: Any) -> "_Affine":
        return _Affine(self.base * factor, self.a * factor, self.c * factor)

    def shift(self, constant: Any) -> "_Affine":
        return _Affine(self.base + constant, self.a, self.c)

    def value(self, a_value: Any, c_value: Any) -> Any:
        return self.base + self.a * a_value + self.c * c_value


class PiecewiseHierarchy(LazyOrders):
    """Order-by-order solution of the piecewise problem (same interface as the smooth hierarchy).

    Examples
    --------
    >>> from lindstedt._problem import Oscillator
    >>> hierarchy = PiecewiseHierarchy(piecewise_normal_form(Oscillator("Max(0, u)", a0=1, omega0=1)), "initial")
    >>> hierarchy.form.to_expr(hierarchy.squared_frequency(2))
    -3/16
    """

    def __init__(self, form: PiecewiseNormalForm, normalization: str):
        self.form = form
        self.normalization = normalization
        domain = form.domain
        self._domain = domain
        pieces = len(form.piece_coefficients)
        self._branches: list[list[Branch]] = [[Branch.cosine(domain) for _ in range(pieces)]]
        self._squared: list[Any] = [domain.one]
        self._frequencies: list[Any] = [domain.one]
        self._boundary_terms: list[list[Any]] = [[b.point.value for b in form.boundaries]]
        self._derivative_cache: dict[tuple[int, int, int], Branch] = {}
        self._resonant = Branch(domain, {(1, 1, 1): domain.convert(QQ(1, 2))})  # s sin s / 2 solves v''+v = cos s
        self.counters = {"orders": 0}

    # -- helpers -----------------------------------------------------------------------------
    def _derivative(self, order: int, piece: int, times: int) -> Branch:
        key = (order, piece, times)
        if key not in self._derivative_cache:
            if times == 0:
                self._derivative_cache[key] = self._branches[order][piece]
            else:
                self._derivative_cache[key] = self._derivative(order, piece, times - 1).derivative()
        return self._derivative_cache[key]

    def _shift_powers(self, boundary: int, order: int) -> list[list[Any]]:
        """[δσ^n]_j for n, j <= order, δσ = Σ_{1<=i<order} σ_i ε̂^i (σ_order excluded)."""
        return shift_powers([term[boundary] for term in self._boundary_terms[:order]], order, self._domain)

    def _known_at_boundary(self, boundary: int, piece: int, order: int, derivative: int, powers: list[list[Any]]) -> Any:
        """ε̂^order coefficient of ∂^derivative W^piece at s*(ε̂), without W_order and σ_order."""
        point = self.form.boundaries[boundary].point
        factorial = 1
        total = self._domain.zero
        for times in range(1, order + 1):
            factorial *= times
            inverse_factorial = self._domain.convert(QQ(1, factorial))
            for j in range(0, order - times + 1):
                weight = powers[times][order - j]
                if weight:
                    value = self._derivative(j, piece, times + derivative).evaluate(point)
                    total = total + value * weight * inverse_factorial
        return total

    def _boundary_first_harmonic(self, boundary: int, order: int, powers: list[list[Any]]) -> Any:
        """ε̂^order coefficient of ∫_β^{s*} (W^p − W^{p+1}) cos s ds (known part)."""
        point = self.form.boundaries[boundary].point
        total = self._domain.zero
        for j in range(1, order):
            difference = (self._branches[j][boundary] - self._branches[j][boundary + 1]).times_cosine(1)
            derivative = difference
            factorial = 1
            for times in range(0, order - j):
                factorial *= times + 1
                weight = powers[times + 1][order - j]
                if weight:
                    total = total + derivative.evaluate(point) * weight * self._domain.convert(QQ(1, factorial))
                derivative = derivative.derivative()
        return total

    # -- one order -------------------------------------------------------------------------------
    def _solve_order(self, order: int) -> None:
        domain, form = self._domain, self.form
        zero, one = domain.zero, domain.one
        particular: list[Branch] = []
        for piece, (ell, m) in enumerate(form.piece_coefficients):
            rhs = Branch(domain)
            for i in range(1, order):
                rhs = rhs - self._derivative(order - i, piece, 2).scale(self._squared[i])
            rhs = rhs - self._branches[order - 1][piece].scale(ell)
            if order == 1 and m:
                rhs = rhs - Branch.constant(domain, m)
            particular.append(rhs.oscillator_particular_solution())
        resonant = self._resonant
        resonant_derivative = resonant.derivative()
        zero_point = form.zero_point
        # Piece 0 contains s = 0: W'(0) = 0 fixes d_0; c_0 is the free unknown "c".
        c_values = [_Affine(zero, zero, one)]
        d_values = [_Affine(-particular[0].derivative().evaluate(zero_point), -resonant_derivative.evaluate(zero_point), zero)]
        boundary_values: list[_Affine] = []
        for index, boundary in enumerate(form.boundaries):
            point = boundary.point
            cosine, sine = boundary.kappa_element, boundary.sine_element
            powers = self._shift_powers(index, order)
            left, right = index, index + 1

            def value_at(piece: int, c: _Affine, d: _Affine, derivative: bool) -> _Affine:
                branch = particular[piece].derivative() if derivative else particular[piece]
                resonant_branch = resonant_derivative if derivative else resonant
                if derivative:
                    homogeneous = c.scale(-sine) + d.scale(cosine)
                else:
                    homogeneous = c.scale(cosine) + d.scale(sine)
                return homogeneous + _Affine(branch.evaluate(point), resonant_branch.evaluate(point), zero)

            left_value = value_at(left, c_values[left], d_values[left], False)
            left_slope = value_at(left, c_values[left], d_values[left], True)
            known_left = self._known_at_boundary(index, left, order, 0, powers)
            known_right = self._known_at_boundary(index, right, order, 0, powers)
            known_left_slope = self._known_at_boundary(index, left, order, 1, powers)
            known_right_slope = self._known_at_boundary(index, right, order, 1, powers)
            # Contact: W_k^p(β) + W_0'(β) σ_k + known = 0 with W_0'(β) = −sin β.
            boundary_values.append(left_value.shift(known_left).scale(one / sine))
            target_value = left_value.shift(known_left - known_right)
            target_slope = left_slope.shift(known_left_slope - known_right_slope)
            x = target_value - _Affine(particular[right].evaluate(point), resonant.evaluate(point), zero)
            y = target_slope - _Affine(
                particular[right].derivative().evaluate(point), resonant_derivative.evaluate(point), zero
            )
            c_values.append(x.scale(cosine) - y.scale(sine))
            d_values.append(x.scale(sine) + y.scale(cosine))
        last = len(particular) - 1
        pi_point = form.pi_point
        # W'(π) = P'(π) + A_k Q'(π) − d_last = 0.
        end_condition = _Affine(particular[last].derivative().evaluate(pi_point), resonant_derivative.evaluate(pi_point), zero) - d_values[last]
        if self.normalization == "initial":
            normalization = _Affine(particular[0].evaluate(zero_point), resonant.evaluate(zero_point), zero) + c_values[0]
        else:
            normalization = self._first_harmonic_condition(order, particular, c_values, d_values)
        # Solve the 2x2 system end_condition = 0, normalization = 0 for (A_k, c).
        determinant = end_condition.a * normalization.c - end_condition.c * normalization.a
        if not determinant:
            raise ProblemError("the order-%d matching system is singular (a tangent contact?)" % order)
        a_value = (-end_condition.base * normalization.c + end_condition.c * normalization.base) / determinant
        c_value = (-end_condition.a * normalization.base + normalization.a * end_condition.base) / determinant
        branches = []
        for piece in range(len(particular)):
            homogeneous = Branch(
                domain,
                {(1, 0, 0): c_values[piece].value(a_value, c_value), (1, 1, 0): d_values[piece].value(a_value, c_value)},
            )
            branches.append(particular[piece] + resonant.scale(a_value) + homogeneous)
        self._branches.append(branches)
        self._squared.append(a_value)
        self._boundary_terms.append([value.value(a_value, c_value) for value in boundary_values])
        self.counters["orders"] += 1

    def _first_harmonic_condition(self, order: int, particular: list[Branch], c_values: list[_Affine], d_values: list[_Affine]) -> _Affine:
        """ε̂^order coefficient of ∫_0^π W cos s ds (must vanish), affine in (A_k, c)."""
        form = self.form
        domain = self._domain
        limits = [form.zero_point] + [b.point for b in form.boundaries] + [form.pi_point]
        cos_cos = Branch.cosine(domain).times_cosine(1)
        sin_cos = Branch.sine(domain).times_cosine(1)
        resonant_cos = self._resonant.times_cosine(1)
        total = _Affine(domain.zero, domain.zero, domain.zero)
        for piece, branch in enumerate(particular):
            lower, upper = limits[piece], limits[piece + 1]
            total = total + _Affine(
                branch.times_cosine(1).integral(lower, upper), resonant_cos.integral(lower, upper), domain.zero
            )
            total = total + c_values[piece].scale(cos_cos.integral(lower, upper))
            total = total + d_values[piece].scale(sin_cos.integral(lower, upper))
        for index in range(len(form.boundaries)):
            total = total.shift(self._boundary_first_harmonic(index, order, self._shift_powers(index, order)))
        return total

    # -- public interface (mirrors SmoothHierarchy; squared_frequency/frequency from LazyOrders) ----
    def branches(self, order: int) -> list[Branch]:
        """W_order on each piece (analytic branches)."""
        self._ensure(order)
        return self._branches[order]

    def boundary_shift(self, order: int) -> list[Any]:
        """σ_{i,order} for every boundary (order 0: the contact angles β_i)."""
        self._ensure(order)
        return self._boundary_terms[order]
