"""Stable float evaluation of the gap coefficients ω_k(κ): exact series near κ = ±1 and at interior roots.

For f = (u − κ)_+ with one free symbol, ω_k(κ) is a closed form in κ, acos κ and
sqrt(1 − κ²) whose terms cancel in float64 as κ → ±1 (ω_2 ∝ (1 − κ)^{5/2}).  This
module replaces it by series in β = arccos κ, π − β and β − π/2, computed exactly
from the closed form, plus Taylor windows at interior roots; the reasoning and the
measured switch points are in the comment block below.  Used by
:mod:`lindstedt.export.codegen` (``GeneratedCode.accuracy`` states the result).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import mpmath
import numpy as np
import sympy
from gmpy2 import mpq as Fraction  # exact rationals, several times faster than fractions.Fraction

from .._precision import LOCK, locked, workdps, workprec

__all__ = ["SERIES_TARGET", "BoundedFamily", "Patch", "StableCoefficient", "compile_family", "stable_coefficient"]

# Stable evaluation of ω_k(κ) for a gap: piecewise series near κ = ±1 (and at interior roots)
# =====================================================================================================
#
# For f = (u − κ)_+ with one free symbol, ω_k(κ) is P(κ, acos κ, sqrt(1 − κ²), π) / (c π^i (1 − κ²)^(j/2)).
# In float64 that closed form cancels: ω_2 ∝ (1 − κ)^(5/2), ω_4 ∝ (1 − κ)^(9/2) near κ = 1 while its terms
# stay O(1).  Measured (Horner form of the simplified closed form, float64, against 250-digit values):
# ω_2 loses 3.4 digits at κ = 0.99, all 16 from 1 − 1e-6; ω_4 loses 2.6 digits already at κ = 0.5,
# 4.9 at 0.8, 10 at 0.99, and 3-6 digits towards κ = −1 (where ω_3, ω_4 have poles).  Since no interior
# stretch of the closed form is safe for every k at the 1e-14 level, the stable code uses no closed form:
# with κ = cos β it covers β ∈ [0, π] by three series, computed EXACTLY from the closed form
# (coefficients in Q[π, 1/π], rounded to doubles only when printed):
#
#   β-patch  κ ≥ cos(1.25) = 0.3153:  series in β = 2 asin(sqrt((1 − κ)/2)) (0.5 − 0.5κ is one rounding,
#            exact for κ ≥ 0.5 by Sterbenz; acos κ itself would be as good, but this form is exact at κ → 1)
#   γ-patch  κ ≤ −cos(1) = −0.5403:   Laurent series in γ = π − β = 2 asin(sqrt((1 + κ)/2)) (ω_3, ω_4 have
#            poles at κ = −1)
#   δ-patch  in between:               series in δ = β − π/2 = −asin κ
#
# Switch points.  The singularities of ω_k(β) are at β = ±π (zeros of sin β; β = 0 is removable), so the
# β- and γ-series converge for |β| < π and the δ-series for |δ| < π/2: at the switch points (β = 1.25,
# γ = 1, δ ∈ [−0.32, 0.57]) the ratios are 0.40, 0.32 and 0.36, so 25-50 terms reach the truncation target
# 1e-17 (the count is chosen per coefficient from the exactly computed tail, and the truncated series is
# checked against the closed form at 120 digits at nine points per patch).  β = 1.25 rather than 1 on the
# κ > 0 side: ω_k decays towards κ = 1, and the δ-series cancels there (measured: ω_4 lost 1.4 digits at
# κ = 0.53 with β = 1).  Each patch is a Horner sum of decreasing terms in an argument known to a few ulps;
# its float64 rounding is measured at generation time (80 doubles per patch, stated in
# GeneratedCode.accuracy): ≤ 7e-15 relative for ω_1…ω_4.
#
# Interior roots (ω_3 at κ = −0.8459, ω_4 at κ = −0.6964): near a simple root r no evaluation in β can be
# accurate relative to ω_k itself, so a window |κ − r| ≤ h (h = 0.1, at most a third of 1 − |r|) gets a
# Taylor series in t = (κ − r_hi) − r_lo (r = r_hi + r_lo in double-double; κ − r_hi is exact by
# Sterbenz), its coefficients from the host patch's full exact series at 60 digits (mpmath.taylor), checked
# against the closed form at 120 digits at ±h and ±h/3.

SERIES_TARGET = 1e-17  # truncation error of every series at its patch edge, relative to |ω_k| there
_SERIES_ORDER = 72  # numerator orders computed exactly (enough for 40 terms after the shift by sin^j)
_BETA_SWITCH = 1.25  # β-patch: 0 ≤ β ≤ 1.25 (κ ≥ 0.315); δ-patch: −(π/2 − 1.25) ≤ δ ≤ π/2 − 1
_GAMMA_SWITCH = 1  # γ-patch: 0 ≤ γ ≤ 1 (κ ≤ −0.540)
_ROOT_WINDOW = 0.1  # half-width of the Taylor window around an interior root (at most a third of its distance to ±1)


@dataclass(frozen=True)
class Patch:
    """One piece of a stabilised coefficient: ``value`` (in the local symbols of ``definitions``) where
    ``lower <= x <= upper`` (``None``: unbounded; the δ-patch is the rest, ``lower``/``upper`` open)."""

    name: str
    lower: float | None
    upper: float | None
    definitions: tuple[tuple[sympy.Symbol, sympy.Expr], ...]
    value: sympy.Expr
    comment: str


@dataclass(frozen=True)
class StableCoefficient:
    patches: tuple[Patch, ...]  # root windows first, then β, γ, and the δ-patch last (the rest)
    error_estimate: float  # estimated float64 relative error (max over the sample points)
    summary: str


def _gap_parts(expression: sympy.Expr, x: sympy.Symbol) -> Any:
    """``expression`` as (numerator monomials, denominator constant, π power, sin power), or None.

    Monomials are ``(i, j, l, m, c)`` for c κ^i sqrt(1 − κ²)^j (acos κ)^l π^m; the denominator must be
    c π^m (1 − κ²)^(j/2).
    """
    cosine, sine, angle, pi = sympy.symbols("_C _S _A _P")
    one_minus = 1 - x**2

    def replace(node: sympy.Expr) -> sympy.Expr:
        if node == x:
            return cosine
        if node is sympy.pi:
            return pi
        if isinstance(node, sympy.acos):
            return angle if node.args[0] == x else node
        if isinstance(node, sympy.Pow) and node.base == one_minus and (2 * node.exp).is_Integer:
            return sine ** int(2 * node.exp)
        if not node.args:
            return node
        return node.func(*[replace(a) for a in node.args])

    if not expression.has(sympy.acos(x)):
        return None
    numerator, denominator = sympy.fraction(sympy.together(replace(expression)))
    generators = (cosine, sine, angle, pi)
    # a denominator with factors (1 ± κ)^a (a pole of ω_k at κ = ∓1): 1/(1 ± κ) = (1 ∓ κ)/sqrt(1 − κ²)², so the
    # denominator becomes c π^m sqrt(1 − κ²)^j as the series below need
    content, factors = sympy.factor_list(denominator, *generators)
    denominator = content
    for factor, power in factors:
        complement = {cosine + 1: 1 - cosine, cosine - 1: -1 - cosine, 1 - cosine: 1 + cosine}.get(factor)
        if complement is not None:  # factor · complement = ±(1 − κ²) = sqrt(1 − κ²)²
            numerator *= complement**power
            denominator *= sine ** (2 * power)
        else:
            denominator *= factor**power
    try:
        top = sympy.Poly(sympy.expand(numerator), *generators, domain="QQ")
        bottom = sympy.Poly(sympy.expand(denominator), *generators, domain="QQ")
    except (sympy.PolynomialError, sympy.polys.polyerrors.CoercionFailed):
        return None
    if top.is_zero or len(bottom.terms()) != 1:
        return None
    (i, j, l, m), constant = bottom.terms()[0]
    if i or l:
        return None
    terms = [(*monomial, Fraction(int(c.numerator), int(c.denominator))) for monomial, c in top.terms()]
    return terms, Fraction(int(constant.numerator), int(constant.denominator)), m, j


def _power_series(kind: str, order: int) -> list[Fraction]:
    """Taylor coefficients of sin (``"sin"``) or cos (``"cos"``) at 0, up to ``order`` (exclusive)."""
    out = [Fraction(0)] * order
    factorial = 1
    for n in range(order):
        factorial = factorial * n if n else 1
        if (kind == "sin" and n % 2 == 1) or (kind == "cos" and n % 2 == 0):
            out[n] = Fraction((-1) ** (n // 2), factorial)
    return out


def _multiply(a: list[Fraction], b: list[Fraction], order: int) -> list[Fraction]:
    nonzero = [(i, c) for i, c in enumerate(b) if c]
    out = [Fraction(0)] * order
    for i, ai in enumerate(a):
        if ai:
            for j, bj in nonzero:
                if i + j >= order:
                    break
                out[i + j] += ai * bj
    return out


def _exact_series(parts: Any, side: str, order: int) -> tuple[int, list[dict[int, Fraction]]]:
    """Exact series of the coefficient in the local variable y of ``side`` (β, γ or δ).

    Returns (v, coefficients): ω = Σ_n coefficients[n] y^(v+n), each coefficient a dict {π power: rational};
    the first ``order − (sin power)`` orders are exact.
    """
    terms, constant, pi_power, sin_power = parts
    # κ, sqrt(1 − κ²), acos κ in the local variable y, with acos κ = a + y·s (a times π)
    if side == "beta":  # κ = cos y, sqrt = sin y, acos = y
        kappa, root, angle_pi, angle_sign = _power_series("cos", order), _power_series("sin", order), Fraction(0), 1
    elif side == "gamma":  # κ = −cos y, sqrt = sin y, acos = π − y
        kappa = [-c for c in _power_series("cos", order)]
        root, angle_pi, angle_sign = _power_series("sin", order), Fraction(1), -1
    else:  # δ: κ = −sin y, sqrt = cos y, acos = π/2 + y
        kappa = [-c for c in _power_series("sin", order)]
        root, angle_pi, angle_sign = _power_series("cos", order), Fraction(1, 2), 1
    powers: dict[tuple[int, int], list[Fraction]] = {}
    kappa_powers = [[Fraction(1)] + [Fraction(0)] * (order - 1)]
    root_powers = [[Fraction(1)] + [Fraction(0)] * (order - 1)]

    def power(table: list[list[Fraction]], base: list[Fraction], n: int) -> list[Fraction]:
        while len(table) <= n:
            table.append(_multiply(table[-1], base, order))
        return table[n]

    numerator: dict[int, list[Fraction]] = {}
    for i, j, l, m, c in terms:
        if (i, j) not in powers:
            powers[i, j] = _multiply(power(kappa_powers, kappa, i), power(root_powers, root, j), order)
        base = powers[i, j]
        # (a π + s y)^l = Σ_r binom(l, r) (a π)^(l−r) (s y)^r
        for r in range(l + 1):
            weight = c * math.comb(l, r) * angle_pi ** (l - r) * angle_sign**r
            if not weight or r >= order:
                continue
            target = numerator.setdefault(m + l - r, [Fraction(0)] * order)
            for n in range(order - r):
                if base[n]:
                    target[n + r] += weight * base[n]
    # divide by constant π^pi_power root^sin_power, root = y·(unit series) for β and γ, a unit (cos y) for δ
    shift = sin_power if side != "delta" else 0
    unit = power(root_powers, root, sin_power)[shift:][: order - shift]
    inverse = [Fraction(0)] * len(unit)
    inverse[0] = 1 / unit[0]
    for n in range(1, len(unit)):
        inverse[n] = -sum((unit[k] * inverse[n - k] for k in range(1, n + 1) if unit[k]), Fraction(0)) / unit[0]
    exact = order - shift
    result: list[dict[int, Fraction]] = [dict() for _ in range(exact)]
    for m, series in numerator.items():
        product = _multiply(series[:exact], inverse, exact)
        for n, value in enumerate(product):
            if value:
                result[n][m - pi_power] = result[n].get(m - pi_power, Fraction(0)) + value / constant
    valuation = -shift
    result = [{m: v for m, v in term.items() if v} for term in result]
    while result and not result[0]:
        result.pop(0)
        valuation += 1
    return valuation, result


def _mp_value(term: dict[int, Fraction]) -> Any:

    return mpmath.fsum(mpmath.mpf(v.numerator) / v.denominator * mpmath.pi**m for m, v in term.items())


@locked
def stable_coefficient(expression: sympy.Expr, x: sympy.Symbol) -> StableCoefficient | None:
    """The piecewise-series form of ω_k(x) (see the comment above), or None if ``expression`` has another shape."""

    parts = _gap_parts(expression, x)
    if parts is None:
        return None
    with workdps(60):
        closed = sympy.lambdify(x, expression, "mpmath")

        def exact(kappa: Any) -> Any:  # the closed form at 120 digits (it cancels at most ~40 digits at the samples)
            with workdps(2 * 60):
                return +closed(mpmath.mpf(kappa))

        edge, other_edge = mpmath.mpf(_BETA_SWITCH), mpmath.mpf(_GAMMA_SWITCH)
        kappa_switch, other_switch = float(mpmath.cos(edge)), float(-mpmath.cos(other_edge))
        # side: (interval of the local variable, its κ, κ -> it)
        sides = {
            "beta": ((0, edge), lambda y: mpmath.cos(y), lambda k: 2 * mpmath.asin(mpmath.sqrt((1 - k) / 2))),
            "gamma": ((0, other_edge), lambda y: -mpmath.cos(y), lambda k: 2 * mpmath.asin(mpmath.sqrt((1 + k) / 2))),
            "delta": ((edge - mpmath.pi / 2, mpmath.pi / 2 - other_edge), lambda y: -mpmath.sin(y), lambda k: -mpmath.asin(k)),
        }
        series: dict[str, tuple[int, list[Any]]] = {}
        for side in sides:
            valuation, terms = _exact_series(parts, side, _SERIES_ORDER)
            series[side] = (valuation, [_mp_value(t) for t in terms])

        def evaluate(side: str, y: Any, count: int | None = None) -> Any:
            valuation, values = series[side]
            return mpmath.polyval(values[:count][::-1], y) * y**valuation

        # interior roots: sign changes on a grid in β (each point by its patch's series), refined on the closed form
        def anywhere(beta: Any) -> Any:
            if beta <= edge:
                return evaluate("beta", beta)
            if beta >= mpmath.pi - other_edge:
                return evaluate("gamma", mpmath.pi - beta)
            return evaluate("delta", beta - mpmath.pi / 2)

        grid = [mpmath.pi * (n + 1) / 401 for n in range(400)]
        signs = [mpmath.sign(anywhere(b)) for b in grid]
        roots = []
        for left, right, s_left, s_right in zip(grid, grid[1:], signs, signs[1:]):
            if s_left != s_right:
                roots.append(mpmath.cos(mpmath.findroot(anywhere, (left, right), solver="anderson")))
        windows = []
        for root in roots:
            half = float(min(_ROOT_WINDOW, (1 - abs(root)) / 3))
            windows.append((root, half))

        def in_window(kappa: Any) -> bool:
            return any(abs(kappa - r) <= h for r, h in windows)

        patches: list[Patch] = []
        worst_error = 0.0
        notes = []
        # root windows: Taylor series in t = κ − r, r = r_hi + r_lo, from the host patch's full exact series
        for index, (root, half) in enumerate(windows):
            distance = 1 - abs(root)
            count = max(8, int(math.ceil(math.log(SERIES_TARGET) / math.log(half / distance))) + 4)
            host = "beta" if root >= kappa_switch else "gamma" if root <= other_switch else "delta"
            host_function = lambda k, host=host: evaluate(host, sides[host][2](k))  # noqa: E731
            for _attempt in range(3):
                coefficients = mpmath.taylor(host_function, root, count)
                check = max(
                    abs(mpmath.polyval(coefficients[::-1], t) / exact(root + t) - 1) for t in (-half, half, -half / 3, half / 3)
                )
                if check <= 10 * SERIES_TARGET:
                    break
                count += 8
            else:
                return None
            high = float(root)
            low = float(root - mpmath.mpf(high))
            shift, t = sympy.Symbol(f"_shift{index}"), sympy.Symbol(f"_t{index}")
            definitions = ((shift, x - sympy.Float(high, 17)), (t, shift - sympy.Float(low, 17)))
            patches.append(
                Patch(f"root{index}", float(root - half), float(root + half), definitions, _horner(coefficients, t, 0),
                       f"|kappa - {high!r}| <= {half:.3g}: Taylor series ({count} terms) at the root of this coefficient")
            )
            notes.append(f"root {high!r} (window ±{half:.3g}, {count} terms, checked {float(check):.1e})")
        # the three series patches: truncation from the exact tail, checked against the closed form
        for side, ((start, end), to_kappa, from_kappa) in sides.items():
            valuation, values = series[side]
            samples = [start + (end - start) * q / 8 for q in range(9)]
            samples = [y for y in samples if y] + ([] if side == "delta" else [mpmath.mpf(1) / 1000])
            samples = [y for y in samples if not in_window(to_kappa(y))]
            # tail[i][n]: |term n| / |ω| at sample i; the exact orders must end far below the target everywhere
            tail = []
            for y in samples:
                scale, power, row = abs(evaluate(side, y)), y**valuation, []
                for c in values:
                    row.append(abs(c * power) / scale)
                    power *= y
                tail.append(row)
            if max(max(row[-6:]) for row in tail) > SERIES_TARGET / 100:
                return None
            count = len(values)
            while count > 1 and max(mpmath.fsum(row[count - 1 :]) for row in tail) <= SERIES_TARGET:
                count -= 1
            for y in samples:
                if abs(evaluate(side, y, count) / exact(to_kappa(y)) - 1) > 10 * SERIES_TARGET:
                    return None
            # float64 rounding of this patch as printed: Horner sum of the rounded coefficients at double y
            rounded = [float(c) for c in values[:count]]
            for q in range(1, 81):
                y = float(start + (end - start) * q / 80)
                if in_window(to_kappa(y)):
                    continue
                value = 0.0
                for c in reversed(rounded):
                    value = value * y + c
                value *= y**valuation
                worst_error = max(worst_error, float(abs(value / evaluate(side, mpmath.mpf(y)) - 1)))
            variable = sympy.Symbol(f"_{side}")
            half_sum = sympy.Float(0.5, 17) * x
            definitions = (
                (variable, 2 * sympy.asin(sympy.sqrt(sympy.Float(0.5, 17) - half_sum)))
                if side == "beta"
                else (variable, 2 * sympy.asin(sympy.sqrt(sympy.Float(0.5, 17) + half_sum)))
                if side == "gamma"
                else (variable, -sympy.asin(x)),
            )
            bounds = {"beta": (kappa_switch, None), "gamma": (None, other_switch), "delta": (other_switch, kappa_switch)}[side]
            description = {
                "beta": f"kappa >= cos({_BETA_SWITCH}) = {kappa_switch!r}: series in beta = acos(kappa) = 2 asin(sqrt((1 - kappa)/2))",
                "gamma": f"kappa <= -cos({_GAMMA_SWITCH}) = {other_switch!r}: series in gamma = pi - acos(kappa) = 2 asin(sqrt((1 + kappa)/2))",
                "delta": "otherwise: series in delta = acos(kappa) - pi/2 = -asin(kappa)",
            }[side]
            patches.append(
                Patch(side, *bounds, definitions, _horner(values[:count], variable, valuation),
                       f"{description}, powers {valuation}..{valuation + count - 1}")
            )
            notes.append(f"{side}: powers {valuation}..{valuation + count - 1}")
    summary = (
        "piecewise exact series (" + "; ".join(notes) + f"); switch points beta = {_BETA_SWITCH} (kappa = {kappa_switch:.6f}) "
        f"and pi - beta = {_GAMMA_SWITCH} (kappa = {other_switch:.6f}); truncation ≤ {SERIES_TARGET:g} relative, checked against the closed form "
        f"at 120 digits; float64 rounding of the series measured ≤ {worst_error:.1e} relative"
    )
    return StableCoefficient(tuple(patches), worst_error, summary)


def _horner(values: list[Any], variable: sympy.Symbol, valuation: int) -> sympy.Expr:
    """Σ_n values[n] variable^(n + valuation) in Horner form, coefficients as 25-digit floats."""
    result: sympy.Expr = sympy.Integer(0)
    for value in reversed(values):
        result = sympy.Float(value, 25) + variable * result if result != 0 else sympy.Float(value, 25)
    return variable**valuation * result if valuation else result


# Compiled families of closed forms with a first-order rounding-error bound
# =====================================================================================================
#
# The numeric evaluators of an expansion with free symbols (a0, omega0, a gap kappa...) evaluate many closed
# forms (ω_k, the waveform coefficients, the moving contact angles, the assumptions' signs) at new parameter
# values.  :func:`compile_family` turns such a list once into a vectorised float64 evaluator that also returns
# a first-order bound of its rounding error, so a caller can accept a value where the bound is small and
# recompute it exactly where the closed form cancels (near κ = ±1 or at a root).
#
# Representation.  Each expression is written as N/D, polynomials in *generators*: the free symbols (exact
# inputs) and the atoms that depend on them, ``base^(1/q)`` and elementary functions (acos, asin, atan, exp,
# log, sin, cos, ...).  Symbol-free constants (π, acos(3/10), sqrt(91)) are folded into the coefficients at 40
# digits before rounding; a single-term denominator is folded into negative exponents.  An atom's argument is
# factored over Q (1 − κ² = −(κ − 1)(κ + 1)) and evaluated factor by factor, which keeps it accurate to a few
# ulps where the expanded form would cancel (its root at κ → 1).
#
# Error bound (first order in the unit roundoff u = 2^-53).  Generators carry a relative error (0 for the
# symbols; for an atom f(a): |f'(a)| err(a) + 2u |f(a)|, libm being within one ulp).  A monomial Π x_g^e_g has
# relative error Σ |e_g| rel_g plus one u per power (e ∉ {0, 1}) and per product; a row Σ_m c_m x^m has
#   err ≤ Σ_m |c_m x^m| (rel_m + rel(c_m)) + γ_{n−1} Σ_m |c_m x^m|,   γ_{n−1} = (n − 1) u / (1 − (n − 1) u)
# (any summation order), rel(c) = 0 for ±2^k, u for another double (the product), 2u for a rounded constant;
# a row of at most two terms has one rounding of its result instead of the γ term.  A quotient adds
# (err_N + |q| err_D)/|D| + u|q|.  The bound is first order: callers accept a value only where it is far below
# their tolerance (so second-order terms are negligible).

_UNIT = 2.0**-53


def _abs_derivative_acos(x: np.ndarray) -> np.ndarray:
    return 1 / np.sqrt(np.abs(1 - x * x))


def _math(function: Any) -> Any:
    """A math function returning NaN outside its domain (as numpy does)."""

    def call(x: float) -> float:
        try:
            return function(x)
        except (ValueError, OverflowError):
            return math.nan

    return call


# sympy function: (numpy f, numpy |f'|, math f, math |f'|)
_FUNCTIONS: dict[Any, tuple[Any, Any, Any, Any]] = {
    sympy.acos: (np.arccos, _abs_derivative_acos, _math(math.acos), _math(lambda x: 1 / math.sqrt(abs(1 - x * x)))),
    sympy.asin: (np.arcsin, _abs_derivative_acos, _math(math.asin), _math(lambda x: 1 / math.sqrt(abs(1 - x * x)))),
    sympy.atan: (np.arctan, lambda x: 1 / (1 + x * x), math.atan, lambda x: 1 / (1 + x * x)),
    sympy.exp: (np.exp, np.exp, _math(math.exp), _math(math.exp)),
    sympy.log: (np.log, lambda x: 1 / np.abs(x), _math(math.log), _math(lambda x: 1 / abs(x))),
    sympy.sin: (np.sin, lambda x: np.ones_like(x), _math(math.sin), lambda x: 1.0),
    sympy.cos: (np.cos, lambda x: np.ones_like(x), _math(math.cos), lambda x: 1.0),
    sympy.sinh: (np.sinh, np.cosh, _math(math.sinh), _math(math.cosh)),
    sympy.cosh: (np.cosh, np.cosh, _math(math.cosh), _math(math.cosh)),
    sympy.tanh: (np.tanh, lambda x: np.ones_like(x), math.tanh, lambda x: 1.0),
    sympy.asinh: (np.arcsinh, lambda x: 1 / np.sqrt(1 + x * x), math.asinh, lambda x: 1 / math.sqrt(1 + x * x)),
    sympy.acosh: (np.arccosh, lambda x: 1 / np.sqrt(np.abs(x * x - 1)), _math(math.acosh), _math(lambda x: 1 / math.sqrt(abs(x * x - 1)))),
    sympy.atanh: (np.arctanh, lambda x: 1 / np.abs(1 - x * x), _math(math.atanh), _math(lambda x: 1 / abs(1 - x * x))),
}


class _Unsupported(Exception):
    """An expression outside what :func:`compile_family` represents (Piecewise, Max, symbolic exponents...)."""


def _coefficient_rounding(value: Any) -> float:
    """Relative error of c·x in float64 for the exact constant ``value`` (mpf): 0 for ±2^k, u for another
    double (the product's rounding), 2u for a rounded constant."""
    number = float(value)
    if number == 0:
        return 0.0
    if mpmath.mpf(number) != value:
        return 2 * _UNIT
    mantissa, _ = math.frexp(abs(number))
    return 0.0 if mantissa == 0.5 else _UNIT


class _Block:
    """Rows Σ_m c_{r,m} Π_g x_g^{e_{m,g}} over a prefix of the generators, evaluated with an error bound."""

    def __init__(self, rows: list[dict[tuple[int, ...], Any]], generators: int):
        monomials = sorted({monomial for row in rows for monomial in row})
        index = {monomial: position for position, monomial in enumerate(monomials)}
        exponents = np.array(monomials, dtype=np.int64).reshape(len(monomials), generators)
        count, size = len(rows), len(monomials)
        coefficients = np.zeros((count, size))
        rounding = np.zeros((count, size))
        for r, row in enumerate(rows):
            for monomial, value in row.items():
                coefficients[r, index[monomial]] = float(value)
                rounding[r, index[monomial]] = _coefficient_rounding(value)
        absolute = np.abs(coefficients)
        zero = np.zeros_like(coefficients)
        # one product gives the rows, their propagated error and the sums of |terms|:
        # [C 0 0; 0 |C|·rel(c) |C|; 0 |C| 0] @ [x^m; |x^m|; |x^m|·rel_m]
        self.stack = np.block([[coefficients, zero, zero], [zero, absolute * rounding, absolute], [zero, absolute, zero]])
        self.rows = count
        terms = np.array([len(row) for row in rows])
        gamma = np.maximum(terms - 1, 0) * _UNIT
        short = terms <= 2
        self.summation = np.where(short, 0.0, gamma / (1 - gamma))[:, None]
        self.short = np.where(short, _UNIT, 0.0)[:, None] if short.any() else None  # one rounding of the result
        # x^k by pow (within one ulp); counted as k - 1 roundings (repeated products) and one more for k < 0,
        # which also covers pow; one rounding per product of powers
        powers = np.maximum(np.abs(exponents) - 1, 0) + (exponents < 0)
        factors = (exponents != 0).sum(axis=1)
        self.roundings = ((powers.sum(axis=1) + np.maximum(factors - 1, 0)) * _UNIT)[:, None]
        self.magnitudes = np.abs(exponents).astype(float)
        # per generator used: the exponent range and where each monomial takes its power from
        self.tables = []
        for g in range(generators):
            column = exponents[:, g]
            if column.any():
                low = int(column.min())
                self.tables.append((g, np.arange(low, int(column.max()) + 1, dtype=float)[:, None], column - low))
        self.generators = generators
        # small blocks (an atom's factors) are evaluated in plain floats for one point: numpy's per-call
        # overhead would dominate; the same bound, term by term
        self.python = None
        if sum(len(row) for row in rows) <= 16:
            self.python = [
                (
                    [
                        (float(value), _coefficient_rounding(value)
                         + (sum(max(abs(e) - 1, 0) + (e < 0) for e in monomial) + max(sum(e != 0 for e in monomial) - 1, 0)) * _UNIT,
                         tuple((g, e) for g, e in enumerate(monomial) if e))
                        for monomial, value in row.items()
                    ],
                    len(row) <= 2,
                    float(self.summation[r, 0]),
                )
                for r, row in enumerate(rows)
            ]

    def evaluate_floats(self, values: list[float], relative: list[float]) -> tuple[list[float], list[float]]:
        """:meth:`evaluate` at one point in plain floats (small blocks only: ``self.python``)."""
        results, bounds = [], []
        for terms, short, summation in self.python:
            total = size = propagated = 0.0
            for coefficient, rounding, factors in terms:
                term, error = coefficient, rounding
                for g, exponent in factors:
                    term *= values[g] ** exponent
                    error += abs(exponent) * relative[g]
                total += term
                size += abs(term)
                propagated += abs(term) * error
            results.append(total)
            bounds.append(propagated + (_UNIT * abs(total) if short else summation * size))
        return results, bounds

    def evaluate(self, values: np.ndarray, relative: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Values and error bounds of the rows, shape (rows, S), from generators ``values`` (G, S) with
        relative errors ``relative`` (G, S)."""
        monomial = None
        for g, exponents, position in self.tables:
            table = (values[g] ** exponents)[position]
            monomial = table if monomial is None else monomial * table
        if monomial is None:
            monomial = np.ones((self.stack.shape[1] // 3, values.shape[1]))
        size_of = np.abs(monomial)
        error = self.magnitudes @ relative[: self.generators] + self.roundings
        stacked = self.stack @ np.concatenate((monomial, size_of, size_of * error))
        rows = self.rows
        result = stacked[:rows]
        bound = stacked[rows : 2 * rows] + self.summation * stacked[2 * rows :]
        if self.short is not None:
            bound += self.short * np.abs(result)
        return result, bound


@dataclass(frozen=True)
class _Atom:
    kind: str  # "root" (argument^(1/q)) or "function"
    root: int
    function: Any
    derivative: Any
    scalar_function: Any  # the same on floats (math)
    scalar_derivative: Any
    constant: float  # the argument is constant · Π factor^power over earlier generators
    constant_error: float
    block: _Block | None
    source: int | None  # the argument is this generator (constant 1, no factors)
    exponents: np.ndarray  # (rows of ``block``, 1): the power of each factor
    powers: tuple[int, ...]  # the same as ints
    magnitudes: np.ndarray  # |exponents| as a row
    roundings: float  # u per product and per power


class BoundedFamily:
    """Float64 values of a list of closed forms in ``symbols``, vectorised, with first-order error bounds.

    Call with one number or array per symbol (broadcast together); returns ``(values, bounds)`` of shape
    ``(len(expressions),) + broadcast shape``.  Build with :func:`compile_family`.

    Examples
    --------
    >>> import sympy
    >>> kappa = sympy.Symbol("kappa", real=True)
    >>> family = compile_family([sympy.acos(kappa) - kappa * sympy.sqrt(1 - kappa**2)], (kappa,))
    >>> values, bounds = family(0.5)
    >>> round(float(values[0]), 12), bool(bounds[0] < 1e-15)
    (0.614184849304, True)
    """

    def __init__(self, symbols: tuple[sympy.Symbol, ...], atoms: list[_Atom], block: _Block, quotients: np.ndarray, rows: int):
        self.symbols, self.atoms, self.block, self.rows = symbols, atoms, block, rows
        # rows of ``block``: the numerators, then the denominators that are not one term (quotients[r] >= 0)
        self.quotient_rows = np.flatnonzero(quotients >= 0)
        self.divisor_rows = quotients[self.quotient_rows]

    def _scalar_generators(self, numbers: list[float]) -> tuple[np.ndarray, np.ndarray]:
        """Generator values and relative errors at one point, the atoms in plain floats."""
        first = len(self.symbols)
        values, relative = list(numbers), [0.0] * len(numbers)
        for g, atom in enumerate(self.atoms, start=first):
            if atom.source is not None:
                argument, argument_error = values[atom.source], relative[atom.source]
            elif atom.block is None:
                argument, argument_error = atom.constant, atom.constant_error
            elif atom.block.python is not None:
                factors, bounds = atom.block.evaluate_floats(values[:g], relative[:g])
                argument, argument_error = atom.constant, atom.constant_error + atom.roundings
                for factor, bound, power in zip(factors, bounds, atom.powers):
                    argument *= factor**power if factor else math.inf
                    argument_error += abs(power) * bound / abs(factor) if factor else math.inf
            else:
                return self._array_generators([np.array([value]) for value in numbers], 1)
            if atom.kind == "root":
                value = math.sqrt(argument) if argument >= 0 else math.nan
                value = value if atom.root == 2 else (argument ** (1.0 / atom.root) if argument >= 0 else math.nan)
                error = argument_error / atom.root + (_UNIT if atom.root == 2 else 2 * _UNIT)
            else:
                value = atom.scalar_function(argument)
                if atom.source is not None and atom.source < first:
                    error = 2 * _UNIT
                else:
                    propagated = atom.scalar_derivative(argument) * abs(argument) * argument_error if argument_error > 0 else 0.0
                    error = propagated / abs(value) + 2 * _UNIT if value else math.inf
            values.append(value)
            relative.append(error)
        return np.array(values)[:, None], np.array(relative)[:, None]

    def _array_generators(self, arrays: list[np.ndarray], size: int) -> tuple[np.ndarray, np.ndarray]:
        first = len(self.symbols)
        values = np.empty((first + len(self.atoms), size))
        relative = np.zeros((first + len(self.atoms), size))
        for g, array in enumerate(arrays):
            values[g] = array.reshape(size)
        for g, atom in enumerate(self.atoms, start=first):
            if atom.source is not None:  # the argument is one generator
                argument, argument_error = values[atom.source], relative[atom.source]
            elif atom.block is None:
                argument, argument_error = np.full(size, atom.constant), atom.constant_error
            else:
                factors, bounds = atom.block.evaluate(values[:g], relative[:g])
                argument = atom.constant * np.prod(factors**atom.exponents, axis=0)
                argument_error = atom.constant_error + atom.magnitudes @ (bounds / np.abs(factors)) + atom.roundings
            if atom.kind == "root":
                values[g] = np.sqrt(argument) if atom.root == 2 else np.power(argument, 1.0 / atom.root)
                relative[g] = argument_error / atom.root + (_UNIT if atom.root == 2 else 2 * _UNIT)
            else:
                value = values[g] = atom.function(argument)
                if atom.source is not None and atom.source < first:  # an exact argument
                    relative[g] = 2 * _UNIT
                else:  # |f'(a)| |a| rel(a) / |f(a)|, zero where the argument is exact
                    propagated = np.where(argument_error > 0, atom.derivative(argument) * np.abs(argument) * argument_error, 0.0)
                    relative[g] = propagated / np.abs(value) + 2 * _UNIT
        return values, relative

    def __call__(self, *arguments: Any) -> tuple[np.ndarray, np.ndarray]:
        if all(isinstance(value, float) for value in arguments):
            with np.errstate(all="ignore"):
                values, relative = self._scalar_generators([float(value) for value in arguments])
                return self._rows(values, relative, ())
        arrays = [np.asarray(value, dtype=float) for value in arguments]
        if len(arrays) > 1:
            arrays = np.broadcast_arrays(*arrays)
        shape = arrays[0].shape if arrays else ()
        size = arrays[0].size if arrays else 1
        with np.errstate(all="ignore"):
            values, relative = self._array_generators(arrays, size)
            return self._rows(values, relative, shape)

    def _rows(self, values: np.ndarray, relative: np.ndarray, shape: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
        result, bound = self.block.evaluate(values, relative)
        rows, divisors = self.quotient_rows, self.divisor_rows
        if rows.size:
            divisor, divisor_bound = result[divisors], bound[divisors]
            quotient = result[rows] / divisor
            bound[rows] = (bound[rows] + np.abs(quotient) * divisor_bound) / np.abs(divisor) + _UNIT * np.abs(quotient)
            result[rows] = quotient
        result, bound = result[: self.rows], bound[: self.rows]
        bound[~np.isfinite(result)] = np.inf
        return result.reshape((self.rows, *shape)), bound.reshape((self.rows, *shape))


class _FamilyBuilder:
    def __init__(self, symbols: tuple[sympy.Symbol, ...]):
        self.symbols = symbols
        self.symbol_set = frozenset(symbols)
        self.atom_keys: dict[Any, sympy.Dummy] = {}
        self.atom_list: list[_Atom] = []
        self.atom_dummies: list[sympy.Dummy] = []
        self.constants: dict[sympy.Dummy, Any] = {}
        self.constant_keys: dict[sympy.Expr, sympy.Dummy] = {}
        self.memo: dict[sympy.Expr, sympy.Expr] = {}

    @property
    def generators(self) -> list[sympy.Symbol]:
        return [*self.symbols, *self.atom_dummies]

    def constant(self, expression: sympy.Expr) -> sympy.Expr:
        if expression.is_Rational:
            return expression
        if expression not in self.constant_keys:
            value = sympy.N(expression, 45)
            if not value.is_real or not value.is_finite:
                raise _Unsupported(f"the constant {expression} is not a finite real number")
            dummy = sympy.Dummy("c")
            self.constant_keys[expression] = dummy
            with workdps(45):
                self.constants[dummy] = mpmath.mpf(value)
        return self.constant_keys[expression]

    def replace(self, expression: sympy.Expr) -> sympy.Expr:
        if expression in self.memo:
            return self.memo[expression]
        free = expression.free_symbols
        if not free:
            result = self.constant(expression)
        elif not free <= self.symbol_set:
            raise _Unsupported(f"symbols {sorted(map(str, free - self.symbol_set))} are not arguments")
        elif expression.is_Symbol:
            result = expression
        elif expression.is_Add or expression.is_Mul:
            result = expression.func(*[self.replace(argument) for argument in expression.args])
        elif expression.is_Pow and expression.exp.is_Integer:
            result = self.replace(expression.base) ** expression.exp
        elif expression.is_Pow and expression.exp.is_Rational:
            exponent = expression.exp
            result = self.atom(("root", exponent.q, expression.base)) ** exponent.p
        elif isinstance(expression, sympy.Function) and expression.func in _FUNCTIONS and len(expression.args) == 1:
            result = self.atom(("function", expression.func, expression.args[0]))
        else:
            raise _Unsupported(f"{type(expression).__name__} is not compiled")
        self.memo[expression] = result
        return result

    def atom(self, key: tuple) -> sympy.Dummy:
        if key in self.atom_keys:
            return self.atom_keys[key]
        kind, detail, argument = key
        replaced = self.replace(argument)  # inner atoms first: the atoms stay in dependency order
        generators = self.generators
        numerator, denominator = sympy.fraction(sympy.together(replaced))
        constant = mpmath.mpf(1)
        rows: list[dict[tuple[int, ...], Any]] = []
        powers: list[int] = []
        for part, sign in ((numerator, 1), (denominator, -1)):
            content, factors = sympy.factor_list(part, *generators, *self.constants) if part.free_symbols else (part, [])
            constant = constant * self.fold(content) ** sign
            for factor, power in factors:
                terms = self.rows_of(factor, generators)
                if len(terms) == 1 and all(not any(m) for m in terms):  # a constant factor
                    constant = constant * next(iter(terms.values())) ** (sign * power)
                    continue
                rows.append(terms)
                powers.append(sign * int(power))
        function, derivative, scalar_function, scalar_derivative = (None,) * 4 if kind == "root" else _FUNCTIONS[detail]
        source = None
        if constant == 1 and powers == [1] and len(rows[0]) == 1:
            (monomial, value), = rows[0].items()
            if value == 1 and sum(monomial) == 1 and max(monomial) == 1:
                source = monomial.index(1)
        atom = _Atom(
            kind, detail if kind == "root" else 0, function, derivative, scalar_function, scalar_derivative, float(constant),
            _coefficient_rounding(constant),
            _Block(rows, len(generators)) if rows else None, source, np.array(powers, dtype=float)[:, None], tuple(powers),
            np.abs(np.array(powers, dtype=float)), (len(powers) + sum(abs(p) > 1 for p in powers)) * _UNIT,
        )
        dummy = sympy.Dummy("a")
        self.atom_keys[key] = dummy
        self.atom_list.append(atom)
        self.atom_dummies.append(dummy)
        return dummy

    def fold(self, expression: sympy.Expr) -> Any:
        """A symbol-free expression in the constant dummies, at 45 digits."""
        with workdps(45):
            return sympy.lambdify(list(self.constants), expression, "mpmath")(*self.constants.values()) if expression.free_symbols else mpmath.mpf(sympy.N(expression, 45))

    def rows_of(self, polynomial: sympy.Expr, generators: list[sympy.Symbol]) -> dict[tuple[int, ...], Any]:
        """{exponents over ``generators``: coefficient (mpf, constants folded)} of a polynomial."""
        constants = list(self.constants)
        poly = sympy.Poly(polynomial, *generators, *constants, domain="QQ")
        width = len(generators)
        terms: dict[tuple[int, ...], Any] = {}
        with workdps(45):
            for monomial, coefficient in poly.terms():
                value = mpmath.mpf(int(coefficient.numerator)) / int(coefficient.denominator)
                for dummy, exponent in zip(constants, monomial[width:]):
                    if exponent:
                        value *= self.constants[dummy] ** exponent
                key = tuple(monomial[:width])
                terms[key] = terms.get(key, 0) + value
        return {key: value for key, value in terms.items() if value != 0} or {(0,) * width: mpmath.mpf(0)}


#: Compiled families by (expressions, symbols), oldest first (guarded by the precision lock).
_FAMILIES: dict[tuple, BoundedFamily | None] = {}
_FAMILY_MEMORY = 64


def forget_families() -> None:
    """Drop the remembered families (:func:`lindstedt.clear_cache`)."""
    with LOCK:
        _FAMILIES.clear()


def compile_family(expressions: list[sympy.Expr], symbols: tuple[sympy.Symbol, ...]) -> BoundedFamily | None:
    """A :class:`BoundedFamily` for ``expressions`` in ``symbols``, or None if one of them is outside the
    representation (see the comment block above: polynomials over monomial or polynomial denominators in the
    symbols and in roots and elementary functions of such expressions).

    The constants are folded in double precision whatever mpmath's precision outside, under the lock that
    guards it: the same family on every thread.  Families are remembered (the last :data:`_FAMILY_MEMORY`),
    so threads that ask for one at once compile it once."""
    key = (tuple(expressions), tuple(symbols))
    with workprec(53):
        family = _FAMILIES.pop(key, _FAMILIES)  # the dict itself marks a miss (None is a valid entry)
        if family is _FAMILIES:
            family = _compile_family(expressions, symbols)
        _FAMILIES[key] = family  # most recent last
        while len(_FAMILIES) > _FAMILY_MEMORY:
            del _FAMILIES[next(iter(_FAMILIES))]
        return family


def _compile_family(expressions: list[sympy.Expr], symbols: tuple[sympy.Symbol, ...]) -> BoundedFamily | None:
    builder = _FamilyBuilder(tuple(symbols))
    parts = []
    try:
        for expression in expressions:
            replaced = builder.replace(sympy.sympify(expression, strict=True))
            numerator, denominator = sympy.fraction(sympy.together(replaced)) if replaced.free_symbols else (replaced, sympy.Integer(1))
            parts.append((numerator, denominator))
        generators = builder.generators
        width = len(generators)
        numerators: list[dict[tuple[int, ...], Any]] = []
        denominators: list[dict[tuple[int, ...], Any]] = []
        links = []
        for numerator, denominator in parts:
            top = builder.rows_of(numerator, generators)
            bottom = builder.rows_of(denominator, generators)
            if len(bottom) == 1:
                (shift, divisor), = bottom.items()
                with workdps(45):
                    top = {tuple(a - b for a, b in zip(key, shift)): value / divisor for key, value in top.items()}
                links.append(-1)
            else:
                links.append(len(denominators))
                denominators.append(bottom)
            numerators.append(top)
    except (_Unsupported, sympy.PolynomialError, sympy.polys.polyerrors.CoercionFailed, ZeroDivisionError):
        return None
    quotients = np.array([-1 if link < 0 else len(numerators) + link for link in links], dtype=np.int64)
    return BoundedFamily(builder.symbols, builder.atom_list, _Block(numerators + denominators, width), quotients, len(expressions))
