#!/usr/bin/env python3
"""Preloaded unilateral spring  u'' + omega0^2 u + eps (u - b)_+ = 0,  b = -1/2 < 0,  u(0) = 1.

Exact coefficients (omega0 = 1); checked against the exact period and the symbolic-kappa closed forms.

Usage::

    python derivations/prestress.py [--order N] [--output DIR]

writes ``prestress.tex`` (LaTeX fragment) and ``prestress.json`` (coefficients, schema
``lindstedt.derivation/1``) into DIR (default ``derivations/output/``) and prints
their paths.  Same as ``lindstedt._derive.derive("prestress", order, DIR)``.
"""

import sys
from pathlib import Path

from lindstedt._derive import script_main

if __name__ == "__main__":
    sys.exit(script_main("prestress", default_output=Path(__file__).resolve().parent / "output"))
