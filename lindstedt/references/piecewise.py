"""Exact period of the piecewise-linear (unilateral spring) oscillator.

Equation implemented::

    u'' + omega0**2 u + epsilon a (u - b)_+ = 0,    u(0) = a0,   u'(0) = 0,

with ``(v)_+ = max(v, 0)``: a spring of stiffness ``k = epsilon a`` acts only
in the *contact region* ``u > b`` (``b > 0``: a gap; ``b < 0``: a prestress).

Derivation (no Lindstedt-Poincare machinery)
--------------------------------------------
The potential ``V(u) = omega0**2 u**2/2 + k (u - b)_+**2/2`` is convex when
``Omega**2 = omega0**2 + k > 0`` and the energy ``E = V(a0)`` is conserved.
On each side of ``u = b`` the potential is a parabola:

* free region ``u <= b``: ``V = omega0**2 u**2/2`` (centre 0, frequency omega0);
* contact region ``u >= b``: ``V = Omega**2 (u - u_e)**2/2 + C`` with centre
  ``u_e = k b/Omega**2`` and floor ``C = k omega0**2 b**2/(2 Omega**2)``.

The orbit ``{u'**2/2 + V(u) = E}`` is the union of the part ``u <= b`` of the
free ellipse ``u'**2 + omega0**2 u**2 = 2E`` and the part ``u >= b`` of the
contact ellipse ``u'**2 + Omega**2 (u - u_e)**2 = 2(E - C)``; on each it moves
with uniform phase speed.  With the free amplitude ``A_f = sqrt(2E)/omega0``
and the contact amplitude ``A_c = sqrt(2(E - C))/Omega``:

    T = 2 (pi - arccos(w_f))/omega0 + 2 arccos(w_c)/Omega,
    w_f = b/A_f = b omega0/sqrt(2E),
    w_c = (b - u_e)/A_c = b omega0**2/sqrt(P),   P = 2E Omega**2 - k omega0**2 b**2,

where each arccos argument is clamped to ``[-1, 1]`` and an empty part
(``E <= 0`` or ``P <= 0``) contributes nothing.  This covers every case: no
contact (``w_f >= 1``: ``T = 2 pi/omega0``), permanent contact
(``w_c <= -1``: ``T = 2 pi/Omega``), and crossing orbits released on either
side of ``b``.  Note ``w_f**2 = 1`` and ``w_c**2 = 1`` both reduce to the
grazing condition ``2E = omega0**2 b**2`` (``b`` is a turning point).

For ``b = 0`` the arguments vanish and ``T = pi/omega0 + pi/Omega``, i.e.
``omega = 2 omega0 Omega/(omega0 + Omega)`` independently of the amplitude.

Analytic continuation.  Away from grazing (``|b| != |a0|``) the regime at
``epsilon = 0`` (no contact ``b > |a0|``, permanent contact ``b < -|a0|``, or
crossing) persists up to the nearest zero of ``Omega**2``, ``E``, ``P`` or
``2E - omega0**2 b**2`` (all polynomials in ``epsilon``; the last is where the
real orbit grazes ``b`` and changes regime).  In the disc bounded by that zero
the period is analytic: ``E``, ``Omega**2`` and the linear factors of ``P``
keep a positive real part and the arccos arguments never reach the cuts
``|w| >= 1``, so principal branches are the continuation.  Note that in the
contact regime the centre ``u_e`` moves with ``epsilon``, so for large real
``epsilon`` the orbit can leave the contact region even if ``b < -|a0|``.  Taylor coefficients
at ``epsilon = 0`` follow from the Cauchy integral on a circle inside that
disc (trapezoidal rule, geometric convergence).
"""

from __future__ import annotations

from typing import Any

import mpmath
import sympy

from .._errors import ConvergenceError, ProblemError
from .._precision import locked, workdps
from .arguments import (
    as_mpmath_number,
    omega0_parameter,
    real_parameter,
    rounded_coefficients,
    validate_order,
    validate_precision,
)

__all__ = [
    "piecewise_linear_exact_period",
    "piecewise_linear_exact_frequency",
    "piecewise_linear_frequency_taylor",
    "piecewise_linear_frequency_taylor_symbolic",
]

_MAXIMUM_CAUCHY_NODES = 2**12
_MAXIMUM_TAYLOR_ORDER = 60


