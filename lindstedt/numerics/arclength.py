"""The one continuation driver of the periodic-orbit core: branches of ``G(z; λ) = 0``, free or forced.

A branch problem gives a residual ``G(w)`` of the unknowns ``w = (z, λ)`` with its exact Jacobian
``[∂G/∂z, ∂G/∂λ]`` (:class:`~lindstedt.numerics.newton.Evaluation`): the NNM shooting residual of
:mod:`lindstedt.numerics.shooting` (autonomous orbit: unknown period, phase and amplitude conditions; λ = ε,
the energy or the modal amplitude) or the fixed point ``Π(z; λ) − z`` of a forced period map (known period;
λ = Ω or the load scale).  Everything else is here, once:

* :func:`drive` — the loop: the first point, the steps of a :class:`Stepper`, rejected steps, progress, a spent
  budget or a cancel (the points so far are kept), the branch assembled by the stepper;
* :class:`Arclength` — pseudo-arclength continuation (Keller): predictor ``w + h D t`` along the unit tangent t
  (in the variables scaled by D), the null vector of the scaled ``[∂G/∂z, ∂G/∂λ]`` oriented as the previous one;
  corrector: the one damped Newton (:func:`~lindstedt.numerics.newton.newton`) on
  ``[G(w); tᵀ(w − w_k)/D − h] = 0``; step control on the corrector's first correction (the predictor's error,
  aimed at ``predictor_error``) and its iterations; a turn of the tangent beyond ``max_turn`` is rejected;
  a step across the end of the range lands exactly on it by a solve at fixed λ;
* branch switching (:meth:`Arclength.branch_off`): the first point of another branch through a special point;
* the test functions of every branch (:func:`bifurcation_tests`), located by regula falsi (Illinois) along the
  arclength (:meth:`Arclength.locate`): a **fold** (the λ-component of the tangent changes sign), a **branch
  point** (``det [∂G/∂w; tᵀ]`` changes sign while the tangent does not turn back), a **period doubling**
  (``∏(1 + μ)`` over the non-trivial Floquet multipliers: a real multiplier crosses −1) and a
  **Neimark–Sacker** point (the bialternate product ``∏_{i<j}(μ_i μ_j − 1)``: a complex pair crosses the unit
  circle; not defined on conservative branches, whose multipliers come in pairs μ, 1/μ).

A stepper specialises the driver through a few hooks (the branch's residual and scales, the verification of a
point, the landing solve, the branch's result): the NNM stepper of :mod:`lindstedt.numerics.nnm_branch` adds the
resonance-tongue jumps and contact-change refinement of free NNM branches, the forced stepper of
:mod:`lindstedt.numerics.forced_response` the growth rescaling and the rejoining of a period-2k branch.

Examples
--------
>>> import numpy as np
>>> D = np.array([1.0, 1.0])
>>> t = tangent(np.array([[2.0, -1.0]]), D, None, 1.0)        # G(z, λ) = 2 z − λ: the tangent ∝ (1, 2)
>>> np.round(t * 5**0.5, 12).tolist()
[1.0, 2.0]
"""

from __future__ import annotations

import math
import time
from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._errors import BudgetError, Cancelled
from ..limits import checkpoint
from .newton import Evaluation, NewtonOutcome, newton

__all__ = ["Arclength", "Attempt", "Bracket", "Stepper", "drive", "locate_kind", "step_factor", "tangent", "bifurcation_tests",
           "KINDS"]

#: the special points every branch is searched for, in the order they are reported
KINDS = ("fold", "branch-point", "period-doubling", "neimark-sacker")
#: a location whose test is still above this share of its values at the step's ends after this many probes, or
#: above the second share when bracketed, found a jump of the test, not a zero (a smooth zero is approached
#: superlinearly: ~1e-7 of them when bracketed to 1e-9 of a step)
_JUMP_PROBES, _JUMP_RATIO, _ZERO_RATIO = 8, 1e-3, 1e-5


