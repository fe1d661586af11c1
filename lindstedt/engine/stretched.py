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
the Chebyshev tail of every component of every Y_n is below the working precision.  Arithmetic is at the
requested digits plus guard digits (the quotient R_m near v = 0 loses up to log10(1/v_min^d) of them): node
values are numpy object arrays of gmpy2 ``mpfr`` at mpmath's working precision (correctly rounded like mpmath's
mpf, a tenth of the cost through mpmath's Python layer), the transforms fixed-point integers
(:class:`_FixedPointTransform`, two vectors a transform).  Only what later orders read is kept per order: the
projections ``c·Y_n`` of the laws' vectors, ``Y_n''`` and ``Y_n'`` per component at the nodes, and Y_n's node
values until their Chebyshev series are wanted (then the series).  Measured on the reduced 1000-dof chain (13
components, 1024 points, order 2): the arc 0.70 s CPU where the mpmath arc took 3.9 s; a 200-dof chain's arc
(200 components, 512 points) 5.7 s and 83 MB where it took 28 s and 266 MB.
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Any, Callable, Sequence

import gmpy2
import mpmath
import numpy as np
import sympy

from .._errors import ConvergenceError, UnsupportedNonlinearityError
from .._mpfr import mpf_of_mpfr, mpfr_of_mpf
from .._precision import locked, workdps
from ..algebra.cosine import _pack

__all__ = ["FloatArc", "VectorArc"]

_INITIAL_NODES = 32
_MAXIMUM_NODES = 4096
_GUARD_DIGITS = 20
_TWO = gmpy2.mpfr(2)


def _mpfr(value: Any) -> Any:
    """An mpmath number (or anything mpmath reads, at mpmath's working precision) as a gmpy2 mpfr of the current
    gmpy2 precision, exactly when the mantissa fits."""
    return mpfr_of_mpf(mpmath.mpf(value))


def _array(values: Sequence[Any]) -> np.ndarray:
    """A one-dimensional object array (``np.array`` of gmpy2 numbers is 70 times slower: it probes each for a
    sequence)."""
    return np.fromiter(values, dtype=object, count=len(values))