def _parameters(a: Any, b: Any, a0: Any, omega0: Any) -> tuple[mpmath.mpf, mpmath.mpf, mpmath.mpf, mpmath.mpf]:
    return real_parameter(a, "a"), real_parameter(b, "b"), real_parameter(a0, "a0"), omega0_parameter(omega0)


def _real_period(stiffness: mpmath.mpf, b: mpmath.mpf, a0: mpmath.mpf, omega0: mpmath.mpf) -> mpmath.mpf:
    """Period for a real contact stiffness ``k = epsilon a`` (every regime)."""
    penetration = max(a0 - b, mpmath.mpf(0))
    if omega0**2 * a0 + stiffness * penetration == 0:
        raise ProblemError(
            f"a0 = {mpmath.nstr(a0, 15)} is the static equilibrium of u'' + omega0^2 u + epsilon a (u - b)_+ = 0: "
            "the motion is at rest and has no frequency; choose a0 away from the equilibrium"
        )
    if a0 < b and abs(a0) <= b:
        # Released in the free region with |a0| <= b: the orbit never reaches b.
        return 2 * mpmath.pi / omega0
    contact_square = omega0**2 + stiffness
    if contact_square <= 0:
        raise ProblemError(
            f"omega0**2 + epsilon*a = {mpmath.nstr(contact_square, 15)} <= 0: the contact spring makes the "
            "contact region unstable and the orbit reaches it; need omega0**2 + epsilon*a > 0"
        )
    energy = omega0**2 * a0**2 / 2 + stiffness * penetration**2 / 2
    contact_frequency = mpmath.sqrt(contact_square)
    free_time = mpmath.mpf(0)
    if energy > 0:
        argument = b * omega0 / mpmath.sqrt(2 * energy)
        if argument >= 1:
            free_time = 2 * mpmath.pi / omega0
        elif argument > -1:
            free_time = 2 * (mpmath.pi - mpmath.acos(argument)) / omega0
    contact_time = mpmath.mpf(0)
    scaled_contact_energy = 2 * energy * contact_square - stiffness * omega0**2 * b**2  # P = 2 (E - C) Omega**2
    if scaled_contact_energy > 0:
        argument = b * omega0**2 / mpmath.sqrt(scaled_contact_energy)
        if argument <= -1:
            contact_time = 2 * mpmath.pi / contact_frequency
        elif argument < 1:
            contact_time = 2 * mpmath.acos(argument) / contact_frequency
    return free_time + contact_time


class _AnalyticBranch:
    """Period as an analytic function of complex epsilon near 0 (non-grazing).

    The regime (free, contact or crossing) is the one at epsilon = 0.
    """

    def __init__(self, a: mpmath.mpf, b: mpmath.mpf, a0: mpmath.mpf, omega0: mpmath.mpf) -> None:
        if abs(b) == abs(a0):
            raise ProblemError(
                f"grazing case |b| = |a0| = {mpmath.nstr(abs(a0), 15)}: at epsilon = 0 the orbit just touches "
                "u = b and the frequency is not analytic in epsilon (no Taylor series, no complex continuation); "
                "use |b| != |a0| or a real epsilon"
            )
        if a0 == 0:
            raise ProblemError("a0 = 0 is the equilibrium at epsilon = 0; choose a0 != 0")
        self.a, self.b, self.a0, self.omega0 = a, b, a0, omega0
        if b > abs(a0):
            self.regime = "free"
        elif b < -abs(a0):
            self.regime = "contact"
        else:
            self.regime = "crossing"
        self.released_in_contact = a0 > b
        self.penetration = a0 - b if self.released_in_contact else mpmath.mpf(0)
        # P(k) = p2 k**2 + p1 k + p0 in the contact stiffness k = epsilon a.
        penetration_square = self.penetration**2
        p2 = penetration_square
        p1 = omega0**2 * (a0**2 + penetration_square - b**2)
        p0 = omega0**4 * a0**2
        self._p0 = p0
        if p2 != 0:
            root = mpmath.sqrt(mpmath.mpc(p1**2 - 4 * p2 * p0))
            self._p_roots = [(-p1 + root) / (2 * p2), (-p1 - root) / (2 * p2)]
        elif p1 != 0:
            self._p_roots = [mpmath.mpc(-p0 / p1)]
        else:
            self._p_roots = []
        singular_stiffnesses = [-(omega0**2)]
        if self.released_in_contact:
            # Grazing 2E = omega0**2 b**2: the real frequency changes regime there (for the
            # contact regime the other turning point 2 u_e - a0 reaches b).
            singular_stiffnesses.append(omega0**2 * (b**2 - a0**2) / penetration_square)
        if self.regime == "crossing":
            singular_stiffnesses += [abs(root) for root in self._p_roots]
            if self.released_in_contact:
                singular_stiffnesses.append(-(omega0**2) * a0**2 / penetration_square)  # E = 0
        if a == 0 or self.regime == "free":
            self.radius = mpmath.inf
        else:
            self.radius = min(abs(value) for value in singular_stiffnesses) / abs(a)

    def period(self, epsilon: mpmath.mpc) -> mpmath.mpc:
        omega0 = self.omega0
        if self.regime == "free" or self.a == 0:
            return 2 * mpmath.pi / omega0 + 0 * epsilon
        stiffness = epsilon * self.a
        contact_frequency = mpmath.sqrt(omega0**2 + stiffness)
        if self.regime == "contact":
            return 2 * mpmath.pi / contact_frequency
        energy = omega0**2 * self.a0**2 / 2 + stiffness * self.penetration**2 / 2
        free_argument = self.b * omega0 / mpmath.sqrt(2 * energy)
        root_of_p = mpmath.sqrt(self._p0)
        for root in self._p_roots:
            root_of_p *= mpmath.sqrt(1 - stiffness / root)
        contact_argument = self.b * omega0**2 / root_of_p
        return 2 * (mpmath.pi - mpmath.acos(free_argument)) / omega0 + 2 * mpmath.acos(contact_argument) / contact_frequency


