#!/usr/bin/env python3
"""Nonlinear normal modes of  M X'' + K X + eps A^T (A X - b)_+ = 0  for a chain of 2 unit masses.

One zero-gap unilateral spring on mass 1; every mode: omega_0 .. omega_N and the release a_k;
omega_1 cross-checked with Theorem 4.3.

Usage::

    python derivations/nnm_2dof.py [--order N] [--output DIR]

writes ``nnm_2dof.tex`` (LaTeX fragment) and ``nnm_2dof.json`` (coefficients, schema
``lindstedt.derivation/1``) into DIR (default ``derivations/output/``) and prints
their paths.  Same as ``lindstedt._derive.derive("nnm_2dof", order, DIR)``.
"""

import sys
from pathlib import Path

from lindstedt._derive import script_main

if __name__ == "__main__":
    sys.exit(script_main("nnm_2dof", default_output=Path(__file__).resolve().parent / "output"))
