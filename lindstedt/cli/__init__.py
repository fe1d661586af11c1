"""Command-line interface ``lindstedt`` (expansions of u'' + ω0² u + ε f(u) = 0 and friends).

Sub-commands
------------
``lindstedt expand F --order N [--a0 A] [--omega0 W] [--param NAME=VALUE ...]
[--normalization initial|harmonic] [--eps E] [--format pretty|plain|latex|json]``
    Lindstedt–Poincaré expansion of the oscillator with nonlinearity F; ``--eps E`` also
    prints ω(E) evaluated from the expansion, with the estimate of its truncation error.  Text output is pretty (Unicode, 2-D
    formulas) by default; ``--format plain`` (alias ``text``) prints Python syntax.
    ``--u0 U --v0 V`` instead of ``--a0``: the orbit through u(0) = U, u'(0) = V
    (its turning-point and phase series are printed too).
``lindstedt nnm SYSTEM.json --mode J --a0 A [--order 2] [--eps E] [--format pretty|plain|latex|json]``
    Nonlinear normal mode of M X'' + K X + ε W (A X − b)_+ = 0 grown from mode J
    (``--eps E``: and the expansion's frequency at ε = E).
``lindstedt nnm SYSTEM.json --mode J --numeric (--a0 A | --energy E) --eps EPS [--format json]``
    The same NNM by shooting (the exact flow; DOP853 for laws other than unilateral springs): frequency, period,
    release state, Floquet multipliers.
``lindstedt forced F --eps E (--from W1 --to W2 | --at W) [--omega0 W] [--zeta Z] [--forcing F] [--param NAME=VALUE ...]
[--method exact|multiple-scales] [--order 1|2] [--format pretty|plain|latex|json] [--figure PATH]``
    Forced response of u'' + 2ζω0 u' + ω0² u + ε f(u) = ε F cos(Ω t): periodic responses by shooting on the
    exact flow, continued in Ω through folds with bifurcations located (or one orbit at ``--at``), or the
    closed-form multiple-scales curve and its steady amplitudes.
``lindstedt derive NAME [--order N] [--format text|latex|json] [--output DIR]`` / ``lindstedt derive --list``
    Named derivations (Duffing, u_+, gaps, grazing, NNMs, all modes).
``lindstedt demo [--figure PATH]``
    The tour: derives the Duffing and unilateral-spring expansions, prints them
    and their agreement with the exact references.

Every failure prints one line ``error: <message naming the fix>`` on stderr and exits
non-zero: 2 for bad input (arguments, files, values outside what a method takes),
1 for a computation that failed (a numerical method that did not converge, an
unexpected internal error).  JSON output never contains NaN or infinities: a
failed numerical result has ``null`` values with ``"success": false`` and a message.
A validity warning of an evaluated expansion (``--eps``), like any other warning, is one line ``warning: …``
on stderr.  Ctrl-C stops any command with the one line ``error: interrupted`` and exit status 130.
Long commands (``forced`` sweeps, ``nnm --numeric``, ``expand`` from order 10 or estimated at a second or more)
show their progress on stderr while they run when it is a terminal (a tqdm bar, if tqdm is installed), and
otherwise print one summary line there when they succeed (e.g. ``forced: 214 points, 2 folds, 3.1 s``); stdout holds the
result alone.
System files (``nnm SYSTEM.json``, ``forced FORCED.json``) are read within limits checked before the work:
at most ``--max-dof N`` degrees of freedom and ``--max-springs S`` springs (default 100 each), at most
64·(N + 1)·(N + S + 1) bytes (1.3 MB by default; a file that never ends, such as /dev/zero, is refused after
that many), arrays and objects nested at most 8 deep; beyond them one ``error:`` line names the limit and
the option, exit status 2.  An output that cannot be written (a full disk) is one line
``error: cannot write output: …``, exit status 1.
Every command takes ``--budget SECONDS`` and ``--budget-memory MB`` (defaults 600 s and 2048 MB; ``none``: no
limit; see :mod:`lindstedt.limits`): a request whose estimated cost exceeds them is refused before it starts
(exit status 2, the estimate and what drives it named), and a command that runs past them stops at its next
checkpoint (exit status 1; a continuation prints the branch computed so far).
Nothing is written to disk unless asked (``derive --output DIR``, ``demo --figure PATH``, ``forced --figure PATH``).
"""

