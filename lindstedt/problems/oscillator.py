"""The one-degree-of-freedom problem  u'' + ω0² u + ε f(u) = 0,  u(0) = a0 + ε a1,  u'(0) = 0.

``Oscillator`` is a frozen dataclass that parses, sympifies and validates its
inputs when it is built, so that every method downstream receives a problem
that is known to make sense: f depends only on ``u`` and declared parameters,
every declared parameter is used, ``a0 ≠ 0``, ``ω0 > 0``, and the amplitude
normalisation is explicit:

``"initial"``
    ``a0`` is the release point: u(0) = a0 + ε a1 exactly (a1 = 0 by default; the
    corrections v_k, k ≥ 2, vanish at s = 0 and v_1(0) = a1).
``"harmonic"``
    ``a0`` is the amplitude of the first harmonic: the ``cos(s)`` coefficient of
    every correction v_k, k ≥ 1, vanishes.
"""

from __future__ import annotations

import keyword
from dataclasses import dataclass, field
from typing import Any, Mapping

import sympy

from .._errors import ParameterError, ProblemError
from .parsing import ALLOWED_FUNCTIONS, CONSTANTS, as_exact, parse_expression, parse_real, parse_value

__all__ = ["Oscillator", "NORMALIZATIONS", "DISPLACEMENT"]

NORMALIZATIONS = ("initial", "harmonic")
DISPLACEMENT = sympy.Symbol("u", real=True)
_NON_SMOOTH = (sympy.Max, sympy.Min, sympy.Heaviside, sympy.Abs, sympy.sign, sympy.Piecewise)
# Names a parameter cannot take: the variables of the problem and of its results (u, the strained time s,
# the time t, epsilon, a0, omega0, the normalised w) and the names the parser reserves for functions and constants.
RESERVED_NAMES = frozenset({"u", "s", "t", "w", "epsilon", "a0", "omega0"}) | frozenset(ALLOWED_FUNCTIONS) | frozenset(CONSTANTS)


def _default_amplitude() -> sympy.Symbol:
    return sympy.Symbol("a0", positive=True)


def _default_omega0() -> sympy.Symbol:
    return sympy.Symbol("omega0", positive=True)


def _given_quantity(value: Any, what: str) -> sympy.Expr:
    """a0 or omega0 as given: a number (exact), or a sympy expression in symbols the caller made."""
    if isinstance(value, sympy.Basic) and not value.is_number:
        expression = as_exact(value, what=what)
        if not isinstance(expression, sympy.Expr) or expression.has(sympy.zoo, sympy.oo, -sympy.oo, sympy.nan):
            raise ProblemError(f"{what} = {value} must be a finite real expression")
        if any(symbol.is_real is not True for symbol in expression.free_symbols):
            raise ProblemError(f"{what} = {value}: declare its symbols real, e.g. sympy.Symbol('{what}', positive=True)")
        return expression
    return parse_real(value, what=what)


