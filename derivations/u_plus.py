#!/usr/bin/env python3
"""Unilateral spring a*u_+: symbolic a, a0, omega0, exact check against the period.

Equation (strained time s = omega t)::

    u'' + omega0^2 u + eps a max(u, 0) = 0,    u(0) = a0 > 0,  u'(0) = 0,

with symbolic stiffness a, amplitude a0 and omega0.  The frequency does not
depend on a0: the exact period is pi/omega0 + pi/sqrt(omega0^2 + eps a) (two
harmonic half-arcs).

Check: omega_0..omega_N equal, exactly, the Taylor coefficients of 2 pi / period
(``lindstedt.references.piecewise_linear_frequency_taylor_symbolic``).

Run::

    python derivations/u_plus.py [--order N] [--output DIR] [--format text|latex|json]

prints the coefficients and the check, and writes ``u_plus.tex`` and ``u_plus.json``
into DIR (default ``derivations/output/``).
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

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

DEFAULT_ORDER = 4
OMEGA0 = sympy.Symbol("omega0", positive=True)  # lindstedt's symbol for an unspecified omega0
EPSILON = sympy.Symbol("epsilon")


def derive(order: int) -> common.Sheet:
    sheet = common.Sheet(
        title=r"Unilateral spring without gap: $f(u) = a\,u_{+}$",
        equation="u'' + omega0**2*u + epsilon*a*max(u, 0) = 0, u(0) = a0, u'(0) = 0",
    )
    sheet.paragraph(
        r"Symbolic stiffness $a$, amplitude $a_{0} > 0$ and $\omega_{0}$. The frequency does not depend on $a_{0}$: "
        r"the exact period is $\pi/\omega_{0} + \pi/\sqrt{\omega_{0}^{2} + \varepsilon a}$ (two harmonic half-arcs)."
    )
    expansion = lindstedt.expand("a*Max(0, u)", order=order, params={"a": None})
    sheet.add_expansion("a u_+", expansion)

    # the series of the exact frequency, in the same symbol a as the expansion
    a = next(symbol for symbol in expansion.problem.free_symbols if symbol.name == "a")
    series = references.piecewise_linear_frequency_taylor_symbolic(order, epsilon=EPSILON, a=a, omega0=OMEGA0)
    equal = all(sympy.simplify(omega_k - series.coeff(EPSILON, k)) == 0 for k, omega_k in enumerate(expansion.omega))
    quantity, quantity_latex = common.omega_range(order)
    sheet.check_exact(
        "a u_+", quantity, "the Taylor series of the exact period pi/omega0 + pi/sqrt(omega0**2 + epsilon*a)", equal,
        latex=(r"$a\,u_{+}$", quantity_latex,
               r"the Taylor series of the exact period $\pi/\omega_{0} + \pi/\sqrt{\omega_{0}^{2} + \varepsilon a}$"),
    )
    return sheet


if __name__ == "__main__":
    sys.exit(common.main(sys.modules[__name__]))
