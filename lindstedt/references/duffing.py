"""Exact reference frequency of the Duffing oscillator.

Equation implemented::

    u'' + omega0**2 u + epsilon c u**3 = 0.

Derivation (no Lindstedt-Poincare machinery)
--------------------------------------------
Write ``lam = epsilon c`` and let ``A`` be the turning-point amplitude,
``u(0) = A``, ``u'(0) = 0``.  Try ``u = A cn(Omega t | m)``.  Since
``d^2 cn/dz^2 = -(1 - 2m) cn - 2m cn**3``, substitution gives
``Omega**2 (1 - 2m) = omega0**2`` and ``2 m Omega**2 = lam A**2``, so with the
dimensionless strength ``x = lam A**2 / omega0**2``

    Omega = omega0 sqrt(1 + x),       m = x / (2 (1 + x)).

``cn(. | m)`` has period ``4 K(m)``, hence the period is ``T = 4 K(m)/Omega``
and the angular frequency

    omega = pi Omega / (2 K(m)) = omega0 sqrt(1 + x) / (2 K(m)/pi).

This holds for every ``x > -1``: for softening (``x < 0``) the parameter
``m`` is negative (``K`` stays real and ``cn`` periodic); ``x -> -1`` is the
separatrix (``A`` reaches the hilltop ``omega0/sqrt(-lam)``) where the period
diverges, and for ``x <= -1`` there is no periodic orbit through ``u(0) = A``.

First-harmonic amplitude.  With the nome ``q`` of ``m`` and the theta
functions ``theta3 = 1 + 2 sum_{n>=1} q**(n**2)``,
``theta2 = 2 q**(1/4) psi(q)``, ``psi(q) = sum_{n>=0} q**(n (n+1))`` one has
``2K/pi = theta3**2`` and ``sqrt(m) = theta2**2/theta3**2``.  The Fourier
series ``cn(z|m) = 2 pi/(K sqrt(m)) sum_{n>=0} q**(n+1/2)/(1 + q**(2n+1))
cos((2n+1) pi z/(2K))`` then gives the coefficient of ``cos(omega t)``

    A1 = A / ((1 + q) psi(q)**2),

which is real and analytic for ``-1 < q < 1`` (negative ``q`` for negative
``m``).  The "harmonic" normalisation takes ``A1`` as the given amplitude.

Exact Taylor series.  With ``omega = omega0 sum_k r_k x**k``:

* "initial": ``2K(m)/pi = 2F1(1/2, 1/2; 1; m) = sum_n (binom(2n, n)/4**n)**2 m**n``
  composed with ``m(x) = x/(2(1+x))``, and ``omega/omega0 = sqrt(1+x)/2F1``;
* "harmonic": everything as a series in ``q``:
  ``m = 16 q psi**4/theta3**4``, ``x = 2m/(1 - 2m)``,
  ``omega/omega0 = (1 - 2m)**(-1/2)/theta3**2`` and the first-harmonic strength
  ``y = x (A1/A)**2 = x / ((1+q)**2 psi**4)``; reverting ``y(q)`` and
  composing gives ``omega/omega0`` as a series in ``y = lam A1**2/omega0**2``.

The series are truncated power series over ``QQ`` in sympy's
``sympy.polys.ring_series`` (products, reciprocals, roots, composition).  They
replaced a hand-written power-series class, measured on this very computation
with identical exact output (CPython 3.11, sympy 1.14, python ground types,
medians of 5-31 runs in one process, cache cleared; hand-written vs
ring_series): initial 2.1 vs 2.0 ms at order 10, 72 vs 16 ms at 30, 0.56 vs
0.11 s at 60, 3.0 vs 0.28 s at 100; harmonic 9.1 vs 8.0 ms, 197 vs 82 ms,
1.44 vs 0.57 s, 7.6 vs 2.5 s.  ``sympy.series`` of the closed form takes 3.5 s
at order 10.
"""

from __future__ import annotations

import functools
from typing import Any, Callable

import mpmath
import sympy
from sympy import QQ
from sympy.polys.ring_series import (
    rs_mul,
    rs_nth_root,
    rs_series_from_list,
    rs_series_inversion,
    rs_square,
)
from sympy.polys.rings import ring

