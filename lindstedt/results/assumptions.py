"""What an expansion was derived under, checked on the numbers a user evaluates it at.

A symbolic expansion of ``u'' + ω0² u + ε f(u) = 0`` holds only where its
derivation's assumptions hold: the declared signs of its free symbols (a0 and
ω0 default to positive), ω0 > 0, a0 ≠ 0, and for piecewise-linear f the side of
the release point and, for every breakpoint u_i = κ_i a0, where it lies relative
to the orbit [−|a0|, |a0|] (crossed, grazing, never reached, permanent contact)
and the order of the breakpoints.  A problem from initial data (u0, v0) has numeric
u0, v0 and a0 = their turning point: the re-derivation it suggests passes u0 and v0.  :class:`DerivationAssumptions` lists them and
:meth:`~DerivationAssumptions.check` raises a :class:`~lindstedt.ParameterError`
naming the regime and the re-derivation when numeric values leave them.
"""

from __future__ import annotations

from dataclasses import dataclass
from .._precision import cached_property
from typing import Any, Callable, Mapping

import numpy as np
import sympy

from .._errors import ParameterError
from ..compiled.family import compile_family
from ..problems.oscillator import Oscillator, check_names

__all__ = ["DerivationAssumptions", "check_names", "shown_values"]


def _numeric_sign(value: sympy.Expr) -> int:
    """Sign (-1, 0, 1) of a real number given as a sympy expression without free symbols."""
    if value.is_zero:
        return 0
    if value.is_positive:
        return 1
    if value.is_negative:
        return -1
    number = float(sympy.N(value, 50))
    return (number > 0) - (number < 0)


def _binary_float(value: sympy.Expr) -> float | None:
    """The float whose exact binary value ``value`` is (floats are read exactly), else None."""
    if value.is_Float:
        return float(value)
    if value.is_Rational and not value.is_Integer and value.q & (value.q - 1) == 0 and value.q > 2**20:
        number = float(value)
        if sympy.Rational(number) == value:
            return number
    return None


def _shown_number(value: sympy.Expr) -> str:
    number = _binary_float(value)
    return repr(number) if number is not None else str(value)


def _literal(value: sympy.Expr) -> str:
    """A Python literal that ``expand`` accepts for a number (exact numbers as strings)."""
    if value.is_Integer:
        return str(int(value))
    number = _binary_float(value)
    if number is not None:
        return repr(number)
    return repr(sympy.sstr(value))


def shown_values(substitution: Mapping[sympy.Symbol, sympy.Expr]) -> str:
    """``a0 = 1, omega0 = 0.5`` (sorted by name, floats short)."""
    return ", ".join(
        f"{symbol} = {_shown_number(value)}" for symbol, value in sorted(substitution.items(), key=lambda item: item[0].name)
    )


_POSITIVE, _NEGATIVE, _ZERO, _NONZERO = frozenset({1}), frozenset({-1}), frozenset({0}), frozenset({-1, 1})


@dataclass(frozen=True)
class _Assumption:
    """One condition the derivation relied on, checked on numeric values (see :meth:`Expansion._validated`)."""

    text: str
    holds: Callable[[Mapping[sympy.Symbol, sympy.Expr]], bool]
    amplitude_sign: bool = False
    rederivable: bool = True  # False: no expansion exists for such values (ω0 ≤ 0, a0 = 0)
    # the same test for float values: every expression's sign must be in its set (empty: not expressible,
    # checked exactly); ``integer`` names a symbol that must hold an integer
    conditions: tuple[tuple[sympy.Expr, frozenset[int]], ...] = ()
    integer: sympy.Symbol | None = None


def _symbol_assumptions(symbol: sympy.Symbol, is_amplitude: bool, is_frequency: bool) -> list[_Assumption]:
    """The sign/integrality assumptions a free symbol was declared with (derivations may use them)."""
    facts = symbol.assumptions0
    name = symbol.name
    checks: list[tuple[str, frozenset[int]]] = []
    if facts.get("positive"):
        checks.append((f"{name} > 0 ({name} is declared positive)", _POSITIVE))
    elif facts.get("negative"):
        checks.append((f"{name} < 0 ({name} is declared negative)", _NEGATIVE))
    elif facts.get("nonnegative"):
        checks.append((f"{name} >= 0 ({name} is declared nonnegative)", frozenset({0, 1})))
    elif facts.get("nonpositive"):
        checks.append((f"{name} <= 0 ({name} is declared nonpositive)", frozenset({-1, 0})))
    elif facts.get("nonzero"):
        checks.append((f"{name} != 0 ({name} is declared nonzero)", _NONZERO))
    assumptions = [
        _Assumption(
            text, lambda substitution, signs=signs: _numeric_sign(substitution[symbol]) in signs, is_amplitude, not is_frequency,
            ((symbol, signs),),
        )
        for text, signs in checks
    ]
    if facts.get("integer"):
        assumptions.append(
            _Assumption(
                f"{name} an integer ({name} is declared integer)",
                lambda substitution: float(sympy.N(substitution[symbol], 30)).is_integer(),
                integer=symbol,
            )
        )
    return assumptions


