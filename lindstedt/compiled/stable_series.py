"""Stable float evaluation of the gap coefficients ω_k(κ): exact series near κ = ±1 and at interior roots.

For f = (u − κ)_+ with one free symbol, ω_k(κ) is a closed form in κ, acos κ and
sqrt(1 − κ²) whose terms cancel in float64 as κ → ±1 (ω_2 ∝ (1 − κ)^{5/2}).  This
module replaces it by series in β = arccos κ, π − β and β − π/2, computed exactly
from the closed form, plus Taylor windows at interior roots; the reasoning and the
measured switch points are in the comment block below.  Printed by :mod:`lindstedt.compiled.stable_source`
for :mod:`lindstedt.export.codegen` (``GeneratedCode.accuracy`` states the result) and for the float evaluators
of an expansion (:func:`~lindstedt.compiled.stable_source.stable_function`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import mpmath
import sympy
from gmpy2 import mpq as Fraction  # exact rationals, several times faster than fractions.Fraction

from .._precision import locked, workdps

__all__ = ["SERIES_TARGET", "Patch", "StableCoefficient", "stable_coefficient"]

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
