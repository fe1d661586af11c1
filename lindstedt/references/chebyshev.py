"""Taylor coefficients of the exact frequency at epsilon = 0 from a Chebyshev interpolant.

Equation implemented::

    omega(epsilon) = 2 pi / T(epsilon) = sum_k omega_k epsilon**k

for ``u'' + omega0**2 u + epsilon f(u) = 0``, ``u(0) = a0``, ``u'(0) = v0``, with ``T`` by quadrature of
the energy integral (:mod:`.quadrature`).  ``omega`` is sampled at the Chebyshev-Lobatto points of a small
real interval ``[-r, r]``; the Taylor coefficients of the interpolant follow from its Chebyshev
coefficients and the exact integer monomial coefficients of ``T_k``, and two nested grids (33 and 65
points) give the error estimate.  For a piecewise f, ``omega`` is analytic at ``epsilon = 0`` as long as
no turning point of the ``epsilon = 0`` orbit lies on a breakpoint (no grazing); ``r`` is kept below a
quarter of the nearest real epsilon at which a breakpoint becomes a turning point (there ``V(c) = E``,
which is linear in epsilon).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import mpmath

from .._errors import ConvergenceError, ProblemError
from .._precision import locked, workdps
from .arguments import (
    Nonlinearity,
    omega0_parameter,
    real_parameter,
    rounded_coefficients,
    validate_order,
    validate_precision,
)
from .breakpoints import _PiecewisePotential
from .quadrature import _make_potential, _period
from .trapezoid import _orbit_scale, _Potential

__all__ = ["frequency_taylor_coefficients"]

_MAXIMUM_CHEBYSHEV_ORDER = 24


def _characteristic_epsilon(potential: _Potential, a0: mpmath.mpf, omega0: mpmath.mpf) -> mpmath.mpf:
    """An epsilon scale: omega0**2 over the largest |f(u)/u| on |u| <= 3|a0|/2."""
    amplitude = abs(a0) if a0 != 0 else mpmath.mpf(1)
    largest_ratio = mpmath.mpf(0)
    for fraction in (-3, -2, -1, 1, 2, 3):
        position = amplitude * fraction / 2
        ratio = abs(potential.force(position) / position)
        largest_ratio = max(largest_ratio, ratio)
    if largest_ratio == 0:
        return mpmath.mpf(1)
    return omega0**2 / largest_ratio


def _chebyshev_taylor_coefficients(values: list[mpmath.mpf], radius: mpmath.mpf, order: int) -> list[mpmath.mpf]:
    """Taylor coefficients at 0 of the interpolant through Chebyshev-Lobatto samples.

    ``values[j]`` is the function at ``radius * cos(pi j / n)``, ``j = 0..n``.
    """
    n = len(values) - 1
    chebyshev = []
    for k in range(n + 1):
        total = mpmath.fsum(
            (values[j] / (2 if j in (0, n) else 1)) * mpmath.cospi(mpmath.mpf(j * k) / n) for j in range(n + 1)
        )
        coefficient = 2 * total / n
        if k in (0, n):
            coefficient /= 2
        chebyshev.append(coefficient)
    # Monomial coefficients of T_k(t) by the exact integer recurrence.
    monomials: list[list[int]] = [[1], [0, 1]]
    for k in range(2, n + 1):
        previous, before = monomials[k - 1], monomials[k - 2]
        current = [0] * (k + 1)
        for power, value in enumerate(previous):
            current[power + 1] += 2 * value
        for power, value in enumerate(before):
            current[power] -= value
        monomials.append(current)
    taylor = []
    for power in range(order + 1):
        total = mpmath.fsum(
            chebyshev[k] * monomials[k][power] for k in range(power, n + 1) if monomials[k][power] != 0
        )
        taylor.append(total / radius**power)
    return taylor


def _piecewise_characteristic_epsilon(potential: _PiecewisePotential, scale: mpmath.mpf, omega0: mpmath.mpf) -> mpmath.mpf:
    """An epsilon scale: omega0**2 over the largest |f(u)/u| on |u| <= 3 scale/2 (sampled, both sides of breakpoints)."""
    largest_ratio = mpmath.mpf(0)
    for fraction in (-3, -2, -1, 1, 2, 3):
        position = scale * fraction / 2
        for piece in set(potential.locate(position)):
            if potential.pieces[piece].problem is not None:
                continue
            try:
                ratio = abs(potential.force(piece, position) / position)
            except (ZeroDivisionError, ValueError, TypeError):
                continue
            if mpmath.isfinite(ratio):
                largest_ratio = max(largest_ratio, ratio)
    if largest_ratio == 0:
        return mpmath.mpf(1)
    return omega0**2 / largest_ratio


def _grazing_epsilon(
    potential: _PiecewisePotential, a0: mpmath.mpf, velocity: mpmath.mpf, omega0: mpmath.mpf
) -> mpmath.mpf:
    """Smallest |epsilon| at which a breakpoint c can become a turning point (``V(c) = E``, linear in epsilon).

    ``omega0**2 c**2/2 + epsilon F(c) = v0**2/2 + omega0**2 a0**2/2 + epsilon F(a0)`` gives
    ``epsilon_c = omega0**2 (A**2 - c**2) / (2 (F(c) - F(a0)))``, ``A**2 = a0**2 + v0**2/omega0**2``.
    Raises ProblemError if a turning point of the epsilon = 0 orbit is a breakpoint (grazing: omega is not
    analytic at epsilon = 0).
    """
    amplitude = mpmath.sqrt(a0**2 + (velocity / omega0) ** 2)
    cuts = potential.cut_values()
    for cut in cuts:
        if abs(abs(cut) - amplitude) <= mpmath.eps * 1000 * max(amplitude, 1):
            raise ProblemError(
                f"grazing: the turning point {mpmath.nstr(cut, 15)} of the epsilon = 0 orbit (amplitude "
                f"sqrt(a0**2 + v0**2/omega0**2) = {mpmath.nstr(amplitude, 15)}) is a breakpoint of "
                f"{potential.description}, so omega(epsilon) is not analytic at epsilon = 0 (no Taylor series); "
                "choose the orbit so that no turning point lies on a breakpoint"
            )
    left, right = potential.locate(a0)
    reference = right if potential.pieces[right].problem is None else left
    constants, _ = potential.constants(reference)
    start = constants[reference] + potential.primitive(reference, a0)
    nearest = mpmath.inf
    for index, cut in enumerate(cuts):
        for piece, side in ((index, 1), (index + 1, -1)):
            if constants[piece] is None:
                continue
            primitive = potential.boundary_primitive(piece, side)
            if primitive is None:
                continue
            change = constants[piece] + primitive - start
            if change != 0:
                nearest = min(nearest, abs(omega0**2 * (amplitude**2 - cut**2) / (2 * change)))
            break
    return nearest


@locked
def frequency_taylor_coefficients(
    f: Nonlinearity,
    order: int,
    *,
    a0: Any,
    omega0: Any = 1,
    precision: int = 40,
    velocity: Any = 0,
    breakpoints: Sequence[Any] | None = None,
) -> list[tuple[mpmath.mpf, mpmath.mpf]]:
    """Taylor coefficients ``omega_k`` of the exact frequency ``omega(epsilon)`` at 0.

    ``omega(epsilon) = sum_k omega_k epsilon**k`` for the oscillator
    ``u'' + omega0**2 u + epsilon f(u) = 0``, ``u(0) = a0``, ``u'(0) = velocity``.
    The frequency is sampled (by :func:`conservative_frequency`'s quadrature)
    at the Chebyshev-Lobatto points of a real interval ``[-r, r]`` on which
    the orbit exists, with 33 and 65 points; the Taylor coefficients of the
    65-point interpolant are returned and the difference between the two
    grids, plus a rounding allowance, is the error estimate.  If that estimate
    is not below ``10**(-precision/2)`` relative, ``r`` is reduced.  For a
    piecewise f, ``r`` starts below a quarter of the nearest epsilon at which a
    breakpoint becomes a turning point, so the orbit keeps its pieces on
    ``[-r, r]``; an orbit that escapes at ``+-r`` (a softening spring) also
    reduces ``r``.

    Parameters
    ----------
    f : sympy expression in ``u`` or callable
        The nonlinearity (numeric coefficients), as for :func:`conservative_period`.
    order : int
        Highest Taylor coefficient wanted (0 <= order <= 24).
    a0, omega0 : real numbers
        Initial position and linear frequency (omega0 > 0).
    precision : int, optional
        Working digits of the frequency samples.
    velocity : real number, optional
        Initial velocity (default 0).
    breakpoints : sequence of real numbers, optional
        As for :func:`conservative_period`.

    Returns
    -------
    list of (value, error_estimate)
        ``[(omega_0, err_0), ..., (omega_order, err_order)]`` as mpf.

    Raises
    ------
    ProblemError
        If a turning point of the epsilon = 0 orbit lies on a breakpoint of f
        (grazing: omega is not analytic at epsilon = 0).
    ConvergenceError
        If no interval ``[-r, r]`` gives agreeing interpolants.

    Examples
    --------
    >>> import sympy
    >>> u = sympy.Symbol("u")
    >>> coefficients = frequency_taylor_coefficients(u**3, 2, a0=1, precision=30)
    >>> [mpmath.nstr(value, 12) for value, error in coefficients]  # 1, 3/8, -21/256
    ['1.0', '0.375', '-0.08203125']
    >>> coefficients = frequency_taylor_coefficients(sympy.Max(0, u), 2, a0=1, precision=12)
    >>> [mpmath.nstr(value, 8) for value, error in coefficients]  # 1, 1/4, -1/8 (unilateral spring)
    ['1.0', '0.25', '-0.125']
    """
    order = validate_order(order, maximum=_MAXIMUM_CHEBYSHEV_ORDER)
    precision = validate_precision(precision)
    potential = _make_potential(f, breakpoints)
    fine_nodes = 64  # the coarse grid is every other node (33 points)
    working_dps = precision + 15
    with workdps(working_dps):
        a0_value = real_parameter(a0, "a0")
        omega0_value = omega0_parameter(omega0)
        velocity_value = real_parameter(velocity, "velocity")
        if isinstance(potential, _PiecewisePotential):
            scale = _orbit_scale(a0_value, velocity_value, omega0_value)
            radius = min(
                _piecewise_characteristic_epsilon(potential, scale, omega0_value) / 8,
                _grazing_epsilon(potential, a0_value, velocity_value, omega0_value) / 4,
            )
        elif velocity_value == 0:
            radius = _characteristic_epsilon(potential, a0_value, omega0_value) / 8
        else:
            scale = _orbit_scale(a0_value, velocity_value, omega0_value)
            radius = _characteristic_epsilon(potential, scale, omega0_value) / 8
        last_problem = "no attempt made"
        for _attempt in range(6):
            try:
                samples = []
                for j in range(fine_nodes + 1):
                    epsilon = radius * mpmath.cospi(mpmath.mpf(j) / fine_nodes)
                    period, _ = _period(potential, epsilon, a0_value, omega0_value, working_dps, velocity_value)
                    samples.append(2 * mpmath.pi / period)
            except ConvergenceError as error:
                last_problem = str(error)
                radius /= 4
                continue
            fine = _chebyshev_taylor_coefficients(samples, radius, order)
            coarse = _chebyshev_taylor_coefficients(samples[::2], radius, order)
            magnitude = max(abs(value) for value in samples)
            results = []
            acceptable = True
            for power in range(order + 1):
                rounding = magnitude * mpmath.mpf(10) ** (-working_dps + 3) * fine_nodes**2 / radius**power
                error = abs(fine[power] - coarse[power]) + rounding
                results.append((fine[power], error))
                if error > mpmath.mpf(10) ** (-(precision // 2)) * max(magnitude / radius**power, abs(fine[power])):
                    acceptable = False
            if acceptable:
                return rounded_coefficients(results, precision)
            last_problem = "Chebyshev grids of 33 and 65 points disagree (the interval reaches a singularity)"
            radius /= 4
    raise ConvergenceError(
        f"could not obtain Taylor coefficients of omega(epsilon) for {potential.description}: {last_problem}; "
        "check that a periodic orbit exists for small |epsilon|"
    )
