#!/usr/bin/env python3
"""|a0| = |b|: grazing — a turning point of the unperturbed orbit touches the spring's gap.

Equation (strained time s = omega t)::

    u'' + omega0^2 u + eps max(u - b, 0) = 0,    u(0) = a0 = 1,  u'(0) = 0,   b = 1 or b = -1.

When |a0| = |b| the order-zero gap v_0 - b has a double root.  For b = a0 the
release point touches the gap from outside and the orbit never enters it: the
solution is a0 cos(omega0 t) exactly.  For b = -a0 the orbit is in contact except
at the far turning point; for eps > 0 the perturbed orbit dips past the gap for
a time O(eps^(1/2)) each period, so omega(eps) is not analytic: the expansion is
in powers of eps^(1/2), with the first non-analytic term -8/(3 pi) eps^(5/2)
(omega0 = 1), and its error falls with the order on t <= C/eps.

Checks against the exact frequency (``lindstedt.references.piecewise_linear_exact_frequency``,
closed-form period of the piecewise-linear oscillator, 30 digits) at eps = 1e-2, 1e-3,
1e-4: for b = a0 the expansion equals it to within 1e-25; for b = -a0, and for the
release just inside the gap (u(0) = 1 + eps, seed Prop. 2.3), the remainder stays within
twice the first neglected term.

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
EPSILON = sympy.Symbol("epsilon", real=True)  # lindstedt's symbol for eps in frequency_expr
#: b = -a0: the remainder over the first neglected term tends to 1 as eps -> 0; at eps = 1e-2 the
#: next terms add at most |omega_{k+1}/omega_k| eps^(1/2) <= 0.7 (order 1: -1/8 eps^2 then -8/(3 pi) eps^(5/2)).
REMAINDER_RATIO = 2.0
LATEX_LABELS = {"b = -a0": r"$b = -a_{0}$", "b = a0, a1 = 1": r"$b = a_{0},\ a_{1} = 1$"}


def derive(order: int) -> common.Sheet:
    sheet = common.Sheet(
        title=r"Grazing: $|a_{0}| = |b|$",
        equation="u'' + omega0**2*u + epsilon*max(u - b, 0) = 0, u(0) = a0 = 1, b = 1 or b = -1",
    )
    sheet.paragraph(
        r"When $|a_{0}| = |b|$ the order-zero gap $v_0 - b$ has a double root: a turning point touches the "
        r"switching point.  If the perturbed orbit stays on its side, the expansion is the analytic one of that "
        r"side; if it passes the switching point, it does so for a time $O(\varepsilon^{1/2})$ per period and "
        r"$\omega(\varepsilon)$ is expanded in powers of $\varepsilon^{1/2}$."
    )
    cases = (
        ("b = a0", 1, 0, r"$b = a_{0} = 1$: the release point touches the spring, no contact; $\omega = \omega_{0}$ exactly."),
        ("b = -a0", -1, 0, r"$b = -a_{0} = -1$: in contact except at the far turning point, which the perturbed orbit "
                           r"passes: a free arc of length $O(\varepsilon^{1/2})$ opens there."),
        ("b = a0, a1 = 1", 1, 1, r"$b = a_{0} = 1$, released just inside the gap at $u(0) = 1 + \varepsilon$ (seed Prop. 2.3): "
                                 r"a contact arc of length $O(\varepsilon^{1/2})$ around the release point; the linear "
                                 r"approximation $\omega_0$ misses a term $\propto \varepsilon^{5/2}$."),
    )
    table = {}
    for label, b, a1, heading in cases:
        expansion = lindstedt.expand(f"Max(0, u - ({b}))", order=order, a0=1, a1=a1)
        sheet.add_expansion(label, expansion, heading)

        # the truncated omega(eps) = sum_k omega_k gauge^k (omega0 = 1) against the exact frequency
        gauge = expansion.gauge
        truncated = expansion.frequency_expr().subs(OMEGA0, 1)
        # the first neglected nonzero term, to compare the remainder with
        next_terms = [expansion.omega_correction(k).subs(OMEGA0, 1) * gauge**k for k in range(len(expansion.omega), len(expansion.omega) + 4)]
        first_neglected = next((term for term in next_terms if term != 0), sympy.Integer(0))
        rows, worst = [], 0.0
        for epsilon in EPSILONS:
            with mpmath.workdps(DIGITS):  # the difference of two 30-digit numbers, taken at 30 digits
                row, ratio = _compare(epsilon, b, a1, truncated, first_neglected)
            rows.append(row)
            worst = max(worst, ratio)
        table[label] = rows
        sheet.paragraph(
            r"Against the exact frequency ($\omega_0 = 1$, exact period of the piecewise-linear oscillator):" + "\n"
            + common.align([rf"\varepsilon = 10^{{{int(row['epsilon'][2:])}}}:\ \omega_{{\mathrm{{exact}}}} - \omega_{{\le {order}}} "
                            rf"&= {common.sci(float(row['difference']), 3)}" for row in rows])
        )
        if b == 1 and not a1:  # the exact solution is a0 cos(omega0 t): the expansion must be exact
            sheet.check(label, "omega(epsilon)", "the exact frequency (closed-form period) at epsilon = 1e-2, 1e-3, 1e-4",
                        worst, EXACT_TOLERANCE,
                        latex=(r"$b = a_{0}$", r"$\omega(\varepsilon)$",
                               r"the exact frequency (closed-form period) at $\varepsilon = 10^{-2}, 10^{-3}, 10^{-4}$"))
        else:  # asymptotic: the remainder is the first neglected term plus smaller ones
            sheet.check(label, "|omega_exact - omega_N| / |first neglected term|",
                        "the exact frequency (closed-form period) at epsilon = 1e-2, 1e-3, 1e-4", worst, REMAINDER_RATIO,
                        latex=(LATEX_LABELS[label], r"$|\omega_{\mathrm{exact}} - \omega_{\le N}| / |\text{first neglected term}|$",
                               r"the exact frequency (closed-form period) at $\varepsilon = 10^{-2}, 10^{-3}, 10^{-4}$"))
    sheet.extra["exact_comparison"] = {
        "omega0": "1",
        "note": "exact frequency (closed-form period) minus the truncated expansion, and the first neglected term",
        "rows": table,
    }
    return sheet


def _compare(epsilon: str, b: int, a1: int, truncated: sympy.Expr, first_neglected: sympy.Expr) -> tuple[dict, float]:
    """One row of the table and the checked number: |difference| (b = a0) or |difference| / |first neglected term|."""
    release = 1 + a1 * mpmath.mpf(epsilon)  # u(0) = a0 + eps a1
    exact = references.piecewise_linear_exact_frequency(epsilon, a=1, b=b, a0=release, omega0=1, precision=DIGITS)
    value = sympy.Rational(epsilon)
    approximate = mpmath.mpf(str(sympy.N(truncated.subs(EPSILON, value), DIGITS)))
    neglected = abs(mpmath.mpf(str(sympy.N(first_neglected.subs(EPSILON, value), DIGITS))))
    difference = exact - approximate
    row = {"epsilon": epsilon, "exact": mpmath.nstr(exact, 20), "expansion": mpmath.nstr(approximate, 20),
           "difference": mpmath.nstr(difference, 6), "first_neglected_term": mpmath.nstr(neglected, 6)}
    return row, abs(float(difference)) if (b == 1 and not a1) else float(abs(difference) / neglected)


if __name__ == "__main__":
    sys.exit(common.main(sys.modules[__name__]))