class DerivationAssumptions:
    """The assumptions of one derivation (problem + normal form + order) and their check on numeric values.

    Examples
    --------
    >>> import lindstedt
    >>> expansion = lindstedt.expand("Max(0, u - 1/2)", order=1)
    >>> expansion.frequency(0.1, values={"a0": -1, "omega0": 1})
    Traceback (most recent call last):
    ...
    lindstedt._errors.ParameterError: the values a0 = -1, omega0 = 1 are outside the assumptions ...
    """

    def __init__(self, problem: Oscillator, form: Any, order: int):
        self.problem, self.form, self.order = problem, form, order

    @cached_property
    def assumptions(self) -> tuple[_Assumption, ...]:
        """What the derivation assumed about the symbols left free (empty when none are).

        * every declared sign of a free symbol (a0 and omega0 default to positive symbols;
          parameters are real unless declared otherwise);
        * ω0 > 0 and a0 ≠ 0;
        * piecewise-linear f: the sign of a0 the derivation used (it decides which side of
          each breakpoint the release point is on), and for every breakpoint u_i = κ_i a0
          where it lies relative to the orbit [-|a0|, |a0|] — crossed (|κ_i| < 1: contact;
          assumed when a single gap or a0 is symbolic), grazing (|κ_i| = 1), never reached
          (κ_i > 1) or permanent contact (κ_i < -1) — and the order of the breakpoints.
        """
        problem = self.problem
        if not problem.free_symbols:
            return ()
        assumptions: list[_Assumption] = []
        for symbol in sorted(problem.free_symbols, key=lambda item: item.name):
            assumptions += _symbol_assumptions(symbol, symbol in problem.a0.free_symbols, symbol == problem.omega0)
        omega0, amplitude = problem.omega0, problem.a0
        if omega0.free_symbols and not omega0.is_Symbol:
            assumptions.append(
                _Assumption(
                    f"omega0 = {omega0} > 0", lambda substitution: _numeric_sign(omega0.xreplace(substitution)) > 0, rederivable=False,
                    conditions=((omega0, _POSITIVE),),
                )
            )
        if amplitude.free_symbols:
            sign = self.form.amplitude_sign
            if sign is not None and not amplitude.is_Symbol:
                relation = ">" if sign > 0 else "<"
                assumptions.append(
                    _Assumption(
                        f"a0 = {amplitude} {relation} 0 (the side of the release point)",
                        lambda substitution: _numeric_sign(amplitude.xreplace(substitution)) == sign,
                        amplitude_sign=True,
                        conditions=((amplitude, frozenset({sign})),),
                    )
                )
            if not amplitude.is_nonzero:
                assumptions.append(
                    _Assumption(
                        "a0 != 0 (a0 = 0 is the rest state)",
                        lambda substitution: _numeric_sign(amplitude.xreplace(substitution)) != 0,
                        rederivable=False,
                        conditions=((amplitude, _NONZERO),),
                    )
                )
        if self.form.regime != "smooth":
            assumptions += self._piecewise_assumptions()
        return tuple(assumptions)

    def _piecewise_assumptions(self) -> list[_Assumption]:
        form = self.form
        amplitude = self.problem.a0
        size = amplitude if form.amplitude_sign > 0 else -amplitude  # |a0| under the derivation's sign
        classes = form.breakpoint_classes
        assumptions: list[_Assumption] = []
        tests = {
            "crossing": lambda kappa: _numeric_sign(kappa + 1) > 0 and _numeric_sign(kappa - 1) < 0,
            "above": lambda kappa: _numeric_sign(kappa - 1) > 0,
            "below": lambda kappa: _numeric_sign(kappa + 1) < 0,
        }
        for kappa, kind in classes:
            if not kappa.free_symbols:
                continue
            point = sympy.simplify(kappa * amplitude)
            if kind == "crossing":
                text = f"-{size} < {point} < {size} (contact: the orbit crosses the breakpoint u = {point})"
                test = tests["crossing"]
                conditions = ((kappa + 1, _POSITIVE), (kappa - 1, _NEGATIVE))
            elif kind == "above":
                text = f"{point} > {size} (no contact: the breakpoint u = {point} is never reached)"
                test = tests["above"]
                conditions = ((kappa - 1, _POSITIVE),)
            elif kind == "below":
                text = f"{point} < -{size} (permanent contact beyond the breakpoint u = {point})"
                test = tests["below"]
                conditions = ((kappa + 1, _NEGATIVE),)
            else:
                target = 1 if sympy.simplify(kappa - 1) == 0 else -1
                text = f"{point} = {target * size} (grazing: the breakpoint is a turning point)"
                test = lambda value, target=target: _numeric_sign(value - target) == 0  # noqa: E731
                conditions = ((kappa - target, _ZERO),)
            assumptions.append(
                _Assumption(text, lambda substitution, kappa=kappa, test=test: test(kappa.xreplace(substitution)), conditions=conditions)
            )
        if len(classes) > 1 and any(kappa.free_symbols for kappa, _ in classes):
            kappas = [kappa for kappa, _ in classes]
            points = " < ".join(str(sympy.simplify(form.amplitude_sign * kappa * amplitude)) for kappa in kappas)
            assumptions.append(
                _Assumption(
                    f"breakpoints ordered as {points} (times the sign of a0)",
                    lambda substitution: all(
                        _numeric_sign((right - left).xreplace(substitution)) > 0 for left, right in zip(kappas, kappas[1:])
                    ),
                    conditions=tuple((right - left, _POSITIVE) for left, right in zip(kappas, kappas[1:])),
                )
            )
        return assumptions

    @cached_property
    def _symbols(self) -> tuple[sympy.Symbol, ...]:
        return tuple(sorted(self.problem.free_symbols, key=lambda symbol: symbol.name))

    @cached_property
    def _condition_rows(self) -> tuple[list[sympy.Expr], np.ndarray]:
        """The expressions whose signs the assumptions test, and per expression its allowed signs as a
        (rows, 3) table indexed by sign + 1."""
        expressions, table = [], []
        for assumption in self.assumptions:
            for expression, signs in assumption.conditions:
                expressions.append(expression)
                table.append([sign in signs for sign in (-1, 0, 1)])
        return expressions, np.array(table, dtype=bool).reshape(len(table), 3)

    @property
    def float_conditions(self) -> list[sympy.Expr]:
        """The expressions whose signs :meth:`float_verdict` reads (compile them in the free symbols sorted by name)."""
        return self._condition_rows[0]

    def float_verdict(self, values: np.ndarray | None, bounds: np.ndarray | None, arrays: tuple[Any, ...]) -> tuple[np.ndarray, np.ndarray]:
        """(violated, undecided) masks of the broadcast shape of ``arrays`` (one float or array per free symbol,
        sorted by name), from the :attr:`float_conditions` evaluated in float64 with rounding ``bounds``.

        A sign is decided where |value| exceeds its bound (or both are 0); an undecided element, or an
        assumption without a float form, must be checked exactly with :meth:`check` (which words the error).
        """
        shape = np.broadcast_shapes(*[np.shape(value) for value in arrays]) if arrays else ()
        violated = np.zeros(shape, dtype=bool)
        undecided = np.zeros(shape, dtype=bool)
        table = self._condition_rows[1]
        if not shape and len(table) and not self._integers:  # one point: plain floats
            failed = unknown = False
            for value, bound, allowed in zip(values.tolist(), bounds.tolist(), table.tolist()):
                if abs(value) > bound or (value == 0 and bound == 0):
                    failed = failed or not allowed[(value > 0) - (value < 0) + 1]
                else:
                    unknown = True
            return np.array(failed), np.array(unknown and not failed or self._inexpressible)
        if len(table):
            decided = (np.abs(values) > bounds) | ((values == 0) & (bounds == 0))  # False for NaN
            signs = np.sign(np.where(decided, values, 0.0)).astype(np.int64) + 1
            fits = table[np.arange(len(table)).reshape(-1, *[1] * len(shape)), signs]
            violated = (decided & ~fits).any(axis=0)
            undecided = (~decided).any(axis=0)
        for symbol in self._integers:
            violated = violated | np.broadcast_to(np.mod(arrays[self._symbols.index(symbol)], 1) != 0, shape)
        if self._inexpressible:
            undecided = np.ones(shape, dtype=bool)
        return violated, undecided & ~violated

    @cached_property
    def _integers(self) -> tuple[sympy.Symbol, ...]:
        return tuple(assumption.integer for assumption in self.assumptions if assumption.integer is not None)

    @cached_property
    def _inexpressible(self) -> bool:
        """An assumption without a float form (checked exactly at every new value)."""
        return any(not assumption.conditions and assumption.integer is None for assumption in self.assumptions)

    def float_check(self, arrays: tuple[Any, ...]) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`float_verdict` with the conditions compiled here.

        Examples
        --------
        >>> import lindstedt, numpy as np
        >>> e = lindstedt.expand("Max(0, u - b)", order=1, params={"b": None})   # a0, b, omega0
        >>> violated, undecided = e._assumptions.float_check((1.0, np.array([0.5, 1.5, 1.0]), 1.0))
        >>> violated.tolist(), undecided.tolist()    # b = a0 exactly: grazing, left to the exact check
        ([False, True, False], [False, False, True])
        """
        expressions = self.float_conditions
        family = compile_family(expressions, self._symbols) if expressions else None
        if expressions and family is None:
            shape = np.broadcast_shapes(*[np.shape(value) for value in arrays]) if arrays else ()
            return np.zeros(shape, dtype=bool), np.ones(shape, dtype=bool)
        values, bounds = family(*arrays) if family is not None else (None, None)
        return self.float_verdict(values, bounds, arrays)

    def check(self, substitution: dict[sympy.Symbol, sympy.Expr]) -> dict[sympy.Symbol, sympy.Expr]:
        """Check numeric values (finite and real already: read by the parser) against the derivation's regime."""
        assumptions = self.assumptions
        violated = [assumption for assumption in assumptions if not assumption.holds(substitution)]
        if violated:
            raise ParameterError(self._outside_message(substitution, violated, assumptions))
        return substitution

    def _outside_message(
        self, substitution: Mapping[sympy.Symbol, sympy.Expr], violated: list[_Assumption], assumptions: tuple[_Assumption, ...]
    ) -> str:
        problem = self.problem
        given = shown_values(substitution)
        regime = f" ({self.form.regime} regime)" if self.form.regime != "smooth" else ""
        message = (
            f"the values {given} are outside the assumptions this expansion was derived under: "
            f"{'; '.join(assumption.text for assumption in violated)} does not hold. "
            f"It was derived for {' and '.join(assumption.text for assumption in assumptions)}{regime}; "
        )
        admissible = (
            _numeric_sign(problem.a0.xreplace(substitution)) != 0 and _numeric_sign(problem.omega0.xreplace(substitution)) > 0
        )
        if not admissible or not all(assumption.rederivable for assumption in violated):
            return message + "no expansion exists there: give omega0 > 0 (the linear angular frequency) and a0 != 0"
        arguments = [repr(sympy.sstr(problem.f)), f"order={self.order}"]
        if problem.has_initial_velocity:  # from (u0, v0): a0 is their turning point, not an input
            arguments.append(f"u0={_literal(problem.u0)}")
            arguments.append(f"v0={_literal(problem.v0)}")
        else:
            arguments.append(f"a0={_literal(problem.a0.xreplace(substitution))}")
        arguments.append(f"omega0={_literal(problem.omega0.xreplace(substitution))}")
        if problem.params:
            params = ", ".join(f"{str(symbol)!r}: {_literal(value.xreplace(substitution))}" for symbol, value in problem.params)
            arguments.append("params={" + params + "}")
        if problem.normalization != "initial":
            arguments.append(f"normalization={problem.normalization!r}")
        message += f"re-derive with these numbers: lindstedt.expand({', '.join(arguments)})"
        amplitude = problem.a0
        if any(assumption.amplitude_sign for assumption in violated) and (amplitude.is_Symbol or (-amplitude).is_Symbol):
            symbol = amplitude if amplitude.is_Symbol else -amplitude
            declared = "positive" if symbol.is_positive else "negative" if symbol.is_negative else "real"
            code = f"sympy.Symbol({symbol.name!r}, {declared}=True)"
            other_side = f"-{code}" if amplitude.is_Symbol else code
            message += (
                f", or keep the amplitude symbolic on the other side with a0={other_side} "
                f"(then {symbol} = {_shown_number(-substitution[symbol])} gives u(0) = {_shown_number(amplitude.xreplace(substitution))})"
            )
        return message
