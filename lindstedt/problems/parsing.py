"""The one parser of user input: nonlinearities f(u), numbers and parameter values.

Every string that reaches lindstedt from a user (Python arguments, ``values=``,
command-line flags, entries of a SYSTEM.json) is read here and nowhere else.
Nothing is ever handed to ``eval``, ``sympify`` or ``parse_expr``: the text is
parsed by Python's ``ast`` in expression mode and the tree is *walked* by a
whitelist that builds the sympy expression node by node.

Accepted grammar (``^`` is read as ``**``)::

    expr    := expr ('+' | '-' | '*' | '/' | '**') expr | ('+' | '-') expr | '(' expr ')'
             | NUMBER | NAME | FUNCTION '(' expr (',' expr)* ')'
             | 'Piecewise' '(' piece (',' piece)* ')'
    piece   := '(' expr ',' expr ('<' | '<=' | '>' | '>=') expr ')' | '(' expr ',' 'True' ')'   (True: last piece only)
    NUMBER  := integer or decimal literal (``3``, ``0.25``, ``1e-3``, ``1_000``), read exactly
    NAME    := 'u' | a declared parameter | 'pi' | 'E'
    FUNCTION:= sin cos tan sinh cosh tanh asin acos atan exp log sqrt
               Abs abs Max max Min min Heaviside sign

Nothing else: no strings, bytes or f-strings, no attribute access, subscripts,
keywords, lambdas, comprehensions or assignment expressions; comparisons and
tuples only as the (value, condition) pieces of ``Piecewise``, one comparison each.

Bounds (checked *before* the work they protect is done; the error names the bound):
:data:`LIMITS` — input length, number of syntax nodes, nesting depth, length of a
numeric literal, size of a decimal exponent, integer exponents of powers and the
size (in bits) of every exact number built along the way.

Numbers are exact: ``"0.1"`` is 1/10, a Python ``float`` is its exact binary value
(``0.1`` is 3602879701896397/36028797018963968), a sympy ``Float`` likewise.
"""

from __future__ import annotations

import ast
import math
import numbers
import re
import sys
from dataclasses import dataclass
from decimal import Decimal
from fractions import Fraction
from typing import Any, Callable, Mapping

import numpy as np
import sympy

from .._errors import ParameterError, ProblemError
from .._precision import LOCK, locked

__all__ = ["ALLOWED_FUNCTIONS", "CONSTANTS", "LIMITS", "ParserLimits", "as_exact", "parse_expression", "parse_float", "parse_floats",
           "parse_real", "parse_value"]


@dataclass(frozen=True)
class ParserLimits:
    """Size bounds of the parser (every user string is checked against them).

    Attributes
    ----------
    length : int
        Characters of one input.
    nodes : int
        Syntax-tree nodes of one input.
    depth : int
        Nesting depth of the syntax tree.
    literal : int
        Characters of one numeric literal (the exact decimal of any double fits).
    decimal_exponent : int
        |e| of a literal ``…e±e``.
    power : int
        |p| and q of an exponent p/q of a power whose base is not a plain rational, |x| of an irrational
        numeric exponent x, and the degree of the expression *after* sympy combines powers
        (``(u**a)**b`` is ``u**(a*b)``, ``u**a * u**b`` is ``u**(a+b)``): in each symbol, exponents of
        nested powers multiply, those of factors add.
    bits : int
        Bits of numerator plus denominator of any exact rational built.
    """

    length: int = 2000
    nodes: int = 500
    depth: int = 40
    literal: int = 1200
    decimal_exponent: int = 400
    power: int = 200
    bits: int = 20000


LIMITS = ParserLimits()

# name -> (sympy callable, minimum and maximum number of arguments)
ALLOWED_FUNCTIONS: dict[str, tuple[Callable[..., sympy.Expr], int, int]] = {
    "sin": (sympy.sin, 1, 1),
    "cos": (sympy.cos, 1, 1),
    "tan": (sympy.tan, 1, 1),
    "sinh": (sympy.sinh, 1, 1),
    "cosh": (sympy.cosh, 1, 1),
    "tanh": (sympy.tanh, 1, 1),
    "asin": (sympy.asin, 1, 1),
    "acos": (sympy.acos, 1, 1),
    "atan": (sympy.atan, 1, 1),
    "exp": (sympy.exp, 1, 1),
    "log": (sympy.log, 1, 1),
    "sqrt": (sympy.sqrt, 1, 1),
    "Abs": (sympy.Abs, 1, 1),
    "abs": (sympy.Abs, 1, 1),
    "Max": (sympy.Max, 1, 16),
    "max": (sympy.Max, 1, 16),
    "Min": (sympy.Min, 1, 16),
    "min": (sympy.Min, 1, 16),
    "Heaviside": (sympy.Heaviside, 1, 1),
    "sign": (sympy.sign, 1, 1),
    "Piecewise": (sympy.Piecewise, 1, 16),  # built by _Builder.piecewise from (value, condition) pieces
}
_COMPARISONS: dict[type, Callable[[Any, Any], Any]] = {
    ast.Lt: lambda left, right: left < right,
    ast.LtE: lambda left, right: left <= right,
    ast.Gt: lambda left, right: left > right,
    ast.GtE: lambda left, right: left >= right,
}
CONSTANTS: dict[str, sympy.Expr] = {"pi": sympy.pi, "E": sympy.E}

