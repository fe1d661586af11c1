"""Generated code for Octave/MATLAB, Julia, Fortran, Rust and JAX (the targets of
:func:`lindstedt.export.codegen.generate_code` beyond NumPy and C).

The expressions — ω(ε), u(t; ε), or a gap coefficient ω_k(κ) by the stable series of
:mod:`lindstedt.compiled.stable_series` — are printed by sympy's printer of each language; this module writes
only the scaffolding around them (function header, element loop, if/else over the series' patches).
"""

from __future__ import annotations

import functools
from typing import Any

import sympy

from .._errors import CodeGenerationError
from ..compiled.names import _C_RESERVED, _PYTHON_RESERVED, _safe_names
from ..compiled.stable_series import Patch

# -- Octave/MATLAB, Julia, Fortran, Rust and JAX -------------------------------------------------------
#
# Every expression is printed by sympy's printer of the language (octave_code, julia_code, fcode, rust_code,
# JaxPrinter); only the scaffolding (function header, loop, if/else) is written here.  Octave and Fortran
# names cannot start with "_", so their internal names start with "lx_" instead, and an argument with such
# a name is renamed like a reserved word.

_MATH_NAMES = frozenset("sqrt cbrt exp log abs sign asin acos atan atan2 sin cos tan sinh cosh tanh max min mod".split())
_TARGETS = ("octave", "julia", "fortran", "rust", "jax")
_INTERNAL = ("output", "index", "x", "beta", "gamma", "delta", "free", "mask")
_OCTAVE_RESERVED = frozenset(
    """
    __FILE__ __LINE__ break case catch classdef continue do else elseif end end_try_catch end_unwind_protect
    endclassdef endenumeration endevents endfor endfunction endif endmethods endparfor endproperties endswitch
    endwhile enumeration events for function global if methods otherwise parfor persistent properties return
    switch try until unwind_protect unwind_protect_cleanup while spmd pi e Inf inf NaN nan NA i j I J eps true
    false zeros ones size numel nargin nargout ans
    """.split()
)
_JULIA_RESERVED = frozenset(
    """
    baremodule begin break catch const continue do else elseif end export false finally for function global if
    import let local macro module quote return struct true try using while abstract mutable primitive type where
    in isa outer public pi im Inf NaN Float64 Real zero one
    """.split()
)
_FORTRAN_RESERVED = frozenset(
    """
    function subroutine end if then else elseif endif result real integer double precision elemental pure
    implicit none intent in out inout do program module contains use call return kind parameter dble
    """.split()
)
_RUST_RESERVED = frozenset(
    """
    as break const continue crate else enum extern false fn for if impl in let loop match mod move mut pub ref
    return self Self static struct super trait true type unsafe use where while async await dyn abstract become
    box final macro override priv typeof unsized virtual yield try union f64
    """.split()
)


def _internal(language: str, name: str) -> str:
    return ("lx_" if language in ("octave", "fortran") else "_") + name


def _reserved(language: str) -> frozenset[str]:
    if language == "c":
        return _C_RESERVED
    if language == "numpy":
        return _PYTHON_RESERVED
    if language == "jax":
        return _PYTHON_RESERVED | {"jax"}
    functions = frozenset(str(name) for name in _printer(language).known_functions.values() if isinstance(name, str)) | _MATH_NAMES
    if language == "octave":
        return _OCTAVE_RESERVED | functions
    if language == "julia":
        return _JULIA_RESERVED | functions
    if language == "fortran":
        return frozenset(name.lower() for name in _FORTRAN_RESERVED | functions)
    return _RUST_RESERVED | frozenset(_printer(language).reserved_words)


def _renaming(arguments: list[sympy.Symbol], language: str) -> dict[sympy.Symbol, sympy.Symbol]:
    reserved = _reserved(language)
    fold = str.lower if language == "fortran" else str
    if language in ("octave", "fortran"):  # internal names lx_...: reserve every lx_ name an argument has
        reserved = reserved | {fold(a.name) for a in arguments if fold(a.name).startswith("lx_")}
    return _safe_names(arguments, reserved, fold)


def _printer(language: str) -> Any:
    """sympy's code printer of ``language`` (human=False: unsupported functions are reported, not commented)."""
    if language == "octave":
        from sympy.printing.octave import OctaveCodePrinter

        return OctaveCodePrinter({"human": False, "allow_unknown_functions": False})
    if language == "julia":
        from sympy.printing.julia import JuliaCodePrinter

        return JuliaCodePrinter({"human": False, "allow_unknown_functions": False})
    if language == "fortran":
        from sympy.printing.fortran import FCodePrinter

        return FCodePrinter({"human": False, "source_format": "free", "standard": 2003, "allow_unknown_functions": False})
    if language == "rust":
        return _rust_printer()
    from sympy.printing.numpy import JaxPrinter

    return JaxPrinter({"fully_qualified_modules": True, "allow_unknown_functions": False})


