#!/usr/bin/env python3
"""Preloaded spring (u - b)_+ with b = -1/2 < 0, a0 = omega0 = 1, exact.

Equation (strained time s = omega t)::

    u'' + omega0^2 u + eps max(u + 1/2, 0) = 0,    u(0) = 1,  u'(0) = 0,   omega0 = 1.

With b < 0 the spring is already compressed at u = 0: it is in contact for u > b,
most of the period (kappa = b/a0 = -1/2, contact angle 2 pi/3).

Checks: omega_0..omega_N against the Taylor coefficients of the exact period
(``lindstedt.references.piecewise_linear_frequency_taylor``, 40 digits,
|difference| <= 1e-20), and the symbolic-kappa closed forms of ``gap.py`` at
kappa = -1/2.

Run::

    python derivations/prestress.py [--order N] [--output DIR] [--format text|latex|json]

prints the coefficients and the checks, and writes ``prestress.tex`` and
``prestress.json`` into DIR (default ``derivations/output/``).
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
gap = common.load("gap")  # the symbolic-kappa closed forms derived there

DEFAULT_ORDER = 3
REFERENCE_DIGITS = 40
REFERENCE_TOLERANCE = 1e-20


def derive(order: int) -> common.Sheet:
    sheet = common.Sheet(
        title=r"Prestressed unilateral spring: $f(u) = (u - b)_{+}$, $b = -\frac{1}{2} < 0$",
        equation="u'' + omega0**2*u + epsilon*max(u + 1/2, 0) = 0, u(0) = 1, u'(0) = 0",
    )
    sheet.paragraph(
        r"With $b < 0$ the spring is already compressed at $u = 0$: it is in contact for $u > b$, "
        r"most of the period. Here $a_{0} = \omega_{0} = 1$, $\kappa = -1/2$, contact angle $2\pi/3$."
    )
    kappa = sympy.Rational(-1, 2)
    expansion = lindstedt.expand("Max(0, u + 1/2)", order=order, a0=1, omega0=1)
    sheet.add_expansion("kappa = -1/2", expansion)

    # check 1: the Taylor coefficients of the exact frequency 2 pi / period, by a Cauchy integral
    with mpmath.workdps(REFERENCE_DIGITS):
        reference = references.piecewise_linear_frequency_taylor(order, a=1, b=kappa, a0=1, omega0=1, precision=REFERENCE_DIGITS)
        difference = max(abs(mpmath.mpf(str(sympy.N(omega_k, REFERENCE_DIGITS))) - reference[k][0])
                         for k, omega_k in enumerate(expansion.omega))
    quantity, quantity_latex = common.omega_range(order)
    reference_text = f"the Taylor coefficients of the exact period (Cauchy integral, {REFERENCE_DIGITS} digits)"
    sheet.check("kappa = -1/2", quantity, reference_text, difference, REFERENCE_TOLERANCE,
                latex=(r"$\kappa = -1/2$", quantity_latex, reference_text))

    # check 2: gap.py's closed forms in kappa hold for b < 0 too
    gap.check_closed_forms(sheet, "kappa = -1/2", r"$\kappa = -1/2$", expansion, kappa)
    return sheet


if __name__ == "__main__":
    sys.exit(common.main(sys.modules[__name__]))
