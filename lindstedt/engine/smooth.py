"""The Lindstedt–Poincaré (strained coordinates) hierarchy for smooth f.

Problem: ``u'' + ω0² u + ε f(u) = 0``, ``u(0) = a0``, ``u'(0) = 0``.  With the
strained time ``s = ω t`` and ``u(t) = v(s)`` the equation becomes

    ω² v'' + ω0² v + ε f(v) = 0.

**Normal form.**  Writing ``v = a0 w``, ``ω = ω0 Ω`` gives
``Ω² w'' + w + ε f̃(w) = 0`` with ``f̃(w) = f(a0 w) / (a0 ω0²)``.  For a
polynomial ``f̃(w) = Σ_m q_m w^m`` one coefficient ``q_L`` is factored out:
``ε̂ = ε q_L`` and ``f̂ = f̃ / q_L`` has coefficients ``ρ_m = q_m / q_L``.
Every quantity of order k is then homogeneous of degree k in the ``q_m``, so

    ω_k = ω0 q_L^k Ω_k,   α_k = ω0² q_L^k A_k,   v_k = a0 q_L^k w_k,

where ``Ω_k, A_k, w_k`` depend only on the ratios ``ρ_m``.  Rational ratios
are exact rationals; other ratios (symbols, floats, surds) become generators of
a polynomial ring ``QQ[ρ...]``: the arithmetic stays exact and fast, and the
true values are substituted only when a result is printed.

**Hierarchy.**  With ``Ω² = Σ A_k ε̂^k`` (``A_0 = 1``), ``w = Σ ε̂^k w_k``
(``w_0 = cos s``) and ``F_n = [f̂(w)]_n`` the ε̂ⁿ coefficient of f̂(w):

    w_k'' + w_k = −F_{k−1} − Σ_{i=1}^{k} A_i w_{k−i}''.

The ``cos s`` (secular) coefficient of the right-hand side must vanish:

    A_k = [F_{k−1}]_1 − Σ_{i=1}^{k−1} A_i [w_{k−i}]_1.

``F_n`` comes from the Taylor expansion of f̂ about the operating point
``w_0 = cos s``: ``F_n = Σ_m g_m [δ^m]_n``, ``g_m = f̂^{(m)}(cos s)/m!``,
``δ = w − w_0``.  For polynomial f the ``g_m`` are exact cosine polynomials;
for analytic f they are Chebyshev (cosine) coefficients computed to the working
precision in a ``RealField``.  Work is lazy: ``A_k`` needs ``w_1 … w_{k−1}``
and only the ``cos s`` coefficient of ``F_{k−1}``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable, ClassVar

import mpmath
import sympy
from sympy import QQ, RealField

from ..algebra.cosine import CosineSeries, solve_harmonic_oscillator, sum_series
from .._errors import UnsupportedNonlinearityError
from ..problems.oscillator import DISPLACEMENT, Oscillator
from .branches import FloatBranches
from .orders import LazyOrders

__all__ = ["MAX_ORDER", "NormalForm", "SmoothHierarchy", "normal_form"]

MAX_ORDER = 100
_MAX_CHEBYSHEV_NODES = 512
_NORMALISED = sympy.Symbol("w", real=True)


@dataclass(frozen=True)
class NormalForm:
    """The problem in normalised variables ``Ω² w'' + w + ε̂ f̂(w) = 0``.

    Attributes
    ----------
    domain : sympy domain
        Coefficient domain of the hierarchy (``QQ``, ``QQ[ρ…]`` or ``RealField``).
    epsilon_scale : sympy.Expr
        ``q_L`` with ``ε̂ = q_L ε``.
    generator_values : tuple of (Symbol, Expr)
        Ring generators and the expressions they stand for.
    taylor_series : callable m -> CosineSeries or None
        ``g_m = f̂^{(m)}(cos s) / m!``; ``None`` beyond the degree of a polynomial.
    prune_tolerance : float or None
        Coefficients below this are dropped (float domains only).
    """

    domain: Any
    epsilon_scale: sympy.Expr
    generator_values: tuple[tuple[sympy.Symbol, sympy.Expr], ...]
    taylor_series: Callable[[int], CosineSeries | None]
    prune_tolerance: float | None
    degree: int | None
    release: tuple = ()  # (w_1(0), w_2(0), …): the release u(0) = a0 + Σ ε^n a_n in normalised units a_n/(a0 q_L^n)
    # What a result reads of every normal form (the piecewise one has contact boundaries instead):
    regime: ClassVar[str] = "smooth"
    validity_exponent: ClassVar[sympy.Integer] = sympy.Integer(-1)
    boundaries: ClassVar[tuple] = ()
    amplitude_sign: ClassVar[int | None] = None  # no side of the release point is assumed

    def to_expr(self, element: Any) -> sympy.Expr:
        """Domain element -> sympy expression with the generators substituted."""
        expression = self.domain.to_sympy(element)
        if self.generator_values:
            expression = expression.subs(dict(self.generator_values))
        return expression

    def scaled_expr(self, element: Any, power: int, prefactor: sympy.Expr) -> sympy.Expr:
        """``prefactor · q_L^power · element`` in the problem's symbols (expanded when ratios are generators)."""
        expression = prefactor * self.epsilon_scale**power * self.to_expr(element)
        return sympy.expand(expression) if self.generator_values else expression


