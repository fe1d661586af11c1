r"""Exact Taylor series of the frequency of a polynomial oscillator, from the energy integral.

Equation implemented::

    u'' + omega0**2 u + epsilon f(u) = 0,    u(0) = a0,   u'(0) = 0,

``f`` a polynomial with rational coefficients, ``omega0**2`` and ``a0 != 0`` rational.  No
Lindstedt–Poincaré machinery is involved: the series comes from the period integral alone.

Derivation
----------
The energy ``E = u'**2/2 + V(u)``, ``V = omega0**2 u**2/2 + epsilon F(u)``, ``F' = f``, ``F(0) = 0``, is
``V(a0)`` on the orbit released at rest from ``a0``.  With ``u = a0 x``

    2 (E − V) = omega0**2 a0**2 (1 − x**2) (1 + epsilon h(x)/(1 − x**2)),
    h(x) = 2 (F(a0) − F(a0 x)) / (omega0**2 a0**2),

a polynomial with ``h(1) = 0``.  The period ``T = ∮ dt`` is the integral of
``du/sqrt(2(E − V))`` around a closed contour ``C`` that encircles the two turning points
(the orbit's ends, ``x = 1`` and a point near ``x = −1``) once; for small epsilon ``C`` can be
fixed away from ``x = ±1``, where ``|epsilon h/(1 − x**2)| < 1``, so the binomial series of
``(1 + epsilon h/(1 − x**2))**(−1/2)`` may be integrated term by term:

    T = (1/omega0) Σ_k binom(−1/2, k) epsilon**k ∮_C h(x)**k (1 − x**2)**(−k − 1/2) dx.

For ``Re α > −1`` the contour integral of ``g(x)(1 − x**2)**α`` around the cut ``[−1, 1]`` is
``(1 − e**(2πiα))`` times ``∫_{−1}^{1} g (1 − x**2)**α dx`` (up to orientation); both sides are
analytic in ``α``, and the factor has period 1 in ``α``, so at ``α = −k − 1/2`` it equals its value
at ``α = −1/2`` (where the contour integral is twice the real one) and the real integral is
continued analytically: for ``g = x**(2j)`` it is the Beta function

    B(j + 1/2, α + 1) = Γ(j + 1/2) Γ(1/2 − k) / Γ(j + 1 − k),

zero for ``j < k`` (a pole of the denominator's Γ) and odd powers vanish by symmetry.  With
``Γ(j + 1/2) = √π (2j)!/(4**j j!)``, ``Γ(1/2 − k) = √π (−4)**k k!/(2k)!`` and
``binom(−1/2, k) = (−1)**k (2k)!/(4**k k!**2)`` the ε**k coefficient of ``T / (2π/omega0)`` is

    S_k = Σ_{j ≥ k} [h**k]_{2j} · C(2j, j) C(j, k) / 4**j,

a rational number (``[p]_n`` the x**n coefficient of p).  Then ``omega = omega0 / S(epsilon)``:
the series reciprocal.  Checks: ``f = u`` gives ``S = (1 + epsilon/omega0**2)**(−1/2)`` exactly, and
``f = u**3`` the elliptic series of :func:`lindstedt.references.duffing_frequency_taylor`
(tests/test_energy_series.py).

Cost: the powers ``h**k`` (degree ≤ (deg f + 1) k) and the reciprocal, O(order² deg f) rational
operations in gmpy2 — the cost of the elliptic series, for any polynomial f.
"""

from __future__ import annotations

import math
from typing import Any

import sympy
from gmpy2 import mpq

from .._errors import ProblemError, UnsupportedNonlinearityError
from ..problems.parsing import parse_expression, parse_real
from .arguments import _checked_expression, validate_order

__all__ = ["conservative_frequency_series"]

#: orders above this are refused (the powers h**k grow like order² digits; order 400 of a quintic: seconds)
_MAX_ORDER = 400