_BINARY_OPERATORS: dict[type, Callable[[Any, Any], Any]] = {
    ast.Add: lambda left, right: left + right,
    ast.Sub: lambda left, right: left - right,
    ast.Mult: lambda left, right: left * right,
    ast.Div: lambda left, right: left / right,
}
_FORBIDDEN: dict[type, str] = {
    ast.Attribute: "attribute access ('.')",
    ast.Subscript: "subscripts ('[...]')",
    ast.Lambda: "lambda",
    ast.NamedExpr: "assignment expressions (':=')",
    ast.JoinedStr: "f-strings",
    ast.FormattedValue: "f-strings",
    ast.Compare: "comparisons",
    ast.BoolOp: "'and'/'or'",
    ast.IfExp: "conditional expressions",
    ast.ListComp: "comprehensions",
    ast.SetComp: "comprehensions",
    ast.DictComp: "comprehensions",
    ast.GeneratorExp: "comprehensions",
    ast.List: "lists",
    ast.Tuple: "tuples",
    ast.Set: "sets",
    ast.Dict: "dictionaries",
    ast.Starred: "'*' unpacking",
    ast.Await: "await",
    ast.Yield: "yield",
    ast.YieldFrom: "yield",
    ast.Slice: "slices",
}
# exp, sinh, cosh of a number are computed only for |x| <= 1000 (e^1000 ~ 1e434); any numeric function value must stay below 1e400
_EXPONENTIAL = (sympy.exp, sympy.sinh, sympy.cosh)
_EXPONENTIAL_ARGUMENT = 1000
_LARGEST = sympy.Integer(10) ** 400
_FLOAT_LITERAL = re.compile(r"^(?P<whole>[0-9_]*)(?:\.(?P<fraction>[0-9_]*))?(?:[eE](?P<exponent>[+-]?[0-9_]+))?$")
_GRAMMAR_HINT = "use numbers, u, declared parameters, + - * / ** ^, parentheses and functions such as sin, exp, Max, Heaviside"


def _bits(number: sympy.Rational) -> int:
    return int(number.p).bit_length() + int(number.q).bit_length()


def _check_size(value: Any, what: str, text: str) -> None:
    if isinstance(value, sympy.Rational) and _bits(value) > LIMITS.bits:
        raise ProblemError(
            f"{what} = {text!r} builds a number of {_bits(value)} bits, more than the bound of {LIMITS.bits}; "
            "write the quantity with smaller numbers"
        )


def _degrees(expression: sympy.Basic, cache: dict[sympy.Basic, dict[sympy.Symbol, Fraction]]) -> dict[sympy.Symbol, Fraction]:
    """The degree of ``expression`` in each of its free symbols, as sympy holds it: exponents of nested powers
    multiply, those of factors add, a sum or a function takes the largest of its arguments'."""
    known = cache.get(expression)
    if known is not None:
        return known
    if not expression.free_symbols:
        degrees: dict[sympy.Symbol, Fraction] = {}
    elif expression.is_Symbol:
        degrees = {expression: Fraction(1)}
    elif expression.is_Mul:
        degrees = {}
        for argument in expression.args:
            for symbol, degree in _degrees(argument, cache).items():
                degrees[symbol] = degrees.get(symbol, Fraction(0)) + degree
    elif expression.is_Pow and not expression.exp.free_symbols:
        exponent = expression.exp
        if exponent.is_Rational:
            factor = abs(Fraction(int(exponent.p), int(exponent.q)))
        else:  # an irrational number, bounded by LIMITS.power where it was built
            with LOCK:
                factor = Fraction(math.ceil(abs(complex(sympy.N(exponent, 15)))))
        degrees = {symbol: degree * factor for symbol, degree in _degrees(expression.base, cache).items()}
    else:
        degrees = {}
        for argument in expression.args:
            for symbol, degree in _degrees(argument, cache).items():
                degrees[symbol] = max(degrees.get(symbol, Fraction(0)), degree)
    cache[expression] = degrees
    return degrees


