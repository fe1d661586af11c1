"""Continuation of NNMs of  M X'' + K X + ε W (A X − b)_+ = 0 : one driver, three methods, and sweeps.

:func:`continue_nnm` follows the NNM of one mode in a parameter λ — ε, the
energy or the modal amplitude (:mod:`lindstedt.numerics.shooting` gives the
residual ``G(z; λ) = 0`` in the shooting unknowns z and its exact Jacobian).
One driver runs every method: it solves the first point from the linear mode,
then asks the method for the next point, counts rejected steps, reports
progress (:class:`~lindstedt.numerics.ContinuationProgress`) and assembles the
:class:`~lindstedt.numerics.NNMBranch` (folds, stability and contact changes).
The methods (``method=``, a small registry) differ only in how they step:

``"arclength"`` — pseudo-arclength continuation
    Unknowns ``w = (z, λ)``; predictor ``w + h t`` along the unit tangent t, the
    null vector of the exact augmented Jacobian ``[∂G/∂z, ∂G/∂λ]`` oriented as
    the previous one; corrector: Newton on ``[G(w); tᵀ(w − w_k) − h] = 0`` in
    scaled variables.  Step control on the corrector's iterations and the turn
    of the tangent; passes folds; the Floquet multipliers of every point give
    the stability along the branch; the last point is solved at exactly
    ``λ = stop``.
``"natural"`` — natural-parameter continuation
    λ steps with the secant-extrapolated previous solution as guess and Newton
    at fixed λ, the step halved on failure.
``"seed"`` — the seed's algorithm, kept as the baseline
    Natural continuation in ε with a constant increment halved on failure, and
    Powell's hybrid method without Jacobian (``scipy.optimize.root(method="hybr")``)
    on the seed's square residual ``[X(T) − X0, X'(T) − X1, E − c ε]`` (as
    printed it has no phase condition, so its Jacobian is singular along the
    orbit — hybr still converges to some point of it because the system is
    consistent).

:func:`nnm_sweep` solves independent points (:func:`~lindstedt.numerics.nnm_point`
at each parameter value, optionally on an executor), without continuation.

Examples
--------
>>> branch = continue_nnm(UnilateralSystem.one_dof(1), 1, modal_amplitude=1.0, start=0.0, stop=1.0, method="natural",
...                       step=0.25)
>>> branch.success, branch.parameter_values.tolist()
(True, [0.0, 0.25, 0.5, 0.75, 1.0])
"""

from __future__ import annotations

import math
import time
from abc import ABC, abstractmethod
from collections.abc import Callable, Iterable
from concurrent.futures import Executor
from dataclasses import dataclass
from functools import partial
from typing import Any

import numpy as np

from .._errors import ProblemError
from ..problems.system import UnilateralSystem
from .results import ContinuationProgress, NNMBranch, NNMResult, _branch_events
from .sensitivity import _check_epsilon, _integrate
from .shooting import (
    _TWO_PI,
    NNMShooting,
    _Amplitude,
    _impossible_amplitude,
    _newton,
    nnm_energy,
    nnm_point,
)

__all__ = ["continue_nnm", "nnm_sweep"]

_PARAMETERS = ("epsilon", "energy", "modal_amplitude")


# --------------------------------------------------------------------------- #
# the continuation parameter
# --------------------------------------------------------------------------- #
@dataclass(frozen=True)
class _Path:
    """Map the continuation parameter λ to (ε, amplitude) and back."""

    parameter: str
    amplitude: _Amplitude | None  # fixed, when λ = ε
    epsilon: float | None  # fixed, when λ is the energy or the modal amplitude

    def at(self, value: float) -> tuple[float, _Amplitude]:
        if self.parameter == "epsilon":
            return value, self.amplitude
        return self.epsilon, _Amplitude(self.parameter, value)

    def derivative(self, out: dict[str, Any]) -> np.ndarray:
        return out["d_epsilon"] if self.parameter == "epsilon" else out["d_level"]


def _check_parameter(parameter: str, epsilon: float | None, verb: str) -> None:
    """``parameter`` is one of :data:`_PARAMETERS`; ε is given exactly when it is not the one that ``verb``s."""
    if parameter not in _PARAMETERS:
        raise ProblemError(f"parameter must be one of {_PARAMETERS}, got {parameter!r}")
    if parameter == "epsilon" and epsilon is not None:
        raise ProblemError(f"parameter='epsilon' {verb} ε: do not also pass epsilon=")
    if parameter != "epsilon" and epsilon is None:
        raise ProblemError(f"parameter={parameter!r} needs the fixed epsilon=")