def _cosine_powers(domain: Any, highest: int) -> list[CosineSeries]:
    powers = [CosineSeries.constant(domain, domain.one)]
    cosine = CosineSeries.cosine(domain)
    for _ in range(highest):
        powers.append(powers[-1] * cosine)
    return powers


def _polynomial_normal_form(problem: Oscillator) -> NormalForm:
    amplitude, omega0 = problem.a0, problem.omega0
    scaled = sympy.expand(problem.nonlinearity.subs(DISPLACEMENT, amplitude * _NORMALISED) / (amplitude * omega0**2))
    polynomial = sympy.Poly(scaled, _NORMALISED)
    terms = {monomial[0]: coefficient for monomial, coefficient in polynomial.terms() if coefficient != 0}
    degree = max(terms)
    lead = terms[degree]
    generators: list[tuple[sympy.Symbol, sympy.Expr]] = []
    ratios: dict[int, Any] = {}
    for power, coefficient in terms.items():
        ratio = sympy.cancel(coefficient / lead)
        if ratio.is_Rational:
            ratios[power] = ratio
        else:
            generator = sympy.Dummy(f"rho{power}")
            generators.append((generator, ratio))
            ratios[power] = generator
    # u(0) = a0 (1 + Σ ε̂^n w_n(0)) with ε̂ = q_L ε
    releases = [sympy.cancel(shift / (amplitude * lead**n)) for n, shift in enumerate(problem.release_shifts, 1)]
    release_generators: list[sympy.Expr] = []
    for n, release in enumerate(releases, 1):
        if release.is_Rational:
            release_generators.append(release)
        else:
            generator = sympy.Dummy(f"w{n}0")
            generators.append((generator, release))
            release_generators.append(generator)
    domain = QQ if not generators else QQ[tuple(symbol for symbol, _ in generators)]
    ratio_elements = {power: domain.convert(value) if value.is_Rational else domain.from_sympy(value) for power, value in ratios.items()}
    powers = _cosine_powers(domain, degree)
    cache: dict[int, CosineSeries | None] = {}

    def taylor_series(order: int) -> CosineSeries | None:
        # g_m = Σ_j ρ_j binom(j, m) cos^{j-m}(s)
        if order > degree:
            return None
        if order not in cache:
            cache[order] = sum_series(
                (
                    powers[power - order].scale(element * domain.convert(math.comb(power, order)))
                    for power, element in ratio_elements.items()
                    if power >= order
                ),
                domain,
            )
        return cache[order]

    release_elements = tuple(domain.convert(value) if value.is_Rational else domain.from_sympy(value) for value in release_generators)
    return NormalForm(domain, lead, tuple(generators), taylor_series, None, degree, release_elements)


def _analytic_normal_form(problem: Oscillator, digits: int) -> NormalForm:
    if problem.free_symbols:
        names = ", ".join(sorted(str(symbol) for symbol in problem.free_symbols))
        raise UnsupportedNonlinearityError(
            f"f = {problem.f} is not a polynomial in u, so its expansion is computed numerically "
            f"and needs numeric values for {names}; give them (a0=..., omega0=..., params={{...}})"
        )
    amplitude, omega0 = problem.a0, problem.omega0
    scaled = problem.nonlinearity.subs(DISPLACEMENT, amplitude * _NORMALISED) / (amplitude * omega0**2)
    _check_continuous_on_orbit(scaled, problem)
    domain = RealField(dps=digits)
    tolerance = 10.0 ** (-(digits + 2))
    cache: dict[int, CosineSeries] = {}
    derivative_expression = [scaled]

    def taylor_series(order: int) -> CosineSeries:
        if order in cache:
            return cache[order]
        while len(derivative_expression) <= order:
            derivative_expression.append(sympy.diff(derivative_expression[-1], _NORMALISED))
        function = sympy.lambdify(_NORMALISED, derivative_expression[order] / math.factorial(order), modules="mpmath")
        cache[order] = _chebyshev_cosine_series(function, domain, digits, tolerance, problem)
        return cache[order]

    release = tuple(domain.from_sympy(sympy.Float(shift / amplitude, digits + 10)) for shift in problem.release_shifts)
    return NormalForm(domain, sympy.Integer(1), (), taylor_series, tolerance, None, release)


