"""Problems: what is solved, as frozen validated dataclasses, and the one parser of user text.

* :mod:`~lindstedt.problems.parsing` — the AST-whitelist parser (every user string goes through it);
* :mod:`~lindstedt.problems.oscillator` — ``u'' + ω0² u + ε f(u) = 0``, ``u(0) = a0``, ``u'(0) = 0``;
* :mod:`~lindstedt.problems.piecewise_linear` — a continuous piecewise-linear f split into linear intervals;
* :mod:`~lindstedt.problems.system` — ``M X'' + K X + ε Σ_i w_i f_i(a_iᵀ X − b_i) = 0`` (unilateral springs by default,
  any law per element) and its linear modes;
* :mod:`~lindstedt.problems.couplings` — a polynomial force ``ε g(X)`` turned exactly into elements ``ε w (aᵀX)^d``;
* :mod:`~lindstedt.problems.matrices` — exact matrices read from user input, and their float copies;
* :mod:`~lindstedt.problems.modes` — the linear modes ``K Φ = M Φ diag(λ²)``, float64 then multiprecision;
* :mod:`~lindstedt.problems.structures` — ``M``, ``K`` (``C``) read from ``.npz``/``.mat``/``.mtx`` files, and the
  lowest modes of large sparse models (shift-invert Lanczos);
* :mod:`~lindstedt.problems.beam` — the Euler–Bernoulli beam in cubic Hermite elements with breathing cracks
  (unilateral rotational springs), as a ``UnilateralSystem`` or sparse matrices;
* :mod:`~lindstedt.problems.nnm` — the NNM of one mode of such a system.

The public names are re-exported by :mod:`lindstedt`.
"""