def _continuation_setup(system, mode, parameter, epsilon, energy, modal_amplitude, energy_per_epsilon, formulation,
                        release_sign):
    _check_parameter(parameter, epsilon, "varies")
    if parameter == "epsilon":
        problem = NNMShooting(system, mode, energy=energy, modal_amplitude=modal_amplitude,
                              energy_per_epsilon=energy_per_epsilon, formulation=formulation, release_sign=release_sign)
        return problem, _Path("epsilon", problem.amplitude, None)
    if energy is not None or modal_amplitude is not None or energy_per_epsilon is not None:
        raise ProblemError(f"parameter={parameter!r} varies the amplitude itself: do not pass energy=, "
                           "modal_amplitude= or energy_per_epsilon=")
    eps = _check_epsilon(epsilon)
    # the amplitude value is a placeholder: _Path.at sets it to λ at every point
    problem = NNMShooting(system, mode, formulation=formulation, release_sign=release_sign, **{parameter: 1.0})
    return problem, _Path(parameter, None, eps)


# --------------------------------------------------------------------------- #
# the entry point
# --------------------------------------------------------------------------- #
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
    if method == "seed" and (parameter != "epsilon" or path.amplitude.kind == "modal_amplitude"):
        raise ProblemError("method='seed' is the seed's algorithm: parameter='epsilon' with energy= or "
                           "energy_per_epsilon=")
    options = dict(tol=tol, verify_tol=verify_tol, stability_tol=stability_tol, max_iterations=max_iterations)
    stepper = _METHODS[method](problem, path, start, stop, step=step, min_step=min_step, max_step=max_step,
                               max_halvings=max_halvings, options=options)
    return _drive(stepper, start, stop, max_points, callback)


# --------------------------------------------------------------------------- #
# the driver
# --------------------------------------------------------------------------- #
@dataclass(frozen=True)
class _Attempt:
    """One step of a method: the accepted point, or why it was rejected, or why the branch ends.

    ``result`` is the accepted point at parameter ``value`` (None: rejected, for
    ``reason``); ``end`` ends the branch unsuccessfully; ``complete`` marks a
    point solved exactly at ``stop`` that completes the branch whatever the
    callback answers; ``iterations`` are the corrector iterations spent.
    """

    iterations: int
    value: float = math.nan
    result: NNMResult | None = None
    reason: str = ""
    end: str | None = None
    complete: bool = False


def _drive(stepper: _Stepper, start: float, stop: float, max_points: int,
           callback: Callable[[ContinuationProgress], bool | None] | None) -> NNMBranch:
    """Run one continuation method from ``start`` towards ``stop``: first point, steps, bookkeeping, the branch."""
    started = time.perf_counter()
    problem, path = stepper.problem, stepper.path

    def finish(points: list[NNMResult], values: list[float], stop_reason: str, success: bool, rejected: int,
               iterations: int) -> NNMBranch:
        folds, stability, contact = _branch_events(points, values)
        return NNMBranch(
            success=success, stop_reason=stop_reason, method=stepper.name, parameter=path.parameter,
            points=tuple(points), parameter_values=np.array(values, dtype=float), folds=folds,
            stability_changes=stability, contact_changes=contact, flow_evaluations=problem.flow_evaluations,
            newton_iterations=iterations, rejected_steps=rejected, wall_time=time.perf_counter() - started,
            system=problem.system,
        )

    def notify(index: int, value: float, result: NNMResult) -> bool:
        if callback is None:
            return False
        return bool(callback(ContinuationProgress(index, value, result, stepper.step, problem.flow_evaluations)))

    first = stepper.first(start)
    if not first.success:
        return finish([], [], f"first point failed: {first.message}", False, 0, first.newton_iterations)
    points, values = [first], [start]
    iterations, rejected = first.newton_iterations, 0
    if notify(0, start, first):
        return finish(points, values, "callback requested stop", False, 0, iterations)
    failure = stepper.begin(first, start)
    if failure:
        return finish(points, values, failure, False, 0, iterations)
    while True:
        if len(points) >= max_points:
            return finish(points, values, f"max_points = {max_points} reached at {stepper.label} = {values[-1]:.6g}",
                          False, rejected, iterations)
        attempt = stepper.advance(points, values)
        iterations += attempt.iterations
        if attempt.end is not None:
            return finish(points, values, attempt.end, False, rejected, iterations)
        if attempt.result is None:
            rejected += 1
            failure = stepper.reject(attempt, values)
            if failure:
                return finish(points, values, failure, False, rejected, iterations)
            continue
        points.append(attempt.result)
        values.append(attempt.value)
        requested = notify(len(points) - 1, attempt.value, attempt.result)
        if attempt.complete or (not requested and attempt.value == stop):
            return finish(points, values, f"reached stop = {stop:g}", True, rejected, iterations)
        if requested:
            return finish(points, values, "callback requested stop", False, rejected, iterations)
        stepper.accept(attempt)


