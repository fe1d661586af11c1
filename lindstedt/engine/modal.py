"""The modal normal form of an N-dof unilateral system:  M X'' + K X + ε W (A X − b)_+ = 0.

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
:class:`~lindstedt.engine.branches.BranchSystem` with N components, solved by
the one branch hierarchy.  Its release ``W_{1,j}(0) = a1 λ_j² / a0`` comes from
``u_j(0) = a0 + ε a1``.  The arithmetic is a ``RealField`` of the requested
precision.  Of the modes the normal form needs only the λ_k and the contact
projections ``B = A Φ``, ``G = Φᵀ W`` (O(N·m) numbers, from
:meth:`~lindstedt.problems.system.UnilateralSystem.modal_coupling`: float64 modes
refined in multiprecision), and ``L_p`` enters the hierarchy as its rank-one terms
``G_i B_iᵀ`` (:class:`~lindstedt.engine.branches.ContactState`), never as an N × N matrix.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import mpmath
import numpy as np
import sympy
from sympy import RealField

from .._errors import ProblemError, ResonanceError
from .._precision import locked
from ..problems.system import UnilateralSystem
from ..algebra.branch import EvaluationPoint
from .branches import BranchHierarchy, BranchSystem, ContactState, MovingBoundary

__all__ = ["ModalNormalForm", "SpringAtOrderZero", "modal_guard_digits", "modal_normal_form"]

_RESONANCE_TOLERANCE = 1e-9
_GRAZING_TOLERANCE = 1e-12


@dataclass(frozen=True)
class SpringAtOrderZero:
    """How spring i meets the linear mode: its coupling a0 B_ij, κ_i = b_i/(a0 B_ij) and status."""

    index: int
    coupling: Any
    kappa: Any | None
    orientation: int  # +1: contact for cos s > κ (near s = 0); -1: contact for cos s < κ
    status: str  # "crossing", "grazing", "never", "always"

    @property
    def touches_from_contact(self) -> bool:
        """A grazing spring in contact over the rest of the orbit (it touches its gap at one turning point)."""
        return self.status == "grazing" and (self.kappa > 0) != (self.orientation > 0)


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
        if abs(ratio - nearest) < _RESONANCE_TOLERANCE * max(1, abs(ratio)):
            raise ResonanceError(
                f"internal resonance: lambda_{k + 1}/lambda_{mode + 1} = {mpmath.nstr(ratio, 12)} is the harmonic "
                f"{nearest} of mode {mode + 1}; the strained-coordinates NNM of mode {mode + 1} does not exist "
                "(choose another mode or detune the system)"
            )
        # smallest |r_k² − n²| over the harmonics n that the forcing contains
        divisor = min(abs(ratio * ratio - n * n) for n in (nearest - 1, nearest, nearest + 1) if n >= 0)
        divisors.append((k, nearest, divisor))
    return tuple(divisors)


def _classify(index: int, coupling: Any, gap: Any, digits: int, mode: int) -> SpringAtOrderZero:
    scale = max(abs(coupling), abs(gap), 1)
    if abs(coupling) <= mpmath.mpf(10) ** (-digits + 5) * scale:
        if gap == 0:
            raise ProblemError(
                f"spring {index + 1} is not moved by mode {mode + 1} and has zero gap: its contact is degenerate; "
                "give it a nonzero gap or choose another mode"
            )
        return SpringAtOrderZero(index, coupling, None, 1, "always" if gap < 0 else "never")
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
    return SpringAtOrderZero(index, coupling, kappa, orientation, status)


@locked
def modal_normal_form(system: UnilateralSystem, mode: int, amplitude: Any, release_correction: Any, digits: int) -> ModalNormalForm:
    """The modal normal form of the NNM of ``mode`` (0-based) released at u_j(0) = a0 + ε a1, in ``digits`` digits."""
    domain = RealField(dps=digits)
    size, springs_count = system.n_dof, system.n_springs

    def convert(value: Any) -> Any:
        value = value if isinstance(value, sympy.Basic) else sympy.Float(value, digits + 10)
        return domain.from_sympy(sympy.N(value, digits + 10))

    # λ_k and the contact projections B = A Φ, G = Φᵀ W: all the normal form needs of the modes (O(N·m) numbers)
    lambdas, coupling_rows, forcing_rows = system.modal_coupling(digits + 10)
    frequencies = [domain.dtype(value) for value in lambdas]
    a0 = convert(amplitude)
    lam = frequencies[mode]
    ratios = [value / lam for value in frequencies]
    small_divisors = _small_divisors(ratios, mode)
    gaps = [convert(v) for v in list(system.b_exact)]
    B = [[domain.dtype(value) for value in row] for row in coupling_rows]  # B[i][k]
    G = [[domain.dtype(value) for value in row] for row in forcing_rows]  # G[k][i]
    forcing_columns = [tuple(G[k][i] for k in range(size)) for i in range(springs_count)]
    coupling_vectors = [tuple(B[i]) for i in range(springs_count)]
    springs = tuple(_classify(i, a0 * B[i][mode], gaps[i], digits, mode) for i in range(springs_count))
    pi = domain.convert(sympy.N(sympy.pi, digits + 10))
    zero_point = EvaluationPoint(domain, domain.zero, domain.one, domain.zero)
    pi_point = EvaluationPoint(domain, pi, -domain.one, domain.zero)

    def assemble(crossed: dict[int, Any]) -> BranchSystem:
        """The branch system; ``crossed`` maps a grazing spring the perturbed orbit passes to its σ_1."""
        top = [s for s in springs if s.index in crossed and s.kappa > 0]
        bottom = [s for s in springs if s.index in crossed and s.kappa < 0]
        crossing = sorted((s for s in springs if s.status == "crossing"), key=lambda s: s.kappa.context.acos(s.kappa))
        boundaries, angles = [], []
        for spring in top:
            boundaries.append(MovingBoundary(zero_point, tuple(a0 * B[spring.index][k] for k in range(size)), domain.zero, crossed[spring.index]))
        for spring in crossing:
            kappa = spring.kappa
            angle = kappa.context.acos(kappa)
            point = EvaluationPoint(domain, angle, kappa, kappa.context.sqrt((1 - kappa) * (1 + kappa)))
            boundaries.append(MovingBoundary(point, tuple(a0 * B[spring.index][k] for k in range(size)), point.sin_multiple(1)))
            angles.append(angle)
        for spring in bottom:
            boundaries.append(MovingBoundary(pi_point, tuple(a0 * B[spring.index][k] for k in range(size)), domain.zero, crossed[spring.index]))
        # One contact state per piece: a sample angle inside it decides the active springs (a crossed
        # grazing spring flips on its short piece next to the turning point).
        limits = [domain.zero] + angles + [pi]
        samples = [(lower + upper) / 2 for lower, upper in zip(limits, limits[1:])]
        flipped = [set() for _ in samples]
        if top:
            samples.insert(0, domain.zero)
            flipped.insert(0, {s.index for s in top})
        if bottom:
            samples.append(pi)
            flipped.append({s.index for s in bottom})
        states = []
        for middle, flips in zip(samples, flipped):
            cosine = middle.context.cos(middle)
            active = [
                s.index
                for s in springs
                if (s.status == "always" or s.touches_from_contact or (s.status == "crossing" and ((cosine > s.kappa) if s.orientation > 0 else (cosine < s.kappa))))
                != (s.index in flips)
            ]
            # L_p = Σ_{i active} G_i B_iᵀ as rank-one terms (never an N × N matrix)
            load = tuple(-sum((G[k][i] * gaps[i] for i in active), domain.zero) / a0 for k in range(size))
            states.append(ContactState((), load, rank_one=tuple((forcing_columns[i], coupling_vectors[i]) for i in active)))
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
        )

    branch_system = assemble({})
    crossed = {}
    grazing = [s for s in springs if s.status == "grazing"]
    if grazing:
        # A grazing spring touches its gap at a turning point β (double root of the order-zero gap).  The
        # order-one orbit decides: with η = ε̂^{1/2}, s* = β + σ_1 η, the gap's ε̂ term g_1 = Σ_k c_k W_{1,k}(β)
        # and W_0''(β) = −cos β give g_1 − c_j cos β σ_1²/2 = 0; the perturbed orbit passes iff σ_1² > 0.
        first_order = BranchHierarchy(branch_system).branches(1)
        for spring in grazing:
            top = spring.kappa > 0
            point, piece = (zero_point, 0) if top else (pi_point, len(branch_system.states) - 1)
            coupling = [a0 * B[spring.index][k] for k in range(size)]
            gap = sum((coupling[k] * first_order[piece][k].evaluate(point) for k in range(size)), domain.zero)
            squared = 2 * gap / (coupling[mode] * point.cos_multiple(1))
            if squared > mpmath.mpf(10) ** (-digits // 2) * max(1, abs(gap)):
                root = squared.context.sqrt(squared)
                crossed[spring.index] = root if top else -root
        if crossed:
            branch_system = assemble(crossed)
    return ModalNormalForm(branch_system, digits, tuple(frequencies), a0, springs, small_divisors)
