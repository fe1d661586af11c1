"""The one-degree-of-freedom problem  u'' + ω0² u + ε f(u) = 0,  u(0) = a0 + ε a1,  u'(0) = 0
(or general initial data u(0) = u0, u'(0) = v0).

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

**General initial data** ``u(0) = u0``, ``u'(0) = v0`` (``Oscillator(f, u0=..., v0=...)``,
exclusive with ``a0``/``a1``; ``"initial"`` normalization only).  The motion conserves
``E = u'²/2 + V(u)``, ``V(u) = ω0² u²/2 + ε F(u)``, ``F' = f``, ``F(0) = 0``, so the orbit
through (u0, v0) turns at the **positive** turning point ``A(ε) > 0`` with ``V(A) = E``:

    A² + (2ε/ω0²) F(A) = u0² + v0²/ω0² + (2ε/ω0²) F(u0).

With ``A = A0 + δ``, ``A0 = (u0² + v0²/ω0²)^{1/2}``, ``δ = Σ_{n≥1} ε^n A_n`` and
``F(A0 + δ) = F(A0) + Σ_{m≥1} c_m δ^m``, ``c_m = f^{(m−1)}(A0)/m!`` (on the piece of f
that contains A0), the ε^n coefficient gives, exactly,

    A_n = −[ Σ_{i=1}^{n−1} A_i A_{n−i} + (2/ω0²) ( [n = 1] (F(A0) − F(u0)) + Σ_{m≥1} c_m [δ^m]_{n−1} ) ] / (2 A0).

If A0 sits on a breakpoint of f, the side is the sign of the first nonzero A_k (the
one-sided coefficients c_m enter only after it); if every A_k vanishes the orbit only
touches the breakpoint.  The problem is then the release at rest at ``a0 = A0`` with
``release_shifts = (A_1, A_2, …)`` (:meth:`Oscillator.amplitude_series`), and the motion
is ``u(t) = v(ω t + φ(ε); ε)`` with the phase φ of :class:`~lindstedt.Expansion`.
``v0 = 0`` is the release at rest at ``a0 = u0``: that problem is built, identical to
``Oscillator(f, a0=u0)`` (``u0`` and ``v0`` are then stored as ``None``).
"""

from __future__ import annotations

import copy
import difflib
import keyword
import math
import sys
from dataclasses import dataclass, field
from typing import Any, Mapping, Sequence

import sympy

from .._precision import LOCK, locked_methods
from .._errors import ParameterError, ProblemError, UnsupportedNonlinearityError
from .parsing import ALLOWED_FUNCTIONS, CONSTANTS, as_exact, parse_expression, parse_real, parse_value
from .piecewise_linear import decompose_piecewise

__all__ = ["Oscillator", "NORMALIZATIONS", "DISPLACEMENT", "DEFAULT_RELEASE_ORDER"]

NORMALIZATIONS = ("initial", "harmonic")
DISPLACEMENT = sympy.Symbol("u", real=True)
_NON_SMOOTH = (sympy.Max, sympy.Min, sympy.Heaviside, sympy.Abs, sympy.sign, sympy.Piecewise)
# Names a parameter cannot take: the variables of the problem and of its results (u, the strained time s,
# the time t, epsilon, a0, omega0, the normalised w) and the names the parser reserves for functions and constants.
RESERVED_NAMES = frozenset({"u", "s", "t", "w", "epsilon", "a0", "omega0"}) | frozenset(ALLOWED_FUNCTIONS) | frozenset(CONSTANTS)
#: How many ε-orders of the turning-point series A_1, A_2, … an Oscillator built from (u0, v0) hands to
#: an engine by default (``release_shifts``); :class:`~lindstedt.LindstedtPoincare` extends it to the
#: order it expands to (:meth:`Oscillator.with_release_order`).
DEFAULT_RELEASE_ORDER = 4


