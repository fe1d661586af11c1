#!/usr/bin/env python3
"""Gap (u - 1/3)_+ released on the far side, a0 = -1, exact.

Equation (strained time s = omega t)::

    u'' + omega0^2 u + eps max(u - 1/3, 0) = 0,    u(0) = -1,  u'(0) = 0,   omega0 = 1.

Released at a0 = -1 < 0 the mass meets the spring half a period later, around
s = pi.  At first order only the orbit of v_0 matters, so omega_1 equals that of
the release at a0 = +1 (the ``gap`` case); from omega_2 on they differ (the two
releases lie on different orbits).

Check: omega_0..omega_N against the Taylor coefficients of the exact period
(``lindstedt.references.piecewise_linear_frequency_taylor``, 40 digits,
|difference| <= 1e-20).

Run::

    python derivations/negative_release.py [--order N] [--output DIR] [--format text|latex|json]

prints the coefficients and the check, and writes ``negative_release.tex`` and
``negative_release.json`` into DIR (default ``derivations/output/``).
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import mpmath
import sympy

import lindstedt
from lindstedt import references


def _helper():
    """derivations/_common.py, loaded from next to this file (the script runs from any directory)."""
    name = "lindstedt_derivations_common"
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, Path(__file__).resolve().with_name("_common.py"))
        sys.modules[name] = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(sys.modules[name])
    return sys.modules[name]


common = _helper()

DEFAULT_ORDER = 3
REFERENCE_DIGITS = 40
REFERENCE_TOLERANCE = 1e-20


def derive(order: int) -> common.Sheet:
    sheet = common.Sheet(
        title=r"Release on the far side: $f(u) = (u - \frac{1}{3})_{+}$, $a_{0} = -1$",
        equation="u'' + omega0**2*u + epsilon*max(u - 1/3, 0) = 0, u(0) = -1, u'(0) = 0",
    )
    sheet.paragraph(
        r"Released at $a_{0} = -1 < 0$ ($\omega_{0} = 1$) the mass meets the spring half a period later, "
        r"around $s = \pi$. At first order only the orbit of $v_0$ matters, so $\omega_1$ equals that of the release "
        r"at $a_{0} = +1$; from $\omega_2$ on they differ (the two releases lie on different orbits)."
    )
    expansion = lindstedt.expand("Max(0, u - 1/3)", order=order, a0=-1, omega0=1)
    sheet.add_expansion("a0 = -1", expansion)

    # check: the Taylor coefficients of the exact frequency 2 pi / period, by a Cauchy integral
    with mpmath.workdps(REFERENCE_DIGITS):
        reference = references.piecewise_linear_frequency_taylor(
            order, a=1, b=sympy.Rational(1, 3), a0=-1, omega0=1, precision=REFERENCE_DIGITS
        )
        difference = max(abs(mpmath.mpf(str(sympy.N(omega_k, REFERENCE_DIGITS))) - reference[k][0])
                         for k, omega_k in enumerate(expansion.omega))
    quantity, quantity_latex = common.omega_range(order)
    reference_text = f"the Taylor coefficients of the exact period (Cauchy integral, {REFERENCE_DIGITS} digits)"
    sheet.check("a0 = -1", quantity, reference_text, difference, REFERENCE_TOLERANCE,
                latex=(r"$a_{0} = -1$", quantity_latex, reference_text))

    # comparison with the release at a0 = +1 (the gap case): same omega_1, different omega_2
    mirror = lindstedt.expand("Max(0, u - 1/3)", order=min(order, 2), a0=1, omega0=1)
    differences = [sympy.Integer(0) if k == 0 else sympy.N(expansion.omega[k] - mirror.omega[k], common.DECIMAL_DIGITS)
                   for k in range(mirror.order + 1)]
    sheet.paragraph(
        "Comparison with the release at $a_{0} = +1$ (the \\texttt{gap} case):\n"
        + common.align([rf"\omega_{{{k}}}(a_0 = -1) - \omega_{{{k}}}(a_0 = +1) &\approx {sympy.N(value, common.LATEX_DIGITS)}"
                        for k, value in enumerate(differences) if k])
    )
    sheet.extra["comparison_with_positive_release"] = {
        "omega_difference": [str(value) for value in differences],
        "note": "omega_k(a0 = -1) - omega_k(a0 = +1), same f",
    }
    return sheet


if __name__ == "__main__":
    sys.exit(common.main(sys.modules[__name__]))
