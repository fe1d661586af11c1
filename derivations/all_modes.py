#!/usr/bin/env python3
"""Theorem 4.3: first-order corrections with all modes of a 3-mass chain excited.

Equation::

    M X'' + K X + eps A^T (A X - b)_+ = 0,   M = I, K = tridiag(-1, 2, -1) (3 x 3),

every mode released at once, u_k(0) = a_k with (a_1, a_2, a_3) = (1, 1/2, 1/4),
velocities zero, each mode strained separately:
u_k(t) ~ a_k cos(lambda_k^eps t), lambda_k^eps = lambda_k + eps lambda_k^1, with
lambda_k^1 = c_k / (2 lambda_k a_k) and c_k the cos(lambda_k t) component of the
almost-periodic forcing.  Two settings: one zero-gap spring on mass 1 (closed form
lambda_k^1 = G_k1 B_1k / (4 lambda_k), independent of the amplitudes), and with an
extra spring of gap 1/10 on mass 3 (Hann-windowed averages with error estimates).
Valid for t = o(1/eps).  Order 1 only.

Check (zero gaps): lambda_k^1 against the omega_1 of the NNM of mode k
(``lindstedt.nnm``, 30 digits; the same closed form), tolerance 1e-12.

Run::

    python derivations/all_modes.py [--output DIR] [--format text|latex|json]

prints the corrections and the checks, and writes ``all_modes.tex`` and
``all_modes.json`` into DIR (default ``derivations/output/``).
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import sympy

import lindstedt


def _helper():
    """derivations/_common.py, loaded from next to this file (the script runs from any directory)."""
    name = "lindstedt_derivations_common"
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, Path(__file__).resolve().with_name("_common.py"))
        sys.modules[name] = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(sys.modules[name])
    return sys.modules[name]


common = _helper()

DEFAULT_ORDER = 1
MAX_ORDER = 1
AMPLITUDES = [1.0, 0.5, 0.25]
#: Working digits of the NNM reference, and the agreement required (zero gaps: the same closed form).
PRECISION = 30
TOLERANCE = 1e-12
SETTINGS = (
    ("zero gaps", [(0, 0)], (r"One zero-gap spring on mass 1: closed form $\lambda_k^{1} = G_{k1} B_{1k}/(4\lambda_k)$ "
                             r"($B = A\Phi$, $G = \Phi^{T} A^{T}$), independent of the amplitudes.")),
    ("with a gap", [(0, 0), (2, "1/10")], (r"Add a spring with gap $1/10$ on mass 3: Hann-windowed almost-periodic "
                                           r"averages, with error estimates.")),
)


def derive(order: int) -> common.Sheet:
    sheet = common.Sheet(
        title=r"All modes excited: first-order corrections (Theorem 4.3), 3-mass chain",
        equation="M X'' + K X + epsilon A^T (A X - b)_+ = 0, chain of 3 unit masses, u_k(0) = a_k for every mode",
    )
    sheet.paragraph(
        r"Every mode is released at once, $u_k(0) = a_k$ with $(a_1, a_2, a_3) = (1, \tfrac12, \tfrac14)$, velocities zero, "
        r"and each mode is strained separately: $u_k(t) \approx a_k \cos(\lambda_k^{\varepsilon} t)$, "
        r"$\lambda_k^{\varepsilon} = \lambda_k + \varepsilon \lambda_k^{1}$, with "
        r"$\lambda_k^{1} = c_k/(2\lambda_k a_k)$ and $c_k$ the $\cos(\lambda_k t)$ component of the almost-periodic forcing. "
        r"First terms: $X(t) \approx \Phi\, (a_k \cos(\lambda_k^{\varepsilon} t))_k$. "
        r"Validity: $t = o(\varepsilon^{-1})$ (weaker than for a single NNM)."
    )
    for name, springs, text in SETTINGS:
        system = lindstedt.UnilateralSystem.chain(3, unilateral=springs)
        result = lindstedt.all_modes_first_order(system, AMPLITUDES)
        lines = []
        for k, (lam, (value, error), method) in enumerate(zip(result.lambdas, result.corrections, result.methods)):
            estimate = rf"\ (\pm {common.sci(error)})" if error else ""
            lines.append(rf"\lambda_{{{k + 1}}} = {lam:.12g},\quad \lambda_{{{k + 1}}}^{{1}} &= {value:.12g}{estimate}")
            sheet.omega[f"{name}, mode {k + 1}"] = [repr(lam), repr(value)]
            sheet.omega_float[f"{name}, mode {k + 1}"] = [lam, value]
        sheet.paragraph(rf"\paragraph{{{name.capitalize()}.}} " + text + "\n" + common.system_latex(system, "") + "\n"
                        + common.align(lines))
        sheet.variants.append({
            "label": name,
            "system": system.to_json_dict(),
            "amplitudes": AMPLITUDES,
            "lambda": list(result.lambdas),
            "corrections": [{"mode": k + 1, "lambda_1": value, "error_estimate": error, "method": method}
                            for k, ((value, error), method) in enumerate(zip(result.corrections, result.methods))],
            "validity": {"exponent": "-1", "time_scale": "t = o(1/epsilon)"},
            "averaging_time": result.averaging_time,
            "message": result.message,
        })
        if name == "zero gaps":  # each lambda_k^1 is the omega_1 of the NNM of mode k
            for k, (value, _) in enumerate(result.corrections):
                single = lindstedt.nnm(system, k + 1, sympy.Integer(1), 1, precision=PRECISION)
                reference = f"the NNM omega_1 of mode {k + 1} (zero gaps: the same closed form)"
                sheet.check(f"{name}, mode {k + 1}", "lambda_1", reference, abs(float(single.omega[1]) - value), TOLERANCE,
                            latex=(f"{name.capitalize()}, mode {k + 1}", rf"$\lambda_{{{k + 1}}}^{{1}}$",
                                   rf"the NNM $\omega_{{1}}$ of mode {k + 1} (zero gaps: the same closed form)"))
    return sheet


if __name__ == "__main__":
    sys.exit(common.main(sys.modules[__name__]))
