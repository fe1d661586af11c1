"""Nonlinear normal modes by strained coordinates:  M X'' + K X + ε Σ_i w_i f_i(a_iᵀ X − b_i) = 0 (seed §4).

The method :class:`StrainedCoordinatesNNM` (verb ``expand``) and its shortcut
:func:`nnm`.  The NNM of mode j is sought with one strained time ``s = ω t``,
``ω(ε) = λ_j + Σ ω_n ε^n``, the other modal coordinates released at
``u_k(0) = ε a_k`` with the a_k outputs fixed by periodicity (Corollary 4.2).
The derivation runs on the one branch hierarchy (:mod:`lindstedt.engine.branches`)
from the modal normal form (:mod:`lindstedt.engine.modal`); this module undoes
the normalisation ``U = a0 W``, ``Ω = ω/λ_j``, ``ε̂ = ε/λ_j²``.
:func:`release_amplitudes_by_series` is an independent cross-check of the a_k.
"""

from __future__ import annotations

from typing import Any

import mpmath
import numpy as np
import sympy

from .._errors import ProblemError
from .._precision import locked, locked_methods
from ..engine.branches import BranchHierarchy
from ..engine.modal import modal_guard_digits, modal_normal_form
from ..problems.nnm import NNMProblem
from ..problems.system import UnilateralSystem
from ..results.nnm import NNMExpansion
from .._cost import nnm_estimate
from ..limits import Estimate

__all__ = ["StrainedCoordinatesNNM", "nnm", "release_amplitudes_by_series"]


@locked_methods()
class StrainedCoordinatesNNM:
    """The method: Lindstedt–Poincaré NNM expansion of an N-dof unilateral system (one verb, :meth:`expand`).

    Parameters
    ----------
    precision : int
        Decimal digits of the arithmetic (mode shapes included).
    """

    def __init__(self, precision: int = 30):
        if not isinstance(precision, int) or precision < 15 or precision > 500:
            raise ProblemError("precision must be an integer number of digits between 15 and 500")
        self.precision = precision

    def estimate(self, problem: NNMProblem, order: int = 2) -> Estimate:
        """What :meth:`expand` will cost (CPU seconds, memory: the cost model of :mod:`lindstedt.limits`).

        Examples
        --------
        >>> import lindstedt
        >>> chain = lindstedt.UnilateralSystem.chain(1000, unilateral=[(0, 0)])
        >>> cost = StrainedCoordinatesNNM().estimate(lindstedt.NNMProblem(chain, 1, 1), order=2)
        >>> dict(cost.drivers)["degrees of freedom"], 1 < cost.seconds < 60
        (1000, True)
        """
        if not isinstance(problem, NNMProblem):
            raise ProblemError("expand takes an NNMProblem(system, mode, a0, a1=0)")
        if isinstance(order, bool) or not isinstance(order, int) or not 0 <= order <= 12:
            raise ProblemError(f"order must be an integer between 0 and 12, got {order!r}")
        return nnm_estimate(problem.system, problem.mode, order)

    def expand(self, problem: NNMProblem, order: int = 2) -> NNMExpansion:
        """The NNM of ``problem`` to ``order`` (ω_0 … ω_order, the a_k, the waveform branches), refused before any
        work if its :meth:`estimate` exceeds the budget in force (:class:`~lindstedt.BudgetError`)."""
        self.estimate(problem, order).check()
        system, mode = problem.system, problem.mode
        digits = self.precision + modal_guard_digits(system, mode - 1, order)
        form = modal_normal_form(system, mode - 1, problem.a0, problem.a1, digits)
        hierarchy = BranchHierarchy(form.system)
        steps = form.system.gauge  # η = ε̂ or ε̂^{1/2} (a grazing spring that the perturbed orbit passes)
        lam = form.frequencies[mode - 1]
        root = lam ** (-2 / form.system.domain.convert(steps))  # (1/λ²)^(1/steps): η = root · ε^(1/steps)
        omegas = tuple(hierarchy.frequency(n) * lam * root**n for n in range(steps * order + 1))
        alphas = tuple(hierarchy.squared_frequency(n) * lam * lam * root**n for n in range(steps * order + 1))
        zero = form.system.domain.zero
        releases = tuple(
            hierarchy.release(steps, k) * form.amplitude * root**steps if order >= 1 else zero for k in range(system.n_dof)
        )
        # per element: a double root where one of its breakpoints is grazed, simple where one is crossed
        statuses = [{spring.status for spring in form.springs if spring.element == i} for i in range(system.n_springs)]
        roots = tuple("double" if "grazing" in found else "simple" if "crossing" in found else "none"
                      for found in statuses)
        return NNMExpansion(
            problem=problem,
            order=order,
            digits=digits,
            lambdas=tuple(float(value) for value in form.frequencies),
            omega=omegas,
            alpha=alphas,
            release_modal=releases,
            # a grazing spring the perturbed orbit passes is expanded in the gauge ε^{1/2} (valid on t ≲ 1/ε);
            # one it only touches keeps the linear-approximation time scale ε^{-1/2}
            validity_exponent=sympy.Rational(-1, 2) if "double" in roots and steps == 1 else sympy.Integer(-1),
            spring_roots=roots,
            gauge=steps,
            small_divisors=tuple((k + 1, n, float(d)) for k, n, d in form.small_divisors),
            _hierarchy=hierarchy,
            _method=self,
        )


