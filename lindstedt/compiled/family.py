"""Compiled families of closed forms with a first-order bound of their float64 rounding error.

:func:`compile_family` turns a list of closed forms in some symbols (ω_k, waveform coefficients, contact-angle
shifts, the signs an expansion's derivation assumed) once into a :class:`BoundedFamily`, a vectorised float64
evaluator that returns, with the values, a bound ``|fl(e) − e| ≤ bound`` to first order in the unit roundoff;
the float evaluators of :class:`~lindstedt.Expansion` accept a value where the bound is small and recompute it
exactly (or by the stable series of :mod:`lindstedt.compiled.stable_series`) where the closed form cancels.
At one point (:meth:`BoundedFamily.scalar`) the same values and bounds come from plain floats: the atoms term by
term and each block as one generated straight-line function (no NumPy call per point).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import mpmath
import numpy as np
import sympy

from .._precision import LOCK, workdps, workprec

__all__ = ["BoundedFamily", "compile_family", "forget_families"]


# Compiled families of closed forms with a first-order rounding-error bound
# =====================================================================================================
#
# The numeric evaluators of an expansion with free symbols (a0, omega0, a gap kappa...) evaluate many closed
# forms (ω_k, the waveform coefficients, the moving contact angles, the assumptions' signs) at new parameter
# values.  :func:`compile_family` turns such a list once into a vectorised float64 evaluator that also returns
# a first-order bound of its rounding error, so a caller can accept a value where the bound is small and
# recompute it exactly where the closed form cancels (near κ = ±1 or at a root).
#
# Representation.  Each expression is written as N/D, polynomials in *generators*: the free symbols (exact
# inputs) and the atoms that depend on them, ``base^(1/q)`` and elementary functions (acos, asin, atan, exp,
# log, sin, cos, ...).  Symbol-free constants (π, acos(3/10), sqrt(91)) are folded into the coefficients at 40
# digits before rounding; a single-term denominator is folded into negative exponents.  An atom's argument is
# factored over Q (1 − κ² = −(κ − 1)(κ + 1)) and evaluated factor by factor, which keeps it accurate to a few
# ulps where the expanded form would cancel (its root at κ → 1).
#
# Error bound (first order in the unit roundoff u = 2^-53).  Generators carry a relative error (0 for the
# symbols; for an atom f(a): |f'(a)| err(a) + 2u |f(a)|, libm being within one ulp).  A monomial Π x_g^e_g has
# relative error Σ |e_g| rel_g plus one u per power (e ∉ {0, 1}) and per product; a row Σ_m c_m x^m has
#   err ≤ Σ_m |c_m x^m| (rel_m + rel(c_m)) + γ_{n−1} Σ_m |c_m x^m|,   γ_{n−1} = (n − 1) u / (1 − (n − 1) u)
# (any summation order), rel(c) = 0 for ±2^k, u for another double (the product), 2u for a rounded constant;
# a row of at most two terms has one rounding of its result instead of the γ term.  A quotient adds
# (err_N + |q| err_D)/|D| + u|q|.  The bound is first order: callers accept a value only where it is far below
# their tolerance (so second-order terms are negligible).

_UNIT = 2.0**-53
_SCALAR_TERMS = 2000  # largest block evaluated at one point by generated straight-line code


def _abs_derivative_acos(x: np.ndarray) -> np.ndarray:
    return 1 / np.sqrt(np.abs(1 - x * x))


def _math(function: Any) -> Any:
    """A math function returning NaN outside its domain (as numpy does)."""

    def call(x: float) -> float:
        try:
            return function(x)
        except (ValueError, OverflowError):
            return math.nan

    return call


# sympy function: (numpy f, numpy |f'|, math f, math |f'|)
_FUNCTIONS: dict[Any, tuple[Any, Any, Any, Any]] = {
    sympy.acos: (np.arccos, _abs_derivative_acos, _math(math.acos), _math(lambda x: 1 / math.sqrt(abs(1 - x * x)))),
    sympy.asin: (np.arcsin, _abs_derivative_acos, _math(math.asin), _math(lambda x: 1 / math.sqrt(abs(1 - x * x)))),
    sympy.atan: (np.arctan, lambda x: 1 / (1 + x * x), math.atan, lambda x: 1 / (1 + x * x)),
    sympy.exp: (np.exp, np.exp, _math(math.exp), _math(math.exp)),
    sympy.log: (np.log, lambda x: 1 / np.abs(x), _math(math.log), _math(lambda x: 1 / abs(x))),
    sympy.sin: (np.sin, lambda x: np.ones_like(x), _math(math.sin), lambda x: 1.0),
    sympy.cos: (np.cos, lambda x: np.ones_like(x), _math(math.cos), lambda x: 1.0),
    sympy.sinh: (np.sinh, np.cosh, _math(math.sinh), _math(math.cosh)),
    sympy.cosh: (np.cosh, np.cosh, _math(math.cosh), _math(math.cosh)),
    sympy.tanh: (np.tanh, lambda x: np.ones_like(x), math.tanh, lambda x: 1.0),
    sympy.asinh: (np.arcsinh, lambda x: 1 / np.sqrt(1 + x * x), math.asinh, lambda x: 1 / math.sqrt(1 + x * x)),
    sympy.acosh: (np.arccosh, lambda x: 1 / np.sqrt(np.abs(x * x - 1)), _math(math.acosh), _math(lambda x: 1 / math.sqrt(abs(x * x - 1)))),
    sympy.atanh: (np.arctanh, lambda x: 1 / np.abs(1 - x * x), _math(math.atanh), _math(lambda x: 1 / abs(1 - x * x))),
}


class _Unsupported(Exception):
    """An expression outside what :func:`compile_family` represents (Piecewise, Max, symbolic exponents...)."""


def _coefficient_rounding(value: Any) -> float:
    """Relative error of c·x in float64 for the exact constant ``value`` (mpf): 0 for ±2^k, u for another
    double (the product's rounding), 2u for a rounded constant."""
    number = float(value)
    if number == 0:
        return 0.0
    if mpmath.mpf(number) != value:
        return 2 * _UNIT
    mantissa, _ = math.frexp(abs(number))
    return 0.0 if mantissa == 0.5 else _UNIT


class _Block:
    """Rows Σ_m c_{r,m} Π_g x_g^{e_{m,g}} over a prefix of the generators, evaluated with an error bound."""

    def __init__(self, rows: list[dict[tuple[int, ...], Any]], generators: int):
        monomials = sorted({monomial for row in rows for monomial in row})
        index = {monomial: position for position, monomial in enumerate(monomials)}
        exponents = np.array(monomials, dtype=np.int64).reshape(len(monomials), generators)
        count, size = len(rows), len(monomials)
        coefficients = np.zeros((count, size))
        rounding = np.zeros((count, size))
        for r, row in enumerate(rows):
            for monomial, value in row.items():
                coefficients[r, index[monomial]] = float(value)
                rounding[r, index[monomial]] = _coefficient_rounding(value)
        absolute = np.abs(coefficients)
        zero = np.zeros_like(coefficients)
        # one product gives the rows, their propagated error and the sums of |terms|:
        # [C 0 0; 0 |C|·rel(c) |C|; 0 |C| 0] @ [x^m; |x^m|; |x^m|·rel_m]
        self.stack = np.block([[coefficients, zero, zero], [zero, absolute * rounding, absolute], [zero, absolute, zero]])
        self.rows = count
        terms = np.array([len(row) for row in rows])
        gamma = np.maximum(terms - 1, 0) * _UNIT
        short = terms <= 2
        self.summation = np.where(short, 0.0, gamma / (1 - gamma))[:, None]
        self.short = np.where(short, _UNIT, 0.0)[:, None] if short.any() else None  # one rounding of the result
        # x^k by pow (within one ulp); counted as k - 1 roundings (repeated products) and one more for k < 0,
        # which also covers pow; one rounding per product of powers
        powers = np.maximum(np.abs(exponents) - 1, 0) + (exponents < 0)
        factors = (exponents != 0).sum(axis=1)
        self.roundings = ((powers.sum(axis=1) + np.maximum(factors - 1, 0)) * _UNIT)[:, None]
        self.magnitudes = np.abs(exponents).astype(float)
        # per generator used: the exponent range and where each monomial takes its power from
        self.tables = []
        for g in range(generators):
            column = exponents[:, g]
            if column.any():
                low = int(column.min())
                self.tables.append((g, np.arange(low, int(column.max()) + 1, dtype=float)[:, None], column - low))
        self.generators = generators
        self._source_rows = (rows, monomials)  # for the straight-line scalar evaluator (:meth:`scalar_function`)
        self._scalar: Any = None
        # small blocks (an atom's factors) are evaluated in plain floats for one point: numpy's per-call
        # overhead would dominate; the same bound, term by term
        self.python = None
        if sum(len(row) for row in rows) <= 16:
            self.python = [
                (
                    [
                        (float(value), _coefficient_rounding(value)
                         + (sum(max(abs(e) - 1, 0) + (e < 0) for e in monomial) + max(sum(e != 0 for e in monomial) - 1, 0)) * _UNIT,
                         tuple((g, e) for g, e in enumerate(monomial) if e))
                        for monomial, value in row.items()
                    ],
                    len(row) <= 2,
                    float(self.summation[r, 0]),
                )
                for r, row in enumerate(rows)
            ]

    def evaluate_floats(self, values: list[float], relative: list[float]) -> tuple[list[float], list[float]]:
        """:meth:`evaluate` at one point in plain floats (small blocks only: ``self.python``)."""
        results, bounds = [], []
        for terms, short, summation in self.python:
            total = size = propagated = 0.0
            for coefficient, rounding, factors in terms:
                term, error = coefficient, rounding
                for g, exponent in factors:
                    term *= values[g] ** exponent
                    error += abs(exponent) * relative[g]
                total += term
                size += abs(term)
                propagated += abs(term) * error
            results.append(total)
            bounds.append(propagated + (_UNIT * abs(total) if short else summation * size))
        return results, bounds

    def scalar_function(self, exact: int) -> Any:
        """The rows and their bounds at one point as one generated straight-line Python function of the generator
        values and relative errors (lists) returning two lists: the same bound as :meth:`evaluate`, term by term
        (Σ_m |c_m| |x^m| (rel(c_m) + rel_m + the summation's γ), or one rounding u |result| for rows of at most two
        terms); the first ``exact`` generators (the symbols) carry no error.  Generated on first use.  Measured on the core family of a symbolic-κ gap expansion (order 3: 9 rows,
        56 monomials, 102 terms): 20 µs through :meth:`evaluate` and the quotients (NumPy's per-call overhead on one
        column), 7 µs here; the whole family at one point 36 µs → 10 µs; the order-4 waveform family (96 rows, 654
        terms) 53 µs → 42 µs.  None for a block of more than _SCALAR_TERMS terms (the time here grows with the terms,
        NumPy's hardly: its product is left to win there).  The function raises OverflowError / ZeroDivisionError
        where a power does (the caller falls back to NumPy)."""
        if self._scalar is None:
            rows = self._source_rows[0]
            self._scalar = False if sum(len(row) for row in rows) > _SCALAR_TERMS else _generate_block(
                *self._source_rows, self.generators, self.summation[:, 0], exact)
        return self._scalar or None

    def evaluate(self, values: np.ndarray, relative: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Values and error bounds of the rows, shape (rows, S), from generators ``values`` (G, S) with
        relative errors ``relative`` (G, S)."""
        monomial = None
        for g, exponents, position in self.tables:
            table = (values[g] ** exponents)[position]
            monomial = table if monomial is None else monomial * table
        if monomial is None:
            monomial = np.ones((self.stack.shape[1] // 3, values.shape[1]))
        size_of = np.abs(monomial)
        error = self.magnitudes @ relative[: self.generators] + self.roundings
        stacked = self.stack @ np.concatenate((monomial, size_of, size_of * error))
        rows = self.rows
        result = stacked[:rows]
        bound = stacked[rows : 2 * rows] + self.summation * stacked[2 * rows :]
        if self.short is not None:
            bound += self.short * np.abs(result)
        return result, bound


def _generate_block(rows: list[dict[tuple[int, ...], Any]], monomials: list[tuple[int, ...]], generators: int,
                    summation: np.ndarray, exact: int) -> Any:
    """The straight-line scalar evaluator of a :class:`_Block` (see :meth:`_Block.scalar_function`)."""
    used = sorted({g for monomial in monomials for g, e in enumerate(monomial) if e})
    lines = ["def block(v, r):"]
    for g in used:
        lines.append(f"    g{g} = v[{g}]" + (f"; q{g} = r[{g}]" if g >= exact else ""))
    powers: dict[tuple[int, int], str] = {}
    erring: set[int] = set()  # monomials with a rounding or an inexact generator
    for monomial in monomials:
        for g, e in enumerate(monomial):
            if e not in (0, 1) and (g, e) not in powers:
                powers[(g, e)] = name = f"p{g}_{e}".replace("-", "m")
                lines.append(f"    {name} = g{g} ** {e}")  # pow, as NumPy's table of powers
    for index, monomial in enumerate(monomials):
        factors = [f"g{g}" if e == 1 else powers[(g, e)] for g, e in enumerate(monomial) if e]
        count = sum(max(abs(e) - 1, 0) + (e < 0) for e in monomial) + max(sum(e != 0 for e in monomial) - 1, 0)
        error = [repr(count * _UNIT)] * bool(count) + [f"{abs(e)}.0 * q{g}" for g, e in enumerate(monomial) if e and g >= exact]
        lines.append(f"    x{index} = {' * '.join(factors) or '1.0'}; a{index} = abs(x{index})")
        if error:  # else exact: 1 or one exact symbol
            lines.append(f"    e{index} = a{index} * ({' + '.join(error)})")
            erring.add(index)
    position = {monomial: index for index, monomial in enumerate(monomials)}
    results, bounds = [], []
    for r, row in enumerate(rows):
        short = len(row) <= 2
        value, bound = [], []
        for monomial, coefficient in row.items():
            m, c = position[monomial], float(coefficient)
            weight = abs(c) * (_coefficient_rounding(coefficient) + (0.0 if short else float(summation[r])))
            value.append(f"{c!r} * x{m}")
            if m in erring:
                bound.append(f"{abs(c)!r} * e{m}")
            if weight:
                bound.append(f"{weight!r} * a{m}")
        lines.append(f"    s{r} = {' + '.join(value)}")
        if short:
            bound.append(f"{_UNIT!r} * abs(s{r})")
        lines.append(f"    b{r} = {' + '.join(bound) or '0.0'}")
        results.append(f"s{r}")
        bounds.append(f"b{r}")
    lines.append(f"    return [{', '.join(results)}], [{', '.join(bounds)}]")
    namespace: dict[str, Any] = {}
    exec(compile("\n".join(lines), "<lindstedt compiled family>", "exec"), namespace)  # generated from numbers only
    return namespace["block"]


@dataclass(frozen=True)
class _Atom:
    kind: str  # "root" (argument^(1/q)) or "function"
    root: int
    function: Any
    derivative: Any
    scalar_function: Any  # the same on floats (math)
    scalar_derivative: Any
    constant: float  # the argument is constant · Π factor^power over earlier generators
    constant_error: float
    block: _Block | None
    source: int | None  # the argument is this generator (constant 1, no factors)
    exponents: np.ndarray  # (rows of ``block``, 1): the power of each factor
    powers: tuple[int, ...]  # the same as ints
    magnitudes: np.ndarray  # |exponents| as a row
    roundings: float  # u per product and per power


class BoundedFamily:
    """Float64 values of a list of closed forms in ``symbols``, vectorised, with first-order error bounds.

    Call with one number or array per symbol (broadcast together); returns ``(values, bounds)`` of shape
    ``(len(expressions),) + broadcast shape``.  Build with :func:`compile_family`.

    Examples
    --------
    >>> import sympy
    >>> kappa = sympy.Symbol("kappa", real=True)
    >>> family = compile_family([sympy.acos(kappa) - kappa * sympy.sqrt(1 - kappa**2)], (kappa,))
    >>> values, bounds = family(0.5)
    >>> round(float(values[0]), 12), bool(bounds[0] < 1e-15)
    (0.614184849304, True)
    """

    def __init__(self, symbols: tuple[sympy.Symbol, ...], atoms: list[_Atom], block: _Block, quotients: np.ndarray, rows: int):
        self.symbols, self.atoms, self.block, self.rows = symbols, atoms, block, rows
        # rows of ``block``: the numerators, then the denominators that are not one term (quotients[r] >= 0)
        self.quotient_rows = np.flatnonzero(quotients >= 0)
        self.divisor_rows = quotients[self.quotient_rows]
        self._quotient_pairs = list(zip(self.quotient_rows.tolist(), self.divisor_rows.tolist()))

    def scalar(self, *numbers: float) -> tuple[list[float], list[float]] | None:
        """``(values, bounds)`` at one point as lists of floats, all in plain Python (the atoms, then the generated
        straight-line rows of :meth:`_Block.scalar_function`, then the quotients); None where a block is too large
        for plain floats or a power overflows (then call the family, which takes NumPy's path)."""
        try:
            generators = self._scalar_generators(list(numbers))
            if generators is None:
                return None
            rows = self.block.scalar_function(len(self.symbols))
            if rows is None:
                return None
            result, bound = rows(*generators)
            for row, divisor in self._quotient_pairs:
                denominator = result[divisor]
                quotient = result[row] / denominator
                bound[row] = (bound[row] + abs(quotient) * bound[divisor]) / abs(denominator) + _UNIT * abs(quotient)
                result[row] = quotient
        except (OverflowError, ZeroDivisionError):
            return None
        result, bound = result[: self.rows], bound[: self.rows]
        for index, value in enumerate(result):
            if not math.isfinite(value):
                bound[index] = math.inf
        return result, bound

    def _scalar_generators(self, numbers: list[float]) -> tuple[list[float], list[float]] | None:
        """Generator values and relative errors at one point, the atoms in plain floats (None: an atom's block is
        too large for plain floats)."""
        first = len(self.symbols)
        values, relative = list(numbers), [0.0] * len(numbers)
        for g, atom in enumerate(self.atoms, start=first):
            if atom.source is not None:
                argument, argument_error = values[atom.source], relative[atom.source]
            elif atom.block is None:
                argument, argument_error = atom.constant, atom.constant_error
            elif atom.block.python is not None:
                factors, bounds = atom.block.evaluate_floats(values[:g], relative[:g])
                argument, argument_error = atom.constant, atom.constant_error + atom.roundings
                for factor, bound, power in zip(factors, bounds, atom.powers):
                    argument *= factor**power if factor else math.inf
                    argument_error += abs(power) * bound / abs(factor) if factor else math.inf
            else:
                return None
            if atom.kind == "root":
                value = math.sqrt(argument) if argument >= 0 else math.nan
                value = value if atom.root == 2 else (argument ** (1.0 / atom.root) if argument >= 0 else math.nan)
                error = argument_error / atom.root + (_UNIT if atom.root == 2 else 2 * _UNIT)
            else:
                value = atom.scalar_function(argument)
                if atom.source is not None and atom.source < first:
                    error = 2 * _UNIT
                else:
                    propagated = atom.scalar_derivative(argument) * abs(argument) * argument_error if argument_error > 0 else 0.0
                    error = propagated / abs(value) + 2 * _UNIT if value else math.inf
            values.append(value)
            relative.append(error)
        return values, relative

    def _array_generators(self, arrays: list[np.ndarray], size: int) -> tuple[np.ndarray, np.ndarray]:
        first = len(self.symbols)
        values = np.empty((first + len(self.atoms), size))
        relative = np.zeros((first + len(self.atoms), size))
        for g, array in enumerate(arrays):
            values[g] = array.reshape(size)
        for g, atom in enumerate(self.atoms, start=first):
            if atom.source is not None:  # the argument is one generator
                argument, argument_error = values[atom.source], relative[atom.source]
            elif atom.block is None:
                argument, argument_error = np.full(size, atom.constant), atom.constant_error
            else:
                factors, bounds = atom.block.evaluate(values[:g], relative[:g])
                argument = atom.constant * np.prod(factors**atom.exponents, axis=0)
                argument_error = atom.constant_error + atom.magnitudes @ (bounds / np.abs(factors)) + atom.roundings
            if atom.kind == "root":
                values[g] = np.sqrt(argument) if atom.root == 2 else np.power(argument, 1.0 / atom.root)
                relative[g] = argument_error / atom.root + (_UNIT if atom.root == 2 else 2 * _UNIT)
            else:
                value = values[g] = atom.function(argument)
                if atom.source is not None and atom.source < first:  # an exact argument
                    relative[g] = 2 * _UNIT
                else:  # |f'(a)| |a| rel(a) / |f(a)|, zero where the argument is exact
                    propagated = np.where(argument_error > 0, atom.derivative(argument) * np.abs(argument) * argument_error, 0.0)
                    relative[g] = propagated / np.abs(value) + 2 * _UNIT
        return values, relative

    def __call__(self, *arguments: Any) -> tuple[np.ndarray, np.ndarray]:
        if all(isinstance(value, float) for value in arguments):
            point = self.scalar(*[float(value) for value in arguments])
            if point is not None:
                return np.array(point[0]), np.array(point[1])
        arrays = [np.asarray(value, dtype=float) for value in arguments]
        if len(arrays) > 1:
            arrays = np.broadcast_arrays(*arrays)
        shape = arrays[0].shape if arrays else ()
        size = arrays[0].size if arrays else 1
        with np.errstate(all="ignore"):
            values, relative = self._array_generators(arrays, size)
            return self._rows(values, relative, shape)

    def _rows(self, values: np.ndarray, relative: np.ndarray, shape: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
        result, bound = self.block.evaluate(values, relative)
        rows, divisors = self.quotient_rows, self.divisor_rows
        if rows.size:
            divisor, divisor_bound = result[divisors], bound[divisors]
            quotient = result[rows] / divisor
            bound[rows] = (bound[rows] + np.abs(quotient) * divisor_bound) / np.abs(divisor) + _UNIT * np.abs(quotient)
            result[rows] = quotient
        result, bound = result[: self.rows], bound[: self.rows]
        bound[~np.isfinite(result)] = np.inf
        return result.reshape((self.rows, *shape)), bound.reshape((self.rows, *shape))


class _FamilyBuilder:
    def __init__(self, symbols: tuple[sympy.Symbol, ...]):
        self.symbols = symbols
        self.symbol_set = frozenset(symbols)
        self.atom_keys: dict[Any, sympy.Dummy] = {}
        self.atom_list: list[_Atom] = []
        self.atom_dummies: list[sympy.Dummy] = []
        self.constants: dict[sympy.Dummy, Any] = {}
        self.constant_keys: dict[sympy.Expr, sympy.Dummy] = {}
        self.memo: dict[sympy.Expr, sympy.Expr] = {}

    @property
    def generators(self) -> list[sympy.Symbol]:
        return [*self.symbols, *self.atom_dummies]

    def constant(self, expression: sympy.Expr) -> sympy.Expr:
        if expression.is_Rational:
            return expression
        if expression not in self.constant_keys:
            value = sympy.N(expression, 45)
            if not value.is_real or not value.is_finite:
                raise _Unsupported(f"the constant {expression} is not a finite real number")
            dummy = sympy.Dummy("c")
            self.constant_keys[expression] = dummy
            with workdps(45):
                self.constants[dummy] = mpmath.mpf(value)
        return self.constant_keys[expression]

    def replace(self, expression: sympy.Expr) -> sympy.Expr:
        if expression in self.memo:
            return self.memo[expression]
        free = expression.free_symbols
        if not free:
            result = self.constant(expression)
        elif not free <= self.symbol_set:
            raise _Unsupported(f"symbols {sorted(map(str, free - self.symbol_set))} are not arguments")
        elif expression.is_Symbol:
            result = expression
        elif expression.is_Add or expression.is_Mul:
            result = expression.func(*[self.replace(argument) for argument in expression.args])
        elif expression.is_Pow and expression.exp.is_Integer:
            result = self.replace(expression.base) ** expression.exp
        elif expression.is_Pow and expression.exp.is_Rational:
            exponent = expression.exp
            result = self.atom(("root", exponent.q, expression.base)) ** exponent.p
        elif isinstance(expression, sympy.Function) and expression.func in _FUNCTIONS and len(expression.args) == 1:
            result = self.atom(("function", expression.func, expression.args[0]))
        else:
            raise _Unsupported(f"{type(expression).__name__} is not compiled")
        self.memo[expression] = result
        return result

    def atom(self, key: tuple) -> sympy.Dummy:
        if key in self.atom_keys:
            return self.atom_keys[key]
        kind, detail, argument = key
        replaced = self.replace(argument)  # inner atoms first: the atoms stay in dependency order
        generators = self.generators
        numerator, denominator = sympy.fraction(sympy.together(replaced))
        constant = mpmath.mpf(1)
        rows: list[dict[tuple[int, ...], Any]] = []
        powers: list[int] = []
        for part, sign in ((numerator, 1), (denominator, -1)):
            content, factors = sympy.factor_list(part, *generators, *self.constants) if part.free_symbols else (part, [])
            constant = constant * self.fold(content) ** sign
            for factor, power in factors:
                terms = self.rows_of(factor, generators)
                if len(terms) == 1 and all(not any(m) for m in terms):  # a constant factor
                    constant = constant * next(iter(terms.values())) ** (sign * power)
                    continue
                rows.append(terms)
                powers.append(sign * int(power))
        function, derivative, scalar_function, scalar_derivative = (None,) * 4 if kind == "root" else _FUNCTIONS[detail]
        source = None
        if constant == 1 and powers == [1] and len(rows[0]) == 1:
            (monomial, value), = rows[0].items()
            if value == 1 and sum(monomial) == 1 and max(monomial) == 1:
                source = monomial.index(1)
        atom = _Atom(
            kind, detail if kind == "root" else 0, function, derivative, scalar_function, scalar_derivative, float(constant),
            _coefficient_rounding(constant),
            _Block(rows, len(generators)) if rows else None, source, np.array(powers, dtype=float)[:, None], tuple(powers),
            np.abs(np.array(powers, dtype=float)), (len(powers) + sum(abs(p) > 1 for p in powers)) * _UNIT,
        )
        dummy = sympy.Dummy("a")
        self.atom_keys[key] = dummy
        self.atom_list.append(atom)
        self.atom_dummies.append(dummy)
        return dummy

    def fold(self, expression: sympy.Expr) -> Any:
        """A symbol-free expression in the constant dummies, at 45 digits."""
        with workdps(45):
            return sympy.lambdify(list(self.constants), expression, "mpmath")(*self.constants.values()) if expression.free_symbols else mpmath.mpf(sympy.N(expression, 45))

    def rows_of(self, polynomial: sympy.Expr, generators: list[sympy.Symbol]) -> dict[tuple[int, ...], Any]:
        """{exponents over ``generators``: coefficient (mpf, constants folded)} of a polynomial."""
        constants = list(self.constants)
        poly = sympy.Poly(polynomial, *generators, *constants, domain="QQ")
        width = len(generators)
        terms: dict[tuple[int, ...], Any] = {}
        with workdps(45):
            for monomial, coefficient in poly.terms():
                value = mpmath.mpf(int(coefficient.numerator)) / int(coefficient.denominator)
                for dummy, exponent in zip(constants, monomial[width:]):
                    if exponent:
                        value *= self.constants[dummy] ** exponent
                key = tuple(monomial[:width])
                terms[key] = terms.get(key, 0) + value
        return {key: value for key, value in terms.items() if value != 0} or {(0,) * width: mpmath.mpf(0)}


#: Compiled families by (expressions, symbols), oldest first (guarded by the precision lock).
_FAMILIES: dict[tuple, BoundedFamily | None] = {}
_FAMILY_MEMORY = 64


def forget_families() -> None:
    """Drop the remembered families (:func:`lindstedt.clear_cache`)."""
    with LOCK:
        _FAMILIES.clear()


def compile_family(expressions: list[sympy.Expr], symbols: tuple[sympy.Symbol, ...]) -> BoundedFamily | None:
    """A :class:`BoundedFamily` for ``expressions`` in ``symbols``, or None if one of them is outside the
    representation (see the comment block above: polynomials over monomial or polynomial denominators in the
    symbols and in roots and elementary functions of such expressions).

    The constants are folded in double precision whatever mpmath's precision outside, under the lock that
    guards it: the same family on every thread.  Families are remembered (the last :data:`_FAMILY_MEMORY`),
    so threads that ask for one at once compile it once."""
    key = (tuple(expressions), tuple(symbols))
    with workprec(53):
        family = _FAMILIES.pop(key, _FAMILIES)  # the dict itself marks a miss (None is a valid entry)
        if family is _FAMILIES:
            family = _compile_family(expressions, symbols)
        _FAMILIES[key] = family  # most recent last
        while len(_FAMILIES) > _FAMILY_MEMORY:
            del _FAMILIES[next(iter(_FAMILIES))]
        return family


def _compile_family(expressions: list[sympy.Expr], symbols: tuple[sympy.Symbol, ...]) -> BoundedFamily | None:
    builder = _FamilyBuilder(tuple(symbols))
    parts = []
    try:
        for expression in expressions:
            replaced = builder.replace(sympy.sympify(expression, strict=True))
            numerator, denominator = sympy.fraction(sympy.together(replaced)) if replaced.free_symbols else (replaced, sympy.Integer(1))
            parts.append((numerator, denominator))
        generators = builder.generators
        width = len(generators)
        numerators: list[dict[tuple[int, ...], Any]] = []
        denominators: list[dict[tuple[int, ...], Any]] = []
        links = []
        for numerator, denominator in parts:
            top = builder.rows_of(numerator, generators)
            bottom = builder.rows_of(denominator, generators)
            if len(bottom) == 1:
                (shift, divisor), = bottom.items()
                with workdps(45):
                    top = {tuple(a - b for a, b in zip(key, shift)): value / divisor for key, value in top.items()}
                links.append(-1)
            else:
                links.append(len(denominators))
                denominators.append(bottom)
            numerators.append(top)
    except (_Unsupported, sympy.PolynomialError, sympy.polys.polyerrors.CoercionFailed, ZeroDivisionError):
        return None
    quotients = np.array([-1 if link < 0 else len(numerators) + link for link in links], dtype=np.int64)
    return BoundedFamily(builder.symbols, builder.atom_list, _Block(numerators + denominators, width), quotients, len(expressions))