class _Stepper(ABC):
    """A continuation method: the first point and how to step from the last accepted one.

    ``step`` is the current step (reported in the progress), ``label`` names the
    parameter in stop reasons.  :meth:`begin` may return a reason to end the
    branch; :meth:`reject` is told of a rejected attempt and may return one.
    """

    name = ""

    def __init__(self, problem: NNMShooting, path: _Path, start: float, stop: float, *, step: float | None,
                 min_step: float | None, max_step: float | None, max_halvings: int, options: dict[str, Any]) -> None:
        self.problem, self.path, self.start, self.stop = problem, path, start, stop
        self.direction = 1.0 if stop > start else -1.0
        self.span = abs(stop - start)
        self.max_halvings = max_halvings
        self.options = options
        self.step = abs(step) if step else self.default_step()
        # bounds of the step (the upper one is used by "arclength" only)
        self.h_min = abs(min_step) if min_step else self.step / 2.0**max_halvings
        self.h_max = abs(max_step) if max_step else 4.0 * self.step

    @property
    def label(self) -> str:
        return self.path.parameter

    def default_step(self) -> float:
        """The initial step when none is given: 1/50 of the parameter range."""
        return self.span / 50.0

    def first(self, value: float) -> NNMResult:
        """The first point, solved from the linear mode."""
        problem = self.problem
        eps, amplitude = self.path.at(value)
        impossible = _impossible_amplitude(problem, eps, amplitude)
        if impossible:
            return problem._failure(eps, impossible)
        return problem._solve(problem._linear_guess(eps, amplitude), eps, amplitude, min_mode_share=0.5, **self.options)

    def begin(self, first: NNMResult, value: float) -> str | None:
        return None

    @abstractmethod
    def advance(self, points: list[NNMResult], values: list[float]) -> _Attempt:
        """One attempted step from the accepted points."""

    @abstractmethod
    def reject(self, attempt: _Attempt, values: list[float]) -> str | None:
        """Adapt to a failed attempt; a reason ends the branch."""

    def accept(self, attempt: _Attempt) -> None:
        pass


# --------------------------------------------------------------------------- #
# natural-parameter continuation (and the seed's algorithm, below)
# --------------------------------------------------------------------------- #
class _Natural(_Stepper):
    """Fixed-λ solves at ``λ_k + step`` from the previous solution, the step halved on failure."""

    name = "natural"

    halvings = 0  # failures since the last accepted point

    def guess(self, points: list[NNMResult], values: list[float], target: float) -> np.ndarray:
        guess = _unknowns_of(self.problem, points[-1])
        if len(points) >= 2 and values[-1] != values[-2]:  # secant extrapolation
            previous = _unknowns_of(self.problem, points[-2])
            fraction = (target - values[-1]) / (values[-1] - values[-2])
            guess = guess + fraction * (guess - previous)
        return guess

    def solve(self, value: float, guess: np.ndarray) -> NNMResult:
        return self.problem._solve(guess, *self.path.at(value), **self.options)

    def advance(self, points: list[NNMResult], values: list[float]) -> _Attempt:
        target = values[-1] + self.direction * self.step
        if self.direction * (target - self.stop) > -1e-9 * abs(self.stop - self.start):  # never leave a sliver before stop
            target = self.stop
        result = self.solve(target, self.guess(points, values, target))
        if not result.success:
            return _Attempt(result.newton_iterations, target, reason=result.message)
        return _Attempt(result.newton_iterations, target, result)

    def reject(self, attempt: _Attempt, values: list[float]) -> str | None:
        self.halvings += 1
        self.step *= 0.5
        if self.halvings > self.max_halvings:
            return (f"step halved {self.max_halvings} times without convergence at {self.label} = "
                    f"{attempt.value:.6g}: {attempt.reason}")
        if self.step < self.h_min:  # accepted points reset the halvings: the step itself is bounded below
            return (f"step size {self.step:.2e} below min_step {self.h_min:.2e} at {self.label} = "
                    f"{attempt.value:.6g}: {attempt.reason}")
        return None

    def accept(self, attempt: _Attempt) -> None:
        self.halvings = 0