@locked
def piecewise_linear_exact_period(
    epsilon: Any,
    *,
    a: Any,
    b: Any,
    a0: Any,
    omega0: Any = 1,
    precision: int = 30,
) -> mpmath.mpf | mpmath.mpc:
    """Exact period of ``u'' + omega0**2 u + epsilon a (u - b)_+ = 0``, ``u(0) = a0``, ``u'(0) = 0``.

    Parameters
    ----------
    epsilon : real or complex number
        Real: every regime (no contact, permanent contact, crossing, grazing).
        Complex: the analytic continuation from ``epsilon = 0`` (needs
        ``|b| != |a0|`` and ``|epsilon|`` below the nearest singularity).
    a : real number
        Contact stiffness coefficient (the spring is ``epsilon a``).
    b : real number
        Contact threshold (gap ``b > 0``, prestress ``b < 0``).
    a0 : real number
        Release position (either sign).
    omega0 : positive real number, optional
        Free angular frequency.
    precision : int, optional
        Decimal digits of the result.

    Returns
    -------
    mpmath.mpf or mpmath.mpc
        The period (complex only for complex epsilon).

    Raises
    ------
    ProblemError
        If the orbit enters a contact region with ``omega0**2 + epsilon a <= 0``,
        if ``a0`` is an equilibrium, or for complex epsilon in the grazing case
        or outside the disc of analyticity.

    Examples
    --------
    >>> import mpmath
    >>> mpmath.nstr(piecewise_linear_exact_period(3, a=1, b=0, a0=1, precision=20), 15)  # pi + pi/2
    '4.71238898038469'
    >>> mpmath.nstr(piecewise_linear_exact_period(3, a=1, b=2, a0=1, precision=20), 15)  # no contact: 2 pi
    '6.28318530717959'
    """
    precision = validate_precision(precision)
    with workdps(precision + 10):
        a_value, b_value, a0_value, omega0_value = _parameters(a, b, a0, omega0)
        epsilon_value = as_mpmath_number(epsilon, "epsilon")
        if isinstance(epsilon_value, mpmath.mpc) and epsilon_value.imag == 0:
            epsilon_value = epsilon_value.real
        if not mpmath.isfinite(epsilon_value):
            raise ProblemError(f"epsilon = {epsilon} must be finite")
        if isinstance(epsilon_value, mpmath.mpc):
            branch = _AnalyticBranch(a_value, b_value, a0_value, omega0_value)
            if abs(epsilon_value) >= branch.radius:
                raise ProblemError(
                    f"complex epsilon = {epsilon} lies outside the disc |epsilon| < "
                    f"{mpmath.nstr(branch.radius, 10)} where the period is analytic (a zero of omega0^2 + "
                    "epsilon a, of the energy or a grazing point bounds it); use a smaller |epsilon|"
                )
            period = branch.period(epsilon_value)
        else:
            period = _real_period(epsilon_value * a_value, b_value, a0_value, omega0_value)
    with workdps(precision):
        return +period


