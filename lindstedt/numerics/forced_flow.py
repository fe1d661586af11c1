"""Exact event-driven flow of the forced, damped piecewise-linear oscillators (the numerical ground truth).

The equations (:mod:`lindstedt.problems.forced`)::

    M X'' + C X' + K X + ε W (A X − b)_+ = ε s P cos(Ω t)          (ForcedSystem)
    u'' + 2 ζ ω0 u' + ω0² u + ε f(u)     = ε s F cos(Ω t)          (ForcedOscillator, f piecewise linear)

with ``s`` the load scale (1 by default).  In a *contact state* S (the springs engaged, or the
interval of f holding u) the system is linear with constant coefficients; with ``z = (X, X')``

    z' = A_S z + c_S + Re(e e^{iΩt}),    e = (0, ε s M⁻¹ P),

so an arc starting at ``(t0, z0)`` is, in closed form,

    z(t) = z*_S + Re(Z_S e^{iΩt}) + expm(A_S (t − t0)) w0,    w0 = z0 − z*_S − Re(Z_S e^{iΩt0}),

with the equilibrium ``z*_S = −A_S⁻¹ c_S`` and the harmonic particular solution
``Z_S = (iΩ − A_S)⁻¹ e`` (a :class:`~lindstedt.ResonanceError` when iΩ is an eigenvalue of an
undamped state).  ``expm(A_S τ) = V e^{Λτ} V⁻¹`` uses a cached eigen-decomposition per state
(complex eigenvalues allowed); when ``A_S`` is defective or its eigenvectors ill-conditioned
(e.g. critical damping), ``scipy.linalg.expm`` is used instead.

Switches.  A gap ``g_i = a_i X − b_i`` is, inside an arc, the finite exponential sum
``c_i + Re Σ_k γ_ik e^{λ_k τ}`` (the eigenvalues of A_S and iΩ for the forcing) with the
derivative bounds ``|g^{(j)}| ≤ Σ_k |λ_k|^j |γ_ik| e^{max(Re λ_k, 0) τ_max}`` (for the
``expm`` fallback: ``|a_i| ‖A_S‖^j ‖w0‖`` times Van Loan's bound of ``‖expm(A_S τ)‖`` from a
Schur form).  These bounds feed the Taylor minorants of :mod:`lindstedt.numerics.switching`
exactly as in :class:`~lindstedt.numerics.ExactFlow`: no excursion to the other side deeper
than the rounding band can be stepped over; the root is polished by Brent's method to about
4 ulp.  On a switching surface the side is decided by ``g'``, then by ``g''`` computed with the
field of the side being entered.

Sensitivities (analytic).  Across an arc ``∂z/∂z0`` is multiplied by ``expm(A_S τ)``; the
parameter sensitivities obey ``δ(t) = expm(A_S τ) δ(t0) + q(t) − expm(A_S τ) q(t0)`` with
``q = Re(∂Z/∂s e^{iΩt})`` for the load scale and ``q = Re((∂Z/∂Ω + i t Z) e^{iΩt})``,
``∂Z/∂Ω = −i (iΩ − A_S)⁻¹ Z`` for the frequency.  At a switch where the field jumps (a law
such as ``c*Heaviside(u - b)``) all of them are multiplied by the saltation matrix
``I + (f⁺ − f⁻) nᵀ / (nᵀ f⁻)`` (the identity for the continuous ``(·)_+`` springs).  The period
map ``Π(z0) = z(2πk/Ω)`` adds ``z'(kT) · d(kT)/dΩ = −z'(kT) kT/Ω`` to ``∂Π/∂Ω``.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
import sympy

from .._errors import ConvergenceError, ParameterError, ProblemError, ResonanceError, UnsupportedNonlinearityError
from .._precision import locked
from ..problems.forced import ForcedOscillator, ForcedSystem, check_forcing_frequency
from ..problems.piecewise_linear import decompose_piecewise_linear
from ._period_map import PeriodMapValue, linear_frequency_bounds, real_argument
from .flow import FlowResult, SwitchEvent
from .switching import _Bracket, _Counters, _earliest_switch, _first_exit, _SearchFailure

__all__ = ["ForcedFlow"]

_EPS = float(np.finfo(float).eps)
_TINY = float(np.finfo(float).tiny)
#: half-width of the band of rounding-level excursions, in eps × magnitude of g (as ExactFlow)
_BAND_FACTOR = 64.0
#: |g| below this many eps × magnitude counts as "on the switching surface" (as ExactFlow)
_SURFACE_FACTOR = 16.0
#: an arc is restarted after this many periods of the forcing (or of the slowest eigenvalue)
_CHUNK_PERIODS = 4.0
#: eigenvector bases with a larger condition number fall back to scipy.linalg.expm
_CONDITION_LIMIT = 1e5
#: consecutive switches at one instant after which the motion is declared stuck on a surface
_MAX_INSTANT_SWITCHES = 50


def _sup_power_exp(power: int, alpha: float, tau_max: float) -> float:
    """sup of τ^power e^{α τ} over [0, tau_max]."""
    if power == 0:
        return math.exp(max(alpha, 0.0) * tau_max)
    if alpha >= 0.0 or tau_max <= power / -alpha:
        return tau_max**power * math.exp(alpha * tau_max)
    peak = power / -alpha
    return peak**power * math.exp(-power)


@dataclass(frozen=True)
class _State:
    """One contact state: z' = A z + c + forcing; ``eigenvalues`` None means the expm fallback."""

    flags: tuple[bool, ...]
    A: np.ndarray
    equilibrium: np.ndarray
    eigenvalues: np.ndarray | None
    basis: np.ndarray | None
    inverse: np.ndarray | None
    norm: float  # ‖A‖₂
    abscissa: float  # max Re λ
    nilpotent: float  # ‖N‖_F of the Schur form (fallback only)
    slowest: float  # min |λ|

    def propagator(self, tau: float) -> np.ndarray:
        """expm(A τ) (real)."""
        if self.eigenvalues is None:
            import scipy.linalg  # here, not at module level: import lindstedt stays light
            return scipy.linalg.expm(self.A * tau)
        return ((self.basis * np.exp(self.eigenvalues * tau)) @ self.inverse).real

    def growth_bound(self, tau_max: float) -> float:
        """A bound of ‖expm(A τ)‖₂ on [0, tau_max] (fallback: Van Loan's Schur bound)."""
        n = self.A.shape[0]
        return sum(self.nilpotent**k / math.factorial(k) * _sup_power_exp(k, self.abscissa, tau_max) for k in range(n))

    def chunk(self, frequency: float) -> float:
        length = _CHUNK_PERIODS * 2.0 * math.pi / max(frequency, self.slowest)
        if self.abscissa > 0.0:
            length = min(length, 1.0 / self.abscissa)
        return length


