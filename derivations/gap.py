#!/usr/bin/env python3
"""Gap (u - b)_+ with b > 0: kappa = b/a0 = 1/3 exactly, plus symbolic-kappa closed forms of omega_1, omega_2.

Equation (strained time s = omega t)::

    u'' + omega0^2 u + eps max(u - b, 0) = 0,    u(0) = a0,  u'(0) = 0,   b > 0.

The spring engages only while u > b.  With kappa = b/a0 = 1/3 (a0 = omega0 = 1)
every coefficient is an exact closed form in pi, arccos(1/3) and sqrt(2).  Then
omega_1, omega_2 for symbolic kappa (|kappa| < 1, either sign of b), written with
beta = arccos(kappa) (the contact angle) and sigma = sqrt(1 - kappa^2) = sin(beta):
:func:`closed_forms`, also used by ``prestress.py``.

Checks: omega_0..omega_N against the Taylor coefficients of the exact period
(``lindstedt.references.piecewise_linear_frequency_taylor``, Cauchy integral at 40
digits, |difference| <= 1e-20), and the kappa closed forms at kappa = 1/3 against
the exact derivation (40 digits, 1e-20).

Run::

    python derivations/gap.py [--order N] [--output DIR] [--format text|latex|json]

prints the coefficients and the checks, and writes ``gap.tex`` and ``gap.json``
into DIR (default ``derivations/output/``).
"""

from __future__ import annotations

import functools
import importlib.util
import sys
from pathlib import Path

import mpmath
import sympy

import lindstedt
from lindstedt import references
from lindstedt.algebra import in_contact_angles


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
#: Working digits of the exact-period reference, and the agreement required from it.
REFERENCE_DIGITS = 40
REFERENCE_TOLERANCE = 1e-20
OMEGA0 = sympy.Symbol("omega0", positive=True)  # lindstedt's symbol for an unspecified omega0
KAPPA = sympy.Symbol("kappa", real=True)
BETA = sympy.Symbol("beta", positive=True)
SIGMA = sympy.Symbol("sigma", positive=True)


@functools.cache
def closed_forms() -> tuple[sympy.Expr, sympy.Expr]:
    """(omega_1, omega_2) of u'' + omega0^2 u + eps (u - b)_+ = 0, u(0) = a0 > 0, as functions of kappa = b/a0 (|kappa| < 1):
    the exact omega_k(b) at a0 = 1 in kappa, beta = acos(kappa), sigma = sqrt(1 - kappa^2)
    (:func:`lindstedt.algebra.in_contact_angles`, reduced modulo sigma^2 = 1 - kappa^2)."""
    expansion = lindstedt.expand("Max(0, u - b)", order=2, a0=1, params={"b": None})
    form = in_contact_angles(expansion.omega[1:])
    return form.forms


def at_kappa(form: sympy.Expr, kappa: sympy.Expr) -> sympy.Expr:
    """A closed form at a given kappa."""
    return form.subs({KAPPA: kappa, BETA: sympy.acos(kappa), SIGMA: sympy.sqrt(1 - kappa**2)})


def check_closed_forms(sheet: common.Sheet, label: str, label_latex: str, expansion: lindstedt.Expansion,
                       kappa: sympy.Expr) -> None:
    """The symbolic-kappa omega_1, omega_2 at this kappa against the exact derivation (omega0 = 1), to 40 digits."""
    difference = max(
        abs(sympy.N(at_kappa(form, kappa).subs(OMEGA0, 1) - expansion.omega[k + 1], REFERENCE_DIGITS))
        for k, form in enumerate(closed_forms()[: expansion.order])
    )
    sheet.check(label, "omega_1, omega_2", f"the symbolic-kappa closed forms at kappa = {kappa}", difference,
                REFERENCE_TOLERANCE, latex=(label_latex, r"$\omega_{1}, \omega_{2}$",
                                            rf"the symbolic-$\kappa$ closed forms at $\kappa = {common.latex(kappa)}$"))


def derive(order: int) -> common.Sheet:
    sheet = common.Sheet(
        title=r"Unilateral spring with a gap: $f(u) = (u - b)_{+}$, $b > 0$",
        equation="u'' + omega0**2*u + epsilon*max(u - b, 0) = 0, u(0) = a0, u'(0) = 0",
    )
    sheet.paragraph(
        r"The spring engages only while $u > b$. With $\kappa = b/a_{0} = 1/3$ ($a_{0} = \omega_{0} = 1$) "
        r"every coefficient is an exact closed form in $\pi$, $\arccos\frac{1}{3}$ and $\sqrt{2}$."
    )
    kappa = sympy.Rational(1, 3)
    expansion = lindstedt.expand("Max(0, u - 1/3)", order=order, a0=1, omega0=1)
    sheet.add_expansion("kappa = 1/3", expansion, r"$\kappa = 1/3$.")

    # check 1: the Taylor coefficients of the exact frequency 2 pi / period, by a Cauchy integral
    with mpmath.workdps(REFERENCE_DIGITS):
        reference = references.piecewise_linear_frequency_taylor(order, a=1, b=kappa, a0=1, omega0=1, precision=REFERENCE_DIGITS)
        difference = max(abs(mpmath.mpf(str(sympy.N(omega_k, REFERENCE_DIGITS))) - reference[k][0])
                         for k, omega_k in enumerate(expansion.omega))
    quantity, quantity_latex = common.omega_range(order)
    reference_text = f"the Taylor coefficients of the exact period (Cauchy integral, {REFERENCE_DIGITS} digits)"
    sheet.check("kappa = 1/3", quantity, reference_text, difference, REFERENCE_TOLERANCE,
                latex=(r"$\kappa = 1/3$", quantity_latex, reference_text))

    # the closed forms for symbolic kappa
    forms = closed_forms()
    sheet.paragraph(
        r"\paragraph{Symbolic $\kappa$.} For $a_{0} > 0$ and $|\kappa| < 1$, with $\kappa = b/a_{0}$, "
        r"$\beta = \arccos\kappa$ (the contact angle) and $\sigma = \sqrt{1-\kappa^{2}} = \sin\beta$, "
        r"the closed forms (independent of $a_{0}$ at fixed $\kappa$; $b < 0$ is the prestressed spring) are" + "\n"
        + common.align([rf"\omega_{{{k + 1}}} &= {common.latex(form)}" for k, form in enumerate(forms)])
    )
    sheet.extra["closed_forms"] = {
        "equation": "u'' + omega0**2*u + epsilon*max(u - b, 0) = 0, u(0) = a0 > 0, u'(0) = 0",
        "valid_for": "|kappa| < 1",
        "definitions": {"kappa": "b/a0", "beta": "acos(kappa)", "sigma": "sqrt(1 - kappa**2)"},
        "omega": {f"omega_{k + 1}": sympy.sstr(form) for k, form in enumerate(forms)},
    }
    # check 2: the closed forms at kappa = 1/3 give back the exact omega_1, omega_2
    check_closed_forms(sheet, "kappa = 1/3", r"$\kappa = 1/3$", expansion, kappa)
    return sheet


if __name__ == "__main__":
    sys.exit(common.main(sys.modules[__name__]))
