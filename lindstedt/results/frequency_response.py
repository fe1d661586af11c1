r"""The frequency response near the primary resonance, by multiple scales: :class:`FrequencyResponseCurve`.

For ``u'' + 2 ζ ω0 u' + ω0² u + ε f(u) = ε F cos Ω t`` with ``ζ = O(ε)`` and ``Ω = ω0 + ε σ``
(see :mod:`lindstedt.methods.multiple_scales` for the derivation), the result holds, as sympy
expressions in the amplitude ``A``, the detuning ``σ``, the phase ``γ`` and ``ε``:

* the first Fourier coefficient ``f1(A) = (1/π) ∫_0^{2π} f(A cos θ) cos θ dθ``;
* the slow flow ``(A', γ')`` of ``u ≈ A cos(Ω t − γ)``;
* the FRC relation ``H(A, σ) = (2 ω0² ζ A/ε)² + (f1 − 2 ω0 σ A)² − F² (+ ε H2) = 0`` and its two branches
  ``σ_±(A) = f1/(2 ω0 A) ± sqrt((F/(2 ω0 A))² − (ζ ω0/ε)²) (+ ε σ2_±)``;
* the backbone ``σ_b(A) = f1/(2 ω0 A) (+ ε σ_b2)``, the peak amplitude, the phase (``sin γ``, ``cos γ``);
* the Jacobian of the slow flow at a fixed point: ``trace = −2 ζ ω0`` and
  ``det = ζ² ω0² + ε² s² − ε² A g'(A) s/(2 ω0)`` (``s = σ − f1/(2 ω0 A)``, ``g = f1/A``),
  zero at the folds;

and evaluates them: :meth:`~FrequencyResponseCurve.amplitudes` (every steady amplitude at a forcing
frequency), :meth:`~FrequencyResponseCurve.detuning`, :meth:`~FrequencyResponseCurve.frequency`,
:meth:`~FrequencyResponseCurve.backbone`, :meth:`~FrequencyResponseCurve.stability`.  It shows
itself through the one rendering layer: :meth:`~FrequencyResponseCurve.to_latex`, ``to_json()``
(:class:`~lindstedt.render.json.JsonExport`) and ``_repr_latex_``; code for its closed forms is
``lindstedt.generate_code(curve, quantity, language)`` (the export layer reads the result, via
:meth:`~FrequencyResponseCurve.code_form`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable, ClassVar, NamedTuple

import numpy as np
import sympy

from .._errors import ParameterError, ProblemError
from .._precision import locked_methods
from ..render.display import jupyter_latex, labelled_repr, latex_text, shorten
from ..render.json import JsonExport
from ..problems.forced import ForcedOscillator, check_forcing_frequency
from .expansion import EPSILON

__all__ = ["AMPLITUDE", "DETUNING", "PHASE", "FrequencyResponseCurve", "Stability", "SteadyState"]

#: The amplitude A of ``u ≈ A cos(Ω t − γ)`` (positive).
AMPLITUDE = sympy.Symbol("A", positive=True)
#: The detuning σ of ``Ω = ω0 + ε σ``.
DETUNING = sympy.Symbol("sigma", real=True)
#: The phase lag γ of ``u ≈ A cos(Ω t − γ)``.
PHASE = sympy.Symbol("gamma", real=True)

#: |Ω − ω0| must stay below this fraction of ω0 (the nearest secondary resonance, ω0/2, is at ω0/2).
DETUNING_LIMIT = 0.5

_CODE_QUANTITIES = ("detuning_upper", "detuning_lower", "backbone", "first_harmonic", "relation", "determinant")


class Stability(NamedTuple):
    """Stability of a fixed point of the slow flow: its Jacobian's trace and determinant."""

    trace: np.ndarray
    determinant: np.ndarray
    stable: np.ndarray
    kind: np.ndarray  # "stable", "saddle", "center" (ζ = 0, det > 0), "fold" (det = 0) or "none" (no fixed point)


class SteadyState(NamedTuple):
    """One steady state at a forcing frequency: ``u ≈ A cos(Ω t − γ)``, its branch of the FRC and its stability."""

    amplitude: float
    branch: str  # "upper" (σ = σ+(A)) or "lower" (σ = σ−(A)), first order
    phase: float  # γ in (−π, π] (first order)
    kind: str  # "stable", "saddle", "center", "fold"
    max_displacement: float  # max_t u (order 2: with the O(ε) harmonics)


def _positive_number(value: Any, name: str, example: str) -> float:
    if isinstance(value, (bool, str)) or isinstance(value, sympy.Basic) and not value.is_number:
        raise ParameterError(f"{name} must be a positive number such as {example}, got {value!r}")
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be a positive number such as {example}, got {value!r}") from None
    if not math.isfinite(number) or number <= 0:
        raise ParameterError(f"{name} must be a positive finite number such as {example}, got {value!r}")
    return number


