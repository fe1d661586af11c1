"""Nonlinear normal modes by strained coordinates:  M X'' + K X + ε W (A X − b)_+ = 0 (seed §4).

The problem (:class:`NNMProblem`: system, mode j, release u_j(0) = a0 + ε a1
at rest), the method (:class:`StrainedCoordinatesNNM`, verb ``expand``) and the
result (:class:`NNMExpansion`).  The NNM of mode j is sought with one strained
time ``s = ω t``, ``ω(ε) = λ_j + Σ ω_n ε^n``, the other modal coordinates
released at ``u_k(0) = ε a_k`` with the a_k outputs fixed by periodicity
(Corollary 4.2).  The derivation runs on the one branch hierarchy
(:mod:`lindstedt.engine.branches`) from the modal normal form
(:mod:`lindstedt.engine.modal`); this module undoes the normalisation
``U = a0 W``, ``Ω = ω/λ_j``, ``ε̂ = ε/λ_j²``.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import mpmath
import numpy as np
import sympy

from ._errors import ProblemError
from ._parsing import parse_real
from ._system import UnilateralSystem
from .engine.branches import BranchHierarchy, FloatBranches
from .engine.modal import modal_guard_digits, modal_normal_form

__all__ = ["NNMExpansion", "NNMProblem", "StrainedCoordinatesNNM", "nnm", "release_amplitudes_by_series"]

@dataclass(frozen=True)
class NNMProblem:
    """The NNM grown from linear mode j of ``M X'' + K X + ε W (A X − b)_+ = 0``, released at rest.

    Release: modal coordinate u_j(0) = a0 + ε a1 of mode j; the other modal
    coordinates are what the NNM makes them (u_k(0) = ε a_k + …), X'(0) = 0.

    Parameters
    ----------
    system : UnilateralSystem
    mode : int
        1-based mode number j (modes by increasing λ).
    a0, a1 : number or numeric string
        Exact numbers (a float is its binary value; strings are read by the one parser); a0 ≠ 0.

    Examples
    --------
    >>> import lindstedt
    >>> problem = lindstedt.NNMProblem(lindstedt.UnilateralSystem.chain(2, unilateral=[(0, 0)]), mode=1, a0="1/2")
    >>> problem.a0, problem.a1
    (1/2, 0)
    """

    system: UnilateralSystem
    mode: int
    a0: Any
    a1: Any = 0

    def __post_init__(self) -> None:
        if not isinstance(self.system, UnilateralSystem):
            raise ProblemError("system must be a UnilateralSystem (see UnilateralSystem.from_json_dict)")
        if isinstance(self.mode, bool) or not isinstance(self.mode, int) or not 1 <= self.mode <= self.system.n_dof:
            raise ProblemError(f"mode must be an integer between 1 and {self.system.n_dof}, got {self.mode!r}")
        amplitude = parse_real(self.a0, what="a0")
        if amplitude == 0:
            raise ProblemError("a0 = 0 is the rest state: give a nonzero modal amplitude a0")
        object.__setattr__(self, "a0", amplitude)
        object.__setattr__(self, "a1", parse_real(self.a1, what="a1"))


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
        (λ_j, ω_1, …, ω_order) with ω(ε) = Σ ω_n ε^n.
    alpha : tuple of mpf
        ω² = Σ α_n ε^n.
    release_modal : tuple of mpf
        a_k = v_k^1(0) for every mode k (a_j = a1): u_k(0) = ε a_k.
    validity_exponent : sympy.Rational
        −1 (all contact roots simple) or −1/2 (a spring grazes: double root).
    spring_roots : tuple of str
        Per spring: "simple", "double" (grazing), "none" (never/always in contact).
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
        """ω(ε) = Σ_{n≤order} ω_n ε^n (vectorised)."""
        coefficients = np.array([float(w) for w in self.omega])
        return np.polynomial.polynomial.polyval(np.asarray(epsilon, dtype=float), coefficients)

    def modal_displacement(self, t: Any, epsilon: float) -> np.ndarray:
        """Modal coordinates U(t) ≈ a0 Σ_{n<N} ε̂^n W_n(ω t), ω through ω_N (shape ``t.shape + (N_dof,)``).

        The branches are used between the *moving* contact angles s_i*(ε); with the
        frequency through ω_N and the waveforms through order N−1 the error is O(ε^N)
        on t ≤ C/ε (Theorem 4.1 for N = 2: u = v⁰ + ε v¹ + O(ε²)).
        """
        lam = float(self.omega[0])
        strained = np.asarray(t, dtype=float) * float(self.frequency(epsilon))
        return self.a0 * self._float_branches.evaluate(strained, float(epsilon) / (lam * lam))

    @cached_property
    def _float_branches(self) -> FloatBranches:
        """W_0 … W_{N−1} as floats (built once)."""
        return self._hierarchy.float_branches(max(self.order - 1, 0))

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
        for n in range(1, len(self.omega)):
            lines.append(rf"\omega_{{{n}}} &= {mpmath.nstr(self.omega[n], 15)}")
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

    def expand(self, problem: NNMProblem, order: int = 2) -> NNMExpansion:
        """The NNM of ``problem`` to ``order`` (ω_0 … ω_order, the a_k, the waveform branches)."""
        if not isinstance(problem, NNMProblem):
            raise ProblemError("expand takes an NNMProblem(system, mode, a0, a1=0)")
        if isinstance(order, bool) or not isinstance(order, int) or not 0 <= order <= 12:
            raise ProblemError(f"order must be an integer between 0 and 12, got {order!r}")
        system, mode = problem.system, problem.mode
        digits = self.precision + modal_guard_digits(system, mode - 1, order)
        form = modal_normal_form(system, mode - 1, problem.a0, problem.a1, digits)
        hierarchy = BranchHierarchy(form.system)
        lam = form.frequencies[mode - 1]
        scale = 1 / (lam * lam)
        omegas = tuple(hierarchy.frequency(n) * lam * scale**n for n in range(order + 1))
        alphas = tuple(hierarchy.squared_frequency(n) * lam * lam * scale**n for n in range(order + 1))
        zero = form.system.domain.zero
        releases = tuple(hierarchy.release(1, k) * form.amplitude * scale if order >= 1 else zero for k in range(system.n_dof))
        roots = tuple({"crossing": "simple", "grazing": "double"}.get(spring.status, "none") for spring in form.springs)
        return NNMExpansion(
            problem=problem,
            order=order,
            digits=digits,
            lambdas=tuple(float(value) for value in form.frequencies),
            omega=omegas,
            alpha=alphas,
            release_modal=releases,
            validity_exponent=sympy.Rational(-1, 2) if "double" in roots else sympy.Integer(-1),
            spring_roots=roots,
            small_divisors=tuple((k + 1, n, float(d)) for k, n, d in form.small_divisors),
            _hierarchy=hierarchy,
        )


def release_amplitudes_by_series(system: UnilateralSystem, mode: int, a0: Any, *, precision: int = 30) -> list[tuple[Any, Any]]:
    """The a_k (k ≠ j) of Corollary 4.2 as Fourier series, summed by mpmath with an error estimate.

    Order one of mode k ≠ j: ``λ_j² v'' + λ_k² v = −Σ_i G_ki (a0 B_ij cos s − b_i)_+`` with the
    cosine coefficients of the contact functions from the Fourier kernel
    (``(c cos s − b)_+ = |c| (±1)^l c_l[b/|c|]`` for ±c > 0), so

        a_k = v_k(0) = Σ_l F_{k,l} / (λ_k² − l² λ_j²),   F_{k,l} = −Σ_i G_ki |c_i| (sign c_i)^l c_l[b_i/|c_i|].

    Independent of the branch hierarchy (a cross-check of :func:`nnm`'s closed form).

    Returns
    -------
    list of (value, error_estimate)
        One pair per mode k ≠ j, in increasing mode order.
    """
    from .algebra.fourier import contact_ramp_coefficient_mp
    from .algebra.series import series_sum

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


def nnm(system: UnilateralSystem, mode: int, a0: Any, order: int = 2, *, a1: Any = 0, precision: int = 30) -> NNMExpansion:
    """Nonlinear normal mode of ``M X'' + K X + ε W (A X − b)_+ = 0`` grown from ``mode`` (strained coordinates).

    Examples
    --------
    >>> import lindstedt
    >>> chain = lindstedt.UnilateralSystem.chain(2, unilateral=[(0, 0)])
    >>> result = lindstedt.nnm(chain, mode=1, a0=1)
    >>> len(result.omega), len(result.a_k)
    (3, 1)
    """
    return StrainedCoordinatesNNM(precision).expand(NNMProblem(system, mode, a0, a1), order)
