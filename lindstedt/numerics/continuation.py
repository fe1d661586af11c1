"""Continuation of NNMs of  M X'' + K X + ε W (A X − b)_+ = 0 : one driver, three methods, and sweeps.

:func:`continue_nnm` follows the NNM of one mode in a parameter λ — ε, the
energy or the modal amplitude (:mod:`lindstedt.numerics.shooting` gives the
residual ``G(z; λ) = 0`` in the shooting unknowns z and its exact Jacobian).
One driver runs every method: it solves the first point (Newton from the
linear mode, then from the strained-coordinates expansion :func:`lindstedt.nnm`,
then by continuation in ε from where the expansion holds — the route of
:func:`~lindstedt.numerics.nnm_point`), then asks the method for
the next point, counts rejected steps, reports progress
(:class:`~lindstedt.numerics.ContinuationProgress`) and assembles the
:class:`~lindstedt.numerics.NNMBranch` (folds, stability and contact changes,
resonance jumps).  The methods (``method=``, a small registry) differ only in
how they step:

``"arclength"`` — pseudo-arclength continuation
    Unknowns ``w = (z, λ)``; predictor ``w + h t`` along the unit tangent t, the
    null vector of the exact augmented Jacobian ``[∂G/∂z, ∂G/∂λ]`` oriented as
    the previous one; corrector: Newton on ``[G(w); tᵀ(w − w_k) − h] = 0`` in
    scaled variables.  Step control on the corrector's first correction (the
    predictor's error), its iterations, contact changes and the turn of the
    tangent; the Floquet multipliers of every point give the stability along
    the branch; the last point is solved at exactly ``λ = stop``.
    Contact changes: where the springs switching along the orbit change (a
    spring grazes the orbit — at the contact onset the backbone has a kink
    and a steep part, dω/dλ jumps), a step across is refined to 1/8 of the
    initial step and the branch is followed through the corner and the steep
    part (the tangent may turn and its λ-component drop there: that is not a
    resonance); the stop reason names each contact change.
    Internal resonances: where ``λ_k ≈ n ω`` the branch of mode j meets a
    resonance tongue of mode k — the arc turns vertical (λ stops advancing)
    *towards mode k* and climbing it stalls the continuation (the 20-dof chain
    with three springs did so at ε ≈ 0.011 after 330 points).  When the
    tangent's λ-component collapses, mode k dominates it and the period is locked
    (its component of the tangent small), the method *jumps*:
    it solves at fixed λ further and further beyond (predictor: the last
    regular tangent) and lands on the first regular point of mode j
    (``NNMBranch.jumps``, the stop reason names what each jump crossed).  If no
    landing succeeds, the turn is a fold of mode j itself and is followed,
    until the branch leaves mode j; a turn that stays in mode j (a steep part
    of the backbone, or a fold) is followed from the start.  A step that would
    shrink below ``min_step`` is rescued once by the same jump; the branch
    never ends without a reason naming where and why.
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
from dataclasses import dataclass, replace
from functools import partial
from typing import Any

import numpy as np

from .._errors import BudgetError, Cancelled, ProblemError
from .._cost import shooting_estimate
from ..limits import checkpoint
from .._sweep import sweep_map
from ..problems.system import UnilateralSystem
from .results import ContinuationProgress, NNMBranch, NNMResult, _branch_events
from .sensitivity import _check_epsilon, _integrate
from .shooting import (
    _TWO_PI,
    NNMShooting,
    _Amplitude,
    _ExpansionPredictor,
    _impossible_amplitude,
    _guess_unknowns,
    _newton,
    nnm_energy,
)

__all__ = ["continue_nnm", "nnm_point", "nnm_sweep"]

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
# one point, robustly: linear mode, expansion predictor, continuation in ε
# --------------------------------------------------------------------------- #
#: scaled arclength steps of the continuation that reaches a hard point (its λ range is scaled to 1)
_HOMOTOPY_STEP, _HOMOTOPY_MAX_STEP, _HOMOTOPY_POINTS = 0.1, 0.25, 60
#: the continuation to a hard point starts at the largest ε / 2**k (k = 1 … this) where the expansion holds
_HOMOTOPY_HALVINGS = 6
#: a start of that continuation must have a unit tangent with at least this λ-component (not in a turn)
_HOMOTOPY_START_SLOPE = 0.5


def _robust_point(problem: NNMShooting, epsilon: float, amplitude: _Amplitude, options: dict[str, Any], *,
                  min_mode_share: float | None, guesses: tuple[str, ...] = ("linear",), homotopy: bool = True,
                  near_linear: bool = True) -> NNMResult:
    """The NNM at (ε, amplitude), trying in turn the ``guesses`` and then a continuation in ε.

    ``"linear"``: Newton from the linear mode j; ``"expansion"``: Newton from the
    strained-coordinates expansion (:func:`lindstedt.nnm`, order 2: ω(ε) and the
    release state).  With ``near_linear`` (the default route of :func:`nnm_point`
    and of the first point of :func:`continue_nnm`) Newton from the linear mode is
    kept only when it returns the linear mode itself (no spring touched: then it
    *is* the NNM, exactly) or an orbit near it (:func:`_near_linear`: period and
    release state within ``_NEAR_LINEAR`` of the linear mode's — the weakly
    nonlinear NNM): an orbit reached by Newton far from its guess can be another
    periodic orbit — on the SDND123 stop system at ε = 30 Newton from the linear
    mode gave a 52-switch orbit at E = 10, a collapse T → 0 at E = 2.5 and the NNM
    run 2, 3 or 12 times elsewhere.  Otherwise, and
    if the guesses fail, the point is reached by pseudo-arclength continuation in
    ε (with the resonance jumps of :class:`_Arclength`) from the largest
    ``ε/2**k`` where the expansion holds and its point converges, else from ε = 0
    (the linear mode): the NNM by its definition, the orbit that grows out of the
    linear mode.  The message says which route succeeded; the iterations and
    flows of every attempt are counted.
    """
    impossible = _impossible_amplitude(problem, epsilon, amplitude)
    if impossible:
        return problem._failure(epsilon, impossible)
    labels = {"linear": "the linear mode", "expansion": "the expansion predictor (lindstedt.nnm, order 2)"}
    failures: list[str] = []
    iterations = 0
    for kind in guesses:
        if kind == "linear":
            guess = problem._linear_guess(epsilon, amplitude)
        else:
            predictor = _ExpansionPredictor.build(problem, epsilon, amplitude)
            guess = None if predictor is None else predictor.guess(epsilon)
            if guess is None:
                failures.append(f"{labels[kind]}: not available (lindstedt.nnm failed or ω(ε) ≤ 0)")
                continue
        result = problem._solve(guess, epsilon, amplitude, min_mode_share=min_mode_share, **options)
        iterations += result.newton_iterations
        if result.success and near_linear and kind == "linear" and not _near_linear(problem, result, guess):
            failures.append(f"Newton from {labels[kind]} reached an orbit far from it (ω = {result.frequency:.10g}, "
                            f"{result.n_switches} switches), which need not be the NNM: not kept")
            continue
        if result.success:
            note = f"; Newton from {labels[kind]} (before: {'; '.join(failures)})" if failures else ""
            return replace(result, message=result.message + note, newton_iterations=iterations)
        failures.append(f"Newton from {labels[kind]}: {result.message}")
    if homotopy and epsilon != 0.0:
        result = _homotopy(problem, epsilon, amplitude, options, min_mode_share)
        iterations += result.newton_iterations
        if result.success:
            return replace(result, message=f"{result.message} (before: {'; '.join(failures)})",
                           newton_iterations=iterations)
        failures.append(result.message)
    failed = problem._failure(epsilon, "; ".join(failures), iterations)
    return replace(failed, flow_evaluations=problem.flow_evaluations)


#: Newton from the linear mode is kept when its orbit's period and release position are within this relative
#: distance of the linear mode's (a multiple of the NNM has twice its period at least, a collapse none)
_NEAR_LINEAR = 0.25


def _near_linear(problem: NNMShooting, result: NNMResult, guess: np.ndarray) -> bool:
    """Whether a verified orbit is the linear mode itself (ε = 0, or no switch and no spring engaged at the release
    point) or within ``_NEAR_LINEAR`` of the linear-mode guess in period and release position."""
    if result.epsilon == 0.0 or (result.n_switches == 0
                                 and not np.any(problem.system.gaps(result.release_position) > 0)):
        return True
    x0, _, period = problem.split(guess)
    return (abs(result.period - period) <= _NEAR_LINEAR * period
            and float(np.linalg.norm(result.release_position - x0)) <= _NEAR_LINEAR * float(np.linalg.norm(x0)))


def _homotopy(problem: NNMShooting, epsilon: float, amplitude: _Amplitude, options: dict[str, Any],
              min_mode_share: float | None) -> NNMResult:
    """The NNM at ε by continuation in ε at fixed amplitude, from where the expansion or the linear mode holds.

    Starts: the largest ``ε/2**k`` where the expansion holds and its point
    converges, provided the branch is not turning there (the λ-component of
    its unit tangent is at least ``_HOMOTOPY_START_SLOPE``: a start next to an
    internal resonance would leave no reference for the resonance jumps);
    else ε = 0, the linear mode (``ε/2**6`` for ``energy_per_epsilon``).
    """
    failures: list[str] = []
    iterations = 0
    fallback = 0.0 if amplitude.kind != "energy_per_epsilon" else epsilon / 2.0**_HOMOTOPY_HALVINGS
    starts: list[tuple[float, NNMResult | None]] = []
    predictor = _ExpansionPredictor.build(problem, epsilon, amplitude) if amplitude.kind != "energy_per_epsilon" else None
    if predictor is not None:
        for k in range(1, _HOMOTOPY_HALVINGS + 1):
            candidate = epsilon / 2.0**k
            if predictor.valid(candidate):
                guess = predictor.guess(candidate)
                if guess is not None:
                    result = problem._solve(guess, candidate, amplitude, min_mode_share=0.5, **options)
                    iterations += result.newton_iterations
                    if result.success:
                        starts.append((candidate, result))
                break
    starts.append((fallback, None))
    for start, first in starts:
        if first is None:
            impossible = _impossible_amplitude(problem, start, amplitude)
            if impossible:
                failures.append(f"no start at ε = {start:g} ({impossible})")
                continue
            first = problem._solve(problem._linear_guess(start, amplitude), start, amplitude, min_mode_share=0.5,
                                   **options)
            iterations += first.newton_iterations
            if not first.success:
                failures.append(f"the start at ε = {start:g} failed: {first.message}")
                continue
        stepper = _Arclength(problem, _Path("epsilon", amplitude, None), start, epsilon, step=_HOMOTOPY_STEP,
                             min_step=None, max_step=_HOMOTOPY_MAX_STEP, max_halvings=12, options=options)
        stepper.initial = first
        stepper.minimum_start_slope = _HOMOTOPY_START_SLOPE if start != fallback else None
        branch = _drive(stepper, start, epsilon, _HOMOTOPY_POINTS, None)
        iterations += branch.newton_iterations - first.newton_iterations
        if not branch.success:
            failures.append(f"from ε = {start:g}: {branch.stop_reason}")
            continue
        last = branch.points[-1]
        route = (f"reached by continuation in ε from {start:g} ({len(branch)} points"
                 + (f", {len(branch.jumps)} resonance jump(s)" if branch.jumps else "") + ")")
        if min_mode_share is not None and last.mode_share < min_mode_share:
            failures.append(f"{route} to a periodic orbit that is not the NNM of mode {problem.mode} "
                            f"(mode-{problem.mode} share {last.mode_share:.1%} < {min_mode_share:.0%})")
            continue
        return replace(last, message=f"{last.message}; {route}", newton_iterations=iterations,
                       flow_evaluations=problem.flow_evaluations)
    return problem._failure(epsilon, "continuation in ε: " + "; ".join(failures), iterations)


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
        the linear mode j (exactly the linear mode at ε = 0), else from the
        expansion :func:`lindstedt.nnm` (order 2), else by continuation in ε
        from where the expansion holds (as :func:`nnm_point`).
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
        period).  Step control: the next step aims at a first corrector
        correction of 2e-3 (scaled; the factor is kept in [0.5, 2]) or grows
        ×1.5 after ≤ 2 corrector iterations, ×0.6 after ≥ 5, never growing
        across a change of the springs touching the orbit, halved after a
        failure or a turn of the tangent by more than ~25°; the last point is
        solved at exactly ``λ = stop``.
        A step across which the springs switching along the orbit change is
        refined to 1/8 of the initial step, then the branch is followed through
        that corner (contact onset: the backbone turns steep there).
        Where the branch turns vertical towards another mode (its tangent's
        λ-component falls below half its recent level, another mode dominates
        the tangent and the period is locked: an internal-resonance tongue), the method jumps
        across at fixed λ to the next regular point of mode j (up to 8 landings,
        distances growing ×1.5 from the recent step's λ-extent, at most a
        quarter of the range; ``NNMBranch.jumps``); if none lands, the turn is
        followed as a fold until the branch leaves mode j (its mode-j share of
        the modal energy falls below half that where the turn began), which
        ends it with that reason.
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
    shooting_estimate(system, max_iterations + 1, f"NNM continuation of mode {mode} (its first point)").check()
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
    callback answers; ``iterations`` are the corrector iterations spent;
    ``jumped`` marks a point reached by a parameter jump across an internal
    resonance and ``rejected`` counts the failed landings before it.
    """

    iterations: int
    value: float = math.nan
    result: NNMResult | None = None
    reason: str = ""
    end: str | None = None
    complete: bool = False
    jumped: bool = False  # the accepted point was reached by a parameter jump (see _Arclength.jump); reason: why
    rejected: int = 0  # failed landings of a jump, counted as rejected steps


