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
for analytic f they are Chebyshev (cosine) coefficients in a ``RealField`` of
the requested digits plus guard digits.  Those of ``f̂`` decay like ``ρ^(−n)``,
``ρ`` the parameter of the Bernstein ellipse (foci ±1) through the nearest
complex singularity of ``f̂`` (poles and branch points, located symbolically
where sympy can, else from the decay of the computed coefficients): the number
of harmonics is predicted from ρ and the digits, ``f̂`` is sampled once, and
every ``g_m`` follows by the Chebyshev derivative recurrence, checked off the
grid against ``mpmath.taylor``.  A singularity on the orbit (ρ = 1) is an
:class:`~lindstedt.UnsupportedNonlinearityError`.  As for polynomials a scale is
factored out, ``ε̂ = q ε`` with q a power of two near the size of ``f̂``, so that
the hierarchy's absolute pruning tolerance is a relative one.  Work is lazy:
``A_k`` needs ``w_1 … w_{k−1}`` and only the ``cos s`` coefficient of ``F_{k−1}``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable, ClassVar

import mpmath
import numpy
import sympy
from sympy import QQ, RealField

from ..algebra.cosine import CosineSeries, linear_combination, solve_harmonic_oscillator, sum_of_products, sum_series
from .._errors import UnsupportedNonlinearityError
from ..problems.oscillator import DISPLACEMENT, Oscillator
from .float_branches import FloatBranches
from .orders import LazyOrders
from .._precision import locked, workdps

__all__ = ["MAX_ORDER", "NormalForm", "SmoothHierarchy", "normal_form"]

MAX_ORDER = 100
_MAX_CHEBYSHEV_NODES = 4096  # harmonics of g_m; beyond, the hierarchy's products of such series take minutes
_GUARD_DIGITS = 10
_DERIVATIVE_BATCH = 8  # g_0 … g_8 from one sampling (orders up to 9); more are computed on demand
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
    # Guard digits: the hierarchy's sums cancel (1/(1 − u) − 1 − u at a0 = 0.99, precision 30, order 6:
    # 1e-25 relative without them, 9e-32 with 10, at the same run time).
    domain = RealField(dps=digits + _GUARD_DIGITS)
    tolerance = 10.0 ** (-(digits + 2))
    expansion = _ChebyshevTaylor(scaled, digits, problem)
    # ε̂ = q ε with q a power of two near the size of f̂ on the orbit (the polynomial form factors out
    # q_L alike): the hierarchy prunes at an absolute tolerance, relative only if its terms are O(1)
    # (unscaled, sin(u) − u at a0 = 0.1, precision 15, had ω_6 off by 13 %).
    size = max(abs(c) for c in expansion.coefficients(0))
    exponent = _binary_exponent(size)
    cache: dict[int, CosineSeries] = {}

    def taylor_series(order: int) -> CosineSeries:
        if order not in cache:
            coefficients = expansion.coefficients(order)
            # relative to g_m, or absolute in the normalised units where g_m is below f̂ itself
            threshold = tolerance * max(max((abs(c) for c in coefficients), default=0), size)
            kept = {
                n: domain.from_sympy(sympy.Float(mpmath.ldexp(c, -exponent), digits + _GUARD_DIGITS + 5))
                for n, c in enumerate(coefficients)
                if abs(c) > threshold
            }
            cache[order] = CosineSeries(domain, kept)
        return cache[order]

    scale = sympy.Integer(2) ** exponent
    release = tuple(domain.from_sympy(sympy.Float(shift / (amplitude * scale**n), digits + 10)) for n, shift in enumerate(problem.release_shifts, 1))
    return NormalForm(domain, scale, (), taylor_series, tolerance, None, release)


def _binary_exponent(size: Any) -> int:
    """The integer p with 2^p nearest to ``size`` on a log scale (0 for size 0)."""
    return int(mpmath.nint(mpmath.log(size, 2))) if size else 0


