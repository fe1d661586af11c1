"""Modal truncation with residual flexibility: a large structure reduced to its low modes and one static vector
per element, projected in multiprecision.

The structure ``M X'' + K X + ε Σ_i w_i f_i(a_iᵀ X − b_i) = 0`` (N dof, sparse: a finite-element model) is
written ``X = V q`` on the basis

    ``V = [Φ_K, Z]``,   ``Φ_K`` the K lowest modes,   ``Z = K⁻¹ W − Φ_K (Φ_Kᵀ M K⁻¹ W)``,

``Z`` the **residual flexibility** — the static response to the elements' forces that the kept modes miss
(MacNeal 1971; Rubin 1975; Craig & Kurdila, *Fundamentals of Structural Dynamics*, 2006, §17.3): the modes above
the cut respond to the element forces nearly statically, their periods being short against the NNM's.  The
Galerkin (Rayleigh–Ritz) projection

    ``(VᵀMV) q'' + (VᵀKV) q + ε Σ_i (Vᵀ w_i) f_i((a_iᵀ V) q − b_i) = 0``

is a :class:`~lindstedt.problems.system.UnilateralSystem` of K + m dof with the same laws, which every engine
takes (strained coordinates, shooting, forced responses).  A forced problem's load shapes ``P`` join ``W`` in the
static residuals (``Z = K⁻¹[W, P] − …``), and ``Vᵀ P`` is the reduced load; residual vectors that the kept modes
and one another already span are dropped (two stops on one dof, a load on a contact dof).  The truncation is a model reduction, not an exact
step: ``ω₀`` and ``ω₁`` of an NNM of a kept mode are those of the full model to the working precision (the mode
is in the basis), ``ω₂`` and beyond carry the truncation error.  Measured against the full 201-dof cracked
cantilever (all 201 modes, 30 digits), relative errors of ω₂: K modes alone 0.9 at K = 2 and still 0.22 at
K = 32 (the forces' quasi-static share is missing); with the residual vector 1.5e-4 at K = 2, 3.5e-7 at K = 4…8
(modes 5…8 add little: their curvature nearly vanishes at the crack), 1e-10 at 12, 2.4e-11 at 16, 1e-12 at 32
(``tests/test_reduction.py``).  The error is mesh-dependent: 1.6e-6 at K = 4 and 8 on the 801-dof mesh
(``benchmarks/bench_structures.py``); compare two K to judge it.  A spectrum near the harmonics of the motion
converges slowly: a string-like chain (λ_k ≈ k λ₁) forced into contact at its first frequency errs by 3e-2, 2e-3
and 4e-4 (relative displacement) at K = 4, 8, 16 (a slow test), where the beam's spectrum (λ_k ≈ k² λ₁) gives folds
of the forced response agreeing to 3e-11 between K = 4 and 8.  Reducing a reduced model again to K' < K modes
gives the K'-reduction of the full model exactly (its basis spans K⁻¹W), so that comparison costs no large solve.

**Precision.**  A float64 factorisation of a fine mesh loses ``eps · cond(K)`` (λ₁ of the float Lanczos
modes is 1e-3 off at 10⁴ dof), so the basis is computed in multiprecision (gmpy2 ``mpfr`` at the working digits
plus ``log10 cond(K)`` and guard digits): ``K = L D Lᵀ`` in its band after a reverse Cuthill–McKee ordering —
O(N b²) for the factorisation, O(N b) per right-hand side, O(N · (K + m)) numbers kept — and subspace
iteration with a Rayleigh–Ritz step (Bathe & Wilson 1972) from the float Lanczos modes, accelerated by Chebyshev
polynomials (Rutishauser 1970): between two Ritz steps the q columns X advance by ``T_s(2θ_q K⁻¹M − I) X``, which
damps the modes above the last Ritz value θ_q and lifts mode K by ``T_s(x)``, ``x = 2θ_q/θ_K − 1`` — a Ritz
value's error falls by ``(x + √(x² − 1))²`` a step, against ``(θ_q/θ_K)²`` for plain inverse iteration (5.5 against
2.3 bits a step on a string-like chain with K = 8, q = 12).  The iteration stops when the K Ritz values are
stationary to twice the working precision (the vectors then to the working precision): when their last change
times the slower of the observed and the predicted rate is below 2^-2t.  The small Ritz eigenproblems are solved
in mpfr by Jacobi sweeps from float64 eigenvectors.
Products with K cancel up to log2 cond(K) bits, which the working precision holds in reserve.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

import mpmath
import numpy as np
import sympy

from .._budget import Estimate, checkpoint
from .._errors import ProblemError
from .._mpfr import mpf_of_mpfr, mpfr_of_mpf
from .._precision import warn_caller
from .modes import _leading_sign, _leading_signs
from .system import UnilateralSystem

__all__ = ["ResidualFlexibility", "ReducedStructure"]

#: CPU seconds of one multiprecision operation of the reduction (gmpy2 mpfr in numpy object arrays, ~360 bits),
#: fitted to the measured CPU time of the operation count of :meth:`ResidualFlexibility.estimate` at the
#: iterations done: 1.15e-7 and 1.35e-7 on a chain of 1000 and 2000 dof (b = 1), 1.25e-7 on beams of 400 and
#: 1000 dof (b = 4); the float modes, the checks and imports make small models dearer per operation
_SECONDS_PER_OPERATION = 1.3e-7
_MAX_ITERATIONS = 60
#: Chebyshev steps between two Ritz steps at most, and the bits held in reserve for the columns' drift between them
_MAX_STEPS = 8
_GUARD_BITS = 96
#: cyclic Jacobi sweeps allowed on a small symmetric matrix (from float64 eigenvectors: 3–4 reach 400 bits)
_MAX_SWEEPS = 12


def _gmpy2() -> Any:
    import gmpy2

    return gmpy2


def _rational(value: Any, name: str = "an entry") -> Any:
    """An exact number (int, float, Fraction, sympy number) as a gmpy2 mpq, or a real sympy number kept as it is
    (an irrational entry, rounded by :func:`_mpfr` at the working precision)."""
    gmpy2 = _gmpy2()
    if isinstance(value, (bool, np.bool_)):
        raise ProblemError(f"{name} must be a real number, got {value!r}")
    if isinstance(value, (int, np.integer)):
        return gmpy2.mpq(int(value))
    if isinstance(value, (float, np.floating)):
        if not np.isfinite(value):
            raise ProblemError(f"{name} must be finite, got {value!r}")
        return gmpy2.mpq(float(value))
    if isinstance(value, Fraction):
        return gmpy2.mpq(value.numerator, value.denominator)
    if isinstance(value, sympy.Basic) and value.is_number and value.is_real and value.is_finite:
        return gmpy2.mpq(int(value.p), int(value.q)) if value.is_Rational else value
    raise ProblemError(f"{name} must be a real number (int, float, Fraction or a sympy number), got {value!r:.60}")


def _mpfr(value: Any) -> Any:
    """An entry of :func:`_rational` as an mpfr at the current gmpy2 precision."""
    gmpy2 = _gmpy2()
    if isinstance(value, sympy.Basic):
        return gmpy2.mpfr(str(sympy.N(value, int(gmpy2.get_context().precision * 0.302) + 5)))
    return gmpy2.mpfr(value)


def _entries(matrix: Any, rows: int, cols: int, name: str) -> dict[tuple[int, int], Any]:
    """The nonzero entries ``(i, j) -> exact value`` of a scipy.sparse, numpy or sympy matrix of shape (rows, cols)."""
    import scipy.sparse

    if isinstance(matrix, sympy.MatrixBase):
        if matrix.shape != (rows, cols):
            raise ProblemError(f"{name} is {matrix.shape[0]}×{matrix.shape[1]}, expected {rows}×{cols}")
        pairs = matrix.todok().items()
    else:
        if scipy.sparse.issparse(matrix):
            coo = scipy.sparse.coo_matrix(matrix)
        else:
            array = np.asarray(matrix)
            if array.dtype == object or not np.issubdtype(array.dtype, np.number) or np.iscomplexobj(array):
                raise ProblemError(f"{name} must be a real numeric matrix (numpy, scipy.sparse or sympy), got {matrix!r:.80}")
            coo = scipy.sparse.coo_matrix(np.asarray(np.atleast_2d(array), dtype=float))  # no copy of a float array
        if coo.shape != (rows, cols):
            raise ProblemError(f"{name} is {coo.shape[0]}×{coo.shape[1]}, expected {rows}×{cols}")
        if np.iscomplexobj(coo.data) or not np.all(np.isfinite(coo.data)):
            raise ProblemError(f"{name} has a complex or non-finite entry; give finite real numbers")
        summed: dict[tuple[int, int], float] = {}
        for i, j, v in zip(coo.row.tolist(), coo.col.tolist(), coo.data.tolist()):
            summed[i, j] = summed.get((i, j), 0.0) + v
        pairs = summed.items()
    return {key: _rational(value, f"{name}[{key[0]}, {key[1]}]") for key, value in pairs if value != 0}


def _check_symmetric(entries: dict[tuple[int, int], Any], name: str) -> None:
    """Refuse a matrix whose entries (i, j) and (j, i) differ by more than 1e-12 of its largest entry."""
    largest = max((abs(float(value)) for value in entries.values()), default=0.0)
    for (i, j), value in entries.items():
        if i < j and abs(float(value) - float(entries.get((j, i), 0))) > 1e-12 * largest:
            raise ProblemError(f"{name} is not symmetric: entries ({i}, {j}) and ({j}, {i}) differ; give the full "
                               f"symmetric matrix (not one triangle), or ({name} + {name}ᵀ)/2 if the difference is rounding")


class _BandedLDL:
    """``P S Pᵀ = L D Lᵀ`` of a symmetric positive definite sparse matrix S in its band, P the reverse
    Cuthill–McKee ordering, in gmpy2 mpfr at the context's precision; solves on object arrays of columns."""

    def __init__(self, entries: dict[tuple[int, int], Any], n: int) -> None:
        import scipy.sparse
        from scipy.sparse.csgraph import reverse_cuthill_mckee

        gmpy2 = _gmpy2()
        keys = list(entries)
        pattern = scipy.sparse.csr_matrix((np.ones(len(keys)), ([k[0] for k in keys], [k[1] for k in keys])), shape=(n, n))
        order = np.asarray(reverse_cuthill_mckee(pattern, symmetric_mode=True), dtype=np.int64)
        position = np.empty(n, dtype=np.int64)
        position[order] = np.arange(n)
        self.order, self.n = order, n
        rows: list[dict[int, Any]] = [{} for _ in range(n)]
        width = 0
        for (i, j), value in entries.items():
            p, q = int(position[i]), int(position[j])
            if q <= p:
                rows[p][q] = _mpfr(value)
                width = max(width, p - q)
        self.width = width
        lower: list[list[tuple[int, Any]]] = []
        diagonal: list[Any] = []
        zero = gmpy2.mpfr(0)
        for i in range(n):
            start = max(0, i - width)
            row = [rows[i].get(j, zero) for j in range(start, i + 1)]
            # row[j - start] becomes L[i, j] D[j] while the later entries are reduced (Crout, band of width b)
            for j in range(start, i):
                total = row[j - start]
                for k, lik_dk in lower[j]:  # L[j, k] for k < j, stored as (k, L[j, k])
                    if k >= start:
                        total -= row[k - start] * lik_dk
                row[j - start] = total
            entries_i = []
            total = row[i - start]
            for j in range(start, i):
                l_ij = row[j - start] / diagonal[j]
                total -= l_ij * row[j - start]
                if l_ij:
                    entries_i.append((j, l_ij))
            if not total > 0:
                raise ProblemError("K is not positive definite (a non-positive pivot in its L D Lᵀ factorisation): the "
                                   "structure is a mechanism; fix its supports")
            diagonal.append(total)
            lower.append(entries_i)
        # the band of L by rows (forward sweep) and by columns (Lᵀ sweep) as small object arrays: one dot per row
        # (rows and columns of L with no entry off the diagonal left out)
        self._rows: list[tuple[int, int, np.ndarray]] = []
        by_column: list[list[tuple[int, Any]]] = [[] for _ in range(n)]
        for i, entries in enumerate(lower):
            if entries:
                start = entries[0][0]
                coefficients = [zero] * (i - start)
                for j, l_ij in entries:
                    coefficients[j - start] = l_ij
                    by_column[j].append((i, l_ij))
                self._rows.append((i, start, np.array(coefficients, dtype=object)))
        self._columns: list[tuple[int, int, np.ndarray]] = []
        for j in range(n - 1, -1, -1):  # in the order of the Lᵀ sweep
            if by_column[j]:
                stop = by_column[j][-1][0] + 1
                coefficients = [zero] * (stop - j - 1)
                for i, l_ij in by_column[j]:
                    coefficients[i - j - 1] = l_ij
                self._columns.append((j, stop, np.array(coefficients, dtype=object)))
        self._diagonal = np.array(diagonal, dtype=object)[:, None]

    def solve(self, columns: np.ndarray, scale: Any = 1) -> np.ndarray:
        """``scale · S⁻¹ columns`` for an (n, c) object array of mpfr (one small dot per row and sweep: the band's
        entries of a row, or of a column of L, against the rows of the right-hand side they meet; ``scale`` joins
        the division by D)."""
        subtract = np.subtract
        y = columns[self.order]
        for i, start, coefficients in self._rows:  # L: y_i = c_i − Σ_{j < i} L[i, j] y_j, in place
            row = y[i]
            subtract(row, coefficients.dot(y[start:i]), out=row)
        y = y / self._diagonal if scale == 1 else y * (scale / self._diagonal)
        for j, stop, coefficients in self._columns:  # Lᵀ: x_j = y_j − Σ_{i > j} L[i, j] x_i
            row = y[j]
            subtract(row, coefficients.dot(y[j + 1:stop]), out=row)
        result = np.empty_like(y)
        result[self.order] = y
        return result


