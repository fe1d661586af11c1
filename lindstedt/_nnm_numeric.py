"""Nonlinear normal modes of  M X'' + K X + ε W (A X − b)_+ = 0  by shooting on the exact flow.

A nonlinear normal mode (NNM, in Rosenberg's sense) of mode j is a periodic
orbit that grows out of the linear mode ``φ_j`` (``K φ_j = λ_j² M φ_j``,
``Φᵀ M Φ = I``) as ε → 0 or as the amplitude → 0.  It is computed here by
*shooting*: unknown initial state and period, residuals evaluated with the
exact piecewise closed-form flow (:class:`lindstedt._flow.ExactFlow`), and a
Newton (Gauss–Newton) iteration whose Jacobian is exact — the state transition
matrix of the flow over T/2 or T (over a full period: the monodromy matrix),
the vector field at the end point for the derivative in T, and a closed-form
Duhamel integral for the derivative in ε.  No finite differences are used.

Formulations (``formulation=``)
-------------------------------
``"full"`` — the seed's formulation (section 4.3.2) plus a phase condition.
    Unknowns ``(X0, X1, T)`` (2N + 1); residuals (2N + 2, consistent)::

        X(T) − X0,   X'(T) − X1,   amplitude(X0, X1) − target,   φ_jᵀ M X1

    The last row is the phase condition: the orbit is started where the
    modal velocity of mode j vanishes, which removes the time-shift
    invariance without assuming any symmetry (for the brake orbits of these
    time-reversible systems it selects a turning point, so ``X1 = 0`` at the
    solution).  One periodicity row is redundant on a family of periodic
    orbits (energy conservation, or reversibility when ``W ≠ Aᵀ``), so the
    system is solved in the least-squares (Gauss–Newton) sense: it converges
    quadratically because the residual vanishes at the solution.

``"symmetric"`` (default) — time-reversible orbits released from rest.
    The force depends on positions only, so ``t → −t`` maps solutions to
    solutions; an orbit with ``X'(0) = 0`` and ``X'(T/2) = 0`` is T-periodic.
    Unknowns ``(X0, T)`` (N + 1), square system::

        X'(T/2; X0, X'(0) = 0) = 0,   amplitude(X0, 0) − target

    Half the integration time, half the unknowns, better conditioned.

Amplitude (exactly one of)
--------------------------
``energy=E``
    ``E(X0, X1) = E``.  For ``W = Aᵀ`` this is the conserved energy
    ``½ X'ᵀ M X' + ½ Xᵀ K X + ½ ε Σ (A X − b)_+²``; for ``W ≠ Aᵀ`` (e.g. the
    seed's example, which has no conserved energy) it is the *linear* energy
    ``½ X'ᵀ M X' + ½ Xᵀ K X`` at the release point (see :func:`nnm_energy`).
``energy_per_epsilon=c``
    The seed's ``E = c ε`` (the amplitude grows with ε).
``modal_amplitude=a0``
    ``u_j(0) = φ_jᵀ M X0 = a0``, i.e. ``X0 = Φ (a0 e_j + Σ_{k≠j} q_k e_k)``
    with the ``q_k`` free — directly comparable with a Lindstedt–Poincaré
    NNM expansion (``ω(ε) = λ_j + ε ω_1 + ε² ω_2``, ``u_k(0) = ε a_k``; see
    :func:`lindstedt.nnm`).

Modes are numbered from 1 (``mode=1`` is the lowest λ), as in the seed and in
:func:`lindstedt.nnm`.

Continuation (:func:`continue_nnm`)
-----------------------------------
Pseudo-arclength continuation in ε, the energy or the modal amplitude (tangent
predictor from the null vector of the augmented Jacobian, Newton corrector
with the arclength constraint, step control, fold detection, Floquet
multipliers and stability along the branch), and — as the baseline — the
seed's algorithm: natural continuation in ε with step halving on failure and
Powell's hybrid method without Jacobian (``scipy.optimize.root(method="hybr")``)
on the seed's square residual ``[X(T) − X0, X'(T) − X1, E − c ε]`` (as printed
it has no phase condition, so its Jacobian is singular along the orbit — hybr
still converges to some point of it because the system is consistent).

Every result is verified on its final state with one more flow over the full
period: the periodicity residual is recomputed and the monodromy matrix gives
the Floquet multipliers; an orbit that fails this check is never reported as a
success.  A single solve from the linear-mode guess also rejects an orbit in
which mode j does not carry at least half of the modal energy (Newton from a
distant guess can land on another periodic orbit).
"""

from __future__ import annotations

import math
import time
from concurrent.futures import Executor
from dataclasses import dataclass, field
from functools import partial
from typing import Any, Callable, Iterable, Sequence

import numpy as np
import scipy.optimize

from ._errors import ConvergenceError, ProblemError
from ._parsing import parse_float
from ._flow import ExactFlow
from ._system import UnilateralSystem

__all__ = [
    "NNMResult",
    "NNMBranch",
    "ContinuationProgress",
    "NNMShooting",
    "nnm_point",
    "continue_nnm",
    "nnm_sweep",
    "nnm_energy",
    "seed_example_system",
    "flow_epsilon_derivative",
]

_TWO_PI = 2.0 * math.pi
_FORMULATIONS = ("symmetric", "full")
_PARAMETERS = ("epsilon", "energy", "modal_amplitude")
#: relative σ_min/σ_max below which a Newton matrix is declared singular
_SINGULAR_RATIO = 1e-13
#: a scaled Newton step this small ends the iteration (the caller verifies the final state)
_STEP_TOL = 1e-7


# --------------------------------------------------------------------------- #
# the seed's example system
# --------------------------------------------------------------------------- #
def seed_example_system(n_dof: int, gap: float = 0.0) -> UnilateralSystem:
    """The seed's N-dof example: a chain with the nonlinearity ``F(X) = (X_1 − β_1)_+ M φ_1``.

    Unit masses and unit springs, both ends fixed (``M = I``, ``K`` tridiagonal
    (2, −1)); one unilateral spring on the first mass, written as a
    :class:`UnilateralSystem` with ``A = e_1ᵀ`` (the first mass's
    displacement), gap ``b = β_1 = gap`` and force distribution
    ``W = M φ_1`` (one column; ``φ_1`` the lowest mode shape, M-normalised,
    positive).  So ``W ≠ Aᵀ``: the coupling is non-symmetric and the system
    has no conserved energy.  In modal coordinates (``X = Φ u``) it reads::

        u_1'' + λ_1² u_1 + ε (Σ_k Φ_1k u_k − β_1)_+ = 0,     u_k'' + λ_k² u_k = 0  (k ≠ 1)

    so only ``u_1`` is nonlinear: the NNM of mode 1 is the one-dof oscillator
    ``u'' + λ_1² u + ε Φ_11 (u − β_1/Φ_11)_+ = 0`` (all other ``u_k = 0``) and the
    NNM of a mode j ≠ 1 keeps ``u_j = a cos(λ_j t)`` exactly, so its frequency is
    exactly ``λ_j`` for every ε, ``u_1`` being the T-periodic forced response.

    The seed does not print β_1; the default ``gap = 0`` (the case b = 0 of its
    Corollary 4.2) is used for its examples here.  With ``gap = 0`` the force is
    positively homogeneous, so the NNM frequency depends on ε only, not on the
    amplitude (energy).

    Parameters
    ----------
    n_dof : int
        Number of masses N ≥ 1.
    gap : float, optional
        β_1 (default 0).

    Examples
    --------
    >>> system = seed_example_system(5)
    >>> system.n_dof, system.symmetric_coupling
    (5, False)
    >>> lam, phi = system.modes()
    >>> bool(np.allclose(phi.T @ system.W[:, 0], [1, 0, 0, 0, 0], atol=1e-15))
    True
    """
    if isinstance(n_dof, bool) or not isinstance(n_dof, (int, np.integer)) or n_dof < 1:
        raise ProblemError(f"n_dof must be a positive integer, got {n_dof!r}")
    chain = UnilateralSystem.chain(int(n_dof))
    shape = chain.modes().shapes[:, 0]
    mass = np.asarray(chain.M, dtype=float)
    row = [[1] + [0] * (int(n_dof) - 1)]
    column = (mass @ shape).reshape(-1, 1).tolist()
    return UnilateralSystem(M=chain.M_exact, K=chain.K_exact, A=row, b=[gap], W=column)


# --------------------------------------------------------------------------- #
# energy and amplitude
# --------------------------------------------------------------------------- #
def nnm_energy(system: UnilateralSystem, x: Any, v: Any, epsilon: float) -> float:
    """The energy used to parametrise NNMs.

    ``W = Aᵀ``: the conserved energy ``½ X'ᵀ M X' + ½ Xᵀ K X + ½ ε Σ (A X − b)_+²``.
    ``W ≠ Aᵀ`` (no conserved energy exists): the linear energy
    ``½ X'ᵀ M X' + ½ Xᵀ K X`` of the given state — for an NNM, of its release
    point.

    Examples
    --------
    >>> nnm_energy(UnilateralSystem.one_dof(1), [2.0], [1.0], 0.5)
    3.5
    >>> nnm_energy(seed_example_system(2), [1.0, 0.0], [0.0, 0.0], 0.5)
    1.0
    """
    x = np.asarray(x, dtype=float)
    v = np.asarray(v, dtype=float)
    value = 0.5 * float(v @ system.M @ v) + 0.5 * float(x @ system.K @ x)
    if system.symmetric_coupling and system.n_springs:
        value += 0.5 * float(epsilon) * float(np.sum(np.maximum(system.gaps(x), 0.0) ** 2))
    return value