# --------------------------------------------------------------------------- #
# the driver
# --------------------------------------------------------------------------- #
@dataclass(frozen=True)
class Attempt:
    """One step of a stepper: the accepted point, or why it was rejected, or why the branch ends.

    ``point`` is the accepted point at parameter ``value`` (None: rejected, for ``reason``); ``end`` ends the
    branch unsuccessfully; ``complete`` marks a point that completes the branch (solved exactly at the end of
    the range, or where a period-2k branch rejoins its parent) whatever the callback answers, ``reason`` then
    says how; ``iterations`` are the corrector iterations spent; ``jumped`` marks a point reached by a parameter
    jump across an internal resonance and ``rejected`` counts the failed landings before it.
    """

    iterations: int
    value: float = math.nan
    point: Any = None
    reason: str = ""
    end: str | None = None
    complete: bool = False
    jumped: bool = False
    rejected: int = 0


class Stepper(ABC):
    """A continuation method: how to step from the last accepted point, and the branch it assembles.

    ``step`` is the current step (reported in the progress), ``label`` names the parameter in stop reasons.
    :meth:`begin` may return a reason to end the branch; :meth:`reject` is told of a rejected attempt and may
    return one; :meth:`assemble` builds the branch's result from the points.
    """

    name = ""
    label = "λ"

    def __init__(self, start: float, stop: float, *, step: float, min_step: float | None, max_step: float | None,
                 max_halvings: int) -> None:
        self.start, self.stop = start, stop
        self.direction = 1.0 if stop > start else -1.0
        self.span = abs(stop - start)
        self.max_halvings = max_halvings
        self.step = abs(step)
        self.h_min = abs(min_step) if min_step else self.step / 2.0**max_halvings
        self.h_max = abs(max_step) if max_step else 4.0 * self.step
        self.bifurcations: list[Any] = []
        self.brackets: list[Bracket] = []

    def begin(self, first: Any, value: float) -> str | None:
        return None

    def note(self) -> str:
        """What the stop reasons of the driver should add about the state of the method ("" or "; …")."""
        return ""

    @abstractmethod
    def advance(self, points: list[Any], values: list[float]) -> Attempt:
        """One attempted step from the accepted points."""

    @abstractmethod
    def reject(self, attempt: Attempt, values: list[float]) -> str | None:
        """Adapt to a failed attempt; a reason ends the branch."""

    def accept(self, attempt: Attempt) -> None:
        pass

    def reached(self, points: list[Any], values: list[float], attempt: Attempt) -> str:
        """The stop reason of a completed branch."""
        return attempt.reason or f"reached stop = {self.stop:g}"

    @abstractmethod
    def assemble(self, points: list[Any], values: list[float], reason: str, success: bool, rejected: int,
                 iterations: int, started: float) -> Any:
        """The branch's result."""


def drive(stepper: Stepper, first: Any, start: float, max_points: int, *, iterations: int = 0,
          notify: Callable[[int, float, Any], bool] | None = None, started: float | None = None) -> Any:
    """Run ``stepper`` from its verified first point at ``λ = start``: steps, bookkeeping, the assembled branch.

    ``notify(index, value, point)`` is called after every accepted point (the first is index 0); True stops the
    branch ("callback requested stop").  A spent budget or a cancel stops the branch where it is, the points so
    far kept.
    """
    started = time.perf_counter() if started is None else started
    points, values = [first], [start]
    rejected = 0

    def finish(reason: str, success: bool) -> Any:
        return stepper.assemble(points, values, reason, success, rejected, iterations, started)

    def told(index: int, value: float, point: Any) -> bool:
        return bool(notify(index, value, point)) if notify is not None else False

    if told(0, start, first):
        return finish("callback requested stop", False)
    failure = stepper.begin(first, start)
    if failure:
        return finish(failure, False)
    while True:
        if len(points) >= max_points:
            return finish(f"max_points = {max_points} reached at {stepper.label} = {values[-1]:.8g}" + stepper.note(),
                          False)
        try:
            checkpoint("continuation point", len(points), max_points)
            attempt = stepper.advance(points, values)
        except (BudgetError, Cancelled) as stopped:
            return finish(f"stopped after {len(points)} point(s): {stopped}", False)
        iterations += attempt.iterations
        rejected += attempt.rejected
        if attempt.end is not None:
            return finish(attempt.end, False)
        if attempt.point is None:
            rejected += 1
            failure = stepper.reject(attempt, values)
            if failure:
                return finish(failure, False)
            continue
        points.append(attempt.point)
        values.append(attempt.value)
        stepper.accept(attempt)
        requested = told(len(points) - 1, attempt.value, attempt.point)
        if attempt.complete:
            return finish(stepper.reached(points, values, attempt), True)
        if requested:
            return finish("callback requested stop", False)