class _FixedPointTransform:
    """The arc's Chebyshev matrix ``T_{k,i} = cos(k θ_i)``, ``θ_i = π (i + ½)/M`` (a DCT-II; Tᵀ a DCT-III), applied
    to two real vectors at once in fixed point: Makhoul's reordering makes T x the real part of a length-M DFT,

        (T x)_k = Re(e^{−iπk/(2M)} V_k),   V = DFT(v),   v = (x_0, x_2, …, x_{M−2}, x_{M−1}, …, x_3, x_1),

    and Tᵀ its inverse (``v = IDFT(e^{iπk/(2M)} (b_k − i b_{M−k}))/2``, b_M = 0, unshuffled), so two real vectors are the
    real and imaginary parts of one complex DFT, split by ``V_k = (Z_k + conj Z_{−k})/2``.  The DFT is Bluestein's
    chirp, ``nk = (n² + k² − (k − n)²)/2``:

        Z_k = W^{k²} Σ_n (u_n W^{n²}) W^{−(k−n)²},   W = e^{−iπ/M},

    one complex convolution with the chirp ``W^{−m²}`` — three integer convolutions (Karatsuba), each one GMP product
    of Kronecker-packed vectors (:func:`~lindstedt.algebra.cosine._pack`).  Each input vector is scaled to integers
    relative to its own largest entry (the split is linear) and the roots of unity to 2^bits; the rounding adds
    ~8 M 2^-bits of that entry (the guard bits cover it with 15 bits to spare).  Only the 4M values of ``e^{−iπe/(2M)}``
    are computed, not the M² entries of T.  The per-node work is numpy object arrays of gmpy2 integers; in and out
    go gmpy2 mpfr at the caller's gmpy2 precision.  Measured at 61 digits, M = 1024 (a loaded 2-core machine, CPU
    time): two transforms 9–10 ms, one as a length-M Bluestein DCT 7–9.5 ms; ~4 ms are the three GMP products.
    """

    def __init__(self, size: int, digits: int):
        if size % 2:
            raise ValueError("the fixed-point Chebyshev transform needs an even number of points")
        self.size = size
        # rounding ~8 M 2^-bits of an entry (M = 2^m): m + 3 bits, and 15 bits of margin (28 guard bits up to M = 1024)
        bits = self.bits = int(digits * 3.33) + max(28, size.bit_length() + 17)
        period = 4 * size  # e^{−iπe/(2M)} depends on e mod 4M
        with gmpy2.context(precision=bits + 20):
            angle = gmpy2.const_pi() / (2 * size)
            table = []
            for e in range(period):
                sine, cosine = gmpy2.sin_cos(angle * e)
                table.append((gmpy2.mpz(cosine * _TWO**bits), -gmpy2.mpz(sine * _TWO**bits)))
        self._square = tuple(_array(part) for part in zip(*[table[(2 * k * k) % period] for k in range(size)]))  # W^{k²}
        self._twist = tuple(_array(part) for part in zip(*table[:size]))  # e^{−iπk/(2M)}
        # P_k = e^{−iπk/(2M)} W^{k²} and Q_k = e^{−iπk/(2M)} conj W^{k²}
        self._post = tuple(tuple(_array(part) for part in zip(*[table[(k + sign * 2 * k * k) % period] for k in range(size)]))
                           for sign in (1, -1))
        # the chirp W^{−m²}, m = −(M−1) … M−1, as the real, imaginary and summed parts of the Karatsuba products
        chirp = [table[(-2 * m * m) % period] for m in range(-(size - 1), size)]
        # digits of the packed convolutions: |g| < 2^(bits+2), |chirp| < 2^(bits+1), M terms, a sign
        self._width = 2 * bits + size.bit_length() + 6
        width = self._width
        self._chirp = [_pack(part, width) for part in ([c for c, _ in chirp], [c_s for _, c_s in chirp],
                                                        [c + c_s for c, c_s in chirp])]
        # the data go in lifted by 2^(bits+3) (|g| < 2^(bits+2): one unsigned pack), their digits come back lifted
        # by 2^(width−1) (unsigned for gmpy2.unpack); one constant per chirp part takes the first lift out and puts
        # the second in: lift − 2^(bits+3) Σ_i chirp_{k−i}
        self._offset = 1 << (bits + 3)
        ones = gmpy2.pack([self._offset] * size, width)
        self._half = 1 << (width - 1)
        lift = gmpy2.pack([self._half] * (3 * size - 2), width)
        self._correction = [lift - ones * part for part in self._chirp]
        self._negated = (-np.arange(size)) % size  # −k mod M
        self._reversed = np.concatenate([[0], np.arange(size - 1, 0, -1)])  # M − k, with b_M = 0 read at k = 0

    def _integers(self, values: np.ndarray | None) -> tuple[np.ndarray, int]:
        """values · 2^shift rounded to integers, the largest near 2^bits."""
        if values is None:
            return np.zeros(self.size, dtype=object), 0
        largest = max(abs(v) for v in values)
        if not largest:
            return np.zeros(self.size, dtype=object), 0
        shift = self.bits - gmpy2.get_exp(largest)
        scale = _TWO**shift  # a power of two: exact
        return _array([gmpy2.mpz(v * scale) for v in values]), shift

    def _convolution(self, real: np.ndarray, imaginary: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
        """z_k = Σ_n (u_n W^{n²}) W^{−(k−n)²} · 2^bits for u = real + i imaginary (integers; Z_k = W^{k²} z_k)."""
        size, bits = self.size, self.bits
        c, s_ = self._square
        if imaginary is None:
            g_real, g_imaginary = (real * c) >> bits, (real * s_) >> bits
        else:
            g_real = (real * c - imaginary * s_) >> bits
            g_imaginary = (real * s_ + imaginary * c) >> bits
        width, offset = self._width, self._offset
        products = []
        for g, chirp, correction in zip((g_real, g_imaginary, g_real + g_imaginary), self._chirp, self._correction):
            digits = gmpy2.unpack(gmpy2.pack(list(g + offset), width) * chirp + correction, width)
            products.append(_array(digits[size - 1:2 * size - 1]))  # each lifted by 2^(width−1)
        first, second, third = products
        return first - second, third - first - second + self._half

    def forward(self, a: np.ndarray, b: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray | None]:
        """(T a, T b)."""
        (x, shift_a), (y, shift_b) = self._integers(a), self._integers(b)
        order = lambda z: np.concatenate([z[0::2], z[1::2][::-1]])  # noqa: E731  Makhoul's v
        z_real, z_imaginary = self._convolution(order(x), None if b is None else order(y))
        mirrored_real, mirrored_imaginary = z_real[self._negated], z_imaginary[self._negated]
        (p_real, p_imaginary), (q_real, q_imaginary) = self._post
        # 2V_k = Z_k + conj Z_{−k}, 2Y_k = (Z_k − conj Z_{−k})/i with Z_k = W^{k²} z_k, and (T a)_k = Re(e^{−iπk/(2M)} V_k):
        # with P_k = e^{−iπk/(2M)} W^{k²}, Q_k = e^{−iπk/(2M)} conj W^{k²},
        # 2(T a)_k = Re(P_k z_k + Q_k conj z_{−k}),   2(T b)_k = Im(P_k z_k − Q_k conj z_{−k})
        scale = -2 * self.bits - 1
        a_out = p_real * z_real - p_imaginary * z_imaginary + q_real * mirrored_real + q_imaginary * mirrored_imaginary
        result_a = a_out * _TWO ** (scale - shift_a)
        if b is None:
            return result_a, None
        b_out = p_real * z_imaginary + p_imaginary * z_real - q_imaginary * mirrored_real + q_real * mirrored_imaginary
        return result_a, b_out * _TWO ** (scale - shift_b)

    def transposed(self, a: np.ndarray, b: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray | None]:
        """(Tᵀ a, Tᵀ b)."""
        (x, shift_a), (y, shift_b) = self._integers(a), self._integers(b)
        twist_real, twist_imaginary = self._twist  # e^{−iπk/(2M)}: the inverse takes its conjugate
        reversed_ = self._reversed

        def hermitian(values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            """2H_k = e^{iπk/(2M)} (b_k − i b_{M−k}) (k ≥ 1), 2H_0 = 2 b_0."""
            mirror = values[reversed_]
            real = (twist_real * values - twist_imaginary * mirror) >> self.bits
            imaginary = (-twist_imaginary * values - twist_real * mirror) >> self.bits
            real[0], imaginary[0] = 2 * values[0], 0
            return real, imaginary

        (p, q) = hermitian(x)
        if b is None:
            z_real, z_imaginary = self._convolution(p, -q)
        else:
            r, s_ = hermitian(y)
            z_real, z_imaginary = self._convolution(p - s_, -(q + r))
        # G = H_a + i H_b; IDFT(G) = conj DFT(conj G) = v_a + i v_b (both real), DFT(conj G)_k = W^{k²} z_k
        c, s_ = self._square
        size, scale = self.size, -2 * self.bits - 1

        def unshuffle(v: np.ndarray) -> np.ndarray:
            out = np.empty(size, dtype=object)
            out[0::2], out[1::2] = v[:size // 2], v[size // 2:][::-1]
            return out

        result_a = unshuffle(c * z_real - s_ * z_imaginary) * _TWO ** (scale - shift_a)
        if b is None:
            return result_a, None
        return result_a, unshuffle(-(s_ * z_real + c * z_imaginary)) * _TWO ** (scale - shift_b)


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
        The rest of the law on the arc as in :class:`~lindstedt.engine.branch_system.ContactState`: a constant load,
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
            self._precision = mpmath.mp.prec
            self.ratios = [mpmath.mpf(r) for r in ratios]
            self.kappa = mpmath.mpf(kappa)
            self.beta = mpmath.acos(self.kappa)
            with self._context():
                def vector(values: Sequence[Any]) -> np.ndarray:
                    return _array([_mpfr(x) for x in values])

                self._beta = _mpfr(self.beta)
                self._omega = [self._beta * _mpfr(r) for r in self.ratios]  # β r_k
                self.coupling = vector(coupling)
                self.forcing = vector(forcing)
                self.coefficient = _mpfr(coefficient) if exponent is not None else gmpy2.mpfr(0)
                load, rank_one, elements = polynomial
                self._load = vector(load)
                self._rank_one = [(vector(g), vector(c)) for g, c in rank_one]
                self._elements = [(vector(g), vector(c), [(m, _mpfr(value)) for m, value in powers])
                                  for g, c, powers in elements]
                self._analytic = [(vector(g), vector(c), law) for g, c, law in analytic]
        # every projection c·Y_n the laws read (memoised per vector and order when Y_n is fixed; the node values
        # of the components themselves are not kept)
        self._vectors = [self.coupling] + [c for _, c in self._rank_one] + [c for _, c, _ in self._elements] \
            + [c for _, c, _ in self._analytic]
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

    def _context(self) -> Any:
        """gmpy2 arithmetic at mpmath's working precision (the node arithmetic: numpy object arrays of mpfr)."""
        return gmpy2.context(precision=self._precision)

    # -- grid -------------------------------------------------------------------------------------------
    def _reset(self) -> None:
        M, d = self.nodes, self.denominator
        with self._context():
            beta = self._beta
            pi = gmpy2.const_pi()
            self._v = _array([(gmpy2.cos(pi * (2 * i + 1) / (2 * M)) + 1) / 2 for i in range(M)])
            power = self._v**d  # 1 − τ
            self._tau = 1 - power
            self._trig = []
            for omega in self._omega:
                pairs = [gmpy2.sin_cos(omega * t) for t in self._tau]
                self._trig.append((_array([c for _, c in pairs]), _array([s for s, _ in pairs])))
            # cos βτ − cos β = 2 sin(β(1 + τ)/2) sin(β v^d/2), without cancellation near τ = 1
            self._gap = _array([2 * gmpy2.sin(beta * (1 + t) / 2) * gmpy2.sin(beta * w / 2)
                                for t, w in zip(self._tau, power)])
            self._zero = np.full(M, gmpy2.mpfr(0), dtype=object)
            if self.exponent is not None:
                p = gmpy2.mpfr(self.exponent.numerator) / self.exponent.denominator
                self._weight = self.coefficient * _array([g**p for g in self._gap])
            self._jacobian = d * self._v ** (d - 1) if d > 1 else None  # −dt/dν
            self._fast = _FixedPointTransform(M, self._working)
            cosine = self._trig[self.mode][0]
            self._second: list[list[np.ndarray] | None] = [None]  # Y_n'' per component (order 0 is never read)
            self._slopes: list[list[np.ndarray]] = []  # dY_n/dτ per component at the nodes (their series on demand)
            self._slope_series: dict[tuple[int, int], list[Any]] = {}
            self._ratios_r: list[np.ndarray | None] = [None]  # R_n (n ≥ 1)
            self._binomial = [np.full(M, gmpy2.mpfr(1), dtype=object)]  # B_n of (1 + Σ R ε̂)^p
            self._mu = [1 / (beta * beta)]
            self._projections = {(id(vector), 0): vector[self.mode] * cosine for vector in self._vectors}
            self._powers: dict[tuple, np.ndarray] = {}  # [(c·Y)^m]_n, [(y − y_0)^m]_n at the nodes
            self._taylor: dict[tuple[int, int], np.ndarray] = {}  # f^{(k)}(y_0)/k! of an analytic law at the nodes
            self._series: list[list[np.ndarray]] = []  # Chebyshev coefficients of Y_{n,k} (node values before)
            self._unresolved: list[int] = []  # orders whose _series still hold node values
            self.tail = gmpy2.mpfr(0)

    def _coefficients(self, values: np.ndarray, other: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray | None]:
        """Chebyshev coefficients a_k (a_0 halved) of the interpolants through the node values (one or two vectors)."""
        scale = gmpy2.mpfr(2) / self.nodes
        result = []
        for coefficients in self._fast.forward(values, other):
            if coefficients is not None:
                coefficients = coefficients * scale
                coefficients[0] /= 2
            result.append(coefficients)
        return result[0], result[1]

    def _integrals_to_end(self, first: np.ndarray, second: np.ndarray) -> list[tuple[np.ndarray, Any, np.ndarray]]:
        """For two integrands h: ∫_v^1 h(ν) dν at every node, ∫_0^1 h, and h's Chebyshev coefficients (cumulative
        Chebyshev integration in x = 2ν − 1)."""
        M = self.nodes
        steps = 2 * np.arange(2, M + 1)
        integrals, sums = [], []
        for coefficients in self._coefficients(first, second):
            a = np.concatenate([coefficients, self._zero[:2]])
            b = np.empty(M + 1, dtype=object)
            b[0] = gmpy2.mpfr(0)
            b[1] = a[0] - a[2] / 2
            b[2:] = (a[1:M] - a[3:M + 2]) / steps
            top = b.sum()
            integrals.append(b[:M])
            sums.append((top, (top - (b[0::2].sum() - b[1::2].sum())) / 2, coefficients))
        # T_M(x_i) = cos(M θ_i) = 0 at first-kind nodes: Σ_{k<M} b_k T_k(x_i), the transposed transform
        return [((top - at_nodes) / 2, total, coefficients)
                for at_nodes, (top, total, coefficients) in zip(self._fast.transposed(*integrals), sums)]

    # -- the law on the arc -----------------------------------------------------------------------------
    def _projection(self, vector: np.ndarray, order: int) -> np.ndarray:
        """vector · Y_order at the nodes (computed for every vector of the laws when Y_order is fixed: every
        component's law reads the same projections — recomputing them per component made the N-dof arc O(N²) per
        order)."""
        return self._projections[(id(vector), order)]

    def _power(self, element: int, power: int, order: int) -> np.ndarray:
        """[(c_e · Y)^power]_order at the nodes."""
        key = (element, power, order)
        if key not in self._powers:
            coupling = self._elements[element][1]
            if power == 1:
                result = self._projection(coupling, order)
            else:
                result = sum((self._power(element, power - 1, i) * self._power(element, 1, order - i)
                              for i in range(order + 1)), self._zero)
            self._powers[key] = result
        return self._powers[key]

    def _taylor_values(self, element: int, k: int) -> np.ndarray:
        """f^{(k)}(y_0)/k! at the nodes for the analytic law ``element``, y_0 = c · Y_0."""
        key = (element, k)
        if key not in self._taylor:
            _, coupling, (expression, symbol) = self._analytic[element]
            terms = self._analytic_terms[element]
            while len(terms) <= k:
                derivative = sympy.diff(expression, symbol, len(terms))
                scale = sympy.Integer(math.factorial(len(terms)))
                terms.append(sympy.lambdify(symbol, derivative / scale, modules="mpmath"))
            values = [mpmath.mpf(terms[k](mpf_of_mpfr(y))) for y in self._projection(coupling, 0)]
            if not all(mpmath.isfinite(value) for value in values):
                raise UnsupportedNonlinearityError(
                    f"the law {expression} is not analytic on the contact arc (derivative {k} is not finite there)")
            self._taylor[key] = _array([_mpfr(value) for value in values])
        return self._taylor[key]

    def _deviation(self, element: int, power: int, order: int) -> np.ndarray:
        """[(y − y_0)^power]_order at the nodes for the analytic law ``element``, y = c · Y (1 ≤ power ≤ order)."""
        key = ("deviation", element, power, order)
        if key not in self._powers:
            if power == 1:
                result = self._projection(self._analytic[element][1], order)
            else:
                result = sum((self._deviation(element, 1, j) * self._deviation(element, power - 1, order - j)
                              for j in range(1, order - power + 2)), self._zero)
            self._powers[key] = result
        return self._powers[key]

    def _law_terms(self, order: int) -> list[tuple[np.ndarray, np.ndarray]]:
        """[F(Y)]_order as pairs (per-component weights g, node values): [F_k(Y)]_order = Σ g_k values."""
        terms = []
        if self.exponent is not None:
            terms.append((self.forcing, self._weight * self._binomial[order]))
        for g, c in self._rank_one:
            terms.append((g, self._projection(c, order)))
        for element, (g, _, powers) in enumerate(self._elements):
            for power, value in powers:
                terms.append((g, value * self._power(element, power, order)))
        for element, (g, _, _) in enumerate(self._analytic):
            if order == 0:
                terms.append((g, self._taylor_values(element, 0)))
            for power in range(1, order + 1):
                terms.append((g, self._taylor_values(element, power) * self._deviation(element, power, order)))
        return terms

    # -- the hierarchy ----------------------------------------------------------------------------------
    def _particular(self, order: int, tolerance: Any = None) -> list[dict] | None:
        """Per component: the forcing without μ_order, P_k at the nodes and P_k(1), P_k'(1).  With a tolerance, None
        as soon as one component's forcing is not resolved (the stiffest first: they decide a refinement)."""
        beta2 = self._beta * self._beta
        terms = self._law_terms(order - 1)
        mus = [beta2 * self._mu[i] for i in range(1, order)]
        out: list[dict] = [{}] * self.size
        for k in sorted(range(self.size), key=lambda k: -abs(self._omega[k])):
            law = self._zero
            for g, values in terms:
                if g[k]:
                    law = law + g[k] * values
            if order == 1 and self._load[k]:
                law = law + self._load[k]
            forcing = law * -beta2
            for i, mu in enumerate(mus, start=1):
                forcing = forcing - mu * self._second[order - i][k]
            cosine, sine = self._trig[k]
            weighted = forcing if self._jacobian is None else self._jacobian * forcing
            (cos_integral, cos_total, coefficients), (sin_integral, sin_total, _) = \
                self._integrals_to_end(cosine * weighted, sine * weighted)
            omega = self._omega[k]
            end_sin, end_cos = gmpy2.sin_cos(omega)
            scale = max(abs(a) for a in coefficients) or gmpy2.mpfr(1)
            tail = max(abs(a) for a in coefficients[-4:]) / scale
            if tolerance is not None and tail > tolerance:
                return None
            out[k] = {
                "forcing": forcing, "cos": cos_integral, "sin": sin_integral,
                "end": (end_sin * cos_total - end_cos * sin_total) / omega,
                "end_slope": end_cos * cos_total + end_sin * sin_total,
            }
        return out

    def _solve(self, order: int, release: list[Any], mu: Any, data: list[dict]) -> None:
        beta = self._beta
        resonant = beta**3 / 2 * mu
        values_all, second_all, slopes_all = [], [], []
        for k in range(self.size):
            cosine, sine = self._trig[k]
            omega = self._omega[k]
            item = data[k]
            values = (sine * item["cos"] - cosine * item["sin"]) / omega
            slopes = cosine * item["cos"] + sine * item["sin"]
            force = item["forcing"]
            if release[k]:
                values = values + release[k] * cosine
                slopes = slopes - (release[k] * omega) * sine
            if k == self.mode:
                values = values + resonant * (self._tau * sine)
                slopes = slopes + resonant * (sine + beta * (self._tau * cosine))
                force = force + (beta**4 * mu) * cosine
            values_all.append(values)
            second_all.append(force - (omega * omega) * values)
            slopes_all.append(slopes)
        stacked = np.vstack(values_all)
        for vector in self._vectors:
            key = (id(vector), order)
            if key not in self._projections:
                self._projections[key] = vector.dot(stacked)
        self._second.append(second_all)
        self._slopes.append(slopes_all)
        deformation = self._projection(self.coupling, order)
        self._ratios_r.append(deformation / (self.coupling[self.mode] * self._gap))
        if self.exponent is None:
            self._binomial.append(self._zero)
        else:
            p = gmpy2.mpfr(self.exponent.numerator) / self.exponent.denominator
            # B_n = (1/n) Σ_{k=1}^{n} ((p + 1) k − n) R_k B_{n−k}   (powers of 1 + Σ R_k ε̂^k)
            self._binomial.append(sum((((p + 1) * k - order) * (self._ratios_r[k] * self._binomial[order - k])
                                       for k in range(1, order + 1)), self._zero) / order)
        self._mu.append(mu)
        self._series.append(values_all)  # node values until their series are wanted (:meth:`_resolve`)
        self._unresolved.append(order)

    def _resolve(self) -> None:
        """The Chebyshev series of the fixed orders' Y_{n,k} (two components a transform) and the largest relative
        tail among them, ``self.tail`` — wanted by the next order's refinement test or by :meth:`series` only (the
        last order of an expansion never pays for them unless its series are read)."""
        for order in self._unresolved:
            values_all, series = self._series[order - 1], []
            for k in range(0, self.size, 2):
                pair = self._coefficients(*values_all[k:k + 2])
                for value_series in pair[:len(values_all[k:k + 2])]:
                    series.append(value_series)
                    size = max(abs(a) for a in value_series)
                    if size:
                        self.tail = max(self.tail, max(abs(a) for a in value_series[-4:]) / size)
            self._series[order - 1] = series
        self._unresolved = []

    def _refine(self, order: int) -> None:
        """Double the Chebyshev points and redo the fixed orders with their h_k and μ_n."""
        if 2 * self.nodes > _MAXIMUM_NODES:
            raise ConvergenceError(
                f"the stretched contact arc needs more than {_MAXIMUM_NODES} Chebyshev points "
                f"for {self.digits} digits at order {order} (tail {float(self.tail):.3g}); "
                "ask for fewer digits or a lower order")
        self.nodes *= 2
        self.counters["restarts"] += 1
        self._reset()
        for n, (release, mu) in enumerate(self._fixed, start=1):
            with workdps(self._working), self._context():
                self._solve(n, [_mpfr(h) for h in release], _mpfr(mu), self._particular(n))

    @locked
    def response(self, order: int) -> list[tuple[Any, Any]]:
        """Per component, ``(P_k(1), P_k'(1))``: the end value and slope of Y_{order,k} without its unknowns.

        The whole end value is ``P_k(1) + h_k cos(β r_k) [+ (β³ μ/2) sin β for k = j]``, the slope
        ``P_k'(1) − h_k β r_k sin(β r_k) [+ (β³ μ/2)(sin β + β cos β)]`` (:meth:`end_terms`).
        """
        if order != len(self._mu):
            raise ValueError(f"order {order} of the stretched arc is not the next one ({len(self._mu)})")
        while True:  # the grid doubles until this order's forcing and the fixed orders are resolved
            with workdps(self._working), self._context():
                tolerance = gmpy2.mpfr(10) ** (-(self.digits + 2))
                self._resolve()
                data = self._particular(order, tolerance) if self.tail <= tolerance else None
                if data is not None:
                    self._pending = (order, data)
                    return [(mpf_of_mpfr(item["end"]), mpf_of_mpfr(item["end_slope"])) for item in data]
            self._refine(order)

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
        with workdps(self._working), self._context():
            release = [mpmath.mpf(h) for h in release]
            mu = mpmath.mpf(mu)
            self._solve(order, [_mpfr(h) for h in release], _mpfr(mu), self._pending[1])
        self._fixed.append((release, mu))
        self._pending = None
        self.counters["orders"] += 1

    @locked
    def mu(self, order: int) -> Any:
        """μ_order (fixed orders only)."""
        if order >= len(self._mu):
            raise IndexError(f"μ_{order} of the stretched arc is not fixed yet")
        if order:
            return self._fixed[order - 1][1]
        with workdps(self._working):
            return 1 / (self.beta * self.beta)

    @locked
    def release(self, order: int, component: int) -> Any:
        """Y_{order, component}(0) (fixed orders only)."""
        return mpmath.mpf(1 if component == self.mode else 0) if order == 0 else self._fixed[order - 1][0][component]

    @locked
    def series(self, order: int, component: int) -> tuple[list[Any], list[Any]]:
        """Chebyshev coefficients (in x = 2v − 1) of Y_{order,component} and of its τ-derivative (fixed orders only)."""
        if len(self._mu) <= order:
            raise ValueError(f"order {order} of the stretched arc is not fixed yet")
        with workdps(self._working), self._context():
            if order:
                self._resolve()
                key = (order, component)
                if key not in self._slope_series:
                    self._slope_series[key] = self._coefficients(self._slopes[order - 1][component])[0]
                values, slopes = self._series[order - 1][component], self._slope_series[key]
            else:  # Y_0 = e_j cos βτ and its τ-slope, interpolated on the same grid
                cosine, sine = self._trig[component]
                on = component == self.mode
                values, slopes = self._coefficients(cosine if on else self._zero,
                                                    -self._omega[component] * sine if on else self._zero)
            return [mpf_of_mpfr(a) for a in values], [mpf_of_mpfr(a) for a in slopes]

    @locked
    def float_arcs(self, highest: int) -> tuple[FloatArc, ...]:
        """One float evaluator per component of Y_0 … Y_highest."""
        arcs = []
        for k in range(self.size):
            series = [self.series(n, k) for n in range(highest + 1)]
            arcs.append(FloatArc(self.denominator, [np.array([float(a) for a in values]) for values, _ in series],
                                 [np.array([float(a) for a in slopes]) for _, slopes in series]))
        return tuple(arcs)