def _energy_gradient(
    system: UnilateralSystem, x: np.ndarray, v: np.ndarray, epsilon: float
) -> tuple[np.ndarray, np.ndarray, float]:
    """(∂E/∂x, ∂E/∂v, ∂E/∂ε) of :func:`nnm_energy`."""
    grad_x = system.K @ x
    d_eps = 0.0
    if system.symmetric_coupling and system.n_springs:
        engaged = np.maximum(system.gaps(x), 0.0)
        grad_x = grad_x + epsilon * system.A.T @ engaged
        d_eps = 0.5 * float(np.sum(engaged**2))
    return grad_x, system.M @ v, d_eps


def _equilibrium(system: UnilateralSystem, epsilon: float) -> np.ndarray:
    """Static equilibrium ``K X + ε W (A X − b)_+ = 0`` by active-set iteration (X = 0 when b ≥ 0)."""
    n = system.n_dof
    if system.n_springs == 0 or np.all(system.b >= 0):
        return np.zeros(n)
    x = np.zeros(n)
    seen = set()
    for _ in range(2 ** min(system.n_springs, 12) + 1):
        state = tuple(bool(g > 0) for g in system.gaps(x))
        if state in seen:
            break
        seen.add(state)
        mask = np.array(state)
        stiffness = system.K + epsilon * system.W[:, mask] @ system.A[mask]
        x = np.linalg.solve(stiffness, epsilon * system.W[:, mask] @ system.b[mask])
    return x


@dataclass(frozen=True)
class _Amplitude:
    """amplitude(X0, X1; ε) − target(ε): kind ∈ {"energy", "energy_per_epsilon", "modal_amplitude"}."""

    kind: str
    value: float

    def target(self, epsilon: float) -> float:
        return self.value * epsilon if self.kind == "energy_per_epsilon" else self.value

    def d_target_d_epsilon(self) -> float:
        return self.value if self.kind == "energy_per_epsilon" else 0.0

    def d_target_d_value(self, epsilon: float) -> float:
        return epsilon if self.kind == "energy_per_epsilon" else 1.0


def _amplitude_spec(energy: Any, modal_amplitude: Any, energy_per_epsilon: Any) -> _Amplitude:
    given = [(name, value) for name, value in (("energy", energy), ("modal_amplitude", modal_amplitude),
                                               ("energy_per_epsilon", energy_per_epsilon)) if value is not None]
    if len(given) != 1:
        raise ProblemError(
            "give exactly one amplitude: energy=E, modal_amplitude=a0 (u_j(0) = a0) or energy_per_epsilon=c "
            f"(the seed's E = c ε); got {[name for name, _ in given] or 'none'}"
        )
    name, value = given[0]
    return _Amplitude(name, parse_float(value, what=name))


def _check_mode(system: UnilateralSystem, mode: Any) -> int:
    if isinstance(mode, bool) or not isinstance(mode, (int, np.integer)) or not 1 <= mode <= system.n_dof:
        raise ProblemError(
            f"mode must be an integer in 1..{system.n_dof} (1 = lowest linear frequency, as in the seed), got {mode!r}"
        )
    return int(mode)


def _check_epsilon(epsilon: Any) -> float:
    return parse_float(epsilon, what="epsilon")


# --------------------------------------------------------------------------- #
# the flow with exact derivatives
# --------------------------------------------------------------------------- #
@dataclass(frozen=True)
class _Trajectory:
    success: bool
    message: str
    position: np.ndarray
    velocity: np.ndarray
    sensitivity: np.ndarray | None  # ∂(X, V)(t) / ∂(X0, V0)
    d_epsilon: np.ndarray | None  # ∂(X, V)(t) / ∂ε
    n_switches: int


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


def _integrate(
    flow: ExactFlow, x0: np.ndarray, v0: np.ndarray, t: float, *, sensitivity: bool, d_epsilon: bool
) -> _Trajectory:
    """Flow to time t with the exact sensitivities in (X0, V0) and, optionally, in ε.

    The ε-derivative z = ∂(X, V)/∂ε solves z' = J(t) z + (0, −M⁻¹ W (A X − b)_+),
    z(0) = 0; the saltation matrices are the identity because the vector field
    and its ε-derivative are continuous across the switching surfaces.  On each
    arc, in the modal coordinates (P, Q = P⁻¹, ω) of its contact state, the
    forcing is a constant plus harmonics of the arc's own frequencies, and the
    Duhamel integral is summed in closed form (:func:`_duhamel_kernels`).

    Uses the arc data of ``ExactFlow._run`` (same package).
    """
    system = flow.system
    n = system.n_dof
    try:
        run = flow._run(x0, v0, t, dense=d_epsilon, sensitivity=sensitivity or d_epsilon)
    except ProblemError as error:
        return _Trajectory(False, f"the flow failed: {error}", np.full(n, np.nan), np.full(n, np.nan), None, None, 0)
    if not run["success"]:
        return _Trajectory(False, f"the flow failed: {run['message']}", run["x"], run["v"], None, None, len(run["events"]))
    derivative = None
    if d_epsilon:
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
        derivative = z
    return _Trajectory(True, "", run["x"], run["v"], run["jacobian"] if sensitivity else None, derivative, len(run["events"]))