@functools.lru_cache(maxsize=1)
def _rust_printer_class() -> type:
    from sympy.printing.rust import RustCodePrinter

    class _RustPrinter(RustCodePrinter):
        """sympy's RustCodePrinter without its implicit integer-to-float casts.

        sympy 1.14 wraps the terms of a product or sum that mixes integers and floats in ``TypeCast``,
        which it then prints without parentheses (``x*(x + 1)`` -> ``x*x + 1.0``).  Every number
        handed to this printer is already a float (see :func:`_floated`), so the casts are not needed.
        """

        def _cast_to_float(self, expr: Any) -> Any:
            return expr

    return _RustPrinter


def _rust_printer() -> Any:
    return _rust_printer_class()({"human": False, "allow_unknown_functions": False})


def _floated(expression: sympy.Expr) -> sympy.Expr:
    """Every rational number of ``expression`` as a 25-digit float, except integer exponents (Rust has no
    implicit integer-to-float conversion: ``2*x`` does not compile for an f64 ``x``)."""
    if isinstance(expression, sympy.Rational):
        return sympy.Float(expression, 25)
    if not expression.args:
        return expression
    if isinstance(expression, sympy.Pow):
        exponent = expression.exp if expression.exp.is_Integer else _floated(expression.exp)
        return sympy.Pow(_floated(expression.base), exponent)
    return expression.func(*[_floated(a) for a in expression.args])


def _widened(value: float) -> sympy.Float:
    """A double as a 25-digit sympy Float with the same value (printers then print 17 digits: it round-trips)."""
    import mpmath

    return sympy.Float(mpmath.mpf(value), 25)


def _print(language: str, expression: Any, assign_to: str | None = None) -> str:
    """``expression`` printed by sympy's printer of ``language`` (optionally as an assignment)."""
    if isinstance(expression, sympy.Expr):
        expression = expression.xreplace({f: _widened(float(f)) for f in expression.atoms(sympy.Float) if f._prec < 60})
    if language == "rust":
        expression = _floated(expression)
    printer = _printer(language)
    if language == "jax":
        return printer.doprint(expression)
    if language == "fortran" and assign_to is not None:
        constants, unsupported, text = printer.doprint(expression, assign_to=assign_to)
    else:
        constants, unsupported, text = printer.doprint(expression)
    if constants or unsupported:
        missing = ", ".join(sorted(str(f) for f in unsupported)) or ", ".join(str(c) for c, _ in constants)
        raise CodeGenerationError(f"sympy's {language} printer cannot print {missing}; use language='numpy' or 'c'")
    if assign_to is not None and language != "fortran":
        return f"{assign_to} = {text}"
    return text


def _condition(x: sympy.Symbol, patch: Patch) -> Any:
    """The domain of ``patch`` as a sympy boolean (the δ-patch: strictly inside; NaN fails every comparison)."""
    if patch.name == "delta":
        return sympy.And(sympy.StrictGreaterThan(x, _widened(patch.lower)), sympy.StrictLessThan(x, _widened(patch.upper)))
    parts = []
    if patch.lower is not None:
        parts.append(sympy.GreaterThan(x, _widened(patch.lower)))
    if patch.upper is not None:
        parts.append(sympy.LessThan(x, _widened(patch.upper)))
    return parts[0] if len(parts) == 1 else sympy.And(*parts)


def _local_names(language: str, expressions: list[Any], exclude: set[str]) -> dict[sympy.Symbol, sympy.Symbol]:
    """Internal symbols (``_beta``, ``_common0``...) of ``expressions`` renamed to the language's internal prefix."""
    renaming = {}
    for expression in expressions:
        for symbol in expression.free_symbols:
            if symbol.name.startswith("_") and symbol.name not in exclude:
                renaming[symbol] = sympy.Symbol(_internal(language, symbol.name[1:]), real=True)
    return renaming


def _header(language: str, lines: list[str]) -> list[str]:
    mark = {"octave": "% ", "julia": "# ", "fortran": "! ", "rust": "// ", "jax": "# "}[language]
    return [(mark + line).rstrip() for line in lines]


def _target_source(
    language: str, name: str, arguments: list[sympy.Symbol], vector: sympy.Symbol, expression: sympy.Expr, accuracy: str
) -> str:
    """The closed form (after common-subexpression elimination) as one function of ``language``."""
    exclude = {a.name for a in arguments}
    prefix = _internal(language, "common")
    replacements, (reduced,) = sympy.cse(
        [expression], symbols=sympy.numbered_symbols(prefix, exclude=[sympy.Symbol(n) for n in exclude])
    )
    statements: list[Any] = [("let", str(symbol), value) for symbol, value in replacements]
    scalars = [a for a in arguments if a != vector]
    return _assemble(language, name, arguments, vector, scalars, statements, reduced, accuracy, vectorised_closed_form=True)


