"""A contact arc under a fractional power law, on a fixed interval (Hertz contact and its kin).

Problem: a piece of the branch hierarchy (N = 1, see :mod:`lindstedt.engine.branches`)
that holds a turning point — the first piece ``s ∈ [0, s*(ε̂))`` (the release point),
or the last one ``(s*(ε̂), π]`` read backwards (τ = (π − s)/(π − s*), W = −Y) — on which
the normalised law is

    Ω² W'' + W + ε̂ f̂(W) = 0,   f̂(W) = Σ_m c_m W^m + c (W − κ)^p,   W > κ,

with a rational exponent ``p = q/d > 0`` that is not an integer (Hertz: p = 3/2), plus
the rest of the law, polynomial or analytic, g(W) expanded about Y_0 at every point,
``[g(Y)]_n = Σ_k g^{(k)}(Y_0)/k! [(Y − Y_0)^k]_n`` (an analytic law alone has d = 1).
The solution is not analytic at the contact point W = κ (W − κ ~ s* − s, so
W'' ~ (s* − s)^p), and that point moves with ε̂: Lindstedt coefficients W_n(s) at a
fixed s would diverge there from the order where p − n < −1.  So the arc is mapped
to a fixed interval: ``τ = s/s*(ε̂) ∈ [0, 1]``, ``Y(τ) = W(s* τ)``, ``μ = Ω²/s*²``:

    μ Y'' + Y + ε̂ f̂(Y) = 0,   Y'(0) = 0,   Y(0) = 1 + Σ h_n ε̂^n,   Y(1) = κ,

and the contact point stays at τ = 1 for every ε̂.  With ``Y = Σ ε̂^n Y_n``,
``Y_0 = cos βτ``, ``β = arccos κ``, ``μ = Σ μ_n ε̂^n``, ``μ_0 = 1/β²``, the vanishing
factor stays a fixed weight,

    (Y − κ)^p = (Y_0 − κ)^p (1 + Σ_{j≥1} R_j ε̂^j)^p,   R_j = Y_j/(Y_0 − κ)   (bounded: Y_j(1) = 0),

expanded by the recurrence for powers of a power series.  Order n ≥ 1 reads

    Y_n'' + β² Y_n = g_n = −β² (μ_n Y_0'' + Σ_{i=1}^{n−1} μ_i Y_{n−i}'' + [f̂(Y)]_{n−1}),

solved by variation of parameters from τ = 0 (ĝ_n is g_n without its μ_n term),

    Y_n = h_n cos βτ + (β³ μ_n/2) τ sin βτ + (1/β)[sin βτ ∫_0^τ cos βt ĝ_n dt − cos βτ ∫_0^τ sin βt ĝ_n dt],

with μ_n from the contact condition Y_n(1) = 0: μ_n and the end slope Y_n'(1) are affine in
the turning-point value h_n (:meth:`StretchedArc.response`).  At the release point h_n is
the prescribed w_n; at the far turning point it is an unknown of the branch hierarchy,
which ties μ to Ω and the arc's length (``length² = Ω²/μ``), matches the neighbouring piece
to the arc's end and hands h_n back (:meth:`StretchedArc.fix`).

**Representation.**  Every Y_n is analytic in ``v = (1 − τ)^{1/d}`` on [0, 1] (the
powers (1 − τ)^{k/d} that the contact point brings are powers of v, and τ = 1 − v^d),
so it is kept by its values at M Chebyshev points of the first kind in v (interior
points: R_j is 0/0 at v = 0) and the integrals are cumulative Chebyshev integrals in v
(t = 1 − ν^d, dt = −d ν^{d−1} dν), which converge geometrically.  M doubles until
the Chebyshev tail of every Y_n is below the working precision.  Arithmetic is mpmath
at the requested digits plus guard digits (the quotient R_j near v = 0 loses up to
log10(1/v_min^d) of them).
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Any, Callable, Sequence

import mpmath
import numpy as np
import sympy

from .._errors import ConvergenceError, UnsupportedNonlinearityError
from .._precision import locked, workdps

__all__ = ["StretchedArc", "FloatArc", "VectorArc"]

_INITIAL_NODES = 32
_MAXIMUM_NODES = 1024
_GUARD_DIGITS = 20


def _resolved(arc: Any, order: int, tail_of: Callable[[Any], Any]) -> Any:
    """The next order's particular data of an arc (:class:`StretchedArc` or :class:`VectorArc`), the Chebyshev grid
    doubled until its tail (``tail_of``) and the fixed orders' are below the working precision; kept as pending."""
    if order != len(arc._mu):
        raise ValueError(f"order {order} of the stretched arc is not the next one ({len(arc._mu)})")
    tolerance = mpmath.mpf(10) ** (-(arc.digits + 2))
    while True:
        with workdps(arc._working):
            data = arc._particular(order)
        if max(tail_of(data), arc.tail) <= tolerance:
            break
        arc._refine(order)
    arc._pending = (order, data)
    return data