from __future__ import annotations

import argparse
import math
import sys
from typing import Any, Sequence

from .._errors import BudgetError, Cancelled, ConvergenceError, LindstedtError, ProblemError
from ..limits import budget
from ._progress import Progress
from ._signals import INTERRUPTS

__all__ = ["main", "build_parser"]

EXIT_BAD_INPUT = 2
EXIT_FAILED = 1
#: Ctrl-C (SIGINT): the shell's convention, 128 + 2
EXIT_INTERRUPTED = 130
#: ``expand`` from this order on, or estimated to take this many seconds (lindstedt.expansion_cost), shows its
#: progress (orders one by one)
HIGH_ORDER, PROGRESS_SECONDS = 10, 1.0

FORMATS = ("pretty", "plain", "text", "latex", "json")
FORMAT_HELP = (
    "pretty: Unicode 2-D formulas (default); plain: Python syntax, one formula a line "
    "(text is an alias of plain); latex: an align* block; json: the documented schema"
)


class _InputError(Exception):
    """Raised by the argument parser instead of printing usage and exiting."""


class _ArgumentParser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # type: ignore[override]
        raise _InputError(f"{message} (see {self.prog} --help)")


def _parse_parameters(items: Sequence[str]) -> dict[str, str | None]:
    parameters: dict[str, str | None] = {}
    for item in items:
        name, value = (part.strip() for part in item.split("=", 1)) if "=" in item else (item.strip(), None)
        if name in parameters:
            raise ProblemError(f"--param {name} is given twice ({parameters[name]} and {value}); give each parameter once")
        parameters[name] = value
    return parameters


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``lindstedt`` command."""
    from .. import __version__
    from .forced import add_forced_parser, add_size_options

    parser = _ArgumentParser(
        prog="lindstedt",
        description="Exact Lindstedt-Poincare expansions of u'' + omega0^2 u + eps f(u) = 0, checked against exact references.",
    )
    parser.add_argument("--version", action="version", version=f"lindstedt {__version__}", help="print the version and exit")
    commands = parser.add_subparsers(dest="command", required=True, parser_class=_ArgumentParser, metavar="COMMAND",
                                     help="expand, nnm, forced, derive or demo (lindstedt COMMAND --help for its options)")

    expand = commands.add_parser("expand", help="expand u'' + omega0^2 u + eps f(u) = 0 to a given order")
    expand.add_argument("f", help="the nonlinearity f(u), e.g. 'u**3' or 'u**3 + c*u**5'")
    expand.add_argument("--order", type=int, default=2, help="highest order N (default 2)")
    expand.add_argument("--a0", default=None, help="amplitude a0 (number or symbol name; default: symbol a0)")
    expand.add_argument("--omega0", default=None, help="linear angular frequency (default: symbol omega0)")
    expand.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="declare a parameter of f with its value; NAME alone keeps it symbolic (repeatable)",
    )
    expand.add_argument("--normalization", choices=("initial", "harmonic"), default="initial",
                        help="initial: a0 is u(0); harmonic: a0 is the first-harmonic amplitude")
    expand.add_argument("--a1", default="0", help="release at u(0) = a0 + eps*a1 (default 0; e.g. just inside a gap that a0 touches)")
    expand.add_argument("--u0", default=None, help="initial displacement u(0) (with --v0; instead of --a0)")
    expand.add_argument("--v0", default=None,
                        help="initial velocity u'(0): the orbit through (u0, v0), with its turning-point and phase series")
    expand.add_argument("--eps", default=None, metavar="E",
                        help="also print omega(E), the expansion's frequency at eps = E, and its truncation error's estimate "
                             "(needs numeric --a0, --omega0 and parameter values)")
    expand.add_argument("--format", choices=FORMATS, default="pretty", help=FORMAT_HELP)
    expand.add_argument("--waveforms", action="store_true", help="include the waveforms v_k in text/LaTeX output")
    expand.add_argument("--precision", type=int, default=30, help="decimal digits for non-polynomial f (default 30)")

    nnm = commands.add_parser("nnm", help="nonlinear normal mode of M X'' + K X + eps W f(A X - b) = 0 by strained "
                                          "coordinates (unilateral springs) or by shooting (--numeric, any law)")
    nnm.add_argument("system", help="SYSTEM.json with keys M, K, A and optional b (default 0), W, laws and couplings "
                                         "(nested lists, numbers or exact strings; laws: one f(u) per row of A, default "
                                         "Max(0, u)), or M, K and elements: [{law, a, b, w}, ...]")
    nnm.add_argument("--mode", type=int, required=True, help="mode number j (1-based, increasing frequency)")
    nnm.add_argument("--a0", default=None, help="modal amplitude of mode j at release (expansion, or --numeric with the other modal coordinates free)")
    nnm.add_argument("--numeric", action="store_true", help="periodic orbit by shooting instead of the expansion (on the exact flow for "
                     "unilateral springs, DOP853 with variational equations for other laws)")
    nnm.add_argument("--energy", default=None, help="with --numeric: prescribed energy instead of --a0")
    nnm.add_argument("--eps", default=None, metavar="E",
                     help="the value of epsilon: the expansion's frequency at E with its truncation error's estimate, or with --numeric the orbit at E (required there)")
    nnm.add_argument("--order", type=int, default=2, help="expansion order (default 2)")
    nnm.add_argument("--precision", type=int, default=30, help="decimal digits of the arithmetic (default 30)")
    nnm.add_argument("--format", choices=FORMATS, default="pretty", help=FORMAT_HELP + " (--numeric: pretty, plain and latex print its summary)")
    nnm.add_argument("--reduce", type=int, default=None, metavar="K",
                     help="reduce the model first to its K lowest modes plus one residual-flexibility vector per element "
                          "(ResidualFlexibility); required for a model whose M, K come from matrix files "
                          "({\"matrices\": \"model.npz\" or {\"M\": file, \"K\": file}, \"elements\": [...]})")
    add_size_options(nnm)

    add_forced_parser(commands, FORMATS, FORMAT_HELP)

    derive = commands.add_parser(
        "derive", help="run a worked example of the source tree's derivations/ (LaTeX fragment + JSON coefficients)"
    )
    derive.add_argument("name", nargs="?", help="derivation name: the script derivations/NAME.py (see --list)")
    derive.add_argument("--list", action="store_true", help="list the scripts in derivations/ with their first docstring line")
    derive.add_argument("--order", type=int, default=None, help="expansion order (default: the script's own)")
    derive.add_argument("--format", choices=("text", "plain", "latex", "json"), default="text",
                        help="print the coefficients and checks (text, alias plain), the LaTeX fragment or the JSON (default text)")
    derive.add_argument("--output", default=None, help="directory to write NAME.tex and NAME.json into (default: write nothing)")

    demo = commands.add_parser("demo", help="the tour: Duffing and u_+ expansions checked against exact references")
    demo.add_argument("--order", type=int, default=8, help="Duffing order to derive (default 8)")
    demo.add_argument("--figure", default=None, metavar="PATH",
                      help="also draw the error of orders 0-2 against the exact flow into PATH (matplotlib; .png, .svg, .pdf...), "
                           "e.g. lindstedt-demo.png (default: write nothing)")
    for command in commands.choices.values():
        _add_budget_options(command)
    return parser


def _budget_value(text: str) -> float | None:
    """A budget option's value: a positive number, or ``none`` for no limit."""
    if text.strip().lower() in ("none", "inf", "infinity"):
        return None
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not (value > 0 and value != float("inf")):
        raise argparse.ArgumentTypeError(f"expected a positive number or 'none', got {text!r}")
    return value


