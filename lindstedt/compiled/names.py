"""Names in generated code: the reserved words of each target and the renaming of clashing arguments
(shared by :mod:`lindstedt.export.codegen`, its targets :mod:`lindstedt.export._targets`, and the NumPy source of
the stable series that the float evaluators compile, :mod:`lindstedt.compiled.stable_source`)."""

from __future__ import annotations

import builtins
import keyword
from typing import Callable

import sympy
from sympy.printing.c import C99CodePrinter
from sympy.printing.numpy import NumPyPrinter

from .._errors import CodeGenerationError

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


def _safe_names(
    arguments: list[sympy.Symbol], reserved: frozenset[str], fold: Callable[[str], str] = str
) -> dict[sympy.Symbol, sympy.Symbol]:
    """Map each argument to a symbol whose name is not in ``reserved`` nor taken by another argument.

    Free ASCII names are kept; the others get ``_`` appended until they are free
    (``double`` -> ``double_``, or ``double__`` if ``double_`` is an argument too).  Names are compared
    after ``fold`` (``str.lower`` for Fortran, whose names are case-insensitive).  Every generated name is
    ASCII (Fortran, Octave and some Python tools take no other): a non-ASCII character becomes ``u`` and its
    code point in hex (``α`` -> ``u03b1``, ``κ_2`` -> ``u03ba_2``), then the same ``_`` rule keeps it distinct.
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
        if symbol.name.isascii() and fold(symbol.name) not in reserved and fold(symbol.name) not in taken:
            names[symbol] = symbol.name
            taken.add(fold(symbol.name))
    for symbol in arguments:
        if symbol not in names:
            name = _ascii(symbol.name)
            while fold(name) in reserved or fold(name) in taken:
                name += "_"
            names[symbol] = name
            taken.add(fold(name))
    return {s: s if n == s.name else sympy.Symbol(n, **s.assumptions0) for s, n in names.items()}


def _ascii(name: str) -> str:
    """``name`` with each non-ASCII character written ``u`` + its code point in hex (``α`` -> ``u03b1``)."""
    return "".join(character if character.isascii() else f"u{ord(character):04x}" for character in name)