def _stable_target_source(
    language: str, name: str, epsilon: sympy.Symbol, x: sympy.Symbol, pieces: list, frequency: bool, accuracy: str
) -> str:
    """The piecewise exact series of :mod:`lindstedt.compiled.stable_series` as if/else (where-chains for JAX)."""
    statements: list[Any] = []
    targets = []
    for k, piece in pieces:
        target = _internal(language, f"omega{k}")
        targets.append(sympy.Symbol(target, real=True))
        if isinstance(piece, sympy.Expr):
            statements.append(("let", target, piece))
            continue
        cases = []
        for index, patch in enumerate(piece.patches):
            renaming = _local_names(language, [patch.value, *(v for _, v in patch.definitions)], {x.name})
            renaming.update({s: sympy.Symbol(_internal(language, s.name[1:]), real=True) for s, _ in patch.definitions})
            body = [("let", str(renaming.get(s, s)), v.xreplace(renaming)) for s, v in patch.definitions]
            body.append(("set", target, patch.value.xreplace(renaming)))
            last = index == len(piece.patches) - 1
            cases.append((None if last else _condition(x, patch), body, patch.comment))
        statements.append(("declare", target, None))
        statements.append(("if", target, cases))
    if frequency:
        total: sympy.Expr = sympy.Integer(0)
        for symbol in reversed(targets):
            total = symbol + epsilon * total if total != 0 else symbol
        arguments, vector, scalars = [epsilon, x], epsilon, [x]
    else:
        total, arguments, vector, scalars = targets[0], [x], x, []
    return _assemble(language, name, arguments, vector, scalars, statements, total, accuracy, vectorised_closed_form=frequency)


def _assemble(
    language: str,
    name: str,
    arguments: list[sympy.Symbol],
    vector: sympy.Symbol,
    scalars: list[sympy.Symbol],
    statements: list[Any],
    result: sympy.Expr,
    accuracy: str,
    vectorised_closed_form: bool,
) -> str:
    """Wrap ``statements`` (then ``result``) in a function of ``language``.

    ``statements`` are ``("let", name, value)`` (a new local), ``("declare", name, None)``, ``("set", name,
    value)`` and ``("if", target, [(condition or None, statements, comment), ...])``.  Octave evaluates the
    statements element by element in a loop when they branch on the vectorised argument, else vectorised.
    """
    names = ", ".join(a.name for a in arguments)
    branches_on_vector = any(s[0] == "if" for s in statements) and not vectorised_closed_form
    signature = {
        "octave": f"{_internal('octave', 'output')} = {name}({names})",
        "julia": f"{name}({names})",
        "fortran": f"elemental function {name}({names}) result({_internal('fortran', 'output')})",
        "rust": f"pub fn {name}({', '.join(f'{a.name}: f64' for a in arguments)}) -> f64",
        "jax": f"{name}({names})",
    }[language]
    usage = {
        "octave": f"elementwise over {vector} (any shape; the other arguments scalars), MATLAB and Octave",
        "julia": f"scalar Float64 arguments; broadcast over arrays with {name}.({names})",
        "fortran": "real(8) scalars; elemental, so it also maps over arrays of the same shape (Fortran 2003)",
        "rust": f"f64 scalars; map over a slice with xs.iter().map(|&{vector.name}| {name}(...))",
        "jax": f"vectorised over {vector} (jax.jit-able); needs float64: jax.config.update('jax_enable_x64', True)",
    }[language]
    header = _header(
        language,
        [f"Generated by lindstedt: {signature}", f"  {usage}.", *(f"  {line}" for line in _wrapped("Accuracy: " + accuracy))],
    )
    if language == "jax":
        return _assemble_jax(name, arguments, vector, statements, result, header)
    output = _internal(language, "output")
    lines: list[str] = []
    if language == "octave":
        lines = [f"function {signature}", *("  " + line for line in header)]
        body: list[str] = []
        if branches_on_vector:
            element = sympy.Symbol(_internal("octave", "x"), real=True)
            index = _internal("octave", "index")
            body.append(f"{output} = nan(size({vector}));")
            body.append(f"for {index} = 1:numel({vector})")
            body.append(f"  {element} = {vector}({index});")
            body.extend("  " + line for line in _statements("octave", statements, {vector: element}))
            body.append(f"  {output}({index}) = {_print('octave', result.xreplace({vector: element}))};")
            body.append("end")
        else:
            body.extend(_statements("octave", statements, {}))
            body.append(f"{output} = {_print('octave', result)} + 0*{vector};")
        lines.extend("  " + line for line in body)
        lines.append("end")
    elif language == "julia":
        lines = [*header, f"function {signature}"]
        lines.extend("    " + line for line in _statements("julia", statements, {}))
        lines.append(f"    return Float64({_print('julia', result)})")
        lines.append("end")
    elif language == "fortran":
        locals_ = sorted({s[1] for s in _flattened(statements) if s[0] in ("let", "declare")})
        lines = [*header, signature, "    implicit none"]
        lines.extend(f"    real(8), intent(in) :: {a.name}" for a in arguments)
        lines.append(f"    real(8) :: {output}")
        lines.extend(f"    real(8) :: {local}" for local in locals_)
        lines.extend("    " + line for line in _statements("fortran", statements, {}))
        lines.extend("    " + line for line in _print("fortran", result, output).splitlines())
        lines.append(f"end function {name}")
    else:
        lines = [*header, "#[allow(non_snake_case, unused_parens, clippy::all)]", f"{signature} {{"]
        lines.extend("    " + line for line in _statements("rust", statements, {}))
        lines.append(f"    {_print('rust', result)}")
        lines.append("}")
    return "\n".join(lines) + "\n"


