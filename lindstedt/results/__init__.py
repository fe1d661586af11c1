"""Results: frozen, lazy, keep their problem and export themselves (JSON, LaTeX, code).

* :mod:`~lindstedt.results.expansion` — ``Expansion`` of one oscillator (ω_k, α_k, waveforms, evaluators);
* :mod:`~lindstedt.results.nnm` — ``NNMExpansion`` of an N-dof system;
* :mod:`~lindstedt.results.assumptions` — what a derivation assumed, checked on numeric values.
* :mod:`~lindstedt.results.orbit_range` — how far in ε the derivation holds (regime bounds, radius of convergence).

The public names are re-exported by :mod:`lindstedt`.
"""