@dataclass(frozen=True)
class Oscillator:
    """Weakly nonlinear oscillator ``u'' + ω0² u + ε f(u) = 0``, ``u(0) = a0 + ε a1``, ``u'(0) = 0``.

    Parameters
    ----------
    f : str or sympy expression
        The nonlinearity, in the variable ``u``.  Strings are parsed safely
        (``^`` means power; decimals are exact).
    a0 : number, numeric string or sympy expression, optional
        Amplitude (see ``normalization``).  Default: the positive symbol ``a0``.
        Numbers are exact: a float means its binary value, ``"0.1"`` means 1/10
        (strings are read by the one parser, ``lindstedt.problems.parsing``); a sympy
        expression may contain real symbols of the caller's own.
    omega0 : number, numeric string or sympy expression, optional
        Linear angular frequency, must be positive.  Default: the positive symbol ``omega0``.
    params : mapping name -> value, optional
        Every symbol of f other than ``u`` must be declared here.  A value of
        ``None`` (or the parameter's own name, or a sympy Symbol) keeps it symbolic;
        any other value must be a finite real number.  Reserved names
        (:data:`RESERVED_NAMES`) cannot be parameters.
    normalization : {"initial", "harmonic"}
        Meaning of ``a0``: release point, or first-harmonic amplitude.
    a1 : number, numeric string or sympy expression, optional
        The O(ε) shift of the release point, u(0) = a0 + ε a1 (default 0; "initial" normalization
        only).  It matters where a0 sits exactly on a breakpoint: the release just inside or
        outside a gap (seed Prop. 2.3).

    Raises
    ------
    ProblemError, ParameterError
        With a message that names the fix.

    Examples
    --------
    >>> problem = Oscillator("u**3 + c*u**5", a0=1, omega0=2, params={"c": "1/3"})
    >>> problem.nonlinearity
    u**5/3 + u**3
    >>> problem.normalization
    'initial'
    """

    f: Any
    a0: Any = None
    omega0: Any = None
    params: Any = None
    normalization: str = "initial"
    a1: Any = 0
    variable: sympy.Symbol = field(default=DISPLACEMENT, init=False)

    def __post_init__(self) -> None:
        set_field = object.__setattr__
        if self.normalization not in NORMALIZATIONS:
            raise ProblemError(
                f"normalization must be one of {NORMALIZATIONS}, got {self.normalization!r}; "
                "'initial' means u(0) = a0, 'harmonic' means a0 is the first-harmonic amplitude"
            )
        raw_params = self.params or {}
        if isinstance(raw_params, tuple):
            raw_params = dict(raw_params)
        if not isinstance(raw_params, Mapping):
            raise ParameterError("params must be a mapping {name: value}, e.g. {'c': '1/3'}")
        parameter_symbols: dict[str, sympy.Symbol] = {}
        for name in raw_params:
            if not isinstance(name, str) or not name.isidentifier() or name.startswith("_") or keyword.iskeyword(name):
                raise ParameterError(f"parameter name {name!r} must be a plain identifier such as 'c'")
            if name in RESERVED_NAMES:
                role = "the displacement variable" if name == "u" else "a reserved name (variables s, t, w, epsilon, a0, omega0 of the results, functions and constants of the grammar)"
                raise ParameterError(f"{name!r} is {role} and cannot be a parameter; rename it, e.g. 'c'")
            parameter_symbols[name] = sympy.Symbol(name, real=True)
        values: dict[str, sympy.Expr] = {}
        for name, value in raw_params.items():
            if isinstance(value, sympy.Symbol) and value.name == name:
                parameter_symbols[name] = value
            values[name] = parse_value(value, name=name, symbol=parameter_symbols[name])
            if values[name].free_symbols - {parameter_symbols[name]}:
                raise ParameterError(
                    f"the value of parameter {name!r} must be a number (or None to keep it symbolic), got {value!r}"
                )

        known = {"u": DISPLACEMENT, **parameter_symbols}
        expression = parse_expression(self.f, symbols=known, what="f")
        expression = expression.subs({sympy.Symbol("u"): DISPLACEMENT})
        expression = expression.subs({sympy.Symbol(n): s for n, s in parameter_symbols.items()})
        foreign = expression.free_symbols - {DISPLACEMENT} - set(parameter_symbols.values())
        if foreign:
            names = ", ".join(sorted(str(s) for s in foreign))
            raise ParameterError(
                f"f depends on {names}, which are neither u nor declared parameters; "
                f"declare them with params={{'{sorted(str(s) for s in foreign)[0]}': value}}"
            )
        if expression == 0:
            raise ProblemError("f is identically zero: the oscillator is linear and there is nothing to expand")
        if expression.has(sympy.zoo, sympy.oo, sympy.nan, -sympy.oo):
            raise ProblemError(f"f = {expression} contains an infinity or NaN")

        amplitude = self._parse_amplitude(self.a0)
        omega0 = self._parse_omega0(self.omega0)
        release_shift = _given_quantity(self.a1, "a1")
        if release_shift != 0 and self.normalization != "initial":
            raise ProblemError("a1 shifts the release point u(0) = a0 + eps*a1: it needs normalization='initial'")

        used = expression.free_symbols | amplitude.free_symbols | omega0.free_symbols | release_shift.free_symbols
        unused = [name for name, symbol in parameter_symbols.items() if symbol not in used]
        if unused:
            raise ParameterError(
                f"parameter(s) {', '.join(unused)} declared but not used by f; remove them from params"
            )

        set_field(self, "f", expression)
        set_field(self, "a0", amplitude)
        set_field(self, "omega0", omega0)
        set_field(self, "a1", release_shift)
        set_field(self, "params", tuple((parameter_symbols[name], values[name]) for name in raw_params))

    # -- parsing of the amplitude and of the linear frequency -------------------------------
    @staticmethod
    def _parse_amplitude(value: Any) -> sympy.Expr:
        if value is None:
            return _default_amplitude()
        amplitude = _given_quantity(value, "a0")
        if amplitude.is_number and amplitude == 0 or amplitude.is_zero:
            raise ProblemError("a0 = 0 is the rest state: give a nonzero amplitude a0")
        return amplitude

    @staticmethod
    def _parse_omega0(value: Any) -> sympy.Expr:
        if value is None:
            return _default_omega0()
        omega0 = _given_quantity(value, "omega0")
        if omega0.is_number:
            if not omega0 > 0:
                raise ProblemError(f"omega0 must be positive (it is the linear angular frequency), got {omega0}")
        elif omega0.is_positive is not True:
            raise ProblemError(
                f"omega0 = {omega0} is not known to be positive; declare it "
                "sympy.Symbol('omega0', positive=True) or pass a positive number"
            )
        return omega0

    # -- derived views ---------------------------------------------------------------------
    @property
    def nonlinearity(self) -> sympy.Expr:
        """f(u) with the numeric parameter values substituted (symbolic ones kept)."""
        return self.f.subs({symbol: value for symbol, value in self.params if value != symbol})

    @property
    def parameter_values(self) -> dict[sympy.Symbol, sympy.Expr]:
        """Declared parameters and their values (a symbol stands for itself)."""
        return dict(self.params)

    @property
    def symbolic_parameters(self) -> tuple[sympy.Symbol, ...]:
        """Parameters without a numeric value."""
        return tuple(symbol for symbol, value in self.params if value == symbol)

    @property
    def release_shifts(self) -> tuple[sympy.Expr, ...]:
        """``(a1, a2, …)`` of the release point ``u(0) = a0 + Σ ε^n a_n`` (empty: released at a0 exactly)."""
        return (self.a1,) if self.a1 != 0 else ()

    @property
    def free_symbols(self) -> set[sympy.Symbol]:
        """Symbols a numeric evaluation must be given: a0, ω0 or parameters left symbolic."""
        symbols = set(self.nonlinearity.free_symbols) - {DISPLACEMENT}
        return symbols | self.a0.free_symbols | self.omega0.free_symbols | self.a1.free_symbols

    @property
    def is_non_smooth(self) -> bool:
        """True when f contains Max, Heaviside, Abs, sign or Piecewise."""
        return any(self.f.has(function) for function in _NON_SMOOTH)

    @property
    def is_polynomial(self) -> bool:
        """True when f is a polynomial in u (coefficients may be symbolic)."""
        return (not self.is_non_smooth) and self.nonlinearity.is_polynomial(DISPLACEMENT)

    def numeric_substitution(self, values: Mapping[Any, Any] | None = None) -> dict[sympy.Symbol, sympy.Expr]:
        """Map every free symbol to a number, from ``values`` (names or symbols as keys).

        Raises
        ------
        ParameterError
            If a symbol has no value, naming it and how to pass it.
        """
        given: dict[str, sympy.Expr] = {}
        for key, value in (values or {}).items():
            name = key.name if isinstance(key, sympy.Symbol) else str(key)
            given[name] = parse_real(value, what=name)
        substitution: dict[sympy.Symbol, sympy.Expr] = {}
        missing = []
        for symbol in sorted(self.free_symbols, key=str):
            if symbol.name in given:
                substitution[symbol] = given[symbol.name]
            else:
                missing.append(symbol.name)
        if missing:
            raise ParameterError(
                f"a numeric result needs values for {', '.join(missing)}; pass values={{"
                + ", ".join(f"'{name}': ..." for name in missing)
                + "} (or give them when building the problem)"
            )
        unknown = set(given) - {symbol.name for symbol in self.free_symbols}
        if unknown:
            raise ParameterError(
                f"values given for {', '.join(sorted(unknown))}, which the problem does not have as free symbols; remove them"
            )
        return substitution

    def describe(self) -> str:
        """One-line human description of the problem."""
        params = ", ".join(f"{symbol} = {value}" for symbol, value in self.params if value != symbol)
        symbolic = ", ".join(str(symbol) for symbol in self.symbolic_parameters)
        squared = self.omega0**2
        stiffness = f"({sympy.sstr(squared)})" if isinstance(squared, sympy.Add) else sympy.sstr(squared)
        stiffness_term = "u" if squared == 1 else f"{stiffness}*u"
        release = f"{self.a0}" if self.a1 == 0 else f"{self.a0} + eps*({self.a1})"
        text = f"u'' + {stiffness_term} + eps*({self.f}) = 0, u(0) = {release} [{self.normalization}]"
        if params:
            text += f"; {params}"
        if symbolic:
            text += f"; symbolic: {symbolic}"
        return text