# --------------------------------------------------------------------------- #
# pieces of pseudo-arclength continuation
# --------------------------------------------------------------------------- #
def tangent(matrix: np.ndarray, scales: np.ndarray, previous: np.ndarray | None, direction: float) -> np.ndarray:
    """Unit null vector (variables scaled by ``scales``) of ``[∂G/∂z, ∂G/∂λ]``, oriented like ``previous``, or
    with its λ-component along ``direction`` when there is none."""
    vector = np.linalg.svd(matrix * scales[None, :])[2][-1]
    if previous is not None:
        if float(vector @ previous) < 0:
            vector = -vector
    elif vector[-1] * direction < 0:
        vector = -vector
    return vector / np.linalg.norm(vector)


def step_factor(outcome: NewtonOutcome, target: float, smooth: bool = True) -> float:
    """Factor of the next step from the corrector: its first correction (the predictor's error, O(h²)) and its
    iterations; never growing where the residual is not smooth (``smooth=False``: across a contact change).

    The error factor ``sqrt(target / first correction)`` (kept in [0.5, 2]) and the iteration factor (×1.5
    after ≤ 2 iterations) each may grow the step; ≥ 4 iterations stop the growth, ≥ 5 shrink it (×0.6 at least).

    Examples
    --------
    >>> step_factor(NewtonOutcome(True, "", np.zeros(1), 2, steps=(2e-3,)), 2e-3)   # on target, quick: grow
    1.5
    >>> step_factor(NewtonOutcome(True, "", np.zeros(1), 6, steps=(8e-3,)), 2e-3)   # slow: shrink
    0.5
    """
    iterations, steps = outcome.iterations, outcome.steps
    error = min(max(math.sqrt(target / steps[0]), 0.5), 2.0) if steps and steps[0] > 0 else 2.0
    if iterations >= 5:
        return min(error, 0.6)
    factor = max(error, 1.5 if iterations <= 2 else 1.0)
    if iterations >= 4:
        factor = min(factor, 1.0)
    return min(factor, 1.0) if not smooth else factor


def bifurcation_tests(multipliers: np.ndarray | None, unit_tangent: np.ndarray, scaled_jacobian: np.ndarray, *,
                   conservative: bool) -> dict[str, float]:
    """The test functions of :data:`KINDS` at a point: zero at the special point, changing sign across it.

    ``multipliers`` are the non-trivial Floquet multipliers (every one of a forced orbit); ``scaled_jacobian``
    is ``[∂G/∂z, ∂G/∂λ] · D``.  NaN where a test does not apply (the Neimark–Sacker test on conservative
    branches and with fewer than four multipliers).

    Examples
    --------
    A real multiplier past −1 makes the period-doubling test negative:

    >>> tests = bifurcation_tests(np.array([-1.2, 0.5]), np.array([0.0, 1.0]), np.array([[1.0, 0.0]]),
    ...                           conservative=False)
    >>> tests["fold"], round(tests["period-doubling"], 12), tests["branch-point"]
    (1.0, -0.3, 1.0)
    """
    bordered = np.vstack([scaled_jacobian, unit_tangent])
    tests = {"fold": float(unit_tangent[-1]),
             "branch-point": float(np.linalg.det(bordered)) if bordered.shape[0] == bordered.shape[1] else math.nan,
             "period-doubling": math.nan, "neimark-sacker": math.nan}
    if multipliers is not None and len(multipliers):
        mu = np.asarray(multipliers, dtype=complex)
        tests["period-doubling"] = float(np.real(np.prod(1.0 + mu)))
        if not conservative and len(mu) >= 4:
            tests["neimark-sacker"] = float(np.real(np.prod([mu[i] * mu[j] - 1 for i in range(len(mu))
                                                             for j in range(i + 1, len(mu))])))
    return tests