def _undecidable(arguments: Sequence[sympy.Expr]) -> bool:
    """True when no two of ``arguments`` can be ordered for every u: each pairwise difference is r·u + c with r a
    nonzero rational and c free of u and finite (u real and unbounded, so its sign changes with u), and none is
    itself a switch.  ``Max``/``Min`` of such arguments keeps every one of them: sympy's evaluation
    (``_collapse_arguments``, ``_find_localzeros``, which decide the pairwise orderings through the assumptions
    system, milliseconds per call) cannot remove any, and ``evaluate=False`` builds the same object."""
    lines = [_rational_line(argument) for argument in arguments]
    if all(line is not None for line in lines):  # r·u + c with rational r, c: decided by the slopes alone
        return len({slope for slope, _ in lines}) == len(lines)
    if any(argument.has(sympy.Max, sympy.Min, sympy.Piecewise, sympy.oo, -sympy.oo, sympy.zoo, sympy.nan)
           for argument in arguments):
        return False
    for index, first in enumerate(arguments):
        for second in arguments[index + 1:]:
            constant, linear = (first - second).as_independent(DISPLACEMENT, as_Add=True)
            factor, rest = linear.as_coeff_Mul()
            if rest != DISPLACEMENT or not factor.is_Rational or factor == 0 or constant.is_extended_real is not True:
                return False
    return True


def _rational_line(expression: sympy.Expr) -> tuple[Any, Any] | None:
    """(r, c) when ``expression`` is r·u + c with rational r and c (read from its structure), else None."""
    if expression.is_Rational:
        return 0, expression
    if expression == DISPLACEMENT:
        return 1, 0
    arguments = expression.args
    if expression.is_Mul and len(arguments) == 2 and arguments[0].is_Rational and arguments[1] == DISPLACEMENT:
        return arguments[0], 0
    if expression.is_Add and len(arguments) == 2 and arguments[0].is_Rational:
        line = _rational_line(arguments[1])
        if line is not None and line[1] == 0 and line[0] != 0:
            return line[0], arguments[0]
    return None


def substitute(expression: sympy.Expr, values: Mapping[sympy.Symbol, sympy.Expr]) -> sympy.Expr:
    """``expression.subs(values)`` for numbers given to parameter symbols, the same object, without re-deciding the
    orderings of a ``Max``/``Min`` whose arguments stay undecidable (:func:`_undecidable`): such a switch is rebuilt
    with ``evaluate=False``; every other node as ``subs`` builds it.

    Examples
    --------
    >>> kappa = sympy.Symbol("kappa", real=True)
    >>> f = sympy.Max(0, DISPLACEMENT - kappa) + kappa * DISPLACEMENT**3
    >>> substitute(f, {kappa: sympy.Rational(3, 10)}) == f.subs(kappa, sympy.Rational(3, 10))
    True
    """
    if expression.is_Symbol:  # what subs does to a symbol
        return values.get(expression, expression)
    if not values or not expression.free_symbols & set(values):
        return expression
    if isinstance(expression, (sympy.Max, sympy.Min)):
        arguments = [substitute(argument, values) for argument in expression.args]
        if _undecidable(arguments):
            return expression.func(*arguments, evaluate=False)
        return expression.func(*arguments)
    if isinstance(expression, (sympy.Add, sympy.Mul, sympy.Pow)):
        return expression.func(*[substitute(argument, values) for argument in expression.args])
    return expression.subs(values)


#: the largest (u0·ω0)² + v0² taken: a finite float (sympy extracts the square root of it through a float)
_LARGEST_SQUARE = sympy.Rational(*sys.float_info.max.as_integer_ratio())


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


def _decided_sign(value: sympy.Expr, what: str) -> int:
    """Sign (-1, 0, 1) of an exact real expression; a ProblemError naming ``what`` when it cannot be decided."""
    if value.is_zero:
        return 0
    if value.is_positive:
        return 1
    if value.is_negative:
        return -1
    if value.free_symbols:
        names = ", ".join(sorted(str(symbol) for symbol in value.free_symbols))
        raise ProblemError(
            f"the initial data need the sign of {value} ({what}), which depends on {names}; give numbers for them "
            "(omega0=..., params={...})"
        )
    approximation = sympy.N(value, 60)
    if approximation != 0 and abs(approximation) > sympy.Float("1e-45"):
        return 1 if approximation > 0 else -1
    if sympy.simplify(value) == 0:
        return 0
    approximation = sympy.N(value, 400)
    if approximation == 0:  # pragma: no cover - an exact zero sympy could not prove
        return 0
    return 1 if approximation > 0 else -1


