"""The modal normal form of an N-dof system:  M X'' + K X + ε Σ_i w_i f_i(a_iᵀ X − b_i) = 0.

Seed §4 (Theorem 4.1, Corollary 4.2), derived here from the equations.  With
the modes ``K Φ = M Φ Λ²``, ``Φᵀ M Φ = I`` and ``X = Φ U``:

    U'' + Λ² U + ε G (B U − b)_+ = 0,      G = Φᵀ W,   B = A Φ.

The NNM grown from mode j uses one strained time ``s = ω t`` for every modal
coordinate; with ``U = a0 W``, ``Ω = ω/λ_j``, ``ε̂ = ε/λ_j²`` and ``r_k = λ_k/λ_j``

    Ω² W'' + R² W + ε̂ G (a0 B W − b)_+ / a0 = 0,    W_0 = e_j cos s.

Spring i's gap at order zero, ``a0 B_ij cos s − b_i``, crosses zero at the
contact angle ``β_i = arccos(b_i/(a0 B_ij))`` when |b_i| < |a0 B_ij| (simple
root); |b_i| = |a0 B_ij| is grazing (double root, validity ~ε^{-1/2}).
Between consecutive angles the active set is fixed and the law is linear,
``ε̂ (L_p W + m_p)`` with ``L_p = Σ_{i active} G_i B_iᵀ`` and
``m_p = −Σ_{i active} G_i b_i / a0``: a
:class:`~lindstedt.engine.branch_system.BranchSystem` with N components, solved by
the one branch hierarchy.  Its release ``W_{1,j}(0) = a1 λ_j² / a0`` comes from
``u_j(0) = a0 + ε a1``.  The arithmetic is a ``RealField`` of the requested
precision.  Of the modes the normal form needs only the λ_k and the contact
projections ``B = A Φ``, ``G = Φᵀ W`` (O(N·m) numbers, from
:meth:`~lindstedt.problems.system.UnilateralSystem.modal_coupling`: float64 modes
refined in multiprecision), and ``L_p`` enters the hierarchy as its rank-one terms
``G_i B_iᵀ`` (:class:`~lindstedt.engine.branch_system.ContactState`), never as an N × N matrix.

**Any law.**  Element i's law ``f_i`` is split at its breakpoints ``p`` into polynomial pieces
(:func:`~lindstedt.problems.piecewise_linear.decompose_piecewise`); each breakpoint is a candidate boundary, crossed
where the order-zero deformation ``a0 B_ij cos s − b_i`` reaches p (``κ = (b_i + p)/(a0 B_ij)``), and on every piece
of [0, π] a sample angle picks each element's polynomial ``Σ_m c_m u^m``.  In ``y = B_i·W``,
``f_i(a0 y − b_i)/a0 = Σ_l e_l y^l`` (binomial expansion): ``e_0`` joins the load, ``e_1`` the rank-one stiffness
``e_1 G_i B_iᵀ`` and the powers ``l ≥ 2`` act on the deformation ``y`` with the force direction ``G_i``
(``ContactState.elements``: products of branches).  Unilateral springs are the case ``f = (·)_+``, one breakpoint 0.
An element whose deformation stays between two breakpoints along the whole orbit may carry an analytic part ``f_a``
(``sin(u)``), and a fractional power ``c |u − p|^q`` is analytic there too: both are expanded along the orbit
(:class:`_AnalyticElement`).  On an element that crosses a breakpoint, a non-polynomial law — a fractional power
(Hertz), an analytic part (``Max(0, u − p) e^u``) or both — must sit on the contact interval that holds a turning
point: it makes the first (release) or the last (far turning point) piece a stretched arc
(:class:`~lindstedt.engine.stretched.VectorArc`; the far one in ``Y = −W``, ``τ = (π − s)/(π − s_L*)``), on which its
analytic part and those of the other elements act as ``h(y) = f_a(a0 y − b_i)/a0`` of their deformations ``y``,
Taylor-expanded about the order-zero ones.  Anything else (such a law mid-orbit or on both sides of a breakpoint,
contacts around both turning points, grazing) is refused with a typed error naming shooting.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import mpmath
import numpy as np
import sympy

from .._errors import ProblemError, ResonanceError, UnsupportedNonlinearityError
from .._precision import locked, workdps
from ..problems.system import LAW_VARIABLE, UnilateralSystem
from ..algebra.branch import Branch, EvaluationPoint, key_harmonic
from .branch_system import BranchSystem, ContactState, MovingBoundary
from .branches import BranchHierarchy
from .contact import real_field
from .stretched import VectorArc

__all__ = ["ModalNormalForm", "SpringAtOrderZero", "modal_guard_digits", "modal_normal_form"]

_RESONANCE_TOLERANCE = 1e-9
_GRAZING_TOLERANCE = 1e-12


@dataclass(frozen=True)
class SpringAtOrderZero:
    """How breakpoint p of element i's law meets the linear mode: the deformation ``a0 B_ij cos s − b_i`` reaches
    p where ``cos s = κ = (b_i + p)/(a0 B_ij)``; its coupling a0 B_ij, κ and status (a unilateral spring is an
    element with the one breakpoint 0).  ``index`` numbers the (element, breakpoint) pairs."""

    index: int
    coupling: Any
    kappa: Any | None
    orientation: int  # +1: the deformation is above p for cos s > κ (near s = 0); -1: for cos s < κ
    status: str  # "crossing", "grazing", "never" (the deformation stays below p), "always" (above)
    element: int = 0
    breakpoint: int = 0  # index of p among the element law's breakpoints


@dataclass(frozen=True)
class _PiecewisePolynomial:
    """An element's law as increasing breakpoints and one polynomial (coefficients by degree) per interval, plus
    its fractional terms ``c |u − point|^p`` (a Hertz contact) per interval."""

    breakpoints: tuple[Any, ...]
    pieces: tuple[tuple[Any, ...], ...]
    fractional: tuple[tuple[tuple[Any, Any, Fraction], ...], ...] = ()
    analytic: tuple[sympy.Expr, ...] = ()  # the analytic non-polynomial part per interval (0: none)
    #: per interval, the fractional terms exactly: (c, p, q, side) for c·(side·(u − p))^q, side = +1 above p
    exact_fractional: tuple[tuple[tuple[sympy.Expr, sympy.Expr, sympy.Rational, int], ...], ...] = ()

    def interval(self, deformation: Any) -> int:
        """Index of the interval holding a deformation (not on a breakpoint)."""
        return sum(1 for point in self.breakpoints if deformation > point)


def _piecewise_polynomial(law: sympy.Expr, convert: Any) -> _PiecewisePolynomial:
    """Breakpoints and polynomial pieces of an element's law, or an UnsupportedNonlinearityError naming shooting."""
    from ..problems.piecewise_linear import decompose_piecewise

    intervals = decompose_piecewise(law, LAW_VARIABLE)
    return _PiecewisePolynomial(
        tuple(convert(interval.upper) for interval in intervals[:-1]),
        tuple(tuple(convert(c) for c in interval.coefficients) for interval in intervals),
        tuple(tuple((convert(c), convert(point), Fraction(int(p.p), int(p.q))) for c, point, p in interval.fractional)
              for interval in intervals),
        tuple(interval.analytic for interval in intervals),
        tuple(tuple((c, point, p, 1 if point == interval.lower else -1) for c, point, p in interval.fractional)
              for interval in intervals))


