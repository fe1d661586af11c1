"""Exact flow of  M X'' + K X + ε W (A X − b)_+ = 0  (the numerical ground truth).

For fixed ε and a fixed *contact state* S (the springs with ``A_i X − b_i > 0``)
the system is linear with a constant load,

    M X'' + (K + ε W_S A_S) X = ε W_S b_S,

so between two switches the motion is a closed-form sum of harmonics about the
equilibrium ``X*_S`` of the state:

    X(t) = X*_S + P_S (q0 cos(ω t) + (p0/ω) sin(ω t)),    q0 = Q_S (X0 − X*_S),  p0 = Q_S V0,

where ``ω²`` and the columns of ``P_S`` are the eigenvalues and eigenvectors of
``M⁻¹(K + ε W_S A_S)`` and ``Q_S = P_S⁻¹``.  With ``W = Aᵀ`` the symmetric
generalised problem ``(K + ε A_Sᵀ A_S) P = M P ω²`` is solved (``scipy.linalg.eigh``,
``Q_S = P_Sᵀ M``); otherwise a real eigen-decomposition is required to exist
with positive eigenvalues.  The decomposition of every visited state is cached.

Switches.  Inside an arc each gap function ``g_i(t) = A_i X(t) − b_i`` is the
trigonometric sum ``c_i + Σ_k α_ik cos ω_k t + β_ik sin ω_k t``, with the
derivative bounds ``|g''| ≤ G2 = Σ ω_k² R_ik`` and ``|g'''| ≤ G3 = Σ ω_k³ R_ik``
(``R_ik = hypot(α_ik, β_ik)``).  For the spring's watch function
``h = ±g`` (positive on the current side) the search advances only by steps
proven root-free by a Taylor minorant:

* ``h(t + s) ≥ F + h'(t) s − G2 s²/2`` with ``F = h(t) + δ``;
* ``h(t + s) ≥ F + h'(t) s + h''(t) s²/2 − G3 s³/6`` (used near tangencies);
* while ``h' < 0``, ``h`` is strictly decreasing on ``[t, t + |h'|/G2]``, so a
  sign change there is a unique root.

Hence no excursion of ``g`` to the other side deeper than the band ``δ``
(64 machine epsilons of the magnitude of the terms of ``g``, i.e. the level of
rounding in evaluating ``g``) can be stepped over, however short: a double
crossing inside a step is impossible.  Excursions shallower than ``δ`` are
indistinguishable from rounding and are treated as grazing contacts (no
switch); since the spring force is ``ε (g)_+``, skipping them changes the
force by at most ``ε δ``.  Roots are then located by Brent's method on the
closed form (relative accuracy 4 machine epsilons).  A tangency
``g = g' = 0`` is not a switch.  At ``t = 0`` and after every switch, a spring
sitting on its switching surface (``|g| ≤`` rounding) is put in the state it is
moving into, decided by the sign of ``g'``, then ``g''`` (both are the same in
either state because the force ``(·)_+`` is continuous).  The search of an arc
that starts on a spring's surface (``|h(0)| ≤ δ``) looks for the next switch
strictly after the start: ``τ = 0`` is the switch just made, never a bracket
end.  It resumes at the first instant a minorant certifies to be clearly on
the new side (``h > δ`` there, ``h > −δ`` before): ``h'(0)/G2`` when moving in
(``h'(0) > 0``), ``2 h''(0)/G3`` for a grazing entry (``h'' > 0``).  (Otherwise
the first step may cross a whole shallow excursion, from ``τ = 0`` to beyond its
exit, and the root solve of the bracket ``[0, step]`` returns the start again:
the flow would switch in and out at one instant.)  If neither certifies, the
motion onto the new side is itself at rounding level (a graze): ``τ = 0`` is
then a bracket end only if ``h`` is already leaving (``h(0) ≥ 0 > h'(0)``).

Precision.  The modal decompositions (for ``W = Aᵀ``: refined by an
Ogita–Aishima iteration), the equilibria, the state carried from arc to arc
and the dense output are computed in extended precision (``numpy.longdouble``,
80-bit on x86-64), so the per-switch rounding stays far below double precision:
over thousands of switches the energy drifts by no more than the rounding of
its own evaluation.  Where ``longdouble`` is plain double the same code runs
with a drift of about one ulp per switch.

Sensitivity.  The vector field is continuous across every switching surface,
so the saltation matrices are the identity and the sensitivity
``∂(X(t), X'(t))/∂(X0, V0)`` is the product of the state transition matrices
of the arcs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, Sequence

import numpy as np

from .._errors import ConvergenceError, ProblemError
from ._period_map import PeriodMapValue
from ..problems.system import UnilateralSystem
from .flow_results import FlowMapResult, FlowResult, SwitchEvent
from .switching import _Bracket, _Counters, _earliest_switch, _first_exit_trig, _SearchFailure

__all__ = ["ExactFlow", "FlowResult", "FlowMapResult", "SwitchEvent"]

_EPS = float(np.finfo(float).eps)
#: half-width of the band of rounding-level excursions, in eps × magnitude of g
_BAND_FACTOR = 64.0
#: |g| below this many eps × magnitude counts as "on the switching surface"
_SURFACE_FACTOR = 16.0
#: an arc longer than this many periods of its slowest mode is restarted (keeps ω t small)
_CHUNK_PERIODS = 4.0
#: extended precision carrying the state between arcs (80-bit on x86-64; double elsewhere)
_LONG = np.longdouble
#: eigenvalues closer than this (relative) are treated as one cluster by the refinement
_CLUSTER_RTOL = 1e-9


def _duhamel_kernels(omega_k: np.ndarray, omega_m: np.ndarray, tau: float) -> tuple[np.ndarray, ...]:
    """Responses ζ(τ), ζ'(τ) of ζ'' + ω_k² ζ = cos(ω_m s) or sin(ω_m s), ζ(0) = ζ'(0) = 0.

    Written with σ = (ω_k + ω_m)/2, δ = ω_m − ω_k and sinc so that they stay
    accurate for ω_m → ω_k (resonance: the τ sin, τ cos terms).
    """
    sigma = 0.5 * (omega_k + omega_m)
    delta = omega_m - omega_k
    sinc = np.sinc(delta * tau / (2.0 * math.pi))  # sin(δτ/2)/(δτ/2)
    sin_sigma, cos_sigma = np.sin(sigma * tau), np.cos(sigma * tau)
    sin_k = np.sin(omega_k * tau)
    cos_response = tau * sin_sigma * sinc / (2.0 * sigma)
    cos_rate = (omega_m * tau * cos_sigma * sinc + sin_k) / (2.0 * sigma)
    sin_response = (sin_k / omega_k - tau * cos_sigma * sinc) / (2.0 * sigma)
    sin_rate = omega_m * tau * sin_sigma * sinc / (2.0 * sigma)
    return cos_response, cos_rate, sin_response, sin_rate



# --------------------------------------------------------------------------- #
# contact states
# --------------------------------------------------------------------------- #
@dataclass(frozen=True)
class _ContactMode:
    """Modal decomposition of one contact state (Y = X − X*,  q = Q Y,  Y = P q).

    The ``*_l`` arrays are in extended precision (``numpy.longdouble``); they
    carry the state between arcs.  The double copies feed the switch search
    and the sensitivities.
    """

    active: tuple[bool, ...]
    omega: np.ndarray
    omega_l: np.ndarray
    basis: np.ndarray
    basis_l: np.ndarray
    projector: np.ndarray
    projector_l: np.ndarray
    equilibrium_l: np.ndarray
    gap_basis: np.ndarray  # A P
    gap_basis_abs: np.ndarray  # |A| |P|
    gap_offset: np.ndarray  # A X* − b
    gap_offset_scale: np.ndarray  # |A| |X*| + |b|
    chunk_length: float

    def project(self, x_l: np.ndarray, v_l: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Modal coordinates (q0, p0) of the state (x, v), extended precision."""
        return self.projector_l @ (x_l - self.equilibrium_l), self.projector_l @ v_l

    def evaluate(self, q0_l: np.ndarray, p0_l: np.ndarray, tau_l: Any) -> tuple[np.ndarray, np.ndarray]:
        """Positions and velocities (extended precision) at local times tau (rows broadcast)."""
        tau_l = np.asarray(tau_l, dtype=_LONG)
        phase = tau_l[..., None] * self.omega_l
        cos, sin = np.cos(phase), np.sin(phase)
        modal_position = q0_l * cos + (p0_l / self.omega_l) * sin
        modal_velocity = p0_l * cos - (q0_l * self.omega_l) * sin
        return self.equilibrium_l + modal_position @ self.basis_l.T, modal_velocity @ self.basis_l.T

    def transition(self, tau: float) -> np.ndarray:
        """State transition matrix ∂(X, V)(tau) / ∂(X, V)(0) of this linear state."""
        cos, sin = np.cos(self.omega * tau), np.sin(self.omega * tau)
        P, Q = self.basis, self.projector
        return np.block(
            [
                [(P * cos) @ Q, (P * (sin / self.omega)) @ Q],
                [(P * (-self.omega * sin)) @ Q, (P * cos) @ Q],
            ]
        )


