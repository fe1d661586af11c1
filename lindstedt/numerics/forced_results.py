"""Results of the forced responses: one periodic orbit (:class:`ForcedOrbit`), a branch (:class:`FrequencyResponse`)
and the bifurcations located on it (:class:`Bifurcation`).

The responses are those of ``u'' + 2 ζ ω0 u' + ω0² u + ε f(u) = ε s F cos(Ω t)`` and
``M X'' + C X' + K X + ε W (A X − b)_+ = ε s P cos(Ω t)``, computed by
:mod:`lindstedt.numerics.forced_response`.  Each is a frozen dataclass exporting itself through
:mod:`lindstedt.render.json` (schemas ``lindstedt.forced-orbit/1``, ``lindstedt.bifurcation/1``,
``lindstedt.frequency-response/1``) and showing itself through :mod:`lindstedt.render.display`
(``__repr__``, ``_repr_html_``); :meth:`FrequencyResponse.to_dataframe` needs pandas
(``pip install lindstedt[pandas]``).

Examples
--------
>>> import numpy as np
>>> b = Bifurcation("fold", 1.2, np.array([1.5]), np.array([1.0, 0.0]), np.array([1.0, 0.5]), 3)
>>> b
Bifurcation(kind=fold, frequency=1.2, amplitude=[1.5], index=3)
>>> b.to_dict()["multipliers"]
[1.0, 0.5]
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._errors import LindstedtError, ProblemError
from ..render.display import format_number, format_vector, html_grid, html_table, labelled_repr
from ..render.json import JsonExport

__all__ = ["Bifurcation", "ForcedOrbit", "FrequencyResponse"]

_NO_EXPORT = {"export": False}


@dataclass(frozen=True, eq=False)
class ForcedOrbit(JsonExport):
    """A periodic response of period ``k T`` (``T = 2π/Ω``), or why it could not be computed.

    Attributes
    ----------
    success : bool
        True when ``|Π(z0) − z0| ≤ tol · |z0|`` (max norms) and, for :func:`forced_periodic_orbit`, an
        independent DOP853 integration of the period agrees (``forced_setup.VERIFY_TOL``).
    message : str
    frequency, forcing_scale : float
        Ω and the load scale s.
    periods : int
        k, the forcing periods of the orbit (of the map Π it is a fixed point of).
    minimal_periods : int
        The smallest divisor m of k with ``Π_m(z0) ≈ z0`` (1 for a period-k orbit run k times; k for
        a true period-k orbit such as a period-doubled one) — the rule every periodic orbit of the
        package shares (:attr:`NNMResult.minimal_periods <lindstedt.numerics.NNMResult>` too): the state
        after a part of the period is back within ``max(1e3 · residual, 1e-7)`` of ``z0`` (relative).
    epsilon : float or None
    state : numpy.ndarray, shape (2N,)
        ``z0 = (X(0), X'(0))``.
    multipliers : numpy.ndarray (complex), shape (2N,)
        Floquet multipliers (eigenvalues of the monodromy over k periods), by decreasing modulus.
    stable : bool
        ``max |μ| ≤ 1 + stability_tol``.
    maximum, minimum, mean : numpy.ndarray, shape (N,)
        Extremes (cubic-Hermite refined between samples) and mean of each ``X_i`` over the orbit.
    amplitude : numpy.ndarray, shape (N,)
        The peak ``max_t |X_i(t)|``.
    harmonic_cos, harmonic_sin, harmonic : numpy.ndarray, shape (N,)
        The first harmonic ``X_i ≈ a_i cos Ωt + b_i sin Ωt``: a, b and the modulus ``√(a² + b²)``.
    residual : float
        ``|Π(z0) − z0|∞ / |z0|∞`` at the returned state.
    newton_iterations, flow_evaluations, steps, evaluations : int
        Newton iterations, period maps, DOP853 steps and right-hand-side evaluations (when the flow
        reports them).

    JSON schema ``lindstedt.forced-orbit/1`` (:meth:`to_json`).

    Examples
    --------
    >>> from lindstedt.problems.forced import ForcedOscillator
    >>> from lindstedt.numerics.forced_smooth import SmoothForcedFlow
    >>> from lindstedt.numerics.forced_response import forced_periodic_orbit
    >>> flow = SmoothForcedFlow(ForcedOscillator("u", omega0=1, zeta="1/20", forcing=1), 0.5)
    >>> orbit = forced_periodic_orbit(flow, 1.0)          # H = ε F / (1 + ε − Ω² + 2iζΩ) = 0.5/(0.5 + 0.1i)
    >>> [round(float(x), 10) for x in (orbit.harmonic_cos[0], orbit.harmonic_sin[0])], bool(abs(orbit.mean[0]) < 1e-12)
    ([0.9615384615, 0.1923076923], True)
    >>> orbit.to_dict()["schema"], orbit.stable
    ('lindstedt.forced-orbit/1', True)
    """

    SCHEMA = "lindstedt.forced-orbit/1"

    success: bool
    message: str
    frequency: float
    forcing_scale: float
    periods: int
    minimal_periods: int
    epsilon: float | None
    state: np.ndarray
    multipliers: np.ndarray
    stable: bool
    maximum: np.ndarray
    minimum: np.ndarray
    amplitude: np.ndarray
    mean: np.ndarray
    harmonic_cos: np.ndarray
    harmonic_sin: np.ndarray
    harmonic: np.ndarray
    residual: float
    newton_iterations: int = 0
    flow_evaluations: int = 0
    steps: int = 0
    evaluations: int = 0
    monodromy: np.ndarray | None = field(default=None, repr=False, metadata=_NO_EXPORT)

    @property
    def phase(self) -> np.ndarray:
        """φ_i with ``X_i ≈ |H_i| cos(Ωt − φ_i)`` (the lag behind the load)."""
        return np.arctan2(self.harmonic_sin, self.harmonic_cos)

    @property
    def max_abs_multiplier(self) -> float:
        """``max |μ|`` (NaN when unknown)."""
        return float(np.max(np.abs(self.multipliers))) if np.size(self.multipliers) else float("nan")

    def _display_rows(self) -> list[tuple[str, str]]:
        return [("success", str(self.success)), ("message", self.message), ("frequency", format_number(self.frequency)),
                ("forcing_scale", format_number(self.forcing_scale)), ("periods", str(self.periods)),
                ("amplitude", format_vector(self.amplitude)), ("harmonic", format_vector(self.harmonic)),
                ("stable", str(self.stable)), ("max_abs_multiplier", format_number(self.max_abs_multiplier, 6)),
                ("residual", format_number(self.residual, 3)), ("newton_iterations", str(self.newton_iterations)),
                ("flow_evaluations", str(self.flow_evaluations))]

    def __repr__(self) -> str:
        return labelled_repr("ForcedOrbit", self._display_rows())

    def _repr_html_(self) -> str:
        return html_table(f"ForcedOrbit: Ω = {format_number(self.frequency)}, "
                          f"{'converged' if self.success else 'FAILED'}", self._display_rows())


@dataclass(frozen=True, eq=False)
class Bifurcation(JsonExport):
    """A bifurcation located on a branch, between the points ``index`` and ``index + 1``.

    Attributes
    ----------
    kind : str
        ``"fold"`` (a multiplier +1: the branch turns back in the parameter), ``"period-doubling"``
        (a real multiplier −1) or ``"neimark-sacker"`` (a complex pair on the unit circle).
    frequency, forcing_scale : float
        Ω and s at the located point.
    amplitude : numpy.ndarray, shape (N,)
        Peak of each ``X_i`` on the orbit there.
    state : numpy.ndarray, shape (2N,)
    multipliers : numpy.ndarray (complex)
    index : int
    test_value : float
        The test function at the located point (≈ 0).
    """

    SCHEMA = "lindstedt.bifurcation/1"

    kind: str
    frequency: float
    amplitude: np.ndarray
    state: np.ndarray
    multipliers: np.ndarray
    index: int
    forcing_scale: float = 1.0
    test_value: float = 0.0

    def __repr__(self) -> str:
        return labelled_repr("Bifurcation", [("kind", self.kind), ("frequency", format_number(self.frequency)),
                                             ("amplitude", format_vector(self.amplitude)), ("index", str(self.index))])


@dataclass(frozen=True, eq=False)
class FrequencyResponse(JsonExport):
    """A branch of forced periodic responses, with its located bifurcations.

    Attributes
    ----------
    success : bool
        Whether the continuation reached ``stop`` (or, for a period-2 branch, the end of its range or
        the period-1 branch again).
    message : str
    parameter : str
        ``"frequency"`` (Ω varies, s fixed) or ``"forcing"`` (s varies at fixed Ω).
    periods : int
        k of the orbits (2 on a period-doubled branch).
    epsilon : float or None
    description : dict
        The problem (equation and data), when the flow says which.
    points : tuple of ForcedOrbit
        In branch order.
    arclength : numpy.ndarray
        Scaled arclength at each point.
    bifurcations : tuple of Bifurcation
        In branch order.
    newton_iterations, flow_evaluations, steps, evaluations, rejected_steps : int
    wall_time : float
    flow : PeriodMap
        The flow (kept for branch switching; not exported).

    JSON schema ``lindstedt.frequency-response/1`` (:meth:`to_json`).

    Examples
    --------
    >>> from lindstedt.problems.forced import ForcedOscillator
    >>> from lindstedt.numerics.forced_smooth import SmoothForcedFlow
    >>> from lindstedt.numerics.forced_response import frequency_response
    >>> flow = SmoothForcedFlow(ForcedOscillator("u", omega0=1, zeta="1/20", forcing=1), 0.5)
    >>> response = frequency_response(flow, 1.0, 1.4, tol=1e-9)
    >>> response.success, response.parameter_values[[0, -1]].tolist(), response.bifurcations
    (True, [1.0, 1.4], ())
    >>> table = response.to_dataframe()
    >>> list(table.columns[:3]), len(table) == len(response)
    (['frequency', 'forcing_scale', 'stable'], True)
    """

    SCHEMA = "lindstedt.frequency-response/1"

    success: bool
    message: str
    parameter: str
    periods: int
    epsilon: float | None
    description: Any
    points: tuple[ForcedOrbit, ...]
    arclength: np.ndarray
    bifurcations: tuple[Bifurcation, ...]
    newton_iterations: int
    flow_evaluations: int
    steps: int
    evaluations: int
    rejected_steps: int
    wall_time: float
    flow: Any = field(default=None, repr=False, metadata=_NO_EXPORT)
    _scales: Any = field(default=None, repr=False)

    def __len__(self) -> int:
        return len(self.points)

    def _column(self, name: str) -> np.ndarray:
        return np.array([getattr(p, name) for p in self.points])

    frequencies = property(lambda self: self._column("frequency"), doc="Ω at each point.")
    forcing_scales = property(lambda self: self._column("forcing_scale"), doc="s at each point.")
    states = property(lambda self: self._column("state"), doc="z0 at each point, shape (n, 2N).")
    amplitudes = property(lambda self: self._column("amplitude"), doc="Peaks, shape (n, N).")
    maxima = property(lambda self: self._column("maximum"), doc="Maxima, shape (n, N).")
    minima = property(lambda self: self._column("minimum"), doc="Minima, shape (n, N).")
    means = property(lambda self: self._column("mean"), doc="Means, shape (n, N).")
    harmonics = property(lambda self: self._column("harmonic"), doc="First-harmonic moduli, shape (n, N).")
    multipliers = property(lambda self: self._column("multipliers"), doc="Floquet multipliers, shape (n, 2N).")
    stable = property(lambda self: self._column("stable").astype(bool), doc="Stability flags.")

    @property
    def parameter_values(self) -> np.ndarray:
        """The continuation parameter at each point (Ω or s)."""
        return self.frequencies if self.parameter == "frequency" else self.forcing_scales

    def of_kind(self, kind: str) -> tuple[Bifurcation, ...]:
        """The bifurcations of one kind (``"fold"``, ``"period-doubling"``, ``"neimark-sacker"``)."""
        return tuple(b for b in self.bifurcations if b.kind == kind)

    def _display_rows(self) -> list[tuple[str, str]]:
        values = self.parameter_values
        span = f"[{format_number(float(values.min()))}, {format_number(float(values.max()))}]" if len(values) else "[]"
        kinds = ", ".join(f"{b.kind} at {format_number(b.frequency if self.parameter == 'frequency' else b.forcing_scale, 8)}"
                          for b in self.bifurcations) or "none"
        return [("success", str(self.success)), ("message", self.message), ("parameter", self.parameter),
                ("periods", str(self.periods)), ("epsilon", format_number(self.epsilon)), ("points", str(len(self))),
                ("parameter_range", span), ("bifurcations", kinds), ("flow_evaluations", str(self.flow_evaluations)),
                ("newton_iterations", str(self.newton_iterations)), ("rejected_steps", str(self.rejected_steps)),
                ("wall_time", f"{self.wall_time:.3g} s")]

    def __repr__(self) -> str:
        return labelled_repr("FrequencyResponse", self._display_rows())

    def _repr_html_(self, rows: int = 12) -> str:
        summary = html_table(f"FrequencyResponse: {len(self)} points", self._display_rows())
        if not self.points:
            return summary
        chosen = sorted({int(k) for k in np.linspace(0, len(self) - 1, min(rows, len(self)))}
                        | {b.index for b in self.bifurcations})
        table = [[k, format_number(p.frequency), format_number(p.forcing_scale), format_vector(p.amplitude),
                  p.stable, format_number(p.max_abs_multiplier, 6),
                  "; ".join(b.kind for b in self.bifurcations if b.index == k)] for k, p in
                 ((k, self.points[k]) for k in chosen)]
        return summary + html_grid("points", ["index", "Ω", "s", "amplitude", "stable", "max|μ|",
                                              "bifurcation (→ next point)"], table)

    def spectrum(self, index: int, *, dof: int = 0, samples: int = 1024) -> Any:
        """The line spectrum of ``X_dof`` on the orbit ``points[index]`` (one period kT of the flow, sampled).

        The exact flow's orbit over its whole period, rectangular window: the lines at multiples of Ω/k
        (:func:`lindstedt.spectrum`; draw it with :func:`lindstedt.plot.spectrum`).

        Examples
        --------
        >>> import lindstedt
        >>> problem = lindstedt.ForcedOscillator("u", omega0=1, zeta="1/20", forcing=1)
        >>> response = lindstedt.frequency_response(problem, 0.9, 1.1, epsilon=0.1)
        >>> line = response.spectrum(0).peaks[0]   # linear: one line at Ω, |H| = εF/|1 + ε − Ω² + 2iζΩ| (textbook)
        >>> round(line.angular_frequency, 12), round(line.amplitude, 10)
        (0.9, 0.329332461)
        """
        from ..validate.spectra import spectrum

        if isinstance(index, bool) or not isinstance(index, (int, np.integer)) or not -len(self) <= index < len(self):
            raise ProblemError(f"index must be a point of the branch, -{len(self)} … {len(self) - 1}, got {index!r}")
        dofs = self.flow.dimension // 2 if self.flow is not None else len(self.points[index].amplitude)
        if isinstance(dof, bool) or not isinstance(dof, (int, np.integer)) or not 0 <= dof < dofs:
            raise ProblemError(f"dof must be a degree of freedom, 0 … {dofs - 1}, got {dof!r}")
        if self.flow is None:
            raise LindstedtError("this response has no flow (it was read back from JSON): recompute it to sample its orbits")
        point = self.points[index]
        _, states = self.flow.sample(point.state, point.frequency, periods=point.periods,
                                     forcing_scale=point.forcing_scale, samples=samples)
        return spectrum(states[:, dof], point.periods * 2 * np.pi / point.frequency, periods=point.periods)

    def to_dataframe(self) -> Any:
        """One row per point: Ω, s, stability, max|μ|, per degree of freedom i the peak, extremes, mean and
        first harmonic (``amplitude_i``, ``maximum_i``, … ``harmonic_i``), and ``bifurcation_after``.

        pandas is optional: ``pip install lindstedt[pandas]``.
        """
        from ..export.tables import dataframe

        after = {}
        for b in self.bifurcations:
            after.setdefault(b.index, []).append(b.kind)
        rows = []
        for k, p in enumerate(self.points):
            row: dict[str, Any] = {"frequency": p.frequency, "forcing_scale": p.forcing_scale, "stable": p.stable,
                                   "max_abs_multiplier": p.max_abs_multiplier}
            for name in ("amplitude", "maximum", "minimum", "mean", "harmonic_cos", "harmonic_sin", "harmonic"):
                for i, value in enumerate(getattr(p, name)):
                    row[f"{name}_{i + 1}"] = float(value)
            row["bifurcation_after"] = "; ".join(after.get(k, []))
            rows.append(row)
        return dataframe(rows)