def _check_continuous_on_orbit(scaled: sympy.Expr, problem: Oscillator) -> None:
    orbit = sympy.Interval(-1, 1)
    try:
        domain = sympy.calculus.util.continuous_domain(scaled, _NORMALISED, orbit)
    except (NotImplementedError, TypeError, ValueError):  # sympy cannot decide: the numeric checks decide
        return
    if domain != orbit:
        raise UnsupportedNonlinearityError(
            f"f = {problem.f} is not continuous on the whole orbit |u| <= |a0| = {abs(problem.a0)}; "
            f"{_SUPPORTED}"
        )


_SUPPORTED = (
    "the smooth hierarchy needs f polynomial, or analytic on the orbit [-|a0|, |a0|] "
    "(every pole or branch point of f off it); unilateral springs and jumps (Max, Heaviside, sign, "
    "piecewise-linear Piecewise) go to the piecewise-linear method"
)

# Functions whose singular points are known: the argument values where they have a pole or a branch
# point ...
_SINGULAR_VALUES: dict[Any, tuple[Any, ...]] = {
    sympy.log: (0,),
    sympy.atan: (sympy.I, -sympy.I),
    sympy.acot: (sympy.I, -sympy.I, 0),
    sympy.asinh: (sympy.I, -sympy.I),
    sympy.asin: (1, -1),
    sympy.acos: (1, -1),
    sympy.acosh: (1, -1),
    sympy.atanh: (1, -1),
    sympy.acoth: (1, -1, 0),
}
# ... a periodic family offset + k·period ...
_PERIODIC_SINGULARITIES: dict[Any, tuple[Any, Any]] = {
    sympy.tan: (sympy.pi / 2, sympy.pi),
    sympy.sec: (sympy.pi / 2, sympy.pi),
    sympy.cot: (0, sympy.pi),
    sympy.csc: (0, sympy.pi),
    sympy.tanh: (sympy.I * sympy.pi / 2, sympy.I * sympy.pi),
    sympy.sech: (sympy.I * sympy.pi / 2, sympy.I * sympy.pi),
    sympy.coth: (0, sympy.I * sympy.pi),
    sympy.csch: (0, sympy.I * sympy.pi),
}
# ... or none at all (entire).  Any other function of u leaves the singularities unknown.
_ENTIRE = (sympy.exp, sympy.sin, sympy.cos, sympy.sinh, sympy.cosh, sympy.erf, sympy.erfc, sympy.erfi)
_PROBES = ("1", "0.3183", "-0.7071")  # points w of the orbit off every sampling grid, and its end
_PERIODS_SEARCHED = 2  # k = -2 … 2 of a periodic family; a nearer one missed is caught by the decay estimate


def _singular_points(scaled: sympy.Expr) -> list[complex] | None:
    """Candidate complex singularities of ``scaled(w)``: poles and branch points; ``None`` if unknown.

    sympy's ``singularities`` is not used: it misses branch points (``sqrt(w + 2)``
    and ``atan(w)`` give the empty set) and returns infinite image sets for ``tan``.
    """
    equations: list[tuple[sympy.Expr, Any]] = []
    for node in sympy.preorder_traversal(scaled):
        if not node.has(_NORMALISED):
            continue
        if isinstance(node, sympy.Pow):
            base, exponent = node.args
            if base.has(_NORMALISED) and not (exponent.is_Integer and exponent >= 0):
                equations.append((base, 0))  # pole or branch point where the base vanishes
        elif isinstance(node, sympy.Function):
            function = node.func
            if function in _SINGULAR_VALUES:
                equations.extend((node.args[0], value) for value in _SINGULAR_VALUES[function])
            elif function in _PERIODIC_SINGULARITIES:
                offset, period = _PERIODIC_SINGULARITIES[function]
                equations.extend((node.args[0], offset + k * period) for k in range(-_PERIODS_SEARCHED, _PERIODS_SEARCHED + 1))
            elif function not in _ENTIRE:
                return None
    points: list[complex] = []
    for argument, value in equations:
        numerator, _ = sympy.fraction(sympy.together(argument - value))
        numerator = sympy.expand(numerator)
        if not numerator.is_polynomial(_NORMALISED):
            return None
        polynomial = sympy.Poly(numerator, _NORMALISED)
        if polynomial.degree() > 0:
            points.extend(complex(root) for root in polynomial.nroots(n=15))
    return points