def _flattened(statements: list[Any]) -> list[Any]:
    flat = []
    for statement in statements:
        flat.append(statement)
        if statement[0] == "if":
            for _, body, _ in statement[2]:
                flat.extend(_flattened(body))
    return flat


def _statements(language: str, statements: list[Any], substitution: dict) -> list[str]:
    """Lines of ``statements`` in ``language`` (expressions through sympy's printer)."""
    lines: list[str] = []
    end = {"octave": ";", "julia": "", "fortran": "", "rust": ";"}[language]
    for kind, target, value in statements:
        if kind == "declare":
            if language == "rust":
                lines.append(f"let {target}: f64;")
            continue
        if kind in ("let", "set"):
            text = _print(language, value.xreplace(substitution), target)
            if kind == "let" and language == "rust":
                text = "let " + text
            lines.extend(line + end if i == len(text.splitlines()) - 1 else line for i, line in enumerate(text.splitlines()))
            continue
        for index, (condition, body, comment) in enumerate(value):
            if condition is not None:
                condition = _print(language, condition.xreplace(substitution))
            note = {"octave": "% ", "julia": "# ", "fortran": "! ", "rust": "// "}[language] + comment
            if language == "rust":
                head = (f"if {condition} {{" if index == 0 else f"}} else if {condition} {{") if condition else "} else {"
            elif language == "fortran":
                head = (f"if ({condition}) then" if index == 0 else f"else if ({condition}) then") if condition else "else"
            else:
                head = (f"if {condition}" if index == 0 else f"elseif {condition}") if condition else "else"
            lines.append(f"{head}  {note}")
            lines.extend("    " + line for line in _statements(language, body, substitution))
        lines.append({"octave": "end", "julia": "end", "fortran": "end if", "rust": "}"}[language])
    return lines


def _assemble_jax(
    name: str, arguments: list[sympy.Symbol], vector: sympy.Symbol, statements: list[Any], result: sympy.Expr, header: list[str]
) -> str:
    lines = ["import jax", "import jax.numpy", "", "", f"def {name}({', '.join(a.name for a in arguments)}):"]
    lines.append(f'    """Generated by lindstedt: vectorised over {vector} (where-style branches)."""')
    lines.extend("    " + line for line in header)
    lines.append("    if not jax.config.jax_enable_x64:")
    lines.append("        raise RuntimeError(\"float64 is needed: call jax.config.update('jax_enable_x64', True) first\")")
    lines.append(f"    {vector} = jax.numpy.asarray({vector}, dtype=jax.numpy.float64)")
    for kind, target, value in statements:
        if kind == "let":
            lines.append(f"    {target} = {_print('jax', value)}")
        elif kind == "if":
            # the same priority as the if/else chain: the first matching patch wins, the last one is the rest
            cases = value
            for condition, body, comment in reversed(cases):
                lines.append(f"    # {comment}")
                for local_kind, local, local_value in body:
                    text = _print("jax", local_value)
                    lines.append(f"    {local if local_kind == 'let' else '_value'} = {text}")
                if condition is None:
                    lines.append(f"    {target} = _value")
                else:
                    lines.append(f"    {target} = jax.numpy.where({_print('jax', condition)}, _value, {target})")
    lines.append(f"    return {_print('jax', result)} + 0.0 * {vector}")
    return "\n".join(lines) + "\n"


def _wrapped(text: str, width: int = 100) -> list[str]:
    import textwrap

    return textwrap.wrap(text, width)
