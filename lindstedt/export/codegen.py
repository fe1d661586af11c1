"""Code generation for expansions of u'' + ω0² u + ε f(u) = 0 through sympy's printers.

Targets: NumPy, C, Octave/MATLAB, Julia, Fortran (2003, free form), Rust and JAX; every expression is
printed by sympy's printer of the language, the stable gap series as if/elseif/else (where-chains in
JAX).  Octave code is elementwise over its first argument; Julia, Fortran (``elemental``) and Rust
functions take scalars; the header of each source states the signature and the accuracy.

Two quantities can be generated for any :class:`~lindstedt.Expansion`:

``"frequency"``
    ω(ε; parameters) = Σ_{k≤N} ω_k ε^k, vectorised over ε;
``"displacement"``
    u(t; ε, parameters) = Σ_{k≤N} ε^k v_k(ω t) (frequency through ω_{N+1}),
    vectorised over t;
``"omega<k>"`` (e.g. ``"omega2"``)
    the coefficient ω_k(parameters) alone, vectorised over the first free
    symbol (e.g. ω_2(κ) over an array of gaps).

Accuracy.  When the expansion's one free symbol is a gap κ (f = (u − κ)_+, a0 = 1: ω_k is a closed form
in κ, acos κ and sqrt(1 − κ²)), ``"omega<k>"`` and ``"frequency"`` are not printed from the closed form,
which cancels catastrophically near κ = ±1 (ω_2 ∝ (1 − κ)^(5/2) from O(1) terms), but as piecewise exact
series in acos κ (see :mod:`lindstedt.export.stable`): relative error ≤ 1e-13 for every κ in
(−1, 1).  :attr:`GeneratedCode.accuracy` states the guarantee, or its absence, for every generated function.

Otherwise the expression is reduced by common-subexpression elimination (``sympy.cse``)
and printed by ``NumPyPrinter`` or ``C99CodePrinter``.  C code is a loop over
an array (``void f(const double *x, double *out, long n, double p1, ...)``);
:meth:`GeneratedCode.compile` builds it with the system C compiler and loads it
with ctypes, so round trips against the exact evaluators are testable.

Names.  Internal names of the generated code start with ``_`` (``_input``,
``_index``, ``_common0``...), which a lindstedt parameter name never does.
An argument whose name is reserved in the target language (a C keyword or a
name from ``<math.h>`` such as ``double``, ``y0``, ``gamma``, ``NAN``; a Python
keyword or builtin or ``numpy``) gets ``_`` appended until it is free, e.g.
``double_``; :attr:`GeneratedCode.arguments` lists the names as in the source.

Compiled C code is cached per user, see :func:`_compile_c`.
"""

from __future__ import annotations

import builtins
import contextlib
import ctypes
import functools
import hashlib
import keyword
import os
import shutil
import stat
import subprocess
import tempfile
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
import sympy
from sympy.printing.c import C99CodePrinter
from sympy.printing.numpy import NumPyPrinter

from .._errors import LindstedtError, ProblemError
from .stable import SERIES_TARGET, Patch, StableCoefficient, stable_coefficient

__all__ = ["GeneratedCode", "generate_code", "stable_function"]

_LANGUAGES = ("numpy", "c", "octave", "julia", "fortran", "rust", "jax")
_QUANTITIES = ("frequency", "displacement")

