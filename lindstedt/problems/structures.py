"""Structural matrices from files, and the lowest modes of large sparse models.

A structural model enters the package as its mass, stiffness (and damping) matrices of

    ``M X'' + C X' + K X = 0``,

the linear part of ``M X'' + K X + ε W (A X − b)_+ = 0`` (:class:`~lindstedt.problems.system.UnilateralSystem`).

* :func:`read_matrices` — ``M``, ``K`` (optionally ``C``, or any named matrices) from the files structural
  engineers already have: numpy ``.npz`` / ``.npy`` (``numpy.savez``, ``scipy.sparse.save_npz``), MATLAB
  ``.mat`` (v4–v7, ``scipy.io.loadmat``) and Matrix Market ``.mtx`` (``scipy.io.mmread``), dense or sparse.
  Nothing is evaluated (no pickle); every file is bounded in size before it is read.  The matrices are
  checked: square, of one size, finite, real, symmetric to the relative tolerance
  ``max|X − Xᵀ| ≤ rtol · max|X|``, and ``M`` positive definite (Cholesky; for a sparse ``M`` the
  diagonal of its symmetric ``LDLᵀ`` factorisation by SuperLU, all positive by Sylvester's criterion).
* :func:`sparse_modes` — the few lowest modes ``K φ = λ² M φ``, ``φᵀ M φ = 1``, by the Lanczos method in
  shift-invert mode (``scipy.sparse.linalg.eigsh`` with ``sigma``): it iterates with
  ``(K − σ M)⁻¹ M``, whose largest eigenvalues ``1/(λ² − σ)`` are the modes nearest ``σ``; one sparse
  factorisation of ``K − σ M`` and O(N) work per iteration.  The shapes are signed as in
  :meth:`UnilateralSystem.modes <lindstedt.problems.system.UnilateralSystem.modes>`.
"""

from __future__ import annotations

import os
import stat
import zipfile
from typing import Any, Mapping, Sequence

import numpy as np

from .._errors import ProblemError
from .modes import _leading_sign
from .system import Modes

__all__ = ["read_matrices", "sparse_modes", "SYMMETRY_RTOL", "MAX_FILE_BYTES"]

#: relative tolerance of the symmetry check of :func:`read_matrices`: ``max|X − Xᵀ| ≤ rtol · max|X|``
SYMMETRY_RTOL = 1e-12
#: default bound (bytes) on a file read by :func:`read_matrices` and on the data it expands to (256 MiB)
MAX_FILE_BYTES = 1 << 28

_SUFFIXES = (".npz", ".npy", ".mat", ".mtx")
_DENSE_CHOLESKY_MAX = 200  # a sparse M up to this size is checked by a dense Cholesky (measured: dense 0.54 ms, sparse LDLᵀ
# 0.17 ms at 200 dof; 21 ms against 0.32 ms at 1000, and the dense copy is N² memory)


def _sparse():
    import scipy.sparse  # here, not at module level: import lindstedt stays light

    return scipy.sparse


# --------------------------------------------------------------------------- #
# reading
# --------------------------------------------------------------------------- #
def _checked_path(path: Any, max_bytes: int) -> str:
    """The path as a string, refused unless it is a regular file of at most ``max_bytes`` bytes."""
    if not isinstance(path, (str, os.PathLike)):
        raise ProblemError(f"a matrix file must be given by its path (str or pathlib.Path), got {type(path).__name__}")
    name = os.fspath(path)
    if not isinstance(name, str):
        name = os.fsdecode(name)
    try:
        info = os.stat(name)
    except OSError as error:
        raise ProblemError(f"cannot read the matrix file {name!r}: {error.strerror or error}; check the path") from None
    if not stat.S_ISREG(info.st_mode):
        raise ProblemError(f"the matrix file {name!r} is not a regular file; give the path of a .npz, .npy, .mat or .mtx file")
    if info.st_size > max_bytes:
        raise ProblemError(
            f"the matrix file {name!r} has {info.st_size} bytes, more than the limit {max_bytes}; "
            f"pass max_bytes={info.st_size} (or more) to read it"
        )
    suffix = os.path.splitext(name)[1].lower()
    if suffix not in _SUFFIXES:
        raise ProblemError(
            f"the matrix file {name!r} has the suffix {suffix!r}; write it as .npz (numpy.savez or scipy.sparse.save_npz), "
            ".npy, .mat (scipy.io.savemat, MATLAB save -v7) or .mtx (scipy.io.mmwrite)"
        )
    return name