def reduce_quadratic(value: sympy.Expr, generator: sympy.Symbol, square: sympy.Expr) -> sympy.Expr:
    """``value`` in the field K(a), a = ``generator`` with a² = ``square``: the canonical form P + Q a
    (P, Q cancelled rational functions of the other symbols, a rational denominator).

    Examples
    --------
    >>> a = sympy.Symbol("a", positive=True)
    >>> reduce_quadratic(1 / (1 + a), a, 2)      # 1/(1 + √2) = √2 − 1
    a - 1
    """
    a = generator
    if not value.has(a):
        return sympy.cancel(value)
    modulus = sympy.Poly(a**2 - square, a)
    numerator, denominator = sympy.fraction(sympy.cancel(sympy.together(value)))
    numerator = sympy.Poly(numerator, a).rem(modulus)
    denominator = sympy.Poly(denominator, a).rem(modulus)
    r, s = denominator.coeff_monomial(1), denominator.coeff_monomial(a)
    if s != 0:  # rationalise: (p + q a)/(r + s a) = (p + q a)(r − s a)/(r² − s² a²)
        numerator = (numerator * sympy.Poly(r - s * a, a)).rem(modulus)
        denominator_value = sympy.expand(r**2 - s**2 * square)
    else:
        denominator_value = r
    p, q = numerator.coeff_monomial(1), numerator.coeff_monomial(a)
    return sympy.cancel(p / denominator_value) + sympy.cancel(q / denominator_value) * a