def locate_kind(kind: str, f0: float, f1: float, h: float, probe: Callable[[float], tuple[float, Any] | None], *,
                tol: float, max_iterations: int = 60) -> tuple[Any, float] | None:
    """Regula falsi (Illinois) on a test function along the arclength σ ∈ [0, h] of one step.

    ``probe(σ)`` corrects the predictor at σ and returns ``(test value, located data)``, None on failure.
    Returns the data and the test value at the last probe, an end of a bracket of the zero at most ``tol`` wide
    (or after ``max_iterations`` probes), or None — also when the test does not go to zero but jumps (still
    above ``_JUMP_RATIO`` of its values at the ends after ``_JUMP_PROBES`` probes, or above ``_ZERO_RATIO`` of
    them at the end: the test is discontinuous where the residual is not smooth, e.g. at a grazing).

    Examples
    --------
    >>> found = locate_kind("fold", -1.0, 3.0, 2.0, lambda s: (s * s - 0.5, s), tol=1e-12)
    >>> abs(found[0] - 0.5**0.5) < 1e-12
    True
    >>> locate_kind("fold", -1.0, 1.0, 2.0, lambda s: (-1.0 if s < 1 else 1.0, s), tol=1e-12) is None  # a jump
    True
    """
    a, fa, b, fb = 0.0, f0, h, f1
    scale = max(abs(f0), abs(f1))
    found = None
    for probes in range(1, max_iterations + 1):
        c = b - fb * (b - a) / (fb - fa)
        if not (min(a, b) < c < max(a, b)):
            c = (a + b) / 2
        probed = probe(c)
        if probed is None:
            return None
        fc, data = probed
        found = (data, fc)
        if fc == 0:
            break
        if probes >= _JUMP_PROBES and abs(fc) > _JUMP_RATIO * scale:
            return None  # the test jumps across the step (the residual is not smooth there): not a zero
        if fc * fb < 0:
            a, fa = b, fb
        else:
            fa /= 2
        b, fb = c, fc
        if abs(b - a) <= tol:
            break
    if found is None or abs(found[1]) > _ZERO_RATIO * scale:
        return None  # not brought near zero: a jump of the test, not a special point
    return found


def changes(before: dict[str, float], after: dict[str, float], *, turned_back: bool) -> list[str]:
    """The kinds whose test function changes sign between two points (a branch point not where the branch
    folds: both tests change sign across a fold when the orientation is kept by the λ-component)."""
    kinds = []
    for kind in KINDS:
        f0, f1 = before[kind], after[kind]
        if not (math.isfinite(f0) and math.isfinite(f1) and f0 * f1 < 0):
            continue
        if kind == "neimark-sacker" and min(abs(f0), abs(f1)) <= 1e-9:
            continue
        if kind == "branch-point" and turned_back:
            continue
        kinds.append(kind)
    return kinds


@dataclass(frozen=True)
class Bracket:
    """A sign change of the test function of ``kind`` over one step, from the base point (``w``, ``scales``,
    ``unit`` tangent, the verified ``point``) over the arclength ``h``: what locating it needs, kept by steppers
    that locate lazily (:attr:`Arclength.lazy_location`)."""

    kind: str
    index: int
    f0: float
    f1: float
    h: float
    w: np.ndarray
    scales: np.ndarray
    unit: np.ndarray
    point: Any
    within: float | None = None


