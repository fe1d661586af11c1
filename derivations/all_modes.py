#!/usr/bin/env python3
"""All modes excited  M X'' + K X + eps A^T (A X - b)_+ = 0,  chain of 3 unit masses (Theorem 4.3).

First-order corrections lambda_k^1 with u_k(0) = (1, 1/2, 1/4): zero gaps (closed form, checked against
the NNMs) and with a gap 1/10 on mass 3 (almost-periodic averages).

Usage::

    python derivations/all_modes.py [--order N] [--output DIR]

writes ``all_modes.tex`` (LaTeX fragment) and ``all_modes.json`` (coefficients, schema
``lindstedt.derivation/1``) into DIR (default ``derivations/output/``) and prints
their paths.  Same as ``lindstedt._derive.derive("all_modes", order, DIR)``.
"""

import sys
from pathlib import Path

from lindstedt._derive import script_main

if __name__ == "__main__":
    sys.exit(script_main("all_modes", default_output=Path(__file__).resolve().parent / "output"))
