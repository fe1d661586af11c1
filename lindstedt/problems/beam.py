"""The Euler–Bernoulli beam in finite elements, with breathing cracks as unilateral rotational springs.

The beam ``ρA w_tt + (EI w_xx)_xx = 0`` on ``0 ≤ x ≤ L`` has the weak form, for every admissible ``v``,

    ``∫₀ᴸ ρA w_tt v dx + ∫₀ᴸ EI w_xx v_xx dx + Σ_cracks k_c (θ⁺ − θ⁻)(v_x⁺ − v_x⁻) = 0``,

discretised by ``n`` equal elements of length ``h = L/n`` with cubic Hermite shape functions on the nodal
values ``(w, θ = w_x)``: on each element, with its dofs ``(w₁, θ₁, w₂, θ₂)``,

    ``K_e = EI/h³ [[12, 6h, −12, 6h], [6h, 4h², −6h, 2h²], [−12, −6h, 12, −6h], [6h, 2h², −6h, 4h²]]``,
    ``M_e = ρA h/420 [[156, 22h, 54, −13h], [22h, 4h², 13h, −3h²], [54, 13h, 156, −22h], [−13h, −3h², −22h, 4h²]]``

(the consistent mass matrix).  The natural frequencies converge like ``h⁴`` (relative error
``O((λ_k h)⁴)``, from above: the discretisation is a Rayleigh–Ritz one).

**Boundary conditions.**  Each end is ``"clamped"`` (``w = θ = 0``: both dofs removed), ``"pinned"``
(``w = 0``) or ``"free"``.  A beam that can move without bending (free–free, pinned–free, or a chain of
segments split by zero-stiffness hinges that is not held) is refused: ``K`` must be positive definite.

**Breathing cracks** (the rotational-spring model of the crack-detection literature): at an interior node
``j`` the two elements meeting there share the displacement ``w_j`` but keep their own rotations ``θ_j⁻``
(the left element's) and ``θ_j⁺`` (the right one's), joined by a rotational spring of stiffness ``k_c``
(``k_c = 0``: a hinge; ``k_c → ∞``: the intact beam) — in ``K`` — and by a unilateral one acting on the
relative rotation: the model's unilateral spring has the gap function ``a = d (θ_j⁺ − θ_j⁻) − gap``
(``d = ±1`` the direction in which the crack closes), so that

    ``M X'' + K X + ε aᵀ (a X − gap)_+ = 0``

is a :class:`~lindstedt.problems.system.UnilateralSystem` with ``A``'s row ``d (e(θ_j⁺) − e(θ_j⁻))``,
``W = Aᵀ``: the joint's stiffness is ``k_c`` while the crack is open and ``k_c + ε`` while it is closed.

**Degree-of-freedom numbering.**  Nodes ``0 … n`` at ``x_j = j L/n``, taken in order; each node contributes,
unless removed by a support, ``w_j`` then ``θ_j`` — or ``θ_j⁻, θ_j⁺`` at a crack.  The labels
(:attr:`EulerBernoulliBeam.dofs`) are ``"w3"``, ``"theta3"``, ``"theta3-"``, ``"theta3+"``; the matrices are
banded (half-bandwidth at most 4).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Iterable, Sequence

import numpy as np
import sympy

from .._errors import ProblemError
from .._precision import cached_property, locked_methods
from .matrices import _exact_scalar, _exact_to_float
from .structures import sparse_modes
from .system import Modes, UnilateralSystem

__all__ = ["EulerBernoulliBeam"]

_ENDS = ("clamped", "pinned", "free")


def _element_matrices(h: sympy.Expr, EI: sympy.Expr, rhoA: sympy.Expr) -> tuple[list[list[sympy.Expr]], list[list[sympy.Expr]]]:
    """The exact cubic-Hermite stiffness and consistent mass matrices of one element of length ``h``."""
    k = EI / h**3
    stiffness = [[12, 6 * h, -12, 6 * h], [6 * h, 4 * h**2, -6 * h, 2 * h**2],
                 [-12, -6 * h, 12, -6 * h], [6 * h, 2 * h**2, -6 * h, 4 * h**2]]
    mass = [[156, 22 * h, 54, -13 * h], [22 * h, 4 * h**2, 13 * h, -3 * h**2],
            [54, 13 * h, 156, -22 * h], [-13 * h, -3 * h**2, -22 * h, 4 * h**2]]
    m = rhoA * h / 420
    return ([[k * v for v in row] for row in stiffness],
            [[m * v for v in row] for row in mass])


def _positive(value: Any, name: str) -> sympy.Expr:
    exact = _exact_scalar(value, name)
    if not (exact > 0):
        raise ProblemError(f"{name} must be positive, got {exact}")
    return exact


@locked_methods()
@dataclass(frozen=True, init=False, eq=False, repr=False)
class EulerBernoulliBeam:
    """A uniform Euler–Bernoulli beam in ``n_elements`` cubic Hermite elements, optionally with breathing cracks.

    Parameters
    ----------
    n_elements : int
        Number of equal elements (n ≥ 1; the nodes are ``0 … n``).
    length, E, I, rho, area : number, optional
        ``L``, Young's modulus, second moment of area, density and cross-section area (positive; default 1).
        Exact numbers (ints, ``Fraction``, strings such as ``"1/3"``) give an exact model; a float is read as
        its exact binary value.
    left, right : {"clamped", "pinned", "free"}
        The supports at ``x = 0`` and ``x = L`` (default a cantilever: clamped, free).
    cracks : iterable of (node, k_c) or (node, k_c, direction) or (node, k_c, direction, gap)
        Breathing cracks at interior nodes ``1 … n − 1``: a linear rotational spring ``k_c ≥ 0`` between
        ``θ⁻`` and ``θ⁺`` and a unilateral one engaged while ``direction · (θ⁺ − θ⁻) > gap``
        (direction ±1, default +1; gap default 0).

    Attributes
    ----------
    dofs : tuple of str
        The label of each degree of freedom, in order (see the module notes): ``"w3"``, ``"theta3"``,
        ``"theta3-"``, ``"theta3+"``.

    The assembled ``M``, ``K`` (floats correctly rounded from the exact assembly), the crack rows ``A`` and their
    gaps ``b`` are the properties below.

    Raises
    ------
    ProblemError
        On a non-positive size or property, an unknown support, a crack at an end or repeated node, a negative
        ``k_c``, or a beam that is a mechanism (``K`` singular); the message names the fix.

    Examples
    --------
    >>> beam = EulerBernoulliBeam(4, cracks=[(2, 10)])
    >>> beam.dofs
    ('w1', 'theta1', 'w2', 'theta2-', 'theta2+', 'w3', 'theta3', 'w4', 'theta4')
    >>> beam.A.toarray().tolist()[0]
    [0.0, 0.0, 0.0, -1.0, 1.0, 0.0, 0.0, 0.0, 0.0]
    >>> system = beam.system()     # M X'' + K X + ε Aᵀ (A X − b)_+ = 0, exact
    >>> system.K_exact[3, 4], system.n_springs
    (-10, 1)
    >>> round(float(EulerBernoulliBeam(8).modes(1).frequencies[0]), 5)    # 1.875104² = 3.51602
    3.51602
    """

    n_elements: int
    length: sympy.Expr
    E: sympy.Expr
    I: sympy.Expr  # noqa: E741 - the engineers' name of the second moment of area
    rho: sympy.Expr
    area: sympy.Expr
    left: str
    right: str
    cracks: tuple[tuple[int, sympy.Expr, int, sympy.Expr], ...]
    dofs: tuple[str, ...]

    def __init__(
        self,
        n_elements: int,
        *,
        length: Any = 1,
        E: Any = 1,
        I: Any = 1,  # noqa: E741
        rho: Any = 1,
        area: Any = 1,
        left: str = "clamped",
        right: str = "free",
        cracks: Iterable[Sequence[Any]] = (),
    ) -> None:
        if isinstance(n_elements, bool) or not isinstance(n_elements, (int, np.integer)) or n_elements < 1:
            raise ProblemError(f"n_elements must be a positive integer, got {n_elements!r}")
        n = int(n_elements)
        values = {name: _positive(value, name) for name, value in
                  (("length", length), ("E", E), ("I", I), ("rho", rho), ("area", area))}
        for name, end in (("left", left), ("right", right)):
            if end not in _ENDS:
                raise ProblemError(f"{name} must be one of {_ENDS}, got {end!r}")
        parsed: list[tuple[int, sympy.Expr, int, sympy.Expr]] = []
        for k, spec in enumerate(cracks):
            if isinstance(spec, (str, bytes)) or not isinstance(spec, Sequence) or not 2 <= len(spec) <= 4:
                raise ProblemError(f"crack {k} must be (node, k_c), (node, k_c, direction) or (node, k_c, direction, gap), "
                                   f"got {spec!r}")
            node = spec[0]
            if isinstance(node, bool) or not isinstance(node, (int, np.integer)) or not 0 < node < n:
                raise ProblemError(f"crack {k}: the node must be an interior node, an integer in 1..{n - 1} "
                                   f"(node j is at x = j·L/{n}), got {node!r}; refine the mesh to place a crack")
            stiffness = _exact_scalar(spec[1], f"k_c of crack {k}")
            if stiffness < 0:
                raise ProblemError(f"crack {k}: k_c must be ≥ 0 (0 is a hinge), got {stiffness}")
            direction = spec[2] if len(spec) > 2 else 1
            if isinstance(direction, bool) or direction not in (1, -1):
                raise ProblemError(f"crack {k}: direction must be +1 or -1, got {direction!r}")
            gap = _exact_scalar(spec[3], f"gap of crack {k}") if len(spec) > 3 else sympy.Integer(0)
            parsed.append((int(node), stiffness, int(direction), gap))
        nodes = [crack[0] for crack in parsed]
        if len(set(nodes)) != len(nodes):
            raise ProblemError(f"two cracks at one node {sorted(nodes)}; give one crack per node (one spring joins θ⁻ and θ⁺)")
        _check_held(n, left, right, sorted(crack[0] for crack in parsed if crack[1] == 0))
        cracked = set(nodes)
        labels: list[str] = []
        for j in range(n + 1):
            support = left if j == 0 else right if j == n else "free"
            if support == "free":
                labels.append(f"w{j}")
            if j in cracked:
                labels += [f"theta{j}-", f"theta{j}+"]
            elif support != "clamped":
                labels.append(f"theta{j}")
        for attribute, value in (("n_elements", n), *values.items(), ("left", left), ("right", right),
                                 ("cracks", tuple(parsed)), ("dofs", tuple(labels))):
            object.__setattr__(self, attribute, value)

    # ------------------------------------------------------------------ basics
    @property
    def n_dof(self) -> int:
        """Number of degrees of freedom N."""
        return len(self.dofs)

    def index(self, label: str) -> int:
        """The position of the dof ``label`` (``"w3"``, ``"theta3"``, ``"theta3+"``…) in ``X``.

        Examples
        --------
        >>> EulerBernoulliBeam(2, left="pinned", right="pinned").index("theta2")
        3
        """
        try:
            return self._positions[label]
        except KeyError:
            raise ProblemError(f"no degree of freedom {label!r}; the labels are {self.dofs[:6]}… (see .dofs)") from None

    @cached_property
    def _positions(self) -> dict[str, int]:
        return {label: k for k, label in enumerate(self.dofs)}

    def node_positions(self) -> np.ndarray:
        """``x_j = j L / n`` for the nodes ``j = 0 … n`` (floats).

        Examples
        --------
        >>> EulerBernoulliBeam(4, length=2).node_positions().tolist()
        [0.0, 0.5, 1.0, 1.5, 2.0]
        """
        return np.linspace(0.0, _exact_to_float(self.length), self.n_elements + 1)

    def _key(self) -> tuple:
        return (self.n_elements, self.length, self.E, self.I, self.rho, self.area, self.left, self.right, self.cracks)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, EulerBernoulliBeam):
            return NotImplemented
        return self._key() == other._key()

    def __hash__(self) -> int:
        return hash(self._key())

    def __repr__(self) -> str:
        return (f"EulerBernoulliBeam(n_elements={self.n_elements}, {self.left}–{self.right}, N={self.n_dof}, "
                f"cracks at nodes {[crack[0] for crack in self.cracks]})")

    # -------------------------------------------------------------- assembly
    @cached_property
    def _exact(self) -> tuple[dict[tuple[int, int], sympy.Expr], dict[tuple[int, int], sympy.Expr]]:
        """The exact ``M`` and ``K`` by their nonzero entries (one element matrix: the mesh is uniform)."""
        n = self.n_elements
        h = self.length / n
        element_K, element_M = _element_matrices(h, self.E * self.I, self.rho * self.area)
        position = self._positions
        cracked = {crack[0] for crack in self.cracks}
        mass: dict[tuple[int, int], sympy.Expr] = {}
        stiffness: dict[tuple[int, int], sympy.Expr] = {}
        for e in range(n):
            rotation_left = f"theta{e}+" if e in cracked else f"theta{e}"
            rotation_right = f"theta{e + 1}-" if e + 1 in cracked else f"theta{e + 1}"
            local = [position.get(label) for label in (f"w{e}", rotation_left, f"w{e + 1}", rotation_right)]
            for r, row in enumerate(local):
                if row is None:
                    continue
                for c, col in enumerate(local):
                    if col is None:
                        continue
                    mass[row, col] = mass.get((row, col), 0) + element_M[r][c]
                    stiffness[row, col] = stiffness.get((row, col), 0) + element_K[r][c]
        for node, spring, _, _ in self.cracks:
            if spring != 0:
                minus, plus = position[f"theta{node}-"], position[f"theta{node}+"]
                for row, col, sign in ((minus, minus, 1), (plus, plus, 1), (minus, plus, -1), (plus, minus, -1)):
                    stiffness[row, col] = stiffness.get((row, col), 0) + sign * spring
        return ({key: value for key, value in mass.items() if value != 0},
                {key: value for key, value in stiffness.items() if value != 0})

    def _sparse(self, entries: dict[tuple[int, int], sympy.Expr], shape: tuple[int, int]) -> Any:
        import scipy.sparse

        keys = list(entries)
        rows = np.array([key[0] for key in keys], dtype=np.int64)
        cols = np.array([key[1] for key in keys], dtype=np.int64)
        data = np.array([_exact_to_float(entries[key]) for key in keys], dtype=float)
        return scipy.sparse.csr_matrix((data, (rows, cols)), shape=shape)

    @cached_property
    def _A_exact(self) -> dict[tuple[int, int], sympy.Expr]:
        entries: dict[tuple[int, int], sympy.Expr] = {}
        for i, (node, _, direction, _) in enumerate(self.cracks):
            entries[i, self._positions[f"theta{node}+"]] = sympy.Integer(direction)
            entries[i, self._positions[f"theta{node}-"]] = sympy.Integer(-direction)
        return entries

    @cached_property
    def M(self) -> Any:
        """The consistent mass matrix (``scipy.sparse.csr_matrix``, N×N)."""
        return self._sparse(self._exact[0], (self.n_dof, self.n_dof))

    @cached_property
    def K(self) -> Any:
        """The stiffness matrix, crack springs ``k_c`` included (``scipy.sparse.csr_matrix``, N×N)."""
        return self._sparse(self._exact[1], (self.n_dof, self.n_dof))

    @cached_property
    def A(self) -> Any:
        """The unilateral springs' rows ``direction · (e(θ⁺) − e(θ⁻))`` (``scipy.sparse.csr_matrix``, m×N)."""
        return self._sparse(self._A_exact, (len(self.cracks), self.n_dof))

    @property
    def b(self) -> np.ndarray:
        """The gaps of the unilateral springs (floats)."""
        return np.array([_exact_to_float(crack[3]) for crack in self.cracks], dtype=float)

    # ------------------------------------------------------------------ uses
    def system(self) -> UnilateralSystem:
        """The exact :class:`~lindstedt.problems.system.UnilateralSystem` ``M X'' + K X + ε Aᵀ (A X − b)_+ = 0``.

        Its float matrices are dense (N×N): for large models use :attr:`M`, :attr:`K` and :meth:`modes`.

        Examples
        --------
        >>> EulerBernoulliBeam(1, E="1/2").system().K_exact.tolist()
        [[6, -3], [-3, 2]]
        """
        n, m = self.n_dof, len(self.cracks)
        mass, stiffness = self._exact
        return UnilateralSystem(
            M=sympy.SparseMatrix(n, n, mass),
            K=sympy.SparseMatrix(n, n, stiffness),
            A=sympy.SparseMatrix(m, n, self._A_exact) if m else sympy.zeros(0, n),
            b=[crack[3] for crack in self.cracks],
        )

    def modes(self, count: int, *, sigma: float = 0.0) -> Modes:
        """The ``count`` lowest linear modes (nearest ``λ² = sigma``) by sparse shift-invert Lanczos.

        See :func:`~lindstedt.problems.structures.sparse_modes` (``count < N``), and its notes: in float64 the
        relative error of λ_k grows like ``eps (L/h)⁴`` (1e-3 at 5000 elements).

        Examples
        --------
        >>> lam = EulerBernoulliBeam(16, left="pinned", right="pinned").modes(2).frequencies
        >>> [round(float(v), 3) for v in lam]      # π² = 9.8696, 4π² = 39.4784 (error O(h⁴))
        [9.87, 39.479]
        """
        return sparse_modes(self.M, self.K, count, sigma=sigma)


