#!/usr/bin/env python3
"""Unilateral spring with a gap  u'' + omega0^2 u + eps (u - b)_+ = 0,  b > 0,  u(0) = a0,  u'(0) = 0.

kappa = b/a0 = 1/3 exactly (a0 = omega0 = 1), plus the closed forms of omega_1, omega_2 for
symbolic kappa; checked against the Taylor coefficients of the exact period.

Usage::

    python derivations/gap.py [--order N] [--output DIR]

writes ``gap.tex`` (LaTeX fragment) and ``gap.json`` (coefficients, schema
``lindstedt.derivation/1``) into DIR (default ``derivations/output/``) and prints
their paths.  Same as ``lindstedt._derive.derive("gap", order, DIR)``.
"""

import sys
from pathlib import Path

from lindstedt._derive import script_main

if __name__ == "__main__":
    sys.exit(script_main("gap", default_output=Path(__file__).resolve().parent / "output"))
