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
series in acos κ (see :mod:`lindstedt.compiled.stable_series`): relative error ≤ 1e-13 for every κ in
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

import contextlib
import ctypes
import hashlib
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

from .._errors import CodeGenerationError, ProblemError
from .._precision import locked, locked_methods
from ._targets import _TARGETS, _renaming, _stable_target_source, _target_source
from ..compiled.stable_series import SERIES_TARGET, StableCoefficient
from ..compiled.stable_source import renamed, stable_c_source, stable_coefficient_cached, stable_numpy_source

__all__ = ["GeneratedCode", "generate_code"]

_LANGUAGES = ("numpy", "c", "octave", "julia", "fortran", "rust", "jax")
_QUANTITIES = ("frequency", "displacement")

class UnknownLanguageError(CodeGenerationError, ValueError):
    """``language`` is not one of the supported targets (also a ``ValueError``, as before)."""


def _check_language(language: Any) -> None:
    if language not in _LANGUAGES:
        raise UnknownLanguageError(
            f"language must be one of {', '.join(repr(name) for name in _LANGUAGES)}, got {language!r}"
        )


@locked_methods()
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

    def __repr__(self) -> str:
        """Labelled fields with the source cut (the whole source is ``.source``)."""
        from ..render.display import labelled_repr

        return labelled_repr("GeneratedCode", [
            ("language", repr(self.language)), ("quantity", repr(self.quantity)),
            ("function_name", repr(self.function_name)), ("arguments", repr(self.arguments)),
            ("source", f"<{len(self.source.splitlines())} lines; print(code.source)>"), ("accuracy", repr(self.accuracy)),
        ])

    def _repr_markdown_(self) -> str:
        """Jupyter's rendering: the accuracy statement and the source, highlighted as its language.

        Examples
        --------
        >>> import lindstedt
        >>> code = lindstedt.generate_code(lindstedt.expand("u**3", order=1, a0=1, omega0=1), "frequency", "julia")
        >>> code._repr_markdown_().splitlines()[2]
        '```julia'
        """
        fence = {"numpy": "python", "jax": "python", "octave": "matlab"}.get(self.language, self.language)
        return (f"**{self.function_name}** ({self.language}, {self.quantity}; arguments {', '.join(self.arguments)})\n\n"
                f"```{fence}\n{self.source.rstrip()}\n```\n\n*Accuracy:* {self.accuracy}\n")

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


@locked
def generate_code(expansion: Any, quantity: str = "frequency", language: str = "numpy") -> GeneratedCode:
    """Generate code for ``quantity`` of ``expansion`` in ``language``.

    Parameters
    ----------
    expansion : Expansion, NNMExpansion or FrequencyResponseCurve
    quantity : {"frequency", "displacement", "omega<k>"}
        For a FrequencyResponseCurve: one of its :meth:`~lindstedt.FrequencyResponseCurve.code_form` quantities
        (``"detuning_upper"``, ``"backbone"``, ``"relation"``, …).
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
    from ..results.frequency_response import FrequencyResponseCurve
    from ..results.nnm import NNMExpansion

    if isinstance(expansion, NNMExpansion):  # numeric coefficients, no free parameters
        return _nnm_code(expansion, quantity, language)
    if isinstance(expansion, FrequencyResponseCurve):  # closed forms in the amplitude A
        arguments, vector, expression = expansion.code_form(quantity)
        _check_language(language)
        return _generated(language, quantity, arguments, vector, expression.evalf(25), _UNANALYSED)
    if not isinstance(expansion, Expansion):
        raise ProblemError(
            "generate_code takes an Expansion (lindstedt.expand), an NNMExpansion (lindstedt.nnm) or a "
            f"FrequencyResponseCurve (lindstedt.frequency_response_curve), got {type(expansion).__name__}"
        )
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
    "is amplified by any cancellation in it (e.g. a gap near +-a0 can cost all digits); no bound is claimed"
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
        stable = stable_coefficient_cached(value, x)
        if stable is None:
            return None
        pieces.append((k, stable))
    renaming = _renaming([x] if coefficient is not None else [EPSILON, x], language)
    x = renaming[x]
    pieces = [(k, p.evalf(25) if isinstance(p, sympy.Expr) else renamed(p, parameters[0], x)) for k, p in pieces]
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
        source = (stable_numpy_source if language == "numpy" else stable_c_source)(name, x, pieces, coefficient is None, accuracy)
    arguments = (x.name,) if coefficient is not None else (renaming[EPSILON].name, x.name)
    return GeneratedCode(language, quantity, name, arguments, source, accuracy)


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
        _remove_stale_partials(directory)
    return directory


#: a temporary ``.partial-*`` file of the cache older than this (seconds) is left by a killed build; no compile
#: of a generated function takes a minute, so an hour is a safe margin for a concurrent build in progress
STALE_PARTIAL_AGE = 3600.0


def _remove_stale_partials(directory: str) -> None:
    """Delete the ``.partial-*`` files of a killed build: our own regular files older than STALE_PARTIAL_AGE."""
    import time

    now = time.time()
    try:
        entries = [entry for entry in os.scandir(directory) if entry.name.startswith(".partial-")]
    except OSError:
        return
    for entry in entries:
        with contextlib.suppress(OSError):
            status = entry.stat(follow_symlinks=False)
            if stat.S_ISREG(status.st_mode) and status.st_uid == os.getuid() and now - status.st_mtime > STALE_PARTIAL_AGE:
                os.unlink(entry.path)


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


@locked  # one build at a time: a thread checking a library another one is writing would delete it
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