class _TurningPoint:
    """The positive turning point A(ε) = Σ ε^n A_n of the orbit through (u0, v0), exactly and lazily.

    Reversion of the energy equation A² + (2ε/ω0²) F(A) = u0² + v0²/ω0² + (2ε/ω0²) F(u0)
    (see the module docstring); thread safe (grown under :data:`lindstedt._precision.LOCK`), shared by the copies
    of :meth:`Oscillator.with_release_order`.

    For polynomial and piecewise-polynomial f with an irrational A0 = R^{1/2} the arithmetic runs in
    the field K(A0) = K[a]/(a² − R): every A_n is kept as P + Q a with P, Q rational functions of the
    other symbols (ω0, parameters), so no nested radicals build up; ``a`` is replaced by A0 on output.
    """

    def __init__(self, problem: "Oscillator"):
        self._f = problem.nonlinearity
        self._omega0 = problem.omega0
        self._start = problem.u0
        self._amplitude = problem.a0
        self._non_smooth = problem.is_non_smooth
        self._radicand = sympy.expand(problem.u0**2 + problem.v0**2 / problem.omega0**2)  # A0²
        # the generator a of K(A0) (None: work with A0 itself — rational A0, or non-polynomial analytic f)
        algebraic = problem.is_polynomial or problem.is_non_smooth
        self._a = sympy.Dummy("A0", positive=True) if algebraic and not problem.a0.is_Rational else None
        self._internal: list[sympy.Expr] = [self._a if self._a is not None else problem.a0]
        self._series: list[sympy.Expr] = [problem.a0]
        self._prepared = False
        self._difference: sympy.Expr = sympy.Integer(0)  # F(A0) − F(u0)
        self._laws: dict[int, sympy.Expr] = {}  # side (+1 above, −1 below, 0 inside a piece) -> f on that piece
        self._side: int | None = None  # the side of A0 the turning point is on (breakpoint only)
        self._derivatives: dict[tuple[int, int], sympy.Expr] = {}

    def series(self, order: int) -> tuple[sympy.Expr, ...]:
        with LOCK:  # shared by the copies and by threads
            if not self._prepared:
                self._prepare()
            while len(self._series) <= order:
                value = self._next()
                self._internal.append(value)
                self._series.append(self._output(value))
            return tuple(self._series[: order + 1])

    # -- arithmetic in K(A0) -------------------------------------------------------------------------
    def _output(self, value: sympy.Expr) -> sympy.Expr:
        if self._a is None:
            return value
        return value.xreplace({self._a: self._amplitude})

    def _reduce(self, value: sympy.Expr) -> sympy.Expr:
        """``value`` in canonical form: P + Q a (a² = A0²) with a rational denominator, or cancelled."""
        if self._a is None:
            return sympy.cancel(sympy.expand(value)) if value.free_symbols else sympy.expand(value)
        try:
            return reduce_quadratic(value, self._a, self._radicand)
        except sympy.PolynomialError:  # a fractional power (u − b)^p at A0: not polynomial in a, keep it as it is
            return sympy.expand(value)

    # -- the potential near A0 -----------------------------------------------------------------
    def _prepare(self) -> None:
        u, amplitude, start = DISPLACEMENT, self._amplitude, self._start
        top = self._internal[0]  # A0, or its generator a
        if not self._non_smooth:
            self._difference = self._reduce(sympy.integrate(self._f, (u, start, top)))
            self._laws = {0: self._f}
            self._prepared = True
            return
        try:
            intervals = decompose_piecewise(self._f, u)
        except UnsupportedNonlinearityError as error:
            raise UnsupportedNonlinearityError(f"the energy of the initial data needs f piecewise polynomial: {error}") from None
        total = sympy.Integer(0)
        for interval in intervals:
            law = sum((c * u**m for m, c in enumerate(interval.coefficients)), interval.analytic)  # analytic part too
            for coefficient, point, power in interval.fractional:  # c·|u − b|^p, b an end of the piece
                law += coefficient * ((u - point) if point == interval.lower else (point - u)) ** power
            lower, upper = start, top  # u0 < A0: the integral runs over [u0, A0] ∩ [lower, upper]
            if interval.lower is not None and _decided_sign(interval.lower - start, "a breakpoint against u0") > 0:
                lower = interval.lower
            if interval.upper is not None and _decided_sign(interval.upper - amplitude, "a breakpoint against A0") < 0:
                upper = interval.upper
            length = upper.xreplace({top: amplitude}) - lower.xreplace({top: amplitude})
            if _decided_sign(length, "the pieces of f between u0 and A0") > 0:
                total += sympy.integrate(law, (u, lower, upper))
            below = interval.lower is None or _decided_sign(amplitude - interval.lower, "A0 against a breakpoint") >= 0
            above = interval.upper is None or _decided_sign(interval.upper - amplitude, "A0 against a breakpoint") >= 0
            if below and above:
                at_lower = interval.lower is not None and _decided_sign(amplitude - interval.lower, "") == 0
                at_upper = interval.upper is not None and _decided_sign(interval.upper - amplitude, "") == 0
                self._laws[1 if at_lower else -1 if at_upper else 0] = law
        self._difference = self._reduce(total)
        self._prepared = True

    def _coefficient(self, power: int) -> sympy.Expr:
        """c_m = f^{(m−1)}(A0)/m! on the piece of the turning point."""
        side = 0 if 0 in self._laws else self._side
        key = (side, power)
        if key not in self._derivatives:
            if side is None:  # pragma: no cover - only asked for after a nonzero A_k decided the side
                raise ProblemError("the side of the breakpoint at A0 is undecided")
            derivative = sympy.diff(self._laws[side], DISPLACEMENT, power - 1)
            value = derivative.subs(DISPLACEMENT, self._internal[0]) / math.factorial(power)
            if value.has(sympy.zoo, sympy.oo, -sympy.oo, sympy.nan):
                raise UnsupportedNonlinearityError(
                    f"the turning point A0 = {self._amplitude} of the orbit through (u0, v0) sits where a fractional power "
                    "of f vanishes: A(eps) is not a power series there; move u0 or v0 off that orbit"
                )
            self._derivatives[key] = self._reduce(value)
        return self._derivatives[key]

    # -- the reversion -----------------------------------------------------------------------------
    def _power(self, power: int, order: int) -> sympy.Expr:
        """The ε^order coefficient of δ^power, δ = Σ_{k≥1} A_k ε^k (known A_k only)."""
        series = self._internal
        table = [sympy.Integer(1)] + [sympy.Integer(0)] * order  # δ^0
        for _ in range(power):
            table = [
                self._reduce(sympy.Add(*[series[k] * table[j - k] for k in range(1, j + 1) if table[j - k] != 0]))
                for j in range(order + 1)
            ]
        return table[order]

    def _next(self) -> sympy.Expr:
        series, n = self._internal, len(self._internal)
        square = sympy.Add(*[series[i] * series[n - i] for i in range(1, n)])
        force = self._difference if n == 1 else sympy.Integer(0)
        moved = [k for k in range(1, n) if self._series[k] != 0]
        if moved:
            if self._side is None and 0 not in self._laws:
                self._side = _decided_sign(self._series[moved[0]], "the side of the breakpoint the turning point moves to")
            for power in range(1, n):
                coefficient = self._coefficient(power)
                if coefficient != 0:
                    force += coefficient * self._power(power, n - 1)
        value = self._reduce(-(square + 2 * force / self._omega0**2) / (2 * series[0]))
        if not value.free_symbols - ({self._a} if self._a is not None else set()) and value != 0:
            if _decided_sign(self._output(value), "A_n") == 0:
                value = sympy.Integer(0)
        return value