class _FixedPointTransform:
    """``y = T x`` (or ``Tᵀ x``) for the arc's Chebyshev matrix ``T_{k,i} = cos(k θ_i)`` in fixed point: T and x as
    Python integers scaled by 2^bits (x relative to its largest entry), one integer matrix product (numpy object
    arrays), then back to mpf.  Measured 5x faster than ``mpmath.fsum`` of mpf products at 128 nodes and 60 digits,
    agreeing to 8e-60 — the arcs spent 85 % of their time in those sums."""

    def __init__(self, matrix: list[list[Any]], digits: int):
        self.bits = int(digits * 3.33) + 24
        self.matrix = np.array([[int(mpmath.nint(mpmath.ldexp(entry, self.bits))) for entry in row] for row in matrix],
                               dtype=object)
        self.transposed = self.matrix.T.copy()

    def apply(self, values: Sequence[Any], transposed: bool = False) -> list[Any]:
        largest = max((abs(v) for v in values), default=0)
        if not largest:
            return [mpmath.mpf(0)] * len(values)
        shift = self.bits - mpmath.frexp(largest)[1]
        integers = np.array([int(mpmath.nint(mpmath.ldexp(v, shift))) for v in values], dtype=object)
        product = (self.transposed if transposed else self.matrix).dot(integers)
        return [mpmath.ldexp(mpmath.mpf(int(value)), -self.bits - shift) for value in product]


class FloatArc:
    """Float image of Y_0 … Y_N for fast evaluation: Chebyshev coefficients in x = 2v − 1 of Y_n and dY_n/dτ."""

    def __init__(self, denominator: int, values: Sequence[np.ndarray], slopes: Sequence[np.ndarray]):
        self.denominator = denominator
        self.values = np.array(values)
        self.slopes = np.array(slopes)

    def evaluate(self, stretched_time: np.ndarray, weights: np.ndarray, derivative: bool) -> np.ndarray:
        """Σ_n weights[n] Y_n(τ) (or dY_n/dτ) at τ ∈ [0, 1]."""
        position = np.clip(1.0 - stretched_time, 0.0, 1.0) ** (1.0 / self.denominator)
        coefficients = weights @ (self.slopes if derivative else self.values)
        return np.polynomial.chebyshev.chebval(2.0 * position - 1.0, coefficients)


