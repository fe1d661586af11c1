"""An expansion for programs and for the eye: its JSON dictionary, its ``repr`` and its plain-text summary
(LaTeX: :mod:`lindstedt.results._latex`).

JSON schema ``lindstedt.expansion/1`` (:meth:`Expansion.to_dict`)::

    {
      "schema": "lindstedt.expansion/1",
      "problem": {"equation": str, "f": str, "a0": str, "a1": str, "omega0": str,
                  "parameters": {name: str}, "normalization": str},
      "order": int, "normalization": "initial" | "harmonic",
      "gauge": "epsilon" | "sqrt(epsilon)",    # ω(ε) = Σ_k ω_k gauge^k
      "exponents": [str, ...],        # the power of ε of each ω_k: k, or k/2
      "omega": [str, ...],            # ω_0..ω_N (ω_0..ω_2N in the gauge ε^(1/2)), sympy-parsable
      "omega_float": [float | null],  # null where symbolic
      "alpha": [str, ...], "alpha_float": [float | null],
      "omega_next": str,              # ω_{N+1}, used by the displacement evaluator
      "waveforms": [{"order": k, "cosine_coefficients": {"n": str}}]   # optional; piecewise f:
                   [{"order": k, "breakpoints": [str], "pieces": [str], "interval": str}]
      "regime", "validity_exponent", "contact_angles"                   # piecewise f only
      # from u0, v0 only: "problem" also has "u0", "v0"; and
      "solution": str, "amplitude": [str], "amplitude_float": [float | null],   # A_k
      "phase": [str], "phase_float": [float | null]                            # φ_k
    }

Functions of an :class:`~lindstedt.Expansion`, typed ``Any``: :mod:`lindstedt.results.expansion` imports this
module, never the other way round.
"""

from __future__ import annotations

from typing import Any

import sympy

from .._precision import locked
from ..render.display import labelled_repr, shorten
from ..render.json import finite_float
from ._readable import readable_coefficients
from .waveforms import PiecewiseWaveform

__all__ = ["SCHEMA", "expansion_dict", "expansion_repr", "expansion_summary"]

SCHEMA = "lindstedt.expansion/1"


@locked
def _as_float(expression: sympy.Expr) -> float | None:
    """The float of a numeric coefficient for JSON; None when symbolic, or beyond a float's range (JSON has no inf)."""
    return None if expression.free_symbols else finite_float(expression)


def expansion_repr(expansion: Any) -> str:
    """The problem, the order and ω_k (each cut to a few hundred characters; ``.omega[k]`` is the full one)."""
    fields = [("problem", repr(expansion.problem.describe())), ("order", str(expansion.order))]
    try:
        if expansion._steps != 1:
            fields.append(("gauge", str(expansion.gauge)))
        omega = ", ".join(shorten(sympy.sstr(value), 160, f".omega[{k}]") for k, value in enumerate(expansion.omega))
        fields.append(("omega", f"({omega})"))
        if expansion.is_piecewise:
            fields.append(("regime", repr(expansion.regime)))
    except Exception as error:  # a repr never raises: show why the coefficients are missing
        fields.append(("omega", f"<not available: {type(error).__name__}: {shorten(str(error), 120)}>"))
    return labelled_repr("Expansion", fields, field_limit=1200)


def expansion_dict(expansion: Any, waveforms: bool) -> dict[str, Any]:
    """The documented JSON-ready dictionary (schema ``lindstedt.expansion/1``)."""
    problem = expansion.problem
    data: dict[str, Any] = {
        "schema": SCHEMA,
        "problem": {
            "equation": "u'' + omega0**2*u + epsilon*f(u) = 0, u(0) = a0 + epsilon*a1, u'(0) = 0",
            "f": sympy.sstr(problem.f),
            "a0": sympy.sstr(problem.a0),
            "a1": sympy.sstr(problem.a1),
            "omega0": sympy.sstr(problem.omega0),
            "parameters": {str(symbol): sympy.sstr(value) for symbol, value in problem.params},
            "normalization": problem.normalization,
        },
        "order": expansion.order,
        "normalization": problem.normalization,
        "gauge": sympy.sstr(expansion.gauge),
        "exponents": [str(value) for value in expansion.exponents],
        "omega": [sympy.sstr(value) for value in expansion.omega],
        "omega_float": [_as_float(value) for value in expansion.omega],
        "alpha": [sympy.sstr(value) for value in expansion.alpha],
        "alpha_float": [_as_float(value) for value in expansion.alpha],
        "omega_next": sympy.sstr(expansion.omega_next),
    }
    if problem.has_initial_velocity:
        data["problem"]["equation"] = "u'' + omega0**2*u + epsilon*f(u) = 0, u(0) = u0, u'(0) = v0"
        data["problem"]["u0"] = sympy.sstr(problem.u0)
        data["problem"]["v0"] = sympy.sstr(problem.v0)
        data["solution"] = "u(t) = v(omega*t + phase; epsilon), v(0; epsilon) = amplitude (positive turning point)"
        data["amplitude"] = [sympy.sstr(value) for value in expansion.amplitude]
        data["amplitude_float"] = [_as_float(value) for value in expansion.amplitude]
        data["phase"] = [sympy.sstr(value) for value in expansion.phase]
        data["phase_float"] = [_as_float(value) for value in expansion.phase]
    if waveforms:
        data["waveforms"] = [
            w.to_dict()
            if isinstance(w, PiecewiseWaveform)
            else {"order": w.order, "cosine_coefficients": {str(n): sympy.sstr(c) for n, c in w.coefficients}}
            for w in expansion.waveforms
        ]
    if expansion.is_piecewise:
        data["regime"] = expansion.regime
        data["validity_exponent"] = str(expansion.validity_exponent)
        data["contact_angles"] = [sympy.sstr(value) for value in expansion.contact_angles]
    if waveforms and expansion.stretched_arcs:
        data["stretched_arcs"] = [arc.to_dict() for arc in expansion.stretched_arcs]
    return data


def expansion_summary(expansion: Any) -> str:
    """Plain-text summary: the problem and ω_0..ω_N (in the contact angles, defined once, when they have any)."""
    definitions, omega, amplitude, phase = readable_coefficients(expansion)
    lines = [expansion.problem.describe()]
    if definitions:
        lines.append("  where " + ", ".join(f"{symbol} = {value}" for symbol, value in definitions))
    if expansion._steps != 1:
        lines.append(f"  omega(eps) = sum_k omega_k {expansion.gauge}**k (grazing: not analytic in eps)")
    for k, value in enumerate(omega):
        lines.append(f"  omega_{k} = {value}")
    if expansion.problem.has_initial_velocity:
        lines.append("  u(t) = v(omega*t + phi(eps); eps), released at the turning point A(eps) = v(0; eps) > 0")
        lines += [f"  A_{k} = {value}" for k, value in enumerate(amplitude)]
        lines += [f"  phi_{k} = {value}" for k, value in enumerate(phase)]
    return "\n".join(lines)
