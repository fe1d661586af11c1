"""Results of the flows: a trajectory with its switches (:class:`FlowResult`), a state map (:class:`FlowMapResult`).

The exact event-driven flow of ``M X'' + K X + ε W (A X − b)_+ = 0`` (:class:`~lindstedt.numerics.ExactFlow`),
the DOP853 flow of ``u'' + ω0² u + ε f(u) = 0`` (:func:`~lindstedt.numerics.smooth_flow`) and the forced flows
(:class:`~lindstedt.numerics.ForcedFlow`) return them; each is a frozen dataclass exporting itself as JSON.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from .._errors import ProblemError
from .._precision import locked
from ..render.display import format_number, format_vector, html_table, labelled_repr
from ..render.json import JsonExport, exported_fields, to_jsonable
from ..problems.system import UnilateralSystem

if TYPE_CHECKING:
    from ..problems.forced import ForcedOscillator, ForcedSystem

__all__ = ["FlowMapResult", "FlowResult", "SwitchEvent"]

_EPS = float(np.finfo(float).eps)


# --------------------------------------------------------------------------- #
# results
# --------------------------------------------------------------------------- #
@dataclass(frozen=True, repr=False)
class SwitchEvent(JsonExport):
    """A switch of one unilateral spring.

    Attributes
    ----------
    time : float
        Switching time.
    spring : int
        Index of the spring (row of ``A``); for :func:`smooth_flow`, the index
        of the event function.
    direction : int
        +1 when the spring engages (``g`` becomes positive), −1 when it releases
        (for :func:`smooth_flow`: the sign of the event function's slope).

    JSON schema ``lindstedt.switch-event/1`` (:meth:`to_json`).
    """

    SCHEMA = "lindstedt.switch-event/1"

    time: float
    spring: int
    direction: int


@dataclass(frozen=True)
class FlowResult(JsonExport):
    """Trajectory returned by :meth:`ExactFlow.solve`, :func:`smooth_flow` and :meth:`ForcedFlow.solve`.

    Attributes
    ----------
    success : bool
        Whether ``t_end`` was reached.
    message : str
        What happened (why it stopped, when it failed).
    method : str
        ``"exact"`` (closed-form arcs), ``"exact-forced"`` (:class:`ForcedFlow`) or ``"DOP853"``.
    t_final : float
        Last time reached (``t_end`` on success).
    position, velocity : numpy.ndarray, shape (N,)
        State at ``t_final``.
    events : tuple of SwitchEvent
        Switches in time order.
    n_switches : int
        Number of spring switches (0 for ``smooth_flow``).
    n_root_solves : int
        Bracketed root solves (Brent) for switching times, or events located
        by ``solve_ivp``.
    n_arcs : int
        Closed-form arcs, including the restarts that keep each arc shorter
        than four periods of its slowest mode (1 for ``smooth_flow``).
    n_evaluations : int
        Gap-function evaluations of the switch search, or right-hand-side
        evaluations of ``solve_ivp``.
    n_decompositions : int
        Modal decompositions computed for this run (cache misses).
    contact_states : tuple of tuple of int
        Distinct contact states visited, in order of first visit, each given by
        its engaged springs.
    system : UnilateralSystem, ForcedSystem, ForcedOscillator or None
        The problem flowed: the :class:`UnilateralSystem` of :meth:`ExactFlow.solve`,
        the forced problem of :meth:`ForcedFlow.solve`; None for :func:`smooth_flow`,
        whose right-hand side is a function.  Exported exactly, as
        :meth:`UnilateralSystem.to_json_dict` or :meth:`ForcedSystem.to_json_dict`;
        a :class:`ForcedOscillator` as its equation (``description``) and its ``f``,
        ``params``, ``omega0``, ``zeta`` and ``forcing`` as strings (the arguments that rebuild it).
    epsilon : float or None
        ε of the flow (:meth:`ExactFlow.solve`, :meth:`ForcedFlow.solve`).

    JSON schema ``lindstedt.flow/1`` (:meth:`to_json`; the dense output is not exported).
    """

    SCHEMA = "lindstedt.flow/1"

    success: bool
    message: str
    method: str
    t_final: float
    position: np.ndarray
    velocity: np.ndarray
    events: tuple[SwitchEvent, ...]
    n_switches: int
    n_root_solves: int
    n_arcs: int
    n_evaluations: int
    n_decompositions: int
    contact_states: tuple[tuple[int, ...], ...]
    _evaluator: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]] = field(repr=False, compare=False)
    system: UnilateralSystem | ForcedSystem | ForcedOscillator | None = field(default=None, repr=False, compare=False)
    epsilon: float | None = field(default=None, repr=False, compare=False)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (see :class:`~lindstedt.render.json.JsonExport`); a forced problem as in ``system`` above.

        Examples
        --------
        >>> from lindstedt.numerics.forced_flow import ForcedFlow
        >>> from lindstedt.problems.forced import ForcedOscillator
        >>> run = ForcedFlow(ForcedOscillator("Max(0, u - 1/5)", omega0=1, zeta="1/20"), 0.5).solve([0.0, 0.0], 5.0, 1.2)
        >>> run.to_dict()["system"]["zeta"]
        '1/20'
        """
        data: dict[str, Any] = {"schema": type(self).SCHEMA}
        for item in exported_fields(self):
            value = getattr(self, item.name)
            data[item.name] = _problem_json(value) if item.name == "system" else to_jsonable(value)
        return data

    @property
    def n_states_visited(self) -> int:
        """Number of distinct contact states visited."""
        return len(self.contact_states)

    def state(self, t: Any) -> tuple[np.ndarray, np.ndarray]:
        """Positions and velocities at the times ``t`` (scalar or array) in ``[0, t_final]``.

        Returns
        -------
        (X, V) : numpy.ndarray
            Each of shape ``t.shape + (N,)``.
        """
        times = np.asarray(t, dtype=float)
        if not np.all(np.isfinite(times)):
            raise ProblemError("state(t) needs finite times")
        slack = 4 * _EPS * max(1.0, self.t_final)
        if times.size and (times.min() < -slack or times.max() > self.t_final + slack):
            raise ProblemError(
                f"state(t) is defined on [0, {self.t_final}] only, got times in [{times.min()}, {times.max()}]; "
                "solve over a longer interval"
            )
        flat = np.clip(times.reshape(-1), 0.0, self.t_final)
        positions, velocities = self._evaluator(flat)
        n = positions.shape[-1]
        return positions.reshape(times.shape + (n,)), velocities.reshape(times.shape + (n,))

    # -- display -----------------------------------------------------------------------------
    def _display_rows(self, quoted: bool = True) -> list[tuple[str, str]]:
        events = ", ".join(
            f"t={format_number(e.time, 6)} spring {e.spring} {'on' if e.direction > 0 else 'off'}" for e in self.events[:3]
        )
        if len(self.events) > 3:
            events += f", … ({len(self.events)} events; all in .events)"
        return [
            ("success", str(bool(self.success))),
            ("message", repr(self.message) if quoted else self.message),
            ("method", repr(self.method) if quoted else self.method),
            ("t_final", format_number(self.t_final)),
            ("position", format_vector(self.position)),
            ("velocity", format_vector(self.velocity)),
            ("events", f"[{events}]"),
            ("n_switches", str(self.n_switches)),
            ("n_root_solves", str(self.n_root_solves)),
            ("n_arcs", str(self.n_arcs)),
            ("n_evaluations", str(self.n_evaluations)),
            ("n_decompositions", str(self.n_decompositions)),
            ("contact_states", format_vector([str(list(state)) for state in self.contact_states], limit=6)
             .replace("'", "")),
        ]

    def __repr__(self) -> str:
        """Outcome, final state and cost counters; at most three events (``.events`` holds them all).

        Examples
        --------
        >>> import lindstedt
        >>> run = lindstedt.ExactFlow(lindstedt.UnilateralSystem.one_dof(1), 0.5).solve([1.0], [0.0], 10.0)
        >>> text = repr(run)
        >>> "success=True" in text and "n_switches=" in text and len(text) < 1500
        True
        """
        return labelled_repr("FlowResult", self._display_rows())

    def _repr_html_(self) -> str:
        """Jupyter's rendering: a two-column table of :meth:`__repr__`'s fields."""
        return html_table(f"FlowResult: {'success' if self.success else 'FAILED'}", self._display_rows(quoted=False))


@locked  # sympy printing
def _problem_json(problem: Any) -> Any:
    """The JSON form of the problem a flow ran on (forced problems included)."""
    from ..problems.forced import ForcedOscillator, ForcedSystem  # here: import lindstedt stays light

    if isinstance(problem, ForcedSystem):
        return problem.to_json_dict()
    if isinstance(problem, ForcedOscillator):
        import sympy

        return {
            "description": problem.describe(),
            "f": sympy.sstr(problem.f),
            "params": {str(name): None if value == name else sympy.sstr(value) for name, value in problem.params},
            "omega0": sympy.sstr(problem.omega0),
            "zeta": sympy.sstr(problem.zeta),
            "forcing": sympy.sstr(problem.forcing),
        }
    return to_jsonable(problem)


@dataclass(frozen=True)
class FlowMapResult(JsonExport):
    """Result of :meth:`ExactFlow.flow_map`.

    Attributes
    ----------
    success, message : bool, str
        As in :class:`FlowResult`.
    position, velocity : numpy.ndarray, shape (N,)
        ``X(t)`` and ``X'(t)``.
    sensitivity : numpy.ndarray of shape (2N, 2N) or None
        ``∂(X(t), X'(t)) / ∂(X0, V0)`` when requested.
    n_switches, n_root_solves, n_arcs, n_evaluations : int
        Cost counters as in :class:`FlowResult`.
    system : UnilateralSystem or None
        The system flowed (exported exactly).
    epsilon : float or None
        ε of the flow.

    JSON schema ``lindstedt.flow-map/1`` (:meth:`to_json`).
    """

    SCHEMA = "lindstedt.flow-map/1"

    success: bool
    message: str
    position: np.ndarray
    velocity: np.ndarray
    sensitivity: np.ndarray | None
    n_switches: int
    n_root_solves: int
    n_arcs: int
    n_evaluations: int
    system: UnilateralSystem | None = field(default=None, repr=False, compare=False)
    epsilon: float | None = field(default=None, repr=False, compare=False)

    def _display_rows(self, quoted: bool = True) -> list[tuple[str, str]]:
        sensitivity = "None" if self.sensitivity is None else f"<{self.sensitivity.shape[0]}x{self.sensitivity.shape[1]} matrix; see .sensitivity>"
        return [
            ("success", str(bool(self.success))),
            ("message", repr(self.message) if quoted else self.message),
            ("position", format_vector(self.position)),
            ("velocity", format_vector(self.velocity)),
            ("sensitivity", sensitivity),
            ("n_switches", str(self.n_switches)),
            ("n_root_solves", str(self.n_root_solves)),
            ("n_arcs", str(self.n_arcs)),
            ("n_evaluations", str(self.n_evaluations)),
        ]

    def __repr__(self) -> str:
        """Outcome, state and cost counters; the sensitivity matrix by its shape."""
        return labelled_repr("FlowMapResult", self._display_rows())

    def _repr_html_(self) -> str:
        """Jupyter's rendering: a two-column table of :meth:`__repr__`'s fields."""
        return html_table(f"FlowMapResult: {'success' if self.success else 'FAILED'}", self._display_rows(quoted=False))


# --------------------------------------------------------------------------- #
# contact states
