"""Independent exact references: frequencies computed without any Lindstedt–Poincaré machinery.

Each reference solves the problem it names by a route of its own, so that it can
check the expansions of :func:`lindstedt.expand` and :func:`lindstedt.nnm`:

Duffing oscillator ``u'' + ω0² u + ε c u³ = 0``, ``u(0) = A``, ``u'(0) = 0``
    :func:`duffing_exact_frequency` — ``ω = π Ω / (2 K(m))`` (complete elliptic
    integral K, ``Ω = ω0 √(1 + x)``, ``m = x / (2 (1 + x))``, ``x = ε c A² / ω0²``);
    :func:`duffing_frequency_taylor` — the exact rational Taylor coefficients
    ``r_k`` of ``ω = ω0 Σ r_k x^k`` (release point or first-harmonic amplitude).

Unilateral spring ``u'' + ω0² u + ε a (u − b)_+ = 0``, ``u(0) = a0``, ``u'(0) = 0``
    :func:`piecewise_linear_exact_period`, :func:`piecewise_linear_exact_frequency`
    — the closed-form period ``T = 2 (π − arccos w_f)/ω0 + 2 arccos(w_c)/Ω``,
    ``Ω² = ω0² + ε a`` (the orbit is a free and a contact ellipse joined at
    ``u = b``); :func:`piecewise_linear_frequency_taylor` — the Taylor
    coefficients ``ω_k`` of ``ω(ε) = Σ ω_k ε^k`` by a Cauchy integral of that
    closed form, each with an error estimate; :func:`piecewise_linear_frequency_taylor_symbolic`
    — for ``b = 0`` (``T = π/ω0 + π/Ω``) the exact Taylor polynomial in ε.

Conservative oscillator ``u'' + ω0² u + ε f(u) = 0``, ``u(0) = a0``, ``u'(0) = v0`` (default 0)
    :func:`conservative_period`, :func:`conservative_frequency` — the period
    ``T = 2 ∫_{b−}^{b+} du / √(2 (E − V(u)))``, ``V = ω0² u²/2 + ε F(u)``,
    ``E = v0²/2 + V(a0)``, between the turning points ``V(b±) = E``, by
    quadrature, with an error estimate: the periodic trapezoidal rule for an
    analytic f, tanh-sinh piece by piece between the breakpoints of a
    piecewise-analytic f (``Max``, ``Min``, ``Abs``, ``Heaviside``, ``sign``,
    ``Piecewise`` with arguments linear in u and real powers of them, e.g. the
    Hertz contact ``Max(0, u)**(3/2)``; :func:`nonlinearity_breakpoints` lists
    them); :func:`frequency_taylor_coefficients` — the ``ω_k`` from a Chebyshev
    interpolant of ``ω(ε) = 2π/T``; :func:`as_mpmath_number` — how these
    references read a number (exact inputs rounded once, at the mpmath
    precision in effect).

Polynomial oscillator ``u'' + ω0² u + ε f(u) = 0``, ``u(0) = a0``, ``u'(0) = 0`` (f with rational coefficients)
    :func:`conservative_frequency_series` — the exact rational Taylor coefficients of
    ``ω(ε)`` from the energy integral: the ε series of ``T = ∮ du/√(2(E − V))`` integrated
    term by term around the turning points (Beta functions continued to ``−k − 1/2``).

Nonlinear normal modes of ``M X'' + K X + ε W (A X − b)_+ = 0``
    :func:`release_amplitudes_by_series` — the release amplitudes ``a_k``
    (k ≠ j) of mode j at first order as Fourier series of the contact functions,
    summed with an error estimate (a cross-check of :func:`lindstedt.nnm`'s closed form).

Examples
--------
>>> import lindstedt
>>> from lindstedt.references import duffing_frequency_taylor, piecewise_linear_frequency_taylor_symbolic
>>> duffing_frequency_taylor(2)
[1, 3/8, -21/256]
>>> lindstedt.expand("u**3", order=2, a0=1, omega0=1).omega == tuple(duffing_frequency_taylor(2))
True
>>> piecewise_linear_frequency_taylor_symbolic(1)
a*epsilon/(4*omega0) + omega0
"""

from ..methods.strained_coordinates import release_amplitudes_by_series
from .duffing import duffing_exact_frequency, duffing_frequency_taylor
from .piecewise import (
    piecewise_linear_exact_frequency,
    piecewise_linear_exact_period,
    piecewise_linear_frequency_taylor,
    piecewise_linear_frequency_taylor_symbolic,
)
from .arguments import as_mpmath_number
from .chebyshev import frequency_taylor_coefficients
from .energy_series import conservative_frequency_series
from .quadrature import conservative_frequency, conservative_period, nonlinearity_breakpoints

__all__ = [
    "duffing_exact_frequency",
    "duffing_frequency_taylor",
    "piecewise_linear_exact_period",
    "piecewise_linear_exact_frequency",
    "piecewise_linear_frequency_taylor",
    "piecewise_linear_frequency_taylor_symbolic",
    "conservative_period",
    "conservative_frequency",
    "frequency_taylor_coefficients",
    "conservative_frequency_series",
    "nonlinearity_breakpoints",
    "as_mpmath_number",
    "release_amplitudes_by_series",
]
