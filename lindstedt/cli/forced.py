"""``lindstedt forced``: the response of u'' + 2ζω0 u' + ω0² u + ε f(u) = ε F cos(Ω t)
(or, from a FORCED.json file, of M X'' + C X' + K X + ε W (A X − b)_+ = ε P cos(Ω t)).

``--method exact`` (default): periodic responses by shooting on the exact flow (event-driven for
piecewise-linear f, DOP853 otherwise), continued over ``--from``/``--to`` with folds and bifurcations
located, or one orbit at ``--at``.  ``--method multiple-scales``: the closed-form frequency-response
curve (slow flow, relation, branches, backbone, stability) and its steady amplitudes over the range.
"""

from __future__ import annotations

import argparse
import json
from typing import Any

from .._errors import LindstedtError, ProblemError
from ._progress import Progress

__all__ = ["add_forced_parser", "add_size_options", "run_forced"]

#: rows of a text table (ends, bifurcations and evenly spaced points)
TABLE_ROWS = 24


def add_forced_parser(commands: Any, formats: tuple[str, ...], format_help: str) -> None:
    """The ``forced`` sub-command's options."""
    forced = commands.add_parser(
        "forced", help="forced response of u'' + 2 zeta omega0 u' + omega0^2 u + eps f(u) = eps F cos(Omega t)"
    )
    forced.add_argument("f", help="the nonlinearity f(u), e.g. 'Max(0, u - 1/10)' or 'u**3'; or FORCED.json, an N-dof "
                                  "system {\"system\": {M, K, A, b, optional W and laws: one law f(u) per row of A, default "
                                  "Max(0, u)}, \"load\": P, and rayleigh, modal_damping or C}")
    forced.add_argument("--omega0", default="1", help="linear angular frequency omega0 > 0 (default 1)")
    forced.add_argument("--zeta", default="0", help="damping ratio zeta >= 0 (default 0)")
    forced.add_argument("--forcing", default="1", help="forcing amplitude F != 0; the load is eps F cos(Omega t) (default 1)")
    forced.add_argument("--eps", required=True, metavar="E", help="the value of epsilon")
    forced.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                        help="a parameter of f with its value (repeatable)")
    forced.add_argument("--from", dest="start", default=None, metavar="OMEGA", help="first forcing frequency of the sweep")
    forced.add_argument("--to", dest="stop", default=None, metavar="OMEGA", help="last forcing frequency of the sweep")
    forced.add_argument("--at", default=None, metavar="OMEGA", help="one periodic response at this forcing frequency (exact)")
    forced.add_argument("--method", choices=("exact", "multiple-scales"), default="exact",
                        help="exact: shooting and continuation on the exact flow (default); multiple-scales: the closed-form curve")
    forced.add_argument("--order", type=int, default=1, help="multiple-scales order, 1 or 2 (2: polynomial f) (default 1)")
    forced.add_argument("--format", choices=formats, default="pretty", help=format_help)
    forced.add_argument("--figure", default=None, metavar="PATH",
                        help="also draw the response into PATH (matplotlib; .png, .svg, .pdf...) (default: write nothing)")
    add_size_options(forced)


def add_size_options(command: Any) -> None:
    """``--max-dof`` and ``--max-springs``: the largest system a JSON file may hold (see ``_files``)."""
    from ._files import MAX_DOF, MAX_SPRINGS

    command.add_argument("--max-dof", type=int, default=MAX_DOF, metavar="N",
                         help=f"refuse system files of more than N degrees of freedom (default {MAX_DOF})")
    command.add_argument("--max-springs", type=int, default=MAX_SPRINGS, metavar="S",
                         help=f"refuse system files of more than S unilateral springs (default {MAX_SPRINGS})")


def _problem(arguments: argparse.Namespace, parameters: dict[str, Any]) -> Any:
    from ..problems.forced import ForcedOscillator, ForcedSystem

    if arguments.f.endswith(".json"):
        given = [option for option, value in (("--omega0", arguments.omega0 != "1"), ("--zeta", arguments.zeta != "0"),
                                              ("--forcing", arguments.forcing != "1"), ("--param", parameters)) if value]
        if given:
            raise ProblemError(f"{', '.join(given)} describe a 1-dof problem; a FORCED.json file holds its own damping and load")
        from ._files import check_system_size, read_json_file

        limits = {"max_dof": arguments.max_dof, "max_springs": arguments.max_springs}
        data = read_json_file(arguments.f, "forced system file", **limits)
        if isinstance(data, dict):
            check_system_size(data.get("system"), "forced system file", **limits)
        return ForcedSystem.from_json_dict(data)
    return ForcedOscillator(arguments.f, omega0=arguments.omega0, zeta=arguments.zeta, forcing=arguments.forcing,
                            params=parameters)


