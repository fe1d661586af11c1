"""The NNM problem: the mode j of  M X'' + K X + ε Σ_i w_i f_i(a_iᵀ X − b_i) = 0  released at rest at u_j(0) = a0 + ε a1
(every law f_i polynomial between its breakpoints: unilateral springs, cubic springs, gaps, jumps, contact pieces)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from .._errors import ProblemError
from .._precision import locked_methods
from .parsing import parse_real
from .piecewise_linear import decompose_piecewise
from .system import LAW_VARIABLE, UnilateralSystem

__all__ = ["NNMProblem"]


@locked_methods()
@dataclass(frozen=True)
class NNMProblem:
    """The NNM grown from linear mode j of ``M X'' + K X + ε Σ_i w_i f_i(a_iᵀ X − b_i) = 0``, released at rest.

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
        for law in self.system.laws:  # every law must split into pieces (polynomial, Hertz, analytic): else a typed error
            decompose_piecewise(law, LAW_VARIABLE)
        if isinstance(self.mode, bool) or not isinstance(self.mode, int) or not 1 <= self.mode <= self.system.n_dof:
            raise ProblemError(f"mode must be an integer between 1 and {self.system.n_dof}, got {self.mode!r}")
        amplitude = parse_real(self.a0, what="a0")
        if amplitude == 0:
            raise ProblemError("a0 = 0 is the rest state: give a nonzero modal amplitude a0")
        object.__setattr__(self, "a0", amplitude)
        object.__setattr__(self, "a1", parse_real(self.a1, what="a1"))
