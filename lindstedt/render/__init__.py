"""How results show themselves, below the results (internal layout): text, LaTeX and HTML for people, JSON for programs.

* :mod:`~lindstedt.render.display` — short ``__repr__`` text, Jupyter LaTeX, HTML tables;
* :mod:`~lindstedt.render.json` — :func:`~lindstedt.render.json.to_jsonable` and the
  :class:`~lindstedt.render.json.JsonExport` mixin every result class exports itself through.

Results (and the numerical results of :mod:`lindstedt.numerics`, :mod:`lindstedt.validate`) import these
primitives; :mod:`lindstedt.export` reads the results.
"""
