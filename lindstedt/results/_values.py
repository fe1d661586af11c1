"""The parameter values of an expansion's float evaluators: read into float points and checked against what the
derivation assumed (signs of the free symbols, the contact regime ``|b| < a0`` of a gap b, ...).

Floats are taken as they are (their exact binary value, as the exact reader takes them) and checked by vectorised
sign tests with a rounding bound, evaluated with ω_0 … ω_M in one compiled family
(:func:`lindstedt.compiled.family.compile_family`); an undecided or violated element is checked exactly, which
raises the :class:`~lindstedt.ParameterError` naming the regime.  Exact numbers (``"3/10"``) are read and checked
exactly, once per values.  :class:`FloatState` is what an expansion keeps for its float evaluators: the float
data per parameter point, the compiled families and the exact ω_k they were compiled from.

Functions of an :class:`~lindstedt.Expansion`, typed ``Any``: :mod:`lindstedt.results.expansion` imports this
module, never the other way round.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from typing import Any, Callable, Mapping, NamedTuple

import numpy as np
import sympy

from ..compiled.family import BoundedFamily, compile_family
from .._errors import ParameterError
from .._precision import locked
from ..problems.parsing import parse_real
from .assumptions import check_names, shown_values

__all__ = ["GRID_CELLS", "UNSET", "FloatState", "Point", "core_family", "finite", "floats", "grid_cell", "omega_expr", "omega_known",
           "parameter_grid", "probe_points", "read", "substitution", "to_float", "values_key"]

_MEMORY = 64  # scalar parameter points whose float data an expansion keeps
GRID_CELLS = 256  # cells of the parameter grid of a one-parameter expansion (:func:`parameter_grid`)
UNSET: Any = object()  # a member of FloatState not built yet


class Point(NamedTuple):
    """Parameter values as floats, in the order of Expansion.arguments, with the float data computed for them."""

    arrays: tuple[Any, ...]  # float or float array per argument
    shape: tuple[int, ...]  # their broadcast shape (() for scalars)
    cache: dict[Any, Any]  # checked flag, compiled values (kept for the last _MEMORY scalar points)


class FloatState:
    """What one expansion keeps for its float evaluators (it holds no reference to the expansion).

    ``symbols`` are the expansion's free symbols in the order of :attr:`lindstedt.Expansion.arguments`, ``names``
    their names, ``gauge`` the gauge's text for warnings, ``cache`` the float data (per parameter values, per
    point, the compiled families) and ``no_parameters`` the point of an expansion without free symbols; ``range_source`` and ``layout`` are built on first use.

    Examples
    --------
    >>> a0 = sympy.Symbol("a0", positive=True)
    >>> state = FloatState((a0,), "epsilon")
    >>> values, bounds = state.family("demo", lambda: [a0**2 / 3])(0.5)
    >>> round(float(values[0]), 12), bool(bounds[0] < 1e-15)
    (0.083333333333, True)
    """

    __slots__ = ("symbols", "names", "gauge", "cache", "no_parameters", "range_source", "layout")

    def __init__(self, symbols: tuple[sympy.Symbol, ...], gauge: str):
        self.symbols = symbols
        self.names = tuple(symbol.name for symbol in symbols)
        self.gauge = gauge
        self.cache: dict[Any, Any] = {}
        self.no_parameters = Point((), (), {"checked": True})
        # built on first use, under the lock the evaluators hold (plain attributes: the hot paths read them directly)
        self.range_source: Any = UNSET  # the data orbit_range reads, as one function of the symbols (None: no range)
        self.layout: Any = None  # where each float of the displacement lives (_WaveformLayout)

    def cached(self, tag: Any, values: Mapping[Any, Any] | None, compute: Callable[[], Any]) -> Any:
        """Float data that depends only on the parameter values, computed once per values (ε-independent).

        ``compute`` goes through :func:`substitution`, which checks the values against the derivation's
        assumptions once per values.
        """
        key = (tag, values_key(values))
        if key not in self.cache:
            self.cache[key] = compute()
        return self.cache[key]

    def family(self, tag: Any, expressions: Callable[[], list[sympy.Expr]]) -> BoundedFamily | None:
        """The compiled :class:`~lindstedt.compiled.family.BoundedFamily` of some expressions (None: not compilable)."""
        families = self.cache.setdefault("families", {})
        if tag not in families:
            families[tag] = compile_family(expressions(), self.symbols)
        return families[tag]

    def remembered(self, key: Any, arrays: tuple[float, ...]) -> Point:
        """The scalar point ``arrays`` with its cache (the last _MEMORY points are kept)."""
        memory = self.cache.setdefault("memory", OrderedDict())
        point = memory.get(key)
        if point is None:
            point = memory[key] = Point(arrays, (), {})
            if len(memory) > _MEMORY:
                memory.popitem(last=False)
        return point

    def values_at(self, point: Point, index: int) -> dict[str, float]:
        """The values of element ``index`` of the point, by name."""
        return {name: float(np.broadcast_to(value, point.shape).flat[index]) for name, value in zip(self.names, point.arrays)}

    def exact_at(self, expression: sympy.Expr, point: Point, index: int) -> float:
        """The exact value of ``expression`` at element ``index`` of the point (its doubles read exactly)."""
        substitution = {
            symbol: sympy.Rational(float(np.broadcast_to(value, point.shape).flat[index]))
            for symbol, value in zip(self.symbols, point.arrays)
        }
        return to_float(expression.xreplace(substitution))


def values_key(values: Mapping[Any, Any] | None) -> tuple[tuple[str, str], ...]:
    """The values as a hashable key (names and numbers as text)."""
    return tuple(sorted((str(k), str(v)) for k, v in (values or {}).items()))


@locked  # sympy's evalf of acos, … sets mpmath's process-wide precision
def to_float(expression: sympy.Expr) -> float:
    """float() of a numeric expression; NaN where it is not a finite real number (checked by :func:`finite`)."""
    try:
        return float(expression)
    except (TypeError, ValueError):
        return math.nan


def finite(numbers: np.ndarray, substitution: Mapping[sympy.Symbol, sympy.Expr]) -> np.ndarray:
    """``numbers``, or the ParameterError of coefficients singular or not real at the substituted values."""
    if not np.all(np.isfinite(numbers)):
        given = shown_values(substitution)
        raise ParameterError(
            f"the expansion's coefficients are singular or not real at {given or 'these values'}: the values are at a "
            "degenerate point of the symbolic derivation; re-derive with the numbers substituted "
            "(lindstedt.expand(..., a0=..., params=...))"
        )
    return numbers


def _binary_value(value: sympy.Expr) -> float | None:
    """The double equal to the exact number ``value``, or None."""
    if not value.is_Rational:
        return None
    number = float(value)
    return number if sympy.Rational(number) == value else None


def substitution(expansion: Any, values: Mapping[Any, Any] | None) -> dict[sympy.Symbol, sympy.Expr]:
    """The numeric substitution for ``values``, checked against the derivation's assumptions.

    Checked once per values (cached with the float data): repeated evaluations pay nothing.
    """
    cache = expansion._floats.cache
    key = ("substitution", values_key(values))
    if key not in cache:  # numeric_substitution names an unknown value (check_names) or a missing one
        cache[key] = expansion._assumptions.check(expansion.problem.numeric_substitution(values))
    return cache[key]


def floats(expansion: Any, expressions: list[sympy.Expr], values: Mapping[Any, Any] | None) -> np.ndarray:
    """The expressions at the exactly substituted values, as floats (finite, else the ParameterError)."""
    exact = substitution(expansion, values)
    return finite(np.array([to_float(e.xreplace(exact)) for e in expressions], dtype=float), exact)


def read(expansion: Any, values: Mapping[Any, Any] | None) -> Point | None:
    """The parameter values as floats in the order of :attr:`~lindstedt.Expansion.arguments` (float arrays kept),
    checked against the derivation's assumptions; None when an exact number a double cannot hold is among them
    (then the exact path evaluates).

    Floats are taken as they are (their exact binary value, as the exact reader takes them) and checked by
    vectorised float tests (:func:`_check_point`); other numbers go through the problem's reader and the
    exact check, once per values."""
    state = expansion._floats
    names = state.names
    if not values:
        if names:
            expansion.problem.numeric_substitution(values)  # raises: values needed
        return state.no_parameters
    check_names(values, names)
    numbers: dict[str, Any] = {}
    scalar = True
    for key, value in values.items():
        name = key.name if isinstance(key, sympy.Symbol) else str(key)
        if isinstance(value, float):
            if not math.isfinite(value):
                parse_real(value, what=name)  # raises
            numbers[name] = float(value)
        elif isinstance(value, (np.ndarray, list, tuple)) and np.asarray(value).dtype.kind in "fiu":
            array = numbers[name] = np.asarray(value, dtype=float)
            if not np.all(np.isfinite(array)):
                parse_real(float(array[~np.isfinite(array)].flat[0]), what=name)  # raises
            scalar = False
        else:
            return _read_exact(expansion, values)
    if len(numbers) != len(names) or len(values) != len(names) or any(name not in numbers for name in names):
        expansion.problem.numeric_substitution({key: 0 for key in values})  # names the missing or unknown ones
        raise ParameterError(f"values must name {', '.join(names)} once each")
    arrays = tuple(numbers[name] for name in names)
    if scalar:
        point = state.remembered(("float", arrays), arrays)
    else:
        point = Point(arrays, np.broadcast_shapes(*[np.shape(value) for value in arrays]), {})
    _check_point(expansion, point)
    return point


def _read_exact(expansion: Any, values: Mapping[Any, Any]) -> Point | None:
    """Exact numbers: read and checked exactly (once per values); the compiled path if doubles hold them."""
    state = expansion._floats
    key = ("exact", values_key(values))
    memory = state.cache.setdefault("memory", OrderedDict())
    if key in memory:
        return memory[key]
    exact = substitution(expansion, values)
    numbers = [_binary_value(exact[symbol]) for symbol in state.symbols]
    point = None
    if all(number is not None for number in numbers):
        point = state.remembered(("float", tuple(numbers)), tuple(numbers))
        point.cache["checked"] = True
    memory[key] = point
    return point


def _check_point(expansion: Any, point: Point) -> None:
    """The derivation's assumptions on float parameter values: vectorised sign tests with a rounding
    bound (evaluated with ω_0 … ω_M in one compiled family); an undecided or violated element is checked
    exactly, which raises the ParameterError naming the regime."""
    if point.cache.get("checked"):
        return
    family, conditions, highest = core_family(expansion)
    values, bounds = family(*point.arrays) if family is not None else (None, None)
    assumptions = expansion._assumptions
    if values is None and conditions:
        violated, undecided = np.zeros(point.shape, dtype=bool), np.ones(point.shape, dtype=bool)
    else:
        violated, undecided = assumptions.float_verdict(
            None if values is None else values[:conditions], None if bounds is None else bounds[:conditions], point.arrays
        )
    for index in [*np.flatnonzero(violated)[:1], *np.flatnonzero(undecided)]:
        assumptions.check(expansion.problem.numeric_substitution(expansion._floats.values_at(point, int(index))))
    if values is not None:
        point.cache["core"] = (values[conditions:], bounds[conditions:], highest)
    point.cache["checked"] = True


def core_family(expansion: Any) -> tuple[Any, int, int]:
    """(family, number of assumption conditions, M): one compiled family for the assumptions' conditions
    and ω_0 … ω_M (M = N, or N + 1 once ω_{N+1} is derived), evaluated once per new parameter point."""
    last = expansion._steps * expansion.order
    highest = last + (1 if omega_known(expansion, last + 1) else 0)
    conditions = expansion._assumptions.float_conditions

    def expressions() -> list[sympy.Expr]:
        return [*conditions, *[omega_expr(expansion, k) for k in range(highest + 1)]]

    return expansion._floats.family(("core", highest), expressions), len(conditions), highest


def parameter_grid(expansion: Any) -> tuple[np.ndarray, np.ndarray] | None:
    """For an expansion with one free symbol p: the grid nodes p_i = s_i / (1 − |s_i|), s_i = −1 + 2i/GRID_CELLS
    (i = 0 … GRID_CELLS; ±inf at the ends: uniform in s = p / (1 + |p|), which maps the real line onto (−1, 1)),
    and whether the derivation's assumptions hold at each node (decided by the float test, not undecided);
    None for other expansions.  What the evaluators tabulate once per expansion (the range of ε that needs no
    warning, the coefficients whose closed form cancels somewhere) is tabulated on these nodes."""
    state = expansion._floats
    if "grid" not in state.cache:
        grid = None
        if len(state.symbols) == 1:
            s = np.linspace(-1.0, 1.0, GRID_CELLS + 1)
            with np.errstate(divide="ignore"):
                nodes = s / (1 - np.abs(s))
            valid = np.isfinite(nodes)
            family, conditions, _ = core_family(expansion)
            if family is None and conditions:
                valid[:] = False
            elif conditions:
                values, bounds = family(nodes[valid])
                violated, undecided = expansion._assumptions.float_verdict(values[:conditions], bounds[:conditions], (nodes[valid],))
                valid[valid] = ~violated & ~undecided
            grid = (nodes, valid)
        state.cache["grid"] = grid
    return state.cache["grid"]


def probe_points(expansion: Any) -> np.ndarray:
    """The valid nodes of :func:`parameter_grid` and, towards each end of a valid stretch, 52 points approaching the
    neighbouring invalid node geometrically (to within 2^-52 of the way; doubling up to 2^40 towards ±inf): where a
    closed form that cancels at the edge of its domain (a gap κ → ±a0) fails first.  Empty without a grid."""
    grid = parameter_grid(expansion)
    if grid is None:
        return np.array([])
    nodes, valid = grid
    parts = [nodes[valid]]
    steps = 1 - 0.5 ** np.arange(1, 53)
    for index in np.flatnonzero(valid):
        for neighbour in (index - 1, index + 1):
            if 0 <= neighbour < len(nodes) and not valid[neighbour]:
                if np.isfinite(nodes[neighbour]):
                    parts.append(nodes[index] + (nodes[neighbour] - nodes[index]) * steps)
                else:
                    parts.append(nodes[index] * 2.0 ** np.arange(1, 41))
    return np.concatenate(parts)


def grid_cell(value: Any) -> Any:
    """The index of the cell of :func:`parameter_grid` holding p (int, or int array for an array)."""
    if isinstance(value, float):
        return min(max(int((value / (1 + abs(value)) + 1) * (GRID_CELLS / 2)), 0), GRID_CELLS - 1)
    value = np.asarray(value, dtype=float)
    return np.clip(((value / (1 + np.abs(value)) + 1) * (GRID_CELLS / 2)).astype(np.int64), 0, GRID_CELLS - 1)


def omega_expr(expansion: Any, k: int) -> sympy.Expr:
    """The exact ω_k, kept with the float data (the families are compiled from it)."""
    cache = expansion._floats.cache.setdefault("omega expressions", {})
    if k not in cache:
        cache[k] = expansion.omega_correction(k)
    return cache[k]


def omega_known(expansion: Any, k: int) -> bool:
    """Whether ω_k costs nothing more to derive (within the expansion's order, or derived already)."""
    last = expansion._steps * expansion.order
    return k <= last or k in expansion._floats.cache.get("omega expressions", {}) or (
        k == last + 1 and "omega_next" in expansion.__dict__
    )
