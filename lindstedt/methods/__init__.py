"""Methods: thin objects named after the literature, one verb each, from a problem to a result.

* :mod:`~lindstedt.methods.lindstedt_poincare` — ``LindstedtPoincare.expand`` (strained coordinates for
  one oscillator; chooses the engine and keeps the bounded hierarchy cache);
* :mod:`~lindstedt.methods.strained_coordinates` — ``StrainedCoordinatesNNM.expand`` (NNMs of N-dof
  unilateral systems, seed §4);
* :mod:`~lindstedt.methods.all_modes` — first-order averaging of every mode at once.

The public names are re-exported by :mod:`lindstedt`.
"""
