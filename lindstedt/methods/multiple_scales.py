r"""Multiple scales / averaging for the primary resonance of a forced, damped oscillator: the verb ``frequency_response``.

The problem (:class:`~lindstedt.problems.forced.ForcedOscillator`) is

.. math::

    u'' + 2 \zeta \omega_0 u' + \omega_0^2 u + \varepsilon f(u) = \varepsilon F \cos \Omega t,
    \qquad \zeta = \varepsilon \hat\zeta, \quad \Omega = \omega_0 + \varepsilon \sigma ,

(weak damping, weak forcing, detuning σ = O(1)).  With the van der Pol variables
``u = A cos φ``, ``u' = −A Ω sin φ``, ``φ = Ω t − γ`` the equation is exactly
``A' = −(ε G/Ω) sin φ``, ``A γ' = (ε G/Ω) cos φ`` with
``ε G = (Ω² − ω0²) u − 2 ζ ω0 u' − ε f(u) + ε F cos Ω t``; averaging over φ gives, to first order,
the slow flow (derived here, see :func:`first_order_slow_flow`)

.. math::

    A' = -\zeta\omega_0 A + \frac{\varepsilon F}{2\omega_0}\sin\gamma, \qquad
    \gamma' = \varepsilon\sigma - \frac{\varepsilon f_1(A)}{2\omega_0 A} + \frac{\varepsilon F}{2\omega_0 A}\cos\gamma,

with ``f1(A) = (1/π) ∫_0^{2π} f(A cos θ) cos θ dθ`` (:func:`first_harmonic`).  Its fixed points give the
frequency-response curve (FRC)

.. math::

    \sigma_\pm(A) = \frac{f_1(A)}{2\omega_0 A} \pm \sqrt{\Big(\frac{F}{2\omega_0 A}\Big)^2 - \Big(\frac{\zeta\omega_0}{\varepsilon}\Big)^2},
    \qquad \sin\gamma = \frac{2\omega_0^2 \zeta A}{\varepsilon F},\quad
    \cos\gamma = \frac{f_1(A) - 2\omega_0\sigma A}{F},

the backbone ``Ω = ω0 + ε f1(A)/(2 ω0 A)`` (the first-order Lindstedt frequency in the harmonic
normalization), the peak ``A_max = ε F/(2 ζ ω0²)`` and the Jacobian of the slow flow at a fixed point:
``trace = −2 ζ ω0`` and, with ``s = σ − f1/(2 ω0 A)`` the distance to the backbone and
``g = f1/A``,

.. math::

    \det = \zeta^2\omega_0^2 + \varepsilon^2 s^2 - \frac{\varepsilon^2 A g'(A)}{2\omega_0} s
         = \mp \varepsilon^2 A R(A)\, \sigma_\pm'(A), \qquad R = \sqrt{\cdots},

so a fixed point is stable iff ``det > 0`` (a saddle iff ``det < 0``) and the folds (vertical tangents
of the FRC ``A(σ)``) are ``det = 0``, i.e. ``σ_±'(A) = 0``.

Second order (polynomial f only) is second-order averaging (Sanders–Verhulst) of the same exact
equations in the fast time τ = Ω t, with the zero-mean near-identity transformation
``x = y + ε u1(y, τ)`` (:func:`second_order_averaging`): the slow flow gains its ε² terms, the FRC
relation its O(ε) correction (eliminating γ consistently, so it stays regular at the peak), and
the maximum of u over a period is ``A + ε u1_A(φ = 0)``.  The amplitude ``A`` of the second-order
result is the averaged variable y (not the first harmonic of u, which differs at O(ε)).

Not covered (typed errors naming the fix): second order for piecewise or non-polynomial f
(:class:`~lindstedt.UnsupportedNonlinearityError`), orders above 2
(:class:`~lindstedt.OrderError`), f that is neither polynomial nor piecewise polynomial, and
the secondary (super/sub-harmonic) resonances: ``Ω`` far from ``ω0`` is refused by the
evaluators (:class:`~lindstedt.ParameterError`).

Examples
--------
>>> from lindstedt.problems.forced import ForcedOscillator
>>> curve = MultipleScales(order=1).frequency_response(ForcedOscillator("u**3", omega0=1, zeta="1/100", forcing=1))
>>> curve.first_harmonic
3*A**3/4
>>> curve.detuning_upper
3*A**2/8 + sqrt(-1/(10000*epsilon**2) + 1/(4*A**2))
"""

from __future__ import annotations

