"""NNMs of  M X'' + K X + ε W (A X − b)_+ = 0 : one point, a branch, a sweep (the entry points).

:func:`continue_nnm` follows the NNM of one mode in a parameter λ — ε, the
energy or the modal amplitude (:mod:`lindstedt.numerics.shooting` gives the
residual ``G(z; λ) = 0`` in the shooting unknowns z and its exact Jacobian).
It solves the first point by :func:`nnm_point`'s route (Newton from the linear
mode, then from the strained-coordinates expansion :func:`lindstedt.nnm`, then
by continuation in ε from where the expansion holds) and hands it to the one
continuation driver of the periodic-orbit core
(:func:`lindstedt.numerics.arclength.drive`) with the stepper of the method
(``method=``; :mod:`lindstedt.numerics.nnm_branch`):

``"arclength"`` — pseudo-arclength continuation
    The core's stepper (:class:`lindstedt.numerics.arclength.Arclength`):
    predictor ``w + h t`` along the unit tangent t, the null vector of the
    exact augmented Jacobian ``[∂G/∂z, ∂G/∂λ]`` oriented as the previous one;
    corrector: the core's Newton on ``[G(w); tᵀ(w − w_k) − h] = 0`` in scaled
    variables; step control on the corrector's first correction and its
    iterations; the Floquet multipliers of every point give the stability, and
    the folds, branch points and period doublings are located on the branch
    (``NNMBranch.bifurcations``) by the same test functions as on forced
    branches; the last point is solved at exactly ``λ = stop``.  What free
    NNM branches add: a step across which the springs switching along the
    orbit change is refined to 1/8 of the initial step (the backbone has a
    corner there, a spring grazes the orbit); where the branch turns vertical
    towards another mode k (an internal-resonance tongue, ``λ_k ≈ n ω``, the
    period locked), a parameter jump across it to the next regular point of
    mode j (``NNMBranch.jumps``; the 20-dof chain with three springs would
    otherwise stall at ε ≈ 0.011); where no jump lands, the turn is followed as
    a fold until the branch leaves mode j.  A step that would shrink below
    ``min_step`` is rescued once by the same jump; the branch never ends
    without a reason naming where and why.
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

:func:`nnm_sweep` solves independent points (:func:`nnm_point` at each
parameter value, optionally on an executor), without continuation.

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
from collections.abc import Callable, Iterable
from concurrent.futures import Executor
from dataclasses import replace
from functools import partial
from typing import Any

import numpy as np

from .._errors import ProblemError
from .._cost import shooting_estimate
from .._sweep import sweep_map
from ..problems.system import UnilateralSystem
from .arclength import drive
from .nnm_branch import METHODS, _check_parameter, _continuation_setup, _NNMArclength, _Path
from .results import ContinuationProgress, NNMBranch, NNMResult
from .sensitivity import _check_epsilon
from .nnm_guesses import _ExpansionPredictor, _guess_unknowns, _impossible_amplitude
from .shooting import NNMShooting, _Amplitude

__all__ = ["continue_nnm", "nnm_point", "nnm_sweep"]

_PARAMETERS = ("epsilon", "energy", "modal_amplitude")


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
    if result.epsilon == 0.0 or (problem.system.unilateral and result.n_switches == 0
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
        stepper = _NNMArclength(problem, _Path("epsilon", amplitude, None), start, epsilon, step=_HOMOTOPY_STEP,
                                min_step=None, max_step=_HOMOTOPY_MAX_STEP, max_halvings=12, options=options)
        stepper.minimum_start_slope = _HOMOTOPY_START_SLOPE if start != fallback else None
        branch = drive(stepper, first, start, _HOMOTOPY_POINTS, iterations=first.newton_iterations)
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
    started = time.perf_counter()
    stepper = METHODS[method](problem, path, start, stop, step=step, min_step=min_step, max_step=max_step,
                              max_halvings=max_halvings, options=options)
    if method == "seed":
        first = stepper.first(start)
    else:  # nnm_point's route: the linear mode, the expansion, continuation in ε
        first = _robust_point(problem, *path.at(start), options, min_mode_share=0.5)
    if not first.success:
        return stepper.assemble([], [], f"first point failed: {first.message}", False, 0, first.newton_iterations,
                                started)

    def notify(index: int, value: float, point: NNMResult) -> bool:
        return callback is not None and bool(callback(ContinuationProgress(index, value, point, stepper.step,
                                                                          problem.flow_evaluations)))

    return drive(stepper, first, start, max_points, iterations=first.newton_iterations, notify=notify, started=started)


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
    """The NNM of ``mode`` at one ε and one amplitude, by Newton shooting (the exact flow for unilateral springs,
    DOP853 with variational equations for any other law).

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
