"""The strained-coordinates NNM of  M X'' + K X + ε W (A X − b)_+ = 0  in physical units.

``ω(ε) = λ_j + Σ_n ω_n ε^n``, ``ω² = Σ α_n ε^n``, the release amplitudes
``u_k(0) = ε a_k`` of the other modes, and the waveform
``U(t) ≈ a0 Σ_n ε̂^n W_n(ω t)`` (``ε̂ = ε/λ_j²``) evaluated between the moving
contact angles; exports to JSON (schema ``lindstedt.nnm/1``) and LaTeX.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from .._precision import cached_property, locked_methods, warn_caller
from typing import Any

import mpmath
import numpy as np
import sympy

from ..render.json import finite_float
from ..render.display import DIGITS, format_number, format_vector, jupyter_latex, labelled_repr
from ..engine.branches import BranchHierarchy
from ..engine.float_branches import FloatBranches, fold
from .accuracy import (
    ExpansionValidityWarning,
    branch_bound,
    displacement_error,
    gauge_values,
    geometric_tail,
    phase_warning,
    radius_warning,
    series_warning,
)
from ..problems.nnm import NNMProblem
from ..problems.parsing import parse_floats
from ..problems.system import UnilateralSystem
from ._recipe import derived_again

__all__ = ["NNMExpansion"]


@locked_methods()
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
        Near-resonance report: ``|r_k² − n²|`` for the closest harmonic n of each mode k ≠ j;
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
    _method: Any = field(default=None, repr=False, compare=False)  # the method that derived it: its recipe

    def __reduce__(self) -> tuple[Any, tuple[Any, ...]]:
        """Pickled as its recipe (the method that derived it, problem, order): the receiving process derives it again.

        Examples
        --------
        >>> import pickle, lindstedt
        >>> mode = lindstedt.nnm(lindstedt.UnilateralSystem.one_dof(1, a=1, b=0), mode=1, a0=1, order=2)
        >>> pickle.loads(pickle.dumps(mode)).omega == mode.omega
        True
        """
        if self._method is None:
            raise TypeError("an NNMExpansion built without its method cannot be pickled; derive it with lindstedt.nnm")
        return derived_again, (self._method, self.problem, self.order)

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
        converge: its terms grow, the next term exceeds the whole correction, or η is beyond
        the radius of convergence estimated from the growth of ω_1 … ω_{n+1} (where
        :meth:`truncation_error_estimate` is infinite).  The first call derives that next term
        ω_{n+1}; later calls are one polynomial evaluation.

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
        eta = self._gauge_values(parse_floats(epsilon, what="epsilon"))
        message = self._series_message(eta)
        if message:
            warn_caller(ExpansionValidityWarning(message))
        return np.polynomial.polynomial.polyval(eta, self._known_coefficients)

    def _series_message(self, eta: np.ndarray) -> str | None:
        last = len(self.omega) - 1
        return series_warning(self._coefficients, last, np.atleast_1d(eta), self._gauge_name) or radius_warning(
            self._radius, eta, self._gauge_name, last)

    def _tail(self, eta: Any) -> tuple[np.ndarray, float]:
        return geometric_tail(self._coefficients, len(self.omega) - 1, eta)

    @cached_property
    def _radius(self) -> float:
        """The radius of convergence in η that :func:`geometric_tail` estimates (it depends on the coefficients only)."""
        return self._tail(0.0)[1]

    def truncation_error_estimate(self, epsilon: Any) -> Any:
        """Estimated ``|ω(ε) − Σ_{k≤n} ω_k η^k|`` (vectorised): the first neglected term ``|ω_{n+1} η^{n+1}|`` plus
        the later ones bounded by a geometric envelope of ω_1 … ω_{n+1}; +inf beyond the radius of convergence that envelope
        estimates (:meth:`frequency` warns there).

        The first call derives ω_{n+1}: order n + 1 of the hierarchy, which needs every W_{n,k} (O(N²) terms).

        Examples
        --------
        >>> import lindstedt
        >>> mode = lindstedt.nnm(lindstedt.UnilateralSystem.one_dof(1, a=1, b=0), mode=1, a0=1, order=2)
        >>> float(mode.truncation_error_estimate(0.01)) < 1e-6 < float(mode.truncation_error_estimate(0.1))
        True
        """
        estimate, _ = self._tail(self._gauge_values(parse_floats(epsilon, what="epsilon")))
        return estimate if np.ndim(estimate) else float(estimate)

    def displacement_error_estimate(self, t: Any, epsilon: float) -> np.ndarray:
        """Estimated error of :meth:`modal_displacement` at ``t`` (vectorised, the worst modal coordinate): the phase
        drift ``|a0| δω t`` (δω the frequency's :meth:`truncation_error_estimate`) plus the first neglected waveform
        term (the last kept one times η̂).  Derives ω_{n+1} on first use.

        Examples
        --------
        >>> import lindstedt
        >>> mode = lindstedt.nnm(lindstedt.UnilateralSystem.chain(2, unilateral=[(0, 0)]), mode=1, a0=1, order=2)
        >>> bool(mode.displacement_error_estimate(10.0, 0.01) < 1e-4 < mode.displacement_error_estimate(1e7, 0.01))
        True
        """
        t, epsilon = parse_floats(t, what="t"), parse_floats(epsilon, what="epsilon", scalar=True)
        eta = float(self._gauge_values(float(epsilon)))
        lam = float(self.omega[0])
        scaled = eta * (lam * lam) ** (-1 / self.gauge)
        neglected = abs(self.a0) * abs(scaled) ** len(self._float_branches.terms) * self._last_branch_bound
        frequency_error = float(self._tail(eta)[0])
        return displacement_error(self.a0, frequency_error, np.asarray(t, dtype=float), neglected)

    @cached_property
    def _last_branch_bound(self) -> float:
        """max |W_{n−1}| over [0, π] (sampled once): the waveform pairs orders < n with ω through n."""
        return branch_bound(self._float_branches.terms[-1], self._float_branches.shifts[0])

    @property
    def _gauge_name(self) -> str:
        return "eps" if self.gauge == 1 else "sqrt(eps)"

    @cached_property
    def _known_coefficients(self) -> np.ndarray:
        """ω_0 … ω_n as floats."""
        return np.array([float(w) for w in self.omega])

    @cached_property
    def _coefficients(self) -> np.ndarray:
        """ω_0 … ω_n and the next coefficient ω_{n+1} (derived on first use: order n + 1 of the hierarchy, priced by
        the NNM cost model and refused above the budget, :class:`~lindstedt.BudgetError`), as floats."""
        from dataclasses import replace

        from .._cost import nnm_estimate

        # priced like any request: the next order is the check's own work (140 s against the expansion's 7 s on a
        # 1000-dof chain), refused above the budget in force rather than spent unannounced
        estimate = nnm_estimate(self.system, self.mode, self.order + 1)
        replace(estimate, task=f"the validity check of this expansion (its order {self.order + 1}: "
                               f"{estimate.task})").check()
        lam = self.omega[0]
        steps = self.gauge
        index = steps * self.order + 1
        next_value = self._hierarchy.frequency(index) * lam * lam ** (-2 * mpmath.mpf(index) / steps)
        return np.array([float(w) for w in self.omega] + [float(next_value)])

    def _gauge_values(self, epsilon: Any) -> np.ndarray:
        return gauge_values(epsilon, self.gauge, "use lindstedt.nnm_point")

    def modal_displacement(self, t: Any, epsilon: Any) -> np.ndarray:
        """Modal coordinates U(t) ≈ a0 Σ_{n<N} ε̂^n W_n(ω t), ω through ω_N (shape ``broadcast(t, ε).shape + (N_dof,)``).

        The branches are used between the *moving* contact angles s_i*(ε); with the
        frequency through ω_N and the waveforms through order N−1 the error is O(ε^N)
        on t ≤ C/ε (Theorem 4.1 for N = 2: u = v⁰ + ε v¹ + O(ε²)).  Vectorised over ``t``
        and ``epsilon`` (broadcast together); the branches are compiled once per expansion
        into one sparse (terms × components) matrix per piece and order, so a call costs a
        few array operations, not a loop over the N components.

        Examples
        --------
        >>> import lindstedt, numpy as np
        >>> mode = lindstedt.nnm(lindstedt.UnilateralSystem.chain(3, unilateral=[(0, 0)]), mode=1, a0=1.0)
        >>> mode.modal_displacement(np.linspace(0, 1, 4), [[0.0], [0.01]]).shape
        (2, 4, 3)
        """
        lam = float(self.omega[0])
        times = np.asarray(parse_floats(t, what="t"), dtype=float)
        epsilons = np.asarray(parse_floats(epsilon, what="epsilon"), dtype=float)
        eta = self._gauge_values(epsilons)
        message = self._series_message(eta) or phase_warning(
            float(self._tail(float(np.max(np.abs(eta), initial=0.0)))[0]), times
        )
        if message:
            warn_caller(ExpansionValidityWarning(message))
        strained = times * np.polynomial.polynomial.polyval(eta, self._known_coefficients)
        scaled = eta * (lam * lam) ** (-1 / self.gauge)
        if not scaled.ndim:
            return self.a0 * self._compiled.evaluate(strained, float(scaled))
        strained, scaled = np.broadcast_arrays(strained, scaled)
        result = np.empty(strained.shape + (self.system.n_dof,))
        for value in np.unique(scaled):  # one evaluation per distinct ε (the contact angles move with it)
            mask = scaled == value
            result[mask] = self._compiled.evaluate(strained[mask], float(value))
        return self.a0 * result

    @cached_property
    def _float_branches(self) -> FloatBranches:
        """W_0 … W_{N−1} as floats (built once)."""
        return self._hierarchy.float_branches(max(self.gauge * self.order - 1, 0))

    @cached_property
    def _compiled(self) -> "_CompiledWaveform | FloatBranches":
        """W_0 … W_{N−1} compiled for evaluation over every component at once (built once); with a stretched
        contact arc (a Hertz element) the float branches themselves, which evaluate the arc in stretched time."""
        branches = self._float_branches
        return branches if branches.arcs != (None, None) else _CompiledWaveform(branches)

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
        modal = np.array([float(a) for a in self.release_modal]) * parse_floats(epsilon, what="epsilon", scalar=True)
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
            "omega": [finite_float(w) for w in self.omega],  # null beyond a float's range (omega_digits keeps it)
            "omega_digits": [mpmath.nstr(w, self.digits) for w in self.omega],
            "alpha": [finite_float(a) for a in self.alpha],
            "a_k": [finite_float(a) for a in self.a_k],
            "validity": {"exponent": str(self.validity_exponent), "spring_roots": list(self.spring_roots)},
            "small_divisors": [{"mode": k, "harmonic": n, "divisor": d} for k, n, d in self.small_divisors],
        }

    def to_json(self, indent: int | None = 2) -> str:
        """JSON text of :meth:`to_dict`."""
        return json.dumps(self.to_dict(), indent=indent, allow_nan=False)

    def to_latex(self) -> str:
        r"""A LaTeX fragment (``align*``): λ_j, the ω_n, ω(ε) in increasing powers, the a_k and the validity.

        Numbers to 15 significant digits (``to_dict()["omega_digits"]`` holds all working digits).

        Examples
        --------
        >>> import lindstedt
        >>> system = lindstedt.UnilateralSystem.one_dof(1, a=1, b=0)
        >>> print(lindstedt.nnm(system, mode=1, a0=1, order=2).to_latex())
        \begin{align*}
        \lambda_{1} &= 1.0 \\
        \omega_{1} &= 0.25 \\
        \omega_{2} &= -0.125 \\
        \omega(\varepsilon) &= 1.0 + 0.25\,\varepsilon - 0.125\,\varepsilon^{2} + O(\varepsilon^{3}) \\
        & \text{release } u_{1}(0) = 1;\quad \text{springs: simple, valid for } t = O(\varepsilon^{-1})
        \end{align*}
        <BLANKLINE>
        """
        def number(value: Any) -> str:
            return mpmath.nstr(value, 15)

        lines = [rf"\lambda_{{{self.mode}}} &= {number(self.omega[0])}"]
        series = number(self.omega[0])
        for n in range(1, len(self.omega)):  # ω_{n/gauge} multiplies ε^{n/gauge}
            exponent = sympy.Rational(n, self.gauge)
            lines.append(rf"\omega_{{{exponent}}} &= {number(self.omega[n])}")
            if self.omega[n] == 0:
                continue
            power = r"\varepsilon" if exponent == 1 else rf"\varepsilon^{{{sympy.latex(exponent)}}}"
            series += (" - " if self.omega[n] < 0 else " + ") + number(abs(self.omega[n])) + r"\," + power
        remainder = sympy.latex(sympy.Rational(len(self.omega), self.gauge))
        lines.append(rf"\omega(\varepsilon) &= {series} + O(\varepsilon^{{{remainder}}})")
        for k, value in enumerate(self.release_modal):
            if k != self.mode - 1:
                lines.append(rf"a_{{{k + 1}}} &= {number(value)}")
        release = format_number(self.a0, 15) + ("" if self.a1 == 0 else rf" + {format_number(self.a1, 15)}\,\varepsilon")
        validity = sympy.latex(self.validity_exponent)
        lines.append(
            rf"& \text{{release }} u_{{{self.mode}}}(0) = {release};\quad "
            rf"\text{{springs: {', '.join(self.spring_roots)}, valid for }} t = O(\varepsilon^{{{validity}}})"
        )
        return "\\begin{align*}\n" + " \\\\\n".join(lines) + "\n\\end{align*}\n"

    def _repr_latex_(self) -> str:
        """Jupyter's rendering: :meth:`to_latex` as display math."""
        return jupyter_latex(self.to_latex())

    def __repr__(self) -> str:
        """Mode, release, order and the coefficients to 10 significant digits (``.omega`` holds the full ones)."""
        fields = [
            ("mode", str(self.mode)),
            ("a0", format_number(self.a0)),
            ("order", str(self.order)),
            ("omega", format_vector(self.omega, DIGITS, limit=12)),
            ("a_k", format_vector(self.a_k, DIGITS)),
            ("lambdas", format_vector(self.lambdas, DIGITS)),
            ("validity_exponent", str(self.validity_exponent)),
            ("spring_roots", repr(self.spring_roots)),
        ]
        if self.a1:
            fields.insert(2, ("a1", format_number(self.a1)))
        if self.gauge != 1:
            fields.append(("gauge", "sqrt(epsilon)"))
        return labelled_repr("NNMExpansion", fields)

    def summary(self) -> str:
        """Plain-text summary."""
        lines = [f"NNM of mode {self.mode} (a0 = {self.a0}), strained coordinates to order {self.order}"]
        lines.append("  lambda = " + ", ".join(f"{value:.10g}" for value in self.lambdas))
        for n, value in enumerate(self.omega):
            lines.append(f"  omega_{n} = {mpmath.nstr(value, 15)}")
        lines.append("  a_k = " + ", ".join(mpmath.nstr(value, 12) for value in self.a_k))
        lines.append(f"  validity: T ~ eps^({self.validity_exponent}); spring roots: {', '.join(self.spring_roots)}")
        return "\n".join(lines)


class _CompiledWaveform:
    """Σ_n η̂^n W_n(s) for every component at once, from :class:`~lindstedt.engine.branches.FloatBranches`.

    Per piece of [0, π]: the distinct terms (ν, parity, m) of all components and orders, the distinct
    frequencies ν among them, and per order a sparse (terms × components) coefficient matrix.  An
    evaluation forms cos/sin of the distinct frequencies at the points of each piece once and multiplies
    by the ε̂-weighted sum of the sparse matrices: O(points × terms + nonzeros), no Python loop over
    components.  (A stretched arc is evaluated by :class:`FloatBranches` instead.)
    """

    def __init__(self, branches: FloatBranches):
        import scipy.sparse  # here, not at module level: import lindstedt stays light

        if branches.arcs != (None, None):
            raise ValueError("stretched arcs are evaluated by FloatBranches")  # pragma: no cover - _compiled routes them
        self.shifts = np.array(branches.shifts, dtype=float).reshape(len(branches.shifts), -1)
        self.orders = len(branches.terms)
        self.size = len(branches.terms[0][0])
        self.pieces = []
        for piece in range(len(branches.terms[0])):
            keys: dict[tuple[float, int, int], int] = {}
            entries: list[tuple[list[int], list[int], list[float]]] = []
            for order_terms in branches.terms:
                rows, columns, values = [], [], []
                for component, terms in enumerate(order_terms[piece]):
                    for frequency, parity, power, value in terms:
                        rows.append(keys.setdefault((float(frequency), parity, power), len(keys)))
                        columns.append(component)
                        values.append(value)
                entries.append((rows, columns, values))
            ordered = list(keys)
            frequencies, inverse = np.unique(np.array([key[0] for key in ordered] or [0.0]), return_inverse=True)
            matrices = [
                scipy.sparse.csr_matrix((values, (rows, columns)), shape=(max(len(ordered), 1), self.size)) for rows, columns, values in entries
            ]
            parity = np.array([key[1] for key in ordered] or [0])
            power = np.array([key[2] for key in ordered] or [0], dtype=float)
            self.pieces.append((frequencies, inverse[: len(ordered) or 1], parity, power, matrices))

    def evaluate(self, strained_time: Any, scaled_epsilon: float) -> np.ndarray:
        """Σ_n ε̂^n W_n(s) at the strained times s; shape ``s.shape + (N,)``."""
        folded, _ = fold(np.asarray(strained_time, dtype=float))
        weights = float(scaled_epsilon) ** np.arange(self.orders)
        result = np.zeros(folded.shape + (self.size,))
        piece_index = np.searchsorted(weights @ self.shifts, folded) if len(self.pieces) > 1 else np.zeros(folded.shape, dtype=int)
        for piece, (frequencies, index, parity, power, matrices) in enumerate(self.pieces):
            mask = piece_index == piece
            if not np.any(mask):
                continue
            points = folded[mask]
            argument = np.multiply.outer(points, frequencies)
            columns = np.where(parity == 0, np.cos(argument)[:, index], np.sin(argument)[:, index])
            if power.any():
                columns = columns * np.power.outer(points, power)
            coefficients = matrices[0] * weights[0]
            for weight, matrix in zip(weights[1:], matrices[1:]):
                coefficients = coefficients + matrix * weight
            result[mask] = np.asarray(coefficients.T @ columns.T).T
        return result