def _drive(stepper: _Stepper, start: float, stop: float, max_points: int,
           callback: Callable[[ContinuationProgress], bool | None] | None) -> NNMBranch:
    """Run one continuation method from ``start`` towards ``stop``: first point, steps, bookkeeping, the branch."""
    started = time.perf_counter()
    problem, path = stepper.problem, stepper.path

    jumps: list[int] = []
    causes: list[str] = []  # what each jump stepped across

    def finish(points: list[NNMResult], values: list[float], stop_reason: str, success: bool, rejected: int,
               iterations: int) -> NNMBranch:
        folds, stability, contact = _branch_events(points, values)
        return NNMBranch(
            success=success, stop_reason=stop_reason, method=stepper.name, parameter=path.parameter,
            points=tuple(points), parameter_values=np.array(values, dtype=float), folds=folds,
            stability_changes=stability, contact_changes=contact, flow_evaluations=problem.flow_evaluations,
            newton_iterations=iterations, rejected_steps=rejected, wall_time=time.perf_counter() - started,
            system=problem.system, jumps=tuple(jumps),
        )

    def notify(index: int, value: float, result: NNMResult) -> bool:
        if callback is None:
            return False
        return bool(callback(ContinuationProgress(index, value, result, stepper.step, problem.flow_evaluations)))

    def reached() -> str:
        text = f"reached stop = {stop:g}"
        changes = [k for k in range(len(points) - 1) if points[k].contact_springs != points[k + 1].contact_springs]
        if changes:
            where = ", ".join(f"{values[k]:.6g}–{values[k + 1]:.6g} ({_springs(points[k])} → {_springs(points[k + 1])})"
                              for k in changes[:6]) + (", …" if len(changes) > 6 else "")
            text += (f"; {len(changes)} contact change(s) — the springs switching along the orbit change, a spring "
                     f"grazes it: {stepper.label} in {where} (NNMBranch.contact_changes)")
        if jumps:
            where = "; ".join(f"{values[k]:.4g}–{values[k + 1]:.4g}: {cause}" for k, cause in zip(jumps, causes))
            text += (f"; {len(jumps)} part(s) of the branch crossed by parameter jumps, not followed "
                     f"({stepper.label} in {where}; NNMBranch.jumps)")
        return text

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
            return finish(points, values, f"max_points = {max_points} reached at {stepper.label} = {values[-1]:.6g}"
                          + stepper.note(), False, rejected, iterations)
        try:  # a spent budget or a cancel stops the branch where it is: the points so far are kept
            checkpoint("continuation point", len(points), max_points)
            attempt = stepper.advance(points, values)
        except (BudgetError, Cancelled) as stopped:
            return finish(points, values, f"stopped after {len(points)} point(s): {stopped}", False, rejected,
                          iterations)
        iterations += attempt.iterations
        rejected += attempt.rejected
        if attempt.end is not None:
            return finish(points, values, attempt.end, False, rejected, iterations)
        if attempt.result is None:
            rejected += 1
            failure = stepper.reject(attempt, values)
            if failure:
                return finish(points, values, failure, False, rejected, iterations)
            continue
        if attempt.jumped:
            jumps.append(len(points) - 1)
            causes.append(attempt.reason or "a turn of the branch")
        points.append(attempt.result)
        values.append(attempt.value)
        requested = notify(len(points) - 1, attempt.value, attempt.result)
        if attempt.complete or (not requested and attempt.value == stop):
            return finish(points, values, reached(), True, rejected, iterations)
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

    #: a first point solved beforehand (the continuation of :func:`_robust_point`), or None
    initial: NNMResult | None = None

    def first(self, value: float) -> NNMResult:
        """The first point: Newton from the linear mode, then from the expansion, then by continuation in ε."""
        if self.initial is not None:
            return self.initial
        eps, amplitude = self.path.at(value)
        return _robust_point(self.problem, eps, amplitude, self.options, min_mode_share=0.5)  # nnm_point's route

    def begin(self, first: NNMResult, value: float) -> str | None:
        return None

    def note(self) -> str:
        """What the stop reasons of the driver should add about the state of the method ("" or "; …")."""
        return ""

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