from typing import Any, Mapping

import sympy

from .._errors import OrderError, ParameterError, ProblemError, UnsupportedNonlinearityError
from .._cost import multiple_scales_estimate
from .._precision import locked, locked_methods
from ..problems.forced import ForcedOscillator
from ..problems.oscillator import DISPLACEMENT
from ..problems.parsing import as_exact, parse_real
from ..problems.piecewise_linear import decompose_piecewise
from ..results.expansion import EPSILON
from ..results.frequency_response import AMPLITUDE, DETUNING, PHASE, FrequencyResponseCurve

__all__ = [
    "MAX_ORDER",
    "MultipleScales",
    "first_harmonic",
    "first_order_slow_flow",
    "frequency_response_curve",
    "second_order_averaging",
]

#: Highest order of the multiple-scales frequency response.
MAX_ORDER = 2

_THETA = sympy.Dummy("theta", real=True)
#: the scaled damping ζ̂ = ζ/ε used inside the second-order derivation
_ZETA_HAT = sympy.Dummy("zeta_hat", nonnegative=True)
#: the forcing amplitude inside the second-order derivation (F = 0 gives the free oscillation: the backbone)
_FORCING = sympy.Dummy("F", real=True)


# ---------------------------------------------------------------------------------------------
# f1(A): first Fourier coefficient of f(A cos θ)
# ---------------------------------------------------------------------------------------------


def _cosine_power_primitive(power: int) -> sympy.Expr:
    """A primitive of cos(θ)**power in θ (sympy's, exact)."""
    return sympy.integrate(sympy.cos(_THETA) ** power, _THETA)


def _at_angle(primitive: sympy.Expr, kappa: sympy.Expr | None, side: str) -> sympy.Expr:
    """The primitive at θ = arccos κ (cos θ = κ, sin θ = sqrt(1 − κ²)), at θ = 0 for an upper end above the orbit,
    θ = π for a lower end below it (``kappa=None`` means unbounded on that side)."""
    if kappa is None:
        return primitive.subs(_THETA, 0 if side == "upper" else sympy.pi)
    cosine, sine = sympy.Dummy("c"), sympy.Dummy("s")
    value = primitive.subs({sympy.sin(_THETA): sine, sympy.cos(_THETA): cosine}).subs(_THETA, sympy.acos(kappa))
    return value.subs({cosine: kappa, sine: sympy.sqrt(1 - kappa**2)})


def _regime_value(intervals: list, amplitude: sympy.Expr, sample: sympy.Expr | None) -> sympy.Expr:
    """f1 on one regime: the intervals' pieces integrated over the θ-ranges they occupy.

    ``sample`` is a numeric amplitude inside the regime (None: every breakpoint is inside (−A, A)).
    """
    total = sympy.S.Zero
    for interval in intervals:
        bounds = []
        for end, side in ((interval.upper, "upper"), (interval.lower, "lower")):
            if end is None:
                bounds.append(None)
                continue
            inside = True if sample is None else bool(abs(end) < sample)
            if inside:
                bounds.append(end / amplitude)
            elif (side == "upper") == bool(end > 0):
                bounds.append(None)  # this end lies beyond the orbit on its own side: no limit
            else:
                bounds.append("empty")  # the whole interval lies beyond the orbit
        if "empty" in bounds:
            continue
        upper, lower = bounds
        for power, coefficient in enumerate(interval.coefficients):
            if coefficient == 0:
                continue
            primitive = _cosine_power_primitive(power + 1)
            span = _at_angle(primitive, lower, "lower") - _at_angle(primitive, upper, "upper")
            total += coefficient * amplitude**power * span
    return 2 * total / sympy.pi