def _amplitude_array(value: Any) -> np.ndarray:
    if isinstance(value, (bool, str)) or isinstance(value, sympy.Basic) and not value.is_number:
        raise ParameterError(f"A must be a positive number or an array of them, such as 0.5, got {value!r}")
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(f"A must be a positive number or an array of them, such as 0.5, got {value!r}") from None
    if not np.all(np.isfinite(array)) or np.any(array <= 0):
        raise ParameterError("A must be positive and finite (the amplitude of u ≈ A cos(Ω t − γ))")
    return array


def _branch_sign(branch: Any) -> int:
    if branch in ("upper", "+", 1):
        return 1
    if branch in ("lower", "-", -1):
        return -1
    raise ParameterError(f"branch must be 'upper' (σ+) or 'lower' (σ−), got {branch!r}")


@locked_methods()
@dataclass(frozen=True)
class FrequencyResponseCurve(JsonExport):
    r"""The frequency response of a forced oscillator near Ω = ω0 by multiple scales (frozen; symbolic).

    Build it with :class:`~lindstedt.methods.multiple_scales.MultipleScales` or
    :func:`~lindstedt.methods.multiple_scales.frequency_response_curve`.  Symbols: ``A``
    (:data:`AMPLITUDE`), ``sigma`` (:data:`DETUNING`), ``gamma`` (:data:`PHASE`), ``epsilon``;
    the problem's ω0, ζ, F and parameters are substituted (symbolic ones kept).

    Attributes
    ----------
    problem : ForcedOscillator
    order : int
        1 or 2 (2: polynomial f).
    first_harmonic : sympy.Expr
        f1(A) (a ``Piecewise`` in A over the contact regimes for numeric gaps).
    assumptions : tuple of str
        What the closed forms assume besides ``A > 0``, ``ζ = O(ε)``, ``Ω − ω0 = O(ε)``.
    slow_flow : (sympy.Expr, sympy.Expr)
        ``(dA/dt, dγ/dt)``, truncated at ε^order.
    backbone_detuning : sympy.Expr
        σ_b(A): the free oscillation's frequency is ``ω0 + ε σ_b``.
    detuning_upper, detuning_lower : sympy.Expr
        σ_±(A), the two branches of the FRC (order 2: ``σ1_± + ε σ2_±``, singular at the peak where the
        branches meet — use :attr:`relation` there).
    relation : sympy.Expr
        ``H(A, σ)``; the FRC is ``H = 0`` (order 2: consistent to O(ε), regular everywhere).
    phase_sine, phase_cosine : sympy.Expr
        sin γ and cos γ at a fixed point, in A and σ (first order).
    peak_amplitude : sympy.Expr
        The largest amplitude, ``ε F/(2 ζ ω0²)`` (order 2 with its O(ε²) correction); ``oo`` without damping.
    trace, determinant : sympy.Expr
        Jacobian of the first-order slow flow at a fixed point, in A and σ.
    max_displacement : sympy.Expr
        ``max_t u`` on the steady state of amplitude A at detuning σ (``A``; order 2: ``A + ε u1_A``).

    Examples
    --------
    >>> from lindstedt.methods.multiple_scales import frequency_response_curve
    >>> curve = frequency_response_curve("u**3", omega0=1, zeta="1/100", forcing=1)
    >>> curve.backbone_detuning, curve.trace
    (3*A**2/8, -1/50)
    >>> curve.determinant
    -3*A**2*epsilon**2*(-3*A**2/8 + sigma)/4 + epsilon**2*(-3*A**2/8 + sigma)**2 + 1/10000
    >>> round(float(curve.backbone(1.0, 0.1)), 6)
    1.0375
    """

    SCHEMA: ClassVar[str] = "lindstedt.frequency-response-curve/1"

    problem: ForcedOscillator
    order: int
    first_harmonic: sympy.Expr
    assumptions: tuple[str, ...]
    slow_flow: tuple[sympy.Expr, sympy.Expr]
    backbone_detuning: sympy.Expr
    detuning_upper: sympy.Expr
    detuning_lower: sympy.Expr
    relation: sympy.Expr
    phase_sine: sympy.Expr
    phase_cosine: sympy.Expr
    peak_amplitude: sympy.Expr
    trace: sympy.Expr
    determinant: sympy.Expr
    max_displacement: sympy.Expr
    _cache: dict = field(default_factory=dict, repr=False, compare=False)

    def __getstate__(self) -> dict[str, Any]:
        """Picklable (process pools, Dask): the memo of compiled closures is rebuilt where it is needed."""
        state = dict(self.__dict__)
        state["_cache"] = {}
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)

    # -- construction ----------------------------------------------------------------------
    @classmethod
    def build(
        cls,
        problem: ForcedOscillator,
        order: int,
        f1: sympy.Expr,
        assumptions: tuple[str, ...],
        slow_flow: tuple[sympy.Expr, sympy.Expr],
        second: dict[str, Any] | None = None,
    ) -> "FrequencyResponseCurve":
        """Assemble the closed forms from f1 and the first-order ``slow_flow`` (A', γ') the method derived (and, at
        order 2, :func:`~lindstedt.methods.multiple_scales.second_order_averaging`)."""
        A, sigma, epsilon = AMPLITUDE, DETUNING, EPSILON
        omega0, zeta, forcing = problem.omega0, problem.zeta, problem.forcing
        g = f1 / A
        backbone = sympy.simplify(g / (2 * omega0)) if not isinstance(f1, sympy.Piecewise) else sympy.piecewise_fold(g / (2 * omega0))
        radius = sympy.sqrt((forcing / (2 * omega0 * A)) ** 2 - (zeta * omega0 / epsilon) ** 2)
        upper, lower = backbone + radius, backbone - radius
        relation = (2 * omega0**2 * zeta * A / epsilon) ** 2 + (f1 - 2 * omega0 * sigma * A) ** 2 - forcing**2
        phase_sine = 2 * omega0**2 * zeta * A / (epsilon * forcing)
        phase_cosine = (f1 - 2 * omega0 * sigma * A) / forcing
        peak = epsilon * sympy.Abs(forcing) / (2 * zeta * omega0**2) if zeta != 0 else sympy.oo  # F < 0: a phase shift
        trace = -2 * zeta * omega0
        distance = sigma - backbone
        determinant = zeta**2 * omega0**2 + epsilon**2 * distance**2 - epsilon**2 * A * sympy.diff(g, A) * distance / (2 * omega0)
        flow = slow_flow
        maximum: sympy.Expr = A
        if second is not None:
            flow, backbone, upper, lower, relation, peak, maximum = _second_order(
                problem, f1, second, backbone, upper, lower, relation, peak, phase_sine, phase_cosine
            )
        return cls(
            problem=problem,
            order=order,
            first_harmonic=f1,
            assumptions=tuple(assumptions),
            slow_flow=flow,
            backbone_detuning=backbone,
            detuning_upper=upper,
            detuning_lower=lower,
            relation=relation,
            phase_sine=phase_sine,
            phase_cosine=phase_cosine,
            peak_amplitude=peak,
            trace=trace,
            determinant=determinant,
            max_displacement=maximum,
        )

    # -- numeric evaluation ----------------------------------------------------------------
    def _numeric(self, name: str, arguments: tuple[sympy.Symbol, ...]) -> Callable[..., Any]:
        """The expression ``name`` as a NumPy function of ``arguments`` (the problem's values substituted)."""
        key = (name, arguments)
        if key not in self._cache:
            self.problem.numeric_coefficients()  # a ParameterError naming the symbols without a value
            expression = getattr(self, name)
            if isinstance(expression, tuple):
                raise TypeError(name)
            function = sympy.lambdify(arguments, expression, modules="numpy")

            def quiet(*values: Any, function: Callable[..., Any] = function) -> Any:
                # a Piecewise becomes numpy.select, which evaluates every piece: the discarded pieces may be NaN
                with np.errstate(invalid="ignore", divide="ignore"):
                    return function(*values)

            self._cache[key] = quiet
        return self._cache[key]

    def _check_epsilon(self, epsilon: Any) -> float:
        return _positive_number(epsilon, "epsilon", "0.05")

    def detuning(self, A: Any, epsilon: Any, branch: str = "upper") -> np.ndarray:
        """σ_±(A) at ``epsilon`` (NaN where A exceeds the peak: no steady state of that amplitude).

        Examples
        --------
        >>> from lindstedt.methods.multiple_scales import frequency_response_curve
        >>> curve = frequency_response_curve("u**3", omega0=1, zeta="1/100", forcing=1)
        >>> round(float(curve.detuning(1.0, 0.1, "upper")), 6), round(float(curve.detuning(1.0, 0.1, "lower")), 6)
        (0.864898, -0.114898)
        """
        amplitude = _amplitude_array(A)
        eps = self._check_epsilon(epsilon)
        name = "detuning_upper" if _branch_sign(branch) > 0 else "detuning_lower"
        with np.errstate(invalid="ignore"):
            value = self._numeric(name, (AMPLITUDE, EPSILON))(amplitude, eps)
        return np.asarray(value, dtype=float) + 0.0 * amplitude

    def frequency(self, A: Any, epsilon: Any, branch: str = "upper") -> np.ndarray:
        """The forcing frequency ``Ω = ω0 + ε σ_±(A)`` at which A is a steady amplitude (NaN where there is none,
        and where ``|Ω − ω0| ≥ ω0/2``: outside the primary resonance the method covers)."""
        eps = self._check_epsilon(epsilon)
        return self._within_range(float(self.problem.omega0) + eps * self.detuning(A, eps, branch))

    def backbone(self, A: Any, epsilon: Any) -> np.ndarray:
        """The backbone frequency ``ω0 + ε σ_b(A)`` (the free oscillation of amplitude A; NaN where
        ``|Ω − ω0| ≥ ω0/2``, outside the primary resonance the method covers)."""
        amplitude = _amplitude_array(A)
        eps = self._check_epsilon(epsilon)
        value = self._numeric("backbone_detuning", (AMPLITUDE, EPSILON))(amplitude, eps)
        return self._within_range(float(self.problem.omega0) + eps * (np.asarray(value, dtype=float) + 0.0 * amplitude))

    def _within_range(self, omega: np.ndarray) -> np.ndarray:
        omega0 = float(self.problem.omega0)
        return np.where(np.abs(omega - omega0) < DETUNING_LIMIT * omega0, omega, np.nan)

    def stability(self, A: Any, epsilon: Any, branch: str = "upper") -> Stability:
        """Trace and determinant of the slow flow's Jacobian at the fixed point (A, σ_±(A)), and its kind.

        Stable iff trace < 0 and det > 0; ``det < 0`` is a saddle (the middle branch of a fold); with ζ = 0
        a fixed point with ``det > 0`` is a center of the averaged flow.  The classification is the first
        order one also for ``order=2`` (it changes only within O(ε) of a fold).

        Examples
        --------
        >>> from lindstedt.methods.multiple_scales import frequency_response_curve
        >>> curve = frequency_response_curve("u**3", omega0=1, zeta="1/100", forcing="1/2")
        >>> [str(k) for k in curve.stability([0.2549, 1.523], 0.1, "upper").kind]   # σ+: right of the backbone
        ['stable', 'saddle']
        >>> [str(k) for k in curve.stability(1.7172, 0.1, "lower").kind.ravel()]   # the resonant state, left of it
        ['stable']
        """
        amplitude = _amplitude_array(A)
        eps = self._check_epsilon(epsilon)
        sign = _branch_sign(branch)
        with np.errstate(invalid="ignore", divide="ignore"):  # numpy.select evaluates every piece
            sigma = self._first_order_detunings()["upper" if sign > 0 else "lower"](amplitude, eps)
            determinant = self._numeric("determinant", (AMPLITUDE, DETUNING, EPSILON))(amplitude, sigma, eps)
        return self._classified(amplitude, np.asarray(determinant, dtype=float), eps)

    def _classified(self, amplitude: np.ndarray, determinant: np.ndarray, eps: float) -> Stability:
        determinant = determinant + 0.0 * amplitude
        trace = np.full(amplitude.shape, float(self.trace.subs(self.problem.parameter_values)))
        scale = max(float(self.problem.zeta) * float(self.problem.omega0), eps) ** 2
        kind = np.where(
            np.isnan(determinant),
            "none",
            np.where(
                np.abs(determinant) <= 1e-12 * scale,
                "fold",
                np.where(determinant < 0, "saddle", np.where(trace < 0, "stable", "center")),
            ),
        )
        return Stability(trace, determinant, kind == "stable", kind)

    def _relation_function(self, sigma: float, eps: float) -> Callable[[np.ndarray], np.ndarray]:
        function = self._numeric("relation", (AMPLITUDE, DETUNING, EPSILON))

        def relation(a: Any) -> np.ndarray:
            with np.errstate(invalid="ignore", divide="ignore"):  # numpy.select evaluates every piece
                return np.asarray(function(a, sigma, eps), dtype=float) + 0.0 * np.asarray(a)

        return relation

    def _detuning_of(self, Omega: Any, epsilon: Any) -> tuple[float, float]:
        omega = check_forcing_frequency(Omega)
        eps = self._check_epsilon(epsilon)
        omega0 = float(self.problem.numeric_coefficients()[0])
        if abs(omega - omega0) >= DETUNING_LIMIT * omega0:
            raise ParameterError(
                f"Omega = {omega:g} is far from omega0 = {omega0:g}: multiple scales here covers the primary resonance "
                f"Omega = omega0 + eps*sigma with |Omega - omega0| < {DETUNING_LIMIT:g}*omega0 (the super/sub-harmonic "
                "resonances near 2*omega0, omega0/2, 3*omega0, omega0/3 are not covered); give Omega near omega0, "
                "or integrate the full equation numerically"
            )
        return (omega - omega0) / eps, eps

    def amplitudes(self, Omega: Any, epsilon: Any) -> np.ndarray:
        """Every real steady amplitude A > 0 at the forcing frequency Ω, increasing.

        Polynomial f: the positive real roots of the FRC relation, a polynomial in A (``numpy.roots``,
        polished by Newton on the relation).  Piecewise f: a bracketing search on ``(0, A_max]`` — with
        damping every root satisfies ``A ≤ ε F/(2 ζ ω0²)`` exactly; without it the bound is found by doubling
        until the relation stays positive — on a grid refined at the breakpoints ``|b|``, each sign change
        solved by Brent's method, and tangential (double) roots caught by minimising ``|H|`` between grid points.

        Examples
        --------
        >>> from lindstedt.methods.multiple_scales import frequency_response_curve
        >>> curve = frequency_response_curve("Max(0, u - 1/5)", omega0=1, zeta="1/100", forcing="1/2")
        >>> [round(float(a), 6) for a in curve.amplitudes(1.0, 0.1)]
        [1.142756]
        """
        sigma, eps = self._detuning_of(Omega, epsilon)
        key = ("roots", sigma, eps)
        roots = self._cache.get(key)
        if roots is None:
            if len(self._cache) > 256:  # keep the memo of roots small
                for stale in [k for k in list(self._cache) if isinstance(k, tuple) and k[0] == "roots"]:
                    self._cache.pop(stale, None)  # another thread may have dropped it already
            polynomial = self.problem.oscillator.is_polynomial
            roots = self._polynomial_roots(sigma, eps) if polynomial else self._bracketed_roots(sigma, eps)
            self._cache[key] = roots
        return roots.copy()

    def steady_states(self, Omega: Any, epsilon: Any) -> tuple[SteadyState, ...]:
        """Every steady state at Ω: amplitude, branch, phase, stability and ``max_t u``, by increasing amplitude.

        The branch, phase and stability are those of the first-order fixed point (for ``order=2`` the
        amplitude and the maximum of u are the second-order ones).

        Examples
        --------
        >>> from lindstedt.methods.multiple_scales import frequency_response_curve
        >>> curve = frequency_response_curve("u**3", omega0=1, zeta="1/100", forcing="1/2")
        >>> [(round(s.amplitude, 4), s.branch, s.kind) for s in curve.steady_states(1.1, 0.1)]
        [(0.2549, 'upper', 'stable'), (1.523, 'upper', 'saddle'), (1.7172, 'lower', 'stable')]
        """
        sigma, eps = self._detuning_of(Omega, epsilon)
        roots = self.amplitudes(Omega, epsilon)
        maxima = self.displacement_maxima(Omega, epsilon)
        phase_sine = self._numeric("phase_sine", (AMPLITUDE, DETUNING, EPSILON))
        phase_cosine = self._numeric("phase_cosine", (AMPLITUDE, DETUNING, EPSILON))
        first = self._first_order_detunings()
        states = []
        for amplitude, maximum in zip(roots, maxima):
            with np.errstate(invalid="ignore", divide="ignore"):
                candidates = {name: float(function(amplitude, eps)) for name, function in first.items()}
            branch = min(candidates, key=lambda name: abs(candidates[name] - sigma) if math.isfinite(candidates[name]) else math.inf)
            with np.errstate(invalid="ignore", divide="ignore"):
                sine = float(phase_sine(amplitude, sigma, eps))
                cosine = float(phase_cosine(amplitude, sigma, eps))
                at = candidates[branch]
                determinant = float(self._numeric("determinant", (AMPLITUDE, DETUNING, EPSILON))(amplitude, at, eps))
            kind = str(self._classified(np.asarray([amplitude]), np.asarray([determinant]), eps).kind[0])
            states.append(SteadyState(float(amplitude), branch, math.atan2(sine, cosine), kind, float(maximum)))
        return tuple(states)

    def _first_order_detunings(self) -> dict[str, Callable[..., Any]]:
        """σ±(A) of the first order (the branch a steady state lies on), as NumPy functions of (A, ε)."""
        if "first_detunings" not in self._cache:
            self.problem.numeric_coefficients()
            f1 = self.first_harmonic
            omega0, zeta, forcing = self.problem.omega0, self.problem.zeta, self.problem.forcing
            backbone = f1 / (2 * omega0 * AMPLITUDE)
            radius = sympy.sqrt((forcing / (2 * omega0 * AMPLITUDE)) ** 2 - (zeta * omega0 / EPSILON) ** 2)
            self._cache["first_detunings"] = {
                name: sympy.lambdify((AMPLITUDE, EPSILON), backbone + sign * radius, modules="numpy")
                for name, sign in (("upper", 1), ("lower", -1))
            }
        return self._cache["first_detunings"]

    def displacement_maxima(self, Omega: Any, epsilon: Any) -> np.ndarray:
        """``max_t u`` of every steady state at Ω (order 1: the amplitudes; order 2: ``A + ε u1_A``)."""
        sigma, eps = self._detuning_of(Omega, epsilon)
        roots = self.amplitudes(Omega, epsilon)
        function = self._numeric("max_displacement", (AMPLITUDE, DETUNING, EPSILON))
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.asarray([float(function(a, sigma, eps)) for a in roots], dtype=float)

    def _polynomial_roots(self, sigma: float, eps: float) -> np.ndarray:
        key = ("polynomial", self.order)
        if key not in self._cache:
            expression = sympy.together(self.relation.subs(self.problem.parameter_values))
            numerator = sympy.numer(expression)
            self._cache[key] = sympy.Poly(sympy.expand(numerator), AMPLITUDE)
        polynomial = self._cache[key]
        coefficients = [complex(sympy.N(c.subs({DETUNING: sigma, EPSILON: eps}), 30)).real for c in polynomial.all_coeffs()]
        if not all(math.isfinite(c) for c in coefficients):
            raise ParameterError(f"the steady-state amplitude equation at detuning σ = {sigma:.6g}, ε = {eps:.6g} has "
                                 "coefficients beyond the range of a float (a forcing, damping or ε far too large); "
                                 "rescale the problem")
        while coefficients and coefficients[0] == 0:
            coefficients.pop(0)
        roots = np.roots(coefficients) if len(coefficients) > 1 else np.array([])
        relation = self._relation_function(sigma, eps)
        derivative = sympy.lambdify((AMPLITUDE, DETUNING, EPSILON), sympy.diff(self.relation.subs(self.problem.parameter_values), AMPLITUDE))
        found = []
        scale = max(abs(c) for c in coefficients) if coefficients else 1.0
        for root in roots:
            if abs(root.imag) > 1e-6 * max(1.0, abs(root)) or root.real <= 0:
                continue
            a = root.real
            for _ in range(20):  # Newton polish on the relation itself
                slope = float(derivative(a, sigma, eps))
                if slope == 0:
                    break
                step = float(relation(a)) / slope
                a -= step
                if abs(step) <= 1e-15 * abs(a):
                    break
            if a > 0 and abs(float(relation(a))) <= 1e-8 * scale * max(1.0, a) ** len(coefficients):
                found.append(a)
        if self.order == 2:
            found = [a for a in found if self._near_first_order(a, sigma, eps)]
        return np.unique(np.round(np.sort(np.asarray(found, dtype=float)), 13))

    def _near_first_order(self, a: float, sigma: float, eps: float) -> bool:
        """Order 2: keep a root of the corrected relation ``H1 + ε H2`` only where the correction is one.

        ``H1 = (2ω0²ζA/ε)² + (f1 − 2ω0σA)² − F²``: a genuine root has ``|ε H2|`` small against the size of
        the terms of H1, ``S = (2ω0²ζA/ε)² + f1² + (2ω0σA)² + F²`` (here ``|ε H2| ≤ S/2``); the truncated
        ε-terms, of higher degree in A, bring spurious roots at large A where ``ε H2 ≈ −H1`` is as large as S.
        """
        key = "relation_terms"
        if key not in self._cache:
            f1 = self.first_harmonic
            omega0, zeta, forcing = self.problem.omega0, self.problem.zeta, self.problem.forcing
            damping = (2 * omega0**2 * zeta * AMPLITUDE / EPSILON) ** 2
            h1 = damping + (f1 - 2 * omega0 * DETUNING * AMPLITUDE) ** 2 - forcing**2
            size = damping + f1**2 + (2 * omega0 * DETUNING * AMPLITUDE) ** 2 + forcing**2
            arguments = (AMPLITUDE, DETUNING, EPSILON)
            self._cache[key] = (sympy.lambdify(arguments, h1), sympy.lambdify(arguments, size))
        h1, size = self._cache[key]
        correction = float(self._relation_function(sigma, eps)(a)) - float(h1(a, sigma, eps))
        return abs(correction) <= 0.5 * float(size(a, sigma, eps))

    def _bracketed_roots(self, sigma: float, eps: float) -> np.ndarray:
        from scipy.optimize import brentq, minimize_scalar

        relation = self._relation_function(sigma, eps)
        omega0, zeta, forcing = self.problem.numeric_coefficients()
        breakpoints = sorted({abs(float(b)) for b in _breakpoints(self.problem)} - {0.0})
        if zeta > 0:
            top = eps * abs(forcing) / (2 * zeta * omega0**2) * (1 + 1e-12)
        else:
            top = max([1.0, *breakpoints]) * 2
            while top < 1e8 and not (relation(top) > 0 and relation(2 * top) > 0 and top > 2 * max([0.0, *breakpoints])):
                top *= 2
        grid = np.unique(
            np.concatenate(
                [np.geomspace(top * 1e-9, top, 1500), np.linspace(0, top, 3001)[1:], np.asarray([b for b in breakpoints if b < top])]
            )
        )
        values = relation(grid)
        roots: list[float] = []
        tolerance = 1e-12 * forcing**2
        for index in range(len(grid) - 1):
            left, right = grid[index], grid[index + 1]
            if values[index] == 0:
                roots.append(left)
            elif values[index] * values[index + 1] < 0:
                roots.append(brentq(relation, left, right, xtol=1e-15 * right, rtol=1e-15, maxiter=200))
        if values[-1] == 0:
            roots.append(grid[-1])
        for index in range(1, len(grid) - 1):  # a local minimum of |H| that does not change sign: tangency
            if values[index - 1] * values[index] > 0 and values[index] * values[index + 1] > 0 and abs(values[index]) < 1e-2 * forcing**2:
                magnitude = np.abs(values[index - 1 : index + 2])
                if magnitude[1] <= magnitude[0] and magnitude[1] <= magnitude[2]:
                    best = minimize_scalar(
                        lambda a: abs(float(relation(a))), bounds=(grid[index - 1], grid[index + 1]), method="bounded",
                        options={"xatol": 1e-14},
                    )
                    if best.fun <= tolerance * 1e3:
                        roots.append(float(best.x))
        roots = sorted(roots)
        unique: list[float] = []
        for root in roots:
            if not unique or abs(root - unique[-1]) > 1e-9 * max(1.0, root):
                unique.append(root)
        return np.asarray(unique, dtype=float)

    # -- exports ------------------------------------------------------------------------------
    def to_latex(self) -> str:
        r"""A LaTeX fragment (``align*``): the equation, the assumptions, f1, the slow flow, the FRC, the backbone,
        the peak and the stability determinant.

        Examples
        --------
        >>> from lindstedt.methods.multiple_scales import frequency_response_curve
        >>> print(frequency_response_curve("u**3", omega0=1, zeta="1/100", forcing=1).to_latex())  # doctest: +ELLIPSIS
        % lindstedt: u'' + u'/50 + u + eps*(u**3) = eps*cos(Omega*t); multiple scales, order 1
        \begin{align*}
        & \ddot u + 2\zeta\omega_0 \dot u + \omega_0^2 u + \varepsilon f(u) = \varepsilon F \cos \Omega t,\quad ...
        & f(u) = u^{3},\ \omega_0 = 1,\ \zeta = \frac{1}{100},\ F = 1 \\
        f_1(A) &= \frac{3 A^{3}}{4} \\
        ...
        \sigma_{b}(A) &= \frac{3 A^{2}}{8} \\
        A_{\max} &= 50 \varepsilon \\
        ...
        \end{align*}
        <BLANKLINE>
        """
        def latex(expression: Any) -> str:
            return sympy.latex(expression, symbol_names={EPSILON: r"\varepsilon"})

        problem = self.problem
        values = (
            rf"f(u) = {latex(problem.nonlinearity)},\ \omega_0 = {latex(problem.omega0)},\ \zeta = {latex(problem.zeta)},"
            rf"\ F = {latex(problem.forcing)}"
        )
        lines = [
            r"& \ddot u + 2\zeta\omega_0 \dot u + \omega_0^2 u + \varepsilon f(u) = \varepsilon F \cos \Omega t,\quad "
            r"\Omega = \omega_0 + \varepsilon\sigma,\quad u \approx A\cos(\Omega t - \gamma)",
            r"& " + values,
        ]
        if self.assumptions:
            lines.append(r"& \text{assuming } " + latex_text("; ".join(self.assumptions)))
        lines.append(rf"f_1(A) &= {latex(self.first_harmonic)}")
        lines.append(rf"\dot A &= {latex(self.slow_flow[0])} + O(\varepsilon^{{{self.order + 1}}})")
        lines.append(rf"\dot \gamma &= {latex(self.slow_flow[1])} + O(\varepsilon^{{{self.order + 1}}})")
        lines.append(rf"\sigma_{{+}}(A) &= {latex(self.detuning_upper)}")
        lines.append(rf"\sigma_{{-}}(A) &= {latex(self.detuning_lower)}")
        lines.append(rf"0 &= {latex(self.relation)}")
        lines.append(rf"\sigma_{{b}}(A) &= {latex(self.backbone_detuning)}")
        lines.append(rf"A_{{\max}} &= {latex(self.peak_amplitude)}")
        lines.append(rf"\operatorname{{tr}} J &= {latex(self.trace)},\quad \det J = {latex(self.determinant)}")
        header = f"% lindstedt: {problem.describe()}; multiple scales, order {self.order}\n"
        return header + "\\begin{align*}\n" + " \\\\\n".join(lines) + "\n\\end{align*}\n"

    def _repr_latex_(self) -> str:
        """Jupyter's rendering: :meth:`to_latex` as display math."""
        return jupyter_latex(self.to_latex())

    def __repr__(self) -> str:
        fields = [
            ("problem", repr(self.problem.describe())),
            ("order", str(self.order)),
            ("first_harmonic", shorten(sympy.sstr(self.first_harmonic), 200, "curve.first_harmonic")),
            ("detuning_upper", shorten(sympy.sstr(self.detuning_upper), 200, "curve.detuning_upper")),
        ]
        return labelled_repr("FrequencyResponseCurve", fields)

    def code_form(self, quantity: str) -> tuple[list[sympy.Symbol], sympy.Symbol, sympy.Expr]:
        """(arguments, the vectorised argument, the exact closed form) of ``quantity``: what code generation prints
        (with 25-digit constants).

        Examples
        --------
        >>> from lindstedt.methods.multiple_scales import frequency_response_curve
        >>> arguments, vector, expression = frequency_response_curve("u**3", omega0=1, forcing=1).code_form("backbone")
        >>> arguments, expression
        ([A, epsilon], 3*A**2/8)
        """
        if quantity not in _CODE_QUANTITIES:
            raise ProblemError(f"quantity must be one of {_CODE_QUANTITIES}, got {quantity!r}")
        name = {"backbone": "backbone_detuning"}.get(quantity, quantity)
        expression = getattr(self, name)
        symbols = sorted(
            (s for s in expression.free_symbols if s not in (AMPLITUDE, DETUNING, EPSILON)), key=lambda s: s.name
        )
        head = [AMPLITUDE, DETUNING, EPSILON] if quantity in ("relation", "determinant") else [AMPLITUDE, EPSILON]
        return [*head, *symbols], AMPLITUDE, expression


