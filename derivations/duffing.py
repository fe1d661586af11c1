#!/usr/bin/env python3
"""Duffing oscillator  u'' + omega0^2 u + eps u^3 = 0,  u(0) = a0,  u'(0) = 0.

Symbolic a0 and omega0, both amplitude normalisations (initial, harmonic); checked exactly
against the Taylor series of the exact (elliptic-integral) frequency.

Usage::

    python derivations/duffing.py [--order N] [--output DIR]

writes ``duffing.tex`` (LaTeX fragment) and ``duffing.json`` (coefficients, schema
``lindstedt.derivation/1``) into DIR (default ``derivations/output/``) and prints
their paths.  Same as ``lindstedt._derive.derive("duffing", order, DIR)``.
"""

import sys
from pathlib import Path

from lindstedt._derive import script_main

if __name__ == "__main__":
    sys.exit(script_main("duffing", default_output=Path(__file__).resolve().parent / "output"))
