#!/usr/bin/env python3
"""NNMs of a 5-mass chain, springs on mass 1 (gap 0) and mass 4 (preload b = -1/5): every mode.

Equation::

    M X'' + K X + eps A^T (A X - b)_+ = 0,   M = I, K = tridiag(-1, 2, -1) (5 x 5),
    A = [e_1; e_4], b = (0, -1/5):

five unit masses between fixed walls joined by unit springs.  The seed does not
fix the springs; our choice: a zero-gap spring on mass 1 (engaged while X_1 > 0)
and a preloaded spring with b = -1/5 on mass 4 (engaged while X_4 > -1/5) --
``lindstedt.UnilateralSystem.chain(5, unilateral=[(0, 0), (3, "-1/5")])``, the
chain of the top-level README; modal amplitude a0 = 1.  The same derivation as
``nnm_2dof.py`` (its :func:`modes`) for every mode.

Check: omega_1 of mode j against Theorem 4.3 with only mode j excited
(``lindstedt.all_modes_first_order``; with a gap: Hann-windowed average,
tolerance 1e-6).

Run::

    python derivations/nnm_5dof.py [--order N] [--output DIR] [--format text|latex|json]

prints the coefficients and the checks, and writes ``nnm_5dof.tex`` and
``nnm_5dof.json`` into DIR (default ``derivations/output/``).
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

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
nnm_2dof = common.load("nnm_2dof")  # every mode of a chain, checked against Theorem 4.3

DEFAULT_ORDER = 2
MAX_ORDER = 12


def derive(order: int) -> common.Sheet:
    system = lindstedt.UnilateralSystem.chain(5, unilateral=[(0, 0), (3, "-1/5")])
    sheet = common.Sheet(
        title=r"Nonlinear normal modes of a 5-mass chain with two unilateral springs",
        equation="M X'' + K X + epsilon A^T (A X - b)_+ = 0, chain of 5 unit masses, zero-gap spring on mass 1, "
                 "preloaded spring (b = -1/5) on mass 4",
    )
    sheet.paragraph(common.system_latex(
        system, r"The seed's $N$-degree-of-freedom setting, with our choice of springs (the seed does not fix them): "
                r"five unit masses between fixed walls joined by unit springs; unilateral springs of stiffness "
                r"$\varepsilon$ on mass 1 with zero gap (engaged while $X_1 > 0$) and on mass 4 with the gap "
                r"$b = -1/5$ (preloaded: engaged while $X_4 > -1/5$). Modal amplitude $a_{0} = 1$."))
    nnm_2dof.modes(sheet, system, order, 1)
    sheet.extra["system"] = {"definition": system.to_json_dict(), "a0": 1,
                             "springs": [{"mass": 1, "gap": "0", "engages_while": "X_1 > 0"},
                                         {"mass": 4, "gap": "-1/5", "engages_while": "X_4 > -1/5"}],
                             "lambda": [float(value) for value in system.modes().frequencies]}
    return sheet


if __name__ == "__main__":
    sys.exit(common.main(sys.modules[__name__]))
