#!/usr/bin/env python3
"""Hertz contact (u - b)_+^(3/2): without a gap and with b = 1/5, omega_k to 30 digits on the stretched contact arc.

Equation (strained time s = omega t)::

    u'' + omega0^2 u + eps max(u - b, 0)^(3/2) = 0,    u(0) = a0,  u'(0) = 0,   a0 > b.

The force vanishes like (u - b)^(3/2) where the contact ends, so the solution is
not analytic there and the contact angle moves with eps: lindstedt maps the contact
arc to the fixed interval tau = s/s*(eps) in [0, 1] (the weight (u_0 - b)^(3/2)
stays fixed, every correction is analytic in (1 - tau)^(1/2)), solves each order
there numerically at the requested precision, and matches it to the free arc
exactly (the branch hierarchy).

Checks: omega_1 without a gap against the first-order averaging integral in closed
form, Gamma(7/4) / (2 sqrt(pi) Gamma(9/4)); omega_0..omega_N of both variants against
the Taylor coefficients of the exact period (``lindstedt.references.frequency_taylor_coefficients``:
quadrature of the energy integral, tanh-sinh per segment, Chebyshev fit in eps),
within the reference's own error estimate; the exact amplitude scaling of the
gap-free law, omega_k(a0) = omega_k(1) a0^(k/2) (u = a0 w turns eps into eps a0^(1/2)).

Run::

    python derivations/hertz.py [--order N] [--output DIR] [--format text|latex|json]

prints the coefficients and the checks, and writes ``hertz.tex`` and ``hertz.json``
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

DEFAULT_ORDER = 4
#: Digits of the expansion and of the exact-period reference; the agreement required on top of the reference's estimate.
DIGITS = 30
TOLERANCE = 1e-25
VARIANTS = (("no gap", "Max(0, u)**(3/2)", r"$b = 0$"), ("gap b = 1/5", "Max(0, u - 1/5)**(3/2)", r"$b = 1/5$"))


def against_reference(sheet: common.Sheet, label: str, label_latex: str, expansion: lindstedt.Expansion) -> None:
    """omega_0..omega_N against the Taylor coefficients of the exact period, within the reference's estimate."""
    reference = references.frequency_taylor_coefficients(expansion.problem.nonlinearity, expansion.order, a0=1,
                                                         omega0=1, precision=DIGITS)
    with mpmath.workdps(DIGITS + 10):
        excess = max(abs(mpmath.mpf(sympy.Float(value, DIGITS + 10)) - exact) - error
                     for value, (exact, error) in zip(expansion.omega, reference))
    quantity, quantity_latex = common.omega_range(expansion.order)
    text = f"the Taylor coefficients of the exact period (quadrature, {DIGITS} digits), beyond its error estimate"
    sheet.check(label, quantity, text, max(float(excess), 0.0), TOLERANCE, latex=(label_latex, quantity_latex, text))


def derive(order: int) -> common.Sheet:
    sheet = common.Sheet(
        title=r"Hertz contact: $f(u) = (u - b)_{+}^{3/2}$",
        equation="u'' + omega0**2*u + epsilon*max(u - b, 0)**(3/2) = 0, u(0) = a0 > b, u'(0) = 0",
    )
    sheet.paragraph(
        r"The force vanishes like $(u - b)^{3/2}$ where the contact ends: the solution is not analytic there and the "
        r"contact angle $s^*(\varepsilon)$ moves. The contact arc is mapped to $\tau = s/s^*(\varepsilon) \in [0, 1]$, where "
        r"$\mu Y'' + Y + \varepsilon (Y - \kappa)^{3/2} = 0$, $\mu = \Omega^2/s^{*2}$, $Y(1) = \kappa$: the factor "
        r"$(Y_0 - \kappa)^{3/2}$ stays a fixed weight and every $Y_n$ is analytic in $(1 - \tau)^{1/2}$; each order is "
        rf"solved there with {DIGITS} digits and matched to the free arc, whose branches are exact."
    )
    expansions = {}
    for label, law, label_latex in VARIANTS:
        expansion = lindstedt.expand(law, order=order, a0=1, omega0=1, precision=DIGITS)
        expansions[label] = expansion
        sheet.add_expansion(label, expansion, label_latex + ", $a_0 = \\omega_0 = 1$.")
        against_reference(sheet, label, label_latex, expansion)

    # omega_1 of the gap-free law from the averaging integral (1/2 pi) int cos^(5/2) s ds over the contact arc
    gap_free = expansions["no gap"]
    closed_form = sympy.gamma(sympy.Rational(7, 4)) / (2 * sympy.sqrt(sympy.pi) * sympy.gamma(sympy.Rational(9, 4)))
    difference = abs(sympy.N(gap_free.omega[1] - closed_form, DIGITS + 5))
    text = r"the averaging integral Gamma(7/4) / (2 sqrt(pi) Gamma(9/4))"
    sheet.check("no gap", "omega_1", text, float(difference), TOLERANCE,
                latex=(r"$b = 0$", r"$\omega_1$", r"the averaging integral $\Gamma(7/4)/(2\sqrt{\pi}\,\Gamma(9/4))$"))

    # the amplitude scaling of the gap-free law: omega_k(a0) = omega_k(1) a0^(k/2)
    scaled = lindstedt.expand("Max(0, u)**(3/2)", order=order, a0=4, omega0=1, precision=DIGITS)
    difference = max(abs(sympy.N(value - reference * 2**k, DIGITS)) / 2**k
                     for k, (value, reference) in enumerate(zip(scaled.omega, gap_free.omega)))
    text = "the exact scaling omega_k(a0) = omega_k(1) a0^(k/2), at a0 = 4"
    sheet.check("no gap", "omega_k(4)", text, float(difference), TOLERANCE,
                latex=(r"$b = 0$", r"$\omega_k(a_0 = 4)$", r"the exact scaling $\omega_k(a_0) = \omega_k(1)\, a_0^{k/2}$"))
    return sheet


if __name__ == "__main__":
    sys.exit(common.main(sys.modules[__name__]))