# C names an argument must not take: keywords (C99, plus GNU and C23 ones), everything <math.h> declares
# (functions with their f/l variants, macros, types) and common libc or predefined macros.
_C_MATH_FUNCTIONS = """
    acos acosh asin asinh atan atan2 atanh cbrt ceil copysign cos cosh drem erf erfc exp exp10 exp2 expm1 fabs
    fdim finite floor fma fmax fmin fmod frexp gamma hypot ilogb isinf isnan j0 j1 jn ldexp lgamma llrint llround
    log log10 log1p log2 logb lrint lround modf nan nearbyint nextafter nexttoward pow pow10 remainder remquo rint
    round scalb scalbln scalbn significand sin sincos sinh sqrt tan tanh tgamma trunc y0 y1 yn
""".split()
_C_RESERVED = frozenset(
    """
    auto break case char const continue default do double else enum extern float for goto if inline int long
    register restrict return short signed sizeof static struct switch typedef union unsigned void volatile while
    asm typeof alignas alignof bool constexpr false nullptr static_assert thread_local true typeof_unqual
    lgamma_r lgammaf_r lgammal_r float_t double_t signgam math_errhandling MATH_ERRNO MATH_ERREXCEPT
    HUGE_VAL HUGE_VALF HUGE_VALL INFINITY NAN FP_INFINITE FP_NAN FP_NORMAL FP_SUBNORMAL FP_ZERO FP_FAST_FMA
    FP_FAST_FMAF FP_FAST_FMAL FP_ILOGB0 FP_ILOGBNAN fpclassify isfinite isnormal signbit isgreater isgreaterequal
    isless islessequal islessgreater isunordered M_E M_LOG2E M_LOG10E M_LN2 M_LN10 M_PI M_PI_2 M_PI_4 M_1_PI
    M_2_PI M_2_SQRTPI M_SQRT2 M_SQRT1_2 errno index rindex assert NULL EOF EDOM ERANGE EILSEQ offsetof stdin
    stdout stderr complex imaginary I linux unix i386
    """.split()
    + [name + suffix for name in _C_MATH_FUNCTIONS for suffix in ("", "f", "l")]
) | frozenset(C99CodePrinter().reserved_words)
_PYTHON_RESERVED = frozenset([*keyword.kwlist, *keyword.softkwlist, *dir(builtins), "numpy"]) | frozenset(
    NumPyPrinter().reserved_words
)


class CodeGenerationError(LindstedtError):
    """The generated code could not be generated, compiled or loaded (e.g. an unknown target language)."""


class UnknownLanguageError(CodeGenerationError, ValueError):
    """``language`` is not one of the supported targets (also a ``ValueError``, as before)."""


def _check_language(language: Any) -> None:
    if language not in _LANGUAGES:
        raise UnknownLanguageError(
            f"language must be one of {', '.join(repr(name) for name in _LANGUAGES)}, got {language!r}"
        )


@dataclass(frozen=True)
class GeneratedCode:
    """Source code of one quantity in one language, with its calling convention.

    Attributes
    ----------
    language : {"numpy", "c", "octave", "julia", "fortran", "rust", "jax"}
    quantity : {"frequency", "displacement", "omega<k>"}
    function_name : str
    arguments : tuple of str
        Vectorised argument first (``epsilon`` or ``t``), then the scalars, named as
        in ``source`` (a name reserved in the language has ``_`` appended).
    source : str
    accuracy : str
        The accuracy guaranteed for float64 evaluation, and where it was validated.  For ``"omega<k>"``
        and ``"frequency"`` of an expansion whose one free symbol is a gap κ (f = (u − κ)_+ with
        a0 = 1): relative error ≤ 1e-13 for every κ in (−1, 1), by exact series near κ = ±1 and at
        interior roots (see :func:`generate_code`); otherwise the closed form is printed as it is and
        the text says that no bound is claimed (cancellation in it can cost digits).
    """

    language: str
    quantity: str
    function_name: str
    arguments: tuple[str, ...]
    source: str
    accuracy: str = "not analysed: the expression is printed as it is"

    def compile(self) -> Callable[..., np.ndarray]:
        """A Python callable running the generated code (C is built with ``cc``).

        Examples
        --------
        >>> import lindstedt
        >>> code = lindstedt.generate_code(lindstedt.expand("u**3", order=2, a0=1, omega0=1), "frequency")
        >>> float(code.compile()(0.1))
        1.0366796875
        """
        if self.language in ("numpy", "jax"):
            namespace: dict[str, Any] = {"numpy": np}
            exec(compile(self.source, f"<lindstedt {self.function_name}>", "exec"), namespace)  # noqa: S102 - our own generated source
            return namespace[self.function_name]
        if self.language != "c":
            raise CodeGenerationError(
                f"compile() runs numpy, jax and C code only; compile this {self.language} source with its own toolchain"
            )
        return _compile_c(self)


