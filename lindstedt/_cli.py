"""Command-line interface ``lindstedt`` (expansions of u'' + ω0² u + ε f(u) = 0 and friends).

Sub-commands
------------
``lindstedt expand F --order N [--a0 A] [--omega0 W] [--param NAME=VALUE ...]
[--normalization initial|harmonic] [--format text|latex|json]``
    Lindstedt–Poincaré expansion of the oscillator with nonlinearity F.
``lindstedt nnm SYSTEM.json --mode J --a0 A [--order 2] [--format text|latex|json]``
    Nonlinear normal mode of M X'' + K X + ε W (A X − b)_+ = 0 grown from mode J.
``lindstedt nnm SYSTEM.json --mode J --numeric (--a0 A | --energy E) --eps EPS [--format json]``
    The same NNM by shooting on the exact flow: frequency, period, release state, Floquet multipliers.
``lindstedt derive NAME [--order N] [--format text|latex|json] [--output DIR]`` / ``lindstedt derive --list``
    Named derivations (Duffing, u_+, gaps, grazing, NNMs, all modes).
``lindstedt demo``
    The tour: derives the Duffing and unilateral-spring expansions, prints them
    and their agreement with the exact references.

Errors in the input print ``error: <message naming the fix>`` and exit with status 2.
"""

from __future__ import annotations

import argparse
import sys
from typing import Sequence

from ._errors import LindstedtError

__all__ = ["main", "build_parser"]