def _add_budget_options(command: argparse.ArgumentParser) -> None:
    from ..limits import DEFAULT

    command.add_argument("--budget", type=_budget_value, default=DEFAULT.seconds, metavar="SECONDS",
                         help=f"refuse a request estimated above SECONDS of CPU and stop one that runs longer "
                              f"(default {DEFAULT.seconds:g}; 'none': no limit)")
    command.add_argument("--budget-memory", type=_budget_value, default=DEFAULT.memory_mb, metavar="MB",
                         help=f"the same for memory, in MB of growth (default {DEFAULT.memory_mb:g}; 'none': no limit)")


def _command_expand(arguments: argparse.Namespace) -> str:
    from ..methods.lindstedt_poincare import LindstedtPoincare
    from ..problems.oscillator import Oscillator

    problem = Oscillator(arguments.f, a0=arguments.a0, omega0=arguments.omega0,
                         params=_parse_parameters(arguments.param), normalization=arguments.normalization,
                         a1=arguments.a1, u0=arguments.u0, v0=arguments.v0)
    method = LindstedtPoincare(precision=arguments.precision)
    if arguments.order < HIGH_ORDER and method.estimate(problem, arguments.order).seconds < PROGRESS_SECONDS:
        return _expand_output(arguments, method.expand(problem, arguments.order))
    with Progress("expand", total=arguments.order + 2, unit="step") as progress:
        text = _expand_output(arguments, method.expand(problem, arguments.order), progress)
        progress.summary = f"orders 0-{arguments.order}"
    return text


