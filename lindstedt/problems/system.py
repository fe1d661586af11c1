"""N degrees of freedom with unilateral springs:  M X'' + K X + ε W (A X − b)_+ = 0.

``UnilateralSystem`` is the problem definition shared by the N-dof methods:

* ``M``, ``K`` (N×N): symmetric positive definite mass and stiffness matrices;
* ``A`` (m×N): one row per unilateral spring, its *gap function* being
  ``g_i(X) = A_i X − b_i``; the spring pushes back only while ``g_i > 0``;
* ``b`` (m): the gaps.  ``b_i > 0`` is a clearance, ``b_i < 0`` a spring that
  is already compressed (preloaded) at ``X = 0``;
* ``W`` (N×m): how the spring forces are distributed on the masses, by default
  ``Aᵀ`` — then the system derives from the energy

  ``E = ½ X'ᵀ M X' + ½ Xᵀ K X + ½ ε Σ_i (A_i X − b_i)_+²``.

``(·)_+ = max(·, 0)`` acts entrywise.  Elements may carry other laws f_i (``ε W f(A X − b)``), and a polynomial force
``ε g(X)`` (``couplings``, one polynomial in ``x1 … xN`` per degree of freedom) is turned exactly into elements
``(a_iᵀ X)^d`` by :mod:`~lindstedt.problems.couplings`.  Every matrix is stored twice: exactly
(``sympy.ImmutableMatrix``; the string ``"0.1"`` is read as ``1/10``, the float
``0.1`` as its exact binary value) and as a read-only float ``numpy`` array (the correctly rounded
values of the exact entries).  The N-dof setting is section 4 of the seed
paper, whose force term ``ε (Ã X − B)_+`` is the special case ``W = I``.
The entries are read by :mod:`~lindstedt.problems.matrices` and the linear modes computed by
:mod:`~lindstedt.problems.modes`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Iterable, Mapping, NamedTuple, Sequence

import numpy as np
import sympy

from .._errors import ProblemError, UnsupportedNonlinearityError
from .._precision import cached_property, locked, locked_methods
from .couplings import coupling_elements, read_couplings
from .matrices import _check_symmetric_positive_definite, _exact_matrix, _exact_scalar, _exactly_equal, _float_array
from .modes import _float_modes, _high_precision_modes, _modal_coupling
from .parsing import parse_expression

__all__ = ["UnilateralSystem", "Modes", "OneDofUnilateral"]

_JSON_KEYS = ("M", "K", "A", "b", "W", "laws", "couplings", "elements")
_ELEMENT_KEYS = ("law", "a", "b", "w")
#: the variable of an element's law f(u) (the oscillator's u)
LAW_VARIABLE = sympy.Symbol("u", real=True)
#: the law of a unilateral spring, the default of every element
UNILATERAL = sympy.Max(0, LAW_VARIABLE)


def _element_laws(laws: Any, m: int) -> tuple[sympy.Expr, ...]:
    """One law f_i(u) per row of A, read by the one parser (default: every element a unilateral spring)."""
    if laws is None:
        return (UNILATERAL,) * m
    if isinstance(laws, (str, bytes)) or not isinstance(laws, Sequence):
        raise ProblemError(f"laws must be a list of one law f(u) per row of A, e.g. ['Max(0, u)', 'u**3'], got {laws!r}")
    if len(laws) != m:
        raise ProblemError(f"laws must have one law per row of A ({m}), got {len(laws)}")
    read = []
    for i, law in enumerate(laws):
        expression = parse_expression(law, symbols={"u": LAW_VARIABLE}, what=f"laws[{i}]")
        if not expression.has(LAW_VARIABLE):
            raise ProblemError(f"laws[{i}] = {law!r} does not depend on u: a constant force is a load, not an element; "
                               "write the law as a function of u = A_i X − b_i")
        read.append(expression)
    return tuple(read)


class Modes(NamedTuple):
    """Linear normal modes ``K Φ = M Φ diag(λ²)``, ``Φᵀ M Φ = I``.

    Attributes
    ----------
    frequencies : numpy.ndarray, shape (N,)
        Angular frequencies λ_1 ≤ … ≤ λ_N (positive).
    shapes : numpy.ndarray, shape (N, N)
        Column k is the mode shape of λ_k.
    """

    frequencies: np.ndarray
    shapes: np.ndarray


def _json_entry(expr: sympy.Expr) -> str:
    return str(expr)


# --------------------------------------------------------------------------- #
# the problem
# --------------------------------------------------------------------------- #
@locked_methods("n_dof", "n_springs", "modes", "gaps", "acceleration", "energy")  # floats: the integrators' own
@dataclass(frozen=True, init=False, eq=False, repr=False)
class UnilateralSystem:
    """The problem ``M X'' + K X + ε W (A X − b)_+ = 0`` (ε is given to the solvers).

    Parameters
    ----------
    M, K : array_like, shape (N, N)
        Mass and stiffness matrices, symmetric positive definite.
    A : array_like, shape (m, N)
        One row per unilateral spring; ``g_i = A_i X − b_i`` is its gap
        function.  ``A = []`` (with ``b = []``) means no unilateral spring.
    b : array_like, shape (m,), optional
        Gaps (any sign; ``b_i < 0`` is a preloaded spring); default zeros.
    W : array_like, shape (N, m), optional
        Distribution of the spring forces on the masses; default ``Aᵀ``
        (the conservative case, with energy ``E`` of :meth:`energy`).
    laws : sequence of str, optional
        One law ``f_i(u)`` per row of A, the element's force ``ε W_i f_i(A_i X − b_i)`` (default: every
        element the unilateral spring ``Max(0, u)``, the problem above).  Any law of the 1-dof library
        (``"u**3"``, ``"Max(0, u)**(3/2)"``, …), read by the one parser.  The exact event-driven flow takes
        unilateral springs only (a typed error says so); NNM shooting and forced responses integrate any law
        (:class:`~lindstedt.numerics.SmoothForcedFlow`), the strained-coordinates NNMs (:func:`lindstedt.nnm`)
        take every law that is polynomial between breakpoints (gaps, jumps, cubic springs, contact pieces).
    couplings : sequence of str or sympy expressions, optional
        A polynomial force ``ε g(X)``: one polynomial ``g_r`` per degree of freedom in the displacements ``x1 … xN``
        (1-based; ``"0"`` where there is none), e.g. ``["x1**3", "x1**2*x2"]``, read by the one parser.  It is
        turned exactly into elements ``ε w (aᵀ X)^d`` (law ``u**d``, offset 0; :mod:`~lindstedt.problems.couplings`),
        appended after the rows of ``A`` (and columns of ``W``) given here, so every method taking elements takes
        it.  Constant terms (loads) and linear terms (stiffness: K) are refused with the fix.

    Entries may be ints, floats, ``fractions.Fraction``, exact strings such as
    ``"1/3"`` or ``"sqrt(2)"``, or sympy numbers; strings are read exactly (``"0.1"`` → ``1/10``), a
    float is its exact binary value (``0.1`` → ``3602879701896397/36028797018963968``).

    Attributes
    ----------
    M, K, A, b, W : numpy.ndarray
        Read-only float copies (correctly rounded from the exact values).
    M_exact, K_exact, A_exact, b_exact, W_exact : sympy.ImmutableMatrix
        Exact copies (``b_exact`` is a column).
    laws : tuple of sympy expressions
        The law of each element, in the variable ``u``.
    couplings : tuple of sympy expressions or None
        The polynomials ``g_r`` as given (expanded, exact), ``None`` without couplings; their elements are the
        last rows of ``A_exact`` (columns of ``W_exact``, entries of ``b_exact`` and ``laws``).

    Raises
    ------
    ProblemError
        On a shape mismatch, a non-finite or non-real entry, a non-symmetric or
        non positive definite ``M`` or ``K``, or a zero row of ``A``; the
        message names the fix.

    Examples
    --------
    >>> system = UnilateralSystem(M=[[1, 0], [0, 1]], K=[[2, -1], [-1, 2]], A=[[0, 1]], b=["1/10"])
    >>> system.n_dof, system.n_springs, system.symmetric_coupling
    (2, 1, True)
    >>> system.b_exact[0]
    1/10
    >>> [round(float(x), 12) for x in system.modes().frequencies]
    [1.0, 1.732050807569]
    >>> geometric = UnilateralSystem(M=[[1, 0], [0, 1]], K=[[2, -1], [-1, 2]], couplings=["x1**3", "x1**2*x2"])
    >>> geometric.A_exact.tolist(), geometric.laws
    ([[2, 1], [1, 1], [1, 0], [0, 1]], (u**3, u**3, u**3, u**3))
    >>> geometric.W_exact.tolist()
    [[0, 0, 1, 0], [1/6, -1/3, -1, 1/6]]
    """

    M: np.ndarray
    K: np.ndarray
    A: np.ndarray
    b: np.ndarray
    W: np.ndarray
    M_exact: sympy.ImmutableMatrix
    K_exact: sympy.ImmutableMatrix
    A_exact: sympy.ImmutableMatrix
    b_exact: sympy.ImmutableMatrix
    W_exact: sympy.ImmutableMatrix
    laws: tuple[sympy.Expr, ...]
    couplings: tuple[sympy.Expr, ...] | None

    def __init__(self, M: Any, K: Any, A: Any = (), b: Any | None = None, W: Any | None = None,
                 laws: Any = None, couplings: Any = None) -> None:
        M_exact = _exact_matrix(M, "M", ndim=2)
        K_exact = _exact_matrix(K, "K", ndim=2)
        n = M_exact.rows
        if n == 0 or M_exact.cols != n:
            raise ProblemError(f"M must be a non-empty square N×N matrix, got shape ({M_exact.rows}, {M_exact.cols})")
        if K_exact.shape != (n, n):
            raise ProblemError(f"K must have the shape of M, ({n}, {n}), got {K_exact.shape}")
        A_exact = _exact_matrix(A, "A", ndim=2)
        if A_exact.rows == 0:
            A_exact = sympy.ImmutableMatrix.zeros(0, n)
        if A_exact.cols != n:
            raise ProblemError(
                f"A must have one column per degree of freedom ({n}), got shape {A_exact.shape}; "
                "each row of A is one unilateral spring"
            )
        m = A_exact.rows
        b_exact = sympy.ImmutableMatrix.zeros(m, 1) if b is None else _exact_matrix(b, "b", ndim=1)
        if b_exact.rows != m:
            raise ProblemError(f"b must have one gap per row of A ({m}), got {b_exact.rows} entries")
        for i in range(m):
            if all(entry == 0 for entry in A_exact.row(i)):
                raise ProblemError(
                    f"row {i} of A is zero, so spring {i} never changes state; remove it (and b[{i}]) "
                    "or give the degree of freedom it acts on"
                )
        if W is None:
            W_exact = A_exact.T
        else:
            W_exact = _exact_matrix(W, "W", ndim=2)
            if W_exact.rows == 0 and m == 0:
                W_exact = sympy.ImmutableMatrix.zeros(n, 0)
            if W_exact.shape != (n, m):
                raise ProblemError(
                    f"W must be N×m = ({n}, {m}) (column i distributes the force of spring i), "
                    f"got shape {W_exact.shape}; omit W to use Aᵀ"
                )
        M_float = _float_array(M_exact)
        K_float = _float_array(K_exact)
        _check_symmetric_positive_definite(M_exact, M_float, "M", "mass matrix")
        _check_symmetric_positive_definite(K_exact, K_float, "K", "stiffness matrix")
        element_laws = _element_laws(laws, m)
        read = None if couplings is None else read_couplings(couplings, n)
        derived = coupling_elements(read) if read else ()
        if derived:  # the elements of ε g(X), after the given ones
            A_exact = A_exact.col_join(sympy.ImmutableMatrix([list(a) for a, _, _ in derived]))
            b_exact = b_exact.col_join(sympy.ImmutableMatrix.zeros(len(derived), 1))
            W_exact = W_exact.row_join(sympy.ImmutableMatrix([list(w) for _, _, w in derived]).T)
            element_laws += tuple(LAW_VARIABLE**d for _, d, _ in derived)
        object.__setattr__(self, "_given_elements", m)
        for attribute, value in (
            ("M", M_float),
            ("K", K_float),
            ("A", _float_array(A_exact)),
            ("b", _float_array(b_exact, vector=True)),
            ("W", _float_array(W_exact)),
            ("M_exact", M_exact),
            ("K_exact", K_exact),
            ("A_exact", A_exact),
            ("b_exact", b_exact),
            ("W_exact", W_exact),
            ("laws", element_laws),
            ("couplings", read),
        ):
            object.__setattr__(self, attribute, value)

    # ------------------------------------------------------------------ basics
    @property
    def n_dof(self) -> int:
        """Number of degrees of freedom N."""
        return self.M_exact.rows

    @property
    def n_springs(self) -> int:
        """Number of unilateral springs m."""
        return self.A_exact.rows

    @cached_property
    def symmetric_coupling(self) -> bool:
        """True when ``W = Aᵀ`` exactly (conservative, symmetric effective stiffness)."""
        return all(_exactly_equal(self.W_exact[j, i], self.A_exact[i, j]) for i in range(self.n_springs) for j in range(self.n_dof))

    @property
    def unilateral(self) -> bool:
        """True when every element is a unilateral spring ``Max(0, u)`` (the exact flow's problem)."""
        return all(law == UNILATERAL for law in self.laws)

    @cached_property
    def ramp_equivalent(self) -> tuple["UnilateralSystem", tuple[int, ...]] | None:
        """The same system written with unilateral springs only, where every law is continuous and piecewise linear
        and vanishes at its first breakpoint (gaps, stops, dead zones, multi-stage springs); None otherwise.

        Such a law is a sum of ramps: with p_1 its first breakpoint, β its slope before p_1 and d_k its slope jumps,
        ``f(u) = −β (p_1 − u)_+ + Σ_k s_k (u − p_k)_+`` (s_1 = β + d_1, s_k = d_k), exactly, when ``f(p_1) = 0``; a
        linear law ``β (u − p)`` with a root p is ``β (u − p)_+ − β (p − u)_+``.  Each ramp of element i becomes the
        spring ``(±a_iᵀX ∓ (b_i + p))_+`` with force column ``weight · w_i``.  The exact event-driven flows run on it.

        Returns
        -------
        (UnilateralSystem, tuple of int) or None
            The equivalent system and, for each of its springs, the element it comes from.

        Examples
        --------
        A dead zone of width 1/5 at mass 1: two springs, one on each side.

        >>> system = UnilateralSystem(M=[[1]], K=[[1]], A=[[1]], laws=["Max(0, u - 1/5) - Max(0, -u - 1/5)"])
        >>> equivalent, elements = system.ramp_equivalent
        >>> equivalent.A.tolist(), equivalent.b.tolist(), equivalent.W.tolist(), elements
        ([[-1.0], [1.0]], [0.2, 0.2], [[-1.0, 1.0]], (0, 0))
        """
        from .piecewise_linear import decompose_piecewise, has_non_polynomial_law

        if self.unilateral:
            return self, tuple(range(self.n_springs))
        rows, offsets, columns, origin = [], [], [], []
        for i, law in enumerate(self.laws):
            if has_non_polynomial_law(law, LAW_VARIABLE):
                return None
            try:
                intervals = decompose_piecewise(law, LAW_VARIABLE, max_degree=1)
            except (ProblemError, UnsupportedNonlinearityError):
                return None
            pieces = [(interval.coefficients[0], interval.coefficients[1] if len(interval.coefficients) > 1 else 0)
                      for interval in intervals]
            points = [interval.upper for interval in intervals[:-1]]
            if not points:  # linear: β (u − p) with its root p
                intercept, slope = pieces[0]
                if slope == 0:
                    return None
                points, pieces = [-intercept / slope], pieces * 2
            for point, (c_left, s_left), (c_right, s_right) in zip(points, pieces, pieces[1:]):
                if sympy.simplify(c_left + s_left * point - (c_right + s_right * point)) != 0:
                    return None  # a jump: not a sum of ramps
            intercept, slope = pieces[0]
            if sympy.simplify(intercept + slope * points[0]) != 0:
                return None  # f(p_1) ≠ 0: a constant load, not a spring
            a, b, w = self.A_exact.row(i), self.b_exact[i, 0], self.W_exact.col(i)
            # −β (p_1 − u)_+, then at p_1 the slope right of it, at every later p_k the slope's jump
            ramps = [(-1, points[0], -slope), (1, points[0], pieces[1][1])]
            ramps += [(1, point, right[1] - left[1]) for point, left, right in zip(points[1:], pieces[1:], pieces[2:])]
            for side, point, weight in ramps:
                if weight != 0:
                    rows.append([side * entry for entry in a])
                    offsets.append(side * (b + point))
                    columns.append([weight * entry for entry in w])
                    origin.append(i)
        if not rows:
            return None
        W = [[column[r] for column in columns] for r in range(self.n_dof)]
        return UnilateralSystem(M=self.M_exact.tolist(), K=self.K_exact.tolist(), A=rows, b=offsets, W=W), tuple(origin)

    def require_unilateral(self, what: str) -> None:
        """Raise :class:`~lindstedt.UnsupportedNonlinearityError` naming ``what`` unless every element is a
        unilateral spring.

        Examples
        --------
        >>> cubic = UnilateralSystem(M=[[1]], K=[[1]], A=[[1]], b=[0], laws=["u**3"])
        >>> cubic.require_unilateral("the exact flow")
        Traceback (most recent call last):
            ...
        lindstedt._errors.UnsupportedNonlinearityError: the exact flow takes unilateral springs Max(0, u) only; this system has the laws [u**3]: its forced responses run on the DOP853 flow (lindstedt.numerics.SmoothForcedFlow, chosen by forced_flow)
        """
        if not self.unilateral:
            raise UnsupportedNonlinearityError(
                f"{what} takes unilateral springs Max(0, u) only; this system has the laws "
                f"[{', '.join(map(str, self.laws))}]: its forced responses run on the DOP853 flow "
                "(lindstedt.numerics.SmoothForcedFlow, chosen by forced_flow)")

    def _key(self) -> tuple:
        return (self.M_exact, self.K_exact, self.A_exact, self.b_exact, self.W_exact, self.laws, self.couplings)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, UnilateralSystem):
            return NotImplemented
        return self._key() == other._key()

    def __hash__(self) -> int:
        return hash(self._key())

    def __repr__(self) -> str:
        coupling = "W=Aᵀ" if self.symmetric_coupling else "W≠Aᵀ"
        given = self.laws[:self._given_elements]
        laws = "" if all(law == UNILATERAL for law in given) else f", laws=[{', '.join(map(str, given))}]"
        if self.couplings is None:
            return f"UnilateralSystem(N={self.n_dof}, m={self.n_springs}, {coupling}{laws})"
        derived = self.n_springs - self._given_elements
        return (f"UnilateralSystem(N={self.n_dof}, m={self.n_springs} ({derived} from couplings), {coupling}{laws}, "
                f"couplings=[{', '.join(map(str, self.couplings))}])")

    # ------------------------------------------------------------ constructors
    @classmethod
    def chain(
        cls,
        n_masses: int,
        unilateral: Iterable[Sequence[Any]] = (),
        *,
        mass: Any = 1,
        stiffness: Any = 1,
        elements: Iterable[Sequence[Any]] = (),
        couplings: Any = None,
    ) -> "UnilateralSystem":
        """Chain of equal masses joined by equal springs, both ends fixed to walls.

        ``K`` is tridiagonal ``stiffness·(2, −1)``, ``M = mass·I``.  Each
        unilateral spring acts on one mass: ``(j, gap)`` engages while
        ``X_j > gap``; ``(j, gap, -1)`` engages while ``−X_j > gap`` (a stop on
        the other side).  Masses are indexed from 0.  ``W = Aᵀ``.

        Parameters
        ----------
        n_masses : int
            Number of masses N ≥ 1.
        unilateral : iterable of (int, gap) or (int, gap, direction)
            The unilateral springs; ``direction`` is +1 (default) or −1.
        mass, stiffness : number, optional
            Positive mass and spring constant (default 1).
        elements : iterable of (i, j, law) or (i, j, law, gap)
            Elements of any law f(u) of the 1-dof library between two masses: the force
            ``ε f(X_i − X_j − gap)`` pushes mass j and pulls mass i (``j = None``: between mass i and the
            ground).  They follow the unilateral springs in A.
        couplings : sequence of str, optional
            A polynomial force ``ε g(X)`` in ``x1 … xN`` (1-based), as for the constructor; its elements come last.

        Examples
        --------
        >>> chain = UnilateralSystem.chain(3, unilateral=[(0, 0), (2, "1/2", -1)])
        >>> chain.K.tolist()
        [[2.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 2.0]]
        >>> chain.A.tolist(), chain.b.tolist()
        ([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0]], [0.0, 0.5])
        >>> cubic = UnilateralSystem.chain(2, elements=[(0, 1, "u**3")])      # a cubic spring between the masses
        >>> cubic.A.tolist(), cubic.laws
        ([[1.0, -1.0]], (u**3,))
        """
        if isinstance(n_masses, bool) or not isinstance(n_masses, (int, np.integer)) or n_masses < 1:
            raise ProblemError(f"n_masses must be a positive integer, got {n_masses!r}")
        n = int(n_masses)
        mass_exact = _exact_scalar(mass, "mass")
        stiffness_exact = _exact_scalar(stiffness, "stiffness")
        if not (mass_exact > 0):
            raise ProblemError(f"mass must be positive, got {mass_exact}")
        if not (stiffness_exact > 0):
            raise ProblemError(f"stiffness must be positive, got {stiffness_exact}")
        M = sympy.eye(n) * mass_exact
        K = sympy.zeros(n, n)
        for j in range(n):
            K[j, j] = 2 * stiffness_exact
            if j + 1 < n:
                K[j, j + 1] = K[j + 1, j] = -stiffness_exact
        rows: list[list[sympy.Expr]] = []
        gaps: list[sympy.Expr] = []
        for k, spec in enumerate(unilateral):
            if isinstance(spec, (str, bytes)) or not isinstance(spec, Sequence) or len(spec) not in (2, 3):
                raise ProblemError(
                    f"unilateral spring {k} must be a pair (mass index, gap) or a triple "
                    f"(mass index, gap, direction), got {spec!r}"
                )
            index, gap = spec[0], spec[1]
            direction = spec[2] if len(spec) == 3 else 1
            if isinstance(index, bool) or not isinstance(index, (int, np.integer)) or not 0 <= index < n:
                raise ProblemError(
                    f"unilateral spring {k}: the mass index must be an integer in 0..{n - 1} "
                    f"(masses are indexed from 0), got {index!r}"
                )
            if direction not in (1, -1) or isinstance(direction, bool):
                raise ProblemError(f"unilateral spring {k}: direction must be +1 or -1, got {direction!r}")
            row = [sympy.Integer(0)] * n
            row[int(index)] = sympy.Integer(direction)
            rows.append(row)
            gaps.append(_exact_scalar(gap, f"gap of unilateral spring {k}"))
        laws: list[Any] = [UNILATERAL] * len(rows)
        for k, spec in enumerate(elements):
            if isinstance(spec, (str, bytes)) or not isinstance(spec, Sequence) or len(spec) not in (3, 4):
                raise ProblemError(f"element {k} must be (i, j, law) or (i, j, law, gap): the law f(u) acts on "
                                   f"u = X_i − X_j − gap (j = None: the ground), got {spec!r}")
            row = [sympy.Integer(0)] * n
            for index, sign in ((spec[0], 1), (spec[1], -1)):
                if index is None and sign == -1:
                    continue
                if isinstance(index, bool) or not isinstance(index, (int, np.integer)) or not 0 <= index < n:
                    raise ProblemError(f"element {k}: a mass index must be an integer in 0..{n - 1} (masses are "
                                       f"indexed from 0; the second may be None, the ground), got {index!r}")
                row[int(index)] += sign
            if all(entry == 0 for entry in row):
                raise ProblemError(f"element {k} acts on X_{spec[0]} − X_{spec[1]} = 0: join two different masses")
            rows.append(row)
            gaps.append(_exact_scalar(spec[3] if len(spec) == 4 else 0, f"gap of element {k}"))
            laws.append(spec[2])
        unilateral_only = all(law is UNILATERAL for law in laws)
        return cls(M=M, K=K, A=rows if rows else sympy.zeros(0, n), b=gaps, laws=None if unilateral_only else laws,
                   couplings=couplings)

    @classmethod
    def one_dof(cls, omega0: Any, a: Any = 1, b: Any = 0) -> "UnilateralSystem":
        """The one-degree-of-freedom problem ``u'' + ω0² u + ε (a u − b)_+ = 0``.

        ``M = [[1]]``, ``K = [[ω0²]]``, ``A = [[a]]``, gap ``b``, ``W = [[1]]``
        (so ``W = Aᵀ`` only when ``a = 1``).

        Examples
        --------
        >>> system = UnilateralSystem.one_dof(2, a="1/2", b=1)
        >>> system.K_exact[0, 0], system.A_exact[0, 0], system.W_exact[0, 0]
        (4, 1/2, 1)
        """
        omega0_exact = _exact_scalar(omega0, "omega0")
        if not (omega0_exact > 0):
            raise ProblemError(f"omega0 must be positive, got {omega0_exact}")
        a_exact = _exact_scalar(a, "a")
        if a_exact == 0:
            raise ProblemError("a must be non-zero, otherwise the unilateral spring never changes state")
        return cls(M=[[1]], K=[[omega0_exact**2]], A=[[a_exact]], b=[_exact_scalar(b, "b")], W=[[1]])

    @classmethod
    def from_json_dict(cls, data: Mapping[str, Any]) -> "UnilateralSystem":
        """Build from a mapping with keys ``M``, ``K``, ``A`` and optional ``b`` (default zeros), ``W``, ``laws`` and
        ``couplings`` — or, instead of ``A``, ``b``, ``W``, ``laws``, a list ``elements`` of
        ``{"law": f, "a": row, "b": offset, "w": column}`` (``law`` default ``Max(0, u)``, ``b`` default 0, ``w``
        default ``a``): the element's force ``ε w f(aᵀX − b)``.

        Entries may be numbers or exact strings (as written by :meth:`to_json_dict`).

        Examples
        --------
        >>> data = {"M": [["1"]], "K": [["4"]], "A": [["1"]], "b": ["1/3"]}
        >>> UnilateralSystem.from_json_dict(data).b_exact[0]
        1/3
        >>> chain = {"M": [[1, 0], [0, 1]], "K": [[2, -1], [-1, 2]],
        ...          "elements": [{"law": "u**3", "a": [1, -1]}, {"a": [0, 1], "b": "1/10"}]}
        >>> system = UnilateralSystem.from_json_dict(chain)
        >>> system.laws, system.A.tolist(), system.b.tolist()
        ((u**3, Max(0, u)), [[1.0, -1.0], [0.0, 1.0]], [0.0, 0.1])
        """
        if not isinstance(data, Mapping):
            raise ProblemError(f"from_json_dict expects a mapping with keys M, K, A, b (and optionally W), got {type(data).__name__}")
        unknown = sorted(set(data) - set(_JSON_KEYS))
        if unknown:
            raise ProblemError(f"unknown keys {unknown} in the system definition; the keys are M, K, A, b and optional W, "
                               "laws and couplings (or elements instead of A, b, W, laws)")
        if "elements" in data:
            clash = sorted(key for key in ("A", "b", "W", "laws") if key in data)
            if clash:
                raise ProblemError(f"the system definition gives both elements and {clash}: write every element in "
                                   "'elements' ({law, a, b, w}) or use the keys A, b, W, laws — not both")
            data = {**{key: value for key, value in data.items() if key != "elements"},
                    **_elements_as_matrices(data["elements"])}
        missing = [key for key in ("M", "K", "A") if key not in data]
        if missing:
            raise ProblemError(f"the system definition lacks the keys {missing}; give M, K and A (A = [] for none) or "
                               "elements, and b (may be omitted when every offset is 0)")
        return cls(M=data["M"], K=data["K"], A=data["A"], b=data.get("b"), W=data.get("W"), laws=data.get("laws"),
                   couplings=data.get("couplings"))

    def to_json_dict(self) -> dict[str, Any]:
        """Exact JSON-ready dictionary (entries as strings such as ``"1/3"``).

        ``W`` is written only when it differs from ``Aᵀ``, ``laws`` only when an element is not a unilateral
        spring, ``couplings`` only when given (``A``, ``b``, ``W`` and ``laws`` then hold the given elements only: the
        couplings' elements are derived again on reading).

        Examples
        --------
        >>> UnilateralSystem(M=[[1]], K=[[2]], A=[[1]], b=[0.25]).to_json_dict()
        {'M': [['1']], 'K': [['2']], 'A': [['1']], 'b': ['1/4']}
        """
        def matrix(exact: sympy.ImmutableMatrix) -> list[list[str]]:
            return [[_json_entry(exact[i, j]) for j in range(exact.cols)] for i in range(exact.rows)]

        m = self._given_elements
        A, W = self.A_exact[:m, :], self.W_exact[:, :m]
        data: dict[str, Any] = {
            "M": matrix(self.M_exact),
            "K": matrix(self.K_exact),
            "A": matrix(A),
            "b": [_json_entry(self.b_exact[i, 0]) for i in range(m)],
        }
        if not all(_exactly_equal(W[j, i], A[i, j]) for i in range(m) for j in range(self.n_dof)):
            data["W"] = matrix(W)
        if any(law != UNILATERAL for law in self.laws[:m]):
            data["laws"] = [str(law) for law in self.laws[:m]]
        if self.couplings is not None:
            data["couplings"] = [str(g) for g in self.couplings]
        return data

    # ------------------------------------------------------------ quantities
    @cached_property
    def _modes(self) -> Modes:
        frequencies, shapes = _float_modes(self.M, self.K)
        frequencies.setflags(write=False)
        shapes.setflags(write=False)
        return Modes(frequencies, shapes)

    @locked
    def modes_high_precision(self, digits: int) -> tuple[list[Any], list[list[Any]]]:
        """The modes of :meth:`modes` computed from the exact matrices to ``digits`` digits.

        The float modes of :meth:`modes` are refined in multiprecision (see :meth:`modal_coupling`);
        the result is the exact eigen-decomposition rounded to ``digits`` digits.

        Returns
        -------
        frequencies : list of mpmath.mpf
            λ_1 ≤ … ≤ λ_N.
        shapes : list of lists of mpmath.mpf
            ``shapes[k]`` is the mode shape of λ_{k+1} (ΦᵀMΦ = I), signed as in :meth:`modes`.

        Examples
        --------
        >>> import mpmath
        >>> lam, phi = UnilateralSystem.chain(2).modes_high_precision(30)
        >>> mpmath.nstr(lam[1], 25)
        '1.732050807568877293527446'
        """
        if isinstance(digits, bool) or not isinstance(digits, int) or digits < 1:
            raise ProblemError(f"digits must be a positive integer, got {digits!r}")
        return _high_precision_modes(self, digits)

    @locked
    def modal_coupling(self, digits: int) -> tuple[list[Any], list[list[Any]], list[list[Any]]]:
        """λ_k, ``B = A Φ`` (m×N) and ``G = Φᵀ W`` (N×m) to ``digits`` digits: all the modal normal form needs.

        The modes of :meth:`modes` (float64, LAPACK; tridiagonal or banded solvers when ``M`` is diagonal)
        are refined in fixed-point multiprecision a block of modes at a time: each sweep forms the exact
        residuals ``R = K X − M X Θ`` from the bands of K and M and corrects every mode in float64 — by a shifted
        banded solve with ``K − θ̃_k M`` when the band is narrow (O(N · bandwidth) a mode), else by its
        projections on the float modes, ``x_k −= Σ_{l≠k} x̃_l (x̃_lᵀ r_k)/(θ_l − θ_k)`` (O(N²)) — and θ_k is
        the final Rayleigh quotient (:mod:`lindstedt.problems.modes`).  The working precision adds guard bits
        for the spread of the θ_k and for the smallest gap, so every λ_k (not only the largest) and every B_ik,
        G_ki is accurate to ``digits`` digits.  Near-repeated frequencies fall back to a dense mpmath
        decomposition.  Every mode's full shape is refined: O(N²) numbers of ``digits`` digits per sweep.

        Examples
        --------
        >>> import mpmath
        >>> lam, B, G = UnilateralSystem.chain(2, unilateral=[(0, 0)]).modal_coupling(30)
        >>> mpmath.nstr(B[0][1], 25), mpmath.nstr(G[1][0], 25)    # 1/sqrt(2)
        ('0.7071067811865475244008444', '0.7071067811865475244008444')
        """
        if isinstance(digits, bool) or not isinstance(digits, int) or digits < 1:
            raise ProblemError(f"digits must be a positive integer, got {digits!r}")
        cache = self.__dict__.setdefault("_coupling_cache", {})  # O(N·m) numbers per precision (frozen: not a field)
        if digits not in cache:
            cache[digits] = _modal_coupling(self, digits)
        frequencies, B, G = cache[digits]
        return list(frequencies), [list(row) for row in B], [list(row) for row in G]

    def modes(self) -> Modes:
        """Linear normal modes: ``K Φ = M Φ diag(λ²)`` with ``Φᵀ M Φ = I``.

        Returns
        -------
        Modes
            ``(frequencies, shapes)``: λ increasing, and Φ column by column.

        Notes
        -----
        Sign convention: each mode shape is signed so that its entry of largest
        magnitude is positive; when several entries tie (magnitudes equal to a
        relative 1e-9, as in symmetric chains) the first of them (lowest index)
        decides.  Within a repeated frequency the basis is the one returned by
        LAPACK and is not otherwise normalised.

        Examples
        --------
        >>> lam, phi = UnilateralSystem.chain(2).modes()
        >>> lam.round(12).tolist()
        [1.0, 1.732050807569]
        >>> (phi * 2**0.5).round(12).tolist()
        [[1.0, 1.0], [1.0, -1.0]]
        """
        return self._modes

    @cached_property
    @locked  # sympy: integration and lambdify
    def _element_laws_numeric(self) -> tuple[tuple[Any, ...], tuple[Any, ...] | None]:
        """The laws f_i and their potentials V_i(u) = ∫_0^u f_i as NumPy functions (potentials None when one has
        no closed form)."""
        s = sympy.Symbol("s", real=True)
        forces, potentials = [], []
        for law in self.laws:
            forces.append(sympy.lambdify(LAW_VARIABLE, law, "numpy"))
            potential = sympy.integrate(law.subs(LAW_VARIABLE, s).rewrite(sympy.Piecewise), (s, 0, LAW_VARIABLE))
            potentials.append(None if potential.has(sympy.Integral) else sympy.lambdify(LAW_VARIABLE, potential, "numpy"))
        return tuple(forces), (None if any(p is None for p in potentials) else tuple(potentials))

    def _element_forces(self, gaps: np.ndarray) -> np.ndarray:
        """``f_i(g_i)`` for gaps of shape (..., m)."""
        if self.unilateral:
            return np.maximum(gaps, 0.0)
        forces, _ = self._element_laws_numeric
        with np.errstate(invalid="ignore", divide="ignore"):  # NumPy evaluates every branch of a Piecewise
            return np.stack([np.broadcast_to(f(gaps[..., i]), gaps.shape[:-1]) for i, f in enumerate(forces)],
                            axis=-1).astype(float)

    def _element_potentials(self, gaps: np.ndarray) -> np.ndarray:
        """``V_i(g_i)`` for gaps of shape (..., m)."""
        if self.unilateral:
            return 0.5 * np.maximum(gaps, 0.0) ** 2
        _, potentials = self._element_laws_numeric
        if potentials is None:
            raise UnsupportedNonlinearityError(
                f"the energy needs the potential ∫f of every law, and one of [{', '.join(map(str, self.laws))}] has "
                "no closed form; use a law whose antiderivative sympy finds, or the modal amplitude")
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.stack([np.broadcast_to(V(gaps[..., i]), gaps.shape[:-1]) for i, V in enumerate(potentials)],
                            axis=-1).astype(float)

    def gaps(self, x: Any) -> np.ndarray:
        """Gap functions ``A X − b`` (positive: spring engaged); ``x`` has shape (..., N).

        Examples
        --------
        >>> UnilateralSystem.chain(2, [(1, 0.5)]).gaps([0.0, 1.0]).tolist()
        [0.5]
        """
        positions = np.asarray(x, dtype=float)
        return positions @ self.A.T - self.b

    def acceleration(self, x: Any, epsilon: float) -> np.ndarray:
        """``X'' = −M⁻¹ (K X + ε W f(A X − b))`` for positions of shape (..., N) (f the elements' laws).

        Examples
        --------
        >>> UnilateralSystem.one_dof(1).acceleration([2.0], 0.5).tolist()
        [-3.0]
        """
        positions = np.asarray(x, dtype=float)
        force = positions @ self.K.T + epsilon * self._element_forces(self.gaps(positions)) @ self.W.T
        return -np.linalg.solve(self.M, force.reshape(-1, self.n_dof).T).T.reshape(force.shape)

    def energy(self, x: Any, v: Any, epsilon: float) -> np.ndarray | float:
        """``E = ½ X'ᵀ M X' + ½ Xᵀ K X + ε Σ_i V_i(A_i X − b_i)`` (requires ``W = Aᵀ``).

        ``V_i(u) = ∫_0^u f_i`` is the potential of element i's law (``½ u_+²`` for a unilateral spring), integrated
        exactly once per system; a law whose potential has no closed form raises
        :class:`~lindstedt.UnsupportedNonlinearityError`.

        ``x`` and ``v`` have shape (..., N); the result has shape (...).

        Examples
        --------
        >>> UnilateralSystem.one_dof(1).energy([2.0], [1.0], 0.5)
        3.5
        """
        if not self.symmetric_coupling:
            raise ProblemError("the energy E is conserved only for W = Aᵀ; this system has W ≠ Aᵀ")
        positions = np.asarray(x, dtype=float)
        velocities = np.asarray(v, dtype=float)
        kinetic = 0.5 * np.einsum("...i,ij,...j->...", velocities, self.M, velocities)
        potential = 0.5 * np.einsum("...i,ij,...j->...", positions, self.K, positions)
        contact = epsilon * np.sum(self._element_potentials(self.gaps(positions)), axis=-1)
        total = kinetic + potential + contact
        return float(total) if np.ndim(total) == 0 else total