def _unreadable(name: str, error: BaseException, how: str) -> ProblemError:
    return ProblemError(f"cannot read the matrix file {name!r} ({type(error).__name__}: {error}); {how}")


def _read_npz(name: str, max_bytes: int) -> dict[str, Any]:
    """The arrays of a ``.npz`` (a ``scipy.sparse.save_npz`` file is one matrix, under the key ``""``)."""
    how = "write it with numpy.savez(path, M=M, K=K) or scipy.sparse.save_npz(path, matrix)"
    try:
        with zipfile.ZipFile(name) as archive:  # the expanded size is bounded before anything is inflated
            expanded = sum(member.file_size for member in archive.infolist())
    except (OSError, zipfile.BadZipFile, ValueError) as error:
        raise _unreadable(name, error, how) from None
    if expanded > max_bytes:
        raise ProblemError(
            f"the matrix file {name!r} expands to {expanded} bytes, more than the limit {max_bytes}; "
            f"pass max_bytes={expanded} (or more) to read it"
        )
    try:
        with np.load(name, allow_pickle=False) as data:
            arrays = {key: data[key] for key in data.files}
    except Exception as error:  # noqa: BLE001 - any failure of a hostile file is the user's to fix
        raise _unreadable(name, error, how) from None
    if "format" in arrays and "shape" in arrays and "data" in arrays:
        try:
            return {"": _sparse().load_npz(name)}
        except Exception as error:  # noqa: BLE001
            raise _unreadable(name, error, how) from None
    return arrays


def _read_npy(name: str) -> dict[str, Any]:
    try:
        return {"": np.load(name, allow_pickle=False)}
    except Exception as error:  # noqa: BLE001
        raise _unreadable(name, error, "write it with numpy.save(path, matrix) (no object arrays)") from None


def _read_mat(name: str, max_bytes: int) -> dict[str, Any]:
    import scipy.io

    how = "save it from MATLAB with save(path, 'M', 'K', '-v7') or with scipy.io.savemat (v7.3 / HDF5 files are not read)"
    try:
        listing = scipy.io.whosmat(name)
    except Exception as error:  # noqa: BLE001
        raise _unreadable(name, error, how) from None
    for variable, shape, kind in listing:
        if kind != "sparse" and int(np.prod(shape, dtype=object)) * 16 > max_bytes:
            raise ProblemError(
                f"the variable {variable!r} of the matrix file {name!r} has shape {shape}, more than the limit of "
                f"{max_bytes} bytes; pass a larger max_bytes to read it"
            )
    try:
        data = scipy.io.loadmat(name, squeeze_me=False, mat_dtype=False)
    except Exception as error:  # noqa: BLE001
        raise _unreadable(name, error, how) from None
    return {key: value for key, value in data.items() if not key.startswith("__")}


def _read_mtx(name: str, max_bytes: int) -> dict[str, Any]:
    import scipy.io

    how = "write it with scipy.io.mmwrite(path, matrix) (a real or integer matrix)"
    try:
        rows, cols, entries, layout, field, _ = scipy.io.mminfo(name)
    except Exception as error:  # noqa: BLE001
        raise _unreadable(name, error, how) from None
    if field not in ("real", "integer", "double"):
        raise ProblemError(f"the matrix file {name!r} holds {field} entries; a structural matrix must be real ({how})")
    count = rows * cols if layout == "array" else entries
    if count * 24 > max_bytes:
        raise ProblemError(
            f"the matrix file {name!r} declares {count} entries, more than the limit of {max_bytes} bytes; "
            "pass a larger max_bytes to read it"
        )
    try:
        return {"": scipy.io.mmread(name)}
    except Exception as error:  # noqa: BLE001
        raise _unreadable(name, error, how) from None


def _read_file(name: str, max_bytes: int) -> dict[str, Any]:
    suffix = os.path.splitext(name)[1].lower()
    if suffix == ".npz":
        return _read_npz(name, max_bytes)
    if suffix == ".npy":
        return _read_npy(name)
    if suffix == ".mat":
        return _read_mat(name, max_bytes)
    return _read_mtx(name, max_bytes)


def _as_matrix(value: Any, key: str, origin: str) -> Any:
    """A real 2-D numpy array or a CSR sparse matrix of floats or ints, finite."""
    sparse = _sparse()
    if sparse.issparse(value):
        matrix = sparse.csr_matrix(value)
        values = matrix.data
    else:
        matrix = np.asarray(value)
        values = matrix
    if values.dtype.kind not in "iuf":
        kind = {"c": "complex", "b": "boolean", "O": "object", "U": "text", "S": "text"}.get(values.dtype.kind, str(values.dtype))
        raise ProblemError(f"{key} in {origin} is {kind}; a structural matrix must hold real numbers")
    if matrix.ndim != 2 or matrix.shape[0] != matrix.shape[1] or matrix.shape[0] == 0:
        raise ProblemError(f"{key} in {origin} must be a non-empty square N×N matrix, got shape {tuple(matrix.shape)}")
    if values.dtype.kind == "f" and not np.all(np.isfinite(values)):
        raise ProblemError(f"{key} in {origin} has non-finite entries (NaN or infinity); every entry must be a finite real number")
    return matrix


