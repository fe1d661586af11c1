"""The engine: the hierarchies that solve the Lindstedt–Poincaré equations order by order.

* :mod:`~lindstedt.engine.orders` — the lazy order loop and the truncated ε-series
  shared by every hierarchy (Ω = √(Σ A_k ε̂^k), powers of a moving boundary shift);
* :mod:`~lindstedt.engine.smooth` — smooth f: cosine series, the secular condition on cos s;
* :mod:`~lindstedt.engine.branches` — piecewise-polynomial systems with moving contact
  boundaries: one branch hierarchy generic over its N components and its number field;
* :mod:`~lindstedt.engine.stretched` — contact arcs under a fractional power law (Hertz) or an analytic law in
  stretched time: one implementation for N components (:class:`~lindstedt.engine.stretched.VectorArc`; N = 1 for
  the oscillator);
* :mod:`~lindstedt.engine.float_branches` — the float image of a branch hierarchy, for fast waveforms;
* :mod:`~lindstedt.engine.contact` and :mod:`~lindstedt.engine.modal` — the normal forms that
  feed it: a 1-dof oscillator (N = 1) and the NNM of an N-dof system with elements of any law
  polynomial between breakpoints, or Hertz.
"""