def _check_degree(expression: sympy.Basic, what: str, text: str, cache: dict[sympy.Basic, dict[sympy.Symbol, Fraction]]) -> None:
    for part in (expression, *expression.args) if expression.is_Mul else (expression,):
        if part.is_Pow and part.exp.is_Rational and part.exp.q > LIMITS.power and part.base.free_symbols:
            raise ProblemError(
                f"{what} = {text!r} holds {part} once sympy combines its powers ((u**a)**b is u**(a*b)): exponents are "
                f"bounded by {LIMITS.power} in numerator and denominator; write it with smaller exponents"
            )
    for symbol, degree in _degrees(expression, cache).items():
        if degree > LIMITS.power:
            raise ProblemError(
                f"{what} = {text!r} has degree {degree} in {symbol} once sympy combines its powers "
                f"((u**a)**b is u**(a*b), u**a*u**b is u**(a+b)), more than the bound of {LIMITS.power}; "
                "write it with smaller exponents"
            )


def _not_real(expression: sympy.Expr) -> str | None:
    """``None`` for a real number, else its value (a numeric expression without free symbols: checked by sympy's
    assumptions, else by a 30-digit evaluation, under the package's lock)."""
    if expression.is_Rational:
        return None
    with LOCK:
        real = expression.is_extended_real
        if real is True and expression.is_finite is not False:
            return None
        value = sympy.N(expression, 30, chop=True)
        if real is None and value.is_extended_real and value.is_finite:
            return None
        return str(sympy.N(value, 6))


def _check_real(expression: sympy.Basic, what: str, text: str, segment: str | None = None) -> None:
    if not isinstance(expression, sympy.Expr) or expression.free_symbols or not expression.is_number:
        return
    value = _not_real(expression)
    if value is None:
        return
    name = segment if segment is not None else str(expression)
    hint = "keep each function's argument in its real domain (sqrt and fractional powers x >= 0, log x > 0, asin and acos |x| <= 1)"
    raise ProblemError(
        f"{what} = {text!r}: the sub-expression {name!r} is not a real number (its value is {value}); "
        f"lindstedt works with real numbers only: {hint}"
    )


