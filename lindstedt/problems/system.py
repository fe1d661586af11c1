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

``(·)_+ = max(·, 0)`` acts entrywise.  Every matrix is stored twice: exactly
(``sympy.ImmutableMatrix``; the string ``"0.1"`` is read as ``1/10``, the float
``0.1`` as its exact binary value) and as a read-only float ``numpy`` array (the correctly rounded
values of the exact entries).  The N-dof setting is section 4 of the seed
paper, whose force term ``ε (Ã X − B)_+`` is the special case ``W = I``.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from functools import cached_property
from typing import Any, Iterable, Mapping, NamedTuple, Sequence

import mpmath
import numpy as np
import sympy

from .._errors import ProblemError
from .parsing import parse_real

__all__ = ["UnilateralSystem", "Modes", "OneDofUnilateral"]

# Two entries of a mode shape whose magnitudes agree to this relative
# tolerance count as tied for "largest" in the sign convention of modes().
_MODE_SIGN_TIE_RTOL = 1e-9

_JSON_KEYS = ("M", "K", "A", "b", "W")


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


def _leading_sign(column: Sequence[Any]) -> int:
    """±1 making the first entry of largest magnitude (ties within a relative 1e-9) positive."""
    largest = max(abs(value) for value in column)
    for value in column:
        if abs(value) >= largest * (1 - _MODE_SIGN_TIE_RTOL):
            return 1 if value > 0 else -1
    return 1


# --------------------------------------------------------------------------- #
# exact conversion of user input
# --------------------------------------------------------------------------- #
def _exact_scalar(value: Any, what: str) -> sympy.Expr:
    """One entry as an exact, finite, real sympy number (read by the one parser; a float is its binary value)."""
    if isinstance(value, np.bool_):
        raise ProblemError(f"{what} is a boolean ({value}); give a number such as 1, 0.5 or '1/3'")
    if isinstance(value, np.generic):
        value = value.item()
    return parse_real(value, what=what)


def _exact_to_float(expr: sympy.Expr) -> float:
    """Correctly rounded float of an exact number."""
    if isinstance(expr, sympy.Rational):
        return float(Fraction(int(expr.p), int(expr.q)))
    return float(sympy.N(expr, 40))


def _exact_matrix(value: Any, name: str, *, ndim: int) -> sympy.ImmutableMatrix:
    """Convert nested sequences / numpy arrays / sympy matrices (ndim 1 or 2)."""
    if isinstance(value, sympy.MatrixBase):
        rows = [[value[i, j] for j in range(value.cols)] for i in range(value.rows)]
        if ndim == 1:
            if value.cols == 1:
                rows = [row[0] for row in rows]
            elif value.rows == 1:
                rows = list(rows[0]) if rows else []
            else:
                raise ProblemError(f"{name} must be a vector, got a {value.rows}×{value.cols} matrix")
        value = rows
    if isinstance(value, np.ndarray):
        if value.dtype.kind == "c":
            raise ProblemError(f"{name} is complex; the matrices of the system must be real")
        if value.ndim != ndim:
            raise ProblemError(
                f"{name} must be {'a vector (1-D)' if ndim == 1 else 'a matrix (2-D)'}, "
                f"got an array of shape {value.shape}"
            )
        value = value.tolist()
    if isinstance(value, (str, bytes)) or not isinstance(value, (Sequence, np.ndarray)):
        raise ProblemError(
            f"{name} must be {'a vector' if ndim == 1 else 'a matrix'} given as nested lists, a numpy array "
            f"or a sympy Matrix, got {type(value).__name__}"
        )
    if ndim == 1:
        entries = [_exact_scalar(entry, f"{name}[{i}]") for i, entry in enumerate(value)]
        return sympy.ImmutableMatrix(len(entries), 1, entries)
    rows = list(value)
    if not rows:
        return sympy.ImmutableMatrix(0, 0, [])
    widths = set()
    for i, row in enumerate(rows):
        if isinstance(row, (str, bytes)) or not isinstance(row, (Sequence, np.ndarray)):
            raise ProblemError(
                f"{name} must be a matrix (a list of rows); row {i} is {row!r}. "
                f"Wrap a single row in brackets, e.g. {name}=[[1, 0]]"
            )
        widths.add(len(row))
    if len(widths) != 1:
        raise ProblemError(f"the rows of {name} have different lengths {sorted(widths)}; every row needs the same length")
    entries = [_exact_scalar(entry, f"{name}[{i}, {j}]") for i, row in enumerate(rows) for j, entry in enumerate(row)]
    return sympy.ImmutableMatrix(len(rows), widths.pop(), entries)


def _float_array(matrix: sympy.ImmutableMatrix, *, vector: bool = False) -> np.ndarray:
    array = np.array([[_exact_to_float(matrix[i, j]) for j in range(matrix.cols)] for i in range(matrix.rows)], dtype=float)
    array = array.reshape(matrix.rows, matrix.cols)
    if vector:
        array = array.reshape(matrix.rows)
    array.setflags(write=False)
    return array


