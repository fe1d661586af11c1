"""``lindstedt demo``: the tour, each expansion of u'' + ω0² u + ε f(u) = 0 checked against an exact reference.

1. Duffing f = u³ to order N, symbolic a0 and ω0, both normalisations, against
   the Taylor coefficients of the exact frequency (complete elliptic integral K).
2. The unilateral spring f = a·u_+ with symbolic a and ω0 (α1 = 1/2, α2 = −3/16,
   ω2 = −1/(2ω0)³ for a = 1), against the series of the exact period
   (two harmonic half-arcs).
3. A gap f = (u − 1/3)_+ to order 4, exact, against the Cauchy-integral
   Taylor coefficients of the exact piecewise-linear frequency.
4. The waveform: order-2 expansion vs a DOP853 solution over t ∈ [0, 1/ε],
   and (``figure_path``, matplotlib) a figure of the error of orders 0, 1, 2 over time against the exact
   flow (:func:`lindstedt.plot.error_over_time`; PNG, SVG or PDF by the path's suffix).
"""

from __future__ import annotations

import time
from typing import Any

import mpmath
import numpy as np
import sympy

from ..methods.lindstedt_poincare import expand
from ..references.duffing import duffing_frequency_taylor
from ..references.piecewise import piecewise_linear_frequency_taylor, piecewise_linear_frequency_taylor_symbolic
from .._precision import workdps

__all__ = ["run_demo"]


def _verdict(ok: bool) -> str:
    return "agrees" if ok else "DISAGREES"


def run_demo(order: int = 8, figure_path: str | None = None) -> str:
    """Run the tour and return its text.

    Examples
    --------
    >>> "Duffing" in run_demo(order=3)
    True
    """
    if figure_path:
        _figure_class(figure_path)  # a bad suffix or a missing matplotlib fails before the tour, not after it
    started = time.perf_counter()
    lines: list[str] = []
    a0, omega0 = sympy.Symbol("a0", positive=True), sympy.Symbol("omega0", positive=True)

    lines.append(f"1. Duffing  u'' + omega0^2 u + eps u^3 = 0, u(0) = a0, u'(0) = 0   (order {order})")
    for normalization in ("initial", "harmonic"):
        tick = time.perf_counter()
        expansion = expand("u**3", order=order, normalization=normalization)
        omegas = expansion.omega
        elapsed = time.perf_counter() - tick
        reference = duffing_frequency_taylor(order, normalization=normalization)
        exact = all(
            sympy.simplify(value - omega0 * reference[k] * (a0**2 / omega0**2) ** k) == 0 for k, value in enumerate(omegas)
        )
        lines.append(f"   [{normalization}] derived in {elapsed * 1e3:.0f} ms")
        for k in range(1, min(order, 4) + 1):
            lines.append(f"     omega_{k} = {omegas[k]}")
        if order > 4:
            lines.append(f"     ... omega_{order} = {omegas[order]}")
        lines.append(
            f"     vs exact frequency (elliptic K, exact rational Taylor series): omega_1..omega_{order} {_verdict(exact)} exactly"
        )
    latex = expand("u**3", order=2).to_latex()
    lines.append("   LaTeX (order 2):")
    lines.extend("     " + line for line in latex.strip().splitlines()[1:])

    lines.append("")
    lines.append("2. Unilateral spring  u'' + omega0^2 u + eps a u_+ = 0   (order 4)")
    tick = time.perf_counter()
    spring = expand("a*Max(0, u)", order=4, params={"a": None})
    alphas, omegas = spring.alpha, spring.omega
    elapsed = time.perf_counter() - tick
    a = sympy.Symbol("a", real=True)
    lines.append(f"   derived in {elapsed * 1e3:.0f} ms; regime: {spring.regime}, validity T ~ eps^({spring.validity_exponent})")
    lines.append(f"     alpha_1 = {alphas[1]},  alpha_2 = {sympy.simplify(alphas[2])}")
    for k in range(1, 5):
        lines.append(f"     omega_{k} = {sympy.simplify(omegas[k])}")
    epsilon = sympy.Symbol("epsilon")
    series = piecewise_linear_frequency_taylor_symbolic(4, epsilon=epsilon, a=a, omega0=omega0)
    exact = all(sympy.simplify(omegas[k] - series.coeff(epsilon, k)) == 0 for k in range(5))
    lines.append(f"     vs series of the exact period pi/omega0 + pi/sqrt(omega0^2 + eps a): {_verdict(exact)} exactly")
    unit = expand("Max(0, u)", order=2, a0=1, omega0=1)
    lines.append(f"     a = omega0 = 1: alpha_2 = {unit.alpha[2]}, omega_2 = {unit.omega[2]} = -1/(2 omega0)^3")

    lines.append("")
    lines.append("3. Gap  u'' + u + eps (u - 1/3)_+ = 0, u(0) = 1   (order 4, exact closed forms in pi, acos(1/3), sqrt(2))")
    tick = time.perf_counter()
    gap = expand("Max(0, u - 1/3)", order=4, a0=1, omega0=1)
    gap_omegas = gap.omega
    elapsed = time.perf_counter() - tick
    lines.append(f"   derived in {elapsed * 1e3:.0f} ms; contact angle beta = {gap.contact_angles[0]}")
    lines.append(f"     omega_1 = {sympy.simplify(gap_omegas[1])}")
    with workdps(40):
        reference_values = piecewise_linear_frequency_taylor(4, a=1, b=mpmath.mpf(1) / 3, a0=1, precision=40)
        worst = 0.0
        for k in range(1, 5):
            value, _ = reference_values[k]
            ours = mpmath.mpf(sympy.N(gap_omegas[k], 40))
            relative = float(abs(ours - value) / abs(value))
            worst = max(worst, relative)
            lines.append(f"     omega_{k} = {sympy.N(gap_omegas[k], 20)}   exact-period reference {mpmath.nstr(value, 20)}")
    lines.append(f"     largest relative difference: {worst:.1e}")

    lines.append("")
    lines.append("4. Waveform: u(t) ~ sum_{k<=2} eps^k v_k(omega t) vs DOP853 (rtol 1e-12), t in [0, 1/eps]")
    for text, force in (("u**3", lambda x: x**3), ("Max(0, u - 1/3)", lambda x: max(0.0, x - 1 / 3))):
        expansion = expand(text, order=2, a0=1, omega0=1)
        for eps in (0.05, 0.025):
            t = np.linspace(0, 1 / eps, 2000)

            def field(_, state, eps=eps, force=force):
                return [state[1], -state[0] - eps * force(state[0])]

            from scipy.integrate import solve_ivp  # here, not at module level: import lindstedt stays light
            reference = solve_ivp(field, (0, t[-1]), [1.0, 0.0], method="DOP853", t_eval=t, rtol=1e-12, atol=1e-14).y[0]
            error = float(np.max(np.abs(expansion.displacement(t, eps) - reference)))
            lines.append(f"     f = {text:16s} eps = {eps:<6} max error {error:.2e}   (eps^3 = {eps**3:.1e})")

    lines.append("")
    if figure_path:
        _write_figure(figure_path)
        lines.append(f"Figure (error of orders 0, 1, 2 against the exact flow) written to {figure_path}")
    elif _has_matplotlib():
        lines.append("Figures: `lindstedt demo --figure demo.png` draws the error of orders 0-2 (lindstedt.plot).")
    else:
        lines.append("Figures: pip install 'lindstedt[plot]' (matplotlib), then `lindstedt demo --figure demo.png`.")

    lines.append(f"Tour finished in {time.perf_counter() - started:.1f} s.  Next: `lindstedt expand --help`.")
    return "\n".join(lines)