def check_names(values: Mapping[Any, Any], names: Sequence[str]) -> None:
    """Raise a :class:`~lindstedt.ParameterError` naming a key of ``values`` that is not one of ``names`` (the free
    symbols), with the closest name as a suggestion.

    Examples
    --------
    >>> check_names({"A0": 1}, ("a0", "omega0"))
    Traceback (most recent call last):
    ...
    lindstedt._errors.ParameterError: unknown parameter 'A0'; did you mean 'a0'? (the problem does not have it as a free symbol; its free symbols are a0, omega0)
    """
    for key in values:
        name = key.name if isinstance(key, sympy.Symbol) else str(key)
        if name in names:
            continue
        close = difflib.get_close_matches(name, names, n=1, cutoff=0.5) or [
            candidate for candidate in names if candidate.lower() == name.lower()]
        hint = f"; did you mean {close[0]!r}?" if close else ""
        free = f"its free symbols are {', '.join(names)}" if names else "it has none: give no values"
        raise ParameterError(f"unknown parameter {name!r}{hint} (the problem does not have it as a free symbol; {free})")



@locked_methods()
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
    u0, v0 : number or numeric string, optional
        General initial data u(0) = u0, u'(0) = v0 (exact finite real numbers; a missing one
        is 0).  Exclusive with ``a0`` and ``a1``; needs ``normalization="initial"``.  With
        ``v0 = 0`` the problem *is* the release at rest ``a0 = u0`` (``u0``, ``v0`` are stored
        as ``None``); otherwise ``a0`` becomes the positive turning point
        ``A0 = (u0² + v0²/ω0²)^{1/2}`` and :attr:`release_shifts` its corrections
        A_1, A_2, … from the energy (see the module docstring).

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
    >>> moving = Oscillator("u**3", u0="3/5", v0="4/5", omega0=1)   # through u(0) = 3/5, u'(0) = 4/5
    >>> moving.a0, moving.amplitude_series(2)                        # its positive turning point A(eps)
    (1, (1, -136/625, 75752/390625))
    >>> Oscillator("u**3", u0=1, v0=0) == Oscillator("u**3", a0=1)
    True
    """

    f: Any
    a0: Any = None
    omega0: Any = None
    params: Any = None
    normalization: str = "initial"
    a1: Any = 0
    u0: Any = None
    v0: Any = None
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
        present = expression.free_symbols  # only the plain symbols that occur are replaced (subs of the rest is a no-op)
        if sympy.Symbol("u") in present:
            expression = expression.subs({sympy.Symbol("u"): DISPLACEMENT})
        plain = {sympy.Symbol(n): s for n, s in parameter_symbols.items() if sympy.Symbol(n) in present}
        if plain:
            expression = expression.subs(plain)
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

        omega0 = self._parse_omega0(self.omega0)
        initial_data = self._parse_initial_data(omega0)
        if initial_data is None:
            amplitude = self._parse_amplitude(self.a0)
            start, speed = None, None
        else:
            amplitude, start, speed = initial_data
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
        set_field(self, "u0", start)
        set_field(self, "v0", speed)
        set_field(self, "params", tuple((parameter_symbols[name], values[name]) for name in raw_params))
        set_field(self, "_release_order", DEFAULT_RELEASE_ORDER if speed is not None else None)
        set_field(self, "_release_digits", None)
        set_field(self, "_turning", _TurningPoint(self) if speed is not None else None)

    def _parse_initial_data(self, omega0: sympy.Expr) -> tuple[sympy.Expr, sympy.Expr | None, sympy.Expr | None] | None:
        """(a0, u0, v0) from u0/v0 (None when neither is given); v0 = 0 is the release at rest a0 = u0."""
        if self.u0 is None and self.v0 is None:
            return None
        if self.normalization != "initial":
            raise ProblemError(
                "u0/v0 prescribe u(0) and u'(0), which needs normalization='initial' (the 'harmonic' normalization "
                "prescribes the first-harmonic amplitude a0 instead); drop normalization='harmonic', or give a0= without u0/v0"
            )
        if self.a0 is not None:
            raise ProblemError(
                "give either a0 (release at rest, u(0) = a0 + eps*a1, u'(0) = 0) or u0/v0 (u(0) = u0, u'(0) = v0), not both; "
                "the release at rest at a0 is u0=a0 with v0=0"
            )
        if _given_quantity(self.a1, "a1") != 0:
            raise ProblemError(
                "a1 shifts a release at rest (u(0) = a0 + eps*a1); with u0/v0 the initial data are exact: remove a1 "
                "(or put the shift into u0)"
            )
        start = sympy.Integer(0) if self.u0 is None else parse_real(self.u0, what="u0")
        speed = sympy.Integer(0) if self.v0 is None else parse_real(self.v0, what="v0")
        if start == 0 and speed == 0:
            raise ProblemError("u0 = v0 = 0 is the rest state, which does not move: give a nonzero u0 or v0")
        if speed == 0:
            return start, None, None  # the release at rest at a0 = u0: the same problem as Oscillator(f, a0=u0)
        radicand = start**2 * omega0**2 + speed**2
        if radicand.is_number and radicand > _LARGEST_SQUARE:  # sympy's root extraction passes it through a float
            raise ProblemError(f"u0 = {self.u0!r}, v0 = {self.v0!r}: the squared turning point (u0·ω0)² + v0² is beyond the range "
                               "of a float; rescale the problem (choose units in which the motion is of order one)")
        amplitude = sympy.sqrt(radicand) / omega0
        if amplitude.is_positive is not True:  # pragma: no cover - omega0 > 0 and v0 != 0
            raise ProblemError(f"the turning point A0 = {amplitude} is not known to be positive; give omega0 as a number")
        return amplitude, start, speed

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
        """f(u) with the numeric parameter values substituted (symbolic ones kept); made once per problem."""
        cached = self.__dict__.get("_nonlinearity")
        if cached is None:
            cached = substitute(self.f, {symbol: value for symbol, value in self.params if value != symbol})
            object.__setattr__(self, "_nonlinearity", cached)
        return cached

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
        """``(a1, a2, …)`` of the release point ``u(0) = a0 + Σ ε^n a_n`` (empty: released at a0 exactly).

        For general initial data (u0, v0 with v0 ≠ 0) these are the corrections A_1 … A_M of the
        positive turning point, M = :attr:`release_order` (every normal form reads them as
        W_n(0) = w_n).  For non-polynomial analytic f, whose hierarchy is numeric, each A_n is
        handed as ``A0·r_n`` with r_n a rational approximation of A_n/A0 to the digits of
        :meth:`with_release_order` (the exact A_n: :meth:`amplitude_series`).
        """
        if self._turning is None:
            return (self.a1,) if self.a1 != 0 else ()
        series = self.amplitude_series(self._release_order)[1:]
        if self._release_digits is None or self.is_polynomial or self.is_non_smooth:
            return series
        digits = self._release_digits
        return tuple(self.a0 * sympy.Rational(str(sympy.N(shift / self.a0, digits))) for shift in series)

    @property
    def release_order(self) -> int | None:
        """How many ε-orders of the turning-point series :attr:`release_shifts` holds (None: a release at rest)."""
        return self._release_order

    @property
    def has_initial_velocity(self) -> bool:
        """True for general initial data with u'(0) = v0 ≠ 0 (then u0, v0 are set)."""
        return self.v0 is not None

    def with_release_order(self, order: int, digits: int | None = None) -> "Oscillator":
        """The same problem (``==``) whose :attr:`release_shifts` hold A_1 … A_order (and, for
        non-polynomial analytic f, are rounded to ``digits`` digits); ``self`` for a release at rest.

        The turning-point series is shared with ``self`` (computed once, lazily).

        Examples
        --------
        >>> problem = Oscillator("u**3", u0=0, v0=1, omega0=1)
        >>> len(problem.release_shifts), len(problem.with_release_order(6).release_shifts)
        (4, 6)
        """
        if self._turning is None:
            return self
        if isinstance(order, bool) or not isinstance(order, int) or order < 1:
            raise ProblemError(f"the release order must be a positive integer, got {order!r}")
        extended = copy.copy(self)
        object.__setattr__(extended, "_release_order", order)
        object.__setattr__(extended, "_release_digits", digits)
        return extended

    def amplitude_series(self, order: int) -> tuple[sympy.Expr, ...]:
        """``(A_0, …, A_order)``, exact: the turning point u(0) of the release the expansion starts from.

        General initial data: the positive turning point of the orbit through (u0, v0), by
        reversion of the energy equation (module docstring).  A release at rest
        (``"initial"``): ``(a0, a1, 0, …)``.

        Raises
        ------
        ProblemError
            For ``normalization="harmonic"`` (u(0) is then a result of the expansion:
            ``Expansion.amplitude``), or where a side of a breakpoint cannot be decided.

        Examples
        --------
        >>> Oscillator("Max(0, u - 1/4)", u0="3/5", v0="4/5", omega0=1).amplitude_series(2)
        (1, -11/50, 88/625)
        """
        if isinstance(order, bool) or not isinstance(order, int) or order < 0:
            raise ProblemError(f"order must be a non-negative integer, got {order!r}")
        if self._turning is not None:
            return self._turning.series(order)
        if self.normalization != "initial":
            raise ProblemError(
                "with normalization='harmonic' a0 is the first-harmonic amplitude and the turning point is a result: "
                "use Expansion.amplitude"
            )
        return (self.a0, self.a1, *([sympy.Integer(0)] * (order - 1)))[: order + 1]

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
            If a symbol has no value, naming it and how to pass it, or a value names no free symbol
            (:func:`check_names`).
        """
        symbols = sorted(self.free_symbols, key=str)
        check_names(values or {}, [symbol.name for symbol in symbols])
        given: dict[str, sympy.Expr] = {}
        for key, value in (values or {}).items():
            name = key.name if isinstance(key, sympy.Symbol) else str(key)
            given[name] = parse_real(value, what=name)
        substitution: dict[sympy.Symbol, sympy.Expr] = {}
        missing = []
        for symbol in symbols:
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
        return substitution

    def describe(self) -> str:
        """One-line human description of the problem, its terms simplified.

        Examples
        --------
        >>> Oscillator("u**3", a0=1, omega0=2, a1="-1/10").describe()
        "u'' + 4*u + eps*(u**3) = 0, u(0) = 1 - eps/10 [initial]"
        """
        params = ", ".join(f"{symbol} = {value}" for symbol, value in self.params if value != symbol)
        symbolic = ", ".join(str(symbol) for symbol in self.symbolic_parameters)
        equation = f"{terms_text(_ACCELERATION, self.omega0**2 * DISPLACEMENT)} + eps*({self.f}) = 0"
        if self.has_initial_velocity:
            text = f"{equation}, u(0) = {self.u0}, u'(0) = {self.v0} [turning point a0 = {self.a0} + O(eps)]"
        else:
            text = f"{equation}, u(0) = {terms_text(self.a0, _EPS * self.a1)} [{self.normalization}]"
        if params:
            text += f"; {params}"
        if symbolic:
            text += f"; symbolic: {symbolic}"
        return text


_EPS, _ACCELERATION = sympy.Symbol("eps"), sympy.Symbol("u''")


def terms_text(*terms: sympy.Expr) -> str:
    """The sum of ``terms`` in their order, each printed simplified by sympy, zero terms left out: ``u'' + u'/50 + u``.

    Examples
    --------
    >>> u, v = sympy.symbols("u u'")
    >>> terms_text(sympy.Symbol("u''"), 2 * sympy.Rational(1, 100) * 1 * v, 1**2 * u, -sympy.Rational(1, 3) * u**3)
    "u'' + u'/50 + u - u**3/3"
    """
    text = ""
    for term in terms:
        if term == 0:
            continue
        printed = sympy.sstr(term)
        if not text:
            text = printed
        elif printed.startswith("-"):
            text += " - " + printed[1:]
        else:
            text += " + " + printed
    return text or "0"