def _check_continuous_on_orbit(scaled: sympy.Expr, problem: Oscillator) -> None:
    orbit = sympy.Interval(-1, 1)
    try:
        domain = sympy.calculus.util.continuous_domain(scaled, _NORMALISED, orbit)
    except (NotImplementedError, TypeError, ValueError):  # sympy cannot decide: the numeric checks decide
        return
    if domain != orbit:
        raise UnsupportedNonlinearityError(
            f"f = {problem.f} is not continuous on the whole orbit |u| <= |a0| = {abs(problem.a0)}; "
            "the smooth hierarchy needs f analytic on [-|a0|, |a0|]"
        )


def _chebyshev_cosine_series(function: Callable, domain: Any, digits: int, tolerance: float, problem: Oscillator) -> CosineSeries:
    """Cosine coefficients of ``function(cos s)`` (= Chebyshev coefficients) to ``digits``."""
    with mpmath.workdps(digits + 10):
        nodes = 32
        while nodes <= _MAX_CHEBYSHEV_NODES:
            angles = [mpmath.pi * (j + mpmath.mpf(1) / 2) / nodes for j in range(nodes)]
            try:
                samples = [mpmath.mpf(function(mpmath.cos(angle))) for angle in angles]
            except (ZeroDivisionError, ValueError, TypeError) as error:
                raise UnsupportedNonlinearityError(
                    f"f = {problem.f} cannot be evaluated on the orbit |u| <= |a0| ({error}); "
                    "the smooth hierarchy needs f analytic on [-|a0|, |a0|]"
                ) from None
            if not all(mpmath.isfinite(sample) for sample in samples):
                raise UnsupportedNonlinearityError(
                    f"f = {problem.f} is not finite on the orbit |u| <= |a0|; "
                    "the smooth hierarchy needs f analytic on [-|a0|, |a0|]"
                )
            coefficients = []
            for harmonic in range(nodes):
                total = mpmath.fsum(sample * mpmath.cos(harmonic * angle) for sample, angle in zip(samples, angles))
                coefficients.append(total * (1 if harmonic else mpmath.mpf(1) / 2) * 2 / nodes)
            scale = max(abs(c) for c in coefficients) or mpmath.mpf(1)
            tail = max(abs(c) for c in coefficients[-nodes // 4 :])
            if tail <= tolerance * scale:
                # Independent check off the sampling grid (catches poles between nodes).
                for point in (mpmath.mpf(1), mpmath.mpf(-1), mpmath.mpf("0.3183"), mpmath.mpf("-0.7071")):
                    exact = mpmath.mpf(function(point))
                    value = _clenshaw(coefficients, point)
                    if not mpmath.isfinite(exact) or abs(value - exact) > 1000 * tolerance * max(scale, abs(exact)):
                        break
                else:
                    kept = {n: domain.from_sympy(sympy.Float(c, digits + 10)) for n, c in enumerate(coefficients) if abs(c) > tolerance * scale}
                    return CosineSeries(domain, kept)
            nodes *= 2
    raise UnsupportedNonlinearityError(
        f"the Chebyshev coefficients of f = {problem.f} on the orbit do not converge to 1e-{digits} "
        f"within {_MAX_CHEBYSHEV_NODES} harmonics; f is not analytic enough on [-|a0|, |a0|] for this precision"
    )


def _clenshaw(coefficients: list, point: Any) -> Any:
    """Σ c_n T_n(point) by Clenshaw's recurrence."""
    following = current = mpmath.mpf(0)
    for coefficient in reversed(coefficients[1:]):
        current, following = 2 * point * current - following + coefficient, current
    return point * current - following + coefficients[0]


def normal_form(problem: Oscillator, digits: int = 30) -> NormalForm:
    """Build the normalised hierarchy data for a smooth problem.

    Raises
    ------
    UnsupportedNonlinearityError
        For non-smooth f (Max, Heaviside, Abs, ...) or non-polynomial f with symbols.
    """
    if problem.is_non_smooth:
        raise UnsupportedNonlinearityError(
            f"f = {problem.f} is not smooth; the Taylor hierarchy handles polynomial or analytic f, "
            "and unilateral springs a*Max(0, u - b) are handled by the piecewise-linear method"
        )
    if problem.is_polynomial:
        return _polynomial_normal_form(problem)
    return _analytic_normal_form(problem, digits)


class SmoothHierarchy(LazyOrders):
    """Lazy, cached hierarchy ``A_k``, ``w_k`` of the normal form.

    Examples
    --------
    >>> from lindstedt.problems.oscillator import Oscillator
    >>> hierarchy = SmoothHierarchy(normal_form(Oscillator("u**3", a0=1, omega0=1)), "initial")
    >>> print(hierarchy.squared_frequency(1))
    3/4
    """

    def __init__(self, form: NormalForm, normalization: str):
        self.form = form
        self.normalization = normalization
        domain = form.domain
        self._domain = domain
        self._waveforms: list[CosineSeries] = [CosineSeries.cosine(domain)]
        self._squared: list[Any] = [domain.one]
        self._frequencies: list[Any] = [domain.one]
        self._delta_powers: dict[tuple[int, int], CosineSeries] = {}
        self._forcing: dict[int, CosineSeries] = {}
        self._forcing_secular: dict[int, Any] = {}
        self.counters = {"products": 0, "secular_projections": 0}

    def _prune(self, series: CosineSeries) -> CosineSeries:
        if self.form.prune_tolerance is None:
            return series
        return series.pruned(self.form.prune_tolerance)

    def _multiply(self, left: CosineSeries, right: CosineSeries) -> CosineSeries:
        self.counters["products"] += 1
        return self._prune(left * right)

    def delta_power(self, power: int, order: int) -> CosineSeries:
        """ε̂^order coefficient of δ^power, δ = Σ_{j≥1} ε̂^j w_j."""
        key = (power, order)
        if key in self._delta_powers:
            return self._delta_powers[key]
        if order < power:
            result = CosineSeries(self._domain)
        elif power == 1:
            result = self.waveform(order)
        else:
            result = sum_series(
                (self._multiply(self.waveform(j), self.delta_power(power - 1, order - j)) for j in range(1, order - power + 2)),
                self._domain,
            )
            result = self._prune(result)
        self._delta_powers[key] = result
        return result

    def _taylor_terms(self, order: int):
        power = 0
        while power <= order:
            series = self.form.taylor_series(power)
            if series is None:
                return
            if power == 0:
                if order == 0:
                    yield series, CosineSeries.constant(self._domain, self._domain.one)
            else:
                yield series, self.delta_power(power, order)
            power += 1

    def forcing(self, order: int) -> CosineSeries:
        """``F_order``: the ε̂^order coefficient of f̂(w) as a cosine series."""
        if order not in self._forcing:
            self._forcing[order] = self._prune(
                sum_series((self._multiply(g, delta) for g, delta in self._taylor_terms(order)), self._domain)
            )
        return self._forcing[order]

    def forcing_secular(self, order: int) -> Any:
        """``[F_order]_1`` without forming F_order when it is not cached."""
        if order in self._forcing:
            return self._forcing[order].coefficient(1)
        if order not in self._forcing_secular:
            total = self._domain.zero
            for g, delta in self._taylor_terms(order):
                self.counters["secular_projections"] += 1
                total = total + g.product_coefficient(delta, 1)
            self._forcing_secular[order] = total
        return self._forcing_secular[order]

    def _solve_order(self, k: int) -> None:
        """A_k = [F_{k−1}]_1 − Σ_{i<k} A_i [w_{k−i}]_1 (the waveforms follow lazily in :meth:`waveform`)."""
        value = self.forcing_secular(k - 1)
        for i in range(1, k):
            value = value - self._squared[i] * self.waveform(k - i).coefficient(1)
        self._squared.append(value)

    def float_branches(self, highest: int, to_float: Callable[[Any], float] = float) -> FloatBranches:
        """w_0 … w_highest as one float branch each (one piece, no contact boundary)."""
        terms = tuple(
            (([(harmonic, 0, 0, to_float(value)) for harmonic, value in self.waveform(k).coefficients.items()],),)
            for k in range(highest + 1)
        )
        return FloatBranches(terms, ((),) * (highest + 1))

    def waveform(self, order: int) -> CosineSeries:
        """``w_order`` (normalised correction of order ``order``)."""
        while len(self._waveforms) <= order:
            k = len(self._waveforms)
            self.squared_frequency(k)
            right_hand_side = -self.forcing(k - 1)
            for i in range(1, k + 1):
                right_hand_side = right_hand_side - self._waveforms[k - i].second_derivative().scale(self._squared[i])
            # The secular coefficient vanishes by the choice of A_k: exactly in exact domains
            # (solve_harmonic_oscillator checks it), to rounding in float domains (removed here).
            if self.form.prune_tolerance is not None:
                right_hand_side = right_hand_side - CosineSeries.cosine(self._domain, 1, right_hand_side.coefficient(1))
            if self.normalization == "initial":
                release = self.form.release[k - 1] if k <= len(self.form.release) else self._domain.zero
                solution = solve_harmonic_oscillator(right_hand_side, self._domain.one, value_at_zero=release)
            else:
                solution = solve_harmonic_oscillator(right_hand_side, self._domain.one, first_harmonic=self._domain.zero)
            self._waveforms.append(self._prune(solution))
        return self._waveforms[order]
