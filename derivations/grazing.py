#!/usr/bin/env python3
"""|a0| = |b|: grazing regime, linear approximation, validity eps^(-1/2).

Equation (strained time s = omega t)::

    u'' + omega0^2 u + eps max(u - b, 0) = 0,    u(0) = a0 = 1,  u'(0) = 0,   b = 1 or b = -1.

When |a0| = |b| the order-zero gap v_0 - b has a double root (a turning point
touches the switching point): the expansion reduces to the linear approximation
of the side the orbit lives on (omega = omega0 for b = a0, sqrt(omega0^2 + eps)
for b = -a0), valid only on t <= C eps^(-1/2): the true frequency is not
analytic in eps there.

Check: for b = a0 the exact solution is a0 cos(omega0 t), so the expansion must
equal the exact frequency (``lindstedt.references.piecewise_linear_exact_frequency``,
closed-form period, 30 digits) at eps = 1e-2, 1e-3, 1e-4 to within 1e-25; for
b = -a0 the non-analytic remainder is tabulated.

Run::

    python derivations/grazing.py [--order N] [--output DIR] [--format text|latex|json]

prints the coefficients and the check, and writes ``grazing.tex`` and ``grazing.json``
into DIR (default ``derivations/output/``).
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
DIGITS = 30
#: Grazing from outside (b = a0): the exact solution is a0 cos(omega0 t); allowed difference at 30 digits.
EXACT_TOLERANCE = 1e-25
OMEGA0 = sympy.Symbol("omega0", positive=True)  # lindstedt's symbol for an unspecified omega0
EPSILONS = ("1e-2", "1e-3", "1e-4")


def derive(order: int) -> common.Sheet:
    sheet = common.Sheet(
        title=r"Grazing: $|a_{0}| = |b|$",
        equation="u'' + omega0**2*u + epsilon*max(u - b, 0) = 0, u(0) = a0 = 1, b = 1 or b = -1",
    )
    sheet.paragraph(
        r"When $|a_{0}| = |b|$ the order-zero gap $v_0 - b$ has a double root (a turning point touches the "
        r"switching point): the expansion reduces to the \emph{linear approximation} of the side the orbit "
        r"lives on, and it holds only on the shorter time scale $T_\varepsilon \sim \varepsilon^{-1/2}$, "
        r"because the true frequency is not analytic in $\varepsilon$ there."
    )
    cases = (
        ("b = a0", 1, r"$b = a_{0} = 1$: the turning point touches the spring, no contact; $\omega = \omega_{0}$ exactly."),
        ("b = -a0", -1, r"$b = -a_{0} = -1$: always in contact except at the far turning point; linear frequency $\sqrt{\omega_{0}^{2} + \varepsilon}$."),
    )
    table = {}
    for label, b, heading in cases:
        expansion = lindstedt.expand(f"Max(0, u - ({b}))", order=order, a0=1)
        sheet.add_expansion(label, expansion, heading)

        # the truncated omega(eps) = sum_k omega_k eps^k (omega0 = 1) against the exact frequency
        rows, worst = [], 0.0
        for epsilon in EPSILONS:
            exact = references.piecewise_linear_exact_frequency(epsilon, a=1, b=b, a0=1, omega0=1, precision=DIGITS)
            truncated = sum(omega_k.subs(OMEGA0, 1) * sympy.Rational(epsilon) ** k for k, omega_k in enumerate(expansion.omega))
            approximate = mpmath.mpf(str(sympy.N(truncated, DIGITS)))
            difference = exact - approximate
            rows.append({"epsilon": epsilon, "exact": mpmath.nstr(exact, 20), "expansion": mpmath.nstr(approximate, 20),
                         "difference": mpmath.nstr(difference, 6)})
            worst = max(worst, abs(float(difference)))
        table[label] = rows
        sheet.paragraph(
            r"Against the exact frequency ($\omega_0 = 1$, exact period of the piecewise-linear oscillator):" + "\n"
            + common.align([rf"\varepsilon = 10^{{{int(row['epsilon'][2:])}}}:\ \omega_{{\mathrm{{exact}}}} - \omega_{{\le {order}}} "
                            rf"&= {common.sci(float(row['difference']), 3)}" for row in rows])
        )
        if b == 1:  # the exact solution is a0 cos(omega0 t): the expansion must be exact
            sheet.check(label, "omega(epsilon)", "the exact frequency (closed-form period) at epsilon = 1e-2, 1e-3, 1e-4",
                        worst, EXACT_TOLERANCE,
                        latex=(r"$b = a_{0}$", r"$\omega(\varepsilon)$",
                               r"the exact frequency (closed-form period) at $\varepsilon = 10^{-2}, 10^{-3}, 10^{-4}$"))
    sheet.extra["exact_comparison"] = {
        "omega0": "1",
        "note": "exact frequency (closed-form period) minus the truncated expansion; b = -a0 shows the non-analytic remainder",
        "rows": table,
    }
    return sheet


if __name__ == "__main__":
    sys.exit(common.main(sys.modules[__name__]))
