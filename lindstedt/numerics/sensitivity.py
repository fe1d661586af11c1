"""Exact derivatives of the flow of ``M X'' + K X + ε W (A X − b)_+ = 0``: in the initial state and in ε.

The flow of the piecewise-linear system (:class:`lindstedt.numerics.ExactFlow`)
is a chain of closed-form arcs, one per contact state S, each a sum of
harmonics about the state's equilibrium.  Its derivatives are exact too:

* ``∂(X, X')(t)/∂(X0, V0)`` — the state transition matrix, the product of the
  arcs' transition matrices (the saltation matrices are the identity: the
  vector field is continuous across the switching surfaces); over one period
  it is the monodromy matrix;
* ``∂(X, X')(t)/∂ε`` — the solution z of the variational equation
  ``z' = J(t) z + (0, −M⁻¹ W (A X − b)_+)``, ``z(0) = 0``, whose forcing on each
  arc is a constant plus harmonics of the arc's own frequencies, so the
  Duhamel integral is summed in closed form (:func:`flow_epsilon_derivative`).

No finite differences are used.  These are the Jacobians of the NNM shooting
(:mod:`lindstedt.numerics.shooting`).

Examples
--------
>>> system = UnilateralSystem.one_dof(1)          # u'' + u + ε u_+ = 0
>>> state, sensitivity, d_eps = flow_epsilon_derivative(system, 2.0, [-1.0], [0.0], np.pi / 2)
>>> np.round(sensitivity + 0.0, 12).tolist(), float(d_eps[0])  # u = −cos t, no contact yet: the linear flow
([[0.0, 1.0], [-1.0, 0.0]], 0.0)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._errors import ConvergenceError, ProblemError
from .flow import ExactFlow
from ..problems.parsing import parse_float
from ..problems.system import UnilateralSystem

__all__ = ["flow_epsilon_derivative"]


def _check_epsilon(epsilon: Any) -> float:
    return parse_float(epsilon, what="epsilon")


@dataclass(frozen=True)
class _Trajectory:
    success: bool
    message: str
    position: np.ndarray
    velocity: np.ndarray
    sensitivity: np.ndarray | None  # ∂(X, V)(t) / ∂(X0, V0)
    d_epsilon: np.ndarray | None  # ∂(X, V)(t) / ∂ε
    n_switches: int
    springs: tuple[int, ...] = ()  # the springs that switch on [0, t], increasing


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
    springs = tuple(sorted({event.spring for event in run["events"]}))
    return _Trajectory(True, "", run["x"], run["v"], run["jacobian"] if sensitivity else None, derivative,
                       len(run["events"]), springs)


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
