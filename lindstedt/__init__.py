"""lindstedt: exact Lindstedt–Poincaré (strained coordinates) expansions of weakly nonlinear oscillators.

The public API is re-exported here and in the documented public subpackages:

* :mod:`lindstedt.references` — independent exact references (Duffing, unilateral
  spring, quadrature of a conservative oscillator, NNM release amplitudes);
* :mod:`lindstedt.validate` — expansions against the true solution (errors,
  convergence orders, validity times, contact measure, spectra);
* :mod:`lindstedt.algebra` — the exact algebra (cosine series, the contact Fourier
  kernel of ``(cos s − κ)_+`` and ``H(cos s − κ)``);
* :mod:`lindstedt.numerics` — the exact piecewise-linear flow and NNMs by shooting;
* :mod:`lindstedt.cli` — the ``lindstedt`` command (``python -m lindstedt``).

Behind the facade the package is laid out as the pipeline: ``problems/`` →
``methods/`` → ``engine/`` → ``results/`` → ``export/`` (their public names are
re-exported here); modules whose names start with an underscore are private.

Examples
--------
>>> import lindstedt
>>> lindstedt.expand("u**3", order=2, a0=1, omega0=1).omega
(1, 3/8, -21/256)
"""

from .methods.all_modes import AllModesFirstOrder, all_modes_first_order
from .methods.lindstedt_poincare import LindstedtPoincare, cache_info, clear_cache, expand
from .export.codegen import CodeGenerationError, GeneratedCode, generate_code
from .algebra.cosine import CosineSeries, SineSeries, solve_harmonic_oscillator
from ._errors import (
    ConvergenceError,
    LindstedtError,
    OrderError,
    ParameterError,
    ProblemError,
    ResonanceError,
    UnsupportedNonlinearityError,
)
from .results.expansion import Expansion, ExpansionValidityWarning, PiecewiseWaveform, Waveform
from .numerics.flow import ExactFlow
from .results.nnm import NNMExpansion
from .problems.nnm import NNMProblem
from .methods.strained_coordinates import StrainedCoordinatesNNM, nnm
from .numerics import NNMBranch, NNMResult, continue_nnm, nnm_point, nnm_sweep, seed_example_system
from .problems.oscillator import Oscillator
from .problems.system import Modes, UnilateralSystem
from .validate import (
    Spectrum,
    contact_measure,
    exact_spectrum,
    expansion_error,
    expansion_spectrum,
    fitted_convergence_order,
    fitted_validity_exponent,
    reference_solution,
    spectrum,
)

__version__ = "0.1.0"

__all__ = [
    "expand",
    "clear_cache",
    "cache_info",
    "nnm",
    "all_modes_first_order",
    "AllModesFirstOrder",
    "Oscillator",
    "UnilateralSystem",
    "Modes",
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
]