class _Builder:
    """Walks a whitelisted syntax tree and builds the sympy expression bottom-up."""

    def __init__(self, text: str, names: Mapping[str, sympy.Expr], what: str):
        self.text = text
        self.names = names
        self.what = what
        self.degrees: dict[sympy.Basic, dict[sympy.Symbol, Fraction]] = {}

    def checked(self, result: sympy.Basic, node: ast.AST) -> sympy.Basic:
        """A built node after sympy's automatic simplification: real if it is a number, of bounded degree."""
        _check_real(result, self.what, self.text, ast.get_source_segment(self.text, node))
        _check_degree(result, self.what, self.text, self.degrees)
        return result

    def fail(self, reason: str) -> ProblemError:
        return ProblemError(f"cannot parse {self.what} = {self.text!r}: {reason}; {_GRAMMAR_HINT}")

    def build(self, node: ast.AST, depth: int = 0) -> sympy.Expr:
        if depth > LIMITS.depth:
            raise ProblemError(f"{self.what} is nested more than {LIMITS.depth} levels deep; simplify it")
        if isinstance(node, ast.Expression):
            return self.build(node.body, depth)
        if isinstance(node, ast.Constant):
            return self.constant(node)
        if isinstance(node, ast.Name):
            return self.name(node.id)
        if isinstance(node, ast.UnaryOp):
            operand = self.build(node.operand, depth + 1)
            if isinstance(node.op, ast.USub):
                return -operand
            if isinstance(node.op, ast.UAdd):
                return operand
            raise self.fail(f"the operator {type(node.op).__name__} is not allowed")
        if isinstance(node, ast.BinOp):
            left = self.build(node.left, depth + 1)
            right = self.build(node.right, depth + 1)
            if isinstance(node.op, ast.Pow):
                result = self.power(left, right)
            elif type(node.op) in _BINARY_OPERATORS:
                result = _BINARY_OPERATORS[type(node.op)](left, right)
            else:
                raise self.fail(f"the operator {type(node.op).__name__} is not allowed")
            _check_size(result, self.what, self.text)
            return self.checked(result, node)
        if isinstance(node, ast.Call):
            return self.checked(self.call(node, depth), node)
        reason = _FORBIDDEN.get(type(node), f"the construct {type(node).__name__}")
        raise self.fail(f"not allowed: {reason}")

    def constant(self, node: ast.Constant) -> sympy.Expr:
        value = node.value
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            kind = {str: "string literals", bytes: "bytes literals", complex: "complex numbers"}.get(type(value), repr(value))
            raise self.fail(f"not allowed: {kind}")
        literal = ast.get_source_segment(self.text, node) or ""
        if len(literal) > LIMITS.literal:
            raise ProblemError(f"{self.what}: a numeric literal longer than {LIMITS.literal} characters is not accepted")
        if isinstance(value, int):
            return sympy.Integer(value)
        match = _FLOAT_LITERAL.match(literal)
        if match is None:  # pragma: no cover - Python's tokenizer only makes such literals
            raise self.fail(f"the literal {literal!r} is not a decimal number")
        exponent = int((match["exponent"] or "0").replace("_", ""))
        if abs(exponent) > LIMITS.decimal_exponent:
            raise ProblemError(
                f"{self.what}: the decimal exponent in {literal!r} exceeds the bound |e| <= {LIMITS.decimal_exponent}"
            )
        whole = (match["whole"] or "").replace("_", "")
        fraction = (match["fraction"] or "").replace("_", "")
        mantissa = int((whole + fraction) or "0")
        return sympy.Rational(mantissa, 10 ** len(fraction)) * sympy.Rational(10) ** exponent

    def name(self, identifier: str) -> sympy.Expr:
        if identifier in self.names:
            return self.names[identifier]
        if identifier in CONSTANTS:
            return CONSTANTS[identifier]
        if identifier in ALLOWED_FUNCTIONS:
            raise self.fail(f"the function {identifier!r} must be called, e.g. {identifier}(u)")
        if identifier.startswith("_"):
            raise self.fail(f"the name {identifier!r} is not allowed")
        raise ParameterError(
            f"{self.what} uses {identifier!r}, which is neither the variable nor a declared parameter; "
            f"declare it, e.g. params={{{identifier!r}: value}} in Python or --param {identifier}=VALUE on the command line"
        )

    def power(self, base: sympy.Expr, exponent: sympy.Expr) -> sympy.Expr:
        if isinstance(exponent, sympy.Rational):
            p, q = abs(int(exponent.p)), int(exponent.q)
            if isinstance(base, sympy.Rational) and base < 0 and q != 1:
                raise ProblemError(
                    f"{self.what} = {self.text!r}: ({base})**({exponent}) is not a real number (sympy takes the principal, "
                    f"complex root); lindstedt works with real numbers only: for the real root write the sign outside the "
                    f"power, e.g. -{-base}**({exponent}) or -({-base}**({exponent}))"
                )
            if isinstance(base, sympy.Rational):
                if base not in (0, 1, -1) and (q > LIMITS.power or _bits(base) * p > LIMITS.bits * q):
                    raise ProblemError(
                        f"{self.what} = {self.text!r}: the power {base}**({exponent}) exceeds the bound of "
                        f"{LIMITS.bits} bits; write the quantity with smaller numbers"
                    )
            elif p > LIMITS.power or q > LIMITS.power:
                raise ProblemError(
                    f"{self.what} = {self.text!r}: exponents are bounded by {LIMITS.power} in numerator and denominator, "
                    f"got {exponent}"
                )
        elif exponent.is_number:
            # irrational numeric exponent: sympy keeps 2**pi or u**pi symbolic, but a huge one would be evaluated later
            _check_real(exponent, self.what, self.text)
            with LOCK:
                if exponent.has(sympy.zoo, sympy.nan, sympy.oo, -sympy.oo) or not abs(sympy.N(exponent, 15)) <= LIMITS.power:
                    raise ProblemError(f"{self.what} = {self.text!r}: the exponent {exponent} exceeds the bound {LIMITS.power}")
        result = base**exponent
        if result.is_number and not isinstance(result, sympy.Rational):  # E**x, pi**x: of moderate size, as function values
            with LOCK:
                magnitude = abs(sympy.N(result, 15))
            if magnitude.has(sympy.nan, sympy.zoo, sympy.oo) or magnitude > _LARGEST:
                raise ProblemError(f"{self.what} = {self.text!r}: the power {base}**({exponent}) is not a finite number of moderate size")
        return result

    def call(self, node: ast.Call, depth: int) -> sympy.Expr:
        if not isinstance(node.func, ast.Name) or node.func.id not in ALLOWED_FUNCTIONS:
            callee = node.func.id if isinstance(node.func, ast.Name) else type(node.func).__name__
            raise self.fail(f"calling {callee!r} is not allowed (allowed functions: {', '.join(sorted(ALLOWED_FUNCTIONS))})")
        if node.keywords:
            raise self.fail("keyword arguments are not allowed")
        function, least, most = ALLOWED_FUNCTIONS[node.func.id]
        if not least <= len(node.args) <= most:
            raise self.fail(f"{node.func.id} takes {least if least == most else f'{least} to {most}'} argument(s)")
        if function is sympy.Piecewise:
            return self.piecewise(node, depth)
        arguments = [self.build(argument, depth + 1) for argument in node.args]
        if function in _EXPONENTIAL and arguments[0].is_number and not abs(sympy.N(arguments[0], 15)) <= _EXPONENTIAL_ARGUMENT:
            raise ProblemError(
                f"{self.what} = {self.text!r}: {node.func.id} of a number larger than {_EXPONENTIAL_ARGUMENT} in magnitude is not accepted"
            )
        try:
            result = function(*arguments)
        except (TypeError, ValueError, ArithmeticError) as error:
            raise self.fail(f"{node.func.id}{tuple(arguments)} cannot be formed ({error})") from None
        if result.is_number and not isinstance(result, sympy.Rational):
            magnitude = abs(sympy.N(result, 15))
            if magnitude.has(sympy.nan, sympy.zoo, sympy.oo) or magnitude > _LARGEST:
                raise ProblemError(f"{self.what} = {self.text!r}: {node.func.id}{tuple(arguments)} is not a finite number of moderate size")
        return result

    def piecewise(self, node: ast.Call, depth: int) -> sympy.Expr:
        """``Piecewise((value, u < b), …, (value, True))``: each piece a 2-tuple of an expression and one comparison
        (``True`` only for the last piece); nothing else of the comparison/tuple syntax is accepted."""
        pieces = []
        for position, argument in enumerate(node.args):
            if not isinstance(argument, ast.Tuple) or len(argument.elts) != 2:
                raise self.fail("each Piecewise argument must be a pair (value, condition), e.g. (u, u > 0)")
            value_node, condition_node = argument.elts
            value = self.build(value_node, depth + 2)
            if isinstance(condition_node, ast.Constant) and condition_node.value is True:
                if position != len(node.args) - 1:
                    raise self.fail("only the last Piecewise piece may have the condition True")
                condition = sympy.true
            elif (
                isinstance(condition_node, ast.Compare)
                and len(condition_node.ops) == 1
                and type(condition_node.ops[0]) in _COMPARISONS
            ):
                left = self.build(condition_node.left, depth + 3)
                right = self.build(condition_node.comparators[0], depth + 3)
                condition = _COMPARISONS[type(condition_node.ops[0])](left, right)
            else:
                raise self.fail("a Piecewise condition must be one comparison (<, <=, >, >=) such as u > 0, or True (last piece)")
            pieces.append((value, condition))
        try:
            return sympy.Piecewise(*pieces)
        except (TypeError, ValueError) as error:
            raise self.fail(f"Piecewise{tuple(pieces)} cannot be formed ({error})") from None


