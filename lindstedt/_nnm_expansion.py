"""Nonlinear normal modes by strained coordinates:  M X'' + K X + ε W (A X − b)_+ = 0.

Seed §4, Theorem 4.1 and Corollary 4.2 — derived here from the equations, not
copied.  With the modes ``K Φ = M Φ Λ²``, ``Φᵀ M Φ = I`` and ``X = Φ U``:

    U'' + Λ² U + ε G (B U − b)_+ = 0,      G = Φᵀ W,   B = A Φ.

The NNM grown from mode j is sought with one strained time ``s = ω t`` for all
modal coordinates, ``ω² = Σ α_n ε^n`` (α_0 = λ_j²), released from rest at
``u_j(0) = a0 + ε a1``, ``u_k(0) = ε a_k`` (k ≠ j): the a_k are *outputs*,
chosen so that every v_k is 2π-periodic.  In normalised form
(``U = a0 W``, ``Ω = ω/λ_j``, ``ε̂ = ε/λ_j²``, ``r_k = λ_k/λ_j``)

    Ω² W'' + R² W + ε̂ G (a0 B W − b)_+ / a0 = 0,    W_0 = e_j cos s.

Spring i's gap at order zero, ``a0 B_ij cos s − b_i``, crosses zero at the
contact angle ``β_i = arccos(b_i/(a0 B_ij))`` when |b_i| < |a0 B_ij| (simple
root: validity ~ε^{-1}); |b_i| = |a0 B_ij| is grazing (double root:
validity ~ε^{-1/2}).  Between consecutive angles the active set is fixed and
the equations are linear, ``Ω² W'' + (R² + ε̂ L_p) W = ε̂ m_p``, so every
correction is an analytic quasi-trigonometric branch per piece (frequencies
1 and r_k), and order n gives, component by component,

    W_{n,k}'' + r_k² W_{n,k} = A_n δ_kj cos s − Σ_{i<n} A_i W_{n−i,k}'' − (L_p W_{n−1})_k + δ_{n1} (m_p)_k.

Unknowns of order n: A_n, the homogeneous parts ``c cos(r_k s) + d sin(r_k s)``
of every component on every piece, and the boundary shifts σ_{i,n} of the
moving contact angles.  Conditions: W_k'(0) = 0 and W_k'(π) = 0 for every k
(even, 2π-periodic), C¹ matching of every component at every moving boundary
(Taylor-expanded about β_i), the contact condition gap_i(s_i*) = 0, and the
release ``W_{n,j}(0) = δ_{n1} a1/a0``.  The mode-j condition W_j'(π) = 0 is the
secular (Fredholm) condition that fixes A_n; for k ≠ j it fixes the periodic
solution, which exists iff r_k ∉ ℤ (else: internal resonance, an error).  The
arithmetic runs in a ``RealField`` of the requested precision (mode shapes are
computed there with mpmath), so results are as accurate as asked.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any

import mpmath
import numpy as np
import sympy
from sympy import RealField

from .algebra.branch import Branch, EvaluationPoint, evaluate_float_terms
from ._errors import ProblemError, ResonanceError
from ._parsing import parse_real
from ._series_algebra import LazyOrders, shift_powers
from ._system import UnilateralSystem

__all__ = ["NNMExpansion", "NNMProblem", "StrainedCoordinatesNNM", "nnm", "release_amplitudes_by_series"]

_RESONANCE_TOLERANCE = 1e-9
_GRAZING_TOLERANCE = 1e-12


@dataclass(frozen=True)
class _SpringAtOrderZero:
    index: int
    coupling: Any  # a0 B_ij
    kappa: Any | None  # b_i / (a0 B_ij) when crossing
    orientation: int  # +1: contact for cos s > κ (near s = 0); -1: contact for cos s < κ
    status: str  # "crossing", "grazing", "never", "always"


class _Affine:
    """A value of order n, affine in the unknowns (A_n, c_1 … c_N): base + Σ coefficient·unknown."""

    __slots__ = ("base", "coefficients")

    def __init__(self, base: Any, coefficients: list[Any]):
        self.base = base
        self.coefficients = coefficients

    def __add__(self, other: "_Affine") -> "_Affine":
        return _Affine(self.base + other.base, [a + b for a, b in zip(self.coefficients, other.coefficients)])

    def __sub__(self, other: "_Affine") -> "_Affine":
        return _Affine(self.base - other.base, [a - b for a, b in zip(self.coefficients, other.coefficients)])

    def scale(self, factor: Any) -> "_Affine":
        return _Affine(self.base * factor, [a * factor for a in self.coefficients])

    def shift(self, constant: Any) -> "_Affine":
        return _Affine(self.base + constant, list(self.coefficients))

    def value(self, unknowns: list[Any]) -> Any:
        total = self.base
        for coefficient, unknown in zip(self.coefficients, unknowns):
            total = total + coefficient * unknown
        return total


class _ModalHierarchy(LazyOrders):
    """Order-by-order NNM hierarchy (see the module docstring)."""

    def __init__(self, system: UnilateralSystem, mode: int, amplitude: Any, release_correction: Any, digits: int):
        self.system = system
        self.mode = mode
        self.digits = digits
        domain = RealField(dps=digits)
        self.domain = domain
        self._domain = domain
        size = system.n_dof
        self.size = size
        frequencies, shapes = system.modes_high_precision(digits + 10)

        def convert(value: Any) -> Any:
            return domain.from_sympy(sympy.Float(value, digits + 10)) if not isinstance(value, sympy.Basic) else domain.from_sympy(sympy.N(value, digits + 10))

        self.frequencies = [convert(value) for value in frequencies]
        self.shapes = [[convert(value) for value in column] for column in shapes]  # shapes[k][row]
        self.amplitude = convert(amplitude)
        self.release_correction = convert(release_correction)
        lam = self.frequencies[mode]
        self.ratios = [value / lam for value in self.frequencies]
        self.ratios[mode] = domain.one
        self._check_resonance()
        springs = system.n_springs
        A = [[convert(v) for v in row] for row in system.A_exact.tolist()]
        W = [[convert(v) for v in row] for row in system.W_exact.tolist()]
        self.gaps = [convert(v) for v in list(system.b_exact)]
        # B = A Φ (m×N), G = Φᵀ W (N×m)
        self.B = [[sum((A[i][row] * self.shapes[k][row] for row in range(size)), domain.zero) for k in range(size)] for i in range(springs)]
        self.G = [[sum((self.shapes[k][row] * W[row][i] for row in range(size)), domain.zero) for i in range(springs)] for k in range(size)]
        self._classify_springs()
        self._build_pieces()
        self._branches: list[list[list[Branch]]] = [
            [[Branch.cosine(domain) if k == mode else Branch(domain) for k in range(size)] for _ in self.pieces]
        ]
        self._squared = [domain.one]
        self._frequencies = [domain.one]
        self._shifts: list[list[Any]] = [[boundary.point.value for boundary in self.boundaries]]
        self._derivatives: dict[tuple[int, int, int, int], Branch] = {}

    # -- set-up ------------------------------------------------------------------------------------
    def _check_resonance(self) -> None:
        self.small_divisors = []
        for k, ratio in enumerate(self.ratios):
            if k == self.mode:
                continue
            nearest = int(mpmath.nint(ratio))
            distance = abs(ratio - nearest)
            if distance < _RESONANCE_TOLERANCE * max(1, abs(ratio)):
                raise ResonanceError(
                    f"internal resonance: lambda_{k + 1}/lambda_{self.mode + 1} = {mpmath.nstr(ratio, 12)} is the harmonic "
                    f"{nearest} of mode {self.mode + 1}; the strained-coordinates NNM of mode {self.mode + 1} does not exist "
                    "(choose another mode or detune the system)"
                )
            # smallest |r_k² − n²| over the harmonics n that the forcing contains
            divisor = min(abs(ratio * ratio - n * n) for n in (nearest - 1, nearest, nearest + 1) if n >= 0)
            self.small_divisors.append((k, nearest, divisor))

    def _classify_springs(self) -> None:
        domain = self.domain
        one = domain.one
        springs = []
        for i in range(len(self.gaps)):
            coupling = self.amplitude * self.B[i][self.mode]
            gap = self.gaps[i]
            scale = max(abs(coupling), abs(gap), one)
            if abs(coupling) <= mpmath.mpf(10) ** (-self.digits + 5) * scale:
                if gap < 0:
                    springs.append(_SpringAtOrderZero(i, coupling, None, 1, "always"))
                elif gap > 0:
                    springs.append(_SpringAtOrderZero(i, coupling, None, 1, "never"))
                else:
                    raise ProblemError(
                        f"spring {i + 1} is not moved by mode {self.mode + 1} and has zero gap: its contact is degenerate; "
                        "give it a nonzero gap or choose another mode"
                    )
                continue
            kappa = gap / coupling
            orientation = 1 if coupling > 0 else -1
            # |κ| within 1e-12 of 1: the contact lasts ~1e-6 of a period, valid only for ε ≪ 1e-12 as a
            # simple root; report it as grazing (double root, validity ε^{-1/2}).
            if abs(abs(kappa) - 1) <= _GRAZING_TOLERANCE:
                status = "grazing"
            elif abs(kappa) < 1:
                status = "crossing"
            elif (kappa >= 1) == (orientation > 0):
                status = "never"
            else:
                status = "always"
            springs.append(_SpringAtOrderZero(i, coupling, kappa, orientation, status))
        self.springs = springs

    def _build_pieces(self) -> None:
        domain = self.domain
        crossing = [spring for spring in self.springs if spring.status == "crossing"]
        angles = []
        for spring in crossing:
            angles.append((spring.kappa.context.acos(spring.kappa), spring))
        angles.sort(key=lambda item: item[0])
        self.boundaries = []
        for angle, spring in angles:
            kappa = spring.kappa
            sine = kappa.context.sqrt((1 - kappa) * (1 + kappa))
            point = EvaluationPoint(domain, kappa.context.acos(kappa), kappa, sine)
            self.boundaries.append(_Boundary(spring, point, kappa, sine))
        limits = [domain.zero] + [b.point.value for b in self.boundaries] + [None]
        self.pieces = []
        for index in range(len(self.boundaries) + 1):
            # a sample angle inside the piece decides the active springs
            lower = limits[index]
            upper = limits[index + 1] if limits[index + 1] is not None else domain.convert(sympy.N(sympy.pi, self.digits + 10))
            middle = (lower + upper) / 2
            cosine = middle.context.cos(middle)
            active = []
            for spring in self.springs:
                if spring.status == "always":
                    active.append(spring.index)
                elif spring.status == "crossing":
                    inside = cosine > spring.kappa if spring.orientation > 0 else cosine < spring.kappa
                    if inside:
                        active.append(spring.index)
            size = self.size
            stiffness = [[sum((self.G[k][i] * self.B[i][l] for i in active), domain.zero) for l in range(size)] for k in range(size)]
            offset = [sum((self.G[k][i] * self.gaps[i] for i in active), domain.zero) / self.amplitude for k in range(size)]
            self.pieces.append((active, stiffness, offset))
        pi = domain.convert(sympy.N(sympy.pi, self.digits + 10))
        self.zero_point = EvaluationPoint(domain, domain.zero, domain.one, domain.zero)
        self.pi_point = EvaluationPoint(domain, pi, -domain.one, domain.zero)

    # -- helpers ---------------------------------------------------------------------------------------
    def _derivative(self, order: int, piece: int, component: int, times: int) -> Branch:
        key = (order, piece, component, times)
        if key not in self._derivatives:
            if times == 0:
                self._derivatives[key] = self._branches[order][piece][component]
            else:
                self._derivatives[key] = self._derivative(order, piece, component, times - 1).derivative()
        return self._derivatives[key]

    def _shift_powers(self, boundary: int, order: int) -> list[list[Any]]:
        return shift_powers([terms[boundary] for terms in self._shifts[:order]], order, self.domain)

    def _known(self, boundary: int, piece: int, component: int, order: int, derivative: int, powers: list[list[Any]]) -> Any:
        point = self.boundaries[boundary].point
        total = self.domain.zero
        factorial = 1
        for times in range(1, order + 1):
            factorial *= times
            inverse = self.domain.one / self.domain.convert(factorial)
            for j in range(0, order - times + 1):
                weight = powers[times][order - j]
                if weight:
                    total = total + self._derivative(j, piece, component, times + derivative).evaluate(point) * weight * inverse
        return total

    # -- one order -------------------------------------------------------------------------------------
    def _solve_order(self, order: int) -> None:
        domain = self.domain
        zero, one = domain.zero, domain.one
        size, mode = self.size, self.mode
        unknown_count = size + 1  # A_n, then c_k on the first piece for every component k
        resonant = Branch(domain, {(1, 1, 1): one / domain.convert(2)})  # s sin s / 2 solves v'' + v = cos s

        def constant(value: Any) -> _Affine:
            return _Affine(value, [zero] * unknown_count)

        def unit(index: int) -> list[Any]:
            return [one if position == index else zero for position in range(unknown_count)]

        particular: list[list[Branch]] = []
        for piece, (_, stiffness, offset) in enumerate(self.pieces):
            components = []
            for k in range(size):
                rhs = Branch(domain)
                for i in range(1, order):
                    rhs = rhs - self._derivative(order - i, piece, k, 2).scale(self._squared[i])
                for l in range(size):
                    if stiffness[k][l]:
                        rhs = rhs - self._branches[order - 1][piece][l].scale(stiffness[k][l])
                if order == 1 and offset[k]:
                    rhs = rhs + Branch.constant(domain, offset[k])
                components.append(rhs.oscillator_particular_solution(self.ratios[k] if k != mode else None))
            particular.append(components)

        def value_of(piece: int, k: int, c: _Affine, d: _Affine, point: EvaluationPoint, slope: bool) -> _Affine:
            ratio = self.ratios[k]
            frequency = 1 if k == mode else ratio
            cosine, sine = point.cos_multiple(frequency), point.sin_multiple(frequency)
            branch = particular[piece][k].derivative() if slope else particular[piece][k]
            result = _Affine(branch.evaluate(point), [zero] * unknown_count)
            if k == mode:
                resonant_branch = resonant.derivative() if slope else resonant
                result = result + _Affine(zero, unit(0)).scale(resonant_branch.evaluate(point))
            if slope:
                return result + c.scale(-sine * ratio) + d.scale(cosine * ratio)
            return result + c.scale(cosine) + d.scale(sine)

        # first piece: c_k free, d_k from W_k'(0) = 0
        c_values = [[_Affine(zero, unit(1 + k)) for k in range(size)]]
        d_values = []
        first = []
        for k in range(size):
            slope_without_d = value_of(0, k, c_values[0][k], constant(zero), self.zero_point, True)
            frequency = one if k == mode else self.ratios[k]
            first.append(slope_without_d.scale(-one / frequency))  # d r + slope_without_d = 0
        d_values.append(first)
        shift_values: list[_Affine] = []
        for index, boundary in enumerate(self.boundaries):
            point = boundary.point
            powers = self._shift_powers(index, order)
            left, right = index, index + 1
            spring = boundary.spring
            coupling_row = [self.amplitude * self.B[spring.index][k] for k in range(size)]
            # contact: Σ_k a0 B_ik W_k(s*) = b_i  ->  order n: Σ_k a0 B_ik [W_{n,k}(β) + known_k] + a0 B_ij W_0'(β) σ_n = 0
            gap_value = constant(zero)
            for k in range(size):
                if coupling_row[k]:
                    left_value = value_of(left, k, c_values[left][k], d_values[left][k], point, False)
                    gap_value = gap_value + left_value.shift(self._known(index, left, k, order, 0, powers)).scale(coupling_row[k])
            shift_values.append(gap_value.scale(one / (coupling_row[mode] * boundary.sine)))  # W_0j'(β) = −sin β
            c_next, d_next = [], []
            for k in range(size):
                left_value = value_of(left, k, c_values[left][k], d_values[left][k], point, False)
                left_slope = value_of(left, k, c_values[left][k], d_values[left][k], point, True)
                target_value = left_value.shift(self._known(index, left, k, order, 0, powers) - self._known(index, right, k, order, 0, powers))
                target_slope = left_slope.shift(self._known(index, left, k, order, 1, powers) - self._known(index, right, k, order, 1, powers))
                right_value = value_of(right, k, constant(zero), constant(zero), point, False)
                right_slope = value_of(right, k, constant(zero), constant(zero), point, True)
                x = target_value - right_value
                y = target_slope - right_slope
                frequency = 1 if k == mode else self.ratios[k]
                ratio = one if k == mode else self.ratios[k]
                cosine, sine = point.cos_multiple(frequency), point.sin_multiple(frequency)
                c_next.append(x.scale(cosine) - y.scale(sine / ratio))
                d_next.append(x.scale(sine) + y.scale(cosine / ratio))
            c_values.append(c_next)
            d_values.append(d_next)
        last = len(self.pieces) - 1
        equations = []
        for k in range(size):
            equations.append(value_of(last, k, c_values[last][k], d_values[last][k], self.pi_point, True))
        release = value_of(0, mode, c_values[0][mode], d_values[0][mode], self.zero_point, False)
        lam = self.frequencies[mode]
        target = self.release_correction * lam * lam / self.amplitude if order == 1 else zero
        equations.append(release.shift(-target))
        unknowns = _solve_linear(
            [list(equation.coefficients) for equation in equations], [-equation.base for equation in equations], domain, order
        )
        branches = []
        for piece in range(len(self.pieces)):
            components = []
            for k in range(size):
                frequency = 1 if k == mode else self.ratios[k]
                homogeneous = Branch(
                    domain,
                    {(frequency, 0, 0): c_values[piece][k].value(unknowns), (frequency, 1, 0): d_values[piece][k].value(unknowns)},
                )
                branch = particular[piece][k] + homogeneous
                if k == mode:
                    branch = branch + resonant.scale(unknowns[0])
                components.append(branch)
            branches.append(components)
        self._branches.append(branches)
        self._squared.append(unknowns[0])
        self._shifts.append([value.value(unknowns) for value in shift_values])

    def release(self, order: int, component: int) -> Any:
        """W_{order, component}(0)."""
        self._ensure(order)
        return self._branches[order][0][component].evaluate(self.zero_point)

    def branches(self, order: int) -> list[list[Branch]]:
        self._ensure(order)
        return self._branches[order]


def _solve_linear(matrix: list[list[Any]], vector: list[Any], domain: Any, order: int) -> list[Any]:
    """Gaussian elimination with partial pivoting in the (float) domain."""
    size = len(vector)
    rows = [row[:] + [value] for row, value in zip(matrix, vector)]
    scale = max((abs(entry) for row in matrix for entry in row), default=domain.one) or domain.one
    for column in range(size):
        pivot = max(range(column, size), key=lambda r: abs(rows[r][column]))
        if abs(rows[pivot][column]) <= scale * mpmath.mpf(10) ** (-(domain.dps - 3)):
            raise ResonanceError(f"the order-{order} matching system is singular (internal resonance or tangent contact)")
        rows[column], rows[pivot] = rows[pivot], rows[column]
        for r in range(column + 1, size):
            factor = rows[r][column] / rows[column][column]
            if factor:
                rows[r] = [a - factor * b for a, b in zip(rows[r], rows[column])]
    solution = [domain.zero] * size
    for r in range(size - 1, -1, -1):
        total = rows[r][size]
        for c in range(r + 1, size):
            total = total - rows[r][c] * solution[c]
        solution[r] = total / rows[r][r]
    return solution


@dataclass(frozen=True)
class _Boundary:
    spring: _SpringAtOrderZero
    point: EvaluationPoint
    kappa: Any
    sine: Any


def _to_float(value: Any) -> float:
    return float(value)


@dataclass(frozen=True)
class NNMProblem:
    """The NNM grown from linear mode j of ``M X'' + K X + ε W (A X − b)_+ = 0``, released at rest.

    Release: modal coordinate u_j(0) = a0 + ε a1 of mode j; the other modal
    coordinates are what the NNM makes them (u_k(0) = ε a_k + …), X'(0) = 0.

    Parameters
    ----------
    system : UnilateralSystem
    mode : int
        1-based mode number j (modes by increasing λ).
    a0, a1 : number or numeric string
        Exact numbers (a float is its binary value; strings are read by the one parser); a0 ≠ 0.

    Examples
    --------
    >>> import lindstedt
    >>> problem = lindstedt.NNMProblem(lindstedt.UnilateralSystem.chain(2, unilateral=[(0, 0)]), mode=1, a0="1/2")
    >>> problem.a0, problem.a1
    (1/2, 0)
    """

    system: UnilateralSystem
    mode: int
    a0: Any
    a1: Any = 0

    def __post_init__(self) -> None:
        if not isinstance(self.system, UnilateralSystem):
            raise ProblemError("system must be a UnilateralSystem (see UnilateralSystem.from_json_dict)")
        if isinstance(self.mode, bool) or not isinstance(self.mode, int) or not 1 <= self.mode <= self.system.n_dof:
            raise ProblemError(f"mode must be an integer between 1 and {self.system.n_dof}, got {self.mode!r}")
        amplitude = parse_real(self.a0, what="a0")
        if amplitude == 0:
            raise ProblemError("a0 = 0 is the rest state: give a nonzero modal amplitude a0")
        object.__setattr__(self, "a0", amplitude)
        object.__setattr__(self, "a1", parse_real(self.a1, what="a1"))


@dataclass(frozen=True)
class NNMExpansion:
    """Strained-coordinates NNM of mode j to order 2 (and beyond), in physical units.

    Attributes
    ----------
    problem : NNMProblem
        The system, the mode j (1-based; modes sorted by increasing λ, shapes signed so
        that their largest entry — the first such — is positive) and the release
        u_j(0) = a0 + ε a1; ``system``, ``mode``, ``a0``, ``a1`` are read from it.
    order : int
    digits : int
        Working decimal digits of the coefficients (precision plus near-resonance guard digits).
    lambdas : tuple of float
        All linear frequencies λ_1 ≤ … ≤ λ_N.
    omega : tuple of mpf
        (λ_j, ω_1, …, ω_order) with ω(ε) = Σ ω_n ε^n.
    alpha : tuple of mpf
        ω² = Σ α_n ε^n.
    release_modal : tuple of mpf
        a_k = v_k^1(0) for every mode k (a_j = a1): u_k(0) = ε a_k.
    validity_exponent : sympy.Rational
        −1 (all contact roots simple) or −1/2 (a spring grazes: double root).
    spring_roots : tuple of str
        Per spring: "simple", "double" (grazing), "none" (never/always in contact).
    small_divisors : tuple of (mode, harmonic, divisor)
        Near-resonance report: |r_k² − n²| for the closest harmonic n of each mode k ≠ j;
        the amplification of mode k is ~1/divisor.

    Examples
    --------
    >>> import lindstedt
    >>> system = lindstedt.UnilateralSystem.one_dof(1, a=1, b=0)
    >>> result = lindstedt.nnm(system, mode=1, a0=1, order=2)
    >>> [round(float(w), 12) for w in result.omega]
    [1.0, 0.25, -0.125]
    """

    problem: NNMProblem
    order: int
    digits: int
    lambdas: tuple[float, ...]
    omega: tuple[Any, ...]
    alpha: tuple[Any, ...]
    release_modal: tuple[Any, ...]
    validity_exponent: sympy.Rational
    spring_roots: tuple[str, ...]
    small_divisors: tuple[tuple[int, int, float], ...]
    _hierarchy: _ModalHierarchy = field(repr=False, compare=False)

    @property
    def system(self) -> UnilateralSystem:
        return self.problem.system

    @property
    def mode(self) -> int:
        return self.problem.mode

    @property
    def a0(self) -> float:
        """u_j(0) at ε = 0 (float)."""
        return float(self.problem.a0)

    @property
    def a1(self) -> float:
        """The ε-correction of the release u_j(0) = a0 + ε a1 (float)."""
        return float(self.problem.a1)

    @property
    def a_k(self) -> tuple[Any, ...]:
        """The a_k for k ≠ j in increasing mode order."""
        return tuple(value for k, value in enumerate(self.release_modal) if k != self.mode - 1)

    def frequency(self, epsilon: Any) -> Any:
        """ω(ε) = Σ_{n≤order} ω_n ε^n (vectorised)."""
        coefficients = np.array([float(w) for w in self.omega])
        return np.polynomial.polynomial.polyval(np.asarray(epsilon, dtype=float), coefficients)

    def modal_displacement(self, t: Any, epsilon: float) -> np.ndarray:
        """Modal coordinates U(t) ≈ a0 Σ_{n<N} ε̂^n W_n(ω t), ω through ω_N (shape ``t.shape + (N_dof,)``).

        The branches are used between the *moving* contact angles s_i*(ε); with the
        frequency through ω_N and the waveforms through order N−1 the error is O(ε^N)
        on t ≤ C/ε (Theorem 4.1 for N = 2: u = v⁰ + ε v¹ + O(ε²)).
        """
        hierarchy = self._hierarchy
        lam = float(self.omega[0])
        scaled = float(epsilon) / (lam * lam)
        frequency = float(self.frequency(epsilon))
        times = np.asarray(t, dtype=float)
        strained = np.mod(times * frequency + np.pi, 2 * np.pi) - np.pi
        folded = np.abs(strained)
        boundaries = np.array(
            [sum(float(hierarchy._shifts[n][index]) * scaled**n for n in range(max(self.order, 1))) for index in range(len(hierarchy.boundaries))]
        )
        piece_index = np.searchsorted(boundaries, folded)
        result = np.zeros(times.shape + (hierarchy.size,))
        for piece in range(len(hierarchy.pieces)):
            mask = piece_index == piece
            if not np.any(mask):
                continue
            points = folded[mask]
            for order in range(max(self.order, 1)):
                weight = self.a0 * scaled**order
                for component, branch in enumerate(hierarchy.branches(order)[piece]):
                    terms = [(frequency, parity, power, float(value)) for (frequency, parity, power), value in branch.terms.items()]
                    result[mask, component] += weight * evaluate_float_terms(terms, points)
        return result

    def displacement(self, t: Any, epsilon: float) -> np.ndarray:
        """Physical X(t) = Φ U(t) of :meth:`modal_displacement` (shape ``t.shape + (N_dof,)``).

        Examples
        --------
        >>> import lindstedt, numpy as np
        >>> chain = lindstedt.UnilateralSystem.chain(2, unilateral=[(0, 0)])
        >>> mode = lindstedt.nnm(chain, mode=1, a0=1.0)
        >>> np.allclose(mode.displacement(0.0, 0.01), mode.release_state(0.01))
        True
        """
        return self.modal_displacement(t, epsilon) @ self.system.modes().shapes.T

    def release_state(self, epsilon: float) -> np.ndarray:
        """Physical release X(0) = Φ U(0), U_j(0) = a0 + ε a1, U_k(0) = ε a_k (velocities zero)."""
        modes = self.system.modes()
        modal = np.array([float(a) for a in self.release_modal]) * epsilon
        modal[self.mode - 1] += self.a0
        return modes.shapes @ modal

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (schema ``lindstedt.nnm/1``)."""
        return {
            "schema": "lindstedt.nnm/1",
            "mode": self.mode,
            "a0": self.a0,
            "a1": self.a1,
            "order": self.order,
            "lambda": list(self.lambdas),
            "omega": [_to_float(w) for w in self.omega],
            "omega_digits": [mpmath.nstr(w, self.digits) for w in self.omega],
            "alpha": [_to_float(a) for a in self.alpha],
            "a_k": [_to_float(a) for a in self.a_k],
            "validity": {"exponent": str(self.validity_exponent), "spring_roots": list(self.spring_roots)},
            "small_divisors": [{"mode": k, "harmonic": n, "divisor": d} for k, n, d in self.small_divisors],
        }

    def to_json(self, indent: int | None = 2) -> str:
        """JSON text of :meth:`to_dict`."""
        return json.dumps(self.to_dict(), indent=indent, allow_nan=False)

    def to_latex(self) -> str:
        """A LaTeX fragment with λ_j, ω_1, ω_2 and the a_k."""
        lines = [rf"\lambda_{{{self.mode}}} &= {mpmath.nstr(self.omega[0], 15)}"]
        for n in range(1, len(self.omega)):
            lines.append(rf"\omega_{{{n}}} &= {mpmath.nstr(self.omega[n], 15)}")
        for k, value in enumerate(self.release_modal):
            if k != self.mode - 1:
                lines.append(rf"a_{{{k + 1}}} &= {mpmath.nstr(value, 15)}")
        return "\\begin{align*}\n" + " \\\\\n".join(lines) + "\n\\end{align*}\n"

    def summary(self) -> str:
        """Plain-text summary."""
        lines = [f"NNM of mode {self.mode} (a0 = {self.a0}), strained coordinates to order {self.order}"]
        lines.append("  lambda = " + ", ".join(f"{value:.10g}" for value in self.lambdas))
        for n, value in enumerate(self.omega):
            lines.append(f"  omega_{n} = {mpmath.nstr(value, 15)}")
        lines.append("  a_k = " + ", ".join(mpmath.nstr(value, 12) for value in self.a_k))
        lines.append(f"  validity: T ~ eps^({self.validity_exponent}); spring roots: {', '.join(self.spring_roots)}")
        return "\n".join(lines)


