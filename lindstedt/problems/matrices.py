"""Exact matrices from user input: ``X_exact`` read entry by entry, ``X`` its correctly rounded float copy.

An entry (int, float, ``fractions.Fraction``, numeric string, sympy number) is read exactly by the one
parser (:func:`~lindstedt.problems.parsing.parse_real`: the string ``"0.1"`` is ``1/10``, the float ``0.1``
its exact binary value); a matrix is given as nested lists, a numpy array or a sympy Matrix (by its nonzero
entries: a large banded matrix converts in O(nonzeros)).  The float copy ``fl(X_exact)`` is read-only.
``M`` and ``K`` must satisfy ``M = Mᵀ`` exactly and ``M ≻ 0`` (Cholesky).
"""

from __future__ import annotations

from fractions import Fraction
from typing import Any, Sequence

import numpy as np
import sympy

from .._errors import ProblemError
from .parsing import parse_real


def _exact_scalar(value: Any, what: str) -> sympy.Expr:
    """One entry as an exact, finite, real sympy number (read by the one parser; a float is its binary value)."""
    if isinstance(value, np.bool_):
        raise ProblemError(f"{what} is a boolean ({value}); give a number such as 1, 0.5 or '1/3'")
    if isinstance(value, np.generic):
        value = value.item()
    # fast paths (what parse_real returns for them, without its printing): the N² entries of a large system
    if type(value) is int and -(2**62) < value < 2**62:
        return sympy.Integer(value)
    if isinstance(value, sympy.Rational) and int(value.p).bit_length() + int(value.q).bit_length() <= 128:
        return value
    return parse_real(value, what=what)


def _exact_to_float(expr: sympy.Expr) -> float:
    """Correctly rounded float of an exact number."""
    if isinstance(expr, sympy.Rational):
        return float(Fraction(int(expr.p), int(expr.q)))
    return float(sympy.N(expr, 40))


def _exact_matrix(value: Any, name: str, *, ndim: int) -> sympy.ImmutableMatrix:
    """Convert nested sequences / numpy arrays / sympy matrices (ndim 1 or 2)."""
    if isinstance(value, sympy.MatrixBase) and ndim == 2:
        # by its nonzero entries (a large banded system converts in O(nonzeros)); zeros are exact
        converted = {(i, j): _exact_scalar(entry, f"{name}[{i}, {j}]") for (i, j), entry in sorted(value.todok().items())}
        return sympy.ImmutableMatrix(sympy.SparseMatrix(value.rows, value.cols, converted))
    if isinstance(value, sympy.MatrixBase):
        rows = value.tolist()
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
    array = np.zeros((matrix.rows, matrix.cols))
    for (i, j), value in matrix.todok().items():
        array[i, j] = _exact_to_float(value)
    array = array.reshape(matrix.rows, matrix.cols)
    if vector:
        array = array.reshape(matrix.rows)
    array.setflags(write=False)
    return array


def _exactly_equal(first: sympy.Expr, second: sympy.Expr) -> bool:
    return first == second or sympy.simplify(first - second) == 0


def _check_symmetric_positive_definite(exact: sympy.ImmutableMatrix, numeric: np.ndarray, name: str, role: str) -> None:
    entries = exact.todok()  # the nonzero entries: a large banded matrix is checked in O(nonzeros)
    for i, j in sorted(set(entries) | {(j, i) for i, j in entries}):
        if i < j:
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