def _numpy_source(name: str, arguments: list[sympy.Symbol], vector: sympy.Symbol, expression: sympy.Expr) -> str:
    printer = NumPyPrinter({"fully_qualified_modules": True, "allow_unknown_functions": False})
    replacements, (reduced,) = sympy.cse([expression], symbols=sympy.numbered_symbols("_common"))
    lines = [f"def {name}({', '.join(str(a) for a in arguments)}):"]
    lines.append(f'    """Generated by lindstedt: vectorised over {vector}."""')
    lines.append(f"    {vector} = numpy.asarray({vector}, dtype=float)")
    for symbol, value in replacements:
        lines.append(f"    {symbol} = {printer.doprint(value)}")
    lines.append(f"    return {printer.doprint(reduced)} + 0.0 * {vector}")
    return "\n".join(lines) + "\n"


def _c_source(name: str, arguments: list[sympy.Symbol], vector: sympy.Symbol, expression: sympy.Expr) -> str:
    printer = C99CodePrinter()
    replacements, (reduced,) = sympy.cse([expression], symbols=sympy.numbered_symbols("_common"))
    scalars = [a for a in arguments if a != vector]
    signature = ", ".join(["const double *_input", "double *_output", "long _count"] + [f"double {a}" for a in scalars])
    lines = ["#include <math.h>", "", f"/* Generated by lindstedt: _output[i] = quantity({vector} = _input[i]). */"]
    lines.append(f"void {name}({signature}) {{")
    lines.append("    for (long _index = 0; _index < _count; ++_index) {")
    lines.append(f"        const double {vector} = _input[_index];")
    for symbol, value in replacements:
        lines.append(f"        const double {symbol} = {printer.doprint(value)};")
    lines.append(f"        _output[_index] = {printer.doprint(reduced)};")
    lines.append("    }")
    lines.append("}")
    return "\n".join(lines) + "\n"


def _safe_names(
    arguments: list[sympy.Symbol], reserved: frozenset[str], fold: Callable[[str], str] = str
) -> dict[sympy.Symbol, sympy.Symbol]:
    """Map each argument to a symbol whose name is not in ``reserved`` nor taken by another argument.

    Free names are kept; the others get ``_`` appended until they are free
    (``double`` -> ``double_``, or ``double__`` if ``double_`` is an argument too).  Names are compared
    after ``fold`` (``str.lower`` for Fortran, whose names are case-insensitive).
    """
    if len(set(arguments)) != len(arguments):
        twice = sorted({str(a) for a in arguments if arguments.count(a) > 1})
        raise CodeGenerationError(
            f"the argument(s) {', '.join(twice)} occur twice (a parameter has the name of the expansion "
            "variable epsilon or t); rename the parameter"
        )
    taken: set[str] = set()
    names: dict[sympy.Symbol, str] = {}
    for symbol in arguments:
        if fold(symbol.name) not in reserved and fold(symbol.name) not in taken:
            names[symbol] = symbol.name
            taken.add(fold(symbol.name))
    for symbol in arguments:
        if symbol not in names:
            name = symbol.name
            while fold(name) in reserved or fold(name) in taken:
                name += "_"
            names[symbol] = name
            taken.add(fold(name))
    return {s: s if n == s.name else sympy.Symbol(n, **s.assumptions0) for s, n in names.items()}


def _generated(
    language: str, quantity: str, arguments: list[sympy.Symbol], vector: sympy.Symbol, expression: sympy.Expr, accuracy: str
) -> GeneratedCode:
    renaming = _renaming(arguments, language)
    arguments = [renaming[a] for a in arguments]
    vector, expression = renaming[vector], expression.xreplace(renaming)
    name = f"lindstedt_{quantity}"
    if language in _TARGETS:
        source = _target_source(language, name, arguments, vector, expression, accuracy)
    else:
        source = (_numpy_source if language == "numpy" else _c_source)(name, arguments, vector, expression)
    return GeneratedCode(language, quantity, name, tuple(a.name for a in arguments), source, accuracy)