# --------------------------------------------------------------------------- #
# the pseudo-arclength stepper
# --------------------------------------------------------------------------- #
class Arclength(Stepper):
    """Pseudo-arclength continuation (see the module docstring); subclasses give the branch through hooks.

    Hooks: :meth:`evaluate` (residual and ``[∂G/∂z, ∂G/∂λ]`` at w), :meth:`scales_of` (D at a point),
    :meth:`verify` (the point at a corrected w, or the reason it is not one), :meth:`multipliers` (the
    non-trivial Floquet multipliers of a point), :meth:`land` (a solve at fixed λ), :meth:`boundary` (where the
    range ends), :meth:`screen` (branch-specific checks of a verified point: may reject, end or jump), and
    :meth:`assemble`.  The attributes ``predictor_error``, ``max_turn`` (the cosine below which the tangent
    turned too much), ``step_tol`` (the corrector's step convergence) and ``conservative`` (no Neimark–Sacker
    test) set the method.
    """

    name = "arclength"
    #: keep the sign changes as :class:`Bracket` (``self.brackets``) to be located on demand (:meth:`resolve`)
    lazy_location = False
    predictor_error = 2e-3
    max_turn = 0.9
    step_tol: float | None = None
    conservative = False
    locate_tol = 1e-9
    tol = 1e-10
    max_iterations = 10

    # ------------------------------------------------------------ hooks
    @abstractmethod
    def evaluate(self, w: np.ndarray) -> Evaluation:
        """G(w) (rows scaled) and ``[∂G/∂z, ∂G/∂λ]`` with respect to the unscaled w."""

    @abstractmethod
    def scales_of(self, w: np.ndarray, evaluation: Evaluation) -> np.ndarray:
        """The typical magnitudes D of the unknowns at w (the row scaling of G may follow them)."""

    @abstractmethod
    def verify(self, w: np.ndarray, outcome: NewtonOutcome) -> tuple[Any, str]:
        """(the point at w, "") or (None, why it is not one)."""

    @abstractmethod
    def multipliers(self, point: Any, evaluation: Evaluation) -> np.ndarray | None:
        """The non-trivial Floquet multipliers at a point."""

    @abstractmethod
    def land(self, value: float, guess: np.ndarray) -> tuple[Any, int, str]:
        """(the point at λ = value solved from the guess of z or None, Newton iterations, message)."""

    @abstractmethod
    def unknowns_of(self, point: Any, value: float) -> np.ndarray:
        """The unknowns w = (z, λ) of a point."""

    def check_value(self, value: float, iterations: int) -> Attempt | None:
        """A rejection of a corrected λ before anything else (e.g. behind start), else None."""
        return None

    def landing_failed(self, iterations: int, target: float, message: str) -> Attempt:
        """The attempt when the solve exactly at the end of the range failed (default: the branch ends)."""
        return Attempt(iterations, target, end=f"the last point at {self.label} = {target:.8g} failed: {message}")

    def boundary(self, value: float) -> float | None:
        """The end of the range crossed by a step to λ = value (it lands there), else None."""
        return self.stop if self.direction * (value - self.stop) >= 0 else None

    def screen(self, point: Any, value: float, values: list[float], new_tangent: np.ndarray,
               new_scales: np.ndarray, turn: float, iterations: int) -> Attempt | None:
        """Branch-specific checks of a verified point before it is accepted; an Attempt overrides the step."""
        return None

    def turn_counts(self, point: Any) -> bool:
        """Whether a turn of the tangent beyond ``max_turn`` rejects the step at this point."""
        return True

    def admissible(self, value: float, within: float | None) -> bool:
        """Whether a special point located at λ = value is reported (inside the range followed)."""
        end = self.stop if within is None else within
        return self.direction * (value - self.start) >= 0 and self.direction * (value - end) <= 0

    def complete_at(self, point: Any, w: np.ndarray, values: list[float]) -> str | None:
        """A reason when the branch is complete at an accepted point (before the end of the range)."""
        return None

    @abstractmethod
    def bifurcation(self, kind: str, w: np.ndarray, evaluation: Evaluation, test: float, index: int) -> Any:
        """The record of a special point located at w (with the residual's evaluation there), None to drop it."""

    # ------------------------------------------------------------ machinery
    def corrector(self, base: np.ndarray, scales: np.ndarray, unit: np.ndarray, sigma: float, *,
                  locating: bool = False, start: np.ndarray | None = None) -> NewtonOutcome:
        """Newton on ``[G(w); tᵀ(w − base)/D − σ] = 0`` from the predictor ``base + σ D t`` (or from ``start``).

        ``locating``: a probe of a special point — converged on the residual alone (the last evaluation, whose
        test functions are read, is then at the returned point) and through a branch point, where the augmented
        Jacobian is singular."""

        def augmented(candidate: np.ndarray) -> Evaluation:
            inner = self.evaluate(candidate)
            if not inner.success:
                return inner
            constraint = float(unit @ ((candidate - base) / scales)) - sigma
            return Evaluation(True, "", np.r_[inner.residual, constraint],
                              np.vstack([inner.jacobian, unit / scales]), inner.step_bound, inner, inner.singular)

        return newton(augmented, base + sigma * unit * scales if start is None else start, scales, tol=self.tol,
                      max_iterations=self.max_iterations, step_tol=None if locating else self.step_tol,
                      allow_singular=locating)

    #: the orientation of the first tangent (scaled variables); None: towards stop
    hint: np.ndarray | None = None

    def begin(self, first: Any, value: float) -> str | None:
        return self.start_at(self.unknowns_of(first, value), first, self.hint)

    def tests_at(self, w: np.ndarray, outcome: NewtonOutcome, point: Any, unit: np.ndarray,
                 scales: np.ndarray) -> dict[str, float]:
        """The test functions at an accepted point reached without them (a jump's landing)."""
        inner = outcome.last.data
        return bifurcation_tests(self.multipliers(point, inner), unit, inner.jacobian * scales[None, :],
                                 conservative=self.conservative)

    def branch_off(self, w_star: np.ndarray, direction: np.ndarray, h: float) -> NewtonOutcome:
        """Branch switching: the first point of another branch through the special point ``w_star``.

        Predictor ``w* + h D d`` along the unit direction d (scaled variables) of the other branch — the
        eigenvector of the multiplier −1 at a period doubling of the doubled-period map, the second null vector
        at a branch point — and corrector in the plane ⟂ d: it lands on the other branch on either side of the
        pitchfork.  The new branch's first tangent is then oriented along d (:attr:`hint`).
        """
        self.hint = direction
        return self.corrector(w_star, self.scales_of(w_star, None), direction, h)

    def start_at(self, w: np.ndarray, point: Any, hint: np.ndarray | None = None) -> str | None:
        """Set the branch's first point w (its tangent oriented along ``hint`` or towards stop)."""
        evaluation = self.evaluate(w)
        if not evaluation.success:
            return f"tangent failed: {evaluation.message}"
        self.w, self.scales, self.last = w, self.scales_of(w, evaluation), point
        self.tangent = tangent(evaluation.jacobian, self.scales, hint, self.direction)
        self.tests = bifurcation_tests(self.multipliers(point, evaluation), self.tangent,
                                       evaluation.jacobian * self.scales[None, :], conservative=self.conservative)
        return None

    #: the step under way: (w, scales, tangent, corrector outcome, point, tests, base index, λ-extent) of the point
    #: an accepted attempt takes; None when the attempt is not a regular step (a landing at the end of the range)
    pending: tuple | None = None

    def advance(self, points: list[Any], values: list[float]) -> Attempt:
        self.pending = None
        w, scales, unit, h = self.w, self.scales, self.tangent, self.step
        outcome = self.corrector(w, scales, unit, h)
        iterations = outcome.iterations
        if not outcome.success:
            return Attempt(iterations, reason=outcome.message)
        candidate = outcome.unknowns
        value = float(candidate[-1])
        inner = outcome.last.data
        early = self.check_value(value, iterations)
        if early is not None:
            return early
        target = self.boundary(value)
        if target is not None:
            return self.finish_at(target, w, candidate, outcome, h, iterations, values)
        point, why = self.verify(candidate, outcome)
        if point is None:
            return Attempt(iterations, value, reason=why)
        new_scales = self.scales_of(candidate, inner)
        previous = unit * scales / new_scales
        previous /= np.linalg.norm(previous)
        new_tangent = tangent(inner.jacobian, new_scales, previous, self.direction)
        turn = float(new_tangent @ previous)
        self.spent = (iterations, 0)
        screened = self.screen(point, value, values, new_tangent, new_scales, turn, iterations)
        if screened is not None:
            return screened
        iterations, rejected = self.spent
        if turn < self.max_turn and h > self.h_min and self.turn_counts(point):
            return Attempt(iterations, value, reason=f"the tangent turned too much (cos = {turn:.3f})")
        new_tests = bifurcation_tests(self.multipliers(point, inner), new_tangent,
                                      inner.jacobian * new_scales[None, :], conservative=self.conservative)
        self.pending = (candidate, new_scales, new_tangent, outcome, point, new_tests, len(values) - 1,
                        abs(value - values[-1]))
        complete = self.complete_at(point, candidate, values)
        if complete:
            return Attempt(iterations, value, point, reason=complete, complete=True, rejected=rejected)
        return Attempt(iterations, value, point, rejected=rejected)

    def finish_at(self, target: float, w: np.ndarray, candidate: np.ndarray, outcome: NewtonOutcome, h: float,
                  iterations: int, values: list[float]) -> Attempt:
        """A step across the end of the range: the special points up to there, then the point exactly at it."""
        inner = outcome.last.data
        new_scales = self.scales_of(candidate, inner)
        previous = self.tangent * self.scales / new_scales
        new_tangent = tangent(inner.jacobian, new_scales, previous / np.linalg.norm(previous), self.direction)
        tests = bifurcation_tests(self.multipliers(None, inner), new_tangent, inner.jacobian * new_scales[None, :],
                                  conservative=self.conservative)
        self.search(self.tests, tests, h, len(values) - 1, within=target)
        fraction = (target - values[-1]) / (float(candidate[-1]) - values[-1]) if candidate[-1] != values[-1] else 1.0
        guess = w[:-1] + fraction * (candidate[:-1] - w[:-1])
        point, more, message = self.land(target, guess)
        iterations += more
        if point is None:
            return self.landing_failed(iterations, target, message)
        return Attempt(iterations, target, point, complete=True)

    def search(self, before: dict[str, float], after: dict[str, float], h: float, index: int, *,
               within: float | None = None, smooth: bool = True) -> None:
        """Locate the special points whose test function changes sign over the step of length h from self.w
        (only the fold where the residual is not smooth over the step: the other tests may jump there)."""
        turned_back = before["fold"] * after["fold"] < 0
        for kind in changes(before, after, turned_back=turned_back):
            if not smooth and kind != "fold":
                continue
            bracket = Bracket(kind, index, before[kind], after[kind], h, self.w, self.scales, self.tangent, self.last,
                              within)
            if self.lazy_location:
                self.brackets.append(bracket)
                continue
            record = self.resolve(bracket)
            if record is not None:
                self.bifurcations.append(record)

    def resolve(self, bracket: Bracket) -> Any:
        """Locate the special point of a :class:`Bracket` (the stepper's base state is set to the bracket's);
        its record, or None where the test jumps instead of vanishing or the point lies outside the range."""
        self.w, self.scales, self.tangent, self.last = bracket.w, bracket.scales, bracket.unit, bracket.point
        found = self.locate(bracket.kind, bracket.f0, bracket.f1, bracket.h)
        if found is None:
            return None
        (w, evaluation), test = found
        if not self.admissible(float(w[-1]), bracket.within):
            return None
        return self.bifurcation(bracket.kind, w, evaluation, test, bracket.index)

    def locate(self, kind: str, f0: float, f1: float, h: float) -> tuple[tuple[np.ndarray, Evaluation], float] | None:
        """The special point of ``kind`` on the step from self.w: regula falsi on its test along the arclength."""
        base, scales, unit = self.w, self.scales, self.tangent
        known: list[tuple[float, np.ndarray]] = [(0.0, base)]  # corrected points of this step: warm starts

        def probe(sigma: float) -> tuple[float, Any] | None:
            near, w_near = min(known, key=lambda item: abs(item[0] - sigma))
            outcome = self.corrector(base, scales, unit, sigma, locating=True,
                                     start=w_near + (sigma - near) * unit * scales)
            if not outcome.success:
                return None
            known.append((sigma, outcome.unknowns))
            inner = outcome.last.data
            local = tangent(inner.jacobian, scales, unit, self.direction)
            tests = bifurcation_tests(self.multipliers(None, inner), local, inner.jacobian * scales[None, :],
                                      conservative=self.conservative)
            return tests[kind], (outcome.unknowns, inner)

        return locate_kind(kind, f0, f1, h, probe, tol=self.locate_tol)

    def accept(self, attempt: Attempt) -> None:
        if self.pending is None:
            return  # landed at the end of the range: its special points were searched by finish_at
        candidate, scales, unit, outcome, point, tests, index, _ = self.pending
        self.search(self.tests, tests, self.step, index)
        if attempt.complete:
            return
        smooth = self.smooth_step(point)
        self.w, self.scales, self.tangent, self.last, self.tests = candidate, scales, unit, point, tests
        self.step = min(max(self.step * step_factor(outcome, self.predictor_error, smooth), self.h_min), self.h_max)

    def smooth_step(self, point: Any) -> bool:
        """Whether the residual was smooth over the step to ``point`` (the step may grow)."""
        return True

    def reject(self, attempt: Attempt, values: list[float]) -> str | None:
        self.step *= 0.5
        if self.step < self.h_min:
            return (f"step size {self.step:.2e} below min_step {self.h_min:.2e} at {self.label} = "
                    f"{values[-1]:.8g}: {attempt.reason}")
        return None
