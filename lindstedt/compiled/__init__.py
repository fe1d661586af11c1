"""Compiled float evaluation, below the results and the export layer (internal layout, behind the facade).

* :mod:`~lindstedt.compiled.family` — :func:`compile_family`: closed forms compiled once into a vectorised
  float64 evaluator with a first-order bound of its rounding error (the float evaluators of an expansion);
* :mod:`~lindstedt.compiled.stable_series` — the exact series in acos κ of a gap coefficient ω_k(κ), stable
  in float64 where its closed form cancels (κ → ±1, interior roots);
* :mod:`~lindstedt.compiled.stable_source` — those series as NumPy and C source, and as a NumPy function;
* :mod:`~lindstedt.compiled.names` — the names generated source may use in each target language.

The results evaluate through it; :mod:`lindstedt.export.codegen` prints through it.
"""