def first_harmonic(f: sympy.Expr, amplitude: sympy.Expr = AMPLITUDE) -> tuple[sympy.Expr, tuple[str, ...]]:
    r"""``f1(A) = (1/π) ∫_0^{2π} f(A cos θ) cos θ dθ`` in closed form, with the assumptions it was derived under.

    Polynomial f: a polynomial in A (odd powers only; ``u**3`` gives ``3 A³/4``).  Piecewise-polynomial
    f (unilateral springs ``a*Max(0, u - b)``, ``Max(0, u)**2``, jumps ``Heaviside(u - b)``): each piece
    integrated over the arc ``θ ∈ [arccos(upper/A), arccos(lower/A)]`` where ``A cos θ`` stays in it, a
    closed form in ``κ = b/A`` (``acos κ``, ``sqrt(1 − κ²)``).  With numeric breakpoints the result is a
    ``Piecewise`` in A over the regimes ``A < |b_1| < |b_2| ...`` (a breakpoint with ``|b| ≥ A`` is never
    reached: no contact, or contact during the whole period); with symbolic ones every breakpoint is
    assumed inside the orbit, ``|b| < A`` (returned as an assumption).

    Parameters
    ----------
    f : sympy expression in ``u`` (the problem's nonlinearity, parameters substituted)
    amplitude : positive sympy symbol or number

    Returns
    -------
    (f1, assumptions)

    Raises
    ------
    UnsupportedNonlinearityError
        f neither polynomial nor piecewise polynomial (``sin(u)``, the Hertz law ``Max(0, u)**(3/2)``).

    Examples
    --------
    >>> import sympy
    >>> u = sympy.Symbol("u", real=True)
    >>> first_harmonic(u**3)
    (3*A**3/4, ())
    >>> first_harmonic(sympy.Max(0, u))                       # the spring u_+: half the linear one
    (A/2, ())
    >>> f1, _ = first_harmonic(sympy.Max(0, u - sympy.Rational(1, 2)))
    >>> f1.args[0]                                            # no contact below A = 1/2
    (0, A <= 1/2)
    >>> b = sympy.Symbol("b", real=True)
    >>> first_harmonic(sympy.Max(0, u - b))[1]
    ('|b| < A (every breakpoint inside the orbit: contact regime)',)
    """
    try:
        intervals = decompose_piecewise(f, DISPLACEMENT)
    except UnsupportedNonlinearityError as error:
        raise UnsupportedNonlinearityError(
            f"multiple scales needs f1(A) in closed form: {error}; for other laws integrate the full equation numerically"
        ) from None
    for interval in intervals:
        if interval.fractional or interval.analytic != 0:
            raise UnsupportedNonlinearityError(
                f"f = {f}: its first Fourier coefficient f1(A) is not elementary (fractional power or analytic "
                "non-polynomial piece); multiple scales covers polynomial and piecewise-polynomial f"
            )
    breakpoints = [interval.upper for interval in intervals[:-1]]
    if not breakpoints:
        return sympy.expand(_regime_value(intervals, amplitude, None)), ()
    if not all(point.is_number for point in breakpoints):
        names = ", ".join(f"|{sympy.sstr(point)}| < {sympy.sstr(amplitude)}" for point in breakpoints)
        value = sympy.simplify(_regime_value(intervals, amplitude, None))
        return value, (f"{names} (every breakpoint inside the orbit: contact regime)",)
    radii = sorted({abs(point) for point in breakpoints if point != 0})
    if not amplitude.is_Symbol:
        sample = amplitude
        return sympy.simplify(_regime_value(intervals, amplitude, sample)), ()
    edges = [sympy.S.Zero, *radii]
    pieces = []
    for index, low in enumerate(edges):
        high = edges[index + 1] if index + 1 < len(edges) else None
        sample = (low + high) / 2 if high is not None else low + 1
        value = sympy.simplify(_regime_value(intervals, amplitude, sample))
        pieces.append((value, amplitude <= high if high is not None else True))
    if len(pieces) == 1:
        return pieces[0][0], ()
    return sympy.Piecewise(*pieces), ()


# ---------------------------------------------------------------------------------------------
# first order
# ---------------------------------------------------------------------------------------------


def _exact(value: Any, what: str) -> sympy.Expr:
    """A coefficient: a sympy expression as it is (exactly), a number or numeric string through the one parser."""
    return as_exact(value, what=what) if isinstance(value, sympy.Basic) else parse_real(value, what=what)