def generate_code(expansion: Any, quantity: str = "frequency", language: str = "numpy") -> GeneratedCode:
    """Generate code for ``quantity`` of ``expansion`` in ``language``.

    Parameters
    ----------
    expansion : Expansion
    quantity : {"frequency", "displacement", "omega<k>"}
    language : {"numpy", "c", "octave", "julia", "fortran", "rust", "jax"}
        Any other value raises :class:`CodeGenerationError` (also a ``ValueError``) naming these.
        :meth:`GeneratedCode.compile` runs NumPy, JAX and C code; the others are for their own toolchains.

    Returns
    -------
    GeneratedCode
        Arguments: ``(epsilon, *expansion.arguments)`` for the frequency,
        ``(t, epsilon, *expansion.arguments)`` for the displacement; a name
        reserved in ``language`` gets ``_`` appended (``lambda`` -> ``lambda_``).

    Examples
    --------
    >>> import lindstedt
    >>> code = lindstedt.generate_code(lindstedt.expand("u**3", order=1), "frequency", "c")
    >>> code.arguments
    ('epsilon', 'a0', 'omega0')
    """
    from ..results.expansion import EPSILON, TIME, Expansion
    from ..results.nnm import NNMExpansion

    if isinstance(expansion, NNMExpansion):  # numeric coefficients, no free parameters
        return _nnm_code(expansion, quantity, language)
    if not isinstance(expansion, Expansion):
        raise ProblemError(f"generate_code takes an Expansion (lindstedt.expand) or an NNMExpansion (lindstedt.nnm), got {type(expansion).__name__}")
    coefficient = _coefficient_index(quantity)
    if quantity not in _QUANTITIES and coefficient is None:
        raise ProblemError(f"quantity must be one of {_QUANTITIES} or 'omega<k>' (e.g. 'omega2')")
    _check_language(language)

    parameters = list(expansion.arguments)
    if coefficient is not None and not parameters:
        raise ProblemError(f"{quantity} of this expansion is a constant ({expansion.omega_correction(coefficient)}); nothing to vectorise")
    stable = _stable_code(expansion, quantity, coefficient, language, parameters)
    if stable is not None:
        return stable
    if coefficient is not None:
        # A single coefficient is worth simplifying once (e.g. ω_2(κ) shrinks several-fold).
        vector = parameters[0]
        expression = _horner_form(sympy.simplify(expansion.omega_correction(coefficient)), vector)
        arguments = parameters
    elif quantity == "frequency":
        vector, expression = EPSILON, _horner_form(expansion.frequency_expr(), EPSILON)
        arguments = [EPSILON, *parameters]
    else:
        vector, expression = TIME, expansion.displacement_expr()
        arguments = [TIME, EPSILON, *parameters]
    # Exact constants (π, acos(1/3), big rationals) become 25-digit floats: compact code, no accuracy lost in doubles.
    expression = expression.evalf(25)
    return _generated(language, quantity, arguments, vector, expression, _UNANALYSED)


_UNANALYSED = (
    "not analysed: the closed form is printed as it is (Horner form, 25-digit constants), so float64 rounding "
    "is amplified by any cancellation in it (e.g. a gap near ±a0 can cost all digits); no bound is claimed"
)


def _stable_code(expansion: Any, quantity: str, coefficient: int | None, language: str, parameters: list) -> GeneratedCode | None:
    """Piecewise-series code for ω_k(κ) or ω(ε; κ) if the one free symbol κ is a gap, else None."""
    from ..results.expansion import EPSILON

    if len(parameters) != 1 or quantity == "displacement":
        return None
    x = parameters[0]
    if coefficient is not None:
        orders = [coefficient]
    else:
        if getattr(expansion, "gauge", None) != EPSILON or expansion.frequency_expr() != sympy.Add(
            *[expansion.omega_correction(k) * EPSILON**k for k in range(expansion.order + 1)]
        ):
            return None
        orders = list(range(expansion.order + 1))
    pieces: list[tuple[int, sympy.Expr | StableCoefficient]] = []
    for k in orders:
        value = expansion.omega_correction(k)
        if not value.has(x):
            if coefficient is not None:
                return None
            pieces.append((k, value))
            continue
        stable = _stable_coefficient_cached(value, x)
        if stable is None:
            return None
        pieces.append((k, stable))
    renaming = _renaming([x] if coefficient is not None else [EPSILON, x], language)
    x = renaming[x]
    pieces = [(k, p.evalf(25) if isinstance(p, sympy.Expr) else _renamed(p, parameters[0], x)) for k, p in pieces]
    error = max(p.error_estimate for _, p in pieces if isinstance(p, StableCoefficient))
    details = " | ".join(f"omega{k}: {p.summary}" for k, p in pieces if isinstance(p, StableCoefficient))
    if coefficient is not None:
        accuracy = (
            f"relative error <= 1e-13 for every {x} in (-1, 1) in float64 (validated at generation: series "
            f"truncation <= {SERIES_TARGET:g}, float64 rounding measured <= {error:.1e}; tested at "
            f"{x} = ±(1 - 10^-p), p = 1..14, and random {x}); outside [-1, 1] the result is NaN. {details}"
        )
    else:
        accuracy = (
            f"each omega_k({x}) with relative error <= 1e-13 for every {x} in (-1, 1) (float64; series truncation <= "
            f"{SERIES_TARGET:g}, rounding measured <= {error:.1e}), so omega(epsilon; {x}) has relative error "
            f"<= 1e-13 * sum_k |omega_k epsilon^k| / |omega| (<= 2e-13 while the series converges, "
            f"sum_k>=1 |omega_k epsilon^k| <= |omega0|); outside [-1, 1] the result is NaN. {details}"
        )
    name = f"lindstedt_{quantity}"
    if language in _TARGETS:
        source = _stable_target_source(language, name, renaming.get(EPSILON, EPSILON), x, pieces, coefficient is None, accuracy)
    else:
        source = (_stable_numpy_source if language == "numpy" else _stable_c_source)(name, x, pieces, coefficient is None, accuracy)
    arguments = (x.name,) if coefficient is not None else (renaming[EPSILON].name, x.name)
    return GeneratedCode(language, quantity, name, arguments, source, accuracy)