def conservative_frequency_series(f: Any, order: int, *, a0: Any = 1, omega0: Any = 1) -> tuple[sympy.Expr, ...]:
    """Exact ``ω_0 … ω_order`` of ``ω(ε) = Σ ω_k ε^k`` for ``u'' + ω0² u + ε f(u) = 0``, ``u(0) = a0``, ``u'(0) = 0``.

    Parameters
    ----------
    f : str or sympy expression in ``u``
        A polynomial with rational coefficients (a string is read by the package's one parser).
    order : int
        Highest power of ε (0 … 400).
    a0 : rational number, optional
        The release point (a turning point of the orbit); nonzero.
    omega0 : positive number with a rational square, optional
        Linear angular frequency.

    Returns
    -------
    tuple of sympy expressions
        ``ω_k = ω0 · r_k`` with ``r_k`` rational.

    Raises
    ------
    UnsupportedNonlinearityError
        If f is not a polynomial in u with rational coefficients.
    ProblemError
        If a0 is zero or not rational, or ω0 is not positive with a rational square.

    Examples
    --------
    >>> conservative_frequency_series("u**3", 2)          # Duffing: 1 + 3ε/8 − 21ε²/256
    (1, 3/8, -21/256)
    >>> conservative_frequency_series("u", 2, omega0=2)   # sqrt(4 + ε) = 2 + ε/4 − ε²/64
    (2, 1/4, -1/64)
    """
    order = validate_order(order, _MAX_ORDER)
    coefficients = _polynomial(f)
    release = _rational(a0, "a0")
    if release == 0:
        raise ProblemError("a0 = 0 is the equilibrium (no orbit to take the period of); give a nonzero release point a0")
    omega0 = parse_real(omega0, what="omega0")
    if not omega0.is_positive:
        raise ProblemError(f"omega0 = {omega0} must be positive")
    square = omega0**2
    if not square.is_Rational:
        raise ProblemError(f"omega0 = {omega0}: its square must be rational (e.g. 2, 3/2, sqrt(2)) for an exact series")
    stiffness = mpq(int(square.p), int(square.q))
    # h(x) = 2 (F(a0) − F(a0 x)) / (ω0² a0²) = Σ_m 2 c_m a0^(m−1) (1 − x^(m+1)) / ((m + 1) ω0²)
    h = [mpq(0)] * (len(coefficients) + 1)
    for m, c in enumerate(coefficients):
        if c:
            term = 2 * c * release ** (m - 1) / ((m + 1) * stiffness)
            h[0] += term
            h[m + 1] -= term
    while len(h) > 1 and not h[-1]:
        h.pop()
    weights = [mpq(math.comb(2 * j, j), 4**j) for j in range((len(h) - 1) * order // 2 + 1)]  # C(2j, j)/4^j
    period = [mpq(1)]  # S_k, the ε^k coefficient of T/(2π/ω0)
    power = [mpq(1)]  # h^k
    for k in range(1, order + 1):
        power = _times(power, h)
        period.append(sum((power[2 * j] * weights[j] * math.comb(j, k) for j in range(k, (len(power) - 1) // 2 + 1)), mpq(0)))
    frequency = [mpq(1)]  # 1/S
    for k in range(1, order + 1):
        frequency.append(-sum((period[i] * frequency[k - i] for i in range(1, k + 1)), mpq(0)))
    return tuple(omega0 * sympy.Rational(int(r.numerator), int(r.denominator)) for r in frequency)


def _times(first: list, second: list) -> list:
    """The product of two dense coefficient lists."""
    result = [mpq(0)] * (len(first) + len(second) - 1)
    for i, a in enumerate(first):
        if a:
            for j, b in enumerate(second):
                if b:
                    result[i + j] += a * b
    return result


def _rational(value: Any, name: str) -> Any:
    number = parse_real(value, what=name)
    if not number.is_Rational:
        raise ProblemError(f"{name} = {number} must be rational for an exact series (e.g. 1, 1/2, 0.75)")
    return mpq(int(number.p), int(number.q))


def _polynomial(f: Any) -> list:
    """The coefficients c_0 … c_d of f(u) as gmpy2 rationals."""
    u = sympy.Symbol("u")
    expression = parse_expression(f, symbols={"u": u}, what="f")
    expression, variable = _checked_expression(expression)
    try:
        polynomial = sympy.Poly(expression, variable)
    except sympy.PolynomialError:
        polynomial = None
    if polynomial is None or not all(c.is_Rational for c in polynomial.all_coeffs()):
        raise UnsupportedNonlinearityError(
            f"f(u) = {expression} is not a polynomial in u with rational coefficients; for other f use "
            "lindstedt.references.frequency_taylor_coefficients (numeric, with error estimates)"
        )
    return [mpq(int(c.p), int(c.q)) for c in reversed(polynomial.all_coeffs())]
