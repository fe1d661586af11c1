#!/usr/bin/env python3
"""NNMs of a 2-mass chain with a zero-gap unilateral spring: every mode, omega_0..omega_N, a_k.

Equation::

    M X'' + K X + eps A^T (A X - b)_+ = 0,   M = I, K = [[2, -1], [-1, 2]], A = [1, 0], b = 0:

two unit masses between fixed walls, unit springs, one unilateral spring of
stiffness eps on mass 1 with zero gap (it pushes back while X_1 > 0).  Each
nonlinear normal mode (Theorem 4.1) is sought with one strained time
s = omega t, omega = sum_n omega_n eps^n, omega_0 = lambda_j, released from rest
at u_j(0) = a0 = 1, u_k(0) = eps a_k (modal coordinates X = Phi U); the a_k are
outputs that make every correction periodic.  :func:`modes` is also used by
``nnm_5dof.py``.

Check: omega_1 of mode j against Theorem 4.3 with only mode j excited
(``lindstedt.all_modes_first_order``; zero gaps: closed form, tolerance 1e-12).

Run::

    python derivations/nnm_2dof.py [--order N] [--output DIR] [--format text|latex|json]

prints the coefficients and the checks, and writes ``nnm_2dof.tex`` and
``nnm_2dof.json`` into DIR (default ``derivations/output/``).
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np
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

DEFAULT_ORDER = 2
MAX_ORDER = 12
#: Working digits of the strained-coordinates arithmetic.
PRECISION = 30
#: Agreement required between the NNM omega_1 and Theorem 4.3's lambda^1 for a single excited mode:
#: exact closed form for zero gaps, Hann-windowed average (accuracy ~1e-7) otherwise.
TOLERANCE = {"closed form (zero gaps)": 1e-12, "almost-periodic average": 1e-6}


def modes(sheet: common.Sheet, system: lindstedt.UnilateralSystem, order: int, a0: int) -> None:
    """Every NNM of ``system`` at modal amplitude ``a0``, each checked against Theorem 4.3."""
    lambdas = system.modes().frequencies
    sheet.paragraph(
        "Linear frequencies: " + ", ".join(rf"$\lambda_{{{k + 1}}} = {value:.12g}$" for k, value in enumerate(lambdas))
        + r". Each NNM is sought with one strained time $s = \omega t$, $\omega = \sum_n \omega_n \varepsilon^n$, "
        r"$\omega_0 = \lambda_j$, released from rest at $u_j(0) = a_{0}$, $u_k(0) = \varepsilon a_k$ ($k \ne j$, modal "
        r"coordinates $X = \Phi U$, $\Phi^{T} M \Phi = I$); the $a_k$ are outputs that make every correction periodic."
    )
    for mode in range(1, system.n_dof + 1):
        result = lindstedt.nnm(system, mode, sympy.Integer(a0), order, precision=PRECISION)
        sheet.add_nnm(f"mode {mode}", result)
        if order >= 1:  # Theorem 4.3 with this mode alone excited gives the same omega_1
            amplitudes = np.zeros(system.n_dof)
            amplitudes[mode - 1] = 1.0
            first_order = lindstedt.all_modes_first_order(system, amplitudes)
            value, _ = first_order.corrections[mode - 1]
            method = first_order.methods[mode - 1]
            reference = f"Theorem 4.3 with only mode {mode} excited, {method}"
            sheet.check(f"mode {mode}", "omega_1", reference, abs(float(result.omega[1]) - value), TOLERANCE[method],
                        latex=(f"Mode {mode}", r"$\omega_{1}$", reference))


def derive(order: int) -> common.Sheet:
    system = lindstedt.UnilateralSystem.chain(2, unilateral=[(0, 0)])
    sheet = common.Sheet(
        title=r"Nonlinear normal modes of a 2-mass chain with a unilateral spring",
        equation="M X'' + K X + epsilon A^T (A X - b)_+ = 0, chain of 2 unit masses, zero-gap spring on mass 1",
    )
    sheet.paragraph(common.system_latex(
        system, r"Two unit masses between fixed walls, unit springs; one unilateral spring of stiffness $\varepsilon$ "
                r"on mass 1 with zero gap (it pushes back while $X_1 > 0$). Modal amplitude $a_{0} = 1$ (with a zero gap "
                r"the $\omega_n$ do not depend on it)."))
    modes(sheet, system, order, 1)
    sheet.extra["system"] = {"definition": system.to_json_dict(), "a0": 1,
                             "springs": [{"mass": 1, "gap": "0", "engages_while": "X_1 > 0"}],
                             "lambda": [float(value) for value in system.modes().frequencies]}
    return sheet


if __name__ == "__main__":
    sys.exit(common.main(sys.modules[__name__]))