from .._errors import ConvergenceError, ProblemError
from .._precision import locked, workdps
from .arguments import omega0_parameter, real_parameter, validate_order, validate_precision

__all__ = ["duffing_exact_frequency", "duffing_frequency_taylor"]

_NORMALIZATIONS = ("initial", "harmonic")
_MAXIMUM_TAYLOR_ORDER = 200
_SERIES_RING, _X = ring("x", QQ)  # truncated series with exact rational coefficients (sympy.polys.ring_series)


def _check_normalization(normalization: Any) -> str:
    if normalization not in _NORMALIZATIONS:
        raise ProblemError(
            f"normalization must be 'initial' (amplitude = u(0)) or 'harmonic' "
            f"(amplitude = first-harmonic coefficient), got {normalization!r}"
        )
    return normalization


def _strength_pair(strength: mpmath.mpf, peak_amplitude: mpmath.mpf, omega0: mpmath.mpf) -> tuple[mpmath.mpf, mpmath.mpf]:
    """``x = strength A**2/omega0**2`` and ``1 + x``, the latter to full relative precision.

    ``1 + x = (omega0**2 + strength A**2)/omega0**2`` has its numerator formed
    with exact binary arithmetic, so the cancellation near the softening
    separatrix (``1 + x -> 0``) costs no digits.
    """
    omega0_squared = mpmath.fmul(omega0, omega0, exact=True)
    stiffening = mpmath.fmul(strength, mpmath.fmul(peak_amplitude, peak_amplitude, exact=True), exact=True)
    x = stiffening / omega0_squared
    one_plus_x = mpmath.fadd(omega0_squared, stiffening, exact=True) / omega0_squared
    return x, one_plus_x


def _frequency(x: mpmath.mpf, one_plus_x: mpmath.mpf, omega0: mpmath.mpf) -> mpmath.mpf:
    """omega = pi omega0 sqrt(1 + x)/(2 K(m)), m = x/(2(1 + x))."""
    if one_plus_x <= 0:
        raise ProblemError(
            f"no periodic orbit: epsilon*c*amplitude**2/omega0**2 = {mpmath.nstr(x, 15)} <= -1 puts the "
            "release point on or beyond the hilltop of the softening potential; reduce |epsilon c| or the amplitude"
        )
    if x == 0:
        return +omega0
    parameter = x / (2 * one_plus_x)
    return mpmath.pi * omega0 * mpmath.sqrt(one_plus_x) / (2 * mpmath.ellipk(parameter))


def _psi(nome: mpmath.mpf) -> mpmath.mpf:
    """psi(q) = sum_{n>=0} q**(n(n+1)) for real |q| < 1."""
    total = mpmath.mpf(0)
    n = 0
    threshold = mpmath.eps
    while True:
        term = nome ** (n * (n + 1))
        total += term
        if abs(term) < threshold and n > 0:
            return total
        n += 1
        if n > 10**6:
            raise ConvergenceError("the theta series psi(q) did not converge (|q| too close to 1)")


def _harmonic_ratio(x: mpmath.mpf, one_plus_x: mpmath.mpf) -> mpmath.mpf:
    """A1/A = 1/((1 + q) psi(q)**2) for the orbit of strength x (q: nome of m = x/(2(1+x)))."""
    if x == 0:
        return mpmath.mpf(1)
    nome = mpmath.qfrom(m=x / (2 * one_plus_x))
    if isinstance(nome, mpmath.mpc):
        nome = nome.real
    return 1 / ((1 + nome) * _psi(nome) ** 2)