def _parse_parameters(items: Sequence[str]) -> dict[str, str | None]:
    parameters: dict[str, str | None] = {}
    for item in items:
        if "=" in item:
            name, value = item.split("=", 1)
            parameters[name.strip()] = value.strip()
        else:
            parameters[item.strip()] = None
    return parameters


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``lindstedt`` command."""
    parser = argparse.ArgumentParser(
        prog="lindstedt",
        description="Exact Lindstedt-Poincare expansions of u'' + omega0^2 u + eps f(u) = 0, checked against exact references.",
    )
    commands = parser.add_subparsers(dest="command", required=True)

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
    expand.add_argument("--normalization", choices=("initial", "harmonic"), default="initial")
    expand.add_argument("--format", choices=("text", "latex", "json"), default="text")
    expand.add_argument("--waveforms", action="store_true", help="include the waveforms v_k in text/LaTeX output")
    expand.add_argument("--precision", type=int, default=30, help="decimal digits for non-polynomial f (default 30)")

    nnm = commands.add_parser("nnm", help="nonlinear normal mode of M X'' + K X + eps W (A X - b)_+ = 0 by strained coordinates")
    nnm.add_argument("system", help="SYSTEM.json with keys M, K, A, b and optional W (nested lists, numbers or exact strings)")
    nnm.add_argument("--mode", type=int, required=True, help="mode number j (1-based, increasing frequency)")
    nnm.add_argument("--a0", default=None, help="modal amplitude of mode j at release (expansion, or --numeric with the other modal coordinates free)")
    nnm.add_argument("--numeric", action="store_true", help="periodic orbit by shooting on the exact flow instead of the expansion")
    nnm.add_argument("--energy", default=None, help="with --numeric: prescribed energy instead of --a0")
    nnm.add_argument("--eps", default=None, help="with --numeric: the value of epsilon")
    nnm.add_argument("--order", type=int, default=2, help="expansion order (default 2)")
    nnm.add_argument("--precision", type=int, default=30, help="decimal digits of the arithmetic (default 30)")
    nnm.add_argument("--format", choices=("text", "latex", "json"), default="text")

    derive = commands.add_parser("derive", help="run a named derivation (LaTeX fragment + JSON coefficients)")
    derive.add_argument("name", nargs="?", help="derivation name (see --list)")
    derive.add_argument("--list", action="store_true", help="list the named derivations")
    derive.add_argument("--order", type=int, default=None, help="expansion order (default: the derivation's own)")
    derive.add_argument("--format", choices=("text", "latex", "json"), default="text")
    derive.add_argument("--output", default=None, help="directory to write NAME.tex and NAME.json into")

    demo = commands.add_parser("demo", help="the tour: Duffing and u_+ expansions checked against exact references")
    demo.add_argument("--order", type=int, default=8, help="Duffing order to derive (default 8)")
    demo.add_argument("--figure", default="lindstedt-demo.svg", help="where to write the SVG figure (default lindstedt-demo.svg; '' for none)")
    return parser


def _command_expand(arguments: argparse.Namespace) -> str:
    from ._api import expand

    expansion = expand(
        arguments.f,
        order=arguments.order,
        a0=arguments.a0,
        omega0=arguments.omega0,
        params=_parse_parameters(arguments.param),
        normalization=arguments.normalization,
        precision=arguments.precision,
    )
    if arguments.format == "json":
        return expansion.to_json()
    if arguments.format == "latex":
        return expansion.to_latex(waveforms=arguments.waveforms)
    text = expansion.summary()
    if arguments.waveforms:
        text += "\n" + "\n".join(f"  v_{w.order}(s) = {w.to_expr()}" for w in expansion.waveforms)
    return text


def _command_nnm(arguments: argparse.Namespace) -> str:
    import json

    from ._errors import ProblemError
    from ._nnm_expansion import nnm
    from ._parsing import parse_number
    from ._system import UnilateralSystem

    try:
        with open(arguments.system, encoding="utf-8") as handle:
            data = json.load(handle)
    except (OSError, json.JSONDecodeError) as error:
        raise ProblemError(f"cannot read the system file {arguments.system!r}: {error}") from None
    system = UnilateralSystem.from_json_dict(data)
    if arguments.numeric:
        return _numeric_nnm(system, arguments)
    if arguments.a0 is None:
        raise ProblemError("give --a0 (the modal amplitude of the mode), or --numeric with --energy")
    result = nnm(system, arguments.mode, parse_number(arguments.a0, what="a0"), arguments.order, precision=arguments.precision)
    if arguments.format == "json":
        return result.to_json()
    if arguments.format == "latex":
        return result.to_latex()
    return result.summary()


def _command_derive(arguments: argparse.Namespace) -> str:
    from ._derive import derive, format_derivation, list_derivations
    from ._errors import ProblemError

    if arguments.list:
        return "\n".join(f"{name:18s} {description}" for name, description in list_derivations())
    if not arguments.name:
        raise ProblemError("name a derivation (lindstedt derive --list shows them)")
    result = derive(arguments.name, order=arguments.order, output_directory=arguments.output)
    return format_derivation(result, arguments.format)


def _numeric_nnm(system, arguments: argparse.Namespace) -> str:
    import json

    from ._errors import ProblemError
    from ._nnm_numeric import nnm_point

    if arguments.eps is None:
        raise ProblemError("--numeric needs --eps EPS (the value of epsilon)")
    if (arguments.a0 is None) == (arguments.energy is None):
        raise ProblemError("--numeric needs exactly one of --a0 A (modal amplitude) and --energy E")
    amplitude = {"modal_amplitude": float(arguments.a0)} if arguments.a0 is not None else {"energy": float(arguments.energy)}
    result = nnm_point(system, float(arguments.eps), arguments.mode, **amplitude)
    multipliers = [] if result.floquet_multipliers is None else [[float(z.real), float(z.imag)] for z in result.floquet_multipliers]
    data = {
        "schema": "lindstedt.nnm-numeric/1",
        "success": bool(result.success),
        "message": result.message,
        "mode": result.mode,
        "epsilon": result.epsilon,
        "frequency": result.frequency,
        "period": result.period,
        "release_position": [float(x) for x in result.release_position],
        "release_velocity": [float(x) for x in result.release_velocity],
        "modal_coordinates": [float(x) for x in result.modal_coordinates],
        "energy": result.energy,
        "floquet_multipliers": multipliers,
        "stable": result.stable,
        "newton_iterations": result.newton_iterations,
        "flow_evaluations": result.flow_evaluations,
    }
    if arguments.format == "json":
        return json.dumps(data, indent=2)
    return result.summary()


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status.

    Examples
    --------
    >>> main(["expand", "u**3", "--order", "1", "--a0", "1", "--omega0", "1"])
    u'' + u + eps*(u**3) = 0, u(0) = 1 [initial]
      omega_0 = 1
      omega_1 = 3/8
    0
    """
    parser = build_parser()
    arguments = parser.parse_args(argv)
    try:
        if arguments.command == "expand":
            output = _command_expand(arguments)
        elif arguments.command == "nnm":
            output = _command_nnm(arguments)
        elif arguments.command == "derive":
            output = _command_derive(arguments)
        elif arguments.command == "demo":
            from ._demo import run_demo

            output = run_demo(order=arguments.order, figure_path=arguments.figure or None)
        else:  # pragma: no cover - argparse enforces the choices
            parser.error(f"unknown command {arguments.command}")
            return 2
    except LindstedtError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    try:
        print(output)
    except BrokenPipeError:  # e.g. `lindstedt expand ... | head`
        sys.stderr.close()
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