#: Texts already read (the text, what it is called, the bounds, and what each name of its syntax tree stands for) →
#: their expression: the same text is built once (its sympy evaluation, e.g. of a ``Max``, costs milliseconds); only
#: texts that passed every check are kept.
_PARSED: dict[tuple[Any, ...], sympy.Basic] = {}
_PARSED_SIZE = 256
#: the texts of :data:`_PARSED` → (their syntax node count, the names their tree uses): a text read before is
#: looked up without parsing it again (bounded and cleared with it)
_SHAPES: dict[str, tuple[int, tuple[str, ...]]] = {}


@locked
def parse_expression(
    text: str | sympy.Expr | int | float,
    *,
    symbols: Mapping[str, sympy.Expr],
    what: str = "f",
) -> sympy.Expr:
    """Read ``text`` into a sympy expression through the whitelist (the only way user text becomes sympy).

    Parameters
    ----------
    text : str or sympy expression or number
        The expression.  Strings follow the grammar of this module; sympy
        objects are the caller's own (their ``Float`` atoms become exact).
    symbols : mapping
        Names that may appear (the variable ``u`` and declared parameters).
    what : str
        How to call the expression in error messages.

    Returns
    -------
    sympy.Expr
        Finite: an expression containing ``nan``, ``oo`` or ``zoo`` is refused.

    Raises
    ------
    ProblemError
        If the text is not in the grammar or exceeds a bound of :data:`LIMITS`.
    ParameterError
        If it uses a name that is neither allowed nor declared.

    Examples
    --------
    >>> import sympy
    >>> u, c = sympy.symbols("u c")
    >>> parse_expression("u^3 + c*u**5 + 0.5", symbols={"u": u, "c": c})
    c*u**5 + u**3 + 1/2
    >>> try:
    ...     parse_expression("sin('x')", symbols={"u": u})
    ... except ProblemError as error:
    ...     print(str(error).split(";")[0])
    cannot parse f = "sin('x')": not allowed: string literals
    """
    if not isinstance(text, str):
        if isinstance(text, bool) or not isinstance(text, (sympy.Basic, numbers.Number, Decimal)):
            raise ProblemError(f"{what} must be a string or a sympy expression, got {type(text).__name__}")
        expression = as_exact(text, what=what)
        if isinstance(expression, sympy.Basic):  # the caller's own tree: every numeric sub-expression real, degree bounded
            for part in sympy.preorder_traversal(expression):
                _check_real(part, what, str(text))
            _check_degree(expression, what, str(text), {})
    else:
        expression = _parse_text(text, symbols, what)
    if not isinstance(expression, sympy.Expr):
        raise ProblemError(f"{what} = {text!r} is not a mathematical expression")
    if expression.has(sympy.zoo, sympy.oo, -sympy.oo, sympy.nan):
        raise ProblemError(f"{what} = {text!r} is not finite (it contains a division by zero, an infinity or NaN)")
    return expression


