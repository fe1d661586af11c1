"""The one JSON encoding of results: :func:`to_jsonable` for everything results hold, and the :class:`JsonExport` mixin.

Every result class of the package exports itself through this module.  A
result is a frozen dataclass that derives from :class:`JsonExport`, names its
schema in the class attribute ``SCHEMA = "lindstedt.<name>/1"`` and keeps the
problem it was computed from (an :class:`~lindstedt.Oscillator` or a
:class:`~lindstedt.UnilateralSystem`) in a field; :meth:`JsonExport.to_dict`
converts its fields with :func:`to_jsonable` and :meth:`JsonExport.to_json`
writes strict JSON (never ``NaN``: non-finite numbers become ``null``).
Results with a documented hand-written schema (``Expansion``, ``NNMExpansion``,
``NNMResult``) keep their own ``to_dict`` and are exported through it when they
are nested inside another result.

Conversions of :func:`to_jsonable`:

* ``None``, ``bool``, ``str`` and ``int`` unchanged (NumPy integers and
  booleans become Python ones), enums by their value;
* floats (Python, NumPy, mpmath ``mpf``) to ``float``, ``None`` when NaN or infinite;
* complex numbers (Python, NumPy, mpmath ``mpc``) to ``[real, imag]``;
* NumPy arrays to nested lists, element by element as above;
* SymPy expressions to :func:`sympy.sstr` (exact text);
* an :class:`~lindstedt.Oscillator` to its ``describe()`` line plus the exact
  ``f``, ``a0``, ``omega0`` and ``a1``; a :class:`~lindstedt.UnilateralSystem`
  to its exact ``to_json_dict()``;
* anything with a ``to_dict()`` method through it (the nested results);
* other dataclasses by their exported fields (see :class:`JsonExport`);
* mappings to dicts with string keys; tuples, lists, sets to lists.

mpmath numbers are written as floats; a result that also keeps exact digits
(``NNMExpansion.to_dict()["omega_digits"]``) writes them as strings itself.

Examples
--------
>>> import numpy as np, sympy
>>> to_jsonable({"x": np.array([1.0, np.nan]), "n": np.int64(3), "f": sympy.Rational(1, 3)})
{'x': [1.0, None], 'n': 3, 'f': '1/3'}
>>> from dataclasses import dataclass
>>> @dataclass(frozen=True)
... class Point(JsonExport):
...     SCHEMA = "lindstedt.point/1"
...     x: float
...     _cache: object = None
>>> Point(float("inf")).to_dict()
{'schema': 'lindstedt.point/1', 'x': None}
"""

from __future__ import annotations

import dataclasses
import enum
import json
import math
from collections.abc import Mapping
from typing import Any, ClassVar

import mpmath
import numpy as np
import sympy

from .._precision import LOCK, locked, locked_methods
from .display import format_number, format_vector, html_table, labelled_repr, shorten

__all__ = ["JsonExport", "exported_fields", "finite_float", "to_jsonable"]


def finite_float(value: Any) -> float | None:
    """``float(value)``, or ``None`` when it is NaN, infinite or beyond a float's range (JSON has no such numbers).

    Examples
    --------
    >>> finite_float(2), finite_float(float("nan")), finite_float(-float("inf")), finite_float(10**400)
    (2.0, None, None, None)
    """
    try:
        number = float(value)
    except OverflowError:  # an exact integer or rational beyond 1.8e308
        return None
    return number if math.isfinite(number) else None


def _complex(real: Any, imag: Any) -> list[float | None]:
    return [finite_float(real), finite_float(imag)]


@locked  # printing evaluates the numbers (sympy sets mpmath's precision)
def _problem_dict(value: Any) -> dict[str, Any] | None:
    """The JSON form of the library's problems, or None for anything else."""
    from ..problems.oscillator import Oscillator
    from ..problems.system import UnilateralSystem

    if isinstance(value, Oscillator):
        return {
            "description": value.describe(),
            "f": sympy.sstr(value.f),
            "a0": sympy.sstr(value.a0),
            "omega0": sympy.sstr(value.omega0),
            "a1": sympy.sstr(value.a1),
        }
    if isinstance(value, UnilateralSystem):
        return value.to_json_dict()
    return None


def exported_fields(instance: Any) -> list[dataclasses.Field]:
    """The dataclass fields :meth:`JsonExport.to_dict` writes.

    Skipped: names starting with ``_`` and fields declared with
    ``field(metadata={"export": False})``.

    Examples
    --------
    >>> from dataclasses import dataclass, field
    >>> @dataclass
    ... class Run:
    ...     value: float
    ...     matrix: object = field(default=None, metadata={"export": False})
    >>> [f.name for f in exported_fields(Run(1.0))]
    ['value']
    """
    return [
        item
        for item in dataclasses.fields(instance)
        if not item.name.startswith("_") and item.metadata.get("export", True)
    ]