def _check_symmetric(matrix: Any, key: str, origin: str, rtol: float) -> None:
    sparse = _sparse()
    if sparse.issparse(matrix):
        difference = matrix - matrix.T
        asymmetry = float(abs(difference).max()) if difference.nnz else 0.0
        largest = float(abs(matrix).max()) if matrix.nnz else 0.0
    else:
        as_float = matrix.astype(float)
        asymmetry = float(np.max(np.abs(as_float - as_float.T)))
        largest = float(np.max(np.abs(as_float)))
    if asymmetry > rtol * largest:
        raise ProblemError(
            f"{key} in {origin} is not symmetric: max|{key} − {key}ᵀ| = {asymmetry:.3g} > {rtol:g} · max|{key}| = "
            f"{rtol * largest:.3g}; check the export (a full, not triangular, matrix), or pass ({key} + {key}.T)/2 "
            f"if the difference is rounding, or raise symmetry_rtol"
        )


def _check_positive_definite(matrix: Any, key: str, origin: str) -> None:
    """Refuse a mass matrix that is not positive definite (dense Cholesky, or the signs of a sparse LDLᵀ)."""
    sparse = _sparse()
    fix = (f"{key} in {origin} must be positive definite (a mass matrix); check that every degree of freedom "
           "carries mass (no massless rotations or Lagrange multipliers: condense them first) and that the "
           "constrained degrees of freedom are removed")
    diagonal = matrix.diagonal().astype(float)
    if np.any(diagonal <= 0):
        index = int(np.flatnonzero(diagonal <= 0)[0])
        raise ProblemError(f"{fix}; its diagonal entry {index} is {diagonal[index]:g}")
    n = matrix.shape[0]
    if not sparse.issparse(matrix) or n <= _DENSE_CHOLESKY_MAX:
        dense = matrix.toarray() if sparse.issparse(matrix) else matrix
        try:
            np.linalg.cholesky(dense.astype(float))
        except np.linalg.LinAlgError:
            raise ProblemError(f"{fix}; its Cholesky factorisation fails") from None
        return
    from scipy.sparse.linalg import splu

    try:  # symmetric mode without pivoting: P M Pᵀ = L U with U = D Lᵀ; M ≻ 0 ⟺ every pivot > 0
        factor = splu(matrix.tocsc().astype(float), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                      options={"SymmetricMode": True})
    except RuntimeError:  # exactly singular
        raise ProblemError(f"{fix}; it is singular") from None
    if not np.array_equal(factor.perm_r, factor.perm_c):  # SuperLU pivoted off the diagonal: M is indefinite
        raise ProblemError(f"{fix}; its symmetric factorisation needs off-diagonal pivots, so it is indefinite")
    pivots = factor.U.diagonal()
    if np.any(pivots <= 0):
        raise ProblemError(f"{fix}; {int(np.sum(pivots <= 0))} pivots of its LDLᵀ factorisation are not positive")


