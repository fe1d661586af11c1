"""Linear normal modes ``K Φ = M Φ diag(λ²)``, ``Φᵀ M Φ = I``: float64, then refined in multiprecision.

* :func:`_float_modes` — λ and Φ in float64 by LAPACK (tridiagonal or banded solvers when ``M`` is
  diagonal), each shape signed so that its first entry of largest magnitude is positive;
* :func:`_refine` — those modes refined in fixed-point arithmetic (X = ints · 2^-p), a block of modes at a time
  (:func:`_refined_blocks`; O(N · block) integers in memory): each sweep forms the exact residuals
  ``R = K X − M X Θ`` from the band of K and M, rounds them to float64 and corrects every mode in float64 — by the
  shifted banded solve ``δ_k = −(K − θ̃_k M)⁻¹ (r_k − M x̃_k (x̃_kᵀ r_k))`` when the band is narrow (O(N w) a mode),
  else by its projections on the float modes, ``δ_k = −Σ_{l≠k} x̃_l (x̃_lᵀ r_k)/(θ_l − θ_k)`` (O(N²)); θ_k is the
  final Rayleigh quotient.  The integers are an object array (:class:`_ObjectColumns`, any band) or, when every
  diagonal of K and M is constant (a chain, whatever its element laws), one GMP integer a mode with the rows in
  fixed-width slots (:class:`_PackedColumns`: a diagonal is one product or shift of the whole column, and the
  slots are read and written as numpy limbs in place);
* :func:`_dense_mpmath_modes` — the dense mpmath decomposition, the fallback for near-repeated frequencies;
* :func:`_high_precision_modes`, :func:`_modal_coupling` — λ_k, Φ and ``B = A Φ``, ``G = Φᵀ W`` to a
  requested number of digits (what :class:`~lindstedt.problems.system.UnilateralSystem` returns).

Measured (issue 26; the NNM of the benchmark's 1000-dof chain, order 2, 51 digits): the modal coupling took
3.0 s as object arrays with projections; packed with banded solves, 0.7 s (of which the big-integer residuals
0.15 s, the limb conversions 0.15 s, the float solves 0.1 s, the exact Gram norms 0.08 s).
"""

from __future__ import annotations

import ctypes
from typing import Any, Callable, Iterator, NamedTuple, Protocol, Sequence

import mpmath
import numpy as np
import sympy

from .._precision import workdps, workprec

# Two entries of a mode shape whose magnitudes agree to this relative
# tolerance count as tied for "largest" in the sign convention of modes().
_MODE_SIGN_TIE_RTOL = 1e-9


class _ExactSystem(Protocol):
    """What the refinement reads of a :class:`~lindstedt.problems.system.UnilateralSystem`."""

    M: np.ndarray
    K: np.ndarray
    M_exact: sympy.ImmutableMatrix
    K_exact: sympy.ImmutableMatrix
    A_exact: sympy.ImmutableMatrix
    W_exact: sympy.ImmutableMatrix

    @property
    def n_dof(self) -> int: ...

    @property
    def n_springs(self) -> int: ...

    def modes(self) -> Any: ...  # Modes(frequencies, shapes)


def _leading_signs(shapes: np.ndarray) -> np.ndarray:
    """±1 per column making its first entry of largest magnitude (ties within a relative 1e-9) positive."""
    magnitudes = np.abs(shapes)
    first = np.argmax(magnitudes >= magnitudes.max(axis=0) * (1 - _MODE_SIGN_TIE_RTOL), axis=0)
    return np.where(shapes[first, np.arange(shapes.shape[1])] > 0, 1, -1)


def _leading_sign(column: Sequence[Any]) -> int:
    """:func:`_leading_signs` of one column."""
    return int(_leading_signs(np.array([float(value) for value in column])[:, None])[0])