class _AnalyticElement:
    """The analytic part f_a of an element's law along the NNM, as the cosine series of its Taylor coefficients.

    With ``y = B_i·W``, ``y_0 = B_ij cos s`` and ``h(w) = f_a(a0 B_ij w − b_i)/a0``, the force is
    ``f_a(a0 y − b_i)/a0 = Σ_m g_m(s) (y − y_0)^m``, ``g_m = h^{(m)}(cos s)/(m! B_ij^m)``: the Chebyshev
    coefficients of h^{(m)}/m! (one sampling, the derivative recurrence: :mod:`lindstedt.engine.smooth`, which
    checks that h is analytic on the orbit) are the cosine coefficients of g_m.  An element that mode j does not
    move (B_ij = 0) has the constants ``g_m = f_a^{(m)}(−b_i) a0^{m−1}/m!``.
    """

    def __init__(self, law: sympy.Expr, expression: sympy.Expr, a0: Any, coupling: Any, gap: Any, domain: Any,
                 digits: int):
        from types import SimpleNamespace

        from .smooth import _NORMALISED, _ChebyshevTaylor, _check_continuous_on_orbit

        def number(value: Any) -> sympy.Float:
            return sympy.N(value, digits + 10) if isinstance(value, sympy.Basic) else sympy.Float(mpmath.mpf(value),
                                                                                                    digits + 10)

        self._domain, self._digits, self._cache = domain, digits, {}
        self._a0, self._coupling, gap = number(a0), number(coupling), number(gap)
        if abs(self._coupling) <= sympy.Float(10) ** (-digits):
            point = -gap
            self._constants = [sympy.diff(expression, LAW_VARIABLE, m).subs(LAW_VARIABLE, point) for m in range(40)]
            self._taylor = None
            return
        self._constants = None
        scaled = expression.subs(LAW_VARIABLE, self._a0 * self._coupling * _NORMALISED - gap) / self._a0
        # the orbit of the deformation, in the words of the 1-dof checks (f, and the amplitude a0 B_ij)
        describe = SimpleNamespace(f=law, a0=self._a0 * self._coupling)
        _check_continuous_on_orbit(scaled, describe)
        self._taylor = _ChebyshevTaylor(scaled, digits, describe)

    def branch(self, power: int) -> Branch:
        """g_power as a branch (cosine terms)."""
        if power not in self._cache:
            with workdps(self._digits + 20):  # mpmath arithmetic at the global precision would round to a double
                self._cache[power] = self._series(power)
        return self._cache[power]

    def _series(self, power: int) -> Branch:
        domain = self._domain
        if self._taylor is None:
            if power >= len(self._constants):
                raise UnsupportedNonlinearityError("more than 40 Taylor terms of an analytic element law")
            value = self._constants[power] * self._a0 ** (power - 1) / math.factorial(power)
            return Branch.constant(domain, domain.dtype(mpmath.mpf(sympy.N(value, self._digits + 10))))
        coefficients = self._taylor.coefficients(power)
        scale = mpmath.mpf(sympy.N(self._coupling, self._digits + 10)) ** power
        size = max((abs(c) for c in coefficients), default=mpmath.mpf(0))
        threshold = size * mpmath.mpf(10) ** (-(self._digits + 2))
        return Branch(domain, {(n, 0, 0): domain.dtype(c / scale)
                               for n, c in enumerate(coefficients) if c and abs(c) > threshold})