def _springs(result: NNMResult) -> str:
    """The springs switching along an orbit, in words ("no contact" when none)."""
    if not result.contact_springs:
        return "no contact"
    return "spring" + ("s " if len(result.contact_springs) > 1 else " ") + ", ".join(map(str, result.contact_springs))


def _unknowns_of(problem: NNMShooting, result: NNMResult) -> np.ndarray:
    return problem._join(result.release_position, result.release_velocity, result.period)


# --------------------------------------------------------------------------- #
# pseudo-arclength continuation
# --------------------------------------------------------------------------- #
#: the branch is "turning vertical" when the λ-component of its unit tangent falls below this share of its recent level
_VERTICAL_RATIO = 0.5
#: below this recent level of the λ-component the branch is not regular enough to judge a turn
_REGULAR_MIN = 0.05
#: accepted points whose tangent's λ-component over the reference is at least this are "regular" (jump bases)
_REGULAR_RATIO = 0.7
#: a parameter jump tries these many distances, growing from the typical λ-extent of a regular step
_JUMP_TRIES = 8
#: the growth of the jump distance from one landing attempt to the next
_JUMP_GROWTH = 1.5
#: a landing point is regular when its tangent's λ-component is at least this share of the reference
_LANDING_RATIO = 0.5
#: the scaled first correction of the corrector aimed at by the step control (the predictor's error)
_PREDICTOR_ERROR = 2e-3
#: in a resonance tongue the period is locked: the scaled period component of the tangent is at most this share of
#: the state's (0.03–0.05 on the tongues of the 8-mass chain; 0.5–0.6 on the steep backbone after a contact onset)
_LOCKED_RATIO = 0.2
#: where the springs switching along the orbit change, the step is refined to the initial one / 2**this
_CONTACT_REFINEMENT = 3
#: the longest jump, as a fraction of the range |stop − start|
_JUMP_MAX_FRACTION = 0.25
#: the landing point of a jump must carry at least min(this, _RELATIVE_MODE_SHARE × the base point's share) of
#: the modal energy in mode j (the NNM of mode j, not an orbit of the resonant mode)
_JUMP_MODE_SHARE = 0.5
#: followed through a turn (no jump landed), the branch ends when its mode-j share falls below this fraction of
#: the share where the turn began: it has become an orbit of other modes
_RELATIVE_MODE_SHARE = 0.5