@locked
def piecewise_linear_exact_frequency(
    epsilon: Any,
    *,
    a: Any,
    b: Any,
    a0: Any,
    omega0: Any = 1,
    precision: int = 30,
) -> mpmath.mpf | mpmath.mpc:
    """Exact angular frequency ``2 pi / T`` of ``u'' + omega0**2 u + epsilon a (u - b)_+ = 0``.

    Same parameters as :func:`piecewise_linear_exact_period`.

    Examples
    --------
    >>> import mpmath
    >>> mpmath.nstr(piecewise_linear_exact_frequency(3, a=1, b=0, a0=-2, precision=20), 15)  # 2*1*2/(1+2)
    '1.33333333333333'
    """
    precision = validate_precision(precision)
    with workdps(precision + 10):
        period = piecewise_linear_exact_period(epsilon, a=a, b=b, a0=a0, omega0=omega0, precision=precision + 10)
        frequency = 2 * mpmath.pi / period
    with workdps(precision):
        return +frequency


@locked
def piecewise_linear_frequency_taylor(
    order: int,
    *,
    a: Any,
    b: Any,
    a0: Any,
    omega0: Any = 1,
    precision: int = 40,
) -> list[tuple[mpmath.mpf, mpmath.mpf]]:
    """Taylor coefficients ``omega_k`` of the exact frequency at ``epsilon = 0``.

    ``omega(epsilon) = sum_k omega_k epsilon**k`` for
    ``u'' + omega0**2 u + epsilon a (u - b)_+ = 0``, ``u(0) = a0``, ``u'(0) = 0``,
    in the non-grazing case ``|b| != |a0|``.  Without contact at epsilon = 0
    (``b > |a0|``) omega is exactly ``omega0``; in permanent contact
    (``b < -|a0|``) it is exactly ``sqrt(omega0**2 + epsilon a)`` (binomial
    series).  Otherwise the coefficients come from the Cauchy integral
    ``omega_k = (1/N) sum_j omega(r z_j) (r z_j)**(-k)`` over the N-th roots of
    unity ``z_j`` on the circle of radius ``r`` = 1/4 of the analyticity
    radius; N is doubled until the results agree, and the error estimate is
    the difference between N and N/2 nodes plus a rounding allowance.

    Parameters
    ----------
    order : int
        Highest coefficient wanted (0 <= order <= 60).
    a, b, a0 : real numbers
        Contact stiffness coefficient, threshold, release position.
    omega0 : positive real number, optional
        Free angular frequency.
    precision : int, optional
        Working digits.

    Returns
    -------
    list of (value, error_estimate)
        ``[(omega_0, err_0), ..., (omega_order, err_order)]`` as mpf.

    Raises
    ------
    ProblemError
        In the grazing case ``|b| = |a0|`` (omega is not analytic at 0).

    Examples
    --------
    >>> import mpmath
    >>> coefficients = piecewise_linear_frequency_taylor(2, a=1, b=0, a0=1, omega0=1, precision=30)
    >>> [mpmath.nstr(value, 15) for value, error in coefficients]  # 1, a/4, -a**2/8
    ['1.0', '0.25', '-0.125']
    """
    order = validate_order(order, maximum=_MAXIMUM_TAYLOR_ORDER)
    precision = validate_precision(precision)
    working_dps = precision + 15
    with workdps(working_dps):
        a_value, b_value, a0_value, omega0_value = _parameters(a, b, a0, omega0)
        branch = _AnalyticBranch(a_value, b_value, a0_value, omega0_value)
        zero = mpmath.mpf(0)
        if branch.regime == "free" or a_value == 0:
            results = [(+omega0_value, zero)] + [(zero, zero)] * order
        elif branch.regime == "contact":
            # sqrt(omega0**2 + epsilon a) = omega0 sum_k binom(1/2, k) (a/omega0**2)**k epsilon**k
            results = []
            for power in range(order + 1):
                value = omega0_value * mpmath.binomial(mpmath.mpf(1) / 2, power) * (a_value / omega0_value**2) ** power
                results.append((value, abs(value) * mpmath.mpf(10) ** (-working_dps + 2)))
        else:
            results = _cauchy_coefficients(branch, order, working_dps)
        return rounded_coefficients(results, precision)