def _solve_bracketed(mismatch: Callable[[mpmath.mpf], mpmath.mpf], low: mpmath.mpf, high: mpmath.mpf, scale: mpmath.mpf) -> mpmath.mpf:
    """Root of a monotone mismatch with a sign change on [low, high], polished by secant steps."""
    try:
        root = mpmath.findroot(mismatch, (low, high), solver="anderson", verify=False)
    except (ValueError, ZeroDivisionError) as error:  # pragma: no cover - defensive
        raise ConvergenceError(f"solving for the peak amplitude failed: {error}") from None
    previous = root + (high - low) * mpmath.mpf(10) ** (-(mpmath.mp.dps // 3))
    for _ in range(60):
        value, previous_value = mismatch(root), mismatch(previous)
        if value == 0 or value == previous_value:
            break
        step = value * (root - previous) / (value - previous_value)
        previous, root = root, root - step
        if abs(step) <= mpmath.eps * 4 * max(abs(root), 1):
            break
    if abs(mismatch(root)) > mpmath.mpf(10) ** (-(mpmath.mp.dps - 8)) * scale:
        raise ConvergenceError("solving for the peak amplitude from the first-harmonic amplitude did not converge")
    return root


def _strength_from_harmonic(
    harmonic_amplitude: mpmath.mpf, strength: mpmath.mpf, omega0: mpmath.mpf
) -> tuple[mpmath.mpf, mpmath.mpf]:
    """Solve A (A1/A)(A) = |A1| and return (x, 1 + x) of the orbit."""
    target = abs(harmonic_amplitude)
    if target == 0 or strength == 0:
        return _strength_pair(strength, target, omega0)
    if strength > 0:
        # A1/A decreases from 1 (m = 0) to 1/((1 + e^-pi) psi(e^-pi)**2) ~ 0.955 (m -> 1/2).
        def mismatch_in_peak(peak: mpmath.mpf) -> mpmath.mpf:
            return peak * _harmonic_ratio(*_strength_pair(strength, peak, omega0)) - target

        peak = _solve_bracketed(mismatch_in_peak, target, target / mpmath.mpf("0.95"), target)
        return _strength_pair(strength, peak, omega0)
    # Softening: A1/A increases from 1 to 4/pi (square wave) as A -> hilltop A_s, but only
    # logarithmically, so the unknown is y = log(1 - A/A_s) and 1 + x = e^y (2 - e^y) exactly.
    hilltop = omega0 / mpmath.sqrt(-strength)
    supremum = 4 * hilltop / mpmath.pi
    if target >= supremum:
        raise ProblemError(
            f"no periodic orbit of the softening Duffing oscillator has first-harmonic amplitude "
            f"{mpmath.nstr(target, 15)}: the supremum is 4/pi * omega0/sqrt(-epsilon c) = "
            f"{mpmath.nstr(supremum, 15)}; reduce |epsilon c| or the amplitude"
        )

    def pair(log_gap: mpmath.mpf) -> tuple[mpmath.mpf, mpmath.mpf]:
        gap = mpmath.exp(log_gap)
        return -((1 - gap) ** 2), gap * (2 - gap)

    def mismatch_in_log_gap(log_gap: mpmath.mpf) -> mpmath.mpf:
        peak = hilltop * (1 - mpmath.exp(log_gap))
        return peak * _harmonic_ratio(*pair(log_gap)) - target

    # Near A = pi/4 |A1| the mismatch is <= 0 (ratio <= 4/pi); near A = |A1| (or the hilltop) >= 0.
    upper = mpmath.log(1 - target * mpmath.pi / (4 * hilltop))
    if target < hilltop:
        lower = mpmath.log(1 - target / hilltop)
    else:
        lower = min(upper, mpmath.mpf(-1))
        while mismatch_in_log_gap(lower) < 0:
            lower *= 4
            if lower < -4000:
                raise ProblemError(
                    f"the first-harmonic amplitude {mpmath.nstr(target, 15)} is too close to the separatrix "
                    f"supremum {mpmath.nstr(supremum, 15)}: the turning point would lie within exp(-4000) of "
                    "the hilltop; reduce the amplitude"
                )
    log_gap = _solve_bracketed(mismatch_in_log_gap, lower, upper, target)
    return pair(log_gap)


@locked
def duffing_exact_frequency(
    epsilon: Any,
    *,
    amplitude: Any,
    omega0: Any = 1,
    coefficient: Any = 1,
    normalization: str = "initial",
    precision: int = 30,
) -> mpmath.mpf:
    """Exact angular frequency of ``u'' + omega0**2 u + epsilon c u**3 = 0``.

    Parameters
    ----------
    epsilon : real number
        The small parameter.
    amplitude : real number
        ``u(0)`` (with ``u'(0) = 0``) if ``normalization="initial"``; the
        coefficient of ``cos(omega t)`` in the exact periodic solution if
        ``normalization="harmonic"``.  Only ``|amplitude|`` matters.
    omega0 : positive real number, optional
        Linear angular frequency.
    coefficient : real number, optional
        ``c``; the cubic term is ``epsilon * c * u**3``.
    normalization : {"initial", "harmonic"}
        Meaning of ``amplitude``.
    precision : int, optional
        Decimal digits of the result (the global mpmath precision is untouched).

    Returns
    -------
    mpmath.mpf
        ``omega = pi Omega / (2 K(m))`` with ``Omega = omega0 sqrt(1+x)``,
        ``m = x/(2(1+x))``, ``x = epsilon c A**2/omega0**2`` (``A = u(0)``).

    Raises
    ------
    ProblemError
        For softening (``epsilon c < 0``) beyond the separatrix, i.e. when no
        periodic orbit with the requested amplitude exists, or bad inputs.

    Examples
    --------
    >>> import mpmath
    >>> print(duffing_exact_frequency(0, amplitude=1, omega0=2, precision=15))
    2.0
    >>> mpmath.nstr(duffing_exact_frequency(1, amplitude=1, precision=25), 20)
    '1.3177760649655266261'
    >>> mpmath.nstr(duffing_exact_frequency("0.1", amplitude=1, normalization="harmonic", precision=25), 20)
    '1.036928728956429301'
    """
    normalization = _check_normalization(normalization)
    precision = validate_precision(precision)
    with workdps(precision + 10):
        epsilon_value = real_parameter(epsilon, "epsilon")
        amplitude_value = real_parameter(amplitude, "amplitude")
        omega0_value = omega0_parameter(omega0)
        coefficient_value = real_parameter(coefficient, "coefficient")
        strength = mpmath.fmul(epsilon_value, coefficient_value, exact=True)
        if normalization == "harmonic":
            x, one_plus_x = _strength_from_harmonic(amplitude_value, strength, omega0_value)
        else:
            x, one_plus_x = _strength_pair(strength, abs(amplitude_value), omega0_value)
        frequency = _frequency(x, one_plus_x, omega0_value)
    with workdps(precision):
        return +frequency


def _coefficients(series: Any, order: int) -> tuple[sympy.Rational, ...]:
    """``c_0, ..., c_order`` of a series in the ring ``QQ[x]`` as sympy Rationals."""
    return tuple(QQ.to_sympy(series.get((power,), QQ.zero)) for power in range(order + 1))


def _hypergeometric_half_half_one(order: int) -> list[Any]:
    """2F1(1/2, 1/2; 1; m) = 2K(m)/pi = sum_n (binom(2n, n)/4**n)**2 m**n, coefficients to m**order."""
    values = []
    central = QQ(1)  # binom(2n, n) / 4**n
    for n in range(order + 1):
        if n > 0:
            central = central * (2 * n - 1) / (2 * n)
        values.append(central * central)
    return values


@functools.lru_cache(maxsize=64)
def _initial_taylor(order: int) -> tuple[sympy.Rational, ...]:
    x, truncation = _X, order + 1  # ring_series truncates at O(x**truncation)
    parameter = rs_mul(x, rs_series_inversion(1 + x, x, truncation), x, truncation) * QQ(1, 2)  # m = x/(2(1+x))
    complete_integral = rs_series_from_list(parameter, _hypergeometric_half_half_one(order), x, truncation)
    ratio = rs_mul(rs_nth_root(1 + x, 2, x, truncation), rs_series_inversion(complete_integral, x, truncation), x, truncation)
    return _coefficients(ratio, order)


def _theta_series(order: int) -> tuple[Any, Any]:
    """theta3(q) = 1 + 2 sum q**(n**2) and psi(q) = sum_{n>=0} q**(n(n+1)) to q**order."""
    theta3 = {(0,): QQ(1)}
    n = 1
    while n * n <= order:
        theta3[(n * n,)] = QQ(2)
        n += 1
    psi = {}
    n = 0
    while n * (n + 1) <= order:
        psi[(n * (n + 1),)] = QQ(1)
        n += 1
    return _SERIES_RING(theta3), _SERIES_RING(psi)


def _reversion(series: Any, order: int) -> Any:
    """The compositional inverse ``g`` of ``f = c_1 x + c_2 x**2 + ...`` (``c_1 != 0``) to x**order.

    Lagrange inversion, ``[x**n] g = (1/n) [w**(n-1)] (w/f(w))**n``, on sympy's
    ring_series products.  Kept instead of ``rs_series_reversion`` because it was
    measured faster on the Duffing nome series, with the same exact result (CPython
    3.11, sympy 1.14, python ground types, medians of 3-5 runs): 0.024 s vs 0.091 s
    at order 30, 0.37 s vs 2.2 s at order 60 (``rs_series_reversion`` recomposes the
    whole series once per order).
    """
    quotient = rs_series_inversion(_SERIES_RING({(power - 1,): value for (power,), value in series.items()}), _X, order)
    quotient_power = _SERIES_RING.one
    inverse = {}
    for n in range(1, order + 1):
        quotient_power = rs_mul(quotient_power, quotient, _X, order)
        value = quotient_power.get((n - 1,), QQ.zero)
        if value:
            inverse[(n,)] = value / n
    return _SERIES_RING(inverse)


@functools.lru_cache(maxsize=64)
def _harmonic_taylor(order: int) -> tuple[sympy.Rational, ...]:
    if order == 0:
        return (sympy.Integer(1),)
    q, truncation = _X, order + 1  # ring_series truncates at O(q**truncation)
    theta3, psi = _theta_series(order)
    theta3_squared_inverse = rs_series_inversion(rs_square(theta3, q, truncation), q, truncation)
    psi_squared = rs_square(psi, q, truncation)
    parameter = rs_mul(q, rs_square(rs_mul(psi_squared, theta3_squared_inverse, q, truncation), q, truncation), q, truncation) * 16  # m(q)
    one_minus_two_m = 1 - 2 * parameter
    strength = rs_mul(2 * parameter, rs_series_inversion(one_minus_two_m, q, truncation), q, truncation)  # x(q) = 2m/(1-2m)
    frequency_ratio = rs_mul(rs_nth_root(one_minus_two_m, -2, q, truncation), theta3_squared_inverse, q, truncation)
    amplitude_ratio = rs_series_inversion(rs_mul(1 + q, psi_squared, q, truncation), q, truncation)  # A1/A
    harmonic_strength = rs_mul(strength, rs_square(amplitude_ratio, q, truncation), q, truncation)  # y(q)
    nome_of_y = _reversion(harmonic_strength, order)
    frequency = rs_series_from_list(nome_of_y, list(_coefficients(frequency_ratio, order)), q, truncation)
    return _coefficients(frequency, order)


@locked
def duffing_frequency_taylor(order: int, normalization: str = "initial") -> list[sympy.Rational]:
    """Exact Taylor coefficients of the Duffing frequency in the strength x.

    ``omega(epsilon) = omega0 * sum_{k=0..order} r_k x**k + O(x**(order+1))`` with
    ``x = epsilon c a**2 / omega0**2``, where ``a`` is ``u(0)``
    (``"initial"``) or the first-harmonic amplitude (``"harmonic"``).  Built
    from exact rational power series (see the module docstring); no
    Lindstedt-Poincare machinery.

    Parameters
    ----------
    order : int
        Highest power of x (0 <= order <= 200).
    normalization : {"initial", "harmonic"}
        Meaning of the amplitude ``a``.

    Returns
    -------
    list of sympy.Rational
        ``[r_0, r_1, ..., r_order]``.

    Examples
    --------
    >>> duffing_frequency_taylor(2)
    [1, 3/8, -21/256]
    >>> duffing_frequency_taylor(2, "harmonic")
    [1, 3/8, -15/256]
    """
    order = validate_order(order, maximum=_MAXIMUM_TAYLOR_ORDER)
    normalization = _check_normalization(normalization)
    return list(_initial_taylor(order) if normalization == "initial" else _harmonic_taylor(order))