def _renamed(stable: StableCoefficient, old: sympy.Symbol, new: sympy.Symbol) -> StableCoefficient:
    if old == new:
        return stable
    patches = tuple(
        Patch(p.name, p.lower, p.upper, tuple((s, e.xreplace({old: new})) for s, e in p.definitions), p.value, p.comment)
        for p in stable.patches
    )
    return StableCoefficient(patches, stable.error_estimate, stable.summary)


def _conditions(x: str, patch: Patch, language: str) -> str:
    both = " & " if language == "numpy" else " && "
    parts = []
    if patch.name == "delta":  # the rest: strictly inside the switch points (NaN fails every comparison)
        parts = [f"({x} > {patch.lower!r})", f"({x} < {patch.upper!r})"]
    else:
        if patch.lower is not None:
            parts.append(f"({x} >= {patch.lower!r})")
        if patch.upper is not None:
            parts.append(f"({x} <= {patch.upper!r})")
    return both.join(parts)


def _stable_numpy_source(name: str, x: sympy.Symbol, pieces: list, frequency: bool, accuracy: str) -> str:
    printer = NumPyPrinter({"fully_qualified_modules": True, "allow_unknown_functions": False})
    subset = sympy.Symbol("_x", real=True)
    arguments = ["epsilon", x.name] if frequency else [x.name]
    lines = [f"def {name}({', '.join(arguments)}):"]
    lines.append(f'    """Generated by lindstedt: vectorised over {arguments[0]}; piecewise exact series in {x}."""')
    lines.extend(f"    # {line}" for line in _wrapped(accuracy))
    if frequency:
        lines.append("    epsilon = numpy.asarray(epsilon, dtype=float)")
    lines.append(f"    {x} = numpy.asarray({x}, dtype=float)")
    targets = []
    for k, piece in pieces:
        target = f"_omega{k}" if frequency else "_output"
        targets.append(sympy.Symbol(target))
        if isinstance(piece, sympy.Expr):
            lines.append(f"    {target} = {printer.doprint(piece)}")
            continue
        lines.append(f"    {target} = numpy.full({x}.shape, numpy.nan)")
        lines.append(f"    _free = numpy.ones({x}.shape, dtype=bool)")
        for patch in piece.patches:
            lines.append(f"    # {patch.comment}")
            lines.append(f"    _mask = _free & {_conditions(str(x), patch, 'numpy')}")
            lines.append("    _free &= ~_mask")
            lines.append(f"    _x = {x}[_mask]")
            for symbol, value in patch.definitions:
                lines.append(f"    {symbol} = {printer.doprint(value.xreplace({x: subset}))}")
            lines.append(f"    {target}[_mask] = {printer.doprint(patch.value)}")
    if frequency:
        epsilon = sympy.Symbol("epsilon")
        total = sympy.Integer(0)
        for symbol in reversed(targets):
            total = symbol + epsilon * total if total != 0 else symbol
        lines.append(f"    return {printer.doprint(total)} + 0.0 * epsilon")
    else:
        lines.append("    return _output[()]")
    return "\n".join(lines) + "\n"


