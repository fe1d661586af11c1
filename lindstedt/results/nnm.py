"""The strained-coordinates NNM of  M X'' + K X + ε W (A X − b)_+ = 0  in physical units.

``ω(ε) = λ_j + Σ_n ω_n ε^n``, ``ω² = Σ α_n ε^n``, the release amplitudes
``u_k(0) = ε a_k`` of the other modes, and the waveform
``U(t) ≈ a0 Σ_n ε̂^n W_n(ω t)`` (``ε̂ = ε/λ_j²``) evaluated between the moving
contact angles; exports to JSON (schema ``lindstedt.nnm/1``) and LaTeX.
"""

from __future__ import annotations

import json
import warnings
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import mpmath
import numpy as np
import sympy

from ..engine.branches import BranchHierarchy, FloatBranches
from .accuracy import ExpansionValidityWarning, branch_bound, displacement_error, gauge_values, phase_warning, series_warning
from ..problems.nnm import NNMProblem
from ..problems.system import UnilateralSystem

__all__ = ["NNMExpansion"]


@dataclass(frozen=True)
class NNMExpansion:
    """Strained-coordinates NNM of mode j to order 2 (and beyond), in physical units.

    Attributes
    ----------
    problem : NNMProblem
        The system, the mode j (1-based; modes sorted by increasing λ, shapes signed so
        that their largest entry — the first such — is positive) and the release
        u_j(0) = a0 + ε a1; ``system``, ``mode``, ``a0``, ``a1`` are read from it.
    order : int
    digits : int
        Working decimal digits of the coefficients (precision plus near-resonance guard digits).
    lambdas : tuple of float
        All linear frequencies λ_1 ≤ … ≤ λ_N.
    omega : tuple of mpf
        (λ_j, ω_1, …, ω_order) with ω(ε) = Σ ω_n ε^n; when ``gauge`` is 2,
        (λ_j, ω_{1/2}, ω_1, …, ω_order) with ω(ε) = Σ_n ω_{n/2} ε^{n/2}.
    alpha : tuple of mpf
        ω² = Σ α_n ε^n (same gauge).
    release_modal : tuple of mpf
        a_k = v_k^1(0) for every mode k (a_j = a1): u_k(0) = ε a_k.
    validity_exponent : sympy.Rational
        −1 (all contact roots simple) or −1/2 (a spring grazes: double root).
    spring_roots : tuple of str
        Per spring: "simple", "double" (grazing), "none" (never/always in contact).
    gauge : int
        1: series in ε; 2: in ε^{1/2} — a grazing spring (touching its gap at a turning point
        of the linear mode) that the perturbed orbit passes makes ω(ε) non-analytic.
    small_divisors : tuple of (mode, harmonic, divisor)
        Near-resonance report: |r_k² − n²| for the closest harmonic n of each mode k ≠ j;
        the amplification of mode k is ~1/divisor.

    Examples
    --------
    >>> import lindstedt
    >>> system = lindstedt.UnilateralSystem.one_dof(1, a=1, b=0)
    >>> result = lindstedt.nnm(system, mode=1, a0=1, order=2)
    >>> [round(float(w), 12) for w in result.omega]
    [1.0, 0.25, -0.125]
    """

    problem: NNMProblem
    order: int
    digits: int
    lambdas: tuple[float, ...]
    omega: tuple[Any, ...]
    alpha: tuple[Any, ...]
    release_modal: tuple[Any, ...]
    validity_exponent: sympy.Rational
    spring_roots: tuple[str, ...]
    small_divisors: tuple[tuple[int, int, float], ...]
    gauge: int
    _hierarchy: BranchHierarchy = field(repr=False, compare=False)

    @property
    def system(self) -> UnilateralSystem:
        return self.problem.system

    @property
    def mode(self) -> int:
        return self.problem.mode

    @property
    def a0(self) -> float:
        """u_j(0) at ε = 0 (float)."""
        return float(self.problem.a0)

    @property
    def a1(self) -> float:
        """The ε-correction of the release u_j(0) = a0 + ε a1 (float)."""
        return float(self.problem.a1)

    @property
    def a_k(self) -> tuple[Any, ...]:
        """The a_k for k ≠ j in increasing mode order."""
        return tuple(value for k, value in enumerate(self.release_modal) if k != self.mode - 1)

    def frequency(self, epsilon: Any) -> Any:
        """ω(ε) = Σ_n ω_n η^n (vectorised), η = ε, or ε^{1/2} when ``gauge`` is 2.

        Warns (:class:`~lindstedt.ExpansionValidityWarning`) where the series does not
        converge: its terms grow, or the next term exceeds the whole correction.

        Examples
        --------
        >>> import lindstedt, warnings
        >>> mode = lindstedt.nnm(lindstedt.UnilateralSystem.one_dof(1, a=1, b=0), mode=1, a0=1, order=2)
        >>> float(mode.frequency(0.1))
        1.02375
        >>> with warnings.catch_warnings(record=True) as caught:
        ...     warnings.simplefilter("always")
        ...     _ = mode.frequency(10.0)
        >>> "not converging" in str(caught[0].message)
        True
        """
        eta = self._gauge_values(epsilon)
        message = series_warning(self._coefficients, len(self.omega) - 1, np.atleast_1d(eta), self._gauge_name)
        if message:
            warnings.warn(ExpansionValidityWarning(message), stacklevel=2)
        return np.polynomial.polynomial.polyval(eta, self._coefficients[:-1])

    def truncation_error_estimate(self, epsilon: Any) -> Any:
        """|ω_{n+1} η^{n+1}|: the size of the first neglected term of ω(ε) (vectorised)."""
        return np.abs(self._coefficients[-1] * self._gauge_values(epsilon) ** len(self.omega))

    def displacement_error_estimate(self, t: Any, epsilon: float) -> np.ndarray:
        """Estimated error of :meth:`modal_displacement` at ``t`` (vectorised, the worst modal coordinate): the phase
        drift |a0 ω_{n+1} η^{n+1}| t plus the first neglected waveform term (the last kept one times η̂).

        Examples
        --------
        >>> import lindstedt
        >>> mode = lindstedt.nnm(lindstedt.UnilateralSystem.chain(2, unilateral=[(0, 0)]), mode=1, a0=1, order=2)
        >>> bool(mode.displacement_error_estimate(10.0, 0.01) < 1e-4 < mode.displacement_error_estimate(1e7, 0.01))
        True
        """
        eta = float(self._gauge_values(float(epsilon)))
        lam = float(self.omega[0])
        scaled = eta * (lam * lam) ** (-1 / self.gauge)
        last = len(self.omega) - 1
        kept = self._float_branches.terms[-1]  # W_{n−1}: the waveform pairs orders < n with ω through n
        neglected = abs(self.a0) * abs(scaled) ** len(self._float_branches.terms) * branch_bound(kept, self._float_branches.shifts[0])
        frequency_error = abs(self._coefficients[-1]) * abs(eta) ** (last + 1)
        return displacement_error(self.a0, frequency_error, np.asarray(t, dtype=float), neglected)

    @property
    def _gauge_name(self) -> str:
        return "eps" if self.gauge == 1 else "sqrt(eps)"

    @cached_property
    def _coefficients(self) -> np.ndarray:
        """ω_0 … ω_n and the next coefficient ω_{n+1} (derived on first use), as floats."""
        lam = self.omega[0]
        steps = self.gauge
        index = steps * self.order + 1
        next_value = self._hierarchy.frequency(index) * lam * lam ** (-2 * mpmath.mpf(index) / steps)
        return np.array([float(w) for w in self.omega] + [float(next_value)])

    def _gauge_values(self, epsilon: Any) -> np.ndarray:
        return gauge_values(epsilon, self.gauge, "use lindstedt.nnm_point")

    def modal_displacement(self, t: Any, epsilon: float) -> np.ndarray:
        """Modal coordinates U(t) ≈ a0 Σ_{n<N} ε̂^n W_n(ω t), ω through ω_N (shape ``t.shape + (N_dof,)``).

        The branches are used between the *moving* contact angles s_i*(ε); with the
        frequency through ω_N and the waveforms through order N−1 the error is O(ε^N)
        on t ≤ C/ε (Theorem 4.1 for N = 2: u = v⁰ + ε v¹ + O(ε²)).
        """
        lam = float(self.omega[0])
        eta = float(self._gauge_values(float(epsilon)))
        times = np.asarray(t, dtype=float)
        last = len(self.omega) - 1
        message = series_warning(self._coefficients, last, np.array([eta]), self._gauge_name) or phase_warning(
            abs(self._coefficients[-1]) * abs(eta) ** (last + 1), times
        )
        if message:
            warnings.warn(ExpansionValidityWarning(message), stacklevel=2)
        strained = times * float(np.polynomial.polynomial.polyval(eta, self._coefficients[:-1]))
        scaled = eta * (lam * lam) ** (-1 / self.gauge)
        return self.a0 * self._float_branches.evaluate(strained, scaled)

    @cached_property
    def _float_branches(self) -> FloatBranches:
        """W_0 … W_{N−1} as floats (built once)."""
        return self._hierarchy.float_branches(max(self.gauge * self.order - 1, 0))

    def displacement(self, t: Any, epsilon: float) -> np.ndarray:
        """Physical X(t) = Φ U(t) of :meth:`modal_displacement` (shape ``t.shape + (N_dof,)``).

        Examples
        --------
        >>> import lindstedt, numpy as np
        >>> chain = lindstedt.UnilateralSystem.chain(2, unilateral=[(0, 0)])
        >>> mode = lindstedt.nnm(chain, mode=1, a0=1.0)
        >>> np.allclose(mode.displacement(0.0, 0.01), mode.release_state(0.01))
        True
        """
        return self.modal_displacement(t, epsilon) @ self.system.modes().shapes.T

    def release_state(self, epsilon: float) -> np.ndarray:
        """Physical release X(0) = Φ U(0), U_j(0) = a0 + ε a1, U_k(0) = ε a_k (velocities zero)."""
        modes = self.system.modes()
        modal = np.array([float(a) for a in self.release_modal]) * epsilon
        modal[self.mode - 1] += self.a0
        return modes.shapes @ modal

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (schema ``lindstedt.nnm/1``)."""
        return {
            "schema": "lindstedt.nnm/1",
            "mode": self.mode,
            "a0": self.a0,
            "a1": self.a1,
            "order": self.order,
            "gauge": "epsilon" if self.gauge == 1 else "sqrt(epsilon)",
            "lambda": list(self.lambdas),
            "omega": [float(w) for w in self.omega],
            "omega_digits": [mpmath.nstr(w, self.digits) for w in self.omega],
            "alpha": [float(a) for a in self.alpha],
            "a_k": [float(a) for a in self.a_k],
            "validity": {"exponent": str(self.validity_exponent), "spring_roots": list(self.spring_roots)},
            "small_divisors": [{"mode": k, "harmonic": n, "divisor": d} for k, n, d in self.small_divisors],
        }

    def to_json(self, indent: int | None = 2) -> str:
        """JSON text of :meth:`to_dict`."""
        return json.dumps(self.to_dict(), indent=indent, allow_nan=False)

    def to_latex(self) -> str:
        """A LaTeX fragment with λ_j, ω_1, ω_2 and the a_k."""
        lines = [rf"\lambda_{{{self.mode}}} &= {mpmath.nstr(self.omega[0], 15)}"]
        for n in range(1, len(self.omega)):  # ω_{n/gauge} multiplies ε^{n/gauge}
            lines.append(rf"\omega_{{{sympy.Rational(n, self.gauge)}}} &= {mpmath.nstr(self.omega[n], 15)}")
        for k, value in enumerate(self.release_modal):
            if k != self.mode - 1:
                lines.append(rf"a_{{{k + 1}}} &= {mpmath.nstr(value, 15)}")
        return "\\begin{align*}\n" + " \\\\\n".join(lines) + "\n\\end{align*}\n"

    def summary(self) -> str:
        """Plain-text summary."""
        lines = [f"NNM of mode {self.mode} (a0 = {self.a0}), strained coordinates to order {self.order}"]
        lines.append("  lambda = " + ", ".join(f"{value:.10g}" for value in self.lambdas))
        for n, value in enumerate(self.omega):
            lines.append(f"  omega_{n} = {mpmath.nstr(value, 15)}")
        lines.append("  a_k = " + ", ".join(mpmath.nstr(value, 12) for value in self.a_k))
        lines.append(f"  validity: T ~ eps^({self.validity_exponent}); spring roots: {', '.join(self.spring_roots)}")
        return "\n".join(lines)
