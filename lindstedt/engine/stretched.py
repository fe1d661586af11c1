"""A contact arc on a fixed interval: a fractional power law (Hertz contact and its kin) or an analytic law on the
piece of an orbit that holds a turning point, for N components (N = 1: the 1-dof oscillator).

Problem: a piece of the branch hierarchy (:mod:`lindstedt.engine.branches`) that holds a turning point — the first
piece ``s ∈ [0, s*(ε̂))`` (the release point), or the last one ``(s*(ε̂), π]`` read backwards
(τ = (π − s)/(π − s*), Y = −W, the laws −F(−Y)) — on which one element is in contact:

    Ω² W_k'' + r_k² W_k + ε̂ F_k(W) = 0,
    F_k(W) = g_k ĉ z^p + (load, linear and polynomial elements) + Σ_e g_{e,k} f_e(c_e · W),   z = (χ·W)/χ_j − κ > 0,

with ``χ`` the element's coupling (``z`` its normalised deformation past its breakpoint; z = W − κ for one degree
of freedom, χ = g = (1,)), ``g`` its force direction, a rational exponent ``p = q/d > 0`` that is not an integer
(Hertz: p = 3/2) or no fractional term at all (then d = 1), and the rest of the laws polynomial in projections
``c_e · W`` or analytic, ``f_e(y)`` expanded about its order-zero value y_0 at every point,
``[f(y)]_n = Σ_k f^{(k)}(y_0)/k! [(y − y_0)^k]_n``.
The solution is not analytic at the contact point z = 0 (z ~ s* − s, so W'' ~ (s* − s)^p), and that point moves
with ε̂: Lindstedt coefficients W_n(s) at a fixed s would diverge there from the order where p − n < −1.  So the arc
is mapped to a fixed interval: ``τ = s/s*(ε̂) ∈ [0, 1]``, ``Y(τ) = W(s* τ)``, ``μ = Ω²/s*²``:

    μ Y_k'' + r_k² Y_k + ε̂ F_k(Y) = 0,   Y_k'(0) = 0,   Y(0) = e_j + Σ h_n ε̂^n,   χ·Y(1) = κ χ_j,

and the contact point stays at τ = 1 for every ε̂.  With ``Y = Σ ε̂^n Y_n``, ``Y_0 = e_j cos βτ``, ``β = arccos κ``,
``μ = Σ μ_n ε̂^n``, ``μ_0 = 1/β²``, the vanishing factor stays a fixed weight,

    z^p = (cos βτ − cos β)^p (1 + Σ_{m≥1} R_m ε̂^m)^p,   R_m = (χ·Y_m)/(χ_j (cos βτ − cos β))   (bounded: χ·Y_m(1) = 0),

expanded by the recurrence for powers of a power series.  Order n ≥ 1 reads, component by component,

    Y_{n,k}'' + β² r_k² Y_{n,k} = −β² (Σ_{i=1}^{n} μ_i Y_{n−i,k}'' + [F_k(Y)]_{n−1}),

solved by variation of parameters from τ = 0: ``Y_{n,k} = h_{n,k} cos(β r_k τ) + P_{n,k}(τ)`` plus, for k = j, the
resonant ``(β³ μ_n/2) τ sin βτ``.  The unknowns of an order — the turning-point values ``h_{n,k} = Y_{n,k}(0)``
(at the release point h_{n,j} = w_n is prescribed, at the far turning point every h_{n,k} is unknown) and μ_n — enter
the arc's end values and slopes affinely (:meth:`VectorArc.response`, :meth:`VectorArc.end_terms`); the branch
hierarchy fixes them with the contact condition ``χ·Y_n(1) = 0``, the matching of the neighbouring piece to the arc's
end and ``A_n = [μ ℓ²]_n`` (ℓ the arc's length), and hands them back (:meth:`VectorArc.fix`).

**Representation.**  Every Y_n is analytic in ``v = (1 − τ)^{1/d}`` on [0, 1] (the
powers (1 − τ)^{k/d} that the contact point brings are powers of v, and τ = 1 − v^d),
so it is kept by its values at M Chebyshev points of the first kind in v (interior
points: R_m is 0/0 at v = 0) and the integrals are cumulative Chebyshev integrals in v
(t = 1 − ν^d, dt = −d ν^{d−1} dν), which converge geometrically.  M doubles until
the Chebyshev tail of every component of every Y_n is below the working precision.  Arithmetic is mpmath
at the requested digits plus guard digits (the quotient R_m near v = 0 loses up to
log10(1/v_min^d) of them).
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Any, Callable, Sequence

import gmpy2
import mpmath
import numpy as np
import sympy
from mpmath.libmp import mpf_shift, to_int

from .._errors import ConvergenceError, UnsupportedNonlinearityError
from .._precision import locked, workdps, workprec
from ..algebra.cosine import _pack

__all__ = ["FloatArc", "VectorArc"]

_INITIAL_NODES = 32
_MAXIMUM_NODES = 1024
_GUARD_DIGITS = 20


class _FixedPointTransform:
    """``y = T x`` (or ``Tᵀ x``) for the arc's Chebyshev matrix ``T_{k,i} = cos(k θ_i)``, ``θ_i = π (i + ½)/M``, in
    fixed point, by Bluestein's chirp: with ``w = e^{iπ/(2M)}`` and ``2ki = k² + i² − (k − i)²``,

        (T x)_k = Re(w^{k + k²} Σ_i (x_i w^{i²}) w^{−(k−i)²}),   (Tᵀ x)_i = Re(w^{i²} Σ_k (x_k w^{k + k²}) w^{−(i−k)²}),

    so each is one complex convolution with the chirp ``w^{−m²}`` — three integer convolutions (Karatsuba), each one
    GMP product of Kronecker-packed vectors (:func:`~lindstedt.algebra.cosine._pack`).  x is scaled to integers
    relative to its largest entry and the chirp's values to 2^bits; the rounding adds ~4 M 2^-bits of the largest
    entry (the guard bits cover M ≤ 1024 four times over).  Only the 4M values of ``w^e`` are computed, not the M²
    entries of T.  Measured at 50 digits against the integer matrix product it replaces (numpy object arrays, itself
    5x faster than ``mpmath.fsum``), M = 32 / 128 / 512: a transform 0.25 / 1.0 / 4.8 ms against 0.24 / 2.0 / 27 ms,
    the set-up 2.4 / 7 / 47 ms against 7 / 104 / 1860 ms (the M² mpmath cosines of T, most of a grid refinement);
    the same values to the working precision (7e-49 relative at M = 512).
    """

    def __init__(self, size: int, digits: int):
        self.size = size
        self.bits = int(digits * 3.33) + 28
        period = 4 * size  # w^e depends on e mod 4M
        with workprec(self.bits + 20):
            angle = mpmath.pi / (2 * size)
            table = [(int(mpmath.nint(mpmath.ldexp(mpmath.cos(angle * e), self.bits))),
                      int(mpmath.nint(mpmath.ldexp(mpmath.sin(angle * e), self.bits)))) for e in range(period)]
        square = [(k * k) % period for k in range(size)]
        self._square = [table[e] for e in square]  # w^{k²}
        self._square_linear = [table[(e + k) % period] for k, e in enumerate(square)]  # w^{k + k²}
        # the chirp w^{−m²}, m = −(M−1) … M−1, as the real, imaginary and summed parts of the Karatsuba products
        chirp = [table[(-(m * m)) % period] for m in range(-(size - 1), size)]
        # digits of the packed convolutions: |g| < 2^(bits+1), |chirp| < 2^(bits+1), M terms, a sign
        self._width = 2 * self.bits + size.bit_length() + 6
        self._chirp = [_pack(part, self._width) for part in ([c for c, _ in chirp], [c_s for _, c_s in chirp],
                                                              [c + c_s for c, c_s in chirp])]
        half = 1 << (self._width - 1)
        self._half, self._lift = half, gmpy2.pack([half] * (3 * size - 2), self._width)  # signed digits read back

    def apply(self, values: Sequence[Any], transposed: bool = False) -> list[Any]:
        size, bits = self.size, self.bits
        largest = max((abs(v) for v in values), default=0)
        if not largest:
            return [mpmath.mpf(0)] * len(values)
        shift = bits - mpmath.frexp(largest)[1]
        x = [to_int(mpf_shift(mpmath.mpf(v)._mpf_, shift), "n") for v in values]
        before, after = (self._square_linear, self._square) if transposed else (self._square, self._square_linear)
        real = [(v * c) >> bits for v, (c, _) in zip(x, before)]
        imaginary = [(v * s_) >> bits for v, (_, s_) in zip(x, before)]
        summed = [r + i for r, i in zip(real, imaginary)]
        width, half = self._width, self._half
        products = []
        for g, chirp in zip((real, imaginary, summed), self._chirp):
            digits = gmpy2.unpack(_pack(g, width) * chirp + self._lift, width)
            products.append([digit - half for digit in digits[size - 1:2 * size - 1]])
        first, second, third = products
        result = []
        for k in range(size):
            z_real, z_imaginary = first[k] - second[k], third[k] - first[k] - second[k]
            c, s_ = after[k]
            result.append(mpmath.mpf((int(c * z_real - s_ * z_imaginary), -2 * bits - shift)))
        return result


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


class VectorArc:
    """Order-by-order solution on a stretched contact arc of N components (module docstring), lazy and memoised.

    Parameters
    ----------
    ratios : sequence of numbers
        r_k, the components' frequencies relative to the mode's (r_j = 1).
    mode : int
        j: Y_0 = e_j cos βτ.
    coupling : sequence of numbers
        χ: the contact element's deformation is χ·Y, past its breakpoint by z = (χ·Y)/χ_j − κ.
    forcing : sequence of numbers
        g, the direction of the fractional force g ĉ z^p.
    kappa : number
        κ (|κ| < 1): the arc ends where χ·Y = κ χ_j.
    exponent : Fraction or None
        p = q/d > 0, not an integer; None: no fractional term (an analytic law alone, d = 1).
    coefficient : number
        ĉ.
    polynomial : (load, rank_one, elements)
        The rest of the law on the arc as in :class:`~lindstedt.engine.branches.ContactState`: a constant load,
        pairs (g, c) adding g (c·Y), and (g, c, ((m, c_m), …)) adding g Σ_m c_m (c·Y)^m.
    digits : int
        Decimal digits wanted.
    analytic : sequence of (g, c, (expression, symbol)), optional
        Analytic laws g f(c·Y), ``f`` a sympy expression of ``symbol``, expanded about f's order-zero argument.

    Examples
    --------
    u'' + u + ε u_+^{3/2} released at u = 1: one component, contact point κ = 0; the order's μ_1 from the contact
    condition Y_1(1) = 0 with the release value h_1 = 0.

    >>> from fractions import Fraction
    >>> arc = VectorArc((1,), 0, (1,), (1,), 0, Fraction(3, 2), 1, ((0,), (), ()), 20)
    >>> ((end, end_slope),) = arc.response(1)
    >>> per_h, _, per_mu, _ = arc.end_terms(0)
    >>> arc.fix(1, [0], -end / per_mu)
    >>> mpmath.nstr(arc.mu(1), 10)
    '0.3709618659'
    """

    def __init__(self, ratios: Sequence[Any], mode: int, coupling: Sequence[Any], forcing: Sequence[Any],
                 kappa: Any, exponent: Fraction | None, coefficient: Any, polynomial: Any, digits: int,
                 analytic: Sequence[tuple[Sequence[Any], Sequence[Any], tuple[Any, Any]]] = ()):
        if exponent is not None and (exponent <= 0 or exponent.denominator == 1):
            raise ValueError("the stretched arc's power law needs a non-integer exponent p > 0")
        self.exponent = exponent
        self.denominator = 1 if exponent is None else exponent.denominator
        self.digits = digits
        self.mode = mode
        self._working = digits + _GUARD_DIGITS
        with workdps(self._working):
            self.ratios = [mpmath.mpf(r) for r in ratios]
            self.coupling = [mpmath.mpf(c) for c in coupling]
            self.forcing = [mpmath.mpf(g) for g in forcing]
            self.kappa = mpmath.mpf(kappa)
            self.coefficient = mpmath.mpf(coefficient) if exponent is not None else mpmath.mpf(0)
            self.beta = mpmath.acos(self.kappa)
            load, rank_one, elements = polynomial
            self._load = [mpmath.mpf(x) for x in load]
            self._rank_one = [([mpmath.mpf(x) for x in g], [mpmath.mpf(x) for x in c]) for g, c in rank_one]
            self._elements = [([mpmath.mpf(x) for x in g], [mpmath.mpf(x) for x in c],
                               [(m, mpmath.mpf(value)) for m, value in powers]) for g, c, powers in elements]
            self._analytic = [([mpmath.mpf(x) for x in g], [mpmath.mpf(x) for x in c], law) for g, c, law in analytic]
        self._analytic_terms: list[list[Callable[[Any], Any]]] = [[] for _ in self._analytic]  # f^{(k)}/k!
        self.size = len(self.ratios)
        self._fixed: list[tuple[list[Any], Any]] = []  # (h_k, μ_n) of orders 1, 2, …
        self._pending: tuple[int, list[dict]] | None = None
        # the grid resolves cos(β r_k τ) of the stiffest component, d·β r_k oscillations in v near τ = 0: start at
        # the power of two below d·β·max r_k (chains of 40 and 200 dof needed 256 and 512 nodes for 40 and 135 —
        # starting at 32 cost three and four restarts, each redoing the grid's trigonometry and the fixed orders)
        stiffest = float(self.beta) * max(abs(float(r)) for r in self.ratios) * self.denominator
        self.nodes = max(_INITIAL_NODES, min(_MAXIMUM_NODES, 1 << max(0, int(math.log2(max(stiffest, 1.0))))))
        self._reset()
        self.counters = {"orders": 0, "restarts": 0}

    # -- grid -------------------------------------------------------------------------------------------
    def _reset(self) -> None:
        M, d = self.nodes, self.denominator
        with workdps(self._working):
            beta = self.beta
            angles = [mpmath.pi * (i + mpmath.mpf(1) / 2) / M for i in range(M)]
            self._v = [(mpmath.cos(angle) + 1) / 2 for angle in angles]
            self._tau = [1 - v**d for v in self._v]
            self._trig = [([mpmath.cos(beta * r * t) for t in self._tau], [mpmath.sin(beta * r * t) for t in self._tau])
                          for r in self.ratios]
            # cos βτ − cos β = 2 sin(β(1 + τ)/2) sin(β v^d/2), without cancellation near τ = 1
            self._gap = [2 * mpmath.sin(beta * (1 + t) / 2) * mpmath.sin(beta * v**d / 2) for t, v in zip(self._tau, self._v)]
            self._weight = [self.coefficient * g**self.exponent for g in self._gap] if self.exponent is not None \
                else [mpmath.mpf(0)] * M
            self._jacobian = [d * v ** (d - 1) for v in self._v]  # −dt/dν
            self._fast = _FixedPointTransform(M, self._working)
            zero = [mpmath.mpf(0)] * M
            cosine = self._trig[self.mode][0]
            self._values = [[list(cosine) if k == self.mode else list(zero) for k in range(self.size)]]  # Y_n at the nodes
            self._second = [[[-beta * beta * c for c in cosine] if k == self.mode else list(zero) for k in range(self.size)]]
            self._ratios_r: list[list[Any]] = [[]]  # R_n (n ≥ 1)
            self._binomial = [[mpmath.mpf(1)] * M]  # B_n of (1 + Σ R ε̂)^p
            self._mu = [1 / (beta * beta)]
            self._powers: dict[tuple, list[Any]] = {}  # [(c·Y)^m]_n, [(y − y_0)^m]_n at the nodes
            self._taylor: dict[tuple[int, int], list[Any]] = {}  # f^{(k)}(y_0)/k! of an analytic law at the nodes
            self._series: list[list[tuple[list[Any], list[Any]]]] = []  # Chebyshev coefficients of Y_{n,k}, Y_{n,k}'
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

    # -- the law on the arc -----------------------------------------------------------------------------
    def _projection(self, vector: Sequence[Any], order: int) -> list[Any]:
        """vector · Y_order at the nodes (memoised per vector and order: every component's law reads the same
        projections — recomputing them per component made the N-dof arc O(N²) per order)."""
        key = ("projection", id(vector), order)
        if key not in self._powers:
            values = self._values[order]
            self._powers[key] = [mpmath.fsum(w * values[k][i] for k, w in enumerate(vector) if w) for i in range(self.nodes)]
        return self._powers[key]

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

    def _taylor_values(self, element: int, k: int) -> list[Any]:
        """f^{(k)}(y_0)/k! at the nodes for the analytic law ``element``, y_0 = c · Y_0."""
        key = (element, k)
        if key not in self._taylor:
            _, coupling, (expression, symbol) = self._analytic[element]
            terms = self._analytic_terms[element]
            while len(terms) <= k:
                derivative = sympy.diff(expression, symbol, len(terms))
                scale = sympy.Integer(math.factorial(len(terms)))
                terms.append(sympy.lambdify(symbol, derivative / scale, modules="mpmath"))
            values = [mpmath.mpf(terms[k](y)) for y in self._projection(coupling, 0)]
            if not all(mpmath.isfinite(value) for value in values):
                raise UnsupportedNonlinearityError(
                    f"the law {expression} is not analytic on the contact arc (derivative {k} is not finite there)")
            self._taylor[key] = values
        return self._taylor[key]

    def _deviation(self, element: int, power: int, order: int) -> list[Any]:
        """[(y − y_0)^power]_order at the nodes for the analytic law ``element``, y = c · Y (1 ≤ power ≤ order)."""
        key = ("deviation", element, power, order)
        if key not in self._powers:
            if power == 1:
                result = self._projection(self._analytic[element][1], order)
            else:
                result = [mpmath.mpf(0)] * self.nodes
                for j in range(1, order - power + 2):
                    left, right = self._deviation(element, 1, j), self._deviation(element, power - 1, order - j)
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
        for element, (g, _, _) in enumerate(self._analytic):
            if g[k]:
                if order == 0:
                    total = [t + g[k] * f for t, f in zip(total, self._taylor_values(element, 0))]
                for power in range(1, order + 1):
                    term = self._deviation(element, power, order)
                    total = [t + g[k] * f * y for t, f, y in zip(total, self._taylor_values(element, power), term)]
        return total

    # -- the hierarchy ----------------------------------------------------------------------------------
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
        chi_j = self.coupling[self.mode]
        deformation = self._projection(self.coupling, order)
        self._ratios_r.append([z / (chi_j * g) for z, g in zip(deformation, self._gap)])
        if self.exponent is None:
            self._binomial.append([mpmath.mpf(0)] * self.nodes)
        else:
            p = mpmath.mpf(self.exponent.numerator) / self.exponent.denominator
            # B_n = (1/n) Σ_{k=1}^{n} ((p + 1) k − n) R_k B_{n−k}   (powers of 1 + Σ R_k ε̂^k)
            self._binomial.append([mpmath.fsum(((p + 1) * k - order) * self._ratios_r[k][i] * self._binomial[order - k][i]
                                               for k in range(1, order + 1)) / order for i in range(self.nodes)])
        self._mu.append(mu)
        self._series.append(series)

    def _refine(self, order: int) -> None:
        """Double the Chebyshev points and redo the fixed orders with their h_k and μ_n."""
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
        if order != len(self._mu):
            raise ValueError(f"order {order} of the stretched arc is not the next one ({len(self._mu)})")
        tolerance = mpmath.mpf(10) ** (-(self.digits + 2))
        while True:  # the grid doubles until this order's forcing and the fixed orders are resolved
            with workdps(self._working):
                data = self._particular(order)
            if max(max(item["tail"] for item in data), self.tail) <= tolerance:
                break
            self._refine(order)
        self._pending = (order, data)
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
    def series(self, order: int, component: int) -> tuple[list[Any], list[Any]]:
        """Chebyshev coefficients (in x = 2v − 1) of Y_{order,component} and of its τ-derivative (fixed orders only)."""
        if len(self._mu) <= order:
            raise ValueError(f"order {order} of the stretched arc is not fixed yet")
        if order:
            return self._series[order - 1][component]
        with workdps(self._working):  # Y_0 = e_j cos βτ and its τ-slope, interpolated on the same grid
            on = component == self.mode
            cosine, sine = self._trig[component]
            omega = self.beta * self.ratios[component]
            return (self._coefficients([c if on else mpmath.mpf(0) for c in cosine]),
                    self._coefficients([-omega * s if on else mpmath.mpf(0) for s in sine]))

    @locked
    def float_arcs(self, highest: int) -> tuple[FloatArc, ...]:
        """One float evaluator per component of Y_0 … Y_highest."""
        arcs = []
        for k in range(self.size):
            series = [self.series(n, k) for n in range(highest + 1)]
            arcs.append(FloatArc(self.denominator, [np.array([float(a) for a in values]) for values, _ in series],
                                 [np.array([float(a) for a in slopes]) for _, slopes in series]))
        return tuple(arcs)