def _expand_output(arguments: argparse.Namespace, expansion: Any, progress: Progress | None = None) -> str:
    if progress is not None:  # the orders one by one (the hierarchy is lazy), then the output
        for k in range(arguments.order + 1):
            progress.update(status=f"order {k}")
            expansion.omega_correction(k)
        progress.update(status="formatting the output")
    evaluated = None if arguments.eps is None else _evaluate_expansion(expansion, arguments.eps)
    if arguments.format == "json":
        if evaluated is None:
            return expansion.to_json()
        import json

        data = expansion.to_dict()
        data["evaluated"] = _evaluated_json(*evaluated)
        return json.dumps(data, indent=2, allow_nan=False)
    if arguments.format == "latex":
        text = expansion.to_latex(waveforms=arguments.waveforms)
        return text if evaluated is None else text.rstrip("\n") + _evaluated_latex(*evaluated)
    if arguments.format == "pretty":
        text = _pretty_expansion(expansion, waveforms=arguments.waveforms)
        return text if evaluated is None else text + _evaluated_text(*evaluated, pretty=True)
    text = expansion.summary()
    if arguments.waveforms:
        text += "\n" + "\n".join(f"  v_{w.order}(s) = {w.to_expr()}" for w in expansion.waveforms)
    return text if evaluated is None else text + _evaluated_text(*evaluated, pretty=False)


def _evaluated_text(epsilon: float, omega: float, error: float, pretty: bool) -> str:
    """ω(ε) and, on a line of its own, the estimate of its truncation error (the terms beyond the order)."""
    head = f"ω(ε = {epsilon!r}) = {omega!r}" if pretty else f"omega({epsilon!r}) = {omega!r}"
    return f"\n{head}\n  truncation error estimate: {error:.3g} (the omitted terms of the series)"


def _evaluated_latex(epsilon: float, omega: float, error: float) -> str:
    return f"\n\\[ \\omega({epsilon!r}) \\approx {omega!r} \\quad (\\text{{truncation error}} \\approx {_latex_number(error)}) \\]"


def _latex_number(value: float) -> str:
    """``value`` to 3 significant digits in LaTeX (sympy.latex(Float(v, 3)) rounds the binary value at ~10 bits:
    3.955e-5 printed 3.95)."""
    mantissa, _, exponent = f"{value:.3g}".partition("e")
    return mantissa if not exponent else f"{mantissa} \\times 10^{{{int(exponent)}}}"


def _evaluated_json(epsilon: float, omega: float, error: float) -> dict[str, Any]:
    return {"epsilon": epsilon, "omega": omega, "truncation_error_estimate": error if math.isfinite(error) else None}


def _pretty(expression: Any) -> str:
    import sympy

    return sympy.pretty(expression, use_unicode=True, order="none")


def _pretty_equation(name: Any, value: Any) -> str:
    """``name = value`` in 2-D Unicode (``omega_1`` prints as ω₁, ``a0`` as a₀, ``epsilon`` as ε)."""
    import sympy

    left = sympy.Symbol(name) if isinstance(name, str) else name
    return _pretty(sympy.Eq(left, sympy.sympify(value, strict=True), evaluate=False))