class _SparseProduct:
    """``S @ columns`` for exact sparse entries, in mpfr, grouped by diagonal (vectorised over rows)."""

    def __init__(self, entries: dict[tuple[int, int], Any], n: int) -> None:
        by_offset: dict[int, tuple[list[int], list[Any]]] = {}
        for (i, j), value in entries.items():
            rows, values = by_offset.setdefault(j - i, ([], []))
            rows.append(i)
            values.append(_mpfr(value))
        self.diagonals = []
        for offset, (rows, values) in by_offset.items():
            order = np.argsort(rows)
            rows_sorted = np.array(rows, dtype=np.int64)[order]
            column = np.array(values, dtype=object)[order][:, None]
            if rows_sorted[-1] - rows_sorted[0] + 1 == len(rows_sorted):  # a full stretch of the diagonal: slices
                first, last = int(rows_sorted[0]), int(rows_sorted[-1]) + 1
                self.diagonals.append((slice(first, last), slice(first + offset, last + offset), column))
            else:
                self.diagonals.append((rows_sorted, rows_sorted + offset, column))
        # a diagonal meeting every row (the main one of a mass or stiffness matrix) first: it sets the result
        def full(diagonal: tuple) -> bool:
            return isinstance(diagonal[0], slice) and diagonal[0] == slice(0, n)

        self.diagonals.sort(key=lambda diagonal: not full(diagonal))
        self._full = bool(self.diagonals) and full(self.diagonals[0])
        self.n = n

    def times(self, columns: np.ndarray) -> np.ndarray:
        diagonals = self.diagonals
        if self._full:
            result, diagonals = diagonals[0][2] * columns[diagonals[0][1]], diagonals[1:]
        else:
            result = np.full(columns.shape, _gmpy2().mpfr(0), dtype=object)
        for rows, sources, values in diagonals:
            result[rows] += values * columns[sources]  # one entry per row on a diagonal
        return result