def _stable_c_source(name: str, x: sympy.Symbol, pieces: list, frequency: bool, accuracy: str) -> str:
    printer = C99CodePrinter()
    lines = ["#include <math.h>", ""]
    vector = "epsilon" if frequency else str(x)
    lines.append(f"/* Generated by lindstedt: _output[i] = quantity({vector} = _input[i]); piecewise exact series in {x}.")
    lines.extend(f"   {line}" for line in _wrapped(accuracy))
    lines.append("*/")
    signature = "const double *_input, double *_output, long _count" + (f", double {x}" if frequency else "")
    lines.append(f"void {name}({signature}) {{")
    indent = "    " if frequency else "        "
    body: list[str] = []
    targets = []
    for k, piece in pieces:
        target = f"_omega{k}"
        targets.append(sympy.Symbol(target))
        if isinstance(piece, sympy.Expr):
            body.append(f"{indent}const double {target} = {printer.doprint(piece)};")
            continue
        body.append(f"{indent}double {target};")
        for index, patch in enumerate(piece.patches):
            last = index == len(piece.patches) - 1
            head = "else {" if last and index else "{" if last else ("if" if index == 0 else "else if") + f" ({_conditions(str(x), patch, 'c')}) {{"
            body.append(f"{indent}{head}  /* {patch.comment.replace('*/', '* /')} */")
            for symbol, value in patch.definitions:
                body.append(f"{indent}    const double {symbol} = {printer.doprint(value)};")
            body.append(f"{indent}    {target} = {printer.doprint(patch.value)};")
            body.append(f"{indent}}}")
    if frequency:
        epsilon = sympy.Symbol("epsilon")
        total = sympy.Integer(0)
        for symbol in reversed(targets):
            total = symbol + epsilon * total if total != 0 else symbol
        lines.extend(body)
        lines.append("    for (long _index = 0; _index < _count; ++_index) {")
        lines.append("        const double epsilon = _input[_index];")
        lines.append(f"        _output[_index] = {printer.doprint(total)};")
    else:
        lines.append("    for (long _index = 0; _index < _count; ++_index) {")
        lines.append(f"        const double {x} = _input[_index];")
        lines.extend(body)
        lines.append(f"        _output[_index] = {targets[0]};")
    lines.append("    }")
    lines.append("}")
    return "\n".join(lines) + "\n"


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
    """The piecewise exact series of :mod:`lindstedt.export.stable` as if/else (where-chains for JAX)."""
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


def stable_function(expression: sympy.Expr, symbol: sympy.Symbol) -> Callable[[Any], np.ndarray] | None:
    """A vectorised NumPy function of ``symbol`` evaluating ``expression`` (a gap coefficient ω_k(κ)) by the piecewise
    exact series of :mod:`lindstedt.export.stable` (relative error <= 1e-13 on (-1, 1), NaN outside), or None if
    the expression has another shape.  The same code as ``generate_code(expansion, "omega<k>")`` prints; the
    series are generated once per expression (cached, 0.1-0.5 s).

    Examples
    --------
    >>> import lindstedt, numpy as np
    >>> e = lindstedt.expand("Max(0, u - kappa)", order=1, a0=1, omega0=1, params={"kappa": None})
    >>> omega1 = stable_function(e.omega_correction(1), e.arguments[0])
    >>> float(omega1(np.array(0.0)))      # 1/4 at kappa = 0
    0.25
    """
    stable = _stable_coefficient_cached(expression, symbol)
    if stable is None:
        return None
    renaming = _safe_names([symbol], _PYTHON_RESERVED)
    name = renaming[symbol]
    source = _stable_numpy_source("lindstedt_stable", name, [(0, _renamed(stable, symbol, name))], False, stable.summary)
    namespace: dict[str, Any] = {"numpy": np}
    exec(compile(source, "<lindstedt stable series>", "exec"), namespace)  # noqa: S102 - our own generated source
    return namespace["lindstedt_stable"]


@functools.lru_cache(maxsize=32)
def _stable_coefficient_cached(expression: sympy.Expr, x: sympy.Symbol) -> StableCoefficient | None:
    return stable_coefficient(expression, x)