class StretchedArc:
    """Order-by-order solution on the stretched contact arc (module docstring), lazy and memoised.

    Parameters
    ----------
    kappa : number
        The contact point κ (|κ| < 1) of Y.
    exponent : Fraction
        p = q/d > 0, not an integer.
    coefficient : number
        c of the fractional term c (Y − κ)^p.
    digits : int
        Decimal digits wanted.
    analytic : (sympy expression, symbol), optional
        The rest of the law g(Y), polynomial or analytic (``exponent`` may then be None: no fractional term).

    Examples
    --------
    >>> from fractions import Fraction
    >>> arc = StretchedArc(0, Fraction(3, 2), 1, 20)
    >>> mu_constant, mu_per_h, slope_constant, slope_per_h = arc.response(1)
    >>> arc.fix(1, 0)                       # released at Y(0) = 1 exactly
    >>> arc.mu(1) == mu_constant
    True
    """

    def __init__(self, kappa: Any, exponent: Fraction | None, coefficient: Any, digits: int,
                 analytic: tuple[Any, Any] | None = None):
        if exponent is not None and (exponent <= 0 or exponent.denominator == 1):
            raise ValueError("the stretched arc's power law needs a non-integer exponent p > 0")
        self.exponent = exponent
        self.denominator = 1 if exponent is None else exponent.denominator
        self._analytic_terms: list[Callable[[Any], Any]] = []
        self._analytic_expression, self._analytic_symbol = analytic if analytic is not None else (None, None)
        self.digits = digits
        self._working = digits + _GUARD_DIGITS
        self._turning: list[Any] = [mpmath.mpf(1)]  # h_n = Y_n(0) as fixed so far
        self._pending: tuple[int, dict] | None = None
        with workdps(self._working):
            self.kappa = mpmath.mpf(kappa)
            self.coefficient = mpmath.mpf(coefficient) if exponent is not None else mpmath.mpf(0)
            self.beta = mpmath.acos(self.kappa)
        self.nodes = _INITIAL_NODES
        self._reset()
        self.counters = {"orders": 0, "restarts": 0}

    # -- grid -------------------------------------------------------------------------------------------
    def _reset(self) -> None:
        M, d = self.nodes, self.denominator
        with workdps(self._working):
            angles = [mpmath.pi * (i + mpmath.mpf(1) / 2) / M for i in range(M)]
            x = [mpmath.cos(angle) for angle in angles]
            self._x = x
            self._v = [(xi + 1) / 2 for xi in x]
            self._tau = [1 - vi**d for vi in self._v]
            beta = self.beta
            self._cos = [mpmath.cos(beta * t) for t in self._tau]
            self._sin = [mpmath.sin(beta * t) for t in self._tau]
            # Y_0 − κ = cos βτ − cos β = 2 sin(β(1 + τ)/2) sin(β v^d/2), without cancellation near τ = 1
            self._gap = [2 * mpmath.sin(beta * (1 + t) / 2) * mpmath.sin(beta * vi**d / 2) for t, vi in zip(self._tau, self._v)]
            self._weight = [self.coefficient * g**self.exponent for g in self._gap] if self.exponent is not None else [mpmath.mpf(0)] * M
            self._jacobian = [d * vi ** (d - 1) for vi in self._v]  # −dt/dν
            self._transform = [[mpmath.cos(k * angle) for angle in angles] for k in range(M)]
            self._fast = _FixedPointTransform(self._transform, self._working)
        self._values: list[list[Any]] = [list(self._cos)]  # Y_n at the nodes
        self._second: list[list[Any]] = [[-beta * beta * c for c in self._cos]]  # Y_n''
        self._ratios: list[list[Any]] = [[]]  # R_n (n ≥ 1)
        self._binomial: list[list[Any]] = [[mpmath.mpf(1)] * M]  # B_n of (1 + Σ R ε̂)^p
        self._taylor: dict[int, list[Any]] = {}  # g^{(k)}(Y_0)/k! at the nodes
        self._deviation: dict[tuple[int, int], list[Any]] = {}  # [(Y − Y_0)^k]_n at the nodes
        self._mu: list[Any] = [1 / (beta * beta)]
        self._slope: list[Any] = [-beta * mpmath.sin(beta)]
        self._series: list[tuple[list[Any], list[Any]]] = []  # Chebyshev coefficients of Y_n and Y_n' (n ≥ 1)
        self.tail = mpmath.mpf(0)

    def _coefficients(self, values: list[Any]) -> list[Any]:
        """Chebyshev coefficients a_k (a_0 halved) of the interpolant through the node values."""
        M = self.nodes
        scale = mpmath.mpf(2) / M
        coefficients = [scale * c for c in self._fast.apply(values)]
        coefficients[0] /= 2
        return coefficients

    def _integral_to_end(self, integrand: list[Any]) -> tuple[list[Any], Any]:
        """∫_v^1 h(ν) dν at every node and ∫_0^1 h: cumulative Chebyshev integration in x = 2ν − 1."""
        M = self.nodes
        a = self._coefficients(integrand) + [mpmath.mpf(0), mpmath.mpf(0)]
        b = [mpmath.mpf(0)] * (M + 1)
        b[1] = a[0] - a[2] / 2
        for k in range(2, M + 1):
            b[k] = (a[k - 1] - a[k + 1]) / (2 * k)
        top = mpmath.fsum(b)
        bottom = mpmath.fsum(value if k % 2 == 0 else -value for k, value in enumerate(b))
        # T_M(x_i) = cos(M θ_i) = 0 at first-kind nodes: Σ_{k<M} b_k T_k(x_i), the transposed transform
        at_nodes = [(top - value) / 2 for value in self._fast.apply(b[:M], transposed=True)]
        return at_nodes, (top - bottom) / 2

    # -- the hierarchy ----------------------------------------------------------------------------------
    def _taylor_values(self, k: int) -> list[Any]:
        """g^{(k)}(Y_0)/k! at the nodes (the analytic part of the law)."""
        if k not in self._taylor:
            while len(self._analytic_terms) <= k:
                derivative = sympy.diff(self._analytic_expression, self._analytic_symbol, len(self._analytic_terms))
                scale = sympy.Integer(math.factorial(len(self._analytic_terms)))
                self._analytic_terms.append(sympy.lambdify(self._analytic_symbol, derivative / scale, modules="mpmath"))
            values = [mpmath.mpf(self._analytic_terms[k](y)) for y in self._cos]
            if not all(mpmath.isfinite(value) for value in values):
                raise UnsupportedNonlinearityError(
                    f"the law {self._analytic_expression} is not analytic on the contact arc (derivative {k} is not finite there)"
                )
            self._taylor[k] = values
        return self._taylor[k]

    def _deviation_power(self, power: int, order: int) -> list[Any]:
        """[(Y − Y_0)^power]_order at the nodes (power ≥ 1, order ≥ power)."""
        key = (power, order)
        if key not in self._deviation:
            if power == 1:
                result = self._values[order]
            else:
                result = [mpmath.mpf(0)] * self.nodes
                for j in range(1, order - power + 2):
                    left, right = self._values[j], self._deviation_power(power - 1, order - j)
                    result = [r + x * y for r, x, y in zip(result, left, right)]
            self._deviation[key] = result
        return self._deviation[key]

    def _law(self, order: int) -> list[Any]:
        """[f̂(Y)]_order at the nodes."""
        M = self.nodes
        total = [self._weight[i] * self._binomial[order][i] for i in range(M)]
        if self._analytic_expression is not None:
            if order == 0:
                total = [t + g for t, g in zip(total, self._taylor_values(0))]
            for k in range(1, order + 1):
                term = self._deviation_power(k, order)
                total = [t + g * x for t, g, x in zip(total, self._taylor_values(k), term)]
        return total

    def _particular(self, order: int) -> dict:
        """The part of Y_order that lower orders fix: ĝ, the variation-of-parameters integrals, Y_p(1), Y_p'(1)."""
        beta = self.beta
        law = self._law(order - 1)
        forcing = [-beta * beta * value for value in law]
        for i in range(1, order):
            mu = self._mu[i]
            forcing = [g - beta * beta * mu * y for g, y in zip(forcing, self._second[order - i])]
        integrand_cos = [j * c * g for j, c, g in zip(self._jacobian, self._cos, forcing)]
        integrand_sin = [j * s * g for j, s, g in zip(self._jacobian, self._sin, forcing)]
        cos_integral, cos_total = self._integral_to_end(integrand_cos)
        sin_integral, sin_total = self._integral_to_end(integrand_sin)
        sin_b, cos_b = mpmath.sin(beta), mpmath.cos(beta)
        coefficients = self._coefficients(integrand_cos)
        scale = max(abs(a) for a in coefficients) or mpmath.mpf(1)
        return {
            "forcing": forcing, "cos": cos_integral, "sin": sin_integral,
            "end": (sin_b * cos_total - cos_b * sin_total) / beta, "end_slope": cos_b * cos_total + sin_b * sin_total,
            "tail": max(abs(a) for a in coefficients[-4:]) / scale,
        }

    def _response(self, data: dict) -> tuple[Any, Any, Any, Any]:
        beta = self.beta
        sin_b, cos_b = mpmath.sin(beta), mpmath.cos(beta)
        resonant = beta**3 / 2
        mu_constant, mu_per_h = -data["end"] / (resonant * sin_b), -cos_b / (resonant * sin_b)
        growth = resonant * (sin_b + beta * cos_b)
        return mu_constant, mu_per_h, data["end_slope"] + growth * mu_constant, -beta * sin_b + growth * mu_per_h

    def _solve(self, order: int, release: Any, data: dict) -> None:
        M, beta = self.nodes, self.beta
        p = mpmath.mpf(0) if self.exponent is None else mpmath.mpf(self.exponent.numerator) / self.exponent.denominator
        forcing, cos_integral, sin_integral = data["forcing"], data["cos"], data["sin"]
        resonant = beta**3 / 2
        mu_constant, mu_per_h, slope_constant, slope_per_h = self._response(data)
        mu = mu_constant + mu_per_h * release
        values, slopes, second = [], [], []
        for i in range(M):
            t, c, s = self._tau[i], self._cos[i], self._sin[i]
            particular = (s * cos_integral[i] - c * sin_integral[i]) / beta
            particular_slope = c * cos_integral[i] + s * sin_integral[i]
            value = release * c + resonant * mu * t * s + particular
            values.append(value)
            slopes.append(-release * beta * s + resonant * mu * (s + beta * t * c) + particular_slope)
            second.append(forcing[i] + beta**4 * mu * c - beta * beta * value)
        end_slope = slope_constant + slope_per_h * release
        self._values.append(values)
        self._second.append(second)
        self._ratios.append([y / g for y, g in zip(values, self._gap)])
        # B_n = (1/n) Σ_{k=1}^{n} ((p + 1) k − n) R_k B_{n−k}   (powers of 1 + Σ R_k ε̂^k)
        self._binomial.append(
            [mpmath.fsum(((p + 1) * k - order) * self._ratios[k][i] * self._binomial[order - k][i] for k in range(1, order + 1)) / order for i in range(M)]
            if self.exponent is not None else [mpmath.mpf(0)] * M
        )
        self._mu.append(mu)
        self._slope.append(end_slope)
        value_series, slope_series = self._coefficients(values), self._coefficients(slopes)
        self._series.append((value_series, slope_series))
        scale = max(abs(a) for a in value_series) or mpmath.mpf(1)
        self.tail = max(self.tail, max(abs(a) for a in value_series[-4:]) / scale)

    def _refine(self, order: int) -> None:
        """Double the Chebyshev points and redo orders 1 … order − 1 with their fixed h_n."""
        if 2 * self.nodes > _MAXIMUM_NODES:
            raise ConvergenceError(
                f"the stretched contact arc needs more than {_MAXIMUM_NODES} Chebyshev points "
                f"for {self.digits} digits at order {order} (tail {mpmath.nstr(self.tail, 3)}); "
                "ask for fewer digits or a lower order"
            )
        self.nodes *= 2
        self.counters["restarts"] += 1
        self._reset()
        for n in range(1, order):
            with workdps(self._working):
                self._solve(n, self._turning[n], self._particular(n))

    @locked
    def response(self, order: int) -> tuple[Any, Any, Any, Any]:
        """``(μ_c, μ_h, S_c, S_h)`` with μ_order = μ_c + μ_h h and Y_order'(1) = S_c + S_h h, h = Y_order(0).

        Orders below ``order`` must be fixed (:meth:`fix`); the Chebyshev grid is refined until
        the order's forcing is resolved to the working precision.
        """
        data = _resolved(self, order, lambda data: data["tail"])
        with workdps(self._working):
            return self._response(data)

    @locked
    def fix(self, order: int, turning_value: Any) -> None:
        """Complete Y_order with its turning-point value h = Y_order(0)."""
        if self._pending is None or self._pending[0] != order:
            self.response(order)
        with workdps(self._working):
            value = mpmath.mpf(turning_value)
            self._solve(order, value, self._pending[1])
        self._turning.append(value)
        self._pending = None
        self.counters["orders"] += 1

    @locked
    def series(self, order: int) -> tuple[list[Any], list[Any]]:
        """Chebyshev coefficients (in x = 2v − 1) of Y_order and of dY_order/dτ (fixed orders only)."""
        if order == 0:
            with workdps(self._working):
                return self._coefficients(self._cos), self._coefficients([-self.beta * s for s in self._sin])
        return self._series[order - 1]

    @locked
    def mu(self, order: int) -> Any:
        """μ_order (fixed orders only)."""
        return self._mu[order]

    @locked
    def slope(self, order: int) -> Any:
        """Y_order'(1) (fixed orders only)."""
        return self._slope[order]

    def _ensure(self, order: int) -> None:
        if len(self._mu) <= order:
            raise ValueError(f"order {order} of the stretched arc is not fixed yet")

    @locked
    def float_arc(self, highest: int) -> FloatArc:
        """The float evaluator of Y_0 … Y_highest."""
        self._ensure(highest)
        size = self.nodes
        zeroth_values = np.zeros(size)
        zeroth_slopes = np.zeros(size)
        zeroth = self.series(0)  # Y_0 = cos βτ and its τ-slope −β sin βτ, interpolated on the same grid
        zeroth_values[:] = [float(a) for a in zeroth[0]]
        zeroth_slopes[:] = [float(a) for a in zeroth[1]]
        values = [zeroth_values] + [np.array([float(a) for a in series[0]]) for series in self._series[:highest]]
        slopes = [zeroth_slopes] + [np.array([float(a) for a in series[1]]) for series in self._series[:highest]]
        return FloatArc(self.denominator, values, slopes)