def _guard_digits(system: UnilateralSystem, mode: int, order: int) -> int:
    """Extra digits near an internal resonance: each order divides by |r_k² − n²| once more."""
    frequencies = system.modes().frequencies
    smallest = 1.0
    for k, value in enumerate(frequencies):
        if k == mode:
            continue
        ratio = value / frequencies[mode]
        nearest = round(ratio)
        smallest = min(smallest, abs(ratio * ratio - nearest * nearest) or 1e-300)
    return int(np.ceil(max(0.0, -np.log10(smallest)) * max(order, 1)))


class StrainedCoordinatesNNM:
    """The method: Lindstedt–Poincaré NNM expansion of an N-dof unilateral system (one verb, :meth:`expand`).

    Parameters
    ----------
    precision : int
        Decimal digits of the arithmetic (mode shapes included).
    """

    def __init__(self, precision: int = 30):
        if not isinstance(precision, int) or precision < 15 or precision > 500:
            raise ProblemError("precision must be an integer number of digits between 15 and 500")
        self.precision = precision

    def expand(self, problem: NNMProblem, order: int = 2) -> NNMExpansion:
        """The NNM of ``problem`` to ``order`` (ω_0 … ω_order, the a_k, the waveform branches)."""
        if not isinstance(problem, NNMProblem):
            raise ProblemError("expand takes an NNMProblem(system, mode, a0, a1=0)")
        if isinstance(order, bool) or not isinstance(order, int) or not 0 <= order <= 12:
            raise ProblemError(f"order must be an integer between 0 and 12, got {order!r}")
        system, mode = problem.system, problem.mode
        digits = self.precision + _guard_digits(system, mode - 1, order)
        hierarchy = _ModalHierarchy(system, mode - 1, problem.a0, problem.a1, digits)
        lam = hierarchy.frequencies[mode - 1]
        scale = 1 / (lam * lam)
        omegas = tuple(hierarchy.frequency(n) * lam * scale**n for n in range(order + 1))
        alphas = tuple(hierarchy.squared_frequency(n) * lam * lam * scale**n for n in range(order + 1))
        releases = []
        for k in range(system.n_dof):
            if order >= 1:
                releases.append(hierarchy.release(1, k) * hierarchy.amplitude * scale)
            else:
                releases.append(hierarchy.domain.zero)
        roots = []
        for spring in hierarchy.springs:
            roots.append({"crossing": "simple", "grazing": "double"}.get(spring.status, "none"))
        validity = sympy.Rational(-1, 2) if "double" in roots else sympy.Integer(-1)
        return NNMExpansion(
            problem=problem,
            order=order,
            digits=digits,
            lambdas=tuple(float(value) for value in hierarchy.frequencies),
            omega=omegas,
            alpha=alphas,
            release_modal=tuple(releases),
            validity_exponent=validity,
            spring_roots=tuple(roots),
            small_divisors=tuple((k + 1, n, float(d)) for k, n, d in hierarchy.small_divisors),
            _hierarchy=hierarchy,
        )