def _breakpoints(problem: ForcedOscillator) -> list[sympy.Expr]:
    from ..problems.oscillator import DISPLACEMENT
    from ..problems.piecewise_linear import decompose_piecewise

    intervals = decompose_piecewise(problem.nonlinearity, DISPLACEMENT)
    return [interval.upper for interval in intervals[:-1]]


def _second_order(
    problem: ForcedOscillator,
    f1: sympy.Expr,
    second: dict[str, Any],
    backbone: sympy.Expr,
    upper: sympy.Expr,
    lower: sympy.Expr,
    relation: sympy.Expr,
    peak: sympy.Expr,
    phase_sine: sympy.Expr,
    phase_cosine: sympy.Expr,
) -> tuple:
    """The order-2 closed forms from the averaged ``g1``, ``g2`` (τ-time, scaled damping ζ̂)."""
    A, sigma, gamma, epsilon = AMPLITUDE, DETUNING, PHASE, EPSILON
    omega0, zeta, forcing = problem.omega0, problem.zeta, problem.forcing
    zeta_hat, F = second["zeta_hat"], second["forcing"]  # scaled damping ζ̂ = ζ/ε and the forcing, as symbols
    # the free oscillation (F = 0, ζ = 0) first: its frequency Ω − γ_t is the backbone
    free = {zeta_hat: 0, F: 0}
    g1_free = [sympy.expand(v.subs(free)) for v in second["g1"]]
    g2_free = [sympy.expand(v.subs(free)) for v in second["g2"]]
    phase_rate = epsilon * omega0 * g1_free[1] + epsilon**2 * (omega0 * g2_free[1] + sigma * g1_free[1])
    free_frequency = sympy.expand(omega0 + epsilon * sigma - phase_rate)
    free_frequency = sympy.expand(free_frequency.subs(sigma, backbone))  # independent of σ to O(ε²) on the backbone
    free_frequency = sum(free_frequency.coeff(epsilon, k) * epsilon**k for k in range(3))
    backbone2 = sympy.expand((free_frequency - omega0) / epsilon)
    g1 = [sympy.expand(v.subs(F, forcing)) for v in second["g1"]]
    g2 = [sympy.expand(v.subs(F, forcing)) for v in second["g2"]]
    physical = {zeta_hat: zeta / epsilon}
    # slow flow in t = τ/Ω: y_t = (ω0 + εσ)(ε g1 + ε² g2) = ε ω0 g1 + ε² (ω0 g2 + σ g1) + O(ε³)
    flow = tuple(
        sympy.expand((epsilon * omega0 * a + epsilon**2 * (omega0 * b + sigma * a)).subs(physical)) for a, b in zip(g1, g2)
    )
    # the FRC relation, γ eliminated consistently to O(ε): sin γ = S1 + ε S2, cos γ = C1 + ε C2, S² + C² = 1
    s1 = 2 * omega0**2 * zeta_hat * A / forcing
    c1 = (f1 - 2 * omega0 * sigma * A) / forcing
    at_first = {sympy.sin(gamma): s1, sympy.cos(gamma): c1}
    h2_hat = sympy.expand(-4 * omega0**2 * forcing * (s1 * g2[0].subs(at_first) + A * c1 * g2[1].subs(at_first)))
    h1_hat = (2 * omega0**2 * zeta_hat * A) ** 2 + (f1 - 2 * omega0 * sigma * A) ** 2 - forcing**2
    relation2 = sympy.expand((h1_hat + epsilon * h2_hat).subs(physical))
    # branches σ1± + ε σ2±, σ2 = −H2/∂_σ H1 at σ1± (singular at the peak, where ∂_σ H1 = 0)
    d_sigma = sympy.diff(h1_hat, sigma)
    branches = []
    for first in (upper, lower):
        correction = (-(h2_hat / d_sigma)).subs(physical).subs(sigma, first)
        branches.append(first + epsilon * correction)
    # peak: A1 + ε A2 with A2 = −H2/(∂_A H1) at (A1, σ_b(A1)), where ∂_σ H1 = 0
    if zeta != 0:
        a1 = sympy.Abs(forcing) / (2 * zeta_hat * omega0**2)
        sigma1 = (f1 / (2 * omega0 * A)).subs(A, a1)
        at_peak = {A: a1, sigma: sigma1}
        a2 = -(h2_hat.subs(at_peak)) / sympy.diff(h1_hat, A).subs(at_peak)
        peak = sympy.simplify((a1 + epsilon * a2).subs(physical))
    u1_peak = second["u1_amplitude_at_peak"].subs(F, forcing).subs({sympy.sin(gamma): phase_sine, sympy.cos(gamma): phase_cosine})
    maximum = A + epsilon * sympy.expand(u1_peak.subs(physical))
    return flow, backbone2, branches[0], branches[1], relation2, peak, maximum

