"""NNM shooting for  M X'' + K X + ε Σ_i w_i f_i(a_iᵀ X − b_i) = 0 : the residual, its exact Jacobian, Newton, one orbit.

A nonlinear normal mode (NNM, in Rosenberg's sense) of mode j is a periodic
orbit that grows out of the linear mode ``φ_j`` (``K φ_j = λ_j² M φ_j``,
``Φᵀ M Φ = I``) as ε → 0 or as the amplitude → 0.  It is computed here by
*shooting*: unknown initial state and period, residuals evaluated with a flow,
and a Newton (Gauss–Newton) iteration whose Jacobian is exact — the state
transition matrix of the flow over T/2 or T (over a full period: the monodromy
matrix), the vector field at the end point for the derivative in T, and the
derivative in ε.  No finite differences are used.  Where every element is a
unilateral spring ``f_i = (·)_+``, or a continuous piecewise-linear law written as such springs
(:attr:`UnilateralSystem.ramp_equivalent`), the flow is the exact piecewise closed form
(:class:`lindstedt.numerics.ExactFlow`, its ∂/∂ε a closed-form Duhamel integral,
:mod:`lindstedt.numerics.sensitivity`); for any other law (``u**3``, a Hertz
contact ``Max(0, u)**(3/2)``, a gap with a jump …) it is DOP853 with its
variational equations, stopped at every breakpoint of every law (the saltation
matrices where a law jumps; :class:`lindstedt.numerics.SmoothForcedFlow`).

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

Newton and verification
-----------------------
The Newton iteration is damped (backtracking on the scaled residual), solves
in the least-squares sense with column scaling, and stops on a singular
Jacobian (a fold, a bifurcation or a degenerate amplitude) with that reason.
Every result is verified on its final state with one more flow over the full
period: the periodicity residual is recomputed, the period must be minimal (an
orbit of period T/m run m times is re-solved at T/m, ``NNMResult.minimal_periods``),
not collapsed (T above Yorke's bound 2π/L, L the Lipschitz constant of the flow)
and not the rest state, and the monodromy matrix gives the Floquet multipliers,
the trivial pair (flow direction, family tangent) deflated by construction; an
orbit that fails this check is never reported as a success.  A single solve also
rejects an orbit in which mode j does not carry at least half of the modal
energy, and the default route of :func:`nnm_point` keeps Newton from the linear
mode only near the linear mode — elsewhere the NNM is reached by continuation
from it (Newton from a distant guess can land on another periodic orbit).
Branches of orbits are followed by :mod:`lindstedt.numerics.continuation`.

Examples
--------
>>> from lindstedt.numerics import nnm_point      # the front end (lindstedt.numerics.continuation) of this module
>>> orbit = nnm_point(UnilateralSystem.one_dof(1), 1.0, 1, energy=0.5, formulation="full")
>>> orbit.success, round(orbit.frequency, 12) == round(2 * 2**0.5 / (1 + 2**0.5), 12)
(True, True)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, Callable

import numpy as np

from .._errors import ConvergenceError, ProblemError, UnsupportedNonlinearityError
from .flow import ExactFlow
from .forced_smooth import SmoothForcedFlow
from .newton import Evaluation, newton
from ..problems.parsing import parse_float
from ..problems.system import UnilateralSystem
from .results import NNMResult, _repetitions
from .sensitivity import _check_epsilon, _map_over

__all__ = ["NNMShooting", "nnm_energy"]

_TWO_PI = 2.0 * math.pi
_FORMULATIONS = ("symmetric", "full")
#: a scaled Newton step this small ends the iteration (the caller verifies the final state)
_STEP_TOL = 1e-7


# --------------------------------------------------------------------------- #
# energy and amplitude
# --------------------------------------------------------------------------- #
def nnm_energy(system: UnilateralSystem, x: Any, v: Any, epsilon: float) -> float:
    """The energy used to parametrise NNMs.

    ``W = Aᵀ``: the conserved energy ``½ X'ᵀ M X' + ½ Xᵀ K X + ε Σ_i V_i(a_iᵀ X − b_i)``, ``V_i = ∫_0^u f_i``
    (``½ (·)_+²`` for a unilateral spring; :meth:`UnilateralSystem.energy`).
    ``W ≠ Aᵀ`` (no conserved energy exists): the linear energy
    ``½ X'ᵀ M X' + ½ Xᵀ K X`` of the given state — for an NNM, of its release
    point.

    Examples
    --------
    >>> nnm_energy(UnilateralSystem.one_dof(1), [2.0], [1.0], 0.5)
    3.5
    >>> from lindstedt.numerics import seed_example_system
    >>> nnm_energy(seed_example_system(2), [1.0, 0.0], [0.0, 0.0], 0.5)
    1.0
    """
    x = np.asarray(x, dtype=float)
    v = np.asarray(v, dtype=float)
    value = 0.5 * float(v @ system.M @ v) + 0.5 * float(x @ system.K @ x)
    if system.symmetric_coupling and system.n_springs:
        value += float(epsilon) * float(np.sum(system._element_potentials(system.gaps(x))))
    return value


def _energy_gradient(
    system: UnilateralSystem, x: np.ndarray, v: np.ndarray, epsilon: float
) -> tuple[np.ndarray, np.ndarray, float]:
    """(∂E/∂x, ∂E/∂v, ∂E/∂ε) of :func:`nnm_energy`."""
    grad_x = system.K @ x
    d_eps = 0.0
    if system.symmetric_coupling and system.n_springs:
        gaps = system.gaps(x)
        grad_x = grad_x + epsilon * system.A.T @ system._element_forces(gaps)
        d_eps = float(np.sum(system._element_potentials(gaps)))
    return grad_x, system.M @ v, d_eps


def _unilateral_equilibrium(system: UnilateralSystem, epsilon: float) -> np.ndarray:
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


def _state_at(run: dict[str, Any], t: float) -> tuple[np.ndarray, np.ndarray]:
    """The state at time t of a dense run of :class:`ExactFlow` (its closed-form arc containing t)."""
    starts, modes, q0s, p0s = run["arcs"]
    index = max(int(np.searchsorted(np.array(starts, dtype=float), t, side="right")) - 1, 0)
    x, v = modes[index].evaluate(q0s[index], p0s[index], type(starts[index])(t) - starts[index])
    return np.asarray(x, dtype=float), np.asarray(v, dtype=float)


@dataclass(frozen=True)
class _Run:
    """One flow over a candidate period, as the verification reads it: the end state, the monodromy, the switch
    count and the elements switching, the state at any time of the period and (any law) the steepest slope of
    every element's law over the deformations met (None for unilateral springs: Yorke's bound is global)."""

    state: np.ndarray
    monodromy: np.ndarray
    switches: int
    elements: tuple[int, ...]
    state_at: Callable[[float], tuple[np.ndarray, np.ndarray]]
    slopes: np.ndarray | None = None


#: the verification samples an orbit of any law at this many equally spaced times (the range of its elements'
#: deformations, for Yorke's bound) and at T/m for m up to _PROBED_REPETITIONS (the minimal-period test)
_SAMPLES = 64
_PROBED_REPETITIONS = 16


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
        self._flows: dict[float, ExactFlow | SmoothForcedFlow] = {}
        self._expansions: dict[tuple[str, float], Any] = {}  # lindstedt.nnm per (amplitude kind, a0)
        self.flow_evaluations = 0
        self.set_scales(epsilon=0.0)

    def __getstate__(self) -> dict[str, Any]:
        """Pickled without its caches of flows and expansions (rebuilt on demand)."""
        state = dict(self.__dict__)
        state["_flows"], state["_expansions"] = {}, {}
        return state

    # ------------------------------------------------------------------ scales
    def _guess_amplitude(self, epsilon: float, amplitude: _Amplitude | None = None) -> tuple[np.ndarray, float]:
        """Release position of the linear-mode guess and its modal amplitude."""
        amplitude = amplitude or self.amplitude
        equilibrium = self.equilibrium(epsilon)
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
    def _flow(self, epsilon: float) -> ExactFlow | SmoothForcedFlow:
        """The flow at ε: exact for unilateral springs and their ramp sums, DOP853 with variational equations for any
        other law."""
        flow = self._flows.get(epsilon)
        if flow is None:
            if len(self._flows) > 8:
                self._flows.clear()
            exact = self.system.ramp_equivalent  # unilateral springs, or continuous piecewise-linear laws as ramps
            flow = self._flows[epsilon] = (ExactFlow(exact[0], epsilon) if exact is not None
                                           else SmoothForcedFlow(self.system, epsilon))
        return flow

    def equilibrium(self, epsilon: float) -> np.ndarray:
        """The static equilibrium about which the NNMs oscillate: active sets for unilateral springs, the core
        Newton from X = 0 on the elements' laws otherwise (:meth:`SmoothForcedFlow.static_equilibrium`)."""
        exact = self.system.ramp_equivalent
        if exact is not None:
            return _unilateral_equilibrium(exact[0], epsilon)
        return self._flow(epsilon).static_equilibrium()

    def initial_guess(self, epsilon: float) -> np.ndarray:
        """Unknowns of the linear mode j with the requested amplitude (period 2π/λ_j)."""
        return self._linear_guess(_check_epsilon(epsilon))

    def _linear_guess(self, epsilon: float, amplitude: _Amplitude | None = None) -> np.ndarray:
        """:meth:`initial_guess` for another amplitude condition (default: this problem's)."""
        x0, _ = self._guess_amplitude(epsilon, amplitude)
        return self._join(x0, np.zeros(self.n), _TWO_PI / self.linear_frequency)

    def _join(self, x0: np.ndarray, v0: np.ndarray, period: float) -> np.ndarray:
        """The unknown vector of (X0, X1, T): the inverse of :meth:`split`."""
        if self.formulation == "symmetric":
            return np.r_[x0, period]
        return np.r_[x0, v0, period]

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
        ``d_level`` (∂residual/∂amplitude value), ``sensitivity`` (``∂z(t)/∂z0``
        over the flown time, T/2 or T), ``success``, ``message``, ``n_switches``.
        """
        epsilon = _check_epsilon(epsilon)
        amplitude = amplitude or self.amplitude
        x0, v0, period = self.split(unknowns)
        n = self.n
        if not (math.isfinite(period) and period > 0) or not (np.all(np.isfinite(x0)) and np.all(np.isfinite(v0))):
            return {"success": False, "message": f"the iterate left the admissible set (T = {period:.6g})"}
        horizon = 0.5 * period if self.formulation == "symmetric" else period
        self.flow_evaluations += 1
        trajectory = _map_over(self._flow(epsilon), x0, v0, horizon, sensitivity=jacobian, d_epsilon=d_epsilon)
        if isinstance(trajectory, str):
            return {"success": False, "message": trajectory}
        amp_value, amp_x, amp_v, amp_eps = self._amplitude_row(x0, v0, epsilon, amplitude)
        xs, vs, As = self.position_scale, self.velocity_scale, self.amplitude_scale
        if self.formulation == "symmetric":
            residual = np.r_[trajectory.state[n:] / vs, amp_value / As]
        else:
            residual = np.r_[
                (trajectory.state[:n] - x0) / xs,
                (trajectory.state[n:] - v0) / vs,
                amp_value / As,
                float(self.modal_row @ v0) / vs,
            ]
        out: dict[str, Any] = {"success": True, "message": "", "residual": residual, "n_switches": trajectory.counters["switches"],
                               "end_position": trajectory.state[:n], "end_velocity": trajectory.state[n:]}
        if jacobian or d_epsilon:
            acceleration = self.system.acceleration(trajectory.state[:n], epsilon)
        if jacobian:
            S = out["sensitivity"] = trajectory.d_state
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
                J[:n, 2 * n] = trajectory.state[n:] / xs
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
        # only the amplitude row depends on the amplitude value
        d_level = np.zeros(len(residual))
        d_level[n if self.formulation == "symmetric" else 2 * n] = -amplitude.d_target_d_value(epsilon) / As
        out["d_level"] = d_level
        return out

    def _evaluation(self, unknowns: np.ndarray, epsilon: float, amplitude: _Amplitude | None) -> Evaluation:
        """:meth:`evaluate` for the core's Newton."""
        out = self.evaluate(unknowns, epsilon, amplitude=amplitude)
        if not out["success"]:
            return Evaluation(False, out["message"])
        return Evaluation(True, "", out["residual"], out["jacobian"], data=out)

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

    def shortest_period(self, epsilon: float, slopes: Any = None) -> float:
        """A lower bound ``2π / L`` of the period of every non-constant periodic orbit at ε (Yorke, 1969).

        ``L`` bounds the Lipschitz constant of the vector field ``(X, X') ↦ (X', −M⁻¹(K X + ε Σ_i w_i f_i(u_i)))``
        in the norm ``|(√κ X, X')|``: where every law's slope obeys ``|f_i'| ≤ s_i`` the tangent stiffness obeys
        ``‖M⁻¹ K_T‖ ≤ κ = ‖M⁻¹ K‖ + |ε| Σ_i s_i ‖M⁻¹ w_i‖ ‖a_i‖``, so ``L ≤ √κ``.  A shooting solution with a shorter
        period is a collapse of the iteration (T → 0 solves the half-period equations), never an orbit.

        ``slopes`` are the ``s_i``: 1 for unilateral springs (the default, a global bound); for other laws the
        steepest slope over the deformations an orbit reaches (:meth:`SmoothForcedFlow.steepest_slopes`), a bound
        for the periodic orbits in that range (Yorke's proof uses the field at the orbit's points only).  A law that
        jumps (slope ``inf``) has no Lipschitz constant: the bound is 0.

        Examples
        --------
        >>> problem = NNMShooting(UnilateralSystem.one_dof(1), 1, modal_amplitude=1.0)
        >>> bool(problem.shortest_period(3.0) == np.pi)   # κ = 1 + 3: L = 2; the bilinear orbit has T = 3π/2
        True
        """
        exact = self.system.ramp_equivalent
        system = exact[0] if exact is not None and slopes is None else self.system
        stiffness = float(np.linalg.norm(np.linalg.solve(system.M, system.K), 2))
        if system.n_springs and epsilon != 0:
            steepest = np.ones(system.n_springs) if slopes is None else np.abs(np.asarray(slopes, dtype=float))
            loads = np.linalg.solve(system.M, system.W)
            stiffness += abs(epsilon) * float(np.sum(steepest * np.linalg.norm(loads, axis=0)
                                                     * np.linalg.norm(system.A, axis=1)))
        return _TWO_PI / math.sqrt(stiffness)

    def floquet(self, monodromy: np.ndarray, flow_vector: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(trivial pair, non-trivial multipliers) of an autonomous periodic orbit's monodromy matrix.

        The flow direction ``f`` and the family tangent ``ξ`` span a plane the monodromy ``Φ`` maps into itself
        (``Φ f = f``; ``Φ ξ = ξ − T' f`` along the family): their pair is ``(f, 0)`` and ``(ξ, T')`` of the
        two-dimensional null space of ``[Φ − I, f]``, taken as its two smallest right singular vectors.  With U an
        orthonormal basis of that plane and Q of its orthogonal complement, ``Φ`` is block triangular in (U, Q):
        the trivial pair are the eigenvalues of ``Uᵀ Φ U`` and the non-trivial multipliers those of ``Qᵀ Φ Q``
        (sorted by distance to 1) — deflated by construction, not by their distance to 1.

        Examples
        --------
        Two uncoupled oscillators ``λ = 1, 2`` over ``T = 2π``: the monodromy is the identity, the trivial pair
        belongs to the mode carrying the orbit (flow vector in its plane), the other pair is non-trivial:

        >>> problem = NNMShooting(UnilateralSystem(M=[[1, 0], [0, 1]], K=[[1, 0], [0, 4]]), 1, modal_amplitude=1.0)
        >>> trivial, nontrivial = problem.floquet(np.eye(4), np.array([0.0, 0.0, -1.0, 0.0]))
        >>> np.round(trivial.real, 12).tolist(), np.round(nontrivial.real, 12).tolist()
        ([1.0, 1.0], [1.0, 1.0])
        """
        size = monodromy.shape[0]
        bordered = np.column_stack([monodromy - np.eye(size), flow_vector / max(float(np.linalg.norm(flow_vector)),
                                                                                 np.finfo(float).tiny)])
        plane = np.linalg.svd(bordered)[2][-2:, :size].T
        basis = np.linalg.qr(plane, mode="complete")[0]
        U, Q = basis[:, :2], basis[:, 2:]
        trivial = np.linalg.eigvals(U.T @ monodromy @ U)
        nontrivial = np.linalg.eigvals(Q.T @ monodromy @ Q) if size > 2 else np.array([], dtype=complex)
        nontrivial = nontrivial[np.argsort(np.abs(nontrivial - 1.0), kind="stable")]
        return trivial.astype(complex), nontrivial.astype(complex)

    def monodromy_of(self, evaluation: dict[str, Any]) -> np.ndarray:
        """The monodromy matrix from an evaluation's sensitivity, without another flow.

        The full formulation flows over T: its sensitivity is the monodromy.  The symmetric one flows over T/2
        from rest; the system is reversible (``R = diag(I, −I)``, ``φ_{−t} = R φ_t R``) and the orbit turns at
        rest at T/2, so the second half-period is the first one reversed and ``Φ(T) = R S⁻¹ R S``,
        S = ``∂z(T/2)/∂z0``.
        """
        S = evaluation["sensitivity"]
        if self.formulation != "symmetric":
            return S
        n = self.n
        reverse = np.r_[np.ones(n), -np.ones(n)]
        return reverse[:, None] * np.linalg.solve(S, reverse[:, None] * S)

    def verify(self, unknowns: np.ndarray, epsilon: float, *, verify_tol: float, stability_tol: float,
               iterations: int, amplitude: _Amplitude | None = None, formulation_label: str | None = None,
               min_mode_share: float | None = None, note: str = "") -> NNMResult:
        """One flow over the full period: periodicity, minimal period, monodromy, Floquet multipliers.

        A success is the right orbit: the state returns after T (``verify_tol``), the amplitude condition holds,
        T is above the shortest possible period (:meth:`shortest_period`; a collapse T → 0 is not an orbit), the
        release state is not the equilibrium, and T is the minimal period — an orbit of period T/m run m times
        (the same closed-form flow, the state at T/m back at the release state by the rule of
        :func:`~lindstedt.numerics.results._repetitions`) is a failure with ``minimal_periods = m`` (:meth:`_solve`
        re-solves it at T/m).  With ``min_mode_share``, an orbit whose mode-j share of the modal energy is below
        it is a failure too (Newton from a distant guess can land on another periodic orbit, e.g. a resonant one).
        The stability counts the non-trivial multipliers only (:meth:`floquet`).
        """
        amplitude = amplitude or self.amplitude
        label = formulation_label or self.formulation
        x0, v0, period = self.split(unknowns)
        if not (math.isfinite(period) and period > 0):
            return self._failure(epsilon, f"invalid period T = {period}", iterations, label=label, x0=x0)
        shortest = self.shortest_period(epsilon) if self.system.ramp_equivalent is not None else 0.0
        if period < shortest:
            return self._collapse(epsilon, period, shortest, note, iterations, label, x0)
        self.flow_evaluations += 1
        try:
            run = self._closed_run(epsilon, x0, v0, period)
        except (ProblemError, ConvergenceError) as error:
            return self._failure(epsilon, f"the flow failed: {error}", iterations, label=label, x0=x0)
        if run.slopes is not None:  # any law: Yorke's bound from the slopes over the deformations of this run
            shortest = self.shortest_period(epsilon, run.slopes)
            if period < shortest:
                return self._collapse(epsilon, period, shortest, note, iterations, label, x0)
        frequency = _TWO_PI / period
        equilibrium = self.equilibrium(epsilon)
        scale = max(float(np.max(np.abs(x0))), float(np.max(np.abs(v0))) / frequency, np.finfo(float).tiny)

        def distance(x: np.ndarray, v: np.ndarray) -> float:
            return max(float(np.max(np.abs(x - x0))), float(np.max(np.abs(v - v0))) / frequency) / scale

        residual = distance(run.state[:self.n], run.state[self.n:])
        switches, springs = run.switches, run.elements
        # the orbit is run m times in T only if m divides its switch count (and T/m is a possible period)
        longest = int(period // shortest) if shortest > 0 else _PROBED_REPETITIONS  # 0: a law jumps, no bound
        candidates = [m for m in range(2, longest + 1) if switches % m == 0]
        repetitions = _repetitions(candidates, lambda m: distance(*run.state_at(period / m)), residual)
        amp_value, _, _, _ = self._amplitude_row(x0, v0, epsilon, amplitude)
        amp_scale = max(abs(amplitude.target(epsilon)), self.amplitude_scale, np.finfo(float).tiny)
        amplitude_error = abs(amp_value) / amp_scale
        monodromy = run.monodromy
        flow_vector = np.r_[v0, self.system.acceleration(x0, epsilon)]
        trivial, nontrivial = self.floquet(monodromy, flow_vector)
        multipliers = np.r_[trivial, nontrivial]
        stable = bool(np.max(np.abs(nontrivial), initial=0.0) <= 1.0 + stability_tol)
        share, dominant = self.mode_share(x0, v0)
        at_rest = max(float(np.max(np.abs(x0 - equilibrium))), float(np.max(np.abs(v0))) / frequency) <= \
            1e-12 * max(float(np.max(np.abs(equilibrium))), 1.0)
        if not (residual <= verify_tol and amplitude_error <= verify_tol):
            success, message = False, (
                f"verification failed: periodicity residual {residual:.2e}, amplitude residual "
                f"{amplitude_error:.2e} over one full period (verify_tol = {verify_tol:.1e}){note}"
            )
        elif at_rest:
            success, message = False, (f"degenerate solution: the release state is the static equilibrium (the "
                                       f"amplitude collapsed), not a periodic orbit{note}")
        elif repetitions > 1:
            success, message = False, (
                f"not a minimal period: the state returns to the release state after T/{repetitions} = "
                f"{period / repetitions:.10g} ({switches // repetitions} switches), so this is an orbit of period "
                f"T/{repetitions} run {repetitions} times (ω would be reported {repetitions} times too small){note}"
            )
        elif min_mode_share is not None and share < min_mode_share:
            success, message = False, (
                f"converged to a periodic orbit that is not the NNM of mode {self.mode}: mode {dominant} carries "
                f"the most modal energy, mode {self.mode} only {share:.1%} (< {min_mode_share:.0%}); start closer "
                "(continue_nnm from the linear mode, or initial_guess=)"
            )
        else:
            success, message = True, (
                f"converged in {iterations} iterations, verified residual {residual:.1e}"
                f"{self._contact_words(x0, switches, epsilon)}{note}"
            )
        return NNMResult(
            success=success, message=message, mode=self.mode, epsilon=epsilon, frequency=frequency, period=period,
            linear_frequency=self.linear_frequency, release_position=np.array(x0), release_velocity=np.array(v0),
            modal_coordinates=self.projector @ x0, energy=self._energy_or_nan(x0, v0, epsilon),
            floquet_multipliers=multipliers, stable=stable, residual=residual, n_switches=switches,
            mode_share=share, formulation=label, newton_iterations=iterations,
            flow_evaluations=self.flow_evaluations, monodromy=monodromy, system=self.system,
            contact_springs=springs, minimal_periods=repetitions,
        )

    def _energy_or_nan(self, x0: np.ndarray, v0: np.ndarray, epsilon: float) -> float:
        """:func:`nnm_energy` of the release state, NaN where a law's potential has no closed form."""
        try:
            return nnm_energy(self.system, x0, v0, epsilon)
        except UnsupportedNonlinearityError:
            return math.nan

    def _closed_run(self, epsilon: float, x0: np.ndarray, v0: np.ndarray, period: float) -> _Run:
        """The flow over the period from (x0, v0) with its monodromy, dense (raises ConvergenceError if it fails)."""
        flow = self._flow(epsilon)
        n = self.n
        if isinstance(flow, ExactFlow):
            run = flow._run(x0, v0, period, dense=True, sensitivity=True)
            if not run["success"]:
                raise ConvergenceError(run["message"])
            elements = self.system.ramp_equivalent[1]  # the element each spring of the exact flow comes from
            return _Run(np.r_[run["x"], run["v"]], run["jacobian"], len(run["events"]),
                        tuple(sorted({elements[event.spring] for event in run["events"]})), lambda t: _state_at(run, t))
        fractions = {period * k / _SAMPLES for k in range(_SAMPLES)} | \
            {period / m for m in range(2, _PROBED_REPETITIONS + 1)}
        times = np.array(sorted(fractions))
        value, states, crossed = flow.run(np.r_[x0, v0], period, times)
        probes = {float(t): state for t, state in zip(times, states)}

        def state_at(t: float) -> tuple[np.ndarray, np.ndarray]:
            state = probes.get(float(t))
            if state is None:
                self.flow_evaluations += 1
                state = flow.advance(np.r_[x0, v0], t, sensitivity=False).state
            return state[:n], state[n:]

        gaps = self.system.gaps(states[:, :n])
        slopes = flow.steepest_slopes(np.min(gaps, axis=0), np.max(gaps, axis=0))
        return _Run(value.state, value.d_state, value.counters["switches"], crossed, state_at, slopes)

    def _collapse(self, epsilon: float, period: float, shortest: float, note: str, iterations: int,
                  label: str, x0: np.ndarray) -> NNMResult:
        return self._failure(epsilon, (
            f"degenerate solution: the period T = {period:.3g} collapsed below {shortest:.6g}, the shortest period "
            f"of any periodic orbit at ε = {epsilon:g} (2π/L, L the Lipschitz constant of the flow: Yorke's "
            f"bound){note}"), iterations, label=label, x0=x0)

    def _contact_words(self, x0: np.ndarray, switches: int, epsilon: float) -> str:
        """What the message says of an orbit without switches: free of every spring (the linear mode, ω = λ_j) or
        engaged on some springs all along (a linear mode of the stiffened system) — read from the release state."""
        if not self.system.unilateral:
            return ""  # other laws act without contact too (a cubic spring): no claim on the orbit's linearity
        if switches or not self.system.n_springs:
            return "" if switches else "; no contact along the orbit: it is the linear mode (ω = λ_j)"
        engaged = tuple(int(i) for i in np.flatnonzero(self.system.gaps(x0) > 0))
        if not engaged or epsilon == 0:
            return "; no contact along the orbit: it is the linear mode (ω = λ_j)"
        return (f"; permanent contact with spring(s) {', '.join(map(str, engaged))} (engaged at every instant, no "
                "switch): a linear mode of the stiffened system")

    def _failure(self, epsilon: float, message: str, iterations: int = 0, *, label: str | None = None,
                 x0: np.ndarray | None = None) -> NNMResult:
        """A failed :class:`NNMResult` (NaN orbit data; the release position x0 if known) with the flows used so far."""
        n = self.n
        nan = float("nan")
        return NNMResult(
            success=False, message=message, mode=self.mode, epsilon=epsilon, frequency=nan, period=nan,
            linear_frequency=self.linear_frequency,
            release_position=np.full(n, np.nan) if x0 is None else np.array(x0, dtype=float),
            release_velocity=np.full(n, np.nan), modal_coordinates=np.full(n, np.nan), energy=nan,
            floquet_multipliers=None, stable=None, residual=nan, n_switches=0, mode_share=nan,
            formulation=label or self.formulation, newton_iterations=iterations, flow_evaluations=self.flow_evaluations,
            system=self.system,
        )

    def _solve(self, z0: np.ndarray, epsilon: float, amplitude: _Amplitude | None = None, *, tol: float,
               max_iterations: int, verify_tol: float, stability_tol: float,
               min_mode_share: float | None = None) -> NNMResult:
        """Newton from the unknowns z0 at fixed (ε, amplitude), scaled by z0, then the full-period verification.

        A solution that is an orbit of period T/m run m times (:meth:`verify`) is re-solved once from its own
        release state at T/m; the result says so, or fails with both reasons.
        """
        options = dict(tol=tol, max_iterations=max_iterations, verify_tol=verify_tol, stability_tol=stability_tol,
                       min_mode_share=min_mode_share)
        first = self._solve_and_verify(z0, epsilon, amplitude, **options)
        m = first.minimal_periods
        if first.success or m == 1:
            return first
        guess = self._join(first.release_position, first.release_velocity, first.period / m)
        result = self._solve_and_verify(guess, epsilon, amplitude, **options)
        iterations = first.newton_iterations + result.newton_iterations
        if result.success:
            return replace(result, newton_iterations=iterations, message=(
                f"{result.message}; the first solution was this orbit run {m} times (period {first.period:.10g}), "
                f"re-solved at its minimal period T/{m}"))
        return replace(result, newton_iterations=iterations, message=(
            f"{first.message}; re-solving at T/{m} failed: {result.message}"))

    def _solve_and_verify(self, z0: np.ndarray, epsilon: float, amplitude: _Amplitude | None, *, tol: float,
                       max_iterations: int, verify_tol: float, stability_tol: float,
                       min_mode_share: float | None) -> NNMResult:
        x_guess, _, period_guess = self.split(z0)
        self.set_scales(epsilon, x_guess if np.max(np.abs(x_guess)) > 0 else None, period_guess, amplitude)
        outcome = newton(lambda z: self._evaluation(z, epsilon, amplitude), z0, self.column_scales(), tol=tol,
                         max_iterations=max_iterations, step_tol=_STEP_TOL)
        if not outcome.success:
            return self._failure(epsilon, outcome.message, outcome.iterations, x0=self.split(outcome.unknowns)[0])
        return self.verify(outcome.unknowns, epsilon, verify_tol=verify_tol, stability_tol=stability_tol,
                           iterations=outcome.iterations, amplitude=amplitude, min_mode_share=min_mode_share)
