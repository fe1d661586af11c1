"""Exact algebra behind the expansions: cosine series and the contact Fourier kernel.

Cosine series (2π-periodic, even)
    :class:`CosineSeries` ``v(s) = Σ_n c_n cos(n s)`` and :class:`SineSeries`
    ``Σ_n c_n sin(n s)``, with coefficients in a sympy domain (``QQ``,
    ``QQ[r1, …]``, ``RealField``), multiplied by
    ``cos(m s) cos(n s) = ½ [cos((m + n) s) + cos(|m − n| s)]``;
    :func:`solve_harmonic_oscillator` solves ``α0 (v'' + v) = r(s)`` in closed form,
    ``v = Σ_{n≠1} r_n / (α0 (1 − n²)) cos(n s) + C cos(s)``, and raises
    :class:`SecularTermError` when ``r`` still has a ``cos(s)`` term.

Contact Fourier kernel of a unilateral spring (``κ = b/|a0|``, ``β = arccos κ``)
    ``(cos s − κ)_+ = Σ_k c_k[κ] cos(k s)`` and ``H(cos s − κ) = Σ_k h_k[κ] cos(k s)``
    with ``c_0 = (sin β − κ β)/π``, ``c_1 = (β − κ sin β)/π``,
    ``c_k = 2 (κ sin kβ − k sin β cos kβ) / (π k (k² − 1))`` (k ≥ 2),
    ``h_0 = β/π``, ``h_k = 2 sin(kβ)/(π k)``:
    exactly (:func:`contact_angle`, :func:`contact_ramp_coefficient`,
    :func:`contact_step_coefficient`, and the coefficients of their products with
    ``cos(m s)``: :func:`ramp_times_cosine_coefficient`,
    :func:`step_times_cosine_coefficient`), in floating point accurate near
    grazing ``κ → ±1`` and for ``k`` up to ~1e6 (:func:`contact_angle_float`,
    :func:`contact_ramp_coefficients_float`, :func:`contact_step_coefficients_float`),
    at any mpmath precision (:func:`contact_ramp_coefficient_mp`,
    :func:`contact_step_coefficient_mp`), and the accelerated sums of the slowly
    converging series they build (:func:`series_sum`,
    :func:`sum_cosine_series_at`, each a :class:`SeriesEstimate` ``(value, error_estimate)``).

Closed forms in the contact angles
    :func:`in_contact_angles` rewrites the coefficients of a piecewise expansion with
    a symbolic gap in ``κ = b/a0``, ``β = arccos κ``, ``σ = sqrt(1 − κ²)`` (reduced
    modulo ``σ² = 1 − κ²``): an identity, returned with the definitions as a
    :class:`ContactAngleForm` that any text or LaTeX output prints.

Analytic branches
    ``Σ c s^m cos(j s) + d s^m sin(j s)`` on one contact state (module
    :mod:`lindstedt.algebra.branch`): the representation the piecewise engines
    work in; an internal interface, not re-exported here.

The contact field
    The exact coefficients of those branches for rational or symbolic gaps
    (module :mod:`lindstedt.algebra.contact_field`): π, the contact angles β_i
    and their sines σ_i with ``σ_i² + κ_i² = 1`` built in (a polynomial ring
    modulo ``κ² = 1 − σ²`` or ``(√ℓ)² = ℓ``, localised at monomials in π and σ),
    canonical and without polynomial gcds; internal, not re-exported here.

Examples
--------
>>> import sympy
>>> from sympy import QQ
>>> from lindstedt.algebra import CosineSeries, contact_ramp_coefficient, solve_harmonic_oscillator
>>> s = sympy.Symbol("s")
>>> (CosineSeries.cosine(QQ) ** 3).to_expr(s)             # cos³ s = (3 cos s + cos 3s)/4
3*cos(s)/4 + cos(3*s)/4
>>> solve_harmonic_oscillator(CosineSeries.cosine(QQ, 3), QQ(1), value_at_zero=QQ(0)).to_expr(s)
cos(s)/8 - cos(3*s)/8
>>> contact_ramp_coefficient(2, 0)                        # c_2[0] = 2/(3π)
2/(3*pi)
"""

from .fourier import (
    contact_angle,
    contact_ramp_coefficient,
    contact_ramp_coefficient_mp,
    contact_step_coefficient,
    contact_step_coefficient_mp,
    ramp_times_cosine_coefficient,
    step_times_cosine_coefficient,
)
from .fourier_float import contact_angle_float, contact_ramp_coefficients_float, contact_step_coefficients_float
from .series import SeriesEstimate, series_sum, sum_cosine_series_at
from .cosine import CosineSeries, SecularTermError, SineSeries, solve_harmonic_oscillator
from .contact_angles import ContactAngleForm, in_contact_angles

__all__ = [
    "CosineSeries",
    "SineSeries",
    "solve_harmonic_oscillator",
    "SecularTermError",
    "contact_angle",
    "contact_angle_float",
    "contact_ramp_coefficient",
    "contact_step_coefficient",
    "ramp_times_cosine_coefficient",
    "step_times_cosine_coefficient",
    "contact_ramp_coefficients_float",
    "contact_step_coefficients_float",
    "contact_ramp_coefficient_mp",
    "contact_step_coefficient_mp",
    "SeriesEstimate",
    "series_sum",
    "sum_cosine_series_at",
    "ContactAngleForm",
    "in_contact_angles",
]