def _elements_as_matrices(elements: Any) -> dict[str, Any]:
    """A, b, W, laws from a JSON list of elements ``{law, a, b, w}`` (shapes checked by the constructor)."""
    if not isinstance(elements, (list, tuple)):
        raise ProblemError(f"elements must be a list of {{law, a, b, w}} objects, got {type(elements).__name__}")
    rows, offsets, columns, laws = [], [], [], []
    for index, element in enumerate(elements):
        if not isinstance(element, Mapping) or "a" not in element:
            raise ProblemError(f"elements[{index}] must be an object with at least 'a' (the row a of aᵀX) and "
                               f"optional law, b, w; got {element!r}")
        unknown = sorted(set(element) - set(_ELEMENT_KEYS))
        if unknown:
            raise ProblemError(f"elements[{index}] has unknown keys {unknown}; the keys are law, a, b, w")
        rows.append(element["a"])
        offsets.append(element.get("b", 0))
        columns.append(element.get("w", element["a"]))
        laws.append(element.get("law", "Max(0, u)"))
    if not rows:
        return {"A": [], "b": []}
    if any(not isinstance(column, (list, tuple)) for column in columns):
        raise ProblemError("every element's a and w must be lists with one entry per degree of freedom")
    width = len(columns[0])
    if any(len(column) != width for column in columns):
        raise ProblemError("every element's w must have one entry per degree of freedom (the size of M)")
    W = [[column[i] for column in columns] for i in range(width)]
    return {"A": rows, "b": offsets, "W": W, "laws": laws}


@locked
def OneDofUnilateral(omega0: Any, a: Any = 1, b: Any = 0) -> UnilateralSystem:
    """Factory for ``u'' + ω0² u + ε (a u − b)_+ = 0`` (same as :meth:`UnilateralSystem.one_dof`).

    Examples
    --------
    >>> OneDofUnilateral(1).to_json_dict()
    {'M': [['1']], 'K': [['1']], 'A': [['1']], 'b': ['0']}
    """
    return UnilateralSystem.one_dof(omega0, a, b)