def _dense(entries: dict[tuple[int, int], Any], shape: tuple[int, int], transposed: bool = False) -> np.ndarray:
    """An (object) mpfr array of ``shape`` holding sparse exact ``entries`` ``(i, j) -> value`` (at ``(j, i)`` if
    ``transposed``), zeros elsewhere."""
    array = np.full(shape, _gmpy2().mpfr(0), dtype=object)
    for (i, j), value in entries.items():
        array[(j, i) if transposed else (i, j)] = _mpfr(value)
    return array


def _gram(left: np.ndarray, right: np.ndarray) -> np.ndarray:
    """``leftᵀ right`` known to be symmetric (``Vᵀ M V``): its upper triangle, mirrored (half the products)."""
    size = left.shape[1]
    result = np.empty((size, size), dtype=object)
    for a in range(size):
        result[a, a:] = left[:, a].dot(right[:, a:])
        result[a + 1:, a] = result[a, a + 1:]
    return result


def _rows_times(entries: dict[tuple[int, int], Any], rows: int, columns: np.ndarray) -> np.ndarray:
    """``S @ columns`` for a sparse exact (rows × N) matrix S given by its entries ``(r, i) -> value``."""
    result = np.full((rows, columns.shape[1]), _gmpy2().mpfr(0), dtype=object)
    for (r, i), value in entries.items():
        result[r] += _mpfr(value) * columns[i]
    return result




