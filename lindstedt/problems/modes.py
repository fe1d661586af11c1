"""Linear normal modes ``K Φ = M Φ diag(λ²)``, ``Φᵀ M Φ = I``: float64, then refined in multiprecision.

* :func:`_float_modes` — λ and Φ in float64 by LAPACK (tridiagonal or banded solvers when ``M`` is
  diagonal), each shape signed so that its first entry of largest magnitude is positive;
* :func:`_refine` — those modes refined in fixed-point arithmetic on Python ints, a block of modes at a time
  (:func:`_refined_blocks`; O(N · block) ints in memory): with the exact
  residuals ``R = K X − M X Θ`` (products with the band of K and M), each sweep corrects every mode by its
  projections on the float modes, ``x_k −= Σ_{l≠k} x̃_l (x̃_lᵀ r_k)/(θ_l − θ_k)``, and θ_k is the final
  Rayleigh quotient; :func:`_dense_mpmath_modes` — the dense mpmath decomposition, the fallback for
  near-repeated frequencies;
* :func:`_high_precision_modes`, :func:`_modal_coupling` — λ_k, Φ and ``B = A Φ``, ``G = Φᵀ W`` to a
  requested number of digits (what :class:`~lindstedt.problems.system.UnilateralSystem` returns).
"""

from __future__ import annotations

from typing import Any, NamedTuple, Protocol, Sequence

import mpmath
import numpy as np
import sympy

from .._precision import workdps, workprec

# Two entries of a mode shape whose magnitudes agree to this relative
# tolerance count as tied for "largest" in the sign convention of modes().
_MODE_SIGN_TIE_RTOL = 1e-9


class _ExactSystem(Protocol):
    """What the refinement reads of a :class:`~lindstedt.problems.system.UnilateralSystem`."""

    M_exact: sympy.ImmutableMatrix
    K_exact: sympy.ImmutableMatrix
    A_exact: sympy.ImmutableMatrix
    W_exact: sympy.ImmutableMatrix

    @property
    def n_dof(self) -> int: ...

    @property
    def n_springs(self) -> int: ...

    def modes(self) -> Any: ...  # Modes(frequencies, shapes)


def _leading_sign(column: Sequence[Any]) -> int:
    """±1 making the first entry of largest magnitude (ties within a relative 1e-9) positive."""
    largest = max(abs(value) for value in column)
    for value in column:
        if abs(value) >= largest * (1 - _MODE_SIGN_TIE_RTOL):
            return 1 if value > 0 else -1
    return 1