def _float_modes(M: np.ndarray, K: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """λ and Φ (ΦᵀMΦ = I) in float64: LAPACK's tridiagonal / banded solvers when M is diagonal, else dense.

    Each shape is signed by :func:`_leading_signs`.
    """
    import scipy.linalg  # here, not at module level: import lindstedt stays light

    n = M.shape[0]
    if np.count_nonzero(M - np.diag(np.diag(M))) == 0:
        scale = 1 / np.sqrt(np.diag(M))
        scaled = K * scale[:, None] * scale[None, :]
        rows, cols = np.nonzero(scaled)
        width = int(np.max(np.abs(rows - cols))) if rows.size else 0
        if n > 1 and width == 1:
            # MRRR (stemr) from 256 dof: 0.13 s against divide and conquer's (stevd) 0.35 s at 1000; below, stevd
            # keeps the small systems' float modes bit for bit (a 5-dof continuation near its collapse hangs on them)
            squared, vectors = scipy.linalg.eigh_tridiagonal(np.diag(scaled).copy(), np.diag(scaled, 1).copy(),
                                                               lapack_driver="stemr" if n >= 256 else "stevd")
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
    shapes = np.array(shapes) * _leading_signs(shapes)[None, :]
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
    """Mode shapes to high precision as fixed-point ints: ``row(i)[k] / sqrt(norms[k])`` is φ_k at row i
    (``norms[k] = x_kᵀ M x_k`` in the same units); ``theta[k] = numerators[k] / norms[k]`` is λ_k²."""

    row: Callable[[int], np.ndarray]  # row i of the fixed-point shapes, an object array of ints (one per mode)
    count: int  # modes in the block
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
            total = np.zeros(self.count, dtype=object)
            scaled = False
            for col, value in entries.get(row, []):
                if value.is_Integer:
                    total = total + self.row(col) * (int(value) << shift)
                else:
                    total = total + self.row(col) * _fixed_point(value, shift)
                scaled = True
            rows.append([mpmath.ldexp(mpmath.mpf(int(v)), -shift) / root if scaled else mpmath.mpf(0) for v, root in zip(total, roots)])
        return rows


class _Refinement(NamedTuple):
    """What every block of modes shares in :func:`_refine`: the float modes, the precision, the bands (exact, and
    in float64 as LAPACK band storage ``(3w + 1) × N`` for the shifted solves, w the half-bandwidth)."""

    shapes: np.ndarray
    theta_float: np.ndarray
    magnitude: float
    largest: float
    target: int
    gain: float
    bits: int
    p: int
    stiffness: _Band
    mass: _Band
    width: int
    stiffness_float: np.ndarray
    mass_float: np.ndarray


def _lapack_band(matrix: np.ndarray, width: int) -> np.ndarray:
    """``matrix`` (half-bandwidth ``width``) in the band storage of LAPACK's gbtrf with kl = ku = width."""
    n = matrix.shape[0]
    band = np.zeros((3 * width + 1, n))
    for offset in range(-width, width + 1):  # A[i, j] at band[2w + i − j, j]
        if offset >= 0:
            band[2 * width - offset, offset:] = np.diagonal(matrix, offset)
        else:
            band[2 * width - offset, :n + offset] = np.diagonal(matrix, offset)
    return band


def _refinement(system: _ExactSystem, digits: int) -> _Refinement | None:
    """The set-up of :func:`_refine` (see ``modal_coupling``), or None when the sweeps cannot converge: two θ_k
    coincide, or a sweep would gain fewer than 4 bits (``log2(θ_max/gap) > 44``); the caller then decomposes
    densely in mpmath."""
    frequencies, shapes = system.modes()
    theta_float = frequencies**2
    n = system.n_dof
    largest = float(theta_float[-1])
    smallest_gap = float(np.min(np.diff(theta_float))) if n > 1 else largest
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
    stiffness, mass = _Band.of(system.K_exact, p), _Band.of(system.M_exact, p)
    width = max(abs(offset) for band in (stiffness, mass) for offset in band.diagonals)
    if width >= max(2, n // 4):  # a wide band: the corrections by projection on the float modes (no band storage)
        return _Refinement(shapes, theta_float, magnitude, largest, target, gain, bits, p, stiffness, mass, width,
                           np.empty((0, n)), np.empty((0, n)))
    return _Refinement(shapes, theta_float, magnitude, largest, target, gain, bits, p, stiffness, mass, width,
                       _lapack_band(np.asarray(system.K, dtype=float), width), _lapack_band(np.asarray(system.M, dtype=float), width))


#: modes refined together: the fixed-point shapes of a block are O(N · block) ints (all N at once: 436 MB for the NNM
#: of a 1000-dof chain as object arrays; blocks of 128: 118 MB, CPU within the noise of one block — blocks of 64 cost
#: 25 % more, the (N × N) @ (N × block) float products of a sweep running below BLAS speed). Packed (a chain), the
#: modal coupling of 1000 dof peaks at 54 MB traced with blocks of 128 (28 MB with 64), CPU within the noise.
_BLOCK = 128

_TOP = np.uint64(1 << 63)  # the top bit of a 64-bit limb: the sign of a slot's top limb, flipped by the bias


def _fixed_parts(values: np.ndarray, p: int) -> tuple[np.ndarray, int]:
    """``(ints, shift)`` with ``ints << shift`` = round(values · 2^p), ints an int64 array of 62 significant bits."""
    largest = float(np.max(np.abs(values))) if values.size else 0.0
    if largest == 0.0:
        return np.zeros(values.shape, dtype=np.int64), 0
    exponent = min(61 - int(np.ceil(np.log2(largest))), p)
    return np.rint(np.ldexp(values, exponent)).astype(np.int64), p - exponent


def _to_fixed(values: np.ndarray, p: int) -> np.ndarray:
    """round(values · 2^p) as an object array of ints, for floats of any size (62 significant bits kept)."""
    ints, shift = _fixed_parts(values, p)
    return ints.astype(object) << shift


def _to_float(values: np.ndarray, p: int) -> np.ndarray:
    """values · 2^-p as floats, for an object array of ints (shifted first where they could overflow a float)."""
    if p > 900:
        return np.ldexp((values >> (p - 900)).astype(float), -900)
    return np.ldexp(values.astype(float), -p)


class _ObjectColumns:
    """The fixed-point shapes of a block as an (N × block) object array of ints: the band of K and M applied
    entry by entry (any band; O(N · block) Python-int operations per product)."""

    def __init__(self, setup: _Refinement, ints: np.ndarray, shift: int) -> None:
        self._setup = setup
        self.X = ints.astype(object) << shift

    def _mass_times(self) -> np.ndarray:
        return self.X if self._setup.mass.identity else self._setup.mass.times(self.X)

    def residual(self, theta: np.ndarray) -> np.ndarray:
        """``K X − M X Θ`` as floats (Θ = theta · 2^-p)."""
        p = self._setup.p
        return _to_float(self._setup.stiffness.times(self.X) - ((self._mass_times() * theta[None, :]) >> p), p)

    def add(self, ints: np.ndarray, shift: int) -> None:
        self.X = self.X + (ints.astype(object) << shift)

    def refined(self, last: tuple[np.ndarray, int]) -> _RefinedModes:
        """The modes with the ``last`` correction (``ints << shift``) added."""
        self.add(*last)
        X = self.X
        norms = [int(v) for v in (X * self._mass_times()).sum(axis=0)]
        numerators = [int(v) for v in (X * self._setup.stiffness.times(X)).sum(axis=0)]  # Rayleigh quotients
        return _RefinedModes(X.__getitem__, X.shape[1], norms, numerators, self._setup.bits)


def _native_limbs() -> bool:
    """Whether GMP's limbs are numpy's little-endian uint64 (the packed columns are read and written in place)."""
    import sys

    import gmpy2

    return (getattr(gmpy2.xmpz, "limb_size", 0) == 8 and sys.byteorder == "little"
            and all(hasattr(gmpy2.xmpz, name) for name in ("limbs_read", "limbs_write", "limbs_finish", "num_limbs")))


class _PackedColumns:
    """The fixed-point shapes of a block when every diagonal of K and M is constant (a chain, any element law):
    column k is ONE gmpy2 integer ``Σ_i x_ik 2^(w (i + pad))`` (``pad`` empty slots either side, wider than the band),
    so ``K x_k`` is a few big-integer shifts and products by the diagonals' constants per column, ``M x_k θ_k`` one
    product, and the slots go to and from numpy limbs (uint64, each slot biased by 2^(w−1)) in one buffer a block.

    Measured (1000-dof chain, the NNM's 51 digits, 5 sweeps): 0.27 s of big-integer and limb work for all
    1000 modes, where the object array of ints (:class:`_ObjectColumns`) took 2.9 s.
    """

    def __init__(self, setup: _Refinement, ints: np.ndarray, shift: int) -> None:
        import gmpy2  # a dependency (sympy's ground types); imported here, as scipy is

        self._setup, self._gmpy2 = setup, gmpy2
        p = setup.p
        bands = (setup.stiffness.diagonals, setup.mass.diagonals)
        self._pad = max(abs(offset) for band in bands for offset in band) if any(bands) else 0
        self._rows = ints.shape[0]
        self._slots = self._rows + 2 * self._pad
        self._scale = max(shift_ for band in bands for _, shift_ in band.values()) if any(bands) else 0
        # bits of a residual slot: (Σ|K| 2^(p+s) + θ_max Σ|M| 2^s) max|x|, max|x| < 2^(p + log2 magnitude + 1)
        x_bits = p + max(0, int(np.ceil(np.log2(setup.magnitude)))) + 1
        k_bits = sum(abs(entries) for entries, _ in bands[0].values()).bit_length() + p + self._scale
        m_bits = (sum(abs(entries) for entries, _ in bands[1].values()).bit_length() + self._scale
                  + p + max(0, int(np.ceil(np.log2(setup.largest * 1.01)))) + 1)
        bits = max(max(k_bits, m_bits) + x_bits + 2, p + 130)  # p + 130: an encoded correction's two limbs
        self._limbs = -(-bits // 64)
        self._width = 64 * self._limbs
        buffer = np.zeros((self._slots, self._limbs), dtype=np.uint64)
        buffer[:, -1] = _TOP
        self._bias = gmpy2.mpz.from_bytes(buffer, "little")  # 2^(w−1) in every slot
        self._columns = self._encode(ints, shift)

    def _encode(self, ints: np.ndarray, shift: int) -> list[Any]:
        """The columns ``ints << shift`` (int64, |ints| < 2^62) as packed integers."""
        index, bit = divmod(shift, 64)
        values = np.ascontiguousarray(ints.T)  # (block, N)
        buffer = np.zeros((values.shape[0], self._slots, self._limbs), dtype=np.uint64)
        rows = slice(self._pad, self._pad + self._rows)
        # the 128-bit two's complement of values · 2^bit in limbs index, index + 1; sign limbs above
        buffer[:, rows, index] = values.view(np.uint64) << np.uint64(bit)
        buffer[:, rows, index + 1] = (values >> (64 - bit) if bit else values >> 63).view(np.uint64)
        if index + 2 < self._limbs:
            buffer[:, rows, index + 2:] = np.where(values < 0, ~np.uint64(0), np.uint64(0))[:, :, None]
        buffer[:, :, -1] ^= _TOP  # + 2^(w−1): the slot's two's complement with its top bit flipped
        count = self._slots * self._limbs
        columns = []
        for column in buffer:  # written into GMP's own limbs (from_bytes: 53 µs a 1000-dof column, this 2.5 µs)
            packed = self._gmpy2.xmpz(0)
            ctypes.memmove(packed.limbs_write(count), column.ctypes.data, 8 * count)
            packed.limbs_finish(count)
            columns.append(packed - self._bias)
        return columns

    def _decode(self, columns: list[Any]) -> np.ndarray:
        """The biased limbs (block, N, limbs) of the rows of packed columns (each slot |v| < 2^(w−1)), read from
        GMP's limbs (to_bytes: 30 µs a 1000-dof column, this 3 µs)."""
        limbs = np.zeros((len(columns), self._slots * self._limbs), dtype=np.uint64)
        for row, column in zip(limbs, columns):
            biased = self._gmpy2.xmpz(column + self._bias)
            count = biased.num_limbs()
            row[:count] = np.ctypeslib.as_array((ctypes.c_uint64 * count).from_address(biased.limbs_read()))
        return limbs.reshape(len(columns), self._slots, self._limbs)[:, self._pad:self._pad + self._rows]

    @staticmethod
    def _to_float(limbs: np.ndarray, scale: int) -> np.ndarray:
        """Biased limbs as floats · 2^-scale (a negative slot's magnitude read as ~u: one unit low)."""
        negative = limbs[..., -1] < _TOP
        flip = np.where(negative, ~np.uint64(0), np.uint64(0))  # ~u for a negative slot
        count = limbs.shape[-1]

        def magnitude(limb: int) -> np.ndarray:
            values = limbs[..., limb] ^ flip
            return values & ~_TOP if limb == count - 1 else values

        # the 4 limbs from the block's top one: entries 2^-190 below its largest count as zero in a float correction
        top = next((limb for limb in reversed(range(count)) if magnitude(limb).any()), 0)
        total = np.zeros(limbs.shape[:-1])
        for limb in reversed(range(max(0, top - 3), top + 1)):
            total += np.ldexp(magnitude(limb).astype(float), 64 * limb - scale)
        return np.where(negative, -total, total)

    def residual(self, theta: np.ndarray) -> np.ndarray:
        """``K X − M X Θ`` as floats (Θ = theta · 2^-p), the exact packed residual at scale 2^(2p + s):
        ``r_k = Σ_o a_ok · (x_k moved by o slots)``, ``a_ok = K_o 2^(p+s−sK) − θ_k M_o 2^(s−sM)`` (one product or,
        for a power of two, one shift a diagonal: 5 passes over a chain's column, 9 in separate K x and M x)."""
        setup, p, s = self._setup, self._setup.p, self._scale
        offsets = sorted(set(setup.stiffness.diagonals) | set(setup.mass.diagonals), key=abs)
        stiffness = {o: entries << (p + s - shift) for o, (entries, shift) in setup.stiffness.diagonals.items()}
        mass = {o: entries << (s - shift) for o, (entries, shift) in setup.mass.diagonals.items()}
        residuals = []
        for column, t in zip(self._columns, theta):
            total = None
            for offset in offsets:
                a = stiffness.get(offset, 0) - int(t) * mass.get(offset, 0)
                if not a:
                    continue
                bits = self._width * offset  # row i takes x[i + offset]: a right shift by `bits`
                size = abs(a)
                if size & (size - 1) == 0:  # ±2^e: one shift, exact (the slots shifted out are empty pads)
                    bits -= size.bit_length() - 1
                    term = column >> bits if bits > 0 else column << -bits
                    sign = -1 if a < 0 else 1
                else:
                    term, sign = (column >> bits if bits > 0 else column << -bits) * a, 1
                total = (term if sign > 0 else -term) if total is None else total + term if sign > 0 else total - term
            residuals.append(0 if total is None else total)
        return self._to_float(self._decode(residuals), 2 * p + s).T

    def add(self, ints: np.ndarray, shift: int) -> None:
        self._columns = [column + correction for column, correction in zip(self._columns, self._encode(ints, shift))]

    def refined(self, last: tuple[np.ndarray, int]) -> _RefinedModes:
        """Norms and Rayleigh numerators from the exact lagged sums ``Σ_i x_i x_(i+o)`` of every column, before the
        ``last`` correction (``ints << shift``, M-orthogonal to the mode: second order there); the rows with it."""
        limbs = self._decode(self._columns)
        self._columns = []
        setup, rows = self._setup, self._rows
        # 16-bit pieces of each slot's two's complement (a view of its limbs) up to bit 16·count, above which every bit
        # is the sign, and the sign itself (−1 at 2^(16·count)): products < 2^32, sums over N < 2^21 exact in float64
        piece = 16
        count = -(-(setup.p + max(0, int(np.ceil(np.log2(setup.magnitude)))) + 2) // piece)
        complement = limbs.copy()
        complement[..., -1] ^= _TOP  # two's complement of each slot
        pieces = np.empty(limbs.shape[:2] + (count + 1,))
        pieces[..., :count] = complement.view(np.uint16)[..., :count]
        pieces[..., count] = np.where(limbs[..., -1] < _TOP, -1.0, 0.0)
        count += 1
        lags: dict[int, list[int]] = {}
        for offset in {abs(o) for band in (setup.stiffness, setup.mass) for o in band.diagonals}:
            gram = np.matmul(pieces[:, :rows - offset].transpose(0, 2, 1), pieces[:, offset:])  # (block, t, u), exact
            flipped = gram.astype(np.int64)[:, :, ::-1]
            sums = np.stack([np.trace(flipped, offset=count - 1 - d, axis1=1, axis2=2) for d in range(2 * count - 1)],
                            axis=1).tolist()  # Σ_{t+u=d}
            values = []
            for column in sums:
                total = 0
                for value in reversed(column):
                    total = (total << piece) + value
                values.append(total)
            lags[offset] = values

        def quadratic(band: _Band) -> list[int]:
            return [sum((entries * lags[abs(o)][k]) >> shift for o, (entries, shift) in band.diagonals.items())
                    for k in range(limbs.shape[0])]

        half = 1 << (self._width - 1)

        ints, shift = last

        def row(i: int) -> np.ndarray:
            return np.array([int.from_bytes(limbs[k, i].tobytes(), "little") - half + (int(ints[i, k]) << shift)
                             for k in range(limbs.shape[0])], dtype=object)

        return _RefinedModes(row, limbs.shape[0], quadratic(setup.mass), quadratic(setup.stiffness), setup.bits)


def _shifted_solver(setup: _Refinement, shift: float) -> Callable[[np.ndarray], np.ndarray]:
    """``r -> (K − σ M)⁻¹ r`` in float64 by LAPACK's banded LU with partial pivoting (O(N w²) once, O(N w) a solve;
    the tridiagonal gttrf/gttrs when w = 1: 9 + 11 µs a mode against gbtrf/gbtrs' 30 + 24 at 1000 dof, mostly
    the wrappers'); σ is nudged off an eigenvalue that float64 hits exactly (a singular factor)."""
    from scipy.linalg import lapack

    w = setup.width
    for nudge in (0.0, 2.0**-45, -(2.0**-45), 2.0**-40):
        sigma = shift + nudge * max(abs(shift), setup.largest)
        band = setup.stiffness_float - sigma * setup.mass_float
        if w == 1 and band.shape[1] > 2:  # A[i + 1, i], A[i, i], A[i, i + 1] at band[3, i], band[2, i], band[1, i + 1]
            # (scipy's gttrf wrapper rejects N = 2)
            *factors, info = lapack.dgttrf(band[3, :-1], band[2], band[1, 1:])
            if info == 0:
                return lambda rhs: lapack.dgttrs(*factors, rhs)[0]
        else:
            lu, pivots, info = lapack.dgbtrf(band, w, w)
            if info == 0:
                return lambda rhs: lapack.dgbtrs(lu, w, w, rhs, pivots)[0]
    return lambda rhs: np.full(rhs.shape, np.nan)  # singular at every nudge: the sweeps fail, the caller goes dense


def _mass_float_times(setup: _Refinement, Y: np.ndarray) -> np.ndarray:
    """``M @ Y`` in float64 from the band storage."""
    w, n = setup.width, Y.shape[0]
    result = np.zeros(Y.shape)
    for offset in range(-w, w + 1):  # row i takes M[i, i + offset] Y[i + offset]
        entries = setup.mass_float[2 * w - offset]
        if offset >= 0:
            result[:n - offset] += entries[offset:, None] * Y[offset:]
        else:
            result[-offset:] += entries[:n + offset, None] * Y[:n + offset]
    return result


def _refine(setup: _Refinement, columns: slice) -> _RefinedModes | None:
    """The float modes ``columns`` refined to the set-up's precision (see ``modal_coupling``).

    Fixed-point arithmetic on integers (X = ints · 2^-p): the residual ``r_k`` of every mode is formed exactly
    from the band of K and M (integer entries exactly, others to 2^-(p+64)), rounded to float64, and the mode
    corrected in float64: for a narrow band by the shifted solve ``δ_k = −(K − θ̃_k M)⁻¹ (r_k − M x̃_k (x̃_kᵀ r_k))``
    (θ̃_k the float eigenvalue, fixed: the factor is formed once; the solve's error and its part along x_k, a
    rescaling, are harmless; O(N w) a mode), otherwise by the projections on all the float modes,
    ``δ_k = −Σ_{l≠k} x̃_l (x̃_lᵀ r_k)/(θ_l − θ_k)`` (O(N²) a mode).  Both contract the error by ~2^-52 θ_max/gap
    a sweep.  Measured on a 1000-dof chain (51 digits): the projections took 0.9 s of (N × N) @ (N × block)
    products in all, the shifted solves 0.1 s.  None when the sweeps do not converge.
    """
    shapes, p, target = setup.shapes, setup.p, setup.target
    block = shapes[:, columns]
    indices = np.arange(shapes.shape[1])[columns]
    start = 62 - int(np.ceil(np.log2(setup.magnitude)))
    constant = all(isinstance(entries, int) for band in (setup.stiffness, setup.mass) for entries, _ in band.diagonals.values())
    constant = constant and _native_limbs()
    store = (_PackedColumns if constant else _ObjectColumns)(setup, np.rint(np.ldexp(block, start)).astype(np.int64), p - start)
    scale = int(np.ceil(np.log2(setup.largest)))
    theta = np.array([int(v) for v in np.rint(np.ldexp(setup.theta_float[indices], 52 - scale))], dtype=object)
    theta = theta << (p - 52 + scale)
    if setup.mass_float.size:
        solvers = [_shifted_solver(setup, float(value)) for value in setup.theta_float[indices]]
        mass_block = _mass_float_times(setup, block)
    else:
        theta_float = setup.theta_float
        gaps = theta_float[:, None] - theta_float[None, indices]
        gaps[indices, np.arange(len(indices))] = np.inf
    previous, contraction = None, 0.0
    for _ in range(int(np.ceil((target - 40) / setup.gain)) + 3):
        residual = store.residual(theta)
        if setup.mass_float.size:
            update = np.einsum("ik,ik->k", block, residual)  # x̃_kᵀ r_k = θ*_k − θ_k to first order
            projected = residual - mass_block * update[None, :]
            correction = -np.column_stack([solve(projected[:, [k]]) for k, solve in enumerate(solvers)])
        else:
            projections = shapes.T @ residual  # x̃_lᵀ r_k ≈ (θ_l − θ_k) δ_lk, and θ*_k − θ_k on the diagonal
            update = projections[indices, np.arange(len(indices))]
            correction = shapes @ (-projections / gaps)
        if not np.all(np.isfinite(correction)):
            return None
        theta = theta + _to_fixed(update, p)
        # the error left is about the next correction: this one times the contraction seen so far (2^8 to spare)
        size = float(np.max(np.abs(correction))) / setup.magnitude
        if previous is not None:  # the largest ratio of successive corrections seen (none yet: 1)
            contraction = max(contraction, size / previous) if contraction else size / previous
        previous = size
        if size * min(1.0, 256 * contraction if contraction else 1.0) <= 2.0**-target:
            # the last correction, made M-orthogonal to x̃_k, changes the norm and the Rayleigh quotient only to
            # second order: they are taken before it, and it is added to the rows read (not packed: one
            # conversion a mode saved)
            if setup.mass_float.size:
                correction = correction - block * (np.einsum("ik,ik->k", mass_block, correction)
                                                   / np.einsum("ik,ik->k", mass_block, block))[None, :]
            return store.refined(_fixed_parts(correction, p))
        store.add(*_fixed_parts(correction, p))
    return None


def _refined_blocks(system: _ExactSystem, digits: int) -> Iterator[_RefinedModes] | None:
    """The modes of :meth:`UnilateralSystem.modes` refined to ``digits`` digits, block by block, as the caller
    consumes them (O(N · block) ints at a time); None, or a None block: the caller falls back to the dense mpmath
    decomposition."""
    setup = _refinement(system, digits)
    if setup is None:
        return None
    return (_refine(setup, slice(first, min(first + _BLOCK, system.n_dof))) for first in range(0, system.n_dof, _BLOCK))


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
    frequencies: list[Any] = []
    shapes: list[list[Any]] = []
    for refined in _refined_blocks(system, digits) or [None]:
        if refined is None:
            return _dense_mpmath_modes(system, digits)
        with workprec(refined.bits):
            frequencies += refined.frequencies()
            roots = [mpmath.sqrt(norm) for norm in refined.norms]
            rows = [refined.row(i) for i in range(system.n_dof)]
            shapes += [[mpmath.mpf(int(row[k])) / root for row in rows] for k, root in enumerate(roots)]
    with workdps(digits):
        return [+value for value in frequencies], [[+value for value in column] for column in shapes]


def _dense_coupling(system: _ExactSystem, digits: int) -> tuple[list[Any], list[list[Any]], list[list[Any]]]:
    """:func:`_modal_coupling` from the dense mpmath decomposition."""
    frequencies, columns = _dense_mpmath_modes(system, digits)
    with workdps(digits + 10):
        A = [[_exact_mpf(v) for v in row] for row in system.A_exact.tolist()]
        W = [[_exact_mpf(v) for v in row] for row in system.W_exact.tolist()]
        B = [[+mpmath.fdot(row, column) for column in columns] for row in A]
        G = [[+mpmath.fdot(column, (W[r][i] for r in range(system.n_dof))) for i in range(system.n_springs)] for column in columns]
    with workdps(digits):
        return frequencies, [[+v for v in row] for row in B], [[+v for v in row] for row in G]


def _modal_coupling(system: _ExactSystem, digits: int) -> tuple[list[Any], list[list[Any]], list[list[Any]]]:
    """λ_k, ``B = A Φ`` and ``G = Φᵀ W`` of :meth:`~lindstedt.problems.system.UnilateralSystem.modal_coupling`."""
    frequencies = []
    B: list[list[Any]] = [[] for _ in range(system.A_exact.rows)]
    G: list[list[Any]] = []
    for refined in _refined_blocks(system, digits) or [None]:  # each block's shapes dropped once projected
        if refined is None:
            return _dense_coupling(system, digits)
        with workprec(refined.bits):
            frequencies += refined.frequencies()
            for row, values in zip(B, refined.projections(system.A_exact)):
                row += values
            if system.n_springs:
                G += [list(column) for column in zip(*refined.projections(system.W_exact.T))]
            else:
                G += [[] for _ in range(refined.count)]
    with workdps(digits):
        return [+value for value in frequencies], [[+value for value in row] for row in B], [[+value for value in row] for row in G]