def _check_held(n: int, left: str, right: str, hinges: list[int]) -> None:
    """Refuse a beam with a rigid-body motion: segments between the hinges (``k_c = 0``) move as
    ``w = c₀ + c₁ x``, continuous at the hinges and held by the supports; any such motion but zero is a mechanism."""
    breaks = [0, *hinges, n]
    segments = len(breaks) - 1
    rows: list[list[int]] = []

    def row(entries: dict[int, Any]) -> None:
        rows.append([entries.get(k, 0) for k in range(2 * segments)])

    if left != "free":
        row({0: 1})  # w(0) = c₀
    if left == "clamped":
        row({1: 1})
    last = 2 * (segments - 1)
    if right != "free":
        row({last: 1, last + 1: n})  # w(L) with x in units of L/n
    if right == "clamped":
        row({last + 1: 1})
    for s, node in enumerate(hinges):
        row({2 * s: 1, 2 * s + 1: node, 2 * s + 2: -1, 2 * s + 3: -node})
    rank = sympy.Matrix(rows).rank() if rows else 0
    if rank < 2 * segments:
        hinge_text = f" with hinges (k_c = 0) at nodes {hinges}" if hinges else ""
        raise ProblemError(
            f"a {left}–{right} beam{hinge_text} moves without bending ({2 * segments - rank} rigid-body motion"
            f"{'s' if 2 * segments - rank > 1 else ''}), so K is singular; clamp or pin an end, or give the cracks "
            "a positive k_c"
        )