def _float_modes(M: np.ndarray, K: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """λ and Φ (ΦᵀMΦ = I) in float64: LAPACK's tridiagonal / banded solvers when M is diagonal, else dense.

    Each shape is signed by :func:`_leading_sign`.
    """
    import scipy.linalg  # here, not at module level: import lindstedt stays light

    n = M.shape[0]
    if np.count_nonzero(M - np.diag(np.diag(M))) == 0:
        scale = 1 / np.sqrt(np.diag(M))
        scaled = K * scale[:, None] * scale[None, :]
        rows, cols = np.nonzero(scaled)
        width = int(np.max(np.abs(rows - cols))) if rows.size else 0
        if n > 1 and width == 1:
            squared, vectors = scipy.linalg.eigh_tridiagonal(np.diag(scaled).copy(), np.diag(scaled, 1).copy())
        elif n > 1 and 1 < width < n // 4:
            band = np.zeros((width + 1, n))
            for offset in range(width + 1):
                band[width - offset, offset:] = np.diag(scaled, offset)
            squared, vectors = scipy.linalg.eig_banded(band)
        else:
            squared, vectors = scipy.linalg.eigh((scaled + scaled.T) / 2)
        shapes = vectors * scale[:, None]
    else:
        squared, shapes = scipy.linalg.eigh(K, M)
    shapes = np.array(shapes)
    for k in range(n):
        shapes[:, k] *= _leading_sign(shapes[:, k].tolist())
    return np.sqrt(squared), shapes


def _exact_mpf(value: sympy.Expr) -> Any:
    """An exact sympy number as an mpmath mpf at the current precision."""
    if value.is_Rational:
        return mpmath.mpf(value.p) / value.q
    return mpmath.mpf(sympy.N(value, mpmath.mp.dps + 5))


def _fixed_point(value: sympy.Expr, shift: int) -> int:
    """round(value · 2^shift) for an exact sympy number."""
    if value.is_Rational:
        numerator, denominator = int(value.p) << shift, int(value.q)
        return (2 * numerator + denominator) // (2 * denominator)
    with workprec(shift + 64):
        return int(mpmath.nint(mpmath.ldexp(_exact_mpf(value), shift)))


class _Band(NamedTuple):
    """A matrix by its nonzero diagonals: ``offset -> (entries, shift)``, the entries an int (a constant
    diagonal) or an object column of ints, equal to the exact entries times 2^shift (shift 0: exact integers)."""

    diagonals: dict[int, tuple[Any, int]]

    @classmethod
    def of(cls, exact: sympy.ImmutableMatrix, bits: int) -> "_Band":
        by_offset: dict[int, dict[int, sympy.Expr]] = {}
        for (row, col), value in exact.todok().items():
            by_offset.setdefault(col - row, {})[row] = value
        n = exact.rows
        nonzero = [abs(float(value)) for entries in by_offset.values() for value in entries.values()]
        # non-integer entries as fixed point, with room for the smallest of them relative to the largest
        shift = bits + 64 + (int(np.ceil(np.log2(max(nonzero) / min(nonzero)))) if nonzero and min(nonzero) > 0 else 0)
        diagonals: dict[int, tuple[Any, int]] = {}
        for offset, entries in by_offset.items():
            values = [entries.get(row - min(offset, 0), sympy.S.Zero) for row in range(n - abs(offset))]
            exact = all(value.is_Integer for value in values)
            scale = 0 if exact else shift
            if all(value == values[0] for value in values):  # a constant diagonal: one int
                diagonals[offset] = (int(values[0]) if exact else _fixed_point(values[0], scale), scale)
            else:
                diagonals[offset] = (np.array([int(v) if exact else _fixed_point(v, scale) for v in values], dtype=object)[:, None], scale)
        return cls(diagonals)

    @property
    def identity(self) -> bool:
        entries, shift = self.diagonals.get(0, (0, 0))
        return set(self.diagonals) == {0} and isinstance(entries, int) and entries == 1 and not shift

    def times(self, Y: np.ndarray) -> np.ndarray:
        """``A @ Y`` for an object matrix of ints Y (rounded down where an entry is fixed point)."""
        result = None
        for offset in sorted(self.diagonals, key=lambda d: d != 0):
            entries, shift = self.diagonals[offset]
            if offset == 0:
                source, target = Y, slice(None)
            elif offset > 0:  # row i takes Y[i + offset]
                source, target = Y[offset:], slice(None, -offset)
            else:
                source, target = Y[:offset], slice(-offset, None)
            constant = isinstance(entries, int)
            negate = constant and entries == -1 and not shift
            if negate or (constant and entries == 1 and not shift):
                term = source
            else:
                term = source * entries
                if shift:
                    term = term >> shift
            if result is None:
                result = np.zeros(Y.shape, dtype=object)
            if negate:
                result[target] -= term
            else:
                result[target] += term
        return np.zeros(Y.shape, dtype=object) if result is None else result


class _RefinedModes(NamedTuple):
    """Mode shapes to high precision as fixed-point ints: column k of ``X`` over ``sqrt(norms[k])`` is φ_k
    (``norms[k] = x_kᵀ M x_k`` in the same units); ``theta[k] = numerators[k] / norms[k]`` is λ_k²."""

    X: np.ndarray
    norms: list[int]
    numerators: list[int]
    bits: int

    def frequencies(self) -> list[Any]:
        """λ_k as mpf at the current mpmath precision."""
        return [mpmath.sqrt(mpmath.mpf(numerator) / norm) for numerator, norm in zip(self.numerators, self.norms)]

    def projections(self, exact: sympy.ImmutableMatrix) -> list[list[Any]]:
        """``exact @ Φ`` (rows × modes) as mpf, for an exact matrix with few nonzero entries per row."""
        rows: list[list[Any]] = []
        shift = self.bits + 64
        roots = [mpmath.sqrt(norm) for norm in self.norms]
        entries: dict[int, list[tuple[int, sympy.Expr]]] = {}
        for (row, col), value in exact.todok().items():
            entries.setdefault(row, []).append((col, value))
        for row in range(exact.rows):
            total = np.zeros(self.X.shape[1], dtype=object)
            scaled = False
            for col, value in entries.get(row, []):
                if value.is_Integer:
                    total = total + self.X[col] * (int(value) << shift)
                else:
                    total = total + self.X[col] * _fixed_point(value, shift)
                scaled = True
            rows.append([mpmath.ldexp(mpmath.mpf(int(v)), -shift) / root if scaled else mpmath.mpf(0) for v, root in zip(total, roots)])
        return rows


class _Refinement(NamedTuple):
    """What every block of modes shares in :func:`_refine`: the float modes, the gaps, the precision, the bands."""

    shapes: np.ndarray
    theta_float: np.ndarray
    gaps: np.ndarray
    magnitude: float
    largest: float
    target: int
    gain: float
    bits: int
    p: int
    stiffness: _Band
    mass: _Band


def _refinement(system: _ExactSystem, digits: int) -> _Refinement | None:
    """The set-up of :func:`_refine` (see ``modal_coupling``), or None when the sweeps cannot converge: two θ_k
    coincide, or a sweep would gain fewer than 4 bits (``log2(θ_max/gap) > 44``); the caller then decomposes
    densely in mpmath."""
    frequencies, shapes = system.modes()
    theta_float = frequencies**2
    n = system.n_dof
    largest = float(theta_float[-1])
    gaps = theta_float[:, None] - theta_float[None, :]
    np.fill_diagonal(gaps, np.inf)
    smallest_gap = float(np.min(np.abs(gaps))) if n > 1 else largest
    if not smallest_gap > 0:  # a repeated frequency: the sweeps cannot separate it
        return None
    # a sweep gains the float residual's 52 bits less log2(θ_max/gap): the only test of convergence needed (a test
    # of the gap against 1e-9 θ_max refused beams past ~200 dof, whose θ_max grows like n⁴, at 18 bits a sweep)
    conditioning = np.log2(largest / smallest_gap)
    gain = 52 - conditioning - 4  # bits gained per sweep
    if gain < 4:
        return None
    target = int(np.ceil(digits * np.log2(10))) + 4
    magnitude = float(np.max(np.abs(shapes)))
    # guard bits: the θ_k are accurate to 2^-p absolutely (the smallest one relatively: + log2(1/θ_1)), the
    # shapes to 2^-p relative to their largest entry, and a sweep's residual loses log2(θ_max/gap)
    bits = target + int(np.ceil(max(0.0, np.log2(max(1.0, largest) / float(theta_float[0]))) + conditioning)) + 16
    p = bits + max(0, int(np.ceil(np.log2(max(1.0, magnitude) / min(np.max(np.abs(shapes), axis=0))))))
    return _Refinement(shapes, theta_float, gaps, magnitude, largest, target, gain, bits, p,
                       _Band.of(system.K_exact, p), _Band.of(system.M_exact, p))


#: modes refined together: the fixed-point shapes of a block are O(N · block) ints (all N at once: 436 MB for the NNM
#: of a 1000-dof chain; blocks of 128: 118 MB, CPU within the noise of one block — blocks of 64 cost 25 % more, the
#: (N × N) @ (N × block) float products of a sweep running below BLAS speed)
_BLOCK = 128


def _refine(setup: _Refinement, columns: slice) -> _RefinedModes | None:
    """The float modes ``columns`` refined to the set-up's precision (see ``modal_coupling``).

    Fixed-point arithmetic on Python ints (X = ints · 2^-p): the residual of every mode is formed exactly
    from the band of K and M (integer entries exactly, others to 2^-(p+64)), rounded to float64 and
    projected on all the float modes.  None when the sweeps do not converge.
    """
    shapes, p, target = setup.shapes, setup.p, setup.target
    block = shapes[:, columns]
    indices = np.arange(shapes.shape[1])[columns]
    start = 62 - int(np.ceil(np.log2(setup.magnitude)))
    X = np.rint(np.ldexp(block, start)).astype(np.int64).astype(object) << (p - start)
    scale = int(np.ceil(np.log2(setup.largest)))
    theta = np.array([int(v) for v in np.rint(np.ldexp(setup.theta_float[indices], 52 - scale))], dtype=object)
    theta = theta << (p - 52 + scale)
    gaps = setup.gaps[:, indices]
    for _ in range(int(np.ceil((target - 40) / setup.gain)) + 3):
        KX = setup.stiffness.times(X)
        MX = X if setup.mass.identity else setup.mass.times(X)
        residual = _to_float(KX - ((MX * theta[None, :]) >> p), p)
        projections = shapes.T @ residual  # x̃_lᵀ r_k ≈ (θ_l − θ_k) δ_lk, and θ*_k − θ_k on the diagonal
        update = projections[indices, np.arange(len(indices))]
        theta = theta + _to_fixed(update, p)
        correction = shapes @ (-projections / gaps)
        X = X + _to_fixed(correction, p)
        if np.max(np.abs(correction)) <= 2.0**-target * setup.magnitude:
            break
    else:
        return None
    KX = setup.stiffness.times(X)
    MX = X if setup.mass.identity else setup.mass.times(X)
    norms = [int(v) for v in (X * MX).sum(axis=0)]
    numerators = [int(v) for v in (X * KX).sum(axis=0)]  # Rayleigh quotients: error ~ (shape error)²
    return _RefinedModes(X, norms, numerators, setup.bits)


def _refined_blocks(system: _ExactSystem, digits: int) -> list[_RefinedModes] | None:
    """The modes of :meth:`UnilateralSystem.modes` refined to ``digits`` digits, block by block (None: the caller
    falls back to the dense mpmath decomposition)."""
    setup = _refinement(system, digits)
    if setup is None:
        return None
    blocks = []
    for first in range(0, system.n_dof, _BLOCK):
        refined = _refine(setup, slice(first, min(first + _BLOCK, system.n_dof)))
        if refined is None:
            return None
        blocks.append(refined)
    return blocks


def _to_float(values: np.ndarray, p: int) -> np.ndarray:
    """values · 2^-p as floats, for an object array of ints (shifted first where they could overflow a float)."""
    if p > 900:
        return np.ldexp((values >> (p - 900)).astype(float), -900)
    return np.ldexp(values.astype(float), -p)


def _to_fixed(values: np.ndarray, p: int) -> np.ndarray:
    """round(values · 2^p) as an object array of ints, for floats of any size (62 significant bits kept)."""
    largest = float(np.max(np.abs(values))) if values.size else 0.0
    if largest == 0.0:
        return np.zeros(values.shape, dtype=object)
    exponent = 61 - int(np.ceil(np.log2(largest)))
    scaled = np.rint(np.ldexp(values, min(exponent, p))).astype(np.int64).astype(object)
    return scaled << (p - exponent) if exponent < p else scaled


def _dense_mpmath_modes(system: _ExactSystem, digits: int) -> tuple[list[Any], list[list[Any]]]:
    """Dense mpmath decomposition (O(N³) in multiprecision): the fallback for near-repeated frequencies."""
    with workdps(digits + 10):
        mass = mpmath.matrix([[_exact_mpf(v) for v in row] for row in system.M_exact.tolist()])
        stiffness = mpmath.matrix([[_exact_mpf(v) for v in row] for row in system.K_exact.tolist()])
        inverse_lower = mpmath.inverse(mpmath.cholesky(mass))
        symmetric = inverse_lower * stiffness * inverse_lower.T
        eigenvalues, eigenvectors = mpmath.eigsy((symmetric + symmetric.T) / 2)
        shapes_matrix = inverse_lower.T * eigenvectors
        reference = system.modes().shapes
        frequencies, shapes = [], []
        for position, index in enumerate(sorted(range(len(eigenvalues)), key=lambda i: eigenvalues[i])):
            column = [shapes_matrix[row, index] for row in range(system.n_dof)]
            # the sign of the float mode (modes()), so that both agree
            sign = 1 if sum(float(value) * reference[row, position] for row, value in enumerate(column)) >= 0 else -1
            frequencies.append(mpmath.sqrt(eigenvalues[index]))
            shapes.append([sign * value for value in column])
    with workdps(digits):
        return [+value for value in frequencies], [[+value for value in column] for column in shapes]


def _high_precision_modes(system: _ExactSystem, digits: int) -> tuple[list[Any], list[list[Any]]]:
    """λ_k and the shapes of :meth:`~lindstedt.problems.system.UnilateralSystem.modes_high_precision`."""
    blocks = _refined_blocks(system, digits)
    if blocks is None:
        return _dense_mpmath_modes(system, digits)
    frequencies: list[Any] = []
    shapes: list[list[Any]] = []
    with workprec(blocks[0].bits):
        for refined in blocks:
            frequencies += refined.frequencies()
            roots = [mpmath.sqrt(norm) for norm in refined.norms]
            shapes += [[mpmath.mpf(int(value)) / root for value in refined.X[:, k]] for k, root in enumerate(roots)]
    with workdps(digits):
        return [+value for value in frequencies], [[+value for value in column] for column in shapes]


def _modal_coupling(system: _ExactSystem, digits: int) -> tuple[list[Any], list[list[Any]], list[list[Any]]]:
    """λ_k, ``B = A Φ`` and ``G = Φᵀ W`` of :meth:`~lindstedt.problems.system.UnilateralSystem.modal_coupling`."""
    blocks = _refined_blocks(system, digits)
    if blocks is None:
        frequencies, columns = _dense_mpmath_modes(system, digits)
        with workdps(digits + 10):
            A = [[_exact_mpf(v) for v in row] for row in system.A_exact.tolist()]
            W = [[_exact_mpf(v) for v in row] for row in system.W_exact.tolist()]
            B = [[+mpmath.fdot(row, column) for column in columns] for row in A]
            G = [[+mpmath.fdot(column, (W[r][i] for r in range(system.n_dof))) for i in range(system.n_springs)] for column in columns]
        with workdps(digits):
            return frequencies, [[+v for v in row] for row in B], [[+v for v in row] for row in G]
    frequencies = []
    B = [[] for _ in range(system.A_exact.rows)]
    G: list[list[Any]] = []
    with workprec(blocks[0].bits):
        for refined in blocks:  # the block's shapes are dropped once projected: O(N · block) ints at a time
            frequencies += refined.frequencies()
            for row, values in zip(B, refined.projections(system.A_exact)):
                row += values
            if system.n_springs:
                G += [list(column) for column in zip(*refined.projections(system.W_exact.T))]
            else:
                G += [[] for _ in range(refined.X.shape[1])]
    with workdps(digits):
        return [+value for value in frequencies], [[+value for value in row] for row in B], [[+value for value in row] for row in G]
