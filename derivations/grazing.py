#!/usr/bin/env python3
"""Grazing  u'' + omega0^2 u + eps (u - b)_+ = 0 with |a0| = |b|  (a0 = 1, b = 1 and b = -1).

Regime "grazing": the linear approximation, valid on t <= C eps^(-1/2); compared with the exact frequency.

Usage::

    python derivations/grazing.py [--order N] [--output DIR]

writes ``grazing.tex`` (LaTeX fragment) and ``grazing.json`` (coefficients, schema
``lindstedt.derivation/1``) into DIR (default ``derivations/output/``) and prints
their paths.  Same as ``lindstedt._derive.derive("grazing", order, DIR)``.
"""

import sys
from pathlib import Path

from lindstedt._derive import script_main

if __name__ == "__main__":
    sys.exit(script_main("grazing", default_output=Path(__file__).resolve().parent / "output"))