class _Arclength(_Stepper):
    """Predictor along the tangent of the branch, corrector with the arclength constraint, adaptive step.

    Internal resonances.  Where ``λ_k ≈ n ω`` for another mode k, the branch of
    mode j meets a resonance tongue: the arc bends, its tangent turns towards
    mode k and the parameter stops advancing (the tongue grows mode k at almost
    constant λ, without bound for these piecewise-linear systems, or closes on
    itself).  Followed faithfully, pseudo-arclength climbs the tongue and the
    parameter stalls.  So when the λ-component of the unit tangent falls below
    ``_VERTICAL_RATIO`` of its recent level (or the tangent turns too much and
    it falls below ``_REGULAR_RATIO``) and another mode dominates the tangent
    (:meth:`other_mode`), the step is not taken: :meth:`jump`
    solves at fixed λ beyond it (distances growing ×``_JUMP_GROWTH`` from the
    λ-extent of the recent steps, at most ``_JUMP_MAX_FRACTION`` of the range;
    predictor: the last regular tangent) and lands on the first point of mode j
    whose own tangent is regular again.  If no landing succeeds the turn is a fold of mode j and
    is followed (pseudo-arclength as before) until the branch is regular again
    or leaves mode j, which ends it with the reason.  The same jump rescues,
    once, a step that would shrink below ``min_step``.
    """

    name = "arclength"
    #: reject a first point whose tangent's λ-component is below this (None: no check)
    minimum_start_slope: float | None = None

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

    # ------------------------------------------------------------ the branch's shape
    def slope(self, tangent: np.ndarray) -> float:
        """The λ-component of a unit tangent, positive towards ``stop``."""
        return self.direction * float(tangent[-1])

    def reference(self) -> float | None:
        """The recent level of the tangent's λ-component (median of the last regular points), None if too small."""
        if not self.slopes:
            return None
        level = float(np.median(self.slopes[-5:]))
        return level if level > _REGULAR_MIN else None

    def other_mode(self, tangent: np.ndarray, scales: np.ndarray) -> int | None:
        """The mode (1-based) dominating the tangent's change of state when it is not mode j and the period is
        locked (a resonance tongue: the scaled period component of the tangent at most ``_LOCKED_RATIO`` of the
        state's), else None — a tangent turning to another mode while the period changes fast is a steep part of
        the backbone (as after a contact onset in the modal-amplitude parametrisation)."""
        problem = self.problem
        _, _, period = problem.split(tangent[:-1])
        if abs(period) > _LOCKED_RATIO * float(np.linalg.norm(tangent[:problem.n_unknowns - 1])):
            return None
        x, v, _ = problem.split(tangent[:-1] * scales[:-1])
        frequencies = problem.system.modes().frequencies
        energy = (frequencies * (problem.projector @ x)) ** 2 + (problem.projector @ v) ** 2
        total = float(np.sum(energy))
        if not total > 0 or energy[problem.mode - 1] >= 0.5 * total:
            return None
        return int(np.argmax(energy)) + 1

    def resonance(self, mode: int | None, result: NNMResult) -> str:
        """Words for the vertical turn of the branch at ``result``, its tangent mostly ``mode`` (None: mode j)."""
        if mode is None:
            return "the branch turns vertical (a fold)"
        lam = float(self.problem.system.modes().frequencies[mode - 1])
        harmonic = max(1, round(lam / result.frequency))
        if abs(lam / result.frequency - harmonic) > 0.1:
            return f"the branch turns vertical towards mode {mode} (λ_{mode} = {lam:.6g}, ω = {result.frequency:.6g})"
        return (f"the branch turns vertical towards mode {mode}: internal resonance λ_{mode} = {lam:.6g} ≈ "
                f"{harmonic} ω (ω = {result.frequency:.6g})")

    def begin(self, first: NNMResult, value: float) -> str | None:
        self.w = np.r_[_unknowns_of(self.problem, first), value]
        self.scales = self.scales_at(first, value)
        out = self.augmented(self.w)
        if not out["success"]:
            return f"tangent failed: {out['message']}"
        self.tangent = self.tangent_of(out["augmented"], self.scales, None)
        if self.minimum_start_slope is not None and self.slope(self.tangent) < self.minimum_start_slope:
            return (f"the first point at {self.label} = {value:.6g} lies in a turn of the branch (λ-component of the "
                    f"unit tangent {self.slope(self.tangent):.3f} < {self.minimum_start_slope:g})")
        self.last = first
        self.last_regular_share = first.mode_share
        self.slopes: list[float] = []
        self.extents: list[float] = []
        self.regular = (self.tangent, self.scales, self.step)
        self.rescue: str | None = None
        self.rescued = False
        #: the step is refined below this where the springs switching along the orbit change
        self.h_refine = max(self.step / 2.0**_CONTACT_REFINEMENT, self.h_min)
        self.following: str | None = None  # why the branch is followed through a turn (jumps failed there)
        return None

    def note(self) -> str:
        return f"; {self.following}" if self.following else ""

    # ------------------------------------------------------------ one step
    def advance(self, points: list[NNMResult], values: list[float]) -> _Attempt:
        if self.rescue is not None:  # the step collapsed: step across instead of shrinking to nothing
            reason, self.rescue = self.rescue, None
            return self.jump(0, reason, collapse=True)
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
        if direction * (value - start) < 0:  # a step too long for the curvature, or a fold: retry shorter
            return _Attempt(iterations, value, reason=f"the corrector returned behind start = {start:g} "
                            f"({path.parameter} = {value:.6g}): the branch folds back there or the step is too long")
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
        floor = _RELATIVE_MODE_SHARE * self.last_regular_share
        if self.following and result.mode_share < floor:
            return _Attempt(iterations, value, end=(
                f"{self.following}, and it leaves mode {problem.mode} at {self.label} = {value:.6g} "
                f"(mode-{problem.mode} share {result.mode_share:.1%}, below half its {self.last_regular_share:.1%} "
                f"where the turn began)"))
        contact_changed = result.contact_springs != self.last.contact_springs
        if contact_changed and h > self.h_refine:  # resolve the contact change: the backbone bends there
            return _Attempt(iterations, value, reason=(
                f"the springs switching along the orbit change within the step ({_springs(self.last)} → "
                f"{_springs(result)}): the step is refined towards the contact change"))
        # tangent at the new point from the corrector's last Jacobian (no extra flow)
        new_scales = self.scales_at(result, value)
        previous = tangent * scales / new_scales
        previous /= np.linalg.norm(previous)
        new_tangent = self.tangent_of(outcome.last["augmented"], new_scales, previous)
        reference, slope = self.reference(), self.slope(new_tangent)
        turn = float(new_tangent @ previous)
        # across a contact change (a small step by now) the tangent may turn and the λ-component drop: the branch
        # has a corner or a steep part there (contact onset: dω/dλ jumps), not a resonance tongue — it is followed
        turned = not (turn >= 0.9 or h <= self.h_min or contact_changed)
        vertical = not contact_changed and reference is not None and (
            slope < _VERTICAL_RATIO * reference or (turned and slope < _REGULAR_RATIO * reference))
        other = self.other_mode(new_tangent, new_scales) if vertical else None
        if other is not None and not self.following:
            # the branch turns vertical towards another mode: a resonance tongue ahead — do not climb it, step
            # across (if that fails, it is a fold of mode j: follow it).  Turning vertical in mode j itself is a
            # steep part of the backbone (or a fold of mode j): followed, the step adapting to its curvature
            self.scales_at(self.last, values[-1])  # the residual scaling of the base point
            jump = self.jump(iterations, self.resonance(other, result), extent=abs(value - values[-1]))
            if jump.end is None:
                return jump
            self.following = (f"{jump.end}; the branch is followed through the turn from {self.label} = "
                              f"{values[-1]:.6g}")
            self.scales_at(result, value)
            iterations, rejected = jump.iterations, jump.rejected
        else:
            rejected = 0
        if turned:
            return _Attempt(iterations, value, reason=f"the tangent turned too much (cos = {turn:.3f})",
                            rejected=rejected)
        self.pending = (candidate, new_scales, new_tangent, outcome, result, abs(value - values[-1]))
        return _Attempt(iterations, value, result, rejected=rejected)

    def reject(self, attempt: _Attempt, values: list[float]) -> str | None:
        self.step *= 0.5
        if self.step < self.h_min:
            if not self.rescued:  # one rescue per collapse: a parameter jump from the last point
                self.rescued = True
                self.rescue = (f"step size {self.step:.2e} below min_step {self.h_min:.2e} at {self.path.parameter} = "
                               f"{values[-1]:.6g}: {attempt.reason}")
                return None
            return (f"step size {self.step:.2e} below min_step {self.h_min:.2e} at {self.path.parameter} = "
                    f"{values[-1]:.6g}: {attempt.reason}")
        return None

    def accept(self, attempt: _Attempt) -> None:
        candidate, scales, tangent, outcome, result, extent = self.pending
        contact_changed = result.contact_springs != self.last.contact_springs
        self.w, self.scales, self.tangent, self.last = candidate, scales, tangent, result
        self.rescued = False
        if contact_changed:  # a new contact regime: the λ-component of the tangent has a new level
            self.slopes.clear()
        slope = self.slope(tangent)
        reference = self.reference()
        if not attempt.jumped:
            self.extents.append(extent)
        if reference is None or slope >= _REGULAR_RATIO * reference:
            self.slopes.append(slope)
            self.regular = (tangent, scales, self.step)
            self.last_regular_share = result.mode_share
            self.following = None
        if attempt.jumped:
            return  # the step was reset by the jump
        self.step = min(max(self.step * self.step_factor(outcome, contact_changed), self.h_min), self.h_max)

    def step_factor(self, outcome: Any, contact_changed: bool) -> float:
        """Factor of the next step from the corrector: its first correction (the predictor's error, O(h²)) and
        its iterations; never growing across a contact change (the residual is not smooth there).

        The error factor ``sqrt(_PREDICTOR_ERROR / first correction)`` (kept in [0.5, 2]) and the iteration
        factor (×1.5 after ≤ 2 iterations) each may grow the step; ≥ 5 iterations shrink it (×0.6 at least).
        """
        iterations, steps = outcome.iterations, outcome.steps
        error = min(max(math.sqrt(_PREDICTOR_ERROR / steps[0]), 0.5), 2.0) if steps and steps[0] > 0 else 2.0
        if iterations >= 5:
            return min(error, 0.6)
        factor = max(error, 1.5 if iterations <= 2 else 1.0)
        if iterations >= 4:
            factor = min(factor, 1.0)
        return min(factor, 1.0) if contact_changed else factor

    # ------------------------------------------------------------ parameter jumps
    def jump(self, iterations: int, why: str, collapse: bool = False, extent: float = 0.0) -> _Attempt:
        """Solve at fixed λ beyond the last point, further and further, until a regular point of mode j is found.

        The distances grow ×``_JUMP_GROWTH`` from ``extent`` or the typical
        λ-extent of the recent steps, whichever is larger, up to
        ``_JUMP_MAX_FRACTION`` of the range.  The landing must verify, carry
        mode j (share ≥ min(``_JUMP_MODE_SHARE``, ``_RELATIVE_MODE_SHARE`` × the
        base point's)) and have a regular tangent; a landing at ``stop`` only
        needs the first two.  Returns the accepted landing or the reason none
        succeeded (``end``).
        """
        problem, options = self.problem, self.options
        base, base_scales = self.w, self.scales
        value0 = float(base[-1])
        tangent, scales, step = self.regular
        direction_vector = tangent * scales  # unscaled
        extent = max(extent, float(np.median(self.extents[-5:])) if self.extents else 0.0)
        if not extent > 0:
            extent = abs(step * tangent[-1] * scales[-1]) or self.span / 50.0
        reference = self.reference()
        rejected, last_reason = 0, "no landing tried"
        longest = max(extent, _JUMP_MAX_FRACTION * self.span)
        distance = 0.0
        for attempt in range(_JUMP_TRIES):
            previous, distance = distance, min(extent * _JUMP_GROWTH**attempt, longest)
            if distance == previous:
                break  # capped: the same distance again would land on the same point
            target = value0 + self.direction * distance
            final = self.direction * (target - self.stop) >= 0
            if final:
                target = self.stop
            if not abs(direction_vector[-1]) > 0:
                break
            guess = base[:-1] + (target - value0) / direction_vector[-1] * direction_vector[:-1]
            eps, amplitude = self.path.at(target)
            outcome = _newton(lambda z, target=target: self.augmented(np.r_[z, target]), guess, base_scales[:-1],
                              tol=options["tol"], max_iterations=options["max_iterations"])
            iterations += outcome.iterations
            if not outcome.success:
                rejected, last_reason = rejected + 1, outcome.message
                continue
            result = problem.verify(outcome.unknowns, eps, verify_tol=options["verify_tol"],
                                    stability_tol=options["stability_tol"], iterations=outcome.iterations,
                                    amplitude=amplitude,
                                    min_mode_share=min(_JUMP_MODE_SHARE, _RELATIVE_MODE_SHARE * self.last.mode_share))
            if not result.success:
                rejected, last_reason = rejected + 1, result.message
                self.scales_at(self.last, value0)
                continue
            cause = (f"a contact change ({_springs(self.last)} → {_springs(result)}: a spring grazes the orbit)"
                     if result.contact_springs != self.last.contact_springs else why)
            if final:
                return _Attempt(iterations, target, result, reason=cause, complete=True, jumped=True,
                                rejected=rejected)
            new_scales = self.scales_at(result, target)
            new_tangent = self.tangent_of(outcome.last["augmented"], new_scales, None)
            slope = self.slope(new_tangent)
            if reference is None or slope >= _LANDING_RATIO * reference:
                self.pending = (np.r_[outcome.unknowns, target], new_scales, new_tangent, outcome, result,
                                abs(target - value0))
                self.step = step
                return _Attempt(iterations, target, result, reason=cause, jumped=True, rejected=rejected)
            rejected += 1
            last_reason = (f"landed at {self.label} = {target:.6g} in a turn of the branch again "
                           f"({self.resonance(self.other_mode(new_tangent, new_scales), result)})")
            self.scales_at(self.last, value0)
        where = f"{self.label} ≈ {value0:.6g}"
        if collapse:
            return _Attempt(iterations, end=f"{why}; no parameter jump beyond {where} converged to the NNM of mode "
                            f"{problem.mode} (last: {last_reason})", rejected=rejected)
        return _Attempt(iterations, end=f"at {where} {why}; no parameter jump up to {distance:.3g} beyond it landed "
                        f"on a regular point of the NNM of mode {problem.mode} (last: {last_reason})", rejected=rejected)


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
    progress: bool | Callable[[int, float, NNMResult], Any] | None = None,
    **options: Any,
) -> list[NNMResult]:
    """NNM points at many parameter values, optionally in parallel; results in input order.

    Each point is solved independently by :func:`nnm_point`'s default route
    (Newton from the linear mode near it, else continuation in ε from it; no
    continuation between the points): :func:`continue_nnm` follows a branch
    with fewer flows, or pass ``initial_guess`` in ``options``.

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
        Any executor: a thread or process pool, or a Dask cluster's
        ``distributed.Client(...).get_executor()``; default: serial in this thread.
    progress : bool or callable, optional
        ``True``: a tqdm progress bar (warns, naming ``pip install tqdm``, when tqdm is
        missing); a callable is called as ``progress(index, value, result)`` for every
        point as it finishes (completion order with an executor).
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
    return sweep_map(task, values, executor=executor, progress=progress, description="nnm_sweep")


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
    initial_guess : NNMResult, (X0, T), "linear", "expansion" or None
        An orbit or a pair ``(X0, T)``: Newton from it, nothing else.
        ``"linear"``: Newton from the linear mode j with the requested
        amplitude, ``T = 2π/λ_j``, nothing else.  ``"expansion"``: Newton from
        the strained-coordinates expansion (:func:`lindstedt.nnm`, order 2:
        ``ω(ε)`` and the release state ``Φ (a0 e_j + ε a)``) and, if that
        fails (ε beyond the expansion's validity), continuation in ε
        (:func:`continue_nnm`, with its resonance jumps) from the largest
        ``ε/2**k`` where the expansion holds, or from ε = 0.  None (default):
        Newton from the linear mode, kept only when its orbit is the linear mode
        or near it (period and release position within 25 %: the weakly
        nonlinear NNM); otherwise the continuation in ε above — the NNM by its
        definition, the orbit that grows out of the linear mode (Newton from the
        linear mode far from it can land on another orbit, or on the NNM run
        several times).  The message names the route that succeeded; the cost
        counters include every attempt.
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
        ``success`` is False (with the reason in ``message``: every route
        tried) on an impossible energy, a singular Jacobian, no convergence, a
        flow failure, a failed verification or a degenerate solution (period
        collapsed, rest state, not a minimal period that re-solving at T/m could
        not repair); no exception is raised for those.

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
    shooting_estimate(system, max_iterations + 1, f"NNM point of mode {mode} (shooting)").check()
    impossible = _impossible_amplitude(problem, epsilon, problem.amplitude)
    if impossible:
        return problem._failure(epsilon, impossible)
    options = dict(tol=tol, max_iterations=max_iterations, verify_tol=verify_tol, stability_tol=stability_tol)
    if initial_guess is None or isinstance(initial_guess, str):
        routes = {None: ("linear",), "linear": ("linear",), "expansion": ("expansion",)}
        if initial_guess not in routes:
            raise ProblemError(f"initial_guess must be an NNMResult, a pair (X0, T), 'linear', 'expansion' or None, "
                               f"got {initial_guess!r}")
        return _robust_point(problem, epsilon, problem.amplitude, options, min_mode_share=min_mode_share,
                             guesses=routes[initial_guess], homotopy=initial_guess != "linear",
                             near_linear=initial_guess is None)
    return problem._solve(_guess_unknowns(problem, epsilon, initial_guess), epsilon,
                          min_mode_share=min_mode_share, **options)