def _unknowns_of(problem: NNMShooting, result: NNMResult) -> np.ndarray:
    return problem._join(result.release_position, result.release_velocity, result.period)


# --------------------------------------------------------------------------- #
# pseudo-arclength continuation
# --------------------------------------------------------------------------- #
class _Arclength(_Stepper):
    """Predictor along the tangent of the branch, corrector with the arclength constraint, adaptive step."""

    name = "arclength"

    def default_step(self) -> float:
        """The initial step when none is given: 1/50 in scaled arclength (λ is scaled by the range)."""
        return 1.0 / 50.0

    def scales_at(self, result: NNMResult, value: float) -> np.ndarray:
        eps, amplitude = self.path.at(value)
        self.problem.set_scales(eps, result.release_position, result.period, amplitude)
        return np.r_[self.problem.column_scales(), self.span]

    def augmented(self, w: np.ndarray) -> dict[str, Any]:
        eps, amplitude = self.path.at(float(w[-1]))
        out = self.problem.evaluate(w[:-1], eps, amplitude=amplitude, d_epsilon=self.path.parameter == "epsilon")
        if out["success"]:
            out["augmented"] = np.column_stack([out["jacobian"], self.path.derivative(out)])
        return out

    def tangent_of(self, matrix: np.ndarray, scales: np.ndarray, previous: np.ndarray | None) -> np.ndarray:
        """Unit null vector (scaled variables) of the augmented Jacobian, oriented like ``previous``."""
        vector = np.linalg.svd(matrix * scales[None, :])[2][-1]
        if previous is not None:
            if float(vector @ previous) < 0:
                vector = -vector
        elif vector[-1] * self.direction < 0:
            vector = -vector
        return vector / np.linalg.norm(vector)

    def begin(self, first: NNMResult, value: float) -> str | None:
        self.w = np.r_[_unknowns_of(self.problem, first), value]
        self.scales = self.scales_at(first, value)
        out = self.augmented(self.w)
        if not out["success"]:
            return f"tangent failed: {out['message']}"
        self.tangent = self.tangent_of(out["augmented"], self.scales, None)
        return None

    def advance(self, points: list[NNMResult], values: list[float]) -> _Attempt:
        problem, path, options = self.problem, self.path, self.options
        w, scales, tangent, h = self.w, self.scales, self.tangent, self.step
        direction, start, stop = self.direction, self.start, self.stop
        predictor = w + h * tangent * scales

        def corrector_evaluate(candidate: np.ndarray) -> dict[str, Any]:
            out = self.augmented(candidate)
            if out["success"]:
                constraint = float(tangent @ ((candidate - w) / scales)) - h
                out["residual"] = np.r_[out["residual"], constraint]
                out["jacobian_aug"] = np.vstack([out["augmented"], tangent / scales])
            return out

        outcome = _newton(corrector_evaluate, predictor, scales, tol=options["tol"],
                          max_iterations=options["max_iterations"], jacobian_key="jacobian_aug")
        iterations = outcome.iterations
        if not outcome.success:
            return _Attempt(iterations, reason=outcome.message)
        candidate = outcome.unknowns
        value = float(candidate[-1])
        if direction * (value - start) < 0:
            return _Attempt(iterations, value, end=f"the branch turned back past start = {start:g} (folds of the "
                            f"branch in {path.parameter}; see NNMBranch.folds)")
        if direction * (value - stop) >= 0:  # crossed stop: land exactly on it, from the interpolated guess
            fraction = (stop - values[-1]) / (value - values[-1])
            guess = w[:-1] + fraction * (candidate[:-1] - w[:-1])
            result = problem._solve(guess, *path.at(stop), **options)
            iterations += result.newton_iterations
            if result.success:
                return _Attempt(iterations, stop, result, complete=True)
            return _Attempt(iterations, stop, reason=f"final point at stop failed: {result.message}")
        eps, amplitude = path.at(value)
        result = problem.verify(candidate[:-1], eps, verify_tol=options["verify_tol"],
                                stability_tol=options["stability_tol"], iterations=outcome.iterations,
                                amplitude=amplitude)
        if not result.success:
            return _Attempt(iterations, value, reason=result.message)
        # tangent at the new point from the corrector's last Jacobian (no extra flow)
        new_scales = self.scales_at(result, value)
        previous = tangent * scales / new_scales
        previous /= np.linalg.norm(previous)
        new_tangent = self.tangent_of(outcome.last["augmented"], new_scales, previous)
        turn = float(new_tangent @ previous)
        if not (turn >= 0.9 or h <= self.h_min):
            return _Attempt(iterations, value, reason=f"the tangent turned too much (cos = {turn:.3f})")
        self.pending = (candidate, new_scales, new_tangent, outcome.iterations)
        return _Attempt(iterations, value, result)

    def reject(self, attempt: _Attempt, values: list[float]) -> str | None:
        self.step *= 0.5
        if self.step < self.h_min:
            return (f"step size {self.step:.2e} below min_step {self.h_min:.2e} at {self.path.parameter} = "
                    f"{values[-1]:.6g}: {attempt.reason}")
        return None

    def accept(self, attempt: _Attempt) -> None:
        self.w, self.scales, self.tangent, corrector_iterations = self.pending
        if corrector_iterations <= 2:
            self.step = min(1.5 * self.step, self.h_max)
        elif corrector_iterations >= 5:
            self.step = max(0.6 * self.step, self.h_min)


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


