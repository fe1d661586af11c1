"""Results of the Lindstedt–Poincaré expansion of ``u'' + ω0² u + ε f(u) = 0``.

An :class:`Expansion` of order N holds, lazily and exactly,

* ``omega`` = (ω_0, …, ω_N): ``ω(ε) = Σ_k ω_k ε^k``;
* ``alpha`` = (α_0, …, α_N): ``ω(ε)² = Σ_k α_k ε^k``;
* ``waveforms`` = (v_0, …, v_N): ``u(t) = Σ_k ε^k v_k(ω t)``, each an exact
  even cosine polynomial :class:`Waveform` (:mod:`lindstedt.results.waveforms`).

The numeric evaluator :meth:`Expansion.displacement` pairs the waveforms
v_0 … v_N with the frequency through ω_{N+1} (computed on demand, it needs only
the secular part of the next forcing): that is the consistent truncation whose
error is O(ε^{N+1}) uniformly for t ≤ C/ε.

Numeric evaluation (:meth:`Expansion.frequency`, :meth:`Expansion.displacement`, :meth:`Expansion.velocity`,
:meth:`Expansion.frequency_coefficients`) works on floats computed once per expansion and parameter values and
is vectorised over ε, t and arrays of parameter values.  With free symbols, the closed forms (ω_k, the waveform
coefficients, the contact-angle shifts, the assumptions' signs) are compiled once into one float64 evaluator
with a first-order rounding-error bound (:func:`lindstedt.compiled.family.compile_family`); a value is used where
its bound is below 1e-13 (relative for ω_k, of |a0| for u), else replaced by the exact series of a gap
coefficient in acos κ or by the exact expression.  Floats are taken as their exact binary value and checked
against the derivation's assumptions by vectorised sign tests (undecided cases exactly); exact numbers a double
cannot hold (``"3/10"``) are evaluated through the exactly substituted coefficients.  The warnings read ω_{N+1}
(ω_{N+2} for the phase drift) only where they could speak: the exact term is derived where a stand-in as large
as :func:`lindstedt.results.accuracy.next_term_bound` (1000 times the geometric extrapolation of the known
terms) would make them speak; below that, a true term smaller than the stand-in (by a factor >= 9 on 21 test
problems, orders 1-6) cannot change the answer.

General initial data u(0) = u0, u'(0) = v0 (``lindstedt.expand(f, u0=..., v0=...)``): the expansion
is released at rest at the orbit's positive turning point ``A(ε) = Σ A_k ε^k`` (:attr:`Expansion.amplitude`)
and ``u(t) = Σ_k ε^k v_k(ω t + φ(ε))`` with the exact phase series ``φ(ε) = Σ φ_k ε^k``
(:attr:`Expansion.phase`); the evaluators, :meth:`Expansion.displacement_expr` and generated code include it.

The class is the result (problem, order, the exact coefficients, waveforms and metadata, derived lazily);
what it does with them lives in modules of their own: the float evaluators in
:mod:`~lindstedt.results._evaluators` (on the parameter values read and checked by
:mod:`~lindstedt.results._values` and the float coefficients of :mod:`~lindstedt.results._coefficients`), the
phase and turning-point series in :mod:`~lindstedt.results._phase`, the LaTeX in
:mod:`~lindstedt.results._latex`, the JSON dictionary (schema ``lindstedt.expansion/1``), ``repr`` and summary
in :mod:`~lindstedt.results._views`.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping

import numpy as np
import sympy

from .._errors import OrderError, ProblemError, UnsupportedNonlinearityError
from .._precision import cached_property, locked_methods
from ..render.display import jupyter_latex
from ..engine.branches import BranchHierarchy
from ..engine.contact import PiecewiseNormalForm
from ..engine.smooth import MAX_ORDER, NormalForm, SmoothHierarchy
from ..problems.oscillator import Oscillator
from . import _evaluators
from ._latex import expansion_latex
from ._phase import amplitude_series, phase_series
from ._recipe import derived_again
from ._values import FloatState
from ._views import expansion_dict, expansion_repr, expansion_summary
from .accuracy import ExpansionValidityWarning
from .assumptions import DerivationAssumptions
from .orbit_range import OrbitRange
from .stretched_arcs import STRETCHED_TIME, StretchedArcSeries, arc_series
from .waveforms import STRAINED_TIME, PiecewiseWaveform, Waveform

__all__ = ["Expansion", "ExpansionValidityWarning", "Waveform", "PiecewiseWaveform", "STRAINED_TIME", "EPSILON", "TIME"]

EPSILON = sympy.Symbol("epsilon", real=True)
TIME = sympy.Symbol("t", real=True)


@locked_methods("frequency", "displacement", "velocity")  # float evaluators: each locks its own slow part
@dataclass(frozen=True)
class Expansion:
    """Lindstedt–Poincaré expansion of an :class:`~lindstedt.Oscillator` to a given order.

    Everything is computed on first access and cached; the object itself is
    frozen and keeps a reference to its problem.

    Examples
    --------
    >>> import lindstedt
    >>> expansion = lindstedt.expand("u**3", order=2)
    >>> expansion.omega[2]
    -21*a0**4/(256*omega0**3)
    >>> round(expansion.frequency(0.1, values={"a0": 1, "omega0": 1}), 12)
    1.0366796875
    """

    problem: Oscillator
    order: int
    _hierarchy: SmoothHierarchy | BranchHierarchy = field(repr=False, compare=False)
    _form: NormalForm | PiecewiseNormalForm = field(repr=False, compare=False)
    #: (precision, numeric) of the LindstedtPoincare that derived it: how a process that unpickles it re-derives it
    _method: Any = field(default=None, repr=False, compare=False)  # the method that derived it: its recipe

    def __reduce__(self) -> tuple[Any, tuple[Any, ...]]:
        """Pickled as its recipe (problem, order, method): the receiving process re-derives it (lazily, cached
        there), so expansions travel to process pools and Dask workers.

        Examples
        --------
        >>> import pickle, lindstedt
        >>> e = lindstedt.expand("Max(0, u - 1/3)", order=2, a0=1, omega0=1)
        >>> pickle.loads(pickle.dumps(e)).omega == e.omega
        True
        """
        if self._method is None:
            raise TypeError("an Expansion built without its method cannot be pickled; derive it with lindstedt.expand")
        return derived_again, (self._method, self.problem, self.order)

    @property
    def is_piecewise(self) -> bool:
        """True for piecewise-linear f (unilateral springs)."""
        return self._form.regime != "smooth"

    @property
    def regime(self) -> str:
        """``"smooth"``, or for piecewise f: ``"contact"``, ``"no contact"`` or ``"grazing"``."""
        return self._form.regime

    @property
    def validity_exponent(self) -> sympy.Rational:
        """p in the validity time T_ε ~ ε^p: −1 (simple roots of v0 − b), −1/2 (grazing, double root)."""
        return self._form.validity_exponent

    @property
    def gauge(self) -> sympy.Expr:
        """The expansion variable: ``epsilon``, or ``sqrt(epsilon)`` when the perturbed orbit crosses a
        breakpoint that the unperturbed orbit only touches (grazing: ω(ε) is not analytic at 0).

        Every sequence of coefficients (``omega``, ``alpha``, ``waveforms``, the index of
        :meth:`omega_correction`) runs over the powers of the gauge: ω(ε) = Σ_k ω_k gauge^k,
        k = 0 … gauge-order of ε^N (2N for ``sqrt(epsilon)``).

        Examples
        --------
        >>> import lindstedt
        >>> e = lindstedt.expand("Max(0, u + 1)", order=3, a0=1, omega0=1)   # grazing at the far turning point
        >>> e.gauge, e.omega[5]
        (sqrt(epsilon), -8/(3*pi))
        """
        return EPSILON if self._steps == 1 else EPSILON ** sympy.Rational(1, self._steps)

    @property
    def _steps(self) -> int:
        """Powers of the gauge per power of ε (1, or 2 for the gauge ε^{1/2})."""
        return getattr(self._form, "gauge", 1)

    @property
    def exponents(self) -> tuple[sympy.Rational, ...]:
        """The power of ε of each entry of ``omega`` (k/2 in the gauge sqrt(epsilon))."""
        return tuple(sympy.Rational(k, self._steps) for k in range(self._steps * self.order + 1))

    @property
    def contact_angles(self) -> tuple[sympy.Expr, ...]:
        """β_i = arccos κ_i of the contact boundaries crossed by v_0 (empty for smooth f)."""
        return tuple(boundary.contact_angle for boundary in self._form.boundaries)

    def contact_angle_correction(self, order: int) -> tuple[sympy.Expr, ...]:
        """σ_{i,order}: the ε^order coefficient of the moving contact angles s_i*(ε) (empty for smooth f)."""
        if not self._form.boundaries:
            return ()
        self._check(order)
        return tuple(self._to_expr(value, order, sympy.Integer(1)) for value in self._hierarchy.boundary_shift(order))

    # -- exact quantities ---------------------------------------------------------------
    def _to_expr(self, element: Any, power: int, prefactor: sympy.Expr) -> sympy.Expr:
        """prefactor · (ε̂/ε)^power · element: a coefficient of the normalised hierarchy in the problem's units."""
        return self._form.scaled_expr(element, power, prefactor)

    def _check(self, order: int, frequency: bool = False) -> None:
        highest = self._steps * (MAX_ORDER + 1)
        if isinstance(order, bool) or not isinstance(order, int) or order < 0 or order > highest:
            raise OrderError(f"correction index must be an integer in [0, {highest}], got {order!r}")
        released = self.problem.release_order
        # from (u0, v0) the engine knows the turning point through A_M: waveforms and contact angles through the
        # gauge index s·M, ω and α (which need the waveforms before them) through s·M + 1
        reach = None if released is None else self._steps * released + (1 if frequency else 0)
        if reach is not None and order > reach:
            raise OrderError(
                f"correction index {order} is beyond what the turning-point series A_1 … A_{released} of this expansion "
                f"from (u0, v0) determines (index {reach}); expand to a higher order: "
                f"lindstedt.expand(..., order={max(self.order, -(-(order - (1 if frequency else 0)) // self._steps) - 1)})"
            )

    def omega_correction(self, order: int) -> sympy.Expr:
        """Exact ω_order (any order, computed lazily; beyond ``self.order`` allowed, from (u0, v0) up to order + 1)."""
        self._check(order, frequency=True)
        return self._to_expr(self._hierarchy.frequency(order), order, self.problem.omega0)

    def alpha_correction(self, order: int) -> sympy.Expr:
        """Exact α_order, the ε^order coefficient of ω²."""
        self._check(order, frequency=True)
        return self._to_expr(self._hierarchy.squared_frequency(order), order, self.problem.omega0**2)

    def waveform(self, order: int) -> Waveform | PiecewiseWaveform:
        """Exact v_order(s): a :class:`Waveform` (smooth f) or :class:`PiecewiseWaveform`.

        A piece on a stretched contact arc (non-polynomial contact law) holds the placeholder
        ``Y_order(tau)``: its expansion is :attr:`stretched_arcs`.
        """
        self._check(order)
        if self.is_piecewise:
            form = self._form
            pieces = tuple(components[0] for components in self._hierarchy.branches(order))
            scale = self.problem.a0 * form.epsilon_scale**order
            branches = [scale * piece.to_expr(STRAINED_TIME, form.to_expr) for piece in pieces]
            stretched = self._stretched_pieces
            for piece in stretched:
                branches[piece] = sympy.Function(f"Y_{order}")(STRETCHED_TIME)
            branches = tuple(branches)
            limits = (form.system.zero_point, *[b.point for b in form.boundaries], form.system.pi_point)
            return PiecewiseWaveform(
                order=order,
                breakpoints=self.contact_angles,
                branches=branches,
                _pieces=pieces,
                _limits=limits,
                _convert=lambda element, scale=scale: scale * form.to_expr(element),
                stretched=stretched,
            )
        series = self._hierarchy.waveform(order)
        coefficients = tuple(
            (harmonic, self._to_expr(series.coefficient(harmonic), order, self.problem.a0)) for harmonic in series.harmonics
        )
        return Waveform(order=order, coefficients=coefficients)

    @property
    def _stretched_pieces(self) -> tuple[int, ...]:
        if not self.is_piecewise:
            return ()
        first, last = self._form.system.arcs
        return tuple(piece for piece, arc in ((0, first), (len(self._form.system.states) - 1, last)) if arc is not None)

    @cached_property
    def stretched_arcs(self) -> tuple[StretchedArcSeries, ...]:
        """The contact arcs expanded in stretched time (non-polynomial contact laws; empty otherwise)."""
        if not self.is_piecewise:
            return ()
        return arc_series(self._hierarchy, self._form.system.arcs, self._steps * self.order)

    def _solve_through(self, highest: int) -> int:
        """Solve the hierarchy through order ``highest`` in one pass (so that its checkpoints report progress
        against the whole request, see :mod:`lindstedt.limits`); returns ``highest``."""
        self._hierarchy.squared_frequency(highest)
        return highest

    @cached_property
    def omega(self) -> tuple[sympy.Expr, ...]:
        """(ω_0, …, ω_N), exact."""
        self._solve_through(self._steps * self.order)
        return tuple(self.omega_correction(k) for k in range(self._steps * self.order + 1))

    @cached_property
    def alpha(self) -> tuple[sympy.Expr, ...]:
        """(α_0, …, α_N) with ω² = Σ α_k ε^k, exact."""
        self._solve_through(self._steps * self.order)
        return tuple(self.alpha_correction(k) for k in range(self._steps * self.order + 1))

    @cached_property
    def waveforms(self) -> tuple[Waveform | PiecewiseWaveform, ...]:
        """(v_0, …, v_N), exact cosine polynomials."""
        self._solve_through(self._steps * self.order)
        return tuple(self.waveform(k) for k in range(self._steps * self.order + 1))

    @cached_property
    def amplitude(self) -> tuple[sympy.Expr, ...]:
        """(A_0, …, A_N): the turning point ``v(0; ε) = Σ_k A_k gauge^k`` the expansion is released at, exact.

        General initial data (u0, v0): the positive turning point of the orbit through them, from
        the energy (:meth:`Oscillator.amplitude_series`).  A release at rest: ``(a0, a1, 0, …)``;
        ``"harmonic"`` normalization: ``v_k(0)``.  Indexed like :attr:`omega` (powers of the gauge).

        Examples
        --------
        >>> import lindstedt
        >>> lindstedt.expand("Max(0, u - 1/4)", order=2, u0="3/5", v0="4/5", omega0=1).amplitude
        (1, -11/50, 88/625)
        """
        return amplitude_series(self)

    @cached_property
    def phase(self) -> tuple[sympy.Expr, ...]:
        """(φ_0, …, φ_N): the phase ``φ(ε) = Σ_k φ_k gauge^k`` of ``u(t) = v(ω t + φ(ε); ε)``, exact.

        Zero for a release at rest.  From (u0, v0): ``v(φ; ε) = u0`` with the sign of
        ``u'(0) = ω v_s(φ) = v0``, i.e. ``φ_0 = atan2(−v0/ω0, u0)`` and φ_k from the Taylor
        expansion of the waveforms at φ_0: with ψ = ``|φ|`` = ψ_0 + Δ, Δ = Σ_{k≥1} ψ_k gauge^k,
        ``Σ_{k,m} v_k^{(m)}(ψ_0) [Δ^m]_{n−k}/m! = 0`` at order n ≥ 1, which is linear in ψ_n
        through ``v_0'(ψ_0) = −|v0|/ω0``.  For piecewise f the branch of the piece that
        contains ψ_0 is used (its analytic continuation); if u0 sits on a crossed breakpoint
        the phase is the moving contact angle itself, ψ = s*(ε) (:meth:`contact_angle_correction`).

        Examples
        --------
        >>> import lindstedt
        >>> e = lindstedt.expand("u**3", order=1, u0=0, v0=1, omega0=1)   # kicked from equilibrium
        >>> e.phase
        (-pi/2, 0)
        """
        return phase_series(self)

    @cached_property
    def omega_next(self) -> sympy.Expr:
        """ω_{N+1}: the frequency term the displacement evaluator pairs with v_0..v_N."""
        return self.omega_correction(self._steps * self.order + 1)

    # -- numeric evaluation (the bodies: _evaluators.py) ------------------------------------------------
    @cached_property
    def _assumptions(self) -> DerivationAssumptions:
        """What the derivation assumed (signs of the free symbols, the contact regime), checked on numeric values."""
        return DerivationAssumptions(self.problem, self._form, self.order)

    @cached_property
    def _floats(self) -> FloatState:
        """What the float evaluators keep: the float data per parameter values, the compiled families."""
        return FloatState(self.arguments, str(self.gauge))

    def frequency(self, epsilon: Any, values: Mapping[Any, Any] | None = None, *, order: int | None = None) -> Any:
        """ω(ε) = Σ_{k≤order} ω_k ε^k as float (vectorised over ``epsilon`` and over arrays in ``values``).

        Evaluated from float coefficients computed once per expansion and parameter values (compiled
        closed forms for free symbols, accepted only where their rounding-error bound is below 1e-13
        relative; stable series or exact evaluation elsewhere, see :meth:`frequency_coefficients`).
        Judged against :meth:`epsilon_range`: raises :class:`~lindstedt.ParameterError` at an ε where no
        periodic orbit exists (the motion escapes, a contact piece loses its stiffness, the release point is an
        equilibrium); warns (:class:`ExpansionValidityWarning`) where the orbit has left the contact regime the
        expansion was derived for, where ε is beyond the series' radius of convergence, or where its terms stop
        decreasing.

        Parameters
        ----------
        epsilon : float or array
            Read by the one reading of numbers: exact strings such as ``"1/10"`` are accepted; None, booleans,
            NaN, infinities, complex numbers and words raise :class:`~lindstedt.ParameterError`.
        values : mapping, optional
            Numbers for the symbols left free (a0, omega0, parameters); float arrays are broadcast
            against ``epsilon`` and each other.  Floats are used as they are; other numbers (ints,
            fractions, strings) are read exactly, and a value a double cannot hold exactly is evaluated
            through the exact coefficients.
        order : int, optional
            Truncation order (default: the expansion's order).

        Examples
        --------
        >>> import lindstedt, numpy as np
        >>> e = lindstedt.expand("Max(0, u - kappa)", order=2, a0=1, omega0=1, params={"kappa": None})
        >>> eps, kappa = np.array([0.01, 0.1]), np.array([0.3, -0.5])
        >>> both = e.frequency(eps, values={"kappa": kappa})       # element by element
        >>> bool(np.all(both == [e.frequency(x, values={"kappa": y}) for x, y in zip(eps, kappa)]))
        True
        """
        fast = self.__dict__.get("_fast_frequency")
        if fast is not None and values is None and order is None and type(epsilon) is float:
            coefficients, radius = fast
            if -radius <= epsilon <= radius:  # no warning possible there (see _set_fast_frequency)
                total = 0.0
                for coefficient in coefficients:
                    total = total * epsilon + coefficient
                return total
        return _evaluators.frequency(self, epsilon, values, order)


    def frequency_coefficients(self, values: Mapping[Any, Any] | None = None, *, order: int | None = None) -> np.ndarray:
        """ω_0 … ω_n as floats (n the gauge index of ε^order), vectorised over arrays in ``values``:
        shape ``(n + 1,) + broadcast shape``.

        With free symbols each ω_k is a compiled closed form, accepted where its first-order
        rounding-error bound is at most 1e-13 of its value; elsewhere (a closed form that cancels,
        e.g. near a grazing gap κ → ±1) it comes from exact series in acos κ (one gap symbol,
        :mod:`lindstedt.compiled.stable_series`, relative error ≤ 1e-13) or from the exact expression.

        Examples
        --------
        >>> import lindstedt
        >>> e = lindstedt.expand("Max(0, u - kappa)", order=2, a0=1, omega0=1, params={"kappa": None})
        >>> e.frequency_coefficients({"kappa": [0.0, 0.999999]}).shape
        (3, 2)
        >>> float(e.frequency_coefficients({"kappa": 0.0})[1])      # omega_1 = 1/4 at kappa = 0
        0.25
        """
        return _evaluators.coefficients(self, values, order)

    def truncation_error_estimate(self, epsilon: Any, values: Mapping[Any, Any] | None = None, *, order: int | None = None) -> Any:
        """``|ω_{order+1} ε^{order+1}|``: the size of the first neglected term of ω(ε) (vectorised).

        Examples
        --------
        >>> import lindstedt
        >>> e = lindstedt.expand("u**3", order=1, a0=1, omega0=1)
        >>> round(float(e.truncation_error_estimate(0.1)), 12)     # |omega_2| eps^2 = 21/256 * 0.01
        0.0008203125
        """
        return _evaluators.truncation_error_estimate(self, epsilon, values, order)

    def displacement_error_estimate(self, t: Any, epsilon: float, values: Mapping[Any, Any] | None = None) -> np.ndarray:
        """Estimated error of :meth:`displacement` at ``t`` (vectorised): the phase drift ``|a0| δω t``, δω the terms of ω
        after ω_{n+1} (which the displacement uses) through one more power of ε, plus the first neglected waveform
        term (the last kept one times η̂).

        Examples
        --------
        >>> import lindstedt
        >>> e = lindstedt.expand("u**3", order=2, a0=1, omega0=1)
        >>> bool(e.displacement_error_estimate(10.0, 0.01) < 1e-5 < e.displacement_error_estimate(1e6, 0.01))
        True
        """
        return _evaluators.displacement_error_estimate(self, t, epsilon, values)

    def epsilon_range(self, values: Mapping[Any, Any] | None = None) -> OrbitRange | None:
        """How far in ε the derivation holds at these parameter values (one point): the open interval
        ``(lower, upper)`` on which the true orbit through the release state keeps the contact regime the
        expansion was derived for, and ``radius``, the distance to the nearest singularity of ω(ε) the law gives
        (see :mod:`lindstedt.results.orbit_range`).

        Computed for every law (pieces that are not polynomials — sin u, Hertz — numerically, their radius from
        the real events only); None for a release shifted by ε a1 and the "harmonic" normalization.

        The evaluators (:meth:`frequency`, :meth:`displacement`, :meth:`velocity`, the error estimates) raise
        a :class:`~lindstedt.ParameterError` at an ε where no periodic orbit exists (the motion escapes over a
        separatrix, a contact state with ω0² + ε·slope ≤ 0 it cannot leave, the release point an equilibrium)
        and warn (:class:`ExpansionValidityWarning`, naming the bound) at an ε outside ``(lower, upper)`` or at
        ``|ε| >= radius``.

        Examples
        --------
        >>> import lindstedt
        >>> duffing = lindstedt.expand("u**3", order=2, a0=1, omega0=1)
        >>> bounds = duffing.epsilon_range()          # softening past eps a0**2 = -omega0**2: the separatrix
        >>> round(bounds.lower, 12), bounds.upper, round(bounds.radius, 12)
        (-1.0, inf, 1.0)
        >>> lindstedt.expand("Max(0, u + 3/2)", order=2, a0=1, omega0=1).epsilon_range().upper   # leaves contact
        0.2
        """
        return _evaluators.epsilon_range(self, values)

    def displacement(self, t: Any, epsilon: Any, values: Mapping[Any, Any] | None = None) -> np.ndarray:
        """u(t) ≈ Σ_{k≤N} ε^k v_k(ω t + φ(ε)), ω through ω_{N+1}, φ through φ_N; vectorised over ``t``,
        ``epsilon`` and arrays in ``values`` (broadcast together).

        The phase φ(ε) is zero for a release at rest (see :attr:`phase` for initial data u0, v0).

        For piecewise-linear f the branches are used up to the *moving* contact
        angles s_i*(ε) = β_i + Σ σ_{i,k} ε^k, so the error stays O(ε^{N+1}).

        The waveform coefficients are evaluated once per parameter values (compiled closed forms, accepted
        where their rounding bound keeps u within ``1e-13 |a0|``, exact elsewhere); see :meth:`frequency`
        for how ``values`` are read.

        Examples
        --------
        >>> import lindstedt, numpy as np
        >>> e = lindstedt.expand("u**3", order=1, a0=1, omega0=1)
        >>> float(e.displacement(0.0, 0.1))
        1.0
        >>> e.displacement(np.array([0.0, np.pi]), np.array([0.1, 0.0]))   # u(0) = a0; at eps = 0, u(pi) = -a0
        array([ 1., -1.])
        """
        return _evaluators.evaluate(self, t, epsilon, values, False)

    def velocity(self, t: Any, epsilon: Any, values: Mapping[Any, Any] | None = None) -> np.ndarray:
        """u'(t) of the same approximation as :meth:`displacement` (vectorised the same way)."""
        return _evaluators.evaluate(self, t, epsilon, values, True)

    # -- symbolic views and exports -------------------------------------------------------
    def frequency_expr(self, order: int | None = None) -> sympy.Expr:
        """ω(ε) truncated at ``order`` as a sympy polynomial in ``epsilon``."""
        last = self._steps * (self.order if order is None else order)
        return sympy.Add(*[self.omega_correction(k) * self.gauge**k for k in range(last + 1)])

    def phase_expr(self, order: int | None = None) -> sympy.Expr:
        """φ(ε) truncated at ``order`` as a sympy polynomial in ``epsilon`` (0 for a release at rest)."""
        last = self._steps * (self.order if order is None else order)
        if not self.problem.has_initial_velocity:
            return sympy.Integer(0)
        if last > self._steps * self.order:
            raise OrderError(f"the phase series holds orders up to {self.order}; expand to a higher order")
        return sympy.Add(*[self.phase[k] * self.gauge**k for k in range(last + 1)])

    def amplitude_expr(self, order: int | None = None) -> sympy.Expr:
        """A(ε), the turning point the expansion is released at, truncated at ``order`` (see :attr:`amplitude`)."""
        last = self._steps * (self.order if order is None else order)
        if last > self._steps * self.order:
            raise OrderError(f"the amplitude series holds orders up to {self.order}; expand to a higher order")
        return sympy.Add(*[self.amplitude[k] * self.gauge**k for k in range(last + 1)])

    def displacement_expr(self, derivative: bool = False) -> sympy.Expr:
        """u(t; ε) = Σ_{k≤N} ε^k v_k(ω t + φ(ε)) with ω through ω_{N+1}, as a sympy expression (its time derivative
        u'(t) with ``derivative=True``, as :meth:`velocity` evaluates it).

        For piecewise-linear f the strained time is folded to [0, π]
        (evenness, 2π-periodicity) and the pieces end at the moving contact
        angles s_i*(ε) = β_i + Σ_{k≤N} σ_{i,k} ε^k, as in :meth:`displacement`.
        """
        if self._stretched_pieces:
            raise UnsupportedNonlinearityError(
                "a stretched contact arc (non-polynomial contact law) has no closed-form displacement: evaluate it with "
                "Expansion.displacement, or export Expansion.stretched_arcs (Chebyshev coefficients) with to_json"
            )
        frequency = self.frequency_expr(self.order) + self.omega_next * self.gauge ** (self._steps * self.order + 1)
        strained = frequency * TIME + self.phase_expr()
        if not self.is_piecewise:
            displacement = sympy.Add(*[EPSILON**w.order * w.to_expr(strained) for w in self.waveforms])
            return sympy.diff(displacement, TIME) if derivative else displacement
        folded = sympy.Abs(sympy.Mod(strained + sympy.pi, 2 * sympy.pi) - sympy.pi)
        pieces = [sympy.Add(*[self.gauge**w.order * w.branches[p] for w in self.waveforms]) for p in range(len(self.waveforms[0].branches))]
        if derivative:  # d/dt v(|s|) = ω sign(s) v'(|s|), s the strained time folded to (−π, π]
            pieces = [frequency * sympy.sign(sympy.Mod(strained + sympy.pi, 2 * sympy.pi) - sympy.pi) * sympy.diff(piece, STRAINED_TIME)
                      for piece in pieces]
        boundaries = [
            sympy.Add(*[self.gauge**k * self.contact_angle_correction(k)[index] for k in range(1, self._steps * self.order + 1)], angle)
            for index, angle in enumerate(self.contact_angles)
        ]
        conditions = [(piece.subs(STRAINED_TIME, folded), folded <= boundary) for piece, boundary in zip(pieces, boundaries)]
        conditions.append((pieces[-1].subs(STRAINED_TIME, folded), True))
        return sympy.Piecewise(*conditions)

    @property
    def arguments(self) -> tuple[sympy.Symbol, ...]:
        """Free symbols of the results (sorted by name): the trailing arguments of :meth:`lambdify`."""
        return tuple(sorted(self.problem.free_symbols, key=lambda symbol: symbol.name))

    def lambdify(self, quantity: str = "displacement", modules: str = "numpy") -> Callable[..., Any]:
        """A vectorised numeric function generated through ``sympy.lambdify``.

        ``quantity="displacement"`` gives ``u(t, epsilon, *arguments)``;
        ``quantity="velocity"`` gives ``u'(t, epsilon, *arguments)``;
        ``quantity="frequency"`` gives ``omega(epsilon, *arguments)``.
        The generated functions do not check ε against the expansion's range (:meth:`epsilon_range`).

        Examples
        --------
        >>> import lindstedt, numpy as np
        >>> e = lindstedt.expand("u**3", order=2, a0=1, omega0=1)
        >>> omega = e.lambdify("frequency")
        >>> round(float(omega(0.1)), 12)
        1.0366796875
        """
        if quantity in ("displacement", "velocity"):
            expression = self.displacement_expr(derivative=quantity == "velocity")
            return _lambdify((TIME, EPSILON, *self.arguments), expression, modules)
        if quantity == "frequency":
            return _lambdify((EPSILON, *self.arguments), self.frequency_expr(), modules)
        raise ProblemError(f"quantity must be 'displacement', 'velocity' or 'frequency', got {quantity!r}")

    def to_latex(self, *, waveforms: bool = False) -> str:
        r"""A LaTeX fragment (``align*``): the equation, what the derivation assumed, the ω_k, ω(ε), optionally the v_k.

        Series are written in increasing powers of ε; a coefficient longer than a line is referred to
        by its name ω_k in ω(ε) (its closed form is on its own line above).  The assumptions are those
        :meth:`frequency` checks values against (the signs of the free symbols, the contact regime such
        as ``|b| < a0`` for a gap b), plus the regime and validity time of a piecewise f.  Waveform LaTeX
        is built only when ``waveforms=True``.

        Examples
        --------
        >>> import lindstedt
        >>> print(lindstedt.expand("u**3", order=2, a0=1, omega0=1).to_latex())  # doctest: +NORMALIZE_WHITESPACE
        % lindstedt: u'' + u + eps*(u**3) = 0, u(0) = 1 [initial]
        \begin{align*}
        & \ddot u + u + \varepsilon u^{3} = 0,\quad u(0) = 1,\ \dot u(0) = 0 \\
        \omega_{0} &= 1 \\
        \omega_{1} &= \frac{3}{8} \\
        \omega_{2} &= - \frac{21}{256} \\
        \omega(\varepsilon) &= 1 + \frac{3 \varepsilon}{8} - \frac{21 \varepsilon^{2}}{256} + O(\varepsilon^{3})
        \end{align*}
        """
        return expansion_latex(self, waveforms)

    # -- display -----------------------------------------------------------------------------
    def _repr_latex_(self) -> str:
        """Jupyter's rendering: :meth:`to_latex` (without waveforms) as display math."""
        return jupyter_latex(self.to_latex())

    def __repr__(self) -> str:
        """The problem, the order and ω_k (each cut to a few hundred characters; ``.omega[k]`` is the full one)."""
        return expansion_repr(self)

    def to_dict(self, *, waveforms: bool = True) -> dict[str, Any]:
        """The documented JSON-ready dictionary (schema ``lindstedt.expansion/1``, :mod:`lindstedt.results._views`)."""
        return expansion_dict(self, waveforms)

    def to_json(self, *, waveforms: bool = True, indent: int | None = 2) -> str:
        """JSON text of :meth:`to_dict`."""
        return json.dumps(self.to_dict(waveforms=waveforms), indent=indent, allow_nan=False)

    def summary(self) -> str:
        """Plain-text summary: the problem and ω_0..ω_N."""
        return expansion_summary(self)


def _lambdify(arguments: tuple, expression: sympy.Expr, modules: Any) -> Callable[..., Any]:
    """``sympy.lambdify``; for NumPy with its printer's default settings except the order of terms, which the
    default printer sorts by evaluating every term numerically (8× the time for closed forms in arccos of an
    irrational contact point: 7.8 s → 1.0 s for ``Max(0, u - acos(1/3)/2)`` at order 2, measured)."""
    if modules != "numpy":
        return sympy.lambdify(arguments, expression, modules=modules)
    from sympy.printing.numpy import NumPyPrinter

    printer = NumPyPrinter({"fully_qualified_modules": False, "inline": True, "allow_unknown_functions": True,
                            "user_functions": {}, "order": "none"})
    return sympy.lambdify(arguments, expression, modules=modules, printer=printer)
