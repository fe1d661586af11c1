#!/usr/bin/env python3
"""Duffing u'' + omega0^2 u + eps u^3 = 0: symbolic a0, omega0, both normalisations, exact check.

Equation (strained time s = omega t)::

    u'' + omega0^2 u + eps u^3 = 0,    u'(0) = 0,

with symbolic amplitude a0 and linear frequency omega0, in the two amplitude
normalisations: *initial* (u(0) = a0, every v_k(0) = 0) and *harmonic* (a0 is
the amplitude of the first harmonic, no cos s in v_k for k >= 1).

Check: omega_0..omega_N equal, exactly, the Taylor series of the exact frequency
(complete elliptic integral K; ``lindstedt.references.duffing_frequency_taylor``
gives the coefficients c_k of omega = omega0 sum_k c_k (eps a0^2/omega0^2)^k as
exact rationals).

Run::

    python derivations/duffing.py [--order N] [--output DIR] [--format text|latex|json]

prints the coefficients and the check, and writes ``duffing.tex`` and ``duffing.json``
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

DEFAULT_ORDER = 6
#: lindstedt's symbols for an unspecified amplitude and linear frequency.
A0, OMEGA0 = sympy.symbols("a0 omega0", positive=True)


def derive(order: int) -> common.Sheet:
    sheet = common.Sheet(
        title=r"Duffing oscillator: $f(u) = u^{3}$",
        equation="u'' + omega0**2*u + epsilon*u**3 = 0, u'(0) = 0",
    )
    sheet.paragraph(
        r"Symbolic amplitude $a_{0}$ and linear frequency $\omega_{0}$. Two normalisations of the amplitude: "
        r"\emph{initial} ($u(0) = a_{0}$, every $v_k(0) = 0$) and \emph{harmonic} ($a_{0}$ is the amplitude "
        r"of the first harmonic, no $\cos s$ in $v_k$, $k \ge 1$). They agree at first order and differ from $\omega_2$ on."
    )
    quantity, quantity_latex = common.omega_range(order)
    reference_text = "the Taylor series of the exact frequency (complete elliptic integral K, exact rationals)"
    for normalization, heading in (("initial", r"Initial normalisation, $u(0) = a_{0}$."),
                                   ("harmonic", r"Harmonic normalisation, $a_{0}$ = first-harmonic amplitude.")):
        expansion = lindstedt.expand("u**3", order=order, normalization=normalization)
        sheet.add_expansion(normalization, expansion, heading)

        # omega_k = omega0 c_k (a0^2/omega0^2)^k exactly
        c = references.duffing_frequency_taylor(order, normalization=normalization)
        equal = all(sympy.simplify(omega_k - OMEGA0 * c[k] * (A0**2 / OMEGA0**2) ** k) == 0
                    for k, omega_k in enumerate(expansion.omega))
        sheet.check_exact(normalization, quantity, reference_text, equal,
                          latex=(f"{normalization.capitalize()} normalisation", quantity_latex, reference_text))
    return sheet


if __name__ == "__main__":
    sys.exit(common.main(sys.modules[__name__]))