def _has_matplotlib() -> bool:
    import importlib.util

    return importlib.util.find_spec("matplotlib") is not None


def _figure_class(figure_path: str) -> Any:
    """matplotlib's Figure, once the path's suffix is known to be a format it writes (typed errors otherwise)."""
    from .._errors import LindstedtError

    try:
        from matplotlib.figure import Figure  # no pyplot: a file is asked for, never a window
    except ImportError as error:
        raise LindstedtError("--figure needs matplotlib: pip install 'lindstedt[plot]'") from error
    formats = Figure().canvas.get_supported_filetypes()
    suffix = figure_path.rsplit(".", 1)[-1].lower() if "." in figure_path else ""
    if suffix not in formats:
        raise LindstedtError(f"--figure {figure_path!r}: the suffix must name an image format, one of "
                             f"{', '.join('.' + name for name in sorted(formats))} (e.g. demo.png)")
    return Figure


def _write_figure(figure_path: str) -> None:
    """The error of orders 0, 1, 2 of u'' + u + ε (u − 1/3)_+ = 0 against the exact flow, ε = 0.05, t ∈ [0, 1/ε]."""
    from .. import plot

    Figure = _figure_class(figure_path)
    eps = 0.05
    t = np.linspace(0, 1 / eps, 4000)
    figure = Figure(figsize=(7, 4), layout="tight")
    ax = figure.subplots()
    plot.error_over_time([expand("Max(0, u - 1/3)", order=order, a0=1, omega0=1) for order in (0, 1, 2)], eps, t, ax=ax)
    ax.set_title(r"$u'' + u + 0.05\,(u - 1/3)_+ = 0$: error against the exact flow")
    figure.savefig(figure_path)
