"""Starting points of the NNM shooting of  M X'' + K X + ε W (A X − b)_+ = 0 : expansion, user guesses, impossible amplitudes.

Newton on the shooting residual (:class:`~lindstedt.numerics.shooting.NNMShooting`) starts from the linear mode
(:meth:`NNMShooting.initial_guess`), from the strained-coordinates expansion (:class:`_ExpansionPredictor`:
``ω(ε) = λ_j + ω_1 ε + ω_2 ε²`` and the release state ``Φ (a0 e_j + ε a)`` of :func:`lindstedt.nnm`, order 2),
or from a user's guess (:func:`_guess_unknowns`); an amplitude no orbit can have is refused before any flow
(:func:`_impossible_amplitude`).
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np

from .._errors import ProblemError
from .._precision import LOCK
from .results import NNMResult
from .shooting import _TWO_PI, NNMShooting, _Amplitude, nnm_energy


class _ExpansionPredictor:
    """Newton guesses from the strained-coordinates NNM expansion (:func:`lindstedt.nnm`, order 2).

    The expansion of mode j at the release modal amplitude ``a0`` gives
    ``ω(ε) = λ_j + ω_1 ε + ω_2 ε²`` and the release state
    ``X(0) = Φ (a0 e_j + ε a)`` (velocities zero).  :meth:`guess` turns them
    into shooting unknowns (for an energy amplitude the release state is scaled
    about the static equilibrium to the target energy) and :meth:`valid` says
    whether the series converges at ε (no :class:`~lindstedt.ExpansionValidityWarning`).
    """

    def __init__(self, problem: NNMShooting, expansion: Any, amplitude: _Amplitude) -> None:
        self.problem = problem
        self.expansion = expansion
        self.amplitude = amplitude

    @classmethod
    def build(cls, problem: NNMShooting, epsilon: float, amplitude: _Amplitude) -> _ExpansionPredictor | None:
        """The predictor for the amplitude at ε, or None where the expansion is not available."""
        x0, _ = problem._guess_amplitude(epsilon, amplitude)
        a0 = amplitude.value if amplitude.kind == "modal_amplitude" else float(problem.modal_row @ x0)
        if not (math.isfinite(a0) and a0 != 0.0) or problem.system.n_springs == 0:
            return None
        key = (amplitude.kind, round(a0, 12))
        cache = problem._expansions
        if key not in cache:
            from .. import nnm  # here: the expansion engine is only needed when a guess is asked for

            try:
                # the package's one lock (nnm takes it too: one lock, no lock order to get wrong)
                with LOCK, warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    cache[key] = nnm(problem.system, problem.mode, a0=a0, order=2)
            except Exception:  # noqa: BLE001 — a predictor only: any failure of the expansion means "no predictor"
                cache[key] = None
        expansion = cache[key]
        return None if expansion is None else cls(problem, expansion, amplitude)

    def frequency(self, epsilon: float) -> tuple[float, bool]:
        """ω(ε) of the expansion and whether the series converges there."""
        from .. import ExpansionValidityWarning

        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                omega = float(self.expansion.frequency(float(epsilon)))
            except (ArithmeticError, ValueError):
                return math.nan, False
        valid = not any(issubclass(w.category, ExpansionValidityWarning) for w in caught)
        return omega, valid and math.isfinite(omega) and omega > 0

    def valid(self, epsilon: float) -> bool:
        """Whether the expansion's series converges at ε (its validity warning is not raised)."""
        return self.frequency(epsilon)[1]

    def guess(self, epsilon: float) -> np.ndarray | None:
        """Shooting unknowns (X0, [X1,] T) predicted at ε, or None when ω(ε) is not positive."""
        problem = self.problem
        omega, _ = self.frequency(epsilon)
        if not (math.isfinite(omega) and omega > 0):
            return None
        x0 = np.asarray(self.expansion.release_state(float(epsilon)), dtype=float)
        if self.amplitude.kind != "modal_amplitude":  # scale about the equilibrium to the target energy
            equilibrium = problem.equilibrium(epsilon)
            floor = nnm_energy(problem.system, equilibrium, np.zeros(problem.n), epsilon)
            level = nnm_energy(problem.system, x0, np.zeros(problem.n), epsilon) - floor
            excess = self.amplitude.target(epsilon) - floor
            if level > 0 and excess > 0:
                x0 = equilibrium + math.sqrt(excess / level) * (x0 - equilibrium)
        if not np.all(np.isfinite(x0)):
            return None
        return problem._join(x0, np.zeros(problem.n), _TWO_PI / omega)


def _impossible_amplitude(problem: NNMShooting, epsilon: float, amplitude: _Amplitude) -> str | None:
    if amplitude.kind == "modal_amplitude":
        equilibrium = problem.equilibrium(epsilon)
        if amplitude.value == float(problem.modal_row @ equilibrium):
            return (f"impossible amplitude: u_j(0) = {amplitude.value:g} is the equilibrium's, so the orbit is the "
                    "rest state; give a non-zero modal amplitude")
        return None
    floor = nnm_energy(problem.system, problem.equilibrium(epsilon), np.zeros(problem.n), epsilon)
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
    return problem._join(np.asarray(x0, dtype=float).reshape(problem.n), np.asarray(v0, dtype=float).reshape(problem.n),
                         float(period))
