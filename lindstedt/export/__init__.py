"""Export: generated code (NumPy, C) from any result through one dispatch, and the SVG line plots.

The public names are re-exported by :mod:`lindstedt`.
"""