def _exactly_equal(first: sympy.Expr, second: sympy.Expr) -> bool:
    return first == second or sympy.simplify(first - second) == 0


def _check_symmetric_positive_definite(exact: sympy.ImmutableMatrix, numeric: np.ndarray, name: str, role: str) -> None:
    n = exact.rows
    for i in range(n):
        for j in range(i + 1, n):
            if not _exactly_equal(exact[i, j], exact[j, i]):
                raise ProblemError(
                    f"{name} ({role}) must be symmetric but {name}[{i}, {j}] = {exact[i, j]} while "
                    f"{name}[{j}, {i}] = {exact[j, i]}; if the difference is rounding, pass ({name} + {name}.T)/2"
                )
    try:
        np.linalg.cholesky(numeric)
    except np.linalg.LinAlgError:
        smallest = float(np.linalg.eigvalsh(numeric)[0])
        raise ProblemError(
            f"{name} ({role}) must be positive definite but its Cholesky factorisation fails "
            f"(smallest eigenvalue ≈ {smallest:.3g}); check the signs of its diagonal and that no "
            "degree of freedom is left without mass or spring"
        ) from None


def _json_entry(expr: sympy.Expr) -> str:
    return str(expr)


# --------------------------------------------------------------------------- #
# the problem
# --------------------------------------------------------------------------- #
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
    b : array_like, shape (m,)
        Gaps (any sign; ``b_i < 0`` is a preloaded spring).
    W : array_like, shape (N, m), optional
        Distribution of the spring forces on the masses; default ``Aᵀ``
        (the conservative case, with energy ``E`` of :meth:`energy`).

    Entries may be ints, floats, ``fractions.Fraction``, exact strings such as
    ``"1/3"`` or ``"sqrt(2)"``, or sympy numbers; decimal floats and strings are
    read exactly (``0.1`` → ``1/10``).

    Attributes
    ----------
    M, K, A, b, W : numpy.ndarray
        Read-only float copies (correctly rounded from the exact values).
    M_exact, K_exact, A_exact, b_exact, W_exact : sympy.ImmutableMatrix
        Exact copies (``b_exact`` is a column).

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

    def __init__(self, M: Any, K: Any, A: Any = (), b: Any = (), W: Any | None = None) -> None:
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
        b_exact = _exact_matrix(b, "b", ndim=1)
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

    def _key(self) -> tuple:
        return (self.M_exact, self.K_exact, self.A_exact, self.b_exact, self.W_exact)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, UnilateralSystem):
            return NotImplemented
        return self._key() == other._key()

    def __hash__(self) -> int:
        return hash(self._key())

    def __repr__(self) -> str:
        coupling = "W=Aᵀ" if self.symmetric_coupling else "W≠Aᵀ"
        return f"UnilateralSystem(N={self.n_dof}, m={self.n_springs}, {coupling})"

    # ------------------------------------------------------------ constructors
    @classmethod
    def chain(
        cls,
        n_masses: int,
        unilateral: Iterable[Sequence[Any]] = (),
        *,
        mass: Any = 1,
        stiffness: Any = 1,
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

        Examples
        --------
        >>> chain = UnilateralSystem.chain(3, unilateral=[(0, 0), (2, "1/2", -1)])
        >>> chain.K.tolist()
        [[2.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 2.0]]
        >>> chain.A.tolist(), chain.b.tolist()
        ([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0]], [0.0, 0.5])
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
        return cls(M=M, K=K, A=rows if rows else sympy.zeros(0, n), b=gaps)

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
        """Build from a mapping with keys ``M``, ``K``, ``A``, ``b`` and optional ``W``.

        Entries may be numbers or exact strings (as written by :meth:`to_json_dict`).

        Examples
        --------
        >>> data = {"M": [["1"]], "K": [["4"]], "A": [["1"]], "b": ["1/3"]}
        >>> UnilateralSystem.from_json_dict(data).b_exact[0]
        1/3
        """
        if not isinstance(data, Mapping):
            raise ProblemError(f"from_json_dict expects a mapping with keys M, K, A, b (and optionally W), got {type(data).__name__}")
        unknown = sorted(set(data) - set(_JSON_KEYS))
        if unknown:
            raise ProblemError(f"unknown keys {unknown} in the system definition; the keys are M, K, A, b and optional W")
        missing = [key for key in ("M", "K", "A", "b") if key not in data]
        if missing:
            raise ProblemError(f"the system definition lacks the keys {missing}; give M, K, A, b (A = [] and b = [] for none)")
        return cls(M=data["M"], K=data["K"], A=data["A"], b=data["b"], W=data.get("W"))

    def to_json_dict(self) -> dict[str, Any]:
        """Exact JSON-ready dictionary (entries as strings such as ``"1/3"``).

        ``W`` is written only when it differs from ``Aᵀ``.

        Examples
        --------
        >>> UnilateralSystem(M=[[1]], K=[[2]], A=[[1]], b=[0.25]).to_json_dict()
        {'M': [['1']], 'K': [['2']], 'A': [['1']], 'b': ['1/4']}
        """
        def matrix(exact: sympy.ImmutableMatrix) -> list[list[str]]:
            return [[_json_entry(exact[i, j]) for j in range(exact.cols)] for i in range(exact.rows)]

        data: dict[str, Any] = {
            "M": matrix(self.M_exact),
            "K": matrix(self.K_exact),
            "A": matrix(self.A_exact),
            "b": [_json_entry(self.b_exact[i, 0]) for i in range(self.n_springs)],
        }
        if not self.symmetric_coupling:
            data["W"] = matrix(self.W_exact)
        return data

    # ------------------------------------------------------------ quantities
    @cached_property
    def _modes(self) -> Modes:
        import scipy.linalg  # here, not at module level: import lindstedt stays light
        squared, shapes = scipy.linalg.eigh(self.K, self.M)
        frequencies = np.sqrt(squared)
        shapes = np.array(shapes)
        for k in range(self.n_dof):
            shapes[:, k] *= _leading_sign(shapes[:, k].tolist())
        frequencies.setflags(write=False)
        shapes.setflags(write=False)
        return Modes(frequencies, shapes)

    def modes_high_precision(self, digits: int) -> tuple[list[Any], list[list[Any]]]:
        """The modes of :meth:`modes` computed from the exact matrices with mpmath at ``digits`` digits.

        Returns
        -------
        frequencies : list of mpmath.mpf
            λ_1 ≤ … ≤ λ_N.
        shapes : list of lists of mpmath.mpf
            ``shapes[k]`` is the mode shape of λ_{k+1} (ΦᵀMΦ = I), signed by the convention of :meth:`modes`.

        Examples
        --------
        >>> import mpmath
        >>> lam, phi = UnilateralSystem.chain(2).modes_high_precision(30)
        >>> mpmath.nstr(lam[1], 25)
        '1.732050807568877293527446'
        """
        def number(value: sympy.Expr) -> Any:
            return mpmath.mpf(value.p) / value.q if value.is_Rational else mpmath.mpf(sympy.N(value, digits + 5))

        with mpmath.workdps(digits):
            mass = mpmath.matrix([[number(v) for v in row] for row in self.M_exact.tolist()])
            stiffness = mpmath.matrix([[number(v) for v in row] for row in self.K_exact.tolist()])
            inverse_lower = mpmath.inverse(mpmath.cholesky(mass))
            symmetric = inverse_lower * stiffness * inverse_lower.T
            eigenvalues, eigenvectors = mpmath.eigsy((symmetric + symmetric.T) / 2)
            shapes_matrix = inverse_lower.T * eigenvectors
            frequencies, shapes = [], []
            for index in sorted(range(len(eigenvalues)), key=lambda i: eigenvalues[i]):
                frequencies.append(mpmath.sqrt(eigenvalues[index]))
                column = [shapes_matrix[row, index] for row in range(self.n_dof)]
                sign = _leading_sign(column)
                shapes.append([sign * value for value in column])
            return frequencies, shapes

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
        """``X'' = −M⁻¹ (K X + ε W (A X − b)_+)`` for positions of shape (..., N).

        Examples
        --------
        >>> UnilateralSystem.one_dof(1).acceleration([2.0], 0.5).tolist()
        [-3.0]
        """
        positions = np.asarray(x, dtype=float)
        force = positions @ self.K.T + epsilon * np.maximum(self.gaps(positions), 0.0) @ self.W.T
        return -np.linalg.solve(self.M, force.reshape(-1, self.n_dof).T).T.reshape(force.shape)

    def energy(self, x: Any, v: Any, epsilon: float) -> np.ndarray | float:
        """``E = ½ X'ᵀ M X' + ½ Xᵀ K X + ½ ε Σ_i (A_i X − b_i)_+²`` (requires ``W = Aᵀ``).

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
        contact = 0.5 * epsilon * np.sum(np.maximum(self.gaps(positions), 0.0) ** 2, axis=-1)
        total = kinetic + potential + contact
        return float(total) if np.ndim(total) == 0 else total


def OneDofUnilateral(omega0: Any, a: Any = 1, b: Any = 0) -> UnilateralSystem:
    """Factory for ``u'' + ω0² u + ε (a u − b)_+ = 0`` (same as :meth:`UnilateralSystem.one_dof`).

    Examples
    --------
    >>> OneDofUnilateral(1).to_json_dict()
    {'M': [['1']], 'K': [['1']], 'A': [['1']], 'b': ['0']}
    """
    return UnilateralSystem.one_dof(omega0, a, b)