def release_amplitudes_by_series(system: UnilateralSystem, mode: int, a0: Any, *, precision: int = 30) -> list[tuple[Any, Any]]:
    """The a_k (k ≠ j) of Corollary 4.2 as Fourier series, summed by mpmath with an error estimate.

    Order one of mode k ≠ j: ``λ_j² v'' + λ_k² v = −Σ_i G_ki (a0 B_ij cos s − b_i)_+`` with the
    cosine coefficients of the contact functions from the Fourier kernel
    (``(c cos s − b)_+ = |c| (±1)^l c_l[b/|c|]`` for ±c > 0), so::

        a_k = v_k(0) = Σ_l F_{k,l} / (λ_k² − l² λ_j²),   F_{k,l} = −Σ_i G_ki |c_i| (sign c_i)^l c_l[b_i/|c_i|].

    Independent of the branch hierarchy (a cross-check of :func:`nnm`'s closed form).

    Returns
    -------
    list of (value, error_estimate)
        One pair per mode k ≠ j, in increasing mode order.
    """
    from ..algebra.fourier import contact_ramp_coefficient_mp
    from ..algebra.series import series_sum

    system.require_unilateral("the Fourier-series cross-check of the a_k (release_amplitudes_by_series)")

    modes = system.modes()
    frequencies, shapes = modes.frequencies, modes.shapes
    j = mode - 1
    coupling = float(a0) * (np.asarray(system.A, dtype=float) @ shapes)[:, j]
    forcing = shapes.T @ np.asarray(system.W, dtype=float)
    gaps = np.asarray(system.b, dtype=float).reshape(-1)
    results = []
    for k in range(system.n_dof):
        if k == j:
            continue

        def term(harmonic: Any, k: int = k) -> Any:
            harmonic = int(harmonic)
            total = mpmath.mpf(0)
            for i in range(len(gaps)):
                if coupling[i] == 0:
                    continue
                sign = 1 if coupling[i] > 0 else (-1) ** harmonic
                ramp = contact_ramp_coefficient_mp(harmonic, gaps[i] / abs(coupling[i]), precision=precision)
                total += -forcing[k, i] * abs(coupling[i]) * sign * ramp
            return total / (frequencies[k] ** 2 - harmonic**2 * frequencies[j] ** 2)

        estimate = series_sum(term, start=0, precision=precision)
        results.append((estimate.value, estimate.error_estimate))
    return results


@locked
def nnm(system: UnilateralSystem, mode: int, a0: Any, order: int = 2, *, a1: Any = 0, precision: int = 30) -> NNMExpansion:
    """Nonlinear normal mode of ``M X'' + K X + ε Σ_i w_i f_i(a_iᵀ X − b_i) = 0`` grown from ``mode`` (strained
    coordinates; unilateral springs ``f_i = Max(0, u)`` by default, any law polynomial between breakpoints).

    Examples
    --------
    >>> import lindstedt
    >>> chain = lindstedt.UnilateralSystem.chain(2, unilateral=[(0, 0)])
    >>> result = lindstedt.nnm(chain, mode=1, a0=1)
    >>> len(result.omega), len(result.a_k)
    (3, 1)
    """
    return StrainedCoordinatesNNM(precision).expand(NNMProblem(system, mode, a0, a1), order)