def first_order_slow_flow(
    f1: sympy.Expr, omega0: sympy.Expr, zeta: sympy.Expr, forcing: sympy.Expr
) -> tuple[sympy.Expr, sympy.Expr]:
    """``(A', γ')`` of the first-order slow flow (physical time t; ``ζ`` the problem's damping ratio).

    Averaging ``A' = −(ε G/Ω) sin φ``, ``A γ' = (ε G/Ω) cos φ`` over φ with Ω → ω0 in the denominators:
    ``<cos φ sin φ> = 0``, ``<sin² φ> = 1/2``, ``<f(A cos φ) sin φ> = 0`` (even in φ),
    ``<f(A cos φ) cos φ> = f1/2``, ``<cos(φ + γ) sin φ> = −sin γ/2``, ``<cos(φ + γ) cos φ> = cos γ/2``.

    Examples
    --------
    >>> import sympy
    >>> from lindstedt.results.frequency_response import AMPLITUDE as A
    >>> first_order_slow_flow(3*A**3/4, 1, sympy.Rational(1, 100), 1)
    (-A/100 + epsilon*sin(gamma)/2, -3*A**2*epsilon/8 + epsilon*sigma + epsilon*cos(gamma)/(2*A))
    """
    A, gamma, sigma, epsilon = AMPLITUDE, PHASE, DETUNING, EPSILON
    omega0, zeta, forcing = _exact(omega0, "omega0"), _exact(zeta, "zeta"), _exact(forcing, "forcing")
    amplitude_rate = -zeta * omega0 * A + epsilon * forcing * sympy.sin(gamma) / (2 * omega0)
    phase_rate = epsilon * sigma - epsilon * f1 / (2 * omega0 * A) + epsilon * forcing * sympy.cos(gamma) / (2 * omega0 * A)
    return sympy.expand(amplitude_rate), sympy.expand(phase_rate)


# ---------------------------------------------------------------------------------------------
# second order: averaging with Laurent polynomials in z = exp(i φ)
# ---------------------------------------------------------------------------------------------

_Laurent = dict  # {k: coefficient of z**k}, z = exp(i φ)


def _laurent_add(*terms: _Laurent) -> _Laurent:
    total: _Laurent = {}
    for term in terms:
        for k, value in term.items():
            total[k] = total.get(k, 0) + value
    return {k: sympy.expand(v) for k, v in total.items() if sympy.expand(v) != 0}


def _laurent_scale(term: _Laurent, factor: sympy.Expr) -> _Laurent:
    return {k: sympy.expand(factor * v) for k, v in term.items()}


def _laurent_mul(left: _Laurent, right: _Laurent) -> _Laurent:
    total: _Laurent = {}
    for i, a in left.items():
        for j, b in right.items():
            total[i + j] = total.get(i + j, 0) + a * b
    return {k: sympy.expand(v) for k, v in total.items() if sympy.expand(v) != 0}


def _laurent_antiderivative(term: _Laurent) -> _Laurent:
    """The zero-mean primitive in φ."""
    return {k: sympy.expand(v / (sympy.I * k)) for k, v in term.items() if k != 0}


def _laurent_dphi(term: _Laurent) -> _Laurent:
    return {k: sympy.expand(sympy.I * k * v) for k, v in term.items() if k != 0}


def _laurent_diff(term: _Laurent, symbol: sympy.Expr) -> _Laurent:
    return {k: sympy.expand(sympy.diff(v, symbol)) for k, v in term.items()}


def _mean(term: _Laurent) -> sympy.Expr:
    return sympy.expand(term.get(0, sympy.S.Zero))


def _real(value: sympy.Expr) -> sympy.Expr:
    """A real expression written with I: its imaginary parts cancel exactly once expanded."""
    value = sympy.expand(value)
    if value.has(sympy.I):
        value = sympy.expand(sympy.simplify(value))
    if value.has(sympy.I):  # pragma: no cover - a bug, not an input error
        raise ArithmeticError(f"second-order averaging left an imaginary part in {value}")
    return value