def _frequencies(arguments: argparse.Namespace) -> tuple[float | None, float | None, float | None]:
    from ..problems.forced import check_forcing_frequency

    at = None if arguments.at is None else check_forcing_frequency(arguments.at, "--at")
    start = None if arguments.start is None else check_forcing_frequency(arguments.start, "--from")
    stop = None if arguments.stop is None else check_forcing_frequency(arguments.stop, "--to")
    if at is not None and (start is not None or stop is not None):
        raise ProblemError("give either --at OMEGA (one response) or --from/--to (a sweep), not both")
    if at is None and (start is None or stop is None):
        raise ProblemError("give --from OMEGA --to OMEGA (a sweep) or --at OMEGA (one response)")
    if at is None and start == stop:
        raise ProblemError("--from and --to must differ")
    return at, start, stop


def _rows(count: int, events: set[int]) -> list[int]:
    import numpy as np

    chosen = {0, count - 1} | {k for k in events if 0 <= k < count}
    for k in np.linspace(0, count - 1, TABLE_ROWS).astype(int):
        if len(chosen) >= TABLE_ROWS:
            break
        chosen.add(int(k))
    return sorted(chosen)


def _response_text(response: Any, pretty: bool) -> str:
    import numpy as np

    omega, sep = ("Ω", "  ") if pretty else ("Omega", "  ")
    lines = [
        f"{'frequency response' if response.success else 'frequency response (INCOMPLETE)'}: {response.message}",
        f"{len(response)} points, {response.flow_evaluations} period maps, {response.wall_time:.2f} s",
    ]
    if response.bifurcations:
        lines.append("bifurcations:")
        for event in response.bifurcations:
            lines.append(f"  {event.kind:16s} {omega} = {event.frequency:.10g}   max|u| = {float(np.max(event.amplitude)):.10g}")
    else:
        lines.append("bifurcations: none")
    if len(response):
        dofs = min(len(response.points[0].amplitude), 4)
        if dofs == 1:
            header = f"{omega:>14s}{sep}{'max|u|':>14s}{sep}{'|u_1|':>14s}{sep}{'mean':>12s}{sep}stable"
        else:
            header = f"{omega:>14s}" + "".join(f"{sep}{f'max|X{i + 1}|':>14s}" for i in range(dofs)) + f"{sep}stable"
        lines += ["", header]
        events = {event.index for event in response.bifurcations}
        for k in _rows(len(response), events):
            point = response.points[k]
            stable = "yes" if point.stable else "no"
            if dofs == 1:
                lines.append(f"{point.frequency:14.10g}{sep}{float(point.amplitude[0]):14.10g}{sep}"
                             f"{float(point.harmonic[0]):14.10g}{sep}{float(point.mean[0]):12.4g}{sep}{stable}")
            else:
                lines.append(f"{point.frequency:14.10g}" + "".join(f"{sep}{float(a):14.10g}" for a in point.amplitude[:dofs])
                             + f"{sep}{stable}")
    return "\n".join(lines)


def _orbit_text(orbit: Any, pretty: bool) -> str:
    import numpy as np

    omega = "Ω" if pretty else "Omega"
    largest = float(np.max(np.abs(orbit.multipliers))) if len(orbit.multipliers) else float("nan")
    lines = [f"periodic response at {omega} = {orbit.frequency!r}: {'converged' if orbit.success else 'FAILED'} ({orbit.message})"]
    dofs = len(orbit.maximum)
    for i in range(dofs):
        name = "u" if dofs == 1 else f"X{i + 1}"
        lines += [
            f"{name}: max = {float(orbit.maximum[i])!r}, min = {float(orbit.minimum[i])!r}, mean = {float(orbit.mean[i])!r}",
            f"{' ' * len(name)}  first harmonic {float(orbit.harmonic_cos[i])!r} cos({omega} t) + "
            f"{float(orbit.harmonic_sin[i])!r} sin({omega} t)  (modulus {float(orbit.harmonic[i])!r})",
        ]
    lines += [f"Floquet multipliers: max |mu| = {largest:.10g} -> {'stable' if orbit.stable else 'unstable'}",
              f"state (X(0), X'(0)) = {[float(x) for x in orbit.state]}"]
    return "\n".join(lines)


def _curve_output(curve: Any, arguments: argparse.Namespace, epsilon: float, start: float | None,
                  stop: float | None) -> str:
    import numpy as np

    grid = np.linspace(start, stop, TABLE_ROWS) if start is not None else np.array([])
    rows = [(float(w), [float(a) for a in curve.amplitudes(w, epsilon)]) for w in grid]
    if arguments.format == "json":
        data = json.loads(curve.to_json())
        data["evaluated"] = {"epsilon": epsilon, "points": [{"frequency": w, "amplitudes": a} for w, a in rows]}
        return json.dumps(data, indent=2, allow_nan=False)
    if arguments.format == "latex":
        return curve.to_latex()
    text = [repr(curve) if arguments.format != "pretty" else _pretty_curve(curve), ""]
    if rows:
        omega = "Ω" if arguments.format == "pretty" else "Omega"
        text.append(f"steady amplitudes A at eps = {epsilon!r} (order {curve.order}):")
        for w, amplitudes in rows:
            text.append(f"  {omega} = {w:.6g}: " + (", ".join(f"{a:.10g}" for a in amplitudes) or "none"))
    return "\n".join(text)