def _bernstein_parameter(point: complex) -> float:
    """ρ of the Bernstein ellipse (foci ±1) through ``point``: ρ + 1/ρ = |point − 1| + |point + 1|."""
    half_sum = (abs(point - 1) + abs(point + 1)) / 2
    return half_sum + math.sqrt(max(half_sum * half_sum - 1, 0.0))


def _nodes_needed(rho: float, digits: float, derivatives: int) -> int:
    """Smallest N with ``N^derivatives · ρ^(−N) ≤ 10^(−digits)``.

    The Chebyshev coefficients of f decay like ρ^(−n); those of the interpolant's
    m-th derivative are off by about ``N^m`` times the aliased tail (measured:
    ``1/(1 − 0.99 w)``, N = 768, m = 5: relative error 5e-35 where
    ``ρ^(−N) N^m = 1e-33``).
    """
    logarithm = math.log(rho)
    nodes = 16.0
    for _ in range(50):
        nodes = (digits * math.log(10) + derivatives * math.log(nodes)) / logarithm
    return math.ceil(nodes)


class _ChebyshevTaylor:
    """``g_m = f̂^{(m)}(cos s)/m!`` as cosine (Chebyshev) coefficients, m = 0 … a batch, from one sampling of f̂.

    Representations measured (CPU seconds, one core, 30 digits):

    * chosen — one sampling of f̂ at N first-kind Chebyshev nodes, one DCT, and the
      Chebyshev derivative recurrence ``c'_{n−1} = c'_{n+1} + 2n c_n`` for every g_m:
      g_0 … g_8 in 0.24 s for ``log(1 + u) − u`` at a0 = 0.95 (N = 454) and 0.60 s for
      ``1/(1 − u)`` at a0 = 0.99 (N = 1066); on ``1/(1 − 0.99 w)``, m ≤ 5, N = 768 the
      recurrence's g_5 is right to 5e-35 relative;
    * the former sampling of every derivative, one ``mpmath.fsum`` of ``mpmath.cos`` terms
      per coefficient, doubling to 512 nodes: 2.8 s per g_m (log case), and 512 nodes
      were too few for the pole at 1.0101 a0;
    * sampling each lambdified sympy derivative with the same fast transform: 1.1 s
      for m ≤ 5 at N = 768 (the recurrence: 0.21 s), and the derivatives swell with m;
    * Taylor coefficients at every node by ``mpmath.taylor``: 0.7–3 ms per node, so
      0.7–3 s at N = 1024 before one transform per m;
    * the power series Σ_j c_j binom(j, m) w^{j−m} with exact cosine powers: it converges
      in the disc |w| < R, not in the Bernstein ellipse, so J terms with R^(−J) ≈ 10^(−35)
      at O(J²) cost — g_0 alone 1.8 s for the log case (J = 1431), and J ≈ 8000 for the pole.

    N is predicted from ρ of the nearest singularity (:func:`_singular_points`) and the
    digits wanted, then checked a posteriori: the decay of the computed coefficients
    gives ρ again (this also covers f whose singularities are not known symbolically),
    and the interpolant's derivatives are compared off the grid with ``mpmath.taylor``.
    The transform is a matrix product of fixed-point integers (numpy object arrays;
    neither mpmath nor numpy has a multiprecision FFT): 0.09 s at N = 512, 0.24 s at
    N = 1024, 70 digits.
    """

    def __init__(self, scaled: sympy.Expr, digits: int, problem: Oscillator):
        self._function = sympy.lambdify(_NORMALISED, scaled, modules="mpmath")
        self._digits = digits
        self._problem = problem
        points = _singular_points(scaled)
        self._singularity: tuple[complex, float] | None = None
        if points:
            nearest = min(points, key=_bernstein_parameter)
            self._singularity = (nearest, _bernstein_parameter(nearest))
            if self._singularity[1] <= 1 + 1e-12:
                raise UnsupportedNonlinearityError(
                    f"f = {problem.f} has a singularity (pole or branch point) at u = {self._describe(nearest)}, "
                    f"on the orbit |u| <= |a0| = {abs(problem.a0)}; {_SUPPORTED}"
                )
        self._highest = -1
        self._series: list[list[mpmath.mpf]] = []
        self._cancellation: dict[int, int] = {}

    def _describe(self, point: complex) -> str:
        value = complex(sympy.N(self._problem.a0)) * point
        return f"{value.real:.6g}" if abs(value.imag) < 1e-12 * max(abs(value), 1) else f"{value:.6g}"

    @locked
    def coefficients(self, order: int) -> list[mpmath.mpf]:
        """Chebyshev coefficients of ``g_order`` (at the working precision)."""
        if order > self._highest:
            self._compute(max(order, 2 * self._highest, _DERIVATIVE_BATCH))
        return self._series[order]

    def _compute(self, highest: int) -> None:
        wanted = self._digits + 5  # guard digits on every g_m, relative to its largest coefficient
        rho = self._singularity[1] if self._singularity else math.inf
        nodes = 32 if math.isinf(rho) else max(32, math.ceil(1.1 * _nodes_needed(rho, wanted, highest)) + 16)
        for _ in range(12):
            if nodes > _MAX_CHEBYSHEV_NODES:
                break
            working = wanted + math.ceil(2 * highest * math.log10(nodes)) + 10  # the recurrence amplifies rounding ~N^(2m)
            with workdps(working):
                coefficients = self._transform(nodes, working)
                needed = self._nodes_from_decay(coefficients, rho, wanted, highest, working)
                if needed <= nodes:
                    series = [coefficients]
                    for m in range(1, highest + 1):
                        series.append(_chebyshev_derivative(series[-1], m))
                    if self._matches_off_grid(series, working):
                        with workdps(self._digits + _GUARD_DIGITS + 5):
                            self._series = [[+c for c in s] for s in series]
                        self._highest = highest
                        return
                    needed = 2 * nodes
            nodes = max(needed, 3 * nodes // 2)
        where = ""
        if self._singularity:
            point, rho = self._singularity
            where = f" (its nearest singularity, at u = {self._describe(point)}, gives ρ = {rho:.6g})"
        raise UnsupportedNonlinearityError(
            f"the Chebyshev coefficients of f = {self._problem.f} on the orbit need more than {_MAX_CHEBYSHEV_NODES} "
            f"harmonics for 1e-{self._digits}{where}: f is too close to a singularity on [-|a0|, |a0|] for this "
            f"precision; lower precision= or |a0|, or {_SUPPORTED.split('; ')[0]}"
        )

    def _transform(self, nodes: int, working: int) -> list[mpmath.mpf]:
        """Chebyshev coefficients of the interpolant of f̂ at ``nodes`` first-kind nodes (a DCT-II in fixed point)."""
        samples = []
        sampling = working + self._cancelled_digits(working)
        for j in range(nodes):
            try:
                with workdps(sampling):
                    value = +mpmath.mpf(self._function(mpmath.cospi(mpmath.mpf(2 * j + 1) / (2 * nodes))))
            except (ZeroDivisionError, ValueError, TypeError) as error:
                raise UnsupportedNonlinearityError(
                    f"f = {self._problem.f} cannot be evaluated on the orbit |u| <= |a0| ({error}); {_SUPPORTED}"
                ) from None
            if not mpmath.isfinite(value):
                raise UnsupportedNonlinearityError(f"f = {self._problem.f} is not finite on the orbit |u| <= |a0|; {_SUPPORTED}")
            samples.append(value)
        # Integers scaled to the largest sample: the transform is then relative to |f̂|, whatever its size.
        bits = int(working * 3.33) + 16
        shift = bits - mpmath.frexp(max(abs(value) for value in samples))[1]
        quarter = 4 * nodes
        table = numpy.array([int(mpmath.nint(mpmath.ldexp(mpmath.cospi(mpmath.mpf(k) / (2 * nodes)), bits))) for k in range(quarter)], dtype=object)
        values = numpy.array([int(mpmath.nint(mpmath.ldexp(value, shift))) for value in samples], dtype=object)
        odd = 2 * numpy.arange(nodes) + 1
        coefficients = []
        for harmonic in range(nodes):
            total = mpmath.ldexp(mpmath.mpf(int(values.dot(table[(harmonic * odd) % quarter]))), 1 - bits - shift) / nodes
            coefficients.append(total / 2 if harmonic == 0 else total)
        return coefficients

    def _cancelled_digits(self, working: int) -> int:
        """Digits that evaluating f̂ loses to cancellation (``sin(u) − u`` at a0 = 1e-12 loses 25), probed at three points.

        f̂ is evaluated at ``working``, twice and three times as many digits.  Where the
        last two share no digits f̂ vanishes (to rounding); if it does at all three points
        it is taken to be zero on the orbit, e.g. ``sin(u)**2 + cos(u)**2 − 1``.
        """
        if working not in self._cancellation:
            lost, vanishing = 0, 0
            for point in _PROBES:
                low, high, check = (self._value_at(point, digits) for digits in (working, 2 * working, 3 * working))
                if high == 0 or abs(check - high) > abs(check) / 10**5:
                    vanishing += 1
                elif low != high:
                    lost = max(lost, working + int(mpmath.ceil(mpmath.log10(abs(low - high) / abs(high)))))
            if vanishing == len(_PROBES):
                raise UnsupportedNonlinearityError(
                    f"f = {self._problem.f} evaluates to rounding noise on the orbit (u = a0·w, w = {', '.join(_PROBES)}, "
                    f"even with {3 * working} digits): is it identically zero there? Simplify f before expanding it"
                )
            self._cancellation[working] = lost + 5 if lost else 0
        return self._cancellation[working]

    def _value_at(self, point: str, digits: int) -> mpmath.mpf:
        with workdps(digits):
            try:
                return mpmath.mpf(self._function(mpmath.mpf(point)))
            except (ZeroDivisionError, ValueError, TypeError) as error:
                raise UnsupportedNonlinearityError(
                    f"f = {self._problem.f} cannot be evaluated on the orbit at u = {point}·a0 ({error}); {_SUPPORTED}"
                ) from None

    def _nodes_from_decay(self, coefficients: list, rho: float, wanted: int, highest: int, working: int) -> int:
        """Nodes needed according to the computed coefficients' own decay (and the known ρ, if smaller)."""
        nodes = len(coefficients)
        scale = max(abs(c) for c in coefficients)
        if scale == 0:
            return nodes
        width = max(4, nodes // 32)

        def envelope(start: int) -> mpmath.mpf:
            return max(abs(c) for c in coefficients[start : start + width]) / scale

        early, late = nodes // 8, nodes // 2 - width
        floor = mpmath.mpf(10) ** (-(working - 5))
        late_value = envelope(late)
        if late_value <= floor:  # decayed to rounding (the working digits cover the recurrence's amplification)
            return nodes
        decay = float(mpmath.root(envelope(early) / late_value, late - early))
        if decay <= 1 + 1e-6:
            return 2 * nodes
        return _nodes_needed(min(decay, rho), wanted, highest)

    def _matches_off_grid(self, series: list[list], working: int) -> bool:
        """Every g_m against ``mpmath.taylor`` of f̂ at points off the sampling grid (and at the ends)."""
        tolerance = mpmath.mpf(10) ** (-(self._digits + 2))
        size = max(abs(c) for c in series[0])  # g_m far below f̂ need only be accurate relative to f̂
        for point in (mpmath.mpf(-1), *(mpmath.mpf(probe) for probe in _PROBES)):
            with workdps(working + self._cancelled_digits(working)):
                try:
                    derivatives = mpmath.taylor(self._function, point, len(series) - 1)
                except (ZeroDivisionError, ValueError, TypeError):  # f̂ not analytic around the point: refine, then fail
                    return False
            for coefficients, exact in zip(series, derivatives):
                scale = max(max(abs(c) for c in coefficients), abs(exact), size)
                if not abs(_clenshaw(coefficients, point) - exact) <= tolerance * scale:
                    return False
        return True


def _chebyshev_derivative(coefficients: list, order: int) -> list:
    """Chebyshev coefficients of ``p'/order`` for ``p = Σ c_n T_n`` (``c'_{n−1} = c'_{n+1} + 2n c_n``)."""
    size = len(coefficients)
    derivative = [mpmath.mpf(0)] * (size + 1)
    for n in range(size - 1, 0, -1):
        derivative[n - 1] = derivative[n + 1] + 2 * n * coefficients[n]
    derivative[0] /= 2
    return [c / order for c in derivative[: max(size - 1, 1)]]


def _clenshaw(coefficients: list, point: Any) -> Any:
    """Σ c_n T_n(point) by Clenshaw's recurrence."""
    following = current = mpmath.mpf(0)
    for coefficient in reversed(coefficients[1:]):
        current, following = 2 * point * current - following + coefficient, current
    return point * current - following + coefficients[0]


@locked
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
        self._curvatures: list[CosineSeries] = [self._waveforms[0].second_derivative()]  # w_k''
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

    def _sum_of_products(self, pairs: list[tuple[CosineSeries, CosineSeries]]) -> CosineSeries:
        self.counters["products"] += len(pairs)
        return self._prune(sum_of_products(pairs, self._domain))

    @locked
    def delta_power(self, power: int, order: int) -> CosineSeries:
        """ε̂^order coefficient of δ^power, δ = Σ_{j≥1} ε̂^j w_j."""
        key = (power, order)
        if key in self._delta_powers:
            return self._delta_powers[key]
        if order < power:
            result = CosineSeries(self._domain)
        elif power == 1:
            result = self.waveform(order)
        elif power == 2:  # Σ_{i+j=order} w_i w_j: each unordered pair once, doubled
            pairs = [(self.waveform(j), self.waveform(order - j)) for j in range(1, (order + 1) // 2)]
            result = self._sum_of_products(pairs).scale(self._domain.convert(2))
            if order % 2 == 0:
                result = self._prune(result + self._sum_of_products([(self.waveform(order // 2),) * 2]))
        else:
            result = self._sum_of_products(
                [(self.waveform(j), self.delta_power(power - 1, order - j)) for j in range(1, order - power + 2)]
            )
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

    @locked
    def forcing(self, order: int) -> CosineSeries:
        """``F_order``: the ε̂^order coefficient of f̂(w) as a cosine series."""
        if order not in self._forcing:
            self._forcing[order] = self._sum_of_products(list(self._taylor_terms(order)))
        return self._forcing[order]

    @locked
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

    @locked
    def float_branches(self, highest: int, to_float: Callable[[Any], float] = float) -> FloatBranches:
        """w_0 … w_highest as one float branch each (one piece, no contact boundary)."""
        terms = tuple(
            (([(harmonic, 0, 0, to_float(value)) for harmonic, value in self.waveform(k).coefficients.items()],),)
            for k in range(highest + 1)
        )
        return FloatBranches(terms, ((),) * (highest + 1))

    @locked
    def waveform(self, order: int) -> CosineSeries:
        """``w_order`` (normalised correction of order ``order``)."""
        while len(self._waveforms) <= order:
            k = len(self._waveforms)
            self.squared_frequency(k)
            # −F_{k−1} − Σ_i A_i w''_{k−i}: the w'' cached, the sum one exact integer sum over QQ
            curvature = linear_combination(self._squared[1:k + 1], self._curvatures[::-1], self._domain)
            right_hand_side = -self.forcing(k - 1) - curvature
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
            self._curvatures.append(self._waveforms[-1].second_derivative())
        return self._waveforms[order]