def second_order_averaging(
    f: sympy.Expr, omega0: sympy.Expr, forcing: sympy.Expr
) -> dict[str, Any]:
    r"""Second-order averaging of the exact van der Pol equations for a polynomial f.

    In the fast time ``τ = Ω t`` with ``x = (A, γ)``: ``x_τ = ε F1(x, τ) + ε² F2(x, τ) + O(ε³)``, where
    (``φ = τ − γ``, ``G0 = 2ω0σ A cos φ + 2ζ̂ω0² A sin φ − f(A cos φ) + F cos(φ + γ)``,
    ``G1 = σ² A cos φ + 2ζ̂ω0σ A sin φ``, from ``1/Ω² = 1/ω0² − 2εσ/ω0³ + …``)

    ``F1 = (−G0 sin φ, G0 cos φ/A)/ω0²``,  ``F2 = (−G1 sin φ, G1 cos φ/A)/ω0² − (2σ/ω0³)(−G0 sin φ, G0 cos φ/A)``.

    With ``x = y + ε u1(y, τ)``, ``u1 = ∫ (F1 − <F1>) dτ`` of zero mean, ``y_τ = ε g1 + ε² g2`` with
    ``g1 = <F1>``, ``g2 = <DF1 · u1> + <F2>``, where the derivative in γ at fixed τ is ``∂_γ − ∂_φ``.
    Everything is computed exactly on Laurent polynomials in ``z = e^{iφ}``.

    Returns
    -------
    dict
        ``g1``, ``g2`` (pairs, τ-time, in A, γ, σ and the scaled damping ζ̂), ``u1_amplitude_at_peak``
        (``u1_A`` at φ = 0), ``harmonic_shift`` (the cos φ coefficient of ``u1_A cos φ + A u1_γ sin φ``:
        the first harmonic of u is ``A + ε`` this), and ``zeta_hat`` (the symbol used for ζ̂).

    Examples
    --------
    >>> import sympy
    >>> u = sympy.Symbol("u", real=True)
    >>> F = sympy.Symbol("F")
    >>> result = second_order_averaging(u**3, 1, F)
    >>> result["g1"][0]
    -_zeta_hat*A + F*sin(gamma)/2
    >>> free = {result["forcing"]: 0, result["zeta_hat"]: 0}               # the free oscillation
    >>> result["g2"][0].subs(free), result["u1_amplitude_at_peak"].subs(free)
    (0, -5*A**3/32 + A*sigma/2)
    """
    A, gamma, sigma = AMPLITUDE, PHASE, DETUNING
    omega0, forcing = _exact(omega0, "omega0"), _exact(forcing, "forcing")
    half = sympy.Rational(1, 2)
    cosine: _Laurent = {1: half, -1: half}
    sine: _Laurent = {1: -sympy.I * half, -1: sympy.I * half}
    polynomial = sympy.Poly(sympy.expand(f), DISPLACEMENT)
    nonlinear: _Laurent = {}
    power: _Laurent = {0: sympy.S.One}
    for degree in range(polynomial.degree() + 1):
        coefficient = polynomial.coeff_monomial(DISPLACEMENT**degree)
        if coefficient != 0:
            nonlinear = _laurent_add(nonlinear, _laurent_scale(power, coefficient * A**degree))
        power = _laurent_mul(power, cosine)
    zeta_hat = _ZETA_HAT
    G0 = _laurent_add(
        _laurent_scale(cosine, 2 * omega0 * sigma * A + forcing * sympy.cos(gamma)),
        _laurent_scale(sine, 2 * zeta_hat * omega0**2 * A - forcing * sympy.sin(gamma)),
        _laurent_scale(nonlinear, -1),
    )
    G1 = _laurent_add(_laurent_scale(cosine, sigma**2 * A), _laurent_scale(sine, 2 * zeta_hat * omega0 * sigma * A))
    F1 = (_laurent_scale(_laurent_mul(G0, sine), -1 / omega0**2), _laurent_scale(_laurent_mul(G0, cosine), 1 / (omega0**2 * A)))
    F2 = (
        _laurent_add(_laurent_scale(_laurent_mul(G1, sine), -1 / omega0**2), _laurent_scale(F1[0], -2 * sigma / omega0)),
        _laurent_add(_laurent_scale(_laurent_mul(G1, cosine), 1 / (omega0**2 * A)), _laurent_scale(F1[1], -2 * sigma / omega0)),
    )
    g1 = tuple(_real(_mean(component)) for component in F1)
    u1 = tuple(_laurent_antiderivative(component) for component in F1)
    g2 = []
    for component, correction in zip(F1, F2):
        d_amplitude = _laurent_diff(component, A)
        d_phase = _laurent_add(_laurent_diff(component, gamma), _laurent_scale(_laurent_dphi(component), -1))
        product = _laurent_add(_laurent_mul(d_amplitude, u1[0]), _laurent_mul(d_phase, u1[1]))
        g2.append(_real(_mean(product) + _mean(correction)))
    u1_peak = _real(sum(u1[0].values(), sympy.S.Zero))
    first = _laurent_add(_laurent_mul(u1[0], cosine), _laurent_scale(_laurent_mul(u1[1], sine), A))
    harmonic_shift = _real(first.get(1, 0) + first.get(-1, 0))
    return {
        "g1": g1,
        "g2": tuple(g2),
        "u1_amplitude_at_peak": u1_peak,
        "harmonic_shift": harmonic_shift,
        "zeta_hat": zeta_hat,
        "forcing": forcing,
    }


# ---------------------------------------------------------------------------------------------
# the method
# ---------------------------------------------------------------------------------------------


