"""Branches of NNMs of  M X'' + K X + ε W (A X − b)_+ = 0 : the steppers of the core driver for free orbits.

The NNM of mode j is a zero of the shooting residual ``G(z; λ)`` of :class:`~lindstedt.numerics.shooting.NNMShooting`
(unknowns ``z = (X0, T)`` or ``(X0, X1, T)``; λ = ε, the energy or the modal amplitude, :class:`_Path`).  Its
branches run on the one driver of the periodic-orbit core (:func:`~lindstedt.numerics.arclength.drive`) with one
of three steppers (``continue_nnm(method=...)``):

``"arclength"`` — :class:`_NNMArclength`, the core's pseudo-arclength stepper
    (:class:`~lindstedt.numerics.arclength.Arclength`: tangent, corrector by the core's Newton, step control,
    fold / branch-point / period-doubling tests and their location on the non-trivial Floquet multipliers) with
    what free NNM branches add: every point verified over a full period; a step across which the springs
    switching along the orbit change is refined (the backbone has a corner there); where the branch turns
    vertical towards another mode (an internal-resonance tongue) a parameter jump across it; where no jump
    lands, the turn followed as a fold until the branch leaves mode j.
``"natural"`` — :class:`_Natural`, fixed-λ Newton solves at ``λ_k + step`` (secant guess), halved on failure.
``"seed"`` — :class:`_Seed`, the seed's algorithm kept as the baseline: natural continuation in ε with a
    constant increment and ``scipy.optimize.root(method="hybr")`` without Jacobian on the seed's square
    residual ``[X(T) − X0, X'(T) − X1, E − c ε]`` (no phase condition).

The first point is given to the driver (:func:`lindstedt.numerics.continue_nnm` solves it by
:func:`~lindstedt.numerics.nnm_point`'s route); the branch is an :class:`~lindstedt.numerics.NNMBranch`.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._errors import ProblemError
from .arclength import Arclength, Attempt, Stepper, step_factor
from .arclength import tangent as unit_tangent
from .forced_results import Bifurcation
from .newton import Evaluation, NewtonOutcome, newton
from .results import NNMBranch, NNMResult, _branch_events
from .sensitivity import _check_epsilon, _map_over
from .nnm_guesses import _impossible_amplitude
from .shooting import _STEP_TOL, _TWO_PI, NNMShooting, _Amplitude, nnm_energy

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
# what every NNM stepper shares: the problem, the parameter, the branch
# --------------------------------------------------------------------------- #
class _NNMStepper(Stepper):
    """A stepper on an NNM shooting problem; assembles the :class:`NNMBranch` (jumps, contact changes)."""

    def __init__(self, problem: NNMShooting, path: _Path, start: float, stop: float, *, step: float | None,
                 min_step: float | None, max_step: float | None, max_halvings: int, options: dict[str, Any]) -> None:
        self.problem, self.path, self.options = problem, path, options
        self.span = abs(stop - start)
        super().__init__(start, stop, step=step or self.default_step(), min_step=min_step, max_step=max_step,
                         max_halvings=max_halvings)
        self.label = path.parameter
        self.tol, self.max_iterations = options["tol"], options["max_iterations"]
        self.jumps: list[int] = []
        self.causes: list[str] = []  # what each jump stepped across
        self.accepted = 0  # points accepted after the first

    def default_step(self) -> float:
        """The initial step when none is given: 1/50 of the parameter range."""
        return self.span / 50.0

    def accept(self, attempt: Attempt) -> None:
        if attempt.jumped:
            self.jumps.append(self.accepted)
            self.causes.append(attempt.reason or "a turn of the branch")
        self.accepted += 1

    def reached(self, points: list[NNMResult], values: list[float], attempt: Attempt) -> str:
        text = f"reached stop = {self.stop:g}"
        changes = [k for k in range(len(points) - 1) if points[k].contact_springs != points[k + 1].contact_springs]
        if changes:
            where = ", ".join(f"{values[k]:.6g}–{values[k + 1]:.6g} ({_springs(points[k])} → {_springs(points[k + 1])})"
                              for k in changes[:6]) + (", …" if len(changes) > 6 else "")
            text += (f"; {len(changes)} contact change(s) — the springs switching along the orbit change, a spring "
                     f"grazes it: {self.label} in {where} (NNMBranch.contact_changes)")
        if self.jumps:
            where = "; ".join(f"{values[k]:.4g}–{values[k + 1]:.4g}: {cause}" for k, cause in zip(self.jumps, self.causes))
            text += (f"; {len(self.jumps)} part(s) of the branch crossed by parameter jumps, not followed "
                     f"({self.label} in {where}; NNMBranch.jumps)")
        return text

    def assemble(self, points: list[NNMResult], values: list[float], reason: str, success: bool, rejected: int,
                 iterations: int, started: float) -> NNMBranch:
        folds, stability, contact = _branch_events(points, values)
        return NNMBranch(
            success=success, stop_reason=reason, method=self.name, parameter=self.path.parameter,
            points=tuple(points), parameter_values=np.array(values, dtype=float), folds=folds,
            stability_changes=stability, contact_changes=contact, flow_evaluations=self.problem.flow_evaluations,
            newton_iterations=iterations, rejected_steps=rejected, wall_time=time.perf_counter() - started,
            system=self.problem.system, jumps=tuple(self.jumps),
            _locator=_Locator(self.problem, self.path, self.start, self.stop, self.options, tuple(self.brackets))
            if self.brackets else None,
        )


@dataclass(frozen=True)
class _Locator:
    """The special points bracketed along an NNM branch, located on demand (``NNMBranch.bifurcations``).

    Holds what a stepper needs to run the core's location again from each bracket's base point (the problem,
    the parameter, the solver options); picklable (the problem drops its flow caches).
    """

    problem: NNMShooting
    path: _Path
    start: float
    stop: float
    options: dict[str, Any]
    brackets: tuple[Any, ...]

    def __call__(self) -> tuple[Bifurcation, ...]:
        stepper = _NNMArclength(self.problem, self.path, self.start, self.stop, step=None, min_step=None,
                                max_step=None, max_halvings=12, options=self.options)
        records = (stepper.resolve(bracket) for bracket in self.brackets)
        return tuple(record for record in records if record is not None)


# --------------------------------------------------------------------------- #
# natural-parameter continuation (and the seed's algorithm, below)
# --------------------------------------------------------------------------- #
class _Natural(_NNMStepper):
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

    def advance(self, points: list[NNMResult], values: list[float]) -> Attempt:
        target = values[-1] + self.direction * self.step
        if self.direction * (target - self.stop) > -1e-9 * abs(self.stop - self.start):  # never leave a sliver before stop
            target = self.stop
        result = self.solve(target, self.guess(points, values, target))
        if not result.success:
            return Attempt(result.newton_iterations, target, reason=result.message)
        return Attempt(result.newton_iterations, target, result, complete=target == self.stop)

    def reject(self, attempt: Attempt, values: list[float]) -> str | None:
        self.halvings += 1
        self.step *= 0.5
        if self.halvings > self.max_halvings:
            return (f"step halved {self.max_halvings} times without convergence at {self.label} = "
                    f"{attempt.value:.6g}: {attempt.reason}")
        if self.step < self.h_min:  # accepted points reset the halvings: the step itself is bounded below
            return (f"step size {self.step:.2e} below min_step {self.h_min:.2e} at {self.label} = "
                    f"{attempt.value:.6g}: {attempt.reason}")
        return None

    def accept(self, attempt: Attempt) -> None:
        super().accept(attempt)
        self.halvings = 0


def _springs(result: NNMResult) -> str:
    """The springs switching along an orbit, in words ("no contact" when none)."""
    if not result.contact_springs:
        return "no contact"
    return "spring" + ("s " if len(result.contact_springs) > 1 else " ") + ", ".join(map(str, result.contact_springs))


def _unknowns_of(problem: NNMShooting, result: NNMResult) -> np.ndarray:
    return problem._join(result.release_position, result.release_velocity, result.period)



# --------------------------------------------------------------------------- #
# pseudo-arclength continuation of NNMs
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


class _NNMArclength(_NNMStepper, Arclength):
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
    conservative = True
    lazy_location = True  # located when NNMBranch.bifurcations is first read (lazy work: a continuation needs none)
    step_tol = _STEP_TOL
    #: reject a first point whose tangent's λ-component is below this (None: no check)
    minimum_start_slope: float | None = None

    def default_step(self) -> float:
        """The initial step when none is given: 1/50 in scaled arclength (λ is scaled by the range)."""
        return 1.0 / 50.0

    # ------------------------------------------------------------ hooks of the core
    def evaluate(self, w: np.ndarray) -> Evaluation:
        eps, amplitude = self.path.at(float(w[-1]))
        out = self.problem.evaluate(w[:-1], eps, amplitude=amplitude, d_epsilon=self.path.parameter == "epsilon")
        if not out["success"]:
            return Evaluation(False, out["message"])
        out["unknowns"] = w
        return Evaluation(True, "", out["residual"], np.column_stack([out["jacobian"], self.path.derivative(out)]),
                          data=out)

    def at_fixed(self, w: np.ndarray) -> Evaluation:
        """The residual at fixed λ (the Jacobian without its λ column; ``data``: the full evaluation)."""
        full = self.evaluate(w)
        if not full.success:
            return full
        return Evaluation(True, "", full.residual, full.jacobian[:, :-1], data=full)

    def scales_of(self, w: np.ndarray, evaluation: Evaluation | None) -> np.ndarray:
        """Column scales at w (the problem's residual rows are scaled by the same release state and period)."""
        eps, amplitude = self.path.at(float(w[-1]))
        x0, _, period = self.problem.split(w[:-1])
        self.problem.set_scales(eps, x0, period, amplitude)
        return np.r_[self.problem.column_scales(), self.span]

    def verify(self, w: np.ndarray, outcome: NewtonOutcome) -> tuple[Any, str]:
        eps, amplitude = self.path.at(float(w[-1]))
        result = self.problem.verify(w[:-1], eps, verify_tol=self.options["verify_tol"],
                                     stability_tol=self.options["stability_tol"], iterations=outcome.iterations,
                                     amplitude=amplitude)
        return (result, "") if result.success else (None, result.message)

    def multipliers(self, point: NNMResult | None, evaluation: Evaluation) -> np.ndarray:
        """The non-trivial multipliers of a verified point, else from the evaluation's sensitivity
        (:meth:`NNMShooting.monodromy_of`): no verification flow, so the special points are located on the
        corrector's evaluations alone."""
        if point is not None:
            return point.nontrivial_multipliers
        out = evaluation.data
        w = out["unknowns"]
        eps, _ = self.path.at(float(w[-1]))
        x0, v0, _ = self.problem.split(w[:-1])
        monodromy = self.problem.monodromy_of(out)
        return self.problem.floquet(monodromy, np.r_[v0, self.problem.system.acceleration(x0, eps)])[1]

    def land(self, value: float, guess: np.ndarray) -> tuple[Any, int, str]:
        result = self.problem._solve(guess, *self.path.at(value), **self.options)
        return (result if result.success else None), result.newton_iterations, result.message

    def landing_failed(self, iterations: int, target: float, message: str) -> Attempt:
        return Attempt(iterations, target, reason=f"final point at stop failed: {message}")

    def check_value(self, value: float, iterations: int) -> Attempt | None:
        if self.direction * (value - self.start) < 0:  # a step too long for the curvature, or a fold: retry shorter
            return Attempt(iterations, value, reason=f"the corrector returned behind start = {self.start:g} "
                           f"({self.path.parameter} = {value:.6g}): the branch folds back there or the step is too long")
        return None

    def smooth_step(self, point: NNMResult) -> bool:
        return point.contact_springs == self.last.contact_springs

    def bifurcation(self, kind: str, w: np.ndarray, evaluation: Evaluation, test: float,
                    index: int) -> Bifurcation | None:
        point, _ = self.verify(w, NewtonOutcome(True, "", w, 0))  # the located orbit, over one full period
        if point is None or point.contact_springs != self.last.contact_springs:
            return None
        return Bifurcation(kind, point.frequency, np.abs(point.release_position),
                           np.r_[point.release_position, point.release_velocity], point.floquet_multipliers, index,
                           float(w[-1]), test)

    # ------------------------------------------------------------ the branch's shape
    def slope(self, unit: np.ndarray) -> float:
        """The λ-component of a unit tangent, positive towards ``stop``."""
        return self.direction * float(unit[-1])

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

    def unknowns_of(self, point: NNMResult, value: float) -> np.ndarray:
        return np.r_[_unknowns_of(self.problem, point), value]

    def begin(self, first: NNMResult, value: float) -> str | None:
        failure = super().begin(first, value)
        if failure:
            return failure
        if self.minimum_start_slope is not None and self.slope(self.tangent) < self.minimum_start_slope:
            return (f"the first point at {self.label} = {value:.6g} lies in a turn of the branch (λ-component of the "
                    f"unit tangent {self.slope(self.tangent):.3f} < {self.minimum_start_slope:g})")
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
    def advance(self, points: list[NNMResult], values: list[float]) -> Attempt:
        if self.rescue is not None:  # the step collapsed: step across instead of shrinking to nothing
            reason, self.rescue, self.pending = self.rescue, None, None
            return self.jump(0, reason, collapse=True)
        return super().advance(points, values)

    def screen(self, result: NNMResult, value: float, values: list[float], new_tangent: np.ndarray,
               new_scales: np.ndarray, turn: float, iterations: int) -> Attempt | None:
        problem, h = self.problem, self.step
        floor = _RELATIVE_MODE_SHARE * self.last_regular_share
        if self.following and result.mode_share < floor:
            return Attempt(iterations, value, end=(
                f"{self.following}, and it leaves mode {problem.mode} at {self.label} = {value:.6g} "
                f"(mode-{problem.mode} share {result.mode_share:.1%}, below half its {self.last_regular_share:.1%} "
                f"where the turn began)"))
        contact_changed = result.contact_springs != self.last.contact_springs
        if contact_changed and h > self.h_refine:  # resolve the contact change: the backbone bends there
            return Attempt(iterations, value, reason=(
                f"the springs switching along the orbit change within the step ({_springs(self.last)} → "
                f"{_springs(result)}): the step is refined towards the contact change"))
        reference, slope = self.reference(), self.slope(new_tangent)
        # across a contact change (a small step by now) the tangent may turn and the λ-component drop: the branch
        # has a corner or a steep part there (contact onset: dω/dλ jumps), not a resonance tongue — it is followed
        turned = not (turn >= self.max_turn or h <= self.h_min or contact_changed)
        vertical = not contact_changed and reference is not None and (
            slope < _VERTICAL_RATIO * reference or (turned and slope < _REGULAR_RATIO * reference))
        other = self.other_mode(new_tangent, new_scales) if vertical else None
        rejected = 0
        if other is not None and not self.following:
            # the branch turns vertical towards another mode: a resonance tongue ahead — do not climb it, step
            # across (if that fails, it is a fold of mode j: follow it).  Turning vertical in mode j itself is a
            # steep part of the backbone (or a fold of mode j): followed, the step adapting to its curvature
            self.scales_of(self.w, None)  # the residual scaling of the base point
            jump = self.jump(iterations, self.resonance(other, result), extent=abs(value - values[-1]))
            if jump.end is None:
                return jump
            self.following = (f"{jump.end}; the branch is followed through the turn from {self.label} = "
                              f"{values[-1]:.6g}")
            self.scales_of(np.r_[_unknowns_of(problem, result), value], None)
            iterations, rejected = jump.iterations, jump.rejected
        if turned:
            return Attempt(iterations, value, reason=f"the tangent turned too much (cos = {turn:.3f})",
                           rejected=rejected)
        self.spent = (iterations, rejected)
        return None

    def turn_counts(self, point: NNMResult) -> bool:
        return False  # screen() judged the turn

    def reject(self, attempt: Attempt, values: list[float]) -> str | None:
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

    def accept(self, attempt: Attempt) -> None:
        _NNMStepper.accept(self, attempt)
        if self.pending is None:
            return  # landed on stop (by a corrector's step or a jump)
        candidate, scales, unit, outcome, result, tests, _, extent = self.pending
        contact_changed = result.contact_springs != self.last.contact_springs
        if not attempt.jumped and tests is not None:
            self.search(self.tests, tests, self.step, self.accepted - 1, smooth=not contact_changed)
        self.w, self.scales, self.tangent, self.last = candidate, scales, unit, result
        self.tests = tests if tests is not None else self.tests_at(candidate, outcome, result, unit, scales)
        self.rescued = False
        if contact_changed:  # a new contact regime: the λ-component of the tangent has a new level
            self.slopes.clear()
        slope = self.slope(unit)
        reference = self.reference()
        if not attempt.jumped:
            self.extents.append(extent)
        if reference is None or slope >= _REGULAR_RATIO * reference:
            self.slopes.append(slope)
            self.regular = (unit, scales, self.step)
            self.last_regular_share = result.mode_share
            self.following = None
        if attempt.jumped:
            return  # the step was reset by the jump
        self.step = min(max(self.step * step_factor(outcome, self.predictor_error, not contact_changed), self.h_min),
                        self.h_max)

    # ------------------------------------------------------------ parameter jumps
    def jump(self, iterations: int, why: str, collapse: bool = False, extent: float = 0.0) -> Attempt:
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
            outcome = newton(lambda z, target=target: self.at_fixed(np.r_[z, target]), guess, base_scales[:-1],
                             tol=options["tol"], max_iterations=options["max_iterations"], step_tol=_STEP_TOL)
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
                self.scales_of(base, None)
                continue
            cause = (f"a contact change ({_springs(self.last)} → {_springs(result)}: a spring grazes the orbit)"
                     if result.contact_springs != self.last.contact_springs else why)
            if final:
                return Attempt(iterations, target, result, reason=cause, complete=True, jumped=True,
                                rejected=rejected)
            landing = np.r_[outcome.unknowns, target]
            new_scales = self.scales_of(landing, None)
            new_tangent = unit_tangent(outcome.last.data.jacobian, new_scales, None, self.direction)
            slope = self.slope(new_tangent)
            if reference is None or slope >= _LANDING_RATIO * reference:
                self.pending = (landing, new_scales, new_tangent, outcome, result, None, None, abs(target - value0))
                self.step = step
                return Attempt(iterations, target, result, reason=cause, jumped=True, rejected=rejected)
            rejected += 1
            last_reason = (f"landed at {self.label} = {target:.6g} in a turn of the branch again "
                           f"({self.resonance(self.other_mode(new_tangent, new_scales), result)})")
            self.scales_of(base, None)
        where = f"{self.label} ≈ {value0:.6g}"
        if collapse:
            return Attempt(iterations, end=f"{why}; no parameter jump beyond {where} converged to the NNM of mode "
                            f"{problem.mode} (last: {last_reason})", rejected=rejected)
        return Attempt(iterations, end=f"at {where} {why}; no parameter jump up to {distance:.3g} beyond it landed "
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
    trajectory = _map_over(problem._flow(eps), x0, v0, period, sensitivity=False, d_epsilon=False)
    if isinstance(trajectory, str):
        return np.full(2 * n + 1, 1e6)
    energy = nnm_energy(problem.system, x0, v0, eps)
    return np.r_[
        (trajectory.state[:n] - x0) / problem.position_scale,
        (trajectory.state[n:] - v0) / problem.velocity_scale,
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

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.label = "ε"

    def first(self, value: float) -> NNMResult:
        """The seed's first point: hybr from the linear mode (its route, not :func:`nnm_point`'s)."""
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
METHODS: dict[str, type[_NNMStepper]] = {"arclength": _NNMArclength, "natural": _Natural, "seed": _Seed}