def _clusters(values: np.ndarray, rtol: float) -> list[np.ndarray]:
    """Groups (of size ≥ 2) of indices whose values agree to rtol × max|values|."""
    order = np.argsort(values.astype(float))
    threshold = rtol * float(np.max(np.abs(values)))
    groups, current = [], [int(order[0])]
    for previous, index in zip(order[:-1], order[1:]):
        if abs(float(values[index] - values[previous])) <= threshold:
            current.append(int(index))
        else:
            groups.append(current)
            current = [int(index)]
    groups.append(current)
    return [np.array(group) for group in groups if len(group) > 1]


def _refine_symmetric(stiffness_l: np.ndarray, mass_l: np.ndarray, basis: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """Refine K X = M X Λ, Xᵀ M X = I to extended precision (Ogita–Aishima iteration).

    Starting from the double-precision eigenvectors, each step solves the
    first-order equations  E + Eᵀ = R,  S + Eᵀ Λ + Λ E = diag  with
    R = I − Xᵀ M X and S = Xᵀ K X, then X ← X (I + E); convergence is
    quadratic.  Within a cluster of (numerically) equal eigenvalues only the
    M-orthonormality is corrected and the cluster is then diagonalised by an
    orthogonal rotation.  Returns None when the refinement does not converge.
    """
    n = basis.shape[0]
    identity = np.eye(n, dtype=_LONG)
    X = basis.astype(_LONG)

    def step(X: np.ndarray) -> np.ndarray:
        residual = identity - X.T @ mass_l @ X
        rayleigh = X.T @ stiffness_l @ X
        values = np.diag(rayleigh) / (1 - np.diag(residual))
        difference = values[None, :] - values[:, None]
        separated = np.abs(difference) > _CLUSTER_RTOL * np.max(np.abs(values))
        correction = np.where(
            separated, (rayleigh + values[None, :] * residual) / np.where(separated, difference, 1), residual / 2
        )
        np.fill_diagonal(correction, np.diag(residual) / 2)
        return X + X @ correction

    for _ in range(3):
        X = step(X)
    rayleigh = X.T @ stiffness_l @ X
    for group in _clusters(np.diag(rayleigh), _CLUSTER_RTOL):
        block = rayleigh[np.ix_(group, group)]
        block = block - np.mean(np.diag(block)) * np.eye(len(group), dtype=_LONG)
        scale = float(np.max(np.abs(block))) or 1.0
        import scipy.linalg  # here, not at module level: import lindstedt stays light
        rotation = scipy.linalg.eigh((block / scale).astype(float))[1].astype(_LONG)
        for _ in range(2):
            rotation = rotation + rotation @ ((np.eye(len(group), dtype=_LONG) - rotation.T @ rotation) / 2)
        X[:, group] = X[:, group] @ rotation
    X = step(X)
    rayleigh = X.T @ stiffness_l @ X
    residual = identity - X.T @ mass_l @ X
    off_diagonal = rayleigh - np.diag(np.diag(rayleigh))
    if not (
        np.all(np.isfinite(X.astype(float)))
        and float(np.max(np.abs(residual))) < 1e-15
        and float(np.max(np.abs(off_diagonal))) < 1e-15 * float(np.max(np.abs(np.diag(rayleigh))))
    ):
        return None
    return np.diag(rayleigh) / np.diag(identity - residual), X


# --------------------------------------------------------------------------- #
# the exact flow
# --------------------------------------------------------------------------- #
def _as_state_vector(value: Any, n: int, name: str) -> np.ndarray:
    try:
        array = np.asarray(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise ProblemError(f"{name} must be a vector of {n} real numbers, got {value!r}") from None
    if array.shape != (n,):
        raise ProblemError(f"{name} must have {n} entries (one per degree of freedom), got {array.size}")
    if not np.all(np.isfinite(array)):
        raise ProblemError(f"{name} must be finite, got {array}")
    return array


def _as_time(value: Any, name: str) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ProblemError(f"{name} must be a real number, got {value!r}") from None
    if not math.isfinite(number) or number < 0.0:
        raise ProblemError(
            f"{name} must be finite and non-negative, got {number}; for backward time use the "
            "reversibility X(−t; x0, v0) = X(t; x0, −v0)"
        )
    return number


class ExactFlow:
    """Exact (closed-form, piecewise) flow of ``M X'' + K X + ε W (A X − b)_+ = 0``.

    Parameters
    ----------
    system : UnilateralSystem
        The problem.
    epsilon : float
        The small parameter ε (any finite real number for which every visited
        contact state has positive squared frequencies).
    max_arcs : int, optional
        Safety cap on the number of arcs of one run.

    Examples
    --------
    >>> import numpy as np
    >>> flow = ExactFlow(UnilateralSystem.one_dof(1), epsilon=3.0)
    >>> result = flow.solve([1.0], [0.0], t_end=10.0)
    >>> result.success, result.n_switches
    (True, 4)
    >>> period = np.pi / 2 + np.pi  # half a period in contact (ω = 2), half free (ω = 1)
    >>> float(abs(result.state(period)[0][0] - 1.0)) < 1e-14
    True
    """

    def __init__(self, system: UnilateralSystem, epsilon: float, *, max_arcs: int = 1_000_000) -> None:
        if not isinstance(system, UnilateralSystem):
            raise ProblemError(f"ExactFlow needs a UnilateralSystem, got {type(system).__name__}")
        system.require_unilateral("the exact flow (ExactFlow)")
        try:
            eps_value = float(epsilon)
        except (TypeError, ValueError):
            raise ProblemError(f"epsilon must be a real number, got {epsilon!r}") from None
        if not math.isfinite(eps_value):
            raise ProblemError(f"epsilon must be finite, got {eps_value}")
        self.system = system
        self.epsilon = eps_value
        self.max_arcs = int(max_arcs)
        self._modes: dict[tuple[bool, ...], _ContactMode] = {}
        mass_inverse = np.linalg.inv(system.M)
        self._mass_inverse_abs = np.abs(mass_inverse)
        self._A_mass_inverse = system.A @ mass_inverse
        self._abs_A = np.abs(system.A)
        self._abs_W = np.abs(system.W)
        # |K| + |ε| |W| |A|: bounds the magnitude of every force term
        self._abs_stiffness_all = np.abs(system.K) + abs(eps_value) * self._abs_W @ self._abs_A

    # ------------------------------------------------------------ contact states
    def _decompose(self, active: tuple[bool, ...]) -> _ContactMode:
        system, eps = self.system, self.epsilon
        mask = np.array(active, dtype=bool)
        A_S, W_S, b_S = system.A[mask], system.W[:, mask], system.b[mask]
        stiffness = system.K + eps * W_S @ A_S
        engaged = tuple(int(i) for i in np.flatnonzero(mask))
        # the same matrices in extended precision (the float system, computed more accurately)
        stiffness_l = system.K.astype(_LONG) + _LONG(eps) * (W_S.astype(_LONG) @ A_S.astype(_LONG))
        load_l = _LONG(eps) * (W_S.astype(_LONG) @ b_S.astype(_LONG))
        mass_l = system.M.astype(_LONG)
        try:
            equilibrium_l = np.linalg.solve(stiffness, load_l.astype(float)).astype(_LONG)
        except np.linalg.LinAlgError:
            raise ProblemError(
                f"the stiffness K + ε W_S A_S of contact state {engaged} is singular at ε = {eps}; reduce |ε|"
            ) from None
        for _ in range(2):  # iterative refinement of X* in extended precision
            correction = np.linalg.solve(stiffness, (load_l - stiffness_l @ equilibrium_l).astype(float))
            equilibrium_l = equilibrium_l + correction.astype(_LONG)
        n = system.n_dof
        if n == 1:
            squared_l = np.array([stiffness_l[0, 0] / mass_l[0, 0]])
            basis_l = np.ones((1, 1), dtype=_LONG)
            projector_l = np.ones((1, 1), dtype=_LONG)
        elif system.symmetric_coupling:
            stiffness = 0.5 * (stiffness + stiffness.T)
            import scipy.linalg  # here, not at module level: import lindstedt stays light
            squared, basis = scipy.linalg.eigh(stiffness, system.M)
            refined = _refine_symmetric(stiffness_l, mass_l, basis) if np.min(squared) > 0 else None
            if refined is None:
                squared_l, basis_l = squared.astype(_LONG), basis.astype(_LONG)
            else:
                squared_l, basis_l = refined
            projector_l = basis_l.T @ mass_l
        else:
            squared, basis = np.linalg.eig(np.linalg.solve(system.M, stiffness))
            if np.iscomplexobj(squared):
                if np.max(np.abs(squared.imag)) > 1e-10 * np.max(np.abs(squared)):
                    raise ProblemError(
                        f"M⁻¹(K + ε W_S A_S) of contact state {engaged} has complex eigenvalues at ε = {eps}, "
                        "so the state is not a vibration; use W = Aᵀ or a smaller |ε|"
                    )
                leading = basis[np.argmax(np.abs(basis), axis=0), np.arange(basis.shape[1])]
                basis = (basis * (np.conj(leading) / np.abs(leading))).real
                squared = squared.real
            if np.linalg.cond(basis) > 1e10:
                raise ProblemError(
                    f"M⁻¹(K + ε W_S A_S) of contact state {engaged} is not (numerically) diagonalisable "
                    f"at ε = {eps}; use W = Aᵀ or perturb W"
                )
            squared_l, basis_l = squared.astype(_LONG), basis.astype(_LONG)
            projector_l = np.linalg.inv(basis).astype(_LONG)
        if float(np.min(squared_l)) <= 0.0:
            raise ProblemError(
                f"contact state {engaged} has a non-positive squared frequency ({float(np.min(squared_l)):.3g}) "
                f"at ε = {eps}; the closed form needs K + ε W_S A_S to be stable — reduce |ε| or use ε ≥ 0 with W = Aᵀ"
            )
        omega_l = np.sqrt(squared_l)
        omega = omega_l.astype(float)
        basis = basis_l.astype(float)
        equilibrium = equilibrium_l.astype(float)
        gap_offset = (system.A.astype(_LONG) @ equilibrium_l - system.b.astype(_LONG)).astype(float)
        return _ContactMode(
            active=active,
            omega=omega,
            omega_l=omega_l,
            basis=basis,
            basis_l=basis_l,
            projector=projector_l.astype(float),
            projector_l=projector_l,
            equilibrium_l=equilibrium_l,
            gap_basis=system.A @ basis,
            gap_basis_abs=self._abs_A @ np.abs(basis),
            gap_offset=gap_offset,
            gap_offset_scale=self._abs_A @ np.abs(equilibrium) + np.abs(system.b),
            chunk_length=_CHUNK_PERIODS * 2.0 * math.pi / float(omega.min()),
        )

    def _mode(self, active: tuple[bool, ...], counters: dict[str, int]) -> _ContactMode:
        mode = self._modes.get(active)
        if mode is None:
            mode = self._modes[active] = self._decompose(active)
            counters["decompositions"] += 1
        return mode

    def contact_state(self, x: Any, v: Any, previous: Sequence[bool] | None = None) -> tuple[bool, ...]:
        """Contact state (engaged flag per spring) to use from the state (x, v).

        A spring with ``g = A_i x − b_i`` beyond rounding is engaged iff
        ``g > 0``.  On the switching surface (``|g|`` at rounding level) it is
        engaged iff it is moving into contact: ``g' > 0``, or ``g' ≈ 0`` and
        ``g'' > 0``; if ``g'`` and ``g''`` also vanish, ``previous`` (or
        disengaged) is kept.

        Examples
        --------
        >>> flow = ExactFlow(UnilateralSystem.one_dof(1, b=1), epsilon=1.0)
        >>> flow.contact_state([1.0], [0.5]), flow.contact_state([1.0], [-0.5]), flow.contact_state([1.0], [0.0])
        ((True,), (False,), (False,))
        """
        system = self.system
        n = system.n_dof
        x = _as_state_vector(x, n, "x")
        v = _as_state_vector(v, n, "v")
        if previous is not None and len(previous) != system.n_springs:
            raise ProblemError(f"previous must hold one flag per spring ({system.n_springs}), got {len(previous)}")
        return self._classify(x, v, previous, np.abs(x), np.abs(v))

    def _classify(
        self,
        x: np.ndarray,
        v: np.ndarray,
        previous: Sequence[bool] | None,
        position_scale: np.ndarray,
        velocity_scale: np.ndarray,
    ) -> tuple[bool, ...]:
        """Contact state from (x, v) whose rounding is relative to the given magnitudes."""
        system = self.system
        gap = system.A @ x - system.b
        rate = system.A @ v
        force = system.K @ x + self.epsilon * (system.W @ np.maximum(gap, 0.0))
        curvature = -(self._A_mass_inverse @ force)
        abs_A = self._abs_A
        tol_gap = _SURFACE_FACTOR * _EPS * (abs_A @ position_scale + np.abs(system.b))
        tol_rate = _SURFACE_FACTOR * _EPS * (abs_A @ velocity_scale)
        forces = self._abs_stiffness_all @ position_scale + abs(self.epsilon) * self._abs_W @ np.abs(system.b)
        tol_curvature = _SURFACE_FACTOR * _EPS * (abs_A @ (self._mass_inverse_abs @ forces))
        kept = np.zeros(len(gap), dtype=bool) if previous is None else np.array(previous, dtype=bool)
        # the sign of g beyond rounding; on the surface that of g', then of g''; else the previous state
        state = np.where(
            np.abs(gap) > tol_gap,
            gap > 0,
            np.where(np.abs(rate) > tol_rate, rate > 0, np.where(np.abs(curvature) > tol_curvature, curvature > 0, kept)),
        )
        return tuple(bool(on) for on in state)

    def _next_event(
        self, mode: _ContactMode, q0: np.ndarray, p0: np.ndarray, tau_max: float, counters: _Counters
    ) -> tuple[float | None, int | None]:
        sign = np.where(np.array(mode.active, dtype=bool), 1.0, -1.0)
        cos_coefficients = mode.gap_basis * q0 * sign[:, None]
        sin_coefficients = mode.gap_basis * (p0 / mode.omega) * sign[:, None]
        offsets = mode.gap_offset * sign
        amplitudes = np.hypot(q0, p0 / mode.omega)
        bands = _BAND_FACTOR * _EPS * (mode.gap_offset_scale + mode.gap_basis_abs @ amplitudes)
        # a spring put on this side within rounding of its surface must start inside the band
        bands = np.maximum(bands, -4.0 * (offsets + cos_coefficients.sum(axis=1)))
        brackets: list[tuple[_Bracket, int]] = []
        horizon = tau_max
        for i in range(len(mode.active)):
            bracket = _first_exit_trig(
                float(offsets[i]), cos_coefficients[i], sin_coefficients[i], mode.omega, float(bands[i]), horizon, counters
            )
            if bracket is not None:
                brackets.append((bracket, i))
                horizon = min(horizon, bracket.high)  # a later root cannot be the first
        return _earliest_switch(brackets, counters)

    def _run(self, x0: Any, v0: Any, t_end: Any, *, dense: bool, sensitivity: bool) -> dict[str, Any]:
        system = self.system
        n = system.n_dof
        x = _as_state_vector(x0, n, "x0")
        v = _as_state_vector(v0, n, "v0")
        t_end = _as_time(t_end, "t_end")
        counters = _Counters()
        cost = {"decompositions": 0}
        active = self.contact_state(x, v)
        # state and time are carried in extended precision from arc to arc
        x_l, v_l = x.astype(_LONG), v.astype(_LONG)
        t_l = _LONG(0.0)
        t_end_l = _LONG(t_end)
        events: list[SwitchEvent] = []
        visited: dict[tuple[bool, ...], None] = {}
        arc_starts: list[Any] = []
        arc_modes: list[_ContactMode] = []
        arc_q0: list[np.ndarray] = []
        arc_p0: list[np.ndarray] = []
        jacobian = np.eye(2 * n) if sensitivity else None
        success, message = True, ""
        n_arcs = 0
        while True:
            if n_arcs >= self.max_arcs:
                success = False
                message = f"stopped at t = {float(t_l)} after max_arcs = {self.max_arcs} arcs; raise max_arcs"
                break
            mode = self._mode(active, cost)
            visited.setdefault(active, None)
            q0_l, p0_l = mode.project(x_l, v_l)
            remaining = float(t_end_l - t_l)
            last_chunk = remaining <= mode.chunk_length
            tau_max = remaining if last_chunk else mode.chunk_length
            try:
                tau_event, spring = self._next_event(mode, q0_l.astype(float), p0_l.astype(float), tau_max, counters)
            except _SearchFailure as failure:
                success, message = False, f"stopped at t = {float(t_l)}: {failure}"
                break
            reaches_end = tau_event is None and last_chunk
            tau_l = t_end_l - t_l if reaches_end else _LONG(tau_max if tau_event is None else tau_event)
            n_arcs += 1
            if dense:
                arc_starts.append(t_l)
                arc_modes.append(mode)
                arc_q0.append(q0_l)
                arc_p0.append(p0_l)
            x_l, v_l = mode.evaluate(q0_l, p0_l, tau_l)
            if jacobian is not None:
                jacobian = mode.transition(float(tau_l)) @ jacobian
            t_l = t_l + tau_l
            if reaches_end:
                t_l = t_end_l
                break
            # rounding of the evaluated state is relative to the arc's magnitudes, not to (x, v)
            amplitudes = np.hypot(q0_l.astype(float), p0_l.astype(float) / mode.omega)
            position_scale = np.abs(mode.equilibrium_l.astype(float)) + np.abs(mode.basis) @ amplitudes
            velocity_scale = np.abs(mode.basis) @ (mode.omega * amplitudes)
            new_active = list(
                self._classify(x_l.astype(float), v_l.astype(float), active, position_scale, velocity_scale)
            )
            if spring is not None:
                new_active[spring] = not active[spring]
            for i, (before, after) in enumerate(zip(active, new_active)):
                if before != after:
                    events.append(SwitchEvent(float(t_l), i, 1 if after else -1))
            active = tuple(new_active)
            if t_l >= t_end_l:
                t_l = t_end_l
                break
        if success:
            message = f"reached t_end = {t_end} with {len(events)} switches in {n_arcs} arcs"
        return {
            "success": success,
            "message": message,
            "t": float(t_l),
            "x": x_l.astype(float),
            "v": v_l.astype(float),
            "events": tuple(events),
            # the cost counters shared by FlowResult and FlowMapResult
            "cost": {
                "n_switches": len(events),
                "n_root_solves": counters.root_solves,
                "n_arcs": n_arcs,
                "n_evaluations": counters.evaluations,
            },
            "decompositions": cost["decompositions"],
            "visited": tuple(tuple(i for i, on in enumerate(state) if on) for state in visited),
            "arcs": (arc_starts, arc_modes, arc_q0, arc_p0),
            "jacobian": jacobian,
        }

    def _epsilon_derivative(self, run: dict[str, Any]) -> np.ndarray:
        """``∂(X, X')(t)/∂ε`` of a dense run, in closed form.

        It solves ``z' = J(t) z + (0, −M⁻¹ W (A X − b)_+)``, ``z(0) = 0``; the saltation matrices are the
        identity because the vector field and its ε-derivative are continuous across the switching surfaces.
        On each arc, in the modal coordinates (P, Q = P⁻¹, ω) of its contact state, the forcing is a constant
        plus harmonics of the arc's own frequencies, and the Duhamel integral is summed in closed form
        (:func:`_duhamel_kernels`).
        """
        system = self.system
        n = system.n_dof
        starts, modes, q0s, p0s = run["arcs"]
        ends = [float(s) for s in starts[1:]] + [float(run["t"])]
        mass_inverse_w = np.linalg.solve(system.M, system.W) if system.n_springs else np.zeros((n, 0))
        z = np.zeros(2 * n)
        for start, end, mode, q0_l, p0_l in zip(starts, ends, modes, q0s, p0s):
            tau = end - float(start)
            mask = np.array(mode.active, dtype=bool)
            P, Q, omega = mode.basis, mode.projector, mode.omega
            z = mode.transition(tau) @ z
            if not mask.any():
                continue
            q0, p0 = q0_l.astype(float), p0_l.astype(float)
            equilibrium = mode.equilibrium_l.astype(float)
            load = mass_inverse_w[:, mask]
            constant = -Q @ (load @ (system.A[mask] @ equilibrium - system.b[mask]))
            coupling = -Q @ load @ (system.A[mask] @ P)  # (n, n): harmonic m forces modal k
            cos_response, cos_rate, sin_response, sin_rate = _duhamel_kernels(omega[:, None], omega[None, :], tau)
            cos_amplitude = coupling * q0[None, :]
            sin_amplitude = coupling * (p0 / omega)[None, :]
            zeta = constant * (1.0 - np.cos(omega * tau)) / omega**2 + np.sum(
                cos_amplitude * cos_response + sin_amplitude * sin_response, axis=1
            )
            eta = constant * np.sin(omega * tau) / omega + np.sum(cos_amplitude * cos_rate + sin_amplitude * sin_rate, axis=1)
            z = z + np.concatenate([P @ zeta, P @ eta])
        return z

    # --------------------------------------------------------------- the period map (the core's flow protocol)
    @property
    def dimension(self) -> int:
        """2N, the size of the state z = (X, X')."""
        return 2 * self.system.n_dof

    def linear_frequencies(self) -> tuple[float, float] | None:
        """(lowest, highest) linear frequency over the free system and the one with every spring engaged."""
        system = self.system
        stiffnesses = [system.K] + ([system.K + self.epsilon * system.W @ system.A] if system.n_springs else [])
        squares = [float(x) for K in stiffnesses for x in np.linalg.eigvals(np.linalg.solve(system.M, K)).real]
        roots = [math.sqrt(abs(x)) for x in squares if x != 0.0]
        return (min(roots), max(roots)) if roots else None

    def period_map(self, state0: Any, frequency: float, *, periods: int = 1, forcing_scale: float = 1.0,
                   sensitivity: bool = True, d_epsilon: bool = False) -> PeriodMapValue:
        """``Π(z0; Ω) = z(2πk/Ω)`` of the free flow with its exact derivatives (the forced flows' protocol).

        ``d_state`` is the state transition matrix (the saltation matrices are the identity), ``d_frequency``
        ``= −(2πk/Ω²) f(z(2πk/Ω))`` (the horizon moves with Ω), ``d_forcing`` zero (no load), ``d_epsilon`` the
        closed-form ε-derivative when asked for; the counters hold the switches.  Raises
        :class:`~lindstedt.ConvergenceError` when the flow fails.

        Examples
        --------
        >>> flow = ExactFlow(UnilateralSystem.one_dof(1), epsilon=3.0)          # ω = 4/3 at any amplitude
        >>> value = flow.period_map([1.0, 0.0], 4 / 3)
        >>> np.round(value.state, 12).tolist(), value.counters["switches"]
        ([1.0, 0.0], 2)
        """
        frequency = _as_time(frequency, "frequency")
        if not frequency > 0:
            raise ProblemError(f"frequency must be positive, got {frequency}")
        horizon = 2.0 * math.pi * int(periods) / frequency
        value = self.advance(state0, horizon, sensitivity=sensitivity, d_epsilon=d_epsilon)
        if not sensitivity:
            return value
        n = self.system.n_dof
        field = np.r_[value.state[n:], self.system.acceleration(value.state[:n], self.epsilon)]
        return replace(value, d_frequency=-(horizon / frequency) * field, d_forcing=np.zeros(2 * n))

    def advance(self, state0: Any, t: float, *, sensitivity: bool = True, d_epsilon: bool = False) -> PeriodMapValue:
        """The state after time t with ``∂z(t)/∂z0`` (``sensitivity``) and ``∂z(t)/∂ε`` (``d_epsilon``): the
        autonomous form of :meth:`period_map` (the NNM shooting flows over T/2 or T).

        Examples
        --------
        >>> flow = ExactFlow(UnilateralSystem.one_dof(1), epsilon=0.0)
        >>> (np.round(flow.advance([1.0, 0.0], np.pi).state, 12) + 0.0).tolist()
        [-1.0, 0.0]
        """
        n = self.system.n_dof
        z0 = _as_state_vector(state0, 2 * n, "state0")
        run = self._run(z0[:n], z0[n:], t, dense=d_epsilon, sensitivity=sensitivity or d_epsilon)
        if not run["success"]:
            raise ConvergenceError(f"the flow failed: {run['message']}")
        counters = {"switches": len(run["events"]), "arcs": run["cost"]["n_arcs"],
                    "evaluations": run["cost"]["n_evaluations"]}
        return PeriodMapValue(np.r_[run["x"], run["v"]], run["jacobian"] if sensitivity else None, counters=counters,
                              d_epsilon=self._epsilon_derivative(run) if d_epsilon else None)

    def sample(self, state0: Any, frequency: float, *, periods: int = 1, forcing_scale: float = 1.0,
               samples: int = 256) -> tuple[np.ndarray, np.ndarray]:
        """``(t, z(t))`` at ``samples`` equally spaced times of ``[0, 2πk/Ω)`` (dense closed-form output).

        Examples
        --------
        >>> t, z = ExactFlow(UnilateralSystem.one_dof(1), epsilon=0.0).sample([1.0, 0.0], 1.0, samples=4)
        >>> (np.round(z[:, 0], 12) + 0.0).tolist()
        [1.0, 0.0, -1.0, 0.0]
        """
        n = self.system.n_dof
        z0 = _as_state_vector(state0, 2 * n, "state0")
        horizon = 2.0 * math.pi * int(periods) / _as_time(frequency, "frequency")
        times = np.linspace(0.0, horizon, int(samples), endpoint=False)
        X, V = self.solve(z0[:n], z0[n:], horizon).state(times)
        return times, np.hstack([X, V])

    # --------------------------------------------------------------- public API
    def solve(self, x0: Any, v0: Any, t_end: float) -> FlowResult:
        """Flow from ``X(0) = x0``, ``X'(0) = v0`` to ``t_end`` with dense closed-form output.

        Parameters
        ----------
        x0, v0 : array_like, shape (N,)
            Initial positions and velocities.
        t_end : float
            Final time (≥ 0).

        Returns
        -------
        FlowResult
            ``result.state(t)`` evaluates the closed form of the arc containing t.

        Examples
        --------
        >>> flow = ExactFlow(UnilateralSystem.chain(3, [(0, 0.1)]), epsilon=0.5)
        >>> result = flow.solve([0.3, 0.0, 0.0], [0.0, 0.0, 0.0], t_end=20.0)
        >>> result.success, result.n_states_visited
        (True, 2)
        >>> X, V = result.state([0.0, 20.0])
        >>> X.shape, bool(np.allclose(X[1], result.position, rtol=0, atol=1e-14))
        ((2, 3), True)
        """
        run = self._run(x0, v0, t_end, dense=True, sensitivity=False)
        starts, modes, q0s, p0s = run["arcs"]
        start_array = np.array(starts, dtype=_LONG)
        q0_array = np.array(q0s, dtype=_LONG).reshape(len(q0s), self.system.n_dof)
        p0_array = np.array(p0s, dtype=_LONG).reshape(len(p0s), self.system.n_dof)
        # the distinct contact modes in order of first use, and each arc's index into them
        unique_modes = list({id(mode): mode for mode in modes}.values())
        mode_index = {id(mode): k for k, mode in enumerate(unique_modes)}
        arc_mode = np.array([mode_index[id(mode)] for mode in modes], dtype=int)
        n = self.system.n_dof
        final_x, final_v = run["x"].copy(), run["v"].copy()

        def evaluator(times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            positions = np.empty((times.size, n))
            velocities = np.empty((times.size, n))
            if start_array.size == 0:
                positions[:] = final_x
                velocities[:] = final_v
                return positions, velocities
            times_l = times.astype(_LONG)
            arcs = np.clip(np.searchsorted(start_array, times_l, side="right") - 1, 0, start_array.size - 1)
            for index, mode in enumerate(unique_modes):
                selected = np.flatnonzero(arc_mode[arcs] == index)
                if selected.size:
                    arc = arcs[selected]
                    x_l, v_l = mode.evaluate(q0_array[arc], p0_array[arc], times_l[selected] - start_array[arc])
                    positions[selected] = x_l.astype(float)
                    velocities[selected] = v_l.astype(float)
            return positions, velocities

        return FlowResult(
            success=run["success"],
            message=run["message"],
            method="exact",
            t_final=run["t"],
            position=final_x,
            velocity=final_v,
            events=run["events"],
            **run["cost"],
            n_decompositions=run["decompositions"],
            contact_states=run["visited"],
            _evaluator=evaluator,
            system=self.system,
            epsilon=self.epsilon,
        )

    def flow_map(self, x0: Any, v0: Any, t: float, *, sensitivity: bool = False) -> FlowMapResult:
        """State at time ``t`` and optionally the sensitivity ``∂(X(t), X'(t))/∂(X0, V0)``.

        The sensitivity is the product of the arcs' state transition matrices
        (the saltation matrices are the identity: the force is continuous).

        Examples
        --------
        >>> flow = ExactFlow(UnilateralSystem.one_dof(1), epsilon=3.0)
        >>> out = flow.flow_map([1.0], [0.0], 1.5 * np.pi, sensitivity=True)
        >>> out.position.round(12).tolist(), out.sensitivity.shape
        ([1.0], (2, 2))
        """
        run = self._run(x0, v0, t, dense=False, sensitivity=sensitivity)
        return FlowMapResult(
            success=run["success"],
            message=run["message"],
            position=run["x"],
            velocity=run["v"],
            sensitivity=run["jacobian"],
            **run["cost"],
            system=self.system,
            epsilon=self.epsilon,
        )