def read_matrices(
    source: Any,
    names: Sequence[str] = ("M", "K"),
    *,
    symmetry_rtol: float = SYMMETRY_RTOL,
    max_bytes: int = MAX_FILE_BYTES,
) -> dict[str, Any]:
    """Read and check the structural matrices ``names`` (default ``M`` and ``K``) from files.

    Parameters
    ----------
    source : path or mapping of name to path
        One file holding every matrix under its name — ``.npz`` (``numpy.savez(path, M=M, K=K)``) or ``.mat``
        (MATLAB ``save(path, 'M', 'K')``, v4 to v7) — or a mapping ``{name: path}`` of one-matrix files:
        ``.mtx`` (Matrix Market), ``.npy``, a ``.npz`` written by ``scipy.sparse.save_npz``, or a ``.npz``/``.mat``
        holding ``name`` (or a single matrix).
    names : sequence of str
        The matrices to read.  Each is checked square, of the common size, real and finite, and symmetric to
        ``symmetry_rtol``; ``"M"``, when read, is also checked positive definite.  ``"C"`` (damping) is read like
        the others.
    symmetry_rtol : float
        Relative tolerance of the symmetry check, ``max|X − Xᵀ| ≤ symmetry_rtol · max|X|``
        (default :data:`SYMMETRY_RTOL` = 1e-12).
    max_bytes : int
        Largest file read, and largest content a compressed file may expand to (default :data:`MAX_FILE_BYTES`,
        256 MiB).

    Returns
    -------
    dict
        ``{name: matrix}``: a ``numpy.ndarray`` as stored (dense), or a ``scipy.sparse.csr_matrix`` (sparse).

    Raises
    ------
    ProblemError
        On an unreadable, non-regular, oversized or unsupported file, a missing name, a matrix of the wrong
        shape or kind, a non-finite entry, a non-symmetric matrix or an ``M`` that is not positive definite;
        the message names the fix.

    Examples
    --------
    >>> import os, tempfile, numpy as np, scipy.sparse, scipy.io
    >>> folder = tempfile.mkdtemp()
    >>> np.savez(os.path.join(folder, "chain.npz"), M=np.eye(2), K=np.array([[2.0, -1.0], [-1.0, 2.0]]))
    >>> read_matrices(os.path.join(folder, "chain.npz"))["K"].tolist()
    [[2.0, -1.0], [-1.0, 2.0]]
    >>> scipy.io.mmwrite(os.path.join(folder, "K.mtx"), scipy.sparse.csr_matrix([[2.0, -1.0], [-1.0, 2.0]]))
    >>> matrices = read_matrices({"M": os.path.join(folder, "chain.npz"), "K": os.path.join(folder, "K.mtx")})
    >>> type(matrices["K"]).__name__, matrices["K"].nnz
    ('csr_matrix', 4)
    """
    if isinstance(names, str) or not isinstance(names, Sequence) or not names or not all(isinstance(n, str) and n for n in names):
        raise ProblemError(f"names must be a non-empty sequence of matrix names such as ('M', 'K'), got {names!r}")
    if len(set(names)) != len(names):
        raise ProblemError(f"names repeats a matrix: {list(names)}")
    if isinstance(max_bytes, bool) or not isinstance(max_bytes, (int, np.integer)) or max_bytes < 1:
        raise ProblemError(f"max_bytes must be a positive integer, got {max_bytes!r}")
    if isinstance(symmetry_rtol, bool) or not isinstance(symmetry_rtol, (int, float)) or not 0 <= symmetry_rtol < 1:
        raise ProblemError(f"symmetry_rtol must be a number in [0, 1), got {symmetry_rtol!r}")
    raw: dict[str, tuple[Any, str]] = {}
    if isinstance(source, Mapping):
        unknown = sorted(set(source) - set(names))
        if unknown:
            raise ProblemError(f"the files given for {unknown} are not among the names read {list(names)}; add them to names")
        for key in names:
            if key not in source:
                raise ProblemError(f"no file is given for {key}; pass {{{key!r}: path, ...}} or a single .npz/.mat holding {key}")
        for key in names:
            name = _checked_path(source[key], max_bytes)
            content = _read_file(name, max_bytes)
            if key in content:
                raw[key] = (content[key], repr(name))
            elif len(content) == 1:
                raw[key] = (next(iter(content.values())), repr(name))
            else:
                raise ProblemError(f"the matrix file {name!r} holds {sorted(content)}, not one matrix nor one named {key!r}; "
                                   f"save {key} alone or under its name")
    else:
        name = _checked_path(source, max_bytes)
        content = _read_file(name, max_bytes)
        missing = [key for key in names if key not in content]
        if missing:
            found = sorted(key for key in content if key) or "no named matrix"
            raise ProblemError(
                f"the matrix file {name!r} lacks {missing} (it holds {found}); save them under these names, e.g. "
                "numpy.savez(path, M=M, K=K), or give one file per matrix as {'M': path_M, 'K': path_K}"
            )
        raw = {key: (content[key], repr(name)) for key in names}
    matrices: dict[str, Any] = {}
    size = None
    for key in names:
        value, origin = raw[key]
        matrix = _as_matrix(value, key, origin)
        if size is None:
            size, first = matrix.shape[0], key
        elif matrix.shape[0] != size:
            raise ProblemError(
                f"{key} in {origin} is {matrix.shape[0]}×{matrix.shape[0]} but {first} is {size}×{size}; "
                "every matrix of one model has one row per degree of freedom (same constraints removed from each)"
            )
        _check_symmetric(matrix, key, origin, float(symmetry_rtol))
        if key == "M":
            _check_positive_definite(matrix, key, origin)
        matrices[key] = matrix
    return matrices