def _parse_text(text: str, symbols: Mapping[str, sympy.Expr], what: str) -> sympy.Expr:
    if len(text) > LIMITS.length:
        raise ProblemError(f"{what} is longer than {LIMITS.length} characters; simplify it before passing it")
    if not text.strip():
        raise ProblemError(f"{what} is empty; give an expression such as 'u**3'")
    source = text.strip().replace("^", "**")
    ratio = _RATIO.fullmatch(source)
    if ratio is not None:
        number = _ratio(ratio, what, text)
        if number is not None:
            return number
    shape, tree = _SHAPES.get(source), None
    if shape is None:
        try:
            tree = ast.parse(source, mode="eval")
        except (SyntaxError, ValueError, RecursionError, MemoryError) as error:
            reason = getattr(error, "msg", None) or type(error).__name__
            raise ProblemError(f"cannot parse {what} = {text!r}: {reason}; {_GRAMMAR_HINT}") from None
        count, found = 0, set()
        for node in ast.walk(tree):
            count += 1
            if isinstance(node, ast.Name):
                found.add(node.id)
        shape = (count, tuple(sorted(found)))
    count, names = shape
    if count > LIMITS.nodes:
        raise ProblemError(f"{what} has {count} syntax nodes, more than the bound of {LIMITS.nodes}; simplify it")
    key = (source, what, LIMITS, tuple((name, symbols.get(name)) for name in names))
    expression = _PARSED.get(key)
    if expression is not None:
        return expression
    if tree is None:
        tree = ast.parse(source, mode="eval")
    try:
        expression = _Builder(source, symbols, what).build(tree)
    except RecursionError:  # pragma: no cover - the depth bound comes first
        raise ProblemError(f"{what} is nested too deeply; simplify it") from None
    if len(_PARSED) >= _PARSED_SIZE:
        _PARSED.clear()
        _SHAPES.clear()
    _PARSED[key] = expression
    _SHAPES[source] = shape
    return expression


#: an integer or a quotient of two (most numeric arguments: "1/3", "-2"), as Python's grammar writes them (no leading
#: zeros); read by :func:`_ratio` without building the syntax tree
_RATIO = re.compile(r"(-?)(0|[1-9][0-9]*)(?:/(0|[1-9][0-9]*))?")


def _ratio(match: re.Match, what: str, text: str) -> sympy.Rational | None:
    """The number a :data:`_RATIO` text is read as — ``-a/b`` is ``(-a)/b`` — with the bounds the tree's reading
    applies (nodes, depth, literal length, size of the quotient); None where a bound or a zero divisor is met (the
    tree's reading then gives its error)."""
    sign, numerator, denominator = match.groups()
    nodes = 2 + 2 * bool(sign) + 3 * (denominator is not None)
    if (denominator == "0" or nodes > LIMITS.nodes or LIMITS.depth < 2
            or max(len(numerator), len(denominator or "")) > LIMITS.literal):
        return None
    number = sympy.Integer(-int(numerator) if sign else int(numerator))
    if denominator is None:
        return number
    number = number / sympy.Integer(int(denominator))
    return number if _bits(number) <= LIMITS.bits else None


