#!/usr/bin/env python3
"""Nonlinear normal modes of  M X'' + K X + eps A^T (A X - b)_+ = 0  for a chain of 5 unit masses.

Springs chosen here: mass 1 with zero gap, mass 4 preloaded (b = -1/5); every mode: omega_0 .. omega_N, a_k;
omega_1 cross-checked with Theorem 4.3.

Usage::

    python derivations/nnm_5dof.py [--order N] [--output DIR]

writes ``nnm_5dof.tex`` (LaTeX fragment) and ``nnm_5dof.json`` (coefficients, schema
``lindstedt.derivation/1``) into DIR (default ``derivations/output/``) and prints
their paths.  Same as ``lindstedt._derive.derive("nnm_5dof", order, DIR)``.
"""

import sys
from pathlib import Path

from lindstedt._derive import script_main

if __name__ == "__main__":
    sys.exit(script_main("nnm_5dof", default_output=Path(__file__).resolve().parent / "output"))