class VectorArc:
    """A contact arc of an N-dof NNM with one fractional-power element (Hertz), on a fixed interval.

    The modal normal form (:mod:`lindstedt.engine.modal`) on the first piece ``s ∈ [0, s*(ε̂))``, where element i
    is in contact, in stretched time ``τ = s/s*``, ``Y_k(τ) = W_k(s* τ)``, ``μ = Ω²/s*²`` (the last piece, contact
    around the far turning point, is the same problem in ``Y = −W``, ``τ = (π − s)/(π − s_L*)``, with the laws
    ``−F(−Y)``: its h_k are all unknown)::

        μ Y_k'' + r_k² Y_k + ε̂ F_k(Y) = 0,    Y_k'(0) = 0,    χ·Y(1) = κ χ_j (the contact point stays at τ = 1),

    ``F_k = g_k ĉ z^p + (the other elements' polynomial pieces on this state)``, ``z = (χ·Y)/χ_j − κ`` the
    element's normalised deformation past its breakpoint, ``χ = a0 B_i`` its coupling, ``g = G_i`` its force
    direction.  ``Y_0 = e_j cos βτ``, ``μ_0 = 1/β²``; order n reads, component by component,

        Y_{n,k}'' + β² r_k² Y_{n,k} = −β² (Σ_{i=1}^{n} μ_i Y_{n−i,k}'' + [F_k]_{n−1}),

    solved by variation of parameters from τ = 0: ``Y_{n,k} = h_k cos(β r_k τ) + P_k(τ)`` plus, for k = j, the
    resonant ``(β³ μ_n/2) τ sin βτ``.  The fractional factor keeps a fixed weight,
    ``z^p = (cos βτ − cos β)^p (1 + Σ R_m ε̂^m)^p``, ``R_m = (χ·Y_m)/(χ_j (cos βτ − cos β))`` (bounded: the contact
    condition makes χ·Y_m(1) = 0), as for one degree of freedom (:class:`StretchedArc`, the N = 1 case, which
    this arc reduces to).  The unknowns of an order — the release values ``h_k`` (k ≠ j; ``h_j`` is prescribed)
    and ``μ_n`` — are fixed by the branch hierarchy with the matching at the arc's end; :meth:`response` gives
    the arc's end values and slopes without them, :meth:`fix` completes the order.

    Representation as for :class:`StretchedArc`: values at Chebyshev points in ``v = (1 − τ)^{1/d}``, cumulative
    Chebyshev integrals, the grid doubled until every component's tail is below the working precision.
    """

    def __init__(self, ratios: Sequence[Any], mode: int, coupling: Sequence[Any], forcing: Sequence[Any],
                 kappa: Any, exponent: Fraction, coefficient: Any, polynomial: Any, digits: int):
        if exponent <= 0 or exponent.denominator == 1:
            raise ValueError("the stretched arc's power law needs a non-integer exponent p > 0")
        self.exponent = exponent
        self.denominator = exponent.denominator
        self.digits = digits
        self.mode = mode
        self._working = digits + _GUARD_DIGITS
        with workdps(self._working):
            self.ratios = [mpmath.mpf(r) for r in ratios]
            self.coupling = [mpmath.mpf(c) for c in coupling]
            self.forcing = [mpmath.mpf(g) for g in forcing]
            self.kappa = mpmath.mpf(kappa)
            self.coefficient = mpmath.mpf(coefficient)
            self.beta = mpmath.acos(self.kappa)
            load, rank_one, elements = polynomial
            self._load = [mpmath.mpf(x) for x in load]
            self._rank_one = [([mpmath.mpf(x) for x in g], [mpmath.mpf(x) for x in c]) for g, c in rank_one]
            self._elements = [([mpmath.mpf(x) for x in g], [mpmath.mpf(x) for x in c],
                               [(m, mpmath.mpf(value)) for m, value in powers]) for g, c, powers in elements]
        self.size = len(self.ratios)
        self._fixed: list[tuple[list[Any], Any]] = []  # (h_k, μ_n) of orders 1, 2, …
        self._pending: tuple[int, list[dict]] | None = None
        self.nodes = _INITIAL_NODES
        self._reset()
        self.counters = {"orders": 0, "restarts": 0}

    def _reset(self) -> None:
        M, d, beta = self.nodes, self.denominator, None
        with workdps(self._working):
            beta = self.beta
            angles = [mpmath.pi * (i + mpmath.mpf(1) / 2) / M for i in range(M)]
            self._v = [(mpmath.cos(angle) + 1) / 2 for angle in angles]
            self._tau = [1 - v**d for v in self._v]
            self._trig = [([mpmath.cos(beta * r * t) for t in self._tau], [mpmath.sin(beta * r * t) for t in self._tau])
                          for r in self.ratios]
            # cos βτ − cos β = 2 sin(β(1 + τ)/2) sin(β v^d/2), without cancellation near τ = 1
            self._gap = [2 * mpmath.sin(beta * (1 + t) / 2) * mpmath.sin(beta * v**d / 2) for t, v in zip(self._tau, self._v)]
            self._weight = [self.coefficient * g**self.exponent for g in self._gap]
            self._jacobian = [d * v ** (d - 1) for v in self._v]
            self._transform = [[mpmath.cos(k * angle) for angle in angles] for k in range(M)]
            self._fast = _FixedPointTransform(self._transform, self._working)
            zero = [mpmath.mpf(0)] * M
            cosine = self._trig[self.mode][0]
            self._values = [[list(cosine) if k == self.mode else list(zero) for k in range(self.size)]]
            self._second = [[[-beta * beta * c for c in cosine] if k == self.mode else list(zero) for k in range(self.size)]]
            self._ratios_r: list[list[Any]] = [[]]
            self._binomial = [[mpmath.mpf(1)] * M]
            self._mu = [1 / (beta * beta)]
            self._powers: dict[tuple[int, int, int], list[Any]] = {}
            self._series: list[list[tuple[list[Any], list[Any]]]] = []
            self.tail = mpmath.mpf(0)

    _coefficients = StretchedArc._coefficients
    _integral_to_end = StretchedArc._integral_to_end

    def _projection(self, vector: Sequence[Any], order: int) -> list[Any]:
        """vector · Y_order at the nodes."""
        values = self._values[order]
        return [mpmath.fsum(w * values[k][i] for k, w in enumerate(vector) if w) for i in range(self.nodes)]

    def _power(self, element: int, power: int, order: int) -> list[Any]:
        """[(c_e · Y)^power]_order at the nodes."""
        key = (element, power, order)
        if key not in self._powers:
            coupling = self._elements[element][1]
            if power == 1:
                result = self._projection(coupling, order)
            else:
                result = [mpmath.mpf(0)] * self.nodes
                for i in range(order + 1):
                    left, right = self._power(element, power - 1, i), self._power(element, 1, order - i)
                    result = [r + x * y for r, x, y in zip(result, left, right)]
            self._powers[key] = result
        return self._powers[key]

    def _law(self, order: int, k: int) -> list[Any]:
        """[F_k(Y)]_order at the nodes."""
        M = self.nodes
        total = [self.forcing[k] * self._weight[i] * self._binomial[order][i] for i in range(M)] if self.forcing[k] \
            else [mpmath.mpf(0)] * M
        if order == 0 and self._load[k]:
            total = [t + self._load[k] for t in total]
        for g, c in self._rank_one:
            if g[k]:
                projection = self._projection(c, order)
                total = [t + g[k] * y for t, y in zip(total, projection)]
        for element, (g, _, powers) in enumerate(self._elements):
            if g[k]:
                for power, value in powers:
                    term = self._power(element, power, order)
                    total = [t + g[k] * value * y for t, y in zip(total, term)]
        return total

    def _particular(self, order: int) -> list[dict]:
        """Per component: the forcing without μ_order, P_k at the nodes and P_k(1), P_k'(1)."""
        beta = self.beta
        out = []
        for k in range(self.size):
            law = self._law(order - 1, k)
            forcing = [-beta * beta * value for value in law]
            for i in range(1, order):
                mu = self._mu[i]
                forcing = [g - beta * beta * mu * y for g, y in zip(forcing, self._second[order - i][k])]
            cosine, sine = self._trig[k]
            integrand_cos = [j * c * g for j, c, g in zip(self._jacobian, cosine, forcing)]
            integrand_sin = [j * s * g for j, s, g in zip(self._jacobian, sine, forcing)]
            cos_integral, cos_total = self._integral_to_end(integrand_cos)
            sin_integral, sin_total = self._integral_to_end(integrand_sin)
            omega = beta * self.ratios[k]
            end_cos, end_sin = mpmath.cos(omega), mpmath.sin(omega)
            coefficients = self._coefficients(integrand_cos)
            scale = max(abs(a) for a in coefficients) or mpmath.mpf(1)
            out.append({
                "forcing": forcing, "cos": cos_integral, "sin": sin_integral,
                "end": (end_sin * cos_total - end_cos * sin_total) / omega,
                "end_slope": end_cos * cos_total + end_sin * sin_total,
                "tail": max(abs(a) for a in coefficients[-4:]) / scale,
            })
        return out

    def _solve(self, order: int, release: list[Any], mu: Any, data: list[dict]) -> None:
        beta = self.beta
        resonant = beta**3 / 2
        values_all, second_all, series = [], [], []
        for k in range(self.size):
            cosine, sine = self._trig[k]
            omega = beta * self.ratios[k]
            item = data[k]
            values, slopes, second = [], [], []
            for i in range(self.nodes):
                c, s, t = cosine[i], sine[i], self._tau[i]
                value = release[k] * c + (s * item["cos"][i] - c * item["sin"][i]) / omega
                slope = -release[k] * omega * s + c * item["cos"][i] + s * item["sin"][i]
                force = item["forcing"][i]
                if k == self.mode:
                    value += resonant * mu * t * s
                    slope += resonant * mu * (s + beta * t * c)
                    force += beta**4 * mu * c
                values.append(value)
                slopes.append(slope)
                second.append(force - omega * omega * value)
            values_all.append(values)
            second_all.append(second)
            value_series = self._coefficients(values)
            series.append((value_series, self._coefficients(slopes)))
            size = max(abs(a) for a in value_series)
            if size:
                self.tail = max(self.tail, max(abs(a) for a in value_series[-4:]) / size)
        self._values.append(values_all)
        self._second.append(second_all)
        p = mpmath.mpf(self.exponent.numerator) / self.exponent.denominator
        chi_j = self.coupling[self.mode]
        deformation = self._projection(self.coupling, order)
        self._ratios_r.append([z / (chi_j * g) for z, g in zip(deformation, self._gap)])
        # B_n = (1/n) Σ_{k=1}^{n} ((p + 1) k − n) R_k B_{n−k}   (powers of 1 + Σ R_k ε̂^k)
        self._binomial.append([mpmath.fsum(((p + 1) * k - order) * self._ratios_r[k][i] * self._binomial[order - k][i]
                                           for k in range(1, order + 1)) / order for i in range(self.nodes)])
        self._mu.append(mu)
        self._series.append(series)

    def _refine(self, order: int) -> None:
        if 2 * self.nodes > _MAXIMUM_NODES:
            raise ConvergenceError(
                f"the stretched contact arc needs more than {_MAXIMUM_NODES} Chebyshev points "
                f"for {self.digits} digits at order {order} (tail {mpmath.nstr(self.tail, 3)}); "
                "ask for fewer digits or a lower order")
        self.nodes *= 2
        self.counters["restarts"] += 1
        self._reset()
        for n, (release, mu) in enumerate(self._fixed, start=1):
            with workdps(self._working):
                self._solve(n, release, mu, self._particular(n))

    @locked
    def response(self, order: int) -> list[tuple[Any, Any]]:
        """Per component, ``(P_k(1), P_k'(1))``: the end value and slope of Y_{order,k} without its unknowns.

        The whole end value is ``P_k(1) + h_k cos(β r_k) [+ (β³ μ/2) sin β for k = j]``, the slope
        ``P_k'(1) − h_k β r_k sin(β r_k) [+ (β³ μ/2)(sin β + β cos β)]`` (:meth:`end_terms`).
        """
        data = _resolved(self, order, lambda data: max(item["tail"] for item in data))
        return [(item["end"], item["end_slope"]) for item in data]

    @locked
    def end_terms(self, k: int) -> tuple[Any, Any, Any, Any]:
        """(∂Y_k(1)/∂h_k, ∂Y_k'(1)/∂h_k, ∂Y_k(1)/∂μ, ∂Y_k'(1)/∂μ) of one order (the same at every order)."""
        with workdps(self._working):
            beta, omega = self.beta, self.beta * self.ratios[k]
            resonant = beta**3 / 2
            mu_value = resonant * mpmath.sin(beta) if k == self.mode else mpmath.mpf(0)
            mu_slope = resonant * (mpmath.sin(beta) + beta * mpmath.cos(beta)) if k == self.mode else mpmath.mpf(0)
            return mpmath.cos(omega), -omega * mpmath.sin(omega), mu_value, mu_slope

    @locked
    def fix(self, order: int, release: Sequence[Any], mu: Any) -> None:
        """Complete Y_order with its release values h_k = Y_{order,k}(0) and μ_order."""
        if self._pending is None or self._pending[0] != order:
            self.response(order)
        with workdps(self._working):
            release = [mpmath.mpf(h) for h in release]
            mu = mpmath.mpf(mu)
            self._solve(order, release, mu, self._pending[1])
        self._fixed.append((release, mu))
        self._pending = None
        self.counters["orders"] += 1

    @locked
    def mu(self, order: int) -> Any:
        """μ_order (fixed orders only)."""
        return self._mu[order]

    @locked
    def release(self, order: int, component: int) -> Any:
        """Y_{order, component}(0) (fixed orders only)."""
        return mpmath.mpf(1 if component == self.mode else 0) if order == 0 else self._fixed[order - 1][0][component]

    @locked
    def float_arcs(self, highest: int) -> tuple[FloatArc, ...]:
        """One float evaluator per component of Y_0 … Y_highest."""
        if len(self._mu) <= highest:
            raise ValueError(f"order {highest} of the stretched arc is not fixed yet")
        arcs = []
        with workdps(self._working):
            for k in range(self.size):
                cosine, sine = self._trig[k]
                omega = self.beta * self.ratios[k]
                zeroth = ([c if k == self.mode else mpmath.mpf(0) for c in cosine],
                          [-omega * s if k == self.mode else mpmath.mpf(0) for s in sine])
                values = [np.array([float(a) for a in self._coefficients(zeroth[0])])]
                slopes = [np.array([float(a) for a in self._coefficients(zeroth[1])])]
                for series in self._series[:highest]:
                    values.append(np.array([float(a) for a in series[k][0]]))
                    slopes.append(np.array([float(a) for a in series[k][1]]))
                arcs.append(FloatArc(self.denominator, values, slopes))
        return tuple(arcs)