def _pretty_definitions(definitions: Any) -> str:
    """``κ = b/a₀,  β = acos(κ),  σ = √(1 − κ²)`` side by side in 2-D Unicode."""
    import sympy
    from sympy.printing.pretty.pretty import PrettyPrinter
    from sympy.printing.pretty.stringpict import prettyForm

    printer = PrettyPrinter({"use_unicode": True, "order": "none"})
    equations = printer._print_seq([sympy.Eq(symbol, value, evaluate=False) for symbol, value in definitions],
                                   None, None, ",  ")
    return prettyForm(*equations.left("where ")).render(wrap_line=False)


def _pretty_expansion(expansion: Any, *, waveforms: bool = False) -> str:
    """The default text output of ``expand``: the problem and ω_0..ω_N (and more) as Unicode 2-D formulas."""
    import sympy

    problem = expansion.problem
    u, epsilon = sympy.Symbol("u"), sympy.Symbol("epsilon")
    stiffness = u if problem.omega0 == 1 else sympy.Mul(problem.omega0**2, u, evaluate=False)
    equation = sympy.Add(sympy.Symbol("u''"), stiffness, sympy.Mul(epsilon, problem.f, evaluate=False), evaluate=False)
    blocks = [_pretty(sympy.Eq(equation, 0, evaluate=False))]
    if problem.has_initial_velocity:
        blocks.append(_pretty_equation("u(0)", problem.u0))
        blocks.append(_pretty_equation("u'(0)", problem.v0) + "   (released off the turning point a₀ + O(ε))")
    else:
        release = problem.a0 if problem.a1 == 0 else sympy.Add(problem.a0, problem.a1 * epsilon, evaluate=False)
        blocks.append(_pretty_equation("u(0)", release) + f"   u'(0) = 0   [{problem.normalization} normalization]")
    for symbol, value in problem.params:
        if value != symbol:
            blocks.append(_pretty_equation(symbol, value))
    if problem.symbolic_parameters:
        blocks.append("symbolic: " + ", ".join(_pretty(symbol) for symbol in problem.symbolic_parameters))
    terms = len(expansion.omega)
    if isinstance(expansion.gauge, sympy.Symbol):
        series = " + ".join(["ω₀", "ω₁·ε"][:terms] + [f"ω{_subscript(k)}·ε{_superscript(k)}" for k in range(2, terms)])
        blocks.append(f"ω(ε) = {series} + O(ε{_superscript(terms)})")
    else:
        blocks.append(f"ω(ε) = Σₖ ωₖ·({_pretty(expansion.gauge)})ᵏ   (grazing: not analytic in ε)")
    from ..results._readable import readable_coefficients

    definitions, omega, amplitude, phase = readable_coefficients(expansion)
    if definitions:
        blocks.append(_pretty_definitions(definitions))
    blocks += [_pretty_equation(f"omega_{k}", value) for k, value in enumerate(omega)]
    if problem.has_initial_velocity:
        blocks.append("u(t) = v(ω·t + φ(ε); ε), released at the turning point A(ε) = v(0; ε) > 0")
        blocks += [_pretty_equation(f"A_{k}", value) for k, value in enumerate(amplitude)]
        blocks += [_pretty_equation(f"phi_{k}", value) for k, value in enumerate(phase)]
    if waveforms:
        s = sympy.Symbol("s")
        blocks += [_pretty_equation(sympy.Function(f"v_{w.order}")(s), w.to_expr()) for w in expansion.waveforms]
    return "\n".join(blocks)


def _pretty_nnm(result: Any) -> str:
    """The default text output of ``nnm``: the summary with Unicode symbols."""
    import mpmath

    lines = [f"NNM of mode {result.mode} (a₀ = {result.a0}), strained coordinates to order {result.order}"]
    lines.append("  λ = " + ", ".join(f"{value:.10g}" for value in result.lambdas))
    lines += [f"  ω{_subscript(n)} = {mpmath.nstr(value, 15)}" for n, value in enumerate(result.omega)]
    lines.append("  aₖ = " + ", ".join(mpmath.nstr(value, 12) for value in result.a_k) + "   (release uₖ(0) = ε·aₖ)")
    lines.append(f"  validity: T ~ ε^({result.validity_exponent}); spring roots: {', '.join(result.spring_roots)}")
    return "\n".join(lines)


def _superscript(number: int) -> str:
    return "" if number == 1 else str(number).translate(str.maketrans("0123456789", "⁰¹²³⁴⁵⁶⁷⁸⁹"))


