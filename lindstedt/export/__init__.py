"""Export: reads the results and writes them for other programs — generated code (NumPy, C, Octave, Julia,
Fortran, Rust, JAX) from any result through one dispatch (codegen.py, its targets in _targets.py) and pandas
tables (tables.py).  The results show themselves (``to_json``, ``to_latex``, Jupyter) through ``lindstedt.render``.

The public names are re-exported by :mod:`lindstedt`.
"""