@dataclass(frozen=True)
class ModalNormalForm:
    """The NNM problem of mode j in normalised modal variables (see the module docstring)."""

    system: BranchSystem
    digits: int
    frequencies: tuple[Any, ...]  # λ_1 … λ_N in the domain
    amplitude: Any
    springs: tuple[SpringAtOrderZero, ...]
    small_divisors: tuple[tuple[int, int, Any], ...]  # (k, nearest harmonic n, |r_k² − n²|), 0-based k


@locked
def modal_guard_digits(system: UnilateralSystem, mode: int, order: int) -> int:
    """Extra digits near an internal resonance: each order divides by |r_k² − n²| once more (mode 0-based)."""
    frequencies = system.modes().frequencies
    smallest = 1.0
    for k, value in enumerate(frequencies):
        if k == mode:
            continue
        ratio = value / frequencies[mode]
        nearest = round(ratio)
        smallest = min(smallest, abs(ratio * ratio - nearest * nearest) or 1e-300)
    return int(np.ceil(max(0.0, -np.log10(smallest)) * max(order, 1)))


def _small_divisors(ratios: list[Any], mode: int) -> tuple[tuple[int, int, Any], ...]:
    divisors = []
    for k, ratio in enumerate(ratios):
        if k == mode:
            continue
        nearest = int(mpmath.nint(ratio))
        # absolute: the divisor is |r² − n²| ≈ 2n|r − n|, so a high mode within 4e-4 of its harmonic 1.6e6 (a beam's
        # at 801 dof) divides by 1250, not by a small number (a relative test called it a resonance)
        if abs(ratio - nearest) < _RESONANCE_TOLERANCE:
            raise ResonanceError(
                f"internal resonance: lambda_{k + 1}/lambda_{mode + 1} = {mpmath.nstr(ratio, 12)} is the harmonic "
                f"{nearest} of mode {mode + 1}; the strained-coordinates NNM of mode {mode + 1} does not exist "
                "(choose another mode or detune the system)"
            )
        # smallest |r_k² − n²| over the harmonics n that the forcing contains
        divisor = min(abs(ratio * ratio - n * n) for n in (nearest - 1, nearest, nearest + 1) if n >= 0)
        divisors.append((k, nearest, divisor))
    return tuple(divisors)