def as_exact(value: Any, *, what: str) -> sympy.Expr:
    """Convert a Python or sympy number/expression to an exact sympy object (strings are refused).

    ``float`` and sympy ``Float`` become their exact binary value, ``Fraction``
    and ``Decimal`` their exact value; integers are bounded like literals.

    Examples
    --------
    >>> as_exact(0.5, what="a0"), as_exact(0.1, what="b")
    (1/2, 3602879701896397/36028797018963968)
    """
    if isinstance(value, str):
        raise ProblemError(f"{what}: strings must go through parse_real or parse_expression")  # internal misuse
    if isinstance(value, bool):
        raise ProblemError(f"{what} must be a number, got the boolean {value}")
    if isinstance(value, numbers.Integral):
        number = sympy.Integer(int(value))
    elif isinstance(value, (float, Decimal)) or (isinstance(value, numbers.Real) and not isinstance(value, sympy.Basic)):
        if isinstance(value, numbers.Rational):
            number = sympy.Rational(int(value.numerator), int(value.denominator))
        else:
            floating = value if isinstance(value, Decimal) else float(value)
            finite = floating.is_finite() if isinstance(floating, Decimal) else math.isfinite(floating)
            if not finite:
                raise ProblemError(f"{what} = {value!r} is not finite; give a finite real number")
            exact = Fraction(floating)
            number = sympy.Rational(exact.numerator, exact.denominator)
    elif isinstance(value, numbers.Complex) and not isinstance(value, sympy.Basic):
        raise ProblemError(f"{what} = {value!r} is complex; give a real number")
    elif isinstance(value, sympy.Basic):
        number = value
        floats = number.atoms(sympy.Float)
        if floats:
            if any(not math.isfinite(float(f)) for f in floats):
                raise ProblemError(f"{what} = {value} is not finite; give a finite real number")
            number = number.xreplace({f: sympy.Rational(f) for f in floats})
    else:
        raise ProblemError(
            f"{what} has type {type(value).__name__}; give an int, float, Fraction, an exact string such as '1/3', or a sympy number"
        )
    _check_size(number, what, str(value)[:60])
    return number


@locked
def parse_real(value: Any, *, what: str) -> sympy.Expr:
    """A finite real number, exactly: where the API needs a number, this reads it.

    Accepts int, float (exact binary value), Fraction, Decimal, numpy scalars,
    sympy numbers and strings in the grammar of this module without names other
    than ``pi`` and ``E`` (``"1/3"``, ``"0.25"``, ``"sqrt(2)/2"``).  NaN, inf,
    complex values, words and symbols are refused.

    Raises
    ------
    ProblemError
        Naming the quantity and what to give instead.

    Examples
    --------
    >>> parse_real("0.1", what="a0"), parse_real("1/3", what="a0"), parse_real(0.25, what="a0")
    (1/10, 1/3, 1/4)
    >>> parse_real("nan", what="a0")
    Traceback (most recent call last):
    ...
    lindstedt._errors.ProblemError: a0 must be a finite real number such as 1, 0.5, '1/3' or 'sqrt(2)', got 'nan'
    """
    if isinstance(value, str):
        try:
            number = parse_expression(value, symbols={}, what=what)
        except ParameterError:
            raise ProblemError(f"{what} must be a finite real number such as 1, 0.5, '1/3' or 'sqrt(2)', got {value!r}") from None
    else:
        number = as_exact(value, what=what)
    if isinstance(number, sympy.Rational):  # exact, finite and real: its magnitude checked in integers
        numerator, denominator = abs(int(number.p)), int(number.q)
        if numerator and not (denominator <= numerator << 1074
                              and numerator * _LARGEST_MAGNITUDE.q <= _LARGEST_MAGNITUDE.p * denominator):
            raise ProblemError(_beyond_float(what, value))
        return number
    if not isinstance(number, sympy.Expr) or number.free_symbols or not number.is_number:
        raise ProblemError(f"{what} must be a finite real number such as 1, 0.5, '1/3' or 'sqrt(2)', got {value!r}")
    if number.has(sympy.zoo, sympy.oo, -sympy.oo, sympy.nan) or number.is_finite is False:
        raise ProblemError(f"{what} = {value!r} is not finite; give a finite real number")
    if number.is_real is not True:
        approximation = complex(sympy.N(number, 30))
        if number.is_real is False or approximation.imag != 0 or not math.isfinite(approximation.real):
            raise ProblemError(f"{what} = {value!r} is not a real number; give a finite real number")
    if number != 0:
        size = abs(number) if number.is_Rational else abs(sympy.N(number, 15))
        if not _SMALLEST_MAGNITUDE <= size <= _LARGEST_MAGNITUDE:
            raise ProblemError(_beyond_float(what, value))
    return number


