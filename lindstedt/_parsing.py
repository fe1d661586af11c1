"""Safe parsing of user input (nonlinearities f(u), numbers, parameter values).

Strings are tokenised first and every name is checked against a whitelist of
mathematical functions, the variable ``u`` and the declared parameters, so no
attribute access, dunder name or builtin can reach sympy's evaluator.  ``^`` is
read as a power.  Decimals — a value ``"0.1"`` or a literal inside an
expression, ``"Max(0, u - 0.3)"`` — are read *exactly* (as ``1/10``, ``3/10``).
"""

from __future__ import annotations

import io
import keyword
import re
import tokenize
from typing import Any, Iterable, Mapping

import sympy
from sympy.parsing.sympy_parser import convert_xor, parse_expr, rationalize, standard_transformations

from ._errors import ParameterError, ProblemError

__all__ = ["ALLOWED_FUNCTIONS", "parse_expression", "parse_number", "parse_value"]

ALLOWED_FUNCTIONS: dict[str, Any] = {
    "sin": sympy.sin,
    "cos": sympy.cos,
    "tan": sympy.tan,
    "sinh": sympy.sinh,
    "cosh": sympy.cosh,
    "tanh": sympy.tanh,
    "asin": sympy.asin,
    "acos": sympy.acos,
    "atan": sympy.atan,
    "exp": sympy.exp,
    "log": sympy.log,
    "sqrt": sympy.sqrt,
    "Abs": sympy.Abs,
    "abs": sympy.Abs,
    "Max": sympy.Max,
    "max": sympy.Max,
    "Min": sympy.Min,
    "min": sympy.Min,
    "Heaviside": sympy.Heaviside,
    "sign": sympy.sign,
    "pi": sympy.pi,
    "E": sympy.E,
}

_PARSER_GLOBALS: dict[str, Any] = {
    "__builtins__": {},
    "Integer": sympy.Integer,
    "Float": sympy.Float,
    "Rational": sympy.Rational,
    "Symbol": sympy.Symbol,
    **ALLOWED_FUNCTIONS,
}

_MAX_LENGTH = 2000
_DECIMAL = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")


def _names_in(text: str) -> list[str]:
    try:
        tokens = list(tokenize.generate_tokens(io.StringIO(text).readline))
    except (tokenize.TokenError, IndentationError, SyntaxError) as error:
        raise ProblemError(f"cannot parse {text!r}: {error}; write it like 'u**3 + c*u**5'") from None
    names = []
    for token in tokens:
        if token.type == tokenize.OP and token.string in {".", ";", "=", ":", "[", "]", "{", "}", "@", "lambda"}:
            raise ProblemError(
                f"cannot parse {text!r}: the character {token.string!r} is not allowed; "
                "use numbers, u, declared parameters, + - * / ** ^ and functions like sin, exp, Max"
            )
        if token.type == tokenize.NAME:
            names.append(token.string)
    return names


def parse_expression(
    text: str | sympy.Expr | int | float,
    *,
    symbols: Mapping[str, sympy.Symbol],
    what: str = "f",
) -> sympy.Expr:
    """Parse ``text`` into a sympy expression using only whitelisted names.

    Parameters
    ----------
    text : str or sympy expression or number
        The expression.  Strings are tokenised and checked before parsing.
    symbols : mapping
        Names that may appear (the variable ``u`` and declared parameters).
    what : str
        How to call the expression in error messages.

    Returns
    -------
    sympy.Expr

    Raises
    ------
    ProblemError
        If the text cannot be parsed or uses a forbidden construct.
    ParameterError
        If it uses a name that is neither allowed nor declared.

    Examples
    --------
    >>> import sympy
    >>> u, c = sympy.symbols("u c")
    >>> parse_expression("u^3 + c*u**5", symbols={"u": u, "c": c})
    c*u**5 + u**3
    """
    if isinstance(text, sympy.Basic):
        return sympy.sympify(text)
    if isinstance(text, (int, float)) and not isinstance(text, bool):
        return sympy.sympify(text)
    if not isinstance(text, str):
        raise ProblemError(f"{what} must be a string or a sympy expression, got {type(text).__name__}")
    if len(text) > _MAX_LENGTH:
        raise ProblemError(f"{what} is longer than {_MAX_LENGTH} characters; simplify it before passing it")
    if not text.strip():
        raise ProblemError(f"{what} is empty; give an expression such as 'u**3'")
    for name in _names_in(text):
        if "__" in name or keyword.iskeyword(name):
            raise ProblemError(f"{what}: the name {name!r} is not allowed in an expression")
        if name not in symbols and name not in ALLOWED_FUNCTIONS:
            raise ParameterError(
                f"{what} uses {name!r}, which is neither the variable nor a declared parameter; "
                f"declare it, e.g. params={{{name!r}: value}} in Python or --param {name}=VALUE on the command line"
            )
    local_names = dict(symbols)
    try:
        expression = parse_expr(
            text,
            local_dict=local_names,
            global_dict=dict(_PARSER_GLOBALS),
            transformations=standard_transformations + (convert_xor, rationalize),
            evaluate=True,
        )
    except (SyntaxError, TypeError, ValueError, AttributeError, ZeroDivisionError, tokenize.TokenError) as error:
        raise ProblemError(f"cannot parse {what} = {text!r}: {error}") from None
    if not isinstance(expression, sympy.Expr):
        raise ProblemError(f"{what} = {text!r} is not a mathematical expression")
    return expression


def parse_number(text: str | int | float | sympy.Expr, *, what: str) -> sympy.Expr:
    """Parse a numeric value; decimal strings become exact rationals.

    Examples
    --------
    >>> parse_number("0.1", what="a0")
    1/10
    >>> parse_number("1/3", what="a0")
    1/3
    """
    if isinstance(text, str):
        stripped = text.strip()
        if _DECIMAL.match(stripped):
            return sympy.Rational(stripped)
        value = parse_expression(stripped, symbols={}, what=what)
    elif isinstance(text, bool):
        raise ProblemError(f"{what} must be a number, got a boolean")
    else:
        value = sympy.sympify(text)
    if value.free_symbols:
        raise ProblemError(f"{what} = {text!r} must be a number here")
    return value


def parse_value(
    text: str | int | float | sympy.Expr | None,
    *,
    name: str,
    symbol: sympy.Symbol,
    allowed: Iterable[str] = (),
) -> sympy.Expr:
    """Parse a parameter-like value: ``None`` or its own name means "keep symbolic".

    Examples
    --------
    >>> import sympy
    >>> c = sympy.Symbol("c", real=True)
    >>> parse_value(None, name="c", symbol=c)
    c
    >>> parse_value("2/7", name="c", symbol=c)
    2/7
    """
    if text is None:
        return symbol
    if isinstance(text, sympy.Symbol):
        return text
    if isinstance(text, str) and text.strip() == name:
        return symbol
    if isinstance(text, str) and not _DECIMAL.match(text.strip()):
        known = {other: sympy.Symbol(other, real=True) for other in allowed}
        value = parse_expression(text, symbols=known, what=name)
        return value
    return parse_number(text, what=name)