class ForcedFlow:
    """Exact (closed-form, event-driven) flow of a forced, damped piecewise-linear oscillator.

    Implements the :class:`~lindstedt.numerics._period_map.PeriodMap` protocol.

    Parameters
    ----------
    problem : ForcedSystem or ForcedOscillator
        A :class:`ForcedOscillator` must have numeric coefficients and a piecewise-linear f
        (jumps allowed, e.g. ``Max(0, u - b) + c*Heaviside(u - b)``).
    epsilon : float
        ε ≥ 0.
    max_arcs : int, optional
        Safety cap on the arcs of one run.

    Raises
    ------
    ProblemError, ParameterError, UnsupportedNonlinearityError
        With the fix named (a smooth law needs the DOP853 flow ``SmoothForcedFlow``).

    Examples
    --------
    >>> from lindstedt.problems.forced import ForcedOscillator
    >>> flow = ForcedFlow(ForcedOscillator("Max(0, u - 1/5)", omega0=1, zeta="1/20"), epsilon=0.5)
    >>> flow.dimension
    2
    >>> out = flow.period_map([0.0, 0.0], 1.2)
    >>> out.state.shape, out.d_state.shape, out.d_frequency.shape
    ((2,), (2, 2), (2,))
    """

    @locked  # the problem's sympy numbers to floats
    def __init__(self, problem: ForcedSystem | ForcedOscillator, epsilon: float, *, max_arcs: int = 1_000_000) -> None:
        eps = real_argument(epsilon, "epsilon")
        if eps < 0.0:
            raise ParameterError(f"epsilon must be ≥ 0 (the size of the nonlinearity and of the load), got {epsilon!r}; e.g. epsilon=0.1")
        self.problem = problem
        self.epsilon = eps
        self.max_arcs = int(max_arcs)
        if isinstance(problem, ForcedSystem):
            system = problem.system
            system.require_unilateral("the exact forced flow (ForcedFlow)")
            self._M, self._K, self._C = system.M, system.K, np.asarray(problem.C, dtype=float)
            self._P = np.asarray(problem.P, dtype=float)
            self._a, self._b, self._W = system.A, system.b, system.W
            self._jumps = np.zeros(len(self._b))
            self._intervals = None
        elif isinstance(problem, ForcedOscillator):
            omega0, zeta, forcing = problem.numeric_coefficients()  # ParameterError naming missing values
            try:
                intervals = decompose_piecewise_linear(problem.nonlinearity, problem.oscillator.variable)
            except UnsupportedNonlinearityError as error:
                raise UnsupportedNonlinearityError(
                    f"{error}. ForcedFlow needs a piecewise-linear f; for smooth or other laws use the DOP853 flow "
                    "SmoothForcedFlow (lindstedt.numerics.forced_smooth), which has the same interface"
                ) from None
            self._M = np.ones((1, 1))
            self._K = np.array([[omega0**2]])
            self._C = np.array([[2.0 * zeta * omega0]])
            self._P = np.array([forcing])
            self._intervals = [(float(piece.slope), float(piece.intercept)) for piece in intervals]
            breakpoints = [piece.upper for piece in intervals[:-1]]
            self._b = np.array([float(point) for point in breakpoints])
            self._a = np.ones((len(breakpoints), 1))
            self._W = np.zeros((1, len(breakpoints)))
            # jump of f across breakpoint i (exact): f(b_i⁺) − f(b_i⁻)
            self._jumps = np.array([
                float(sympy.simplify((right.slope - left.slope) * point + right.intercept - left.intercept))
                for left, right, point in zip(intervals, intervals[1:], breakpoints)
            ])
        else:
            raise ProblemError(f"ForcedFlow needs a ForcedSystem or a ForcedOscillator, got {type(problem).__name__}")
        for name, matrix in (("M", self._M), ("K", self._K), ("C", self._C), ("P", self._P), ("b", self._b)):
            if not np.all(np.isfinite(matrix)):
                raise ParameterError(f"{name} must be numeric and finite for the exact flow; give numbers")
        n = self._M.shape[0]
        self.dimension: int = 2 * n
        self._n = n
        self._mass_inverse = np.linalg.inv(self._M)
        self._load = np.concatenate([np.zeros(n), self.epsilon * (self._mass_inverse @ self._P)])  # e for s = 1
        self._states: dict[tuple[bool, ...], _State] = {}

    # ------------------------------------------------------------------ contact states
    def _stiffness_and_force(self, flags: tuple[bool, ...]) -> tuple[np.ndarray, np.ndarray]:
        """K_S and the constant force r_S of the state: M X'' + C X' + K_S X = r_S + load."""
        eps = self.epsilon
        if self._intervals is not None:
            slope, intercept = self._intervals[sum(flags)]
            return self._K + eps * slope, np.array([-eps * intercept])
        mask = np.array(flags, dtype=bool)
        W_S = self._W[:, mask]
        return self._K + eps * W_S @ self._a[mask], eps * W_S @ self._b[mask]

    def _state(self, flags: tuple[bool, ...], cost: dict[str, int]) -> _State:
        state = self._states.get(flags)
        if state is None:
            state = self._states[flags] = self._decompose(flags)
            cost["decompositions"] += 1
        return state

    def _decompose(self, flags: tuple[bool, ...]) -> _State:
        n = self._n
        stiffness, force = self._stiffness_and_force(flags)
        A = np.block([[np.zeros((n, n)), np.eye(n)], [-self._mass_inverse @ stiffness, -self._mass_inverse @ self._C]])
        try:
            position = np.linalg.solve(stiffness, force)
        except np.linalg.LinAlgError:
            raise ProblemError(
                f"the stiffness of contact state {flags} is singular at ε = {self.epsilon}: the state has no "
                "static equilibrium; change ε (or the law)"
            ) from None
        equilibrium = np.concatenate([position, np.zeros(n)])
        eigenvalues, basis = np.linalg.eig(A)
        norm = float(np.linalg.norm(A, 2))
        slowest = float(np.min(np.abs(eigenvalues)))
        abscissa = float(np.max(eigenvalues.real))
        if np.linalg.cond(basis) < _CONDITION_LIMIT:
            return _State(flags, A, equilibrium, eigenvalues, basis, np.linalg.inv(basis), norm, abscissa, 0.0, slowest)
        import scipy.linalg  # here, not at module level: import lindstedt stays light
        schur = scipy.linalg.schur(A, output="complex")[0]
        nilpotent = float(np.linalg.norm(np.triu(schur, 1)))
        return _State(flags, A, equilibrium, None, None, None, norm, abscissa, nilpotent, slowest)

    def _particular(self, state: _State, frequency: float) -> tuple[np.ndarray, np.ndarray]:
        """Z1 = (iΩ − A)⁻¹ e and ∂Z1/∂Ω for the unit load scale."""
        if not np.any(self._load):
            zero = np.zeros(self.dimension, dtype=complex)
            return zero, zero
        scale = max(frequency, state.norm)
        if state.eigenvalues is not None:
            close = np.abs(state.eigenvalues - 1j * frequency) <= _BAND_FACTOR * _EPS * scale
        else:
            close = np.array([np.linalg.cond(1j * frequency * np.eye(self.dimension) - state.A) > 1 / (_BAND_FACTOR * _EPS)])
        if np.any(close):
            raise ResonanceError(
                f"exact resonance: iΩ (Ω = {frequency}) is an eigenvalue of the undamped contact state {state.flags}, "
                "so the forced response grows without bound; add damping or detune Ω"
            )
        matrix = 1j * frequency * np.eye(self.dimension) - state.A
        Z1 = np.linalg.solve(matrix, self._load.astype(complex))
        return Z1, -1j * np.linalg.solve(matrix, Z1)

    # ------------------------------------------------------------------ classification
    def _acceleration(self, flags: tuple[bool, ...], z: np.ndarray, t: float, frequency: float, scale: float) -> np.ndarray:
        n = self._n
        stiffness, force = self._stiffness_and_force(flags)
        load = force - stiffness @ z[:n] - self._C @ z[n:]
        return self._mass_inverse @ load + scale * self._load[n:] * math.cos(frequency * t)

    def _classify(
        self, z: np.ndarray, t: float, frequency: float, scale: float, previous: tuple[bool, ...] | None, magnitude: np.ndarray
    ) -> tuple[bool, ...]:
        """Contact flags from z: the sign of g beyond rounding; on a surface that of g', then of g'' on the side entered."""
        n = self._n
        m = len(self._b)
        abs_a = np.abs(self._a)
        gap = self._a @ z[:n] - self._b
        rate = self._a @ z[n:]
        tol_gap = _SURFACE_FACTOR * _EPS * (abs_a @ magnitude[:n] + np.abs(self._b))
        tol_rate = _SURFACE_FACTOR * _EPS * (abs_a @ magnitude[n:])
        flags = list(previous) if previous is not None else [False] * m
        for i in range(m):
            if abs(gap[i]) > tol_gap[i]:
                flags[i] = bool(gap[i] > 0)
            elif abs(rate[i]) > tol_rate[i]:
                flags[i] = bool(rate[i] > 0)
            else:
                on, off = list(flags), list(flags)
                on[i], off[i] = True, False
                stiffness, force = self._stiffness_and_force(tuple(on))
                forces = np.abs(stiffness) @ magnitude[:n] + np.abs(self._C) @ magnitude[n:] + np.abs(force)
                tol = _SURFACE_FACTOR * _EPS * (abs_a[i] @ (np.abs(self._mass_inverse) @ forces) + scale * abs_a[i] @ np.abs(self._load[n:]))
                if self._a[i] @ self._acceleration(tuple(on), z, t, frequency, scale) > tol:
                    flags[i] = True
                elif self._a[i] @ self._acceleration(tuple(off), z, t, frequency, scale) < -tol:
                    flags[i] = False
        return tuple(flags)

    def contact_state(self, state: Any, t: float = 0.0, frequency: float = 1.0, forcing_scale: float = 1.0) -> tuple[bool, ...]:
        """Flags of the surfaces (springs, or breakpoints of f) with ``g > 0`` for the state z at time t.

        Examples
        --------
        >>> flow = ForcedFlow(ForcedSystem.one_dof(1, zeta="1/10", b=1), epsilon=1.0)
        >>> flow.contact_state([1.0, 0.5]), flow.contact_state([1.0, -0.5]), flow.contact_state([2.0, 0.0])
        ((True,), (False,), (True,))
        """
        z = self._as_state(state)
        return self._classify(z, float(t), check_forcing_frequency(frequency, "frequency"), float(forcing_scale), None, np.abs(z))

    # ------------------------------------------------------------------ switch search
    def _next_event(
        self, state: _State, w0: np.ndarray, Zt: np.ndarray, frequency: float, tau_max: float, counters: _Counters
    ) -> tuple[float | None, int | None]:
        n = self._n
        signs = np.where(np.array(state.flags, dtype=bool), 1.0, -1.0)
        offsets = signs * (self._a @ state.equilibrium[:n] - self._b)
        abs_a = np.abs(self._a)
        if state.eigenvalues is not None:
            beta = state.inverse @ w0
            exponents = np.append(state.eigenvalues, 1j * frequency)
            terms = np.concatenate([(self._a @ state.basis[:n]) * beta, (self._a @ Zt[:n])[:, None]], axis=1) * signs[:, None]
            growth = np.exp(np.maximum(exponents.real, 0.0) * tau_max)
            moduli = np.abs(terms) * growth
            amplitude = moduli.sum(axis=1)
            g2 = moduli @ np.abs(exponents) ** 2
            g3 = moduli @ np.abs(exponents) ** 3
            magnitude = abs_a @ (np.abs(state.basis[:n]) @ np.abs(beta) + np.abs(Zt[:n]))
            fastest = float(np.max(np.abs(exponents)))
        else:
            bound = state.growth_bound(tau_max) * float(np.linalg.norm(w0))
            forced = np.abs(self._a @ Zt[:n])
            norms = np.linalg.norm(self._a, axis=1)
            amplitude = norms * bound + forced
            g2 = norms * bound * state.norm**2 + forced * frequency**2
            g3 = norms * bound * state.norm**3 + forced * frequency**3
            magnitude = abs_a @ (np.abs(w0[:n]) + np.abs(Zt[:n])) + norms * bound
            fastest = max(state.norm, frequency)
        bands = _BAND_FACTOR * _EPS * (abs_a @ np.abs(state.equilibrium[:n]) + np.abs(self._b) + magnitude)
        brackets: list[tuple[_Bracket, int]] = []
        horizon = tau_max
        for i in range(len(self._b)):
            if state.eigenvalues is not None:
                derivatives, value = _exponential_sum(float(offsets[i]), terms[i], exponents, counters)
            else:
                derivatives, value = self._expm_sum(state, float(offsets[i]), signs[i], w0, Zt, frequency, i, counters)
            band = max(float(bands[i]), -4.0 * derivatives(0.0)[0])
            bracket = _first_exit(
                float(offsets[i]), float(amplitude[i]), derivatives, value, float(g2[i]), float(g3[i]),
                0.1 / fastest, band, horizon,
            )
            if bracket is not None:
                brackets.append((bracket, i))
                horizon = min(horizon, bracket.high)  # a later root cannot be the first
        return _earliest_switch(brackets, counters)

    def _expm_sum(self, state: _State, offset: float, sign: float, w0: np.ndarray, Zt: np.ndarray, frequency: float,
                  i: int, counters: _Counters) -> tuple[Callable[[float], tuple[float, float, float]], Callable[[float], float]]:
        n = self._n
        a = sign * self._a[i]
        forced = complex(a @ Zt[:n])

        def derivatives(tau: float) -> tuple[float, float, float]:
            counters.evaluations += 1
            y = state.propagator(tau) @ w0
            y1 = state.A @ y
            y2 = state.A @ y1
            phase = forced * cmath.exp(1j * frequency * tau)
            return (offset + a @ y[:n] + phase.real, a @ y1[:n] + (1j * frequency * phase).real,
                    a @ y2[:n] - frequency**2 * phase.real)

        def value(tau: float) -> float:
            return derivatives(tau)[0]

        return derivatives, value

    # ------------------------------------------------------------------ the run
    def _as_state(self, state0: Any) -> np.ndarray:
        try:
            z = np.asarray(state0, dtype=float).reshape(-1)
        except (TypeError, ValueError):
            raise ProblemError(f"state0 must be a vector of {self.dimension} real numbers (X, X'), got {state0!r}") from None
        if z.shape != (self.dimension,) or not np.all(np.isfinite(z)):
            raise ProblemError(f"state0 must hold {self.dimension} finite numbers (positions then velocities), got {state0!r}")
        return z

    def _field(self, state: _State, z: np.ndarray, t: float, frequency: float, scale: float) -> np.ndarray:
        return state.A @ (z - state.equilibrium) + scale * self._load * math.cos(frequency * t)

    def _run(self, state0: Any, t_end: float, frequency: Any, scale: Any, *, dense: bool, sensitivity: bool) -> dict[str, Any]:
        frequency = check_forcing_frequency(frequency, "frequency")
        try:
            scale = float(scale)
        except (TypeError, ValueError):
            raise ParameterError(f"forcing_scale must be a real number such as 1.0, got {scale!r}") from None
        if not math.isfinite(scale):
            raise ParameterError(f"forcing_scale must be finite, got {scale!r}")
        z = self._as_state(state0)
        n, dim = self._n, self.dimension
        counters = _Counters()
        cost = {"decompositions": 0}
        t = 0.0
        flags = self._classify(z, t, frequency, scale, None, np.abs(z))
        particulars: dict[tuple[bool, ...], tuple[np.ndarray, np.ndarray]] = {}
        jacobian = np.eye(dim) if sensitivity else None
        d_frequency = np.zeros(dim)
        d_scale = np.zeros(dim)
        events: list[SwitchEvent] = []
        visited: dict[tuple[bool, ...], None] = {}
        arcs: list[tuple[float, _State, np.ndarray, np.ndarray]] = []
        success, message, n_arcs, instant = True, "", 0, 0
        state = self._state(flags, cost)
        while True:
            if n_arcs >= self.max_arcs:
                success, message = False, f"stopped at t = {t} after max_arcs = {self.max_arcs} arcs; raise max_arcs"
                break
            state = self._state(flags, cost)
            visited.setdefault(flags, None)
            if flags not in particulars:
                particulars[flags] = self._particular(state, frequency)
            Z1, dZ1 = particulars[flags]
            rotation = cmath.exp(1j * frequency * t)
            Zt = scale * Z1 * rotation
            w0 = z - state.equilibrium - Zt.real
            remaining = t_end - t
            chunk = state.chunk(frequency)
            last = remaining <= chunk
            tau_max = remaining if last else chunk
            try:
                tau_event, surface = self._next_event(state, w0, Zt, frequency, tau_max, counters)
            except _SearchFailure as failure:
                success, message = False, f"stopped at t = {t}: {failure}"
                break
            reaches_end = tau_event is None and last
            tau = remaining if reaches_end else (tau_max if tau_event is None else tau_event)
            n_arcs += 1
            if dense:
                arcs.append((t, state, w0, scale * Z1))
            t_next = t_end if reaches_end else t + tau
            propagator = state.propagator(tau)
            rotation_next = cmath.exp(1j * frequency * t_next)
            z_new = state.equilibrium + (scale * Z1 * rotation_next).real + propagator @ w0
            if jacobian is not None:
                jacobian = propagator @ jacobian
                q0 = (scale * (dZ1 + 1j * t * Z1) * rotation).real
                q1 = (scale * (dZ1 + 1j * t_next * Z1) * rotation_next).real
                d_frequency = propagator @ (d_frequency - q0) + q1
                d_scale = propagator @ (d_scale - (Z1 * rotation).real) + (Z1 * rotation_next).real
            z, t = z_new, t_next
            if reaches_end:
                break
            magnitude = np.abs(z) + np.abs(state.equilibrium) + np.abs(Zt) + (
                np.abs(state.basis) @ np.abs(state.inverse @ w0) if state.eigenvalues is not None else np.abs(w0)
            )
            new_flags = list(self._classify(z, t, frequency, scale, flags, magnitude))
            if surface is not None:
                new_flags[surface] = not flags[surface]
            instant = instant + 1 if (surface is not None and tau == 0.0) else 0
            if instant > _MAX_INSTANT_SWITCHES:
                success, message = False, (f"stopped at t = {t}: the motion is stuck on a switching surface (sliding); "
                                           "the exact flow does not follow sliding motions")
                break
            for i, (before, after) in enumerate(zip(flags, new_flags)):
                if before == after:
                    continue
                events.append(SwitchEvent(float(t), i, 1 if after else -1))
                if jacobian is not None and self._jumps[i] != 0.0:
                    # saltation I + (f⁺ − f⁻) nᵀ/(nᵀ f⁻), n = (a_i, 0), nᵀ f⁻ = a_i V
                    jump = np.zeros(dim)
                    # the oscillator's force ε f(u) jumps by ε J_i going up (acceleration: −ε J_i), −ε J_i going down
                    jump[n:] = self._mass_inverse @ np.ones(n) * (-self.epsilon * self._jumps[i] * (1 if after else -1))
                    crossing_rate = float(self._a[i] @ z[n:])
                    if abs(crossing_rate) <= _SURFACE_FACTOR * _EPS * max(1.0, float(np.max(np.abs(z[n:])))):
                        success, message = False, (f"stopped at t = {t}: a grazing crossing of the force jump of switch "
                                                   f"{i} (zero crossing speed): the sensitivity is unbounded there")
                        break
                    saltation = np.eye(dim) + np.outer(jump, np.concatenate([self._a[i], np.zeros(n)])) / crossing_rate
                    jacobian = saltation @ jacobian
                    d_frequency = saltation @ d_frequency
                    d_scale = saltation @ d_scale
            if not success:
                break
            flags = tuple(new_flags)
        if success:
            message = f"reached t_end = {t_end} with {len(events)} switches in {n_arcs} arcs"
        end_field = self._field(self._state(flags, cost), z, t, frequency, scale)
        return {
            "success": success, "message": message, "t": t, "z": z, "events": tuple(events), "arcs": arcs,
            "frequency": frequency, "field": end_field, "jacobian": jacobian, "d_frequency": d_frequency, "d_scale": d_scale,
            "counters": {"arcs": n_arcs, "switches": len(events), "decompositions": cost["decompositions"],
                         "root_solves": counters.root_solves, "evaluations": counters.evaluations},
            "visited": tuple(tuple(i for i, on in enumerate(s) if on) for s in visited),
        }

    def _evaluator(self, run: dict[str, Any]) -> Callable[[np.ndarray], np.ndarray]:
        arcs, frequency = run["arcs"], run["frequency"]
        starts = np.array([arc[0] for arc in arcs])
        final = run["z"].copy()

        def evaluate(times: np.ndarray) -> np.ndarray:
            out = np.empty((times.size, self.dimension))
            if not arcs:
                out[:] = final
                return out
            index = np.clip(np.searchsorted(starts, times, side="right") - 1, 0, len(arcs) - 1)
            for k in np.unique(index):
                selected = np.flatnonzero(index == k)
                t0, state, w0, Z = arcs[k]
                tt = times[selected]
                particular = (Z[None, :] * np.exp(1j * frequency * tt)[:, None]).real
                if state.eigenvalues is not None:
                    beta = state.inverse @ w0
                    homogeneous = ((np.exp(np.outer(tt - t0, state.eigenvalues)) * beta) @ state.basis.T).real
                else:
                    homogeneous = np.array([state.propagator(tau) @ w0 for tau in tt - t0])
                out[selected] = state.equilibrium + particular + homogeneous
            return out

        return evaluate

    # ------------------------------------------------------------------ public API
    def linear_frequencies(self) -> tuple[float, float] | None:
        """(lowest, highest) frequency of the linear pieces (ω² of each piece: M⁻¹(K + ε·slope)),
        computed once."""
        if not hasattr(self, "_bounds"):
            slopes = [slope for slope, _ in self._intervals] if self._intervals is not None else []
            self._bounds = linear_frequency_bounds(self.problem, self.epsilon, slopes)
        return self._bounds

    def period_map(
        self, state0: Any, frequency: float, *, periods: int = 1, forcing_scale: float = 1.0, sensitivity: bool = True
    ) -> PeriodMapValue:
        """``Π(z0; Ω, s) = z(2πk/Ω)`` and, when ``sensitivity``, ``∂Π/∂z0``, ``∂Π/∂Ω``, ``∂Π/∂s`` (analytic).

        Parameters
        ----------
        state0 : array_like, shape (2N,)
            ``z0 = (X0, V0)`` at t = 0 (the forcing is ``cos(Ω t)``).
        frequency : float
            Ω > 0.
        periods : int, optional
            k ≥ 1.
        forcing_scale : float, optional
            s.
        sensitivity : bool, optional

        Returns
        -------
        PeriodMapValue
            Counters ``arcs``, ``switches``, ``decompositions``, ``root_solves``, ``evaluations``.

        Raises
        ------
        ConvergenceError
            When the run stops early (max_arcs, a sliding motion).

        Examples
        --------
        >>> flow = ForcedFlow(ForcedSystem.one_dof(1, zeta="1/10", forcing=1, b=10), epsilon=1.0)
        >>> out = flow.period_map([0.0, 0.0], 2.0)
        >>> out.counters["switches"], bool(np.all(np.isfinite(out.d_frequency)))
        (0, True)
        """
        periods = _as_periods(periods)
        omega = check_forcing_frequency(frequency, "frequency")
        t_end = 2.0 * math.pi * periods / omega
        run = self._run(state0, t_end, omega, forcing_scale, dense=False, sensitivity=sensitivity)
        if not run["success"]:
            raise ConvergenceError(f"the period map did not reach t = {t_end}: {run['message']}")
        if not sensitivity:
            return PeriodMapValue(state=run["z"], counters=run["counters"])
        d_frequency = run["d_frequency"] - run["field"] * (t_end / omega)
        return PeriodMapValue(run["z"], run["jacobian"], d_frequency, run["d_scale"], run["counters"])

    def sample(
        self, state0: Any, frequency: float, *, periods: int = 1, forcing_scale: float = 1.0, samples: int = 256
    ) -> tuple[np.ndarray, np.ndarray]:
        """``(t, z(t))`` at ``samples`` equally spaced times of ``[0, kT)``, z of shape (samples, 2N).

        Examples
        --------
        >>> flow = ForcedFlow(ForcedSystem.one_dof(1, zeta="1/10", b=10), epsilon=1.0)
        >>> t, z = flow.sample([0.0, 0.0], 2.0, samples=8)
        >>> t.shape, z.shape, bool(np.allclose(z[0], [0.0, 0.0], rtol=0, atol=1e-15))
        ((8,), (8, 2), True)
        """
        periods = _as_periods(periods)
        omega = check_forcing_frequency(frequency, "frequency")
        if isinstance(samples, bool) or int(samples) != samples or samples < 1:
            raise ParameterError(f"samples must be a positive integer, got {samples!r}")
        t_end = 2.0 * math.pi * periods / omega
        run = self._run(state0, t_end, omega, forcing_scale, dense=True, sensitivity=False)
        if not run["success"]:
            raise ConvergenceError(f"the flow did not reach t = {t_end}: {run['message']}")
        times = np.arange(int(samples)) * (t_end / int(samples))
        return times, self._evaluator(run)(times)

    def solve(self, state0: Any, t_end: float, frequency: float, forcing_scale: float = 1.0) -> FlowResult:
        """Flow from ``z(0) = state0`` to ``t_end`` (e.g. to a steady state) with dense closed-form output.

        Returns
        -------
        FlowResult
            ``method="exact-forced"``; ``result.state(t)`` gives ``(X, V)``; the counters are those of
            :class:`~lindstedt.numerics.ExactFlow` (``n_decompositions``: state decompositions);
            ``result.system`` is the forced problem, exported by ``result.to_json()``.

        Examples
        --------
        >>> flow = ForcedFlow(ForcedSystem.one_dof(1, zeta="1/20", b="1/10"), epsilon=2.0)
        >>> result = flow.solve([0.0, 0.0], 30.0, frequency=1.3)
        >>> result.success, result.n_switches > 0, result.state(30.0)[0].shape
        (True, True, (1,))
        """
        try:
            t_end = float(t_end)
        except (TypeError, ValueError):
            raise ProblemError(f"t_end must be a real number, got {t_end!r}") from None
        if not math.isfinite(t_end) or t_end < 0.0:
            raise ProblemError(f"t_end must be finite and ≥ 0, got {t_end}")
        run = self._run(state0, t_end, frequency, forcing_scale, dense=True, sensitivity=False)
        evaluate = self._evaluator(run)
        n = self._n

        def evaluator(times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            z = evaluate(times)
            return z[:, :n], z[:, n:]

        counters = run["counters"]
        return FlowResult(
            success=run["success"], message=run["message"], method="exact-forced", t_final=run["t"],
            position=run["z"][:n].copy(), velocity=run["z"][n:].copy(), events=run["events"],
            n_switches=counters["switches"], n_root_solves=counters["root_solves"], n_arcs=counters["arcs"],
            n_evaluations=counters["evaluations"], n_decompositions=counters["decompositions"],
            contact_states=run["visited"], _evaluator=evaluator, system=self.problem, epsilon=self.epsilon,
        )


def _as_periods(periods: Any) -> int:
    if isinstance(periods, bool) or not isinstance(periods, (int, np.integer)) or periods < 1:
        raise ParameterError(f"periods must be a positive integer (the number k of forcing periods), got {periods!r}")
    return int(periods)


def _exponential_sum(
    offset: float, coefficients: np.ndarray, exponents: np.ndarray, counters: _Counters
) -> tuple[Callable[[float], tuple[float, float, float]], Callable[[float], float]]:
    """Evaluators of h = offset + Re Σ c_k e^{λ_k τ}: (h, h', h'') and h alone."""
    terms = list(zip(coefficients.tolist(), exponents.tolist()))

    def derivatives(tau: float) -> tuple[float, float, float]:
        counters.evaluations += 1
        h, h1, h2 = 0j, 0j, 0j
        for c, lam in terms:
            term = c * cmath.exp(lam * tau)
            h += term
            h1 += lam * term
            h2 += lam * lam * term
        return offset + h.real, h1.real, h2.real

    def value(tau: float) -> float:
        counters.evaluations += 1
        return offset + sum(c * cmath.exp(lam * tau) for c, lam in terms).real

    return derivatives, value