def to_jsonable(value: Any) -> Any:
    """Convert ``value`` to plain JSON data (dict, list, str, int, float, bool, None); never NaN.

    Parameters
    ----------
    value : Any
        Anything a result holds (see the module docstring for the rules).

    Returns
    -------
    Any
        Data that ``json.dumps(..., allow_nan=False)`` accepts.

    Raises
    ------
    TypeError
        For a value of a type the export layer does not know.

    Examples
    --------
    >>> import mpmath, numpy as np
    >>> to_jsonable((np.float64(0.5), float("-inf"), mpmath.mpf(2), 1 + 2j))
    [0.5, None, 2.0, [1.0, 2.0]]
    >>> to_jsonable(np.array([[1, 2], [3, 4]]))
    [[1, 2], [3, 4]]
    >>> import lindstedt
    >>> to_jsonable(lindstedt.Oscillator("u**3", a0=1, omega0=1))["f"]
    'u**3'
    """
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, enum.Enum):
        return to_jsonable(value.value)
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating, mpmath.mpf)):
        return finite_float(value)
    if isinstance(value, (complex, np.complexfloating)):
        return _complex(value.real, value.imag)
    if isinstance(value, mpmath.mpc):
        return _complex(value.real, value.imag)
    if isinstance(value, np.ndarray):
        return [to_jsonable(item) for item in value] if value.ndim else to_jsonable(value[()])
    problem = _problem_dict(value)
    if problem is not None:
        return problem
    if isinstance(value, sympy.Basic):
        with LOCK:
            return sympy.sstr(value)
    if callable(getattr(value, "to_dict", None)) and not isinstance(value, type):
        return value.to_dict()
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {item.name: to_jsonable(getattr(value, item.name)) for item in exported_fields(value)}
    if isinstance(value, Mapping):
        return {str(to_jsonable(key) if not isinstance(key, str) else key): to_jsonable(item) for key, item in value.items()}
    if isinstance(value, (tuple, list, set, frozenset)):
        return [to_jsonable(item) for item in value]
    raise TypeError(f"to_jsonable cannot convert a {type(value).__name__}; give the result a to_dict() or a JSON rule here")


@locked
def display_value(value: Any) -> str:
    """A field of a result as short text for people: numbers to 10 digits, vectors cut to 8 entries,
    nested results and problems by name, long text shortened (see :mod:`lindstedt.render.display`).

    Examples
    --------
    >>> display_value(np.linspace(0, 1, 30)), display_value(mpmath.mpf(1) / 3), display_value("ok")
    ('[0, 0.0344828, 0.0689655, 0.103448, 0.137931, 0.172414, 0.206897, 0.241379, … (30 entries)]', '0.3333333333', "'ok'")
    """
    if isinstance(value, str):
        return repr(value)
    if value is None or isinstance(value, (bool, int, float, complex, mpmath.mpf, mpmath.mpc, np.generic)):
        return format_number(value)
    if isinstance(value, np.ndarray):
        if value.ndim == 0:
            return format_number(value)
        return format_vector(value) + (f" (shape {value.shape})" if value.ndim > 1 else "")
    if isinstance(value, enum.Enum):
        return str(value.value)
    describe = getattr(value, "describe", None)
    if callable(describe) and not isinstance(value, type):  # a problem: its equation
        return shorten(f"{type(value).__name__}: {describe()}", 160)
    if isinstance(value, JsonExport) or (dataclasses.is_dataclass(value) and not isinstance(value, type)):
        return f"{type(value).__name__}(…)"
    if isinstance(value, Mapping):
        return f"{{… {len(value)} entries}}" if value else "{}"
    if isinstance(value, (list, tuple)):
        if all(isinstance(item, (int, float, mpmath.mpf, np.generic)) and not isinstance(item, bool) for item in value):
            return format_vector(value)
        if value and all(isinstance(item, JsonExport) for item in value):
            return f"[{len(value)} × {type(value[0]).__name__}]"
        return shorten(str([display_value(item) for item in value[:8]]), 160)
    return shorten(str(value), 160)


@locked_methods()
class JsonExport:
    """Mixin giving a result dataclass ``to_dict()`` and ``to_json()`` through :func:`to_jsonable`, and the
    displays for people: a labelled ``__repr__`` and Jupyter's ``_repr_html_`` table of the exported fields
    (a dataclass keeps them when declared with ``repr=False``; a result may override ``_display_rows``).

    The class names its schema in ``SCHEMA = "lindstedt.<name>/1"``; the
    dictionary is ``{"schema": SCHEMA, <field>: to_jsonable(value), ...}`` in
    field order, without the fields whose name starts with ``_`` or that are
    declared with ``field(metadata={"export": False})``.

    Examples
    --------
    >>> import json, lindstedt
    >>> period = lindstedt.validate.exact_period(lindstedt.Oscillator("u**3", a0=1, omega0=1), 0.1)
    >>> data = json.loads(period.to_json())
    >>> data["schema"], data["period"] == period.period, data["problem"]["f"]
    ('lindstedt.exact-period/1', True, 'u**3')
    """

    SCHEMA: ClassVar[str] = ""

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary: ``"schema"`` then the exported fields (NaN and infinities as ``None``)."""
        data: dict[str, Any] = {"schema": type(self).SCHEMA}
        for item in exported_fields(self):
            data[item.name] = to_jsonable(getattr(self, item.name))
        return data

    def to_json(self, indent: int | None = 2) -> str:
        """Strict JSON text of :meth:`to_dict` (``allow_nan=False``: never NaN)."""
        return json.dumps(self.to_dict(), indent=indent, allow_nan=False)

    def _display_rows(self, quoted: bool = True) -> list[tuple[str, str]]:
        """(label, text) of every exported field that the dataclass shows (``field(repr=False)`` hides one)."""
        rows = []
        for item in exported_fields(self):
            if not item.repr:
                continue
            value = getattr(self, item.name)
            rows.append((item.name, display_value(value) if quoted or not isinstance(value, str) else value))
        return rows

    def __repr__(self) -> str:
        """``Name(field=value, …)`` with short values (numbers to 10 digits, vectors cut)."""
        return labelled_repr(type(self).__name__, self._display_rows())

    def _repr_html_(self) -> str:
        """Jupyter's rendering: a two-column table of the fields."""
        success = getattr(self, "success", None)
        state = "" if success is None else (": success" if success else ": FAILED")
        return html_table(f"{type(self).__name__}{state}", self._display_rows(quoted=False))