def flow_epsilon_derivative(
    system: UnilateralSystem, epsilon: float, x0: Any, v0: Any, t: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """State at time t with its exact derivatives ``∂(X, X')/∂(X0, V0)`` and ``∂(X, X')/∂ε``.

    Returns
    -------
    (state, sensitivity, d_epsilon) : numpy.ndarray
        Shapes (2N,), (2N, 2N), (2N,).

    Raises
    ------
    ConvergenceError
        When the flow fails.

    Examples
    --------
    >>> system = UnilateralSystem.one_dof(1)          # u'' + u + ε u_+ = 0
    >>> state, _, d_eps = flow_epsilon_derivative(system, 0.0, [1.0], [0.0], np.pi / 2)
    >>> round(float(d_eps[0]), 12)                    # ∂u/∂ε = −(t/2) sin t at ε = 0, t = π/2
    -0.785398163397
    """
    flow = ExactFlow(system, _check_epsilon(epsilon))
    n = system.n_dof
    x0 = np.asarray(x0, dtype=float).reshape(n)
    v0 = np.asarray(v0, dtype=float).reshape(n)
    trajectory = _integrate(flow, x0, v0, float(t), sensitivity=True, d_epsilon=True)
    if not trajectory.success:
        raise ConvergenceError(trajectory.message)
    return np.concatenate([trajectory.position, trajectory.velocity]), trajectory.sensitivity, trajectory.d_epsilon


# --------------------------------------------------------------------------- #
# results
# --------------------------------------------------------------------------- #
@dataclass(frozen=True)
class NNMResult:
    """One nonlinear normal mode (a periodic orbit), or why it could not be computed.

    Attributes
    ----------
    success : bool
        True only if the orbit was verified: one more flow over the full
        period from the final state returns to it within ``verify_tol``.
    message : str
        What happened; on failure why (no convergence, singular Jacobian —
        fold or bifurcation —, impossible energy, flow failure, failed
        verification).  Mentions "no contact" when the orbit never touches
        the springs (it is then the linear mode, ω = λ_j).
    mode : int
        1-based mode number j the NNM grows from.
    epsilon : float
    frequency : float
        ω = 2π / T (NaN on failure).
    period : float
        T.
    linear_frequency : float
        λ_j.
    release_position, release_velocity : numpy.ndarray, shape (N,)
        Initial state X0, X1 (X1 = 0 for the symmetric formulation).
    modal_coordinates : numpy.ndarray, shape (N,)
        ``u(0) = Φᵀ M X0`` (release modal coordinates; ``u_j(0)`` is the modal amplitude).
    energy : float
        :func:`nnm_energy` of the release state.
    floquet_multipliers : numpy.ndarray, shape (2N,) or None
        Eigenvalues of the monodromy matrix (over one full period), sorted by
        distance to 1: the first two are the trivial ones (time shift and
        family direction), equal to 1 up to about ``sqrt(machine ε)``.
    stable : bool or None
        Linear stability: all multipliers within ``1 + stability_tol`` of the unit circle.
    residual : float
        Relative periodicity residual of the verification flow,
        ``max(|X(T) − X0|/x_s, |X'(T) − X1|/(ω x_s))``, x_s the orbit's scale.
    n_switches : int
        Contact switches per period (0: no contact).
    mode_share : float
        Share of mode j in the linear modal energies ``½ (u̇_k² + λ_k² u_k²)``
        of the release state (1 for the linear mode).
    formulation : str
        ``"symmetric"``, ``"full"`` or ``"seed"`` (the baseline's residual).
    newton_iterations : int
        Newton (or hybr) iterations.
    flow_evaluations : int
        Flow integrations used, including the verification flow.
    monodromy : numpy.ndarray or None
        The 2N × 2N monodromy matrix.
    """

    success: bool
    message: str
    mode: int
    epsilon: float
    frequency: float
    period: float
    linear_frequency: float
    release_position: np.ndarray
    release_velocity: np.ndarray
    modal_coordinates: np.ndarray
    energy: float
    floquet_multipliers: np.ndarray | None
    stable: bool | None
    residual: float
    n_switches: int
    mode_share: float
    formulation: str
    newton_iterations: int
    flow_evaluations: int
    monodromy: np.ndarray | None = field(default=None, repr=False)

    @property
    def contact(self) -> bool:
        """Whether the orbit touches a unilateral spring (switches during a period)."""
        return self.n_switches > 0

    @property
    def modal_amplitude(self) -> float:
        """``u_j(0)``, the release modal coordinate of the NNM's own mode."""
        return float(self.modal_coordinates[self.mode - 1])

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready data (schema ``lindstedt.nnm-numeric/1``); NaN and infinities become ``None``.

        Examples
        --------
        >>> import lindstedt
        >>> chain = lindstedt.UnilateralSystem.chain(2, unilateral=[(0, 0)])
        >>> data = lindstedt.nnm_point(chain, 0.05, 1, modal_amplitude=1.0).to_dict()
        >>> data["success"], data["status"], round(data["frequency"], 6)
        (True, 'converged', 1.006128)
        """

        def number(value: Any) -> float | None:
            return float(value) if math.isfinite(value) else None

        multipliers = [] if self.floquet_multipliers is None else [[number(z.real), number(z.imag)] for z in self.floquet_multipliers]
        return {
            "schema": "lindstedt.nnm-numeric/1",
            "success": bool(self.success),
            "status": "converged" if self.success else "failed",
            "message": self.message,
            "mode": self.mode,
            "epsilon": number(self.epsilon),
            "frequency": number(self.frequency),
            "period": number(self.period),
            "linear_frequency": number(self.linear_frequency),
            "release_position": [number(x) for x in self.release_position],
            "release_velocity": [number(x) for x in self.release_velocity],
            "modal_coordinates": [number(x) for x in self.modal_coordinates],
            "energy": number(self.energy),
            "floquet_multipliers": multipliers,
            "stable": self.stable,
            "residual": number(self.residual),
            "n_switches": self.n_switches,
            "formulation": self.formulation,
            "newton_iterations": self.newton_iterations,
            "flow_evaluations": self.flow_evaluations,
        }

    def to_json(self, indent: int | None = 2) -> str:
        """Strict JSON text of :meth:`to_dict` (never NaN)."""
        import json

        return json.dumps(self.to_dict(), indent=indent, allow_nan=False)

    def summary(self) -> str:
        """One line: mode, ε, ω, T, energy, stability, cost."""
        if not self.success:
            return f"mode {self.mode}, ε = {self.epsilon:g}: FAILED — {self.message}"
        largest = float(np.max(np.abs(self.floquet_multipliers))) if self.floquet_multipliers is not None else float("nan")
        return (
            f"mode {self.mode}, ε = {self.epsilon:g}: ω = {self.frequency:.12g} (λ_j = {self.linear_frequency:.12g}), "
            f"T = {self.period:.12g}, E = {self.energy:.6g}, max|μ| = {largest:.6g} "
            f"({'stable' if self.stable else 'unstable'}), {self.n_switches} switches/period, "
            f"{self.newton_iterations} iterations, {self.flow_evaluations} flows"
        )


def _failed(mode: int, epsilon: float, linear_frequency: float, n: int, message: str, formulation: str,
            iterations: int, flows: int, x0: np.ndarray | None = None) -> NNMResult:
    position = np.full(n, np.nan) if x0 is None else np.array(x0, dtype=float)
    return NNMResult(
        success=False, message=message, mode=mode, epsilon=epsilon, frequency=float("nan"), period=float("nan"),
        linear_frequency=linear_frequency, release_position=position, release_velocity=np.full(n, np.nan),
        modal_coordinates=np.full(n, np.nan), energy=float("nan"), floquet_multipliers=None, stable=None,
        residual=float("nan"), n_switches=0, mode_share=float("nan"), formulation=formulation, newton_iterations=iterations,
        flow_evaluations=flows,
    )


# --------------------------------------------------------------------------- #
# the shooting problem
# --------------------------------------------------------------------------- #
class NNMShooting:
    """Residual and exact Jacobian of the NNM shooting problem of one mode.

    Parameters
    ----------
    system : UnilateralSystem
    mode : int
        1-based mode number j.
    energy, modal_amplitude, energy_per_epsilon : float
        Exactly one: the amplitude condition (see the module docstring).
    formulation : {"symmetric", "full"}
        Unknowns ``(X0, T)`` or ``(X0, X1, T)``.
    release_sign : {1, -1}
        For energy amplitudes: release on the side ``+φ_j`` (default) or ``−φ_j``.

    Notes
    -----
    Residual rows are scaled (velocities by ``λ_j x_s``, positions by ``x_s``,
    the amplitude equation by its target), ``x_s`` being the amplitude of the
    linear-mode guess; the Jacobian is with respect to the unscaled unknowns.
    Each call of :meth:`evaluate` is one flow integration.

    Examples
    --------
    >>> problem = NNMShooting(UnilateralSystem.one_dof(1), 1, modal_amplitude=1.0)
    >>> guess = problem.initial_guess(0.0)
    >>> guess.tolist() == [1.0, 2 * np.pi]
    True
    >>> float(np.max(np.abs(problem.residual(guess, 0.0)))) < 1e-15   # ε = 0: the linear mode
    True
    """

    def __init__(
        self,
        system: UnilateralSystem,
        mode: int,
        *,
        energy: float | None = None,
        modal_amplitude: float | None = None,
        energy_per_epsilon: float | None = None,
        formulation: str = "symmetric",
        release_sign: int = 1,
    ) -> None:
        if not isinstance(system, UnilateralSystem):
            raise ProblemError(f"system must be a UnilateralSystem, got {type(system).__name__}")
        if formulation not in _FORMULATIONS:
            raise ProblemError(f"formulation must be one of {_FORMULATIONS}, got {formulation!r}")
        if release_sign not in (1, -1):
            raise ProblemError(f"release_sign must be +1 or -1, got {release_sign!r}")
        self.system = system
        self.mode = _check_mode(system, mode)
        self.amplitude = _amplitude_spec(energy, modal_amplitude, energy_per_epsilon)
        self.formulation = formulation
        self.release_sign = int(release_sign)
        frequencies, shapes = system.modes()
        self.n = system.n_dof
        self.linear_frequency = float(frequencies[self.mode - 1])
        self.shape = np.array(shapes[:, self.mode - 1])
        self.modal_row = system.M @ self.shape  # u_j = (M φ_j)ᵀ X
        self.projector = shapes.T @ system.M  # u = Φᵀ M X
        self.n_unknowns = self.n + 1 if formulation == "symmetric" else 2 * self.n + 1
        self._flows: dict[float, ExactFlow] = {}
        self.flow_evaluations = 0
        self.set_scales(epsilon=0.0)

    # ------------------------------------------------------------------ scales
    def _guess_amplitude(self, epsilon: float, amplitude: _Amplitude | None = None) -> tuple[np.ndarray, float]:
        """Release position of the linear-mode guess and its modal amplitude."""
        amplitude = amplitude or self.amplitude
        equilibrium = _equilibrium(self.system, epsilon)
        if amplitude.kind == "modal_amplitude":
            offset = amplitude.value - float(self.modal_row @ equilibrium)
            return equilibrium + offset * self.shape, offset
        floor = nnm_energy(self.system, equilibrium, np.zeros(self.n), epsilon)
        excess = max(amplitude.target(epsilon) - floor, 0.0)
        offset = self.release_sign * math.sqrt(2.0 * excess) / self.linear_frequency
        return equilibrium + offset * self.shape, offset

    def set_scales(self, epsilon: float, x0: np.ndarray | None = None, period: float | None = None,
                   amplitude: _Amplitude | None = None) -> None:
        """Fix the residual scaling from a release state (default: the linear-mode guess)."""
        amplitude = amplitude or self.amplitude
        if x0 is None:
            x0, _ = self._guess_amplitude(epsilon, amplitude)
        scale = float(np.linalg.norm(x0))  # Euclidean: arclength steps measure the relative change of the shape
        if not scale > 0:
            scale = 1.0
        self.position_scale = scale
        self.period_scale = period if period else _TWO_PI / self.linear_frequency
        self.velocity_scale = scale * _TWO_PI / self.period_scale
        target = abs(amplitude.target(epsilon))
        if amplitude.kind == "modal_amplitude":
            self.amplitude_scale = target if target > 0 else scale
        else:
            self.amplitude_scale = target if target > 0 else 0.5 * (self.linear_frequency * scale) ** 2

    def column_scales(self) -> np.ndarray:
        """Typical magnitudes of the unknowns (for scaled Newton steps)."""
        if self.formulation == "symmetric":
            return np.r_[np.full(self.n, self.position_scale), self.period_scale]
        return np.r_[np.full(self.n, self.position_scale), np.full(self.n, self.velocity_scale), self.period_scale]

    # ------------------------------------------------------------------ pieces
    def _flow(self, epsilon: float) -> ExactFlow:
        flow = self._flows.get(epsilon)
        if flow is None:
            if len(self._flows) > 8:
                self._flows.clear()
            flow = self._flows[epsilon] = ExactFlow(self.system, epsilon)
        return flow

    def initial_guess(self, epsilon: float) -> np.ndarray:
        """Unknowns of the linear mode j with the requested amplitude (period 2π/λ_j)."""
        x0, _ = self._guess_amplitude(_check_epsilon(epsilon))
        period = _TWO_PI / self.linear_frequency
        if self.formulation == "symmetric":
            return np.r_[x0, period]
        return np.r_[x0, np.zeros(self.n), period]

    def split(self, unknowns: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
        """(X0, X1, T) from the unknown vector."""
        unknowns = np.asarray(unknowns, dtype=float)
        n = self.n
        if self.formulation == "symmetric":
            return unknowns[:n], np.zeros(n), float(unknowns[n])
        return unknowns[:n], unknowns[n:2 * n], float(unknowns[2 * n])

    def _amplitude_row(
        self, x0: np.ndarray, v0: np.ndarray, epsilon: float, amplitude: _Amplitude
    ) -> tuple[float, np.ndarray, np.ndarray, float]:
        """(value − target, ∂/∂X0, ∂/∂X1, ∂/∂ε) of the amplitude equation (unscaled)."""
        if amplitude.kind == "modal_amplitude":
            return float(self.modal_row @ x0) - amplitude.value, self.modal_row, np.zeros(self.n), 0.0
        grad_x, grad_v, d_eps = _energy_gradient(self.system, x0, v0, epsilon)
        value = nnm_energy(self.system, x0, v0, epsilon) - amplitude.target(epsilon)
        return value, grad_x, grad_v, d_eps - amplitude.d_target_d_epsilon()

    def evaluate(self, unknowns: Any, epsilon: float, *, jacobian: bool = True, d_epsilon: bool = False,
                 amplitude: _Amplitude | None = None) -> dict[str, Any]:
        """Residual (scaled) and, optionally, its exact Jacobian; one flow integration.

        Returns a dict with ``residual`` (rows scaled), ``jacobian`` (rows
        scaled, columns = unscaled unknowns), ``d_epsilon`` (∂residual/∂ε),
        ``d_level`` (∂residual/∂amplitude value), ``success``, ``message``,
        ``n_switches``.
        """
        epsilon = _check_epsilon(epsilon)
        amplitude = amplitude or self.amplitude
        x0, v0, period = self.split(unknowns)
        n = self.n
        if not (math.isfinite(period) and period > 0) or not (np.all(np.isfinite(x0)) and np.all(np.isfinite(v0))):
            return {"success": False, "message": f"the iterate left the admissible set (T = {period:.6g})"}
        horizon = 0.5 * period if self.formulation == "symmetric" else period
        self.flow_evaluations += 1
        trajectory = _integrate(self._flow(epsilon), x0, v0, horizon, sensitivity=jacobian, d_epsilon=d_epsilon)
        if not trajectory.success:
            return {"success": False, "message": trajectory.message}
        amp_value, amp_x, amp_v, amp_eps = self._amplitude_row(x0, v0, epsilon, amplitude)
        xs, vs, As = self.position_scale, self.velocity_scale, self.amplitude_scale
        if self.formulation == "symmetric":
            residual = np.r_[trajectory.velocity / vs, amp_value / As]
        else:
            residual = np.r_[
                (trajectory.position - x0) / xs,
                (trajectory.velocity - v0) / vs,
                amp_value / As,
                float(self.modal_row @ v0) / vs,
            ]
        out: dict[str, Any] = {"success": True, "message": "", "residual": residual, "n_switches": trajectory.n_switches,
                               "end_position": trajectory.position, "end_velocity": trajectory.velocity}
        if jacobian or d_epsilon:
            acceleration = self.system.acceleration(trajectory.position, epsilon)
        if jacobian:
            S = trajectory.sensitivity
            if self.formulation == "symmetric":
                J = np.zeros((n + 1, n + 1))
                J[:n, :n] = S[n:, :n] / vs
                J[:n, n] = 0.5 * acceleration / vs
                J[n, :n] = amp_x / As
            else:
                identity = np.eye(n)
                J = np.zeros((2 * n + 2, 2 * n + 1))
                J[:n, :n] = (S[:n, :n] - identity) / xs
                J[:n, n:2 * n] = S[:n, n:] / xs
                J[:n, 2 * n] = trajectory.velocity / xs
                J[n:2 * n, :n] = S[n:, :n] / vs
                J[n:2 * n, n:2 * n] = (S[n:, n:] - identity) / vs
                J[n:2 * n, 2 * n] = acceleration / vs
                J[2 * n, :n] = amp_x / As
                J[2 * n, n:2 * n] = amp_v / As
                J[2 * n + 1, n:2 * n] = self.modal_row / vs
            out["jacobian"] = J
        if d_epsilon:
            dz = trajectory.d_epsilon
            if self.formulation == "symmetric":
                out["d_epsilon"] = np.r_[dz[n:] / vs, amp_eps / As]
            else:
                out["d_epsilon"] = np.r_[dz[:n] / xs, dz[n:] / vs, amp_eps / As, 0.0]
        level_row = -amplitude.d_target_d_value(epsilon) / As
        out["d_level"] = np.r_[np.zeros(len(residual) - (1 if self.formulation == "symmetric" else 2)), level_row,
                               np.zeros(0 if self.formulation == "symmetric" else 1)]
        return out

    def residual(self, unknowns: Any, epsilon: float) -> np.ndarray:
        """Scaled residual vector (raises ConvergenceError if the flow fails)."""
        out = self.evaluate(unknowns, epsilon, jacobian=False)
        if not out["success"]:
            raise ConvergenceError(out["message"])
        return out["residual"]

    def jacobian(self, unknowns: Any, epsilon: float) -> tuple[np.ndarray, np.ndarray]:
        """Exact Jacobian of :meth:`residual` in the unknowns, and the column ∂residual/∂ε."""
        out = self.evaluate(unknowns, epsilon, jacobian=True, d_epsilon=True)
        if not out["success"]:
            raise ConvergenceError(out["message"])
        return out["jacobian"], out["d_epsilon"]

    # ------------------------------------------------------------ verification
    def mode_share(self, x0: np.ndarray, v0: np.ndarray) -> tuple[float, int]:
        """Share of mode j in the linear modal energies of (x0, v0), and the dominant mode (1-based)."""
        frequencies = self.system.modes().frequencies
        modal_energy = 0.5 * ((self.projector @ v0) ** 2 + (frequencies * (self.projector @ x0)) ** 2)
        total = float(np.sum(modal_energy))
        if not total > 0:
            return 1.0, self.mode
        return float(modal_energy[self.mode - 1] / total), int(np.argmax(modal_energy)) + 1

    def verify(self, unknowns: np.ndarray, epsilon: float, *, verify_tol: float, stability_tol: float,
               iterations: int, amplitude: _Amplitude | None = None, formulation_label: str | None = None,
               min_mode_share: float | None = None, note: str = "") -> NNMResult:
        """One flow over the full period: periodicity residual, monodromy, Floquet multipliers.

        With ``min_mode_share``, an orbit whose mode-j share of the modal
        energy is below it is reported as a failure (Newton from a distant
        guess can land on another periodic orbit, e.g. a resonant one).
        """
        amplitude = amplitude or self.amplitude
        label = formulation_label or self.formulation
        x0, v0, period = self.split(unknowns)
        n = self.n
        if not (math.isfinite(period) and period > 0):
            return _failed(self.mode, epsilon, self.linear_frequency, n, f"invalid period T = {period}", label,
                           iterations, self.flow_evaluations, x0)
        self.flow_evaluations += 1
        trajectory = _integrate(self._flow(epsilon), x0, v0, period, sensitivity=True, d_epsilon=False)
        if not trajectory.success:
            return _failed(self.mode, epsilon, self.linear_frequency, n, trajectory.message, label, iterations,
                           self.flow_evaluations, x0)
        frequency = _TWO_PI / period
        scale = max(float(np.max(np.abs(x0))), float(np.max(np.abs(v0))) / frequency, np.finfo(float).tiny)
        residual = max(
            float(np.max(np.abs(trajectory.position - x0))) / scale,
            float(np.max(np.abs(trajectory.velocity - v0))) / (frequency * scale),
        )
        amp_value, _, _, _ = self._amplitude_row(x0, v0, epsilon, amplitude)
        amp_scale = max(abs(amplitude.target(epsilon)), self.amplitude_scale, np.finfo(float).tiny)
        amplitude_error = abs(amp_value) / amp_scale
        monodromy = trajectory.sensitivity
        multipliers = np.linalg.eigvals(monodromy)
        multipliers = multipliers[np.argsort(np.abs(multipliers - 1.0), kind="stable")]
        stable = bool(np.max(np.abs(multipliers)) <= 1.0 + stability_tol)
        energy = nnm_energy(self.system, x0, v0, epsilon)
        share, dominant = self.mode_share(x0, v0)
        common = dict(
            mode=self.mode, epsilon=epsilon, frequency=frequency, period=period,
            linear_frequency=self.linear_frequency, release_position=np.array(x0), release_velocity=np.array(v0),
            modal_coordinates=self.projector @ x0, energy=energy, floquet_multipliers=multipliers, stable=stable,
            residual=residual, n_switches=trajectory.n_switches, mode_share=share, formulation=label,
            newton_iterations=iterations,
            flow_evaluations=self.flow_evaluations, monodromy=monodromy,
        )
        if not (residual <= verify_tol and amplitude_error <= verify_tol):
            return NNMResult(
                success=False,
                message=(
                    f"verification failed: periodicity residual {residual:.2e}, amplitude residual "
                    f"{amplitude_error:.2e} over one full period (verify_tol = {verify_tol:.1e}){note}"
                ),
                **common,
            )
        if min_mode_share is not None and share < min_mode_share:
            return NNMResult(
                success=False,
                message=(
                    f"converged to a periodic orbit that is not the NNM of mode {self.mode}: mode {dominant} carries "
                    f"the most modal energy, mode {self.mode} only {share:.1%} (< {min_mode_share:.0%}); start closer "
                    "(continue_nnm from the linear mode, or initial_guess=)"
                ),
                **common,
            )
        contact = "" if trajectory.n_switches else "; no contact along the orbit: it is the linear mode (ω = λ_j)"
        return NNMResult(
            success=True,
            message=f"converged in {iterations} iterations, verified residual {residual:.1e}{contact}{note}",
            **common,
        )


# --------------------------------------------------------------------------- #
# Newton
# --------------------------------------------------------------------------- #
@dataclass
class _NewtonOutcome:
    success: bool
    message: str
    unknowns: np.ndarray
    iterations: int
    last: dict[str, Any] | None = None


def _scaled_solve(matrix: np.ndarray, rhs: np.ndarray, columns: np.ndarray) -> tuple[np.ndarray | None, float]:
    """Least-squares solve of matrix·Δ = rhs with column scaling; (Δ, σ_min/σ_max)."""
    scaled = matrix * columns[None, :]
    if not np.all(np.isfinite(scaled)):
        return None, 0.0
    singular_values = np.linalg.svd(scaled, compute_uv=False)
    ratio = float(singular_values[-1] / singular_values[0]) if singular_values[0] > 0 else 0.0
    if ratio < _SINGULAR_RATIO:
        return None, ratio
    step = np.linalg.lstsq(scaled, rhs, rcond=None)[0]
    return step * columns, ratio


def _newton(
    evaluate: Callable[[np.ndarray], dict[str, Any]],
    unknowns: np.ndarray,
    columns: np.ndarray,
    *,
    tol: float,
    max_iterations: int,
    jacobian_key: str = "jacobian",
    step_tol: float = _STEP_TOL,
    max_backtracks: int = 5,
) -> _NewtonOutcome:
    """Damped (Gauss–)Newton on the scaled residual.

    Stops when the residual is ≤ tol, or when a full Newton step is ≤ step_tol
    (scaled): quadratic convergence then puts the residual of ``z + Δ`` far
    below tol, and the caller verifies that final state with a full-period
    flow, so it is not evaluated here (one flow saved per solve).  ``last`` is
    the last evaluation (its Jacobian serves for the continuation tangent).
    """
    z = np.array(unknowns, dtype=float)
    current = evaluate(z)
    if not current["success"]:
        return _NewtonOutcome(False, current["message"], z, 0, None)
    norm = float(np.max(np.abs(current["residual"])))
    for iteration in range(1, max_iterations + 1):
        if norm <= tol:
            return _NewtonOutcome(True, f"residual {norm:.1e}", z, iteration - 1, current)
        step, ratio = _scaled_solve(current[jacobian_key], -current["residual"], columns)
        if step is None:
            return _NewtonOutcome(
                False,
                f"singular Jacobian (σ_min/σ_max = {ratio:.1e}) at iteration {iteration}, residual {norm:.1e}: a fold "
                "of the branch in this parameter, a bifurcation (internal resonance λ_k/ω ∈ ℤ) or a degenerate "
                "amplitude — continue the branch with pseudo-arclength (continue_nnm) or change the parameter",
                z, iteration, current,
            )
        size = float(np.max(np.abs(step / columns)))
        if size <= step_tol:
            return _NewtonOutcome(True, f"residual {norm:.1e}, last step {size:.1e}", z + step, iteration, current)
        damping = 1.0
        for _ in range(max_backtracks + 1):
            trial = z + damping * step
            candidate = evaluate(trial)
            if candidate["success"]:
                trial_norm = float(np.max(np.abs(candidate["residual"])))
                if trial_norm < norm or trial_norm <= tol:
                    break
            damping *= 0.5
        else:
            return _NewtonOutcome(
                False,
                f"no convergence: no Newton step decreased the residual at iteration {iteration} "
                f"(residual {norm:.1e}; last: {candidate.get('message') or 'larger residual'})",
                z, iteration, current,
            )
        z, current, norm = trial, candidate, trial_norm
    if norm <= tol:
        return _NewtonOutcome(True, f"residual {norm:.1e}", z, max_iterations, current)
    return _NewtonOutcome(False, f"no convergence in {max_iterations} Newton iterations (residual {norm:.1e})", z,
                          max_iterations, current)


def _impossible_amplitude(problem: NNMShooting, epsilon: float, amplitude: _Amplitude) -> str | None:
    if amplitude.kind == "modal_amplitude":
        equilibrium = _equilibrium(problem.system, epsilon)
        if amplitude.value == float(problem.modal_row @ equilibrium):
            return (f"impossible amplitude: u_j(0) = {amplitude.value:g} is the equilibrium's, so the orbit is the "
                    "rest state; give a non-zero modal amplitude")
        return None
    floor = nnm_energy(problem.system, _equilibrium(problem.system, epsilon), np.zeros(problem.n), epsilon)
    target = amplitude.target(epsilon)
    if not target > floor:
        return (f"impossible energy: the target E = {target:.6g} is not above the minimum {floor:.6g} (the static "
                "equilibrium), so no periodic orbit has it; give a larger energy")
    return None


def _guess_unknowns(problem: NNMShooting, epsilon: float, initial_guess: Any) -> np.ndarray:
    if initial_guess is None:
        return problem.initial_guess(epsilon)
    if isinstance(initial_guess, NNMResult):
        if not initial_guess.success:
            raise ProblemError("initial_guess is a failed NNMResult; pass a successful one or None")
        x0, v0, period = initial_guess.release_position, initial_guess.release_velocity, initial_guess.period
    else:
        try:
            x0, period = initial_guess
        except (TypeError, ValueError):
            raise ProblemError("initial_guess must be an NNMResult, a pair (X0, T) or None") from None
        v0 = np.zeros(problem.n)
    x0 = np.asarray(x0, dtype=float).reshape(problem.n)
    if problem.formulation == "symmetric":
        return np.r_[x0, float(period)]
    return np.r_[x0, np.asarray(v0, dtype=float).reshape(problem.n), float(period)]


def nnm_point(
    system: UnilateralSystem,
    epsilon: float,
    mode: int,
    *,
    energy: float | None = None,
    modal_amplitude: float | None = None,
    energy_per_epsilon: float | None = None,
    formulation: str = "symmetric",
    initial_guess: Any = None,
    release_sign: int = 1,
    tol: float = 1e-11,
    verify_tol: float = 1e-8,
    stability_tol: float = 1e-6,
    max_iterations: int = 30,
    min_mode_share: float | None = 0.5,
) -> NNMResult:
    """The NNM of ``mode`` at one ε and one amplitude, by Newton shooting on the exact flow.

    Parameters
    ----------
    system : UnilateralSystem
    epsilon : float
    mode : int
        1-based mode number j (1 = lowest λ).
    energy, modal_amplitude, energy_per_epsilon : float
        Exactly one amplitude condition (see the module docstring).
    formulation : {"symmetric", "full"}
        Half-period form for orbits released from rest (default) or the
        seed's full-period form with the phase condition ``φ_jᵀ M X'(0) = 0``.
    initial_guess : NNMResult or (X0, T), optional
        Default: the linear mode j with the requested amplitude, T = 2π/λ_j.
    release_sign : {1, -1}
        Energy amplitudes: release on the ``+φ_j`` or ``−φ_j`` side.
    tol : float
        Newton tolerance on the scaled residual (and on the scaled step).
    verify_tol : float
        Tolerance of the full-period verification of the final state.
    stability_tol : float
        Multipliers with ``|μ| > 1 + stability_tol`` make the orbit unstable.
    max_iterations : int
    min_mode_share : float or None
        Reject an orbit whose share of mode j in the modal energy is below
        this (default 0.5): Newton from a distant guess may converge to
        another periodic orbit.  None disables the check.

    Returns
    -------
    NNMResult
        ``success`` is False (with the reason in ``message``) on an impossible
        energy, a singular Jacobian, no convergence, a flow failure or a failed
        verification; no exception is raised for those.

    Examples
    --------
    The one-dof bilinear oscillator ``u'' + u + ε u_+ = 0`` has
    ``ω = 2 ω_c / (1 + ω_c)``, ``ω_c = sqrt(1 + ε)``:

    >>> result = nnm_point(UnilateralSystem.one_dof(1), 0.5, 1, modal_amplitude=1.0)
    >>> result.success, round(result.frequency, 12), round(2 * 1.5**0.5 / (1 + 1.5**0.5), 12)
    (True, 1.101020514434, 1.101020514434)
    >>> result.stable, result.n_switches
    (True, 2)
    """
    problem = NNMShooting(system, mode, energy=energy, modal_amplitude=modal_amplitude,
                          energy_per_epsilon=energy_per_epsilon, formulation=formulation, release_sign=release_sign)
    epsilon = _check_epsilon(epsilon)
    n = system.n_dof
    impossible = _impossible_amplitude(problem, epsilon, problem.amplitude)
    if impossible:
        return _failed(problem.mode, epsilon, problem.linear_frequency, n, impossible, formulation, 0, 0)
    z0 = _guess_unknowns(problem, epsilon, initial_guess)
    x_guess, _, period_guess = problem.split(z0)
    problem.set_scales(epsilon, x_guess if np.max(np.abs(x_guess)) > 0 else None, period_guess)
    outcome = _newton(lambda z: problem.evaluate(z, epsilon), z0, problem.column_scales(), tol=tol,
                      max_iterations=max_iterations)
    if not outcome.success:
        return _failed(problem.mode, epsilon, problem.linear_frequency, n, outcome.message, formulation,
                       outcome.iterations, problem.flow_evaluations, problem.split(outcome.unknowns)[0])
    return problem.verify(outcome.unknowns, epsilon, verify_tol=verify_tol, stability_tol=stability_tol,
                          iterations=outcome.iterations, min_mode_share=min_mode_share)


# --------------------------------------------------------------------------- #
# continuation
# --------------------------------------------------------------------------- #
@dataclass(frozen=True)
class ContinuationProgress:
    """Passed to the continuation callback after every accepted point.

    Attributes
    ----------
    index : int
        Index of the point in the branch (0 = first).
    parameter : float
        Value of the continuation parameter.
    result : NNMResult
        The accepted point.
    step : float
        Current step (arclength for "arclength", parameter increment otherwise).
    flow_evaluations : int
        Flows used so far by the whole continuation.
    """

    index: int
    parameter: float
    result: NNMResult
    step: float
    flow_evaluations: int


@dataclass(frozen=True)
class NNMBranch:
    """A branch of NNMs from a continuation.

    Attributes
    ----------
    success : bool
        Whether the continuation reached ``stop``.
    stop_reason : str
        Why it stopped ("reached stop = …", "max_points …", "step size … below
        min_step …: <corrector failure>", "callback requested stop", "first
        point failed: …").
    method : str
        ``"arclength"``, ``"natural"`` or ``"seed"``.
    parameter : str
        ``"epsilon"``, ``"energy"`` or ``"modal_amplitude"``.
    points : tuple of NNMResult
        The accepted points in branch order.
    parameter_values : numpy.ndarray
        The parameter at each point.
    folds : tuple of int
        Indices k such that the parameter turns back between points k and k + 1.
    stability_changes : tuple of int
        Indices k such that stability differs between points k and k + 1.
    contact_changes : tuple of int
        Indices k such that contact (switches per period > 0) differs between points k and k + 1.
    flow_evaluations : int
        Total flow integrations (including rejected steps and verifications).
    newton_iterations : int
        Total corrector iterations (Newton or hybr).
    rejected_steps : int
        Steps that failed and were retried with a smaller step.
    wall_time : float
        Seconds.
    """

    success: bool
    stop_reason: str
    method: str
    parameter: str
    points: tuple[NNMResult, ...]
    parameter_values: np.ndarray
    folds: tuple[int, ...]
    stability_changes: tuple[int, ...]
    contact_changes: tuple[int, ...]
    flow_evaluations: int
    newton_iterations: int
    rejected_steps: int
    wall_time: float

    def __len__(self) -> int:
        return len(self.points)

    @property
    def frequencies(self) -> np.ndarray:
        """ω at each point."""
        return np.array([p.frequency for p in self.points])

    @property
    def epsilons(self) -> np.ndarray:
        """ε at each point."""
        return np.array([p.epsilon for p in self.points])

    @property
    def energies(self) -> np.ndarray:
        """Energy (:func:`nnm_energy`) at each point."""
        return np.array([p.energy for p in self.points])

    @property
    def stable(self) -> np.ndarray:
        """Stability flag at each point."""
        return np.array([bool(p.stable) for p in self.points])


def _branch_events(points: Sequence[NNMResult], values: Sequence[float]) -> tuple[tuple[int, ...], ...]:
    folds, stability, contact = [], [], []
    increments = np.diff(np.asarray(values, dtype=float))
    for k in range(len(increments) - 1):
        if increments[k] * increments[k + 1] < 0:
            folds.append(k + 1)
    for k in range(len(points) - 1):
        if points[k].stable != points[k + 1].stable:
            stability.append(k)
        if points[k].contact != points[k + 1].contact:
            contact.append(k)
    return tuple(folds), tuple(stability), tuple(contact)


class _Path:
    """Map the continuation parameter λ to (ε, amplitude) and back."""

    def __init__(self, parameter: str, amplitude: _Amplitude | None, epsilon: float | None):
        self.parameter = parameter
        self.amplitude = amplitude
        self.epsilon = epsilon

    def at(self, value: float) -> tuple[float, _Amplitude]:
        if self.parameter == "epsilon":
            return value, self.amplitude
        kind = "energy" if self.parameter == "energy" else "modal_amplitude"
        return self.epsilon, _Amplitude(kind, value)

    def derivative(self, out: dict[str, Any]) -> np.ndarray:
        return out["d_epsilon"] if self.parameter == "epsilon" else out["d_level"]


def _continuation_setup(system, mode, parameter, epsilon, energy, modal_amplitude, energy_per_epsilon, formulation,
                        release_sign):
    if parameter not in _PARAMETERS:
        raise ProblemError(f"parameter must be one of {_PARAMETERS}, got {parameter!r}")
    if parameter == "epsilon":
        if epsilon is not None:
            raise ProblemError("parameter='epsilon' varies ε: do not also pass epsilon=")
        problem = NNMShooting(system, mode, energy=energy, modal_amplitude=modal_amplitude,
                              energy_per_epsilon=energy_per_epsilon, formulation=formulation, release_sign=release_sign)
        return problem, _Path("epsilon", problem.amplitude, None)
    if epsilon is None:
        raise ProblemError(f"parameter={parameter!r} needs the fixed epsilon=")
    if energy is not None or modal_amplitude is not None or energy_per_epsilon is not None:
        raise ProblemError(f"parameter={parameter!r} varies the amplitude itself: do not pass energy=, "
                           "modal_amplitude= or energy_per_epsilon=")
    eps = _check_epsilon(epsilon)
    seed = {"energy": 1.0} if parameter == "energy" else {"modal_amplitude": 1.0}
    problem = NNMShooting(system, mode, formulation=formulation, release_sign=release_sign, **seed)
    return problem, _Path(parameter, None, eps)


def continue_nnm(
    system: UnilateralSystem,
    mode: int,
    *,
    start: float,
    stop: float,
    parameter: str = "epsilon",
    epsilon: float | None = None,
    energy: float | None = None,
    modal_amplitude: float | None = None,
    energy_per_epsilon: float | None = None,
    method: str = "arclength",
    formulation: str = "symmetric",
    step: float | None = None,
    min_step: float | None = None,
    max_step: float | None = None,
    max_points: int = 500,
    max_halvings: int = 12,
    release_sign: int = 1,
    tol: float = 1e-11,
    verify_tol: float = 1e-8,
    stability_tol: float = 1e-6,
    max_iterations: int = 12,
    callback: Callable[[ContinuationProgress], bool | None] | None = None,
) -> NNMBranch:
    """Follow the NNM of ``mode`` from ``parameter = start`` to ``stop``.

    Parameters
    ----------
    system : UnilateralSystem
    mode : int
        1-based mode number j.
    start, stop : float
        Range of the continuation parameter.  The first point is solved from
        the linear mode j (exactly the linear mode at ε = 0).
    parameter : {"epsilon", "energy", "modal_amplitude"}
        What varies.  ``"epsilon"`` needs one amplitude (``energy``,
        ``modal_amplitude`` or ``energy_per_epsilon``, the seed's E = c ε);
        the others need the fixed ``epsilon``.
    method : {"arclength", "natural", "seed"}
        ``"arclength"``: pseudo-arclength — unknowns ``w = (z, λ)``, predictor
        ``w + h t`` along the unit tangent ``t`` (null vector of the exact
        augmented Jacobian ``[∂G/∂z, ∂G/∂λ]``, oriented as the previous one),
        corrector: Newton on ``[G(w); tᵀ(w − w_k) − h] = 0`` in scaled
        variables (λ by ``|stop − start|``, X by the orbit amplitude, T by the
        period).  Step control: ×1.5 after ≤ 2 corrector iterations, ×0.6
        after ≥ 5, halved after a failure or a turn of the tangent by more than
        ~25°; the last point is solved at exactly ``λ = stop``.
        ``"natural"``: parameter steps with the previous solution (secant
        extrapolated) as guess and Newton at fixed λ, halving on failure.
        ``"seed"``: the seed's algorithm — natural continuation in ε with
        constant increment ``step``, halved on failure, solving the seed's
        square residual ``[X(T) − X0, X'(T) − X1, E − c ε]`` (unknowns X0, X1,
        T) by ``scipy.optimize.root(method="hybr")`` without Jacobian; only
        ``parameter="epsilon"`` with ``energy`` or ``energy_per_epsilon``.
    formulation : {"symmetric", "full"}
        Shooting residual of the "arclength" and "natural" methods.
    step : float, optional
        Initial step: scaled arclength (default 1/50 of the range) for
        "arclength", parameter increment (default range/50) otherwise.
    min_step, max_step : float, optional
        Bounds of the step (default: step / 2**max_halvings and 4 × step).
    max_points : int
        Stop after this many points.
    max_halvings : int
        Failure halvings allowed before stopping ("natural", "seed").
    callback : callable, optional
        ``callback(ContinuationProgress)`` after every accepted point; return
        True to stop.
    tol, verify_tol, stability_tol, max_iterations
        As in :func:`nnm_point` (``max_iterations`` per corrector).

    Returns
    -------
    NNMBranch

    Examples
    --------
    >>> branch = continue_nnm(UnilateralSystem.one_dof(1), 1, modal_amplitude=1.0, start=0.0, stop=1.0, step=0.2)
    >>> branch.success, len(branch) > 4, float(branch.parameter_values[-1])
    (True, True, 1.0)
    >>> abs(float(branch.frequencies[-1]) - 2 * 2**0.5 / (1 + 2**0.5)) < 1e-12   # bilinear oscillator, ε = 1
    True
    """
    if method not in ("arclength", "natural", "seed"):
        raise ProblemError(f"method must be 'arclength', 'natural' or 'seed', got {method!r}")
    start, stop = float(start), float(stop)
    if not (math.isfinite(start) and math.isfinite(stop)) or start == stop:
        raise ProblemError(f"start and stop must be finite and different, got {start}, {stop}")
    if max_points < 2:
        raise ProblemError(f"max_points must be at least 2, got {max_points}")
    problem, path = _continuation_setup(system, mode, parameter, epsilon, energy, modal_amplitude, energy_per_epsilon,
                                        formulation, release_sign)
    if method == "seed":
        if parameter != "epsilon" or path.amplitude.kind == "modal_amplitude":
            raise ProblemError("method='seed' is the seed's algorithm: parameter='epsilon' with energy= or "
                               "energy_per_epsilon=")
        return _continue_seed(problem, path, start, stop, step, max_points, max_halvings, tol, verify_tol,
                              stability_tol, callback)
    options = dict(tol=tol, verify_tol=verify_tol, stability_tol=stability_tol, max_iterations=max_iterations)
    if method == "natural":
        return _continue_natural(problem, path, start, stop, step, max_points, max_halvings, options, callback)
    return _continue_arclength(problem, path, start, stop, step, min_step, max_step, max_points, max_halvings,
                               options, callback)


def _first_point(problem: NNMShooting, path: _Path, value: float, options: dict[str, Any]) -> NNMResult:
    eps, amplitude = path.at(value)
    impossible = _impossible_amplitude(problem, eps, amplitude)
    if impossible:
        return _failed(problem.mode, eps, problem.linear_frequency, problem.n, impossible, problem.formulation, 0,
                       problem.flow_evaluations)
    x0, _ = problem._guess_amplitude(eps, amplitude)
    period = _TWO_PI / problem.linear_frequency
    z0 = np.r_[x0, period] if problem.formulation == "symmetric" else np.r_[x0, np.zeros(problem.n), period]
    return _solve_fixed(problem, path, value, z0, options, min_mode_share=0.5)


def _solve_fixed(problem: NNMShooting, path: _Path, value: float, z0: np.ndarray, options: dict[str, Any],
                 min_mode_share: float | None = None) -> NNMResult:
    eps, amplitude = path.at(value)
    x_guess, _, period_guess = problem.split(z0)
    problem.set_scales(eps, x_guess if np.max(np.abs(x_guess)) > 0 else None, period_guess, amplitude)
    outcome = _newton(lambda z: problem.evaluate(z, eps, amplitude=amplitude), z0, problem.column_scales(),
                      tol=options["tol"], max_iterations=options["max_iterations"])
    if not outcome.success:
        return _failed(problem.mode, eps, problem.linear_frequency, problem.n, outcome.message, problem.formulation,
                       outcome.iterations, problem.flow_evaluations)
    return problem.verify(outcome.unknowns, eps, verify_tol=options["verify_tol"],
                          stability_tol=options["stability_tol"], iterations=outcome.iterations, amplitude=amplitude,
                          min_mode_share=min_mode_share)


def _unknowns_of(problem: NNMShooting, result: NNMResult) -> np.ndarray:
    if problem.formulation == "symmetric":
        return np.r_[result.release_position, result.period]
    return np.r_[result.release_position, result.release_velocity, result.period]


def _finish(problem, path, method, points, values, stop_reason, success, rejected, started, iterations) -> NNMBranch:
    folds, stability, contact = _branch_events(points, values)
    return NNMBranch(
        success=success, stop_reason=stop_reason, method=method, parameter=path.parameter, points=tuple(points),
        parameter_values=np.array(values, dtype=float), folds=folds, stability_changes=stability,
        contact_changes=contact, flow_evaluations=problem.flow_evaluations, newton_iterations=iterations,
        rejected_steps=rejected, wall_time=time.perf_counter() - started,
    )


def _notify(callback, index, value, result, step, flows) -> bool:
    if callback is None:
        return False
    return bool(callback(ContinuationProgress(index, value, result, step, flows)))


def _continue_natural(problem, path, start, stop, step, max_points, max_halvings, options, callback) -> NNMBranch:
    started = time.perf_counter()
    direction = 1.0 if stop > start else -1.0
    increment = abs(step) if step else abs(stop - start) / 50.0
    first = _first_point(problem, path, start, options)
    if not first.success:
        return _finish(problem, path, "natural", [], [], f"first point failed: {first.message}", False, 0, started,
                       first.newton_iterations)
    points, values = [first], [start]
    iterations, rejected, halvings = first.newton_iterations, 0, 0
    if _notify(callback, 0, start, first, increment, problem.flow_evaluations):
        return _finish(problem, path, "natural", points, values, "callback requested stop", False, 0, started, iterations)
    while True:
        if len(points) >= max_points:
            return _finish(problem, path, "natural", points, values, f"max_points = {max_points} reached at "
                           f"{path.parameter} = {values[-1]:.6g}", False, rejected, started, iterations)
        target = values[-1] + direction * increment
        if direction * (target - stop) > -1e-9 * abs(stop - start):  # never leave a sliver before stop
            target = stop
        guess = _unknowns_of(problem, points[-1])
        if len(points) >= 2:  # secant extrapolation
            previous = _unknowns_of(problem, points[-2])
            fraction = (target - values[-1]) / (values[-1] - values[-2])
            guess = guess + fraction * (guess - previous)
        result = _solve_fixed(problem, path, target, guess, options)
        iterations += result.newton_iterations
        if not result.success:
            rejected += 1
            halvings += 1
            increment *= 0.5
            if halvings > max_halvings:
                return _finish(problem, path, "natural", points, values,
                               f"step halved {max_halvings} times without convergence at {path.parameter} = "
                               f"{target:.6g}: {result.message}", False, rejected, started, iterations)
            continue
        halvings = 0
        points.append(result)
        values.append(target)
        if _notify(callback, len(points) - 1, target, result, increment, problem.flow_evaluations):
            return _finish(problem, path, "natural", points, values, "callback requested stop", False, rejected,
                           started, iterations)
        if target == stop:
            return _finish(problem, path, "natural", points, values, f"reached stop = {stop:g}", True, rejected,
                           started, iterations)


def _continue_arclength(problem, path, start, stop, step, min_step, max_step, max_points, max_halvings, options,
                        callback) -> NNMBranch:
    started = time.perf_counter()
    span = abs(stop - start)
    direction = 1.0 if stop > start else -1.0
    h = abs(step) if step else 1.0 / 50.0
    h_max = abs(max_step) if max_step else 4.0 * h
    h_min = abs(min_step) if min_step else h / 2.0**max_halvings
    first = _first_point(problem, path, start, options)
    if not first.success:
        return _finish(problem, path, "arclength", [], [], f"first point failed: {first.message}", False, 0, started,
                       first.newton_iterations)
    points, values = [first], [start]
    iterations, rejected = first.newton_iterations, 0
    if _notify(callback, 0, start, first, h, problem.flow_evaluations):
        return _finish(problem, path, "arclength", points, values, "callback requested stop", False, 0, started,
                       iterations)

    def scales_at(result: NNMResult, value: float) -> np.ndarray:
        eps, amplitude = path.at(value)
        problem.set_scales(eps, result.release_position, result.period, amplitude)
        return np.r_[problem.column_scales(), span]

    def augmented(w: np.ndarray) -> dict[str, Any]:
        eps, amplitude = path.at(float(w[-1]))
        out = problem.evaluate(w[:-1], eps, amplitude=amplitude, d_epsilon=path.parameter == "epsilon")
        if out["success"]:
            out["augmented"] = np.column_stack([out["jacobian"], path.derivative(out)])
        return out

    def tangent_of(matrix: np.ndarray, scales: np.ndarray, previous: np.ndarray | None) -> np.ndarray:
        """Unit null vector (scaled variables) of the augmented Jacobian, oriented like ``previous``."""
        vector = np.linalg.svd(matrix * scales[None, :])[2][-1]
        if previous is not None:
            if float(vector @ previous) < 0:
                vector = -vector
        elif vector[-1] * direction < 0:
            vector = -vector
        return vector / np.linalg.norm(vector)

    w = np.r_[_unknowns_of(problem, first), start]
    scales = scales_at(first, start)
    out = augmented(w)
    if not out["success"]:
        return _finish(problem, path, "arclength", points, values, f"tangent failed: {out['message']}", False, 0,
                       started, iterations)
    tangent = tangent_of(out["augmented"], scales, None)
    while True:
        if len(points) >= max_points:
            return _finish(problem, path, "arclength", points, values, f"max_points = {max_points} reached at "
                           f"{path.parameter} = {values[-1]:.6g}", False, rejected, started, iterations)
        predictor = w + h * tangent * scales

        def corrector_evaluate(candidate: np.ndarray) -> dict[str, Any]:
            out = augmented(candidate)
            if out["success"]:
                constraint = float(tangent @ ((candidate - w) / scales)) - h
                out["residual"] = np.r_[out["residual"], constraint]
                out["jacobian_aug"] = np.vstack([out["augmented"], tangent / scales])
            return out

        outcome = _newton(corrector_evaluate, predictor, scales, tol=options["tol"],
                          max_iterations=options["max_iterations"], jacobian_key="jacobian_aug")
        iterations += outcome.iterations
        accepted = False
        reason = outcome.message
        if outcome.success:
            candidate = outcome.unknowns
            value = float(candidate[-1])
            if direction * (value - start) < 0:
                return _finish(problem, path, "arclength", points, values,
                               f"the branch turned back past start = {start:g} (folds of the branch in "
                               f"{path.parameter}; see NNMBranch.folds)", False, rejected, started, iterations)
            if direction * (value - stop) >= 0:  # crossed stop: land exactly on it, from the interpolated guess
                fraction = (stop - values[-1]) / (value - values[-1])
                guess = w[:-1] + fraction * (candidate[:-1] - w[:-1])
                result = _solve_fixed(problem, path, stop, guess, options)
                iterations += result.newton_iterations
                if result.success:
                    points.append(result)
                    values.append(stop)
                    _notify(callback, len(points) - 1, stop, result, h, problem.flow_evaluations)
                    return _finish(problem, path, "arclength", points, values, f"reached stop = {stop:g}", True,
                                   rejected, started, iterations)
                reason = f"final point at stop failed: {result.message}"
            else:
                eps, amplitude = path.at(value)
                result = problem.verify(candidate[:-1], eps, verify_tol=options["verify_tol"],
                                        stability_tol=options["stability_tol"], iterations=outcome.iterations,
                                        amplitude=amplitude)
                if result.success:
                    # tangent at the new point from the corrector's last Jacobian (no extra flow)
                    new_scales = scales_at(result, value)
                    previous = tangent * scales / new_scales
                    previous /= np.linalg.norm(previous)
                    new_tangent = tangent_of(outcome.last["augmented"], new_scales, previous)
                    turn = float(new_tangent @ previous)
                    if turn >= 0.9 or h <= h_min:
                        accepted = True
                    else:
                        reason = f"the tangent turned too much (cos = {turn:.3f})"
                else:
                    reason = result.message
        if not accepted:
            rejected += 1
            h *= 0.5
            if h < h_min:
                return _finish(problem, path, "arclength", points, values,
                               f"step size {h:.2e} below min_step {h_min:.2e} at {path.parameter} = {values[-1]:.6g}: "
                               f"{reason}", False, rejected, started, iterations)
            continue
        points.append(result)
        values.append(value)
        w, scales, tangent = candidate, new_scales, new_tangent
        if _notify(callback, len(points) - 1, value, result, h, problem.flow_evaluations):
            return _finish(problem, path, "arclength", points, values, "callback requested stop", False, rejected,
                           started, iterations)
        if outcome.iterations <= 2:
            h = min(1.5 * h, h_max)
        elif outcome.iterations >= 5:
            h = max(0.6 * h, h_min)


# --------------------------------------------------------------------------- #
# the seed's algorithm (baseline)
# --------------------------------------------------------------------------- #
def _seed_residual(problem: NNMShooting, eps: float, amplitude: _Amplitude, unknowns: np.ndarray) -> np.ndarray:
    """The seed's F(ε, X0, X1, T) = [X(T) − X0, X'(T) − X1, E(X0, X1) − c ε], scaled (no phase condition)."""
    n = problem.n
    x0, v0, period = unknowns[:n], unknowns[n:2 * n], float(unknowns[2 * n])
    if not (math.isfinite(period) and period > 0) or not np.all(np.isfinite(unknowns)):
        return np.full(2 * n + 1, 1e6)
    problem.flow_evaluations += 1
    trajectory = _integrate(problem._flow(eps), x0, v0, period, sensitivity=False, d_epsilon=False)
    if not trajectory.success:
        return np.full(2 * n + 1, 1e6)
    energy = nnm_energy(problem.system, x0, v0, eps)
    return np.r_[
        (trajectory.position - x0) / problem.position_scale,
        (trajectory.velocity - v0) / problem.velocity_scale,
        (energy - amplitude.target(eps)) / problem.amplitude_scale,
    ]


def _seed_solve(problem, path, value, guess, tol, verify_tol, stability_tol) -> NNMResult:
    eps, amplitude = path.at(value)
    n = problem.n
    problem.set_scales(eps, guess[:n] if np.max(np.abs(guess[:n])) > 0 else None, float(guess[2 * n]), amplitude)
    impossible = _impossible_amplitude(problem, eps, amplitude)
    if impossible:
        return _failed(problem.mode, eps, problem.linear_frequency, n, impossible, "seed", 0, problem.flow_evaluations)
    columns = np.r_[np.full(n, problem.position_scale), np.full(n, problem.velocity_scale), problem.period_scale]
    solution = scipy.optimize.root(lambda y: _seed_residual(problem, eps, amplitude, y * columns), guess / columns,
                                   method="hybr", options={"xtol": 1e-12})
    unknowns = solution.x * columns
    norm = float(np.max(np.abs(_seed_residual(problem, eps, amplitude, unknowns))))
    iterations = int(solution.nfev)  # hybr has no Jacobian: its cost is its function evaluations
    if not norm <= verify_tol:
        return _failed(problem.mode, eps, problem.linear_frequency, n,
                       f"hybr did not converge (residual {norm:.1e}; {solution.message})", "seed", iterations,
                       problem.flow_evaluations)
    saved = problem.formulation
    problem.formulation = "full"
    try:
        return problem.verify(unknowns, eps, verify_tol=verify_tol, stability_tol=stability_tol, iterations=iterations,
                              amplitude=amplitude, formulation_label="seed")
    finally:
        problem.formulation = saved


def _continue_seed(problem, path, start, stop, step, max_points, max_halvings, tol, verify_tol, stability_tol,
                   callback) -> NNMBranch:
    """Natural continuation in ε, constant increment halved on failure, hybr without Jacobian."""
    started = time.perf_counter()
    direction = 1.0 if stop > start else -1.0
    delta = abs(step) if step else abs(stop - start) / 50.0
    n = problem.n
    eps0, amplitude0 = path.at(start)
    x0, _ = problem._guess_amplitude(eps0, amplitude0)
    guess = np.r_[x0, np.zeros(n), _TWO_PI / problem.linear_frequency]
    first = _seed_solve(problem, path, start, guess, tol, verify_tol, stability_tol)
    iterations = first.newton_iterations
    if not first.success:
        return _finish(problem, path, "seed", [], [], f"first point failed: {first.message}", False, 0, started,
                       iterations)
    points, values = [first], [start]
    rejected, halvings = 0, 0
    if _notify(callback, 0, start, first, delta, problem.flow_evaluations):
        return _finish(problem, path, "seed", points, values, "callback requested stop", False, 0, started, iterations)
    while True:
        if len(points) >= max_points:
            return _finish(problem, path, "seed", points, values, f"max_points = {max_points} reached at "
                           f"ε = {values[-1]:.6g}", False, rejected, started, iterations)
        target = values[-1] + direction * delta
        if direction * (target - stop) > -1e-9 * abs(stop - start):
            target = stop
        last = points[-1]
        guess = np.r_[last.release_position, last.release_velocity, last.period]
        result = _seed_solve(problem, path, target, guess, tol, verify_tol, stability_tol)
        iterations += result.newton_iterations
        if not result.success:
            rejected += 1
            halvings += 1
            delta *= 0.5
            if halvings > max_halvings:
                return _finish(problem, path, "seed", points, values,
                               f"step halved {max_halvings} times without convergence at ε = {target:.6g}: "
                               f"{result.message}", False, rejected, started, iterations)
            continue
        halvings = 0
        points.append(result)
        values.append(target)
        if _notify(callback, len(points) - 1, target, result, delta, problem.flow_evaluations):
            return _finish(problem, path, "seed", points, values, "callback requested stop", False, rejected, started,
                           iterations)
        if target == stop:
            return _finish(problem, path, "seed", points, values, f"reached stop = {stop:g}", True, rejected, started,
                           iterations)


# --------------------------------------------------------------------------- #
# sweeps
# --------------------------------------------------------------------------- #
def _sweep_task(value: float, *, system: UnilateralSystem, mode: int, parameter: str, epsilon: float | None,
                options: dict[str, Any]) -> NNMResult:
    if parameter == "epsilon":
        return nnm_point(system, value, mode, **options)
    key = "energy" if parameter == "energy" else "modal_amplitude"
    return nnm_point(system, epsilon, mode, **{key: value}, **options)


def nnm_sweep(
    system: UnilateralSystem,
    mode: int,
    values: Iterable[float],
    *,
    parameter: str = "epsilon",
    epsilon: float | None = None,
    executor: Executor | None = None,
    **options: Any,
) -> list[NNMResult]:
    """NNM points at many parameter values, optionally in parallel; results in input order.

    Each point is solved independently by :func:`nnm_point` from the linear
    mode (no continuation between points): use :func:`continue_nnm` for
    strongly nonlinear points, or pass ``initial_guess`` in ``options``.

    Parameters
    ----------
    system : UnilateralSystem
    mode : int
        1-based mode number.
    values : iterable of float
        ε values (``parameter="epsilon"``, give the amplitude in ``options``),
        energies (``"energy"``) or modal amplitudes (``"modal_amplitude"``) —
        then ``epsilon`` is fixed.
    executor : concurrent.futures.Executor, optional
        Any executor (thread or process pool); default: serial in this thread.
    **options
        Passed to :func:`nnm_point` (``energy=``, ``formulation=``, ``tol=``, …).

    Examples
    --------
    >>> from concurrent.futures import ThreadPoolExecutor
    >>> system = UnilateralSystem.one_dof(1)
    >>> with ThreadPoolExecutor(2) as pool:
    ...     results = nnm_sweep(system, 1, [0.1, 0.2, 0.3], modal_amplitude=1.0, executor=pool)
    >>> [round(r.frequency, 10) for r in results] == [round(2 * (1 + e)**0.5 / (1 + (1 + e)**0.5), 10) for e in (0.1, 0.2, 0.3)]
    True
    """
    if parameter not in _PARAMETERS:
        raise ProblemError(f"parameter must be one of {_PARAMETERS}, got {parameter!r}")
    if parameter == "epsilon" and epsilon is not None:
        raise ProblemError("parameter='epsilon' sweeps ε: do not also pass epsilon=")
    if parameter != "epsilon" and epsilon is None:
        raise ProblemError(f"parameter={parameter!r} needs the fixed epsilon=")
    values = [float(v) for v in values]
    task = partial(_sweep_task, system=system, mode=mode, parameter=parameter, epsilon=epsilon, options=options)
    if executor is None:
        return [task(v) for v in values]
    futures = [executor.submit(task, v) for v in values]
    return [future.result() for future in futures]