def _subscript(number: int) -> str:
    return str(number).translate(str.maketrans("0123456789", "₀₁₂₃₄₅₆₇₈₉"))


def _evaluate_expansion(expansion: Any, eps_text: str) -> tuple[float, float, float]:
    """(ε, ω(ε), the truncation error's estimate) from the expansion; its validity warnings become one ``warning:``
    line on stderr."""
    from ..problems.parsing import parse_float

    epsilon = parse_float(eps_text, what="--eps")
    problem = getattr(expansion, "problem", None)
    if problem is not None:
        free = sorted(str(symbol) for symbol in _free_symbols(problem))
        if free:
            raise ProblemError(
                f"--eps evaluates the expansion, which needs numbers for {', '.join(free)}: "
                "give --a0 A and --omega0 W as numbers and every --param as NAME=VALUE"
            )
    return (epsilon, *_warned(lambda: (float(expansion.frequency(epsilon)),
                                       float(expansion.truncation_error_estimate(epsilon)))))


def _free_symbols(problem: Any) -> set:
    symbols = set(problem.symbolic_parameters)
    for value in (problem.a0, problem.omega0, problem.a1):
        symbols |= set(getattr(value, "free_symbols", ()))
    return symbols


def _warned(compute: Any) -> Any:
    """Run ``compute()``; an ExpansionValidityWarning it raises is printed as one ``warning:`` line on stderr."""
    import warnings

    from ..results.accuracy import ExpansionValidityWarning

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ExpansionValidityWarning)
        value = compute()
    messages = list(dict.fromkeys(" ".join(str(w.message).split()) for w in caught if issubclass(w.category, ExpansionValidityWarning)))
    if messages:
        print("warning: " + "; ".join(messages), file=sys.stderr)
    for other in (w for w in caught if not issubclass(w.category, ExpansionValidityWarning)):
        warnings.warn_explicit(other.message, other.category, other.filename, other.lineno)
    return value


def _command_nnm(arguments: argparse.Namespace) -> str | tuple[str, int]:
    import json

    from ..problems.system import UnilateralSystem
    from ._files import check_system_size, read_json_file

    limits = {"max_dof": arguments.max_dof, "max_springs": arguments.max_springs}
    data = read_json_file(arguments.system, "system file", **limits)
    if not isinstance(data, dict):
        raise ProblemError(f"the system file {arguments.system!r} must hold a JSON object with keys M, K, A, b (and optional W)")
    reduction = None
    if arguments.reduce is not None or "matrices" in data:
        from ._structures import reduced_structure

        if arguments.reduce is None:
            raise ProblemError("a model whose matrices come from files is reduced first: give --reduce K (the modes kept, "
                               "e.g. --reduce 8)")
        if "matrices" not in data:
            check_system_size(data, "system file", **limits)
        reduction = reduced_structure(data, arguments.system, arguments.reduce, arguments.precision)
        system = reduction.system
    else:
        check_system_size(data, "system file", **limits)
        system = UnilateralSystem.from_json_dict(data)
    output = _nnm_output(system, arguments)
    if reduction is None:
        return output
    text, status = output if isinstance(output, tuple) else (output, 0)
    line = (f"reduced: {reduction.n_dof} dof → {system.n_dof} ({reduction.modes} modes + residual vectors; "
            f"{reduction.message})")
    if arguments.format == "json":
        content = json.loads(text)
        content["reduction"] = {"n_dof": reduction.n_dof, "modes": reduction.modes, "reduced_dof": system.n_dof,
                                "message": reduction.message}
        text = json.dumps(content, indent=2, allow_nan=False)
    else:
        text = ("% " if arguments.format == "latex" else "") + line + "\n" + text
    return text, status


