"""``lindstedt nnm MODEL.json --reduce K``: a structure reduced to K modes plus its residual vectors before the NNM.

The model ``M X'' + K X + ε Σ_i w_i f_i(a_iᵀ X − b_i) = 0`` comes either from a system file (``M``, ``K`` as JSON
matrices, see :meth:`~lindstedt.problems.system.UnilateralSystem.from_json_dict`) or, for finite-element models,
from matrix files named in the JSON::

    {"matrices": "beam.npz",                       # or {"M": "M.mtx", "K": "K.mtx"}; paths relative to MODEL.json
     "elements": [{"law": "Max(0, u)", "a": {"101": 1, "102": -1}, "b": 0}]}

read by :func:`~lindstedt.problems.structures.read_matrices` (``.npz``, ``.npy``, ``.mat``, ``.mtx``; bounded,
checked, no pickle).  An element's row ``a`` (and force column ``w``, default ``a``) is a list of N numbers or, for
large models, an object ``{"dof index": value}``; every value goes through the one parser.  The model is reduced
by :class:`~lindstedt.problems.reduction.ResidualFlexibility` (priced before it runs) and the command works on
the reduced system.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from typing import Any

import sympy

from .._errors import ProblemError

__all__ = ["reduced_structure"]

_MODEL_KEYS = ("matrices", "elements")


def _row(value: Any, n: int, what: str) -> dict[int, sympy.Expr]:
    """A row of N entries from a list or a sparse object ``{"index": value}``, every value parsed exactly."""
    from ..problems.parsing import parse_real

    if isinstance(value, list):
        if len(value) != n:
            raise ProblemError(f"{what} has {len(value)} entries; the model has {n} degrees of freedom "
                               "(or give it as an object {\"index\": value})")
        items = enumerate(value)
    elif isinstance(value, Mapping):
        items = []
        for key, entry in value.items():
            if not (isinstance(key, str) and key.isdigit() and int(key) < n):
                raise ProblemError(f"{what} has the key {key!r}; keys are degree-of-freedom indices 0…{n - 1} as strings")
            items.append((int(key), entry))
    else:
        raise ProblemError(f"{what} must be a list of {n} numbers or an object {{\"index\": value}}, got {value!r:.60}")
    row = {index: parse_real(entry, what=f"{what}[{index}]") for index, entry in items}
    return {index: entry for index, entry in row.items() if entry != 0}


def _matrix_files(matrices: Any, folder: str) -> Any:
    if isinstance(matrices, str):
        return os.path.join(folder, matrices)
    if isinstance(matrices, Mapping) and set(matrices) == {"M", "K"} and all(isinstance(v, str) for v in matrices.values()):
        return {key: os.path.join(folder, value) for key, value in matrices.items()}
    raise ProblemError("'matrices' must be a file name (a .npz or .mat holding M and K) or {\"M\": file, \"K\": file}, "
                       f"got {matrices!r:.80}")


def reduced_structure(data: Mapping[str, Any], path: str, modes: int, digits: int) -> Any:
    """The :class:`~lindstedt.problems.reduction.ReducedStructure` of a model file's content ``data``.

    ``path`` is the model file (matrix files are found relative to its folder).
    """
    from ..problems.reduction import ResidualFlexibility
    from ..problems.structures import read_matrices
    from ..problems.system import _ELEMENT_KEYS, UnilateralSystem

    method = ResidualFlexibility(modes=modes, digits=digits)
    if "matrices" not in data:
        system = UnilateralSystem.from_json_dict(data)
        return method.reduce((system.M_exact, system.K_exact), A=system.A_exact, b=list(system.b_exact),
                             W=system.W_exact, laws=[str(law) for law in system.laws])
    unknown = sorted(set(data) - set(_MODEL_KEYS))
    if unknown:
        raise ProblemError(f"unknown keys {unknown} in a model with 'matrices'; its keys are matrices and elements "
                           "(couplings need the matrices in the JSON file)")
    matrices = read_matrices(_matrix_files(data["matrices"], os.path.dirname(os.path.abspath(path))))
    n = matrices["M"].shape[0]
    elements = data.get("elements")
    if not isinstance(elements, list) or not elements:
        raise ProblemError("a model with 'matrices' needs 'elements': a non-empty list of {law, a, b, w}")
    A, W, offsets, laws = {}, {}, [], []
    for i, element in enumerate(elements):
        if not isinstance(element, Mapping) or "a" not in element or set(element) - set(_ELEMENT_KEYS):
            raise ProblemError(f"elements[{i}] must be an object with 'a' and optional law, b, w, got {element!r:.80}")
        row = _row(element["a"], n, f"elements[{i}].a")
        if not row:
            raise ProblemError(f"elements[{i}].a is zero: an element acts on a nonzero combination of displacements")
        A.update({(i, j): value for j, value in row.items()})
        column = row if "w" not in element else _row(element["w"], n, f"elements[{i}].w")
        W.update({(j, i): value for j, value in column.items()})
        offsets.append(element.get("b", 0))
        laws.append(element.get("law", "Max(0, u)"))
    m = len(elements)
    return method.reduce((matrices["M"], matrices["K"]), A=sympy.SparseMatrix(m, n, A), b=offsets,
                         W=sympy.SparseMatrix(n, m, W), laws=laws)