def _horner_form(expression: sympy.Expr, variable: sympy.Symbol) -> sympy.Expr:
    """Horner scheme in ``variable`` and in the transcendental atoms that depend on it.

    ω_k(κ) is a polynomial in κ, acos κ and sqrt(1 − κ²) over a constant
    denominator; nesting it (Horner) halves the operation count and avoids
    slow general powers in vectorised code.  Anything else is returned as is.
    """
    atoms = sorted(
        (
            atom
            for atom in expression.atoms(sympy.Function, sympy.Pow)
            if atom.has(variable) and not (isinstance(atom, sympy.Pow) and atom.exp.is_Integer)
        ),
        key=sympy.default_sort_key,
    )
    placeholders = [sympy.Dummy(f"atom{index}") for index in range(len(atoms))]
    replaced = expression.xreplace(dict(zip(atoms, placeholders)))
    if any(other.has(variable) for other in placeholders) or replaced.has(*atoms):
        return expression
    numerator, denominator = sympy.fraction(sympy.together(replaced))
    generators = [variable, *placeholders]
    try:
        if denominator.has(*generators):
            return expression
        nested = sympy.horner(sympy.Poly(sympy.expand(numerator), *generators)) / denominator
    except sympy.PolynomialError:
        return expression
    return nested.xreplace(dict(zip(placeholders, atoms)))


def _nnm_code(result: Any, quantity: str, language: str) -> GeneratedCode:
    from ..results.expansion import EPSILON

    if quantity != "frequency":
        raise ProblemError(
            "for an N-dof NNM only quantity='frequency' is generated (its waveform is vector valued: "
            "use NNMExpansion.displacement)"
        )
    _check_language(language)
    digits = result.digits
    expression = sympy.Add(*[sympy.Float(str(value), digits) * EPSILON**n for n, value in enumerate(result.omega)])
    accuracy = (
        f"the numeric coefficients ({digits} digits) of the polynomial in epsilon, evaluated by Horner's rule: "
        "a few ulps where the terms do not cancel (small epsilon)"
    )
    return _generated(language, quantity, [EPSILON], EPSILON, _horner_form(expression, EPSILON), accuracy)


def _coefficient_index(quantity: str) -> int | None:
    if quantity.startswith("omega") and quantity[5:].isdigit():
        return int(quantity[5:])
    return None


def _cache_directory() -> str:
    """The private per-user cache directory, created (mode 0o700) and checked."""
    directory = os.environ.get("LINDSTEDT_CACHE_DIR")
    if not directory:
        base = os.environ.get("XDG_CACHE_HOME")
        if not base or not os.path.isabs(base):
            base = os.path.join(os.path.expanduser("~"), ".cache")
        directory = os.path.join(base, "lindstedt", "codegen")
    try:
        os.makedirs(directory, mode=0o700, exist_ok=True)
        status = os.stat(directory)
    except OSError as error:
        raise CodeGenerationError(
            f"cannot create the code cache directory {directory}: {error}; set LINDSTEDT_CACHE_DIR to a writable directory"
        ) from None
    if hasattr(os, "getuid"):
        fix = f"run 'chmod 700 {directory}' if it is yours, or set LINDSTEDT_CACHE_DIR to a private directory"
        if not stat.S_ISDIR(status.st_mode):
            raise CodeGenerationError(f"the code cache {directory} is not a directory; set LINDSTEDT_CACHE_DIR to a private directory")
        if status.st_uid != os.getuid():
            raise CodeGenerationError(
                f"the code cache directory {directory} belongs to uid {status.st_uid}, not to you (uid {os.getuid()}), "
                "so compiled code in it is not loaded; set LINDSTEDT_CACHE_DIR to a directory of your own"
            )
        if status.st_mode & 0o077:
            raise CodeGenerationError(
                f"the code cache directory {directory} is accessible to other users (mode {stat.S_IMODE(status.st_mode):o}), "
                f"so compiled code in it is not loaded; {fix}"
            )
    return directory