def _nnm_output(system: Any, arguments: argparse.Namespace) -> str | tuple[str, int]:
    import json

    from ..methods.strained_coordinates import nnm

    if arguments.numeric:
        return _numeric_nnm(system, arguments)
    if arguments.energy is not None:
        raise ProblemError("--energy goes with --numeric (the expansion is parametrised by --a0, the modal amplitude)")
    if arguments.a0 is None:
        raise ProblemError("give --a0 (the modal amplitude of the mode), or --numeric with --energy")
    epsilon = None
    if arguments.eps is not None:
        from ..problems.parsing import parse_float

        epsilon = parse_float(arguments.eps, what="--eps")
    result = nnm(system, arguments.mode, arguments.a0, arguments.order, precision=arguments.precision)
    evaluated = None if epsilon is None else (epsilon, *_warned(
        lambda: (float(result.frequency(epsilon)), float(result.truncation_error_estimate(epsilon)))))
    if arguments.format == "json":
        if evaluated is None:
            return result.to_json()
        data = json.loads(result.to_json())
        data["evaluated"] = _evaluated_json(*evaluated)
        return json.dumps(data, indent=2, allow_nan=False)
    if arguments.format == "latex":
        text = result.to_latex()
        return text if evaluated is None else text.rstrip("\n") + _evaluated_latex(*evaluated)
    if arguments.format == "pretty":
        text = _pretty_nnm(result)
        return text if evaluated is None else text + _evaluated_text(*evaluated, pretty=True)
    text = result.summary()
    return text if evaluated is None else text + _evaluated_text(*evaluated, pretty=False)


def _command_derive(arguments: argparse.Namespace) -> str | tuple[str, int]:
    """Run ``derivations/NAME.py`` of the source tree in this process, through its helper ``derivations/_common.py``."""
    import importlib.util
    from pathlib import Path

    import lindstedt

    directory = Path(lindstedt.__file__).resolve().parent.parent / "derivations"
    helper = directory / "_common.py"
    if not helper.is_file():
        raise ProblemError(
            f"the derivations ship with the source tree, not with the installed package (no {helper}); "
            "run `lindstedt derive` from an editable install of a checkout (pip install -e .), "
            "or run `python derivations/NAME.py` there"
        )
    key = "lindstedt_derivations_common"  # the name the scripts load their helper under
    common = sys.modules.get(key)
    if common is None or Path(common.__file__).resolve() != helper:
        spec = importlib.util.spec_from_file_location(key, helper)
        common = importlib.util.module_from_spec(spec)
        sys.modules[key] = common
        spec.loader.exec_module(common)
    if arguments.list:
        return "\n".join(f"{name:18s} {description}" for name, description in common.list_derivations(directory))
    if not arguments.name:
        raise ProblemError("name a derivation (lindstedt derive --list shows them)")
    result = common.run_script(arguments.name, order=arguments.order, output=arguments.output, directory=directory)
    text = common.render(result, "text" if arguments.format == "plain" else arguments.format)
    return text if result.agrees else (text, EXIT_FAILED)


