"""Results of the NNM computations: one periodic orbit (:class:`NNMResult`) and a branch of them (:class:`NNMBranch`).

An NNM of ``M X'' + K X + ε W (A X − b)_+ = 0`` is reported with its frequency
``ω = 2π/T``, release state ``(X0, X1)``, modal coordinates ``u(0) = Φᵀ M X0``,
energy, Floquet multipliers (eigenvalues of the monodromy matrix) and the cost
of the computation; a failure carries its reason and is never raised.  A
continuation returns an :class:`NNMBranch` (points in branch order, folds,
stability and contact changes) and reports its progress as
:class:`ContinuationProgress`.  All three export themselves to JSON through
:mod:`lindstedt.render.json` (schemas ``lindstedt.nnm-numeric/1``,
``lindstedt.nnm-branch/1``, ``lindstedt.continuation-progress/1``).

Examples
--------
>>> import lindstedt
>>> result = lindstedt.nnm_point(lindstedt.UnilateralSystem.one_dof(1), 3.0, 1, modal_amplitude=1.0)
>>> type(result).__name__, result.success, result.contact, result.modal_amplitude
('NNMResult', True, True, 1.0)
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..render.display import format_number, format_vector, html_grid, html_table, labelled_repr
from ..render.json import JsonExport, finite_float, to_jsonable
from .._precision import cached_property, locked
from .forced_results import Bifurcation

__all__ = ["ContinuationProgress", "NNMBranch", "NNMResult", "to_dataframe"]


@dataclass(frozen=True)
class NNMResult(JsonExport):
    """One nonlinear normal mode (a periodic orbit), or why it could not be computed.

    Attributes
    ----------
    success : bool
        True only if the orbit was verified: one more flow over the full
        period from the final state returns to it within ``verify_tol``.
    message : str
        What happened; on failure why (no convergence, singular Jacobian —
        fold or bifurcation —, impossible energy, flow failure, failed
        verification).  Mentions "no contact" when the orbit never touches
        the springs (it is then the linear mode, ω = λ_j).
    mode : int
        1-based mode number j the NNM grows from.
    epsilon : float
    frequency : float
        ω = 2π / T (NaN on failure).
    period : float
        T.
    linear_frequency : float
        λ_j.
    release_position, release_velocity : numpy.ndarray, shape (N,)
        Initial state X0, X1 (X1 = 0 for the symmetric formulation).
    modal_coordinates : numpy.ndarray, shape (N,)
        ``u(0) = Φᵀ M X0`` (release modal coordinates; ``u_j(0)`` is the modal amplitude).
    energy : float
        :func:`nnm_energy` of the release state.
    floquet_multipliers : numpy.ndarray, shape (2N,) or None
        Eigenvalues of the monodromy matrix (over one full period).  The first
        two are the trivial pair — the monodromy restricted to the plane of
        the flow direction and the family tangent, which it maps into itself
        (both are 1 exactly; the computed ones carry the rounding of that
        double eigenvalue, up to about ``sqrt(machine ε)``) — the others, the
        non-trivial ones (:attr:`nontrivial_multipliers`), are the eigenvalues
        of the monodromy on the quotient by that plane, sorted by distance to 1.
    stable : bool or None
        Linear (orbital) stability: every non-trivial multiplier within
        ``1 + stability_tol`` of the unit circle.  The trivial pair is deflated
        by construction, so a neutral NNM is never reported unstable.
    residual : float
        Relative periodicity residual of the verification flow,
        ``max(|X(T) − X0|/x_s, |X'(T) − X1|/(ω x_s))``, x_s the orbit's scale.
    n_switches : int
        Contact switches per period (0: no contact).
    mode_share : float
        Share of mode j in the linear modal energies ``½ (u̇_k² + λ_k² u_k²)``
        of the release state (1 for the linear mode).
    formulation : str
        ``"symmetric"``, ``"full"`` or ``"seed"`` (the baseline's residual).
    newton_iterations : int
        Newton (or hybr) iterations.
    flow_evaluations : int
        Flow integrations used, including the verification flow.
    monodromy : numpy.ndarray or None
        The 2N × 2N monodromy matrix.
    system : UnilateralSystem
        The system the orbit belongs to (kept, not written into ``nnm-numeric/1``).
    contact_springs : tuple of int
        The springs (rows of ``A``) that switch along the orbit, increasing
        (not written into ``nnm-numeric/1``); a spring engaged or free during
        the whole orbit is not listed.  A change between two points of a branch
        is a spring whose gap ``A_i X − b_i`` starts or stops changing sign
        along the orbit: it grazes the orbit's turning point in between.
    minimal_periods : int
        How many times the orbit closes within ``period``: the minimal period
        is ``period / minimal_periods``.  1 on every success (a solution that
        is an orbit of period T/m run m times is re-solved at T/m or reported
        as a failure with m here, and the message says so); checked by the one
        rule of the forced orbits' ``minimal_periods`` too.  Not written into
        ``nnm-numeric/1`` (the schema is unchanged).

    JSON schema ``lindstedt.nnm-numeric/1`` (:meth:`to_dict`, documented key by key).
    """

    SCHEMA = "lindstedt.nnm-numeric/1"

    success: bool
    message: str
    mode: int
    epsilon: float
    frequency: float
    period: float
    linear_frequency: float
    release_position: np.ndarray
    release_velocity: np.ndarray
    modal_coordinates: np.ndarray
    energy: float
    floquet_multipliers: np.ndarray | None
    stable: bool | None
    residual: float
    n_switches: int
    mode_share: float
    formulation: str
    newton_iterations: int
    flow_evaluations: int
    monodromy: np.ndarray | None = field(default=None, repr=False)
    system: Any = field(default=None, repr=False, compare=False)  # the UnilateralSystem it was computed for
    contact_springs: tuple[int, ...] = field(default=(), compare=False)
    minimal_periods: int = 1

    @property
    def minimal_period(self) -> float:
        """The orbit's minimal period ``period / minimal_periods`` (equal to ``period`` on success)."""
        return self.period / self.minimal_periods

    @property
    def nontrivial_multipliers(self) -> np.ndarray | None:
        """The Floquet multipliers without the trivial pair (see :attr:`floquet_multipliers`), or None."""
        return None if self.floquet_multipliers is None else self.floquet_multipliers[2:]

    @property
    def contact(self) -> bool:
        """Whether the orbit touches a unilateral spring (switches during a period)."""
        return self.n_switches > 0

    @property
    def modal_amplitude(self) -> float:
        """``u_j(0)``, the release modal coordinate of the NNM's own mode."""
        return float(self.modal_coordinates[self.mode - 1])

    @property
    def max_abs_multiplier(self) -> float | None:
        """The largest ``|μ|`` of the non-trivial Floquet multipliers (1.0 when there are none, as for one degree of
        freedom; None when they were not computed)."""
        if self.floquet_multipliers is None or not np.size(self.floquet_multipliers):
            return None
        nontrivial = self.nontrivial_multipliers
        return float(np.max(np.abs(nontrivial))) if np.size(nontrivial) else 1.0

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready data (schema ``lindstedt.nnm-numeric/1``); NaN and infinities become ``None``.

        Examples
        --------
        >>> import lindstedt
        >>> chain = lindstedt.UnilateralSystem.chain(2, unilateral=[(0, 0)])
        >>> data = lindstedt.nnm_point(chain, 0.05, 1, modal_amplitude=1.0).to_dict()
        >>> data["success"], data["status"], round(data["frequency"], 6)
        (True, 'converged', 1.006128)
        """

        def vector(values: Any) -> list[float | None]:
            return to_jsonable(np.asarray(values, dtype=float).reshape(-1))

        multipliers = (
            [] if self.floquet_multipliers is None
            else to_jsonable(np.asarray(self.floquet_multipliers, dtype=complex).reshape(-1))
        )
        return {
            "schema": self.SCHEMA,
            "success": bool(self.success),
            "status": "converged" if self.success else "failed",
            "message": self.message,
            "mode": self.mode,
            "epsilon": finite_float(self.epsilon),
            "frequency": finite_float(self.frequency),
            "period": finite_float(self.period),
            "linear_frequency": finite_float(self.linear_frequency),
            "release_position": vector(self.release_position),
            "release_velocity": vector(self.release_velocity),
            "modal_coordinates": vector(self.modal_coordinates),
            "energy": finite_float(self.energy),
            "floquet_multipliers": multipliers,
            "stable": self.stable,
            "residual": finite_float(self.residual),
            "n_switches": self.n_switches,
            "formulation": self.formulation,
            "newton_iterations": self.newton_iterations,
            "flow_evaluations": self.flow_evaluations,
        }

    def summary(self) -> str:
        """One line: mode, ε, ω, T, energy, stability, cost."""
        if not self.success:
            return f"mode {self.mode}, ε = {self.epsilon:g}: FAILED — {self.message}"
        largest = float("nan") if self.max_abs_multiplier is None else self.max_abs_multiplier
        return (
            f"mode {self.mode}, ε = {self.epsilon:g}: ω = {self.frequency:.12g} (λ_j = {self.linear_frequency:.12g}), "
            f"T = {self.period:.12g}, E = {self.energy:.6g}, max|μ| = {largest:.6g} "
            f"({'stable' if self.stable else 'unstable'}), {self.n_switches} switches/period, "
            f"{self.newton_iterations} iterations, {self.flow_evaluations} flows"
        )

    # -- display -----------------------------------------------------------------------------
    def _display_rows(self, quoted: bool = True) -> list[tuple[str, str]]:
        """(label, text) of the fields people read first: outcome, frequencies, release, stability, cost."""
        largest = "None" if self.max_abs_multiplier is None else format_number(self.max_abs_multiplier, 6)
        return [
            ("success", str(bool(self.success))),
            ("message", repr(self.message) if quoted else self.message),
            ("mode", str(self.mode)),
            ("epsilon", format_number(self.epsilon)),
            ("frequency", format_number(self.frequency)),
            ("period", format_number(self.period)),
            ("linear_frequency", format_number(self.linear_frequency)),
            ("modal_amplitude", format_number(self.modal_amplitude)),
            ("release_position", format_vector(self.release_position)),
            ("energy", format_number(self.energy)),
            ("stable", str(self.stable)),
            ("max_abs_multiplier", largest),
            ("residual", format_number(self.residual, 3)),
            ("n_switches", str(self.n_switches)),
            ("formulation", repr(self.formulation) if quoted else self.formulation),
            ("newton_iterations", str(self.newton_iterations)),
            ("flow_evaluations", str(self.flow_evaluations)),
        ]

    def __repr__(self) -> str:
        """Labelled fields, numbers to 10 significant digits (the arrays are the fields themselves).

        Examples
        --------
        >>> import lindstedt
        >>> point = lindstedt.nnm_point(lindstedt.UnilateralSystem.one_dof(1), 3.0, 1, modal_amplitude=1.0)
        >>> text = repr(point)
        >>> "success=True" in text and "frequency=1.333333333" in text and len(text) < 1000
        True
        """
        return labelled_repr("NNMResult", self._display_rows())

    def _repr_html_(self) -> str:
        """Jupyter's rendering: a two-column table of :meth:`__repr__`'s fields."""
        state = "converged" if self.success else "FAILED"
        return html_table(f"NNMResult: mode {self.mode}, {state}", self._display_rows(quoted=False))


@dataclass(frozen=True)
class ContinuationProgress(JsonExport):
    """Passed to the continuation callback after every accepted point.

    Attributes
    ----------
    index : int
        Index of the point in the branch (0 = first).
    parameter : float
        Value of the continuation parameter.
    result : NNMResult
        The accepted point.
    step : float
        Current step (arclength for "arclength", parameter increment otherwise).
    flow_evaluations : int
        Flows used so far by the whole continuation.

    JSON schema ``lindstedt.continuation-progress/1`` (:meth:`to_json`; the
    point as its ``lindstedt.nnm-numeric/1`` dictionary).
    """

    SCHEMA = "lindstedt.continuation-progress/1"

    index: int
    parameter: float
    result: NNMResult
    step: float
    flow_evaluations: int

    def __repr__(self) -> str:
        """Index, parameter, step and the point's frequency (the point itself is ``.result``)."""
        return labelled_repr("ContinuationProgress", [
            ("index", str(self.index)),
            ("parameter", format_number(self.parameter)),
            ("frequency", format_number(self.result.frequency)),
            ("step", format_number(self.step, 4)),
            ("flow_evaluations", str(self.flow_evaluations)),
        ])


@dataclass(frozen=True)
class NNMBranch(JsonExport):
    """A branch of NNMs from a continuation.

    Attributes
    ----------
    success : bool
        Whether the continuation reached ``stop``.
    stop_reason : str
        Why it stopped ("reached stop = …", "max_points …", "step size … below
        min_step …: <corrector failure>", "callback requested stop", "first
        point failed: …").
    method : str
        ``"arclength"``, ``"natural"`` or ``"seed"``.
    parameter : str
        ``"epsilon"``, ``"energy"`` or ``"modal_amplitude"``.
    points : tuple of NNMResult
        The accepted points in branch order.
    parameter_values : numpy.ndarray
        The parameter at each point.
    folds : tuple of int
        Indices k such that the parameter turns back between points k and k + 1.
    stability_changes : tuple of int
        Indices k such that stability differs between points k and k + 1.
    contact_changes : tuple of int
        Indices k such that contact (switches per period > 0) or the springs
        switching along the orbit (:attr:`NNMResult.contact_springs`) differ
        between points k and k + 1: a spring grazes the orbit in between.
    flow_evaluations : int
        Total flow integrations (including rejected steps and verifications).
    newton_iterations : int
        Total corrector iterations (Newton or hybr).
    rejected_steps : int
        Steps that failed and were retried with a smaller step, and failed
        landings of parameter jumps.
    wall_time : float
        Seconds.
    system : UnilateralSystem
        The system of the branch (exported as its JSON dictionary).
    jumps : tuple of int
        Indices k such that points k and k + 1 are joined by a parameter jump
        across an internal resonance (method "arclength": the branch of mode j
        turns there into a resonance tongue of another mode, which is not
        followed; see :func:`~lindstedt.numerics.continue_nnm`), not by a
        continuous arc; ``stop_reason`` says what each jump crossed.  Contact
        changes (``contact_changes``, e.g. the contact onset where the
        backbone turns steep) are followed, not jumped.

    JSON schema ``lindstedt.nnm-branch/1`` (:meth:`to_json`; every point as
    its ``lindstedt.nnm-numeric/1`` dictionary).
    """

    SCHEMA = "lindstedt.nnm-branch/1"

    success: bool
    stop_reason: str
    method: str
    parameter: str
    points: tuple[NNMResult, ...]
    parameter_values: np.ndarray
    folds: tuple[int, ...]
    stability_changes: tuple[int, ...]
    contact_changes: tuple[int, ...]
    flow_evaluations: int
    newton_iterations: int
    rejected_steps: int
    wall_time: float
    system: Any = field(default=None, repr=False, compare=False)  # the UnilateralSystem it was computed for
    jumps: tuple[int, ...] = ()
    #: the sign changes of the test functions met along the branch, located on demand (bifurcations)
    _locator: Any = field(default=None, repr=False, compare=False, metadata={"export": False})

    @cached_property
    @locked  # the location runs the problem's flows again: one thread at a time
    def bifurcations(self) -> tuple[Bifurcation, ...]:
        """The special points of the branch (method "arclength"), located when first read.

        Folds, branch points and period doublings (a non-trivial Floquet multiplier through −1) — found by the
        same test functions and the same location as on forced branches (:mod:`lindstedt.numerics.arclength`);
        the Neimark–Sacker test does not apply to these conservative orbits.  The continuation only notes where
        a test changes sign (at no cost); reading this locates them (a few corrector solves each, counted in no
        cost counter of the branch).  A sign change is not searched across a contact change or a jump (the
        residual is not smooth there), and one whose test jumps instead of vanishing is not a special point.
        ``frequency`` is ω, ``amplitude`` ``|X0|``, ``state`` ``(X0, X1)`` and ``forcing_scale`` the parameter
        value there.
        """
        return self._locator() if self._locator is not None else ()

    def __len__(self) -> int:
        return len(self.points)

    @property
    def frequencies(self) -> np.ndarray:
        """ω at each point."""
        return np.array([p.frequency for p in self.points])

    @property
    def epsilons(self) -> np.ndarray:
        """ε at each point."""
        return np.array([p.epsilon for p in self.points])

    @property
    def energies(self) -> np.ndarray:
        """Energy (:func:`nnm_energy`) at each point."""
        return np.array([p.energy for p in self.points])

    @property
    def stable(self) -> np.ndarray:
        """Stability flag at each point."""
        return np.array([bool(p.stable) for p in self.points])

    # -- display -----------------------------------------------------------------------------
    def _display_rows(self, quoted: bool = True) -> list[tuple[str, str]]:
        """(label, text) of the branch as a whole: outcome, ranges, events, cost."""
        def span(values: np.ndarray) -> str:
            if not len(values):
                return "[]"
            return f"[{format_number(float(np.nanmin(values)))}, {format_number(float(np.nanmax(values)))}]"

        def indices(values: tuple[int, ...]) -> str:
            return format_vector(values, limit=10) if values else "()"

        return [
            ("success", str(bool(self.success))),
            ("stop_reason", repr(self.stop_reason) if quoted else self.stop_reason),
            ("method", repr(self.method) if quoted else self.method),
            ("parameter", repr(self.parameter) if quoted else self.parameter),
            ("points", str(len(self.points))),
            ("parameter_range", span(np.asarray(self.parameter_values, dtype=float))),
            ("frequency_range", span(self.frequencies)),
            ("folds", indices(self.folds)),
            ("stability_changes", indices(self.stability_changes)),
            ("contact_changes", indices(self.contact_changes)),
            ("jumps", indices(self.jumps)),
            ("bifurcations", f"{len(self._locator.brackets) if self._locator is not None else 0} sign change(s) of "
                             "the tests (.bifurcations locates them)"),
            ("flow_evaluations", str(self.flow_evaluations)),
            ("newton_iterations", str(self.newton_iterations)),
            ("rejected_steps", str(self.rejected_steps)),
            ("wall_time", f"{self.wall_time:.3g} s"),
        ]

    def to_dataframe(self) -> Any:
        """The branch as a pandas DataFrame: one row per point, the continuation parameter's column first
        (the columns of :func:`to_dataframe`, plus ``jump_after``: the point is followed by a jump).

        Examples
        --------
        >>> import lindstedt
        >>> branch = lindstedt.continue_nnm(lindstedt.UnilateralSystem.one_dof(1), 1, start=0.0, stop=0.5, modal_amplitude=1.0)
        >>> table = branch.to_dataframe()
        >>> list(table.columns[:3]), len(table) == len(branch.points)
        (['epsilon', 'success', 'frequency'], True)
        """
        table = to_dataframe(self.points)
        table = table[[self.parameter, *(column for column in table.columns if column != self.parameter)]]
        jumps = set(self.jumps)
        table["jump_after"] = [index in jumps for index in range(len(self.points))]
        return table

    def __repr__(self) -> str:
        """A summary (ranges, events, cost), never the points themselves (``.points``, ``.frequencies``…).

        Examples
        --------
        >>> import numpy as np
        >>> branch = NNMBranch(True, "reached stop = 1", "natural", "epsilon", (), np.array([]), (), (), (), 4, 3, 0, 0.5)
        >>> print(repr(branch).splitlines()[5:7])
        ['  points=0,', '  parameter_range=[],']
        """
        return labelled_repr("NNMBranch", self._display_rows())

    def _repr_html_(self, rows: int = 12) -> str:
        """Jupyter's rendering: the summary table, then at most ``rows`` points (ends, events and evenly spaced)."""
        summary = html_table(f"NNMBranch: {len(self.points)} points", self._display_rows(quoted=False))
        if not self.points:
            return summary
        last = len(self.points) - 1
        events = {k for group in (self.folds, self.stability_changes, self.contact_changes, self.jumps) for k in group}
        chosen = set(sorted({0, last} | {k for k in events if k <= last})[:rows])
        for k in np.linspace(0, last, rows).astype(int):
            if len(chosen) >= rows:
                break
            chosen.add(int(k))
        chosen_rows = sorted(chosen)
        values = np.asarray(self.parameter_values, dtype=float)
        table = [
            [k, format_number(values[k]) if k < len(values) else "", format_number(p.epsilon), format_number(p.frequency),
             format_number(p.energy, 6), p.stable, p.n_switches, "; ".join(
                 name for name, group in (("fold", self.folds), ("stability change →", self.stability_changes),
                                          ("contact change →", self.contact_changes), ("jump →", self.jumps)) if k in group)]
            for k, p in ((k, self.points[k]) for k in chosen_rows)
        ]
        note = None if len(chosen_rows) == len(self.points) else (
            f"{len(chosen_rows)} of {len(self.points)} points shown (ends, events, evenly spaced); all in .points"
        )
        points = html_grid(
            "points", ["index", self.parameter, "ε", "ω", "energy", "stable", "switches", "event (→: before the next point)"], table, note=note
        )
        return summary + points


#: a state returns to the release state when it is within this factor of the verified periodicity residual …
_RETURN_FACTOR = 1e3
#: … or within this relative distance, whichever is larger
_RETURN_FLOOR = 1e-7


def _repetitions(candidates: Iterable[int], distance: Callable[[int], float], residual: float) -> int:
    """How many times a verified periodic orbit is run within its computed period: the largest candidate m with
    ``distance(m) ≤ max(1e3 · residual, 1e-7)``, else 1.

    ``distance(m)`` is the relative distance between the release state and the state after ``1/m`` of the
    computed period; ``residual`` is the orbit's relative periodicity residual (the return after the whole
    period).  The one rule for the minimal period of every periodic orbit: the NNMs (m among the divisors of the
    switch count, bounded by the shortest possible period) and the forced orbits (m among the divisors of the
    forcing periods k; then ``minimal_periods = k // m``).

    Examples
    --------
    >>> _repetitions([2, 3, 6], lambda m: 0.0 if m in (2, 3, 6) else 1.0, 1e-12)   # period T/6, run 6 times
    6
    >>> _repetitions([2, 3], lambda m: 0.4, 1e-12)
    1
    """
    tol = max(_RETURN_FACTOR * residual, _RETURN_FLOOR)
    for m in sorted({int(m) for m in candidates if m > 1}, reverse=True):  # the largest first: the shortest period
        if distance(m) <= tol:
            return m
    return 1


def _branch_events(points: Sequence[NNMResult], values: Sequence[float]) -> tuple[tuple[int, ...], ...]:
    """Folds (the parameter turns back at point k), stability and contact changes (between points k and k + 1).

    A contact change is a change of the springs switching along the orbit (a spring grazing in between).
    """
    increments = np.diff(np.asarray(values, dtype=float))
    folds = tuple(int(k) + 1 for k in np.flatnonzero(increments[:-1] * increments[1:] < 0))
    pairs = list(zip(points[:-1], points[1:]))
    stability = tuple(k for k, (a, b) in enumerate(pairs) if a.stable != b.stable)
    contact = tuple(k for k, (a, b) in enumerate(pairs)
                    if a.contact != b.contact or a.contact_springs != b.contact_springs)
    return folds, stability, contact


def to_dataframe(results: Sequence[NNMResult]) -> Any:
    """NNM points (a sweep's list, a branch's points) as a pandas DataFrame, one row per point.

    Columns: ``success, frequency, period, epsilon, energy, modal_amplitude, stable, max_abs_multiplier,
    residual, n_switches, mode_share, newton_iterations, flow_evaluations, message`` (pandas is optional:
    ``pip install pandas``).

    Examples
    --------
    >>> import lindstedt
    >>> from lindstedt.numerics import to_dataframe
    >>> points = lindstedt.nnm_sweep(lindstedt.UnilateralSystem.one_dof(1), 1, [0.1, 0.2], modal_amplitude=1.0)
    >>> to_dataframe(points)[["epsilon", "frequency"]].round(6).values.tolist()
    [[0.1, 1.023823], [0.2, 1.045549]]
    """
    from ..export.tables import dataframe

    rows = [
        {
            "success": result.success, "frequency": result.frequency, "period": result.period, "epsilon": result.epsilon,
            "energy": result.energy, "modal_amplitude": result.modal_amplitude, "stable": result.stable,
            "max_abs_multiplier": float("nan") if result.max_abs_multiplier is None else result.max_abs_multiplier, "residual": result.residual, "n_switches": result.n_switches,
            "mode_share": result.mode_share, "newton_iterations": result.newton_iterations,
            "flow_evaluations": result.flow_evaluations, "message": result.message,
        }
        for result in results
    ]
    return dataframe(rows, columns=["success", "frequency", "period", "epsilon", "energy", "modal_amplitude", "stable",
                                           "max_abs_multiplier", "residual", "n_switches", "mode_share", "newton_iterations",
                                           "flow_evaluations", "message"])