def release_amplitudes_by_series(system: UnilateralSystem, mode: int, a0: Any, *, dps: int = 30) -> list[tuple[Any, Any]]:
    """The a_k (k ≠ j) of Corollary 4.2 as Fourier series, summed by mpmath with an error estimate.

    Order one of mode k ≠ j: ``λ_j² v'' + λ_k² v = −Σ_i G_ki (a0 B_ij cos s − b_i)_+`` with the
    cosine coefficients of the contact functions from the Fourier kernel
    (``(c cos s − b)_+ = |c| (±1)^l c_l[b/|c|]`` for ±c > 0), so

        a_k = v_k(0) = Σ_l F_{k,l} / (λ_k² − l² λ_j²),   F_{k,l} = −Σ_i G_ki |c_i| (sign c_i)^l c_l[b_i/|c_i|].

    Independent of the branch hierarchy (a cross-check of :func:`nnm`'s closed form).

    Returns
    -------
    list of (value, error_estimate)
        One pair per mode k ≠ j, in increasing mode order.
    """
    from .algebra.fourier import contact_ramp_coefficient_mp
    from .algebra.series import series_sum

    modes = system.modes()
    frequencies, shapes = modes.frequencies, modes.shapes
    j = mode - 1
    coupling = float(a0) * (np.asarray(system.A, dtype=float) @ shapes)[:, j]
    forcing = shapes.T @ np.asarray(system.W, dtype=float)
    gaps = np.asarray(system.b, dtype=float).reshape(-1)
    results = []
    for k in range(system.n_dof):
        if k == j:
            continue

        def term(harmonic: Any, k: int = k) -> Any:
            harmonic = int(harmonic)
            total = mpmath.mpf(0)
            for i in range(len(gaps)):
                if coupling[i] == 0:
                    continue
                sign = 1 if coupling[i] > 0 else (-1) ** harmonic
                ramp = contact_ramp_coefficient_mp(harmonic, gaps[i] / abs(coupling[i]), dps=dps)
                total += -forcing[k, i] * abs(coupling[i]) * sign * ramp
            return total / (frequencies[k] ** 2 - harmonic**2 * frequencies[j] ** 2)

        estimate = series_sum(term, start=0, dps=dps)
        results.append((estimate.value, estimate.error_estimate))
    return results


def nnm(system: UnilateralSystem, mode: int, a0: Any, order: int = 2, *, a1: Any = 0, precision: int = 30) -> NNMExpansion:
    """Nonlinear normal mode of ``M X'' + K X + ε W (A X − b)_+ = 0`` grown from ``mode`` (strained coordinates).

    Examples
    --------
    >>> import lindstedt
    >>> chain = lindstedt.UnilateralSystem.chain(2, unilateral=[(0, 0)])
    >>> result = lindstedt.nnm(chain, mode=1, a0=1)
    >>> len(result.omega), len(result.a_k)
    (3, 1)
    """
    return StrainedCoordinatesNNM(precision).expand(NNMProblem(system, mode, a0, a1), order)
