"""Results: frozen, lazy, keep their problem and show themselves (JSON, LaTeX, Jupyter); export reads them (code).

* :mod:`~lindstedt.results.expansion` — ``Expansion`` of one oscillator (ω_k, α_k, waveforms, metadata), with
  :mod:`~lindstedt.results.waveforms` (the exact v_k), its float evaluators (``_evaluators``, on ``_values`` and
  ``_coefficients``), its phase and turning-point series (``_phase``), LaTeX (``_latex``) and JSON/repr (``_views``);
* :mod:`~lindstedt.results.nnm` — ``NNMExpansion`` of an N-dof system;
* :mod:`~lindstedt.results.frequency_response` — ``FrequencyResponseCurve`` of a forced oscillator;
* :mod:`~lindstedt.results.assumptions` — what a derivation assumed, checked on numeric values;
* :mod:`~lindstedt.results.orbit_range` — how far in ε the derivation holds (regime bounds, radius of convergence).

Results import neither the methods nor :mod:`lindstedt.export`; their primitives for display and JSON are in
``lindstedt.render``, their compiled float machinery in ``lindstedt.compiled``.  The public names are
re-exported by :mod:`lindstedt`.
"""
