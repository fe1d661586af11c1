#!/usr/bin/env python3
"""Unilateral spring without gap  u'' + omega0^2 u + eps a u_+ = 0,  u(0) = a0,  u'(0) = 0.

Symbolic a, a0 and omega0; checked exactly against the series of the exact period
pi/omega0 + pi/sqrt(omega0^2 + eps a).

Usage::

    python derivations/u_plus.py [--order N] [--output DIR]

writes ``u_plus.tex`` (LaTeX fragment) and ``u_plus.json`` (coefficients, schema
``lindstedt.derivation/1``) into DIR (default ``derivations/output/``) and prints
their paths.  Same as ``lindstedt._derive.derive("u_plus", order, DIR)``.
"""

import sys
from pathlib import Path

from lindstedt._derive import script_main

if __name__ == "__main__":
    sys.exit(script_main("u_plus", default_output=Path(__file__).resolve().parent / "output"))