def _pretty_curve(curve: Any) -> str:
    import sympy

    def show(expression: Any) -> str:
        return sympy.pretty(expression, use_unicode=True)

    return "\n".join([
        f"multiple scales, order {curve.order}: A the amplitude, σ = (Ω − ω0)/ε the detuning",
        "first harmonic of f(A cos θ):", show(curve.first_harmonic),
        "frequency-response relation (= 0):", show(curve.relation),
        "backbone detuning σ_b(A):", show(curve.backbone_detuning),
        "peak amplitude:", show(curve.peak_amplitude),
    ])


def run_forced(arguments: argparse.Namespace, parameters: dict[str, Any]) -> str | tuple[str, int]:
    """Run ``lindstedt forced``; (text, 1) when the numerical method did not succeed."""
    from ..problems.parsing import parse_float

    epsilon = parse_float(arguments.eps, what="--eps")
    if epsilon < 0:
        raise ProblemError(f"--eps must be ≥ 0, got {arguments.eps}")
    problem = _problem(arguments, parameters)
    if arguments.method == "multiple-scales" and not hasattr(problem, "oscillator"):
        raise ProblemError("--method multiple-scales is for one degree of freedom (f given as text); "
                           "an N-dof FORCED.json is computed by --method exact")
    if arguments.method == "multiple-scales":
        from ..methods.multiple_scales import MultipleScales

        if arguments.at is not None:
            raise ProblemError("--at is for --method exact; give --from/--to for the multiple-scales amplitudes")
        if (arguments.start is None) != (arguments.stop is None):
            raise ProblemError("give both --from and --to (or neither, for the closed forms alone)")
        start = stop = None
        if arguments.start is not None:
            _, start, stop = _frequencies(arguments)
        curve = MultipleScales(order=arguments.order).frequency_response(problem)
        if arguments.figure:
            raise ProblemError("--figure draws an exact response: use --method exact (the curve is overlaid)")
        return _curve_output(curve, arguments, epsilon, start, stop)
    if arguments.order != 1:
        raise ProblemError("--order is the multiple-scales order; it goes with --method multiple-scales")
    from ..numerics.forced_response import forced_periodic_orbit, frequency_response

    at, start, stop = _frequencies(arguments)
    if at is not None:
        if arguments.figure:
            raise ProblemError("--figure draws a sweep: give --from/--to instead of --at")
        orbit = forced_periodic_orbit(problem, at, epsilon=epsilon)
        if arguments.format == "json":
            text = orbit.to_json()
        else:
            text = _orbit_text(orbit, arguments.format == "pretty")
        return text if orbit.success else (text, 1)
    if arguments.figure:
        from .demo import _figure_class

        _figure_class(arguments.figure)  # a bad suffix or no matplotlib fails before the computation
    with Progress("forced", unit="point") as progress:
        def report(index: int, orbit: Any) -> None:
            progress.update(status=f"Ω = {orbit.frequency:.6g}, max|u| = {max(orbit.amplitude):.4g}")

        response = frequency_response(problem, start, stop, epsilon=epsilon, callback=report)
        if arguments.figure:
            _draw(response, problem, arguments.figure)
        text = response.to_json() if arguments.format == "json" else _response_text(response, arguments.format == "pretty")
        if arguments.figure and arguments.format != "json":
            text += f"\nfigure written to {arguments.figure}"
        if response.success:
            progress.summary = _summary(response)
    return text if response.success else (text, 1)


def _summary(response: Any) -> str:
    """``214 points, 2 folds`` (the bifurcations by kind, or none)."""
    from collections import Counter

    counts = Counter(event.kind for event in response.bifurcations)
    kinds = ", ".join(f"{count} {kind}{'s' if count > 1 else ''}" for kind, count in counts.items()) or "no bifurcation"
    return f"{len(response)} points, {kinds}"


def _draw(response: Any, problem: Any, path: str) -> None:
    from .. import plot
    from ..methods.multiple_scales import MultipleScales
    from .demo import _figure_class

    figure = _figure_class(path)(figsize=(7, 4.5), layout="tight")
    ax = figure.subplots()
    try:
        curve = MultipleScales(order=1).frequency_response(problem) if hasattr(problem, "oscillator") else None
    except LindstedtError:  # the overlay is optional: a law the method does not take is drawn without it
        curve = None
    plot.frequency_response(response, curve=curve, ax=ax)
    figure.savefig(path)