def _exact(value: Any) -> sympy.Rational:
    numerator, denominator = value.as_integer_ratio()
    return sympy.Rational(int(numerator), int(denominator))


@dataclass(frozen=True)
class ReducedStructure:
    """A structure reduced by :class:`ResidualFlexibility`: the reduced ``system`` and how it was obtained.

    Attributes
    ----------
    system : UnilateralSystem
        The projected model: the kept modes, then the residual vectors of the elements (and loads) that the modes
        and one another leave independent (``modes + m`` dof when they all are), with the
        elements' laws; its data are the projections to the working precision, as exact binary rationals.
    n_dof : int
        Degrees of freedom of the full model.
    modes : int
        Modes kept.
    frequencies : tuple
        The kept λ_k of the full model (mpmath mpf, ``digits`` digits: the converged Ritz values).
    digits : int
        The working precision of the projection.
    success : bool
        Whether the Ritz values converged to ``digits`` digits within the iterations allowed.
    message : str
        What happened.
    iterations, solves : int
        Subspace iterations and multiprecision solves with ``K`` (block solves, one column each).
    bandwidth : int
        The half-bandwidth of ``K`` in the reverse Cuthill–McKee ordering (the factorisation costs O(N b²)).
    loads : tuple
        The projections ``Vᵀ P`` of the ``loads`` given (one tuple of exact numbers per load).
    basis : numpy.ndarray
        ``V`` in float64 (N × reduced dof): the full displacements ``X ≈ V q`` of a reduced state ``q``.
    """

    system: UnilateralSystem
    n_dof: int
    modes: int
    frequencies: tuple[Any, ...]
    digits: int
    success: bool
    message: str
    iterations: int
    solves: int
    bandwidth: int
    loads: tuple[tuple[Any, ...], ...]
    basis: np.ndarray = field(repr=False)


