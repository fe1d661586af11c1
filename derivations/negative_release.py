#!/usr/bin/env python3
"""Release on the far side  u'' + omega0^2 u + eps (u - 1/3)_+ = 0,  u(0) = -1,  u'(0) = 0.

Exact coefficients (omega0 = 1), compared with the release at +1; checked against the exact period.

Usage::

    python derivations/negative_release.py [--order N] [--output DIR]

writes ``negative_release.tex`` (LaTeX fragment) and ``negative_release.json`` (coefficients, schema
``lindstedt.derivation/1``) into DIR (default ``derivations/output/``) and prints
their paths.  Same as ``lindstedt._derive.derive("negative_release", order, DIR)``.
"""

import sys
from pathlib import Path

from lindstedt._derive import script_main

if __name__ == "__main__":
    sys.exit(script_main("negative_release", default_output=Path(__file__).resolve().parent / "output"))