def _check_order(order: Any) -> int:
    if isinstance(order, bool) or not isinstance(order, int):
        raise OrderError(f"order must be the integer 1 or 2, got {order!r}")
    if order < 1 or order > MAX_ORDER:
        raise OrderError(
            f"multiple scales is derived to order 1 (any polynomial or piecewise-polynomial f) and 2 (polynomial f), "
            f"got order={order}; ask for order=1 or order=2"
        )
    return order


@locked_methods()
class MultipleScales:
    """The method of multiple scales (equivalently, averaging) for the primary resonance Ω ≈ ω0.

    One verb: :meth:`frequency_response`.

    Parameters
    ----------
    order : {1, 2}
        1: any polynomial or piecewise-polynomial f (unilateral springs, gaps, jumps).  2: polynomial f.

    Examples
    --------
    >>> from lindstedt.problems.forced import ForcedOscillator
    >>> curve = MultipleScales(order=1).frequency_response(ForcedOscillator("Max(0, u)", omega0=1, zeta="1/20"))
    >>> curve.backbone_detuning
    1/4
    >>> MultipleScales(order=3)
    Traceback (most recent call last):
    ...
    lindstedt._errors.OrderError: multiple scales is derived to order 1 (any polynomial or piecewise-polynomial f) and 2 (polynomial f), got order=3; ask for order=1 or order=2
    """

    def __init__(self, order: int = 1):
        self.order = _check_order(order)

    def __repr__(self) -> str:
        return f"MultipleScales(order={self.order})"

    def frequency_response(self, problem: ForcedOscillator) -> FrequencyResponseCurve:
        """The frequency response of ``problem`` near Ω = ω0 (slow flow, FRC, backbone, stability).

        Parameters
        ----------
        problem : ForcedOscillator

        Returns
        -------
        FrequencyResponseCurve

        Raises
        ------
        ProblemError
            ``problem`` is not a :class:`ForcedOscillator`.
        ParameterError
            f uses a parameter named ``A``, ``sigma`` or ``gamma`` (the result's own symbols).
        UnsupportedNonlinearityError
            f1 not elementary, or order 2 for a non-polynomial f.
        """
        if not isinstance(problem, ForcedOscillator):
            raise ProblemError(
                f"frequency_response takes a lindstedt ForcedOscillator, got {type(problem).__name__}; "
                "build one with ForcedOscillator(f, omega0=..., zeta=..., forcing=...)"
            )
        clashes = sorted({symbol.name for symbol in problem.nonlinearity.free_symbols} & {"A", "sigma", "gamma"})
        if clashes:
            raise ParameterError(f"the parameter name(s) {clashes} are the result's own symbols (A, sigma, gamma); rename them")
        f = problem.nonlinearity
        omega0 = problem.omega0
        polynomial = problem.oscillator.is_polynomial
        if self.order == 2 and not polynomial:
            raise UnsupportedNonlinearityError(
                f"second-order multiple scales is derived for polynomial f only, not f = {f} (the averaging of the "
                "product DF1·u1 needs f smooth); use MultipleScales(order=1) for piecewise f"
            )
        if not polynomial:
            multiple_scales_estimate(problem).check()
        f1, assumptions = first_harmonic(f)
        second = second_order_averaging(f, omega0, _FORCING) if self.order == 2 else None
        slow_flow = first_order_slow_flow(f1, omega0, problem.zeta, problem.forcing)
        return FrequencyResponseCurve.build(problem, self.order, f1, assumptions, slow_flow, second)


@locked
def frequency_response_curve(
    problem: Any,
    order: int = 1,
    *,
    omega0: Any = None,
    zeta: Any = 0,
    forcing: Any = 1,
    params: Mapping[str, Any] | None = None,
) -> FrequencyResponseCurve:
    """``MultipleScales(order).frequency_response(problem)``; ``problem`` may also be f with its arguments.

    Examples
    --------
    >>> curve = frequency_response_curve("u**3", omega0=1, zeta="1/100", forcing="1/2")
    >>> curve.peak_amplitude
    25*epsilon
    >>> [round(float(a), 6) for a in curve.amplitudes(1.1, 0.1)]      # three steady states at Ω = 1.1
    [0.254908, 1.523003, 1.717212]
    """
    if isinstance(problem, ForcedOscillator):
        if omega0 is not None or zeta != 0 or forcing != 1 or params is not None:
            raise ProblemError("pass either a ForcedOscillator or f with its problem arguments (omega0=, zeta=, forcing=, "
                               "params=), not both")
    else:
        problem = ForcedOscillator(problem, omega0=omega0, zeta=zeta, forcing=forcing, params=params)
    return MultipleScales(order).frequency_response(problem)