# --------------------------------------------------------------------------- #
# modes
# --------------------------------------------------------------------------- #
def sparse_modes(M: Any, K: Any, count: int, *, sigma: float = 0.0) -> Modes:
    """The ``count`` modes of ``K φ = λ² M φ`` nearest ``λ² = sigma`` by shift-invert Lanczos (``eigsh``).

    With the default ``sigma = 0`` (``K`` positive definite) these are the lowest modes.  The shapes are
    mass-normalised (``Φᵀ M Φ = I``) and signed like :meth:`UnilateralSystem.modes
    <lindstedt.problems.system.UnilateralSystem.modes>` (the entry of largest magnitude positive).

    Parameters
    ----------
    M, K : array_like or scipy.sparse matrix, shape (N, N)
        Symmetric mass (positive definite) and stiffness matrices.
    count : int
        Number of modes, ``1 ≤ count < N`` (for all N modes use the dense ``UnilateralSystem.modes``).
    sigma : float
        The shift: the modes with ``λ²`` nearest ``sigma`` are returned (``K − σ M`` must be nonsingular).

    Returns
    -------
    Modes
        ``(frequencies, shapes)``: λ increasing (shape ``(count,)``) and Φ column by column (``(N, count)``).

    Notes
    -----
    Float64 limits the accuracy: the residual ``K φ − λ² M φ`` of a smooth mode cancels to ``eps · ‖K‖ ‖φ‖``,
    so ``λ_k²`` carries a relative error of order ``eps · cond(K)`` whatever the solver.  For a beam of
    ``n`` elements ``cond(K) ~ (L/h)⁴``: the first cantilever frequency was measured off by 7e-10 (relative)
    at n = 128, 3e-7 at 512, 1e-5 at 2048 and 1e-3 at 5000 (10⁴ dof).  Fine meshes need the modes refined
    with residuals in higher precision.

    Examples
    --------
    >>> import numpy as np, scipy.sparse
    >>> n = 50
    >>> K = scipy.sparse.diags([-np.ones(n - 1), 2 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1], format="csc")
    >>> lam, phi = sparse_modes(scipy.sparse.identity(n, format="csc"), K, 2)
    >>> np.allclose(lam, 2 * np.sin(np.arange(1, 3) * np.pi / (2 * (n + 1))), rtol=1e-12, atol=0)
    True
    """
    from scipy.sparse.linalg import ArpackError, eigsh

    sparse = _sparse()
    mass = sparse.csc_matrix(M, dtype=float)
    stiffness = sparse.csc_matrix(K, dtype=float)
    n = mass.shape[0]
    if mass.shape != (n, n) or stiffness.shape != (n, n):
        raise ProblemError(f"M and K must be square of one size, got shapes {mass.shape} and {stiffness.shape}")
    if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or not 1 <= count < n:
        raise ProblemError(f"count must be an integer in 1..{n - 1} (N − 1), got {count!r}; for all the modes use "
                           "UnilateralSystem(M, K).modes()")
    if isinstance(sigma, bool) or not isinstance(sigma, (int, float)) or not np.isfinite(sigma):
        raise ProblemError(f"sigma must be a finite real number (a shift of λ²), got {sigma!r}")
    try:
        # a fixed start vector: ARPACK's default is a fresh random one per call, and the modes' last bits (and every
        # exact result refined from them: ResidualFlexibility's reduced data below 1e-30) changed from run to run
        start = np.random.default_rng(20261127).uniform(-1.0, 1.0, n)
        squared, shapes = eigsh(stiffness, k=int(count), M=mass, sigma=float(sigma), which="LM", tol=0.0, v0=start)
    except RuntimeError as error:  # a singular K − σ M ("Factor is exactly singular")
        raise ProblemError(f"K − sigma·M is singular at sigma = {sigma} ({error}); the structure is a mechanism "
                           "(fix its supports) or sigma is an eigenvalue (move it)") from None
    except ArpackError as error:
        raise ProblemError(f"eigsh did not converge ({error}); ask for fewer modes or move sigma") from None
    order = np.argsort(squared)
    squared, shapes = squared[order], np.array(shapes[:, order])
    if np.any(squared <= 0):
        raise ProblemError(f"λ² = {squared[squared <= 0][0]:.3g} is not positive; K must be positive definite "
                           "(a structure held against rigid-body motion)")
    for k in range(shapes.shape[1]):
        column = shapes[:, k]
        column /= np.sqrt(column @ (mass @ column))
        column *= _leading_sign(column.tolist())
    return Modes(np.sqrt(squared), shapes)