def _beyond_float(what: str, value: Any) -> str:
    return (f"{what} = {value!r} is beyond the range of a float (magnitudes 5e-324 to 1.8e308), where the numerics "
            "and the float evaluators cannot follow; rescale the problem (choose units in which it is of order one)")


#: The magnitudes a number of a problem may have: those of a finite float, from the smallest subnormal to the
#: largest (beyond them no float evaluator, flow or export can hold it)
_SMALLEST_MAGNITUDE = sympy.Rational(1, 2**1074)
_LARGEST_MAGNITUDE = sympy.Rational(*sys.float_info.max.as_integer_ratio())


def parse_value(value: Any, *, name: str, symbol: sympy.Symbol) -> sympy.Expr:
    """A parameter's value: ``None``, its own name or a sympy Symbol keep it symbolic; anything else is a number.

    Examples
    --------
    >>> import sympy
    >>> c = sympy.Symbol("c", real=True)
    >>> parse_value(None, name="c", symbol=c), parse_value("2/7", name="c", symbol=c)
    (c, 2/7)
    """
    if value is None:
        return symbol
    if isinstance(value, sympy.Symbol):
        return value
    if isinstance(value, str) and value.strip() == name:
        return symbol
    return parse_real(value, what=name)


def parse_float(value: Any, *, what: str) -> float:
    """A finite real number as a float (the correctly rounded value of :func:`parse_real`).

    Examples
    --------
    >>> parse_float("1/3", what="epsilon"), parse_float(0.25, what="epsilon")
    (0.3333333333333333, 0.25)
    """
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        try:
            number = float(value)
        except OverflowError:
            raise ProblemError(f"{what} = {value!r} does not fit in a double; give a smaller number") from None
        if not math.isfinite(number):
            raise ProblemError(f"{what} = {value!r} is not finite; give a finite real number")
        return number
    with LOCK:  # sympy evaluates the number through mpmath (parse_floats calls this from lock-free evaluators)
        exact = parse_real(value, what=what)
        number = float(exact) if isinstance(exact, sympy.Rational) else float(sympy.N(exact, 20))
    if not math.isfinite(number):
        raise ProblemError(f"{what} = {value!r} does not fit in a double; give a smaller number")
    return number


def parse_floats(value: Any, *, what: str, scalar: bool = False) -> Any:
    """ε or t where the API is vectorised: a float or an int as it is (the fast path), an array (or list) of finite
    real numbers as a float array, anything else through :func:`parse_float` (exact strings such as ``"1/10"``).

    None, booleans, NaN, infinities, words and complex numbers are refused with a :class:`ParameterError`, and
    arrays too where ``scalar`` is true (one number).

    Examples
    --------
    >>> parse_floats(0.1, what="epsilon"), parse_floats("1/8", what="epsilon")
    (0.1, 0.125)
    >>> parse_floats([0.0, 0.5], what="t")
    array([0. , 0.5])
    >>> parse_floats(float("nan"), what="epsilon")
    Traceback (most recent call last):
    ...
    lindstedt._errors.ParameterError: epsilon = nan is not finite; give a finite real number
    """
    kind = type(value)
    if (kind is float or kind is np.float64) and math.isfinite(value):
        return value
    try:
        if isinstance(value, (np.ndarray, list, tuple)):
            if scalar and np.ndim(value):
                raise ParameterError(f"{what} must be one number here, got {type(value).__name__} of shape {np.shape(value)}")
            array = np.asarray(value)
            if array.dtype.kind in "fiu":
                array = array.astype(float, copy=False)
            elif array.dtype.kind in "OU" and array.size <= 10_000:
                array = np.vectorize(lambda item: parse_float(item, what=what), otypes=[float])(array)
            else:
                raise ParameterError(f"{what} must be real numbers, got an array of {array.dtype}")
            if not np.all(np.isfinite(array)):
                bad = array[~np.isfinite(array)].flat[0]
                raise ParameterError(f"{what} holds {bad}, which is not finite; give finite real numbers")
            return array
        if isinstance(value, np.generic):
            value = value.item()
        return parse_float(value, what=what)
    except ParameterError:
        raise
    except ProblemError as error:
        raise ParameterError(str(error)) from None


parse_number = parse_real  # transitional alias, removed once every caller is updated
