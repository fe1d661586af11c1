"""lindstedt: exact Lindstedt–Poincaré (strained coordinates) expansions of weakly nonlinear oscillators.

The public API is re-exported here and in the documented public subpackages:

* :mod:`lindstedt.references` — independent exact references (Duffing, unilateral
  spring, quadrature of a conservative oscillator, NNM release amplitudes);
* :mod:`lindstedt.validate` — expansions against the true solution (errors,
  convergence orders, validity times, contact measure, spectra);
* :mod:`lindstedt.algebra` — the exact algebra (cosine series, the contact Fourier
  kernel of ``(cos s − κ)_+`` and ``H(cos s − κ)``);
* :mod:`lindstedt.numerics` — the exact piecewise-linear flow and NNMs by shooting;
* :mod:`lindstedt.limits` — bounded work: the budget of a request (time, memory), its cost estimate
  before it runs, cancellation and progress while it runs;
* :mod:`lindstedt.plot` — figures on matplotlib (backbone, waveform, spectra, convergence, NNM branches);
* :mod:`lindstedt.cli` — the ``lindstedt`` command (``python -m lindstedt``).

Behind the facade the package is laid out as the pipeline: ``problems/`` →
``methods/`` → ``engine/`` → ``results/`` (on ``render/``, their display and JSON
primitives, and ``compiled/``, their float evaluators) → ``export/`` (their public
names are re-exported here); the imports go one way, without a circle, and no module
is over 800 lines (``tests/test_import_graph.py``); modules whose names start with an
underscore are private.

Examples
--------
>>> import lindstedt
>>> lindstedt.expand("u**3", order=2, a0=1, omega0=1).omega
(1, 3/8, -21/256)
"""

from ._errors import (
    BudgetError,
    Cancelled,
    ConvergenceError,
    LindstedtError,
    OrderError,
    ParameterError,
    ProblemError,
    ResonanceError,
    UnsupportedNonlinearityError,
)

# Lazy facade (PEP 562): a public name is imported from its module on first use, so
# `import lindstedt` (and the CLI's --help) costs the interpreter, not sympy/numpy/mpmath.
_LAZY = {
    "methods.all_modes": ("AllModesFirstOrder", "all_modes_first_order"),
    "_precision": ("precision_lock",),
    "methods.lindstedt_poincare": ("LindstedtPoincare", "cache_info", "clear_cache", "expand", "expansion_cost"),
    "export.codegen": ("CodeGenerationError", "GeneratedCode", "generate_code"),
    "algebra.cosine": ("CosineSeries", "SineSeries", "solve_harmonic_oscillator"),
    "results.expansion": ("Expansion", "ExpansionValidityWarning", "PiecewiseWaveform", "Waveform"),
    "numerics.flow": ("ExactFlow",),
    "results.nnm": ("NNMExpansion",),
    "problems.nnm": ("NNMProblem",),
    "methods.strained_coordinates": ("StrainedCoordinatesNNM", "nnm"),
    "numerics": ("NNMBranch", "NNMResult", "continue_nnm", "nnm_point", "nnm_sweep", "seed_example_system",
                 "FrequencyResponse", "ForcedOrbit", "forced_flow", "forced_periodic_orbit", "frequency_response",
                 "switch_period_doubling"),
    "problems.oscillator": ("Oscillator",),
    "problems.forced": ("ForcedOscillator", "ForcedSystem"),
    "methods.multiple_scales": ("MultipleScales", "frequency_response_curve"),
    "results.frequency_response": ("FrequencyResponseCurve",),
    "problems.system": ("Modes", "UnilateralSystem"),
    "problems.structures": ("read_matrices", "sparse_modes"),
    "problems.beam": ("EulerBernoulliBeam",),
    "problems.reduction": ("ResidualFlexibility", "ReducedStructure"),
    "validate": (
        "Spectrum",
        "contact_measure",
        "exact_spectrum",
        "expansion_error",
        "expansion_spectrum",
        "fitted_convergence_order",
        "fitted_validity_exponent",
        "reference_solution",
        "spectrum",
    ),
}
_MODULE_OF = {name: module for module, names in _LAZY.items() for name in names}


def __getattr__(name: str):
    module = _MODULE_OF.get(name)
    if module is None:
        raise AttributeError(f"module 'lindstedt' has no attribute {name!r}")
    import importlib

    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value  # later lookups skip __getattr__
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_MODULE_OF))


__version__ = "0.1.0"

__all__ = [
    "expand",
    "clear_cache",
    "cache_info",
    "precision_lock",
    "nnm",
    "all_modes_first_order",
    "AllModesFirstOrder",
    "Oscillator",
    "UnilateralSystem",
    "Modes",
    "read_matrices",
    "sparse_modes",
    "EulerBernoulliBeam",
    "ResidualFlexibility",
    "ReducedStructure",
    "StrainedCoordinatesNNM",
    "NNMProblem",
    "NNMExpansion",
    "ExactFlow",
    "nnm_point",
    "continue_nnm",
    "nnm_sweep",
    "NNMResult",
    "NNMBranch",
    "seed_example_system",
    "ForcedOscillator",
    "ForcedSystem",
    "MultipleScales",
    "frequency_response_curve",
    "FrequencyResponseCurve",
    "forced_flow",
    "forced_periodic_orbit",
    "ForcedOrbit",
    "frequency_response",
    "FrequencyResponse",
    "switch_period_doubling",
    "reference_solution",
    "expansion_error",
    "fitted_convergence_order",
    "fitted_validity_exponent",
    "contact_measure",
    "spectrum",
    "Spectrum",
    "expansion_spectrum",
    "exact_spectrum",
    "LindstedtPoincare",
    "Expansion",
    "ExpansionValidityWarning",
    "Waveform",
    "PiecewiseWaveform",
    "generate_code",
    "GeneratedCode",
    "CosineSeries",
    "SineSeries",
    "solve_harmonic_oscillator",
    "LindstedtError",
    "ProblemError",
    "ParameterError",
    "UnsupportedNonlinearityError",
    "OrderError",
    "ResonanceError",
    "ConvergenceError",
    "CodeGenerationError",
    "BudgetError",
    "Cancelled",
    "expansion_cost",
]