def _seed_solve(problem: NNMShooting, path: _Path, value: float, guess: np.ndarray, verify_tol: float,
                stability_tol: float) -> NNMResult:
    """One point of the seed's algorithm: hybr (no Jacobian) on :func:`_seed_residual`, then the verification."""
    eps, amplitude = path.at(value)
    n = problem.n
    problem.set_scales(eps, guess[:n] if np.max(np.abs(guess[:n])) > 0 else None, float(guess[2 * n]), amplitude)
    impossible = _impossible_amplitude(problem, eps, amplitude)
    if impossible:
        return problem._failure(eps, impossible, label="seed")
    columns = np.r_[np.full(n, problem.position_scale), np.full(n, problem.velocity_scale), problem.period_scale]
    import scipy.optimize  # here, not at module level: import lindstedt stays light
    solution = scipy.optimize.root(lambda y: _seed_residual(problem, eps, amplitude, y * columns), guess / columns,
                                   method="hybr", options={"xtol": 1e-12})
    unknowns = solution.x * columns
    norm = float(np.max(np.abs(_seed_residual(problem, eps, amplitude, unknowns))))
    iterations = int(solution.nfev)  # hybr has no Jacobian: its cost is its function evaluations
    if not norm <= verify_tol:
        return problem._failure(eps, f"hybr did not converge (residual {norm:.1e}; {solution.message})", iterations,
                                label="seed")
    saved = problem.formulation
    problem.formulation = "full"
    try:
        return problem.verify(unknowns, eps, verify_tol=verify_tol, stability_tol=stability_tol, iterations=iterations,
                              amplitude=amplitude, formulation_label="seed")
    finally:
        problem.formulation = saved


class _Seed(_Natural):
    """The seed's algorithm: natural continuation in ε with hybr on the seed's residual (no secant guess)."""

    name = "seed"

    label = "ε"

    def first(self, value: float) -> NNMResult:
        eps0, amplitude0 = self.path.at(value)
        x0, _ = self.problem._guess_amplitude(eps0, amplitude0)
        return self.solve(value, np.r_[x0, np.zeros(self.problem.n), _TWO_PI / self.problem.linear_frequency])

    def guess(self, points: list[NNMResult], values: list[float], target: float) -> np.ndarray:
        last = points[-1]
        return np.r_[last.release_position, last.release_velocity, last.period]

    def solve(self, value: float, guess: np.ndarray) -> NNMResult:
        return _seed_solve(self.problem, self.path, value, guess, self.options["verify_tol"],
                           self.options["stability_tol"])


#: the continuation methods of :func:`continue_nnm` (``method=``)
_METHODS: dict[str, type[_Stepper]] = {"arclength": _Arclength, "natural": _Natural, "seed": _Seed}


# --------------------------------------------------------------------------- #
# sweeps
# --------------------------------------------------------------------------- #
def _sweep_task(value: float, *, system: UnilateralSystem, mode: int, parameter: str, epsilon: float | None,
                options: dict[str, Any]) -> NNMResult:
    if parameter == "epsilon":
        return nnm_point(system, value, mode, **options)
    return nnm_point(system, epsilon, mode, **{parameter: value}, **options)


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
    _check_parameter(parameter, epsilon, "sweeps")
    values = [float(v) for v in values]
    task = partial(_sweep_task, system=system, mode=mode, parameter=parameter, epsilon=epsilon, options=options)
    if executor is None:
        return [task(v) for v in values]
    futures = [executor.submit(task, v) for v in values]
    return [future.result() for future in futures]
