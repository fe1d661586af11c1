"""Validation tools: expansions of ``u'' + ω0² u + ε f(u) = 0`` against the true solution.

The problem is ``u'' + ω0² u + ε f(u) = 0``, ``u(0) = a0 + ε a1``, ``u'(0) = 0``,
and ``u_N(t) = Σ_{k≤N} ε^k v_k(ω t)`` is its order-N Lindstedt–Poincaré expansion
(:func:`lindstedt.expand`).

The modules follow the pipeline, each importing only the ones before it:

True solution (:mod:`lindstedt.validate.solutions`)
    :func:`reference_solution` (a :class:`ReferenceSolution`): the closed-form
    arcs of the exact piecewise-linear flow for unilateral springs
    ``a (u − b)_+`` (machine precision), DOP853 for smooth f;
    :func:`exact_period` (:class:`ExactPeriod`): twice the first positive
    zero of ``u'``.

Errors and rates (:mod:`lindstedt.validate.errors`)
    :func:`expansion_error` (:class:`ExpansionError`): ``e(t) = u_N(t) − u(t)``
    and its phase-plane size ``ρ = ((u_N − u)² + ((u_N' − u')/ω0)²)^{1/2}``;
    :func:`fitted_convergence_order` (:class:`ConvergenceFit`): the slope of
    ``log max_{[0, C/ε]} |e|`` against ``log ε`` (N + 1 for a simple contact);
    :func:`fitted_validity_exponent` (:class:`ValidityFit`): the exponent of
    the first time ``T_ε`` at which ``ρ > C ε^{N+1}`` (−1; −1/2 at grazing);
    :func:`loglog_fit` (:class:`LogLogFit`): the least-squares line through
    ``(log x, log y)`` behind these fits.

Contact measure, Lemma 3.2 (:mod:`lindstedt.validate.contact`)
    :func:`contact_measure` (:class:`ContactMeasure`):
    ``μ_ε(T) = |{t ∈ [0, T] : |u(t) − b| ≤ ε M}|``;
    :func:`fitted_contact_measure_order` (:class:`ContactMeasureFit`): the
    slope of ``log(μ_ε(T)/T)`` against ``log ε`` (1, or 1/2 at grazing).

Backbone (:mod:`lindstedt.validate.backbone`)
    :func:`backbone` (:class:`Backbone`): ω(a0) on an amplitude grid, the series truncated at every
    order against the exact frequency (energy-integral quadrature), serially or on any executor.

Spectra (:mod:`lindstedt.validate.spectra`; also exported by :mod:`lindstedt`)
    :func:`spectrum` (:class:`Spectrum` of :class:`SpectralPeak` lines): the
    line spectrum ``|c_0|, |c_k − i s_k|`` of a periodic signal sampled over
    whole periods; :func:`expansion_spectrum` samples ``u_N`` over periods of
    its own ω(ε), :func:`exact_spectrum` the true solution over its exact
    period :func:`exact_period`.

Figures of all of these are drawn by :mod:`lindstedt.plot` (matplotlib, optional).

Every numerical result is a frozen dataclass with ``success``, ``message``
and counters (samples, reference solves, switches, right-hand-side or gap
evaluations).

Examples
--------
>>> import lindstedt
>>> from lindstedt.validate import expansion_error, loglog_fit
>>> e = lindstedt.expand("Max(0, u)", order=1, a0=1, omega0=1)
>>> result = expansion_error(e, 0.01, 100.0)
>>> result.success, result.reference_method, result.max_error < 2e-4
(True, 'exact', True)
>>> round(loglog_fit([0.1, 0.01], [3e-2, 3e-4]).slope, 12)
2.0
"""

from .backbone import Backbone, backbone
from .contact import ContactMeasure, ContactMeasureFit, contact_measure, fitted_contact_measure_order
from .errors import (
    ConvergenceFit,
    ExpansionError,
    LogLogFit,
    ValidityFit,
    expansion_error,
    fitted_convergence_order,
    fitted_validity_exponent,
    loglog_fit,
)
from .solutions import ExactPeriod, ReferenceSolution, exact_period, reference_solution
from .spectra import SpectralPeak, Spectrum, exact_spectrum, expansion_spectrum, spectrum

__all__ = [
    "reference_solution",
    "ReferenceSolution",
    "expansion_error",
    "ExpansionError",
    "fitted_convergence_order",
    "ConvergenceFit",
    "fitted_validity_exponent",
    "ValidityFit",
    "loglog_fit",
    "LogLogFit",
    "contact_measure",
    "ContactMeasure",
    "fitted_contact_measure_order",
    "ContactMeasureFit",
    "spectrum",
    "Spectrum",
    "SpectralPeak",
    "expansion_spectrum",
    "exact_spectrum",
    "exact_period",
    "ExactPeriod",
    "backbone",
    "Backbone",
]
