"""The problem the branch hierarchy solves (:mod:`lindstedt.engine.branches`): a normalised piecewise system

    W_k'' + r_k² W_k + ε̂ F_k(W) = 0   on the pieces of [0, π] between moving contact angles,

its contact states (the law on each piece: linear part, load, polynomial elements, rank-one projections, analytic
laws), its moving boundaries (simple crossings and grazing turning points) and the stretched arcs that solve a first or
last piece holding a turning point.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ..algebra.branch import EvaluationPoint
from .stretched import VectorArc

__all__ = ["BranchSystem", "ContactState", "MovingBoundary"]


@dataclass(frozen=True)
class ContactState:
    """One contact state: the law ε̂ (L W + m + Σ_e g_e Σ_m c_{e,m} (c_e · W)^m) on a piece of [0, π] (rows of
    domain elements).

    ``rank_one`` lists pairs ``(g, c)`` adding ``g cᵀ`` to L (``stiffness`` holds the dense
    rest, or is empty): the N-dof normal form's ``L_p = Σ_{i active} G_i B_iᵀ``, applied as
    one projection ``c · W`` and one rank-one update per pair, O(N) instead of O(N²).
    ``elements`` lists ``(g, c, ((m, c_m), …))``, m ≥ 2: the higher powers of a polynomial law acting on
    the deformation ``c · W`` with the force direction g — the 1-dof oscillator's piecewise-polynomial f is
    ``((1,), (1,), …)``, an N-dof element's ``(G_i, B_i, …)``.
    ``analytic`` lists ``(g, c, law)``: an analytic law of the deformation ``y = c · W`` expanded about its
    order-zero value, ``Σ_m law.branch(m) [(y − y_0)^m]_n`` (``law.branch(m)``: the cosine series of its m-th Taylor
    coefficient along ``y_0(s)``).
    """

    stiffness: tuple[tuple[Any, ...], ...]
    load: tuple[Any, ...]
    elements: tuple[tuple[tuple[Any, ...], tuple[Any, ...], tuple[tuple[int, Any], ...]], ...] = ()
    rank_one: tuple[tuple[tuple[Any, ...], tuple[Any, ...]], ...] = ()
    analytic: tuple[tuple[tuple[Any, ...], tuple[Any, ...], Any], ...] = ()


@dataclass(frozen=True)
class MovingBoundary:
    """A contact angle β = arccos κ where ``Σ_k coupling[k] W_k`` crosses κ.

    A simple crossing has ``sine`` = sin β ≠ 0 and moves as ``s* = β + Σ σ_n η^n``.  A
    *grazing* boundary sits at a turning point (β = 0 or π, sine 0): the gap has a double
    root there, the crossing exists only because the order-one orbit moves past the
    breakpoint, and its shift starts at ``first_shift`` = σ_1 in the gauge η = ε̂^{1/2}
    (root of the quadratic contact condition, chosen by the normal form).
    """

    point: EvaluationPoint
    coupling: tuple[Any, ...]
    sine: Any
    first_shift: Any = None

    @property
    def grazing(self) -> bool:
        """True for a boundary at a turning point (double root of the order-zero gap)."""
        return self.first_shift is not None


@dataclass(frozen=True)
class BranchSystem:
    """The normalised piecewise-linear problem that :class:`BranchHierarchy` solves (module docstring).

    ``ratios[k] = r_k`` (``None`` for the mode component j, whose frequency is 1
    and whose solves use the exact rational kernel); ``states`` has one entry per
    piece of [0, π], ``boundaries`` one per crossing, increasing in angle;
    ``release`` is ``(w_1, w_2, …)``, the ε̂-coefficients of W_j(0) under the "initial" normalisation
    (shorter tuples mean zeros beyond).
    ``gauge`` is 1 for expansions in η = ε̂ and 2 for η = ε̂^{1/2} (a grazing boundary is
    crossed): the laws and the release then enter at order 2 in η.
    """

    domain: Any
    ratios: tuple[Any, ...]
    mode: int
    states: tuple[ContactState, ...]
    boundaries: tuple[MovingBoundary, ...]
    zero_point: EvaluationPoint
    pi_point: EvaluationPoint
    release: tuple[Any, ...]
    gauge: int = 1
    arcs: tuple[VectorArc | None, VectorArc | None] = (None, None)  # the arcs solving the first / last piece

    def release_at(self, order: int) -> Any | None:
        """The prescribed W_{order,j}(0) in the gauge's powers (None: zero)."""
        step, remainder = divmod(order, self.gauge)
        return self.release[step - 1] if not remainder and 1 <= step <= len(self.release) and self.release[step - 1] else None

    @property
    def size(self) -> int:
        """Number of components N."""
        return len(self.ratios)

    def frequency(self, component: int) -> Any:
        """r_k as a branch frequency (the integer 1 for the mode component)."""
        ratio = self.ratios[component]
        return 1 if ratio is None else ratio