def _cauchy_coefficients(branch: _AnalyticBranch, order: int, working_dps: int) -> list[tuple[mpmath.mpf, mpmath.mpf]]:
    radius = branch.radius / 4

    def frequency(node_index: int, node_count: int) -> mpmath.mpc:
        point = radius * mpmath.expjpi(mpmath.mpf(2 * node_index) / node_count)
        return 2 * mpmath.pi / branch.period(point)

    def coefficients(samples: list[mpmath.mpc]) -> list[mpmath.mpf]:
        count = len(samples)
        values = []
        for power in range(order + 1):
            total = mpmath.fsum(
                samples[j] * mpmath.expjpi(-mpmath.mpf(2 * j * power) / count) for j in range(count)
            )
            values.append((total / count).real / radius**power)
        return values

    node_count = 32
    samples = [frequency(j, node_count) for j in range(node_count)]
    previous = coefficients(samples)
    magnitude = max(abs(sample) for sample in samples)
    while node_count < _MAXIMUM_CAUCHY_NODES:
        refined_samples = []
        for j in range(node_count):
            refined_samples.append(samples[j])
            refined_samples.append(frequency(2 * j + 1, 2 * node_count))
        samples = refined_samples
        node_count *= 2
        current = coefficients(samples)
        results = []
        converged = True
        for power in range(order + 1):
            rounding = magnitude * mpmath.mpf(10) ** (-working_dps + 2) / radius**power
            difference = abs(current[power] - previous[power])
            results.append((current[power], difference + rounding))
            if difference > 100 * rounding:
                converged = False
        if converged:
            return results
        previous = current
    raise ConvergenceError(
        f"the Cauchy integral for the Taylor coefficients did not converge with {node_count} nodes; "
        "the orbit is extremely close to grazing (|b| ~ |a0|)"
    )


@locked
def piecewise_linear_frequency_taylor_symbolic(
    order: int,
    *,
    epsilon: sympy.Symbol | None = None,
    a: sympy.Symbol | None = None,
    omega0: sympy.Symbol | None = None,
) -> sympy.Expr:
    """Exact Taylor polynomial of omega(epsilon) for ``b = 0`` (f = a u_+).

    Obtained by ``sympy.series`` from the closed form of the period with
    ``b = 0``: both arccos arguments vanish, ``T = pi/omega0 + pi/Omega``,
    ``Omega = sqrt(omega0**2 + epsilon a)``, independent of ``a0``.

    Parameters
    ----------
    order : int
        Highest power of epsilon kept (0 <= order <= 60).
    epsilon, a, omega0 : sympy.Symbol, optional
        Symbols to use; defaults ``epsilon``, ``a`` and a positive ``omega0``.

    Returns
    -------
    sympy.Expr
        ``sum_{k<=order} omega_k epsilon**k`` (no O-term).

    Examples
    --------
    >>> piecewise_linear_frequency_taylor_symbolic(2)
    -a**2*epsilon**2/(8*omega0**3) + a*epsilon/(4*omega0) + omega0
    """
    order = validate_order(order, maximum=_MAXIMUM_TAYLOR_ORDER)
    epsilon_symbol = epsilon if epsilon is not None else sympy.Symbol("epsilon")
    a_symbol = a if a is not None else sympy.Symbol("a")
    omega0_symbol = omega0 if omega0 is not None else sympy.Symbol("omega0", positive=True)
    # Closed form with b = 0: w_f = w_c = 0 in the crossing formula of the module docstring,
    # T omega0 = 2 (pi - arccos 0) + 2 arccos(0) / (Omega/omega0) = pi + pi / (Omega/omega0).
    scaled = sympy.Symbol("s")  # s = epsilon a / omega0**2
    contact_ratio = sympy.sqrt(1 + scaled)  # Omega / omega0
    frequency_ratio = 2 * sympy.pi / (sympy.pi + sympy.pi / contact_ratio)
    series = sympy.series(frequency_ratio, scaled, 0, order + 1).removeO()
    return sympy.expand(omega0_symbol * series.subs(scaled, epsilon_symbol * a_symbol / omega0_symbol**2))