def _numeric_nnm(system: Any, arguments: argparse.Namespace) -> tuple[str, int]:
    from ..numerics import nnm_point
    from ..problems.parsing import parse_float

    if arguments.eps is None:
        raise ProblemError("--numeric needs --eps EPS (the value of epsilon)")
    if (arguments.a0 is None) == (arguments.energy is None):
        raise ProblemError("--numeric needs exactly one of --a0 A (modal amplitude) and --energy E")
    epsilon = parse_float(arguments.eps, what="--eps")
    if arguments.a0 is not None:
        amplitude = {"modal_amplitude": parse_float(arguments.a0, what="--a0")}
    else:
        amplitude = {"energy": parse_float(arguments.energy, what="--energy")}
    with Progress("nnm", total=1, unit="orbit") as progress:
        result = nnm_point(system, epsilon, arguments.mode, **amplitude)
        progress.update()
        if result.success:
            progress.summary = (f"mode {arguments.mode} by shooting, {result.newton_iterations} Newton iterations, "
                                f"{result.flow_evaluations} flows")
    status = 0 if result.success else EXIT_FAILED
    return (result.to_json() if arguments.format == "json" else result.summary()), status


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status.

    Examples
    --------
    >>> main(["expand", "u**3", "--order", "1", "--a0", "1", "--omega0", "1", "--format", "plain", "--eps", "0.1"])
    u'' + u + eps*(u**3) = 0, u(0) = 1 [initial]
      omega_0 = 1
      omega_1 = 3/8
    omega(0.1) = 1.0375
      truncation error estimate: 0.00082 (the omitted terms of the series)
    0
    """
    import warnings

    with INTERRUPTS:
        try:
            with warnings.catch_warnings():
                warnings.showwarning = _show_warning
                return _run(argv)
        except KeyboardInterrupt:  # Ctrl-C anywhere, the imports of a command included: one line, no traceback
            INTERRUPTS.ignore()
            return _fail("interrupted", EXIT_INTERRUPTED)


def _run(argv: Sequence[str] | None) -> int:
    status = 0
    try:
        arguments = build_parser().parse_args(argv)
        with INTERRUPTS.deferred():  # mpmath (every command's) imports gmpy2 in a bare `except:` that swallows Ctrl-C
            import mpmath  # noqa: F401
        with budget(seconds=arguments.budget, memory_mb=arguments.budget_memory):
            output = _dispatch(arguments)
        if isinstance(output, tuple):
            output, status = output
        INTERRUPTS.check()  # a Ctrl-C that a library swallowed on the way
    except SystemExit as exit_request:  # --help and --version print and exit 0
        return int(exit_request.code or 0)
    except (_InputError, ProblemError) as error:
        return _fail(error, EXIT_BAD_INPUT)
    except OSError as error:
        where = f" {error.filename!r}" if error.filename else ""
        return _fail(f"cannot access{where}: {error.strerror or error}; check that the path exists and is writable", EXIT_BAD_INPUT)
    except (BudgetError, Cancelled) as error:  # refused up front: the request is the input to change
        return _fail(error, EXIT_BAD_INPUT if getattr(error, "up_front", False) else EXIT_FAILED)
    except LindstedtError as error:
        return _fail(error, EXIT_FAILED if isinstance(error, ConvergenceError) else EXIT_BAD_INPUT)
    except RecursionError:
        return _fail("the input is too deeply nested to process; simplify it", EXIT_BAD_INPUT)
    except Exception as error:  # noqa: BLE001 - the command line never shows a traceback
        return _fail(f"internal failure ({type(error).__name__}: {error}); please report it", EXIT_FAILED)
    return _print_output(output, status)


def _dispatch(arguments: argparse.Namespace) -> Any:
    """The output of the command ``arguments`` name (text, or (text, status))."""
    if arguments.command == "expand":
        return _command_expand(arguments)
    if arguments.command == "nnm":
        return _command_nnm(arguments)
    if arguments.command == "forced":
        from .forced import run_forced

        return run_forced(arguments, _parse_parameters(arguments.param))
    if arguments.command == "derive":
        return _command_derive(arguments)
    from .demo import run_demo

    return run_demo(order=arguments.order, figure_path=arguments.figure or None)


def _print_output(output: str, status: int) -> int:
    """Print the command's output; the exit status (``status``, or 1 when stdout cannot take it)."""
    try:
        print(output)
        sys.stdout.flush()  # a full disk (/dev/full) fails here, not at the interpreter's exit
    except BrokenPipeError:  # e.g. `lindstedt expand ... | head`
        _discard_stdout()
        sys.stderr.close()
    except UnicodeEncodeError:
        return _fail("the output stream cannot encode Unicode; use --format plain (or set PYTHONIOENCODING=utf-8)", EXIT_BAD_INPUT)
    except OSError as error:  # e.g. no space left on the device stdout writes to
        _discard_stdout()
        return _fail(f"cannot write output: {error.strerror or error}", EXIT_FAILED)
    if status and output:
        print("error: the computation did not succeed (see its message above)", file=sys.stderr)
    return status


def _discard_stdout() -> None:
    """Point stdout at /dev/null, so that the interpreter's flush at exit of what could not be written is silent."""
    import os

    try:
        sys.stdout.flush()
    except OSError:
        pass
    try:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):  # no file descriptor (stdout replaced, e.g. under pytest)
        pass


def _fail(error: Any, status: int) -> int:
    message = " ".join(str(error).split())  # one line
    print(f"error: {message}", file=sys.stderr)
    return status


def _show_warning(message: Any, category: type, filename: str, lineno: int, file: Any = None, line: Any = None) -> None:
    """A Python warning raised by a command: one line ``warning: <message>`` on stderr (no source line)."""
    print(f"warning: {' '.join(str(message).split())} ({category.__name__})", file=sys.stderr if file is None else file)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