@dataclass(frozen=True)
class ResidualFlexibility:
    """Reduce a large structure to ``modes`` low modes plus one residual-flexibility vector per element.

    Parameters
    ----------
    modes : int
        The number K of lowest modes kept (``1 ≤ K``, ``K + m < N``).
    digits : int
        The working precision of the reduced model's data (default 30).

    Examples
    --------
    >>> import lindstedt
    >>> beam = lindstedt.EulerBernoulliBeam(40, cracks=[(10, 10)])
    >>> reduced = ResidualFlexibility(modes=6).reduce(beam)
    >>> reduced.system.n_dof, reduced.success
    (7, True)
    >>> full = lindstedt.nnm(beam.system(), 1, a0=1, order=1).omega
    >>> small = lindstedt.nnm(reduced.system, 1, a0=1, order=1).omega
    >>> [float(abs(x - y)) < 1e-25 for x, y in zip(full, small)]     # ω₀, ω₁: a kept mode's are exact
    [True, True]
    """

    modes: int = 12
    digits: int = 30

    def __post_init__(self) -> None:
        for name in ("modes", "digits"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
                raise ProblemError(f"{name} must be a positive integer, got {value!r}")

    def reduce(self, structure: Any, A: Any = None, b: Any = None, W: Any = None, laws: Any = None,
               loads: Any = None) -> ReducedStructure:
        """The reduced model of ``structure``.

        Parameters
        ----------
        structure : EulerBernoulliBeam or (M, K)
            A beam (its exact matrices and its cracks as the elements), or the mass and stiffness matrices
            (scipy.sparse, numpy or sympy; floats are taken as the binary numbers they are), symmetric, K
            positive definite.
        A, b, W, laws
            The elements as for :class:`~lindstedt.problems.system.UnilateralSystem` (``A`` m×N required with
            matrices; ``b`` default zeros, ``W`` default ``Aᵀ``, ``laws`` default the unilateral spring); not
            given with a beam.
        loads : array_like, optional
            Load shapes ``P`` (N, or N × p) of a forced problem ``… = ε P cos Ωt``: their static residuals join the
            basis (a load away from the elements excites the modes above the cut quasi-statically too), and
            :attr:`ReducedStructure.loads` holds their projections ``Vᵀ P`` for
            :class:`~lindstedt.ForcedSystem`.

        Returns
        -------
        ReducedStructure

        Raises
        ------
        ProblemError
            On inconsistent shapes, a K that is not positive definite, too many modes.
        BudgetError
            When the estimated cost exceeds the budget in force.
        """
        from .beam import EulerBernoulliBeam

        if isinstance(structure, EulerBernoulliBeam):
            if any(value is not None for value in (A, b, W, laws)):
                raise ProblemError("a beam brings its own elements (its cracks): do not pass A, b, W or laws with it")
            n = structure.n_dof
            mass, stiffness = ({key: _rational(v) for key, v in part.items()} for part in structure._exact)
            elements = {key: _rational(v) for key, v in structure._A_exact.items()}
            m = len(structure.cracks)
            gaps = [crack[3] for crack in structure.cracks]
            forces = None
            laws = None
        else:
            if isinstance(structure, (str, bytes)) or not isinstance(structure, (tuple, list)) or len(structure) != 2:
                raise ProblemError("structure must be an EulerBernoulliBeam or a pair (M, K) of matrices")
            if A is None:
                raise ProblemError("give the elements' rows A (m×N) with the matrices (M, K)")
            shape = getattr(structure[1], "shape", None)
            if shape is None or len(shape) != 2 or shape[0] != shape[1]:
                raise ProblemError(f"K must be a square matrix, got shape {shape}")
            n = int(shape[0])
            mass = _entries(structure[0], n, n, "M")
            stiffness = _entries(structure[1], n, n, "K")
            _check_symmetric(mass, "M")
            _check_symmetric(stiffness, "K")
            rows_A = getattr(A, "shape", None) or np.shape(np.asarray(A, dtype=object))
            m = int(rows_A[0]) if len(rows_A) == 2 else 1
            elements = _entries(A, m, n, "A")
            gaps = [0] * m if b is None else list(b)
            if len(gaps) != m:
                raise ProblemError(f"b has {len(gaps)} entries for {m} elements")
            forces = None if W is None else _entries(W, n, m, "W")
        if self.modes + m >= n:
            raise ProblemError(f"{self.modes} modes and {m} elements leave nothing to reduce in {n} dof; keep fewer "
                               "modes (modes + elements < N) or use the full system")
        load_entries = []
        if loads is not None:
            array = np.asarray(loads, dtype=object)
            columns = array.reshape(n, -1) if array.size and array.shape[0] == n else None
            if columns is None:
                raise ProblemError(f"loads must have one row per degree of freedom ({n}), got shape {array.shape}")
            load_entries = [{i: _rational(value, f"loads[{i}]") for i, value in enumerate(columns[:, c]) if value != 0}
                            for c in range(columns.shape[1])]
        return _reduce(self, n, m, mass, stiffness, elements, forces, gaps, laws, load_entries)

    def estimate(self, n: int, bandwidth: int, elements: int, iterations: int, steps: int = 1) -> Estimate:
        """The cost of a reduction of an N-dof model whose K has half-bandwidth ``bandwidth``."""
        columns = self.modes + max(4, self.modes // 2)
        # the factorisation, then per Chebyshev step the band solve, the product with M and the recurrence
        # (N (8b + 6) q), every ``steps`` steps the Gram matrices and the Ritz transform (3 N q²), then the residual
        # vectors and the projections (N ((2b + 1) m + 2 (K + m)²))
        operations = (n * bandwidth**2 + iterations * n * ((8 * bandwidth + 6) * columns + 3 * columns**2 / steps)
                      + n * ((2 * bandwidth + 1) * elements + 2 * (self.modes + elements) ** 2))
        return Estimate(task=f"residual-flexibility reduction of a {n}-dof model to {self.modes} modes",
                        seconds=_SECONDS_PER_OPERATION * operations,
                        memory_mb=3e-4 * n * (bandwidth + 6 * columns + elements),  # ~150 bytes per mpfr kept
                        drivers=(("degrees of freedom", n), ("half-bandwidth", bandwidth), ("modes", self.modes)),
                        advice="keep fewer modes")


def _reduce(method: ResidualFlexibility, n: int, m: int, mass: dict, stiffness: dict, elements: dict, forces: dict | None,
            gaps: list, laws: Any, loads: list) -> ReducedStructure:
    import scipy.sparse

    from .structures import _check_positive_definite, sparse_modes

    gmpy2 = _gmpy2()
    K = method.modes
    columns = min(n - 1, K + max(4, K // 2))

    def as_float(entries: dict) -> Any:
        keys = list(entries)
        return scipy.sparse.csc_matrix(([float(entries[k]) for k in keys], ([k[0] for k in keys], [k[1] for k in keys])),
                                       shape=(n, n))

    float_mass = as_float(mass)
    _check_positive_definite(float_mass, "M", "the structure")
    float_modes = sparse_modes(float_mass, as_float(stiffness), columns)
    theta = float_modes.frequencies**2
    stiffest = max(float(abs(v)) for (i, j), v in stiffness.items() if i == j)
    lightest = min(float(v) for (i, j), v in mass.items() if i == j)
    conditioning = max(1.0, stiffest / lightest / float(theta[0]))
    # the Ritz values are stationary to 2^-2t when the vectors are to 2^-t (t the target bits): room for both
    target = int(math.ceil(method.digits * math.log2(10))) + 8
    # between two Ritz steps ``steps`` Chebyshev steps run on the columns alone (the Ritz step's products are
    # O(N q²), a step's O(N b q)): the columns drift towards the lowest mode by log2 T_1(x_1) ≈ log2(4θ_q/θ_1) bits
    # a step, which the guard bits absorb
    drift = max(1, int(math.ceil(math.log2(4 * float(theta[-1] / theta[0])))))
    steps = max(1, min(_MAX_STEPS, _GUARD_BITS // drift))
    bits = 2 * target + int(math.ceil(math.log2(conditioning))) + 32 + _GUARD_BITS
    # a Ritz value's error falls by ρ² a step, ρ = 1/(x + √(x² − 1)), x = 2θ_q/θ_K − 1 (Chebyshev on [0, 1/θ_q]
    # against the kept mode K; a Krylov-free ρ would be θ_K/θ_q), from the float modes' (~2^-20 at worst)
    x = 2 * float(theta[-1] / theta[K - 1]) - 1
    gain = 2 * math.log2(x + math.sqrt(x * x - 1)) if x > 1 else 1.0
    iterations = min(_MAX_ITERATIONS, int(math.ceil((2 * target - 20) / max(1.0, gain))) + steps)
    with gmpy2.context(gmpy2.get_context(), precision=bits):
        factor = _BandedLDL(stiffness, n)
        method.estimate(n, factor.width, m, iterations, steps).check()
        product = _SparseProduct(mass, n)
        X = np.frompyfunc(gmpy2.mpfr, 1, 1)(np.asarray(float_modes.shapes, dtype=float))
        MX = product.times(X)
        previous: list[Any] | None = None
        success, done, solves, change, last, last_cycle = False, 0, 0, math.inf, None, steps
        tolerance = gmpy2.mpfr(2) ** (-2 * target)
        with mpmath.workprec(bits):
            upper = gmpy2.mpfr(float(theta[-1]))  # the damped interval of K⁻¹M: [0, 1/θ_q]
            stiffness_product = _SparseProduct(stiffness, n)
            cycle = steps  # the Chebyshev steps until the next Ritz step
            while done < _MAX_ITERATIONS:
                # Y_j = T_j(2 θ_q K⁻¹M − I) X: Y_{j+1} = 4 θ_q K⁻¹M Y_j − 2 Y_j − Y_{j−1}, carried by the sums
                # S_j = Y_j + Y_{j−1} (S_{j+1} = 4 θ_q K⁻¹M Y_j − S_j, Y_{j+1} = S_{j+1} − Y_j: two subtractions a step)
                total = factor.solve(MX, 2 * upper)
                Y = total - X
                for _ in range(cycle - 1):
                    total = factor.solve(product.times(Y), 4 * upper) - total
                    Y = total - Y
                done += cycle
                solves += cycle * columns
                MY = product.times(Y)
                values, transform = _ritz(_gram(Y, stiffness_product.times(Y)), _gram(Y, MY))
                upper = values[-1]
                kept = values[:K]
                X = Y.dot(transform)
                MX = product.times(X)  # O(N b q) against O(N q²) for MY·transform
                if previous is not None:
                    # the change is the previous values' error; theirs falls over s steps by the slower of T_s(x)⁻²,
                    # x = 2θ_q/θ_K − 1, and the rate observed between the last two changes
                    change = max(abs(a - b) / abs(a) for a, b in zip(kept, previous))
                    x = 2 * values[-1] / values[K - 1] - 1
                    observed = (change / last) ** (1 / last_cycle) if last else gmpy2.mpfr(0)

                    def ratio(s: int) -> Any:
                        return max(1 / gmpy2.cosh(s * gmpy2.acosh(x)) ** 2 if x > 1 else 1, observed**s)

                    error = change * ratio(cycle)
                    if error <= tolerance:
                        success = True
                        break
                    last, last_cycle = change, cycle
                    # the next Ritz step after the steps that should bring the error to a quarter of the tolerance
                    cycle = next((s for s in range(1, steps) if error * ratio(s) <= tolerance / 4), steps)
                previous = kept
                checkpoint("subspace iteration", done, _MAX_ITERATIONS)
            # K X by the sparse product: it cancels log2 cond(K) bits, which the working precision holds in reserve
            KX = stiffness_product.times(X[:, :K])
            X, MX = X[:, :K], MX[:, :K]
            # each mode signed as the full model's modes are (its first entry of largest magnitude positive)
            signs = np.array([_leading_sign([float(v) for v in X[:, k]]) for k in range(K)], dtype=object)
            X, KX, MX = X * signs, KX * signs, MX * signs
            W = _dense(elements, (n, m), transposed=True) if forces is None else _dense(forces, (n, m))
            P = _dense({(i, column): value for column, load in enumerate(loads) for i, value in load.items()}, (n, len(loads)))
            statics = np.hstack((W, P))
            Z = factor.solve(statics)  # K Z = [W, P]
            solves += statics.shape[1]
            coefficients = MX.T.dot(Z)  # Φᵀ M Z, Φ M-orthonormal
            Z = Z - X.dot(coefficients)
            KZ = statics - KX.dot(coefficients)
            # M-orthonormal residual vectors, those the kept modes and the others already span dropped (two stops on
            # one dof, a load on a contact dof): the eigenvectors of their Gram matrix above 2^-t of the largest
            gram, U = mpmath.eigsy(_small(Z.T.dot(product.times(Z))))
            largest = max(gram[i] for i in range(gram.rows))
            keep = [i for i in range(gram.rows) if gram[i] > largest * mpmath.mpf(2) ** (-target)]
            scale = np.array([[mpfr_of_mpf(mpmath.mpf(U[r, i] / mpmath.sqrt(gram[i]))) for i in keep] for r in range(gram.rows)], dtype=object)
            Z, KZ = Z.dot(scale), KZ.dot(scale)
            signs = _leading_signs(Z.astype(float)).astype(object)  # signed as the modes (eigsy's signs are arbitrary)
            Z, KZ = Z * signs, KZ * signs
            MZ = product.times(Z)
            V, KV, MV = (np.hstack(pair) for pair in ((X, Z), (KX, KZ), (MX, MZ)))
            reduced_mass = _gram(V, MV)
            reduced_stiffness = _gram(V, KV)
            reduced_A = _rows_times(elements, m, V)  # A V, Wᵀ V and Pᵀ V from the few nonzero entries
            reduced_W = (reduced_A if forces is None else
                         _rows_times({(j, i): value for (i, j), value in forces.items()}, m, V)).T
            reduced_loads = _rows_times({(c, i): value for c, load in enumerate(loads) for i, value in load.items()},
                                        len(loads), V).T
            basis = V.astype(float)
            frequencies = tuple(mpf_of_mpfr(gmpy2.sqrt(value)) for value in values[:K])

        def exact(matrix: np.ndarray, symmetric: bool) -> sympy.Matrix:
            if symmetric:
                matrix = (matrix + matrix.T) / 2
            return sympy.Matrix(matrix.shape[0], matrix.shape[1], [_exact(v) for v in matrix.ravel()])

        system = UnilateralSystem(exact(reduced_mass, True), exact(reduced_stiffness, True), exact(reduced_A, False),
                                  gaps, exact(reduced_W, False), laws)
        projected = tuple(tuple(_exact(v) for v in reduced_loads[:, column]) for column in range(len(loads)))
    with mpmath.workdps(method.digits):
        frequencies = tuple(+value for value in frequencies)
    message = (f"{K} modes converged to {method.digits} digits in {done} subspace iterations" if success else
               f"the Ritz values were still moving after {done} subspace iterations (by {float(change):.1e} relative in the last "
               f"{last_cycle}): the kept modes are not converged to {method.digits} digits, so a kept mode's ω₀, ω₁ are not the "
               "full model's to that precision (keep fewer modes, or more: a step gains a factor (x + √(x² − 1))² with "
               "x = 2λ_q/λ_K − 1)")
    if not success:
        warn_caller(UserWarning(message))
    return ReducedStructure(system, n, K, frequencies, method.digits, success, message, done, solves, factor.width,
                            projected, basis)


def _small(matrix: np.ndarray) -> Any:
    """A small symmetric object matrix of mpfr as an mpmath matrix (symmetrised)."""
    size = matrix.shape[0]
    return mpmath.matrix([[(mpf_of_mpfr(matrix[i, j]) + mpf_of_mpfr(matrix[j, i])) / 2 for j in range(size)] for i in range(size)])


def _cholesky(matrix: np.ndarray) -> np.ndarray:
    """The lower Cholesky factor of a small symmetric positive definite object matrix of mpfr."""
    gmpy2 = _gmpy2()
    size = matrix.shape[0]
    lower = np.full((size, size), gmpy2.mpfr(0), dtype=object)
    for j in range(size):
        pivot = matrix[j, j] - lower[j, :j].dot(lower[j, :j])
        if not pivot > 0:
            raise ProblemError("the subspace basis lost its rank (a Gram matrix is not positive definite): the "
                               "structure has fewer independent modes than asked for; keep fewer modes")
        lower[j, j] = gmpy2.sqrt(pivot)
        for i in range(j + 1, size):
            lower[i, j] = (matrix[i, j] - lower[i, :j].dot(lower[j, :j])) / lower[j, j]
    return lower


def _forward(lower: np.ndarray, right: np.ndarray) -> np.ndarray:
    """``L⁻¹ right`` for a lower triangular object matrix L (forward substitution, row by row)."""
    result = right.copy()
    for i in range(lower.shape[0]):
        result[i] = (right[i] - lower[i, :i].dot(result[:i])) / lower[i, i]
    return result


def _eigen(matrix: np.ndarray) -> tuple[list[Any], np.ndarray]:
    """The eigenpairs of a small symmetric object matrix of mpfr at the context's precision: values increasing,
    vectors orthonormal.  The float64 eigenvectors, orthonormalised (Cholesky QR), leave off-diagonal entries of
    ~1e-16 ‖C‖ that cyclic Jacobi sweeps square away (quadratic convergence, clusters included) until the
    diagonal holds the eigenvalues to the working precision (the vectors then to about half of it)."""
    gmpy2 = _gmpy2()
    size = matrix.shape[0]
    to_mpfr = np.vectorize(gmpy2.mpfr, otypes=[object])
    largest = max(abs(value) for value in matrix.ravel()) or 1  # float64 sees the matrix scaled to 1
    Q = to_mpfr(np.linalg.eigh((matrix / largest).astype(float))[1])
    Q = _forward(_cholesky(Q.T.dot(Q)), Q.T).T  # Q R⁻¹, R = chol(QᵀQ)ᵀ: orthonormal to the working precision
    D = Q.T.dot(matrix).dot(Q)
    D = (D + D.T) / 2
    floor = gmpy2.mpfr(2) ** (-gmpy2.get_context().precision)
    for _ in range(_MAX_SWEEPS):
        # done when each diagonal entry is an eigenvalue to the working precision: its second-order shift
        # d_pq² / (d_pp − d_qq) below 2^-p of the scale (and a clustered pair, whose shift is first order, rotated)
        if all(D[p, q] ** 2 <= floor * (abs(D[p, p]) + abs(D[q, q])) * abs(D[p, p] - D[q, q])
               for p in range(size - 1) for q in range(p + 1, size)):
            break
        rotated = False
        for p in range(size - 1):
            for q in range(p + 1, size):
                off = D[p, q]
                if abs(off) <= floor * (abs(D[p, p]) + abs(D[q, q])):
                    continue
                rotated = True
                tau = (D[q, q] - D[p, p]) / (2 * off)
                t = (1 if tau >= 0 else -1) / (abs(tau) + gmpy2.sqrt(1 + tau * tau))
                c = 1 / gmpy2.sqrt(1 + t * t)
                s = t * c
                for array in (D, Q):  # columns p, q of D and Q, then rows p, q of D
                    first, second = array[:, p].copy(), array[:, q].copy()
                    array[:, p], array[:, q] = c * first - s * second, s * first + c * second
                first, second = D[p].copy(), D[q].copy()
                D[p], D[q] = c * first - s * second, s * first + c * second
        if not rotated:
            break
    order = sorted(range(size), key=lambda i: D[i, i])
    return [D[i, i] for i in order], Q[:, order]


def _ritz(stiffness: np.ndarray, mass: np.ndarray) -> tuple[list[Any], np.ndarray]:
    """The generalized eigenpairs of the small pencil (stiffness, mass) of object mpfr matrices (symmetrised):
    values increasing, vectors mass-orthonormal (``L⁻ᵀ`` times the eigenvectors of ``L⁻¹ S L⁻ᵀ``, M = L Lᵀ)."""
    lower = _cholesky((mass + mass.T) / 2)
    half = _forward(lower, (stiffness + stiffness.T) / 2)  # L⁻¹ S
    symmetric = _forward(lower, half.T)  # L⁻¹ (L⁻¹ S)ᵀ = L⁻¹ S L⁻ᵀ
    values, vectors = _eigen((symmetric + symmetric.T) / 2)
    return values, _forward(lower.T[::-1, ::-1], vectors[::-1])[::-1]  # L⁻ᵀ: the reversed upper triangle