def _classify(index: int, coupling: Any, gap: Any, digits: int, mode: int, element: int = 0,
              breakpoint: int = 0) -> SpringAtOrderZero:
    scale = max(abs(coupling), abs(gap), 1)
    if abs(coupling) <= mpmath.mpf(10) ** (-digits + 5) * scale:
        if gap == 0:
            raise ProblemError(
                f"element {element + 1} is not moved by mode {mode + 1} and rests on a breakpoint of its law (a "
                "spring with zero gap): its contact is degenerate; give it a nonzero gap or choose another mode"
            )
        return SpringAtOrderZero(index, coupling, None, 1, "always" if gap < 0 else "never", element, breakpoint)
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
    return SpringAtOrderZero(index, coupling, kappa, orientation, status, element, breakpoint)


@locked
def modal_normal_form(system: UnilateralSystem, mode: int, amplitude: Any, release_correction: Any, digits: int) -> ModalNormalForm:
    """The modal normal form of the NNM of ``mode`` (0-based) released at u_j(0) = a0 + ε a1, in ``digits`` digits."""
    domain = real_field(digits)  # a RealField with the fused sum of products (the same bits, ~2.5 times faster)
    size, springs_count = system.n_dof, system.n_springs

    def convert(value: Any) -> Any:
        value = value if isinstance(value, sympy.Basic) else sympy.Float(value, digits + 10)
        return domain.from_sympy(sympy.N(value, digits + 10))

    # λ_k and the contact projections B = A Φ, G = Φᵀ W: all the normal form needs of the modes (O(N·m) numbers)
    lambdas, coupling_rows, forcing_rows = system.modal_coupling(digits + 10)
    frequencies = [domain.dtype(value) for value in lambdas]
    a0 = convert(amplitude)
    lam = frequencies[mode]
    ratios = [key_harmonic(value / lam) for value in frequencies]  # term keys' frequencies, their hash remembered
    small_divisors = _small_divisors(ratios, mode)
    gaps = [convert(v) for v in list(system.b_exact)]
    B = [[domain.dtype(value) for value in row] for row in coupling_rows]  # B[i][k]
    G = [[domain.dtype(value) for value in row] for row in forcing_rows]  # G[k][i]
    forcing_columns = [tuple(G[k][i] for k in range(size)) for i in range(springs_count)]
    coupling_vectors = [tuple(B[i]) for i in range(springs_count)]
    distinct = {law: _piecewise_polynomial(law, convert) for law in set(system.laws)}
    laws = [distinct[law] for law in system.laws]
    # one candidate boundary per (element, breakpoint): the deformation a0 B_ij cos s − b_i reaches p at cos s = κ
    springs = []
    for i, law in enumerate(laws):
        for t, point in enumerate(law.breakpoints):
            springs.append(_classify(len(springs), a0 * B[i][mode], gaps[i] + point, digits, mode, i, t))
    springs = tuple(springs)
    pi = domain.convert(sympy.N(sympy.pi, digits + 10))
    zero_point = EvaluationPoint(domain, domain.zero, domain.one, domain.zero)
    pi_point = EvaluationPoint(domain, pi, -domain.one, domain.zero)
    binomials = {}

    def element_law(i: int, interval: int) -> tuple[Any, Any, tuple[tuple[int, Any], ...]]:
        """Element i's force on an interval of its law, in W: ``G_i f_i(a0 y − b_i)/a0 = G_i Σ_l e_l y^l``,
        ``y = B_i · W``; returns (e_0, e_1, ((l, e_l), l ≥ 2))."""
        coefficients = laws[i].pieces[interval]
        shift = -gaps[i]
        terms = []
        for l in range(len(coefficients)):
            total = domain.zero
            for m in range(l, len(coefficients)):
                if coefficients[m]:
                    key = (m, l)
                    if key not in binomials:
                        binomials[key] = domain.convert(math.comb(m, l))
                    total += coefficients[m] * binomials[key] * shift ** (m - l)
            terms.append(total * a0 ** (l - 1) if l else total / a0)
        return terms[0], (terms[1] if len(terms) > 1 else domain.zero), \
            tuple((l, e) for l, e in enumerate(terms) if l >= 2 and e)

    analytic_elements: dict[tuple[int, int], _AnalyticElement] = {}

    crossed_elements = {spring.element for spring in springs if spring.status in ("crossing", "grazing")}

    def moved_across(i: int) -> bool:
        """Whether the orbit crosses (or grazes) a breakpoint of element i's law."""
        return i in crossed_elements

    def non_polynomial(i: int, interval: int, fractional: bool = True) -> sympy.Expr:
        """Element i's analytic part on one interval of its law, in u; with ``fractional``, plus its terms
        c |u − p|^q on the side of p the orbit stays on (analytic there)."""
        return laws[i].analytic[interval] + sum(
            (c * (side * (LAW_VARIABLE - point)) ** q for c, point, q, side in laws[i].exact_fractional[interval]),
            sympy.S.Zero) if fractional else laws[i].analytic[interval]

    def analytic_element(i: int, interval: int) -> _AnalyticElement:
        """Element i's analytic part on one interval of its law; its deformation stays inside the interval along
        the whole orbit (no breakpoint of that element crossed: the Taylor series about y_0(s) holds on every
        piece)."""
        key = (i, interval)
        if key not in analytic_elements:
            analytic_elements[key] = _AnalyticElement(system.laws[i], non_polynomial(i, interval), amplitude,
                                                      coupling_rows[i][mode], list(system.b_exact)[i], domain, digits)
        return analytic_elements[key]

    def assemble(crossed: dict[int, Any]) -> BranchSystem:
        """The branch system; ``crossed`` maps a grazing boundary the perturbed orbit passes to its σ_1."""
        top = [s for s in springs if s.index in crossed and s.kappa > 0]
        bottom = [s for s in springs if s.index in crossed and s.kappa < 0]
        crossing = sorted((s for s in springs if s.status == "crossing"), key=lambda s: s.kappa.context.acos(s.kappa))
        boundaries, angles = [], []
        for spring in top:
            boundaries.append(MovingBoundary(zero_point, tuple(a0 * B[spring.element][k] for k in range(size)), domain.zero, crossed[spring.index]))
        for spring in crossing:
            kappa = spring.kappa
            angle = kappa.context.acos(kappa)
            point = EvaluationPoint(domain, angle, kappa, kappa.context.sqrt((1 - kappa) * (1 + kappa)))
            boundaries.append(MovingBoundary(point, tuple(a0 * B[spring.element][k] for k in range(size)), point.sin_multiple(1)))
            angles.append(angle)
        for spring in bottom:
            boundaries.append(MovingBoundary(pi_point, tuple(a0 * B[spring.element][k] for k in range(size)), domain.zero, crossed[spring.index]))
        # One contact state per piece: a sample angle inside it decides the interval of every element's law (on
        # the short piece next to a turning point that a crossed grazing boundary cuts off, the interval beyond
        # that boundary's breakpoint).
        limits = [domain.zero] + angles + [pi]
        samples = [(lower + upper) / 2 for lower, upper in zip(limits, limits[1:])]
        flipped: list[set[int]] = [set() for _ in samples]
        if top:
            samples.insert(0, samples[0])
            flipped.insert(0, {s.index for s in top})
        if bottom:
            samples.append(samples[-1])
            flipped.append({s.index for s in bottom})
        # per piece, the (element, interval) of the non-polynomial laws: on an element that crosses a breakpoint
        # (a stretched arc's law), or one whose deformation stays inside an interval (expanded along the orbit)
        states, arc_laws, whole_orbit = [], [], []
        for piece, (middle, flips) in enumerate(zip(samples, flipped)):
            cosine = middle.context.cos(middle)
            load = [domain.zero] * size
            rank_one, elements, analytic = [], [], []
            whole_orbit.append([])
            flipped_springs = [springs[index] for index in flips]  # the grazed breakpoints this piece lies beyond
            for i, law in enumerate(laws):
                interval = law.interval(a0 * B[i][mode] * cosine - gaps[i])
                for spring in flipped_springs:
                    if spring.element == i:  # across the grazed breakpoint
                        interval = spring.breakpoint + 1 if interval == spring.breakpoint else spring.breakpoint
                if law.analytic[interval] != 0 or law.fractional[interval]:
                    if moved_across(i):
                        arc_laws.append((piece, i, interval))
                    else:  # a fractional term in contact along the whole orbit is analytic there: expanded like one
                        analytic.append((forcing_columns[i], coupling_vectors[i], analytic_element(i, interval)))
                        whole_orbit[piece].append((i, interval))
                constant, linear, powers = element_law(i, interval)
                if constant:
                    for k in range(size):
                        load[k] += G[k][i] * constant
                if linear:  # L_p = Σ_i e_1 G_i B_iᵀ as rank-one terms (never an N × N matrix)
                    rank_one.append((forcing_columns[i], coupling_vectors[i] if linear == domain.one
                                     else tuple(linear * c for c in coupling_vectors[i])))
                if powers:
                    elements.append((forcing_columns[i], coupling_vectors[i], powers))
            states.append(ContactState((), tuple(load), elements=tuple(elements), rank_one=tuple(rank_one),
                                       analytic=tuple(analytic)))
        arcs = _contact_arc(arc_laws, whole_orbit, states, crossing, boundaries, crossed) if arc_laws else (None, None)
        return BranchSystem(
            domain=domain,
            ratios=tuple(None if k == mode else ratio for k, ratio in enumerate(ratios)),
            mode=mode,
            states=tuple(states),
            boundaries=tuple(boundaries),
            zero_point=zero_point,
            pi_point=pi_point,
            release=(convert(release_correction) * lam * lam / a0,),
            gauge=2 if crossed else 1,
            arcs=arcs,
        )

    def _contact_arc(arc_laws: list, whole_orbit: list, states: list, crossing: list, boundaries: list,
                     crossed: dict) -> tuple[VectorArc | None, VectorArc | None]:
        """The first or the last piece as a stretched arc: one element's non-polynomial law — a fractional (Hertz)
        term, an analytic part or both — in contact around a turning point (the release, or the far one), ending where
        that element's deformation reaches the breakpoint of its contact interval (the first, or the last,
        boundary).  The analytic laws of the other elements on that piece act on the arc too."""
        supported = ("the N-dof strained-coordinates NNM takes a fractional power (Hertz) or analytic law on one "
                     "element whose contact holds a turning point and ends at the first or the last contact angle, "
                     "without grazing")
        piece, i, interval = arc_laws[0]
        last = len(states) - 1
        fractional = laws[i].fractional[interval]
        if len(arc_laws) != 1 or piece not in (0, last) or crossed or not crossing or len(fractional) > 1 or last == 0:
            raise UnsupportedNonlinearityError(
                f"{supported}; element {i + 1} ({system.laws[i]}) is not in contact around one turning point only: "
                "compute its NNMs by shooting (nnm_point, continue_nnm)")
        spring = crossing[0] if piece == 0 else crossing[-1]
        if spring.element != i or (fractional and fractional[0][1] != laws[i].breakpoints[spring.breakpoint]):
            raise UnsupportedNonlinearityError(
                f"{supported}; another breakpoint is crossed inside element {i + 1}'s contact arc: compute its NNMs "
                "by shooting (nnm_point, continue_nnm)")
        end, far = laws[i].breakpoints[spring.breakpoint], piece == last
        # the analytic laws on the arc as h(y) = f(a0 y − b)/a0 of the deformation y = c·W (c·Y on the arc); the
        # contact element's must be analytic on the deformations it takes there, from its breakpoint to the turning
        # point (the arc's own check sees its interior nodes only)
        own = non_polynomial(i, interval, fractional=False)
        if own != 0:
            reach = sorted(domain.to_sympy(value) for value in (end, (-a0 if far else a0) * B[i][mode] - gaps[i]))
            try:
                continuous = sympy.calculus.util.continuous_domain(own, LAW_VARIABLE, sympy.Interval(*reach))
            except (NotImplementedError, TypeError, ValueError):  # undecided: the arc's own finiteness check decides
                continuous = sympy.Interval(*reach)
            if continuous != sympy.Interval(*reach):
                raise UnsupportedNonlinearityError(
                    f"element {i + 1}'s law {system.laws[i]} is not analytic on its whole contact arc (u from "
                    f"{sympy.N(reach[0], 6)} to {sympy.N(reach[1], 6)}); a non-polynomial piece must be analytic up to "
                    "its breakpoint: compute its NNMs by shooting (nnm_point, continue_nnm)")
        deformation = sympy.Symbol("y", real=True)
        analytic = []
        for e, law in [(i, own)] + [(e, non_polynomial(e, k)) for e, k in whole_orbit[piece]]:
            if law != 0:
                law = law.subs(LAW_VARIABLE, amplitude * deformation - list(system.b_exact)[e]) / amplitude
                if far:  # Y = −W: the law −h(−y)
                    law = -law.subs(deformation, -deformation)
                analytic.append((forcing_columns[e], coupling_vectors[e], (sympy.expand(law), deformation)))
        chi = (boundaries[-1] if far else boundaries[0]).coupling
        exponent, coefficient = None, domain.zero
        if fractional:
            c, _, exponent = fractional[0]
            coefficient = c * abs(chi[mode]) ** domain.convert(sympy.Rational(exponent.numerator, exponent.denominator)) / a0
        state = states[piece]
        rows = [domain.one if k == mode else ratio for k, ratio in enumerate(ratios)]
        if not far:
            return VectorArc(rows, mode, chi, forcing_columns[i], spring.kappa, exponent, coefficient,
                             (state.load, state.rank_one, state.elements), digits, analytic), None
        # the far arc in Y = −W, τ = (π − s)/ℓ: F̃(Y) = −F(−Y) flips the load, the Hertz force and the odd powers'
        # signs of the even powers; the deformation's coupling is −χ and its contact point cos(π − β) = −κ
        flipped = tuple((g, c_, tuple((m, value if m % 2 else -value) for m, value in powers))
                        for g, c_, powers in state.elements)
        polynomial = (tuple(-x for x in state.load), state.rank_one, flipped)
        return None, VectorArc(rows, mode, tuple(-x for x in chi), tuple(-g for g in forcing_columns[i]), -spring.kappa,
                               exponent, coefficient, polynomial, digits, analytic)

    branch_system = assemble({})
    crossed = {}
    grazing = [s for s in springs if s.status == "grazing"]
    if grazing:
        # A grazing boundary touches its breakpoint at a turning point β (double root of the order-zero
        # deformation − p).  The order-one orbit decides: with η = ε̂^{1/2}, s* = β + σ_1 η, the deformation's ε̂
        # term g_1 = Σ_k c_k W_{1,k}(β) and W_0''(β) = −cos β give g_1 − c_j cos β σ_1²/2 = 0; the perturbed
        # orbit passes iff σ_1² > 0.
        first_order = BranchHierarchy(branch_system).branches(1)
        for spring in grazing:
            top = spring.kappa > 0
            point, piece = (zero_point, 0) if top else (pi_point, len(branch_system.states) - 1)
            coupling = [a0 * B[spring.element][k] for k in range(size)]
            gap = sum((coupling[k] * first_order[piece][k].evaluate(point) for k in range(size)), domain.zero)
            squared = 2 * gap / (coupling[mode] * point.cos_multiple(1))
            if squared > mpmath.mpf(10) ** (-digits // 2) * max(1, abs(gap)):
                root = squared.context.sqrt(squared)
                crossed[spring.index] = root if top else -root
        if crossed:
            branch_system = assemble(crossed)
    return ModalNormalForm(branch_system, digits, tuple(frequencies), a0, springs, small_divisors)