def _write_atomically(path: str, data: bytes) -> None:
    """Write ``data`` to a temporary file next to ``path`` (mode 0o600), then rename it onto ``path``."""
    handle, temporary = tempfile.mkstemp(prefix=".partial-", dir=os.path.dirname(path))
    try:
        with os.fdopen(handle, "wb") as stream:
            stream.write(data)
        os.replace(temporary, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(temporary)
        raise


def _file_digest(path: str) -> str:
    with open(path, "rb") as stream:
        return hashlib.sha256(stream.read()).hexdigest()


def _trusted(library_path: str, record_path: str) -> bool:
    """True if the library and its SHA-256 record are our own regular files and the hash matches."""
    try:
        for path in (library_path, record_path):
            status = os.lstat(path)
            if not stat.S_ISREG(status.st_mode):
                return False
            if hasattr(os, "getuid") and (status.st_uid != os.getuid() or status.st_mode & 0o022):
                return False
        with open(record_path, encoding="ascii") as stream:
            recorded = stream.read().strip()
        return recorded == _file_digest(library_path)
    except (OSError, ValueError):
        return False


def _build(compiler: str, source: str, stem: str) -> None:
    """Compile ``source`` to ``stem.so`` and record its SHA-256 in ``stem.so.sha256``, both atomically."""
    source_path = stem + ".c"
    _write_atomically(source_path, source.encode())
    handle, temporary = tempfile.mkstemp(prefix=".partial-", suffix=".so", dir=os.path.dirname(stem))
    os.close(handle)
    try:
        result = subprocess.run(
            [compiler, "-O2", "-shared", "-fPIC", "-o", temporary, source_path, "-lm"],
            capture_output=True,
            text=True,
            check=False,
        )
        if result.returncode != 0:
            raise CodeGenerationError(f"the C compiler failed:\n{result.stderr}")
        os.chmod(temporary, 0o700)
        digest = _file_digest(temporary)
        os.replace(temporary, stem + ".so")
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(temporary)
        raise
    _write_atomically(stem + ".so.sha256", f"{digest}\n".encode())


def _compile_c(code: GeneratedCode) -> Callable[..., np.ndarray]:
    """Build (or reuse) the shared library of ``code`` and wrap its function.

    Guarantees: the library lives in a per-user cache directory
    (``$LINDSTEDT_CACHE_DIR``, else ``$XDG_CACHE_HOME/lindstedt/codegen``, else
    ``~/.cache/lindstedt/codegen``), created with mode 0o700; on POSIX it is used only if
    it is owned by the current user and has no group/other permissions
    (:class:`CodeGenerationError` otherwise).  Files are written to temporary names in
    that directory and renamed into place, so no reader ever sees a partial file.
    ``<function>-<sha256 of source>.so`` is loaded only if it is a regular file owned by the
    user, not writable by others, and its SHA-256 equals the one in
    ``<function>-<sha256 of source>.so.sha256``; otherwise (or if ctypes cannot load it)
    both are deleted and the library is rebuilt once.
    """
    compiler = shutil.which("cc") or shutil.which("gcc")
    if compiler is None:
        raise CodeGenerationError("no C compiler (cc or gcc) on PATH; install one or use language='numpy'")
    digest = hashlib.sha256(code.source.encode()).hexdigest()
    stem = os.path.join(_cache_directory(), f"{code.function_name}-{digest}")
    library_path, record_path = stem + ".so", stem + ".so.sha256"
    problem = ""
    for rebuild in (False, True):
        if rebuild:
            for path in (library_path, record_path):
                with contextlib.suppress(FileNotFoundError):
                    os.unlink(path)
            _build(compiler, code.source, stem)
        if not _trusted(library_path, record_path):
            problem = f"{library_path} does not match its SHA-256 record {record_path}"
            continue
        try:
            library = ctypes.CDLL(library_path)
            break
        except OSError as error:
            problem = f"ctypes cannot load {library_path}: {error}"
    else:
        raise CodeGenerationError(f"{problem} even after a rebuild; delete the directory and retry")
    function = getattr(library, code.function_name)
    scalar_count = len(code.arguments) - 1
    function.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_long] + [ctypes.c_double] * scalar_count
    function.restype = None

    def call(vector: Any, *scalars: float) -> np.ndarray:
        if len(scalars) != scalar_count:
            raise TypeError(f"expected {scalar_count} scalar arguments {code.arguments[1:]}, got {len(scalars)}")
        values = np.require(np.asarray(vector, dtype=float), requirements="C")  # keeps 0-d input 0-d
        output = np.empty_like(values)
        function(values.ctypes.data, output.ctypes.data, values.size, *[float(s) for s in scalars])
        return output if output.ndim else float(output)

    call.__doc__ = f"Compiled {code.function_name}{code.arguments}"
    return call
